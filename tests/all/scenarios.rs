//! Every checked-in scenario parses and expands; bad files give errors that name the file,
//! line and key.

use std::path::Path;

use settle::Error;

fn parse_err(text: &str) -> String {
    let path = Path::new("bad.toml");
    let r =
        settle::expand::parse(text, path).and_then(|(sc, src)| settle::expand::expand(&sc, &src));
    match r {
        Ok(runs) => panic!("expected an error, got {} runs", runs.len()),
        Err(e) => {
            assert!(e.is_input_error(), "{e}");
            e.to_string()
        }
    }
}

const GOOD: &str = r#"name = "t"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 10.0
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 1e5
[sweep]
"move.distance_mm" = { from = 1, to = 100, steps = 3, scale = "log" }
profile = ["trapezoid", "scurve"]
"#;

#[test]
fn every_scenario_file_parses_and_expands() {
    let dir = Path::new(crate::support::manifest_dir()).join("scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("scenarios/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "toml") {
            let (_, runs) = settle::load_runs(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!runs.is_empty(), "{} expands to no runs", path.display());
            n += 1;
        }
    }
    assert!(n >= 1, "no scenario files found");
}

#[test]
fn sweep_expands_in_order_with_log_ranges() {
    let (sc, src) = settle::expand::parse(GOOD, Path::new("t.toml")).expect("parses");
    let runs = settle::expand::expand(&sc, &src).expect("expands");
    assert_eq!(runs.len(), 6);
    let d: Vec<f64> = runs.iter().map(|r| r.distance_mm).collect();
    assert_eq!(d[0], 1.0);
    assert!((d[2] - 10.0).abs() < 1e-12, "{d:?}");
    assert_eq!(d[4], 100.0);
    assert_eq!(runs[0].profile.name(), "trapezoid");
    assert_eq!(runs[1].profile.name(), "scurve");
    assert!(runs.iter().enumerate().all(|(i, r)| r.id == i));
}

#[test]
fn unknown_key_names_file_line_and_key() {
    let text = GOOD.replace("amax_mm_s2 = 3000.0", "amax_mm_s2 = 3000.0\nacel_max = 5");
    let msg = parse_err(&text);
    assert!(msg.starts_with("bad.toml:9:"), "{msg}");
    assert!(msg.contains("acel_max"), "{msg}");
    assert!(
        msg.contains("vmax_mm_s") && msg.contains("jmax_mm_s3"),
        "lists allowed keys: {msg}"
    );
}

#[test]
fn wrong_type_names_file_line_and_key() {
    let msg = parse_err(&GOOD.replace("vmax_mm_s = 300.0", "vmax_mm_s = \"fast\""));
    assert!(msg.starts_with("bad.toml:7:"), "{msg}");
    assert!(msg.contains("key `limits.vmax_mm_s`"), "{msg}");
    assert!(msg.contains("invalid type"), "{msg}");
}

#[test]
fn invalid_limits_name_the_key_and_what_is_allowed() {
    let msg = parse_err(&GOOD.replace("amax_mm_s2 = 3000.0", "amax_mm_s2 = -3000.0"));
    assert!(
        msg.starts_with("bad.toml:8:1: key `limits.amax_mm_s2`"),
        "{msg}"
    );
    assert!(
        msg.contains("from 1e-3 to 1e9 (mm/s^2), got -3000"),
        "{msg}"
    );
    // A swept value is blamed on the sweep line.
    let msg = parse_err(&GOOD.replace(
        "profile = [",
        "\"limits.jmax_mm_s3\" = [1e5, 0.0]\nprofile = [",
    ));
    assert!(
        msg.starts_with("bad.toml:12:1: key `sweep.limits.jmax_mm_s3`"),
        "{msg}"
    );
}

#[test]
fn unknown_profile_kind_lists_the_allowed_ones() {
    let msg = parse_err(&GOOD.replace("\"scurve\"]", "\"scruve\"]"));
    assert!(
        msg.starts_with("bad.toml:12:1: key `sweep.profile`"),
        "{msg}"
    );
    assert!(
        msg.contains("scruve") && msg.contains("trapezoid, scurve"),
        "{msg}"
    );
}

#[test]
fn empty_sweep_axis_and_bad_ranges_are_errors() {
    let msg = parse_err(&GOOD.replace("profile = [\"trapezoid\", \"scurve\"]", "profile = []"));
    assert!(
        msg.contains("key `sweep.profile`") && msg.contains("empty sweep axis"),
        "{msg}"
    );
    let msg = parse_err(&GOOD.replace("steps = 3", "steps = 0"));
    assert!(
        msg.contains("key `sweep.move.distance_mm`") && msg.contains("steps"),
        "{msg}"
    );
    let msg = parse_err(&GOOD.replace("\"move.distance_mm\"", "\"move.speed\""));
    assert!(
        msg.contains("cannot be swept") && msg.contains("limits.vmax_mm_s"),
        "{msg}"
    );
}

#[test]
fn bad_modes_and_observe_values_are_errors() {
    let msg = parse_err(&GOOD.replace("damping_ratio = 0.05", "damping_ratio = 1.5"));
    assert!(
        msg.starts_with("bad.toml:3:1: key `machine.modes`"),
        "{msg}"
    );
    let msg = parse_err(&GOOD.replace("[sweep]", "[observe]\nbands_um = [10, -1]\n[sweep]"));
    assert!(msg.contains("key `observe.bands_um`"), "{msg}");
}

#[test]
fn missing_jerk_for_scurve_is_an_error() {
    let msg = parse_err(&GOOD.replace("jmax_mm_s3 = 1e5\n", ""));
    assert!(
        msg.contains("jmax_mm_s3") && msg.contains("scurve"),
        "{msg}"
    );
}

