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

/// An accelerometer's full scale as a firmware reads it: the file holds `count x
/// count_mm_s2` for counts from `-min_count` to `max_count`. A sensor whose acceleration
/// passes its range reads the extreme count (it saturates), so a signal that reached it is
/// flat there and its spectrum holds harmonics that are not modes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FullScale {
    /// The sensor (and its axes), as messages name it.
    pub sensor: &'static str,
    /// One count of the value the firmware scales (mm/s^2).
    pub count_mm_s2: f64,
    /// The largest positive count.
    pub max_count: u32,
    /// The magnitude of the most negative count.
    pub min_count: u32,
}

impl FullScale {
    /// The magnitudes (mm/s^2) of the sensor's full scale: from its largest positive count
    /// to the magnitude of its most negative one (one count apart for a right-justified
    /// count; Klipper's `axes_map` may negate an axis, so either sign reaches both).
    pub fn magnitudes_mm_s2(&self) -> (f64, f64) {
        (
            f64::from(self.max_count) * self.count_mm_s2,
            f64::from(self.min_count) * self.count_mm_s2,
        )
    }
}

/// Klipper's `FREEFALL_ACCEL` (`klippy/extras/adxl345.py`), the g its drivers scale by.
const KLIPPER_G: f64 = 9.80665 * 1000.;

/// The full scales Klipper reads its accelerometers at (`klippy/extras/*.py` of Klipper,
/// the range register each driver writes and the scale it multiplies counts by; every
/// value is then rounded to 6 decimals):
/// - `adxl345.py`: `REG_DATA_FORMAT` 0x0B (full resolution, +-16 g), 13-bit counts
///   (-4096 to 4095, as `_convert_samples` sign-extends them) times `SCALE_XY` (0.003774 g)
///   or `SCALE_Z` (0.003906 g); before October 2022 one `SCALE` of 0.0039 g;
/// - `lis2dw.py`, LIS2DW: `CTRL_REG6` 0x34 (+-16 g), 14-bit counts left-justified in 16
///   bits (-32768 to 32764) times `1.952 / 4` mg;
/// - `lis2dw.py`, LIS3DH: `CTRL_REG4` 0x38 (+-16 g, high resolution), 12-bit counts
///   left-justified (-32768 to 32752) times `11.718 / 16` mg;
/// - `mpu9250.py` (MPU-9250, MPU-6050 and kin): `ACCEL_CONFIG` 0x10 (+-8 g), 16-bit counts
///   times 1/4096 g;
/// - `icm20948.py` (`ACCEL_CONFIG` 0x06) and `bmi160.py` (`ACC_RANGE` 0x0C): +-16 g,
///   16-bit counts times 1/2048 g.
pub const KLIPPER_FULL_SCALES: [FullScale; 7] = [
    FullScale {
        sensor: "an ADXL345's x or y axis (+-16 g, 13-bit counts of 3.774 mg)",
        count_mm_s2: 0.003774 * KLIPPER_G,
        max_count: 4095,
        min_count: 4096,
    },
    FullScale {
        sensor: "an ADXL345's z axis (+-16 g, 13-bit counts of 3.906 mg)",
        count_mm_s2: 0.003906 * KLIPPER_G,
        max_count: 4095,
        min_count: 4096,
    },
    FullScale {
        sensor: "an ADXL345 as Klipper read it before October 2022 (+-16 g, 13-bit counts of 3.9 mg)",
        count_mm_s2: 0.0039 * KLIPPER_G,
        max_count: 4095,
        min_count: 4096,
    },
    FullScale {
        sensor: "an LIS2DW (+-16 g, 14-bit counts of 1.952 mg)",
        count_mm_s2: 9.80665 * 1.952 / 4.,
        max_count: 32764,
        min_count: 32768,
    },
    FullScale {
        sensor: "an LIS3DH (+-16 g, 12-bit counts of 11.718 mg)",
        count_mm_s2: 9.80665 * 11.718 / 16.,
        max_count: 32752,
        min_count: 32768,
    },
    FullScale {
        sensor: "an MPU-9250 or MPU-6050 (+-8 g, 16-bit counts of 1/4096 g)",
        count_mm_s2: 0.000244140625 * KLIPPER_G,
        max_count: 32767,
        min_count: 32768,
    },
    FullScale {
        sensor: "an ICM-20948 or BMI160 (+-16 g, 16-bit counts of 1/2048 g)",
        count_mm_s2: KLIPPER_G / 2048.,
        max_count: 32767,
        min_count: 32768,
    },
];

/// How far a value Klipper wrote may lie from the full scale it reads (mm/s^2): its last
/// decimal (`round(..., 6)` and `%.6f` move a value by at most half of it).
pub const KLIPPER_FULL_SCALE_TOLERANCE_MM_S2: f64 = 1e-6;

