//! One lightly damped mode driven by the command's acceleration, by hand: the error
//! `e = x - x_cmd` obeys `e'' + 2 zeta w e' + w^2 e = -a(t)`; over a phase of constant
//! acceleration `a` the solution is the free vibration of `e + a/w^2` about `-a/w^2`.

/// A mode of `f_hz` and `zeta`.
#[derive(Debug, Clone, Copy)]
pub struct OneMode {
    w: f64,
    s: f64,
    wd: f64,
}

impl OneMode {
    /// The mode.
    pub fn new(f_hz: f64, zeta: f64) -> Self {
        let w = std::f64::consts::TAU * f_hz;
        Self {
            w,
            s: zeta * w,
            wd: w * (1.0 - zeta * zeta).sqrt(),
        }
    }

    /// Its decay rate `zeta w` (1/s).
    pub fn sigma(&self) -> f64 {
        self.s
    }

    /// The free vibration from `(u, u')` after `t` s: `(u, u')`.
    pub fn free(&self, u: f64, v: f64, t: f64) -> (f64, f64) {
        let (s, wd) = (self.s, self.wd);
        let (a, b) = (u, (v + s * u) / wd);
        let (c, sn, e) = ((wd * t).cos(), (wd * t).sin(), (-s * t).exp());
        (
            e * (a * c + b * sn),
            e * ((-s * a + wd * b) * c + (-s * b - wd * a) * sn),
        )
    }

    /// `t` s of command acceleration `acc` (m/s^2) from `(e, e')`.
    pub fn phase(&self, e: f64, v: f64, acc: f64, t: f64) -> (f64, f64) {
        let p = -acc / (self.w * self.w);
        let (u, v) = self.free(e - p, v, t);
        (u + p, v)
    }

    /// `(e, e')` at the end of `phases` (acceleration, duration) from rest.
    pub fn after(&self, phases: &[(f64, f64)]) -> (f64, f64) {
        phases
            .iter()
            .fold((0.0, 0.0), |(e, v), &(a, t)| self.phase(e, v, a, t))
    }
}
