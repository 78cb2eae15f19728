//! The `[tune]` table of a scenario: the search of `settle tune` (see
//! `crate::workflows::tune`), as written.

use std::collections::BTreeMap;

use serde::Deserialize;

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
    /// Robustness margin in (0, 1]: candidates are scored on settling into
    /// `margin x band_um`, so the winner's residual has room inside the band for what
    /// another engine or the real machine adds [default
    /// `crate::workflows::tune::grid::DEFAULT_MARGIN`].
    pub margin: Option<f64>,
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
    /// Rounds of local refinement around the grid winner (a compass search on the shaper
    /// frequency and the jerk with halving steps; 0 = grid only) [default
    /// `crate::workflows::tune::rank::DEFAULT_REFINE_ROUNDS`].
    pub refine_rounds: Option<usize>,
    /// Microsteps per mm of every axis for the TMC4361A export, where `[tune.axis.<name>]`
    /// does not give the axis's own [default: none; the register file needs the machine's
    /// own resolution and is not written without it].
    pub usteps_per_mm: Option<f64>,
    /// TMC4361A clock (Hz) for the register export [default 16 MHz, the evaluation
    /// board's crystal; the chip takes 4 to 32 MHz].
    pub tmc_clock_hz: Option<u32>,
    /// Axes to tune, each on its own with its own shaper and frequency [default: the
    /// move's axis].
    pub axes: Option<Vec<String>>,
    /// Restrict candidates to what one firmware runs: `klipper`, `marlin`, `rrf` (planned
    /// trapezoids with that firmware's shapers), `tmc4361a` (the chip's S-ramps, no
    /// shaper) or `any` [default `any`].
    pub firmware: Option<String>,
    /// With `firmware = "marlin"`: the printer's input shaper, `ft_motion` (Fixed-Time
    /// Motion, `M493`, Marlin 2.1.3+) or `input_shaping` (the built-in ZV shaper, `M593`,
    /// Marlin 2.1.2+) [default `ft_motion`; `settle import marlin` writes the reply's].
    pub marlin_shaping: Option<String>,
    /// Accelerations searched (mm/s^2) [default: `limits.amax_mm_s2` alone].
    pub accelerations_mm_s2: Option<Vec<f64>>,
    /// Largest shaper smoothing a candidate may have at its acceleration (mm, Klipper's
    /// figure at the square-corner velocity of 5 mm/s); shaped candidates above it are
    /// infeasible [default 0.12 mm, the target of Klipper's suggested max_accel].
    pub max_smoothing_mm: Option<f64>,
    /// Robustness: shaped candidates are scored on the worst of their shaper at its
    /// frequency and detuned by this many percent either way (the real mode a few percent
    /// off the identified one) [default 0: the nominal frequency alone].
    pub frequency_tolerance_pct: Option<f64>,
    /// The damping ratio every shaper is designed for, 0 to under 1 (within what each
    /// shaper's firmware takes) [default: on a machine given by its modes (a machine file
    /// from `settle identify`, or modes written by hand) the damping ratio of the mode the
    /// shaper is tuned to; on a physical machine, whose modal damping is an estimate from
    /// its parts, Klipper's default 0.1].
    pub shaper_damping_ratio: Option<f64>,
    /// The user's current settings per axis (`[tune.axis.x]`): the baseline candidate of
    /// that axis and the machine's resolution for the register export.
    pub axis: Option<BTreeMap<String, AxisCurrent>>,
}

/// `[tune.axis.<name>]`: one axis's current firmware settings.
#[derive(Debug, Clone, Deserialize, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct AxisCurrent {
    /// The current shaper (`shaper.type` names; `none` for no shaping) [default: the
    /// scenario's `[shaper]`].
    pub shaper: Option<String>,
    /// Its frequency (Hz).
    pub frequency_hz: Option<f64>,
    /// Its damping ratio [default 0.1].
    pub damping_ratio: Option<f64>,
    /// The axis's microsteps per mm (firmware steps per mm x microstepping).
    pub usteps_per_mm: Option<f64>,
    /// The axis's own acceleration cap (mm/s^2): Marlin's and RepRapFirmware's `M201`,
    /// which caps every move's acceleration as `M204` does. `marlin.gcode` and `rrf.g`
    /// raise it with `M201` where it is below the recommended acceleration [default: not
    /// known; the exports then set it to the recommended acceleration whenever that
    /// changes].
    pub max_accel_mm_s2: Option<f64>,
}
