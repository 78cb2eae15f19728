//! `settle tune`: search the profile parameters that minimise move-and-settle on the
//! scenario's machine.
//!
//! The search is a deterministic grid, evaluated through the same runs as a sweep (so a
//! tuned candidate is a plain [`RunSpec`] that any backend can re-run):
//! - profile kind (`[tune] kinds`),
//! - jerk: `jerk_steps` values log-spaced from `jmax / jerk_span` to the scenario's
//!   `jmax_mm_s3` (the machine's limit: the search never exceeds it; vmax and amax are the
//!   scenario's limits and stay fixed),
//! - `pvt_asym`: the asymmetry `Ki` (`pvt_asym_ki`), `fourjerk`: BOW1..4 patterns (each
//!   scale <= 1, so no bow exceeds jmax),
//! - input shaper: `none` or each type at each mode frequency times `frequency_scales`
//!   (the modes: the scenario's, or the moving axis's two strongest linearised modes).
//!
//! A candidate's score is the mean `move_and_settle_s` over the move family
//! (`distances_mm`, or a corner scenario's `angles_deg`) into the tighter band
//! `margin x band_um` (a robustness margin: see [`DEFAULT_MARGIN`]); a candidate that does
//! not settle in the window for some move scores infinity. A `[scan]` scenario is the
//! scan-step family: the moves are the raster's step-overs, and the score is the overhead
//! per line at which the step is settled (see [`scan_figures`]). Ties break on the lower
//! residual, then grid order, so the result is deterministic.

use settle_planner::shaper::ShaperKind;
use settle_planner::{KindParams, ProfileKind};

use crate::error::Error;
use crate::execute::pool::{Progress, quiet, run_all};
use crate::input::scenario::Scenario;
use crate::input::source::Source;
use crate::input::tune_spec::TuneSpec;
use crate::kinds::corner::Corner;
use crate::kinds::scan::ScanSpec;
use crate::kinds::shaping::{DEFAULT_DAMPING_RATIO, ShaperSetting};
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;

/// One point of the search grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Profile kind.
    pub kind: ProfileKind,
    /// Jerk limit (mm/s^3), `None` for the trapezoid.
    pub jmax_mm_s3: Option<f64>,
    /// PVT asymmetry and four-jerk BOW scales.
    pub params: KindParams,
    /// Input shaper (`None`: unshaped).
    pub shaper: Option<ShaperSetting>,
}

impl Candidate {
    /// A short label (`scurve j=1e5 +mzv@40.0`).
    pub fn label(&self) -> String {
        let mut s = self.kind.name().to_string();
        if let Some(j) = self.jmax_mm_s3 {
            s.push_str(&format!(" j={j:.3e}"));
        }
        match self.kind {
            ProfileKind::PvtAsym => s.push_str(&format!(" ki={}", self.params.pvt_asym_ki)),
            ProfileKind::FourJerk => {
                let b = self.params.fourjerk_jerk_scale;
                s.push_str(&format!(" bow={}/{}/{}/{}", b[0], b[1], b[2], b[3]));
            }
            _ => {}
        }
        if let Some(sh) = self.shaper.filter(|s| s.kind.is_some()) {
            s.push_str(&format!(
                " +{}@{:.1}Hz",
                sh.kind.map_or("none", ShaperKind::name),
                sh.frequency_hz
            ));
        }
        s
    }

    /// Apply to a run (its move length is left alone).
    pub fn apply(&self, run: &mut RunSpec) {
        run.profile = self.kind;
        run.jmax_mm_s3 = self.jmax_mm_s3.or(run.jmax_mm_s3);
        run.kind_params = self.params;
        match self.shaper {
            Some(sh) => run.put_state(Box::new(sh)),
            None => run.remove_state("shaper"),
        }
    }

    /// The candidate a run is (its profile, jerk, kind parameters and shaper).
    pub fn of(run: &RunSpec) -> Self {
        Self {
            kind: run.profile,
            jmax_mm_s3: run.jmax_mm_s3,
            params: run.kind_params,
            shaper: run.state::<ShaperSetting>().copied(),
        }
    }
}

