//! The modes form of a machine: per axis, the lightly damped modes between the commanded
//! position and the toolhead (settle-sim's `Mode`: toolhead = command + sum weight_k e_k
//! with `e_k'' + 2 zeta_k w_k e_k' + w_k^2 e_k = -a_cmd`).
//!
//! Written as `[axis.<name>] modes = [...]` in a machine file, `[machine.axis.<name>]
//! modes = [...]` in a scenario, or `[machine] modes = [...]`, the shorthand for axis `x`.

use serde::Deserialize;

use crate::error::Error;
use crate::input::source::Source;

/// One mode of an axis. Every field has a documented range, checked when the machine is
/// read ([`ModeSpec::check`]).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ModeSpec {
    /// Natural frequency (Hz), [`MIN_FREQUENCY_HZ`] to [`MAX_FREQUENCY_HZ`].
    pub frequency_hz: f64,
    /// Damping ratio, in [0, 1).
    pub damping_ratio: f64,
    /// Participation in the toolhead error (weights of a real structure sum to 1), 0 to
    /// [`MAX_WEIGHT`].
    #[serde(default = "one")]
    pub weight: f64,
    /// One standard deviation of the frequency (Hz), >= 0 and below `frequency_hz`, when it
    /// was measured (`settle identify` writes it): `settle tune` then checks its shapers
    /// over the frequency's uncertainty band.
    #[serde(default)]
    pub frequency_sigma_hz: Option<f64>,
    /// One standard deviation of the damping ratio, when it was measured: 0, or > 0 and
    /// below `damping_ratio`.
    #[serde(default)]
    pub damping_ratio_sigma: Option<f64>,
}

/// The slowest mode a machine may have (Hz): a period of 100 s. The slowest structures
/// settle models have modes well above it (a wafer stage's air isolators at 0.5 to 3 Hz,
/// a gantry's frame at several Hz; `settle identify`'s resonance tests start at 1 Hz at
/// the lowest, Klipper's `FREQ_START`); a slower mode is a unit mistake (a period typed
/// for a frequency), and its observation window alone would be 50 s or more.
pub const MIN_FREQUENCY_HZ: f64 = 0.01;

/// The fastest mode a machine may have (Hz): the Nyquist frequency of the fastest
/// recording `settle identify` reads and of the fastest sample rate `settle gcode` takes
/// (both 100 kHz, settle-identify's `MAX_RATE_HZ` and `settle gcode`'s
/// `MAX_SAMPLE_RATE_HZ`), so no faster mode could be measured or resolved. A toolhead's
/// modes lie at tens to hundreds of Hz, a stiff stage's at a few kHz.
pub const MAX_FREQUENCY_HZ: f64 = 50_000.0;

/// The largest participation weight of a mode: twice the largest `settle identify`'s fit
/// can give (settle-identify's `fit::sweep_residual::MAX_WEIGHT`, 5), so every file it
/// writes reads back. The weights of a real structure's modes sum to 1, so a weight far
/// above that is no structure's.
pub const MAX_WEIGHT: f64 = 10.0;

/// A field of a mode outside its documented range.
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfRange {
    /// The key of the field (`frequency_hz`, `damping_ratio`, `weight`,
    /// `frequency_sigma_hz`, `damping_ratio_sigma`).
    pub field: &'static str,
    /// The value written.
    pub value: f64,
    /// What is allowed.
    pub allowed: String,
}

impl std::fmt::Display for OutOfRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`{}` = {:?}: allowed {}",
            self.field, self.value, self.allowed
        )
    }
}

