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
//!   (the modes: the scenario's, or the moving axis's two strongest linearised modes),
//! - acceleration (`accelerations_mm_s2`, default the scenario's `amax_mm_s2`),
//!
//! restricted to what the `firmware` runs. A shaped candidate's smoothing (Klipper's figure
//! at its acceleration and 5 mm/s) and the largest acceleration keeping it within
//! `max_smoothing_mm` (Klipper's bisection) are part of its score; a candidate smoothing
//! more is infeasible. With `frequency_tolerance_pct`, or a machine whose modes carry the
//! standard deviation of their frequency (`frequency_sigma_hz`, as `settle identify`
//! writes it), a shaped candidate is also run with its shaper detuned either way by the
//! larger of that tolerance and the modes' 2-sigma band ([`super::grid::frequency_band`])
//! and scored on the worst of the three.
//!
//! A candidate's score is the mean `move_and_settle_s` over the move family
//! (`distances_mm`, or a corner scenario's `angles_deg`) into the tighter band
//! `margin x band_um` (a robustness margin: see [`super::grid::DEFAULT_MARGIN`]); a
//! candidate that does not settle in the window for some move scores infinity. A `[scan]` scenario is the
//! scan-step family: the moves are the raster's step-overs, and the score is the overhead
//! per line at which the step is settled (see [`super::scan_figures`]). Ties break on the lower
//! residual, then grid order, so the result is deterministic.

use settle_planner::shaper::Shaper;
use settle_planner::{ProfileKind, ProfileParams};

use crate::error::Error;
use crate::input::tune_spec::TuneSpec;
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;
use crate::studies::corner::Corner;
use crate::studies::scan::ScanSpec;
use crate::studies::shaping::{SMOOTHING_SCV_MM_S, ShaperSetting, max_accel_mm_s2};
use crate::workflows::tune::scan_figures::scan_figures;

/// One point of the search grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Profile kind.
    pub kind: ProfileKind,
    /// Jerk limit (mm/s^3), `None` for the trapezoid.
    pub jmax_mm_s3: Option<f64>,
    /// PVT asymmetry and four-jerk BOW scales.
    pub params: ProfileParams,
    /// Input shaper (`None`: unshaped).
    pub shaper: Option<ShaperSetting>,
    /// Acceleration limit (mm/s^2), `None` for the scenario's.
    pub amax_mm_s2: Option<f64>,
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
        if let Some(a) = self.amax_mm_s2 {
            s.push_str(&format!(" a={a}"));
        }
        if let Some(sh) = self.shaper.filter(|s| s.shaper_type.is_some()) {
            s.push_str(&format!(
                " +{}@{:.1}Hz",
                sh.shaper_type
                    .map_or_else(|| "none".to_string(), |k| k.name().to_string()),
                sh.frequency_hz
            ));
        }
        s
    }

    /// The shaper, when the candidate is shaped (`None` also for a setting the planner
    /// refuses, which fails its runs).
    pub fn shaper(&self) -> Option<Shaper> {
        self.shaper.and_then(|sh| sh.shaper().ok()).flatten()
    }

    /// Apply to a run (its move length is left alone).
    pub fn apply(&self, run: &mut RunSpec) {
        run.profile = self.kind;
        run.jmax_mm_s3 = self.jmax_mm_s3.or(run.jmax_mm_s3);
        run.profile_params = self.params;
        if let Some(a) = self.amax_mm_s2 {
            run.amax_mm_s2 = a;
        }
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
            params: run.profile_params,
            shaper: run.state::<ShaperSetting>().copied(),
            amax_mm_s2: None,
        }
    }
}

/// A candidate's aggregate over the move family.
#[derive(Debug, Clone, PartialEq)]
pub struct Score {
    /// The candidate.
    pub candidate: Candidate,
    /// Acceleration (mm/s^2) the candidate moves at.
    pub accel_mm_s2: f64,
    /// Klipper's smoothing of its shaper at that acceleration and 5 mm/s (mm); 0 unshaped.
    pub smoothing_mm: f64,
    /// Klipper's largest acceleration keeping the smoothing within the plan's
    /// `max_smoothing_mm` (mm/s^2); infinite unshaped.
    pub max_accel_mm_s2: f64,
    /// `move_and_settle_s` as simulated, before the smoothing limit (which makes a
    /// candidate smoothing more infeasible: `move_and_settle_s` infinite).
    pub simulated_move_and_settle_s: f64,
    /// Mean commanded move time (s).
    pub move_time_s: f64,
    /// Mean residual peak (um).
    pub residual_peak_um: f64,
    /// Mean move-and-settle at the band (s), the ranking key: infinite when some move does
    /// not settle, a corner exceeds `max_contour_error_um` or the shaper smooths too much
    /// (see [`Score::infeasible`]).
    pub move_and_settle_s: f64,
    /// Largest contour error over the family (um), NaN for point-to-point moves.
    pub max_contour_error_um: f64,
    /// Mean move-and-settle into the band itself, `band_um` (s), as simulated: equal to
    /// `simulated_move_and_settle_s` when the margin is 1. For scan steps: the overhead
    /// per line at which the step is settled into the band.
    pub at_band_s: f64,
    /// Why the candidate is out of the running (`None`: it is in); an infeasible
    /// candidate never wins and is not on the Pareto front.
    pub infeasible: Option<Infeasible>,
}

