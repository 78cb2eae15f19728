//! Parameters without bounds, each refused before work with its key and its limit: a
//! shaper of 1e-6 Hz (on the command line and in a G-code file), a sample rate of 1e12
//! Hz, an integration step of 1e-300 s, scans of 1e9 and 2^63 lines, 100,000 modes, a
//! search of a thousand frequencies, a figure count of a million; and memory that would
//! grow with the job (the ringing map of a layer of 3,200 long lines, which must stay
//! under the suite's 1 GiB like every case).

use super::sandbox::SCENARIO;
use super::{Case, Expect, Sandbox, check_all};

/// The sandbox's scenario with `from` replaced by `to`.
pub fn scenario_with(from: &str, to: &str) -> String {
    assert!(SCENARIO.contains(from), "{from}");
    SCENARIO.replacen(from, to, 1)
}

/// A scan scenario of `lines` lines.
fn scan(lines: &str) -> String {
    scenario_with(
        "[observe]",
        &format!("[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nwidth_mm = 10.0\nlines = {lines}\n[observe]"),
    )
    .replace("distance_mm = 5.0", "distance_mm = 0.5")
}

/// Every case of the class.
pub fn cases(sb: &Sandbox) -> Vec<Case> {
    sb.write(
        "m593.gcode",
        "M593 F0.000001\nG28\nM83\nG1 X10 Y10 E1 F3000\nG1 X20 Y10 E1\n",
    );
    sb.write(
        "step.toml",
        &scenario_with("[observe]", "[sim]\nmax_step_s = 1e-300\n[observe]"),
    );
    sb.write("scan_1e9.toml", &scan("1000000000"));
    sb.write("scan_max.toml", &scan("9223372036854775807"));
    let modes: Vec<String> = (0..100_000)
        .map(|i| {
            format!(
                "{{ frequency_hz = {}, damping_ratio = 0.05, weight = 0.00001 }}",
                40.0 + f64::from(i) * 0.001
            )
        })
        .collect();
    sb.write(
        "modes.toml",
        &scenario_with(
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
            &format!("modes = [{}]", modes.join(", ")),
        ),
    );
    let scales: Vec<String> = (0..1000)
        .map(|i| format!("{}", 0.5 + f64::from(i) * 0.001))
        .collect();
    sb.write(
        "tune_many.toml",
        &(scenario_with("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "")
            + &format!("[tune]\nfrequency_scales = [{}]\n", scales.join(", "))),
    );
    // One layer of 3,200 lines of 190 mm (1.9 s each): the ringing map of a layer of
    // 6,080 s of printing.
    let mut layer = String::from("G28\nM83\nG1 Z0.2 F3000\n");
    for i in 0..3200 {
        let x = if i % 2 == 0 { 200 } else { 10 };
        layer.push_str(&format!(
            "G1 X{x} Y{:.2} E0.5 F6000\n",
            10.0 + f64::from(i % 600) * 0.3
        ));
    }
    sb.write("layer.gcode", &layer);
    let gcode = |what: &str, more: &[&str], parts: &[&str]| {
        let mut a = vec![
            "gcode",
            "print.gcode",
            "--machine",
            "printer_xy",
            "--out",
            "o",
        ];
        a.extend_from_slice(more);
        Case::new(what, &a, &[], Expect::refused(parts))
    };
    let refused = |what: &str, line: &str, parts: &[&str]| {
        Case::line(what, line, &[], Expect::refused(parts))
    };
    vec![
        gcode(
            "--shaper mzv@1e-6",
            &["--shaper", "mzv@1e-6"],
            &["below 1 Hz"],
        ),
        refused(
            "M593 F0.000001 in a Marlin file",
            "gcode m593.gcode --machine printer_xy --firmware marlin --out o",
            &["m593.gcode:1", "M593", "below 1 Hz"],
        ),
        gcode(
            "--sample-rate-hz 1e12",
            &["--sample-rate-hz", "1e12"],
            &["--sample-rate-hz", "above the limit of 100000 Hz"],
        ),
        gcode("--maps 1000000", &["--maps", "1000000"], &["--maps"]),
        refused(
            "sim.max_step_s = 1e-300",
            "sweep step.toml --backend rapier --out o",
            &["step.toml:", "sim.max_step_s", "1e-6"],
        ),
        refused(
            "scan.lines = 1e9",
            "sweep scan_1e9.toml --backend modal --out o",
            &["scan.lines", "100000"],
        ),
        refused(
            "scan.lines = 2^63 - 1",
            "sweep scan_max.toml --backend modal --out o",
            &["scan.lines", "100000"],
        ),
        refused(
            "100,000 modes",
            "run modes.toml --case 0 --backend modal --out o/t.csv",
            &["machine.modes", "at most 100 per axis"],
        ),
        refused(
            "tune over 1,000 frequency scales",
            "tune tune_many.toml --out o",
            &["tune.frequency_scales", "at most 64"],
        ),
        refused(
            "identify --hz-per-sec 1e-9",
            "identify rec_x.csv --hz-per-sec 1e-9",
            &["--hz-per-sec", "0.1 to 100"],
        ),
        Case::line(
            "the ringing map of a 3,200-line layer (1 h 41 min)",
            "gcode layer.gcode --machine printer_xy --out o_layer",
            &["o_layer"],
            Expect::answered(&["wrote o_layer/ringing-layer-1.png"]),
        ),
        refused(
            "identify --sweeping-period 1e-9",
            "identify rec_x.csv --sweeping-period 1e-9",
            &["--sweeping-period"],
        ),
    ]
}

#[test]
fn every_parameter_is_bounded_before_work() {
    let sb = Sandbox::new();
    let cases = cases(&sb);
    check_all(&sb, &cases);
}
