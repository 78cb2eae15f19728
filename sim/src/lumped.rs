//! The lumped-parameter model: the one description every physical backend is built from.
//!
//! A machine (motor rotor, belt or screw, carriage, toolhead, frame) compiles to a set of
//! one-degree-of-freedom [`Body`]s joined by linear spring-dampers ([`Coupling`]s). The
//! modal backend diagonalises it, rapier and MuJoCo build bodies and joints from it, so
//! all backends simulate the same physics by construction.
//!
//! Conventions (SI):
//! - Generalised coordinate `q_i` of body `i`: metres for [`DofKind::Linear`] (absolute
//!   position along the axis), radians for [`DofKind::Angular`]. All start at rest at the
//!   commanded start, i.e. at the static equilibrium for the command's start position.
//! - [`Node::Command`] is the commanded axis position `x_cmd` (m), moved kinematically by
//!   the trajectory; [`Node::Ground`] is the fixed world (coordinate always 0).
//! - A coupling's *extension* is `e = sum_k gain_k q_{node_k}` (m or rad: the gains convert,
//!   e.g. a belt from a rotor of pulley radius r to a carriage has terms
//!   `(carriage, +1), (rotor, -r)`). Its potential is `k e^2 / 2` and its dissipation
//!   `c e'^2 / 2`, so it pushes body `i` with the generalised force
//!   `-(k e + c e') * gain_i` (N, or N m for angular bodies).
//! - The toolhead position (m) is `sum_k gain_k q_{node_k}` over [`Lumped::output`].

use nalgebra::{DMatrix, DVector};

use crate::{Mode, SimError};

/// What a body's coordinate measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DofKind {
    /// Translation along the axis (m); inertia in kg.
    Linear,
    /// Rotation about the motor shaft (rad); inertia in kg m^2.
    Angular,
}

/// One body with one degree of freedom.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Name for outputs and error messages, e.g. `rotor`, `carriage`, `toolhead`, `frame`.
    pub name: String,
    /// Translational or rotational.
    pub kind: DofKind,
    /// Mass (kg) or moment of inertia (kg m^2), > 0.
    pub inertia: f64,
}

/// Where a coupling or the output takes a coordinate from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Node {
    /// The fixed world: coordinate 0.
    Ground,
    /// The commanded axis position (m), moved by the trajectory.
    Command,
    /// Body `i`'s coordinate.
    Body(usize),
}

/// `gain * q_node`: one term of a linear combination of coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Term {
    /// The coordinate.
    pub node: Node,
    /// Its factor (dimension converts the coordinate to the coupling's extension unit).
    pub gain: f64,
}

/// How stiff a coupling is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stiffness {
    /// Constant stiffness (N/m, or N m/rad for an angular extension).
    Constant(f64),
    /// A belt driven at one end: the two belt paths from the carriage back to the drive
    /// pulley act in parallel, `k = EA/s + EA/(L - s)` (N/m), with
    /// `s = s0_m + q_carriage` the span from the drive pulley to the carriage. Backends that
    /// cannot vary a stiffness during a run use [`Stiffness::at`] at the start position.
    BeltSpans {
        /// Belt axial stiffness E*A (N): ~ 10-20 kN for a 6 mm GT2 glass-fibre belt.
        ea_n: f64,
        /// Length L of belt from the drive pulley, along the carriage, back to the drive
        /// pulley (m): for the usual closed loop around a free idler, twice the
        /// pulley-to-idler distance (the return path runs around the idler); for a belt
        /// whose far end is anchored, the pulley-to-anchor distance.
        length_m: f64,
        /// Span s when the carriage coordinate is 0 (m).
        s0_m: f64,
        /// The carriage body whose coordinate moves the split point.
        carriage: usize,
    },
}

/// The shortest span a belt model allows (m): keeps `EA/s` finite at the ends of travel.
pub const MIN_SPAN_M: f64 = 0.005;

