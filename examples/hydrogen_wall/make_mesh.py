"""Write hydrogen_wall.exo: a coated steel wall, coating and substrate meshed apart
(lengths in metres; a 1 x 1 mm patch of the wall, through its thickness along z).

  block 1 `coating`:   [0, 1] x [0, 1] x [0, 0.1] mm, 3 x 3 cells across, 16 through.
  block 2 `substrate`: [0, 1] x [0, 1] x [0.1, 2.1] mm, 2 x 2 cells across, 20 through:
                       the two meet at z = 0.1 mm, where their faces do not match.

Side sets: 1 `gas_side` (z = 0), 2 `coating_back` (the coating at z = 0.1 mm), 3
`substrate_front` (the substrate at z = 0.1 mm), 4 `vacuum_side` (z = 2.1 mm).

Run: python3 examples/hydrogen_wall/make_mesh.py [--out FILE]
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
    """The side set `name` of the sides for which keep(face node coordinates) holds."""
    sides = np.array(sides, np.int64).reshape(-1, 2)
    local = np.array([SIDE_CORNERS[s] for s in range(1, 7)])
    x = coords[conn[sides[:, 0][:, None], local[sides[:, 1] - 1]]]
    chosen = sides[keep(x)]
    return {"id": ident, "name": name, "elems": offset + chosen[:, 0] + 1, "sides": chosen[:, 1]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join(HERE, "hydrogen_wall.exo"), help="the Exodus file to write")
    args = parser.parse_args()
    every = lambda i, j, k: np.ones_like(i, bool)  # noqa: E731
    a_c, a_e = grid(np.linspace(0, 1, 4) * MM, np.linspace(0, 1, 4) * MM, np.linspace(0, 0.1, 17) * MM, every)
    b_c, b_e = grid(np.linspace(0, 1, 3) * MM, np.linspace(0, 1, 3) * MM, np.linspace(0.1, 2.1, 21) * MM, every)
    coords = np.vstack([a_c, b_c])
    b_e = b_e + len(a_c)
    n_a = len(a_e)
    a_sides, b_sides = exterior_sides(a_e), exterior_sides(b_e)
    eps = 1e-12

    def plane(z):
        return lambda x: np.all(np.abs(x[:, :, 2] - z) < eps, axis=1)

    mesh = {
        "dim": 3,
        "title": "seam example: hydrogen permeating a coated wall",
        "coords": coords,
        "blocks": [
            {"id": 1, "name": "coating", "type": "HEX8", "conn": a_e},
            {"id": 2, "name": "substrate", "type": "HEX8", "conn": b_e},
        ],
        "side_sets": [
            pick(1, "gas_side", coords, a_e, 0, a_sides, plane(0.0)),
            pick(2, "coating_back", coords, a_e, 0, a_sides, plane(0.1 * MM)),
            pick(3, "substrate_front", coords, b_e, n_a, b_sides, plane(0.1 * MM)),
            pick(4, "vacuum_side", coords, b_e, n_a, b_sides, plane(2.1 * MM)),
        ],
        "node_sets": [],
    }
    write_exodus(args.out, "NETCDF3_64BIT_OFFSET", mesh)
    print(f"wrote {args.out}: {len(coords)} nodes, {len(a_e) + len(b_e)} hexes")


if __name__ == "__main__":
    main()
