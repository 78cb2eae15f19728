//! The jerk-limited corner blend.
//!
//! Instead of stopping at the corner `p1` of `p0 -> p1 -> p2`, the toolhead leaves the first
//! segment a distance `d` before `p1` at speed `s` and joins the second segment `d` after
//! it at the same speed `s`. In between, the acceleration points only along
//! `e_n = (u_out - u_in)/|u_out - u_in|` (the interior bisector, into the corner's inside;
//! perpendicular to the mean travel direction `u_in + u_out`), so the velocity component
//! along the mean direction stays `s sin(theta/2)` and the component along `e_n` goes from
//! `-s cos(theta/2)` to `+s cos(theta/2)`: a velocity change `dv = 2 s cos(theta/2)`
//! (`theta`: interior angle, see [`crate::path`]). The speed dips to `s sin(theta/2)` in
//! the middle and is `s` at both ends.
//!
//! The along-`e_n` acceleration is the fastest jerk-limited change of `dv` with zero
//! acceleration at both ends, lasting `T`. Travel along the mean direction at constant
//! speed gives `2 d sin(theta/2) = s sin(theta/2) T`, i.e. `d = s T / 2` for every angle, so
//! the minimal `d` is the minimal `T`:
//! - **triangle** (`dv jlimit <= alimit^2`, peak `jlimit T/2 <= alimit`):
//!   `T = 2 sqrt(dv/jlimit)`, `d = s sqrt(2 s cos(theta/2) / jlimit)`;
//! - **trapezoid** (otherwise): `T = dv/alimit + alimit/jlimit`,
//!   `d = s^2 cos(theta/2)/alimit + 0.5 s alimit/jlimit`;
//! - without a jerk limit (`jlimit = inf`, trapezoid profiles): `T = dv/alimit`,
//!   `d = s^2 cos(theta/2)/alimit`.
//!
//! The blend is symmetric about its middle, which is its closest point to the corner; the
//! **deviation** from the sharp corner is `delta = integral_0^{T/2} w'(t) dt`, where `w'` is
//! the velocity gained along `e_n` (the `d sin(theta/2)` the entry point lies inside the
//! corner cancels against the travel `s cos(theta/2) T/2` towards it):
//! triangle `delta = jlimit (T/2)^3 / 6 = dv T / 12`; trapezoid with `tr = alimit/jlimit`,
//! `h = T/2 - tr`: `delta = jlimit tr^3/6 + (alimit tr/2) h + alimit h^2/2`; no jerk limit:
//! `delta = alimit T^2/8`.
//!
//! Limits of the convention: `theta = pi` (straight) needs no blend (`d = 0`);
//! `theta = 0` (reversal) degenerates to a one-dimensional stop and return along the line:
//! the mean-direction speed is zero and the entry and exit points coincide.

use super::vector::{V3, axpy, norm, scale, sub};
use crate::Segment;

/// Which acceleration shape the blend has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlendCase {
    /// No direction change (`theta = pi`) or zero speed: no blend.
    Straight,
    /// The acceleration along `e_n` is a triangle (peak below `alimit`).
    Triangle,
    /// The acceleration along `e_n` is a trapezoid (holds `alimit`).
    Trapezoid,
    /// No jerk limit: the acceleration steps to `alimit` and back.
    AccelStep,
}

/// The minimal blend for one speed and angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlendShape {
    /// Which case applies.
    pub case: BlendCase,
    /// Corner speed `s` (m/s) at entry and exit.
    pub speed: f64,
    /// Distance `d` (m) from the corner at which the blend leaves the first segment and
    /// joins the second.
    pub distance_m: f64,
    /// Duration `T` (s).
    pub duration_s: f64,
    /// Velocity change along `e_n`, `2 s cos(theta/2)` (m/s).
    pub dv: f64,
    /// Peak acceleration (m/s^2).
    pub peak_accel: f64,
    /// Distance from the sharp corner to the blend's closest point (its middle), m.
    pub deviation_m: f64,
}

/// Triangle case: `d = s sqrt(2 s cos(theta/2) / jlimit)`.
pub fn distance_triangle(s: f64, theta: f64, jlimit: f64) -> f64 {
    s * (2.0 * s * (0.5 * theta).cos() / jlimit).sqrt()
}

