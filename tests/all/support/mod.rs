//! Helpers shared by the test modules.

use std::path::{Path, PathBuf};
use std::process::Command;

pub mod html;

/// The `settle` binary, run from the repository root.
pub fn settle() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_settle"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// Run `cmd` and require success (the message shows its standard error); its output.
pub fn run_ok(cmd: &mut Command) -> std::process::Output {
    let out = cmd.output().expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Write `text` as `dir/name`; its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("writes");
    p
}

/// The extra figure `name` of a run kind in `m`.
pub fn extra(m: &settle::Metrics, name: &str) -> f64 {
    m.extra
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .1
}
pub mod resonance;
