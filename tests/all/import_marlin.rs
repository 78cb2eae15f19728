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
    // Neither M593 nor M493 in the reply: a build without an input shaper, tuned for
    // Marlin's built-in ZV (M593), and said.
    assert_eq!(t.marlin_shaping.as_deref(), Some("input_shaping"));
    assert!(
        c.notes
            .iter()
            .any(|n| n.starts_with("the reply has neither M593 nor M493")),
        "{:?}",
        c.notes
    );
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
    assert_eq!(c.axes[0].shaper, Some(("marlin:m593".into(), 40.5, 0.12)));
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
        Some("marlin:m593")
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
        refused(&write(dir.path(), "none.txt", text), &out, want);
    }
}

/// Values the firmware takes that settle cannot stand behind: a shaper frequency of a
/// GHz, and limits that round to nothing at the millionth of a millimetre settle keeps
/// (they came back as "empty sweep axis" and "got 0", naming no line). Each is refused,
/// exit 2, at its file, line and command.
#[test]
fn implausible_values_are_refused_at_their_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("o.toml");
    let head = "M92 X80 Y80 Z400 E100\nM203 X500 Y500 Z10 E50\nM201 X500 Y500 Z100 E5000\nM204 P500 R500 T500\nM205 B20000 S0 T0 J0.08\n";
    for (last, want) in [
        (
            "M593 X F999999999 D0.1",
            "m.txt:6: key `M593.F`: [M593] F = `999999999`: not allowed (allowed: 0 (off) or 1 to 1000 Hz: below 1 Hz",
        ),
        (
            "M201 X0.0000001",
            "m.txt:6: key `M201`: the printing acceleration",
        ),
        (
            "M204 P0.0000001",
            "m.txt:6: key `M204`: the printing acceleration",
        ),
        (
            "M203 X0.0000001",
            "m.txt:6: key `M203`: the lower of X and Y",
        ),
        // Slow enough that a move of the search outlasts a run: the speed is at fault,
        // not the acceleration the search sweeps (the old error named `M201 / M204 P`
        // at line 4).
        (
            "M203 X0.001",
            "m.txt:6: key `M203`: axis x: settle cannot run these settings: run 0: a move of 20 mm at vmax_mm_s = 0.001",
        ),
    ] {
        refused(
            &write(dir.path(), "m.txt", &format!("{head}{last}\n")),
            &out,
            want,
        );
    }
}

/// The cells of the Markdown table rows of `md` whose first two cells are `first`,
/// `second`.
fn row<'a>(md: &'a str, first: &str, second: &str) -> Vec<&'a str> {
    crate::support::md_rows(md)
        .find(|c| c.len() > 4 && c[0] == first && c[1] == second)
        .unwrap_or_else(|| panic!("no row {first} {second} in\n{md}"))
}

/// The real reply with `lines` added before its closing `ok`, written as `name` in `dir`.
fn ender_with(dir: &Path, name: &str, lines: &str) -> PathBuf {
    let reply = std::fs::read_to_string(ender()).expect("reply");
    let at = reply.rfind("Recv: ok").expect("the reply ends with ok");
    write(
        dir,
        name,
        &format!("{}{lines}{}", &reply[..at], &reply[at..]),
    )
}

