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

/// The closed-form response of a linear lumped axis ([`crate::DriverMode::Linear`], every
/// stiffness at its start value) to a profile, for times after the move.
///
/// Generalises DESIGN.md's G-sum to several coupled, non-proportionally damped modes: in
/// deflection coordinates `r = q - g x_cmd` the state `s = [r, r']` obeys
/// `s' = A s + b_a a(t) + b_v v(t)`; with `A = V diag(lambda) V^-1` each complex modal
/// coordinate `y_k` obeys `y_k' = lambda_k y_k + beta_k a + gamma_k v`, whose response to a
/// piecewise-linear acceleration (and piecewise-quadratic velocity) is integrated in closed
/// form segment by segment (`phi` functions of `lambda h`). After the move, `y_k(t) =
/// e^{lambda_k (t - T)} y_k(T)` and the toolhead error is `Re sum_k (c . V_k) y_k(t)`.
/// Independent of the matrix exponential the modal plant uses.
#[derive(Debug, Clone)]
pub struct LinearResponse {
    lambda: Vec<C>,
    /// `(c . V_k) y_k(T)`: each modal term's contribution at the move end (m).
    terms: Vec<C>,
    /// Static toolhead offset from the commanded end point (m), normally 0.
    offset: f64,
    t_end: f64,
    /// Each pole's participation weight in the modes form's convention (see
    /// [`LinearResponse::weighted_modes`]); 0 for real poles.
    weights: Vec<f64>,
}

/// `phi_k(z) h^k` with `phi_1 = (e^z - 1)/z`, `phi_2 = (e^z - 1 - z)/z^2`,
/// `phi_3 = (e^z - 1 - z - z^2/2)/z^3`, by series for small `|z|`.
fn phis(lambda: C, h: f64) -> (C, C, C) {
    let z = lambda * h;
    if z.norm() < 0.5 {
        // phi_k(z) = sum_m z^m / (m + k)!
        let (mut p1, mut p2, mut p3) = (C::new(0.0, 0.0), C::new(0.0, 0.0), C::new(0.0, 0.0));
        let mut term = C::new(1.0, 0.0); // z^m / m!
        for m in 0..24 {
            let mf = m as f64;
            let t1 = term / (mf + 1.0);
            let t2 = t1 / (mf + 2.0);
            let t3 = t2 / (mf + 3.0);
            p1 += t1;
            p2 += t2;
            p3 += t3;
            term = term * z / (mf + 1.0);
        }
        (p1 * h, p2 * h * h, p3 * h * h * h)
    } else {
        let ez = z.exp();
        let p1 = (ez - 1.0) / z;
        let p2 = (ez - 1.0 - z) / (z * z);
        let p3 = (ez - 1.0 - z - z * z / 2.0) / (z * z * z);
        (p1 * h, p2 * h * h, p3 * h * h * h)
    }
}

