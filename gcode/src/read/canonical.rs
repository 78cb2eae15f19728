//! Events written back as canonical G-code: absolute millimetre coordinates in the
//! reader's machine frame, every axis and the feed on every move, numbers printed
//! shortest-exact (Rust's `{}` for `f64` reads back to the same bits), limits in the
//! chosen dialect's own commands. Reading the output with the same options gives the same
//! events (line numbers aside).
//!
//! Where a dialect's unit differs from the event's (mm/min feeds, RepRapFirmware's
//! `M566` mm/min, Klipper's `G4 P` ms, Marlin's `M205 B` us), the value written is the
//! decimal whose conversion by the reader gives back the event's value exactly.

use std::io::{self, Write};

use crate::read::arc::Plane;
use crate::read::dialect::Dialect;
use crate::read::event::{Event, EventKind, LayerSource, Note};
use crate::read::geometry::{Move, Path};
use crate::read::limits::{AxisFlags, AxisValues, LimitChange};
use crate::read::setting::Setting;

/// Writes events as G-code.
#[derive(Debug)]
pub struct CanonicalWriter<W> {
    out: W,
    dialect: Dialect,
    /// The next dwell came from a Klipper `G4 S..` already written with its note.
    skip_dwell: bool,
    /// The `P` word of the next arc, from a Klipper note that it was passed over.
    arc_word: Option<String>,
}

/// The number `d` near `guess` with `forward(d) == value` (so a reader that applies
/// `forward` to the written number gets `value` back bit for bit).
fn inverse(value: f64, guess: f64, forward: impl Fn(f64) -> f64) -> f64 {
    let (mut up, mut down) = (guess, guess);
    for _ in 0..64 {
        if forward(up) == value {
            return up;
        }
        if forward(down) == value {
            return down;
        }
        up = up.next_up();
        down = down.next_down();
    }
    guess
}

fn per_min(v_mm_s: f64) -> f64 {
    inverse(v_mm_s, v_mm_s * 60.0, |d| d * (1.0 / 60.0))
}

impl<W: Write> CanonicalWriter<W> {
    /// A writer for `dialect`; writes the header (units, absolute modes) at once. The
    /// printer dialects only: GRBL's events (spindle synchronisations, modal state)
    /// cannot be written back one for one (an `Unsupported` error).
    pub fn new(mut out: W, dialect: Dialect) -> io::Result<Self> {
        if dialect == Dialect::Grbl {
            return Err(io::Error::new(
                io::ErrorKind::Unsupported,
                "canonical G-code is written in the printer dialects (klipper, marlin, rrf)",
            ));
        }
        writeln!(
            out,
            "; canonical G-code written by settle-gcode ({dialect})"
        )?;
        writeln!(out, "G21\nG90\nM82")?;
        Ok(CanonicalWriter {
            out,
            dialect,
            skip_dwell: false,
            arc_word: None,
        })
    }

    /// The output.
    pub fn into_inner(self) -> W {
        self.out
    }

