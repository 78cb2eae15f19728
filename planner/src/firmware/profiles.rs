//! Planned moves as per-axis [`Profile`]s, in bounded chunks.
//!
//! Each axis follows the path speed of its move times its share ([`PlannedMove::axes_r`]).
//! Linear ramps and cruises become constant-acceleration segments exactly. Two things a
//! [`Profile`] cannot hold are approximated, with these bounds:
//!
//! - **Speed jumps.** At a sharp corner the firmwares change each axis's speed at once
//!   (that is what square corner velocity, junction deviation and jerk allow); Marlin also
//!   starts and ends blocks at step rates that differ a little. A profile's velocity is
//!   continuous, so a jump of `dv` at `t_j` is replaced over the window
//!   `[t_j - w/2, t_j + w/2]` by two constant-acceleration halves that reach the exact
//!   position and velocity at the window end: timing is unchanged, the acceleration is
//!   `dv / w` (a finite impulse), and the position error inside the window is at most
//!   `|dv| w / 8` plus `|da| w^2 / 8` (`w` = [`ProfileOptions::jump_window_s`], 100 µs:
//!   0.1 µm for a 7 mm/s jump). Jumps closer than `w` share one window.
//! - **Marlin's S-curve.** The quintic Bezier speed is a polynomial, not piecewise
//!   constant jerk. It is split into steps of at most `h` =
//!   [`ProfileOptions::bezier_step_s`], each with the constant acceleration that meets the
//!   exact speed at both ends (the trapezoid rule on the speed, exact at every step
//!   boundary); the last two steps are a two-half bridge onto the exact position. The
//!   position error inside the ramp is at most `h^2 a_peak / 12` (the trapezoid rule's
//!   error on a polynomial whose end derivatives cancel), `a_peak = 1.875 dv / T`: 0.2 µm
//!   for 100 mm/s in 50 ms with `h` = 0.5 ms. The acceleration is a staircase of that
//!   step, so its spectrum is exact far below `1 / h` (2 kHz).
//!
//! Time between moves (a dwell) holds the position. Before the first move the toolhead is
//! at rest; after [`ProfileStream::finish`] it comes to rest at the last move's end.
//! Chunks are cut at most every [`ProfileOptions::max_chunk_s`] or
//! [`ProfileOptions::max_chunk_segments`], so a long job streams in bounded memory.

use std::collections::VecDeque;

use super::{Phase, PlannedMove, RampShape};
use crate::{PlanError, Profile, Segment, State, Trajectory};

/// Axes of a chunk: X, Y, Z, E.
pub const AXES: usize = 4;

/// Speed mismatch (m/s) below which two pieces are taken as continuous.
const TOL_V: f64 = 1e-9;
/// Position mismatch (m) below which two pieces are taken as continuous.
const TOL_P: f64 = 1e-12;

/// How planned moves become profiles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileOptions {
    /// Width of the window that replaces a speed jump (s, > 0).
    pub jump_window_s: f64,
    /// Longest constant-acceleration step of a Bezier ramp (s, > 0).
    pub bezier_step_s: f64,
    /// Longest chunk (s, > 0); a chunk ends at the first piece boundary after it.
    pub max_chunk_s: f64,
    /// Most segments per axis in a chunk (>= 16).
    pub max_chunk_segments: usize,
}

impl Default for ProfileOptions {
    /// 100 µs jump windows, 0.5 ms Bezier steps, chunks of at most 1 s or 4096 segments.
    fn default() -> Self {
        Self {
            jump_window_s: 100e-6,
            bezier_step_s: 0.5e-3,
            max_chunk_s: 1.0,
            max_chunk_segments: 4096,
        }
    }
}

/// A stretch of motion: X, Y, Z, E profiles starting at `start_time_s` on the print clock
/// (each profile's `t = 0`). Consecutive chunks join continuously.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileChunk {
    /// Print-clock time of the chunk's `t = 0` (s).
    pub start_time_s: f64,
    /// The four axes (X, Y, Z, E), all of the same duration.
    pub trajectory: Trajectory,
}