impl ModeSpec {
    /// Check every field against its documented range (the one check for every command:
    /// a machine is read through [`to_axis_modes`], swept values are checked with this
    /// too): `frequency_hz` [`MIN_FREQUENCY_HZ`] to [`MAX_FREQUENCY_HZ`], `damping_ratio`
    /// in [0, 1) (settle-sim's `Mode`: underdamped), `weight` 0 to [`MAX_WEIGHT`] (0: a
    /// mode that does not show at the toolhead; settle-sim's `Mode` takes no negative
    /// weight), `frequency_sigma_hz` >= 0 and below `frequency_hz`,
    /// `damping_ratio_sigma` 0, or below `damping_ratio`. A standard deviation as
    /// large as its value says the value is not known (the 2-sigma band of a frequency
    /// would reach below 0 Hz); `settle identify` refuses such a fit before it writes a
    /// file (settle-identify's trust check), so every file it writes reads back.
    pub fn check(&self) -> Result<(), OutOfRange> {
        let out = |field, value, allowed: String| {
            Err(OutOfRange {
                field,
                value,
                allowed,
            })
        };
        let f = self.frequency_hz;
        if !(MIN_FREQUENCY_HZ..=MAX_FREQUENCY_HZ).contains(&f) {
            return out(
                "frequency_hz",
                f,
                format!(
                    "{MIN_FREQUENCY_HZ} to {MAX_FREQUENCY_HZ} Hz (a machine's modes lie at tens to hundreds of Hz, a stiff stage's at a few kHz; check the unit: Hz)"
                ),
            );
        }
        let z = self.damping_ratio;
        if !(0.0..1.0).contains(&z) {
            return out(
                "damping_ratio",
                z,
                "0 <= damping_ratio < 1 (underdamped; typical 0.02-0.15)".into(),
            );
        }
        if !(0.0..=MAX_WEIGHT).contains(&self.weight) {
            return out(
                "weight",
                self.weight,
                format!(
                    "0 to {MAX_WEIGHT} (the mode's share of the toolhead error; the weights of a real structure sum to 1)"
                ),
            );
        }
        if let Some(s) = self.frequency_sigma_hz
            && !(s >= 0.0 && s < f)
        {
            return out(
                "frequency_sigma_hz",
                s,
                format!(
                    "0 <= frequency_sigma_hz < frequency_hz ({f:?} Hz here): a standard deviation as large as the frequency says it is not known"
                ),
            );
        }
        if let Some(s) = self.damping_ratio_sigma
            && !(s == 0.0 || (s > 0.0 && s < z))
        {
            return out(
                "damping_ratio_sigma",
                s,
                format!(
                    "0, or > 0 and below damping_ratio ({z:?} here): a standard deviation as large as the damping ratio says it is not known"
                ),
            );
        }
        Ok(())
    }
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
/// least one mode each and at most [`MAX_MODES_PER_AXIS`], every mode in its documented
/// ranges ([`ModeSpec::check`]); errors name the key, the axis, the mode's index, the
/// field, its value and what is allowed.
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
            m.check()
                .map_err(|e| src.error_at(&key, format!("axis `{axis}`, mode {i}: {e}")))?;
        }
        out.push(AxisModes {
            axis,
            modes: modes.to_vec(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: ModeSpec = ModeSpec {
        frequency_hz: 40.0,
        damping_ratio: 0.05,
        weight: 1.0,
        frequency_sigma_hz: Some(0.2),
        damping_ratio_sigma: Some(0.004),
    };

    /// The field a mode is refused for, `None` when it is in range.
    fn refused(m: ModeSpec) -> Option<&'static str> {
        m.check().err().map(|e| e.field)
    }

    #[test]
    fn each_field_is_refused_outside_its_range_and_read_at_its_edges() {
        let with = |f: &dyn Fn(&mut ModeSpec)| {
            let mut m = GOOD;
            f(&mut m);
            m
        };
        assert_eq!(refused(GOOD), None);
        for (f, field) in [
            (1e-300, Some("frequency_hz")),
            (0.0099, Some("frequency_hz")),
            (MIN_FREQUENCY_HZ, None),
            (MAX_FREQUENCY_HZ, None),
            (50_000.1, Some("frequency_hz")),
            (1e300, Some("frequency_hz")),
            (f64::INFINITY, Some("frequency_hz")),
            (f64::NAN, Some("frequency_hz")),
        ] {
            let m = with(&|m| {
                m.frequency_hz = f;
                m.frequency_sigma_hz = None;
            });
            assert_eq!(refused(m), field, "frequency_hz = {f}");
        }
        for (z, field) in [
            (0.0, None),
            (0.999, None),
            (1.0, Some("damping_ratio")),
            (-0.01, Some("damping_ratio")),
        ] {
            let m = with(&|m| {
                m.damping_ratio = z;
                m.damping_ratio_sigma = None;
            });
            assert_eq!(refused(m), field, "damping_ratio = {z}");
        }
        for (w, field) in [
            (0.0, None),
            (MAX_WEIGHT, None),
            (10.001, Some("weight")),
            (1e300, Some("weight")),
            (-1.0, Some("weight")),
            (f64::NAN, Some("weight")),
        ] {
            assert_eq!(refused(with(&|m| m.weight = w)), field, "weight = {w}");
        }
        for (s, field) in [
            (0.0, None),
            (39.999, None),
            (40.0, Some("frequency_sigma_hz")),
            (1e300, Some("frequency_sigma_hz")),
            (-0.1, Some("frequency_sigma_hz")),
            (f64::INFINITY, Some("frequency_sigma_hz")),
            (f64::NAN, Some("frequency_sigma_hz")),
        ] {
            let m = with(&|m| m.frequency_sigma_hz = Some(s));
            assert_eq!(refused(m), field, "frequency_sigma_hz = {s}");
        }
        for (s, field) in [
            (0.0, None),
            (0.0499, None),
            (0.05, Some("damping_ratio_sigma")),
            (1e300, Some("damping_ratio_sigma")),
            (-1e-9, Some("damping_ratio_sigma")),
            (f64::NAN, Some("damping_ratio_sigma")),
        ] {
            let m = with(&|m| m.damping_ratio_sigma = Some(s));
            assert_eq!(refused(m), field, "damping_ratio_sigma = {s}");
        }
        // An undamped mode known exactly.
        let m = with(&|m| {
            m.damping_ratio = 0.0;
            m.damping_ratio_sigma = Some(0.0);
        });
        assert_eq!(refused(m), None);
    }

    #[test]
    fn a_mode_out_of_range_is_refused_naming_file_axis_mode_key_value_and_range() {
        let text = "name = \"m\"\n[axis.x]\nmodes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]\n[axis.y]\nmodes = [\n  { frequency_hz = 40.0, damping_ratio = 0.05 },\n  { frequency_hz = 60.0, damping_ratio = 0.05, frequency_sigma_hz = 1e300 },\n]\n";
        let e = crate::input::machine_file::parse_any(text, std::path::Path::new("m.toml"))
            .expect_err("refused")
            .to_string();
        assert!(
            e.starts_with("m.toml:5:1: key `axis.y.modes`: axis `y`, mode 1: `frequency_sigma_hz` = 1e300: allowed 0 <= frequency_sigma_hz < frequency_hz (60.0 Hz here)"),
            "{e}"
        );
        let e = crate::input::machine_file::parse_any(
            &text.replace("frequency_hz = 40.0", "frequency_hz = 1e300"),
            std::path::Path::new("m.toml"),
        )
        .expect_err("refused")
        .to_string();
        assert!(
            e.starts_with("m.toml:3:1: key `axis.x.modes`: axis `x`, mode 0: `frequency_hz` = 1e300: allowed 0.01 to 50000 Hz"),
            "{e}"
        );
    }

    #[test]
    fn the_bounds_keep_what_settle_identify_measures() {
        // No recording settle identify reads resolves a faster mode (settle gcode's rate
        // bound: tests/all/machine_cmd.rs).
        assert_eq!(MAX_FREQUENCY_HZ, settle_identify::read::MAX_RATE_HZ / 2.0);
        // Every weight settle identify's fit gives reads back.
        const { assert!(settle_identify::fit::sweep_residual::MAX_WEIGHT < MAX_WEIGHT) };
    }
}
