//! Checks of expanded runs: every value finite and in range, the studies' own checks,
//! the machine and the move's travel. Errors name the key to blame: the sweep axis when
//! the value was swept.

use crate::error::Error;
use crate::input::modes::MAX_FREQUENCY_HZ;
use crate::input::source::Source;
use crate::measure::metrics::BLOWUP_M;
use crate::spec::MAX_POSITION_MM;
use crate::spec::run_spec::{RunSpec, needs_jerk};
use crate::studies::{self, Role};

/// The most samples one run may simulate, move and observation window together: at the
/// default 10 kHz that is 10,000 s of simulated time, far beyond any settling question, and
/// about a minute of work on the fastest backend. A longer run is a mistake in the input
/// (a distance in metres written as millimetres, a speed limit of `1e-9`), not a run to wait
/// for.
pub const MAX_SAMPLES_PER_RUN: f64 = 1e8;

/// The most values (samples times channels, the time stamp included) a run whose trace is
/// kept may hold: `settle run`, a recorded sweep (`--mcap`, `--rerun`) and the run kinds
/// that measure the whole trace (scans, shaping) keep it in memory, about 21 bytes a value
/// with the vectors' growth: 336 MB at the limit, 670,000 samples (67 s at 10 kHz) of the
/// 24 channels of a two-axis printer. A longer trace is refused before it is simulated.
pub const MAX_RECORDED_VALUES: f64 = 1.6e7;

/// The shortest integration step `sim.max_step_s` may force (s): 1 us, a hundred times
/// finer than a 1 kHz mode needs (`w h` = 0.006). The steps of a run are bounded as its
/// samples are, by [`MAX_SAMPLES_PER_RUN`].
pub const MIN_STEP_S: f64 = 1e-6;

/// The most settling bands a scenario may give: each is a column of runs.csv and a panel
/// of every figure, and a handful (a tolerance and a few looser or tighter ones) answers
/// every settling question.
pub const MAX_BANDS: usize = 16;

/// The longest observation window `observe.window_s` may give (s): 1e4 s, the whole
/// [`MAX_SAMPLES_PER_RUN`] at the default 10 kHz, and a hundred periods of the slowest mode
/// a machine may have ([`crate::input::modes::MIN_FREQUENCY_HZ`], a period of 100 s). A settling question is
/// answered in seconds (ten decay time constants of a 40 Hz, zeta 0.05 mode are 0.8 s); a
/// window of hours is a unit mistake (milliseconds written as seconds). The samples limit
/// alone does not bound it: at 0.02 Hz, two samples per period of that slowest mode, it
/// would let a window reach 5e9 s.
pub const MAX_WINDOW_S: f64 = 1e4;

/// The highest sample rate `observe.sample_rate_hz` may give (Hz): 1 MHz, twenty samples
/// per period of the fastest mode a machine may have ([`MAX_FREQUENCY_HZ`], 50 kHz; twenty
/// or more give settling times to a few percent, as [`validate_sampling`] advises), one
/// sample per [`MIN_STEP_S`], the finest integration step `sim.max_step_s` may force. A
/// faster rate resolves nothing a machine's modes hold and only spends samples.
pub const MAX_SAMPLE_RATE_HZ: f64 = 1e6;

/// The widest settling band `observe.bands_um` may give is below this (um): the blow-up
/// limit [`BLOWUP_M`] (0.1 m) in um. An error past it stops the run as a fault, so every run
/// that completes stays within it: a band as wide would be entered at the move's end by
/// every run, a settling time of 0 that says nothing.
pub const BAND_LIMIT_UM: f64 = BLOWUP_M * 1e6;

/// The most sweep axes a scenario may give: a figure draws one line per combination of
/// the axes other than its x axis, and a report compares the axes side by side.
pub const MAX_SWEEP_AXES: usize = 8;

/// The shortest time (s) a move of `distance_mm` can take at `vmax_mm_s` and `amax_mm_s2`:
/// the trapezoid's, exact for it and a lower bound for every jerk-limited kind.
pub fn min_move_time_s(distance_mm: f64, vmax_mm_s: f64, amax_mm_s2: f64) -> f64 {
    let d = distance_mm.abs();
    if d * amax_mm_s2 <= vmax_mm_s * vmax_mm_s {
        2.0 * (d / amax_mm_s2).sqrt()
    } else {
        d / vmax_mm_s + vmax_mm_s / amax_mm_s2
    }
}

