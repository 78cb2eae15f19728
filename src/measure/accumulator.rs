//! The streaming accumulator of [`Metrics`]: samples in time order, no traces kept (the
//! definitions are in [`crate::measure::metrics`]).

use crate::measure::metrics::{AxisMetrics, Metrics, Status};

/// Settle-time bookkeeping for one error signal and every band.
#[derive(Debug, Clone)]
struct Bands {
    band_m: Vec<f64>,
    /// Crossing time (s after T) of the last entry into each band; None while outside.
    entered_at: Vec<Option<f64>>,
    prev: Option<(f64, f64)>,
    peak_m: f64,
    sum_sq: f64,
    n: usize,
}

impl Bands {
    fn new(bands_um: &[f64]) -> Self {
        Self {
            band_m: bands_um.iter().map(|b| b * 1e-6).collect(),
            entered_at: vec![Some(0.0); bands_um.len()],
            prev: None,
            peak_m: 0.0,
            sum_sq: 0.0,
            n: 0,
        }
    }

    /// |error| `e` (m) at `tau` s after T.
    fn push(&mut self, tau: f64, e: f64) {
        self.peak_m = self.peak_m.max(e);
        self.sum_sq += e * e;
        self.n += 1;
        for (b, entered) in self.band_m.iter().zip(&mut self.entered_at) {
            if e > *b {
                *entered = None;
            } else if entered.is_none() {
                // Entered between the previous sample (outside) and this one.
                *entered = Some(match self.prev {
                    Some((tp, ep)) if ep > e => tp + (tau - tp) * (ep - b) / (ep - e),
                    _ => tau,
                });
            }
        }
        self.prev = Some((tau, e));
    }

    /// [`Bands::push`] for the samples `e` (m) at the times `tau` (s after T), bit for
    /// bit. The peak and the sum of squares see every sample in order, as there. Each
    /// band's entry time only depends on the last sample outside the band: after it
    /// the per-sample rule sets the entry to the crossing between that sample and the
    /// next one (or leaves it unset when it is the last one), and nothing changes it
    /// afterwards; with no sample outside, only an unset entry changes, at the first
    /// sample (crossing from the previous call's last one). So each band is one scan
    /// for its last outside sample and one evaluation of the same crossing formula.
    fn push_slice(&mut self, tau: &[f64], e: &[f64]) {
        let count = e.len().min(tau.len());
        if count == 0 {
            return;
        }
        let (tau, e) = (&tau[..count], &e[..count]);
        let (mut peak, mut sum_sq) = (self.peak_m, self.sum_sq);
        for &e in e {
            peak = raise(peak, e);
            sum_sq += e * e;
        }
        let prev = self.prev;
        // The per-sample rule's crossing into band `b` at sample `i` after `prev`.
        let crossing = |prev: Option<(f64, f64)>, i: usize, b: f64| match prev {
            Some((tp, ep)) if ep > e[i] => tp + (tau[i] - tp) * (ep - b) / (ep - e[i]),
            _ => tau[i],
        };
        for (&b, entered) in self.band_m.iter().zip(&mut self.entered_at) {
            let last_out = last_above(e, b);
            match last_out {
                Some(l) if l + 1 == count => *entered = None,
                Some(l) => *entered = Some(crossing(Some((tau[l], e[l])), l + 1, b)),
                None => {
                    if entered.is_none() {
                        *entered = Some(crossing(prev, 0, b));
                    }
                }
            }
        }
        self.peak_m = peak;
        self.sum_sq = sum_sq;
        self.prev = Some((tau[count - 1], e[count - 1]));
        self.n += count;
    }

    fn rms_m(&self) -> f64 {
        if self.n > 0 {
            (self.sum_sq / self.n as f64).sqrt()
        } else {
            0.0
        }
    }
}

/// `acc.max(x)` for the running maxima here, in one instruction instead of `f64::max`'s
/// NaN fix-up: a NaN `x` is ignored and the larger value kept, as there. The two differ
/// only in the sign of a zero when `acc` and `x` are zeros of opposite signs, which never
/// happens here: every maximum starts at `+0` and takes values that are never `-0` (an
/// `abs`, a `sqrt` of a sum of squares, or a sum that starts at `+0`: a sum is `-0` only
/// if both its terms are).
#[inline(always)]
fn raise(acc: f64, x: f64) -> f64 {
    if x > acc { x } else { acc }
}

