#!/usr/bin/env bash
# The streaming sweep's scale checks, on request (not part of scripts/test.sh: they take minutes).
#   scripts/scale.sh memory   a 10,000-run sweep; fails if its peak RSS exceeds 200 MB
#   scripts/scale.sh planner  the any-state planner's random suite with 2 x 5,000,000 = 1e7
#                             problems against rsruckig (SETTLE_PLANNER_STATE_CASES)
#   scripts/scale.sh flat     sweeps of 1,000, 10,000 and 100,000 runs (scale_10k.toml with
#                             more or fewer distances); fails if the CPU time (user + sys,
#                             not wall: the machine may be shared) per run at 100,000 is
#                             more than 20 % above that at 1,000 or at 10,000, if the
#                             peak RSS per run grows by more than 20 % from 10,000 to 100,000,
#                             or if the peak RSS per run at 100,000 runs over the 1,000-run
#                             sweep's (the fixed base) exceeds PER_RUN_LIMIT_B bytes
#   scripts/scale.sh gcode    `settle gcode` on the real sliced print of gcode/prints/benchy/
#                             (60,070 moves, 3,816 s of print; Klipper, MZV at 48 Hz on X
#                             and Y, printer_xy, modal): fails below GCODE_RATE (default
#                             5000) simulated seconds per CPU second or above GCODE_MB
#                             (default 50) MB of peak RSS; then a [gcode] sweep of 50
#                             settings (5 shapers x 10 frequencies) over the same file with
#                             --jobs 2: fails above SWEEP_WALL_S (default 60) s of wall time
#   scripts/scale.sh          all four
# BACKEND (default modal) picks the sweep's backend; LIMIT_MB (default 200) the bound;
# PER_RUN_LIMIT_B (default 600) the bound per run of `flat`: measured 469-495 B at 100,000
# runs (a ci-profile binary on 2 cores), the bound leaves room for the allocator's noise;
# SETTLE=path/to/settle uses that binary instead of building the release one.
set -euo pipefail
cd "$(dirname "$0")/.."
what="${1:-all}"
backend="${BACKEND:-modal}"
limit_mb="${LIMIT_MB:-200}"
per_run_limit_b="${PER_RUN_LIMIT_B:-600}"

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

# One sweep of $1 runs: prints "runs cpu_s peak_kb".
sweep_of() {
    local n="$1" dir="$2" scenario
    scenario="$dir/scale_$n.toml"
    sed -e "s/steps = 5000,/steps = $((n / 2)),/" -e "s/^name = .*/name = \"scale_$n\"/" \
        scenarios/scale_10k.toml > "$scenario"
    /usr/bin/time -v "$(settle_bin)" sweep "$scenario" \
        --backend "$backend" --out "$dir/out_$n" 2> "$dir/time_$n.txt" \
        || { cat "$dir/time_$n.txt" >&2; exit 1; }
    local rows
    rows="$(($(wc -l < "$dir/out_$n/runs.csv") - 1))"
    [ "$rows" -eq "$n" ] || { echo "scale.sh: expected $n runs, got $rows" >&2; exit 1; }
    awk -v n="$n" -F: '
        /User time/ { cpu += $2 } /System time/ { cpu += $2 }
        /Maximum resident set size/ { kb = $2 }
        END { printf "%d %.2f %d\n", n, cpu, kb }' "$dir/time_$n.txt"
    rm -rf "$dir/out_$n"
}

# The binary to measure: $SETTLE, else the release build (built here).
settle_bin() {
    echo "${SETTLE:-${CARGO_TARGET_DIR:-target}/release/settle}"
}

flat() {
    [ -n "${SETTLE:-}" ] || cargo build --release --locked --bin settle
    if [ ! -x /usr/bin/time ]; then
        echo "scale.sh: needs /usr/bin/time (Debian: apt-get install time)" >&2
        exit 2
    fi
    local dir
    dir="$(mktemp -d)"
    for n in 1000 10000 100000; do
        sweep_of "$n" "$dir"
    done | tee "$dir/table.txt"
    rm -rf "$dir/"*.toml "$dir/"time_*.txt
    local status=0
    awk -v backend="$backend" -v limit="$per_run_limit_b" '
        { n[NR] = $1; cpu[NR] = $2 / $1 * 1e3; kb[NR] = $3 / $1 }
        END {
            printf "| runs | CPU time (s) | per run (ms) | peak RSS (MB) | per run (KB) |\n"
            printf "|---:|---:|---:|---:|---:|\n"
            for (i = 1; i <= NR; i++)
                printf "| %d | %.2f | %.3f | %.0f | %.1f |\n", n[i], cpu[i] * n[i] / 1e3, cpu[i], kb[i] * n[i] / 1024, kb[i]
            bad = 0
            if (cpu[3] > 1.2 * cpu[1] || cpu[3] > 1.2 * cpu[2]) {
                printf "scale.sh: CPU time per run at %d runs is more than 20 %% above that at %d or %d runs (%s)\n", n[3], n[1], n[2], backend > "/dev/stderr"
                bad = 1
            }
            if (kb[3] > 1.2 * kb[2]) {
                printf "scale.sh: peak RSS per run grows by more than 20 %% from %d to %d runs\n", n[2], n[3] > "/dev/stderr"
                bad = 1
            }
            # Bytes per run over the smallest sweep (the fixed base: binary, plot buffers).
            marginal = (kb[3] * n[3] - kb[1] * n[1]) * 1024 / (n[3] - n[1])
            printf "peak RSS per run over the %d-run base at %d runs: %.0f B (limit %d B)\n", n[1], n[3], marginal, limit
            if (marginal > limit) {
                printf "scale.sh: peak RSS per run at %d runs is %.0f B, above %d B\n", n[3], marginal, limit > "/dev/stderr"
                bad = 1
            }
            exit bad
        }' "$dir/table.txt" || status=1
    rm -rf "$dir"
    return "$status"
}

