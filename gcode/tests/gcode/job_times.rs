//! Print times through the G-code job equal the firmware planners' hand-computed cases
//! (planner/tests/firmware_*.rs) and Klipper's own toolhead.py, to 1e-9 relative: the
//! same moves written as G-code plan the same.

use settle_gcode::job::{JobConfig, PlannerConfig};
use settle_gcode::{ArcSegmentation, Reader, ReaderOptions};
use settle_planner::firmware::Firmware;
use settle_planner::firmware::klipper::{KlipperConfig, KlipperPlanner};
use settle_planner::firmware::marlin::{MarlinConfig, MarlinJerk, MarlinPlanner};
use settle_planner::firmware::rrf::{RrfConfig, RrfPlanner};
use settle_planner::firmware::{FirmwarePlanner, LinearMove};

use crate::job_util::{MM, assert_rel, direct, job, leg, run};

fn klipper(v_mm_s: f64, a_mm_s2: f64, mcr: f64) -> KlipperConfig {
    let mut c = KlipperConfig::new(v_mm_s * MM, a_mm_s2 * MM);
    c.minimum_cruise_ratio = mcr;
    c
}

#[test]
fn klipper_hand_computed_cases() {
    let (v, a, l) = (100.0, 3000.0, 50.0);
    let (_, s) = run(
        "G1 X50 F6000\nG1 Y50\n",
        job(PlannerConfig::Klipper(klipper(v, a, 0.5))),
    );
    // A 90-degree corner at square_corner_velocity, 5 mm/s.
    assert_rel("corner", s.print_time_s, 2.0 * leg(l, v, a, 0.0, 5.0), 1e-9);
    let (_, s) = run(
        "G1 X50 F6000\nG1 X0\n",
        job(PlannerConfig::Klipper(klipper(v, a, 0.5))),
    );
    assert_rel("reversal", s.print_time_s, 2.0 * (l / v + v / a), 1e-9);
    // A 2 mm move: the pseudo-acceleration a (1 - r) sets the peak, v^2 = a (1 - r) L.
    for r in [0.0, 0.5, 0.8] {
        let (_, s) = run(
            "G1 X2 F6000\n",
            job(PlannerConfig::Klipper(klipper(v, a, r))),
        );
        let vc = (a * (1.0 - r) * 2.0).sqrt();
        let t = 2.0 * vc / a + (2.0 - vc * vc / a) / vc;
        assert_rel("minimum cruise ratio", s.print_time_s, t, 1e-9);
    }
    // Extrusion 0.05 then 0.01 mm per mm straight on: 1 mm/s / 0.04 = 25 mm/s.
    let (_, s) = run(
        "M83\nG1 X50 E2.5 F6000\nG1 X100 E0.5\n",
        job(PlannerConfig::Klipper(klipper(v, a, 0.5))),
    );
    assert_rel(
        "extruder corner",
        s.print_time_s,
        2.0 * leg(l, v, a, 0.0, 25.0),
        1e-9,
    );
}

/// The move list of Klipper's reference driver (planner/tests/firmware_klipper.rs,
/// `lcg_moves`), as G-code with absolute E (so the reader's E differences are the same
/// doubles) after `G92 Z0.25`, and as the planner's moves.
fn lcg(n: usize, seed: u64) -> (String, Vec<LinearMove>) {
    let lcg = |x: u64| (1_664_525 * x + 1_013_904_223) % (1 << 32);
    let (mut x, mut pos, mut moves) = (seed, [0.0, 0.0, 0.25, 0.0f64], Vec::new());
    let mut text = String::from("G90\nM82\nG92 Z0.25\n");
    for i in 0..n {
        x = lcg(x);
        let px = (x % 200) as f64 / 4.0;
        x = lcg(x);
        let py = (x % 200) as f64 / 4.0;
        x = lcg(x);
        let speed = 20.0 + (x % 200) as f64;
        x = lcg(x);
        let kind = x % 10;
        let z = if i % 17 == 16 { pos[2] + 0.25 } else { pos[2] };
        let end = match kind {
            0 => [pos[0], pos[1], pos[2], pos[3] - 0.75],
            1 => [px, py, z, pos[3]],
            _ => {
                let d =
                    ((px - pos[0]).powi(2) + (py - pos[1]).powi(2) + (z - pos[2]).powi(2)).sqrt();
                [px, py, z, pos[3] + d * 0.033]
            }
        };
        text.push_str(&format!(
            "G1 X{} Y{} Z{} E{} F{}\n",
            end[0],
            end[1],
            end[2],
            end[3],
            speed * 60.0
        ));
        moves.push(LinearMove::new(
            [pos[0] * MM, pos[1] * MM, pos[2] * MM],
            [end[0] * MM, end[1] * MM, end[2] * MM],
            (end[3] - pos[3]) * MM,
            speed * MM,
        ));
        pos = end;
    }
    (text, moves)
}