/// A candidate's aggregate over the move family.
#[derive(Debug, Clone, PartialEq)]
pub struct Score {
    /// The candidate.
    pub candidate: Candidate,
    /// Mean commanded move time (s).
    pub move_time_s: f64,
    /// Mean residual peak (um).
    pub residual_peak_um: f64,
    /// Mean move-and-settle at the band (s); infinite when some move does not settle (or
    /// a corner exceeds `max_contour_error_um`).
    pub move_and_settle_s: f64,
    /// Largest contour error over the family (um), NaN for point-to-point moves.
    pub max_contour_error_um: f64,
    /// Mean move-and-settle into the band itself, `band_um` (s): equal to
    /// `move_and_settle_s` when the margin is 1. For scan steps: the overhead per line at
    /// which the step is settled into the band.
    pub at_band_s: f64,
}

/// The resolved search.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The base run (the scenario as written: the untuned default).
    pub base: RunSpec,
    /// Move lengths (mm) of the point-to-point family.
    pub distances_mm: Vec<f64>,
    /// Interior angles (degrees) of the corner family (empty for point-to-point moves).
    pub angles_deg: Vec<f64>,
    /// Index of the band (`band_um`) in the runs' `bands_um`.
    pub band_index: usize,
    /// Index of the scored band (`margin x band_um`) in the runs' `bands_um` (the runs of
    /// [`Plan::runs`] carry it; equal to `band_index` for a margin of 1).
    pub score_band_index: usize,
    /// The robustness margin (0, 1].
    pub margin: f64,
    /// The runs' bands (um): the scenario's, plus `margin x band_um` when it is new.
    pub bands_um: Vec<f64>,
    /// Candidates in grid order (the default first).
    pub candidates: Vec<Candidate>,
    /// Modes the shaper frequencies come from: `(Hz, damping ratio)`.
    pub modes: Vec<(f64, f64)>,
    /// The `[tune]` table.
    pub spec: TuneSpec,
}

/// Four-jerk BOW1..4 patterns searched (multiples of jmax; each <= 1).
pub const BOW_PATTERNS: [[f64; 4]; 5] = [
    [1.0, 1.0, 1.0, 1.0],
    [1.0, 0.5, 0.5, 1.0],
    [0.5, 1.0, 1.0, 0.5],
    [1.0, 0.5, 1.0, 0.5],
    [0.5, 1.0, 0.5, 1.0],
];

/// PVT asymmetries searched (`KindParams::pvt_asym_ki`, in (1/3, 1); 0.5 is its default).
pub const PVT_KI: [f64; 4] = [0.4, 0.5, 0.65, 0.8];

/// Default frequency scales: the mode frequency +-20% (shapers are tuned to a measured
/// frequency; the neighbourhood covers the shift of the damped and coupled modes).
pub const FREQUENCY_SCALES: [f64; 7] = [0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2];

/// Default rounds of refinement around the grid winner: 0 (grid only). Each round looks
/// at up to 8 neighbours (the shaper frequency +-1 and +-2 steps, the jerk likewise), the
/// step halving each round from half the grid's spacing, so 4 rounds resolve the frequency
/// to ~0.3% for ~1% of the grid's cost. Off by default because on the shipped scenarios it
/// gained 0.02-0.4 ms and, by pushing the shaper frequency up until the residual touches
/// the scored band, gave back the robustness the margin buys (tune_corner: rapier settles
/// the refined winner 4.9 ms later than modal predicted; the grid winner on time).
pub const DEFAULT_REFINE_ROUNDS: usize = 0;

/// Default robustness margin, 0.8: score on settling into 80% of the band. The engines
/// agree on residual peaks to a few percent on fixed-stiffness machines but up to ~20% on
/// the belt printer (rapier's belt stiffness varies along the move; tune_corner: 9.18 um on
/// modal, 10.9 um on rapier), so a winner scored at the band's edge can miss the band on
/// another engine; 0.8 keeps that 20% inside it.
pub const DEFAULT_MARGIN: f64 = 0.8;

