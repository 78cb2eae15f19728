//! summary.md and report.html rank every swept setting: the committed scenarios
//! `shaper_current.toml` (one profile, shaper type x frequency, a `[current]` candidate) and
//! `corner_shapers.toml` (corner strategy x shaper), swept through the binary on the modal
//! backend. Every number asserted is recomputed from the runs.csv of the same sweep; the
//! report is opened in headless Chromium. Also: `[current]` errors, and `--force`.

use std::path::{Path, PathBuf};

use settle::input::runs_table::RunsTable;

use crate::support::html::chromium::{
    Rect, browser, console_clean, region_spread, selftest, visit,
};
use crate::support::{run_ok, settle, write};

/// Sweep `scenario` on the modal backend into a new folder; the folder.
fn sweep(scenario: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    run_ok(
        settle()
            .args([
                "sweep",
                scenario,
                "--backend",
                "modal",
                "--jobs",
                "2",
                "--out",
            ])
            .arg(dir.path()),
    );
    dir
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The rows of the Markdown table under heading `heading` (header first), cells trimmed.
fn md_table(md: &str, heading: &str) -> Vec<Vec<String>> {
    let start = md
        .find(heading)
        .unwrap_or_else(|| panic!("no `{heading}` in\n{md}"));
    md[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .filter(|l| !l.starts_with("|---"))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

/// The cell of `row` in the column named `name` of a table whose first row is the header.
fn cell<'a>(t: &'a [Vec<String>], row: usize, name: &str) -> &'a str {
    let j = t[0]
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", t[0]));
    &t[row][j]
}

/// `reference / t - 1` as the summary shows it.
fn gain_text(g: f64) -> String {
    if (g * 100.0).abs() < 10.0 {
        format!("{:+.1} %", g * 100.0)
    } else {
        format!("{:+.0} %", g * 100.0)
    }
}

#[test]
fn a_shaper_sweep_of_one_profile_ranks_the_shapers_against_current() {
    let dir = sweep("scenarios/shaper_current.toml");
    let runs = RunsTable::parse(&read(dir.path(), "runs.csv")).expect("runs.csv");
    let summary = read(dir.path(), "summary.md");
    let n = runs.rows.len();
    assert_eq!(n, 8, "4 shaper types x 2 frequencies");
    // From runs.csv: the current run (mzv at 36 Hz) and the expected order (by time, ties
    // by run number).
    let total = |i: usize| runs.num(i, "move_and_settle_s_10um").expect("total");
    let current = (0..n)
        .find(|&i| {
            runs.cell(i, "shaper_type") == Some("mzv")
                && runs.num(i, "shaper_frequency_hz") == Some(36.0)
        })
        .expect("the current run");
    // No shaper has no frequency: `none` at 40 Hz (run 1) is `none` at 36 Hz (run 0),
    // ranked once.
    assert_eq!(
        (
            runs.cell(1, "shaper_type"),
            runs.num(1, "shaper_frequency_hz")
        ),
        (Some("none"), Some(40.0))
    );
    for c in ["move_and_settle_s_10um", "residual_peak_um"] {
        assert_eq!(runs.num(0, c), runs.num(1, c), "{c}: the same move");
    }
    let mut order: Vec<usize> = (0..n).filter(|&i| i != 1).collect();
    order.sort_by(|&a, &b| total(a).total_cmp(&total(b)).then(a.cmp(&b)));
    assert!(
        summary.contains(
            "Ranked once: 1 run(s) repeat another run of their point in every setting that changes them (`shaper.frequency_hz`: no shaper (`none`) has a frequency or damping ratio)"
        ) && summary.contains("(run 1 repeats run 0)."),
        "{summary}"
    );

    let t = md_table(&summary, "## Ranking: move and settle to within 10 um");
    assert_eq!(t.len(), n, "one row per run but the repeat");
    assert_eq!(
        t[0][1], "shaper.type",
        "the shapers are compared: {:?}",
        t[0]
    );
    assert_eq!(t[0][2], "shaper.frequency_hz");
    for (k, &i) in order.iter().enumerate() {
        let row = k + 1;
        let id = runs.run_id(i).expect("run id");
        assert_eq!(cell(&t, row, "run"), id.to_string(), "rank {row}");
        let rank = if i == current {
            format!("{row} (current)")
        } else {
            row.to_string()
        };
        assert_eq!(cell(&t, row, "rank"), rank);
        assert_eq!(
            cell(&t, row, "shaper.type"),
            runs.cell(i, "shaper_type").expect("type")
        );
        let frequency = match runs.cell(i, "shaper_type") {
            Some("none") => "-".to_string(),
            _ => runs.cell(i, "shaper_frequency_hz").expect("f").to_string(),
        };
        assert_eq!(cell(&t, row, "shaper.frequency_hz"), frequency, "run {id}");
        let shown_total = format!("{:.1}", total(i) * 1e3);
        assert_eq!(
            cell(&t, row, "total").trim_matches('*'),
            shown_total,
            "run {id}"
        );
        assert_eq!(
            cell(&t, row, "gain vs current"),
            gain_text(total(current) / total(i) - 1.0),
            "run {id}"
        );
        assert_eq!(
            cell(&t, row, "smoothing (mm)"),
            format!("{:.3}", runs.num(i, "smoothing_mm").expect("smoothing"))
        );
        assert_eq!(
            cell(&t, row, "remaining vibration (%)"),
            format!(
                "{:.1}",
                runs.num(i, "remaining_vibration_pct")
                    .expect("remaining vibration")
            )
        );
        assert_eq!(
            cell(&t, row, "command"),
            format!("`settle run scenarios/shaper_current.toml --case {id} --backend modal`")
        );
    }
    // The winner of the band, against current.
    let w = order[0];
    let winner = format!(
        "- within 10 um: **{}, frequency_hz={}**, {:.1} ms; {} vs current (mzv, frequency_hz=36, {:.1} ms)",
        runs.cell(w, "shaper_type").expect("type"),
        runs.num(w, "shaper_frequency_hz").expect("frequency"),
        total(w) * 1e3,
        gain_text(total(current) / total(w) - 1.0),
        total(current) * 1e3
    );
    assert!(summary.contains(&winner), "{winner}\nnot in\n{summary}");
    assert!(!summary.contains("vs slowest"), "a current is given");
}

#[test]
fn a_corner_sweep_shows_the_strategy_and_the_shaper_of_every_run() {
    let dir = sweep("scenarios/corner_shapers.toml");
    let runs = RunsTable::parse(&read(dir.path(), "runs.csv")).expect("runs.csv");
    let summary = read(dir.path(), "summary.md");
    let t = md_table(&summary, "## Corners: speed, rounding and contour error");
    assert_eq!(t.len(), runs.rows.len() + 1);
    let mut seen = Vec::new();
    for row in 1..t.len() {
        let id: usize = cell(&t, row, "run").parse().expect("run number");
        let i = (0..runs.rows.len())
            .find(|&i| runs.run_id(i) == Some(id))
            .expect("row of the run");
        let shaper = match runs.cell(i, "shaper_type").expect("shaper") {
            "none" => "none".to_string(),
            ty => format!(
                "{ty} {} Hz",
                runs.cell(i, "shaper_frequency_hz").expect("frequency")
            ),
        };
        let strategy = runs.cell(i, "corner_strategy").expect("strategy");
        assert_eq!(cell(&t, row, "strategy"), strategy);
        assert_eq!(cell(&t, row, "shaper"), shaper);
        assert_eq!(
            cell(&t, row, "corner speed (mm/s)"),
            format!("{:.2}", runs.num(i, "corner_speed_mm_s").expect("speed"))
        );
        seen.push((strategy.to_string(), shaper));
    }
    seen.sort();
    seen.dedup();
    assert_eq!(
        seen.len(),
        4,
        "every strategy with and without the shaper: {seen:?}"
    );
    // The ranking compares both, slowest as the reference (no current given).
    let r = md_table(&summary, "## Ranking: move and settle to within 50 um");
    assert_eq!(&r[0][1..3], ["corner.strategy", "shaper.type"]);
    assert!(r[0].contains(&"gain vs slowest (no current given)".to_string()));
}

#[test]
fn current_takes_only_swept_keys_and_swept_values() {
    let dir = tempfile::tempdir().expect("tempdir");
    let base =
        std::fs::read_to_string(crate::support::root().join("scenarios/shaper_current.toml"))
            .expect("scenario");
    for (current, expect) in [
        (
            "\"shaper.frequency_hz\" = 38.0\n",
            "38.0 is not among the swept values of `shaper.frequency_hz`; allowed: 36, 40",
        ),
        (
            "profile = \"scurve\"\n",
            "`profile` is not swept; [current] takes the swept keys: `shaper.type`, `shaper.frequency_hz`",
        ),
    ] {
        let text = base.replace("\"shaper.frequency_hz\" = 36.0\n", current);
        let path = write(dir.path(), "current.toml", &text);
        let line = text
            .lines()
            .position(|l| l == current.trim_end())
            .expect("line")
            + 1;
        let out = settle()
            .args(["sweep", "--backend", "modal", "--out"])
            .arg(dir.path().join("out"))
            .arg(&path)
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{err}");
        assert!(
            err.contains(&format!("{}:{line}", path.display())),
            "file and line {line}: {err}"
        );
        assert!(err.contains("current."), "the key: {err}");
    }
}

#[test]
fn a_sweep_refuses_to_overwrite_results_without_force() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out: PathBuf = dir.path().join("out");
    let run = |extra: &[&str]| {
        settle()
            .args([
                "sweep",
                "scenarios/ci_quickstart.toml",
                "--backend",
                "modal",
            ])
            .args(extra)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("runs")
    };
    assert!(run(&[]).status.success());
    let before = std::fs::read(out.join("runs.csv")).expect("runs.csv");
    let again = run(&[]);
    assert_eq!(again.status.code(), Some(2));
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(
        err.contains("already holds the results of a sweep: pass --force to overwrite it"),
        "{err}"
    );
    let forced = run(&["--force"]);
    assert!(
        forced.status.success(),
        "{}",
        String::from_utf8_lossy(&forced.stderr)
    );
    assert_eq!(
        std::fs::read(out.join("runs.csv")).expect("runs.csv"),
        before
    );
}

