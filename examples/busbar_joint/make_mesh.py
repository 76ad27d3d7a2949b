"""Write busbar_joint.exo: two copper busbars bolted in a lap joint (lengths in metres).

  block 1 `bar_a`: [0, 100] x [0, 40] x [0, 5] mm, 2.5 x 4 x 1.25 mm cells.
  block 2 `bar_b`: [70, 170] x [0, 40] x [5, 10] mm, 2 x 5 x 1.25 mm cells: the two
                   bars overlap on x in [70, 100] mm, where their faces do not match.

Side sets: 1 `a_end` (x = 0), 2 `a_joint` (bar A's top in the overlap), 3 `b_joint`
(bar B's bottom in the overlap), 4 `b_end` (x = 170 mm), 5 `a_cooled` and 6 `b_cooled`
(every other exterior face of each bar).

Run: python3 examples/busbar_joint/make_mesh.py [--refine N] [--out FILE]
"""

import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))
sys.path.insert(0, os.path.join(HERE, "..", "electronics"))

import numpy as np  # noqa: E402
from make_fixtures import write_exodus  # noqa: E402
from make_mesh import SIDE_CORNERS, exterior_sides, grid  # noqa: E402

MM = 1e-3


def pick(ident, name, coords, conn, offset, sides, keep):
    """The sides for which keep(face node coordinates (n, 4, 3)) holds."""
    sides = np.array(sides, np.int64).reshape(-1, 2)
    local = np.array([SIDE_CORNERS[s] for s in range(1, 7)])
    x = coords[conn[sides[:, 0][:, None], local[sides[:, 1] - 1]]]
    chosen = sides[keep(x)]
    return {"id": ident, "name": name, "elems": offset + chosen[:, 0] + 1, "sides": chosen[:, 1]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=int, default=1, help="split every cell into refine³ (default 1)")
    parser.add_argument("--out", default=os.path.join(HERE, "busbar_joint.exo"), help="the Exodus file to write")
    args = parser.parse_args()
    r = args.refine
    every = lambda i, j, k: np.ones_like(i, bool)  # noqa: E731
    a_c, a_e = grid(np.linspace(0, 100, 40 * r + 1) * MM, np.linspace(0, 40, 10 * r + 1) * MM,
                    np.linspace(0, 5, 4 * r + 1) * MM, every)
    b_c, b_e = grid(np.linspace(70, 170, 50 * r + 1) * MM, np.linspace(0, 40, 8 * r + 1) * MM,
                    np.linspace(5, 10, 4 * r + 1) * MM, every)
    coords = np.vstack([a_c, b_c])
    b_e = b_e + len(a_c)
    n_a = len(a_e)
    a_sides, b_sides = exterior_sides(a_e), exterior_sides(b_e)
    eps = 1e-9

    def plane(axis, value):
        return lambda x: np.all(np.abs(x[:, :, axis] - value) < eps, axis=1)

    def joint(z):
        return lambda x: plane(2, z)(x) & np.all(x[:, :, 0] > 70 * MM - eps, axis=1) & np.all(x[:, :, 0] < 100 * MM + eps, axis=1)

    def other(*rules):
        return lambda x: ~np.any([rule(x) for rule in rules], axis=0)

    a_end, b_end = plane(0, 0.0), plane(0, 170 * MM)
    a_joint, b_joint = joint(5 * MM), joint(5 * MM)
    mesh = {
        "dim": 3,
        "title": "seam example: a bolted busbar lap joint",
        "coords": coords,
        "blocks": [
            {"id": 1, "name": "bar_a", "type": "HEX8", "conn": a_e},
            {"id": 2, "name": "bar_b", "type": "HEX8", "conn": b_e},
        ],
        "side_sets": [
            pick(1, "a_end", coords, a_e, 0, a_sides, a_end),
            pick(2, "a_joint", coords, a_e, 0, a_sides, a_joint),
            pick(3, "b_joint", coords, b_e, n_a, b_sides, b_joint),
            pick(4, "b_end", coords, b_e, n_a, b_sides, b_end),
            pick(5, "a_cooled", coords, a_e, 0, a_sides, other(a_end, a_joint)),
            pick(6, "b_cooled", coords, b_e, n_a, b_sides, other(b_end, b_joint)),
        ],
        "node_sets": [],
    }
    write_exodus(args.out, "NETCDF3_64BIT_OFFSET", mesh)
    print(f"wrote {args.out}: {len(coords)} nodes, {len(a_e) + len(b_e)} hexes")


if __name__ == "__main__":
    main()
