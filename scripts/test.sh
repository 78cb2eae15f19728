#!/usr/bin/env bash
# The whole test suite: formatting, lints, every test. Installs nothing system-wide; what
# it needs comes from crates.io through cargo. Used verbatim by CI (.ci/run).
#
# Environment:
#   SETTLE_PLANNER_CASES  random planner cases (default 100000)
#   SETTLE_SIM_CASES      random modal-plant cases (default 2000)
#   SETTLE_MUJOCO=0       skip the MuJoCo backend (otherwise scripts/setup-mujoco.sh fetches
#                         libmujoco into .deps/mujoco/ when missing, and its tests run)
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null; then
  echo "cargo not found: install Rust from https://rustup.rs" >&2
  exit 1
fi

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy"
cargo clippy --workspace --all-targets --locked -- -D warnings
echo "== cargo test (release: the property suites are numeric-heavy)"
cargo test --workspace --release --locked
if [[ "${SETTLE_MUJOCO:-1}" != 0 ]]; then
  echo "== MuJoCo backend (cargo feature mujoco)"
  scripts/setup-mujoco.sh
  cargo clippy --workspace --all-targets --locked --features mujoco -- -D warnings
  cargo test -p settle-sim --release --locked --features mujoco --test 'mujoco*'
fi
