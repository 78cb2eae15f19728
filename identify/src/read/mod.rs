//! Readers for the accelerometer files users already have. Each returns plain data.
//!
//! - [`klipper_raw`]: Klipper's raw accelerometer CSV (`#time,accel_x,accel_y,accel_z`);
//! - [`klipper_psd`]: Klipper's processed spectra (`freq,psd_x,psd_y,psd_z,psd_xyz...`),
//!   and [`klipper_grid`], the frequency grid they are written on;
//! - [`rrf`]: RepRapFirmware's M956 CSV (`Sample,X,Y,Z` ... `Rate <Hz>, overflows <n>`);
//! - [`stdata`]: Shake&Tune's `.stdata` (zstd-compressed JSON lines).
//!
//! [`read_file`] picks the reader from the file's content.

pub mod klipper_grid;
pub mod klipper_psd;
pub mod klipper_raw;
pub mod rrf;
pub mod stdata;

use std::path::Path;

use crate::IdentifyError;

/// The largest file the readers take, and the most text a `.stdata` file may decompress
/// to (bytes): settle-files' limit for a recording, [`settle_files::limit::RECORDING`]
/// (64 MiB, three times a 130 s Klipper test at 3.2 kHz: 20 MB). With [`MAX_SAMPLES`] it
/// bounds what identifying a file holds in memory (`docs/performance.md`).
pub const MAX_FILE_BYTES: u64 = settle_files::limit::RECORDING.bytes;

/// The most samples one recording may hold: 1.5 million, 7.8 minutes at 3.2 kHz.
pub const MAX_SAMPLES: usize = 1_500_000;

/// The most rows a processed spectrum may hold (Klipper writes about 130, one per bin up
/// to 200 Hz).
pub const MAX_SPECTRUM_ROWS: usize = 100_000;

/// The error for a recording with more than [`MAX_SAMPLES`] samples, found at `line`.
pub(crate) fn too_many_samples(file: &str, line: usize) -> IdentifyError {
    IdentifyError::not_accepted(
        file,
        format!("more than {MAX_SAMPLES} samples (line {line})"),
        format!("at most {MAX_SAMPLES} samples a recording (7.8 minutes at 3.2 kHz)"),
    )
}

/// Standard gravity (mm/s^2), as Klipper's `adxl345.py` (`FREEFALL_ACCEL`) and the g
/// values of RepRapFirmware's files use it.
pub const STANDARD_GRAVITY_MM_S2: f64 = 9_806.65;

/// Largest acceleration a recording may hold (mm/s^2): 1e9, about 100,000 g, 250 times
/// the range of the widest-range MEMS accelerometers (+-400 g) and 6,000 times the
/// ADXL345's +-16 g. A larger value is a unit or scale mistake, not a measurement; far
/// beyond it (from about 1e70) the spectrum's squares overflow.
pub const MAX_ACCEL_MM_S2: f64 = 1e9;

/// Smallest vibration a recording may hold (mm/s^2): the largest deviation of a sensor
/// axis from its mean must reach 1e-6 mm/s^2, the resolution Klipper writes (`%.6f`);
/// no accelerometer resolves less (an ADXL345 step is 38 mm/s^2).
pub const MIN_VIBRATION_MM_S2: f64 = 1e-6;

/// Largest power spectral density a processed spectrum may hold ((mm/s^2)^2/Hz): 1e20,
/// above the PSD of accelerations within [`MAX_ACCEL_MM_S2`] (`1e18 x` Klipper's 0.5 s
/// window at most).
pub const MAX_PSD: f64 = 1e20;

/// Smallest peak a processed spectrum may hold ((mm/s^2)^2/Hz): 1e-12, about the PSD of a
/// vibration at [`MIN_VIBRATION_MM_S2`] over Klipper's 0.5 s window.
pub const MIN_PEAK_PSD: f64 = 1e-12;