/// The index of the last entry of `e` above `b` (`e > b`, as [`Bands::push`] tests it: a
/// NaN is not above). Eight entries at a time without a branch, from the end (a settled
/// run's samples are all inside), then the exact position within the chunk that has one.
fn last_above(e: &[f64], b: f64) -> Option<usize> {
    const W: usize = 8;
    let whole = e.len() / W * W;
    if let Some(i) = e[whole..].iter().rposition(|&x| x > b) {
        return Some(whole + i);
    }
    let (k, chunk) = e[..whole]
        .chunks_exact(W)
        .enumerate()
        .rev()
        .find(|(_, c)| c.iter().fold(false, |any, &x| any | (x > b)))?;
    chunk.iter().rposition(|&x| x > b).map(|i| k * W + i)
}

/// Streaming metric accumulator over one or more axes. Feed samples in time order with
/// [`Accumulator::push`].
#[derive(Debug, Clone)]
pub struct Accumulator {
    target_m: Vec<f64>,
    direction: Vec<f64>,
    move_end_s: f64,
    bands_um: Vec<f64>,
    total: Bands,
    per_axis: Vec<Bands>,
    overshoot_m: f64,
    /// Largest squared length of the following-error vector (m^2; `sqrt` is monotone, so
    /// the square root of the largest square is the largest length, bit for bit, and
    /// costs one `sqrt` per run instead of one per sample).
    max_follow_sq_m2: f64,
    axis_follow_m: Vec<f64>,
    /// Largest squared distance to the target (m^2), as `max_follow_sq_m2`.
    abs_err_max_sq_m2: f64,
    /// Reused buffers of [`Accumulator::push_run`] for the samples after T: their time
    /// after T, the distance to the target, and one axis's error at a time.
    tau_s: Vec<f64>,
    dist_m: Vec<f64>,
    axis_err_m: Vec<f64>,
}

impl Accumulator {
    /// `target_m`: commanded end point per axis; `direction`: the direction of motion per
    /// axis (normalised here; all zero for no motion); `move_end_s`: T; `bands_um`:
    /// settling bands.
    pub fn new(target_m: &[f64], direction: &[f64], move_end_s: f64, bands_um: &[f64]) -> Self {
        let norm = direction.iter().map(|d| d * d).sum::<f64>().sqrt();
        let direction = direction
            .iter()
            .map(|d| if norm > 0.0 { d / norm } else { 0.0 })
            .collect();
        Self {
            target_m: target_m.to_vec(),
            direction,
            move_end_s,
            bands_um: bands_um.to_vec(),
            total: Bands::new(bands_um),
            per_axis: target_m.iter().map(|_| Bands::new(bands_um)).collect(),
            overshoot_m: 0.0,
            max_follow_sq_m2: 0.0,
            axis_follow_m: vec![0.0; target_m.len()],
            abs_err_max_sq_m2: 0.0,
            tau_s: Vec::new(),
            dist_m: Vec::new(),
            axis_err_m: Vec::new(),
        }
    }

    /// One sample at time `t_s`: commanded and toolhead positions per axis (m).
    pub fn push(&mut self, t_s: f64, commanded_m: &[f64], toolhead_m: &[f64]) {
        let (mut e2, mut along, mut f2) = (0.0, 0.0, 0.0);
        let during = t_s <= self.move_end_s;
        let axes = self
            .target_m
            .iter()
            .zip(&self.direction)
            .zip(commanded_m.iter().zip(toolhead_m))
            .zip(&mut self.axis_follow_m);
        for (((target, d), (c, h)), follow) in axes {
            let e = h - target;
            e2 += e * e;
            along += e * d;
            let f = h - c;
            f2 += f * f;
            if during {
                *follow = follow.max(f.abs());
            }
        }
        self.overshoot_m = self.overshoot_m.max(along);
        self.abs_err_max_sq_m2 = self.abs_err_max_sq_m2.max(e2);
        if during {
            self.max_follow_sq_m2 = self.max_follow_sq_m2.max(f2);
        }
        if t_s < self.move_end_s {
            return;
        }
        let tau = t_s - self.move_end_s;
        self.total.push(tau, e2.sqrt());
        for ((b, h), target) in self.per_axis.iter_mut().zip(toolhead_m).zip(&self.target_m) {
            b.push(tau, (h - target).abs());
        }
    }

