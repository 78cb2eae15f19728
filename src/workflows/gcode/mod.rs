//! `settle gcode`: a G-code job replayed through a firmware's planner (settle-gcode's
//! [`Job`]) on a machine, streaming, with its ringing map.
//!
//! The job's shaped X, Y (and Z, when the machine has it) motion drives the machine's
//! axes of the same names, in the G-code's coordinates (position 0 of a machine axis is
//! G-code 0). Per sample the toolhead's contour error ([`crate::studies::gcode::contour`]) is measured, per move
//! its largest value (the ringing after the corner at the move's start), per layer the
//! worst and 95th percentile over working samples ([`crate::studies::gcode::stats`]); the outputs are
//! `layers.csv`, `summary.md` and the ringing maps of the worst layers ([`report`]).
//! Everything is computed before anything is written: a bad file writes nothing.
//!
//! On the modal backend a machine whose stiffness depends on position (a belt's spans) is
//! linearised at one point for the whole file, where the print is
//! ([`crate::studies::gcode::linpoint`]: the centre of the working moves' bounding box),
//! for the whole run and for any layer range alike; the `[gcode]` study uses the same
//! point, so both give the same numbers.

pub mod compare;
pub mod features;
pub mod record;
pub mod report;
pub mod stream;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use settle_gcode::job::{Job, JobConfig, ShaperSetting};
use settle_gcode::{GcodeError, Reader, ReaderOptions};
use settle_planner::firmware::Firmware;
use settle_planner::{Profile, State};
use settle_sim::closed_form::LinearResponse;
use settle_sim::machine::Machine;
use settle_sim::{AxisModel, DriverMode};

use crate::error::{Error, Location};
use crate::execute::SimOptions;
use crate::expand::machine::Named;
use crate::input::machine_form::MachineForm;
use crate::spec::backend::{Backend, NO_MUJOCO};
use crate::studies::gcode::linpoint::{LinPoint, depends_on_position, linearisation_point};
use crate::studies::gcode::preroll::{preroll_s, slowest_decay_per_s};
use crate::studies::gcode::stats::{self, LayerMap, Spot};
use crate::workflows::{Exit, Report};
use stream::{StreamOptions, Streamed, simulate_job};

/// Sample rate of `settle gcode` (Hz): 2 kHz is 13 samples per period of a 150 Hz mode,
/// the highest of a printer's toolhead modes, and keeps a job's simulation well above
/// real time.
pub const DEFAULT_SAMPLE_RATE_HZ: f64 = 2000.0;

/// What `settle gcode` runs.
#[derive(Debug, Clone)]
pub struct GcodeOptions {
    /// The G-code file.
    pub file: PathBuf,
    /// The machine: a preset name, a machine file, or a scenario whose machine to use.
    pub machine: String,
    /// The planner and its settings (a firmware's defaults unless changed).
    pub job: JobConfig,
    /// Only these layers (inclusive); the rest is planned, not simulated.
    pub layers: Option<(u32, u32)>,
    /// The backend.
    pub backend: Backend,
    /// The driver model of a physical machine.
    pub driver: DriverMode,
    /// Output folder (`None`: `results/<file stem>-gcode/`).
    pub out: Option<PathBuf>,
    /// Count and skip bad lines instead of stopping at the first.
    pub skip_bad_lines: bool,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Ringing maps to draw (the worst layers).
    pub maps: usize,
    /// A layer whose ringing map is kept besides the worst ones (the comparison's).
    pub map_layer: Option<u32>,
    /// A second setting to compare with (`--versus`): firmware and X/Y shapers.
    pub versus: Option<(Firmware, XyShapers)>,
    /// Write `recording.mcap` into the output folder ([`record`]).
    pub mcap: bool,
    /// The most samples the recording holds ([`record::MAX_RECORDED_SAMPLES`], what the
    /// command line uses): a job that reaches it is an error and writes nothing.
    pub mcap_max_samples: u64,
    /// The firmware configuration the planner's settings come from (`--config`).
    pub config: Option<ConfigSource>,
    /// Overwrite the results of an earlier run in the output folder (refused without it).
    pub force: bool,
}

/// A firmware configuration read for `--config`.
#[derive(Debug, Clone)]
pub struct ConfigSource {
    /// printer.cfg or config.g.
    pub path: PathBuf,
    /// The job configuration it gives (shapers before `--shaper`).
    pub job: JobConfig,
    /// What the reader noted (SAVE_CONFIG values overridden, blocks not read).
    pub notes: Vec<String>,
    /// The files read (the configuration and what it includes or runs).
    pub files: Vec<PathBuf>,
}

/// `--shaper` as written: `KIND@FREQ_HZ[/DAMPING]` or `none` for X and Y, or per axis
/// `x=SPEC,y=SPEC`. An axis not named keeps the shaper it has (the configuration's with
/// `--config`, none without).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct XyShapers {
    /// X: `None` not named, `Some(None)` unshaped.
    pub x: Option<Option<ShaperSetting>>,
    /// Y: `None` not named, `Some(None)` unshaped.
    pub y: Option<Option<ShaperSetting>>,
}

impl XyShapers {
    /// The same shaper (or none) on X and Y.
    pub fn both(s: Option<ShaperSetting>) -> Self {
        Self {
            x: Some(s),
            y: Some(s),
        }
    }

    /// `--shaper`'s text for `shapers` (X and Y): one spec when they are equal, else
    /// `x=...,y=...`.
    pub fn text(shapers: &[Option<ShaperSetting>; 3]) -> String {
        let one =
            |s: &Option<ShaperSetting>| s.as_ref().map_or("none".to_string(), report::shaper_arg);
        if shapers[0] == shapers[1] {
            one(&shapers[0])
        } else {
            format!("x={},y={}", one(&shapers[0]), one(&shapers[1]))
        }
    }
}

/// Parses `--shaper` (and the shaper of `--versus`): see [`XyShapers`].
pub fn parse_shapers(s: &str) -> Result<XyShapers, String> {
    let one = |spec: &str| -> Result<Option<ShaperSetting>, String> {
        if spec.eq_ignore_ascii_case("none") {
            Ok(None)
        } else {
            parse_shaper(spec).map(Some)
        }
    };
    if !s.contains('=') {
        return Ok(XyShapers::both(one(s)?));
    }
    let mut out = XyShapers::default();
    for part in s.split(',') {
        let bad_axis = || {
            format!(
                "`{s}`: per-axis shapers are x=SPEC,y=SPEC (SPEC a shaper such as mzv@48, or none)"
            )
        };
        let (axis, spec) = part.split_once('=').ok_or_else(bad_axis)?;
        let slot = match axis.trim().to_ascii_lowercase().as_str() {
            "x" => &mut out.x,
            "y" => &mut out.y,
            _ => return Err(bad_axis()),
        };
        if slot.is_some() {
            return Err(format!("`{s}`: axis {} is named twice", axis.trim()));
        }
        *slot = Some(one(spec.trim())?);
    }
    Ok(out)
}

