//! `settle tune --criterion klipper FILE...`: Klipper's own shaper choice, as its
//! `scripts/calibrate_shaper.py` makes it, on the files a Klipper user has:
//!
//! - processed resonance CSVs (`resonances_*.csv`, `calibration_data_*.csv`): the PSD
//!   columns (one data set per column, or `psd_xyz` of the per-axis layout), normalised
//!   to the test's frequencies unless the file holds shaper columns. A file with shaper
//!   columns (`SHAPER_CALIBRATE`'s `calibration_data_*.csv`) was written normalised,
//!   whether its header names them after a `shapers:` column (Klipper since October
//!   2025) or straight after `psd_xyz` (before). Today's script takes only the first
//!   as normalised and normalises the older ones a second time (its `parse_log` tests
//!   `',shapers:' not in header`; before October 2025 it tested `'mzv' not in header`);
//!   settle reads them as written, as the script of their day did;
//! - raw accelerometer CSVs (`raw_data_*.csv`): the PSD computed as Klipper computes it
//!   (settle-identify's [`klipper_response`]), summed over the axes and normalised.
//!
//! Then `find_best_shaper` with the script's options (settle-planner's `shaper_select`,
//! matched against the script). Files name their machine axis like Klipper's
//! (`calibration_data_x_*.csv`); the files of one axis are combined into one choice as the
//! script combines the files it is given, and each axis gets its own. The output repeats
//! the script's lines, so the two can be compared word for word; `--out` writes the
//! `[input_shaper]` lines and, per axis, the graph the script draws (the spectrum, each
//! shaper's remaining vibration and the spectrum after the recommended one).

use std::path::{Path, PathBuf};

use settle_identify::SweepTest;
use settle_identify::read::{FileData, klipper_psd};
use settle_identify::welch::klipper_response;
use settle_planner::shaper::ShaperType;
use settle_planner::shaper_select::{
    CalibrationData, MAX_SHAPER_FREQ_HZ, SelectOptions, Selection, find_best_shaper,
};

use crate::error::Error;
use crate::output::atomic::{create_dir, write_atomic};
use crate::workflows::{Exit, Report};

/// What `settle tune --criterion klipper` does.
#[derive(Debug, Clone, PartialEq)]
pub struct KlipperCriterion {
    /// The resonance files (processed or raw CSVs).
    pub files: Vec<PathBuf>,
    /// Folder for `input_shaper.cfg` and the graphs, if any.
    pub out: Option<PathBuf>,
    /// calibrate_shaper.py's options (`--shapers`, `--scv`, `--max_smoothing`, ...).
    pub select: SelectOptions,
    /// Overwrite the results of an earlier run in `out` (refused without it).
    pub force: bool,
}

/// The files `--criterion klipper` writes in its output folder: `input_shaper.cfg` and
/// one figure per axis group ([`FIGURES`]).
const FILES: [&str; 1] = ["input_shaper.cfg"];

/// The figures, `klipper-shapers-<axis>.svg/png` (`<axis>`: x, y, z or all).
const FIGURES: [(&str, &str); 2] = [("klipper-shapers-", ".svg"), ("klipper-shapers-", ".png")];

/// What marks an earlier run's results in the output folder.
const MARKS: [&str; 5] = [
    "input_shaper.cfg",
    "klipper-shapers-x.svg",
    "klipper-shapers-y.svg",
    "klipper-shapers-z.svg",
    "klipper-shapers-all.svg",
];

/// An earlier run's results, which `--force` overwrites.
const RESULTS: crate::output::folder::Results<'static> = crate::output::folder::Results {
    what: "settle tune --criterion klipper",
    marks: &MARKS,
};

