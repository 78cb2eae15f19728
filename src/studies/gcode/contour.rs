//! Contour error on a G-code job: the distance (in the XY plane, mm) from the toolhead to
//! the commanded geometry of the moves active at that time, and which move a sample
//! belongs to.
//!
//! - A move is *active* at time `t` when `t` lies in its planned span widened by
//!   [`ACTIVE_WINDOW_S`] on both sides; the contour error is the distance to the nearest
//!   active move's geometry (lines as written; arcs as the firmware cuts them, the path the
//!   machine is commanded along). The widening lets a toolhead that lags its command (or a
//!   shaped command that leads it by up to half a shaper's duration) be measured against
//!   the move it is still on, not the next one, after a corner.
//! - A sample *belongs* to the latest move that has started (`start_time_s <= t`, moves of
//!   zero duration skipped): the error while a move runs is the ringing left by the corner
//!   at its start plus the move's own following error.

use std::collections::VecDeque;
use std::sync::Arc;

use settle_gcode::job::{MoveGeometry, MoveInfo};

use super::box2::Box2;

/// How far (s) a move's span is widened for [`ActiveMoves::at`]: 20 ms is longer
/// than half the longest Klipper shaper at 20 Hz (2DHUMP_EI at 20 Hz lasts 75 ms: the
/// shaped command leads by at most half of it, 37 ms, only on shapers tuned below 40 Hz)
/// and than a quarter period of the printer modes (30-120 Hz): the lag of the toolhead.
pub const ACTIVE_WINDOW_S: f64 = 0.02;

/// Distance (mm) from `p` to the segment `a`-`b` (XY).
pub fn segment_distance_mm(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    segment_distance_sq(p, a, b).sqrt()
}