#[test]
fn the_sweep_report_renders_and_sorts_in_chromium() {
    let dir = sweep("scenarios/shaper_current.toml");
    let page = dir.path().join("report.html");
    let html = read(dir.path(), "report.html");
    assert!(html.contains("settle sweep scenarios/shaper_current.toml --backend modal"));
    assert!(
        html.contains("[current]"),
        "the scenario text is in the provenance"
    );
    let Some(chrome) = browser() else { return };
    let runs = RunsTable::parse(&read(dir.path(), "runs.csv")).expect("runs.csv");
    // The first ranking table (10 um; tables are numbered from 1), sorted by its run
    // column: every run but run 1 (no shaper at 40 Hz, the same move as at 36 Hz: ranked
    // once).
    let (res, _) = selftest(&chrome, &page, "&grid=table-1&col=run");
    let mut ids: Vec<usize> = (0..runs.rows.len())
        .map(|i| runs.run_id(i).expect("id"))
        .filter(|&id| id != 1)
        .collect();
    ids.sort_unstable();
    let asc: Vec<String> = ids.iter().map(usize::to_string).collect();
    let desc: Vec<String> = ids.iter().rev().map(usize::to_string).collect();
    assert_eq!(res["asc"], serde_json::json!(asc), "{res}");
    assert_eq!(res["desc"], serde_json::json!(desc), "{res}");
    assert_eq!(res["rows"], runs.rows.len() - 1);
    assert!(html.contains("run 1 repeats run 0"), "the table says why");
    // Every run, sorted by move-and-settle (numbers as numbers).
    let (all, _) = selftest(&chrome, &page, "&col=move_and_settle_s_10um");
    let j = runs.column("move_and_settle_s_10um").expect("column");
    let mut cells: Vec<&str> = runs.rows.iter().map(|r| r[j].as_str()).collect();
    cells.sort_by(|a, b| {
        let (x, y): (f64, f64) = (a.parse().expect("number"), b.parse().expect("number"));
        x.total_cmp(&y)
    });
    assert_eq!(all["asc"], serde_json::json!(cells), "{all}");
    // A screenshot: the runs table is drawn, not blank.
    let shot = dir.path().join("shot.png");
    let v = visit(
        &chrome,
        &page,
        "",
        &[&format!("--screenshot={}", shot.display())],
    );
    console_clean(&v).expect("no console messages");
    let img = image::open(&shot).expect("screenshot PNG").to_rgba8();
    let table = Rect::from_json(&res["rects"]["table"]).expect("table box");
    let (spread, share) = region_spread(&img, table);
    assert!(share > 0.3, "the table is off screen: {table:?}");
    assert!(spread > 20.0, "the table looks blank: {spread:.1}");
}