    /// Writes one event.
    pub fn write(&mut self, ev: &Event) -> io::Result<()> {
        match &ev.kind {
            EventKind::Move(mv) => self.write_move(mv),
            EventKind::Dwell { duration_s } => {
                if std::mem::take(&mut self.skip_dwell) {
                    return Ok(());
                }
                match self.dialect {
                    Dialect::Klipper => {
                        writeln!(
                            self.out,
                            "G4 P{}",
                            inverse(*duration_s, duration_s * 1000.0, |d| d / 1000.0)
                        )
                    }
                    Dialect::Marlin | Dialect::Prusa | Dialect::Rrf | Dialect::Grbl => {
                        writeln!(self.out, "G4 S{duration_s}")
                    }
                }
            }
            EventKind::Layer(c) => match (c.source, c.slicer_number, c.z_mm) {
                (LayerSource::Cura, Some(n), _) => writeln!(self.out, ";LAYER:{n}"),
                (LayerSource::LayerChange, _, z) => {
                    writeln!(self.out, ";LAYER_CHANGE")?;
                    z.map_or(Ok(()), |z| writeln!(self.out, ";Z:{z}"))
                }
                (LayerSource::ChangeLayer, _, z) => {
                    writeln!(self.out, "; CHANGE_LAYER")?;
                    z.map_or(Ok(()), |z| writeln!(self.out, "; Z_HEIGHT: {z}"))
                }
                (LayerSource::Simplify3d, Some(n), Some(z)) => {
                    writeln!(self.out, "; layer {n}, Z = {z}")
                }
                // Z-change layers come back from the moves themselves.
                _ => Ok(()),
            },
            EventKind::Note(Note::Homed { axes }) => {
                if axes.x && axes.y && axes.z {
                    writeln!(self.out, "G28")
                } else {
                    writeln!(self.out, "G28{}", flags(axes))
                }
            }
            // A Klipper `G2`/`G3` with a `P` word: the word goes on the arc that follows.
            EventKind::Note(Note::IgnoredByFirmware { command, .. })
                if command.starts_with("G2 P") || command.starts_with("G3 P") =>
            {
                self.arc_word = Some(command[3..].to_string());
                Ok(())
            }
            EventKind::Note(Note::IgnoredByFirmware { command, .. }) => {
                // A Klipper `G4 S..` note is followed by its own (zero) dwell, which the
                // command written here produces again on reading.
                self.skip_dwell = command.starts_with("G4");
                writeln!(self.out, "{command}")
            }
            EventKind::Note(Note::PrinterModel { name }) => {
                writeln!(self.out, "M862.3 P\"{name}\"")
            }
            EventKind::Note(Note::MacroCall { command, path }) => match *command {
                "M501" => writeln!(self.out, "M501"),
                _ => writeln!(self.out, "{command} P\"{}\"", path.replace('"', "\"\"")),
            },
            EventKind::Limits(c) => self.write_limits(c),
            EventKind::Setting(c) => self.write_setting(c),
        }
    }

    fn write_setting(&mut self, c: &Setting) -> io::Result<()> {
        let o = &mut self.out;
        match c {
            Setting::Grbl { number, value } => write!(o, "${number}={value}")?,
            Setting::StepsPerMm {
                per_axis,
                at_microstepping,
            } => {
                write!(o, "M92{}", axes(per_axis, |v| v))?;
                opt(o, " S", at_microstepping.map(f64::from))?;
            }
            Setting::Microstepping {
                per_axis,
                interpolation,
            } => write!(
                o,
                "M350{} I{}",
                axes(per_axis, |v| v),
                u8::from(*interpolation)
            )?,
            Setting::MotorCurrent {
                per_axis_ma,
                idle_percent,
            } => {
                write!(o, "M906{}", axes(per_axis_ma, |v| v))?;
                opt(o, " I", *idle_percent)?;
            }
            Setting::AxisLimits {
                minimum_mm,
                maximum_mm,
            } => {
                // One command holds single values of one kind only: minimums (S1) or
                // maximums; pairs mean both either way.
                let s1 = [
                    (minimum_mm.x, maximum_mm.x),
                    (minimum_mm.y, maximum_mm.y),
                    (minimum_mm.z, maximum_mm.z),
                ]
                .iter()
                .any(|(lo, hi)| lo.is_some() && hi.is_none());
                write!(o, "M208{}", if s1 { " S1" } else { "" })?;
                for (l, lo, hi) in [
                    ("X", minimum_mm.x, maximum_mm.x),
                    ("Y", minimum_mm.y, maximum_mm.y),
                    ("Z", minimum_mm.z, maximum_mm.z),
                ] {
                    match (lo, hi) {
                        (Some(lo), Some(hi)) => write!(o, " {l}{lo}:{hi}")?,
                        (Some(v), None) | (None, Some(v)) => write!(o, " {l}{v}")?,
                        (None, None) => {}
                    }
                }
            }
            Setting::Kinematics { code } => write!(o, "M669 K{code}")?,
        }
        writeln!(o)
    }

