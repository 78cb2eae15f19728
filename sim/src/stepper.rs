//! The two-phase hybrid stepper motor and its current-controlled (chopper) driver.
//!
//! Conventions: `theta` is the rotor angle (rad) as a [`crate::lumped::Lumped`] body
//! coordinate; the commanded rotor angle is `x_cmd * rad_per_m`. The driver works in
//! electrical angle `Nr * theta` (Nr = rotor teeth, 50 for a 1.8 degree motor).
//!
//! - **Step/dir quantisation**: the driver only knows whole microsteps, so the commanded
//!   position is rounded to the microstep grid (`full step = pi / (2 Nr)` rad of rotor,
//!   divided by the microstep count). Position 0 is a full-step position.
//! - **Current loop**: phase references `ia* = I cos(Nr theta_q)`, `ib* = I sin(Nr theta_q)`;
//!   each phase obeys `L di/dt = V - R i - e` with back-EMF `e_a = -Km w sin(Nr theta)`,
//!   `e_b = Km w cos(Nr theta)` (the power-conserving partner of the torque law below).
//!   The chopper is modelled as a proportional controller `V = R i* + Kp (i* - i)` with
//!   `Kp = 2 pi f_bw L - R` (closed-loop bandwidth `f_bw`), clamped to the supply `+-Vs`:
//!   at speed the back-EMF and `w L` eat the supply and the current (torque) falls off.
//!   Within a sub-step the inputs are frozen and each phase is integrated exactly through
//!   its clamped and unclamped pieces (closed-form exponentials), so the stiff current
//!   loop costs nothing in stability.
//! - **Torque**: `T = -Km ia sin(Nr theta) + Km ib cos(Nr theta) - Td sin(4 Nr theta)`
//!   plus a viscous term `-c (w - w_cmd)` on the slip rate (the damping of the rotor on
//!   its magnetic spring; the same `c` the linear driver spring carries, so both modes
//!   agree at small amplitude). With ideal currents `T = Km I sin(Nr (theta_q - theta))`:
//!   for small angles a spring `k_theta = Km I Nr`.
//! - **Lost steps**: the load angle is the angle between the current vector and the rotor,
//!   `phi = atan2(ib, ia) - Nr theta`. Past `|phi| = 90` electrical degrees the torque falls
//!   as the lag grows, so the rotor can no longer follow: the run has lost steps. Each
//!   pole slip (the rotor falling into the next equilibrium, 360 electrical degrees
//!   away) loses 4 full steps.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use crate::SimError;

/// The longest electrical sub-step (s): the current references and back-EMF are frozen
/// over it (evaluated at its middle). 25 us is 0.06 rad of electrical angle at 300 mm/s on
/// a 20-tooth GT2 pulley; the error of the midpoint rule is ~(0.06)^2/24 of the current.
pub const ELECTRICAL_SUBSTEP_S: f64 = 25e-6;

/// A stepper motor with its driver, pushing body `rotor` of an axis model.
#[derive(Debug, Clone, PartialEq)]
pub struct Stepper {
    /// The rotor body (an angular body of the axis's lumped model).
    pub rotor: usize,
    /// Rotor angle per metre of axis travel (rad/m): `1/r_pulley`, or `2 pi / lead`.
    pub rad_per_m: f64,
    /// Rotor teeth Nr (50 for a 1.8 degree hybrid stepper).
    pub rotor_teeth: u32,
    /// Microsteps per full step (1 = full stepping).
    pub microsteps: u32,
    /// Torque constant Km (N m/A), also the back-EMF constant (V s/rad).
    pub torque_constant_n_m_per_a: f64,
    /// Phase current amplitude I (A): the peak of the sine the driver commands.
    pub current_a: f64,
    /// Phase resistance R (ohm).
    pub resistance_ohm: f64,
    /// Phase inductance L (H).
    pub inductance_h: f64,
    /// Detent (cogging) torque amplitude Td (N m).
    pub detent_torque_n_m: f64,
    /// Supply voltage Vs (V): the most the driver can put across a phase.
    pub supply_v: f64,
    /// Viscous damping of the rotor on its magnetic spring (N m s/rad).
    pub damping_n_m_s_per_rad: f64,
    /// Closed-loop bandwidth of the current controller (Hz).
    pub current_loop_bandwidth_hz: f64,
}

