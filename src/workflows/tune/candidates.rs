//! Every candidate of every tuned axis: `candidates.csv` (full precision, one row per
//! candidate with its acceleration, Klipper's smoothing, the largest acceleration within
//! the smoothing limit, its figures and whether it is out and why), and the same rows for
//! report.html, rounded to what they mean.

use super::Outcome;
use super::search::Score;
use crate::input::runs_table::record;
use crate::output::html::{Cell, Table};

/// The columns of `candidates.csv`.
const COLUMNS: [&str; 19] = [
    "axis",
    "candidate",
    "profile",
    "jmax_mm_s3",
    "pvt_asym_ki",
    "bow_scales",
    "shaper_type",
    "shaper_frequency_hz",
    "shaper_damping_ratio",
    "accel_mm_s2",
    "smoothing_mm",
    "max_accel_mm_s2",
    "move_time_s",
    "residual_peak_um",
    "simulated_move_and_settle_s",
    "move_and_settle_s",
    "max_contour_error_um",
    "status",
    "reason",
];

/// The shaper's type, frequency and damping ratio as text (`none` and empty cells when
/// unshaped).
fn shaper_cells(s: &Score) -> (String, Option<f64>, Option<f64>) {
    match s.candidate.shaper.and_then(|sh| {
        sh.shaper_type
            .map(|k| (k, sh.frequency_hz, sh.damping_ratio))
    }) {
        Some((k, f, z)) => (k.name().to_string(), Some(f), Some(z)),
        None => ("none".to_string(), None, None),
    }
}

/// `ok` or `out`, and the reason.
fn standing(s: &Score) -> (&'static str, String) {
    match &s.infeasible {
        None => ("ok", String::new()),
        Some(why) => ("out", why.short()),
    }
}

/// `candidates.csv`: every candidate of every tuned axis (see the module documentation).
/// `move_and_settle_s` is the ranking key (infinite for a candidate out of the running),
/// `simulated_move_and_settle_s` what the simulation gave.
pub fn csv(axes: &[(String, Outcome)]) -> String {
    let mut out = record(&COLUMNS);
    let opt = |x: Option<f64>| x.map_or(String::new(), |v| v.to_string());
    for (axis, o) in axes {
        for (i, s) in o.scores.iter().enumerate() {
            let c = &s.candidate;
            let b = c.params.fourjerk_jerk_scale;
            let (st, sf, sz) = shaper_cells(s);
            let (status, reason) = standing(s);
            out.push_str(&record(&[
                axis.clone(),
                i.to_string(),
                c.kind.to_string(),
                opt(c.jmax_mm_s3),
                c.params.pvt_asym_ki.to_string(),
                format!("{}/{}/{}/{}", b[0], b[1], b[2], b[3]),
                st,
                opt(sf),
                opt(sz),
                s.accel_mm_s2.to_string(),
                s.smoothing_mm.to_string(),
                s.max_accel_mm_s2.to_string(),
                s.move_time_s.to_string(),
                s.residual_peak_um.to_string(),
                s.simulated_move_and_settle_s.to_string(),
                s.move_and_settle_s.to_string(),
                opt(Some(s.max_contour_error_um).filter(|x| !x.is_nan())),
                status.to_string(),
                reason,
            ]));
        }
    }
    out
}

/// A number cell shown with `digits` decimals (`inf` shown as `not settled` when `inf` is
/// given, else as `-`), sorted by its value.
fn num(value: f64, digits: usize, inf: Option<&str>) -> Cell {
    let text = if value.is_finite() {
        format!("{value:.digits$}")
    } else if value.is_infinite() {
        inf.unwrap_or("-").to_string()
    } else {
        String::new()
    };
    Cell::Number { value, text }
}

/// The candidates for report.html: the rows of [`csv()`] with times in ms (0.1 ms),
/// residuals to 0.01 um, smoothing to 0.001 mm, accelerations to 1 mm/s^2.
pub fn table(axes: &[(String, Outcome)]) -> Table {
    let header = [
        "axis",
        "candidate",
        "accel (mm/s^2)",
        "smoothing (mm)",
        "max_accel (mm/s^2)",
        "move (ms)",
        "residual peak (um)",
        "move+settle (ms)",
        "status",
    ];
    let mut rows = Vec::new();
    for (axis, o) in axes {
        for (i, s) in o.scores.iter().enumerate() {
            let tag = if i == 0 {
                " (current)"
            } else if i == o.winner {
                " (recommended)"
            } else {
                ""
            };
            rows.push(vec![
                Cell::text(axis.as_str()),
                Cell::text(format!("{}{tag}", s.candidate.label())),
                num(s.accel_mm_s2, 0, None),
                num(s.smoothing_mm, 3, None),
                num(s.max_accel_mm_s2, 0, None),
                num(s.move_time_s * 1e3, 1, None),
                num(s.residual_peak_um, 2, None),
                num(s.simulated_move_and_settle_s * 1e3, 1, Some("not settled")),
                Cell::text(super::cells::status(s)),
            ]);
        }
    }
    Table {
        title: "Every candidate".into(),
        note: "Rounded; candidates.csv holds every digit. `out` candidates never win: the status says why.".into(),
        header: header.iter().map(|h| h.to_string()).collect(),
        rows,
    }
}