/// Resolve the scenario's search. Errors name the `[tune]` key.
pub fn plan(sc: &Scenario, src: &Source, runs: &[RunSpec]) -> Result<Plan, Error> {
    let spec = sc.tune.clone().unwrap_or_default();
    if !sc.sweep.is_empty() {
        return Err(src.error_at(
            "sweep",
            "settle tune does its own search: remove [sweep] (give the move family in [tune] distances_mm)",
        ));
    }
    let base = runs
        .first()
        .cloned()
        .ok_or_else(|| src.error_at("name", "the scenario has no run"))?;
    let jmax = base.jmax_mm_s3.ok_or_else(|| {
        src.error_at(
            "limits",
            "settle tune needs `jmax_mm_s3` in [limits]: the machine's jerk limit bounds the jerk search",
        )
    })?;
    let distances_mm = spec
        .distances_mm
        .clone()
        .unwrap_or_else(|| vec![base.distance_mm]);
    if distances_mm.is_empty() || distances_mm.iter().any(|d| !(d.is_finite() && *d != 0.0)) {
        return Err(src.error_at(
            "tune.distances_mm",
            "give one or more finite, non-zero move lengths (mm)",
        ));
    }
    let angles_deg = match base.state::<Corner>() {
        None if spec.angles_deg.is_some() => {
            return Err(src.error_at("tune.angles_deg", "corner angles need a [corner] scenario"));
        }
        None => Vec::new(),
        Some(c) => {
            if spec.distances_mm.is_some() {
                return Err(src.error_at(
                    "tune.distances_mm",
                    "a [corner] scenario tunes over corner angles: give `angles_deg`, not distances_mm",
                ));
            }
            let angles = spec.angles_deg.clone().unwrap_or_else(|| vec![c.angle_deg]);
            if angles.is_empty()
                || angles
                    .iter()
                    .any(|a| !(a.is_finite() && (0.0..=180.0).contains(a)))
            {
                return Err(src.error_at(
                    "tune.angles_deg",
                    "give one or more interior angles from 0 (reversal) to 180 (straight on) degrees",
                ));
            }
            angles
        }
    };
    if let Some(e) = spec.max_contour_error_um
        && !(e.is_finite() && e > 0.0)
    {
        return Err(src.error_at(
            "tune.max_contour_error_um",
            "must be a finite number > 0 (um)",
        ));
    }
    let band = spec.band_um.unwrap_or(base.bands_um[0]);
    let band_index = base
        .bands_um
        .iter()
        .position(|b| *b == band)
        .ok_or_else(|| {
            src.error_at(
                "tune.band_um",
                format!(
                    "{band} um is not one of observe.bands_um = {:?}",
                    base.bands_um
                ),
            )
        })?;
    let margin = spec.margin.unwrap_or(DEFAULT_MARGIN);
    if !(margin.is_finite() && margin > 0.0 && margin <= 1.0) {
        return Err(src.error_at(
            "tune.margin",
            format!("must be in (0, 1] (the scored band is margin x band_um), got {margin}"),
        ));
    }
    let mut bands_um = base.bands_um.clone();
    let tight = band * margin;
    let score_band_index = match bands_um.iter().position(|b| *b == tight) {
        Some(i) => i,
        None => {
            bands_um.push(tight);
            bands_um.len() - 1
        }
    };
    let kinds = match &spec.kinds {
        None => ProfileKind::ALL.to_vec(),
        Some(list) if list.is_empty() => {
            return Err(src.error_at("tune.kinds", "give at least one profile kind"));
        }
        Some(list) => list
            .iter()
            .map(|k| ProfileKind::parse(k).map_err(|e| src.error_at("tune.kinds", e.to_string())))
            .collect::<Result<_, _>>()?,
    };
    let shapers: Vec<Option<ShaperKind>> = match &spec.shapers {
        None => std::iter::once(None)
            .chain(ShaperKind::ALL.map(Some))
            .collect(),
        Some(list) if list.is_empty() => {
            return Err(src.error_at(
                "tune.shapers",
                "give at least one shaper type (or \"none\")",
            ));
        }
        Some(list) => list
            .iter()
            .map(|s| {
                crate::kinds::shaping::parse_type(s).map_err(|m| src.error_at("tune.shapers", m))
            })
            .collect::<Result<_, _>>()?,
    };
    let scales = spec
        .frequency_scales
        .clone()
        .unwrap_or_else(|| FREQUENCY_SCALES.to_vec());
    if scales.is_empty() || scales.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(src.error_at(
            "tune.frequency_scales",
            "give one or more finite multiples > 0 of the mode frequency",
        ));
    }
    if spec.refine_rounds.is_some_and(|r| r > 20) {
        return Err(src.error_at("tune.refine_rounds", "must be 0 to 20"));
    }
    let steps = spec.jerk_steps.unwrap_or(6);
    if !(1..=100).contains(&steps) {
        return Err(src.error_at("tune.jerk_steps", "must be 1 to 100"));
    }
    let span = spec.jerk_span.unwrap_or(30.0);
    if !(span.is_finite() && span >= 1.0) {
        return Err(src.error_at("tune.jerk_span", "must be a finite number >= 1"));
    }
    let jerks: Vec<f64> = (0..steps)
        .map(|i| {
            if steps == 1 {
                jmax
            } else {
                let f = i as f64 / (steps - 1) as f64;
                jmax / span.powf(1.0 - f)
            }
        })
        .collect();
    let modes = tuning_modes(&base);
    if modes.is_empty() && shapers.iter().any(Option::is_some) {
        return Err(src.error_at(
            "machine",
            "found no vibration mode of the moving axis to tune shapers to",
        ));
    }
    let mut shaper_settings: Vec<Option<ShaperSetting>> = Vec::new();
    for s in &shapers {
        match s {
            None => shaper_settings.push(None),
            Some(k) => {
                for (f, _) in &modes {
                    for x in &scales {
                        shaper_settings.push(Some(ShaperSetting {
                            kind: Some(*k),
                            frequency_hz: f * x,
                            damping_ratio: DEFAULT_DAMPING_RATIO,
                        }));
                    }
                }
            }
        }
    }
    let default = Candidate::of(&base);
    let mut candidates = vec![default];
    for kind in kinds {
        let jerk_list: Vec<Option<f64>> = if kind == ProfileKind::Trapezoid {
            vec![None]
        } else {
            jerks.iter().copied().map(Some).collect()
        };
        let params: Vec<KindParams> = match kind {
            // Corner paths plan their legs from the limits alone.
            _ if base.state::<Corner>().is_some() => vec![KindParams::default()],
            ProfileKind::PvtAsym => PVT_KI
                .iter()
                .map(|&k| KindParams {
                    pvt_asym_ki: k,
                    ..KindParams::default()
                })
                .collect(),
            ProfileKind::FourJerk => BOW_PATTERNS
                .iter()
                .map(|&b| KindParams {
                    fourjerk_jerk_scale: b,
                    ..KindParams::default()
                })
                .collect(),
            _ => vec![KindParams::default()],
        };
        for j in &jerk_list {
            for p in &params {
                for sh in &shaper_settings {
                    candidates.push(Candidate {
                        kind,
                        jmax_mm_s3: *j,
                        params: *p,
                        shaper: *sh,
                    });
                }
            }
        }
    }
    Ok(Plan {
        base,
        distances_mm,
        angles_deg,
        band_index,
        score_band_index,
        margin,
        bands_um,
        candidates,
        modes,
        spec,
    })
}

