//! Every real root of a low-degree polynomial on an interval, isolated by the roots of its
//! derivative (between consecutive critical points the polynomial is monotone, so each
//! piece holds at most one root, found by Newton steps safeguarded by bisection). Exact up
//! to rounding, with no initial guesses to miss a root.

/// Largest degree handled (the squared distance to a cubic arc has a quintic derivative).
const MAX_DEGREE: usize = 5;

/// `c[0] + c[1] x + ...` at `x`.
#[inline]
pub(crate) fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * x + k)
}

/// The roots of `c` (coefficients, constant first, degree <= 5) in `[lo, hi]`, ascending,
/// written to `out`; returns how many.
pub(crate) fn distance_roots(c: &[f64], lo: f64, hi: f64, out: &mut [f64; MAX_DEGREE]) -> usize {
    let mut deg = c.len().saturating_sub(1).min(MAX_DEGREE);
    while deg > 0 && c[deg] == 0.0 {
        deg -= 1;
    }
    let c = &c[..=deg];
    match deg {
        0 => 0,
        1 => {
            let x = -c[0] / c[1];
            if x >= lo && x <= hi {
                out[0] = x;
                1
            } else {
                0
            }
        }
        _ => {
            let mut d = [0.0; MAX_DEGREE];
            for k in 1..=deg {
                d[k - 1] = k as f64 * c[k];
            }
            let mut crit = [0.0; MAX_DEGREE];
            let nc = distance_roots(&d[..deg], lo, hi, &mut crit);
            let mut knots = [0.0; MAX_DEGREE + 2];
            knots[0] = lo;
            knots[1..=nc].copy_from_slice(&crit[..nc]);
            knots[nc + 1] = hi;
            let mut n = 0;
            for w in knots[..nc + 2].windows(2) {
                if let Some(x) = monotone_root(c, &d[..deg], w[0], w[1]) {
                    // A root at a shared knot is found from both sides: keep it once.
                    if n == 0 || x > out[n - 1] {
                        out[n] = x;
                        n += 1;
                    }
                    if n == MAX_DEGREE {
                        break;
                    }
                }
            }
            n
        }
    }
}

/// The root of `c` in `[a, b]` where `c` is monotone (`dc` its derivative), if any.
fn monotone_root(c: &[f64], dc: &[f64], a: f64, b: f64) -> Option<f64> {
    let (fa, fb) = (eval(c, a), eval(c, b));
    if fa == 0.0 {
        return Some(a);
    }
    if fb == 0.0 {
        return Some(b);
    }
    if fa.signum() == fb.signum() {
        return None;
    }
    let (mut lo, mut hi) = (a, b);
    let mut x = 0.5 * (a + b);
    for _ in 0..200 {
        let fx = eval(c, x);
        if fx == 0.0 {
            return Some(x);
        }
        if fx.signum() == fa.signum() {
            lo = x;
        } else {
            hi = x;
        }
        let slope = eval(dc, x);
        let newton = x - fx / slope;
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if next == x || next <= lo || next >= hi {
            return Some(next.clamp(lo, hi));
        }
        x = next;
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_clustered_roots() {
        // (x - 0.1)(x - 0.1001)(x - 0.5)(x + 2)(x - 0.9): expand numerically.
        let rs = [0.1, 0.1001, 0.5, -2.0, 0.9];
        let mut c = vec![1.0];
        for r in rs {
            let mut n = vec![0.0; c.len() + 1];
            for (k, &ck) in c.iter().enumerate() {
                n[k] -= r * ck;
                n[k + 1] += ck;
            }
            c = n;
        }
        let mut out = [0.0; MAX_DEGREE];
        let n = distance_roots(&c, 0.0, 1.0, &mut out);
        assert_eq!(n, 4, "{out:?}");
        for (got, want) in out[..n].iter().zip([0.1, 0.1001, 0.5, 0.9]) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        // A double root (tangency) is found too.
        let n = distance_roots(&[0.25, -1.0, 1.0], 0.0, 1.0, &mut out);
        assert_eq!((n, (out[0] - 0.5).abs() < 1e-7), (1, true));
    }
}
