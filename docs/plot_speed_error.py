#!/usr/bin/env python3
"""Plot L2 error against total time from the table `cargo bench --bench enforce` prints.

Usage: python3 docs/plot_speed_error.py docs/speed_error.txt docs/speed_error.png
(needs matplotlib: pip install matplotlib). One marker per case, one line per method.
"""

import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(src, dst):
    series = defaultdict(list)
    for line in open(src):
        parts = line.split()
        if len(parts) < 9 or not parts[-1].replace(".", "").isdigit() or "n=" not in line:
            continue
        # The label is everything before the eight number columns (a long one runs
        # into the unknowns column, so no fixed width).
        label = line[: line.rindex(parts[-8])].strip()
        method = label.rsplit(" n=", 1)[0]
        unknowns = int(parts[-8])
        l2 = float(parts[-7])
        total = float(parts[-1])
        series[method].append((total, l2, unknowns))
    fig, ax = plt.subplots(figsize=(7, 5))
    for method, pts in sorted(series.items()):
        pts.sort()
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=method)
    ax.set_xlabel("total time per solve (s)")
    ax.set_ylabel("L2 error")
    ax.set_title("seam: error against time, two blocks 3:2 non-matching vs conforming")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
