//! `settle import marlin`: a Marlin printer's reply to `M503`, as a terminal saves it,
//! becomes a scenario of its current settings, read by settle-gcode's `MarlinSettings`
//! (gcode/src/config/marlin.rs); `settle tune --firmware marlin` on it writes the winner
//! as Marlin lines.
//!
//! The real reply is an Ender-3 V2 Neo owner's, kept byte for byte with its provenance in
//! gcode/tests/data/real/marlin/PROVENANCE.md; the values asserted are read by hand from
//! that file, with their lines.

use std::path::{Path, PathBuf};

use settle::workflows::import::{ImportOptions, import};
use settle_planner::firmware::Firmware;

use crate::support::{root, run_ok, settle, write};

fn ender() -> PathBuf {
    root().join("gcode/tests/data/real/marlin/ender3v2neo/m503_20241028.gcode")
}

fn opts(config: PathBuf, out: &Path) -> ImportOptions {
    ImportOptions {
        firmware: Firmware::Marlin,
        config,
        machine: None,
        out: Some(out.to_path_buf()),
        force: false,
    }
}

/// The real reply: its M203, M201, M204, M92 and M205 as the baseline.
#[test]
fn the_real_ender_reply_becomes_the_baseline() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("ender.toml");
    let i = import(&opts(ender(), &out)).expect("imports");
    let c = &i.current;
    assert_eq!(c.firmware, Firmware::Marlin);
    // m503_20241028.gcode line 11: `M203 X500.00 Y500.00 Z10.00 E50.00` (mm/s).
    assert_eq!(c.vmax_mm_s, 500.0);
    // Line 15 `M204 P500.00 R5000.00 T500.00` and line 13 `M201 X500.00 Y500.00 ...`
    // (mm/s^2): printing moves at 500.
    assert_eq!(c.amax_mm_s2, 500.0);
    // Line 9: `M92 X80.29 Y80.29 Z399.21 E425.35` (steps per mm, microsteps included);
    // no M593: no shaper.
    for (a, name) in c.axes.iter().zip(["x", "y"]) {
        assert_eq!(a.name, name);
        assert_eq!(a.usteps_per_mm, Some(80.29), "{name}");
        assert_eq!(a.shaper, None, "{name}");
    }
    // Line 17: `M205 B20000.00 S0.00 T0.00 X10.00 Y10.00 Z0.40 E5.00`: classic jerk, a note.
    assert!(
        c.notes
            .iter()
            .any(|n| n.starts_with("M205 X10 Y10 (classic jerk")),
        "{:?}",
        c.notes
    );
    // The Professional firmware's own `C100` (line 49) is noted with its line.
    assert!(
        c.notes
            .iter()
            .any(|n| n.contains("m503_20241028.gcode:49: C100")),
        "{:?}",
        c.notes
    );
    let (sc, _) = settle::load_runs(&out).expect("loads");
    assert_eq!(std::fs::read_to_string(&out).expect("written"), i.scenario);
    assert_eq!(
        sc.current
            .get("limits.amax_mm_s2")
            .and_then(|v| v.as_float()),
        Some(500.0)
    );
    assert_eq!(
        sc.current.get("shaper.type").and_then(|v| v.as_str()),
        Some("none")
    );
    let t = sc.tune.as_ref().expect("[tune]");
    assert_eq!(t.firmware.as_deref(), Some("marlin"));
    let x = &t.axis.as_ref().expect("[tune.axis]")["x"];
    assert_eq!(
        (x.shaper.as_deref(), x.usteps_per_mm),
        (Some("none"), Some(80.29))
    );
    // Line 13 `M201 X500.00 Y500.00 Z100.00 E1000.00`: each axis's cap, for marlin.gcode to
    // raise (so no note asks the owner to raise it by hand).
    for a in ["x", "y"] {
        assert_eq!(
            t.axis.as_ref().expect("[tune.axis]")[a].max_accel_mm_s2,
            Some(500.0),
            "{a}"
        );
    }
    assert!(!c.notes.iter().any(|n| n.contains("M201")), "{:?}", c.notes);
    assert!(
        i.scenario
            .contains("[limits]\nvmax_mm_s = 500.0\namax_mm_s2 = 500.0\n")
    );
}

