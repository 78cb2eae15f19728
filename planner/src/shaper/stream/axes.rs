//! Several axes shaped together, each with its own shaper, cut into common chunks.

use super::alignment::Alignment;
use super::single::ShaperStream;
use crate::shaper::Shaper;
use crate::{PlanError, Trajectory};

/// One [`ShaperStream`] per axis of a [`Trajectory`] stream: chunks in, shaped chunks out,
/// every axis cut at the same instants (Klipper shapes X and Y with their own settings;
/// axes without a shaper pass through unchanged).
#[derive(Debug, Clone)]
pub struct AxesShaper {
    axes: Vec<ShaperStream>,
    started: bool,
}

impl AxesShaper {
    /// One stream per entry of `shapers` (`None`: that axis is not shaped).
    pub fn new(shapers: &[Option<Shaper>], alignment: Alignment) -> Self {
        Self {
            axes: shapers
                .iter()
                .map(|s| ShaperStream::new(s.as_ref(), alignment))
                .collect(),
            started: false,
        }
    }

    /// Number of axes.
    pub fn dof(&self) -> usize {
        self.axes.len()
    }

    /// Append the next chunk (one profile per axis, all of the same duration), starting
    /// at `start_time_s` where the previous one ended.
    pub fn push(&mut self, start_time_s: f64, chunk: &Trajectory) -> Result<(), PlanError> {
        if chunk.dof() != self.axes.len() {
            return Err(PlanError::InvalidInput {
                reason: "a shaped chunk needs one profile per shaped axis",
            });
        }
        let d = chunk.duration_s();
        if chunk
            .axes()
            .iter()
            .any(|p| (p.duration_s() - d).abs() > 1e-9 * (1.0 + d))
        {
            return Err(PlanError::InvalidInput {
                reason: "every axis of a shaped chunk must last as long as the chunk",
            });
        }
        for (s, p) in self.axes.iter_mut().zip(chunk.axes()) {
            s.push(start_time_s, p)?;
        }
        if !self.started {
            self.started = true;
            let start = self
                .axes
                .iter()
                .map(ShaperStream::emitted_until_s)
                .fold(f64::INFINITY, f64::min);
            for s in &mut self.axes {
                s.start_output_at(start)?;
            }
        }
        Ok(())
    }

    /// Shape axis `axis` with `shaper` from the end of the input so far
    /// ([`ShaperStream::set_shaper`]).
    pub fn set_shaper(&mut self, axis: usize, shaper: Option<&Shaper>) -> Result<(), PlanError> {
        let s = self.axes.get_mut(axis).ok_or(PlanError::InvalidInput {
            reason: "no such shaped axis",
        })?;
        s.set_shaper(shaper)
    }

    /// No more input.
    pub fn finish(&mut self) {
        for s in &mut self.axes {
            s.finish();
        }
    }

    /// How far every axis's output is known (s).
    pub fn available_until_s(&self) -> f64 {
        self.axes
            .iter()
            .map(ShaperStream::available_until_s)
            .fold(f64::INFINITY, f64::min)
    }

    /// Where the next chunk starts (s).
    pub fn emitted_until_s(&self) -> f64 {
        self.axes
            .first()
            .map_or(f64::NEG_INFINITY, ShaperStream::emitted_until_s)
    }

    /// After [`Self::finish`]: when the last axis's shaped motion ends (s).
    pub fn end_s(&self) -> Option<f64> {
        self.axes
            .iter()
            .map(ShaperStream::end_s)
            .try_fold(f64::NEG_INFINITY, |m, e| e.map(|e| m.max(e)))
    }

    /// The shaped chunk from the end of the last one to `until_s` (at most
    /// [`Self::available_until_s`]): its start time and one profile per axis.
    pub fn emit(&mut self, until_s: f64) -> Result<(f64, Trajectory), PlanError> {
        let mut start = 0.0;
        let mut profiles = Vec::with_capacity(self.axes.len());
        for s in &mut self.axes {
            let (t0, p) = s.emit(until_s)?;
            start = t0;
            profiles.push(p);
        }
        Ok((start, Trajectory::new(profiles)?))
    }
}
