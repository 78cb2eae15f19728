//! Why settle's damping ratios are about 1.6 times Shake&Tune's on the same recording.
//!
//! Shake&Tune (`compute_mechanical_parameters` in `shaketune/helpers/common_func.py`)
//! reads the damping ratio from the normalised power spectrum `psd_xyz / (f + 0.1)`: the
//! bandwidth `bw` between the points where the PSD falls to its peak over `sqrt 2`, then
//! `zeta = sqrt(1/2 - sqrt(1 / (4 + 4 (bw/f)^2 - (bw/f)^4)))`, the amplitude half-power
//! rule. On a *power* spectrum `|T|^2` the points at `1/sqrt 2` of the peak are where
//! `|T|` is at `2^(-1/4)` of its peak, a bandwidth of `2 zeta f sqrt(sqrt 2 - 1) = 0.644 x
//! 2 zeta f` for a lightly damped mode: the estimate is 0.644 times the true damping ratio
//! (settle's sweep fit models the power response itself and is unbiased, see
//! `identify/tests/identify/sweep.rs`).
//!
//! Checked here twice for modes with the parameters settle identifies on the corpus's real
//! files: on the exact power response `|T|^2` (Shake&Tune's rule returns `sqrt(sqrt 2 - 1)
//! = 0.644` of the true damping ratio, less for heavier damping), and on the expected PSD
//! of Klipper's resonance test (the pulse-only test the corpus files were measured with,
//! `accel_per_hz` 75, 5 to 133.3 Hz) seen through Klipper's estimator, whose window widens
//! a narrow peak: there the rule returns 0.62 to 0.77 of the true damping ratio.
//!
//! And on the real recordings whose Shake&Tune graph the owner published
//! (`identify/tests/corpus/MANIFEST.md`): the rule applied to the spectrum settle
//! measured gives the graph's damping ratio, and applied to settle's fitted model (the
//! spectrum settle's modes give under that file's own test, window and sample rate) it
//! gives about the same, while settle's own damping ratio stands above it.

use settle_identify::fit::sweep_model::{ModeParams, SweepModel};
use settle_identify::welch::Welch;
use settle_identify::{AxisIdentification, IdentifiedMode, SweepTest};

/// Shake&Tune's damping estimate from a normalised PSD (see the module notes).
fn shaketune_zeta(freq: &[f64], psd: &[f64]) -> Option<f64> {
    let (peak, _) = psd.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    let half = psd[peak] / 2f64.sqrt();
    let below = (0..peak).rev().find(|&i| psd[i] <= half)?;
    let above = (peak..psd.len()).find(|&i| psd[i] <= half)?;
    let cross =
        |i: usize, j: usize| freq[i] + (half - psd[i]) * (freq[j] - freq[i]) / (psd[j] - psd[i]);
    let bw = (cross(above - 1, above) - cross(below, below + 1)) / freq[peak];
    let (b1, b2) = (bw * bw, bw.powi(4));
    let inner = 0.5 - (1.0 / (4.0 + 4.0 * b1 - b2)).sqrt();
    (inner > 0.0).then(|| inner.sqrt())
}

