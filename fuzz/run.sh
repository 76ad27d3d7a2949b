#!/usr/bin/env bash
# Build the fuzz targets and run each, one after the other, for SECONDS (default 30).
# Fails if any target crashes (a panic, a sanitizer report), hangs (one input over
# 10 s) or runs out of memory (2 GiB); the input that did it is left in
# fuzz/artifacts/<target>/. Seeds come from the repository's own inputs; what each run
# discovers is kept in fuzz/corpus/<target>/ (not committed) for the next run.
#
# libFuzzer needs the compiler's unstable sanitizer flags; RUSTC_BOOTSTRAP=1 lets the
# stable toolchain accept them. Usage: fuzz/run.sh [SECONDS] [TARGET...]
set -euo pipefail
secs=${1:-30}
shift || true
cd "$(dirname "$0")"
root=..
all=(deck_sierra deck_toml problem mesh_exodus mesh_gmsh lua_map)
targets=("${@:-${all[@]}}")

command -v cargo-fuzz >/dev/null || cargo install --locked cargo-fuzz
export RUSTC_BOOTSTRAP=1
# Release code with debug assertions and overflow checks, under AddressSanitizer; 16
# codegen units shorten the first build (about 20 min on two cores) at some speed.
flags=(-O -a --codegen-units 16)
cargo fuzz build "${flags[@]}"

seed() { # seed TARGET FILE...: copy the files that exist into the target's corpus
    local dir=corpus/$1
    shift
    mkdir -p "$dir"
    for f in "$@"; do
        [ -f "$f" ] && cp "$f" "$dir/seed-$(echo "$f" | tr / _)"
    done
    return 0
}
shopt -s nullglob
seed deck_sierra "$root"/examples/*/*.i "$root"/tests/bad/*/*.i "$root"/tests/cases/*/*.i
seed deck_toml "$root"/examples/*/contact.toml "$root"/tests/bad/*/deck.toml
seed problem "$root"/examples/*/*.toml "$root"/tests/bad/*/problem.toml "$root"/tests/cases/*/*.toml
seed mesh_exodus "$root"/tests/fixtures/*.exo "$root"/examples/*/*.exo
seed mesh_gmsh "$root"/tests/fixtures/*.msh
seed lua_map "$root"/tests/bad/*/*.lua
# The quoted maps of the decks, one expression a line, as the target reads them.
mkdir -p corpus/lua_map
grep -ho '[xyz]_map = "[^"]*"' "$root"/examples/*/*.i "$root"/tests/bad/*/*.i |
    sed 's/^[xyz]_map = "\(.*\)"$/\1/' >corpus/lua_map/seed-deck-maps || true
printf -- '-y\nx\nz - 0.05\n' >corpus/lua_map/seed-twisted

failed=()
mkdir -p artifacts
for t in "${targets[@]}"; do
    echo "== fuzz $t for ${secs}s"
    log=artifacts/$t.log
    rc=0
    cargo fuzz run "${flags[@]}" "$t" "corpus/$t" -- \
        -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
        -print_final_stats=1 >"$log" 2>&1 || rc=$?
    grep -E '^(#[0-9]+[[:space:]]+(INITED|DONE)|stat::number_of_executed_units|==[0-9]+== *ERROR|SUMMARY|thread .* panicked)' "$log" || true
    if [ "$rc" -ne 0 ]; then
        tail -n 30 "$log"
        failed+=("$t")
    fi
done
if [ ${#failed[@]} -ne 0 ]; then
    echo "fuzzing found a fault in: ${failed[*]} (inputs in fuzz/artifacts/, logs in fuzz/artifacts/*.log)"
    exit 1
fi
echo "fuzzing: ${#targets[@]} target(s), ${secs}s each, no fault"
