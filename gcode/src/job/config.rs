//! What a job plans with: the firmware, its starting configuration, the input shapers and
//! how arcs are cut, as plain data (the harness fills it from a machine or preset, or from
//! an imported printer.cfg / config.g).

use settle_planner::firmware::klipper::KlipperConfig;
use settle_planner::firmware::marlin::{MarlinConfig, PrusaModel};
use settle_planner::firmware::profiles::ProfileOptions;
use settle_planner::firmware::rrf::RrfConfig;
use settle_planner::firmware::{Firmware, Kinematics};
use settle_planner::path::junction::Junction;
use settle_planner::path::{CornerStrategy, PathOptions};
use settle_planner::shaper::ShaperType;
use settle_planner::shaper::stream::Alignment;
use settle_planner::{Limits, PlanError, ProfileKind};

pub use super::shapers::ShaperSetting;
use crate::config::GrblSettings;
use crate::error::Location;
use crate::{ArcSegmentation, Dialect, GcodeError, GrblArcs, LayerMode, ReaderOptions};

/// A firmware by name, for a G-code job: one of [`Firmware::GCODE`] (klipper, marlin,
/// prusa, rrf, grbl, settle; `buddy` is prusa, `reprapfirmware` and `duet` are rrf,
/// `grblhal` is grbl).
pub fn parse_firmware(name: &str) -> Result<Firmware, GcodeError> {
    Firmware::parse_among(name, &Firmware::GCODE, "a G-code planner").map_err(|reason| {
        GcodeError::JobSetting {
            key: "firmware",
            reason,
        }
    })
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
    /// Prusa-Firmware-Buddy's: Marlin's planner run by its precise stepping, with a
    /// printer's settings ([`PrusaModel::config`]).
    Prusa(MarlinConfig),
    /// RepRapFirmware's config.g settings.
    Rrf(RrfConfig),
    /// GRBL's `$` settings (the planner's, the arc tolerance, the laser mode).
    Grbl(GrblSettings),
    /// settle's planner.
    Settle(SettleConfig),
}

impl PlannerConfig {
    /// Which firmware.
    pub fn firmware(&self) -> Firmware {
        match self {
            PlannerConfig::Klipper(_) => Firmware::Klipper,
            PlannerConfig::Marlin(_) => Firmware::Marlin,
            PlannerConfig::Prusa(_) => Firmware::Prusa,
            PlannerConfig::Rrf(_) => Firmware::Rrf,
            PlannerConfig::Grbl(_) => Firmware::Grbl,
            PlannerConfig::Settle(_) => Firmware::Settle,
        }
    }
}

/// Which Prusa printer's settings a `--firmware prusa` job runs with, and why: the
/// printer the file names with its first `M862.3 P "<name>"` before its first move (every
/// PrusaSlicer start G-code writes one), else the MK4 ([`crate::job::prusa_printer`] reads
/// it).
#[derive(Debug, Clone, PartialEq)]
pub struct PrusaPrinter {
    /// The printer family.
    pub model: PrusaModel,
    /// The line that named it and the name as written (`None`: the file names none, so
    /// the MK4's settings, settle's default).
    pub named_at: Option<(u64, String)>,
}

impl PrusaPrinter {
    /// The MK4, for a file that names no printer.
    pub fn unnamed() -> Self {
        Self {
            model: PrusaModel::Mk4,
            named_at: None,
        }
    }
}

