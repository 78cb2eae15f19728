//! Calibration data as Klipper holds it (`CalibrationData`): frequency bins and power
//! spectral densities per accelerometer axis and their sum.

/// One data set: the PSD of one resonance test. Klipper's choice reads only `psd_sum`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CalibrationData {
    /// Frequency bins (Hz), increasing.
    pub freq_hz: Vec<f64>,
    /// `psd_xyz`: the sum of the three axes' PSDs.
    pub psd_sum: Vec<f64>,
    /// X axis PSD, if held.
    pub psd_x: Option<Vec<f64>>,
    /// Y axis PSD, if held.
    pub psd_y: Option<Vec<f64>>,
    /// Z axis PSD, if held.
    pub psd_z: Option<Vec<f64>>,
}

impl CalibrationData {
    /// What Klipper does to raw resonance PSDs before choosing (`normalize_to_frequencies`,
    /// applied by SHAPER_CALIBRATE and by calibrate_shaper.py to a CSV without shaper
    /// columns): divide by `f + 0.1` (the test's acceleration grows with frequency) and
    /// damp bins below 10 Hz by `exp(1 - (10 / (f + 0.1))^2)`.
    pub fn normalize_to_frequencies(&mut self) {
        let freqs = &self.freq_hz;
        let apply = |psd: &mut Vec<f64>| {
            for (p, &f) in psd.iter_mut().zip(freqs) {
                *p /= f + 0.1;
                if f < 2.0 * 5.0 {
                    let x = 2.0 * 5.0 / (f + 0.1);
                    *p *= (-(x * x) + 1.0).exp();
                }
            }
        };
        apply(&mut self.psd_sum);
        for psd in [&mut self.psd_x, &mut self.psd_y, &mut self.psd_z]
            .into_iter()
            .flatten()
        {
            apply(psd);
        }
    }
}