/// The full scale RepRapFirmware reads every accelerometer at (g): +-2 g.
/// `LISAccelerometer::Configure` (`src/Accelerometers/LISAccelerometer.cpp`) leaves the
/// range bits of the LIS3DH, LIS3DSH and LIS2DW at +-2 g, and `Accelerometers.cpp` writes
/// each value as `count / 2^(bits - 2)` g (`GetBitsAfterPoint`: "assumes the range is +/-
/// 2g") with `GetDecimalPlaces` decimals: 2 for 8-bit counts, 3 for 10 and 12, 4 for 14
/// and 16 (`Configure` sets 8, 10 or 12 bits for an LIS3DH, 14 for an LIS2DW, 16 for an
/// LIS3DSH). Every value M956 writes lies from -2 to one count below 2 g.
pub const M956_FULL_SCALE_G: f64 = 2.0;

/// The count (g) of the coarsest resolution M956 writes with `decimals` decimals
/// (`GetDecimalPlaces` in RepRapFirmware's `Accelerometers.cpp`): 1/64 g (8 bits) for 2,
/// 1/256 g (10 bits) for 3, 1/4096 g (14 bits) for 4; the coarsest, 1/64 g, for any
/// other count of decimals (M956 writes none).
pub fn m956_count_g(decimals: usize) -> f64 {
    match decimals {
        3 => 1.0 / 256.0,
        4 => 1.0 / 4096.0,
        _ => 1.0 / 64.0,
    }
}

/// The magnitudes (mm/s^2) from which a value M956 wrote with `decimals` decimals is at its
/// full scale, and above which it is not M956's (a value beyond +-2 g): from one count of
/// [`m956_count_g`] below 2 g (the largest positive count; RepRapFirmware's axis inversion
/// turns the most negative count into it), less half the last decimal, to 2 g plus half
/// the last decimal. With 3 or 4 decimals the file's resolution may be finer than the
/// count taken (12 or 16 bits): the window then holds its last few counts too (within
/// 0.2 % of the full scale).
pub fn m956_full_scale_mm_s2(decimals: usize) -> (f64, f64) {
    let half = 0.5 * 10f64.powi(-(decimals.min(9) as i32));
    (
        (M956_FULL_SCALE_G - m956_count_g(decimals) - half) * STANDARD_GRAVITY_MM_S2,
        (M956_FULL_SCALE_G + half) * STANDARD_GRAVITY_MM_S2,
    )
}

/// One axis of a recording, for [`check_clipping`]: its column's name, its samples, and the
/// full scales (window of magnitudes, sensor named) it may have been read at.
pub(crate) struct ClipAxis<'a> {
    /// The column's name in the file (`accel_x`, `X`; `x` of a `.stdata` sample).
    pub column: String,
    /// The samples (mm/s^2).
    pub values: &'a [f64],
    /// Each full scale: the window of magnitudes `(low, high)` (mm/s^2) and the sensor.
    pub scales: Vec<((f64, f64), String)>,
}

/// Refuse a recording the sensor clipped: an axis with a sample whose magnitude lies in a
/// full scale's window while no sample of the axis lies above it (a sensor never reads
/// beyond its full scale; an axis that does was read at another range, and its values
/// near this one are measurements: the corpus's LIS2DW recordings, written at the
/// ADXL345's scale, pass it 14 times and reach 3.7 times it). The message names the axis
/// whose first clipped sample comes first: its line (`line_of`), its time (`time_of`, s),
/// its column (`name_of` the axis's column and the sample's index), its value and how many
/// samples of the axis are at the full scale.
///
/// A single sample at the full scale is refused too: whether the acceleration passed the
/// range or the read was corrupt, that sample is not a measurement, and nothing in the
/// file tells the two apart. (Klipper's `adxl_query` in `src/sensor_adxl345.c` already
/// drops reads it finds corrupt.)
pub(crate) fn check_clipping(
    file: &str,
    axes: &[ClipAxis],
    line_of: impl Fn(usize) -> usize,
    time_of: impl Fn(usize) -> f64,
    name_of: impl Fn(&str, usize) -> String,
    remedy: &str,
) -> Result<(), IdentifyError> {
    // (first index, count, axis, scale)
    let mut first: Option<(usize, usize, usize, usize)> = None;
    for (a, axis) in axes.iter().enumerate() {
        let peak = axis.values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (s, ((low, high), _)) in axis.scales.iter().enumerate() {
            if peak < *low || peak > *high {
                continue;
            }
            let at = |v: &&f64| v.abs() >= *low;
            let count = axis.values.iter().filter(at).count();
            let i = axis.values.iter().position(|v| v.abs() >= *low);
            if let Some(i) = i
                && first.is_none_or(|(j, ..)| i < j)
            {
                first = Some((i, count, a, s));
            }
        }
    }
    let Some((i, count, a, s)) = first else {
        return Ok(());
    };
    let axis = &axes[a];
    let v = axis.values[i];
    let column = name_of(&axis.column, i);
    let samples = if count == 1 {
        "1 sample, this one".to_string()
    } else {
        format!("{count} samples, the first here")
    };
    Err(IdentifyError::format(
        file,
        line_of(i),
        format!(
            "`{column}` reads {v:.6} mm/s^2 ({:.4} g) at {:.6} s, the full scale of {} (no sample of `{}` reads more): the sensor clipped ({samples})",
            v / STANDARD_GRAVITY_MM_S2,
            time_of(i),
            axis.scales[s].1,
            axis.column
        ),
        format!(
            "a recording within the sensor's range (a clipped signal is flat at the full scale, and its spectrum holds harmonics that are not modes): {remedy}"
        ),
    ))
}