/// `settle import marlin reply` then `settle tune --firmware marlin` on the scenario with
/// the search cut down to keep the test fast (one move length, three frequency scales;
/// `shapers`, when given, the shapers searched); the scenario text, tune.md and
/// marlin.gcode.
fn import_and_tune(dir: &Path, reply: &Path, shapers: Option<&str>) -> (String, String, String) {
    let scenario = dir.join("scenario.toml");
    run_ok(
        settle()
            .args(["import", "marlin"])
            .arg(reply)
            .arg("--out")
            .arg(&scenario)
            .arg("--force"),
    );
    let text = std::fs::read_to_string(&scenario).expect("reads");
    let scales = "frequency_scales = [0.95, 1.0, 1.05]";
    let cut = text
        .replace("distances_mm = [5.0, 20.0]", "distances_mm = [20.0]")
        .replace(
            "frequency_scales = [0.9, 0.95, 1.0, 1.05, 1.1]",
            &match shapers {
                Some(list) => format!("{scales}\nshapers = {list}"),
                None => scales.to_string(),
            },
        );
    assert_ne!(cut, text, "the import's [tune] as expected");
    std::fs::write(&scenario, &cut).expect("writes");
    let out = dir.join("tune");
    run_ok(
        settle()
            .arg("tune")
            .arg(&scenario)
            .args(["--firmware", "marlin", "--jobs", "2", "--out"])
            .arg(&out),
    );
    let md = std::fs::read_to_string(out.join("tune.md")).expect("tune.md");
    let g = std::fs::read_to_string(out.join("marlin.gcode")).expect("marlin.gcode");
    (cut, md, g)
}

/// The acceleration Marlin runs printing moves at after `reply` and then `g` are sent
/// (settle's Marlin reader: M204 P capped by M201 X and Y), mm/s^2, and the M593 shapers.
fn after_sending(
    dir: &Path,
    reply: &Path,
    g: &str,
) -> (f64, [Option<settle_gcode::job::ShaperSetting>; 3]) {
    let sent = dir.join("sent.txt");
    let r = std::fs::read_to_string(reply).expect("reply");
    std::fs::write(&sent, format!("{r}{g}")).expect("writes");
    let after = settle_gcode::config::MarlinSettings::read(&sent).expect("reads");
    let p = after.planner;
    let effective = p
        .print_accel_m_s2
        .min(p.max_accel_m_s2[0])
        .min(p.max_accel_m_s2[1])
        * 1e3;
    (effective, after.shapers)
}

/// The recommended acceleration of both axes in tune.md (one for both).
fn recommended_accel(md: &str) -> f64 {
    let rec = row(md, "x", "**recommended**")[4];
    assert_eq!(row(md, "y", "**recommended**")[4], rec, "{md}");
    rec.parse().expect("a number")
}

/// The real reply (no M593, no M493) -> `settle import marlin` -> `settle tune --firmware
/// marlin` -> marlin.gcode, from the command line as an owner runs it: the build's input
/// shaper is Marlin's built-in ZV, so the export is `M593` lines (no `M493`, which this
/// printer could not run); sent after the reply, settle's Marlin reader gives each axis
/// the ZV tune.md recommends, and the recommended acceleration.
#[test]
fn the_real_reply_imports_tunes_and_exports_m593_lines() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (scenario, md, g) = import_and_tune(dir.path(), &ender(), None);
    assert!(
        scenario.contains("marlin_shaping = \"input_shaping\""),
        "{scenario}"
    );
    // The current settings are the reply's: no shaper at M204 P500.
    assert_eq!(row(&md, "x", "current")[3..5], ["none", "500"], "{md}");
    let lines: Vec<&str> = g.lines().filter(|l| !l.starts_with(';')).collect();
    assert!(!g.contains("M493"), "{g}");
    assert_eq!(lines.len(), 4, "{g}");
    assert!(
        lines[0].starts_with("M593 X F") && lines[1].starts_with("M593 Y F"),
        "{g}"
    );
    let rec = recommended_accel(&md);
    assert!(rec > 500.0, "{md}");
    assert_eq!(
        lines[2..],
        [format!("M201 X{rec} Y{rec}"), format!("M204 P{rec} T{rec}")],
        "{g}"
    );
    let (effective, shapers) = after_sending(dir.path(), &ender(), &g);
    assert_eq!(effective, rec, "{g}");
    for (i, letter) in ["x", "y"].into_iter().enumerate() {
        let s = shapers[i].as_ref().expect("shaped");
        let text = format!(
            "{} @ {:.1} Hz (zeta {})",
            s.shaper_type.name(),
            s.frequency_hz,
            s.damping_ratio
        );
        assert_eq!(
            row(&md, letter, "**recommended**")[3],
            text,
            "{letter}\n{g}\n{md}"
        );
        assert!(text.starts_with("marlin:m593 @ "), "{text}");
    }
    assert!(
        md.contains("Marlin (`marlin.gcode`; input shaping, M593)"),
        "{md}"
    );
}

