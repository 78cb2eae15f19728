//! The worker pool: runs in parallel, results in spec order, progress reported through a
//! callback (the binary draws a progress bar with it; tests and library callers pass
//! [`quiet`] or their own).

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::error::Error;
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;

/// Called after each finished run with `(runs finished, runs in the batch)`, from the
/// worker threads.
pub type Progress<'a> = &'a (dyn Fn(usize, usize) + Sync);

/// A [`Progress`] that reports nothing.
pub fn quiet(_done: usize, _total: usize) {}

/// The most worker threads `--jobs` takes: far above the cores of a machine settle runs
/// on (threads beyond the cores only share them), far below what starting them costs
/// (65,535 threads kept a sweep of 16 runs busy for minutes, and a Ctrl-C waited for them).
pub const MAX_JOBS: u16 = 1024;

/// A thread pool of `jobs` threads (all cores when `None`), never more than `work`, the
/// pieces of work it will be given (at least one thread): a thread without work only
/// costs its start.
pub fn thread_pool(jobs: Option<usize>, work: usize) -> Result<rayon::ThreadPool, Error> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = jobs {
        builder = builder.num_threads(n.min(work).max(1));
    }
    builder.build().map_err(|e| {
        Error::input(
            "--jobs",
            format!("cannot start {jobs:?} worker threads: {e}"),
        )
    })
}

/// Run every spec, in parallel on `jobs` threads (all cores when `None`), reporting to
/// `progress`. Results come back in spec order; each run is computed the same way whatever
/// the thread count.
pub fn run_all(
    runs: &[RunSpec],
    jobs: Option<usize>,
    progress: Progress,
) -> Result<Vec<Result<Metrics, Error>>, Error> {
    run_all_with(runs, jobs, progress, |spec| {
        crate::execute::execute(spec, None)
    })
}

/// Run `run_one(k)` for every `k` in `0..n`, in parallel on `jobs` threads (all cores when
/// `None`), reporting to `progress`: the errors with their `k`, in order of `k` (nothing is
/// kept for a call that succeeds). Once an interruption is requested
/// ([`crate::execute::interrupt`]), calls not yet started are not made and come back as
/// [`Error::Interrupted`] (with `k` as the run).
pub fn run_each_errors<F>(
    n: usize,
    jobs: Option<usize>,
    progress: Progress,
    run_one: F,
) -> Result<Vec<(usize, Error)>, Error>
where
    F: Fn(usize) -> Result<(), Error> + Sync,
{
    let pool = thread_pool(jobs, n)?;
    let done = AtomicUsize::new(0);
    let errors = pool.install(|| {
        (0..n)
            .into_par_iter()
            .filter_map(|k| {
                if crate::execute::interrupt::requested() {
                    return Some((k, Error::Interrupted { run: k }));
                }
                let r = run_one(k);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, n);
                r.err().map(|e| (k, e))
            })
            .collect()
    });
    Ok(errors)
}

/// [`run_all`] with a custom way to run one spec (e.g. recording it, or appending its row
/// to a journal). Once an interruption is requested ([`crate::execute::interrupt`]), runs
/// not yet started are not started and come back as [`Error::Interrupted`]; runs in
/// progress finish.
pub fn run_all_with<T, F>(
    runs: &[RunSpec],
    jobs: Option<usize>,
    progress: Progress,
    run_one: F,
) -> Result<Vec<Result<T, Error>>, Error>
where
    T: Send,
    F: Fn(&RunSpec) -> Result<T, Error> + Sync,
{
    let pool = thread_pool(jobs, runs.len())?;
    let done = AtomicUsize::new(0);
    let total = runs.len();
    let results = pool.install(|| {
        runs.par_iter()
            .map(|spec| {
                if crate::execute::interrupt::requested() {
                    return Err(Error::Interrupted { run: spec.id });
                }
                let r = run_one(spec);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                r
            })
            .collect()
    });
    Ok(results)
}