/// The driver's torque over a step, for an integrator that holds it constant
/// ([`Stepper::advance_predicted`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MidStep {
    /// Phase A current at mid-step (A).
    pub i_a: f64,
    /// Phase B current at mid-step (A).
    pub i_b: f64,
    /// The predicted rotor angle at mid-step (rad).
    pub theta_rad: f64,
    /// Magnetic plus detent torque (N m), averaged over the step along the predicted
    /// rotor path and the currents' closed form (trapezoidal rule on the electrical
    /// sub-step boundaries); without the slip damping (the caller's integrator applies
    /// that with its own velocities).
    pub torque_n_m: f64,
}

/// The driver's mutable state.
#[derive(Debug, Clone, PartialEq)]
pub struct StepperState {
    /// Phase A current (A).
    pub i_a: f64,
    /// Phase B current (A).
    pub i_b: f64,
    /// Load angle now (electrical rad): current vector minus rotor, unwrapped.
    pub load_angle_rad: f64,
    /// Largest |load angle| so far (electrical rad).
    pub max_load_angle_rad: f64,
    /// Pole slips so far (each 4 full steps).
    pub slips: u32,
    /// The pole pitch (multiple of 2 pi electrical) the rotor currently sits in.
    pole: i64,
}

impl StepperState {
    /// A state at rest with these currents (A) and load angle (electrical rad).
    fn new(i_a: f64, i_b: f64, phi: f64) -> Self {
        Self {
            i_a,
            i_b,
            load_angle_rad: phi,
            max_load_angle_rad: phi.abs(),
            slips: 0,
            pole: 0,
        }
    }

    /// Record a load angle (electrical rad).
    #[inline]
    pub fn track(&mut self, phi: f64) {
        self.load_angle_rad = phi;
        self.max_load_angle_rad = self.max_load_angle_rad.max(phi.abs());
        // The pole pitch changes only when the angle leaves +-pi around the current one.
        if (phi - self.pole as f64 * TAU).abs() <= PI {
            return;
        }
        let pole = (phi / TAU).round() as i64;
        if pole != self.pole {
            self.slips = self.slips.saturating_add(pole.abs_diff(self.pole) as u32);
            self.pole = pole;
        }
    }

    /// Full steps lost so far: 0 while the load angle stayed within 90 electrical degrees;
    /// otherwise 4 per pole slip, and at least 1 (the rotor passed its stability limit and
    /// fell at least one full step behind its field even if it was caught again).
    pub fn lost_steps(&self) -> u32 {
        if self.max_load_angle_rad > FRAC_PI_2 {
            (4 * self.slips).max(1)
        } else {
            0
        }
    }
}

/// Electrical constants of one phase, precomputed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Phase {
    r: f64,
    l: f64,
    kp: f64,
    vs: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Regime {
    High,
    Linear,
    Low,
}

impl Phase {
    /// Advance one phase current `i` (A) by `h` s with the reference `i_ref` (A) and
    /// back-EMF `e` (V) frozen, exactly through the clamped (+-Vs) and proportional pieces
    /// (the current of [`Phase::advance_integral`]).
    fn advance(&self, i: f64, i_ref: f64, e: f64, h: f64) -> f64 {
        self.advance_integral(i, i_ref, e, h).0
    }

