//! The harness's lean path with [`Plant::step_samples`] (several samples per call) gives
//! the same metrics and the same status, faults included (time and reason), as stepping
//! sample by sample. A wrapper plant around the modal plant injects faults at a chosen
//! step: a failing step, a blow-up, a NaN, and a sample the plant declines to vouch for
//! although it is fine.

use std::path::Path;

use settle::Metrics;
use settle::execute::Observe;
use settle::execute::plant::Simulation;
use settle::execute::simulate::{AxisMeta, Run};
use settle::studies::Motion;
use settle_planner::{Limits, Profile, ProfileKind, Sample, State, Trajectory};
use settle_sim::{AxisModel, DriverMode, ModalPlant, Observation, Plant, SimError};

/// What the wrapper does at its `at`-th step (0-based count of steps since the start).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fault {
    None,
    /// The step fails.
    StepFails,
    /// From this step on the toolhead is 0.2 m off (past the blow-up limit).
    BlowsUp,
    /// From this step on the toolhead is NaN.
    Nan,
    /// `step_samples` stops after this step's sample without vouching for it (although it
    /// is fine).
    Declines,
}

/// The modal plant with an injected fault, stepping several samples per call (`batch`)
/// or not (the per-sample path).
struct Wrapped {
    inner: ModalPlant,
    batch: bool,
    fault: Fault,
    at: usize,
    /// Steps taken so far in the run.
    steps: std::cell::Cell<usize>,
}

struct WState {
    inner: <ModalPlant as Plant>::State,
    steps: usize,
}

impl Wrapped {
    fn offset(&self, st: &WState) -> f64 {
        match self.fault {
            Fault::BlowsUp if st.steps > self.at => 0.2,
            Fault::Nan if st.steps > self.at => f64::NAN,
            _ => 0.0,
        }
    }
}

impl Plant for Wrapped {
    type State = WState;

    fn axes(&self) -> usize {
        self.inner.axes()
    }

    fn initial_state(&self, start: &[State]) -> Result<WState, SimError> {
        Ok(WState {
            inner: self.inner.initial_state(start)?,
            steps: 0,
        })
    }

    fn step(&self, st: &mut WState, cmd: &[Sample], dt_s: f64) -> Result<(), SimError> {
        if self.fault == Fault::StepFails && st.steps == self.at {
            return Err(SimError::InvalidStep { dt_s: -1.0 });
        }
        st.steps += 1;
        self.steps.set(st.steps);
        self.inner.step(&mut st.inner, cmd, dt_s)
    }

    fn observe(&self, st: &WState, out: &mut [Observation]) {
        self.inner.observe(&st.inner, out);
        let off = self.offset(st);
        for o in out.iter_mut() {
            o.toolhead_m += off;
        }
    }

    fn positions(&self, st: &WState, commanded_m: &mut [f64], toolhead_m: &mut [f64]) -> bool {
        let ok = self.inner.positions(&st.inner, commanded_m, toolhead_m);
        let off = self.offset(st);
        for h in toolhead_m.iter_mut() {
            *h += off;
        }
        ok && off.is_finite()
    }

    fn step_samples(
        &self,
        st: &mut WState,
        cmds: &[Sample],
        dt_s: f64,
        blowup_m: f64,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        if !self.batch {
            return Ok(None);
        }
        let n = self.axes();
        for (i, cmd) in cmds.chunks_exact(n).enumerate() {
            self.step(st, cmd, dt_s).map_err(|e| (i, e))?;
            let (c, h) = (
                &mut commanded_m[i * n..(i + 1) * n],
                &mut toolhead_m[i * n..(i + 1) * n],
            );
            let vouched = self.positions(st, c, h)
                && c.iter()
                    .zip(h.iter())
                    .all(|(c, h)| (h - c).abs() <= blowup_m)
                && !(self.fault == Fault::Declines && st.steps == self.at + 1);
            if !vouched {
                return Ok(Some(i + 1));
            }
        }
        Ok(Some(cmds.len() / n))
    }
}

struct Case {
    axes: Vec<AxisModel>,
    traj: Trajectory,
    observe: Observe,
}

impl Case {
    fn run(&self, batch: bool, fault: Fault, at: usize) -> Metrics {
        self.run_counting(batch, fault, at).0
    }

    /// The metrics and the number of steps taken.
    fn run_counting(&self, batch: bool, fault: Fault, at: usize) -> (Metrics, usize) {
        let plant = Wrapped {
            inner: ModalPlant::new(self.axes.clone(), 1.0 / self.observe.sample_rate_hz)
                .expect("modal"),
            batch,
            fault,
            at,
            steps: std::cell::Cell::new(0),
        };
        let m = self.simulate(&plant);
        (m, plant.steps.get())
    }

