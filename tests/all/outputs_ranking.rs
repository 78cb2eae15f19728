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
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| total(a).total_cmp(&total(b)).then(a.cmp(&b)));

    let t = md_table(&summary, "## Ranking: move and settle to within 10 um");
    assert_eq!(t.len(), n + 1, "one row per run");
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
    // The first ranking table (10 um; tables are numbered from 1), sorted by its run column.
    let (res, _) = selftest(&chrome, &page, "&grid=table-1&col=run");
    let mut ids: Vec<usize> = (0..runs.rows.len())
        .map(|i| runs.run_id(i).expect("id"))
        .collect();
    ids.sort_unstable();
    let asc: Vec<String> = ids.iter().map(usize::to_string).collect();
    let desc: Vec<String> = ids.iter().rev().map(usize::to_string).collect();
    assert_eq!(res["asc"], serde_json::json!(asc), "{res}");
    assert_eq!(res["desc"], serde_json::json!(desc), "{res}");
    assert_eq!(res["rows"], runs.rows.len());
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