    /// [`Phase::advance`] that also returns the exact integral of the current over the
    /// interval (A s): each closed-form piece `i(t) = target + (i0 - target) e^{-rate t}`
    /// integrates to `target T + (i0 - target)(1 - e^{-rate T}) / rate`.
    pub(crate) fn advance_integral(&self, mut i: f64, i_ref: f64, e: f64, h: f64) -> (f64, f64) {
        let Phase { r, l, kp, vs } = *self;
        // Proportional region: V = R i* + Kp (i* - i) within +-Vs, i.e. i_hi <= i <= i_lo.
        let i_hi = i_ref + (r * i_ref - vs) / kp;
        let i_lo = i_ref + (r * i_ref + vs) / kp;
        let mut regime = if i < i_hi {
            Regime::High
        } else if i > i_lo {
            Regime::Low
        } else {
            Regime::Linear
        };
        let mut left = h;
        let mut area = 0.0;
        for _ in 0..4 {
            let (target, rate) = match regime {
                Regime::High => ((vs - e) / r, r / l),
                Regime::Low => ((-vs - e) / r, r / l),
                Regime::Linear => (i_ref - e / (r + kp), (r + kp) / l),
            };
            // The boundary the current runs into on its way to `target`, if any.
            let exit = match regime {
                Regime::High if target > i_hi => Some((i_hi, Regime::Linear)),
                Regime::Low if target < i_lo => Some((i_lo, Regime::Linear)),
                Regime::Linear if target < i_hi => Some((i_hi, Regime::High)),
                Regime::Linear if target > i_lo => Some((i_lo, Regime::Low)),
                _ => None,
            };
            if let Some((b, next)) = exit {
                let ratio = (i - target) / (b - target);
                let t_b = if ratio > 1.0 { ratio.ln() / rate } else { 0.0 };
                if t_b < left {
                    // Over t_b the current went from i to b: (i - target)(1 - e^{-rate t_b})
                    // is i - b.
                    area += target * t_b + (i - b) / rate;
                    i = b;
                    left -= t_b;
                    regime = next;
                    continue;
                }
            }
            let decay = (-rate * left).exp();
            area += target * left + (i - target) * (1.0 - decay) / rate;
            return (target + (i - target) * decay, area);
        }
        (i, area)
    }
}

impl Phase {
    /// [`Phase::advance_integral`] for both phases at once: the same numbers, with one
    /// exponential for both when both stay in the proportional region (the usual case:
    /// same rate `(R + Kp) / L`), otherwise phase by phase.
    pub(crate) fn advance_pair(
        &self,
        i: [f64; 2],
        i_ref: [f64; 2],
        e: [f64; 2],
        h: f64,
    ) -> [(f64, f64); 2] {
        let Phase { r, l, kp, vs } = *self;
        let linear = |k: usize| {
            let i_hi = i_ref[k] + (r * i_ref[k] - vs) / kp;
            let i_lo = i_ref[k] + (r * i_ref[k] + vs) / kp;
            let target = i_ref[k] - e[k] / (r + kp);
            // NaN falls through to the phase-by-phase path (same numbers).
            let inside = |x: f64| (i_hi..=i_lo).contains(&x);
            (inside(i[k]) && inside(target)).then_some(target)
        };
        if let (Some(ta), Some(tb)) = (linear(0), linear(1)) {
            let rate = (r + kp) / l;
            let decay = (-rate * h).exp();
            let one = |i: f64, target: f64| {
                (
                    target + (i - target) * decay,
                    0.0 + (target * h + (i - target) * (1.0 - decay) / rate),
                )
            };
            return [one(i[0], ta), one(i[1], tb)];
        }
        [
            self.advance_integral(i[0], i_ref[0], e[0], h),
            self.advance_integral(i[1], i_ref[1], e[1], h),
        ]
    }
}