impl LinearResponse {
    /// The response of `axis` (linear driver) to `profile`, linearised at the profile's
    /// start position.
    pub fn new(axis: &crate::AxisModel, profile: &Profile) -> Result<Self, crate::SimError> {
        use nalgebra::{DMatrix, DVector};
        let unsupported = |reason: &str| crate::SimError::Unsupported {
            backend: "closed form",
            reason: format!("axis `{}`: {reason}", axis.name),
        };
        if axis.mode != crate::DriverMode::Linear {
            return Err(unsupported("needs the linear driver"));
        }
        let l = &axis.lumped;
        let n = l.dof();
        let x0 = profile.start().p;
        let q0 = l.equilibrium(x0, None)?;
        let lin = l.linearised(&q0);
        let g = lin
            .k
            .clone()
            .lu()
            .solve(&lin.bk)
            .ok_or_else(|| unsupported("a body is held by no spring"))?;
        let minv = DVector::from_iterator(n, (0..n).map(|i| 1.0 / lin.m[(i, i)]));
        let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -minv[i] * lin.k[(i, j)];
                a[(n + i, n + j)] = -minv[i] * lin.c[(i, j)];
            }
        }
        let cg = &lin.c * &g;
        let mut ba = DVector::<f64>::zeros(2 * n);
        let mut bv = DVector::<f64>::zeros(2 * n);
        for i in 0..n {
            ba[n + i] = -g[i];
            bv[n + i] = minv[i] * (lin.bc[i] - cg[i]);
        }
        // Eigenvalues, then eigenvectors by inverse iteration on (A - lambda I).
        let lambda: Vec<C> = crate::numerics::eigenvalues(&a).ok_or_else(|| {
            unsupported("the eigenvalues of its linearised model do not converge (parts that differ by hundreds of orders of magnitude: check their units)")
        })?;
        let ac: DMatrix<C> = a.map(C::from);
        let dim = 2 * n;
        let mut v = DMatrix::<C>::zeros(dim, dim);
        for (k, &lk) in lambda.iter().enumerate() {
            let shift = lk + C::new(1e-10, 1e-10) * lk.norm().max(1.0);
            let m = &ac - DMatrix::<C>::identity(dim, dim) * shift;
            let lu = m.lu();
            let mut x = DVector::<C>::from_fn(dim, |i, _| C::new(1.0 + 0.1 * i as f64, 0.3));
            for _ in 0..3 {
                x = lu
                    .solve(&x)
                    .ok_or_else(|| unsupported("eigenvector iteration failed"))?;
                let nrm = x.norm();
                x /= C::from(nrm);
            }
            v.set_column(k, &x);
        }
        let w = v
            .clone()
            .try_inverse()
            .ok_or_else(|| unsupported("defective modes (repeated eigenvalues)"))?;
        let beta = &w * ba.map(C::from);
        let gamma = &w * bv.map(C::from);
        // Output: toolhead = c . q + c_cmd x = c . r + (c . g + c_cmd) x.
        let mut c_out = DVector::<f64>::zeros(n);
        let mut static_gain = 0.0;
        for t in &l.output {
            match t.node {
                crate::lumped::Node::Body(i) => {
                    c_out[i] += t.gain;
                    static_gain += t.gain * g[i];
                }
                crate::lumped::Node::Command => static_gain += t.gain,
                crate::lumped::Node::Ground => {}
            }
        }
        let mut y = vec![C::new(0.0, 0.0); dim];
        for (t0, s0, seg) in profile.iter() {
            let h = seg.duration_s();
            let (a0, j) = match *seg {
                Segment::Jerk { jerk, .. } => (s0.a, jerk),
                Segment::Accel { accel, .. } => (accel, 0.0),
            };
            let _ = t0;
            for k in 0..dim {
                let (p1, p2, p3) = phis(lambda[k], h);
                let ia = p1 * a0 + p2 * j;
                let iv = p1 * s0.v + p2 * a0 + p3 * j;
                y[k] = (lambda[k] * h).exp() * y[k] + beta[k] * ia + gamma[k] * iv;
            }
        }
        let terms = (0..dim)
            .map(|k| {
                let cv: C = (0..n).map(|i| v[(i, k)] * c_out[i]).sum();
                cv * y[k]
            })
            .collect();
        // The residue of the toolhead error's transfer function from the commanded
        // acceleration at pole lambda_k (with v = a / s): (c . V_k) (beta_k + gamma_k /
        // lambda_k). A mode of the modes form, -w / ((s - lambda)(s - conj lambda)), has the
        // residue -w / (2 i Im lambda) there, so w = -2 i Im(lambda) residue.
        let weights = (0..dim)
            .map(|k| {
                let lk = lambda[k];
                if lk.im <= 0.0 || lk.norm() == 0.0 {
                    return 0.0;
                }
                let cv: C = (0..n).map(|i| v[(i, k)] * c_out[i]).sum();
                let residue = cv * (beta[k] + gamma[k] / lk);
                (C::new(0.0, -2.0 * lk.im) * residue).re
            })
            .collect();
        let end = profile.end().p;
        Ok(Self {
            lambda,
            terms,
            offset: (static_gain - 1.0) * end,
            t_end: profile.duration_s(),
            weights,
        })
    }

    /// Toolhead minus commanded end point (m) at `t_s >= T`.
    pub fn error_at(&self, t_s: f64) -> f64 {
        let dt = t_s - self.t_end;
        self.lambda
            .iter()
            .zip(&self.terms)
            .map(|(l, c)| ((l * dt).exp() * c).re)
            .sum::<f64>()
            + self.offset
    }

    /// The modes as `(natural frequency Hz, damping ratio, amplitude at T in m)`, one per
    /// oscillatory pair (and one per real pole), strongest first.
    pub fn modes(&self) -> Vec<(f64, f64, f64)> {
        let mut out: Vec<(f64, f64, f64)> = self
            .lambda
            .iter()
            .zip(&self.terms)
            .filter(|(l, _)| l.im >= 0.0)
            .map(|(l, c)| {
                let w = l.norm();
                let amp = if l.im > 0.0 { 2.0 * c.norm() } else { c.norm() };
                (
                    w / std::f64::consts::TAU,
                    -l.re / w.max(f64::MIN_POSITIVE),
                    amp,
                )
            })
            .collect();
        out.sort_by(|a, b| b.2.total_cmp(&a.2));
        out
    }

    /// The oscillatory modes as `(natural frequency Hz, damping ratio, weight)`, lowest
    /// frequency first, independent of the profile: the weight is the mode's participation
    /// in the toolhead error in the modes form's convention (settle-sim's `Mode`: error =
    /// sum weight_k e_k with `e_k'' + 2 zeta_k w_k e_k' + w_k^2 e_k = -a_cmd`), from the
    /// residue of the error's transfer function at the mode's pole. For an axis built from
    /// modes it returns them; for a physical axis, its linearised modes at the profile's
    /// start position.
    pub fn weighted_modes(&self) -> Vec<(f64, f64, f64)> {
        let mut out: Vec<(f64, f64, f64)> = self
            .lambda
            .iter()
            .zip(&self.weights)
            .filter(|(l, _)| l.im > 0.0)
            .map(|(l, &w)| {
                let wn = l.norm();
                (wn / std::f64::consts::TAU, -l.re / wn, w)
            })
            .collect();
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        out
    }

    /// The continuous-time poles (1/s).
    pub fn poles(&self) -> &[C] {
        &self.lambda
    }
}
