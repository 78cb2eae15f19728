//! The recommendation as firmware configuration that pastes cleanly, each parsed back by
//! `settle import` in `tests/all/import_roundtrip.rs`:
//!
//! - `klipper.cfg`: one `[input_shaper]` section with per-axis `shaper_type_x/y`,
//!   `shaper_freq_x/y`, `damping_ratio_x/y`, and `[printer]` `max_accel` only when the
//!   recommended acceleration differs from the current one (settle-gcode's
//!   `KlipperExport`). Written when both X and Y are known: tuned, or their current
//!   settings given in `[tune.axis.<name>]` (an axis left out would be written as "off"),
//!   and only when every tuned axis's recommendation is something Klipper runs (a
//!   trapezoid with one of its shapers: [`super::target::expressible`]).
//! - `rrf.g`: RepRapFirmware's one `M593` line (one shaper for every axis; settle-gcode's
//!   `RrfExport`), the shaper of the lowest-frequency tuned axis, since a shaper tuned
//!   below a mode still reduces it, one tuned above it much less (the responses in
//!   `planner/src/shaper/response.rs`); `M204` when the acceleration changes, and `M201`
//!   where an axis's cap (`[tune.axis.<name>] max_accel_mm_s2`) is below the recommended
//!   acceleration, or is not known while the acceleration changes; `M593 P"none"` alone
//!   for an unshaped trapezoid; nothing for what RepRapFirmware does not plan.
//!
//! Every value that differs from the current one carries a comment above it: what it was
//! and why it changed ([`super::changes`]); a machine that is a built-in preset standing in
//! for the user's printer is named in the header.
//! - `marlin.gcode`: for the input shaper of the printer's build (`[tune] marlin_shaping`),
//!   Fixed-Time Motion's `M493 S1` and one `M493 <axis> C A I [Q]` line per tuned axis
//!   (settle-gcode's `MarlinExport`), or the built-in ZV shaper's one `M593 <axis> F D`
//!   line per tuned axis, `F0` unshaped (settle-gcode's `MarlinZvExport`); Marlin shapes X
//!   and Y apart. Then `M204 P T` when the acceleration changes, with `M201` as in
//!   `rrf.g`. Read back by settle's G-code reader in `tests/all/tune_firmware.rs` and
//!   `tests/all/import_marlin.rs`. An axis not tuned is left as it is, and said. An
//!   `M493 A` below `FTM_MIN_SHAPE_FREQ` (10 Hz) or above `FTM_FS / 2`, which Marlin's
//!   `M493` answers with `?Invalid`, is not written (`tests/all/tune_firmware.rs`).
//! - `prusa.gcode`: Prusa-Firmware-Buddy's `M593 <axis> T F D [R]` line per tuned axis
//!   (settle-gcode's `PrusaExport`; `F0` unshaped), `M593 W` to store them, then `M201`
//!   and `M204` as in `marlin.gcode` (Buddy plans with Marlin's planner). Written when
//!   every tuned axis's recommendation is one of Buddy's six shapers at 10 to 100 Hz
//!   (`--firmware prusa`). Read back by settle's G-code reader in
//!   `tests/all/tune_firmware.rs`. An axis not tuned is left as it is, and said.
//! - `tmc4361a.txt`: per axis, the TMC4361A ramp registers of the recommended move, from
//!   the axis's own microsteps per mm; refused, with the reason, for what the chip cannot
//!   run (a trapezoid's infinite bows, an input shaper, a value outside a register).
//!
//! A file whose exporter refuses a value says why in its place, and `tune.md` has no
//! "What changes in" table for it (`tests/all/export_roundtrip.rs` reads each written file
//! back against `candidates.csv`).

use std::fmt::Write as _;

use settle_gcode::FtShaper;
use settle_gcode::config::{
    FtAxisShaper, KlipperExport, MarlinExport, MarlinZvExport, Note, PrusaAxisShaper, PrusaExport,
    RrfExport, ShaperSetting as FirmwareShaper, ZvAxisShaper,
};
use settle_planner::ProfileKind;
use settle_planner::firmware::Firmware;
use settle_planner::shaper::{MARLIN_FTM_FS_HZ, ShaperType};
use settle_planner::tmc::ramp::SRampParams;
use settle_planner::tmc::registers::{TmcUnits, export};

