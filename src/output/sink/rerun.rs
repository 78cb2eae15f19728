//! rerun recordings (`.rrd`) of one run, behind the cargo feature `rerun`.
//!
//! Layout of `run-<id>.rrd`: timeline `sim_time` (duration, the simulation time); one scalar
//! entity per channel at `<group>/<field_unit>` (the same groups and keys as the MCAP topics,
//! see [`super::groups`]); static text documents `settle/metrics` (the run's `runs.csv` row
//! as a markdown table), `settle/scenario` (the scenario file) and `settle/provenance`
//! (settle's version, scenario name and file, run, swept values). Recording name:
//! `<scenario> run <id>`. Unlike MCAP, an .rrd is not byte-reproducible (rerun stamps row
//! ids with the wall clock).

use std::path::Path;

use super::{Provenance, RunRecord};
use crate::error::Error;

/// True when this binary was built with the `rerun` feature.
pub const AVAILABLE: bool = cfg!(feature = "rerun");

/// What to tell a user who asks for `--rerun` from a build without the feature.
pub const UNAVAILABLE: &str = "--rerun needs settle built with the `rerun` cargo feature \
(off by default: it adds the rerun SDK, a cold build of several minutes). Build it with \
`cargo build --release --features rerun` (or run `cargo run --release --features rerun -- ...`)";

#[cfg(feature = "rerun")]
fn markdown_row(rec: &RunRecord) -> String {
    let mut s = String::from("| column | value |\n|---|---:|\n");
    for (h, v) in rec.row.header.iter().zip(&rec.row.rows[0]) {
        s.push_str(&format!("| {h} | {v} |\n"));
    }
    s
}

/// Write one run to the file `path` (a temporary file, then a rename).
#[cfg(feature = "rerun")]
pub fn write_file(path: &Path, p: &Provenance, rec: &RunRecord) -> Result<(), Error> {
    use re_sdk::{RecordingStreamBuilder, log::TimeColumn};
    use re_sdk_types::archetypes::{Scalars, TextDocument};

    let err = |e: String| Error::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(e),
    };
    let tmp = crate::output::atomic::tmp_path(path);
    crate::output::atomic::prepare_tmp(path, &tmp)?;
    let result = (|| -> Result<(), String> {
        let stream = RecordingStreamBuilder::new("settle")
            .save(&tmp)
            .map_err(|e| e.to_string())?;
        stream
            .send_recording_name(format!("{} run {}", p.scenario_name, rec.spec.id))
            .map_err(|e| e.to_string())?;
        let series = rec.series;
        for g in super::groups::groups(series) {
            for f in &g.fields {
                let time = TimeColumn::new_duration_secs("sim_time", series.t_s.iter().copied());
                let values = Scalars::new(series.channels[f.channel].data.iter().copied())
                    .columns_of_unit_batches()
                    .map_err(|e| e.to_string())?;
                stream
                    .send_columns(format!("{}/{}", g.name, f.key), [time], values)
                    .map_err(|e| e.to_string())?;
            }
        }
        let provenance = format!(
            "settle {}\n\nscenario `{}` ({})\n\nrun {}: {}\n",
            p.settle_version,
            p.scenario_name,
            p.scenario_file,
            rec.spec.id,
            rec.spec.swept_text("; ")
        );
        for (entity, text) in [
            ("settle/metrics", markdown_row(rec)),
            ("settle/provenance", provenance),
        ] {
            stream
                .log_static(entity, &TextDocument::from_markdown(text))
                .map_err(|e| e.to_string())?;
        }
        stream
            .log_static(
                "settle/scenario",
                &TextDocument::new(p.scenario_text.clone()),
            )
            .map_err(|e| e.to_string())?;
        stream.flush_blocking().map_err(|e| e.to_string())?;
        drop(stream);
        crate::output::atomic::commit(&tmp, path).map_err(|e| e.to_string())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(err)
}

/// Without the `rerun` feature: an error saying how to build with it.
#[cfg(not(feature = "rerun"))]
pub fn write_file(path: &Path, _p: &Provenance, _rec: &RunRecord) -> Result<(), Error> {
    Err(Error::Write {
        path: path.to_path_buf(),
        source: std::io::Error::other(UNAVAILABLE),
    })
}
