//! Look-ahead over a path: corner speeds by backward and forward passes, then
//! the per-segment attack/sustain/release profiles and the corner transitions, assembled
//! into a multi-axis [`Trajectory`] carrying its [`PathGeometry`].
//!
//! Each point `k` gets a speed cap `cap_k` (zero at the ends, at waypoints and for exact
//! stops; the junction speed for sharp corners; the fastest blend within the deviation
//! tolerance for blends; never above `vmax`) and uses up `d_k(v)` of each adjacent segment
//! for its transition at speed `v` (the blend distance; half the velocity-jump window for
//! sharp corners). The straight run of segment `k` is what the two transitions leave,
//! `l_k = L_k - d_k(v_k) - d_{k+1}(v_{k+1})`, and must hold the speed change:
//! `l_k >= D(v_k -> v_{k+1})` (the law's change distance: the minimum segment length).
//! The backward pass lowers each speed so that the next one can be reached decelerating;
//! the forward pass lowers each so that it can be reached accelerating. Both are bisections
//! on monotone conditions (`d` and `D` grow with the higher speed). Caps keep
//! `d_k <= L/2` on both sides, so runs never have negative length.
//!
//! Appending a point turns the old last point (a stop) into a corner; the backward pass
//! reruns from the new end and stops at the first point whose backward speed is unchanged
//! (nothing before it can change), as in GRBL's planner.

use std::f64::consts::PI;
use std::sync::Arc;

use super::blend::{self, Blend};
use super::geometry::{CornerPlan, CornerTransition, PathGeometry, Primitive};
use super::junction::Junction;
use super::law::{self, SpeedLaw, largest};
use super::pieces::{Piece, VSeg, VState, profiles};
use super::polyline::{Path, PathPoint, PointKind, interior_angle};
use super::vector::{V3, axpy, norm, scale, sub};
use crate::{Limits, PlanError, ProfileKind, Trajectory};

/// How control points are passed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CornerStrategy {
    /// Stop at every point (every point behaves as a waypoint).
    ExactStop,
    /// Sharp corner passed at the junction speed (GRBL or Klipper) with an instantaneous
    /// change of the velocity vector (written as a constant acceleration over
    /// [`PathOptions::velocity_jump_s`]).
    Junction(Junction),
    /// The jerk-limited corner blend ([`super::blend`]), at the highest speed whose
    /// deviation from the corner is at most `max_deviation_m` (m) and whose distance fits
    /// half of each segment.
    Blend {
        /// Largest allowed distance between the corner and the blend (m), >= 0.
        max_deviation_m: f64,
    },
}

/// Default duration (s) over which a sharp corner's velocity jump is spread: short
/// against every mechanical period (a 300 Hz mode lasts 3.3 ms) and against a 10 kHz
/// sample, while keeping the acceleration finite for the per-axis profiles. The corner is
/// cut by `dv T/8`: 25 nm for a 0.2 m/s change.
pub const DEFAULT_VELOCITY_JUMP_S: f64 = 1e-6;

/// Options of a path plan.
#[derive(Debug, Clone)]
pub struct PathOptions {
    /// Vector limits of the toolhead: `vmax` (m/s), `amax` (m/s^2) and `jmax` (m/s^3) for
    /// blends (no `jmax`: blends step the acceleration).
    pub limits: Limits,
    /// The speed-change law of the straight runs.
    pub law: Arc<dyn SpeedLaw>,
    /// How control points are passed.
    pub corners: CornerStrategy,
    /// Duration of a sharp corner's velocity jump (s), > 0.
    pub velocity_jump_s: f64,
}

impl PathOptions {
    /// Options for a profile kind (its law at `limits`) and a corner strategy.
    pub fn new(
        limits: Limits,
        kind: ProfileKind,
        corners: CornerStrategy,
    ) -> Result<Self, PlanError> {
        Ok(Self {
            law: law::for_kind(kind, &limits)?,
            limits,
            corners,
            velocity_jump_s: DEFAULT_VELOCITY_JUMP_S,
        })
    }

