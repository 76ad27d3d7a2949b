#!/usr/bin/env python3
"""Check the result files of a `seam run` output directory with meshio.

Usage:
    python check_results.py [--expect-heat-flux] [--expect-contact]
                            [--libexodus-dump DUMP] OUTPUT_DIR

Opens every `.vtu` in OUTPUT_DIR, every file listed by a `.pvd` there, and every Exodus
file (`.exo`, `.e`), and checks that each has point data `temperature`, one value per
point, finite on every solid node (a node of a 3-D cell, or of a 2-D cell when the
mesh has no 3-D cells), that every step of an Exodus file is finite there too, that
`.pvd` times are finite and non-decreasing, and that all files agree on the number of
nodes.

Wherever they are present (required with the flags):
- `--expect-heat-flux`: cell data `heat_flux` (3 components) in every mesh `.vtu` and
  element variables `heat_flux_x/_y/_z` in every Exodus file (`_x/_y` only, and no
  `_z`, in a 2-D one), finite on every solid cell and at every step;
- `--expect-contact`: the contact faces, `contact.vtu` and the files `contact.pvd`
  lists, with cell data `interaction`, `side`, `contact_gap`, `contact_fraction`,
  `contact_area`, `interface_flux` (finite; the fraction in [0, 1]; an interaction's
  flux may be NaN only on all of its cells, where its point fluxes were not derived),
  and the nodal variables `contact_gap`, `contact_fraction`, `interface_flux` in every
  Exodus file, finite at every step. `contact_points.vtu` is checked when present.

Every mesh `.vtu` is also read by VTK's own reader (vtkXMLUnstructuredGridReader),
which must find the same points, the point data `temperature` (equal to meshio's) and,
with `--expect-heat-flux`, the cell data `heat_flux`.

`--libexodus-dump DUMP`: DUMP was written by tests/exodus/check_results.c from
`results.exo` as the Exodus II C library reads it; its times must be those of the
`.pvd` series (transient runs), its last step's nodal temperature that of the last
`.vtu` as VTK reads it (on every node where the `.vtu` value is finite), and its global
variables `heat_side_a:A/B`, `heat_side_b:A/B` at each step the interface heat that
`interface_heat.csv` gives for that time and pair (a term's last row: its total).

The contact files have their own points, so they are left out of the node-count check.
Prints one summary line; exits 0 when all is well, 1 when a check fails, 2 on bad
usage.

Needs meshio, netCDF4, numpy and vtk (pinned in requirements.txt beside this file):

    python3 -m venv venv && venv/bin/pip install -r tests/python/requirements.txt

The Rust test `output_sample_results_pass_the_python_check` (tests/it/output.rs) writes
a sample output directory and, when the environment variable SEAM_PYTHON names a
Python with these packages, runs this script on it (and on a broken copy, which must
fail):

    SEAM_PYTHON=venv/bin/python cargo test --test it output_sample
"""

import contextlib
import io
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

SOLID_3D = {"tetra", "hexahedron", "wedge", "pyramid"}
SOLID_2D = {"triangle", "quad"}
CONTACT_CELL = ["contact_gap", "contact_fraction", "contact_area", "interface_flux"]
CONTACT_NODAL = ["contact_gap", "contact_fraction", "interface_flux"]
HEAT_FLUX_EXO = ["heat_flux_x", "heat_flux_y", "heat_flux_z"]


class CheckError(Exception):
    pass


def solid_nodes(mesh, np):
    """Indices of the nodes of solid cells (3-D ones, else 2-D ones)."""
    kinds = {block.type for block in mesh.cells}
    wanted = SOLID_3D if kinds & SOLID_3D else SOLID_2D
    parts = [block.data.ravel() for block in mesh.cells if block.type in wanted]
    if not parts:
        return np.arange(len(mesh.points))
    return np.unique(np.concatenate(parts))


def check_temperature(values, nodes, npoints, where, np):
    values = np.asarray(values, dtype=float).ravel()
    if values.size != npoints:
        raise CheckError(f"{where}: temperature has {values.size} values for {npoints} points")
    bad = nodes[~np.isfinite(values[nodes])]
    if bad.size:
        raise CheckError(
            f"{where}: temperature is not finite on {bad.size} solid node(s), "
            f"first at node index {bad[0]}"
        )


def read(path, meshio):
    try:
        # meshio reads an Exodus file's first step only and warns about the others;
        # exodus_steps checks every step.
        with contextlib.redirect_stderr(io.StringIO()):
            return meshio.read(str(path))
    except Exception as e:  # meshio raises many kinds
        raise CheckError(f"{path}: meshio cannot read it: {e}") from e