/// The key at fault for a run whose move takes too long ([`validate_duration`]): of the
/// two values the move's time rests on (the distance and vmax when the move cruises, its
/// time then mostly `d / vmax`; the distance and amax when it never reaches vmax,
/// `2 sqrt(d / amax)`), the one swept, else the one further from a 100 mm move at
/// 100 mm/s and 1000 mm/s^2 (the time grows with the distance and falls with the
/// limit). A limit that takes no part is never named, whatever is swept.
fn duration_key(run: &RunSpec) -> String {
    const DISTANCE: &str = "move.distance_mm";
    let (d, v, a) = (run.distance_mm.abs(), run.vmax_mm_s, run.amax_mm_s2);
    // Each value with how far it is from the reference, in the direction that lengthens.
    let (first, second) = if d * a <= v * v {
        ((DISTANCE, d / 100.0), ("limits.amax_mm_s2", 1000.0 / a))
    } else {
        ((DISTANCE, d / 100.0), ("limits.vmax_mm_s", 100.0 / v))
    };
    let swept = |k: &str| run.blame(k).starts_with("sweep.");
    let key = match (swept(first.0), swept(second.0)) {
        (true, false) => first.0,
        (false, true) => second.0,
        _ if second.1 > first.1 => second.0,
        _ => first.0,
    };
    run.blame(key)
}

/// Check that a run's simulated time (its move at the fastest the limits allow, plus the
/// observation window) stays within [`MAX_SAMPLES_PER_RUN`] samples, before any work.
fn validate_duration(run: &RunSpec, src: &Source) -> Result<(), Error> {
    let move_s = min_move_time_s(run.distance_mm, run.vmax_mm_s, run.amax_mm_s2);
    if let Some(h) = run.max_step_s {
        let steps = (move_s + run.window_s) / h;
        if !(steps.is_finite() && steps <= MAX_SAMPLES_PER_RUN) {
            return Err(src.error_at(
                &run.blame("sim.max_step_s"),
                format!(
                    "{h} s steps over at least {:.3e} s (the move and the window) are {steps:.3e} steps, over the limit of {MAX_SAMPLES_PER_RUN:e} per run: raise max_step_s",
                    move_s + run.window_s
                ),
            ));
        }
    }
    let samples = (move_s + run.window_s) * run.sample_rate_hz;
    if samples.is_finite() && samples <= MAX_SAMPLES_PER_RUN {
        return Ok(());
    }
    let key = duration_key(run);
    Err(src.error_at(
        &key,
        format!(
            "{}: a move of {} mm at vmax_mm_s = {} and amax_mm_s2 = {} takes at least {move_s:.3e} s; with the {} s window at {} Hz that is {samples:.3e} samples, over the limit of {MAX_SAMPLES_PER_RUN:e} per run: shorten the move, raise the limits or lower observe.sample_rate_hz",
            if run.swept.is_empty() && run.id == 0 {
                "the move as written".to_string()
            } else {
                format!("run {}", run.id)
            },
            run.distance_mm, run.vmax_mm_s, run.amax_mm_s2, run.window_s, run.sample_rate_hz
        ),
    ))
}

/// Check the size of a run whose motion lasts `duration_s` (s): its samples, move and
/// window together, within [`MAX_SAMPLES_PER_RUN`], and, when its trace is `kept` in
/// memory, its values (`per_sample` each, the time stamp included) within
/// [`MAX_RECORDED_VALUES`]. The message for a run over a limit. `crate::execute::execute`
/// checks this before it simulates; [`validate_run`] before any run, on the planned
/// motion.
pub fn check_run_size(
    run: &RunSpec,
    duration_s: f64,
    per_sample: usize,
    kept: bool,
) -> Result<(), String> {
    let samples = (duration_s + run.window_s) * run.sample_rate_hz;
    if !(samples.is_finite() && samples <= MAX_SAMPLES_PER_RUN) {
        return Err(format!(
            "the planned move takes {duration_s:.3e} s: with the {} s window at {} Hz that is {samples:.3e} samples, over the limit of {MAX_SAMPLES_PER_RUN:e} per run",
            run.window_s, run.sample_rate_hz,
        ));
    }
    let values = samples * per_sample as f64;
    if kept && values > MAX_RECORDED_VALUES {
        return Err(format!(
            "its trace is kept in memory: {samples:.3e} samples (the {duration_s:.3e} s move and the {} s window at {} Hz) of {per_sample} values each are {values:.3e} values, over the limit of {MAX_RECORDED_VALUES:e}: shorten the move or the window, or lower observe.sample_rate_hz",
            run.window_s, run.sample_rate_hz,
        ));
    }
    Ok(())
}

