//! Settling metrics, computed streaming (one sample at a time, no traces kept).
//!
//! Definitions (DESIGN.md): error = toolhead - commanded end point after the move ends.
//! - `move_time_s`: commanded duration T.
//! - `residual_peak_um`, `residual_rms_um`: max |error| and RMS error over the samples in
//!   [T, T + window].
//! - `settle_time_s(band)`: time after T until |error| enters the band and stays in it for
//!   the rest of the window; the crossing is interpolated linearly between the last sample
//!   out of the band and the next one. `None` (not settled) if the last sample is outside.
//!   Zero if the error is inside the band from T on.
//! - `overshoot_um`: largest excursion past the target in the direction of motion, over the
//!   whole run (0 if none; for a zero-length move, the largest |error|).
//! - `max_following_error_um`: max |toolhead - commanded| for t <= T.
//! - `move_and_settle_s(band) = move_time_s + settle_time_s(band)`.

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
}

impl Metrics {
    /// `move_time_s + settle_time_s` for band `i`; `None` if not settled.
    pub fn move_and_settle_s(&self, i: usize) -> Option<f64> {
        self.settle_time_s[i].map(|s| self.move_time_s + s)
    }
}

#[derive(Debug, Clone, Copy)]
struct BandState {
    band_m: f64,
    /// Crossing time (s after T) of the last entry into the band; None while outside.
    entered_at: Option<f64>,
}

/// Streaming metric accumulator. Feed samples in time order with [`Accumulator::push`].
#[derive(Debug, Clone)]
pub struct Accumulator {
    target_m: f64,
    direction: f64,
    move_end_s: f64,
    bands: Vec<BandState>,
    bands_um: Vec<f64>,
    prev_post: Option<(f64, f64)>,
    peak_m: f64,
    sum_sq: f64,
    n_post: usize,
    overshoot_m: f64,
    max_follow_m: f64,
    abs_err_max_m: f64,
}

impl Accumulator {
    /// `target_m`: commanded end point; `direction`: sign of the move (0 for none);
    /// `move_end_s`: T; `bands_um`: settling bands.
    pub fn new(target_m: f64, direction: f64, move_end_s: f64, bands_um: &[f64]) -> Self {
        Self {
            target_m,
            direction,
            move_end_s,
            bands: bands_um
                .iter()
                .map(|b| BandState {
                    band_m: b * 1e-6,
                    entered_at: Some(0.0),
                })
                .collect(),
            bands_um: bands_um.to_vec(),
            prev_post: None,
            peak_m: 0.0,
            sum_sq: 0.0,
            n_post: 0,
            overshoot_m: 0.0,
            max_follow_m: 0.0,
            abs_err_max_m: 0.0,
        }
    }

    /// One sample at time `t_s`: commanded and toolhead positions (m).
    pub fn push(&mut self, t_s: f64, commanded_m: f64, toolhead_m: f64) {
        let err = toolhead_m - self.target_m;
        self.overshoot_m = self.overshoot_m.max(err * self.direction);
        self.abs_err_max_m = self.abs_err_max_m.max(err.abs());
        if t_s <= self.move_end_s {
            self.max_follow_m = self.max_follow_m.max((toolhead_m - commanded_m).abs());
        }
        if t_s < self.move_end_s {
            return;
        }
        let tau = t_s - self.move_end_s;
        let e = err.abs();
        self.peak_m = self.peak_m.max(e);
        self.sum_sq += err * err;
        self.n_post += 1;
        for b in &mut self.bands {
            if e > b.band_m {
                b.entered_at = None;
            } else if b.entered_at.is_none() {
                // Entered between the previous sample (outside) and this one.
                b.entered_at = Some(match self.prev_post {
                    Some((tp, ep)) if ep > e => tp + (tau - tp) * (ep - b.band_m) / (ep - e),
                    _ => tau,
                });
            }
        }
        self.prev_post = Some((tau, e));
    }

