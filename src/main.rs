//! The `settle` command: arguments, a call to a workflow of the library
//! (`settle::workflows`), printing, and exit codes (docs/reference/cli.md):
//!
//! - 0: the command finished and wrote every output. Runs that failed physically (lost
//!   steps, a simulation fault) are results, not failures of the command: recorded with
//!   their reasons (runs.csv, summary.md, stderr) and still exit 0, so that a scheduler's
//!   `afterok` dependency (Slurm) or a Job's success (Kubernetes) goes on to the merge;
//!   `--fail-on-failed-runs` turns them into exit 1;
//! - 1: the command failed: a regression found by `settle check`, a failed `settle
//!   validate` check, an I/O failure (with `--fail-on-failed-runs`, also failed runs);
//! - 2: bad input or usage, nothing run;
//! - 130: an interrupted sweep (its finished runs kept for `--resume`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use settle::Error;
use settle::execute::interrupt;
use settle::spec::backend::Backend;
use settle::workflows::scheduler::ShardArg;
use settle::workflows::{self, Exit, Report};

fn parse_backend(s: &str) -> Result<Backend, String> {
    Backend::parse(s).ok_or_else(|| format!("unknown backend `{s}`; allowed: {}", Backend::ALLOWED))
}

fn parse_firmware(s: &str) -> Result<settle_planner::firmware::Firmware, String> {
    settle_gcode::job::parse_firmware(s).map_err(|e| e.to_string())
}

fn parse_driver(s: &str) -> Result<settle_sim::DriverMode, String> {
    settle_sim::DriverMode::parse(s).ok_or_else(|| {
        format!(
            "unknown driver model `{s}`; allowed: {}",
            settle_sim::DriverMode::ALLOWED
        )
    })
}

