//! MJCF generation: a [`Lumped`] model as a MuJoCo model description.
//!
//! Every body becomes its own kinematic tree under the world, with one joint:
//! - [`DofKind::Linear`]: a slide joint along x; the body's mass is the inertia (kg).
//! - [`DofKind::Angular`]: a hinge about x; the rotor inertia is the joint `armature`
//!   (kg m^2), the body itself carries only a token inertia (MuJoCo needs one > 0) that is
//!   subtracted from the armature, so the joint's total inertia is the lumped inertia.
//!
//! Joint `i` is body `i`, so MuJoCo's `qpos[i]` / `qvel[i]` are the lumped coordinates `q_i`
//! and their rates. Every coupling becomes a fixed tendon whose length is its extension
//! `sum gain_k q_k` (`coef` = gain), with the coupling's stiffness, damping and
//! `springlength = 0`; MuJoCo's passive tendon force `-(k L + c L')` times `coef` on each
//! joint is exactly the lumped force law.
//!
//! The kinematic command ([`Node::Command`]) is one more slide joint (`command`) on a body
//! so heavy (see [`COMMAND_MASS_FACTOR`]) that the springs' reaction moves it by nothing
//! measurable. An `integrator`-dynamics actuator drives it: its activation is the commanded
//! acceleration, its control the (constant) commanded jerk, and its force
//! `gain * activation` with `gain` = the command body's mass. With the command joint's
//! position, velocity and the activation set to the commanded `p, v, a` at each step start,
//! MuJoCo's RK4 integrates `x''' = j` exactly (a cubic is inside RK4's order), so the
//! command follows the profile exactly within the step, also at the intermediate stages.
//!
//! The driver torque on the [`Lumped::actuated`] body enters through a `motor` actuator
//! (`drive`, gear 1, unlimited): its control is the generalised force (N m or N).
//!
//! A position-dependent stiffness ([`Stiffness::BeltSpans`]) is the tendon's stiffness at
//! coordinate 0 plus an actuator on the same tendon with an affine gain
//! (`gainprm = "0 1 0"`: force = tendon length * control): with the control set to
//! `-(k(q) - k(0))` before each step, the total tendon force is `-(k(q) e + c e')` with the
//! extension `e` varying inside the step and `k` held at its value at the predicted
//! mid-step coordinates. (Changing the tendon stiffness itself would need a model swap per
//! step, whose layout check costs more than the step.)
//!
//! Gravity, contacts, constraints and MuJoCo's automatic reset are disabled: the lumped
//! model has none of them, and a diverging run must surface as an error, not a silent reset.

use std::fmt::Write as _;

use crate::lumped::{DofKind, Lumped, Node, Stiffness};

/// The command body's mass is this times the largest lumped inertia (kg, and at least
/// this many kg): the springs' reaction on it then changes its acceleration by about
/// `1e-10` of the force per kg, far below anything a run measures, and the state is reset
/// to the exact command at every step start anyway.
pub const COMMAND_MASS_FACTOR: f64 = 1e10;

/// The share of an angular body's inertia carried by the body (the rest is armature).
const ANGULAR_BODY_SHARE: f64 = 1.0 / 1024.0;

/// MuJoCo's time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Classic 4th-order Runge-Kutta: frequency error `(w h)^4 / 120`, numerical damping
    /// ratio `(w h)^5 / 144` for an undamped spring; the default, measured in the tests.
    #[default]
    Rk4,
    /// Semi-implicit Euler (implicit in joint damping only): frequency error of order
    /// `(w h)^2`. For comparison only.
    Euler,
    /// Implicit in velocity-dependent forces (`implicitfast`), first order. For comparison
    /// only.
    ImplicitFast,
}

impl Integrator {
    /// The MJCF attribute value.
    pub fn mjcf_name(self) -> &'static str {
        match self {
            Integrator::Rk4 => "RK4",
            Integrator::Euler => "Euler",
            Integrator::ImplicitFast => "implicitfast",
        }
    }
}

/// Where the generated model keeps what the stepper needs.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layout {
    /// Number of lumped bodies (= joints `0..n`).
    pub bodies: usize,
    /// The command joint's `qpos`/`qvel` index and its actuator's index. Its activation is
    /// `act[0]`: it is the only actuator with one.
    pub command: Option<(usize, usize)>,
    /// The `drive` actuator's index.
    pub drive: Option<usize>,
    /// For every position-dependent coupling: the index of the actuator that adds
    /// `-(k(q) - k_ref) * extension`, its stiffness law and `k_ref` (its stiffness at
    /// coordinate 0, the tendon's own stiffness).
    pub variable: Vec<(usize, Stiffness, f64)>,
}

/// A name usable as an MJCF identifier: `prefix{index}_{name}` with anything but
/// `[A-Za-z0-9_-.]` replaced by `_` (unique through the index, readable through the name).
fn ident(prefix: &str, index: usize, name: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{prefix}{index}_{clean}")
}

/// Joint name of body `i`.
fn joint_name(l: &Lumped, i: usize) -> String {
    ident("q", i, &l.bodies[i].name)
}