    fn write_move(&mut self, mv: &Move) -> io::Result<()> {
        let e = &mv.end;
        if let Path::Arc(a) = &mv.path
            && a.plane != Plane::Xy
        {
            writeln!(self.out, "{}", a.plane.code())?;
        }
        let word = match (&mv.path, mv.rapid) {
            (Path::Line, true) => "G0",
            (Path::Line, false) => "G1",
            (Path::Arc(a), _) if a.clockwise() => "G2",
            (Path::Arc(_), _) => "G3",
        };
        let f = inverse(mv.feed_mm_s, mv.feed_mm_s * 60.0, |d| d / 60.0);
        write!(
            self.out,
            "{word} X{} Y{} Z{} E{} F{f}",
            e.x_mm, e.y_mm, e.z_mm, e.e_mm
        )?;
        match &mv.path {
            Path::Line => writeln!(self.out),
            Path::Arc(a) => {
                let [i, j] = a.plane.offset_words().map(char::from);
                match a.radius_word_mm {
                    Some(r) => write!(self.out, " R{r}")?,
                    None => write!(self.out, " {i}{} {j}{}", a.offset_i_mm, a.offset_j_mm)?,
                }
                if let Some(word) = self.arc_word.take() {
                    write!(self.out, " {word}")?;
                }
                writeln!(self.out)?;
                if a.plane != Plane::Xy {
                    // The plane holds for this arc only: the written file stays in G17.
                    writeln!(self.out, "G17")?;
                }
                Ok(())
            }
        }
    }

