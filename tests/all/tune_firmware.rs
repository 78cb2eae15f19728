//! `settle tune` as a printer user needs it: candidates restricted to what a firmware runs,
//! Klipper's smoothing and max_accel per candidate (checked against numbers Klipper's own
//! code printed) used as a constraint, the frequency-tolerance worst case, and
//! `--criterion klipper` reproducing calibrate_shaper.py's lines on its calibration files.

use std::path::{Path, PathBuf};

use settle::spec::backend::Backend;
use settle::workflows::tune::{Options, tune_axis};
use settle_planner::ProfileKind;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::ShaperType;

use crate::support::{root, write};

/// One mode at 47.2 Hz (the `one_peak` calibration file's MZV frequency), Klipper-style
/// trapezoids.
fn scenario(tune: &str) -> String {
    format!(
        r#"name = "fw_test"
[machine]
modes = [{{ frequency_hz = 47.2, damping_ratio = 0.05 }}]
[move]
distance_mm = 20.0
profile = "trapezoid"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.4
sample_rate_hz = 5000
bands_um = [10.0]
[tune]
{tune}
"#
    )
}

fn run(dir: &Path, tune: &str, opts: &Options) -> settle::workflows::tune::Outcome {
    let p = write(dir, "fw_test.toml", &scenario(tune));
    tune_axis(&p, None, opts, &settle::execute::pool::quiet).expect("tunes")
}

fn modal() -> Options {
    Options {
        jobs: Some(2),
        ..Options::new(Backend::Modal)
    }
}

#[test]
fn firmware_restricts_the_candidates() {
    let dir = tempfile::tempdir().expect("tempdir");
    // The TMC4361A's register ranges depend on the resolution: 80 microsteps per mm.
    let small = "frequency_scales = [1.0]\njerk_steps = 1\nusteps_per_mm = 80.0\n";
    for (fw, shaper_fw) in [
        ("klipper", Some(Firmware::Klipper)),
        ("marlin", Some(Firmware::Marlin)),
        ("rrf", Some(Firmware::Rrf)),
        ("prusa", Some(Firmware::Prusa)),
        ("tmc4361a", None),
    ] {
        let o = run(
            dir.path(),
            small,
            &Options {
                firmware: Some(fw.into()),
                ..modal()
            },
        );
        let grid = &o.scores[1..o.plan.candidates.len()];
        assert!(!grid.is_empty());
        for s in grid {
            let c = &s.candidate;
            let kind = c.shaper.and_then(|sh| sh.shaper_type);
            match shaper_fw {
                Some(f) => {
                    assert_eq!(c.kind, ProfileKind::Trapezoid, "{fw}: {}", c.label());
                    // Buddy's M593 T0-T2 are Klipper's zv, zvd and mzv (input_shaper.cpp).
                    let buddy = [ShaperType::Zv, ShaperType::Zvd, ShaperType::MZV];
                    assert!(
                        kind.is_none_or(
                            |k| k.firmware() == f || (f == Firmware::Prusa && buddy.contains(&k))
                        ),
                        "{fw}: {}",
                        c.label()
                    );
                }
                None => {
                    assert!(
                        matches!(c.kind, ProfileKind::SCurve | ProfileKind::FourJerk),
                        "{fw}: {}",
                        c.label()
                    );
                    assert!(kind.is_none(), "{fw}: {}", c.label());
                }
            }
        }
        // Klipper: none + its six shapers at the one mode frequency; Buddy: none + its six
        // (M593 T0 to T5).
        if fw == "klipper" || fw == "prusa" {
            assert_eq!(grid.len(), 7, "{fw}");
        }
    }
    // A shaper the firmware does not run: the key is named.
    let p = write(
        dir.path(),
        "bad.toml",
        &scenario("firmware = \"klipper\"\nshapers = [\"rrf:ei2\"]\n"),
    );
    let e = tune_axis(&p, None, &modal(), &settle::execute::pool::quiet).expect_err("refused");
    let text = e.to_string();
    assert!(
        text.contains("tune.shapers") && text.contains("klipper"),
        "{text}"
    );
}

