//! Welch's power spectral density exactly as Klipper computes it.
//!
//! Klipper's `klippy/extras/shaper_calibrate.py` (`ShaperCalibrate._psd` and
//! `calc_freq_response`): sample rate `fs = N / (t_last - t_first)`; segment length
//! `nfft = 1 << bit_length(int(fs * WINDOW_T_SEC - 1))` with `WINDOW_T_SEC = 0.5` (the
//! power of two just above half a second); a Kaiser window with beta 6; segments overlap
//! by `nfft / 2`; each segment has its own mean removed before windowing; the periodogram
//! is `|rfft|^2 / (fs sum w^2)`, doubled except at 0 Hz and the Nyquist bin, and averaged
//! over the segments. Bins are `k fs / nfft`. Units: (input unit)^2 / Hz.

use std::sync::Arc;

use realfft::{RealFftPlanner, RealToComplex};

/// Klipper's segment length in seconds (`WINDOW_T_SEC`).
pub const WINDOW_T_SEC: f64 = 0.5;

/// Klipper's Kaiser window parameter.
pub const KAISER_BETA: f64 = 6.0;

/// Klipper's segment length for a sample rate: the power of two above
/// `int(fs * 0.5 - 1)`.
pub fn klipper_nfft(sample_rate_hz: f64) -> usize {
    let m = (sample_rate_hz * WINDOW_T_SEC - 1.0).max(1.0) as u64;
    1usize << (64 - m.leading_zeros())
}

/// The modified Bessel function of the first kind, order 0 (power series; converges for
/// every argument, used here for |x| <= ~10).
pub fn bessel_i0(x: f64) -> f64 {
    let q = x * x / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while term > 1e-17 * sum {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// numpy's `kaiser(n, beta)`: `I0(beta sqrt(1 - (2 i / (n - 1) - 1)^2)) / I0(beta)`.
pub fn kaiser(n: usize, beta: f64) -> Vec<f64> {
    if n == 1 {
        return vec![1.0];
    }
    let denom = bessel_i0(beta);
    (0..n)
        .map(|i| {
            let r = 2.0 * i as f64 / (n - 1) as f64 - 1.0;
            bessel_i0(beta * (1.0 - r * r).max(0.0).sqrt()) / denom
        })
        .collect()
}

/// A Welch estimator with Klipper's settings for one sample rate and segment length.
pub struct Welch {
    nfft: usize,
    /// Samples from one segment's start to the next (`nfft / 2` in Klipper).
    hop: usize,
    sample_rate_hz: f64,
    window: Vec<f64>,
    /// `1 / (fs sum w^2)`.
    scale: f64,
    fft: Arc<dyn RealToComplex<f64>>,
}

impl std::fmt::Debug for Welch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Welch")
            .field("nfft", &self.nfft)
            .field("hop", &self.hop)
            .field("sample_rate_hz", &self.sample_rate_hz)
            .finish_non_exhaustive()
    }
}

impl Welch {
    /// Klipper's estimator for `sample_rate_hz` (segment length from [`klipper_nfft`]).
    pub fn klipper(sample_rate_hz: f64) -> Self {
        Self::new(sample_rate_hz, klipper_nfft(sample_rate_hz))
    }

    /// Klipper's window and overlap with another (even) segment length.
    pub fn new(sample_rate_hz: f64, nfft: usize) -> Self {
        let window = kaiser(nfft, KAISER_BETA);
        let sum_sq: f64 = window.iter().map(|w| w * w).sum();
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(nfft);
        Self {
            nfft,
            hop: (nfft / 2).max(1),
            sample_rate_hz,
            window,
            scale: 1.0 / (sample_rate_hz * sum_sq),
            fft,
        }
    }

    /// The same window and segment length with segments `hop` samples apart (at least 1)
    /// instead of Klipper's `nfft / 2`. A sweep's spectrum summed over segments is the
    /// time integral of the short-time spectrum sampled every `hop`; sampling it every
    /// `nfft / 4` leaves out none of what the window lets through (its main lobe is
    /// narrower than the `fs / hop = 4` bins such sampling repeats at), while `nfft / 2`
    /// aliases coherent cross terms ([`crate::fit::sweep_model`]).
    pub fn with_hop(mut self, hop: usize) -> Self {
        self.hop = hop.max(1);
        self
    }

