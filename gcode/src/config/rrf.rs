//! What settle needs from a RepRapFirmware `config.g`, applied in order as the firmware
//! applies it (RepRapFirmware 3.6: `src/GCodes/GCodes2.cpp`, `src/Movement/Move.cpp`,
//! `src/Movement/AxisShaper.cpp`, defaults from `src/Config/Configuration.h`):
//!
//! - `M350` changes microstepping and rescales steps per mm so a millimetre stays one;
//!   `M92 S<m>` gives steps per mm at `m` microsteps, converted to the microstepping in
//!   force. So the order of `M350` and `M92` matters, as on the machine.
//! - `M201` (mm/s^2), `M203` (mm/min), `M566` (mm/min), `M204 P/T`, `M906` (mA),
//!   `M208`, `M669 K`/`M665`, and `M593`, whose one shaper serves every axis (RRF has a
//!   single `AxisShaper`; `M593` names no axis). `M593` with `F` or `S` but no `P` while
//!   shaping is off selects `zvd`, as the firmware does.
//! - `M98 P"file"` and `M501` (`config-override.g`) run the named file in place: relative
//!   names are looked up in the folder of `config.g` (the SD card's `/sys`) whichever
//!   file calls them, `/name` and `0:/name` from that folder's parent (the card's root).
//!   A file that is not there is a note, as the firmware only warns.
//! - Meta-commands and `{expressions}` that name anything are not evaluated (see the
//!   notes); an expression of numbers alone is worked out (`rrf_script`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::budget::Budget;
use super::klipper_files::absolute;
use super::machine::{AxisDrive, ConfigNote, MICROSTEPS_PER_MM, ShaperSetting, Xyz};
use super::rrf_script::unconditional;
use crate::error::{GcodeError, Location};
use crate::read::dialect::Dialect;
use crate::read::event::{EventKind, Note};
use crate::read::limits::{AxisValues, LimitChange};
use crate::read::setting::Setting;

/// The least jerk RepRapFirmware keeps (mm/s): `MinimumJerk` in
/// src/Config/Configuration.h, applied by `Platform::SetInstantDv` to every `M566` value,
/// in config.g as in a job (`M566 X0` runs at 0.1 mm/s).
pub const RRF_MINIMUM_JERK_MM_S: f64 = 0.1;

/// The least acceleration RepRapFirmware keeps (mm/s^2): `MinimumAcceleration` in
/// src/Config/Configuration.h, applied by `Platform::SetAcceleration` to every `M201`
/// value and by `GCodes::ConfigureAccelerations` to `M204`'s (src/GCodes/GCodes5.cpp),
/// in config.g as in a job.
pub const RRF_MINIMUM_ACCEL_MM_S2: f64 = 0.1;

/// The kinematics by `M669 K` code (`KinematicsType`,
/// `src/Movement/Kinematics/Kinematics.h`), named as Klipper names the same ones.
const KINEMATICS: [&str; 15] = [
    "cartesian",
    "corexy",
    "corexz",
    "delta",
    "scara",
    "corexyu",
    "hangprinter",
    "polar",
    "corexyuv",
    "five_bar_scara",
    "rotary_delta",
    "markforged",
    "collinear_tripteron",
    "robot5axis",
    "six_axis_delta",
];

/// The shaper types `M593 P` accepts (`InputShaperType`, `src/Movement/AxisShaper.h`).
const SHAPERS: [&str; 8] = [
    "custom", "ei2", "ei3", "mzv", "none", "zvd", "zvdd", "zvddd",
];

/// An `M593 P` type as `GcodeBuffer::GetReducedString` (src/GCodes/GCodeBuffer/
/// GCodeBuffer.cpp) gives it to `InputShaperType`: lower case, without `-`, `_` and
/// spaces (`"EI-2"` is `ei2`).
pub(crate) fn rrf_shaper_name(written: &str) -> String {
    written
        .chars()
        .filter(|c| !matches!(c, '-' | '_' | ' '))
        .flat_map(char::to_lowercase)
        .collect()
}

