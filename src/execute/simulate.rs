//! The simulation loop: drive a plant through a trajectory sample by sample (or in runs of
//! samples where the plant can), then hold the end point for the observation window,
//! feeding the streaming metrics and, when asked, a full [`Series`].

use settle_planner::{Profile, Sample, State, Trajectory};
use settle_sim::{AxisModel, DriverMode, Observation, Plant, SimError};

use crate::execute::Observe;
use crate::measure::accumulator::Accumulator;
use crate::measure::metrics::{Metrics, Status};
use crate::measure::series::Series;

/// The channels [`crate::execute::execute`] records for these axes: per axis `cmd_p_<axis>` (m),
/// `cmd_v_<axis>` (m/s), `cmd_a_<axis>` (m/s^2), `cmd_j_<axis>` (m/s^3), `toolhead_<axis>`
/// (m), `error_<axis>` (toolhead - command, m) and, where the model has them,
/// `carriage_<axis>` (m), `motor_angle_<axis>` (rad), `load_angle_<axis>` (electrical
/// rad), `current_a_<axis>`, `current_b_<axis>` (A, full driver); then `error` (length of
/// the toolhead-minus-command vector, m).
pub fn channels(axes: &[AxisModel]) -> Vec<(String, String)> {
    let mut ch = Vec::new();
    for a in axes {
        let n = &a.name;
        for (c, u) in [
            ("cmd_p", "m"),
            ("cmd_v", "m_s"),
            ("cmd_a", "m_s2"),
            ("cmd_j", "m_s3"),
            ("toolhead", "m"),
            ("error", "m"),
        ] {
            ch.push((format!("{c}_{n}"), u.to_string()));
        }
        if a.carriage.is_some() {
            ch.push((format!("carriage_{n}"), "m".into()));
        }
        if a.stepper.is_some() {
            ch.push((format!("motor_angle_{n}"), "rad".into()));
            ch.push((format!("load_angle_{n}"), "rad".into()));
        }
        if a.mode == DriverMode::Full {
            ch.push((format!("current_a_{n}"), "A".into()));
            ch.push((format!("current_b_{n}"), "A".into()));
        }
    }
    ch.push(("error".into(), "m".into()));
    ch
}

/// Which optional channels an axis records.
#[derive(Debug, Clone, Copy)]
pub struct AxisMeta {
    carriage: bool,
    motor: bool,
    currents: bool,
}

impl AxisMeta {
    /// What `axis` has.
    pub fn of(axis: &AxisModel) -> Self {
        Self {
            carriage: axis.carriage.is_some(),
            motor: axis.stepper.is_some(),
            currents: axis.mode == DriverMode::Full,
        }
    }
}

