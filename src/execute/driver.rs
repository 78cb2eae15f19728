//! The simulation driver: one plant stepped through a command on a sample clock, every
//! sample handed to a [`Sink`]. Every command that simulates a machine runs it: a sweep's
//! runs and `settle run`'s traces ([`crate::execute::simulate`]) and `settle gcode`'s jobs
//! (`crate::workflows::gcode::stream`) are its sinks.
//!
//! - The clock: sample `k` is at `k / sample_rate` s. A command ([`Driver::follow`]) is a
//!   trajectory whose time 0 is `t0` on the clock; a motion's chunks follow one another
//!   on one clock, the plant's state carried across them ([`Driver::follow_chunks`], the
//!   one loop of a run and of a G-code job); [`Driver::hold`] holds a command, on a clock
//!   of its own (the observation window after a move) or on the driver's from where it
//!   stands (a G-code job's ringing after its last move).
//! - Steps are split at every breakpoint of every axis, so each axis's commanded jerk is
//!   constant within each step (the modal plant is then exact). A whole sample interval
//!   is stepped as exactly `1 / sample_rate` s.
//! - Runs of whole samples go to the plant in one call ([`Plant::step_samples`]) while it
//!   implements it and the sink does not record every sample in full; the last sample of
//!   each call is evaluated in full.
//! - A sample evaluated in full is checked: a non-finite value or an error past
//!   [`BLOWUP_M`] stops the driver with [`Stop::Fault`] ([`fault_in`]); a backend that
//!   fails stops it with [`Stop::Backend`]; an interruption (Ctrl-C, SIGTERM) requested
//!   ([`crate::execute::interrupt`]) is seen within [`INTERRUPT_POLL`] samples evaluated
//!   in full and stops it with [`Stop::Interrupted`].

use std::borrow::Cow;
use std::ops::ControlFlow;

use settle_planner::{Sample, State, Trajectory};
use settle_sim::{InnerBreak, Observation, Plant, SimError};

use crate::execute::cursor::Cursor;
use crate::execute::inner_breaks::AxisBreaks;
use crate::measure::metrics::BLOWUP_M;

/// Samples between two looks at [`crate::execute::interrupt::requested`].
pub const INTERRUPT_POLL: usize = 64;

/// Samples per [`Plant::step_samples`] call: long enough to make the per-call cost
/// negligible, short enough that the buffers stay in the first-level cache.
pub const CHUNK: usize = 256;

/// Why the driver stopped before the end of what it was asked to do.
#[derive(Debug)]
pub enum Stop {
    /// The sink asked to stop.
    Sink,
    /// A sample's values are not physical: the reason, with the axis and the time.
    Fault(String),
    /// The backend failed on the step that starts at `t_s` (s, on the clock).
    Backend {
        /// When the step started.
        t_s: f64,
        /// What the backend said.
        error: SimError,
    },
    /// An interruption was requested.
    Interrupted,
}

/// Times on a sample clock: sample `k` is at `origin_s + k dt_s` (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock {
    /// The time of sample 0 (s).
    pub origin_s: f64,
    /// The sample period (s).
    pub dt_s: f64,
}

impl Clock {
    /// The time of sample `k` (s). (`0 + x` is `x` bit for bit for every `x >= 0`: a clock
    /// at origin 0 gives `k dt` exactly.)
    #[inline]
    pub fn time(&self, k: u64) -> f64 {
        self.origin_s + k as f64 * self.dt_s
    }
}

/// Samples handed to a [`Sink`], sample-major: those of one [`Plant::step_samples`] call
/// (positions only: the plant vouched for them), or one sample evaluated in full (with
/// its command, and what the plant shows when it was observed).
#[derive(Debug)]
pub struct Samples<'a> {
    /// The first one's index on the clock.
    pub k0: u64,
    /// How many.
    pub count: usize,
    /// The clock.
    pub clock: Clock,
    /// Axes per sample.
    pub axes: usize,
    /// The commanded positions (m): sample `i`'s at `[i * axes ..]`.
    pub commanded_m: &'a [f64],
    /// The toolhead positions (m), the same layout.
    pub toolhead_m: &'a [f64],
    /// A sample evaluated in full: the command at that time, per axis.
    pub cmd: Option<&'a [Sample]>,
    /// A sample evaluated in full: what the plant shows, when it was observed (always
    /// when recording, or when the sink asked through [`Sink::observes`]).
    pub observed: Option<&'a [Observation]>,
}

