"""Write spot_weld.exo: two steel sheets squeezed between two copper electrodes, each
part meshed on its own (lengths in metres, built from millimetres).

  block 1 `sheet_bottom`:     [0, 20] x [0, 20] x [0, 1] mm, 8 x 8 x 2 cells
  block 2 `sheet_top`:        [0, 20] x [0, 20] x [1, 2] mm, 10 x 10 x 2 cells
  block 3 `electrode_top`:    [7, 13] x [7, 13] x [2, 12] mm, 4 x 4 x 5 cells
  block 4 `electrode_bottom`: [7, 13] x [7, 13] x [-10, 0] mm, 3 x 3 x 5 cells

Side sets: 1 `feed` (the top electrode's cooled end, z = 12 mm), 2 `ground` (the
bottom electrode's end, z = -10 mm), 3 `top_tip` (the top electrode's face on the top
sheet), 4 `top_sheet_up` (the top sheet's upper face), 5 `top_sheet_down` (its lower
face: the faying surface), 6 `bottom_sheet_up` (the bottom sheet's upper face), 7
`bottom_sheet_down`, 8 `bottom_tip` (the bottom electrode's face under the bottom sheet).

Run: python3 examples/spot_weld/make_mesh.py [--out FILE]
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


def part(x, y, z, cells):
    """A box [x0, x1] x [y0, y1] x [z0, z1] mm with (nx, ny, nz) cells."""
    every = lambda i, j, k: np.ones_like(i, bool)  # noqa: E731
    axes = [np.linspace(a, b, n + 1) * MM for (a, b), n in zip((x, y, z), cells)]
    return grid(*axes, every)


def on_plane(ident, name, coords, conn, offset, z):
    """The exterior sides of a block lying in the plane at height z (mm)."""
    sides = np.array(exterior_sides(conn), np.int64).reshape(-1, 2)
    local = np.array([SIDE_CORNERS[s] for s in range(1, 7)])
    x = coords[conn[sides[:, 0][:, None], local[sides[:, 1] - 1]]]
    chosen = sides[np.all(np.abs(x[:, :, 2] - z * MM) < 1e-9, axis=1)]
    return {"id": ident, "name": name, "elems": offset + chosen[:, 0] + 1, "sides": chosen[:, 1]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join(HERE, "spot_weld.exo"), help="the Exodus file to write")
    args = parser.parse_args()
    parts = [
        ("sheet_bottom", part((0, 20), (0, 20), (0, 1), (8, 8, 2))),
        ("sheet_top", part((0, 20), (0, 20), (1, 2), (10, 10, 2))),
        ("electrode_top", part((7, 13), (7, 13), (2, 12), (4, 4, 5))),
        ("electrode_bottom", part((7, 13), (7, 13), (-10, 0), (3, 3, 5))),
    ]
    coords, blocks, node_offset, elem_offset, offsets = [], [], 0, 0, {}
    for k, (name, (c, e)) in enumerate(parts):
        coords.append(c)
        blocks.append({"id": k + 1, "name": name, "type": "HEX8", "conn": e + node_offset})
        offsets[name] = (elem_offset, e + node_offset)
        node_offset += len(c)
        elem_offset += len(e)
    coords = np.vstack(coords)

    def plane(ident, name, block, z):
        offset, conn = offsets[block]
        return on_plane(ident, name, coords, conn, offset, z)

    mesh = {
        "dim": 3,
        "title": "seam example: a resistance spot weld",
        "coords": coords,
        "blocks": blocks,
        "side_sets": [
            plane(1, "feed", "electrode_top", 12),
            plane(2, "ground", "electrode_bottom", -10),
            plane(3, "top_tip", "electrode_top", 2),
            plane(4, "top_sheet_up", "sheet_top", 2),
            plane(5, "top_sheet_down", "sheet_top", 1),
            plane(6, "bottom_sheet_up", "sheet_bottom", 1),
            plane(7, "bottom_sheet_down", "sheet_bottom", 0),
            plane(8, "bottom_tip", "electrode_bottom", 0),
        ],
        "node_sets": [],
    }
    write_exodus(args.out, "NETCDF3_64BIT_OFFSET", mesh)
    print(f"wrote {args.out}: {len(coords)} nodes, {elem_offset} hexes")


if __name__ == "__main__":
    main()
