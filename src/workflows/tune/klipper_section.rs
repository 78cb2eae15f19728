//! The "Klipper's choice on this machine" part of an axis's section: Klipper's
//! recommendation next to settle's, both judged both ways, why they differ and what
//! Klipper's choice costs in settle's terms ([`super::klipper_choice`]).

use std::fmt::Write as _;

use super::cells::{ms, shaper_text, status};
use super::klipper_choice::KlipperChoice;
use super::search::{Plan, Score};
use settle_planner::shaper_select::Fit;

/// The shaper's length (ms): the time from its first impulse to its last, which every
/// shaped move adds.
fn duration_ms(s: &Score) -> Option<f64> {
    let sh = s.candidate.shaper()?;
    sh.times_s().last().map(|t| t * 1e3)
}

fn fit_cells(f: Option<&Fit>) -> (String, String, String) {
    match f {
        Some(f) => (
            format!("{:.1}", f.vibrations * 100.0),
            format!("{:.3}", f.smoothing_mm),
            format!("{:.4}", f.score),
        ),
        None => ("-".into(), "-".into(), "-".into()),
    }
}

/// The part's Markdown (a `###` heading, a table, the reasons).
pub fn section(plan: &Plan, winner: &Score, k: &KlipperChoice) -> String {
    let pick = &k.selection.recommended;
    let band = plan.bands_um[plan.score_band_index];
    let modes: Vec<String> = k
        .modes
        .iter()
        .map(|(f, z, w)| format!("{f:.1} Hz zeta {z:.3} weight {w:.2}"))
        .collect();
    let mut out = String::from("### Klipper's choice on this machine\n\n");
    let _ = writeln!(
        out,
        "Klipper's `SHAPER_CALIBRATE`, on the spectrum its default resonance test would record on this machine ({}), recommends **{} @ {:.1} Hz** (suggested max_accel <= {:.0} mm/s^2). Run by settle as Klipper would save it (damping ratio 0.1), at {} mm/s^2 (the lower of the current acceleration and that suggestion):\n",
        modes.join(", "),
        pick.shaper_type.name(),
        pick.frequency_hz,
        (k.suggested_max_accel_mm_s2 / 100.0).round_ties_even() * 100.0,
        k.score.accel_mm_s2
    );
    let _ = writeln!(
        out,
        "| | shaper | accel (mm/s^2) | remaining vibration, Klipper's measure (%) | smoothing at 5000 mm/s^2 (mm) | Klipper's score | move+settle into {band} um (ms) | status |\n|---|---|---:|---:|---:|---:|---:|---|"
    );
    for (tag, s, f) in [
        ("Klipper's choice", &k.score, Some(pick)),
        ("settle's recommendation", winner, k.settle_fit.as_ref()),
    ] {
        let (v, sm, sc) = fit_cells(f);
        let _ = writeln!(
            out,
            "| {tag} | {} | {} | {v} | {sm} | {sc} | {} | {} |",
            shaper_text(s),
            s.accel_mm_s2,
            ms(s.simulated_move_and_settle_s),
            status(s)
        );
    }
    let _ = writeln!(
        out,
        "\nWhy they differ: Klipper judges a shaper by the vibration it leaves on the spectrum, at its worst over damping ratios 0.075 to 0.15, weighed against its smoothing (score = smoothing x (v^1.5 + 0.2 v + 0.01)); settle simulates each candidate's moves on the machine's modes at their own damping and scores the time until they settle into {band} um. {}\n",
        difference(k, winner)
    );
    let _ = writeln!(out, "{}\n", cost(&k.score, winner));
    out
}