#[test]
fn smoothing_and_max_accel_are_klippers_and_bound_the_acceleration() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run(
        dir.path(),
        "firmware = \"klipper\"\nshapers = [\"mzv\"]\nfrequency_scales = [1.0]\naccelerations_mm_s2 = [5000.0, 7000.0]\nshaper_damping_ratio = 0.1\n",
        &modal(),
    );
    // Klipper's numbers for MZV at 47.19999999999992 Hz, damping 0.1, at 5000 mm/s^2 and
    // 5 mm/s (calibrate_shaper.py on planner/tests/data/klipper_one_peak.csv, see
    // planner/tests/all/shaper_select.rs): smoothing 0.09142074090152724 mm, max_accel
    // 6563.062102569528 mm/s^2 (smoothing <= 0.12 mm). settle's grid has 47.2 Hz exactly.
    let at = |a: f64| {
        o.scores
            .iter()
            .find(|s| s.candidate.amax_mm_s2 == Some(a))
            .expect("candidate")
    };
    let s5 = at(5000.0);
    assert!(
        (s5.smoothing_mm - 0.09142074090152724).abs() < 1e-9,
        "{s5:?}"
    );
    assert!(
        (s5.max_accel_mm_s2 - 6563.062102569528).abs() < 1e-5,
        "{s5:?}"
    );
    assert!(s5.move_and_settle_s.is_finite(), "{s5:?}");
    // 7000 mm/s^2 is above max_accel: the smoothing passes 0.12 mm, the candidate is out.
    let s7 = at(7000.0);
    assert!(s7.smoothing_mm > 0.12, "{s7:?}");
    assert!(s7.move_and_settle_s.is_infinite(), "{s7:?}");
    // A looser limit lets it in.
    let o = run(
        dir.path(),
        "firmware = \"klipper\"\nshapers = [\"mzv\"]\nfrequency_scales = [1.0]\naccelerations_mm_s2 = [7000.0]\nmax_smoothing_mm = 0.2\nshaper_damping_ratio = 0.1\n",
        &modal(),
    );
    assert!(
        o.scores[1].move_and_settle_s.is_finite(),
        "{:?}",
        o.scores[1]
    );
}

#[test]
fn frequency_tolerance_scores_the_worst_detuned_case() {
    let dir = tempfile::tempdir().expect("tempdir");
    let t =
        "firmware = \"klipper\"\nshapers = [\"none\", \"zv\", \"ei\"]\nfrequency_scales = [1.0]\n";
    let nominal = run(dir.path(), t, &modal());
    let robust = run(
        dir.path(),
        t,
        &Options {
            frequency_tolerance_pct: Some(10.0),
            ..modal()
        },
    );
    assert_eq!(nominal.scores.len(), robust.scores.len());
    for (n, r) in nominal.scores.iter().zip(&robust.scores) {
        assert_eq!(n.candidate, r.candidate);
        if n.candidate.shaper.and_then(|s| s.shaper_type).is_some() {
            // The worst of nominal, -10 % and +10 %: never better than nominal.
            assert!(r.move_and_settle_s >= n.move_and_settle_s, "{n:?} {r:?}");
        } else {
            assert_eq!(r.move_and_settle_s, n.move_and_settle_s);
        }
    }
    // Detuned by 10 %, ZV (zero vibration at one frequency) leaves more than EI (designed
    // for <= 5 % over a band): the worst cases say so.
    let worst = |name: &str| {
        robust
            .scores
            .iter()
            .find(|s| {
                s.candidate
                    .shaper
                    .and_then(|sh| sh.shaper_type)
                    .map(|k| k.name())
                    .as_deref()
                    == Some(name)
            })
            .expect("shaped candidate")
            .residual_peak_um
    };
    assert!(
        worst("zv") > worst("ei"),
        "zv {} ei {}",
        worst("zv"),
        worst("ei")
    );
    // A bad tolerance names the option.
    let p = write(dir.path(), "x.toml", &scenario(t));
    let e = tune_axis(
        &p,
        None,
        &Options {
            frequency_tolerance_pct: Some(80.0),
            ..modal()
        },
        &settle::execute::pool::quiet,
    )
    .expect_err("refused");
    assert!(e.to_string().contains("--frequency-tolerance"), "{e}");
}

/// A machine file (`settle identify`'s form) with one mode at 47.2 Hz, zeta 0.05, and the
/// frequency's standard deviation `sigma_hz` when given; the scenario of [`scenario`] on
/// it, with a 4 um band.
fn identified_machine(dir: &Path, sigma_hz: Option<f64>) -> PathBuf {
    let sigma = sigma_hz.map_or(String::new(), |s| {
        format!(", frequency_sigma_hz = {s:?}, damping_ratio_sigma = 0.004")
    });
    write(
        dir,
        "machine.toml",
        &format!(
            "name = \"identified\"\n[axis.x]\nmodes = [\n  {{ frequency_hz = 47.2, damping_ratio = 0.05, weight = 1.0{sigma} }},\n]\n"
        ),
    );
    let text = scenario("firmware = \"klipper\"\nshapers = [\"none\", \"zv\", \"mzv\", \"ei\"]\nfrequency_scales = [1.0]\n")
        .replace(
            "[machine]\nmodes = [{ frequency_hz = 47.2, damping_ratio = 0.05 }]",
            "[machine]\npreset = \"machine.toml\"",
        )
        // A 4 um band: the detuned ZV's residual (4.2 um) leaves it, the exact one's
        // (1.6 um) does not.
        .replace("bands_um = [10.0]", "bands_um = [4.0]");
    write(dir, "identified.toml", &text)
}

/// The score of the candidate shaped by `name`.
fn shaped<'a>(
    o: &'a settle::workflows::tune::Outcome,
    name: &str,
) -> &'a settle::workflows::tune::search::Score {
    o.scores
        .iter()
        .find(|s| {
            s.candidate
                .shaper
                .and_then(|sh| sh.shaper_type)
                .map(|k| k.name())
                .as_deref()
                == Some(name)
        })
        .expect("shaped candidate")
}

