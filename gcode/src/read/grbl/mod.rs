//! GRBL's G-code (gnea/grbl 1.1 grbl/gcode.c `gc_execute_line`; grblHAL reads the same
//! language): a block's commands in GRBL's order of execution, the spindle and laser
//! state, work offsets, and `$` lines.
//!
//! - **Several commands a line**, at most one per modal group ([`words`]); axis words
//!   without a motion command continue the modal motion (`X10 Y5` after `G1`); GRBL
//!   starts in `G0`, `G17`, `G21`, `G90`, `G94`, `G54`, `M5`, with no feed rate (a `G1`
//!   before an `F` is refused, error:22).
//! - **Units**: `F` in mm/min (in/min after `G20`), coordinates in mm (inches after
//!   `G20`); `G93` inverse time (`F` per block: the move takes `1/F` minutes); `G4 P` in
//!   seconds.
//! - **Spindle and laser** ([`crate::Tool`]): `M3`, `M4`, `M5` and `S`. With the laser
//!   mode off (`$32=0`, the default) a spindle speed change while the spindle is on, and
//!   every `M3`/`M4`/`M5` change, waits for the machine to stop (`spindle_sync` calls
//!   `protocol_buffer_synchronize`): a dwell of 0 s here. With the laser mode on (`$32=1`)
//!   an `S` on a line that moves is planned with the move, without a stop; `G0` runs with
//!   the laser off (`GC_PARSER_LASER_DISABLE`); `M3` changes of motion mode on a line that
//!   does not move still synchronise (`GC_PARSER_LASER_FORCE_SYNC`). Coolant (`M7`, `M8`,
//!   `M9`, often a laser's air assist) synchronises too (`coolant_sync`); so do `M0`,
//!   `M2` and `M30`. `M2`/`M30` end the program: motion `G1`, `G17`, `G90`, `G94`,
//!   `G54`, `M5`, `M9`.
//! - **Work offsets**: work = machine - `G54`..`G59` offset - `G92` offset - tool length
//!   offset (`G43.1`). The offsets stored in the machine are not in the file; they are
//!   taken as 0 (so the file's coordinates are the machine's, as for the printer
//!   dialects), and `G10 L2`/`L20`, `G92`, `G92.1`, `G43.1`, `G49` change them as GRBL
//!   does. `G53` moves to machine coordinates; `G28`/`G30` travel (at the rapid rate) to
//!   the optional intermediate point and then to the stored position (machine 0 until a
//!   `G28.1`/`G30.1` stores one).
//! - **`$` lines** ([`dollar`]): `$N=V` settings ([`crate::Setting::Grbl`]; GRBL takes
//!   them only while idle: after motion and before the machine has stopped it answers
//!   error:8 and the setting is not changed), `$H` homing, `$X` and the report commands.

pub(crate) mod arcs;
pub(crate) mod dollar;
pub(crate) mod words;

use crate::error::GcodeError;
use crate::read::arc::Plane;
use crate::read::cmd::{Cmd, NON_NEGATIVE, POSITIVE};
use crate::read::event::{EventKind, Note};
use crate::read::geometry::Tool;
use crate::read::motion::Motion;
use crate::read::params::Params;
use words::{Flow, MotionMode, NonModal, Spindle, Words};

/// GRBL's modal state besides [`Motion`]'s (grbl/gcode.h `parser_state_t`).
#[derive(Debug, Clone)]
pub(crate) struct GrblState {
    /// `$32`: laser mode.
    pub(crate) laser_mode: bool,
    /// `$31` and `$30`: the `S` of the least and of full speed or power.
    pub(crate) spindle_range: [f64; 2],
    motion: MotionMode,
    spindle: Spindle,
    /// The spindle speed / laser power `S`.
    s: f64,
    /// G93.
    inverse_time: bool,
    /// G54..G59 (0..5).
    coord_select: usize,
    /// Work coordinate offsets (machine mm), as stored.
    wcs: [[f64; 3]; 6],
    /// The G92 offset (mm).
    g92: [f64; 3],
    /// The tool length offset on Z (mm).
    tlo: f64,
    /// The G28 and G30 stored positions (machine mm).
    home: [[f64; 3]; 2],
    /// A move was read since the machine last stood still (start, or a synchronising
    /// command): a `$` command now meets a moving machine.
    pub(crate) moving: bool,
}