use super::Outcome;
use super::firmware::{Candidates, MarlinShaping};
use super::search::Score;
use super::{changes, head, target};
use crate::studies::corner::Corner;
use crate::studies::shaping::DEFAULT_DAMPING_RATIO;

/// The TMC4361A clock assumed when `[tune] tmc_clock_hz` is not given (Hz). In the chip's
/// default (frequency) mode the clock appears only in CLK_FREQ, so the ramp registers do
/// not depend on it; give the board's clock to have CLK_FREQ right.
pub const DEFAULT_TMC_CLOCK_HZ: u32 = 16_000_000;

/// The winner of the axis `letter` (`x`, `y`), from an outcome tuned on it (a corner path
/// `x+y` moves both).
fn winner_of<'a>(axes: &'a [(String, Outcome)], letter: &str) -> Option<&'a Outcome> {
    axes.iter()
        .find(|(a, _)| a.split('+').any(|x| x == letter))
        .map(|(_, o)| o)
}

/// The firmware shaper of a score: `None` when the candidate is unshaped.
fn shaper_of(s: &Score) -> Option<FirmwareShaper> {
    let sh = s.candidate.shaper?;
    let k = sh.shaper_type?;
    Some(FirmwareShaper {
        name: k.name(),
        frequency_hz: sh.frequency_hz,
        damping_ratio: sh.damping_ratio,
    })
}

/// Klipper's "no shaping" on an axis: frequency 0 (`klippy/extras/input_shaper.py`).
fn klipper_off() -> FirmwareShaper {
    FirmwareShaper {
        name: "mzv".into(),
        frequency_hz: 0.0,
        damping_ratio: target::KLIPPER_OFF_DAMPING,
    }
}

/// The header notes of an export: the stand-in machine, if any.
fn header_notes(axes: &[(String, Outcome)]) -> Vec<Note> {
    head::stand_in(axes)
        .into_iter()
        .map(|text| Note {
            key: String::new(),
            text,
        })
        .collect()
}

/// Axis `letter`'s shaper for Klipper: the tuned winner's, else the current one from
/// `[tune.axis.<letter>]`; `Err` names what is missing.
fn klipper_axis(axes: &[(String, Outcome)], letter: &str) -> Result<FirmwareShaper, String> {
    if let Some(o) = winner_of(axes, letter) {
        let w = &o.scores[o.winner];
        if let Err(why) = target::expressible(Candidates::of(Firmware::Klipper), &w.candidate) {
            return Err(format!(
                "the recommendation on {letter}, {}, is not something Klipper runs ({why}); tune with --firmware klipper",
                w.candidate.label()
            ));
        }
        return Ok(shaper_of(w).unwrap_or_else(klipper_off));
    }
    let current = axes
        .first()
        .and_then(|(_, o)| o.plan.spec.axis.as_ref())
        .and_then(|m| m.get(letter));
    match current {
        Some(c) => match (c.shaper.as_deref(), c.frequency_hz) {
            (Some("none"), _) | (_, None) => Ok(klipper_off()),
            (name, Some(f)) => Ok(FirmwareShaper {
                name: name.unwrap_or("mzv").to_string(),
                frequency_hz: f,
                damping_ratio: c.damping_ratio.unwrap_or(DEFAULT_DAMPING_RATIO),
            }),
        },
        None => Err(format!(
            "axis {letter} was not tuned and its current shaper is not known: tune it too ([tune] axes = [\"x\", \"y\"]) or give [tune.axis.{letter}]"
        )),
    }
}

/// The recommended acceleration: the lowest of the axes' winners (Klipper and
/// RepRapFirmware have one for all axes), and whether it differs from the current one.
fn accel(axes: &[(String, Outcome)]) -> Option<(f64, bool)> {
    let rec = axes
        .iter()
        .map(|(_, o)| o.scores[o.winner].accel_mm_s2)
        .fold(f64::INFINITY, f64::min);
    let cur = axes
        .iter()
        .map(|(_, o)| o.scores[0].accel_mm_s2)
        .fold(f64::INFINITY, f64::min);
    rec.is_finite().then_some((rec, rec != cur))
}