/// What `--config` reads, as its refusals end.
const CONFIG_READS: &str = "--config reads a Klipper printer.cfg (--firmware klipper), a RepRapFirmware config.g (--firmware rrf), GRBL's $$ settings (--firmware grbl), Marlin's M503 reply (--firmware marlin) or a Prusa's replies to M115, M503 and M593 (--firmware prusa)";

impl GcodeOptions {
    /// `file` on `machine` with `firmware`'s defaults, the modal backend and the linear
    /// driver (what the modal backend solves exactly).
    /// A Prusa job takes the settings of the printer the file names
    /// ([`JobConfig::for_file`]).
    pub fn new(file: PathBuf, machine: &str, firmware: Firmware) -> Result<Self, Error> {
        let job = JobConfig::for_file(firmware, &file).map_err(gcode_error(&file))?;
        Ok(Self {
            file,
            machine: machine.to_string(),
            job,
            layers: None,
            backend: Backend::Modal,
            driver: DriverMode::Linear,
            out: None,
            skip_bad_lines: false,
            sample_rate_hz: DEFAULT_SAMPLE_RATE_HZ,
            maps: 1,
            map_layer: None,
            versus: None,
            mcap: false,
            mcap_max_samples: record::MAX_RECORDED_SAMPLES,
            config: None,
            force: false,
        })
    }

    /// `file` on `machine` with the planner settings and shapers of a firmware
    /// configuration (Klipper's printer.cfg with its includes, or RepRapFirmware's
    /// config.g): `firmware` names which (`None`: RepRapFirmware for a file ending in `.g`,
    /// else Klipper).
    pub fn with_config(
        file: PathBuf,
        machine: &str,
        firmware: Option<Firmware>,
        config: PathBuf,
    ) -> Result<Self, Error> {
        let is_g = config
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("g"));
        let firmware = firmware.unwrap_or(if is_g {
            Firmware::Rrf
        } else {
            Firmware::Klipper
        });
        crate::workflows::import::not_a_config(&config, firmware, CONFIG_READS)?;
        let (job, mut notes, files): (JobConfig, Vec<String>, _) = match firmware {
            Firmware::Klipper => {
                let c = settle_gcode::config::KlipperConfig::read(&config)
                    .map_err(|e| crate::workflows::import::config_error(&config, e))?;
                let job = JobConfig::from_klipper(&c).map_err(gcode_error(&config))?;
                let notes = c.notes.iter().map(ToString::to_string).collect();
                (job, notes, c.files)
            }
            Firmware::Rrf => {
                let c = settle_gcode::config::RrfConfig::read(&config)
                    .map_err(|e| crate::workflows::import::config_error(&config, e))?;
                let job = JobConfig::from_rrf(&c).map_err(gcode_error(&config))?;
                let notes = c.notes.iter().map(ToString::to_string).collect();
                (job, notes, c.files)
            }
            Firmware::Grbl => {
                let c = settle_gcode::config::GrblSettings::read(&config)
                    .map_err(|e| crate::workflows::import::config_error(&config, e))?;
                let job = JobConfig::from_grbl(&c).map_err(gcode_error(&config))?;
                let notes = c.notes.iter().map(ToString::to_string).collect();
                (job, notes, c.files)
            }
            Firmware::Marlin => {
                let c = settle_gcode::config::MarlinSettings::read(&config)
                    .map_err(|e| crate::workflows::import::config_error(&config, e))?;
                let job = c.job_config().map_err(gcode_error(&config))?;
                let notes = c.notes.iter().map(ToString::to_string).collect();
                (job, notes, c.files)
            }
            Firmware::Prusa => {
                let c = settle_gcode::config::MarlinSettings::read_prusa(&config)
                    .map_err(|e| crate::workflows::import::config_error(&config, e))?;
                let job = c.job_config().map_err(gcode_error(&config))?;
                let notes = c.notes.iter().map(ToString::to_string).collect();
                (job, notes, c.files)
            }
            Firmware::Settle | Firmware::Tmc4361a => {
                return Err(Error::input_key(
                    &config,
                    "--config",
                    format!("{CONFIG_READS}, not {firmware}'s settings"),
                ));
            }
        };
        let mut opts = Self::new(file, machine, firmware)?;
        // A Prusa job: which printer it runs as, against the one the file names (read by
        // `Self::new`).
        notes.extend(prusa_printers(
            &opts.file,
            &config,
            job.prusa.as_ref(),
            &opts.job,
        ));
        opts.job = job.clone();
        opts.config = Some(ConfigSource {
            path: config,
            job,
            notes,
            files,
        });
        Ok(opts)
    }

    /// The same input shaper on X and Y.
    pub fn with_shaper(self, shaper: Option<ShaperSetting>) -> Self {
        self.with_shapers(XyShapers::both(shaper))
    }

    /// Layers from `mode` (`--layer-source`).
    pub fn with_layer_mode(mut self, mode: settle_gcode::LayerMode) -> Self {
        self.job.layer_mode = mode;
        self
    }

    /// The shapers `--shaper` names; an axis it does not name keeps its own.
    pub fn with_shapers(mut self, shapers: XyShapers) -> Self {
        if let Some(x) = shapers.x {
            self.job.shapers[0] = x;
        }
        if let Some(y) = shapers.y {
            self.job.shapers[1] = y;
        }
        self
    }
}

/// One row of layers.csv.
#[derive(Debug, Clone)]
pub struct LayerRow {
    /// Layer index.
    pub layer: u32,
    /// Its Z (mm): where the file says, else where its first working move in a plane
    /// runs ([`settle_gcode::job::LayerTime::z_mm`]).
    pub z_mm: Option<f64>,
    /// When it starts (s).
    pub start_s: f64,
    /// How long it takes (s).
    pub duration_s: f64,
    /// Moves in it.
    pub moves: u64,
    /// The lowest and highest Z of its extruding moves (mm;
    /// [`settle_gcode::job::LayerTime::print_z_mm`]).
    pub print_z_mm: Option<[f64; 2]>,
    /// What opened it ([`settle_gcode::job::LayerTime::opened_by`]).
    pub opened_by: Option<settle_gcode::LayerSource>,
    /// Its contour-error account, when it was simulated.
    pub stats: Option<stats::LayerStats>,
}

/// A layer whose extruding moves span more Z than this (mm) is not one plane: thicker
/// than any layer a nozzle prints.
pub const NON_PLANAR_MM: f64 = 1.0;

