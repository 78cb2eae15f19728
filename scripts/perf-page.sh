#!/usr/bin/env bash
# Regenerate docs/performance.md from measurements on this machine: the criterion benches
# (planner, four-jerk, paths, the simulation loop per backend, the sweep, MuJoCo), the
# shipped sweeps timed with /usr/bin/time, and `scripts/scale.sh memory` and `flat`. The page starts
# with the date, the commit and the machine (CPU, cores, memory, rustc, load average).
#
#   scripts/perf-page.sh            everything (about 30 minutes on a busy 2-core machine with
#                                   the bench builds; about 5 minutes of measuring)
#   scripts/perf-page.sh --quick    the cheapest subset: the sweep bench, the modal case of
#                                   the simulation bench, the any-state planner bench, the
#                                   quickstart sweep; short measurement times
#
# Environment:
#   SETTLE_MUJOCO=0   leave out the MuJoCo cases (otherwise scripts/setup-mujoco.sh fetches
#                     the library when missing and the benches run with `--features mujoco`)
#   PERF_OUT=FILE     write the page elsewhere (default docs/performance.md)
#
# Run it on a quiet machine: every figure is wall or CPU time, and a shared machine's noise
# shows in them (the page records the load average before and after).
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
case "${1:-}" in
  --quick) quick=1 ;;
  "") ;;
  *) echo "usage: scripts/perf-page.sh [--quick]" >&2; exit 2 ;;
