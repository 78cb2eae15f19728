//! A short list of segments on the stack, so planning allocates only the final profile.

use crate::Segment;

/// Capacity: the longest profile body (a blend of two seven-segment profiles with their
/// breakpoints merged: at most 13 pieces) fits.
const CAP: usize = 16;

/// Up to [`CAP`] segments, without heap allocation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segs {
    s: [Segment; CAP],
    n: usize,
}

impl Default for Segs {
    fn default() -> Self {
        Self {
            s: [Segment::Jerk {
                duration_s: 0.0,
                jerk: 0.0,
            }; CAP],
            n: 0,
        }
    }
}

impl Segs {
    /// Append a segment. Panics beyond the capacity (a planner bug, not an input error).
    pub(crate) fn push(&mut self, seg: Segment) {
        assert!(self.n < CAP, "segment list capacity exceeded");
        self.s[self.n] = seg;
        self.n += 1;
    }

    /// The segments.
    pub(crate) fn as_slice(&self) -> &[Segment] {
        &self.s[..self.n]
    }

    /// Total duration (s).
    pub(crate) fn duration_s(&self) -> f64 {
        self.as_slice().iter().map(Segment::duration_s).sum()
    }
}

impl Extend<Segment> for Segs {
    fn extend<I: IntoIterator<Item = Segment>>(&mut self, iter: I) {
        for seg in iter {
            self.push(seg);
        }
    }
}