/// Axis `letter`'s acceleration cap from `[tune.axis.<letter>] max_accel_mm_s2` (Marlin's
/// and RepRapFirmware's `M201`, as `settle import` reads it); `None` when not known.
fn cap_of(axes: &[(String, Outcome)], letter: &str) -> Option<f64> {
    axes.first()
        .and_then(|(_, o)| o.plan.spec.axis.as_ref())
        .and_then(|m| m.get(letter))
        .and_then(|a| a.max_accel_mm_s2)
        .filter(|c| c.is_finite() && *c > 0.0)
}

/// The `M201 X`, `Y` that `marlin.gcode` and `rrf.g` write, with each axis's cap as it was:
/// both firmwares cap every move's acceleration by `M201` too, so an axis whose cap is
/// below the recommended acceleration is raised to it; one whose cap is not known is set
/// to it when the acceleration changes. A cap at or above it is left as it is (lowering
/// it would also cap what the slicer's own `M204` asks for).
fn m201(axes: &[(String, Outcome)]) -> [(Option<f64>, Option<f64>); 2] {
    let rec = accel(axes);
    ["x", "y"].map(|letter| {
        let cap = cap_of(axes, letter);
        let write = match (rec, cap) {
            (Some((a, _)), Some(c)) => (c < a).then_some(a),
            (Some((a, changed)), None) => changed.then_some(a),
            (None, _) => None,
        };
        (write, cap)
    })
}

/// What `klipper.cfg` writes, or why it is not written.
fn klipper_export(axes: &[(String, Outcome)], produced_by: &str) -> Result<KlipperExport, String> {
    let (x, y) = (klipper_axis(axes, "x")?, klipper_axis(axes, "y")?);
    let scv = axes.iter().find_map(|(_, o)| {
        o.plan
            .base
            .state::<Corner>()
            .filter(|c| c.strategy.name() == "square_corner_velocity")
            .map(|c| c.square_corner_velocity_mm_s)
    });
    let max_accel = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    Ok(KlipperExport {
        produced_by: produced_by.to_string(),
        x,
        y,
        max_accel_mm_s2: max_accel,
        minimum_cruise_ratio: None,
        square_corner_velocity_mm_s: scv,
    })
}

/// `klipper.cfg`: the snippet, or comments saying why it is not written.
pub fn klipper(axes: &[(String, Outcome)], produced_by: &str) -> String {
    let e = match klipper_export(axes, produced_by) {
        Ok(e) => e,
        Err(why) => return format!("# no Klipper configuration: {why}\n"),
    };
    let mut notes = header_notes(axes);
    notes.extend(
        changes::klipper(axes, e.max_accel_mm_s2)
            .iter()
            .map(changes::Change::note),
    );
    match e.to_config_with_notes(&notes) {
        Ok(text) => text,
        Err(err) => format!("# no Klipper configuration: {err}\n"),
    }
}

/// The changes `klipper.cfg` makes (`None` when it is not written: a recommendation Klipper
/// does not run, or a value its exporter refuses).
pub fn klipper_changes(axes: &[(String, Outcome)]) -> Option<Vec<changes::Change>> {
    let e = klipper_export(axes, "").ok()?;
    e.to_config().ok()?;
    Some(changes::klipper(axes, e.max_accel_mm_s2))
}

/// The axis whose shaper `rrf.g` writes (the lowest-frequency tuned axis's), and its
/// recommendation.
fn rrf_axis(axes: &[(String, Outcome)]) -> Option<(&str, &Score)> {
    let mut shaped: Vec<(&str, &Score)> = axes
        .iter()
        .map(|(a, o)| (a.as_str(), &o.scores[o.winner]))
        .collect();
    shaped.sort_by(|a, b| {
        let f = |s: &Score| {
            s.candidate
                .shaper
                .filter(|sh| sh.shaper_type.is_some())
                .map_or(f64::INFINITY, |sh| sh.frequency_hz)
        };
        f(a.1).total_cmp(&f(b.1))
    });
    shaped.first().copied()
}