#[test]
fn identified_frequency_band_makes_tune_prefer_a_robust_shaper() {
    use settle::workflows::tune::search::BandSource;
    let dir = tempfile::tempdir().expect("tempdir");
    let tune = |sigma: Option<f64>, tolerance: Option<f64>| {
        let p = identified_machine(dir.path(), sigma);
        let opts = Options {
            frequency_tolerance_pct: tolerance,
            ..modal()
        };
        tune_axis(&p, None, &opts, &settle::execute::pool::quiet).expect("tunes")
    };
    let name = |o: &settle::workflows::tune::Outcome| {
        o.scores[o.winner]
            .candidate
            .shaper
            .and_then(|s| s.shaper_type)
            .map(|k| k.name())
    };
    // Known exactly (no sigma): no band, and ZV, the shortest shaper, wins at 47.2 Hz.
    let exact = tune(None, None);
    assert_eq!(exact.plan.frequency_tolerance, 0.0);
    assert_eq!(exact.plan.band_source, BandSource::None);
    assert_eq!(
        name(&exact).as_deref(),
        Some("zv"),
        "{:?}",
        exact.scores[exact.winner]
    );
    // Identified as 47.2 +- 2.36 Hz (5 %): the band is 2 sigma = +-10 %, and ZV's worst
    // case over it collapses while a robust shaper holds.
    let wide = tune(Some(2.36), None);
    assert!(
        (wide.plan.frequency_tolerance - 0.1).abs() < 1e-12,
        "{}",
        wide.plan.frequency_tolerance
    );
    assert_eq!(wide.plan.band_source, BandSource::Identified(47.2, 2.36));
    let winner = name(&wide);
    assert!(
        matches!(winner.as_deref(), Some("mzv" | "ei")),
        "{winner:?} {:?}",
        wide.scores[wide.winner]
    );
    let (zv_exact, zv_wide) = (shaped(&exact, "zv"), shaped(&wide, "zv"));
    let w = &wide.scores[wide.winner];
    eprintln!(
        "zv: {:.2} um, {:.1} ms exact; {:.2} um, {:.1} ms worst over the band; winner {winner:?}: {:.2} um, {:.1} ms (exact {:.1} ms)",
        zv_exact.residual_peak_um,
        zv_exact.move_and_settle_s * 1e3,
        zv_wide.residual_peak_um,
        zv_wide.move_and_settle_s * 1e3,
        w.residual_peak_um,
        w.move_and_settle_s * 1e3,
        shaped(&exact, winner.as_deref().expect("shaped")).move_and_settle_s * 1e3,
    );
    // Measured: ZV 1.61 um and 173.9 ms exactly tuned, 4.17 um and 191.3 ms at worst over
    // the band; MZV 2.23 um and 181.0 ms at worst (179.3 ms exactly tuned).
    assert!(zv_wide.residual_peak_um > 2.0 * zv_exact.residual_peak_um);
    assert!(zv_wide.move_and_settle_s > w.move_and_settle_s);
    assert!(
        zv_exact.move_and_settle_s
            < shaped(&exact, winner.as_deref().expect("shaped")).move_and_settle_s
    );
    // The report says which band it used.
    let md = settle::workflows::tune::report::axis_section("x", &wide, "pareto.svg");
    assert!(
        md.contains("Frequency band: +-10.000% (2 sigma of the identified 47.20 +- 2.360 Hz mode"),
        "{md}"
    );
    // A given tolerance counts where it is wider than the identified band, not where it is narrower.
    let given = tune(Some(2.36), Some(20.0));
    assert!((given.plan.frequency_tolerance - 0.2).abs() < 1e-12);
    assert_eq!(
        given.plan.band_source,
        BandSource::GivenOverIdentified(47.2, 2.36)
    );
    let narrow = tune(Some(2.36), Some(1.0));
    assert!((narrow.plan.frequency_tolerance - 0.1).abs() < 1e-12);
    // A negative sigma is an input error naming the key.
    let p = identified_machine(dir.path(), Some(-1.0));
    let e = tune_axis(&p, None, &modal(), &settle::execute::pool::quiet).expect_err("refused");
    assert!(e.to_string().contains("frequency_sigma_hz"), "{e}");
}

fn calibration(file: &str) -> PathBuf {
    root().join("planner/tests/data").join(file)
}

#[test]
fn klipper_criterion_prints_what_calibrate_shaper_printed() {
    // The recommendations calibrate_shaper.py printed for these files (Klipper 84104bbbd762,
    // planner/tests/all/shaper_select.rs).
    for (file, want) in [
        (
            "klipper_one_peak.csv",
            "Recommended shaper is mzv @ 47.2 Hz",
        ),
        (
            "klipper_two_peaks.csv",
            "Recommended shaper is mzv @ 39.0 Hz",
        ),
        (
            "klipper_low_peak.csv",
            "Recommended shaper is mzv @ 25.6 Hz",
        ),
    ] {
        let c = settle::workflows::tune::klipper_criterion::KlipperCriterion::from_args(
            vec![calibration(file)],
            None,
            None,
            None,
            None,
        )
        .expect("options");
        let r = settle::workflows::tune::klipper_criterion::report(&c).expect("chooses");
        assert_eq!(r.stdout.lines().last(), Some(want), "{file}:\n{}", r.stdout);
    }
    // The per-shaper lines, from the same run's numbers for one_peak (zv: 46.0 Hz,
    // vibrations 1.49 %, smoothing 0.0783, max_accel 8246 -> 8200).
    let r = crate::support::settle()
        .args(["tune", "--criterion", "klipper"])
        .arg(calibration("klipper_one_peak.csv"))
        .output()
        .expect("runs");
    assert!(r.status.success(), "{r:?}");
    let out = String::from_utf8_lossy(&r.stdout);
    for want in [
        "Fitted shaper 'zv' frequency = 46.0 Hz (vibrations = 1.5%, smoothing ~= 0.078)",
        "To avoid too much smoothing with 'zv', suggested max_accel <= 8200 mm/sec^2",
        "To avoid too much smoothing with 'mzv', suggested max_accel <= 6600 mm/sec^2",
    ] {
        assert!(out.contains(want), "missing `{want}` in\n{out}");
    }
}