impl Samples<'_> {
    /// The time of sample `i` (s).
    #[inline]
    pub fn time(&self, i: usize) -> f64 {
        self.clock.time(self.k0 + i as u64)
    }

    /// The commanded and toolhead positions of sample `i`.
    #[inline]
    pub fn positions(&self, i: usize) -> (&[f64], &[f64]) {
        let r = i * self.axes..(i + 1) * self.axes;
        (&self.commanded_m[r.clone()], &self.toolhead_m[r])
    }
}

/// What the driver hands its samples to.
pub trait Sink {
    /// Whether the next sample evaluated in full should come with the plant's
    /// observations (e.g. to see where a motor first loses steps).
    fn observes(&self) -> bool {
        false
    }

    /// Samples, in order; `Break(i)` stops the driver at sample `i` (taken): [`Stop::Sink`].
    fn samples(&mut self, s: &Samples<'_>) -> ControlFlow<usize>;
}

/// A plant, its state and the sample clock (see the module doc).
pub struct Driver<'p, P: Plant> {
    plant: &'p P,
    state: P::State,
    names: &'p [String],
    /// Sample `k` at `k / sample_rate` s.
    clock: Clock,
    /// The next sample's index on the clock.
    k: u64,
    /// The time of the last thing done (s): a step's end, or a sample.
    t: f64,
    /// Every sample observed in full (a recording): no batches.
    record: bool,
    /// The fewest samples a batch takes (fewer are stepped one by one); `usize::MAX`: no
    /// batches (when recording, or once the plant has declined one: [`Plant::step_samples`]
    /// returned `None`).
    min_batch: usize,
    /// Batches go across breakpoints where the plant can ([`Driver::across_breakpoints`]).
    across: bool,
    /// Per axis, the breakpoints inside the steps of the batch being made.
    breaks: Vec<Vec<InnerBreak>>,
    obs: Vec<Observation>,
    /// The command now, one sample per axis.
    cmd: Vec<Sample>,
    /// A batch's commands at its steps' starts (up to [`CHUNK`] samples, sample-major).
    cmds: Vec<Sample>,
    /// The commanded and toolhead positions (m) of the sample evaluated in full (the
    /// first axes' worth), or of a batch's samples (sample-major).
    cmd_p: Vec<f64>,
    toolhead: Vec<f64>,
    polls: usize,
}

impl<P: Plant> std::fmt::Debug for Driver<'_, P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Driver {{ next_sample: {}, .. }}", self.k)
    }
}

impl<'p, P: Plant> Driver<'p, P> {
    /// `plant` at rest at `start` (one state per axis, named `names`), its clock at
    /// `sample_rate_hz` with the next sample the first at or after `t0_s`; `record`: every
    /// sample evaluated in full.
    pub fn new(
        plant: &'p P,
        names: &'p [String],
        start: &[State],
        sample_rate_hz: f64,
        t0_s: f64,
        record: bool,
    ) -> Result<Self, SimError> {
        let (axes, dt) = (start.len(), 1.0 / sample_rate_hz);
        Ok(Self {
            state: plant.initial_state(start)?,
            plant,
            names,
            clock: Clock {
                origin_s: 0.0,
                dt_s: dt,
            },
            k: (t0_s / dt).ceil() as u64,
            t: 0.0,
            record,
            min_batch: if record { usize::MAX } else { 1 },
            across: false,
            breaks: vec![Vec::new(); axes],
            obs: vec![Observation::default(); axes],
            cmd: vec![Sample::default(); axes],
            cmds: vec![Sample::default(); CHUNK * axes],
            cmd_p: vec![0.0; CHUNK * axes],
            toolhead: vec![0.0; CHUNK * axes],
            polls: 0,
        })
    }

    /// The driver of a streamed motion (a G-code job's, in `settle gcode` or a sweep):
    /// batches across breakpoints ([`Driver::across_breakpoints`]) of two samples at least,
    /// a lone whole sample stepped through [`Plant::step`] as `settle gcode` has always
    /// stepped it (a plant's batch may take longer internal steps than one sample, MuJoCo's
    /// does: the choice can change the last bits).
    pub fn streamed(mut self) -> Self {
        self.min_batch = self.min_batch.max(2);
        self.across_breakpoints()
    }

    /// Batches of whole samples go on across the command's breakpoints where the plant
    /// steps across them exactly ([`Plant::step_samples_across`]: the modal plant) instead
    /// of ending at each breakpoint, whose step is then split there. The results agree
    /// with the split steps' to rounding, not bit for bit (a G-code job's command has
    /// breakpoints every millisecond or so; splitting there cost most of its time).
    pub fn across_breakpoints(mut self) -> Self {
        self.across = true;
        self
    }