impl Stiffness {
    /// The stiffness with the carriage coordinate at `q_carriage_m` (N/m or N m/rad).
    pub fn at(&self, q_carriage_m: f64) -> f64 {
        match *self {
            Stiffness::Constant(k) => k,
            Stiffness::BeltSpans {
                ea_n,
                length_m,
                s0_m,
                ..
            } => {
                let s = (s0_m + q_carriage_m).clamp(MIN_SPAN_M, length_m - MIN_SPAN_M);
                ea_n / s + ea_n / (length_m - s)
            }
        }
    }

    /// The body whose coordinate the stiffness depends on, if any.
    pub fn depends_on(&self) -> Option<usize> {
        match *self {
            Stiffness::Constant(_) => None,
            Stiffness::BeltSpans { carriage, .. } => Some(carriage),
        }
    }
}

/// A linear spring-damper on the extension `sum gain_k q_k`.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupling {
    /// Name, e.g. `driver`, `belt`, `mount`, `frame`.
    pub name: String,
    /// The extension's terms (at least one).
    pub terms: Vec<Term>,
    /// Stiffness.
    pub stiffness: Stiffness,
    /// Viscous damping on the extension rate (N s/m, or N m s/rad), >= 0.
    pub damping: f64,
}

/// The lumped model of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Lumped {
    /// The bodies (the degrees of freedom), in order.
    pub bodies: Vec<Body>,
    /// The spring-dampers.
    pub couplings: Vec<Coupling>,
    /// The toolhead position (m) as a combination of coordinates.
    pub output: Vec<Term>,
    /// The body a stepper driver model pushes with a computed generalised force (the motor
    /// rotor), when the command enters through a driver instead of a coupling to
    /// [`Node::Command`].
    pub actuated: Option<usize>,
}

impl Lumped {
    /// The modal form: each mode is a unit mass on a spring-damper to the commanded
    /// position (`k = w^2`, `c = 2 zeta w`), so its deflection `e = q - x_cmd` obeys
    /// `e'' + 2 zeta w e' + w^2 e = -a_cmd`; the toolhead is
    /// `x_cmd + sum weight_i e_i = (1 - sum w_i) x_cmd + sum w_i q_i`.
    pub fn from_modes(modes: &[Mode]) -> Result<Self, SimError> {
        if modes.is_empty() {
            return Err(SimError::NoModes);
        }
        let mut bodies = Vec::with_capacity(modes.len());
        let mut couplings = Vec::with_capacity(modes.len());
        let mut output = Vec::with_capacity(modes.len() + 1);
        let mut rest = 1.0;
        for (i, m) in modes.iter().enumerate() {
            let w = m.omega();
            bodies.push(Body {
                name: format!("mode{i}"),
                kind: DofKind::Linear,
                inertia: 1.0,
            });
            couplings.push(Coupling {
                name: format!("mode{i}"),
                terms: vec![
                    Term {
                        node: Node::Body(i),
                        gain: 1.0,
                    },
                    Term {
                        node: Node::Command,
                        gain: -1.0,
                    },
                ],
                stiffness: Stiffness::Constant(w * w),
                damping: 2.0 * m.damping_ratio() * w,
            });
            output.push(Term {
                node: Node::Body(i),
                gain: m.weight(),
            });
            rest -= m.weight();
        }
        output.push(Term {
            node: Node::Command,
            gain: rest,
        });
        let l = Self {
            bodies,
            couplings,
            output,
            actuated: None,
        };
        l.validate()?;
        Ok(l)
    }