esac
out="${PERF_OUT:-docs/performance.md}"
command -v /usr/bin/time >/dev/null || { echo "perf-page: needs /usr/bin/time (Debian: apt-get install time)" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
log="$work/benches.log"
sweeps="$work/sweeps.tsv"
: >"$log"
: >"$sweeps"

features=()
if [[ "${SETTLE_MUJOCO:-1}" != 0 && $quick == 0 ]]; then
  scripts/setup-mujoco.sh
  features=(--features mujoco)
fi

# The planner benches live in settle-planner (planner/benches/) or, in older trees, in the
# root package (benches/): call whichever package has them.
planner_pkg=settle
[[ -f planner/benches/planner.rs ]] && planner_pkg=settle-planner

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
started=$(date -u '+%Y-%m-%d %H:%M UTC')

bench() { # bench PACKAGE BENCH [FEATURES...] -- CRITERION ARGS...
  local pkg=$1 name=$2
  shift 2
  echo "== cargo bench -p $pkg --bench $name $*" | tee -a "$log"
  cargo bench --locked -p "$pkg" --bench "$name" "$@" 2>&1 | tee -a "$log"
}

if [[ $quick == 1 ]]; then
  mt=(--warm-up-time 1 --measurement-time 2)
  bench "$planner_pkg" planner -- "${mt[@]}" any_state
  bench "$planner_pkg" planner -- interleaved
  bench settle sweep -- "${mt[@]}"
  bench settle sim -- "${mt[@]}" modal
else
  mt=(--warm-up-time 1 --measurement-time 5)
  bench "$planner_pkg" planner -- "${mt[@]}"
  # The bench's own interleaved comparison runs only without a filter or with one naming
  # it, and it reads option values as filters: call it on its own.
  bench "$planner_pkg" planner -- interleaved
  # Iterations of 0.7 s (four-jerk, any state) and 1.8 s (brute-force contour error):
  # criterion's minimum of 10 samples instead of 100 keeps each under half a minute.
  bench "$planner_pkg" fourjerk -- "${mt[@]}" --sample-size 10
  bench "$planner_pkg" path -- "${mt[@]}" --sample-size 10
  bench settle sweep -- "${mt[@]}"
  bench settle-identify identify -- "${mt[@]}"
  bench settle sim "${features[@]}" -- "${mt[@]}"
  if [[ ${#features[@]} -gt 0 ]]; then
    bench settle mujoco "${features[@]}" -- "${mt[@]}"
  fi
fi

echo "== settle sweep, timed"
cargo build --release --locked -p settle --bin settle 2>&1 | tail -1
bin="${CARGO_TARGET_DIR:-target}/release/settle"
timed() { # timed LABEL ARGS... : one line of sweeps.tsv: label, wall s, user+sys s, peak MB, summary line
  local label=$1
  shift
  /usr/bin/time -f '%e %U %S %M' -o "$work/time" "$bin" "$@" --out "$work/out" >"$work/stdout" 2>&1 ||
    { cat "$work/stdout" >&2; echo "perf-page: $label failed" >&2; exit 1; }
  read -r wall user sys kb <"$work/time"
  printf '%s\t%s\t%s\t%s\t%s\n' "$label" "$wall" \
    "$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')" \
    "$((kb / 1024))" "$(grep -m1 '^wrote' "$work/stdout" | sed 's/.*(//; s/)$//')" >>"$sweeps"
  rm -rf "$work/out"
}
timed "quickstart, rapier (16 runs)" sweep scenarios/quickstart.toml
timed "quickstart, modal (16 runs)" sweep scenarios/quickstart.toml --backend modal
if [[ $quick == 0 ]]; then
  timed "printer_xy, rapier, full driver (8 runs)" sweep scenarios/printer_xy.toml
  timed "corner_angles, rapier (104 runs)" sweep scenarios/corner_angles.toml
  timed "scan_steps, rapier, full driver (80 runs)" sweep scenarios/scan_steps.toml
  timed "scale_10k, modal (10,000 runs)" sweep scenarios/scale_10k.toml --backend modal
  echo "== scripts/scale.sh memory" | tee -a "$log"
  scripts/scale.sh memory 2>&1 | tee -a "$log"
  echo "== scripts/scale.sh flat" | tee -a "$log"
  SETTLE="$bin" scripts/scale.sh flat 2>&1 | tee -a "$log"
fi

load_after=$(cut -d' ' -f1-3 /proc/loadavg)
commit=$(git rev-parse --short=12 HEAD)
git diff --quiet HEAD -- . ':!docs/performance.md' || commit="$commit (with uncommitted changes)"
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
mem=$(awk '/MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo)
mode="full run (every bench, the shipped sweeps, scripts/scale.sh memory and flat)"
[[ $quick == 1 ]] && mode="quick run (scripts/perf-page.sh --quick): the cheapest subset only; regenerate with scripts/perf-page.sh for every bench"
[[ $quick == 0 && ${#features[@]} -eq 0 ]] && mode="$mode, without MuJoCo"

export PERF_DATE="$started" PERF_COMMIT="$commit" PERF_CPU="$cpu" PERF_CORES="$(nproc)" \
  PERF_MEM="$mem" PERF_RUSTC="$(rustc --version)" PERF_MODE="$mode" \
  PERF_LOAD="$load_before before, $load_after after (1, 5 and 15 minutes)"
python3 - "$log" "$sweeps" "$out" <<'EOF'
"""Render the page from the bench log (criterion's text output plus what the benches
print) and the timed sweeps."""
import os, re, sys

log_path, sweeps_path, out_path = sys.argv[1:]
env = os.environ

ABOUT = {
    "planner": "Planning time of settle, rsruckig and the official Ruckig (C++) on the same "
    "seeded random problems: 1,000 one-axis problems from any state to any target, the same "
    "states as 333 three-axis time-synchronised problems, and 1,000 rest-to-rest moves. "
    "Before timing, the bench checks that settle's durations equal rsruckig's (shorter only "
    "after a brake). Target: settle at most 0.5x rsruckig. On a shared machine the groups "
    "drift with the load between one function and the next; the `interleaved` lines time "
    "settle and rsruckig in alternating batches and are the figure to compare.",
    "fourjerk": "The four-jerk planner (any state and rest to rest, four independent jerks) "
    "and the TMC4361A S-ramp, 1,000 seeded problems each.",
    "path": "A 1,000-segment random polyline planned with look-ahead and jerk-limited "
    "blends, and contour-error queries of 10,000 samples near it (bounding-box tree, with "
    "the hint, and brute force on 1,000 samples).",
    "sweep": "One quickstart run on the modal backend (plan, exact simulation of a 10 mm "
    "S-curve and the 0.5 s window at 10 kHz, streaming metrics) and the 16-run quickstart "
    "sweep on one thread.",
    "identify": "A 130 s Klipper raw resonance test at 3.2 kHz (419,200 samples, three axes, "
    "19.8 MB of CSV, two modes): parsing the text, and identifying (Klipper's PSD at a "
    "quarter-segment hop, the motion's direction, the sweep fit with model selection and "
    "uncertainties), on one thread. Target: parse and identify under 1 s.",
    "sim": "The simulation loop per backend at its validated default step: the printer_xy "
    "preset, both axes simulated, a 10 mm S-curve on Y and the 0.5 s window at 10 kHz "
    "(0.649 s simulated per run), metrics streaming. *x real time* is simulated seconds per "
    "wall second; the bench then times each case on its own thread's CPU clock (the lines "
    "below the table), the per-core figure on a shared machine. Targets per core: modal at "
    "least 2000x, rapier and MuJoCo at least 20x.",
    "mujoco": "MuJoCo stepped once per 10 kHz sample through the plant (the path a "
    "recording takes): a printer-like axis (modes 48, 158 and 282 Hz) and one 40 Hz mode, a "
    "100 mm S-curve plus 0.2 s of settling.",
}
# Seconds simulated per criterion "element", for the groups that declare a throughput.
ELEMENT_S = {"printer_xy_10mm_scurve_y": 1e-6, "mujoco": 1e-3}
# Seconds simulated per iteration of benches without a declared throughput: the
# quickstart's 10 mm S-curve is a 149.3 ms move and the 0.5 s window.
ITER_S = {"quickstart_run_10mm_scurve": 0.6493}
TIME_UNIT = {"ps": 1e-12, "ns": 1e-9, "µs": 1e-6, "us": 1e-6, "ms": 1e-3, "s": 1.0}
ELEM_UNIT = {"elem/s": 1.0, "Kelem/s": 1e3, "Melem/s": 1e6, "Gelem/s": 1e9}
NOTE = re.compile(r"interleaved|durations vs|real time per CPU second|simulated per run|"
                  r"scale\.sh:|Maximum resident|Elapsed")


def fmt_time(x):
    for unit, f in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if x >= f:
            return f"{x / f:.4g} {unit}"
    return f"{x / 1e-12:.4g} ps"


sections, current, last_name = [], None, None
for raw in open(log_path, encoding="utf-8", errors="replace"):
    line = raw.rstrip()
    m = re.match(r"== (cargo bench -p \S+ --bench (\S+).*|scripts/scale\.sh (memory|flat))$", line)
    if m:
        bench = m.group(2) or ("scale_flat" if m.group(3) == "flat" else "scale")
        current = next((s for s in sections if s["bench"] == bench), None)
        if current is None:
            current = {"cmds": [], "bench": bench, "rows": [], "notes": []}
            sections.append(current)
        current["cmds"].append(m.group(1))
        continue
    if current is None or not line.strip():
        continue
    if current["bench"] == "scale_flat":
        # scale.sh flat prints its table as markdown rows.
        if line.startswith("|"):
            current["notes"].append(line.strip())
        continue
    if "time:" in line:
        name = line.split("time:")[0].strip() or last_name
        vals = re.findall(r"([0-9.]+) (ps|ns|µs|us|ms|s)\b", line.split("time:")[1])
        if len(vals) == 3:
            t = [float(v) * TIME_UNIT[u] for v, u in vals]
            current["rows"].append({"name": name, "time": t, "thrpt": None})
        continue
    if "thrpt:" in line and current["rows"]:
        vals = re.findall(r"([0-9.]+) ([KMG]?elem/s)", line)
        if len(vals) == 3:
            current["rows"][-1]["thrpt"] = float(vals[1][0]) * ELEM_UNIT[vals[1][1]]
        continue
    if NOTE.search(line):
        if line.strip() not in current["notes"]:
            current["notes"].append(line.strip())
        continue
    if not line.startswith((" ", "Benchmarking", "Found", "Warning", "warning", "Compiling",
                            "Finished", "Running", "Gnuplot", "change", "No change",
                            "Performance", "Change")):
        last_name = line.strip()

out = []
w = out.append
w("# Performance")
w("")
w(f"Generated by `scripts/perf-page.sh` on {env['PERF_DATE']} from commit "
  f"`{env['PERF_COMMIT']}`: a {env['PERF_MODE']}.")
w("")
w("| machine | |")
w("|---|---|")
w(f"| CPU | {env['PERF_CPU']} |")
w(f"| cores | {env['PERF_CORES']} |")
w(f"| memory | {env['PERF_MEM']} |")
w(f"| rustc | {env['PERF_RUSTC']} |")
w(f"| load average | {env['PERF_LOAD']} |")
w("")
w("Every figure is a time measured on the machine above; on a machine shared with other "
  "work the same code reads up to tens of percent apart between runs. Criterion's "
  "estimate is the middle of its confidence interval, given in brackets.")
busy = max(float(x) for x in env["PERF_LOAD"].replace(",", " ").split()[:7]
           if re.fullmatch(r"[0-9.]+", x))
if busy > float(env["PERF_CORES"]):
    w("")
    w(f"**The machine was busy while this page was measured** (load average up to "
      f"{busy:g} on {env['PERF_CORES']} cores): other work shared the cores, so the times "
      f"are upper bounds and the ratios noisier than on a quiet machine.")
for sec in sections:
    if sec["bench"] == "scale":
        continue
    w("")
    w(f"## `{sec['bench']}`")
    w("")
    w(ABOUT.get(sec["bench"], ""))
    w("")
    w("```text")
    out.extend(sec["cmds"])
    w("```")
    def real_time(r):
        group = r["name"].split("/")[0]
        if r["thrpt"] is not None and group in ELEMENT_S:
            return f"{r['thrpt'] * ELEMENT_S[group]:.0f}x"
        if r["name"] in ITER_S:
            return f"{ITER_S[r['name']] / r['time'][1]:.0f}x"
        return None

    if sec["rows"]:
        rt = any(real_time(r) for r in sec["rows"])
        w("")
        w("| bench | time per iteration | interval |" + (" x real time |" if rt else ""))
        w("|---|---:|---|" + ("---:|" if rt else ""))
        for r in sec["rows"]:
            lo, mid, hi = r["time"]
            cell = f" {real_time(r) or ''} |" if rt else ""
            w(f"| `{r['name']}` | {fmt_time(mid)} | [{fmt_time(lo)}, {fmt_time(hi)}] |{cell}")
    if sec["notes"]:
        w("")
        w("Printed by the bench:")
        w("")
        w("```text")
        out.extend(sec["notes"])
        w("```")

rows = [l.rstrip("\n").split("\t") for l in open(sweeps_path, encoding="utf-8") if l.strip()]
if rows:
    w("")
    w("## Sweeps")
    w("")
    w("The shipped scenarios through the release binary (`settle sweep SCENARIO --out DIR`, "
      "all cores), timed with `/usr/bin/time`: wall time, CPU time (user + system) and peak "
      "memory, planning, simulation and every output included.")
    w("")
    w("| sweep | wall (s) | CPU (s) | peak RSS (MB) | settle's own report |")
    w("|---|---:|---:|---:|---|")
    for label, wall, cpu, mb, own in rows:
        w(f"| {label} | {wall} | {cpu} | {mb} | {own} |")
scale = [s for s in sections if s["bench"] == "scale"]
if scale:
    w("")
    w("## Memory at scale")
    w("")
    w("`scripts/scale.sh memory`: a 10,000-run sweep (`scenarios/scale_10k.toml`, modal "
      "backend), failing above 200 MB peak RSS.")
    w("")
    w("```text")
    out.extend(scale[0]["notes"])
    w("```")
flat = [s for s in sections if s["bench"] == "scale_flat"]
if flat:
    w("")
    w("## Time and memory per run at scale")
    w("")
    w("`scripts/scale.sh flat`: `scenarios/scale_10k.toml` with 1,000, 10,000 and 100,000 "
      "runs (modal backend, all cores, every output written), timed with `/usr/bin/time`. "
      "CPU time is user + system (the wall time of a shared machine says little). The check "
      "fails if the CPU time per run at 100,000 runs is more than 20 % above that at 1,000 "
      "or 10,000 runs, or the peak RSS per run grows by more than 20 % from 10,000 to "
      "100,000.")
    w("")
    out.extend(flat[0]["notes"])
w("")
w("Not measured here: `scripts/scale.sh planner` (1e7 random planner problems against "
  "rsruckig; a correctness check at scale that takes minutes) and the test suite's own "
  "time.")
open(out_path, "w", encoding="utf-8").write("\n".join(out) + "\n")
print(f"perf-page: wrote {out_path}")
EOF