/// `x / reference - 1` as the G-code table shows it.
fn change_text(x: f64) -> String {
    gain_text(x)
}

#[test]
fn a_gcode_sweep_ranks_firmware_shaper_and_limits_by_contour_error() {
    let dir = sweep("scenarios/gcode_cube.toml");
    let runs = RunsTable::parse(&read(dir.path(), "runs.csv")).expect("runs.csv");
    let summary = read(dir.path(), "summary.md");
    let n = runs.rows.len();
    assert_eq!(n, 16, "4 firmwares x 2 shapers x 2 accelerations");
    let num = |i: usize, c: &str| runs.num(i, c).unwrap_or_else(|| panic!("{c} of row {i}"));
    let (time, worst) = (
        |i: usize| num(i, "print_time_s"),
        |i: usize| num(i, "contour_worst_um"),
    );
    // From runs.csv: the order (worst error, then print time, then run number), the
    // current run (klipper, no shaper, 3000 mm/s^2) and the Pareto front.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        worst(a)
            .total_cmp(&worst(b))
            .then(time(a).total_cmp(&time(b)))
            .then(a.cmp(&b))
    });
    let current = (0..n)
        .find(|&i| {
            runs.cell(i, "firmware") == Some("klipper")
                && runs.cell(i, "shaper_type") == Some("none")
                && runs.num(i, "amax_mm_s2") == Some(3000.0)
        })
        .expect("the current run");
    let on_front = |i: usize| {
        !(0..n).any(|k| {
            time(k) <= time(i) && worst(k) <= worst(i) && (time(k) < time(i) || worst(k) < worst(i))
        })
    };
    let t = md_table(
        &summary,
        "## G-code jobs: print time and contour error (cube_layer.gcode)",
    );
    assert_eq!(t.len(), n + 1, "one row per run: {t:?}");
    assert_eq!(
        &t[0][1..4],
        ["gcode.firmware", "shaper.type", "limits.amax_mm_s2"]
    );
    let fronts = order.iter().filter(|&&i| on_front(i)).count();
    assert!(fronts >= 2, "a trade-off between time and error: {fronts}");
    for (k, &i) in order.iter().enumerate() {
        let row = k + 1;
        let id = runs.run_id(i).expect("id");
        assert_eq!(cell(&t, row, "run"), id.to_string(), "rank {row}");
        let rank = if i == current {
            format!("{row} (current)")
        } else {
            row.to_string()
        };
        assert_eq!(cell(&t, row, "rank"), rank);
        assert_eq!(
            cell(&t, row, "gcode.firmware"),
            runs.cell(i, "firmware").expect("firmware")
        );
        assert_eq!(
            cell(&t, row, "shaper.type"),
            runs.cell(i, "shaper_type").expect("shaper")
        );
        assert_eq!(cell(&t, row, "print time (s)"), format!("{:.2}", time(i)));
        assert_eq!(
            cell(&t, row, "worst (um)").trim_matches('*'),
            format!("{:.2}", worst(i))
        );
        assert_eq!(
            cell(&t, row, "p95 (um)"),
            format!("{:.2}", num(i, "contour_p95_um"))
        );
        assert_eq!(
            cell(&t, row, "worst line"),
            format!("{}", num(i, "contour_worst_line"))
        );
        assert_eq!(
            cell(&t, row, "time vs current"),
            change_text(time(i) / time(current) - 1.0),
            "run {id}"
        );
        assert_eq!(
            cell(&t, row, "worst vs current"),
            change_text(worst(i) / worst(current) - 1.0),
            "run {id}"
        );
        assert_eq!(
            cell(&t, row, "Pareto"),
            if on_front(i) { "yes" } else { "" },
            "run {id}"
        );
        assert_eq!(
            cell(&t, row, "command"),
            format!("`settle run scenarios/gcode_cube.toml --case {id} --backend modal`")
        );
    }
    // The headline: least error and fastest, with cost and gain against current.
    let label = |i: usize| {
        format!(
            "{}, {}, amax_mm_s2={}",
            runs.cell(i, "firmware").expect("firmware"),
            runs.cell(i, "shaper_type").expect("shaper"),
            num(i, "amax_mm_s2")
        )
    };
    let words = |i: usize| {
        format!(
            "{}: {:.2} s, {:.1} um worst (p95 {:.1} um)",
            label(i),
            time(i),
            worst(i),
            num(i, "contour_p95_um")
        )
    };
    let best = order[0];
    let line = format!(
        "- least contour error: **{}**; print time {}, worst error {} vs current",
        words(best),
        change_text(time(best) / time(current) - 1.0),
        change_text(worst(best) / worst(current) - 1.0)
    );
    assert!(summary.contains(&line), "{line}\nnot in\n{summary}");
    assert!(summary.contains(&format!("- current: {}", words(current))));
    // The figure, linked from the summary and embedded in the report, and the table in
    // the report with every run's command.
    for ext in ["svg", "png"] {
        let p = dir.path().join(format!("plots/gcode_jobs.{ext}"));
        assert!(std::fs::metadata(&p).expect("figure").len() > 1000, "{p:?}");
    }
    assert!(summary.contains("](plots/gcode_jobs.svg)"));
    let svg = read(dir.path(), "plots/gcode_jobs.svg");
    for i in 0..n {
        let entry = format!("run {}: {}", runs.run_id(i).expect("id"), label(i));
        assert!(svg.contains(&entry), "legend entry `{entry}`");
    }
    let html = read(dir.path(), "report.html");
    assert!(html.contains("G-code jobs: print time and contour error (cube_layer.gcode)"));
    assert!(html.contains("Print time against worst and p95 contour error"));
    for i in 0..n {
        let c = format!(
            "settle run scenarios/gcode_cube.toml --case {} --backend modal",
            runs.run_id(i).expect("id")
        );
        assert!(html.contains(&c), "{c}");
    }
}

