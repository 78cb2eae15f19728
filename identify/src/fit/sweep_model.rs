//! The expected Welch PSD of a resonance sweep seen through the modal model.
//!
//! The sensor on the toolhead measures the toolhead's acceleration. With settle's modal
//! model (toolhead = command + sum w_k e_k, `e_k'' + 2 zeta_k w_k e_k' + w_k^2 e_k =
//! -a_cmd`) the transfer from the commanded to the measured acceleration is
//!
//! `T(i w) = 1 + sum_k w_k w^2 / (w_k^2 - w^2 + 2 i zeta_k w_k w)`
//!
//! (transmissibility; `1` below the modes, `w_k / (2 zeta_k)` in magnitude at an isolated
//! mode, `1 - sum w_k` far above). The whole record's spectrum is exactly
//! `|Y(nu)|^2 = |T(nu)|^2 |A(nu)|^2`, and averaging windowed periodograms over the record
//! smooths it with the window's kernel `K` ([`crate::welch::Welch::kernel_table`]). So the
//! expected PSD at bin `f` is
//!
//! `M(f) = G int B(nu) |T(nu)|^2 K(f - nu) dnu + N`
//!
//! with `B` the energy spectrum of the test's whole commanded acceleration, computed from
//! its pieces ([`crate::energy_spectrum`]: the sweep, its start and stop, the square
//! wave's harmonics and the sweeping wave's lines with their interference), `G` an
//! unknown gain (record length, sensor scale,
//! the test's true amplitude) and `N` the sensor's white noise floor. The integral runs on
//! a grid of `1 / GRID_PER_BIN` bins, fine enough for a half-power width of a fraction of
//! a bin (the trapezoid rule of a smooth peak converges geometrically once the step is
//! below its half width). Sweep transients need no extra term: they are part of `T` times
//! `A`, and only time-local spectra see them as distortion.

use nalgebra::Complex;

use crate::energy_spectrum::EnergySpectrum;
use crate::excitation::SweepTest;
use crate::welch::Welch;

/// Fine-grid points per bin.
pub const GRID_PER_BIN: usize = 32;

/// Kernel half width (bins): Kaiser(6)'s main lobe is +-2.2 bins, its side lobes below
/// -44 dB beyond; 6 bins keep what the PSD's dynamic range can show.
pub const KERNEL_HALF_WIDTH_BINS: usize = 6;

/// A mode's parameters for the model: natural frequency (Hz), damping ratio, weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeParams {
    /// Natural frequency (Hz).
    pub f_hz: f64,
    /// Damping ratio.
    pub zeta: f64,
    /// Participation weight.
    pub weight: f64,
}

/// `|T(nu)|^2` of the modal model at `nu_hz`.
pub fn transmissibility_sq(modes: &[ModeParams], nu_hz: f64) -> f64 {
    let mut t = Complex::new(1.0, 0.0);
    for m in modes {
        let r = nu_hz / m.f_hz;
        t += m.weight * r * r / Complex::new(1.0 - r * r, 2.0 * m.zeta * r);
    }
    t.norm_sqr()
}

/// The precomputed pieces of the model for a set of bins.
#[derive(Debug, Clone)]
pub struct SweepModel {
    /// Fine grid frequencies (Hz).
    grid_hz: Vec<f64>,
    /// Per fitted bin: first fine-grid index and the weights `K B dnu / bin` over the
    /// following `2 H R + 1` points.
    rows: Vec<(usize, Vec<f64>)>,
    /// `B dnu / bin` per fine-grid point.
    energy: Vec<f64>,
    /// Per fitted bin: its fine-grid index.
    centres: Vec<usize>,
    /// The amplitude kernel `a` ([`Welch::amplitude_kernel_table`]) at `GRID_PER_BIN`
    /// points per bin out to [`KERNEL_HALF_WIDTH_BINS`].
    amplitude: Vec<f64>,
    /// Segments' spacing in fine-grid points of the frequencies their sampling aliases:
    /// `fs / hop` = `nfft / hop` bins.
    alias_step: usize,
}

impl SweepModel {
    /// The model for bins `k` (bin index; frequency `k bin_hz`) of an estimator with
    /// `welch`'s window, under the test `test`.
    pub fn new(welch: &Welch, bins: &[usize], test: &SweepTest) -> Self {
        let bin = welch.bin_hz();
        let r = GRID_PER_BIN;
        let h = KERNEL_HALF_WIDTH_BINS;
        let kernel = welch.kernel_table(h, r);
        let amplitude = welch.amplitude_kernel_table(h, r);
        let first = bins.first().copied().unwrap_or(0);
        let last = bins.last().copied().unwrap_or(0);
        // Fine index g <-> frequency g bin / R; grid from (first - h) to (last + h) bins.
        let g0 = (first * r).saturating_sub(h * r);
        let g1 = (last + h) * r;
        let dnu = bin / r as f64;
        let spectrum = EnergySpectrum::of_pieces(&test.pieces(), dnu, g1 as f64 * dnu);
        let grid_hz: Vec<f64> = (g0..=g1).map(|g| g as f64 * dnu).collect();
        let energy: Vec<f64> = (g0..=g1)
            .map(|g| spectrum.density().get(g).copied().unwrap_or(0.0) * dnu / bin)
            .collect();
        let rows = bins
            .iter()
            .map(|&k| {
                let centre = k * r;
                let start = centre.saturating_sub(h * r).max(g0);
                let weights = (start..=centre + h * r)
                    .map(|g| kernel[g.abs_diff(centre)] * energy[g - g0])
                    .collect();
                (start - g0, weights)
            })
            .collect();
        let centres = bins.iter().map(|&k| k * r - g0).collect();
        let alias_step = (welch.nfft() as f64 / welch.hop() as f64 * r as f64).round() as usize;
        Self {
            grid_hz,
            rows,
            energy,
            centres,
            amplitude,
            alias_step,
        }
    }