#[derive(Parser, Debug)]
#[command(
    name = "settle",
    version,
    about = "Which motion profile makes my machine settle fastest, and by how much?",
    after_help = "Example:\n  settle sweep scenarios/quickstart.toml\n  (writes results/quickstart/runs.csv and summary.md)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run every point of a scenario's sweep and write runs.csv, summary.md, report.html and plots.
    #[command(
        after_help = "Example:\n  settle sweep scenarios/quickstart.toml --out /tmp/qs --jobs 2"
    )]
    Sweep {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// Output folder [default: results/<scenario name>/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads, at most 1024 [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=i64::from(settle::execute::pool::MAX_JOBS)))]
        jobs: Option<u16>,
        /// Simulation backend: modal (exact, linear driver only), rapier, mujoco.
        #[arg(long, default_value = "rapier", value_parser = parse_backend)]
        backend: Backend,
        #[command(flatten)]
        outputs: OutputFlags,
        /// Run only shard K of N (1-based: runs i with i % N == K-1) into
        /// DIR [default: results/<scenario name>/shard-K-of-N/]; combine with `settle merge`.
        /// `slurm`: K and N of this Slurm job array task (SLURM_ARRAY_TASK_ID, _MIN, _STEP,
        /// _COUNT); `kubernetes`: of this Indexed Job pod (JOB_COMPLETION_INDEX + 1 of
        /// SETTLE_SHARD_COUNT, which the Job spec sets to its completions).
        #[arg(long, value_name = "K/N|slurm|kubernetes")]
        shard: Option<ShardArg>,
        /// Continue an interrupted sweep: keep the runs in OUT/journal.csv, run the rest.
        #[arg(long)]
        resume: bool,
        /// Overwrite the results of an earlier sweep in OUT (refused without it).
        #[arg(long, conflicts_with = "resume")]
        force: bool,
        #[command(flatten)]
        failed_runs: FailedRunsFlag,
    },
    /// Check every backend against the closed form and against each other; print a table.
    #[command(
        after_help = "Example:\n  settle validate\n  settle validate --backend rapier --out validate.md\n\nExit code 1 when a check is past its threshold (frequency 0.5 %, residual 2 %,\nengines 3 %, numerical damping 10 % of the physical)."
    )]
    Validate {
        /// Only this backend (with the modal reference) [default: every available one].
        #[arg(long, value_parser = parse_backend)]
        backend: Option<Backend>,
        /// Also write the table as Markdown to this file.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Rerun a scenario and compare every metric of every run with a committed baseline.
    #[command(
        after_help = "Exit status: 0 when every value is within the tolerance, 1 (with a table of run,\nmetric, baseline, now, delta%) when any is not, 2 on bad input.\n\nAny change beyond the tolerance fails, worse or better: settle is deterministic, so a\nchange means behaviour changed, and --update makes accepting it a reviewed commit.\n\nExample:\n  settle check scenarios/ci_quickstart.toml --backend modal --baseline results/baselines/ci_quickstart.modal.csv\n  settle check scenarios/ci_quickstart.toml --backend modal --baseline results/baselines/ci_quickstart.modal.csv --update"
    )]
    Check {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// The baseline: a runs.csv written by settle (results/baselines/<name>.csv).
        #[arg(long)]
        baseline: PathBuf,
        /// Relative tolerance in percent (numbers closer than this to the baseline pass).
        #[arg(long, value_name = "PCT", allow_hyphen_values = true, default_value_t = workflows::check::DEFAULT_TOLERANCE_PCT)]
        tolerance: f64,
        /// Absolute floor of lengths in um (`_um` columns; `_mm` ones in their unit): a
        /// change smaller than this is no change, whatever its percentage.
        #[arg(long, value_name = "UM", default_value_t = workflows::check::DEFAULT_FLOOR_UM)]
        floor_um: f64,
        /// Rewrite the baseline with this run's values (on purpose: commit the diff).
        #[arg(long)]
        update: bool,
        /// Pass when every change is an improvement of a settling metric.
        #[arg(long)]
        allow_improvements: bool,
        /// Simulation backend: modal, rapier, mujoco [default: the one the baseline was made
        /// with (its `backend` column); rapier for a new baseline].
        #[arg(long, value_parser = parse_backend)]
        backend: Option<Backend>,
        /// Worker threads, at most 1024 [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=i64::from(settle::execute::pool::MAX_JOBS)))]
        jobs: Option<u16>,
    },
    /// Combine the folders of a sharded sweep into the outputs of an unsharded one.
    #[command(
        after_help = "Example:\n  settle sweep scenarios/quickstart.toml --shard 1/2\n  settle sweep scenarios/quickstart.toml --shard 2/2\n  settle merge results/quickstart/shard-1-of-2 results/quickstart/shard-2-of-2\n  (writes results/quickstart/runs.csv, summary.md and plots/, as an unsharded sweep)"
    )]
    Merge {
        /// The shard folders (each written by `settle sweep --shard K/N`), in any order.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output folder [default: results/<scenario name>/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Overwrite the results of an earlier sweep in the output folder (refused
        /// without it).
        #[arg(long)]
        force: bool,
        #[command(flatten)]
        failed_runs: FailedRunsFlag,
    },
    /// Plan motion problems: JSON lines on stdin, one profile (or error) per line on stdout.
    #[command(
        after_help = "Example:\n  echo '{\"p0\":[0],\"pf\":[1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10],\"sync\":\"time\"}' | settle plan\n\nInput keys (arrays, one value per axis): p0 v0 a0 pf vf af vmax amax jmax [vmin amin];\n\"sync\": time|phase|none, \"kind\": scurve|trapezoid, \"interface\": position|velocity.\nOutput: {\"duration\":..,\"axes\":[{\"p0\",\"v0\",\"a0\",\"segments\":[[duration,jerk],..]}]}\n(a constant-acceleration segment is [duration,0,accel]) or {\"error\":\"..\"}."
    )]
    Plan {
        /// Worker threads, at most 1024 [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=i64::from(settle::execute::pool::MAX_JOBS)))]
        jobs: Option<u16>,
    },
    /// Search the profile parameters (kind, jerk, PVT asymmetry, BOW1..4, input shaper)
    /// that minimise move-and-settle on the scenario's machine; export the winner.
    #[command(
        after_help = "Example:\n  settle tune scenarios/tune_printer.toml --check-on rapier\n  (writes results/tune_printer-tune/tune.md, candidates.csv, pareto.svg/png,\n  klipper.cfg, rrf.g and tmc4361a.txt)\n  settle tune printer_import.toml --firmware klipper --frequency-tolerance 5\n  settle tune --criterion klipper calibration_data_x.csv\n  (Klipper's own choice, as scripts/calibrate_shaper.py prints it)"
    )]
    Tune {
        /// The scenario file (TOML) with [move], [limits] and an optional [tune] table; with
        /// `--criterion klipper`, one or more Klipper resonance CSVs (processed or raw; the
        /// files of one axis, named like calibration_data_x_*.csv, are combined).
        #[arg(required = true, num_args = 1..)]
        scenario: Vec<PathBuf>,
        /// Only candidates this firmware runs: klipper, marlin, prusa, rrf, tmc4361a, any
        /// [default: the scenario's `[tune] firmware`, else any].
        #[arg(long)]
        firmware: Option<String>,
        /// Score shaped candidates on their worst case with the shaper this many percent
        /// off its frequency either way [default: `[tune] frequency_tolerance_pct`, else 0];
        /// a machine whose modes carry `frequency_sigma_hz` is checked over the wider of
        /// this and their 2-sigma band.
        #[arg(long, value_name = "PCT", allow_hyphen_values = true)]
        frequency_tolerance: Option<f64>,
        /// `settle` (simulate move-and-settle on the machine) or `klipper` (Klipper's
        /// calibrate_shaper.py choice on a processed resonance CSV).
        #[arg(long, default_value = "settle", value_parser = ["settle", "klipper"])]
        criterion: String,
        /// Output folder [default: results/<scenario name>-tune/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Backend of the search [default: modal, exact and fast; needs the linear driver].
        #[arg(long, default_value = "modal", value_parser = parse_backend)]
        backend: Backend,
        /// Re-run the default and the winner on this second backend and compare.
        #[arg(long, value_parser = parse_backend)]
        check_on: Option<Backend>,
        /// Worker threads, at most 1024 [default: all cores].
        #[arg(long, value_parser = clap::value_parser!(u16).range(1..=i64::from(settle::execute::pool::MAX_JOBS)))]
        jobs: Option<u16>,
        /// Overwrite the results of an earlier tuning in the output folder (refused
        /// without it).
        #[arg(long)]
        force: bool,
        /// `--criterion klipper`: the shapers to try, comma-separated (calibrate_shaper.py's
        /// --shapers) [default: zv,mzv,ei,2hump_ei,3hump_ei].
        #[arg(long)]
        shapers: Option<String>,
        /// `--criterion klipper`: the square-corner velocity for smoothing (mm/s, 0.1 to
        /// 1000; calibrate_shaper.py's --scv) [default: 5].
        #[arg(long)]
        scv: Option<f64>,
        /// `--criterion klipper`: the most smoothing to allow (mm, 0.05 to 10;
        /// calibrate_shaper.py's --max_smoothing).
        #[arg(long, alias = "max_smoothing")]
        max_smoothing: Option<f64>,
    },
    /// Read a firmware configuration (Klipper printer.cfg, RepRapFirmware config.g,
    /// Marlin's reply to M503, a Prusa's replies to M115, M503 and M593) into a scenario with your current settings as its baseline
    /// and a search around them.
    #[command(
        after_help = "Example:\n  settle import klipper printer.cfg --machine machine.toml --out printer.toml\n  settle tune printer.toml\n  (klipper.cfg in results/printer_import-tune/ holds the recommendation)\n  settle import marlin m503.txt --out printer.toml\n  settle tune printer.toml --firmware marlin\n  (marlin.gcode holds Marlin's lines)\n  settle import prusa terminal.txt --out printer.toml\n  settle tune printer.toml\n  (prusa.gcode holds Prusa-Firmware-Buddy's lines)"
    )]
    Import {
        /// The firmware: klipper, marlin, prusa or rrf (also written reprapfirmware or duet).
        firmware: String,
        /// printer.cfg (with its includes), config.g, Marlin's reply to M503, or a
        /// Prusa's replies to M115, M503 and M593, as a terminal saves them.
        config: PathBuf,
        /// The machine file (from `settle identify`, or written by hand) [default: the
        /// preset printer_xy stands in, with a note].
        #[arg(long)]
        machine: Option<PathBuf>,
        /// The scenario to write [default: <config name>_import.toml beside the config].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Overwrite a scenario already at the output path (refused without it).
        #[arg(long)]
        force: bool,
    },
    /// Replay a G-code file through a firmware's planner on a machine: print time, contour
    /// error per layer, the worst spots with their lines, the ringing map.
    #[command(
        after_help = "Example:\n  settle gcode gcode/prints/cube_layer.gcode --machine printer_xy --firmware klipper --shaper mzv@48 --out /tmp/cube\n  (writes /tmp/cube/layers.csv, summary.md and ringing-layer-<n>.svg/png)"
    )]
    Gcode {
        /// The G-code file.
        file: PathBuf,
        /// The machine: a preset (printer_xy), a machine file, or a scenario file (its [machine]).
        #[arg(long)]
        machine: String,
        /// The planner: klipper, marlin, prusa (Prusa-Firmware-Buddy, also buddy), rrf, grbl
        /// (GRBL and grblHAL: lasers and CNC) or settle [default: klipper; with --config,
        /// rrf for a file ending in .g].
        #[arg(long, value_parser = parse_firmware)]
        firmware: Option<settle_planner::firmware::Firmware>,
        /// The firmware's configuration (Klipper printer.cfg with its includes,
        /// RepRapFirmware config.g, GRBL's settings as `$$` prints them, with --firmware
        /// grbl, or Marlin's reply to M503, with --firmware marlin): the planner's limits
        /// and the input shapers start as it sets them, instead of the firmware's defaults.
        #[arg(long, value_name = "FILE")]
        config: Option<PathBuf>,
        /// Only these layers, A..B (both included) or A; the rest is planned, not simulated.
        #[arg(long, value_name = "A..B", value_parser = workflows::gcode::parse_layers)]
        layers: Option<(u32, u32)>,
        /// Where layers come from: auto (slicer markers, else each working move in a
        /// plane at a new Z), markers (slicer markers only: a file without them is one
        /// layer; for milling and engraving jobs, whose changes of Z are not layers) or z
        /// (changes of Z only).
        #[arg(long, value_name = "SOURCE", default_value = "auto", value_parser = settle_gcode::LayerMode::parse)]
        layer_source: settle_gcode::LayerMode,
        /// Input shaper: KIND@FREQ_HZ[/DAMPING] (or none) on X and Y, e.g. mzv@48, or per
        /// axis x=SPEC,y=SPEC, e.g. x=mzv@52,y=ei@41/0.08; an axis not named keeps its own
        /// [default: none, or --config's].
        #[arg(long, value_parser = workflows::gcode::parse_shapers)]
        shaper: Option<workflows::gcode::XyShapers>,
        /// Simulation backend: modal (exact, linear driver only), rapier, mujoco.
        #[arg(long, default_value = "modal", value_parser = parse_backend)]
        backend: Backend,
        /// Driver model: linear, spring or full (modal: linear only).
        #[arg(long, default_value = "linear", value_parser = parse_driver)]
        driver: settle_sim::DriverMode,
        /// Output folder [default: results/<file stem>-gcode/].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Count and skip bad lines instead of stopping at the first.
        #[arg(long)]
        skip_bad_lines: bool,
        /// Sample rate (Hz).
        #[arg(long, allow_hyphen_values = true, default_value_t = workflows::gcode::DEFAULT_SAMPLE_RATE_HZ)]
        sample_rate_hz: f64,
        /// Ringing maps to draw: the layers with the largest contour error (0 to 50).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u16).range(0..=50))]
        maps: u16,
        /// Also write recording.mcap into the output folder: every simulated sample of
        /// the layers (commanded and toolhead XY, contour error, line), streaming; at most
        /// 2^25 samples (4.7 h of print at 2 kHz, about 4.5 GB), or the job is refused.
        #[arg(long)]
        mcap: bool,
        /// Also run FIRMWARE[:SHAPER] (e.g. settle:none, klipper:ei@48,
        /// klipper:x=mzv@52,y=ei@41) and compare: the worst layer under both
        /// (compare-layer-<n>.svg/png) and compare.md. The firmware of --config keeps its
        /// settings; another starts from its defaults.
        #[arg(long, value_name = "FIRMWARE[:SHAPER]", value_parser = workflows::gcode::compare::parse_setting)]
        versus: Option<(
            settle_planner::firmware::Firmware,
            workflows::gcode::XyShapers,
        )>,
        /// Overwrite the results of an earlier run in the output folder (refused without
        /// it).
        #[arg(long)]
        force: bool,
        #[command(flatten)]
        failed_runs: FailedRunsFlag,
    },
    /// Run one point of a sweep in detail: print its metrics, write its full trace as CSV.
    #[command(
        after_help = "Example:\n  settle run scenarios/quickstart.toml --case 3\n  (prints the metrics of run 3 and writes results/quickstart/run-3.csv)"
    )]
    Run {
        /// The scenario file (TOML).
        scenario: PathBuf,
        /// The run index, as in the `run` column of runs.csv.
        #[arg(long)]
        case: usize,
        /// Trace file [default: results/<scenario name>/run-<case>.csv].
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        outputs: OutputFlags,
        /// Also draw the run's time series as run-<case>.svg and .png beside the trace.
        #[arg(long)]
        plot: bool,
        /// Simulation backend: modal, rapier, mujoco.
        #[arg(long, default_value = "rapier", value_parser = parse_backend)]
        backend: Backend,
        #[command(flatten)]
        failed_runs: FailedRunsFlag,
    },
    /// Print a machine's modes per axis (frequency, damping ratio, weight).
    #[command(
        after_help = "FILE is a scenario, a machine file or a preset name. A physical machine prints its\nlinearised modes (linear driver, at axis position 0 mm).\n\nExample:\n  settle machine printer_xy\n  settle machine examples/data/machine.toml"
    )]
    Machine {
        /// A scenario (TOML), a machine file (TOML) or a built-in preset's name.
        file: String,
    },
    /// Vibration modes per axis from accelerometer files, with uncertainties: a table, a
    /// figure per axis and (with --out) a machine file.
    #[command(
        after_help = "Files: Klipper raw CSV (#time,accel_x,accel_y,accel_z), Klipper processed CSV\n(resonances_*.csv, calibration_data_*.csv), RepRapFirmware M956 CSV, Shake&Tune .stdata.\nThe machine axis of each file: --axis, else the x/y/z in its name (raw_data_x_*.csv).\n\nExample:\n  settle identify examples/data/raw_data_x_example.csv examples/data/raw_data_y_example.csv \\\n      --freq-start 30 --freq-end 90 --hz-per-sec 10 --out /tmp/machine.toml"
    )]
    Identify {
        /// The accelerometer files (one recording per machine axis).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The machine axis every file excited: x, y or z [default: from each file's name].
        #[arg(long)]
        axis: Option<String>,
        /// Write a machine file (modes per axis) here, for `preset = "<file>"` in a scenario.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Folder of the figures identify-<axis>.svg/.png [default: --out's folder, else
        /// results/identify/].
        #[arg(long)]
        figures: Option<PathBuf>,
        /// Most modes to fit per axis (1 to 4).
        #[arg(long, default_value_t = 3)]
        max_modes: usize,
        /// The fit: auto (a sweep fit for a resonance test, a ring-down fit for a free
        /// decay), sweep, ringdown.
        #[arg(long, default_value = "auto", value_parser = parse_method)]
        method: settle_identify::MethodChoice,
        /// The column of a Klipper processed spectrum to fit: xyz (psd_xyz, the total
        /// Klipper tunes against) or one sensor axis's (x, y, z).
        #[arg(long, default_value = "xyz", value_parser = parse_column)]
        column: settle_identify::SpectrumColumn,
        /// The resonance test's first frequency (Hz; Klipper's FREQ_START / min_freq)
        /// [default: Klipper's defaults for this and the five options below].
        #[arg(long, allow_hyphen_values = true)]
        freq_start: Option<f64>,
        /// Its last frequency (Hz; Klipper's FREQ_END / max_freq).
        #[arg(long, allow_hyphen_values = true)]
        freq_end: Option<f64>,
        /// Its sweep rate (Hz/s; Klipper's HZ_PER_SEC).
        #[arg(long, allow_hyphen_values = true)]
        hz_per_sec: Option<f64>,
        /// Its acceleration per Hz (mm/s^2/Hz; Klipper's accel_per_hz).
        #[arg(long, allow_hyphen_values = true)]
        accel_per_hz: Option<f64>,
        /// The slow sweeping motion's acceleration (mm/s^2; Klipper's sweeping_accel; 0
        /// for the pulse-only test of Klipper before December 2024).
        #[arg(long, allow_hyphen_values = true)]
        sweeping_accel: Option<f64>,
        /// Its period (s; Klipper's sweeping_period).
        #[arg(long, allow_hyphen_values = true)]
        sweeping_period: Option<f64>,
        /// Overwrite the machine file at --out and the figures of an earlier
        /// identification in the figures folder (refused without it).
        #[arg(long)]
        force: bool,
    },
}

