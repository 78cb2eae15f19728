#!/usr/bin/env bash
# The whole test suite, used verbatim by CI (.ci/run): formatting, lints, API docs, every
# test, the adversarial suite (scripts/adversarial.sh), the regression gate, every command
# of the README and the book (scripts/check-commands.sh), a fuzz smoke run and the `rerun`
# feature. Installs what it needs without root: crates from crates.io through cargo, libmujoco 3.17.0 from its PyPI
# wheel into .deps/mujoco/ (scripts/setup-mujoco.sh), the official MCAP reader from PyPI into .deps/ (scripts/mcap-python,
# for the MCAP tests); with root (or sudo), headless Chromium from Debian's `chromium`
# package when missing (scripts/browser-test.sh, for the report.html tests), and Debian's
# Slurm 22.05 and munge when missing (scripts/slurm-recipes.sh: a single-node Slurm,
# started and stopped by that phase, runs the cluster recipes of docs/guide/shards.md).
#
# Builds, and what they share (the cargo profiles are in Cargo.toml):
#   - clippy (default features), clippy with MuJoCo (only settle-sim and the crates that
#     depend on it change with the feature; everything else is reused), `cargo doc`: type
#     checking only, one set of dependency metadata for all three, in profile `ci` like the
#     test build: the build scripts and proc macros (syn, serde_derive, clap_derive, the C++
#     build of the `ruckig` dev-dependency, zstd's C library, ...) are built once, for the
#     four builds (in profile `dev` they would be built optimised, its `package."*"`
#     override outranking `build-override`, and then again for the test build). What the
#     profile changes for the lints: code under `#[cfg(debug_assertions)]` is not compiled,
#     so not linted (the workspace has none; `debug_assert!` is still checked);
#   - profile `ci` (optimised like release, without LTO or debug info): every test of the
#     workspace, then the regression gate with the `settle` binary the tests built;
#   - profile `ci-rerun` (unoptimised: the rerun test writes one small recording): the
#     `rerun` feature's build (rerun's `re_sdk`, not the `rerun` crate that wraps it) and its
#     test;
#   - scripts/fuzz.sh: in "$CARGO_TARGET_DIR-fuzz", settle's crates libFuzzer-instrumented
#     at optimisation level 1, every other crate plain at level 0 (7.7 and 9.9 CPU-minutes
#     cold instead of 12.1 and 13.5 with everything instrumented at level 1).
#   The fuzz build and the rerun build run in the background from the end of the test
#   build (see there).
# Headless Chromium's apt-get install runs in the background from the start and is waited
# for before the test run (it waits on the network and the disk while the builds use the
# CPU).
# Every phase prints the time since the start; a table of phase durations ends the output.
#
# Environment:
#   CARGO_TARGET_DIR      cargo's build directory (.ci/run keeps ~/.cache/settle/target
#                         between runs; default: target/ in the clone)
#   SETTLE_PLANNER_CASES  random planner cases (default 100000); the other planner and sim
#                         case counts (SETTLE_PLANNER_STATE_CASES, ..._EDGE_CASES,
#                         ..._MULTI_CASES, ..._BRAKED_CASES, ..._RUCKIG_CASES,
#                         ..._ORACLE_CASES, SETTLE_PATH_CASES, SETTLE_SIM_CASES) are in the
#                         README and each suite's documentation
#   SETTLE_MUJOCO=0       skip the MuJoCo backend (otherwise it is fetched when missing and
#                         every test runs with the `mujoco` feature)
#   SETTLE_FUZZ_SECONDS   fuzz smoke time per target (default 15)
#   SETTLE_SKIP_RERUN=1   skip building and testing the `rerun` feature
#   SETTLE_SKIP_BROWSER=1 skip the report's browser checks (otherwise Debian's chromium is
#                         installed with apt-get when /usr/bin/chromium is missing)
#   SETTLE_SKIP_SLURM=1   skip the Slurm recipes (skipped by themselves, with the reason,
#                         on a machine that cannot run the daemons)
#   SETTLE_MCAP_PY_VERSION  the MCAP reader's version (scripts/mcap-python)
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null; then
  echo "cargo not found: install Rust from https://rustup.rs" >&2
  exit 1
