//! A `[gcode]` run's job as a streamed motion ([`crate::studies::Motion::Stream`]): its
//! chunks simulated one after the other, as `settle gcode` simulates them, and the
//! contour error measured along them (working samples of the range's moves, during the
//! job), so that no run holds the whole job planned or its samples recorded.
//!
//! Where the run starts and how long it lasts (the module doc of [`super`]: the print
//! clock's sample grid, the pre-roll, a shaped job's lead) is found by a first pass over
//! the job (`Outline`), which keeps only the chunks before the run's start (a pre-roll's
//! worth at most) and the durations and end state after it; the run then plans the job
//! again as it is simulated (`JobChunks`).

use settle_gcode::FileInput;
use settle_gcode::job::{Job, JobChunk};
use settle_planner::shaper::stream::cut;
use settle_planner::{PlanError, Profile, Segment, State, Trajectory};

use std::collections::VecDeque;
use std::sync::Arc;

use super::command_path::{CommandPath, CommandTrack};
use super::contour::ActiveMoves;
use super::position::PositionCursor;
use super::stats::Histogram;
use crate::measure::metrics::Metrics;
use crate::studies::MotionStream;

/// The job axis (0 X, 1 Y, 2 Z) of each machine axis, by name.
pub(super) fn job_axes(axes: &[String]) -> Result<Vec<usize>, PlanError> {
    axes.iter()
        .map(|name| match name.as_str() {
            "x" => Ok(0),
            "y" => Ok(1),
            "z" => Ok(2),
            _ => Err(PlanError::InvalidInput {
                reason: "a G-code job drives machine axes named x, y and z only",
            }),
        })
        .collect()
}

/// A job chunk's profiles on the machine's axes.
fn on_machine(c: &JobChunk, map: &[usize]) -> Result<Trajectory, PlanError> {
    Trajectory::new(map.iter().map(|&i| c.trajectory.axes()[i].clone()).collect())
}

/// `tr` (starting at `t0_s` on the print clock) from `at_s` on ([`cut`]: the exact state
/// there); `None` when it ends at or before `at_s`.
fn from(t0_s: f64, tr: Trajectory, at_s: f64) -> Result<Option<Trajectory>, PlanError> {
    let d = tr.duration_s();
    if at_s <= t0_s {
        return Ok(Some(tr));
    }
    if t0_s + d <= at_s {
        return Ok(None);
    }
    let axes = tr
        .axes()
        .iter()
        .map(|p| cut(p, at_s - t0_s, d))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Some(Trajectory::new(axes)?))
}

/// Standing at `start` for `rest_s` (s).
fn standing(start: &[State], rest_s: f64) -> Result<Trajectory, PlanError> {
    Trajectory::new(
        start
            .iter()
            .map(|s| {
                Profile::new(
                    *s,
                    vec![Segment::Jerk {
                        duration_s: rest_s,
                        jerk: 0.0,
                    }],
                )
            })
            .collect::<Result<Vec<_>, _>>()?,
    )
}

/// Where a run of the job starts and ends (module doc).
#[derive(Debug)]
pub(super) struct Outline {
    /// Print-clock time of the run's `t = 0` (s), on the sample grid.
    pub origin_s: f64,
    /// How long the run stands at the start before the job's motion (s): a job at rest
    /// that starts between two instants of the grid.
    pub rest_s: f64,
    /// Print-clock time the job's chunks are cut at (s): the motion before is not run.
    pub cut_s: f64,
    /// The start per machine axis.
    pub start: Vec<State>,
    /// The end per machine axis.
    pub end: Vec<State>,
    /// The run's duration (s): the rest, then the chunks' durations, summed in order.
    pub duration_s: f64,
    /// The whole file's print time (s).
    pub print_time_s: f64,
}

/// A job's planning failure where the sweep's validation has already planned it.
fn failed<E>(_: E) -> PlanError {
    PlanError::InvalidInput {
        reason: "the G-code job failed to plan (checked when the sweep was validated)",
    }
}