impl KlipperCriterion {
    /// From the command line: the files, `--out`, and calibrate_shaper.py's `--shapers`
    /// (comma-separated, commas inside parentheses kept: `mzv(n=4,t=0.8),ei`), `--scv`
    /// (0.1 to 1000 mm/s) and `--max_smoothing` (0.05 to 10 mm; the script's own lower
    /// bound).
    pub fn from_args(
        files: Vec<PathBuf>,
        out: Option<PathBuf>,
        shapers: Option<&str>,
        scv_mm_s: Option<f64>,
        max_smoothing_mm: Option<f64>,
    ) -> Result<Self, Error> {
        let mut select = SelectOptions::default();
        if let Some(list) = shapers {
            select.shapers = split_shapers(list)
                .iter()
                .map(|name| {
                    ShaperType::parse(name).map_err(|e| Error::input("--shapers", e.to_string()))
                })
                .collect::<Result<_, _>>()?;
            if select.shapers.is_empty() {
                return Err(Error::input("--shapers", "name at least one shaper"));
            }
        }
        if let Some(v) = scv_mm_s {
            if !(0.1..=1000.0).contains(&v) {
                return Err(Error::input(
                    "--scv",
                    format!("{v} mm/s is out of range; allowed 0.1 to 1000"),
                ));
            }
            select.scv_mm_s = v;
        }
        if let Some(v) = max_smoothing_mm {
            if !(0.05..=10.0).contains(&v) {
                return Err(Error::input(
                    "--max-smoothing",
                    format!("{v} mm is out of range; allowed 0.05 to 10"),
                ));
            }
            select.max_smoothing_mm = Some(v);
        }
        Ok(Self {
            files,
            out,
            select,
            force: false,
        })
    }
}

