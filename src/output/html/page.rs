//! The page around the tables: head (inline style, a content policy that forbids any
//! fetch), title and intro, winner cards, figures, failed runs, provenance, inline script.

use super::Out;
use super::escape::{base64, escaped, push_escaped};
use super::grid::{push_csv_table, push_made_table, push_table, push_table_at};
use super::model::{
    BandWinner, Cell, Figure, Image, Provenance, Reference, Report, Rows, Section, Table,
};
use crate::error::Error;

const STYLE: &str = include_str!("style.css");
const SCRIPT: &str = include_str!("script.js");

/// Everything the page may load: nothing from the network; images only as `data:` URIs;
/// style and script only inline. A blocked load shows as a console error.
const CONTENT_POLICY: &str =
    "default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'unsafe-inline'";

/// The whole page.
pub(crate) fn page(r: &Report) -> String {
    let mut out = String::with_capacity(64 * 1024);
    // Only a figure given as a file can fail, and then it is left out.
    let _ = page_to(&mut out, r, None, &());
    out
}

/// The whole page, written to `out`; `runs_csv` (title, CSV text) is the table of every
/// run when `r.runs` is `None`, written a record at a time. The error is a figure file
/// that cannot be read.
pub(crate) fn page_to(
    out: &mut impl Out,
    r: &Report,
    runs_csv: Option<(&str, &str)>,
    rows: &dyn Rows,
) -> Result<(), Error> {
    out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    let _ = writeln!(
        out,
        "<meta http-equiv=\"Content-Security-Policy\" content=\"{CONTENT_POLICY}\">"
    );
    out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    let _ = writeln!(
        out,
        "<meta name=\"generator\" content=\"settle {}\">",
        escaped(&r.provenance.settle_version)
    );
    let _ = writeln!(out, "<title>{}</title>", escaped(&r.title));
    let _ = writeln!(out, "<style>\n{STYLE}</style>\n</head>\n<body>");
    let _ = writeln!(out, "<header>\n<h1>{}</h1>", escaped(&r.title));
    for line in &r.intro {
        let _ = writeln!(out, "<p>{}</p>", escaped(line));
    }
    out.push_str("</header>\n");
    push_winners(out, &r.winners);
    for (i, t) in r.tables.iter().enumerate() {
        let id = format!("table-{}", i + 1);
        if t.rows.is_empty() && rows.row(i, 0).is_some() {
            push_made_table(out, &id, t, |k| rows.row(i, k));
        } else {
            push_table(out, &id, t);
        }
    }
    let mut next = r.tables.len();
    for s in &r.sections {
        push_section(out, s, &mut next)?;
    }
    push_figures(out, &r.figures)?;
    if let Some(runs) = &r.runs {
        push_table(out, "runs", runs);
    } else if let Some((title, text)) = runs_csv {
        push_csv_table(out, "runs", title, text);
    }
    if !r.failed.is_empty() {
        let failed = Table {
            title: format!("Failed runs ({})", r.failed.len()),
            note: "These runs produced no numbers and are never compared or averaged.".into(),
            header: vec!["run".into(), "status".into(), "reason".into()],
            rows: r
                .failed
                .iter()
                .map(|f| {
                    vec![
                        Cell::text(f.run.as_str()),
                        Cell::text(f.status.as_str()),
                        Cell::text(f.reason.as_str()),
                    ]
                })
                .collect(),
        };
        push_table(out, "failed", &failed);
    }
    push_provenance(out, &r.provenance);
    let _ = write!(out, "<script>\n{SCRIPT}</script>\n</body>\n</html>\n");
    Ok(())
}

/// The gain as shown large, and the sentence naming the reference.
fn gain_text(ratio: f64, reference: &Reference) -> (String, String) {
    let (who, label) = match reference {
        Reference::Current { label } => ("your current settings", label),
        Reference::Slowest { label } => ("the slowest candidate", label),
    };
    let headline = if ratio.is_infinite() && ratio > 0.0 {
        "reference never settles".to_string()
    } else if ratio > 1.0 {
        let pct = (ratio - 1.0) * 100.0;
        if pct < 10.0 {
            format!("+{pct:.1} %")
        } else {
            format!("+{pct:.0} %")
        }
    } else {
        "no gain".to_string()
    };
    (headline, format!("vs {who}: {label}"))
}

fn push_winners(out: &mut impl Out, winners: &[BandWinner]) {
    if winners.is_empty() {
        return;
    }
    out.push_str(
        "<section id=\"winners\">\n<h2>Winner per band</h2>\n<p class=\"note\">Gain: how much \
longer the reference takes than the winner.</p>\n<div class=\"cards\">\n",
    );
    for w in winners {
        let _ = write!(
            out,
            "<article class=\"card\">\n<h3>{}</h3>\n<p class=\"winner\">{}</p>\n",
            escaped(&w.band),
            escaped(&w.winner)
        );
        if !w.numbers.is_empty() {
            out.push_str("<dl class=\"stats\">");
            for s in &w.numbers {
                let _ = write!(
                    out,
                    "<dt>{}</dt><dd>{}</dd>",
                    escaped(&s.label),
                    escaped(&s.value)
                );
            }
            out.push_str("</dl>\n");
        }
        if let Some(g) = &w.gain {
            let (headline, reference) = gain_text(g.ratio, &g.reference);
            let class = if g.ratio > 1.0 { "gain" } else { "gain none" };
            let _ = writeln!(
                out,
                "<p class=\"{class}\">{}</p>\n<p class=\"ref\">{}</p>",
                escaped(&headline),
                escaped(&reference)
            );
            if !g.detail.is_empty() {
                let _ = writeln!(out, "<p class=\"detail\">{}</p>", escaped(&g.detail));
            }
        }
        out.push_str("</article>\n");
    }
    out.push_str("</div>\n</section>\n");
}

