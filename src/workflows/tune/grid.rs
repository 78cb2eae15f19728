//! The search grid of `settle tune`: the `[tune]` table resolved against the scenario's
//! base run into candidates (kinds, jerks, kind parameters, shapers) and the move family.

use settle_planner::shaper::ShaperType;
use settle_planner::{ProfileKind, ProfileParams};

use crate::error::Error;
use crate::input::scenario::Scenario;
use crate::input::source::Source;
use crate::spec::run_spec::RunSpec;
use crate::studies::corner::Corner;
use crate::studies::shaping::{DEFAULT_DAMPING_RATIO, ShaperSetting};
use crate::workflows::tune::firmware::{Candidates, MarlinShaping};
use crate::workflows::tune::search::{BandSource, Candidate, Plan};
use crate::workflows::tune::target;
use settle_planner::firmware::Firmware;

/// Four-jerk BOW1..4 patterns searched (multiples of jmax; each <= 1).
pub const BOW_PATTERNS: [[f64; 4]; 5] = [
    [1.0, 1.0, 1.0, 1.0],
    [1.0, 0.5, 0.5, 1.0],
    [0.5, 1.0, 1.0, 0.5],
    [1.0, 0.5, 1.0, 0.5],
    [0.5, 1.0, 0.5, 1.0],
];

/// PVT asymmetries searched (`ProfileParams::pvt_asym_ki`, in (1/3, 1); 0.5 is its default).
pub const PVT_KI: [f64; 4] = [0.4, 0.5, 0.65, 0.8];

/// Default frequency scales: the mode frequency +-20% (shapers are tuned to a measured
/// frequency; the neighbourhood covers the shift of the damped and coupled modes).
pub const FREQUENCY_SCALES: [f64; 7] = [0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2];

/// Default robustness margin, 0.8: score on settling into 80% of the band. The engines
/// agree on residual peaks to a few percent on fixed-stiffness machines but up to ~20% on
/// the belt printer (rapier's belt stiffness varies along the move; tune_corner: 9.18 um on
/// modal, 10.9 um on rapier), so a winner scored at the band's edge can miss the band on
/// another engine; 0.8 keeps that 20% inside it.
pub const DEFAULT_MARGIN: f64 = 0.8;

/// Klipper's smoothing target (mm): its suggested max_accel keeps the smoothing within it
/// (`TARGET_SMOOTHING` of shaper_calibrate.py); the default `max_smoothing_mm`.
pub const DEFAULT_MAX_SMOOTHING_MM: f64 = settle_planner::shaper_select::TARGET_SMOOTHING_MM;

/// The most values a list of `[tune]` may hold: the search is their product.
pub const MAX_LIST: usize = 64;

/// The most candidates a search may have (each is simulated over the move family; the
/// default search of a printer axis has a few hundred).
pub const MAX_CANDIDATES: usize = 100_000;

