//! The machine's travel and what each firmware does with a move that leaves it:
//!
//! - **Klipper** (`position_min`/`position_max` of `[stepper_x]`...): `check_move` in
//!   klippy/kinematics/cartesian.py and corexy.py refuses a move whose end leaves the
//!   range on an axis the move moves, with `Move out of range: x y z [e]`
//!   (klippy/toolhead.py `Move.move_error`, `%.3f`): the print stops. This job stops
//!   with the same words (an input error: the file does not run on this configuration).
//! - **RepRapFirmware 3.5 and 3.6** (`M208`, limits on by default, `M564 S1`): on a
//!   printer (`MachineType::fff`) `GCodes::DoStraightMove` (src/GCodes/GCodes.cpp) clamps
//!   each coordinate of a homed moving axis to its limits (`Kinematics::LimitPosition`
//!   of a Cartesian machine) and takes the clamped point as the new position
//!   (`ToolOffsetInverseTransform`); only a laser or CNC machine raises "target position
//!   outside machine limits". Simulated so: every point of a move (start, arc segments,
//!   end) clamped to the limits, the extrusion as written, and listed once per axis (the
//!   part differs from the file). An arc (`G2`/`G3`) whose end is past the limits is
//!   abandoned with "G2/G3: outside machine limits" on every machine type
//!   (`GCodes::DoArcMove`): this job stops with those words. An arc that ends inside but
//!   passes beyond them on the way is cut short at its last segment inside
//!   (`GCodes::ReadMove` aborts the segmented move; a printer carries on from there):
//!   simulated so, and listed. RepRapFirmware 3.7 raises the error on printers too for
//!   absolute moves; that version is not the one settle's planner follows.
//! - **GRBL** (`$130`-`$132`, soft limits `$20=1` with homing `$22=1`): machine
//!   coordinates run over the travel from the homed end, and the work offsets are not in
//!   the file, so what settle can check is the job's extent: an axis whose moves span more
//!   than its travel cannot fit under any offset. With soft limits GRBL stops with
//!   `ALARM:2` (soft limit, grbl/limits.c `limits_soft_check`); without, the machine runs
//!   into its end: listed.
//!
//! Marlin's limits are compiled in (not read here): not checked.

use settle_planner::firmware::Firmware;

use crate::read::geometry::Point;

/// What a move did to the travel.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum TravelCheck {
    /// Inside.
    Inside,
    /// The firmware refuses it with this message (the print stops).
    Refused(String),
    /// The firmware clamps it or runs into its end: listed with this text (once per
    /// axis).
    Listed(String),
}

/// The travel of X, Y, Z and the firmware's rule.
#[derive(Debug, Clone)]
pub(crate) struct Travel {
    firmware: Firmware,
    /// Minimum and maximum per axis (mm); for GRBL `(0, $13x)`.
    limits: [Option<(f64, f64)>; 3],
    /// GRBL: soft limits on.
    soft_limits: bool,
    /// GRBL: the extent of the moves so far.
    seen: [(f64, f64); 3],
    listed: [bool; 3],
}

const AXES: [&str; 3] = ["X", "Y", "Z"];

impl Travel {
    /// `limits` for `firmware`.
    pub(crate) fn new(
        firmware: Firmware,
        limits: [Option<(f64, f64)>; 3],
        soft_limits: bool,
    ) -> Self {
        Self {
            firmware,
            limits,
            soft_limits,
            seen: [(f64::INFINITY, f64::NEG_INFINITY); 3],
            listed: [false; 3],
        }
    }

    /// Whether the firmware runs a move past the travel clamped to it (RepRapFirmware).
    pub(crate) fn clamps(&self) -> bool {
        self.firmware == Firmware::Rrf && self.limits.iter().any(Option::is_some)
    }

