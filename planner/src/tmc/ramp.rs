//! The TMC4361A S-shaped ramp in physical units.
//!
//! Seven phases (the chip's names): **B1** raises the acceleration from 0 to AMAX at jerk
//! BOW1, **B12** holds AMAX, **B2** lowers it to 0 at BOW2 (reaching VMAX), **B23** cruises
//! at VMAX, **B3** raises the deceleration from 0 to DMAX at BOW3, **B34** holds DMAX, **B4**
//! lowers it to 0 at BOW4, arriving at VSTOP. The ramp starts at VSTART with zero
//! acceleration (the chip's default `use_astart_and_vstart = 0`: AACTUAL starts at 0) and
//! ends at VSTOP with zero acceleration; the chip then steps the velocity from VSTOP to 0,
//! which is outside the profile. The four bows are independent: asymmetric S-curves.
//!
//! Reduced cases, all handled by the same construction:
//! - AMAX not reached (B12 vanishes): the velocity gain `VMAX - VSTART` is below
//!   `AMAX^2 (1/BOW1 + 1/BOW2)/2`; the peak acceleration is
//!   `sqrt(2 dv / (1/BOW1 + 1/BOW2))`. Likewise DMAX (B34) with BOW3, BOW4.
//! - VMAX not reached (B23 vanishes): the distance of "accelerate to `vp`, decelerate to
//!   VSTOP" grows strictly with the peak velocity `vp`, so the highest `vp <= VMAX` whose
//!   ramp fits in the distance is found by bisection over `[max(VSTART, VSTOP), VMAX]` to
//!   the last bit; the sub-ULP remainder becomes a cruise at `vp` (so the distance is
//!   covered exactly, and `vp` is the largest peak that does not overshoot).
//! - A distance shorter than the VSTART-to-VSTOP transition itself has no ramp of this
//!   shape (the chip would overshoot and return): an error, not a wrong profile.
//!
//! A negative distance mirrors the ramp (VSTART, VMAX, VSTOP are speeds, the register
//! values are unsigned magnitudes; the direction comes from the sign of the distance).
//!
//! Phase-distance formulas: the distance of B2 with `v3` the velocity at its
//! start, `a` = AMAX and `j2` = BOW2 (the register values), `t3 = a/j2`, is
//! `d3 = v3 t3 + a t3^2/2 - j2 t3^3/6` (the vendor's 1/6 form) and of B4 with `v7` at its
//! start, `a` = DMAX, `j4` = BOW4: `d7 = v7 t7 - a t7^2/2 + j4 t7^3/6`. The "1/3"
//! correction is the identity `d = v0 t + a t^2/2 - j t^3/3` for `a` the acceleration at the
//! *end* of a constant-jerk phase and `j` its signed jerk: true as algebra, but its
//! derivation (`a = a0 + j2 t3` with `a = AMAX`) describes a phase that *raises* the
//! acceleration to AMAX, not B2. See `planner/tests/tmc_ramp.rs`, which checks both
//! readings against exact integration.

use crate::{PlanError, Profile, Segment, State};

/// The seven phases of the ramp, in time order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RampPhase {
    /// Acceleration rises from 0 at BOW1.
    B1,
    /// Acceleration held at AMAX.
    B12,
    /// Acceleration falls to 0 at BOW2.
    B2,
    /// Cruise at the peak velocity.
    B23,
    /// Deceleration rises from 0 at BOW3.
    B3,
    /// Deceleration held at DMAX.
    B34,
    /// Deceleration falls to 0 at BOW4, arriving at VSTOP.
    B4,
}

impl RampPhase {
    /// All phases in time order (the index into [`SRamp::phases_s`]).
    pub const ALL: [RampPhase; 7] = [
        RampPhase::B1,
        RampPhase::B12,
        RampPhase::B2,
        RampPhase::B23,
        RampPhase::B3,
        RampPhase::B34,
        RampPhase::B4,
    ];

    /// The chip's name of the phase.
    pub fn name(self) -> &'static str {
        match self {
            RampPhase::B1 => "B1",
            RampPhase::B12 => "B12",
            RampPhase::B2 => "B2",
            RampPhase::B23 => "B23",
            RampPhase::B3 => "B3",
            RampPhase::B34 => "B34",
            RampPhase::B4 => "B4",
        }
    }
}

/// Ramp parameters in physical units (the caller's length unit `u`, e.g. metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SRampParams {
    /// VSTART: speed the ramp starts at (u/s, >= 0, <= VMAX).
    pub vstart: f64,
    /// VMAX: cruise speed (u/s, > 0).
    pub vmax: f64,
    /// VSTOP: speed the ramp ends at (u/s, >= 0, <= VMAX).
    pub vstop: f64,
    /// AMAX: acceleration limit of B1..B2 (u/s^2, > 0).
    pub amax: f64,
    /// DMAX: deceleration limit of B3..B4 (u/s^2, > 0, a magnitude).
    pub dmax: f64,
    /// BOW1..BOW4 (u/s^3, > 0): the jerks of B1, B2, B3, B4.
    pub bow: [f64; 4],
}

