//! RepRapFirmware's M956 accelerometer CSV (`0:/sys/accelerometer/*.csv`).
//!
//! Written by `src/Accelerometers/Accelerometers.cpp` of RepRapFirmware: a header
//! `Sample` followed by `,X`, `,Y`, `,Z` for the requested axes only (all three when none
//! is named), then one row per sample: the sample number counting from 0 and the
//! acceleration of each requested axis in g (printed with 2 to 4 decimals depending on the
//! resolution). There are no time stamps; the last line is `Rate <Hz>, overflows <n>` (the
//! measured sample rate). A capture that failed holds a line such as `Failed to collect
//! data from accelerometer` or `Received bad data` instead.

use super::{
    ClipAxis, MAX_RATE_HZ, MAX_SAMPLES, MIN_RATE_HZ, MIN_SAMPLES, Recording, RecordingFormat,
    STANDARD_GRAVITY_MM_S2, check_accel, check_clipping, m956_full_scale_mm_s2, parse_number,
    too_many_samples, truncate,
};
use crate::IdentifyError;

const EXPECTED_HEADER: &str = "`Sample` followed by one or more of `,X`, `,Y`, `,Z` in that order";

/// Parse the text of an M956 file; `file` names it in errors.
pub fn parse(file: &str, text: &str) -> Result<Recording, IdentifyError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let Some((hn, header)) = lines.next() else {
        return Err(IdentifyError::format(
            file,
            1,
            "an empty file",
            EXPECTED_HEADER,
        ));
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut axis_of_column = Vec::new();
    let mut last_axis = None;
    for name in names.iter().skip(1) {
        let axis = match *name {
            "X" => 0,
            "Y" => 1,
            "Z" => 2,
            _ => usize::MAX,
        };
        if axis == usize::MAX || last_axis.is_some_and(|a| a >= axis) {
            return Err(IdentifyError::format(
                file,
                hn,
                format!("header `{}`", truncate(header)),
                EXPECTED_HEADER,
            ));
        }
        last_axis = Some(axis);
        axis_of_column.push(axis);
    }
    if names[0] != "Sample" || axis_of_column.is_empty() {
        return Err(IdentifyError::format(
            file,
            hn,
            format!("header `{}`", truncate(header)),
            EXPECTED_HEADER,
        ));
    }
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); axis_of_column.len()];
    // The fewest decimals a column's values are written with: M956 writes them all with
    // as many as its resolution gives (`GetDecimalPlaces`), which says its count.
    let mut decimals = vec![usize::MAX; axis_of_column.len()];
    let mut line_numbers = Vec::new();
    let mut rate_hz = None;
    let mut last_line = hn;
    for (n, l) in lines {
        if rate_hz.is_some() {
            return Err(IdentifyError::format(
                file,
                n,
                format!("`{}` after the rate line", truncate(l)),
                "nothing after the last line `Rate <Hz>, overflows <n>`",
            ));
        }
        if let Some(rest) = l.strip_prefix("Rate") {
            rate_hz = Some(parse_rate_line(file, n, rest)?);
            continue;
        }
        let mut fields = l.split(',');
        let index = fields.next().unwrap_or("").trim();
        let expected_index = columns[0].len();
        if index.parse::<usize>().ok() != Some(expected_index) {
            let expected = format!(
                "a row `{expected_index},<g>...` (sample numbers count up from 0), or the last line `Rate <Hz>, overflows <n>`"
            );
            return Err(IdentifyError::format(
                file,
                n,
                format!("`{}`", truncate(l)),
                expected,
            ));
        }
        if columns[0].len() == MAX_SAMPLES {
            return Err(too_many_samples(file, n));
        }
        for (k, col) in columns.iter_mut().enumerate() {
            let name = names[k + 1];
            let Some(v) = fields.next() else {
                return Err(IdentifyError::format(
                    file,
                    n,
                    format!("no value for column `{name}` (`{}`)", truncate(l)),
                    format!(
                        "{} values in g after the sample number",
                        axis_of_column.len()
                    ),
                ));
            };
            let g = parse_number(file, n, name, v)?;
            col.push(check_accel(file, n, name, v, g * STANDARD_GRAVITY_MM_S2)?);
            decimals[k] = decimals[k].min(decimals_of(v));
        }
        if fields.next().is_some() {
            return Err(IdentifyError::format(
                file,
                n,
                format!("more fields than the header names (`{}`)", truncate(l)),
                format!(
                    "{} values in g after the sample number",
                    axis_of_column.len()
                ),
            ));
        }
        line_numbers.push(n);
        last_line = n;
    }
    let Some(rate_hz) = rate_hz else {
        return Err(IdentifyError::format(
            file,
            last_line,
            "no rate line at the end of the file (a capture cut short?)",
            "the last line `Rate <Hz>, overflows <n>`",
        ));
    };
    let count = columns[0].len();
    if count < MIN_SAMPLES {
        return Err(IdentifyError::TooFewSamples {
            file: file.to_string(),
            line: last_line,
            what: "samples",
            found: count,
            needed: MIN_SAMPLES,
        });
    }
    let clip: Vec<_> = columns
        .iter()
        .zip(&names[1..])
        .zip(&decimals)
        .map(|((values, name), &d)| ClipAxis {
            column: name.to_string(),
            values,
            scales: vec![(
                m956_full_scale_mm_s2(d),
                format!(
                    "RepRapFirmware's accelerometers (+-2 g; {d} decimals: counts of 1/{:.0} g or finer)",
                    1.0 / super::m956_count_g(d)
                ),
            )],
        })
        .collect();
    check_clipping(
        file,
        &clip,
        |i| line_numbers[i],
        |i| i as f64 / rate_hz,
        |c, _| c.to_string(),
        "record again with less acceleration (a gentler move), or mount the sensor where it moves less (RepRapFirmware reads every accelerometer at +-2 g; an axis along gravity reads 1 g at rest)",
    )?;
    let named_axis = (axis_of_column.len() == 1).then(|| axis_of_column[0]);
    let mut accel: [Option<Vec<f64>>; 3] = [None, None, None];
    for (axis, col) in axis_of_column.into_iter().zip(columns) {
        accel[axis] = Some(col);
    }
    Ok(Recording {
        source: file.to_string(),
        format: RecordingFormat::RrfM956,
        name: None,
        time_s: (0..count).map(|i| i as f64 / rate_hz).collect(),
        accel_mm_s2: accel,
        sample_rate_hz: rate_hz,
        named_axis,
        last_line,
    })
}

