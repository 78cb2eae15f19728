//! Arc algebra under four jerks: which jerk applies where, the velocity an acceleration
//! arc gains, the segments of an arc, and the time-optimal velocity change to zero
//! acceleration.
//!
//! A **U arc** raises the acceleration at full jerk (`j1` while `a >= 0`, `j4` while
//! `a < 0`), a **D arc** lowers it (`j2` while `a > 0`, `j3` while `a <= 0`). Because
//! `dv = a dt = a da / J(a)`, the velocity an arc gains depends only on its end
//! accelerations: a U arc from `x` to `y` gains `gu(y) - gu(x)`, a D arc from `x` to `y`
//! gains `gd(x) - gd(y)`, with `gu(a) = a^2/(2 J_U(a))` and `gd(a) = a^2/(2 J_D(a))`.

use super::limits::FourJerkLimits;
use crate::{Segment, State};

impl FourJerkLimits {
    /// Jerk magnitude that raises the acceleration from `a` (`j1` for `a >= 0`, else `j4`).
    pub fn j_up(&self, a: f64) -> f64 {
        if a >= 0.0 { self.jerk[0] } else { self.jerk[3] }
    }

    /// Jerk magnitude that lowers the acceleration from `a` (`j2` for `a > 0`, else `j3`).
    pub fn j_down(&self, a: f64) -> f64 {
        if a > 0.0 { self.jerk[1] } else { self.jerk[2] }
    }

    /// `gu(a) = a^2/(2 J_U(a))` (u/s).
    pub(crate) fn gu(&self, a: f64) -> f64 {
        a * a / (2.0 * self.j_up(a))
    }

    /// `gd(a) = a^2/(2 J_D(a))` (u/s).
    pub(crate) fn gd(&self, a: f64) -> f64 {
        a * a / (2.0 * self.j_down(a))
    }

    /// `1/(2 j1) + 1/(2 j2)`: velocity per squared peak of a positive U-D excursion.
    pub(crate) fn k_acc(&self) -> f64 {
        0.5 / self.jerk[0] + 0.5 / self.jerk[1]
    }

    /// `1/(2 j3) + 1/(2 j4)`: velocity per squared valley of a negative D-U excursion.
    pub(crate) fn k_dec(&self) -> f64 {
        0.5 / self.jerk[2] + 0.5 / self.jerk[3]
    }

    /// The same limits seen in the mirrored frame (p, v, a -> -p, -v, -a): AMAX and DMAX
    /// swap, and so do the jerk pairs (j1, j3) and (j2, j4).
    pub fn mirrored(&self) -> Self {
        let [j1, j2, j3, j4] = self.jerk;
        Self {
            vmax: self.vmax,
            amax: self.dmax,
            dmax: self.amax,
            jerk: [j3, j4, j1, j2],
        }
    }
}

/// Append the U arc from acceleration `x` to `y >= x` (split where it crosses zero).
pub(crate) fn push_up(out: &mut Vec<Segment>, x: f64, y: f64, l: &FourJerkLimits) {
    if y <= x {
        return;
    }
    if x < 0.0 && y > 0.0 {
        push_up(out, x, 0.0, l);
        push_up(out, 0.0, y, l);
        return;
    }
    let j = l.j_up(x);
    out.push(Segment::Jerk {
        duration_s: (y - x) / j,
        jerk: j,
    });
}

/// Append the D arc from acceleration `x` to `y <= x` (split where it crosses zero).
pub(crate) fn push_down(out: &mut Vec<Segment>, x: f64, y: f64, l: &FourJerkLimits) {
    if y >= x {
        return;
    }
    if x > 0.0 && y < 0.0 {
        push_down(out, x, 0.0, l);
        push_down(out, 0.0, y, l);
        return;
    }
    let j = l.j_down(x);
    out.push(Segment::Jerk {
        duration_s: (x - y) / j,
        jerk: -j,
    });
}

/// Append a hold at acceleration `a` for `h` seconds (if `h > 0`).
pub(crate) fn push_hold(out: &mut Vec<Segment>, a: f64, h: f64) {
    if h > 0.0 {
        out.push(Segment::Accel {
            duration_s: h,
            accel: a,
        });
    }
}

