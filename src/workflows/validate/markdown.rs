//! The Markdown tables of `settle validate`.

use std::fmt::Write as _;

use super::{DAMPING_PCT, ENGINES_PCT, FREQUENCY_PCT, RESIDUAL_FLOOR_UM, RESIDUAL_PCT, Validation};

fn ms(t: Option<f64>) -> String {
    t.map_or("-".into(), |t| format!("{:.1}", t * 1e3))
}

fn ms_all(t: &[Option<f64>]) -> String {
    t.iter().map(|t| ms(*t)).collect::<Vec<_>>().join(" / ")
}

fn bands(b: &[f64]) -> String {
    b.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(" / ")
}

/// The report as Markdown tables.
pub fn markdown(r: &Validation) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Linear driver, belt stiffness frozen at the start (the model the closed form solves). \
Thresholds: frequency {FREQUENCY_PCT} %, residual {RESIDUAL_PCT} % (of the closed form, or of \
{RESIDUAL_FLOOR_UM} um if smaller), settle time and engines {ENGINES_PCT} % (or one sample), \
numerical damping {DAMPING_PCT} % of the physical. Settle times to {} um.\n",
        bands(&r.bands_um)
    );
    let _ = writeln!(
        out,
        "| case | backend | f analytic Hz | f measured Hz | df % | zeta analytic | zeta measured | num. damping % | residual closed form um | residual um | dr % | settle modal ms | settle ms | vs first engine % | result |"
    );
    let _ = writeln!(out, "|---|---|{}", "---:|".repeat(13));
    for row in &r.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.3} | {:.3} | {:+.4} | {:.4} | {:.4} | {:+.2} | {:.3} | {:.3} | {:+.3} | {} | {} | {} | {} |",
            row.case,
            row.backend,
            row.f_analytic_hz,
            row.f_measured_hz,
            row.f_err_pct(),
            row.zeta_analytic,
            row.zeta_measured,
            row.damping_pct(),
            row.residual_closed_um,
            row.residual_um,
            row.residual_err_pct(),
            ms_all(&row.settle_modal_s),
            ms_all(&row.settle_s),
            row.engine_pct.map_or("-".into(), |d| format!("{d:+.2}")),
            if row.failures.is_empty() {
                "ok".to_string()
            } else {
                format!("**FAIL** ({})", row.failures.join(", "))
            }
        );
    }
    if let Some(first) = r.effects.first() {
        let engine = first
            .full_driver
            .first()
            .map_or("rapier".to_string(), |f| f.0.to_string());
        let _ = writeln!(
            out,
            "\nWhat the linear model leaves out ({engine}, middle distances; the full driver on every engine; \
information, no thresholds): residual peak um / settle ms to {} um.\n",
            r.bands_um[0]
        );
        let mut head = "| case | linear, frozen belt | belt stiffness varying |".to_string();
        let mut rule = "|---|---:|---:|".to_string();
        for f in &first.full_driver {
            head.push_str(&format!(" + full stepper driver ({}) |", f.0));
            rule.push_str("---:|");
        }
        let _ = writeln!(out, "{head}\n{rule}");
        for e in &r.effects {
            let mut line = format!(
                "| {} | {:.3} / {} | {:.3} / {} |",
                e.case,
                e.linear.0,
                ms(e.linear.1),
                e.varying_belt.0,
                ms(e.varying_belt.1),
            );
            for f in &e.full_driver {
                let lost = if f.3 > 0 {
                    format!(" (lost {} steps)", f.3)
                } else {
                    String::new()
                };
                line.push_str(&format!(" {:.3} / {}{lost} |", f.1, ms(f.2)));
            }
            let _ = writeln!(out, "{line}");
        }
    }
    out
}