/// Why the export for `runs` (named `who`) is not written, if it is not: a tuned axis's
/// recommendation that the firmware does not run.
fn refusal(axes: &[(String, Outcome)], runs: Candidates, who: &str) -> Option<String> {
    if axes.is_empty() {
        return Some("nothing was tuned".into());
    }
    axes.iter().find_map(|(a, o)| {
        let w = &o.scores[o.winner];
        target::expressible(runs, &w.candidate).err().map(|why| {
            format!(
                "the recommendation on {a}, {}, is not something {who} runs ({why}); tune with --firmware {}",
                w.candidate.label(),
                runs.name()
            )
        })
    })
}

/// Why `rrf.g` is not written, if it is not.
fn rrf_refusal(axes: &[(String, Outcome)]) -> Option<String> {
    refusal(axes, Candidates::of(Firmware::Rrf), "RepRapFirmware")
}

/// What `rrf.g` writes and the axis whose shaper it is, or why it is not written.
fn rrf_export<'a>(
    axes: &'a [(String, Outcome)],
    produced_by: &str,
) -> Result<(RrfExport, &'a str), String> {
    if let Some(why) = rrf_refusal(axes) {
        return Err(why);
    }
    let Some((axis, w)) = rrf_axis(axes) else {
        return Err("nothing was tuned".into());
    };
    let shaper = shaper_of(w).unwrap_or(FirmwareShaper {
        name: "none".into(),
        frequency_hz: f64::NAN,
        damping_ratio: f64::NAN,
    });
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    let e = RrfExport {
        produced_by: produced_by.to_string(),
        shaper,
        max_accel_xy_mm_s2: m201(axes).map(|(w, _)| w),
        print_accel_mm_s2: a,
        travel_accel_mm_s2: a,
    };
    Ok((e, axis))
}

/// `rrf.g`: the `M593` line (and `M204` when the acceleration changes), or comments saying
/// why it is not written.
pub fn rrf(axes: &[(String, Outcome)], produced_by: &str) -> String {
    let (e, axis) = match rrf_export(axes, produced_by) {
        Ok(found) => found,
        Err(why) => return format!("; no RepRapFirmware configuration: {why}\n"),
    };
    let mut others = String::new();
    for (a, o) in axes.iter().filter(|(a, _)| a != axis) {
        let _ = writeln!(
            others,
            "; axis {a} alone would take {} (RepRapFirmware has one shaper for all axes: the lowest-frequency axis's is written)",
            super::cells::shaper_text(&o.scores[o.winner])
        );
    }
    let a = e.print_accel_mm_s2;
    let caps = m201(axes);
    let mut notes = header_notes(axes);
    notes.extend(
        changes::rrf(axes, axis, caps, a)
            .iter()
            .map(changes::Change::note),
    );
    // The other axes' own choices follow the lines (the file starts with its header).
    match e.to_config_with_notes(&notes) {
        Ok(text) => format!("{text}{others}"),
        Err(err) => format!("; no RepRapFirmware configuration: {err}\n{others}"),
    }
}

/// The changes `rrf.g` makes (`None` when it is not written: a recommendation
/// RepRapFirmware does not run, or a value its exporter refuses).
pub fn rrf_changes(axes: &[(String, Outcome)]) -> Option<Vec<changes::Change>> {
    let (e, axis) = rrf_export(axes, "").ok()?;
    e.to_config().ok()?;
    Some(changes::rrf(axes, axis, m201(axes), e.print_accel_mm_s2))
}

/// Marlin's input shaper the tune was for (`[tune] marlin_shaping`; Fixed-Time Motion
/// unless the tune searched Marlin's built-in input shaping).
fn marlin_shaping(axes: &[(String, Outcome)]) -> MarlinShaping {
    axes.first().map_or(MarlinShaping::FtMotion, |(_, o)| {
        o.plan.firmware.marlin_shaping()
    })
}

/// Why `marlin.gcode` is not written, if it is not.
fn marlin_refusal(axes: &[(String, Outcome)]) -> Option<String> {
    let runs = Candidates::of(Firmware::Marlin).with_marlin_shaping(marlin_shaping(axes));
    refusal(axes, runs, "Marlin")
}

