//! What a job plans with: the firmware, its starting configuration, the input shapers and
//! how arcs are cut, as plain data (the harness fills it from a machine or preset, or from
//! an imported printer.cfg / config.g).

use std::fmt;
use std::str::FromStr;

use settle_planner::firmware::Kinematics;
use settle_planner::firmware::klipper::KlipperConfig;
use settle_planner::firmware::marlin::MarlinConfig;
use settle_planner::firmware::profiles::ProfileOptions;
use settle_planner::firmware::rrf::RrfConfig;
use settle_planner::path::junction::Junction;
use settle_planner::path::{CornerStrategy, PathOptions};
use settle_planner::shaper::stream::Alignment;
use settle_planner::shaper::{Shaper, ShaperKind};
use settle_planner::{Limits, PlanError, ProfileKind};

use crate::{ArcSegmentation, Dialect, GcodeError};

/// Whose planner runs the job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Firmware {
    /// Klipper's toolhead planner.
    Klipper,
    /// Marlin's planner and stepper.
    Marlin,
    /// RepRapFirmware's planner.
    Rrf,
    /// settle's own jerk-limited look-ahead ([`settle_planner::path`]).
    Settle,
}

impl Firmware {
    /// Every firmware, in a fixed order.
    pub const ALL: [Firmware; 4] = [
        Firmware::Klipper,
        Firmware::Marlin,
        Firmware::Rrf,
        Firmware::Settle,
    ];

    /// The name on the command line (`klipper`, `marlin`, `rrf`, `settle`).
    pub fn name(self) -> &'static str {
        match self {
            Firmware::Klipper => "klipper",
            Firmware::Marlin => "marlin",
            Firmware::Rrf => "rrf",
            Firmware::Settle => "settle",
        }
    }

    /// The G-code dialect a file for this firmware is read in (settle's planner reads
    /// Marlin-flavoured G-code unless told otherwise: most slicers write it).
    pub fn dialect(self) -> Dialect {
        match self {
            Firmware::Klipper => Dialect::Klipper,
            Firmware::Marlin | Firmware::Settle => Dialect::Marlin,
            Firmware::Rrf => Dialect::Rrf,
        }
    }
}

impl fmt::Display for Firmware {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Firmware {
    type Err = GcodeError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "klipper" => Ok(Firmware::Klipper),
            "marlin" => Ok(Firmware::Marlin),
            "rrf" | "reprapfirmware" | "duet" => Ok(Firmware::Rrf),
            "settle" => Ok(Firmware::Settle),
            _ => Err(GcodeError::JobSetting {
                key: "firmware",
                reason: format!("unknown firmware `{s}` (allowed: klipper, marlin, rrf, settle)"),
            }),
        }
    }
}

/// An input shaper on one axis: which, and the mode it is tuned to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaperSetting {
    /// The shaper (bare names are Klipper's, `marlin:` and `rrf:` the other firmwares').
    pub kind: ShaperKind,
    /// Frequency it is tuned to (Hz).
    pub frequency_hz: f64,
    /// Damping ratio it is tuned to.
    pub damping_ratio: f64,
}

impl ShaperSetting {
    /// The shaper's impulses (its firmware's checks apply).
    pub fn build(&self) -> Result<Shaper, PlanError> {
        Shaper::new(self.kind, self.frequency_hz, self.damping_ratio)
    }
}

/// settle's own planner: its limits, speed law, corner strategy and look-ahead window.
#[derive(Debug, Clone)]
pub struct SettleConfig {
    /// Vector limits of the toolhead (m/s, m/s^2, m/s^3); each move's feed rate lowers
    /// `vmax` for that move.
    pub limits: Limits,
    /// The speed law of the straight runs.
    pub kind: ProfileKind,
    /// How corners are passed.
    pub corners: CornerStrategy,
    /// Points held in the look-ahead window (>= 3). 256 points of 0.5 mm is 12.8 cm,
    /// enough to stop from 300 mm/s at 3000 mm/s^2 (1.5 cm) many times over.
    pub window_points: usize,
}

impl SettleConfig {
    /// 300 mm/s, 3000 mm/s^2, 100 m/s^3 (the jerk of settle's corner scenarios), S-curve
    /// runs, Klipper's corner rule at 5 mm/s, a window of 256 points.
    pub fn new() -> Result<Self, PlanError> {
        Ok(Self {
            limits: Limits::new(0.3, 3.0, Some(100.0))?,
            kind: ProfileKind::SCurve,
            corners: CornerStrategy::Junction(Junction::Klipper {
                square_corner_velocity: 5e-3,
            }),
            window_points: 256,
        })
    }

