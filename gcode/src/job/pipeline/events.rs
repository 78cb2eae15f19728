//! How the job handles each reader event: moves and homing to the planner, limit and
//! shaper commands as its firmware applies them, planned moves to profiles and shaped
//! chunks, and the end of the file.

use std::io::BufRead;
use std::sync::Arc;

use settle_planner::firmware::{LinearMove, PlannedMove};
use settle_planner::{PlanError, Trajectory};

use super::{Job, MM, Planner, Range, build};
use crate::config::GrblSettings;
use crate::error::{GcodeError, Location};
use crate::job::chunk::LimitOverride;
use crate::job::chunk::{JobChunk, MoveGeometry, MoveInfo};
use crate::job::driver::{Driver, LimitOutcome};
use crate::job::input::AxisShapers;
use crate::job::shapers::ShaperProblem;
use crate::job::travel::TravelCheck;
use crate::read::event::{Event, EventKind, Note};
use crate::read::geometry::{Move, MoveKind, Path, Point, Tool};
use crate::read::limits::{AxisFlags, LimitChange};
use crate::read::setting::Setting;
use crate::{ArcSegmentation, GrblArcs};

/// The planner's refusal of what line `line` asks for.
fn plan_error(source: &Arc<str>, line: u64, command: &str, e: PlanError) -> GcodeError {
    GcodeError::Plan {
        at: Location {
            source_name: source.clone(),
            line,
            column: None,
        },
        command: command.to_string(),
        source: Box::new(e),
    }
}

/// Klipper's step-generation flush delay for `shapers` (klippy/extras/motion_queuing.py
/// `check_step_generation_scan_windows`): the largest pulse offset before or after the
/// centre (`gen_steps_pre_active`/`post_active`, klippy/chelper/kin_shaper.c), at least
/// `floor_s`.
fn klipper_flush_delay_s(shapers: &AxisShapers, floor_s: f64) -> f64 {
    shapers.iter().flatten().fold(floor_s, |m, s| {
        let c: f64 = s.weights().zip(s.times_s()).map(|(w, t)| w * t).sum();
        m.max(c).max(s.duration_s() - c)
    })
}

impl<R: BufRead> Job<R> {
    fn at(&self, line: u64) -> Location {
        Location {
            source_name: self.source.clone(),
            line,
            column: None,
        }
    }

    fn ignore(&mut self, what: String) {
        *self.ignored.entry(what).or_insert(0) += 1;
    }

    /// Read and handle one event (or the end of the file).
    pub(super) fn step(&mut self) -> Result<(), GcodeError> {
        match self.reader.next() {
            None => self.end_of_file(),
            Some(Err(e)) => Err(e),
            Some(Ok(ev)) => self.event(ev),
        }
    }

    fn event(&mut self, ev: Event) -> Result<(), GcodeError> {
        match ev.kind {
            EventKind::Move(mv) => self.on_move(ev.line, ev.layer, &mv),
            EventKind::Dwell { duration_s } => {
                if duration_s > crate::MAX_STEP_DURATION_S {
                    return Err(GcodeError::TooLong {
                        at: self.at(ev.line),
                        command: "G4".to_string(),
                        duration_s,
                        what: "a dwell".to_string(),
                    });
                }
                let r = match &mut self.planner {
                    Planner::Firmware(d, _) => d.planner().dwell(duration_s),
                    Planner::Settle(s) => s.dwell(duration_s),
                };
                r.map_err(|e| plan_error(&self.source, ev.line, "G4", e))?;
                self.drain(ev.line)
            }
            EventKind::Layer(c) => {
                self.table.layer_z(ev.layer, c.z_mm, c.source);
                Ok(())
            }
            EventKind::Limits(c) => self.on_limits(ev.line, &c),
            EventKind::Note(Note::Homed { axes }) => self.on_home(ev.line, ev.layer, axes),
            EventKind::Note(Note::IgnoredByFirmware { command, reason }) => {
                let name = command.split_whitespace().next().unwrap_or("").to_string();
                self.ignore(format!("{name}: {reason}"));
                Ok(())
            }
            // The model was chosen before the job started ([`crate::job::PrusaPrinter`]);
            // the reader counts the command among the ones it passes over.
            EventKind::Note(Note::PrinterModel { .. }) => Ok(()),
            EventKind::Note(Note::MacroCall { command, .. }) => {
                self.ignore(format!(
                    "{command}: a macro file the job does not open (config.g's reader runs them)"
                ));
                Ok(())
            }
            EventKind::Setting(Setting::Grbl { number, value }) => {
                self.on_grbl_setting(ev.line, number, value)
            }
            // Configuration commands (steps per mm, currents, axis ranges, kinematics) in a
            // job are not simulated: the job runs with its configuration.
            EventKind::Setting(s) => {
                self.ignore(format!(
                    "{}: a configuration command; the job keeps its configuration",
                    s.command_name()
                ));
                Ok(())
            }
        }
    }

