#!/usr/bin/env python3
"""Check the result files of a `seam run` output directory with meshio.

Usage:
    python check_results.py OUTPUT_DIR

Opens every `.vtu` in OUTPUT_DIR, every file listed by a `.pvd` there, and every Exodus
file (`.exo`, `.e`), and checks that each has point data `temperature`, one value per
point, finite on every solid node (a node of a 3-D cell, or of a 2-D cell when the
mesh has no 3-D cells), that every step of an Exodus file is finite there too, that
`.pvd` times are finite and non-decreasing, and that all files agree on the number of
nodes. Prints one summary line; exits 0 when all is well, 1 when a check fails, 2 on
bad usage.

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


def check_mesh_file(path, meshio, np):
    """Check one file meshio reads; return its number of points."""
    try:
        # meshio reads an Exodus file's first step only and warns about the others;
        # exodus_steps checks every step.
        with contextlib.redirect_stderr(io.StringIO()):
            mesh = meshio.read(str(path))
    except Exception as e:  # meshio raises many kinds
        raise CheckError(f"{path}: meshio cannot read it: {e}") from e
    if "temperature" not in mesh.point_data:
        have = ", ".join(sorted(mesh.point_data)) or "none"
        raise CheckError(f"{path}: no point data `temperature` (point data: {have})")
    nodes = solid_nodes(mesh, np)
    check_temperature(mesh.point_data["temperature"], nodes, len(mesh.points), str(path), np)
    return len(mesh.points), nodes


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
    if len(argv) != 2 or not Path(argv[1]).is_dir():
        print("usage: check_results.py OUTPUT_DIR", file=sys.stderr)
        print("error: give one existing output directory", file=sys.stderr)
        return 2
    import meshio
    import numpy as np

    out = Path(argv[1])
    counts = {}
    vtus = set(sorted(out.glob("*.vtu")))
    pvds = sorted(out.glob("*.pvd"))
    exos = sorted(p for p in out.iterdir() if p.suffix.lower() in (".exo", ".e"))
    try:
        pvd_steps = 0
        for pvd in pvds:
            listed = pvd_files(pvd)
            pvd_steps += len(listed)
            vtus.update(f for _, f in listed)
        if not vtus and not exos:
            raise CheckError(f"{out}: no .vtu, .pvd or Exodus file to check")
        solid = None
        for f in sorted(vtus):
            counts[f], solid = check_mesh_file(f, meshio, np)
        exo_steps = 0
        for f in exos:
            counts[f], nodes = check_mesh_file(f, meshio, np)
            exo_steps += exodus_steps(f, nodes, counts[f], np)
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
        f"{len(solid)} solid nodes"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
