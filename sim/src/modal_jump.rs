//! A modal axis's response to a jump of its command inside a step (a breakpoint of the
//! profile that does not fall on a step's end), so that a whole step can hold
//! breakpoints ([`crate::Plant::step_samples_across`]).
//!
//! The augmented state `x = [r, r', v, a, j]` of [`crate::modal`] obeys `x' = A x` while
//! the jerk is constant, and a breakpoint at `tau` into a step of length `h` makes `v, a,
//! j` jump by `d` (the next piece's values minus the continuation of the one before). The
//! system is linear, so the state at the step's end is the step of the command as it
//! stood at the step's start (the nominal transition), plus `Phi(h - tau) [0; d]`: the
//! jump's own response over what is left of the step. Its first `2n` rows are the
//! command columns of the transition, `Q(s) d = sum_k s^k (A^k / k!) [0; d]`, summed here
//! by Horner's rule from coefficients computed once per axis (the columns of `A^k / k!`
//! for the three command inputs, in physical coordinates).
//!
//! The series is taken to [`JUMP_TERMS`] terms for `|A| s <= JUMP_MAX_NORM`: the first
//! omitted term is below `4^41 / 41! = 1.4e-25` of `|d|`, and the largest term `4^4 / 4!`
//! loses at most a few units in the last place to cancellation. A plant whose step is
//! longer ([`Jumps::covers`]) splits its steps at the breakpoints instead.

use nalgebra::DMatrix;

/// Terms of the series (degree 1 to `JUMP_TERMS`).
pub(crate) const JUMP_TERMS: usize = 40;

/// Largest `|A| s` (infinity norm of the scaled augmented matrix times the time left in
/// the step) the series serves.
pub(crate) const JUMP_MAX_NORM: f64 = 4.0;

/// Bound on the first omitted term, relative to the jump.
const JUMP_OMITTED: f64 = 1e-18;

/// The command columns of `A^k / k!` of one axis (module doc).
#[derive(Debug, Clone)]
pub(crate) struct Jumps {
    /// Rows per coefficient (`2n`).
    n2: usize,
    /// Induced infinity norm of the scaled augmented matrix (1/s).
    norm_per_s: f64,
    /// `coeffs[(c * JUMP_TERMS + k - 1) * n2 + i]`: row `i` of column `c` (`v`, `a`, `j`)
    /// of `A^k / k!`, physical coordinates.
    coeffs: Vec<f64>,
    /// `reach[d - 1]`: the largest `|A| s` for which degree `d` leaves a first omitted
    /// term `(|A| s)^(d + 1) / (d + 1)!` at most [`JUMP_OMITTED`].
    reach: [f64; JUMP_TERMS],
}

impl Jumps {
    /// From the scaled augmented matrix of an axis with `n` bodies (`2n + 3` square), the
    /// scale of each augmented coordinate (scaled = scale x physical) and its norm.
    pub(crate) fn new(a_scaled: &DMatrix<f64>, scale: &[f64], n: usize, norm_per_s: f64) -> Self {
        let (n2, dim) = (2 * n, 2 * n + 3);
        let mut coeffs = vec![0.0; 3 * JUMP_TERMS * n2];
        for c in 0..3 {
            let col = n2 + c;
            // v_k = A^k e_col / k!, in scaled coordinates.
            let mut v = nalgebra::DVector::<f64>::zeros(dim);
            v[col] = 1.0;
            for k in 1..=JUMP_TERMS {
                v = (a_scaled * &v) / k as f64;
                let at = (c * JUMP_TERMS + k - 1) * n2;
                for i in 0..n2 {
                    coeffs[at + i] = v[i] * scale[col] / scale[i];
                }
            }
        }
        let reach = std::array::from_fn(|i| {
            // (JUMP_OMITTED (d + 1)!)^(1 / (d + 1)) for degree d = i + 1.
            let k = (i + 2) as f64;
            let ln_fact: f64 = (2..=i + 2).map(|j| (j as f64).ln()).sum();
            ((JUMP_OMITTED.ln() + ln_fact) / k).exp()
        });
        Self {
            n2,
            norm_per_s,
            coeffs,
            reach,
        }
    }

    /// Whether a jump with `s` seconds left in its step is served (module doc).
    pub(crate) fn covers(&self, s: f64) -> bool {
        self.norm_per_s * s <= JUMP_MAX_NORM
    }

    /// Add the response `Q(s) d` of a jump `d = [dv, da, dj]` with `s` seconds left in
    /// the step to the state `z` (its first `2n` entries; `s` must be
    /// [covered](Jumps::covers)).
    #[inline]
    pub(crate) fn add_to(&self, s: f64, d: [f64; 3], z: &mut [f64]) {
        let n2 = self.n2;
        let x = self.norm_per_s * s;
        // The least degree whose first omitted term is at most JUMP_OMITTED.
        let degree = self
            .reach
            .iter()
            .position(|&r| x <= r)
            .map_or(JUMP_TERMS, |i| i + 1);
        let z = &mut z[..n2];
        match n2 {
            2 => horner::<2>(&self.coeffs, degree, s, d, z),
            4 => horner::<4>(&self.coeffs, degree, s, d, z),
            6 => horner::<6>(&self.coeffs, degree, s, d, z),
            8 => horner::<8>(&self.coeffs, degree, s, d, z),
            _ => {
                let mut acc = vec![0.0; n2];
                for k in (1..=degree).rev() {
                    for (i, a) in acc.iter_mut().enumerate() {
                        let mut c = 0.0;
                        for (col, &dc) in d.iter().enumerate() {
                            if dc != 0.0 {
                                c += self.coeffs[(col * JUMP_TERMS + k - 1) * n2 + i] * dc;
                            }
                        }
                        *a = c + s * *a;
                    }
                }
                for (zi, a) in z.iter_mut().zip(&acc) {
                    *zi += s * a;
                }
            }
        }
    }
}

/// [`Jumps::add_to`] for `N2` rows: `z += s sum_{k=1}^{degree} s^(k-1) C_k d`, with
/// `C_k d` over the nonzero entries of `d`.
#[inline(always)]
fn horner<const N2: usize>(coeffs: &[f64], degree: usize, s: f64, d: [f64; 3], z: &mut [f64]) {
    let mut acc = [0.0f64; N2];
    for k in (1..=degree).rev() {
        let mut c = [0.0f64; N2];
        for (col, &dc) in d.iter().enumerate() {
            if dc != 0.0 {
                let at = (col * JUMP_TERMS + k - 1) * N2;
                for (ci, &q) in c.iter_mut().zip(&coeffs[at..at + N2]) {
                    *ci += q * dc;
                }
            }
        }
        for (a, ci) in acc.iter_mut().zip(c) {
            *a = ci + s * *a;
        }
    }
    for (zi, a) in z.iter_mut().zip(acc) {
        *zi += s * a;
    }
}
