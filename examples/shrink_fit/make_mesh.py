#!/usr/bin/env python3
"""Write shrink_fit.exo: the (r, z) section of a steel shaft with a bronze sleeve
shrink-fitted on it, for an axisymmetric run (x is the radius, y the axis).

  block 1 `shaft`:  r in [0, 0.020] m, z in [0, 0.060] m, 6 x 18 Quad4 (nodes on the axis)
  block 2 `sleeve`: r in [0.020, 0.035] m, z in [0, 0.060] m, 4 x 14 Quad4
                    (meshed apart: its bore's edges do not match the shaft's)

Side sets: 1 `shaft_surface` (r = 0.020, on the shaft), 2 `sleeve_bore` (r = 0.020, on
the sleeve), 3 `sleeve_outside` (r = 0.035). The ends are left insulated; the axis
needs nothing.

Run: python3 examples/shrink_fit/make_mesh.py (needs numpy and libexodus, as
tests/fixtures/make_fixtures.py).
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))

import numpy as np  # noqa: E402
from make_fixtures import write_exodus  # noqa: E402

SHAFT, SLEEVE, LENGTH = 0.020, 0.035, 0.060


def quad_grid(nr, nz, r0, r1, offset):
    """Nodes and counter-clockwise Quad4 connectivity (0-based, shifted by `offset`) of
    [r0, r1] x [0, LENGTH]; the elements whose side 2 (+r) or 4 (-r) is on r1 or r0."""
    rs, zs = np.linspace(r0, r1, nr + 1), np.linspace(0.0, LENGTH, nz + 1)
    coords = [(r, z, 0.0) for z in zs for r in rs]
    at = lambda i, j: offset + j * (nr + 1) + i  # noqa: E731
    conn = [[at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]
            for j in range(nz) for i in range(nr)]
    inner = [j * nr for j in range(nz)]
    outer = [j * nr + nr - 1 for j in range(nz)]
    return coords, np.array(conn), inner, outer


def main():
    c1, e1, _, shaft_out = quad_grid(6, 18, 0.0, SHAFT, 0)
    c2, e2, bore, outside = quad_grid(4, 14, SHAFT, SLEEVE, len(c1))
    n1 = len(e1)
    mesh = {
        "dim": 2,
        "title": "seam example: a shrink-fitted sleeve, axisymmetric (r, z) section",
        "coords": np.array(c1 + c2),
        "blocks": [
            {"id": 1, "name": "shaft", "type": "QUAD4", "conn": e1},
            {"id": 2, "name": "sleeve", "type": "QUAD4", "conn": e2},
        ],
        "side_sets": [
            {"id": 1, "name": "shaft_surface", "elems": [e + 1 for e in shaft_out],
             "sides": [2] * len(shaft_out)},
            {"id": 2, "name": "sleeve_bore", "elems": [n1 + e + 1 for e in bore],
             "sides": [4] * len(bore)},
            {"id": 3, "name": "sleeve_outside", "elems": [n1 + e + 1 for e in outside],
             "sides": [2] * len(outside)},
        ],
        "node_sets": [],
    }
    write_exodus(os.path.join(HERE, "shrink_fit.exo"), "NETCDF3_64BIT_OFFSET", mesh)


if __name__ == "__main__":
    main()
