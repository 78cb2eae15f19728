//! The `[tune]` table of a scenario: the search of `settle tune` (see
//! `crate::workflows::tune`), as written.

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
    /// Microsteps per mm for the Trinamic export [default 1280 = 80 full steps/mm x 16].
    pub usteps_per_mm: Option<f64>,
    /// TMC5160 clock (Hz) for the Trinamic export [default 12 MHz, the internal clock].
    pub tmc_clock_hz: Option<u32>,
}