/// What `settle gcode` measured.
#[derive(Debug, Clone)]
pub struct GcodeOutcome {
    /// The G-code file.
    pub file: PathBuf,
    /// The planner.
    pub firmware: Firmware,
    /// The planner and the shapers on X and Y, in words (`klipper + mzv@48 Hz`).
    pub setting: String,
    /// The machine's name.
    pub machine: String,
    /// The backend.
    pub backend: Backend,
    /// The print time of the whole file (s), the planner's clock.
    pub print_time_s: f64,
    /// Per layer.
    pub layers: Vec<LayerRow>,
    /// Largest contour error while printing (um).
    pub worst_um: f64,
    /// 95th percentile of the contour error while printing (um; the upper edge of its
    /// histogram bin, at most 0.1 % above the sample quantile).
    pub p95_um: f64,
    /// The simulation's account.
    pub streamed: Streamed,
    /// Lines skipped (`--skip-bad-lines`).
    pub skipped_lines: u64,
    /// Commands read but not followed, with why, and how often.
    pub ignored: BTreeMap<String, u64>,
    /// The slicer feature types the file names ([`settle_gcode::Reader::features`]).
    pub features: Vec<String>,
    /// The file's limit commands that raise a limit above the configuration's.
    pub overrides: Vec<settle_gcode::job::LimitOverride>,
    /// Files written.
    pub files: Vec<PathBuf>,
    /// The outcome of the `--versus` setting.
    pub versus: Option<Box<GcodeOutcome>>,
    /// The MCAP recording's channels, when one was written.
    pub recording: Option<Vec<crate::output::sink::mcap::ChannelInfo>>,
    /// Where the modal backend linearised the machine (a machine whose stiffness depends
    /// on position; [`crate::studies::gcode::linpoint`]).
    pub linearised_at: Option<LinPoint>,
    /// The planner's settings read from `--config`, in words, and the reader's notes.
    pub config: Option<(String, Vec<String>)>,
    /// GRBL's steps per mm of X and Y at the job's start (`$100`, `$101`): GRBL rounds
    /// every target to whole steps. `None` for the other firmwares.
    pub grbl_steps_per_mm: Option<[f64; 2]>,
}

impl GcodeOutcome {
    /// The worst spots of the job, largest first.
    pub fn worst(&self) -> &[Spot] {
        &self.streamed.worst
    }

    /// The ringing maps of the worst layers.
    pub fn maps(&self) -> &[LayerMap] {
        &self.streamed.maps
    }

    /// The layers whose extruding moves are not in one plane ([`NON_PLANAR_MM`]), in
    /// words, by what the first such layer is: the moves before a slicer's first layer
    /// marker (a start G-code's purge line that extrudes on its way down), a marked layer
    /// with non-planar moves, or, in a file that marks no layer and prints rising (a
    /// spiral vase, non-planar moves), a layer from Z that holds all of that height. Its
    /// numbers are then not one layer's. `None` when every layer is planar.
    pub fn non_planar_words(&self) -> Option<String> {
        let spans: Vec<&LayerRow> = self
            .layers
            .iter()
            .filter(|l| l.print_z_mm.is_some_and(|[lo, hi]| hi - lo > NON_PLANAR_MM))
            .collect();
        let first = *spans.first()?;
        let (layer, [lo, hi]) = (first.layer, first.print_z_mm?);
        let more = match spans.len() {
            1 => String::new(),
            n => format!(" (and {} more such layers)", n - 1),
        };
        let marked = |s: &settle_gcode::LayerSource| *s != settle_gcode::LayerSource::ZChange;
        let file_marks = self
            .layers
            .iter()
            .any(|l| l.opened_by.as_ref().is_some_and(marked));
        let what = match first.opened_by {
            None if file_marks => format!(
                "layer {layer} (the moves before the file's first layer marker: its start G-code) extrudes between Z {lo:.2} and {hi:.2} mm{more}: not one plane (a purge line that extrudes on its way down, say)"
            ),
            Some(s) if marked(&s) => format!(
                "layer {layer}'s extruding moves span Z {lo:.2} to {hi:.2} mm{more}: not one plane (non-planar moves within one layer the file marks)"
            ),
            _ => format!(
                "layer {layer}'s extruding moves rise from Z {lo:.2} to {hi:.2} mm{more}: not one plane (a spiral vase, or non-planar moves, in a file that marks no layers)"
            ),
        };
        Some(format!(
            "{what}, so its per-layer numbers (Z, time, contour error) are over that whole height, not one layer's"
        ))
    }

    /// Whether the simulation faulted before any working sample: the contour error was
    /// not measured at all (its numbers would read 0).
    pub fn measured_nothing(&self) -> bool {
        self.streamed.fault.is_some() && self.streamed.all.total() == 0
    }

    /// What the binary prints; [`Exit::RunsFailed`] when the simulation failed (lost steps,
    /// a fault): a result, written and reported, not a failure of the command.
    pub fn report(&self) -> Report {
        let failed = self.streamed.fault.is_some() || self.streamed.lost_steps > 0;
        let mut r = Report::new(if failed { Exit::RunsFailed } else { Exit::Ok });
        let error = if self.measured_nothing() {
            "contour error not measured: the simulation faulted before any working sample (below)"
                .to_string()
        } else {
            format!(
                "contour error worst {:.2} um, p95 {:.2} um (smoothing worst {:.2} um, vibration worst {:.2} um){}",
                self.worst_um,
                self.p95_um,
                self.streamed.split_worst.smoothing_um,
                self.streamed.split_worst.vibration_um,
                if self.streamed.fault.is_some() {
                    ", before the simulation fault (below)"
                } else {
                    ""
                }
            )
        };
        r.out(format!(
            "{}: {} on {} ({}): print time {:.1} s, {error}",
            self.file.display(),
            self.firmware,
            self.machine,
            self.backend.name(),
            self.print_time_s,
        ));
        if let Some((settings, notes)) = &self.config {
            r.out(settings.clone());
            for n in notes {
                r.err(format!("note: {n}"));
            }
        }
        if let Some(p) = &self.linearised_at {
            r.out(format!("modal backend linearised at {}", p.describe()));
        }
        if let Some(s) = self.worst().first() {
            r.out(format!(
                "worst at line {} (layer {}, X {:.2} Y {:.2} mm)",
                s.line, s.layer, s.x_mm, s.y_mm
            ));
        }
        if let Some(f) = features::fly_words(self) {
            r.out(f);
        }
        if let Some(t) = &self.streamed.tail {
            r.out(format!(
                "ringing after the last move: {:.2} um at most, {:.3} um after {:.2} s",
                t.residual_peak_um, t.residual_last_um, t.duration_s
            ));
        }
        if let Some(b) = &self.versus {
            r.out(compare::table(&[self, b]));
        }
        for f in &self.files {
            r.out(format!("wrote {}", f.display()));
        }
        if let Some(fault) = &self.streamed.fault {
            r.err(format!("simulation fault: {fault}"));
        }
        if self.streamed.lost_steps > 0 {
            let at = self.streamed.first_lost_step.as_ref().map_or(String::new(), |l| {
                format!(
                    "; first seen on axis {} at {:.3} s (line {}, layer {}), load angle {:.0} electrical degrees",
                    l.axis, l.time_s, l.line, l.layer, l.max_load_angle_deg
                )
            });
            r.err(format!(
                "result: the machine loses steps ({} full steps{at}): the motion asks more of a motor than its torque gives (its load angle passed 90 electrical degrees); what it prints after that is not this simulation's toolpath (a failed run: a result, exit 0; --fail-on-failed-runs makes it exit 1)",
                self.streamed.lost_steps
            ));
        }
        if self.skipped_lines > 0 {
            r.err(format!("skipped {} bad lines", self.skipped_lines));
        }
        for o in &self.overrides {
            r.err(format!("note: {}", override_words(o)));
        }
        if let Some(w) = self.non_planar_words() {
            r.err(format!("note: {w}"));
        }
        if !self.ignored.is_empty() {
            const SHOWN: usize = 8;
            let mut names: Vec<String> = self
                .ignored
                .iter()
                .take(SHOWN)
                .map(|(what, n)| {
                    let name = what.split(':').next().unwrap_or(what);
                    format!("{name} ({n}x)")
                })
                .collect();
            if self.ignored.len() > SHOWN {
                names.push(format!("and {} more", self.ignored.len() - SHOWN));
            }
            r.err(format!(
                "not followed: {} (why: summary.md, Commands not followed)",
                names.join(", ")
            ));
        }
        r
    }
}

