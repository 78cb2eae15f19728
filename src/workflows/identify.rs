//! `settle identify FILE...`: vibration modes per machine axis from accelerometer files
//! (Klipper raw and processed CSV, RepRapFirmware M956 CSV, Shake&Tune `.stdata`; read and
//! fitted by settle-identify), a table with uncertainties, a figure per axis and a
//! machine file in the modes form that `settle sweep` and `settle tune` take
//! (`preset = "machine.toml"` in a scenario's `[machine]`).
//!
//! Which machine axis a file excited: `--axis` when given, else the file's name: in
//! Klipper's names (`raw_data_x_*.csv`, `resonances_y_*.csv`, `calibration_data_x_*.csv`)
//! the word after the prefix, in others the one of the words `x`, `y`, `z` they hold (a
//! name holding two is refused); else the Shake&Tune measurement's name.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_identify::{AxisIdentification, Options, WeightBasis};

use settle_files::write::Inputs;

use crate::error::Error;
use crate::input::modes::{AxisModes, ModeSpec, machine_file_text};
use crate::output::folder::Results;
use crate::workflows::{Exit, Report};

/// What `settle identify` does.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifyOptions {
    /// The accelerometer files.
    pub files: Vec<PathBuf>,
    /// The machine axis every file excited (`x`, `y` or `z`), instead of the file names'.
    pub axis: Option<String>,
    /// Where to write the machine file, if anywhere.
    pub out: Option<PathBuf>,
    /// Folder of the figures `identify-<axis>.svg` / `.png` [default: the machine file's
    /// folder, else `results/identify/`].
    pub figures: Option<PathBuf>,
    /// settle-identify's options (the resonance test's parameters, modes per axis, fit).
    pub identify: Options,
    /// Overwrite the machine file at `out` and the figures of an earlier identification
    /// in the figures folder (refused without it).
    pub force: bool,
}

impl IdentifyOptions {
    /// Identify `files` with settle-identify's defaults (Klipper's resonance test).
    pub fn new(files: Vec<PathBuf>) -> Self {
        Self {
            files,
            axis: None,
            out: None,
            figures: None,
            identify: Options::default(),
            force: false,
        }
    }
}

/// One machine axis, identified.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifiedAxis {
    /// The machine axis.
    pub axis: String,
    /// The file it came from.
    pub file: PathBuf,
    /// settle-identify's result.
    pub id: AxisIdentification,
}

/// The outcome of `settle identify`.
#[derive(Debug, Clone, PartialEq)]
pub struct Identified {
    /// Per machine axis, ordered by axis name.
    pub axes: Vec<IdentifiedAxis>,
    /// The modes per axis as the machine file holds them (a weight the data do not
    /// determine is shared equally among the axis's modes, see [`modes_of`]).
    pub modes: Vec<AxisModes>,
    /// The machine file written, if asked for.
    pub machine_file: Option<PathBuf>,
    /// The figures written (`.svg`; a `.png` beside each).
    pub figures: Vec<PathBuf>,
}

/// The file-name prefixes of Klipper's resonance files: `get_filename` in
/// `klippy/extras/resonance_tester.py` names them `<prefix>_<axis>[_<chip>][_<point>]_<NAME>`
/// (`raw_data` for `OUTPUT=raw_data`, `resonances` for `TEST_RESONANCES`,
/// `calibration_data` for `SHAPER_CALIBRATE`), where `<axis>` is `x`, `y` or, for a
/// direction given as `AXIS=dx,dy`, `axis=dx,dy`, and `NAME` is the user's (the date and time
/// by default).
const KLIPPER_PREFIXES: [&str; 3] = ["raw_data_", "resonances_", "calibration_data_"];

