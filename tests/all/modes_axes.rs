//! The modes form on every axis (`[machine.axis.<name>] modes = [...]`): a move on Y rings
//! at Y's modes and a corner on an XY modes machine rings on each axis at that axis's
//! modes, both against the closed form (settle-sim's `residual_at`, the convolution of the
//! mode's impulse response with the profile's acceleration, independent of the modal
//! plant's matrix exponential); the `[machine] modes` shorthand is axis X; bad input names
//! file, line and key.

use std::path::Path;

use settle::Error;
use settle::spec::backend::Backend;
use settle_sim::Mode;
use settle_sim::closed_form::residual_at;

const X_MODE: (f64, f64) = (40.0, 0.05);
const Y_MODE: (f64, f64) = (25.0, 0.03);

fn two_axes(motion: &str) -> String {
    format!(
        r#"name = "xy_modes"
[machine.axis.x]
modes = [{{ frequency_hz = {}, damping_ratio = {} }}]
[machine.axis.y]
modes = [{{ frequency_hz = {}, damping_ratio = {}, weight = 1.0 }}]
{motion}
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
[observe]
window_s = 0.3
sample_rate_hz = 10000
"#,
        X_MODE.0, X_MODE.1, Y_MODE.0, Y_MODE.1
    )
}

fn expand(text: &str) -> Result<Vec<settle::RunSpec>, Error> {
    settle::expand::parse(text, Path::new("m.toml"))
        .and_then(|(sc, src)| settle::expand::expand(&sc, &src))
}