/// Split a shaper list at commas outside parentheses (the script's
/// `re.split(r",(?![^(]*\))", ...)`), lower-cased.
fn split_shapers(list: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut depth = 0usize;
    for c in list.to_ascii_lowercase().chars() {
        match c {
            '(' => {
                depth += 1;
                cur.push(c);
            }
            ')' => {
                depth = depth.saturating_sub(1);
                cur.push(c);
            }
            ',' if depth == 0 => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out.into_iter()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

/// The files of one machine axis and Klipper's choice on them.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisChoice {
    /// The machine axis (`x`, `y`, `z`) from the file names, `None` when they name none.
    pub axis: Option<char>,
    /// The files, in the order given.
    pub files: Vec<PathBuf>,
    /// Their data sets, as calibrate_shaper.py holds them.
    pub data: Vec<CalibrationData>,
    /// The choice.
    pub selection: Selection,
}

/// The machine axis a Klipper file's name names (`calibration_data_x_20220317.csv`), by
/// `settle identify`'s rule ([`crate::workflows::identify::axis_in_name`]); a name that
/// names two axes, or Klipper's diagonal direction, is refused.
fn axis_token(path: &Path) -> Result<Option<char>, Error> {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    let axis = crate::workflows::identify::axis_in_name(&stem.unwrap_or_default());
    let axis = axis.map_err(|why| {
        Error::input(
            path,
            format!("cannot tell which machine axis this file's test shook: {why}"),
        )
    })?;
    Ok(axis.and_then(|a| a.chars().next()))
}

/// The data sets of one file as calibrate_shaper.py's `parse_log` makes them.
pub fn load(path: &Path) -> Result<Vec<CalibrationData>, Error> {
    match settle_identify::read_file(path)? {
        FileData::Spectrum(psd) => {
            spectrum_sees_the_test(path, psd.freq_hz.last().copied())?;
            let sets = processed(&psd);
            for d in &sets {
                holds_a_resonance(path, d)?;
            }
            Ok(sets)
        }
        FileData::Recordings(recs) => recs
            .iter()
            .map(|rec| {
                sees_the_test(path, rec.sample_rate_hz)?;
                let (freq_hz, [x, y, z]) = klipper_response(rec).ok_or_else(|| {
                    Error::input(
                        path,
                        "a raw recording with all three axes, longer than Klipper's half-second segment",
                    )
                })?;
                let psd_sum = x.iter().zip(&y).zip(&z).map(|((a, b), c)| a + b + c).collect();
                let mut d = CalibrationData {
                    freq_hz,
                    psd_sum,
                    psd_x: Some(x),
                    psd_y: Some(y),
                    psd_z: Some(z),
                };
                d.normalize_to_frequencies();
                holds_a_resonance(path, &d)?;
                Ok(d)
            })
            .collect(),
    }
}

/// The highest frequency a recording's spectrum must show for Klipper's fit (Hz): the top
/// of Klipper's resonance test (`max_freq` of `[resonance_tester]`, 135 Hz,
/// [`SweepTest::klipper`]) and of the shaper frequencies the fit tries
/// (`MAX_SHAPER_FREQ` of shaper_calibrate.py, 150 Hz, [`MAX_SHAPER_FREQ_HZ`]), whichever
/// is higher. Below the first the spectrum cannot show the resonances the test excites;
/// below the second the fit can place a shaper at a frequency the recording does not
/// resolve (a 125 Hz resonance sampled at 280 Hz had its `ei`, `2hump_ei` and `3hump_ei`
/// fitted at 149.8, 145.8 and 149.8 Hz, above the recording's 140 Hz Nyquist frequency).
fn fit_top_hz() -> f64 {
    SweepTest::klipper().freq_end_hz.max(MAX_SHAPER_FREQ_HZ)
}

/// A raw recording sampled at `sample_rate_hz` resolves frequencies up to its Nyquist
/// frequency only: at or below [`fit_top_hz`], a shaper fitted to its spectrum answers
/// for what it never saw. Refused, with the rate that would do.
fn sees_the_test(path: &Path, sample_rate_hz: f64) -> Result<(), Error> {
    let top_hz = fit_top_hz();
    let nyquist_hz = sample_rate_hz / 2.0;
    if nyquist_hz > top_hz {
        return Ok(());
    }
    Err(Error::input(
        path,
        format!(
            "sampled at {sample_rate_hz:.1} Hz, it resolves frequencies up to {nyquist_hz:.1} Hz (Nyquist), not the {top_hz:.0} Hz up to which Klipper's fit places shapers (its resonance test stops at {:.0} Hz): a shaper fitted to it would answer for frequencies it cannot show; record at more than {:.0} Hz (an ADXL345 records at 3,200 Hz)",
            SweepTest::klipper().freq_end_hz,
            2.0 * top_hz
        ),
    ))
}

/// A processed spectrum (a PSD CSV) whose rows end at `last_hz`: [`sees_the_test`] for
/// spectra. calibrate_shaper.py writes its rows up to 200 Hz (every file of the corpus
/// ends at 198.5-199.9 Hz); one that ends below [`fit_top_hz`] (a cut copy) holds nothing
/// of the resonances above its end, and a shaper fitted to it answers for them. Refused,
/// with the range that would do.
fn spectrum_sees_the_test(path: &Path, last_hz: Option<f64>) -> Result<(), Error> {
    let top_hz = fit_top_hz();
    match last_hz {
        Some(last) if last >= top_hz => Ok(()),
        _ => Err(Error::input(
            path,
            format!(
                "its spectrum ends at {:.1} Hz, below the {top_hz:.0} Hz up to which Klipper's fit places shapers (its resonance test stops at {:.0} Hz): a shaper fitted to it would answer for frequencies it does not show; give the whole file (calibrate_shaper.py writes its rows up to 200 Hz)",
                last_hz.unwrap_or(0.0),
                SweepTest::klipper().freq_end_hz
            ),
        )),
    }
}

/// The band in which a spectrum must show a resonance (Hz): from twice Klipper's lowest
/// frequency (`MIN_FREQ` 5 Hz; below 10 Hz calibrate_shaper.py's normalisation also rolls
/// the spectrum off) to the top of Klipper's resonance test ([`SweepTest::klipper`]).
const RESONANCE_BAND_LO_HZ: f64 = 10.0;

/// A data set `d` (as calibrate_shaper.py fits it: normalised to the frequencies,
/// `psd / (f + 0.1)`) must show a resonance: in the test's band, its largest PSD as
/// measured (the normalisation undone) at least
/// [`settle_identify::fit::sweep::MIN_PEAK_TO_FLOOR`] (10) times its noise floor (the 5th
/// percentile), the rule of `settle identify`'s sweep fit, and at least
/// [`settle_identify::read::MIN_PEAK_PSD`] (a spectrum of zeros or of rounding is no
/// vibration). A recording of noise, of a still machine or of a constant holds none (its
/// ratio is about 1; the resonance tests of the corpus, identify/tests/corpus, reach 71 to
/// 939): Klipper's fit would still name a shaper and a frequency for it, which answer for
/// nothing. Refused, with the ratio.
/// (A processed file with shaper columns comes normalised as Klipper wrote it; the others
/// are normalised when read, as the script does.)
fn holds_a_resonance(path: &Path, d: &CalibrationData) -> Result<(), Error> {
    let top_hz = SweepTest::klipper().freq_end_hz;
    let mut sorted: Vec<f64> = d
        .freq_hz
        .iter()
        .zip(&d.psd_sum)
        .filter(|(f, _)| (RESONANCE_BAND_LO_HZ..=top_hz).contains(*f))
        .map(|(f, p)| p * (f + 0.1))
        .collect();
    sorted.sort_by(f64::total_cmp);
    let (peak, floor) = match sorted.as_slice() {
        [] => (0.0, 0.0),
        s => (
            s[s.len() - 1],
            s[((s.len() - 1) as f64 * 0.05).round() as usize],
        ),
    };
    let needed = settle_identify::fit::sweep::MIN_PEAK_TO_FLOOR;
    let least = settle_identify::read::MIN_PEAK_PSD;
    if peak >= least && peak >= needed * floor {
        return Ok(());
    }
    let why = if peak >= least {
        format!(
            "no resonance peak above the noise between {RESONANCE_BAND_LO_HZ:.0} and {top_hz:.0} Hz (largest PSD / noise floor is {:.2}; at least {needed:.0} is needed): a recording of noise or of a machine at rest, for which a shaper and its frequency would answer for nothing; record a resonance test (TEST_RESONANCES)",
            peak / floor
        )
    } else {
        format!(
            "no vibration between {RESONANCE_BAND_LO_HZ:.0} and {top_hz:.0} Hz: the largest PSD is {peak:.3e} (mm/s^2)^2/Hz, below the {least:.0e} of a vibration at the resolution Klipper writes (a sensor that read one value, a file of zeros); record a resonance test (TEST_RESONANCES)"
        )
    };
    Err(Error::input(path, why))
}

/// A processed file's data sets: `psd_xyz` (with the axes) of the per-axis layout, else
/// one per column; normalised unless the file holds shaper columns (with or without the
/// `shapers:` column before them: Klipper wrote both normalised).
fn processed(psd: &klipper_psd::ProcessedPsd) -> Vec<CalibrationData> {
    let normalise = psd.shapers.is_empty();
    let col = |k: usize| Some(psd.columns[k].1.clone());
    let sets: Vec<CalibrationData> = if psd.per_axis {
        vec![CalibrationData {
            freq_hz: psd.freq_hz.clone(),
            psd_sum: psd.columns[3].1.clone(),
            psd_x: col(0),
            psd_y: col(1),
            psd_z: col(2),
        }]
    } else {
        psd.columns
            .iter()
            .map(|(_, c)| CalibrationData {
                freq_hz: psd.freq_hz.clone(),
                psd_sum: c.clone(),
                ..CalibrationData::default()
            })
            .collect()
    };
    sets.into_iter()
        .map(|mut d| {
            if normalise {
                d.normalize_to_frequencies();
            }
            d
        })
        .collect()
}

/// Klipper's choice per machine axis.
pub fn choose(c: &KlipperCriterion) -> Result<Vec<AxisChoice>, Error> {
    if c.files.is_empty() {
        return Err(Error::input(
            "FILE",
            "give one or more Klipper resonance CSVs",
        ));
    }
    let mut groups: Vec<(Option<char>, Vec<PathBuf>, Vec<CalibrationData>)> = Vec::new();
    for f in &c.files {
        let axis = axis_token(f)?;
        let data = load(f)?;
        match groups.iter_mut().find(|g| g.0 == axis) {
            Some(g) => {
                g.1.push(f.clone());
                g.2.extend(data);
            }
            None => groups.push((axis, vec![f.clone()], data)),
        }
    }
    groups
        .into_iter()
        .map(|(axis, files, data)| {
            let selection = find_best_shaper(&data, &c.select)
                .map_err(|e| Error::input(&files[0], e.to_string()))?;
            Ok(AxisChoice {
                axis,
                files,
                data,
                selection,
            })
        })
        .collect()
}

/// calibrate_shaper.py's lines for one axis.
fn script_lines(a: &AxisChoice, r: &mut Report) {
    let names: Vec<String> = a.files.iter().map(|f| f.display().to_string()).collect();
    r.out(format!("Processing resonances from {}", names.join(",")));
    for s in &a.selection.per_shaper {
        r.out(format!(
            "Fitted shaper '{}' frequency = {:.1} Hz (vibrations = {:.1}%, smoothing ~= {:.3})",
            s.shaper_type.name(),
            s.frequency_hz,
            s.vibrations * 100.0,
            s.smoothing_mm
        ));
        r.out(format!(
            "To avoid too much smoothing with '{}', suggested max_accel <= {:.0} mm/sec^2",
            s.shaper_type.name(),
            (s.max_accel_mm_s2 / 100.0).round_ties_even() * 100.0 // Python 3 round()
        ));
    }
    r.out(format!(
        "Recommended shaper is {} @ {:.1} Hz",
        a.selection.recommended.shaper_type.name(),
        a.selection.recommended.frequency_hz
    ));
}

/// The `[input_shaper]` lines of the recommendations (`shaper_type_x` / `shaper_freq_x`,
/// `_y`, per axis the file names name), with the suggested acceleration limit as a comment.
/// Klipper's `[input_shaper]` reads `shaper_freq_x` and `shaper_freq_y` only (and refuses
/// an option it does not read, klippy/configfile.py's `check_unused_options`): the
/// recommendation for files that name no axis, or name `z`, is written as a comment that
/// says where it goes.
pub fn input_shaper_cfg(choices: &[AxisChoice]) -> String {
    let mut s = String::from(
        "# Klipper's recommendation (scripts/calibrate_shaper.py's choice), from settle tune --criterion klipper\n[input_shaper]\n",
    );
    for a in choices {
        let r = &a.selection.recommended;
        match a.axis {
            Some(c @ ('x' | 'y')) => s.push_str(&format!(
                "shaper_type_{c}: {}\nshaper_freq_{c}: {:.1}\n",
                r.shaper_type.name(),
                r.frequency_hz
            )),
            _ => s.push_str(&format!("# {}\n", unplaced(a))),
        }
    }
    for a in choices {
        let r = &a.selection.recommended;
        s.push_str(&format!(
            "# {}: suggested max_accel <= {:.0} mm/s^2 with {}\n",
            a.axis.map_or("all".to_string(), |c| c.to_string()),
            (r.max_accel_mm_s2 / 100.0).round_ties_even() * 100.0,
            r.shaper_type.name()
        ));
    }
    s
}

/// Why a recommendation has no `[input_shaper]` key (its files name no axis Klipper
/// shapes), and where it goes.
fn unplaced(a: &AxisChoice) -> String {
    let r = &a.selection.recommended;
    let names: Vec<String> = a.files.iter().map(|f| f.display().to_string()).collect();
    let why = match a.axis {
        Some(c) => format!("name{} axis {c}", if names.len() == 1 { "s" } else { "" }),
        None => format!(
            "name{} no axis (an x or y in the name, as calibration_data_x_*.csv)",
            if names.len() == 1 { "s" } else { "" }
        ),
    };
    format!(
        "{} {why}, and Klipper's [input_shaper] shapes x and y only (shaper_type_x, shaper_freq_x, shaper_type_y, shaper_freq_y): {} @ {:.1} Hz goes under the keys of the axis the test shook",
        names.join(", "),
        r.shaper_type.name(),
        r.frequency_hz
    )
}

/// What `settle tune --criterion klipper FILE...` prints (calibrate_shaper.py's lines per
/// axis) and writes (with `--out`).
pub fn report(c: &KlipperCriterion) -> Result<Report, Error> {
    // The output folder, before any work: never one of the files read, a file, a link out
    // or a device where a file goes, nor earlier results unasked.
    if let Some(dir) = &c.out {
        let inputs = settle_files::write::Inputs::of(&c.files);
        let writes = |rel: &Path| crate::output::folder::written(rel, &FILES, &[], &FIGURES);
        crate::output::folder::check(dir, &RESULTS, c.force, &inputs, writes)?;
    }
    let choices = choose(c)?;
    let mut r = Report::new(Exit::Ok);
    for a in &choices {
        script_lines(a, &mut r);
    }
    for a in choices
        .iter()
        .filter(|a| !matches!(a.axis, Some('x' | 'y')))
    {
        r.err(format!("note: {}", unplaced(a)));
    }
    if let Some(dir) = &c.out {
        create_dir(dir)?;
        let cfg = dir.join("input_shaper.cfg");
        write_atomic(&cfg, input_shaper_cfg(&choices).as_bytes())?;
        r.err(format!("wrote {}", cfg.display()));
        for a in &choices {
            let axis = a.axis.map_or("all".to_string(), |c| c.to_string());
            let stem = format!("klipper-shapers-{axis}");
            let figure = crate::output::plot::klipper_shapers::figure(
                &axis,
                &a.files,
                &a.data[0],
                &a.selection,
                &c.select,
            );
            crate::output::plot::write(&figure, dir, &stem)?;
            r.err(format!(
                "wrote {} (and .png)",
                dir.join(format!("{stem}.svg")).display()
            ));
        }
    }
    Ok(r)
}