/// Drive `plant` through `traj`, then hold the end point for the observation window.
///
/// Samples are taken every `1/sample_rate` s during the move, exactly at the move end T,
/// and every `1/sample_rate` s after T. Plant steps are split at every breakpoint of every
/// axis, so each axis's commanded jerk is constant within each step (the modal plant is
/// then exact).
pub fn simulate<P: Plant>(
    plant: &P,
    names: &[String],
    meta: &[AxisMeta],
    traj: &Trajectory,
    observe: &Observe,
    mut record: Option<&mut Series>,
) -> Result<Metrics, SimError> {
    let n_axes = traj.dof();
    let dt = 1.0 / observe.sample_rate_hz;
    let t_end = traj.duration_s();
    let starts: Vec<State> = traj.axes().iter().map(Profile::start).collect();
    let ends: Vec<State> = traj.axes().iter().map(Profile::end).collect();
    let target: Vec<f64> = ends.iter().map(|e| e.p).collect();
    let direction: Vec<f64> = starts.iter().zip(&ends).map(|(s, e)| e.p - s.p).collect();
    let mut acc = Accumulator::new(&target, &direction, t_end, &observe.bands_um);
    let mut path_acc = traj
        .path()
        .map(|g| crate::measure::path_metrics::PathAccumulator::new(g, t_end));
    let mut state = plant.initial_state(&starts)?;
    let mut obs = vec![Observation::default(); n_axes];
    let mut cmd = vec![Sample::default(); n_axes];
    let mut row: Vec<f64> = Vec::new();
    let mut cmd_p = vec![0.0; n_axes];
    let mut toolhead = vec![0.0; n_axes];
    // Without a recording the metrics need only the positions: plants that can report
    // them directly ([`Plant::positions`]) skip building observations; `obs` is then
    // brought up to date where it is read (a fault, the end of the run).
    let lean = record.is_none();
    // The lean path steps runs of whole samples in one call ([`Plant::step_samples`])
    // while the plant implements it: its buffers, allocated once per run.
    let mut batch = lean.then(|| Batch::new(n_axes));
    let mut cursor = crate::execute::cursor::Cursor::new(traj);

    let mut sample = |t: f64,
                      at: &[Sample],
                      state: &P::State,
                      obs: &mut [Observation],
                      acc: &mut Accumulator,
                      path_acc: &mut Option<crate::measure::path_metrics::PathAccumulator>|
     -> Result<(), String> {
        let checked = lean
            && plant.positions(state, &mut cmd_p, &mut toolhead)
            && cmd_p
                .iter()
                .zip(&toolhead)
                .all(|(c, h)| (h - c).abs() <= crate::measure::metrics::BLOWUP_M);
        if !checked {
            // Every value finite and no blow-up is what `fault_in` checks; otherwise it
            // names the fault.
            plant.observe(state, obs);
            for (i, o) in obs.iter().enumerate() {
                cmd_p[i] = o.commanded_m;
                toolhead[i] = o.toolhead_m;
            }
            if let Some(reason) = fault_in(t, names, obs) {
                return Err(reason);
            }
        }
        acc.push(t, &cmd_p, &toolhead);
        let contour = path_acc.as_mut().map(|p| p.push(t, &toolhead));
        if let Some(rec) = record.as_deref_mut() {
            row.clear();
            let mut f2 = 0.0;
            for ((o, c), m) in obs.iter().zip(at).zip(meta) {
                let f = o.toolhead_m - o.commanded_m;
                f2 += f * f;
                row.extend([c.p, c.v, c.a, c.j, o.toolhead_m, f]);
                if m.carriage {
                    row.push(o.carriage_m.unwrap_or(f64::NAN));
                }
                if m.motor {
                    row.push(o.motor_angle_rad.unwrap_or(f64::NAN));
                    row.push(o.load_angle_rad.unwrap_or(f64::NAN));
                }
                if m.currents {
                    let [ia, ib] = o.currents_a.unwrap_or([f64::NAN; 2]);
                    row.extend([ia, ib]);
                }
            }
            row.push(f2.sqrt());
            row.extend(contour);
            rec.push(t, &row);
        }
        Ok(())
    };
    // A fault ends the run where it happened; what was measured so far is kept in the
    // accumulator but reported as a failed run (no metric values).
    let angles_of = |obs: &[Observation]| -> Vec<Option<f64>> {
        obs.iter().map(|o| o.max_load_angle_rad).collect()
    };
    macro_rules! fault {
        ($reason:expr) => {{
            if lean {
                plant.observe(&state, &mut obs);
            }
            return Ok(acc.finish_with(names, &angles_of(&obs), Status::Fault { reason: $reason }));
        }};
    }
    macro_rules! step {
        ($cmd:expr, $dt:expr, $t:expr) => {
            if let Err(e) = plant.step(&mut state, $cmd, $dt) {
                fault!(format!("the backend failed at t = {:.6} s: {e}", $t));
            }
        };
    }
    // An interruption (Ctrl-C, SIGTERM) ends a run in progress: polled every
    // `INTERRUPT_POLL` evaluated samples (a batch of up to `CHUNK` samples counts once), a
    // few milliseconds of work on any backend. The caller sees the interruption and drops
    // the run (`crate::execute::execute`).
    let mut polls = 0usize;
    macro_rules! sample {
        ($t:expr, $cmd:expr) => {
            if let Err(reason) = sample($t, $cmd, &state, &mut obs, &mut acc, &mut path_acc) {
                fault!(reason);
            }
            polls += 1;
            if polls % INTERRUPT_POLL == 0 && crate::execute::interrupt::requested() {
                fault!(INTERRUPTED.to_string());
            }
        };
    }
    // `m` whole samples in one call, the commands at their step starts in `b.cmds`; the
    // sample after step `i` is at `time(i)` and a failed step `i` is reported at
    // `fail_time(i)` (what the per-sample path prints). Pushes every sample but the last
    // one done; `Some(done)`: `done` samples stepped, the state at the last one, which the
    // caller evaluates in full (`sample!`: the per-sample path's check and push). That
    // also covers a plant that stopped at an unvouched last sample of the call (it returns
    // `done == m` then, which reads as "all vouched for"), at one `positions` per call.
    // `None`: the plant steps sample by sample (nothing was done).
    macro_rules! batch {
        ($b:expr, $m:expr, $time:expr, $fail_time:expr) => {{
            let b: &mut Batch = $b;
            let m: usize = $m;
            let len = m * n_axes;
            match plant.step_samples(
                &mut state,
                &b.cmds[..len],
                dt,
                crate::measure::metrics::BLOWUP_M,
                &mut b.cmd_p[..len],
                &mut b.toolhead[..len],
            ) {
                Ok(Some(done)) if (1..=m).contains(&done) => {
                    b.push(done - 1, &$time, &mut acc, &mut path_acc);
                    Some(done)
                }
                Ok(_) => None,
                Err((failed, e)) => {
                    b.push(failed.min(m), &$time, &mut acc, &mut path_acc);
                    fault!(format!(
                        "the backend failed at t = {:.6} s: {e}",
                        $fail_time(failed)
                    ));
                }
            }
        }};
    }

    let breakpoints = traj.breakpoints();
    let mut next_bp = 0usize;
    cursor.at(0.0, &mut cmd);
    sample!(0.0, &cmd);
    let mut k = 1usize; // index of the next sample during the move
    let mut t = 0.0;
    let mut fresh = true; // `cmd` already holds the command at `t`
    while t < t_end {
        while next_bp < breakpoints.len() && breakpoints[next_bp] <= t {
            next_bp += 1;
        }
        let bp = breakpoints
            .get(next_bp)
            .copied()
            .unwrap_or(t_end)
            .min(t_end);
        let t_sample = k as f64 * dt;
        let next = t_sample.min(bp);
        if !fresh {
            cursor.at(t, &mut cmd);
        }
        // A whole sample interval is stepped as exactly `dt` (k dt - (k-1) dt can differ
        // from dt in the last bit, which would cost the modal plant a fresh transition
        // matrix); partial steps at breakpoints use their true length.
        let whole = next == t_sample && t == (k - 1) as f64 * dt;
        if whole
            && t_sample < t_end
            && let Some(b) = batch.as_mut()
        {
            // Samples k, k + 1, ... up to the breakpoint (inclusive) and before the end:
            // every step lies in one piece of every axis's command.
            let mut m = 1;
            while m < CHUNK {
                let ts = (k + m) as f64 * dt;
                if ts > bp || ts >= t_end {
                    break;
                }
                m += 1;
            }
            b.cmds[..n_axes].copy_from_slice(&cmd);
            for i in 1..m {
                cursor.at(
                    (k + i - 1) as f64 * dt,
                    &mut b.cmds[i * n_axes..(i + 1) * n_axes],
                );
            }
            let k0 = k;
            // (Sample indices are far below 2^63: `i64` converts in one instruction and
            // gives the same value as `usize`.)
            let time = |i: usize| (k0 + i) as i64 as f64 * dt;
            let fail_time = |i: usize| (k0 - 1 + i) as f64 * dt;
            match batch!(b, m, time, fail_time) {
                Some(done) => {
                    t = time(done - 1);
                    // The command at the last sample serves it and the next step.
                    cursor.at(t, &mut cmd);
                    sample!(t, &cmd);
                    fresh = true;
                    k += done;
                    continue;
                }
                None => batch = None,
            }
        }
        step!(&cmd, if whole { dt } else { next - t }, t);
        t = next;
        fresh = false;
        if t_sample <= bp {
            if t_sample < t_end {
                // The command at t serves the sample and the next step.
                cursor.at(t, &mut cmd);
                sample!(t, &cmd);
                fresh = true;
            }
            k += 1;
        }
    }
    // The end of the move, then the observation window at the end point.
    let hold: Vec<Sample> = ends
        .iter()
        .map(|e| Sample {
            p: e.p,
            ..Sample::default()
        })
        .collect();
    if t_end > 0.0 {
        sample!(t_end, &hold);
    }
    let n = (observe.window_s * observe.sample_rate_hz).ceil() as usize;
    let mut i = 1;
    let mut hold_filled = false;
    while i <= n {
        if let Some(b) = batch.as_mut() {
            if !hold_filled {
                for c in b.cmds.chunks_exact_mut(n_axes) {
                    c.copy_from_slice(&hold);
                }
                hold_filled = true;
            }
            let m = (n + 1 - i).min(CHUNK);
            let i0 = i;
            let time = |j: usize| t_end + (i0 + j) as i64 as f64 * dt;
            let fail_time = |j: usize| time(j) - dt;
            match batch!(b, m, time, fail_time) {
                Some(done) => {
                    sample!(time(done - 1), &hold);
                    i += done;
                    continue;
                }
                None => batch = None,
            }
        }
        let t = t_end + i as f64 * dt;
        step!(&hold, dt, t - dt);
        sample!(t, &hold);
        i += 1;
    }
    if lean {
        plant.observe(&state, &mut obs);
    }
    let lost: u32 = obs.iter().map(|o| o.lost_steps).sum();
    let status = match obs.iter().position(|o| o.lost_steps > 0) {
        Some(i) => Status::LostSteps {
            axis: names[i].clone(),
            steps: lost,
        },
        None => Status::Ok,
    };
    let mut metrics = acc.finish_with(names, &angles_of(&obs), status);
    metrics.path = path_acc.map(|p| p.finish());
    Ok(metrics)
}