/// Resolve the scenario's search on `axis` (default: the move's axis), with `axis`'s
/// current settings (`[tune.axis.<name>]`) as the baseline candidate. Errors name the
/// `[tune]` key. A `[sweep]` is refused unless the scenario marks a `[current]` point (an
/// imported scenario: its sweep is for `settle sweep`; tune searches from `[tune]`).
pub fn plan(
    sc: &Scenario,
    src: &Source,
    runs: &[RunSpec],
    axis: Option<&str>,
) -> Result<Plan, Error> {
    let spec = sc.tune.clone().unwrap_or_default();
    for (key, len) in [
        (
            "tune.distances_mm",
            spec.distances_mm.as_ref().map(Vec::len),
        ),
        ("tune.angles_deg", spec.angles_deg.as_ref().map(Vec::len)),
        ("tune.kinds", spec.kinds.as_ref().map(Vec::len)),
        ("tune.shapers", spec.shapers.as_ref().map(Vec::len)),
        (
            "tune.frequency_scales",
            spec.frequency_scales.as_ref().map(Vec::len),
        ),
        ("tune.axes", spec.axes.as_ref().map(Vec::len)),
        (
            "tune.accelerations_mm_s2",
            spec.accelerations_mm_s2.as_ref().map(Vec::len),
        ),
    ] {
        if let Some(n) = len.filter(|n| *n > MAX_LIST) {
            return Err(src.error_at(
                key,
                format!("{n} values; at most {MAX_LIST} (the search is their product)"),
            ));
        }
    }
    if !sc.sweep.is_empty() && sc.current.is_empty() {
        return Err(src.error_at(
            "sweep",
            "settle tune does its own search: remove [sweep] (give the move family in [tune] distances_mm)",
        ));
    }
    let mut base = runs
        .first()
        .cloned()
        .ok_or_else(|| src.error_at("name", "the scenario has no run"))?;
    if let Some(a) = axis {
        base.axis = a.to_string();
        // The scenario's sampling was checked against the move's axis: this one's modes
        // must be seen too.
        let range = crate::expand::validate::mode_range_hz(&base);
        crate::expand::validate::validate_sampling(&base, range, src)?;
    }
    let firmware = match &spec.firmware {
        None => Candidates::ANY,
        Some(f) => Candidates::parse(f).map_err(|m| src.error_at("tune.firmware", m))?,
    };
    let firmware = match &spec.marlin_shaping {
        None => firmware,
        Some(m) => firmware.with_marlin_shaping(
            MarlinShaping::parse(m).map_err(|e| src.error_at("tune.marlin_shaping", e))?,
        ),
    };
    if let Some(cur) = spec.axis.as_ref().and_then(|m| m.get(&base.axis)) {
        let current = current_shaper(cur, base.state::<ShaperSetting>())
            .map_err(|m| src.error_at(&format!("tune.axis.{}.shaper", base.axis), m))?;
        match current {
            Some(sh) => base.put_state(Box::new(sh)),
            None => base.remove_state("shaper"),
        }
    }

    let builtin_preset = sc
        .machine
        .preset
        .as_ref()
        .filter(|p| {
            crate::input::machine_file::PRESETS
                .iter()
                .any(|(n, _, _)| n == p)
        })
        .cloned();
    let distances_mm = spec
        .distances_mm
        .clone()
        .unwrap_or_else(|| vec![base.distance_mm]);
    if distances_mm.is_empty() {
        return Err(src.error_at(
            "tune.distances_mm",
            "give one or more finite, non-zero move lengths (mm)",
        ));
    }
    for d in &distances_mm {
        // Either sign; a zero move is a sweep's baseline, not a move to tune.
        crate::spec::check_length(d.abs(), false).map_err(|m| {
            src.error_at(
                "tune.distances_mm",
                format!("each length's magnitude {m} (from {d})"),
            )
        })?;
    }
    let angles_deg = match base.state::<Corner>() {
        None if spec.angles_deg.is_some() => {
            return Err(src.error_at("tune.angles_deg", "corner angles need a [corner] scenario"));
        }
        None => Vec::new(),
        Some(c) => {
            if spec.distances_mm.is_some() {
                return Err(src.error_at(
                    "tune.distances_mm",
                    "a [corner] scenario tunes over corner angles: give `angles_deg`, not distances_mm",
                ));
            }
            let angles = spec.angles_deg.clone().unwrap_or_else(|| vec![c.angle_deg]);
            if angles.is_empty()
                || angles
                    .iter()
                    .any(|a| !(a.is_finite() && (0.0..=180.0).contains(a)))
            {
                return Err(src.error_at(
                    "tune.angles_deg",
                    "give one or more interior angles from 0 (reversal) to 180 (straight on) degrees",
                ));
            }
            angles
        }
    };
    if let Some(e) = spec.max_contour_error_um
        && !(e.is_finite() && e > 0.0)
    {
        return Err(src.error_at(
            "tune.max_contour_error_um",
            "must be a finite number > 0 (um)",
        ));
    }
    let band = spec.band_um.unwrap_or(base.bands_um[0]);
    let band_index = base
        .bands_um
        .iter()
        .position(|b| *b == band)
        .ok_or_else(|| {
            src.error_at(
                "tune.band_um",
                format!(
                    "{band} um is not one of observe.bands_um = {:?}",
                    base.bands_um
                ),
            )
        })?;
    let margin = spec.margin.unwrap_or(DEFAULT_MARGIN);
    if !(margin.is_finite() && margin > 0.0 && margin <= 1.0) {
        return Err(src.error_at(
            "tune.margin",
            format!("must be in (0, 1] (the scored band is margin x band_um), got {margin}"),
        ));
    }
    let mut bands_um = base.bands_um.clone();
    let tight = band * margin;
    let score_band_index = match bands_um.iter().position(|b| *b == tight) {
        Some(i) => i,
        None => {
            bands_um.push(tight);
            bands_um.len() - 1
        }
    };
    let kinds = match &spec.kinds {
        None => firmware.kinds(),
        Some(list) if list.is_empty() => {
            return Err(src.error_at("tune.kinds", "give at least one profile kind"));
        }
        Some(list) => list
            .iter()
            .map(|k| {
                let kind =
                    ProfileKind::parse(k).map_err(|e| src.error_at("tune.kinds", e.to_string()))?;
                firmware
                    .check_kind(kind)
                    .map(|()| kind)
                    .map_err(|m| src.error_at("tune.kinds", m))
            })
            .collect::<Result<_, _>>()?,
    };
    let shapers: Vec<Option<ShaperType>> = match &spec.shapers {
        None => std::iter::once(None)
            .chain(firmware.shapers().into_iter().map(Some))
            .collect(),
        Some(list) if list.is_empty() => {
            return Err(src.error_at(
                "tune.shapers",
                "give at least one shaper type (or \"none\")",
            ));
        }
        Some(list) => list
            .iter()
            .map(|s| {
                let k = crate::studies::shaping::parse_type(s)
                    .map_err(|m| src.error_at("tune.shapers", m))?;
                firmware
                    .check_shaper(k)
                    .map(|()| k)
                    .map_err(|m| src.error_at("tune.shapers", m))
            })
            .collect::<Result<_, _>>()?,
    };
    let accels: Vec<Option<f64>> = match &spec.accelerations_mm_s2 {
        None => vec![None],
        Some(list) => {
            if list.is_empty() {
                return Err(src.error_at(
                    "tune.accelerations_mm_s2",
                    "give one or more finite accelerations > 0 (mm/s^2)",
                ));
            }
            for a in list {
                crate::spec::check_limit(*a, crate::spec::Quantity::Acceleration).map_err(|m| {
                    src.error_at("tune.accelerations_mm_s2", format!("each acceleration {m}"))
                })?;
            }
            list.iter().copied().map(Some).collect()
        }
    };
    let max_smoothing_mm = spec.max_smoothing_mm.unwrap_or(DEFAULT_MAX_SMOOTHING_MM);
    if !(max_smoothing_mm.is_finite() && max_smoothing_mm > 0.0) {
        return Err(src.error_at("tune.max_smoothing_mm", "must be a finite number > 0 (mm)"));
    }
    let given_pct = spec.frequency_tolerance_pct;
    if let Some(p) = given_pct
        && !(p.is_finite() && (0.0..50.0).contains(&p))
    {
        return Err(src.error_at(
            "tune.frequency_tolerance_pct",
            "must be 0 to under 50 (percent)",
        ));
    }
    let identified = identified_band(&base);
    let (tolerance_pct, band_source) = frequency_band(given_pct, identified);
    let scales = spec
        .frequency_scales
        .clone()
        .unwrap_or_else(|| FREQUENCY_SCALES.to_vec());
    if scales.is_empty() || scales.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(src.error_at(
            "tune.frequency_scales",
            "give one or more finite multiples > 0 of the mode frequency",
        ));
    }
    if spec.refine_rounds.is_some_and(|r| r > 20) {
        return Err(src.error_at("tune.refine_rounds", "must be 0 to 20"));
    }
    if let Some(hz) = spec.tmc_clock_hz
        && !(4_000_000..=32_000_000).contains(&hz)
    {
        return Err(src.error_at(
            "tune.tmc_clock_hz",
            format!("{hz} Hz: the TMC4361A takes a clock of 4 to 32 MHz (4000000 to 32000000)"),
        ));
    }
    check_usteps(&spec, src)?;
    let mut notes: Vec<String> = Vec::new();
    let tmc = match firmware.firmware() {
        Some(Firmware::Tmc4361a) => {
            let usteps = spec
                .axis
                .as_ref()
                .and_then(|m| m.get(&base.axis))
                .and_then(|a| a.usteps_per_mm)
                .or(spec.usteps_per_mm)
                .ok_or_else(|| {
                    src.error_at(
                        "tune.usteps_per_mm",
                        format!(
                            "firmware tmc4361a searches only what the chip's registers hold, which depends on the axis's resolution: give [tune.axis.{}] usteps_per_mm or [tune] usteps_per_mm (microsteps per mm)",
                            base.axis
                        ),
                    )
                })?;
            let clock = spec
                .tmc_clock_hz
                .unwrap_or(super::export::DEFAULT_TMC_CLOCK_HZ);
            let r = target::tmc_ranges(usteps, clock);
            for (key, a) in std::iter::once(("limits.amax_mm_s2", base.amax_mm_s2)).chain(
                accels
                    .iter()
                    .flatten()
                    .map(|a| ("tune.accelerations_mm_s2", *a)),
            ) {
                if a > r.accel_mm_s2 {
                    return Err(src.error_at(
                        key,
                        format!(
                            "{a} mm/s^2 is more than the TMC4361A's AMAX holds at {usteps} microsteps/mm ({:.0} mm/s^2)",
                            r.accel_mm_s2
                        ),
                    ));
                }
            }
            if base.vmax_mm_s > r.speed_mm_s {
                return Err(src.error_at(
                    "limits.vmax_mm_s",
                    format!(
                        "{} mm/s is more than the TMC4361A's VMAX holds at {usteps} microsteps/mm ({:.0} mm/s)",
                        base.vmax_mm_s, r.speed_mm_s
                    ),
                ));
            }
            Some((usteps, r))
        }
        _ => None,
    };
    let jmax = match base.jmax_mm_s3 {
        Some(j) => match tmc {
            Some((usteps, r)) if j > r.jerk_mm_s3.1 => {
                notes.push(format!(
                    "Jerks searched up to {:.0} mm/s^3, not the scenario's {j}: the most the TMC4361A's BOW1..4 registers hold at {usteps} microsteps/mm.",
                    r.jerk_mm_s3.1
                ));
                r.jerk_mm_s3.1
            }
            _ => j,
        },
        // Only trapezoids: no jerk to search.
        None if kinds.iter().all(|k| *k == ProfileKind::Trapezoid) => 0.0,
        None => {
            return Err(src.error_at(
                "limits",
                "settle tune needs `jmax_mm_s3` in [limits]: the machine's jerk limit bounds the jerk search",
            ));
        }
    };
    let steps = spec.jerk_steps.unwrap_or(6);
    if !(1..=100).contains(&steps) {
        return Err(src.error_at("tune.jerk_steps", "must be 1 to 100"));
    }
    let span = spec.jerk_span.unwrap_or(30.0);
    if !(span.is_finite() && span >= 1.0) {
        return Err(src.error_at("tune.jerk_span", "must be a finite number >= 1"));
    }
    let lowest_jerk = tmc.map_or(0.0, |(_, r)| r.jerk_mm_s3.0);
    let mut jerks: Vec<f64> = (0..steps)
        .map(|i| {
            if steps == 1 {
                jmax
            } else {
                let f = i as f64 / (steps - 1) as f64;
                (jmax / span.powf(1.0 - f)).max(lowest_jerk)
            }
        })
        .collect();
    jerks.dedup();
    // The jerks searched are the scenario's limit divided by up to jerk_span: each within
    // the range of a jerk, as the limit is (a TMC4361A's lowest BOW register is within it).
    if let Some(j) = jerks.iter().find(|j| **j > 0.0) {
        crate::spec::check_limit(*j, crate::spec::Quantity::Jerk).map_err(|m| {
            src.error_at(
                "tune.jerk_span",
                format!("the lowest jerk searched, jmax_mm_s3 / jerk_span = {j:e} mm/s^3, {m}"),
            )
        })?;
    }
    let modes = tuning_modes(&base);
    if modes.is_empty() && shapers.iter().any(Option::is_some) {
        return Err(src.error_at(
            "machine",
            "found no vibration mode of the moving axis to tune shapers to",
        ));
    }
    if let Some(z) = spec.shaper_damping_ratio
        && !(z.is_finite() && (0.0..1.0).contains(&z))
    {
        return Err(src.error_at(
            "tune.shaper_damping_ratio",
            format!("must be 0 to under 1, got {z}"),
        ));
    }
    let (fixed_damping, damping_source) = design_damping_source(&spec, &base);
    let mut shaper_settings: Vec<Option<ShaperSetting>> = Vec::new();
    // The frequencies left out: outside what the firmware runs.
    let mut outside: Vec<f64> = Vec::new();
    for s in &shapers {
        match s {
            None => shaper_settings.push(None),
            Some(k) => {
                for (f, zeta) in &modes {
                    // Designed for the mode's own damping (or the fixed one), as far as
                    // the firmware takes it.
                    let (damping_ratio, moved) =
                        target::design_damping(*k, fixed_damping.unwrap_or(*zeta));
                    if let Some(why) = moved {
                        let note = format!(
                            "{} is designed for damping {damping_ratio} on the {f:.1} Hz mode: {why}.",
                            k.name()
                        );
                        if !notes.contains(&note) {
                            notes.push(note);
                        }
                    }
                    for x in &scales {
                        // To 0.1 Hz, as firmware configurations write it (Klipper's
                        // calibrate_shaper.py prints `%.1f`): the exported value is the
                        // simulated one.
                        let s = ShaperSetting {
                            shaper_type: Some(*k),
                            frequency_hz: (f * x * 10.0).round() / 10.0,
                            damping_ratio,
                        };
                        let max = crate::input::modes::MAX_FREQUENCY_HZ;
                        if s.frequency_hz > max {
                            return Err(src.error_at(
                                "tune.frequency_scales",
                                format!(
                                    "{x} times the {f:.1} Hz mode is a shaper of {} Hz, above {max} Hz, the fastest mode a machine may have: give multiples that keep every shaper at or below it (the default is 0.8 to 1.2)",
                                    s.frequency_hz
                                ),
                            ));
                        }
                        // A frequency the firmware would clamp is not what it runs.
                        if !firmware.takes_frequency(s.frequency_hz) {
                            outside.push(s.frequency_hz);
                            continue;
                        }
                        if !shaper_settings.contains(&Some(s)) {
                            shaper_settings.push(Some(s));
                        }
                    }
                }
            }
        }
    }
    if let (Some((lo, hi)), Some(min), Some(max)) = (
        firmware.frequency_range(),
        outside.iter().copied().reduce(f64::min),
        outside.iter().copied().reduce(f64::max),
    ) {
        notes.push(format!(
            "Prusa-Firmware-Buddy runs shapers of {lo} to {hi} Hz only (M593 F; it clamps others): shapers at {min} to {max} Hz left out."
        ));
    }
    let per_shape = shaper_settings.len() * accels.len();
    let count: usize = 1 + kinds
        .iter()
        .map(|&k| {
            let jerks_n = if k == ProfileKind::Trapezoid {
                1
            } else {
                jerks.len()
            };
            let params_n = match k {
                _ if base.state::<Corner>().is_some() => 1,
                ProfileKind::PvtAsym => PVT_KI.len(),
                ProfileKind::FourJerk => BOW_PATTERNS.len(),
                _ => 1,
            };
            jerks_n * params_n * per_shape
        })
        .sum::<usize>();
    if count > MAX_CANDIDATES {
        return Err(src.error_at(
            "tune",
            format!(
                "{count} candidates (kinds x jerks x kind parameters x shapers x frequencies x accelerations); at most {MAX_CANDIDATES}: give fewer values"
            ),
        ));
    }
    let default = Candidate::of(&base);
    let mut candidates = vec![default];
    for kind in kinds {
        let jerk_list: Vec<Option<f64>> = if kind == ProfileKind::Trapezoid {
            vec![None]
        } else {
            jerks.iter().copied().map(Some).collect()
        };
        let params: Vec<ProfileParams> = match kind {
            // Corner paths plan their legs from the limits alone.
            _ if base.state::<Corner>().is_some() => vec![ProfileParams::default()],
            ProfileKind::PvtAsym => PVT_KI
                .iter()
                .map(|&k| ProfileParams {
                    pvt_asym_ki: k,
                    ..ProfileParams::default()
                })
                .collect(),
            ProfileKind::FourJerk => BOW_PATTERNS
                .iter()
                .map(|&b| ProfileParams {
                    fourjerk_jerk_scale: b,
                    ..ProfileParams::default()
                })
                .collect(),
            _ => vec![ProfileParams::default()],
        };
        for j in &jerk_list {
            for p in &params {
                for sh in &shaper_settings {
                    for a in &accels {
                        candidates.push(Candidate {
                            kind,
                            jmax_mm_s3: *j,
                            params: *p,
                            shaper: *sh,
                            amax_mm_s2: *a,
                        });
                    }
                }
            }
        }
    }
    let modes_source = modes_source(&base, builtin_preset.as_deref());
    Ok(Plan {
        base,
        distances_mm,
        angles_deg,
        band_index,
        score_band_index,
        margin,
        bands_um,
        candidates,
        modes,
        spec,
        frequency_tolerance: tolerance_pct / 100.0,
        band_source,
        max_smoothing_mm,
        firmware,
        notes,
        modes_source,
        builtin_preset,
        damping_source,
        shaper_damping: fixed_damping,
    })
}

