//! Answers settle cannot stand behind, refused (exit 2) or said: a G-code file without a
//! move (prose, a system file as a scenario's `[gcode] file`) or a layer range without
//! a working one, a move or dwell of more than an hour, a sample rate under Nyquist (a
//! replay's; a scan's fly axis; a `[gcode]` job's z axis; an axis `[tune] axes` adds; a recording's for Klipper's
//! shaper choice), a ring-down fit of a record that
//! holds no free decay, a move, corner or scan where f64 cannot resolve it, a shaper
//! Klipper refuses in an imported configuration, a mode too slow for the window,
//! two-value keys given three, a fly axis that is none, a clock of 0 Hz, a plan without
//! its start; and unknown G-code words listed as not followed.

use super::params::scenario_with;
use super::sandbox::SECRET;
use super::{Case, Expect, Sandbox, check_all};

/// A G-code scenario whose file is not G-code (a file with a secret in it).
const GCODE_SECRET: &str = r#"name = "gcode_secret"
[machine]
preset = "printer_xy"
driver_model = "linear"
[gcode]
file = "secret.txt"
firmware = "klipper"
[limits]
vmax_mm_s = 100.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.2
sample_rate_hz = 10000
bands_um = [10.0]
"#;

/// A corner scenario whose corner point has three coordinates.
const CORNER3: &str = r#"name = "corner3"
[machine]
preset = "printer_xy"
driver_model = "linear"
[corner]
angle_deg = 90.0
leg_in_mm = 20.0
leg_out_mm = 20.0
corner_mm = [1, 2, 3]
[limits]
vmax_mm_s = 200.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.2
sample_rate_hz = 10000
bands_um = [10.0]
"#;

/// A corner path on two modal axes (no belt travel to keep it in), its corner at `at`.
fn corner_at(at: &str) -> String {
    CORNER3
        .replace(
            "preset = \"printer_xy\"\ndriver_model = \"linear\"",
            "[machine.axis.x]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n[machine.axis.y]\nmodes = [{ frequency_hz = 50.0, damping_ratio = 0.05 }]",
        )
        .replace("corner_mm = [1, 2, 3]", &format!("corner_mm = {at}"))
}

