//! The scan view of a run's figure (`settle run SCAN --case N --plot`): what a raster
//! scan's step is judged by, drawn where it happens.
//!
//! - Every time panel marks each line's exit (laser off) and the next line's re-entry
//!   (laser on): the step has to settle in between.
//! - A panel of the fly axis's commanded position (from the planned raster: in the modes
//!   form the fly axis is not simulated), with the same marks.
//! - The step axis's error zoomed on the first turnaround, from the step's end to the next
//!   line's exit (the laser-on window after re-entry), with every settling band drawn, so
//!   the error at re-entry reads against the bands instead of the run-out after the raster.

use super::trace::decimate;
use super::{Line, PALETTE, Panel, Rule, fmt_num};
use crate::output::sink::RunRecord;
use crate::studies::scan::ScanSpec;

/// The raster's exit and re-entry marks (the first turnaround's labelled).
fn marks(r: &settle_planner::raster::Raster) -> Vec<Rule> {
    let mut out = Vec::new();
    for (k, tr) in r.turnarounds.iter().enumerate() {
        let first = k == 0;
        out.push(Rule {
            at: tr.exit_s,
            label: if first {
                format!("line {} exit (laser off)", tr.line)
            } else {
                String::new()
            },
        });
        out.push(Rule {
            at: tr.reentry_s,
            label: if first {
                format!("line {} re-entry (laser on)", tr.line + 1)
            } else {
                String::new()
            },
        });
    }
    out
}

/// Add the scan view to `panels` (the run's time panels, then its error zooms) when the
/// run is a scan; the error zooms after the raster are replaced by the re-entry zoom.
pub fn scan_view(rec: &RunRecord, panels: &mut Vec<Panel>) {
    let Some(scan) = rec.spec.state::<ScanSpec>() else {
        return;
    };
    let Ok(r) = crate::studies::scan::raster(rec.spec) else {
        return;
    };
    let rules = marks(&r);
    // The zooms after the raster's end measure the run-out: drop them.
    panels.retain(|p| !p.title.contains("after the move (residual vibration)"));
    for p in panels.iter_mut() {
        p.vrules.extend(rules.iter().cloned());
    }
    let s = rec.series;
    // The fly axis, commanded (axis 0 of the raster's trajectory).
    if let Some(fly) = r.trajectory.axes().first() {
        let y: Vec<f64> = s.t_s.iter().map(|&t| fly.state_at(t).p * 1e3).collect();
        panels.insert(
            0,
            Panel {
                title: format!(
                    "fly axis {} (commanded, from the raster plan)",
                    scan.fly_axis
                ),
                x_label: "time (s)".into(),
                y_label: "mm".into(),
                lines: vec![Line::new(
                    None,
                    PALETTE[0],
                    decimate(&s.t_s, &y, super::trace::MAX_POINTS),
                )],
                vrules: rules.clone(),
                ..Panel::default()
            },
        );
    }
    // The step axis's error around the first re-entry.
    let Some(tr) = r.turnarounds.first() else {
        return;
    };
    let name = format!("error_{}", rec.spec.axis);
    let Some(c) = s.channels.iter().find(|c| c.name == name && c.unit == "m") else {
        return;
    };
    let (from, to) = (tr.step_end_s, tr.reentry_s + r.overhead.line_s);
    let a = s.t_s.partition_point(|&t| t < from);
    let b = s.t_s.partition_point(|&t| t <= to);
    if b <= a {
        return;
    }
    let y: Vec<f64> = c.data[a..b].iter().map(|v| v * 1e6).collect();
    let mut hrules = Vec::new();
    for band in &rec.spec.bands_um {
        hrules.push(Rule {
            at: *band,
            label: format!("+{} um", fmt_num(*band)),
        });
        hrules.push(Rule {
            at: -band,
            label: format!("-{} um", fmt_num(*band)),
        });
    }
    let at = rec
        .metrics
        .extra
        .iter()
        .find(|(n, _)| n == "scan_reentry_error_um");
    let mut l = Line::new(
        None,
        PALETTE[2],
        decimate(&s.t_s[a..b], &y, super::trace::MAX_POINTS),
    );
    l.width = 2;
    panels.push(Panel {
        title: format!(
            "{name} from the step's end to line {}'s exit: |error| at re-entry {} um (worst over the raster), settling bands dashed",
            tr.line + 1,
            at.map_or("-".to_string(), |(_, v)| format!("{v:.2}"))
        ),
        x_label: "time (s)".into(),
        y_label: "um".into(),
        lines: vec![l],
        vrules: vec![
            Rule {
                at: tr.step_end_s,
                label: "step ends".into(),
            },
            Rule {
                at: tr.reentry_s,
                label: "re-entry (laser on)".into(),
            },
        ],
        hrules,
        ..Panel::default()
    });
}
