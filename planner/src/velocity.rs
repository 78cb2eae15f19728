//! Time-optimal velocity changes: the building block of the any-state planners and the
//! velocity interface (reach a velocity and acceleration; position free).
//!
//! From `(v0, a0)` to `(vf, af)` with jerk limited to `j` and acceleration to
//! `[amin, amax]`, the fastest change is one of two shapes:
//! - **up-down** (`UD`): jerk `+j` to a peak acceleration `A`, [hold at `amax`], jerk `-j` to
//!   `af`. The velocity gained is `(A^2 - a0^2)/(2j) + (A^2 - af^2)/(2j)`, so
//!   `A^2 = j dv + (a0^2 + af^2)/2`, with `A >= max(a0, af)`.
//! - **down-up** (`DU`): the mirror, with a valley `A^2 = (a0^2 + af^2)/2 - j dv`,
//!   `A <= min(a0, af)`, [hold at `amin`].
//!
//! Without a jerk limit (trapezoid variant) the acceleration jumps: one constant-
//! acceleration segment at `amax` or `amin`, then a jump to `af`.

use crate::Segment;

/// Up to three segments of a velocity change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Change {
    /// The segments (zero-duration ones are kept; callers drop them).
    pub segments: [Segment; 3],
}

/// A zero-length `Jerk` segment.
const NONE: Segment = Segment::Jerk {
    duration_s: 0.0,
    jerk: 0.0,
};

impl Change {
    /// Total duration (s).
    pub fn duration_s(&self) -> f64 {
        self.segments.iter().map(Segment::duration_s).sum()
    }

    /// Velocity and distance at the end, starting from `(v0, a0)` at position 0.
    pub fn end(&self, v0: f64, a0: f64) -> crate::State {
        let mut s = crate::State {
            p: 0.0,
            v: v0,
            a: a0,
        };
        for seg in &self.segments {
            s = seg.end_state(&s);
        }
        s
    }
}

/// Acceleration bounds and jerk for the velocity changes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Upper acceleration limit (> 0).
    pub amax: f64,
    /// Lower acceleration limit (< 0).
    pub amin: f64,
    /// Jerk limit (> 0), or infinity for the trapezoid variant.
    pub jmax: f64,
}

/// The time-optimal change from `(v0, a0)` to `(vf, af)`; `a0` and `af` must lie in
/// `[amin, amax]` (brake first otherwise). `None` only for non-finite input.
pub fn change(v0: f64, a0: f64, vf: f64, af: f64, b: &Bounds) -> Option<Change> {
    let mut best: Option<Change> = None;
    each_local_change(v0, a0, vf, af, b, |c| {
        if best.is_none_or(|x| c.duration_s() < x.duration_s()) {
            best = Some(c);
        }
    });
    best
}

/// Every locally fastest velocity change (up-down and down-up, each with its peak or
/// valley of either sign): the fastest is [`change`]; the others start the ranges of
/// longer durations that velocity-interface synchronisation can use.
pub fn local_changes(v0: f64, a0: f64, vf: f64, af: f64, b: &Bounds) -> Vec<Change> {
    let mut all = Vec::with_capacity(4);
    each_local_change(v0, a0, vf, af, b, |c| all.push(c));
    all
}

