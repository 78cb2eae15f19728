//! MCAP recordings of one run, for Foxglove and any MCAP reader.
//!
//! Layout of `run-<id>.mcap` (one file per run; see the README's "MCAP recordings"):
//! - profile `""` (no ROS); chunks compressed with zstd (single-threaded, so the bytes do not
//!   depend on the machine's core count); message, chunk and metadata indexes and statistics.
//! - one channel per signal group of the run's [`crate::measure::series::Series`] (see
//!   [`super::groups`]): topic `/<group>`, message encoding `json`, schema
//!   `settle.<group>` in encoding `jsonschema`, one message per sample whose keys are the
//!   group's fields with their units (`p_m`, `v_m_s`, ...). `log_time` = `publish_time` =
//!   simulation time in ns from the start of the run.
//! - channel `/metrics` (schema `settle.metrics`): one message at the last sample's time
//!   holding the run's `runs.csv` row (parameters and metrics) as JSON; numbers as numbers,
//!   `inf` (not settled) as `null`, text (e.g. the profile kind) as strings.
//! - a metadata record `settle` with `settle_version`, `scenario_name`, `scenario_file`,
//!   `scenario` (the scenario file's full text), `run` and `swept` (the run's swept values).

use std::collections::BTreeMap;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

use serde_json::{Map, Value, json};

use super::groups::{Group, groups};
use super::{Provenance, RunRecord};
use crate::error::Error;
use crate::input::runs_table::number;

/// Schema name of the metrics channel.
pub const METRICS_TOPIC: &str = "/metrics";

/// What one channel of a written file holds.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelInfo {
    /// Topic, e.g. `/cmd`.
    pub topic: String,
    /// Schema name, e.g. `settle.cmd`.
    pub schema_name: String,
    /// The JSON schema text.
    pub schema: String,
    /// Messages written.
    pub messages: u64,
}

/// Simulation time (s) to MCAP time (ns).
fn ns(t_s: f64) -> u64 {
    (t_s * 1e9).round().max(0.0) as u64
}

/// JSON schema of one signal group.
fn group_schema(g: &Group) -> Value {
    let mut props = Map::new();
    for f in &g.fields {
        let unit = if f.unit.is_empty() {
            String::new()
        } else {
            format!(" ({})", f.unit)
        };
        props.insert(
            f.key.clone(),
            json!({ "type": "number", "description": format!("channel {}{unit}", f.channel_name) }),
        );
    }
    json!({
        "title": format!("settle.{}", g.name),
        "description": "one sample of the run; log_time is the simulation time",
        "type": "object",
        "properties": props,
        "required": g.fields.iter().map(|f| f.key.clone()).collect::<Vec<_>>(),
    })
}

/// The metrics row as a JSON object and its schema.
fn metrics_message(rec: &RunRecord) -> (Value, Value) {
    let mut msg = Map::new();
    let mut props = Map::new();
    for (name, cell) in rec.row.header.iter().zip(&rec.row.rows[0]) {
        let (value, schema) = match number(cell) {
            Some(x) if x.is_finite() => (json!(x), json!({ "type": ["number", "null"] })),
            Some(_) => (
                Value::Null,
                json!({ "type": ["number", "null"], "description": format!("null: `{cell}` in runs.csv (not settled)") }),
            ),
            None => (json!(cell), json!({ "type": "string" })),
        };
        msg.insert(name.clone(), value);
        props.insert(name.clone(), schema);
    }
    let schema = json!({
        "title": "settle.metrics",
        "description": "the run's row of runs.csv: parameters, then metrics (units in the names)",
        "type": "object",
        "properties": props,
    });
    (Value::Object(msg), schema)
}

fn metadata(p: &Provenance, rec: &RunRecord) -> BTreeMap<String, String> {
    BTreeMap::from([
        ("settle_version".to_string(), p.settle_version.to_string()),
        ("scenario_name".to_string(), p.scenario_name.clone()),
        ("scenario_file".to_string(), p.scenario_file.clone()),
        ("scenario".to_string(), p.scenario_text.clone()),
        ("run".to_string(), rec.spec.id.to_string()),
        ("swept".to_string(), rec.spec.swept_text("; ")),
    ])
}

