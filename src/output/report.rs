//! `report.html` of a sweep: the same data summary.md shows ([`crate::output::ranking`]),
//! as a [`Report`] for [`crate::output::html::render`]: the winner per band, one ranking
//! table per band, the figures embedded, every run (runs.csv, sortable and filterable),
//! the failed runs with their reasons and the provenance (scenario text, settle version,
//! backend, the command that reruns it).
//!
//! No clock is read: the same runs give the same page, so a merged sweep's report is the
//! unsharded one's.

use crate::input::runs_columns::RunsColumns;
use crate::input::scenario::Scenario;
use crate::output::html::{
    BandWinner, Cell, FailedRun, Figure, Gain, Image, InputFile, Provenance, Reference, Report,
    Rows, Stat, Table,
};
use crate::output::jobs::{self, Jobs};
use crate::output::ranking::{
    Point, Ranked, Ranking, SHAPER_COLUMNS, gain_text, rank, run_command,
};
use crate::output::summary::{machines_line, ms};
use crate::spec::runs::RunList;

/// The scenario a sweep ran, as the report names it.
#[derive(Debug, Clone, Copy)]
pub struct ScenarioFile<'a> {
    /// The path, as given on the command line (the commands in the report use it).
    pub path: &'a std::path::Path,
    /// Its text.
    pub text: &'a str,
}

/// The title of the table of every run in a sweep's report.
pub const RUNS_TITLE: &str = "All runs (runs.csv)";

/// A number cell with `text` shown (`value` non-finite for `not settled`).
fn num(value: f64, text: String) -> Cell {
    Cell::Number { value, text }
}

fn winners(ranking: &Ranking) -> Vec<BandWinner> {
    ranking
        .bands
        .iter()
        .map(|b| {
            let band = format!("within {} um", b.band_um);
            let Some(w) = &b.winner else {
                return BandWinner {
                    band,
                    winner: "no candidate settles at every point".into(),
                    ..BandWinner::default()
                };
            };
            let mut numbers = vec![Stat {
                label: if w.points > 1 {
                    format!("move and settle, sum over {} points", w.points)
                } else {
                    "move and settle".into()
                },
                value: format!("{:.1} ms", w.total_s * 1e3),
            }];
            if let Some((label, t)) = &w.reference {
                numbers.push(Stat {
                    label: format!("{} ({label})", ranking.reference_name()),
                    value: if t.is_finite() {
                        format!("{:.1} ms", t * 1e3)
                    } else {
                        "not settled everywhere".into()
                    },
                });
            }
            let gain = w.reference.as_ref().map(|(label, t)| Gain {
                reference: if ranking.has_current {
                    Reference::Current {
                        label: label.clone(),
                    }
                } else {
                    Reference::Slowest {
                        label: label.clone(),
                    }
                },
                ratio: t / w.total_s,
                detail: format!(
                    "move and settle {} ms vs {} ms",
                    ms(Some(w.total_s)),
                    ms(Some(*t).filter(|t| t.is_finite()))
                ),
            });
            BandWinner {
                band,
                winner: w.label.clone(),
                numbers,
                gain,
            }
        })
        .collect()
}

/// The ranking tables, one per band, without their rows ([`RankingRows`] makes them).
fn ranking_tables(ranking: &Ranking, runs: &dyn RunList) -> Vec<Table> {
    let repeats = ranking
        .repeats_note(runs)
        .map_or(String::new(), |n| format!(" {}", n.replace('`', "")));
    ranking
        .bands
        .iter()
        .map(|b| {
            let mut header: Vec<String> = ranking.workload_keys.clone();
            header.push("rank".into());
            header.push("candidate".into());
            for h in [
                "move (ms)",
                "settle (ms)",
                "total (ms)",
                "residual peak (um)",
            ] {
                header.push(h.into());
            }
            header.push(format!("gain {} (%)", ranking.reference_name()));
            if ranking.shapers {
                header.extend(SHAPER_COLUMNS.map(String::from));
            }
            header.push("run".into());
            header.push("command".into());
            Table {
                title: format!("Ranking: move and settle to within {} um", b.band_um),
                note: format!(
                    "Per swept point of the workload, fastest first. Gain {}: how much longer the reference takes.{repeats}",
                    ranking.reference_name()
                ),
                header,
                rows: Vec::new(),
            }
        })
        .collect()
}

