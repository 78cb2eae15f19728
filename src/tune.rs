//! `settle tune`: search the profile parameters that minimise move-and-settle on the
//! scenario's machine (issue 9).
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
//! A candidate's score is the mean `move_and_settle_s` at the tuning band over the move
//! family (`distances_mm`); a candidate that does not settle in the window for some move
//! scores infinity. Ties break on grid order, so the result is deterministic.

use serde::Deserialize;
use settle_planner::shaper::ShaperKind;
use settle_planner::{KindParams, ProfileKind};

use crate::error::Error;
use crate::metrics::Metrics;
use crate::scenario::Source;
use crate::shaping::{DEFAULT_DAMPING_RATIO, ShaperSetting};
use crate::sweep::RunSpec;

/// The `[tune]` table of a scenario (every key optional).
#[derive(Debug, Clone, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct TuneSpec {
    /// The point-to-point move family: move lengths (mm) [default: `move.distance_mm`].
    pub distances_mm: Option<Vec<f64>>,
    /// The corner family (a scenario with `[corner]`): interior angles (degrees)
    /// [default: `corner.angle_deg`].
    pub angles_deg: Option<Vec<f64>>,
    /// Corner paths: the largest contour error (um) a candidate may reach on any corner of
    /// the family; candidates above it are infeasible [default: no limit].
    pub max_contour_error_um: Option<f64>,
    /// The settling band the score uses (um) [default: the first of `observe.bands_um`].
    pub band_um: Option<f64>,
    /// Profile kinds to search [default: all].
    pub kinds: Option<Vec<String>>,
    /// Shaper types to search, `none` included [default: none and all six].
    pub shapers: Option<Vec<String>>,
    /// Shaper frequencies as multiples of each mode frequency [default 0.8 to 1.2].
    pub frequency_scales: Option<Vec<f64>>,
    /// Number of jerk values [default 6].
    pub jerk_steps: Option<usize>,
    /// Lowest jerk = jmax / jerk_span [default 30: jerk phases up to 30x longer].
    pub jerk_span: Option<f64>,
    /// Microsteps per mm for the Trinamic export [default 1280 = 80 full steps/mm x 16].
    pub usteps_per_mm: Option<f64>,
    /// TMC5160 clock (Hz) for the Trinamic export [default 12 MHz, the internal clock].
    pub tmc_clock_hz: Option<u32>,
}

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
        run.shaper = self.shaper;
    }

    /// The candidate a run is (its profile, jerk, kind parameters and shaper).
    pub fn of(run: &RunSpec) -> Self {
        Self {
            kind: run.profile,
            jmax_mm_s3: run.jmax_mm_s3,
            params: run.kind_params,
            shaper: run.shaper,
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
    /// Index of the band in the runs' `bands_um`.
    pub band_index: usize,
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

/// PVT asymmetries searched (the seed's Ki in (1/3, 1); 0.5 is its default).
pub const PVT_KI: [f64; 4] = [0.4, 0.5, 0.65, 0.8];

/// Default frequency scales: the mode frequency +-20% (shapers are tuned to a measured
/// frequency; the neighbourhood covers the shift of the damped and coupled modes).
pub const FREQUENCY_SCALES: [f64; 7] = [0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2];

/// Resolve the scenario's search. Errors name the `[tune]` key.
pub fn plan(sc: &crate::scenario::Scenario, src: &Source, runs: &[RunSpec]) -> Result<Plan, Error> {
    let spec = sc.tune.clone().unwrap_or_default();
    if sc.scan.is_some() {
        return Err(src.error_at(
            "scan",
            "settle tune searches point-to-point moves ([move]) and corners ([corner]); scan steps are not tunable yet",
        ));
    }
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
    let angles_deg = match &base.corner {
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
            .map(|s| crate::shaping::parse_type(s).map_err(|m| src.error_at("tune.shapers", m)))
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
            _ if base.corner.is_some() => vec![KindParams::default()],
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
        let (start_m, dist_m) = if base.corner.is_some() {
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
                match r.corner.as_mut() {
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
        if self.base.corner.is_some() {
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
                let (mut t, mut r, mut mas) = (0.0, 0.0, 0.0);
                let mut contour = f64::NAN;
                for m in rs {
                    match m {
                        Ok(m) if m.is_ok() => {
                            t += m.move_time_s;
                            r += m.residual_peak_um;
                            mas += m
                                .move_and_settle_s(self.band_index)
                                .unwrap_or(f64::INFINITY);
                            if let Some(p) = &m.path {
                                contour = contour.max(p.max_contour_error_um);
                                if p.max_contour_error_um > limit {
                                    mas = f64::INFINITY;
                                }
                            }
                        }
                        _ => {
                            t = f64::NAN;
                            mas = f64::INFINITY;
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

/// Evaluate every candidate of `plan` (all runs in one parallel batch, with a progress bar
/// when `progress`).
pub fn evaluate(
    plan: &Plan,
    candidates: &[Candidate],
    jobs: Option<usize>,
    progress: bool,
) -> Result<Vec<Score>, Error> {
    let runs = plan.runs(candidates);
    let results = crate::run_all(&runs, jobs, progress)?;
    Ok(plan.scores(candidates, &results))
}