/// One phase of one move (or a pause) on the print clock.
#[derive(Debug, Clone, Copy)]
struct Piece {
    t0: f64,
    t1: f64,
    /// Axis positions at `t0`.
    start: [f64; AXES],
    /// Axis displacement per metre of path (zero for a pause).
    r: [f64; AXES],
    phase: Phase,
}

impl Piece {
    /// Exact position and velocity of every axis at `t` (clamped to the piece).
    fn state(&self, t: f64) -> [(f64, f64); AXES] {
        let st = self
            .phase
            .state_at((t - self.t0).clamp(0.0, (self.t1 - self.t0).max(0.0)));
        std::array::from_fn(|i| (self.start[i] + self.r[i] * st.s_m, self.r[i] * st.v_m_s))
    }

    fn rest(t0: f64, t1: f64, at: [f64; AXES]) -> Self {
        Self {
            t0,
            t1,
            start: at,
            r: [0.0; AXES],
            phase: Phase::constant(t1 - t0, 0.0),
        }
    }
}

fn mismatch(a: &[(f64, f64); AXES], b: &[(f64, f64); AXES]) -> bool {
    a.iter()
        .zip(b)
        .any(|(x, y)| (x.0 - y.0).abs() > TOL_P || (x.1 - y.1).abs() > TOL_V)
}

/// Turns planned moves, pushed in execution order, into [`ProfileChunk`]s.
#[derive(Debug)]
pub struct ProfileStream {
    opts: ProfileOptions,
    pieces: VecDeque<Piece>,
    /// End time and axis positions of the last move pushed.
    last_end: Option<(f64, [f64; AXES])>,
    finished: bool,
    cursor_s: f64,
    /// Position and velocity of each profile at the cursor.
    state: [(f64, f64); AXES],
    chunk_t0: f64,
    chunk_start: [State; AXES],
    segs: [Vec<Segment>; AXES],
    ready: VecDeque<ProfileChunk>,
}

impl ProfileStream {
    /// A stream with `opts` (checked).
    pub fn new(opts: ProfileOptions) -> Result<Self, PlanError> {
        for (name, v) in [
            ("jump_window_s", opts.jump_window_s),
            ("bezier_step_s", opts.bezier_step_s),
            ("max_chunk_s", opts.max_chunk_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(PlanError::InvalidLimit { name, value: v });
            }
        }
        if opts.max_chunk_segments < 16 {
            return Err(PlanError::InvalidLimit {
                name: "max_chunk_segments (>= 16)",
                value: opts.max_chunk_segments as f64,
            });
        }
        Ok(Self {
            opts,
            pieces: VecDeque::new(),
            last_end: None,
            finished: false,
            cursor_s: 0.0,
            state: [(0.0, 0.0); AXES],
            chunk_t0: 0.0,
            chunk_start: [State::default(); AXES],
            segs: std::array::from_fn(|_| Vec::new()),
            ready: VecDeque::new(),
        })
    }

    /// Add the next planned move (in execution order, not before the previous one ends).
    pub fn push(&mut self, mv: &PlannedMove) -> Result<(), PlanError> {
        if self.finished {
            return Err(PlanError::InvalidInput {
                reason: "a move was pushed after ProfileStream::finish",
            });
        }
        let mut t = mv.start_time_s;
        match self.last_end {
            None => {
                // At rest at the first move's start until it begins.
                let start = mv.start_m;
                self.cursor_s = t;
                self.state = start.map(|p| (p, 0.0));
                self.chunk_t0 = t;
                self.chunk_start = start.map(|p| State { p, v: 0.0, a: 0.0 });
            }
            Some((end, at)) => {
                if t < end - 1e-9 {
                    return Err(PlanError::InvalidInput {
                        reason: "planned moves must be pushed in time order",
                    });
                }
                t = t.max(end);
                if t > end {
                    self.pieces.push_back(Piece::rest(end, t, at));
                }
            }
        }
        let mut s0 = 0.0;
        for ph in mv.phases() {
            let d = ph.duration_s.max(0.0);
            let start = std::array::from_fn(|i| mv.start_m[i] + mv.axes_r[i] * s0);
            self.pieces.push_back(Piece {
                t0: t,
                t1: t + d,
                start,
                r: mv.axes_r,
                phase: Phase {
                    duration_s: d,
                    ..*ph
                },
            });
            s0 += ph.distance_m();
            t += d;
        }
        let end = std::array::from_fn(|i| mv.start_m[i] + mv.axes_r[i] * s0);
        self.last_end = Some((t, end));
        self.process()
    }

