//! Input shapers as first-class sweep parameters: a shaped trapezoid on a
//! one-mode machine, through the whole harness on the exact modal backend, against the
//! closed-form residual of the analytic reference (settle_sim::closed_form) and the
//! shaper's remaining vibration; and the errors of bad `[shaper]` input.

use std::path::Path;

use settle::spec::backend::Backend;
use settle_planner::shaper::{Shaper, ShaperType};
use settle_planner::{Limits, ProfileKind};
use settle_sim::Mode;
use settle_sim::closed_form::{residual_at, residual_envelope};

const F_HZ: f64 = 40.0;
const ZETA: f64 = 0.05;
const RATE_HZ: f64 = 10_000.0;
const WINDOW_S: f64 = 0.5;

fn scenario() -> String {
    format!(
        r#"name = "shaped"
[machine]
modes = [{{ frequency_hz = {F_HZ}, damping_ratio = {ZETA} }}]
[move]
distance_mm = 10.0
profile = "trapezoid"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
[observe]
window_s = {WINDOW_S}
sample_rate_hz = {RATE_HZ}
bands_um = [10.0]
[shaper]
type = "mzv"
frequency_hz = {F_HZ}
[sweep]
"shaper.type" = ["none", "zv", "mzv", "zvd", "ei", "2hump_ei", "3hump_ei"]
"#
    )
}

/// Peak |e(t)| of the closed-form residual, sampled as the harness samples (every
/// 1/RATE_HZ from the end of the move over the window).
fn closed_form_peak_m(profile: &settle_planner::Profile, mode: &Mode) -> f64 {
    let t_end = profile.duration_s();
    let n = (WINDOW_S * RATE_HZ).round() as usize;
    (0..=n)
        .map(|i| residual_at(profile, mode, t_end + i as f64 / RATE_HZ).abs())
        .fold(0.0, f64::max)
}

#[test]
fn shaped_trapezoid_leaves_the_closed_form_fraction_of_the_residual() {
    let path = Path::new("shaped.toml");
    let (sc, src) = settle::expand::parse(&scenario(), path).expect("parses");
    let mut runs = settle::expand::expand(&sc, &src).expect("expands");
    assert_eq!(runs.len(), 7);
    settle::execute::set_backend(path, &mut runs, Backend::Modal).expect("modal");
    let results = settle::execute::pool::run_all(&runs, Some(1), &settle::execute::pool::quiet)
        .expect("pool");
    let metrics: Vec<_> = results.into_iter().map(|r| r.expect("runs")).collect();

    // Independent reference: the planner's unshaped trapezoid and the closed form.
    let mode = Mode::new(F_HZ, ZETA, 1.0).expect("mode");
    let limits = Limits::new(0.3, 3.0, None).expect("limits");
    let plain = ProfileKind::Trapezoid
        .rest_to_rest(0.0, 0.01, &limits)
        .expect("plans");
    let plain_env = residual_envelope(&plain, &mode);
    let plain_peak_um = closed_form_peak_m(&plain, &mode) * 1e6;
    let unshaped = &metrics[0];
    assert!(
        (unshaped.residual_peak_um - plain_peak_um).abs() < 1e-6 * plain_peak_um,
        "unshaped: harness {} um vs closed form {plain_peak_um} um",
        unshaped.residual_peak_um
    );
    assert!(plain_peak_um > 50.0, "the test needs a real residual");

    let csv = settle::output::runs_csv::runs_csv(&runs, &metrics);
    let header: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let rv_col = col("remaining_vibration_pct");

    for (i, kind) in ShaperType::ALL.into_iter().enumerate() {
        let (run, m) = (&runs[i + 1], &metrics[i + 1]);
        let shaper = Shaper::new(kind, F_HZ, 0.1).expect("shaper");
        let rv = shaper.remaining_vibration(F_HZ, ZETA);
        // The closed form of the shaped command: its residual envelope is exactly the
        // unshaped one times the remaining vibration (superposition of delayed copies).
        let shaped = shaper.apply(&plain).expect("shapes");
        let env = residual_envelope(&shaped, &mode);
        assert!(
            (env / plain_env - rv).abs() < 1e-9,
            "{kind}: closed-form ratio {} vs remaining vibration {rv}",
            env / plain_env
        );
        // The harness's shaped run is that command: same duration and residual.
        assert!(
            (m.move_time_s - shaped.duration_s()).abs() < 1e-12,
            "{kind}"
        );
        let peak_um = closed_form_peak_m(&shaped, &mode) * 1e6;
        assert!(
            (m.residual_peak_um - peak_um).abs() < 1e-6 * plain_peak_um,
            "{kind}: harness {} um vs closed form {peak_um} um",
            m.residual_peak_um
        );
        // And it is below the unshaped residual by the predicted factor: the peak never
        // exceeds the envelope, and every shaper cuts this mode to < 8%.
        assert!(
            m.residual_peak_um <= rv * plain_env * 1e6 * (1.0 + 1e-9),
            "{kind}"
        );
        assert!(rv < 0.08, "{kind}: {rv}");
        // runs.csv reports the remaining vibration of the machine's mode in %.
        let row: Vec<&str> = csv.lines().nth(i + 2).expect("row").split(',').collect();
        let pct: f64 = row[rv_col].parse().expect("number");
        assert!((pct - 100.0 * rv).abs() < 1e-9, "{kind}: {pct}");
        assert_eq!(row[col("shaper_type")], kind.name());
        assert_eq!(
            run.state::<settle::studies::shaping::ShaperSetting>()
                .and_then(|s| s.shaper_type),
            Some(kind)
        );
    }
    // MZV at the mode: Klipper's 5% class (its published bands are 5% wide).
    assert!(metrics[2].residual_peak_um < 0.05 * unshaped.residual_peak_um);
}

