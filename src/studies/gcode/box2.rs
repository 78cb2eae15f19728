//! An axis-aligned box in the XY plane and the lower bound it gives on distances: the
//! pruning of the nearest-segment searches of [`crate::studies::gcode::command_path`]
//! (the command's path) and [`crate::studies::gcode::contour`] (an arc's segments).

/// An axis-aligned box (XY, mm): least X and Y, then largest.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Box2 {
    pub(crate) min: [f64; 2],
    pub(crate) max: [f64; 2],
}

impl Box2 {
    pub(crate) fn at(c: [f64; 2]) -> Self {
        Self { min: c, max: c }
    }

    pub(crate) fn add(&mut self, c: [f64; 2]) {
        for ((lo, hi), c) in self.min.iter_mut().zip(&mut self.max).zip(c) {
            *lo = lo.min(c);
            *hi = hi.max(c);
        }
    }

    /// [`Box2::near_sq`] with [`f64::max`] (which passes over a NaN): the reference it
    /// equals bit for bit on finite numbers.
    #[cfg(test)]
    pub(crate) fn distance_sq(&self, p: [f64; 2]) -> f64 {
        let dx = (self.min[0] - p[0]).max(p[0] - self.max[0]).max(0.0);
        let dy = (self.min[1] - p[1]).max(p[1] - self.max[1]).max(0.0);
        dx * dx + dy * dy
    }

    /// The square of the distance (mm^2) from `p` to the box: at most the square of the
    /// distance to anything in it. The larger of two numbers is taken without looking
    /// for a NaN ([`larger`]; the sign of a zero is squared away). A NaN only comes from
    /// a NaN `p` or a box of NaN points, whose segments' distances are NaN, which the
    /// least distance ignores: which of them are computed changes nothing.
    #[inline]
    pub(crate) fn near_sq(&self, p: [f64; 2]) -> f64 {
        let dx = larger(larger(self.min[0] - p[0], p[0] - self.max[0]), 0.0);
        let dy = larger(larger(self.min[1] - p[1], p[1] - self.max[1]), 0.0);
        dx * dx + dy * dy
    }
}

/// The larger of `a` and `b`, `b` when either is NaN (one instruction where
/// [`f64::max`] needs four to pass over a NaN).
#[inline]
pub(crate) fn larger(a: f64, b: f64) -> f64 {
    if a > b { a } else { b }
}
