//! From unshaped per-axis chunks to shaped ones: shaper changes at their instants, the
//! layer range, and the look-back that gives the range's first chunk its exact state.
//!
//! Before the range starts, chunks are only kept for the last [`LOOKBACK_MARGIN_S`] plus
//! the longest shaper's duration; when the range's first move is known, those chunks are
//! shaped (so the shaped state at the range start is exact: the shaper's output there
//! depends on the input up to a shaper's duration earlier) and the output is cut at the
//! range start. After the range's last move the output is cut at its end.
//!
//! A pre-roll ([`Input::set_preroll`]) starts the output that long before the range's
//! first move (no earlier than the input's start), so that a simulation of the range
//! starts from the motion before it; the look-back then also keeps the pre-roll.

use std::collections::VecDeque;

use settle_planner::shaper::Shaper;
use settle_planner::shaper::stream::{Alignment, AxesShaper};
use settle_planner::{PlanError, Trajectory};

use super::slice::split;

/// Look-back beyond the longest shaper (s): covers a profile chunk's jump window.
const LOOKBACK_MARGIN_S: f64 = 0.01;

/// Shapers of X, Y, Z, E (E is never shaped).
pub(crate) type AxisShapers = [Option<Shaper>; 4];

#[derive(Debug)]
enum Entry {
    Chunk(f64, Trajectory),
    Switch(Box<AxisShapers>),
}

/// The shaping stage (module doc).
#[derive(Debug)]
pub(crate) struct Input {
    alignment: Alignment,
    /// Shapers in force at the end of the input so far.
    current: AxisShapers,
    /// Shapers in force at the start of the look-back.
    lookback_start: AxisShapers,
    lookback: VecDeque<Entry>,
    /// Shaper changes not yet reached by the input: (time, shapers).
    switches: VecDeque<(f64, AxisShapers)>,
    shaper: Option<AxesShaper>,
    /// Whether a layer range limits the output.
    ranged: bool,
    range_start_s: Option<f64>,
    range_end_s: Option<f64>,
    input_end_s: f64,
    finished: bool,
    /// How long before the range's first move the output starts (s).
    preroll_s: f64,
}

fn longest(s: &AxisShapers) -> f64 {
    s.iter()
        .flatten()
        .map(Shaper::duration_s)
        .fold(0.0, f64::max)
}

impl Input {
    /// A stage shaping with `initial`; `ranged`: output only between
    /// [`Self::start_range`] and [`Self::end_range`].
    pub(crate) fn new(alignment: Alignment, initial: AxisShapers, ranged: bool) -> Self {
        Self {
            alignment,
            lookback_start: initial.clone(),
            current: initial,
            lookback: VecDeque::new(),
            switches: VecDeque::new(),
            shaper: None,
            ranged,
            range_start_s: None,
            range_end_s: None,
            input_end_s: f64::NEG_INFINITY,
            finished: false,
            preroll_s: 0.0,
        }
    }

    /// Start the output `preroll_s` before the range's first move (module doc).
    pub(crate) fn set_preroll(&mut self, preroll_s: f64) {
        self.preroll_s = preroll_s;
    }

    /// The pre-roll (s).
    pub(crate) fn preroll_s(&self) -> f64 {
        self.preroll_s
    }

    /// How far back (s) from the end of the input the look-back reaches: the longest
    /// shaper's duration, a margin and the pre-roll. Moves ending before that can no
    /// longer meet an emitted chunk.
    pub(crate) fn lookback_s(&self) -> f64 {
        longest(&self.current).max(longest(&self.lookback_start))
            + LOOKBACK_MARGIN_S
            + self.preroll_s
    }

    /// The shapers become `shapers` at `at_s` (no earlier than the input so far).
    pub(crate) fn schedule(&mut self, at_s: f64, shapers: AxisShapers) {
        self.switches.push_back((at_s, shapers));
    }

    /// The range's first move starts at `at_s`: shape from the look-back on.
    pub(crate) fn start_range(&mut self, at_s: f64) -> Result<(), PlanError> {
        if self.range_start_s.is_some() {
            return Ok(());
        }
        self.range_start_s = Some(at_s - self.preroll_s);
        let mut shaper = AxesShaper::new(&self.lookback_start, self.alignment);
        let mut shapers = self.lookback_start.clone();
        for e in self.lookback.drain(..) {
            match e {
                Entry::Chunk(t0, tr) => shaper.push(t0, &tr)?,
                Entry::Switch(s) => {
                    for (i, (old, new)) in shapers.iter().zip(s.iter()).enumerate() {
                        if old != new {
                            shaper.set_shaper(i, new.as_ref())?;
                        }
                    }
                    shapers = *s;
                }
            }
        }
        self.shaper = Some(shaper);
        Ok(())
    }

