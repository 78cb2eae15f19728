//! One axis's stream: input history, the shaper regimes in force, shaped output.

use std::collections::VecDeque;

use super::alignment::Alignment;
use super::history::{Held, History};
use super::regime::Regime;
use crate::runs::RunSort;
use crate::shaper::Shaper;
use crate::shaper::apply::segments_between;
use crate::{PlanError, Profile, Sample, Segment, State};

/// Shapes one axis's motion chunk by chunk (module doc).
#[derive(Debug, Clone)]
pub struct ShaperStream {
    alignment: Alignment,
    /// Active shaping regimes, oldest first.
    regimes: VecDeque<Regime>,
    /// Position offset left by retired regimes (module doc).
    offset: f64,
    /// Input segments still needed, oldest first.
    history: History,
    /// For each impulse of each regime in turn, where its input was last found in
    /// `history` ([`History::at_from`]; any value is safe).
    cursors: Vec<usize>,
    /// The knots of the last emitted chunk and their sorter: buffers kept between chunks.
    knots: Vec<f64>,
    sorter: RunSort,
    /// Time and state of the first input instant.
    first: Option<(f64, State)>,
    /// Time and state at the end of the input so far.
    last: (f64, State),
    finished: bool,
    /// Output emitted up to here.
    cursor_s: f64,
    /// Acceleration at the end of the last emitted segment.
    a_now: f64,
}

impl ShaperStream {
    /// A stream shaping with `shaper` (`None`: the output is the input).
    pub fn new(shaper: Option<&Shaper>, alignment: Alignment) -> Self {
        let mut regimes = VecDeque::new();
        regimes.push_back(Regime::new(shaper, alignment, None));
        Self {
            alignment,
            regimes,
            offset: 0.0,
            history: History::default(),
            cursors: Vec::new(),
            knots: Vec::new(),
            sorter: RunSort::default(),
            first: None,
            last: (0.0, State::default()),
            finished: false,
            cursor_s: 0.0,
            a_now: 0.0,
        }
    }

    /// Append the next chunk of input, `profile` starting at `start_time_s` on the
    /// stream's clock: the end of the previous chunk (to 1e-9 s).
    pub fn push(&mut self, start_time_s: f64, profile: &Profile) -> Result<(), PlanError> {
        if self.finished {
            return Err(PlanError::InvalidInput {
                reason: "a chunk was pushed into a shaper stream after finish",
            });
        }
        if !start_time_s.is_finite() {
            return Err(PlanError::NonFinite {
                name: "chunk start time",
                value: start_time_s,
            });
        }
        match self.first {
            None => {
                self.first = Some((start_time_s, profile.start()));
                self.cursor_s = start_time_s + self.min_tau();
            }
            Some(_) => {
                if (start_time_s - self.last.0).abs() > 1e-9 {
                    return Err(PlanError::InvalidInput {
                        reason: "shaper stream chunks must follow each other without gaps",
                    });
                }
            }
        }
        let mut t = start_time_s;
        for (t0, start, seg) in profile.iter() {
            self.history.push_back(Held {
                t0: start_time_s + t0,
                start,
                seg: *seg,
            });
            t = start_time_s + t0 + seg.duration_s();
        }
        self.last = (t.max(start_time_s), profile.end());
        Ok(())
    }

    /// Shape the input from the end of the input so far with `shaper` (module doc); the
    /// motion before keeps its shaper. Before any input this just replaces the shaper.
    pub fn set_shaper(&mut self, shaper: Option<&Shaper>) -> Result<(), PlanError> {
        if self.finished {
            return Err(PlanError::InvalidInput {
                reason: "the shaper of a finished shaper stream cannot change",
            });
        }
        if self.first.is_none() {
            self.regimes.clear();
            self.regimes
                .push_back(Regime::new(shaper, self.alignment, None));
            return Ok(());
        }
        let (t, s) = self.last;
        if let Some(r) = self.regimes.back_mut() {
            r.until = Some((t, s.p, s.v));
        }
        self.regimes
            .push_back(Regime::new(shaper, self.alignment, Some((t, s.p, s.v))));
        Ok(())
    }

    /// No more input: the motion continues at its final velocity (at rest after a move).
    pub fn finish(&mut self) {
        self.finished = true;
    }

    /// Smallest impulse time of the active regimes (s; <= 0).
    fn min_tau(&self) -> f64 {
        self.regimes.iter().map(Regime::min_tau).fold(0.0, f64::min)
    }

    /// How far the output is known (s): the input end plus the earliest impulse time;
    /// after [`Self::finish`] everything is (infinity); before any input nothing (minus
    /// infinity).
    pub fn available_until_s(&self) -> f64 {
        if self.first.is_none() {
            return f64::NEG_INFINITY;
        }
        if self.finished {
            return f64::INFINITY;
        }
        self.last.0 + self.min_tau()
    }