#[test]
fn out_of_the_running_candidates_say_why_and_never_win_or_reach_the_front() {
    use settle::workflows::tune::search::Infeasible;
    let dir = tempfile::tempdir().expect("tempdir");
    // The current EI at 47.2 Hz smooths ~0.08 mm at 3000 mm/s^2: over a 0.05 mm limit.
    let o = run(
        dir.path(),
        "firmware = \"klipper\"\nshapers = [\"none\", \"zv\", \"ei\"]\nfrequency_scales = [1.0]\naccelerations_mm_s2 = [3000.0, 9000.0]\nmax_smoothing_mm = 0.05\n[tune.axis.x]\nshaper = \"ei\"\nfrequency_hz = 47.2\n",
        &modal(),
    );
    let cur = &o.scores[0];
    match &cur.infeasible {
        Some(Infeasible::Smoothing {
            smoothing_mm,
            limit_mm,
            accel_mm_s2,
        }) => {
            assert_eq!(*smoothing_mm, cur.smoothing_mm);
            assert_eq!((*limit_mm, *accel_mm_s2), (0.05, 3000.0));
        }
        other => panic!("{other:?}"),
    }
    // Its simulated time is kept (and shown), its ranking key is out of reach.
    assert!(cur.simulated_move_and_settle_s.is_finite() && cur.move_and_settle_s.is_infinite());
    for s in &o.scores {
        let over = s.smoothing_mm > 0.05;
        assert_eq!(
            over,
            matches!(s.infeasible, Some(Infeasible::Smoothing { .. })),
            "{s:?}"
        );
    }
    assert!(o.scores[o.winner].is_feasible());
    // The front is the Pareto front of the feasible candidates, found here by brute force.
    let ok: Vec<usize> = (0..o.scores.len())
        .filter(|&i| o.scores[i].is_feasible())
        .collect();
    let dominated = |i: usize| {
        let a = &o.scores[i];
        ok.iter().any(|&j| {
            let b = &o.scores[j];
            b.move_time_s <= a.move_time_s
                && b.residual_peak_um <= a.residual_peak_um
                && (b.move_time_s < a.move_time_s || b.residual_peak_um < a.residual_peak_um)
        })
    };
    let mut front: Vec<usize> = ok.iter().copied().filter(|&i| !dominated(i)).collect();
    front.sort_by(|&a, &b| o.scores[a].move_time_s.total_cmp(&o.scores[b].move_time_s));
    assert!(o.front.iter().all(|&i| o.scores[i].is_feasible()));
    assert_eq!(o.front.len(), front.len());
    // The report's row of the current settings gives its simulated time and why it is out.
    let md = settle::workflows::tune::report::axis_section("x", &o, "pareto.svg");
    let row = md
        .lines()
        .find(|l| l.starts_with("| current |"))
        .expect("current row");
    assert!(
        row.contains(&format!("{:.1}", cur.simulated_move_and_settle_s * 1e3))
            && row.ends_with(&format!(
                "| out: smooths {:.3} mm > 0.05 mm |",
                cur.smoothing_mm
            )),
        "{row}"
    );
}

#[test]
fn shapers_are_designed_for_the_modes_damping_within_what_the_firmware_takes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = scenario(
        "firmware = \"klipper\"\nshapers = [\"mzv\", \"3hump_ei\"]\nfrequency_scales = [1.0]\n",
    )
    .replace("damping_ratio = 0.05", "damping_ratio = 0.25");
    let p = write(dir.path(), "fw_test.toml", &text);
    let o = tune_axis(&p, None, &modal(), &settle::execute::pool::quiet).expect("tunes");
    let damping = |name: &str| {
        o.scores
            .iter()
            .filter_map(|s| s.candidate.shaper)
            .find(|sh| sh.shaper_type.is_some_and(|k| k.name() == name))
            .expect("searched")
            .damping_ratio
    };
    // MZV takes the mode's 0.25; Klipper's 3hump_ei at most 0.2 (shaper_defs.py).
    assert_eq!(damping("mzv"), 0.25);
    assert_eq!(damping("3hump_ei"), 0.2);
    let md = settle::workflows::tune::report::axis_section("x", &o, "pareto.svg");
    assert!(
        md.contains("designed for the damping ratio of the mode"),
        "{md}"
    );
    assert!(
        md.contains("3hump_ei takes a damping ratio of at most 0.2"),
        "{md}"
    );
    // A fixed damping ratio is taken as given (Klipper's default here).
    let o = run(
        dir.path(),
        "shapers = [\"zv\"]\nfrequency_scales = [1.0]\nshaper_damping_ratio = 0.1\n",
        &modal(),
    );
    assert!(
        o.scores[1..]
            .iter()
            .all(|s| s.candidate.shaper.is_none_or(|sh| sh.damping_ratio == 0.1))
    );
}

