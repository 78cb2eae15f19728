//! The corner of a corner run: the `[corner]` table as written ([`CornerSpec`]), resolved
//! per run ([`Corner`], the study's state that the sweep sets through `corner.<key>`), its
//! geometry in the machine's coordinates and its checks against the run's machine.
//!
//! The geometry: the first segment (`leg_in_mm`) runs along the first path axis (`axes[0]`,
//! default `x`) into the corner point `corner_mm`; the second (`leg_out_mm`) leaves it
//! turning towards the second path axis by `180 - angle_deg` degrees. `angle_deg` is the
//! *interior* angle as drawn (the planner's convention, as in GRBL and Klipper): 180
//! straight on, 90 a square corner, 0 a full reversal.

use serde::Deserialize;
use settle_planner::path::junction::Junction;
use settle_planner::path::{CornerStrategy, Path, PathPoint};
use settle_planner::{PlanError, ProfileKind};

use crate::error::Error;
use crate::input::source::Source;
use crate::spec::run_spec::{StudyState, RunSpec};
use crate::spec::{MAX_POSITION_MM, beyond_positions};
use crate::spec::value::Value;

/// The `[corner]` table as written (mm, mm/s, degrees).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CornerSpec {
    /// Interior angle between the two segments (degrees, 0 to 180): 180 straight on, 90 a
    /// square corner, 0 a full reversal.
    pub angle_deg: f64,
    /// Length of the segment into the corner (mm), > 0.
    pub leg_in_mm: f64,
    /// Length of the segment out of the corner (mm), > 0.
    pub leg_out_mm: f64,
    /// The corner point, one coordinate per path axis (mm). Default the origin: the middle
    /// of the travel on the presets.
    #[serde(default, deserialize_with = "exactly")]
    pub corner_mm: [f64; 2],
    /// The machine axes of the path's two directions (default `["x", "y"]`): the first
    /// segment runs along `axes[0]`.
    #[serde(default = "default_axes", deserialize_with = "exactly")]
    pub axes: [String; 2],
    /// Profile kind of the straight runs (`trapezoid`, `scurve`, `fourjerk`); sweep
    /// `profile` to compare kinds.
    #[serde(default = "default_profile")]
    pub profile: String,
    /// How the corner is passed: `exact_stop`, `junction_deviation` (GRBL),
    /// `square_corner_velocity` (Klipper) or `blend` (a jerk-limited blend at constant speed).
    #[serde(default = "default_strategy")]
    pub strategy: String,
    /// GRBL junction deviation (mm). Default 0.01 mm: GRBL's `$11` default.
    #[serde(default = "default_junction_deviation")]
    pub junction_deviation_mm: f64,
    /// Klipper square corner velocity (mm/s). Default 5 mm/s: Klipper's default.
    #[serde(default = "default_scv")]
    pub square_corner_velocity_mm_s: f64,
    /// Largest distance the blend may keep from the sharp corner (mm). Default 0.05 mm: a
    /// typical path tolerance of CNC blending (e.g. LinuxCNC `G64 P0.05`), about half a
    /// printer's line width of 0.4 mm divided by 4.
    #[serde(default = "default_blend_deviation")]
    pub blend_deviation_mm: f64,
}

/// Exactly `N` values: serde reads the first `N` of a longer array into `[T; N]` and would
/// drop the rest (`corner_mm = [1, 2, 3]`).
fn exactly<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    let v = Vec::<T>::deserialize(d)?;
    let n = v.len();
    v.try_into()
        .map_err(|_| serde::de::Error::custom(format!("{n} values; give exactly {N}, one per path axis")))
}

fn default_axes() -> [String; 2] {
    ["x".to_string(), "y".to_string()]
}
fn default_profile() -> String {
    "scurve".to_string()
}
fn default_strategy() -> String {
    "exact_stop".to_string()
}
fn default_junction_deviation() -> f64 {
    0.01
}
fn default_scv() -> f64 {
    5.0
}
fn default_blend_deviation() -> f64 {
    0.05
}