    /// [`Accumulator::push`] for `count` samples at once, bit for bit: sample `i` is at
    /// `t_s(i)` with the positions `commanded_m[i * axes ..]` and `toolhead_m[i * axes
    /// ..]` (sample-major, `axes` = the accumulator's axis count); times must not
    /// decrease. Each running value sees the same operations in the same order as with
    /// one `push` per sample; they are only grouped by value (the vector error's, then
    /// each settling bookkeeping in turn) so that they stay in registers.
    pub fn push_run(
        &mut self,
        count: usize,
        t_s: impl Fn(usize) -> f64,
        commanded_m: &[f64],
        toolhead_m: &[f64],
    ) {
        let n = self.target_m.len();
        if n == 0 || count == 0 {
            for i in 0..count {
                self.push(t_s(i), &[], &[]);
            }
            return;
        }
        // The axis count as a constant where it is a common one: the per-axis loops
        // unroll and the running values stay in registers.
        match n {
            1 => self.push_run_n::<1>(count, t_s, commanded_m, toolhead_m),
            2 => self.push_run_n::<2>(count, t_s, commanded_m, toolhead_m),
            3 => self.push_run_n::<3>(count, t_s, commanded_m, toolhead_m),
            _ => self.push_run_n::<0>(count, t_s, commanded_m, toolhead_m),
        }
    }

    /// [`Accumulator::push_run`] for `N` axes (`N == 0`: any count).
    #[inline(always)]
    fn push_run_n<const N: usize>(
        &mut self,
        count: usize,
        t_s: impl Fn(usize) -> f64,
        commanded_m: &[f64],
        toolhead_m: &[f64],
    ) {
        let n = if N > 0 { N } else { self.target_m.len() };
        let commanded_m = &commanded_m[..count * n];
        let toolhead_m = &toolhead_m[..count * n];
        let end = self.move_end_s;
        let (target, direction) = (&self.target_m[..n], &self.direction[..n]);
        let follow = &mut self.axis_follow_m[..n];
        // The squared distance to the target and the component along the motion.
        let err = |h: &[f64]| {
            let (mut e2, mut along) = (0.0, 0.0);
            for a in 0..n {
                let e = h[a] - target[a];
                e2 += e * e;
                along += e * direction[a];
            }
            (e2, along)
        };
        let (mut overshoot, mut abs_err, mut max_follow) = (
            self.overshoot_m,
            self.abs_err_max_sq_m2,
            self.max_follow_sq_m2,
        );
        // The first sample not before T (`t >= end`, or a NaN time, as `push` tests);
        // times do not decrease, so every later one is not either.
        let first_after = (0..count)
            .find(|&i| {
                let t = t_s(i);
                t >= end || t.is_nan()
            })
            .unwrap_or(count);
        let after = count - first_after;
        let (mut tau_s, mut dist_m) = (
            std::mem::take(&mut self.tau_s),
            std::mem::take(&mut self.dist_m),
        );
        tau_s.clear();
        tau_s.resize(after, 0.0);
        dist_m.clear();
        dist_m.resize(after, 0.0);
        // The following error (`t <= end`) of one sample.
        let mut follow_error = |c: &[f64], h: &[f64], max_follow: &mut f64| {
            let mut f2 = 0.0;
            for a in 0..n {
                let f = h[a] - c[a];
                f2 += f * f;
                follow[a] = raise(follow[a], f.abs());
            }
            *max_follow = raise(*max_follow, f2);
        };
        let split = first_after * n;
        // Before T (every time there is below `end`, so every sample counts for the
        // following error).
        let before = commanded_m[..split]
            .chunks_exact(n)
            .zip(toolhead_m[..split].chunks_exact(n));
        for (c, h) in before {
            let (e2, along) = err(h);
            overshoot = raise(overshoot, along);
            abs_err = raise(abs_err, e2);
            follow_error(c, h, &mut max_follow);
        }
        // From T on (the sample exactly at T also counts for the following error), with
        // the time after T and the distance to the target kept for the settling
        // bookkeeping.
        let from = commanded_m[split..]
            .chunks_exact(n)
            .zip(toolhead_m[split..].chunks_exact(n))
            .zip(tau_s.iter_mut().zip(dist_m.iter_mut()));
        for (i, ((c, h), (tau, dist))) in (first_after..).zip(from) {
            let t = t_s(i);
            let (e2, along) = err(h);
            overshoot = raise(overshoot, along);
            abs_err = raise(abs_err, e2);
            if t <= end {
                follow_error(c, h, &mut max_follow);
            }
            *tau = t - end;
            *dist = e2.sqrt();
        }
        self.overshoot_m = overshoot;
        self.abs_err_max_sq_m2 = abs_err;
        self.max_follow_sq_m2 = max_follow;
        if after > 0 {
            self.total.push_slice(&tau_s, &dist_m);
            let th = &toolhead_m[first_after * n..];
            let mut axis_err_m = std::mem::take(&mut self.axis_err_m);
            for (a, (b, target)) in self.per_axis.iter_mut().zip(target).enumerate() {
                axis_err_m.clear();
                axis_err_m.extend(th.chunks_exact(n).map(|h| (h[a] - target).abs()));
                b.push_slice(&tau_s, &axis_err_m);
            }
            self.axis_err_m = axis_err_m;
        }
        self.tau_s = tau_s;
        self.dist_m = dist_m;
    }

