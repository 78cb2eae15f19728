//! Real roots of polynomials of degree <= 6 inside an interval, without allocation.
//!
//! The planner's profile cases reduce to one polynomial equation in one unknown whose valid
//! solutions lie in a known interval. Rather than solving the quartic in closed form and
//! filtering, roots are *isolated*: the critical points (roots of the derivative, found the
//! same way one degree lower, down to the closed-form quadratic) split the interval into
//! monotone pieces; a piece whose ends differ in sign holds exactly one root, refined by
//! Newton's method kept inside the bracket (bisection whenever a step would leave it). A
//! critical point where the polynomial touches zero counts as a (double) root. Work outside
//! the interval is never done, and an interval whose Taylor bound excludes zero costs one
//! shifted evaluation.

/// Highest degree handled.
const MAX_DEG: usize = 6;

/// Up to [`MAX_DEG`] roots, ascending.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Roots {
    x: [f64; MAX_DEG],
    n: usize,
}

impl Roots {
    fn push(&mut self, x: f64) {
        if self.n < MAX_DEG && (self.n == 0 || x > self.x[self.n - 1]) {
            self.x[self.n] = x;
            self.n += 1;
        }
    }

    /// The roots, ascending.
    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.x[..self.n]
    }
}

/// `c[0] + c[1] x + ... + c[n] x^n` and its derivative.
#[inline]
fn eval_d(c: &[f64], x: f64) -> (f64, f64) {
    if let [c0, c1, c2, c3, c4] = *c {
        // The quartic, unrolled (the common case).
        let f = (((c4 * x + c3) * x + c2) * x + c1) * x + c0;
        let d = ((4.0 * c4 * x + 3.0 * c3) * x + 2.0 * c2) * x + c1;
        return (f, d);
    }
    let n = c.len() - 1;
    let mut f = c[n];
    let mut d = 0.0;
    for k in (0..n).rev() {
        d = d * x + f;
        f = f * x + c[k];
    }
    (f, d)
}

/// `sum |c_k| |x|^k`: the size of the terms, for rounding tolerances.
#[inline]
fn magnitude(c: &[f64], x: f64) -> f64 {
    let ax = x.abs();
    c.iter().rev().fold(0.0, |m, ck| m * ax + ck.abs())
}

