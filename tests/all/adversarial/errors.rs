//! Errors that name their place and keep to it: an include of a folder names the
//! including file's line, identify's options are named as typed, a machine file that is
//! not TOML is named with its line, and the content of a file that is not what it was
//! said to be (an include of a secret, `/proc/self/environ`, a recording that is not one)
//! is never repeated; import blames what is wrong (a missing machine file, the firmware
//! key of a limit settle cannot run), never the machine; no line 0, no internal names;
//! a byte-order mark read in G-code, printer.cfg and recordings; a journal row of
//! garbage with a valid checksum not counted as a finished run.

use super::sandbox::SECRET;
use super::{Case, Expect, Sandbox, check_all};

/// A Klipper configuration of a cartesian printer with `max_accel: {accel}`.
fn printer_cfg(accel: &str) -> String {
    format!(
        "[printer]\nkinematics: cartesian\nmax_velocity: 300\nmax_accel: {accel}\n[stepper_x]\nrotation_distance: 40\nmicrosteps: 16\n[stepper_y]\nrotation_distance: 40\nmicrosteps: 16\n"
    )
}

/// A sweep folder whose journal holds run 0 with a metric that is no number (and a
/// checksum that matches) and run 1 as it ran: resuming must run 0 again.
fn garbage_journal(sb: &Sandbox) {
    let d = sb.root();
    let done = crate::support::settle()
        .current_dir(d)
        .args(["sweep", "sc.toml", "--backend", "modal", "--out", "j_full"])
        .output()
        .expect("runs");
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let csv = std::fs::read_to_string(d.join("j_full/runs.csv")).expect("runs.csv");
    let mut lines: Vec<String> = csv.split_inclusive('\n').map(str::to_string).collect();
    let header = lines.remove(0);
    let peak = header
        .split(',')
        .position(|h| h == "residual_peak_um")
        .expect("residual_peak_um");
    let mut cells: Vec<String> = lines[0].trim_end().split(',').map(str::to_string).collect();
    cells[peak] = "garbage".to_string();
    let rows = [
        crate::sweep_safety::journal_line(&format!("{}\n", cells.join(","))),
        crate::sweep_safety::journal_line(&lines[1]),
    ];
    std::fs::create_dir_all(d.join("j")).expect("mkdir");
    std::fs::write(
        d.join("j/journal.csv"),
        crate::sweep_safety::journal_of(&d.join("sc.toml"), &header, &rows),
    )
    .expect("journal");
}