impl GrblState {
    /// GRBL's power-up state; `laser_mode` (`$32`) and `spindle_range` (`$31`, `$30`)
    /// from the configuration.
    pub(crate) fn new(laser_mode: bool, spindle_range: [f64; 2]) -> Self {
        Self {
            laser_mode,
            spindle_range,
            motion: MotionMode::Seek,
            spindle: Spindle::Off,
            s: 0.0,
            inverse_time: false,
            coord_select: 0,
            wcs: [[0.0; 3]; 6],
            g92: [0.0; 3],
            tlo: 0.0,
            home: [[0.0; 3]; 2],
            moving: false,
        }
    }

    /// Machine minus work coordinates of X, Y, Z.
    fn offsets(&self) -> [f64; 3] {
        let w = self.wcs[self.coord_select];
        [
            w[0] + self.g92[0],
            w[1] + self.g92[1],
            w[2] + self.g92[2] + self.tlo,
        ]
    }

    /// The machine waits for its moves to finish here.
    fn sync(&mut self, out: &mut Vec<EventKind>) {
        out.push(EventKind::Dwell { duration_s: 0.0 });
        self.moving = false;
    }

    /// The tool over a move planned now in motion mode `mode`.
    fn tool(&self, mode: MotionMode) -> Tool {
        match (self.spindle, self.laser_mode) {
            (Spindle::Off, _) => Tool::Off,
            (_, true) if !mode.is_feed() => Tool::Off,
            (sp, true) => Tool::Laser {
                s: self.s,
                dynamic: sp == Spindle::Ccw,
            },
            (_, false) => Tool::Spindle { s: self.s },
        }
    }

