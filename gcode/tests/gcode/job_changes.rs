//! Limit and shaper changes in the middle of a file: the moves after a limit command plan
//! with the new limits; a shaper command drains the planner (Klipper also pauses for both
//! shapers' flush delays) and shapes what follows with the new shaper, the motion before
//! keeping the old one.

use settle_gcode::job::{JobChunk, JobConfig, PlannerConfig, ShaperSetting};
use settle_planner::firmware::Firmware;
use settle_planner::firmware::klipper::KlipperConfig;
use settle_planner::firmware::marlin::{MarlinConfig, MarlinPlanner};
use settle_planner::firmware::rrf::RrfConfig;
use settle_planner::firmware::{FirmwarePlanner, LinearMove};
use settle_planner::shaper::{Shaper, ShaperType};

use crate::job_util::{assert_contiguous, assert_rel, at, job, leg, run};

#[test]
fn klipper_set_velocity_limit_and_m204() {
    let k = || job(PlannerConfig::Klipper(KlipperConfig::new(0.1, 3.0)));
    let (l, v) = (50.0, 100.0);
    // The reversal stops the toolhead: two rest-to-rest legs at 3000 then 1000 mm/s^2.
    let (_, s) = run("G1 X50 F6000\nSET_VELOCITY_LIMIT ACCEL=1000\nG1 X0\n", k());
    assert_rel(
        "ACCEL",
        s.print_time_s,
        l / v + v / 3000.0 + l / v + v / 1000.0,
        1e-9,
    );
    assert_eq!(s.limit_changes, 1);
    let (_, s) = run("G1 X50 F6000\nM204 S500\nG1 X0\n", k());
    assert_rel(
        "M204",
        s.print_time_s,
        l / v + v / 3000.0 + l / v + v / 500.0,
        1e-9,
    );
    // A new square corner velocity: the corner at 10 mm/s.
    let (_, s) = run(
        "SET_VELOCITY_LIMIT SQUARE_CORNER_VELOCITY=10\nG1 X50 F6000\nG1 Y50\n",
        k(),
    );
    assert_rel(
        "SCV",
        s.print_time_s,
        2.0 * leg(l, v, 3000.0, 0.0, 10.0),
        1e-9,
    );
    // Marlin's commands mean nothing to Klipper: counted, not applied.
    let (_, s) = run(
        "G1 X50 F6000\nSET_VELOCITY_LIMIT ACCEL_TO_DECEL=100\nG1 X0\n",
        k(),
    );
    assert_rel("ignored", s.print_time_s, 2.0 * (l / v + v / 3000.0), 1e-9);
    assert_eq!(s.ignored.values().sum::<u64>(), 1, "{:?}", s.ignored);
    // OrcaSlicer writes ACCEL_TO_DECEL beside ACCEL (`SET_VELOCITY_LIMIT ACCEL=1000
    // ACCEL_TO_DECEL=1000`): ACCEL applies, ACCEL_TO_DECEL is listed as not followed
    // (Klipper removed it on 2025-08-11), and the minimum cruise ratio stays.
    let (_, s) = run(
        "G1 X50 F6000\nSET_VELOCITY_LIMIT ACCEL=1000 ACCEL_TO_DECEL=1000\nG1 X0\n",
        k(),
    );
    assert_rel(
        "ACCEL beside ACCEL_TO_DECEL",
        s.print_time_s,
        l / v + v / 3000.0 + l / v + v / 1000.0,
        1e-9,
    );
    assert_eq!(s.limit_changes, 1);
    let listed: Vec<_> = s.ignored.iter().collect();
    assert_eq!(listed.len(), 1, "{listed:?}");
    assert!(
        listed[0]
            .0
            .starts_with("SET_VELOCITY_LIMIT: ACCEL_TO_DECEL is not read")
            && *listed[0].1 == 1,
        "{listed:?}"
    );
}

