//! What a user wants to know about a file before planning it.

use std::collections::BTreeMap;
use std::fmt;
use std::io::BufRead;

use crate::error::GcodeError;
use crate::read::event::{Event, EventKind, Note};
use crate::read::geometry::{Bounds, MoveKind, Path};
use crate::read::limits::LimitChange;
use crate::read::reader::Reader;
use crate::read::setting::Setting;

/// Distinct limit changes (and notes) kept; further distinct ones are only counted.
const MAX_KEPT: usize = 256;

/// One distinct limit change and how often the file sets it.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitSeen {
    /// The change.
    pub change: LimitChange,
    /// Line of its first occurrence.
    pub first_line: u64,
    /// How many times the file sets exactly this.
    pub count: u64,
}

/// Statistics of a file's events.
#[derive(Debug, Clone)]
pub struct Summary {
    /// Lines read.
    pub lines: u64,
    /// Bytes read.
    pub bytes: u64,
    /// Moves by kind.
    pub print_moves: u64,
    /// Travel moves.
    pub travel_moves: u64,
    /// Extruder-only moves.
    pub extruder_moves: u64,
    /// Of all moves, how many are arcs.
    pub arc_moves: u64,
    /// XYZ path length of printing moves, mm.
    pub print_length_mm: f64,
    /// XYZ path length of travel moves, mm.
    pub travel_length_mm: f64,
    /// Filament pushed (sum of positive E steps), mm.
    pub extruded_mm: f64,
    /// Filament pulled back (sum of negative E steps, as a positive number), mm.
    pub retracted_mm: f64,
    /// Slowest and fastest requested feed of printing moves, mm/s.
    pub print_feed_range_mm_s: Option<(f64, f64)>,
    /// Layer changes seen (= index of the last layer).
    pub layers: u32,
    /// Box around every move's path, mm.
    pub bounds_all: Bounds,
    /// Box around printing moves' paths, mm.
    pub bounds_print: Bounds,
    /// Dwells (G4, M400) and their total time, s.
    pub dwells: u64,
    /// Total dwell time, s.
    pub dwell_s: f64,
    /// Distinct limit changes in file order of first appearance.
    pub limits: Vec<LimitSeen>,
    /// Limit-change events beyond the distinct ones kept.
    pub limits_not_kept: u64,
    /// Machine settings with their line (the first few hundred; RepRapFirmware only).
    pub settings: Vec<(u64, Setting)>,
    /// Notes with their line (the first few hundred).
    pub notes: Vec<(u64, Note)>,
    /// Commands ignored, by name.
    pub ignored: BTreeMap<String, u64>,
    /// Lines skipped as bad (with `skip_bad_lines`).
    pub skipped_lines: u64,
}

impl Default for Summary {
    fn default() -> Self {
        Summary {
            lines: 0,
            bytes: 0,
            print_moves: 0,
            travel_moves: 0,
            extruder_moves: 0,
            arc_moves: 0,
            print_length_mm: 0.0,
            travel_length_mm: 0.0,
            extruded_mm: 0.0,
            retracted_mm: 0.0,
            print_feed_range_mm_s: None,
            layers: 0,
            bounds_all: Bounds::empty(),
            bounds_print: Bounds::empty(),
            dwells: 0,
            dwell_s: 0.0,
            limits: Vec::new(),
            limits_not_kept: 0,
            settings: Vec::new(),
            notes: Vec::new(),
            ignored: BTreeMap::new(),
            skipped_lines: 0,
        }
    }
}

impl Summary {
    /// Reads `reader` to the end (or its first error).
    pub fn read<R: BufRead>(mut reader: Reader<R>) -> Result<Summary, GcodeError> {
        let mut s = Summary::default();
        for ev in reader.by_ref() {
            s.add(&ev?);
        }
        s.take_counts(&reader);
        Ok(s)
    }

    /// Copies the reader's line, byte, ignored and skipped counts.
    pub fn take_counts<R: BufRead>(&mut self, reader: &Reader<R>) {
        self.lines = reader.lines_read();
        self.bytes = reader.bytes_read();
        self.ignored = reader.ignored_commands().clone();
        self.skipped_lines = reader.skipped().count;
    }

    /// All moves.
    pub fn moves(&self) -> u64 {
        self.print_moves + self.travel_moves + self.extruder_moves
    }

