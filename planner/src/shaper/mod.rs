//! Input shapers, applicable to any profile, with Klipper's definitions and figures.
//!
//! A shaper is a train of impulses `A_i` at times `T_i` (`T_0 = 0`). Shaping a profile
//! convolves it with the normalised train: `q(t) = sum_i w_i p(t - T_i)`, `w_i = A_i / sum A`.
//! For a lightly damped mode `(f, zeta)` the residual vibration is multiplied by
//! [`Shaper::remaining_vibration`], so a shaper tuned to the mode cancels most of it, at the
//! price of a longer, smoother move (duration `T_last`, [`Shaper::smoothing_mm`]).
//!
//! Definitions (amplitudes and times for frequency `f` and damping ratio `zeta`) are those
//! Klipper publishes for its shapers (klippy/extras/shaper_defs.py, the closed forms of
//! 2020-2021): with `df = sqrt(1 - zeta^2)`, `K = exp(-zeta pi / df)`, `t_d = 1/(f df)` and the
//! vibration tolerance `v = 1/20` of the EI family:
//! - ZV: `A = [1, K]`, `T = [0, t_d/2]`
//! - MZV: `K' = exp(-0.75 zeta pi / df)`, `A = [1 - 1/sqrt2, (sqrt2 - 1) K', (1 - 1/sqrt2) K'^2]`,
//!   `T = [0, 0.375, 0.75] t_d`
//! - ZVD: `A = [1, 2K, K^2]`, `T = [0, 0.5, 1] t_d`
//! - EI: `A = [(1+v)/4, (1-v) K/2, (1+v) K^2/4]`, `T = [0, 0.5, 1] t_d`
//! - 2HUMP_EI: `X = (v^2 (sqrt(1 - v^2) + 1))^(1/3)`, `a1 = (3X^2 + 2X + 3v^2)/(16X)`,
//!   `A = [a1, (1/2 - a1) K, (1/2 - a1) K^2, a1 K^3]`, `T = [0, 0.5, 1, 1.5] t_d`
//! - 3HUMP_EI: `a1 = (1 + 3v + 2 sqrt(2 (v + 1) v))/16`,
//!   `A = [a1, (1-v) K/4, ((1+v)/2 - 2 a1) K^2, (1-v) K^3/4, a1 K^4]`, `T = [0, .5, 1, 1.5, 2] t_d`
//!
//! The shaped profile is again a [`Profile`]: between consecutive shifted breakpoints every
//! copy has constant jerk, so the sum does too; acceleration jumps (trapezoids) stay jumps.

use std::f64::consts::{PI, SQRT_2};

use crate::{PlanError, Profile, Sample, Segment, State};

/// Klipper's vibration tolerance of the EI family: 5% (a 20x reduction).
pub const VIBRATION_TOLERANCE: f64 = 1.0 / 20.0;

/// The shaper families.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ShaperKind {
    /// Zero vibration (2 impulses).
    Zv,
    /// Modified ZV (3 impulses over 0.75 periods).
    Mzv,
    /// Zero vibration and derivative (3 impulses).
    Zvd,
    /// Extra-insensitive (3 impulses, 5% tolerance).
    Ei,
    /// Two-hump EI (4 impulses).
    TwoHumpEi,
    /// Three-hump EI (5 impulses).
    ThreeHumpEi,
}

impl ShaperKind {
    /// Every kind, shortest first.
    pub const ALL: [ShaperKind; 6] = [
        ShaperKind::Zv,
        ShaperKind::Mzv,
        ShaperKind::Zvd,
        ShaperKind::Ei,
        ShaperKind::TwoHumpEi,
        ShaperKind::ThreeHumpEi,
    ];
    /// Names accepted by [`ShaperKind::parse`] (Klipper's `shaper_type` names).
    pub const ALLOWED: &'static str = "zv, mzv, zvd, ei, 2hump_ei, 3hump_ei";

