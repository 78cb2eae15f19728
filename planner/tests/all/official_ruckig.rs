//! Cross-check against the official Ruckig library (C++, through the `ruckig` crate), on
//! the Ruckig paper's distribution: 1-DoF durations and 3-DoF time-synchronised
//! durations. Case count: `SETTLE_PLANNER_RUCKIG_CASES` (default 100,000 1-DoF, a tenth of
//! that 3-DoF).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use settle_planner::position::{Shape, to_state};
use settle_planner::sync::{Axis, Sync, plan};

use crate::common::{braked, draw_axis};

fn cases() -> usize {
    std::env::var("SETTLE_PLANNER_RUCKIG_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(100_000)
}

fn official(axes: &[Axis]) -> Option<f64> {
    let n = axes.len();
    let mut otg = ruckig::Ruckig::new_direct_and_offline(n);
    let mut input = ruckig::InputParameter::new(n);
    for (i, a) in axes.iter().enumerate() {
        input.current_position[i] = a.start.p;
        input.current_velocity[i] = a.start.v;
        input.current_acceleration[i] = a.start.a;
        input.target_position[i] = a.target.p;
        input.target_velocity[i] = a.target.v;
        input.target_acceleration[i] = a.target.a;
        input.max_velocity[i] = a.limits.vmax();
        input.max_acceleration[i] = a.limits.amax();
        input.max_jerk[i] = a.limits.jmax().expect("jerk");
    }
    let mut traj = ruckig::Trajectory::new_direct(n);
    match otg.calculate(&mut input, &mut traj) {
        ruckig::Result::Working | ruckig::Result::Finished => Some(traj.get_duration()),
        _ => None,
    }
}

#[test]
fn one_dof_durations_equal_the_official_ruckig() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let (mut equal, mut shorter) = (0, 0);
    for _ in 0..cases() {
        let a = draw_axis(&mut rng);
        let ours = to_state(a.start, a.target, &a.limits, Shape::JerkLimited);
        let (prof, t) = match (ours, official(&[a])) {
            (Ok(p), Some(t)) => (p, t),
            (Err(_), None) => continue,
            (o, t) => panic!(
                "only one solved: ours {:?} ruckig {t:?}: {a:?}",
                o.map(|p| p.duration_s())
            ),
        };
        let rel = (prof.duration_s() - t) / t;
        if rel.abs() <= 1e-9 {
            equal += 1;
        } else if rel < 0.0 && braked(&a) {
            shorter += 1;
        } else {
            panic!("duration {} vs ruckig {t}: {a:?}", prof.duration_s());
        }
    }
    eprintln!("1-DoF vs official Ruckig: equal {equal}, shorter after a brake {shorter}");
}

#[test]
fn three_dof_time_sync_vs_the_official_ruckig() {
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let (mut equal, mut shorter, mut longer) = (0usize, 0usize, 0usize);
    for _ in 0..cases() / 10 {
        let axes = [
            draw_axis(&mut rng),
            draw_axis(&mut rng),
            draw_axis(&mut rng),
        ];
        let (profs, t) = match (plan(&axes, Shape::JerkLimited, Sync::Time), official(&axes)) {
            (Ok(p), Some(t)) => (p, t),
            (Err(_), None) => continue,
            (o, t) => panic!(
                "only one solved: ours {:?} ruckig {t:?}: {axes:?}",
                o.map(|p| p.len())
            ),
        };
        let rel = (profs[0].duration_s() - t) / t;
        if rel.abs() <= 1e-9 {
            equal += 1;
        } else if rel < 0.0 && axes.iter().any(braked) {
            shorter += 1;
        } else {
            longer += 1;
        }
    }
    eprintln!(
        "3-DoF vs official Ruckig: equal {equal}, shorter after a brake {shorter}, longer {longer}"
    );
    // As in multi_axis.rs: never longer.
    assert!(
        longer == 0,
        "{longer} synchronised durations longer than Ruckig's"
    );
}