/// A limit the file raises, in words: `line 12: M204 raises max_accel (mm/s^2) from the
/// configuration's 7000 to 15000; the firmware follows the file`.
pub fn override_words(o: &settle_gcode::job::LimitOverride) -> String {
    // Klipper reads M204 S as its SET_VELOCITY_LIMIT ACCEL (klippy/toolhead.py
    // `cmd_M204`); its other limits only SET_VELOCITY_LIMIT sets.
    let command = match o.command.as_str() {
        "SET_VELOCITY_LIMIT" if o.limit.starts_with("max_accel ") => "M204 (or SET_VELOCITY_LIMIT)",
        c => c,
    };
    let more = match o.raises {
        0 | 1 => String::new(),
        n => format!(
            " ({n} commands set it above the configuration's, to {} at most)",
            plot_num(o.highest)
        ),
    };
    format!(
        "line {}: {} raises {} from the configuration's {} to {}{more}; the firmware follows the file",
        o.line,
        command,
        o.limit,
        plot_num(o.configured),
        plot_num(o.file)
    )
}

/// A setting's value as written (`7000`, `0.5`), without float noise.
fn plot_num(v: f64) -> String {
    format!("{}", (v * 1e6).round() / 1e6)
}

/// A settle-gcode error as the harness reports it: a located one is bad input at its
/// file, line and column; an unreadable file a read error; a bad setting names `file` and
/// the setting.
pub fn gcode_error(file: &Path) -> impl Fn(GcodeError) -> Error + '_ {
    move |e| {
        let e = match e {
            GcodeError::Io {
                source_name,
                source,
            } => return Error::read(PathBuf::from(&*source_name), source),
            GcodeError::File(f) => return (*f).into(),
            GcodeError::Bgcode {
                source_name,
                source,
            } => {
                return Error::input(
                    PathBuf::from(&*source_name),
                    format!("binary G-code, {source}"),
                );
            }
            e => e,
        };
        if let Some(at) = e.location() {
            let prefix = format!("{at}: ");
            let text = e.to_string();
            let (key, message) = match &e {
                GcodeError::ConfigSetting { key, reason, .. } => {
                    (Some(key.clone()), reason.clone())
                }
                _ => (
                    None,
                    text.strip_prefix(&prefix).unwrap_or(&text).to_string(),
                ),
            };
            return Error::Input {
                at: Location {
                    line: usize::try_from(at.line).ok(),
                    column: at.column,
                    key,
                    ..Location::file(PathBuf::from(&*at.source_name))
                },
                message,
            };
        }
        if let GcodeError::JobSetting { key, reason } = &e {
            return Error::input_key(file, *key, reason.clone());
        }
        Error::input(file, e.to_string())
    }
}

/// The machine `--machine` names: a built-in preset, a machine file (either form), or a
/// scenario file (its `[machine]`), resolved by [`crate::expand::machine::named`].
fn named_machine(name: &str) -> Result<Named, Error> {
    crate::expand::machine::named(name, Path::new(""), true, &|m| Error::input("--machine", m))
}

/// The physical machine `--machine` names.
pub fn resolve_machine(name: &str) -> Result<Machine, Error> {
    match named_machine(name)?.form {
        MachineForm::Physical(m) => Ok(m),
        MachineForm::Modes(_) => Err(Error::input(
            "--machine",
            format!("`{name}` gives the machine by its modes; a physical machine is needed here"),
        )),
    }
}

/// The machine's axes for `driver`, and the same axes with the linear driver (whose
/// modes bound how fast a disturbance decays), and the machine's name. A machine given by
/// its modes has no driver: its axes are the modes (`driver` must be linear).
pub fn resolve_axes(
    name: &str,
    driver: DriverMode,
) -> Result<(String, Vec<AxisModel>, Vec<AxisModel>), Error> {
    let n = named_machine(name)?;
    if n.form.physical().is_none() && driver != DriverMode::Linear {
        return Err(Error::input(
            "--driver",
            format!(
                "`{name}` gives the machine by its modes: it has no driver model but the linear one"
            ),
        ));
    }
    let bad = |e: settle_sim::SimError| Error::input("--machine", e.to_string());
    let axes = n.form.axes(driver).map_err(bad)?;
    let linear = n.form.axes(DriverMode::Linear).map_err(bad)?;
    Ok((n.name, axes, linear))
}

/// The longest period (s) of the axes' oscillatory modes (their damped periods).
fn longest_period_s(linear_axes: &[AxisModel]) -> f64 {
    let rest = Profile::empty(State::default());
    linear_axes
        .iter()
        .filter_map(|a| LinearResponse::new(a, &rest).ok())
        .flat_map(|lr| lr.poles().to_vec())
        .filter(|p| p.im > 0.0)
        .map(|p| std::f64::consts::TAU / p.im)
        .fold(0.0, f64::max)
}

