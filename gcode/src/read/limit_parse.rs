//! Motion-limit commands read in the units of the chosen dialect (see [`crate::read::limits`]
//! for each command's source).

use crate::error::GcodeError;
use crate::read::cmd::{
    BELOW_ONE, BOOL, Check, Cmd, FINITE, FRACTION, NON_NEGATIVE, POSITIVE, SMALL_INT,
};
use crate::read::dialect::Dialect;
use crate::read::event::Note;
use crate::read::limits::{AxisFlags, AxisValues, FtShaper, LimitChange};
use crate::read::params::{KeyValues, Params};

/// What a command turned out to be.
#[derive(Debug)]
pub(crate) enum Outcome {
    /// A limit change to report.
    Limits(LimitChange),
    /// A note to report.
    Note(Note),
    /// A query or no-op (no parameters): nothing to report.
    Nothing,
    /// Not a motion-limit command in this dialect: count it as ignored.
    Unknown,
}

const PER_MIN: f64 = 1.0 / 60.0;

/// Marlin's `FTM_MIN_SHAPE_FREQ`, Hz: the lowest `M493 A` Fixed-Time Motion takes
/// (`ft_config_t::goodBaseFreq`, `WITHIN(f, FTM_MIN_SHAPE_FREQ, (FTM_FS) / 2)`, in
/// Marlin/src/module/ft_motion.h): 10 in Marlin's Configuration_adv.h, the lowest a Marlin
/// release configures (later Configuration_adv.h files raise it to 20).
pub(crate) const FTM_MIN_SHAPE_FREQ_HZ: f64 = 10.0;

/// Marlin's `M493 A`, Hz: what `M493` takes (Marlin/src/gcode/feature/ft_motion/M493.cpp,
/// `WITHIN(baseFreqVal, FTM_MIN_SHAPE_FREQ, (FTM_FS) / 2)`; it answers `?Invalid` and keeps
/// the old frequency otherwise), with the lowest `FTM_MIN_SHAPE_FREQ` a Marlin release
/// configures (10 Hz; later Configuration_adv.h files have 20) and the default `FTM_FS`
/// (1000 Hz).
pub(crate) const FT_FREQUENCY: Check = Check {
    ok: |v| (FTM_MIN_SHAPE_FREQ_HZ..=500.0).contains(&v),
    allowed: "10 to 500 Hz: Marlin's M493 refuses a frequency below FTM_MIN_SHAPE_FREQ (10 Hz at the least, 20 in later Configuration_adv.h files) or above FTM_FS / 2 (FTM_FS 1000 Hz), and keeps the old one (Marlin/src/gcode/feature/ft_motion/M493.cpp)",
};

/// Marlin's `M493 I`, the damping ratio: `M493` takes 0.01 to 1 (M493.cpp); at 1 the
/// shapers divide by zero (`sqrt(1 - zeta^2)` in ft_motion.cpp), so 1 is refused too.
pub(crate) const FT_DAMPING: Check = Check {
    ok: |v| (0.01..1.0).contains(&v),
    allowed: "0.01 to below 1: Marlin's M493 refuses a damping ratio outside 0.01 to 1 (Marlin/src/gcode/feature/ft_motion/M493.cpp), and at 1 its shapers divide by sqrt(1 - zeta^2) = 0",
};

/// Marlin's `M494 O`, the POLY6 trajectory's acceleration overshoot: `M494` takes 1.25 to
/// 1.875 and answers `?Invalid` and keeps the old value otherwise
/// (Marlin/src/gcode/feature/ft_motion/M494.cpp, `GcodeSuite::M494`).
pub(crate) const FT_OVERSHOOT: Check = Check {
    ok: |v| (1.25..=1.875).contains(&v),
    allowed: "1.25 to 1.875: Marlin's M494 refuses another POLY6 acceleration overshoot and keeps the old one (Marlin/src/gcode/feature/ft_motion/M494.cpp)",
};