/// The label texts of the ranking chart's bars, per panel in drawing order: `(rank, label,
/// run)` from `1. zv, frequency_hz=40 (run 3)`.
fn bar_labels(svg: &str) -> Vec<(usize, String, usize)> {
    let mut out = Vec::new();
    for piece in svg.split("<text").skip(1) {
        let Some(text) = piece
            .split_once('>')
            .and_then(|(_, rest)| rest.split_once("</text>"))
            .map(|(t, _)| t.trim())
        else {
            continue;
        };
        let Some((rank, rest)) = text.split_once(". ") else {
            continue;
        };
        let (Ok(rank), Some((label, run))) = (rank.parse::<usize>(), rest.rsplit_once(" (")) else {
            continue;
        };
        let run = run.trim_end_matches(')');
        let run = run.strip_prefix("current, ").unwrap_or(run);
        if let Some(id) = run.strip_prefix("run ").and_then(|r| r.parse().ok()) {
            out.push((rank, label.to_string(), id));
        }
    }
    out
}

#[test]
fn a_shaper_sweep_without_a_numeric_axis_gets_a_ranking_chart() {
    let dir = sweep("scenarios/shapers.toml");
    let runs = RunsTable::parse(&read(dir.path(), "runs.csv")).expect("runs.csv");
    let n = runs.rows.len();
    assert_eq!(n, 14, "2 profiles x 7 shapers");
    for ext in ["svg", "png"] {
        let p = dir.path().join(format!("plots/ranking.{ext}"));
        assert!(std::fs::metadata(&p).expect("chart").len() > 1000, "{p:?}");
    }
    let svg = read(dir.path(), "plots/ranking.svg");
    let bars = bar_labels(&svg);
    assert_eq!(bars.len(), 2 * n, "one bar per candidate per band");
    let mut unsettled = 0;
    for (panel, band) in ["10", "50"].iter().enumerate() {
        // From runs.csv: settled runs by move-and-settle time (ties: run number), then
        // the unsettled ones by run number.
        let total = |i: usize| {
            runs.num(i, &format!("move_and_settle_s_{band}um"))
                .expect("total")
        };
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| {
            let key = |i: usize| (!total(i).is_finite(), total(i));
            let (ua, ta) = key(a);
            let (ub, tb) = key(b);
            ua.cmp(&ub)
                .then(if ua {
                    std::cmp::Ordering::Equal
                } else {
                    ta.total_cmp(&tb)
                })
                .then(a.cmp(&b))
        });
        unsettled += order.iter().filter(|&&i| !total(i).is_finite()).count();
        let shown = &bars[panel * n..(panel + 1) * n];
        for (k, &i) in order.iter().enumerate() {
            let (rank, label, id) = &shown[k];
            assert_eq!(*rank, k + 1, "band {band}");
            assert_eq!(*id, runs.run_id(i).expect("id"), "band {band}, rank {rank}");
            assert_eq!(
                *label,
                format!(
                    "{}, {}",
                    runs.cell(i, "profile").expect("profile"),
                    runs.cell(i, "shaper_type").expect("shaper")
                )
            );
        }
    }
    assert_eq!(
        svg.matches(">\nnot settled in the window\n</text>").count(),
        unsettled
    );
    assert_eq!(
        svg.matches(" ms  winner\n</text>").count(),
        2,
        "one winner per band"
    );
    // The only figure: linked from the summary, embedded in the report.
    let summary = read(dir.path(), "summary.md");
    assert!(summary.contains("](plots/ranking.svg)"), "{summary}");
    assert!(
        !summary.contains("plots/vs_"),
        "no numeric axis, no line figure"
    );
    let html = read(dir.path(), "report.html");
    assert!(html.contains("Every candidate ranked by move-and-settle time, per band"));
    assert!(
        html.contains(">\n1. "),
        "the chart's labels are in the page"
    );
}

