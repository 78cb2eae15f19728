#!/usr/bin/env bash
# Fuzz settle's two text inputs (scenario files, `settle plan` JSON lines) with libFuzzer
# (the cargo-fuzz layout in fuzz/) for a bounded time each. Works on stable Rust (no
# sanitizer; libFuzzer's coverage instrumentation only). A crash or panic fails
# the run and leaves the input in fuzz/artifacts/<target>/.
#
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]    (default: 60 s, all targets)
#   scripts/fuzz.sh --build-only                         (build every target, run none)
#
# The corpus grows in fuzz/corpus/<target>/ (the seeds there are committed; found inputs
# are ignored by git). Long runs: scripts/fuzz.sh 3600
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
build_only=0
if [[ "${1:-}" == --build-only ]]; then
  build_only=1
  shift
fi
secs="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scenario plan)

# libFuzzer's coverage comes from LLVM's SanitizerCoverage, added by scripts/fuzz-rustc.sh
# (cargo's rustc wrapper here) to settle's own crates only: the code under test. The other
# crates (serde, toml, nalgebra, ...) are built plainly, at optimisation level 0 (profile
# `fuzz`), which halves the cold build. No cargo-fuzz: it would be built from source first,
# and the targets need nothing but these flags (libfuzzer-sys links libFuzzer itself).
# A rustc wrapper of your own (RUSTC_WRAPPER, e.g. sccache) still runs: fuzz-rustc.sh
# calls it with the flags added.
if [[ "${RUSTC_WRAPPER:-}" != */fuzz-rustc.sh ]]; then
  export SETTLE_FUZZ_INNER_WRAPPER="${RUSTC_WRAPPER:-}"
fi
export RUSTC_WRAPPER="$PWD/../scripts/fuzz-rustc.sh"
# Keep fuzz builds apart from the workspace's (different instrumentation flags).
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}-fuzz"
# Profile `fuzz` (fuzz/Cargo.toml): settle's crates at optimisation level 1, the rest at 0.
echo "== fuzz build (${targets[*]})"
bins=()
for t in "${targets[@]}"; do bins+=(--bin "$t"); done
cargo build --profile fuzz "${bins[@]}"
[[ $build_only == 0 ]] || exit 0
for t in "${targets[@]}"; do
  echo "== fuzz $t for ${secs}s"
  mkdir -p "corpus/$t"
  log="$(mktemp)"
  status=0
  mkdir -p "artifacts/$t"
  "$CARGO_TARGET_DIR/fuzz/$t" "corpus/$t" -artifact_prefix="artifacts/$t/" \
    -max_total_time="$secs" -max_len=4096 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    >"$log" 2>&1 || status=$?
  # Show libFuzzer's summary, and everything on failure.
  if [ "$status" -ne 0 ]; then
    tail -n 60 "$log"
    echo "fuzz target $t failed (exit $status): the input is in fuzz/artifacts/$t/" >&2
    exit 1
  fi
  grep -E "^(Done|stat::number_of_executed_units|#[0-9]+[[:space:]]+DONE)" "$log" || true
  rm -f "$log"
done