    /// Check every index and parameter.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |what: String| Err(SimError::InvalidModel { what });
        if self.bodies.is_empty() {
            return bad("a lumped model needs at least one body".into());
        }
        let n = self.bodies.len();
        for b in &self.bodies {
            if !(b.inertia.is_finite() && b.inertia > 0.0) {
                return bad(format!(
                    "body `{}`: inertia must be finite and > 0, got {}",
                    b.name, b.inertia
                ));
            }
        }
        let node_ok = |node: &Node| !matches!(node, Node::Body(i) if *i >= n);
        for c in &self.couplings {
            if c.terms.is_empty()
                || !c
                    .terms
                    .iter()
                    .all(|t| node_ok(&t.node) && t.gain.is_finite())
            {
                return bad(format!(
                    "coupling `{}`: needs terms on existing bodies with finite gains",
                    c.name
                ));
            }
            let k_ok = match c.stiffness {
                Stiffness::Constant(k) => k.is_finite() && k >= 0.0,
                Stiffness::BeltSpans {
                    ea_n,
                    length_m,
                    s0_m,
                    carriage,
                } => {
                    ea_n.is_finite()
                        && ea_n > 0.0
                        && length_m.is_finite()
                        && length_m > 2.0 * MIN_SPAN_M
                        && s0_m.is_finite()
                        && carriage < n
                }
            };
            if !(k_ok && c.damping.is_finite() && c.damping >= 0.0) {
                return bad(format!(
                    "coupling `{}`: stiffness and damping must be finite and >= 0",
                    c.name
                ));
            }
        }
        if self.output.is_empty() || !self.output.iter().all(|t| node_ok(&t.node)) {
            return bad("the output needs terms on existing bodies".into());
        }
        if self.actuated.is_some_and(|i| i >= n) {
            return bad("the actuated body does not exist".into());
        }
        Ok(())
    }

    /// Number of degrees of freedom.
    pub fn dof(&self) -> usize {
        self.bodies.len()
    }

    /// Diagonal mass matrix (kg, kg m^2).
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        DMatrix::from_diagonal(&DVector::from_iterator(
            self.dof(),
            self.bodies.iter().map(|b| b.inertia),
        ))
    }

    /// Stiffness matrix `K` and damping matrix `C` of the free coordinates, with every
    /// position-dependent stiffness evaluated at coordinates `q` (m, rad), and the input
    /// vectors `bk`, `bc` such that the equations of motion are
    /// `M q'' + C q' + K q = bk x_cmd + bc x_cmd' (+ driver force)`.
    pub fn linearised(&self, q: &[f64]) -> Linear {
        let n = self.dof();
        let mut k = DMatrix::zeros(n, n);
        let mut c = DMatrix::zeros(n, n);
        let mut bk = DVector::zeros(n);
        let mut bc = DVector::zeros(n);
        for cp in &self.couplings {
            let kk = cp
                .stiffness
                .at(cp.stiffness.depends_on().map_or(0.0, |i| q[i]));
            let cmd_gain: f64 = cp
                .terms
                .iter()
                .filter(|t| t.node == Node::Command)
                .map(|t| t.gain)
                .sum();
            for ti in &cp.terms {
                let Node::Body(i) = ti.node else { continue };
                for tj in &cp.terms {
                    if let Node::Body(j) = tj.node {
                        k[(i, j)] += kk * ti.gain * tj.gain;
                        c[(i, j)] += cp.damping * ti.gain * tj.gain;
                    }
                }
                bk[i] -= kk * ti.gain * cmd_gain;
                bc[i] -= cp.damping * ti.gain * cmd_gain;
            }
        }
        Linear {
            m: self.mass_matrix(),
            k,
            c,
            bk,
            bc,
        }
    }

    /// The toolhead position (m) for coordinates `q` and commanded position `x_cmd`.
    pub fn toolhead_m(&self, q: &[f64], x_cmd: f64) -> f64 {
        self.output
            .iter()
            .map(|t| {
                t.gain
                    * match t.node {
                        Node::Ground => 0.0,
                        Node::Command => x_cmd,
                        Node::Body(i) => q[i],
                    }
            })
            .sum()
    }
}

