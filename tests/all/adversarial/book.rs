//! The book's page of limits (docs/guide/failures.md) names every limit as the code has
//! it: each kind of file's size limit and the numeric bounds checked before work.

#[test]
fn the_book_lists_every_limit_as_the_code_has_it() {
    let page = std::fs::read_to_string(crate::support::root().join("docs/guide/failures.md"))
        .expect("docs/guide/failures.md");
    let mut missing = Vec::new();
    let mut has = |text: String| {
        if !page.contains(&text) {
            missing.push(text);
        }
    };
    for l in settle_files::limit::ALL {
        has(l.human());
    }
    let thousands = |n: usize| {
        let s = n.to_string();
        let mut out = String::new();
        for (i, c) in s.chars().enumerate() {
            if i > 0 && (s.len() - i).is_multiple_of(3) {
                out.push(',');
            }
            out.push(c);
        }
        out
    };
    has(format!("+-{:e} mm", settle::spec::MAX_POSITION_MM));
    has(format!(
        "{:e}",
        settle::expand::validate::MAX_SAMPLES_PER_RUN
    ));
    has(format!(
        "{:e}",
        settle::expand::validate::MAX_RECORDED_VALUES
    ));
    has(format!(
        "at least {:e} s",
        settle::expand::validate::MIN_STEP_S
    ));
    has(format!(
        "at most {} bands",
        settle::expand::validate::MAX_BANDS
    ));
    has(format!(
        "at most {}",
        settle::expand::validate::MAX_SWEEP_AXES
    ));
    has(thousands(settle::expand::axes::MAX_RUNS));
    has(format!(
        "2 to {}",
        thousands(settle::studies::scan::table::MAX_LINES)
    ));
    has(format!(
        "at most {}",
        settle::input::modes::MAX_MODES_PER_AXIS
    ));
    has(format!(
        "`frequency_hz` {} to {} Hz",
        settle::input::modes::MIN_FREQUENCY_HZ,
        settle::input::modes::MAX_FREQUENCY_HZ
    ));
    has(format!(
        "`weight` 0 to {}",
        settle::input::modes::MAX_WEIGHT
    ));
    has(format!(
        "at most {} values each",
        settle::workflows::tune::grid::MAX_LIST
    ));
    has(format!(
        "at most {} candidates",
        thousands(settle::workflows::tune::grid::MAX_CANDIDATES)
    ));
    has(format!(
        "at most {} Hz",
        thousands(settle::workflows::gcode::MAX_SAMPLE_RATE_HZ as usize)
    ));
    has(format!(
        "past {} points",
        thousands(settle::workflows::gcode::stream::MAX_MAP_POINTS)
    ));
    has(format!(
        "at least {} Hz",
        settle_planner::shaper::MIN_FREQUENCY_HZ
    ));
    has(format!(
        "at most {} distinct names",
        settle_gcode::MAX_FEATURES
    ));
    has(format!(
        "at most {} layers",
        thousands(settle_gcode::MAX_LAYERS as usize)
    ));
    has(format!(
        "{:e} to {:e} in the file's units",
        settle_gcode::MIN_LIMIT_VALUE,
        settle_gcode::MAX_LIMIT_VALUE
    ));
    use settle_identify::read::{MAX_ACCEL_MM_S2, MAX_PSD, MIN_PEAK_PSD, MIN_VIBRATION_MM_S2};
    has(format!("within +-{MAX_ACCEL_MM_S2:.0e} mm/s^2"));
    has(format!("at least {MIN_VIBRATION_MM_S2:.3} mm/s^2"));
    has(format!("at most {MAX_PSD:.0e} (mm/s^2)^2/Hz"));
    has(format!("a peak of at least {MIN_PEAK_PSD:.0e}"));
    assert!(
        missing.is_empty(),
        "docs/guide/failures.md lacks {missing:?}"
    );
}
