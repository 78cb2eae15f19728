//! One shaper fitted to calibration data (`fit_shaper`, `_estimate_remaining_vibrations`).

use super::accel::max_accel_mm_s2;
use super::data::CalibrationData;
use super::grid::arange;
use super::options::{
    Fit, MAX_FREQ_HZ, MAX_SHAPER_FREQ_HZ, SelectOptions, ShaperFreqs, TARGET_SMOOTHING_MM,
    TEST_DAMPING_RATIOS,
};
use crate::PlanError;
use crate::shaper::{
    KLIPPER_DEFAULT_DAMPING_RATIO, Shaper, ShaperType, remaining_vibration, smoothing_mm,
};

/// Klipper's "the shaper reduces vibrations at most 20x": PSD below `max/20` is ignored.
const SHAPER_VIBRATION_REDUCTION: f64 = 20.0;

/// numpy's sum of a contiguous array (pairwise summation in blocks of up to 128 with eight
/// accumulators), so that sums over PSD bins round as Klipper's do.
fn numpy_sum(a: &[f64]) -> f64 {
    let n = a.len();
    if n < 8 {
        let mut r = 0.0;
        for x in a {
            r += x;
        }
        r
    } else if n <= 128 {
        let mut r = [0.0; 8];
        r.copy_from_slice(&a[..8]);
        let whole = n - n % 8;
        let mut i = 8;
        while i < whole {
            for (j, rj) in r.iter_mut().enumerate() {
                *rj += a[i + j];
            }
            i += 8;
        }
        let mut res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for x in &a[whole..] {
            res += x;
        }
        res
    } else {
        let mut n2 = n / 2;
        n2 -= n2 % 8;
        numpy_sum(&a[..n2]) + numpy_sum(&a[n2..])
    }
}

/// Remaining vibration of a train on one PSD for one test damping ratio.
fn remaining(a: &[f64], t: &[f64], zeta: f64, freq_hz: &[f64], psd: &[f64]) -> f64 {
    let thr = psd.iter().copied().fold(f64::NEG_INFINITY, f64::max) / SHAPER_VIBRATION_REDUCTION;
    let left: Vec<f64> = freq_hz
        .iter()
        .zip(psd)
        .map(|(&f, &p)| (remaining_vibration(a, t, f, zeta) * p - thr).max(0.0))
        .collect();
    let all: Vec<f64> = psd.iter().map(|&p| (p - thr).max(0.0)).collect();
    numpy_sum(&left) / numpy_sum(&all)
}

/// The frequencies tried for `kind`, in increasing order.
fn test_freqs(kind: ShaperType, freqs: &ShaperFreqs) -> Result<Vec<f64>, PlanError> {
    let bad = |reason: String| PlanError::InvalidShaper {
        name: kind.to_string(),
        reason,
    };
    let out = match freqs {
        ShaperFreqs::List(v) => v.clone(),
        ShaperFreqs::Range {
            start_hz,
            end_hz,
            step_hz,
        } => {
            // Python's `x or default`: zero counts as unset.
            let set = |x: Option<f64>| x.filter(|&v| v != 0.0);
            let end = set(*end_hz).unwrap_or(MAX_SHAPER_FREQ_HZ);
            let start = set(*start_hz)
                .or(kind.klipper_min_freq_hz())
                .ok_or_else(|| bad("needs a start frequency (no Klipper minimum)".into()))?;
            arange(start.min(end - 1e-7), end, set(*step_hz).unwrap_or(0.2))
        }
    };
    if out.is_empty() || out.iter().any(|f| !(f.is_finite() && *f > 0.0)) {
        return Err(bad(format!(
            "test frequencies must be a non-empty list of positive numbers, got {out:?}"
        )));
    }
    Ok(out)
}