# `settle gcode` and a [gcode] sweep on the benchy (see the top of this file).
gcode() {
    [ -n "${SETTLE:-}" ] || cargo build --release --locked --bin settle
    if [ ! -x /usr/bin/time ]; then
        echo "scale.sh: needs /usr/bin/time (Debian: apt-get install time)" >&2
        exit 2
    fi
    local dir file rate_min mb_max wall_max
    dir="$(mktemp -d)"
    file="$(pwd)/gcode/prints/benchy/3DBenchy.gcode"
    rate_min="${GCODE_RATE:-5000}"
    mb_max="${GCODE_MB:-50}"
    wall_max="${SWEEP_WALL_S:-60}"
    /usr/bin/time -v "$(settle_bin)" gcode "$file" --machine printer_xy --firmware klipper \
        --shaper mzv@48 --out "$dir/gcode" > "$dir/gcode.txt" 2> "$dir/time_gcode.txt" \
        || { cat "$dir/gcode.txt" "$dir/time_gcode.txt" >&2; exit 1; }
    local simulated
    simulated="$(sed -n 's/.* | \([0-9.]*\) s of print |$/\1/p' "$dir/gcode/summary.md")"
    local status=0
    awk -v sim="$simulated" -v rate_min="$rate_min" -v mb_max="$mb_max" -F: '
        /User time/ { cpu += $2 } /System time/ { cpu += $2 }
        /Maximum resident set size/ { kb = $2 }
        /Elapsed/ { sub(/.*\): /, ""); wall = $0 }
        END {
            rate = sim / cpu
            printf "settle gcode, benchy: %.1f s of print simulated in %.2f CPU s (wall %s): %.0f simulated s per CPU s (limit %d), peak RSS %.1f MB (limit %d MB)\n", sim, cpu, wall, rate, rate_min, kb / 1024, mb_max
            bad = 0
            if (rate < rate_min) { print "scale.sh: below the speed limit" > "/dev/stderr"; bad = 1 }
            if (kb > mb_max * 1024) { print "scale.sh: over the memory limit" > "/dev/stderr"; bad = 1 }
            exit bad
        }' "$dir/time_gcode.txt" || status=1
    cat > "$dir/sweep.toml" <<TOML
name = "benchy_50"
description = "The benchy under 50 shaper settings (scripts/scale.sh gcode)."
[machine]
preset = "printer_xy"
driver_model = "linear"
[gcode]
file = "$file"
firmware = "klipper"
[shaper]
type = "mzv"
frequency_hz = 48.0
[limits]
vmax_mm_s = 500.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.1
sample_rate_hz = 2000
bands_um = [10.0]
[sweep]
"shaper.type" = ["zv", "mzv", "zvd", "ei", "2hump_ei"]
"shaper.frequency_hz" = [30.0, 34.0, 38.0, 42.0, 46.0, 50.0, 54.0, 58.0, 62.0, 66.0]
TOML
    /usr/bin/time -v "$(settle_bin)" sweep "$dir/sweep.toml" --backend modal --jobs 2 \
        --out "$dir/sweep" > "$dir/sweep.txt" 2> "$dir/time_sweep.txt" \
        || { cat "$dir/sweep.txt" "$dir/time_sweep.txt" >&2; exit 1; }
    local rows
    rows="$(($(wc -l < "$dir/sweep/runs.csv") - 1))"
    [ "$rows" -eq 50 ] || { echo "scale.sh: expected 50 runs, got $rows" >&2; exit 1; }
    awk -v wall_max="$wall_max" -F: '
        /User time/ { cpu += $2 } /System time/ { cpu += $2 }
        /Maximum resident set size/ { kb = $2 }
        /Elapsed/ { n = split($0, p, ":"); wall = p[n - 1] * 60 + p[n] }
        END {
            printf "[gcode] sweep, benchy, 50 settings, --jobs 2: wall %.1f s (limit %d s), CPU %.1f s, peak RSS %.1f MB\n", wall, wall_max, cpu, kb / 1024
            if (wall > wall_max) { print "scale.sh: the sweep took too long" > "/dev/stderr"; exit 1 }
        }' "$dir/time_sweep.txt" || status=1
    rm -rf "$dir"
    return "$status"
}

planner() {
    SETTLE_PLANNER_STATE_CASES=5000000 cargo test --release --locked -p settle-planner \
        --test any_state -- --nocapture
}

case "$what" in
    memory) memory ;;
    planner) planner ;;
    flat) flat ;;
    gcode) gcode ;;
    all) memory; flat; gcode; planner ;;
    *) echo "usage: scripts/scale.sh [memory|flat|gcode|planner|all]" >&2; exit 2 ;;
esac