    /// The metrics of everything pushed, for axes named `names`, with status `status` and
    /// each axis's largest load angle (electrical rad), if it has a motor.
    pub fn finish_with(
        &self,
        names: &[String],
        load_angles: &[Option<f64>],
        status: Status,
    ) -> Metrics {
        let to_um = 1e6;
        let moving = self.direction.iter().any(|d| *d != 0.0);
        Metrics {
            move_time_s: self.move_end_s,
            residual_peak_um: self.total.peak_m * to_um,
            residual_rms_um: self.total.rms_m() * to_um,
            bands_um: self.bands_um.clone(),
            settle_time_s: self.total.entered_at.clone(),
            overshoot_um: if moving {
                self.overshoot_m * to_um
            } else {
                self.abs_err_max_sq_m2.sqrt() * to_um
            },
            max_following_error_um: self.max_follow_sq_m2.sqrt() * to_um,
            axes: self
                .per_axis
                .iter()
                .enumerate()
                .map(|(i, b)| AxisMetrics {
                    name: names.get(i).cloned().unwrap_or_else(|| format!("axis{i}")),
                    residual_peak_um: b.peak_m * to_um,
                    residual_rms_um: b.rms_m() * to_um,
                    settle_time_s: b.entered_at.clone(),
                    max_following_error_um: self.axis_follow_m[i] * to_um,
                    max_load_angle_deg: load_angles.get(i).copied().flatten().map(f64::to_degrees),
                })
                .collect(),
            status,
            path: None,
            extra: Vec::new(),
        }
    }