impl Stepper {
    /// Check every parameter; `axis` names the axis in the error.
    pub fn validate(&self, axis: &str) -> Result<(), SimError> {
        let bad = |field: &str, value: f64, allowed: &str| {
            Err(SimError::InvalidMachine {
                axis: axis.to_string(),
                field: field.to_string(),
                value,
                allowed: allowed.to_string(),
            })
        };
        let pos = |x: f64| x.is_finite() && x > 0.0;
        if !pos(self.rad_per_m) {
            return bad("rad_per_m", self.rad_per_m, "a finite number > 0");
        }
        if self.rotor_teeth == 0 {
            return bad(
                "motor.rotor_teeth",
                0.0,
                "an integer >= 1 (50 for 1.8 degree motors)",
            );
        }
        if self.microsteps == 0 {
            return bad("driver.microsteps", 0.0, "an integer >= 1");
        }
        for (f, v) in [
            ("motor.torque_constant", self.torque_constant_n_m_per_a),
            ("driver.run_current", self.current_a),
            ("motor.resistance_ohm", self.resistance_ohm),
            ("motor.inductance_mh", self.inductance_h),
            ("driver.supply_v", self.supply_v),
        ] {
            if !pos(v) {
                return bad(f, v, "a finite number > 0");
            }
        }
        if !(self.detent_torque_n_m.is_finite() && self.detent_torque_n_m >= 0.0) {
            return bad(
                "motor.detent_torque_n_m",
                self.detent_torque_n_m,
                "a finite number >= 0",
            );
        }
        if !(self.damping_n_m_s_per_rad.is_finite() && self.damping_n_m_s_per_rad >= 0.0) {
            return bad(
                "motor.damping_ratio",
                self.damping_n_m_s_per_rad,
                "a finite number >= 0",
            );
        }
        let min_bw = self.resistance_ohm / (TAU * self.inductance_h);
        if !(self.current_loop_bandwidth_hz.is_finite() && self.current_loop_bandwidth_hz > min_bw)
        {
            return bad(
                "driver.current_loop_bandwidth_hz",
                self.current_loop_bandwidth_hz,
                &format!("a finite number > R/(2 pi L) = {min_bw:.1} Hz"),
            );
        }
        Ok(())
    }

    /// Rotor teeth as a float.
    pub(crate) fn nr(&self) -> f64 {
        f64::from(self.rotor_teeth)
    }

    /// One full step of rotor angle (rad): `pi / (2 Nr)` (1.8 degrees for Nr = 50).
    pub fn full_step_rad(&self) -> f64 {
        PI / (2.0 * self.nr())
    }

    /// One microstep of axis travel (m).
    pub fn microstep_m(&self) -> f64 {
        self.full_step_rad() / f64::from(self.microsteps) / self.rad_per_m
    }

    /// The commanded position as the driver sees it: rounded to the microstep grid (m).
    #[inline]
    pub fn quantise_m(&self, x_m: f64) -> f64 {
        let step = self.microstep_m();
        (x_m / step).round() * step
    }

    /// Peak electromagnetic torque `Km I` (N m): the pull-out torque at standstill
    /// without detent.
    pub fn peak_torque_n_m(&self) -> f64 {
        self.torque_constant_n_m_per_a * self.current_a
    }

    /// The small-angle stiffness of the driver's magnetic spring `k_theta = Km I Nr`
    /// (N m/rad).
    pub fn k_theta(&self) -> f64 {
        self.peak_torque_n_m() * self.nr()
    }

    /// The largest stiffness the detent adds or removes (N m/rad): `4 Nr Td`.
    pub fn detent_stiffness(&self) -> f64 {
        4.0 * self.nr() * self.detent_torque_n_m
    }

    pub(crate) fn phase(&self) -> Phase {
        Phase {
            r: self.resistance_ohm,
            l: self.inductance_h,
            kp: TAU * self.current_loop_bandwidth_hz * self.inductance_h - self.resistance_ohm,
            vs: self.supply_v,
        }
    }

