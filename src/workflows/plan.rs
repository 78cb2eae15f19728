//! `settle plan`: planning problems as JSON lines in, profiles as JSON lines out.
//!
//! One problem per input line, e.g.
//! `{"p0":[0],"pf":[1],"vmax":[1],"amax":[2],"jmax":[10],"sync":"time"}` (v0, a0, vf, af
//! default to zero; optional `vmin`, `amin`, `"kind":"trapezoid"`,
//! `"interface":"velocity"`, for which the targets are `vf` and `af`). One output line per input line, in order:
//! `{"duration":1.7,"axes":[{"p0":0,"v0":0,"a0":0,"segments":[[0.2,10.0],...]}]}` where each
//! segment is `[duration, jerk]`, or `[duration, 0, accel]` for a constant-acceleration
//! segment whose acceleration jumps to `accel` (trapezoids); or `{"error":"..."}`.
//!
//! Every line is bounded before it is planned: its length ([`settle_files::limit::PLAN_LINE`],
//! read no further), its axes ([`MAX_AXES`]) and each value ([`MAX_MAGNITUDE`],
//! [`MIN_LIMIT`]); a line outside them is answered with an error naming the field, the
//! axis and the range.

use serde::Deserialize;
use serde_json::{Value, json};
use settle_planner::position::Shape;
use settle_planner::sync::{Axis, Sync, plan, plan_velocity};
use settle_planner::{Limits, Profile, Segment, State};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Problem {
    #[serde(default)]
    p0: Vec<f64>,
    #[serde(default)]
    v0: Vec<f64>,
    #[serde(default)]
    a0: Vec<f64>,
    #[serde(default)]
    pf: Vec<f64>,
    #[serde(default)]
    vf: Vec<f64>,
    #[serde(default)]
    af: Vec<f64>,
    vmax: Vec<f64>,
    amax: Vec<f64>,
    #[serde(default)]
    jmax: Vec<f64>,
    #[serde(default)]
    vmin: Vec<f64>,
    #[serde(default)]
    amin: Vec<f64>,
    #[serde(default = "default_sync")]
    sync: String,
    #[serde(default = "default_kind")]
    kind: String,
    #[serde(default = "default_interface")]
    interface: String,
}

/// The most axes one problem may have: 30, the most movement axes a firmware here drives
/// (RepRapFirmware on a Duet 3 MB6HC: `MaxAxes`, src/Config/Pins_Duet3_MB6HC.h). Each axis
/// is planned and answered with its own profile, so the axes bound a line's work and its
/// answer as the line's length bounds its reading.
pub const MAX_AXES: usize = 30;

/// The largest magnitude of a value of a problem (a position, velocity, acceleration or
/// jerk, in the problem's own units): 1e15. The planner is unit-free and answers only what
/// f64 resolves: it checks each profile's end against the target to 1e-8 of the move's
/// largest position and refuses one that misses (`verify`, planner/src/position.rs,
/// "inputs beyond what f64 arithmetic resolves"). Inside 1e15 and [`MIN_LIMIT`] lie the
/// problems of every machine in mm or m (`settle::spec`: positions to 1e5 mm, jerks to
/// 1e15 mm/s^3) and the slowest answer (a 1e15 move at 1e-9 per second lasts 1e24 s) and
/// the positions it passes stay far inside f64's range, where that check decides; beyond,
/// the numbers stop meaning a motion (a 1e300 move at 1 per second was answered as lasting
/// 1e300 s, its jerk phases of 1 s lost in the sum of its segments).
pub const MAX_MAGNITUDE: f64 = 1e15;

/// The smallest limit (`vmax`, `amax`, `jmax`, and the magnitude of `vmin`, `amin`): 1e-9,
/// the least motion setting a G-code file may set (`settle_gcode::MIN_LIMIT_VALUE`: below
/// it the planners' arithmetic leaves the range of f64). settle's slowest limits, 1e-3 mm/s
/// (1e-6 m/s) and the like, lie above it.
pub const MIN_LIMIT: f64 = settle_gcode::MIN_LIMIT_VALUE;