    fn on_move(&mut self, line: u64, layer: u32, mv: &Move) -> Result<(), GcodeError> {
        self.plan_move(line, layer, mv, true)
    }

    /// A move; `check_travel` false for the travel a `G28` stands for (homing ends on the
    /// endstops, inside the travel).
    fn plan_move(
        &mut self,
        line: u64,
        layer: u32,
        mv: &Move,
        check_travel: bool,
    ) -> Result<(), GcodeError> {
        let command = match (&mv.path, mv.rapid) {
            (Path::Arc(a), _) if a.clockwise() => "G2",
            (Path::Arc(_), _) => "G3",
            (Path::Line, true) => "G0",
            (Path::Line, false) => "G1",
        };
        // At its feed (or slower: the limits only slow it), an extruder-only move over its
        // extrusion.
        let length_mm = match mv.length_mm() {
            0.0 => mv.extrusion_mm().abs(),
            l => l,
        };
        let duration_s = length_mm / mv.feed_mm_s;
        if mv.feed_mm_s > 0.0 && duration_s > crate::MAX_STEP_DURATION_S {
            return Err(GcodeError::TooLong {
                at: self.at(line),
                command: command.to_string(),
                duration_s,
                what: format!("{length_mm:.3} mm at {:.6} mm/min", mv.feed_mm_s * 60.0),
            });
        }
        let mut points = std::mem::take(&mut self.points);
        mv.segments_into(&self.cfg.arcs, &mut points);
        if points.len() > crate::MAX_ARC_SEGMENTS {
            let segments = points.len();
            self.points = points;
            return Err(GcodeError::ArcTooManySegments {
                at: self.at(line),
                command: command.to_string(),
                firmware: self.cfg.firmware().to_string(),
                length_mm,
                segments,
                max: crate::MAX_ARC_SEGMENTS,
            });
        }
        if check_travel {
            if let (Path::Arc(_), Some(message)) = (&mv.path, self.travel.arc_refused(&mv.end)) {
                self.points = points;
                return Err(GcodeError::OutOfTravel {
                    at: self.at(line),
                    command: command.to_string(),
                    message,
                });
            }
            if matches!(mv.path, Path::Arc(_))
                && self.travel.clamps()
                && let Some(i) = points.iter().position(|p| !self.travel.inside(p))
            {
                points.truncate(i);
                self.ignore(format!(
                    "{command}: an arc past the M208 limits on the way: RepRapFirmware stops it at its last segment inside (\"intermediate position outside machine limits\") and goes on from there"
                ));
            }
            let mut from = mv.start;
            for p in &points {
                match self.travel.check(&from, p) {
                    TravelCheck::Inside => {}
                    TravelCheck::Listed(text) => self.ignore(format!("{command}: {text}")),
                    TravelCheck::Refused(message) => {
                        self.points = points;
                        return Err(GcodeError::OutOfTravel {
                            at: self.at(line),
                            command: command.to_string(),
                            message,
                        });
                    }
                }
                from = *p;
            }
        }
        // What the firmware runs: the file's points, or RepRapFirmware's clamped ones, from
        // where the firmware stands.
        let (mut start, mut end) = (self.resync.take().unwrap_or(mv.start), mv.end);
        if check_travel && self.travel.clamps() {
            self.travel.clamp(&mut start);
            for p in &mut points {
                self.travel.clamp(p);
            }
            end = points.last().copied().unwrap_or(start);
            if end != mv.end {
                self.resync = Some(end);
            }
            if points.is_empty() {
                self.points = points;
                return Ok(());
            }
        }
        let xyz = |p: &Point| [p.x_mm, p.y_mm, p.z_mm];
        let geometry = match &mv.path {
            Path::Line => MoveGeometry::Line {
                from_mm: xyz(&start),
                to_mm: xyz(&end),
            },
            Path::Arc(a) => MoveGeometry::Arc {
                arc: *a,
                points_mm: std::iter::once(xyz(&start))
                    .chain(points.iter().map(xyz))
                    .collect(),
            },
        };
        let info = MoveInfo {
            index: self.moves,
            line,
            layer,
            kind: mv.kind,
            working: mv.is_working(),
            tool: mv.tool,
            feature: mv.feature,
            start_time_s: 0.0,
            duration_s: 0.0,
            start_mm: start,
            end_mm: end,
            feed_mm_s: mv.feed_mm_s,
            geometry,
        };
        self.moves += 1;
        self.last_end = end;
        self.last_feed_mm_s = mv.feed_mm_s;
        let first = self.seq;
        let extruder_only = mv.kind == MoveKind::Extruder;
        let n = if extruder_only {
            1
        } else {
            points.len() as u64
        };
        self.table.add(info, first, first + n);
        let speed = mv.feed_mm_s * MM;
        // GRBL runs a G0 at its rapid rate, whatever the feed (which may be undefined).
        let grbl_rapid = mv.rapid && self.grbl.is_some();
        let speed = if grbl_rapid && !(speed > 0.0) {
            1.0
        } else {
            speed
        };
        let mut prev = start;
        let result = (|| -> Result<(), GcodeError> {
            if extruder_only {
                let de = mv.extrusion_mm() * MM;
                match &mut self.planner {
                    Planner::Firmware(d, _) => {
                        let p = [prev.x_mm * MM, prev.y_mm * MM, prev.z_mm * MM];
                        d.planner()
                            .push(&LinearMove::new(p, p, de, speed))
                            .map_err(|e| plan_error(&self.source, line, command, e))?;
                        self.seq += 1;
                    }
                    Planner::Settle(s) => {
                        let span = s.extrude(de, speed);
                        let (t0, t1) =
                            span.map_err(|e| plan_error(&self.source, line, command, e))?;
                        self.drain(line)?;
                        let seq = self.seq;
                        self.seq += 1;
                        self.on_span(seq, t0, t1)
                            .map_err(|e| plan_error(&self.source, line, command, e))?;
                        self.refuse_too_long()?;
                    }
                }
                return self.drain(line);
            }
            for p in &points {
                let (a, b) = (
                    [prev.x_mm * MM, prev.y_mm * MM, prev.z_mm * MM],
                    [p.x_mm * MM, p.y_mm * MM, p.z_mm * MM],
                );
                let seq = self.seq;
                let r = match &mut self.planner {
                    Planner::Firmware(d, _) => {
                        let mut lm = LinearMove::new(a, b, (p.e_mm - prev.e_mm) * MM, speed);
                        lm.rapid = grbl_rapid;
                        d.planner().push(&lm)
                    }
                    Planner::Settle(s) => s.push(b, speed, seq),
                };
                r.map_err(|e| plan_error(&self.source, line, command, e))?;
                self.seq += 1;
                prev = *p;
                self.drain(line)?;
            }
            Ok(())
        })();
        self.points = points;
        result
    }