impl Lumped {
    /// The static equilibrium (m, rad) for a constant command `x_cmd` (m): every coupling
    /// relaxed, `K q = bk x_cmd`. With `fixed = Some((i, q_i))` body `i` is held at `q_i`
    /// and the others are solved for (used for a rotor whose equilibrium angle a stepper
    /// driver decides). Errors if some body is held by nothing.
    pub fn equilibrium(
        &self,
        x_cmd: f64,
        fixed: Option<(usize, f64)>,
    ) -> Result<Vec<f64>, SimError> {
        let n = self.dof();
        let mut q = vec![0.0; n];
        // Relaxed couplings do not depend on the stiffness values, but position-dependent
        // stiffnesses are evaluated near the answer anyway (two passes).
        for _ in 0..2 {
            let lin = self.linearised(&q);
            let free: Vec<usize> = (0..n)
                .filter(|&i| fixed.is_none_or(|(f, _)| f != i))
                .collect();
            let m = free.len();
            if m == 0 {
                if let Some((f, qf)) = fixed {
                    q[f] = qf;
                }
                break;
            }
            let mut k = DMatrix::zeros(m, m);
            let mut rhs = DVector::zeros(m);
            for (a, &i) in free.iter().enumerate() {
                rhs[a] = lin.bk[i] * x_cmd;
                if let Some((f, qf)) = fixed {
                    rhs[a] -= lin.k[(i, f)] * qf;
                }
                for (b, &j) in free.iter().enumerate() {
                    k[(a, b)] = lin.k[(i, j)];
                }
            }
            let sol = k
                .clone()
                .lu()
                .solve(&rhs)
                .filter(|s| s.iter().all(|x| x.is_finite()));
            let Some(sol) = sol else {
                return Err(SimError::InvalidModel {
                    what: "no static equilibrium: some body is held by no spring (a driver spring or an actuator is missing)".into(),
                });
            };
            for (a, &i) in free.iter().enumerate() {
                q[i] = sol[a];
            }
            if let Some((f, qf)) = fixed {
                q[f] = qf;
            }
        }
        Ok(q)
    }

    /// The stiffness of coupling `c` for coordinates `q` (N/m or N m/rad).
    #[inline]
    pub fn stiffness_of(c: &Coupling, q: &[f64]) -> f64 {
        c.stiffness
            .at(c.stiffness.depends_on().map_or(0.0, |i| q[i]))
    }

    /// The generalised force (N or N m) every coupling exerts on every body, for
    /// coordinates `q`, rates `qd`, command position `x_cmd` (m) and velocity `v_cmd`
    /// (m/s), written into `out` (one entry per body; overwritten). Position-dependent
    /// stiffnesses are evaluated at `stiffness_q` (pass `q` for the nonlinear model, or
    /// fixed coordinates to freeze them).
    pub fn generalised_forces(
        &self,
        q: &[f64],
        qd: &[f64],
        x_cmd: f64,
        v_cmd: f64,
        stiffness_q: &[f64],
        out: &mut [f64],
    ) {
        out.iter_mut().for_each(|f| *f = 0.0);
        let at = |node: Node, pos: bool| match node {
            Node::Ground => 0.0,
            Node::Command => {
                if pos {
                    x_cmd
                } else {
                    v_cmd
                }
            }
            Node::Body(i) => {
                if pos {
                    q[i]
                } else {
                    qd[i]
                }
            }
        };
        for c in &self.couplings {
            let (mut e, mut ed) = (0.0, 0.0);
            for t in &c.terms {
                e += t.gain * at(t.node, true);
                ed += t.gain * at(t.node, false);
            }
            let f = Self::stiffness_of(c, stiffness_q) * e + c.damping * ed;
            for t in &c.terms {
                if let Node::Body(i) = t.node {
                    out[i] -= f * t.gain;
                }
            }
        }
    }

