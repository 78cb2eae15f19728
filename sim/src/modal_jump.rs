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

    /// The least degree whose first omitted term is at most [`JUMP_OMITTED`] at `|A| s =
    /// x` ([`JUMP_TERMS`] when none is, or `x` is NaN): `reach` increases with the
    /// degree, so the first entry `>= x` is found by bisection.
    #[inline]
    fn degree(&self, x: f64) -> usize {
        let first = self.reach.partition_point(|&r| x.is_nan() || x > r);
        (first + 1).min(JUMP_TERMS)
    }

    /// The response `Q(s) d` of a jump `d = [dv, da, dj]` with `s` seconds left in the
    /// step (`s` must be [covered](Jumps::covers)), to add to the state's first `N2 = 2n`
    /// entries: `s sum_{k=1}^{degree} s^(k-1) C_k d` by Horner's rule, with `C_k d`
    /// summed over the nonzero entries of `d` in order from `+0`. It does not depend on
    /// the state, so a caller may form it ahead of the step it joins.
    #[inline]
    pub(crate) fn response<const N2: usize>(&self, s: f64, d: [f64; 3]) -> [f64; N2] {
        debug_assert_eq!(N2, self.n2);
        let degree = self.degree(self.norm_per_s * s);
        let acc = match d.map(|dc| dc != 0.0) {
            // Only the acceleration jumps (a trapezoid's corners): one column.
            [false, true, false] => self.horner_one::<N2>(1, degree, s, d[1]),
            // Nothing jumps: every sum is +0.
            [false, false, false] => [0.0; N2],
            _ => self.horner::<N2>(degree, s, d),
        };
        acc.map(|a| s * a)
    }

    /// Horner's sum `sum_{k=1}^{degree} s^(k-1) C_k d` over the columns where `d` is
    /// nonzero.
    #[inline(always)]
    fn horner<const N2: usize>(&self, degree: usize, s: f64, d: [f64; 3]) -> [f64; N2] {
        let mut acc = [0.0f64; N2];
        for k in (1..=degree).rev() {
            let mut c = [0.0f64; N2];
            for (col, &dc) in d.iter().enumerate() {
                if dc != 0.0 {
                    let at = (col * JUMP_TERMS + k - 1) * N2;
                    for (ci, &q) in c.iter_mut().zip(&self.coeffs[at..at + N2]) {
                        *ci += q * dc;
                    }
                }
            }
            for (a, ci) in acc.iter_mut().zip(c) {
                *a = ci + s * *a;
            }
        }
        acc
    }

    /// [`Jumps::horner`] when only column `col` is nonzero (`dc`): the same sums
    /// (`+0 + q dc` for each `C_k d`), without a test per column and term.
    #[inline(always)]
    fn horner_one<const N2: usize>(&self, col: usize, degree: usize, s: f64, dc: f64) -> [f64; N2] {
        let at = col * JUMP_TERMS * N2;
        let terms = &self.coeffs[at..at + degree * N2];
        let mut acc = [0.0f64; N2];
        for q in terms.chunks_exact(N2).rev() {
            for (a, &q) in acc.iter_mut().zip(q) {
                *a = (0.0 + q * dc) + s * *a;
            }
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (splitmix64), so the test needs no dependency.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let z = (self.0 ^ (self.0 >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            let z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }

        /// Uniform in `[-1, 1)`.
        fn signed(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// The sum the response stands for, written out: the degree by a scan of `reach`, and
    /// for each term every nonzero column added in order to `+0`.
    fn reference(j: &Jumps, s: f64, d: [f64; 3]) -> Vec<f64> {
        let x = j.norm_per_s * s;
        let degree = j
            .reach
            .iter()
            .position(|&r| x <= r)
            .map_or(JUMP_TERMS, |i| i + 1);
        let mut acc = vec![0.0; j.n2];
        for k in (1..=degree).rev() {
            for (i, a) in acc.iter_mut().enumerate() {
                let mut c = 0.0;
                for (col, &dc) in d.iter().enumerate() {
                    if dc != 0.0 {
                        c += j.coeffs[(col * JUMP_TERMS + k - 1) * j.n2 + i] * dc;
                    }
                }
                *a = c + s * *a;
            }
        }
        acc.iter().map(|a| s * a).collect()
    }

    fn check<const N2: usize>(rng: &mut Rng) {
        let n = N2 / 2;
        let dim = N2 + 3;
        // Sparse, as a chain of bodies is: the first terms of some rows are exact zeros.
        let a = DMatrix::from_fn(dim, dim, |_, _| match rng.next() % 3 {
            0 => 40.0 * rng.signed(),
            _ => 0.0,
        });
        let scale: Vec<f64> = (0..dim).map(|_| 2f64.powf(4.0 * rng.signed())).collect();
        let norm = (0..dim)
            .map(|i| a.row(i).iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let j = Jumps::new(&a, &scale, n, norm);
        for _ in 0..2000 {
            // Times across the whole range the series serves, some tiny; jumps with each
            // pattern of zero columns, some with a signed zero.
            let s =
                JUMP_MAX_NORM / norm * (0.5 + 0.5 * rng.signed()).powi(1 + (rng.next() % 6) as i32);
            let mut d = [rng.signed(), 50.0 * rng.signed(), 1e4 * rng.signed()];
            let pattern = rng.next() % 10;
            for (c, v) in d.iter_mut().enumerate() {
                if pattern < 8 && (pattern >> c) & 1 == 0 {
                    *v = if rng.next().is_multiple_of(2) {
                        0.0
                    } else {
                        -0.0
                    };
                }
            }
            let got = j.response::<N2>(s, d);
            let want = reference(&j, s, d);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "s {s}, d {d:?}");
        }
    }

    /// The response equals the written-out sum bit for bit, for every state size the
    /// plant serves and every pattern of zero jumps.
    #[test]
    fn the_response_is_the_written_out_sum_bit_for_bit() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        check::<2>(&mut rng);
        check::<4>(&mut rng);
        check::<6>(&mut rng);
        check::<8>(&mut rng);
        check::<10>(&mut rng);
        check::<16>(&mut rng);
    }
}