    /// Samples from one segment's start to the next.
    pub fn hop(&self) -> usize {
        self.hop
    }

    /// Segment length (samples).
    pub fn nfft(&self) -> usize {
        self.nfft
    }

    /// Sample rate (Hz).
    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    /// Bin spacing (Hz).
    pub fn bin_hz(&self) -> f64 {
        self.sample_rate_hz / self.nfft as f64
    }

    /// The frequencies of the bins (Hz): `k fs / nfft`, `k = 0..=nfft/2`.
    pub fn freqs_hz(&self) -> Vec<f64> {
        (0..=self.nfft / 2)
            .map(|k| k as f64 * self.bin_hz())
            .collect()
    }

    /// Number of segments for `n` samples: `(n - nfft) / hop + 1` (0 when `n < nfft`),
    /// Klipper's `(n - nfft / 2) / (nfft / 2)` at its hop.
    pub fn segments(&self, n: usize) -> usize {
        if n < self.nfft {
            0
        } else {
            (n - self.nfft) / self.hop + 1
        }
    }

    /// The PSD of `x` ((unit of x)^2/Hz per bin of [`Welch::freqs_hz`]); `None` when `x`
    /// is shorter than one segment.
    pub fn psd(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.cross(&[x]).and_then(|mut v| v.pop())
    }

    /// The real parts of the cross spectra of `channels` (all of one length), packed by
    /// pairs `(a, b)` with `a <= b` in the order `(0,0), (0,1), ..., (1,1), ...`: the
    /// diagonal entries are each channel's PSD as [`Welch::psd`] gives it, and the PSD of
    /// any combination `sum d_a x_a` is `sum d_a d_b Re S_ab` (per bin). `None` when the
    /// channels are shorter than one segment.
    pub fn cross(&self, channels: &[&[f64]]) -> Option<Vec<Vec<f64>>> {
        let n = channels.iter().map(|c| c.len()).min()?;
        let segments = self.segments(n);
        if segments == 0 {
            return None;
        }
        let m = channels.len();
        let step = self.hop;
        let bins = self.nfft / 2 + 1;
        let mut input = self.fft.make_input_vec();
        let mut scratch = self.fft.make_scratch_vec();
        let mut spectra = vec![self.fft.make_output_vec(); m];
        let mut acc = vec![vec![0.0; bins]; m * (m + 1) / 2];
        for s in 0..segments {
            for (x, spectrum) in channels.iter().zip(spectra.iter_mut()) {
                let seg = &x[s * step..s * step + self.nfft];
                let mean = seg.iter().sum::<f64>() / self.nfft as f64;
                for ((o, &v), &w) in input.iter_mut().zip(seg).zip(&self.window) {
                    *o = w * (v - mean);
                }
                // Lengths come from the plan, so this cannot fail.
                self.fft
                    .process_with_scratch(&mut input, spectrum, &mut scratch)
                    .ok()?;
            }
            let mut p = 0;
            for a in 0..m {
                for b in a..m {
                    for ((o, u), v) in acc[p].iter_mut().zip(&spectra[a]).zip(&spectra[b]) {
                        *o += u.re * v.re + u.im * v.im;
                    }
                    p += 1;
                }
            }
        }
        let norm = self.scale / segments as f64;
        for row in &mut acc {
            for (k, a) in row.iter_mut().enumerate() {
                *a *= if k == 0 || k == bins - 1 {
                    norm
                } else {
                    2.0 * norm
                };
            }
        }
        Some(acc)
    }

    /// The spectral kernel of one segment, `K(d) = |W(d)|^2 / (nfft sum w^2)` for an
    /// offset of `d` bins (W the window's transform): the PSD this estimator reports at a
    /// bin `d` bins away from a sinusoid of power `P` is `P K(d) / bin_hz`, and `K`
    /// sums to 1 over all offsets (Parseval). Tabulated at `per_bin` points per bin out to
    /// `half_width_bins`, from `d = 0`.
    pub fn kernel_table(&self, half_width_bins: usize, per_bin: usize) -> Vec<f64> {
        let n = self.nfft as f64;
        let sum_sq: f64 = self.window.iter().map(|w| w * w).sum();
        (0..=half_width_bins * per_bin)
            .map(|i| {
                let w = self.window_transform(i as f64 / per_bin as f64);
                w * w / (n * sum_sq)
            })
            .collect()
    }

