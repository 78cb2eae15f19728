//! The firmware planners behind one interface, and the limit commands each applies.
//!
//! Limit changes take effect for the moves queued after them; moves already queued keep
//! theirs, as in every firmware (Klipper's `SET_VELOCITY_LIMIT`, Marlin's and
//! RepRapFirmware's M201/M203/M204/M205/M566 change the settings new moves are planned
//! with). A command of another firmware's dialect, or one a firmware reads but this model
//! does not simulate, is counted as ignored with the reason.

use settle_planner::PlanError;
use settle_planner::firmware::grbl::GrblPlanner;
use settle_planner::firmware::klipper::KlipperPlanner;
use settle_planner::firmware::marlin::{MarlinJerk, MarlinPlanner};
use settle_planner::firmware::rrf::RrfPlanner;
use settle_planner::firmware::{FirmwarePlanner, PlannedMove};

use super::config::PlannerConfig;
use crate::read::limits::{AxisValues, LimitChange};

/// Millimetres (and mm/s, mm/s^2) to metres.
const MM: f64 = 1e-3;

/// What a limit command did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LimitOutcome {
    /// The planner's settings changed.
    Applied,
    /// Nothing changed, for this reason.
    Ignored(&'static str),
    /// Nothing changed: every value was dropped, each with its note.
    Dropped,
}

/// Marlin's `M205 J` range: it keeps its junction deviation and answers "?J out of range
/// (0.01 to 0.3)" for any other (Marlin/src/gcode/config/M200-M205.cpp), mm.
pub(crate) const MARLIN_JUNCTION_DEVIATION_MM: std::ops::RangeInclusive<f64> = 0.01..=0.3;

use crate::config::RRF_MINIMUM_ACCEL_MM_S2;

/// RepRapFirmware's least minimum movement speed, mm/s (`AbsoluteMinFeedrate`,
/// src/Config/Configuration.h; `Platform::SetMinMovementSpeed`, src/Platform/Platform.h).
pub(crate) const RRF_ABSOLUTE_MIN_SPEED_MM_S: f64 = 0.01;

const MARLIN_J_OUT_OF_RANGE: &str = "J outside 0.01 to 0.3 mm is refused by Marlin, which keeps its junction deviation (\"?J out of range\", Marlin/src/gcode/config/M200-M205.cpp)";
const MARLIN_JERK_IN_JD_BUILD: &str = "X Y Z E (classic jerk) are read only by a Marlin built with CLASSIC_JERK; this one uses junction deviation (Marlin/src/gcode/config/M200-M205.cpp)";
const MARLIN_J_IN_CLASSIC_BUILD: &str = "J (junction deviation) is not read by a Marlin built with CLASSIC_JERK (Marlin/src/gcode/config/M200-M205.cpp)";
const KLIPPER_ACCEL_TO_DECEL: &str = "ACCEL_TO_DECEL is not read: Klipper removed it on 2025-08-11 (docs/Config_Changes.md) and keeps its minimum_cruise_ratio; an older Klipper planned as with minimum_cruise_ratio = 1 - min(1, ACCEL_TO_DECEL / ACCEL) (give that as minimum_cruise_ratio in --config to plan as it did)";
const MARLIN_XY_FREQUENCY: &str = "F and S (the XY frequency limit) are read only by a Marlin built with XY_FREQUENCY_LIMIT, off in its example configuration (Marlin/src/gcode/config/M200-M205.cpp); not modelled";
const RRF_ACCEL_RAISED: &str = "an acceleration below 0.1 mm/s^2 runs at 0.1, RepRapFirmware's least (MinimumAcceleration, src/Config/Configuration.h; Platform::SetAcceleration, GCodes::ConfigureAccelerations)";
const RRF_MIN_SPEED_RAISED: &str = "I below 0.01 mm/s runs at 0.01, RepRapFirmware's least (AbsoluteMinFeedrate, src/Config/Configuration.h; Platform::SetMinMovementSpeed)";
const RRF_MAX_SPEED_RAISED: &str = "a maximum speed below the minimum movement speed (M203 I, 0.5 mm/s unless set) runs at that speed (Platform::SetMaxFeedrate, src/Platform/Platform.h)";

/// One of the firmware planners.
#[derive(Debug)]
pub(crate) enum Driver {
    Klipper(Box<KlipperPlanner>),
    Marlin(Box<MarlinPlanner>),
    Rrf(Box<RrfPlanner>),
    Grbl(Box<GrblPlanner>),
}