impl Outline {
    /// The outline of `job` on the machine axes `map` ([`job_axes`]), sampled every `dt`
    /// s; `range`: the first layer of a layer range and the least pre-roll it needs (s).
    pub(super) fn of(
        mut job: Job<FileInput>,
        map: &[usize],
        dt: f64,
        range: Option<(u32, f64)>,
    ) -> Result<Self, PlanError> {
        // The chunks that start within two samples of the first (the run starts in the
        // first of them), then only durations; the end; the range's first move.
        let (mut early, mut later) = (Vec::new(), Vec::new());
        let mut range_start: Option<f64> = None;
        let mut end = Vec::new();
        let mut first_s = None;
        while let Some(c) = job.next_chunk().map_err(failed)? {
            // The chunk's profiles on the machine's axes, read in place (a chunk is
            // copied only when kept).
            let axes = map.iter().map(|&i| &c.trajectory.axes()[i]);
            end.clear();
            end.extend(axes.clone().map(Profile::end));
            if let (Some((a, _)), None) = (range, range_start) {
                range_start = c
                    .moves
                    .iter()
                    .find(|m| m.layer >= a && m.duration_s > 0.0)
                    .map(|m| m.start_time_s);
            }
            let first = *first_s.get_or_insert(c.start_time_s);
            if c.start_time_s < first + 2.0 * dt {
                early.push((c.start_time_s, on_machine(&c, map)?));
            } else {
                // As `Trajectory::new` sums it up.
                later.push(axes.map(|p| p.duration_s()).fold(0.0, f64::max));
            }
        }
        job.run_to_end().map_err(failed)?;
        let mut cut_s = first_s.ok_or(PlanError::InvalidInput {
            reason: "the G-code job has no motion",
        })?;
        if let Some((_, needed)) = range {
            // The pre-roll's start moved to the print clock's sample grid (module doc of
            // [`super`]), when that leaves at least the pre-roll the modes need (it does
            // unless the range starts within a pre-roll of the file's start, where the job
            // starts at rest as in the whole run).
            let on_grid = (cut_s / dt).ceil() * dt;
            if range_start.is_some_and(|r| r - on_grid >= needed) {
                cut_s = on_grid;
            }
        }
        let mut chunks = Vec::with_capacity(early.len());
        for (s, tr) in early {
            if let Some(tr) = from(s, tr, cut_s)? {
                chunks.push(tr);
            }
        }
        let first = chunks.first().ok_or(PlanError::InvalidInput {
            reason: "the G-code job has no motion",
        })?;
        let start: Vec<State> = first.axes().iter().map(Profile::start).collect();
        // A job at rest that starts between two instants of the grid (a shaped job starts
        // before 0 by half its shaper) stands still from the instant before.
        let (mut origin_s, mut rest_s) = (cut_s, 0.0);
        let at_rest = start.iter().all(|s| s.v == 0.0 && s.a == 0.0);
        if (cut_s / dt).ceil() * dt != cut_s && at_rest {
            origin_s = (cut_s / dt).floor() * dt;
            rest_s = cut_s - origin_s;
        }
        let mut duration_s = 0.0;
        if rest_s > 0.0 {
            duration_s += standing(&start, rest_s)?.duration_s();
        }
        for d in chunks.iter().map(Trajectory::duration_s).chain(later) {
            duration_s += d;
        }
        Ok(Self {
            origin_s,
            rest_s,
            cut_s,
            start,
            end,
            duration_s,
            print_time_s: job.print_time_s(),
        })
    }
}

/// The run's chunks and contour error (module doc).
pub(super) struct JobChunks {
    job: Job<FileInput>,
    map: Vec<usize>,
    /// Print-clock time of the run's `t = 0` (s).
    origin_s: f64,
    /// Where the job's chunks are cut (s, print clock).
    cut_s: f64,
    /// The standing start, until taken.
    rest: Option<Trajectory>,
    duration_s: f64,
    /// Machine indices of X and Y.
    xy: [usize; 2],
    layers: Option<(u32, u32)>,
    active: ActiveMoves,
    hist: Histogram,
    /// Errors (um) counted but not in [`JobChunks::hist`] yet (fewer than
    /// [`ERRORS_BATCH`]).
    errors_um: Vec<f64>,
    /// The largest error (um) and its G-code line.
    worst: (f64, f64),
    /// The largest smoothing and vibration (um) of the counted samples (see
    /// [`super::stats::Split`]).
    split_worst: [f64; 2],
    /// A square (mm^2) at or below which a sample's bound ([`CommandPath::bound_mm`])
    /// squared is surely no larger than the largest vibration (`-1` until there is one).
    below_vibration_sq: f64,
    print_time_s: f64,
    /// The chunks handed out whose samples may still come.
    handed: VecDeque<Handed>,
    /// The next chunk's time 0 on the run's clock (s).
    next_t0_s: f64,
    /// The command's path, and the samples waiting to be measured against it
    /// ([`CommandPath::delay`] of them).
    command: CommandTrack,
    waiting: VecDeque<Waiting>,
    delay: usize,
    /// Samples measured.
    measured: u64,
}

