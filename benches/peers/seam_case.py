#!/usr/bin/env python3
"""One side-by-side case on seam's side: the geometry of a peer's case, meshed here,
solved by `seam run` with its defaults, and one JSON line of what it cost and how far it
is from the exact answer.

  tied  : lower box [0,1]^2 x [0,0.5] (n1 cells per unit length) and upper box
          [0,1]^2 x [0.5,1] (n2 cells per unit length), meshed independently and tied
          at z = 0.5 (`Enforcement for Energy = Tied_Temperature`). T = 1 at z = 0,
          T = 0 at z = 1, sides insulated: exact T = 1 - z.
  dual  : the tied boxes, tied by a mortar tie with dual Lagrange multipliers
          (`Enforcement for Energy = Tied Multipliers = Dual`, `Side B Variable
          Temperature To Temperature`), condensed out: exact T = 1 - z.
  gap   : the same boxes joined by a gap conductance h at z = 0.5 (`Gap_Conductance`,
          constant h); k = 1 in both. T = 1 at z = 0, 0 at z = 1: the flux is
          q = 1 / (1 + 1/h), exact T = 1 - q z below and q (1 - z) above.

usage: seam_case.py tied|dual|gap --n1 120 --n2 80 [--h 10] [--seam target/release/seam]
       [--dir DIR] [--repeat 3]

seam runs `--repeat` times (after the mesh file is written out to disk) and the line
reports the run of median wall time, with every run's wall time beside it: a single
run straight after writing a 100 MB mesh shares the machine with its write-back.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import netCDF4
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
sys.path.insert(0, os.path.join(ROOT, "tests", "fixtures"))
from make_fixtures import write_exodus  # noqa: E402

# Exodus hex node order: bottom face counter-clockwise, then the top face.
CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def box(n, z0, z1, first):
    """Nodes and 0-based Hex8 connectivity (numbered from `first`) of [0,1]^2 x [z0,z1]
    with n cells per unit length."""
    nz = max(1, round(n * (z1 - z0)))
    xs = np.linspace(0.0, 1.0, n + 1)
    zs = np.linspace(z0, z1, nz + 1)
    z, y, x = np.meshgrid(zs, xs, xs, indexing="ij")
    coords = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(nz), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    order = np.lexsort((i, j, k))
    i, j, k = i[order], j[order], k[order]
    node = lambda a, b, c: first + a + (n + 1) * (b + (n + 1) * c)  # noqa: E731
    conn = np.stack([node(i + a, j + b, k + c) for a, b, c in CORNERS], axis=1)
    return coords, conn.astype(np.int64), nz, (i, j, k)


def mesh(n1, n2):
    c1, e1, nz1, (_, _, k1) = box(n1, 0.0, 0.5, 0)
    c2, e2, nz2, (_, _, k2) = box(n2, 0.5, 1.0, len(c1))
    m1 = len(e1)
    # Exodus hex sides: 5 is the bottom (z-), 6 the top (z+).
    sides = lambda elems, s: {"elems": elems, "sides": [s] * len(elems)}  # noqa: E731
    side_sets = [
        {"id": 1, "name": "lower_top", **sides(list(np.flatnonzero(k1 == nz1 - 1) + 1), 6)},
        {"id": 2, "name": "upper_bottom", **sides(list(np.flatnonzero(k2 == 0) + 1 + m1), 5)},
        {"id": 3, "name": "bottom", **sides(list(np.flatnonzero(k1 == 0) + 1), 5)},
        {"id": 4, "name": "top", **sides(list(np.flatnonzero(k2 == nz2 - 1) + 1 + m1), 6)},
    ]
    coords = np.vstack([c1, c2])
    return {
        "dim": 3,
        "coords": coords,
        "node_map": np.arange(1, len(coords) + 1),
        "elem_map": np.arange(1, m1 + len(e2) + 1),
        "blocks": [
            {"id": 1, "name": "lower", "type": "HEX8", "conn": e1},
            {"id": 2, "name": "upper", "type": "HEX8", "conn": e2},
        ],
        "side_sets": side_sets,
        "node_sets": [],
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("case", choices=["tied", "dual", "gap"])
    ap.add_argument("--n1", type=int, default=12)
    ap.add_argument("--n2", type=int, default=8)
    ap.add_argument("--h", type=float, default=10.0)
    ap.add_argument("--seam", default=os.path.join(ROOT, "target", "release", "seam"))
    ap.add_argument("--dir", default=None)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    wd = a.dir or os.path.join(ROOT, "target", "peers", f"seam_{a.case}_{a.n1}x{a.n2}")
    os.makedirs(wd, exist_ok=True)
    t0 = time.time()
    m = mesh(a.n1, a.n2)
    write_exodus(os.path.join(wd, "boxes.exo"), "NETCDF4", m)
    gen_s = time.time() - t0
    enforcement = {
        "tied": "tied_temperature",
        "dual": "tied multipliers = dual\n    side b variable temperature to temperature",
        "gap": f"gap_conductance\n    gap conductance coefficient = constant h = {a.h!r}",
    }[a.case]
    with open(os.path.join(wd, "contact.i"), "w") as f:
        f.write("begin contact definition boxes\n"
                "  contact surface below contains lower_top\n"
                "  contact surface above contains upper_bottom\n"
                "  begin interaction\n    side a below\n    side b above\n  end\n"
                f"  begin enforcement\n    enforcement for energy = {enforcement}\n  end\nend\n")
    with open(os.path.join(wd, "problem.toml"), "w") as f:
        f.write('[mesh]\nfile = "boxes.exo"\n\n'
                '[[material]]\nblocks = ["lower", "upper"]\nconductivity = 1.0\n\n'
                '[[bc]]\nkind = "temperature"\nsurfaces = ["bottom"]\nvalue = 1.0\n\n'
                '[[bc]]\nkind = "temperature"\nsurfaces = ["top"]\nvalue = 0.0\n\n'
                '[contact]\nfile = "contact.i"\n\n[solve]\nkind = "steady"\n\n'
                '[output]\ndir = "out"\n')
    os.sync()
    runs = []
    for _ in range(max(1, a.repeat)):
        t1 = time.time()
        # GNU time reports the peak resident memory of seam alone (KiB, last stderr line).
        run = subprocess.run(["/usr/bin/time", "-f", "%M", a.seam, "run", "problem.toml", "--json"],
                             cwd=wd, capture_output=True, text=True)
        wall = time.time() - t1
        if run.returncode != 0:
            sys.exit(f"seam run failed ({run.returncode}):\n{run.stderr}")
        runs.append((wall, run))
    walls = [w for w, _ in runs]
    wall, run = sorted(runs, key=lambda r: r[0])[len(runs) // 2]
    peak_mib = int(run.stderr.strip().splitlines()[-1]) / 1024
    summary = json.loads(run.stdout)
    d = netCDF4.Dataset(os.path.join(wd, "out", "results.exo"))
    names = [b"".join(v).decode().strip("\0 ") for v in d.variables["name_nod_var"][:]]
    k = names.index("temperature") + 1
    t = np.asarray(d.variables[f"vals_nod_var{k}"][-1, :], float)
    z = m["coords"][:, 2]
    if a.case in ("tied", "dual"):
        exact = 1.0 - z
    else:
        q = 1.0 / (1.0 + 1.0 / a.h)
        below = np.arange(len(z)) < len(z) - (a.n2 + 1) ** 2 * (round(a.n2 / 2) + 1)
        exact = np.where(below, 1.0 - q * z, q * (1.0 - z))
    print(json.dumps({
        "code": "seam", "case": a.case, "n1": a.n1, "n2": a.n2, "nodes": len(z),
        "h": a.h if a.case == "gap" else None,
        "wall_s": round(wall, 3), "walls_s": [round(w, 3) for w in walls], "peak_mib": round(peak_mib, 1), "gen_s": round(gen_s, 2),
        "max_err": float(np.max(np.abs(t - exact))),
        "linear_solver": summary.get("linear_solver", {}).get("name"),
        "cg_iterations": summary.get("linear_solver", {}).get("iterations"),
        "timing": summary.get("timing"),
    }))


if __name__ == "__main__":
    main()
