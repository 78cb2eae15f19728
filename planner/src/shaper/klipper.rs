//! Klipper's shapers as klippy/extras/shaper_defs.py computes them (the amplitudes are
//! not normalised; Klipper's C side divides by their sum).
//!
//! With `df = sqrt(1 - zeta^2)`, `K = exp(-zeta pi / df)` and the damped period
//! `t_d = 1 / (f df)`:
//! - `zv`: `A = [1, K]`, `T = [0, t_d/2]`; `zvd`: `A = [1, 2K, K^2]`, `T = [0, t_d/2, t_d]`.
//! - `mzv(n, t)`: `n` impulses at `T_i = i t t_d / (n - 1)`; undamped amplitudes summing to
//!   one from a least-squares system that places the shaper's zeros (`get_mzv_coeffs`, in
//!   [`mzv_coeffs`]), then damped by `K_m^i` with `K_m = exp(-2 t zeta pi / ((n - 1) df))`.
//!   `mzv(3, 0.75)` is the classic MZV.
//! - `ei(v_tol)`: `a1`, `a3` and the middle time `t2` are polynomials in `zeta` whose
//!   coefficients are linear in `v_tol`; `a2 = 1 - a1 - a3`; `T = [0, t2 t_d, t_d]`.
//! - `2hump_ei`, `3hump_ei`: every time (in units of `1/f`, not the damped period) and
//!   amplitude is a cubic in `zeta` (`_get_shaper_from_expansion_coeffs`).
//!
//! Each expression keeps the Python's order of operations, so the values agree with
//! Klipper's to the last bit wherever the platform's `exp`, `sin` and `cos` do.

use std::f64::consts::PI;

use super::mzv_solve::least_squares_first_column;
use super::shaper_type::Impulses;

/// Klipper's largest damping ratio per shaper (`max_damping_ratio` in `INPUT_SHAPERS`):
/// `damping_ratio` above it is refused by `[input_shaper]` and `SET_INPUT_SHAPER`.
pub(super) fn max_damping_ratio(family: &str) -> f64 {
    match family {
        "ei" => 0.4,
        "2hump_ei" => 0.3,
        "3hump_ei" => 0.2,
        _ => 0.99,
    }
}

/// The most impulses Klipper's step generation takes (`pulses[10]` in
/// klippy/chelper/kin_shaper.c); a longer shaper fails to configure.
const MAX_PULSES: u32 = 10;

fn damped(f_hz: f64, zeta: f64) -> (f64, f64, f64) {
    let df = (1.0 - zeta * zeta).sqrt();
    let k = (-zeta * PI / df).exp();
    let t_d = 1.0 / (f_hz * df);
    (df, k, t_d)
}

pub(super) fn zv(f_hz: f64, zeta: f64) -> Impulses {
    let (_, k, t_d) = damped(f_hz, zeta);
    (vec![1.0, k], vec![0.0, 0.5 * t_d])
}

pub(super) fn zvd(f_hz: f64, zeta: f64) -> Impulses {
    let (_, k, t_d) = damped(f_hz, zeta);
    (vec![1.0, 2.0 * k, k * k], vec![0.0, 0.5 * t_d, t_d])
}

/// `t` of `mzv(n, tau=...)`: the duration whose projected duration for `n -> infinity`
/// is `tau` (`get_mzv_shaper`).
pub(super) fn mzv_t_from_tau(n: u32, tau: f64) -> f64 {
    let n = f64::from(n);
    tau * (n - 1.0) / (n + 2.0 * tau - 2.0)
}

/// Undamped MZV amplitudes (summing to one) and times in damped periods
/// (`get_mzv_coeffs`), or Klipper's reason for refusing `(n, t)`.
pub(super) fn mzv_coeffs(n: u32, t: f64) -> Result<Impulses, String> {
    if n < 3 {
        return Err(format!("Too small n={n}, must be at least 3"));
    }
    if n > MAX_PULSES {
        return Err(format!(
            "n={n} impulses: Klipper's step generation takes at most {MAX_PULSES}"
        ));
    }
    let nf = f64::from(n);
    if !(t.is_finite() && t > 0.0) || nf <= 2.0 * t + 1.0 + 1e-7 {
        return Err(format!(
            "Too large t={t:.6} for n={n}, must be less than {:.6}",
            0.5 * (nf - 1.0)
        ));
    }
    // Projected duration with n -> infinity, which places the shaper's zeros.
    let tau = t * (nf - 2.0) / (nf - 2.0 * t - 1.0);
    let times: Vec<f64> = (0..n).map(|i| f64::from(i) * t / (nf - 1.0)).collect();
    // Rows: sum(A) = 1, then cos and sin rows for each of the n - 1 zeros.
    let mut rows: Vec<Vec<f64>> = vec![vec![1.0; n as usize]];
    for i in 0..n - 1 {
        let w: Vec<f64> = times
            .iter()
            .map(|tj| 2.0 * PI * (1.0 + f64::from(i) / tau) * tj)
            .collect();
        rows.push(w.iter().map(|w| w.cos()).collect());
        rows.push(w.iter().map(|w| w.sin()).collect());
    }
    let a = least_squares_first_column(&rows)
        .ok_or_else(|| format!("Ill-formed shaper with n={n}, t={t:.6}"))?;
    if a.iter().any(|&x| x < -0.00001) {
        return Err(format!("Negative-valued shaper with n={n}, t={t:.6}"));
    }
    Ok((a, times))
}

