//! RepRapFirmware's M593 shapers as src/Movement/AxisShaper.cpp (`AxisShaper::Configure`,
//! 3.6 line: 3.6-dev at 8875b7ec447dd29399433711d6b686d4ad587318) computes them:
//! amplitudes that sum to one (the last is `1 - sum` of the others) and delays in whole
//! step-clock ticks.
//!
//! With `s = sqrt(1 - zeta^2)`, `k = expf(-zeta pi / s)` and the damped period in ticks
//! `P = lrintf(step_clock / (f s))`:
//! - `zvd` `[1, 2k, k^2] / (1+k)^2` at `[0, P/2, P]`; `zvdd` `[1, 3k, 3k^2, k^3] / (1+k)^3`
//!   at `[0, P/2, P, 3P/2]`; `zvddd` `[1, 4k, 6k^2, 4k^3, k^4] / (1+k)^4` at
//!   `[0, P/2, P, 3P/2, 2P]` (integer divisions of `P`);
//! - `mzv`: Klipper's classic amplitudes `a1 = 1 - sqrt2/2`, `a2 = (sqrt2 - 1) k_m`,
//!   `a3 = a1 k_m^2` (`k_m = exp(-0.75 zeta pi / s)`), normalised, but applied in the order
//!   `[a3, a2, a1]` at `[0, 3P/8, 2 (3P/8)]`: for `zeta > 0` the decaying impulses come
//!   first, so unlike Klipper's MZV it does not cancel the mode it is tuned to exactly;
//! - `ei2`, `ei3`: the same damping cubics as Klipper's `2hump_ei`/`3hump_ei`, but the
//!   times are fractions of the damped period `P` (Klipper: of `1/f`) and the last
//!   amplitude is `1 - sum` of the others (Klipper normalises by the sum). Klipper stops
//!   these cubics at damping 0.3 and 0.2 (`max_damping_ratio`); M593 takes `S` to 0.99
//!   and evaluates them there too. From about 0.41 (`ei3`) and 0.47 (`ei2`) their delays
//!   are no longer increasing (`M593 P"ei3" F40 S0.5`: 0, 49566, 75373, 68758, 58195
//!   ticks), and amplitudes turn negative (there: 1.138, 0.505, -0.314, -0.272, -0.056).
//!   The firmware runs them as they are: `Move::AddLinearSegments` (src/Movement/Move.cpp)
//!   adds each impulse's scaled copy of a move at its own delay through
//!   `Move::AddSegment`, which merges the copy into the time-ordered segment list wherever
//!   it starts, so the motion is the sum of the copies in whatever order the delays come.
//!   This file gives the same sum in time order: the impulses sorted by delay, and those
//!   at the same tick (they occur, e.g. `ei3` at 100 Hz and S0.5629) added into one.
//!
//! Single precision where the firmware uses `float`, so `P` and the delays round as on the
//! board; `lrintf` rounds half to even.

use super::shaper_type::Impulses;
use super::shaper_type::RrfShaper;

/// `lrintf` of a value the firmware computes in double precision and passes as float.
fn lrintf(x: f64) -> i64 {
    (x as f32).round_ties_even() as i64
}

