//! The test-frequency grid: numpy's `arange(start, stop, step)` as numpy fills it
//! (`len = ceil((stop - start) / step)`, `x_i = start + i * ((start + step) - start)`), so
//! the frequencies are Klipper's to the bit (45.999999999999915 Hz, not 46).

pub(super) fn arange(start: f64, stop: f64, step: f64) -> Vec<f64> {
    let len = ((stop - start) / step).ceil();
    if !(len.is_finite() && len > 0.0) {
        return Vec::new();
    }
    let delta = (start + step) - start;
    (0..len as usize)
        .map(|i| {
            if i == 0 {
                start
            } else {
                start + i as f64 * delta
            }
        })
        .collect()
}
