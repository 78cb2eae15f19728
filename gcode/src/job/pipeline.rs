//! The job: reader events in, shaped chunks out (see the module doc of [`crate::job`]).

use std::collections::{BTreeMap, VecDeque};
use std::io::BufRead;
use std::ops::RangeInclusive;
use std::path::Path as FsPath;
use std::sync::Arc;

use settle_planner::PlanError;
use settle_planner::firmware::profiles::ProfileStream;

use super::chunk::{JobChunk, JobSummary, LimitOverride};
use super::config::{JobConfig, PlannerConfig, ShaperSetting};
use super::driver::Driver;
use super::input::{AxisShapers, Input};
use super::moves::MoveTable;
use super::settle::SettlePlanner;
use super::shapers::ShaperState;
use super::travel::Travel;
use crate::config::GrblSettings;
use crate::error::GcodeError;
use crate::read::geometry::Point;
use crate::read::reader::Reader;

mod events;

/// Millimetres to metres.
const MM: f64 = 1e-3;

#[derive(Debug)]
enum Planner {
    Firmware(Driver, Box<ProfileStream>),
    Settle(Box<SettlePlanner>),
}

/// Where the job is relative to the layer range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Range {
    Before,
    In,
    After,
}

/// A G-code file planned by a firmware and shaped, streaming (see [`crate::job`]).
#[derive(Debug)]
pub struct Job<R> {
    reader: Reader<R>,
    source: Arc<str>,
    cfg: JobConfig,
    planner: Planner,
    shapers: ShaperState,
    input: Input,
    table: MoveTable,
    layers: Option<(u32, u32)>,
    range: Range,
    seq: u64,
    moves: u64,
    out: VecDeque<JobChunk>,
    eof: bool,
    points: Vec<Point>,
    /// Where the last move ended, and its feed (mm, mm/s).
    last_end: Point,
    /// Where the firmware stands when it is not where the file put it (RepRapFirmware
    /// after an arc cut short at its limits): the next move starts here.
    resync: Option<Point>,
    last_feed_mm_s: f64,
    limit_changes: u64,
    shaper_changes: u64,
    ignored: BTreeMap<String, u64>,
    /// GRBL: the `$` settings in force.
    grbl: Option<GrblSettings>,
    /// The machine's travel and the firmware's rule for moves that leave it.
    travel: Travel,
    /// The planner's limits at the start (the configuration's), by name.
    start_limits: Vec<(&'static str, f64)>,
    /// Limits the file raised above them.
    overrides: Vec<LimitOverride>,
}

impl Job<crate::FileInput> {
    /// Open `path` and plan it with `cfg` (read in `cfg.dialect`).
    pub fn open(path: impl AsRef<FsPath>, cfg: JobConfig) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let reader = Reader::open(path, cfg.reader_options())?;
        Ok(Job::new(reader, cfg)?.with_name(path.display().to_string()))
    }
}

fn build(s: &[Option<ShaperSetting>; 3]) -> Result<AxisShapers, PlanError> {
    let b = |i: usize| s[i].as_ref().map(ShaperSetting::build).transpose();
    Ok([b(0)?, b(1)?, b(2)?, None])
}

