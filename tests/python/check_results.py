#!/usr/bin/env python3
"""Check the result files of a `seam run` output directory with meshio.

Usage:
    python check_results.py [--expect-heat-flux] [--expect-contact] OUTPUT_DIR

Opens every `.vtu` in OUTPUT_DIR, every file listed by a `.pvd` there, and every Exodus
file (`.exo`, `.e`), and checks that each has point data `temperature`, one value per
point, finite on every solid node (a node of a 3-D cell, or of a 2-D cell when the
mesh has no 3-D cells), that every step of an Exodus file is finite there too, that
`.pvd` times are finite and non-decreasing, and that all files agree on the number of
nodes.

Wherever they are present (required with the flags):
- `--expect-heat-flux`: cell data `heat_flux` (3 components) in every mesh `.vtu` and
  element variables `heat_flux_x/_y/_z` in every Exodus file, finite on every solid
  cell and at every step;
- `--expect-contact`: the contact faces, `contact.vtu` and the files `contact.pvd`
  lists, with cell data `interaction`, `side`, `contact_gap`, `contact_fraction`,
  `contact_area`, `interface_flux` (finite; the fraction in [0, 1]; an interaction's
  flux may be NaN only on all of its cells, where its point fluxes were not derived),
  and the nodal variables `contact_gap`, `contact_fraction`, `interface_flux` in every
  Exodus file, finite at every step. `contact_points.vtu` is checked when present.

The contact files have their own points, so they are left out of the node-count check.
Prints one summary line; exits 0 when all is well, 1 when a check fails, 2 on bad
usage.

Needs meshio, netCDF4 and numpy (pinned in requirements.txt beside this file):

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
        found = [n for n in HEAT_FLUX_EXO if n in element]
        if expect_heat_flux and len(found) < 3:
            raise CheckError(f"{path}: element variables {HEAT_FLUX_EXO} expected (has {element})")
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
    known = {"--expect-heat-flux", "--expect-contact"}
    if len(args) != 1 or not Path(args[0]).is_dir() or flags - known:
        print(
            "usage: check_results.py [--expect-heat-flux] [--expect-contact] OUTPUT_DIR",
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
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