    /// The time of the last thing done (s): the end of the last step, or the last sample
    /// handed to the sink.
    pub fn time_s(&self) -> f64 {
        self.t
    }

    /// The driver's clock (origin 0).
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// What the plant shows now.
    pub fn observe(&mut self) -> &[Observation] {
        self.plant.observe(&self.state, &mut self.obs);
        &self.obs
    }

    /// What the plant showed when it was last observed (by [`Driver::observe`] or at a
    /// sample evaluated in full).
    pub fn observations(&self) -> &[Observation] {
        &self.obs
    }

    /// Step `traj`, whose time 0 is `t0_s` on the clock, to its end, taking every sample
    /// of the clock from the next one on up to its end: before it (`with_end` false) or
    /// at it too.
    pub fn follow(
        &mut self,
        traj: &Trajectory,
        t0_s: f64,
        with_end: bool,
        sink: &mut impl Sink,
    ) -> Result<(), Stop> {
        let (clock, t1) = (self.clock, traj.duration_s());
        let dt = clock.dt_s;
        // Sample `k` in the trajectory's own time. The trajectory is stepped in its own
        // time so that a step ends exactly on each breakpoint and the next step's command
        // comes from the next piece (a clock time `t0 + bp` taken back to the
        // trajectory's time can fall a rounding error before the breakpoint: the previous
        // piece's acceleration, held for a whole step, would be a large error of the
        // command).
        let local = |k: u64| k as f64 * dt - t0_s;
        let takes = |tau: f64| tau < t1 || (with_end && tau <= t1);
        let mut breakpoints = traj.breakpoints().into_iter().peekable();
        let mut cursor = Cursor::new(traj);
        let mut inner = self.across.then(|| AxisBreaks::new(traj));
        let mut tau = 0.0_f64;
        while tau < t1 {
            while breakpoints.next_if(|&b| b <= tau).is_some() {}
            let bp = breakpoints.peek().map_or(t1, |&b| b.min(t1));
            let t_sample = local(self.k);
            let next = t_sample.min(bp);
            let at_sample = self.k > 0 && tau == local(self.k - 1);
            let whole = next == t_sample && at_sample;
            // Samples k, k + 1, ... in one call: up to the breakpoint (inclusive), so that
            // every step lies in one piece of every axis's command, or, across
            // breakpoints, up to the trajectory's end.
            let across = inner.is_some();
            let (k0, end) = (self.k, if across { t1 } else { bp });
            let fits = |&ts: &f64| at_sample && self.min_batch <= CHUNK && ts <= end && takes(ts);
            let m = (k0..k0 + CHUNK as u64).map(local).take_while(fits).count();
            if m >= self.min_batch {
                let n = self.cmd.len();
                for (i, c) in self.cmds.chunks_exact_mut(n).take(m).enumerate() {
                    cursor.at(local(k0 - 1 + i as u64), c);
                }
                if let Some(walk) = inner.as_mut() {
                    walk.fill(m, |i| local(k0 - 1 + i as u64), &mut self.breaks);
                }
                let fail = |i: usize| clock.time(k0 - 1 + i as u64);
                let done = self.batch(m, k0, clock, fail, across, sink)?;
                // The plant steps these samples one by one (so does the rest of the
                // trajectory, from this sample on), or the walk went past steps not taken.
                if done.is_none_or(|done| done < m) {
                    inner = None;
                }
                let Some(done) = done else { continue };
                self.k = k0 + done as u64 - 1;
                tau = local(self.k);
            } else {
                cursor.at(tau, &mut self.cmd);
                self.step(if whole { dt } else { next - tau }, t0_s + tau)?;
                tau = next;
                self.t = t0_s + tau;
                if next != t_sample {
                    continue;
                }
            }
            if takes(tau) {
                cursor.at(tau, &mut self.cmd);
                self.sample(self.k, clock, None, sink)?;
            }
            self.k += 1;
        }
        Ok(())
    }