    /// Start the output at `t_s` instead of where the first input first shows (before
    /// anything is emitted, and no later than that point): the output there is the
    /// input's continuation before its start. Used to start several axes together.
    pub fn start_output_at(&mut self, t_s: f64) -> Result<(), PlanError> {
        let natural = self.first.map(|(t, _)| t + self.min_tau());
        match natural {
            Some(n) if t_s <= n && self.cursor_s == n => {
                self.cursor_s = t_s;
                Ok(())
            }
            _ => Err(PlanError::InvalidInput {
                reason: "the output start can only move earlier, after the first chunk and before any output",
            }),
        }
    }

    /// Where the next emitted chunk starts (s on the stream's clock).
    pub fn emitted_until_s(&self) -> f64 {
        self.cursor_s
    }

    /// After [`Self::finish`]: the time after which the shaped motion continues at the
    /// input's final velocity (the last input instant plus the latest impulse time).
    pub fn end_s(&self) -> Option<f64> {
        let last = self.regimes.back()?;
        self.finished.then(|| self.last.0 + last.max_tau())
    }

    /// The exact shaped state at `t` (right-continuous), for any `t` the input determines.
    pub fn shaped_at(&self, t: f64) -> Sample {
        self.shaped_with(t, |_, x| self.input_at(x))
    }

    /// [`Self::shaped_at`] with `input(k, s)` the input at `s` for the `k`-th impulse
    /// counted over all regimes in turn.
    fn shaped_with(&self, t: f64, mut input: impl FnMut(usize, f64) -> Sample) -> Sample {
        let mut s = Sample {
            p: self.offset,
            ..Sample::default()
        };
        let mut k = 0;
        for r in &self.regimes {
            r.add_to(&mut s, t, |i, x| input(k + i, x));
            k += r.taus().len();
        }
        s
    }

    /// The input (with its extensions) at `t`.
    fn input_at(&self, t: f64) -> Sample {
        self.input_in(t, |h| h.at(t))
    }

    /// [`Self::input_at`], bit for bit, finding the input segment by walking from
    /// `cursor` ([`History::at_from`]).
    #[inline]
    fn input_from(&self, cursor: &mut usize, t: f64) -> Sample {
        self.input_in(t, |h| h.at_from(cursor, t))
    }

    /// The input at `t`, `index` giving the history segment in force there.
    #[inline]
    fn input_in(&self, t: f64, index: impl FnOnce(&History) -> usize) -> Sample {
        let extend = |t0: f64, st: State| Sample {
            p: st.p + st.v * (t - t0),
            v: st.v,
            a: 0.0,
            j: 0.0,
        };
        match self.first {
            None => return Sample::default(),
            Some((t0, st)) if t < t0 => return extend(t0, st),
            _ => {}
        }
        if self.finished && t >= self.last.0 {
            return extend(self.last.0, self.last.1);
        }
        let i = index(&self.history);
        match self.history.held().get(i) {
            Some(h) => h.seg.sample(&h.start, t - h.t0),
            None => extend(self.last.0, self.last.1),
        }
    }

    /// The shaped motion from the end of the last emitted chunk to `until_s` (at most
    /// [`Self::available_until_s`]), as a profile whose `t = 0` is the returned start
    /// time. Consecutive chunks join continuously.
    pub fn emit(&mut self, until_s: f64) -> Result<(f64, Profile), PlanError> {
        if self.first.is_none() {
            return Err(PlanError::InvalidInput {
                reason: "a shaper stream cannot emit before its first chunk",
            });
        }
        let limit = self.available_until_s();
        if !(until_s <= limit + 1e-12) {
            return Err(PlanError::InvalidInput {
                reason: "a shaper stream can only emit what its input determines",
            });
        }
        let (a, b) = (self.cursor_s, until_s.max(self.cursor_s));
        if self.regimes.len() == 1 && self.offset == 0.0 && self.regimes[0].is_identity() {
            return self.pass_through(a, b);
        }
        let mut knots = std::mem::take(&mut self.knots);
        let mut sorter = std::mem::take(&mut self.sorter);
        self.knots_into(a, b, &mut knots, &mut sorter);
        // Every evaluation below is at a time no earlier than the one before (`a`, then
        // the middles of the sorted knots' intervals): each impulse's input is found by a
        // cursor walking forward through the history.
        let impulses = self.regimes.iter().map(|r| r.taus().len()).sum();
        let mut cursors = std::mem::take(&mut self.cursors);
        cursors.resize(impulses, usize::MAX);
        let mut shaped = |t: f64| self.shaped_with(t, |k, x| self.input_from(&mut cursors[k], x));
        let s0 = shaped(a);
        let start = State {
            p: s0.p,
            v: s0.v,
            a: self.a_now,
        };
        let (segments, a_end) = segments_between(&knots, self.a_now, &mut shaped);
        self.cursors = cursors;
        self.knots = knots;
        self.sorter = sorter;
        self.a_now = a_end;
        self.cursor_s = b;
        self.forget();
        Ok((a, Profile::new(start, segments)?))
    }