    /// Undamped natural frequencies (Hz, ascending) of the model linearised at `q`: the
    /// square roots of the eigenvalues of `M^-1/2 K M^-1/2`. A body held by nothing
    /// (e.g. a rotor left to an actuator) gives a 0 Hz rigid-body mode.
    pub fn natural_frequencies_hz(&self, q: &[f64]) -> Vec<f64> {
        let lin = self.linearised(q);
        let n = self.dof();
        let s = DVector::from_iterator(n, (0..n).map(|i| 1.0 / lin.m[(i, i)].sqrt()));
        let kt = DMatrix::from_fn(n, n, |i, j| s[i] * lin.k[(i, j)] * s[j]);
        let mut f: Vec<f64> = kt
            .symmetric_eigenvalues()
            .iter()
            .map(|l| l.max(0.0).sqrt() / std::f64::consts::TAU)
            .collect();
        f.sort_by(f64::total_cmp);
        f
    }
}

/// `M q'' + C q' + K q = bk x_cmd + bc x_cmd'`: a lumped model linearised at a position.
#[derive(Debug, Clone, PartialEq)]
pub struct Linear {
    /// Mass matrix (diagonal).
    pub m: DMatrix<f64>,
    /// Stiffness matrix (symmetric).
    pub k: DMatrix<f64>,
    /// Damping matrix (symmetric).
    pub c: DMatrix<f64>,
    /// Input of the commanded position.
    pub bk: DVector<f64>,
    /// Input of the commanded velocity.
    pub bc: DVector<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modal_form_reproduces_each_mode() {
        let modes = [
            Mode::new(40.0, 0.05, 0.7).expect("mode"),
            Mode::new(120.0, 0.02, 0.3).expect("mode"),
        ];
        let l = Lumped::from_modes(&modes).expect("lumped");
        let lin = l.linearised(&[0.0, 0.0]);
        for (i, m) in modes.iter().enumerate() {
            let w = m.omega();
            // K_ii / M_ii = w^2 and C_ii / M_ii = 2 zeta w; no coupling between modes.
            assert!((lin.k[(i, i)] / lin.m[(i, i)] - w * w).abs() <= 1e-9 * w * w);
            assert!(
                (lin.c[(i, i)] / lin.m[(i, i)] - 2.0 * m.damping_ratio() * w).abs() <= 1e-12 * w
            );
            assert_eq!(lin.k[(i, 1 - i)], 0.0);
            // Static equilibrium under a constant command x: K q = bk x gives q = x.
            assert!((lin.bk[i] - lin.k[(i, i)]).abs() <= 1e-9 * w * w);
        }
        // At equilibrium (q = x_cmd) the toolhead is at the command.
        assert!((l.toolhead_m(&[0.25, 0.25], 0.25) - 0.25).abs() < 1e-15);
        // Deflections add with their weights.
        let th = l.toolhead_m(&[0.25 + 1e-3, 0.25 - 2e-3], 0.25);
        assert!((th - (0.25 + 0.7e-3 - 0.6e-3)).abs() < 1e-15);
    }

    #[test]
    fn belt_spans_stiffen_towards_the_ends() {
        let s = Stiffness::BeltSpans {
            ea_n: 10_000.0,
            length_m: 0.5,
            s0_m: 0.25,
            carriage: 0,
        };
        // Middle: 2 EA / (L/2) = 80 kN/m; 0.2 m off-centre: EA/0.05 + EA/0.45.
        assert!((s.at(0.0) - 80_000.0).abs() < 1e-6);
        assert!((s.at(-0.2) - (10_000.0 / 0.05 + 10_000.0 / 0.45)).abs() < 1e-6);
        assert_eq!(s.at(-0.2), s.at(0.2));
        // Clamped at the ends of travel instead of dividing by zero.
        assert!(s.at(-1.0).is_finite());
    }

    #[test]
    fn invalid_models_are_rejected() {
        let mut l = Lumped::from_modes(&[Mode::new(40.0, 0.05, 1.0).expect("mode")]).expect("ok");
        l.bodies[0].inertia = 0.0;
        assert!(matches!(l.validate(), Err(SimError::InvalidModel { .. })));
        let mut l = Lumped::from_modes(&[Mode::new(40.0, 0.05, 1.0).expect("mode")]).expect("ok");
        l.couplings[0].terms[0].node = Node::Body(3);
        assert!(l.validate().is_err());
    }
}