    /// Klipper's name (`shaper_type`).
    pub fn name(self) -> &'static str {
        match self {
            ShaperKind::Zv => "zv",
            ShaperKind::Mzv => "mzv",
            ShaperKind::Zvd => "zvd",
            ShaperKind::Ei => "ei",
            ShaperKind::TwoHumpEi => "2hump_ei",
            ShaperKind::ThreeHumpEi => "3hump_ei",
        }
    }

    /// Parse a Klipper shaper name (case-insensitive).
    pub fn parse(name: &str) -> Result<Self, PlanError> {
        let lower = name.to_ascii_lowercase();
        Self::ALL
            .into_iter()
            .find(|k| k.name() == lower)
            .ok_or_else(|| PlanError::UnknownKind {
                name: name.to_string(),
                allowed: Self::ALLOWED,
            })
    }
}

impl std::fmt::Display for ShaperKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A shaper: impulse amplitudes (not normalised, as Klipper writes them) and times (s).
#[derive(Debug, Clone, PartialEq)]
pub struct Shaper {
    kind: ShaperKind,
    frequency_hz: f64,
    damping_ratio: f64,
    amplitudes: Vec<f64>,
    times_s: Vec<f64>,
}

impl Shaper {
    /// The shaper of `kind` tuned to `frequency_hz` (> 0) and `damping_ratio` in [0, 1).
    /// Klipper's default damping ratio is 0.1.
    pub fn new(kind: ShaperKind, frequency_hz: f64, damping_ratio: f64) -> Result<Self, PlanError> {
        if !(frequency_hz.is_finite() && frequency_hz > 0.0) {
            return Err(PlanError::NonFinite {
                name: "shaper frequency_hz (must be finite and > 0)",
                value: frequency_hz,
            });
        }
        if !(0.0..1.0).contains(&damping_ratio) {
            return Err(PlanError::NonFinite {
                name: "shaper damping_ratio (must be in [0, 1))",
                value: damping_ratio,
            });
        }
        let df = (1.0 - damping_ratio * damping_ratio).sqrt();
        let k = (-damping_ratio * PI / df).exp();
        let t_d = 1.0 / (frequency_hz * df);
        let v = VIBRATION_TOLERANCE;
        let (amplitudes, fractions): (Vec<f64>, Vec<f64>) = match kind {
            ShaperKind::Zv => (vec![1.0, k], vec![0.0, 0.5]),
            ShaperKind::Mzv => {
                let k = (-0.75 * damping_ratio * PI / df).exp();
                let a1 = 1.0 - 1.0 / SQRT_2;
                (
                    vec![a1, (SQRT_2 - 1.0) * k, a1 * k * k],
                    vec![0.0, 0.375, 0.75],
                )
            }
            ShaperKind::Zvd => (vec![1.0, 2.0 * k, k * k], vec![0.0, 0.5, 1.0]),
            ShaperKind::Ei => {
                let a1 = 0.25 * (1.0 + v);
                (
                    vec![a1, 0.5 * (1.0 - v) * k, a1 * k * k],
                    vec![0.0, 0.5, 1.0],
                )
            }
            ShaperKind::TwoHumpEi => {
                let v2 = v * v;
                let x = (v2 * ((1.0 - v2).sqrt() + 1.0)).cbrt();
                let a1 = (3.0 * x * x + 2.0 * x + 3.0 * v2) / (16.0 * x);
                let a2 = (0.5 - a1) * k;
                (
                    vec![a1, a2, a2 * k, a1 * k * k * k],
                    vec![0.0, 0.5, 1.0, 1.5],
                )
            }
            ShaperKind::ThreeHumpEi => {
                let k2 = k * k;
                let a1 = 0.0625 * (1.0 + 3.0 * v + 2.0 * (2.0 * (v + 1.0) * v).sqrt());
                let a2 = 0.25 * (1.0 - v) * k;
                (
                    vec![
                        a1,
                        a2,
                        (0.5 * (1.0 + v) - 2.0 * a1) * k2,
                        a2 * k2,
                        a1 * k2 * k2,
                    ],
                    vec![0.0, 0.5, 1.0, 1.5, 2.0],
                )
            }
        };
        Ok(Self {
            kind,
            frequency_hz,
            damping_ratio,
            amplitudes,
            times_s: fractions.into_iter().map(|f| f * t_d).collect(),
        })
    }

