//! A G-code job simulated on a plant, streaming: the job's chunks drive the plant one
//! after the other with its state carried across them (chunks join continuously), on one
//! sample clock (`k / sample_rate` s of print time), with plant steps split at every
//! breakpoint of the command (the modal plant is then exact). Each sample's contour error
//! ([`crate::kinds::gcode::contour`]) feeds the per-move, per-layer and whole-job account
//! ([`crate::kinds::gcode::stats`]).

use std::io::BufRead;
use std::path::Path;

use settle_gcode::MoveKind;
use settle_gcode::job::Job;
use settle_planner::{Profile, Sample, Trajectory};
use settle_sim::{Observation, Plant};

use crate::error::Error;
use crate::execute::cursor::Cursor;
use crate::kinds::gcode::contour::ActiveMoves;
use crate::kinds::gcode::stats::{Histogram, LayerMap, LayerStats, MapPoint, Spot, TopSpots};
use crate::measure::metrics::BLOWUP_M;

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
}

/// What the simulation measured.
#[derive(Debug, Clone, Default)]
pub struct Streamed {
    /// Every simulated layer's account, in order (moved into [`super::GcodeOutcome::layers`] by
    /// [`super::measure`]).
    pub layers: Vec<LayerStats>,
    /// Every printing sample's contour error.
    pub all: Histogram,
    /// The worst spots of the job (one per move).
    pub worst: Vec<Spot>,
    /// The ringing maps of the worst layers, largest error first.
    pub maps: Vec<LayerMap>,
    /// The map of [`StreamOptions::map_layer`].
    pub chosen: Option<LayerMap>,
    /// Print time simulated (s).
    pub simulated_s: f64,
    /// Samples taken.
    pub samples: u64,
    /// A simulation fault (non-finite state or a blow-up) that ended the simulation.
    pub fault: Option<String>,
    /// Lost steps per axis (driver models that have them).
    pub lost_steps: u32,
}

/// The running account (module doc).
#[derive(Debug)]
struct Account {
    opts: StreamOptions,
    active: ActiveMoves,
    out: Streamed,
    top: TopSpots,
    layer: Option<LayerStats>,
    /// The current layer's errors.
    hist: Histogram,
    map: Vec<MapPoint>,
    layer_top: TopSpots,
    /// The move the last sample belonged to: index, kind, layer, line, worst spot.
    owner: Option<(u64, MoveKind, u32, u64, Option<Spot>)>,
    map_every: u64,
}

impl Account {
    fn new(opts: StreamOptions) -> Self {
        // About 1 kHz of map points.
        let map_every = (opts.sample_rate_hz / 1000.0).round().max(1.0) as u64;
        Self {
            top: TopSpots::new(opts.top_spots),
            layer_top: TopSpots::new(5),
            opts,
            active: ActiveMoves::default(),
            out: Streamed::default(),
            layer: None,
            hist: Histogram::default(),
            map: Vec::new(),
            owner: None,
            map_every,
        }
    }

    fn end_move(&mut self) {
        if let Some((_, MoveKind::Print, _, _, Some(spot))) = self.owner.take()
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
        l.p95_um = self.hist.quantile_um(0.95);
        self.out.all.merge(&self.hist);
        self.hist = Histogram::default();
        let map = LayerMap {
            layer: l.layer,
            points: std::mem::take(&mut self.map),
            spots: std::mem::replace(&mut self.layer_top, TopSpots::new(5))
                .spots()
                .to_vec(),
        };
        if self.opts.map_layer == Some(map.layer) {
            self.out.chosen = Some(map.clone());
        }
        let maps = &mut self.out.maps;
        let at = maps.partition_point(|m| m.worst_um() >= map.worst_um());
        if at < self.opts.maps {
            maps.insert(at, map);
            maps.truncate(self.opts.maps);
        }
        self.out.layers.push(l);
    }

    fn sample(&mut self, k: u64, t: f64, toolhead_m: &[f64]) {
        self.out.samples += 1;
        self.active.retire(t);
        let [ix, iy] = self.opts.xy;
        let (x, y) = (toolhead_m[ix] * 1e3, toolhead_m[iy] * 1e3);
        let Some(err_mm) = self.active.error_mm(t, [x, y]) else {
            return;
        };
        let Some(m) = self.active.owner(t).cloned() else {
            return;
        };
        if self.owner.as_ref().is_none_or(|o| o.0 != m.index) {
            if self.layer.as_ref().is_none_or(|l| l.layer != m.layer) {
                self.end_layer();
                self.layer = Some(LayerStats::new(m.layer));
            } else {
                self.end_move();
            }
            self.owner = Some((m.index, m.kind, m.layer, m.line, None));
        }
        let err_um = err_mm * 1e3;
        let print = m.kind == MoveKind::Print;
        if print {
            self.hist.push(err_um);
            if let Some(o) = self.owner.as_mut()
                && o.4.as_ref().is_none_or(|s| err_um > s.error_um)
            {
                o.4 = Some(Spot {
                    error_um: err_um,
                    time_s: t,
                    x_mm: x,
                    y_mm: y,
                    line: m.line,
                    layer: m.layer,
                    move_index: m.index,
                });
            }
        }
        if k.is_multiple_of(self.map_every) {
            self.map.push(MapPoint {
                x_mm: x as f32,
                y_mm: y as f32,
                error_um: err_um as f32,
                print,
            });
        }
    }
}

/// Samples per [`Plant::step_samples`] call (as the harness's simulation loop).
const BATCH: usize = 256;