/// Calls `f` with every locally fastest velocity change (see [`local_changes`]), in a fixed
/// order, without allocating.
pub(crate) fn each_local_change(
    v0: f64,
    a0: f64,
    vf: f64,
    af: f64,
    b: &Bounds,
    mut f: impl FnMut(Change),
) {
    if b.jmax.is_infinite() {
        f(trapezoid_change(v0, vf, af, b));
        return;
    }
    let j = b.jmax;
    let dv = vf - v0;
    let scale = a0.abs().max(af.abs()).max(b.amax).max(-b.amin);
    let eps = 1e-12 * scale;
    let mut consider = |c: Change| {
        if c.segments.iter().all(|s| s.duration_s() >= 0.0) {
            f(c);
        }
    };
    // Up-down.
    let s_ud = j * dv + 0.5 * (a0 * a0 + af * af);
    if s_ud >= 0.0 {
        for peak in [-s_ud.sqrt(), s_ud.sqrt()] {
            if peak < a0.max(af) - eps {
                continue;
            }
            let peak = peak.max(a0).max(af);
            if peak <= b.amax {
                consider(three(j, (peak - a0) / j, 0.0, (peak - af) / j));
            } else {
                let t1 = (b.amax - a0) / j;
                let t3 = (b.amax - af) / j;
                let hold = (dv
                    - (b.amax * b.amax - a0 * a0) / (2.0 * j)
                    - (b.amax * b.amax - af * af) / (2.0 * j))
                    / b.amax;
                consider(three(j, t1, hold.max(0.0), t3));
            }
        }
    }
    // Down-up.
    let s_du = 0.5 * (a0 * a0 + af * af) - j * dv;
    if s_du >= 0.0 {
        for valley in [s_du.sqrt(), -s_du.sqrt()] {
            if valley > a0.min(af) + eps {
                continue;
            }
            let valley = valley.min(a0).min(af);
            if valley >= b.amin {
                consider(three(-j, (a0 - valley) / j, 0.0, (af - valley) / j));
            } else {
                let t1 = (a0 - b.amin) / j;
                let t3 = (af - b.amin) / j;
                let hold = (dv
                    - (a0 * a0 - b.amin * b.amin) / (2.0 * j)
                    - (af * af - b.amin * b.amin) / (2.0 * j))
                    / b.amin;
                consider(three(-j, t1, hold.max(0.0), t3));
            }
        }
    }
}

/// Jerk `j1` for `t1`, hold (zero jerk) for `hold`, jerk `-j1` for `t3`.
fn three(j1: f64, t1: f64, hold: f64, t3: f64) -> Change {
    Change {
        segments: [
            Segment::Jerk {
                duration_s: t1.max(0.0),
                jerk: j1,
            },
            if hold > 0.0 {
                // The acceleration is already on the limit: hold it with zero jerk.
                Segment::Jerk {
                    duration_s: hold,
                    jerk: 0.0,
                }
            } else {
                NONE
            },
            Segment::Jerk {
                duration_s: t3.max(0.0),
                jerk: -j1,
            },
        ],
    }
}

/// Jerk-unlimited: hold `amax` or `amin` until `vf`, then jump to `af`.
fn trapezoid_change(v0: f64, vf: f64, af: f64, b: &Bounds) -> Change {
    let dv = vf - v0;
    let a = if dv >= 0.0 { b.amax } else { b.amin };
    Change {
        segments: [
            Segment::Accel {
                duration_s: if dv == 0.0 { 0.0 } else { dv / a },
                accel: a,
            },
            Segment::Accel {
                duration_s: 0.0,
                accel: af,
            },
            NONE,
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const B: Bounds = Bounds {
        amax: 2.0,
        amin: -3.0,
        jmax: 10.0,
    };

    #[test]
    fn reaches_the_target_velocity_and_acceleration() {
        for &(v0, a0, vf, af) in &[
            (0.0, 0.0, 1.0, 0.0),
            (0.0, 1.5, 0.1, 0.0),
            (1.0, -2.5, -1.0, 1.0),
            (0.0, 0.0, 0.01, 0.0),
            (0.3, 1.0, 0.3, 1.0),
            (0.0, -1.0, 5.0, -2.0),
        ] {
            let c = change(v0, a0, vf, af, &B).expect("change");
            let e = c.end(v0, a0);
            assert!(
                (e.v - vf).abs() < 1e-12 && (e.a - af).abs() < 1e-12,
                "{c:?} -> {e:?}"
            );
        }
    }

    #[test]
    fn known_value_rest_to_speed_with_hold() {
        // 0 -> 1 m/s at amax 2, jerk 10: ramps of 0.2 s give 0.4 m/s, hold 0.3 s at 2 m/s^2.
        let c = change(0.0, 0.0, 1.0, 0.0, &B).expect("change");
        assert!((c.duration_s() - 0.7).abs() < 1e-12);
        match c.segments[1] {
            Segment::Jerk { duration_s, jerk } => {
                assert!((duration_s - 0.3).abs() < 1e-12 && jerk == 0.0)
            }
            other => panic!("expected a hold, got {other:?}"),
        }
    }
}
