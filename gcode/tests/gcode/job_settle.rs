//! settle's planner on G-code: a file that fits one look-ahead window plans as
//! `plan_path` plans the same path (the corner run kind's planner): the same trajectory
//! bit for bit (unshaped axes pass through the shaping stage unchanged), the same
//! duration.

use settle_gcode::job::{JobConfig, PlannerConfig};
use settle_planner::firmware::Firmware;
use settle_planner::path::{Path, PathPoint, plan_path};
use settle_planner::{Sample, Trajectory};

use crate::job_util::{MM, at, run};

fn check(text: &str, points: &[[f64; 3]]) {
    let cfg = JobConfig::defaults(Firmware::Settle).expect("defaults");
    let PlannerConfig::Settle(settle) = &cfg.planner else {
        unreachable!("settle defaults");
    };
    let n = points.len();
    let pts = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let p = [p[0] * MM, p[1] * MM, p[2] * MM];
            if i == 0 || i + 1 == n {
                PathPoint::waypoint(p)
            } else {
                PathPoint::control(p)
            }
        })
        .collect();
    let want: Trajectory = plan_path(
        &Path::new(3, pts).expect("path"),
        &settle.path_options().expect("options"),
    )
    .expect("plan");
    let (chunks, s) = run(text, cfg.clone());
    assert_eq!(chunks[0].start_time_s, 0.0);
    let end = chunks.last().expect("chunks").end_time_s();
    assert_eq!(chunks.len(), 1);
    assert_eq!(end, want.duration_s());
    assert_eq!(s.print_time_s, want.duration_s());
    let mut w = [Sample::default(); 3];
    for k in 0..=5000 {
        let t = end * k as f64 / 5000.0;
        want.state_at(t, &mut w);
        let g = at(&chunks, t);
        for i in 0..3 {
            assert_eq!(
                (g[i].p, g[i].v, g[i].a),
                (w[i].p, w[i].v, w[i].a),
                "t {t} axis {i}"
            );
        }
    }
}

#[test]
fn a_single_corner_file_is_plan_path() {
    // Feed 400 mm/s, above settle's vmax (300 mm/s): the path limits apply.
    check(
        "G1 X50 F24000\nG1 X50 Y50\n",
        &[[0.0; 3], [50.0, 0.0, 0.0], [50.0, 50.0, 0.0]],
    );
}

#[test]
fn a_straight_line_file_is_plan_path() {
    check("G1 X100 F24000\n", &[[0.0; 3], [100.0, 0.0, 0.0]]);
}
