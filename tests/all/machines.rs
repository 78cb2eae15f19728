//! Machine presets, machine files and inline machines: they parse, compile and put their
//! modes where their comments say; bad input names the file, line and key.

use std::path::Path;

use settle::Error;
use settle_sim::DriverMode;

fn expand(text: &str, path: &Path) -> Result<Vec<settle::RunSpec>, Error> {
    settle::expand::parse(text, path).and_then(|(sc, src)| settle::expand::expand(&sc, &src))
}

fn err(text: &str) -> String {
    match expand(text, Path::new("bad.toml")) {
        Ok(runs) => panic!("expected an error, got {} runs", runs.len()),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

const PRINTER: &str = r#"name = "p"
[machine]
preset = "printer_xy"
[move]
distance_mm = 10.0
axis = "y"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 1e5
"#;

#[test]
fn presets_parse_compile_and_ring_where_their_comments_say() {
    let dir = Path::new(crate::support::manifest_dir());
    for (name, path, text) in settle::input::machine_file::PRESETS {
        // The embedded text is the checked-in file.
        let on_disk = std::fs::read_to_string(dir.join(path)).expect("preset file");
        assert_eq!(on_disk, text, "{name}");
        let (m, description) =
            settle::input::machine_file::parse(text, Path::new(path)).expect("preset parses");
        assert_eq!(m.name, name);
        assert!(!description.is_empty());
        for mode in [DriverMode::Full, DriverMode::Spring, DriverMode::Linear] {
            m.compile(mode).expect("compiles");
        }
        for axis in m.compile(DriverMode::Linear).expect("compiles") {
            let q = axis.lumped.equilibrium(0.0, None).expect("equilibrium");
            let f = axis.lumped.natural_frequencies_hz(&q);
            eprintln!("{name}/{}: modes {f:.1?} Hz", axis.name);
            match name {
                // "a belt-driven printer XY ... modes roughly 40-70 Hz"
                "printer_xy" => assert!((38.0..70.0).contains(&f[0]), "{f:?}"),
                "leadscrew_stage" => assert!((150.0..250.0).contains(&f[0]), "{f:?}"),
                _ => {}
            }
        }
    }
}

#[test]
fn scenario_with_a_preset_expands_on_the_named_axis() {
    let runs = expand(PRINTER, Path::new("p.toml")).expect("expands");
    assert_eq!(runs.len(), 1);
    let r = &runs[0];
    assert_eq!(
        (r.axis.as_str(), r.machine_name.as_str()),
        ("y", "printer_xy")
    );
    assert_eq!(r.driver, DriverMode::Full);
    assert_eq!(r.machine.physical().map(|m| m.axes.len()), Some(2));
}

#[test]
fn machine_parameters_can_be_swept() {
    let text = format!(
        "{PRINTER}[sweep]\n\"machine.axis.y.mount.stiffness_n_per_m\" = [1e5, 1e6]\n\"machine.driver.microsteps\" = [16, 64]\n"
    );
    let runs = expand(&text, Path::new("p.toml")).expect("expands");
    assert_eq!(runs.len(), 4);
    let y = |r: &settle::RunSpec| r.machine.physical().expect("machine").axes[1].clone();
    assert_eq!(y(&runs[0]).mount.stiffness_n_per_m, 1e5);
    assert_eq!(y(&runs[3]).mount.stiffness_n_per_m, 1e6);
    assert_eq!(y(&runs[1]).driver.microsteps, 64);
    // Every axis gets the machine-wide value.
    assert_eq!(
        runs[1].machine.physical().expect("machine").axes[0]
            .driver
            .microsteps,
        64
    );
    let msg = err(&format!(
        "{PRINTER}[sweep]\n\"machine.driver.microsteps\" = [16, 12]\n"
    ));
    assert!(
        msg.starts_with("bad.toml:12:1: key `sweep.machine.driver.microsteps`")
            && msg.contains("power of two"),
        "{msg}"
    );
    let msg = err(&format!(
        "{PRINTER}[sweep]\n\"machine.axis.x.belt.colour\" = [1]\n"
    ));
    assert!(msg.contains("no numeric field `belt.colour`"), "{msg}");
}

#[test]
fn inline_machines_and_their_errors_name_the_key() {
    let inline = r#"name = "inline"
[machine]
driver_model = "spring"
[machine.motor]
holding_torque_n_m = 0.4
rated_current_a = 1.7
resistance_ohm = 1.5
inductance_mh = 2.8
rotor_inertia_g_cm2 = 54.0
damping_ratio = 0.05
[machine.driver]
microsteps = 16
run_current_a_rms = 0.8
supply_v = 24.0
[machine.axis.x]
carriage_kg = 0.2
toolhead_kg = 0.5
[machine.axis.x.screw]
lead_mm = 8.0
stiffness_n_per_m = 2e7
damping_ratio = 0.05
[machine.axis.x.mount]
stiffness_n_per_m = 1e6
damping_ratio = 0.05
[move]
distance_mm = 5.0
[limits]
vmax_mm_s = 50.0
amax_mm_s2 = 1000.0
jmax_mm_s3 = 1e5
"#;
    let runs = expand(inline, Path::new("i.toml")).expect("inline machine");
    assert_eq!(runs[0].driver, DriverMode::Spring);
    assert_eq!(runs[0].machine_name, "inline");
    let msg = err(&inline.replace("stiffness_n_per_m = 1e6", "stiffness_n_per_m = -1e6"));
    assert!(
        msg.starts_with("bad.toml:23:1: key `machine.axis.x.mount.stiffness_n_per_m`"),
        "{msg}"
    );
    let msg = err(&inline.replace("supply_v = 24.0", "supply_v = 0.0"));
    assert!(
        msg.starts_with("bad.toml:14:1: key `machine.driver.supply_v`"),
        "{msg}"
    );
    let msg = err(&inline.replace("lead_mm = 8.0", "lead_mm = 8.0\npitch = 2"));
    assert!(
        msg.starts_with("bad.toml:20:") && msg.contains("pitch"),
        "{msg}"
    );
    let msg = err(&inline.replace("driver_model = \"spring\"", "driver_model = \"ideal\""));
    assert!(msg.contains("full, spring, linear"), "{msg}");
    let msg = err(&inline.replace("[machine.axis.x.screw]", "[machine.axis.x.unused]"));
    assert!(msg.contains("unused"), "{msg}");
}

/// Parts each within its range whose mode is not (a 0.1 g toolhead on a 1e12 N/m mount,
/// 16 MHz): the sweep asked for a sample rate of 3e7 Hz at `observe.sample_rate_hz`, as if
/// the rate were the mistake. The error names the machine and the units to check instead.
#[test]
fn a_machine_with_an_implausible_mode_is_named_not_the_sample_rate() {
    let msg = err(&format!(
        "{PRINTER}[sweep]\n\"machine.axis.y.mount.stiffness_n_per_m\" = [1e12]\n\"machine.axis.y.toolhead_kg\" = [1e-4]\n"
    ));
    assert!(
        msg.starts_with("bad.toml:2:1: key `machine`: the linearised modes of the machine `printer_xy` reach 1.59"),
        "{msg}"
    );
    assert!(
        msg.contains("the machine is implausible") && msg.contains("motor.rotor_inertia_g_cm2"),
        "{msg}"
    );
    assert!(!msg.contains("give at least"), "{msg}");
}

#[test]
fn machine_form_errors() {
    let msg = err(&PRINTER.replace(
        "preset = \"printer_xy\"",
        "preset = \"printer_xy\"\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
    ));
    assert!(msg.contains("not both"), "{msg}");
    let msg = err(&PRINTER.replace("printer_xy", "printer_zz"));
    assert!(
        msg.starts_with("bad.toml:3:1: key `machine.preset`")
            && msg.contains("printer_xy, leadscrew_stage"),
        "{msg}"
    );
    let msg = err(&PRINTER.replace("axis = \"y\"", "axis = \"z\""));
    assert!(msg.contains("no axis `z`") && msg.contains("x, y"), "{msg}");
    // The belt's travel: +-170 mm around the middle.
    let msg = err(&PRINTER.replace("distance_mm = 10.0", "distance_mm = 200.0"));
    assert!(
        msg.contains("key `move.distance_mm`") && msg.contains("-170.0 to 170.0 mm"),
        "{msg}"
    );
    let msg = err(&PRINTER.replace("preset = \"printer_xy\"", "name = \"empty\""));
    assert!(msg.contains("give the machine"), "{msg}");
}

#[test]
fn machine_file_by_path_reports_its_own_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let preset = settle::input::machine_file::PRESETS[1].2;
    std::fs::write(dir.path().join("stage.toml"), preset).expect("write");
    let scenario = PRINTER
        .replace("\"printer_xy\"", "\"stage.toml\"")
        .replace("axis = \"y\"", "axis = \"x\"");
    let path = dir.path().join("s.toml");
    let runs = expand(&scenario, &path).expect("machine file by path");
    assert_eq!(runs[0].machine_name, "leadscrew_stage");
    std::fs::write(
        dir.path().join("stage.toml"),
        preset.replace("lead_mm = 5.0", "lead_mm = -5.0"),
    )
    .expect("write");
    let e = expand(&scenario, &path).expect_err("bad machine file");
    let msg = e.to_string();
    assert!(
        msg.contains("stage.toml:") && msg.contains("key `axis.x.screw.lead_mm`"),
        "{msg}"
    );
}