/// Simulate `job`'s chunks on `plant` (see the module doc).
pub fn simulate_job<R: BufRead, P: Plant>(
    job: &mut Job<R>,
    plant: &P,
    opts: StreamOptions,
    file: &Path,
) -> Result<Streamed, Error> {
    let n = opts.job_axes.len();
    let dt = 1.0 / opts.sample_rate_hz;
    let job_axes = opts.job_axes.clone();
    let mut acc = Account::new(opts);
    let mut state: Option<P::State> = None;
    let mut cmd = vec![Sample::default(); n];
    let mut cmd_p = vec![0.0; n];
    let mut toolhead = vec![0.0; n];
    let mut obs = vec![Observation::default(); n];
    let (mut t, mut k, mut t_first) = (0.0_f64, 0_u64, 0.0_f64);
    let sim_err = |source| Error::Sim { run: 0, source };
    // Runs of whole samples go to the plant in one call while it implements it.
    let mut batch = true;
    let mut cmds = vec![Sample::default(); BATCH * n];
    let (mut bcmd_p, mut btool) = (vec![0.0; BATCH * n], vec![0.0; BATCH * n]);
    // The sample at `t` (state `st`), checked in full: `true` when the plant faulted (the
    // fault is recorded and the simulation ends).
    macro_rules! sample_at {
        ($st:expr, $t:expr) => {{
            let t = $t;
            let ok = plant.positions($st, &mut cmd_p, &mut toolhead)
                && cmd_p
                    .iter()
                    .zip(&toolhead)
                    .all(|(c, h)| (h - c).abs() <= BLOWUP_M);
            let mut fault = false;
            if !ok {
                plant.observe($st, &mut obs);
                match crate::execute::simulate::fault_in(t, &acc.opts.names, &obs) {
                    Some(reason) => {
                        acc.out.fault = Some(reason);
                        fault = true;
                    }
                    None => {
                        for (h, o) in toolhead.iter_mut().zip(&obs) {
                            *h = o.toolhead_m;
                        }
                    }
                }
            }
            if !fault {
                acc.sample(k, t, &toolhead);
            }
            fault
        }};
    }
    'chunks: while let Some(chunk) = job.next_chunk().map_err(super::gcode_error(file))? {
        acc.active.add(&chunk.moves);
        let axes: Vec<Profile> = job_axes
            .iter()
            .map(|&i| chunk.trajectory.axes()[i].clone())
            .collect();
        let sub = Trajectory::new(axes).map_err(|source| Error::Plan { run: 0, source })?;
        // The chunk is stepped in its own time (`tau`, s from its start), so that a step
        // ends exactly on each breakpoint and the next step's command comes from the next
        // piece (a print-clock time `t0 + bp` taken back to the chunk's time can fall a
        // rounding error before the breakpoint: the previous piece's acceleration, held
        // for a whole step, would be a large error of the command). Samples are on the
        // print clock: sample `k` is at `k dt`, `k dt - t0` in the chunk.
        let t0 = chunk.start_time_s;
        let t1 = sub.duration_s();
        let mut cursor = Cursor::new(&sub);
        let mut tau = 0.0_f64;
        let st = match state.as_mut() {
            Some(s) => s,
            None => {
                let starts: Vec<_> = sub.axes().iter().map(Profile::start).collect();
                t_first = t0;
                k = (t0 / dt).ceil() as u64;
                state.insert(plant.initial_state(&starts).map_err(sim_err)?)
            }
        };
        let local = |k: u64| k as f64 * dt - t0;
        let bps = sub.breakpoints();
        let mut next_bp = 0;
        while tau < t1 {
            while next_bp < bps.len() && bps[next_bp] <= tau {
                next_bp += 1;
            }
            let t_sample = local(k);
            let bp = bps.get(next_bp).copied().unwrap_or(t1).min(t1);
            let next = t_sample.min(bp);
            let whole = next == t_sample && k > 0 && tau == local(k - 1);
            if whole && batch {
                // Whole samples k, k + 1, ... before the breakpoint: one call.
                let mut m = 1;
                while m < BATCH && local(k + m as u64) <= bp {
                    m += 1;
                }
                if m > 1 {
                    for i in 0..m {
                        cursor.at(local(k - 1 + i as u64), &mut cmds[i * n..(i + 1) * n]);
                    }
                    let (cp, th) = (&mut bcmd_p[..m * n], &mut btool[..m * n]);
                    match plant.step_samples(st, &cmds[..m * n], dt, BLOWUP_M, cp, th) {
                        Ok(Some(done)) if (1..=m).contains(&done) => {
                            for i in 0..done - 1 {
                                let ki = k + i as u64;
                                acc.sample(ki, ki as f64 * dt, &th[i * n..(i + 1) * n]);
                            }
                            k += done as u64 - 1;
                            tau = local(k);
                            t = k as f64 * dt;
                            // The last sample of the call is evaluated in full.
                            if sample_at!(st, t) {
                                break 'chunks;
                            }
                            k += 1;
                            continue;
                        }
                        Ok(_) => batch = false,
                        Err((_, source)) => return Err(sim_err(source)),
                    }
                }
            }
            cursor.at(tau, &mut cmd);
            let h = if whole { dt } else { next - tau };
            if h > 0.0 {
                plant.step(st, &cmd, h).map_err(sim_err)?;
            }
            tau = next;
            t = t0 + tau;
            if next == t_sample {
                t = k as f64 * dt;
                if sample_at!(st, t) {
                    break 'chunks;
                }
                k += 1;
            }
        }
    }
    acc.end_layer();
    if let Some(st) = state.as_ref() {
        plant.observe(st, &mut obs);
        acc.out.lost_steps = obs.iter().map(|o| o.lost_steps).sum();
    }
    acc.out.simulated_s = t - t_first;
    acc.out.worst = acc.top.spots().to_vec();
    Ok(acc.out)
}