/// The damping ratio the shapers are designed for when it is one for all (`None`: each
/// mode's own), and the report's sentence saying which and why: `[tune]
/// shaper_damping_ratio`, else the modes' own on a machine given by its modes, else
/// Klipper's default 0.1 (a physical machine's modal damping is an estimate from its
/// parts).
pub fn design_damping_source(
    spec: &crate::input::tune_spec::TuneSpec,
    base: &RunSpec,
) -> (Option<f64>, String) {
    match (spec.shaper_damping_ratio, base.machine.physical()) {
        (Some(z), _) => (
            Some(z),
            format!("Shapers are designed for damping ratio {z} (`[tune] shaper_damping_ratio`)."),
        ),
        (None, Some(_)) => (
            Some(DEFAULT_DAMPING_RATIO),
            format!(
                "Shapers are designed for Klipper's default damping ratio {DEFAULT_DAMPING_RATIO}: the damping of a physical machine's linearised modes is an estimate from its parts, not a measurement (`[tune] shaper_damping_ratio` sets another)."
            ),
        ),
        (None, None) => (
            None,
            "Shapers are designed for the damping ratio of the mode they are tuned to (the machine's, not Klipper's default 0.1).".into(),
        ),
    }
}

/// Where the modes of `base`'s machine come from, in a few words: identified (the modes
/// carry their standard deviations, as `settle identify` writes them), given, or
/// linearised from a physical machine (`preset`: the built-in preset it is).
pub fn modes_source(base: &RunSpec, preset: Option<&str>) -> String {
    let name = &base.machine_name;
    let identified = base.axis.split('+').any(|a| {
        base.machine
            .modes_of(a)
            .iter()
            .any(|m| m.frequency_sigma_hz.is_some())
    });
    match (base.machine.physical(), preset) {
        (Some(_), Some(p)) => format!("linearised from the built-in preset `{p}`"),
        (Some(_), None) => format!("linearised from the machine `{name}`"),
        (None, _) if identified => format!("identified, machine `{name}`"),
        (None, Some(p)) => format!("given by the built-in preset `{p}`"),
        (None, None) => format!("given, machine `{name}`"),
    }
}