    /// The excitation alone seen through the estimator (`|T| = 1`, `G = 1`, `N = 0`).
    pub fn excitation(&self) -> Vec<f64> {
        self.rows
            .iter()
            .map(|(_, w)| w.iter().sum::<f64>())
            .collect()
    }

    /// The expected PSD per bin for gain `gain`, noise floor `noise` and `modes`, written
    /// into `out` (one entry per bin given to [`SweepModel::new`]); `t2` is scratch.
    pub fn evaluate(
        &self,
        gain: f64,
        noise: f64,
        modes: &[ModeParams],
        t2: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        t2.clear();
        t2.extend(
            self.grid_hz
                .iter()
                .map(|&nu| transmissibility_sq(modes, nu)),
        );
        for (o, (start, w)) in out.iter_mut().zip(&self.rows) {
            let cont: f64 = w.iter().zip(&t2[*start..]).map(|(a, b)| a * b).sum();
            *o = gain * cont + noise;
        }
    }

    /// The covariance of the estimate between the bins, `cov(P_k, P_l)`, for gain `gain`,
    /// noise floor `noise` and `modes`, times the number of segments averaged (which
    /// scales it as `1 / segments`); one row and column per bin given to
    /// [`SweepModel::new`].
    ///
    /// Derivation (white Gaussian sensor noise of PSD `N` added to the deterministic
    /// response `y` whose whole-record density, as the model sees it, is
    /// `S = G B |T|^2`). Per segment `s` and bin `k` the transform is `Y_sk + n_sk`; the
    /// periodogram's fluctuation is the cross term `2 Re(Y_sk* n_sk)` plus the noise's own
    /// `|n_sk|^2 - E`. Written in frequency, `n_sk = int n(mu) W(k - mu) e^(2 pi i mu s
    /// hop) dmu`, and the sum over segments of `e^(2 pi i (mu - nu) s hop)` is a comb at
    /// multiples of `fs / hop` (`D = nfft / hop` bins). What survives averaging over the
    /// record is, with `a` the amplitude kernel ([`Welch::amplitude_kernel_table`]):
    ///
    /// `cov(P_k, P_l) = (D / segments) sum_m int (2 N S(nu) + N^2) a(k - nu) a(l - nu)
    /// a(k - nu - m D) a(l - nu - m D) dnu`
    ///
    /// (`nu` in bins; terms pairing different frequencies of `y` oscillate across the
    /// kernel and cancel). For `S` smooth over the kernel this is Welch's (1967) result
    /// for overlapping segments, `(2 S N + N^2)` times the window's overlap correlation
    /// `sum_j |rho(j hop)|^2`, spread over neighbouring bins; where `S` is peaked within
    /// the kernel (a lightly damped mode, a line) the cross term of overlapping segments
    /// adds coherently and its variance reaches `1.39` times that (Kaiser 6, quarter
    /// segment hop; `1.28` at half). A fit that weights bins as independent with one
    /// common variance factor misses both the correlation between bins and this excess at
    /// the peaks, which carry the modes' parameters.
    pub fn psd_covariance(
        &self,
        gain: f64,
        noise: f64,
        modes: &[ModeParams],
    ) -> nalgebra::DMatrix<f64> {
        let r = GRID_PER_BIN;
        let h = (KERNEL_HALF_WIDTH_BINS * r) as isize;
        let step = self.alias_step as isize;
        let d = step as f64 / r as f64;
        let density: Vec<f64> = self
            .grid_hz
            .iter()
            .zip(&self.energy)
            .map(|(&nu, &e)| {
                2.0 * noise * gain * e * transmissibility_sq(modes, nu) + noise * noise / r as f64
            })
            .collect();
        let a = |x: isize| -> f64 { self.amplitude.get(x.unsigned_abs()).copied().unwrap_or(0.0) };
        let n = self.centres.len();
        let mut cov = nalgebra::DMatrix::zeros(n, n);
        let last = density.len() as isize - 1;
        for i in 0..n {
            let ci = self.centres[i] as isize;
            for j in i..n {
                let cj = self.centres[j] as isize;
                if cj - ci > 2 * h {
                    break;
                }
                // Grid points within the kernel of both bins.
                let lo = (cj - h).max(0);
                let hi = (ci + h).min(last);
                let mut sum = 0.0;
                for g in lo..=hi {
                    let (x, y) = (ci - g, cj - g);
                    let base = a(x) * a(y);
                    if base == 0.0 {
                        continue;
                    }
                    let mut q = 0.0;
                    let mut m = -(2 * h / step.max(1)) - 1;
                    while m * step <= 2 * h + step {
                        q += a(x - m * step) * a(y - m * step);
                        m += 1;
                    }
                    sum += density[g as usize] * base * q;
                }
                cov[(i, j)] = d * sum;
                cov[(j, i)] = d * sum;
            }
        }
        cov
    }
}
