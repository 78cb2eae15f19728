//! The reports the browser tests load: the committed quickstart baseline as a report, and
//! a generated runs table of any size.

use std::path::Path;

use settle::output::html::{
    BandWinner, Cell, Figure, Gain, Image, InputFile, Provenance, Reference, Report, Stat, Table,
};

/// A file of the repository as text.
fn repo_file(rel: &str) -> String {
    let path = Path::new(crate::support::manifest_dir()).join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A column of `t` as numbers (`inf` for not settled).
pub fn column(t: &Table, name: &str) -> Vec<f64> {
    let j = t.header.iter().position(|h| h == name).expect("column");
    t.rows
        .iter()
        .map(|r| match &r[j] {
            Cell::Number { value, .. } => *value,
            other => panic!("{name}: not a number: {other:?}"),
        })
        .collect()
}

/// A bar chart of the move-and-settle times, written here as a small SVG (the crate's own
/// plots are wired in by the sweep's output code).
fn bar_svg(labels: &[String], ms: &[f64]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"640\" \
         height=\"260\" viewBox=\"0 0 640 260\"><rect width=\"640\" height=\"260\" \
         fill=\"#fff\"/><line x1=\"60\" y1=\"220\" x2=\"620\" y2=\"220\" stroke=\"#333\"/>",
    );
    let top = ms
        .iter()
        .cloned()
        .filter(|x| x.is_finite())
        .fold(1.0, f64::max);
    for (i, (label, &v)) in labels.iter().zip(ms).enumerate() {
        let h = if v.is_finite() {
            180.0 * v / top
        } else {
            200.0
        };
        let x = 70.0 + 90.0 * i as f64;
        let fill = if v.is_finite() { "#3b78d8" } else { "#c0392b" };
        s.push_str(&format!(
            "<rect x=\"{x}\" y=\"{}\" width=\"60\" height=\"{h}\" fill=\"{fill}\"/><text \
             x=\"{x}\" y=\"240\" font-size=\"12\">{label}</text>",
            220.0 - h
        ));
    }
    s.push_str("</svg>\n");
    s
}