    /// The window's transform at an offset of `d` bins, `W(d) = sum_k w_k cos(2 pi d
    /// (k - c) / nfft)` about the window's centre `c` (real: the window is symmetric).
    fn window_transform(&self, d: f64) -> f64 {
        let n = self.nfft as f64;
        let centre = (n - 1.0) / 2.0;
        self.window
            .iter()
            .enumerate()
            .map(|(k, &wk)| wk * (std::f64::consts::TAU * d * (k as f64 - centre) / n).cos())
            .sum()
    }

    /// `c = 1 + 2 sum_d rho_d` of the estimator's bins: `rho_d`, the correlation of two
    /// bins `d` apart of one windowed segment's periodogram, is `(sum a(x) a(x + d))^2 /
    /// (sum a(x)^2)^2` over the amplitude kernel `a` ([`Welch::amplitude_kernel_table`];
    /// 0.47 for neighbouring bins of Klipper's Kaiser window), summed over 6 bins. `n` bins
    /// carry about `n / c` independent ones (1.95 for Klipper's window), which the sweep
    /// fit's model selection counts ([`crate::fit::sweep`]). This is the noise's own
    /// correlation, not a fit's residuals': on a real spectrum those mostly measure what
    /// the model leaves out (a mode not yet fitted, structure the modal model does not
    /// hold), and would count a spectrum with more to explain as holding fewer independent
    /// bins, against adding the mode that explains it.
    pub fn bin_correlation(&self) -> f64 {
        const PER_BIN: usize = 32;
        const BINS: usize = 6;
        let table = self.amplitude_kernel_table(2 * BINS, PER_BIN);
        let a = |x: isize| table.get(x.unsigned_abs()).copied().unwrap_or(0.0);
        let span = (BINS * PER_BIN) as isize;
        let overlap = |d: isize| -> f64 { (-span..=span).map(|x| a(x) * a(x + d)).sum() };
        let zero = overlap(0);
        let sum: f64 = (1..=BINS as isize)
            .map(|d| (overlap(d * PER_BIN as isize) / zero).powi(2))
            .sum();
        1.0 + 2.0 * sum
    }

    /// The signed amplitude kernel `a(d) = W(d) / sqrt(nfft sum w^2)`, so that
    /// [`Welch::kernel_table`] is `a^2`: one segment's transform of white noise at two
    /// frequencies `d1` and `d2` bins from a point correlates as `a(d1) a(d2)`, which is
    /// what the covariance of the estimate between bins is built from
    /// ([`crate::fit::sweep_model::SweepModel::psd_covariance`]). Tabulated like
    /// [`Welch::kernel_table`].
    pub fn amplitude_kernel_table(&self, half_width_bins: usize, per_bin: usize) -> Vec<f64> {
        let n = self.nfft as f64;
        let sum_sq: f64 = self.window.iter().map(|w| w * w).sum();
        let norm = (n * sum_sq).sqrt();
        (0..=half_width_bins * per_bin)
            .map(|i| self.window_transform(i as f64 / per_bin as f64) / norm)
            .collect()
    }
}

/// Klipper's frequency response of a raw recording (`calc_freq_response` in
/// `klippy/extras/shaper_calibrate.py`): the sample rate `N / (t_last - t_first)`, Klipper's
/// segment length and half-segment hop, and the PSD of each sensor axis. Returns the bin
/// frequencies and the three PSDs ((mm/s^2)^2/Hz); `None` when an axis is missing or the
/// recording is not longer than one segment (Klipper's `N <= M`).
pub fn klipper_response(rec: &crate::read::Recording) -> Option<(Vec<f64>, [Vec<f64>; 3])> {
    let welch = Welch::klipper(rec.sample_rate_hz);
    if rec.len() <= welch.nfft() {
        return None;
    }
    let mut psd = rec
        .accel_mm_s2
        .iter()
        .map(|a| a.as_deref().and_then(|a| welch.psd(a)));
    let (x, y, z) = (psd.next()??, psd.next()??, psd.next()??);
    Some((welch.freqs_hz(), [x, y, z]))
}