def cell_array(mesh, name, path, np):
    """A cell data array over all cell blocks, or None."""
    if name not in mesh.cell_data:
        return None
    return np.concatenate([np.asarray(a, dtype=float) for a in mesh.cell_data[name]])


def solid_cells(mesh):
    """Per cell (all blocks in order), whether it is a solid cell (as solid_nodes)."""
    kinds = {block.type for block in mesh.cells}
    wanted = SOLID_3D if kinds & SOLID_3D else SOLID_2D
    out = []
    for block in mesh.cells:
        out.extend([block.type in wanted] * len(block.data))
    return out


def check_mesh_file(path, meshio, np, expect_heat_flux, is_vtu):
    """Check one file meshio reads; return its number of points and solid nodes."""
    mesh = read(path, meshio)
    if "temperature" not in mesh.point_data:
        have = ", ".join(sorted(mesh.point_data)) or "none"
        raise CheckError(f"{path}: no point data `temperature` (point data: {have})")
    nodes = solid_nodes(mesh, np)
    check_temperature(mesh.point_data["temperature"], nodes, len(mesh.points), str(path), np)
    if is_vtu:
        q = cell_array(mesh, "heat_flux", path, np)
        if q is None:
            if expect_heat_flux:
                have = ", ".join(sorted(mesh.cell_data)) or "none"
                raise CheckError(f"{path}: no cell data `heat_flux` (cell data: {have})")
        else:
            solid = np.array(solid_cells(mesh), dtype=bool)
            if q.ndim != 2 or q.shape != (len(solid), 3):
                raise CheckError(f"{path}: heat_flux has shape {q.shape}, expected ({len(solid)}, 3)")
            bad = np.nonzero(solid & ~np.all(np.isfinite(q), axis=1))[0]
            if bad.size:
                raise CheckError(
                    f"{path}: heat_flux is not finite on {bad.size} solid cell(s), first at cell {bad[0]}"
                )
    return len(mesh.points), nodes


def check_contact_file(path, meshio, np):
    """Check one contact-face file; return its number of cells."""
    mesh = read(path, meshio)
    arrays = {}
    for name in ["interaction", "side"] + CONTACT_CELL:
        a = cell_array(mesh, name, path, np)
        if a is None:
            have = ", ".join(sorted(mesh.cell_data)) or "none"
            raise CheckError(f"{path}: no cell data `{name}` (cell data: {have})")
        arrays[name] = a.ravel()
    for name in ["interaction", "side", "contact_gap", "contact_fraction", "contact_area"]:
        bad = np.nonzero(~np.isfinite(arrays[name]))[0]
        if bad.size:
            raise CheckError(f"{path}: {name} is not finite on {bad.size} cell(s), first at cell {bad[0]}")
    f = arrays["contact_fraction"]
    if np.any(f < 0) or np.any(f > 1):
        raise CheckError(f"{path}: contact_fraction outside [0, 1]: {f.min()} … {f.max()}")
    q = arrays["interface_flux"]
    if np.any(np.isinf(q)):
        raise CheckError(f"{path}: interface_flux is infinite somewhere")
    for k in np.unique(arrays["interaction"]):
        nan = np.isnan(q[arrays["interaction"] == k])
        if nan.any() and not nan.all():
            raise CheckError(f"{path}: interface_flux of interaction {int(k)} is NaN on some cells only")
    return len(f)


def check_contact_points(path, meshio, np):
    """Check `contact_points.vtu`; return its number of points."""
    mesh = read(path, meshio)
    arrays = {}
    for name in ["interaction", "status", "weight", "contact_gap", "interface_flux"]:
        a = cell_array(mesh, name, path, np)
        if a is None:
            raise CheckError(f"{path}: no cell data `{name}`")
        arrays[name] = a.ravel()
    matched = arrays["status"] == 0
    if not np.all(np.isfinite(arrays["weight"])) or not np.all(np.isfinite(arrays["contact_gap"][matched])):
        raise CheckError(f"{path}: weight or contact_gap (of matched points) is not finite")
    if np.any((arrays["status"] < 0) | (arrays["status"] > 4)):
        raise CheckError(f"{path}: status outside 0..4")
    return len(matched)


def exodus_names(nc, table):
    if table not in nc.variables:
        return []
    return [b"".join(row).decode().strip("\0 ").strip() for row in nc.variables[table][:]]


