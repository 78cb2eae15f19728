#!/usr/bin/env bash
# Byte-identical outputs of two settle binaries: the proof a refactor changed nothing.
#
#   scripts/same-outputs.sh OLD_BIN NEW_BIN
#
# Runs the same commands with both binaries, each in a folder of its own (so that the
# relative paths the outputs print are the same), and compares the folders with `diff -r`:
# every file written, and every command's stdout, stderr and exit code. The commands:
#   - `settle sweep` of every scenario in scenarios/ on modal and on rapier (runs.csv,
#     summary.md, report.html, plots), one with --mcap, and one that sweeps a physical
#     machine's fields by their machine-file keys;
#   - `settle run` of a few cases with --plot and --mcap (the trace sink);
#   - `settle check` of every baseline in results/baselines/ (without --update);
#   - `settle gcode` on every print in gcode/prints/: plain, with --layers (and --mcap),
#     --versus and --config (Klipper's printer.cfg, RepRapFirmware's config.g), and a layer
#     on rapier with the full driver model; GRBL's jobs on grbl with their $$ settings (the
#     milled contour also with --layer-source markers); the
#     real Fusion 360 (GRBL), LaserWeb and Inkscape Lasertools (GRBL, laser mode), Cura
#     (Marlin), Slic3r and OrcaSlicer (Klipper) jobs in its cnc/, laser/, cura/, slic3r/
#     and orca/ folders, PrusaSlicer's binary G-code in bgcode/ (on marlin and on prusa),
#     and the Prusa MINI's Cura 5 and PrusaSlicer files in cura5/ and prusaslicer/;
#   - `settle identify` on the example recordings, `settle machine` on the presets and on
#     what identify wrote, `settle import` of the example configurations and of the real
#     ones of gcode/tests/data/real/ (a Marlin M503 reply among them; two, and the reply,
#     also under the Benchy) and a Prusa's M115/M503/M593 log (also under a job),
#     `settle tune` on
#     the tune scenarios (one also for Prusa-Firmware-Buddy), on the imported printers
#     (Klipper, RepRapFirmware, Marlin) and
#     with `--criterion klipper`;
#   - `settle validate --backend rapier`;
#   - `settle identify` on every spectrum of identify/tests/corpus/ (and its refusals),
#     `settle tune --criterion klipper` on them (per axis, with the script's options) and
#     on a raw recording;
#   - failed runs (lost steps, a fault) in a sweep, a run and a G-code job, with and
#     without --fail-on-failed-runs; a sharded sweep (K/N, a Slurm array task and a
#     Kubernetes completion index from the environment) and its merges, whole and with a
#     shard missing.
# Sweeps and tunes run with --jobs 2. Exit 0 when everything is the same, 1 with the diff.
#
# The old binary's outputs are kept and reused while neither it nor the inputs (this
# script, scenarios/, gcode/prints/, the example configurations and recordings, the
# baselines) change: a second comparison runs only the new binary.
#
# Environment:
#   SAME_OUTPUTS_DIR    where the outputs go (default target/same-outputs)
#   SAME_OUTPUTS_ONLY   an extended regular expression: only the cases whose name matches
#                       (the old side is then not cached)
set -euo pipefail
[[ $# -eq 2 ]] || { echo "usage: $0 OLD_BIN NEW_BIN" >&2; exit 2; }
cd "$(dirname "$0")/.."
root=$(pwd)
abs() { [[ $1 = /* ]] && echo "$1" || echo "$root/$1"; }
old=$(abs "$1")
new=$(abs "$2")
for b in "$old" "$new"; do
  [[ -x $b ]] || { echo "no executable at $b" >&2; exit 2; }
done
dir=$(abs "${SAME_OUTPUTS_DIR:-target/same-outputs}")
only=${SAME_OUTPUTS_ONLY:-}

S=$root/scenarios
P=$root/gcode/prints
VORON=$root/gcode/tests/data/klipper/voron/printer.cfg
MINI=$root/gcode/tests/data/rrf/mini5plus/sys/config.g
REAL=$root/gcode/tests/data/real
CORPUS=$root/identify/tests/corpus
LOST=$root/tests/shards/big_lost_steps.toml
FAULT=$root/tests/faults/blowup.toml
FIELDS=$root/tests/sweeps/machine_fields.toml

# The cases: NAME then the arguments of one settle command; `{out}` in an argument is the
# case's output folder (out/NAME, relative to the side's folder).
cases() {
  local s b p stem base
  for s in "$S"/*.toml; do
    for b in modal rapier; do
      echo "sweep-$(basename "$s" .toml)-$b sweep $s --backend $b --jobs 2 --out {out}"
    done
  done
  echo "sweep-mcap-ci_corners sweep $S/ci_corners.toml --backend modal --jobs 2 --mcap --out {out}"
  echo "sweep-machine-fields-modal sweep $FIELDS --backend modal --jobs 2 --out {out}"
  echo "sweep-machine-fields-rapier sweep $FIELDS --backend rapier --jobs 2 --out {out}"
  echo "run-quickstart-modal run $S/quickstart.toml --case 3 --backend modal --plot --mcap --out {out}/run-3.csv"
  echo "run-quickstart-rapier run $S/quickstart.toml --case 3 --backend rapier --plot --out {out}/run-3.csv"
  echo "run-ci_corners run $S/ci_corners.toml --case 3 --backend rapier --plot --out {out}/run-3.csv"
  echo "run-ci_scan run $S/ci_scan.toml --case 5 --backend modal --plot --out {out}/run-5.csv"
  echo "run-shapers run $S/shapers.toml --case 4 --backend modal --plot --out {out}/run-4.csv"
  echo "run-gcode_corner run $S/gcode_corner.toml --case 0 --backend modal --plot --out {out}/run-0.csv"
  for base in "$root"/results/baselines/*.csv; do
    stem=$(basename "$base" .csv)
    echo "check-$stem check $S/${stem%.*}.toml --baseline $base --jobs 2"
  done
  echo "identify identify $root/examples/data/raw_data_x_example.csv $root/examples/data/raw_data_y_example.csv --freq-start 30 --freq-end 90 --hz-per-sec 10 --out {out}/machine.toml"
  for p in "$P"/*.gcode; do
    stem=$(basename "$p" .gcode)
    # GRBL's jobs (a laser raster, a milled contour) run on GRBL with their $$ settings.
    grbl=
    case $stem in
      laser_raster) grbl=$P/laser_grbl_settings.txt ;;
      cnc_contour) grbl=$P/shapeoko3_grbl_settings.txt ;;
    esac
    if [[ -n $grbl ]]; then
      echo "gcode-$stem gcode $p --machine printer_xy --firmware grbl --config $grbl --out {out}"
      echo "gcode-$stem-layers gcode $p --machine printer_xy --firmware grbl --config $grbl --layers 0..1 --mcap --out {out}"
      echo "gcode-$stem-rapier gcode $p --machine printer_xy --firmware grbl --config $grbl --backend rapier --driver full --layers 1..1 --out {out}"
      continue
    fi
    # Klipper refuses the R form of G2/G3, which arc_part.gcode uses: RepRapFirmware there.
    fw=klipper cfg=$VORON
    if [[ $stem == arc_part ]]; then
      fw=rrf cfg=$MINI
    fi
    echo "gcode-$stem gcode $p --machine printer_xy --firmware $fw --shaper mzv@48 --out {out}"
    echo "gcode-$stem-layers gcode $p --machine printer_xy --firmware $fw --shaper x=mzv@52,y=ei@41/0.08 --layers 0..1 --mcap --out {out}"
    echo "gcode-$stem-versus gcode $p --machine printer_xy --firmware $fw --shaper mzv@48 --versus settle:none --maps 2 --out {out}"
    echo "gcode-$stem-config gcode $p --machine printer_xy --config $cfg --versus $fw:none --out {out}"
    echo "gcode-$stem-rrf gcode $p --machine printer_xy --config $MINI --out {out}"
    echo "gcode-$stem-marlin gcode $p --machine $S/printer_xy.toml --firmware marlin --out {out}"
    echo "gcode-$stem-rapier gcode $p --machine printer_xy --firmware $fw --backend rapier --driver full --layers 1..1 --out {out}"
  done
  # The real jobs in gcode/prints' folders (their provenance there): Fusion 360's milling
  # jobs on GRBL with the Shapeoko's settings, Cura's file on Marlin, Slic3r's (arcs, layers
  # from Z) on Klipper: two of its 240 layers.
  for p in "$P"/cnc/*.nc; do
    echo "gcode-fusion-$(basename "$p" .nc) gcode $p --machine printer_xy --firmware grbl --config $P/shapeoko3_grbl_settings.txt --out {out}"
  done
  # The real laser jobs (a LaserWeb cut, an Inkscape Lasertools fill) with the laser's
  # settings ($32=1).
  for stem in escaleras_300-02 btc_laser_qr_unbt_0001; do
    echo "gcode-laser-$stem gcode $P/laser/$stem.gcode --machine printer_xy --firmware grbl --config $P/laser_grbl_settings.txt --out {out}"
  done
  # The milled contour's layers from slicer markers only (it has none: one layer).
  echo "gcode-cnc_contour-markers gcode $P/cnc_contour.gcode --machine printer_xy --firmware grbl --config $P/shapeoko3_grbl_settings.txt --layer-source markers --out {out}"
  echo "gcode-cura-kreistest gcode $P/cura/Kreistest.gcode --machine printer_xy --firmware marlin --shaper mzv@48 --out {out}"
  echo "gcode-slic3r-benchy-arcs gcode $P/slic3r/benchy_arcs.gcode --machine printer_xy --shaper mzv@48 --layers 120..121 --out {out}"
  # OrcaSlicer's Klipper file (per-feature SET_VELOCITY_LIMIT, spiral lifts): two of its
  # 190 layers, a solid bottom layer and a wall layer.
  echo "gcode-orca-klipper gcode $P/orca/orca_slicer.gcode --machine printer_xy --firmware klipper --shaper mzv@48 --layers 8..9 --out {out}"
  # PrusaSlicer's binary G-code (heatshrink, MeatPack) for an MK4S, its end G-code's
  # Prusa-only M593 T skipped.
  echo "gcode-prusaslicer-bgcode gcode $P/bgcode/mini_cube_ps2.8.1.bgcode --machine printer_xy --firmware marlin --skip-bad-lines --out {out}"
  # The same file as Prusa's firmware reads it, every line (its M593 T among them).
  echo "gcode-prusaslicer-bgcode-prusa gcode $P/bgcode/mini_cube_ps2.8.1.bgcode --machine printer_xy --firmware prusa --out {out}"
  # Cura 5.4 for a Prusa MINI under the MINI's own M503 reply, and PrusaSlicer 2.6.1's
  # ASCII vase for the MINI as Prusa's firmware reads it.
  echo "gcode-cura5-mini gcode $P/cura5/prusa_mini_cura5.gcode --machine printer_xy --firmware marlin --config $P/prusaslicer/M503_prusa_mini.txt --out {out}"
  echo "gcode-prusaslicer-mini gcode $P/prusaslicer/prusa_mini_2.gcode --machine printer_xy --firmware prusa --out {out}"
  echo "gcode-corner-modes gcode $S/gcode_corner.gcode --machine out/identify/machine.toml --firmware settle --out {out}"
  echo "machine-printer_xy machine printer_xy"
  echo "machine-leadscrew_stage machine leadscrew_stage"
  echo "machine-scenario machine $S/scan_machines.toml"
  echo "machine-identified machine out/identify/machine.toml"
  echo "import-voron import klipper $VORON --out {out}/printer.toml"
  echo "import-voron-identified import klipper $VORON --machine out/identify/machine.toml --out {out}/printer.toml"
  echo "import-mini import rrf $MINI --out {out}/printer.toml"
  # The owners' real configurations (gcode/tests/data/real/MANIFEST.md), imported and
  # under a real job.
  for p in voronpi zippy metis vt627; do
    echo "import-real-$p import klipper $REAL/$p/printer.cfg --out {out}/printer.toml"
  done
  echo "import-real-railcore import rrf $REAL/railcore/sys/config.g --out {out}/printer.toml"
  # A Marlin owner's M503 reply (gcode/tests/data/real/marlin/PROVENANCE.md), imported.
  echo "import-marlin-ender3v2neo import marlin $REAL/marlin/ender3v2neo/m503_20241028.gcode --out {out}/printer.toml"
  # A Prusa's replies to M115, M503 and M593 (written in Buddy's formats,
  # gcode/tests/data/prusa/README.md), imported and driving a job.
  echo "import-prusa-mk4s import prusa $root/gcode/tests/data/prusa/mk4s_m115_m503_m593.txt --out {out}/printer.toml"
  echo "gcode-mini-prusa-config gcode $P/bgcode/mini_cube_b_ref.gcode --machine printer_xy --firmware prusa --config $root/gcode/tests/data/prusa/mk4s_m115_m503_m593.txt --out {out}"
  echo "gcode-benchy-real-vt627 gcode $P/benchy/3DBenchy.gcode --machine printer_xy --config $REAL/vt627/printer.cfg --out {out}"
  echo "gcode-benchy-real-railcore gcode $P/benchy/3DBenchy.gcode --machine printer_xy --config $REAL/railcore/sys/config.g --out {out}"
  # A Marlin owner's M503 reply (gcode/tests/data/real/marlin/PROVENANCE.md).
  echo "gcode-benchy-real-marlin gcode $P/benchy/3DBenchy.gcode --machine printer_xy --firmware marlin --config $REAL/marlin/ender3v2neo/m503_20241028.gcode --out {out}"
  for s in "$S"/tune_*.toml; do
    echo "tune-$(basename "$s" .toml) tune $s --jobs 2 --out {out}"
  done
  echo "tune-printer-checked tune $S/tune_printer.toml --check-on rapier --jobs 2 --out {out}"
  echo "tune-imported tune out/import-voron-identified/printer.toml --jobs 2 --out {out}"
  echo "tune-imported-rrf tune out/import-mini/printer.toml --firmware rrf --jobs 2 --out {out}"
  echo "tune-imported-marlin tune out/import-marlin-ender3v2neo/printer.toml --firmware marlin --jobs 2 --out {out}"
  echo "tune-printer-prusa tune $S/tune_printer.toml --firmware prusa --jobs 2 --out {out}"
  echo "tune-imported-prusa tune out/import-prusa-mk4s/printer.toml --jobs 2 --out {out}"
  echo "tune-klipper-criterion tune --criterion klipper $root/planner/tests/data/klipper_two_peaks.csv"
  echo "validate-rapier validate --backend rapier --out {out}/validate.md"
  # Real recordings: every corpus spectrum, one sensor column, a raw recording without its
  # test's parameters (refused), Klipper's criterion per axis and with the script's options.
  for f in "$CORPUS"/*.csv; do
    echo "identify-corpus-$(basename "$f" .csv) identify $f --figures {out} --out {out}/machine.toml"
  done
  echo "identify-corpus-column identify $CORPUS/voronpi_resonances_y_20221029_162350.csv --column y --figures {out}"
  echo "identify-corpus-column-refused identify $CORPUS/zippy_resonances_y_20220317_143943.csv --column x --figures {out}"
  echo "identify-raw-no-parameters identify $root/examples/data/raw_data_x_example.csv --figures {out}"
  echo "tune-klipper-corpus tune --criterion klipper $(echo "$CORPUS"/voronpi_resonances_[xy]_2022*.csv) --out {out}"
  echo "tune-klipper-options tune --criterion klipper $CORPUS/voronpi_resonances_y_20221029_162350.csv --shapers mzv(n=4,t=0.8),ei --max-smoothing 0.08 --scv 10"
  echo "tune-klipper-raw tune --criterion klipper $root/examples/data/raw_data_x_example.csv --out {out}"
  # Failed runs are results; shards by K/N, by a Slurm array task and by a Kubernetes
  # completion index (NAME=value before the arguments: the command's environment); merges
  # of every shard and of a set with one missing.
  echo "sweep-failed sweep $LOST --jobs 2 --out {out}"
  echo "sweep-failed-flag sweep $LOST --jobs 2 --fail-on-failed-runs --out {out}"
  echo "shard-1 sweep $LOST --shard 1/4 --out {out}"
  echo "shard-2 sweep $LOST --shard 2/4 --out {out}"
  echo "shard-3 JOB_COMPLETION_INDEX=2 SETTLE_SHARD_COUNT=4 sweep $LOST --shard kubernetes --out {out}"
  echo "shard-4 SLURM_JOB_ID=104 SLURM_ARRAY_JOB_ID=100 SLURM_ARRAY_TASK_ID=4 SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_MAX=4 SLURM_ARRAY_TASK_COUNT=4 sweep $LOST --shard slurm --fail-on-failed-runs --out {out}"
  echo "merge-missing merge out/shard-1 out/shard-2 out/shard-3 --out {out}"
  echo "merge merge out/shard-4 out/shard-2 out/shard-1 out/shard-3 --out {out}"
  echo "merge-flag merge out/shard-1 out/shard-2 out/shard-3 out/shard-4 --fail-on-failed-runs --out {out}"
  echo "run-failed run $LOST --case 7 --backend rapier --out {out}/run-7.csv"
  echo "run-failed-flag run $LOST --case 7 --backend rapier --fail-on-failed-runs --out {out}/run-7.csv"
  echo "sweep-fault sweep $FAULT --backend rapier --out {out}"
  echo "run-fault run $FAULT --case 1 --backend rapier --plot --out {out}/run-1.csv"
  echo "gcode-lost-steps gcode in/arcs.gcode --machine printer_xy --mcap --out {out}"
  echo "gcode-lost-steps-flag gcode in/arcs.gcode --machine printer_xy --fail-on-failed-runs --out {out}"
}

# Run every case with binary $1, then move the results to folder $2. Both sides run in
# the same folder ($dir/run), so that absolute paths written into outputs (the machine file
# an imported scenario names) are the same.
run_side() {
  local bin=$1 dest=$2 side=$dir/run name args a out i=0 total start
  total=$(cases | grep -cE "^(${only:-.*}) " || true)
  rm -rf "$side" "$dest"
  mkdir -p "$side/out" "$side/status" "$side/in"
  # Two 2 mm arcs at 6000 mm/s^2 after a travel: printer_xy loses steps (a failed run).
  printf 'G90\nM83\nM204 S6000\nG0 X100 Y100 F9000\nG2 X102 Y102 I2 J0 E0.1 F3000\nG3 X100 Y100 I-2 J0 E0.1\n' >"$side/in/arcs.gcode"
  while read -r name args; do
    [[ -z $only || $name =~ ^($only)$ ]] || continue
    i=$((i + 1))
    out=out/$name
    mkdir -p "$side/$out"
    local argv=() envs=()
    for a in $args; do
      if [[ ${#argv[@]} -eq 0 && $a =~ ^[A-Z_][A-Z0-9_]*= ]]; then
        envs+=("$a")
      else
        argv+=("${a//\{out\}/$out}")
      fi
    done
    start=$(date +%s)
    set +e
    (cd "$side" && env "${envs[@]}" "$bin" "${argv[@]}" </dev/null >"status/$name.stdout" 2>"status/$name.stderr")
    echo $? >"$side/status/$name.exit"
    set -e
    echo "   [$i/$total] $name: exit $(cat "$side/status/$name.exit") ($(($(date +%s) - start)) s)"
  done < <(cases)
  mv "$side" "$dest"
}

# The wall-clock times the commands report on stderr ("16 runs in 0.05 s", "48 rows, 0
# failed (2.0 s)") are no output: blanked in both sides before they are compared.
blank_times() {
  sed -i -E 's/([0-9]+ runs? in )[0-9.]+ s/\1<time> s/g; s/\([0-9.]+ s\)/(<time> s)/g' "$1"/status/*.stderr
}

# The identity of the inputs the old side's outputs depend on.
key=$( (sha256sum <"$old"; cases; find scenarios gcode/prints gcode/tests/data examples/data \
  planner/tests/data results/baselines identify/tests/corpus tests/shards tests/faults tests/sweeps -type f -print0 | sort -z | xargs -0 sha256sum) |
  sha256sum | cut -c1-16)
old_side=$dir/old-$key
if [[ -n $only ]]; then
  old_side=$dir/old-partial
fi
mkdir -p "$dir"
if [[ -n $only || ! -f $old_side/done ]]; then
  echo "== old: $old"
  run_side "$old" "$old_side"
  [[ -n $only ]] || touch "$old_side/done"
else
  echo "== old: $old (outputs kept in $old_side)"
fi
echo "== new: $new"
run_side "$new" "$dir/new"
blank_times "$old_side"
blank_times "$dir/new"
echo "== diff -r $old_side $dir/new"
if diff -r -x done "$old_side" "$dir/new" >"$dir/diff.txt"; then
  echo "same outputs: $(find "$dir/new/out" -type f | wc -l) files and $(find "$dir/new/status" -name '*.exit' | wc -l) commands' stdout, stderr and exit code"
else
  head -100 "$dir/diff.txt"
  echo "DIFFERENT (the whole diff: $dir/diff.txt)" >&2
  exit 1
fi
