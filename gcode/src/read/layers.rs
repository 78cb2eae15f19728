//! Layer changes from slicer comments, or from Z when a file has none.
//!
//! In [`LayerMode::Auto`] the Z fallback stays off once the file names, in its header
//! comments (before the first move), a slicer whose files mark every layer
//! ([`marks_every_layer`]), and from the first marker on: a purge line in the start G-code
//! must not count as a layer.
//!
//! A job has at most [`MAX_LAYERS`] layers: the change that would open one more is not
//! emitted but kept ([`Layers::refused`]), and the reader ends with
//! [`crate::GcodeError::TooManyLayers`] at its line.

use crate::MAX_LAYERS;
use crate::read::event::{LayerChange, LayerSource};
use crate::read::geometry::Move;

/// Where layer changes come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LayerMode {
    /// Slicer markers; a planar printing move at a new Z when the file has none.
    #[default]
    Auto,
    /// Slicer markers only.
    Comments,
    /// Planar printing moves at a new Z only.
    ZChange,
}

impl LayerMode {
    /// Every mode by its name, as `--layer-source` and `[gcode] layer_source` take them.
    pub const NAMES: [(&'static str, LayerMode); 3] = [
        ("auto", LayerMode::Auto),
        ("markers", LayerMode::Comments),
        ("z", LayerMode::ZChange),
    ];

    /// The mode a name gives (`auto`, `markers`, `z`; any case); the error names what is
    /// allowed.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::NAMES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name.trim()))
            .map(|&(_, m)| m)
            .ok_or_else(|| {
                format!(
                    "`{}`: allowed: auto (slicer markers, else changes of Z), markers (slicer markers only: a file without them is one layer), z (changes of Z only)",
                    crate::excerpt(name, crate::QUOTED_CHARS)
                )
            })
    }

    /// The mode's name ([`LayerMode::NAMES`]).
    pub fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, m)| *m == self)
            .map_or("auto", |(n, _)| n)
    }
}

/// Slicers whose every file marks every layer, as they name themselves in the header
/// (lower case).
const MARKING_SLICERS: [&str; 5] = [
    "orcaslicer",
    "bambustudio",
    "cura_steamengine",
    "simplify3d",
    "ideamaker",
];

/// Slicers that mark every layer from version 2.3 on: PrusaSlicer writes `;LAYER_CHANGE`
/// and `;Z:` at every layer from 2.3.0 (`GCode::process_layer` in its
/// src/libslic3r/GCode.cpp; 2.2.0 writes neither), and SuperSlicer, its fork, numbers its
/// versions after the PrusaSlicer it follows. Slic3r itself (and Slic3r Prusa Edition,
/// which names itself "Slic3r 1.x-prusa3d") writes no marker unless the user's layer
/// G-code does.
const MARKING_FROM_2_3: [&str; 2] = ["prusaslicer", "superslicer"];

/// Whether a header comment (lower case) names a slicer whose files mark every layer.
fn marks_every_layer(lower: &str) -> bool {
    if MARKING_SLICERS.iter().any(|s| lower.contains(s)) {
        return true;
    }
    MARKING_FROM_2_3.iter().any(|name| {
        lower.match_indices(name).any(|(at, _)| {
            let version = lower[at + name.len()..].trim_start();
            let mut parts = version.split('.').map(|p| {
                let digits = p.len() - p.trim_start_matches(|c: char| c.is_ascii_digit()).len();
                p[..digits].parse::<u32>().ok()
            });
            match (parts.next().flatten(), parts.next().flatten()) {
                (Some(major), Some(minor)) => (major, minor) >= (2, 3),
                _ => false,
            }
        })
    })
}

/// Z differences smaller than this are the same layer, mm.
const SAME_Z_MM: f64 = 1e-6;

#[derive(Debug, Default)]
pub(crate) struct Layers {
    mode: LayerMode,
    /// The current layer index.
    pub(crate) index: u32,
    /// A marker waiting for its Z comment: (line, change).
    pending: Option<(u64, LayerChange)>,
    z_fallback_off: bool,
    moved: bool,
    layer_z: Option<f64>,
    /// The first layer change past [`MAX_LAYERS`]: (line, how it was found).
    refused: Option<(u64, LayerSource)>,
}

