//! Exact arc geometry for G2/G3, from a centre offset I/J or a radius R, in the XY plane
//! (G17), or in the ZX (G18) or YZ (G19) plane where the dialect reads them ([`Plane`]).
//!
//! - Centre = start + (I, J); radius = |(I, J)|; the sweep runs from the start angle to the
//!   end point's angle, clockwise for G2 and counter-clockwise for G3, in (0, 2 pi]; an end
//!   point within 1e-6 mm of the start (Marlin's `NEAR`, `Marlin/src/core/macros.h`) makes
//!   a full circle.
//! - I/J arcs whose end point is off the circle: Klipper (`klippy/extras/gcode_arcs.py`),
//!   Marlin (`Marlin/src/gcode/motion/G2_G3.cpp`: "The given XY is not error-checked") and
//!   RepRapFirmware (`GCodes::DoArcMove`, `src/GCodes/GCodes.cpp`) do not check; they trace
//!   the start radius and jump to the end point at the last segment. This reader refuses
//!   an end radius that differs from the start radius by more than 0.005 mm and by more
//!   than either 0.1 % of the radius or 0.5 mm (grbl's rule, `grbl/gcode.c` in gnea/grbl);
//!   within that the arc keeps the start radius and its last point is the end point as
//!   written.
//! - R form: positive R takes the short arc (< 180 deg), negative R the long one, in both
//!   Marlin and RepRapFirmware. A radius shorter than half the chord is refused unless
//!   within RepRapFirmware's slack (`h^2 >= -0.02 R^2`: "allow the radius to be up to 1%
//!   too short"), where the arc becomes the half circle on the chord.

use std::f64::consts::{FRAC_PI_2, TAU};

/// End points closer than this make a full circle, mm (Marlin's `NEAR`).
pub const FULL_CIRCLE_TOLERANCE_MM: f64 = 1e-6;

/// The plane of an arc, as G17, G18 and G19 select it: its first and second axis (the
/// arc's angle turns from the first towards the second: counter-clockwise for G3 seen
/// from the positive side of the third) and the axis that moves linearly with the angle,
/// as GRBL takes them (grbl/gcode.c, "Set active plane": G18 is Z then X, linear Y; G19 Y
/// then Z, linear X).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// G17: X then Y, Z linear.
    #[default]
    Xy,
    /// G18: Z then X, Y linear.
    Zx,
    /// G19: Y then Z, X linear.
    Yz,
}

impl Plane {
    /// The indices (0 X, 1 Y, 2 Z) of the plane's first and second axis and of its
    /// linear axis.
    pub fn axes(self) -> [usize; 3] {
        match self {
            Plane::Xy => [0, 1, 2],
            Plane::Zx => [2, 0, 1],
            Plane::Yz => [1, 2, 0],
        }
    }

    /// The command that selects it.
    pub fn code(self) -> &'static str {
        match self {
            Plane::Xy => "G17",
            Plane::Zx => "G18",
            Plane::Yz => "G19",
        }
    }

    /// The offset words of its first and second axis (`I` X, `J` Y, `K` Z).
    pub fn offset_words(self) -> [u8; 2] {
        let [a, b, _] = self.axes();
        [b"IJK"[a], b"IJK"[b]]
    }
}

/// A circular arc in its [`Plane`] (XY unless the file selected another); the plane's
/// linear axis (Z in XY: a helix) and E change linearly with the angle. Centre and offsets
/// are along the plane's first and second axis (X and Y in the XY plane, Z and X in ZX,
/// Y and Z in YZ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// Centre along the plane's first axis (X in the XY plane), mm (machine frame).
    pub centre_x_mm: f64,
    /// Centre along the plane's second axis (Y in the XY plane), mm.
    pub centre_y_mm: f64,
    /// Centre minus start along the plane's first axis, mm (the I word in the XY plane,
    /// K in ZX, J in YZ; or derived from R).
    pub offset_i_mm: f64,
    /// Centre minus start along the plane's second axis, mm (the J word in the XY plane,
    /// I in ZX, K in YZ; or derived from R).
    pub offset_j_mm: f64,
    /// Radius at the start, mm.
    pub radius_mm: f64,
    /// Angle of the start point about the centre, rad (atan2 convention).
    pub start_angle_rad: f64,
    /// Signed sweep, rad: positive counter-clockwise (G3), negative clockwise (G2);
    /// `|sweep| = 2 pi` is a full circle.
    pub sweep_rad: f64,
    /// The R word as written, for arcs given in the R form.
    pub radius_word_mm: Option<f64>,
    /// The plane the arc lies in.
    pub plane: Plane,
}

/// Why an arc cannot be built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ArcProblem {
    NoCentre,
    RadiusMismatch { start_mm: f64, end_mm: f64 },
    RadiusTooSmall { radius_mm: f64, chord_mm: f64 },
    ZeroChord,
    ZeroSweep,
}

/// grbl's end-radius rule: differences up to this always pass, mm ...
pub const RADIUS_TOLERANCE_MM: f64 = 0.005;
/// ... larger ones fail when they exceed this fraction of the radius ...
pub const RADIUS_TOLERANCE_REL: f64 = 0.001;
/// ... or this absolute difference, mm.
pub const RADIUS_TOLERANCE_MAX_MM: f64 = 0.5;