impl Score {
    /// Whether the candidate is in the running.
    pub fn is_feasible(&self) -> bool {
        self.infeasible.is_none()
    }
}

/// Why a candidate is out of the running, first reason first: a failed run, then the
/// smoothing limit, then the contour limit, then not settling.
#[derive(Debug, Clone, PartialEq)]
pub enum Infeasible {
    /// A run of its move family failed (lost steps, a broken-down simulation): the reason.
    Failed(String),
    /// Its shaper smooths more than the limit at its acceleration (Klipper's figure).
    Smoothing {
        /// Smoothing at its acceleration (mm).
        smoothing_mm: f64,
        /// The limit, `max_smoothing_mm` (mm).
        limit_mm: f64,
        /// The acceleration (mm/s^2).
        accel_mm_s2: f64,
    },
    /// A corner's toolhead leaves the path by more than `max_contour_error_um`.
    Contour {
        /// The largest contour error over the family (um).
        error_um: f64,
        /// The limit (um).
        limit_um: f64,
    },
    /// Some move of the family is not settled into the scored band by the end of the
    /// observation window (with a frequency band: at its frequency or at an edge).
    NotSettled {
        /// The scored band (um).
        band_um: f64,
        /// The observation window (s).
        window_s: f64,
    },
    /// The target firmware cannot take it: why.
    NotExportable(String),
}

impl Infeasible {
    /// A short phrase for tables and plots (`smooths 0.154 mm > 0.12 mm`).
    pub fn short(&self) -> String {
        match self {
            Infeasible::Failed(why) => format!("failed: {why}"),
            Infeasible::Smoothing {
                smoothing_mm,
                limit_mm,
                ..
            } => format!("smooths {smoothing_mm:.3} mm > {limit_mm} mm"),
            Infeasible::Contour { error_um, limit_um } => {
                format!("contour error {error_um:.1} um > {limit_um} um")
            }
            Infeasible::NotSettled { band_um, window_s } => {
                format!(
                    "not settled into {band_um} um within the {:.0} ms window",
                    window_s * 1e3
                )
            }
            Infeasible::NotExportable(why) => format!("not exportable: {why}"),
        }
    }

    /// The group a plot draws it in (`over the smoothing limit`, ...).
    pub fn group(&self) -> &'static str {
        match self {
            Infeasible::Failed(_) => "out: failed run",
            Infeasible::Smoothing { .. } => "out: over the smoothing limit",
            Infeasible::Contour { .. } => "out: over the contour limit",
            Infeasible::NotSettled { .. } => "out: not settled in the window",
            Infeasible::NotExportable(_) => "out: not exportable",
        }
    }

    /// The order of precedence (lower first): see [`Infeasible`].
    fn rank(&self) -> u8 {
        match self {
            Infeasible::Failed(_) => 0,
            Infeasible::NotExportable(_) => 1,
            Infeasible::Smoothing { .. } => 2,
            Infeasible::Contour { .. } => 3,
            Infeasible::NotSettled { .. } => 4,
        }
    }

    /// The first of `a` and `b` by precedence.
    pub fn first(a: Option<Self>, b: Option<Self>) -> Option<Self> {
        match (a, b) {
            (Some(x), Some(y)) => Some(if y.rank() < x.rank() { y } else { x }),
            (x, y) => x.or(y),
        }
    }
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
    /// Detuning of the robustness check, a fraction (0: none).
    pub frequency_tolerance: f64,
    /// Where that detuning came from ([`super::grid::frequency_band`]).
    pub band_source: BandSource,
    /// Largest smoothing a shaped candidate may have (mm).
    pub max_smoothing_mm: f64,
    /// The target whose candidates are searched.
    pub firmware: crate::workflows::tune::firmware::Candidates,
    /// How the target or the machine shaped the search, as sentences for the report
    /// (the jerks a register holds, a damping ratio a shaper does not take).
    pub notes: Vec<String>,
    /// Where the machine's modes come from, in words ([`super::grid::modes_source`]).
    pub modes_source: String,
    /// The built-in preset the machine is, if it is one (a model, not a measured machine).
    pub builtin_preset: Option<String>,
    /// Which damping ratio the shapers are designed for, as a sentence for the report
    /// ([`super::grid::design_damping_source`]).
    pub damping_source: String,
    /// The damping ratio every shaper is designed for, when it is one for all (`[tune]
    /// shaper_damping_ratio`, or Klipper's default on a physical machine); `None`: each
    /// the damping of the mode it is tuned to.
    pub shaper_damping: Option<f64>,
}

