//! Which Prusa printer a file is for: the first `M862.3 P "<name>"` before its first move.
//!
//! PrusaSlicer's start G-code for every Buddy printer begins with the printer-model check
//! (`M862.3 P "[printer_model]"` or the name itself, resources/profiles/PrusaResearch.ini:
//! `MINI`, `MK3.5`, `MK3.9`, `MK3.9S`, `MK4`, `MK4S`, `XL`, `COREONE`); Buddy reads it before
//! printing (src/common/gcode/gcode_info.cpp, `GCodeInfo::parse_m862`) to warn about a
//! file sliced for another printer.

use std::io::BufRead;
use std::path::Path;

use settle_planner::firmware::Firmware;
use settle_planner::firmware::marlin::PrusaModel;

use super::config::{JobConfig, PrusaPrinter};
use crate::error::{GcodeError, Location};
use crate::read::dialect::Dialect;
use crate::read::event::{EventKind, Note};
use crate::read::reader::{Reader, ReaderOptions};

/// The printer `reader`'s file names (read in the Prusa dialect, up to its first move):
/// [`PrusaPrinter::unnamed`] when no `M862.3 P` comes before the first move, an error
/// ([`GcodeError::UnknownPrinter`], with the line) when it names a printer settle has no
/// settings for. A read error before the first move is returned as the job would meet it.
pub fn prusa_printer<R: BufRead>(mut reader: Reader<R>) -> Result<PrusaPrinter, GcodeError> {
    for ev in reader.by_ref() {
        let ev = ev?;
        match ev.kind {
            EventKind::Move(_) => break,
            EventKind::Note(Note::PrinterModel { name }) => {
                return match PrusaModel::from_printer_name(&name) {
                    Some(model) => Ok(PrusaPrinter {
                        model,
                        named_at: Some((ev.line, name)),
                    }),
                    None => Err(GcodeError::UnknownPrinter {
                        at: Location {
                            source_name: reader.source_name().clone(),
                            line: ev.line,
                            column: None,
                        },
                        name,
                        known: PrusaModel::printer_names(),
                    }),
                };
            }
            _ => {}
        }
    }
    Ok(PrusaPrinter::unnamed())
}

impl JobConfig {
    /// [`JobConfig::defaults`] for the file at `path`: for Prusa, the settings of the
    /// printer the file names ([`prusa_printer`], [`JobConfig::prusa`]); the file is read
    /// up to its first move.
    pub fn for_file(firmware: Firmware, path: &Path) -> Result<Self, GcodeError> {
        if firmware != Firmware::Prusa {
            return Self::defaults(firmware);
        }
        let reader = Reader::open(path, ReaderOptions::new(Dialect::Prusa))?;
        Self::prusa(prusa_printer(reader)?)
    }
}
