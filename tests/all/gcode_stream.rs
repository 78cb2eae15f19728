//! The `[gcode]` study streams its job (`Motion::Stream`): it plans the job chunk by chunk
//! as it is simulated, as `settle gcode` does, and measures the contour error along the
//! chunks, so that no run holds the whole job planned or its samples recorded.

use settle::studies::Motion;
use settle::workflows::gcode::{GcodeOptions, measure, parse_shapers};
use settle_planner::firmware::Firmware;

use crate::support::{extra, one_modal_run, root, write};

/// The whole ringing tower (`gcode/prints/ringing_tower.gcode`, Klipper's defaults, MZV
/// at 48 Hz on X and Y) as a `[gcode]` run gives `settle gcode`'s numbers on `printer_xy`
/// (modal backend, 2 kHz, both linearised at the centre of the printing moves): the two
/// plan the same chunks, step the plant alike across the command's breakpoints and
/// sample the same instants of the print clock, so the worst error agrees to rounding
/// (1e-9 relative: far above the modal plant's rounding, 1e-16 per step, and far below
/// what a sample grid moved by a fraction of a sample changes), on the same line, with
/// the same 95th percentile and print time, and the same largest smoothing and
/// vibration.
/// The run's motion is streamed: its plan holds no trajectory.
#[test]
fn the_gcode_study_streams_the_whole_job_with_settle_gcodes_numbers() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tower = root().join("gcode/prints/ringing_tower.gcode");
    let scenario = write(
        dir.path(),
        "whole.toml",
        &format!(
            "name = \"whole\"\n[machine]\npreset = \"printer_xy\"\ndriver_model = \"linear\"\n\
             [gcode]\nfile = {:?}\nfirmware = \"klipper\"\n\
             [shaper]\ntype = \"mzv\"\nfrequency_hz = 48.0\n\
             [limits]\nvmax_mm_s = 500.0\namax_mm_s2 = 3000.0\njmax_mm_s3 = 100000.0\n\
             [observe]\nwindow_s = 0.05\nsample_rate_hz = 2000\nbands_um = [10.0]\n",
            tower.to_str().expect("utf-8")
        ),
    );
    let run = one_modal_run(&scenario);
    let names = run.axis_names();
    let planned = settle::studies::plan(&run, &names).expect("plans");
    assert!(
        matches!(planned.motion, Motion::Stream(_)) && planned.probe.is_none(),
        "a G-code run is streamed, not held planned and recorded"
    );
    let m = settle::execute::execute(&run, None).expect("runs");
    assert!(m.is_ok(), "{m:?}");
    let opts = GcodeOptions::new(tower, "printer_xy", Firmware::Klipper)
        .expect("options")
        .with_shapers(parse_shapers("mzv@48").expect("a shaper"));
    let whole = measure(&opts).expect("runs");
    let worst = extra(&m, "contour_worst_um");
    assert!(
        (worst - whole.worst_um).abs() <= 1e-9 * whole.worst_um,
        "study {worst} um vs settle gcode {} um",
        whole.worst_um
    );
    assert_eq!(
        extra(&m, "contour_worst_line"),
        whole.worst().first().expect("spot").line as f64
    );
    let p95 = extra(&m, "contour_p95_um");
    assert!(
        (p95 - whole.p95_um).abs() <= 1e-9 * whole.p95_um,
        "p95 {p95} vs {}",
        whole.p95_um
    );
    assert_eq!(
        extra(&m, "print_time_s").to_bits(),
        whole.print_time_s.to_bits()
    );
    // The error's two parts: the command evaluated as the runner evaluates it, the
    // command's path built and measured 20 ms late as `settle gcode` does.
    let split = whole.streamed.split_worst;
    for (column, theirs) in [
        ("smoothing_worst_um", split.smoothing_um),
        ("vibration_worst_um", split.vibration_um),
    ] {
        let ours = extra(&m, column);
        assert!(
            theirs > 0.0 && (ours - theirs).abs() <= 1e-9 * theirs,
            "{column}: study {ours} um vs settle gcode {theirs} um"
        );
    }
}
