#!/usr/bin/env bash
# The report's real-browser tests (tests/all/html_report.rs and the sweep report in
# tests/all/outputs_ranking.rs): installs headless Chromium from
# Debian's `chromium` package when /usr/bin/chromium is missing (needs root and apt), then
# runs the test. Extra arguments go to `cargo test`.
#
# Environment:
#   SETTLE_SKIP_BROWSER=1  skip the browser checks (they print a notice instead)
#   SETTLE_HTML_ROWS       rows of the generated large table (default 6000; try 100000)
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ "${SETTLE_SKIP_BROWSER:-0}" != 1 && ! -x /usr/bin/chromium ]]; then
  echo "== installing chromium (apt-get)"
  if [[ $(id -u) -ne 0 ]]; then
    echo "/usr/bin/chromium is missing and this is not root: run 'sudo apt-get install -y chromium' or set SETTLE_SKIP_BROWSER=1" >&2
    exit 1
  fi
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
echo "== cargo test --test all html_report outputs_ranking"
cargo test --locked --test all "$@" -- --nocapture html_report outputs_ranking