#[test]
fn the_search_holds_only_what_the_target_can_take() {
    use settle::workflows::tune::export;
    let dir = tempfile::tempdir().expect("tempdir");
    // The TMC4361A at 160 microsteps/mm: BOW1..4 hold at most (2^24 - 1) / 160 mm/s^3 in
    // the frequency mode, far below the scenario's 1e8.
    let text = scenario(
        "firmware = \"tmc4361a\"\nusteps_per_mm = 160.0\njerk_steps = 3\nkinds = [\"scurve\"]\n",
    )
    .replace("jmax_mm_s3 = 100000.0", "jmax_mm_s3 = 1e8");
    let p = write(dir.path(), "fw_test.toml", &text);
    let o = tune_axis(&p, None, &modal(), &settle::execute::pool::quiet).expect("tunes");
    let cap = 16_777_215.0 / 160.0;
    for s in &o.scores[1..] {
        assert!(s.candidate.jmax_mm_s3.is_some_and(|j| j <= cap), "{s:?}");
    }
    let tmc = export::tmc4361a(&[("x".to_string(), o.clone())]);
    assert!(!tmc.contains("not written"), "{tmc}");
    let md = settle::workflows::tune::report::axis_section("x", &o, "pareto.svg");
    assert!(
        md.contains("47.2 Hz (zeta 0.050)"),
        "the modes are reported: {md}"
    );
    assert!(md.contains("Jerks searched up to 104858 mm/s^3"), "{md}");
    // Without the resolution the chip's ranges are unknown: an error naming the key.
    let p = write(
        dir.path(),
        "fw_test.toml",
        &scenario("firmware = \"tmc4361a\"\n"),
    );
    let e = tune_axis(&p, None, &modal(), &settle::execute::pool::quiet).expect_err("refused");
    assert!(e.to_string().contains("tune.usteps_per_mm"), "{e}");
    // RepRapFirmware plans trapezoids: an S-curve recommendation is not written as an
    // M593 line; an unshaped trapezoid is `M593 P"none"` alone.
    let s = run(
        dir.path(),
        "kinds = [\"scurve\"]\nshapers = [\"none\"]\njerk_steps = 1\n",
        &modal(),
    );
    let rrf = export::rrf(&[("x".to_string(), s)], "a test");
    assert!(
        rrf.starts_with("; no RepRapFirmware configuration: the recommendation on x, scurve")
            && !rrf.contains("M593"),
        "{rrf}"
    );
    let t = run(
        dir.path(),
        "kinds = [\"trapezoid\"]\nshapers = [\"none\"]\n",
        &modal(),
    );
    let rrf = export::rrf(&[("x".to_string(), t)], "a test");
    assert!(
        rrf.contains("\nM593 P\"none\"\n") && !rrf.contains(" F"),
        "{rrf}"
    );
}

/// `scenarios/tune_printer.toml` tuned on X and Y for `firmware` with the `shapers` (a TOML
/// list's items) at the modes' own frequencies, one 20 mm move, written under `dir/out`.
fn tune_printer_xy(dir: &Path, shapers: &str, firmware: &str) -> settle::workflows::tune::Tuned {
    let text = std::fs::read_to_string(root().join("scenarios/tune_printer.toml"))
        .expect("scenario")
        .replace(
            "frequency_scales = [0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.15]",
            &format!("frequency_scales = [1.0]\naxes = [\"x\", \"y\"]\nshapers = [{shapers}]"),
        )
        .replace("distances_mm = [5.0, 20.0, 50.0]", "distances_mm = [20.0]")
        .replace("jerk_steps = 5", "jerk_steps = 1");
    let p = write(dir, &format!("{firmware}.toml"), &text);
    let opts = Options {
        firmware: Some(firmware.into()),
        ..modal()
    };
    settle::workflows::tune::tune_with(
        &p,
        Some(dir.join("out")),
        &opts,
        &settle::execute::pool::quiet,
    )
    .expect("tunes")
}

