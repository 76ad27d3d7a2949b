#!/usr/bin/env bash
# seam beside CalculiX on the same problems, in one sitting: the tied boxes (CalculiX
# *TIE against seam's Tied_Temperature) and the boxes joined by a gap conductance h = 10
# (CalculiX surface-to-surface contact against seam's Gap_Conductance), and seam's mortar
# tie with dual multipliers beside the same CalculiX *TIE; lower box
# n1 and upper box n2 cells per unit length, T = 1 at z = 0 and 0 at z = 1. Both run on
# one thread with their defaults (CalculiX's iterative solver from 1e5 nodes, where its
# direct one runs out of memory). Prints, per case, each code's wall time (seam's: the
# median of 3 runs), peak memory and largest nodal error against the exact answer, and
# the ratios.
#
#   benches/peers.sh [quick|full]        (default full: 24x16, 54x36 and 120x80)
#
# Needs the CalculiX case scripts (PEERS, default ../shared/peers/calculix: they write
# CalculiX's decks and parse its results) and `ccx` (Debian calculix-ccx). Opt-in: not
# part of .ci/run. Writes target/peers/ (results.jsonl: one line per run).
set -euo pipefail
cd "$(dirname "$0")/.."
peers="$(cd "${PEERS:-../shared/peers/calculix}" && pwd)"
size="${1:-full}"
command -v ccx > /dev/null || { echo "ccx not found: apt-get install calculix-ccx" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "/usr/bin/time not found: apt-get install time" >&2; exit 2; }
mkdir -p target/peers
out="$PWD/target/peers/results.jsonl"
: > "$out"
if [ ! -x target/bench-venv/bin/python ]; then
    python3 -m venv target/bench-venv
    target/bench-venv/bin/pip install --quiet -r tests/python/requirements.txt
fi
if [ ! -x target/peers-venv/bin/python ]; then
    python3 -m venv target/peers-venv
    target/peers-venv/bin/pip install --quiet numpy scipy
fi
cargo build --release --locked --quiet
export RAYON_NUM_THREADS=1 OMP_NUM_THREADS=1 CCXRUNS="$PWD/target/peers/ccxruns"
sizes=("24 16")
[ "$size" = full ] && sizes+=("54 36" "120 80")
for nn in "${sizes[@]}"; do
    set -- $nn
    n1=$1 n2=$2
    solver=()
    [ "$n1" -ge 54 ] && solver=(--solver "ITERATIVE SCALING")
    echo "== tied ${n1}x${n2}" >&2
    target/bench-venv/bin/python benches/peers/seam_case.py tied --n1 "$n1" --n2 "$n2" >> "$out"
    (cd target/peers && CCX_RESULTS="$out" "$PWD/../peers-venv/bin/python" "$peers/case_tie.py" \
        --field z --n1 "$n1" --n2 "$n2" "${solver[@]}" > /dev/null)
    echo "== dual ${n1}x${n2}" >&2
    target/bench-venv/bin/python benches/peers/seam_case.py dual --n1 "$n1" --n2 "$n2" >> "$out"
    echo "== gap ${n1}x${n2}" >&2
    target/bench-venv/bin/python benches/peers/seam_case.py gap --n1 "$n1" --n2 "$n2" --h 10 >> "$out"
    (cd target/peers && CCX_RESULTS="$out" "$PWD/../peers-venv/bin/python" "$peers/case_gap.py" \
        --field z --n1 "$n1" --n2 "$n2" --h 10 "${solver[@]}" > /dev/null)
done
target/bench-venv/bin/python - "$out" <<'PY'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip()]
seam = {(r["case"], r["n1"], r["n2"]): r for r in rows if r.get("code") == "seam"}
peer = {}
for r in rows:
    if r.get("code") == "seam":
        continue
    kind = "tied" if r["case"].startswith("tie") else "gap"
    peer[(kind, r.get("n1"), r.get("n2"))] = r
print(f"{'case':<16}{'nodes':>10}{'seam s':>9}{'ccx s':>9}{'ccx/seam':>9}"
      f"{'seam MiB':>10}{'ccx MiB':>9}{'seam err':>11}{'ccx err':>11}")
for key, s in seam.items():
    # The mortar tie with dual multipliers beside the same CalculiX *TIE.
    c = peer.get(("tied" if key[0] == "dual" else key[0],) + key[1:])
    if c is None:
        continue
    print(f"{key[0] + ' ' + str(key[1]) + 'x' + str(key[2]):<16}{s['nodes']:>10}"
          f"{s['wall_s']:>9.2f}{c['wall_s']:>9.2f}{c['wall_s'] / s['wall_s']:>9.1f}"
          f"{s['peak_mib']:>10.0f}{c['peak_mib']:>9.0f}{s['max_err']:>11.1e}{c['max_err']:>11.1e}")
PY