/// The fastest natural frequency (Hz) of the axes' modes, 0 when they have none.
fn fastest_mode_hz(linear_axes: &[AxisModel]) -> f64 {
    let rest = Profile::empty(State::default());
    linear_axes
        .iter()
        .filter_map(|a| LinearResponse::new(a, &rest).ok())
        .flat_map(|lr| lr.poles().to_vec())
        .map(|p| p.norm() / std::f64::consts::TAU)
        .fold(0.0, f64::max)
}

/// The highest `--sample-rate-hz` (Hz): fifty samples per period of a 2 kHz mode, far
/// above a printer's (a toolhead's highest modes are 100-300 Hz); a job's simulation time
/// grows with the rate.
pub const MAX_SAMPLE_RATE_HZ: f64 = 100_000.0;

/// `--sample-rate-hz` checked before any work: at least two samples per period of the
/// machine's fastest mode (`fastest_hz`; fewer alias it, and the contour error between
/// samples far apart is not seen: a scenario's `observe.sample_rate_hz` is held to the
/// same), at most [`MAX_SAMPLE_RATE_HZ`].
fn check_sample_rate(rate_hz: f64, fastest_hz: f64) -> Result<(), Error> {
    let min = 2.0 * fastest_hz;
    if rate_hz.is_finite() && rate_hz >= min && rate_hz > 0.0 && rate_hz <= MAX_SAMPLE_RATE_HZ {
        return Ok(());
    }
    if rate_hz.is_finite()
        && rate_hz > 0.0
        && rate_hz <= MAX_SAMPLE_RATE_HZ
        && min > MAX_SAMPLE_RATE_HZ
    {
        // No rate the replay takes resolves the mode: the machine is what to look at.
        return Err(Error::input(
            "--machine",
            format!(
                "its fastest mode, {fastest_hz:.1} Hz, needs a sample rate of two samples per period at least, {min:.1} Hz, above the most `settle gcode` takes ({MAX_SAMPLE_RATE_HZ} Hz): a toolhead's modes lie at tens to hundreds of Hz; check the machine's frequency_hz (in Hz)"
            ),
        ));
    }
    Err(Error::input(
        "--sample-rate-hz",
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            format!("{rate_hz}: give a finite number of Hz > 0")
        } else if rate_hz > MAX_SAMPLE_RATE_HZ {
            format!("{rate_hz} Hz is above the limit of {MAX_SAMPLE_RATE_HZ} Hz")
        } else {
            let better = if 20.0 * fastest_hz <= MAX_SAMPLE_RATE_HZ {
                format!(
                    "or twenty samples per period, {:.0} Hz, for contour errors to a few percent",
                    20.0 * fastest_hz
                )
            } else {
                format!(
                    "or the most, {MAX_SAMPLE_RATE_HZ} Hz, {:.1} samples per period",
                    MAX_SAMPLE_RATE_HZ / fastest_hz
                )
            };
            format!(
                "{rate_hz} Hz gives fewer than two samples per period of the machine's fastest mode ({fastest_hz:.1} Hz): give at least {min:.1} Hz (the default {DEFAULT_SAMPLE_RATE_HZ} Hz, {better})"
            )
        },
    ))
}

/// How much the ringing after the last move decays over the longest tail: 1e-3.
pub const TAIL_DECAY: f64 = 1e-3;

/// The longest simulation after the last move (s): the time the slowest mode needs to
/// decay by [`TAIL_DECAY`].
pub fn tail_s(slowest_decay_per_s: f64) -> f64 {
    (1.0 / TAIL_DECAY).ln() / slowest_decay_per_s
}

/// Which job axis (0 X, 1 Y, 2 Z) each machine axis follows, and the machine indices of
/// X and Y.
fn axis_map(axes: &[AxisModel]) -> Result<(Vec<usize>, [usize; 2]), String> {
    let mut map = Vec::new();
    for a in axes {
        map.push(match a.name.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            other => {
                return Err(format!(
                    "machine axis `{other}` has no G-code axis; a G-code job drives axes named x, y and z"
                ));
            }
        });
    }
    let find = |j: usize| map.iter().position(|&m| m == j);
    match (find(0), find(1)) {
        (Some(x), Some(y)) => Ok((map, [x, y])),
        _ => Err("a G-code job needs a machine with axes x and y".into()),
    }
}

/// Simulate the job without writing anything.
pub fn measure(opts: &GcodeOptions) -> Result<GcodeOutcome, Error> {
    simulate(opts, None, None).map(|(o, _)| o)
}

/// How far a simulation has read its G-code file: called as it goes with the bytes read
/// and the file's size.
pub type Progress<'a> = &'a dyn Fn(u64, u64);