/// A reply with M593 lines (the real reply with the block Marlin's M593_report prints):
/// each axis's current ZV is the baseline, the scenario is for input shaping, and the
/// export's M593 lines replace them.
#[test]
fn a_reply_with_m593_tunes_its_zv_shapers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let reply = ender_with(
        dir.path(),
        "m593.txt",
        "Recv: echo:; Input Shaping:\n\
         Recv: echo:  M593 X F42.50 D0.15\n\
         Recv: echo:  M593 Y F36.00 D0.08\n",
    );
    let i = import(&opts(reply.clone(), &dir.path().join("m593.toml"))).expect("imports");
    let c = &i.current;
    assert_eq!(c.axes[0].shaper, Some(("marlin:m593".into(), 42.5, 0.15)));
    assert_eq!(c.axes[1].shaper, Some(("marlin:m593".into(), 36.0, 0.08)));
    assert!(
        !c.notes.iter().any(|n| n.contains("neither M593 nor M493")),
        "{:?}",
        c.notes
    );
    let (scenario, md, g) = import_and_tune(dir.path(), &reply, None);
    assert!(
        scenario.contains("marlin_shaping = \"input_shaping\""),
        "{scenario}"
    );
    assert_eq!(
        row(&md, "x", "current")[3..5],
        ["marlin:m593 @ 42.5 Hz (zeta 0.15)", "500"],
        "{md}"
    );
    assert!(!g.contains("M493"), "{g}");
    let (effective, shapers) = after_sending(dir.path(), &reply, &g);
    assert_eq!(effective, recommended_accel(&md), "{g}");
    for (i, letter) in ["x", "y"].into_iter().enumerate() {
        let rec = row(&md, letter, "**recommended**")[3];
        match shapers[i].as_ref() {
            Some(s) => assert_eq!(
                rec,
                format!(
                    "{} @ {:.1} Hz (zeta {})",
                    s.shaper_type.name(),
                    s.frequency_hz,
                    s.damping_ratio
                ),
                "{letter}\n{g}"
            ),
            None => assert_eq!(rec, "none", "{letter}\n{g}"),
        }
    }
}

