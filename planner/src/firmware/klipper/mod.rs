//! Klipper's toolhead planner (klippy/toolhead.py), move by move.
//!
//! A move gets its limits when it is queued: speed `min(F, max_velocity)`, acceleration
//! `max_accel`, lowered for Z (cartesian.py / corexy.py `check_move`: `max_z_velocity` and
//! `max_z_accel` scaled by `move_d / |dz|`) and for extruder-only or retracting moves
//! (extruder.py: `max_extrude_only_velocity/accel` over the extruder's share). Junction
//! speeds follow `Move.calc_junction` ([`crate::path::junction`] has the geometry):
//! `jd = scv^2 (sqrt 2 - 1) / max_accel`, `v^2 = R jd a` with `R = sin(t/2)/(1 - sin(t/2))`,
//! the centripetal caps `0.5 L a tan(t/2)` of both moves, both cruise speeds, what the
//! previous move can reach, and the extruder's `instantaneous_corner_velocity` over the
//! change of its share. `minimum_cruise_ratio` plans peaks with the pseudo-acceleration
//! `max_accel (1 - ratio)` (the older `max_accel_to_decel` `d` maps to
//! `ratio = 1 - min(1, d / max_accel)`: [`min_cruise_ratio_from_accel_to_decel`]).
//!
//! The look-ahead ([`KlipperPlanner`]) flushes lazily as Klipper does: once the queued
//! moves' minimum times exceed the flush time (1 s after a start or a full flush, 0.15 s
//! after a lazy one), the moves whose plan can no longer change leave the queue.
//!
//! Approximations: the host's real-time behaviour (a flush when the MCU's step buffer runs
//! low, `BUFFER_TIME_START` after an idle host) is not modelled: printing from a file the
//! host stays ahead. Moves are checked for nothing but speed (no endstop range, no
//! `max_extrude_cross_section` error).

mod config;
mod kmove;
mod queue;

pub use config::{KlipperConfig, KlipperExtruder, min_cruise_ratio_from_accel_to_decel};
pub use queue::KlipperPlanner;