/// Fit one shaper (`fit_shaper`): Klipper's pick for it and every frequency tried, from the
/// highest down (the scan stops early under `max_smoothing_mm`).
pub fn fit_shaper(
    kind: ShaperType,
    data: &[CalibrationData],
    opts: &SelectOptions,
) -> Result<(Fit, Vec<Fit>), PlanError> {
    if data.is_empty()
        || data
            .iter()
            .any(|d| d.freq_hz.is_empty() || d.freq_hz.len() != d.psd_sum.len())
    {
        return Err(PlanError::InvalidInput {
            reason: "calibration data needs frequency bins and one PSD value per bin",
        });
    }
    let zeta = if opts.damping_ratio == 0.0 {
        KLIPPER_DEFAULT_DAMPING_RATIO
    } else {
        opts.damping_ratio
    };
    let test_dr: &[f64] = if opts.test_damping_ratios.is_empty() {
        &TEST_DAMPING_RATIOS
    } else {
        &opts.test_damping_ratios
    };
    let freqs = test_freqs(kind, &opts.shaper_freqs)?;
    let highest = freqs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let max_freq = opts
        .max_freq_hz
        .filter(|&v| v != 0.0)
        .unwrap_or(MAX_FREQ_HZ)
        .max(highest);
    let sets: Vec<(Vec<f64>, Vec<f64>)> = data
        .iter()
        .map(|d| {
            d.freq_hz
                .iter()
                .zip(&d.psd_sum)
                .filter(|(f, _)| **f <= max_freq)
                .map(|(f, p)| (*f, *p))
                .unzip()
        })
        .collect();
    // Klipper's remaining vibration is the vibration over its threshold after the shaper
    // divided by that before it: on a spectrum without a positive finite value (a sensor
    // that read a constant, a file of zeros) it is 0 / 0, which Klipper's numpy makes NaN
    // and a comparison would make a confident "0 % left". Nothing was measured.
    if sets.iter().any(|(_, psd)| {
        let max = psd.iter().copied().fold(0.0, f64::max);
        !(max > 0.0 && max.is_finite())
    }) {
        return Err(PlanError::InvalidInput {
            reason: "the spectrum holds no vibration to shape (no positive finite PSD value up to the highest frequency fitted): nothing was measured",
        });
    }
    let mut results: Vec<Fit> = Vec::with_capacity(freqs.len());
    let mut best: Option<Fit> = None;
    for &f in freqs.iter().rev() {
        let shaper = Shaper::new(kind, f, zeta)?;
        let (a, t) = (shaper.amplitudes(), shaper.times_s());
        let smoothing = smoothing_mm(a, t, 5000.0, opts.scv_mm_s);
        if let (Some(limit), Some(b)) = (opts.max_smoothing_mm.filter(|&m| m != 0.0), best)
            && smoothing > limit
        {
            return Ok((b, results));
        }
        let max_accel = max_accel_mm_s2(a, t, opts.scv_mm_s, TARGET_SMOOTHING_MM);
        let mut vibrations = 0.0;
        for (bins, psd) in &sets {
            for &dr in test_dr {
                let v = remaining(a, t, dr, bins, psd);
                if v > vibrations {
                    vibrations = v;
                }
            }
        }
        let score = smoothing * (vibrations.powf(1.5) + vibrations * 0.2 + 0.01);
        let fit = Fit {
            shaper_type: kind,
            frequency_hz: f,
            vibrations,
            smoothing_mm: smoothing,
            score,
            max_accel_mm_s2: max_accel,
        };
        results.push(fit);
        if best.is_none_or(|b| b.vibrations > fit.vibrations) {
            best = Some(fit);
        }
    }
    let Some(best) = best else {
        return Err(PlanError::NoSolution {
            reason: "no shaper frequency to try",
        });
    };
    // A frequency not much worse than the best but with a better score (less smoothing).
    let mut selected = best;
    for res in results.iter().rev() {
        if res.vibrations < best.vibrations * 1.1 + 0.0005
            && (res.score < selected.score
                || opts.max_vibrations.is_some_and(|m| best.vibrations > m))
        {
            selected = *res;
        }
    }
    Ok((selected, results))
}
