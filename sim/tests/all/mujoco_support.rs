//! Shared by the MuJoCo tests: the stepping schedule of a profile, the exact solution of a
//! linear lumped model (matrix exponential, independent of MuJoCo), an independent
//! fine-step RK4 for position-dependent stiffness, and a printer-axis lumped model.

#![allow(dead_code)] // Each test file uses part of this module.

use nalgebra::{DMatrix, DVector};
use settle_planner::{Profile, Sample};
use settle_sim::lumped::{Body, Coupling, DofKind, Linear, Lumped, Node, Stiffness, Term};

/// One interval of a run: start time (s), the commanded sample at its start (constant
/// jerk over it) and its length (s).
#[derive(Debug, Clone, Copy)]
pub struct Interval {
    pub t0: f64,
    pub cmd: Sample,
    pub h: f64,
}

/// The intervals that step through `profile` on a grid of `dt` (s), split at segment
/// boundaries, then hold the end point until `t_stop` (s). Every backend under comparison
/// steps through the same list.
pub fn schedule(profile: &Profile, dt: f64, t_stop: f64) -> Vec<Interval> {
    let mut out = Vec::new();
    for (t0, s0, seg) in profile.iter() {
        let t1 = t0 + seg.duration_s();
        let mut t = t0;
        while t < t1 {
            let next = ((t / dt + 1e-9).floor() + 1.0) * dt;
            let next = next.min(t1);
            out.push(Interval {
                t0: t,
                cmd: seg.sample(&s0, t - t0),
                h: next - t,
            });
            t = next;
        }
    }
    let end = profile.end();
    let hold = Sample {
        p: end.p,
        v: 0.0,
        a: 0.0,
        j: 0.0,
    };
    let mut t = profile.duration_s();
    while t < t_stop - 1e-12 {
        let next = (((t / dt) + 1e-9).floor() + 1.0) * dt;
        let next = next.min(t_stop);
        out.push(Interval {
            t0: t,
            cmd: hold,
            h: next - t,
        });
        t = next;
    }
    out
}

/// The exact solution of `M q'' + C q' + K q = bk x + bc x' + e_d f` for a command with
/// piecewise-constant jerk and a piecewise-constant driver force `f` on body `d`: the
/// augmented state `z = [q, q', x, v, a, j, f]` evolves as `z' = A z`, so an interval of
/// length h is `exp(A h)` (nalgebra's Pade scaling-and-squaring).
#[derive(Debug, Clone)]
pub struct Exact {
    a: DMatrix<f64>,
    n: usize,
    cache: Vec<(f64, DMatrix<f64>)>,
}

impl Exact {
    pub fn new(lin: &Linear, drive: Option<usize>) -> Self {
        let n = lin.m.nrows();
        let dim = 2 * n + 5;
        let mut a = DMatrix::zeros(dim, dim);
        for i in 0..n {
            let mi = lin.m[(i, i)];
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -lin.k[(i, j)] / mi;
                a[(n + i, n + j)] = -lin.c[(i, j)] / mi;
            }
            a[(n + i, 2 * n)] = lin.bk[i] / mi;
            a[(n + i, 2 * n + 1)] = lin.bc[i] / mi;
            if drive == Some(i) {
                a[(n + i, 2 * n + 4)] = 1.0 / mi;
            }
        }
        a[(2 * n, 2 * n + 1)] = 1.0;
        a[(2 * n + 1, 2 * n + 2)] = 1.0;
        a[(2 * n + 2, 2 * n + 3)] = 1.0;
        Self {
            a,
            n,
            cache: Vec::new(),
        }
    }

    fn phi(&mut self, h: f64) -> DMatrix<f64> {
        if let Some((_, p)) = self.cache.iter().find(|(hh, _)| *hh == h) {
            return p.clone();
        }
        let p = (&self.a * h).exp();
        if self.cache.len() < 8 {
            self.cache.push((h, p.clone()));
        }
        p
    }

    /// Advance `(q, qd)` over an interval with command sample `cmd` and force `f`.
    pub fn step(&mut self, q: &mut [f64], qd: &mut [f64], cmd: &Sample, f: f64, h: f64) {
        let n = self.n;
        let mut z = DVector::zeros(2 * n + 5);
        for i in 0..n {
            z[i] = q[i];
            z[n + i] = qd[i];
        }
        z[2 * n] = cmd.p;
        z[2 * n + 1] = cmd.v;
        z[2 * n + 2] = cmd.a;
        z[2 * n + 3] = cmd.j;
        z[2 * n + 4] = f;
        let z1 = self.phi(h) * z;
        for i in 0..n {
            q[i] = z1[i];
            qd[i] = z1[n + i];
        }
    }
}

