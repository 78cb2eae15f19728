//! Every exported value that differs from the user's current one, with what it was, what
//! it is and why: shown in the report ("What changes in klipper.cfg") and written as a
//! comment above the value in the export. One function per export target.
//!
//! The reasons are the search's own numbers: the shaper's by the gain over the current
//! settings (or why the current settings are out), its frequency by the mode it is tuned
//! to, its damping ratio by the mode's damping and where that comes from, the
//! acceleration by the best candidate at the current acceleration against the
//! recommendation.

use std::fmt::Write as _;

use settle_gcode::config::Note;

use super::Outcome;
use super::cells::ms;
use super::firmware::MarlinShaping;
use super::search::Score;

/// One changed setting.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// The setting as the export names it (`shaper_freq_x`, `max_accel`, `M593 F`).
    pub key: String,
    /// The current value, as the export would write it.
    pub was: String,
    /// The recommended value, as the export writes it.
    pub now: String,
    /// Why.
    pub why: String,
}

impl Change {
    /// The export's comment for it.
    pub fn note(&self) -> Note {
        Note {
            key: self.key.clone(),
            text: format!("{}: {} -> {}: {}", self.key, self.was, self.now, self.why),
        }
    }
}

/// A shaper as `(type, frequency, damping)` text; `None` unshaped.
fn shaper_values(s: &Score) -> Option<(String, f64, f64)> {
    let sh = s.candidate.shaper?;
    Some((sh.shaper_type?.name(), sh.frequency_hz, sh.damping_ratio))
}

/// Why the recommendation `w` replaces the current `d` on `axis`: the gain, or why the
/// current settings are out.
fn gain_why(axis: &str, o: &Outcome) -> String {
    let (d, w) = (&o.scores[0], &o.scores[o.winner]);
    let now = format!(
        "the recommendation settles axis {axis}'s moves in {} ms",
        ms(w.move_and_settle_s)
    );
    match &d.infeasible {
        Some(why) => format!(
            "your current setting on {axis} is out ({}); {now}",
            why.short()
        ),
        None => format!(
            "{now}, your current setting in {} ms ({:.1}% faster)",
            ms(d.simulated_move_and_settle_s),
            100.0 * (1.0 - w.move_and_settle_s / d.simulated_move_and_settle_s)
        ),
    }
}

/// The `(frequency, damping)` of the tuned mode nearest to `f` Hz (by ratio).
fn nearest_mode(o: &Outcome, f: f64) -> Option<(f64, f64)> {
    o.plan
        .modes
        .iter()
        .copied()
        .min_by(|a, b| (f / a.0 - 1.0).abs().total_cmp(&(f / b.0 - 1.0).abs()))
}

/// The default damping ratio shapers are designed for, as Klipper knows it
/// (`shaper_defs.DEFAULT_DAMPING_RATIO`, 0.1).
const KLIPPER_DEFAULT: &str = "Klipper's default";

/// The same 0.1 as Prusa-Firmware-Buddy knows it: the `damping_ratio` of its
/// `axis_x_default` and `axis_y_default` (every printer it builds for).
const BUDDY_DEFAULT: &str = "Buddy's default (damping_ratio 0.1 of axis_x_default and axis_y_default, lib/Marlin/Marlin/src/feature/input_shaper/input_shaper_config.hpp; Klipper's is the same)";

/// Why the shaper is tuned to `f`: the mode it is nearest to as a multiple.
fn frequency_why(axis: &str, o: &Outcome, f: f64) -> String {
    match nearest_mode(o, f) {
        Some((m, _)) => format!(
            "tuned to axis {axis}'s {m:.1} Hz mode ({}; {:.2} x its frequency)",
            o.plan.modes_source,
            f / m
        ),
        None => "the search's best frequency".into(),
    }
}

