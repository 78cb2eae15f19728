//! RepRapFirmware's planner (src/Movement/DDA.cpp, DDARing.cpp, the 3.5 line) with its
//! ring of moves.
//!
//! A move's acceleration is the largest along its direction inside the `M201` box, capped
//! by `M204 P` (printing moves: XY with forward extrusion) or `M204 T` (other XY moves);
//! its speed is the requested one raised to the minimum movement speed and kept inside the
//! `M203` box (CoreXY also limits each motor). At a junction every drive, extruder
//! included, may change speed by at most its `M566` "instantaneous speed change" (jerk):
//! `MatchSpeeds`. With the default jerk policy (`M566 P0`) moves of different kinds
//! (printing, travel, extruder-only) are not joined: the toolhead stops between them.
//! `DoLookahead` raises the previous move's end speed when a move is added, walking back
//! through deceleration-only moves that are still provisional.
//!
//! The ring (60 moves on Duet 3) fills from the file while the printer moves:
//! `CanAddMove` accepts a move while a slot is free and the unprepared moves other than
//! the oldest last less than 0.5 s (or all of them less than 2 s); `PrepareMoves` freezes
//! moves 100 ms before they are due (50 ms for one that still decelerates at its end), at
//! most half the ring. A frozen move can no longer change: a move added after it starts
//! from rest. This model runs that timeline in exact continuous time.
//!
//! Approximations: f64 instead of f32; move times are not truncated to whole step clocks
//! (at most 1.33 µs per move); when RRF drops a very short ramp next to a cruise
//! (`MinimumAccelOrDecelClocks`) the other ramp's distance is recomputed so that the
//! distances add up; the firmware's polling (a few ms) around the 100 ms preparation
//! margin is taken as exact. Not modelled: input shaping (`M593`), pressure advance limits
//! on extruder acceleration, nonlinear extrusion, babystepping.

mod config;
mod dda;
mod planner;

pub use config::RrfConfig;
pub use planner::RrfPlanner;