/// Axis `letter`'s `M493` values from its tuned winner (`C0` unshaped), and the `FTM_FS`
/// it was designed for; `None` when the axis was not tuned.
fn marlin_axis(axes: &[(String, Outcome)], letter: &str) -> Option<(FtAxisShaper, Option<u32>)> {
    let o = winner_of(axes, letter)?;
    let w = &o.scores[o.winner];
    let axis = letter.to_ascii_uppercase().chars().next()?;
    let off = FtAxisShaper {
        axis,
        shaper: FtShaper::None,
        frequency_hz: f64::NAN,
        damping_ratio: f64::NAN,
        vibration_tolerance: None,
    };
    let Some(sh) = w.candidate.shaper else {
        return Some((off, None));
    };
    match sh.shaper_type {
        Some(ShaperType::Marlin {
            shaper,
            v_tol,
            ftm_fs_hz,
        }) => {
            let code = u32::from(shaper.m493_code());
            let ft = FtAxisShaper {
                shaper: FtShaper::from_code(code)?,
                frequency_hz: sh.frequency_hz,
                damping_ratio: sh.damping_ratio,
                vibration_tolerance: shaper.has_v_tol().then_some(v_tol),
                ..off
            };
            Some((ft, Some(ftm_fs_hz)))
        }
        _ => Some((off, None)),
    }
}

/// Axis `letter`'s `M593` values from its tuned winner (`F0` unshaped); `None` when the
/// axis was not tuned. The search ran only `marlin:m593` ([`super::firmware::Candidates`]),
/// whose F and D are the `M593` ones: Marlin computes the shaper from them as it did.
fn marlin_zv_axis(axes: &[(String, Outcome)], letter: &str) -> Option<ZvAxisShaper> {
    let o = winner_of(axes, letter)?;
    let w = &o.scores[o.winner];
    let axis = letter.to_ascii_uppercase().chars().next()?;
    Some(match w.candidate.shaper {
        Some(sh) if sh.shaper_type == Some(ShaperType::MarlinM593) => ZvAxisShaper {
            axis,
            frequency_hz: sh.frequency_hz,
            damping_ratio: sh.damping_ratio,
        },
        _ => ZvAxisShaper {
            axis,
            frequency_hz: 0.0,
            damping_ratio: f64::NAN,
        },
    })
}

/// `marlin.gcode`: Marlin Fixed-Time Motion's `M493` lines per tuned axis, or with
/// `[tune] marlin_shaping = "input_shaping"` its built-in ZV shaper's `M593` lines;
/// `M201`/`M204` as the module documentation says; or comments saying why it is not
/// written.
pub fn marlin(axes: &[(String, Outcome)], produced_by: &str) -> String {
    if let Some(why) = marlin_refusal(axes) {
        return format!("; no Marlin configuration: {why}\n");
    }
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    let mut notes = header_notes(axes);
    notes.extend(
        changes::marlin(axes, marlin_shaping(axes), m201(axes), a)
            .iter()
            .map(changes::Change::note),
    );
    marlin_text(axes, produced_by, &notes)
        .unwrap_or_else(|err| format!("; no Marlin configuration: {err}\n"))
}