/// `value_mm_s2` (read as `text` in column `column` at `line`) as an acceleration within
/// +-[`MAX_ACCEL_MM_S2`].
pub(crate) fn check_accel(
    file: &str,
    line: usize,
    column: &str,
    text: &str,
    value_mm_s2: f64,
) -> Result<f64, IdentifyError> {
    if value_mm_s2.abs() > MAX_ACCEL_MM_S2 {
        return Err(IdentifyError::format(
            file,
            line,
            format!(
                "`{}` in column `{column}`, an acceleration of {value_mm_s2:.3e} mm/s^2 ({:.3e} g)",
                truncate(text.trim()),
                value_mm_s2 / STANDARD_GRAVITY_MM_S2
            ),
            format!(
                "accelerations within +-{MAX_ACCEL_MM_S2:.0e} mm/s^2 (about 100,000 g; no accelerometer reads more: the file's unit or scale is wrong)"
            ),
        ));
    }
    Ok(value_mm_s2)
}

/// Fewest samples a reader accepts: below this no spectrum or decay can be measured.
pub const MIN_SAMPLES: usize = 64;

/// Slowest sample rate a reader accepts (Hz): accelerometers for resonance tests sample at
/// 400 to 6,400 Hz; a rate below this means the time column is not in seconds
/// (milliseconds give 1,000 times too low a rate) or the file is not a recording.
pub const MIN_RATE_HZ: f64 = 20.0;

/// Fastest sample rate a reader accepts (Hz): fifteen times the fastest ADXL345 rate.
pub const MAX_RATE_HZ: f64 = 100_000.0;

/// Longest interval between two samples, in median intervals: Klipper's and Shake&Tune's
/// samples arrive evenly (their time stamps jitter by a few percent); a longer pause is a
/// gap in the recording (two recordings joined, samples lost), which a spectrum or a
/// decay fit cannot bridge.
pub const MAX_GAP_INTERVALS: f64 = 20.0;

/// Largest departure of the sample rate over a stretch of a recording from its mean rate
/// (a fraction): 1 %. The analysis reads every sample at the mean rate, so a recording
/// whose rate changes (two recordings at different rates joined, a logger that lost its
/// clock) shows each frequency of a stretch at another rate moved by the difference: a
/// 45 Hz ring-down whose rate halves after 0.3 s fits as a confident 24.8 Hz. The raw
/// recordings of the corpus (identify/tests/corpus) hold their rate to 0.22 % over every
/// tenth of the file.
pub const MAX_RATE_DEPARTURE: f64 = 0.01;

/// Fewest intervals a stretch of [`MAX_RATE_DEPARTURE`]'s check spans: 100, over which
/// the jitter of single time stamps (a few percent of an interval) averages out to under
/// 0.1 %. The check takes up to ten stretches of at least this many intervals (none in a
/// recording of fewer than 200 intervals).
pub const RATE_STRETCH_INTERVALS: usize = 100;

/// Which file format a recording came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordingFormat {
    /// Klipper raw accelerometer CSV.
    KlipperRaw,
    /// RepRapFirmware M956 CSV.
    RrfM956,
    /// Shake&Tune `.stdata`.
    ShakeTune,
}

/// Accelerometer samples in the sensor's frame (after the firmware's axes map).
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Where the data came from (the file name as given), for messages.
    pub source: String,
    /// The file format.
    pub format: RecordingFormat,
    /// The measurement's name inside the file (Shake&Tune), if any.
    pub name: Option<String>,
    /// Sample times (s). For RepRapFirmware files (no time stamps): `n / rate`.
    pub time_s: Vec<f64>,
    /// Acceleration per sensor axis x, y, z (mm/s^2); `None` for an axis the file does not
    /// hold (M956 writes only the requested axes).
    pub accel_mm_s2: [Option<Vec<f64>>; 3],
    /// Sample rate (Hz). Klipper files: `N / (t_last - t_first)`, exactly as Klipper's
    /// `shaper_calibrate.py` computes it; M956 files: the `Rate` line.
    pub sample_rate_hz: f64,
    /// The one sensor axis the file holds, when it names a single one (an M956 capture of
    /// one axis, `Sample,Y`): RepRapFirmware users record the axis they test, so it is the
    /// machine axis unless told otherwise (0 = x).
    pub named_axis: Option<usize>,
    /// The last line number of the file that holds a sample (for messages).
    pub last_line: usize,
}

