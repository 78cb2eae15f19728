//! The full stepper driver inside rapier's leapfrog step: the driver torque as the mean
//! over the step's kick window, with the microstep edges resolved exactly in time.
//!
//! rapier integrates by symplectic Euler, i.e. leapfrog with the velocities at half steps:
//! the force applied at `t_n` is the impulse over `[t_n - h/2, t_n + h/2]`. For forces that
//! depend on the position (springs, the detent) the value at `t_n` is right to second
//! order. The driver's magnetic torque also depends on *time*: the phase currents follow a
//! staircase (one edge per microstep) through a current loop of ~8 us, so within a 100 us
//! step they jump at instants that have nothing to do with the step grid. Sampling them at
//! `t_n` moves every edge by up to `h/2`, a timing jitter that changed the printer's
//! residual vibration by up to 7 % at the default step (the figures are in
//! `sim/tests/all/rapier_full_step.rs`, which checks the default step as it is now).
//!
//! So the torque applied at `t_n` is the mean of `Km (-ia sin(Nr theta) + ib cos(Nr theta))`
//! over the kick window, along the rotor's leapfrog path `theta_n + omega_{n-1/2} (t - t_n)`
//! (the same line on both sides of `t_n`, so a torque linear in the angle averages to its
//! value at `theta_n`: no numerical damping, unlike a midpoint evaluation, which adds
//! `k h / 2`). Its two halves come from two passes of the current loop:
//! - before rapier's step, `[t_n, t_n + h/2]` along the predicted path (`omega_{n-1/2}` is
//!   the rotor speed rapier holds at `t_n`);
//! - after it, `[t_n + h/2, t_{n+1}]` along the path rapier actually took over the step,
//!   which is the line through `theta_{n+1}` with slope `omega_{n+1/2}`: the first half of
//!   the next window, on the next window's own path. The currents at `t_{n+1}` (reported,
//!   and used for the load angle) therefore come from the step's real rotor motion.
//!
//! Within each pass the current loop is solved exactly ([`crate::stepper`]'s closed-form
//! pieces) between consecutive microstep edges, whose times are the roots of the command's
//! cubic (`x(t) = (k + 1/2) * microstep`); the back-EMF and the torque's rotor angle are
//! held at the middle of pieces of at most [`MAX_PIECE_ELECTRICAL_RAD`] of rotor travel
//! (one piece per half step at the printer's speeds). The currents' integrals are exact.
//! Measured in `sim/tests/all/rapier_full_step.rs` against a 16x smaller step.

use settle_planner::Sample;

use crate::stepper::{Stepper, StepperState};

/// The most electrical angle (rad) the rotor turns within one piece of the current loop
/// that holds the back-EMF and the torque's angle at the piece's middle: the midpoint
/// rule's error on a sinusoid is `(angle)^2 / 24`, 0.04 % here. The printer's rotor at
/// 300 mm/s turns 0.12 electrical rad in half a 100 us step.
pub const MAX_PIECE_ELECTRICAL_RAD: f64 = 0.1;

/// The time in `[lo, hi]` where the command `u(t)` (in microsteps) crosses `b`, with
/// `u(lo)` and `u(hi)` on either side of it: Newton from the secant, kept inside the
/// bracket (bisection where Newton leaves it), to 1e-13 s.
fn crossing(u: impl Fn(f64) -> f64, du: impl Fn(f64) -> f64, lo: f64, hi: f64, b: f64) -> f64 {
    let (mut lo, mut hi) = (lo, hi);
    let g_lo = u(lo) - b;
    let g_hi = u(hi) - b;
    if g_lo == 0.0 {
        return lo;
    }
    if g_hi == 0.0 || (g_lo < 0.0) == (g_hi < 0.0) {
        return hi;
    }
    let mut t = lo + (hi - lo) * (g_lo / (g_lo - g_hi));
    for _ in 0..64 {
        let g = u(t) - b;
        if g == 0.0 {
            return t;
        }
        if (g < 0.0) == (g_lo < 0.0) {
            lo = t;
        } else {
            hi = t;
        }
        let mut next = t - g / du(t);
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - t).abs() <= 1e-13 {
            return next;
        }
        t = next;
    }
    t
}

/// The phase references' sine and cosine of the last microstep index used (only a
/// saving: the same numbers are computed again when the index changes).
#[derive(Debug, Clone, Copy)]
pub struct ReferenceCache {
    k: f64,
    sq: f64,
    cq: f64,
}

impl Default for ReferenceCache {
    fn default() -> Self {
        Self {
            k: f64::NAN,
            sq: 0.0,
            cq: 0.0,
        }
    }
}

impl Stepper {
    /// The magnetic torque `Km (-ia sin(Nr theta) + ib cos(Nr theta))` (N m) of the state's
    /// currents at rotor angle `theta` (rad).
    pub fn magnetic_torque(&self, st: &StepperState, theta: f64) -> f64 {
        let (s, c) = (self.nr() * theta).sin_cos();
        self.torque_constant_n_m_per_a * (-st.i_a * s + st.i_b * c)
    }

