//! The planned motion as pieces of vector segments (straight runs, blends, velocity jumps),
//! and their conversion to one [`Profile`] per axis.
//!
//! Every piece starts and ends with zero acceleration (a velocity jump resets it), so the
//! per-axis profiles are the pieces' segments side by side. All axes share every segment
//! boundary; on a straight run each axis is the path coordinate times the direction
//! component, which keeps the motion on the line (every axis breaks where the path does).

use super::vector::{V3, add, axpy, scale};
use crate::{PlanError, Profile, Segment, State};

/// One vector segment: constant jerk, or a constant acceleration set at its start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum VSeg {
    /// Constant jerk vector (m/s^3) for `duration_s`.
    Jerk { duration_s: f64, jerk: V3 },
    /// Constant acceleration vector (m/s^2) for `duration_s`, set at the start.
    Accel { duration_s: f64, accel: V3 },
}

impl VSeg {
    pub(crate) fn duration_s(&self) -> f64 {
        match *self {
            VSeg::Jerk { duration_s, .. } | VSeg::Accel { duration_s, .. } => duration_s,
        }
    }

    /// The scalar segment of one axis.
    fn axis(&self, i: usize) -> Segment {
        match *self {
            VSeg::Jerk { duration_s, jerk } => Segment::Jerk {
                duration_s,
                jerk: jerk[i],
            },
            VSeg::Accel { duration_s, accel } => Segment::Accel {
                duration_s,
                accel: accel[i],
            },
        }
    }

    /// A scalar segment along direction `u`.
    pub(crate) fn along(seg: &Segment, u: V3) -> Self {
        match *seg {
            Segment::Jerk { duration_s, jerk } => VSeg::Jerk {
                duration_s,
                jerk: scale(u, jerk),
            },
            Segment::Accel { duration_s, accel } => VSeg::Accel {
                duration_s,
                accel: scale(u, accel),
            },
        }
    }

    /// Acceleration at the start (given the acceleration before) and the jerk.
    pub(crate) fn accel_and_jerk(&self, a_before: V3) -> (V3, V3) {
        match *self {
            VSeg::Jerk { jerk, .. } => (a_before, jerk),
            VSeg::Accel { accel, .. } => (accel, [0.0; 3]),
        }
    }
}

/// A vector kinematic state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct VState {
    pub p: V3,
    pub v: V3,
    pub a: V3,
}

impl VState {
    /// The state `tau` into `seg` from this state.
    pub(crate) fn advance(&self, seg: &VSeg, tau: f64) -> VState {
        let (a0, j) = seg.accel_and_jerk(self.a);
        let p = add(
            axpy(axpy(self.p, tau, self.v), 0.5 * tau * tau, a0),
            scale(j, tau * tau * tau / 6.0),
        );
        let v = axpy(axpy(self.v, tau, a0), 0.5 * tau * tau, j);
        VState {
            p,
            v,
            a: axpy(a0, tau, j),
        }
    }
}

/// A piece of the plan (a straight run, a blend or a velocity jump): its start state and
/// segments.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Piece {
    pub start: VState,
    pub segs: Vec<VSeg>,
}

impl Piece {
    pub(crate) fn duration_s(&self) -> f64 {
        self.segs.iter().map(VSeg::duration_s).sum()
    }
}

/// One profile per axis (`dim` axes) from the pieces, starting at rest at `start`.
pub(crate) fn profiles(dim: usize, start: V3, pieces: &[Piece]) -> Result<Vec<Profile>, PlanError> {
    let at_rest = VState {
        p: start,
        v: [0.0; 3],
        a: [0.0; 3],
    };
    profiles_from(dim, at_rest, pieces)
}

/// One profile per axis (`dim` axes) from the pieces, starting at the position and
/// velocity of `start` (with zero acceleration, as every piece starts).
pub(crate) fn profiles_from(
    dim: usize,
    start: VState,
    pieces: &[Piece],
) -> Result<Vec<Profile>, PlanError> {
    (0..dim)
        .map(|i| {
            let s0 = State {
                p: start.p[i],
                v: start.v[i],
                a: 0.0,
            };
            let mut segs = Vec::new();
            let mut st = s0;
            for (n, piece) in pieces.iter().enumerate() {
                // Pieces start with zero acceleration; rounding may leave a trace of the
                // last one: reset it (on every axis alike, so all axes keep the same
                // segment boundaries) so it cannot integrate into position drift.
                if n > 0 && matches!(piece.segs.first(), Some(VSeg::Jerk { .. })) {
                    let reset = Segment::Accel {
                        duration_s: 0.0,
                        accel: 0.0,
                    };
                    st = reset.end_state(&st);
                    segs.push(reset);
                }
                for vs in &piece.segs {
                    let seg = vs.axis(i);
                    st = seg.end_state(&st);
                    segs.push(seg);
                }
            }
            Profile::new(s0, segs)
        })
        .collect()
}