/// A zstd-compressed MCAP writer on `w`, its library field naming this settle version.
fn create<W: Write + Seek>(w: W, version: &str) -> Result<mcap::Writer<W>, mcap::McapError> {
    mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .compression_threads(0)
        .library(format!("settle {version}"))
        .create(w)
}

/// One JSON-schema channel per signal group, `/<group>`; with what each will hold
/// (`messages` messages).
#[allow(clippy::type_complexity)]
fn add_channels<W: Write + Seek>(
    out: &mut mcap::Writer<W>,
    groups: Vec<Group>,
    messages: u64,
) -> Result<(Vec<(u16, Group)>, Vec<ChannelInfo>), mcap::McapError> {
    let mut ids = Vec::new();
    let mut info = Vec::new();
    for g in groups {
        let schema = group_schema(&g).to_string();
        let name = format!("settle.{}", g.name);
        let schema_id = out.add_schema(&name, "jsonschema", schema.as_bytes())?;
        let topic = format!("/{}", g.name);
        let id = out.add_channel(schema_id, &topic, "json", &BTreeMap::new())?;
        ids.push((id, g));
        info.push(ChannelInfo {
            topic,
            schema_name: name,
            schema,
            messages,
        });
    }
    Ok((ids, info))
}

/// Write one run to `w`; returns what each channel holds.
pub fn write<W: Write + Seek>(
    w: W,
    p: &Provenance,
    rec: &RunRecord,
) -> Result<Vec<ChannelInfo>, mcap::McapError> {
    let mut out = create(w, p.settle_version)?;
    out.write_metadata(&mcap::records::Metadata {
        name: "settle".to_string(),
        metadata: metadata(p, rec),
    })?;
    let series = rec.series;
    let (ids, mut info) = add_channels(&mut out, groups(series), series.len() as u64)?;
    let mut buf = Vec::with_capacity(256);
    for (i, &t) in series.t_s.iter().enumerate() {
        let time = ns(t);
        for (id, g) in &ids {
            buf.clear();
            buf.push(b'{');
            for (k, f) in g.fields.iter().enumerate() {
                if k > 0 {
                    buf.push(b',');
                }
                // Keys are channel names and units: plain identifiers, but escape anyway.
                serde_json::to_writer(&mut buf, &f.key).map_err(std::io::Error::from)?;
                buf.push(b':');
                serde_json::to_writer(&mut buf, &series.channels[f.channel].data[i])
                    .map_err(std::io::Error::from)?;
            }
            buf.push(b'}');
            out.write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: *id,
                    sequence: i as u32,
                    log_time: time,
                    publish_time: time,
                },
                &buf,
            )?;
        }
    }
    let (msg, schema) = metrics_message(rec);
    let schema = schema.to_string();
    let schema_id = out.add_schema("settle.metrics", "jsonschema", schema.as_bytes())?;
    let id = out.add_channel(schema_id, METRICS_TOPIC, "json", &BTreeMap::new())?;
    let end = ns(series.t_s.last().copied().unwrap_or(0.0));
    out.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id: id,
            sequence: 0,
            log_time: end,
            publish_time: end,
        },
        msg.to_string().as_bytes(),
    )?;
    info.push(ChannelInfo {
        topic: METRICS_TOPIC.to_string(),
        schema_name: "settle.metrics".to_string(),
        schema,
        messages: 1,
    });
    out.finish()?;
    Ok(info)
}

/// A recording written sample by sample (bounded memory: the writer holds one chunk),
/// in the layout of [`write()`]: one channel per signal group of the channels named at
/// [`Stream::new`], one message per sample, a `/metrics` message at the end (a JSON
/// object given by the caller), a metadata record `settle`.
pub struct Stream<W: Write + Seek> {
    out: mcap::Writer<W>,
    ids: Vec<(u16, Group)>,
    info: Vec<ChannelInfo>,
    buf: Vec<u8>,
    sequence: u32,
    last_ns: u64,
}

