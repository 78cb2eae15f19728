//! The machine description: constant physical parameters of a gantry, per axis, in the
//! units datasheets use (units in every name). [`AxisMachine::compile`] turns an axis into
//! the [`crate::AxisModel`] every backend simulates.
//!
//! Per axis (DESIGN.md, Physics):
//! `rotor (J) --driver (k_theta = Km I Nr)-- command`,
//! `rotor --pulley r / screw lead-- belt or screw -- carriage (+ beam)`,
//! `carriage --mount (k, c)-- toolhead`, optionally `frame (m_f, k_f)` carrying the motor and
//! the idler (the belt is stretched between carriage and frame).
//!
//! Damping is given as damping ratios, each against a documented reference (the element's
//! stiffness and the mass it carries), because that is what people measure and compare:
//! `c = 2 zeta sqrt(k m_ref)`.
//!
//! The field names are the keys of machine files (settle's `docs/reference/machine-file.md`):
//! the parts read and write themselves through serde under those names, so they are
//! known in one place, here.

mod compile;

use serde::{Deserialize, Serialize};

use crate::SimError;

/// A whole machine: one or more axes (X, Y, ...), dynamically independent.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// Name, for reports.
    pub name: String,
    /// The axes, in order (axis 0 is X by convention).
    pub axes: Vec<AxisMachine>,
}

/// One axis of a gantry. As a table it is a machine file's `[axis.<name>]` with its
/// `motor` and `driver` in it (the transmission as its `belt` or `screw` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisMachine {
    /// Axis name (`x`, `y`, ...).
    pub name: String,
    /// Carriage mass (kg): what rides on the guide and is clamped to the belt or nut.
    pub carriage_kg: f64,
    /// Toolhead mass (kg): what sits on the carriage through the mount.
    pub toolhead_kg: f64,
    /// Mass rigidly carried with the carriage besides itself (kg): for a Y axis, the X beam
    /// with its rail, the X motor and the X carriage. 0 when there is none.
    #[serde(default)]
    pub beam_kg: f64,
    /// Belt or screw.
    #[serde(flatten)]
    pub transmission: Transmission,
    /// Toolhead-to-carriage mount.
    pub mount: Mount,
    /// The frame mode, if modelled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<Frame>,
    /// The motor.
    pub motor: Motor,
    /// The driver.
    pub driver: Driver,
}

/// How the motor moves the carriage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Transmission {
    /// A toothed belt loop from the drive pulley around an idler.
    Belt(Belt),
    /// A lead screw or ball screw.
    Screw(Screw),
}

/// A timing belt: drive pulley at one end, free idler at the other, carriage clamped to
/// one strand. The carriage is held by the span to the pulley (length s) and, in parallel,
/// by the path around the idler back to the pulley (length 2 L - s):
/// `k = EA/s + EA/(2 L - s)`, stiffest near the motor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Belt {
    /// Axial stiffness E*A (N).
    pub ea_n: f64,
    /// Drive-pulley-to-idler distance L (mm).
    pub span_mm: f64,
    /// Teeth on the drive pulley.
    pub pulley_teeth: u32,
    /// Belt pitch (mm): 2 for GT2 (the default).
    #[serde(default = "gt2_pitch_mm")]
    pub pitch_mm: f64,
    /// Belt length from the drive pulley to the carriage clamp when the axis is at
    /// position 0 (mm). Positive axis moves lengthen it.
    pub carriage_at_zero_mm: f64,
    /// Damping ratio of the belt against the mass it carries (carriage, beam and toolhead).
    pub damping_ratio: f64,
}

/// A lead screw or ball screw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Screw {
    /// Lead: travel per revolution (mm).
    pub lead_mm: f64,
    /// Axial stiffness of screw, nut and support bearings in series (N/m), taken constant.
    pub stiffness_n_per_m: f64,
    /// Damping ratio against the mass it carries (carriage, beam and toolhead).
    pub damping_ratio: f64,
}

/// The toolhead's mount on the carriage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mount {
    /// Stiffness along the axis (N/m).
    pub stiffness_n_per_m: f64,
    /// Damping ratio against the toolhead mass.
    pub damping_ratio: f64,
}

