//! The scan study's own figures, measured from the step axis's toolhead positions over the
//! whole raster (see the module documentation of [`crate::studies::scan`] for their
//! definitions).

use settle_planner::raster::Raster;

use crate::error::Error;
use crate::studies::Probe;
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::spec::run_spec::RunSpec;

/// Measures a planned raster's step axis from the run's series.
#[derive(Debug)]
pub struct StepProbe {
    /// The raster the run follows.
    pub raster: Raster,
    /// The step axis's start position (m).
    pub y0_m: f64,
}

impl Probe for StepProbe {
    fn measure(&self, run: &RunSpec, series: &Series, m: &mut Metrics) -> Result<(), Error> {
        let ch = format!("toolhead_{}", run.axis);
        let y = &series
            .channel(&ch)
            .ok_or_else(|| Error::Sim {
                run: run.id,
                source: settle_sim::SimError::Unsupported {
                    backend: "scan",
                    reason: format!("no channel {ch}"),
                },
            })?
            .data;
        m.extra = step_metrics(&series.t_s, y, &self.raster, self.y0_m, &run.bands_um);
        Ok(())
    }
}

/// The scan columns from the step axis's toolhead positions `y` (m) at times `t` (s,
/// increasing), for the raster `r` whose step axis started at `y0` (m).
pub fn step_metrics(
    t: &[f64],
    y: &[f64],
    r: &Raster,
    y0: f64,
    bands_um: &[f64],
) -> Vec<(String, f64)> {
    let mut reentry_um: f64 = 0.0;
    let mut line_peak_um: f64 = 0.0;
    let mut settle_s = vec![0.0f64; bands_um.len()];
    for tr in &r.turnarounds {
        let target = y0 + tr.y_to;
        let err_um = |i: usize| (y[i] - target).abs() * 1e6;
        let next_exit = tr.reentry_s + r.overhead.line_s;
        // The error at re-entry, interpolated between the samples around it.
        let k = t.partition_point(|&ti| ti < tr.reentry_s).min(t.len() - 1);
        let at = if k > 0 && t[k] > tr.reentry_s {
            let f = (tr.reentry_s - t[k - 1]) / (t[k] - t[k - 1]);
            ((y[k - 1] + f * (y[k] - y[k - 1])) - target).abs() * 1e6
        } else {
            err_um(k)
        };
        reentry_um = reentry_um.max(at);
        let end = t.partition_point(|&ti| ti <= next_exit).max(k);
        let peak = (k..end).map(err_um).fold(at, f64::max);
        line_peak_um = line_peak_um.max(peak);
        // Settle time after the step's end, until the next exit.
        let first = t.partition_point(|&ti| ti < tr.step_end_s);
        let last = t.partition_point(|&ti| ti <= next_exit);
        for (b, s) in bands_um.iter().zip(&mut settle_s) {
            let out = (first..last).rev().find(|&i| err_um(i) > *b);
            let here = match out {
                None => 0.0,
                Some(i) if i + 1 >= last => f64::INFINITY,
                Some(i) => {
                    // Linear crossing between the last sample out and the next one in.
                    let (e0, e1) = (err_um(i), err_um(i + 1));
                    let tc = t[i] + (t[i + 1] - t[i]) * (e0 - b) / (e0 - e1);
                    (tc - tr.step_end_s).max(0.0)
                }
            };
            *s = s.max(here);
        }
    }
    let mut out = vec![
        ("scan_step_s".to_string(), r.overhead.step_s),
        ("scan_window_s".to_string(), r.overhead.per_line_s),
        ("scan_reentry_error_um".to_string(), reentry_um),
        ("scan_line_residual_peak_um".to_string(), line_peak_um),
    ];
    for b in bands_um {
        let settled = if line_peak_um <= *b { 1.0 } else { 0.0 };
        out.push((format!("scan_settled_{b}um"), settled));
    }
    for (b, s) in bands_um.iter().zip(&settle_s) {
        out.push((format!("scan_step_settle_time_s_{b}um"), *s));
    }
    out
}
