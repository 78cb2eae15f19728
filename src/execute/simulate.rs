//! One run of a sweep (or `settle run`) on the simulation driver: its motion (a trajectory
//! planned whole, or streamed chunk by chunk), then the end point held for the observation
//! window, feeding the streaming metrics and, when asked, a full [`Series`].

use std::borrow::Cow;
use std::ops::ControlFlow;

use settle_planner::{PlanError, Profile, State};
use settle_sim::{AxisModel, Plant, SimError};

use crate::execute::Observe;
use crate::execute::driver::{Chunk, Clock, Driver, Samples, Sink, Stop, standing_at};
use crate::execute::plant::{SimOptions, Simulation, with_plant};
use crate::measure::accumulator::Accumulator;
pub use crate::measure::channels::{AxisMeta, channels};
use crate::measure::metrics::{Metrics, Status};
use crate::measure::path_metrics::PathAccumulator;
use crate::measure::series::Series;
use crate::spec::backend::Backend;
use crate::studies::{Motion, MotionStream};

/// Simulate `motion` (one profile per axis of `axes`, in their order; planned whole or
/// streamed) on `backend` and measure it against its end point ([`Run`]). When
/// `record` is given, it is replaced by a series with the run's channels ([`channels`],
/// and `contour_error` for a path) and every sample is appended to it. A chunk of a
/// streamed motion that fails to plan is the outer error.
pub fn run_motion(
    axes: Vec<AxisModel>,
    backend: Backend,
    options: &SimOptions,
    motion: &mut Motion,
    observe: &Observe,
    record: Option<&mut Series>,
) -> Result<Result<Metrics, SimError>, PlanError> {
    let (starts, _) = bounds(motion);
    if starts.len() != axes.len() {
        return Ok(Err(SimError::AxisCount {
            expected: axes.len(),
            got: starts.len(),
        }));
    }
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let record = record.map(|rec| {
        let mut ch = channels(&axes);
        if motion.whole().is_some_and(|t| t.path().is_some()) {
            // Distance from the toolhead to the commanded path.
            ch.push(("contour_error".into(), "m".into()));
        }
        *rec = Series::with_channels(ch);
        rec
    });
    let meta: Vec<AxisMeta> = axes.iter().map(AxisMeta::of).collect();
    let start_m: Vec<f64> = starts.iter().map(|s| s.p).collect();
    let run = Run {
        names: &names,
        meta: &meta,
        motion,
        observe,
        record,
    };
    let rate = observe.sample_rate_hz;
    with_plant(backend, axes, options, rate, &start_m, run).unwrap_or_else(|e| Ok(Err(e)))
}

/// Where `motion` starts and ends, per axis.
fn bounds(motion: &Motion) -> (Vec<State>, Vec<State>) {
    match motion {
        Motion::Whole(t) => (
            t.axes().iter().map(Profile::start).collect(),
            t.axes().iter().map(Profile::end).collect(),
        ),
        Motion::Stream(s) => (s.start.clone(), s.end.clone()),
    }
}

/// A run on a plant ([`Simulation::run`]): the [`Driver`] through `motion`, then the end
/// point held for the observation window, measuring the run ([`Accumulator`], the contour
/// error of a path, a streamed motion's own measurement) and recording every sample into
/// `record` when given.
///
/// A whole trajectory is a stream of one chunk. A streamed motion (a G-code job,
/// [`crate::studies::Motion::Stream`]) is driven chunk by chunk on one sample clock, as
/// `settle gcode` steps it (across breakpoints; a lone whole sample through
/// `Plant::step`); a chunk that fails to plan is the outer error. Samples are taken every
/// `1/sample_rate` s during the move, exactly at the move end T (with the command standing
/// at the end point), and every `1/sample_rate` s after T. A fault ends the run where it
/// happened: what was measured so far is kept in the accumulator but reported as a failed
/// run (no metric values).
#[derive(Debug)]
pub struct Run<'a> {
    /// The axes' names.
    pub names: &'a [String],
    /// The channels each axis records.
    pub meta: &'a [AxisMeta],
    /// The motion, one profile per axis.
    pub motion: &'a mut Motion,
    /// How it is observed.
    pub observe: &'a Observe,
    /// The recording (its channels already set), when asked.
    pub record: Option<&'a mut Series>,
}