    /// The path options these settings make.
    pub fn path_options(&self) -> Result<PathOptions, PlanError> {
        PathOptions::new(self.limits, self.kind, self.corners)
    }
}

/// The planner and its starting configuration (SI units: m, s).
#[derive(Debug, Clone)]
pub enum PlannerConfig {
    /// Klipper's `[printer]` settings.
    Klipper(KlipperConfig),
    /// Marlin's Configuration.h settings.
    Marlin(MarlinConfig),
    /// RepRapFirmware's config.g settings.
    Rrf(RrfConfig),
    /// settle's planner.
    Settle(SettleConfig),
}

impl PlannerConfig {
    /// Which firmware.
    pub fn firmware(&self) -> Firmware {
        match self {
            PlannerConfig::Klipper(_) => Firmware::Klipper,
            PlannerConfig::Marlin(_) => Firmware::Marlin,
            PlannerConfig::Rrf(_) => Firmware::Rrf,
            PlannerConfig::Settle(_) => Firmware::Settle,
        }
    }
}

/// Everything a job plans with.
#[derive(Debug, Clone)]
pub struct JobConfig {
    /// The planner and its settings at the start of the file.
    pub planner: PlannerConfig,
    /// The dialect the file is read in.
    pub dialect: Dialect,
    /// Input shapers on X, Y, Z at the start of the file (`None`: not shaped). The file's
    /// own shaper commands change them (see [`crate::job`]).
    pub shapers: [Option<ShaperSetting>; 3],
    /// Where the impulses sit ([`Alignment::Centred`]: shaped motion keeps the commanded
    /// timing, as Klipper and Marlin's FT_MOTION arrange).
    pub alignment: Alignment,
    /// How arcs are cut into straight moves.
    pub arcs: ArcSegmentation,
    /// How planned moves become profiles.
    pub profiles: ProfileOptions,
    /// Klipper: the least step-generation flush delay (s) besides the shapers', the
    /// larger of `SDS_CHECK_TIME` (1 ms, klippy/extras/motion_queuing.py) and half the
    /// extruder's `pressure_advance_smooth_time` when pressure advance is on (0.020 s for
    /// the default 0.040 s; off by default). It sets the pause a `SET_INPUT_SHAPER` makes.
    pub klipper_flush_delay_s: f64,
}

impl JobConfig {
    /// The firmware's defaults (no input shaping: every firmware ships with it off):
    /// - Klipper: `max_velocity` 500 mm/s, `max_accel` 3000 mm/s^2, `max_z_velocity`
    ///   25 mm/s, `max_z_accel` 30 mm/s^2 (Klipper requires these in printer.cfg; these are
    ///   its config/example-cartesian.cfg) and Klipper's defaults for the rest
    ///   ([`KlipperConfig::new`]);
    /// - Marlin: [`MarlinConfig::new`] (its example configuration);
    /// - RepRapFirmware: [`RrfConfig::new`] (Configuration.h);
    /// - settle: [`SettleConfig::new`].
    pub fn defaults(firmware: Firmware) -> Result<Self, GcodeError> {
        let planner = match firmware {
            Firmware::Klipper => {
                let mut c = KlipperConfig::new(0.5, 3.0);
                c.max_z_velocity_m_s = 0.025;
                c.max_z_accel_m_s2 = 0.03;
                c.kinematics = Kinematics::Cartesian;
                PlannerConfig::Klipper(c)
            }
            Firmware::Marlin => PlannerConfig::Marlin(MarlinConfig::new()),
            Firmware::Rrf => PlannerConfig::Rrf(RrfConfig::new()),
            Firmware::Settle => {
                PlannerConfig::Settle(SettleConfig::new().map_err(|e| GcodeError::JobSetting {
                    key: "settle limits",
                    reason: e.to_string(),
                })?)
            }
        };
        let dialect = firmware.dialect();
        Ok(Self {
            planner,
            dialect,
            shapers: [None; 3],
            alignment: Alignment::Centred,
            arcs: ArcSegmentation::default_for(dialect),
            profiles: ProfileOptions::default(),
            klipper_flush_delay_s: 0.001,
        })
    }

    /// Which firmware.
    pub fn firmware(&self) -> Firmware {
        self.planner.firmware()
    }
}