#[test]
fn marlin_m204_m203_m205_mid_file() {
    let text = "G1 X50 F6000\nM204 S1000\nM203 X60\nM205 J0.05\nG1 Y50\nG1 X0\n";
    let (_, s) = run(text, job(PlannerConfig::Marlin(MarlinConfig::new())));
    let mut p = MarlinPlanner::new(MarlinConfig::new()).expect("config");
    p.push(&LinearMove::new([0.0; 3], [0.05, 0.0, 0.0], 0.0, 0.1))
        .expect("move");
    let mut c = MarlinConfig::new();
    c.print_accel_m_s2 = 1.0;
    c.travel_accel_m_s2 = 1.0;
    c.max_feedrate_m_s[0] = 0.06;
    if let settle_planner::firmware::marlin::MarlinJerk::JunctionDeviation { deviation_m, .. } =
        &mut c.jerk
    {
        *deviation_m = 0.05e-3;
    }
    p.set_config(c).expect("config");
    p.push(&LinearMove::new(
        [0.05, 0.0, 0.0],
        [0.05, 0.05, 0.0],
        0.0,
        0.1,
    ))
    .expect("move");
    p.push(&LinearMove::new(
        [0.05, 0.05, 0.0],
        [0.0, 0.05, 0.0],
        0.0,
        0.1,
    ))
    .expect("move");
    p.finish();
    while p.pop().is_some() {}
    assert_eq!(s.print_time_s, p.print_time_s());
    assert_eq!(s.limit_changes, 3);
}

#[test]
fn rrf_m201_and_m566_mid_file() {
    let r = || job(PlannerConfig::Rrf(RrfConfig::new()));
    let (l, v) = (50.0, 100.0);
    let (_, s) = run("G1 X50 F6000\nM400\nM201 X500\nG1 X0\n", r());
    assert_rel(
        "M201",
        s.print_time_s,
        l / v + v / 1000.0 + l / v + v / 500.0,
        1e-9,
    );
    // M566 in mm/min: 1800 = 30 mm/s per axis at the corner.
    let (_, s) = run("M566 X1800 Y1800\nG1 X50 F6000\nG1 Y50\n", r());
    assert_rel(
        "M566",
        s.print_time_s,
        2.0 * leg(l, v, 1000.0, 0.0, 30.0),
        1e-9,
    );
}

/// Expected shaped motion of axis `i` at `t`: the old shapers on the unshaped motion `u`
/// up to `switch_s` (continued at its velocity there), the new ones on the rest (the same
/// continuation before it), minus the continuation both share; centred impulses
/// `T_k - c`. (Marlin's blocks end and start at its minimal step rate, so `u` may still
/// move at the switch.)
fn expected(
    u: &[JobChunk],
    i: usize,
    t: f64,
    switch_s: f64,
    old: &Option<Shaper>,
    new: &Option<Shaper>,
) -> f64 {
    let taus = |s: &Option<Shaper>| -> Vec<(f64, f64)> {
        match s {
            None => vec![(1.0, 0.0)],
            Some(s) => centred(
                &s.weights()
                    .zip(s.times_s().iter().copied())
                    .collect::<Vec<_>>(),
            ),
        }
    };
    expected_taus(u, i, t, switch_s, &taus(old), &taus(new))
}

/// Impulses `(w, T)` as `(w, T - c)`, `c = sum w T` their centroid.
fn centred(impulses: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let c: f64 = impulses.iter().map(|(w, t)| w * t).sum();
    impulses.iter().map(|&(w, t)| (w, t - c)).collect()
}