/// The velocity reached when the acceleration `a0` is brought to zero at once (u/s).
pub(crate) fn v_zero(v0: f64, a0: f64, l: &FourJerkLimits) -> f64 {
    if a0 >= 0.0 {
        v0 + l.gd(a0)
    } else {
        v0 - l.gu(a0)
    }
}

/// The time-optimal change from `(v0, a0)` (a0 within the limits) to `(v1, 0)`: up-down
/// if `v1` is above [`v_zero`], else down-up, holding the acceleration limit if reached.
pub(crate) fn change_to_zero(v0: f64, a0: f64, v1: f64, l: &FourJerkLimits) -> Vec<Segment> {
    let mut out = Vec::with_capacity(5);
    if v1 >= v_zero(v0, a0, l) {
        let (k, rhs) = (l.k_acc(), v1 - v0 + l.gu(a0));
        let peak = if rhs >= l.amax * l.amax * k {
            l.amax
        } else {
            (rhs / k).sqrt().max(a0).max(0.0)
        };
        push_up(&mut out, a0, peak, l);
        push_hold(&mut out, peak, (rhs - peak * peak * k) / l.amax);
        push_down(&mut out, peak, 0.0, l);
    } else {
        let (k, rhs) = (l.k_dec(), l.gd(a0) - (v1 - v0));
        let valley = if rhs >= l.dmax * l.dmax * k {
            -l.dmax
        } else {
            -(rhs / k).sqrt().max(-a0).max(0.0)
        };
        push_down(&mut out, a0, valley, l);
        push_hold(&mut out, valley, (rhs - valley * valley * k) / l.dmax);
        push_up(&mut out, valley, 0.0, l);
    }
    out
}

/// End state after `segs` from `s`.
pub(crate) fn run(s: State, segs: &[Segment]) -> State {
    segs.iter().fold(s, |st, seg| seg.end_state(&st))
}

/// Mirror segments (negate jerks and held accelerations).
pub(crate) fn mirror(segs: &mut [Segment]) {
    for s in segs {
        *s = match *s {
            Segment::Jerk { duration_s, jerk } => Segment::Jerk {
                duration_s,
                jerk: -jerk,
            },
            Segment::Accel { duration_s, accel } => Segment::Accel {
                duration_s,
                accel: -accel,
            },
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lim() -> FourJerkLimits {
        FourJerkLimits {
            vmax: 10.0,
            amax: 2.0,
            dmax: 3.0,
            jerk: [10.0, 20.0, 30.0, 40.0],
        }
    }

    #[test]
    fn change_to_zero_reaches_the_velocity() {
        let l = lim();
        for &(v0, a0, v1) in &[
            (0.0, 0.0, 1.0),
            (0.0, 1.5, 0.1),
            (1.0, -2.5, -1.0),
            (0.0, 0.0, 0.01),
            (0.3, 1.0, 0.3),
            (0.0, -1.0, 5.0),
            (5.0, 2.0, -5.0),
        ] {
            let segs = change_to_zero(v0, a0, v1, &l);
            let e = run(
                State {
                    p: 0.0,
                    v: v0,
                    a: a0,
                },
                &segs,
            );
            assert!(
                (e.v - v1).abs() < 1e-12 && e.a.abs() < 1e-12,
                "{v0} {a0} {v1}: {e:?}"
            );
        }
    }

    #[test]
    fn arc_velocity_gain_is_the_g_difference() {
        let l = lim();
        for &(x, y) in &[(-2.0, 1.5), (0.5, 2.0), (-3.0, -1.0)] {
            let mut s = Vec::new();
            push_up(&mut s, x, y, &l);
            let e = run(
                State {
                    p: 0.0,
                    v: 0.0,
                    a: x,
                },
                &s,
            );
            assert!((e.v - (l.gu(y) - l.gu(x))).abs() < 1e-12 && (e.a - y).abs() < 1e-12);
            let mut s = Vec::new();
            push_down(&mut s, y, x, &l);
            let e = run(
                State {
                    p: 0.0,
                    v: 0.0,
                    a: y,
                },
                &s,
            );
            assert!((e.v - (l.gd(y) - l.gd(x))).abs() < 1e-12 && (e.a - x).abs() < 1e-12);
        }
    }
}
