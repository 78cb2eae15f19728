//! `report.html` (settle::output::html): deterministic, escaped, and working in a real browser.
//!
//! The browser tests drive headless Chromium (`/usr/bin/chromium`, Debian's `chromium`
//! package; `scripts/browser-test.sh` installs it) through the page's `#selftest` hook: it
//! clicks a header through the real click handler, types into the filters and writes what
//! the page then shows into the DOM, which `--dump-dom` prints. `SETTLE_SKIP_BROWSER=1`
//! skips them with a notice; otherwise a missing browser fails them.
//! `SETTLE_HTML_ROWS` sets the rows of the generated large table (default 6,000: just above
//! the size at which the script pages the table from its text).

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::support::html::chromium::{
    Rect, browser, console_clean, region_spread, selftest, selftest_result, visit,
};
use crate::support::html::fixture::{column, generated_csv, quickstart_report};
use settle::output::html::{Cell, FailedRun, LAZY_ROWS, Report, Rows, Table, render, render_to};

/// The shown texts of column `name` in the order a correct sort gives: by value, ascending
/// or descending, non-finite values last either way, ties in row order.
fn sorted_texts(t: &Table, name: &str, ascending: bool) -> Vec<String> {
    let j = t.header.iter().position(|h| h == name).expect("column");
    let values = column(t, name);
    let mut idx: Vec<usize> = (0..values.len()).collect();
    idx.sort_by(|&a, &b| {
        let (x, y) = (values[a], values[b]);
        match (x.is_finite(), y.is_finite()) {
            (true, true) if ascending => x.total_cmp(&y),
            (true, true) => y.total_cmp(&x),
            (fx, fy) => fy.cmp(&fx),
        }
        .then(a.cmp(&b))
    });
    idx.iter()
        .map(|&i| t.rows[i][j].shown().to_string())
        .collect()
}

/// `Ok` when the page showed exactly `expected`.
fn check_order(shown: &serde_json::Value, expected: &[String]) -> Result<(), String> {
    let shown: Vec<String> = shown
        .as_array()
        .ok_or("no column in the selftest result")?
        .iter()
        .map(|v| v.as_str().unwrap_or_default().to_string())
        .collect();
    if shown == expected {
        Ok(())
    } else {
        Err(format!("shown {shown:?}, expected {expected:?}"))
    }
}

/// Write `html` as `report.html` in a new temporary folder (and as `NAME.html` in the folder
/// `SETTLE_HTML_KEEP` names, when set, to look at).
fn write_page(name: &str, html: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("report.html");
    std::fs::write(&path, html).expect("write report.html");
    if let Some(keep) = std::env::var_os("SETTLE_HTML_KEEP") {
        std::fs::write(Path::new(&keep).join(format!("{name}.html")), html).expect("keep page");
    }
    (dir, path)
}

#[test]
fn render_is_deterministic() {
    let r = quickstart_report();
    let a = render(&r);
    let b = render(&r.clone());
    assert!(a == b, "two renders of the same report differ");
    // One file: no reference to anything outside it.
    for outside in [
        "http://",
        "https://",
        "<link",
        "src=\"http",
        "@import",
        "url(",
    ] {
        let hits: Vec<&str> = a
            .lines()
            .filter(|l| l.contains(outside) && !l.contains("xmlns=\"http://www.w3.org"))
            .collect();
        assert!(hits.is_empty(), "{outside}: {hits:?}");
    }
}