/// Simulate the job, recording the counted samples into `rec` when given, telling
/// `progress` how far it has read.
fn simulate(
    opts: &GcodeOptions,
    rec: Option<record::Recorder>,
    progress: Option<Progress<'_>>,
) -> Result<(GcodeOutcome, Option<record::Recorder>), Error> {
    let (machine_name, axes, linear_axes) = resolve_axes(&opts.machine, opts.driver)?;
    // A machine with an undamped mode never settles: no tail, and a layer range cannot
    // start from the state the layers before leave.
    let sigma = slowest_decay_per_s(&linear_axes).map_err(|m| Error::input("--machine", m));
    if opts.layers.is_some() && sigma.is_err() {
        return Err(Error::input(
            "--layers",
            "the machine has an undamped mode: its vibration never decays, so a layer range cannot start from the state the layers before leave; simulate the whole file",
        ));
    }
    let (job_axes, xy) = axis_map(&axes).map_err(|m| Error::input("--machine", m))?;
    if opts.backend == Backend::Modal && opts.driver != DriverMode::Linear {
        return Err(Error::input(
            "--backend",
            "the modal backend solves the linear driver model only; use --backend rapier for the others",
        ));
    }
    if !opts.backend.available() {
        return Err(Error::input("--backend", NO_MUJOCO));
    }
    check_sample_rate(opts.sample_rate_hz, fastest_mode_hz(&linear_axes))?;
    let names = axes.iter().map(|a| a.name.clone()).collect();
    let sopts = StreamOptions {
        sample_rate_hz: opts.sample_rate_hz,
        job_axes,
        names,
        xy,
        top_spots: 10,
        maps: opts.maps,
        map_layer: opts.map_layer,
        layers: opts.layers,
        tail_s: sigma.as_ref().map_or(0.0, |&s| tail_s(s)),
        tail_hold_s: longest_period_s(&linear_axes),
    };
    let err = gcode_error(&opts.file);
    let reader_options = ReaderOptions {
        skip_bad_lines: opts.skip_bad_lines,
        ..opts.job.reader_options()
    };
    // The modal backend's linearisation point, where a position-dependent stiffness
    // makes it matter: one pass of the reader over the whole file.
    let point = match opts.backend == Backend::Modal && depends_on_position(&axes) {
        true => Some(
            linearisation_point(Reader::open(&opts.file, reader_options.clone()).map_err(&err)?)
                .map_err(&err)?,
        ),
        false => None,
    };
    let reader = Reader::open(&opts.file, reader_options).map_err(&err)?;
    let mut job = Job::new(reader, opts.job.clone())
        .map_err(&err)?
        .with_name(opts.file.display().to_string());
    if let Some((a, b)) = opts.layers {
        job = job
            .with_layers(a..=b)
            .and_then(|j| j.with_preroll_s(sigma.as_ref().map_or(0.0, |&s| preroll_s(s))))
            .map_err(&err)?;
    }
    // On the modal backend: linearised where the print is, the same point for the whole
    // run and any layer range ([`crate::studies::gcode::linpoint`]); a range starts at rest
    // in the commanded state of its pre-roll.
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let options = SimOptions {
        linearise_at_m: point.as_ref().map(|p| p.on_axes(&names)),
        // Every planner starts the job at the origin: rapier's step is sized there, for
        // the whole file and any layer range alike.
        step_at_m: Some(vec![0.0; names.len()]),
        ..SimOptions::default()
    };
    let (streamed, rec) = simulate_job(
        &mut job,
        opts.backend,
        axes,
        &options,
        sopts,
        rec,
        (&opts.file, progress),
    )?;
    if let Some(at) = rec.as_ref().and_then(record::Recorder::full) {
        let (bound, rate) = (opts.mcap_max_samples, opts.sample_rate_hz);
        return Err(Error::input("--mcap", recording_too_long(at, bound, rate)));
    }
    job.run_to_end().map_err(&err)?;
    let summary = job.summary();
    if let Some(why) = crate::studies::gcode::work::nothing_to_measure(
        &summary,
        job.reader().lines_read(),
        job.reader().looks(),
    ) {
        return Err(Error::input(&opts.file, why));
    }
    if let Some(why) = opts
        .layers
        .and_then(|r| crate::studies::gcode::work::no_work_in(&summary, r))
    {
        return Err(Error::input("--layers", why));
    }
    let mut by_layer: BTreeMap<u32, stats::LayerStats> = streamed
        .layers
        .iter()
        .map(|l| (l.layer, l.clone()))
        .collect();
    let layers = summary
        .layers
        .iter()
        .map(|l| LayerRow {
            layer: l.layer,
            z_mm: l.z_mm,
            start_s: l.start_time_s,
            duration_s: l.duration_s,
            moves: l.moves,
            print_z_mm: l.print_z_mm,
            opened_by: l.opened_by,
            stats: by_layer.remove(&l.layer),
        })
        .collect();
    let outcome = GcodeOutcome {
        file: opts.file.clone(),
        firmware: opts.job.firmware(),
        setting: setting_name(&opts.job),
        machine: machine_name,
        backend: opts.backend,
        print_time_s: summary.print_time_s,
        layers,
        worst_um: streamed.worst.first().map_or(0.0, |s| s.error_um),
        p95_um: streamed.all.quantile_um(0.95),
        streamed,
        skipped_lines: job.reader().skipped().count,
        ignored: summary.ignored,
        features: summary.features,
        overrides: summary.overrides,
        files: Vec::new(),
        versus: None,
        recording: None,
        linearised_at: point,
        config: opts
            .config
            .as_ref()
            .map(|c| {
                (
                    format!(
                        "settings from {}: {}",
                        c.path.display(),
                        config_settings(&opts.job)
                    ),
                    c.notes.clone(),
                )
            })
            .or_else(|| {
                // Which printer's settings a Prusa job runs with, and why.
                let p = opts.job.prusa.as_ref()?;
                Some((format!("{p}: {}", config_settings(&opts.job)), Vec::new()))
            }),
        grbl_steps_per_mm: match &opts.job.planner {
            settle_gcode::job::PlannerConfig::Grbl(g) => {
                Some([g.steps_per_mm[0], g.steps_per_mm[1]])
            }
            _ => None,
        },
    };
    Ok((outcome, rec))
}

/// Which printer a Prusa job runs as under `--config`: the configuration's (`from`, read
/// from `config`), said; a file sliced for another family (its `M862.3 P`, in `job`, the
/// settings the file alone gives) is said too, as Buddy warns of it before printing.
fn prusa_printers(
    file: &Path,
    config: &Path,
    from: Option<&settle_gcode::job::PrusaPrinter>,
    job: &JobConfig,
) -> Vec<String> {
    let Some(printer) = from else {
        return Vec::new();
    };
    let mut notes = vec![match &printer.named_at {
        Some((line, name)) => format!(
            "{}:{line}: planned as the printer the configuration names, a Prusa {name} (M115's MACHINE_TYPE; the {}'s settings stand for what the replies do not give)",
            config.display(),
            printer.model
        ),
        None => format!(
            "{}: planned with the replies over the MK4's settings (no M115 reply names the printer)",
            config.display()
        ),
    }];
    if let Some(sliced) = job.prusa.as_ref().filter(|p| p.model != printer.model)
        && let Some((line, name)) = &sliced.named_at
    {
        notes.push(format!(
                "{}:{line}: the file was sliced for a Prusa {name} (M862.3 P), not the configuration's {}: planned as the configuration's printer",
                file.display(),
                printer.model
            ));
    }
    notes
}

