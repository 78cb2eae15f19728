//! A profile's position at times that mostly increase (a sample clock), as
//! [`Profile::state_at_from`] gives it, bit for bit: the segment the last time fell in is
//! held with its start, so that a time in it costs two compares and the segment's own
//! evaluation ([`Segment::sample`], of which only the position is used: no walk). The test module checks it against
//! [`Profile::state_at`] at random times on random profiles.

use settle_planner::{Profile, Segment, State};

/// The held segment of [`PositionCursor`]: its span `[from_s, to_s)`, the state it
/// starts from and the segment.
#[derive(Debug, Clone, Copy)]
struct Held {
    from_s: f64,
    to_s: f64,
    start: State,
    segment: Segment,
}

/// [`Profile::state_at_from`]'s position with the segment held (module doc).
#[derive(Debug, Clone, Copy)]
pub struct PositionCursor {
    /// [`Profile::state_at_from`]'s cursor.
    seg: usize,
    held: Held,
}

impl Default for PositionCursor {
    fn default() -> Self {
        Self {
            seg: 0,
            // No time is in an empty span.
            held: Held {
                from_s: f64::INFINITY,
                to_s: f64::NEG_INFINITY,
                start: State::default(),
                segment: Segment::Jerk {
                    duration_s: 0.0,
                    jerk: 0.0,
                },
            },
        }
    }
}

impl PositionCursor {
    /// `profile`'s position at `t` (s): [`Profile::state_at_from`]'s `p`, bit for bit
    /// (the cursor follows one profile).
    #[inline]
    pub fn position(&mut self, profile: &Profile, t: f64) -> f64 {
        let h = &self.held;
        if h.from_s <= t && t < h.to_s {
            return h.segment.sample(&h.start, t - h.from_s).p;
        }
        let p = profile.state_at_from(&mut self.seg, t).p;
        self.hold(profile, t);
        p
    }

    /// Hold the segment of `t` ([`Profile::state_at_from`] has just put the cursor on it),
    /// or none when `t` is outside the segments (before 0, at or after the end, NaN).
    #[cold]
    fn hold(&mut self, profile: &Profile, t: f64) {
        let segments = profile.segments();
        if segments.is_empty() || t.is_nan() || t < 0.0 || t >= profile.duration_s() {
            self.held = Self::default().held;
            return;
        }
        // The segment's span: from its start to the next one's (the profile's end after
        // the last), in which `state_at_from` lands on it: at or after its start, before
        // the next start (and so before the end).
        let i = self.seg;
        let (from_s, start) = profile.segment_start(i);
        let to_s = match i + 1 < segments.len() {
            true => profile.segment_start(i + 1).0,
            false => profile.duration_s(),
        };
        self.held = Held {
            from_s,
            to_s,
            start,
            segment: segments[i],
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use settle_planner::Segment;

    /// On random profiles of jerk and acceleration segments (some of no duration), at
    /// times that mostly increase by less than a segment, now and then jump back, and
    /// fall before the start, on breakpoints and at and after the end: the position is
    /// `state_at`'s, bit for bit.
    #[test]
    fn the_position_is_state_ats() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..200 {
            let n = rng.random_range(0..12);
            let segments: Vec<Segment> = (0..n)
                .map(|_| {
                    let d = if rng.random_bool(0.15) {
                        0.0
                    } else {
                        rng.random_range(0.0..0.01)
                    };
                    if rng.random_bool(0.5) {
                        Segment::Jerk {
                            duration_s: d,
                            jerk: rng.random_range(-1e5..1e5),
                        }
                    } else {
                        Segment::Accel {
                            duration_s: d,
                            accel: rng.random_range(-1e3..1e3),
                        }
                    }
                })
                .collect();
            let start = State {
                p: rng.random_range(-0.2..0.2),
                v: rng.random_range(-0.5..0.5),
                a: rng.random_range(-100.0..100.0),
            };
            let profile = Profile::new(start, segments).expect("valid");
            let mut c = PositionCursor::default();
            let d = profile.duration_s();
            let mut t = -1e-3;
            let mut check = |t: f64| {
                let want = profile.state_at(t).p;
                assert_eq!(c.position(&profile, t).to_bits(), want.to_bits(), "t {t}");
            };
            while t < d + 2e-3 {
                check(t);
                if rng.random_bool(0.05) {
                    t -= rng.random_range(0.0..0.005);
                } else {
                    t += rng.random_range(0.0..5e-4);
                }
            }
            for i in 0..n {
                check(profile.segment_start(i).0);
            }
            check(d);
            check(0.0);
        }
    }
}