impl Driver {
    /// The planner of `cfg` (`None` for settle's planner, which is not a firmware).
    pub(crate) fn new(cfg: &PlannerConfig) -> Result<Option<Self>, PlanError> {
        Ok(Some(match cfg {
            PlannerConfig::Klipper(c) => Driver::Klipper(Box::new(KlipperPlanner::new(*c)?)),
            PlannerConfig::Marlin(c) | PlannerConfig::Prusa(c) => {
                Driver::Marlin(Box::new(MarlinPlanner::new(*c)?))
            }
            PlannerConfig::Rrf(c) => Driver::Rrf(Box::new(RrfPlanner::new(*c)?)),
            PlannerConfig::Grbl(s) => Driver::Grbl(Box::new(GrblPlanner::new(s.planner())?)),
            PlannerConfig::Settle(_) => return Ok(None),
        }))
    }

    /// The planner.
    pub(crate) fn planner(&mut self) -> &mut dyn FirmwarePlanner {
        match self {
            Driver::Klipper(p) => p.as_mut(),
            Driver::Marlin(p) => p.as_mut(),
            Driver::Rrf(p) => p.as_mut(),
            Driver::Grbl(p) => p.as_mut(),
        }
    }

    /// The print clock (s).
    pub(crate) fn print_time_s(&self) -> f64 {
        match self {
            Driver::Klipper(p) => p.print_time_s(),
            Driver::Marlin(p) => p.print_time_s(),
            Driver::Rrf(p) => p.print_time_s(),
            Driver::Grbl(p) => p.print_time_s(),
        }
    }

    /// The limits a file's commands change, by the firmware's name for them, in mm
    /// units (mm/s, mm/s^2): what [`crate::job::JobSummary::overrides`] compares with the
    /// configuration's.
    pub(crate) fn limits(&self) -> Vec<(&'static str, f64)> {
        let mm = |v: f64| v / MM;
        match self {
            Driver::Klipper(p) => {
                let c = p.config();
                vec![
                    ("max_velocity (mm/s)", mm(c.max_velocity_m_s)),
                    ("max_accel (mm/s^2)", mm(c.max_accel_m_s2)),
                    (
                        "square_corner_velocity (mm/s)",
                        mm(c.square_corner_velocity_m_s),
                    ),
                ]
            }
            Driver::Marlin(p) => {
                let c = p.config();
                m20x(
                    [c.print_accel_m_s2, c.travel_accel_m_s2],
                    &c.max_accel_m_s2,
                    &c.max_feedrate_m_s,
                )
            }
            Driver::Rrf(p) => {
                let c = p.config();
                m20x(
                    [c.print_accel_m_s2, c.travel_accel_m_s2],
                    &c.max_accel_m_s2,
                    &c.max_feedrate_m_s,
                )
            }
            Driver::Grbl(p) => {
                let c = p.config();
                vec![
                    ("$110 (mm/min)", c.max_rate_m_s[0] * 60e3),
                    ("$111 (mm/min)", c.max_rate_m_s[1] * 60e3),
                    ("$120 (mm/s^2)", mm(c.accel_m_s2[0])),
                    ("$121 (mm/s^2)", mm(c.accel_m_s2[1])),
                ]
            }
        }
    }

    /// Take the next planned move.
    pub(crate) fn pop(&mut self) -> Option<PlannedMove> {
        self.planner().pop()
    }