/// A square (mm^2) such that a distance (mm) whose square is no larger is, once taken
/// the root of and scaled to um, surely no larger than `largest_um`: below it by a margin
/// (1e-9 relative) far above the rounding of the root and the products; `-1` (none) near
/// the smallest numbers, where a square loses its relative precision.
fn below_sq(largest_um: f64) -> f64 {
    let mm = largest_um * 1e-3;
    match mm >= 1e-100 {
        true => mm * mm * (1.0 - 1e-9),
        false => -1.0,
    }
}

/// Samples measured between two trims of the command's path.
const FORGET_EVERY: u64 = 64;

/// Errors put in the histogram at a time.
const ERRORS_BATCH: usize = 128;

/// A chunk handed out whose samples may still come.
#[derive(Debug)]
struct Handed {
    /// Its start (s, run clock).
    t0_s: f64,
    duration_s: f64,
    /// Its X and Y.
    xy: Arc<[Profile; 2]>,
    /// The segment of X and Y the last sample fell in.
    seg: [PositionCursor; 2],
}

/// A sample waiting for its vibration: time (s, run clock), toolhead and command (XY,
/// mm), and whether it counts.
#[derive(Debug, Clone, Copy)]
struct Waiting {
    t_s: f64,
    p: [f64; 2],
    c: [f64; 2],
    counted: bool,
}

impl JobChunks {
    /// The chunks of `job` (opened again as the outline's was) from `outline`'s start,
    /// sampled at `sample_rate_hz`; only samples of moves in `layers` count.
    pub(super) fn new(
        job: Job<FileInput>,
        map: Vec<usize>,
        outline: &Outline,
        layers: Option<(u32, u32)>,
        sample_rate_hz: f64,
    ) -> Result<Self, PlanError> {
        let find = |j: usize| map.iter().position(|&m| m == j);
        let (Some(ix), Some(iy)) = (find(0), find(1)) else {
            return Err(PlanError::InvalidInput {
                reason: "a G-code job needs machine axes x and y",
            });
        };
        let rest = match outline.rest_s > 0.0 {
            true => Some(standing(&outline.start, outline.rest_s)?),
            false => None,
        };
        Ok(Self {
            job,
            map,
            origin_s: outline.origin_s,
            cut_s: outline.cut_s,
            rest,
            duration_s: outline.duration_s,
            xy: [ix, iy],
            layers,
            active: ActiveMoves::default(),
            hist: Histogram::default(),
            errors_um: Vec::with_capacity(ERRORS_BATCH),
            worst: (0.0, f64::NAN),
            split_worst: [0.0; 2],
            below_vibration_sq: -1.0,
            print_time_s: outline.print_time_s,
            handed: VecDeque::new(),
            next_t0_s: 0.0,
            command: CommandTrack::default(),
            waiting: VecDeque::new(),
            delay: CommandPath::delay(sample_rate_hz),
            measured: 0,
        })
    }

    /// A chunk handed out with its time 0: it starts where the one before ended (run
    /// clock).
    fn hand(&mut self, tr: Trajectory) -> (f64, Trajectory) {
        let [ix, iy] = self.xy;
        let t0 = self.next_t0_s;
        let d = tr.duration_s();
        let xy = Arc::new([tr.axes()[ix].clone(), tr.axes()[iy].clone()]);
        self.handed.push_back(Handed {
            t0_s: t0,
            duration_s: d,
            xy: Arc::clone(&xy),
            seg: Default::default(),
        });
        self.command.follow(t0, xy);
        self.next_t0_s += d;
        (t0, tr)
    }

    /// The commanded X and Y (mm) at `t_s` (run clock), as the runner evaluates them: by
    /// the chunk that takes the sample (a chunk followed by another takes a sample at its
    /// end; the last one's end is its end state, held).
    fn commanded_mm(&mut self, t_s: f64) -> Option<[f64; 2]> {
        while self.handed.len() > 1
            && self
                .handed
                .front()
                .is_some_and(|c| t_s - c.t0_s > c.duration_s)
        {
            self.handed.pop_front();
        }
        let Handed { t0_s, xy, seg, .. } = self.handed.front_mut()?;
        let tau = t_s - *t0_s;
        Some([
            seg[0].position(&xy[0], tau) * 1e3,
            seg[1].position(&xy[1], tau) * 1e3,
        ])
    }