    /// Follow a motion's chunks one after the other ([`Driver::follow`]): `first`, then
    /// each one `next` gives (handed the sink, which may be what reads them) until `None`.
    /// Every chunk's end is sampled but the last one's, unless `last_end`: a run samples
    /// its move's end apart (so it reads a chunk ahead, to know the last), a G-code job
    /// does not. A chunk that fails to come is the outer error.
    pub fn follow_chunks<'t, S: Sink, E>(
        &mut self,
        first: Option<Chunk<'t>>,
        mut next: impl FnMut(&mut S) -> Result<Option<Chunk<'t>>, E>,
        last_end: bool,
        sink: &mut S,
    ) -> Result<Result<(), Stop>, E> {
        let mut chunk = first;
        while let Some((t0, traj)) = chunk {
            let ahead = if last_end { None } else { next(sink)? };
            if let Err(stop) = self.follow(&traj, t0, last_end || ahead.is_some(), sink) {
                return Ok(Err(stop));
            }
            chunk = if last_end { next(sink)? } else { ahead };
        }
        Ok(Ok(()))
    }

    /// Hold `cmd` (one sample per axis, the driver's command from now on) to every sample
    /// `k` of `clock` from `first` to `last`, each after a step of one sample period taken
    /// at `clock.time(k)`; without `first`, from the driver's next sample, the step to it
    /// from where the driver stands (part of a period).
    pub fn hold(
        &mut self,
        cmd: &[Sample],
        first: Option<u64>,
        last: u64,
        clock: Clock,
        sink: &mut impl Sink,
    ) -> Result<(), Stop> {
        self.cmd.copy_from_slice(cmd);
        for c in self.cmds.chunks_exact_mut(cmd.len()) {
            c.copy_from_slice(cmd);
        }
        let (mut k, t, dt) = (first.unwrap_or(self.k), self.t, self.clock.dt_s);
        if first.is_none() && k <= last {
            self.step(clock.time(k) - t, t)?;
            self.sample(k, clock, None, sink)?;
            k += 1;
        }
        while k <= last {
            let m = (last - k + 1).min(CHUNK as u64) as usize;
            let fail = |i: usize| clock.time(k + i as u64) - dt;
            match (m >= self.min_batch).then(|| self.batch(m, k, clock, fail, false, sink)) {
                Some(Ok(Some(done))) => k += done as u64 - 1,
                Some(Err(stop)) => return Err(stop),
                _ => self.step(dt, clock.time(k) - dt)?,
            }
            self.sample(k, clock, None, sink)?;
            k += 1;
        }
        Ok(())
    }

    /// A step of `h` s (none if `h` is not positive) with the current command; a failure
    /// is reported at `t_fail`.
    fn step(&mut self, h: f64, t_fail: f64) -> Result<(), Stop> {
        if h > 0.0 {
            let result = self.plant.step(&mut self.state, &self.cmd, h);
            result.map_err(|error| Stop::Backend { t_s: t_fail, error })?;
        }
        Ok(())
    }

    /// `m` whole samples in one call from sample `k0` on, the commands at their step
    /// starts in [`Driver::cmds`]. The sink gets every sample but the last one done;
    /// `Some(done)`: `done` samples stepped, the state at the last one, which the caller
    /// evaluates in full. That also covers a plant that stopped at an unvouched last
    /// sample of the call (it returns `done == m` then, which reads as "all vouched
    /// for"), at one `positions` per call. `None`: the plant steps sample by sample
    /// (nothing was done; batches are off from now on). A step `i` that fails is reported
    /// at `fail(i)`. `across`: the steps hold the breakpoints in [`Driver::breaks`]
    /// ([`Plant::step_samples_across`]); `None` then leaves batches on.
    fn batch(
        &mut self,
        m: usize,
        k0: u64,
        clock: Clock,
        fail: impl Fn(usize) -> f64,
        across: bool,
        sink: &mut impl Sink,
    ) -> Result<Option<usize>, Stop> {
        let len = m * self.cmd.len();
        let (cmds, dt, state) = (&self.cmds[..len], self.clock.dt_s, &mut self.state);
        let (cmd_p, toolhead) = (&mut self.cmd_p[..len], &mut self.toolhead[..len]);
        let p = self.plant;
        let result = if across {
            let breaks: Vec<&[InnerBreak]> = self.breaks.iter().map(Vec::as_slice).collect();
            p.step_samples_across(state, cmds, &breaks, dt, BLOWUP_M, cmd_p, toolhead)
        } else {
            p.step_samples(state, cmds, dt, BLOWUP_M, cmd_p, toolhead)
        };
        let (count, outcome) = match result {
            Ok(Some(done)) if (1..=m).contains(&done) => (done - 1, Ok(Some(done))),
            Ok(_) if across => return Ok(None),
            Ok(_) => {
                self.min_batch = usize::MAX;
                return Ok(None);
            }
            Err((failed, error)) => {
                let t_s = fail(failed);
                (failed.min(m), Err(Stop::Backend { t_s, error }))
            }
        };
        if count > 0 {
            self.hand(k0, count, clock, None, sink)?;
        }
        outcome
    }

    /// Hand the sink samples `k0 ..` (`count` of them) of `clock`, their positions in
    /// [`Driver::cmd_p`] and [`Driver::toolhead`]: a batch's (`full` `None`), or a sample
    /// evaluated in full (`Some(observed)`: with the driver's command, and its observations
    /// when `observed`). The last sample the sink takes is the last thing done.
    fn hand(
        &mut self,
        k0: u64,
        count: usize,
        clock: Clock,
        full: Option<bool>,
        sink: &mut impl Sink,
    ) -> Result<(), Stop> {
        let (axes, len) = (self.cmd.len(), count * self.cmd.len());
        let view = Samples {
            k0,
            count,
            clock,
            axes,
            commanded_m: &self.cmd_p[..len],
            toolhead_m: &self.toolhead[..len],
            cmd: full.map(|_| &self.cmd[..]),
            observed: full.unwrap_or(false).then_some(&self.obs[..]),
        };
        let stop = sink.samples(&view);
        self.t = view.time(stop.break_value().unwrap_or(count - 1));
        match stop {
            ControlFlow::Break(_) => Err(Stop::Sink),
            ControlFlow::Continue(()) => Ok(()),
        }
    }

    /// Evaluate the plant now in full as sample `k` of `clock` (command `cmd` when given,
    /// the driver's command from then on; else the driver's current one): checked, handed
    /// to the sink, and an interruption looked for.
    pub fn sample(
        &mut self,
        k: u64,
        clock: Clock,
        cmd: Option<&[Sample]>,
        sink: &mut impl Sink,
    ) -> Result<(), Stop> {
        let t = clock.time(k);
        self.t = t;
        if let Some(cmd) = cmd {
            self.cmd.copy_from_slice(cmd);
        }
        let (plant, n) = (self.plant, self.cmd.len());
        let (cmd_p, toolhead) = (&mut self.cmd_p[..n], &mut self.toolhead[..n]);
        let within = |(c, h): (&f64, &f64)| (h - c).abs() <= BLOWUP_M;
        let observed = self.record
            || sink.observes()
            || !plant.positions(&self.state, cmd_p, toolhead)
            || !cmd_p.iter().zip(&*toolhead).all(within);
        if observed {
            // Every value finite and no blow-up is what `fault_in` checks; otherwise it
            // names the fault.
            plant.observe(&self.state, &mut self.obs);
            for ((c, h), o) in cmd_p.iter_mut().zip(toolhead.iter_mut()).zip(&self.obs) {
                (*c, *h) = (o.commanded_m, o.toolhead_m);
            }
            if let Some(reason) = fault_in(t, self.names, &self.obs) {
                return Err(Stop::Fault(reason));
            }
        }
        self.hand(k, 1, clock, Some(observed), sink)?;
        self.polls += 1;
        if self.polls.is_multiple_of(INTERRUPT_POLL) && crate::execute::interrupt::requested() {
            return Err(Stop::Interrupted);
        }
        Ok(())
    }
}