/// The modes shapers are tuned to: the scenario's modes (by weight, at most two), or the
/// two strongest modes of the moving axis's linearised response.
pub fn tuning_modes(base: &RunSpec) -> Vec<(f64, f64)> {
    if base.machine.is_none() {
        let mut m: Vec<_> = base.modes.clone();
        m.sort_by(|a, b| b.weight.abs().total_cmp(&a.weight.abs()));
        return m
            .iter()
            .take(2)
            .map(|m| (m.frequency_hz, m.damping_ratio))
            .collect();
    }
    let Some(machine) = &base.machine else {
        return Vec::new();
    };
    let Ok(axes) = machine.compile(settle_sim::DriverMode::Linear) else {
        return Vec::new();
    };
    let Ok(limits) = base.limits_si() else {
        return Vec::new();
    };
    // The moving axis, or both axes of a corner path (its strongest mode each).
    let names: Vec<&str> = base.axis.split('+').collect();
    let per_axis = if names.len() > 1 { 1 } else { 2 };
    let mut out: Vec<(f64, f64)> = Vec::new();
    for name in names {
        let Some(axis) = axes.iter().find(|a| a.name == name) else {
            continue;
        };
        let (start_m, dist_m) = if base.state::<Corner>().is_some() {
            (0.0, 0.02)
        } else {
            (base.start_mm * 1e-3, base.distance_mm * 1e-3)
        };
        let Ok(profile) = base.profile.rest_to_rest(start_m, dist_m, &limits) else {
            continue;
        };
        let Ok(lr) = settle_sim::closed_form::LinearResponse::new(axis, &profile) else {
            continue;
        };
        for (f, z, _) in lr
            .modes()
            .into_iter()
            .filter(|(f, _, _)| *f > 0.5)
            .take(per_axis)
        {
            if !out.iter().any(|(g, _)| (g - f).abs() < 1e-6 * f) {
                out.push((f, z));
            }
        }
    }
    out
}