/// RepRapFirmware's input shaper before any `M593` (`AxisShaper::AxisShaper`): off, with
/// 40 Hz and damping 0.05 waiting for a type.
pub const RRF_DEFAULT_SHAPER: (&str, f64, f64) = ("none", 40.0, 0.05);
/// Print and travel acceleration before any `M204`, mm/s^2 (`DefaultPrintingAcceleration`:
/// "higher than any likely max acceleration defined by M201").
pub const RRF_DEFAULT_M204_MM_S2: f64 = 50_000.0;

/// One axis as the firmware has it after the file.
#[derive(Debug, Clone, PartialEq)]
pub struct RrfAxis {
    /// Resolution (`M92`/`M350`), current (`M906`), travel (`M208`).
    pub drive: AxisDrive,
    /// `M203`: the highest speed, mm/s (default 100, Z 20).
    pub max_speed_mm_s: f64,
    /// `M201`: the highest acceleration, mm/s^2 (default 1000, Z 200).
    pub max_accel_mm_s2: f64,
    /// `M566`: the largest instantaneous speed change ("jerk"), mm/s (default 15, Z 10).
    pub max_jerk_mm_s: f64,
    /// `M906`: motor current, mA peak (0 until set).
    pub motor_current_ma: f64,
}

/// The settings settle reads from a RepRapFirmware configuration, as the firmware would
/// use them.
#[derive(Debug, Clone, PartialEq)]
pub struct RrfConfig {
    /// `M669 K` (or `M665`): `cartesian` (default), `corexy`, `delta`, ...
    pub kinematics: String,
    /// X, Y, Z.
    pub axes: Xyz<RrfAxis>,
    /// `M204 P`: acceleration of printing moves, mm/s^2.
    pub print_accel_mm_s2: f64,
    /// `M204 T`: acceleration of travel moves, mm/s^2.
    pub travel_accel_mm_s2: f64,
    /// `M593`: the one shaper of every axis (`name` `none`: off).
    pub input_shaper: ShaperSetting,
    /// `M906 I`: idle current, percent of the run current (default 30).
    pub idle_current_percent: f64,
    /// The files read, `config.g` first, then macros in the order run.
    pub files: Vec<PathBuf>,
    /// What was not read (conditional blocks, expressions, missing macros).
    pub notes: Vec<ConfigNote>,
    /// Where each command in effect was last given, by its name (`M593`, `M203`, and
    /// `M593 F` for the last `M593` with a frequency): the file and line an error about a
    /// value read here names.
    pub set_at: BTreeMap<String, Location>,
}