    pub(crate) fn validate(&self) -> Result<(), PlanError> {
        match self.corners {
            CornerStrategy::ExactStop => {}
            CornerStrategy::Junction(j) => j.validate()?,
            CornerStrategy::Blend { max_deviation_m } => {
                if max_deviation_m.is_nan() || max_deviation_m < 0.0 {
                    return Err(PlanError::InvalidLimit {
                        name: "max_deviation_m",
                        value: max_deviation_m,
                    });
                }
            }
        }
        let t = self.velocity_jump_s;
        if !(t.is_finite() && t > 0.0) {
            return Err(PlanError::InvalidLimit {
                name: "velocity_jump_s",
                value: t,
            });
        }
        Ok(())
    }

    fn jmax(&self) -> f64 {
        self.limits.jmax().unwrap_or(f64::INFINITY)
    }
}

/// Incremental look-ahead over a growing path.
#[derive(Debug, Clone)]
pub struct Lookahead {
    path: Path,
    opts: PathOptions,
    /// Interior angle at each point (`pi` at the ends).
    theta: Vec<f64>,
    /// Speed cap at each point.
    cap: Vec<f64>,
    /// Speeds after the backward pass.
    bwd: Vec<f64>,
    /// Planned speeds (after the forward pass).
    speed: Vec<f64>,
    /// First point whose planned speed the last update recomputed.
    replanned_from: usize,
}

impl Lookahead {
    /// Plan the corner speeds of `path`.
    pub fn new(path: Path, opts: PathOptions) -> Result<Self, PlanError> {
        opts.validate()?;
        let n = path.points().len();
        let mut la = Self {
            path,
            opts,
            theta: vec![PI; n],
            cap: vec![0.0; n],
            bwd: vec![0.0; n],
            speed: vec![0.0; n],
            replanned_from: 0,
        };
        for k in 1..n - 1 {
            la.set_corner(k);
        }
        la.passes(true);
        Ok(la)
    }

    /// Append a point: the old last point becomes a corner (its terminal stop is removed
    /// if it is a control point) and the speeds are re-planned from the end backwards as
    /// far as they change.
    pub fn push(&mut self, point: PathPoint) -> Result<(), PlanError> {
        self.path.push(point)?;
        let last = self.path.points().len() - 1;
        self.theta.push(PI);
        self.cap.push(0.0);
        self.bwd.push(0.0);
        self.speed.push(0.0);
        self.set_corner(last - 1);
        self.passes(false);
        Ok(())
    }

    /// The path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The options.
    pub fn options(&self) -> &PathOptions {
        &self.opts
    }

    /// Planned speed at each point (m/s).
    pub fn speeds(&self) -> &[f64] {
        &self.speed
    }

    /// Speed cap of each point before the passes (m/s).
    pub fn caps(&self) -> &[f64] {
        &self.cap
    }

    /// The first point whose speed the last `new`/`push` recomputed (0 after `new`).
    pub fn replanned_from(&self) -> usize {
        self.replanned_from
    }

    /// Angle and speed cap of interior point `k`.
    fn set_corner(&mut self, k: usize) {
        let (u_in, u_out) = (self.path.direction(k - 1), self.path.direction(k));
        let theta = interior_angle(u_in, u_out);
        self.theta[k] = theta;
        let (l_in, l_out) = (self.path.segment_length(k - 1), self.path.segment_length(k));
        let lim = &self.opts.limits;
        let (vmax, amax) = (lim.vmax(), lim.amax());
        let straight = norm(sub(u_out, u_in)) == 0.0;
        self.cap[k] = if self.path.points()[k].kind == PointKind::Waypoint {
            0.0
        } else {
            match self.opts.corners {
                CornerStrategy::ExactStop => 0.0,
                _ if straight => vmax,
                CornerStrategy::Junction(j) => {
                    let tj = self.opts.velocity_jump_s;
                    vmax.min(j.speed(theta, amax, l_in, l_out))
                        .min(l_in.min(l_out) / tj)
                }
                CornerStrategy::Blend { max_deviation_m } => blend::max_speed(
                    theta,
                    amax,
                    self.opts.jmax(),
                    max_deviation_m,
                    0.5 * l_in.min(l_out),
                    vmax,
                ),
            }
        };
    }

    /// Length of segment `k` used by the transition at point `k` at speed `v`.
    fn used(&self, k: usize, v: f64) -> f64 {
        let last = self.path.points().len() - 1;
        if k == 0 || k == last || v <= 0.0 {
            return 0.0;
        }
        corner_used(
            &self.opts,
            self.path.direction(k - 1),
            self.path.direction(k),
            v,
        )
    }