    /// Rotor torque (N m) from the phase currents, the detent and the slip damping, at rotor
    /// angle `theta` (rad) and speed `omega` (rad/s), with the command moving at `v_cmd`
    /// (m/s).
    #[inline]
    pub fn torque(&self, st: &StepperState, theta: f64, omega: f64, v_cmd: f64) -> f64 {
        let km = self.torque_constant_n_m_per_a;
        let (s, c) = (self.nr() * theta).sin_cos();
        km * (-st.i_a * s + st.i_b * c)
            - self.detent_torque_n_m * (4.0 * self.nr() * theta).sin()
            - self.damping_n_m_s_per_rad * (omega - v_cmd * self.rad_per_m)
    }

    /// The driver at rest for a command held at `x_cmd` (m): the state (currents at their
    /// references) and the rotor's equilibrium angle (rad), where the magnetic torque
    /// balances the detent.
    pub fn at_rest(&self, x_cmd: f64) -> (StepperState, f64) {
        let nr = self.nr();
        let th_q = self.quantise_m(x_cmd) * self.rad_per_m;
        let (i_b, i_a) = (nr * th_q).sin_cos();
        let (i_a, i_b) = (self.current_a * i_a, self.current_a * i_b);
        let km_i = self.peak_torque_n_m();
        let td = self.detent_torque_n_m;
        let f = |th: f64| km_i * (nr * (th_q - th)).sin() - td * (4.0 * nr * th).sin();
        // Bracket within half a full step and bisect: f > 0 below the equilibrium.
        let half = self.full_step_rad() / 2.0;
        let (mut lo, mut hi) = (th_q - half, th_q + half);
        if f(th_q) == 0.0 {
            (lo, hi) = (th_q, th_q);
        } else if f(th_q) > 0.0 {
            lo = th_q;
        } else {
            hi = th_q;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if f(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let th = 0.5 * (lo + hi);
        (StepperState::new(i_a, i_b, nr * (th_q - th)), th)
    }

    /// Advance the currents over a step of `h` s during which the rotor moved from
    /// `theta0` to `theta1` (rad) at speed `omega` (rad/s) and the command followed
    /// `x(tau) = p + v tau + a tau^2/2 + j tau^3/6` (m); then record the load angle.
    pub fn advance(
        &self,
        st: &mut StepperState,
        theta0: f64,
        theta1: f64,
        omega: f64,
        cmd: &settle_planner::Sample,
        h: f64,
    ) {
        let nr = self.nr();
        let km = self.torque_constant_n_m_per_a;
        let ph = self.phase();
        let n = (h / ELECTRICAL_SUBSTEP_S).ceil().max(1.0);
        let he = h / n;
        let x_at = |tau: f64| cmd.p + tau * (cmd.v + tau * (cmd.a / 2.0 + tau * cmd.j / 6.0));
        for k in 0..n as usize {
            let f = (k as f64 + 0.5) / n;
            let th = theta0 + (theta1 - theta0) * f;
            let el_q = nr * self.quantise_m(x_at(f * h)) * self.rad_per_m;
            let (sq, cq) = el_q.sin_cos();
            let (s, c) = (nr * th).sin_cos();
            let (e_a, e_b) = (-km * omega * s, km * omega * c);
            st.i_a = ph.advance(st.i_a, self.current_a * cq, e_a, he);
            st.i_b = ph.advance(st.i_b, self.current_a * sq, e_b, he);
        }
        // Load angle: the current vector's angle, unwrapped next to the commanded
        // electrical angle (the current never lags its reference by half a turn), minus
        // the rotor's.
        self.track_currents(st, theta1, x_at(h));
    }

    /// Advance the currents over a step of `h` s in one pass, with the rotor predicted to
    /// turn at a constant `omega` (rad/s) from `theta0` (rad), the command following
    /// `x(tau) = p + v tau + a tau^2/2 + j tau^3/6` (m), and return the driver torque to
    /// hold over the step ([`MidStep`]: its mean along the predicted path) for an
    /// integrator that holds it constant (MuJoCo's motor actuator). For a torque linear in
    /// the angle the mean is the value at the predicted midpoint, which adds no numerical
    /// damping to a spring integrated that way; unlike the midpoint value it also carries
    /// the microstep edges and current transients inside the step with their timing
    /// (see `sim/tests/all/mujoco_step_budget.rs` for the printer's Y axis against a 4x
    /// smaller step).
    ///
    /// Each electrical sub-step (at most [`ELECTRICAL_SUBSTEP_S`], an even number of them)
    /// freezes the reference and back-EMF at its middle and solves
    /// `L di/dt = V - R i - e` exactly through its clamped and proportional pieces, as
    /// [`Stepper::advance`] does; the torque's mean and the mid-step currents come from
    /// the same pass. Unlike [`Stepper::advance`] the rotor path is the prediction, not the
    /// step's result: the back-EMF is off by the rotor's speed change over the step,
    /// `Km dw`, against a current loop that forgets it within `L / (R + Kp)` (8 us for the
    /// presets). The load angle is not recorded here: call [`Stepper::track_currents`]
    /// with the rotor angle at the step's end.
    #[inline]
    pub fn advance_predicted(
        &self,
        st: &mut StepperState,
        theta0: f64,
        omega: f64,
        cmd: &settle_planner::Sample,
        h: f64,
    ) -> MidStep {
        self.advance_predicted_inner::<false>(st, theta0, omega, cmd, h, &mut Vec::new())
    }

    /// [`Stepper::advance_predicted`] that also keeps, for each electrical sub-step
    /// boundary inside the step, its time (s after the step start), the current vector's
    /// angle and the commanded electrical angle (rad) in `inner` (cleared first): with the
    /// rotor's angle there, [`Stepper::track_peak`] gives the load angle between the
    /// step's ends, for steps long enough that the ends alone would miss its peak (the
    /// lean path of a plant that steps several samples at once).
    #[inline]
    pub fn advance_predicted_inner_angles(
        &self,
        st: &mut StepperState,
        theta0: f64,
        omega: f64,
        cmd: &settle_planner::Sample,
        h: f64,
        inner: &mut Vec<[f64; 3]>,
    ) -> MidStep {
        inner.clear();
        self.advance_predicted_inner::<true>(st, theta0, omega, cmd, h, inner)
    }

    /// Raise `st.max_load_angle_rad` to the largest |load angle| at the points kept by
    /// [`Stepper::advance_predicted_inner_angles`], `theta(t)` giving the rotor angle
    /// (rad) at `t` s after the step start. Pole slips are left to
    /// [`Stepper::track_currents`] at the step's end.
    pub fn track_peak(
        &self,
        st: &mut StepperState,
        inner: &[[f64; 3]],
        theta: impl Fn(f64) -> f64,
    ) {
        let nr = self.nr();
        for &[t, psi, el_cmd] in inner {
            let lag = (psi - el_cmd + PI).rem_euclid(TAU) - PI;
            let phi = el_cmd + lag - nr * theta(t);
            st.max_load_angle_rad = st.max_load_angle_rad.max(phi.abs());
        }
    }

    #[inline(always)]
    fn advance_predicted_inner<const KEEP: bool>(
        &self,
        st: &mut StepperState,
        theta0: f64,
        omega: f64,
        cmd: &settle_planner::Sample,
        h: f64,
        inner: &mut Vec<[f64; 3]>,
    ) -> MidStep {
        let nr = self.nr();
        let km = self.torque_constant_n_m_per_a;
        let ph = self.phase();
        // An even count puts mid-step on a sub-step boundary.
        let n = (h / ELECTRICAL_SUBSTEP_S).ceil().max(1.0) as usize;
        let n = n + n % 2;
        let he = h / n as f64;
        let x_at = |tau: f64| cmd.p + tau * (cmd.v + tau * (cmd.a / 2.0 + tau * cmd.j / 6.0));
        let el_per_m = nr * self.rad_per_m;
        let mut mid = None;
        // The torque at a sub-step boundary (magnetic and detent, at the predicted angle).
        let torque_at = |i_a: f64, i_b: f64, theta: f64| {
            let (s, c) = (nr * theta).sin_cos();
            // sin(4 x) from sin x and cos x (double angle twice): no third sine.
            let (s2, c2) = (2.0 * s * c, 1.0 - 2.0 * s * s);
            km * (-i_a * s + i_b * c) - self.detent_torque_n_m * 2.0 * s2 * c2
        };
        // The mean over the step by the trapezoidal rule on the sub-step boundaries.
        let mut sum = 0.5 * torque_at(st.i_a, st.i_b, theta0);
        for k in 0..n {
            if 2 * k == n {
                mid = Some((st.i_a, st.i_b));
            }
            let t = (k as f64 + 0.5) * he;
            let el_q = el_per_m * self.quantise_m(x_at(t));
            let (sq, cq) = el_q.sin_cos();
            let (s, c) = (nr * (theta0 + omega * t)).sin_cos();
            let (e_a, e_b) = (-km * omega * s, km * omega * c);
            st.i_a = ph.advance(st.i_a, self.current_a * cq, e_a, he);
            st.i_b = ph.advance(st.i_b, self.current_a * sq, e_b, he);
            let w = if k + 1 == n { 0.5 } else { 1.0 };
            sum += w * torque_at(st.i_a, st.i_b, theta0 + omega * (k + 1) as f64 * he);
            if KEEP && k + 1 < n {
                inner.push([(k + 1) as f64 * he, st.i_b.atan2(st.i_a), el_q]);
            }
        }
        let (i_a, i_b) = mid.unwrap_or((st.i_a, st.i_b));
        MidStep {
            i_a,
            i_b,
            theta_rad: theta0 + 0.5 * h * omega,
            torque_n_m: sum / n as f64,
        }
    }

    /// Record the load angle at the end of a step: the current vector's angle, unwrapped
    /// next to the commanded electrical angle for a command at `x_cmd` (m), minus the
    /// rotor's at `theta` (rad).
    #[inline]
    pub fn track_currents(&self, st: &mut StepperState, theta: f64, x_cmd: f64) {
        let nr = self.nr();
        let el_cmd = nr * self.quantise_m(x_cmd) * self.rad_per_m;
        let psi = st.i_b.atan2(st.i_a);
        let lag = (psi - el_cmd + PI).rem_euclid(TAU) - PI;
        st.track(el_cmd + lag - nr * theta);
    }

    /// Record the load angle of a linear driver spring (no currents): commanded electrical
    /// angle minus the rotor's, for a command at `x_cmd` (m, as the spring sees it).
    pub fn track_spring(&self, st: &mut StepperState, theta: f64, x_cmd: f64) {
        st.track(self.nr() * (x_cmd * self.rad_per_m - theta));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A NEMA17 (17HS4401-like) on a 20-tooth GT2 pulley at 0.8 A rms.
    fn motor() -> Stepper {
        Stepper {
            rotor: 0,
            rad_per_m: 1.0 / (0.040 / TAU),
            rotor_teeth: 50,
            microsteps: 16,
            torque_constant_n_m_per_a: 0.40 / (2f64.sqrt() * 1.7),
            current_a: 0.8 * 2f64.sqrt(),
            resistance_ohm: 1.5,
            inductance_h: 2.8e-3,
            detent_torque_n_m: 0.022,
            supply_v: 24.0,
            damping_n_m_s_per_rad: 7e-4,
            current_loop_bandwidth_hz: 20e3,
        }
    }

    #[test]
    fn microsteps_and_spring_constant() {
        let m = motor();
        // 40 mm per turn, 200 full steps, 16 microsteps: 12.5 um.
        assert!((m.microstep_m() - 12.5e-6).abs() < 1e-15);
        assert!((m.quantise_m(12.5e-6 * 3.4) - 12.5e-6 * 3.0).abs() < 1e-18);
        assert!((m.quantise_m(-12.5e-6 * 3.6) + 12.5e-6 * 4.0).abs() < 1e-18);
        assert!((m.k_theta() - m.peak_torque_n_m() * 50.0).abs() < 1e-12);
        m.validate("x").expect("valid");
    }

    #[test]
    fn ideal_currents_give_the_sinusoidal_torque_law() {
        // With currents at their references, T = Km I sin(Nr (theta_q - theta)) - detent.
        let m = motor();
        let x = 3.0 * m.microstep_m();
        let (st, _) = m.at_rest(x);
        let th_q = x * m.rad_per_m;
        for k in -20..=20 {
            let th = th_q + f64::from(k) * 0.002;
            let want = m.peak_torque_n_m() * (50.0 * (th_q - th)).sin()
                - m.detent_torque_n_m * (200.0 * th).sin();
            let got = m.torque(&st, th, 0.0, 0.0);
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn rest_angle_balances_magnetic_and_detent_torque() {
        let m = motor();
        for k in 0..16 {
            let x = f64::from(k) * m.microstep_m();
            let (st, th) = m.at_rest(x);
            assert!(m.torque(&st, th, 0.0, 0.0).abs() < 1e-12);
            // Off by at most Td / (k_theta - 4 Nr Td) from the commanded angle.
            let bound = m.detent_torque_n_m / (m.k_theta() - m.detent_stiffness());
            assert!((th - x * m.rad_per_m).abs() <= bound * 1.0001);
        }
        // On a full step the detent has no torque: exactly at the command.
        let (_, th) = m.at_rest(0.0);
        assert_eq!(th, 0.0);
    }

    #[test]
    fn current_reaches_its_reference_with_the_loop_time_constant() {
        let m = motor();
        let ph = m.phase();
        // Unclamped: a small reference step decays with tau = L / (R + Kp).
        let tau = m.inductance_h / (ph.r + ph.kp);
        let i = ph.advance(0.0, 0.01, 0.0, tau);
        assert!((i - 0.01 * (1.0 - (-1f64).exp())).abs() < 1e-12, "{i}");
        // A large step saturates: V = Vs, di/dt = (Vs - R i)/L, until the proportional
        // region; compare with a fine explicit integration of the clamped law.
        let (i_ref, h) = (1.0, 2e-4);
        let mut x = 0.0;
        let n = 200_000;
        for _ in 0..n {
            let v = (ph.r * i_ref + ph.kp * (i_ref - x)).clamp(-ph.vs, ph.vs);
            x += (h / f64::from(n)) * (v - ph.r * x) / ph.l;
        }
        let exact = ph.advance(0.0, i_ref, 0.0, h);
        assert!((exact - x).abs() < 1e-5, "{exact} vs {x}");
        // Against a back-EMF larger than the supply the current cannot follow.
        let i = ph.advance(0.0, 1.0, 30.0, 1.0);
        assert!((i - (24.0 - 30.0) / 1.5).abs() < 1e-9, "{i}");
    }

    #[test]
    fn load_angle_tracking_counts_pole_slips() {
        let mut st = StepperState::new(1.0, 0.0, 0.0);
        st.track(1.0);
        assert_eq!(st.lost_steps(), 0);
        st.track(2.0);
        assert_eq!((st.slips, st.lost_steps()), (0, 1));
        st.track(TAU + 0.1);
        assert_eq!((st.slips, st.lost_steps()), (1, 4));
        // Swinging within the new pole pitch is no further slip; back to the first is one.
        st.track(TAU - 2.0);
        assert_eq!(st.slips, 1);
        st.track(0.5);
        assert_eq!((st.slips, st.lost_steps()), (2, 8));
    }
}