/// The key at fault for a run whose planned motion is too long ([`validate_planned`]):
/// `observe.window_s` when the window is at least as long as the motion (it holds most of
/// the samples; the `[observe]` keys are never swept), else a swept key the motion's time
/// rests on, else for a scan the line's speed or its settle
/// margin (whichever adds more to each line), for a move the jerk limit when the planned
/// move takes more than twice its trapezoid's time (the jerk phases set it), else the key
/// [`duration_key`] names.
fn planned_key(run: &RunSpec, duration_s: f64) -> String {
    use crate::studies::scan::ScanSpec;
    const SCAN: [&str; 6] = [
        "scan.v_scan_mm_s",
        "scan.width_mm",
        "scan.lines",
        "scan.settle_margin_s",
        "scan.fly_amax_mm_s2",
        "scan.fly_jmax_mm_s3",
    ];
    const MOVE: [&str; 4] = [
        "move.distance_mm",
        "limits.vmax_mm_s",
        "limits.amax_mm_s2",
        "limits.jmax_mm_s3",
    ];
    if run.window_s >= duration_s {
        return "observe.window_s".to_string();
    }
    let scan = run.state::<ScanSpec>();
    let candidates = SCAN.iter().filter(|_| scan.is_some()).chain(MOVE.iter());
    if let Some(k) = candidates
        .map(|k| run.blame(k))
        .find(|k| k.starts_with("sweep."))
    {
        return k;
    }
    if let Some(s) = scan {
        let key = if s.settle_margin_s > s.width_mm / s.v_scan_mm_s {
            "scan.settle_margin_s"
        } else {
            "scan.v_scan_mm_s"
        };
        return run.blame(key);
    }
    let trapezoid_s = min_move_time_s(run.distance_mm, run.vmax_mm_s, run.amax_mm_s2);
    if run.jmax_mm_s3.is_some() && duration_s > 2.0 * trapezoid_s {
        return run.blame("limits.jmax_mm_s3");
    }
    duration_key(run)
}

/// Check a run's planned motion against [`check_run_size`] before any run: the planner's
/// own duration, so a jerk limit that stretches a move (a 1e-3 mm/s^3 jerk makes a 1e5 mm
/// move last 1474 s, far beyond its 0.1 s at 1e6 mm/s) and a scan's lines (each crossed at
/// `v_scan_mm_s`) count. The trace counted as kept is the one the run's study measures
/// whole (a scan's, a shaped step's). A run that does not plan is left to fail as a run,
/// its row saying why; a G-code job is planned as it streams and bounded by its own checks
/// (`settle_gcode::MAX_STEP_DURATION_S`).
fn validate_planned(run: &RunSpec, src: &Source) -> Result<(), Error> {
    check_planned(run, src, false)
}

/// Check a run whose trace is recorded (`settle sweep --mcap`, `--rerun`: every run's trace
/// is kept; `settle run`'s one run, its trace written whole) as `validate_planned` checks
/// one whose study keeps it: the sweep calls this for each of its runs before any starts,
/// `settle run` for its run before it writes anything.
pub fn validate_recorded(run: &RunSpec, src: &Source) -> Result<(), Error> {
    check_planned(run, src, true)
}

