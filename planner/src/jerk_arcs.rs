//! Profiles of jerk arcs in normalised units (jerk 1), shared by the three-arc cases (UDU,
//! DUD: `udu`) and the four-arc cases (UDUD, DUDU: `udud`) of step 1: the profile type
//! [`Arcs`], the [`Sink`] the case searches offer their valid roots to, and the check
//! that a root really reaches the target ([`reaches`]).

use crate::unit::Unit;

/// A profile of jerk arcs in normalised units, in the frame where it starts with jerk
/// `+1`; `sign = -1` marks one found on the mirrored problem. Three arcs (UDU): jerk `+1`
/// for `t[0]`, hold at `amax` for `t[1]`, jerk `-1` for `t[2]`, hold at `amin` for `t[3]`,
/// jerk `+1` for `t[4]` (`t[5] = 0`). Four arcs (UDUD, see `udud`): jerk `+1`, hold at
/// `amax`, jerk `-1` down to zero acceleration, jerk `+1`, hold at `amax`, jerk `-1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Arcs {
    /// `1` as found, `-1` mirrored.
    pub sign: f64,
    /// Four arcs rather than three.
    pub four: bool,
    /// Phase durations (normalised time).
    pub t: [f64; 6],
}

impl Arcs {
    /// Duration (normalised time).
    pub(crate) fn duration(&self) -> f64 {
        self.t.iter().sum()
    }

    /// The jerk of each phase (normalised, in the frame of the search).
    pub(crate) fn jerks(&self) -> [f64; 6] {
        if self.four {
            [1.0, 0.0, -1.0, 1.0, 0.0, -1.0]
        } else {
            [1.0, 0.0, -1.0, 0.0, 1.0, 0.0]
        }
    }

    /// Distance covered from the start of `u` (normalised), `u` being the problem in the
    /// original frame (the mirrored one for `sign = -1` is undone here).
    pub(crate) fn end_p(&self, u: &Unit) -> f64 {
        let (mut p, mut v, mut acc) = (0.0, self.sign * u.v0, self.sign * u.a0);
        for (t, j) in self.t.iter().zip(self.jerks()) {
            p += t * (v + t * (0.5 * acc + t * j * (1.0 / 6.0)));
            v += t * (acc + t * j / 2.0);
            acc += t * j;
        }
        self.sign * p
    }
}

/// Receives valid profiles.
pub(crate) trait Sink {
    /// Only profiles shorter than this are wanted (normalised time).
    fn t_max(&self) -> f64;
    /// Take a profile. Returns true if slower roots of the same case are not wanted.
    fn offer_arcs(&mut self, arcs: Arcs) -> bool;
}

/// Does `arcs` reach the target position of `u` (the frame it was found in)? A guard
/// against spurious roots (such as `s = 0` of `none`, a factor of its quartic), relative
/// to the size of the terms that make up the position, so it also holds for tiny moves.
pub(crate) fn reaches(u: &Unit, arcs: &Arcs) -> bool {
    let p = arcs.end_p(&u_frame(u, arcs.sign));
    let t = arcs.duration();
    let scale = u.dp.abs() + t * (u.v0.abs() + t * (0.5 * u.a0.abs() + t / 6.0));
    (p - arcs.sign * u.dp).abs() <= 1e-8 * scale
}

/// The problem in the original frame, given the (possibly mirrored) frame `u` of a family.
fn u_frame(u: &Unit, sign: f64) -> Unit {
    if sign > 0.0 { *u } else { u.mirror() }
}
