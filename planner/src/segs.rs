//! A short list of segments on the stack, so planning allocates only the final profile.

use crate::Segment;

/// Up to `CAP` segments, without heap allocation. The default capacity holds any profile
/// a planner builds (a brake and a seven-segment body, or one of the two profiles a
/// step-2 mixture combines, see `mixture`).
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

/// Somewhere to append segments: a profile's `Vec` or a [`Segs`] on the stack.
pub(crate) trait Push {
    /// Append `seg`.
    fn push_seg(&mut self, seg: Segment);

    /// Append a constant-jerk segment, unless it lasts no time (it would change nothing).
    fn push_jerk(&mut self, duration_s: f64, jerk: f64) {
        if duration_s != 0.0 {
            self.push_seg(Segment::Jerk { duration_s, jerk });
        }
    }
}

impl Push for Vec<Segment> {
    fn push_seg(&mut self, seg: Segment) {
        self.push(seg);
    }
}

impl<const CAP: usize> Push for Segs<CAP> {
    fn push_seg(&mut self, seg: Segment) {
        self.push(seg);
    }
}
