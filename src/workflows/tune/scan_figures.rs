//! The scan-step figure of merit of `settle tune`: the overhead per line at which a
//! raster's step is settled.

use crate::measure::metrics::Metrics;
use crate::studies::scan::ScanSpec;

/// The scan-step figures of one scan run (from its [`Metrics::extra`] columns).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanFigures {
    /// The step's duration (s), shaper included.
    pub step_s: f64,
    /// The planner's window between exit and re-entry (s): the fastest turnaround or the
    /// step, whichever is longer.
    pub window_s: f64,
    /// Peak |error| of the step axis over the next line at that window (um).
    pub line_residual_peak_um: f64,
    /// Per band: the overhead per line at which the step is settled when the fly axis
    /// re-enters and stays settled over the line (s); infinite when the step is still
    /// outside the band when the next line ends.
    pub overhead_s: Vec<f64>,
}

/// The scan-step figure of merit: the time between the fly axis leaving the region and
/// the step axis being settled, `ready = offset + step + settle`, where `offset` is where
/// the step starts in the window (0 for placement `exit`) and `settle` the run's
/// `scan_step_settle_time_s_<band>um` (from the step's end until the error enters the
/// band for good); the overhead per line a scan needs for a settled re-entry is
/// `max(window, ready)` (the fly turnaround cannot be shorter than the planner's fastest,
/// and a scan planned with `settle_margin_s = settle` re-enters at `ready`).
pub fn scan_figures(scan: &ScanSpec, m: &Metrics, bands_um: &[f64]) -> ScanFigures {
    let get = |k: &str| {
        m.extra
            .iter()
            .find(|(n, _)| n == k)
            .map_or(f64::NAN, |(_, v)| *v)
    };
    let step_s = get("scan_step_s");
    let window_s = get("scan_window_s");
    let offset_s = if scan.placement == "centered" {
        0.5 * (window_s - step_s - scan.settle_margin_s)
    } else {
        0.0
    };
    let overhead_s = bands_um
        .iter()
        .map(|b| {
            let settle = get(&format!("scan_step_settle_time_s_{b}um"));
            if settle.is_finite() {
                window_s.max(offset_s + step_s + settle)
            } else {
                f64::INFINITY
            }
        })
        .collect();
    ScanFigures {
        step_s,
        window_s,
        line_residual_peak_um: get("scan_line_residual_peak_um"),
        overhead_s,
    }
}
