//! The peaks a person sees in a sweep fit's figure that are not modes, each with the
//! reason: the bumps the fitted model leaves in the data, with the verdict of the model
//! selection where it tried a further mode there.

use super::lm::LmFit;
use super::sweep_residual::SweepResidual;
use super::{BIC_MARGIN, FittedSpectrum, SIGNAL_OVER_FLOOR};
use crate::result::RejectedPeak;

/// A bump counts when the data stand this many times over the fitted model (local
/// maximum over +-2 bins) in a bin whose signal stands [`SIGNAL_OVER_FLOOR`] times over
/// the noise floor.
pub const BUMP_RATIO: f64 = 1.5;

/// The mode of `larger` (one more than `smaller`) farthest from all of `smaller`'s: the
/// one the model selection added.
fn added_mode_hz(larger: &LmFit, smaller: &LmFit) -> f64 {
    let old: Vec<f64> = SweepResidual::modes(&smaller.theta)
        .iter()
        .map(|m| m.f_hz)
        .collect();
    SweepResidual::modes(&larger.theta)
        .iter()
        .map(|m| m.f_hz)
        .max_by(|a, b| {
            let d = |f: &f64| {
                old.iter()
                    .map(|o| (o - f).abs())
                    .fold(f64::INFINITY, f64::min)
            };
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(f64::NAN)
}

/// The further mode tried and refused: where it would lie and why it is not a mode.
pub fn refused_candidate(
    larger: &LmFit,
    smaller: &LmFit,
    bic_larger: f64,
    bic_smaller: f64,
    preferred: bool,
) -> RejectedPeak {
    let gain = bic_smaller - bic_larger;
    let reason = if !preferred && gain < 0.0 {
        format!(
            "a further mode here raises the Bayesian information criterion by {:.1}; a mode must lower it by {BIC_MARGIN}",
            -gain
        )
    } else if !preferred {
        format!(
            "a further mode here lowers the Bayesian information criterion by {gain:.1}, less than the {BIC_MARGIN} a mode must gain"
        )
    } else {
        "a further mode here would not stand three standard deviations clear of zero (weight or damping ratio), or would lie within a bin of another mode".to_string()
    };
    RejectedPeak {
        frequency_hz: added_mode_hz(larger, smaller),
        reason,
    }
}

/// The bumps the fitted model leaves (see [`BUMP_RATIO`]), more than 3 bins from every
/// mode's natural and peak frequency (`taken_hz`). A bump within 3 bins of a further mode
/// the model selection tried and refused (`tried`) carries that verdict; the others say
/// that no further mode passed, or (`limit`) that the fit holds the most modes allowed.
pub fn bumps(
    s: FittedSpectrum,
    taken_hz: &[f64],
    tried: &[RejectedPeak],
    limit: Option<usize>,
) -> Vec<RejectedPeak> {
    let (data, freq, bin) = (s.data, s.freq, s.bin);
    let n = data.len();
    let ratio: Vec<f64> = data.iter().zip(s.model).map(|(d, m)| d / m).collect();
    let mut out: Vec<RejectedPeak> = Vec::new();
    for j in 0..n {
        let (lo, hi) = (j.saturating_sub(2), (j + 2).min(n - 1));
        let local = (lo..=hi).all(|i| ratio[i] <= ratio[j]);
        if !local || ratio[j] < BUMP_RATIO || data[j] < SIGNAL_OVER_FLOOR * s.noise.max(0.0) {
            continue;
        }
        let near = |f: f64| (f - freq[j]).abs() <= 3.0 * bin;
        if taken_hz.iter().any(|&f| near(f)) || out.iter().any(|p| near(p.frequency_hz)) {
            continue;
        }
        let verdict = tried.iter().find(|p| near(p.frequency_hz));
        let reason = match (verdict, limit) {
            (Some(v), _) => format!(
                "the data stand {:.1} times over the fitted model here; {}",
                ratio[j], v.reason
            ),
            (None, Some(m)) => format!(
                "the data stand {:.1} times over the fitted model here; the fit holds the most modes allowed ({m}, --max-modes)",
                ratio[j]
            ),
            (None, None) => format!(
                "the data stand {:.1} times over the fitted model here; no further mode passed the model selection",
                ratio[j]
            ),
        };
        out.push(RejectedPeak {
            frequency_hz: freq[j],
            reason,
        });
    }
    out
}