    /// Does the run of segment `k` hold the change `v0 -> v1` (v0 at point k)?
    fn fits(&self, k: usize, v0: f64, v1: f64) -> bool {
        let len = self.path.segment_length(k) - self.used(k, v0) - self.used(k + 1, v1);
        len >= self.opts.law.change(v0, v1).distance_m
    }

    /// Backward pass from the end; unless `full`, it stops at the first point (before the
    /// old last one) whose backward speed is unchanged, since nothing before it can change.
    /// Then the forward pass from there.
    fn passes(&mut self, full: bool) {
        let last = self.path.points().len() - 1;
        self.bwd[last] = 0.0;
        let mut start = 0;
        for k in (0..last).rev() {
            let next = self.bwd[k + 1];
            let cap = if k == 0 { 0.0 } else { self.cap[k] };
            let b = if cap <= next {
                cap
            } else {
                largest(next, cap, |v| self.fits(k, v, next))
            };
            let unchanged = !full && k + 1 < last && b == self.bwd[k];
            self.bwd[k] = b;
            if unchanged {
                // Its forward speed depends only on unchanged values too.
                start = k;
                break;
            }
        }
        if start == 0 {
            self.speed[0] = 0.0;
            self.replanned_from = 0;
        } else {
            self.replanned_from = start + 1;
        }
        for k in start..last {
            let (v0, b) = (self.speed[k], self.bwd[k + 1]);
            self.speed[k + 1] = if b <= v0 {
                b
            } else {
                largest(v0, b, |v| self.fits(k, v0, v))
            };
        }
        self.replanned_from = start;
    }

    /// The trajectory (one profile per axis, all starting at `t = 0` at rest on the first
    /// point and ending at rest on the last) with its geometry attached.
    pub fn plan(&self) -> Result<Trajectory, PlanError> {
        let pts = self.path.points();
        let n = pts.len();
        let lim = &self.opts.limits;
        let mut pieces: Vec<Piece> = Vec::with_capacity(2 * n);
        let mut prims: Vec<Primitive> = Vec::with_capacity(3 * n);
        let mut corners: Vec<CornerPlan> = Vec::with_capacity(n);
        let mut t = 0.0;
        let stop = |k: usize, t: f64, theta: f64| CornerPlan {
            index: k,
            kind: pts[k].kind,
            theta_rad: theta,
            speed: 0.0,
            transition: CornerTransition::Stop,
            deviation_m: 0.0,
            time_s: t,
        };
        corners.push(stop(0, 0.0, PI));
        for k in 0..n - 1 {
            let u = self.path.direction(k);
            let (v0, v1) = (self.speed[k], self.speed[k + 1]);
            let (d0, d1) = (self.used(k, v0), self.used(k + 1, v1));
            let from = axpy(pts[k].position, d0, u);
            let to = axpy(pts[k + 1].position, -d1, u);
            let len = self.path.segment_length(k) - d0 - d1;
            let piece = straight_piece(&self.opts, from, u, v0, v1, len, lim.vmax());
            t += piece.duration_s();
            if len > 0.0 {
                prims.push(Primitive::Line { a: from, b: to });
            }
            pieces.push(piece);
            if k + 1 == n - 1 {
                corners.push(stop(k + 1, t, PI));
                break;
            }
            // The transition at point k + 1.
            let c = k + 1;
            let u_out = self.path.direction(c);
            let theta = self.theta[c];
            let corner = pts[c].position;
            let plan = if v1 <= 0.0 {
                stop(c, t, theta)
            } else if d1 == 0.0 {
                CornerPlan {
                    transition: CornerTransition::Pass,
                    speed: v1,
                    ..stop(c, t, theta)
                }
            } else {
                let (piece, transition, deviation) =
                    corner_piece(&self.opts, corner, u, u_out, v1, d1);
                let dur = piece.duration_s();
                arcs(&piece, &mut prims);
                pieces.push(piece);
                let cp = CornerPlan {
                    index: c,
                    kind: pts[c].kind,
                    theta_rad: theta,
                    speed: v1,
                    transition,
                    deviation_m: deviation,
                    time_s: t + 0.5 * dur,
                };
                t += dur;
                cp
            };
            corners.push(plan);
        }
        let axes = profiles(self.path.dim(), pts[0].position, &pieces)?;
        let geometry = PathGeometry::new(self.path.dim(), pts.to_vec(), prims, corners);
        Ok(Trajectory::new(axes)?.with_path(geometry))
    }
}

