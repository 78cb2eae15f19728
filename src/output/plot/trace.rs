//! The time-series figure of one run (`settle run ... --plot`).
//!
//! One panel per signal group and unit (the groups of [`crate::output::sink::groups`]; e.g. the
//! commanded position, velocity, acceleration and jerk, the toolhead, the error), stacked on
//! one time axis, with the end of the move marked. Every channel whose name ends in `error`
//! (in m) gets a second panel zoomed on the time after the move, in um, with the settling
//! bands and where the error settled into each. Lengths are shown in mm (um when the
//! signal stays below 1 mm). A raster scan's run adds its scan view
//! (`super::scan_trace`). Long traces are reduced to at most [`MAX_POINTS`] per line by
//! keeping each bucket's minimum and maximum, so peaks survive.

use super::{Figure, Line, PALETTE, Panel, Rule, fmt_num};
use crate::measure::series::Series;
use crate::output::sink::RunRecord;
use crate::output::sink::groups::groups;

/// Points per drawn line at most.
pub const MAX_POINTS: usize = 4000;

/// Display unit and factor for a series unit, given the largest |value|.
fn display_unit(unit: &str, max_abs: f64) -> (String, f64) {
    let base = |per: &str| -> (String, f64) {
        if unit == "m" && max_abs < 1e-3 {
            ("um".to_string(), 1e6)
        } else {
            (format!("mm{per}"), 1e3)
        }
    };
    match unit {
        "m" => base(""),
        "m_s" => base("/s"),
        "m_s2" => base("/s^2"),
        "m_s3" => base("/s^3"),
        other => (other.to_string(), 1.0),
    }
}

/// Min-max decimation of `(t, y)` to about `max` points.
pub fn decimate(t: &[f64], y: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = t.len().min(y.len());
    if n <= max {
        return t.iter().copied().zip(y.iter().copied()).take(n).collect();
    }
    let bucket = n.div_ceil(max / 2);
    let mut out = Vec::with_capacity(max + 2);
    let mut i = 0;
    while i < n {
        let end = (i + bucket).min(n);
        let (mut lo, mut hi) = (i, i);
        for k in i..end {
            if y[k] < y[lo] {
                lo = k;
            }
            if y[k] > y[hi] {
                hi = k;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push((t[a], y[a]));
        if b != a {
            out.push((t[b], y[b]));
        }
        i = end;
    }
    out
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The run's figure. `title` names the run.
pub fn figure(title: &str, rec: &RunRecord) -> Figure {
    let s: &Series = rec.series;
    let move_end = rec.row.num(0, "move_time_s").unwrap_or(0.0);
    let end_rule = Rule {
        at: move_end,
        label: "move ends".into(),
    };
    let mut panels = Vec::new();
    let mut color_i = 0;
    for g in groups(s) {
        let mut units: Vec<&str> = Vec::new();
        for f in &g.fields {
            if !units.contains(&f.unit.as_str()) {
                units.push(&f.unit);
            }
        }
        for u in units {
            let fields: Vec<_> = g.fields.iter().filter(|f| f.unit == u).collect();
            let m = fields
                .iter()
                .map(|f| max_abs(&s.channels[f.channel].data))
                .fold(0.0, f64::max);
            let (shown, k) = display_unit(u, m);
            let lines = fields
                .iter()
                .map(|f| {
                    let y: Vec<f64> = s.channels[f.channel].data.iter().map(|v| v * k).collect();
                    let c = PALETTE[color_i % PALETTE.len()];
                    color_i += 1;
                    Line::new(
                        (fields.len() > 1).then(|| f.channel_name.clone()),
                        c,
                        decimate(&s.t_s, &y, MAX_POINTS),
                    )
                })
                .collect();
            let names: Vec<&str> = fields.iter().map(|f| f.channel_name.as_str()).collect();
            panels.push(Panel {
                title: names.join(", "),
                x_label: "time (s)".into(),
                y_label: shown,
                lines,
                vrules: vec![end_rule.clone()],
                legend: true,
                ..Panel::default()
            });
        }
    }
    // Zoom on the residual after the move, with the bands.
    for c in s
        .channels
        .iter()
        .filter(|c| c.name.ends_with("error") && c.unit == "m")
    {
        let start = s.t_s.partition_point(|&t| t < move_end);
        let t = &s.t_s[start..];
        let y: Vec<f64> = c.data[start..].iter().map(|v| v * 1e6).collect();
        if t.is_empty() {
            continue;
        }
        let mut hrules = Vec::new();
        let mut vrules = vec![end_rule.clone()];
        let peak = max_abs(&y);
        // A length (e.g. the error vector's) is never negative: no lower band then.
        let signed = y.iter().any(|v| *v < 0.0);
        for b in &rec.spec.bands_um {
            // Bands far outside the residual would squash it: show those that matter.
            if *b <= 3.0 * peak.max(1e-9) {
                hrules.push(Rule {
                    at: *b,
                    label: format!("+{} um", fmt_num(*b)),
                });
                if signed {
                    hrules.push(Rule {
                        at: -b,
                        label: format!("-{} um", fmt_num(*b)),
                    });
                }
            }
            let settle = rec.row.num(0, &format!("settle_time_s_{b}um"));
            match settle {
                Some(st) if st.is_finite() && st > 0.0 => vrules.push(Rule {
                    at: move_end + st,
                    label: format!("in {} um after {:.1} ms", fmt_num(*b), st * 1e3),
                }),
                Some(st) if st.is_infinite() => {}
                _ => {}
            }
        }
        let mut l = Line::new(None, PALETTE[2], decimate(t, &y, MAX_POINTS));
        l.width = 2;
        panels.push(Panel {
            title: format!(
                "{} after the move (residual vibration), settling bands dashed",
                c.name
            ),
            x_label: "time (s)".into(),
            y_label: "um".into(),
            lines: vec![l],
            vrules,
            hrules,
            ..Panel::default()
        });
    }
    Figure {
        title: title.to_string(),
        panels,
        columns: 1,
        width: 1400,
        row_height: 260,
        legend: Vec::new(),
    }
}
