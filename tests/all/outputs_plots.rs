//! Figures: a sweep draws settle time and residual against each swept parameter and links
//! them from summary.md; `settle run --plot` draws the run's time series. PNGs carry text
//! rendered from the embedded font (no system fonts needed).

use std::path::Path;

fn ok(args: &[&str]) {
    let o = crate::support::settle()
        .args(args)
        .output()
        .expect("settle runs");
    assert!(
        o.status.success(),
        "settle {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Dark pixels in the figure's title strip (the top 40 px): text was drawn there.
fn title_ink(png: &Path) -> (u32, u32, usize) {
    let img = image::open(png).expect("decodes").to_rgb8();
    let (w, h) = img.dimensions();
    let dark = (0..w)
        .flat_map(|x| (0..40.min(h)).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
        .count();
    (w, h, dark)
}

#[test]
fn sweep_figures_are_written_and_linked() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("qs");
    ok(&[
        "sweep",
        "scenarios/quickstart.toml",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    let svg = std::fs::read_to_string(out.join("plots/vs_move_distance_mm.svg")).expect("svg");
    for text in [
        "settle time to within 10 um",
        "move + settle to within 50 um",
        "residual vibration after the move: peak",
        "trapezoid",
        "scurve",
        "move.distance_mm",
    ] {
        assert!(svg.contains(text), "`{text}` missing from the SVG");
    }
    let (w, h, ink) = title_ink(&out.join("plots/vs_move_distance_mm.png"));
    assert_eq!(
        (w, h),
        (1500, 3 * 380 + 50 + 36),
        "three rows of panels, one legend row"
    );
    assert!(
        ink > 200,
        "the PNG title has {ink} dark pixels: no text rendered?"
    );
    let summary = std::fs::read_to_string(out.join("summary.md")).expect("summary");
    assert!(
        summary.contains("![Settle time and residual vibration against move.distance_mm](plots/vs_move_distance_mm.svg)"),
        "{summary}"
    );
    assert!(summary.contains("[PNG](plots/vs_move_distance_mm.png)"));
}

#[test]
fn run_plot_draws_every_channel_and_the_residual() {
    let dir = tempfile::tempdir().expect("tempdir");
    let trace = dir.path().join("run-4.csv");
    ok(&[
        "run",
        "scenarios/quickstart.toml",
        "--case",
        "4",
        "--plot",
        "--out",
        trace.to_str().expect("utf-8"),
    ]);
    let svg = std::fs::read_to_string(dir.path().join("run-4.svg")).expect("svg");
    let root = Path::new(crate::support::manifest_dir());
    let (_, runs) = settle::load_runs(&root.join("scenarios/quickstart.toml")).expect("scenario");
    let (series, _) = settle::output::sink::record_run(&runs[4]).expect("runs");
    for c in &series.channels {
        assert!(svg.contains(&c.name), "channel {} not drawn", c.name);
    }
    assert!(svg.contains("after the move (residual vibration)"));
    assert!(svg.contains("move ends"));
    let (_, _, ink) = title_ink(&dir.path().join("run-4.png"));
    assert!(ink > 100, "no text in the PNG title ({ink} dark pixels)");
}
