//! The print clock and the queue of planned moves waiting to be taken.

use std::collections::VecDeque;

use super::PlannedMove;

/// Final moves in execution order, stamped with their start time on the print clock.
#[derive(Debug, Default)]
pub(crate) struct Timeline {
    time_s: f64,
    ready: VecDeque<PlannedMove>,
}

impl Timeline {
    /// Stamp `mv` with the current time, advance the clock by its phases (added one by
    /// one, in order, as the firmwares add their phase times) and queue it.
    pub(crate) fn emit(&mut self, mut mv: PlannedMove) {
        mv.start_time_s = self.time_s;
        self.time_s = mv.end_time_s();
        self.ready.push_back(mv);
    }

    /// Let the clock run `delay_s` with nothing moving (a dwell).
    pub(crate) fn idle(&mut self, delay_s: f64) {
        self.time_s += delay_s;
    }

    /// Move the clock forward to `time_s` if it is later (the machine idled until then).
    pub(crate) fn idle_until(&mut self, time_s: f64) {
        self.time_s = self.time_s.max(time_s);
    }

    /// The print clock (s): the end of the last planned move or dwell.
    pub(crate) fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Take the oldest planned move.
    pub(crate) fn pop(&mut self) -> Option<PlannedMove> {
        self.ready.pop_front()
    }
}