/// [`expected`] with the old and new shapers as centred impulses `(w, tau)`.
fn expected_taus(
    u: &[JobChunk],
    i: usize,
    t: f64,
    switch_s: f64,
    old: &[(f64, f64)],
    new: &[(f64, f64)],
) -> f64 {
    let at_switch = at(u, switch_s)[i];
    let line = |s: f64| at_switch.p + at_switch.v * (s - switch_s);
    let p = |s: f64| at(u, s)[i].p;
    let a: f64 = old
        .iter()
        .map(|(w, tau)| {
            w * if t - tau <= switch_s {
                p(t - tau)
            } else {
                line(t - tau)
            }
        })
        .sum();
    let b: f64 = new
        .iter()
        .map(|(w, tau)| {
            w * if t - tau >= switch_s {
                p(t - tau)
            } else {
                line(t - tau)
            }
        })
        .sum();
    a + b - line(t)
}

/// Run `text` (with a shaper command between two moves) and `reference` (the same moves
/// with the same pause, no shaper command and no shapers); check the print times agree
/// and the shaped motion is the old shapers' before the switch and the new ones' after.
fn check_switch(
    what: &str,
    cfg: JobConfig,
    text: &str,
    reference: &str,
    new: [Option<ShaperSetting>; 3],
    switch_after_end_s: f64,
) {
    let (chunks, s) = run(text, cfg.clone());
    assert_contiguous(&chunks);
    assert_eq!(s.shaper_changes, 1, "{what}");
    let mut plain = cfg.clone();
    plain.shapers = [None; 3];
    let (u, su) = run(reference, plain);
    assert_rel(what, s.print_time_s, su.print_time_s, 1e-12);
    let first_end = u[0].moves[0].end_time_s();
    let switch_s = first_end + switch_after_end_s;
    let build = |s: &Option<ShaperSetting>| s.map(|s| s.build().expect("shaper"));
    let end = chunks.last().map(JobChunk::end_time_s).expect("chunks");
    for i in 0..2 {
        let (old, new) = (build(&cfg.shapers[i]), build(&new[i]));
        for k in 0..=3000 {
            let t = chunks[0].start_time_s + (end - chunks[0].start_time_s) * k as f64 / 3000.0;
            let got = at(&chunks, t)[i].p;
            let want = expected(&u, i, t, switch_s, &old, &new);
            assert!(
                (got - want).abs() < 1e-12,
                "{what} axis {i} t {t}: {got} vs {want}"
            );
        }
    }
}

fn setting(name: &str, f: f64, z: f64) -> Option<ShaperSetting> {
    Some(ShaperSetting {
        shaper_type: ShaperType::parse(name).expect("name"),
        frequency_hz: f,
        damping_ratio: z,
    })
}

#[test]
fn klipper_set_input_shaper_pauses_for_both_flush_delays() {
    let mut cfg = job(PlannerConfig::Klipper(KlipperConfig::new(0.1, 3.0)));
    cfg.shapers = [setting("mzv", 50.0, 0.1), None, None];
    // Klipper's mzv at 50 Hz, damping 0.1 (shaper_defs.py, planner/tests/shaper_klipper.rs).
    let a = [0.2928932188134524, 0.3268741504100068, 0.18239874354058666];
    let t = [0.0, 0.00753778361444409, 0.01507556722888818];
    let sum: f64 = a.iter().sum();
    let c: f64 = a.iter().zip(t).map(|(a, t)| a * t).sum::<f64>() / sum;
    let old_delay = c.max(t[2] - c);
    // zvd at 35 Hz, damping 0.1: impulses 1, 2K, K^2 at 0, Td/2, Td; the centroid is
    // Td K / (1 + K), so the later side, Td / (1 + K), is the flush delay.
    let z: f64 = 0.1;
    let td = 1.0 / (35.0 * (1.0 - z * z).sqrt());
    let kk = (-z * std::f64::consts::PI / (1.0 - z * z).sqrt()).exp();
    let new_delay = td / (1.0 + kk);
    let text = "G1 X50 F6000\nSET_INPUT_SHAPER SHAPER_TYPE_X=zvd SHAPER_FREQ_X=35\nG1 X100\n";
    let (_, s) = run(text, cfg.clone());
    let (l, v, acc) = (50.0, 100.0, 3000.0);
    let want = 2.0 * (l / v + v / acc) + old_delay + new_delay;
    assert_rel("print time", s.print_time_s, want, 1e-9);
    let pause_ms = (old_delay + new_delay) * 1000.0;
    let reference = format!("G1 X50 F6000\nG4 P{pause_ms}\nG1 X100\n");
    check_switch(
        "klipper",
        cfg,
        text,
        &reference,
        [setting("zvd", 35.0, 0.1), None, None],
        old_delay,
    );
}