#[test]
fn every_text_is_escaped() {
    let evil = "</pre></noscript><script>alert('x')</script> & \"q\"";
    let mut r = quickstart_report();
    r.title = evil.into();
    r.intro = vec![evil.into()];
    r.winners[0].winner = evil.into();
    r.winners[0].numbers[0].label = evil.into();
    r.tables[0].header[0] = evil.into();
    r.tables[0].rows[0][0] = Cell::Link {
        text: evil.into(),
        href: evil.into(),
    };
    r.figures[0].title = evil.into();
    r.failed = vec![FailedRun {
        run: "7".into(),
        status: "lost_steps".into(),
        reason: evil.into(),
    }];
    r.provenance.command_line = evil.into();
    r.provenance.inputs[0].text = format!("name = \"a<b & c\"\n{evil}\n");
    // A large plain table goes inside <noscript>: its text must not close it either.
    let mut big = Table {
        title: evil.into(),
        note: evil.into(),
        header: vec!["v".into(), evil.into()],
        rows: Vec::new(),
    };
    big.rows = (0..=LAZY_ROWS)
        .map(|i| vec![Cell::number(i as f64), Cell::text(evil)])
        .collect();
    r.runs = Some(big);
    let html = render(&r);
    assert_eq!(
        html.matches("<script").count(),
        1,
        "only the page's own script"
    );
    assert_eq!(html.matches("</noscript>").count(), 1);
    assert_eq!(html.matches("</pre>").count(), 1);
    let escaped = "&lt;/pre&gt;&lt;/noscript&gt;&lt;script&gt;alert(&#39;x&#39;)\
                   &lt;/script&gt; &amp; &quot;q&quot;";
    // Title (twice), intro, winner, stat, header, link text and href, figure, failed
    // reason, command line, input text, and the large table's title, note, header and
    // every row.
    assert_eq!(html.matches(escaped).count(), 15 + LAZY_ROWS + 1);
    assert!(html.contains("name = &quot;a&lt;b &amp; c&quot;"));
}

#[test]
fn report_renders_sorts_and_logs_nothing_in_chromium() {
    let Some(chrome) = browser() else { return };
    let start = Instant::now();
    let report = quickstart_report();
    let (_dir, page) = write_page("quickstart", &render(&report));
    let runs = report.runs.as_ref().expect("runs");
    let col = "move_and_settle_s_10um";
    // The screenshot (a plain visit) runs beside the selftest visit.
    let dir = tempfile::tempdir().expect("temporary folder");
    let shot = dir.path().join("shot.png");
    let screenshot = {
        let (chrome, page) = (chrome.clone(), page.clone());
        let arg = format!("--screenshot={}", shot.display());
        std::thread::spawn(move || visit(&chrome, &page, "", &[&arg]))
    };
    let (res, dump_time) = selftest(&chrome, &page, &format!("&col={col}"));
    assert_eq!(res["rows"], 6);
    assert_eq!(res["lazy"], false);
    check_order(&res["asc"], &sorted_texts(runs, col, true)).expect("ascending order");
    check_order(&res["desc"], &sorted_texts(runs, col, false)).expect("descending order");
    assert_eq!(res["asc_aria"], "ascending");
    assert_eq!(res["desc_aria"], "descending");
    assert_eq!(res["images"], serde_json::json!([200]), "the PNG decodes");
    assert_eq!(
        res["columns"],
        serde_json::json!(runs.header),
        "every column"
    );
    let table = Rect::from_json(&res["rects"]["table"]).expect("table box");
    let figure = Rect::from_json(&res["rects"]["figure"]).expect("figure box");

    let s = screenshot.join().expect("screenshot visit");
    console_clean(&s).expect("no console messages");
    let img = image::open(&shot).expect("screenshot PNG").to_rgba8();
    assert_eq!((img.width(), img.height()), (1280, 2000));
    for (name, rect) in [("runs table", table), ("figure", figure)] {
        let (spread, share) = region_spread(&img, rect);
        eprintln!("{name}: {rect:?}, {share:.2} visible, luminance deviation {spread:.1}");
        assert!(share > 0.3, "{name} is off screen: {rect:?}");
        assert!(spread > 20.0, "{name} looks blank: deviation {spread:.1}");
    }
    eprintln!(
        "browser test: {:.2} s (dump {:.2} s, screenshot {:.2} s)",
        start.elapsed().as_secs_f64(),
        dump_time.as_secs_f64(),
        s.elapsed.as_secs_f64()
    );
}