/// How the corner is passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    /// Every axis stops on the corner.
    ExactStop,
    /// GRBL's junction deviation: a sharp corner at `v^2 = a d sin(t/2)/(1 - sin(t/2))`.
    JunctionDeviation,
    /// Klipper's square corner velocity (GRBL's formula with `d = scv^2 (sqrt 2 - 1)/a`,
    /// capped mid-move).
    SquareCornerVelocity,
    /// A jerk-limited blend at constant speed within `blend_deviation_mm` of the corner.
    Blend,
}

impl Strategy {
    /// Every strategy.
    pub const ALL: [Strategy; 4] = [
        Strategy::ExactStop,
        Strategy::JunctionDeviation,
        Strategy::SquareCornerVelocity,
        Strategy::Blend,
    ];
    /// Names accepted by [`Strategy::parse`].
    pub const ALLOWED: &'static str =
        "exact_stop, junction_deviation, square_corner_velocity, blend";

    /// The name as written in scenario files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::ExactStop => "exact_stop",
            Strategy::JunctionDeviation => "junction_deviation",
            Strategy::SquareCornerVelocity => "square_corner_velocity",
            Strategy::Blend => "blend",
        }
    }

    /// Parse a name.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown corner strategy `{name}`; allowed: {}",
                    Self::ALLOWED
                )
            })
    }
}

/// The corner of one run, resolved (scenario units).
#[derive(Debug, Clone, PartialEq)]
pub struct Corner {
    /// The profile kind named in `[corner]` (the sweep's `profile` overrides the run's).
    pub profile: String,
    /// Interior angle (degrees).
    pub angle_deg: f64,
    /// Segment into the corner (mm).
    pub leg_in_mm: f64,
    /// Segment out of the corner (mm).
    pub leg_out_mm: f64,
    /// The corner point (mm) along the two path axes.
    pub corner_mm: [f64; 2],
    /// The machine axes of the two path directions.
    pub axes: [String; 2],
    /// How the corner is passed.
    pub strategy: Strategy,
    /// GRBL junction deviation (mm).
    pub junction_deviation_mm: f64,
    /// Klipper square corner velocity (mm/s).
    pub square_corner_velocity_mm_s: f64,
    /// Blend tolerance (mm).
    pub blend_deviation_mm: f64,
}

impl Corner {
    /// Resolve the `[corner]` table (the strategy name is checked here).
    pub fn from_spec(spec: &CornerSpec, src: &Source) -> Result<Self, Error> {
        let strategy =
            Strategy::parse(&spec.strategy).map_err(|m| src.error_at("corner.strategy", m))?;
        Ok(Self {
            profile: spec.profile.clone(),
            angle_deg: spec.angle_deg,
            leg_in_mm: spec.leg_in_mm,
            leg_out_mm: spec.leg_out_mm,
            corner_mm: spec.corner_mm,
            axes: spec.axes.clone(),
            strategy,
            junction_deviation_mm: spec.junction_deviation_mm,
            square_corner_velocity_mm_s: spec.square_corner_velocity_mm_s,
            blend_deviation_mm: spec.blend_deviation_mm,
        })
    }

    /// The corner strategy in the planner's terms (SI units).
    pub fn strategy_si(&self) -> CornerStrategy {
        match self.strategy {
            Strategy::ExactStop => CornerStrategy::ExactStop,
            Strategy::JunctionDeviation => CornerStrategy::Junction(Junction::Grbl {
                deviation_m: self.junction_deviation_mm * 1e-3,
            }),
            Strategy::SquareCornerVelocity => CornerStrategy::Junction(Junction::Klipper {
                square_corner_velocity: self.square_corner_velocity_mm_s * 1e-3,
            }),
            Strategy::Blend => CornerStrategy::Blend {
                max_deviation_m: self.blend_deviation_mm * 1e-3,
            },
        }
    }