#[test]
fn shaketune_reads_about_two_thirds_of_the_damping() {
    let test = SweepTest::klipper_legacy();
    let welch = Welch::new(3200.0, 2048);
    let bin = welch.bin_hz();
    let bins: Vec<usize> = (0..welch.nfft() / 2)
        .filter(|&k| {
            let f = k as f64 * bin;
            (5.0..=130.0).contains(&f)
        })
        .collect();
    let freq: Vec<f64> = bins.iter().map(|&k| k as f64 * bin).collect();
    let model = SweepModel::new(&welch, &bins, &test);
    // (frequency, damping ratio) as settle identifies them on the corpus.
    for (f_hz, zeta) in [
        (45.0, 0.06),
        (45.0, 0.1),
        (63.0, 0.06),
        (63.0, 0.12),
        (44.0, 0.16),
    ] {
        let modes = [ModeParams {
            f_hz,
            zeta,
            weight: 1.0,
        }];
        // The exact power response on a fine grid: the closed-form ratio.
        let fine: Vec<f64> = (1..20_000).map(|i| i as f64 * 0.01).collect();
        let exact: Vec<f64> = fine
            .iter()
            .map(|&nu| settle_identify::fit::sweep_model::transmissibility_sq(&modes, nu))
            .collect();
        let st = shaketune_zeta(&fine, &exact).expect("two half-power points");
        let closed = (2f64.sqrt() - 1.0).sqrt();
        eprintln!(
            "{f_hz} Hz, zeta {zeta}: on |T|^2 Shake&Tune reads {st:.4} ({:.3} of it)",
            st / zeta
        );
        assert!(
            (st / zeta - closed).abs() < 0.02,
            "{f_hz} Hz, zeta {zeta}: {st}"
        );
        let mut psd = vec![0.0; bins.len()];
        model.evaluate(1.0, 0.0, &modes, &mut Vec::new(), &mut psd);
        let normalised: Vec<f64> = psd.iter().zip(&freq).map(|(p, f)| p / (f + 0.1)).collect();
        let st = shaketune_zeta(&freq, &normalised).expect("a peak with two half-power points");
        let ratio = st / zeta;
        eprintln!("{f_hz} Hz, zeta {zeta}: Shake&Tune reads {st:.4} ({ratio:.3} of it)");
        assert!(
            (0.62..=0.77).contains(&ratio),
            "{f_hz} Hz, zeta {zeta}: ratio {ratio}"
        );
    }
}

/// The corpus files with a published Shake&Tune graph: `(file, w0 (Hz), zeta)` as the
/// graph's title prints them.
const SHAKETUNE_GRAPHS: [(&str, f64, f64); 5] = [
    (
        "neptune4pro_inputshaper_20250707_143713_axis_X.stdata",
        77.1,
        0.093,
    ),
    (
        "neptune4pro_inputshaper_20250804_210218_axis_Y.stdata",
        81.6,
        0.064,
    ),
    ("metis_resonances_20240206_200114_X.csv", 64.1, 0.062),
    ("metis_resonances_20240206_200335_Y.csv", 55.0, 0.088),
    ("vt627_resonances_20240226_202625_X.csv", 68.8, 0.039),
];

/// Shake&Tune's damping estimate on the spectrum settle measured and on settle's fitted
/// model (`psd / (f + 0.1)` over the fitted band of the identification's figure).
fn shaketune_on_figure(id: &AxisIdentification) -> (f64, f64) {
    let fig = &id.figure;
    let fitted: Vec<usize> = (0..fig.x.len())
        .filter(|&i| fig.model[i].is_finite())
        .collect();
    let freq: Vec<f64> = fitted.iter().map(|&i| fig.x[i]).collect();
    let normalised =
        |v: &[f64]| -> Vec<f64> { fitted.iter().map(|&i| v[i] / (fig.x[i] + 0.1)).collect() };
    let zeta = |v: &[f64]| shaketune_zeta(&freq, &normalised(v)).expect("two half-power points");
    (zeta(&fig.measured), zeta(&fig.model))
}

/// The mode whose natural frequency or own peak lies nearest `main_hz`.
fn main_mode(id: &AxisIdentification, main_hz: f64) -> &IdentifiedMode {
    let d = |m: &IdentifiedMode| {
        (m.frequency_hz.value - main_hz)
            .abs()
            .min((m.peak_hz - main_hz).abs())
    };
    id.modes
        .iter()
        .min_by(|a, b| d(a).total_cmp(&d(b)))
        .expect("a mode")
}

/// The median of `v`.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    0.5 * (v[(n - 1) / 2] + v[n / 2])
}