#[test]
fn a_broken_script_fails_the_console_check() {
    let Some(chrome) = browser() else { return };
    let html = render(&quickstart_report());
    let broken = html.replacen("'use strict';", "'use strict'; var broken = ;", 1);
    assert_ne!(broken, html, "the script has its strict-mode line");
    let (_dir, page) = write_page("broken_script", &broken);
    let v = visit(&chrome, &page, "#selftest", &["--dump-dom"]);
    let err = console_clean(&v).expect_err("a syntax error shows on the console");
    assert!(err.contains("SyntaxError"), "{err}");
    assert!(selftest_result(&v.stdout).is_none());
}

#[test]
fn a_broken_sort_fails_the_order_check() {
    let Some(chrome) = browser() else { return };
    let report = quickstart_report();
    let html = render(&report);
    let head = "function cmpNum(x, y, dir) {";
    let broken = html.replacen(head, &format!("{head} return 0;"), 1);
    assert_ne!(broken, html, "the script has its number comparison");
    let (_dir, page) = write_page("broken_sort", &broken);
    let col = "move_and_settle_s_10um";
    let (res, _) = selftest(&chrome, &page, &format!("&col={col}"));
    let runs = report.runs.as_ref().expect("runs");
    assert!(check_order(&res["asc"], &sorted_texts(runs, col, true)).is_err());
    assert!(check_order(&res["desc"], &sorted_texts(runs, col, false)).is_err());
}