#[test]
fn marlin_and_rrf_shaper_commands_wait_for_a_standstill() {
    let marlin = job(PlannerConfig::Marlin(MarlinConfig::new()));
    check_switch(
        "marlin M593",
        marlin.clone(),
        "G1 X50 F6000\nM593 X F40 D0.1\nG1 X100 Y20\n",
        "G1 X50 F6000\nM400\nG1 X100 Y20\n",
        [setting("marlin:m593", 40.0, 0.1), None, None],
        0.0,
    );
    let mut ft = marlin;
    ft.shapers = [
        setting("marlin:zvd", 45.0, 0.1),
        setting("marlin:zvd", 45.0, 0.1),
        None,
    ];
    check_switch(
        "marlin M493",
        ft,
        "G1 X50 F6000\nM493 C8 A38 I0.05\nG1 X100 Y20\n",
        "G1 X50 F6000\nM400\nG1 X100 Y20\n",
        [
            setting("marlin:mzv", 38.0, 0.05),
            setting("marlin:mzv", 38.0, 0.05),
            None,
        ],
        0.0,
    );
    check_switch(
        "rrf M593",
        job(PlannerConfig::Rrf(RrfConfig::new())),
        "G1 X50 F6000\nM593 P\"zvd\" F40 S0.1\nG1 X100 Y20\n",
        "G1 X50 F6000\nM400\nG1 X100 Y20\n",
        [
            setting("rrf:zvd", 40.0, 0.1),
            setting("rrf:zvd", 40.0, 0.1),
            None,
        ],
        0.0,
    );
}

/// A Marlin build may have INPUT_SHAPING_X/Y and FT_MOTION both (Marlin/src/inc/SanityCheck.h
/// forbids neither with the other); while `M493 S1` has FT_MOTION on, `Stepper::isr`
/// (Marlin/src/module/stepper.cpp) skips `shaping_isr()`, so `M593`'s ZV (here an `M503`
/// reply's, the job's start) stops at `M493 S1` and is back at `M493 S0`.
#[test]
fn marlin_m493_s1_bypasses_m593s_shaping() {
    let mut cfg = job(PlannerConfig::Marlin(MarlinConfig::new()));
    let m593 = setting("marlin:m593", 40.0, 0.15);
    cfg.shapers = [m593, m593, None];
    check_switch(
        "M493 S1",
        cfg.clone(),
        "G1 X50 F6000\nM493 S1\nG1 X100 Y20\n",
        "G1 X50 F6000\nM400\nG1 X100 Y20\n",
        [None; 3],
        0.0,
    );
    // An M593 under FT_MOTION is kept and runs from M493 S0: the motion of an M593 there.
    cfg.shapers = [None; 3];
    let (kept, _) = run(
        "M493 S1\nM593 F40 D0.15\nG1 X50 F6000\nM493 S0\nG1 X100 Y20\n",
        cfg.clone(),
    );
    let (there, _) = run("G1 X50 F6000\nM593 F40 D0.15\nG1 X100 Y20\n", cfg.clone());
    let (plain, _) = run("G1 X50 F6000\nM400\nG1 X100 Y20\n", cfg.clone());
    let last = |c: &[JobChunk]| c.last().map(JobChunk::end_time_s).expect("chunks");
    let end = last(&there);
    assert_rel("end", last(&kept), end, 1e-12);
    let mut shaped = 0.0f64;
    for n in 0..=3000 {
        let t = end * n as f64 / 3000.0;
        for i in 0..2 {
            let (got, want) = (at(&kept, t)[i].p, at(&there, t)[i].p);
            assert!(
                (got - want).abs() < 1e-12,
                "axis {i} t {t}: {got} vs {want}"
            );
            shaped = shaped.max((got - at(&plain, t)[i].p).abs());
        }
    }
    // The ZV's echo moves the axes off the unshaped path (by 5.8e-5 mm at most, sampled),
    // ten million times the agreement above: the comparison is not vacuous.
    assert!(shaped > 1e-5, "{shaped}");
}