/// The band (percent) a search scores its shapers over and where it came from: the
/// larger of the given tolerance and the identified band (`(percent, frequency_hz,
/// sigma_hz)`, [`identified_band`]). Both bound how far the real mode may lie from the
/// shaper's frequency: the identified band what the measurement cannot rule out, the
/// given one what the user knows beyond it (the frequency moving with the toolhead's
/// position, load or temperature), so a winner must hold over the wider. Without either,
/// no band.
pub fn frequency_band(
    given_pct: Option<f64>,
    identified: Option<(f64, f64, f64)>,
) -> (f64, BandSource) {
    match (given_pct, identified) {
        (None, None) => (0.0, BandSource::None),
        (Some(p), None) => (
            p,
            if p > 0.0 {
                BandSource::Given
            } else {
                BandSource::None
            },
        ),
        (None, Some((p, f, s))) => (p, BandSource::Identified(f, s)),
        (Some(g), Some((p, f, s))) if g >= p => (g, BandSource::GivenOverIdentified(f, s)),
        (Some(_), Some((p, f, s))) => (p, BandSource::Identified(f, s)),
    }
}

/// Largest identified band allowed (percent), as for `frequency_tolerance_pct`.
pub const MAX_BAND_PCT: f64 = 49.0;

/// The identified frequency band of the modes the shapers are tuned to
/// ([`tuning_modes`] of a machine given by its modes, each with `frequency_sigma_hz`):
/// the widest `2 sigma / f` among them, as `(percent, frequency_hz, sigma_hz)` (at most
/// [`MAX_BAND_PCT`]). Two standard deviations: the interval that covers the true
/// frequency in 95 % of identifications when the sigmas are right (they are checked so
/// in settle-identify's `random_sweeps_from_env`). `None` without sigmas or for a
/// physical machine.
pub fn identified_band(base: &RunSpec) -> Option<(f64, f64, f64)> {
    if base.machine.physical().is_some() {
        return None;
    }
    let tuned = tuning_modes(base);
    let mut best: Option<(f64, f64, f64)> = None;
    for name in base.axis.split('+') {
        for m in base.machine.modes_of(name) {
            let Some(s) = m.frequency_sigma_hz else {
                continue;
            };
            let f = m.frequency_hz;
            if !tuned.iter().any(|(g, _)| (g - f).abs() < 1e-6 * f) {
                continue;
            }
            let pct = (200.0 * s / f).min(MAX_BAND_PCT);
            if best.is_none_or(|b| pct > b.0) {
                best = Some((pct, f, s));
            }
        }
    }
    best
}

