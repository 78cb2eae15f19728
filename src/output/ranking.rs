//! The ranking behind summary.md and report.html: every swept setting compared, per swept
//! point of the workload, and the overall winner per band.
//!
//! The swept keys split in two. *Settings* are what a user chooses between: the profile
//! kind, the input shaper, the corner strategy, the machine, the limits, a scan's fly-axis
//! limits. *Workload* keys describe the job the settings are compared on: the move length,
//! the corner angle and legs, the scan's speed and width ([`is_setting`]). A *candidate* is
//! one combination of the swept settings; for each workload point its runs are ranked by
//! move-and-settle time, and the overall winner of a band is the candidate with the least
//! move-and-settle time summed over every workload point (among the candidates that settle
//! at all of them).
//!
//! Gains follow report.html's convention: `reference time / candidate time - 1`, so
//! `+38 %` means the reference takes 38 % longer than the candidate. The reference is the
//! scenario's `[current]` candidate when it has one, else the slowest candidate of the
//! point (labelled so).
//!
//! Everything is read from the runs table (like the rest of the summary), so a summary
//! rebuilt from a merged `runs.csv` is the same.

use std::path::Path;

use settle_planner::shaper::{Shaper, ShaperKind};

use crate::input::runs_table::RunsTable;
use crate::input::scenario::Scenario;
use crate::output::runs_csv::band_label;
use crate::spec::backend::Backend;
use crate::spec::run_spec::RunSpec;
use crate::spec::value::Value;

/// Whether swept key `key` is a setting (compared) rather than part of the workload
/// (grouped by): see the module documentation.
pub fn is_setting(key: &str) -> bool {
    const WORKLOAD: [&str; 8] = [
        "move.distance_mm",
        "move.start_mm",
        "corner.angle_deg",
        "corner.leg_in_mm",
        "corner.leg_out_mm",
        "scan.v_scan_mm_s",
        "scan.width_mm",
        "scan.settle_margin_s",
    ];
    !WORKLOAD.contains(&key)
}

/// A value as a candidate's label shows it: names as they are, numbers as `key=value` with
/// the key's last part (`frequency_hz=52`).
pub fn label_part(key: &str, v: &Value) -> String {
    match v {
        Value::Number(x) => format!("{}={x}", key.rsplit('.').next().unwrap_or(key)),
        other => other.to_string(),
    }
}

/// One run in a band's ranking.
#[derive(Debug, Clone, PartialEq)]
pub struct Ranked {
    /// Row in the runs table (= index into the runs).
    pub row: usize,
    /// The run's id (`--case`).
    pub id: usize,
    /// 1 for the fastest of its point; `None` for a failed or unsettled run.
    pub rank: Option<usize>,
    /// The candidate: its setting values, as shown (one per setting key).
    pub settings: Vec<String>,
    /// The candidate's label (the settings joined by `, `).
    pub label: String,
    /// Move time (s).
    pub move_s: f64,
    /// Settle time (s); `None` when not settled in the window.
    pub settle_s: Option<f64>,
    /// Move and settle (s); `None` when not settled.
    pub total_s: Option<f64>,
    /// Residual peak after the move (um).
    pub residual_peak_um: f64,
    /// `reference time / this time - 1` (see the module doc); `None` without both times.
    pub gain: Option<f64>,
    /// Whether this run is the scenario's `[current]` candidate.
    pub current: bool,
    /// Why the run failed (status, reason); `None` when it ran.
    pub failure: Option<String>,
    /// Shaper figures when shapers are swept: smoothing (mm), remaining vibration (%),
    /// Klipper's suggested max_accel (mm/s^2).
    pub shaper: Option<[Option<f64>; 3]>,
}

/// One workload point of a band: its runs, fastest first.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The workload values, as shown (one per workload key).
    pub workload: Vec<String>,
    /// The reference of the gains: `(label, total s)`.
    pub reference: Option<(String, Option<f64>)>,
    /// The runs, ranked ones first (fastest first), then the unsettled and failed ones.
    pub runs: Vec<Ranked>,
}

