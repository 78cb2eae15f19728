//! `settle gcode`: a G-code job replayed through a firmware's planner (settle-gcode's
//! [`Job`]) on a machine, streaming, with its ringing map.
//!
//! The job's shaped X, Y (and Z, when the machine has it) motion drives the machine's
//! axes of the same names, in the G-code's coordinates (position 0 of a machine axis is
//! G-code 0). Per sample the toolhead's contour error ([`crate::kinds::gcode::contour`]) is measured, per move
//! its largest value (the ringing after the corner at the move's start), per layer the
//! worst and 95th percentile over printing samples ([`crate::kinds::gcode::stats`]); the outputs are
//! `layers.csv`, `summary.md` and the ringing maps of the worst layers ([`report`]).
//! Everything is computed before anything is written: a bad file writes nothing.

pub mod compare;
pub mod report;
pub mod stream;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use settle_gcode::job::{Firmware, Job, JobConfig, ShaperSetting};
use settle_gcode::{GcodeError, Reader, ReaderOptions};
use settle_sim::machine::Machine;
use settle_sim::{AxisModel, DriverMode, ModalPlant, RapierOptions, RapierPlant};

use crate::error::{Error, Location};
use crate::kinds::gcode::stats::{self, LayerMap, Spot};
use crate::spec::backend::{Backend, NO_MUJOCO};
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
    /// A second setting to compare with (`--versus`): firmware and X/Y shaper.
    pub versus: Option<(Firmware, Option<ShaperSetting>)>,
}

impl GcodeOptions {
    /// `file` on `machine` with `firmware`'s defaults, the modal backend and the linear
    /// driver (what the modal backend solves exactly).
    pub fn new(file: PathBuf, machine: &str, firmware: Firmware) -> Result<Self, Error> {
        let job = JobConfig::defaults(firmware).map_err(gcode_error(&file))?;
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
        })
    }

    /// The same input shaper on X and Y.
    pub fn with_shaper(mut self, shaper: Option<ShaperSetting>) -> Self {
        self.job.shapers[0] = shaper;
        self.job.shapers[1] = shaper;
        self
    }
}

