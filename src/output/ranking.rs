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

use settle_planner::shaper::{Shaper, ShaperType};

use crate::input::runs_columns::RunsColumns;
use crate::input::scenario::Scenario;
use crate::output::runs_csv::band_label;
use crate::spec::backend::Backend;
pub use crate::spec::groups::is_setting;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::spec::value::Value;

/// A value as a candidate's label shows it: names as they are, numbers as `key=value` with
/// the key's last part (`frequency_hz=52`).
pub fn label_part(key: &str, v: &Value) -> String {
    match v {
        Value::Number(x) => format!("{}={x}", key.rsplit('.').next().unwrap_or(key)),
        other => other.to_string(),
    }
}

/// One run in a band's ranking, as the tables show it (made by [`Ranking::point`]).
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

/// One workload point of a band, fastest first, as the tables show it (made on demand by
/// [`Ranking::point`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The workload values, as shown (one per workload key).
    pub workload: Vec<String>,
    /// The reference of the gains: `(label, total s)`.
    pub reference: Option<(String, Option<f64>)>,
    /// The runs, ranked ones first (fastest first), then the unsettled and failed ones.
    pub runs: Vec<Ranked>,
}

/// One run's place in a band's ranking, as kept (a few bytes a run: the numbers are read
/// back from the runs table when a [`Ranked`] is made).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slot {
    /// Row in the runs table (= index into the runs).
    pub row: u32,
    /// 1 for the fastest of its point; 0 for a failed or unsettled run.
    pub rank: u32,
    /// The candidate: its index in [`Ranking::candidates`].
    pub candidate: u32,
    /// Whether this run is the scenario's `[current]` candidate.
    pub current: bool,
}

/// One workload point of a band, as kept: its runs are `order[start..start + len]` of its
/// band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointSlots {
    /// The first of its runs in [`Band::order`].
    pub start: u32,
    /// How many runs it has.
    pub len: u32,
    /// The reference of the gains: the position of its run among the point's runs.
    pub reference: Option<u32>,
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
    /// Per workload point (see [`Ranking::point`]).
    pub points: Vec<PointSlots>,
    /// The runs of every workload point, point after point, each point's fastest first.
    pub order: Vec<Slot>,
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
    /// Every candidate's label and setting values as shown (one per setting key), in the
    /// order of the runs.
    pub candidates: Vec<(String, Vec<String>)>,
    /// Per band.
    pub bands: Vec<Band>,
    /// The runs left out of the ranking as repeats: `(row, row of the run it repeats)`,
    /// a run of the same workload point and candidate, differing only in settings that do
    /// not change it (a jerk limit with a trapezoid, a frequency with no shaper).
    pub repeats: Vec<(u32, u32)>,
    /// Why those settings do not change them, once each.
    pub unused: Vec<Unused>,
}

