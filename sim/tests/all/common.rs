//! Test fixtures: a belt-driven printer axis and a lead-screw stage axis, built in code
//! (the TOML presets in `scenarios/machines/` are parsed by the harness).

#![allow(dead_code)]

use settle_planner::{Profile, Sample, State};
use settle_sim::machine::{AxisMachine, Belt, Driver, Frame, Motor, Mount, Screw, Transmission};
use settle_sim::{Observation, Plant};

/// A 17HS4401-class NEMA17 (0.40 N m at 1.7 A, 1.5 ohm, 2.8 mH, 54 g cm^2).
pub fn nema17() -> Motor {
    Motor {
        holding_torque_n_m: 0.40,
        rated_current_a: 1.7,
        resistance_ohm: 1.5,
        inductance_mh: 2.8,
        rotor_inertia_g_cm2: 54.0,
        rotor_teeth: 50,
        detent_torque_n_m: 0.022,
        damping_ratio: 0.05,
    }
}

/// A TMC2209-class driver at 0.8 A rms, 16 microsteps, 24 V.
pub fn driver() -> Driver {
    Driver {
        microsteps: 16,
        run_current_a_rms: 0.8,
        supply_v: 24.0,
        current_loop_bandwidth_hz: 20_000.0,
    }
}

/// A printer X axis: 20T GT2 pulley, 6 mm belt, 0.6 kg toolhead.
pub fn printer_x() -> AxisMachine {
    AxisMachine {
        name: "x".into(),
        carriage_kg: 0.15,
        toolhead_kg: 0.6,
        beam_kg: 0.0,
        transmission: Transmission::Belt(Belt {
            ea_n: 12_000.0,
            span_mm: 400.0,
            pulley_teeth: 20,
            pitch_mm: 2.0,
            carriage_at_zero_mm: 200.0,
            damping_ratio: 0.05,
        }),
        mount: Mount {
            stiffness_n_per_m: 5.0e5,
            damping_ratio: 0.05,
        },
        frame: None,
        motor: nema17(),
        driver: driver(),
    }
}

/// The printer axis with a frame mode.
pub fn printer_y() -> AxisMachine {
    let mut a = printer_x();
    a.name = "y".into();
    a.beam_kg = 0.6;
    a.frame = Some(Frame {
        mass_kg: 6.0,
        stiffness_n_per_m: 2.0e6,
        damping_ratio: 0.05,
    });
    a
}

/// A ball-screw stage (5 mm lead).
pub fn stage_x() -> AxisMachine {
    AxisMachine {
        name: "x".into(),
        carriage_kg: 1.5,
        toolhead_kg: 1.0,
        beam_kg: 0.0,
        transmission: Transmission::Screw(Screw {
            lead_mm: 5.0,
            stiffness_n_per_m: 4.0e7,
            damping_ratio: 0.05,
        }),
        mount: Mount {
            stiffness_n_per_m: 2.0e6,
            damping_ratio: 0.05,
        },
        frame: None,
        motor: nema17(),
        driver: driver(),
    }
}

/// The `printer_xy` preset's axes (scenarios/machines/printer_xy.toml): belts of EA 15 kN
/// (X) and 30 kN (Y, two belts) over 350 mm, 0.2 kg Y carriages, a 0.93 kg beam and a
/// 5 kg frame at 120 Hz on Y.
pub fn printer_preset(y: bool) -> AxisMachine {
    let mut a = if y { printer_y() } else { printer_x() };
    if y {
        a.carriage_kg = 0.2;
        a.beam_kg = 0.93;
        a.frame = Some(Frame {
            mass_kg: 5.0,
            stiffness_n_per_m: 2.84e6,
            damping_ratio: 0.05,
        });
    }
    if let Transmission::Belt(b) = &mut a.transmission {
        b.ea_n = if y { 30_000.0 } else { 15_000.0 };
        b.span_mm = 350.0;
        b.carriage_at_zero_mm = 175.0;
        b.damping_ratio = 0.08;
    }
    a
}

/// The end of the longest of `profiles` (s) and every segment end of every axis, with
/// that end, sorted and deduplicated (s): where [`run`] splits its steps.
pub fn breakpoints(profiles: &[Profile]) -> (f64, Vec<f64>) {
    let t_end = profiles.iter().map(Profile::duration_s).fold(0.0, f64::max);
    let mut bps: Vec<f64> = profiles
        .iter()
        .flat_map(|p| {
            p.iter()
                .map(|(t0, _, s)| t0 + s.duration_s())
                .collect::<Vec<_>>()
        })
        .collect();
    bps.push(t_end);
    bps.sort_by(f64::total_cmp);
    bps.dedup();
    (t_end, bps)
}

/// The first of `bps` after `t` (s), or infinity.
pub fn next_breakpoint(bps: &[f64], t: f64) -> f64 {
    bps.iter()
        .copied()
        .find(|&b| b > t)
        .unwrap_or(f64::INFINITY)
}

/// Step `plant` through `profiles` (one per axis) at `dt`, splitting at breakpoints, then
/// hold for `window`; returns every sample `(t, observations)`.
pub fn run<P: Plant>(
    plant: &P,
    profiles: &[Profile],
    dt: f64,
    window: f64,
) -> Vec<(f64, Vec<Observation>)> {
    let n_axes = profiles.len();
    let starts: Vec<State> = profiles.iter().map(Profile::start).collect();
    let mut st = plant.initial_state(&starts).expect("state");
    let (t_end, bps) = breakpoints(profiles);
    let mut out = Vec::new();
    let mut obs = vec![Observation::default(); n_axes];
    plant.observe(&st, &mut obs);
    out.push((0.0, obs.clone()));
    let mut t = 0.0;
    let mut k = 1usize;
    let stop = t_end + window;
    while t < stop - 1e-12 {
        let ts = k as f64 * dt;
        let next_bp = next_breakpoint(&bps, t);
        let next = ts.min(next_bp);
        let cmd: Vec<Sample> = profiles.iter().map(|p| p.state_at(t)).collect();
        let whole = next == ts && t == (k - 1) as f64 * dt;
        plant
            .step(&mut st, &cmd, if whole { dt } else { next - t })
            .expect("step");
        t = next;
        if next == ts {
            plant.observe(&st, &mut obs);
            out.push((t, obs.clone()));
            k += 1;
        }
    }
    out
}