    /// `G28` after motion: homing is not simulated, but the reader now puts the homed
    /// axes at 0, so the toolhead travels there in a straight line at the modal feed rate
    /// (as a `G0` would) to keep the motion continuous.
    fn on_home(&mut self, line: u64, layer: u32, axes: AxisFlags) -> Result<(), GcodeError> {
        let from = self.last_end;
        let mut to = from;
        for (on, c) in [
            (axes.x, &mut to.x_mm),
            (axes.y, &mut to.y_mm),
            (axes.z, &mut to.z_mm),
        ] {
            if on {
                *c = 0.0;
            }
        }
        if to == from {
            return Ok(());
        }
        let mv = Move {
            start: from,
            end: to,
            feed_mm_s: self.last_feed_mm_s,
            kind: MoveKind::Travel,
            rapid: true,
            path: Path::Line,
            tool: Tool::Off,
            feature: 0,
        };
        self.plan_move(line, layer, &mv, false)
    }

    /// A GRBL `$` setting read while the machine stood still (the reader passes no other):
    /// the planner's settings and the arc tolerance change from here on.
    fn on_grbl_setting(&mut self, line: u64, number: u16, value: f64) -> Result<(), GcodeError> {
        let at = self.at(line);
        let Some(g) = self.grbl.as_mut() else {
            self.ignore(format!("${number}: not a setting of this firmware"));
            return Ok(());
        };
        g.apply(number, value)
            .map_err(|allowed| GcodeError::OutOfRange {
                at,
                command: format!("${number}"),
                param: "value".into(),
                value,
                allowed,
            })?;
        if number == 398 {
            self.ignore("$398: grblHAL changes its planner blocks at the next reboot".into());
            return Ok(());
        }
        if !GrblSettings::is_motion_setting(number) {
            return Ok(());
        }
        let planner = g.planner();
        self.cfg.arcs = ArcSegmentation::Grbl(GrblArcs {
            tolerance_mm: g.arc_tolerance_mm,
        });
        if let Planner::Firmware(d @ Driver::Grbl(_), _) = &mut self.planner {
            let before = d.limits();
            if let Driver::Grbl(p) = d {
                p.set_config(planner)
                    .map_err(|e| plan_error(&self.source, line, "$", e))?;
            }
            let after = d.limits();
            self.limit_changes += 1;
            self.note_overrides(line, &format!("${number}"), &before, &after);
        }
        Ok(())
    }

