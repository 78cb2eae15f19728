#!/usr/bin/env bash
# The report's real-browser tests (tests/all/html_report.rs and the sweep report in
# tests/all/outputs_ranking.rs): installs headless Chromium from
# Debian's `chromium` package when /usr/bin/chromium is missing (needs root and apt), then
# runs the tests. Extra arguments go to `cargo test`; `--install-only` installs the browser
# and stops (scripts/test.sh does that before its test phase, which runs these tests with
# every other).
#
# Environment:
#   SETTLE_SKIP_BROWSER=1  skip the browser checks (they print a notice instead)
#   SETTLE_HTML_ROWS       rows of the generated large table (default 6000; try 100000)
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ "${SETTLE_SKIP_BROWSER:-0}" != 1 && ! -x /usr/bin/chromium ]]; then
  echo "== installing chromium (apt-get)"
  sudo=()
  if [[ $(id -u) -ne 0 ]]; then
    if ! command -v sudo >/dev/null; then
      echo "/usr/bin/chromium is missing and this is not root: run 'apt-get install -y chromium' as root or set SETTLE_SKIP_BROWSER=1" >&2
      exit 1
    fi
    sudo=(sudo)
  fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq chromium >/dev/null
fi
if [[ "${1:-}" == --install-only ]]; then
  exit 0
fi
echo "== cargo test --test all html_report outputs_ranking"
cargo test --locked --test all "$@" -- --nocapture html_report outputs_ranking
