//! Klipper's own choice on the machine `settle tune` tunes, next to settle's, and what it
//! costs in settle's terms.
//!
//! Klipper chooses from a resonance spectrum (`SHAPER_CALIBRATE`: klippy/extras/
//! shaper_calibrate.py, run here by settle-planner's `shaper_select`). The spectrum is the
//! one Klipper's default resonance test would record on this machine: the expected Welch
//! PSD of the test's commanded acceleration (5 to 135 Hz at 1 Hz/s, 60 mm/s^2 per Hz, the
//! slow sweeping wave) seen through the machine's modes, at an ADXL345's 3200 samples per
//! second (settle-identify's `SweepModel`, the model its fits are checked with), normalised
//! as Klipper normalises it. Klipper's recommendation is then run through settle's own
//! scoring as a candidate: a trapezoid (Klipper plans trapezoids) with Klipper's shaper as
//! `SAVE_CONFIG` stores it (frequency to 0.1 Hz, `damping_ratio` 0.1, the default), at the
//! lower of the current acceleration and Klipper's suggested `max_accel` (rounded down to
//! 100 mm/s^2 so that it stays within Klipper's own 0.12 mm of smoothing).

use settle_identify::SweepTest;
use settle_identify::fit::sweep_model::{ModeParams, SweepModel};
use settle_identify::welch::Welch;
use settle_planner::ProfileKind;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::KLIPPER_DEFAULT_DAMPING_RATIO;
use settle_planner::shaper_select::{
    CalibrationData, Fit, MAX_FREQ_HZ, SelectOptions, Selection, ShaperFreqs, find_best_shaper,
    fit_shaper,
};

use super::search::{Candidate, Plan, Score};
use crate::error::Error;
use crate::execute::pool::quiet;
use crate::studies::corner::Corner;
use crate::studies::shaping::ShaperSetting;

/// The accelerometer rate of the spectrum (samples per second): the ADXL345's rate in
/// Klipper's `[adxl345]` default.
pub const SAMPLE_RATE_HZ: f64 = 3200.0;

/// Klipper's choice on one axis and settle's view of it.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperChoice {
    /// Klipper's fits and recommendation on the machine's spectrum.
    pub selection: Selection,
    /// Its recommendation as a candidate, scored by settle.
    pub score: Score,
    /// Klipper's suggested `max_accel` for it (mm/s^2, unrounded).
    pub suggested_max_accel_mm_s2: f64,
    /// settle's recommendation judged by Klipper's criterion on the same spectrum (`None`
    /// when it is unshaped or not one of Klipper's shapers).
    pub settle_fit: Option<Fit>,
    /// The modes the spectrum comes from: `(Hz, damping ratio, weight)`.
    pub modes: Vec<(f64, f64, f64)>,
}

/// The modes of axis `axis` of the plan's machine with their weights: the modes form's,
/// or a physical axis's linearised modes at the move's start.
pub fn weighted_modes(plan: &Plan) -> Vec<(f64, f64, f64)> {
    let base = &plan.base;
    let Some(machine) = base.machine.physical() else {
        return base
            .machine
            .modes_of(&base.axis)
            .iter()
            .map(|m| (m.frequency_hz, m.damping_ratio, m.weight))
            .collect();
    };
    let Ok(axes) = machine.compile(settle_sim::DriverMode::Linear) else {
        return Vec::new();
    };
    let (Some(axis), Ok(limits)) = (axes.iter().find(|a| a.name == base.axis), base.limits_si())
    else {
        return Vec::new();
    };
    let Ok(profile) =
        base.profile
            .rest_to_rest(base.start_mm * 1e-3, base.distance_mm * 1e-3, &limits)
    else {
        return Vec::new();
    };
    settle_sim::closed_form::LinearResponse::new(axis, &profile)
        .map(|lr| {
            lr.weighted_modes()
                .into_iter()
                .filter(|(f, _, _)| *f > 0.5)
                .collect()
        })
        .unwrap_or_default()
}