impl std::fmt::Display for PrusaPrinter {
    /// `Prusa MINI settings (from line 136: M862.3 P "MINI")`, or the MK4's and why.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Prusa {} settings ", self.model)?;
        match &self.named_at {
            Some((line, name)) => write!(f, "(from line {line}: M862.3 P \"{name}\")"),
            None => f.write_str(
                "(the file names no printer: no M862.3 P before its first move; settle's default)",
            ),
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
    /// Where the file's layer changes come from ([`LayerMode::Auto`] by default: slicer
    /// markers, else changes of Z).
    pub layer_mode: LayerMode,
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
    /// The travel of X, Y, Z (mm, machine frame): Klipper's `position_min` and
    /// `position_max`, RepRapFirmware's `M208`, GRBL's `$130`-`$132` (from 0); `None`
    /// where the configuration does not say (see [`crate::job`]'s travel rules).
    pub travel_mm: [Option<(f64, f64)>; 3],
    /// Klipper: the least step-generation flush delay (s) besides the shapers', the
    /// larger of `SDS_CHECK_TIME` (1 ms, klippy/extras/motion_queuing.py) and half the
    /// extruder's `pressure_advance_smooth_time` when pressure advance is on (0.020 s for
    /// the default 0.040 s; off by default). It sets the pause a `SET_INPUT_SHAPER` makes.
    pub klipper_flush_delay_s: f64,
    /// Prusa: the printer whose settings the planner and the shapers start with (`None`
    /// for the other firmwares).
    pub prusa: Option<PrusaPrinter>,
}

impl JobConfig {
    /// The firmware's defaults (no input shaping, as every firmware but Prusa's ships):
    /// - Klipper: `max_velocity` 500 mm/s, `max_accel` 3000 mm/s^2, `max_z_velocity`
    ///   25 mm/s, `max_z_accel` 30 mm/s^2 (Klipper requires these in printer.cfg; these are
    ///   its config/example-cartesian.cfg) and Klipper's defaults for the rest
    ///   ([`KlipperConfig::new`]);
    /// - Marlin: [`MarlinConfig::new`] (its example configuration);
    /// - Prusa: the MK4's, [`JobConfig::prusa`] of [`PrusaPrinter::unnamed`] (a file that
    ///   names its printer takes that printer's, [`crate::job::prusa_printer`]);
    /// - RepRapFirmware: [`RrfConfig::new`] (Configuration.h);
    /// - GRBL: [`GrblSettings::new`] (grbl/defaults.h `DEFAULTS_GENERIC`);
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
            Firmware::Prusa => PlannerConfig::Prusa(PrusaModel::Mk4.config()),
            Firmware::Rrf => PlannerConfig::Rrf(RrfConfig::new()),
            Firmware::Grbl => PlannerConfig::Grbl(GrblSettings::new()),
            Firmware::Settle => {
                PlannerConfig::Settle(SettleConfig::new().map_err(|e| GcodeError::JobSetting {
                    key: "settle limits",
                    reason: e.to_string(),
                })?)
            }
            Firmware::Tmc4361a => {
                return Err(GcodeError::JobSetting {
                    key: "firmware",
                    reason: format!(
                        "{firmware} is a motion controller: it plans no G-code job; allowed: {}",
                        Firmware::names(&Firmware::GCODE)
                    ),
                });
            }
        };
        let dialect = Dialect::of(firmware);
        let prusa = (firmware == Firmware::Prusa).then(PrusaPrinter::unnamed);
        let shapers = match &prusa {
            Some(p) => crate::job::shapers::prusa_shapers(p.model),
            None => [None; 3],
        };
        Ok(Self {
            planner,
            dialect,
            layer_mode: LayerMode::Auto,
            shapers,
            alignment: Alignment::Centred,
            arcs: ArcSegmentation::default_for(dialect),
            profiles: ProfileOptions::default(),
            travel_mm: [None; 3],
            klipper_flush_delay_s: 0.001,
            prusa,
        })
    }

    /// What a Prusa printer starts a file with: its family's settings
    /// ([`PrusaModel::config`]) and its shapers as Prusa ships them (MZV at 50.7 Hz on X
    /// and 40.6 Hz on Y on the MK4 and MK3.5, 118.2 and 32.8 Hz on the MINI, 35.8 and
    /// 35.4 Hz on the XL, EI at 60 and 50 Hz on the CORE One; damping 0.1,
    /// lib/Marlin/Marlin/src/feature/input_shaper/input_shaper_config.hpp). A printer
    /// keeps its own in EEPROM (its calibration may have changed them); the file's
    /// `M593` lines change them.
    pub fn prusa(printer: PrusaPrinter) -> Result<Self, GcodeError> {
        let mut cfg = Self::defaults(Firmware::Prusa)?;
        cfg.planner = PlannerConfig::Prusa(printer.model.config());
        cfg.shapers = crate::job::shapers::prusa_shapers(printer.model);
        cfg.prusa = Some(printer);
        Ok(cfg)
    }

    /// Which firmware.
    pub fn firmware(&self) -> Firmware {
        self.planner.firmware()
    }

    /// How the file is read: in [`JobConfig::dialect`], its layers as
    /// [`JobConfig::layer_mode`] says, with GRBL's laser mode (`$32`) from its settings.
    pub fn reader_options(&self) -> ReaderOptions {
        let mut o = ReaderOptions::new(self.dialect);
        o.layers = self.layer_mode;
        if let PlannerConfig::Grbl(g) = &self.planner {
            o.laser_mode = g.laser_mode;
            o.spindle_range = [g.spindle_min, g.spindle_max];
        }
        o
    }

    /// What a GRBL machine starts a file with, from its `$$` settings
    /// ([`GrblSettings`]): the planner's (`$11`, `$100`-`$122`, `$398`), the arc
    /// tolerance (`$12`) and the laser mode (`$32`).
    pub fn from_grbl(s: &GrblSettings) -> Result<Self, GcodeError> {
        let mut cfg = Self::defaults(Firmware::Grbl)?;
        s.planner().validate().map_err(|e| GcodeError::JobSetting {
            key: "GRBL settings",
            reason: e.to_string(),
        })?;
        cfg.arcs = ArcSegmentation::Grbl(GrblArcs {
            tolerance_mm: s.arc_tolerance_mm,
        });
        cfg.planner = PlannerConfig::Grbl(s.clone());
        cfg.travel_mm = s.max_travel_mm.map(|t| Some((0.0, t)));
        Ok(cfg)
    }
}

