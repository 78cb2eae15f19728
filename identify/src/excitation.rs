//! Klipper's resonance test: the commanded acceleration and its spectrum.
//!
//! `klippy/extras/resonance_tester.py` (`VibrationPulseTestGenerator.gen_test`): starting at
//! `freq_start`, each step holds `+-accel_per_hz * f` for `t_seg = 0.25 / f` twice (signs
//! `s, -s`), then flips `s` and raises `f` by `2 t_seg hz_per_sec`. The acceleration is a
//! square wave of frequency `f` (quarter periods of `t_seg`, pattern `+ - - + + - ...`)
//! whose frequency rises at `hz_per_sec` Hz/s and whose amplitude is `accel_per_hz * f`.
//! Since December 2024 (`SweepingVibrationsTestGenerator`, the default) a slow square wave
//! of `+-sweeping_accel` with period `sweeping_period` is added (its first two pieces last
//! `sqrt(2)/8` and `sqrt(2)/8 + 1/4` periods, then half periods). Before that the test moved
//! between `X +- L` with `L = accel_per_hz f t_seg^2 / 2` at cruise speed `accel_per_hz f
//! t_seg`: the same square wave (defaults `accel_per_hz = 75`, `max_freq = 133.3`).
//! Shake&Tune (`shaketune/helpers/resonance_test.py`) runs the same generators.
//!
//! Spectrum (what the fit models instead of assuming white input): harmonic `k` (odd) of
//! a square wave of amplitude `A` has amplitude `4 A / (pi k)`; a tone of amplitude `c`
//! swept at `rate` Hz/s leaves an energy spectral density `c^2 / (2 rate)` per Hz
//! (stationary phase). With `A = accel_per_hz nu / k` when harmonic `k` sits at `nu` and
//! its sweep rate `k hz_per_sec`, the sweep's energy density is
//! `E(nu) = 8 accel_per_hz^2 nu^2 / (pi^2 hz_per_sec) sum_k k^-5` over the odd `k` with
//! `nu / k` inside `[freq_start, freq_end]`. The slow square wave adds lines at odd
//! multiples `k / sweeping_period` of power `(4 sweeping_accel / (pi k))^2 / 2`, held for
//! the test's duration `(freq_end - freq_start) / hz_per_sec`.

use std::f64::consts::PI;

/// Highest odd harmonic of the square waves kept in the spectrum (the 15th carries
/// `15^-5 = 1.3e-6` of the fundamental's energy density).
pub const MAX_HARMONIC: u32 = 15;

/// One of Klipper's resonance tests. Defaults: [`SweepTest::klipper`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepTest {
    /// First test frequency (Hz); Klipper's `min_freq`, default 5.
    pub freq_start_hz: f64,
    /// Last test frequency (Hz); Klipper's `max_freq`, default 135 (X/Y).
    pub freq_end_hz: f64,
    /// Acceleration per Hz (mm/s^2/Hz); default 60 (75 before December 2024).
    pub accel_per_hz: f64,
    /// Sweep rate (Hz/s); default 1.
    pub hz_per_sec: f64,
    /// The slow sweeping square wave's amplitude (mm/s^2); 0 for the pulse-only test
    /// (Klipper before December 2024, Shake&Tune's pulse-only mode). Default 400.
    pub sweeping_accel_mm_s2: f64,
    /// Its period (s); default 1.2.
    pub sweeping_period_s: f64,
}

impl SweepTest {
    /// Klipper's defaults for X and Y since December 2024 (`[resonance_tester]`).
    pub fn klipper() -> Self {
        Self {
            freq_start_hz: 5.0,
            freq_end_hz: 135.0,
            accel_per_hz: 60.0,
            hz_per_sec: 1.0,
            sweeping_accel_mm_s2: 400.0,
            sweeping_period_s: 1.2,
        }
    }