#[test]
fn large_tables_are_paged_sorted_and_filtered_in_chromium() {
    let Some(chrome) = browser() else { return };
    let n: usize = std::env::var("SETTLE_HTML_ROWS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(LAZY_ROWS + 1_000);
    let runs = Table::from_csv("All runs", &generated_csv(n)).expect("generated CSV");
    let html = render(&Report {
        title: format!("{n} generated runs"),
        runs: Some(runs.clone()),
        ..Report::default()
    });
    assert_eq!(html.contains("data-lazy"), n > LAZY_ROWS);
    // Beside it: the same without JavaScript, and a table of DOM rows (the first 300).
    let plain = {
        let (chrome, html) = (chrome.clone(), html.clone());
        std::thread::spawn(move || parsed_without_scripts(&chrome, &html))
    };
    let dom_rows = {
        let chrome = chrome.clone();
        let mut few = runs.clone();
        few.rows.truncate(300);
        std::thread::spawn(move || check_paging(&chrome, "dom_rows", &few))
    };
    check_paging(&chrome, "large", &runs);
    dom_rows.join().expect("DOM rows checked");
    let plain = plain.join().expect("probe without scripts");
    assert_eq!(plain["rows"], n);
    assert_eq!(plain["first"], serde_json::json!(runs.header));
}

/// Sort `runs` by a settling time both ways, then filter it by a word over all cells and by
/// status, and check the first page and the counts against the table itself.
fn check_paging(chrome: &Path, name: &str, runs: &Table) {
    let html = render(&Report {
        title: format!("{} generated runs", runs.rows.len()),
        runs: Some(runs.clone()),
        ..Report::default()
    });
    let (_dir, page) = write_page(name, &html);
    let col = "settle_time_s_10um";
    let (res, dump_time) = selftest(
        chrome,
        &page,
        &format!("&col={col}&filter=SCURVE&colfilter=status:lost_steps"),
    );
    assert_eq!(res["rows"], runs.rows.len());
    assert_eq!(res["lazy"], runs.rows.len() > LAZY_ROWS);
    let page_of = |mut all: Vec<String>| {
        all.truncate(100);
        all
    };
    check_order(&res["asc"], &page_of(sorted_texts(runs, col, true))).expect("ascending");
    check_order(&res["desc"], &page_of(sorted_texts(runs, col, false))).expect("descending");
    let at = |name: &str| runs.header.iter().position(|h| h == name).expect("column");
    let (profile, status) = (at("profile"), at("status"));
    let matched = runs
        .rows
        .iter()
        .filter(|r| r[profile].shown() == "scurve" && r[status].shown() == "lost_steps")
        .count();
    assert!(matched > 0);
    assert_eq!(res["matched"], matched);
    assert_eq!(res["shown"], matched.min(100));
    eprintln!(
        "{} rows ({:.1} MB): browser run {:.2} s; in the page: init {:.0} ms, sort {:.0} ms, \
         filter {:.0} ms",
        runs.rows.len(),
        html.len() as f64 / 1e6,
        dump_time.as_secs_f64(),
        res["init_ms"].as_f64().unwrap_or(f64::NAN),
        res["sort_ms"].as_f64().unwrap_or(f64::NAN),
        res["filter_ms"].as_f64().unwrap_or(f64::NAN),
    );
}

/// What an HTML parser with scripting off (the browser's `DOMParser`, as with JavaScript
/// disabled: `<noscript>` holds markup) finds in the page: the runs table's body rows and
/// header cells.
fn parsed_without_scripts(chrome: &Path, html: &str) -> serde_json::Value {
    let source = serde_json::to_string(html)
        .expect("page as a JSON string")
        .replace("</", "<\\/");
    let probe = format!(
        "<!DOCTYPE html><meta charset=\"utf-8\"><body><script>\
         var d = new DOMParser().parseFromString({source}, 'text/html');\
         var t = d.querySelector('#runs table');\
         var pre = document.createElement('pre'); pre.id = 'selftest-result';\
         pre.textContent = JSON.stringify({{rows: t ? t.tBodies[0].rows.length : -1,\
           first: t ? Array.from(t.tHead.rows[0].cells, function (c) {{ return c.textContent; }}) : []}});\
         document.body.appendChild(pre);</script>"
    );
    let (_dir, page) = write_page("no_script_probe", &probe);
    let v = visit(chrome, &page, "", &["--dump-dom"]);
    console_clean(&v).expect("no console messages");
    selftest_result(&v.stdout).expect("the probe ran")
}

/// `settle gcode`'s report.html: the layers (layers.csv) sort as numbers, the worst spot
/// shows its G-code line's text, the provenance gives the file's SHA-256 as `sha256sum`
/// prints it, the page logs nothing, and the figures and tables are drawn.
#[test]
fn the_gcode_report_renders_sorts_and_logs_nothing_in_chromium() {
    use crate::support::{root, run_ok, settle};
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("out");
    let file = "gcode/prints/ringing_tower.gcode";
    run_ok(
        settle()
            .args([
                "gcode",
                file,
                "--machine",
                "printer_xy",
                "--firmware",
                "klipper",
                "--shaper",
                "mzv@48",
                "--versus",
                "settle:none",
                "--out",
            ])
            .arg(&out),
    );
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    let csv = std::fs::read_to_string(out.join("layers.csv")).expect("layers.csv");
    let layers = Table::from_csv("layers", &csv).expect("layers.csv");
    // The provenance: the file, its digest by coreutils, the command.
    let sha = std::process::Command::new("sha256sum")
        .arg(root().join(file))
        .output()
        .expect("sha256sum runs");
    let sha = String::from_utf8_lossy(&sha.stdout)
        .split_whitespace()
        .next()
        .expect("a digest")
        .to_string();
    assert_eq!(sha.len(), 64);
    assert!(html.contains(&format!("<dd>{sha}</dd>")), "SHA-256 {sha}");
    assert!(html.contains(&format!(
        "settle gcode {file} --machine printer_xy --firmware klipper --shaper mzv@48 --versus settle:none --out {}",
        out.display()
    )));
    // The worst spot: the layer with the largest worst error, its line's text.
    let rows = settle::input::runs_table::RunsTable::parse(&csv).expect("layers.csv");
    let worst = column(&layers, "worst_um");
    let k = (0..worst.len())
        .max_by(|&a, &b| worst[a].total_cmp(&worst[b]))
        .expect("a layer");
    let line: usize = rows
        .cell(k, "worst_line")
        .and_then(|l| l.parse().ok())
        .expect("the worst layer's line");
    let text = std::fs::read_to_string(root().join(file)).expect("G-code");
    let gcode_line = text.lines().nth(line - 1).expect("the line").trim_end();
    let spots = &html[html.find("<h2>Worst spots</h2>").expect("worst spots")..];
    let first_row = &spots[spots.find("<tbody>").expect("rows")..];
    let first_row = &first_row[..first_row.find("</tr>").expect("row end")];
    assert!(
        first_row.contains(&format!("{line}<td>{gcode_line}")),
        "line {line} `{gcode_line}` in {first_row}"
    );
    // Four figures: the ringing map, its smoothing and vibration, the error against Z
    // and the comparison.
    assert_eq!(html.matches("<figure id=").count(), 4);
    assert!(html.contains("smoothing (command against the G-code path)"));

    let Some(chrome) = browser() else { return };
    let (_keep, page) = write_page("gcode", &html);
    let (res, _) = selftest(&chrome, &page, "&col=worst_um");
    assert_eq!(res["rows"], layers.rows.len());
    assert_eq!(res["columns"], serde_json::json!(layers.header));
    check_order(&res["asc"], &sorted_texts(&layers, "worst_um", true)).expect("ascending");
    check_order(&res["desc"], &sorted_texts(&layers, "worst_um", false)).expect("descending");
    // The worst spots (the first table) and the first figure are drawn, not blank.
    let (spots, _) = selftest(&chrome, &page, "&grid=table-1");
    let shot = dir.path().join("shot.png");
    let v = visit(
        &chrome,
        &page,
        "",
        &[&format!("--screenshot={}", shot.display())],
    );
    console_clean(&v).expect("no console messages");
    let img = image::open(&shot).expect("screenshot PNG").to_rgba8();
    for (name, rect) in [
        ("worst spots", &spots["rects"]["table"]),
        ("figure", &spots["rects"]["figure"]),
    ] {
        let rect = Rect::from_json(rect).expect("box");
        let (spread, share) = region_spread(&img, rect);
        assert!(share > 0.3, "{name} is off screen: {rect:?}");
        assert!(spread > 20.0, "{name} looks blank: deviation {spread:.1}");
    }
}

/// The rows of `tables`, made one at a time (as a sweep's ranking rows are).
struct Held(Vec<Table>);

impl Rows for Held {
    fn row(&self, table: usize, k: usize) -> Option<Vec<Cell>> {
        self.0.get(table)?.rows.get(k).cloned()
    }
}

/// A page written as it is made (`render_to`: the table of every run from CSV text a record
/// at a time, tables' rows made on demand) is byte for byte the page `render` makes from
/// the report holding every row: small tables (DOM rows, sort keys) and tables above
/// `LAZY_ROWS` (paged by the script), and a CSV that is not a table (left out by both).
#[test]
fn a_page_written_as_it_is_made_is_the_rendered_page() {
    let base = quickstart_report();
    let big = Table::from_csv("big", &generated_csv(LAZY_ROWS + 1)).expect("generated CSV");
    for (csv, tables) in [
        (generated_csv(40), base.tables.clone()),
        (
            generated_csv(LAZY_ROWS + 1),
            vec![base.tables[0].clone(), big],
        ),
        ("run,reason\n0,\"open\n".to_string(), base.tables.clone()),
    ] {
        assert!(tables.iter().all(|t| !t.rows.is_empty()));
        let held = Report {
            tables: tables.clone(),
            runs: Table::from_csv("All runs (runs.csv)", &csv).ok(),
            ..base.clone()
        };
        let made = Report {
            tables: tables
                .iter()
                .map(|t| Table {
                    rows: Vec::new(),
                    ..t.clone()
                })
                .collect(),
            runs: None,
            ..base.clone()
        };
        let mut bytes = Vec::new();
        render_to(
            &made,
            Some(("All runs (runs.csv)", &csv)),
            &Held(tables),
            &mut bytes,
            Path::new("report.html"),
        )
        .expect("written");
        let want = render(&held);
        assert!(
            bytes == want.as_bytes(),
            "the page written as it is made differs from the rendered one ({} vs {} bytes)",
            bytes.len(),
            want.len()
        );
    }
}