impl Layers {
    pub(crate) fn new(mode: LayerMode) -> Self {
        Layers {
            mode,
            z_fallback_off: mode == LayerMode::Comments,
            ..Layers::default()
        }
    }

    /// Reads a comment-only line; layer changes to emit now go to `emit` as (line, layer
    /// index, change).
    pub(crate) fn comment(
        &mut self,
        line: u64,
        text: &str,
        emit: &mut Vec<(u64, u32, LayerChange)>,
    ) {
        let t = text.trim();
        if !self.moved && self.mode == LayerMode::Auto && marks_every_layer(&t.to_ascii_lowercase())
        {
            self.z_fallback_off = true;
        }
        if self.mode == LayerMode::ZChange {
            return;
        }
        let marker = if let Some(n) = t.strip_prefix("LAYER:") {
            n.parse::<i64>()
                .ok()
                .map(|n| change(LayerSource::Cura, Some(n), None))
        } else if t == "LAYER_CHANGE" {
            Some(change(LayerSource::LayerChange, None, None))
        } else if t == "CHANGE_LAYER" {
            Some(change(LayerSource::ChangeLayer, None, None))
        } else if let Some(rest) = t.strip_prefix("layer ") {
            simplify3d(rest)
        } else {
            None
        };
        if let Some(marker) = marker {
            self.z_fallback_off = true;
            emit.extend(self.flush());
            self.pending = Some((line, marker));
            if !matches!(
                marker.source,
                LayerSource::LayerChange | LayerSource::ChangeLayer
            ) {
                emit.extend(self.flush());
            }
            return;
        }
        if let Some((_, pending)) = &mut self.pending {
            let z = match pending.source {
                LayerSource::LayerChange => t.strip_prefix("Z:"),
                LayerSource::ChangeLayer => t.strip_prefix("Z_HEIGHT:"),
                _ => None,
            };
            if let Some(z) = z
                .and_then(|z| z.trim().parse::<f64>().ok())
                .filter(|z| z.is_finite())
            {
                pending.z_mm = Some(z);
                emit.extend(self.flush());
            }
        }
    }

    /// Emits the pending marker, if any, as the start of a new layer.
    pub(crate) fn flush(&mut self) -> Option<(u64, u32, LayerChange)> {
        let (line, c) = self.pending.take()?;
        self.open(line, c.source)?;
        Some((line, self.index, c))
    }

    /// Counts a new layer opened at `line`; past [`MAX_LAYERS`] it is refused instead
    /// (`None`).
    fn open(&mut self, line: u64, source: LayerSource) -> Option<()> {
        if self.index >= MAX_LAYERS {
            self.refused.get_or_insert((line, source));
            return None;
        }
        self.index += 1;
        Some(())
    }

    /// The layer change past [`MAX_LAYERS`], once: its line and how it was found.
    pub(crate) fn refused(&mut self) -> Option<(u64, LayerSource)> {
        self.refused.take()
    }

    /// Called for every move (of line `line`) before it is emitted; returns a Z-fallback
    /// layer change.
    pub(crate) fn before_move(
        &mut self,
        line: u64,
        mv: &Move,
        printing: bool,
    ) -> Option<LayerChange> {
        self.moved = true;
        if self.z_fallback_off || !printing || mv.start.z_mm != mv.end.z_mm {
            return None;
        }
        let z = mv.end.z_mm;
        if self.layer_z.is_some_and(|lz| (z - lz).abs() <= SAME_Z_MM) {
            return None;
        }
        self.layer_z = Some(z);
        self.open(line, LayerSource::ZChange)?;
        Some(change(LayerSource::ZChange, None, Some(z)))
    }
}

fn change(source: LayerSource, slicer_number: Option<i64>, z_mm: Option<f64>) -> LayerChange {
    LayerChange {
        source,
        slicer_number,
        z_mm,
    }
}

/// `; layer 12, Z = 2.400` (the text after `layer `).
fn simplify3d(rest: &str) -> Option<LayerChange> {
    let (n, z) = rest.split_once(',')?;
    let n = n.trim().parse::<i64>().ok()?;
    let z = z
        .trim()
        .strip_prefix('Z')?
        .trim_start()
        .strip_prefix('=')?
        .trim()
        .parse::<f64>()
        .ok()?;
    Some(change(
        LayerSource::Simplify3d,
        Some(n),
        Some(z).filter(|z| z.is_finite()),
    ))
}
