//! A stream's input history: the input segments still needed, oldest first, and the
//! segment in force at an instant, found by a search or, for instants that do not
//! decrease, by a cursor walking forward.

use std::collections::VecDeque;

use crate::{Segment, State};

/// One input segment on the stream's clock.
#[derive(Debug, Clone, Copy)]
pub(super) struct Held {
    pub(super) t0: f64,
    pub(super) start: State,
    pub(super) seg: Segment,
}

impl Held {
    pub(super) fn t1(&self) -> f64 {
        self.t0 + self.seg.duration_s()
    }
}

/// The input segments, oldest first (module doc).
#[derive(Debug, Clone, Default)]
pub(super) struct History {
    held: VecDeque<Held>,
    /// Adjacent pairs whose start times decrease. Chunks join to 1e-9 s, so a chunk's
    /// first segment may start a rounding error before the previous chunk's last one;
    /// while such a pair is held, [`Self::at_from`] searches as [`Self::at`] does.
    descents: usize,
}

impl History {
    /// The segments, oldest first.
    pub(super) fn held(&self) -> &VecDeque<Held> {
        &self.held
    }

    /// Append a segment.
    pub(super) fn push_back(&mut self, h: Held) {
        if self.held.back().is_some_and(|b| h.t0 < b.t0) {
            self.descents += 1;
        }
        self.held.push_back(h);
    }

    /// Drop the oldest segment.
    pub(super) fn pop_front(&mut self) {
        if self.held.len() >= 2 && self.held[1].t0 < self.held[0].t0 {
            self.descents -= 1;
        }
        self.held.pop_front();
    }

    /// The index of the segment in force at `t`: the last one starting at or before `t`
    /// (the first if none does; 0 when empty).
    pub(super) fn at(&self, t: f64) -> usize {
        self.held.partition_point(|h| h.t0 <= t).max(1) - 1
    }

    /// [`Self::at`], bit for bit, walking forward from `cursor` (the index the previous
    /// call returned; updated) instead of searching: for instants that mostly increase.
    /// Any `cursor` and `t` are allowed; where a walk from `cursor` could not give the
    /// search's answer (a `t` before the cursor's segment, a cursor past the end, start
    /// times that are not in order) this searches.
    #[inline]
    pub(super) fn at_from(&self, cursor: &mut usize, t: f64) -> usize {
        let h = &self.held;
        let walkable =
            self.descents == 0 && *cursor < h.len() && (*cursor == 0 || h[*cursor].t0 <= t);
        if !walkable {
            *cursor = self.at(t);
            return *cursor;
        }
        // Start times are in order and the cursor's is <= t (or it is the first): the
        // last start <= t is at or after it, and every start walked past is <= t.
        while *cursor + 1 < h.len() && h[*cursor + 1].t0 <= t {
            *cursor += 1;
        }
        *cursor
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift64*), so the test needs no dependency.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }

        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn held(t0: f64) -> Held {
        Held {
            t0,
            start: State::default(),
            seg: Segment::Accel {
                duration_s: 0.0,
                accel: 0.0,
            },
        }
    }

    /// The cursor walk returns the search's index on random histories (equal start
    /// times, start times a rounding error out of order, segments dropped and appended
    /// between queries) and random query sequences (mostly increasing, sometimes going
    /// back, before the first start and after the last).
    #[test]
    fn the_cursor_walk_returns_the_search_s_index() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..300 {
            let mut h = History::default();
            let mut t = 0.0;
            let mut cursor = usize::MAX;
            let mut q = -0.5;
            for _ in 0..400 {
                match rng.next() % 8 {
                    0 | 1 => {
                        // Append: usually later, sometimes equal, sometimes a hair earlier.
                        t += match rng.next() % 6 {
                            0 => 0.0,
                            1 => -1e-12,
                            _ => rng.unit(),
                        };
                        h.push_back(held(t));
                    }
                    2 if !h.held().is_empty() => h.pop_front(),
                    _ => {
                        q += match rng.next() % 10 {
                            0 => -2.0 * rng.unit(),
                            1 => 0.0,
                            _ => 0.7 * rng.unit(),
                        };
                        let probe = match rng.next() % 20 {
                            0 => h
                                .held()
                                .get(rng.next() as usize % (h.held().len() + 1))
                                .map_or(q, |x| x.t0),
                            _ => q,
                        };
                        assert_eq!(h.at_from(&mut cursor, probe), h.at(probe));
                    }
                }
                let descents = h
                    .held()
                    .iter()
                    .zip(h.held().iter().skip(1))
                    .filter(|(a, b)| b.t0 < a.t0)
                    .count();
                assert_eq!(h.descents, descents);
            }
        }
    }
}
