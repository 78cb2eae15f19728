//! settle: which motion profile makes my machine settle fastest, and by how much?
//!
//! The harness: scenario files are expanded into runs ([`sweep`]), each run plans a profile
//! and drives a plant through it ([`run`]), metrics are computed streaming ([`metrics`]) and
//! written as tables ([`report`]).

pub mod error;
pub mod interrupt;
pub mod journal;
pub mod locate;
pub mod machine_file;
pub mod metrics;
pub mod plan_lines;
pub mod report;
pub mod run;
pub mod scan;
pub mod scenario;
pub mod series;
pub mod shaping;
pub mod sweep;
pub mod tune;
pub mod tune_cmd;
pub mod tune_report;
pub mod validate;
// Outputs people keep (issue 7).
pub mod check;
pub mod html;
pub mod outputs;
pub mod plot;
pub mod shard;
pub mod sink;
pub mod table;
// Corners and paths in the harness (issue 5).
pub mod corner;
pub mod path_metrics;
// The harness's command cursor (issue 4, performance).
pub mod cursor;

use std::path::Path;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

pub use error::Error;
pub use metrics::Metrics;
pub use sweep::RunSpec;

/// Run every spec, in parallel on `jobs` threads (all cores when `None`), with a progress
/// bar on stderr when `progress` is set (and stderr is a terminal). Results come back in
/// spec order; each run is computed the same way whatever the thread count.
pub fn run_all(
    runs: &[RunSpec],
    jobs: Option<usize>,
    progress: bool,
) -> Result<Vec<Result<Metrics, Error>>, Error> {
    run_all_with(runs, jobs, progress, |spec| run::execute(spec, None))
}

/// [`run_all`] with a custom way to run one spec (e.g. recording it: [`sink::Recorder`]).
/// Once an interruption is requested ([`interrupt`]), runs not yet started are not started
/// and come back as [`Error::Interrupted`]; runs in progress finish.
pub fn run_all_with<T, F>(
    runs: &[RunSpec],
    jobs: Option<usize>,
    progress: bool,
    run_one: F,
) -> Result<Vec<Result<T, Error>>, Error>
where
    T: Send,
    F: Fn(&RunSpec) -> Result<T, Error> + Sync,
{
    let bar = if progress {
        let bar =
            ProgressBar::with_draw_target(Some(runs.len() as u64), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} runs ({eta} left)",
        ) {
            bar.set_style(style);
        }
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = jobs {
        builder = builder.num_threads(n);
    }
    let pool = builder.build().map_err(|e| Error::Input {
        at: error::Location {
            file: "--jobs".into(),
            line: None,
            column: None,
            key: None,
        },
        message: format!("cannot start {jobs:?} worker threads: {e}"),
    })?;
    let results = pool.install(|| {
        runs.par_iter()
            .map(|spec| {
                if interrupt::requested() {
                    return Err(Error::Interrupted { run: spec.id });
                }
                let r = run_one(spec);
                bar.inc(1);
                r
            })
            .collect()
    });
    bar.finish_and_clear();
    Ok(results)
}

/// Load a scenario file and expand it into validated runs.
pub fn load_runs(path: &Path) -> Result<(scenario::Scenario, Vec<RunSpec>), Error> {
    let (sc, src) = scenario::load(path)?;
    let runs = sweep::expand(&sc, &src)?;
    Ok((sc, runs))
}