/// SVG markup without a leading XML declaration or doctype (both are out of place inside
/// HTML).
fn inline_svg(svg: &str) -> &str {
    let mut s = svg.trim_start();
    for opener in ["<?xml", "<!DOCTYPE", "<!doctype"] {
        if s.starts_with(opener)
            && let Some(end) = s.find('>')
        {
            s = s[end + 1..].trim_start();
        }
    }
    s
}

/// The SVG file at `path`, inline ([`inline_svg`]), copied a line at a time: a figure of
/// many runs (a marker per run) is never held whole. Its head (whole lines, the whole
/// file when it is under 64 KB) is trimmed as [`inline_svg`] trims a document.
fn push_svg_file(out: &mut impl Out, path: &std::path::Path) -> Result<(), Error> {
    use std::io::BufRead as _;
    let file = crate::input::file::open(path, crate::input::file::limit::RESULTS)?;
    let mut r = std::io::BufReader::new(file);
    let mut head = String::new();
    while head.len() < 1 << 16 {
        if r.read_line(&mut head)
            .map_err(|e| crate::input::file::stream_error(path, e))?
            == 0
        {
            break;
        }
    }
    out.push_str(inline_svg(&head));
    let mut line = String::new();
    loop {
        line.clear();
        if r.read_line(&mut line)
            .map_err(|e| crate::input::file::stream_error(path, e))?
            == 0
        {
            return Ok(());
        }
        out.push_str(&line);
    }
}

/// A [`Section`]: heading, paragraphs, its tables (numbered on from `next`, as
/// `table-N`), figures and texts.
fn push_section(out: &mut impl Out, s: &Section, next: &mut usize) -> Result<(), Error> {
    out.push_str("<section class=\"part\" id=\"");
    push_escaped(out, &s.id);
    out.push_str("\">\n<h2>");
    push_escaped(out, &s.title);
    out.push_str("</h2>\n");
    for line in &s.intro {
        let _ = writeln!(out, "<p>{}</p>", escaped(line));
    }
    for t in &s.tables {
        *next += 1;
        push_table_at(out, &format!("table-{next}"), t, "h3");
    }
    for (i, f) in s.figures.iter().enumerate() {
        push_figure(out, &format!("{}-figure-{}", s.id, i + 1), f)?;
    }
    for t in &s.texts {
        out.push_str("<div class=\"file\">\n<h3>");
        push_escaped(out, &t.name);
        out.push_str("</h3>\n<pre>\n");
        push_escaped(out, &t.text);
        out.push_str("</pre>\n</div>\n");
    }
    out.push_str("</section>\n");
    Ok(())
}

/// One figure, with element id `id`.
fn push_figure(out: &mut impl Out, id: &str, f: &Figure) -> Result<(), Error> {
    out.push_str("<figure id=\"");
    push_escaped(out, id);
    out.push_str("\">\n<div class=\"img\">");
    match &f.image {
        Image::Svg(svg) => out.push_str(inline_svg(svg)),
        Image::SvgFile(path) => push_svg_file(out, path)?,
        Image::Png(bytes) => {
            let _ = write!(
                out,
                "<img alt=\"{}\" src=\"data:image/png;base64,{}\">",
                escaped(&f.title),
                base64(bytes)
            );
        }
    }
    let _ = writeln!(
        out,
        "</div>\n<figcaption>{}</figcaption>\n</figure>",
        escaped(&f.title)
    );
    Ok(())
}

fn push_figures(out: &mut impl Out, figures: &[Figure]) -> Result<(), Error> {
    if figures.is_empty() {
        return Ok(());
    }
    out.push_str("<section id=\"figures\">\n<h2>Figures</h2>\n");
    for (i, f) in figures.iter().enumerate() {
        push_figure(out, &format!("figure-{}", i + 1), f)?;
    }
    out.push_str("</section>\n");
    Ok(())
}

fn push_provenance(out: &mut impl Out, p: &Provenance) {
    out.push_str("<section id=\"provenance\">\n<h2>Provenance</h2>\n<dl class=\"prov\">\n");
    for (label, value, code) in [
        ("settle version", &p.settle_version, false),
        ("backend", &p.backend, false),
        ("command line", &p.command_line, true),
        ("date", &p.date, false),
    ] {
        if value.is_empty() {
            continue;
        }
        let _ = write!(out, "<dt>{label}</dt><dd>");
        if code {
            out.push_str("<code>");
        }
        push_escaped(out, value);
        out.push_str(if code { "</code></dd>\n" } else { "</dd>\n" });
    }
    for f in &p.facts {
        let _ = writeln!(
            out,
            "<dt>{}</dt><dd>{}</dd>",
            escaped(&f.label),
            escaped(&f.value)
        );
    }
    out.push_str("</dl>\n");
    // The newline after `<pre>` is dropped by every HTML parser: a text starting with a
    // line break keeps it.
    for f in &p.inputs {
        let _ = write!(
            out,
            "<details>\n<summary>{}</summary>\n<pre>\n",
            escaped(&f.name)
        );
        push_escaped(out, &f.text);
        out.push_str("</pre>\n</details>\n");
    }
    out.push_str("</section>\n");
}