fn klipper_driver_cfg() -> KlipperConfig {
    let mut c = klipper(300.0, 3000.0, 0.5);
    c.max_z_velocity_m_s = 15.0 * MM;
    c.max_z_accel_m_s2 = 100.0 * MM;
    if let Some(e) = c.extruder.as_mut() {
        e.instantaneous_corner_velocity_m_s = 1.0 * MM;
        e.max_extrude_only_velocity_m_s = 120.0 * MM;
        e.max_extrude_only_accel_m_s2 = 1500.0 * MM;
    }
    c
}

#[test]
fn klipper_mixed_job_matches_toolhead_py() {
    // Print times from Klipper's own klippy/toolhead.py on this move list (commit
    // 84104bbbd, committed in planner/tests/firmware_klipper.rs).
    for (n, seed, want) in [
        (40, 7, 13.269525672242882),
        (400, 12345, 141.70163830015153),
    ] {
        let (text, moves) = lcg(n, seed);
        let (chunks, s) = run(&text, job(PlannerConfig::Klipper(klipper_driver_cfg())));
        assert_rel("toolhead.py", s.print_time_s, want, 1e-9);
        let mut p = KlipperPlanner::new(klipper_driver_cfg()).expect("config");
        assert_eq!(
            s.print_time_s,
            direct(&mut p, &moves),
            "same doubles, same plan"
        );
        // The chunks cover the print (plus the shaper-free rest at the end).
        let last = chunks.last().expect("chunks");
        assert!(last.end_time_s() >= want);
        let per_layer: f64 = s.layers.iter().map(|l| l.duration_s).sum();
        assert_rel("layer account", per_layer, want, 1e-12);
    }
}

#[test]
fn marlin_hand_computed_and_direct_cases() {
    // X 100 mm at 100 mm/s, 80 steps/mm: 8000 steps at 8000 steps/s, 240000 steps/s^2,
    // entry and exit at 120 steps/s; 134 acceleration steps (ceil), 133 deceleration
    // steps (floor), the deceleration cut at its 133rd step (planner/tests/firmware_marlin.rs).
    let (n, rn, a, r0): (f64, f64, f64, f64) = (8000.0, 8000.0, 240_000.0, 120.0);
    let (na, nd) = (134.0, 133.0);
    let d_up = (rn * rn - r0 * r0) / (2.0 * a);
    let t_acc = (rn - r0) / a + (na - d_up) / rn;
    let t_cruise = (n - na - nd) / rn;
    let t_dec = 2.0 * nd / (rn + (rn * rn - 2.0 * a * nd).sqrt());
    let (_, s) = run(
        "G1 X100 F6000\n",
        job(PlannerConfig::Marlin(MarlinConfig::new())),
    );
    assert_rel(
        "straight block",
        s.print_time_s,
        t_acc + t_cruise + t_dec,
        1e-9,
    );
    // Corners under junction deviation and classic jerk: as the planner plans the moves.
    let mut classic = MarlinConfig::new();
    classic.jerk = MarlinJerk::Classic {
        max_jerk_m_s: [10.0 * MM, 10.0 * MM, 0.3 * MM, 5.0 * MM],
        travel_extra_xy_jerk_m_s: 0.0,
    };
    let corner = [
        LinearMove::new([0.0; 3], [0.05, 0.0, 0.0], 0.0, 0.1),
        LinearMove::new([0.05, 0.0, 0.0], [0.05, 0.05, 0.0], 0.0, 0.1),
    ];
    for cfg in [MarlinConfig::new(), classic] {
        let (_, s) = run("G1 X50 F6000\nG1 Y50\n", job(PlannerConfig::Marlin(cfg)));
        let want = direct(&mut MarlinPlanner::new(cfg).expect("config"), &corner);
        assert_rel("corner", s.print_time_s, want, 1e-9);
    }
}