/// Check every value of `pr` against [`MAX_MAGNITUDE`] and the limits against
/// [`MIN_LIMIT`]: the message for the first value outside, naming its field and axis.
fn check_values(pr: &Problem) -> Result<(), String> {
    let (lo, hi) = (MIN_LIMIT, MAX_MAGNITUDE);
    // (field, values, allowed range)
    let fields: [(&str, &[f64], (f64, f64)); 11] = [
        ("p0", &pr.p0, (-hi, hi)),
        ("v0", &pr.v0, (-hi, hi)),
        ("a0", &pr.a0, (-hi, hi)),
        ("pf", &pr.pf, (-hi, hi)),
        ("vf", &pr.vf, (-hi, hi)),
        ("af", &pr.af, (-hi, hi)),
        ("vmax", &pr.vmax, (lo, hi)),
        ("amax", &pr.amax, (lo, hi)),
        ("jmax", &pr.jmax, (lo, hi)),
        ("vmin", &pr.vmin, (-hi, -lo)),
        ("amin", &pr.amin, (-hi, -lo)),
    ];
    for (name, values, (min, max)) in fields {
        if let Some((i, x)) = values
            .iter()
            .enumerate()
            .find(|(_, x)| !(x.is_finite() && (min..=max).contains(*x)))
        {
            return Err(format!(
                "`{name}` of axis {i} must be a number from {min:e} to {max:e}, got {x}: the planner answers values within {MAX_MAGNITUDE:e} in magnitude and limits of at least {MIN_LIMIT:e}, in the problem's own units"
            ));
        }
    }
    Ok(())
}

fn default_sync() -> String {
    "time".into()
}
fn default_kind() -> String {
    "scurve".into()
}
fn default_interface() -> String {
    "position".into()
}

/// Answer one input line with one output line (no newline).
pub fn answer(line: &str) -> String {
    match solve(line) {
        Ok(v) => v.to_string(),
        // The problem's own text (a name, a key) is quoted in the message: never 10 MB of it.
        Err(e) => json!({ "error": crate::error::shorten_numbers(&crate::error::echo_quoted(&e)) })
            .to_string(),
    }
}

fn solve(line: &str) -> Result<Value, String> {
    let pr: Problem = serde_json::from_str(line).map_err(|e| format!("invalid problem: {e}"))?;
    let n = pr.vmax.len();
    if n == 0 {
        return Err("`vmax` must list one value per axis".into());
    }
    if n > MAX_AXES {
        return Err(format!(
            "`vmax` lists {n} axes; a problem has 1 to {MAX_AXES} (one value per axis)"
        ));
    }
    check_values(&pr)?;
    let shape = match pr.kind.as_str() {
        "scurve" => Shape::JerkLimited,
        "trapezoid" => Shape::Trapezoid,
        k => return Err(format!("unknown kind `{k}`; allowed: scurve, trapezoid")),
    };
    let sync = match pr.sync.as_str() {
        "time" => Sync::Time,
        "phase" => Sync::Phase,
        "none" => Sync::None,
        s => return Err(format!("unknown sync `{s}`; allowed: time, phase, none")),
    };
    let get = |name: &str, v: &[f64], required: bool, i: usize| -> Result<Option<f64>, String> {
        match (v.len(), required) {
            (0, false) => Ok(None),
            (len, _) if len == n => Ok(Some(v[i])),
            (0, true) => Err(format!(
                "`{name}` is missing: it is required, one value per axis (as `vmax`)"
            )),
            (len, _) => Err(format!(
                "`{name}` has {len} values, expected {n} (one per axis, as `vmax`)"
            )),
        }
    };
    let position = match pr.interface.as_str() {
        "position" => true,
        "velocity" => false,
        i => {
            return Err(format!(
                "unknown interface `{i}`; allowed: position, velocity"
            ));
        }
    };
    let mut axes = Vec::with_capacity(n);
    for i in 0..n {
        let or0 = |name: &str, v: &[f64]| get(name, v, false, i).map(|x| x.unwrap_or(0.0));
        let jmax = get("jmax", &pr.jmax, shape == Shape::JerkLimited, i)?;
        let limits = Limits::asymmetric(
            pr.vmax[i],
            get("vmin", &pr.vmin, false, i)?,
            get("amax", &pr.amax, true, i)?.unwrap_or(f64::NAN),
            get("amin", &pr.amin, false, i)?,
            if shape == Shape::JerkLimited {
                jmax
            } else {
                None
            },
        )
        .map_err(|e| format!("axis {i}: {e}"))?;
        let pf = if position {
            get("pf", &pr.pf, true, i)?.unwrap_or(f64::NAN)
        } else {
            0.0
        };
        axes.push(Axis {
            start: State {
                // Required for the position interface, as documented: a missing start
                // is not 0.
                p: get("p0", &pr.p0, position, i)?.unwrap_or(0.0),
                v: or0("v0", &pr.v0)?,
                a: or0("a0", &pr.a0)?,
            },
            target: State {
                p: pf,
                v: or0("vf", &pr.vf)?,
                a: or0("af", &pr.af)?,
            },
            limits,
        });
    }
    let profiles = if position {
        plan(&axes, shape, sync).map_err(|e| e.to_string())?
    } else {
        plan_velocity(&axes, shape, sync).map_err(|e| e.to_string())?
    };
    let duration = profiles.iter().map(Profile::duration_s).fold(0.0, f64::max);
    Ok(json!({
        "duration": duration,
        "axes": profiles.iter().map(axis_json).collect::<Vec<_>>(),
    }))
}