/// The planner's limits and the shapers of `job` in words, in the firmware's terms
/// (`klipper: max_velocity 300 mm/s, max_accel 5000 mm/s^2, ...; shaper X mzv@52.4 Hz,
/// Y ei@41.5 Hz`).
pub fn config_settings(job: &JobConfig) -> String {
    use settle_gcode::job::PlannerConfig;
    let limits = match &job.planner {
        PlannerConfig::Klipper(k) => format!(
            "max_velocity {} mm/s, max_accel {} mm/s^2, minimum_cruise_ratio {}, square_corner_velocity {} mm/s",
            mm(k.max_velocity_m_s),
            mm(k.max_accel_m_s2),
            k.minimum_cruise_ratio,
            mm(k.square_corner_velocity_m_s)
        ),
        PlannerConfig::Rrf(c) => format!(
            "M203 X{} Y{} mm/s, M201 X{} Y{} mm/s^2, M204 P{} T{} mm/s^2, M566 X{} Y{} mm/s",
            mm(c.max_feedrate_m_s[0]),
            mm(c.max_feedrate_m_s[1]),
            mm(c.max_accel_m_s2[0]),
            mm(c.max_accel_m_s2[1]),
            mm(c.print_accel_m_s2),
            mm(c.travel_accel_m_s2),
            mm(c.instant_dv_m_s[0]),
            mm(c.instant_dv_m_s[1])
        ),
        PlannerConfig::Grbl(g) => format!(
            "$110 {} $111 {} mm/min, $120 {} $121 {} mm/s^2, $11 {} mm, $32={}",
            g.max_rate_mm_min[0],
            g.max_rate_mm_min[1],
            g.accel_mm_s2[0],
            g.accel_mm_s2[1],
            g.junction_deviation_mm,
            u8::from(g.laser_mode)
        ),
        PlannerConfig::Marlin(c) | PlannerConfig::Prusa(c) => {
            use settle_planner::firmware::marlin::MarlinJerk;
            let corner = match c.jerk {
                MarlinJerk::JunctionDeviation { deviation_m, .. } => {
                    format!("M205 J{} mm", mm(deviation_m))
                }
                MarlinJerk::Classic { max_jerk_m_s, .. } => format!(
                    "M205 X{} Y{} mm/s (classic jerk)",
                    mm(max_jerk_m_s[0]),
                    mm(max_jerk_m_s[1])
                ),
            };
            // Buddy's planner counts quarter steps: its M92 is a quarter of the planner's.
            let (per_step, quarter) = match &job.planner {
                PlannerConfig::Prusa(_) => (
                    settle_planner::firmware::marlin::PLANNER_STEPS_MULTIPLIER,
                    " (planned in quarter steps)",
                ),
                _ => (1.0, ""),
            };
            // Steps per m as steps per mm, rounded to 1e-6 (`80`, not `80.00000000000001`).
            let per_mm = |v: f64| format!("{}", (v / per_step * 1e3).round() / 1e6);
            format!(
                "M203 X{} Y{} mm/s, M201 X{} Y{} mm/s^2, M204 P{} T{} mm/s^2, {corner}, M92 X{} Y{} steps/mm{quarter}",
                mm(c.max_feedrate_m_s[0]),
                mm(c.max_feedrate_m_s[1]),
                mm(c.max_accel_m_s2[0]),
                mm(c.max_accel_m_s2[1]),
                mm(c.print_accel_m_s2),
                mm(c.travel_accel_m_s2),
                per_mm(c.steps_per_m[0]),
                per_mm(c.steps_per_m[1])
            )
        }
        PlannerConfig::Settle(_) => "the firmware's defaults".into(),
    };
    format!(
        "{}: {limits}; {}",
        job.firmware(),
        shaper_words(&job.shapers)
    )
}

/// A length, speed or acceleration in m (per s, s^2) as mm, rounded to 1e-6 mm: the
/// configuration's own number, not its round trip through metres (`70`, not
/// `70.00000000000001`).
fn mm(si: f64) -> String {
    format!("{}", (si * 1e9).round() / 1e6)
}

/// The X and Y shapers in words: `shaper mzv@48 Hz on X and Y`, `no shaper`, or per axis.
fn shaper_words(shapers: &[Option<ShaperSetting>; 3]) -> String {
    let name = |s: &Option<ShaperSetting>| {
        s.map_or("none".to_string(), |s| {
            format!("{}@{} Hz", s.shaper_type.name(), s.frequency_hz)
        })
    };
    match (&shapers[0], &shapers[1]) {
        (None, None) => "no shaper".into(),
        (x, y) if x == y => format!("shaper {} on X and Y", name(x)),
        (x, y) => format!("shaper X {}, Y {}", name(x), name(y)),
    }
}

/// The planner and the X and Y shapers in words: `klipper + mzv@48 Hz`, `settle` when
/// unshaped, both shapers when they differ; Prusa's with the printer whose settings it
/// runs (`prusa MINI + X mzv@118.2 Hz, Y mzv@32.8 Hz`).
pub fn setting_name(job: &JobConfig) -> String {
    let name = |s: &Option<ShaperSetting>| {
        s.map(|s| format!("{}@{} Hz", s.shaper_type.name(), s.frequency_hz))
    };
    let firmware = match &job.prusa {
        Some(p) => format!("{} {}", job.firmware(), p.model),
        None => job.firmware().to_string(),
    };
    match (name(&job.shapers[0]), name(&job.shapers[1])) {
        (None, None) => firmware,
        (x, y) if x == y => format!("{firmware} + {}", x.unwrap_or_default()),
        (x, y) => format!(
            "{firmware} + X {}, Y {}",
            x.unwrap_or_else(|| "none".into()),
            y.unwrap_or_else(|| "none".into())
        ),
    }
}

/// `settle gcode`: simulate, then write layers.csv, summary.md and the ringing maps into
/// the output folder.
pub fn gcode(opts: &GcodeOptions) -> Result<GcodeOutcome, Error> {
    gcode_with_progress(opts, None)
}

/// [`gcode`], telling `progress` how far each simulation (the job's, then `--versus`'s)
/// has read the file.
pub fn gcode_with_progress(
    opts: &GcodeOptions,
    progress: Option<Progress<'_>>,
) -> Result<GcodeOutcome, Error> {
    let dir = match &opts.out {
        Some(d) => d.clone(),
        None => {
            let stem = opts
                .file
                .file_stem()
                .map_or("job".into(), |s| s.to_string_lossy().into_owned());
            PathBuf::from("results").join(format!("{stem}-gcode"))
        }
    };
    // The output folder, before any work: never an input, nor earlier results unasked.
    crate::output::folder::check(&dir, &RESULTS, opts.force, &opts.inputs(), writes)?;
    // The recording streams into a temporary file inside the folder, made for it (and
    // removed again, with the folder it needed, when the run fails: a bad file writes
    // nothing).
    let made = opts.mcap && std::fs::symlink_metadata(&dir).is_err();
    let simulated = (|| {
        let rec = match opts.mcap {
            true => {
                crate::output::atomic::create_dir(&dir)?;
                Some(record::Recorder::start(
                    recording_metadata(opts),
                    &dir.join(RECORDING),
                    opts.mcap_max_samples,
                )?)
            }
            false => None,
        };
        simulate(opts, rec, progress)
    })();
    if simulated.is_err() && made {
        let _ = std::fs::remove_dir(&dir);
    }
    let (mut outcome, rec) = simulated?;
    let b_opts = match opts.versus {
        Some((fw, shapers)) => Some(compare::versus(opts, fw, shapers)?),
        None => None,
    };
    let b = match &b_opts {
        Some(b_opts) => Some(simulate(b_opts, None, progress)?.0),
        None => None,
    };
    outcome.files = report::write(&outcome, &dir)?;
    if let Some(rec) = rec {
        let path = dir.join(RECORDING);
        outcome.recording = Some(rec.finish(recording_metrics(&outcome), &path)?);
        outcome.files.push(path);
    }
    if let (Some(b_opts), Some(b)) = (&b_opts, &b) {
        let files = compare::compare((&outcome, opts), (b, b_opts), &dir)?;
        outcome.files.extend(files);
        outcome.versus = Some(Box::new(b.clone()));
    }
    let html = report::write_html(&outcome, opts, &dir)?;
    outcome.files.push(html);
    Ok(outcome)
}

