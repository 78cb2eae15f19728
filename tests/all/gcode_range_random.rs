//! A layer range gives the numbers of the same layers in the whole run, on random cases:
//! machines of both forms (physical, with every damping ratio drawn from 0.01-0.3, and
//! one or two modes per axis at 0.01-0.3), no shaper or one of Klipper's, each firmware's
//! planner, small random files of a few layers, random ranges, on the modal and the
//! rapier backends; and the `[gcode]` study's range equals `settle gcode`'s (Klipper).
//!
//! Why they agree: the range starts at rest in the commanded state of its pre-roll,
//! `ln(1e6) / sigma` before its first move (`sigma` the slowest decay rate of the
//! machine's linearised modes), and the difference of the two runs is a free vibration
//! of the (linear) model from the deflection the whole run has there. It has decayed by
//! 1e-6, times a constant of the modes' eigenvectors, when the range starts: a few
//! hundred um of deflection leaves well under 1e-3 um. Rapier follows the belt's
//! stiffness along the travel (slightly nonlinear) and steps with its own substeps; the
//! same decay holds there. The stated tolerance is 1e-3 um, plus 1e-6 of the error (the
//! decayed difference relative to what the whole run carries); the 95th percentile is a
//! histogram bin's edge (equal bins or neighbours).
//!
//! Random case count: `SETTLE_GCODE_RANGE_CASES` (default 4; each case runs the whole
//! file and the range on both backends). Checked to fail on the code that forgot the
//! range's last moves once the planner's look-ahead ran past the range (with a short
//! pre-roll, high damping, a layer of the range was measured against no move and went
//! uncounted), on the rapier plant that sized its step where each run started (a range
//! starting elsewhere on the belt stepped differently: 1 % apart in 40 cases), and on the
//! study that sampled a shaped whole file off the print clock's grid (3 % apart).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle::spec::backend::Backend;
use settle::studies::gcode::stats::LayerStats;
use settle::workflows::gcode::{GcodeOptions, GcodeOutcome, measure, parse_shaper};
use settle_planner::firmware::Firmware;

use crate::support::{extra, write};

fn cases() -> usize {
    std::env::var("SETTLE_GCODE_RANGE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4)
}

/// A small print: `layers` layers (markers `;LAYER_CHANGE`, layer 1 the first), each a
/// travel to a random polygon of 3-6 corners within 30 mm of the origin, printed at one
/// random feed; the first layer on a skirt-like travel from the origin.
fn random_file(rng: &mut ChaCha8Rng, layers: u32) -> String {
    let feed = rng.random_range(60.0..250.0_f64) * 60.0;
    let mut s = String::from("G90\nM83\nG1 Z0.3 F600\n");
    for l in 1..=layers {
        let z = 0.2 * f64::from(l);
        s.push_str(&format!(";LAYER_CHANGE\n;Z:{z:.1}\nG1 Z{z:.3} F600\n"));
        let corners = rng.random_range(3..=6);
        let pts: Vec<(f64, f64)> = (0..corners)
            .map(|_| (rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0)))
            .collect();
        s.push_str(&format!("G0 X{:.3} Y{:.3} F9000\n", pts[0].0, pts[0].1));
        for p in pts.iter().skip(1).chain(std::iter::once(&pts[0])) {
            s.push_str(&format!("G1 X{:.3} Y{:.3} E0.2 F{feed:.0}\n", p.0, p.1));
        }
    }
    s
}

fn damping(rng: &mut ChaCha8Rng) -> f64 {
    rng.random_range(0.01..0.3)
}