fn axis_json(p: &Profile) -> Value {
    let s = p.start();
    let segs: Vec<Value> = p
        .segments()
        .iter()
        .map(|seg| match *seg {
            Segment::Jerk { duration_s, jerk } => json!([duration_s, jerk]),
            Segment::Accel { duration_s, accel } => json!([duration_s, 0.0, accel]),
        })
        .collect();
    json!({ "p0": s.p, "v0": s.v, "a0": s.a, "segments": segs })
}

/// Answer one input line given as bytes (without its newline): [`answer`] of the text, or
/// an error naming the line (`number`, from 1) and the byte where it stops being UTF-8.
pub fn answer_bytes(number: u64, line: &[u8]) -> String {
    match std::str::from_utf8(line) {
        Ok(text) => answer(text),
        Err(e) => json!({
            "error": format!(
                "line {number}: not UTF-8 (invalid byte at offset {} of the line, counted from 0)",
                e.valid_up_to()
            )
        })
        .to_string(),
    }
}

/// Lines answered together, in parallel, at most.
pub const BATCH: usize = 8192;

/// The most bytes of lines a batch holds: 64 MiB. A batch ends at [`BATCH`] lines or at
/// this many bytes, whichever comes first: [`BATCH`] lines of the longest a line may be
/// ([`settle_files::limit::PLAN_LINE`], 1 MiB) would hold 8 GiB.
pub const BATCH_BYTES: usize = 64 << 20;

/// Answer the JSON lines of `input` on `output`, in order, in parallel batches on `jobs`
/// threads (all cores when `None`).
///
/// Lines are split on `\n` (a `\r` before it is dropped); a line that is not UTF-8, or
/// longer than [`settle_files::limit::PLAN_LINE`] (skipped unread), is answered with an
/// error and the stream goes on. A batch holds up to [`BATCH`] lines
/// (`max_batch` lower, e.g. 1 for a terminal), but never waits for input: it ends as soon
/// as the lines read so far are all that `input` has delivered (no complete line left in
/// the read buffer) or holds [`BATCH_BYTES`], then its answers are written and flushed. So a client that writes one
/// line and waits for its answer gets it, and a file is still answered in large batches.
pub fn plan_stream(
    input: impl std::io::Read,
    mut output: impl std::io::Write,
    jobs: Option<usize>,
    max_batch: usize,
) -> Result<(), crate::error::Error> {
    use rayon::prelude::*;
    use settle_files::lines::{BoundedLines, LineStatus};
    let max_batch = max_batch.clamp(1, BATCH);
    // A batch is the most work handed out at once.
    let pool = crate::execute::pool::thread_pool(jobs, max_batch)?;
    let read_err = |e| crate::error::Error::read("stdin", e);
    let write_err = |e| crate::error::Error::write("stdout", e);
    let limit = settle_files::limit::PLAN_LINE;
    let mut input = BoundedLines::new(
        std::io::BufReader::with_capacity(1 << 16, input),
        usize::try_from(limit.bytes).unwrap_or(usize::MAX),
    );
    // A line longer than the limit is answered with an error, unread (`None`).
    let mut batch: Vec<(u64, Option<Vec<u8>>)> = Vec::new();
    loop {
        batch.clear();
        let mut eof = false;
        let mut held = 0;
        while batch.len() < max_batch && held < BATCH_BYTES {
            // Reading on would wait for input: answer what is here first.
            if !batch.is_empty() && !input.get_ref().buffer().contains(&b'\n') {
                break;
            }
            let Some(status) = input.next_line().map_err(read_err)? else {
                eof = true;
                break;
            };
            let line = match status {
                LineStatus::Complete => Some(input.bytes().to_vec()),
                LineStatus::TooLong => None,
            };
            held += line.as_ref().map_or(0, Vec::len);
            batch.push((input.line_no(), line));
        }
        let too_long = |n: u64| {
            json!({
                "error": format!(
                    "line {n}: longer than {}, the limit for {}",
                    limit.human(),
                    limit.what
                )
            })
            .to_string()
        };
        let answers: Vec<String> = pool.install(|| {
            batch
                .par_iter()
                .map(|(n, l)| match l {
                    Some(l) => answer_bytes(*n, l),
                    None => too_long(*n),
                })
                .collect()
        });
        for a in answers {
            writeln!(output, "{a}").map_err(write_err)?;
        }
        output.flush().map_err(write_err)?;
        if eof {
            return Ok(());
        }
    }
}