    /// The range's last move ends at `at_s`.
    pub(crate) fn end_range(&mut self, at_s: f64) {
        if self.range_end_s.is_none() {
            self.range_end_s = Some(at_s);
        }
    }

    /// Append the next unshaped chunk (X, Y, Z, E) starting at `t0`.
    pub(crate) fn push(&mut self, t0: f64, tr: Trajectory) -> Result<(), PlanError> {
        if !self.ranged && self.shaper.is_none() {
            self.start_range(f64::NEG_INFINITY)?;
        }
        let mut rest = Some((t0, tr));
        while let Some((start, tr)) = rest.take() {
            let next = self.switches.front().map(|s| s.0);
            match next {
                Some(at) if at < start + tr.duration_s() => {
                    let (before, after) = split(start, &tr, at)?;
                    if let Some((s, b)) = before {
                        self.append(s, b)?;
                    }
                    if let Some((_, shapers)) = self.switches.pop_front() {
                        self.switch(shapers)?;
                    }
                    rest = after;
                }
                _ => self.append(start, tr)?,
            }
        }
        Ok(())
    }

    fn append(&mut self, t0: f64, tr: Trajectory) -> Result<(), PlanError> {
        self.input_end_s = t0 + tr.duration_s();
        match &mut self.shaper {
            Some(s) => s.push(t0, &tr)?,
            None => {
                self.lookback.push_back(Entry::Chunk(t0, tr));
                let keep = self.lookback_s();
                // Drop chunks (and the changes before them) that end before the window.
                loop {
                    let stale = match self.lookback.front() {
                        Some(Entry::Chunk(s, c)) if self.lookback.len() > 1 => {
                            s + c.duration_s() < self.input_end_s - keep
                        }
                        _ => false,
                    };
                    if !stale {
                        break;
                    }
                    self.lookback.pop_front();
                    while let Some(Entry::Switch(sw)) = self.lookback.front() {
                        self.lookback_start = (**sw).clone();
                        self.lookback.pop_front();
                    }
                }
            }
        }
        Ok(())
    }

    fn switch(&mut self, shapers: AxisShapers) -> Result<(), PlanError> {
        match &mut self.shaper {
            Some(s) => {
                for (i, (old, new)) in self.current.iter().zip(&shapers).enumerate() {
                    if old != new {
                        s.set_shaper(i, new.as_ref())?;
                    }
                }
            }
            None => self
                .lookback
                .push_back(Entry::Switch(Box::new(shapers.clone()))),
        }
        self.current = shapers;
        Ok(())
    }

    /// No more input.
    pub(crate) fn finish(&mut self) -> Result<(), PlanError> {
        // Changes after the last motion take effect on nothing.
        self.switches.clear();
        self.finished = true;
        if !self.ranged && self.shaper.is_none() {
            return Ok(());
        }
        if let Some(s) = &mut self.shaper {
            s.finish();
        }
        Ok(())
    }

    /// Up to when the output has been emitted (s; minus infinity before it starts).
    pub(crate) fn emitted_until_s(&self) -> f64 {
        self.shaper
            .as_ref()
            .map_or(f64::NEG_INFINITY, AxesShaper::emitted_until_s)
    }

    /// Whether everything the range asks for has been emitted.
    pub(crate) fn done(&self) -> bool {
        let Some(s) = &self.shaper else {
            return self.finished;
        };
        let cursor = s.emitted_until_s();
        match (self.range_end_s, self.finished) {
            (Some(e), _) => cursor >= e,
            (None, true) => s.end_s().is_none_or(|e| cursor >= e),
            (None, false) => false,
        }
    }

    /// The next shaped chunk, ending no later than `limit_s`, if there is one.
    pub(crate) fn emit(&mut self, limit_s: f64) -> Result<Option<(f64, Trajectory)>, PlanError> {
        let Some(s) = &mut self.shaper else {
            return Ok(None);
        };
        let mut target = s.available_until_s().min(limit_s);
        if let Some(e) = self.range_end_s {
            target = target.min(e);
        }
        if let (true, Some(e)) = (self.finished, s.end_s()) {
            target = target.min(e);
        }
        let mut cursor = s.emitted_until_s();
        if let Some(rs) = self.range_start_s.filter(|rs| cursor < *rs) {
            if target < rs {
                return Ok(None);
            }
            s.emit(rs)?;
            cursor = rs;
        }
        if target > cursor {
            return Ok(Some(s.emit(target)?));
        }
        Ok(None)
    }
}
