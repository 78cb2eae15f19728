//! Compiling a machine axis into the lumped model and stepper every backend simulates.

use super::{AxisMachine, Machine, Transmission};
use crate::SimError;
use crate::axis::{AxisModel, DriverMode};
use crate::lumped::{Body, Coupling, DofKind, Lumped, Node, Stiffness, Term};
use crate::stepper::Stepper;

/// Body order of a compiled axis.
pub const ROTOR: usize = 0;
/// The carriage body (with the beam).
pub const CARRIAGE: usize = 1;
/// The toolhead body.
pub const TOOLHEAD: usize = 2;
/// The frame body, when there is a frame mode.
pub const FRAME: usize = 3;

fn term(node: Node, gain: f64) -> Term {
    Term { node, gain }
}

impl AxisMachine {
    /// The motor and driver as the simulation sees them (SI, rotor = body 0).
    pub fn stepper(&self) -> Stepper {
        let m = &self.motor;
        let d = &self.driver;
        let km = m.holding_torque_n_m / (std::f64::consts::SQRT_2 * m.rated_current_a);
        let current_a = std::f64::consts::SQRT_2 * d.run_current_a_rms;
        let j = m.rotor_inertia_g_cm2 * 1e-7;
        let k_theta = km * current_a * f64::from(m.rotor_teeth);
        Stepper {
            rotor: ROTOR,
            rad_per_m: self.rad_per_m(),
            rotor_teeth: m.rotor_teeth,
            microsteps: d.microsteps,
            torque_constant_n_m_per_a: km,
            current_a,
            resistance_ohm: m.resistance_ohm,
            inductance_h: m.inductance_mh * 1e-3,
            detent_torque_n_m: m.detent_torque_n_m,
            supply_v: d.supply_v,
            damping_n_m_s_per_rad: 2.0 * m.damping_ratio * (k_theta * j).sqrt(),
            current_loop_bandwidth_hz: d.current_loop_bandwidth_hz,
        }
    }

    /// Compile into bodies `rotor, carriage (+beam), toolhead[, frame]` and couplings
    /// `belt|screw, mount[, frame]` plus, in the linear and spring driver modes, `driver`
    /// (a spring `k_theta = Km I Nr` from the rotor to the command). The toolhead body is
    /// the output. Every body starts at the static equilibrium of the start command.
    pub fn compile(&self, mode: DriverMode) -> Result<AxisModel, SimError> {
        self.validate()?;
        let stepper = self.stepper();
        let r = 1.0 / stepper.rad_per_m;
        let mut bodies = vec![
            Body {
                name: "rotor".into(),
                kind: DofKind::Angular,
                inertia: self.motor.rotor_inertia_g_cm2 * 1e-7,
            },
            Body {
                name: "carriage".into(),
                kind: DofKind::Linear,
                inertia: self.carriage_kg + self.beam_kg,
            },
            Body {
                name: "toolhead".into(),
                kind: DofKind::Linear,
                inertia: self.toolhead_kg,
            },
        ];
        let moving = self.moving_kg();
        // Belt or screw: extension = (carriage - frame) - r * rotor (m).
        let mut drive_terms = vec![term(Node::Body(CARRIAGE), 1.0), term(Node::Body(ROTOR), -r)];
        if self.frame.is_some() {
            drive_terms.push(term(Node::Body(FRAME), -1.0));
        }
        let (name, stiffness, k_ref, zeta) = match &self.transmission {
            Transmission::Belt(b) => {
                let s = Stiffness::BeltSpans {
                    ea_n: b.ea_n,
                    length_m: 2.0 * b.span_mm * 1e-3,
                    s0_m: b.carriage_at_zero_mm * 1e-3,
                    carriage: CARRIAGE,
                };
                ("belt", s, s.at(0.0), b.damping_ratio)
            }
            Transmission::Screw(s) => (
                "screw",
                Stiffness::Constant(s.stiffness_n_per_m),
                s.stiffness_n_per_m,
                s.damping_ratio,
            ),
        };
        let mut couplings = vec![
            Coupling {
                name: name.into(),
                terms: drive_terms,
                stiffness,
                damping: 2.0 * zeta * (k_ref * moving).sqrt(),
            },
            Coupling {
                name: "mount".into(),
                terms: vec![
                    term(Node::Body(TOOLHEAD), 1.0),
                    term(Node::Body(CARRIAGE), -1.0),
                ],
                stiffness: Stiffness::Constant(self.mount.stiffness_n_per_m),
                damping: 2.0
                    * self.mount.damping_ratio
                    * (self.mount.stiffness_n_per_m * self.toolhead_kg).sqrt(),
            },
        ];
        if let Some(f) = &self.frame {
            bodies.push(Body {
                name: "frame".into(),
                kind: DofKind::Linear,
                inertia: f.mass_kg,
            });
            couplings.push(Coupling {
                name: "frame".into(),
                terms: vec![term(Node::Body(FRAME), 1.0)],
                stiffness: Stiffness::Constant(f.stiffness_n_per_m),
                damping: 2.0 * f.damping_ratio * (f.stiffness_n_per_m * f.mass_kg).sqrt(),
            });
        }
        let actuated = match mode {
            DriverMode::Full => Some(ROTOR),
            DriverMode::Linear | DriverMode::Spring => {
                couplings.push(Coupling {
                    name: "driver".into(),
                    terms: vec![
                        term(Node::Body(ROTOR), 1.0),
                        term(Node::Command, -stepper.rad_per_m),
                    ],
                    stiffness: Stiffness::Constant(stepper.k_theta()),
                    damping: stepper.damping_n_m_s_per_rad,
                });
                None
            }
        };
        let model = AxisModel {
            name: self.name.clone(),
            lumped: Lumped {
                bodies,
                couplings,
                output: vec![term(Node::Body(TOOLHEAD), 1.0)],
                actuated,
            },
            mode,
            stepper: Some(stepper),
            carriage: Some(CARRIAGE),
        };
        model.validate()?;
        Ok(model)
    }
}

impl Machine {
    /// Compile every axis.
    pub fn compile(&self, mode: DriverMode) -> Result<Vec<AxisModel>, SimError> {
        self.validate()?;
        self.axes.iter().map(|a| a.compile(mode)).collect()
    }
}