/// The calibration data Klipper's default resonance test would give on `modes` (see the
/// module documentation), normalised as Klipper does before choosing.
pub fn spectrum(modes: &[(f64, f64, f64)]) -> CalibrationData {
    spectrum_of(modes, &SweepTest::klipper(), SAMPLE_RATE_HZ)
}

/// [`spectrum`] of the resonance test `test` recorded at `sample_rate_hz`.
pub fn spectrum_of(
    modes: &[(f64, f64, f64)],
    test: &SweepTest,
    sample_rate_hz: f64,
) -> CalibrationData {
    let welch = Welch::klipper(sample_rate_hz);
    let bin = welch.bin_hz();
    let bins: Vec<usize> = (0..)
        .take_while(|k| *k as f64 * bin <= MAX_FREQ_HZ.min(sample_rate_hz / 2.0))
        .collect();
    let model = SweepModel::new(&welch, &bins, test);
    let params: Vec<ModeParams> = modes
        .iter()
        .map(|&(f_hz, zeta, weight)| ModeParams { f_hz, zeta, weight })
        .collect();
    let mut psd = vec![0.0; bins.len()];
    model.evaluate(1.0, 0.0, &params, &mut Vec::new(), &mut psd);
    let mut data = CalibrationData {
        freq_hz: bins.iter().map(|&k| k as f64 * bin).collect(),
        psd_sum: psd,
        ..CalibrationData::default()
    };
    data.normalize_to_frequencies();
    data
}

/// Whether the report compares with Klipper: a Klipper (or unrestricted) search of a
/// point-to-point or scan move on one axis with shapers.
pub fn applies(plan: &Plan) -> bool {
    matches!(plan.firmware.firmware(), Some(Firmware::Klipper) | None)
        && plan.base.state::<Corner>().is_none()
        && plan
            .candidates
            .iter()
            .any(|c| c.shaper.is_some_and(|s| s.shaper_type.is_some()))
}

/// Klipper's choice on the plan's machine, scored by settle, with settle's `winner`
/// judged by Klipper; `None` where it does not apply ([`applies`]).
pub fn compare(
    plan: &Plan,
    winner: &Score,
    jobs: Option<usize>,
) -> Result<Option<KlipperChoice>, Error> {
    if !applies(plan) {
        return Ok(None);
    }
    let modes = weighted_modes(plan);
    if modes.is_empty() {
        return Ok(None);
    }
    let data = [spectrum(&modes)];
    let opts = SelectOptions::default();
    let Ok(selection) = find_best_shaper(&data, &opts) else {
        return Ok(None);
    };
    let pick = selection.recommended;
    let suggested = pick.max_accel_mm_s2;
    let accel = plan
        .base
        .amax_mm_s2
        .min((suggested / 100.0).floor() * 100.0);
    let candidate = Candidate {
        kind: ProfileKind::Trapezoid,
        jmax_mm_s3: None,
        params: settle_planner::ProfileParams::default(),
        shaper: Some(ShaperSetting {
            shaper_type: Some(pick.shaper_type),
            frequency_hz: (pick.frequency_hz * 10.0).round() / 10.0,
            damping_ratio: KLIPPER_DEFAULT_DAMPING_RATIO,
        }),
        amax_mm_s2: Some(accel),
    };
    let score = super::rank::evaluate(plan, &[candidate], jobs, &quiet)?.remove(0);
    let settle_fit = winner
        .candidate
        .shaper
        .and_then(|sh| sh.shaper_type.map(|k| (k, sh)))
        .filter(|(k, _)| k.firmware() == Firmware::Klipper)
        .and_then(|(k, sh)| {
            let one = SelectOptions {
                shaper_freqs: ShaperFreqs::List(vec![sh.frequency_hz]),
                damping_ratio: sh.damping_ratio,
                ..SelectOptions::default()
            };
            fit_shaper(k, &data, &one).ok().map(|(fit, _)| fit)
        });
    Ok(Some(KlipperChoice {
        selection,
        score,
        suggested_max_accel_mm_s2: suggested,
        settle_fit,
        modes,
    }))
}
