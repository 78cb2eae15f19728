#!/usr/bin/env bash
# Fuzz settle's two text inputs (scenario files, `settle plan` JSON lines) with libFuzzer
# (the cargo-fuzz layout in fuzz/) for a bounded time each. Works on stable Rust (no
# sanitizer; libFuzzer's coverage instrumentation only). A crash or panic fails
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

# libFuzzer's coverage comes from LLVM's SanitizerCoverage (the flags libFuzzer's documentation
# names: inline 8-bit counters, the PC table, compare tracing), applied by rustc to every crate
# built for the target. Building for the host triple given explicitly keeps build scripts
# and proc macros uninstrumented. No cargo-fuzz: it would be built from source first, and
# the targets need nothing but these flags (libfuzzer-sys links libFuzzer itself).
host=$(rustc -vV | sed -n 's/^host: //p')
export RUSTFLAGS="${RUSTFLAGS:-} --cfg fuzzing -Cpasses=sancov-module \
  -Cllvm-args=-sanitizer-coverage-level=4 -Cllvm-args=-sanitizer-coverage-inline-8bit-counters \
  -Cllvm-args=-sanitizer-coverage-pc-table -Cllvm-args=-sanitizer-coverage-trace-compares"
# Keep fuzz builds apart from the workspace's (different instrumentation flags).
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}-fuzz"
# Profile `fuzz` (fuzz/Cargo.toml): optimisation level 1, otherwise a release build: a smoke
# run needs coverage, and opt-level 3 costs most of the build.
echo "== fuzz build (${targets[*]})"
bins=()
for t in "${targets[@]}"; do bins+=(--bin "$t"); done
cargo build --profile fuzz --target "$host" "${bins[@]}"
for t in "${targets[@]}"; do
  echo "== fuzz $t for ${secs}s"
  mkdir -p "corpus/$t"
  log="$(mktemp)"
  status=0
  mkdir -p "artifacts/$t"
  "$CARGO_TARGET_DIR/$host/fuzz/$t" "corpus/$t" -artifact_prefix="artifacts/$t/" \
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