/// Every case of the class.
pub fn cases(sb: &Sandbox) -> Vec<Case> {
    garbage_journal(sb);
    sb.write("accel.cfg", &printer_cfg("1e-300"));
    sb.write("huge_accel.cfg", &printer_cfg("1e300"));
    sb.write("plain.cfg", &printer_cfg("3000"));
    sb.write(
        "far.gcode",
        "G28\nM83\nG1 X100000000 Y10 E1 F3000\nG1 X20 Y10 E1\n",
    );
    let bom = |name: &str, from: &str| {
        let text = std::fs::read_to_string(sb.root().join(from)).expect("fixture");
        sb.write(name, &format!("\u{feff}{text}"));
    };
    bom("bom.gcode", "print.gcode");
    bom("bom.cfg", "plain.cfg");
    bom("bom_x.csv", "rec_x.csv");
    sb.write(
        "inc_secret.cfg",
        "[printer]\nmax_velocity: 300\n[include secret.txt]\n",
    );
    sb.write(
        "inc_environ.cfg",
        "[printer]\nmax_velocity: 300\n[include /proc/self/environ]\n",
    );
    let with_config = |what: &str, cfg: &str, parts: &[&str]| {
        Case::new(
            what,
            &[
                "gcode",
                "print.gcode",
                "--machine",
                "printer_xy",
                "--out",
                "o",
                "--config",
                cfg,
            ],
            &[],
            Expect::refused(parts),
        )
    };
    let freq = |v: &str| {
        Case::new(
            &format!("identify --freq-start {v}"),
            &["identify", "rec_x.csv", "--freq-start", v],
            &[],
            Expect::refused(&["--freq-start", "Hz"]),
        )
        .never_says("test.freq_end_hz")
    };
    vec![
        with_config(
            "[include] of a secret is not echoed",
            "inc_secret.cfg",
            &["secret.txt:1", "[section]"],
        )
        .never_says(SECRET),
        with_config(
            "[include /proc/self/environ] is not echoed",
            "inc_environ.cfg",
            &["/proc/self/environ:1"],
        )
        .env("SETTLE_ADVERSARIAL_MARKER", SECRET)
        .never_says(SECRET),
        Case::line(
            "identify on a file that is no recording",
            "identify secret.txt --axis x",
            &[],
            Expect::refused(&["secret.txt:1", "not a recording's header"]),
        )
        .never_says(SECRET),
        Case::line(
            "gcode --machine a file that is not TOML",
            "gcode print.gcode --machine ./secret.txt --out o",
            &[],
            Expect::refused(&["secret.txt:1:"]),
        ),
        freq("0"),
        freq("-5"),
        freq("nan"),
        Case::line(
            "identify --freq-end past Klipper's 300 Hz",
            "identify rec_x.csv --freq-end 400",
            &[],
            Expect::refused(&["--freq-end", "300 Hz"]),
        ),
        Case::line(
            "import with a --machine file that is not there",
            "import klipper plain.cfg --machine missing.toml --out o/x.toml",
            &[],
            Expect::refused(&["cannot read missing.toml"]),
        )
        .never_says("neither an x nor a y axis"),
        Case::line(
            "import of max_accel: 1e-300 names the firmware key",
            "import klipper accel.cfg --out o/x.toml",
            &[],
            Expect::refused(&["accel.cfg", "printer.max_accel"]),
        )
        .never_says("neither an x nor a y axis"),
        Case::line(
            "import of max_accel: 1e300 names the firmware key and its bound",
            "import klipper huge_accel.cfg --out o/x.toml",
            &[],
            Expect::refused(&["huge_accel.cfg", "printer.max_accel", "1000000000"]),
        )
        .never_says("Wrote"),
        Case::line(
            "identify of a band too narrow names no line 0",
            "identify rec_x.csv --freq-start 30 --freq-end 35 --out o/m.toml",
            &[],
            Expect::refused(&["rec_x.csv: the data end after", "frequency bins"]),
        )
        .never_says(":0:"),
        Case::line(
            "a G-code coordinate of 1e8 mm, without internal names",
            "gcode far.gcode --machine printer_xy --out o",
            &[],
            Expect::refused(&["far.gcode:3:4", "parameter X", "1e5 mm"]),
        )
        .never_says("::"),
        Case::line(
            "a G-code file with a byte-order mark",
            "gcode bom.gcode --machine printer_xy --out o_bom",
            &["o_bom"],
            Expect::answered(&["bom.gcode: klipper on printer_xy"]),
        ),
        Case::line(
            "a printer.cfg with a byte-order mark",
            "import klipper bom.cfg --out o_bom_cfg/x.toml",
            &["o_bom_cfg"],
            Expect::answered(&["Wrote o_bom_cfg/x.toml"]),
        ),
        Case::line(
            "a recording with a byte-order mark",
            "identify bom_x.csv --freq-start 30 --freq-end 90 --hz-per-sec 10 --out o_bom_x/m.toml",
            &["o_bom_x"],
            Expect::answered(&["wrote o_bom_x/m.toml"]),
        ),
        Case::line(
            "a journal row of garbage is not a finished run",
            "sweep sc.toml --backend modal --resume --out j",
            &["j"],
            Expect::answered(&[
                "its `residual_peak_um` is not a number; run 0 runs again",
                "resuming: 1 of 2",
            ]),
        ),
        Case::line(
            "a 1e300 mm move names its key without 300 digits",
            "run far300.toml --case 0 --backend modal --out o/t.csv",
            &[],
            Expect::refused(&["move.distance_mm"]),
        ),
    ]
}

#[test]
fn errors_name_their_place_and_never_echo_a_foreign_file() {
    let sb = Sandbox::new();
    sb.write(
        "far300.toml",
        &super::params::scenario_with("distance_mm = 5.0", "distance_mm = 1e300"),
    );
    let cases = cases(&sb);
    check_all(&sb, &cases);
}
