#!/usr/bin/env bash
# The streaming sweep's scale checks, on request (not part of scripts/test.sh: they take minutes).
#   scripts/scale.sh memory   a 10,000-run sweep; fails if its peak RSS exceeds 200 MB
#   scripts/scale.sh planner  the any-state planner's random suite with 2 x 5,000,000 = 1e7
#                             problems against rsruckig (SETTLE_PLANNER_STATE_CASES)
#   scripts/scale.sh          both
# BACKEND (default modal) picks the sweep's backend; LIMIT_MB (default 200) the bound.
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
backend="${BACKEND:-modal}"
limit_mb="${LIMIT_MB:-200}"

memory() {
    cargo build --release --locked --bin settle
    local out tmp
    out="$(mktemp -d)"
    tmp="$out/time.txt"
    if [ ! -x /usr/bin/time ]; then
        echo "scale.sh: needs /usr/bin/time (Debian: apt-get install time)" >&2
        exit 2
    fi
    /usr/bin/time -v "${CARGO_TARGET_DIR:-target}/release/settle" sweep scenarios/scale_10k.toml \
        --backend "$backend" --out "$out/sweep" 2> "$tmp" || { cat "$tmp" >&2; exit 1; }
    local kb runs
    kb="$(awk -F: '/Maximum resident set size/ {gsub(/ /, "", $2); print $2}' "$tmp")"
    runs="$(($(wc -l < "$out/sweep/runs.csv") - 1))"
    grep -E "wrote|Elapsed" "$tmp"
    echo "scale.sh: $runs runs on $backend, peak RSS $((kb / 1024)) MB (limit $limit_mb MB)"
    [ "$runs" -eq 10000 ] || { echo "scale.sh: expected 10000 runs" >&2; exit 1; }
    [ "$kb" -le $((limit_mb * 1024)) ] || { echo "scale.sh: over the limit" >&2; exit 1; }
    rm -rf "$out"
}

planner() {
    SETTLE_PLANNER_STATE_CASES=5000000 cargo test --release --locked -p settle-planner \
        --test any_state -- --nocapture
}

case "$what" in
    memory) memory ;;
    planner) planner ;;
    all) memory; planner ;;
    *) echo "usage: scripts/scale.sh [memory|planner|all]" >&2; exit 2 ;;
esac