/// [`validate_planned`], the trace counted as kept when `recorded` or when the run's study
/// measures it whole.
fn check_planned(run: &RunSpec, src: &Source, recorded: bool) -> Result<(), Error> {
    if studies::motion(run).table() == Some("gcode") {
        return Ok(());
    }
    let Ok(axes) = run.machine.axes(run.driver) else {
        return Ok(());
    };
    let names: Vec<String> = axes.iter().map(|a| a.name.clone()).collect();
    let Ok(planned) = studies::plan(run, &names) else {
        return Ok(());
    };
    let duration_s = planned.motion.duration_s();
    let per_sample = crate::measure::channels::channels(&axes).len() + 1;
    let kept = recorded || planned.probe.is_some();
    check_run_size(run, duration_s, per_sample, kept).map_err(|m| {
        let what = if run.swept.is_empty() && run.id == 0 {
            "the run as written".to_string()
        } else {
            format!("run {}", run.id)
        };
        src.error_at(
            &planned_key(run, duration_s),
            format!("{what}: {m}; checked before any run starts"),
        )
    })
}

/// The slowest and fastest vibration modes (Hz) a run's axes have: the modes given, or a
/// physical machine's undamped natural frequencies linearised at the move's start (rigid
/// rotations at 0 Hz left out). `None` when there are none or the machine cannot be
/// linearised (its own checks report why).
pub fn mode_range_hz(run: &RunSpec) -> Option<(f64, f64)> {
    let moved = studies::moved_axes(run);
    let freqs: Vec<f64> = match run.machine.physical() {
        None => moved
            .iter()
            .flat_map(|a| run.machine.modes_of(a).iter().map(|m| m.frequency_hz))
            .collect(),
        Some(machine) => {
            let axes = machine.compile(settle_sim::DriverMode::Linear).ok()?;
            let mut out = Vec::new();
            for a in axes.iter().filter(|a| moved.contains(&a.name)) {
                let q = a.lumped.equilibrium(run.start_mm * 1e-3, None).ok()?;
                out.extend(a.lumped.natural_frequencies_hz(&q));
            }
            out
        }
    };
    // A physical machine's rigid rotations are 0 Hz; a mode given is a mode, however slow
    // (its window is checked against it).
    let rigid = if run.machine.physical().is_some() {
        1e-6
    } else {
        0.0
    };
    let freqs = freqs.into_iter().filter(|f| f.is_finite() && *f > rigid);
    freqs.fold(None, |r, f| match r {
        None => Some((f, f)),
        Some((lo, hi)) => Some((f64::min(lo, f), f64::max(hi, f))),
    })
}

/// Check that the observation can see the run's modes (`range`: [`mode_range_hz`]): a
/// window of at least half a period of the slowest mode (the first residual peak lies
/// inside it) and at least two samples per period of the fastest (Nyquist: fewer alias it
/// and the settling time lands between samples far apart).
pub fn validate_sampling(
    run: &RunSpec,
    range: Option<(f64, f64)>,
    src: &Source,
) -> Result<(), Error> {
    let Some((slowest_hz, fastest_hz)) = range else {
        return Ok(());
    };
    let what = format!(
        "{} of the axes the run moves: {}",
        if run.machine.physical().is_some() {
            "the machine's linearised modes"
        } else {
            "machine.modes"
        },
        studies::moved_axes(run).join(", ")
    );
    if run.window_s < 0.5 / slowest_hz {
        return Err(src.error_at(
            "observe.window_s",
            format!(
                "{} s is shorter than half a period of the slowest mode ({slowest_hz:.4} Hz in {what}): the residual vibration is not seen; give at least {:.4} s (ten decay time constants, 1 / (zeta 2 pi f), is the usual choice)",
                run.window_s,
                0.5 / slowest_hz
            ),
        ));
    }
    if fastest_hz > MAX_FREQUENCY_HZ && run.machine.physical().is_some() {
        // No sample rate can be asked for: the machine is implausible, not the rate.
        return Err(src.error_at(
            "machine",
            format!(
                "the linearised modes of the machine `{}` reach {fastest_hz:.4e} Hz, above the {MAX_FREQUENCY_HZ} Hz a machine's mode may have: the machine is implausible (no sample rate would do); check the units of its parts (motor.rotor_inertia_g_cm2 in g cm^2, 54 for a NEMA 17, not kg m^2; stiffnesses in N/m; masses in kg; `settle machine` prints the modes)",
                run.machine.physical().map_or("", |m| m.name.as_str())
            ),
        ));
    }
    if run.sample_rate_hz < 2.0 * fastest_hz {
        return Err(src.error_at(
            "observe.sample_rate_hz",
            format!(
                "{} Hz gives fewer than two samples per period of the fastest mode ({fastest_hz:.4} Hz in {what}): give at least {:.4} Hz (twenty or more samples per period for settling times to a few percent)",
                run.sample_rate_hz,
                2.0 * fastest_hz
            ),
        ));
    }
    Ok(())
}