/// printer_xy's numbers (scenarios/machines/printer_xy.toml) with every damping ratio
/// drawn.
fn physical_machine(rng: &mut ChaCha8Rng) -> String {
    let mut s = format!(
        "name = \"random physical\"\n\
         [motor]\nholding_torque_n_m = 0.40\nrated_current_a = 1.7\nresistance_ohm = 1.5\n\
         inductance_mh = 2.8\nrotor_inertia_g_cm2 = 54.0\ndamping_ratio = {}\n\
         [driver]\nmicrosteps = 16\nrun_current_a_rms = 0.8\nsupply_v = 24.0\n",
        damping(rng)
    );
    for (axis, ea, extra) in [("x", 15000.0, ""), ("y", 30000.0, "beam_kg = 0.93\n")] {
        s.push_str(&format!(
            "[axis.{axis}]\ncarriage_kg = 0.15\ntoolhead_kg = 0.6\n{extra}\
             [axis.{axis}.belt]\nea_n = {ea}\nspan_mm = 350.0\npulley_teeth = 20\n\
             carriage_at_zero_mm = 175.0\ndamping_ratio = {}\n\
             [axis.{axis}.mount]\nstiffness_n_per_m = 5.0e5\ndamping_ratio = {}\n",
            damping(rng),
            damping(rng)
        ));
    }
    s.push_str(&format!(
        "[axis.y.frame]\nmass_kg = 5.0\nstiffness_n_per_m = 2.84e6\ndamping_ratio = {}\n",
        damping(rng)
    ));
    s
}

/// One or two modes per axis, 25-120 Hz, weights summing to 1.
fn modes_machine(rng: &mut ChaCha8Rng) -> String {
    let mut s = String::from("name = \"random modes\"\n");
    for axis in ["x", "y"] {
        let n = rng.random_range(1..=2);
        let w0 = if n == 1 {
            1.0
        } else {
            rng.random_range(0.3..0.9)
        };
        let modes: Vec<String> = (0..n)
            .map(|i| {
                format!(
                    "{{ frequency_hz = {}, damping_ratio = {}, weight = {} }}",
                    rng.random_range(25.0..120.0),
                    damping(rng),
                    if i == 0 { w0 } else { 1.0 - w0 }
                )
            })
            .collect();
        s.push_str(&format!("[axis.{axis}]\nmodes = [{}]\n", modes.join(", ")));
    }
    s
}

/// The account of layer `n` in `o`.
fn layer(o: &GcodeOutcome, n: u32) -> &LayerStats {
    o.layers
        .iter()
        .find(|l| l.layer == n)
        .and_then(|l| l.stats.as_ref())
        .unwrap_or_else(|| panic!("layer {n} not simulated"))
}

/// `a` and `b` agree within the stated tolerance (module doc).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-3 + 1e-6 * a.abs().max(b.abs())
}

/// Two 95th percentiles are the same histogram bin or neighbours.
fn same_bin(a: f64, b: f64) -> bool {
    a == b || (a > 0.0 && b > 0.0 && (a / b).ln().abs() / 1.001f64.ln() <= 1.0 + 1e-9)
}

