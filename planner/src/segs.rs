//! A short list of segments on the stack, so planning allocates only the final profile.

use crate::Segment;

/// Up to `CAP` segments, without heap allocation. The default capacity holds any profile
/// a planner builds (a brake and a seven-segment body, or one of the two profiles a
/// step-2 blend mixes).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segs<const CAP: usize = 8> {
    s: [Segment; CAP],
    n: usize,
}

impl<const CAP: usize> Default for Segs<CAP> {
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

impl<const CAP: usize> Segs<CAP> {
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

impl<const CAP: usize> Extend<Segment> for Segs<CAP> {
    fn extend<I: IntoIterator<Item = Segment>>(&mut self, iter: I) {
        for seg in iter {
            self.push(seg);
        }
    }
}
