#!/usr/bin/env python3
"""Write plugin_conductance.exo: two plates pressed together at z = 0.010 m.

  block 1 `base`:  [0, 0.04] x [0, 0.04] x [0, 0.010] m, 5 x 5 x 3 Hex8
  block 2 `cover`: [0, 0.04] x [0, 0.04] x [0.010, 0.016] m, 4 x 4 x 2 Hex8
                   (meshed apart: its faces do not match the base's)

Side sets: 1 `base_top` (z = 0.010, on base), 2 `cover_bottom` (z = 0.010, on cover),
3 `base_bottom` (z = 0), 4 `cover_top` (z = 0.016). The four sides are left insulated.

Run: python3 examples/plugin_conductance/make_mesh.py
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))

import numpy as np  # noqa: E402
from make_fixtures import hex_grid, write_exodus  # noqa: E402

SIZE, BASE, COVER = 0.04, 0.010, 0.006
TOP, BOTTOM = (6, [4, 5, 6, 7]), (5, [0, 1, 2, 3])  # Exodus hex sides and their corners


def faces_at(coords, conn, offset, side, z):
    number, local = side
    elems = [offset + e + 1 for e, el in enumerate(conn) if all(abs(coords[el[n]][2] - z) < 1e-12 for n in local)]
    return elems, [number] * len(elems)


def main():
    c1, e1 = hex_grid(5, 5, 3, (0, 0, 0), (SIZE, SIZE, BASE))
    c2, e2 = hex_grid(4, 4, 2, (0, 0, BASE), (SIZE, SIZE, COVER))
    coords = np.vstack([c1, c2])
    e2 = e2 + len(c1)
    n1 = len(e1)
    sets = [
        ("base_top", faces_at(coords, e1, 0, TOP, BASE)),
        ("cover_bottom", faces_at(coords, e2, n1, BOTTOM, BASE)),
        ("base_bottom", faces_at(coords, e1, 0, BOTTOM, 0.0)),
        ("cover_top", faces_at(coords, e2, n1, TOP, BASE + COVER)),
    ]
    mesh = {
        "dim": 3,
        "title": "seam example: two plates joined by a plugin conductance",
        "coords": coords,
        "blocks": [
            {"id": 1, "name": "base", "type": "HEX8", "conn": e1},
            {"id": 2, "name": "cover", "type": "HEX8", "conn": e2},
        ],
        "side_sets": [
            {"id": i + 1, "name": name, "elems": elems, "sides": sides}
            for i, (name, (elems, sides)) in enumerate(sets)
        ],
        "node_sets": [],
    }
    write_exodus(os.path.join(HERE, "plugin_conductance.exo"), "NETCDF3_64BIT_OFFSET", mesh)


if __name__ == "__main__":
    main()