    /// `p` as RepRapFirmware runs it: each of X, Y, Z inside its limits (a Cartesian
    /// machine's `LimitPosition`); E untouched.
    pub(crate) fn clamp(&self, p: &mut Point) {
        for (c, lim) in [&mut p.x_mm, &mut p.y_mm, &mut p.z_mm]
            .into_iter()
            .zip(self.limits)
        {
            if let Some((lo, hi)) = lim {
                *c = c.clamp(lo, hi);
            }
        }
    }

    /// RepRapFirmware's check of an arc (`GCodes::DoArcMove`): an arc whose end is past the
    /// M208 limits is abandoned with an error on every machine type (only the points on
    /// the way are clamped on a printer). The message, or `None` when it ends inside.
    pub(crate) fn arc_refused(&self, end: &Point) -> Option<String> {
        if self.firmware != Firmware::Rrf {
            return None;
        }
        let p = [end.x_mm, end.y_mm, end.z_mm];
        (0..3).find_map(|k| {
            let (lo, hi) = self.limits[k]?;
            (p[k] < lo || p[k] > hi).then(|| {
                format!(
                    "RepRapFirmware abandons the arc: \"G2/G3: outside machine limits\" (its end {} {:.3} mm, M208 {lo} to {hi} mm)",
                    AXES[k], p[k]
                )
            })
        })
    }

    /// Whether `p` is inside every limit.
    pub(crate) fn inside(&self, p: &Point) -> bool {
        [p.x_mm, p.y_mm, p.z_mm]
            .into_iter()
            .zip(self.limits)
            .all(|(c, lim)| lim.is_none_or(|(lo, hi)| (lo..=hi).contains(&c)))
    }

    /// A straight move from `a` to `b` (mm, machine frame).
    pub(crate) fn check(&mut self, a: &Point, b: &Point) -> TravelCheck {
        let (pa, pb) = ([a.x_mm, a.y_mm, a.z_mm], [b.x_mm, b.y_mm, b.z_mm]);
        for k in 0..3 {
            let Some((lo, hi)) = self.limits[k] else {
                continue;
            };
            match self.firmware {
                Firmware::Klipper => {
                    if pb[k] != pa[k] && (pb[k] < lo || pb[k] > hi) {
                        return TravelCheck::Refused(format!(
                            "Klipper stops the print: \"Move out of range: {:.3} {:.3} {:.3} [{:.3}]\" ({} travel {lo} to {hi} mm, position_min/position_max)",
                            b.x_mm, b.y_mm, b.z_mm, b.e_mm, AXES[k]
                        ));
                    }
                }
                Firmware::Rrf => {
                    if pb[k] != pa[k] && (pb[k] < lo || pb[k] > hi) && !self.listed[k] {
                        self.listed[k] = true;
                        return TravelCheck::Listed(format!(
                            "moves past the M208 {} limits ({lo} to {hi} mm): RepRapFirmware clamps them to the limits (simulated clamped; the part differs from the file)",
                            AXES[k]
                        ));
                    }
                }
                Firmware::Grbl => {
                    let s = &mut self.seen[k];
                    s.0 = s.0.min(pa[k]).min(pb[k]);
                    s.1 = s.1.max(pa[k]).max(pb[k]);
                    let span = s.1 - s.0;
                    if span > hi - lo && !self.listed[k] {
                        self.listed[k] = true;
                        let text = format!(
                            "the job spans {span:.3} mm in {}, more than the {:.3} mm of travel (${}): no work offset fits it",
                            AXES[k],
                            hi - lo,
                            130 + k
                        );
                        return if self.soft_limits {
                            TravelCheck::Refused(format!(
                                "GRBL stops with ALARM:2 (soft limit, $20=1): {text}"
                            ))
                        } else {
                            TravelCheck::Listed(format!(
                                "{text}; soft limits are off ($20=0), so the machine runs into its end"
                            ))
                        };
                    }
                }
                Firmware::Marlin | Firmware::Prusa | Firmware::Settle | Firmware::Tmc4361a => {}
            }
        }
        TravelCheck::Inside
    }
}