#[test]
fn prusa_m593_sets_one_axis_shaper_by_type() {
    // The MK4's shapers as Prusa ships them, then `M593 X T3 F45 D0.05`: X runs Prusa's
    // EI at 45 Hz from the standstill the firmware waits for; Y keeps its MZV.
    let prusa = JobConfig::defaults(Firmware::Prusa).expect("defaults");
    assert_eq!(
        prusa.shapers,
        [setting("mzv", 50.7, 0.1), setting("mzv", 40.6, 0.1), None]
    );
    check_switch(
        "prusa M593",
        prusa,
        "G1 X50 F6000\nM593 X T3 F45 D0.05\nG1 X100 Y20\n",
        "G1 X50 F6000\nM400\nG1 X100 Y20\n",
        [
            setting("prusa:ei", 45.0, 0.05),
            setting("mzv", 40.6, 0.1),
            None,
        ],
        0.0,
    );
}

#[test]
fn marlin_refuses_prusas_m593_t_and_names_prusa() {
    let err = job_error(Firmware::Marlin, "G1 X10 F6000\nM593 X T2 F0\n");
    assert!(
        err.contains("Prusa") && err.contains("--firmware prusa"),
        "{err}"
    );
}

#[test]
fn bad_shaper_commands_name_their_line() {
    let k = JobConfig::defaults(Firmware::Klipper).expect("defaults");
    let text = "G1 X10 F6000\nSET_INPUT_SHAPER SHAPER_TYPE=bogus SHAPER_FREQ_X=40\n";
    let r = settle_gcode::Reader::new(text.as_bytes(), settle_gcode::ReaderOptions::new(k.dialect));
    let mut job = settle_gcode::job::Job::new(r, k).expect("job");
    let err = job.by_ref().find_map(Result::err).expect("refused");
    assert_eq!(err.line(), Some(2), "{err}");
    assert!(err.to_string().contains("bogus"), "{err}");
    // A damping ratio Klipper refuses for the shaper.
    let k = JobConfig::defaults(Firmware::Klipper).expect("defaults");
    let text = "SET_INPUT_SHAPER SHAPER_TYPE=ei SHAPER_FREQ_X=40 DAMPING_RATIO_X=0.5\n";
    let r = settle_gcode::Reader::new(text.as_bytes(), settle_gcode::ReaderOptions::new(k.dialect));
    let mut job = settle_gcode::job::Job::new(r, k).expect("job");
    let err = job.by_ref().find_map(Result::err).expect("refused");
    assert_eq!(err.line(), Some(1), "{err}");
}

/// The first error of a job of `firmware` on `text`.
fn job_error(firmware: Firmware, text: &str) -> String {
    let c = JobConfig::defaults(firmware).expect("defaults");
    let r = settle_gcode::Reader::new(text.as_bytes(), settle_gcode::ReaderOptions::new(c.dialect));
    let mut job = settle_gcode::job::Job::new(r, c).expect("job");
    job.by_ref()
        .find_map(Result::err)
        .expect("refused")
        .to_string()
}