/// The square of [`segment_distance_mm`] (mm^2): comparisons need no square root (the
/// root is monotone and correctly rounded, so the root of the least square is the least
/// root, bit for bit).
#[inline]
pub(crate) fn segment_distance_sq(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let (px, py) = (p[0] - a[0], p[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let s = if l2 > 0.0 {
        ((px * dx + py * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ex, ey) = (px - s * dx, py - s * dy);
    ex * ex + ey * ey
}

/// Distance (mm) from `p` to a move's commanded geometry (XY).
pub fn geometry_distance_mm(g: &MoveGeometry, p: [f64; 2]) -> f64 {
    geometry_distance_sq(g, p).sqrt()
}

/// The square of [`geometry_distance_mm`] (mm^2).
#[inline]
fn geometry_distance_sq(g: &MoveGeometry, p: [f64; 2]) -> f64 {
    match g {
        MoveGeometry::Line { from_mm, to_mm } => {
            segment_distance_sq(p, [from_mm[0], from_mm[1]], [to_mm[0], to_mm[1]])
        }
        MoveGeometry::Arc { points_mm, .. } => points_mm
            .windows(2)
            .map(|w| segment_distance_sq(p, [w[0][0], w[0][1]], [w[1][0], w[1][1]]))
            .fold(f64::INFINITY, f64::min),
    }
}

/// A move of [`ActiveMoves`] with what the search reads inline (no pointer to follow for
/// the moves it passes over): its span and, for a line, its XY ends.
#[derive(Debug)]
struct Active {
    /// [`MoveInfo::start_time_s`].
    start_s: f64,
    /// [`MoveInfo::end_time_s`].
    end_s: f64,
    /// Whether it runs (a positive duration): only those own samples.
    runs: bool,
    /// A line's XY ends (mm); `None` for an arc.
    line: Option<[[f64; 2]; 2]>,
    /// An arc's chunks of [`ARC_CHUNK`] segments ([`ArcChunks`]).
    arc: Option<ArcChunks>,
    info: Arc<MoveInfo>,
}

/// Segments per box of an arc's search, and boxes per box of the level above
/// ([`ArcChunks`]).
const ARC_CHUNK: usize = 32;

/// An arc's chord segments in chunks of [`ARC_CHUNK`], each with its XY box, and above
/// them levels of boxes, each around [`ARC_CHUNK`] boxes of the level below, up to a top
/// of at most [`ARC_CHUNK`]: a distance descends to the nearest-looking chunk first and
/// skips every box that cannot hold the nearest segment, so that one to an arc of
/// hundreds of thousands of segments costs a few dozen boxes and segments per level
/// (logarithmic in the segments), not a scan of all of them.
#[derive(Debug)]
struct ArcChunks {
    /// Level 0: per chunk, the box of its points; level `k + 1`: per [`ARC_CHUNK`] boxes
    /// of level `k`, the box around them. The last level has at most [`ARC_CHUNK`].
    levels: Vec<Vec<Box2>>,
    /// The largest `x^2 + y^2` of its points (mm^2): the scale of the rounding errors.
    scale_sq: f64,
}

impl ArcChunks {
    fn new(points: &[[f64; 3]]) -> Self {
        let chunks: Vec<Box2> = (0..points.len().saturating_sub(1))
            .step_by(ARC_CHUNK)
            .map(|i| {
                let chunk = &points[i..(i + ARC_CHUNK + 1).min(points.len())];
                let mut b = Box2::at([chunk[0][0], chunk[0][1]]);
                chunk[1..].iter().for_each(|q| b.add([q[0], q[1]]));
                b
            })
            .collect();
        let mut levels = vec![chunks];
        while let Some(below) = levels.last().filter(|l| l.len() > ARC_CHUNK) {
            let above = below
                .chunks(ARC_CHUNK)
                .map(|c| {
                    let mut b = c[0];
                    c[1..].iter().for_each(|q| {
                        b.add(q.min);
                        b.add(q.max);
                    });
                    b
                })
                .collect();
            levels.push(above);
        }
        let scale_sq = points
            .iter()
            .fold(0.0, |m: f64, q| m.max(q[0] * q[0] + q[1] * q[1]));
        Self { levels, scale_sq }
    }

    /// The least [`segment_distance_sq`] from `p` to the segments of `points` (the arc's),
    /// bit for bit the scan's ([`geometry_distance_sq`]): the least of a set of numbers
    /// does not depend on the order they are visited in. A box is skipped only when its
    /// squared distance exceeds the least so far by a relative 1e-9 plus
    /// `1e-12 (1 + |p|^2 + scale_sq)`: far more than the rounding of either computation
    /// (a few ulps of the box distance, a box being the exact least and largest
    /// coordinates of its points; of a segment's, relative to its coordinates), so a
    /// skipped segment's computed distance is never below the least, and the least of the
    /// rest is the scan's. A NaN point of `p` skips nothing; NaN segments are ignored by
    /// the minimum as in the scan.
    fn distance_sq(&self, points: &[[f64; 3]], p: [f64; 2]) -> f64 {
        let margin = 1e-12 * (1.0 + p[0] * p[0] + p[1] * p[1] + self.scale_sq);
        let mut best = f64::INFINITY;
        let top = self.levels.len() - 1;
        self.visit(top, 0, points, p, margin, &mut best);
        best
    }

    /// Visit the boxes of `level` from `first` (at most [`ARC_CHUNK`] of them, those of
    /// one box of the level above), the nearest first, each not skipped ([`Self::distance_sq`])
    /// down to its segments.
    fn visit(
        &self,
        level: usize,
        first: usize,
        points: &[[f64; 3]],
        p: [f64; 2],
        margin: f64,
        best: &mut f64,
    ) {
        let boxes = &self.levels[level][first..(first + ARC_CHUNK).min(self.levels[level].len())];
        let mut near = [0.0; ARC_CHUNK];
        let mut nearest = 0;
        for (k, b) in boxes.iter().enumerate() {
            near[k] = b.near_sq(p);
            if near[k] < near[nearest] {
                nearest = k;
            }
        }
        let order = std::iter::once(nearest).chain((0..boxes.len()).filter(|&k| k != nearest));
        for k in order {
            if near[k] > *best * (1.0 + 1e-9) + margin {
                continue;
            }
            let below = (first + k) * ARC_CHUNK;
            if level > 0 {
                self.visit(level - 1, below, points, p, margin, best);
            } else {
                for w in points[below..(below + ARC_CHUNK + 1).min(points.len())].windows(2) {
                    let (a, b) = ([w[0][0], w[0][1]], [w[1][0], w[1][1]]);
                    *best = best.min(segment_distance_sq(p, a, b));
                }
            }
        }
    }
}

impl Active {
    fn new(m: &Arc<MoveInfo>) -> Self {
        let line = match &m.geometry {
            MoveGeometry::Line { from_mm, to_mm } => {
                Some([[from_mm[0], from_mm[1]], [to_mm[0], to_mm[1]]])
            }
            MoveGeometry::Arc { .. } => None,
        };
        let arc = match &m.geometry {
            MoveGeometry::Arc { points_mm, .. } => Some(ArcChunks::new(points_mm)),
            MoveGeometry::Line { .. } => None,
        };
        Self {
            start_s: m.start_time_s,
            end_s: m.end_time_s(),
            runs: m.duration_s > 0.0,
            line,
            arc,
            info: Arc::clone(m),
        }
    }

    /// [`geometry_distance_sq`] of its geometry, bit for bit.
    #[inline]
    fn distance_sq(&self, p: [f64; 2]) -> f64 {
        match (&self.line, &self.arc, &self.info.geometry) {
            (Some([a, b]), _, _) => segment_distance_sq(p, *a, *b),
            (None, Some(c), MoveGeometry::Arc { points_mm, .. }) => c.distance_sq(points_mm, p),
            _ => geometry_distance_sq(&self.info.geometry, p),
        }
    }
}

/// The moves of the chunks seen so far that can still be active (module doc).
#[derive(Debug, Default)]
pub struct ActiveMoves {
    moves: VecDeque<Active>,
    last_index: Option<u64>,
}

impl ActiveMoves {
    /// Take a chunk's moves (those already taken from an earlier chunk are skipped).
    pub fn add(&mut self, moves: &[Arc<MoveInfo>]) {
        for m in moves {
            if self.last_index.is_none_or(|i| m.index > i) {
                self.last_index = Some(m.index);
                self.moves.push_back(Active::new(m));
            }
        }
    }

    /// The move a sample at `t_s` belongs to (module doc), if any has started.
    pub fn owner(&self, t_s: f64) -> Option<&Arc<MoveInfo>> {
        self.moves
            .iter()
            .rev()
            .find(|m| m.runs && m.start_s <= t_s)
            .map(|m| &m.info)
    }

    /// Forget the moves that can no longer be active after `t_s` (keeping the latest
    /// started one: a sample during a pause still belongs to it).
    pub fn retire(&mut self, t_s: f64) {
        while self.moves.len() > 1
            && self.moves[0].end_s + ACTIVE_WINDOW_S < t_s
            && self.moves[1].start_s <= t_s
        {
            self.moves.pop_front();
        }
    }

    /// The contour error (mm) of a toolhead at `p` (XY, mm) at `t_s`, and the move the
    /// sample belongs to ([`ActiveMoves::owner`]), in one pass over the moves: the
    /// distance to the nearest active move, or to the move the sample belongs to when
    /// none is active (a pause); `None` before the first move has started.
    pub fn at(&self, t_s: f64, p: [f64; 2]) -> Option<(f64, &MoveInfo)> {
        self.at_each(t_s, [p]).map(|([e], m)| (e, m))
    }

    /// [`ActiveMoves::at`] of each of the points `ps` at `t_s` (the same moves, one pass).
    pub fn at_each<const N: usize>(
        &self,
        t_s: f64,
        ps: [[f64; 2]; N],
    ) -> Option<([f64; N], &MoveInfo)> {
        let mut best = [f64::INFINITY; N];
        let mut active = false;
        let mut owner: Option<&Active> = None;
        // Moves are in order of their start times: every move after the first that starts
        // beyond the window starts after `t_s` too (neither active nor the owner).
        for m in &self.moves {
            if m.start_s - ACTIVE_WINDOW_S > t_s {
                break;
            }
            if m.runs && m.start_s <= t_s {
                owner = Some(m);
            }
            if m.end_s + ACTIVE_WINDOW_S < t_s {
                continue;
            }
            for (b, &p) in best.iter_mut().zip(&ps) {
                let d = m.distance_sq(p);
                // The first active move's distance as it is (an infinite one too).
                *b = if active { b.min(d) } else { d };
            }
            active = true;
        }
        let owner = owner?;
        for (b, &p) in best.iter_mut().zip(&ps) {
            *b = if active {
                b.sqrt()
            } else {
                owner.distance_sq(p).sqrt()
            };
        }
        Some((best, &owner.info))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An arc geometry through `points` (the scan reads the points only).
    fn arc_of(points: &[[f64; 3]]) -> MoveGeometry {
        MoveGeometry::Arc {
            arc: settle_gcode::Arc {
                centre_x_mm: 0.0,
                centre_y_mm: 0.0,
                offset_i_mm: 0.0,
                offset_j_mm: 0.0,
                radius_mm: 0.0,
                start_angle_rad: 0.0,
                sweep_rad: 0.0,
                radius_word_mm: None,
                plane: settle_gcode::Plane::Xy,
            },
            points_mm: points.to_vec(),
        }
    }

    #[test]
    fn an_arcs_chunked_distance_is_the_scans_bit_for_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..302 {
            // Arcs of 1 to 3,000 segments (one or two levels of boxes), and two of 40,000
            // to 700,000 (three levels: the reader's largest arcs are circles of 100 m
            // radius cut at 1 mm), radius 0.01 mm to 50 m, centre up to 1e5 mm out.
            let n = if case < 300 {
                1 + (uniform() * 3000.0) as usize
            } else {
                40_000 + (uniform() * 660_000.0) as usize
            };
            let r = 10f64.powf(-2.0 + 6.7 * uniform());
            let c = [(uniform() - 0.5) * 2e5, (uniform() - 0.5) * 2e5];
            let (a0, sweep) = (uniform() * 6.3, (uniform() - 0.5) * 12.6);
            let points: Vec<[f64; 3]> = (0..=n)
                .map(|i| {
                    let a = a0 + sweep * i as f64 / n as f64;
                    [c[0] + r * a.cos(), c[1] + r * a.sin(), 0.0]
                })
                .collect();
            let geometry = arc_of(&points);
            let chunks = ArcChunks::new(&points);
            assert_eq!(chunks.levels.len(), if n > 32 * 32 * 32 { 3 } else { 1 + usize::from(n > 32 * 32) });
            for k in 0..if case < 300 { 200 } else { 12 } {
                let p = match k % 4 {
                    // On a point of the arc, or a hair off it.
                    0 => {
                        let q = points[(uniform() * n as f64) as usize];
                        [q[0], q[1]]
                    }
                    1 => {
                        let q = points[(uniform() * n as f64) as usize];
                        let e = r * 1e-9 * (uniform() - 0.5);
                        [q[0] + e, q[1] - e]
                    }
                    // Near the circle, or anywhere around it.
                    2 => {
                        let a = uniform() * 6.3;
                        let rr = r * (1.0 + (uniform() - 0.5) * 1e-3);
                        [c[0] + rr * a.cos(), c[1] + rr * a.sin()]
                    }
                    _ => [
                        c[0] + (uniform() - 0.5) * 4.0 * r,
                        c[1] + (uniform() - 0.5) * 4.0 * r,
                    ],
                };
                let scan = geometry_distance_sq(&geometry, p);
                let fast = chunks.distance_sq(&points, p);
                assert_eq!(fast.to_bits(), scan.to_bits(), "case {case}, point {p:?}");
            }
        }
        // A NaN point: NaN from both (no segment is skipped, every one is NaN).
        let points = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        let geometry = arc_of(&points);
        let p = [f64::NAN, 0.0];
        let chunks = ArcChunks::new(&points);
        assert_eq!(
            chunks.distance_sq(&points, p).is_nan(),
            geometry_distance_sq(&geometry, p).is_nan()
        );
    }

    #[test]
    fn distances_to_a_segment_and_its_ends() {
        let (a, b) = ([0.0, 0.0], [10.0, 0.0]);
        assert_eq!(segment_distance_mm([5.0, 3.0], a, b), 3.0);
        assert_eq!(segment_distance_mm([13.0, 4.0], a, b), 5.0);
        assert_eq!(segment_distance_mm([-3.0, -4.0], a, b), 5.0);
        assert_eq!(segment_distance_mm([1.0, 1.0], a, a), 2f64.sqrt());
    }
}