/// Check a positive observation setting against its largest value `max` (in `unit`): the
/// message for a value outside (0, `max`].
fn check_up_to(value: f64, max: f64, unit: &str) -> Result<(), String> {
    if value.is_finite() && value > 0.0 && value <= max {
        Ok(())
    } else {
        Err(format!(
            "must be a finite number > 0 and at most {max:e} ({unit}), got {value}"
        ))
    }
}

/// Check the observation and simulation settings of the base run: `observe.window_s` up to
/// [`MAX_WINDOW_S`], `observe.sample_rate_hz` up to [`MAX_SAMPLE_RATE_HZ`], their product
/// within [`MAX_SAMPLES_PER_RUN`], `sim.max_step_s` at least [`MIN_STEP_S`], and one to
/// [`MAX_BANDS`] distinct `observe.bands_um`, each > 0 and below [`BAND_LIMIT_UM`]. The
/// `[observe]` keys cannot be swept (`crate::spec::run_spec::RunSpec::set`): every run
/// takes the values checked here.
pub fn validate_observe(run: &RunSpec, src: &Source) -> Result<(), Error> {
    check_up_to(run.window_s, MAX_WINDOW_S, "s")
        .map_err(|m| src.error_at("observe.window_s", m))?;
    check_up_to(run.sample_rate_hz, MAX_SAMPLE_RATE_HZ, "Hz")
        .map_err(|m| src.error_at("observe.sample_rate_hz", m))?;
    if run.window_s * run.sample_rate_hz > MAX_SAMPLES_PER_RUN {
        return Err(src.error_at(
            "observe.sample_rate_hz",
            format!(
                "window_s * sample_rate_hz exceeds {MAX_SAMPLES_PER_RUN:e} samples; lower one of them"
            ),
        ));
    }
    if let Some(h) = run.max_step_s
        && !(h.is_finite() && h >= MIN_STEP_S)
    {
        return Err(src.error_at(
            "sim.max_step_s",
            format!("must be a finite number > 0 and at least {MIN_STEP_S:e} (s), got {h}"),
        ));
    }
    if run.bands_um.is_empty() {
        return Err(src.error_at(
            "observe.bands_um",
            format!(
                "give one or more bands, each a finite number > 0 and below {BAND_LIMIT_UM:e} (um)"
            ),
        ));
    }
    if let Some((i, b)) = run
        .bands_um
        .iter()
        .enumerate()
        .find(|(_, b)| !(b.is_finite() && **b > 0.0 && **b < BAND_LIMIT_UM))
    {
        return Err(src.error_at(
            "observe.bands_um",
            format!(
                "band {i} must be a finite number > 0 and below {BAND_LIMIT_UM:e} (um), got {b}: an error past {BLOWUP_M} m stops the run as a fault, so no run that completes leaves a band as wide"
            ),
        ));
    }
    let mut sorted = run.bands_um.clone();
    sorted.sort_by(f64::total_cmp);
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(src.error_at(
            "observe.bands_um",
            format!(
                "band {} um is given twice; each band is a column of runs.csv, give each once",
                w[0]
            ),
        ));
    }
    if run.bands_um.len() > MAX_BANDS {
        return Err(src.error_at(
            "observe.bands_um",
            format!(
                "{} bands; at most {MAX_BANDS} (each band is a column of runs.csv and a panel of the figures)",
                run.bands_um.len()
            ),
        ));
    }
    Ok(())
}

