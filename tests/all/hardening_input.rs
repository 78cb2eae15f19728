//! Input errors that name their place and keep their size: a nesting beyond the TOML
//! parser's recursion limit gets a line, a missing key is named itself, a sweep that is too
//! large is refused before its values are made and without printing its count in full,
//! base values a sweep overrides are still checked, long input is not echoed back, and
//! `settle check` reads a baseline whatever its row order or byte-order mark.

use std::path::Path;

use crate::limits::{expand_err, quickstart_with};
use crate::support::{settle, write};

/// The quickstart scenario with its comment lines left out (its first key is `name`).
fn quickstart_keys() -> String {
    quickstart_with("", "")
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn nesting_beyond_the_recursion_limit_names_its_line() {
    let text = quickstart_keys();
    let nested = format!("deep{} = 1\n", ".a".repeat(400));
    let text = text.replacen("[limits]\n", &format!("[limits]\n{nested}"), 1);
    let line = text
        .lines()
        .position(|l| l.starts_with("deep."))
        .expect("there")
        + 1;
    let e = expand_err(&text);
    assert!(e.contains("recursion limit"), "{e}");
    assert!(
        e.starts_with(&format!("s.toml:{line}:")),
        "line {line}: {e}"
    );
    // Arrays nested as deep: the same.
    let text = quickstart_keys().replacen(
        "[limits]\n",
        &format!("[limits]\ndeep = {}1{}\n", "[".repeat(400), "]".repeat(400)),
        1,
    );
    let line = text
        .lines()
        .position(|l| l.starts_with("deep ="))
        .expect("there")
        + 1;
    let e = expand_err(&text);
    assert!(
        e.starts_with(&format!("s.toml:{line}:")),
        "line {line}: {e}"
    );
}

#[test]
fn a_missing_key_is_named_itself() {
    let text = quickstart_keys();
    // Without `name` the first key is `description`: it must not be blamed.
    let e = expand_err(&text.replacen("name = \"quickstart\"\n", "", 1));
    assert!(e.contains("key `name`: missing field `name`"), "{e}");
    let limits = "[limits]\nvmax_mm_s = 300.0      # a common printer travel speed\namax_mm_s2 = 3000.0    # a common printer acceleration\njmax_mm_s3 = 100000.0  # S-curve jerk: 30 ms to reach amax\n";
    assert!(text.contains(limits));
    let e = expand_err(&text.replacen(limits, "", 1));
    assert!(e.contains("key `limits`: missing field `limits`"), "{e}");
    let e = expand_err(&text.replacen("vmax_mm_s = 300.0 ", "", 1));
    assert!(e.contains("key `limits.vmax_mm_s`"), "{e}");
    let e = expand_err(&text.replacen("{ frequency_hz = 40.0, ", "{ ", 1));
    assert!(e.contains("key `machine.modes.frequency_hz`"), "{e}");
}

#[test]
fn a_range_of_too_many_values_is_refused_without_counting_them() {
    let e = expand_err(&quickstart_with(
        "\"move.distance_mm\" = [0.5, 1, 2, 5, 10, 20, 50, 100]",
        "\"move.distance_mm\" = { from = 0.5, to = 100, step = 1e-300 }",
    ));
    assert!(e.contains("key `sweep.move.distance_mm`"), "{e}");
    assert!(e.contains("about 1.0e302 values"), "{e}");
    assert!(e.len() < 300, "{} characters: {e}", e.len());
    // Five axes of 9e6 values, and two of a million: refused at the axis that makes the
    // product too large, before its values are made.
    let axes: String = [
        "move.distance_mm",
        "move.start_mm",
        "limits.vmax_mm_s",
        "limits.amax_mm_s2",
        "limits.jmax_mm_s3",
    ]
    .iter()
    .map(|k| format!("\"{k}\" = {{ from = 1, to = 2, steps = 9000000 }}\n"))
    .collect();
    let e = expand_err(&quickstart_with(
        "\"move.distance_mm\" = [0.5, 1, 2, 5, 10, 20, 50, 100]\n",
        &axes,
    ));
    assert!(
        e.contains("9000000 values") && e.contains("at most 1000000"),
        "{e}"
    );
    let e = expand_err(&quickstart_with(
        "\"move.distance_mm\" = [0.5, 1, 2, 5, 10, 20, 50, 100]",
        "\"move.distance_mm\" = { from = 1, to = 2, steps = 1000000 }\n\"move.start_mm\" = { from = 0, to = 1, steps = 1000000 }",
    ));
    assert!(e.contains("key `sweep.move.start_mm`"), "{e}");
    assert!(e.contains("at most 1 values here"), "{e}");
}

#[test]
fn base_values_are_checked_even_when_a_sweep_overrides_them() {
    for (from, to, key, what) in [
        (
            "distance_mm = 10.0",
            "distance_mm = nan",
            "move.distance_mm",
            "must be 0 or a finite number at least 1e-6 in magnitude (mm), got NaN",
        ),
        (
            "distance_mm = 10.0",
            "distance_mm = 1e308",
            "move.distance_mm",
            "over the limit of 1e8",
        ),
        (
            "vmax_mm_s = 300.0",
            "vmax_mm_s = inf",
            "limits.vmax_mm_s",
            "must be a finite number from 1e-3 to 1e6 (mm/s), got inf",
        ),
    ] {
        let mut text = quickstart_with(from, to);
        if key.starts_with("limits.") {
            text = text.replacen(
                "profile = [\"trapezoid\", \"scurve\"]",
                "profile = [\"trapezoid\", \"scurve\"]\n\"limits.vmax_mm_s\" = [100, 200]",
                1,
            );
        }
        let e = expand_err(&text);
        assert!(
            e.contains(&format!("key `{key}`")) && e.contains(what),
            "{to}: {e}"
        );
        assert!(
            e.contains("the move as written") || !what.contains("limit"),
            "{e}"
        );
    }
}

#[test]
fn long_input_is_not_echoed_back() {
    let long = "y".repeat(10_000_000);
    let e = expand_err(&quickstart_with(
        "profile = \"scurve\"",
        &format!("profile = \"{long}\""),
    ));
    assert!(e.len() < 1_000, "{} characters", e.len());
    assert!(e.contains("(10000000 characters)"), "{e}");
    let e = expand_err(&quickstart_with(
        "profile = [\"trapezoid\", \"scurve\"]",
        &format!("profile = [\"trapezoid\", \"{long}\"]"),
    ));
    assert!(e.len() < 1_000, "{} characters", e.len());
    // A key of 10 MB.
    let e = expand_err(&quickstart_with(
        "[move]\n",
        &format!("[move]\n{long} = 1\n"),
    ));
    assert!(e.len() < 1_000, "{} characters", e.len());
    // `settle plan`: a kind of 10 MB.
    let answer = settle::workflows::plan::answer(&format!(
        r#"{{"p0":[0],"pf":[1],"vmax":[1],"amax":[2],"jmax":[10],"kind":"{long}"}}"#
    ));
    assert!(answer.len() < 1_000, "{} characters", answer.len());
    assert!(answer.contains("unknown kind"), "{answer}");
}

/// An OS error is said once, naming the file.
#[test]
fn os_errors_are_printed_once() {
    let dir = tempfile::tempdir().expect("tmp");
    let s = write(
        dir.path(),
        "s.toml",
        &quickstart_with(
            "modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]",
            "preset = \"gone.toml\"",
        ),
    );
    for args in [
        vec![
            "sweep".to_string(),
            dir.path().join("none.toml").display().to_string(),
        ],
        vec!["sweep".to_string(), s.display().to_string()],
        vec![
            "check".to_string(),
            dir.path().join("none.toml").display().to_string(),
            "--baseline".into(),
            "b.csv".into(),
        ],
    ] {
        let out = settle().args(&args).output().expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.matches("os error 2").count(), 1, "{err}");
        assert_eq!(err.matches("No such file").count(), 1, "{err}");
    }
}