/// `marlin.gcode` read back by settle's G-code reader (Marlin dialect) as a job would read
/// it: Fixed-Time Motion on, and per tuned axis the winner's shaper (`M493 C`), frequency
/// (`A`), damping (`I`) and, for the EI family, vibration tolerance (`Q`), bit for bit;
/// a job starting with it shapes with them.
#[test]
fn marlin_export_reads_back_as_the_recommendation() {
    use settle_gcode::{Dialect, EventKind, FtShaper, LimitChange, Reader, ReaderOptions};
    use settle_planner::shaper::{MarlinShaper, ShaperType};

    let dir = tempfile::tempdir().expect("tempdir");
    let shapers = r#""none", "marlin:zvd", "marlin:ei", "marlin:mzv""#;
    let t = tune_printer_xy(dir.path(), shapers, "marlin");
    let g = std::fs::read_to_string(t.out.join("marlin.gcode")).expect("marlin.gcode");
    let events: Vec<_> = Reader::new(g.as_bytes(), ReaderOptions::new(Dialect::Marlin))
        .collect::<Result<_, _>>()
        .expect("settle reads its own export");
    let ft: Vec<&LimitChange> = events
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::Limits(l @ LimitChange::FtMotion { .. }) => Some(l),
            _ => None,
        })
        .collect();
    assert!(
        matches!(
            ft.first(),
            Some(LimitChange::FtMotion {
                enabled: Some(true),
                ..
            })
        ),
        "{g}"
    );
    assert_eq!(ft.len(), 3, "M493 S1, then X and Y\n{g}");
    let mut shaped = 0;
    for (line, letter) in ft[1..].iter().zip(["x", "y"]) {
        let o = &t.axes.iter().find(|(a, _)| a == letter).expect("tuned").1;
        let w = &o.scores[o.winner].candidate;
        let LimitChange::FtMotion {
            axes,
            shaper,
            frequency_hz,
            damping_ratio,
            vibration_tolerance,
            ..
        } = line
        else {
            unreachable!()
        };
        assert_eq!((axes.x, axes.y), (letter == "x", letter == "y"), "{g}");
        match w.shaper.and_then(|s| s.shaper_type.map(|k| (k, s))) {
            Some((
                ShaperType::Marlin {
                    shaper: s, v_tol, ..
                },
                sh,
            )) => {
                shaped += 1;
                let code = MarlinShaper::ALL
                    .iter()
                    .position(|f| *f == s)
                    .expect("family");
                assert_eq!(*shaper, FtShaper::from_code(code as u32 + 1), "{g}");
                assert_eq!(*frequency_hz, Some(sh.frequency_hz), "{g}");
                assert_eq!(*damping_ratio, Some(sh.damping_ratio), "{g}");
                assert_eq!(*vibration_tolerance, s.has_v_tol().then_some(v_tol), "{g}");
            }
            Some((k, _)) => panic!("{letter}: not a Marlin shaper: {k:?}"),
            None => assert_eq!(*shaper, Some(FtShaper::None), "{g}"),
        }
    }
    assert!(
        shaped > 0,
        "a shaper wins on printer_xy's 39 Hz Y mode\n{g}"
    );
    // A Marlin job that starts with the file runs with its settings and ignores none.
    let job = format!("{g}G28\nG1 X10 Y10 F6000\nG1 X50 Y10 E1\nG1 X50 Y50 E2\n");
    let cfg = settle_gcode::job::JobConfig::defaults(Firmware::Marlin).expect("defaults");
    let reader = Reader::new(job.as_bytes(), ReaderOptions::new(Dialect::Marlin));
    let mut j = settle_gcode::job::Job::new(reader, cfg).expect("job");
    j.by_ref().collect::<Result<Vec<_>, _>>().expect("plans");
    let summary = j.summary();
    assert!(summary.shaper_changes >= 1, "{summary:?}");
    assert!(
        summary
            .ignored
            .keys()
            .all(|k| !k.contains("M493") && !k.contains("M204")),
        "{:?}",
        summary.ignored
    );
}