/// The overall winner of a band.
#[derive(Debug, Clone, PartialEq)]
pub struct Winner {
    /// The candidate's label.
    pub label: String,
    /// Its move-and-settle time summed over every workload point (s).
    pub total_s: f64,
    /// The workload points summed over.
    pub points: usize,
    /// The reference: `(label, summed time s; infinite when it fails to settle somewhere)`.
    pub reference: Option<(String, f64)>,
}

/// One band's ranking.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// The band (um).
    pub band_um: f64,
    /// Per workload point.
    pub points: Vec<Point>,
    /// The overall winner; `None` when no candidate settles at every point.
    pub winner: Option<Winner>,
    /// Every candidate with its move-and-settle time summed over the workload points, in
    /// the order of the overall ranking: those that settle at every point by that sum
    /// (ties: the lower run number first), then the others, then those with a failed run.
    pub candidates: Vec<Candidate>,
}

/// One candidate of a band, over every workload point.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Its label (the settings joined by `, `).
    pub label: String,
    /// Move and settle summed over every workload point (s); `None` when it does not
    /// settle at one of them, or a run failed.
    pub total_s: Option<f64>,
    /// Its runs' ids, in workload order.
    pub runs: Vec<usize>,
    /// Whether it is the scenario's `[current]` candidate.
    pub current: bool,
    /// Whether one of its runs failed.
    pub failed: bool,
}

/// The ranking of a sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Ranking {
    /// The swept settings compared (sweep order).
    pub setting_keys: Vec<String>,
    /// The swept workload keys grouped by (sweep order).
    pub workload_keys: Vec<String>,
    /// Whether the scenario names a `[current]` candidate.
    pub has_current: bool,
    /// The label of the `[current]` candidate, when it names one.
    pub current_label: Option<String>,
    /// Whether shapers are swept (the shaper columns are shown).
    pub shapers: bool,
    /// Per band.
    pub bands: Vec<Band>,
}

/// Whether `run` is the `[current]` candidate of `sc` (every key given matches).
pub fn is_current(sc: &Scenario, run: &RunSpec) -> bool {
    !sc.current.is_empty()
        && sc.current.iter().all(|(k, v)| {
            run.swept
                .iter()
                .any(|(p, s)| p == k && crate::expand::current::same(v, s))
        })
}

/// The command that runs case `id` alone: `settle run SCENARIO --case N`, with `--backend`
/// when the run's backend is not the default.
pub fn run_command(scenario: &Path, run: &RunSpec) -> String {
    let backend = if run.backend == Backend::default() {
        String::new()
    } else {
        format!(" --backend {}", run.backend)
    };
    format!(
        "settle run {} --case {}{backend}",
        scenario.display(),
        run.id
    )
}

/// Klipper's suggested max_accel (mm/s^2) for the shaper in columns `shaper_type`,
/// `shaper_frequency_hz`, `shaper_damping_ratio` of `row`; `None` for no shaper.
fn max_accel(table: &RunsTable, row: usize) -> Option<f64> {
    let kind = ShaperKind::parse(table.cell(row, "shaper_type")?).ok()?;
    let sh = Shaper::new(
        kind,
        table.num(row, "shaper_frequency_hz")?,
        table.num(row, "shaper_damping_ratio")?,
    )
    .ok()?;
    Some(settle_planner::shaper_select::max_accel_mm_s2(
        sh.amplitudes(),
        sh.times_s(),
        crate::kinds::shaping::SMOOTHING_SCV_MM_S,
        settle_planner::shaper_select::TARGET_SMOOTHING_MM,
    ))
}

