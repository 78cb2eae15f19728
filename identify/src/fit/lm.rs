//! Levenberg-Marquardt least squares with the parameter covariance.
//!
//! Minimises `sum r_i(theta)^2` (Marquardt's scaling: the damping term is
//! `lambda diag(J^T J)`), with a forward-difference Jacobian. The covariance of the
//! estimate is `s^2 (J^T J)^-1` with `s^2 = RSS / (n - p)` (Gauss-Newton linearisation at
//! the optimum), times an inflation factor the caller supplies for correlated residuals.

use nalgebra::{DMatrix, DVector};

/// The search has converged when a step lowers the sum of squares by less than this
/// fraction of it: the parameters then move by far less than their standard deviations
/// (a change `d` of the sum of squares moves a parameter by about `sqrt(d / RSS)` of its
/// standard deviation per residual degree of freedom).
pub const CONVERGED_RELATIVE: f64 = 1e-10;

/// Result of a fit.
#[derive(Debug, Clone)]
pub struct LmFit {
    /// The parameters at the optimum.
    pub theta: Vec<f64>,
    /// The residuals at the optimum.
    pub residuals: Vec<f64>,
    /// Residual sum of squares.
    pub rss: f64,
    /// `(J^T J)^-1` at the optimum (multiply by `s^2` for the covariance); `None` when
    /// `J^T J` is singular (a parameter the data do not determine).
    pub inv_normal: Option<DMatrix<f64>>,
    /// The Jacobian `J` of the residuals at the optimum (rows: residuals, columns:
    /// parameters).
    pub jacobian: DMatrix<f64>,
    /// Iterations taken.
    pub iterations: usize,
    /// True when the last step changed the sum of squares by less than
    /// [`CONVERGED_RELATIVE`] of it (or no step lowered it), false when the iteration limit
    /// stopped the search.
    pub converged: bool,
}

impl LmFit {
    /// Residual variance `RSS / (n - p)`.
    pub fn residual_variance(&self) -> f64 {
        let n = self.residuals.len();
        let p = self.theta.len();
        self.rss / (n.saturating_sub(p).max(1)) as f64
    }

    /// Standard deviations of the parameters: `sqrt(inflation s^2 (J^T J)^-1_ii)`.
    pub fn sigmas(&self, inflation: f64) -> Option<Vec<f64>> {
        let inv = self.inv_normal.as_ref()?;
        let s2 = self.residual_variance() * inflation;
        (0..self.theta.len())
            .map(|i| {
                let v = inv[(i, i)] * s2;
                (v.is_finite() && v >= 0.0).then(|| v.sqrt())
            })
            .collect()
    }

    /// The parameters' covariance when the residuals have the covariance `cov_r`
    /// (not a multiple of the identity): the sandwich `(J^T J)^-1 J^T cov_r J (J^T J)^-1`
    /// of the linearised least-squares estimate, which holds whatever the residuals'
    /// correlation and for any weighting. `None` when `J^T J` is singular.
    pub fn sandwich(&self, cov_r: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        let inv = self.inv_normal.as_ref()?;
        let jt = self.jacobian.transpose();
        let meat = &jt * cov_r * &self.jacobian;
        Some(inv * meat * inv)
    }
}

/// The Jacobian of `f` at `theta` by forward differences (step `1e-6 max(1, |theta_i|)`,
/// backwards where the forward step leaves `f`'s domain); `None` if both fail.
fn jacobian<F>(f: &F, theta: &[f64], r0: &[f64]) -> Option<DMatrix<f64>>
where
    F: Fn(&[f64]) -> Option<Vec<f64>>,
{
    let n = r0.len();
    let p = theta.len();
    let mut j = DMatrix::zeros(n, p);
    let mut t = theta.to_vec();
    for k in 0..p {
        let mut h = 1e-6 * theta[k].abs().max(1.0);
        t[k] = theta[k] + h;
        // At the edge of the domain, difference backwards.
        let r = match f(&t) {
            Some(r) => r,
            None => {
                h = -h;
                t[k] = theta[k] + h;
                f(&t)?
            }
        };
        t[k] = theta[k];
        for i in 0..n {
            j[(i, k)] = (r[i] - r0[i]) / h;
        }
    }
    Some(j)
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Minimise `sum f(theta)^2` from `start`. `f` returns `None` for parameters outside its
/// domain (the step is then rejected). `None` if `f` fails at the start.
pub fn minimise<F>(f: F, start: &[f64], max_iterations: usize) -> Option<LmFit>
where
    F: Fn(&[f64]) -> Option<Vec<f64>>,
{
    let mut theta = start.to_vec();
    let mut r = f(&theta)?;
    let mut rss = sum_sq(&r);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    let mut converged = false;
    let p = theta.len();
    while iterations < max_iterations {
        iterations += 1;
        let j = jacobian(&f, &theta, &r)?;
        let jt = j.transpose();
        let a = &jt * &j;
        let g = &jt * DVector::from_column_slice(&r);
        let mut improved = false;
        while lambda < 1e12 {
            let mut damped = a.clone();
            for k in 0..p {
                damped[(k, k)] += lambda * a[(k, k)].max(1e-12);
            }
            let Some(step) = damped.cholesky().map(|c| c.solve(&(-&g))) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = theta.iter().zip(step.iter()).map(|(t, s)| t + s).collect();
            match f(&trial) {
                Some(rt) if sum_sq(&rt) < rss => {
                    let new_rss = sum_sq(&rt);
                    let small = rss - new_rss <= CONVERGED_RELATIVE * rss.max(f64::MIN_POSITIVE);
                    theta = trial;
                    r = rt;
                    rss = new_rss;
                    lambda = (lambda / 10.0).max(1e-12);
                    improved = !small;
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        if !improved {
            converged = true;
            break;
        }
    }
    let j = jacobian(&f, &theta, &r)?;
    let inv_normal = (j.transpose() * &j).try_inverse();
    Some(LmFit {
        theta,
        residuals: r,
        rss,
        inv_normal,
        jacobian: j,
        iterations,
        converged,
    })
}