impl SRampParams {
    /// Symmetric parameters (VSTART = VSTOP = 0, AMAX = DMAX, four equal bows): the
    /// classic 7-phase S-curve.
    pub fn symmetric(vmax: f64, amax: f64, jmax: f64) -> Self {
        Self {
            vstart: 0.0,
            vmax,
            vstop: 0.0,
            amax,
            dmax: amax,
            bow: [jmax; 4],
        }
    }

    /// Reject NaN/infinite values, non-positive limits and start/stop speeds outside
    /// `[0, VMAX]`, with the parameter's name.
    pub fn validate(&self) -> Result<(), PlanError> {
        let positive = [
            ("vmax", self.vmax),
            ("amax", self.amax),
            ("dmax", self.dmax),
            ("bow1", self.bow[0]),
            ("bow2", self.bow[1]),
            ("bow3", self.bow[2]),
            ("bow4", self.bow[3]),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(PlanError::InvalidLimit { name, value });
            }
        }
        for (name, value) in [("vstart", self.vstart), ("vstop", self.vstop)] {
            if !(value.is_finite() && value >= 0.0 && value <= self.vmax) {
                return Err(PlanError::InvalidLimit { name, value });
            }
        }
        Ok(())
    }
}

/// A planned ramp: the phase durations, what it reached, and the profile.
#[derive(Debug, Clone, PartialEq)]
pub struct SRamp {
    /// Durations of B1, B12, B2, B23, B3, B34, B4 (s), indexed like [`RampPhase::ALL`].
    pub phases_s: [f64; 7],
    /// Peak speed (u/s): VMAX, or less when the distance is too short to reach it.
    pub v_peak: f64,
    /// Acceleration reached in B1..B2 (u/s^2): AMAX, or less.
    pub a_peak: f64,
    /// Deceleration reached in B3..B4 (u/s^2, a magnitude): DMAX, or less.
    pub d_peak: f64,
    /// +1 for a positive distance, -1 for a negative one.
    pub direction: f64,
    /// The parameters it was planned with.
    pub params: SRampParams,
    /// The motion: starts at `(p0, direction * VSTART, 0)`, ends at
    /// `(p0 + distance, direction * VSTOP, 0)`. Always seven segments, segment `i` being
    /// phase `i` (zero durations kept); B12, B23 and B34 are constant-acceleration
    /// segments.
    pub profile: Profile,
}

impl SRamp {
    /// Total duration (s).
    pub fn duration_s(&self) -> f64 {
        self.profile.duration_s()
    }

    /// Which limits the ramp reaches, as a case name: `acc`/`no_acc` (AMAX),
    /// `vel`/`no_vel` (VMAX), `dec`/`no_dec` (DMAX), e.g. `acc_vel_dec`.
    pub fn case_name(&self) -> &'static str {
        let p = &self.params;
        let acc = self.a_peak >= p.amax;
        let vel = self.v_peak >= p.vmax;
        let dec = self.d_peak >= p.dmax;
        match (acc, vel, dec) {
            (true, true, true) => "acc_vel_dec",
            (true, true, false) => "acc_vel_no_dec",
            (true, false, true) => "acc_no_vel_dec",
            (true, false, false) => "acc_no_vel_no_dec",
            (false, true, true) => "no_acc_vel_dec",
            (false, true, false) => "no_acc_vel_no_dec",
            (false, false, true) => "no_acc_no_vel_dec",
            (false, false, false) => "no_acc_no_vel_no_dec",
        }
    }
}

/// A velocity change by `dv >= 0` from zero to zero acceleration under the limit `alim`,
/// ramping up at `j_in` and down at `j_out`: `(t_in, t_hold, t_out, peak)`.
fn half(dv: f64, alim: f64, j_in: f64, j_out: f64) -> (f64, f64, f64, f64) {
    if dv <= 0.0 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let k = 0.5 * (1.0 / j_in + 1.0 / j_out);
    let dv_full = alim * alim * k;
    if dv >= dv_full {
        (alim / j_in, (dv - dv_full) / alim, alim / j_out, alim)
    } else {
        let a = (dv / k).sqrt();
        (a / j_in, 0.0, a / j_out, a)
    }
}

/// Phase durations for peak speed `vp` (cruise excluded), and the peaks reached.
fn phases(vp: f64, p: &SRampParams) -> ([f64; 7], f64, f64) {
    let (t1, t12, t2, a) = half(vp - p.vstart, p.amax, p.bow[0], p.bow[1]);
    let (t3, t34, t4, d) = half(vp - p.vstop, p.dmax, p.bow[2], p.bow[3]);
    ([t1, t12, t2, 0.0, t3, t34, t4], a, d)
}

