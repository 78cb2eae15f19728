//! A G-code job simulated on a plant, streaming: the job's chunks drive the plant one
//! after the other with its state carried across them (chunks join continuously), on one
//! sample clock (`k / sample_rate` s of print time), with plant steps split at every
//! breakpoint of the command (the modal plant is then exact). Each sample's contour error
//! ([`crate::studies::gcode::contour`]) feeds the per-move, per-layer and whole-job account
//! ([`crate::studies::gcode::stats`]).
//!
//! - Each sample is measured [`CommandPath::delay`] samples late (20 ms), when the
//!   command's path is known that far after it too: its vibration is measured against the
//!   command's path around it ([`crate::studies::gcode::command_path`]). The samples still
//!   waiting are measured when the job's simulation ends.
//! - With a layer range the job's chunks start a pre-roll before the range (see
//!   [`crate::studies::gcode::preroll`]): the plant is stepped through it, but only samples of moves in
//!   the range are counted.
//! - When the job's motion ends the file, the machine is simulated on with the command
//!   standing at the end point for [`StreamOptions::tail_s`] (or until the residual has
//!   stayed in [`TAIL_BAND_UM`] for [`StreamOptions::tail_hold_s`]): the ringing after the
//!   last move. Its samples belong to the last move (its contour error, as any sample),
//!   and the largest distance from the end point is the last layer's
//!   [`LayerStats::end_residual_um`].

use std::borrow::Cow;
use std::collections::VecDeque;
use std::io::BufRead;
use std::ops::ControlFlow;
use std::path::Path;
use std::sync::Arc;

use settle_gcode::job::Job;
use settle_planner::{Profile, State, Trajectory};
use settle_sim::{AxisModel, Observation, Plant, SimError};

use super::Progress;
use super::record::Recorder;
use crate::error::Error;
use crate::execute::driver::{Chunk, Driver, Samples, Sink, Stop, standing_at};
use crate::execute::plant::{SimOptions, Simulation, with_plant};
use crate::spec::backend::Backend;
use crate::studies::gcode::command_path::{Asked, CommandPath, CommandTrack};
use crate::studies::gcode::contour::ActiveMoves;
use crate::studies::gcode::features::FeatureAccount;
use crate::studies::gcode::fly::FlyAxis;
use crate::studies::gcode::stats::{
    Histogram, LayerMap, LayerStats, MapPoint, Split, Spot, TopSpots,
};

/// How the job is sampled and what is kept.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamOptions {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Job axis (0 X, 1 Y, 2 Z) of each machine axis, in machine order.
    pub job_axes: Vec<usize>,
    /// The machine's axis names, in order (for fault messages).
    pub names: Vec<String>,
    /// Machine axis indices of X and Y (contour error is measured in XY).
    pub xy: [usize; 2],
    /// Worst spots kept for the whole job.
    pub top_spots: usize,
    /// Ringing maps kept (the layers with the largest errors).
    pub maps: usize,
    /// A layer whose map is kept whatever its errors ([`Streamed::chosen`]).
    pub map_layer: Option<u32>,
    /// Only samples of moves in these layers count (the rest is the pre-roll).
    pub layers: Option<(u32, u32)>,
    /// Longest simulation after the end of the file's motion (s; 0: none).
    pub tail_s: f64,
    /// The tail ends early once the residual has stayed within [`TAIL_BAND_UM`] this
    /// long (s).
    pub tail_hold_s: f64,
}

/// The band (um) the residual after the last move must stay in to end the tail early.
pub const TAIL_BAND_UM: f64 = 0.1;

/// The ringing after the last move.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tail {
    /// Simulated after the last command (s).
    pub duration_s: f64,
    /// Largest distance in XY (um) from the toolhead to the end point after the last
    /// command.
    pub residual_peak_um: f64,
    /// Its last value (um).
    pub residual_last_um: f64,
}