impl Plan {
    /// The runs of `candidates` (each over the move family), in order, ids from 0.
    pub fn runs(&self, candidates: &[Candidate]) -> Vec<RunSpec> {
        let mut out = Vec::with_capacity(candidates.len() * self.family_len());
        for c in candidates {
            for v in self.variants(c) {
                for i in 0..self.family_len() {
                    let mut r = self.base.clone();
                    r.id = out.len();
                    r.bands_um = self.bands_um.clone();
                    match r.state_mut::<Corner>() {
                        Some(corner) => corner.angle_deg = self.angles_deg[i],
                        None => r.distance_mm = self.distances_mm[i],
                    }
                    v.apply(&mut r);
                    out.push(r);
                }
            }
        }
        out
    }

    /// The candidate as run: itself, and for a shaped candidate under a frequency
    /// tolerance `t` also its shaper at `(1 - t)` and `(1 + t)` times its frequency.
    pub fn variants(&self, c: &Candidate) -> Vec<Candidate> {
        let t = self.frequency_tolerance;
        match c.shaper.filter(|s| s.shaper_type.is_some()) {
            Some(sh) if t > 0.0 => [1.0, 1.0 - t, 1.0 + t]
                .into_iter()
                .map(|k| Candidate {
                    shaper: Some(ShaperSetting {
                        frequency_hz: sh.frequency_hz * k,
                        ..sh
                    }),
                    ..*c
                })
                .collect(),
            _ => vec![*c],
        }
    }

    /// The smoothing (mm) and the largest acceleration within `max_smoothing_mm`
    /// (mm/s^2) of a candidate at acceleration `accel_mm_s2`, as Klipper computes them
    /// (at its square-corner velocity of 5 mm/s); `(0, inf)` unshaped.
    pub fn smoothing(&self, c: &Candidate, accel_mm_s2: f64) -> (f64, f64) {
        match c.shaper() {
            None => (0.0, f64::INFINITY),
            Some(s) => (
                s.smoothing_mm(accel_mm_s2, SMOOTHING_SCV_MM_S),
                max_accel_mm_s2(&s, self.max_smoothing_mm),
            ),
        }
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
        let mut at = 0;
        candidates
            .iter()
            .map(|c| {
                let variants = self.variants(c);
                let mut worst: Option<Score> = None;
                for v in &variants {
                    let s = self.score_one(v, &results[at..at + n]);
                    at += n;
                    if worst.as_ref().is_none_or(|w| {
                        s.move_and_settle_s > w.move_and_settle_s || s.move_and_settle_s.is_nan()
                    }) {
                        worst = Some(s);
                    }
                }
                let mut s = worst.unwrap_or_else(|| self.score_one(c, &[]));
                // The candidate is the nominal one; its smoothing too.
                s.candidate = *c;
                let (smoothing, max_accel) = self.smoothing(c, s.accel_mm_s2);
                s.smoothing_mm = smoothing;
                s.max_accel_mm_s2 = max_accel;
                s.simulated_move_and_settle_s = s.move_and_settle_s;
                if smoothing > self.max_smoothing_mm {
                    s.move_and_settle_s = f64::INFINITY;
                    s.infeasible = Infeasible::first(
                        s.infeasible.take(),
                        Some(Infeasible::Smoothing {
                            smoothing_mm: smoothing,
                            limit_mm: self.max_smoothing_mm,
                            accel_mm_s2: s.accel_mm_s2,
                        }),
                    );
                }
                s
            })
            .collect()
    }

