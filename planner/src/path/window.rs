//! settle's own look-ahead ([`super::plan_path`]) over a move stream of any length, in
//! bounded windows.
//!
//! [`WindowedPath`] collects straight moves into a window of at most
//! [`WindowedPath::new`]`(.., window_points)` points that ends, as far as the plan knows,
//! with a stop at its last point. When the window is full it plans it as
//! [`super::Lookahead`] does (corner caps, a backward pass from the stop, a forward pass
//! from the speed the window starts with) and commits the moves up to the last point whose
//! speed no later move can change: a point held at its cap (a sharp corner at its junction
//! speed, a blend at its deviation limit, `vmax`) keeps its speed whatever follows, and so
//! does everything before it. If no point in the window is at its cap (a long chain of
//! nearly collinear short moves) it commits the first half, as a firmware with a bounded
//! look-ahead does: every speed of the plan allows a stop within the window, so the
//! re-plan from the committed point always finds one. The committed point's speed and the
//! part of the next move its corner transition used are where the next window starts.
//!
//! As long as every commit is at a capped point, the speeds are bit for bit those of
//! [`super::plan_path`] on the whole path, and a stream that fits one window is planned
//! exactly as `plan_path` plans it (`planner/tests/paths.rs` has no window; the G-code job
//! tests in settle-gcode compare both). Each move may lower `vmax` (a G-code feed rate):
//! a segment's straight run is planned under its own speed limit and a corner under the
//! lower of its two segments' limits.

use std::collections::VecDeque;

use super::blend;
use super::law::largest;
use super::lookahead::{CornerStrategy, PathOptions, corner_piece, corner_used, straight_piece};
use super::pieces::{Piece, VState, profiles_from};
use super::polyline::interior_angle;
use super::vector::{V3, axpy, dist, norm, scale, sub};
use crate::{PlanError, Profile, Segment, State, Trajectory};

/// When and which move the toolhead follows: from the middle of the transition at its
/// start point to the middle of the one at its end point (s on the planner's clock).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveSpan {
    /// The move's id, as pushed.
    pub seq: u64,
    /// Start (s).
    pub start_time_s: f64,
    /// End (s).
    pub end_time_s: f64,
}

/// A committed stretch of the plan: X, Y, Z profiles starting at `start_time_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct PathChunk {
    /// Clock time of the profiles' `t = 0` (s).
    pub start_time_s: f64,
    /// X, Y, Z.
    pub trajectory: Trajectory,
    /// The moves this stretch finishes, in order.
    pub moves: Vec<MoveSpan>,
}

/// The look-ahead in bounded windows (module doc).
#[derive(Debug, Clone)]
pub struct WindowedPath {
    opts: PathOptions,
    window: usize,
    /// Window points: the first is where the window starts (a committed point).
    pts: Vec<V3>,
    /// Per window segment: its speed limit and move id.
    seg_vmax: Vec<f64>,
    seqs: Vec<u64>,
    /// Speed at the first point, and length of the first segment its transition used.
    v0: f64,
    d0: f64,
    /// Clock at the end of the committed motion, and at the middle of the first point's
    /// transition (where the first move's span starts).
    time_s: f64,
    span_start_s: f64,
    ready: VecDeque<PathChunk>,
}

/// The plan of a window: the speed cap, backward and planned speeds of each point.
struct Plan {
    cap: Vec<f64>,
    bwd: Vec<f64>,
    speed: Vec<f64>,
}

impl WindowedPath {
    /// A planner with `opts` committing at most `window_points` points at a time
    /// (>= 3), at rest at `start_m`.
    pub fn new(opts: PathOptions, window_points: usize, start_m: V3) -> Result<Self, PlanError> {
        opts.validate()?;
        if window_points < 3 {
            return Err(PlanError::InvalidLimit {
                name: "window_points (>= 3)",
                value: window_points as f64,
            });
        }
        Ok(Self {
            opts,
            window: window_points,
            pts: vec![start_m],
            seg_vmax: Vec::new(),
            seqs: Vec::new(),
            v0: 0.0,
            d0: 0.0,
            time_s: 0.0,
            span_start_s: 0.0,
            ready: VecDeque::new(),
        })
    }