    /// The metrics of everything pushed (axes named `x`, `y`, `z`, ..., status ok).
    pub fn finish(&self) -> Metrics {
        let names: Vec<String> = (0..self.target_m.len())
            .map(|i| {
                ["x", "y", "z"]
                    .get(i)
                    .map_or(format!("axis{i}"), |n| n.to_string())
            })
            .collect();
        self.finish_with(&names, &[], Status::Ok)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feed `f(t)` (m) as the toolhead error after a move ending at t = 0.
    fn run(f: impl Fn(f64) -> f64, dt: f64, window: f64, band_um: f64) -> Metrics {
        let mut acc = Accumulator::new(&[0.0], &[1.0], 0.0, &[band_um]);
        let n = (window / dt).round() as usize;
        for i in 0..=n {
            let t = i as f64 * dt;
            acc.push(t, &[0.0], &[f(t)]);
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
        let mut acc = Accumulator::new(&[1.0], &[1.0], 1.0, &[50.0]);
        acc.push(0.5, &[0.5], &[0.498]);
        acc.push(1.0, &[1.0], &[1.0 + 30e-6]);
        acc.push(1.5, &[1.0], &[1.0 - 40e-6]);
        let m = acc.finish();
        assert!((m.max_following_error_um - 2000.0).abs() < 1e-6);
        assert!((m.residual_peak_um - 40.0).abs() < 1e-9);
        assert!((m.residual_rms_um - ((30f64.powi(2) + 40f64.powi(2)) / 2.0).sqrt()).abs() < 1e-9);
        assert!((m.overshoot_um - 30.0).abs() < 1e-9);
        assert_eq!(m.settle_time_s[0], Some(0.0));
        assert_eq!(m.move_and_settle_s(0), Some(1.0));
    }

    #[test]
    fn vector_error_uses_the_distance_and_the_direction_of_motion() {
        // A diagonal move to (1, 1) m ending at T = 1 s; after it the toolhead sits 3 um
        // past the target along x and 4 um short along y: distance 5 um, overshoot along
        // (1, 1)/sqrt 2 = (3 - 4)/sqrt 2 < 0, so none.
        let mut acc = Accumulator::new(&[1.0, 1.0], &[2.0, 2.0], 1.0, &[4.5, 10.0]);
        acc.push(1.0, &[1.0, 1.0], &[1.0 + 3e-6, 1.0 - 4e-6]);
        acc.push(1.1, &[1.0, 1.0], &[1.0, 1.0]);
        let m = acc.finish();
        assert!((m.residual_peak_um - 5.0).abs() < 1e-9);
        assert!((m.axes[0].residual_peak_um - 3.0).abs() < 1e-9);
        assert!((m.axes[1].residual_peak_um - 4.0).abs() < 1e-9);
        assert_eq!(m.overshoot_um, 0.0);
        // 4.5 um band: the vector error (5 um) is outside at T, inside at T + 0.1 s; the
        // x error (3 um) and y error (4 um) are inside from T on.
        assert!(m.settle_time_s[0].expect("settles") > 0.0);
        assert_eq!(m.axes[0].settle_time_s[0], Some(0.0));
        assert_eq!(m.axes[1].settle_time_s[0], Some(0.0));
        assert_eq!(m.settle_time_s[1], Some(0.0));
        assert_eq!(
            (m.axes[0].name.as_str(), m.axes[1].name.as_str()),
            ("x", "y")
        );
    }

    #[test]
    fn push_run_equals_push_per_sample_bit_for_bit() {
        // Two axes, a move ending at 0.0123 s, runs of samples that straddle it, errors
        // that leave and re-enter the bands (a decaying beat), a zero-direction axis.
        let target = [0.01, -0.002];
        let (end, dt) = (0.0123, 1e-4);
        let signal = |t: f64| {
            let e = 80e-6 * (-t / 0.02).exp() * (2.0 * std::f64::consts::PI * 45.0 * t).cos();
            let f = 30e-6 * (-t / 0.015).exp() * (2.0 * std::f64::consts::PI * 11.0 * t).sin();
            (
                [target[0] - 0.001 * (end - t).max(0.0), target[1]],
                [target[0] + e, target[1] + f],
            )
        };
        let mut one = Accumulator::new(&target, &[1.0, 0.0], end, &[10.0, 25.0, 50.0]);
        let mut run = one.clone();
        let mut k = 0usize;
        for len in [1, 7, 100, 3, 250, 256, 1] {
            let t = |i: usize| (k + i) as f64 * dt;
            let (mut c, mut h) = (Vec::new(), Vec::new());
            for i in 0..len {
                let (ci, hi) = signal(t(i));
                one.push(t(i), &ci, &hi);
                c.extend(ci);
                h.extend(hi);
            }
            run.push_run(len, t, &c, &h);
            k += len;
        }
        let (a, b) = (one.finish(), run.finish());
        assert!(a.settle_time_s[0].is_some_and(|s| s > 0.0), "{a:?}");
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }

    #[test]
    fn push_run_equals_push_per_sample_on_edges_and_nans() {
        // Errors exactly on a band edge, runs that end outside a band, runs entirely
        // inside after an outside one, a run entirely outside, and NaN samples (not
        // outside a band by the per-sample rule): every run length from 1 to 9.
        // The band as the accumulator stores it (um times 1e-6), so the edge is exact.
        let band = 10.0 * 1e-6;
        let pattern = [
            20e-6,
            band,
            5e-6,
            40e-6,
            41e-6,
            band,
            f64::NAN,
            30e-6,
            12e-6,
            0.0,
            0.0,
            band,
            11e-6,
            f64::NAN,
            2e-6,
            9e-6,
            band,
            0.0,
        ];
        for len in 1..10 {
            let mut one = Accumulator::new(&[0.0, 0.0], &[1.0, 0.0], 0.0, &[10.0, 35.0]);
            let mut run = one.clone();
            let mut k = 0usize;
            while k < 4 * pattern.len() {
                let m = len.min(4 * pattern.len() - k);
                let t = |i: usize| (k + i) as f64 * 1e-4;
                let (mut c, mut h) = (Vec::new(), Vec::new());
                for i in 0..m {
                    let e = pattern[(k + i) % pattern.len()];
                    let hi = [e, -0.5 * e];
                    one.push(t(i), &[0.0, 0.0], &hi);
                    c.extend([0.0, 0.0]);
                    h.extend(hi);
                }
                run.push_run(m, t, &c, &h);
                k += m;
            }
            let (a, b) = (one.finish(), run.finish());
            // The last sample outside the 10 um band is the 11 um one (a NaN follows).
            assert!(a.settle_time_s[0].is_some_and(|s| s > 0.0), "{a:?}");
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "runs of {len}");
        }
    }
}