#[test]
fn a_layer_range_gives_the_whole_runs_numbers_on_random_machines_and_settings() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut rng = ChaCha8Rng::seed_from_u64(0x31a);
    let firmwares = [
        Firmware::Klipper,
        Firmware::Marlin,
        Firmware::Rrf,
        Firmware::Settle,
    ];
    let shapers = ["zv", "mzv", "zvd", "ei", "2hump_ei"];
    for case in 0..cases() {
        let layers = rng.random_range(3..=4);
        let file = write(
            dir.path(),
            &format!("case{case}.gcode"),
            &random_file(&mut rng, layers),
        );
        let physical = case % 2 == 0;
        let machine_text = if physical {
            physical_machine(&mut rng)
        } else {
            modes_machine(&mut rng)
        };
        let machine = write(dir.path(), &format!("machine{case}.toml"), &machine_text);
        let firmware = firmwares[rng.random_range(0..firmwares.len())];
        let shaper = match rng.random_bool(0.75) {
            true => Some(
                parse_shaper(&format!(
                    "{}@{:.1}/{:.2}",
                    shapers[rng.random_range(0..shapers.len())],
                    rng.random_range(30.0..70.0),
                    rng.random_range(0.05..0.2)
                ))
                .expect("shaper"),
            ),
            false => None,
        };
        let a = rng.random_range(1..=layers);
        let b = rng.random_range(a..=layers);
        let what = format!(
            "case {case}: {} machine\n{machine_text}\n{firmware}, shaper {shaper:?}, layers {a}..{b}",
            if physical { "physical" } else { "modes" }
        );
        let options = |backend, range| GcodeOptions {
            backend,
            layers: range,
            ..GcodeOptions::new(file.clone(), machine.to_str().expect("utf-8"), firmware)
                .expect("options")
                .with_shaper(shaper)
        };
        for backend in [Backend::Modal, Backend::Rapier] {
            let whole = measure(&options(backend, None)).expect("whole run");
            let range = measure(&options(backend, Some((a, b)))).expect("range");
            for n in a..=b {
                let (w, r) = (layer(&whole, n), layer(&range, n));
                let at = format!("{what}, {} backend, layer {n}", backend.name());
                assert!(
                    close(w.worst_um(), r.worst_um()),
                    "{at}: worst {} (whole) vs {} (range)",
                    w.worst_um(),
                    r.worst_um()
                );
                assert!(
                    close(w.mean_move_worst_um, r.mean_move_worst_um),
                    "{at}: mean move worst {} vs {}",
                    w.mean_move_worst_um,
                    r.mean_move_worst_um
                );
                assert!(
                    same_bin(w.p95_um, r.p95_um),
                    "{at}: p95 {} vs {}",
                    w.p95_um,
                    r.p95_um
                );
                assert_eq!(w.print_moves, r.print_moves, "{at}");
                match (w.end_residual_um, r.end_residual_um) {
                    (Some(x), Some(y)) => assert!(close(x, y), "{at}: end residual {x} vs {y}"),
                    (x, y) => assert_eq!(x, y, "{at}: end residual"),
                }
            }
            // Only the range is counted.
            let counted: Vec<u32> = range
                .layers
                .iter()
                .filter(|l| l.stats.is_some())
                .map(|l| l.layer)
                .collect();
            assert_eq!(counted, (a..=b).collect::<Vec<_>>(), "{what}");
            // The `[gcode]` study gives `settle gcode`'s numbers for the range (Klipper's
            // defaults are the scenario's limits below), up to the range's last command
            // (`settle gcode` counts the ringing after the file's last move as the last
            // move's).
            if backend == Backend::Modal && firmware == Firmware::Klipper && b < layers {
                let worst = (a..=b)
                    .map(|n| layer(&whole, n).worst_um())
                    .fold(0.0, f64::max);
                let study = study_worst(dir.path(), &file, &machine_text, shaper, (a, b));
                assert!(
                    close(worst, study),
                    "{what}: study {study} vs gcode {worst}"
                );
            }
        }
    }
}

/// The `[gcode]` study's `contour_worst_um` for `file` on the machine `machine_text`
/// (a machine file's text), Klipper at 500 mm/s and 3000 mm/s^2, `shaper` on X and Y,
/// layers `a..b`, on the modal backend at 2 kHz.
fn study_worst(
    dir: &std::path::Path,
    file: &std::path::Path,
    machine_text: &str,
    shaper: Option<settle_gcode::job::ShaperSetting>,
    (a, b): (u32, u32),
) -> f64 {
    let machine = write(dir, "study_machine.toml", machine_text);
    let shaper = shaper.map_or(String::new(), |s| {
        format!(
            "[shaper]\ntype = \"{}\"\nfrequency_hz = {}\ndamping_ratio = {}\n",
            s.shaper_type.name(),
            s.frequency_hz,
            s.damping_ratio
        )
    });
    let scenario = write(
        dir,
        "study.toml",
        &format!(
            "name = \"range\"\n[machine]\npreset = {:?}\ndriver_model = \"linear\"\n\
             [gcode]\nfile = {:?}\nfirmware = \"klipper\"\nlayers = \"{a}..{b}\"\n{shaper}\
             [limits]\nvmax_mm_s = 500.0\namax_mm_s2 = 3000.0\njmax_mm_s3 = 100000.0\n\
             [observe]\nwindow_s = 0.05\nsample_rate_hz = 2000\nbands_um = [10.0]\n",
            machine.to_str().expect("utf-8"),
            file.to_str().expect("utf-8")
        ),
    );
    let (_, mut runs) = settle::load_runs(&scenario).expect("loads");
    settle::execute::set_backend(&scenario, &mut runs, Backend::Modal).expect("modal");
    assert_eq!(runs.len(), 1);
    let m = settle::execute::execute(&runs[0], None).expect("runs");
    assert!(m.is_ok(), "{m:?}");
    extra(&m, "contour_worst_um")
}