/// A reply with FT_MOTION on (the real reply with M593's block and FT_MOTION's as
/// Marlin's `M593_report` and `M493_report` print them, Marlin/src/gcode/feature/
/// input_shaping/M593.cpp and ft_motion/M493.cpp): the current shapers are FT_MOTION's
/// (ZVD at 37.5 Hz on X, MZV at 44 Hz on Y), not M593's, which `Stepper::isr`
/// (Marlin/src/module/stepper.cpp) does not run while FT_MOTION is on (the old import
/// took M593's 42.5 and 36 Hz ZV); the scenario is for Fixed-Time Motion and
/// marlin.gcode writes `M493` lines, read back by settle's G-code reader as the winner
/// tune.md recommends per axis, and the acceleration.
#[test]
fn a_reply_with_m493_keeps_the_fixed_time_motion_export() {
    use settle_gcode::{Dialect, EventKind, FtShaper, LimitChange, Reader, ReaderOptions};
    use settle_planner::shaper::MarlinShaper;

    let dir = tempfile::tempdir().expect("tempdir");
    let m593 = "Recv: echo:; Input Shaping:\n\
                Recv: echo:  M593 X F42.50 D0.15\n\
                Recv: echo:  M593 Y F36.00 D0.08\n\
                Recv: echo:; Fixed-Time Motion:\n";
    let reply = ender_with(
        dir.path(),
        "m493.txt",
        &format!(
            "{m593}Recv: echo:  M493 S1 D0 H0\n\
             Recv: echo:  M493 X C2 A37.50 F0.00 I0.10 Q0.05\n\
             Recv: echo:  M493 Y C8 A44.00 F0.00 I0.12 Q0.05\n"
        ),
    );
    let i = import(&opts(reply.clone(), &dir.path().join("m493.toml"))).expect("imports");
    let c = &i.current;
    assert_eq!(c.axes[0].shaper, Some(("marlin:zvd".into(), 37.5, 0.1)));
    assert_eq!(c.axes[1].shaper, Some(("marlin:mzv".into(), 44.0, 0.12)));
    assert!(
        c.notes
            .iter()
            .any(|n| n.contains("m493.txt:68: M593: not in force, FT_MOTION is on")),
        "{:?}",
        c.notes
    );
    // An older report's single M493 line with FT_MOTION on does not say which shaper
    // runs: refused at its line, nothing written.
    let older = ender_with(
        dir.path(),
        "older.txt",
        &format!("{m593}Recv: echo:  M493 S1 A37.00 B37.00 D0 F0.00 H0.00 P0 K0.00\n"),
    );
    refused(
        &older,
        &dir.path().join("older.toml"),
        "older.txt:70: key `M493.S`",
    );
    let (scenario, md, g) = import_and_tune(
        dir.path(),
        &reply,
        Some("[\"none\", \"marlin:zv\", \"marlin:ei\"]"),
    );
    assert!(
        scenario.contains("marlin_shaping = \"ft_motion\""),
        "{scenario}"
    );
    assert_eq!(
        row(&md, "x", "current")[3..5],
        ["marlin:zvd @ 37.5 Hz (zeta 0.1)", "500"],
        "{md}"
    );
    assert_eq!(
        row(&md, "y", "current")[3],
        "marlin:mzv @ 44.0 Hz (zeta 0.12)",
        "{md}"
    );
    assert!(!g.lines().any(|l| l.starts_with("M593")), "{g}");
    let events: Vec<_> = Reader::new(g.as_bytes(), ReaderOptions::new(Dialect::Marlin))
        .collect::<Result<_, _>>()
        .expect("settle reads its own export");
    let mut axes_seen = Vec::new();
    for e in &events {
        if let EventKind::Limits(LimitChange::FtMotion {
            axes,
            shaper: Some(shaper),
            frequency_hz,
            damping_ratio,
            ..
        }) = &e.kind
        {
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
    }
    assert_eq!(axes_seen, ["x", "y"], "{g}");
    let rec = recommended_accel(&md);
    assert!(rec > 500.0, "{md}");
    let lines: Vec<&str> = g.lines().filter(|l| !l.starts_with(';')).collect();
    assert_eq!(
        lines[lines.len() - 2..],
        [format!("M201 X{rec} Y{rec}"), format!("M204 P{rec} T{rec}")],
        "{g}"
    );
    // Marlin's planner, as settle follows it (M201 and M204 both cap the move), runs at
    // the recommendation; without M201 it would stay at the reply's 500 mm/s^2 (line 13).
    let (effective, _) = after_sending(dir.path(), &reply, &g);
    assert_eq!(effective, rec, "{g}");
    let without_m201 = g.replace(&format!("M201 X{rec} Y{rec}\n"), "");
    let (capped, _) = after_sending(dir.path(), &reply, &without_m201);
    assert_eq!(capped, 500.0);
}

/// A `[tune] marlin_shaping` that is neither Marlin shaper: exit 2, naming the file, the
/// key and the values allowed.
#[test]
fn an_unknown_marlin_shaping_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scenario = dir.path().join("ender.toml");
    run_ok(
        settle()
            .args(["import", "marlin"])
            .arg(ender())
            .arg("--out")
            .arg(&scenario),
    );
    let text = std::fs::read_to_string(&scenario).expect("reads");
    let bad = text.replace(
        "marlin_shaping = \"input_shaping\"",
        "marlin_shaping = \"zv_shaping\"",
    );
    assert_ne!(bad, text);
    std::fs::write(&scenario, bad).expect("writes");
    let r = settle()
        .arg("tune")
        .arg(&scenario)
        .args(["--firmware", "marlin", "--out"])
        .arg(dir.path().join("tune"))
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    for want in [
        "ender.toml",
        "tune.marlin_shaping",
        "unknown Marlin shaping `zv_shaping`; allowed: ft_motion, input_shaping",
    ] {
        assert!(err.contains(want), "{want}: {err}");
    }
    assert!(!dir.path().join("tune").exists());
}