    fn on_limits(&mut self, line: u64, change: &LimitChange) -> Result<(), GcodeError> {
        let command = change.command_name();
        if matches!(self.planner, Planner::Settle(_)) {
            self.ignore(format!(
                "{command}: settle's planner runs with the job's settings"
            ));
            return Ok(());
        }
        let old = self.shapers.settings();
        let is_shaper = self.shapers.apply(change).map_err(|p| match p {
            ShaperProblem::UnknownName(name, allowed) => plan_error(
                &self.source,
                line,
                command,
                PlanError::UnknownShaper { name, allowed },
            ),
            ShaperProblem::Unsupported(why) => GcodeError::Unsupported {
                at: self.at(line),
                command: command.to_string(),
                why,
            },
        })?;
        if is_shaper {
            let new = self.shapers.settings();
            let (old, new) = (
                build(&old).map_err(|e| plan_error(&self.source, line, command, e))?,
                build(&new).map_err(|e| plan_error(&self.source, line, command, e))?,
            );
            return self.change_shapers(line, command, old, new);
        }
        let Planner::Firmware(d, _) = &mut self.planner else {
            return Ok(());
        };
        let before = d.limits();
        let mut notes = Vec::new();
        let outcome = d
            .apply(change, &mut notes)
            .map_err(|e| plan_error(&self.source, line, command, e))?;
        let after = d.limits();
        for why in notes {
            self.ignore(format!("{command}: {why}"));
        }
        match outcome {
            LimitOutcome::Applied => self.limit_changes += 1,
            LimitOutcome::Ignored(why) => self.ignore(format!("{command}: {why}")),
            LimitOutcome::Dropped => {}
        }
        self.note_overrides(line, command, &before, &after);
        Ok(())
    }

