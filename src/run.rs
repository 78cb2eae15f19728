//! Executing one run: plan the profile, drive the plant through it and through the
//! observation window, and compute the metrics while streaming.

use settle_planner::{Profile, Sample};
use settle_sim::{AxisModel, ModalPlant, Observation, Plant};

use crate::error::Error;
use crate::metrics::{Accumulator, Metrics};
use crate::series::Series;
use crate::sweep::RunSpec;

/// Channels recorded by [`execute`] when asked for a series.
pub const CHANNELS: [(&str, &str); 6] = [
    ("cmd_p", "m"),
    ("cmd_v", "m_s"),
    ("cmd_a", "m_s2"),
    ("cmd_j", "m_s3"),
    ("toolhead", "m"),
    ("error", "m"),
];

/// Plan and simulate one run on the modal reference plant. When `record` is given, every
/// sample is also appended to it (see [`CHANNELS`]).
pub fn execute(spec: &RunSpec, record: Option<&mut Series>) -> Result<Metrics, Error> {
    let plan_err = |source| Error::Plan {
        run: spec.id,
        source,
    };
    let limits = spec.limits_si().map_err(plan_err)?;
    let profile = spec
        .profile
        .rest_to_rest(spec.start_mm * 1e-3, spec.distance_mm * 1e-3, &limits)
        .map_err(plan_err)?;
    let modes = spec.modes_sim().map_err(|source| Error::Sim {
        run: spec.id,
        source,
    })?;
    let plant = AxisModel::from_modes("x", &modes)
        .and_then(|axis| ModalPlant::new(vec![axis], 1.0 / spec.sample_rate_hz))
        .map_err(|source| Error::Sim {
            run: spec.id,
            source,
        })?;
    simulate(&plant, &profile, spec, record).map_err(|source| Error::Sim {
        run: spec.id,
        source,
    })
}

/// Drive `plant` through `profile`, then hold the end point for the observation window.
///
/// Samples are taken every `1/sample_rate` s during the move, exactly at the move end T, and
/// every `1/sample_rate` s after T. Plant steps are split at every profile breakpoint, so the
/// commanded jerk is constant within each step (the modal plant is then exact).
pub fn simulate<P: Plant>(
    plant: &P,
    profile: &Profile,
    spec: &RunSpec,
    mut record: Option<&mut Series>,
) -> Result<Metrics, settle_sim::SimError> {
    let dt = 1.0 / spec.sample_rate_hz;
    let t_end = profile.duration_s();
    let end = profile.end();
    let direction =
        (end.p - profile.start().p).signum() * f64::from(u8::from(spec.distance_mm != 0.0));
    let mut acc = Accumulator::new(end.p, direction, t_end, &spec.bands_um);
    let mut state = plant.initial_state(&[profile.start()])?;

    let mut obs = [Observation::default()];
    let mut observe = |t: f64, cmd: &Sample, state: &P::State, acc: &mut Accumulator| {
        plant.observe(state, &mut obs);
        let o = obs[0];
        acc.push(t, o.commanded_m, o.toolhead_m);
        if let Some(rec) = record.as_deref_mut() {
            rec.push(
                t,
                &[
                    cmd.p,
                    cmd.v,
                    cmd.a,
                    cmd.j,
                    o.toolhead_m,
                    o.toolhead_m - o.commanded_m,
                ],
            );
        }
    };

    // The move: walk the segments, stepping to each sample time or segment end.
    let mut k = 1usize; // index of the next sample during the move
    let first = profile.state_at(0.0);
    observe(0.0, &first, &state, &mut acc);
    for (t0, s0, seg) in profile.iter() {
        let t1 = t0 + seg.duration_s();
        let mut t = t0;
        while t < t1 {
            let t_sample = k as f64 * dt;
            let next = t_sample.min(t1);
            let cmd = seg.sample(&s0, t - t0);
            // A whole sample interval is stepped as exactly `dt` (k dt - (k-1) dt can differ
            // from dt in the last bit, which would cost the plant a fresh transition
            // matrix); partial steps at breakpoints use their true length.
            let whole = next == t_sample && t == (k - 1) as f64 * dt;
            plant.step(&mut state, &[cmd], if whole { dt } else { next - t })?;
            t = next;
            if t_sample <= t1 {
                if t_sample < t_end {
                    let now = seg.sample(&s0, t - t0);
                    observe(t, &now, &state, &mut acc);
                }
                k += 1;
            }
        }
    }
    // The end of the move, then the observation window at the end point.
    let hold = Sample {
        p: end.p,
        ..Sample::default()
    };
    if t_end > 0.0 {
        observe(t_end, &hold, &state, &mut acc);
    }
    let n = (spec.window_s * spec.sample_rate_hz).ceil() as usize;
    for i in 1..=n {
        plant.step(&mut state, &[hold], dt)?;
        observe(t_end + i as f64 * dt, &hold, &state, &mut acc);
    }
    Ok(acc.finish())
}
