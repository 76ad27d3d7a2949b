#!/usr/bin/env bash
# The electronics warm-up at benchmark size: examples/electronics refined N times in
# every direction (N = 13: 1.25 M nodes, 1.17 M hexes), 50 BDF2 steps of 5 s, a result
# every 25 steps. Prints the run's own phase times, the per-step medians and Krylov
# iterations from steps.csv, and the peak memory.
#
#   benches/electronics_scale.sh [N] [parallel]
#
# N defaults to 13. `parallel` sets `reproducible = false`: the factorisations use
# both cores, and runs are no longer bit-for-bit repeatable.
#
# Opt-in: not part of .ci/run. Writes into target/bench-electronics-N/.
set -euo pipefail
cd "$(dirname "$0")/.."
refine="${1:-13}"
mode="${2:-sequential}"
dir="target/bench-electronics-$refine-$mode"
mkdir -p "$dir"
if [ ! -x target/bench-venv/bin/python ]; then
    python3 -m venv target/bench-venv
    target/bench-venv/bin/pip install --quiet -r tests/python/requirements.txt
fi
if [ ! -f "$dir/electronics.exo" ]; then
    target/bench-venv/bin/python examples/electronics/make_mesh.py --refine "$refine" --out "$dir/electronics.exo"
fi
cp examples/electronics/contact.i "$dir/"
reproducible=true
[ "$mode" = parallel ] && reproducible=false
sed -e 's/^end_time = .*/end_time = 250.0/' -e 's/^every = .*/every = 25/' \
    -e "s/^tolerance = .*/&\nreproducible = $reproducible/" \
    examples/electronics/transient.toml > "$dir/transient.toml"
cargo build --release --locked --quiet
target/release/seam run "$dir/transient.toml" | tee "$dir/run.log"
target/bench-venv/bin/python - "$dir/out/steps.csv" <<'PY'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
phases = ["assembly_s", "factor_s", "solve_s"]
print(f"{len(rows)} steps")
for k in phases:
    v = [float(r[k]) for r in rows]
    print(f"  {k[:-2]:8}: median {statistics.median(v):8.3f} s, steps 1-2 {v[0]:8.3f} {v[1]:8.3f} s, sum {sum(v):8.1f} s")
later = [sum(float(r[k]) for k in phases) for r in rows[2:]]
print(f"  step 3 on (the matrix of step 2 kept): median {statistics.median(later):.3f} s")
its = [int(r["krylov_iterations"]) for r in rows]
print(f"  Krylov iterations: {sum(its)} ({' '.join(map(str, its))})")
PY