/// The machine axis a file's name `name` gives: in a Klipper name (see
/// [`KLIPPER_PREFIXES`]) the word after the prefix, whatever the user's `NAME` holds;
/// otherwise the one of `x`, `y`, `z` that its words (split at `_`, `-`, `.`, spaces and
/// brackets) name. `Ok(None)`: no axis named; `Err`: why the name does not tell one (two
/// axes named, or Klipper's diagonal direction).
pub(crate) fn axis_in_name(name: &str) -> Result<Option<&'static str>, String> {
    let lower = name.to_ascii_lowercase();
    let as_axis = |t: &str| match t {
        "x" => Some("x"),
        "y" => Some("y"),
        "z" => Some("z"),
        _ => None,
    };
    if let Some(rest) = KLIPPER_PREFIXES.iter().find_map(|p| lower.strip_prefix(p)) {
        let word = rest.split('_').next().unwrap_or("");
        if let Some(a) = as_axis(word) {
            return Ok(Some(a));
        }
        if word.starts_with("axis=") {
            return Err(format!(
                "its name holds Klipper's `{word}`, a direction between the machine axes (TEST_RESONANCES AXIS=dx,dy), not one of them"
            ));
        }
    }
    let mut found: Vec<&'static str> = lower
        .split(['_', '-', '.', ' ', '(', ')'])
        .filter_map(as_axis)
        .collect();
    found.sort_unstable();
    found.dedup();
    match found.as_slice() {
        [] => Ok(None),
        [a] => Ok(Some(a)),
        many => Err(format!(
            "its name holds the words {}, more than one machine axis (a Klipper name starts `raw_data_<axis>_`, `resonances_<axis>_` or `calibration_data_<axis>_`, where the axis comes first)",
            many.iter()
                .map(|a| format!("`{a}`"))
                .collect::<Vec<_>>()
                .join(" and ")
        )),
    }
}

/// The machine axis `file` (identified as `id`) excited: `axis` if given, else the one
/// the file's name gives ([`axis_in_name`]), else the one a Shake&Tune measurement's name
/// gives, else the one axis
/// the file holds (an M956 capture of one axis). A name that names two axes is refused.
fn axis_of(file: &Path, id: &AxisIdentification, axis: Option<&str>) -> Result<String, Error> {
    if let Some(a) = axis {
        return Ok(a.to_string());
    }
    let refuse = |why: String| {
        Error::input(
            file,
            format!("cannot tell which machine axis this file excited: {why}: give --axis x|y|z"),
        )
    };
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if let Some(a) = axis_in_name(&stem).map_err(refuse)? {
        return Ok(a.to_string());
    }
    // A Shake&Tune measurement's name: the source is `<file> (<name>)`.
    let measurement = id
        .source
        .strip_prefix(&file.display().to_string())
        .unwrap_or("");
    if let Some(a) = axis_in_name(measurement).map_err(refuse)? {
        return Ok(a.to_string());
    }
    id.named_axis
        .map(|k| ["x", "y", "z"][k.min(2)].to_string())
        .ok_or_else(|| {
            refuse(
                "its name holds no `x`, `y` or `z` word as in Klipper's raw_data_x_*.csv, and it holds more than one sensor axis".to_string(),
            )
        })
}

/// The modes a machine file gets from `id`: each mode's estimate with the standard
/// deviations of its frequency and damping ratio (what `settle tune` takes as the
/// frequency's uncertainty band); a weight the data do not determine
/// ([`WeightBasis::NotIdentified`]) becomes `1 / n` for `n` modes.
pub fn modes_of(id: &AxisIdentification) -> Vec<ModeSpec> {
    let n = id.modes.len().max(1) as f64;
    let sigma = |s: f64| s.is_finite().then_some(s);
    id.modes
        .iter()
        .map(|m| ModeSpec {
            frequency_hz: m.frequency_hz.value,
            damping_ratio: m.damping_ratio.value,
            weight: m.weight.map_or(1.0 / n, |w| w.value),
            frequency_sigma_hz: sigma(m.frequency_hz.sigma),
            damping_ratio_sigma: sigma(m.damping_ratio.sigma),
        })
        .collect()
}

