#!/usr/bin/env bash
# The whole test suite: formatting, lints, every test, a fuzz smoke run. Installs what it
# needs without root: crates from crates.io through cargo, libmujoco 3.17.0 from its PyPI
# wheel into .deps/mujoco/ (scripts/setup-mujoco.sh), cargo-fuzz, the official MCAP reader
# from PyPI into .deps/ (scripts/mcap-python, for the MCAP tests). Used verbatim by CI
# (.ci/run).
#
# Environment:
#   SETTLE_PLANNER_CASES  random planner cases (default 100000; see the README for the rest)
#   SETTLE_SIM_CASES      random modal-plant cases (default 2000)
#   SETTLE_MUJOCO=0       skip the MuJoCo backend (otherwise it is fetched when missing and
#                         every test runs with the `mujoco` feature)
#   SETTLE_FUZZ_SECONDS   fuzz smoke time per target (default 15)
#   SETTLE_SKIP_RERUN=1   skip building and testing the `rerun` feature
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v cargo >/dev/null; then
  echo "cargo not found: install Rust from https://rustup.rs" >&2
  exit 1
fi

features=()
if [[ "${SETTLE_MUJOCO:-1}" != 0 ]]; then
  echo "== MuJoCo library (scripts/setup-mujoco.sh)"
  scripts/setup-mujoco.sh
  features=(--features mujoco)
fi

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy (default features, then with MuJoCo)"
cargo clippy --workspace --all-targets --locked -- -D warnings
if [[ ${#features[@]} -gt 0 ]]; then
  cargo clippy --workspace --all-targets --locked "${features[@]}" -- -D warnings
fi
echo "== cargo test (release: the property suites are numeric-heavy)"
cargo test --workspace --release --locked "${features[@]}"
echo "== settle check: the CI regression gate (scenarios/ci_<name>.toml vs results/baselines/<name>.<backend>.csv)"
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
    cargo run --release --locked --quiet "${features[@]}" -- check "$scenario" --backend "$backend" --baseline "$baseline"
  done
done
echo "== fuzz smoke (scenario parser, settle plan input; scripts/fuzz.sh SECONDS for longer runs)"
scripts/fuzz.sh "${SETTLE_FUZZ_SECONDS:-15}"
# The rerun sink is behind a cargo feature (the SDK's cold build is ~14 CPU-minutes): build
# and test it once here. SETTLE_SKIP_RERUN=1 skips it (e.g. for quick local runs).
if [ "${SETTLE_SKIP_RERUN:-0}" != 1 ]; then
  echo "== rerun feature: build once and test the .rrd sink"
  cargo test --release --locked --features rerun --test outputs_rerun
fi