/// Rank `runs` (row `i` of `table` is `runs[i]`).
pub fn rank(sc: &Scenario, runs: &[RunSpec], table: &RunsTable) -> Ranking {
    let keys: Vec<String> = runs
        .first()
        .map(|r| r.swept.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();
    let setting_keys: Vec<String> = keys.iter().filter(|k| is_setting(k)).cloned().collect();
    let workload_keys: Vec<String> = keys.iter().filter(|k| !is_setting(k)).cloned().collect();
    // The values of a run's settings (`setting`) or workload, as shown in the tables.
    let values = |r: &RunSpec, setting: bool| -> Vec<String> {
        r.swept
            .iter()
            .filter(|(p, _)| is_setting(p) == setting)
            .map(|(_, v)| v.to_string())
            .collect()
    };
    let label = |r: &RunSpec| {
        let s: Vec<String> = r
            .swept
            .iter()
            .filter(|(p, _)| is_setting(p))
            .map(|(p, v)| label_part(p, v))
            .collect();
        if s.is_empty() {
            r.profile.to_string()
        } else {
            s.join(", ")
        }
    };
    // Workload points, first-seen order (found through an index: a sweep of many points
    // must not search them all for every run).
    let mut groups: Vec<(Vec<String>, Vec<usize>)> = Vec::new();
    let mut group_of: std::collections::HashMap<Vec<String>, usize> =
        std::collections::HashMap::new();
    for (i, r) in runs.iter().enumerate() {
        let w = values(r, false);
        match group_of.get(&w) {
            Some(&g) => groups[g].1.push(i),
            None => {
                group_of.insert(w.clone(), groups.len());
                groups.push((w, vec![i]));
            }
        }
    }
    let shapers = setting_keys.iter().any(|k| k.starts_with("shaper."))
        && table.column("smoothing_mm").is_some();
    let current_label = runs.iter().find(|r| is_current(sc, r)).map(label);
    let bands_um = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    let mut bands = Vec::new();
    for band in bands_um {
        let b = band_label(band);
        let mut points = Vec::new();
        let mut sums: Vec<(String, f64, usize)> = Vec::new();
        // `sums` and `candidates` list the same labels in the same order; `sum_of` indexes both.
        let mut candidates: Vec<Candidate> = Vec::new();
        let mut sum_of: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
        for (workload, idx) in &groups {
            let mut ranked: Vec<Ranked> = idx
                .iter()
                .map(|&i| {
                    let ok = table.cell(i, "status").is_none_or(|s| s == "ok");
                    let time = |c: &str| table.num(i, c).filter(|x| x.is_finite() && ok);
                    let failure = (!ok).then(|| {
                        let status = table.cell(i, "status").unwrap_or_default();
                        match table.cell(i, "reason").filter(|s| !s.is_empty()) {
                            Some(reason) => format!("{status}: {reason}"),
                            None => status.to_string(),
                        }
                    });
                    Ranked {
                        row: i,
                        id: runs[i].id,
                        rank: None,
                        settings: values(&runs[i], true),
                        label: label(&runs[i]),
                        move_s: table.num(i, "move_time_s").unwrap_or(f64::NAN),
                        settle_s: time(&format!("settle_time_s_{b}")),
                        total_s: time(&format!("move_and_settle_s_{b}")),
                        residual_peak_um: table.num(i, "residual_peak_um").unwrap_or(f64::NAN),
                        gain: None,
                        current: is_current(sc, &runs[i]),
                        failure,
                        shaper: shapers.then(|| {
                            [
                                table.num(i, "smoothing_mm"),
                                table.num(i, "remaining_vibration_pct"),
                                max_accel(table, i),
                            ]
                        }),
                    }
                })
                .collect();
            // Settled runs by time (ties in run order), then unsettled, then failed.
            ranked.sort_by(|a, b| {
                let key = |r: &Ranked| (r.failure.is_some(), r.total_s.unwrap_or(f64::INFINITY));
                let (fa, ta) = key(a);
                let (fb, tb) = key(b);
                fa.cmp(&fb).then(ta.total_cmp(&tb)).then(a.id.cmp(&b.id))
            });
            for (n, r) in ranked.iter_mut().enumerate() {
                r.rank = r.total_s.map(|_| n + 1);
            }
            let reference = match ranked.iter().find(|r| r.current) {
                Some(c) => Some((c.label.clone(), c.total_s)),
                None if current_label.is_some() => None,
                None => ranked
                    .iter()
                    .rev()
                    .find(|r| r.failure.is_none())
                    .map(|r| (r.label.clone(), r.total_s)),
            };
            if let Some((_, rt)) = &reference {
                for r in &mut ranked {
                    r.gain = match (rt, r.total_s) {
                        (Some(rt), Some(t)) => Some(rt / t - 1.0),
                        (None, Some(_)) => Some(f64::INFINITY),
                        _ => None,
                    };
                }
            }
            for r in &ranked {
                let t = r.total_s.unwrap_or(f64::INFINITY);
                match sum_of.get(&r.label) {
                    Some(&k) => {
                        sums[k].1 += t;
                        sums[k].2 += 1;
                        let c = &mut candidates[k];
                        c.total_s = c.total_s.zip(r.total_s).map(|(a, b)| a + b);
                        c.runs.push(r.id);
                        c.failed |= r.failure.is_some();
                    }
                    None => {
                        sum_of.insert(r.label.clone(), sums.len());
                        sums.push((r.label.clone(), t, 1));
                        candidates.push(Candidate {
                            label: r.label.clone(),
                            total_s: r.total_s,
                            runs: vec![r.id],
                            current: r.current,
                            failed: r.failure.is_some(),
                        });
                    }
                }
            }
            points.push(Point {
                workload: workload.clone(),
                reference,
                runs: ranked,
            });
        }
        let n_points = points.len();
        let full: Vec<&(String, f64, usize)> = sums.iter().filter(|s| s.2 == n_points).collect();
        let winner = full
            .iter()
            .filter(|s| s.1.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|w| {
                let reference = match &current_label {
                    Some(c) => full.iter().find(|s| s.0 == *c).map(|s| (s.0.clone(), s.1)),
                    None => full
                        .iter()
                        .max_by(|a, b| a.1.total_cmp(&b.1))
                        .map(|s| (s.0.clone(), s.1)),
                };
                Winner {
                    label: w.0.clone(),
                    total_s: w.1,
                    points: n_points,
                    reference,
                }
            });
        for c in &mut candidates {
            if c.runs.len() < n_points {
                c.total_s = None;
            }
        }
        candidates.sort_by(|a, b| {
            let key = |c: &Candidate| {
                (
                    c.failed,
                    c.total_s.unwrap_or(f64::INFINITY),
                    c.runs.iter().min().copied().unwrap_or(usize::MAX),
                )
            };
            let (fa, ta, ia) = key(a);
            let (fb, tb, ib) = key(b);
            fa.cmp(&fb).then(ta.total_cmp(&tb)).then(ia.cmp(&ib))
        });
        bands.push(Band {
            band_um: band,
            points,
            winner,
            candidates,
        });
    }
    Ranking {
        setting_keys,
        workload_keys,
        has_current: !sc.current.is_empty(),
        current_label,
        shapers,
        bands,
    }
}

impl Ranking {
    /// What the gains are against, for headers: `vs current` or `vs slowest (no current
    /// given)`.
    pub fn reference_name(&self) -> &'static str {
        if self.has_current {
            "vs current"
        } else {
            "vs slowest (no current given)"
        }
    }
}

/// The headers of the shaper columns (where shapers are swept) in summary.md and
/// report.html: [`Ranked::shaper`]'s figures.
pub const SHAPER_COLUMNS: [&str; 3] = [
    "smoothing (mm)",
    "remaining vibration (%)",
    "max_accel (mm/s^2)",
];

/// A gain as shown: `+38 %`, `-5.2 %`, `reference not settled`, or `-`.
pub fn gain_text(gain: Option<f64>) -> String {
    match gain {
        Some(g) if g.is_infinite() => "reference not settled".to_string(),
        Some(g) if (g * 100.0).abs() < 10.0 => format!("{:+.1} %", g * 100.0),
        Some(g) => format!("{:+.0} %", g * 100.0),
        None => "-".to_string(),
    }
}