/// `settle import marlin REPLY --out OUT` exits 2 with `want` in its error and writes
/// nothing.
fn refused(reply: &std::path::Path, out: &std::path::Path, want: &str) {
    let r = settle()
        .args(["import", "marlin"])
        .arg(reply)
        .arg("--out")
        .arg(out)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&r.stderr);
    let what = reply.display();
    assert_eq!(r.status.code(), Some(2), "{what}: {err}");
    assert!(err.contains(want), "{what}: {err}");
    assert!(!out.exists(), "{what}");
}

/// `settle import prusa`: a Prusa-Firmware-Buddy log (`M115`, `M503`, `M593`; the file
/// written in Buddy's formats, gcode/tests/data/prusa/README.md) becomes a scenario whose
/// baseline is the printer's own shapers and limits, tuned for `prusa.gcode`.
#[test]
fn a_prusa_log_imports_its_shapers_as_the_baseline() {
    let dir = tempfile::tempdir().expect("tempdir");
    let log = root().join("gcode/tests/data/prusa/mk4s_m115_m503_m593.txt");
    let out = dir.path().join("mk4s.toml");
    let r = run_ok(
        settle()
            .args(["import", "prusa"])
            .arg(&log)
            .arg("--out")
            .arg(&out),
    );
    let r = String::from_utf8_lossy(&r.stdout).to_string();
    assert!(
        r.contains("current x: mzv @ 50.700001 Hz (zeta 0.1), 4000 mm/s^2, 300 mm/s"),
        "{r}"
    );
    assert!(
        r.contains("current y: mzv @ 40.599998 Hz (zeta 0.1), 4000 mm/s^2, 300 mm/s"),
        "{r}"
    );
    let toml = std::fs::read_to_string(&out).expect("scenario");
    for want in [
        "[tune]\nfirmware = \"prusa\"\n",
        "[tune.axis.x]\nshaper = \"mzv\"\nfrequency_hz = 50.700001\ndamping_ratio = 0.1\nmax_accel_mm_s2 = 4000.0",
        "[tune.axis.y]\nshaper = \"mzv\"\nfrequency_hz = 40.599998\n",
        "the printer is a Prusa MK4S (M115's MACHINE_TYPE)",
        "with prusa.gcode",
    ] {
        assert!(toml.contains(want), "{want}\n{toml}");
    }
    // Buddy's M503 does not report its shapers: a log without the M593 reply is refused.
    let text = std::fs::read_to_string(&log).expect("log");
    let bare: String = text
        .lines()
        .filter(|l| !l.contains("axis"))
        .map(|l| format!("{l}\n"))
        .collect();
    let no_m593 = write(dir.path(), "no_m593.txt", &bare);
    let refused_out = dir.path().join("refused.toml");
    let r = settle()
        .args(["import", "prusa"])
        .arg(&no_m593)
        .arg("--out")
        .arg(&refused_out)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("no_m593.txt:1: no M593 reply for X and Y"),
        "{err}"
    );
    assert!(!refused_out.exists());
}
