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
//! `margin x band_um` (a robustness margin: see [`super::grid::DEFAULT_MARGIN`]); a
//! candidate that does not settle in the window for some move scores infinity. A `[scan]` scenario is the
//! scan-step family: the moves are the raster's step-overs, and the score is the overhead
//! per line at which the step is settled (see [`super::scan_figures`]). Ties break on the lower
//! residual, then grid order, so the result is deterministic.

use settle_planner::{KindParams, ProfileKind};

use crate::error::Error;
use crate::input::tune_spec::TuneSpec;
use crate::kinds::corner::Corner;
use crate::kinds::scan::ScanSpec;
use crate::kinds::shaping::ShaperSetting;
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;
use crate::workflows::tune::scan_figures::scan_figures;

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
                sh.kind
                    .map_or_else(|| "none".to_string(), |k| k.name().to_string()),
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