    /// Klipper's pulse-only test as it was until November 2024 (defaults `accel_per_hz`
    /// 75, `max_freq` 10000 / 75).
    pub fn klipper_legacy() -> Self {
        Self {
            freq_end_hz: 10_000.0 / 75.0,
            accel_per_hz: 75.0,
            sweeping_accel_mm_s2: 0.0,
            ..Self::klipper()
        }
    }

    /// Whether the slow sweeping motion is part of the test.
    pub fn has_sweeping(&self) -> bool {
        self.sweeping_accel_mm_s2 > 0.0 && self.sweeping_period_s > 0.0
    }

    /// Test duration (s): `(freq_end - freq_start) / hz_per_sec`.
    pub fn duration_s(&self) -> f64 {
        (self.freq_end_hz - self.freq_start_hz) / self.hz_per_sec
    }

    /// The commanded acceleration as pieces `(end_time_s, accel_mm_s2)`, each holding from
    /// the previous end (0 for the first): the generator of `resonance_tester.py`,
    /// including the sweeping wave when [`SweepTest::has_sweeping`].
    pub fn pieces(&self) -> Vec<(f64, f64)> {
        let mut base = Vec::new();
        let mut freq = self.freq_start_hz;
        let mut sign = 1.0;
        let mut time = 0.0;
        while freq <= self.freq_end_hz + 1e-6 {
            let t_seg = 0.25 / freq;
            let accel = self.accel_per_hz * freq;
            time += t_seg;
            base.push((time, sign * accel));
            time += t_seg;
            base.push((time, -sign * accel));
            freq += 2.0 * t_seg * self.hz_per_sec;
            sign = -sign;
        }
        if !self.has_sweeping() {
            return base;
        }
        let period = self.sweeping_period_s;
        let mut fraction = 2f64.sqrt() * 0.125;
        let mut t_rem = period * fraction;
        fraction += 0.25;
        let mut sig = 1.0;
        let mut last_t = 0.0;
        let mut out = Vec::with_capacity(base.len() + (time / period * 2.0) as usize + 2);
        for (next_t, accel) in base {
            let mut t_seg = next_t - last_t;
            while t_rem <= t_seg {
                last_t += t_rem;
                out.push((last_t, accel + self.sweeping_accel_mm_s2 * sig));
                t_seg -= t_rem;
                t_rem = period * fraction;
                fraction = 0.5;
                sig = -sig;
            }
            t_rem -= t_seg;
            out.push((next_t, accel + self.sweeping_accel_mm_s2 * sig));
            last_t = next_t;
        }
        out
    }

    /// The sweep's energy spectral density at `nu_hz` ((mm/s^2)^2 s/Hz), without the
    /// sweeping lines (see the module notes).
    pub fn sweep_energy_density(&self, nu_hz: f64) -> f64 {
        let mut sum = 0.0;
        let mut k = 1;
        while k <= MAX_HARMONIC {
            let f = nu_hz / k as f64;
            if f >= self.freq_start_hz && f <= self.freq_end_hz {
                sum += (k as f64).powi(-5);
            }
            k += 2;
        }
        8.0 * self.accel_per_hz * self.accel_per_hz * nu_hz * nu_hz / (PI * PI * self.hz_per_sec)
            * sum
    }

    /// The sweeping wave's lines between `lo_hz` and `hi_hz`: `(frequency_hz, energy)`
    /// with energy = line power x test duration ((mm/s^2)^2 s). Empty without sweeping.
    pub fn sweeping_lines(&self, lo_hz: f64, hi_hz: f64) -> Vec<(f64, f64)> {
        if !self.has_sweeping() {
            return Vec::new();
        }
        let base = 1.0 / self.sweeping_period_s;
        let first = ((lo_hz / base - 1.0) / 2.0).ceil().max(0.0) as u64;
        let mut out = Vec::new();
        let mut j = first;
        loop {
            let k = (2 * j + 1) as f64;
            let f = k * base;
            if f > hi_hz {
                break;
            }
            let amp = 4.0 * self.sweeping_accel_mm_s2 / (PI * k);
            out.push((f, amp * amp / 2.0 * self.duration_s()));
            j += 1;
        }
        out
    }
}