    /// The metrics of everything pushed.
    pub fn finish(&self) -> Metrics {
        let to_um = 1e6;
        Metrics {
            move_time_s: self.move_end_s,
            residual_peak_um: self.peak_m * to_um,
            residual_rms_um: if self.n_post > 0 {
                (self.sum_sq / self.n_post as f64).sqrt() * to_um
            } else {
                0.0
            },
            bands_um: self.bands_um.clone(),
            settle_time_s: self.bands.iter().map(|b| b.entered_at).collect(),
            overshoot_um: if self.direction == 0.0 {
                self.abs_err_max_m * to_um
            } else {
                self.overshoot_m * to_um
            },
            max_following_error_um: self.max_follow_m * to_um,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feed `f(t)` (m) as the toolhead error after a move ending at t = 0.
    fn run(f: impl Fn(f64) -> f64, dt: f64, window: f64, band_um: f64) -> Metrics {
        let mut acc = Accumulator::new(0.0, 1.0, 0.0, &[band_um]);
        let n = (window / dt).round() as usize;
        for i in 0..=n {
            let t = i as f64 * dt;
            acc.push(t, 0.0, f(t));
        }
        acc.finish()
    }

    #[test]
    fn exponential_decay_settles_at_ln_ratio_times_tau() {
        // e(t) = A exp(-zeta w t): enters eps at ln(A/eps)/(zeta w) and stays.
        let (a, zeta, eps_um, dt): (f64, f64, f64, f64) = (100e-6, 0.05, 10.0, 1e-4);
        let w = 2.0 * std::f64::consts::PI * 40.0;
        let m = run(|t| a * (-zeta * w * t).exp(), dt, 1.0, eps_um);
        let expect = (a / (eps_um * 1e-6)).ln() / (zeta * w);
        let got = m.settle_time_s[0].expect("settles");
        assert!((got - expect).abs() <= dt, "got {got}, expected {expect}");
    }

    #[test]
    fn decaying_sinusoid_settles_at_its_last_band_crossing() {
        // e(t) = A exp(-zeta w t) cos(wd t). The envelope crosses eps at
        // t_env = ln(A/eps)/(zeta w); the signal's last exit lies within half a period before
        // it. Find that exit independently (dense bisection on the continuous function).
        let (a, zeta, f, eps): (f64, f64, f64, f64) = (100e-6, 0.05, 40.0, 10e-6);
        let w = 2.0 * std::f64::consts::PI * f;
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let e = |t: f64| a * (-zeta * w * t).exp() * (wd * t).cos();
        let dt = 1e-4;
        let m = run(e, dt, 1.0, eps * 1e6);
        let got = m.settle_time_s[0].expect("settles");
        let t_env = (a / eps).ln() / (zeta * w);
        // Last time |e| = eps: scan backwards from t_env on a fine grid, then bisect.
        let g = |t: f64| e(t).abs() - eps;
        let h = 1e-6;
        let mut t = t_env;
        while g(t) <= 0.0 {
            t -= h;
        }
        let (mut lo, mut hi) = (t, t + h);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if g(mid) > 0.0 { lo = mid } else { hi = mid }
        }
        assert!((got - hi).abs() <= dt, "got {got}, exact last exit {hi}");
        assert!(got <= t_env && got >= t_env - std::f64::consts::PI / wd);
    }

    #[test]
    fn entering_and_leaving_again_is_not_settled_there() {
        // Inside the band from 0.1 to 0.2 s, outside again at 0.25 s, inside from 0.3 s.
        let f = |t: f64| {
            if (0.1..0.2).contains(&t) || t >= 0.3 {
                1e-6
            } else {
                50e-6
            }
        };
        let m = run(f, 1e-3, 0.5, 10.0);
        let got = m.settle_time_s[0].expect("settles");
        assert!((got - 0.3).abs() <= 1e-3, "settled at {got}, expected ~0.3");
        // And a signal that leaves the band at the end of the window never settled.
        let m = run(|t| if t < 0.45 { 1e-6 } else { 50e-6 }, 1e-3, 0.5, 10.0);
        assert_eq!(m.settle_time_s[0], None);
    }

    #[test]
    fn peak_rms_following_and_overshoot() {
        // Move ends at 1 s towards +target 1 m; during the move the toolhead lags 2 mm.
        let mut acc = Accumulator::new(1.0, 1.0, 1.0, &[50.0]);
        acc.push(0.5, 0.5, 0.498);
        acc.push(1.0, 1.0, 1.0 + 30e-6);
        acc.push(1.5, 1.0, 1.0 - 40e-6);
        let m = acc.finish();
        assert!((m.max_following_error_um - 2000.0).abs() < 1e-6);
        assert!((m.residual_peak_um - 40.0).abs() < 1e-9);
        assert!((m.residual_rms_um - ((30f64.powi(2) + 40f64.powi(2)) / 2.0).sqrt()).abs() < 1e-9);
        assert!((m.overshoot_um - 30.0).abs() < 1e-9);
        assert_eq!(m.settle_time_s[0], Some(0.0));
        assert_eq!(m.move_and_settle_s(0), Some(1.0));
    }
}