fi

# Phase timing: `phase NAME` ends the current phase and starts the next.
start_s=$(date +%s)
phase_name=""
phase_start_s=$start_s
timings=()
mmss() { printf '%d:%02d' $(($1 / 60)) $(($1 % 60)); }
phase() {
  local now_s
  now_s=$(date +%s)
  if [[ -n $phase_name ]]; then
    timings+=("$(printf '%7s  %s' "$(mmss $((now_s - phase_start_s)))" "$phase_name")")
  fi
  phase_name=${1:-}
  phase_start_s=$now_s
  if [[ -n $phase_name ]]; then
    echo "== [$(mmss $((now_s - start_s)))] $phase_name"
  fi
}
report() {
  local status=$?
  stop_background
  phase ""
  echo "== phase times (m:ss), total $(mmss $(($(date +%s) - start_s)))$([[ $status -ne 0 ]] && echo ", FAILED in the last phase")"
  printf '%s\n' "${timings[@]}"
}
# Builds started in the background (below), each in a session of its own: stopped with
# all their compilers when the script ends before their phase has waited for them.
background_pids=()
stop_background() {
  local pid
  for pid in "${background_pids[@]}"; do
    kill -- "-$pid" 2>/dev/null || true
  done
}
# `background LOG CMD...`: CMD in a session of its own, its output in LOG; its pid in $!.
background() {
  local log=$1
  shift
  setsid "$@" >"$log" 2>&1 &
  background_pids+=($!)
}
# `await PID LOG WHAT`: wait for a background build, show its output, fail if it failed.
await() {
  local status=0
  wait "$1" || status=$?
  local pid rest=()
  for pid in "${background_pids[@]}"; do
    [[ $pid == "$1" ]] || rest+=("$pid")
  done
  background_pids=("${rest[@]}")
  cat "$2"
  rm -f "$2"
  if [[ $status -ne 0 ]]; then
    echo "$3 failed (exit $status)" >&2
    exit 1
  fi
}
trap report EXIT

# report.html is checked in a real browser by tests in tests/all (html_report,
# outputs_ranking): they fail without one, so it is installed when missing, in the
# background from the start (apt-get waits on the network and the disk while the builds
# use the CPU); the test run waits for it.
browser_pid=""
if [[ "${SETTLE_SKIP_BROWSER:-0}" != 1 ]]; then
  browser_log=$(mktemp)
  scripts/browser-test.sh --install-only >"$browser_log" 2>&1 &
  browser_pid=$!
fi

features=()
if [[ "${SETTLE_MUJOCO:-1}" != 0 ]]; then
  phase "MuJoCo library (scripts/setup-mujoco.sh)"
  scripts/setup-mujoco.sh
  features=(--features mujoco)
fi

phase "cargo fmt --check"
cargo fmt --all -- --check