/// Check the base values of the move and the limits as written, whether or not a sweep
/// overrides them: a value that is not a number, not finite, or (with the others) gives a
/// move beyond [`MAX_SAMPLES_PER_RUN`] is a mistake in the file even when every run takes
/// a swept value instead. A path study's move is checked per run (its length is its path's).
pub fn validate_base(base: &RunSpec, src: &Source) -> Result<(), Error> {
    validate_move(base, src, |k| k.to_string())?;
    validate_duration(base, src)?;
    validate_positions(base, src, |k| k.to_string())
}

/// Check the move's distance and start and the limits (`blame` names the key): each finite,
/// the distance 0 or at least [`crate::spec::MIN_LENGTH_MM`], each limit within the range
/// of its quantity ([`crate::spec::check_limit`]).
fn validate_move(run: &RunSpec, src: &Source, blame: impl Fn(&str) -> String) -> Result<(), Error> {
    if let Err(m) = crate::spec::check_length(run.distance_mm, true) {
        return Err(src.error_at(&blame("move.distance_mm"), m));
    }
    if !run.start_mm.is_finite() {
        return Err(src.error_at(
            &blame("move.start_mm"),
            format!("must be finite, got {}", run.start_mm),
        ));
    }
    use crate::spec::Quantity::{Acceleration, Jerk, Speed};
    for (key, value, quantity) in [
        ("limits.vmax_mm_s", Some(run.vmax_mm_s), Speed),
        ("limits.amax_mm_s2", Some(run.amax_mm_s2), Acceleration),
        ("limits.jmax_mm_s3", run.jmax_mm_s3, Jerk),
    ] {
        if let Some(Err(m)) = value.map(|v| crate::spec::check_limit(v, quantity)) {
            return Err(src.error_at(&blame(key), m));
        }
    }
    Ok(())
}

/// Check that the move starts and ends within [`MAX_POSITION_MM`] (`blame` names the key).
fn validate_positions(
    run: &RunSpec,
    src: &Source,
    blame: impl Fn(&str) -> String,
) -> Result<(), Error> {
    for (key, x) in [
        ("move.start_mm", run.start_mm),
        ("move.distance_mm", run.start_mm + run.distance_mm),
    ] {
        if x.abs() > MAX_POSITION_MM {
            return Err(src.error_at(
                &blame(key),
                crate::spec::beyond_positions(
                    if key == "move.start_mm" {
                        "the move starts"
                    } else {
                        "the move ends"
                    },
                    x,
                ),
            ));
        }
    }
    Ok(())
}

/// Check one run: its path kind first (a corner path checks its profile kind and machine
/// before the limits), then the keys of every run, then its other studies, then its machine.
pub fn validate_run(run: &RunSpec, src: &Source) -> Result<(), Error> {
    let kind_check = |paths: bool| {
        for k in studies::of(run).filter(|k| (k.role() == Role::Path) == paths) {
            k.validate(run).map_err(|(key, m)| src.error_at(&key, m))?;
        }
        Ok::<(), Error>(())
    };
    kind_check(true)?;
    validate_move(run, src, |k| run.blame(k))?;
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
    if let Some(machine) = run.machine.physical() {
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
    // The modes as written were checked when the machine was read; swept values here,
    // by the same check. The key blamed: the swept field itself, else another swept field
    // of the same mode (a swept frequency below the written `frequency_sigma_hz`).
    for a in run.machine.modes() {
        for (i, m) in a.modes.iter().enumerate() {
            if let Err(e) = m.check() {
                let of_mode = |p: &str| {
                    crate::spec::run_spec::mode_param(p)
                        .is_some_and(|(axis, j, _)| axis == a.axis && j == i)
                };
                let key = run
                    .swept
                    .iter()
                    .find(|(p, _)| {
                        crate::spec::run_spec::mode_param(p) == Some((a.axis.as_str(), i, e.field))
                    })
                    .or_else(|| run.swept.iter().find(|(p, _)| of_mode(p)))
                    .map_or_else(|| "machine".to_string(), |(p, _)| format!("sweep.{p}"));
                return Err(src.error_at(&key, format!("axis `{}`, mode {i}: {e}", a.axis)));
            }
        }
    }
    validate_duration(run, src)?;
    validate_positions(run, src, |k| run.blame(k))?;
    validate_planned(run, src)
}
