//! Settling metrics: their definitions and types. They are computed streaming, one sample
//! at a time with no traces kept, by [`crate::measure::accumulator::Accumulator`].
//!
//! Definitions: the error is the toolhead position minus the commanded end
//! point, a vector over the machine's axes; the main metrics use its length (the distance
//! to the end point), and each axis also gets its own from its component.
//! - `move_time_s`: commanded duration T.
//! - `residual_peak_um`, `residual_rms_um`: max |error| and RMS error over the samples in
//!   [T, T + window].
//! - `settle_time_s(band)`: time after T until |error| enters the band and stays in it for
//!   the rest of the window; the crossing is interpolated linearly between the last sample
//!   out of the band and the next one. `None` (not settled) if the last sample is outside.
//!   Zero if the error is inside the band from T on.
//! - `overshoot_um`: largest excursion past the target along the direction of motion (the
//!   unit vector from start to end point), over the whole run (0 if none; for a
//!   zero-length move, the largest |error|).
//! - `max_following_error_um`: max |toolhead - commanded| for t <= T.
//! - `move_and_settle_s(band) = move_time_s + settle_time_s(band)`.
//!
//! A run whose stepper lost steps is a failed run ([`Status::LostSteps`]): its numbers
//! describe a machine that no longer knows where it is, so reports show the failure
//! instead of them and never average them.

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Every axis stayed in step.
    Ok,
    /// A stepper's load angle passed 90 electrical degrees on `axis`.
    LostSteps {
        /// The axis that lost steps first (in axis order).
        axis: String,
        /// Full steps lost, summed over axes.
        steps: u32,
    },
    /// The simulation broke down (a value became NaN or infinite, the error grew past
    /// [`BLOWUP_M`], or the backend failed mid-run): the run stopped there.
    Fault {
        /// What happened, where and when (one line, for runs.csv's `reason` column).
        reason: String,
    },
}

/// An error (toolhead minus command) beyond this length (m) on any axis is a numerical
/// blow-up, not a motion. A stable run's following error is about its static deflection
/// `a / w^2`: 0.5 mm for a 40 Hz mode at 3 g, 19 mm for an implausibly soft 2 Hz one; a
/// run past 10 cm has left physics (an unstable integration grows geometrically, so it
/// passes this bound within a few steps of leaving any physical size).
pub const BLOWUP_M: f64 = 0.1;

impl Status {
    /// `ok` or `lost_steps`, for tables.
    pub fn name(&self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::LostSteps { .. } => "lost_steps",
            Status::Fault { .. } => "fault",
        }
    }

    /// Full steps lost (0 when in step).
    pub fn lost_steps(&self) -> u32 {
        match self {
            Status::Ok => 0,
            Status::LostSteps { steps, .. } => *steps,
            Status::Fault { .. } => 0,
        }
    }

    /// Why the run failed, in words (empty when ok).
    pub fn reason(&self) -> String {
        match self {
            Status::Ok => String::new(),
            Status::LostSteps { axis, steps } => {
                format!("lost {steps} full steps (first on axis {axis})")
            }
            Status::Fault { reason } => reason.clone(),
        }
    }
}

/// Per-axis metrics (on that axis's error component). Lengths in um, times in s.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisMetrics {
    /// Axis name.
    pub name: String,
    /// Peak |error| after the move (um).
    pub residual_peak_um: f64,
    /// RMS error after the move (um).
    pub residual_rms_um: f64,
    /// Settle time per band (s); `None` = not settled within the window.
    pub settle_time_s: Vec<Option<f64>>,
    /// Max following error during the move (um).
    pub max_following_error_um: f64,
    /// Largest |load angle| of the axis's stepper (electrical degrees), if it has one.
    pub max_load_angle_deg: Option<f64>,
}

/// Metrics of one run. Lengths in um, times in s.
#[derive(Debug, Clone, PartialEq)]
pub struct Metrics {
    /// Commanded move duration (s).
    pub move_time_s: f64,
    /// Peak |error| after the move (um).
    pub residual_peak_um: f64,
    /// RMS error after the move (um).
    pub residual_rms_um: f64,
    /// Settling bands (um), in the order given.
    pub bands_um: Vec<f64>,
    /// Settle time per band (s); `None` = not settled within the window.
    pub settle_time_s: Vec<Option<f64>>,
    /// Overshoot past the target (um).
    pub overshoot_um: f64,
    /// Max following error during the move (um).
    pub max_following_error_um: f64,
    /// Per axis, in machine order.
    pub axes: Vec<AxisMetrics>,
    /// Whether the run stayed in step.
    pub status: Status,
    /// Contour error and corner metrics when the trajectory follows a path.
    pub path: Option<crate::measure::path_metrics::PathMetrics>,
    /// Extra named figures a study measures (e.g. a scan's step-axis error at re-entry), in
    /// order; `inf` where a time was not reached.
    pub extra: Vec<(String, f64)>,
}

impl Metrics {
    /// A run that failed before it produced any measurement (e.g. its backend refused the
    /// model mid-sweep): every number NaN, status [`Status::Fault`] with `reason`.
    pub fn failed(bands_um: &[f64], reason: String) -> Self {
        Self {
            move_time_s: f64::NAN,
            residual_peak_um: f64::NAN,
            residual_rms_um: f64::NAN,
            bands_um: bands_um.to_vec(),
            settle_time_s: vec![None; bands_um.len()],
            overshoot_um: f64::NAN,
            max_following_error_um: f64::NAN,
            axes: Vec::new(),
            status: Status::Fault { reason },
            path: None,
            extra: Vec::new(),
        }
    }

    /// `move_time_s + settle_time_s` for band `i`; `None` if not settled.
    pub fn move_and_settle_s(&self, i: usize) -> Option<f64> {
        self.settle_time_s[i].map(|s| self.move_time_s + s)
    }

    /// True when the run stayed in step (its numbers are meaningful).
    pub fn is_ok(&self) -> bool {
        self.status == Status::Ok
    }
}
