"""Write opening_gap.exo: a steel base under an aluminium lid, meshed apart (metres).

  block 1 `base`: [0, 40] x [0, 40] x [0, 20] mm, 5 x 5 x 8 cells.
  block 2 `lid`:  [0, 40] x [0, 40] x [20.01, 30.01] mm, 4 x 4 x 5 cells: it rests on the
                  base across a 10 µm gap (the roughness of the two faces).

Side sets: 1 `base_bottom` (z = 0), 2 `base_top`, 3 `lid_bottom`, 4 `lid_top`.

Run: python3 examples/opening_gap/make_mesh.py [--out FILE]
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
GAP = 0.01 * MM


def pick(ident, name, coords, conn, offset, sides, z):
    """The exterior sides of a block lying in the plane at height z."""
    sides = np.array(sides, np.int64).reshape(-1, 2)
    local = np.array([SIDE_CORNERS[s] for s in range(1, 7)])
    x = coords[conn[sides[:, 0][:, None], local[sides[:, 1] - 1]]]
    chosen = sides[np.all(np.abs(x[:, :, 2] - z) < 1e-9, axis=1)]
    return {"id": ident, "name": name, "elems": offset + chosen[:, 0] + 1, "sides": chosen[:, 1]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join(HERE, "opening_gap.exo"), help="the Exodus file to write")
    args = parser.parse_args()
    every = lambda i, j, k: np.ones_like(i, bool)  # noqa: E731
    side = np.linspace(0, 40, 6) * MM
    base_c, base_e = grid(side, side, np.linspace(0, 20, 9) * MM, every)
    side = np.linspace(0, 40, 5) * MM
    lid_c, lid_e = grid(side, side, np.linspace(20, 30, 6) * MM + GAP, every)
    coords = np.vstack([base_c, lid_c])
    lid_e = lid_e + len(base_c)
    n_base = len(base_e)
    base_s, lid_s = exterior_sides(base_e), exterior_sides(lid_e)
    mesh = {
        "dim": 3,
        "title": "seam example: a lid lifted off its base",
        "coords": coords,
        "blocks": [
            {"id": 1, "name": "base", "type": "HEX8", "conn": base_e},
            {"id": 2, "name": "lid", "type": "HEX8", "conn": lid_e},
        ],
        "side_sets": [
            pick(1, "base_bottom", coords, base_e, 0, base_s, 0.0),
            pick(2, "base_top", coords, base_e, 0, base_s, 20 * MM),
            pick(3, "lid_bottom", coords, lid_e, n_base, lid_s, 20 * MM + GAP),
            pick(4, "lid_top", coords, lid_e, n_base, lid_s, 30 * MM + GAP),
        ],
        "node_sets": [],
    }
    write_exodus(args.out, "NETCDF3_64BIT_OFFSET", mesh)
    print(f"wrote {args.out}: {len(coords)} nodes, {len(base_e) + len(lid_e)} hexes")


if __name__ == "__main__":
    main()