    /// Runs one block (`w`, its value words in `p`) in GRBL's order of execution,
    /// pushing what it does to `out`.
    pub(crate) fn block(
        &mut self,
        motion: &mut Motion,
        cmd: &Cmd,
        w: &Words,
        p: &Params,
        out: &mut Vec<EventKind>,
    ) -> Result<(), GcodeError> {
        if w.tool_change.is_some() {
            // GRBL refuses the whole line (error:20): nothing on it runs.
            out.push(EventKind::Note(Note::IgnoredByFirmware {
                command: "M6".into(),
                reason: "GRBL has no tool change: it refuses a line with M6 (error:20, grbl/gcode.c), so nothing on it runs; the sender changes tools",
            }));
            return Ok(());
        }
        let axis_words = p.has(b'X') || p.has(b'Y') || p.has(b'Z');
        let block_motion = w.motion.unwrap_or(self.motion);
        let axis_non_modal = matches!(
            w.non_modal,
            Some(NonModal::SetCoordinateData | NonModal::GoHome(_) | NonModal::SetOffset)
        );
        if w.motion.is_some() && axis_non_modal {
            return Err(cmd.unsupported(
                "G10, G28, G30 and G92 take the axis words: no motion command on their line (error:24, grbl/gcode.c)",
            ));
        }
        if w.tool_length.is_some() && (w.motion.is_some() || axis_non_modal) {
            return Err(cmd.unsupported(
                "G43.1/G49 take the axis words: no motion command on their line (error:24, grbl/gcode.c)",
            ));
        }
        let moves = axis_words && !axis_non_modal && w.tool_length.is_none();
        if moves && block_motion == MotionMode::None {
            return Err(cmd.unsupported(
                "axis words under G80 (no motion mode): GRBL refuses the line (error:31, grbl/gcode.c)",
            ));
        }
        // Modal settings of the block apply to its own words (grbl/gcode.c step 3).
        let inverse_time = w.inverse_time.unwrap_or(self.inverse_time);
        if let Some(inches) = w.inches {
            motion.set_inches(inches);
        }
        let unit = motion.unit_mm();
        // [2, 3] Feed rate mode and feed rate.
        if w.inverse_time.is_some_and(|t| t != self.inverse_time) || self.inverse_time {
            // Switching modes, or in G93: the feed is undefined until this block's F.
            motion.set_feed_mm_min(0.0);
        }
        self.inverse_time = inverse_time;
        let f = cmd.num(p, b'F', POSITIVE)?;
        if moves && block_motion.is_feed() && f.is_none() && motion.feed_mm_min() == 0.0 {
            return Err(cmd.unsupported(if inverse_time {
                "G93 (inverse time) needs an F on every feed move (error:22, grbl/gcode.c)"
            } else {
                "no feed rate yet: GRBL refuses G1, G2 and G3 before an F (error:22, grbl/gcode.c)"
            }));
        }
        // [4] Spindle speed, [7] spindle state: GRBL's laser-mode flags.
        let laser_disable = self.laser_mode && !block_motion.is_feed();
        let laser_is_motion = self.laser_mode && moves;
        let force_sync = self.laser_mode
            && !laser_is_motion
            && self.spindle == Spindle::Cw
            && (self.motion.is_feed() == laser_disable);
        if let Some(s) = w.s {
            // GRBL runs an S outside $31..$30 at the nearer end (grbl/spindle_control.c
            // `spindle_compute_pwm_value`; grblHAL's `spindle_set_rpm` clamps the same),
            // S0 off: whether the move works is the same, its power is not the file's.
            let [min, max] = self.spindle_range;
            if s > max {
                out.push(EventKind::Note(Note::IgnoredByFirmware {
                    command: "S".into(),
                    reason: "above $30: GRBL runs the spindle or laser at $30, full speed or power (spindle_compute_pwm_value, grbl/spindle_control.c); the move works as it would at $30",
                }));
            } else if s > 0.0 && s < min {
                out.push(EventKind::Note(Note::IgnoredByFirmware {
                    command: "S".into(),
                    reason: "above 0 and below $31: GRBL runs the spindle or laser at $31, its least speed or power (spindle_compute_pwm_value, grbl/spindle_control.c); the move works as it would at $31",
                }));
            }
        }
        let s = w.s.unwrap_or(self.s);
        if s != self.s || force_sync {
            if self.spindle != Spindle::Off && !laser_is_motion {
                self.sync(out);
            }
            self.s = s;
        }
        if let Some(sp) = w.spindle.filter(|&sp| sp != self.spindle) {
            self.sync(out);
            self.spindle = sp;
        }
        // [8] Coolant: every change synchronises (grbl/coolant_control.c `coolant_sync`).
        if w.coolant.is_some() {
            self.sync(out);
        }
        // [10] Dwell.
        if w.non_modal == Some(NonModal::Dwell) {
            let Some(secs) = cmd.num(p, b'P', NON_NEGATIVE)? else {
                return Err(
                    cmd.unsupported("G4 needs P, the dwell in seconds (error:28, grbl/gcode.c)")
                );
            };
            out.push(EventKind::Dwell { duration_s: secs });
            self.moving = false;
        }
        // [11, 17] Plane and distance mode.
        if let Some(plane) = w.plane {
            motion.set_plane(plane);
        }
        if let Some(rel) = w.relative {
            motion.set_relative(rel);
        }
        // [14] Tool length offset (G43.1 Z, G49).
        let value = |letter: u8| -> Result<Option<f64>, GcodeError> {
            Ok(cmd
                .num(p, letter, crate::read::cmd::FINITE)?
                .map(|v| v * unit))
        };
        match w.tool_length {
            Some(true) => {
                if p.has(b'X') || p.has(b'Y') || !p.has(b'Z') {
                    return Err(cmd.unsupported(
                        "G43.1 takes Z, the tool length offset, alone (error:37, grbl/gcode.c)",
                    ));
                }
                self.tlo = value(b'Z')?.unwrap_or(0.0);
            }
            Some(false) => self.tlo = 0.0,
            None => {}
        }
        // [15] Coordinate system.
        if let Some(c) = w.coord_select {
            self.coord_select = c;
        }
        // [19] Non-modal commands.
        let pos = motion.position();
        let machine = [pos.x_mm, pos.y_mm, pos.z_mm];
        let named = |k: usize| [b'X', b'Y', b'Z'][k];
        match w.non_modal {
            Some(NonModal::SetCoordinateData) => {
                let l = cmd.num(p, b'L', NON_NEGATIVE)?;
                let pn = cmd.num(p, b'P', NON_NEGATIVE)?.unwrap_or(0.0).trunc() as usize;
                if !axis_words || !matches!(l, Some(v) if v == 2.0 || v == 20.0) || pn > 6 {
                    return Err(cmd.unsupported(
                        "GRBL's G10 is L2 or L20 with P0-P6 and axis words (grbl/gcode.c)",
                    ));
                }
                let idx = if pn == 0 { self.coord_select } else { pn - 1 };
                for (k, m) in machine.iter().enumerate() {
                    if let Some(v) = value(named(k))? {
                        self.wcs[idx][k] = if l == Some(20.0) {
                            let tlo = if k == 2 { self.tlo } else { 0.0 };
                            m - self.g92[k] - tlo - v
                        } else {
                            v
                        };
                    }
                }
            }
            Some(NonModal::SetOffset) => {
                if !axis_words {
                    return Err(cmd.unsupported("G92 needs axis words (error:26, grbl/gcode.c)"));
                }
                let wcs = self.wcs[self.coord_select];
                for (k, m) in machine.iter().enumerate() {
                    if let Some(v) = value(named(k))? {
                        let tlo = if k == 2 { self.tlo } else { 0.0 };
                        self.g92[k] = m - wcs[k] - tlo - v;
                    }
                }
            }
            Some(NonModal::ResetOffset) => self.g92 = [0.0; 3],
            Some(NonModal::SetHome(k)) => self.home[k] = machine,
            _ => {}
        }
        motion.set_offsets(self.offsets());
        // G28/G30: the intermediate point (as a rapid in the current modes), then the
        // stored position.
        if let Some(NonModal::GoHome(k)) = w.non_modal {
            if axis_words {
                let mut target = machine;
                for (kk, t) in target.iter_mut().enumerate() {
                    if let Some(v) = value(named(kk))? {
                        *t = if motion.is_relative() {
                            machine[kk] + v
                        } else {
                            v + self.offsets()[kk]
                        };
                    }
                }
                self.travel(motion, target, out);
            }
            self.travel(motion, self.home[k], out);
        }
        // [20] Motion.
        self.motion = block_motion;
        if moves {
            if w.non_modal == Some(NonModal::AbsoluteOverride) {
                if !matches!(block_motion, MotionMode::Seek | MotionMode::Linear) {
                    return Err(
                        cmd.unsupported("G53 moves only in G0 or G1 (error:30, grbl/gcode.c)")
                    );
                }
                motion.set_machine_coordinates(true);
            }
            let mv = match block_motion {
                MotionMode::Seek | MotionMode::Linear => {
                    motion.line(cmd, p, block_motion == MotionMode::Seek)?
                }
                MotionMode::CwArc | MotionMode::CcwArc => {
                    Some(motion.arc(cmd, p, block_motion == MotionMode::CwArc)?)
                }
                MotionMode::None => None,
            };
            if let Some(mut mv) = mv {
                if inverse_time && block_motion.is_feed() {
                    // G93: the move takes 1/F minutes.
                    mv.feed_mm_s = f.unwrap_or(0.0) * mv.length_mm() / 60.0;
                }
                mv.tool = self.tool(block_motion);
                self.moving = true;
                out.push(EventKind::Move(mv));
            }
        } else if let Some(f) = f {
            motion.set_feed_mm_min(f * unit);
        }
        if inverse_time {
            motion.set_feed_mm_min(0.0);
        }
        // [21] Program flow.
        match w.flow {
            Some(Flow::Pause) => {
                self.sync(out);
                out.push(EventKind::Note(Note::IgnoredByFirmware {
                    command: "M0".into(),
                    reason: "M0 pauses until the operator resumes (a feed hold); the pause is not simulated",
                }));
            }
            Some(Flow::End) => {
                self.sync(out);
                self.motion = MotionMode::Linear;
                motion.set_plane(Plane::Xy);
                motion.set_relative(false);
                self.inverse_time = false;
                self.coord_select = 0;
                self.spindle = Spindle::Off;
                motion.set_offsets(self.offsets());
            }
            Some(Flow::OptionalStop) | None => {}
        }
        Ok(())
    }

    /// A rapid to `xyz` (machine mm): G28/G30 and `$H`.
    fn travel(&mut self, motion: &mut Motion, xyz: [f64; 3], out: &mut Vec<EventKind>) {
        if let Some(mut mv) = motion.line_to_machine(xyz, true) {
            mv.tool = self.tool(MotionMode::Seek);
            self.moving = true;
            out.push(EventKind::Move(mv));
        }
    }
}