/// What the simulation measured.
#[derive(Debug, Clone, Default)]
pub struct Streamed {
    /// Every simulated layer's account, in order (moved into [`super::GcodeOutcome::layers`] by
    /// [`super::measure`]).
    pub layers: Vec<LayerStats>,
    /// Every printing sample's contour error.
    pub all: Histogram,
    /// The largest smoothing and the largest vibration of the printing samples.
    pub split_worst: Split,
    /// The worst spots of the job (one per move).
    pub worst: Vec<Spot>,
    /// The ringing maps of the worst layers, largest error first.
    pub maps: Vec<LayerMap>,
    /// The map of [`StreamOptions::map_layer`].
    pub chosen: Option<LayerMap>,
    /// Print time simulated (s): from the first chunk (the pre-roll included) to the last
    /// command; the ringing after it is [`Tail::duration_s`].
    pub simulated_s: f64,
    /// Samples taken.
    pub samples: u64,
    /// A simulation fault (non-finite state or a blow-up) that ended the simulation.
    pub fault: Option<String>,
    /// Lost steps per axis (driver models that have them).
    pub lost_steps: u32,
    /// Simulated before the layer range's first move, not counted (s).
    pub preroll_s: f64,
    /// The ringing after the last move, when the job ended the file.
    pub tail: Option<Tail>,
    /// Where a motor was first seen past its stability limit (see [`LostStep`]).
    pub first_lost_step: Option<LostStep>,
    /// The error per slicer feature type.
    pub features: FeatureAccount,
    /// The along-line error of scan lines (raster jobs).
    pub fly: FlyAxis,
}

/// Where a motor's load angle was first seen past 90 electrical degrees (the driver
/// model's lost step): checked at every sample evaluated in full, so at least once per
/// 256 samples.
#[derive(Debug, Clone, PartialEq)]
pub struct LostStep {
    /// When it was seen (s, print clock).
    pub time_s: f64,
    /// The machine axis.
    pub axis: String,
    /// Its largest |load angle| so far (electrical degrees).
    pub max_load_angle_deg: f64,
    /// The G-code line and layer of the move the sample belongs to.
    pub line: u64,
    /// Its layer.
    pub layer: u32,
}

/// The move a sample belongs to, as the account keeps it.
#[derive(Debug, Clone, Copy)]
struct Owner {
    index: u64,
    working: bool,
    feature: u16,
    layer: u32,
    line: u64,
}

/// A sample waiting to be measured: its clock index and time, and the commanded and
/// toolhead XY (m).
#[derive(Debug, Clone, Copy)]
struct Waiting {
    k: u64,
    t: f64,
    cmd: [f64; 2],
    toolhead: [f64; 2],
}

/// The running account (module doc).
#[derive(Debug)]
struct Account {
    opts: StreamOptions,
    active: ActiveMoves,
    /// The command's path around the sample being measured.
    command: CommandTrack,
    /// The samples not measured yet, oldest first.
    waiting: VecDeque<Waiting>,
    /// How many samples wait.
    delay: usize,
    out: Streamed,
    top: TopSpots,
    layer: Option<LayerStats>,
    /// The current layer's errors, added up from its feature types' at its end
    /// ([`FeatureAccount::end_layer`]).
    hist: Histogram,
    map: Vec<MapPoint>,
    /// The map's points whose vibration is measured only if the map is kept: their
    /// index in it, and the distance to ask.
    unmeasured: Vec<(usize, Asked)>,
    layer_top: TopSpots,
    /// The move the last sample belonged to: index, whether it works, layer, line, worst
    /// spot.
    owner: Option<(u64, bool, u32, u64, Option<Spot>)>,
    map_every: u64,
    /// The current layer's map stride: `map_every`, doubled each time its map is halved.
    map_stride: u64,
    /// The MCAP recording of the counted samples.
    rec: Option<Recorder>,
    /// The ringing after the last move, while it is simulated.
    ringing: Option<Ringing>,
}