/// Trapezoid case: `d = s^2 cos(theta/2)/alimit + 0.5 s alimit/jlimit`.
pub fn distance_trapezoid(s: f64, theta: f64, alimit: f64, jlimit: f64) -> f64 {
    s * s * (0.5 * theta).cos() / alimit + 0.5 * s * alimit / jlimit
}

/// The minimal blend at speed `s` (m/s) and interior angle `theta` (rad) under
/// `alimit` (m/s^2) and `jlimit` (m/s^3; `f64::INFINITY` for no jerk limit).
pub fn shape(s: f64, theta: f64, alimit: f64, jlimit: f64) -> BlendShape {
    // Exactly zero for a straight line (cos(pi/2) rounds to 6e-17).
    let cos_half = if theta >= std::f64::consts::PI {
        0.0
    } else {
        (0.5 * theta.max(0.0)).cos()
    };
    shape_from_dv(s, 2.0 * s * cos_half, alimit, jlimit)
}

/// [`shape`] from the velocity change `dv = 2 s cos(theta/2)` directly.
pub(crate) fn shape_from_dv(s: f64, dv: f64, alimit: f64, jlimit: f64) -> BlendShape {
    let (case, t, peak, dev) = if dv <= 0.0 || s <= 0.0 {
        (BlendCase::Straight, 0.0, 0.0, 0.0)
    } else if jlimit.is_infinite() {
        let t = dv / alimit;
        (BlendCase::AccelStep, t, alimit, alimit * t * t / 8.0)
    } else if dv * jlimit <= alimit * alimit {
        let t = 2.0 * (dv / jlimit).sqrt();
        let half = 0.5 * t;
        (
            BlendCase::Triangle,
            t,
            jlimit * half,
            jlimit * half * half * half / 6.0,
        )
    } else {
        let tr = alimit / jlimit;
        let t = dv / alimit + tr;
        let h = 0.5 * t - tr;
        let dev = jlimit * tr * tr * tr / 6.0 + 0.5 * alimit * tr * h + 0.5 * alimit * h * h;
        (BlendCase::Trapezoid, t, alimit, dev)
    };
    BlendShape {
        case,
        speed: s,
        distance_m: 0.5 * s * t,
        duration_s: t,
        dv: if case == BlendCase::Straight { 0.0 } else { dv },
        peak_accel: peak,
        deviation_m: dev,
    }
}

impl BlendShape {
    /// The acceleration along `e_n` as profile segments, starting from zero acceleration
    /// and ending at zero acceleration (jerk segments; acceleration steps without a jerk
    /// limit).
    pub fn normal_segments(&self, jlimit: f64) -> Vec<Segment> {
        let t = self.duration_s;
        match self.case {
            BlendCase::Straight => Vec::new(),
            BlendCase::Triangle => vec![
                Segment::Jerk {
                    duration_s: 0.5 * t,
                    jerk: jlimit,
                },
                Segment::Jerk {
                    duration_s: 0.5 * t,
                    jerk: -jlimit,
                },
            ],
            BlendCase::Trapezoid => {
                let tr = self.peak_accel / jlimit;
                vec![
                    Segment::Jerk {
                        duration_s: tr,
                        jerk: jlimit,
                    },
                    Segment::Jerk {
                        duration_s: (t - 2.0 * tr).max(0.0),
                        jerk: 0.0,
                    },
                    Segment::Jerk {
                        duration_s: tr,
                        jerk: -jlimit,
                    },
                ]
            }
            BlendCase::AccelStep => vec![
                Segment::Accel {
                    duration_s: t,
                    accel: self.peak_accel,
                },
                Segment::Accel {
                    duration_s: 0.0,
                    accel: 0.0,
                },
            ],
        }
    }
}

