//! The worker pool: runs in parallel, results in spec order.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;

use crate::error::{self, Error};
use crate::expand::RunSpec;
use crate::measure::metrics::Metrics;

/// Run every spec, in parallel on `jobs` threads (all cores when `None`), with a progress
/// bar on stderr when `progress` is set (and stderr is a terminal). Results come back in
/// spec order; each run is computed the same way whatever the thread count.
pub fn run_all(
    runs: &[RunSpec],
    jobs: Option<usize>,
    progress: bool,
) -> Result<Vec<Result<Metrics, Error>>, Error> {
    run_all_with(runs, jobs, progress, |spec| {
        crate::execute::run::execute(spec, None)
    })
}

/// [`run_all`] with a custom way to run one spec (e.g. recording it: [`crate::output::sink::Recorder`]).
/// Once an interruption is requested ([`crate::execute::interrupt`]), runs not yet started are not started
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
                if crate::execute::interrupt::requested() {
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
