//! A G-code job must hold work to measure. A file without a move (prose, a configuration
//! given as G-code) is not a job; one whose moves never work the material has no error
//! that counts. Working moves are [`settle_gcode::Move::is_working`]: extruding moves on
//! a printer, feed moves (`G1`, `G2`, `G3`) with the laser or spindle on at `S > 0` on a
//! GRBL laser or mill. Both cases are refused rather than answered with zeros, and so is
//! a layer range without a working move ([`no_work_in`]); no message repeats the file's
//! text (it is not the G-code it was said to be).

use settle_gcode::job::JobSummary;
use settle_planner::firmware::Firmware;

/// Why the planned job holds nothing to measure (`lines`: lines read), `None` when it
/// does. A file without a move that is text of another kind (`looks`, the reader's
/// [`settle_gcode::Reader::looks`]: a config.g, Marlin's M503 reply) is named as that,
/// with the command that reads it.
pub fn nothing_to_measure(
    summary: &JobSummary,
    lines: u64,
    looks: Option<settle_files::looks::Looks>,
) -> Option<String> {
    if summary.moves == 0 {
        return Some(match looks {
            Some(l) => format!(
                "no move (G0, G1, G2, G3) in its {lines} lines: {}, not a G-code job: {}",
                l.what(),
                l.then()
            ),
            None => format!(
                "no move (G0, G1, G2, G3) in its {lines} lines: not a G-code job settle can replay"
            ),
        });
    }
    if summary.layers.iter().any(|l| l.working_s > 0.0) {
        return None;
    }
    let what = match summary.firmware {
        Some(Firmware::Grbl) => {
            "a feed move (G1, G2, G3) with the laser or spindle on (M3 or M4, S above 0)"
        }
        _ => "an extruding move (E rising while X, Y or Z moves)",
    };
    Some(format!(
        "{} moves, none of them working: the error is measured on working moves, here {what}, so this file has nothing to measure",
        summary.moves
    ))
}

/// Why the layers `a..=b` hold nothing to measure: none of them has a working move (a
/// range past the file's last layer, or over travel only). `None` when one does, or when
/// no layer of the file works ([`nothing_to_measure`] says so).
pub fn no_work_in(summary: &JobSummary, (a, b): (u32, u32)) -> Option<String> {
    let working = || {
        summary
            .layers
            .iter()
            .filter(|l| l.working_s > 0.0)
            .map(|l| l.layer)
    };
    let (first, last) = (working().min()?, working().max()?);
    if working().any(|l| (a..=b).contains(&l)) {
        return None;
    }
    Some(format!(
        "layers {a} to {b} hold no working move, so nothing to measure: this file's working moves are on layers {first} to {last}"
    ))
}