impl Arc {
    /// An arc from `start` to `end` (along the plane's two axes, mm) about `start + (i,
    /// j)`, in the XY plane until [`Arc::in_plane`] says otherwise. `check_radius` applies
    /// the end-radius tolerance.
    pub(crate) fn from_offsets(
        start: [f64; 2],
        end: [f64; 2],
        i: f64,
        j: f64,
        clockwise: bool,
        check_radius: bool,
    ) -> Result<Arc, ArcProblem> {
        if i == 0.0 && j == 0.0 {
            return Err(ArcProblem::NoCentre);
        }
        let (cx, cy) = (start[0] + i, start[1] + j);
        let (rx, ry) = (-i, -j);
        let (tx, ty) = (end[0] - cx, end[1] - cy);
        let radius = rx.hypot(ry);
        if check_radius {
            let end_r = tx.hypot(ty);
            let diff = (end_r - radius).abs();
            if diff > RADIUS_TOLERANCE_MM
                && (diff > RADIUS_TOLERANCE_MAX_MM || diff > RADIUS_TOLERANCE_REL * radius)
            {
                return Err(ArcProblem::RadiusMismatch {
                    start_mm: radius,
                    end_mm: end_r,
                });
            }
        }
        let full = (end[0] - start[0]).abs() <= FULL_CIRCLE_TOLERANCE_MM
            && (end[1] - start[1]).abs() <= FULL_CIRCLE_TOLERANCE_MM;
        let sweep = if full {
            if clockwise { -TAU } else { TAU }
        } else {
            let angle = (rx * ty - ry * tx).atan2(rx * tx + ry * ty);
            if angle == 0.0 {
                return Err(ArcProblem::ZeroSweep);
            }
            match (clockwise, angle < 0.0) {
                (true, false) => angle - TAU,
                (false, true) => angle + TAU,
                _ => angle,
            }
        };
        Ok(Arc {
            centre_x_mm: cx,
            centre_y_mm: cy,
            offset_i_mm: i,
            offset_j_mm: j,
            radius_mm: radius,
            start_angle_rad: ry.atan2(rx),
            sweep_rad: sweep,
            radius_word_mm: None,
            plane: Plane::Xy,
        })
    }

    /// The same arc, its coordinates read as along `plane`'s axes.
    pub(crate) fn in_plane(self, plane: Plane) -> Arc {
        Arc { plane, ..self }
    }

    /// An arc from `start` to `end` with radius `r` (negative: the long way round).
    pub(crate) fn from_radius(
        start: [f64; 2],
        end: [f64; 2],
        r: f64,
        clockwise: bool,
    ) -> Result<Arc, ArcProblem> {
        let (dx, dy) = (end[0] - start[0], end[1] - start[1]);
        let d_sq = dx * dx + dy * dy;
        if d_sq == 0.0 {
            return Err(ArcProblem::ZeroChord);
        }
        let h_sq = r * r - d_sq / 4.0;
        let mut h_div_d = if h_sq >= 0.0 {
            (h_sq / d_sq).sqrt()
        } else if h_sq < -0.02 * r * r {
            return Err(ArcProblem::RadiusTooSmall {
                radius_mm: r.abs(),
                chord_mm: d_sq.sqrt(),
            });
        } else {
            0.0
        };
        if (clockwise && r < 0.0) || (!clockwise && r > 0.0) {
            h_div_d = -h_div_d;
        }
        let i = dx / 2.0 + dy * h_div_d;
        let j = dy / 2.0 - dx * h_div_d;
        let mut arc = Arc::from_offsets(start, end, i, j, clockwise, false)?;
        arc.radius_word_mm = Some(r);
        Ok(arc)
    }

    /// Whether the arc turns clockwise (G2).
    pub fn clockwise(&self) -> bool {
        self.sweep_rad < 0.0
    }

    /// Whether the arc is a full circle.
    pub fn is_full_circle(&self) -> bool {
        self.sweep_rad.abs() == TAU
    }

    /// Exact length of the (helical) path with travel `dz_mm` along the plane's linear
    /// axis (Z in the XY plane), mm.
    pub fn length_mm(&self, dz_mm: f64) -> f64 {
        (self.radius_mm * self.sweep_rad.abs()).hypot(dz_mm)
    }

    /// The angle a fraction `s` of the way along, rad.
    pub fn angle_at(&self, s: f64) -> f64 {
        self.start_angle_rad + self.sweep_rad * s
    }

    /// The position along the plane's two axes (XY in the XY plane) a fraction `s` of the
    /// way along, mm.
    pub(crate) fn xy_at(&self, s: f64) -> (f64, f64) {
        let (sin, cos) = self.angle_at(s).sin_cos();
        (
            self.centre_x_mm + self.radius_mm * cos,
            self.centre_y_mm + self.radius_mm * sin,
        )
    }

    /// The points (along the plane's two axes, mm: X, Y in the XY plane) where the arc
    /// reaches an extreme of either axis: the quadrant points it passes, in the order +X,
    /// +Y, -X, -Y (first axis, second, in the XY plane's names).
    pub(crate) fn extremes_xy(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        let (cx, cy, r) = (self.centre_x_mm, self.centre_y_mm, self.radius_mm);
        let quadrants = [(cx + r, cy), (cx, cy + r), (cx - r, cy), (cx, cy - r)];
        quadrants
            .into_iter()
            .enumerate()
            .filter_map(move |(k, (x, y))| {
                let theta = k as f64 * FRAC_PI_2;
                let ahead = if self.clockwise() {
                    (self.start_angle_rad - theta).rem_euclid(TAU)
                } else {
                    (theta - self.start_angle_rad).rem_euclid(TAU)
                };
                (ahead <= self.sweep_rad.abs()).then_some([x, y])
            })
    }
}
