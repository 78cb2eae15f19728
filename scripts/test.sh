#!/usr/bin/env bash
# The whole test suite: formatting, lints, every test. Installs nothing system-wide; what
# it needs comes from crates.io through cargo. Used verbatim by CI (.ci/run).
#
# Environment:
#   SETTLE_PLANNER_CASES  random planner cases (default 100000)
#   SETTLE_SIM_CASES      random modal-plant cases (default 2000)
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
echo "== settle check: the CI regression gate (scenarios/ci_*.toml vs results/baselines/<name>.csv)"
for scenario in scenarios/ci_*.toml; do
  cargo run --release --locked --quiet -- check "$scenario" --baseline "results/baselines/$(basename "$scenario" .toml).csv"
done