/// A printer's kinematics as settle's firmware planners model them: Cartesian and CoreXY.
fn planner_kinematics(name: &str, key: &'static str) -> Result<Kinematics, GcodeError> {
    match name {
        "cartesian" => Ok(Kinematics::Cartesian),
        "corexy" => Ok(Kinematics::CoreXy),
        other => Err(GcodeError::JobSetting {
            key,
            reason: format!(
                "`{other}`: settle's firmware planners model cartesian and corexy kinematics"
            ),
        }),
    }
}

/// A job setting's error at the configuration line `at` that set it, where known.
fn located(e: GcodeError, at: Option<&Location>) -> GcodeError {
    match (e, at) {
        (GcodeError::JobSetting { key, reason }, Some(at)) => GcodeError::ConfigSetting {
            at: at.clone(),
            key: key.to_string(),
            reason,
        },
        (e, _) => e,
    }
}

/// An axis's shaper as a configuration file sets it, as a job setting (`None`: the
/// firmware does not shape the axis). An error names `keys`' first (the shaper's type),
/// or its second for a frequency below settle's lowest, at the line `line_of` gives for
/// that key (the key alone where it gives none).
fn config_shaper(
    s: &crate::config::ShaperSetting,
    dialect: Dialect,
    keys: [&'static str; 2],
    line_of: &dyn Fn(&str) -> Option<Location>,
) -> Result<Option<ShaperSetting>, GcodeError> {
    let min = settle_planner::shaper::MIN_FREQUENCY_HZ;
    let key = keys[usize::from(s.frequency_hz < min && s.type_name(dialect).is_some())];
    let bad = |reason: String| {
        located(
            GcodeError::JobSetting { key, reason },
            line_of(key).as_ref(),
        )
    };
    let Some(name) = s.type_name(dialect) else {
        if s.is_enabled(dialect) {
            return Err(bad(format!(
                "the `{}` shaper is known only by its impulses; settle does not model it",
                s.name
            )));
        }
        return Ok(None);
    };
    let kind = ShaperType::parse(&name).map_err(|e| bad(e.to_string()))?;
    let setting = ShaperSetting {
        shaper_type: kind,
        frequency_hz: s.frequency_hz,
        damping_ratio: s.damping_ratio,
    };
    setting.build().map_err(|e| bad(e.to_string()))?;
    Ok(Some(setting))
}

impl JobConfig {
    /// What a Klipper printer starts a file with, from its configuration
    /// ([`crate::config::KlipperConfig`]): `[printer]`'s `max_velocity`, `max_accel`,
    /// `minimum_cruise_ratio`, `square_corner_velocity`, `max_z_velocity`, `max_z_accel`
    /// and `kinematics` (cartesian or corexy), and `[input_shaper]` per axis (Klipper
    /// shapes an axis whose frequency is above 0). Everything else is
    /// [`JobConfig::defaults`]' (Klipper's extruder defaults among them: the configuration
    /// reader does not read `[extruder]`).
    pub fn from_klipper(c: &crate::config::KlipperConfig) -> Result<Self, GcodeError> {
        let mut cfg = Self::defaults(Firmware::Klipper)?;
        let p = &c.printer;
        let mut k = KlipperConfig::new(p.max_velocity_mm_s * 1e-3, p.max_accel_mm_s2 * 1e-3);
        k.minimum_cruise_ratio = p.minimum_cruise_ratio;
        k.square_corner_velocity_m_s = p.square_corner_velocity_mm_s * 1e-3;
        k.max_z_velocity_m_s = p.max_z_velocity_mm_s * 1e-3;
        k.max_z_accel_m_s2 = p.max_z_accel_mm_s2 * 1e-3;
        k.kinematics = planner_kinematics(&p.kinematics, "printer.kinematics")
            .map_err(|e| located(e, c.set_at.get("printer.kinematics")))?;
        k.validate().map_err(|e| GcodeError::JobSetting {
            key: "printer",
            reason: e.to_string(),
        })?;
        cfg.planner = PlannerConfig::Klipper(k);
        for (t, (_, s)) in cfg.travel_mm.iter_mut().zip(c.steppers.iter()) {
            *t = s
                .as_ref()
                .and_then(|s| Some((s.drive.position_min_mm, s.drive.position_max_mm?)));
        }
        if let Some(s) = &c.input_shaper {
            let keys = [
                ["input_shaper.shaper_type_x", "input_shaper.shaper_freq_x"],
                ["input_shaper.shaper_type_y", "input_shaper.shaper_freq_y"],
                ["input_shaper.shaper_type_z", "input_shaper.shaper_freq_z"],
            ];
            // The axis's own option, else the one of every axis (`shaper_type`).
            let line_of = |key: &str| {
                let common = key.trim_end_matches(['x', 'y', 'z']).trim_end_matches('_');
                c.set_at.get(key).or_else(|| c.set_at.get(common)).cloned()
            };
            for (i, ((_, axis), key)) in s.iter().zip(keys).enumerate() {
                cfg.shapers[i] = config_shaper(axis, Dialect::Klipper, key, &line_of)?;
            }
        }
        Ok(cfg)
    }

    /// What a RepRapFirmware machine starts a file with, from its `config.g`
    /// ([`crate::config::RrfConfig`]): `M203` speeds, `M201` accelerations and `M566`
    /// jerks of X, Y and Z, `M204`'s printing and travel accelerations, the kinematics of
    /// `M669` (cartesian or corexy) and the `M593` shaper on X and Y (RepRapFirmware has
    /// one shaper for the motion). Everything else is [`JobConfig::defaults`]'.
    pub fn from_rrf(c: &crate::config::RrfConfig) -> Result<Self, GcodeError> {
        let mut cfg = Self::defaults(Firmware::Rrf)?;
        let mut r = RrfConfig::new();
        for (i, (_, a)) in c.axes.iter().enumerate() {
            r.max_feedrate_m_s[i] = a.max_speed_mm_s * 1e-3;
            r.max_accel_m_s2[i] = a.max_accel_mm_s2 * 1e-3;
            r.instant_dv_m_s[i] = a.max_jerk_mm_s * 1e-3;
        }
        r.print_accel_m_s2 = c.print_accel_mm_s2 * 1e-3;
        r.travel_accel_m_s2 = c.travel_accel_mm_s2 * 1e-3;
        r.kinematics = planner_kinematics(&c.kinematics, "M669 K")
            .map_err(|e| located(e, c.set_at.get("M669 K")))?;
        r.validate().map_err(|e| GcodeError::JobSetting {
            key: "config.g limits",
            reason: e.to_string(),
        })?;
        cfg.planner = PlannerConfig::Rrf(r);
        for (t, (_, a)) in cfg.travel_mm.iter_mut().zip(c.axes.iter()) {
            *t = a
                .drive
                .position_max_mm
                .map(|hi| (a.drive.position_min_mm, hi));
        }
        let line_of = |key: &str| c.set_at.get(key).cloned();
        let shaper = config_shaper(&c.input_shaper, Dialect::Rrf, ["M593", "M593 F"], &line_of)?;
        cfg.shapers[0] = shaper;
        cfg.shapers[1] = shaper;
        Ok(cfg)
    }
}

#[cfg(test)]
mod from_config_tests {
    use super::*;
    use crate::config::{KlipperConfig as KlipperFile, RrfConfig as RrfFile};

    #[test]
    fn a_klipper_configuration_sets_the_planner_and_the_shapers_per_axis() {
        let text = "[printer]\nkinematics: corexy\nmax_velocity: 300\nmax_accel: 5000\n\
                    minimum_cruise_ratio: 0.25\nsquare_corner_velocity: 8\n\
                    max_z_velocity: 15\nmax_z_accel: 100\n\
                    [input_shaper]\nshaper_type_x: mzv\nshaper_freq_x: 52.4\n\
                    shaper_type_y: ei\nshaper_freq_y: 41.5\ndamping_ratio_y: 0.08\n";
        let cfg = JobConfig::from_klipper(&KlipperFile::parse(text, "printer.cfg").expect("ok"))
            .expect("ok");
        let PlannerConfig::Klipper(k) = &cfg.planner else {
            panic!("not Klipper's planner: {:?}", cfg.planner)
        };
        assert_eq!(k.max_velocity_m_s, 0.3);
        assert_eq!(k.max_accel_m_s2, 5.0);
        assert_eq!(k.minimum_cruise_ratio, 0.25);
        assert_eq!(k.square_corner_velocity_m_s, 8e-3);
        assert_eq!((k.max_z_velocity_m_s, k.max_z_accel_m_s2), (15e-3, 0.1));
        assert_eq!(k.kinematics, Kinematics::CoreXy);
        let [x, y, z] = cfg.shapers;
        let x = x.expect("X shaped");
        let y = y.expect("Y shaped");
        assert_eq!(
            (x.shaper_type, x.frequency_hz, x.damping_ratio),
            (ShaperType::MZV, 52.4, 0.1)
        );
        assert_eq!(
            (y.shaper_type, y.frequency_hz, y.damping_ratio),
            (ShaperType::EI, 41.5, 0.08)
        );
        assert_eq!(z, None, "Klipper leaves Z unshaped without shaper_freq_z");
        assert_eq!(cfg.dialect, Dialect::Klipper);
    }

    #[test]
    fn a_shaper_error_names_the_key_at_fault() {
        let cfg = |shaper: &str| {
            let text = format!(
                "[printer]\nkinematics: cartesian\nmax_velocity: 200\nmax_accel: 3000\n\
                 [input_shaper]\n{shaper}"
            );
            let err = JobConfig::from_klipper(&KlipperFile::parse(&text, "p.cfg").expect("ok"))
                .expect_err("refused");
            err.to_string()
        };
        // Klipper shapes Y with its default type (mzv): the frequency is at fault.
        let low = cfg("shaper_freq_x: 40\nshaper_freq_y: 0.5\n");
        assert!(low.contains("input_shaper.shaper_freq_y"), "{low}");
        assert!(low.contains("0.5 Hz is below 1 Hz"), "{low}");
    }

    #[test]
    fn a_klipper_configuration_without_input_shaper_or_with_other_kinematics() {
        let plain = "[printer]\nkinematics: cartesian\nmax_velocity: 200\nmax_accel: 3000\n";
        let cfg =
            JobConfig::from_klipper(&KlipperFile::parse(plain, "p.cfg").expect("ok")).expect("ok");
        assert_eq!(cfg.shapers, [None; 3]);
        let delta = "[printer]\nkinematics: delta\nmax_velocity: 200\nmax_accel: 3000\n";
        let err = JobConfig::from_klipper(&KlipperFile::parse(delta, "p.cfg").expect("ok"))
            .expect_err("refused")
            .to_string();
        assert!(
            err.contains("printer.kinematics") && err.contains("delta"),
            "{err}"
        );
    }

    #[test]
    fn a_reprapfirmware_configuration_sets_the_planner_and_one_shaper() {
        // M203 and M566 take mm/min: 18000 mm/min = 300 mm/s, 600 mm/min = 10 mm/s.
        let text = "M669 K1\nM203 X18000 Y12000 Z600\nM201 X5000 Y4000 Z200\n\
                    M566 X600 Y480 Z30\nM204 P3000 T6000\nM593 P\"mzv\" F42.5 S0.1\n";
        let cfg = JobConfig::from_rrf(&RrfFile::parse(text, "config.g").expect("ok")).expect("ok");
        let PlannerConfig::Rrf(r) = &cfg.planner else {
            panic!("not RepRapFirmware's planner: {:?}", cfg.planner)
        };
        assert_eq!(r.kinematics, Kinematics::CoreXy);
        assert_eq!(&r.max_feedrate_m_s[..3], &[0.3, 0.2, 0.01]);
        assert_eq!(&r.max_accel_m_s2[..3], &[5.0, 4.0, 0.2]);
        assert_eq!(&r.instant_dv_m_s[..3], &[0.01, 0.008, 0.0005]);
        assert_eq!((r.print_accel_m_s2, r.travel_accel_m_s2), (3.0, 6.0));
        let x = cfg.shapers[0].expect("X shaped");
        assert_eq!(cfg.shapers[1], Some(x), "one shaper for X and Y");
        assert_eq!(cfg.shapers[2], None);
        assert_eq!((x.frequency_hz, x.damping_ratio), (42.5, 0.1));
        assert_eq!(x.shaper_type, ShaperType::parse("rrf:mzv").expect("ok"));
    }
}
