#!/usr/bin/env bash
# The adversarial suite (tests/all/adversarial/): every class of hostile input, the fixed
# cases and the generated ones, each run as the `settle` binary in a sandbox under a time
# limit and a memory guard, with a table of every case's exit code, time and peak memory.
# As root it also fills a small tmpfs (the full-disk cases); otherwise those are skipped,
# and the script says so.
#
#   scripts/adversarial.sh [CARGO TEST ARGS...]   e.g. --features mujoco (scripts/test.sh
#                                                 passes its own, to reuse its test build)
#
# Environment:
#   SETTLE_ADVERSARIAL_CASES   generated cases per family (default 24)
#   SETTLE_ADVERSARIAL_SEED    their seed (default 29)
#   SETTLE_ADVERSARIAL_BIN     run the cases against another settle binary (an older
#                              build, to see which cases it fails); the test build's otherwise
#   SETTLE_ADVERSARIAL_TIME_LIMIT_S  a case's time limit (default 30)
# Fails if any case fails; prints the number of cases, the time they took and the largest
# peak memory of every settle process they ran (getrusage of the test process's children).
set -euo pipefail
cd "$(dirname "$0")/.."

skip=()
if [[ $(id -u) -ne 0 ]]; then
  echo "(not root: the full-disk cases, which mount a tmpfs, are skipped)"
  skip=(--skip adversarial::full_disk)
fi
start_s=$(date +%s)
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
# One case at a time: each case's peak memory is its own, and cases do not compete for
# the CPU against their time limit.
cargo test --workspace --profile ci --locked "$@" --test all -- \
  --include-ignored --test-threads 1 --nocapture "${skip[@]}" adversarial | tee "$log" || status=$?
cases=$(grep -Eo '^[0-9]+ cases in' "$log" | awk '{n += $1} END {print n + 0}')
peak=$(grep -Eo 'waited for so far: [0-9.]+ MiB' "$log" | tail -1 | grep -Eo '[0-9.]+ MiB' || echo "?")
ran_s=$(grep -Eo 'finished in [0-9.]+s' "$log" | grep -Eo '[0-9.]+' | awk '{s += $1} END {printf "%.1f", s}')
echo "adversarial suite: $cases cases in $ran_s s ($(($(date +%s) - start_s)) s with the build), the largest peak memory of any: $peak (limit 1024 MiB)"
exit "$status"
