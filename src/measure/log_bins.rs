//! The bin of a value in log-spaced bins, `ceil(ln(x / min) / ln(ratio))` clamped to
//! `0..bins` ([`exact_bin`]), found without a logarithm: from two tables built once, the
//! same index for every `f64` as the formula gives.
//!
//! The formula is a non-decreasing function of `x` (a division by a positive constant,
//! the logarithm and `ceil` each are), so each bin `i >= 1` starts at a threshold `T_i`,
//! the least `x` whose bin is `i` or more, found at construction by bisection around
//! `min ratio^(i - 1)`; a value's bin is the number of thresholds at or below it. The
//! values sharing an exponent and the top `MANTISSA_BITS` mantissa bits (a key) span
//! less than a bin when the ratio is above `1 + 2^-10`, so at most one threshold falls
//! among them: a value's bin is that of its key's lowest value, plus one from that
//! threshold on. Two independent loads, no logarithm. The test module checks the lookup
//! against the formula at and around every threshold and at random values.

/// Mantissa bits of the first guess's key (with the exponent).
const MANTISSA_BITS: u32 = 10;
/// Bits below the key.
const SHIFT: u32 = 52 - MANTISSA_BITS;

/// `ceil(ln(x / min) / ln(ratio))` for `x > min`, 0 for `x <= min` or NaN, at most
/// `bins - 1`: the index the lookup reproduces (by definition).
pub fn exact_bin(min: f64, ratio: f64, bins: usize, x: f64) -> usize {
    let i = if x <= min {
        0
    } else {
        ((x / min).ln() / ratio.ln()).ceil() as usize
    };
    i.min(bins - 1)
}

/// Log-spaced bins with their lookup tables.
#[derive(Debug, Clone)]
pub struct LogBins {
    min: f64,
    /// The last bin's threshold: every value from here on is in the last bin.
    top: f64,
    /// The last bin (`bins - 1`).
    last: usize,
    /// The bin of the lowest value of each key, from the key of `min` on.
    start: Vec<u16>,
    /// The threshold of the bin after `start` of the same key (infinite after the last):
    /// a value of that key is in the next bin from there on (the one after starts in a
    /// later key).
    next: Vec<f64>,
    key0: u64,
}

/// `T_i` for `1 <= i < bins` at index `i` (entry 0 is `min`).
fn thresholds(min: f64, ratio: f64, bins: usize) -> Vec<f64> {
    let raw = |x: f64| ((x / min).ln() / ratio.ln()).ceil();
    let mut thresholds = vec![min; bins];
    for (i, t) in thresholds.iter_mut().enumerate().skip(1) {
        // The bin is `i` or more once `ln(x / min) / ln(ratio)` passes `i - 1`: near
        // `min e^((i - 1) ln(ratio))`, within a few units in the last place. Bisect
        // the bit patterns (ordered as the positive values are) between a value below
        // and one at or above, widened until they are.
        let want = i as f64;
        let guess = (min * ((i - 1) as f64 * ratio.ln()).exp()).max(min.next_up());
        let (mut lo, mut hi, mut width) = (guess.to_bits(), guess.to_bits(), 16u64);
        while lo > min.to_bits() && raw(f64::from_bits(lo)) >= want {
            lo = lo.saturating_sub(width).max(min.to_bits());
            width *= 2;
        }
        width = 16;
        while raw(f64::from_bits(hi)) < want {
            hi += width;
            width *= 2;
        }
        // raw(lo) < want (or lo is `min`, bin 0), raw(hi) >= want.
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if raw(f64::from_bits(mid)) >= want {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        *t = f64::from_bits(hi);
    }
    thresholds
}

impl LogBins {
    /// Bins from `min` (`> 0`, finite) by `ratio` (`> 1 + 2^-10`), `bins` of them (2 to
    /// 65,536).
    pub fn new(min: f64, ratio: f64, bins: usize) -> Self {
        assert!(min > 0.0 && min.is_finite(), "min {min}");
        assert!(
            ratio > 1.0 + 1.0 / 1024.0 && ratio.is_finite(),
            "ratio {ratio}"
        );
        assert!((2..=1 << 16).contains(&bins), "bins {bins}");
        let t = thresholds(min, ratio, bins);
        let key = |x: f64| x.to_bits() >> SHIFT;
        let key0 = key(min);
        let last = key(t[bins - 1]);
        let keys = (last - key0 + 1) as usize;
        let (mut start, mut next) = (Vec::with_capacity(keys), Vec::with_capacity(keys));
        let mut i = 0usize;
        for k in key0..=last {
            let lo = f64::from_bits(k << SHIFT).max(min.next_up());
            while i + 1 < bins && t[i + 1] <= lo {
                i += 1;
            }
            // At most one threshold inside a key: a key is narrower than a bin.
            let hi = f64::from_bits((k + 1) << SHIFT);
            assert!(i + 2 >= bins || t[i + 2] >= hi, "two thresholds in a key");
            start.push(u16::try_from(i).expect("at most 65,536 bins"));
            next.push(t.get(i + 1).copied().unwrap_or(f64::INFINITY));
        }
        Self {
            min,
            top: t[bins - 1],
            last: bins - 1,
            start,
            next,
            key0,
        }
    }

    /// The bin of `x`: [`exact_bin`] of the parameters given to [`LogBins::new`].
    #[inline]
    pub fn bin(&self, x: f64) -> usize {
        // NaN and everything at or below `min` are in bin 0.
        if x.is_nan() || x <= self.min {
            return 0;
        }
        if x >= self.top {
            return self.last;
        }
        let k = ((x.to_bits() >> SHIFT) - self.key0) as usize;
        usize::from(self.start[k]) + usize::from(x >= self.next[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// At every threshold and 40 representable values either side (the formula's value
    /// there is within a few units in the last place of an integer: where a logarithm
    /// that is not monotone would show), at the edges and at random values over the whole
    /// range and beyond: the lookup is the formula.
    #[test]
    fn the_lookup_is_the_formula() {
        let (min, ratio, bins) = (1e-3, 1.001, 18_432);
        let b = LogBins::new(min, ratio, bins);
        let check = |x: f64| assert_eq!(b.bin(x), exact_bin(min, ratio, bins, x), "x = {x:e}");
        for &t in &thresholds(min, ratio, bins) {
            let mut x = t;
            for _ in 0..40 {
                x = x.next_down();
            }
            for _ in 0..81 {
                check(x);
                x = x.next_up();
            }
        }
        for x in [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            f64::MIN_POSITIVE,
            min,
            1e6,
            f64::MAX,
        ] {
            check(x);
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        for _ in 0..200_000 {
            let x = 10f64.powf(rng.random_range(-4.0..6.0));
            check(x);
        }
    }

    /// Other parameters (coarse bins, a minimum that is not a round number).
    #[test]
    fn the_lookup_is_the_formula_for_other_bins() {
        for (min, ratio, bins) in [(0.37, 1.5, 40), (2.5e-9, 1.01, 3_000)] {
            let b = LogBins::new(min, ratio, bins);
            let mut x = min / 2.0;
            while x < min * ratio.powi(bins as i32 + 2) {
                assert_eq!(b.bin(x), exact_bin(min, ratio, bins, x), "x = {x:e}");
                x *= 1.000_37;
            }
        }
    }
}