/// A Marlin 2.1 reply of a junction-deviation build with M593 on X (Y off), and a
/// classic-jerk one, in the real file's OctoPrint format: speed the lower of M203 X and Y,
/// acceleration the lowest of M204 P and M201 X, Y; M593 is Marlin's ZV.
#[test]
fn junction_deviation_and_classic_jerk_replies_map_onto_the_baseline() {
    let dir = tempfile::tempdir().expect("tempdir");
    let jd = write(
        dir.path(),
        "jd.txt",
        "Send: M503\n\
         Recv: echo:; Steps per unit:\n\
         Recv: echo:  M92 X100.00 Y160.00 Z400.00 E93.00\n\
         Recv: echo:; Max feedrates (units/s):\n\
         Recv: echo:  M203 X400.00 Y350.00 Z5.00 E25.00\n\
         Recv: echo:; Max Acceleration (units/s2):\n\
         Recv: echo:  M201 X3000.00 Y2500.00 Z100.00 E5000.00\n\
         Recv: echo:; Acceleration (units/s2) (P<print-accel> R<retract-accel> T<travel-accel>):\n\
         Recv: echo:  M204 P2000.00 R1500.00 T3000.00\n\
         Recv: echo:; Advanced (B<min_segment_time_us> S<min_feedrate> T<min_travel_feedrate> J<junc_dev>):\n\
         Recv: echo:  M205 B20000.00 S0.00 T0.00 J0.013\n\
         Recv: echo:; Input Shaping:\n\
         Recv: echo:  M593 X F40.50 D0.12\n\
         Recv: echo:  M593 Y F0.00 D0.10\n\
         Recv: ok\n",
    );
    let i = import(&opts(jd, &dir.path().join("jd.toml"))).expect("imports");
    let c = &i.current;
    assert_eq!((c.vmax_mm_s, c.amax_mm_s2), (350.0, 2000.0));
    assert_eq!(c.axes[0].shaper, Some(("zv".into(), 40.5, 0.12)));
    assert_eq!(c.axes[1].shaper, None, "F0: off");
    assert_eq!(
        (c.axes[0].usteps_per_mm, c.axes[1].usteps_per_mm),
        (Some(100.0), Some(160.0))
    );
    assert!(
        c.notes
            .iter()
            .any(|n| n.starts_with("M205 J0.013 (junction deviation, mm)")),
        "{:?}",
        c.notes
    );
    let (sc, _) = settle::load_runs(&dir.path().join("jd.toml")).expect("loads");
    assert_eq!(
        sc.current.get("shaper.type").and_then(|v| v.as_str()),
        Some("zv")
    );
    assert_eq!(
        sc.current
            .get("shaper.frequency_hz")
            .and_then(|v| v.as_float()),
        Some(40.5)
    );

    let classic = write(
        dir.path(),
        "classic.txt",
        "Send: M503\n\
         Recv: echo:  M92 X80.00 Y80.00 Z400.00 E93.00\n\
         Recv: echo:  M203 X300.00 Y300.00 Z5.00 E25.00\n\
         Recv: echo:  M201 X1000.00 Y800.00 Z100.00 E5000.00\n\
         Recv: echo:  M204 P1500.00 R1500.00 T1500.00\n\
         Recv: echo:  M205 B20000.00 S0.00 T0.00 X8.00 Y9.00 Z0.40 E5.00\n\
         Recv: ok\n",
    );
    let i = import(&opts(classic, &dir.path().join("classic.toml"))).expect("imports");
    let c = &i.current;
    // M201 Y800 is below M204 P1500: Marlin caps the move there.
    assert_eq!((c.vmax_mm_s, c.amax_mm_s2), (300.0, 800.0));
    assert_eq!(
        (c.axes[0].shaper.clone(), c.axes[1].shaper.clone()),
        (None, None)
    );
    assert!(
        c.notes
            .iter()
            .any(|n| n.starts_with("M205 X8 Y9 (classic jerk")),
        "{:?}",
        c.notes
    );
}

/// A reply without motion settings is no scenario of defaults: exit 2, naming the file
/// (and the line, or the command missing); nothing is written.
#[test]
fn a_reply_without_motion_settings_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("o.toml");
    let cases = [
        (
            "Send: M503\nRecv: echo:; PID settings:\nRecv: echo:  M301 P21.73 I1.54 D76.55\nRecv: ok\n",
            "none.txt:1: not an M503 report",
        ),
        (
            "Recv: echo:  M92 X80.00 Y80.00\nRecv: echo:  M203 X300.00 Y300.00\n",
            "key `M201`: the M503 reply has no M201 line",
        ),
        (
            "Recv: echo:  M203 X300.00 Y300.00\nRecv: echo:  M201 X-500 Y500\n",
            "none.txt:2",
        ),
    ];
    for (text, want) in cases {
        let reply = write(dir.path(), "none.txt", text);
        let r = settle()
            .args(["import", "marlin"])
            .arg(&reply)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(want), "{text}: {err}");
        assert!(!out.exists(), "{text}");
    }
}

/// The cells of the Markdown table rows of `md` whose first two cells are `first`,
/// `second`.
fn row<'a>(md: &'a str, first: &str, second: &str) -> Vec<&'a str> {
    md.lines()
        .filter(|l| l.starts_with('|'))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(str::trim)
                .collect::<Vec<_>>()
        })
        .find(|c| c.len() > 4 && c[0] == first && c[1] == second)
        .unwrap_or_else(|| panic!("no row {first} {second} in\n{md}"))
}