    /// The rest of the driver torque (N m): detent `-Td sin(4 Nr theta)` and slip damping
    /// `-c (omega - v_cmd rad_per_m)`, at rotor angle `theta` (rad) and speed `omega`
    /// (rad/s), the command moving at `v_cmd` (m/s).
    pub fn passive_torque(&self, theta: f64, omega: f64, v_cmd: f64) -> f64 {
        -self.detent_torque_n_m * (4.0 * self.nr() * theta).sin()
            - self.damping_n_m_s_per_rad * (omega - v_cmd * self.rad_per_m)
    }

    /// Advance the phase currents from `tau0` to `tau1` (s) of a step whose command starts
    /// as `cmd` (position, speed, acceleration, jerk at `tau = 0`; m, m/s, ...), with the
    /// rotor on the line `theta(tau) = theta_at + omega (tau - tau_at)` (rad, rad/s).
    /// Returns the magnetic torque's integral over the span (N m s): exact in the currents
    /// (closed form between microstep edges found in time), midpoint rule in the rotor
    /// angle over pieces of at most `MAX_PIECE_ELECTRICAL_RAD`. `cache` keeps the last
    /// microstep's reference (one per axis and run; `ReferenceCache::default()` to start).
    #[allow(clippy::too_many_arguments)]
    pub fn advance_span(
        &self,
        st: &mut StepperState,
        cache: &mut ReferenceCache,
        cmd: &Sample,
        tau0: f64,
        tau1: f64,
        theta_at: f64,
        tau_at: f64,
        omega: f64,
    ) -> f64 {
        let nr = self.nr();
        let km = self.torque_constant_n_m_per_a;
        let ph = self.phase();
        let step = self.microstep_m();
        let el_per_m = nr * self.rad_per_m;
        // The command in microsteps and its rate.
        let u_at =
            |tau: f64| (cmd.p + tau * (cmd.v + tau * (cmd.a / 2.0 + tau * cmd.j / 6.0))) / step;
        let du_at = |tau: f64| (cmd.v + tau * (cmd.a + tau * cmd.j / 2.0)) / step;
        let span = tau1 - tau0;
        let pieces = (nr * omega.abs() * span / MAX_PIECE_ELECTRICAL_RAD)
            .ceil()
            .clamp(1.0, 1e6) as usize;
        let mut impulse = 0.0;
        let mut t = tau0;
        let mut k = u_at(tau0).round();
        for p in 0..pieces {
            let t_end = if p + 1 == pieces {
                tau1
            } else {
                tau0 + span * (p + 1) as f64 / pieces as f64
            };
            let (s, c) = (nr * (theta_at + omega * (0.5 * (t + t_end) - tau_at))).sin_cos();
            let (e_a, e_b) = (-km * omega * s, km * omega * c);
            let k_end = u_at(t_end).round();
            let (mut area_a, mut area_b) = (0.0, 0.0);
            // Constant reference between microstep edges: one closed-form piece each.
            loop {
                let last = k == k_end;
                let (t_next, k_next) = if last {
                    (t_end, k)
                } else {
                    let dir = if k_end > k { 1.0 } else { -1.0 };
                    (crossing(u_at, du_at, t, t_end, k + 0.5 * dir), k + dir)
                };
                if k.to_bits() != cache.k.to_bits() {
                    let (sq, cq) = (el_per_m * (k * step)).sin_cos();
                    *cache = ReferenceCache { k, sq, cq };
                }
                let [(ia, aa), (ib, ab)] = ph.advance_pair(
                    [st.i_a, st.i_b],
                    [self.current_a * cache.cq, self.current_a * cache.sq],
                    [e_a, e_b],
                    t_next - t,
                );
                st.i_a = ia;
                st.i_b = ib;
                area_a += aa;
                area_b += ab;
                t = t_next;
                k = k_next;
                if last {
                    break;
                }
            }
            impulse += km * (-area_a * s + area_b * c);
        }
        impulse
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_finds_the_root_of_a_cubic() {
        // u(t) = 1 + 2 t + 3 t^2 + 4 t^3 crosses 2.5 once on [0, 1].
        let u = |t: f64| 1.0 + t * (2.0 + t * (3.0 + 4.0 * t));
        let du = |t: f64| 2.0 + t * (6.0 + 12.0 * t);
        let t = crossing(u, du, 0.0, 1.0, 2.5);
        assert!((u(t) - 2.5).abs() < 1e-12, "{t}");
        // Decreasing.
        let t = crossing(|t| -u(t), |t| -du(t), 0.0, 1.0, -2.5);
        assert!((u(t) - 2.5).abs() < 1e-12, "{t}");
        // A root at a flat spot (zero derivative) is still found by bisection.
        let t = crossing(
            |t: f64| (t - 0.3).powi(3),
            |t: f64| 3.0 * (t - 0.3).powi(2),
            0.0,
            1.0,
            0.0,
        );
        assert!((t - 0.3).abs() < 1e-4, "{t}");
    }
}