/// Why a recording past its bound (`bound` samples) is refused, `at` the first sample it
/// refused.
fn recording_too_long(at: record::Refused, bound: u64, sample_rate_hz: f64) -> String {
    format!(
        "the recording reached its bound of {bound} samples ({:.0} s of print at {} Hz, \
         about {:.1} GB of file) at t = {:.3} s, line {}, layer {}: nothing was written; \
         record the layers you want to look at with --layers A..B, or sample less often \
         with --sample-rate-hz",
        bound as f64 / sample_rate_hz,
        sample_rate_hz,
        bound as f64 * record::BYTES_PER_SAMPLE / 1e9,
        at.t_s,
        at.line,
        at.layer
    )
}

/// `--mcap`'s recording in the output folder.
const RECORDING: &str = "recording.mcap";

/// An earlier run's results in the output folder, which `--force` overwrites.
const RESULTS: crate::output::folder::Results<'static> = crate::output::folder::Results {
    what: "settle gcode",
    marks: &[
        "layers.csv",
        "summary.md",
        "features.csv",
        "layer_features.csv",
        "error-z.svg",
        "error-z.png",
        report::REPORT,
        compare::FILE,
        RECORDING,
    ],
};

/// Whether `settle gcode` writes `rel` in its output folder.
fn writes(rel: &Path) -> bool {
    crate::output::folder::written(
        rel,
        RESULTS.marks,
        &[],
        &[
            ("ringing-layer-", ".svg"),
            ("ringing-layer-", ".png"),
            ("split-layer-", ".svg"),
            ("split-layer-", ".png"),
            ("compare-layer-", ".svg"),
            ("compare-layer-", ".png"),
        ],
    )
}

impl GcodeOptions {
    /// The files the run reads: the G-code, the machine file or scenario (a path), the
    /// configuration and what it includes.
    pub fn inputs(&self) -> settle_files::write::Inputs {
        let mut inputs = settle_files::write::Inputs::of([&self.file]);
        inputs.add(Path::new(&self.machine));
        if let Some(c) = &self.config {
            inputs.add(&c.path);
            for f in &c.files {
                inputs.add(f);
            }
        }
        inputs
    }
}

/// The `settle` metadata record of `--mcap`'s recording.
fn recording_metadata(opts: &GcodeOptions) -> BTreeMap<String, String> {
    let layers = opts
        .layers
        .map_or("all".to_string(), |(a, b)| format!("{a}..{b}"));
    BTreeMap::from([
        (
            "settle_version".to_string(),
            env!("CARGO_PKG_VERSION").to_string(),
        ),
        ("gcode_file".to_string(), opts.file.display().to_string()),
        ("machine".to_string(), opts.machine.clone()),
        ("setting".to_string(), setting_name(&opts.job)),
        ("backend".to_string(), opts.backend.name().to_string()),
        ("layers".to_string(), layers),
        (
            "sample_rate_hz".to_string(),
            opts.sample_rate_hz.to_string(),
        ),
    ])
}

/// The `/metrics` message of `--mcap`'s recording.
fn recording_metrics(o: &GcodeOutcome) -> serde_json::Map<String, serde_json::Value> {
    use serde_json::json;
    let mut m = record::metrics(&[
        ("gcode_file", json!(o.file.display().to_string())),
        ("setting", json!(o.setting)),
        ("machine", json!(o.machine)),
        ("backend", json!(o.backend.name())),
        ("print_time_s", record::num(o.print_time_s)),
        ("contour_worst_um", record::num(o.worst_um)),
        ("contour_p95_um", record::num(o.p95_um)),
        ("simulated_s", record::num(o.streamed.simulated_s)),
        ("preroll_s", record::num(o.streamed.preroll_s)),
    ]);
    if let Some(t) = &o.streamed.tail {
        m.insert("end_residual_um".into(), record::num(t.residual_peak_um));
    }
    if let Some(p) = &o.linearised_at {
        m.insert("linearised_at_mm".into(), json!(p.xyz_mm));
    }
    if let Some(w) = o.worst().first() {
        m.insert("contour_worst_line".into(), json!(w.line));
    }
    m
}

pub use crate::studies::gcode::parse_layers;

/// An input shaper as written on the command line: `KIND@FREQ_HZ` or
/// `KIND@FREQ_HZ/DAMPING` (damping 0.1 when not given, Klipper's default), e.g. `mzv@48`.
pub fn parse_shaper(s: &str) -> Result<ShaperSetting, String> {
    let bad = || {
        format!(
            "`{s}`: a shaper is KIND@FREQ_HZ or KIND@FREQ_HZ/DAMPING, e.g. mzv@48 or ei@52/0.08"
        )
    };
    let (kind, rest) = s.split_once('@').ok_or_else(bad)?;
    let (f, z) = match rest.split_once('/') {
        Some((f, z)) => (f, z.parse::<f64>().map_err(|_| bad())?),
        None => (rest, 0.1),
    };
    let frequency_hz = f.parse::<f64>().map_err(|_| bad())?;
    // As the job's own files set it (printer.cfg's shaper_freq_*, M593 F): at most 1 kHz.
    let max = settle_gcode::config::MAX_SHAPER_FREQUENCY_HZ;
    if frequency_hz > max {
        return Err(format!(
            "`{s}`: {f} Hz is above {max} Hz, the highest shaper frequency a G-code replay takes (as printer.cfg's shaper_freq_* and M593 F): a shaper tuned above 1 kHz cancels nothing a printer's belts or frame carry"
        ));
    }
    let kind = settle_planner::shaper::ShaperType::parse(kind).map_err(|e| e.to_string())?;
    let setting = ShaperSetting {
        shaper_type: kind,
        frequency_hz,
        damping_ratio: z,
    };
    setting.build().map_err(|e| format!("`{s}`: {e}"))?;
    Ok(setting)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_ranges_and_shapers_parse() {
        assert_eq!(parse_layers("2..3"), Ok((2, 3)));
        assert_eq!(parse_layers("2..=3"), Ok((2, 3)));
        assert_eq!(parse_layers("4"), Ok((4, 4)));
        assert!(parse_layers("3..2").is_err());
        assert!(parse_layers("a..2").is_err());
        let s = parse_shaper("mzv@48").expect("shaper");
        assert_eq!((s.frequency_hz, s.damping_ratio), (48.0, 0.1));
        assert!(parse_shaper("mzv").is_err());
        assert!(parse_shaper("nope@40").is_err());
    }
}