    /// No more moves: come to rest after the last one and emit the final chunk.
    pub fn finish(&mut self) -> Result<(), PlanError> {
        if self.finished {
            return Ok(());
        }
        self.finished = true;
        if let Some((end, at)) = self.last_end {
            self.pieces
                .push_back(Piece::rest(end, end + self.opts.jump_window_s, at));
        }
        self.process()?;
        self.close_chunk()
    }

    /// Take the next finished chunk.
    pub fn pop(&mut self) -> Option<ProfileChunk> {
        self.ready.pop_front()
    }

    /// Advance the cursor as far as the moves pushed so far allow.
    fn process(&mut self) -> Result<(), PlanError> {
        while self.step() {
            let n = self.segs[0].len();
            if n + 8 >= self.opts.max_chunk_segments
                || self.cursor_s - self.chunk_t0 >= self.opts.max_chunk_s
            {
                self.close_chunk()?;
            }
        }
        Ok(())
    }

    /// Move the cursor past one piece boundary or one jump window; `false` when more
    /// input is needed (or everything is done).
    fn step(&mut self) -> bool {
        while self.pieces.front().is_some_and(|p| p.t1 <= self.cursor_s) {
            self.pieces.pop_front();
        }
        let Some(&p) = self.pieces.front() else {
            return false;
        };
        let here = p.state(self.cursor_s);
        if mismatch(&self.state, &here) {
            return self.window(self.cursor_s, 0);
        }
        let Some(next) = self.pieces.get(1) else {
            if self.finished {
                self.emit_exact(&p, self.cursor_s, p.t1);
                self.cursor_s = p.t1;
                return true;
            }
            return false;
        };
        let tb = p.t1;
        if !mismatch(&p.state(tb), &next.state(tb)) {
            self.emit_exact(&p, self.cursor_s, tb);
            self.cursor_s = tb;
            return true;
        }
        // A jump at the end of this piece: run exactly up to its window.
        let ws = (tb - 0.5 * self.opts.jump_window_s).max(self.cursor_s);
        self.emit_exact(&p, self.cursor_s, ws);
        self.cursor_s = ws;
        self.window(ws, 1)
    }

    /// Bridge a jump window starting at `ws`, whose first jump is at the start of
    /// `pieces[first]` (`first` = 0: at `ws` itself). Later jumps closer than a window
    /// join it.
    fn window(&mut self, ws: f64, first: usize) -> bool {
        let half = 0.5 * self.opts.jump_window_s;
        let tj = if first == 0 {
            ws
        } else {
            self.pieces[first].t0
        };
        let mut we = tj + half;
        let mut k = first;
        loop {
            // The boundary at the end of pieces[k], if it starts a jump within reach.
            let Some(pk) = self.pieces.get(k) else {
                return self.finished && self.bridge(ws, we);
            };
            let b = pk.t1;
            if b - half >= we {
                break;
            }
            let Some(next) = self.pieces.get(k + 1) else {
                if self.finished {
                    break;
                }
                return false;
            };
            if mismatch(&pk.state(b), &next.state(b)) {
                we = b + half;
            }
            k += 1;
        }
        self.bridge(ws, we)
    }

    /// Replace `[ws, we]` by two constant-acceleration halves per axis that reach the
    /// exact state at `we`.
    fn bridge(&mut self, ws: f64, we: f64) -> bool {
        let Some(target) = self.exact_at(we) else {
            return false;
        };
        let h = 0.5 * (we - ws);
        for (i, tgt) in target.iter().enumerate() {
            let (p0, v0) = self.state[i];
            let (a1, a2) = two_halves(p0, v0, tgt.0, tgt.1, h);
            self.segs[i].push(Segment::Accel {
                duration_s: h,
                accel: a1,
            });
            self.segs[i].push(Segment::Accel {
                duration_s: h,
                accel: a2,
            });
        }
        self.state = target;
        self.cursor_s = we;
        true
    }