impl Plan {
    /// The runs of `candidates` (each over the move family), in order, ids from 0.
    pub fn runs(&self, candidates: &[Candidate]) -> Vec<RunSpec> {
        let mut out = Vec::with_capacity(candidates.len() * self.family_len());
        for c in candidates {
            for i in 0..self.family_len() {
                let mut r = self.base.clone();
                r.id = out.len();
                r.bands_um = self.bands_um.clone();
                match r.state_mut::<Corner>() {
                    Some(corner) => corner.angle_deg = self.angles_deg[i],
                    None => r.distance_mm = self.distances_mm[i],
                }
                c.apply(&mut r);
                out.push(r);
            }
        }
        out
    }

    /// Moves per candidate: the corner angles, or the move lengths.
    pub fn family_len(&self) -> usize {
        if self.base.state::<Corner>().is_some() {
            self.angles_deg.len()
        } else {
            self.distances_mm.len()
        }
    }

    /// Scores of `candidates` from the metrics of [`Plan::runs`] (a failed run scores
    /// infinity).
    pub fn scores(
        &self,
        candidates: &[Candidate],
        results: &[Result<Metrics, Error>],
    ) -> Vec<Score> {
        let n = self.family_len();
        let limit = self.spec.max_contour_error_um.unwrap_or(f64::INFINITY);
        candidates
            .iter()
            .zip(results.chunks(n))
            .map(|(c, rs)| {
                let (mut t, mut r, mut mas, mut at_band) = (0.0, 0.0, 0.0, 0.0);
                let mut contour = f64::NAN;
                for m in rs {
                    match m {
                        Ok(m) if m.is_ok() => {
                            let (time, residual, scored, nominal) =
                                match self.base.state::<ScanSpec>() {
                                    Some(scan) => {
                                        let f = scan_figures(scan, m, &self.bands_um);
                                        (
                                            f.step_s,
                                            f.line_residual_peak_um,
                                            f.overhead_s[self.score_band_index],
                                            f.overhead_s[self.band_index],
                                        )
                                    }
                                    None => (
                                        m.move_time_s,
                                        m.residual_peak_um,
                                        m.move_and_settle_s(self.score_band_index)
                                            .unwrap_or(f64::INFINITY),
                                        m.move_and_settle_s(self.band_index)
                                            .unwrap_or(f64::INFINITY),
                                    ),
                                };
                            t += time;
                            r += residual;
                            mas += scored;
                            at_band += nominal;
                            if let Some(p) = &m.path {
                                contour = contour.max(p.max_contour_error_um);
                                if p.max_contour_error_um > limit {
                                    mas = f64::INFINITY;
                                    at_band = f64::INFINITY;
                                }
                            }
                        }
                        _ => {
                            t = f64::NAN;
                            mas = f64::INFINITY;
                            at_band = f64::INFINITY;
                        }
                    }
                }
                let k = n as f64;
                Score {
                    candidate: *c,
                    move_time_s: t / k,
                    residual_peak_um: r / k,
                    move_and_settle_s: mas / k,
                    max_contour_error_um: contour,
                    at_band_s: at_band / k,
                }
            })
            .collect()
    }
}