/// `prusa.gcode` read back by settle's G-code reader (Prusa-Firmware-Buddy's dialect) as a
/// job would read it: per tuned axis the winner's `M593 T` (Buddy's type code), `F`, `D`
/// and, for the EI family, `R` (1 / the vibration tolerance), bit for bit, then `M593 W`;
/// a Prusa job starting with the file shapes with them.
#[test]
fn prusa_export_reads_back_as_the_recommendation() {
    use settle_gcode::{Dialect, EventKind, LimitChange, Reader, ReaderOptions};

    let dir = tempfile::tempdir().expect("tempdir");
    let t = tune_printer_xy(dir.path(), r#""none", "zvd", "prusa:ei", "mzv""#, "prusa");
    let g = std::fs::read_to_string(t.out.join("prusa.gcode")).expect("prusa.gcode");
    // The damping ratio 0.1 is Buddy's own default (`damping_ratio = 0.1f` of
    // axis_x_default and axis_y_default in lib/Marlin/Marlin/src/feature/input_shaper/
    // input_shaper_config.hpp), and the file says so rather than citing Klipper alone.
    let d_line = g
        .lines()
        .find(|l| l.starts_with("; M593 ") && l.contains(" D: "))
        .expect("the damping's change line");
    assert!(
        d_line.contains("-> 0.1: Buddy's default (damping_ratio 0.1 of axis_x_default"),
        "{d_line}"
    );
    let events: Vec<_> = Reader::new(g.as_bytes(), ReaderOptions::new(Dialect::Prusa))
        .collect::<Result<_, _>>()
        .expect("settle reads its own export");
    let m593: Vec<&LimitChange> = events
        .iter()
        .filter_map(|e| match &e.kind {
            EventKind::Limits(l @ LimitChange::PrusaInputShaping { .. }) => Some(l),
            _ => None,
        })
        .collect();
    assert_eq!(m593.len(), 3, "X, Y, then W\n{g}");
    assert!(
        matches!(m593[2], LimitChange::PrusaInputShaping { save: true, .. }),
        "{g}"
    );
    let mut shaped = 0;
    for (line, letter) in m593[..2].iter().zip(["x", "y"]) {
        let o = &t.axes.iter().find(|(a, _)| a == letter).expect("tuned").1;
        let w = &o.scores[o.winner].candidate;
        let LimitChange::PrusaInputShaping {
            axes,
            shaper_type,
            frequency_hz,
            damping_ratio,
            vibration_reduction,
            save,
            ..
        } = line
        else {
            unreachable!()
        };
        assert_eq!(
            (axes.x, axes.y, *save),
            (letter == "x", letter == "y", false),
            "{g}"
        );
        match w.shaper.and_then(|s| s.shaper_type.map(|k| (k, s))) {
            Some((k, sh)) => {
                shaped += 1;
                // M593.cpp's T: 0 ZV, 1 ZVD, 2 MZV, 3 EI (Buddy's), 4 2HUMP_EI, 5 3HUMP_EI.
                let (code, r) = match k {
                    ShaperType::Zvd => (1, None),
                    k if k == ShaperType::MZV => (2, None),
                    ShaperType::Prusa { v_tol, .. } => (3, Some(1.0 / v_tol)),
                    other => panic!("{letter}: not a shaper of the search: {other:?}"),
                };
                assert_eq!(*shaper_type, Some(code), "{g}");
                assert_eq!(*frequency_hz, Some(sh.frequency_hz), "{g}");
                assert_eq!(*damping_ratio, Some(sh.damping_ratio), "{g}");
                assert_eq!(*vibration_reduction, r, "{g}");
            }
            None => assert_eq!(
                (*shaper_type, *frequency_hz),
                (None, Some(0.0)),
                "F0 turns the axis's shaper off\n{g}"
            ),
        }
    }
    assert!(
        shaped > 0,
        "a shaper wins on printer_xy's 39 Hz Y mode\n{g}"
    );
    // A Prusa job that starts with the file runs with its shapers and ignores only the
    // EEPROM write.
    let job = format!("{g}G28\nG1 X10 Y10 F6000\nG1 X50 Y10 E1\nG1 X50 Y50 E2\n");
    let cfg = settle_gcode::job::JobConfig::defaults(Firmware::Prusa).expect("defaults");
    let reader = Reader::new(job.as_bytes(), ReaderOptions::new(Dialect::Prusa));
    let mut j = settle_gcode::job::Job::new(reader, cfg).expect("job");
    j.by_ref().collect::<Result<Vec<_>, _>>().expect("plans");
    let summary = j.summary();
    assert!(summary.shaper_changes >= 1, "{summary:?}");
    assert!(
        summary.ignored.keys().all(|k| k.starts_with("M593")),
        "{:?}",
        summary.ignored
    );
}

/// Prusa-Firmware-Buddy clamps `M593 F` to 10-100 Hz on its printers (the MINI's 150 Hz is
/// not assumed): the search for it holds no shaper outside that range, in the grid nor in
/// the refinement, and says which it left out. The one mode is at 47.2 Hz: scales of 1 and
/// 2.5 put shapers at 47.2 and 118 Hz.
#[test]
fn prusa_search_holds_only_the_frequencies_buddy_runs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run(
        dir.path(),
        "frequency_scales = [1.0, 2.5]\nshapers = [\"none\", \"mzv\"]\nrefine_rounds = 3\n",
        &Options {
            firmware: Some("prusa".into()),
            ..modal()
        },
    );
    let shaped: Vec<f64> = o.scores[1..]
        .iter()
        .filter_map(|s| s.candidate.shaper.filter(|sh| sh.shaper_type.is_some()))
        .map(|sh| sh.frequency_hz)
        .collect();
    assert!(shaped.contains(&47.2), "{shaped:?}");
    assert!(
        shaped.iter().all(|f| (10.0..=100.0).contains(f)),
        "{shaped:?}"
    );
    assert!(
        o.plan.notes.iter().any(|n| n.contains(
            "Prusa-Firmware-Buddy runs shapers of 10 to 100 Hz only (M593 F; it clamps others): shapers at 118 to 118 Hz left out."
        )),
        "{:?}",
        o.plan.notes
    );
    // Shapers near the top (99.1 Hz, 2.1 x the mode): the refinement's steps above 100 Hz
    // are not taken for Buddy, and are without a firmware.
    let refined = |firmware: Option<&str>| -> Vec<f64> {
        let o = run(
            dir.path(),
            "frequency_scales = [2.1]\nshapers = [\"mzv\"]\nrefine_rounds = 2\n",
            &Options {
                firmware: firmware.map(Into::into),
                ..modal()
            },
        );
        o.scores[o.plan.candidates.len()..]
            .iter()
            .filter_map(|s| s.candidate.shaper.map(|sh| sh.frequency_hz))
            .collect()
    };
    let buddy = refined(Some("prusa"));
    assert!(!buddy.is_empty(), "refined");
    assert!(buddy.iter().all(|f| *f <= 100.0), "{buddy:?}");
    let free = refined(None);
    assert!(free.iter().any(|f| *f > 100.0), "{free:?}");
    // Without the firmware the same search takes the 118 Hz shaper.
    let any = run(
        dir.path(),
        "frequency_scales = [1.0, 2.5]\nshapers = [\"none\", \"mzv\"]\nrefine_rounds = 0\n",
        &modal(),
    );
    assert!(
        any.scores.iter().any(|s| s
            .candidate
            .shaper
            .is_some_and(|sh| sh.frequency_hz == 118.0)),
        "the scales reach 118 Hz"
    );
}