impl Account {
    fn new(opts: StreamOptions, rec: Option<Recorder>) -> Self {
        // About 1 kHz of map points.
        let sample_rate_hz = opts.sample_rate_hz;
        let map_every = (sample_rate_hz / 1000.0).round().max(1.0) as u64;
        Self {
            top: TopSpots::new(opts.top_spots),
            layer_top: TopSpots::new(5),
            opts,
            active: ActiveMoves::default(),
            command: CommandTrack::default(),
            waiting: VecDeque::new(),
            delay: CommandPath::delay(sample_rate_hz),
            out: Streamed::default(),
            layer: None,
            hist: Histogram::default(),
            map: Vec::new(),
            unmeasured: Vec::new(),
            owner: None,
            map_every,
            map_stride: map_every,
            rec,
            ringing: None,
        }
    }

    /// Record where a lost step is first seen in `obs` (at `t`).
    fn lost_step_check(&mut self, t: f64, obs: &[Observation]) {
        let Some((i, o)) = obs.iter().enumerate().find(|(_, o)| o.lost_steps > 0) else {
            return;
        };
        let (line, layer) = self.active.owner(t).map_or((0, 0), |m| (m.line, m.layer));
        self.out.first_lost_step = Some(LostStep {
            time_s: t,
            axis: self.opts.names.get(i).cloned().unwrap_or_default(),
            max_load_angle_deg: o.max_load_angle_rad.unwrap_or(f64::NAN).to_degrees(),
            line,
            layer,
        });
    }

    fn end_move(&mut self) {
        if let Some((_, true, _, _, Some(spot))) = self.owner.take()
            && let Some(l) = self.layer.as_mut()
        {
            l.add_move(&spot);
            self.top.offer(spot.clone());
            self.layer_top.offer(spot);
        }
    }

    fn end_layer(&mut self) {
        self.end_move();
        let Some(mut l) = self.layer.take() else {
            return;
        };
        self.out.features.end_layer(l.layer, &mut self.hist);
        l.p95_um = self.hist.quantile_um(0.95);
        self.out.all.merge(&self.hist);
        self.hist.clear();
        self.map_stride = self.map_every;
        let mut map = LayerMap {
            layer: l.layer,
            points: Vec::new(),
            spots: std::mem::replace(&mut self.layer_top, TopSpots::new(5))
                .spots()
                .to_vec(),
        };
        let chosen = self.opts.map_layer == Some(map.layer);
        let at = self
            .out
            .maps
            .partition_point(|m| m.worst_um() >= map.worst_um());
        self.measure_map(chosen || at < self.opts.maps);
        map.points = std::mem::take(&mut self.map);
        if chosen {
            self.out.chosen = Some(map.clone());
        }
        let maps = &mut self.out.maps;
        if at < self.opts.maps {
            maps.insert(at, map);
            maps.truncate(self.opts.maps);
        }
        self.out.layers.push(l);
    }

    /// A sample: its command joins the path, and the sample `delay` before it is measured.
    fn add_sample(&mut self, k: u64, t: f64, cmd_m: &[f64], toolhead_m: &[f64]) {
        let [ix, iy] = self.opts.xy;
        let w = Waiting {
            k,
            t,
            cmd: [cmd_m[ix], cmd_m[iy]],
            toolhead: [toolhead_m[ix], toolhead_m[iy]],
        };
        // Every sample's command is on the path, counted or not (the pre-roll's too),
        // with the breakpoints before it.
        self.command.sample(t, [w.cmd[0] * 1e3, w.cmd[1] * 1e3]);
        self.waiting.push_back(w);
        if self.waiting.len() > self.delay
            && let Some(w) = self.waiting.pop_front()
        {
            self.measure(w);
        }
    }

    /// Follow the chunk of `tr` from `t0_s` (print clock): its breakpoints go on the
    /// command's path.
    fn follow(&mut self, t0_s: f64, tr: &Trajectory) {
        let [ix, iy] = self.opts.xy;
        let xy = [tr.axes()[ix].clone(), tr.axes()[iy].clone()];
        self.command.follow(t0_s, Arc::new(xy));
    }

