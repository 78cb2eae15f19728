//! `settle gcode --mcap`: an MCAP recording of the simulated samples (of the layer range
//! when one is given; the pre-roll is not recorded, the ringing after the last move is),
//! written while the job streams through the MCAP sink
//! ([`crate::output::sink::mcap::Stream`]): memory stays bounded however long the job.
//!
//! Topics (the sink's signal groups): `/cmd` (`x_m`, `y_m`: the commanded XY position),
//! `/toolhead` (`x_m`, `y_m`), `/contour` (`error_m`: the contour error, see
//! [`crate::studies::gcode::contour`]), `/move` (`line`, `layer`: the G-code line and layer
//! of the move the sample belongs to); `/metrics` at the end: file, setting, machine,
//! backend, print time, worst and p95 contour error.
//!
//! The file is written to a temporary file inside the output folder while the job runs
//! and moved into place only when the job has succeeded: bad G-code found halfway writes
//! nothing. A recording holds at most [`MAX_RECORDED_SAMPLES`] samples from the command
//! line: the job that reaches the bound stops there with an error that says how far it
//! got.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use serde_json::{Map, Value, json};

use crate::error::Error;
use crate::output::sink::mcap::{ChannelInfo, Stream};

/// Channel names of a recording, in the order of [`Recorder::sample`]'s values.
pub const CHANNELS: [&str; 7] = [
    "cmd_x",
    "cmd_y",
    "toolhead_x",
    "toolhead_y",
    "contour_error",
    "move_line",
    "move_layer",
];

/// Their units.
const UNITS: [&str; 7] = ["m", "m", "m", "m", "m", "", ""];

/// The most samples one recording holds: 2^25, 4.7 hours of print at the default 2 kHz and
/// about 4.5 GB of file ([`BYTES_PER_SAMPLE`]). A whole print recorded at 2 kHz takes
/// about 0.27 MB per second of print, and a G-code file of 2 GiB can be weeks of print:
/// without a bound the recording, not the memory, would fill the disk.
pub const MAX_RECORDED_SAMPLES: u64 = 1 << 25;

/// About what a sample takes in a recording (bytes): the four topics' messages with
/// their headers and the file's index (the 3DBenchy of `gcode/prints/benchy/`, 7.6
/// million samples, wrote 1.03 GB).
pub const BYTES_PER_SAMPLE: f64 = 135.0;

/// The first sample a full recording refused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Refused {
    /// Its time on the print clock (s).
    pub t_s: f64,
    /// The G-code line of its move.
    pub line: u64,
    /// Its layer.
    pub layer: u32,
}

/// The recording in progress.
pub struct Recorder {
    stream: Option<Stream<BufWriter<File>>>,
    tmp: PathBuf,
    error: Option<String>,
    /// Samples written.
    samples: u64,
    /// The most it may hold.
    max_samples: u64,
    /// The first sample refused past `max_samples`, once one was.
    full_at: Option<Refused>,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("tmp", &self.tmp)
            .field("error", &self.error)
            .field("samples", &self.samples)
            .finish()
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        // Not finished (an error): leave nothing behind.
        if self.stream.take().is_some() || self.error.is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

impl Recorder {
    /// Start a recording that becomes `path`, in a temporary file beside it (inside the
    /// output folder), with `metadata` in its `settle` record, holding at most
    /// `max_samples` samples ([`MAX_RECORDED_SAMPLES`] from the command line).
    pub fn start(
        metadata: BTreeMap<String, String>,
        path: &Path,
        max_samples: u64,
    ) -> Result<Self, Error> {
        let (tmp, file) = crate::output::atomic::create_tmp(path)?;
        let stream = Stream::new(
            BufWriter::new(file),
            env!("CARGO_PKG_VERSION"),
            metadata,
            &CHANNELS,
            &UNITS,
        )
        .map_err(|e| Error::write(&tmp, std::io::Error::other(e)))?;
        Ok(Self {
            stream: Some(stream),
            tmp,
            error: None,
            samples: 0,
            max_samples,
            full_at: None,
        })
    }

    /// One sample at `t_s` (values as [`CHANNELS`]). A write error stops the recording
    /// and is reported by [`Recorder::finish`]; a sample past the bound is not written
    /// and makes the recording [`Recorder::full`].
    pub fn sample(&mut self, t_s: f64, values: &[f64; 7]) {
        if self.samples >= self.max_samples {
            self.full_at.get_or_insert(Refused {
                t_s,
                line: values[5] as u64,
                layer: values[6] as u32,
            });
            return;
        }
        self.samples += 1;
        if let Some(s) = self.stream.as_mut()
            && let Err(e) = s.sample(t_s, values)
        {
            self.error = Some(crate::output::atomic::io_cause(&e).to_string());
            self.stream = None;
        }
    }

    /// The first sample refused past the bound, if one was. The job stops
    /// there; the recording is not kept.
    pub fn full(&self) -> Option<Refused> {
        self.full_at
    }

    /// End the recording with `metrics` and move it to `path`; returns what each channel
    /// holds.
    pub fn finish(
        mut self,
        metrics: Map<String, Value>,
        path: &Path,
    ) -> Result<Vec<ChannelInfo>, Error> {
        let fail = |m: String| Error::write(path, std::io::Error::other(m));
        if let Some(e) = &self.error {
            return Err(fail(e.clone()));
        }
        let Some(stream) = self.stream.take() else {
            return Err(fail("the recording was not started".into()));
        };
        let finished = stream
            .finish(metrics)
            .map_err(|e| fail(crate::output::atomic::io_cause(&e).to_string()))
            .and_then(|(info, w)| {
                w.into_inner().map_err(|e| fail(e.error().to_string()))?;
                Ok(info)
            });
        let info = finished.inspect_err(|e| self.error = Some(e.to_string()))?;
        crate::output::atomic::commit(&self.tmp, path)
            .inspect_err(|e| self.error = Some(e.to_string()))?;
        Ok(info)
    }
}

/// The `/metrics` message of a recording.
pub fn metrics(fields: &[(&str, Value)]) -> Map<String, Value> {
    fields
        .iter()
        .map(|(k, v)| ((*k).to_string(), v.clone()))
        .collect()
}

/// A number as a metrics value (`null` when not finite).
pub fn num(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { Value::Null }
}