fn parse_column(s: &str) -> Result<settle_identify::SpectrumColumn, String> {
    use settle_identify::SpectrumColumn;
    match s {
        "xyz" => Ok(SpectrumColumn::Total),
        "x" => Ok(SpectrumColumn::Axis(0)),
        "y" => Ok(SpectrumColumn::Axis(1)),
        "z" => Ok(SpectrumColumn::Axis(2)),
        _ => Err(format!("unknown column `{s}`; allowed: xyz, x, y, z")),
    }
}

fn parse_method(s: &str) -> Result<settle_identify::MethodChoice, String> {
    use settle_identify::MethodChoice;
    match s {
        "auto" => Ok(MethodChoice::Auto),
        "sweep" => Ok(MethodChoice::Sweep),
        "ringdown" => Ok(MethodChoice::RingDown),
        _ => Err(format!(
            "unknown method `{s}`; allowed: auto, sweep, ringdown"
        )),
    }
}

/// How runs that failed physically end the command.
#[derive(clap::Args, Debug, Clone, Copy)]
struct FailedRunsFlag {
    /// Exit 1 when a run failed (lost steps, a simulation fault) [default: exit 0: a failed
    /// run is a result, listed with its reason in the outputs and on stderr].
    #[arg(long)]
    fail_on_failed_runs: bool,
}