    /// The family.
    pub fn kind(&self) -> ShaperKind {
        self.kind
    }

    /// The frequency it is tuned to (Hz).
    pub fn frequency_hz(&self) -> f64 {
        self.frequency_hz
    }

    /// The damping ratio it is tuned to.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio
    }

    /// Impulse amplitudes as Klipper writes them (their sum is not 1).
    pub fn amplitudes(&self) -> &[f64] {
        &self.amplitudes
    }

    /// Impulse times (s), the first is 0.
    pub fn times_s(&self) -> &[f64] {
        &self.times_s
    }

    /// Duration: the last impulse time (s). A shaped move is this much longer.
    pub fn duration_s(&self) -> f64 {
        self.times_s.last().copied().unwrap_or(0.0)
    }

    /// Normalised weights `A_i / sum A`.
    pub fn weights(&self) -> impl Iterator<Item = f64> + '_ {
        let inv = 1.0 / self.amplitudes.iter().sum::<f64>();
        self.amplitudes.iter().map(move |a| a * inv)
    }

    /// The fraction of a mode's residual vibration the shaper leaves (Klipper's
    /// `_estimate_shaper`): for a mode at `frequency_hz` with `damping_ratio`,
    /// `|sum_i A_i e^{-zeta w (T_n - T_i)} e^{i wd T_i}| / sum A`. 1 = no reduction.
    pub fn remaining_vibration(&self, frequency_hz: f64, damping_ratio: f64) -> f64 {
        let w = 2.0 * PI * frequency_hz;
        let zw = damping_ratio * w;
        let wd = w * (1.0 - damping_ratio * damping_ratio).sqrt();
        let t_n = self.duration_s();
        let (mut s, mut c) = (0.0, 0.0);
        for (a, t) in self.amplitudes.iter().zip(&self.times_s) {
            let weight = a * (-zw * (t_n - t)).exp();
            s += weight * (wd * t).sin();
            c += weight * (wd * t).cos();
        }
        s.hypot(c) / self.amplitudes.iter().sum::<f64>()
    }

    /// Klipper's smoothing figure (`_get_shaper_smoothing`, mm): the larger of the offsets a
    /// 90-degree corner at square-corner velocity `scv_mm_s` and a 180-degree turn see at
    /// acceleration `accel_mm_s2` (Klipper reports it at 5000 mm/s^2 and 5 mm/s).
    pub fn smoothing_mm(&self, accel_mm_s2: f64, scv_mm_s: f64) -> f64 {
        let half_accel = 0.5 * accel_mm_s2;
        let inv = 1.0 / self.amplitudes.iter().sum::<f64>();
        let ts: f64 = self
            .amplitudes
            .iter()
            .zip(&self.times_s)
            .map(|(a, t)| a * t)
            .sum::<f64>()
            * inv;
        let (mut off90, mut off180) = (0.0, 0.0);
        for (a, t) in self.amplitudes.iter().zip(&self.times_s) {
            let dt = t - ts;
            if *t >= ts {
                off90 += a * (scv_mm_s + half_accel * dt) * dt;
            }
            off180 += a * half_accel * dt * dt;
        }
        (off90 * inv * SQRT_2).max(off180 * inv)
    }

    /// Shape a profile: `q(t) = sum_i w_i p(t - T_i)`. Outside its span the profile is
    /// extended by its start state before `t = 0` and its end state after its end, moving on
    /// at constant velocity (so a move that starts and ends at rest is shaped into one that
    /// does too, `duration_s()` longer). The start and end accelerations must be zero (a
    /// move, not a fragment). Since the weights are positive and sum to 1, the shaped
    /// velocity, acceleration and jerk stay within the original's bounds.
    pub fn apply(&self, profile: &Profile) -> Result<Profile, PlanError> {
        let (start, end) = (profile.start(), profile.end());
        if start.a != 0.0 || end.a != 0.0 {
            return Err(PlanError::InvalidInput {
                reason: "input shaping needs a profile that starts and ends with zero acceleration",
            });
        }
        let weights: Vec<f64> = self.weights().collect();
        let t_end = profile.duration_s();
        let eval = |t: f64| -> Sample {
            if t < 0.0 {
                return Sample {
                    p: start.p + start.v * t,
                    v: start.v,
                    a: 0.0,
                    j: 0.0,
                };
            }
            if t >= t_end {
                return Sample {
                    p: end.p + end.v * (t - t_end),
                    v: end.v,
                    a: 0.0,
                    j: 0.0,
                };
            }
            profile.state_at(t)
        };
        let shaped = |t: f64| -> Sample {
            let mut s = Sample::default();
            for (w, ti) in weights.iter().zip(&self.times_s) {
                let x = eval(t - ti);
                s.p += w * x.p;
                s.v += w * x.v;
                s.a += w * x.a;
                s.j += w * x.j;
            }
            s
        };
        // Every breakpoint of every shifted copy.
        let mut knots: Vec<f64> = Vec::new();
        for ti in &self.times_s {
            knots.push(ti + 0.0);
            for (t0, _, seg) in profile.iter() {
                knots.push(t0 + ti);
                knots.push(t0 + seg.duration_s() + ti);
            }
        }
        knots.sort_by(f64::total_cmp);
        knots.dedup();
        let mut segments = Vec::with_capacity(knots.len());
        let mut a_now = 0.0;
        let s0 = shaped(0.0);
        for pair in knots.windows(2) {
            let (ta, tb) = (pair[0], pair[1]);
            let dur = tb - ta;
            if dur <= 0.0 {
                continue;
            }
            // Right limits on the interval: evaluate just inside it.
            let mid = shaped(ta + 0.5 * dur);
            let a_start = mid.a - mid.j * 0.5 * dur;
            let jumps = (a_start - a_now).abs() > 1e-12 * (1.0 + a_start.abs() + a_now.abs());
            if mid.j == 0.0 {
                segments.push(Segment::Accel {
                    duration_s: dur,
                    accel: a_start,
                });
            } else {
                if jumps {
                    segments.push(Segment::Accel {
                        duration_s: 0.0,
                        accel: a_start,
                    });
                }
                segments.push(Segment::Jerk {
                    duration_s: dur,
                    jerk: mid.j,
                });
            }
            a_now = a_start + mid.j * dur;
        }
        Profile::new(
            State {
                p: s0.p,
                v: s0.v,
                a: 0.0,
            },
            segments,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Limits, ProfileKind};

    /// Klipper's calibration evaluates shapers against modes of damping 0.075, 0.1 and 0.15
    /// (`TEST_DAMPING_RATIOS` in shaper_calibrate.py) and keeps the worst.
    const TEST_DAMPING_RATIOS: [f64; 3] = [0.075, 0.1, 0.15];

    fn band(kind: ShaperKind, tol: f64) -> (f64, f64) {
        // The frequency range (relative to the shaper frequency) around 1 where the worst
        // remaining vibration over the test damping ratios stays <= tol, by a fine scan and
        // bisection at the edges. The shaper is tuned with Klipper's default damping 0.1.
        let s = Shaper::new(kind, 1.0, 0.1).expect("shaper");
        let v = |r: f64| {
            TEST_DAMPING_RATIOS
                .iter()
                .map(|&z| s.remaining_vibration(r, z))
                .fold(0.0, f64::max)
                - tol
        };
        let edge = |mut inside: f64, mut outside: f64| {
            for _ in 0..80 {
                let m = 0.5 * (inside + outside);
                if v(m) <= 0.0 { inside = m } else { outside = m }
            }
            inside
        };
        assert!(
            v(1.0) <= 0.0,
            "{kind} does not reach {tol} at its own frequency"
        );
        let mut lo = 1.0;
        while lo > 0.05 && v(lo - 1e-3) <= 0.0 {
            lo -= 1e-3;
        }
        let mut hi = 1.0;
        while hi < 3.0 && v(hi + 1e-3) <= 0.0 {
            hi += 1e-3;
        }
        (edge(lo, lo - 1e-3), edge(hi, hi + 1e-3))
    }

    #[test]
    fn durations_equal_klippers_table() {
        // Klipper's Resonance_Compensation.md: ZV 0.5/f, MZV 0.75/f, ZVD 1/f, EI 1/f,
        // 2HUMP_EI 1.5/f, 3HUMP_EI 2/f (undamped: t_d = 1/f).
        let f = 40.0;
        for (kind, periods) in [
            (ShaperKind::Zv, 0.5),
            (ShaperKind::Mzv, 0.75),
            (ShaperKind::Zvd, 1.0),
            (ShaperKind::Ei, 1.0),
            (ShaperKind::TwoHumpEi, 1.5),
            (ShaperKind::ThreeHumpEi, 2.0),
        ] {
            let s = Shaper::new(kind, f, 0.0).expect("shaper");
            assert!((s.duration_s() - periods / f).abs() < 1e-15, "{kind}");
            // With damping the period stretches by 1/sqrt(1 - zeta^2).
            let s = Shaper::new(kind, f, 0.1).expect("shaper");
            let expect = periods / (f * (1.0f64 - 0.01).sqrt());
            assert!((s.duration_s() - expect).abs() < 1e-15, "{kind}");
        }
    }

    #[test]
    fn five_percent_bands_equal_klippers_table() {
        // Klipper's table (Resonance_Compensation.md, "vibration reduction 20x (5% vibration
        // tolerance)"): ZV N/A, MZV +-4%, ZVD +-15%, EI +-20%, 2HUMP_EI +-35%,
        // 3HUMP_EI -45%..+50% of the shaper frequency. The table calls its figures
        // approximate and covers a range of mode damping ratios; computed against
        // Klipper's own test damping ratios, each band contains the table's band (the
        // table rounds towards the safe side) and extends past it by less than 4 points.
        for (kind, lo, hi) in [
            (ShaperKind::Mzv, 0.96, 1.04),
            (ShaperKind::Zvd, 0.85, 1.15),
            (ShaperKind::Ei, 0.80, 1.20),
            (ShaperKind::TwoHumpEi, 0.65, 1.35),
            (ShaperKind::ThreeHumpEi, 0.55, 1.50),
        ] {
            let (l, h) = band(kind, 0.05);
            assert!(
                l <= lo && l > lo - 0.04 && h >= hi && h < hi + 0.04,
                "{kind}: 5% band {l:.4}..{h:.4}, Klipper's table {lo}..{hi}"
            );
        }
        // ZV: zero at its own frequency and damping, but above 5% within 10% of it.
        let z = 0.1;
        let zv = Shaper::new(ShaperKind::Zv, 1.0, z).expect("zv");
        assert!(zv.remaining_vibration(1.0, z) < 1e-12);
        assert!(zv.remaining_vibration(0.9, z) > 0.05 && zv.remaining_vibration(1.1, z) > 0.05);
    }

    #[test]
    fn tuned_shapers_cancel_their_mode() {
        for kind in ShaperKind::ALL {
            for z in [0.0, 0.05, 0.1, 0.2] {
                let s = Shaper::new(kind, 47.0, z).expect("shaper");
                let r = s.remaining_vibration(47.0, z);
                // ZV, MZV and ZVD vanish at their frequency; the EI family leaves up to 5%
                // there by design (it trades the notch for width).
                let limit = match kind {
                    ShaperKind::Zv | ShaperKind::Mzv | ShaperKind::Zvd => 1e-12,
                    _ => 0.05 + 1e-9,
                };
                assert!(r <= limit, "{kind} zeta {z}: {r}");
                // Weights are positive and sum to one.
                let w: Vec<f64> = s.weights().collect();
                assert!(w.iter().all(|&x| x > 0.0));
                assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn smoothing_matches_an_independent_evaluation() {
        // ZV undamped at f: impulses 1/2 at 0 and T = 1/(2f); shift ts = T/2. Only the
        // second impulse is at or after ts: off90 = sqrt2 * 1/2 (scv + a/2 T/2) T/2;
        // off180 = 2 * 1/2 * a/2 (T/2)^2.
        let f = 50.0;
        let (a, scv) = (5000.0, 5.0);
        let t = 0.5 / f;
        let off90 = SQRT_2 * 0.5 * (scv + a / 2.0 * t / 2.0) * t / 2.0;
        let off180 = a / 2.0 * (t / 2.0) * (t / 2.0);
        let s = Shaper::new(ShaperKind::Zv, f, 0.0).expect("zv");
        assert!((s.smoothing_mm(a, scv) - off90.max(off180)).abs() < 1e-15);
        // Longer shapers smooth more (Klipper's ordering ZV < MZV < ZVD ~ EI < 2HUMP < 3HUMP).
        let sm: Vec<f64> = ShaperKind::ALL
            .iter()
            .map(|&k| Shaper::new(k, f, 0.1).expect("shaper").smoothing_mm(a, scv))
            .collect();
        assert!(sm[0] < sm[1] && sm[1] < sm[2] && sm[3] < sm[4] && sm[4] < sm[5]);
    }

    #[test]
    fn shaped_profile_is_the_weighted_sum_of_shifted_copies() {
        let lim = Limits::new(0.3, 3.0, Some(100.0)).expect("limits");
        for kind in [ProfileKind::SCurve, ProfileKind::Trapezoid] {
            let p = kind.rest_to_rest(0.01, 0.02, &lim).expect("plan");
            for sk in ShaperKind::ALL {
                let s = Shaper::new(sk, 43.0, 0.07).expect("shaper");
                let q = s.apply(&p).expect("shaped");
                assert!((q.duration_s() - (p.duration_s() + s.duration_s())).abs() < 1e-12);
                let end = q.end();
                assert!(
                    (end.p - 0.03).abs() < 1e-12 && end.v.abs() < 1e-12,
                    "{end:?}"
                );
                let w: Vec<f64> = s.weights().collect();
                for i in 0..=400 {
                    let t = q.duration_s() * i as f64 / 400.0;
                    let expect: f64 = w
                        .iter()
                        .zip(s.times_s())
                        .map(|(w, ti)| w * p.state_at((t - ti).max(0.0)).p)
                        .sum();
                    let got = q.state_at(t);
                    assert!((got.p - expect).abs() < 1e-12, "{kind} {sk} t={t}");
                    // Convex combination: the limits still hold.
                    assert!(got.v.abs() <= 0.3 + 1e-12 && got.a.abs() <= 3.0 + 1e-12);
                    if kind == ProfileKind::SCurve {
                        assert!(got.j.abs() <= 100.0 + 1e-9);
                    }
                }
            }
        }
    }

    #[test]
    fn bad_input_is_rejected() {
        assert!(Shaper::new(ShaperKind::Ei, 0.0, 0.1).is_err());
        assert!(Shaper::new(ShaperKind::Ei, 40.0, 1.0).is_err());
        assert!(ShaperKind::parse("2HUMP_EI").is_ok());
        assert!(matches!(
            ShaperKind::parse("zvdd"),
            Err(PlanError::UnknownKind { .. })
        ));
    }
}