    /// One candidate's score over the runs of its move family.
    fn score_one(&self, c: &Candidate, rs: &[Result<Metrics, Error>]) -> Score {
        let n = self.family_len();
        let limit = self.spec.max_contour_error_um.unwrap_or(f64::INFINITY);
        let (mut t, mut r, mut mas, mut at_band) = (0.0, 0.0, 0.0, 0.0);
        let mut contour = f64::NAN;
        let mut failed: Option<String> = None;
        if rs.len() != n {
            (t, mas, at_band) = (f64::NAN, f64::INFINITY, f64::INFINITY);
            failed = Some("its runs are missing".into());
        }
        for m in rs {
            match m {
                Ok(m) if m.is_ok() => {
                    let (time, residual, scored, nominal) = match self.base.state::<ScanSpec>() {
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
                Ok(m) => {
                    failed.get_or_insert_with(|| {
                        format!("{}: {}", m.status.name(), m.status.reason())
                    });
                    t = f64::NAN;
                    mas = f64::INFINITY;
                    at_band = f64::INFINITY;
                }
                Err(e) => {
                    failed.get_or_insert_with(|| e.to_string());
                    t = f64::NAN;
                    mas = f64::INFINITY;
                    at_band = f64::INFINITY;
                }
            }
        }
        let k = n as f64;
        let infeasible = if let Some(why) = failed {
            Some(Infeasible::Failed(why))
        } else if contour > limit {
            Some(Infeasible::Contour {
                error_um: contour,
                limit_um: limit,
            })
        } else if !mas.is_finite() {
            Some(Infeasible::NotSettled {
                band_um: self.bands_um[self.score_band_index],
                window_s: self.base.window_s,
            })
        } else {
            None
        };
        Score {
            candidate: *c,
            accel_mm_s2: c.amax_mm_s2.unwrap_or(self.base.amax_mm_s2),
            smoothing_mm: 0.0,
            max_accel_mm_s2: f64::INFINITY,
            simulated_move_and_settle_s: mas / k,
            move_time_s: t / k,
            residual_peak_um: r / k,
            move_and_settle_s: mas / k,
            max_contour_error_um: contour,
            at_band_s: at_band / k,
            infeasible,
        }
    }
}

/// Where the robustness band of a search came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BandSource {
    /// No band: the shapers are scored at their frequency alone.
    None,
    /// `--frequency-tolerance` / `[tune] frequency_tolerance_pct`.
    Given,
    /// Twice the identified standard deviation of a mode's frequency (the machine file's
    /// `frequency_sigma_hz`): `(frequency_hz, sigma_hz)` of the mode with the widest band.
    Identified(f64, f64),
    /// The given tolerance, which is at least the identified band `(frequency_hz,
    /// sigma_hz)`.
    GivenOverIdentified(f64, f64),
}

impl BandSource {
    /// A sentence for the report: which band and why.
    pub fn describe(&self, tolerance: f64) -> String {
        let pct = tolerance * 100.0;
        match *self {
            BandSource::None => "no frequency band (the shapers' own frequencies only)".into(),
            BandSource::Given => format!("+-{pct:.3}% (the given frequency tolerance)"),
            BandSource::Identified(f, s) if 200.0 * s / f > pct * (1.0 + 1e-9) => format!(
                "+-{pct:.3}%, the widest band a tune checks: 2 sigma of the identified {f:.2} +- {s:.3} Hz mode, from the machine file, is +-{:.3}%, so the shapers are not checked over all of it",
                200.0 * s / f
            ),
            BandSource::Identified(f, s) => format!(
                "+-{pct:.3}% (2 sigma of the identified {f:.2} +- {s:.3} Hz mode, from the machine file)"
            ),
            BandSource::GivenOverIdentified(f, s) => format!(
                "+-{pct:.3}% (the given frequency tolerance; the identified {f:.2} +- {s:.3} Hz mode's 2 sigma band is narrower)"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::BandSource;

    #[test]
    fn an_identified_band_wider_than_a_tune_checks_says_so() {
        // 2 sigma of 40 +- 4 Hz is 20 %: the band itself.
        let fits = BandSource::Identified(40.0, 4.0).describe(0.2);
        assert!(fits.starts_with("+-20.000% (2 sigma of"), "{fits}");
        // 2 sigma of 40 +- 12 Hz is 60 %, more than the 49 % a tune checks.
        let capped = BandSource::Identified(40.0, 12.0).describe(0.49);
        assert!(
            capped.contains("the widest band a tune checks") && capped.contains("+-60.000%"),
            "{capped}"
        );
    }
}