/// Samples between two looks at [`crate::execute::interrupt::requested`].
const INTERRUPT_POLL: usize = 64;

/// The fault reason of a run ended by an interruption.
pub const INTERRUPTED: &str = "interrupted";

/// Samples per [`Plant::step_samples`] call: long enough to make the per-call cost
/// negligible, short enough that the buffers stay in the first-level cache.
const CHUNK: usize = 256;

/// The buffers of [`Plant::step_samples`] calls (up to [`CHUNK`] samples, sample-major).
#[derive(Debug)]
struct Batch {
    axes: usize,
    cmds: Vec<Sample>,
    cmd_p: Vec<f64>,
    toolhead: Vec<f64>,
}

impl Batch {
    fn new(axes: usize) -> Self {
        Self {
            axes,
            cmds: vec![Sample::default(); CHUNK * axes],
            cmd_p: vec![0.0; CHUNK * axes],
            toolhead: vec![0.0; CHUNK * axes],
        }
    }

    /// Push the first `count` samples into the metrics (as the per-sample path does), the
    /// `i`-th at `time(i)`.
    fn push(
        &self,
        count: usize,
        time: &impl Fn(usize) -> f64,
        acc: &mut Accumulator,
        path_acc: &mut Option<crate::measure::path_metrics::PathAccumulator>,
    ) {
        acc.push_run(count, time, &self.cmd_p, &self.toolhead);
        if let Some(p) = path_acc.as_mut() {
            for (i, h) in self
                .toolhead
                .chunks_exact(self.axes)
                .take(count)
                .enumerate()
            {
                p.push(time(i), h);
            }
        }
    }
}

/// A simulation fault in the observations at `t`: a non-finite value, or an error beyond
/// [`crate::measure::metrics::BLOWUP_M`] (see there). `None` when everything is physical.
pub fn fault_in(t: f64, names: &[String], obs: &[Observation]) -> Option<String> {
    for (i, o) in obs.iter().enumerate() {
        let axis = names.get(i).map_or("?", String::as_str);
        let values = [
            ("toolhead position", Some(o.toolhead_m)),
            ("commanded position", Some(o.commanded_m)),
            ("carriage position", o.carriage_m),
            ("motor angle", o.motor_angle_rad),
        ];
        for (what, v) in values {
            if let Some(v) = v
                && !v.is_finite()
            {
                return Some(format!("{what} of axis {axis} became {v} at t = {t:.6} s"));
            }
        }
        let err = o.toolhead_m - o.commanded_m;
        if err.abs() > crate::measure::metrics::BLOWUP_M {
            return Some(format!(
                "blow-up: axis {axis}'s toolhead is {:.3e} m from its command at t = {t:.6} s (limit {} m)",
                err,
                crate::measure::metrics::BLOWUP_M
            ));
        }
    }
    None
}