    /// Measure the samples still waiting (the path after them is all there will be).
    fn flush(&mut self) {
        while let Some(w) = self.waiting.pop_front() {
            self.measure(w);
        }
    }

    /// The vibration (um) of a printing sample `w` of move `m` whose contour error is
    /// `err_um` (module doc), and whether it was measured: it is where it is read, in a
    /// spot (a move's or a feature's worst error so far), or where it may be the layer's
    /// largest. Elsewhere it is no larger than the layer's largest and changes nothing:
    /// its bound ([`CommandPath::bound_mm`]) is given instead (a ringing map's point is
    /// measured when its layer's map is kept, [`Account::end_layer`]).
    fn vibration_um(&mut self, w: &Waiting, err_um: f64, m: Owner) -> (f64, bool) {
        let p = [w.toolhead[0] * 1e3, w.toolhead[1] * 1e3];
        let c = [w.cmd[0] * 1e3, w.cmd[1] * 1e3];
        let mut measured = || {
            let d = self.command.path.distance_mm(w.t, p, c);
            (d.unwrap_or(0.0) * 1e3, true)
        };
        let spot = self
            .owner
            .as_ref()
            .is_none_or(|o| o.4.as_ref().is_none_or(|s| err_um > s.error_um))
            || self.out.features.is_worst(m.feature, err_um);
        if spot {
            return measured();
        }
        let bound_um = CommandPath::bound_mm(p, c) * 1e3;
        let largest = self
            .layer
            .as_ref()
            .map_or(0.0, |l| l.split_worst.vibration_um);
        if bound_um > largest {
            measured()
        } else {
            (bound_um, false)
        }
    }

    /// Measure the vibration of the ringing map's points that wait for it
    /// ([`Account::unmeasured`]) when `keep`, and hold the command's path for them no
    /// more.
    fn measure_map(&mut self, keep: bool) {
        if keep && !self.unmeasured.is_empty() {
            let asked: Vec<Asked> = self.unmeasured.iter().map(|u| u.1).collect();
            let d = self.command.path.distances_mm(&asked);
            for (&(i, _), d) in self.unmeasured.iter().zip(d) {
                self.map[i].vibration_um = (d * 1e3) as f32;
            }
        }
        self.unmeasured.clear();
        self.command.path.release();
    }

