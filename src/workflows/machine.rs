//! `settle machine FILE`: a machine's modes per axis, so that a model can be checked
//! against measurements. FILE is a scenario (its `[machine]`), a machine file (either
//! form) or a built-in preset's name.
//!
//! A machine given by its modes prints them as written. A physical machine prints the
//! modes of its linearised axes (linear driver, every stiffness at axis position 0 mm,
//! the middle of the travel on the presets) from the closed form
//! (`settle_sim::closed_form::LinearResponse::weighted_modes`): frequency, damping ratio
//! and the participation weight in the toolhead error, in the modes form's convention.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_planner::{Profile, State};
use settle_sim::closed_form::LinearResponse;
use settle_sim::{AxisModel, DriverMode};

use crate::error::Error;
use crate::input::machine_form::MachineForm;
use crate::input::modes::{AxisModes, MAX_FREQUENCY_HZ};
use crate::workflows::{Exit, Report};

/// Modes below this frequency (Hz) are the rigid motion, not a vibration: not listed.
const RIGID_BELOW_HZ: f64 = 0.5;

/// One mode of an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeRow {
    /// Natural frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
    /// Participation weight in the toolhead error.
    pub weight: f64,
}

/// A machine's modes per axis.
#[derive(Debug, Clone, PartialEq)]
pub struct MachineModes {
    /// The machine's name.
    pub name: String,
    /// Where it came from (the file, or the preset's file).
    pub source: PathBuf,
    /// Whether the modes are a physical machine's linearised modes (else: as written).
    pub linearised: bool,
    /// Per axis (in the machine's order), its modes, lowest frequency first for a
    /// physical machine, as written for the modes form.
    pub axes: Vec<(String, Vec<ModeRow>)>,
}

impl MachineModes {
    /// The table `settle machine` prints.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let how = if self.linearised {
            "linearised modes (linear driver, at axis position 0 mm)"
        } else {
            "modes as given"
        };
        let _ = writeln!(
            out,
            "Machine `{}` ({}): {how}",
            self.name,
            self.source.display()
        );
        let _ = writeln!(
            out,
            "{:<5} {:>4} {:>14} {:>14} {:>10}",
            "axis", "mode", "frequency_hz", "damping_ratio", "weight"
        );
        for (axis, modes) in &self.axes {
            for (i, m) in modes.iter().enumerate() {
                let _ = writeln!(
                    out,
                    "{axis:<5} {i:>4} {:>14} {:>14} {:>10}",
                    shown(m.frequency_hz, 3),
                    shown(m.damping_ratio, 4),
                    shown(m.weight, 4)
                );
            }
        }
        out
    }

    /// What the binary prints.
    pub fn report(&self) -> Report {
        let mut r = Report::new(Exit::Ok);
        r.stdout = self.table();
        r
    }
}

/// `v` with `decimals` decimals, or in scientific notation when those would show a value
/// that is not 0 as 0 (a weight of 1e-5, a mode of 1e-300 Hz) or need more than 9 digits
/// before the point (1e300 Hz): the table never shows a number other than the file's.
fn shown(v: f64, decimals: usize) -> String {
    let a = v.abs();
    if v != 0.0 && (a < 0.5 * 10f64.powi(-(decimals as i32)) || a >= 1e9) {
        format!("{v:.3e}")
    } else {
        format!("{v:.decimals$}")
    }
}

/// The modes of the machine `arg` names: a preset name, a machine file or a scenario
/// ([`crate::expand::machine::named`]).
pub fn machine_modes(arg: &str) -> Result<MachineModes, Error> {
    let n = crate::expand::machine::named(arg, Path::new(""), true, &|m| Error::input(arg, m))?;
    of_form(&n.name, &n.source, n.form)
}

fn of_form(name: &str, source: &Path, form: MachineForm) -> Result<MachineModes, Error> {
    let (linearised, axes) = match form {
        MachineForm::Modes(axes) => (false, as_given(&axes)),
        MachineForm::Physical(m) => {
            let sim_err = |e: settle_sim::SimError| Error::input(source, e.to_string());
            let mut out = Vec::new();
            for axis in m.compile(DriverMode::Linear).map_err(sim_err)? {
                let rest = Profile::empty(State::default());
                let lr = LinearResponse::new(&axis, &rest).map_err(sim_err)?;
                trustworthy(source, &axis, &lr)?;
                let modes = lr
                    .weighted_modes()
                    .into_iter()
                    .filter(|(f, _, _)| *f >= RIGID_BELOW_HZ)
                    .map(|(frequency_hz, damping_ratio, weight)| ModeRow {
                        frequency_hz,
                        damping_ratio,
                        weight,
                    })
                    .collect();
                out.push((axis.name.clone(), modes));
            }
            (true, out)
        }
    };
    Ok(MachineModes {
        name: name.to_string(),
        source: source.to_path_buf(),
        linearised,
        axes,
    })
}

/// Refuses modes settle cannot stand behind: a linearised axis with a natural frequency
/// above any mode a machine may have ([`MAX_FREQUENCY_HZ`]; a sweep would need a sample
/// rate past it), or a pole that grows (a negative damping ratio) or is not a number.
/// Parts in the wrong unit (a rotor inertia in kg m^2, 1e7 times too small) make the model
/// so stiff that its eigenvalues lose their digits: the slow modes come out with negative
/// damping, and the fast one, overdamped, is not listed at all.
fn trustworthy(source: &Path, axis: &AxisModel, lr: &LinearResponse) -> Result<(), Error> {
    let sim_err = |e: settle_sim::SimError| Error::input(source, e.to_string());
    let q = axis.lumped.equilibrium(0.0, None).map_err(sim_err)?;
    let fastest_hz = axis
        .lumped
        .natural_frequencies_hz(&q)
        .into_iter()
        .fold(0.0, |a: f64, f| {
            if a.is_nan() || f.is_nan() {
                f64::NAN
            } else {
                a.max(f)
            }
        });
    let grows = lr
        .poles()
        .iter()
        .any(|l| !(l.re <= 0.0 && l.im.is_finite()));
    if fastest_hz.is_nan() || fastest_hz > MAX_FREQUENCY_HZ || grows {
        let what = if grows {
            "a mode with a negative damping ratio".to_string()
        } else {
            format!(
                "a mode at {fastest_hz:.4e} Hz, above the {MAX_FREQUENCY_HZ} Hz a machine's mode may have"
            )
        };
        return Err(Error::input(
            source,
            format!(
                "axis `{}`: the linearised model has {what}: settle cannot resolve its modes; check the units of its parts (motor.rotor_inertia_g_cm2 in g cm^2, 54 for a NEMA 17, not kg m^2; stiffnesses in N/m; masses in kg)",
                axis.name
            ),
        ));
    }
    Ok(())
}

fn as_given(axes: &[AxisModes]) -> Vec<(String, Vec<ModeRow>)> {
    axes.iter()
        .map(|a| {
            let rows = a
                .modes
                .iter()
                .map(|m| ModeRow {
                    frequency_hz: m.frequency_hz,
                    damping_ratio: m.damping_ratio,
                    weight: m.weight,
                })
                .collect();
            (a.axis.clone(), rows)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::shown;

    #[test]
    fn a_value_is_never_shown_as_another() {
        assert_eq!(shown(45.0, 3), "45.000");
        assert_eq!(shown(0.0, 4), "0.0000");
        assert_eq!(shown(0.05, 4), "0.0500");
        assert_eq!(shown(1e-300, 3), "1.000e-300");
        assert_eq!(shown(1e-5, 4), "1.000e-5");
        assert_eq!(shown(1e300, 3), "1.000e300");
    }
}