/// Recordings a sweep or a run can write.
#[derive(clap::Args, Debug, Clone, Copy)]
struct OutputFlags {
    /// Write an MCAP recording per run (zstd, JSON schemas; opens in Foxglove).
    #[arg(long)]
    mcap: bool,
    /// Write a rerun recording (.rrd) per run (needs the `rerun` cargo feature).
    #[arg(long)]
    rerun: bool,
}

fn main() -> ExitCode {
    match dispatch(Cli::parse().command) {
        Ok(report) => {
            // A reader that stops early (`settle machine printer_xy | head -1`) closes the
            // pipe: an I/O failure named once (exit 1, as `settle plan` has it), not a
            // panic of `print!`.
            let written = write_stdout(&report.stdout);
            eprint!("{}", report.stderr);
            if let Err(e) = written {
                eprintln!("error: cannot write stdout: {e}");
                return ExitCode::from(1);
            }
            ExitCode::from(match report.exit {
                Exit::Ok | Exit::RunsFailed => 0,
                Exit::Failed => 1,
                Exit::Interrupted => interrupt::EXIT_CODE,
            })
        }
        Err(e) => {
            eprintln!("error: {}", settle::error::shorten_numbers(&e.to_string()));
            ExitCode::from(if e.is_input_error() { 2 } else { 1 })
        }
    }
}

