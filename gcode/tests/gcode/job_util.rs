//! Helpers of the job tests: running a job on text, and the same moves planned directly.

use settle_gcode::job::{Job, JobChunk, JobConfig, JobSummary, PlannerConfig};
use settle_gcode::{Reader, ReaderOptions};
use settle_planner::Sample;
use settle_planner::firmware::{FirmwarePlanner, LinearMove};

/// One millimetre (m).
pub const MM: f64 = 1e-3;

/// Run `text` through a job with `cfg`: every chunk, and the summary after the file.
pub fn run(text: &str, cfg: JobConfig) -> (Vec<JobChunk>, JobSummary) {
    let reader = Reader::new(text.as_bytes(), ReaderOptions::new(cfg.dialect));
    let mut job = Job::new(reader, cfg).expect("job");
    let chunks = job.by_ref().collect::<Result<Vec<_>, _>>().expect("chunks");
    job.run_to_end().expect("rest");
    (chunks, job.summary())
}

/// Push `moves` into `p`, finish, and return the print time.
pub fn direct(p: &mut dyn FirmwarePlanner, moves: &[LinearMove]) -> f64 {
    for m in moves {
        p.push(m).expect("move");
        while p.pop().is_some() {}
    }
    p.finish();
    while p.pop().is_some() {}
    p.print_time_s()
}

/// `|got - want| <= tol |want|`.
pub fn assert_rel(what: &str, got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol * want.abs(),
        "{what}: got {got:.15e}, want {want:.15e}"
    );
}

/// Every axis of the chunked motion at print time `t` (the later chunk at a boundary).
pub fn at(chunks: &[JobChunk], t: f64) -> [Sample; 4] {
    let i = chunks.partition_point(|c| c.start_time_s <= t).max(1) - 1;
    let c = &chunks[i];
    let mut out = [Sample::default(); 4];
    c.trajectory.state_at(t - c.start_time_s, &mut out);
    out
}

/// Chunks follow each other without gaps and join continuously in position and velocity.
pub fn assert_contiguous(chunks: &[JobChunk]) {
    for w in chunks.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!(
            (a.end_time_s() - b.start_time_s).abs() < 1e-9,
            "gap between {} and {}",
            a.end_time_s(),
            b.start_time_s
        );
        for (pa, pb) in a.trajectory.axes().iter().zip(b.trajectory.axes()) {
            let (e, s) = (pa.end(), pb.start());
            assert!(
                (e.p - s.p).abs() < 1e-9 && (e.v - s.v).abs() < 1e-6,
                "jump at {}: {e:?} -> {s:?}",
                b.start_time_s
            );
        }
    }
}

/// The defaults of `planner`'s firmware with `planner` as its configuration.
pub fn job(planner: PlannerConfig) -> JobConfig {
    let mut c = JobConfig::defaults(planner.firmware()).expect("defaults");
    c.planner = planner;
    c
}

/// Time of a trapezoid leg of length `l` cruising at `v` with acceleration `a`, from
/// `v0` to `v1` (any consistent units).
pub fn leg(l: f64, v: f64, a: f64, v0: f64, v1: f64) -> f64 {
    (v - v0) / a
        + (v - v1) / a
        + (l - (v * v - v0 * v0) / (2.0 * a) - (v * v - v1 * v1) / (2.0 * a)) / v
}