    /// The exact state at `t` (right-continuous), if the pieces reach it.
    fn exact_at(&self, t: f64) -> Option<[(f64, f64); AXES]> {
        let p = self
            .pieces
            .iter()
            .find(|p| p.t1 > t)
            .or_else(|| self.pieces.back().filter(|p| p.t1 >= t && self.finished))?;
        Some(p.state(t))
    }

    /// The exact motion of `p` from `ta` to `tb`.
    fn emit_exact(&mut self, p: &Piece, ta: f64, tb: f64) {
        if !(tb > ta) {
            return;
        }
        let ph = p.phase;
        let linear = ph.shape == RampShape::Linear || ph.dv_m_s == 0.0 || !(ph.ramp_s > 0.0);
        if linear {
            let a = if ph.dv_m_s == 0.0 || !(ph.ramp_s > 0.0) {
                0.0
            } else {
                ph.dv_m_s / ph.ramp_s
            };
            for i in 0..AXES {
                self.push_accel(i, tb - ta, p.r[i] * a);
            }
            return;
        }
        // Bezier: steps meeting the exact speed, then a bridge onto the exact position.
        let n = ((tb - ta) / self.opts.bezier_step_s).ceil().max(1.0) as usize;
        let h = (tb - ta) / n as f64;
        let mut v0 = p.state(ta);
        for k in 0..n.saturating_sub(2) {
            let v1 = p.state(ta + (k + 1) as f64 * h);
            for i in 0..AXES {
                self.push_accel(i, h, (v1[i].1 - v0[i].1) / h);
            }
            v0 = v1;
        }
        let bs = ta + n.saturating_sub(2) as f64 * h;
        let target = p.state(tb);
        let half = 0.5 * (tb - bs);
        for (i, tgt) in target.iter().enumerate() {
            let (p0, v0) = self.state[i];
            let (a1, a2) = two_halves(p0, v0, tgt.0, tgt.1, half);
            self.push_accel(i, half, a1);
            self.push_accel(i, half, a2);
        }
        self.state = target;
    }

    /// Append a constant-acceleration segment to axis `i` and advance its state.
    fn push_accel(&mut self, i: usize, d: f64, a: f64) {
        let (p, v) = self.state[i];
        self.state[i] = (p + d * (v + 0.5 * a * d), v + a * d);
        self.segs[i].push(Segment::Accel {
            duration_s: d,
            accel: a,
        });
    }

    /// Emit the segments gathered since the last chunk as a chunk.
    fn close_chunk(&mut self) -> Result<(), PlanError> {
        if self.segs[0].is_empty() {
            return Ok(());
        }
        let mut axes = Vec::with_capacity(AXES);
        for i in 0..AXES {
            let segs = std::mem::take(&mut self.segs[i]);
            axes.push(Profile::new(self.chunk_start[i], segs)?);
        }
        self.ready.push_back(ProfileChunk {
            start_time_s: self.chunk_t0,
            trajectory: Trajectory::new(axes)?,
        });
        self.chunk_t0 = self.cursor_s;
        self.chunk_start = self.state.map(|(p, v)| State { p, v, a: 0.0 });
        Ok(())
    }
}

/// Accelerations of two halves of length `h` taking `(p0, v0)` to `(p1, v1)`:
/// `v1 = v0 + (a1 + a2) h`, `p1 = p0 + 2 v0 h + (3 a1 + a2) h^2 / 2`.
fn two_halves(p0: f64, v0: f64, p1: f64, v1: f64, h: f64) -> (f64, f64) {
    if !(h > 0.0) {
        return (0.0, 0.0);
    }
    let s = (v1 - v0) / h;
    let d = 2.0 * (p1 - p0 - 2.0 * v0 * h) / (h * h);
    let a1 = 0.5 * (d - s);
    (a1, s - a1)
}