    fn write_limits(&mut self, c: &LimitChange) -> io::Result<()> {
        let o = &mut self.out;
        match c {
            LimitChange::MaxAccel {
                per_axis_mm_s2,
                xy_frequency_limit_hz,
                xy_frequency_min_speed_pct,
            } => {
                write!(o, "M201{}", axes(per_axis_mm_s2, |v| v))?;
                opt(o, " F", *xy_frequency_limit_hz)?;
                opt(o, " S", *xy_frequency_min_speed_pct)?;
            }
            LimitChange::MaxFeedrate {
                per_axis_mm_s,
                min_speed_mm_s,
            } => match self.dialect {
                Dialect::Rrf => {
                    write!(o, "M203 S1{}", axes(per_axis_mm_s, |v| v))?;
                    opt(o, " I", *min_speed_mm_s)?;
                }
                _ => write!(o, "M203{}", axes(per_axis_mm_s, |v| v))?,
            },
            LimitChange::Accel {
                print_mm_s2,
                travel_mm_s2,
                retract_mm_s2,
            } => {
                write!(o, "M204")?;
                opt(o, " P", *print_mm_s2)?;
                opt(o, " T", *travel_mm_s2)?;
                opt(o, " R", *retract_mm_s2)?;
            }
            LimitChange::MarlinAdvanced {
                junction_deviation_mm,
                jerk_mm_s,
                min_feedrate_mm_s,
                min_travel_feedrate_mm_s,
                min_segment_time_s,
            } => {
                write!(o, "M205{}", axes(jerk_mm_s, |v| v))?;
                opt(o, " J", *junction_deviation_mm)?;
                opt(o, " S", *min_feedrate_mm_s)?;
                opt(o, " T", *min_travel_feedrate_mm_s)?;
                opt(
                    o,
                    " B",
                    min_segment_time_s.map(|s| inverse(s, s * 1e6, |d| d * 1e-6)),
                )?;
            }
            LimitChange::RrfJerk {
                per_axis_mm_s,
                policy,
                sets_maximum: true,
            } => {
                write!(o, "M566{}", axes(per_axis_mm_s, per_min))?;
                opt(o, " P", policy.map(f64::from))?;
            }
            LimitChange::RrfJerk {
                per_axis_mm_s,
                sets_maximum: false,
                ..
            } => write!(o, "M205{}", axes(per_axis_mm_s, |v| v))?,
            LimitChange::MarlinInputShaping {
                axes: a,
                frequency_hz,
                damping_ratio,
            } => {
                write!(o, "M593{}", flags(a))?;
                opt(o, " F", *frequency_hz)?;
                opt(o, " D", *damping_ratio)?;
            }
            LimitChange::PrusaInputShaping {
                axes: a,
                shaper_type,
                frequency_hz,
                damping_ratio,
                vibration_reduction,
                weight_frequency_delta_hz,
                weight_mass_limit_g,
                save,
            } => {
                write!(o, "M593{}", flags(a))?;
                opt(o, " T", shaper_type.map(f64::from))?;
                opt(o, " F", *frequency_hz)?;
                opt(o, " D", *damping_ratio)?;
                opt(o, " R", *vibration_reduction)?;
                opt(o, " A", *weight_frequency_delta_hz)?;
                opt(o, " M", *weight_mass_limit_g)?;
                if *save {
                    write!(o, " W")?;
                }
            }
            LimitChange::RrfInputShaping {
                shaper,
                frequency_hz,
                damping_ratio,
                reduction_limit,
                amplitudes,
                durations_s,
            } => {
                write!(o, "M593")?;
                if let Some(s) = shaper {
                    write!(o, " P\"{}\"", s.replace('"', "\"\""))?;
                }
                opt(o, " F", *frequency_hz)?;
                opt(o, " S", *damping_ratio)?;
                opt(o, " L", *reduction_limit)?;
                list(o, " H", amplitudes)?;
                list(o, " T", durations_s)?;
            }
            LimitChange::FtMotion {
                enabled,
                axis_sync,
                axes: a,
                shaper,
                dynamic_mode,
                frequency_hz,
                frequency_scaling,
                damping_ratio,
                vibration_tolerance,
            } => {
                write!(o, "M493{}", flags(a))?;
                opt(o, " S", enabled.map(|b| f64::from(u8::from(b))))?;
                opt(o, " H", axis_sync.map(|b| f64::from(u8::from(b))))?;
                opt(o, " C", shaper.map(|s| f64::from(s.code())))?;
                opt(o, " D", dynamic_mode.map(f64::from))?;
                opt(o, " A", *frequency_hz)?;
                opt(o, " F", *frequency_scaling)?;
                opt(o, " I", *damping_ratio)?;
                opt(o, " Q", *vibration_tolerance)?;
            }
            LimitChange::FtSmoothing {
                trajectory,
                overshoot,
                smoothing_s,
            } => {
                write!(o, "M494{}", axes(smoothing_s, |v| v))?;
                opt(o, " T", trajectory.map(f64::from))?;
                opt(o, " O", *overshoot)?;
            }
            LimitChange::VelocityLimit {
                velocity_mm_s,
                accel_mm_s2,
                accel_to_decel_mm_s2,
                square_corner_velocity_mm_s,
                minimum_cruise_ratio,
            } => {
                write!(o, "SET_VELOCITY_LIMIT")?;
                opt(o, " VELOCITY=", *velocity_mm_s)?;
                opt(o, " ACCEL=", *accel_mm_s2)?;
                opt(o, " ACCEL_TO_DECEL=", *accel_to_decel_mm_s2)?;
                opt(o, " SQUARE_CORNER_VELOCITY=", *square_corner_velocity_mm_s)?;
                opt(o, " MINIMUM_CRUISE_RATIO=", *minimum_cruise_ratio)?;
            }
            LimitChange::InputShaper {
                shaper_type,
                shaper_type_xyz,
                frequency_hz_xyz,
                damping_ratio_xyz,
            } => {
                write!(o, "SET_INPUT_SHAPER")?;
                if let Some(t) = shaper_type {
                    write!(o, " SHAPER_TYPE=\"{t}\"")?;
                }
                for (axis, k) in ["X", "Y", "Z"].iter().zip(0..) {
                    if let Some(t) = &shaper_type_xyz[k] {
                        write!(o, " SHAPER_TYPE_{axis}=\"{t}\"")?;
                    }
                    opt(o, &format!(" SHAPER_FREQ_{axis}="), frequency_hz_xyz[k])?;
                    opt(o, &format!(" DAMPING_RATIO_{axis}="), damping_ratio_xyz[k])?;
                }
            }
        }
        writeln!(o)
    }
}

fn opt(o: &mut impl Write, word: &str, v: Option<f64>) -> io::Result<()> {
    match v {
        Some(v) => write!(o, "{word}{v}"),
        None => Ok(()),
    }
}

fn list(o: &mut impl Write, word: &str, v: &[f64]) -> io::Result<()> {
    if v.is_empty() {
        return Ok(());
    }
    let parts: Vec<String> = v.iter().map(f64::to_string).collect();
    write!(o, "{word}{}", parts.join(":"))
}

fn axes(v: &AxisValues, map: impl Fn(f64) -> f64) -> String {
    let mut s = String::new();
    for (l, x) in [("X", v.x), ("Y", v.y), ("Z", v.z), ("E", v.e)] {
        if let Some(x) = x {
            s.push_str(&format!(" {l}{}", map(x)));
        }
    }
    s
}

fn flags(a: &AxisFlags) -> String {
    let mut s = String::new();
    for (l, on) in [(" X", a.x), (" Y", a.y), (" Z", a.z), (" E", a.e)] {
        if on {
            s.push_str(l);
        }
    }
    s
}