impl<R: BufRead> Job<R> {
    /// Plan what `reader` reads with `cfg` (the reader's dialect is the caller's choice;
    /// [`Job::open`] uses `cfg.dialect`).
    pub fn new(reader: Reader<R>, cfg: JobConfig) -> Result<Self, GcodeError> {
        let setting = |key: &'static str| {
            move |e: PlanError| GcodeError::JobSetting {
                key,
                reason: e.to_string(),
            }
        };
        let planner = match &cfg.planner {
            PlannerConfig::Settle(c) => {
                Planner::Settle(Box::new(SettlePlanner::new(c).map_err(setting("settle"))?))
            }
            other => match Driver::new(other).map_err(setting("planner"))? {
                Some(d) => Planner::Firmware(
                    d,
                    Box::new(ProfileStream::new(cfg.profiles).map_err(setting("profiles"))?),
                ),
                None => {
                    return Err(GcodeError::JobSetting {
                        key: "planner",
                        reason: "no planner".into(),
                    });
                }
            },
        };
        let initial = build(&cfg.shapers).map_err(setting("shapers"))?;
        let cfg_feed = cfg.dialect.initial_feed_mm_s();
        let grbl = match &cfg.planner {
            PlannerConfig::Grbl(g) => Some(g.clone()),
            _ => None,
        };
        let travel = Travel::new(
            cfg.firmware(),
            cfg.travel_mm,
            grbl.as_ref().is_some_and(|g| g.soft_limits),
        );
        let start_limits = match &planner {
            Planner::Firmware(d, _) => d.limits(),
            Planner::Settle(_) => Vec::new(),
        };
        Ok(Self {
            reader,
            source: Arc::from("<input>"),
            shapers: match &cfg.prusa {
                Some(p) => ShaperState::new(cfg.firmware(), &cfg.shapers).with_prusa_model(p.model),
                None => ShaperState::new(cfg.firmware(), &cfg.shapers),
            },
            input: Input::new(cfg.alignment, initial, false),
            cfg,
            planner,
            table: MoveTable::default(),
            layers: None,
            range: Range::Before,
            seq: 0,
            moves: 0,
            out: VecDeque::new(),
            eof: false,
            points: Vec::new(),
            last_end: Point::default(),
            resync: None,
            last_feed_mm_s: cfg_feed,
            limit_changes: 0,
            shaper_changes: 0,
            ignored: BTreeMap::new(),
            grbl,
            travel,
            start_limits,
            overrides: Vec::new(),
        })
    }

    /// Name the input in error messages.
    pub fn with_name(mut self, name: impl Into<Arc<str>>) -> Self {
        self.source = name.into();
        self
    }

    /// Produce chunks only for the layers `layers` (indices as [`crate::Event::layer`]): every
    /// move before still plans, and the first chunk starts at the start of the range's
    /// first move in the exact (shaped) state there; the last ends where the next layer's
    /// first move starts. Set before the first chunk is taken.
    pub fn with_layers(mut self, layers: RangeInclusive<u32>) -> Result<Self, GcodeError> {
        let (a, b) = (*layers.start(), *layers.end());
        if a > b || self.moves > 0 {
            return Err(GcodeError::JobSetting {
                key: "layers",
                reason: format!(
                    "the range {a}..={b} must not be empty and must be set before planning starts"
                ),
            });
        }
        self.layers = Some((a, b));
        let initial = build(&self.cfg.shapers).map_err(|e| GcodeError::JobSetting {
            key: "shapers",
            reason: e.to_string(),
        })?;
        let preroll = self.input.preroll_s();
        self.input = Input::new(self.cfg.alignment, initial, true);
        self.input.set_preroll(preroll);
        Ok(self)
    }

    /// With a layer range: start the chunks `preroll_s` before the range's first move (no
    /// earlier than the start of the file), so that a simulation of the range starts from
    /// the motion the layers before leave; the chunks before the range's first move list
    /// the moves they carry like any other. Set before the first chunk is taken.
    pub fn with_preroll_s(mut self, preroll_s: f64) -> Result<Self, GcodeError> {
        if !(preroll_s.is_finite() && preroll_s >= 0.0) || self.moves > 0 {
            return Err(GcodeError::JobSetting {
                key: "preroll",
                reason: format!(
                    "the pre-roll ({preroll_s} s) must be a finite number >= 0, set before planning starts"
                ),
            });
        }
        self.input.set_preroll(preroll_s);
        Ok(self)
    }

    /// Whether the last chunk has been taken and it ended the file's motion (not a layer
    /// range that ends before the file does): the machine is then commanded to stand
    /// still at the end of the print from the end of that chunk on.
    pub fn ended_at_end_of_file(&self) -> bool {
        self.eof && self.range != Range::After && self.out.is_empty()
    }

    /// The reader (for its statistics: ignored commands, lines read).
    pub fn reader(&self) -> &Reader<R> {
        &self.reader
    }

    /// The settings the job started with.
    pub fn config(&self) -> &JobConfig {
        &self.cfg
    }

    /// The print clock so far (s): the planner's sum of move and dwell times.
    pub fn print_time_s(&self) -> f64 {
        match &self.planner {
            Planner::Firmware(d, _) => d.print_time_s(),
            Planner::Settle(s) => s.print_time_s(),
        }
    }

    /// The next chunk of shaped motion, or `None` when the range (or the file) is done.
    pub fn next_chunk(&mut self) -> Result<Option<JobChunk>, GcodeError> {
        loop {
            if let Some(c) = self.out.pop_front() {
                return Ok(Some(c));
            }
            if self.eof || (self.range == Range::After && self.input.done()) {
                return Ok(None);
            }
            self.step()?;
        }
    }

    /// Plan the rest of the file without producing chunks (completes the account after a
    /// layer range).
    pub fn run_to_end(&mut self) -> Result<(), GcodeError> {
        while !self.eof {
            self.step()?;
            self.out.clear();
        }
        self.out.clear();
        Ok(())
    }

    /// What the job has done so far.
    pub fn summary(&self) -> JobSummary {
        let t = self.print_time_s();
        // What the planner was told to do but did not, and what the reader passed over.
        let mut ignored = self.ignored.clone();
        let firmware = self.cfg.firmware();
        for (name, n) in self.reader.ignored_commands() {
            let what = format!("{name}: {}", super::not_followed::reason(firmware, name));
            *ignored.entry(what).or_insert(0) += n;
        }
        JobSummary {
            firmware: Some(self.cfg.firmware()),
            print_time_s: t,
            layers: self.table.layers(t),
            moves: self.moves,
            segments: self.seq,
            limit_changes: self.limit_changes,
            shaper_changes: self.shaper_changes,
            ignored,
            features: self.reader.features().to_vec(),
            overrides: self.overrides.clone(),
            complete: self.eof,
        }
    }
}

impl<R: BufRead> Iterator for Job<R> {
    type Item = Result<JobChunk, GcodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_chunk().transpose()
    }
}