/// Generate the MJCF for `lumped` (validated by the caller) with time step `timestep_s` and
/// `integrator`, and the layout of the generated model.
pub(crate) fn generate(
    lumped: &Lumped,
    timestep_s: f64,
    integrator: Integrator,
) -> (String, Layout) {
    let uses_command = lumped
        .couplings
        .iter()
        .any(|c| c.terms.iter().any(|t| t.node == Node::Command));
    let max_inertia = lumped
        .bodies
        .iter()
        .map(|b| b.inertia)
        .fold(1.0f64, f64::max);
    let command_mass = COMMAND_MASS_FACTOR * max_inertia;

    let mut x = String::new();
    // Writing to a String cannot fail.
    let mut w = |s: std::fmt::Arguments| x.write_fmt(s).expect("write to String");
    w(format_args!(
        "<mujoco model=\"settle-lumped\">\n  <compiler angle=\"radian\"/>\n"
    ));
    w(format_args!(
        "  <option timestep=\"{timestep_s:e}\" integrator=\"{}\" gravity=\"0 0 0\">\n    \
         <flag contact=\"disable\" constraint=\"disable\" gravity=\"disable\" \
         autoreset=\"disable\" warmstart=\"disable\" sensor=\"disable\"/>\n  </option>\n",
        integrator.mjcf_name()
    ));
    w(format_args!("  <worldbody>\n"));
    for (i, b) in lumped.bodies.iter().enumerate() {
        let body = ident("b", i, &b.name);
        let joint = joint_name(lumped, i);
        match b.kind {
            DofKind::Linear => {
                w(format_args!(
                    "    <body name=\"{body}\">\n      <joint name=\"{joint}\" type=\"slide\" \
                     axis=\"1 0 0\"/>\n      <inertial pos=\"0 0 0\" mass=\"{m:e}\" \
                     diaginertia=\"{m:e} {m:e} {m:e}\"/>\n    </body>\n",
                    m = b.inertia
                ));
            }
            DofKind::Angular => {
                let own = b.inertia * ANGULAR_BODY_SHARE;
                w(format_args!(
                    "    <body name=\"{body}\">\n      <joint name=\"{joint}\" type=\"hinge\" \
                     axis=\"1 0 0\" armature=\"{arm:e}\"/>\n      <inertial pos=\"0 0 0\" \
                     mass=\"{own:e}\" diaginertia=\"{own:e} {own:e} {own:e}\"/>\n    </body>\n",
                    arm = b.inertia - own
                ));
            }
        }
    }
    if uses_command {
        w(format_args!(
            "    <body name=\"command\">\n      <joint name=\"command\" type=\"slide\" \
             axis=\"1 0 0\"/>\n      <inertial pos=\"0 0 0\" mass=\"{command_mass:e}\" \
             diaginertia=\"1 1 1\"/>\n    </body>\n"
        ));
    }
    w(format_args!("  </worldbody>\n"));

    let mut variable = Vec::new();
    let mut tendons = 0usize;
    let mut tendon_xml = String::new();
    for (ci, c) in lumped.couplings.iter().enumerate() {
        // Merge repeated nodes; the ground contributes nothing.
        let mut coefs: Vec<(String, f64)> = Vec::new();
        for t in &c.terms {
            let name = match t.node {
                Node::Ground => continue,
                Node::Command => "command".to_string(),
                Node::Body(i) => joint_name(lumped, i),
            };
            match coefs.iter_mut().find(|(n, _)| *n == name) {
                Some((_, g)) => *g += t.gain,
                None => coefs.push((name, t.gain)),
            }
        }
        coefs.retain(|(_, g)| *g != 0.0);
        if coefs.is_empty() {
            continue; // Acts on nothing that moves.
        }
        // A position-dependent stiffness: its value at coordinate 0 here, the rest through
        // an actuator (below).
        let k = c.stiffness.at(0.0);
        if c.stiffness.depends_on().is_some() {
            variable.push((ident("c", ci, &c.name), c.stiffness, k));
        }
        let _ = writeln!(
            tendon_xml,
            "    <fixed name=\"{}\" stiffness=\"{k:e}\" damping=\"{:e}\" springlength=\"0\">",
            ident("c", ci, &c.name),
            c.damping
        );
        for (joint, g) in coefs {
            let _ = writeln!(
                tendon_xml,
                "      <joint joint=\"{joint}\" coef=\"{g:e}\"/>"
            );
        }
        let _ = writeln!(tendon_xml, "    </fixed>");
        tendons += 1;
    }
    if tendons > 0 {
        w(format_args!("  <tendon>\n{tendon_xml}  </tendon>\n"));
    }

    let mut actuators = 0usize;
    let mut actuator_xml = String::new();
    let drive = lumped.actuated.map(|i| {
        let _ = writeln!(
            actuator_xml,
            "    <motor name=\"drive\" joint=\"{}\" gear=\"1\" ctrllimited=\"false\" \
             forcelimited=\"false\"/>",
            joint_name(lumped, i)
        );
        actuators += 1;
        actuators - 1
    });
    let variable = variable
        .into_iter()
        .map(|(tendon, stiffness, k_ref)| {
            let _ = writeln!(
                actuator_xml,
                "    <general name=\"{tendon}_stiffness\" tendon=\"{tendon}\" gaintype=\"affine\" \
                 gainprm=\"0 1 0\" biastype=\"none\" ctrllimited=\"false\" \
                 forcelimited=\"false\"/>"
            );
            actuators += 1;
            (actuators - 1, stiffness, k_ref)
        })
        .collect();
    let command = uses_command.then(|| {
        let _ = writeln!(
            actuator_xml,
            "    <general name=\"command\" joint=\"command\" dyntype=\"integrator\" \
             gaintype=\"fixed\" gainprm=\"{command_mass:e}\" biastype=\"none\" \
             ctrllimited=\"false\" forcelimited=\"false\" actlimited=\"false\"/>"
        );
        actuators += 1;
        (lumped.bodies.len(), actuators - 1)
    });
    if actuators > 0 {
        w(format_args!("  <actuator>\n{actuator_xml}  </actuator>\n"));
    }
    w(format_args!("</mujoco>\n"));
    (
        x,
        Layout {
            bodies: lumped.bodies.len(),
            command,
            drive,
            variable,
        },
    )
}