/// Every case of the class.
pub fn cases(sb: &Sandbox) -> Vec<Case> {
    sb.write(
        "prose.gcode",
        "This is a note about my print.\nIt has no G-code in it.\n",
    );
    sb.write(
        "words.gcode",
        "G28\nM83\nG1 X10 Y10 F3000\nG999\nFOO\nhello\nG1 X20 Y10 E1\nG1 X20 Y20 E1\n",
    );
    sb.write("sc_secret.toml", GCODE_SECRET);
    // Motion limits a file sets that no planner can run at, or that its firmware refuses.
    let square = "G1 X20 Y10 E1\nG1 X20 Y20 E1\nG1 X10 Y20 E1\n";
    sb.write(
        "crawl_limit.gcode",
        &format!("M83\nG1 X10 Y10 F3000\nSET_VELOCITY_LIMIT VELOCITY=1e-200\n{square}"),
    );
    sb.write(
        "rrf_crawl.gcode",
        &format!("M83\nG1 X10 Y10 F3000\nM204 P1e-300 T1e-300\n{square}"),
    );
    sb.write(
        "grbl_exponent.nc",
        "G21\n$120=1e300\nM4 S1000\nG1 X10 Y10 F3000\nG1 X20 Y10\nM5\n",
    );
    sb.write(
        "marlin_j.gcode",
        &format!("M83\nG1 X10 Y10 F3000\nM205 J5\n{square}"),
    );
    sb.write(
        "far.toml",
        &scenario_with("distance_mm = 5.0", "distance_mm = 1.0\nstart_mm = 1e15"),
    );
    sb.write(
        "slow_mode.toml",
        &scenario_with(
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }, { frequency_hz = 1e-7, damping_ratio = 0.05 }]",
        ),
    );
    sb.write(
        "long_window.toml",
        &scenario_with("window_s = 0.2", "window_s = 7894.0"),
    );
    sb.write("corner3.toml", CORNER3);
    sb.write("corner_far.toml", &corner_at("[1e15, 0.0]"));
    sb.write(
        "scan_wide.toml",
        &scenario_with(
            "[observe]",
            "[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nwidth_mm = 1e15\n[observe]",
        ),
    );
    sb.write(
        "fly.toml",
        &scenario_with(
            "[observe]",
            "[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nfly_axis = \"bogus\"\n[observe]",
        ),
    );
    sb.write(
        "tmc.toml",
        &(scenario_with("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "")
            + "[tune]\ntmc_clock_hz = 0\n"),
    );
    sb.write(
        "mzvn.cfg",
        "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: 3000\n[stepper_x]\nrotation_distance: 40\nmicrosteps: 16\n[stepper_y]\nrotation_distance: 40\nmicrosteps: 16\n[input_shaper]\nshaper_type_x: mzv(n=1000000,t=0.8)\nshaper_freq_x: 50\n",
    );
    // The example recording (800 Hz) kept one sample in 16: 50 Hz, Nyquist 25 Hz.
    let rec = std::fs::read_to_string(sb.root().join("rec_x.csv")).expect("recording");
    let slow: Vec<&str> = rec
        .lines()
        .enumerate()
        .filter(|(i, l)| l.starts_with('#') || i % 16 == 0)
        .map(|(_, l)| l)
        .collect();
    sb.write("slow_x.csv", &(slow.join("\n") + "\n"));
    // The example recording at about 280 Hz (sample round(k * 800 / 280) kept): Nyquist
    // 140 Hz, above the 135 Hz top of Klipper's resonance test but below the 150 Hz up to
    // which its fit places shapers.
    let data: Vec<&str> = rec.lines().filter(|l| !l.starts_with('#')).collect();
    let mut edge: Vec<&str> = rec.lines().filter(|l| l.starts_with('#')).collect();
    edge.extend(
        (0..)
            .map(|k: usize| (k as f64 * 800.0 / 280.0).round() as usize)
            .take_while(|&j| j < data.len())
            .map(|j| data[j]),
    );
    sb.write("edge_x.csv", &(edge.join("\n") + "\n"));
    // The example recording with every acceleration held at one value: a machine that
    // never moved (or a sensor that read a constant).
    let still: Vec<String> = rec
        .lines()
        .map(|l| match l.split_once(',') {
            Some((t, _)) if !l.starts_with('#') => format!("{t},12.5,-3.25,9807.5"),
            _ => l.to_string(),
        })
        .collect();
    sb.write("still_x.csv", &(still.join("\n") + "\n"));
    // The example recording (800 Hz) with its time stamps 2.5 ms apart from its 2,600th
    // sample on (400 Hz): one file at two rates, each read at the mean rate.
    let mut k = 0usize;
    let mut t_s = 0.0_f64;
    let two_rates: Vec<String> = rec
        .lines()
        .map(|l| match l.split_once(',') {
            Some((t, rest)) if !l.starts_with('#') => {
                let t: f64 = t.parse().expect("time");
                if k == 0 {
                    t_s = t;
                }
                k += 1;
                if k > 1 {
                    t_s += if k <= 2600 { 1.0 / 800.0 } else { 1.0 / 400.0 };
                }
                format!("{t_s:.6},{rest}")
            }
            _ => l.to_string(),
        })
        .collect();
    sb.write("two_rates_x.csv", &(two_rates.join("\n") + "\n"));
    // A processed spectrum of the corpus (rows to 199.9 Hz) cut after its 90 Hz row.
    let corpus = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/identify/tests/corpus/voronpi_resonances_x_20211217_070942.csv"
    );
    let psd = std::fs::read_to_string(corpus).expect("corpus spectrum");
    let cut: Vec<&str> = psd
        .lines()
        .take_while(|l| {
            l.split(',')
                .next()
                .and_then(|f| f.parse::<f64>().ok())
                .is_none_or(|f| f <= 90.0)
        })
        .collect();
    sb.write("cut_x.csv", &(cut.join("\n") + "\n"));
    sb.write(
        "sc_past.toml",
        &GCODE_SECRET.replace("gcode_secret", "gcode_past").replace(
            "file = \"secret.txt\"",
            "file = \"print.gcode\"\nlayers = \"50..60\"",
        ),
    );
    sb.write(
        "dwell.gcode",
        "G28\nG1 X10 Y10 F3000\nG1 X50 Y10 E1\nG4 P1000000000\nG1 X50 Y50 E2\n",
    );
    sb.write("crawl.gcode", "G28\nG1 X10 Y10 F0.0001\nG1 X50 Y10 E1\n");
    sb.write(
        "raster.nc",
        "G21 G90\nM4 S0\nG0 X10 Y10\nG1 X50 Y10 S800 F3000\nM5\n",
    );
    sb.write("grbl_zero.txt", "$100=80\n$110=0\n");
    sb.write(
        "ghz.toml",
        "name = \"ghz\"\n[axis.x]\nmodes = [{ frequency_hz = 1e9, damping_ratio = 0.05 }]\n[axis.y]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n",
    );
    sb.write(
        "circle.gcode",
        "G28\nG1 X10 Y10 F3000\nG2 X10 Y10 I15916 J0 E1 F600000\n",
    );
    sb.write(
        "crawl.cfg",
        "[printer]\nkinematics: cartesian\nmax_velocity: 0.0001\nmax_accel: 3000\n",
    );
    // A scan whose fly axis (y, simulated: the machine has it) rings at 1,500 Hz, and a
    // G-code job whose z axis rings at 3,000 Hz, sampled at 2,000 Hz: Nyquist is 1,000 Hz.
    sb.write(
        "scan_fly_fast.toml",
        &scenario_with(
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
            "[machine.axis.x]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n[machine.axis.y]\nmodes = [{ frequency_hz = 1500.0, damping_ratio = 0.05 }]",
        )
        .replace("distance_mm = 5.0", "distance_mm = 0.5")
        .replace(
            "[observe]",
            "[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nwidth_mm = 10.0\n[observe]",
        ),
    );
    sb.write(
        "scan_fly_seen.toml",
        &std::fs::read_to_string(sb.root().join("scan_fly_fast.toml"))
            .expect("scan")
            .replace("sample_rate_hz = 2000", "sample_rate_hz = 3000"),
    );
    sb.write(
        "gcode_z_fast.toml",
        &GCODE_SECRET
            .replace("gcode_secret", "gcode_z_fast")
            .replace("file = \"secret.txt\"", "file = \"print.gcode\"")
            .replace(
                "preset = \"printer_xy\"\ndriver_model = \"linear\"",
                "[machine.axis.x]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n[machine.axis.y]\nmodes = [{ frequency_hz = 50.0, damping_ratio = 0.05 }]\n[machine.axis.z]\nmodes = [{ frequency_hz = 3000.0, damping_ratio = 0.05 }]",
            )
            .replace("sample_rate_hz = 10000", "sample_rate_hz = 2000"),
    );
    // `[tune] axes` tunes y too, whose 1,500 Hz mode the 2,000 Hz sample rate cannot see.
    sb.write(
        "tune_y_fast.toml",
        &(std::fs::read_to_string(sb.root().join("scan_fly_fast.toml"))
            .expect("scan")
            .replace("[sweep]\nprofile = [\"trapezoid\", \"scurve\"]\n", "")
            .replace(
                "[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nwidth_mm = 10.0\n",
                "",
            )
            + "[tune]\naxes = [\"x\", \"y\"]\ndistances_mm = [0.5]\njerk_steps = 2\n"),
    );
    let refused = |what: &str, line: &str, parts: &[&str]| {
        Case::line(what, line, &[], Expect::refused(parts))
    };
    vec![
        refused(
            "tune of an axis whose mode is above Nyquist",
            "tune tune_y_fast.toml --out o",
            &[
                "tune_y_fast.toml:",
                "key `observe.sample_rate_hz`",
                "(1500.0000 Hz in machine.modes of the axes the run moves: y)",
                "at least 3000.0000 Hz",
            ],
        ),
        refused(
            "a scan sampled under Nyquist of its fly axis's mode",
            "run scan_fly_fast.toml --case 0 --backend modal --out o/t.csv",
            &[
                "scan_fly_fast.toml:",
                "key `observe.sample_rate_hz`",
                "2000 Hz gives fewer than two samples per period of the fastest mode (1500.0000 Hz in machine.modes of the axes the run moves: x, y)",
                "at least 3000.0000 Hz",
            ],
        ),
        Case::line(
            "the same scan at 3000 Hz",
            "run scan_fly_seen.toml --case 0 --backend modal --out o_seen/t.csv",
            &["o_seen"],
            Expect::answered(&["axis y: residual_peak_um"]),
        ),
        refused(
            "[gcode] on a machine whose z mode is above Nyquist",
            "sweep gcode_z_fast.toml --backend modal --out o",
            &[
                "gcode_z_fast.toml:",
                "key `observe.sample_rate_hz`",
                "(3000.0000 Hz in machine.modes of the axes the run moves: x, y, z)",
                "at least 6000.0000 Hz",
            ],
        ),
        refused(
            "gcode on prose",
            "gcode prose.gcode --machine printer_xy --out o",
            &["prose.gcode", "no move"],
        )
        .never_says("This is a note"),
        refused(
            "[gcode] file = a file that is not G-code",
            "sweep sc_secret.toml --backend modal --out o",
            &["gcode.file", "no move"],
        )
        .never_says(SECRET),
        refused(
            "gcode --layers past the file's last layer",
            "gcode print.gcode --machine printer_xy --layers 50..60 --out o",
            &[
                "--layers",
                "layers 50 to 60 hold no working move",
                "on layers 1 to",
            ],
        ),
        refused(
            "[gcode] layers past the file's last layer",
            "sweep sc_past.toml --backend modal --out o",
            &["gcode.layers", "layers 50 to 60 hold no working move"],
        ),
        // A unit mistake that would keep the replay busy for weeks.
        refused(
            "gcode with a dwell of 1e9 ms",
            "gcode dwell.gcode --machine printer_xy --out o",
            &["dwell.gcode:4", "a dwell", "at most 3600 s"],
        ),
        refused(
            "gcode at F0.0001",
            "gcode crawl.gcode --machine printer_xy --out o",
            &["crawl.gcode:2", "0.000100 mm/min", "at most 3600 s"],
        ),
        refused(
            "gcode --config with GRBL's $110=0",
            "gcode raster.nc --firmware grbl --config grbl_zero.txt --machine printer_xy --out o",
            &[
                "grbl_zero.txt:2",
                "key `$110`",
                "$110 = `0`",
                "from 1e-9 to 1e9",
            ],
        ),
        // A 100 m circle at 1 mm: its segments would be held until it ends.
        refused(
            "gcode with an arc of 100,003 segments",
            "gcode circle.gcode --machine printer_xy --out o",
            &[
                "circle.gcode:3",
                "100003 straight segments",
                "at most 100000",
            ],
        ),
        refused(
            "gcode under max_velocity: 0.0001",
            "gcode print.gcode --config crawl.cfg --machine printer_xy --out o",
            &["as planned within", "at most 3600 s"],
        ),
        refused(
            "gcode --sample-rate-hz 1 (under Nyquist)",
            "gcode print.gcode --machine printer_xy --sample-rate-hz 1 --out o",
            &["--sample-rate-hz", "two samples per period"],
        ),
        refused(
            "gcode --sample-rate-hz 1e-9",
            "gcode print.gcode --machine printer_xy --sample-rate-hz 1e-9 --out o",
            &["--sample-rate-hz"],
        ),
        refused(
            "a 1 mm move at 1e15 mm",
            "run far.toml --case 0 --backend modal --out o/t.csv",
            &["move.start_mm", "1e5 mm"],
        ),
        refused(
            "tune --criterion klipper on a recording sampled at 50 Hz",
            "tune --criterion klipper slow_x.csv",
            &[
                "slow_x.csv",
                "sampled at 50.",
                "Nyquist",
                "more than 300 Hz",
            ],
        ),
        refused(
            "tune --criterion klipper on a recording sampled at 280 Hz",
            "tune --criterion klipper edge_x.csv",
            &[
                "edge_x.csv",
                "sampled at 280.",
                "140.1 Hz (Nyquist)",
                "150 Hz up to which Klipper's fit places shapers",
                "more than 300 Hz",
            ],
        ),
        // Klipper's remaining vibration is 0 / 0 there: no "0 %" and no input_shaper.cfg.
        refused(
            "tune --criterion klipper on a recording without vibration",
            "tune --criterion klipper still_x.csv --out o_still",
            &[
                "still_x.csv",
                "no vibration between 10 and 135 Hz",
                "a file of zeros",
            ],
        ),
        refused(
            "identify a recording whose sample rate halves halfway",
            "identify two_rates_x.csv --freq-start 30 --freq-end 90 --hz-per-sec 10 --out o/m.toml",
            &[
                "two_rates_x.csv:2:",
                "% off the recording's mean rate of 533.",
                "split the file where its rate changes",
            ],
        ),
        refused(
            "tune --criterion klipper on a spectrum that ends at 90 Hz",
            "tune --criterion klipper cut_x.csv",
            &["cut_x.csv", "ends at 89.9 Hz", "below the 150 Hz", "200 Hz"],
        ),
        refused(
            "identify a resonance sweep without its test's options",
            "identify rec_x.csv --out o/m.toml",
            &["rec_x.csv", "no clean decay", "--hz-per-sec"],
        ),
        // 1.579e7 samples (the 0.08165 s move and the 7894 s window at 2000 Hz) of 8
        // values: 1.263e8, over 1.6e7, refused before the run starts, nothing written.
        refused(
            "run of a trace too long to keep",
            "run long_window.toml --case 0 --backend modal --out o_long/t.csv --fail-on-failed-runs",
            &[
                "long_window.toml:12:1: key `observe.window_s`",
                "its trace is kept in memory",
                "the 7894 s window at 2000 Hz",
                "1.263e8 values, over the limit of 1.6e7",
                "checked before any run starts",
            ],
        ),
        refused(
            "a corner at 1e15 mm",
            "run corner_far.toml --case 0 --backend modal --out o/t.csv",
            &["corner.corner_mm", "1e5 mm"],
        ),
        refused(
            "a scan 1e15 mm wide",
            "run scan_wide.toml --case 0 --backend modal --out o/t.csv",
            &["scan.width_mm", "1e5 mm"],
        ),
        // No sample rate the replay takes resolves it: the machine is named, not the rate.
        refused(
            "gcode on a machine with a mode of 1e9 Hz",
            "gcode print.gcode --machine ghz.toml --out o",
            &["ghz.toml:3:1", "`frequency_hz` = 1000000000.0", "50000 Hz"],
        ),
        refused(
            "a mode of 1e-7 Hz",
            "sweep slow_mode.toml --backend modal --out o",
            &[
                "machine.modes",
                "mode 1: `frequency_hz` = 1e-7",
                "0.01 to 50000 Hz",
            ],
        ),
        refused(
            "import a shaper Klipper refuses",
            "import klipper mzvn.cfg --out o/x.toml",
            &["mzvn.cfg", "shaper_type_x", "at most 10"],
        ),
        refused(
            "corner_mm = [1, 2, 3]",
            "sweep corner3.toml --backend modal --out o",
            &["corner.corner_mm", "give exactly 2"],
        ),
        refused(
            "scan.fly_axis = \"bogus\"",
            "sweep fly.toml --backend modal --out o",
            &["scan.fly_axis", "bogus"],
        ),
        refused(
            "[tune] tmc_clock_hz = 0",
            "tune tmc.toml --out o",
            &["tune.tmc_clock_hz", "4 to 32 MHz"],
        ),
        Case::line(
            "plan without p0",
            "plan",
            &[],
            Expect::answered(&["`p0` is missing"]),
        )
        .stdin("{\"pf\":[1],\"vmax\":[1],\"amax\":[2],\"jmax\":[10]}\n"),
        // A velocity or acceleration below 1e-9 overflowed the planners (a segment of
        // infinite duration, moves out of time order): refused at its line, in every
        // dialect; a GRBL `$` value GRBL cannot read (its read_float has no exponent).
        refused(
            "gcode with SET_VELOCITY_LIMIT VELOCITY=1e-200",
            "gcode crawl_limit.gcode --machine printer_xy --out o",
            &[
                "crawl_limit.gcode:3",
                "`SET_VELOCITY_LIMIT` parameter VELOCITY = 1e-200",
                "from 1e-9 to 1e9",
            ],
        ),
        refused(
            "gcode --firmware rrf with M204 P1e-300",
            "gcode rrf_crawl.gcode --firmware rrf --machine printer_xy --out o",
            &[
                "rrf_crawl.gcode:3",
                "`M204` parameter P = 1e-300",
                "from 1e-9 to 1e9",
            ],
        ),
        refused(
            "gcode --firmware grbl with $120=1e300",
            "gcode grbl_exponent.nc --firmware grbl --machine printer_xy --out o",
            &["grbl_exponent.nc:2", "`$120`", "error:3"],
        ),
        // Marlin keeps its junction deviation for J outside 0.01-0.3 mm: so does settle,
        // and says so.
        Case::line(
            "gcode --firmware marlin with M205 J5",
            "gcode marlin_j.gcode --firmware marlin --machine printer_xy --out o_j",
            &["o_j"],
            Expect::answered(&["not followed: M205 (1x)"]),
        ),
        Case::line(
            "gcode lists unknown words as not followed",
            "gcode words.gcode --machine printer_xy --out o_words",
            &["o_words"],
            Expect::answered(&["not followed: FOO (1x), G999 (1x), HELLO (1x)"]),
        ),
    ]
}