/// A report's standard output, written and flushed.
fn write_stdout(text: &str) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()
}

/// A progress bar on stderr (drawn only when stderr is a terminal), fed by the workflows'
/// progress callback.
fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} runs ({eta} left)",
    ) {
        bar.set_style(style);
    }
    bar
}

/// `settle gcode`'s progress bar on stderr (drawn only when stderr is a terminal): how
/// much of the G-code file the simulation has read.
fn gcode_progress_bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} [{elapsed_precise}] {bar:40} {bytes}/{total_bytes} of G-code simulated ({eta} left)",
    ) {
        bar.set_style(style);
    }
    bar
}

/// Ctrl-C and SIGTERM stop new runs from starting (the finished ones are in the sweep's
/// journal); a second signal exits at once, which loses nothing either.
fn install_interrupt() -> Result<(), Error> {
    ctrlc::set_handler(|| {
        if interrupt::request() {
            eprintln!("\nsettle: second interrupt, exiting now");
            std::process::exit(i32::from(interrupt::EXIT_CODE));
        }
        eprintln!(
            "\nsettle: interrupted; finishing the runs in progress (interrupt again to exit at once)"
        );
    })
    .map_err(|e| {
        Error::input(
            "signals",
            format!("cannot install the Ctrl-C/SIGTERM handler: {e}"),
        )
    })
}