/// Where macros are looked up, and the files being read (absolute, outermost first).
#[derive(Debug)]
struct Files {
    sys: PathBuf,
    stack: Vec<PathBuf>,
    budget: Budget,
    /// Per axis (X, Y, Z), the command that last changed its steps per mm, where, and the
    /// value it gave there (steps per mm for `M92`, microstepping for `M350`).
    steps_set: [Option<(Location, &'static str, f64)>; 3],
}

/// Per-axis state while reading, in the firmware's units where they differ.
#[derive(Debug, Clone)]
struct AxisState {
    steps_per_mm: f64,
    microsteps: u32,
    interpolate: bool,
    min_mm: f64,
    max_mm: f64,
}

impl RrfConfig {
    /// The firmware's state before `config.g` (`Move::Init`, `src/Config/Configuration.h`).
    fn defaults() -> Self {
        let axis = |z: bool| RrfAxis {
            drive: AxisDrive {
                microsteps_per_mm: if z { 800.0 } else { 80.0 },
                microsteps: 16,
                interpolate: Some(true),
                run_current_a_rms: None,
                position_min_mm: 0.0,
                position_max_mm: Some(200.0),
            },
            max_speed_mm_s: if z { 20.0 } else { 100.0 },
            max_accel_mm_s2: if z { 200.0 } else { 1000.0 },
            max_jerk_mm_s: if z { 10.0 } else { 15.0 },
            motor_current_ma: 0.0,
        };
        let (name, f, zeta) = RRF_DEFAULT_SHAPER;
        RrfConfig {
            kinematics: KINEMATICS[0].to_string(),
            axes: Xyz {
                x: axis(false),
                y: axis(false),
                z: axis(true),
            },
            print_accel_mm_s2: RRF_DEFAULT_M204_MM_S2,
            travel_accel_mm_s2: RRF_DEFAULT_M204_MM_S2,
            input_shaper: ShaperSetting {
                name: name.to_string(),
                frequency_hz: f,
                damping_ratio: zeta,
            },
            idle_current_percent: 30.0,
            files: Vec::new(),
            notes: Vec::new(),
            set_at: BTreeMap::new(),
        }
    }

    /// Reads `config.g` at `path` and the macros it runs.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        let path = path.as_ref();
        let mut budget = Budget::new();
        let text = budget.main(path)?;
        Self::parse_with(&text, path, budget)
    }

    /// Reads `text` as the configuration file at `path` (which names it in errors and
    /// anchors the macros it runs; it need not exist).
    pub fn parse(text: &str, path: impl AsRef<Path>) -> Result<Self, GcodeError> {
        Self::parse_with(text, path.as_ref(), Budget::new())
    }

    fn parse_with(text: &str, path: &Path, budget: Budget) -> Result<Self, GcodeError> {
        let mut c = Self::defaults();
        let mut files = Files {
            sys: path.parent().unwrap_or(Path::new("")).to_path_buf(),
            stack: Vec::new(),
            budget,
            steps_set: [None, None, None],
        };
        c.run(text, path, &mut files)?;
        c.check_steps_per_mm(&files)?;
        Ok(c)
    }

    /// Refuse an axis left with steps per mm outside [`MICROSTEPS_PER_MM`], at the `M92`
    /// or `M350` that set it. RepRapFirmware takes any positive `M92` and raises one below
    /// 0.01 to 0.01 (`MinimumStepsPerMm`); settle reads it so, but an axis under one
    /// microstep per mm (a step longer than a millimetre) or over 1e9 is a typing or unit
    /// mistake, and `settle tune` refuses such a `usteps_per_mm`: refused here, where the
    /// value was written, rather than imported into a scenario tune then refuses.
    fn check_steps_per_mm(&self, files: &Files) -> Result<(), GcodeError> {
        let (lo, hi) = MICROSTEPS_PER_MM;
        let axes = [&self.axes.x, &self.axes.y, &self.axes.z];
        for ((axis, letter), set) in axes.into_iter().zip(["X", "Y", "Z"]).zip(&files.steps_set) {
            let v = axis.drive.microsteps_per_mm;
            if let Some((at, command, given)) = set
                && !(lo..=hi).contains(&v)
            {
                return Err(GcodeError::ConfigValue {
                    at: at.clone(),
                    section: (*command).to_string(),
                    key: letter.to_string(),
                    value: given.to_string().into(),
                    allowed: format!(
                        "a value that leaves axis {letter} {lo} to {hi:e} microsteps per mm (this leaves {v}, after RepRapFirmware's floor of {MINIMUM_STEPS_PER_MM} steps/mm, `MinimumStepsPerMm` in src/Config/Configuration.h): below one a microstep is longer than a millimetre, and settle tune takes 1 to 1e9"
                    )
                    .into(),
                });
            }
        }
        Ok(())
    }

    fn run(&mut self, text: &str, path: &Path, files: &mut Files) -> Result<(), GcodeError> {
        let source: Arc<str> = Arc::from(path.display().to_string());
        self.files.push(path.to_path_buf());
        files.stack.push(absolute(path));
        let script = unconditional(text, &source);
        self.notes.extend(script.notes);
        for event in super::located_events(&script.text, Dialect::Rrf, &source) {
            // `M593`'s words are the configuration's shaper: named as its setting.
            let (at, kind) = event.map_err(|e| match e {
                GcodeError::OutOfRange { ref command, .. } if command == "M593" => {
                    super::out_of_range_as_setting(e)
                }
                e => e,
            })?;
            match kind {
                EventKind::Setting(s) => {
                    if let Setting::Kinematics { .. } = s {
                        self.set_at.insert("M669 K".into(), at.clone());
                    }
                    let before = self.state().map(|a| a.steps_per_mm);
                    self.setting(&s, &at)?;
                    let given = match &s {
                        Setting::StepsPerMm { per_axis, .. } => Some(("M92", xyz(per_axis))),
                        Setting::Microstepping { per_axis, .. } => Some(("M350", xyz(per_axis))),
                        _ => None,
                    };
                    if let Some((command, values)) = given {
                        let after = self.state().map(|a| a.steps_per_mm);
                        for i in 0..3 {
                            if let Some(v) = values[i]
                                && after[i] != before[i]
                            {
                                files.steps_set[i] = Some((at.clone(), command, v));
                            }
                        }
                    }
                }
                EventKind::Limits(l) => {
                    self.set_at.insert(l.command_name().into(), at.clone());
                    if let LimitChange::RrfInputShaping {
                        frequency_hz: Some(_),
                        ..
                    } = l
                    {
                        self.set_at.insert("M593 F".into(), at.clone());
                    }
                    self.limits(&l, &at)?;
                }
                EventKind::Note(Note::MacroCall { path: name, .. }) => {
                    self.macro_call(&name, at, files)?;
                }
                _ => {}
            }
        }
        files.stack.pop();
        Ok(())
    }

    /// Runs macro `name` as `Platform::OpenSysFile` finds it: relative to `/sys` whichever
    /// file calls it.
    fn macro_call(
        &mut self,
        name: &str,
        at: Location,
        files: &mut Files,
    ) -> Result<(), GcodeError> {
        let sys = files.sys.as_path();
        let name = match name.split_once(':') {
            Some((drive, rest)) if drive.chars().all(|c| c.is_ascii_digit()) => rest,
            _ => name,
        };
        let file = match name.strip_prefix('/') {
            Some(from_root) => sys.parent().unwrap_or(Path::new("")).join(from_root),
            None => sys.join(name),
        };
        if files.stack.contains(&absolute(&file)) {
            let mut chain: Vec<String> = files
                .stack
                .iter()
                .map(|p| p.display().to_string())
                .collect();
            chain.push(file.display().to_string());
            return Err(GcodeError::IncludeCycle {
                at,
                path: file.display().to_string(),
                chain: chain.join(" -> "),
            });
        }
        if std::fs::metadata(&file).is_err() {
            self.notes.push(ConfigNote::at(
                at,
                format!(
                    "macro `{}` is not there; RepRapFirmware warns and goes on, and so does settle",
                    file.display()
                ),
            ));
            return Ok(());
        }
        let what = format!("M98 P\"{name}\"");
        let text = files.budget.read(&file, &at, &what)?;
        self.run(&text, &file, files)
    }

    fn axes_mut(&mut self) -> [&mut RrfAxis; 3] {
        let Xyz { x, y, z } = &mut self.axes;
        [x, y, z]
    }

    fn state(&self) -> [AxisState; 3] {
        [&self.axes.x, &self.axes.y, &self.axes.z].map(|a| AxisState {
            steps_per_mm: a.drive.microsteps_per_mm,
            microsteps: a.drive.microsteps,
            interpolate: a.drive.interpolate.unwrap_or(true),
            min_mm: a.drive.position_min_mm,
            max_mm: a.drive.position_max_mm.unwrap_or(f64::INFINITY),
        })
    }

    fn set_state(&mut self, state: [AxisState; 3]) {
        for (a, s) in self.axes_mut().into_iter().zip(state) {
            a.drive.microsteps_per_mm = s.steps_per_mm;
            a.drive.microsteps = s.microsteps;
            a.drive.interpolate = Some(s.interpolate);
            a.drive.position_min_mm = s.min_mm;
            a.drive.position_max_mm = Some(s.max_mm);
        }
    }

    fn setting(&mut self, s: &Setting, at: &Location) -> Result<(), GcodeError> {
        let mut state = self.state();
        match s {
            Setting::StepsPerMm {
                per_axis,
                at_microstepping,
            } => {
                for (a, v) in state.iter_mut().zip(xyz(per_axis)) {
                    if let Some(mut v) = v {
                        if let Some(m) = at_microstepping.filter(|&m| m != a.microsteps) {
                            v = v * f64::from(a.microsteps) / f64::from(m);
                        }
                        a.steps_per_mm = v.max(MINIMUM_STEPS_PER_MM);
                    }
                }
            }
            Setting::Microstepping {
                per_axis,
                interpolation,
            } => {
                for (a, v) in state.iter_mut().zip(xyz(per_axis)) {
                    if let Some(m) = v {
                        let m = m as u32;
                        a.steps_per_mm = a.steps_per_mm * f64::from(m) / f64::from(a.microsteps);
                        a.microsteps = m;
                        a.interpolate = *interpolation;
                    }
                }
            }
            Setting::MotorCurrent {
                per_axis_ma,
                idle_percent,
            } => {
                for (a, v) in self.axes_mut().into_iter().zip(xyz(per_axis_ma)) {
                    if let Some(ma) = v {
                        a.motor_current_ma = ma;
                        a.drive.run_current_a_rms =
                            (ma > 0.0).then(|| ma / 1000.0 / std::f64::consts::SQRT_2);
                    }
                }
                if let Some(p) = idle_percent {
                    self.idle_current_percent = p.min(100.0);
                }
                return Ok(());
            }
            Setting::AxisLimits {
                minimum_mm,
                maximum_mm,
            } => {
                for ((a, lo), (hi, letter)) in state
                    .iter_mut()
                    .zip(xyz(minimum_mm))
                    .zip(xyz(maximum_mm).into_iter().zip(["X", "Y", "Z"]))
                {
                    let (new_lo, new_hi) = (lo.unwrap_or(a.min_mm), hi.unwrap_or(a.max_mm));
                    if !(new_hi > new_lo) {
                        return Err(GcodeError::ConfigValue {
                            at: at.clone(),
                            section: "M208".to_string(),
                            key: letter.to_string(),
                            value: format!("{new_lo}:{new_hi}").into(),
                            allowed: "a maximum above the minimum".into(),
                        });
                    }
                    (a.min_mm, a.max_mm) = (new_lo, new_hi);
                }
            }
            Setting::Kinematics { code } => {
                self.kinematics = KINEMATICS
                    .get(*code as usize)
                    .map_or_else(|| format!("kinematics {code}"), |k| (*k).to_string());
                return Ok(());
            }
            // The RepRapFirmware reader produces none.
            Setting::Grbl { .. } => return Ok(()),
        }
        self.set_state(state);
        Ok(())
    }

    fn set_axes(&mut self, values: &AxisValues, field: fn(&mut RrfAxis) -> &mut f64) {
        for (a, v) in self.axes_mut().into_iter().zip(xyz(values)) {
            if let Some(v) = v {
                *field(a) = v;
            }
        }
    }

    fn limits(&mut self, l: &LimitChange, at: &Location) -> Result<(), GcodeError> {
        // An acceleration below RepRapFirmware's least runs at it, as in a job
        // (`crate::job`'s M201 and M204).
        let least = RRF_MINIMUM_ACCEL_MM_S2;
        let raised = |v: &Option<f64>| v.map(|v| v.max(least));
        let given = match l {
            LimitChange::MaxAccel {
                per_axis_mm_s2: a, ..
            } => vec![a.x, a.y, a.z, a.e],
            LimitChange::Accel {
                print_mm_s2,
                travel_mm_s2,
                ..
            } => vec![*print_mm_s2, *travel_mm_s2],
            _ => Vec::new(),
        };
        if given.iter().flatten().any(|&v| v < least) {
            self.notes.push(ConfigNote::at(
                at.clone(),
                format!(
                    "{}: an acceleration below {least} mm/s^2 runs at {least}, RepRapFirmware's least (MinimumAcceleration, src/Config/Configuration.h)",
                    l.command_name()
                ),
            ));
        }
        match l {
            LimitChange::MaxAccel { per_axis_mm_s2, .. } => {
                let a = per_axis_mm_s2.map(raised);
                self.set_axes(&a, |a| &mut a.max_accel_mm_s2);
            }
            LimitChange::MaxFeedrate { per_axis_mm_s, .. } => {
                self.set_axes(per_axis_mm_s, |a| &mut a.max_speed_mm_s);
            }
            // `M205` lowers only the printing moves' value below this limit.
            LimitChange::RrfJerk {
                per_axis_mm_s,
                sets_maximum: true,
                ..
            } => {
                self.set_axes(per_axis_mm_s, |a| &mut a.max_jerk_mm_s);
                for a in self.axes_mut() {
                    a.max_jerk_mm_s = a.max_jerk_mm_s.max(RRF_MINIMUM_JERK_MM_S);
                }
            }
            LimitChange::Accel {
                print_mm_s2,
                travel_mm_s2,
                ..
            } => {
                if let Some(p) = raised(print_mm_s2) {
                    self.print_accel_mm_s2 = p;
                }
                if let Some(t) = raised(travel_mm_s2) {
                    self.travel_accel_mm_s2 = t;
                }
            }
            LimitChange::RrfInputShaping {
                shaper,
                frequency_hz,
                damping_ratio,
                ..
            } => self.shaper(shaper.as_deref(), *frequency_hz, *damping_ratio, at)?,
            _ => {}
        }
        Ok(())
    }

    fn shaper(
        &mut self,
        kind: Option<&str>,
        frequency_hz: Option<f64>,
        damping_ratio: Option<f64>,
        at: &Location,
    ) -> Result<(), GcodeError> {
        let bad = |key: &str, value: String, allowed: String| GcodeError::ConfigValue {
            at: at.clone(),
            section: "M593".to_string(),
            key: key.to_string(),
            value: value.into(),
            allowed: allowed.into(),
        };
        // `F` is within RRF_MIN_SHAPER_FREQUENCY_HZ..=RRF_MAX_SHAPER_FREQUENCY_HZ: the reader's
        // `M593` refuses another (`RRF_SHAPER_FREQUENCY`, crate::read::limit_parse).
        if let Some(f) = frequency_hz {
            self.input_shaper.frequency_hz = f;
        }
        if let Some(z) = damping_ratio {
            self.input_shaper.damping_ratio = z;
        }
        match kind {
            Some(k) => {
                let reduced = rrf_shaper_name(k);
                if !SHAPERS.contains(&reduced.as_str()) {
                    return Err(bad("P", k.to_string(), SHAPERS.join(", ")));
                }
                if reduced == "custom" {
                    self.notes.push(ConfigNote::at(
                        at.clone(),
                        "a custom shaper's impulses (M593 H/T) are not carried over; settle knows it only by name",
                    ));
                }
                self.input_shaper.name = reduced;
            }
            None if (frequency_hz.is_some() || damping_ratio.is_some())
                && self.input_shaper.name == "none" =>
            {
                self.input_shaper.name = "zvd".to_string();
            }
            None => {}
        }
        Ok(())
    }
}

/// RepRapFirmware's floor on steps per mm (`MinimumStepsPerMm`, `src/Config/Configuration.h`).
const MINIMUM_STEPS_PER_MM: f64 = 0.01;

fn xyz(v: &AxisValues) -> [Option<f64>; 3] {
    [v.x, v.y, v.z]
}