#[test]
fn no_answer_settle_cannot_stand_behind() {
    let sb = Sandbox::new();
    let cases = cases(&sb);
    check_all(&sb, &cases);
}

/// The residual peak `settle run` prints for `scenario`.
fn residual_peak(dir: &std::path::Path, scenario: &str) -> String {
    let out = crate::support::settle()
        .current_dir(dir)
        .args([
            "run",
            scenario,
            "--case",
            "0",
            "--backend",
            "modal",
            "--out",
        ])
        .arg(format!("o_{scenario}.csv"))
        .output()
        .expect("runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
        .lines()
        .find(|l| l.trim_start().starts_with("residual_peak_um"))
        .unwrap_or_else(|| panic!("no residual in {stdout}"))
        .to_string()
}

/// The position limit is where f64 still resolves a move: a 1 mm move (and a corner) at
/// the edge of the limit has the residual it has at 0 (physics does not depend on where
/// the machine stands), to the last digit printed.
#[test]
fn a_move_at_the_position_limit_has_the_residual_it_has_at_zero() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let moved = |start: &str| {
        scenario_with(
            "distance_mm = 5.0",
            &format!("distance_mm = 1.0\nstart_mm = {start}"),
        )
    };
    crate::support::write(d, "at0.toml", &moved("0.0"));
    crate::support::write(d, "far.toml", &moved("99999.0"));
    crate::support::write(d, "c0.toml", &corner_at("[0.0, 0.0]"));
    crate::support::write(d, "cfar.toml", &corner_at("[99990.0, -99990.0]"));
    let at0 = residual_peak(d, "at0.toml");
    let um: f64 = at0
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .expect("a number");
    assert!(um > 1.0, "a 1 mm move on a 40 Hz mode rings: {at0}");
    assert_eq!(residual_peak(d, "far.toml"), at0);
    assert_eq!(residual_peak(d, "cfar.toml"), residual_peak(d, "c0.toml"));
}