    /// The three points in the path's plane (mm): start, corner, end.
    pub fn points_mm(&self) -> [[f64; 2]; 3] {
        let [cx, cy] = self.corner_mm;
        let (cos, sin) = cos_sin_deg(180.0 - self.angle_deg);
        [
            [cx - self.leg_in_mm, cy],
            [cx, cy],
            [cx + self.leg_out_mm * cos, cy + self.leg_out_mm * sin],
        ]
    }

    /// The path in machine coordinates (m): one coordinate per machine axis (`names`, 2 or
    /// 3 of them), the axes off the path's plane at 0.
    pub fn path(&self, names: &[String]) -> Result<Path, PlanError> {
        let idx = |a: &str| names.iter().position(|n| n == a).unwrap_or(0);
        let (i, j) = (idx(&self.axes[0]), idx(&self.axes[1]));
        let place = |p: [f64; 2]| {
            let mut q = [0.0; 3];
            q[i] = p[0] * 1e-3;
            q[j] = p[1] * 1e-3;
            q
        };
        let [a, b, c] = self.points_mm();
        Path::new(
            names.len(),
            vec![
                PathPoint::waypoint(place(a)),
                PathPoint::control(place(b)),
                PathPoint::waypoint(place(c)),
            ],
        )
    }

    /// Check the corner against the run's machine; messages name the key to blame.
    pub fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        let key = |p: &str| {
            let swept = format!("corner.{p}");
            if run.swept.iter().any(|(q, _)| *q == swept) {
                format!("sweep.{swept}")
            } else {
                swept
            }
        };
        if !(self.angle_deg.is_finite() && (0.0..=180.0).contains(&self.angle_deg)) {
            return Err((
                key("angle_deg"),
                format!(
                    "must be an interior angle from 0 (reversal) to 180 (straight on) degrees, got {}",
                    self.angle_deg
                ),
            ));
        }
        for (p, x) in [("leg_in_mm", self.leg_in_mm), ("leg_out_mm", self.leg_out_mm)] {
            crate::spec::check_length(x, false).map_err(|m| (key(p), m))?;
        }
        // The deviations within [`crate::spec::DEVIATION_RANGE_MM`]; the square corner
        // velocity is a speed like the limits (Klipper's `square_corner_velocity` takes any
        // value >= 0, `ToolHead.__init__`, klippy/toolhead.py; 0 is `exact_stop` here).
        use crate::spec::Quantity::{Deviation, Speed};
        for (p, x, quantity) in [
            ("junction_deviation_mm", self.junction_deviation_mm, Deviation),
            (
                "square_corner_velocity_mm_s",
                self.square_corner_velocity_mm_s,
                Speed,
            ),
            ("blend_deviation_mm", self.blend_deviation_mm, Deviation),
        ] {
            crate::spec::check_limit(x, quantity).map_err(|m| (key(p), m))?;
        }
        if self.corner_mm.iter().any(|x| !x.is_finite()) {
            return Err((key("corner_mm"), "coordinates must be finite (mm)".into()));
        }
        // Every point within the positions f64 resolves (as a move's start and end).
        let points = self.points_mm();
        for k in [1, 0, 2] {
            if let Some(x) = points[k].iter().find(|x| x.abs() > MAX_POSITION_MM) {
                let what = ["start", "corner", "end"][k];
                return Err((
                    key(["leg_in_mm", "corner_mm", "leg_out_mm"][k]),
                    beyond_positions(&format!("the path's {what} point is"), *x),
                ));
            }
        }
        if matches!(run.profile, ProfileKind::PvtSym | ProfileKind::PvtAsym) {
            let key = if run.swept.iter().any(|(p, _)| p == "profile") {
                "sweep.profile"
            } else {
                "corner.profile"
            };
            return Err((
                key.into(),
                format!(
                    "`{}` is a point-to-point step, not a path speed law; corner paths take trapezoid, scurve or fourjerk",
                    run.profile
                ),
            ));
        }
        if matches!(run.profile, ProfileKind::SCurve | ProfileKind::FourJerk)
            && run.jmax_mm_s3.is_none()
        {
            return Err((
                "limits".into(),
                format!(
                    "profile kind `{}` needs `jmax_mm_s3` in [limits]",
                    run.profile
                ),
            ));
        }
        check_machine(self, &run.machine_name, &run.axis_names()).map_err(|m| (key("axes"), m))?;
        let Some(machine) = run.machine.physical() else {
            return Ok(());
        };
        // Every point inside every axis's belt travel.
        for (k, p) in self.points_mm().iter().enumerate() {
            for (axis, x) in self.axes.iter().zip(p) {
                if let Some((lo, hi)) = machine.axis(axis).and_then(|a| a.travel_m()) {
                    let (lo, hi) = (lo * 1e3, hi * 1e3);
                    if !(lo - 1e-9..=hi + 1e-9).contains(x) {
                        let what = ["start", "corner", "end"][k];
                        return Err((
                            key(if k == 0 {
                                "leg_in_mm"
                            } else if k == 1 {
                                "corner_mm"
                            } else {
                                "leg_out_mm"
                            }),
                            format!(
                                "the path's {what} point reaches {x:.3} mm on axis `{axis}`, outside its belt travel {lo:.1} to {hi:.1} mm"
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}

impl StudyState for Corner {
    fn table(&self) -> &'static str {
        "corner"
    }

    fn set(&mut self, param: &str, value: &Value) -> Result<(), String> {
        let num = || match value {
            Value::Number(x) => Ok(*x),
            _ => Err(format!("`corner.{param}` takes numbers")),
        };
        match param {
            "angle_deg" => self.angle_deg = num()?,
            "leg_in_mm" => self.leg_in_mm = num()?,
            "leg_out_mm" => self.leg_out_mm = num()?,
            "junction_deviation_mm" => self.junction_deviation_mm = num()?,
            "square_corner_velocity_mm_s" => self.square_corner_velocity_mm_s = num()?,
            "blend_deviation_mm" => self.blend_deviation_mm = num()?,
            "strategy" => match value {
                Value::Text(name) => self.strategy = Strategy::parse(name)?,
                _ => return Err("`corner.strategy` takes strategy names".into()),
            },
            _ => {
                return Err(format!(
                    "`corner.{param}` cannot be swept; allowed: {}",
                    super::SWEEPABLE
                ));
            }
        }
        Ok(())
    }
}

/// `(cos, sin)` of an angle in degrees, exact at multiples of 90 degrees (so that a
/// 0-degree corner is an exact reversal and 90 degrees an exact square, not off by 1e-16).
fn cos_sin_deg(deg: f64) -> (f64, f64) {
    if deg.rem_euclid(90.0) == 0.0 {
        match (deg.rem_euclid(360.0) / 90.0) as u8 {
            0 => (1.0, 0.0),
            1 => (0.0, 1.0),
            2 => (-1.0, 0.0),
            _ => (0.0, -1.0),
        }
    } else {
        let r = deg.to_radians();
        (r.cos(), r.sin())
    }
}

fn check_machine(c: &Corner, machine_name: &str, names: &[String]) -> Result<(), String> {
    if !(2..=3).contains(&names.len()) {
        return Err(format!(
            "a corner path needs a machine with 2 or 3 axes (a preset such as `printer_xy`, or [machine.axis.<name>] modes for two axes); `{machine_name}` has {}",
            names.len()
        ));
    }
    for a in &c.axes {
        if !names.contains(a) {
            return Err(format!(
                "no axis `{a}`; the machine has {}",
                names.join(", ")
            ));
        }
    }
    if c.axes[0] == c.axes[1] {
        return Err(format!(
            "the two path axes must differ, got `{}` twice",
            c.axes[0]
        ));
    }
    Ok(())
}
