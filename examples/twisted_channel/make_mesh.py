#!/usr/bin/env python3
"""Write twisted_channel.exo: a straight bar of square section whose outlet is tied to
its inlet by a translation plus a quarter turn (the deck's Lua map).

  block 1 `bar`: [-0.01, 0.01] x [-0.01, 0.01] x [0, 0.05] m, 6 x 6 x 10 Hex8.

The section grid is uniform and centred on the axis, so a quarter turn about z maps it
onto itself: the outlet's image lands on the inlet's nodes.

Side sets: 1 `inlet` (z = 0), 2 `outlet` (z = 0.05), 3 `heated` (x = +0.01),
4 `cooled` (y = -0.01). The faces x = -0.01 and y = +0.01 are left insulated.

Run: python3 examples/twisted_channel/make_mesh.py
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))

import numpy as np  # noqa: E402
from make_fixtures import hex_grid, write_exodus  # noqa: E402

HALF, LENGTH = 0.01, 0.05
N_SECTION, N_AXIAL = 6, 10

# Exodus hex sides: (side number, corner nodes (0-based local), axis, which end).
SIDES = {
    "inlet": (5, [0, 1, 2, 3], 2, 0.0),
    "outlet": (6, [4, 5, 6, 7], 2, LENGTH),
    "heated": (2, [1, 2, 6, 5], 0, HALF),
    "cooled": (1, [0, 1, 5, 4], 1, -HALF),
}


def side_set(ident, name, coords, conn):
    side, local, axis, value = SIDES[name]
    elems = [e + 1 for e, el in enumerate(conn) if all(abs(coords[el[n]][axis] - value) < 1e-12 for n in local)]
    return {"id": ident, "name": name, "elems": elems, "sides": [side] * len(elems)}


def main():
    coords, conn = hex_grid(
        N_SECTION, N_SECTION, N_AXIAL, (-HALF, -HALF, 0.0), (2 * HALF, 2 * HALF, LENGTH)
    )
    mesh = {
        "dim": 3,
        "title": "seam example: bar with a twisted periodic outlet",
        "coords": np.asarray(coords),
        "blocks": [{"id": 1, "name": "bar", "type": "HEX8", "conn": conn}],
        "side_sets": [side_set(i + 1, name, coords, conn) for i, name in enumerate(SIDES)],
        "node_sets": [],
    }
    write_exodus(os.path.join(HERE, "twisted_channel.exo"), "NETCDF3_64BIT_OFFSET", mesh)


if __name__ == "__main__":
    main()