fn dispatch(command: Command) -> Result<Report, Error> {
    let bar = progress_bar();
    let progress = |done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let note = |line: &str| bar.suspend(|| eprintln!("{line}"));
    let jobs = |j: Option<u16>| j.map(usize::from);
    // Failed runs end these commands with exit 1 only when asked.
    let failed_runs = |mut r: Report, flag: FailedRunsFlag| {
        if flag.fail_on_failed_runs && r.exit == Exit::RunsFailed {
            r.exit = Exit::Failed;
        }
        r
    };
    let report = match command {
        Command::Sweep {
            scenario,
            out,
            jobs: j,
            backend,
            outputs,
            shard,
            resume,
            force,
            failed_runs: flag,
        } => {
            let shard = match shard {
                Some(arg) => {
                    let r = arg.resolve(&|name| std::env::var(name).ok())?;
                    if !r.source.is_empty() {
                        note(&format!("--shard {}: {}", r.shard, r.source));
                    }
                    Some(r.shard)
                }
                None => None,
            };
            install_interrupt()?;
            let opts = workflows::sweep::SweepOptions {
                out,
                jobs: jobs(j),
                mcap: outputs.mcap,
                rerun: outputs.rerun,
                shard,
                resume,
                force,
                ..workflows::sweep::SweepOptions::new(scenario, backend)
            };
            failed_runs(
                workflows::sweep::sweep(&opts, &note, &progress)?.report(),
                flag,
            )
        }
        Command::Validate { backend, out } => {
            workflows::validate::validate(backend, out.as_deref())?.report()
        }
        Command::Check {
            scenario,
            baseline,
            tolerance,
            floor_um,
            update,
            allow_improvements,
            backend,
            jobs: j,
        } => {
            let opts = workflows::check::CheckOptions {
                tolerance_pct: tolerance,
                floor_um,
                update,
                allow_improvements,
                backend,
                jobs: jobs(j),
                ..workflows::check::CheckOptions::new(scenario, baseline)
            };
            workflows::check::check(&opts, &progress)?.report()
        }
        Command::Merge {
            dirs,
            out,
            force,
            failed_runs: flag,
        } => failed_runs(workflows::merge::merge(&dirs, out, force)?.report(), flag),
        Command::Tune {
            scenario,
            out,
            backend,
            check_on,
            jobs: j,
            firmware,
            frequency_tolerance,
            criterion,
            force,
            shapers,
            scv,
            max_smoothing,
        } => {
            if criterion == "klipper" {
                workflows::tune::klipper_criterion::report(
                    &workflows::tune::klipper_criterion::KlipperCriterion {
                        force,
                        ..workflows::tune::klipper_criterion::KlipperCriterion::from_args(
                            scenario,
                            out,
                            shapers.as_deref(),
                            scv,
                            max_smoothing,
                        )?
                    },
                )?
            } else if scenario.len() != 1
                || shapers.is_some()
                || scv.is_some()
                || max_smoothing.is_some()
            {
                return Err(Error::input(
                    "SCENARIO",
                    "settle tune takes one scenario file; several files and --shapers, --scv, --max-smoothing go with --criterion klipper",
                ));
            } else {
                let scenario = &scenario[0];
                let opts = workflows::tune::Options {
                    check_on,
                    jobs: jobs(j),
                    firmware,
                    frequency_tolerance_pct: frequency_tolerance,
                    force,
                    ..workflows::tune::Options::new(backend)
                };
                workflows::tune::tune_with(scenario, out, &opts, &progress)?.report()
            }
        }
        Command::Import {
            firmware,
            config,
            machine,
            out,
            force,
        } => {
            let opts = workflows::import::ImportOptions {
                firmware: workflows::import::parse_firmware(&firmware)
                    .map_err(|m| Error::input_key(&config, "firmware", m))?,
                config,
                machine,
                out,
                force,
            };
            workflows::import::import(&opts)?.report()
        }
        Command::Plan { jobs: j } => {
            use std::io::IsTerminal;
            let stdin = std::io::stdin();
            // Typed lines are answered one by one; piped input in batches that never wait
            // for more input (see `plan_stream`).
            let batch = if stdin.is_terminal() {
                1
            } else {
                workflows::plan::BATCH
            };
            let stdout = std::io::BufWriter::new(std::io::stdout().lock());
            workflows::plan::plan_stream(stdin.lock(), stdout, jobs(j), batch)?;
            Report::new(Exit::Ok)
        }
        Command::Gcode {
            file,
            machine,
            firmware,
            config,
            layers,
            layer_source,
            shaper,
            backend,
            driver,
            out,
            skip_bad_lines,
            sample_rate_hz,
            maps,
            mcap,
            versus,
            force,
            failed_runs: flag,
        } => {
            let opts = workflows::gcode::GcodeOptions {
                mcap,
                layers,
                backend,
                driver,
                out,
                skip_bad_lines,
                sample_rate_hz,
                maps: usize::from(maps),
                versus,
                force,
                ..match config {
                    Some(config) => workflows::gcode::GcodeOptions::with_config(
                        file, &machine, firmware, config,
                    )?,
                    None => workflows::gcode::GcodeOptions::new(
                        file,
                        &machine,
                        firmware.unwrap_or(settle_planner::firmware::Firmware::Klipper),
                    )?,
                }
                .with_shapers(shaper.unwrap_or_default())
                .with_layer_mode(layer_source)
            };
            let bar = gcode_progress_bar();
            let tell = |read: u64, size: u64| {
                bar.set_length(size);
                bar.set_position(read);
            };
            let outcome = workflows::gcode::gcode_with_progress(&opts, Some(&tell));
            bar.finish_and_clear();
            failed_runs(outcome?.report(), flag)
        }
        Command::Run {
            scenario,
            case,
            out,
            outputs,
            plot,
            backend,
            failed_runs: flag,
        } => {
            let opts = workflows::run::RunOptions {
                out,
                mcap: outputs.mcap,
                rerun: outputs.rerun,
                plot,
                ..workflows::run::RunOptions::new(scenario, case, backend)
            };
            failed_runs(workflows::run::run(&opts)?.report(), flag)
        }
        Command::Machine { file } => workflows::machine::machine_modes(&file)?.report(),
        Command::Identify {
            files,
            axis,
            out,
            figures,
            max_modes,
            method,
            column,
            freq_start,
            freq_end,
            hz_per_sec,
            accel_per_hz,
            sweeping_accel,
            sweeping_period,
            force,
        } => {
            let opts = workflows::identify::IdentifyOptions {
                axis,
                out,
                figures,
                identify: settle_identify::Options {
                    test: {
                        let k = settle_identify::SweepTest::klipper();
                        settle_identify::SweepTest {
                            freq_start_hz: freq_start.unwrap_or(k.freq_start_hz),
                            freq_end_hz: freq_end.unwrap_or(k.freq_end_hz),
                            accel_per_hz: accel_per_hz.unwrap_or(k.accel_per_hz),
                            hz_per_sec: hz_per_sec.unwrap_or(k.hz_per_sec),
                            sweeping_accel_mm_s2: sweeping_accel.unwrap_or(k.sweeping_accel_mm_s2),
                            sweeping_period_s: sweeping_period.unwrap_or(k.sweeping_period_s),
                        }
                    },
                    max_modes,
                    method,
                    column,
                },
                force,
                ..workflows::identify::IdentifyOptions::new(files)
            };
            workflows::identify::identify(&opts)?.report()
        }
    };
    bar.finish_and_clear();
    Ok(report)
}