/// Index of the best score: lowest move-and-settle, then lowest residual (candidates that
/// are inside the band when their move ends tie on move-and-settle); the first among equals.
pub fn best(scores: &[Score]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, s) in scores.iter().enumerate() {
        let better = |b: &Score| {
            s.move_and_settle_s < b.move_and_settle_s
                || (s.move_and_settle_s == b.move_and_settle_s
                    && s.residual_peak_um < b.residual_peak_um)
        };
        if s.move_and_settle_s.is_finite() && best.is_none_or(|b| better(&scores[b])) {
            best = Some(i);
        }
    }
    best
}

/// Indices of the Pareto front of (move time, residual peak): no other candidate is at
/// least as good in both and better in one. Sorted by move time.
pub fn pareto(scores: &[Score]) -> Vec<usize> {
    let ok: Vec<usize> = (0..scores.len())
        .filter(|&i| scores[i].move_time_s.is_finite() && scores[i].residual_peak_um.is_finite())
        .collect();
    let mut idx: Vec<usize> = ok
        .iter()
        .copied()
        .filter(|&i| {
            let a = &scores[i];
            !ok.iter().any(|&j| {
                let b = &scores[j];
                b.move_time_s <= a.move_time_s
                    && b.residual_peak_um <= a.residual_peak_um
                    && (b.move_time_s < a.move_time_s || b.residual_peak_um < a.residual_peak_um)
            })
        })
        .collect();
    idx.sort_by(|&a, &b| scores[a].move_time_s.total_cmp(&scores[b].move_time_s));
    idx.dedup_by(|a, b| {
        scores[*a].move_time_s == scores[*b].move_time_s
            && scores[*a].residual_peak_um == scores[*b].residual_peak_um
    });
    idx
}

/// Evaluate every candidate of `plan` (all runs in one parallel batch, reporting to
/// `progress`).
pub fn evaluate(
    plan: &Plan,
    candidates: &[Candidate],
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Vec<Score>, Error> {
    let runs = plan.runs(candidates);
    let results = run_all(&runs, jobs, progress)?;
    Ok(plan.scores(candidates, &results))
}

/// The scan-step figures of one scan run (from its [`Metrics::extra`] columns).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanFigures {
    /// The step's duration (s), shaper included.
    pub step_s: f64,
    /// The planner's window between exit and re-entry (s): the fastest turnaround or the
    /// step, whichever is longer.
    pub window_s: f64,
    /// Peak |error| of the step axis over the next line at that window (um).
    pub line_residual_peak_um: f64,
    /// Per band: the overhead per line at which the step is settled when the fly axis
    /// re-enters and stays settled over the line (s); infinite when the step is still
    /// outside the band when the next line ends.
    pub overhead_s: Vec<f64>,
}

