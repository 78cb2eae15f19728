//! Helpers shared by the test modules.

use std::path::{Path, PathBuf};
use std::process::Command;

pub mod html;

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

/// The `settle` binary, run from the repository root.
pub fn settle() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_settle"));
    c.current_dir(manifest_dir());
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

/// `settle run SCENARIO --case 1 --out TRACE EXTRA...`, the case of the failure tests
/// (run 1 of their two-run sweeps fails); its output.
pub fn run_case_1(scenario: &Path, trace: &Path, extra: &[&str]) -> std::process::Output {
    settle()
        .arg("run")
        .arg(scenario)
        .args(["--case", "1", "--out"])
        .arg(trace)
        .args(extra)
        .output()
        .expect("runs")
}

/// Every file under `dir`, relative to it, sorted.
pub fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read_dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).expect("prefix").to_path_buf());
            }
        }
    }
    out.sort();
    out
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(manifest_dir())
}

/// Write `text` as `dir/name`; its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("writes");
    p
}

/// The cells of every Markdown table row of `md` (lines starting with `|`), trimmed.
pub fn md_rows(md: &str) -> impl Iterator<Item = Vec<&str>> {
    md.lines()
        .filter(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
}

/// The extra figure `name` of a study in `m`.
pub fn extra(m: &settle::Metrics, name: &str) -> f64 {
    m.extra
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no column {name}"))
        .1
}
pub mod one_mode;
pub mod resonance;

/// The one run of `scenario`, on the modal backend.
pub fn one_modal_run(scenario: &Path) -> settle::spec::run_spec::RunSpec {
    let (_, mut runs) = settle::load_runs(scenario).expect("loads");
    settle::execute::set_backend(scenario, &mut runs, settle::spec::backend::Backend::Modal)
        .expect("modal");
    assert_eq!(runs.len(), 1, "one run");
    runs.remove(0)
}

/// The resonance test of the example recordings (examples/data/raw_data_*_example.csv,
/// `docs/guide/your-machine.md`): 30 to 90 Hz at 10 Hz/s, as `settle identify` options.
pub const EXAMPLE_TEST: [&str; 6] = [
    "--freq-start",
    "30",
    "--freq-end",
    "90",
    "--hz-per-sec",
    "10",
];