/// A chunk of a motion: its time 0 on the driver's clock (s) and its command.
pub type Chunk<'t> = (f64, Cow<'t, Trajectory>);

/// The command standing still at `ends` (one state per axis): their positions, no motion.
pub fn standing_at(ends: &[State]) -> Vec<Sample> {
    ends.iter()
        .map(|e| Sample {
            p: e.p,
            ..Sample::default()
        })
        .collect()
}

/// A simulation fault in the observations at `t`: a non-finite value, or an error beyond
/// [`BLOWUP_M`] (see there). `None` when everything is physical.
pub fn fault_in(t: f64, names: &[String], obs: &[Observation]) -> Option<String> {
    obs.iter().enumerate().find_map(|(i, o)| {
        let axis = names.get(i).map_or("?", String::as_str);
        let values = [
            ("toolhead position", Some(o.toolhead_m)),
            ("commanded position", Some(o.commanded_m)),
            ("carriage position", o.carriage_m),
            ("motor angle", o.motor_angle_rad),
        ];
        for (what, v) in values {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return Some(format!("{what} of axis {axis} became {v} at t = {t:.6} s"));
            }
        }
        let err = o.toolhead_m - o.commanded_m;
        (err.abs() > BLOWUP_M).then(|| {
            format!(
                "blow-up: axis {axis}'s toolhead is {err:.3e} m from its command \
                 at t = {t:.6} s (limit {BLOWUP_M} m)"
            )
        })
    })
}