/// Identify every file, write the figures and (if asked) the machine file.
pub fn identify(opts: &IdentifyOptions) -> Result<Identified, Error> {
    if let Some(a) = opts.axis.as_deref()
        && !matches!(a, "x" | "y" | "z")
    {
        return Err(Error::input(
            "--axis",
            format!("unknown axis `{a}`; allowed: x, y, z"),
        ));
    }
    if opts.files.is_empty() {
        return Err(Error::input("FILE", "give one or more accelerometer files"));
    }
    check_options(&opts.identify)?;
    // The outputs, checked before any work: never onto a recording, a link or a device.
    let inputs = Inputs::of(&opts.files);
    if let Some(out) = &opts.out {
        inputs.refuse(out)?;
        settle_files::write::check_target(out)?;
        if !opts.force && std::fs::symlink_metadata(out).is_ok() {
            return Err(Error::input(
                "--force",
                format!(
                    "{} already exists (an earlier identification's machine file?): pass --force to overwrite it, --out FILE to write elsewhere",
                    out.display()
                ),
            ));
        }
    }
    let dir = figures_dir(opts);
    crate::output::folder::check(&dir, &FIGURES, opts.force, &inputs, writes_figure)?;
    let mut axes: Vec<IdentifiedAxis> = Vec::new();
    for file in &opts.files {
        for id in settle_identify::identify_file(file, &opts.identify)? {
            let axis = axis_of(file, &id, opts.axis.as_deref())?;
            if let Some(prev) = axes.iter().find(|a| a.axis == axis) {
                return Err(Error::input(
                    file,
                    format!(
                        "a second recording of axis `{axis}` ({} has one): give one recording per axis, or name the axis of each with --axis in separate runs",
                        prev.id.source
                    ),
                ));
            }
            axes.push(IdentifiedAxis {
                axis,
                file: file.clone(),
                id,
            });
        }
    }
    axes.sort_by(|a, b| a.axis.cmp(&b.axis));
    let modes: Vec<AxisModes> = axes
        .iter()
        .map(|a| AxisModes {
            axis: a.axis.clone(),
            modes: modes_of(&a.id),
        })
        .collect();
    crate::output::atomic::create_dir(&dir)?;
    let mut figures = Vec::new();
    for a in &axes {
        let stem = format!("identify-{}", a.axis);
        crate::output::plot::write(
            &crate::output::plot::identify::figure(&a.axis, &a.id),
            &dir,
            &stem,
        )?;
        figures.push(dir.join(format!("{stem}.svg")));
    }
    let machine_file = match &opts.out {
        Some(out) => {
            let sources: Vec<String> = axes.iter().map(|a| a.id.source.clone()).collect();
            let text = machine_file_text(
                "identified",
                &format!(
                    "Modes identified by `settle identify` from {}",
                    sources.join(", ")
                ),
                &modes,
            );
            crate::output::atomic::write_atomic(out, text.as_bytes())?;
            Some(out.clone())
        }
        None => None,
    };
    Ok(Identified {
        axes,
        modes,
        machine_file,
        figures,
    })
}

/// The ranges of the resonance test's options, as `TEST_RESONANCES` takes them in
/// Klipper's `resonance_tester.py` (FREQ_START >= 1 Hz, FREQ_END at most 300 Hz) with
/// settle's own bounds where Klipper has none: a band of at least 5 Hz to fit in, a sweep
/// rate of 0.1 to 100 Hz/s (Klipper's `hz_per_sec` takes 0.1 to 2; slower sweeps make
/// tests of hours whose excitation settle would hold in memory), a sweeping period of 0
/// (off) or 0.1 to 100 s.
pub const FREQ_MIN_HZ: f64 = 1.0;
/// See [`FREQ_MIN_HZ`].
pub const FREQ_MAX_HZ: f64 = 300.0;
/// See [`FREQ_MIN_HZ`].
pub const HZ_PER_SEC: (f64, f64) = (0.1, 100.0);
/// See [`FREQ_MIN_HZ`].
pub const SWEEPING_PERIOD_S: (f64, f64) = (0.1, 100.0);