#[test]
fn a_scan_summary_names_every_swept_machine() {
    let dir = sweep("scenarios/scan_machines.toml");
    let runs = RunsTable::parse(&read(dir.path(), "runs.csv")).expect("runs.csv");
    let summary = read(dir.path(), "summary.md");
    let html = read(dir.path(), "report.html");
    let mut machines: Vec<&str> = (0..runs.rows.len())
        .map(|i| runs.cell(i, "machine").expect("machine"))
        .collect();
    machines.dedup();
    machines.sort_unstable();
    machines.dedup();
    assert_eq!(machines, ["leadscrew_stage", "printer_xy"]);
    let line = summary
        .lines()
        .find(|l| l.starts_with("Machines: "))
        .unwrap_or_else(|| panic!("no machines line in\n{summary}"));
    let t = md_table(&summary, "## Scan steps");
    for m in &machines {
        assert!(
            line.contains(&format!("{m} (axis x, linear driver)")),
            "{line}"
        );
        assert!(
            html.contains(&format!("{m} (axis x, linear driver)")),
            "{m}"
        );
        // Every machine's rows in the scan table.
        let rows = t
            .iter()
            .skip(1)
            .filter(|r| r.contains(&m.to_string()))
            .count();
        let expected = (0..runs.rows.len())
            .filter(|&i| runs.cell(i, "machine") == Some(m))
            .count()
            / 2;
        assert_eq!(rows, expected, "{m}: one row per step-over: {t:?}");
    }
}