pub(super) fn impulses(shaper: RrfShaper, f_hz: f64, zeta: f64, step_clock_hz: u32) -> Impulses {
    let z = zeta as f32;
    let s = (1.0f32 - z * z).sqrt();
    let damped_frequency = f_hz as f32 * s;
    let p = lrintf(f64::from(step_clock_hz as f32 / damped_frequency));
    let k = (-z * std::f32::consts::PI / s).exp();
    let k64 = f64::from(k);
    let zd = f64::from(z);
    // `zetaSquared` and `zetaCubed` are floats; the polynomials are double expressions.
    let (z2, z3) = (f64::from(z * z), f64::from(z * z * z));
    let poly = |c: [f64; 4]| c[0] + c[1] * zd + c[2] * z2 + c[3] * z3;
    // Amplitudes of all impulses but the last, and the delays (ticks) of all.
    let (mut a, delays): (Vec<f64>, Vec<i64>) = match shaper {
        RrfShaper::Zvd => {
            let j = f64::from((1.0 + k) * (1.0 + k));
            (vec![1.0 / j, 2.0 * k64 / j], vec![0, p / 2, p])
        }
        RrfShaper::Zvdd => {
            let j = f64::from((1.0 + k) * (1.0 + k) * (1.0 + k));
            (
                vec![1.0 / j, 3.0 * k64 / j, 3.0 * f64::from(k * k) / j],
                vec![0, p / 2, p, 3 * p / 2],
            )
        }
        RrfShaper::Zvddd => {
            let sq = (1.0 + k) * (1.0 + k);
            let j = f64::from(sq * sq);
            (
                vec![
                    1.0 / j,
                    4.0 * k64 / j,
                    6.0 * f64::from(k * k) / j,
                    4.0 * f64::from(k * k * k) / j,
                ],
                vec![0, p / 2, p, 3 * p / 2, 2 * p],
            )
        }
        RrfShaper::Mzv => {
            // `expf(-zeta * 0.75 * Pi / s)`: a double expression passed as float.
            let k_mzv = (-zd * 0.75 * f64::from(std::f32::consts::PI) / f64::from(s)) as f32;
            let k_mzv = k_mzv.exp();
            let sqrt2 = 2.0f32.sqrt();
            let a1 = (1.0 - 0.5 * f64::from(sqrt2)) as f32;
            let a2 = ((f64::from(sqrt2) - 1.0) * f64::from(k_mzv)) as f32;
            let a3 = a1 * (k_mzv * k_mzv);
            let sum = a1 + a2 + a3;
            let d1 = (3 * p) / 8;
            (
                vec![f64::from(a3 / sum), f64::from(a2 / sum)],
                vec![0, d1, 2 * d1],
            )
        }
        RrfShaper::Ei2 => {
            let a = [
                [0.16054, 0.76699, 2.26560, -1.22750],
                [0.33911, 0.45081, -2.58080, 1.73650],
                [0.34089, -0.61533, -0.68765, 0.42261],
            ];
            let t = [
                [0.49890, 0.16270, -0.54262, 6.16180],
                [0.99748, 0.18382, -1.58270, 8.17120],
                [1.49920, -0.09297, -0.28338, 1.85710],
            ];
            let pf = f64::from(p as f32);
            (
                a.iter().map(|c| f64::from(poly(*c) as f32)).collect(),
                std::iter::once(0)
                    .chain(t.iter().map(|c| lrintf(poly(*c) * pf)))
                    .collect(),
            )
        }
        RrfShaper::Ei3 => {
            let a = [
                [0.11275, 0.76632, 3.29160, -1.44380],
                [0.23698, 0.61164, -2.57850, 4.85220],
                [0.30008, -0.19062, -2.14560, 0.13744],
                [0.23775, -0.73297, 0.46885, -2.08650],
            ];
            let t = [
                [0.49974, 0.23834, 0.44559, 12.4720],
                [0.99849, 0.29808, -2.36460, 23.3990],
                [1.49870, 0.10306, -2.01390, 17.0320],
                [1.99960, -0.28231, 0.61536, 5.40450],
            ];
            let pf = f64::from(p as f32);
            (
                a.iter().map(|c| f64::from(poly(*c) as f32)).collect(),
                std::iter::once(0)
                    .chain(t.iter().map(|c| lrintf(poly(*c) * pf)))
                    .collect(),
            )
        }
    };
    // "The sum of the coefficients must total 1, use this to fill in the last coefficient."
    let sum: f64 = a.iter().sum();
    a.push(1.0 - sum);
    let clock = f64::from(step_clock_hz);
    let (a, delays) = in_time_order(a, delays);
    (a, delays.into_iter().map(|d| d as f64 / clock).collect())
}

/// The impulses `(amplitudes, delays)` sorted by delay (a stable sort: increasing delays
/// are left as they are), those at the same delay added into one: the train the firmware's
/// sum of delayed copies amounts to (module doc).
fn in_time_order(amplitudes: Vec<f64>, delays: Vec<i64>) -> (Vec<f64>, Vec<i64>) {
    let mut train: Vec<(i64, f64)> = delays.into_iter().zip(amplitudes).collect();
    train.sort_by_key(|&(d, _)| d);
    let mut merged: Vec<(i64, f64)> = Vec::with_capacity(train.len());
    for (d, a) in train {
        match merged.last_mut() {
            Some((d0, a0)) if *d0 == d => *a0 += a,
            _ => merged.push((d, a)),
        }
    }
    merged.into_iter().map(|(d, a)| (a, d)).unzip()
}
