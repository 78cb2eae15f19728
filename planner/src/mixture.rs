//! Mixing two profiles of equal duration from one start state: the jerk (or, where both
//! hold a constant acceleration, the acceleration) of the result is `lambda` times the
//! first's plus `1 - lambda` times the second's, on the union of their breakpoints. The
//! result's state is the same mixture of the two states at every instant, so it lies
//! within any limits both respect (the limits are linear constraints), and it ends at the
//! mixture of their end states.

use crate::Segment;
use crate::segs::Push;

/// `lambda x + (1 - lambda) y` for profiles `x`, `y` starting with acceleration `a0` and
/// lasting the same time (up to rounding).
pub(crate) fn mix(x: &[Segment], y: &[Segment], a0: f64, lambda: f64, out: &mut impl Push) {
    let mu = 1.0 - lambda;
    // Per profile: the current segment, the time left in it, its jerk, whether it holds a
    // set acceleration, and the acceleration now.
    struct Cur<'a> {
        segs: &'a [Segment],
        i: usize,
        left: f64,
        j: f64,
        held: bool,
        a: f64,
    }
    impl Cur<'_> {
        /// Move to the next segment with time left (an acceleration segment sets the
        /// acceleration as it is passed); past the end, hold the final acceleration.
        fn next(&mut self) {
            while self.i < self.segs.len() {
                let seg = self.segs[self.i];
                self.i += 1;
                match seg {
                    Segment::Jerk { duration_s, jerk } => {
                        (self.left, self.j, self.held) = (duration_s, jerk, false);
                    }
                    Segment::Accel { duration_s, accel } => {
                        (self.left, self.j, self.held, self.a) = (duration_s, 0.0, true, accel);
                    }
                }
                if self.left > 0.0 {
                    return;
                }
            }
            (self.left, self.j, self.held) = (f64::INFINITY, 0.0, true);
        }
    }
    let start = |segs| {
        let mut c = Cur {
            segs,
            i: 0,
            left: 0.0,
            j: 0.0,
            held: true,
            a: a0,
        };
        c.next();
        c
    };
    let (mut cx, mut cy) = (start(x), start(y));
    let mut a_out = a0;
    loop {
        let d = cx.left.min(cy.left);
        if d == f64::INFINITY {
            break;
        }
        if cx.held && cy.held {
            // Both hold (or jump to) a set acceleration: hold the mixture exactly.
            a_out = lambda * cx.a + mu * cy.a;
            out.push_seg(Segment::Accel {
                duration_s: d,
                accel: a_out,
            });
        } else {
            let jerk = lambda * cx.j + mu * cy.j;
            out.push_seg(Segment::Jerk {
                duration_s: d,
                jerk,
            });
            a_out += jerk * d;
        }
        for c in [&mut cx, &mut cy] {
            c.a += c.j * d;
            c.left -= d;
            if c.left <= 0.0 {
                c.next();
            }
        }
    }
    let a_end = lambda * cx.a + mu * cy.a;
    if a_end != a_out && matches!(x.last(), Some(Segment::Accel { .. })) {
        // Trapezoids end with a jump to the target acceleration.
        out.push_seg(Segment::Accel {
            duration_s: 0.0,
            accel: a_end,
        });
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
        let mut out = Segs::<16>::default();
        mix(&x, &y, start.a, 0.25, &mut out);
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