/// A raster scan's summary (whose own table stands in for the move-and-settle ranking)
/// marks the `[current]` step and compares it, at each step-over, with the best step of
/// that step-over: the one that stays inside the most bands over the next line, then
/// the least error at re-entry (recomputed here from runs.csv).
#[test]
fn a_scan_summary_compares_the_current_step_with_the_best() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(crate::support::root().join("scenarios/ci_scan.toml"))
        .expect("scenario")
        + "\n[current]\nprofile = \"trapezoid\"\n";
    let sc = write(dir.path(), "scan.toml", &text);
    let out = dir.path().join("out");
    run_ok(
        settle()
            .arg("sweep")
            .arg(&sc)
            .args(["--backend", "modal", "--out"])
            .arg(&out),
    );
    let runs = RunsTable::parse(&read(&out, "runs.csv")).expect("runs.csv");
    let summary = read(&out, "summary.md");
    let t = md_table(&summary, "## Scan steps");
    for r in &t[1..] {
        assert!(r[1].ends_with("(current)"), "the trapezoid column: {r:?}");
        assert!(
            !r[2].contains("current") && !r[3].contains("current"),
            "{r:?}"
        );
    }
    let c = md_table(&summary, "### Against your current settings");
    assert_eq!(c.len(), 3, "one row per step-over: {c:?}");
    let n = runs.rows.len();
    for (row, d) in c[1..].iter().zip(["0.05", "0.5"]) {
        let at = |i: usize| runs.num(i, "distance_mm") == d.parse().ok();
        let key = |i: usize| {
            let missed = [1, 10]
                .iter()
                .filter(|b| runs.num(i, &format!("scan_settled_{b}um")) != Some(1.0))
                .count();
            (missed, runs.num(i, "scan_reentry_error_um").expect("error"))
        };
        let current = (0..n)
            .find(|&i| at(i) && runs.cell(i, "profile") == Some("trapezoid"))
            .expect("current");
        let best = (0..n)
            .filter(|&i| at(i))
            .min_by(|&a, &b| {
                let (ka, kb) = (key(a), key(b));
                ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
            })
            .expect("best");
        let id = |i: usize| runs.run_id(i).expect("id");
        assert_eq!(row[0], format!("move.distance_mm = {d}"));
        assert_eq!(row[1], format!("profile = trapezoid (run {})", id(current)));
        assert_eq!(row[2], format!("{:.2}", key(current).1));
        assert_eq!(
            row[3],
            format!(
                "profile = {} (run {})",
                runs.cell(best, "profile").expect("profile"),
                id(best)
            )
        );
        assert_eq!(row[4], format!("{:.2}", key(best).1));
        assert_ne!(best, current, "the trapezoid step is not the best here");
    }
    // report.html has the comparison as a table of its own.
    let html = read(&out, "report.html");
    assert!(html.contains("Against your current settings"));
    assert!(
        !html.contains("###"),
        "no Markdown heading left in the page"
    );
}