    /// Adds one event.
    pub fn add(&mut self, ev: &Event) {
        match &ev.kind {
            EventKind::Move(mv) => {
                let e = mv.extrusion_mm();
                if e > 0.0 {
                    self.extruded_mm += e;
                } else {
                    self.retracted_mm -= e;
                }
                if matches!(mv.path, Path::Arc(_)) {
                    self.arc_moves += 1;
                }
                let b = mv.bounds();
                self.bounds_all.union(&b);
                match mv.kind {
                    MoveKind::Print => {
                        self.print_moves += 1;
                        self.print_length_mm += mv.length_mm();
                        self.bounds_print.union(&b);
                        let f = mv.feed_mm_s;
                        self.print_feed_range_mm_s = Some(match self.print_feed_range_mm_s {
                            Some((lo, hi)) => (lo.min(f), hi.max(f)),
                            None => (f, f),
                        });
                    }
                    MoveKind::Travel => {
                        self.travel_moves += 1;
                        self.travel_length_mm += mv.length_mm();
                    }
                    MoveKind::Extruder => self.extruder_moves += 1,
                }
            }
            EventKind::Dwell { duration_s } => {
                self.dwells += 1;
                self.dwell_s += duration_s;
            }
            EventKind::Layer(_) => self.layers = self.layers.max(ev.layer),
            EventKind::Limits(c) => {
                if let Some(seen) = self.limits.iter_mut().find(|s| s.change == *c) {
                    seen.count += 1;
                } else if self.limits.len() < MAX_KEPT {
                    self.limits.push(LimitSeen {
                        change: c.clone(),
                        first_line: ev.line,
                        count: 1,
                    });
                } else {
                    self.limits_not_kept += 1;
                }
            }
            EventKind::Setting(c) => {
                if self.settings.len() < MAX_KEPT {
                    self.settings.push((ev.line, c.clone()));
                }
            }
            EventKind::Note(n) => {
                if self.notes.len() < MAX_KEPT {
                    self.notes.push((ev.line, n.clone()));
                }
            }
        }
    }
}

fn write_bounds(f: &mut fmt::Formatter<'_>, label: &str, b: &Bounds) -> fmt::Result {
    if b.is_empty() {
        return writeln!(f, "{label}: (none)");
    }
    writeln!(
        f,
        "{label}: X {:.3} .. {:.3}, Y {:.3} .. {:.3}, Z {:.3} .. {:.3} mm",
        b.min_mm[0], b.max_mm[0], b.min_mm[1], b.max_mm[1], b.min_mm[2], b.max_mm[2]
    )
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "lines: {} ({} bytes)", self.lines, self.bytes)?;
        writeln!(
            f,
            "moves: {} (print {}, travel {}, extruder-only {}; arcs {})",
            self.moves(),
            self.print_moves,
            self.travel_moves,
            self.extruder_moves,
            self.arc_moves
        )?;
        writeln!(
            f,
            "print length: {:.3} mm, travel length: {:.3} mm",
            self.print_length_mm, self.travel_length_mm
        )?;
        writeln!(
            f,
            "extruded: {:.3} mm, retracted: {:.3} mm",
            self.extruded_mm, self.retracted_mm
        )?;
        if let Some((lo, hi)) = self.print_feed_range_mm_s {
            writeln!(f, "print feed: {lo:.3} .. {hi:.3} mm/s")?;
        }
        writeln!(f, "layers: {}", self.layers)?;
        write_bounds(f, "bounds (all moves)", &self.bounds_all)?;
        write_bounds(f, "bounds (printing)", &self.bounds_print)?;
        writeln!(f, "dwells: {} ({:.3} s)", self.dwells, self.dwell_s)?;
        writeln!(f, "limit changes: {} distinct", self.limits.len())?;
        for l in &self.limits {
            writeln!(f, "  line {} (x{}): {:?}", l.first_line, l.count, l.change)?;
        }
        if self.limits_not_kept > 0 {
            writeln!(f, "  ... and {} more", self.limits_not_kept)?;
        }
        for (line, c) in &self.settings {
            writeln!(f, "setting, line {line}: {c:?}")?;
        }
        for (line, n) in &self.notes {
            writeln!(f, "note, line {line}: {n:?}")?;
        }
        let ignored: Vec<String> = self
            .ignored
            .iter()
            .map(|(k, v)| format!("{k} x{v}"))
            .collect();
        writeln!(
            f,
            "ignored commands: {}",
            if ignored.is_empty() {
                "none".to_string()
            } else {
                ignored.join(", ")
            }
        )?;
        if self.skipped_lines > 0 {
            writeln!(f, "skipped bad lines: {}", self.skipped_lines)?;
        }
        Ok(())
    }
}
