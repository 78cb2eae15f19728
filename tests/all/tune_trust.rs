//! `settle tune` on the repository's example machine (identified from
//! examples/data/raw_data_*_example.csv) and its own printer.cfg (examples/klipper/: its
//! includes and SAVE_CONFIG block), as its owner runs it: the terminal, tune.md,
//! report.html (in headless Chromium) and klipper.cfg agree; a candidate out of the running
//! says why everywhere; every changed value carries its reason; the identified damping is
//! what the export holds; Klipper's own choice stands next to settle's.

use std::path::{Path, PathBuf};

use settle_gcode::config::KlipperConfig;

use crate::support::html::chromium::{browser, selftest};
use crate::support::{root, run_ok, settle};

/// identify -> import -> tune of the example, in `dir`: the tune's output folder and the
/// terminal's text. `machine`: identify the example recordings (else the stand-in).
fn example(dir: &Path, config: &Path, machine: bool) -> (PathBuf, String) {
    let mut import = settle();
    import.arg("import").arg("klipper").arg(config);
    if machine {
        run_ok(
            settle()
                .arg("identify")
                .arg("examples/data/raw_data_x_example.csv")
                .arg("examples/data/raw_data_y_example.csv")
                .args(crate::support::EXAMPLE_TEST)
                .arg("--out")
                .arg(dir.join("machine.toml")),
        );
        import.arg("--machine").arg(dir.join("machine.toml"));
    }
    run_ok(import.arg("--out").arg(dir.join("printer.toml")));
    let out = dir.join("tune");
    let r = run_ok(
        settle()
            .arg("tune")
            .arg(dir.join("printer.toml"))
            .arg("--out")
            .arg(&out)
            .args(["--jobs", "2"]),
    );
    (out, String::from_utf8(r.stdout).expect("UTF-8"))
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The cells of the Markdown table rows of `md` whose first cell is `first`.
fn rows<'a>(md: &'a str, first: &str) -> Vec<Vec<&'a str>> {
    crate::support::md_rows(md)
        .filter(|c| c[0] == first)
        .collect()
}

/// The `(frequency, damping)` of the strongest mode of `axis` in the machine file.
fn strongest_mode(machine: &Path, axis: &str) -> (f64, f64) {
    let t: toml::Table = read(machine).parse().expect("TOML");
    let modes = t["axis"][axis]["modes"].as_array().expect("modes");
    let m = modes
        .iter()
        .max_by(|a, b| {
            let w = |m: &toml::Value| m["weight"].as_float().unwrap_or(1.0).abs();
            w(a).total_cmp(&w(b))
        })
        .expect("a mode");
    (
        m["frequency_hz"].as_float().expect("f"),
        m["damping_ratio"].as_float().expect("zeta"),
    )
}

