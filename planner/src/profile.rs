//! The `Profile`: one axis of motion as plain data, and its single evaluator.

use crate::PlanError;

/// Kinematic state at an instant: position, velocity, acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// Position (units).
    pub p: f64,
    /// Velocity (units/s).
    pub v: f64,
    /// Acceleration (units/s^2).
    pub a: f64,
}

/// A full sample: state plus the jerk acting at that instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Position (units).
    pub p: f64,
    /// Velocity (units/s).
    pub v: f64,
    /// Acceleration (units/s^2).
    pub a: f64,
    /// Jerk (units/s^3).
    pub j: f64,
}

/// One piece of a profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    /// Constant jerk for `duration_s`, starting from the previous segment's end state.
    Jerk {
        /// Duration (s), >= 0.
        duration_s: f64,
        /// Jerk (units/s^3).
        jerk: f64,
    },
    /// Constant acceleration for `duration_s`. The acceleration *jumps* to `accel` at the
    /// segment start (a jerk impulse): this is how jerk-unlimited profiles such as
    /// trapezoids are written. A zero-duration `Accel` segment only sets the acceleration.
    Accel {
        /// Duration (s), >= 0.
        duration_s: f64,
        /// Acceleration held over the segment (units/s^2).
        accel: f64,
    },
}

impl Segment {
    /// Duration of the segment (s).
    pub fn duration_s(&self) -> f64 {
        match *self {
            Segment::Jerk { duration_s, .. } | Segment::Accel { duration_s, .. } => duration_s,
        }
    }

    /// The acceleration at the segment start and the (constant) jerk over it, given the
    /// state the segment starts from.
    pub fn accel_and_jerk(&self, from: &State) -> (f64, f64) {
        match *self {
            Segment::Jerk { jerk, .. } => (from.a, jerk),
            Segment::Accel { accel, .. } => (accel, 0.0),
        }
    }

    /// Evaluate the segment `tau` seconds after its start, from state `from`.
    #[inline]
    pub fn sample(&self, from: &State, tau: f64) -> Sample {
        let (a0, j) = self.accel_and_jerk(from);
        Sample {
            p: from.p + tau * (from.v + tau * (a0 / 2.0 + tau * j / 6.0)),
            v: from.v + tau * (a0 + tau * j / 2.0),
            a: a0 + tau * j,
            j,
        }
    }

    /// The state at the end of the segment.
    pub fn end_state(&self, from: &State) -> State {
        let s = self.sample(from, self.duration_s());
        State {
            p: s.p,
            v: s.v,
            a: s.a,
        }
    }
}

/// One axis of motion: a start state and a list of segments.
///
/// The evaluator is right-continuous: at a segment boundary it reports the later segment
/// (so the acceleration jump of an `Accel` segment shows at its start). Before `t = 0` it
/// reports the start state, after the end the end state held with zero jerk (and the
/// acceleration of the last segment, which is zero for rest-to-rest moves).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    start: State,
    segments: Vec<Segment>,
    /// Start time and start state of each segment.
    starts: Vec<(f64, State)>,
    end: State,
    duration_s: f64,
}

impl Profile {
    /// Build a profile, validating every segment (durations finite and >= 0, jerks and
    /// accelerations finite).
    pub fn new(start: State, segments: Vec<Segment>) -> Result<Self, PlanError> {
        let mut starts = Vec::with_capacity(segments.len());
        let mut t = 0.0;
        let mut s = start;
        for (index, seg) in segments.iter().enumerate() {
            let d = seg.duration_s();
            if !d.is_finite() || d < 0.0 {
                return Err(PlanError::InvalidSegment {
                    index,
                    reason: "duration must be finite and >= 0",
                });
            }
            let value = match *seg {
                Segment::Jerk { jerk, .. } => jerk,
                Segment::Accel { accel, .. } => accel,
            };
            if !value.is_finite() {
                return Err(PlanError::InvalidSegment {
                    index,
                    reason: "jerk/acceleration must be finite",
                });
            }
            starts.push((t, s));
            s = seg.end_state(&s);
            t += d;
        }
        Ok(Self {
            start,
            segments,
            starts,
            end: s,
            duration_s: t,
        })
    }

    /// A profile with no motion: the start state held (a zero-length move).
    pub fn empty(start: State) -> Self {
        Self {
            start,
            segments: Vec::new(),
            starts: Vec::new(),
            end: start,
            duration_s: 0.0,
        }
    }

    /// The start state.
    pub fn start(&self) -> State {
        self.start
    }

    /// The end state.
    pub fn end(&self) -> State {
        self.end
    }

    /// Total duration (s).
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }

    /// The segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Start time and start state of segment `index`.
    pub fn segment_start(&self, index: usize) -> (f64, State) {
        self.starts[index]
    }

    /// Iterate `(start_time_s, start_state, segment)` over all segments.
    pub fn iter(&self) -> impl Iterator<Item = (f64, State, &Segment)> {
        self.starts
            .iter()
            .zip(&self.segments)
            .map(|(&(t, s), seg)| (t, s, seg))
    }

    /// Position, velocity, acceleration and jerk at time `t` (s). Allocation free.
    pub fn state_at(&self, t: f64) -> Sample {
        if self.segments.is_empty() || t < 0.0 {
            let s = self.start;
            return Sample {
                p: s.p,
                v: s.v,
                a: s.a,
                j: 0.0,
            };
        }
        if t >= self.duration_s {
            let e = self.end;
            return Sample {
                p: e.p,
                v: e.v,
                a: e.a,
                j: 0.0,
            };
        }
        // Last segment whose start time is <= t (right-continuous at boundaries).
        let idx = self.starts.partition_point(|&(ts, _)| ts <= t) - 1;
        let (ts, s) = self.starts[idx];
        self.segments[idx].sample(&s, t - ts)
    }

    /// [`Profile::state_at`] for times that mostly increase (a sample clock), bit for bit:
    /// `seg` is the index of the segment the last query fell in (updated), and the segment
    /// of `t` is found by walking forward from it instead of searching. Any `t` is
    /// allowed; a `t` before segment `seg`'s start restarts the walk from the first
    /// segment.
    #[inline]
    pub fn state_at_from(&self, seg: &mut usize, t: f64) -> Sample {
        if self.segments.is_empty() || t < 0.0 || t >= self.duration_s {
            // Before the start or at and after the end: no segment to find.
            return self.state_at(t);
        }
        // The last segment whose start time is <= t (right-continuous at boundaries, as
        // `state_at`): segment 0 starts at 0 <= t, and start times never decrease, so
        // walking forward while the next one starts at or before `t` lands on it.
        if *seg >= self.segments.len() || self.starts[*seg].0 > t {
            *seg = 0;
        }
        while *seg + 1 < self.segments.len() && self.starts[*seg + 1].0 <= t {
            *seg += 1;
        }
        let (ts, s) = self.starts[*seg];
        self.segments[*seg].sample(&s, t - ts)
    }
}