    /// Record the limits the file just raised above the configuration's: where it first
    /// does for each limit, how often and how high.
    fn note_overrides(
        &mut self,
        line: u64,
        command: &str,
        before: &[(&'static str, f64)],
        after: &[(&'static str, f64)],
    ) {
        for ((name, old), (_, new)) in before.iter().zip(after) {
            let Some(&(_, configured)) = self.start_limits.iter().find(|(n, _)| n == name) else {
                continue;
            };
            if new == old || *new <= configured * (1.0 + 1e-9) {
                continue;
            }
            match self.overrides.iter_mut().find(|o| o.limit == *name) {
                Some(o) => {
                    o.highest = o.highest.max(*new);
                    o.raises += 1;
                }
                None => self.overrides.push(LimitOverride {
                    line,
                    command: command.to_string(),
                    limit: name,
                    configured,
                    file: *new,
                    highest: *new,
                    raises: 1,
                }),
            }
        }
    }

    /// A shaper command: the firmware waits for a standstill (Klipper then also for its
    /// step generation to flush, a pause of both shapers' flush delays), and the new
    /// shapers shape what follows.
    fn change_shapers(
        &mut self,
        line: u64,
        command: &str,
        old: AxisShapers,
        new: AxisShapers,
    ) -> Result<(), GcodeError> {
        let Planner::Firmware(d, _) = &mut self.planner else {
            return Ok(());
        };
        let floor = self.cfg.klipper_flush_delay_s;
        let (gap, offset) = match d {
            Driver::Klipper(_) => {
                let old_delay = klipper_flush_delay_s(&old, floor);
                (old_delay + klipper_flush_delay_s(&new, floor), old_delay)
            }
            _ => (0.0, 0.0),
        };
        d.planner()
            .dwell(gap)
            .map_err(|e| plan_error(&self.source, line, command, e))?;
        let switch_s = d.print_time_s() - gap + offset;
        self.drain(line)?;
        self.input.schedule(switch_s, new);
        self.shaper_changes += 1;
        Ok(())
    }

    /// Take everything the planner has finished, and the chunks it makes.
    fn drain(&mut self, line: u64) -> Result<(), GcodeError> {
        loop {
            let done = self.range == Range::After && self.input.done();
            match &mut self.planner {
                Planner::Firmware(d, ps) => {
                    let Some(pm) = d.pop() else {
                        break;
                    };
                    if !done {
                        ps.push(&pm)
                            .map_err(|e| plan_error(&self.source, line, "G1", e))?;
                    }
                    self.on_planned(&pm)
                        .map_err(|e| plan_error(&self.source, line, "G1", e))?;
                    self.refuse_too_long()?;
                }
                Planner::Settle(s) => {
                    let Some(c) = s.pop() else {
                        break;
                    };
                    let c = c.map_err(|e| plan_error(&self.source, line, "G1", e))?;
                    for m in &c.moves {
                        self.on_span(m.seq, m.start_time_s, m.end_time_s)
                            .map_err(|e| plan_error(&self.source, line, "G1", e))?;
                    }
                    self.refuse_too_long()?;
                    if !done {
                        self.on_input(line, c.start_time_s, c.trajectory)?;
                    }
                }
            }
        }
        if let Planner::Firmware(_, ps) = &mut self.planner {
            let chunks: Vec<_> = std::iter::from_fn(|| ps.pop()).collect();
            for c in chunks {
                self.on_input(line, c.start_time_s, c.trajectory)?;
            }
        }
        Ok(())
    }

    /// A move planned longer than [`crate::MAX_STEP_DURATION_S`] (a feed, or velocity or
    /// acceleration limits, so low that it would run for hours), refused at its line.
    fn refuse_too_long(&mut self) -> Result<(), GcodeError> {
        match self.table.take_too_long() {
            None => Ok(()),
            Some((line, duration_s)) => Err(GcodeError::TooLong {
                at: self.at(line),
                command: "move".to_string(),
                duration_s,
                what: "as planned within the job's velocity and acceleration limits".to_string(),
            }),
        }
    }

    fn on_planned(&mut self, pm: &PlannedMove) -> Result<(), PlanError> {
        self.on_span(pm.seq, pm.start_time_s, pm.end_time_s())
    }

    /// Planned segment `seq` runs from `t0` to `t1`: move timing and the layer range.
    fn on_span(&mut self, seq: u64, t0: f64, t1: f64) -> Result<(), PlanError> {
        let layer = self.table.planned(seq, t0, t1);
        match (self.layers, self.range) {
            // Before the range: the output will start no earlier than the look-back
            // before the range's first move, which starts at `t0` or later.
            (Some(_), Range::Before) => self.table.forget_before(t0 - self.input.lookback_s()),
            // After it: the planner runs ahead of the output (a look-ahead flush gives
            // many segments at once, their chunks come after), so until the range is
            // output only the moves before what has been output can go: the range's
            // last chunks still list theirs.
            (Some(_), Range::After) => {
                let mut before = t0 - self.input.lookback_s();
                if !self.input.done() {
                    before = before.min(self.input.emitted_until_s());
                }
                self.table.forget_before(before);
            }
            _ => {}
        }
        let (Some((a, b)), Some(layer)) = (self.layers, layer) else {
            return Ok(());
        };
        match self.range {
            Range::Before if layer >= a => {
                self.input.start_range(t0)?;
                self.range = Range::In;
                if layer > b {
                    self.input.end_range(t0);
                    self.range = Range::After;
                }
            }
            Range::In if layer > b => {
                self.input.end_range(t0);
                self.range = Range::After;
            }
            _ => {}
        }
        Ok(())
    }

    /// An unshaped chunk: shape it and emit what is ready.
    fn on_input(&mut self, line: u64, t0: f64, tr: Trajectory) -> Result<(), GcodeError> {
        self.input
            .push(t0, tr)
            .map_err(|e| plan_error(&self.source, line, "G1", e))?;
        self.emit(line)
    }

    fn emit(&mut self, line: u64) -> Result<(), GcodeError> {
        loop {
            let limit = self.table.complete_until_s();
            let next = self
                .input
                .emit(limit)
                .map_err(|e| plan_error(&self.source, line, "G1", e))?;
            let Some((t0, tr)) = next else {
                return Ok(());
            };
            let moves = self.table.overlapping(t0, t0 + tr.duration_s());
            self.out.push_back(JobChunk {
                start_time_s: t0,
                trajectory: tr,
                moves,
            });
        }
    }

    fn end_of_file(&mut self) -> Result<(), GcodeError> {
        let line = self.reader.lines_read();
        match &mut self.planner {
            Planner::Firmware(d, _) => d.planner().finish(),
            Planner::Settle(s) => s
                .dwell(0.0)
                .map_err(|e| plan_error(&self.source, line, "end of file", e))?,
        }
        self.drain(line)?;
        if let Planner::Firmware(_, ps) = &mut self.planner {
            ps.finish()
                .map_err(|e| plan_error(&self.source, line, "end of file", e))?;
        }
        let t = self.print_time_s();
        self.table.flush(t);
        self.drain(line)?;
        self.input
            .finish()
            .map_err(|e| plan_error(&self.source, line, "end of file", e))?;
        self.emit(line)?;
        self.eof = true;
        Ok(())
    }
}