/// Generalised accelerations of `lumped` under the lumped force law (the documented one,
/// written independently of every backend): each coupling pushes body i with
/// `-(k(q) e + c e') gain_i`, with position-dependent stiffness evaluated at `q`.
pub fn accelerations(l: &Lumped, q: &[f64], qd: &[f64], x: f64, v: f64, f: f64) -> Vec<f64> {
    let mut force = vec![0.0; l.dof()];
    for c in &l.couplings {
        let (mut e, mut ed) = (0.0, 0.0);
        for t in &c.terms {
            let (p, r) = match t.node {
                Node::Ground => (0.0, 0.0),
                Node::Command => (x, v),
                Node::Body(i) => (q[i], qd[i]),
            };
            e += t.gain * p;
            ed += t.gain * r;
        }
        let k = c
            .stiffness
            .at(c.stiffness.depends_on().map_or(0.0, |i| q[i]));
        let push = -(k * e + c.damping * ed);
        for t in &c.terms {
            if let Node::Body(i) = t.node {
                force[i] += push * t.gain;
            }
        }
    }
    if let Some(i) = l.actuated {
        force[i] += f;
    }
    force
        .iter()
        .zip(&l.bodies)
        .map(|(fi, b)| fi / b.inertia)
        .collect()
}

/// Independent classic RK4 of the lumped equations with the exact command at every stage
/// time and every stiffness re-evaluated at every stage, with `sub` substeps per interval.
pub fn rk4_interval(
    l: &Lumped,
    q: &mut [f64],
    qd: &mut [f64],
    cmd: &Sample,
    f: f64,
    h: f64,
    sub: usize,
) {
    let n = l.dof();
    let hs = h / sub as f64;
    let at = |tau: f64| {
        (
            cmd.p + tau * (cmd.v + tau * (cmd.a / 2.0 + tau * cmd.j / 6.0)),
            cmd.v + tau * (cmd.a + tau * cmd.j / 2.0),
        )
    };
    for s in 0..sub {
        let t = s as f64 * hs;
        let deriv = |tau: f64, q: &[f64], qd: &[f64]| {
            let (x, v) = at(tau);
            (qd.to_vec(), accelerations(l, q, qd, x, v, f))
        };
        let add = |a: &[f64], b: &[f64], s: f64| -> Vec<f64> {
            a.iter().zip(b).map(|(x, y)| x + s * y).collect()
        };
        let (k1q, k1v) = deriv(t, q, qd);
        let (k2q, k2v) = deriv(
            t + hs / 2.0,
            &add(q, &k1q, hs / 2.0),
            &add(qd, &k1v, hs / 2.0),
        );
        let (k3q, k3v) = deriv(
            t + hs / 2.0,
            &add(q, &k2q, hs / 2.0),
            &add(qd, &k2v, hs / 2.0),
        );
        let (k4q, k4v) = deriv(t + hs, &add(q, &k3q, hs), &add(qd, &k3v, hs));
        for i in 0..n {
            q[i] += hs / 6.0 * (k1q[i] + 2.0 * k2q[i] + 2.0 * k3q[i] + k4q[i]);
            qd[i] += hs / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
        }
    }
}

