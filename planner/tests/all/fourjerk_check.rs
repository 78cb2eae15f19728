//! A strict, planner-independent feasibility check for four-jerk profiles, shared by the
//! four-jerk tests (and applied to the oracle's own candidates).
//!
//! Rules, in the axis frame:
//! - every jerk is 0 or the bound for its direction and the sign of the acceleration
//!   (`j1` raising `a >= 0`, `j2` lowering `a > 0`, `j3` lowering `a <= 0`, `j4` raising
//!   `a < 0`), or a hold of constant acceleration;
//! - an acceleration outside `[-dmax, amax]` only at the start, moving towards the limit;
//!   once inside it stays inside;
//! - a start that is unsafe (velocity outside, or the velocity after ramping the
//!   acceleration to zero at once outside) may only brake: lower the acceleration at full
//!   jerk or hold `-dmax` (mirrored for a negative overshoot) until the velocity after
//!   ramping the acceleration to zero is back inside; after the first segment that
//!   is not braking, a velocity outside the band must move strictly monotonically towards
//!   it (no cruise out there) and,
//!   once inside, stay inside. Velocities are checked on the monotone pieces of each
//!   segment, so they cannot slip through the band between segment ends.

#![allow(dead_code)]

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Gamma, Normal};
use settle_planner::fourjerk::FourJerkLimits;
use settle_planner::{Profile, Segment, State};

/// Relative tolerance of every comparison.
pub const TOL: f64 = 1e-9;

/// The velocity after bringing `a` to zero at full jerk.
pub fn v_zero(s: &State, l: &FourJerkLimits) -> f64 {
    if s.a >= 0.0 {
        s.v + s.a * s.a / (2.0 * l.jerk[1])
    } else {
        s.v - s.a * s.a / (2.0 * l.jerk[3])
    }
}

/// `Err(description)` at the first violated rule.
pub fn check(start: State, segs: &[Segment], l: &FourJerkLimits) -> Result<(), String> {
    let vl = l.vmax * (1.0 + TOL);
    let (amax, amin) = (l.amax * (1.0 + TOL), -l.dmax * (1.0 + TOL));
    let jt = |j: f64, want: f64| (j - want).abs() <= TOL * want;
    let mut s = start;
    let mut a_in = s.a <= amax && s.a >= amin;
    let vz0 = v_zero(&s, l);
    // +1: braking a positive overshoot, -1: a negative one, 0: not braking.
    // The overshoot to brake: where vz is heading, else the excess of v itself.
    let mut braking = if vz0 > vl {
        1.0
    } else if vz0 < -vl {
        -1.0
    } else if s.v > vl {
        1.0
    } else if s.v < -vl {
        -1.0
    } else {
        0.0
    };
    let mut inside = s.v.abs() <= vl;
    for (k, seg) in segs.iter().enumerate() {
        let (a0, j) = seg.accel_and_jerk(&s);
        let e = seg.end_state(&s);
        if seg.duration_s() == 0.0 {
            s = e;
            continue;
        }
        // Jerk values.
        let amid = 0.5 * (a0 + e.a);
        let ok_j = match seg {
            Segment::Accel { .. } => true,
            Segment::Jerk { .. } if j == 0.0 => true,
            Segment::Jerk { .. } if j > 0.0 => {
                jt(j, if amid >= 0.0 { l.jerk[0] } else { l.jerk[3] })
            }
            Segment::Jerk { .. } => jt(-j, if amid > 0.0 { l.jerk[1] } else { l.jerk[2] }),
        };
        if !ok_j {
            return Err(format!("segment {k}: jerk {j} at a = {amid}"));
        }
        if let Segment::Accel { accel, .. } = seg
            && (accel - s.a).abs() > TOL * l.amax.max(l.dmax)
        {
            return Err(format!(
                "segment {k}: acceleration jumps {} -> {accel}",
                s.a
            ));
        }
        // Acceleration.
        let a_was_in = a_in;
        if a_in {
            if a0 > amax || a0 < amin || e.a > amax || e.a < amin {
                return Err(format!("segment {k}: a leaves [{amin}, {amax}]"));
            }
        } else {
            let towards = (s.a > amax && j < 0.0) || (s.a < amin && j > 0.0);
            if !towards {
                return Err(format!("segment {k}: a = {} outside, not returning", s.a));
            }
            if e.a <= amax && e.a >= amin {
                a_in = true;
            }
        }
        // Braking prefix (bringing the acceleration back inside belongs to it).
        if braking != 0.0 {
            let floor = if braking > 0.0 { -l.dmax } else { l.amax };
            let brakes = !a_was_in
                || braking * j < 0.0
                || (j == 0.0 && (a0 - floor).abs() <= TOL * l.dmax.max(l.amax));
            if brakes {
                s = e;
                continue;
            }
            // Braking may only stop once the velocity after ramping the acceleration to
            // zero at once is back inside (the brake law: brake until that holds).
            let vz = v_zero(&s, l);
            if vz.abs() > vl {
                return Err(format!(
                    "segment {k}: stops braking with vz = {vz} beyond the limit"
                ));
            }
            braking = 0.0;
            inside = s.v.abs() <= vl;
        }
        // Velocity on monotone pieces.
        // The velocity's monotone pieces: split where the acceleration crosses zero.
        let mut ends = [s.v, e.v, e.v];
        let mut n = 2;
        if j != 0.0 {
            let tau = -a0 / j;
            if tau > 0.0 && tau < seg.duration_s() {
                ends[1] = seg.sample(&s, tau).v;
                n = 3;
            }
        }
        for w in ends[..n].windows(2) {
            let (va, vb) = (w[0], w[1]);
            if inside {
                if vb.abs() > vl {
                    return Err(format!("segment {k}: v = {vb} leaves the band"));
                }
            } else if (va > vl && (vb >= va || vb < -vl)) || (va < -vl && (vb <= va || vb > vl)) {
                return Err(format!(
                    "segment {k}: v = {va} -> {vb} outside, not returning"
                ));
            } else if vb.abs() <= vl {
                inside = true;
            }
        }
        s = e;
    }
    Ok(())
}

/// [`check`] on a profile.
pub fn check_profile(p: &Profile, l: &FourJerkLimits) -> Result<(), String> {
    check(p.start(), p.segments(), l)
}

/// A problem drawn like the Ruckig paper (p ~ N(0, 4), v, a ~ N(0, 0.8), limits ~
/// Gamma(2, 2) + 0.05), with four independent jerks and a target at rest acceleration.
pub fn draw(rng: &mut ChaCha8Rng) -> (State, State, FourJerkLimits) {
    let p = Normal::new(0.0, 4.0).expect("normal");
    let va = Normal::new(0.0, 0.8).expect("normal");
    let g = Gamma::new(2.0, 2.0).expect("gamma");
    loop {
        let mut limit = || g.sample(rng) + 0.05;
        let l = FourJerkLimits::new(
            limit(),
            limit(),
            limit(),
            [limit(), limit(), limit(), limit()],
        )
        .expect("limits");
        let start = State {
            p: p.sample(rng),
            v: va.sample(rng),
            a: va.sample(rng),
        };
        let target = State {
            p: p.sample(rng),
            v: va.sample(rng),
            a: 0.0,
        };
        if target.v.abs() <= l.vmax {
            return (start, target, l);
        }
    }
}