/// An axis's current shaper from `[tune.axis.<name>]`, the scenario's `[shaper]` filling
/// what it leaves out; `None` for no shaping.
fn current_shaper(
    cur: &crate::input::tune_spec::AxisCurrent,
    scenario: Option<&ShaperSetting>,
) -> Result<Option<ShaperSetting>, String> {
    let kind = match &cur.shaper {
        Some(name) => crate::studies::shaping::parse_type(name)?,
        None => scenario.and_then(|s| s.shaper_type),
    };
    let Some(kind) = kind else {
        return Ok(None);
    };
    let s = ShaperSetting {
        shaper_type: Some(kind),
        frequency_hz: cur
            .frequency_hz
            .or(scenario.map(|s| s.frequency_hz))
            .ok_or("a current shaper needs `frequency_hz`")?,
        damping_ratio: cur
            .damping_ratio
            .or(scenario.map(|s| s.damping_ratio))
            .unwrap_or(DEFAULT_DAMPING_RATIO),
    };
    s.validate().map_err(|(_, m)| m)?;
    Ok(Some(s))
}

/// The modes shapers are tuned to: the moving axis's modes (by weight, at most two; a
/// corner path: the strongest of each of its axes), or the two strongest modes of the
/// moving axis's linearised response.
pub fn tuning_modes(base: &RunSpec) -> Vec<(f64, f64)> {
    let Some(machine) = base.machine.physical() else {
        let names: Vec<&str> = base.axis.split('+').collect();
        let per_axis = if names.len() > 1 { 1 } else { 2 };
        let mut out: Vec<(f64, f64)> = Vec::new();
        for name in names {
            let mut m: Vec<_> = base.machine.modes_of(name).to_vec();
            m.sort_by(|a, b| b.weight.abs().total_cmp(&a.weight.abs()));
            for m in m.iter().take(per_axis) {
                let f = m.frequency_hz;
                if !out.iter().any(|(g, _)| (g - f).abs() < 1e-6 * f) {
                    out.push((f, m.damping_ratio));
                }
            }
        }
        return out;
    };
    let Ok(axes) = machine.compile(settle_sim::DriverMode::Linear) else {
        return Vec::new();
    };
    let Ok(limits) = base.limits_si() else {
        return Vec::new();
    };
    // The moving axis, or both axes of a corner path (its strongest mode each).
    let names: Vec<&str> = base.axis.split('+').collect();
    let per_axis = if names.len() > 1 { 1 } else { 2 };
    let mut out: Vec<(f64, f64)> = Vec::new();
    for name in names {
        let Some(axis) = axes.iter().find(|a| a.name == name) else {
            continue;
        };
        let (start_m, dist_m) = if base.state::<Corner>().is_some() {
            (0.0, 0.02)
        } else {
            (base.start_mm * 1e-3, base.distance_mm * 1e-3)
        };
        let Ok(profile) = base.profile.rest_to_rest(start_m, dist_m, &limits) else {
            continue;
        };
        let Ok(lr) = settle_sim::closed_form::LinearResponse::new(axis, &profile) else {
            continue;
        };
        for (f, z, _) in lr
            .modes()
            .into_iter()
            .filter(|(f, _, _)| *f > 0.5)
            .take(per_axis)
        {
            if !out.iter().any(|(g, _)| (g - f).abs() < 1e-6 * f) {
                out.push((f, z));
            }
        }
    }
    out
}

