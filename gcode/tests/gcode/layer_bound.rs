//! A job has at most `MAX_LAYERS` layers: the line that would open one more ends the read
//! with an error naming it, whatever the layers come from; `LayerMode::Comments` takes
//! none from Z.

use settle_gcode::{
    Dialect, EventKind, GcodeError, LayerMode, LayerSource, MAX_LAYERS, Reader, ReaderOptions,
};

/// A CNC-like job whose every layer comes from the Z fallback: a plunge to a new Z, then
/// one planar feed move there (a 1 mm cut along X), alternating between Z -0.1 and 0.
/// Line 1 turns the spindle on; layer `k` (from 1) is opened by line `1 + 2k`.
fn z_layers(n: u32) -> String {
    let mut s = String::from("M3 S10000\n");
    for k in 0..n {
        let (z, x) = if k % 2 == 0 {
            ("-0.1", "1")
        } else {
            ("0", "0")
        };
        s.push_str(&format!("G1 Z{z} F300\nG1 X{x} F1500\n"));
    }
    s
}

/// The layer changes read and the error that ended the read, if any.
fn read(text: &str, opts: ReaderOptions) -> (Vec<(u64, u32)>, Option<GcodeError>) {
    let mut layers = Vec::new();
    for e in Reader::new(text.as_bytes(), opts).with_name("job.nc") {
        match e {
            Ok(e) => {
                if let EventKind::Layer(_) = e.kind {
                    layers.push((e.line, e.layer));
                }
            }
            Err(e) => return (layers, Some(e)),
        }
    }
    (layers, None)
}

#[test]
fn the_bound_is_fifty_thousand_layers() {
    assert_eq!(MAX_LAYERS, 50_000);
}

#[test]
fn a_job_of_max_layers_from_z_reads_whole() {
    let (layers, error) = read(&z_layers(MAX_LAYERS), ReaderOptions::new(Dialect::Grbl));
    assert!(error.is_none(), "{error:?}");
    assert_eq!(layers.len(), 50_000);
    assert_eq!(layers.first(), Some(&(3, 1)));
    assert_eq!(layers.last(), Some(&(100_001, 50_000)));
}

#[test]
fn the_layer_past_the_bound_ends_the_read_at_its_line() {
    let text = z_layers(MAX_LAYERS + 1);
    for skip_bad_lines in [false, true] {
        let opts = ReaderOptions {
            skip_bad_lines,
            ..ReaderOptions::new(Dialect::Grbl)
        };
        let (layers, error) = read(&text, opts);
        assert_eq!(layers.len(), 50_000, "skip_bad_lines {skip_bad_lines}");
        match error {
            Some(GcodeError::TooManyLayers {
                at,
                layer,
                max,
                from,
            }) => {
                assert_eq!(
                    (&*at.source_name, at.line, layer, max, from),
                    ("job.nc", 100_003, 50_001, 50_000, LayerSource::ZChange)
                );
            }
            other => panic!("skip_bad_lines {skip_bad_lines}: {other:?}"),
        }
    }
}

#[test]
fn the_error_names_the_line_the_bound_why_and_the_way_out() {
    let (_, error) = read(&z_layers(MAX_LAYERS + 1), ReaderOptions::new(Dialect::Grbl));
    let text = error.expect("refused").to_string();
    for part in [
        "job.nc:100003: this line opens layer 50001 (a working move at a new Z",
        "past the 50000 layers settle reads in a job",
        "each layer is a row kept in memory and written",
        "give --layer-source markers",
        "[gcode] layer_source = \"markers\"",
    ] {
        assert!(text.contains(part), "{part:?} not in {text}");
    }
}

#[test]
fn markers_past_the_bound_are_refused_too() {
    // `;LAYER:n` opens its layer at its own line; 50,001 of them.
    let text: String = (0..=MAX_LAYERS).map(|n| format!(";LAYER:{n}\n")).collect();
    let (layers, error) = read(&text, ReaderOptions::new(Dialect::Marlin));
    assert_eq!(layers.last(), Some(&(50_000, 50_000)));
    let error = error.expect("refused");
    assert_eq!(error.line(), Some(50_001));
    let text = error.to_string();
    assert!(
        text.contains("(a slicer's layer marker)") && text.contains("give --layer-source z"),
        "{text}"
    );
}

#[test]
fn markers_only_takes_no_layers_from_z() {
    let opts = ReaderOptions {
        layers: LayerMode::Comments,
        ..ReaderOptions::new(Dialect::Grbl)
    };
    let (layers, error) = read(&z_layers(MAX_LAYERS + 1), opts);
    assert!(error.is_none(), "{error:?}");
    assert_eq!(layers, []);
}

#[test]
fn layer_modes_by_name() {
    for (name, mode) in [
        ("auto", LayerMode::Auto),
        ("markers", LayerMode::Comments),
        ("z", LayerMode::ZChange),
    ] {
        assert_eq!(LayerMode::parse(name), Ok(mode));
        assert_eq!(mode.name(), name);
    }
    assert_eq!(LayerMode::parse("Markers"), Ok(LayerMode::Comments));
    let e = LayerMode::parse("comments").expect_err("not a name");
    assert!(
        e.starts_with("`comments`: allowed: auto (")
            && e.contains("markers (")
            && e.contains("z ("),
        "{e}"
    );
}

/// A job (GRBL's planner) plans the 50,000 layers and stops at the line that opens one
/// more, with the reader's error.
#[test]
fn a_job_stops_at_the_layer_past_the_bound() {
    use settle_gcode::job::{Job, JobConfig};
    use settle_planner::firmware::Firmware;
    let text = z_layers(MAX_LAYERS + 1);
    let cfg = JobConfig::defaults(Firmware::Grbl).expect("defaults");
    let mut job = Job::new(
        Reader::new(text.as_bytes(), cfg.reader_options()).with_name("job.nc"),
        cfg,
    )
    .expect("job");
    let error = job.run_to_end().expect_err("refused");
    assert!(
        matches!(&error, GcodeError::TooManyLayers { at, .. } if at.line == 100_003),
        "{error}"
    );
}