def exodus_results(path, np, expect_heat_flux, expect_contact):
    """Check the heat flux element variables and the contact nodal variables of an
    Exodus file at every step (where present, or as expected)."""
    import netCDF4

    with netCDF4.Dataset(str(path)) as nc:
        nc.set_auto_mask(False)
        nodal = exodus_names(nc, "name_nod_var")
        element = exodus_names(nc, "name_elem_var")
        # One component per dimension: a 2-D run writes x and y only.
        dim = len(nc.dimensions["num_dim"])
        wanted = HEAT_FLUX_EXO[:dim]
        found = [n for n in wanted if n in element]
        if expect_heat_flux and len(found) < dim:
            raise CheckError(f"{path}: element variables {wanted} expected (has {element})")
        if dim == 2 and HEAT_FLUX_EXO[2] in element:
            raise CheckError(f"{path}: a 2-D file with {HEAT_FLUX_EXO[2]}")
        blocks = sorted(
            int(v[len("vals_elem_var1eb"):])
            for v in nc.variables
            if v.startswith("vals_elem_var1eb")
        )
        for name in found:
            k = element.index(name) + 1
            for b in blocks:
                v = nc.variables[f"vals_elem_var{k}eb{b}"][:]
                if not np.all(np.isfinite(v)):
                    raise CheckError(f"{path}: {name} is not finite in block {b}")
        found = [n for n in CONTACT_NODAL if n in nodal]
        if expect_contact and len(found) < 3:
            raise CheckError(f"{path}: nodal variables {CONTACT_NODAL} expected (has {nodal})")
        for name in found:
            v = nc.variables[f"vals_nod_var{nodal.index(name) + 1}"][:]
            if not np.all(np.isfinite(v)):
                raise CheckError(f"{path}: nodal variable {name} is not finite")
            if name == "contact_fraction" and (np.any(v < 0) or np.any(v > 1)):
                raise CheckError(f"{path}: contact_fraction outside [0, 1]")


def exodus_steps(path, nodes, npoints, np):
    """Check `temperature` at every step of an Exodus file; return the step count."""
    import netCDF4

    with netCDF4.Dataset(str(path)) as nc:
        nc.set_auto_mask(False)
        names = []
        if "name_nod_var" in nc.variables:
            names = [
                b"".join(row).decode().strip("\0 ").strip()
                for row in nc.variables["name_nod_var"][:]
            ]
        if "temperature" not in names:
            raise CheckError(f"{path}: no nodal variable `temperature` (has {names})")
        var = nc.variables[f"vals_nod_var{names.index('temperature') + 1}"]
        times = nc.variables["time_whole"][:] if "time_whole" in nc.variables else []
        if len(times) != var.shape[0]:
            raise CheckError(f"{path}: {len(times)} times for {var.shape[0]} steps")
        if not np.all(np.isfinite(times)) or np.any(np.diff(times) < 0):
            raise CheckError(f"{path}: times are not finite and non-decreasing: {times}")
        for step in range(var.shape[0]):
            check_temperature(var[step], nodes, npoints, f"{path} step {step}", np)
        return var.shape[0]


def vtk_read(path, np):
    """Points, point data `temperature` and cell data `heat_flux` (or None) of a `.vtu`
    as VTK's own XML reader sees them."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    grid = r.GetOutput()
    if grid is None or grid.GetNumberOfPoints() == 0:
        raise CheckError(f"{path}: VTK's reader finds no points")
    points = vtk_to_numpy(grid.GetPoints().GetData())
    t = grid.GetPointData().GetArray("temperature")
    if t is None:
        raise CheckError(f"{path}: VTK's reader finds no point data `temperature`")
    q = grid.GetCellData().GetArray("heat_flux")
    return points, vtk_to_numpy(t), None if q is None else vtk_to_numpy(q)


def check_vtk(path, meshio, np, expect_heat_flux):
    """VTK reads the same points and temperature as meshio; return the temperature."""
    points, t, q = vtk_read(path, np)
    mesh = read(path, meshio)
    if points.shape != mesh.points.shape or not np.array_equal(points, mesh.points):
        raise CheckError(f"{path}: VTK and meshio read different points")
    tm = np.asarray(mesh.point_data["temperature"], dtype=float).ravel()
    same = (t == tm) | (np.isnan(t) & np.isnan(tm))
    if not np.all(same):
        raise CheckError(f"{path}: VTK and meshio read different temperatures")
    if expect_heat_flux and (q is None or q.shape != (len(solid_cells(mesh)), 3)):
        raise CheckError(f"{path}: VTK's reader finds no 3-component cell data `heat_flux`")
    return t


def check_voltage(voltage, last_vtu, np):
    """A thermal-electrical run: the voltage libexodus read from results.exo equals the
    point data `voltage` VTK reads from the last `.vtu`, which also has the 3-component
    cell data `current_density`."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(str(last_vtu))
    r.Update()
    grid = r.GetOutput()
    v = grid.GetPointData().GetArray("voltage")
    j = grid.GetCellData().GetArray("current_density")
    if v is None or j is None or j.GetNumberOfComponents() != 3:
        raise CheckError(f"{last_vtu}: VTK finds no point data `voltage` or 3-component cell data `current_density`")
    v = vtk_to_numpy(v)
    if len(v) != len(voltage):
        raise CheckError(f"{last_vtu}: {len(v)} voltages, results.exo has {len(voltage)}")
    for k in range(len(v)):
        if np.isfinite(v[k]) and abs(voltage[k + 1] - v[k]) > 1e-12 * max(1.0, abs(v[k])):
            raise CheckError(f"node {k + 1}: voltage {voltage[k + 1]!r} in results.exo (libexodus), {float(v[k])!r} in {last_vtu.name} (VTK)")


