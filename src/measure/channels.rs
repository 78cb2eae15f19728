//! The channels a run records, per axis and for the whole run ([`channels`]), and what
//! each axis has ([`AxisMeta`]): what a recorded series holds, and what a run's kept trace
//! costs per sample (`crate::expand::validate::check_run_size`).

use settle_planner::Sample;
use settle_sim::{AxisModel, DriverMode, Observation};

/// A per-axis channel of a recording: its name (the axis's is appended: `cmd_p_x`), its
/// unit, and its value from the command and the observation of the axis.
pub(crate) type Column = (&'static str, &'static str, fn(&Sample, &Observation) -> f64);

/// The channels every axis records: the command, the toolhead and its error (toolhead -
/// command).
const COMMON: [Column; 6] = [
    ("cmd_p", "m", |c, _| c.p),
    ("cmd_v", "m_s", |c, _| c.v),
    ("cmd_a", "m_s2", |c, _| c.a),
    ("cmd_j", "m_s3", |c, _| c.j),
    ("toolhead", "m", |_, o| o.toolhead_m),
    ("error", "m", |_, o| o.toolhead_m - o.commanded_m),
];

/// The carriage's channel (m), where the model has a carriage.
const CARRIAGE: Column = ("carriage", "m", |_, o| o.carriage_m.unwrap_or(f64::NAN));

/// The motor's channels (rad; the load angle in electrical rad), where it has a stepper.
const MOTOR: [Column; 2] = [
    ("motor_angle", "rad", |_, o| {
        o.motor_angle_rad.unwrap_or(f64::NAN)
    }),
    ("load_angle", "rad", |_, o| {
        o.load_angle_rad.unwrap_or(f64::NAN)
    }),
];

/// The phase currents (A), for the full driver model.
const CURRENTS: [Column; 2] = [
    ("current_a", "A", |_, o| {
        o.currents_a.map_or(f64::NAN, |c| c[0])
    }),
    ("current_b", "A", |_, o| {
        o.currents_a.map_or(f64::NAN, |c| c[1])
    }),
];

/// The channels [`crate::execute::execute`] records for these axes: per axis `cmd_p_<axis>` (m),
/// `cmd_v_<axis>` (m/s), `cmd_a_<axis>` (m/s^2), `cmd_j_<axis>` (m/s^3), `toolhead_<axis>`
/// (m), `error_<axis>` (toolhead - command, m) and, where the model has them,
/// `carriage_<axis>` (m), `motor_angle_<axis>` (rad), `load_angle_<axis>` (electrical
/// rad), `current_a_<axis>`, `current_b_<axis>` (A, full driver); then `error` (length of
/// the toolhead-minus-command vector, m).
pub fn channels(axes: &[AxisModel]) -> Vec<(String, String)> {
    let mut ch = Vec::new();
    for a in axes {
        for (c, u, _) in AxisMeta::of(a).columns {
            ch.push((format!("{c}_{}", a.name), u.to_string()));
        }
    }
    ch.push(("error".into(), "m".into()));
    ch
}

/// The channels an axis records, in order ([`channels`]).
#[derive(Debug, Clone)]
pub struct AxisMeta {
    pub(crate) columns: Vec<Column>,
}

impl AxisMeta {
    /// What `axis` has.
    pub fn of(axis: &AxisModel) -> Self {
        let mut columns = COMMON.to_vec();
        if axis.carriage.is_some() {
            columns.push(CARRIAGE);
        }
        if axis.stepper.is_some() {
            columns.extend(MOTOR);
        }
        if axis.mode == DriverMode::Full {
            columns.extend(CURRENTS);
        }
        Self { columns }
    }
}