/// The full scales of [`KLIPPER_FULL_SCALES`] as [`check_clipping`]'s windows, for the
/// samples `values` of column `column` of a file Klipper (or Shake&Tune, through Klipper)
/// wrote.
pub(crate) fn klipper_clip_axis(column: String, values: &[f64]) -> ClipAxis<'_> {
    let tol = KLIPPER_FULL_SCALE_TOLERANCE_MM_S2;
    let scales = KLIPPER_FULL_SCALES
        .iter()
        .map(|f| {
            let (low, high) = f.magnitudes_mm_s2();
            ((low - tol, high + tol), f.sensor.to_string())
        })
        .collect();
    ClipAxis {
        column,
        values,
        scales,
    }
}

/// What to do about a recording Klipper's sensor clipped.
pub(crate) const KLIPPER_CLIP_REMEDY: &str = "record again with less acceleration (a lower `accel_per_hz` in [resonance_tester] or TEST_RESONANCES, a gentler move), or mount the sensor where it moves less";

/// Smallest vibration a Klipper or Shake&Tune recording may hold (mm/s^2): the largest
/// deviation of a sensor axis from its mean must reach one count of the finest sensor
/// Klipper reads, an MPU-9250's 1/4096 g (2.39 mm/s^2; [`KLIPPER_FULL_SCALES`]: an
/// ICM-20948's or BMI160's is 4.79, an LIS2DW's 19.1, an ADXL345's 37 to 38). A sensor
/// resolves nothing finer: a recording that varies by less holds no measured vibration
/// (a sensor read while the machine stood still, values divided by a unit mistake).
pub const MIN_VIBRATION_MM_S2: f64 = 0.000244140625 * KLIPPER_G;

/// Smallest vibration an M956 recording may hold (mm/s^2): one count of the finest
/// resolution RepRapFirmware reads, 16 bits at +-2 g (1/16384 g, 0.599 mm/s^2; see
/// [`M956_FULL_SCALE_G`]).
pub const MIN_VIBRATION_M956_MM_S2: f64 = STANDARD_GRAVITY_MM_S2 / 16384.0;

/// Largest power spectral density a processed spectrum may hold ((mm/s^2)^2/Hz): 1e20,
/// above the PSD of accelerations within [`MAX_ACCEL_MM_S2`] (`1e18 x` Klipper's 0.5 s
/// window at most).
pub const MAX_PSD: f64 = 1e20;

/// Smallest peak a processed spectrum may hold ((mm/s^2)^2/Hz): 1e-12, about the PSD of a
/// vibration of 1e-6 mm/s^2 (the resolution Klipper writes, `%.6f`) over Klipper's 0.5 s
/// window.
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
                "time stamps {:.6} to {:.6} for {n} samples, a sample rate of {rate:.4} Hz{}",
                time_s[0],
                time_s[n - 1],
                unit_hint(time_s, rate)
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

/// What a time column that gives a rate outside [`MIN_RATE_HZ`] to [`MAX_RATE_HZ`] may be
/// instead of seconds: sample numbers (every step 1), or milliseconds or microseconds
/// when read so they give a rate within it; empty when neither.
fn unit_hint(time_s: &[f64], rate: f64) -> String {
    let numbers = time_s.windows(2).all(|w| w[1] - w[0] == 1.0);
    let within = |r: f64| (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&r);
    let unit = [(1e3, "milliseconds"), (1e6, "microseconds")]
        .into_iter()
        .find(|(k, _)| within(rate * k));
    match (numbers, unit) {
        (true, Some((k, unit))) => format!(
            " (the times count one a sample: sample numbers, or {unit} at {:.1} Hz)",
            rate * k
        ),
        (true, None) => " (the times count one a sample: sample numbers)".to_string(),
        (false, Some((k, unit))) => {
            format!(" (read as {unit}, the times give {:.1} Hz)", rate * k)
        }
        (false, None) => String::new(),
    }
}

/// At most 60 characters of `s`, for messages.
pub(crate) fn truncate(s: &str) -> String {
    if s.chars().count() <= 60 {
        s.to_string()
    } else {
        format!("{}...", s.chars().take(57).collect::<String>())
    }
}