/// A frame mode: the part of the frame that carries the motor and idler, moving along
/// the axis on its own stiffness to the ground.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Frame {
    /// Modal mass (kg).
    pub mass_kg: f64,
    /// Stiffness to ground (N/m).
    pub stiffness_n_per_m: f64,
    /// Damping ratio against the modal mass.
    pub damping_ratio: f64,
}

/// A two-phase hybrid stepper motor (datasheet values).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motor {
    /// Holding torque (N m) with both phases at the rated current (the usual datasheet
    /// convention), so the torque constant is `Km = T_hold / (sqrt 2 I_rated)`.
    pub holding_torque_n_m: f64,
    /// Rated phase current (A).
    pub rated_current_a: f64,
    /// Phase resistance (ohm).
    pub resistance_ohm: f64,
    /// Phase inductance (mH).
    pub inductance_mh: f64,
    /// Rotor inertia (g cm^2).
    pub rotor_inertia_g_cm2: f64,
    /// Rotor teeth (50 for 1.8 degree motors, the default; 100 for 0.9 degree).
    #[serde(default = "rotor_teeth_1_8_deg")]
    pub rotor_teeth: u32,
    /// Detent (cogging, unpowered) torque (N m). Default 0.
    #[serde(default)]
    pub detent_torque_n_m: f64,
    /// Damping ratio of the rotor alone on the driver's magnetic spring (k_theta, J).
    pub damping_ratio: f64,
}

/// The stepper driver's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Driver {
    /// Microsteps per full step.
    pub microsteps: u32,
    /// Run current (A rms, as Klipper's `run_current`): the sine amplitude is sqrt 2 times it.
    pub run_current_a_rms: f64,
    /// Supply voltage (V).
    pub supply_v: f64,
    /// Closed-loop bandwidth of the current controller (Hz); chopper drivers regulate
    /// within a few PWM periods, so tens of kHz (default 20 kHz).
    #[serde(default = "current_loop_20_khz")]
    pub current_loop_bandwidth_hz: f64,
}

/// GT2's pitch (mm).
fn gt2_pitch_mm() -> f64 {
    2.0
}

/// A 1.8 degree motor's rotor teeth.
fn rotor_teeth_1_8_deg() -> u32 {
    50
}

/// A chopper driver's current-loop bandwidth (Hz).
fn current_loop_20_khz() -> f64 {
    20_000.0
}

impl Machine {
    /// Check every axis (names unique and non-empty, every parameter in range).
    pub fn validate(&self) -> Result<(), SimError> {
        if self.axes.is_empty() {
            return Err(SimError::InvalidMachine {
                axis: "machine".into(),
                field: "axis".into(),
                value: 0.0,
                allowed: "at least one axis".into(),
            });
        }
        for (i, a) in self.axes.iter().enumerate() {
            if a.name.is_empty() || self.axes[..i].iter().any(|b| b.name == a.name) {
                return Err(SimError::InvalidModel {
                    what: format!(
                        "axis names must be unique and non-empty, got `{}` twice",
                        a.name
                    ),
                });
            }
            a.validate()?;
        }
        Ok(())
    }

    /// The axis called `name`.
    pub fn axis(&self, name: &str) -> Option<&AxisMachine> {
        self.axes.iter().find(|a| a.name == name)
    }
}

/// The plausible range of each part's value (machine-file key inside the axis, lowest,
/// highest, unit): wide enough for a desktop printer's micro motors and a machine tool's
/// heavy gantry, narrow enough that a value in the wrong unit or a slip (`1e308`, a rotor
/// inertia of 5.4e-6 typed in kg m^2 for 54 g cm^2) is refused at its key rather than
/// overflowing the model or giving it modes of MHz. The values of
/// `scenarios/machines/*.toml` lie well inside; the stiffnesses go to the rigid limit the
/// model is checked against (sim/tests/all/machine.rs).
pub const PART_RANGES: [(&str, f64, f64, &str); 19] = [
    ("carriage_kg", 1e-4, 1e4, "kg"),
    ("toolhead_kg", 1e-4, 1e4, "kg"),
    ("beam_kg", 1e-4, 1e4, "kg; 0 for none"),
    ("belt.ea_n", 1.0, 1e13, "N"),
    ("belt.span_mm", 11.0, 1e5, "mm"),
    ("belt.pitch_mm", 0.1, 100.0, "mm"),
    ("screw.lead_mm", 0.01, 1e3, "mm"),
    ("screw.stiffness_n_per_m", 1.0, 1e15, "N/m"),
    ("mount.stiffness_n_per_m", 1.0, 1e15, "N/m"),
    ("frame.mass_kg", 1e-4, 1e6, "kg"),
    ("frame.stiffness_n_per_m", 1.0, 1e15, "N/m"),
    ("motor.holding_torque_n_m", 1e-4, 1e3, "N m"),
    ("motor.rated_current_a", 1e-3, 1e3, "A"),
    ("motor.resistance_ohm", 1e-4, 1e4, "ohm"),
    ("motor.inductance_mh", 1e-3, 1e4, "mH"),
    (
        "motor.rotor_inertia_g_cm2",
        1e-3,
        1e7,
        "g cm^2: 54 for a NEMA 17, not kg m^2",
    ),
    ("driver.run_current_a_rms", 1e-3, 1e3, "A rms"),
    ("driver.supply_v", 0.1, 1e4, "V"),
    ("driver.current_loop_bandwidth_hz", 0.0, 1e7, "Hz"),
];

