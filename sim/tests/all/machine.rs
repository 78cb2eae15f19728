//! Compiling a machine axis: the lumped model's matrices against hand-derived values, the
//! static equilibrium, the driver modes, and errors that name the field.

use crate::common::{printer_x, printer_y, stage_x};
use settle_sim::machine::Transmission;
use settle_sim::{DriverMode, SimError};

const TAU: f64 = std::f64::consts::TAU;

#[test]
fn printer_axis_matrices_match_hand_derivation() {
    let m = printer_x();
    let axis = m.compile(DriverMode::Linear).expect("compile");
    let lin = axis.lumped.linearised(&[0.0; 3]);
    // 20 teeth x 2 mm = 40 mm per turn: r = 0.04 / 2 pi.
    let r = 0.04 / TAU;
    // Belt: EA (1/s + 1/(2L - s)) at s = 0.2 m, L = 0.4 m.
    let k_belt = 12_000.0 * (1.0 / 0.2 + 1.0 / 0.6);
    // Driver: Km = 0.40 / (sqrt 2 * 1.7) N m/A, I = sqrt 2 * 0.8 A, Nr = 50.
    let k_theta = 0.40 / 1.7 * 0.8 * 50.0;
    let k_mount = 5.0e5;
    let j = 54e-7;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1e-12);
    // Bodies: rotor, carriage, toolhead.
    assert!(close(lin.m[(0, 0)], j));
    assert!(close(lin.m[(1, 1)], 0.15));
    assert!(close(lin.m[(2, 2)], 0.6));
    assert!(close(lin.k[(0, 0)], k_belt * r * r + k_theta));
    assert!(close(lin.k[(0, 1)], -k_belt * r));
    assert!(close(lin.k[(1, 1)], k_belt + k_mount));
    assert!(close(lin.k[(1, 2)], -k_mount));
    assert!(close(lin.k[(2, 2)], k_mount));
    assert_eq!(lin.k[(0, 2)], 0.0);
    // The command pulls only the rotor: bk = k_theta / r.
    assert!(close(lin.bk[0], k_theta / r));
    assert_eq!((lin.bk[1], lin.bk[2]), (0.0, 0.0));
    // Damping ratios against their references: c = 2 zeta sqrt(k m).
    let c_belt = 2.0 * 0.05 * (k_belt * 0.75).sqrt();
    let c_mount = 2.0 * 0.05 * (k_mount * 0.6).sqrt();
    let c_driver = 2.0 * 0.05 * (k_theta * j).sqrt();
    assert!(close(lin.c[(1, 1)], c_belt + c_mount));
    assert!(close(lin.c[(0, 0)], c_belt * r * r + c_driver));
    assert!(close(lin.c[(2, 2)], c_mount));
    // Static equilibrium: everything where the command puts it.
    let x = 0.0371;
    let q = axis.lumped.equilibrium(x, None).expect("equilibrium");
    assert!(
        close(q[0], x / r) && close(q[1], x) && close(q[2], x),
        "{q:?}"
    );
    assert!(close(axis.lumped.toolhead_m(&q, x), x));
    // Microsteps: 40 mm / 200 / 16 = 12.5 um.
    let s = axis.stepper.as_ref().expect("stepper");
    assert!(close(s.microstep_m(), 12.5e-6));
    assert!(close(s.k_theta(), k_theta));
}

#[test]
fn rigid_limit_frequency_is_the_textbook_one() {
    // With a very stiff belt and mount the axis is one mass m + J/r^2 on the driver's
    // reflected spring k_theta / r^2.
    let mut m = printer_x();
    if let Transmission::Belt(b) = &mut m.transmission {
        b.ea_n = 1e12;
    }
    m.mount.stiffness_n_per_m = 1e14;
    let axis = m.compile(DriverMode::Linear).expect("compile");
    let f = axis.lumped.natural_frequencies_hz(&[0.0; 3])[0];
    let r = 0.04 / TAU;
    let k = 0.40 / 1.7 * 0.8 * 50.0 / (r * r);
    let mass = 0.75 + 54e-7 / (r * r);
    let expect = (k / mass).sqrt() / TAU;
    assert!((f / expect - 1.0).abs() < 1e-5, "{f} vs {expect}");
}

#[test]
fn frame_mode_and_driver_modes_change_the_topology() {
    let y = printer_y();
    let lin = y.compile(DriverMode::Linear).expect("linear");
    assert_eq!(lin.lumped.dof(), 4);
    assert_eq!(lin.lumped.bodies[3].name, "frame");
    // The belt is stretched between carriage and frame: its terms include the frame.
    let belt = &lin.lumped.couplings[0];
    assert_eq!(belt.terms.len(), 3);
    // Equilibrium: the frame stays at 0 whatever the command.
    let q = lin.lumped.equilibrium(0.05, None).expect("equilibrium");
    assert!(q[3].abs() < 1e-15);
    let full = y.compile(DriverMode::Full).expect("full");
    assert_eq!(full.lumped.actuated, Some(0));
    assert!(full.lumped.couplings.iter().all(|c| c.name != "driver"));
    let spring = y.compile(DriverMode::Spring).expect("spring");
    // The spring driver sees the command on the microstep grid.
    let step = spring.stepper.as_ref().expect("stepper").microstep_m();
    assert!((spring.command_node_m(3.4 * step) - 3.0 * step).abs() < 1e-18);
    assert_eq!(lin.command_node_m(3.4 * step), 3.4 * step);
    // A screw axis: rotor angle per metre is 2 pi / lead.
    let s = stage_x();
    assert!((s.rad_per_m() - TAU / 0.005).abs() < 1e-9);
}

#[test]
fn invalid_machines_name_the_field() {
    let field = |m: settle_sim::machine::AxisMachine| match m.compile(DriverMode::Full) {
        Err(SimError::InvalidMachine { field, .. }) => field,
        other => panic!("expected InvalidMachine, got {other:?}"),
    };
    let mut m = printer_x();
    m.mount.stiffness_n_per_m = -1.0;
    assert_eq!(field(m), "mount.stiffness_n_per_m");
    let mut m = printer_x();
    m.driver.microsteps = 12;
    assert_eq!(field(m), "driver.microsteps");
    let mut m = printer_x();
    if let Transmission::Belt(b) = &mut m.transmission {
        b.carriage_at_zero_mm = 399.0;
    }
    assert_eq!(field(m), "belt.carriage_at_zero_mm");
    let mut m = printer_x();
    m.motor.damping_ratio = 1.0;
    assert_eq!(field(m), "motor.damping_ratio");
}