    /// The input itself from `a` to `b` (no shaping): its segments, cut at `a` and `b`,
    /// whole segments copied as they are.
    fn pass_through(&mut self, a: f64, b: f64) -> Result<(f64, Profile), PlanError> {
        let s0 = self.input_at(a);
        let mut segments = Vec::new();
        let held = self.history.held();
        let lo = held.partition_point(|h| h.t1() <= a && h.t0 < a);
        let mut covered = a;
        for h in held.range(lo..) {
            if h.t0 >= b {
                break;
            }
            let inside = h.t0 >= a && h.t1() <= b;
            let d = if inside {
                h.seg.duration_s()
            } else {
                (h.t1().min(b) - h.t0.max(a)).max(0.0)
            };
            covered = covered.max(h.t1().min(b));
            segments.push(match h.seg {
                Segment::Jerk { jerk, .. } => Segment::Jerk {
                    duration_s: d,
                    jerk,
                },
                Segment::Accel { accel, .. } => Segment::Accel {
                    duration_s: d,
                    accel,
                },
            });
        }
        if self.finished && b > covered {
            // Beyond the input's end: its continuation at constant velocity.
            segments.push(Segment::Accel {
                duration_s: b - covered,
                accel: 0.0,
            });
        }
        let start = State {
            p: s0.p,
            v: s0.v,
            a: s0.a,
        };
        let profile = Profile::new(start, segments)?;
        self.a_now = profile.end().a;
        self.cursor_s = b;
        self.forget();
        Ok((a, profile))
    }

    /// Every breakpoint of every shifted copy inside `(a, b)`, with `a` and `b`, sorted
    /// and without repeats, into `knots` (its buffer reused).
    fn knots_into(&self, a: f64, b: f64, knots: &mut Vec<f64>, sorter: &mut RunSort) {
        knots.clear();
        knots.extend([a, b]);
        let first_t = self.first.map(|(t, _)| t);
        // Sorted by merging runs that are each in order: [a, b]; for each impulse, the
        // span ends and the input's ends (a few), then the input's breakpoints, in order
        // but for rounding (a chunk's segment times and the next chunk's start).
        for r in &self.regimes {
            for &tau in r.taus() {
                let add = |knots: &mut Vec<f64>, t: f64| {
                    let k = t + tau;
                    if k > a && k < b {
                        knots.push(k);
                    }
                };
                sorter.mark(knots.len());
                for t in r.bounds().into_iter().flatten().chain(first_t) {
                    add(knots, t);
                }
                if self.finished {
                    add(knots, self.last.0);
                }
                sorter.mark(knots.len());
                // Input segments whose shifted span meets (a, b). A time with the same bits
                // as the one before gives the same knot, which the sort and dedup would
                // only remove again: it is left out.
                let held = self.history.held();
                let lo = held.partition_point(|h| h.t1() + tau <= a);
                let mut last = None;
                for h in held.range(lo..) {
                    if h.t0 + tau >= b {
                        break;
                    }
                    for t in [h.t0, h.t1()] {
                        if last != Some(t.to_bits()) {
                            add(knots, t);
                            last = Some(t.to_bits());
                        }
                    }
                }
            }
        }
        sorter.sort(knots);
        knots.dedup();
    }

    /// Drop what later output no longer needs: regimes whose every copy has passed their
    /// end, and input older than the latest impulse time before the cursor.
    fn forget(&mut self) {
        while self.regimes.len() > 1 && self.regimes[0].done_by(self.cursor_s) {
            if let Some(old) = self.regimes.pop_front() {
                // The cursors of the impulses after it move up.
                let n = old.taus().len().min(self.cursors.len());
                self.cursors.drain(..n);
                self.offset += old.retire_offset(&self.regimes[0]);
                self.regimes[0].becomes_first();
            }
        }
        let reach = self.regimes.iter().map(Regime::max_tau).fold(0.0, f64::max);
        let keep_from = self.cursor_s - reach;
        let mut dropped = 0;
        while self.history.held().len() > 1 && self.history.held()[0].t1() < keep_from {
            self.history.pop_front();
            dropped += 1;
        }
        for c in &mut self.cursors {
            *c = c.saturating_sub(dropped);
        }
    }
}
