//! A lean-path driver for the MuJoCo tests: what the harness does without a recording,
//! i.e. [`Plant::step_samples`] over every run of whole samples between two breakpoints of
//! the command, [`Plant::step`] for the partial steps at breakpoints.

#![allow(dead_code)]

use settle_planner::{Profile, Sample, State};
use settle_sim::{Observation, Plant};

/// The same sampling as `common::run` (every `dt` from 0 to the move end plus `window`, and
/// the same breakpoints), through the lean path. Each sample's observation carries only
/// the commanded and toolhead positions (what `step_samples` reports), except the last,
/// which is observed in full. Panics if the plant does not implement `step_samples` or a
/// sample fails its checks.
pub fn run_lean<P: Plant>(
    plant: &P,
    profiles: &[Profile],
    dt: f64,
    window: f64,
) -> Vec<(f64, Vec<Observation>)> {
    let n_axes = profiles.len();
    let starts: Vec<State> = profiles.iter().map(Profile::start).collect();
    let mut st = plant.initial_state(&starts).expect("state");
    let (t_end, bps) = super::common::breakpoints(profiles);
    let mut out = Vec::new();
    let mut obs = vec![Observation::default(); n_axes];
    plant.observe(&st, &mut obs);
    out.push((0.0, obs.clone()));
    let stop = t_end + window;
    let (mut cmd_p, mut head) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    let mut k = 1usize;
    while t < stop - 1e-12 {
        let ts = k as f64 * dt;
        let next_bp = super::common::next_breakpoint(&bps, t);
        // Whole samples up to the next breakpoint (or the end).
        let limit = next_bp.min(stop + 1e-12);
        let mut m = 0usize;
        while ((k + m) as f64) * dt <= limit {
            m += 1;
        }
        if t == (k - 1) as f64 * dt && m > 0 {
            let cmds: Vec<Sample> = (0..m)
                .flat_map(|j| {
                    let tj = (k - 1 + j) as f64 * dt;
                    profiles.iter().map(move |p| p.state_at(tj))
                })
                .collect();
            cmd_p.resize(m * n_axes, 0.0);
            head.resize(m * n_axes, 0.0);
            let done = plant
                .step_samples(&mut st, &cmds, dt, 1.0, &mut cmd_p, &mut head)
                .expect("step_samples")
                .expect("the plant implements step_samples");
            assert_eq!(done, m, "a sample failed the plant's checks");
            for j in 0..m {
                let o = (0..n_axes)
                    .map(|a| Observation {
                        commanded_m: cmd_p[j * n_axes + a],
                        toolhead_m: head[j * n_axes + a],
                        ..Observation::default()
                    })
                    .collect();
                out.push(((k + j) as f64 * dt, o));
            }
            k += m;
            t = (k - 1) as f64 * dt;
            continue;
        }
        let next = ts.min(next_bp);
        let cmd: Vec<Sample> = profiles.iter().map(|p| p.state_at(t)).collect();
        plant.step(&mut st, &cmd, next - t).expect("step");
        t = next;
        if next == ts {
            let (mut c, mut h) = (vec![0.0; n_axes], vec![0.0; n_axes]);
            assert!(plant.positions(&st, &mut c, &mut h), "positions");
            let o = (0..n_axes)
                .map(|a| Observation {
                    commanded_m: c[a],
                    toolhead_m: h[a],
                    ..Observation::default()
                })
                .collect();
            out.push((t, o));
            k += 1;
        }
    }
    plant.observe(&st, &mut obs);
    let last = out.last_mut().expect("samples");
    for (o, full) in last.1.iter_mut().zip(&obs) {
        assert_eq!(
            o.toolhead_m, full.toolhead_m,
            "the last sample is the state"
        );
        *o = *full;
    }
    out
}