/// The row of run `r` of workload point `p` in a ranking table.
fn ranking_row(p: &Point, r: &Ranked, runs: &dyn RunList, file: ScenarioFile<'_>) -> Vec<Cell> {
    let mut row: Vec<Cell> = p.workload.iter().map(Cell::text).collect();
    row.push(match r.rank {
        Some(n) => num(n as f64, n.to_string()),
        None => num(f64::INFINITY, "-".into()),
    });
    row.push(Cell::text(if r.current {
        format!("{} (current)", r.label)
    } else {
        r.label.clone()
    }));
    let t = |x: Option<f64>| num(x.map_or(f64::INFINITY, |x| x * 1e3), ms(x));
    match &r.failure {
        Some(f) => {
            row.push(num(r.move_s * 1e3, format!("{:.1}", r.move_s * 1e3)));
            row.push(Cell::text(f.clone()));
            row.push(num(f64::INFINITY, "failed".into()));
            row.push(num(f64::NAN, "-".into()));
        }
        None => {
            row.push(num(r.move_s * 1e3, format!("{:.1}", r.move_s * 1e3)));
            row.push(t(r.settle_s));
            row.push(t(r.total_s));
            row.push(num(
                r.residual_peak_um,
                format!("{:.2}", r.residual_peak_um),
            ));
        }
    }
    row.push(num(
        r.gain.map_or(f64::NAN, |g| g * 100.0),
        gain_text(r.gain),
    ));
    if let Some(sh) = &r.shaper {
        for (x, prec) in sh.iter().zip([3usize, 1, 0]) {
            row.push(x.map_or(num(f64::NAN, "-".into()), |x| num(x, format!("{x:.prec$}"))));
        }
    }
    row.push(num(r.id as f64, r.id.to_string()));
    row.push(Cell::text(run_command(file.path, &runs.at(r.row))));
    row
}

/// The rows of a sweep report's ranking tables, made as the page is written
/// ([`crate::output::html::render_to`]): a ranking of 100,000 runs is never held as cells.
#[derive(Debug)]
pub struct RankingRows<'a> {
    /// The ranking, when the report has its tables.
    ranking: Option<Ranking>,
    /// The index of the first ranking table in the report's tables.
    first: usize,
    /// The runs (row `i` of the runs table is `runs.at(i)`).
    runs: &'a dyn RunList,
    /// The runs table the ranking was made from.
    table: &'a RunsColumns,
    /// The scenario, as the commands name it.
    file: ScenarioFile<'a>,
}

impl Rows for RankingRows<'_> {
    fn row(&self, table: usize, k: usize) -> Option<Vec<Cell>> {
        let b = table.checked_sub(self.first)?;
        let ranking = self.ranking.as_ref()?;
        let band = ranking.bands.get(b)?;
        let p = band
            .points
            .partition_point(|s| s.start as usize <= k)
            .checked_sub(1)?;
        let at = k - band.points[p].start as usize;
        let point = ranking.point_runs(b, p, at..at + 1, self.runs, self.table)?;
        let r = point.runs.first()?;
        Some(ranking_row(&point, r, self.runs, self.file))
    }
}

/// The G-code jobs' table ([`crate::output::jobs`]): the headline lines as its note.
fn jobs_table(j: &Jobs, runs: &dyn RunList, file: ScenarioFile<'_>) -> Table {
    let opt = |x: Option<f64>, prec: usize| match x {
        Some(x) => num(x, format!("{x:.prec$}")),
        None => num(f64::NAN, "-".into()),
    };
    let change = |x: Option<f64>| match x {
        Some(x) if x.is_finite() => num(x * 100.0, jobs::change(Some(x))),
        _ => num(f64::NAN, "-".into()),
    };
    let rows = j
        .rows
        .iter()
        .map(|r| {
            let mut row = vec![match r.rank {
                Some(n) if r.current => num(n as f64, format!("{n} (current)")),
                Some(n) => num(n as f64, n.to_string()),
                None => num(f64::INFINITY, "-".into()),
            }];
            row.extend(r.values.iter().map(|v| Cell::text(v.as_str())));
            match &r.failure {
                Some(f) => {
                    row.push(Cell::text(f.as_str()));
                    row.extend((0..3).map(|_| num(f64::NAN, "-".into())));
                }
                None => {
                    row.push(opt(r.print_time_s, 2));
                    row.push(opt(r.worst_um, 2));
                    row.push(opt(r.p95_um, 2));
                    row.push(opt(r.worst_line.map(|l| l as f64), 0));
                }
            }
            if j.current().is_some() {
                row.push(change(r.time_vs_current));
                row.push(change(r.worst_vs_current));
            }
            row.push(Cell::text(if r.pareto { "yes" } else { "" }));
            row.push(num(r.id as f64, r.id.to_string()));
            row.push(Cell::text(run_command(file.path, &runs.at(r.row))));
            row
        })
        .collect();
    let lines: Vec<String> = jobs::headline(j)
        .iter()
        .map(|l| l.replace("**", ""))
        .collect();
    Table {
        title: format!("G-code jobs: print time and contour error ({})", j.file),
        note: format!("{} {}.", jobs::NOTE, lines.join("; ")),
        header: jobs::header(j),
        rows,
    }
}