#[test]
fn a_shaper_name_is_one_the_firmware_knows_and_the_error_lists_its_own() {
    // Klipper refuses settle's firmware-prefixed names (shaper_defs.py knows zv..3hump_ei).
    for name in ["rrf:zvd", "marlin:ei", "klipper:mzv"] {
        let e = job_error(
            Firmware::Klipper,
            &format!(
                "G1 X10 F6000\nSET_INPUT_SHAPER SHAPER_TYPE_X={name} SHAPER_FREQ_X=40\nG1 X20\n"
            ),
        );
        assert!(e.contains(&format!("unknown shaper `{name}`")), "{e}");
        assert!(e.contains("zv, mzv, zvd, ei, 2hump_ei or 3hump_ei"), "{e}");
        assert!(
            !e.contains("rrf:") || e.contains(&format!("`{name}`")),
            "{e}"
        );
        assert!(!e.contains("marlin:zv,"), "{e}");
    }
    // RepRapFirmware's M593 P lists its own types.
    let e = job_error(Firmware::Rrf, "G1 X10 F6000\nM593 P\"ei\" F40\nG1 X20\n");
    assert!(e.contains("unknown shaper `ei`"), "{e}");
    assert!(e.contains("none, zvd, zvdd, zvddd, mzv, ei2, ei3"), "{e}");
    assert!(!e.contains("2hump_ei"), "{e}");
}

/// What a firmware refuses, does not read or raises to its least, the job refuses, drops
/// or raises the same way, and lists among the commands not followed: Marlin keeps its
/// junction deviation for `M205 J` outside 0.01 to 0.3 mm and does not read classic
/// jerk in a junction-deviation build or `M201 F`/`S` without XY_FREQUENCY_LIMIT
/// (Marlin/src/gcode/config/M200-M205.cpp); RepRapFirmware raises an acceleration below
/// 0.1 mm/s^2 to 0.1 (src/Platform/Platform.h, src/GCodes/GCodes5.cpp) and keeps its
/// speed factor for `M220 S` below 1 (src/GCodes/GCodes2.cpp).
#[test]
fn values_a_firmware_refuses_or_raises_are_dropped_or_raised_and_listed() {
    let not_followed = |s: &settle_gcode::job::JobSummary, command: &str, part: &str| {
        assert!(
            s.ignored
                .keys()
                .any(|k| k.starts_with(&format!("{command}: ")) && k.contains(part)),
            "{command} {part}: {:?}",
            s.ignored
        );
    };
    let marlin = || job(PlannerConfig::Marlin(MarlinConfig::new()));
    let base = "G1 X50 F6000\nG1 Y50\nG1 X0\n";
    let (_, plain) = run(base, marlin());
    for (line, part) in [
        ("M205 J5", "0.01 to 0.3"),
        ("M205 J0.001", "0.01 to 0.3"),
        ("M205 X0.5 Y0.5", "CLASSIC_JERK"),
        ("M201 F5 S50", "XY_FREQUENCY_LIMIT"),
    ] {
        let (_, s) = run(&format!("{line}\n{base}"), marlin());
        assert_eq!(
            s.print_time_s, plain.print_time_s,
            "{line}: nothing changes"
        );
        assert_eq!(s.limit_changes, 0, "{line}");
        not_followed(&s, &line[..4], part);
    }
    // The part Marlin reads still applies: J 0.3 beside X.
    let (_, s) = run(&format!("M205 J0.3 X0.5\n{base}"), marlin());
    assert_eq!(s.limit_changes, 1);
    assert!(
        s.print_time_s < plain.print_time_s,
        "a larger deviation corners faster"
    );
    not_followed(&s, "M205", "CLASSIC_JERK");

    // RepRapFirmware: M204 P0.01 runs as M204 P0.1.
    let rrf = || job(PlannerConfig::Rrf(RrfConfig::new()));
    let (_, low) = run(&format!("M204 P0.01 T0.01\n{base}"), rrf());
    let (_, least) = run(&format!("M204 P0.1 T0.1\n{base}"), rrf());
    assert_eq!(low.print_time_s, least.print_time_s);
    not_followed(&low, "M204", "0.1 mm/s^2");
    let (_, low) = run(&format!("M201 X0.01 Y0.01\n{base}"), rrf());
    let (_, least) = run(&format!("M201 X0.1 Y0.1\n{base}"), rrf());
    assert_eq!(low.print_time_s, least.print_time_s);
    not_followed(&low, "M201", "0.1 mm/s^2");
    // A maximum speed below the minimum movement speed runs at it.
    let (_, low) = run(&format!("M203 X1 Y1\n{base}"), rrf());
    let (_, least) = run(&format!("M203 X30 Y30\n{base}"), rrf());
    assert_eq!(low.print_time_s, least.print_time_s);
    not_followed(&low, "M203", "minimum movement speed");
    // M220 S0.5 changes nothing.
    let (_, plain) = run(base, rrf());
    let (_, s) = run(&format!("M220 S0.5\n{base}"), rrf());
    assert_eq!(s.print_time_s, plain.print_time_s);
    not_followed(&s, "M220", "below 1 %");
}