/// A swept key that does not change some runs, and why: `(key, reason)`.
pub type Unused = (String, &'static str);

/// Whether `run` is the `[current]` candidate of `sc` (every key given matches, or does
/// not change the run: [`crate::studies::unused`]).
pub fn is_current(sc: &Scenario, run: &RunSpec) -> bool {
    !sc.current.is_empty()
        && sc.current.iter().all(|(k, v)| {
            crate::studies::unused(run, k).is_some()
                || run
                    .swept
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
fn max_accel(table: &RunsColumns, row: usize) -> Option<f64> {
    let kind = ShaperType::parse(&table.cell(row, "shaper_type")?).ok()?;
    let sh = Shaper::new(
        kind,
        table.num(row, "shaper_frequency_hz")?,
        table.num(row, "shaper_damping_ratio")?,
    )
    .ok()?;
    Some(crate::studies::shaping::max_accel_mm_s2(
        &sh,
        settle_planner::shaper_select::TARGET_SMOOTHING_MM,
    ))
}

/// Whether row `i` of `table` ran (`status` ok, or no status column).
fn ran(table: &RunsColumns, i: usize) -> bool {
    table.cell(i, "status").is_none_or(|s| s == "ok")
}

/// A time column of row `i` (`None` when not finite or the run failed).
fn time_of(table: &RunsColumns, i: usize, column: &str) -> Option<f64> {
    table
        .num(i, column)
        .filter(|x| x.is_finite() && ran(table, i))
}

/// The values of a run's settings (`setting`) or workload, as shown in the tables: `-`
/// for a setting that does not change the run ([`crate::studies::unused`]).
fn values(r: &RunSpec, setting: bool) -> Vec<String> {
    r.swept
        .iter()
        .filter(|(p, _)| is_setting(p) == setting)
        .map(|(p, v)| {
            if setting && crate::studies::unused(r, p).is_some() {
                "-".to_string()
            } else {
                v.to_string()
            }
        })
        .collect()
}

/// A run's candidate label: the settings that change it joined by `, `, or its profile
/// kind.
fn label(r: &RunSpec) -> String {
    let s: Vec<String> = r
        .swept
        .iter()
        .filter(|(p, _)| is_setting(p) && crate::studies::unused(r, p).is_none())
        .map(|(p, v)| label_part(p, v))
        .collect();
    if s.is_empty() {
        r.profile.to_string()
    } else {
        s.join(", ")
    }
}

/// The workload points of `runs` in first-seen order, each with its rows in run order, as
/// `(points' first entries in rows, rows)`: a few bytes a run (a point is found through a
/// hash of its values, checked against the point's first run).
fn workload_points(runs: &dyn RunList) -> (Vec<usize>, Vec<u32>) {
    use std::hash::{Hash, Hasher};
    let hash = |w: &[String]| {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        w.hash(&mut h);
        h.finish()
    };
    // Per point: its first row and the next point with the same hash.
    let mut first_row: Vec<u32> = Vec::new();
    let mut next_same: Vec<u32> = Vec::new();
    let mut by_hash: std::collections::HashMap<u64, u32> = std::collections::HashMap::new();
    let mut point_of: Vec<u32> = Vec::with_capacity(runs.len());
    for (i, r) in runs.iter().enumerate() {
        let w = values(&r, false);
        let h = hash(&w);
        let mut found = None;
        let mut k = by_hash.get(&h).copied();
        while let Some(p) = k {
            if values(&runs.at(first_row[p as usize] as usize), false) == w {
                found = Some(p);
                break;
            }
            k = Some(next_same[p as usize]).filter(|&n| n != u32::MAX);
        }
        let p = match found {
            Some(p) => p,
            None => {
                let p = first_row.len() as u32;
                next_same.push(by_hash.insert(h, p).unwrap_or(u32::MAX));
                first_row.push(i as u32);
                p
            }
        };
        point_of.push(p);
    }
    drop((by_hash, next_same, first_row));
    // Rows grouped by point (a counting sort keeps run order within a point).
    let n_points = point_of.iter().map(|&p| p as usize + 1).max().unwrap_or(0);
    let mut starts = vec![0usize; n_points + 1];
    for &p in &point_of {
        starts[p as usize + 1] += 1;
    }
    for k in 0..n_points {
        starts[k + 1] += starts[k];
    }
    let mut fill = starts.clone();
    let mut rows = vec![0u32; runs.len()];
    for (i, &p) in point_of.iter().enumerate() {
        rows[fill[p as usize]] = i as u32;
        fill[p as usize] += 1;
    }
    (starts, rows)
}

/// Rank `runs` (row `i` of `table` is `runs.at(i)`).
pub fn rank(sc: &Scenario, runs: &dyn RunList, table: &RunsColumns) -> Ranking {
    let keys: Vec<String> = runs
        .first()
        .map(|r| r.swept.iter().map(|(p, _)| p.clone()).collect())
        .unwrap_or_default();
    let setting_keys: Vec<String> = keys.iter().filter(|k| is_setting(k)).cloned().collect();
    let workload_keys: Vec<String> = keys.iter().filter(|k| !is_setting(k)).cloned().collect();
    let (starts, point_rows) = workload_points(runs);
    // The candidates, first-seen in run order, and each run's.
    let mut candidates: Vec<(String, Vec<String>)> = Vec::new();
    let mut candidate_of: std::collections::HashMap<String, u32> = std::collections::HashMap::new();
    let mut run_candidate: Vec<u32> = Vec::with_capacity(runs.len());
    let mut run_current: Vec<bool> = Vec::with_capacity(runs.len());
    for r in runs.iter() {
        let l = label(&r);
        let c = match candidate_of.get(&l) {
            Some(&c) => c,
            None => {
                let c = candidates.len() as u32;
                candidate_of.insert(l.clone(), c);
                candidates.push((l, values(&r, true)));
                c
            }
        };
        run_candidate.push(c);
        run_current.push(is_current(sc, &r));
    }
    drop(candidate_of);
    let (repeats, unused) = repeats(runs, &starts, &point_rows, &run_candidate);
    let mut repeat = vec![false; runs.len()];
    for &(row, _) in &repeats {
        repeat[row as usize] = true;
    }
    let shapers = setting_keys.iter().any(|k| k.starts_with("shaper."))
        && table.column("smoothing_mm").is_some();
    let current_label = run_current
        .iter()
        .position(|&c| c)
        .map(|i| candidates[run_candidate[i] as usize].0.clone());
    let bands_um = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
    let mut bands = Vec::new();
    for band in bands_um {
        let b = band_label(band);
        let total_col = format!("move_and_settle_s_{b}");
        let mut points = Vec::with_capacity(starts.len().saturating_sub(1));
        let mut order: Vec<Slot> = Vec::with_capacity(runs.len());
        let mut sums: Vec<(u32, f64, usize)> = Vec::new();
        // `sums` and `band_candidates` list the same candidates in the same order;
        // `sum_of` (by candidate) indexes both.
        let mut band_candidates: Vec<Candidate> = Vec::new();
        let mut sum_of: Vec<Option<usize>> = vec![None; candidates.len()];
        // (failed, total, id) of each run of a point, to sort it.
        let mut ranked: Vec<(Slot, bool, Option<f64>, usize)> = Vec::new();
        for w in starts.windows(2) {
            ranked.clear();
            for &i in point_rows[w[0]..w[1]]
                .iter()
                .filter(|&&i| !repeat[i as usize])
            {
                let i = i as usize;
                let slot = Slot {
                    row: i as u32,
                    rank: 0,
                    candidate: run_candidate[i],
                    current: run_current[i],
                };
                ranked.push((
                    slot,
                    !ran(table, i),
                    time_of(table, i, &total_col),
                    runs.at(i).id,
                ));
            }
            // Settled runs by time (ties in run order), then unsettled, then failed.
            ranked.sort_by(|a, b| {
                let key =
                    |r: &(Slot, bool, Option<f64>, usize)| (r.1, r.2.unwrap_or(f64::INFINITY));
                let (fa, ta) = key(a);
                let (fb, tb) = key(b);
                fa.cmp(&fb).then(ta.total_cmp(&tb)).then(a.3.cmp(&b.3))
            });
            for (n, r) in ranked.iter_mut().enumerate() {
                if r.2.is_some() {
                    r.0.rank = n as u32 + 1;
                }
            }
            let reference = match ranked.iter().position(|r| r.0.current) {
                Some(c) => Some(c as u32),
                None if current_label.is_some() => None,
                None => ranked.iter().rposition(|r| !r.1).map(|k| k as u32),
            };
            for r in &ranked {
                let t = r.2.unwrap_or(f64::INFINITY);
                let c = r.0.candidate as usize;
                match sum_of[c] {
                    Some(k) => {
                        sums[k].1 += t;
                        sums[k].2 += 1;
                        let bc = &mut band_candidates[k];
                        bc.total_s = bc.total_s.zip(r.2).map(|(a, b)| a + b);
                        bc.runs.push(r.3);
                        bc.failed |= r.1;
                    }
                    None => {
                        sum_of[c] = Some(sums.len());
                        sums.push((r.0.candidate, t, 1));
                        band_candidates.push(Candidate {
                            label: candidates[c].0.clone(),
                            total_s: r.2,
                            runs: vec![r.3],
                            current: r.0.current,
                            failed: r.1,
                        });
                    }
                }
            }
            points.push(PointSlots {
                start: order.len() as u32,
                len: ranked.len() as u32,
                reference,
            });
            order.extend(ranked.iter().map(|r| r.0));
        }
        let n_points = points.len();
        let full: Vec<(&str, f64)> = sums
            .iter()
            .filter(|s| s.2 == n_points)
            .map(|s| (candidates[s.0 as usize].0.as_str(), s.1))
            .collect();
        let winner = full
            .iter()
            .filter(|s| s.1.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|w| {
                let reference = match &current_label {
                    Some(c) => full
                        .iter()
                        .find(|s| s.0 == c.as_str())
                        .map(|s| (s.0.to_string(), s.1)),
                    None => full
                        .iter()
                        .max_by(|a, b| a.1.total_cmp(&b.1))
                        .map(|s| (s.0.to_string(), s.1)),
                };
                Winner {
                    label: w.0.to_string(),
                    total_s: w.1,
                    points: n_points,
                    reference,
                }
            });
        for c in &mut band_candidates {
            if c.runs.len() < n_points {
                c.total_s = None;
            }
        }
        band_candidates.sort_by(|a, b| {
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
            order,
            winner,
            candidates: band_candidates,
        });
    }
    Ranking {
        setting_keys,
        workload_keys,
        has_current: !sc.current.is_empty(),
        current_label,
        shapers,
        candidates,
        bands,
        repeats,
        unused,
    }
}

/// The runs that repeat an earlier run of their workload point's candidate (see
/// [`Ranking::repeats`]), with the `(key, reason)` of the settings that do not change
/// them, once each.
fn repeats(
    runs: &dyn RunList,
    starts: &[usize],
    point_rows: &[u32],
    run_candidate: &[u32],
) -> (Vec<(u32, u32)>, Vec<Unused>) {
    let mut repeats = Vec::new();
    let mut unused: Vec<Unused> = Vec::new();
    let mut first: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for w in starts.windows(2) {
        first.clear();
        for &row in &point_rows[w[0]..w[1]] {
            let c = run_candidate[row as usize];
            let Some(&earlier) = first.get(&c) else {
                first.insert(c, row);
                continue;
            };
            repeats.push((row, earlier));
            let r = runs.at(row as usize);
            for (key, _) in &r.swept {
                if let Some(why) = crate::studies::unused(&r, key)
                    && !unused.iter().any(|(k, w)| k == key && *w == why)
                {
                    unused.push((key.clone(), why));
                }
            }
        }
    }
    (repeats, unused)
}

impl Ranking {
    /// The sentence on the runs ranked once ([`Ranking::repeats`]); `None` without any.
    pub fn repeats_note(&self, runs: &dyn RunList) -> Option<String> {
        const SHOWN: usize = 5;
        if self.repeats.is_empty() {
            return None;
        }
        let why: Vec<String> = self
            .unused
            .iter()
            .map(|(k, w)| format!("`{k}`: {w}"))
            .collect();
        let mut pairs: Vec<String> = self
            .repeats
            .iter()
            .take(SHOWN)
            .map(|&(r, e)| {
                format!(
                    "run {} repeats run {}",
                    runs.at(r as usize).id,
                    runs.at(e as usize).id
                )
            })
            .collect();
        if self.repeats.len() > SHOWN {
            pairs.push(format!("{} more", self.repeats.len() - SHOWN));
        }
        Some(format!(
            "Ranked once: {} run(s) repeat another run of their point in every setting that changes them ({}). Those settings show as `-`; runs.csv keeps every run ({}).",
            self.repeats.len(),
            why.join("; "),
            pairs.join(", ")
        ))
    }

    /// Workload point `p` of band `b` as the tables show it: its values, its reference and
    /// its runs with their numbers (read from `table`, row `i` = `runs.at(i)`, the table the
    /// ranking was made from).
    pub fn point(
        &self,
        b: usize,
        p: usize,
        runs: &dyn RunList,
        table: &RunsColumns,
    ) -> Option<Point> {
        let n = self.bands.get(b)?.points.get(p)?.len as usize;
        self.point_runs(b, p, 0..n, runs, table)
    }

    /// [`Ranking::point`] with only its runs `which` (positions among the point's runs).
    pub fn point_runs(
        &self,
        b: usize,
        p: usize,
        which: std::ops::Range<usize>,
        runs: &dyn RunList,
        table: &RunsColumns,
    ) -> Option<Point> {
        let band = self.bands.get(b)?;
        let slots = band.points.get(p)?;
        let start = slots.start as usize;
        let mine = &band.order[start..start + slots.len as usize];
        let shown = mine.get(which)?;
        let label = |s: &Slot| self.candidates[s.candidate as usize].0.clone();
        let b_label = band_label(band.band_um);
        let total_col = format!("move_and_settle_s_{b_label}");
        let settle_col = format!("settle_time_s_{b_label}");
        let reference = slots.reference.map(|k| {
            let s = &mine[k as usize];
            (label(s), time_of(table, s.row as usize, &total_col))
        });
        let ranked = shown
            .iter()
            .map(|s| {
                let i = s.row as usize;
                let ok = ran(table, i);
                let failure = (!ok).then(|| {
                    let status = table.cell(i, "status").unwrap_or_default();
                    match table.cell(i, "reason").filter(|s| !s.is_empty()) {
                        Some(reason) => format!("{status}: {reason}"),
                        None => status.to_string(),
                    }
                });
                let total_s = time_of(table, i, &total_col);
                Ranked {
                    row: i,
                    id: runs.at(i).id,
                    rank: (s.rank > 0).then_some(s.rank as usize),
                    settings: self.candidates[s.candidate as usize].1.clone(),
                    label: label(s),
                    move_s: table.num(i, "move_time_s").unwrap_or(f64::NAN),
                    settle_s: time_of(table, i, &settle_col),
                    total_s,
                    residual_peak_um: table.num(i, "residual_peak_um").unwrap_or(f64::NAN),
                    gain: reference.as_ref().and_then(|(_, rt)| match (rt, total_s) {
                        (Some(rt), Some(t)) => Some(rt / t - 1.0),
                        (None, Some(_)) => Some(f64::INFINITY),
                        _ => None,
                    }),
                    current: s.current,
                    failure,
                    shaper: self.shapers.then(|| {
                        [
                            table.num(i, "smoothing_mm"),
                            table.num(i, "remaining_vibration_pct"),
                            max_accel(table, i),
                        ]
                    }),
                }
            })
            .collect();
        Some(Point {
            workload: values(&runs.at(mine.first()?.row as usize), false),
            reference,
            runs: ranked,
        })
    }

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