pub(super) fn mzv(f_hz: f64, zeta: f64, n: u32, t: f64) -> Result<Impulses, String> {
    let (mut a, mut times) = mzv_coeffs(n, t)?;
    let df = (1.0 - zeta * zeta).sqrt();
    let k = (-2.0 * t * zeta * PI / ((f64::from(n) - 1.0) * df)).exp();
    let t_d = 1.0 / (f_hz * df);
    let mut kp = k;
    for i in 1..n as usize {
        times[i] *= t_d;
        a[i] *= kp;
        kp *= k;
    }
    Ok((a, times))
}

pub(super) fn ei(f_hz: f64, zeta: f64, v_tol: f64) -> Impulses {
    let df = (1.0 - zeta * zeta).sqrt();
    let t_d = 1.0 / (f_hz * df);
    let dr = zeta;
    let a1 = (0.24968 + 0.24961 * v_tol)
        + ((0.80008 + 1.23328 * v_tol) + (0.49599 + 3.17316 * v_tol) * dr) * dr;
    let a3 = (0.25149 + 0.21474 * v_tol)
        + ((-0.83249 + 1.41498 * v_tol) + (0.85181 - 4.90094 * v_tol) * dr) * dr;
    let a2 = 1.0 - a1 - a3;
    let t2 = 0.4999
        + (((0.46159 + 8.57843 * v_tol) * v_tol)
            + (((4.26169 - 108.644 * v_tol) * v_tol) + ((1.75601 + 336.989 * v_tol) * v_tol) * dr)
                * dr)
            * dr;
    (vec![a1, a2, a3], vec![0.0, t2 * t_d, t_d])
}

/// Times (in `1/f`) and amplitudes as cubics in `zeta`, evaluated by Horner's rule as
/// `_get_shaper_from_expansion_coeffs` does.
fn expansion<const N: usize>(
    f_hz: f64,
    zeta: f64,
    t: &[[f64; 4]; N],
    a: &[[f64; 4]; N],
) -> Impulses {
    let tau = 1.0 / f_hz;
    let eval = |c: &[f64; 4]| {
        let mut u = c[3];
        for j in 0..3 {
            u = u * zeta + c[2 - j];
        }
        u
    };
    (
        a.iter().map(eval).collect(),
        t.iter().map(|c| eval(c) * tau).collect(),
    )
}

pub(super) fn two_hump_ei(f_hz: f64, zeta: f64) -> Impulses {
    const T: [[f64; 4]; 4] = [
        [0., 0., 0., 0.],
        [0.49890, 0.16270, -0.54262, 6.16180],
        [0.99748, 0.18382, -1.58270, 8.17120],
        [1.49920, -0.09297, -0.28338, 1.85710],
    ];
    const A: [[f64; 4]; 4] = [
        [0.16054, 0.76699, 2.26560, -1.22750],
        [0.33911, 0.45081, -2.58080, 1.73650],
        [0.34089, -0.61533, -0.68765, 0.42261],
        [0.15997, -0.60246, 1.00280, -0.93145],
    ];
    expansion(f_hz, zeta, &T, &A)
}

pub(super) fn three_hump_ei(f_hz: f64, zeta: f64) -> Impulses {
    const T: [[f64; 4]; 5] = [
        [0., 0., 0., 0.],
        [0.49974, 0.23834, 0.44559, 12.4720],
        [0.99849, 0.29808, -2.36460, 23.3990],
        [1.49870, 0.10306, -2.01390, 17.0320],
        [1.99960, -0.28231, 0.61536, 5.40450],
    ];
    const A: [[f64; 4]; 5] = [
        [0.11275, 0.76632, 3.29160, -1.44380],
        [0.23698, 0.61164, -2.57850, 4.85220],
        [0.30008, -0.19062, -2.14560, 0.13744],
        [0.23775, -0.73297, 0.46885, -2.08650],
        [0.11244, -0.45439, 0.96382, -1.46000],
    ];
    expansion(f_hz, zeta, &T, &A)
}