/// One mode at `mode_hz` (damping 0.05) tuned for Marlin's Fixed-Time Motion at the mode's
/// own frequency (`frequency_scales = [1.0]`), with a smoothing limit loose enough for a
/// shaper that slow, written under `dir/out`.
fn tune_ft_motion_at(dir: &Path, mode_hz: f64) -> settle::workflows::tune::Tuned {
    let text =
        scenario("firmware = \"marlin\"\nfrequency_scales = [1.0]\nmax_smoothing_mm = 5.0\n")
            .replace(
                "frequency_hz = 47.2",
                &format!("frequency_hz = {mode_hz:?}"),
            )
            .replace("window_s = 0.4", "window_s = 2.0")
            .replace("sample_rate_hz = 5000", "sample_rate_hz = 2000");
    let p = write(dir, "ft.toml", &text);
    settle::workflows::tune::tune_with(
        &p,
        Some(dir.join("out")),
        &modal(),
        &settle::execute::pool::quiet,
    )
    .expect("tunes")
}

/// Marlin's `M493` takes `A` from `FTM_MIN_SHAPE_FREQ` (10 Hz in Marlin's
/// Configuration_adv.h) to `FTM_FS / 2` (`goodBaseFreq`, Marlin/src/module/ft_motion.h) and
/// answers `?Invalid` to another frequency, keeping the old one. A machine whose mode is at
/// 9 Hz is best shaped at 9.0 Hz (the mode times the only scale, 1.0): `marlin.gcode` is
/// not written, says why, and `tune.md` lists no changes for it; settle's own Marlin reader
/// refuses the line that would have been written. At 10 Hz the line is written and reads
/// back as 10 Hz.
#[test]
fn marlin_export_below_ftm_min_shape_freq_is_not_written() {
    use settle_gcode::{Dialect, EventKind, LimitChange, Reader, ReaderOptions};

    let read = |text: &str| {
        Reader::new(text.as_bytes(), ReaderOptions::new(Dialect::Marlin))
            .collect::<Result<Vec<_>, _>>()
    };
    let winner = |t: &settle::workflows::tune::Tuned| {
        let o = &t.axes[0].1;
        let sh = o.scores[o.winner].candidate.shaper.expect("shaped");
        assert!(
            matches!(sh.shaper_type, Some(ShaperType::Marlin { .. })),
            "{sh:?}"
        );
        sh
    };

    let dir = tempfile::tempdir().expect("tempdir");
    let t = tune_ft_motion_at(dir.path(), 9.0);
    let sh = winner(&t);
    assert_eq!(sh.frequency_hz, 9.0);
    let g = std::fs::read_to_string(t.out.join("marlin.gcode")).expect("marlin.gcode");
    assert!(
        g.starts_with("; no Marlin configuration: cannot export M493 X A = 9 (allowed: FTM_MIN_SHAPE_FREQ = 10 Hz up to FTM_FS / 2 = 500 Hz"),
        "{g}"
    );
    assert!(!g.lines().any(|l| l.starts_with("M493")), "{g}");
    assert!(
        !t.markdown.contains("What changes in marlin.gcode"),
        "{}",
        t.markdown
    );
    // What would have been written is what settle's reader of Marlin refuses too.
    let would = format!("M493 X C1 A9 I{}\n", sh.damping_ratio);
    let err = read(&would).expect_err("refused").to_string();
    assert!(
        err.contains("A = 9") && err.contains("10 to 500 Hz"),
        "{err}"
    );

    let dir = tempfile::tempdir().expect("tempdir");
    let t = tune_ft_motion_at(dir.path(), 10.0);
    let sh = winner(&t);
    assert_eq!(sh.frequency_hz, 10.0);
    let g = std::fs::read_to_string(t.out.join("marlin.gcode")).expect("marlin.gcode");
    let events = read(&g).expect("settle reads its own export");
    let x = events
        .iter()
        .find_map(|e| match &e.kind {
            EventKind::Limits(LimitChange::FtMotion {
                axes,
                frequency_hz,
                damping_ratio,
                ..
            }) if axes.x => Some((*frequency_hz, *damping_ratio)),
            _ => None,
        })
        .expect("an M493 X line");
    assert_eq!(x, (Some(10.0), Some(sh.damping_ratio)), "{g}");
    assert!(t.markdown.contains("What changes in marlin.gcode"));
}
