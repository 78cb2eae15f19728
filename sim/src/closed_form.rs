//! Closed-form residual vibration of one mode after a profile with piecewise-linear
//! acceleration, independent of any integrator.
//!
//! For `e'' + 2 zeta w e' + w^2 e = -a(t)` from rest, the convolution with the impulse
//! response `h(t) = e^{-zeta w t} sin(wd t)/wd` gives, for t >= T (the profile end),
//! `e(t) = -(e^{-zeta w t}/wd) Im[e^{i wd t} G]` with `G = int_0^T e^{p tau} a(tau) dtau`,
//! `p = zeta w - i wd`. On a segment `a = a_k + j_k (tau - t_k)` the antiderivative is
//! `e^{p tau} ((a_k + j_k (tau - t_k))/p - j_k/p^2)`, which is DESIGN.md's sum. The envelope
//! at T is `A(T) = e^{-zeta w T} |G| / wd`.
//!
//! Numerically, `e^{p tau}` grows like `e^{zeta w tau}`; we accumulate
//! `G' = e^{-zeta w T} G` (each term scaled by `e^{zeta w (tau - T)}`), which never
//! overflows, and write every result in terms of it.

use nalgebra::Complex;
use settle_planner::{Profile, Segment};

use crate::Mode;

type C = Complex<f64>;

/// `G' = e^{-zeta w T} G` for the profile's acceleration and this mode.
fn g_scaled(profile: &Profile, mode: &Mode) -> C {
    let w = mode.omega();
    let zw = mode.damping_ratio() * w;
    let p = C::new(zw, -mode.omega_d());
    let t_end = profile.duration_s();
    let mut g = C::new(0.0, 0.0);
    // e^{p tau} scaled by e^{-zeta w T}: e^{zw (tau - T)} e^{-i wd tau}.
    let ep = |tau: f64| C::from_polar((zw * (tau - t_end)).exp(), -mode.omega_d() * tau);
    for (t0, s0, seg) in profile.iter() {
        let t1 = t0 + seg.duration_s();
        let (ak, jk) = match *seg {
            Segment::Jerk { jerk, .. } => (s0.a, jerk),
            Segment::Accel { accel, .. } => (accel, 0.0),
        };
        let anti =
            |tau: f64| ep(tau) * ((C::from(ak + jk * (tau - t0))) / p - C::from(jk) / (p * p));
        g += anti(t1) - anti(t0);
    }
    g
}

/// Residual envelope A(T) (m) of `mode` at the end of `profile`: the amplitude of the free
/// vibration that follows the move.
pub fn residual_envelope(profile: &Profile, mode: &Mode) -> f64 {
    g_scaled(profile, mode).norm() / mode.omega_d()
}

/// The deflection e(t) (m) of `mode` at time `t_s >= T` after `profile` (zero before the
/// move, command held after it).
pub fn residual_at(profile: &Profile, mode: &Mode, t_s: f64) -> f64 {
    let zw = mode.damping_ratio() * mode.omega();
    let wd = mode.omega_d();
    let g = g_scaled(profile, mode);
    let rot = C::from_polar(1.0, wd * t_s);
    -((-zw * (t_s - profile.duration_s())).exp() / wd) * (rot * g).im
}

/// DESIGN.md's undamped rest-to-rest S-curve residual amplitude (m):
/// `(4 a_peak / w^2) |sin(w (Ta - Tj)/2) sin(w (Ta + Tc)/2)| |sinc(w Tj / 2)|`, where `Ta`
/// is the whole acceleration phase (both jerk ramps included), `Tj` one jerk ramp and `Tc`
/// the cruise. A trapezoid is the case `Tj = 0`. Derivation: the acceleration pulse is a
/// box of width `Ta - Tj` convolved with a unit-area box of width `Tj`; its Fourier
/// magnitude at w is `a_peak (Ta - Tj) sinc(w (Ta - Tj)/2) sinc(w Tj/2)`, the decelerating
/// pulse repeats it with opposite sign `Ta + Tc` later (factor `2 |sin(w (Ta + Tc)/2)|`),
/// and the undamped residual amplitude is that magnitude over w.
pub fn undamped_scurve_residual(
    a_peak: f64,
    t_acc: f64,
    t_jerk: f64,
    t_cruise: f64,
    w: f64,
) -> f64 {
    let sinc = |x: f64| if x == 0.0 { 1.0 } else { x.sin() / x };
    (4.0 * a_peak / (w * w))
        * ((w * (t_acc - t_jerk) / 2.0).sin() * (w * (t_acc + t_cruise) / 2.0).sin()).abs()
        * sinc(w * t_jerk / 2.0).abs()
}
