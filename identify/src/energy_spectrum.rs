//! The energy spectrum of a known commanded acceleration, computed from its pieces.
//!
//! A resonance test commands a piecewise-constant acceleration `a(t)` (Klipper's
//! generator, [`crate::excitation::SweepTest::pieces`]). What a Welch estimate of the
//! toolhead's response shows is the whole record's spectrum `|T A|^2` smoothed by the
//! window's kernel ([`crate::fit::sweep_model`]), so the model needs `|A(nu)|^2` itself,
//! not only its stationary-phase trend: the sweep's start and stop, the square wave's
//! harmonics, the sweeping wave's lines and their interference with the sweep all shape
//! it. It is computed here without approximation other than the three stated below.
//!
//! The acceleration is averaged over intervals of `dt = 1 / fs` (exact integrals of the
//! pieces), which multiplies its spectrum by `sinc(nu dt)` (divided out) and folds in
//! what lies above `fs / 2`, attenuated by `sinc^2` as well: `fs` is at least
//! [`MIN_RATE_PER_BAND_HZ`] times the highest frequency asked for. Its autocorrelation
//! `R(tau) = int a(t) a(t + tau) dt` (by FFT, zero padded so that it is not circular) is
//! tapered by a lag window `kappa` and transformed:
//!
//! `B(nu) = 2 int R(tau) kappa(tau) exp(-2 pi i nu tau) dtau / sinc^2(nu dt)`
//!
//! the one-sided energy spectral density ((mm/s^2)^2 s/Hz) smoothed by `kappa`'s
//! transform. `kappa` is 1 up to [`FLAT_FRACTION`] of `1 / (2 step)` and falls to 0 by
//! [`END_FRACTION`] of it (raised cosine). The smoothing is harmless: the model integrates
//! `B` against `g = |T|^2 K(f - nu)`, whose own lag extent (one segment plus a few decay
//! times `1 / (2 pi zeta f)` of the modes) lies inside the flat part, so that
//! `int B g = int |A|^2 g` exactly; and a grid of `step` sums it exactly as long as the
//! lag extents of `B` and `g` together stay below `1 / step` (Poisson's summation formula).
//! Both hold when `zeta f` of every mode is above about `3 / (2 pi flat)` Hz, where
//! `flat = FLAT_FRACTION / (2 step)` (0.07 Hz at Klipper's 1.56 Hz bins and 32 steps per
//! bin).

use realfft::RealFftPlanner;

/// The averaging rate is at least this multiple of the highest frequency of interest: what
/// folds back from `fs - nu` is then the square wave's harmonic content there (falling
/// as `nu^-2` relative to the fundamental's `nu^2`) times `sinc^2`, below `1e-6` of the
/// local density. That holds for a sweep, whose folded harmonics stand at other
/// frequencies than the fundamental at any moment; a single step's folded content adds to
/// its own coherently instead, up to about `2 (nu / fs)^2` of its envelope (the test
/// `pulse_matches_closed_form` below bounds it exactly).
pub const MIN_RATE_PER_BAND_HZ: f64 = 24.0;

/// The lag window is flat up to this fraction of the largest lag the grid allows.
pub const FLAT_FRACTION: f64 = 0.7;

/// The lag window reaches zero at this fraction of the largest lag the grid allows.
pub const END_FRACTION: f64 = 0.95;

/// `B` on the grid `g step`, `g = 0, 1, ...`.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergySpectrum {
    step_hz: f64,
    density: Vec<f64>,
}

impl EnergySpectrum {
    /// The spectrum of `pieces` (`(end_time_s, accel_mm_s2)`, each holding from the
    /// previous end, from `t = 0`; zero before and after) on a grid of `step_hz` up to at
    /// least `max_hz`.
    pub fn of_pieces(pieces: &[(f64, f64)], step_hz: f64, max_hz: f64) -> Self {
        let points = (max_hz / step_hz).ceil() as usize + 1;
        // Grid of the final transform: q lags of dt, with q dt = 1 / step.
        let mut q = 1usize;
        while (q as f64) * step_hz < MIN_RATE_PER_BAND_HZ * max_hz || q < 2 * points {
            q *= 2;
        }
        let rate_hz = q as f64 * step_hz;
        let dt = 1.0 / rate_hz;
        let x = box_samples(pieces, dt);
        let half_lags = q / 2;
        let flat_s = FLAT_FRACTION * half_lags as f64 * dt;
        let end_s = END_FRACTION * half_lags as f64 * dt;
        let max_lag = (end_s / dt).ceil() as usize + 1;
        let r = autocorrelation(&x, max_lag, dt);
        // Lag-windowed, symmetric sequence of length q; its transform is real.
        let mut planner = RealFftPlanner::<f64>::new();
        let fft = planner.plan_fft_forward(q);
        let mut y = fft.make_input_vec();
        for (m, &rm) in r.iter().enumerate().take(half_lags) {
            let kappa = lag_window(m as f64 * dt, flat_s, end_s);
            if m == 0 {
                y[0] = rm;
            } else if kappa > 0.0 {
                y[m] = rm * kappa;
                y[q - m] = rm * kappa;
            }
        }
        let mut spectrum = fft.make_output_vec();
        let mut scratch = fft.make_scratch_vec();
        // Lengths come from the plan; an error here would be a bug in this function.
        let density = match fft.process_with_scratch(&mut y, &mut spectrum, &mut scratch) {
            Ok(()) => spectrum
                .iter()
                .take(points)
                .enumerate()
                .map(|(g, c)| {
                    let s = sinc(g as f64 * step_hz * dt);
                    2.0 * dt * c.re / (s * s)
                })
                .collect(),
            Err(_) => vec![f64::NAN; points],
        };
        Self { step_hz, density }
    }