/// The arcs of a corner piece (one per non-empty segment).
fn arcs(piece: &Piece, out: &mut Vec<Primitive>) {
    let mut s = piece.start;
    for seg in &piece.segs {
        let d = seg.duration_s();
        let (a0, j) = seg.accel_and_jerk(s.a);
        if d > 0.0 {
            out.push(Primitive::Arc {
                p0: s.p,
                v0: s.v,
                a0,
                j,
                duration_s: d,
            });
        }
        s = s.advance(seg, d);
    }
}

/// Length of each segment used by the transition at a corner from the unit direction
/// `u_in` to `u_out` passed at speed `v` (m): none for a straight continuation or an exact
/// stop, half the velocity jump's travel for a junction, the blend's own distance.
pub(crate) fn corner_used(opts: &PathOptions, u_in: V3, u_out: V3, v: f64) -> f64 {
    if norm(sub(u_out, u_in)) == 0.0 {
        return 0.0;
    }
    match opts.corners {
        CornerStrategy::ExactStop => 0.0,
        CornerStrategy::Junction(_) => 0.5 * v * opts.velocity_jump_s,
        CornerStrategy::Blend { .. } => {
            let (amax, jmax) = (opts.limits.amax(), opts.jmax());
            Blend::new([0.0; 3], u_in, u_out, v, amax, jmax)
                .shape
                .distance_m
        }
    }
}

/// The straight run from `from` along the unit direction `u`, `len` long, from speed `v0`
/// to `v1` under the speed law of `opts` with top speed `vmax` (m, m/s).
pub(crate) fn straight_piece(
    opts: &PathOptions,
    from: V3,
    u: V3,
    v0: f64,
    v1: f64,
    len: f64,
    vmax: f64,
) -> Piece {
    let segs = law::segment(opts.law.as_ref(), v0, v1, len, vmax)
        .iter()
        .map(|s| VSeg::along(s, u))
        .collect();
    Piece {
        start: VState {
            p: from,
            v: scale(u, v0),
            a: [0.0; 3],
        },
        segs,
    }
}

/// The transition at a sharp or blended corner `corner` between the unit directions `u`
/// (in) and `u_out`, passed at speed `v1` and using `d1` of each segment: its piece, what
/// kind of transition it is, and how far it deviates from the corner (m).
pub(crate) fn corner_piece(
    opts: &PathOptions,
    corner: V3,
    u: V3,
    u_out: V3,
    v1: f64,
    d1: f64,
) -> (Piece, CornerTransition, f64) {
    let (amax, jmax, tj) = (opts.limits.amax(), opts.jmax(), opts.velocity_jump_s);
    match opts.corners {
        CornerStrategy::Blend { .. } => {
            let b = Blend::new(corner, u, u_out, v1, amax, jmax);
            let segs = b
                .shape
                .normal_segments(jmax)
                .iter()
                .map(|s| VSeg::along(s, b.e_n))
                .collect();
            let start = VState {
                p: b.entry(),
                v: scale(u, v1),
                a: [0.0; 3],
            };
            let tr = CornerTransition::Blend {
                case: b.shape.case,
                distance_m: b.shape.distance_m,
                duration_s: b.shape.duration_s,
            };
            (Piece { start, segs }, tr, b.shape.deviation_m)
        }
        _ => {
            let dv = sub(scale(u_out, v1), scale(u, v1));
            let segs = vec![
                VSeg::Accel {
                    duration_s: tj,
                    accel: scale(dv, 1.0 / tj),
                },
                VSeg::Accel {
                    duration_s: 0.0,
                    accel: [0.0; 3],
                },
            ];
            let start = VState {
                p: axpy(corner, -d1, u),
                v: scale(u, v1),
                a: [0.0; 3],
            };
            let tr = CornerTransition::Jump {
                dv: norm(dv),
                duration_s: tj,
            };
            (Piece { start, segs }, tr, norm(dv) * tj / 8.0)
        }
    }
}

/// Plan a whole path at once (the look-ahead without appending).
pub fn plan_path(path: &Path, opts: &PathOptions) -> Result<Trajectory, PlanError> {
    Lookahead::new(path.clone(), opts.clone())?.plan()
}
