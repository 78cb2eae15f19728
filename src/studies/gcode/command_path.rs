//! The path of the (shaped) command, as the toolhead's vibration is measured against it:
//! the polyline through the commanded XY positions at the samples and at the command's
//! breakpoints (where an axis's acceleration or jerk changes: a corner's speed jump
//! window, a shaper's copies) within [`ACTIVE_WINDOW_S`] before and after the measured
//! sample, the window the contour error takes the G-code's active moves in (the samples
//! are measured that much late).
//!
//! A toolhead's *vibration* is its distance (XY) to that path: the contour error measured
//! against what the machine was told, not against the G-code. A toolhead that lags or
//! leads its command along the path (the quasi-static `2 zeta v / omega` and
//! `a / omega^2` of a mode) is on the path and has none; a rigid machine has none.
//!
//! Between two points the command is a polynomial of each axis, so the polyline is within
//! `|a| h^2 / 8` of the command's path (`h` the time between the points, at most one
//! sample; `a` the command's acceleration across it): 0.12 um at 4,000 mm/s^2 and 2 kHz,
//! none on straight lines. With the breakpoints in, a corner's chord does not cut the
//! corner (with the samples alone it would, by a third of the distance the command moves
//! in a sample: 1 um at 5 mm/s and 2 kHz).
//!
//! The distance is to the nearest of all the window's segments, measured only for the
//! samples that count (printing moves), each segment first against its bounding box
//! (tracking the nearest segment from one sample to the next is cheaper still but stops
//! at local minima when the toolhead rings far from a fast command: a few um more than
//! the nearest on the ringing tower).

use std::collections::VecDeque;

use super::contour::{ACTIVE_WINDOW_S, segment_distance_sq};

/// The command's path around the measured sample (module doc).
#[derive(Debug, Default)]
pub struct CommandPath {
    /// Print-clock time (s) and commanded XY (mm) of the points, oldest first.
    points: VecDeque<(f64, [f64; 2])>,
}

impl CommandPath {
    /// The samples (at `sample_rate_hz`) in [`ACTIVE_WINDOW_S`]: how late a sample is
    /// measured.
    pub fn delay(sample_rate_hz: f64) -> usize {
        (ACTIVE_WINDOW_S * sample_rate_hz).ceil().max(1.0) as usize
    }

    /// The command is at `c` (XY, mm) at `t_s` (not before the last point's time).
    pub fn push(&mut self, t_s: f64, c: [f64; 2]) {
        self.points.push_back((t_s, c));
    }

    /// The toolhead's vibration at `t_s`: its distance (mm) from `p` (XY, mm) to the path
    /// from [`ACTIVE_WINDOW_S`] before `t_s` (older points are forgotten) to the last
    /// point (module doc), `c` being the commanded point at `t_s` (on the path); `None`
    /// before the first command.
    pub fn distance_mm(&mut self, t_s: f64, p: [f64; 2], c: [f64; 2]) -> Option<f64> {
        while self.points.len() > 1 && self.points[1].0 < t_s - ACTIVE_WINDOW_S {
            self.points.pop_front();
        }
        let first = self.points.front()?.1;
        let (a, b) = self.points.as_slices();
        // The commanded point bounds the distance; a segment whose bounding box is no
        // nearer cannot be nearer (most of the window's segments, skipped cheaply).
        let mut best = segment_distance_sq(p, c, c).min(segment_distance_sq(p, first, first));
        let mut prev = first;
        for &(_, q) in a.iter().chain(b).skip(1) {
            let dx = (prev[0].min(q[0]) - p[0]).max(p[0] - prev[0].max(q[0]));
            let dy = (prev[1].min(q[1]) - p[1]).max(p[1] - prev[1].max(q[1]));
            let (dx, dy) = (dx.max(0.0), dy.max(0.0));
            if dx * dx + dy * dy < best {
                best = best.min(segment_distance_sq(p, prev, q));
            }
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
        let mut c = CommandPath::default();
        for k in 0..=10 {
            c.push(k as f64 * 1e-3, [k as f64, 0.0]);
        }
        for k in 1..=5 {
            c.push((10 + k) as f64 * 1e-3, [10.0, k as f64]);
        }
        assert_eq!(c.distance_mm(0.0, [4.5, 0.0], [10.0, 5.0]), Some(0.0));
        assert_eq!(c.distance_mm(0.0, [7.0, 3.0], [10.0, 5.0]), Some(3.0));
        assert_eq!(c.distance_mm(0.0, [10.0, 2.5], [10.0, 5.0]), Some(0.0));
        assert_eq!(c.distance_mm(0.0, [10.0, 9.0], [10.0, 5.0]), Some(4.0));
    }

    /// Points more than 20 ms before the measured time are forgotten (but for the one
    /// starting the segment that reaches into the window).
    #[test]
    fn forgets_points_older_than_the_window() {
        let mut c = CommandPath::default();
        for k in 0..10 {
            c.push(k as f64 * 0.01, [k as f64, 0.0]);
        }
        // At 0.065 s the window starts at 0.045 s: the segment from 4 (0.04 s) to 5 on.
        assert_eq!(c.distance_mm(0.065, [0.0, 0.0], [9.0, 0.0]), Some(4.0));
    }
}