/// Fewest and most microsteps per mm `[tune] usteps_per_mm` and `[tune.axis.<name>]
/// usteps_per_mm` may give: settle-gcode's [`settle_gcode::config::MICROSTEPS_PER_MM`], 1
/// to 1e9, the range a firmware configuration is read with. The TMC4361A's registers
/// count microsteps, so every range of the search and every register of the export
/// scales with it: 0 or NaN gave a whole search and then no register file, -100 a
/// negative AMAX blamed on `limits.amax_mm_s2`, and 1e-6 a VMAX that rounds to 0.
pub const USTEPS_PER_MM: (f64, f64) = settle_gcode::config::MICROSTEPS_PER_MM;

/// Refuse a `usteps_per_mm` of `spec` outside [`USTEPS_PER_MM`], naming its key, before
/// any work.
fn check_usteps(spec: &crate::input::tune_spec::TuneSpec, src: &Source) -> Result<(), Error> {
    let (lo, hi) = USTEPS_PER_MM;
    let axes = spec.axis.iter().flatten();
    let given = std::iter::once(("tune.usteps_per_mm".to_string(), spec.usteps_per_mm))
        .chain(axes.map(|(name, a)| (format!("tune.axis.{name}.usteps_per_mm"), a.usteps_per_mm)));
    for (key, v) in given {
        if let Some(v) = v
            && !(lo..=hi).contains(&v)
        {
            return Err(src.error_at(
                &key,
                format!(
                    "{v} microsteps per mm: allowed {lo} to {hi:e} (the axis's full steps per mm times its microstepping)"
                ),
            ));
        }
    }
    Ok(())
}
