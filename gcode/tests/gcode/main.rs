//! settle-gcode's tests: one binary, one module per subject.

mod arcs;
mod bambu;
mod bgcode;
mod config_export;
mod config_klipper;
mod config_klipper_examples;
mod config_marlin;
mod config_real;
mod config_rrf;
mod cura;
mod cura5;
mod dialects;
mod errors;
mod features;
mod fullcontrol;
mod grbl;
mod grbl_planes;
mod job_changes;
mod job_prints;
mod job_settle;
mod job_times;
mod job_util;
mod laser;
mod layer_bound;
mod layers;
mod orca;
mod prusa_models;
mod prusaslicer;
mod roundtrip;
mod segments;
mod slic3r;
mod summary;

use settle_gcode::{
    Dialect, Event, EventKind, GcodeError, LimitChange, Move, Reader, ReaderOptions,
};

/// Every event of `text`, read with `dialect`; panics on an error.
pub fn events(text: &str, dialect: Dialect) -> Vec<Event> {
    Reader::new(text.as_bytes(), ReaderOptions::new(dialect))
        .collect::<Result<Vec<_>, _>>()
        .expect("valid G-code")
}

/// The moves of `text`.
pub fn moves(text: &str, dialect: Dialect) -> Vec<Move> {
    events(text, dialect)
        .into_iter()
        .filter_map(|e| match e.kind {
            EventKind::Move(m) => Some(m),
            _ => None,
        })
        .collect()
}

/// The limit changes of `text`.
pub fn limits(text: &str, dialect: Dialect) -> Vec<LimitChange> {
    events(text, dialect)
        .into_iter()
        .filter_map(|e| match e.kind {
            EventKind::Limits(c) => Some(c),
            _ => None,
        })
        .collect()
}

/// The error that ends reading `text`; panics if there is none.
pub fn error(text: &str, dialect: Dialect) -> GcodeError {
    Reader::new(text.as_bytes(), ReaderOptions::new(dialect))
        .find_map(Result::err)
        .unwrap_or_else(|| panic!("expected an error reading {text:?}"))
}

/// The commands `text` ignores, as `NAME xCOUNT`; panics if it yields any event.
pub fn ignored(text: &str, dialect: Dialect) -> Vec<String> {
    let mut r = Reader::new(text.as_bytes(), ReaderOptions::new(dialect));
    assert_eq!(r.by_ref().count(), 0, "{text}");
    r.ignored_commands()
        .iter()
        .map(|(k, v)| format!("{k} x{v}"))
        .collect()
}

/// The package's directory: the `CARGO_MANIFEST_DIR` cargo sets when it runs this
/// binary, else the one it was compiled with. The run-time value is the one that is right
/// when a target directory is shared between clones at different paths: cargo reuses a
/// test binary whose sources are unchanged, with the other clone's path compiled in.
pub fn manifest_dir() -> &'static str {
    static DIR: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned())
    })
}

/// The repository's test prints.
pub fn print_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(manifest_dir())
        .join("prints")
        .join(name)
}

/// A file or folder under `tests/data/`.
pub fn data_path(name: &str) -> std::path::PathBuf {
    std::path::Path::new(manifest_dir())
        .join("tests/data")
        .join(name)
}

/// `|a - b| <= tol * max(|a|, |b|)`.
pub fn close_rel(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs())
}

/// How many moves each feature counts: `features` are the moves' feature indices
/// (`Move::feature`), `names` the reader's feature names (`Reader::features`).
pub fn count_by_feature<'a>(
    names: &'a [String],
    features: &[u16],
) -> std::collections::BTreeMap<&'a str, u32> {
    let mut counted = std::collections::BTreeMap::new();
    for &f in features {
        *counted.entry(names[usize::from(f)].as_str()).or_insert(0) += 1;
    }
    counted
}

/// The summary of the print `name` (in gcode/prints/) planned to its end under `cfg`.
pub fn plan_print(name: &str, cfg: settle_gcode::job::JobConfig) -> settle_gcode::job::JobSummary {
    let mut job = settle_gcode::job::Job::open(print_path(name), cfg).expect("opens");
    job.run_to_end().expect("plans");
    job.summary()
}
