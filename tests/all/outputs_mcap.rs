//! MCAP recordings read back with the official Python reader (`mcap` from PyPI, installed on
//! first use into .deps/ by scripts/mcap-python): every channel, schema, message count and
//! value as written, the metrics message and the metadata record.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;
use settle::input::runs_table::RunsTable;

const SCENARIO: &str = "scenarios/ci_quickstart.toml";

fn root() -> &'static Path {
    Path::new(crate::support::manifest_dir())
}

fn settle(args: &[&str]) -> std::process::Output {
    let out = crate::support::settle()
        .args(args)
        .output()
        .expect("settle runs");
    assert!(
        out.status.success(),
        "settle {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Read files with the Python reader; returns path -> description (see read_mcap.py).
fn python_read(files: &[PathBuf]) -> BTreeMap<String, Value> {
    let out = Command::new(root().join("scripts/mcap-python"))
        .arg(root().join("tests/all/support/read_mcap.py"))
        .args(files)
        .output()
        .expect("scripts/mcap-python runs (needs python3 with pip)");
    assert!(
        out.status.success(),
        "python reader failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("reader prints JSON")
}

/// A number as the reader encodes it ("f:<repr>" / "i:<n>"), parsed exactly.
fn exact(v: &Value) -> Option<f64> {
    let s = v.as_str()?;
    let t = s.strip_prefix("f:").or_else(|| s.strip_prefix("i:"))?;
    t.parse().ok()
}

fn channel<'a>(file: &'a Value, topic: &str) -> &'a Value {
    file["channels"]
        .as_array()
        .expect("channels")
        .iter()
        .find(|c| c["topic"] == topic)
        .unwrap_or_else(|| panic!("no channel {topic}"))
}

/// The metrics message must be the run's row of runs.csv.
fn assert_metrics_message(file: &Value, csv: &RunsTable, row: usize) {
    let m = channel(file, "/metrics");
    assert_eq!(m["count"], 1);
    assert_eq!(m["schema"]["name"], "settle.metrics");
    assert_eq!(m["schema"]["encoding"], "jsonschema");
    let msg = &m["messages"][0];
    let keys: Vec<&String> = msg.as_object().expect("object").keys().collect();
    let mut header: Vec<&String> = csv.header.iter().collect();
    let mut sorted = keys.clone();
    sorted.sort();
    header.sort();
    assert_eq!(sorted, header, "metrics keys = runs.csv columns");
    for (h, cell) in csv.header.iter().zip(&csv.rows[row]) {
        let got = &msg[h];
        match cell.parse::<f64>() {
            Ok(x) if x.is_finite() => assert_eq!(exact(got), Some(x), "{h}"),
            Ok(_) => assert!(got.is_null(), "{h}: inf is written as null, got {got}"),
            Err(_) => assert_eq!(got.as_str(), Some(cell.as_str()), "{h}"),
        }
    }
}

#[test]
fn python_reader_sees_every_channel_schema_message_and_value() {
    let dir = tempfile::tempdir().expect("tempdir");
    let trace = dir.path().join("run-1.csv");
    settle(&[
        "run",
        SCENARIO,
        "--case",
        "1",
        "--mcap",
        "--out",
        trace.to_str().expect("utf-8"),
    ]);
    let sweep = dir.path().join("sweep");
    settle(&[
        "sweep",
        SCENARIO,
        "--mcap",
        "--jobs",
        "2",
        "--out",
        sweep.to_str().expect("utf-8"),
    ]);
    let runs_csv =
        RunsTable::parse(&std::fs::read_to_string(sweep.join("runs.csv")).expect("runs.csv"))
            .expect("parses");
    let recordings: Vec<PathBuf> = (0..runs_csv.rows.len())
        .map(|i| sweep.join(format!("recordings/run-{i}.mcap")))
        .collect();
    let n_files = std::fs::read_dir(sweep.join("recordings"))
        .expect("recordings/")
        .count();
    assert_eq!(n_files, runs_csv.rows.len(), "one recording per run");
    let single = dir.path().join("run-1.mcap");
    let mut files = vec![single.clone()];
    files.extend(recordings.iter().cloned());
    let read = python_read(&files);

    // The single run, against its series computed here through the library (the channels
    // are whatever the run records) and its CSV trace.
    let file = &read[single.to_str().expect("utf-8")];
    let (_, runs) = settle::load_runs(&root().join(SCENARIO)).expect("scenario");
    let (series, _) = settle::output::sink::record_run(&runs[1]).expect("runs");
    let trace_text = std::fs::read_to_string(&trace).expect("trace");
    let trace_rows: Vec<Vec<f64>> = trace_text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().expect("number")).collect())
        .collect();
    assert_eq!(trace_rows.len(), series.len());
    let groups = settle::output::sink::groups::groups(&series);
    assert_eq!(file["profile"], "");
    assert_eq!(file["compression"], serde_json::json!(["zstd"]));
    let channels = file["channels"].as_array().expect("channels");
    assert_eq!(channels.len(), groups.len() + 1, "one per group + /metrics");
    let stats = &file["statistics"];
    for g in &groups {
        let topic = format!("/{}", g.name);
        let c = channel(file, &topic);
        assert_eq!(c["message_encoding"], "json");
        assert_eq!(c["schema"]["encoding"], "jsonschema");
        assert_eq!(c["schema"]["name"], format!("settle.{}", g.name));
        let schema: Value =
            serde_json::from_str(c["schema"]["data"].as_str().expect("text")).expect("schema");
        assert_eq!(schema["type"], "object");
        let keys: Vec<String> = g.fields.iter().map(|f| f.key.clone()).collect();
        let mut props: Vec<String> = schema["properties"]
            .as_object()
            .expect("properties")
            .keys()
            .cloned()
            .collect();
        props.sort();
        let mut sorted = keys.clone();
        sorted.sort();
        assert_eq!(props, sorted, "{topic}: schema properties");
        assert_eq!(schema["required"], serde_json::json!(keys));
        for p in schema["properties"]
            .as_object()
            .expect("properties")
            .values()
        {
            assert_eq!(p["type"], "number");
        }
        // Every sample, every value, exactly; log_time = simulation time in ns.
        assert_eq!(c["count"], trace_rows.len() as u64, "{topic}: messages");
        assert_eq!(
            stats["channel_message_counts"][&topic],
            trace_rows.len() as u64
        );
        let msgs = c["messages"].as_array().expect("messages");
        let times = c["log_times"].as_array().expect("log_times");
        for (k, row) in trace_rows.iter().enumerate() {
            assert_eq!(
                times[k].as_u64(),
                Some((series.t_s[k] * 1e9).round() as u64),
                "{topic} #{k}"
            );
            for f in &g.fields {
                let got = exact(&msgs[k][&f.key]);
                let want = series.channels[f.channel].data[k];
                assert_eq!(got, Some(want), "{topic} #{k} {}", f.key);
                assert_eq!(row[1 + f.channel], want, "the CSV trace agrees");
            }
        }
    }
    assert_eq!(
        stats["message_count"],
        (trace_rows.len() * groups.len() + 1) as u64
    );
    assert_eq!(stats["channel_count"], (groups.len() + 1) as u64);
    assert_eq!(stats["schema_count"], (groups.len() + 1) as u64);
    assert_metrics_message(file, &runs_csv, 1);
    let meta = file["metadata"].as_array().expect("metadata");
    assert_eq!(meta.len(), 1);
    assert_eq!(meta[0]["name"], "settle");
    let md = &meta[0]["metadata"];
    assert_eq!(md["settle_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(md["scenario_name"], "ci_quickstart");
    assert_eq!(md["run"], "1");
    assert_eq!(
        md["scenario"].as_str(),
        Some(
            std::fs::read_to_string(root().join(SCENARIO))
                .expect("scenario")
                .as_str()
        )
    );
    assert!(
        md["swept"]
            .as_str()
            .expect("swept")
            .contains("profile = scurve")
    );

    // Every run of the sweep: same channels, its own metrics row.
    for (i, path) in recordings.iter().enumerate() {
        let f = &read[path.to_str().expect("utf-8")];
        let topics: Vec<&str> = f["channels"]
            .as_array()
            .expect("channels")
            .iter()
            .map(|c| c["topic"].as_str().expect("topic"))
            .collect();
        let mut want: Vec<String> = groups.iter().map(|g| format!("/{}", g.name)).collect();
        want.push("/metrics".into());
        want.sort();
        assert_eq!(topics, want, "run {i}");
        assert_metrics_message(f, &runs_csv, i);
        assert_eq!(f["metadata"][0]["metadata"]["run"], i.to_string());
    }
    // The sweep's recording of run 1 is the single run's, byte for byte (deterministic).
    assert!(
        std::fs::read(&single).expect("single") == std::fs::read(&recordings[1]).expect("sweep"),
        "run 1 recorded by `run` and by `sweep` differ"
    );
}