/// Check the options against their documented ranges before any file is read; errors
/// name the command-line option.
fn check_options(o: &settle_identify::Options) -> Result<(), Error> {
    let t = &o.test;
    let bad = |key: &str, msg: String| Err(Error::input(key, msg));
    if !(1..=4).contains(&o.max_modes) {
        return bad("--max-modes", format!("{}: allowed 1 to 4", o.max_modes));
    }
    if !(t.freq_start_hz.is_finite() && (FREQ_MIN_HZ..FREQ_MAX_HZ).contains(&t.freq_start_hz)) {
        return bad(
            "--freq-start",
            format!(
                "{} Hz: allowed {FREQ_MIN_HZ} to under {FREQ_MAX_HZ} Hz (Klipper's FREQ_START is at least 1 Hz)",
                t.freq_start_hz
            ),
        );
    }
    if !(t.freq_end_hz.is_finite()
        && t.freq_end_hz >= t.freq_start_hz + 5.0
        && t.freq_end_hz <= FREQ_MAX_HZ)
    {
        return bad(
            "--freq-end",
            format!(
                "{} Hz: allowed from 5 Hz above --freq-start ({} Hz) to {FREQ_MAX_HZ} Hz (Klipper's FREQ_END is at most 300 Hz)",
                t.freq_end_hz, t.freq_start_hz
            ),
        );
    }
    let (lo, hi) = HZ_PER_SEC;
    if !(t.hz_per_sec.is_finite() && (lo..=hi).contains(&t.hz_per_sec)) {
        return bad(
            "--hz-per-sec",
            format!("{} Hz/s: allowed {lo} to {hi} Hz/s", t.hz_per_sec),
        );
    }
    if !(t.accel_per_hz.is_finite() && t.accel_per_hz > 0.0) {
        return bad(
            "--accel-per-hz",
            format!("{} mm/s^2/Hz: allowed a finite number > 0", t.accel_per_hz),
        );
    }
    if !(t.sweeping_accel_mm_s2.is_finite() && t.sweeping_accel_mm_s2 >= 0.0) {
        return bad(
            "--sweeping-accel",
            format!(
                "{} mm/s^2: allowed a finite number >= 0 (0: no sweeping motion)",
                t.sweeping_accel_mm_s2
            ),
        );
    }
    let (lo, hi) = SWEEPING_PERIOD_S;
    let p = t.sweeping_period_s;
    if !(p == 0.0 || (p.is_finite() && (lo..=hi).contains(&p))) {
        return bad(
            "--sweeping-period",
            format!("{p} s: allowed 0 (no sweeping motion) or {lo} to {hi} s"),
        );
    }
    Ok(())
}

/// The figures folder: `--figures`, else the machine file's folder, else
/// `results/identify/`.
fn figures_dir(opts: &IdentifyOptions) -> PathBuf {
    match (&opts.figures, &opts.out) {
        (Some(d), _) => d.clone(),
        (None, Some(out)) => out
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf),
        (None, None) => PathBuf::from("results/identify"),
    }
}

/// The figures of an earlier identification, which `--force` overwrites.
const FIGURES: Results<'static> = Results {
    what: "settle identify",
    marks: &[
        "identify-x.svg",
        "identify-x.png",
        "identify-y.svg",
        "identify-y.png",
        "identify-z.svg",
        "identify-z.png",
    ],
};

/// Whether identify writes `rel` in its figures folder.
fn writes_figure(rel: &Path) -> bool {
    crate::output::folder::written(
        rel,
        &[],
        &[],
        &[("identify-", ".svg"), ("identify-", ".png")],
    )
}

/// `value ± sigma` with at least `digits` decimals, and as many more as show the
/// sigma's first two significant digits.
fn pm(value: f64, sigma: f64, digits: usize) -> String {
    let shown = if sigma.is_finite() && sigma > 0.0 {
        digits.max((1.0 - sigma.log10().floor()).max(0.0) as usize)
    } else {
        digits
    };
    format!("{value:.shown$} ± {sigma:.shown$}")
}

