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
//! a G-code replay takes (`settle gcode --shaper`); the motion keys of a move, a corner
//! path, a scan and `settle tune`'s lists just outside their ranges (src/spec/mod.rs),
//! and run at their edges.

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
    let mut cases = motion_cases(sb);
    cases.extend(vec![
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
    ]);
    cases
}

/// A corner path of the printer preset (linear driver, so the modal backend runs it):
/// `legs` (`leg_in_mm = ..\nleg_out_mm = ..`) at 90 degrees.
fn corner(legs: &str) -> String {
    format!(
        "name = \"adv_corner\"\n[machine]\npreset = \"printer_xy\"\ndriver_model = \"linear\"\n[corner]\nangle_deg = 90.0\n{legs}\nprofile = \"scurve\"\n[limits]\nvmax_mm_s = 200.0\namax_mm_s2 = 3000.0\njmax_mm_s3 = 100000.0\n[observe]\nwindow_s = 0.2\nsample_rate_hz = 10000\nbands_um = [10.0]\n"
    )
}

/// The motion keys at the edges of their ranges (src/spec/mod.rs: lengths from 1e-6 mm,
/// speeds 1e-3 to 1e6 mm/s, accelerations 1e-3 to 1e9 mm/s^2, jerks 1e-3 to 1e15 mm/s^3,
/// a scan's margin 0 to 100 s): just outside, refused naming the key (the sweep's when
/// swept) and the range, nothing written; just inside, run and measured.
fn motion_cases(sb: &Sandbox) -> Vec<Case> {
    let mut cases = Vec::new();
    let mut refused = |file: &str, text: String, key: &str, range: &str| {
        sb.write(file, &text);
        cases.push(Case::line(
            &format!("{file}: {key} outside {range}"),
            &format!("sweep {file} --backend modal --out o"),
            &[],
            Expect::refused(&[&format!("{file}:"), &format!("key `{key}`"), range]),
        ));
    };
    let speed = "from 1e-3 to 1e6 (mm/s)";
    let accel = "from 1e-3 to 1e9 (mm/s^2)";
    let jerk = "from 1e-3 to 1e15 (mm/s^3)";
    let length = "at least 1e-6";
    for (line, value, range) in [
        ("vmax_mm_s = 300.0", "vmax_mm_s = 1.1e6", speed),
        ("vmax_mm_s = 300.0", "vmax_mm_s = 9e-4", speed),
        ("amax_mm_s2 = 3000.0", "amax_mm_s2 = 1.1e9", accel),
        ("amax_mm_s2 = 3000.0", "amax_mm_s2 = 9e-4", accel),
        ("jmax_mm_s3 = 100000.0", "jmax_mm_s3 = 1.1e15", jerk),
        ("jmax_mm_s3 = 100000.0", "jmax_mm_s3 = 9e-4", jerk),
        ("distance_mm = 5.0", "distance_mm = 9e-7", length),
        ("distance_mm = 5.0", "distance_mm = -9e-7", length),
    ] {
        let key = value.split(' ').next().unwrap_or_default();
        let table = if key == "distance_mm" {
            "move"
        } else {
            "limits"
        };
        let file = format!("mo_{}.toml", value.replace([' ', '='], ""));
        refused(
            &file,
            scenario_with(line, value),
            &format!("{table}.{key}"),
            range,
        );
    }
    for (sweep, key, range) in [
        (
            "\"limits.amax_mm_s2\" = [3000.0, 1.1e9]",
            "limits.amax_mm_s2",
            accel,
        ),
        (
            "\"limits.jmax_mm_s3\" = [1e5, 9e-4]",
            "limits.jmax_mm_s3",
            jerk,
        ),
        (
            "\"move.distance_mm\" = [5.0, 9e-7]",
            "move.distance_mm",
            length,
        ),
    ] {
        refused(
            &format!("mo_swept_{key}.toml"),
            scenario_with("profile = [\"trapezoid\", \"scurve\"]", sweep),
            &format!("sweep.{key}"),
            range,
        );
    }
    let scan = |more: &str| {
        scenario_with(
            "[observe]",
            &format!("[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nfly_jmax_mm_s3 = 1e6\nwidth_mm = 10.0\nlines = 2\n{more}[observe]"),
        )
        .replace("distance_mm = 5.0", "distance_mm = 0.5")
    };
    let margin = "from 0 to 1e2 (s)";
    for (from, to, range) in [
        ("v_scan_mm_s = 100.0", "v_scan_mm_s = 1.1e6", speed),
        ("v_scan_mm_s = 100.0", "v_scan_mm_s = 9e-4", speed),
        ("fly_amax_mm_s2 = 10000.0", "fly_amax_mm_s2 = 1.1e9", accel),
        ("fly_amax_mm_s2 = 10000.0", "fly_amax_mm_s2 = 9e-4", accel),
        ("fly_jmax_mm_s3 = 1e6", "fly_jmax_mm_s3 = 1.1e15", jerk),
        ("fly_jmax_mm_s3 = 1e6", "fly_jmax_mm_s3 = 9e-4", jerk),
        ("width_mm = 10.0", "width_mm = 9e-7", length),
        ("lines = 2", "lines = 2\nsettle_margin_s = 100.1", margin),
    ] {
        let key = if to.contains("settle_margin_s") {
            "settle_margin_s"
        } else {
            to.split(' ').next().unwrap_or_default()
        };
        refused(
            &format!("mo_scan_{}.toml", to.replace([' ', '=', '\n'], "")),
            scan("").replacen(from, to, 1),
            &format!("scan.{key}"),
            range,
        );
    }
    refused(
        "mo_scan_swept.toml",
        scan("").replacen(
            "profile = [\"trapezoid\", \"scurve\"]",
            "\"scan.v_scan_mm_s\" = [100.0, 1.1e6]",
            1,
        ),
        "sweep.scan.v_scan_mm_s",
        speed,
    );
    for legs in [
        "leg_in_mm = 9e-7\nleg_out_mm = 20.0",
        "leg_in_mm = 20.0\nleg_out_mm = 9e-7",
    ] {
        let key = if legs.starts_with("leg_in_mm = 9") {
            "leg_in_mm"
        } else {
            "leg_out_mm"
        };
        refused(
            &format!("mo_corner_{key}.toml"),
            corner(legs),
            &format!("corner.{key}"),
            length,
        );
    }
    // settle tune's lists and the jerks it searches (jmax / jerk_span), through the same
    // ranges.
    let tune = |table: &str| {
        scenario_with("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "")
            + "[tune]\njerk_steps = 2\nkinds = [\"scurve\"]\n"
            + table
    };
    for (file, table, key, range) in [
        (
            "mo_tune_accel.toml",
            "distances_mm = [5.0]\naccelerations_mm_s2 = [3000.0, 1.1e9]\n",
            "tune.accelerations_mm_s2",
            accel,
        ),
        (
            "mo_tune_distance.toml",
            "distances_mm = [5.0, 9e-7]\n",
            "tune.distances_mm",
            length,
        ),
        (
            "mo_tune_span.toml",
            "distances_mm = [5.0]\njerk_span = 1e9\n",
            "tune.jerk_span",
            jerk,
        ),
    ] {
        sb.write(file, &tune(table));
        cases.push(Case::line(
            &format!("{file}: {key} outside {range}"),
            &format!("tune {file} --out o"),
            &[],
            Expect::refused(&[&format!("{file}:"), &format!("key `{key}`"), range]),
        ));
    }
    // Just inside: each edge runs and prints its measurement.
    let mut answered = |file: &str, case: u32, text: String, parts: &[&str]| {
        sb.write(file, &text);
        let out = format!("o_{}", file.trim_end_matches(".toml"));
        cases.push(Case::line(
            &format!("{file}: the edges of the ranges run"),
            &format!("run {file} --case {case} --backend modal --out {out}/t.csv"),
            &[&out],
            Expect::answered(parts),
        ));
    };
    // 5 mm at the fastest limits: 2 sqrt(d / amax) = 0.141 ms and the jerk phases of 1 us;
    // the 40 Hz mode rings with nearly the whole step.
    answered(
        "mi_fast.toml",
        1,
        scenario_with("vmax_mm_s = 300.0", "vmax_mm_s = 1e6")
            .replace("amax_mm_s2 = 3000.0", "amax_mm_s2 = 1e9")
            .replace("jmax_mm_s3 = 100000.0", "jmax_mm_s3 = 1e15"),
        &[
            "run 1: scurve 5 mm",
            "move_time_s            0.000142",
            "residual_peak_um       4990.1295",
        ],
    );
    // A nanometre step at the slowest limits: (32 d / jmax)^(1/3) = 0.317 s of S-curve.
    answered(
        "mi_slow.toml",
        1,
        scenario_with("distance_mm = 5.0", "distance_mm = -1e-6")
            .replace("vmax_mm_s = 300.0", "vmax_mm_s = 1e-3")
            .replace("amax_mm_s2 = 3000.0", "amax_mm_s2 = 1e-3")
            .replace("jmax_mm_s3 = 100000.0", "jmax_mm_s3 = 1e-3"),
        &[
            "run 1: scurve -0.000001 mm",
            "move_time_s            0.317480",
        ],
    );
    // A scan at the fastest limits; the slowest, with a 1 nm line and a 100 s margin.
    answered(
        "mi_scan_fast.toml",
        1,
        scan("")
            .replace("v_scan_mm_s = 100.0", "v_scan_mm_s = 1e6")
            .replace("fly_amax_mm_s2 = 10000.0", "fly_amax_mm_s2 = 1e9")
            .replace("fly_jmax_mm_s3 = 1e6", "fly_jmax_mm_s3 = 1e15"),
        &["move_time_s            0.059965", "(re-entry) 6.3322 um"],
    );
    answered(
        "mi_scan_slow.toml",
        1,
        scan("settle_margin_s = 100.0\n")
            .replace("v_scan_mm_s = 100.0", "v_scan_mm_s = 1e-3")
            .replace("fly_amax_mm_s2 = 10000.0", "fly_amax_mm_s2 = 1e-3")
            .replace("fly_jmax_mm_s3 = 1e6", "fly_jmax_mm_s3 = 1e-3")
            .replace("width_mm = 10.0", "width_mm = 1e-6"),
        &[
            "move_time_s            105.713143",
            "scan_window_s          100.0542883523319",
        ],
    );
    // Two legs of 1 nm: the corner path is resolved at them.
    answered(
        "mi_corner.toml",
        0,
        corner("leg_in_mm = 1e-6\nleg_out_mm = 1e-6"),
        &[
            "run 0: scurve 0.000002 mm",
            "move_time_s            0.001368",
            "residual_peak_um       0.0014",
        ],
    );
    cases
}

#[test]
fn every_parameter_is_bounded_before_work() {
    let sb = Sandbox::new();
    let cases = cases(&sb);
    check_all(&sb, &cases);
}