#[test]
fn missing_jerk_for_the_jerk_limited_kinds_names_file_line_and_key() {
    // GOOD without jmax: `[limits]` is on line 6.
    let no_jerk = GOOD.replace("jmax_mm_s3 = 1e5\n", "");
    for kind in ["scurve", "fourjerk", "pvt_sym", "pvt_asym"] {
        let msg = parse_err(&no_jerk.replace(
            "profile = [\"trapezoid\", \"scurve\"]",
            &format!("profile = [\"trapezoid\", \"{kind}\"]"),
        ));
        assert!(
            msg.starts_with("bad.toml:6:1: key `limits`")
                && msg.contains(&format!("`{kind}` needs `jmax_mm_s3`")),
            "{msg}"
        );
    }
    // The trapezoid alone needs no jerk limit.
    let text = no_jerk.replace(
        "profile = [\"trapezoid\", \"scurve\"]",
        "profile = [\"trapezoid\"]",
    );
    let (sc, src) = settle::expand::parse(&text, Path::new("t.toml")).expect("parses");
    assert_eq!(settle::expand::expand(&sc, &src).expect("expands").len(), 3);
}

#[test]
fn unreadable_file_is_an_input_error() {
    let e = settle::load_runs(Path::new("/nonexistent/x.toml")).expect_err("no such file");
    assert!(matches!(e, Error::Read { .. }) && e.is_input_error());
    assert!(e.to_string().contains("/nonexistent/x.toml"));
}

#[test]
fn unknown_tables_and_keys_inside_a_study_table_name_their_line() {
    // An unknown table: the strict scenario parse names its line and lists the studies'
    // tables besides its own keys.
    let msg = parse_err(&GOOD.replace("[sweep]", "[scna]\nlines = 3\n[sweep]"));
    assert!(msg.starts_with("bad.toml:10:"), "{msg}");
    assert!(
        msg.contains("scna") && msg.contains("`scan`") && msg.contains("`corner`"),
        "{msg}"
    );
    // A key the `[scan]` kind does not know: its own parse names the line and the key.
    let scan = GOOD.replace(
        "[sweep]",
        "[scan]\nv_scan_mm_s = 100.0\nfly_amax_mm_s2 = 10000.0\nline = 3\n[sweep]",
    );
    let msg = parse_err(&scan);
    assert!(msg.starts_with("bad.toml:13:1: key `scan.line`"), "{msg}");
    assert!(msg.contains("lines"), "lists the allowed keys: {msg}");
    // A wrong type inside `[scan]`.
    let msg = parse_err(&scan.replace("v_scan_mm_s = 100.0", "v_scan_mm_s = \"fast\""));
    assert!(msg.starts_with("bad.toml:11:"), "{msg}");
    assert!(msg.contains("key `scan.v_scan_mm_s`"), "{msg}");
}

/// The keys a table of a scenario accepts, as the parser lists them for an unknown one
/// (`expected one of `a`, `b`...`), without the studies' tables it adds at the top level.
fn accepted_keys(table: &str) -> Vec<String> {
    let head = format!("[{table}]\n");
    let text = if table.is_empty() {
        format!("bogus_key = 1\n{GOOD}")
    } else if GOOD.contains(&head) {
        GOOD.replace(&head, &format!("{head}bogus_key = 1\n"))
    } else {
        // The studies' tables are parsed before the motion is checked, so `[corner]` or
        // `[gcode]` beside `[move]` still reports its unknown key first.
        format!("{GOOD}\n{head}bogus_key = 1\n")
    };
    let e = parse_err(&text);
    let list = e
        .split("expected ")
        .nth(1)
        .unwrap_or_else(|| panic!("[{table}]: {e}"));
    let list = list.split(", or a study's table").next().unwrap_or(list);
    list.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// docs/reference/scenario.md documents every table a scenario takes (a `## `[table]``
/// section, or a row of its top level) and every key of each, as the parser accepts them.
#[test]
fn the_scenario_reference_documents_every_table_and_key() {
    let doc = std::fs::read_to_string(
        Path::new(crate::support::manifest_dir()).join("docs/reference/scenario.md"),
    )
    .expect("docs/reference/scenario.md");
    let section = |heading: &str| -> &str {
        let start = doc
            .find(&format!("\n## {heading}\n"))
            .unwrap_or_else(|| panic!("no section `## {heading}` in scenario.md"));
        let rest = &doc[start + 1..];
        let end = rest[3..].find("\n## ").map_or(rest.len(), |e| e + 3);
        &rest[..end]
    };
    let top = accepted_keys("");
    assert!(top.contains(&"current".to_string()), "{top:?}");
    let mut tables: Vec<String> = settle::studies::tables()
        .iter()
        .map(|t| t.to_string())
        .collect();
    for key in &top {
        if section("Top level").contains(&format!("| `{key}` |")) {
            continue;
        }
        tables.push(key.clone());
    }
    for t in &tables {
        let s = section(&format!("`[{t}]`"));
        if matches!(t.as_str(), "sweep" | "current") {
            continue; // free-form: one key per swept parameter
        }
        for key in accepted_keys(t) {
            assert!(
                s.contains(&format!("`{key}")) || s.contains(&format!(".{key}.")),
                "[{t}] `{key}` is not documented in scenario.md"
            );
        }
    }
    // One motion, and it is not only [move] or [corner].
    assert!(!doc.contains("exactly one of `[move]` and `[corner]`"));
    assert!(doc.contains("exactly one of `[move]`, `[corner]` and `[gcode]`"));
}
