//! The least-squares solve behind Klipper's generalised MZV (`get_mzv_coeffs`), done in the
//! same order as klippy/mathutil.py's `pseudo_inverse` and `gaussian_solve`, so that the
//! amplitudes (and the decision that a system is ill-formed) are Klipper's own.
//!
//! `get_mzv_coeffs` takes the first row of `pinv(M) ^ T`, i.e. the first column of
//! `pinv(M) = (M^T M)^-1 M^T`. The first row of `M` is all ones, so that column is the
//! solution `x` of `(M^T M) x = 1`. `gaussian_solve` eliminates from the last column
//! backwards with partial pivoting among the rows above, scaling each pivot row, and then
//! substitutes forwards; a pivot below `1e-10` in magnitude means "ill-formed".

/// The first column of the pseudo-inverse of `rows` (an `m x n` matrix whose first row is
/// all ones), or `None` when Klipper's elimination meets a pivot below `1e-10`.
pub(super) fn least_squares_first_column(rows: &[Vec<f64>]) -> Option<Vec<f64>> {
    let n = rows.first()?.len();
    // G = M^T M, each entry summed in row order as Python's `sum(map(mul, ...))`.
    let mut g: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let mut s = 0.0;
                    for r in rows {
                        s += r[i] * r[j];
                    }
                    s
                })
                .collect()
        })
        .collect();
    // Right-hand side: the first column of M^T, the first row of M.
    let mut b: Vec<f64> = rows[0].clone();
    for i in (0..n).rev() {
        let mut pivot = 0;
        let mut best = f64::NEG_INFINITY;
        for (j, row) in g.iter().enumerate().take(i + 1) {
            let v = row[i].abs();
            if v > best {
                best = v;
                pivot = j;
            }
        }
        g.swap(i, pivot);
        b.swap(i, pivot);
        let diag = g[i][i];
        if diag.abs() < 1e-10 {
            return None;
        }
        let recipr = 1.0 / diag;
        let row_i: Vec<f64> = g[i][..i].iter().map(|x| x * recipr).collect();
        b[i] *= recipr;
        for j in 0..i {
            let c = g[j][i];
            let new: Vec<f64> = g[j][..i]
                .iter()
                .zip(&row_i)
                .map(|(x, y)| x - c * y)
                .collect();
            g[j] = new;
            b[j] -= c * b[i];
        }
        g[i] = row_i;
    }
    // Forward substitution with the unit lower-triangular factor left in g.
    for i in 1..n {
        let mut s = 0.0;
        for k in 0..i {
            s += g[i][k] * b[k];
        }
        b[i] -= s;
    }
    Some(b)
}