/// Marlin's `M494 X Y Z E`, the FT_MOTION smoothing time per axis, s: `M494` takes 0 to
/// `FTM_MAX_SMOOTHING_TIME` and answers `?Invalid` and keeps the old time otherwise
/// (M494.cpp; `FTMotion::set_smoothing_time` in Marlin/src/module/ft_motion.cpp), and
/// every Configuration_adv.h Marlin ships sets `FTM_MAX_SMOOTHING_TIME` to 0.10 s (a
/// longer one costs `FTM_FS` samples of RAM a second, ft_motion.h `ftm_smooth_max_i`).
pub(crate) const FT_SMOOTHING_S: Check = Check {
    ok: |v| (0.0..=0.1).contains(&v),
    allowed: "0 to 0.1 s: Marlin's M494 refuses a smoothing time above FTM_MAX_SMOOTHING_TIME (0.10 s in Marlin's Configuration_adv.h) and keeps the old one (Marlin/src/gcode/feature/ft_motion/M494.cpp)",
};

/// Marlin's `M205 B`, the minimum segment time, µs. Marlin stores it in a `uint32_t`
/// without a bound (`GcodeSuite::M205`, Marlin/src/gcode/config/M200-M205.cpp), and
/// `SLOWDOWN` (`Planner::_populate_block`, Marlin/src/module/planner.cpp) stretches a block
/// shorter than it, while 2 to `BLOCK_BUFFER_SIZE / 2 - 1` blocks are queued, to
/// `segment + 2 (B - segment) / queued`: with 2 queued, to B itself. Its int32 arithmetic
/// (`2 * time_diff`) overflows from 2^30 µs (18 minutes). Settle takes up to 1 s, 50 times
/// `DEFAULT_MINSEGMENTTIME` (20000 µs in every Configuration.h Marlin and
/// Prusa-Firmware-Buddy ship): a second per short block is a printer stopping at every
/// segment of a curve, no setting a printer runs with.
pub(crate) const MIN_SEGMENT_TIME_US: Check = Check {
    ok: |v| (0.0..=1e6).contains(&v),
    allowed: "0 to 1000000 us (1 s): Marlin's default is 20000 us (DEFAULT_MINSEGMENTTIME); SLOWDOWN stretches a short block to as long as B while the queue drains (Planner::_populate_block), so a B of more than a second would make the printer crawl a second per segment of every curve, and from 2^30 us Marlin's own arithmetic overflows",
};

/// A shaper frequency in a job (Marlin's `M593 F`, Klipper's `SET_INPUT_SHAPER
/// SHAPER_FREQ_*`): 0 (off), or 1 Hz (settle's lowest,
/// `settle_planner::shaper::MIN_FREQUENCY_HZ`) to [`crate::config::MAX_SHAPER_FREQUENCY_HZ`],
/// as where printer.cfg and an `M503` reply set it.
pub(crate) const SHAPER_FREQUENCY: Check = Check {
    ok: |v| v == 0.0 || (1.0..=crate::config::MAX_SHAPER_FREQUENCY_HZ).contains(&v),
    allowed: "0 (off) or 1 to 1000 Hz: below 1 Hz a shaper lasts a second or more, and a shaper tuned above 1 kHz lasts under a millisecond and cancels nothing a printer's belts or frame carry (their modes are tens to a few hundred Hz); RepRapFirmware refuses M593 above 1000 Hz, and printer.cfg's shaper_freq_* and an M503 reply's M593 F are held to the same",
};

/// RepRapFirmware's `M593 F` limits, Hz (`AxisShaper::Configure`,
/// src/Movement/AxisShaper.cpp): at least `StepClockRate / (2 * 65535)` with Duet 3's
/// 750 kHz step clock (`src/RepRapFirmware.h`), at most 1000.
pub(crate) const RRF_MIN_SHAPER_FREQUENCY_HZ: f64 = 750_000.0 / (2.0 * 65535.0);
/// See [`RRF_MIN_SHAPER_FREQUENCY_HZ`].
pub(crate) const RRF_MAX_SHAPER_FREQUENCY_HZ: f64 = 1000.0;