    /// The plain modal plant (its own `step_samples`, if any).
    fn modal(&self) -> Metrics {
        let plant =
            ModalPlant::new(self.axes.clone(), 1.0 / self.observe.sample_rate_hz).expect("modal");
        self.simulate(&plant)
    }

    /// The run on `plant`.
    fn simulate(&self, plant: &impl Plant) -> Metrics {
        let names: Vec<String> = self.axes.iter().map(|a| a.name.clone()).collect();
        let meta: Vec<AxisMeta> = self.axes.iter().map(AxisMeta::of).collect();
        let run = Run {
            names: &names,
            meta: &meta,
            motion: &mut Motion::Whole(self.traj.clone()),
            observe: &self.observe,
            record: None,
        };
        run.run(plant).expect("plans").expect("simulates")
    }
}

/// Equal bit for bit (`Debug` prints every digit of an `f64`, and NaN equals NaN there).
fn same(a: &Metrics, b: &Metrics) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// The bench's run: printer_xy, a 10 mm S-curve on Y, X idle, 0.5 s at 10 kHz.
fn printer_case() -> Case {
    let (_, path, text) = settle::input::machine_file::PRESETS[0];
    let (machine, _) = settle::input::machine_file::parse(text, Path::new(path)).expect("preset");
    let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
    let y = ProfileKind::SCurve
        .rest_to_rest(0.0, 0.01, &lim)
        .expect("plan");
    Case {
        axes: machine.compile(DriverMode::Linear).expect("compile"),
        traj: Trajectory::new(vec![Profile::empty(State::default()), y]).expect("trajectory"),
        observe: Observe {
            window_s: 0.5,
            sample_rate_hz: 10_000.0,
            bands_um: vec![10.0, 50.0],
        },
    }
}

/// A 90 degree blended corner on the printer (both axes move; path metrics).
fn corner_case() -> Case {
    let text = r#"name = "corner"
[machine]
preset = "printer_xy"
driver_model = "linear"
[corner]
angle_deg = 90.0
leg_in_mm = 20.0
leg_out_mm = 20.0
strategy = "blend"
blend_deviation_mm = 0.05
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.1
sample_rate_hz = 10000
bands_um = [10.0]
"#;
    let (sc, src) = settle::expand::parse(text, Path::new("corner.toml")).expect("parses");
    let runs = settle::expand::expand(&sc, &src).expect("expands");
    let spec = &runs[0];
    let axes = settle::execute::axes_of(spec).expect("axes");
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let traj = settle::studies::plan(spec, &names)
        .expect("plan")
        .motion
        .whole()
        .expect("a corner is planned whole")
        .clone();
    assert!(traj.path().is_some(), "a path run");
    Case {
        axes,
        traj,
        observe: Observe {
            window_s: spec.window_s,
            sample_rate_hz: spec.sample_rate_hz,
            bands_um: spec.bands_um.clone(),
        },
    }
}

/// Faults at steps `ats`, and at the last two steps of the run.
fn check(case: &Case, ats: &[usize]) {
    let (plain, steps) = case.run_counting(false, Fault::None, 0);
    let mut ats = ats.to_vec();
    ats.extend([steps - 2, steps - 1]);
    assert!(plain.is_ok(), "{:?}", plain.status);
    assert!(same(&plain, &case.run(true, Fault::None, 0)));
    assert!(same(&plain, &case.modal()), "the modal plant's own path");
    if let Some(p) = &plain.path {
        assert!(p.max_contour_error_um > 0.0, "path metrics measured");
    }
    for fault in [
        Fault::StepFails,
        Fault::BlowsUp,
        Fault::Nan,
        Fault::Declines,
    ] {
        for &at in &ats {
            let a = case.run(false, fault, at);
            let b = case.run(true, fault, at);
            assert!(
                same(&a, &b),
                "{fault:?} at step {at}:\n per sample {a:?}\n batched {b:?}"
            );
            if fault == Fault::Declines {
                assert!(same(&a, &plain), "nothing failed");
            } else {
                assert_eq!(a.status.name(), "fault", "{fault:?} at {at}");
            }
        }
    }
}

#[test]
fn batched_samples_match_the_per_sample_path_with_and_without_faults() {
    // Steps 0 and 1, inside the move (a chunk's first and last), the last move steps
    // (the move has 1490 samples and 6 breakpoints inside), the first window steps, a
    // chunk boundary in the window.
    let case = printer_case();
    check(
        &case,
        &[
            0, 1, 255, 256, 700, 1488, 1494, 1495, 1496, 1497, 1500, 1752, 1753, 3000,
        ],
    );
}

#[test]
fn batched_samples_match_on_a_corner_path() {
    check(&corner_case(), &[0, 300, 900, 2000]);
}