#[test]
fn rrf_hand_computed_cases() {
    let (l, v, a) = (50.0, 100.0, 1000.0);
    let cfg = || job(PlannerConfig::Rrf(RrfConfig::new()));
    // M203 X100 mm/s and M201 X1000 (the defaults) bind a 150 mm/s request.
    let (_, s) = run("G1 X100 F9000\n", cfg());
    assert_rel("straight", s.print_time_s, 0.1 / 0.1 + 0.1 / 1.0, 1e-9);
    // 90 degrees: each axis changes by the corner speed, within M566's 15 mm/s.
    let (_, s) = run("G1 X50 F6000\nG1 Y50\n", cfg());
    assert_rel(
        "corner",
        s.print_time_s,
        2.0 * leg(l, v, a, 0.0, 15.0),
        1e-9,
    );
    // Printing then travelling straight on: jerk policy 0 stops between them.
    let (_, s) = run("M83\nG1 X50 E2 F6000\nG1 X100\n", cfg());
    assert_rel(
        "print then travel",
        s.print_time_s,
        2.0 * leg(l, v, a, 0.0, 0.0),
        1e-9,
    );
}

#[test]
fn arcs_plan_as_the_firmware_cuts_them() {
    // A quarter and a half circle: the job plans exactly the segments the firmware's arc
    // code makes (Move::segments_for), as straight moves.
    let text = "G1 X10 Y0 F3000\nG3 X0 Y10 I-10 J0 F3000\nG2 X0 Y-10 I0 J-10\n";
    for fw in [Firmware::Klipper, Firmware::Marlin, Firmware::Rrf] {
        let cfg = JobConfig::defaults(fw).expect("defaults");
        let (_, s) = run(text, cfg.clone());
        let mut moves = Vec::new();
        let reader = Reader::new(text.as_bytes(), ReaderOptions::new(cfg.dialect));
        for ev in reader {
            if let settle_gcode::EventKind::Move(mv) = ev.expect("event").kind {
                let mut prev = mv.start;
                for p in mv.segments_for(&ArcSegmentation::default_for(cfg.dialect)) {
                    moves.push(LinearMove::new(
                        [prev.x_mm * MM, prev.y_mm * MM, prev.z_mm * MM],
                        [p.x_mm * MM, p.y_mm * MM, p.z_mm * MM],
                        (p.e_mm - prev.e_mm) * MM,
                        mv.feed_mm_s * MM,
                    ));
                    prev = p;
                }
            }
        }
        assert!(moves.len() > 20, "{fw}: {} segments", moves.len());
        let mut p: Box<dyn FirmwarePlanner> = match &cfg.planner {
            PlannerConfig::Klipper(c) => Box::new(KlipperPlanner::new(*c).expect("c")),
            PlannerConfig::Marlin(c) | PlannerConfig::Prusa(c) => {
                Box::new(MarlinPlanner::new(*c).expect("c"))
            }
            PlannerConfig::Rrf(c) => Box::new(RrfPlanner::new(*c).expect("c")),
            PlannerConfig::Grbl(_) | PlannerConfig::Settle(_) => {
                unreachable!("printer firmwares only")
            }
        };
        assert_eq!(s.print_time_s, direct(p.as_mut(), &moves), "{fw}");
        assert_eq!(s.segments as usize, moves.len(), "{fw}");
        assert_eq!(cfg.dialect, settle_gcode::Dialect::of(fw));
    }
}
