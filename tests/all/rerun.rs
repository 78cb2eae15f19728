//! rerun recordings (compiled with the `rerun` feature only): the .rrd decodes with rerun's
//! own decoder and holds one scalar entity per channel with every sample on the `sim_time`
//! timeline, plus the metrics, scenario and provenance documents. (Without the feature,
//! `--rerun` is a clear error: `cli::without_the_feature_rerun_is_a_clear_error`.)

fn settle(args: &[&str]) -> std::process::Output {
    crate::support::settle()
        .args(args)
        .output()
        .expect("settle runs")
}

#[test]
fn rrd_holds_every_channel_and_sample() {
    use std::collections::BTreeMap;

    use re_sdk::external::re_log_encoding::DecoderApp;
    use re_sdk::log::{Chunk, LogMsg};

    let dir = tempfile::tempdir().expect("tempdir");
    let trace = dir.path().join("run-1.csv");
    let o = settle(&[
        "run",
        "scenarios/ci_quickstart.toml",
        "--case",
        "1",
        "--rerun",
        "--out",
        trace.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = std::fs::read_to_string(&trace)
        .expect("trace")
        .lines()
        .count()
        - 1;
    let rrd = dir.path().join("run-1.rrd");
    let file = std::io::BufReader::new(std::fs::File::open(&rrd).expect("rrd"));
    // entity -> (rows, has sim_time)
    let mut entities: BTreeMap<String, (usize, bool)> = BTreeMap::new();
    for msg in DecoderApp::decode_eager(file).expect("an rrd") {
        if let LogMsg::ArrowMsg(_, arrow) = msg.expect("decodes") {
            let chunk = Chunk::from_arrow_msg(&arrow).expect("chunk");
            let e = entities
                .entry(chunk.entity_path().to_string())
                .or_insert((0, false));
            e.0 += chunk.num_rows();
            e.1 |= chunk.timelines().keys().any(|t| t.as_str() == "sim_time");
        }
    }
    let root = std::path::Path::new(crate::support::manifest_dir());
    let (_, runs) =
        settle::load_runs(&root.join("scenarios/ci_quickstart.toml")).expect("scenario");
    let (series, _) = settle::output::sink::record_run(&runs[1]).expect("runs");
    for g in settle::output::sink::groups::groups(&series) {
        for f in &g.fields {
            let path = format!("/{}/{}", g.name, f.key);
            let (n, timed) = entities
                .get(&path)
                .unwrap_or_else(|| panic!("no entity {path} in {entities:?}"));
            assert_eq!(*n, rows, "{path}: one row per sample");
            assert!(timed, "{path} on sim_time");
        }
    }
    for doc in ["/settle/metrics", "/settle/scenario", "/settle/provenance"] {
        assert!(entities.contains_key(doc), "{doc} missing: {entities:?}");
    }
}