/// On each real recording with a published Shake&Tune graph: Shake&Tune's rule on the
/// spectrum settle measured (`psd / (f + 0.1)` over the fitted band) reproduces the
/// graph's damping ratio within 10 % (settle's spectrum is the motion direction's at a
/// quarter-segment hop, Shake&Tune's the sum of the three axes at half a segment), and
/// settle's damping ratio of the main mode is larger. Over the files, the rule applied to
/// settle's fitted model gives the graph's damping ratio within 10 % at the median,
/// where settle's own stands at least 30 % above it: the gap is the rule's reading of a
/// power spectrum, not a difference in the modes. The other modes are shown too
/// (`--nocapture`), for `docs/guide/real-recordings.md`.
#[test]
fn shaketune_rule_on_settles_model_gives_the_published_damping() {
    let (mut settle_over, mut model_over) = (Vec::new(), Vec::new());
    for (file, w0, published) in SHAKETUNE_GRAPHS {
        let ids = crate::corpus::answer(file).as_ref().expect("modes");
        let id = &ids[0];
        let (on_measured, on_model) = shaketune_on_figure(id);
        let main = main_mode(id, w0);
        let settle = main.damping_ratio.value;
        println!(
            "{file}: Shake&Tune {w0} Hz, {published}; its rule on settle's spectrum {on_measured:.3}, on settle's model {on_model:.3}; settle {:.1} Hz, {settle:.3} ({:.2} x)",
            main.frequency_hz.value,
            settle / published
        );
        assert!(
            (on_measured / published - 1.0).abs() <= 0.1,
            "{file}: Shake&Tune's rule on settle's spectrum {on_measured}, graph {published}"
        );
        assert!(settle > published, "{file}: settle {settle}");
        settle_over.push(settle / published);
        model_over.push(on_model / published);
    }
    let (settle_over, model_over) = (median(settle_over), median(model_over));
    println!("median: settle {settle_over:.2} x, the rule on settle's model {model_over:.2} x");
    assert!((model_over - 1.0).abs() <= 0.1, "{model_over}");
    assert!(settle_over >= 1.3, "{settle_over}");
}

/// On every corpus file that gives modes: Shake&Tune's rule on the spectrum settle
/// measured against settle's damping ratio of the mode at the published main resonance,
/// shown per file (`--nocapture`) with the median, for `docs/guide/real-recordings.md`.
/// The rule reads 0.62 to 0.77 of the true damping ratio on Klipper's spectra (above), so
/// settle's must stand above it on every file, by 1.3 to 1.6 at the median. That holds for
/// a peak of one mode: where settle finds the main mode's half-power band overlapping
/// another mode's (`|f1 - f2| < zeta1 f1 + zeta2 f2`, closely spaced modes), the peak is
/// the two together and the rule's bandwidth may span both (the bassco Y files of 2023,
/// 42.5 and 47.0 Hz: the rule reads 0.047 and 0.051, settle's main mode 0.038 and 0.036),
/// so the file is shown and left out of the comparison; which files those are is
/// asserted.
#[test]
fn shaketune_rule_on_the_whole_corpus() {
    let mut ratios = Vec::new();
    let mut overlapping = Vec::new();
    for (file, main_hz, id) in crate::corpus::identified() {
        let (on_measured, _) = shaketune_on_figure(id);
        let main = main_mode(id, main_hz);
        let settle = main.damping_ratio.value;
        let ratio = settle / on_measured;
        let half_band = |m: &IdentifiedMode| m.damping_ratio.value * m.frequency_hz.value;
        let close = id.modes.iter().any(|m| {
            !std::ptr::eq(m, main)
                && (m.frequency_hz.value - main.frequency_hz.value).abs()
                    < half_band(m) + half_band(main)
        });
        println!(
            "{file}: Shake&Tune's rule {on_measured:.3}, settle {settle:.3} ({ratio:.2} x){}",
            if close {
                ", overlapping modes: left out"
            } else {
                ""
            }
        );
        if close {
            overlapping.push(file);
            continue;
        }
        assert!(ratio > 1.0, "{file}: {ratio}");
        ratios.push(ratio);
    }
    assert_eq!(
        overlapping,
        [
            "bassco_calibration_data_y_20230306_225431.csv",
            "bassco_resonances_y_20230306_224919.csv",
            "neptune4pro_inputshaper_20250707_143713_axis_X.stdata",
            "voronpi_resonances_x_20221231_212825.csv",
        ]
    );
    let m = median(ratios);
    println!("median {m:.2} x");
    assert!((1.3..=1.6).contains(&m), "{m}");
}
