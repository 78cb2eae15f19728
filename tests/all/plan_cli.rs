//! `settle plan`: JSON lines in, one answer per line out, in order; profiles that really
//! reach their targets; errors that say what is wrong and let the process go on.

use std::io::Write;
use std::process::{Command, Stdio};

use serde_json::Value;

fn plan(input: &str) -> Vec<Value> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_settle"))
        .args(["plan", "--jobs", "2"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(input.as_bytes())
        .expect("writes");
    let out = child.wait_with_output().expect("runs");
    assert!(out.status.success());
    String::from_utf8(out.stdout)
        .expect("utf8")
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect()
}

/// Integrate an axis's segments from its start state: (p, v, a) at the end.
fn integrate(axis: &Value) -> (f64, f64, f64) {
    let f = |k: &str| axis[k].as_f64().expect("number");
    let (mut p, mut v, mut a) = (f("p0"), f("v0"), f("a0"));
    for seg in axis["segments"].as_array().expect("segments") {
        let s: Vec<f64> = seg
            .as_array()
            .expect("array")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect();
        let (t, j) = (s[0], s[1]);
        if s.len() == 3 {
            a = s[2];
        }
        p += v * t + a * t * t / 2.0 + j * t * t * t / 6.0;
        v += a * t + j * t * t / 2.0;
        a += j * t;
    }
    (p, v, a)
}

#[test]
fn answers_each_line_in_order() {
    let input = r#"{"p0":[0],"v0":[0],"a0":[0],"pf":[1],"vf":[0],"af":[0],"vmax":[1],"amax":[2],"jmax":[10],"sync":"time"}
{"p0":[0,1,2],"pf":[1,-2,2.5],"v0":[0.1,0,0],"vmax":[1,2,1],"amax":[2,1,3],"jmax":[10,5,8]}
this is not json
{"p0":[0],"pf":[1],"vmax":[0],"amax":[2],"jmax":[10]}
{"p0":[0],"pf":[1],"vmax":[1],"amax":[2],"kind":"trapezoid"}
{"p0":[0,0],"pf":[1,2],"vmax":[1,1],"amax":[2,2],"jmax":[10,10],"sync":"phase"}
{"vf":[0.5],"af":[0.2],"vmax":[1],"amax":[2],"jmax":[10],"interface":"velocity"}
{"p0":[0],"pf":[1],"vmax":[1,2],"amax":[2],"jmax":[10]}
{"vf":[0.5,-1],"vmax":[1,1],"amax":[2,2],"jmax":[10,10],"interface":"velocity","sync":"time"}
"#;
    let out = plan(input);
    assert_eq!(out.len(), 9);
    // The issue's example: vmax 1, amax 2, jmax 10, 1 m: ramps 0.2 s, holds 0.3 s, cruise
    // 0.3 s: 1.7 s.
    assert!(
        (out[0]["duration"].as_f64().expect("duration") - 1.7).abs() < 1e-12,
        "{}",
        out[0]
    );
    let (p, v, a) = integrate(&out[0]["axes"][0]);
    assert!((p - 1.0).abs() < 1e-12 && v.abs() < 1e-12 && a.abs() < 1e-12);
    // Three axes, time-synchronised: each reaches its target at the common duration.
    let targets = [1.0, -2.0, 2.5];
    let dur = out[1]["duration"].as_f64().expect("duration");
    for (i, ax) in out[1]["axes"].as_array().expect("axes").iter().enumerate() {
        let (p, v, a) = integrate(ax);
        assert!(
            (p - targets[i]).abs() < 1e-9 && v.abs() < 1e-9 && a.abs() < 1e-9,
            "axis {i}: {p} {v} {a}"
        );
        let t: f64 = ax["segments"]
            .as_array()
            .expect("segs")
            .iter()
            .map(|s| s[0].as_f64().expect("t"))
            .sum();
        assert!((t - dur).abs() < 1e-9, "axis {i} lasts {t}, not {dur}");
    }
    assert!(
        out[2]["error"]
            .as_str()
            .expect("error")
            .contains("invalid problem")
    );
    assert!(out[3]["error"].as_str().expect("error").contains("vmax"));
    // Trapezoid: 1 m at vmax 1, amax 2: 0.5 s up, 0.5 s cruise, 0.5 s down.
    assert!((out[4]["duration"].as_f64().expect("duration") - 1.5).abs() < 1e-12);
    let (p, v, _) = integrate(&out[4]["axes"][0]);
    assert!((p - 1.0).abs() < 1e-12 && v.abs() < 1e-12);
    // Phase sync: straight line, the second axis is the first scaled by 2.
    let a0 = out[5]["axes"][0]["segments"].as_array().expect("segs");
    let a1 = out[5]["axes"][1]["segments"].as_array().expect("segs");
    assert_eq!(a0.len(), a1.len());
    for (s0, s1) in a0.iter().zip(a1) {
        assert_eq!(s0[0], s1[0], "aligned breaks");
    }
    let (_, v, a) = integrate(&out[6]["axes"][0]);
    assert!((v - 0.5).abs() < 1e-12 && (a - 0.2).abs() < 1e-12);
    assert!(
        out[7]["error"]
            .as_str()
            .expect("error")
            .contains("has 1 values, expected 2")
    );
}

/// `settle plan` on raw bytes: the exit status and the answers, one per output line.
fn plan_bytes(input: &[u8]) -> (bool, Vec<Value>) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_settle"))
        .args(["plan", "--jobs", "2"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("starts");
    let mut stdin = child.stdin.take().expect("stdin");
    let input = input.to_vec();
    // Written from a thread: the answers come back while the input is still being written.
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().expect("runs");
    writer.join().expect("joins").expect("writes");
    let answers = String::from_utf8(out.stdout)
        .expect("utf8")
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    (out.status.success(), answers)
}

/// A line that is not UTF-8 is answered with an error naming it, and the lines around it,
/// in batches before it and after it, are answered as usual.
#[test]
fn a_line_that_is_not_utf8_is_answered_and_the_stream_goes_on() {
    let good = r#"{"p0":[0],"pf":[1],"vmax":[1],"amax":[2],"jmax":[10]}"#;
    let mut input = Vec::new();
    for _ in 0..20_000 {
        input.extend_from_slice(good.as_bytes());
        input.push(b'\n');
    }
    // Line 20,001: valid up to byte offset 7, then a lone continuation byte.
    input.extend_from_slice(b"{\"p0\":[\xff0]}\n");
    for _ in 0..3 {
        input.extend_from_slice(good.as_bytes());
        input.push(b'\n');
    }
    let (ok, out) = plan_bytes(&input);
    assert!(ok);
    assert_eq!(out.len(), 20_004, "one answer per line");
    for (i, a) in out.iter().enumerate() {
        if i == 20_000 {
            let e = a["error"].as_str().expect("an error");
            assert!(e.contains("line 20001") && e.contains("offset 7"), "{e}");
        } else {
            assert_eq!(a["duration"].as_f64(), Some(1.7), "line {}: {a}", i + 1);
        }
    }
    // The corpus file: a good line, a line of one 0xff byte, a good line.
    let corpus = std::fs::read(
        std::path::Path::new(crate::support::manifest_dir())
            .join("fuzz/corpus/plan/hardening_bad_utf8.jsonl"),
    )
    .expect("corpus file");
    let (ok, out) = plan_bytes(&corpus);
    assert!(ok);
    assert_eq!(out.len(), 3);
    assert!(
        out[1]["error"]
            .as_str()
            .is_some_and(|e| e.contains("line 2") && e.contains("offset 0")),
        "{}",
        out[1]
    );
    assert_eq!(out[2]["duration"].as_f64(), Some(1.7));
}

/// Request and response through a pipe: each line's answer arrives before the next line is
/// written, so `settle plan` never holds an answer while it waits for input. A stalled
/// answer fails the test after 20 s instead of hanging it.
#[test]
fn each_answer_arrives_before_the_next_line_is_written() {
    use std::io::BufRead;
    use std::sync::mpsc;
    use std::time::Duration;
    let mut child = Command::new(env!("CARGO_BIN_EXE_settle"))
        .args(["plan", "--jobs", "2"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("starts");
    let mut stdin = child.stdin.take().expect("stdin");
    let stdout = child.stdout.take().expect("stdout");
    let (tx, rx) = mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in std::io::BufReader::new(stdout).lines() {
            if tx.send(line.expect("reads")).is_err() {
                break;
            }
        }
    });
    for k in 1..=5 {
        writeln!(
            stdin,
            r#"{{"p0":[0],"pf":[{k}],"vmax":[1],"amax":[2],"jmax":[10]}}"#
        )
        .expect("writes");
        stdin.flush().expect("flushes");
        let answer = match rx.recv_timeout(Duration::from_secs(20)) {
            Ok(a) => a,
            Err(e) => {
                let _ = child.kill();
                panic!("no answer to line {k} within 20 s: {e}");
            }
        };
        let v: Value = serde_json::from_str(&answer).expect("JSON");
        let (p, _, _) = integrate(&v["axes"][0]);
        assert!((p - f64::from(k)).abs() < 1e-9, "line {k}: {answer}");
    }
    drop(stdin);
    assert!(child.wait().expect("exits").success());
    reader.join().expect("joins");
}

/// An axis already at its target, in every sync mode and both kinds: the other axis's
/// profile as alone (1.7 s jerk limited, 1.5 s trapezoid: see `answers_each_line_in_order`),
/// the resting axis standing still for that long (time, phase) or without segments (none).
#[test]
fn an_axis_already_at_its_target_is_answered() {
    let mut input = String::new();
    let corpus = std::fs::read_to_string(
        std::path::Path::new(crate::support::manifest_dir())
            .join("fuzz/corpus/plan/hardening_axis_at_target.jsonl"),
    )
    .expect("corpus file");
    input.push_str(&corpus);
    let modes = ["time", "phase", "none"];
    for sync in modes {
        input.push_str(&format!(
            r#"{{"p0":[0,0],"pf":[0,1],"vmax":[1,1],"amax":[2,2],"jmax":[10,10],"sync":"{sync}"}}"#
        ));
        input.push('\n');
        input.push_str(&format!(
            r#"{{"p0":[3,0],"pf":[3,1],"vmax":[1,1],"amax":[2,2],"kind":"trapezoid","sync":"{sync}"}}"#
        ));
        input.push('\n');
    }
    input.push_str(r#"{"p0":[5],"pf":[5],"vmax":[1],"amax":[2],"jmax":[10]}"#);
    input.push('\n');
    let out = plan(&input);
    assert_eq!(out.len(), 8);
    for (i, a) in out.iter().enumerate().take(7) {
        assert!(a.get("error").is_none(), "line {}: {a}", i + 1);
        let (sync, t, p) = match i {
            0 => ("time", 1.7, 0.0),
            _ => (
                modes[(i - 1) / 2],
                [1.7, 1.5][(i - 1) % 2],
                [0.0, 3.0][(i - 1) % 2],
            ),
        };
        let d = a["duration"].as_f64().expect("duration");
        assert!((d - t).abs() < 1e-12, "line {}: {a}", i + 1);
        let (p1, v1, _) = integrate(&a["axes"][1]);
        assert!((p1 - 1.0).abs() < 1e-12 && v1.abs() < 1e-12, "{a}");
        let rest = &a["axes"][0];
        assert_eq!(integrate(rest), (p, 0.0, 0.0), "line {}: {a}", i + 1);
        let segs = rest["segments"].as_array().expect("segments");
        if sync == "none" {
            assert!(segs.is_empty(), "{a}");
        } else {
            // One hold at exactly zero acceleration, as long as the move.
            assert_eq!(segs.len(), 1, "{a}");
            assert_eq!(segs[0][1].as_f64(), Some(0.0));
            assert_eq!(segs[0][2].as_f64(), Some(0.0));
            assert!((segs[0][0].as_f64().expect("t") - d).abs() < 1e-12, "{a}");
        }
    }
    assert_eq!(out[7]["duration"].as_f64(), Some(0.0), "{}", out[7]);
    assert_eq!(out[7]["axes"][0]["segments"], serde_json::json!([]));
}

/// The next f64 away from zero (`out`) or towards it.
fn next(x: f64, out: bool) -> f64 {
    f64::from_bits(if out {
        x.to_bits() + 1
    } else {
        x.to_bits() - 1
    })
}

/// The first value past `bound` (away from zero with `out`) as the JSON reader reads it:
/// serde_json's default parsing may round a long decimal to a neighbour of its f64, so the
/// next f64 or the one after is the first that reads past the bound.
fn beyond(bound: f64, out: bool) -> f64 {
    let mut x = bound;
    for _ in 0..2 {
        x = next(x, out);
        let read: f64 = serde_json::from_str(&serde_json::json!(x).to_string()).expect("reads");
        if read != bound {
            return read;
        }
    }
    panic!("no value within 2 ulps of {bound} reads past it");
}

#[test]
fn each_value_and_the_axes_are_bounded_before_planning() {
    // The bounds (settle::workflows::plan): values within 1e15 in magnitude, limits at
    // least 1e-9 (vmin, amin at most -1e-9), at most 30 axes. At each bound the line is
    // planned (each axis on its own: fitting the unit move of axis 0 to the 1e15 s of
    // axis 1 is beyond what f64 resolves, and the planner says so); the next f64 beyond is answered with an error naming the field, the axis
    // and the range, and the stream goes on.
    let line = |field: &str, x: f64| {
        let mut v = serde_json::json!({
            "p0": [0, 0], "pf": [1, 1], "v0": [0, 0], "af": [0, 0],
            "vmax": [1, 1], "vmin": [-1, -1], "amax": [1, 1], "amin": [-1, -1], "jmax": [1, 1],
            "sync": "none"
        });
        v[field][1] = serde_json::json!(x);
        v.to_string()
    };
    let mut input = String::new();
    let mut cases = Vec::new();
    for (field, bounds, range) in [
        ("p0", [-1e15, 1e15], "from -1e15 to 1e15"),
        ("pf", [-1e15, 1e15], "from -1e15 to 1e15"),
        ("v0", [-1e15, 1e15], "from -1e15 to 1e15"),
        ("af", [-1e15, 1e15], "from -1e15 to 1e15"),
        ("vmax", [1e-9, 1e15], "from 1e-9 to 1e15"),
        ("amax", [1e-9, 1e15], "from 1e-9 to 1e15"),
        ("jmax", [1e-9, 1e15], "from 1e-9 to 1e15"),
        ("vmin", [-1e15, -1e-9], "from -1e15 to -1e-9"),
        ("amin", [-1e15, -1e-9], "from -1e15 to -1e-9"),
    ] {
        let [lo, hi] = bounds;
        // Away from zero beyond the larger end, towards it beyond the smaller one.
        let (beyond_lo, beyond_hi) = if lo < 0.0 && hi < 0.0 {
            (beyond(lo, true), beyond(hi, false))
        } else if lo < 0.0 {
            (beyond(lo, true), beyond(hi, true))
        } else {
            (beyond(lo, false), beyond(hi, true))
        };
        for (x, ok) in [
            (lo, true),
            (hi, true),
            (beyond_lo, false),
            (beyond_hi, false),
        ] {
            input.push_str(&line(field, x));
            input.push('\n');
            cases.push((field, x, ok, range));
        }
    }
    // The largest and the smallest: a move of 1e15 at 1 (d / v + v / a + a / j), one of 1
    // at 1e-9 per second (the same formula, v / a and a / j under 1 s of it).
    input.push_str("{\"p0\":[-1e15],\"pf\":[1e15],\"vmax\":[1],\"amax\":[1],\"jmax\":[1]}\n");
    let axes = |n: usize| {
        let v = |x: f64| serde_json::json!(vec![x; n]);
        serde_json::json!({"p0": v(0.0), "pf": v(1.0), "vmax": v(1.0), "amax": v(1.0), "jmax": v(1.0)})
            .to_string()
    };
    input.push_str(&format!("{}\n{}\n", axes(30), axes(31)));
    input.push_str("{\"p0\":[0],\"pf\":[1e300],\"vmax\":[1],\"amax\":[1],\"jmax\":[1]}\n");
    let out = plan(&input);
    assert_eq!(out.len(), cases.len() + 4);
    for ((field, x, ok, range), a) in cases.iter().zip(&out) {
        if *ok && matches!(*field, "v0" | "af") {
            // Taken: a start or target far beyond the limits is the planner's to answer
            // (it may find no profile), not refused as out of range.
            let e = a["error"].as_str().unwrap_or("");
            assert!(!e.contains("must be a number"), "{field} = {x}: {a}");
        } else if *ok {
            assert!(a.get("error").is_none(), "{field} = {x}: {a}");
            assert!(a["duration"].as_f64().is_some_and(f64::is_finite), "{a}");
        } else {
            let e = a["error"]
                .as_str()
                .unwrap_or_else(|| panic!("{field} = {x}: {a}"));
            assert!(
                // A number of more digits than a message prints whole is shortened.
                e.starts_with(&settle::error::shorten_numbers(&format!(
                    "`{field}` of axis 1 must be a number {range}, got {x}"
                ))),
                "{field} = {x}: {e}"
            );
        }
    }
    let n = cases.len();
    let d = out[n]["duration"].as_f64().expect("duration");
    assert!((d - (2e15 + 2.0)).abs() <= 2e15 * 1e-12, "{}", out[n]);
    assert_eq!(out[n + 1]["axes"].as_array().map(Vec::len), Some(30));
    assert_eq!(
        out[n + 2]["error"],
        "`vmax` lists 31 axes; a problem has 1 to 30 (one value per axis)"
    );
    let e = out[n + 3]["error"].as_str().expect("error");
    assert!(
        e.starts_with("`pf` of axis 0 must be a number from -1e15 to 1e15, got 1e300"),
        "{e}"
    );
}