fn err(text: &str) -> String {
    match expand(text) {
        Ok(r) => panic!("expected an error, got {} runs", r.len()),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

/// The largest |residual| (um) of `profile` on `mode` over `[t0, t0 + window]`, on a grid
/// ten times finer than the simulation's samples.
fn closed_form_peak_um(
    profile: &settle_planner::Profile,
    mode: (f64, f64),
    t0: f64,
    window: f64,
) -> f64 {
    let m = Mode::new(mode.0, mode.1, 1.0).expect("mode");
    let n = (window * 100_000.0) as usize;
    (0..=n)
        .map(|i| residual_at(profile, &m, t0 + window * i as f64 / n as f64).abs())
        .fold(0.0, f64::max)
        * 1e6
}

fn run_modal(runs: &mut [settle::RunSpec]) -> Vec<settle::Metrics> {
    settle::execute::set_backend(Path::new("m.toml"), runs, Backend::Modal).expect("modal");
    runs.iter()
        .map(|r| settle::execute::execute(r, None).expect("runs"))
        .collect()
}

#[test]
fn a_y_move_rings_at_the_y_modes_and_x_stays_still() {
    let mut runs = expand(&two_axes(
        "[move]\ndistance_mm = 10.0\naxis = \"y\"\nprofile = \"trapezoid\"",
    ))
    .expect("two-axis modes machine");
    assert_eq!(runs[0].axis_names(), ["x", "y"]);
    let m = &run_modal(&mut runs)[0];
    let limits = runs[0].limits_si().expect("limits");
    let profile = settle_planner::trapezoid::rest_to_rest(0.0, 0.010, &limits).expect("trapezoid");
    let t_end = profile.duration_s();
    assert!((m.move_time_s - t_end).abs() < 1e-12);
    let want = closed_form_peak_um(&profile, Y_MODE, t_end, 0.3);
    // The X mode would ring differently: the test tells the axes apart.
    let x_would = closed_form_peak_um(&profile, X_MODE, t_end, 0.3);
    assert!((want - x_would).abs() > 0.1 * want, "{want} {x_would}");
    assert!(
        (m.residual_peak_um - want).abs() < 1e-3 * want,
        "modal {} vs closed form {want}",
        m.residual_peak_um
    );
    let axis = |n: &str| m.axes.iter().find(|a| a.name == n).expect("axis metrics");
    assert!((axis("y").residual_peak_um - want).abs() < 1e-3 * want);
    assert_eq!(axis("x").residual_peak_um, 0.0);
    // runs.csv: X's modes keep their columns, Y's are prefixed; per-axis metrics.
    let csv = settle::output::runs_csv::RunsCsv::new(&runs);
    let cols = csv.columns();
    for c in [
        "mode0_frequency_hz",
        "y_mode0_frequency_hz",
        "y_mode0_weight",
        "x_residual_peak_um",
        "y_residual_peak_um",
    ] {
        assert!(cols.iter().any(|h| h == c), "{c} missing: {cols:?}");
    }
}

#[test]
fn a_corner_on_an_xy_modes_machine_rings_on_each_axis_at_its_own_modes() {
    let mut runs = expand(&two_axes(
        "[corner]\nangle_deg = 90.0\nleg_in_mm = 10.0\nleg_out_mm = 10.0\nstrategy = \"exact_stop\"\nprofile = \"trapezoid\"",
    ))
    .expect("corner on a modes machine");
    let m = &run_modal(&mut runs)[0];
    assert!(m.is_ok(), "{:?}", m.status);
    let names = runs[0].axis_names();
    let planned = settle::studies::plan(&runs[0], &names).expect("plans");
    let traj = planned.motion.whole().expect("a corner is planned whole");
    let t_end = traj.duration_s();
    for (name, mode, profile) in [
        ("x", X_MODE, &traj.axes()[0]),
        ("y", Y_MODE, &traj.axes()[1]),
    ] {
        let want = closed_form_peak_um(profile, mode, t_end, 0.3);
        let got = m
            .axes
            .iter()
            .find(|a| a.name == name)
            .expect("axis")
            .residual_peak_um;
        assert!(want > 0.01, "{name}: {want}");
        assert!(
            (got - want).abs() < 1e-3 * want,
            "axis {name}: modal {got} vs closed form {want}"
        );
    }
}

#[test]
fn the_modes_shorthand_is_axis_x_and_sweeps_reach_every_axis() {
    let text = two_axes("[move]\ndistance_mm = 5.0\nprofile = \"trapezoid\"")
        .replace("[machine.axis.x]\nmodes", "[machine]\nmodes")
        + "[sweep]\n\"machine.axis.y.modes.0.frequency_hz\" = [20.0, 30.0]\n\"machine.modes.0.damping_ratio\" = [0.1]\n";
    let runs = expand(&text).expect("shorthand plus an axis table");
    assert_eq!(runs.len(), 2);
    assert_eq!(runs[1].machine.modes_of("y")[0].frequency_hz, 30.0);
    assert_eq!(runs[1].machine.modes_of("x")[0].damping_ratio, 0.1);
    let msg = err(&text.replace("[20.0, 30.0]", "[20.0, -1.0]"));
    assert!(
        msg.contains("key `sweep.machine.axis.y.modes.0.frequency_hz`"),
        "{msg}"
    );
}

#[test]
fn bad_modes_machines_name_file_line_and_key() {
    let base = two_axes("[move]\ndistance_mm = 5.0\naxis = \"y\"");
    let msg = err(&base.replace("damping_ratio = 0.03", "damping_ratio = 1.5"));
    assert!(
        msg.starts_with("m.toml:5:1: key `machine.axis.y.modes`") && msg.contains("mode 0"),
        "{msg}"
    );
    let msg = err(&base.replace(
        "[machine.axis.y]\n",
        "[machine.axis.y]\ncarriage_kg = 0.2\n",
    ));
    assert!(
        msg.contains("key `machine.axis.y.modes`") && msg.contains("not both"),
        "{msg}"
    );
    let msg = err(&base.replace("axis = \"y\"", "axis = \"z\""));
    assert!(msg.contains("no axis `z`") && msg.contains("x, y"), "{msg}");
    let msg = err(&base.replace("weight = 1.0 }]", "weight = 1.0 }]\nmodes = []"));
    assert!(msg.contains("m.toml:"), "{msg}");
    let msg = err(&base.replace(
        "[machine.axis.x]\nmodes = [{ frequency_hz = 40, damping_ratio = 0.05 }]",
        "[machine.axis.x]\nmodes = []",
    ));
    assert!(
        msg.starts_with("m.toml:3:1: key `machine.axis.x.modes`")
            && msg.contains("one or more modes"),
        "{msg}"
    );
}
