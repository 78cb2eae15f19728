//! Checks of expanded runs: every value finite and in range, the run kinds' own checks,
//! the machine and the move's travel. Errors name the key to blame: the sweep axis when
//! the value was swept.

use settle_sim::Mode;

use crate::error::Error;
use crate::input::source::Source;
use crate::kinds::{self, Role};
use crate::spec::run_spec::{RunSpec, needs_jerk};

/// Check the observation and simulation settings of the base run.
pub fn validate_observe(run: &RunSpec, src: &Source) -> Result<(), Error> {
    if !(run.window_s.is_finite() && run.window_s > 0.0) {
        return Err(src.error_at(
            "observe.window_s",
            format!("must be a finite number > 0 (s), got {}", run.window_s),
        ));
    }
    if !(run.sample_rate_hz.is_finite() && run.sample_rate_hz > 0.0) {
        return Err(src.error_at(
            "observe.sample_rate_hz",
            format!(
                "must be a finite number > 0 (Hz), got {}",
                run.sample_rate_hz
            ),
        ));
    }
    if run.window_s * run.sample_rate_hz > 1e8 {
        return Err(src.error_at(
            "observe.sample_rate_hz",
            "window_s * sample_rate_hz exceeds 1e8 samples; lower one of them",
        ));
    }
    if let Some(h) = run.max_step_s
        && !(h.is_finite() && h > 0.0)
    {
        return Err(src.error_at(
            "sim.max_step_s",
            format!("must be a finite number > 0 (s), got {h}"),
        ));
    }
    if run.bands_um.is_empty() || run.bands_um.iter().any(|b| !(b.is_finite() && *b > 0.0)) {
        return Err(src.error_at(
            "observe.bands_um",
            "give one or more bands, each a finite number > 0 (um)",
        ));
    }
    Ok(())
}

/// Check one run: its path kind first (a corner path checks its profile kind and machine
/// before the limits), then the keys of every run, then its other kinds, then its machine.
pub fn validate_run(run: &RunSpec, src: &Source) -> Result<(), Error> {
    let kind_check = |paths: bool| {
        for k in kinds::of(run).filter(|k| (k.role() == Role::Path) == paths) {
            k.validate(run).map_err(|(key, m)| src.error_at(&key, m))?;
        }
        Ok::<(), Error>(())
    };
    kind_check(true)?;
    for (name, value) in [
        ("move.distance_mm", run.distance_mm),
        ("move.start_mm", run.start_mm),
    ] {
        if !value.is_finite() {
            return Err(src.error_at(&run.blame(name), format!("must be finite, got {value}")));
        }
    }
    let limits = [
        ("limits.vmax_mm_s", Some(run.vmax_mm_s), "mm/s"),
        ("limits.amax_mm_s2", Some(run.amax_mm_s2), "mm/s^2"),
        ("limits.jmax_mm_s3", run.jmax_mm_s3, "mm/s^3"),
    ];
    for (key, value, unit) in limits {
        if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(src.error_at(
                &run.blame(key),
                format!("must be a finite number > 0 ({unit}), got {v}"),
            ));
        }
    }
    if needs_jerk(run.profile) && run.jmax_mm_s3.is_none() {
        return Err(src.error_at(
            "limits",
            format!(
                "profile kind `{}` needs `jmax_mm_s3` in [limits] (every kind but `trapezoid` is jerk-limited: scurve, fourjerk, pvt_sym, pvt_asym)",
                run.profile
            ),
        ));
    }
    kind_check(false)?;
    if let Some(machine) = &run.machine {
        let machine_swept = || {
            run.swept
                .iter()
                .find(|(p, _)| p.starts_with("machine."))
                .map_or("machine".to_string(), |(p, _)| format!("sweep.{p}"))
        };
        if let Err(e) = machine.validate() {
            return Err(src.error_at(&machine_swept(), e.to_string()));
        }
        if let Some(a) = machine.axis(&run.axis)
            && let Some((lo, hi)) = a.travel_m()
        {
            let (lo_mm, hi_mm) = (lo * 1e3, hi * 1e3);
            for (name, x) in [
                ("move.start_mm", run.start_mm),
                ("move.distance_mm", run.start_mm + run.distance_mm),
            ] {
                if !(lo_mm..=hi_mm).contains(&x) {
                    return Err(src.error_at(
                        &run.blame(name),
                        format!(
                            "the move reaches {x} mm, outside the belt travel of axis `{}`: {lo_mm:.1} to {hi_mm:.1} mm (the carriage must stay 5 mm from pulley and idler)",
                            run.axis
                        ),
                    ));
                }
            }
        }
    }
    // The modes as written were checked when the machine was read; swept values here.
    for a in &run.modes {
        for (i, m) in a.modes.iter().enumerate() {
            if let Err(e) = Mode::new(m.frequency_hz, m.damping_ratio, m.weight) {
                let field = if !(m.frequency_hz.is_finite() && m.frequency_hz > 0.0) {
                    "frequency_hz"
                } else if !(0.0..1.0).contains(&m.damping_ratio) {
                    "damping_ratio"
                } else {
                    "weight"
                };
                let key = run
                    .swept
                    .iter()
                    .find(|(p, _)| {
                        crate::spec::run_spec::mode_param(p) == Some((a.axis.as_str(), i, field))
                    })
                    .map_or_else(|| "machine".to_string(), |(p, _)| format!("sweep.{p}"));
                return Err(src.error_at(&key, format!("axis `{}`, mode {i}: {e}", a.axis)));
            }
        }
    }
    Ok(())
}