/// Why the damping ratio is `z`; `default` names the default damping ratio shapers are
/// designed for on a physical machine, as the firmware the export is for knows it.
fn damping_why(axis: &str, o: &Outcome, f: f64, z: f64, default: &str) -> String {
    let spec = &o.plan.spec;
    match (o.plan.shaper_damping, spec.shaper_damping_ratio) {
        (Some(d), Some(_)) if (d - z).abs() < 5e-4 => {
            return "the damping ratio every shaper is designed for (`[tune] shaper_damping_ratio`)"
                .into();
        }
        (Some(d), None) if (d - z).abs() < 5e-4 => {
            return format!(
                "{default}: the damping of the modes of a physical machine ({}) is an estimate from its parts, not a measurement",
                o.plan.modes_source
            );
        }
        _ => {}
    }
    match nearest_mode(o, f) {
        Some((m, zeta)) if (zeta - z).abs() < 5e-4 => format!(
            "the damping ratio of axis {axis}'s {m:.1} Hz mode ({})",
            o.plan.modes_source
        ),
        Some((m, zeta)) => format!(
            "the shaper's damping ratio nearest to that of axis {axis}'s {m:.1} Hz mode ({zeta:.3}) that the firmware takes"
        ),
        None => "the search's damping ratio".into(),
    }
}

/// The changes of one axis's shaper, keyed `{type_key}`, `{freq_key}`, `{damping_key}`;
/// `off` is how the export writes "no shaping" (type, frequency, damping); `default` names
/// the default damping ratio (see [`damping_why`]).
fn shaper_changes(
    axis: &str,
    o: &Outcome,
    keys: [&str; 3],
    off: (&str, f64, f64),
    default: &str,
) -> Vec<Change> {
    let (d, w) = (&o.scores[0], &o.scores[o.winner]);
    let as_written = |s: &Score| shaper_values(s).unwrap_or((off.0.to_string(), off.1, off.2));
    let (was, now) = (as_written(d), as_written(w));
    // "No shaping" may carry no frequency or damping (NaN): shown as `-`.
    let text = |x: f64| {
        if x.is_nan() {
            "-".to_string()
        } else {
            x.to_string()
        }
    };
    let mut out = Vec::new();
    let mut gain = Some(gain_why(axis, o));
    let mut push = |key: &str, a: String, b: String, specific: String| {
        let why = match gain.take() {
            Some(g) if specific.is_empty() => g,
            Some(g) => format!("{g}; {specific}"),
            None => specific,
        };
        out.push(Change {
            key: key.to_string(),
            was: a,
            now: b,
            why,
        });
    };
    if was.0 != now.0 {
        push(keys[0], was.0.clone(), now.0.clone(), String::new());
    }
    if text(was.1) != text(now.1) {
        let why = if shaper_values(w).is_some() {
            frequency_why(axis, o, now.1)
        } else {
            "shaping off".into()
        };
        push(keys[1], text(was.1), text(now.1), why);
    }
    if text(was.2) != text(now.2) {
        let why = if shaper_values(w).is_some() {
            damping_why(axis, o, now.1, now.2, default)
        } else {
            "shaping off".into()
        };
        push(keys[2], text(was.2), text(now.2), why);
    }
    out
}

/// Why the shared acceleration moved from `was` to `now`: per axis, its best feasible
/// candidate at `was` against its recommendation at `now`.
fn accel_why(axes: &[(String, Outcome)], was: f64, now: f64) -> String {
    let mut out = String::new();
    for (axis, o) in axes {
        let w = &o.scores[o.winner];
        let at_was = o
            .scores
            .iter()
            .enumerate()
            .filter(|(_, s)| s.accel_mm_s2 == was && s.is_feasible())
            .min_by(|a, b| a.1.move_and_settle_s.total_cmp(&b.1.move_and_settle_s));
        if !out.is_empty() {
            out.push_str("; ");
        }
        match at_was {
            Some((_, b)) => {
                let _ = write!(
                    out,
                    "axis {axis}: {} ms at {now} mm/s^2 against {} ms at {was} mm/s^2 (its best there, {})",
                    ms(w.move_and_settle_s),
                    ms(b.move_and_settle_s),
                    b.candidate.label()
                );
            }
            None => {
                let why = o
                    .scores
                    .iter()
                    .filter(|s| s.accel_mm_s2 == was)
                    .filter_map(|s| s.infeasible.as_ref().map(|i| (s, i)))
                    .min_by(|a, b| {
                        a.0.simulated_move_and_settle_s
                            .total_cmp(&b.0.simulated_move_and_settle_s)
                    })
                    .map_or("no candidate was searched there".to_string(), |(s, i)| {
                        format!(
                            "no candidate is feasible there (the fastest, {}, {})",
                            s.candidate.label(),
                            i.short()
                        )
                    });
                let _ = write!(
                    out,
                    "axis {axis}: {} ms at {now} mm/s^2; at {was} mm/s^2 {why}",
                    ms(w.move_and_settle_s)
                );
            }
        }
    }
    if axes.len() > 1 {
        out.push_str(
            " (one acceleration for every axis: the least move-and-settle summed over them)",
        );
    }
    out
}

