//! The modes form of a machine: per axis, the lightly damped modes between the commanded
//! position and the toolhead (settle-sim's `Mode`: toolhead = command + sum weight_k e_k
//! with `e_k'' + 2 zeta_k w_k e_k' + w_k^2 e_k = -a_cmd`).
//!
//! Written as `[axis.<name>] modes = [...]` in a machine file, `[machine.axis.<name>]
//! modes = [...]` in a scenario, or `[machine] modes = [...]`, the shorthand for axis `x`.

use serde::Deserialize;
use settle_sim::Mode;

use crate::error::Error;
use crate::input::source::Source;

/// One mode of an axis.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModeSpec {
    /// Natural frequency (Hz), > 0.
    pub frequency_hz: f64,
    /// Damping ratio, in [0, 1).
    pub damping_ratio: f64,
    /// Participation in the toolhead error (weights of a real structure sum to 1).
    #[serde(default = "one")]
    pub weight: f64,
    /// One standard deviation of the frequency (Hz), >= 0, when it was measured
    /// (`settle identify` writes it): `settle tune` then checks its shapers over the
    /// frequency's uncertainty band.
    #[serde(default)]
    pub frequency_sigma_hz: Option<f64>,
    /// One standard deviation of the damping ratio, >= 0, when it was measured.
    #[serde(default)]
    pub damping_ratio_sigma: Option<f64>,
}

fn one() -> f64 {
    1.0
}

/// The modes of one axis of a machine given by its modes.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisModes {
    /// The axis (`x`, `y`, `z`, ...).
    pub axis: String,
    /// Its modes, as written.
    pub modes: Vec<ModeSpec>,
}

/// The modes of `axis` among `axes`, if it has any.
pub fn modes_of<'a>(axes: &'a [AxisModes], axis: &str) -> Option<&'a [ModeSpec]> {
    axes.iter()
        .find(|a| a.axis == axis)
        .map(|a| a.modes.as_slice())
}

/// The machine-file text of a machine given by its modes (the form `settle identify`
/// writes and `settle sweep` / `settle tune` read through `preset = "<file>"`): `name`,
/// `description`, then one `[axis.<name>]` table per axis with its `modes`, each mode on
/// its own line with every digit of its numbers (so a file read back gives the same
/// modes bit for bit), its standard deviations when it has them.
pub fn machine_file_text(name: &str, description: &str, axes: &[AxisModes]) -> String {
    let quote = |s: &str| toml::Value::String(s.to_string()).to_string();
    let mut out = format!(
        "name = {}\ndescription = {}\n",
        quote(name),
        quote(description)
    );
    for a in axes {
        out.push_str(&format!("\n[axis.{}]\nmodes = [\n", a.axis));
        for m in &a.modes {
            let mut sigmas = String::new();
            if let Some(s) = m.frequency_sigma_hz {
                sigmas.push_str(&format!(", frequency_sigma_hz = {s:?}"));
            }
            if let Some(s) = m.damping_ratio_sigma {
                sigmas.push_str(&format!(", damping_ratio_sigma = {s:?}"));
            }
            out.push_str(&format!(
                "  {{ frequency_hz = {:?}, damping_ratio = {:?}, weight = {:?}{sigmas} }},\n",
                m.frequency_hz, m.damping_ratio, m.weight
            ));
        }
        out.push_str("]\n");
    }
    out
}

/// The most modes one axis may have: identification finds up to 4 per axis, a careful
/// model a dozen; the simulation's cost grows with the cube of the count (1,000 modes take
/// 19 s per run, 100,000 would need 80 GB).
pub const MAX_MODES_PER_AXIS: usize = 100;

/// The axes `axes` (name, the key their modes are written at, the modes) checked: at
/// least one mode each and at most [`MAX_MODES_PER_AXIS`], every mode valid (settle-sim's
/// `Mode::new`); errors name the key.
pub fn to_axis_modes<'a>(
    axes: impl IntoIterator<Item = (String, String, &'a [ModeSpec])>,
    src: &Source,
) -> Result<Vec<AxisModes>, Error> {
    let mut out = Vec::new();
    for (axis, key, modes) in axes {
        if modes.is_empty() {
            return Err(src.error_at(
                &key,
                "give one or more modes: `modes = [{ frequency_hz, damping_ratio, weight }]`",
            ));
        }
        if modes.len() > MAX_MODES_PER_AXIS {
            return Err(src.error_at(
                &key,
                format!(
                    "{} modes; at most {MAX_MODES_PER_AXIS} per axis (a machine's axis has a handful that matter; each adds to every step of the simulation)",
                    modes.len()
                ),
            ));
        }
        for (i, m) in modes.iter().enumerate() {
            Mode::new(m.frequency_hz, m.damping_ratio, m.weight)
                .map_err(|e| src.error_at(&key, format!("mode {i}: {e}")))?;
            for (name, sigma) in [
                ("frequency_sigma_hz", m.frequency_sigma_hz),
                ("damping_ratio_sigma", m.damping_ratio_sigma),
            ] {
                if let Some(s) = sigma
                    && !(s.is_finite() && s >= 0.0)
                {
                    return Err(src.error_at(
                        &key,
                        format!("mode {i}: `{name}` = {s}: a standard deviation must be a finite number >= 0"),
                    ));
                }
            }
        }
        out.push(AxisModes {
            axis,
            modes: modes.to_vec(),
        });
    }
    Ok(out)
}