/// `marlin.gcode`'s lines with `notes` above theirs, or why the exporter refuses them (a
/// value Marlin would not take: settle-gcode's `MarlinExport`, `MarlinZvExport`).
fn marlin_text(
    axes: &[(String, Outcome)],
    produced_by: &str,
    notes: &[Note],
) -> Result<String, String> {
    let shaping = marlin_shaping(axes);
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    let max_accel_xy_mm_s2 = m201(axes).map(|(w, _)| w);
    let (text, command) = match shaping {
        MarlinShaping::InputShaping => {
            let (axes_written, untuned) = per_axis(|l| marlin_zv_axis(axes, l));
            let e = MarlinZvExport {
                produced_by: produced_by.to_string(),
                axes: axes_written,
                max_accel_xy_mm_s2,
                print_accel_mm_s2: a,
                travel_accel_mm_s2: a,
            };
            (e.to_config_with_notes(notes), ("M593", untuned))
        }
        MarlinShaping::FtMotion => {
            let (written, untuned) = per_axis(|l| marlin_axis(axes, l));
            // The last tuned axis's sample rate where it sets one.
            let ftm_fs_hz = written
                .iter()
                .rev()
                .find_map(|(_, fs)| *fs)
                .unwrap_or(MARLIN_FTM_FS_HZ);
            let e = MarlinExport {
                produced_by: produced_by.to_string(),
                ftm_fs_hz,
                axes: written.into_iter().map(|(ft, _)| ft).collect(),
                max_accel_xy_mm_s2,
                print_accel_mm_s2: a,
                travel_accel_mm_s2: a,
            };
            (e.to_config_with_notes(notes), ("M493", untuned))
        }
    };
    let (command, untuned) = command;
    let mut out = text.map_err(|err| err.to_string())?;
    for letter in untuned {
        let _ = writeln!(
            out,
            "; axis {letter} was not tuned: its {command} {} settings stay as they are (Marlin shapes X and Y apart; set both)",
            letter.to_ascii_uppercase()
        );
    }
    Ok(out)
}

/// What `of` gives for axes `x` and `y`, and the letters of those it gives nothing for
/// (not tuned).
fn per_axis<T>(of: impl Fn(&str) -> Option<T>) -> (Vec<T>, Vec<&'static str>) {
    let (mut given, mut not) = (Vec::new(), Vec::new());
    for letter in ["x", "y"] {
        match of(letter) {
            Some(t) => given.push(t),
            None => not.push(letter),
        }
    }
    (given, not)
}

/// The changes `marlin.gcode` makes (`None` when it is not written: a recommendation
/// Marlin does not run, or a value its exporter refuses, such as an `M493 A` below
/// `FTM_MIN_SHAPE_FREQ`).
pub fn marlin_changes(axes: &[(String, Outcome)]) -> Option<Vec<changes::Change>> {
    if marlin_refusal(axes).is_some() {
        return None;
    }
    marlin_text(axes, "", &[]).ok()?;
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    Some(changes::marlin(axes, marlin_shaping(axes), m201(axes), a))
}

/// Why `prusa.gcode` is not written, if it is not.
fn prusa_refusal(axes: &[(String, Outcome)]) -> Option<String> {
    refusal(
        axes,
        Candidates::of(Firmware::Prusa),
        "Prusa-Firmware-Buddy",
    )
}

/// Axis `letter`'s `M593` values from its tuned winner (no shaper: `F0`); `None` when the
/// axis was not tuned.
fn prusa_axis(axes: &[(String, Outcome)], letter: &str) -> Option<PrusaAxisShaper> {
    let o = winner_of(axes, letter)?;
    let w = &o.scores[o.winner];
    let axis = letter.to_ascii_uppercase().chars().next()?;
    let shaper = w.candidate.shaper.and_then(|sh| {
        sh.shaper_type
            .map(|k| (k, sh.frequency_hz, sh.damping_ratio))
    });
    Some(PrusaAxisShaper { axis, shaper })
}

/// `prusa.gcode`: Prusa-Firmware-Buddy's `M593` lines per tuned axis and `M593 W`,
/// `M201`/`M204` as the module documentation says; or comments saying why it is not
/// written.
pub fn prusa(axes: &[(String, Outcome)], produced_by: &str) -> String {
    if let Some(why) = prusa_refusal(axes) {
        return format!("; no Prusa-Firmware-Buddy configuration: {why}\n");
    }
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    let caps = m201(axes);
    let mut notes = header_notes(axes);
    notes.extend(
        changes::prusa(axes, caps, a)
            .iter()
            .map(changes::Change::note),
    );
    let (e, untuned) = prusa_export(axes, produced_by);
    match e.to_config_with_notes(&notes) {
        Ok(mut out) => {
            for letter in untuned {
                let _ = writeln!(
                    out,
                    "; axis {letter} was not tuned: its M593 {} settings stay as they are (Buddy shapes X and Y apart)",
                    letter.to_ascii_uppercase()
                );
            }
            out
        }
        Err(err) => format!("; no Prusa-Firmware-Buddy configuration: {err}\n"),
    }
}

