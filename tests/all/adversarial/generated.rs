//! Generated cases (seeded, so a failure is repeatable; `SETTLE_ADVERSARIAL_CASES` sets
//! how many of each family, default 24, `SETTLE_ADVERSARIAL_SEED` the seed): extreme values
//! (0, negatives, 1e-300, 1e300, infinities, NaN, random magnitudes) for the numeric keys
//! of a scenario and the numeric options of `gcode` and `identify`, and `settle plan`
//! problems of extreme numbers; and the file classes of [`super::generated_files`]. Every
//! case keeps the invariants (no panic, no hang, no write outside its output, under 1
//! GiB); an option outside its documented range must be refused (exit 2), one inside it
//! answered; an answered run prints no NaN.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::params::scenario_with;
use super::{Case, Expect, Sandbox, check_all};

/// Cases per family.
fn count() -> usize {
    std::env::var("SETTLE_ADVERSARIAL_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(24)
}

fn rng() -> ChaCha8Rng {
    let seed = std::env::var("SETTLE_ADVERSARIAL_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(29);
    ChaCha8Rng::seed_from_u64(seed)
}

/// An extreme or random number, as TOML writes it.
fn extreme(r: &mut ChaCha8Rng) -> String {
    const FIXED: [&str; 12] = [
        "0.0", "-1.0", "1e-300", "-1e-300", "1e300", "-1e300", "inf", "-inf", "nan", "1e15",
        "1e-9", "4.9e-324",
    ];
    if r.random_bool(0.6) {
        FIXED[r.random_range(0..FIXED.len())].to_string()
    } else {
        let sign = if r.random_bool(0.2) { "-" } else { "" };
        format!("{sign}{:e}", 10f64.powf(r.random_range(-12.0..12.0)))
    }
}

/// The numeric keys of the sandbox's scenario, as written there.
const KEYS: [&str; 9] = [
    "distance_mm = 5.0",
    "vmax_mm_s = 300.0",
    "amax_mm_s2 = 3000.0",
    "jmax_mm_s3 = 100000.0",
    "window_s = 0.2",
    "sample_rate_hz = 2000",
    "frequency_hz = 40.0",
    "damping_ratio = 0.05",
    "[observe]",
];

/// `settle run` of the scenario with one key at an extreme value.
fn scenario_cases(sb: &Sandbox, r: &mut ChaCha8Rng, n: usize) -> Vec<Case> {
    (0..n)
        .map(|i| {
            let key = KEYS[r.random_range(0..KEYS.len())];
            let v = extreme(r);
            let text = if key == "[observe]" {
                // Keys the scenario does not set: a start, a step, a shaper.
                let extra = match r.random_range(0..3) {
                    0 => format!("[sim]\nmax_step_s = {v}\n[observe]"),
                    1 => format!("[shaper]\ntype = \"mzv\"\nfrequency_hz = {v}\n[observe]"),
                    _ => "[observe]".to_string(),
                };
                let text = scenario_with("[observe]", &extra);
                if extra == "[observe]" {
                    text.replacen(
                        "distance_mm = 5.0",
                        &format!("distance_mm = 1.0\nstart_mm = {v}"),
                        1,
                    )
                } else {
                    text
                }
            } else {
                let name = key.split(" = ").next().unwrap_or(key);
                scenario_with(key, &format!("{name} = {v}"))
            };
            let file = format!("gen{i}.toml");
            sb.write(&file, &text);
            let out = format!("gen{i}");
            let t = format!("{out}/t.csv");
            Case::new(
                &format!("run, {} = {v}", key.split(" = ").next().unwrap_or(key)),
                &[
                    "run",
                    &file,
                    "--case",
                    "0",
                    "--backend",
                    "modal",
                    "--out",
                    &t,
                ],
                &[&out],
                Expect::AnyExit,
            )
        })
        .collect()
}

/// `settle gcode` at a generated sample rate: refused under twice the machine's fastest
/// mode (354 Hz, printer_xy's rotor) or over 100 kHz, answered between.
fn gcode_cases(r: &mut ChaCha8Rng, n: usize) -> Vec<Case> {
    (0..n)
        .map(|i| {
            let rate: f64 = if r.random_bool(0.3) {
                r.random_range(720.0..5000.0)
            } else {
                10f64.powf(r.random_range(-9.0..12.0))
            };
            let text = format!("{rate:e}");
            let out = format!("gc{i}");
            let expect = if !(700.0..=1e5).contains(&rate) {
                Expect::refused(&["--sample-rate-hz"])
            } else if rate > 710.0 && rate <= 5000.0 {
                Expect::answered(&[])
            } else {
                Expect::AnyExit
            };
            Case::new(
                &format!("gcode --sample-rate-hz {text}"),
                &[
                    "gcode",
                    "print.gcode",
                    "--machine",
                    "printer_xy",
                    "--sample-rate-hz",
                    &text,
                    "--out",
                    &out,
                ],
                &[&out],
                expect,
            )
        })
        .collect()
}

/// `settle identify` at a generated `--freq-start`: refused outside 1..300 Hz.
fn identify_cases(r: &mut ChaCha8Rng, n: usize) -> Vec<Case> {
    (0..n)
        .map(|i| {
            let v = extreme(r);
            let f: f64 = v.parse().unwrap_or(f64::NAN);
            let expect = if f.is_finite() && (1.0..295.0).contains(&f) {
                Expect::AnyExit
            } else {
                Expect::refused(&["--freq-start"])
            };
            let out = format!("id{i}");
            let m = format!("{out}/m.toml");
            Case::new(
                &format!("identify --freq-start {v}"),
                &[
                    "identify",
                    "rec_x.csv",
                    "--freq-start",
                    &v,
                    "--freq-end",
                    "300",
                    "--out",
                    &m,
                ],
                &[&out],
                expect,
            )
        })
        .collect()
}

/// `settle plan`: problems of extreme numbers, every line answered.
fn plan_case(r: &mut ChaCha8Rng, n: usize) -> Case {
    let mut input = String::new();
    for _ in 0..n {
        let mut num = || {
            let v = extreme(r);
            // JSON has no inf or NaN: those become a string, an error to answer.
            if v.parse::<f64>().is_ok_and(f64::is_finite) {
                v
            } else {
                format!("\"{v}\"")
            }
        };
        input.push_str(&format!(
            "{{\"p0\":[{}],\"pf\":[{}],\"vmax\":[{}],\"amax\":[{}],\"jmax\":[{}]}}\n",
            num(),
            num(),
            num(),
            num(),
            num()
        ));
    }
    Case::new(
        &format!("plan, {n} extreme problems"),
        &["plan"],
        &[],
        Expect::answered(&[]),
    )
    .stdin(input)
}

#[test]
#[ignore = "the generated cases of the adversarial suite: scripts/adversarial.sh runs them"]
fn generated_cases_keep_every_invariant() {
    let sb = Sandbox::new();
    let mut r = rng();
    let n = count();
    let mut cases = scenario_cases(&sb, &mut r, n);
    cases.extend(gcode_cases(&mut r, n));
    cases.extend(identify_cases(&mut r, n));
    cases.push(plan_case(&mut r, 10 * n));
    cases.extend(super::generated_files::output_cases(&sb, &mut r, n));
    cases.extend(super::generated_files::input_cases(&mut r, n));
    cases.extend(super::generated_files::gcode_text_cases(&sb, &mut r, n));
    check_all(&sb, &cases);
}