impl Recording {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// The mean rate of the samples (Hz): `(N - 1) / (t_last - t_first)`, the rate their
    /// spacing gives (Klipper's `N / (t_last - t_first)`, [`Recording::sample_rate_hz`],
    /// is `N / (N - 1)` times it, which would shift every frequency by that factor: 1e-5
    /// for a 100,000-sample sweep, as much as a sweep fit's frequency uncertainty).
    /// [`Recording::sample_rate_hz`] when the times do not span an interval.
    pub fn mean_rate_hz(&self) -> f64 {
        let n = self.time_s.len();
        let span = match (self.time_s.first(), self.time_s.last()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        if n > 1 && span > 0.0 {
            (n - 1) as f64 / span
        } else {
            self.sample_rate_hz
        }
    }

    /// True when the recording holds no samples (readers never return one).
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }
}

/// What a file held: time-domain recordings or a processed spectrum.
#[derive(Debug, Clone, PartialEq)]
pub enum FileData {
    /// One or more recordings (a `.stdata` file may hold several measurements).
    Recordings(Vec<Recording>),
    /// A Klipper processed spectrum.
    Spectrum(klipper_psd::ProcessedPsd),
}

/// Read any supported file, choosing the reader by content: zstd magic bytes ->
/// Shake&Tune, `#time,` -> Klipper raw, `freq,` -> Klipper processed, `Sample` -> M956.
pub fn read_file(path: &Path) -> Result<FileData, IdentifyError> {
    use settle_files::looks::Looks;
    let file = path.display().to_string();
    let bytes = settle_files::read::read_bytes(path, settle_files::limit::RECORDING)?;
    let packed = settle_files::packed::Packed::of(&bytes);
    if packed == Some(settle_files::packed::Packed::Zstd) {
        return stdata::parse(&file, &bytes).map(FileData::Recordings);
    }
    const EXPECTED: &str = "a CSV text file or a zstd-compressed .stdata file";
    // A zip or gzip of a recording, or UTF-16 text (ASCII in UTF-16 is valid UTF-8 with
    // a zero byte between characters): named, with what to do.
    let named = |p: settle_files::packed::Packed| {
        let why = format!("{}, not UTF-8 text: {}", p.name(), p.instead());
        IdentifyError::format(&file, 1, why, EXPECTED)
    };
    if let Some(p) = packed.filter(|p| p.is_utf16()) {
        return Err(named(p));
    }
    // What the file is when it is not a recording (a G-code job, a scenario, a model):
    // named, with the command that reads it, in place of the reader's refusal.
    let head = &bytes[..bytes.len().min(settle_files::looks::HEAD)];
    let looks = settle_files::looks::Looks::of(head, &file, bytes.len() as u64)
        .filter(|l| !matches!(l, Looks::Recording | Looks::Packed(_)));
    let foreign =
        |l: Looks| IdentifyError::format(&file, 1, format!("{}: {}", l.what(), l.then()), EXPECTED);
    let mut text = String::from_utf8(bytes).map_err(|e| match (packed, looks) {
        (Some(p), _) => named(p),
        (None, Some(l)) => foreign(l),
        (None, None) => IdentifyError::format(
            &file,
            1,
            format!("bytes that are not UTF-8 text ({e})"),
            EXPECTED,
        ),
    })?;
    // A byte-order mark (spreadsheet programs on Windows write one) is not the header.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .unwrap_or("");
    if first.starts_with("#time") {
        klipper_raw::parse(&file, &text).map(|r| FileData::Recordings(vec![r]))
    } else if first.starts_with("freq,") {
        klipper_psd::parse(&file, &text).map(FileData::Spectrum)
    } else if first.starts_with("Sample") {
        rrf::parse(&file, &text).map(|r| FileData::Recordings(vec![r]))
    } else if let Some(l) = looks {
        Err(foreign(l))
    } else {
        // The line is not repeated: a file that is not a recording (a wrong path,
        // /etc/shadow) is not shown on the terminal.
        Err(IdentifyError::format(
            &file,
            1,
            "a first line that is not a recording's header",
            "a header `#time,accel_x,accel_y,accel_z` (Klipper raw), `freq,psd_x,...` (Klipper processed), `Sample,X,Y,Z` (RepRapFirmware M956) or a zstd-compressed .stdata file",
        ))
    }
}