/// What sets the two apart on this machine, in numbers.
fn difference(k: &KlipperChoice, winner: &Score) -> String {
    let pick = &k.selection.recommended;
    let same = winner
        .candidate
        .shaper
        .and_then(|s| s.shaper_type.map(|kind| (kind, s.frequency_hz)))
        .is_some_and(|(kind, f)| kind == pick.shaper_type && (f - pick.frequency_hz).abs() < 1.0);
    if same {
        return "Here they agree on the shaper.".into();
    }
    let Some(sf) = &k.settle_fit else {
        return "settle's recommendation is not one of Klipper's shapers (or is unshaped), so Klipper's measure does not rank it.".into();
    };
    let (dk, ds) = (
        duration_ms(&k.score).unwrap_or(0.0),
        duration_ms(winner).unwrap_or(0.0),
    );
    // Vibrations equal to the shown 0.01 %: neither leaves more by Klipper's measure.
    let level = (pick.vibrations * 1e4).round() == (sf.vibrations * 1e4).round();
    let by_klipper = if level {
        format!(
            "By Klipper's measure both leave the same vibration ({:.2}%), and Klipper's score prefers its own ({:.4} against {:.4}; smoothing {:.3} mm against {:.3} mm at 5000 mm/s^2)",
            pick.vibrations * 100.0,
            pick.score,
            sf.score,
            pick.smoothing_mm,
            sf.smoothing_mm
        )
    } else if pick.vibrations < sf.vibrations {
        format!(
            "By Klipper's measure its choice leaves less vibration ({:.2}% against {:.2}%)",
            pick.vibrations * 100.0,
            sf.vibrations * 100.0
        )
    } else {
        format!(
            "settle's choice leaves less vibration even by Klipper's measure ({:.2}% against {:.2}%), Klipper prefers its own for the smaller smoothing ({:.3} mm against {:.3} mm at 5000 mm/s^2)",
            sf.vibrations * 100.0,
            pick.vibrations * 100.0,
            pick.smoothing_mm,
            sf.smoothing_mm
        )
    };
    let zeta: Vec<String> = k.modes.iter().map(|(_, z, _)| format!("{z:.3}")).collect();
    let mut factors: Vec<String> = Vec::new();
    if dk > ds + 0.5 {
        factors.push(format!(
            "its shaper lasts {dk:.1} ms against {ds:.1} ms, and every move pays that delay"
        ));
    }
    if k.score.residual_peak_um > winner.residual_peak_um {
        factors.push(format!(
            "on this machine's modes (damping {}; Klipper designs for 0.1 and judges over 0.075 to 0.15) it leaves {:.2} um of ringing after the move against {:.2} um",
            zeta.join(", "),
            k.score.residual_peak_um,
            winner.residual_peak_um
        ));
    }
    if k.score.accel_mm_s2 < winner.accel_mm_s2 {
        factors.push(format!(
            "its smoothing holds it to {} mm/s^2 against {} mm/s^2",
            k.score.accel_mm_s2, winner.accel_mm_s2
        ));
    }
    let on_machine = if factors.is_empty() {
        "in simulated time the two are this close".to_string()
    } else {
        factors.join("; ")
    };
    format!("{by_klipper}; but {on_machine}.")
}

/// What Klipper's choice costs in settle's terms.
fn cost(klipper: &Score, winner: &Score) -> String {
    let (tk, ts) = (
        klipper.simulated_move_and_settle_s,
        winner.move_and_settle_s,
    );
    if let Some(why) = &klipper.infeasible {
        return format!(
            "In settle's terms Klipper's choice is out of the running: {} (simulated: {} ms; settle's recommendation {} ms).",
            why.short(),
            ms(tk),
            ms(ts)
        );
    }
    if tk >= ts {
        format!(
            "In settle's terms Klipper's choice costs {:.1} ms per move ({:.1}% more than settle's recommendation: {} ms against {} ms).",
            (tk - ts) * 1e3,
            100.0 * (tk / ts - 1.0),
            ms(tk),
            ms(ts)
        )
    } else {
        format!(
            "In settle's terms Klipper's choice is {:.1} ms faster than settle's recommendation ({} ms against {} ms): it lies between the searched frequencies; a finer `frequency_scales` or `refine_rounds` finds it.",
            (ts - tk) * 1e3,
            ms(tk),
            ms(ts)
        )
    }
}
