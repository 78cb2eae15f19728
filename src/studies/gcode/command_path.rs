//! The path of the (shaped) command, as the toolhead's vibration is measured against it:
//! the polyline through the commanded XY positions of the samples of the last
//! [`ACTIVE_WINDOW_S`], up to the current one.
//!
//! A toolhead's *vibration* is its distance (XY) to that path: the contour error measured
//! against what the machine was told, not against the G-code. A toolhead that lags its
//! command along the path (the quasi-static lag `2 zeta v / omega` of a mode) is on the
//! path and has none; one that overshoots the current commanded point along the path has
//! that overshoot (the path ends there, as a G-code move's segment ends at its end point).
//!
//! The distance is to the nearest of all the window's segments (41 at 2 kHz), measured
//! only for the samples that count (printing moves): tracking the nearest segment from one
//! sample to the next is cheaper but stops at local minima when the toolhead rings far
//! from a fast command (a few um more than the nearest, on the ringing tower).

use std::collections::VecDeque;

use super::contour::{ACTIVE_WINDOW_S, segment_distance_sq};

/// The command's recent path and the toolhead's nearest segment on it (module doc).
#[derive(Debug)]
pub struct CommandPath {
    /// Commanded XY (mm) of the window's samples, oldest first.
    points: VecDeque<[f64; 2]>,
    /// Most points kept: the window's samples and one.
    cap: usize,
}

impl CommandPath {
    /// An empty path for samples at `sample_rate_hz`.
    pub fn new(sample_rate_hz: f64) -> Self {
        let cap = (ACTIVE_WINDOW_S * sample_rate_hz).ceil().max(1.0) as usize + 1;
        Self {
            points: VecDeque::with_capacity(cap + 1),
            cap,
        }
    }

    /// The command is at `c` (XY, mm) at the next sample.
    pub fn push(&mut self, c: [f64; 2]) {
        self.points.push_back(c);
        if self.points.len() > self.cap {
            self.points.pop_front();
        }
    }

    /// The toolhead's vibration: its distance (mm) from `p` (XY, mm) to the path (module
    /// doc); `None` before the first command.
    pub fn distance_mm(&self, p: [f64; 2]) -> Option<f64> {
        let first = *self.points.front()?;
        let (a, b) = self.points.as_slices();
        let mut best = segment_distance_sq(p, first, first);
        let mut prev = first;
        for &q in a.iter().chain(b).skip(1) {
            best = best.min(segment_distance_sq(p, prev, q));
            prev = q;
        }
        Some(best.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A toolhead lagging on the first leg of a corner the command has turned is on the
    /// path (distance 0); one off the path by 3 mm is 3 mm away; past the current command
    /// point it is its distance to that point.
    #[test]
    fn distances_to_a_turned_corner() {
        let mut c = CommandPath::new(1000.0);
        for k in 0..=10 {
            c.push([k as f64, 0.0]);
        }
        for k in 1..=5 {
            c.push([10.0, k as f64]);
        }
        assert_eq!(c.distance_mm([4.5, 0.0]), Some(0.0));
        assert_eq!(c.distance_mm([7.0, 3.0]), Some(3.0));
        assert_eq!(c.distance_mm([10.0, 2.5]), Some(0.0));
        assert_eq!(c.distance_mm([10.0, 9.0]), Some(4.0));
    }

    /// The window holds `ceil(0.02 s * rate) + 1` points: older ones are forgotten.
    #[test]
    fn forgets_points_older_than_the_window() {
        let mut c = CommandPath::new(100.0);
        for k in 0..10 {
            c.push([k as f64, 0.0]);
        }
        // 3 points kept: 7, 8, 9.
        assert_eq!(c.distance_mm([0.0, 0.0]), Some(7.0));
    }
}