/// The most teeth a drive pulley may have (a 1000-tooth GT2 pulley is 64 cm across).
pub const MAX_PULLEY_TEETH: u32 = 1000;

/// The most rotor teeth a motor may have (50 for 1.8 degree steppers, 100 for 0.9).
pub const MAX_ROTOR_TEETH: u32 = 1000;

/// `x` as a person writes it: `0.1`, `1000`, `1e-4`, `1e9`.
fn short(x: f64) -> String {
    if x == 0.0 || (0.01..=1e4).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `(lowest, highest, unit)` of `field` in [`PART_RANGES`].
fn part_range(field: &str) -> (f64, f64, &'static str) {
    PART_RANGES
        .iter()
        .find(|(f, ..)| *f == field)
        .map(|&(_, lo, hi, unit)| (lo, hi, unit))
        .unwrap_or((f64::MIN_POSITIVE, f64::MAX, ""))
}

impl AxisMachine {
    /// Check every parameter; errors name the field as a key path inside the axis.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |field: &str, value: f64, allowed: &str| {
            Err(SimError::InvalidMachine {
                axis: self.name.clone(),
                field: field.to_string(),
                value,
                allowed: allowed.to_string(),
            })
        };
        let ratio = |x: f64| (0.0..1.0).contains(&x);
        const RATIO: &str = "0 <= damping_ratio < 1";
        // Each value within its plausible range ([`PART_RANGES`]): a value outside is a
        // slip or a wrong unit, and its products (stiffnesses of 1e308 N/m, torques of
        // 1e308 N m) overflow or leave the linearised model without digits.
        let check = |field: &str, v: f64| {
            let (lo, hi, unit) = part_range(field);
            if v.is_finite() && v >= lo && v <= hi {
                Ok(())
            } else {
                bad(
                    field,
                    v,
                    &format!("a number from {} to {} ({unit})", short(lo), short(hi)),
                )
            }
        };
        check("carriage_kg", self.carriage_kg)?;
        check("toolhead_kg", self.toolhead_kg)?;
        if self.beam_kg != 0.0 {
            check("beam_kg", self.beam_kg)?;
        }
        match &self.transmission {
            Transmission::Belt(b) => {
                check("belt.ea_n", b.ea_n)?;
                check("belt.span_mm", b.span_mm)?;
                check("belt.pitch_mm", b.pitch_mm)?;
                if !(8..=MAX_PULLEY_TEETH).contains(&b.pulley_teeth) {
                    return bad(
                        "belt.pulley_teeth",
                        f64::from(b.pulley_teeth),
                        &format!("an integer from 8 to {MAX_PULLEY_TEETH}"),
                    );
                }
                let min = crate::lumped::MIN_SPAN_M * 1e3;
                if !(b.carriage_at_zero_mm >= min && b.carriage_at_zero_mm <= b.span_mm - min) {
                    return bad(
                        "belt.carriage_at_zero_mm",
                        b.carriage_at_zero_mm,
                        &format!("between {min} and span_mm - {min} = {}", b.span_mm - min),
                    );
                }
                if !ratio(b.damping_ratio) {
                    return bad("belt.damping_ratio", b.damping_ratio, RATIO);
                }
            }
            Transmission::Screw(s) => {
                check("screw.lead_mm", s.lead_mm)?;
                check("screw.stiffness_n_per_m", s.stiffness_n_per_m)?;
                if !ratio(s.damping_ratio) {
                    return bad("screw.damping_ratio", s.damping_ratio, RATIO);
                }
            }
        }
        check("mount.stiffness_n_per_m", self.mount.stiffness_n_per_m)?;
        if !ratio(self.mount.damping_ratio) {
            return bad("mount.damping_ratio", self.mount.damping_ratio, RATIO);
        }
        if let Some(f) = &self.frame {
            check("frame.mass_kg", f.mass_kg)?;
            check("frame.stiffness_n_per_m", f.stiffness_n_per_m)?;
            if !ratio(f.damping_ratio) {
                return bad("frame.damping_ratio", f.damping_ratio, RATIO);
            }
        }
        let m = &self.motor;
        for (f, v) in [
            ("motor.holding_torque_n_m", m.holding_torque_n_m),
            ("motor.rated_current_a", m.rated_current_a),
            ("motor.resistance_ohm", m.resistance_ohm),
            ("motor.inductance_mh", m.inductance_mh),
            ("motor.rotor_inertia_g_cm2", m.rotor_inertia_g_cm2),
        ] {
            check(f, v)?;
        }
        if m.rotor_teeth == 0 || m.rotor_teeth > MAX_ROTOR_TEETH {
            return bad(
                "motor.rotor_teeth",
                f64::from(m.rotor_teeth),
                &format!("an integer from 1 to {MAX_ROTOR_TEETH} (50 for 1.8 degree motors)"),
            );
        }
        if !(m.detent_torque_n_m.is_finite()
            && m.detent_torque_n_m >= 0.0
            && m.detent_torque_n_m < m.holding_torque_n_m)
        {
            return bad(
                "motor.detent_torque_n_m",
                m.detent_torque_n_m,
                "a finite number >= 0 and below the holding torque",
            );
        }
        if !ratio(m.damping_ratio) {
            return bad("motor.damping_ratio", m.damping_ratio, RATIO);
        }
        let d = &self.driver;
        if d.microsteps == 0 || d.microsteps > 256 || !d.microsteps.is_power_of_two() {
            return bad(
                "driver.microsteps",
                f64::from(d.microsteps),
                "a power of two from 1 to 256",
            );
        }
        check("driver.run_current_a_rms", d.run_current_a_rms)?;
        check("driver.supply_v", d.supply_v)?;
        let min_bw = m.resistance_ohm / (std::f64::consts::TAU * m.inductance_mh * 1e-3);
        let max_bw = part_range("driver.current_loop_bandwidth_hz").1;
        if !(d.current_loop_bandwidth_hz.is_finite()
            && d.current_loop_bandwidth_hz > min_bw
            && d.current_loop_bandwidth_hz <= max_bw)
        {
            return bad(
                "driver.current_loop_bandwidth_hz",
                d.current_loop_bandwidth_hz,
                &format!(
                    "a finite number > R / (2 pi L) = {min_bw:.1} Hz and <= {} Hz",
                    short(max_bw)
                ),
            );
        }
        Ok(())
    }

    /// Rotor angle per metre of travel (rad/m): `2 pi / (teeth * pitch)` for a belt,
    /// `2 pi / lead` for a screw.
    pub fn rad_per_m(&self) -> f64 {
        let per_rev_m = match &self.transmission {
            Transmission::Belt(b) => f64::from(b.pulley_teeth) * b.pitch_mm * 1e-3,
            Transmission::Screw(s) => s.lead_mm * 1e-3,
        };
        std::f64::consts::TAU / per_rev_m
    }

    /// The range of axis positions (m) the transmission allows, if limited: a belt
    /// carriage must stay at least [`crate::lumped::MIN_SPAN_M`] from the pulley and the
    /// idler.
    pub fn travel_m(&self) -> Option<(f64, f64)> {
        match &self.transmission {
            Transmission::Belt(b) => {
                let min = crate::lumped::MIN_SPAN_M;
                let s0 = b.carriage_at_zero_mm * 1e-3;
                Some((min - s0, b.span_mm * 1e-3 - min - s0))
            }
            Transmission::Screw(_) => None,
        }
    }

    /// The mass the transmission carries (kg): carriage, beam and toolhead.
    pub fn moving_kg(&self) -> f64 {
        self.carriage_kg + self.beam_kg + self.toolhead_kg
    }
}