/// The seven phases as seven segments (zero durations kept, so segment `i` is phase `i`).
/// The holds and the cruise are written as constant-acceleration segments at exactly the
/// peak, zero and the negative peak: the jerk phases reach them only up to rounding, and a
/// long hold would integrate that rounding into a visible position error.
fn segments(ph: &[f64; 7], p: &SRampParams, a: f64, d: f64, s: f64) -> Vec<Segment> {
    let jerk = |duration_s: f64, j: f64| Segment::Jerk {
        duration_s,
        jerk: s * j,
    };
    let hold = |duration_s: f64, accel: f64| Segment::Accel {
        duration_s,
        accel: s * accel,
    };
    vec![
        jerk(ph[0], p.bow[0]),
        hold(ph[1], a),
        jerk(ph[2], -p.bow[1]),
        hold(ph[3], 0.0),
        jerk(ph[4], -p.bow[2]),
        hold(ph[5], -d),
        jerk(ph[6], p.bow[3]),
    ]
}

/// Distance of the ramp with peak `vp` and no cruise (direction +1).
fn distance_no_cruise(vp: f64, p: &SRampParams) -> f64 {
    let (ph, a, d) = phases(vp, p);
    let mut st = State {
        p: 0.0,
        v: p.vstart,
        a: 0.0,
    };
    for seg in segments(&ph, p, a, d, 1.0) {
        st = seg.end_state(&st);
    }
    st.p
}

/// Plan the ramp for a move of signed `distance` starting at position `p0`.
pub fn plan(p0: f64, distance: f64, prm: &SRampParams) -> Result<SRamp, PlanError> {
    prm.validate()?;
    for (name, value) in [("p0", p0), ("distance", distance)] {
        if !value.is_finite() {
            return Err(PlanError::NonFinite { name, value });
        }
    }
    let s = if distance < 0.0 { -1.0 } else { 1.0 };
    let d = distance.abs();
    let vlo = prm.vstart.max(prm.vstop);
    let d_min = distance_no_cruise(vlo, prm);
    // The VSTART -> VSTOP transition alone; a distance shorter than that (beyond
    // rounding) cannot be covered by this ramp shape.
    if d < d_min * (1.0 - 1e-12) {
        return Err(PlanError::InfeasibleTarget {
            reason: "distance shorter than the ramp from VSTART to VSTOP alone",
        });
    }
    let (vp, cruise) = if d <= d_min {
        (vlo, 0.0)
    } else {
        let d_full = distance_no_cruise(prm.vmax, prm);
        if d >= d_full {
            (prm.vmax, (d - d_full) / prm.vmax)
        } else {
            // distance_no_cruise grows strictly with vp: bisect to the last bit, keeping
            // lo on the side that does not overshoot.
            let (mut lo, mut hi) = (vlo, prm.vmax);
            loop {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if distance_no_cruise(mid, prm) <= d {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let rest = d - distance_no_cruise(lo, prm);
            (lo, if lo > 0.0 { rest.max(0.0) / lo } else { 0.0 })
        }
    };
    let (mut ph, a_peak, d_peak) = phases(vp, prm);
    ph[3] = cruise;
    let start = State {
        p: p0,
        v: s * prm.vstart,
        a: 0.0,
    };
    let profile = Profile::new(start, segments(&ph, prm, a_peak, d_peak, s))?;
    Ok(SRamp {
        phases_s: ph,
        v_peak: vp,
        a_peak,
        d_peak,
        direction: s,
        params: *prm,
        profile,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_value_full_ramp() {
        // VSTART 0, VMAX 1, AMAX 2, DMAX 4, bows 10, 20, 40, 80:
        // B1 0.2 s (dv 0.2), B2 0.1 s (dv 0.1), B12 (1 - 0.3)/2 = 0.35 s;
        // B3 0.1 s (dv 0.2), B4 0.05 s (dv 0.1), B34 (1 - 0.3)/4 = 0.175 s.
        let p = SRampParams {
            vstart: 0.0,
            vmax: 1.0,
            vstop: 0.0,
            amax: 2.0,
            dmax: 4.0,
            bow: [10.0, 20.0, 40.0, 80.0],
        };
        let r = plan(0.0, 5.0, &p).expect("ramp");
        let want = [0.2, 0.35, 0.1, 0.0, 0.1, 0.175, 0.05];
        for (i, w) in want.iter().enumerate() {
            if i != 3 {
                assert!((r.phases_s[i] - w).abs() < 1e-15, "{i}: {:?}", r.phases_s);
            }
        }
        assert_eq!(r.case_name(), "acc_vel_dec");
        assert!((r.profile.end().p - 5.0).abs() < 1e-12);
        assert!(r.profile.end().v.abs() < 1e-12);
    }

    #[test]
    fn rejects_bad_parameters_by_name() {
        let mut p = SRampParams::symmetric(1.0, 1.0, 1.0);
        p.bow[2] = 0.0;
        assert!(matches!(
            plan(0.0, 1.0, &p),
            Err(PlanError::InvalidLimit { name: "bow3", .. })
        ));
        let mut p = SRampParams::symmetric(1.0, 1.0, 1.0);
        p.vstop = 2.0;
        assert!(matches!(
            plan(0.0, 1.0, &p),
            Err(PlanError::InvalidLimit { name: "vstop", .. })
        ));
    }
}
