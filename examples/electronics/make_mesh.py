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

Run: python3 examples/electronics/make_mesh.py [--refine N] [--out FILE]
(--refine N splits every cell into N³: the benchmark's large scenes.)
"""

import argparse
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
    (i, j, k) with keep(i, j, k) (vectorised: i, j, k are index arrays); nodes are
    numbered in order of first use by the cells in (k, j, i) order, and nodes no kept
    cell uses are left out."""
    nx, ny, nz = len(xs), len(ys), len(zs)
    k, j, i = np.meshgrid(np.arange(nz - 1), np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    kept = keep(i, j, k)
    i, j, k = i[kept], j[kept], k[kept]
    corners = np.array(HEX_CORNERS)
    gi = i[:, None] + corners[:, 0]
    gj = j[:, None] + corners[:, 1]
    gk = k[:, None] + corners[:, 2]
    keys = ((gk * ny + gj) * nx + gi).ravel()
    unique, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    # Renumber the grid points in order of first use.
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(unique), np.int64)
    rank[order] = np.arange(len(unique))
    conn = rank[inverse].reshape(-1, 8)
    used = unique[order]
    coords = np.stack([xs[used % nx], ys[(used // nx) % ny], zs[used // (nx * ny)]], axis=1)
    return coords.astype(float), conn.astype(np.int64)


def exterior_sides(conn):
    """(element, side) of every face used by one element only, in (element, side)
    order."""
    faces = np.stack([np.sort(conn[:, list(SIDE_CORNERS[s])], axis=1) for s in range(1, 7)], axis=1)
    flat = faces.reshape(-1, 4)
    _, inverse, counts = np.unique(flat, axis=0, return_inverse=True, return_counts=True)
    once = np.flatnonzero(counts[inverse.ravel()] == 1)
    return [(int(f // 6), int(f % 6) + 1) for f in once]


def side_set(ident, name, coords, conn, offset, sides, pick):
    sides = np.array(sides, np.int64).reshape(-1, 2)
    local = np.array([SIDE_CORNERS[s] for s in range(1, 7)])
    z = coords[conn[sides[:, 0][:, None], local[sides[:, 1] - 1]], 2]
    chosen = sides[pick(z)]
    return {"id": ident, "name": name, "elems": offset + chosen[:, 0] + 1, "sides": chosen[:, 1]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--refine", type=int, default=1, help="split every cell into refine³ (default 1)")
    parser.add_argument("--out", default=os.path.join(HERE, "electronics.exo"), help="the Exodus file to write")
    args = parser.parse_args()
    r = args.refine
    if r < 1:
        parser.error("--refine must be ≥ 1")
    chip_c, chip_e = grid(
        np.linspace(-5, 5, 4 * r + 1) * MM,
        np.linspace(-5, 5, 4 * r + 1) * MM,
        np.linspace(-1, 0, 2 * r + 1) * MM,
        lambda i, j, k: np.ones_like(i, bool),
    )
    # Two base layers, then four fin layers; fins where the x cell index is 1 mod 3.
    zs = np.interp(np.linspace(0, 6, 6 * r + 1), np.arange(7), np.array([0.0, 1.5, 3.0, 5.5, 8.0, 10.5, 13.0])) * MM
    sink_c, sink_e = grid(
        np.linspace(-15, 15, 15 * r + 1) * MM,
        np.linspace(-15, 15, 10 * r + 1) * MM,
        zs,
        lambda i, j, k: (k // r < 2) | ((i // r) % 3 == 1),
    )
    coords = np.vstack([chip_c, sink_c])
    sink_e = sink_e + len(chip_c)
    n_chip = len(chip_e)
    chip_sides = exterior_sides(chip_e)
    sink_sides = exterior_sides(sink_e)

    def on_plane(z):
        return lambda zf: np.all(np.abs(zf - z) < 1e-12, axis=1)

    def off_plane(z):
        return lambda zf: ~np.all(np.abs(zf - z) < 1e-12, axis=1)

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
    fmt = "NETCDF3_64BIT_OFFSET" if len(coords) < 2_000_000 else "NETCDF3_64BIT_DATA"
    write_exodus(args.out, fmt, mesh)
    print(f"wrote {args.out}: {len(coords)} nodes, {len(chip_e) + len(sink_e)} hexes")


if __name__ == "__main__":
    main()