    /// Measure a sample (module doc).
    fn measure(&mut self, w: Waiting) {
        let Waiting { k, t, .. } = w;
        self.out.samples += 1;
        self.active.retire(t);
        let (x, y) = (w.toolhead[0] * 1e3, w.toolhead[1] * 1e3);
        let (cx, cy) = (w.cmd[0] * 1e3, w.cmd[1] * 1e3);
        // The toolhead's and the command's distances to the G-code path: the contour error
        // and the smoothing.
        let Some(([err_mm, smoothing_mm], m)) = self.active.at_each(t, [[x, y], [cx, cy]]) else {
            return;
        };
        if self
            .opts
            .layers
            .is_some_and(|(a, b)| !(a..=b).contains(&m.layer))
        {
            return;
        }
        if m.working {
            self.out.fly.sample(m, t, [cx, cy], [x, y]);
        }
        let m = Owner {
            index: m.index,
            working: m.working,
            feature: m.feature,
            layer: m.layer,
            line: m.line,
        };
        if self.owner.as_ref().is_none_or(|o| o.0 != m.index) {
            if self.layer.as_ref().is_none_or(|l| l.layer != m.layer) {
                self.end_layer();
                self.layer = Some(LayerStats::new(m.layer));
            } else {
                self.end_move();
            }
            self.owner = Some((m.index, m.working, m.layer, m.line, None));
        }
        let err_um = err_mm * 1e3;
        if let Some(r) = self.rec.as_mut() {
            r.sample(
                t,
                &[
                    w.cmd[0],
                    w.cmd[1],
                    w.toolhead[0],
                    w.toolhead[1],
                    err_mm * 1e-3,
                    m.line as f64,
                    f64::from(m.layer),
                ],
            );
        }
        let print = m.working;
        let map_point = k.is_multiple_of(self.map_stride);
        let mut split = Split::default();
        self.command.path.forget_before(t);
        if print {
            let (vibration_um, measured) = self.vibration_um(&w, err_um, m);
            if map_point && !measured {
                let p = [x, y];
                let asked = self.command.path.ask_later(t, p, [cx, cy]);
                self.unmeasured.push((self.map.len(), asked));
            }
            split = Split {
                smoothing_um: smoothing_mm * 1e3,
                vibration_um,
            };
            self.out.split_worst = self.out.split_worst.max(split);
            if let Some(l) = self.layer.as_mut() {
                l.split_worst = l.split_worst.max(split);
            }
            let spot = || Spot {
                error_um: err_um,
                time_s: t,
                x_mm: x,
                y_mm: y,
                line: m.line,
                layer: m.layer,
                move_index: m.index,
                split,
            };
            self.out.features.sample(m.feature, m.layer, err_um, spot);
            if let Some(o) = self.owner.as_mut()
                && o.4.as_ref().is_none_or(|s| err_um > s.error_um)
            {
                o.4 = Some(spot());
            }
        }
        if map_point {
            self.map.push(MapPoint {
                x_mm: x as f32,
                y_mm: y as f32,
                error_um: err_um as f32,
                smoothing_um: split.smoothing_um as f32,
                vibration_um: split.vibration_um as f32,
                print,
            });
            let held = self.command.path.held();
            if held > MAX_HELD_POINTS || self.map.len() >= 2 * MAX_MAP_POINTS {
                self.measure_map(true);
            }
            if self.map.len() >= 2 * MAX_MAP_POINTS {
                halve_map(&mut self.map);
                self.map_stride *= 2;
            }
        }
    }
}

/// The most points of the command's path held for the ringing map's points waiting for
/// their vibration (24 bytes each): past it they are measured
/// (a layer longer than about a minute at 2 kHz, whose map may not be kept).
pub const MAX_HELD_POINTS: u64 = 1 << 18;

/// The most points a layer's ringing map keeps: far more than the figure's 560 x 640
/// pixels show, and a bounded memory whatever the layer's length (a long layer's map is
/// halved, the worse of each pair of points kept, each time it reaches twice this).
pub const MAX_MAP_POINTS: usize = 50_000;

/// Halve a ringing map: each pair of neighbours becomes the one with the larger error
/// (peaks are kept: the map is read for its worst spots), with the larger of each part
/// of the split (the split map is read for its peaks too), printing only if both are (a
/// break in the drawn path stays a break).
fn halve_map(map: &mut Vec<MapPoint>) {
    let halved: Vec<MapPoint> = map
        .chunks(2)
        .map(|pair| {
            let worst = pair
                .iter()
                .copied()
                .fold(pair[0], |a, b| if b.error_um > a.error_um { b } else { a });
            let part = |f: fn(&MapPoint) -> f32| pair.iter().map(f).fold(0.0, f32::max);
            MapPoint {
                print: pair.iter().all(|p| p.print),
                smoothing_um: part(|p| p.smoothing_um),
                vibration_um: part(|p| p.vibration_um),
                ..worst
            }
        })
        .collect();
    *map = halved;
}

impl Tail {
    fn add(&mut self, residual_um: f64) {
        self.residual_peak_um = self.residual_peak_um.max(residual_um);
        self.residual_last_um = residual_um;
    }
}

/// When the residual after the last move has stayed in [`TAIL_BAND_UM`] long enough.
#[derive(Debug)]
struct Band {
    hold_s: f64,
    since: Option<f64>,
}

impl Band {
    fn new(hold_s: f64) -> Self {
        Self {
            hold_s,
            since: None,
        }
    }

    /// The residual is `r_um` at `t`: whether the tail can end here.
    fn stops(&mut self, t: f64, r_um: f64) -> bool {
        if r_um > TAIL_BAND_UM {
            self.since = None;
            return false;
        }
        t - *self.since.get_or_insert(t) >= self.hold_s
    }
}