/// M503 reply -> `settle import marlin` -> `settle tune --firmware marlin` -> marlin.gcode,
/// from the command line as an owner runs it: the Marlin lines, read back by settle's
/// G-code reader, carry the winner tune.md recommends per axis, and the acceleration.
#[test]
fn the_real_reply_imports_tunes_and_exports_marlin_lines() {
    use settle_gcode::{Dialect, EventKind, FtShaper, LimitChange, Reader, ReaderOptions};
    use settle_planner::shaper::MarlinShaper;

    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = dir.path().join("ender.toml");
    run_ok(
        settle()
            .args(["import", "marlin"])
            .arg(ender())
            .arg("--out")
            .arg(&scenario),
    );
    // The search cut down to keep the test fast (one move length, three frequency
    // scales, three shapers); the rest as the import wrote it.
    let text = std::fs::read_to_string(&scenario).expect("reads");
    let cut = text
        .replace("distances_mm = [5.0, 20.0]", "distances_mm = [20.0]")
        .replace(
            "frequency_scales = [0.9, 0.95, 1.0, 1.05, 1.1]",
            "frequency_scales = [0.95, 1.0, 1.05]\nshapers = [\"none\", \"marlin:zv\", \"marlin:ei\"]",
        );
    assert_ne!(cut, text, "the import's [tune] as expected");
    std::fs::write(&scenario, cut).expect("writes");
    let out = dir.path().join("tune");
    run_ok(
        settle()
            .arg("tune")
            .arg(&scenario)
            .args(["--firmware", "marlin", "--jobs", "2", "--out"])
            .arg(&out),
    );
    let md = std::fs::read_to_string(out.join("tune.md")).expect("tune.md");
    let g = std::fs::read_to_string(out.join("marlin.gcode")).expect("marlin.gcode");
    // The current settings are the reply's: no shaper at M204 P500.
    assert_eq!(row(&md, "x", "current")[3..5], ["none", "500"], "{md}");
    let events: Vec<_> = Reader::new(g.as_bytes(), ReaderOptions::new(Dialect::Marlin))
        .collect::<Result<_, _>>()
        .expect("settle reads its own export");
    let mut accel = None;
    let mut axes_seen = Vec::new();
    for e in &events {
        match &e.kind {
            EventKind::Limits(LimitChange::FtMotion {
                axes,
                shaper: Some(shaper),
                frequency_hz,
                damping_ratio,
                ..
            }) => {
                let letter = if axes.x { "x" } else { "y" };
                let rec = row(&md, letter, "**recommended**");
                let text = match shaper {
                    FtShaper::None => "none".to_string(),
                    s => {
                        let i = (0..=8u32)
                            .find(|c| FtShaper::from_code(*c) == Some(*s))
                            .expect("a code") as usize;
                        format!(
                            "marlin:{} @ {:.1} Hz (zeta {})",
                            MarlinShaper::ALL[i - 1].name(),
                            frequency_hz.expect("A"),
                            damping_ratio.expect("I")
                        )
                    }
                };
                assert_eq!(rec[3], text, "{letter}\n{g}\n{md}");
                axes_seen.push(letter);
            }
            EventKind::Limits(LimitChange::Accel { .. }) => accel = Some(e.line),
            _ => {}
        }
    }
    assert_eq!(axes_seen, ["x", "y"], "{g}");
    // One acceleration for both axes: the recommended one, above the reply's M201 X500
    // Y500 (line 13) on the stand-in's modes.
    let rec_accel = row(&md, "x", "**recommended**")[4];
    assert_eq!(row(&md, "y", "**recommended**")[4], rec_accel);
    let rec: f64 = rec_accel.parse().expect("a number");
    assert!(rec > 500.0, "{md}");
    assert!(accel.is_some(), "{g}");
    let lines: Vec<&str> = g.lines().filter(|l| !l.starts_with(';')).collect();
    let m201 = format!("M201 X{rec_accel} Y{rec_accel}");
    let m204 = format!("M204 P{rec_accel} T{rec_accel}");
    assert_eq!(
        lines[lines.len() - 2..],
        [m201.as_str(), m204.as_str()],
        "{g}"
    );
    // The printer after the reply's settings and then these lines: Marlin's planner, as
    // settle follows it (M201 and M204 both cap the move), runs at the recommendation.
    // Without M201 it would stay at 500 mm/s^2.
    let sent = dir.path().join("sent.txt");
    let reply = std::fs::read_to_string(ender()).expect("reply");
    std::fs::write(&sent, format!("{reply}{g}")).expect("writes");
    let after = settle_gcode::config::MarlinSettings::read(&sent).expect("reads");
    let p = after.planner;
    let effective_mm_s2 = p
        .print_accel_m_s2
        .min(p.max_accel_m_s2[0])
        .min(p.max_accel_m_s2[1])
        * 1e3;
    assert!(
        (effective_mm_s2 - rec).abs() < 1e-9,
        "{effective_mm_s2}\n{g}"
    );
    let without_m201 = g.replace(&format!("M201 X{rec_accel} Y{rec_accel}\n"), "");
    std::fs::write(&sent, format!("{reply}{without_m201}")).expect("writes");
    let capped = settle_gcode::config::MarlinSettings::read(&sent).expect("reads");
    assert_eq!(capped.planner.max_accel_m_s2[0] * 1e3, 500.0);
}