    /// Where the toolhead is (or will be once the queued moves are done), m.
    pub fn position_m(&self) -> V3 {
        self.pts.last().copied().unwrap_or([0.0; 3])
    }

    /// Move to `to_m` at no more than `speed_m_s` (capped by the path limits) as move
    /// `seq`. Moves shorter than the path's coincidence threshold are dropped.
    pub fn push(&mut self, to_m: V3, speed_m_s: f64, seq: u64) -> Result<(), PlanError> {
        if !(speed_m_s.is_finite() && speed_m_s > 0.0) {
            return Err(PlanError::InvalidLimit {
                name: "move speed",
                value: speed_m_s,
            });
        }
        let from = self.position_m();
        let scale_m = 1.0 + norm(from).max(norm(to_m));
        if to_m.iter().any(|x| !x.is_finite()) || dist(from, to_m) <= 1e-12 * scale_m {
            return if to_m.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(PlanError::NonFinite {
                    name: "move end",
                    value: f64::NAN,
                })
            };
        }
        self.pts.push(to_m);
        self.seg_vmax.push(speed_m_s.min(self.opts.limits.vmax()));
        self.seqs.push(seq);
        if self.pts.len() > self.window {
            let plan = self.plan();
            let last = self.pts.len() - 1;
            let c = (1..last)
                .rev()
                .find(|&k| plan.bwd[k] == plan.cap[k])
                .unwrap_or(last / 2);
            self.commit(&plan, c)?;
        }
        Ok(())
    }

    /// Stop at the last point, commit everything, then stand still for `dwell_s`.
    pub fn stop(&mut self, dwell_s: f64) -> Result<(), PlanError> {
        if !(dwell_s.is_finite() && dwell_s >= 0.0) {
            return Err(PlanError::NonFinite {
                name: "dwell time (must be finite and >= 0)",
                value: dwell_s,
            });
        }
        if self.pts.len() > 1 {
            let plan = self.plan();
            self.commit(&plan, self.pts.len() - 1)?;
        }
        if dwell_s > 0.0 {
            let at = self.position_m();
            let axes = at
                .iter()
                .map(|&p| {
                    Profile::new(
                        State { p, v: 0.0, a: 0.0 },
                        vec![Segment::Accel {
                            duration_s: dwell_s,
                            accel: 0.0,
                        }],
                    )
                })
                .collect::<Result<Vec<_>, _>>()?;
            self.ready.push_back(PathChunk {
                start_time_s: self.time_s,
                trajectory: Trajectory::new(axes)?,
                moves: Vec::new(),
            });
            self.time_s += dwell_s;
            self.span_start_s = self.time_s;
        }
        Ok(())
    }

    /// Take the next committed chunk.
    pub fn pop(&mut self) -> Option<PathChunk> {
        self.ready.pop_front()
    }

    /// The clock at the end of the committed motion (s).
    pub fn print_time_s(&self) -> f64 {
        self.time_s
    }

    /// Points waiting in the window (the committed start point included).
    pub fn queued(&self) -> usize {
        self.pts.len()
    }

    fn len(&self, k: usize) -> f64 {
        dist(self.pts[k], self.pts[k + 1])
    }

    fn dir(&self, k: usize) -> V3 {
        let d = sub(self.pts[k + 1], self.pts[k]);
        scale(d, 1.0 / norm(d))
    }

    fn jmax(&self) -> f64 {
        self.opts.limits.jmax().unwrap_or(f64::INFINITY)
    }

    /// Speed cap of interior point `k` (as `Lookahead::set_corner`, with the segments'
    /// own speed limits).
    fn cap(&self, k: usize, theta: f64) -> f64 {
        let (u_in, u_out) = (self.dir(k - 1), self.dir(k));
        let (l_in, l_out) = (self.len(k - 1), self.len(k));
        let vmax = self.seg_vmax[k - 1].min(self.seg_vmax[k]);
        let amax = self.opts.limits.amax();
        let straight = norm(sub(u_out, u_in)) == 0.0;
        match self.opts.corners {
            CornerStrategy::ExactStop => 0.0,
            _ if straight => vmax,
            CornerStrategy::Junction(j) => vmax
                .min(j.speed(theta, amax, l_in, l_out))
                .min(l_in.min(l_out) / self.opts.velocity_jump_s),
            CornerStrategy::Blend { max_deviation_m } => blend::max_speed(
                theta,
                amax,
                self.jmax(),
                max_deviation_m,
                0.5 * l_in.min(l_out),
                vmax,
            ),
        }
    }

    /// Length of segment `k` used by the transition at point `k` at speed `v`.
    fn used(&self, k: usize, v: f64) -> f64 {
        let last = self.pts.len() - 1;
        if k == 0 {
            return self.d0;
        }
        if k == last || v <= 0.0 {
            return 0.0;
        }
        corner_used(&self.opts, self.dir(k - 1), self.dir(k), v)
    }

    /// Does the run of segment `k` hold the change `v0 -> v1`?
    fn fits(&self, k: usize, v0: f64, v1: f64) -> bool {
        let len = self.len(k) - self.used(k, v0) - self.used(k + 1, v1);
        len >= self.opts.law.change(v0, v1).distance_m
    }

    /// Caps, then the backward pass from a stop at the last point and the forward pass
    /// from the window's start speed.
    fn plan(&self) -> Plan {
        let n = self.pts.len();
        let last = n - 1;
        let mut p = Plan {
            cap: vec![0.0; n],
            bwd: vec![0.0; n],
            speed: vec![0.0; n],
        };
        for k in 1..last {
            p.cap[k] = self.cap(k, interior_angle(self.dir(k - 1), self.dir(k)));
        }
        for k in (0..last).rev() {
            let next = p.bwd[k + 1];
            let cap = if k == 0 { 0.0 } else { p.cap[k] };
            p.bwd[k] = if cap <= next {
                cap
            } else {
                largest(next, cap, |v| self.fits(k, v, next))
            };
        }
        p.speed[0] = self.v0;
        for k in 0..last {
            let (v0, b) = (p.speed[k], p.bwd[k + 1]);
            p.speed[k + 1] = if b <= v0 {
                b
            } else {
                largest(v0, b, |v| self.fits(k, v0, v))
            };
        }
        p
    }

    /// Commit segments `0..c` and the transition at point `c` (a stop if it is the last
    /// point); the window then starts at point `c`.
    fn commit(&mut self, plan: &Plan, c: usize) -> Result<(), PlanError> {
        let last = self.pts.len() - 1;
        let mut pieces: Vec<Piece> = Vec::with_capacity(2 * c);
        let mut moves = Vec::with_capacity(c);
        let mut t = 0.0;
        let start = VState {
            p: axpy(self.pts[0], self.d0, self.dir(0)),
            v: scale(self.dir(0), self.v0),
            a: [0.0; 3],
        };
        let mut next_d0 = 0.0;
        for k in 0..c {
            let u = self.dir(k);
            let (v0, v1) = (plan.speed[k], plan.speed[k + 1]);
            let (d0, d1) = (self.used(k, v0), self.used(k + 1, v1));
            let from = axpy(self.pts[k], d0, u);
            let len = self.len(k) - d0 - d1;
            let piece = straight_piece(&self.opts, from, u, v0, v1, len, self.seg_vmax[k]);
            t += piece.duration_s();
            pieces.push(piece);
            let p = k + 1;
            let mut mid = t;
            if p != last && v1 > 0.0 && d1 > 0.0 {
                let u_out = self.dir(p);
                let (piece, _, _) = corner_piece(&self.opts, self.pts[p], u, u_out, v1, d1);
                let dur = piece.duration_s();
                mid = t + 0.5 * dur;
                t += dur;
                pieces.push(piece);
                if p == c {
                    next_d0 = d1;
                }
            }
            moves.push(MoveSpan {
                seq: self.seqs[k],
                start_time_s: self.span_start_s,
                end_time_s: self.time_s + mid,
            });
            self.span_start_s = self.time_s + mid;
        }
        let axes = profiles_from(3, start, &pieces)?;
        self.ready.push_back(PathChunk {
            start_time_s: self.time_s,
            trajectory: Trajectory::new(axes)?,
            moves,
        });
        self.time_s += t;
        self.v0 = plan.speed[c];
        self.d0 = next_d0;
        self.pts.drain(..c);
        self.seg_vmax.drain(..c);
        self.seqs.drain(..c);
        Ok(())
    }
}