/// The ringing after the last move, being simulated: the end point and the band.
#[derive(Debug)]
struct Ringing {
    tail: Tail,
    band: Band,
    /// X and Y of the end point (m).
    end_xy: [f64; 2],
}

impl Ringing {
    /// The toolhead at `toolhead_m` at `t`: whether the tail can end here.
    fn stops(&mut self, xy: [usize; 2], t: f64, toolhead_m: &[f64]) -> bool {
        let [ix, iy] = xy;
        let r = (toolhead_m[ix] - self.end_xy[0]).hypot(toolhead_m[iy] - self.end_xy[1]) * 1e6;
        self.tail.add(r);
        self.band.stops(t, r)
    }
}

impl Sink for Account {
    /// Observations until a motor is seen losing steps (where and when is reported).
    fn observes(&self) -> bool {
        self.out.first_lost_step.is_none()
    }

    fn samples(&mut self, s: &Samples<'_>) -> ControlFlow<usize> {
        let xy = self.opts.xy;
        for i in 0..s.count {
            let ((c, h), t) = (s.positions(i), s.time(i));
            self.add_sample(s.k0 + i as u64, t, c, h);
            if let Some(obs) = s.observed.filter(|_| self.out.first_lost_step.is_none()) {
                self.lost_step_check(t, obs);
            }
            // The ringing after the last move has died down, or the recording is past its
            // bound (the job ends here, in an error).
            let settled = self.ringing.as_mut().is_some_and(|r| r.stops(xy, t, h));
            if settled || self.rec.as_ref().is_some_and(|r| r.full().is_some()) {
                return ControlFlow::Break(i);
            }
        }
        ControlFlow::Continue(())
    }
}

/// Simulate `job`'s chunks on the plant of `backend` for `axes` (see the module doc). The
/// belts vary along the travel on the backends that model it ([`SimOptions::belt`]).
/// `file`: the job's G-code file, and what to tell how far it has been read.
pub fn simulate_job<R: BufRead>(
    job: &mut Job<R>,
    backend: Backend,
    axes: Vec<AxisModel>,
    options: &SimOptions,
    opts: StreamOptions,
    rec: Option<Recorder>,
    file: (&Path, Option<Progress<'_>>),
) -> Result<(Streamed, Option<Recorder>), Error> {
    let rate = opts.sample_rate_hz;
    let (file, progress) = file;
    let size = std::fs::metadata(file).map_or(0, |m| m.len());
    let chunks = JobChunks {
        job,
        file,
        progress: progress.map(|p| (p, size)),
        end: Vec::new(),
        range_start: None,
    };
    let sim = (chunks, Account::new(opts, rec));
    with_plant(backend, axes, options, rate, &[], sim).map_err(sim_err)?
}

fn sim_err(source: SimError) -> Error {
    Error::Sim { run: 0, source }
}

/// A job's chunks on the machine's axes and the print clock, each one's moves handed to the
/// account before it is sampled; where the layer range starts and the last chunk ends.
struct JobChunks<'a, R> {
    job: &'a mut Job<R>,
    file: &'a Path,
    /// Told the bytes read after each chunk, with the file's size.
    progress: Option<(Progress<'a>, u64)>,
    /// The end state of the last chunk, per axis.
    end: Vec<State>,
    /// Print-clock time of the layer range's first move.
    range_start: Option<f64>,
}

impl<R: BufRead> JobChunks<'_, R> {
    /// The next chunk, its time 0 its start on the print clock. After the first one (once a
    /// chunk has been simulated) the file is first told how far it has been read.
    fn next(&mut self, acc: &mut Account) -> Result<Option<Chunk<'static>>, Error> {
        if let Some((tell, size)) = self.progress.filter(|_| !self.end.is_empty()) {
            tell(self.job.reader().bytes_read(), size);
        }
        let read = self.job.next_chunk();
        let Some(chunk) = read.map_err(super::gcode_error(self.file))? else {
            return Ok(None);
        };
        acc.active.add(&chunk.moves);
        let axes = acc.opts.job_axes.iter();
        let axes = axes.map(|&i| chunk.trajectory.axes()[i].clone()).collect();
        let sub = Trajectory::new(axes).map_err(|source| Error::Plan { run: 0, source })?;
        if let (None, Some((a, _))) = (self.range_start, acc.opts.layers) {
            let mut moves = chunk.moves.iter();
            let first = moves.find(|m| m.layer >= a && m.duration_s > 0.0);
            self.range_start = first.map(|m| m.start_time_s);
        }
        self.end = sub.axes().iter().map(Profile::end).collect();
        acc.follow(chunk.start_time_s, &sub);
        Ok(Some((chunk.start_time_s, Cow::Owned(sub))))
    }
}