#[test]
fn marlin_m593_runs_the_steppers_zv_not_klippers() {
    // `M593 X F40 D0.5` as Marlin/src/module/stepper.cpp runs it: the echo's share
    // FLOOR(64.44056192 - 99.02008832 * 0.5 - 7.58095488 * 0.25 + 43.073216 * 0.125) =
    // FLOOR(18.419) = 18 of 128 (`set_shaping_damping_ratio`), the step keeps 110; the
    // echo 2 MHz / 2 / 40 = 25000 ticks = 1 / (2 * 40) = 12.5 ms late
    // (`set_shaping_frequency`). Klipper's zv would wait 12.5 ms / sqrt(1 - 0.25) =
    // 14.434 ms with K = exp(-0.5 pi / sqrt(0.75)) = 0.16303: [0.85983, 0.14017].
    let marlin = job(PlannerConfig::Marlin(MarlinConfig::new()));
    let text = "G1 X50 F6000\nM593 X F40 D0.5\nG1 X100 Y20\n";
    let (chunks, s) = run(text, marlin.clone());
    assert_contiguous(&chunks);
    assert_eq!(s.shaper_changes, 1);
    let mut plain = marlin;
    plain.shapers = [None; 3];
    let (u, su) = run("G1 X50 F6000\nM400\nG1 X100 Y20\n", plain);
    assert_rel("print time", s.print_time_s, su.print_time_s, 1e-12);
    let switch_s = u[0].moves[0].end_time_s();
    let hand = centred(&[(110.0 / 128.0, 0.0), (18.0 / 128.0, 0.0125)]);
    let k = (-0.5 * std::f64::consts::PI / 0.75f64.sqrt()).exp();
    let klipper = centred(&[
        (1.0 / (1.0 + k), 0.0),
        (k / (1.0 + k), 0.0125 / 0.75f64.sqrt()),
    ]);
    let end = chunks.last().map(JobChunk::end_time_s).expect("chunks");
    let mut apart = 0.0f64;
    for n in 0..=3000 {
        let t = chunks[0].start_time_s + (end - chunks[0].start_time_s) * n as f64 / 3000.0;
        let got = at(&chunks, t)[0].p;
        let want = expected_taus(&u, 0, t, switch_s, &[(1.0, 0.0)], &hand);
        assert!((got - want).abs() < 1e-12, "t {t}: {got} vs {want}");
        let zv = expected_taus(&u, 0, t, switch_s, &[(1.0, 0.0)], &klipper);
        apart = apart.max((got - zv).abs());
    }
    // Klipper's zv would put X up to 1.0e-5 mm elsewhere (its later, smaller echo), ten
    // million times the agreement above: the job does not run it.
    assert!(apart > 5e-6, "{apart}");
}