phase "cargo clippy (default features)"
cargo clippy --workspace --all-targets --profile ci --locked -- -D warnings
if [[ ${#features[@]} -gt 0 ]]; then
  phase "cargo clippy (with MuJoCo: rechecks what the feature changes)"
  cargo clippy --workspace --all-targets --profile ci --locked "${features[@]}" -- -D warnings
fi

phase "cargo doc --no-deps (warnings are errors)"
RUSTDOCFLAGS="${RUSTDOCFLAGS:-} -D warnings" cargo doc --workspace --no-deps --profile ci --locked "${features[@]}"

phase "the book: mdbook build docs and its internal links (scripts/check-docs.sh)"
scripts/check-docs.sh


phase "cargo test: build (profile ci)"
cargo test --workspace --profile ci --locked "${features[@]}" --no-run

# The fuzz targets' build (scripts/fuzz.sh, a target dir of its own) and the rerun
# feature's (profile ci-rerun) need nothing the phases in between make: they start now
# and share the two cores with the test run, the gate, the book's commands and Slurm,
# filling what those leave idle (a test binary's last long tests, the daemons' start,
# the fresh clones); their phases wait for them. The CPU time is the same, only idle time
# is filled; the test run itself takes about twice as long with them beside it (no test
# may depend on timing). Each runs in a session of its own, so under Linux's autogroup
# scheduling it gets an equal share of the CPU whatever its nice value. The rerun sink's
# tests are in the harness's one test binary, tests/all, or in tests/outputs_rerun.rs:
# whichever this tree has.
if [[ -f tests/all/main.rs ]]; then
  rerun_binary=(--test all)
  rerun_filter=(-- rerun)
else
  rerun_binary=(--test outputs_rerun)
  rerun_filter=()
fi
fuzz_log=$(mktemp)
background "$fuzz_log" scripts/fuzz.sh --build-only
fuzz_pid=$!
if [[ "${SETTLE_SKIP_RERUN:-0}" != 1 ]]; then
  rerun_log=$(mktemp)
  background "$rerun_log" cargo test --profile ci-rerun --locked --features rerun "${rerun_binary[@]}" --no-run
  rerun_pid=$!
fi

if [[ -n $browser_pid ]]; then
  phase "headless Chromium for the report's browser tests (waits for the install started first)"
  browser_status=0
  wait "$browser_pid" || browser_status=$?
  cat "$browser_log"
  rm -f "$browser_log"
  if [[ $browser_status -ne 0 ]]; then
    echo "scripts/browser-test.sh --install-only failed (exit $browser_status)" >&2
    exit 1
  fi
fi

phase "cargo test: run"
cargo test --workspace --profile ci --locked "${features[@]}"

phase "the adversarial suite with its generated cases (scripts/adversarial.sh)"
scripts/adversarial.sh "${features[@]}"

# The gate runs the `settle` binary the test build made (a `cargo run` would build it
# again: without the dev-dependencies, some of its dependencies' features differ).
settle_bin="${CARGO_TARGET_DIR:-target}/ci/settle"
phase "settle check: the regression gate (scenarios/ci_<name>.toml vs results/baselines/<name>.<backend>.csv)"
for scenario in scenarios/ci_*.toml; do
  name=$(basename "$scenario" .toml)
  baselines=(results/baselines/"$name".*.csv)
  if [[ ! -e ${baselines[0]} ]]; then
    echo "$scenario has no baseline: settle check $scenario --backend rapier --baseline results/baselines/$name.rapier.csv --update" >&2
    exit 1
  fi
  for baseline in "${baselines[@]}"; do
    backend=${baseline%.csv}; backend=${backend##*.}
    if [[ $backend == mujoco && ${#features[@]} -eq 0 ]]; then
      echo "(skipping $baseline: MuJoCo not built)"
      continue
    fi
    "$settle_bin" check "$scenario" --backend "$backend" --baseline "$baseline"
  done
done

phase "every command in the README and the book, in fresh clones (scripts/check-commands.sh)"
SETTLE_BIN="$settle_bin" scripts/check-commands.sh

# --- Slurm: the cluster recipes of docs/guide/shards.md ----------------------------------
# A single-node Slurm that scripts/slurm-recipes.sh starts and stops (also on failure):
# the page's job script and submissions run as written, merged outputs against unsharded
# sweeps byte for byte, a shard holding failed runs still merges. About 35 s warm.
phase "Slurm: the recipes of docs/guide/shards.md on a single-node Slurm (scripts/slurm-recipes.sh)"
SETTLE_BIN="$settle_bin" scripts/slurm-recipes.sh
# --- end of the Slurm phase ---------------------------------------------------------------

phase "fuzz smoke (scenario parser, settle plan input; scripts/fuzz.sh SECONDS for longer runs)"
await "$fuzz_pid" "$fuzz_log" "the fuzz build (scripts/fuzz.sh --build-only)"
scripts/fuzz.sh "${SETTLE_FUZZ_SECONDS:-15}"

# The rerun sink is behind a cargo feature (the SDK's build is the largest of all): built
# once, unoptimised, in the background since the test build, and its tests run.
if [[ "${SETTLE_SKIP_RERUN:-0}" != 1 ]]; then
  phase "rerun feature: build (profile ci-rerun) and test the .rrd sink"
  await "$rerun_pid" "$rerun_log" "the rerun feature's build"
  cargo test --profile ci-rerun --locked --features rerun "${rerun_binary[@]}" "${rerun_filter[@]}"
fi