/// The scan-step figure of merit: the time between the fly axis leaving the region and
/// the step axis being settled, `ready = offset + step + settle`, where `offset` is where
/// the step starts in the window (0 for placement `exit`) and `settle` the run's
/// `scan_step_settle_time_s_<band>um` (from the step's end until the error enters the
/// band for good); the overhead per line a scan needs for a settled re-entry is
/// `max(window, ready)` (the fly turnaround cannot be shorter than the planner's fastest,
/// and a scan planned with `settle_margin_s = settle` re-enters at `ready`).
pub fn scan_figures(
    scan: &crate::kinds::scan::ScanSpec,
    m: &Metrics,
    bands_um: &[f64],
) -> ScanFigures {
    let get = |k: &str| {
        m.extra
            .iter()
            .find(|(n, _)| n == k)
            .map_or(f64::NAN, |(_, v)| *v)
    };
    let step_s = get("scan_step_s");
    let window_s = get("scan_window_s");
    let offset_s = if scan.placement == "centered" {
        0.5 * (window_s - step_s - scan.settle_margin_s)
    } else {
        0.0
    };
    let overhead_s = bands_um
        .iter()
        .map(|b| {
            let settle = get(&format!("scan_step_settle_time_s_{b}um"));
            if settle.is_finite() {
                window_s.max(offset_s + step_s + settle)
            } else {
                f64::INFINITY
            }
        })
        .collect();
    ScanFigures {
        step_s,
        window_s,
        line_residual_peak_um: get("scan_line_residual_peak_um"),
        overhead_s,
    }
}

/// The neighbours of `c` one refinement round looks at: the shaper frequency times
/// `1 +- k df` and the jerk times `jr^+-k` (k = 1, 2), never above the scenario's jerk limit
/// `jmax` (a trapezoid has no jerk; an unshaped candidate no frequency).
pub fn neighbours(c: &Candidate, df: f64, jr: f64, jmax: f64) -> Vec<Candidate> {
    let mut out = Vec::new();
    if let Some(sh) = c.shaper.filter(|s| s.kind.is_some()) {
        for k in [-2.0, -1.0, 1.0, 2.0] {
            let f = sh.frequency_hz * (1.0 + k * df);
            if f > 0.0 {
                out.push(Candidate {
                    shaper: Some(ShaperSetting {
                        frequency_hz: f,
                        ..sh
                    }),
                    ..*c
                });
            }
        }
    }
    if let Some(j) = c.jmax_mm_s3 {
        for k in [-2, -1, 1, 2] {
            let jj = j * jr.powi(k);
            if jj <= jmax * (1.0 + 1e-12) {
                out.push(Candidate {
                    jmax_mm_s3: Some(jj.min(jmax)),
                    ..*c
                });
            }
        }
    }
    out
}

/// Refine around the grid winner: `rounds` rounds of [`neighbours`] of the current best,
/// the steps halving each round (from half the grid's frequency and jerk spacing). The
/// evaluated candidates are appended to `scores`; returns the index of the final winner
/// (the grid winner when nothing beats it: [`best`] keeps the first among equals).
pub fn refine(
    plan: &Plan,
    scores: &mut Vec<Score>,
    grid_winner: usize,
    jobs: Option<usize>,
) -> Result<usize, Error> {
    let rounds = plan.spec.refine_rounds.unwrap_or(DEFAULT_REFINE_ROUNDS);
    let jmax = plan.base.jmax_mm_s3.unwrap_or(f64::INFINITY);
    let steps = plan.spec.jerk_steps.unwrap_or(6).max(2);
    let span = plan.spec.jerk_span.unwrap_or(30.0);
    let mut df = 0.025;
    let mut jr = span.powf(0.5 / (steps - 1) as f64).max(1.0 + 1e-3);
    let mut winner = grid_winner;
    for _ in 0..rounds {
        let c = scores[winner].candidate;
        let next: Vec<Candidate> = neighbours(&c, df, jr, jmax)
            .into_iter()
            .filter(|n| !scores.iter().any(|s| s.candidate == *n))
            .collect();
        if !next.is_empty() {
            let found = evaluate(plan, &next, jobs, &quiet)?;
            scores.extend(found);
            winner = best(scores).unwrap_or(winner);
        }
        df *= 0.5;
        jr = jr.sqrt();
    }
    Ok(winner)
}