/// RepRapFirmware's `M593 F`, Hz: `AxisShaper::Configure` (src/Movement/AxisShaper.cpp)
/// reads it with `TryGetLimitedFValue('F', ..., MinimumInputShapingFrequency,
/// MaximumInputShapingFrequency)`, whose `GetLimitedFValue`
/// (src/GCodes/GCodeBuffer/GCodeBuffer.cpp) throws "parameter 'F' too low" or "too high"
/// outside `StepClockRate / (2 * 65535)` (5.722 Hz on Duet 3's 750 kHz step clock) to
/// 1000, compared in single precision, before the type is looked at: `M593 P"none" F3`
/// is refused too.
pub(crate) const RRF_SHAPER_FREQUENCY: Check = Check {
    ok: |v| {
        let f = v as f32;
        f >= RRF_MIN_SHAPER_FREQUENCY_HZ as f32 && f <= RRF_MAX_SHAPER_FREQUENCY_HZ as f32
    },
    allowed: "5.722 to 1000 Hz: RepRapFirmware's M593 answers \"parameter 'F' too low\" (or \"too high\") and changes nothing (AxisShaper::Configure, src/Movement/AxisShaper.cpp; the least is StepClockRate / (2 x 65535) on Duet 3's 750 kHz step clock)",
};

/// Why `M493 D1`/`D2` is refused.
const FT_DYNAMIC_FREQUENCY: &str = "D1 (Z-based) and D2 (mass-based) make Marlin change the shaper frequency as the print goes, by F per mm of Z (D1) or of filament extruded (D2) (Marlin/src/module/ft_motion.cpp); settle shapes at the fixed frequency A only: remove D, or give D0";

/// The steps per mm settle plans with (Marlin's `M92` in a job and in an `M503` reply,
/// GRBL's `$100`-`$102`): 1 to 1e6.
pub(crate) const STEPS_PER_MM: Check = Check {
    ok: |v| (1.0..=1e6).contains(&v),
    allowed: STEPS_PER_MM_ALLOWED,
};

/// What [`STEPS_PER_MM`] allows, and why.
pub(crate) const STEPS_PER_MM_ALLOWED: &str = "1 to 1e6 steps/mm: the planner counts position in whole steps, so below 1 step/mm a step is longer than a millimetre (a 200-step motor at full step on a 40-tooth GT2 pulley, 80 mm a turn, makes 2.5), and above 1e6 the firmware's 32-bit step count overflows within 2.1 m of travel (Marlin's `xyze_long_t position` in Marlin/src/module/planner.h, GRBL's `int32_t sys_position` in grbl/main.c)";

/// Marlin's `M92` in a job: each of X, Y, Z, E given a number is checked against
/// [`STEPS_PER_MM`] (settle's reader does not follow it: the job's planner keeps the
/// configuration's steps). Other words (`T`, `MAGIC_NUMBERS_GCODE`'s `H` and `L`) are
/// not read.
pub(crate) fn marlin_steps(cmd: &Cmd, p: &Params) -> Result<(), GcodeError> {
    for letter in *b"XYZE" {
        if let crate::read::params::Value::Num(v) = p.get(letter)
            && !(STEPS_PER_MM.ok)(v)
        {
            return Err(cmd.out_of_range(
                Some(p.at(letter)),
                &char::from(letter).to_string(),
                v,
                STEPS_PER_MM.allowed,
            ));
        }
    }
    Ok(())
}

/// Why Marlin's `M593` refuses a `T`: the shaper type is Prusa's firmware's word.
const PRUSA_M593_T: &str = "T (the shaper type) is Prusa's firmware's (Prusa-Firmware-Buddy, on the MK4, MINI, XL and CORE One: 0 ZV, 1 ZVD, 2 MZV, 3 EI, 4 2HUMP_EI, 5 3HUMP_EI); Marlin's M593 shapes with ZV only and has no T: read a file sliced for a Prusa printer with --firmware prusa";