    /// Apply a limit command for the moves queued from now on. A value the firmware
    /// refuses, does not read or raises to its least is dropped or raised as the firmware
    /// does, and `notes` gets what was done (the list of commands not followed).
    pub(crate) fn apply(
        &mut self,
        change: &LimitChange,
        notes: &mut Vec<&'static str>,
    ) -> Result<LimitOutcome, PlanError> {
        const OTHER: LimitOutcome = LimitOutcome::Ignored("not a command of this firmware");
        match self {
            Driver::Klipper(p) => match change {
                LimitChange::VelocityLimit {
                    velocity_mm_s,
                    accel_mm_s2,
                    accel_to_decel_mm_s2,
                    square_corner_velocity_mm_s,
                    minimum_cruise_ratio,
                } => {
                    let mm = |v: &Option<f64>| v.map(|x| x * MM);
                    if velocity_mm_s.is_none()
                        && accel_mm_s2.is_none()
                        && square_corner_velocity_mm_s.is_none()
                        && minimum_cruise_ratio.is_none()
                    {
                        return Ok(LimitOutcome::Ignored(if accel_to_decel_mm_s2.is_some() {
                            KLIPPER_ACCEL_TO_DECEL
                        } else {
                            "nothing to change"
                        }));
                    }
                    if accel_to_decel_mm_s2.is_some() {
                        notes.push(KLIPPER_ACCEL_TO_DECEL);
                    }
                    p.set_velocity_limit(
                        mm(velocity_mm_s),
                        mm(accel_mm_s2),
                        mm(square_corner_velocity_mm_s),
                        *minimum_cruise_ratio,
                    )?;
                    Ok(LimitOutcome::Applied)
                }
                LimitChange::InputShaper { .. } => Ok(LimitOutcome::Applied),
                _ => Ok(OTHER),
            },
            Driver::Marlin(p) => {
                let mut c = *p.config();
                match change {
                    LimitChange::MaxAccel {
                        per_axis_mm_s2,
                        xy_frequency_limit_hz,
                        xy_frequency_min_speed_pct,
                    } => {
                        if xy_frequency_limit_hz.is_some() || xy_frequency_min_speed_pct.is_some() {
                            notes.push(MARLIN_XY_FREQUENCY);
                            if per_axis_mm_s2 == &AxisValues::default() {
                                return Ok(LimitOutcome::Dropped);
                            }
                        }
                        set_axes(&mut c.max_accel_m_s2, per_axis_mm_s2);
                    }
                    LimitChange::MaxFeedrate { per_axis_mm_s, .. } => {
                        set_axes(&mut c.max_feedrate_m_s, per_axis_mm_s);
                    }
                    LimitChange::Accel {
                        print_mm_s2,
                        travel_mm_s2,
                        retract_mm_s2,
                    } => {
                        set(&mut c.print_accel_m_s2, print_mm_s2);
                        set(&mut c.travel_accel_m_s2, travel_mm_s2);
                        set(&mut c.retract_accel_m_s2, retract_mm_s2);
                    }
                    LimitChange::MarlinAdvanced {
                        junction_deviation_mm,
                        jerk_mm_s,
                        min_feedrate_mm_s,
                        min_travel_feedrate_mm_s,
                        min_segment_time_s,
                    } => {
                        // A Marlin build has either junction deviation (`J`) or classic
                        // jerk (`X Y Z E`); M205 reads only its own.
                        let jerk_given = jerk_mm_s != &AxisValues::default();
                        let mut jerk_applied = false;
                        match &mut c.jerk {
                            MarlinJerk::JunctionDeviation { deviation_m, .. } => {
                                match junction_deviation_mm {
                                    Some(j) if MARLIN_JUNCTION_DEVIATION_MM.contains(j) => {
                                        set(deviation_m, junction_deviation_mm);
                                        jerk_applied = true;
                                    }
                                    Some(_) => notes.push(MARLIN_J_OUT_OF_RANGE),
                                    None => {}
                                }
                                if jerk_given {
                                    notes.push(MARLIN_JERK_IN_JD_BUILD);
                                }
                            }
                            MarlinJerk::Classic { max_jerk_m_s, .. } => {
                                set_axes(max_jerk_m_s, jerk_mm_s);
                                jerk_applied = jerk_given;
                                if junction_deviation_mm.is_some() {
                                    notes.push(MARLIN_J_IN_CLASSIC_BUILD);
                                }
                            }
                        }
                        if !jerk_applied
                            && min_feedrate_mm_s.is_none()
                            && min_travel_feedrate_mm_s.is_none()
                            && min_segment_time_s.is_none()
                        {
                            return Ok(LimitOutcome::Dropped);
                        }
                        set(&mut c.min_feedrate_m_s, min_feedrate_mm_s);
                        set(&mut c.min_travel_feedrate_m_s, min_travel_feedrate_mm_s);
                        if let Some(b) = min_segment_time_s {
                            c.min_segment_time_s = *b;
                        }
                    }
                    LimitChange::MarlinInputShaping { .. } | LimitChange::FtMotion { .. } => {
                        return Ok(LimitOutcome::Applied);
                    }
                    LimitChange::PrusaInputShaping { save, .. } => {
                        return Ok(LimitOutcome::Ignored(if *save {
                            "W saves the input shaper to EEPROM; A and M, the weight adjustment M74 makes to Y's shaper, are not modelled"
                        } else {
                            "A and M (the weight adjustment M74 makes to Y's shaper) are not modelled"
                        }));
                    }
                    LimitChange::FtSmoothing { .. } => {
                        return Ok(LimitOutcome::Ignored(
                            "FT_MOTION trajectory smoothing (M494) is not modelled",
                        ));
                    }
                    _ => return Ok(OTHER),
                }
                p.set_config(c)?;
                Ok(LimitOutcome::Applied)
            }
            Driver::Rrf(p) => {
                let mut c = *p.config();
                // A value RepRapFirmware raises to its least, raised, with a note.
                let mut raise = |v: &Option<f64>, least_mm: f64, note: &'static str| {
                    v.map(|v| {
                        if v < least_mm {
                            if !notes.contains(&note) {
                                notes.push(note);
                            }
                            least_mm
                        } else {
                            v
                        }
                    })
                };
                match change {
                    LimitChange::MaxAccel { per_axis_mm_s2, .. } => {
                        let raised = per_axis_mm_s2
                            .map(|v| raise(v, RRF_MINIMUM_ACCEL_MM_S2, RRF_ACCEL_RAISED));
                        set_axes(&mut c.max_accel_m_s2, &raised);
                    }
                    LimitChange::MaxFeedrate {
                        per_axis_mm_s,
                        min_speed_mm_s,
                    } => {
                        // `M203` sets the minimum first and keeps every maximum at least
                        // that (src/GCodes/GCodes2.cpp case 203).
                        let min = raise(
                            min_speed_mm_s,
                            RRF_ABSOLUTE_MIN_SPEED_MM_S,
                            RRF_MIN_SPEED_RAISED,
                        );
                        set(&mut c.min_movement_speed_m_s, &min);
                        let least = c.min_movement_speed_m_s / MM;
                        let raised = per_axis_mm_s.map(|v| raise(v, least, RRF_MAX_SPEED_RAISED));
                        set_axes(&mut c.max_feedrate_m_s, &raised);
                    }
                    LimitChange::Accel {
                        print_mm_s2,
                        travel_mm_s2,
                        ..
                    } => {
                        let least = RRF_MINIMUM_ACCEL_MM_S2;
                        set(
                            &mut c.print_accel_m_s2,
                            &raise(print_mm_s2, least, RRF_ACCEL_RAISED),
                        );
                        set(
                            &mut c.travel_accel_m_s2,
                            &raise(travel_mm_s2, least, RRF_ACCEL_RAISED),
                        );
                    }
                    // `M205` sets the printing moves' jerk below the `M566` limit; this
                    // model has one jerk per axis (the limit), so it is not applied.
                    LimitChange::RrfJerk {
                        sets_maximum: false,
                        ..
                    } => {
                        return Ok(LimitOutcome::Ignored(
                            "M205 (printing-move jerk below the M566 limit) is not modelled",
                        ));
                    }
                    LimitChange::RrfJerk {
                        per_axis_mm_s,
                        policy,
                        sets_maximum: true,
                    } => {
                        set_axes(&mut c.instant_dv_m_s, per_axis_mm_s);
                        // RepRapFirmware keeps every jerk at least its minimum.
                        for j in &mut c.instant_dv_m_s {
                            *j = j.max(crate::config::RRF_MINIMUM_JERK_MM_S * MM);
                        }
                        if let Some(p) = policy {
                            c.jerk_policy = *p;
                        }
                    }
                    LimitChange::RrfInputShaping { .. } => return Ok(LimitOutcome::Applied),
                    _ => return Ok(OTHER),
                }
                p.set_config(c)?;
                Ok(LimitOutcome::Applied)
            }
            // GRBL's settings are `$` lines ([`crate::Setting::Grbl`]), not M-codes.
            Driver::Grbl(_) => Ok(OTHER),
        }
    }
}

/// Marlin's and RepRapFirmware's limits by name (mm units): `M204 P`/`T`, `M201` and
/// `M203` of X and Y.
fn m20x(accel: [f64; 2], max_accel: &[f64; 4], max_feed: &[f64; 4]) -> Vec<(&'static str, f64)> {
    vec![
        ("M204 P print acceleration (mm/s^2)", accel[0] / MM),
        ("M204 T travel acceleration (mm/s^2)", accel[1] / MM),
        ("M201 X (mm/s^2)", max_accel[0] / MM),
        ("M201 Y (mm/s^2)", max_accel[1] / MM),
        ("M203 X (mm/s)", max_feed[0] / MM),
        ("M203 Y (mm/s)", max_feed[1] / MM),
    ]
}

/// Set `to` from a value in mm units, if given.
fn set(to: &mut f64, from: &Option<f64>) {
    if let Some(v) = from {
        *to = v * MM;
    }
}

/// Set the X, Y, Z, E entries of `to` from values in mm units, where given.
fn set_axes(to: &mut [f64; 4], from: &AxisValues) {
    for (t, f) in to.iter_mut().zip([from.x, from.y, from.z, from.e]) {
        set(t, &f);
    }
}