/// Parse one number of a CSV field, naming the file, line and column on failure.
pub(crate) fn parse_number(
    file: &str,
    line: usize,
    column: &str,
    text: &str,
) -> Result<f64, IdentifyError> {
    let v: f64 = text.trim().parse().map_err(|_| {
        IdentifyError::format(
            file,
            line,
            format!("`{}` in column `{column}`", truncate(text.trim())),
            "a number",
        )
    })?;
    if !v.is_finite() {
        return Err(IdentifyError::NotFinite {
            file: file.to_string(),
            line,
            column: column.to_string(),
            value: v,
        });
    }
    Ok(v)
}

/// Check the time stamps (at least two): strictly increasing, a sample rate between
/// [`MIN_RATE_HZ`] and [`MAX_RATE_HZ`], the same rate throughout (within
/// [`MAX_RATE_DEPARTURE`]), no interval longer than [`MAX_GAP_INTERVALS`] median
/// intervals. `line_of(i)` is sample `i`'s line number.
pub(crate) fn check_times(
    file: &str,
    time_s: &[f64],
    line_of: impl Fn(usize) -> usize,
) -> Result<(), IdentifyError> {
    for (i, w) in time_s.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(IdentifyError::NotMonotonic {
                file: file.to_string(),
                line: line_of(i + 1),
                time_s: w[1],
                previous_s: w[0],
            });
        }
    }
    let n = time_s.len();
    let rate = (n - 1) as f64 / (time_s[n - 1] - time_s[0]);
    if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) {
        return Err(IdentifyError::format(
            file,
            line_of(n - 1),
            format!(
                "time stamps {:.6} to {:.6} for {n} samples, a sample rate of {rate:.4} Hz",
                time_s[0],
                time_s[n - 1]
            ),
            format!(
                "times in seconds (Klipper writes `%.6f` s) at {MIN_RATE_HZ} to {MAX_RATE_HZ} samples per second"
            ),
        ));
    }
    let mut dt: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = dt.len() / 2;
    let median = *dt.select_nth_unstable_by(mid, f64::total_cmp).1;
    if let Some(i) = time_s
        .windows(2)
        .position(|w| w[1] - w[0] > MAX_GAP_INTERVALS * median)
    {
        return Err(IdentifyError::format(
            file,
            line_of(i + 1),
            format!(
                "a gap of {:.6} s after {:.6} s, {:.0} times the median interval of {median:.6} s",
                time_s[i + 1] - time_s[i],
                time_s[i],
                (time_s[i + 1] - time_s[i]) / median
            ),
            format!(
                "one continuous recording (no interval longer than {MAX_GAP_INTERVALS} median intervals): split the file at the gap"
            ),
        ));
    }
    let stretches = ((n - 1) / RATE_STRETCH_INTERVALS).min(10);
    if stretches >= 2 {
        for j in 0..stretches {
            let (a, b) = (j * (n - 1) / stretches, (j + 1) * (n - 1) / stretches);
            let local = (b - a) as f64 / (time_s[b] - time_s[a]);
            if (local / rate - 1.0).abs() > MAX_RATE_DEPARTURE {
                return Err(IdentifyError::format(
                    file,
                    line_of(a),
                    format!(
                        "samples {a} to {b} ({:.6} to {:.6} s) at {local:.2} Hz, {:+.1} % off the recording's mean rate of {rate:.2} Hz",
                        time_s[a],
                        time_s[b],
                        100.0 * (local / rate - 1.0)
                    ),
                    format!(
                        "one recording at one sample rate (every stretch within {:.0} % of the mean rate): split the file where its rate changes",
                        100.0 * MAX_RATE_DEPARTURE
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// At most 60 characters of `s`, for messages.
pub(crate) fn truncate(s: &str) -> String {
    if s.chars().count() <= 60 {
        s.to_string()
    } else {
        format!("{}...", s.chars().take(57).collect::<String>())
    }
}