/// Per-axis values of X Y Z E scaled by `scale`; E may be a list (first value).
fn axes(cmd: &Cmd, p: &Params, check: Check, scale: f64) -> Result<AxisValues, GcodeError> {
    let get = |l| cmd.num(p, l, check).map(|v| v.map(|v| v * scale));
    Ok(AxisValues {
        x: get(b'X')?,
        y: get(b'Y')?,
        z: get(b'Z')?,
        e: cmd.first_num(p, b'E', check)?.map(|v| v * scale),
    })
}

fn flags(p: &Params) -> AxisFlags {
    AxisFlags {
        x: p.has(b'X'),
        y: p.has(b'Y'),
        z: p.has(b'Z'),
        e: p.has(b'E'),
    }
}

fn small(
    cmd: &Cmd,
    p: &Params,
    letter: u8,
    max: u32,
    allowed: &'static str,
) -> Result<Option<u32>, GcodeError> {
    match cmd.num(p, letter, SMALL_INT)? {
        Some(v) if v as u32 <= max => Ok(Some(v as u32)),
        Some(v) => Err(cmd.out_of_range(
            Some(p.at(letter)),
            &char::from(letter).to_string(),
            v,
            allowed,
        )),
        None => Ok(None),
    }
}

/// An `M` command with letter parameters. `args` of `cmd` must already be in `p`.
pub(crate) fn m_code(
    dialect: Dialect,
    cmd: &Cmd,
    number: u32,
    p: &Params,
) -> Result<Outcome, GcodeError> {
    use Dialect::*;
    let limits = |c| Ok(Outcome::Limits(c));
    let known = matches!(
        (dialect, number),
        (Marlin | Prusa | Rrf, 201 | 203 | 204 | 205 | 593) | (Marlin, 493 | 494) | (Rrf, 566)
    );
    if known && p.is_empty() {
        return Ok(Outcome::Nothing); // a report of the current values
    }
    match (dialect, number) {
        (Marlin | Prusa, 201) => {
            cmd.allow(
                p,
                b"XYZEFST",
                "X Y Z E (mm/s^2), F (Hz), S (%), T (extruder)",
            )?;
            limits(LimitChange::MaxAccel {
                per_axis_mm_s2: axes(cmd, p, POSITIVE, 1.0)?,
                xy_frequency_limit_hz: cmd.num(p, b'F', NON_NEGATIVE)?,
                xy_frequency_min_speed_pct: cmd.num(p, b'S', NON_NEGATIVE)?,
            })
        }
        (Rrf, 201) => {
            cmd.allow(p, b"XYZEUVWABCD", "X Y Z E ... (mm/s^2)")?;
            limits(LimitChange::MaxAccel {
                per_axis_mm_s2: axes(cmd, p, POSITIVE, 1.0)?,
                xy_frequency_limit_hz: None,
                xy_frequency_min_speed_pct: None,
            })
        }
        (Marlin | Prusa, 203) => {
            cmd.allow(p, b"XYZET", "X Y Z E (mm/s), T (extruder)")?;
            limits(LimitChange::MaxFeedrate {
                per_axis_mm_s: axes(cmd, p, POSITIVE, 1.0)?,
                min_speed_mm_s: None,
            })
        }
        (Rrf, 203) => {
            cmd.allow(
                p,
                b"XYZEISUVWABCD",
                "X Y Z E ... I (mm/min, or mm/s with S1), S (0 or 1)",
            )?;
            let scale = if cmd.num(p, b'S', BOOL)? == Some(1.0) {
                1.0
            } else {
                PER_MIN
            };
            limits(LimitChange::MaxFeedrate {
                per_axis_mm_s: axes(cmd, p, POSITIVE, scale)?,
                min_speed_mm_s: cmd.num(p, b'I', POSITIVE)?.map(|v| v * scale),
            })
        }
        (Klipper, 204) => {
            cmd.allow(p, b"SPTR", "S, or P and T (mm/s^2)")?;
            let (s, pp, t) = (
                cmd.num(p, b'S', POSITIVE)?,
                cmd.num(p, b'P', POSITIVE)?,
                cmd.num(p, b'T', POSITIVE)?,
            );
            let accel = match (s, pp, t) {
                (Some(s), _, _) => s,
                (None, Some(pp), Some(t)) => pp.min(t),
                _ => {
                    return Ok(Outcome::Note(Note::IgnoredByFirmware {
                        command: format!("M204{}", cmd.args.trim_end()),
                        reason: "Klipper's M204 needs S, or both P and T (klippy/toolhead.py cmd_M204)",
                    }));
                }
            };
            limits(velocity_limit(None, Some(accel)))
        }
        (Marlin | Prusa | Rrf, 204) => {
            cmd.allow(p, b"PRST", "P T S R (mm/s^2)")?;
            let s = cmd.num(p, b'S', POSITIVE)?;
            let retract = cmd.num(p, b'R', POSITIVE)?;
            limits(LimitChange::Accel {
                print_mm_s2: cmd.num(p, b'P', POSITIVE)?.or(s),
                travel_mm_s2: cmd.num(p, b'T', POSITIVE)?.or(s),
                retract_mm_s2: if dialect.is_marlin() { retract } else { None },
            })
        }
        (Marlin | Prusa, 205) => {
            cmd.allow(p, b"BSTJXYZE", "B (us) S T (mm/s) J (mm) X Y Z E (mm/s)")?;
            limits(LimitChange::MarlinAdvanced {
                junction_deviation_mm: cmd.num(p, b'J', POSITIVE)?,
                jerk_mm_s: axes(cmd, p, NON_NEGATIVE, 1.0)?,
                min_feedrate_mm_s: cmd.num(p, b'S', NON_NEGATIVE)?,
                min_travel_feedrate_mm_s: cmd.num(p, b'T', NON_NEGATIVE)?,
                // `parser.value_ulong()` is `strtoul(value_ptr, NULL, 10)` (Marlin's
                // Marlin/src/gcode/parser.h): the digits before a `.`, so `B20000.7` is
                // 20000 us, truncated, not rounded.
                min_segment_time_s: cmd
                    .num(p, b'B', MIN_SEGMENT_TIME_US)?
                    .map(|us| us.trunc() * 1e-6),
            })
        }
        (Rrf, 205 | 566) => {
            // Axes beyond X Y Z E (U V W A B C D) are accepted and not reported.
            let (allowed, scale): (&[u8], f64) = if number == 205 {
                (b"XYZEUVWABCD", 1.0)
            } else {
                (b"XYZEPUVWABCD", PER_MIN)
            };
            cmd.allow(
                p,
                allowed,
                if number == 205 {
                    "X Y Z E ... (mm/s)"
                } else {
                    "X Y Z E ... (mm/min), P (policy)"
                },
            )?;
            limits(LimitChange::RrfJerk {
                per_axis_mm_s: axes(cmd, p, NON_NEGATIVE, scale)?,
                policy: small(cmd, p, b'P', 1, "0 or 1")?,
                sets_maximum: number == 566,
            })
        }
        (Marlin, 593) => {
            if p.has(b'T') {
                return Err(cmd.unsupported(PRUSA_M593_T));
            }
            cmd.allow(p, b"XYZDF", "X Y Z (flags), D (damping ratio), F (Hz)")?;
            limits(LimitChange::MarlinInputShaping {
                axes: flags(p),
                frequency_hz: cmd.num(p, b'F', SHAPER_FREQUENCY)?,
                damping_ratio: cmd.num(p, b'D', FRACTION)?,
            })
        }
        (Prusa, 593) => {
            cmd.allow(
                p,
                b"XYZTFDRAMW",
                "X Y Z (flags), T (0-6), F (Hz), D (damping ratio), R (> 0), A (Hz, < 0), M (g), W",
            )?;
            let below_zero = Check {
                ok: |v| v < 0.0,
                allowed: "below 0 (Hz)",
            };
            limits(LimitChange::PrusaInputShaping {
                axes: flags(p),
                shaper_type: small(cmd, p, b'T', 6, "0 to 6")?,
                frequency_hz: cmd.num(p, b'F', NON_NEGATIVE)?,
                damping_ratio: cmd.num(p, b'D', FRACTION)?,
                vibration_reduction: cmd.num(p, b'R', POSITIVE)?,
                weight_frequency_delta_hz: cmd.num(p, b'A', below_zero)?,
                weight_mass_limit_g: cmd.num(p, b'M', NON_NEGATIVE)?,
                save: p.has(b'W'),
            })
        }
        (Rrf, 593) => {
            cmd.allow(
                p,
                b"PFSLHT",
                "P\"type\" F (Hz) S (damping) L (limit) H (amplitudes) T (durations, s)",
            )?;
            let damping = Check {
                ok: |v| (0.0..=0.99).contains(&v),
                allowed: "0 to 0.99",
            };
            limits(LimitChange::RrfInputShaping {
                shaper: cmd.string(p, b'P')?.map(|s| s.to_ascii_lowercase()),
                frequency_hz: cmd.num(p, b'F', RRF_SHAPER_FREQUENCY)?,
                damping_ratio: cmd.num(p, b'S', damping)?,
                reduction_limit: cmd.num(p, b'L', FRACTION)?,
                amplitudes: cmd.list(p, b'H', FINITE)?,
                durations_s: cmd.list(p, b'T', NON_NEGATIVE)?,
            })
        }
        (Marlin, 493) => {
            cmd.allow(
                p,
                b"SHCDAFIQXYZE",
                "S H (0/1) C (0-8) D (0-2) A (Hz) F I Q, X Y Z E (flags)",
            )?;
            let shaper = small(cmd, p, b'C', 8, "0 to 8")?.and_then(FtShaper::from_code);
            let dynamic_mode = small(cmd, p, b'D', 2, "0 to 2")?;
            if dynamic_mode.is_some_and(|d| d > 0) {
                return Err(cmd.unsupported(FT_DYNAMIC_FREQUENCY));
            }
            limits(LimitChange::FtMotion {
                enabled: cmd.num(p, b'S', BOOL)?.map(|v| v == 1.0),
                axis_sync: cmd.num(p, b'H', BOOL)?.map(|v| v == 1.0),
                axes: flags(p),
                shaper,
                dynamic_mode,
                frequency_hz: cmd.num(p, b'A', FT_FREQUENCY)?,
                frequency_scaling: cmd.num(p, b'F', FINITE)?,
                damping_ratio: cmd.num(p, b'I', FT_DAMPING)?,
                vibration_tolerance: cmd.num(p, b'Q', FRACTION)?,
            })
        }
        (Marlin, 494) => {
            cmd.allow(p, b"TOXYZE", "T (0-2) O (overshoot) X Y Z E (s)")?;
            limits(LimitChange::FtSmoothing {
                trajectory: small(cmd, p, b'T', 2, "0 to 2")?,
                overshoot: cmd.num(p, b'O', FT_OVERSHOOT)?,
                smoothing_s: axes(cmd, p, FT_SMOOTHING_S, 1.0)?,
            })
        }
        _ => Ok(Outcome::Unknown),
    }
}

