#!/usr/bin/env bash
# Count the code lines that simulate a plant: the simulation driver and its two sinks'
# driving code. A code line is a line before the file's first `#[cfg(test)]` that is
# neither blank nor a comment (doc comments included); tests do not count.
#
#   scripts/count-sim-lines.sh        (from anywhere)
#
# The parts, each found by its function or impl boundaries:
#   driver   src/execute/driver.rs, the whole file;
#   run      src/execute/simulate.rs from `pub struct Run` (its attributes with it) to
#            the end: a run on a plant, `Run`, `RunSink` and its `finish`;
#   job sink src/workflows/gcode/stream.rs, the block `impl Sink for Account`;
#   job loop src/workflows/gcode/stream.rs from `pub fn simulate_job` to the end: the
#            job's chunks, what a stop means for a job, the job on a plant.
# Prints each part's count, then their sum.
set -euo pipefail
cd "$(dirname "$0")/.."

# The code lines of FILE from the item whose first line matches START (its attributes
# and doc comments with it; no START: the first line) up to the end of the file, or with
# BLOCK=1 up to the first `}` at column 0 after it.
count() {
    local file=$1 start=${2:-} block=${3:-0}
    awk -v start="$start" -v block="$block" '
        /^#\[cfg\(test\)\]/ { exit }
        !on && (start == "" || $0 ~ start) { on = 1; printf "%s", attrs }
        # The attributes and doc comments just above a start go with it.
        !on && /^(#\[|\/\/\/)/ { attrs = attrs $0 "\n"; next }
        !on { attrs = "" }
        on { print }
        on && block && /^}/ { exit }
    ' "$file" | grep -c -v -E '^\s*(//|$)' || true
}

driver=$(count src/execute/driver.rs)
run=$(count src/execute/simulate.rs '^pub struct Run[<{ ]')
sink=$(count src/workflows/gcode/stream.rs '^impl Sink for Account' 1)
job=$(count src/workflows/gcode/stream.rs '^pub fn simulate_job')
for part in "driver $driver" "run $run" "job-sink $sink" "job-loop $job"; do
    printf '%-9s %4d\n' $part
done
printf '%-9s %4d\n' sum $((driver + run + sink + job))