#[test]
fn the_example_printer_gets_one_answer_everywhere_with_its_reasons() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = root().join("examples/klipper/printer.cfg");
    let (out, terminal) = example(dir.path(), &config, true);
    let md = read(&out.join("tune.md"));
    assert_eq!(terminal, md, "the terminal prints tune.md");
    let cfg = read(&out.join("klipper.cfg"));

    // Pasted above the SAVE_CONFIG block of the example printer.cfg, Klipper's reading
    // (settle-gcode's, checked against Klipper's own in gcode/tests/gcode/) gives the
    // recommendation of tune.md's head, axis by axis.
    let original = read(&config);
    let at = original.find("#*# <----").expect("SAVE_CONFIG block");
    let pasted = format!("{}{cfg}\n{}", &original[..at], &original[at..]);
    let k = KlipperConfig::parse(&pasted, &config).expect("reads");
    let shaper = k.input_shaper.expect("[input_shaper]");
    for (axis, got) in [("x", &shaper.x), ("y", &shaper.y)] {
        let rec = rows(&md, axis)
            .into_iter()
            .find(|r| r[1] == "**recommended**")
            .expect("recommended row");
        // `zv @ 45.0 Hz (zeta 0.05)`
        let text = format!(
            "{} @ {:.1} Hz (zeta {})",
            got.name, got.frequency_hz, got.damping_ratio
        );
        assert_eq!(rec[3], text, "axis {axis}");
        assert_eq!(rec[4].parse::<f64>().ok(), Some(k.printer.max_accel_mm_s2));
        // The identified damping of the mode the shaper is tuned to, as the export holds it.
        let (f, zeta) = strongest_mode(&dir.path().join("machine.toml"), axis);
        assert_eq!(
            got.damping_ratio,
            (zeta * 1000.0).round() / 1000.0,
            "axis {axis}"
        );
        assert!(
            (got.frequency_hz / f - 1.0).abs() <= 0.11,
            "axis {axis}: {f} Hz mode"
        );
        // SAVE_CONFIG held Klipper's shaper at 7000 mm/s^2, over its own smoothing limit:
        // the current settings are out, and say why.
        let cur = rows(&md, axis)
            .into_iter()
            .find(|r| r[1] == "current")
            .expect("current row");
        assert!(cur[8].starts_with("out: smooths 0."), "{cur:?}");
    }
    // Every changed value: a row of tune.md's table and a comment above it in klipper.cfg.
    let changes = rows(&md, "setting");
    assert!(!changes.is_empty());
    let table = &md[md.find("## What changes in klipper.cfg").expect("changes")..];
    let mut n = 0;
    // Its rows: up to the next section (another export's changes, or the first axis).
    for r in table
        .lines()
        .skip(1)
        .take_while(|l| !l.starts_with("## "))
        .filter(|l| l.starts_with("| ") && !l.starts_with("| setting") && !l.starts_with("|---"))
    {
        let c: Vec<&str> = r.trim_matches('|').split('|').map(str::trim).collect();
        let (key, was, now, why) = (c[0], c[1], c[2], c[3]);
        assert!(!why.is_empty(), "{key}");
        let comment = format!("# {key}: {was} -> {now}: {why}\n{key}: {now}\n");
        assert!(cfg.contains(&comment), "missing\n{comment}in\n{cfg}");
        n += 1;
    }
    assert!(n >= 4, "{table}");
    assert!(cfg.contains("damping_ratio_x: ") && md.contains("| damping_ratio_x | 0.1 |"));

    // Candidates out of the running say why in candidates.csv; each axis has its figure,
    // whose legend names the group out, and Klipper's choice next to settle's.
    let csv = read(&out.join("candidates.csv"));
    let head: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).expect(name);
    let (smooth, status, reason) = (col("smoothing_mm"), col("status"), col("reason"));
    let mut out_rows = 0;
    for line in csv.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        if c[smooth].parse::<f64>().expect("number") > 0.12 {
            assert_eq!(c[status], "out", "{line}");
            assert!(c[reason].starts_with("smooths "), "{line}");
            out_rows += 1;
        }
    }
    assert!(out_rows > 0);
    for axis in ["x", "y"] {
        let section = &md[md.find(&format!("## Axis {axis}")).expect("axis section")..];
        let svg = read(&out.join(format!("pareto-{axis}.svg")));
        assert!(svg.contains("out: over the smoothing limit"), "axis {axis}");
        assert!(
            section.contains("### Klipper's choice on this machine"),
            "axis {axis}"
        );
    }

    // report.html: one section per axis, each with its tables and a drawn Pareto figure,
    // the head's table as tune.md has it, no Markdown left over, numbers rounded.
    let html = read(&out.join("report.html"));
    assert!(!html.contains("###"), "Markdown headings left in the page");
    for table in html.split("<table").skip(1) {
        let body = &table[..table.find("</table>").expect("closed")];
        // The shown text of the cells (a sort key in an attribute is not shown).
        let shown: Vec<&str> = body
            .split('>')
            .filter_map(|t| t.split('<').next())
            .collect();
        let long = shown
            .iter()
            .flat_map(|t| t.split(|c: char| !(c.is_ascii_digit() || c == '.')))
            .find(|t| t.split_once('.').is_some_and(|(_, d)| d.len() > 4));
        assert!(long.is_none(), "unrounded number {long:?} in a table");
    }
    let Some(chrome) = browser() else { return };
    let (res, _) = selftest(&chrome, &out.join("report.html"), "&grid=table-1");
    let sections = res["sections"].as_array().expect("sections");
    let ids: Vec<&str> = sections.iter().filter_map(|s| s["id"].as_str()).collect();
    assert_eq!(ids, ["axis-x", "axis-y", "export"]);
    for s in &sections[..2] {
        assert_eq!(s["figures"], 1, "{s}");
        assert_eq!(s["svgs"], 1, "{s}");
        assert!(s["tables"].as_u64().expect("count") >= 4, "{s}");
    }
    let head_md = rows(&md, "axis");
    assert_eq!(
        res["columns"].as_array().map(|c| c.len()),
        Some(head_md[0].len())
    );
    assert_eq!(res["rows"], 4, "x and y, current and recommended");
}

#[test]
fn a_stand_in_machine_and_a_changed_acceleration_are_said_with_their_reasons() {
    // Without --machine the preset stands in: the terminal, tune.md and klipper.cfg say so.
    let dir = tempfile::tempdir().expect("tempdir");
    let (out, terminal) = example(
        dir.path(),
        &root().join("examples/klipper/printer.cfg"),
        false,
    );
    let warning =
        "These values are for the built-in preset `printer_xy`, which stands in for your printer";
    assert!(terminal.contains(warning), "{terminal}");
    assert!(read(&out.join("klipper.cfg")).contains(&format!("# {warning}")));
    // The search reaches above the current 7000 mm/s^2, up to what the machine allows.
    let scenario = read(&dir.path().join("printer.toml"));
    let accels: Vec<f64> = scenario
        .lines()
        .find_map(|l| l.strip_prefix("accelerations_mm_s2 = ["))
        .expect("accelerations")
        .trim_end_matches(']')
        .split(", ")
        .map(|a| a.parse().expect("number"))
        .collect();
    assert!(accels.iter().any(|a| *a > 7000.0), "{accels:?}");

    // The Voron test configuration (4000 mm/s^2) on the example machine: the shared
    // acceleration moves, and klipper.cfg says from what, to what and why.
    let dir = tempfile::tempdir().expect("tempdir");
    let voron = root().join("gcode/tests/data/klipper/voron/printer.cfg");
    let (out, md) = example(dir.path(), &voron, true);
    let cfg = read(&out.join("klipper.cfg"));
    let now = cfg
        .lines()
        .find_map(|l| l.strip_prefix("max_accel: "))
        .expect("max_accel written");
    assert_ne!(now, "4000");
    let row = rows(&md, "max_accel").pop().expect("a row for max_accel");
    assert_eq!((row[1], row[2]), ("4000", now));
    assert!(
        row[3].contains(&format!("at {now} mm/s^2 against")),
        "{row:?}"
    );
    assert!(
        cfg.contains(&format!(
            "# max_accel: 4000 -> {now}: {}\nmax_accel: {now}\n",
            row[3]
        )),
        "{cfg}"
    );
}