/// Whether the driver stopped early, for a job: a fault is the job's outcome, a backend's
/// failure or an interruption an error.
fn stopped(ran: Result<(), Stop>, acc: &mut Account) -> Result<bool, Error> {
    match ran {
        Ok(()) => Ok(false),
        Err(Stop::Sink) => Ok(true),
        Err(Stop::Fault(reason)) => {
            acc.out.fault = Some(reason);
            Ok(true)
        }
        Err(Stop::Backend { error, .. }) => Err(sim_err(error)),
        Err(Stop::Interrupted) => Err(Error::Interrupted { run: 0 }),
    }
}

/// A job on a plant: its chunks and the account of their samples.
impl<R: BufRead> Simulation for (JobChunks<'_, R>, Account) {
    type Output = Result<(Streamed, Option<Recorder>), Error>;

    fn run<P: Plant>(self, plant: &P) -> Self::Output {
        let (mut chunks, mut acc) = self;
        let names = acc.opts.names.clone();
        if let Some(first) = chunks.next(&mut acc)? {
            let t_first = first.0;
            let starts: Vec<State> = first.1.axes().iter().map(Profile::start).collect();
            let rate = acc.opts.sample_rate_hz;
            let d = Driver::new(plant, &names, &starts, rate, t_first, false).map_err(sim_err)?;
            let mut d = d.streamed();
            let ran = d.follow_chunks(Some(first), |acc| chunks.next(acc), true, &mut acc)?;
            let faulted = stopped(ran, &mut acc)?;
            // The print time simulated: to the last command (the tail is counted apart).
            let t_end = d.time_s();
            acc.out.simulated_s = t_end - t_first;
            let tail_s = acc.opts.tail_s;
            if !faulted && tail_s > 0.0 && chunks.job.ended_at_end_of_file() {
                // The ringing after the last move: the command stands at the end point,
                // from the first sample after the end (a partial step) on.
                let hold = standing_at(&chunks.end);
                let [ix, iy] = acc.opts.xy;
                acc.ringing = Some(Ringing {
                    tail: Tail::default(),
                    band: Band::new(acc.opts.tail_hold_s),
                    end_xy: [hold[ix].p, hold[iy].p],
                });
                let last_k = ((t_end + tail_s) / d.clock().dt_s).floor() as u64;
                stopped(d.hold(&hold, None, last_k, d.clock(), &mut acc), &mut acc)?;
                let mut tail = acc.ringing.take().map(|r| r.tail).unwrap_or_default();
                tail.duration_s = d.time_s() - t_end;
                acc.flush();
                if let Some(l) = acc.layer.as_mut() {
                    l.end_residual_um = Some(tail.residual_peak_um);
                }
                acc.out.tail = Some(tail);
            }
            let preroll_s = chunks.range_start.map(|r| (r - t_first).max(0.0));
            acc.out.preroll_s = preroll_s.unwrap_or(0.0);
            acc.out.lost_steps = d.observe().iter().map(|o| o.lost_steps).sum();
        }
        acc.flush();
        acc.end_layer();
        acc.out.worst = acc.top.spots().to_vec();
        Ok((acc.out, acc.rec))
    }
}