    /// Grid step (Hz).
    pub fn step_hz(&self) -> f64 {
        self.step_hz
    }

    /// The density at `g step`, `g = 0, 1, ...` ((mm/s^2)^2 s/Hz).
    pub fn density(&self) -> &[f64] {
        &self.density
    }
}

/// `sin(pi x) / (pi x)`.
fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        let p = std::f64::consts::PI * x;
        p.sin() / p
    }
}

/// `kappa(tau)`: 1 up to `flat_s`, a raised cosine down to 0 at `end_s`.
fn lag_window(tau_s: f64, flat_s: f64, end_s: f64) -> f64 {
    if tau_s <= flat_s {
        1.0
    } else if tau_s >= end_s {
        0.0
    } else {
        0.5 * (1.0 + (std::f64::consts::PI * (tau_s - flat_s) / (end_s - flat_s)).cos())
    }
}

/// The mean of the piecewise-constant acceleration over `[n dt, (n + 1) dt)`, for every
/// `n` up to the last piece's end.
fn box_samples(pieces: &[(f64, f64)], dt: f64) -> Vec<f64> {
    let end = pieces.last().map_or(0.0, |p| p.0);
    let n = (end / dt).ceil() as usize + 1;
    let mut x = vec![0.0; n];
    let mut start = 0.0;
    for &(stop, a) in pieces {
        // Add a over [start, stop) to the intervals it overlaps.
        let first = ((start / dt).floor() as usize).min(n - 1);
        let last = ((stop / dt).floor() as usize).min(n - 1);
        for (i, v) in x.iter_mut().enumerate().take(last + 1).skip(first) {
            let lo = (i as f64 * dt).max(start);
            let hi = ((i + 1) as f64 * dt).min(stop);
            if hi > lo {
                *v += a * (hi - lo) / dt;
            }
        }
        start = stop;
    }
    x
}

/// `R(m dt) = dt sum_n x_n x_{n + m}` for `m = 0 ..= max_lag` (linear, not circular).
fn autocorrelation(x: &[f64], max_lag: usize, dt: f64) -> Vec<f64> {
    let len = (x.len() + max_lag + 1).next_power_of_two();
    let mut planner = RealFftPlanner::<f64>::new();
    let forward = planner.plan_fft_forward(len);
    let inverse = planner.plan_fft_inverse(len);
    let mut input = forward.make_input_vec();
    input[..x.len()].copy_from_slice(x);
    let mut spectrum = forward.make_output_vec();
    if forward.process(&mut input, &mut spectrum).is_err() {
        return vec![f64::NAN; max_lag + 1];
    }
    for c in spectrum.iter_mut() {
        *c = nalgebra::Complex::new(c.norm_sqr(), 0.0);
    }
    let mut out = inverse.make_output_vec();
    if inverse.process(&mut spectrum, &mut out).is_err() {
        return vec![f64::NAN; max_lag + 1];
    }
    // realfft's inverse is unnormalised: a round trip multiplies by len.
    out.iter()
        .take(max_lag + 1)
        .map(|v| v * dt / len as f64)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::EnergySpectrum;

    /// A single pulse `a` over `[0, T]`: `|A(nu)|^2 = a^2 sin^2(pi nu T) / (pi nu)^2` in
    /// closed form, and `B = 2 |A|^2` (its autocorrelation, `T` long, lies inside the flat
    /// part of the lag window). What remains is the averaging's aliasing: the averaged
    /// samples' transform is `sum_m A(nu - m fs) sinc((nu - m fs) / fs)` (up to phases),
    /// and a single pulse's folded terms `m != 0` add to the `m = 0` term coherently, so
    /// the error is at most `(2 S + S^2)` of the envelope `2 a^2 / (pi nu)^2`, with
    /// `S = sum_m |nu / (nu - m fs)| |sinc((nu - m fs) / fs)|` (`|m| <= 8`, the rest is
    /// smaller than the last term kept); at `nu = 0` every folded term vanishes.
    #[test]
    fn pulse_matches_closed_form() {
        let (a, t) = (3.0, 0.3);
        let spectrum = EnergySpectrum::of_pieces(&[(t, a)], 0.5, 20.0);
        assert_eq!(spectrum.step_hz(), 0.5);
        assert!(spectrum.density().len() >= 41);
        // The averaging rate the construction picks: the least power of two times the step
        // reaching 24 times the band (512 Hz here).
        let fs = 512.0;
        let sinc = |x: f64| {
            let p = std::f64::consts::PI * x;
            if x == 0.0 { 1.0 } else { p.sin() / p }
        };
        for (g, &b) in spectrum.density().iter().enumerate().take(41).skip(1) {
            let nu = g as f64 * 0.5;
            let x = std::f64::consts::PI * nu;
            let envelope = 2.0 * a * a / (x * x);
            let exact = envelope * (x * t).sin().powi(2);
            let s: f64 = (-8i32..=8)
                .filter(|&m| m != 0)
                .map(|m| {
                    let d = nu - m as f64 * fs;
                    (nu / d).abs() * sinc(d / fs).abs()
                })
                .sum();
            let bound = (2.0 * s + s * s) * envelope;
            assert!(
                (b - exact).abs() <= bound,
                "nu {nu}: {b} vs {exact} (bound {bound})"
            );
        }
        let b0 = spectrum.density()[0];
        assert!((b0 - 2.0 * (a * t).powi(2)).abs() <= 1e-9 * b0, "{b0}");
    }
}
