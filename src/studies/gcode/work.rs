//! A G-code job must hold work to measure: a file without a move (prose, `/etc/passwd`,
//! a configuration given as G-code) is not a job, and one whose moves never print has no
//! contour error to measure; both are refused rather than answered with zeros. Neither
//! message repeats the file's text: it is not the G-code it was said to be.

use settle_gcode::job::JobSummary;

/// Why the planned job holds nothing to measure (`lines`: lines read), `None` when it
/// does.
pub fn nothing_to_measure(summary: &JobSummary, lines: u64) -> Option<String> {
    if summary.moves == 0 {
        return Some(format!(
            "no move (G0, G1, G2, G3) in its {lines} lines: not a G-code job settle can replay"
        ));
    }
    if !summary.layers.iter().any(|l| l.printing_s > 0.0) {
        return Some(format!(
            "{} moves, none of them printing (extruding: E rising): the contour error is measured on printing moves, so this file has nothing to measure",
            summary.moves
        ));
    }
    None
}
