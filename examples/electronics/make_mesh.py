#!/usr/bin/env python3
"""Write electronics.exo: a flip-chip die under a finned heat sink (lengths in metres).

  block 1 `chip`: [-5, 5] x [-5, 5] x [-1, 0] mm, 4 x 4 x 2 Hex8 (2.5 mm cells).
  block 2 `sink`: a 30 x 30 x 3 mm base on z in [0, 3] mm with five fins 2 mm thick and
                  10 mm tall along y, at x = -13, -7, -1, 5, 11 mm (fin start), on a
                  2 mm grid in x and 3 mm in y: the chip's faces do not match the
                  sink's.

The die meets the sink's base at z = 0 (its top inside the base's footprint).
Side sets: 1 `chip_bottom` (z = -1 mm, the die's active face), 2 `chip_top` (z = 0),
3 `sink_bottom` (z = 0, on the sink), 4 `sink_cooled` (every other exterior face of the
sink: base top between the fins, base sides, fin faces and tips).

Run: python3 examples/electronics/make_mesh.py
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))

import numpy as np  # noqa: E402
from make_fixtures import HEX_CORNERS, write_exodus  # noqa: E402

MM = 1e-3
# Exodus hex sides: corner nodes (0-based local) by side number.
SIDE_CORNERS = {1: (0, 1, 5, 4), 2: (1, 2, 6, 5), 3: (2, 3, 7, 6), 4: (0, 4, 7, 3), 5: (0, 3, 2, 1), 6: (4, 5, 6, 7)}


def grid(xs, ys, zs, keep):
    """Nodes and Exodus-ordered hexes on the tensor grid xs x ys x zs, for the cells
    (i, j, k) with keep(i, j, k); nodes no kept cell uses are left out."""
    index, coords, conn = {}, [], []
    for k in range(len(zs) - 1):
        for j in range(len(ys) - 1):
            for i in range(len(xs) - 1):
                if not keep(i, j, k):
                    continue
                hexa = []
                for a, b, c in HEX_CORNERS:
                    key = (i + a, j + b, k + c)
                    if key not in index:
                        index[key] = len(coords)
                        coords.append((xs[key[0]], ys[key[1]], zs[key[2]]))
                    hexa.append(index[key])
                conn.append(hexa)
    return np.array(coords, float), np.array(conn, np.int64)


def exterior_sides(conn):
    """(element, side) of every face used by one element only."""
    count = {}
    for e, el in enumerate(conn):
        for s, local in SIDE_CORNERS.items():
            key = tuple(sorted(el[n] for n in local))
            count[key] = count.get(key, 0) + 1
    out = []
    for e, el in enumerate(conn):
        for s, local in SIDE_CORNERS.items():
            if count[tuple(sorted(el[n] for n in local))] == 1:
                out.append((e, s))
    return out


def side_set(ident, name, coords, conn, offset, sides, pick):
    chosen = [(e, s) for e, s in sides if pick([coords[conn[e][n]] for n in SIDE_CORNERS[s]])]
    return {"id": ident, "name": name, "elems": [offset + e + 1 for e, _ in chosen], "sides": [s for _, s in chosen]}


def main():
    chip_c, chip_e = grid(
        np.linspace(-5, 5, 5) * MM, np.linspace(-5, 5, 5) * MM, np.linspace(-1, 0, 3) * MM, lambda i, j, k: True
    )
    # Two base layers, then four fin layers; fins where the x cell index is 1 mod 3.
    zs = np.array([0.0, 1.5, 3.0, 5.5, 8.0, 10.5, 13.0]) * MM
    sink_c, sink_e = grid(
        np.linspace(-15, 15, 16) * MM, np.linspace(-15, 15, 11) * MM, zs, lambda i, j, k: k < 2 or i % 3 == 1
    )
    coords = np.vstack([chip_c, sink_c])
    sink_e = sink_e + len(chip_c)
    n_chip = len(chip_e)
    chip_sides = exterior_sides(chip_e)
    sink_sides = exterior_sides(sink_e)

    def on_plane(z):
        return lambda pts: all(abs(p[2] - z) < 1e-12 for p in pts)

    def off_plane(z):
        return lambda pts: not all(abs(p[2] - z) < 1e-12 for p in pts)

    mesh = {
        "dim": 3,
        "title": "seam example: die, thermal interface and finned heat sink",
        "coords": coords,
        "blocks": [
            {"id": 1, "name": "chip", "type": "HEX8", "conn": chip_e},
            {"id": 2, "name": "sink", "type": "HEX8", "conn": sink_e},
        ],
        "side_sets": [
            side_set(1, "chip_bottom", coords, chip_e, 0, chip_sides, on_plane(-1 * MM)),
            side_set(2, "chip_top", coords, chip_e, 0, chip_sides, on_plane(0.0)),
            side_set(3, "sink_bottom", coords, sink_e, n_chip, sink_sides, on_plane(0.0)),
            side_set(4, "sink_cooled", coords, sink_e, n_chip, sink_sides, off_plane(0.0)),
        ],
        "node_sets": [],
    }
    write_exodus(os.path.join(HERE, "electronics.exo"), "NETCDF3_64BIT_OFFSET", mesh)


if __name__ == "__main__":
    main()