/// A baseline with its rows in another order and a byte-order mark (as an editor may save
/// it) is the same baseline: `settle check` passes.
#[test]
fn check_matches_rows_by_run_and_reads_a_bom() {
    let root = Path::new(crate::support::manifest_dir());
    let scenario = root.join("scenarios/ci_quickstart.toml");
    let committed = std::fs::read_to_string(root.join("results/baselines/ci_quickstart.modal.csv"))
        .expect("committed baseline");
    let mut lines: Vec<&str> = committed.lines().collect();
    let header = lines.remove(0);
    assert!(lines.len() > 2);
    lines.reverse();
    let dir = tempfile::tempdir().expect("tmp");
    let reordered = format!("\u{feff}{header}\n{}\n", lines.join("\n"));
    let baseline = write(dir.path(), "b.csv", &reordered);
    let out = settle()
        .args(["check", &scenario.display().to_string(), "--baseline"])
        .arg(&baseline)
        .args(["--backend", "modal"])
        .output()
        .expect("runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{text}");
    assert!(text.contains("ok:"), "{text}");
}

/// Files saved as UTF-16 (Windows PowerShell 5's `>` writes UTF-16 little-endian with a
/// byte-order mark; ASCII in it is valid UTF-8 byte for byte, a zero byte between the
/// characters) are named as UTF-16 with how to save them as UTF-8, exit 2, by every
/// reader: a real Marlin M503 reply (`settle gcode --config`), the start of the real
/// Benchy (`settle gcode`), the example Klipper recording (`settle identify`) and the
/// example Klipper configuration (`settle import`), each with and without the
/// mark and in both byte orders.
#[test]
fn utf16_files_are_named_with_how_to_save_them_as_utf8() {
    let root = crate::support::root();
    let dir = tempfile::tempdir().expect("tempdir");
    let read = |rel: &str, lines: usize| -> String {
        let text = std::fs::read_to_string(root.join(rel)).expect("reads");
        text.lines().take(lines).map(|l| format!("{l}\n")).collect()
    };
    let benchy = read("gcode/prints/benchy/3DBenchy.gcode", 400);
    let m503 = read(
        "gcode/tests/data/real/marlin/ender3v2neo/m503_20241028.gcode",
        1000,
    );
    let recording = read("examples/data/raw_data_x_example.csv", 2000);
    let cfg = read("examples/klipper/printer.cfg", 1000);
    for (le, bom) in [(true, true), (true, false), (false, true)] {
        let utf16 = |name: &str, text: &str| {
            let units = bom
                .then_some(0xfeff_u16)
                .into_iter()
                .chain(text.encode_utf16());
            let bytes: Vec<u8> = units
                .flat_map(|u| if le { u.to_le_bytes() } else { u.to_be_bytes() })
                .collect();
            let path = dir.path().join(name);
            std::fs::write(&path, bytes).expect("writes");
            path
        };
        let (gcode, reply) = (utf16("job.gcode", &benchy), utf16("m503.txt", &m503));
        let utf8_reply = write(dir.path(), "m503-utf8.txt", &m503);
        let csv = utf16("raw_data_x_1.csv", &recording);
        let printer = utf16("printer.cfg", &cfg);
        let out = dir.path().join("out");
        let runs: [(Vec<std::ffi::OsString>, &Path); 4] = [
            (
                vec![
                    "gcode".into(),
                    gcode.clone().into(),
                    "--out".into(),
                    out.clone().into(),
                ],
                &gcode,
            ),
            (
                vec![
                    "gcode".into(),
                    write(dir.path(), "ok.gcode", &benchy).into(),
                    "--firmware".into(),
                    "marlin".into(),
                    "--config".into(),
                    reply.clone().into(),
                    "--out".into(),
                    out.clone().into(),
                ],
                &reply,
            ),
            (vec!["identify".into(), csv.clone().into()], &csv),
            (
                vec!["import".into(), "klipper".into(), printer.clone().into()],
                &printer,
            ),
        ];
        for (args, named) in runs {
            let mut cmd = settle();
            cmd.args(&args);
            if args[0] == "gcode" {
                cmd.args(["--machine", "printer_xy"]);
            }
            let r = cmd.output().expect("runs");
            let err = String::from_utf8_lossy(&r.stderr);
            assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
            let order = if le {
                "UTF-16 text, little-endian"
            } else {
                "UTF-16 text, big-endian"
            };
            let name = named.file_name().expect("name").to_string_lossy();
            assert!(
                err.contains(&*name) && err.contains(order) && err.contains("save it as UTF-8"),
                "{args:?}: {err}"
            );
            assert!(!out.exists(), "{args:?}");
        }
        // The same reply in UTF-8 is read.
        let r = settle()
            .args([
                "gcode",
                "--machine",
                "printer_xy",
                "--firmware",
                "marlin",
                "--config",
            ])
            .arg(&utf8_reply)
            .arg("--out")
            .arg(&out)
            .arg(write(dir.path(), "ok.gcode", &benchy))
            .output()
            .expect("runs");
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        std::fs::remove_dir_all(&out).expect("removes");
    }
}
