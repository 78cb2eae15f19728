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
