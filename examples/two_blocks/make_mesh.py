#!/usr/bin/env python3
"""Write two_blocks.exo: two blocks meshed apart that meet at z = 1.

  block 1 `base`: [0,1] x [0,1] x [0,1], 6 x 6 x 6 Hex8
  block 2 `lid`:  [0,1] x [0,1] x [1,1.5], 4 x 4 x 3 Hex8   (non-matching, 3:2 in x and y)

Side sets: 1 `base_top` (z = 1, on base), 2 `lid_bottom` (z = 1, on lid),
3 `base_bottom` (z = 0), 4 `lid_top` (z = 1.5), 5 `base_sides` and 6 `lid_sides` (the
four faces x = 0, x = 1, y = 0, y = 1 of each block). Node set 1 `lid_top_nodes`.
Written as Exodus II in the netCDF 64-bit-offset flavour with the fixture writer.

Run: python3 examples/two_blocks/make_mesh.py
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))

import numpy as np  # noqa: E402
from make_fixtures import hex_grid, write_exodus  # noqa: E402


def faces_at(coords, conn, local, z):
    return [i for i, el in enumerate(conn) if all(abs(coords[el[n]][2] - z) < 1e-12 for n in local)]


# Exodus hex sides facing -x, +x, -y, +y and their corner nodes (0-based local).
SIDE_FACES = [(4, [0, 3, 7, 4], 0, 0.0), (2, [1, 2, 6, 5], 0, 1.0), (1, [0, 1, 5, 4], 1, 0.0), (3, [3, 2, 6, 7], 1, 1.0)]


def sides_of(coords, conn, offset):
    """(element numbers, sides) of every face on the planes x = 0, 1 and y = 0, 1."""
    elems, sides = [], []
    for i, el in enumerate(conn):
        for side, local, axis, value in SIDE_FACES:
            if all(abs(coords[el[n]][axis] - value) < 1e-12 for n in local):
                elems.append(offset + i + 1)
                sides.append(side)
    return elems, sides


def main():
    c1, e1 = hex_grid(6, 6, 6, (0, 0, 0), (1, 1, 1))
    c2, e2 = hex_grid(4, 4, 3, (0, 0, 1), (1, 1, 0.5))
    coords = np.vstack([c1, c2])
    e2 = e2 + len(c1)
    n1 = len(e1)
    top, bottom = [4, 5, 6, 7], [0, 1, 2, 3]  # Exodus hex side 6 and side 5 corners
    base_top = faces_at(coords, e1, top, 1.0)
    base_bottom = faces_at(coords, e1, bottom, 0.0)
    lid_bottom = faces_at(coords, e2, bottom, 1.0)
    lid_top = faces_at(coords, e2, top, 1.5)
    base_sides = sides_of(coords, e1, 0)
    lid_sides = sides_of(coords, e2, n1)
    lid_top_nodes = [i + 1 for i in range(len(c1), len(coords)) if abs(coords[i][2] - 1.5) < 1e-12]
    mesh = {
        "dim": 3,
        "title": "seam example: two blocks meshed apart",
        "coords": coords,
        "blocks": [
            {"id": 1, "name": "base", "type": "HEX8", "conn": e1},
            {"id": 2, "name": "lid", "type": "HEX8", "conn": e2},
        ],
        "side_sets": [
            {"id": 1, "name": "base_top", "elems": [i + 1 for i in base_top], "sides": [6] * len(base_top)},
            {"id": 2, "name": "lid_bottom", "elems": [n1 + i + 1 for i in lid_bottom], "sides": [5] * len(lid_bottom)},
            {"id": 3, "name": "base_bottom", "elems": [i + 1 for i in base_bottom], "sides": [5] * len(base_bottom)},
            {"id": 4, "name": "lid_top", "elems": [n1 + i + 1 for i in lid_top], "sides": [6] * len(lid_top)},
            {"id": 5, "name": "base_sides", "elems": base_sides[0], "sides": base_sides[1]},
            {"id": 6, "name": "lid_sides", "elems": lid_sides[0], "sides": lid_sides[1]},
        ],
        "node_sets": [{"id": 1, "name": "lid_top_nodes", "nodes": lid_top_nodes}],
    }
    write_exodus(os.path.join(HERE, "two_blocks.exo"), "NETCDF3_64BIT_OFFSET", mesh)


if __name__ == "__main__":
    main()