impl<W: Write + Seek> std::fmt::Debug for Stream<W> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Stream")
            .field("channels", &self.info)
            .field("sequence", &self.sequence)
            .finish()
    }
}

impl<W: Write + Seek> Stream<W> {
    /// A recording of the channels `names` (with `units`) into `w`, with the metadata
    /// record `settle` holding `metadata`.
    pub fn new(
        w: W,
        version: &str,
        metadata: BTreeMap<String, String>,
        names: &[&str],
        units: &[&str],
    ) -> Result<Self, mcap::McapError> {
        let mut out = create(w, version)?;
        out.write_metadata(&mcap::records::Metadata {
            name: "settle".to_string(),
            metadata,
        })?;
        let (ids, info) = add_channels(&mut out, super::groups::group_names(names, units), 0)?;
        Ok(Self {
            out,
            ids,
            info,
            buf: Vec::with_capacity(256),
            sequence: 0,
            last_ns: 0,
        })
    }

    /// One sample at `t_s`: `values[i]` is channel `names[i]`'s.
    pub fn sample(&mut self, t_s: f64, values: &[f64]) -> Result<(), mcap::McapError> {
        let time = ns(t_s);
        for ((id, g), info) in self.ids.iter().zip(&mut self.info) {
            let buf = &mut self.buf;
            buf.clear();
            buf.push(b'{');
            for (k, f) in g.fields.iter().enumerate() {
                if k > 0 {
                    buf.push(b',');
                }
                serde_json::to_writer(&mut *buf, &f.key).map_err(std::io::Error::from)?;
                buf.push(b':');
                serde_json::to_writer(&mut *buf, &values[f.channel])
                    .map_err(std::io::Error::from)?;
            }
            buf.push(b'}');
            self.out.write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: *id,
                    sequence: self.sequence,
                    log_time: time,
                    publish_time: time,
                },
                buf,
            )?;
            info.messages += 1;
        }
        self.sequence = self.sequence.wrapping_add(1);
        self.last_ns = time;
        Ok(())
    }

    /// End the recording with the `/metrics` message `metrics` (a JSON object; numbers
    /// and strings) at the last sample's time; returns what each channel holds and the
    /// writer.
    #[allow(clippy::type_complexity)]
    pub fn finish(
        mut self,
        metrics: Map<String, Value>,
    ) -> Result<(Vec<ChannelInfo>, W), mcap::McapError> {
        let mut props = Map::new();
        for (k, v) in &metrics {
            let t = if v.is_string() { "string" } else { "number" };
            props.insert(k.clone(), json!({ "type": [t, "null"] }));
        }
        let schema = json!({
            "title": "settle.metrics",
            "description": "the recording's metrics (units in the names)",
            "type": "object",
            "properties": props,
        })
        .to_string();
        let schema_id = self
            .out
            .add_schema("settle.metrics", "jsonschema", schema.as_bytes())?;
        let id = self
            .out
            .add_channel(schema_id, METRICS_TOPIC, "json", &BTreeMap::new())?;
        self.out.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: id,
                sequence: 0,
                log_time: self.last_ns,
                publish_time: self.last_ns,
            },
            Value::Object(metrics).to_string().as_bytes(),
        )?;
        self.info.push(ChannelInfo {
            topic: METRICS_TOPIC.to_string(),
            schema_name: "settle.metrics".to_string(),
            schema,
            messages: 1,
        });
        self.out.finish()?;
        Ok((self.info, self.out.into_inner()))
    }
}

/// Write one run to the file `path` (atomically: a temporary file, then a rename).
pub fn write_file(path: &Path, p: &Provenance, rec: &RunRecord) -> Result<Vec<ChannelInfo>, Error> {
    let err = |source| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    let (tmp, file) = crate::output::atomic::create_tmp(path)?;
    let mut w = BufWriter::new(file);
    let result = write(&mut w, p, rec)
        .map_err(|e| err(crate::output::atomic::io_cause(&e)))
        .and_then(|info| w.flush().map_err(err).map(|()| info))
        .and_then(|info| Ok(crate::output::atomic::commit(&tmp, path).map(|()| info)?));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
