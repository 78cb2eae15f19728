//! A G-code job: a file planned the way a firmware plans it, shaped the way it shapes it,
//! as per-axis motion in bounded chunks.
//!
//! [`Job`] reads a file ([`crate::Reader`]) and feeds its events to a planner chosen by
//! [`JobConfig`] (Klipper, Marlin, RepRapFirmware from [`settle_planner::firmware`], or
//! settle's own look-ahead, [`settle_planner::path::window`]):
//!
//! - moves go in as straight segments, arcs cut as the firmware cuts them
//!   ([`crate::ArcSegmentation`]); dwells (`G4`, `M400`) stop the planner and idle;
//! - limit commands change the planner's settings for the moves queued after them, as each
//!   firmware does (Klipper `SET_VELOCITY_LIMIT`/`M204`; Marlin `M201 M203 M204 M205`;
//!   RepRapFirmware `M201 M203 M204 M566 M205`); a command the firmware does not have, or
//!   one this model does not simulate, is counted in [`JobSummary::ignored`];
//! - shaper commands (Klipper `SET_INPUT_SHAPER`, Marlin `M593` and `M493`,
//!   RepRapFirmware `M593`) take effect at a standstill: the planner drains as for `M400`
//!   (RepRapFirmware waits for standstill before changing its shaper, `AxisShaper::Configure`;
//!   Klipper flushes its look-ahead and step generation, `flush_step_generation` in
//!   klippy/toolhead.py), the motion before keeps the old shaper to its end, and the moves
//!   after are shaped by the new one. Klipper then starts the next move only after both
//!   shapers' step-generation windows, `kin_flush_delay` old plus new
//!   (klippy/extras/motion_queuing.py `calc_step_gen_restart`), which the job adds to the
//!   print time as Klipper does. Marlin applies `M493` to the motion it computes next
//!   without waiting; draining first is this model's approximation;
//! - planned moves become per-axis profiles ([`settle_planner::firmware::profiles`]), each
//!   axis is shaped with the shaper in force ([`settle_planner::shaper::stream`]; X, Y and
//!   Z each their own, E never), and the shaped motion comes out as [`JobChunk`]s in time
//!   order, each listing the moves ([`MoveInfo`]: index, line, layer, kind, planned time
//!   span, end points and commanded geometry) whose planned time span meets it.
//!
//! Memory does not grow with the file: the reader holds a line, the planners their
//! firmware's queue, the profile and shaper stages a chunk and a shaper's duration of
//! history, the move table the moves of the chunks in flight. The print time is the
//! planner's own clock ([`Job::print_time_s`]), and [`JobSummary::layers`] divides it by
//! layer.
//!
//! A layer range ([`Job::with_layers`]) plans every move before it (so the planner's
//! state, limits and shapers are right) but shapes only the last shaper's duration before
//! the range's first move and produces chunks from that move's start to the start of the
//! first move after the range.
//!
//! ```
//! use settle_gcode::job::{Job, JobConfig};
//! use settle_planner::firmware::Firmware;
//! use settle_gcode::{Reader, ReaderOptions};
//!
//! let text = "G1 X50 F6000\nG1 Y50\n";
//! let cfg = JobConfig::defaults(Firmware::Klipper)?;
//! let reader = Reader::new(text.as_bytes(), ReaderOptions::new(cfg.dialect));
//! let mut job = Job::new(reader, cfg)?;
//! let mut moves = 0;
//! while let Some(chunk) = job.next_chunk()? {
//!     assert_eq!(chunk.trajectory.dof(), 4); // X, Y, Z, E
//!     moves = moves.max(chunk.moves.len());
//! }
//! assert_eq!(moves, 2);
//! // 100 mm/s, 3000 mm/s^2, a 90-degree corner at 5 mm/s: two 50 mm legs.
//! let (v, a, vj, l) = (100.0, 3000.0, 5.0, 50.0);
//! let leg = v / a + (v - vj) / a + (l - v * v / (2.0 * a) - (v * v - vj * vj) / (2.0 * a)) / v;
//! assert!((job.print_time_s() - 2.0 * leg).abs() < 1e-9);
//! # Ok::<(), settle_gcode::GcodeError>(())
//! ```

mod chunk;
mod config;
pub(crate) mod driver;
mod input;
mod moves;
mod not_followed;
mod pipeline;
mod printer;
mod settle;
pub(crate) mod shapers;
mod slice;
mod travel;

pub use chunk::{JobChunk, JobSummary, LayerTime, LimitOverride, MoveGeometry, MoveInfo};
pub use config::{
    JobConfig, PlannerConfig, PrusaPrinter, SettleConfig, ShaperSetting, parse_firmware,
};
pub use pipeline::Job;
pub use printer::prusa_printer;
pub use shapers::prusa_common_hz;
