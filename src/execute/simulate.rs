//! One run of a sweep (or `settle run`) on the simulation driver: its motion (a trajectory
//! planned whole, or streamed chunk by chunk), then the end point held for the observation
//! window, feeding the streaming metrics and, when asked, a full [`Series`].

use std::borrow::Cow;
use std::ops::ControlFlow;

use settle_planner::{PlanError, Profile, Sample, State};
use settle_sim::{AxisModel, DriverMode, Observation, Plant, SimError};

use crate::execute::Observe;
use crate::execute::driver::{Chunk, Clock, Driver, Samples, Sink, Stop, standing_at};
use crate::execute::plant::{SimOptions, Simulation, with_plant};
use crate::measure::accumulator::Accumulator;
use crate::measure::metrics::{Metrics, Status};
use crate::measure::path_metrics::PathAccumulator;
use crate::measure::series::Series;
use crate::spec::backend::Backend;
use crate::studies::{Motion, MotionStream};

/// A per-axis channel of a recording: its name (the axis's is appended: `cmd_p_x`), its
/// unit, and its value from the command and the observation of the axis.
type Column = (&'static str, &'static str, fn(&Sample, &Observation) -> f64);

/// The channels every axis records: the command, the toolhead and its error (toolhead -
/// command).
const COMMON: [Column; 6] = [
    ("cmd_p", "m", |c, _| c.p),
    ("cmd_v", "m_s", |c, _| c.v),
    ("cmd_a", "m_s2", |c, _| c.a),
    ("cmd_j", "m_s3", |c, _| c.j),
    ("toolhead", "m", |_, o| o.toolhead_m),
    ("error", "m", |_, o| o.toolhead_m - o.commanded_m),
];

/// The carriage's channel (m), where the model has a carriage.
const CARRIAGE: Column = ("carriage", "m", |_, o| o.carriage_m.unwrap_or(f64::NAN));

/// The motor's channels (rad; the load angle in electrical rad), where it has a stepper.
const MOTOR: [Column; 2] = [
    ("motor_angle", "rad", |_, o| {
        o.motor_angle_rad.unwrap_or(f64::NAN)
    }),
    ("load_angle", "rad", |_, o| {
        o.load_angle_rad.unwrap_or(f64::NAN)
    }),
];

/// The phase currents (A), for the full driver model.
const CURRENTS: [Column; 2] = [
    ("current_a", "A", |_, o| {
        o.currents_a.map_or(f64::NAN, |c| c[0])
    }),
    ("current_b", "A", |_, o| {
        o.currents_a.map_or(f64::NAN, |c| c[1])
    }),
];

/// The channels [`crate::execute::execute`] records for these axes: per axis `cmd_p_<axis>` (m),
/// `cmd_v_<axis>` (m/s), `cmd_a_<axis>` (m/s^2), `cmd_j_<axis>` (m/s^3), `toolhead_<axis>`
/// (m), `error_<axis>` (toolhead - command, m) and, where the model has them,
/// `carriage_<axis>` (m), `motor_angle_<axis>` (rad), `load_angle_<axis>` (electrical
/// rad), `current_a_<axis>`, `current_b_<axis>` (A, full driver); then `error` (length of
/// the toolhead-minus-command vector, m).
pub fn channels(axes: &[AxisModel]) -> Vec<(String, String)> {
    let mut ch = Vec::new();
    for a in axes {
        for (c, u, _) in AxisMeta::of(a).columns {
            ch.push((format!("{c}_{}", a.name), u.to_string()));
        }
    }
    ch.push(("error".into(), "m".into()));
    ch
}

/// The channels an axis records, in order ([`channels`]).
#[derive(Debug, Clone)]
pub struct AxisMeta {
    columns: Vec<Column>,
}

impl AxisMeta {
    /// What `axis` has.
    pub fn of(axis: &AxisModel) -> Self {
        let mut columns = COMMON.to_vec();
        if axis.carriage.is_some() {
            columns.push(CARRIAGE);
        }
        if axis.stepper.is_some() {
            columns.extend(MOTOR);
        }
        if axis.mode == DriverMode::Full {
            columns.extend(CURRENTS);
        }
        Self { columns }
    }
}

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