impl Identified {
    /// The table `settle identify` prints: per axis and mode the frequency, damping ratio
    /// and weight with one standard deviation, and where the motion showed in the sensor.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "{:<4} {:<16} {:>4} {:>20} {:>8} {:>20} {:>18}  method",
            "axis", "sensor", "mode", "frequency_hz", "peak_hz", "damping_ratio", "weight"
        );
        for a in &self.axes {
            let sensor = match (&a.id.direction, a.id.dominant_sensor_axis) {
                (Some(d), _) => d.describe(),
                (None, Some(k)) => format!("psd_{} (PSD)", ["x", "y", "z"][k.min(2)]),
                (None, None) => "-".to_string(),
            };
            let method = match a.id.method {
                settle_identify::Method::SweepFit => "sweep fit",
                settle_identify::Method::RingDownFit => "ring-down fit",
            };
            for (i, m) in a.id.modes.iter().enumerate() {
                let weight = match (m.weight, m.weight_basis) {
                    (Some(w), WeightBasis::Fitted) => pm(w.value, w.sigma, 3),
                    (Some(w), _) => format!("{:.3} (assumed)", w.value),
                    (None, _) => "not identified".to_string(),
                };
                let _ = writeln!(
                    out,
                    "{:<4} {:<16} {:>4} {:>20} {:>8.2} {:>20} {:>18}  {method}",
                    a.axis,
                    sensor,
                    i,
                    pm(m.frequency_hz.value, m.frequency_hz.sigma, 2),
                    m.peak_hz,
                    pm(m.damping_ratio.value, m.damping_ratio.sigma, 4),
                    weight,
                );
            }
            for p in &a.id.diagnostics.rejected {
                let _ = writeln!(
                    out,
                    "{:<4} not a mode: {:.1} Hz: {}",
                    a.axis, p.frequency_hz, p.reason
                );
            }
            for n in &a.id.notes {
                let _ = writeln!(out, "{:<4} note: {n}", a.axis);
            }
        }
        let _ = writeln!(
            out,
            "frequency_hz is each mode's natural frequency (the machine file's); peak_hz is where the mode shows as a peak in a spectrum, as Klipper's and Shake&Tune's graphs show it."
        );
        if self
            .axes
            .iter()
            .flat_map(|a| &a.id.modes)
            .any(|m| m.weight.is_none())
        {
            let _ = writeln!(
                out,
                "A free decay does not show how strongly each mode takes part: the machine file shares the weight equally among such an axis's modes."
            );
        }
        out
    }

    /// What the binary prints: the table on stdout, the files written on stderr.
    pub fn report(&self) -> Report {
        let mut r = Report::new(Exit::Ok);
        r.stdout = self.table();
        for f in &self.figures {
            r.err(format!("wrote {} (and .png)", f.display()));
        }
        if let Some(m) = &self.machine_file {
            r.err(format!(
                "wrote {}: use it with `preset = \"{}\"` in a scenario's [machine], or `settle machine {}`",
                m.display(),
                m.display(),
                m.display()
            ));
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::axis_in_name;

    #[test]
    fn klipper_names_give_the_word_after_their_prefix() {
        for (name, axis) in [
            ("raw_data_x_20260101_120000", "x"),
            ("resonances_y_20260101_120000", "y"),
            ("calibration_data_x_20260101_120000", "x"),
            // The user's NAME may hold any word: the axis is the one after the prefix.
            ("raw_data_y_z_test", "y"),
            ("calibration_data_x_after_y_belt", "x"),
            ("raw_data_x_adxl345_hotend_0.000_0.000_20.000_run1", "x"),
            ("RAW_DATA_Y_20260101", "y"),
        ] {
            assert_eq!(axis_in_name(name), Ok(Some(axis)), "{name}");
        }
        let diagonal = axis_in_name("raw_data_axis=1.000,-1.000_20260101_120000");
        assert!(
            diagonal.as_ref().is_err_and(|e| e.contains("AXIS=dx,dy")),
            "{diagonal:?}"
        );
    }

    #[test]
    fn other_names_give_their_one_axis_word_and_two_are_refused() {
        for (name, axis) in [
            ("neptune_inputshaper_20250707_143713_axis_X", "x"),
            ("metis_resonances_20240206_200335_Y", "y"),
            ("resonances_20240206_200114_X", "x"),
            ("x_again_x", "x"),
        ] {
            assert_eq!(axis_in_name(name), Ok(Some(axis)), "{name}");
        }
        assert_eq!(axis_in_name("recording"), Ok(None));
        for name in ["z_x", "y-belt x", "test x y", "raw_x_data_y"] {
            let got = axis_in_name(name);
            assert!(
                got.as_ref()
                    .is_err_and(|e| e.contains("more than one machine axis")),
                "{name}: {got:?}"
            );
        }
    }
}