/// The shared acceleration's change, keyed `key`, if it changed.
fn accel_change(axes: &[(String, Outcome)], key: &str, now: Option<f64>) -> Option<Change> {
    let now = now?;
    let was = axes
        .iter()
        .map(|(_, o)| o.scores[0].accel_mm_s2)
        .fold(f64::INFINITY, f64::min);
    (was != now && was.is_finite()).then(|| Change {
        key: key.to_string(),
        was: was.to_string(),
        now: now.to_string(),
        why: accel_why(axes, was, now),
    })
}

/// The changes `klipper.cfg` makes: per tuned axis `x`/`y` its shaper (Klipper's "off" is
/// frequency 0), and `max_accel` (`accel`: the one written, when it changes).
pub fn klipper(axes: &[(String, Outcome)], accel: Option<f64>) -> Vec<Change> {
    let mut out = Vec::new();
    for letter in ["x", "y"] {
        if let Some((axis, o)) = axes.iter().find(|(a, _)| a.split('+').any(|x| x == letter)) {
            out.extend(shaper_changes(
                axis,
                o,
                [
                    &format!("shaper_type_{letter}"),
                    &format!("shaper_freq_{letter}"),
                    &format!("damping_ratio_{letter}"),
                ],
                ("mzv", 0.0, super::target::KLIPPER_OFF_DAMPING),
                KLIPPER_DEFAULT,
            ));
        }
    }
    out.extend(accel_change(axes, "max_accel", accel));
    out
}

/// The `M201 X`/`Y` changes: `caps` per axis X, Y is what is written (if anything) and
/// the cap as it was (`None`: not known); `who` the firmware and where it caps the moves.
fn m201_changes(caps: [(Option<f64>, Option<f64>); 2], who: &str) -> Vec<Change> {
    let mut out = Vec::new();
    for ((now, was), letter) in caps.into_iter().zip(["X", "Y"]) {
        let Some(now) = now else { continue };
        let (was, why) = match was {
            Some(c) => (
                c.to_string(),
                format!(
                    "{who} caps every move's acceleration by M201 as well as by M204: raised to the recommended acceleration, so that moves run at it"
                ),
            ),
            None => (
                "not known".to_string(),
                format!(
                    "{who} caps every move's acceleration by M201 as well as by M204, and your M201 {letter} is not known (`settle import` writes it as [tune.axis.{}] max_accel_mm_s2): set to the recommended acceleration, so that moves run at it",
                    letter.to_ascii_lowercase()
                ),
            ),
        };
        out.push(Change {
            key: format!("M201 {letter}"),
            was,
            now: now.to_string(),
            why,
        });
    }
    out
}

/// The changes `rrf.g` makes: the one shaper (axis `axis`'s), `M201 X`/`Y` (`caps`: per
/// axis what is written and the cap as it was) and `M204 P`/`T`.
pub fn rrf(
    axes: &[(String, Outcome)],
    axis: &str,
    caps: [(Option<f64>, Option<f64>); 2],
    accel: Option<f64>,
) -> Vec<Change> {
    let mut out = Vec::new();
    if let Some((a, o)) = axes.iter().find(|(a, _)| a == axis) {
        out.extend(shaper_changes(
            a,
            o,
            ["M593 P", "M593 F", "M593 S"],
            ("none", f64::NAN, f64::NAN),
            KLIPPER_DEFAULT,
        ));
    }
    out.extend(m201_changes(
        caps,
        "RepRapFirmware (src/Movement/DDA.cpp, DDA::InitStandardMove)",
    ));
    for key in ["M204 P", "M204 T"] {
        out.extend(accel_change(axes, key, accel));
    }
    out
}

