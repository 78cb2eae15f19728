//! The streaming G-code reader (see the crate documentation), what is where:
//! - text: `settle_files::lines` (one bounded line at a time), [`lex`] (words and comments), [`cmd`]
//!   (a line's command and [`params`]);
//! - the firmware's conventions: [`dialect`]; GRBL's language: [`grbl`];
//! - motion: [`motion`] (modal state: units, absolute or relative, feed), [`geometry`]
//!   (moves, points, paths, [`geometry::Bounds`]), [`arc`] (`G2`/`G3` geometry),
//!   [`segments`] (how each firmware cuts an arc into straight moves);
//! - what a line means: [`event`] (what the reader yields), [`layers`] (layer changes),
//!   [`limits`] and [`limit_parse`] (motion-limit commands), [`setting`] and
//!   [`setting_parse`] (RepRapFirmware's configuration commands);
//! - [`reader`]: the reader itself, which names a file that holds G-code but is not
//!   text ([`packaged`]: gzip, zip; binary G-code it decodes, [`bgcode`], when it opens
//!   the file itself) and, when it opens the file, one that is no G-code job at all (an
//!   STL model, a 3MF project, a printer.cfg: `settle_files::looks`); [`summary`]: a
//!   file's statistics;
//!   [`canonical`]: events written back as G-code.

pub(crate) mod arc;
pub(crate) mod bgcode;
pub(crate) mod canonical;
pub(crate) mod cmd;
pub(crate) mod dialect;
pub(crate) mod event;
pub(crate) mod geometry;
pub(crate) mod grbl;
pub(crate) mod layers;
pub(crate) mod lex;
pub(crate) mod limit_parse;
pub(crate) mod limits;
pub(crate) mod marlin_arc;
pub(crate) mod motion;
pub(crate) mod packaged;
pub(crate) mod params;
pub(crate) mod prusa_arcs;
pub(crate) mod reader;
pub(crate) mod segments;
pub(crate) mod setting;
pub(crate) mod setting_parse;
pub(crate) mod summary;
