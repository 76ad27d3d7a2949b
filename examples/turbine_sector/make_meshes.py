#!/usr/bin/env python3
"""Write sector.exo and ring.exo: a 1/12 sector of a turbine disk and the full ring.

The disk is an annulus r in [0.10, 0.20] m, z in [0, 0.02] m, meshed with Hex8 on a
structured (r, theta, z) grid: 6 radial cells graded towards the rim, 2 axial cells, and
8 azimuthal cells per 30 degree sector graded towards theta = 0 (cell widths grow by
about a factor 2 across the sector). Nodes lie on circles; faces are flat.

  sector.exo: one sector, theta in [0, 30] degrees, block 1 `disk`.
  ring.exo:   the same sector rotated 12 times by 30 degrees and merged into one
              conforming mesh, block 1 `disk`. Its first sector holds the nodes of
              sector.exo (the same coordinates), so the two solutions compare node by
              node.

Side sets (both files): 1 `rim` (r = 0.20), 2 `bore` (r = 0.10); sector.exo also has
3 `cut_start` (theta = 0) and 4 `cut_end` (theta = 30 degrees).

Run: python3 examples/turbine_sector/make_meshes.py
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "fixtures"))

import numpy as np  # noqa: E402
from make_fixtures import HEX_CORNERS, write_exodus  # noqa: E402

R_IN, R_OUT, THICKNESS = 0.10, 0.20, 0.02
SECTORS = 12
NR, NT, NZ = 6, 8, 2

# Exodus hex sides by the index direction they face: (side number, corner nodes).
SIDE_MINUS_R = 4  # corners 0, 4, 7, 3
SIDE_PLUS_R = 2  # corners 1, 2, 6, 5
SIDE_MINUS_T = 1  # corners 0, 1, 5, 4
SIDE_PLUS_T = 3  # corners 3, 2, 6, 7


def radii():
    s = np.linspace(0.0, 1.0, NR + 1)
    # Finer towards the rim, where the angular load varies most.
    return R_IN + (R_OUT - R_IN) * (1.0 - (1.0 - s) ** 1.4)


def sector_angles():
    s = np.linspace(0.0, 1.0, NT + 1)
    return (2.0 * np.pi / SECTORS) * s**1.3


def disk(n_sectors):
    """Coordinates and connectivity of n_sectors consecutive sectors; a full ring wraps."""
    r = radii()
    z = np.linspace(0.0, THICKNESS, NZ + 1)
    wraps = n_sectors == SECTORS
    theta = np.concatenate(
        [sector_angles()[:-1] + s * 2.0 * np.pi / SECTORS for s in range(n_sectors)]
    )
    if not wraps:
        theta = np.append(theta, n_sectors * 2.0 * np.pi / SECTORS)
    nt_nodes = len(theta)
    nt_cells = nt_nodes if wraps else nt_nodes - 1
    index = {}
    coords = []
    for k in range(NZ + 1):
        for j in range(nt_nodes):
            for i in range(NR + 1):
                index[(i, j, k)] = len(coords)
                coords.append((r[i] * np.cos(theta[j]), r[i] * np.sin(theta[j]), z[k]))
    conn, cells = [], []
    for k in range(NZ):
        for j in range(nt_cells):
            for i in range(NR):
                conn.append([index[(i + a, (j + b) % nt_nodes, k + c)] for a, b, c in HEX_CORNERS])
                cells.append((i, j, k))
    return np.array(coords, float), np.array(conn, np.int64), cells, nt_cells


def side_set(ident, name, cells, pick, side):
    elems = [e + 1 for e, cell in enumerate(cells) if pick(cell)]
    return {"id": ident, "name": name, "elems": elems, "sides": [side] * len(elems)}


def write(path, n_sectors, title):
    coords, conn, cells, nt_cells = disk(n_sectors)
    side_sets = [
        side_set(1, "rim", cells, lambda c: c[0] == NR - 1, SIDE_PLUS_R),
        side_set(2, "bore", cells, lambda c: c[0] == 0, SIDE_MINUS_R),
    ]
    if n_sectors < SECTORS:
        side_sets.append(side_set(3, "cut_start", cells, lambda c: c[1] == 0, SIDE_MINUS_T))
        side_sets.append(side_set(4, "cut_end", cells, lambda c: c[1] == nt_cells - 1, SIDE_PLUS_T))
    mesh = {
        "dim": 3,
        "title": title,
        "coords": coords,
        "blocks": [{"id": 1, "name": "disk", "type": "HEX8", "conn": conn}],
        "side_sets": side_sets,
        "node_sets": [],
    }
    write_exodus(os.path.join(HERE, path), "NETCDF3_64BIT_OFFSET", mesh)


def main():
    write("sector.exo", 1, "seam example: 1/12 sector of a turbine disk")
    write("ring.exo", SECTORS, "seam example: full turbine disk ring")


if __name__ == "__main__":
    main()
