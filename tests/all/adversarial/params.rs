//! Parameters without bounds, each refused before work with its key and its limit: a
//! shaper of 1e-6 Hz (on the command line and in a G-code file), a sample rate of 1e12
//! Hz, an integration step of 1e-300 s, scans of 1e9 and 2^63 lines, 100,000 modes, a
//! search of a thousand frequencies, a figure count of a million; modes of 1e300 Hz and
//! 1e-300 Hz, a weight of 1e300 and a frequency standard deviation of 1e300 Hz (in a
//! machine file each command reads, inline and swept); microsteps per mm of 0 and -100
//! for the TMC4361A's registers; and memory that would grow with
//! the job (the ringing map of a layer of 3,200 long lines, which must stay
//! under the suite's 1 GiB like every case); shapers above the fastest mode a machine may
//! have (50 kHz: `[shaper]`, `[tune.axis.x]`, `tune.frequency_scales`) or above the 1 kHz
//! a G-code replay takes (`settle gcode --shaper`).

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
    // Microsteps per mm the TMC4361A's registers scale with: 0 (a whole search, then no
    // register file) and -100 on one axis (a negative AMAX, blamed on another key).
    for (name, table) in [
        ("tune_usteps0.toml", "[tune]\nusteps_per_mm = 0.0\n"),
        (
            "tune_usteps_axis.toml",
            "[tune]\nusteps_per_mm = 80.0\n[tune.axis.x]\nusteps_per_mm = -100.0\n",
        ),
    ] {
        sb.write(
            name,
            &(scenario_with("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "") + table),
        );
    }
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
    // Machines given by their modes, one field out of its range each (x and y, so that
    // `settle gcode` takes them).
    let machine = |x_mode: &str| {
        format!(
            "name = \"m\"\n[axis.x]\nmodes = [{{ {x_mode} }}]\n[axis.y]\nmodes = [{{ frequency_hz = 40.0, damping_ratio = 0.05 }}]\n"
        )
    };
    sb.write(
        "m_fast.toml",
        &machine("frequency_hz = 1e300, damping_ratio = 0.05"),
    );
    sb.write(
        "m_sigma.toml",
        &machine("frequency_hz = 40.0, damping_ratio = 0.05, frequency_sigma_hz = 1e300"),
    );
    sb.write(
        "m_weight.toml",
        &machine("frequency_hz = 40.0, damping_ratio = 0.05, weight = 1e300"),
    );
    let on = |file: &str| {
        scenario_with(
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
            &format!("preset = \"{file}\""),
        )
    };
    // Without [sweep] (settle tune does its own search): the sigma is what is refused.
    sb.write(
        "tune_sigma.toml",
        &(on("m_sigma.toml").replace("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "")
            + "[tune]\ndistances_mm = [5.0]\njerk_steps = 2\n"),
    );
    sb.write("sweep_fast.toml", &on("m_fast.toml"));
    sb.write(
        "slow_inline.toml",
        &scenario_with("frequency_hz = 40.0", "frequency_hz = 1e-300"),
    );
    sb.write(
        "swept_fast.toml",
        &scenario_with(
            "profile = [\"trapezoid\", \"scurve\"]",
            "\"machine.modes.0.frequency_hz\" = [40.0, 1e6]",
        ),
    );
    // Shapers far above every mode a machine may have (50 kHz): in `[shaper]`, as a
    // `[tune.axis.x]` current setting, and as a multiple of the 40 Hz mode.
    sb.write(
        "shaper_fast.toml",
        &(SCENARIO.to_string() + "[shaper]\ntype = \"mzv\"\nfrequency_hz = 1e300\n"),
    );
    let tune = |table: &str| {
        scenario_with("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "")
            + "[tune]\ndistances_mm = [5.0]\njerk_steps = 2\nkinds = [\"scurve\"]\nshapers = [\"mzv\"]\n"
            + table
    };
    sb.write(
        "tune_current_fast.toml",
        &tune("[tune.axis.x]\nshaper = \"mzv\"\nfrequency_hz = 1e300\n"),
    );
    sb.write(
        "tune_scale_fast.toml",
        &tune("frequency_scales = [1.0, 1e300]\n"),
    );
    // 1250 x 40 Hz = 50 kHz, the bound itself: searched (the shaper shapes nothing).
    sb.write(
        "tune_scale_edge.toml",
        &tune("frequency_scales = [1250.0]\n"),
    );
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
        gcode(
            "--shaper mzv@1e300",
            &["--shaper", "mzv@1e300"],
            &["--shaper", "`mzv@1e300`", "above 1000 Hz"],
        ),
        gcode(
            "--shaper x=mzv@48,y=ei@1001",
            &["--shaper", "x=mzv@48,y=ei@1001"],
            &["--shaper", "`ei@1001`: 1001 Hz is above 1000 Hz"],
        ),
        refused(
            "shaper.frequency_hz = 1e300",
            "sweep shaper_fast.toml --backend modal --out o",
            &[
                "shaper_fast.toml:",
                "key `shaper.frequency_hz`",
                "1e300 Hz is above 50000 Hz",
            ],
        ),
        refused(
            "tune with a current shaper of 1e300 Hz",
            "tune tune_current_fast.toml --out o",
            &["key `tune.axis.x.shaper`", "1e300 Hz is above 50000 Hz"],
        ),
        refused(
            "tune.frequency_scales = [1, 1e300]",
            "tune tune_scale_fast.toml --out o",
            &[
                "key `tune.frequency_scales`",
                "1e300 times the 40.0 Hz mode",
                "above 50000 Hz",
            ],
        ),
        Case::line(
            "tune.frequency_scales = [1250] (a 50 kHz shaper, the bound)",
            "tune tune_scale_edge.toml --out o_edge",
            &["o_edge"],
            Expect::answered(&["+mzv@50000.0Hz"]),
        ),
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
            "tune --firmware tmc4361a at 0 microsteps per mm",
            "tune tune_usteps0.toml --firmware tmc4361a --out o",
            &[
                "tune_usteps0.toml:",
                "key `tune.usteps_per_mm`: 0 microsteps per mm: allowed 1 to 1e9",
            ],
        ),
        refused(
            "tune at -100 microsteps per mm on axis x",
            "tune tune_usteps_axis.toml --firmware tmc4361a --out o",
            &["key `tune.axis.x.usteps_per_mm`: -100 microsteps per mm: allowed 1 to 1e9"],
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
            "settle machine on a mode of 1e300 Hz",
            "machine m_fast.toml",
            &[
                "m_fast.toml:3:1: key `axis.x.modes`: axis `x`, mode 0: `frequency_hz` = 1e300",
                "0.01 to 50000 Hz",
            ],
        ),
        refused(
            "settle tune on a frequency_sigma_hz of 1e300 Hz (taken as its band)",
            "tune tune_sigma.toml --out o",
            &[
                "m_sigma.toml:3:1: key `axis.x.modes`",
                "`frequency_sigma_hz` = 1e300",
                "0 <= frequency_sigma_hz < frequency_hz (40.0 Hz here)",
            ],
        ),
        refused(
            "settle gcode --machine with a weight of 1e300",
            "gcode print.gcode --machine m_weight.toml --out o",
            &[
                "m_weight.toml:3:1: key `axis.x.modes`",
                "`weight` = 1e300",
                "0 to 10",
            ],
        ),
        refused(
            "settle sweep on a machine file with a mode of 1e300 Hz",
            "sweep sweep_fast.toml --backend modal --out o",
            &[
                "m_fast.toml:3:1",
                "`frequency_hz` = 1e300",
                "0.01 to 50000 Hz",
            ],
        ),
        refused(
            "a scenario's mode of 1e-300 Hz",
            "sweep slow_inline.toml --backend modal --out o",
            &[
                "slow_inline.toml:3:1: key `machine.modes`",
                "`frequency_hz` = 1e-300",
                "0.01 to 50000 Hz",
            ],
        ),
        refused(
            "a mode swept to 1e6 Hz",
            "sweep swept_fast.toml --backend modal --out o",
            &[
                "key `sweep.machine.modes.0.frequency_hz`",
                "mode 0: `frequency_hz` = 1000000.0",
                "0.01 to 50000 Hz",
            ],
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