def read_dump(path, voltage=None):
    times, temperature, glob = {}, {}, {}
    for line in Path(path).read_text().splitlines():
        f = line.split(" ")
        if f[0] == "time":
            times[int(f[1])] = float(f[2])
        elif f[0] == "temperature":
            temperature[int(f[1])] = float(f[2])
        elif f[0] == "voltage":
            if voltage is not None:
                voltage[int(f[1])] = float(f[2])
        elif f[0] == "global":
            glob[(int(f[1]), " ".join(f[2:-1]))] = float(f[-1])
        else:
            raise CheckError(f"{path}: unexpected line {line!r}")
    return times, temperature, glob


def interface_heat_rows(path):
    """interface_heat.csv: (time, side_a, side_b) -> (heat_side_a, heat_side_b) of the
    term's last row (its total when split by mechanism)."""
    import csv

    out = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            key = (float(row["time"]), row["side_a"], row["side_b"])
            out[key] = (float(row["heat_side_a"]), float(row["heat_side_b"]))
    return out


def check_dump(dump, out, last_vtu, np):
    """Compare what libexodus read from results.exo with VTK and interface_heat.csv."""
    voltage = {}
    times, temperature, glob = read_dump(dump, voltage)
    if not times:
        raise CheckError(f"{dump}: no steps")
    compared = 0
    if voltage and last_vtu is not None:
        check_voltage(voltage, last_vtu, np)
    if last_vtu is not None:
        _, t, _ = vtk_read(last_vtu, np)
        if len(t) != len(temperature):
            raise CheckError(f"{dump}: {len(temperature)} nodes, {last_vtu.name} has {len(t)}")
        for k in range(len(t)):
            if np.isfinite(t[k]):
                exo = temperature[k + 1]
                if abs(exo - t[k]) > 1e-12 * max(1.0, abs(t[k])):
                    raise CheckError(
                        f"node {k + 1}: temperature {exo!r} in results.exo (libexodus), "
                        f"{float(t[k])!r} in {last_vtu.name} (VTK)")
                compared += 1
    csv = out / "interface_heat.csv"
    pairs = 0
    if glob:
        if not csv.exists():
            raise CheckError(f"{out}: results.exo has global variables but no interface_heat.csv")
        rows = interface_heat_rows(csv)
        for (step, name), value in glob.items():
            side, pair = name.split(":", 1)
            a, b = pair.split("/", 1)
            if ":" in b:  # a repeated pair: its term index, not in the csv key
                continue
            key = (times[step], a, b)
            if key not in rows:
                raise CheckError(f"{csv.name}: no row at time {times[step]} for {a}/{b}")
            want = rows[key][0 if side == "heat_side_a" else 1]
            if abs(value - want) > 1e-12 * max(1.0, abs(want)):
                raise CheckError(
                    f"step {step}: global {name} = {value!r} in results.exo (libexodus), "
                    f"{want!r} in {csv.name}")
            pairs += 1
    return len(times), compared, pairs