/// What `prusa.gcode` writes, and the letters of the axes not tuned.
fn prusa_export(axes: &[(String, Outcome)], produced_by: &str) -> (PrusaExport, Vec<&'static str>) {
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    let (written, untuned) = per_axis(|l| prusa_axis(axes, l));
    let e = PrusaExport {
        produced_by: produced_by.to_string(),
        axes: written,
        max_accel_xy_mm_s2: m201(axes).map(|(w, _)| w),
        print_accel_mm_s2: a,
        travel_accel_mm_s2: a,
    };
    (e, untuned)
}

/// The changes `prusa.gcode` makes (`None` when it is not written: a recommendation
/// Prusa-Firmware-Buddy does not run, or a value its exporter refuses).
pub fn prusa_changes(axes: &[(String, Outcome)]) -> Option<Vec<changes::Change>> {
    if prusa_refusal(axes).is_some() {
        return None;
    }
    prusa_export(axes, "").0.to_config().ok()?;
    let a = accel(axes).and_then(|(a, changed)| changed.then_some(a));
    Some(changes::prusa(axes, m201(axes), a))
}

/// `tmc4361a.txt`: per axis, the register file of the recommended move (the first of the
/// move family), or why the chip cannot run it.
pub fn tmc4361a(axes: &[(String, Outcome)]) -> String {
    let mut out = String::new();
    for (axis, o) in axes {
        let _ = writeln!(out, "# axis {axis}");
        match tmc_axis(axis, o) {
            Ok(text) => out.push_str(&text),
            Err(why) => {
                let _ = writeln!(out, "# not written: {why}");
            }
        }
    }
    out
}

fn tmc_axis(axis: &str, o: &Outcome) -> Result<String, String> {
    let plan = &o.plan;
    let w = &o.scores[o.winner];
    let c = &w.candidate;
    let b = &plan.base;
    if c.shaper.is_some_and(|sh| sh.shaper_type.is_some()) {
        return Err(format!(
            "the recommendation {} is input-shaped; the TMC4361A's ramp generator cannot shape (tune with --firmware tmc4361a)",
            c.label()
        ));
    }
    let Some(j) = c.jmax_mm_s3 else {
        return Err(
            "the recommendation is a trapezoid, whose bows are infinite; the TMC4361A runs S-shaped ramps (tune with --firmware tmc4361a)".into(),
        );
    };
    if matches!(c.kind, ProfileKind::PvtAsym | ProfileKind::PvtSym) {
        return Err(format!(
            "{} is a PVT profile; the TMC4361A runs S-shaped ramps (tune with --firmware tmc4361a)",
            c.kind
        ));
    }
    let usteps = plan
        .spec
        .axis
        .as_ref()
        .and_then(|m| m.get(axis))
        .and_then(|a| a.usteps_per_mm)
        .or(plan.spec.usteps_per_mm)
        .ok_or_else(|| {
            format!(
                "the machine's microsteps per mm on {axis} are not known: give [tune.axis.{axis}] usteps_per_mm (settle import reads them from the firmware configuration)"
            )
        })?;
    let units = TmcUnits {
        f_clk_hz: plan.spec.tmc_clock_hz.unwrap_or(DEFAULT_TMC_CLOCK_HZ),
        usteps_per_unit: usteps,
        direct_acc: false,
        direct_bow: false,
    };
    let (scale, dmax) = match c.kind {
        ProfileKind::FourJerk => (
            c.params.fourjerk_jerk_scale,
            w.accel_mm_s2 * c.params.fourjerk_dmax_scale,
        ),
        _ => ([1.0; 4], w.accel_mm_s2),
    };
    let p = SRampParams {
        vstart: 0.0,
        vmax: b.vmax_mm_s,
        vstop: 0.0,
        amax: w.accel_mm_s2,
        dmax,
        bow: scale.map(|s| j * s),
    };
    let target = b.start_mm + plan.distances_mm.first().copied().unwrap_or(b.distance_mm);
    let r = export(target, &p, &units).map_err(|e| e.to_string())?;
    Ok(format!(
        "# the recommendation {} as a move to {target} mm\n{}",
        c.label(),
        r.register_file_text(&units)
    ))
}