fn parse_err(text: &str) -> String {
    let r = settle::expand::parse(text, Path::new("bad.toml"))
        .and_then(|(sc, src)| settle::expand::expand(&sc, &src));
    match r {
        Ok(runs) => panic!("expected an error, got {} runs", runs.len()),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

const BASE: &str = r#"name = "bad"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 10.0
profile = "trapezoid"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
"#;

#[test]
fn bad_shaper_input_names_file_line_and_key() {
    let msg = parse_err(&format!(
        "{BASE}[shaper]\ntype = \"mzz\"\nfrequency_hz = 40.0\n"
    ));
    assert!(
        msg.contains("bad.toml:11")
            && msg.contains("key `shaper.type`")
            && msg.contains("2hump_ei"),
        "{msg}"
    );
    let msg = parse_err(&format!(
        "{BASE}[shaper]\ntype = \"zv\"\nfrequency_hz = -4.0\n"
    ));
    assert!(
        msg.contains("bad.toml:12")
            && msg.contains("key `shaper.frequency_hz`")
            && msg.contains("> 0"),
        "{msg}"
    );
    let msg = parse_err(&format!(
        "{BASE}[shaper]\ntype = \"zv\"\nfrequency_hz = 40.0\ndamping_ratio = 1.5\n"
    ));
    assert!(msg.contains("key `shaper.damping_ratio`"), "{msg}");
    let msg = parse_err(&format!("{BASE}[shaper]\ntype = \"zv\"\nfreq = 40.0\n"));
    assert!(
        msg.contains("freq") && msg.contains("frequency_hz"),
        "{msg}"
    );
    // Swept: the sweep key is blamed.
    let msg = parse_err(&format!(
        "{BASE}[shaper]\ntype = \"zv\"\nfrequency_hz = 40.0\n[sweep]\n\"shaper.type\" = [\"zv\", \"bogus\"]\n"
    ));
    assert!(
        msg.contains("key `sweep.shaper.type`") && msg.contains("bogus"),
        "{msg}"
    );
    let msg = parse_err(&format!(
        "{BASE}[shaper]\ntype = \"zv\"\nfrequency_hz = 40.0\n[sweep]\n\"shaper.frequency_hz\" = [40, 0]\n"
    ));
    assert!(msg.contains("key `sweep.shaper.frequency_hz`"), "{msg}");
    // Sweeping a shaper key needs the table.
    let msg = parse_err(&format!("{BASE}[sweep]\n\"shaper.type\" = [\"zv\"]\n"));
    assert!(msg.contains("needs a [shaper] table"), "{msg}");
}
