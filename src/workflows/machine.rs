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
use settle_sim::DriverMode;
use settle_sim::closed_form::LinearResponse;

use crate::error::Error;
use crate::input::machine_form::MachineForm;
use crate::input::modes::AxisModes;
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
                    "{axis:<5} {i:>4} {:>14.3} {:>14.4} {:>10.4}",
                    m.frequency_hz, m.damping_ratio, m.weight
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