impl Simulation for Run<'_> {
    type Output = Result<Result<Metrics, SimError>, PlanError>;

    fn run<P: Plant>(self, plant: &P) -> Self::Output {
        let (starts, ends) = bounds(self.motion);
        let (t_end, observe) = (self.motion.duration_s(), self.observe);
        let hold = standing_at(&ends);
        // The command at the move's end; a move of no duration: the trajectory at 0.
        let mut at_end = hold.clone();
        let (whole, stream) = match self.motion {
            Motion::Whole(t) => (Some(&*t), None),
            Motion::Stream(s) => (None, Some(&mut *s.chunks as &mut dyn MotionStream)),
        };
        if let Some(t) = whole.filter(|_| t_end <= 0.0) {
            t.state_at(0.0, &mut at_end);
        }
        let target: Vec<f64> = ends.iter().map(|e| e.p).collect();
        let direction: Vec<f64> = starts.iter().zip(&ends).map(|(s, e)| e.p - s.p).collect();
        let mut sink = RunSink {
            acc: Accumulator::new(&target, &direction, t_end, &observe.bands_um),
            path: whole.and_then(|t| t.path().map(|g| PathAccumulator::new(g, t_end))),
            stream,
            record: self.record,
            meta: self.meta,
            row: Vec::new(),
        };
        // A whole trajectory is a stream of one chunk.
        let first = match whole {
            Some(t) => Some((0.0, Cow::Borrowed(t))),
            None => sink.next_chunk()?,
        };
        let (rate, full) = (observe.sample_rate_hz, sink.record.is_some());
        let mut driver = match Driver::new(plant, self.names, &starts, rate, 0.0, full) {
            Ok(d) if sink.stream.is_some() => d.streamed(),
            Ok(d) => d,
            Err(e) => return Ok(Err(e)),
        };
        let ran = driver.follow_chunks(first, RunSink::next_chunk, false, &mut sink)?;
        // The end of the move, then the observation window at the end point.
        let n = (observe.window_s * rate).ceil() as u64;
        let window = Clock {
            origin_s: t_end,
            ..driver.clock()
        };
        let ran = ran.and_then(|()| {
            driver.sample(0, window, Some(&at_end), &mut sink)?;
            driver.hold(&hold, Some(1), n, window, &mut sink)
        });
        Ok(Ok(sink.finish(&mut driver, self.names, ran)))
    }
}

/// The fault reason of a run ended by an interruption.
pub const INTERRUPTED: &str = "interrupted";

/// A run's sink: the streaming metrics, the measurement of a streamed motion, and the
/// recording when asked.
struct RunSink<'a, 'g> {
    acc: Accumulator,
    path: Option<PathAccumulator<'g>>,
    stream: Option<&'a mut dyn MotionStream>,
    record: Option<&'a mut Series>,
    meta: &'a [AxisMeta],
    row: Vec<f64>,
}

impl<'g> RunSink<'_, 'g> {
    /// A streamed motion's next chunk.
    fn next_chunk(&mut self) -> Result<Option<Chunk<'g>>, PlanError> {
        let Some(s) = self.stream.as_deref_mut() else {
            return Ok(None);
        };
        Ok(s.next_chunk()?.map(|(t0, c)| (t0, Cow::Owned(c))))
    }

    /// The run's metrics: a fault, a backend failure or an interruption makes it a failed
    /// run, lost steps another; a streamed motion adds its figures to an ok run's.
    fn finish<P: Plant>(
        self,
        driver: &mut Driver<'_, P>,
        names: &[String],
        ran: Result<(), Stop>,
    ) -> Metrics {
        let reason = match ran {
            Ok(()) | Err(Stop::Sink) => None,
            Err(Stop::Fault(reason)) => Some(reason),
            Err(Stop::Backend { t_s, error }) => {
                Some(format!("the backend failed at t = {t_s:.6} s: {error}"))
            }
            Err(Stop::Interrupted) => Some(INTERRUPTED.to_string()),
        };
        // A recording observed every sample, the last one too.
        if self.record.is_none() {
            driver.observe();
        }
        let obs = driver.observations();
        let angles: Vec<Option<f64>> = obs.iter().map(|o| o.max_load_angle_rad).collect();
        if let Some(reason) = reason {
            return self
                .acc
                .finish_with(names, &angles, Status::Fault { reason });
        }
        let status = match obs.iter().position(|o| o.lost_steps > 0) {
            Some(i) => Status::LostSteps {
                axis: names[i].clone(),
                steps: obs.iter().map(|o| o.lost_steps).sum(),
            },
            None => Status::Ok,
        };
        let mut metrics = self.acc.finish_with(names, &angles, status);
        metrics.path = self.path.map(|p| p.finish());
        if let Some(s) = self.stream.filter(|_| metrics.is_ok()) {
            s.measure(&mut metrics);
        }
        metrics
    }
}

impl Sink for RunSink<'_, '_> {
    fn samples(&mut self, s: &Samples<'_>) -> ControlFlow<usize> {
        self.acc
            .push_run(s.count, |i| s.time(i), s.commanded_m, s.toolhead_m);
        if let Some(st) = self.stream.as_deref_mut() {
            let clock = [s.clock.origin_s, s.clock.dt_s];
            st.samples(clock, s.k0, s.toolhead_m, s.axes);
        }
        if self.path.is_none() && self.record.is_none() {
            return ControlFlow::Continue(());
        }
        for i in 0..s.count {
            let (t, toolhead) = (s.time(i), s.positions(i).1);
            let contour = self.path.as_mut().map(|p| p.push(t, toolhead));
            let (Some(rec), Some(obs), Some(cmd)) = (self.record.as_deref_mut(), s.observed, s.cmd)
            else {
                continue;
            };
            let row = &mut self.row;
            row.clear();
            let mut f2 = 0.0;
            for ((o, c), m) in obs.iter().zip(cmd).zip(self.meta) {
                let f = o.toolhead_m - o.commanded_m;
                f2 += f * f;
                row.extend(m.columns.iter().map(|(_, _, value)| value(c, o)));
            }
            row.push(f2.sqrt());
            row.extend(contour);
            rec.push(t, row);
        }
        ControlFlow::Continue(())
    }
}