/// A belt-driven printer axis (NEMA17 + 20T GT2), bodies in order rotor, carriage,
/// toolhead:
/// - rotor J = 6.8e-6 kg m^2 (a 48 mm NEMA17, ~68 g cm^2), pulley radius
///   r = 20 * 2 mm / 2 pi = 6.366 mm;
/// - driver as a stiff spring to the commanded angle x/r (when `driver_spring`):
///   k_theta = 12 N m/rad (0.45 N m holding torque at 0.8/1.5 of rated current times 50
///   rotor teeth), damping 9e-4 N m s/rad (zeta ~0.05 of the rotor mode);
/// - belt (rotor -> carriage): `belt` stiffness, 7.2 N s/m (zeta ~0.02);
/// - carriage 0.2 kg, toolhead 0.5 kg on a 100 kN/m mount with 22.4 N s/m (zeta ~0.05).
///
/// With a 160 kN/m belt the undamped modes are 48, 158 and 282 Hz.
pub fn printer_axis(belt: Stiffness, driver_spring: bool) -> Lumped {
    let r = 20.0 * 0.002 / std::f64::consts::TAU;
    let body = |name: &str, kind, inertia| Body {
        name: name.into(),
        kind,
        inertia,
    };
    let t = |node, gain| Term { node, gain };
    let mut couplings = vec![
        Coupling {
            name: "belt".into(),
            terms: vec![t(Node::Body(1), 1.0), t(Node::Body(0), -r)],
            stiffness: belt,
            damping: 7.2,
        },
        Coupling {
            name: "mount".into(),
            terms: vec![t(Node::Body(2), 1.0), t(Node::Body(1), -1.0)],
            stiffness: Stiffness::Constant(1.0e5),
            damping: 22.4,
        },
    ];
    if driver_spring {
        couplings.insert(
            0,
            Coupling {
                name: "driver".into(),
                terms: vec![t(Node::Body(0), 1.0), t(Node::Command, -1.0 / r)],
                stiffness: Stiffness::Constant(12.0),
                damping: 9e-4,
            },
        );
    }
    let l = Lumped {
        bodies: vec![
            body("rotor", DofKind::Angular, 6.8e-6),
            body("carriage", DofKind::Linear, 0.2),
            body("toolhead", DofKind::Linear, 0.5),
        ],
        couplings,
        output: vec![t(Node::Body(2), 1.0)],
        actuated: Some(0),
    };
    l.validate().expect("valid printer axis");
    l
}

/// Belt loop of the printer axis: EA = 20 kN, 0.5 m from drive pulley to idler, the
/// carriage in the middle at coordinate 0 (k = 160 kN/m there).
pub fn belt_spans() -> Stiffness {
    Stiffness::BeltSpans {
        ea_n: 20_000.0,
        length_m: 0.5,
        s0_m: 0.25,
        carriage: 1,
    }
}

/// One axis through the uniform single-axis interface these tests compare backends with:
/// start at rest, step an interval, read the toolhead. (The harness drives plants through
/// the multi-axis `Plant` trait; these tests compare one lumped axis at a time.)
pub trait OneAxis {
    type S;
    fn initial_state(&self, start: &settle_planner::State) -> Self::S;
    fn step(&self, st: &mut Self::S, cmd: &Sample, h: f64);
    fn toolhead_m(&self, st: &Self::S) -> f64;
}

/// MuJoCo's core model (build, step, read) as a [`OneAxis`].
pub struct MujocoOne(pub settle_sim::mujoco::MujocoModel);

impl MujocoOne {
    pub fn new(l: &Lumped, config: settle_sim::mujoco::MujocoConfig) -> Self {
        Self(settle_sim::mujoco::MujocoModel::new(l, config).expect("MuJoCo model"))
    }
    pub fn model(&self) -> &settle_sim::mujoco::MujocoModel {
        &self.0
    }
}

impl OneAxis for MujocoOne {
    type S = settle_sim::mujoco::MujocoSim;
    fn initial_state(&self, start: &settle_planner::State) -> Self::S {
        self.0.state_at_rest(start)
    }
    fn step(&self, st: &mut Self::S, cmd: &Sample, h: f64) {
        self.0.advance(st, cmd, h).expect("step");
    }
    fn toolhead_m(&self, st: &Self::S) -> f64 {
        self.0.toolhead_m(st)
    }
}

/// The exact modal plant of one axis described by its modes, as a [`OneAxis`].
pub struct ModalOne(pub settle_sim::ModalPlant);

impl ModalOne {
    pub fn new(modes: &[settle_sim::Mode], dt: f64) -> Self {
        let axis = settle_sim::AxisModel::from_modes("x", modes).expect("axis");
        Self(settle_sim::ModalPlant::new(vec![axis], dt).expect("modal plant"))
    }
}

impl OneAxis for ModalOne {
    type S = <settle_sim::ModalPlant as settle_sim::Plant>::State;
    fn initial_state(&self, start: &settle_planner::State) -> Self::S {
        settle_sim::Plant::initial_state(&self.0, std::slice::from_ref(start)).expect("state")
    }
    fn step(&self, st: &mut Self::S, cmd: &Sample, h: f64) {
        settle_sim::Plant::step(&self.0, st, std::slice::from_ref(cmd), h).expect("step");
    }
    fn toolhead_m(&self, st: &Self::S) -> f64 {
        let mut o = [settle_sim::Observation::default()];
        settle_sim::Plant::observe(&self.0, st, &mut o);
        o[0].toolhead_m
    }
}