/// The largest speed `<= vmax` whose blend deviates at most `max_deviation_m` from the
/// corner and needs at most `max_distance_m` of each segment (both grow with the speed),
/// by bisection.
pub fn max_speed(
    theta: f64,
    alimit: f64,
    jlimit: f64,
    max_deviation_m: f64,
    max_distance_m: f64,
    vmax: f64,
) -> f64 {
    let ok = |s: f64| {
        let b = shape(s, theta, alimit, jlimit);
        b.deviation_m <= max_deviation_m && b.distance_m <= max_distance_m
    };
    if ok(vmax) {
        return vmax;
    }
    let (mut lo, mut hi) = (0.0, vmax);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if ok(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// A blend placed at a corner: the corner point, the travel directions and the shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Blend {
    /// The sharp corner (m).
    pub corner: V3,
    /// Unit direction of the incoming segment.
    pub u_in: V3,
    /// Unit direction of the outgoing segment.
    pub u_out: V3,
    /// Unit direction of the acceleration (into the corner's inside); zero when straight.
    pub e_n: V3,
    /// The shape (speed, distance, duration, deviation).
    pub shape: BlendShape,
}

impl Blend {
    /// The minimal blend at `corner` between unit directions `u_in` and `u_out` at speed
    /// `s`.
    pub fn new(corner: V3, u_in: V3, u_out: V3, s: f64, alimit: f64, jlimit: f64) -> Self {
        let chord = sub(u_out, u_in);
        let c = norm(chord);
        let e_n = if c > 0.0 {
            scale(chord, 1.0 / c)
        } else {
            [0.0; 3]
        };
        // |u_out - u_in| = 2 cos(theta/2), so dv = s |u_out - u_in|.
        let shape = shape_from_dv(s, s * c, alimit, jlimit);
        Self {
            corner,
            u_in,
            u_out,
            e_n,
            shape,
        }
    }

    /// Where the blend leaves the incoming segment: `corner - d u_in`.
    pub fn entry(&self) -> V3 {
        axpy(self.corner, -self.shape.distance_m, self.u_in)
    }

    /// Where the blend joins the outgoing segment: `corner + d u_out`.
    pub fn exit(&self) -> V3 {
        axpy(self.corner, self.shape.distance_m, self.u_out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn cases_agree_with_the_closed_forms() {
        let (a, j) = (2.0, 50.0);
        for s in [0.01, 0.05, 0.2, 1.0] {
            for deg in [1.0_f64, 30.0, 90.0, 150.0, 179.0] {
                let th = deg.to_radians();
                let b = shape(s, th, a, j);
                let want = match b.case {
                    BlendCase::Triangle => distance_triangle(s, th, j),
                    BlendCase::Trapezoid => distance_trapezoid(s, th, a, j),
                    other => panic!("unexpected {other:?}"),
                };
                assert!((b.distance_m - want).abs() <= 1e-14 * want, "{s} {deg}");
                assert!(b.peak_accel <= a * (1.0 + 1e-15));
            }
        }
        // The two formulas meet where the triangle's peak reaches alimit: dv = a^2/j.
        let dv: f64 = a * a / j;
        let s: f64 = 0.1;
        let th = 2.0 * (dv / (2.0 * s)).acos();
        let (d1, d2) = (distance_triangle(s, th, j), distance_trapezoid(s, th, a, j));
        assert!((d1 - d2).abs() < 1e-15, "{d1} {d2}");
    }

    #[test]
    fn straight_and_reversal() {
        let b = shape(0.3, PI, 2.0, 50.0);
        assert_eq!(
            (b.case, b.distance_m, b.deviation_m),
            (BlendCase::Straight, 0.0, 0.0)
        );
        let b = shape(0.3, 0.0, 2.0, 50.0);
        assert_eq!(b.dv, 0.6);
        // Reversal, trapezoid case (dv j = 30 > 4): T = 0.6/2 + 2/50 = 0.34, d = 0.3*0.34/2.
        assert!((b.duration_s - 0.34).abs() < 1e-15 && (b.distance_m - 0.051).abs() < 1e-15);
        let blend = Blend::new([0.0; 3], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], 0.3, 2.0, 50.0);
        assert_eq!(blend.entry(), blend.exit());
        assert_eq!(blend.e_n, [-1.0, 0.0, 0.0]);
    }

    #[test]
    fn max_speed_inverts_the_deviation() {
        let th = 90.0_f64.to_radians();
        let s = max_speed(th, 3.0, 100.0, 1e-5, 1.0, 10.0);
        let b = shape(s, th, 3.0, 100.0);
        assert!((b.deviation_m - 1e-5).abs() < 1e-15, "{}", b.deviation_m);
        let s = max_speed(th, 3.0, 100.0, 1.0, 1e-3, 10.0);
        assert!((shape(s, th, 3.0, 100.0).distance_m - 1e-3).abs() < 1e-15);
        assert_eq!(max_speed(PI, 3.0, 100.0, 0.0, 0.0, 10.0), 10.0);
    }
}