/// The committed quickstart baseline as a report: its runs, per-band winners among the
/// 10 mm moves (against the slowest), a table of totals in ms, an SVG and a PNG figure.
pub fn quickstart_report() -> Report {
    let csv = repo_file("results/baselines/ci_quickstart.modal.csv");
    let mut runs = Table::from_csv("All runs", &csv).expect("baseline CSV");
    runs.note = "One row per run, as in runs.csv; times in s, lengths in um.".into();
    let profile = |i: usize| runs.rows[i][1].shown().to_string();
    let distance = column(&runs, "distance_mm");
    let mut winners = Vec::new();
    for band in ["10um", "50um"] {
        let totals = column(&runs, &format!("move_and_settle_s_{band}"));
        let at_10: Vec<usize> = (0..totals.len()).filter(|&i| distance[i] == 10.0).collect();
        let best = *at_10
            .iter()
            .min_by(|&&a, &&b| totals[a].total_cmp(&totals[b]))
            .expect("runs at 10 mm");
        let slowest = *at_10
            .iter()
            .max_by(|&&a, &&b| totals[a].total_cmp(&totals[b]))
            .expect("runs at 10 mm");
        winners.push(BandWinner {
            band: format!("10 mm move, within {}", band.replace("um", " um")),
            winner: profile(best),
            numbers: vec![Stat {
                label: "move and settle".into(),
                value: format!("{:.1} ms", totals[best] * 1e3),
            }],
            gain: Some(Gain {
                reference: Reference::Slowest {
                    label: profile(slowest),
                },
                ratio: totals[slowest] / totals[best],
                detail: format!(
                    "{:.1} ms vs {:.1} ms",
                    totals[best] * 1e3,
                    totals[slowest] * 1e3
                ),
            }),
        });
    }
    let totals = column(&runs, "move_and_settle_s_10um");
    let ms = |s: f64| Cell::Number {
        value: s * 1e3,
        text: if s.is_finite() {
            format!("{:.1}", s * 1e3)
        } else {
            "not settled".into()
        },
    };
    let table = Table {
        title: "Move and settle to within 10 um (ms)".into(),
        note: "Trapezoid and S-curve side by side per move length.".into(),
        header: vec!["distance_mm".into(), "trapezoid".into(), "scurve".into()],
        rows: (0..totals.len() / 2)
            .map(|k| {
                vec![
                    Cell::number(distance[2 * k]),
                    ms(totals[2 * k]),
                    ms(totals[2 * k + 1]),
                ]
            })
            .collect(),
    };
    let labels: Vec<String> = (0..totals.len())
        .map(|i| format!("{} {}", profile(i), distance[i]))
        .collect();
    let ms_all: Vec<f64> = totals.iter().map(|s| s * 1e3).collect();
    let gradient = image::RgbImage::from_fn(200, 40, |x, y| {
        image::Rgb([(x * 255 / 199) as u8, (y * 6) as u8, 128])
    });
    let mut png = Vec::new();
    image::DynamicImage::ImageRgb8(gradient)
        .write_to(
            &mut std::io::Cursor::new(&mut png),
            image::ImageOutputFormat::Png,
        )
        .expect("PNG encodes");
    Report {
        title: "ci_quickstart".into(),
        intro: vec![
            "CI gate: 40 Hz, zeta 0.05 axis; trapezoid vs S-curve at 0.5, 2 and 10 mm.".into(),
            "Backend modal, 6 runs, 0.2 s observation windows.".into(),
        ],
        winners,
        tables: vec![table],
        sections: Vec::new(),
        figures: vec![
            Figure {
                title: "Move and settle to within 10 um (ms; red: not settled)".into(),
                image: Image::Svg(bar_svg(&labels, &ms_all)),
            },
            Figure {
                title: "A PNG figure (colour gradient)".into(),
                image: Image::Png(png),
            },
        ],
        runs: Some(runs),
        failed: Vec::new(),
        provenance: Provenance {
            settle_version: "0.1.0".into(),
            backend: "modal".into(),
            command_line: "settle sweep scenarios/ci_quickstart.toml --out results/quick".into(),
            date: "2025-01-01".into(),
            facts: Vec::new(),
            inputs: vec![InputFile {
                name: "scenarios/ci_quickstart.toml".into(),
                text: repo_file("scenarios/ci_quickstart.toml"),
            }],
        },
    }
}

/// Deterministic pseudo-random numbers (SplitMix64).
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A table like the quickstart's runs.csv (the same 26 columns) with `n` generated runs:
/// three profiles, 5 % lost steps, 5 % faults, random numbers, 10 % of the settling times
/// `inf` (not settled).
pub fn generated_csv(n: usize) -> String {
    let baseline = repo_file("results/baselines/ci_quickstart.modal.csv");
    let header: Vec<&str> = baseline
        .lines()
        .next()
        .expect("header")
        .split(',')
        .collect();
    let mut s = 1u64;
    let mut csv = format!("{}\n", header.join(","));
    for i in 0..n {
        let (status, reason) = match splitmix(&mut s) % 20 {
            0 => ("lost_steps", "lost 4 steps (load angle past 90 deg)"),
            1 => ("fault", "simulation diverged"),
            _ => ("ok", ""),
        };
        let cells: Vec<String> = header
            .iter()
            .map(|&name| {
                let r = splitmix(&mut s);
                let unit = (r >> 11) as f64 / (1u64 << 53) as f64;
                match name {
                    "run" => i.to_string(),
                    "profile" => ["trapezoid", "scurve", "fourjerk"][(r % 3) as usize].into(),
                    "machine" => "modes".into(),
                    "axis" => "x".into(),
                    "driver" => "linear".into(),
                    "backend" => "modal".into(),
                    "status" => status.into(),
                    "reason" => reason.into(),
                    "lost_steps" => u64::from(status == "lost_steps").to_string(),
                    n if n.starts_with("settle_time") || n.starts_with("move_and_settle") => {
                        if r.is_multiple_of(10) {
                            "inf".into()
                        } else {
                            (unit * 0.3).to_string()
                        }
                    }
                    _ => (unit * 100.0).to_string(),
                }
            })
            .collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    csv
}