    /// Count a sample at `tp` (print clock) with the toolhead at `p` and the command at
    /// `c` (XY, mm): its contour error and smoothing, when it is a working sample of the
    /// range; whether it counts.
    fn count(&mut self, tp: f64, p: [f64; 2], c: [f64; 2]) -> bool {
        let Some(([e, smoothing], owner)) = self.active.at_each(tp, [p, c]) else {
            return false;
        };
        if !owner.working
            || self
                .layers
                .is_some_and(|(a, b)| !(a..=b).contains(&owner.layer))
        {
            return false;
        }
        let e_um = e * 1e3;
        // Binned and counted a batch at a time (the lookups of a batch overlap).
        self.errors_um.push(e_um);
        if self.errors_um.len() == ERRORS_BATCH {
            self.hist.push_all(&self.errors_um);
            self.errors_um.clear();
        }
        if e_um > self.worst.0 {
            self.worst = (e_um, owner.line as f64);
        }
        self.split_worst[0] = self.split_worst[0].max(smoothing * 1e3);
        true
    }

    /// Measure the oldest waiting sample's vibration, where it may be the largest (its
    /// bound, [`CommandPath::bound_mm`], is larger than the largest so far).
    fn measure_waiting(&mut self) {
        let Some(w) = self.waiting.pop_front() else {
            return;
        };
        // The path forgets as it is asked for a distance (the same points whichever
        // times came before): here only now and then, to bound its memory.
        self.measured += 1;
        if self.measured.is_multiple_of(FORGET_EVERY) {
            self.command.path.forget_before(w.t_s);
        }
        if !w.counted {
            return;
        }
        // The bound's square well below the largest vibration's: the bound is no larger
        // (the margin, 1e-9, is far above the rounding of the root and the products).
        let (dx, dy) = (w.p[0] - w.c[0], w.p[1] - w.c[1]);
        if dx * dx + dy * dy <= self.below_vibration_sq {
            return;
        }
        if CommandPath::bound_mm(w.p, w.c) * 1e3 > self.split_worst[1] {
            let v = self.command.path.distance_mm(w.t_s, w.p, w.c).unwrap_or(0.0) * 1e3;
            self.split_worst[1] = self.split_worst[1].max(v);
            self.below_vibration_sq = below_sq(self.split_worst[1]);
        }
    }
}

impl MotionStream for JobChunks {
    fn next_chunk(&mut self) -> Result<Option<(f64, Trajectory)>, PlanError> {
        if let Some(r) = self.rest.take() {
            return Ok(Some(self.hand(r)));
        }
        while let Some(c) = self.job.next_chunk().map_err(failed)? {
            let tr = on_machine(&c, &self.map)?;
            if let Some(tr) = from(c.start_time_s, tr, self.cut_s)? {
                self.active.add(&c.moves);
                return Ok(Some(self.hand(tr)));
            }
        }
        Ok(None)
    }

    fn samples(&mut self, [origin_s, dt_s]: [f64; 2], k0: u64, toolhead_m: &[f64], axes: usize) {
        for (i, toolhead) in toolhead_m.chunks_exact(axes).enumerate() {
            // As the driver's clock times it.
            self.sample(origin_s + (k0 + i as u64) as f64 * dt_s, toolhead);
        }
    }

    fn measure(&mut self, m: &mut Metrics) {
        while !self.waiting.is_empty() {
            self.measure_waiting();
        }
        self.hist.push_all(&self.errors_um);
        self.errors_um.clear();
        m.extra.push(("print_time_s".into(), self.print_time_s));
        m.extra.push(("contour_worst_um".into(), self.worst.0));
        m.extra
            .push(("contour_p95_um".into(), self.hist.quantile_um(0.95)));
        m.extra.push(("contour_worst_line".into(), self.worst.1));
        m.extra.push(("smoothing_worst_um".into(), self.split_worst[0]));
        m.extra.push(("vibration_worst_um".into(), self.split_worst[1]));
    }
}

impl JobChunks {
    /// A sample at `t_s` (the run's clock) with the toolhead at `toolhead_m` (per machine
    /// axis).
    #[inline]
    fn sample(&mut self, t_s: f64, toolhead_m: &[f64]) {
        if t_s > self.duration_s {
            return;
        }
        let tp = t_s + self.origin_s;
        self.active.retire(tp);
        let [ix, iy] = self.xy;
        let p = [toolhead_m[ix] * 1e3, toolhead_m[iy] * 1e3];
        let Some(c) = self.commanded_mm(t_s) else {
            return;
        };
        // The command's path takes every sample's command; each sample's vibration is
        // measured once the path is known 20 ms after it (as `settle gcode` measures it).
        self.command.sample(t_s, c);
        let counted = self.count(tp, p, c);
        self.waiting.push_back(Waiting {
            t_s,
            p,
            c,
            counted,
        });
        if self.waiting.len() > self.delay {
            self.measure_waiting();
        }
    }
}