/// The report of a sweep: `table` is its runs.csv (row `i` = `runs.at(i)`), `figures` the
/// figures' captions and SVG files. What a report of many runs would hold is left to be
/// made as the page is written ([`crate::output::html::render_to`]): the table of every
/// run (`runs` is `None`; written from runs.csv under [`RUNS_TITLE`]) and the ranking
/// tables' rows (the [`RankingRows`] returned).
pub fn sweep_report<'a>(
    sc: &Scenario,
    file: ScenarioFile<'a>,
    runs: &'a dyn RunList,
    table: &'a RunsColumns,
    figures: &[(String, std::path::PathBuf)],
) -> (Report, RankingRows<'a>) {
    let mut intro = vec![format!("{}. {} runs.", machines_line(runs), runs.len())];
    if !sc.description.trim().is_empty() {
        intro.insert(0, sc.description.trim().to_string());
    }
    let mut replaced = false;
    let mut study_tables = Vec::new();
    for k in crate::studies::all() {
        if let Some(section) =
            k.summary(runs, table, &|r| crate::output::ranking::is_current(sc, r))
        {
            replaced |= k.replaces_move_tables();
            study_tables.extend(markdown_tables(&section));
        }
    }
    let (winners, mut tables, ranking) = if replaced {
        (Vec::new(), Vec::new(), None)
    } else {
        let ranking = rank(sc, runs, table);
        (
            winners(&ranking),
            ranking_tables(&ranking, runs),
            Some(ranking),
        )
    };
    let mut first = 0;
    if let Some(j) = crate::output::jobs::jobs(sc, runs, table) {
        tables.insert(0, jobs_table(&j, runs, file));
        first = 1;
    }
    tables.extend(study_tables);
    let failed = (0..runs.len())
        .filter(|&i| table.cell(i, "status").is_some_and(|s| s != "ok"))
        .map(|i| FailedRun {
            run: format!("run {}", runs.at(i).id),
            status: table.cell(i, "status").unwrap_or_default().to_string(),
            reason: table.cell(i, "reason").unwrap_or_default().to_string(),
        })
        .collect();
    let backend = runs
        .first()
        .map(|r| r.backend.to_string())
        .unwrap_or_default();
    let rows = RankingRows {
        ranking,
        first,
        runs,
        table,
        file,
    };
    let report = Report {
        title: sc.name.clone(),
        intro,
        winners,
        tables,
        sections: Vec::new(),
        figures: figures
            .iter()
            .map(|(title, svg)| Figure {
                title: title.clone(),
                image: Image::SvgFile(svg.clone()),
            })
            .collect(),
        runs: None,
        failed,
        provenance: provenance(
            file,
            &backend,
            format!(
                "settle sweep {}{}",
                file.path.display(),
                if backend.is_empty() || backend == crate::spec::backend::Backend::default().name()
                {
                    String::new()
                } else {
                    format!(" --backend {backend}")
                }
            ),
        ),
    };
    (report, rows)
}

/// The provenance of a run of settle on `file` with `backend`, `command` as typed.
pub fn provenance(file: ScenarioFile<'_>, backend: &str, command: String) -> Provenance {
    Provenance {
        settle_version: env!("CARGO_PKG_VERSION").to_string(),
        backend: backend.to_string(),
        command_line: command,
        date: String::new(),
        facts: Vec::new(),
        inputs: vec![InputFile {
            name: file.path.display().to_string(),
            text: file.text.to_string(),
        }],
    }
}

/// The tables of a summary section (Markdown): each `## heading` (or `###`), the
/// paragraph under it as the note, and its `| ... |` rows (bold marks dropped; numbers sort
/// as numbers).
fn markdown_tables(section: &str) -> Vec<Table> {
    let mut out: Vec<Table> = Vec::new();
    let mut title = String::new();
    let mut note = String::new();
    let mut current: Option<Table> = None;
    let cells = |line: &str| -> Vec<String> {
        line.trim()
            .trim_matches('|')
            .split('|')
            .map(|c| c.trim().replace("**", ""))
            .collect()
    };
    for line in section.lines() {
        let is_row = line.trim_start().starts_with('|');
        if !is_row && let Some(t) = current.take() {
            out.push(t);
        }
        if let Some(h) = line
            .strip_prefix("## ")
            .or_else(|| line.strip_prefix("### "))
        {
            title = h.trim().to_string();
            note.clear();
        } else if is_row {
            let row = cells(line);
            match current.as_mut() {
                None => {
                    current = Some(Table {
                        title: title.clone(),
                        note: note.trim().to_string(),
                        header: row,
                        rows: Vec::new(),
                    });
                }
                Some(_) if row.iter().all(|c| c.chars().all(|ch| "-:".contains(ch))) => {}
                Some(t) => t.rows.push(
                    row.into_iter()
                        .map(|c| match c.parse::<f64>() {
                            Ok(x) => num(x, c),
                            Err(_) => Cell::text(c),
                        })
                        .collect(),
                ),
            }
        } else if !line.trim().is_empty() {
            note.push_str(line.trim());
            note.push(' ');
        }
    }
    out.extend(current);
    out
}