/// One row of layers.csv.
#[derive(Debug, Clone)]
pub struct LayerRow {
    /// Layer index.
    pub layer: u32,
    /// Its Z (mm), where the file says.
    pub z_mm: Option<f64>,
    /// When it starts (s).
    pub start_s: f64,
    /// How long it takes (s).
    pub duration_s: f64,
    /// Moves in it.
    pub moves: u64,
    /// Its contour-error account, when it was simulated.
    pub stats: Option<stats::LayerStats>,
}

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
    /// Files written.
    pub files: Vec<PathBuf>,
    /// The outcome of the `--versus` setting.
    pub versus: Option<Box<GcodeOutcome>>,
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

    /// What the binary prints, and exit 1 when the simulation failed.
    pub fn report(&self) -> Report {
        let failed = self.streamed.fault.is_some() || self.streamed.lost_steps > 0;
        let mut r = Report::new(if failed { Exit::Failed } else { Exit::Ok });
        r.out(format!(
            "{}: {} on {} ({}): print time {:.1} s, contour error worst {:.2} um, p95 {:.2} um",
            self.file.display(),
            self.firmware,
            self.machine,
            self.backend.name(),
            self.print_time_s,
            self.worst_um,
            self.p95_um
        ));
        if let Some(s) = self.worst().first() {
            r.out(format!(
                "worst at line {} (layer {}, X {:.2} Y {:.2} mm)",
                s.line, s.layer, s.x_mm, s.y_mm
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
            r.err(format!("lost steps: {}", self.streamed.lost_steps));
        }
        if self.skipped_lines > 0 {
            r.err(format!("skipped {} bad lines", self.skipped_lines));
        }
        r
    }
}

/// A settle-gcode error as the harness reports it: a located one is bad input at its
/// file, line and column; an unreadable file a read error; a bad setting names `file` and
/// the setting.
pub fn gcode_error(file: &Path) -> impl Fn(GcodeError) -> Error + '_ {
    move |e| {
        if let GcodeError::Io {
            source_name,
            source,
        } = e
        {
            return Error::read(PathBuf::from(&*source_name), source);
        }
        if let Some(at) = e.location() {
            let prefix = format!("{at}: ");
            let text = e.to_string();
            let message = text.strip_prefix(&prefix).unwrap_or(&text).to_string();
            return Error::Input {
                at: Location {
                    line: usize::try_from(at.line).ok(),
                    column: at.column,
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

/// The machine `--machine` names: a built-in preset, a machine file, or a scenario file
/// (its `[machine]`).
pub fn resolve_machine(name: &str) -> Result<Machine, Error> {
    let here = Path::new("--machine");
    let src = crate::input::source::Source::new("", here);
    let path = Path::new(name);
    let is_scenario = name.ends_with(".toml")
        && std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("machine"));
    if is_scenario {
        let (sc, src) = crate::expand::load(path)?;
        let m = crate::expand::machine::resolve_machine(&sc, &src)?.machine;
        return m.ok_or_else(|| {
            Error::input_key(
                path,
                "machine",
                "a G-code job needs a physical machine (a preset, machine file or axis tables), not `modes`",
            )
        });
    }
    let base = std::env::current_dir().unwrap_or_default().join("here");
    crate::input::machine_file::load_preset(name, &base, &src)
        .map(|(m, _, _)| m)
        .map_err(|e| match e {
            Error::Input { message, .. } if !name.ends_with(".toml") => {
                Error::input(here, message.replace("machine.preset", "--machine"))
            }
            other => other,
        })
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
    let machine = resolve_machine(&opts.machine)?;
    let axes = machine
        .compile(opts.driver)
        .map_err(|e| Error::input("--machine", e.to_string()))?;
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
    if !(opts.sample_rate_hz.is_finite() && opts.sample_rate_hz > 0.0) {
        return Err(Error::input(
            "--sample-rate-hz",
            "the sample rate must be a positive number of Hz",
        ));
    }
    let names = axes.iter().map(|a| a.name.clone()).collect();
    let sopts = StreamOptions {
        sample_rate_hz: opts.sample_rate_hz,
        job_axes,
        names,
        xy,
        top_spots: 10,
        maps: opts.maps,
        map_layer: opts.map_layer,
    };
    let err = gcode_error(&opts.file);
    let reader = Reader::open(
        &opts.file,
        ReaderOptions {
            skip_bad_lines: opts.skip_bad_lines,
            ..ReaderOptions::new(opts.job.dialect)
        },
    )
    .map_err(&err)?;
    let mut job = Job::new(reader, opts.job.clone())
        .map_err(&err)?
        .with_name(opts.file.display().to_string());
    if let Some((a, b)) = opts.layers {
        job = job.with_layers(a..=b).map_err(&err)?;
    }
    let sim_err = |source| Error::Sim { run: 0, source };
    let dt = 1.0 / opts.sample_rate_hz;
    let streamed = match opts.backend {
        Backend::Modal => simulate_job(
            &mut job,
            &ModalPlant::new(axes, dt).map_err(sim_err)?,
            sopts,
            &opts.file,
        )?,
        Backend::Rapier => simulate_job(
            &mut job,
            &RapierPlant::new(
                axes,
                RapierOptions {
                    max_step_s: None,
                    belt: Default::default(),
                },
            )
            .map_err(sim_err)?,
            sopts,
            &opts.file,
        )?,
        #[cfg(feature = "mujoco")]
        Backend::Mujoco => simulate_job(
            &mut job,
            &settle_sim::mujoco::MujocoPlant::new(axes, Default::default()).map_err(sim_err)?,
            sopts,
            &opts.file,
        )?,
        #[cfg(not(feature = "mujoco"))]
        Backend::Mujoco => return Err(Error::input("--backend", NO_MUJOCO)),
    };
    job.run_to_end().map_err(&err)?;
    let summary = job.summary();
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
            stats: by_layer.remove(&l.layer),
        })
        .collect();
    Ok(GcodeOutcome {
        file: opts.file.clone(),
        firmware: opts.job.firmware(),
        setting: setting_name(&opts.job),
        machine: machine.name.clone(),
        backend: opts.backend,
        print_time_s: summary.print_time_s,
        layers,
        worst_um: streamed.worst.first().map_or(0.0, |s| s.error_um),
        p95_um: streamed.all.quantile_um(0.95),
        streamed,
        skipped_lines: job.reader().skipped().count,
        ignored: summary.ignored,
        files: Vec::new(),
        versus: None,
    })
}

/// The planner and the X and Y shapers in words: `klipper + mzv@48 Hz`, `settle` when
/// unshaped, both shapers when they differ.
pub fn setting_name(job: &JobConfig) -> String {
    let name =
        |s: &Option<ShaperSetting>| s.map(|s| format!("{}@{} Hz", s.kind.name(), s.frequency_hz));
    match (name(&job.shapers[0]), name(&job.shapers[1])) {
        (None, None) => job.firmware().to_string(),
        (x, y) if x == y => format!("{} + {}", job.firmware(), x.unwrap_or_default()),
        (x, y) => format!(
            "{} + X {}, Y {}",
            job.firmware(),
            x.unwrap_or_else(|| "none".into()),
            y.unwrap_or_else(|| "none".into())
        ),
    }
}

/// `settle gcode`: simulate, then write layers.csv, summary.md and the ringing maps into
/// the output folder.
pub fn gcode(opts: &GcodeOptions) -> Result<GcodeOutcome, Error> {
    let mut outcome = measure(opts)?;
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
    let b_opts = match opts.versus {
        Some((fw, shaper)) => Some(compare::versus(opts, fw, shaper)?),
        None => None,
    };
    let b = match &b_opts {
        Some(b_opts) => Some(measure(b_opts)?),
        None => None,
    };
    outcome.files = report::write(&outcome, &dir)?;
    if let (Some(b_opts), Some(b)) = (&b_opts, &b) {
        let files = compare::compare((&outcome, opts), (b, b_opts), &dir)?;
        outcome.files.extend(files);
        outcome.versus = Some(Box::new(b.clone()));
    }
    let html = report::write_html(&outcome, opts, &dir)?;
    outcome.files.push(html);
    Ok(outcome)
}

pub use crate::kinds::gcode::parse_layers;

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
    let kind = settle_planner::shaper::ShaperKind::parse(kind).map_err(|e| e.to_string())?;
    let setting = ShaperSetting {
        kind,
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