def pvd_files(path):
    """The files a .pvd lists, with their times, checked for order."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        raise CheckError(f"{path}: not well-formed XML: {e}") from e
    out = []
    for ds in root.iter("DataSet"):
        t = float(ds.get("timestep", "nan"))
        f = path.parent / ds.get("file", "")
        if not f.is_file():
            raise CheckError(f"{path}: lists {ds.get('file')!r}, which does not exist")
        out.append((t, f))
    if not out:
        raise CheckError(f"{path}: lists no data sets")
    times = [t for t, _ in out]
    if any(t != t or abs(t) == float("inf") for t in times) or times != sorted(times):
        raise CheckError(f"{path}: times are not finite and non-decreasing: {times}")
    return out


def main(argv):
    flags = {a for a in argv[1:] if a.startswith("--")}
    args = [a for a in argv[1:] if not a.startswith("--")]
    dump = None
    if "--libexodus-dump" in argv[1:]:
        k = argv.index("--libexodus-dump")
        if k + 1 >= len(argv):
            args = []
        else:
            dump = argv[k + 1]
            args = [a for a in args if a != dump]
        flags.discard("--libexodus-dump")
    known = {"--expect-heat-flux", "--expect-contact"}
    if len(args) != 1 or not Path(args[0]).is_dir() or flags - known:
        print(
            "usage: check_results.py [--expect-heat-flux] [--expect-contact] "
            "[--libexodus-dump DUMP] OUTPUT_DIR",
            file=sys.stderr,
        )
        print("error: give one existing output directory", file=sys.stderr)
        return 2
    expect_heat_flux = "--expect-heat-flux" in flags
    expect_contact = "--expect-contact" in flags
    import meshio
    import numpy as np

    out = Path(args[0])
    counts = {}
    vtus = set(sorted(out.glob("*.vtu")))
    pvds = sorted(out.glob("*.pvd"))
    exos = sorted(p for p in out.iterdir() if p.suffix.lower() in (".exo", ".e"))
    try:
        pvd_steps = 0
        contact = set()
        for pvd in pvds:
            listed = pvd_files(pvd)
            pvd_steps += len(listed)
            if pvd.name == "contact.pvd":
                contact.update(f for _, f in listed)
            else:
                vtus.update(f for _, f in listed)
        points = out / "contact_points.vtu"
        for f in [out / "contact.vtu", points]:
            vtus.discard(f)
        if (out / "contact.vtu").exists():
            contact.add(out / "contact.vtu")
        vtus -= contact
        if not vtus and not exos:
            raise CheckError(f"{out}: no .vtu, .pvd or Exodus file to check")
        if expect_contact and not contact:
            raise CheckError(f"{out}: no contact.vtu")
        faces = 0
        for f in sorted(contact):
            faces += check_contact_file(f, meshio, np)
        if points.exists():
            check_contact_points(points, meshio, np)
        solid = None
        for f in sorted(vtus):
            counts[f], solid = check_mesh_file(f, meshio, np, expect_heat_flux, True)
            check_vtk(f, meshio, np, expect_heat_flux)
        dumped = ""
        if dump is not None:
            series = [f for pvd in pvds if pvd.name == "temperature.pvd" for _, f in pvd_files(pvd)]
            last = series[-1] if series else (out / "temperature.vtu")
            steps, nodes, pairs = check_dump(dump, out, last if last.exists() else None, np)
            pvd_times = [t for pvd in pvds if pvd.name == "temperature.pvd"
                         for t, _ in pvd_files(pvd)]
            exo_times = list(read_dump(dump)[0].values())
            if pvd_times and pvd_times != exo_times:
                raise CheckError(f"times differ: results.exo (libexodus) {exo_times}, "
                                 f"temperature.pvd {pvd_times}")
            dumped = (f"; libexodus: {steps} steps, temperature equal to VTK's on {nodes} nodes, "
                      f"{pairs} interface heats equal to interface_heat.csv")
        exo_steps = 0
        for f in exos:
            counts[f], nodes = check_mesh_file(f, meshio, np, expect_heat_flux, False)
            exo_steps += exodus_steps(f, nodes, counts[f], np)
            exodus_results(f, np, expect_heat_flux, expect_contact)
            solid = nodes
        if len(set(counts.values())) > 1:
            detail = ", ".join(f"{p.name}: {n}" for p, n in counts.items())
            raise CheckError(f"node counts differ across files ({detail})")
    except CheckError as e:
        print(f"FAIL: {e}")
        return 1
    n = next(iter(counts.values()))
    print(
        f"ok: {len(vtus)} vtu, {len(pvds)} pvd ({pvd_steps} steps), "
        f"{len(exos)} exodus ({exo_steps} steps); {n} nodes, temperature finite on "
        f"{len(solid)} solid nodes; {len(contact)} contact file(s), {faces} contact faces"
        f"{dumped}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