/// Binomial coefficients `C(n, k)` for `n <= MAX_DEG`.
const BINOM: [[f64; MAX_DEG + 1]; MAX_DEG + 1] = {
    let mut b = [[0.0; MAX_DEG + 1]; MAX_DEG + 1];
    let mut n = 0;
    while n <= MAX_DEG {
        b[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            b[n][k] = b[n - 1][k - 1] + if k < n { b[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    b
};

/// Power-to-Bernstein weights `C(i, k) / C(n, k)`, indexed `[n][i][k]`.
const TO_BERNSTEIN: [[[f64; MAX_DEG + 1]; MAX_DEG + 1]; MAX_DEG + 1] = {
    let mut w = [[[0.0; MAX_DEG + 1]; MAX_DEG + 1]; MAX_DEG + 1];
    let mut n = 0;
    while n <= MAX_DEG {
        let mut i = 0;
        while i <= n {
            let mut k = 0;
            while k <= i {
                w[n][i][k] = BINOM[i][k] / BINOM[n][k];
                k += 1;
            }
            i += 1;
        }
        n += 1;
    }
    w
};

/// `c`'s coefficients (`N = degree + 1` of them) in the Bernstein basis of `[lo, hi]`,
/// and the rounding level below which their signs are not to be trusted. Fixed-size so
/// that each degree gets its own fully unrolled code.
fn bernstein<const N: usize>(c: &[f64; N], lo: f64, hi: f64) -> ([f64; N], f64) {
    let n = N - 1;
    // Coefficients of c(lo + h t), t in [0, 1]: Taylor shift, then scale.
    let mut d = *c;
    for k in 0..n {
        for i in (k..n).rev() {
            d[i] += lo * d[i + 1];
        }
    }
    let h = hi - lo;
    let mut hk = 1.0;
    let mut size = 0.0;
    for dk in &mut d {
        *dk *= hk;
        hk *= h;
        size += dk.abs();
    }
    let mut b = [0.0; N];
    let w = &TO_BERNSTEIN[n];
    for (i, bi) in b.iter_mut().enumerate() {
        for k in 0..=i {
            *bi += w[i][k] * d[k];
        }
    }
    (b, 64.0 * f64::EPSILON * size)
}

/// The roots of `c` in `[lo, hi]` by Bernstein subdivision, given its Bernstein
/// coefficients `b` there: no sign change, no root; one sign change on a monotone control
/// polygon, one root, refined from where the polygon crosses zero; otherwise split in
/// halves (de Casteljau). Returns false, having given up, where a coefficient is too close
/// to zero to trust its sign or the splitting goes too deep (a double root).
fn subdivide<const N: usize>(
    c: &[f64; N],
    b: &[f64; N],
    tol: f64,
    lo: f64,
    hi: f64,
    depth: u32,
    out: &mut Roots,
) -> bool {
    let n = N - 1;
    let mut changes = 0;
    let mut monotone = true;
    for i in 0..=n {
        if b[i].abs() <= tol {
            return false;
        }
        if i > 0 {
            changes += usize::from((b[i] < 0.0) != (b[i - 1] < 0.0));
            monotone &= i < 2 || (b[i] > b[i - 1]) == (b[1] > b[0]);
        }
    }
    if changes == 0 {
        return true;
    }
    if changes == 1 && monotone {
        let i = (0..n)
            .find(|&i| (b[i] < 0.0) != (b[i + 1] < 0.0))
            .unwrap_or(0);
        let t = (i as f64 + b[i] / (b[i] - b[i + 1])) / n as f64;
        out.push(refine(c, lo, hi, b[0], lo + t * (hi - lo)));
        return true;
    }
    if depth == 0 {
        return false;
    }
    // de Casteljau at t = 1/2: left half's coefficients are the first of each row,
    // right half's the last.
    let mut w = *b;
    let (mut left, mut right) = ([0.0; N], [0.0; N]);
    left[0] = w[0];
    right[n] = w[n];
    for r in 1..=n {
        for i in 0..=n - r {
            w[i] = 0.5 * (w[i] + w[i + 1]);
        }
        left[r] = w[0];
        right[n - r] = w[n - r];
    }
    let mid = 0.5 * (lo + hi);
    subdivide(c, &left, tol, lo, mid, depth - 1, out)
        && subdivide(c, &right, tol, mid, hi, depth - 1, out)
}

/// Bernstein isolation of the roots of `c` (degree `N - 1`) in `[lo, hi]`; false if it
/// gave up (see [`subdivide`]).
fn bernstein_roots<const N: usize>(c: &[f64], lo: f64, hi: f64, out: &mut Roots) -> bool {
    let c: &[f64; N] = c.try_into().expect("degree matches");
    let (b, tol) = bernstein(c, lo, hi);
    subdivide(c, &b, tol, lo, hi, 6, out)
}

/// The roots of `c` (lowest degree first, degree `c.len() - 1 <= 6`) in `[lo, hi]`,
/// ascending. Roots within rounding of the interval ends are included.
pub(crate) fn case_roots(c: &[f64], lo: f64, hi: f64) -> Roots {
    let mut out = Roots::default();
    if lo.is_nan() || hi.is_nan() || lo > hi {
        return out;
    }
    // Trailing zero coefficients lower the degree.
    let mut n = c.len() - 1;
    while n > 0 && c[n] == 0.0 {
        n -= 1;
    }
    let c = &c[..=n];
    match n {
        0 => {}
        1 => {
            let x = -c[0] / c[1];
            if x >= lo && x <= hi {
                out.push(x);
            }
        }
        2 => quadratic(c, lo, hi, &mut out),
        _ => {
            let isolated = match n {
                3 => bernstein_roots::<4>(c, lo, hi, &mut out),
                4 => bernstein_roots::<5>(c, lo, hi, &mut out),
                5 => bernstein_roots::<6>(c, lo, hi, &mut out),
                _ => bernstein_roots::<7>(c, lo, hi, &mut out),
            };
            if isolated {
                return out;
            }
            out = Roots::default();
            let mut d = [0.0; MAX_DEG];
            for k in 1..=n {
                d[k - 1] = k as f64 * c[k];
            }
            let crit = case_roots(&d[..n], lo, hi);
            isolate(c, lo, hi, crit.as_slice(), &mut out);
        }
    }
    out
}

/// Roots of a quadratic in `[lo, hi]`, cancellation free, polished by one Newton step.
fn quadratic(c: &[f64], lo: f64, hi: f64, out: &mut Roots) {
    let (a, b, k) = (c[2], c[1], c[0]);
    let disc = b * b - 4.0 * a * k;
    let tol = 8.0 * f64::EPSILON * (b * b + (4.0 * a * k).abs());
    let mut push = |x: f64| {
        if x >= lo && x <= hi {
            let (f, d) = eval_d(c, x);
            let y = if d != 0.0 { x - f / d } else { x };
            out.push(if y >= lo && y <= hi { y } else { x });
        }
    };
    if disc < -tol {
        return;
    }
    if disc <= tol {
        push(-b / (2.0 * a));
        return;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (x1, x2) = if q == 0.0 { (0.0, 0.0) } else { (q / a, k / q) };
    let (x1, x2) = if x1 <= x2 { (x1, x2) } else { (x2, x1) };
    push(x1);
    if x2 != x1 {
        push(x2);
    }
}

/// Roots of `c` on `[lo, hi]` given its critical points there (ascending).
fn isolate(c: &[f64], lo: f64, hi: f64, crit: &[f64], out: &mut Roots) {
    let mut xs = [0.0; MAX_DEG + 2];
    let mut m = 0;
    xs[m] = lo;
    m += 1;
    for &x in crit {
        if x > xs[m - 1] && x < hi {
            xs[m] = x;
            m += 1;
        }
    }
    if hi > xs[m - 1] {
        xs[m] = hi;
        m += 1;
    }
    let mut fs = [0.0; MAX_DEG + 2];
    for i in 0..m {
        fs[i] = eval_d(c, xs[i]).0;
    }
    let tol_at = |x: f64| 16.0 * f64::EPSILON * magnitude(c, x);
    for i in 0..m {
        // A value at a point (end or critical point) within rounding of zero is a root:
        // a double root at a critical point, or a root on the interval's edge.
        let on_zero = fs[i].abs() <= tol_at(xs[i]);
        if on_zero {
            out.push(xs[i]);
        }
        if i + 1 < m {
            let (fa, fb) = (fs[i], fs[i + 1]);
            let next_zero = fb.abs() <= tol_at(xs[i + 1]);
            if !on_zero && !next_zero && (fa < 0.0) != (fb < 0.0) {
                out.push(refine(c, xs[i], xs[i + 1], fa, f64::NAN));
            }
        }
    }
}

/// The root of `c` in `[a, b]` where `c(a)` has the sign of `fa` and `c(b)` the other
/// (exactly one root between), from the guess `x0`: Newton's method kept inside the
/// shrinking bracket; a bisection step replaces any Newton step that would leave it or
/// does not at least halve the step before. Stops when a Newton step is below 1e-14 of
/// the bracket's scale (converged: further steps are lost in rounding) or the bracket is.
fn refine(c: &[f64], a: f64, b: f64, fa: f64, x0: f64) -> f64 {
    let (mut lo, mut hi) = (a, b);
    let neg_lo = fa < 0.0;
    let mut x = if x0 > lo && x0 < hi {
        x0
    } else {
        0.5 * (lo + hi)
    };
    let tol = 1e-14 * a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
    let mut dx = hi - lo;
    // The previous Newton step (infinite until there is one, and after a bisection).
    let mut prev = f64::INFINITY;
    for _ in 0..200 {
        let (f, d) = eval_d(c, x);
        if f == 0.0 {
            return x;
        }
        if (f < 0.0) == neg_lo {
            lo = x;
        } else {
            hi = x;
        }
        let step = f / d;
        // Converged: this step is at the level of rounding, or Newton converges
        // quadratically (error after a step ~ step^2 / previous step) and the step after
        // this one would be.
        if step.abs() <= tol
            || (prev.is_finite() && step.abs() <= 1e-3 * prev && step * step <= tol * prev)
        {
            return (x - step).clamp(lo.min(hi), hi.max(lo));
        }
        let newton = x - step;
        let dx_old = std::mem::replace(&mut dx, step);
        if newton > lo.min(hi) && newton < hi.max(lo) && (2.0 * f).abs() <= (dx_old * d).abs() {
            x = newton;
            prev = step.abs();
        } else {
            prev = f64::INFINITY;
            dx = 0.5 * (hi - lo);
            x = lo + dx;
            if dx.abs() <= tol {
                break;
            }
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_roots(r: &[f64]) -> Vec<f64> {
        // Expand prod (x - r_i), lowest degree first.
        let mut c = vec![1.0];
        for &ri in r {
            let mut next = vec![0.0; c.len() + 1];
            for (k, ck) in c.iter().enumerate() {
                next[k + 1] += ck;
                next[k] -= ri * ck;
            }
            c = next;
        }
        c
    }

    #[test]
    fn finds_every_root_of_known_polynomials() {
        for r in [
            vec![-1.0, 0.5, 2.0, 3.0],
            vec![0.1, 0.1000001, 5.0, -7.0],
            vec![1.0, 2.0, 3.0],
            vec![-2.0, 4.0],
            vec![1e-3, 1e3, 1.0, -1.0],
            vec![-3.0, -1.0, 0.2, 0.7, 2.5, 9.0],
            vec![0.3, 0.31, 0.32, 4.0, -4.0],
        ] {
            let c = from_roots(&r);
            let got = case_roots(&c, -10.0, 1e4);
            let mut want = r.clone();
            want.sort_by(f64::total_cmp);
            assert_eq!(got.as_slice().len(), want.len(), "{r:?}: {got:?}");
            for (g, w) in got.as_slice().iter().zip(&want) {
                assert!((g - w).abs() <= 1e-9 * w.abs().max(1.0), "{r:?}: {got:?}");
            }
        }
    }

    #[test]
    fn double_roots_and_interval_limits() {
        // (x - 1)^2 (x + 2)(x - 4): the double root counts once.
        let c = from_roots(&[1.0, 1.0, -2.0, 4.0]);
        let got = case_roots(&c, -5.0, 5.0);
        assert_eq!(got.as_slice().len(), 3, "{got:?}");
        assert!((got.as_slice()[1] - 1.0).abs() < 1e-7);
        // Only roots inside [0, 3].
        let got = case_roots(&c, 0.0, 3.0);
        assert_eq!(got.as_slice().len(), 1, "{got:?}");
        // A root on the edge is kept.
        let got = case_roots(&c, 4.0, 6.0);
        assert_eq!(got.as_slice(), &[4.0]);
        // None.
        assert!(
            case_roots(&[1.0, 0.0, 1.0, 0.0, 1.0], -3.0, 3.0)
                .as_slice()
                .is_empty()
        );
    }
}
