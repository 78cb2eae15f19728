#!/usr/bin/env bash
# Fuzz settle's two text inputs (scenario files, `settle plan` JSON lines) with cargo-fuzz
# (libFuzzer) for a bounded time each. Installs cargo-fuzz when missing. Works on stable
# Rust (no sanitizer; libFuzzer's coverage instrumentation only). A crash or panic fails
# the run and leaves the input in fuzz/artifacts/<target>/.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]    (default: 60 s, all targets)
#
# The corpus grows in fuzz/corpus/<target>/ (the seeds there are committed; found inputs
# are ignored by git). Long runs: scripts/fuzz.sh 3600
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
secs="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scenario plan)

if ! cargo fuzz --version >/dev/null 2>&1; then
  echo "== installing cargo-fuzz (once)"
  cargo install cargo-fuzz --locked --version 0.13.2
fi
# Keep fuzz builds apart from the workspace's (different instrumentation flags).
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}-fuzz"
# Optimised, no sanitizer; 16 codegen units instead of cargo-fuzz's default of 1 build
# the instrumented harness faster, for somewhat fewer executions a second.
build=(--sanitizer none -O --codegen-units 16)
# Build every target in one cargo invocation (their shared dependencies once, the targets'
# own code in parallel); `cargo fuzz run` below then finds them built.
echo "== fuzz build (${targets[*]})"
if [ "$#" -eq 0 ]; then
  cargo fuzz build "${build[@]}"
else
  for t in "${targets[@]}"; do cargo fuzz build "${build[@]}" "$t"; done
fi
for t in "${targets[@]}"; do
  echo "== fuzz $t for ${secs}s"
  mkdir -p "corpus/$t"
  log="$(mktemp)"
  status=0
  cargo fuzz run "${build[@]}" "$t" "corpus/$t" -- \
    -max_total_time="$secs" -max_len=4096 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    >"$log" 2>&1 || status=$?
  # Show libFuzzer's summary, and everything on failure.
  if [ "$status" -ne 0 ]; then
    tail -n 60 "$log"
    echo "fuzz target $t failed (exit $status): the input is in fuzz/artifacts/$t/" >&2
    exit 1
  fi
  grep -E "^(Done|stat::number_of_executed_units)" "$log" || true
  rm -f "$log"
done
