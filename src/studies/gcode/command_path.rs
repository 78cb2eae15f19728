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
//! samples that count (printing moves). Segments are skipped by bounding boxes, first of
//! runs of [`RUN`] consecutive segments, then of each segment of a run that may be nearer:
//! a box no nearer than the nearest distance so far holds no nearer segment, so the
//! distance is the least over all segments whichever are skipped, to rounding (tracking the nearest
//! segment from one sample to the next is cheaper still but stops at local minima when
//! the toolhead rings far from a fast command: a few um more than the nearest on the
//! ringing tower).

use std::collections::VecDeque;
use std::sync::Arc;

use settle_planner::Profile;

use super::box2::{Box2, larger};
use super::contour::{ACTIVE_WINDOW_S, segment_distance_sq};

/// Consecutive segments sharing a bounding box ([`CommandPath::distance_mm`]): about
/// 12 boxes over a window of 2 x 20 ms at 2 kHz, of which the toolhead is near one or two.
pub const RUN: u64 = 8;

/// The smaller of `a` and `b`, `b` when either is NaN.
#[inline]
fn smaller(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// The offset (mm) of `q` from `p`, each coordinate rounded as in [`Box2::near_sq`].
#[inline]
fn offset(q: [f64; 2], p: [f64; 2]) -> [f64; 2] {
    [q[0] - p[0], q[1] - p[1]]
}

/// [`Box2::near_sq`] of the box of the segment from `a` to `q` for the point `p`, from
/// the ends' offsets from `p` ([`offset`]), bit for bit for finite numbers: rounding is
/// monotone and odd, so the rounded `min(a, q) - p` is the smaller rounded offset and the
/// rounded `p - max(a, q)` the larger one's negative. (A NaN end gives a NaN segment
/// distance, which the least distance ignores: whether it is computed changes nothing.)
#[inline]
fn segment_box_sq(da: [f64; 2], dq: [f64; 2]) -> f64 {
    let near = |a: f64, q: f64| larger(larger(smaller(a, q), -larger(a, q)), 0.0);
    let (dx, dy) = (near(da[0], dq[0]), near(da[1], dq[1]));
    dx * dx + dy * dy
}

/// The fewest forgotten points a vector of held points drops at a time: its forgotten
/// front is dropped once it is at least this long and at least half the vector, so each
/// point is moved a bounded number of times and the vector holds at most about twice the
/// window's points, or the window's and this many.
const COMPACT: usize = 256;

/// Drop the first `gap` items of `v` if they are many (see [`COMPACT`]): returns how many
/// were dropped.
fn compact<T>(v: &mut Vec<T>, gap: usize) -> usize {
    if gap >= COMPACT && 2 * gap >= v.len() {
        v.drain(..gap);
        gap
    } else {
        0
    }
}

/// The command's path around the measured sample (module doc).
///
/// A push only stores the point: the bounding boxes grow when a distance is asked for
/// (most samples never ask: their bound is below the largest vibration so far), each
/// from its points in the order they came, the same bits as a box grown point by point.
/// Points and boxes are held in vectors, oldest first, the forgotten front dropped now
/// and then (`COMPACT`).
#[derive(Debug, Default)]
pub struct CommandPath {
    /// The commanded XY (mm) of the points from index [`CommandPath::base`] among all
    /// pushed on, oldest first: the kept ones, after forgotten ones (at least those of
    /// the first kept one's run: its box holds them).
    c: Vec<[f64; 2]>,
    /// Their print-clock times (s).
    t: Vec<f64>,
    /// The first held point's index among all pushed.
    base: u64,
    /// The number of points ever forgotten: the first kept point's index among all pushed.
    forgotten: u64,
    /// The bounding boxes of the runs from [`CommandPath::first_run`] on, oldest first:
    /// run `k` holds the segments from point `k RUN + i` to the next (`i < RUN`), so its
    /// box holds the points `k RUN ..= (k + 1) RUN`, those grown so far (a run is kept
    /// while any of its segments is; its box may hold points forgotten since, which only
    /// makes it larger).
    boxes: Vec<Box2>,
    /// The run of `boxes[0]`.
    first_run: u64,
    /// The points added to the boxes: those before this index among all pushed.
    grown: u64,
    /// Points from this index among all pushed on are held, forgotten or not, for
    /// [`CommandPath::distances_mm`] (a run's first point).
    held: Option<u64>,
}

/// A distance asked of the path later ([`CommandPath::distances_mm`]): what
/// [`CommandPath::distance_mm`] was given, and the last point pushed then.
#[derive(Debug, Clone, Copy)]
pub struct Asked {
    /// The time (s, print clock).
    pub t_s: f64,
    /// The toolhead (XY, mm).
    pub p: [f64; 2],
    /// The commanded point (XY, mm).
    pub c: [f64; 2],
    /// The index among all pushed of the last point pushed.
    last: u64,
}

impl CommandPath {
    /// The samples (at `sample_rate_hz`) in [`ACTIVE_WINDOW_S`]: how late a sample is
    /// measured.
    pub fn delay(sample_rate_hz: f64) -> usize {
        (ACTIVE_WINDOW_S * sample_rate_hz).ceil().max(1.0) as usize
    }

    /// The command is at `c` (XY, mm) at `t_s` (not before the last point's time).
    #[inline]
    pub fn push(&mut self, t_s: f64, c: [f64; 2]) {
        self.c.push(c);
        self.t.push(t_s);
    }

    /// The points ever pushed.
    fn pushed(&self) -> u64 {
        self.base + self.c.len() as u64
    }

    /// Forget the points older than [`ACTIVE_WINDOW_S`] before `t_s` (but for the one
    /// starting the segment that reaches into the window).
    pub fn forget_before(&mut self, t_s: f64) {
        let from = t_s - ACTIVE_WINDOW_S;
        let mut i = (self.forgotten - self.base) as usize;
        while i + 1 < self.t.len() && self.t[i + 1] < from {
            i += 1;
        }
        self.forgotten = self.base + i as u64;
        // The first kept point's run is held whole, and the held points.
        let keep = self.held.map_or(self.forgotten, |h| h.min(self.forgotten));
        let gap = (keep / RUN * RUN - self.base) as usize;
        let dropped = compact(&mut self.c, gap);
        compact(&mut self.t, dropped);
        self.base += dropped as u64;
    }

    /// Drop the boxes of the runs before the first kept point's, and grow the boxes with
    /// the points pushed since (a point starting a run starts its box and ends the run
    /// before's).
    fn grow_boxes(&mut self) {
        let first = self.forgotten / RUN;
        let gone = first.saturating_sub(self.first_run).min(self.boxes.len() as u64);
        self.boxes.drain(..gone as usize);
        self.first_run += gone;
        if self.boxes.is_empty() {
            self.first_run = first;
            self.grown = self.grown.max(first * RUN);
        }
        for i in self.grown..self.pushed() {
            let c = self.c[(i - self.base) as usize];
            match i % RUN == 0 {
                true => {
                    let ends = self.first_run + self.boxes.len() as u64 == i / RUN;
                    if let Some(b) = self.boxes.last_mut().filter(|_| ends) {
                        b.add(c);
                    }
                    self.boxes.push(Box2::at(c));
                }
                false => self.boxes.last_mut().expect("a run's box").add(c),
            }
        }
        self.grown = self.pushed();
    }

    /// [`CommandPath::distance_mm`] of `p` and `c` at `t_s` (after
    /// [`CommandPath::forget_before`] at `t_s`), to be asked later: the points it needs
    /// are held from now on until [`CommandPath::release`].
    pub fn ask_later(&mut self, t_s: f64, p: [f64; 2], c: [f64; 2]) -> Asked {
        let from = self.forgotten / RUN * RUN;
        self.held.get_or_insert(from);
        Asked {
            t_s,
            p,
            c,
            last: self.pushed() - 1,
        }
    }

    /// The distances (mm) [`CommandPath::distance_mm`] gave when each of `asked` was
    /// made (in the order made, [`CommandPath::ask_later`]), bit for bit: the held points
    /// are pushed again onto a path of their own, and each distance asked of it when its
    /// last point is there. (A box's points are the same whenever it is grown, and it
    /// grows by exact minima and maxima: the boxes, so the skipped segments, are the
    /// same.)
    pub fn distances_mm(&self, asked: &[Asked]) -> Vec<f64> {
        let Some(from) = self.held else {
            return Vec::new();
        };
        let mut path = CommandPath {
            base: from,
            forgotten: from,
            first_run: from / RUN,
            grown: from,
            ..CommandPath::default()
        };
        let at = |i: u64| (i - self.base) as usize;
        asked
            .iter()
            .map(|a| {
                for i in path.pushed()..=a.last {
                    path.push(self.t[at(i)], self.c[at(i)]);
                }
                path.distance_mm(a.t_s, a.p, a.c).unwrap_or(0.0)
            })
            .collect()
    }

    /// How many points [`CommandPath::ask_later`] holds.
    pub fn held(&self) -> u64 {
        self.held.map_or(0, |h| self.pushed() - h)
    }

    /// Stop holding the points [`CommandPath::ask_later`] held.
    pub fn release(&mut self) {
        self.held = None;
    }

    /// What [`CommandPath::distance_mm`] can be no larger than for a toolhead at `p` with
    /// the command at `c` (mm; bit for bit its starting bound).
    pub fn bound_mm(p: [f64; 2], c: [f64; 2]) -> f64 {
        segment_distance_sq(p, c, c).sqrt()
    }

    /// The toolhead's vibration at `t_s`: its distance (mm) from `p` (XY, mm) to the path
    /// from [`ACTIVE_WINDOW_S`] before `t_s` (older points are forgotten) to the last
    /// point (module doc), `c` being the commanded point at `t_s` (on the path); `None`
    /// before the first command.
    pub fn distance_mm(&mut self, t_s: f64, p: [f64; 2], c: [f64; 2]) -> Option<f64> {
        self.forget_before(t_s);
        if self.c.is_empty() {
            return None;
        }
        self.grow_boxes();
        let points = &self.c[..];
        let base = self.base;
        let first = points[(self.forgotten - base) as usize];
        // The commanded point bounds the distance; a box no nearer holds no nearer
        // segment (most of the window's runs and segments, skipped cheaply).
        let mut best = segment_distance_sq(p, c, c).min(segment_distance_sq(p, first, first));
        let last = self.pushed() - 1;
        for (k, b) in (self.first_run..).zip(&self.boxes) {
            if b.near_sq(p) >= best {
                continue;
            }
            // Segments from point `i` to `i + 1` for the kept `i` of run `k`.
            let from = (k * RUN).max(self.forgotten);
            let to = ((k + 1) * RUN).min(last);
            let run = &points[(from - base) as usize..=(to - base) as usize];
            // Each point's offset from `p`, shared by the two segments it ends.
            let mut a = run[0];
            let mut da = offset(a, p);
            for &q in &run[1..] {
                let dq = offset(q, p);
                if segment_box_sq(da, dq) < best {
                    best = best.min(segment_distance_sq(p, a, q));
                }
                (a, da) = (q, dq);
            }
        }
        Some(best.sqrt())
    }
}

/// The command's path as a simulation makes it: the commanded XY of each sample, and
/// the breakpoints of the chunks being followed before it (module doc), every chunk's to
/// its end (a chunk's last breakpoints come after its last sample).
#[derive(Debug)]
pub struct CommandTrack {
    /// The path.
    pub path: CommandPath,
    /// The chunks followed whose breakpoints are not all on the path yet, oldest first.
    chunks: VecDeque<Followed>,
    /// The time of the next breakpoint to put on the path (s, print clock): infinite when
    /// there is none, minus infinity when it is to be found.
    next_s: f64,
}

impl Default for CommandTrack {
    fn default() -> Self {
        Self {
            path: CommandPath::default(),
            chunks: VecDeque::new(),
            next_s: f64::NEG_INFINITY,
        }
    }
}

/// A chunk [`CommandTrack`] follows.
#[derive(Debug)]
struct Followed {
    /// Its start (s, print clock).
    t0_s: f64,
    /// Its X and Y.
    xy: Arc<[Profile; 2]>,
    /// The index of each one's next breakpoint to put on the path.
    next: [usize; 2],
    /// Each one's segment of the last breakpoint put ([`Profile::state_at_from`]'s cursor).
    seg: [usize; 2],
}

impl CommandTrack {
    /// Follow a chunk whose X and Y are `xy` (shared, not copied) from `t0_s` (print
    /// clock), after the ones before: its breakpoints go on the path.
    pub fn follow(&mut self, t0_s: f64, xy: Arc<[Profile; 2]>) {
        self.chunks.push_back(Followed {
            t0_s,
            xy,
            next: [0, 0],
            seg: [0, 0],
        });
        self.next_s = f64::NEG_INFINITY;
    }

    /// A sample at `t_s` commanded at `c` (XY, mm): the chunks' breakpoints before it,
    /// then its point, go on the path.
    #[inline]
    pub fn sample(&mut self, t_s: f64, c: [f64; 2]) {
        // Most samples come before the next breakpoint (one compare).
        // (`next_s` is never NaN; a NaN time looks, as it did, at the breakpoints.)
        if self.next_s < t_s || t_s.is_nan() {
            self.breakpoints_before(t_s);
        }
        self.path.push(t_s, c);
    }

    /// Put the chunks' breakpoints before `t_s` on the path, in time order.
    fn breakpoints_before(&mut self, t_s: f64) {
        while let Some(Followed {
            t0_s: t0,
            xy,
            next,
            seg,
        }) = self.chunks.front_mut()
        {
            let at = |next: &[usize; 2], i: usize| {
                let p: &Profile = &xy[i];
                (next[i] < p.segments().len()).then(|| *t0 + p.segment_start(next[i]).0)
            };
            let tb = match (at(next, 0), at(next, 1)) {
                (Some(a), Some(b)) => a.min(b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => {
                    self.chunks.pop_front();
                    continue;
                }
            };
            if tb >= t_s {
                self.next_s = tb;
                return;
            }
            for i in 0..2 {
                if at(next, i) == Some(tb) {
                    next[i] += 1;
                }
            }
            let tau = tb - *t0;
            let c = [
                xy[0].state_at_from(&mut seg[0], tau).p * 1e3,
                xy[1].state_at_from(&mut seg[1], tau).p * 1e3,
            ];
            self.path.push(tb, c);
        }
        self.next_s = f64::INFINITY;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform numbers in `[0, 1)` from a fixed linear congruential generator seeded with
    /// `seed`: the same walks on every run.
    fn uniform_from(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// The path with its boxes grown as each point is pushed (what [`CommandPath`] makes
    /// only when a distance is asked for): the reference its distances must equal bit for
    /// bit.
    #[derive(Default)]
    struct Grown {
        points: VecDeque<(f64, [f64; 2], Box2)>,
        forgotten: u64,
        boxes: VecDeque<Box2>,
        first_run: u64,
    }

    impl Grown {
        fn push(&mut self, t_s: f64, c: [f64; 2]) {
            let n = self.forgotten + self.points.len() as u64;
            let mut segment = Box2::at(c);
            if let Some(last) = self.points.back() {
                segment.add(last.1);
            }
            if let Some(b) = self.boxes.back_mut() {
                b.add(c);
            }
            if n.is_multiple_of(RUN) {
                if self.boxes.is_empty() {
                    self.first_run = n / RUN;
                }
                self.boxes.push_back(Box2::at(c));
            }
            self.points.push_back((t_s, c, segment));
        }

        fn forget_before(&mut self, t_s: f64) {
            while self.points.len() > 1 && self.points[1].0 < t_s - ACTIVE_WINDOW_S {
                self.points.pop_front();
                self.forgotten += 1;
            }
            while !self.boxes.is_empty() && (self.first_run + 1) * RUN <= self.forgotten {
                self.boxes.pop_front();
                self.first_run += 1;
            }
        }

        fn distance_mm(&mut self, t_s: f64, p: [f64; 2], c: [f64; 2]) -> Option<f64> {
            self.forget_before(t_s);
            let first = self.points.front()?.1;
            let mut best = segment_distance_sq(p, c, c).min(segment_distance_sq(p, first, first));
            let segments = self.points.len() as u64 - 1;
            for (k, b) in self.boxes.iter().enumerate() {
                if b.distance_sq(p) >= best {
                    continue;
                }
                let run = (self.first_run + k as u64) * RUN;
                let from = run.saturating_sub(self.forgotten);
                let to = (run + RUN - self.forgotten.min(run + RUN)).min(segments);
                let mut run = self.points.range(from as usize..=to as usize);
                let Some(mut a) = run.next().map(|q| q.1) else {
                    continue;
                };
                for q in run {
                    let a = std::mem::replace(&mut a, q.1);
                    if q.2.distance_sq(p) < best {
                        best = best.min(segment_distance_sq(p, a, q.1));
                    }
                }
            }
            Some(best.sqrt())
        }
    }

    /// Boxes made when asked give the distances of boxes grown point by point, bit for
    /// bit: on random walks with points at irregular times (several at one time too, as
    /// breakpoints between samples), asked every sample, now and then, or rarely, with
    /// the window forgotten every sample or only when asked.
    #[test]
    fn boxes_made_when_asked_are_the_boxes_grown() {
        let mut uniform = uniform_from(0x9e37_79b9_7f4a_7c15);
        for case in 0..60 {
            let (ask_every, forget_each) = ([1, 3, 37, 400][case % 4], case % 8 < 4);
            let (mut lazy, mut grown) = (CommandPath::default(), Grown::default());
            let mut times: VecDeque<(f64, [f64; 2])> = VecDeque::new();
            let (mut t, mut q) = (0.0, [0.0, 0.0]);
            let mut asked = 0;
            for k in 0..3_000 {
                // A step of 0 to 1 ms (a few of none), a point on a zigzag or still.
                let r = uniform();
                t += if r < 0.1 { 0.0 } else { 1e-3 * uniform() };
                if uniform() < 0.8 {
                    q = [q[0] + uniform() - 0.5, q[1] + 2.0 * uniform() - 1.0];
                }
                lazy.push(t, q);
                grown.push(t, q);
                times.push_back((t, q));
                if times.len() <= 40 {
                    continue;
                }
                let (tm, cm) = times.pop_front().expect("a waiting point");
                if forget_each {
                    lazy.forget_before(tm);
                    grown.forget_before(tm);
                }
                if k % ask_every == 0 {
                    asked += 1;
                    let p = [cm[0] + 3.0 * uniform() - 1.5, cm[1] + 3.0 * uniform() - 1.5];
                    let (a, b) = (lazy.distance_mm(tm, p, cm), grown.distance_mm(tm, p, cm));
                    assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "case {case}, point {k}");
                }
            }
            assert!(asked >= 7, "case {case}");
            // Memory stays bounded: the window, its first run, and a forgotten front
            // dropped now and then (`COMPACT`).
            assert!(lazy.c.len() < 3_000 / 2, "case {case}: {}", lazy.c.len());
        }
    }

    /// Distances asked later ([`CommandPath::ask_later`], [`CommandPath::distances_mm`])
    /// are those asked at the time, bit for bit: on random walks as above, the window
    /// forgotten every sample, some distances asked at once (growing and dropping the
    /// boxes in between), some asked later, released at random, over and over.
    #[test]
    fn distances_asked_later_are_those_asked_at_the_time() {
        let mut uniform = uniform_from(0x2545_f491_4f6c_dd1d);
        let mut later_asked = 0;
        for case in 0..40 {
            let (mut path, mut now) = (CommandPath::default(), CommandPath::default());
            let mut times: VecDeque<(f64, [f64; 2])> = VecDeque::new();
            let (mut t, mut q) = (0.0, [0.0, 0.0]);
            let (mut asked, mut want) = (Vec::new(), Vec::new());
            let ask_now = [0.0, 0.05, 0.5][case % 3];
            for k in 0..4_000 {
                t += if uniform() < 0.1 { 0.0 } else { 1e-3 * uniform() };
                if uniform() < 0.8 {
                    q = [q[0] + uniform() - 0.5, q[1] + 2.0 * uniform() - 1.0];
                }
                path.push(t, q);
                now.push(t, q);
                times.push_back((t, q));
                if times.len() <= 40 {
                    continue;
                }
                let (tm, cm) = times.pop_front().expect("a waiting point");
                path.forget_before(tm);
                now.forget_before(tm);
                let p = [cm[0] + 3.0 * uniform() - 1.5, cm[1] + 3.0 * uniform() - 1.5];
                let r = uniform();
                if r < ask_now {
                    let (a, b) = (path.distance_mm(tm, p, cm), now.distance_mm(tm, p, cm));
                    assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "case {case}, {k}");
                } else if r < ask_now + 0.3 {
                    asked.push(path.ask_later(tm, p, cm));
                    want.push(now.distance_mm(tm, p, cm).unwrap_or(0.0).to_bits());
                }
                if uniform() < 0.002 || k == 3_999 {
                    let got: Vec<u64> = path.distances_mm(&asked).iter().map(|d| d.to_bits()).collect();
                    assert_eq!(got, want, "case {case}, point {k}");
                    later_asked += asked.len();
                    (asked, want) = (Vec::new(), Vec::new());
                    path.release();
                }
            }
            // Released, the held points are dropped again.
            path.forget_before(t);
            assert!(path.c.len() < 4_000 / 2, "case {case}: {}", path.c.len());
        }
        assert!(later_asked > 40_000, "{later_asked}");
    }

    /// A segment's box distance from its ends' offsets, and a box's without looking for
    /// NaN, are the box distances with [`f64::max`] bit for bit: on random points (on a
    /// coarse grid too, so that ends, the point and box sides coincide, zeros of both
    /// signs), a NaN segment end giving a NaN segment distance.
    #[test]
    fn box_distances_from_offsets_are_the_box_distances() {
        let mut uniform = uniform_from(0x5851_f42d_4c95_7f2d);
        for k in 0..200_000 {
            let mut coordinate = || match k % 3 {
                0 => 200.0 * uniform() - 100.0,
                1 => (8.0 * uniform()).floor() * 0.5 - 2.0,
                _ => 1e-3 * (2.0 * uniform() - 1.0) + 0.1,
            };
            let [a, q, p] = [0; 3].map(|_| [coordinate(), coordinate()]);
            let mut segment = Box2::at(q);
            segment.add(a);
            let want = segment.distance_sq(p).to_bits();
            assert_eq!(segment.near_sq(p).to_bits(), want, "{a:?} {q:?} {p:?}");
            let from_offsets = segment_box_sq(offset(a, p), offset(q, p));
            assert_eq!(from_offsets.to_bits(), want, "{a:?} {q:?} {p:?}");
        }
        let nan = [f64::NAN, 1.0];
        assert!(segment_distance_sq([0.0, 0.0], nan, [1.0, 1.0]).is_nan());
        assert!(segment_distance_sq([0.0, 0.0], [1.0, 1.0], nan).is_nan());
    }

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

    /// The boxes skip only segments that cannot be nearer: on random walks (a zigzag that
    /// turns back on itself, points 0.5 ms apart, queried 20 ms late as the account
    /// queries them, the window sliding past many runs), the distance equals the least
    /// over every segment of the window and the two points, computed one by one, to
    /// rounding: a box's distance is exact where a segment's, through its projection,
    /// can come out an ulp below it (a segment skipped for a tie).
    #[test]
    fn boxes_give_the_least_distance_over_every_segment() {
        let mut uniform = uniform_from(0x2545_f491_4f6c_dd1d);
        for _ in 0..20 {
            let mut c = CommandPath::default();
            let mut all: Vec<(f64, [f64; 2])> = Vec::new();
            let mut q = [0.0, 0.0];
            for k in 0..400 {
                let t = k as f64 * 5e-4;
                q = [q[0] + uniform() - 0.5, q[1] + uniform() - 0.5];
                c.push(t, q);
                all.push((t, q));
                let Some(&(tm, cm)) = all.len().checked_sub(41).map(|i| &all[i]) else {
                    continue;
                };
                let p = [cm[0] + 2.0 * uniform() - 1.0, cm[1] + 2.0 * uniform() - 1.0];
                // The kept points: from the first one whose next one is in the window.
                let first = (0..all.len())
                    .find(|&i| i + 1 == all.len() || all[i + 1].0 >= tm - ACTIVE_WINDOW_S)
                    .unwrap_or(0);
                let mut best = segment_distance_sq(p, cm, cm)
                    .min(segment_distance_sq(p, all[first].1, all[first].1));
                for w in all[first..].windows(2) {
                    best = best.min(segment_distance_sq(p, w[0].1, w[1].1));
                }
                let d = c.distance_mm(tm, p, cm).expect("a path");
                let exact = best.sqrt();
                assert!(
                    d >= exact && d - exact <= 1e-15 * exact,
                    "t {tm}: {d} vs {exact}"
                );
            }
        }
    }
}