/// `rest` is what follows `Rate`: ` <Hz>, overflows <n>`. The rate must lie between
/// [`MIN_RATE_HZ`] and [`MAX_RATE_HZ`]; a capture with overflows lost samples (the
/// sensor's FIFO overflowed), so its samples are not evenly spaced at the rate and are
/// refused.
fn parse_rate_line(file: &str, line: usize, rest: &str) -> Result<f64, IdentifyError> {
    let expected =
        format!("`Rate <Hz>, overflows <n>` with a rate of {MIN_RATE_HZ} to {MAX_RATE_HZ} Hz");
    let bad = || {
        IdentifyError::format(
            file,
            line,
            format!("`Rate{}`", truncate(rest)),
            expected.clone(),
        )
    };
    let (rate, overflows) = rest.split_once(',').ok_or_else(bad)?;
    let rate: f64 = rate.trim().parse().map_err(|_| bad())?;
    let overflows = overflows.trim().strip_prefix("overflows").ok_or_else(bad)?;
    let overflows = overflows.trim().parse::<u64>().map_err(|_| bad())?;
    if !(MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate) {
        return Err(bad());
    }
    if overflows > 0 {
        return Err(IdentifyError::format(
            file,
            line,
            format!("`Rate{}`: the capture lost samples", truncate(rest)),
            "`overflows 0`: samples evenly spaced at the rate (capture again, fewer samples or a lower rate)",
        ));
    }
    Ok(rate)
}

/// How many decimals the number `text` is written with (digits after its point).
fn decimals_of(text: &str) -> usize {
    text.trim().split_once('.').map_or(0, |(_, f)| {
        f.chars().take_while(char::is_ascii_digit).count()
    })
}