/// The changes `marlin.gcode` makes: per tuned axis `x`/`y` its shaper (Fixed-Time
/// Motion's `M493 C A I`, or for the built-in input shaping `M593 F D`, whose only shaper
/// is ZV and whose "off" is `F0`), `M201 X`/`Y` (`caps`, as for [`rrf`]) and `M204 P`/`T`.
pub fn marlin(
    axes: &[(String, Outcome)],
    shaping: MarlinShaping,
    caps: [(Option<f64>, Option<f64>); 2],
    accel: Option<f64>,
) -> Vec<Change> {
    let keys = |letter: &str| match shaping {
        MarlinShaping::FtMotion => (
            ["C", "A", "I"].map(|w| format!("M493 {letter} {w}")),
            ("none", f64::NAN, f64::NAN),
        ),
        // The shaper's type has no word in M593 (its stepper ZV only): keyed by the line.
        MarlinShaping::InputShaping => (
            ["", " F", " D"].map(|w| format!("M593 {letter}{w}")),
            ("marlin:m593", 0.0, f64::NAN),
        ),
    };
    let who = "Marlin (Marlin/src/module/planner.cpp, Planner::_populate_block)";
    per_axis_changes(axes, keys, who, KLIPPER_DEFAULT, caps, accel)
}

/// The changes `prusa.gcode` makes: per tuned axis `x`/`y` its `M593 T F D` (no shaping
/// is `F0`), `M201 X`/`Y` (`caps`, as for [`rrf`]) and `M204 P`/`T`.
pub fn prusa(
    axes: &[(String, Outcome)],
    caps: [(Option<f64>, Option<f64>); 2],
    accel: Option<f64>,
) -> Vec<Change> {
    let keys = |letter: &str| {
        (
            ["T", "F", "D"].map(|w| format!("M593 {letter} {w}")),
            ("none", 0.0, f64::NAN),
        )
    };
    let who = "Prusa-Firmware-Buddy (Marlin's planner, lib/Marlin/Marlin/src/module/planner.cpp)";
    per_axis_changes(axes, keys, who, BUDDY_DEFAULT, caps, accel)
}

/// The changes of a firmware that shapes X and Y apart: per tuned axis its shaper under
/// the keys `keys(letter)` gives (type, frequency, damping, and the values of "off"),
/// then `M201 X`/`Y` (`caps`; `who` caps moves by it) and `M204 P`/`T`; `default` names
/// the default damping ratio (see [`damping_why`]).
fn per_axis_changes(
    axes: &[(String, Outcome)],
    keys: impl Fn(&str) -> ([String; 3], (&'static str, f64, f64)),
    who: &str,
    default: &str,
    caps: [(Option<f64>, Option<f64>); 2],
    accel: Option<f64>,
) -> Vec<Change> {
    let mut out = Vec::new();
    for letter in ["X", "Y"] {
        let lower = letter.to_ascii_lowercase();
        if let Some((axis, o)) = axes.iter().find(|(a, _)| a.split('+').any(|x| x == lower)) {
            let (keys, off) = keys(letter);
            out.extend(shaper_changes(
                axis,
                o,
                [&keys[0], &keys[1], &keys[2]],
                off,
                default,
            ));
        }
    }
    out.extend(m201_changes(caps, who));
    for key in ["M204 P", "M204 T"] {
        out.extend(accel_change(axes, key, accel));
    }
    out
}

/// The report's table of `changes` for the export `file`.
pub fn table(file: &str, changes: &[Change]) -> String {
    let mut out = format!("## What changes in {file}\n\n");
    if changes.is_empty() {
        out.push_str("Nothing: the recommendation is your current setting.\n\n");
        return out;
    }
    out.push_str("| setting | yours | recommended | why |\n|---|---|---|---|\n");
    for c in changes {
        let _ = writeln!(out, "| {} | {} | {} | {} |", c.key, c.was, c.now, c.why);
    }
    out.push('\n');
    out
}
