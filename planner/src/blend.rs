//! Mixing two profiles of equal duration from one start state: the jerk (or, where both
//! hold a constant acceleration, the acceleration) of the result is `lambda` times the
//! first's plus `1 - lambda` times the second's, on the union of their breakpoints. The
//! result's state is the same mixture of the two states at every instant, so it lies
//! within any limits both respect (the limits are linear constraints), and it ends at the
//! mixture of their end states.

use crate::Segment;

/// A cursor over one profile's segments: the current segment, the time left in it, and
/// the acceleration the profile has now.
struct Cursor<'a> {
    segs: &'a [Segment],
    i: usize,
    left: f64,
    a: f64,
}

impl<'a> Cursor<'a> {
    fn new(segs: &'a [Segment], a0: f64) -> Self {
        let mut c = Self {
            segs,
            i: 0,
            left: 0.0,
            a: a0,
        };
        c.enter();
        c
    }

    /// Start segment `i`: an acceleration segment sets the acceleration.
    fn enter(&mut self) {
        if let Some(seg) = self.segs.get(self.i) {
            self.left = seg.duration_s();
            if let Segment::Accel { accel, .. } = *seg {
                self.a = accel;
            }
        }
    }

    /// Skip segments with no time left. Returns true if the profile is exhausted.
    fn settle(&mut self) -> bool {
        while self.i < self.segs.len() && self.left <= 0.0 {
            self.i += 1;
            self.enter();
        }
        self.i >= self.segs.len()
    }

    /// Jerk now, and whether the acceleration is held at a set value.
    fn now(&self) -> (f64, bool) {
        match self.segs.get(self.i) {
            Some(Segment::Jerk { jerk, .. }) => (*jerk, false),
            // Past the end: hold the final acceleration.
            Some(Segment::Accel { .. }) | None => (0.0, true),
        }
    }

    fn advance(&mut self, d: f64) {
        let (j, _) = self.now();
        self.a += j * d;
        self.left -= d;
    }
}

/// `lambda x + (1 - lambda) y` for profiles `x`, `y` starting with acceleration `a0` and
/// lasting the same time (up to rounding).
pub(crate) fn blend(
    x: &[Segment],
    y: &[Segment],
    a0: f64,
    lambda: f64,
    out: &mut impl Extend<Segment>,
) {
    let mu = 1.0 - lambda;
    let (mut cx, mut cy) = (Cursor::new(x, a0), Cursor::new(y, a0));
    let mut a_out = a0;
    loop {
        let (ex, ey) = (cx.settle(), cy.settle());
        if ex && ey {
            break;
        }
        let d = match (ex, ey) {
            (false, false) => cx.left.min(cy.left),
            (false, true) => cx.left,
            _ => cy.left,
        };
        let ((jx, hx), (jy, hy)) = (cx.now(), cy.now());
        let a_mix = lambda * cx.a + mu * cy.a;
        if hx && hy {
            // Both hold (or jump to) a set acceleration: hold the mixture exactly.
            out.extend([Segment::Accel {
                duration_s: d,
                accel: a_mix,
            }]);
            a_out = a_mix;
        } else {
            out.extend([Segment::Jerk {
                duration_s: d,
                jerk: lambda * jx + mu * jy,
            }]);
            a_out += (lambda * jx + mu * jy) * d;
        }
        cx.advance(d);
        cy.advance(d);
    }
    let a_end = lambda * cx.a + mu * cy.a;
    if a_end != a_out && matches!(x.last(), Some(Segment::Accel { .. })) {
        // Trapezoids end with a jump to the target acceleration.
        out.extend([Segment::Accel {
            duration_s: 0.0,
            accel: a_end,
        }]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segs::Segs;
    use crate::{Profile, State};

    #[test]
    fn the_mixture_ends_at_the_mixed_end_state() {
        let start = State {
            p: 0.0,
            v: 0.5,
            a: 0.2,
        };
        let x = [
            Segment::Jerk {
                duration_s: 0.3,
                jerk: 2.0,
            },
            Segment::Accel {
                duration_s: 0.4,
                accel: 0.8,
            },
            Segment::Jerk {
                duration_s: 0.5,
                jerk: -2.0,
            },
        ];
        let y = [
            Segment::Jerk {
                duration_s: 0.7,
                jerk: -1.0,
            },
            Segment::Jerk {
                duration_s: 0.5,
                jerk: 1.0,
            },
        ];
        let mut out = Segs::default();
        blend(&x, &y, start.a, 0.25, &mut out);
        let (px, py, pm) = (
            Profile::new(start, x.to_vec()).expect("x").end(),
            Profile::new(start, y.to_vec()).expect("y").end(),
            Profile::new(start, out.as_slice().to_vec())
                .expect("mix")
                .end(),
        );
        for (m, (a, b)) in [pm.p, pm.v, pm.a]
            .iter()
            .zip([(px.p, py.p), (px.v, py.v), (px.a, py.a)])
        {
            assert!(
                (m - (0.25 * a + 0.75 * b)).abs() < 1e-12,
                "{pm:?} {px:?} {py:?}"
            );
        }
        assert!((out.duration_s() - 1.2).abs() < 1e-12);
    }
}
