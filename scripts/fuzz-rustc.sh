#!/usr/bin/env bash
# RUSTC_WRAPPER for scripts/fuzz.sh (cargo runs it as `fuzz-rustc.sh rustc ARGS...`):
# libFuzzer's coverage instrumentation (LLVM's SanitizerCoverage with the flags libFuzzer's
# documentation names: inline 8-bit counters, the PC table, compare tracing) and
# `--cfg fuzzing` for settle's own crates only (CARGO_PKG_NAME `settle` or `settle-*`),
# not for their build scripts; every other crate is compiled as cargo asks. A wrapper the
# user had set (scripts/fuzz.sh passes it as SETTLE_FUZZ_INNER_WRAPPER, e.g. sccache) runs
# the compiler in both cases.
set -euo pipefail
inner="${SETTLE_FUZZ_INNER_WRAPPER:-}"
if [[ -n $inner ]]; then
  set -- "$inner" "$@"
fi
case "${CARGO_PKG_NAME:-}" in
  settle | settle-*)
    case " $* " in
      *" --crate-name build_script_"*) ;;
      *)
        exec "$@" --cfg fuzzing -Cpasses=sancov-module \
          -Cllvm-args=-sanitizer-coverage-level=4 \
          -Cllvm-args=-sanitizer-coverage-inline-8bit-counters \
          -Cllvm-args=-sanitizer-coverage-pc-table \
          -Cllvm-args=-sanitizer-coverage-trace-compares
        ;;
    esac
    ;;
esac
exec "$@"
