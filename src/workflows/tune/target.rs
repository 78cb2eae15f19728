//! What each export target can express, so that `settle tune` searches only that and
//! writes only what the target understands: one function per question, keyed by the
//! target ([`Firmware`]).
//!
//! - the damping ratio a shaper may be designed for ([`damping_range`]): Klipper's
//!   `max_damping_ratio` per shaper (`klippy/extras/shaper_defs.py`: 0.99, `ei` 0.4,
//!   `2hump_ei` 0.3, `3hump_ei` 0.2), Marlin's `M493 I` (0.01 to under 1), RepRapFirmware's
//!   `M593 S` (0 to 0.99); Marlin's `M593 D` takes 0 to 1 (M593.cpp), and its ZV is
//!   Klipper's `zv`, designed within Klipper's 0 to 0.99 (a damping ratio of 1 has no
//!   damped period to shape);
//! - the TMC4361A's register ranges ([`tmc_ranges`]): BOW1..4 and AMAX/DMAX are unsigned
//!   24-bit registers, VMAX a signed 32-bit 24.8 fixed point (the chip's datasheet, the
//!   table in `planner/src/tmc/registers.rs`), in the frequency mode the export writes;
//! - whether the firmware has one acceleration for every axis ([`one_acceleration`]):
//!   Klipper's `[printer] max_accel`, RepRapFirmware's and Marlin's `M204 P`;
//! - whether a recommendation can be written ([`expressible`]): for Prusa-Firmware-Buddy
//!   also a shaper frequency within the 10 to 100 Hz its `M593` takes
//!   ([`Candidates::frequency_range`], which the search holds to).

use settle_planner::ProfileKind;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::ShaperType;
use settle_planner::tmc::registers::TmcUnits;

use super::firmware::Candidates;
use super::search::Candidate;

/// The damping ratio written with Klipper's "no shaping" (frequency 0): its default.
pub const KLIPPER_OFF_DAMPING: f64 = settle_planner::shaper::KLIPPER_DEFAULT_DAMPING_RATIO;

/// The damping ratios a shaper of `kind` may be designed for on its firmware, `(lowest,
/// highest)`.
pub fn damping_range(kind: ShaperType) -> (f64, f64) {
    match kind.firmware() {
        Firmware::Klipper => (
            0.0,
            match kind.family() {
                "ei" => 0.4,
                "2hump_ei" => 0.3,
                "3hump_ei" => 0.2,
                _ => 0.99,
            },
        ),
        Firmware::Marlin => (0.01, 0.99),
        // RepRapFirmware's, and any other (no firmware but these three has shapers).
        _ => (0.0, 0.99),
    }
}

/// The damping ratio a shaper of `kind` is designed for on a mode of damping `zeta`: the
/// mode's own, within [`damping_range`] (rounded to 3 decimals, as a configuration file
/// holds it), and why it differs when it had to be moved into the range.
pub fn design_damping(kind: ShaperType, zeta: f64) -> (f64, Option<String>) {
    let (lo, hi) = damping_range(kind);
    let z = (zeta * 1000.0).round() / 1000.0;
    if z > hi {
        (
            hi,
            Some(format!(
                "{} takes a damping ratio of at most {hi}; the mode's is {zeta:.3}",
                kind.name()
            )),
        )
    } else if z < lo {
        (
            lo,
            Some(format!(
                "{} takes a damping ratio of at least {lo}; the mode's is {zeta:.3}",
                kind.name()
            )),
        )
    } else {
        (z, None)
    }
}

/// Whether the firmware has one acceleration for all axes (so a recommendation for
/// several axes shares it). `any` exports Klipper and RepRapFirmware settings, which do.
pub fn one_acceleration(fw: Candidates) -> bool {
    fw.firmware() != Some(Firmware::Tmc4361a)
}

/// The largest value of an unsigned 24-bit register (BOW1..4, AMAX, DMAX).
const U24_MAX: f64 = 16_777_215.0;
/// The largest value of VMAX (signed 32 bits).
const I32_MAX: f64 = 2_147_483_647.0;

/// What the TMC4361A's registers hold on an axis (frequency mode, the mode the export
/// writes), in mm-based units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TmcRanges {
    /// Smallest and largest jerk (BOW, mm/s^3): one LSB and 2^24 - 1 LSB.
    pub jerk_mm_s3: (f64, f64),
    /// Largest acceleration (AMAX, DMAX; mm/s^2).
    pub accel_mm_s2: f64,
    /// Largest speed (VMAX; mm/s).
    pub speed_mm_s: f64,
}

/// The TMC4361A's ranges at `usteps_per_mm` microsteps per mm and clock `f_clk_hz`.
pub fn tmc_ranges(usteps_per_mm: f64, f_clk_hz: u32) -> TmcRanges {
    let u = TmcUnits {
        f_clk_hz,
        usteps_per_unit: usteps_per_mm,
        direct_acc: false,
        direct_bow: false,
    };
    TmcRanges {
        jerk_mm_s3: (u.bow_lsb(), U24_MAX * u.bow_lsb()),
        accel_mm_s2: U24_MAX * u.accel_lsb(),
        speed_mm_s: I32_MAX * u.velocity_lsb(),
    }
}

/// `Ok` when `runs` (a firmware, and for Marlin its input shaper) can run candidate `c`
/// as it was simulated (its profile kind and shaper), else why not. The jerk and register
/// ranges of the TMC4361A are checked by the export, and kept inside them by the search.
pub fn expressible(runs: Candidates, c: &Candidate) -> Result<(), String> {
    runs.check_kind(c.kind)?;
    runs.check_shaper(c.shaper.and_then(|s| s.shaper_type))?;
    if let Some(sh) = c.shaper.filter(|s| s.shaper_type.is_some())
        && let Err(e) = sh.shaper()
    {
        return Err(e.to_string());
    }
    if let Some(sh) = c.shaper.filter(|s| s.shaper_type.is_some())
        && !runs.takes_frequency(sh.frequency_hz)
        && let Some((lo, hi)) = runs.frequency_range()
    {
        return Err(format!(
            "Prusa-Firmware-Buddy clamps M593 F to {lo} to {hi} Hz (150 Hz on the MINI), not {} Hz",
            sh.frequency_hz
        ));
    }
    if runs.firmware() == Some(Firmware::Tmc4361a) && c.kind == ProfileKind::Trapezoid {
        return Err("a trapezoid's bows are infinite".into());
    }
    Ok(())
}