fn velocity_limit(velocity: Option<f64>, accel: Option<f64>) -> LimitChange {
    LimitChange::VelocityLimit {
        velocity_mm_s: velocity,
        accel_mm_s2: accel,
        accel_to_decel_mm_s2: None,
        square_corner_velocity_mm_s: None,
        minimum_cruise_ratio: None,
    }
}

const VELOCITY_KEYS: [&str; 5] = [
    "VELOCITY",
    "ACCEL",
    "ACCEL_TO_DECEL",
    "SQUARE_CORNER_VELOCITY",
    "MINIMUM_CRUISE_RATIO",
];
const SHAPER_KEYS: [&str; 10] = [
    "SHAPER_TYPE",
    "SHAPER_TYPE_X",
    "SHAPER_TYPE_Y",
    "SHAPER_TYPE_Z",
    "SHAPER_FREQ_X",
    "SHAPER_FREQ_Y",
    "SHAPER_FREQ_Z",
    "DAMPING_RATIO_X",
    "DAMPING_RATIO_Y",
    "DAMPING_RATIO_Z",
];

/// A named (`KEY=VALUE`) command; only Klipper has motion-limit ones.
pub(crate) fn named(
    dialect: Dialect,
    cmd: &Cmd,
    name: &str,
    kv: &KeyValues,
) -> Result<Outcome, GcodeError> {
    if dialect != Dialect::Klipper {
        return Ok(Outcome::Unknown);
    }
    let num = |key: &str, check: Check| -> Result<Option<f64>, GcodeError> {
        kv.pairs()
            .iter()
            .find(|(k, _, _)| k == key)
            .map(|(k, v, at)| cmd.kv_num(*at, k, v, check))
            .transpose()
    };
    let text = |key: &str| {
        kv.pairs()
            .iter()
            .find(|(k, _, _)| k == key)
            .map(|(_, v, _)| v.to_ascii_lowercase())
    };
    if name.eq_ignore_ascii_case("SET_VELOCITY_LIMIT") {
        cmd.kv_unknown(
            kv,
            &VELOCITY_KEYS,
            "VELOCITY ACCEL ACCEL_TO_DECEL SQUARE_CORNER_VELOCITY MINIMUM_CRUISE_RATIO",
        )?;
        if kv.pairs().is_empty() {
            return Ok(Outcome::Nothing);
        }
        return Ok(Outcome::Limits(LimitChange::VelocityLimit {
            velocity_mm_s: num("VELOCITY", POSITIVE)?,
            accel_mm_s2: num("ACCEL", POSITIVE)?,
            accel_to_decel_mm_s2: num("ACCEL_TO_DECEL", POSITIVE)?,
            square_corner_velocity_mm_s: num("SQUARE_CORNER_VELOCITY", NON_NEGATIVE)?,
            minimum_cruise_ratio: num("MINIMUM_CRUISE_RATIO", BELOW_ONE)?,
        }));
    }
    if name.eq_ignore_ascii_case("SET_INPUT_SHAPER") {
        cmd.kv_unknown(
            kv,
            &SHAPER_KEYS,
            "SHAPER_TYPE(_X/_Y/_Z) SHAPER_FREQ_X/_Y/_Z DAMPING_RATIO_X/_Y/_Z",
        )?;
        if kv.pairs().is_empty() {
            return Ok(Outcome::Nothing);
        }
        let per_axis = [
            text("SHAPER_TYPE_X"),
            text("SHAPER_TYPE_Y"),
            text("SHAPER_TYPE_Z"),
        ];
        let shaper_type = text("SHAPER_TYPE");
        if shaper_type.is_some() && per_axis.iter().any(Option::is_some) {
            return Err(GcodeError::Syntax {
                at: cmd.at(None),
                what: "SHAPER_TYPE cannot be combined with SHAPER_TYPE_X/_Y/_Z (Klipper docs/G-Codes.md)",
            });
        }
        return Ok(Outcome::Limits(LimitChange::InputShaper {
            shaper_type,
            shaper_type_xyz: per_axis,
            frequency_hz_xyz: [
                num("SHAPER_FREQ_X", SHAPER_FREQUENCY)?,
                num("SHAPER_FREQ_Y", SHAPER_FREQUENCY)?,
                num("SHAPER_FREQ_Z", SHAPER_FREQUENCY)?,
            ],
            damping_ratio_xyz: [
                num("DAMPING_RATIO_X", FRACTION)?,
                num("DAMPING_RATIO_Y", FRACTION)?,
                num("DAMPING_RATIO_Z", FRACTION)?,
            ],
        }));
    }
    Ok(Outcome::Unknown)
}
