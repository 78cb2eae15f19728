//! What a G-code job's simulation adds up: per-layer contour-error statistics (worst,
//! 95th percentile from a bounded histogram), the worst spots (one per move) and the
//! toolpath points of the ringing maps.

use crate::measure::log_bins::LogBins;

/// A point of a ringing map: the toolhead (mm), its contour error and the error's two
/// parts ([`Split`], um; 0 off printing moves); `print` false breaks the drawn path
/// (travel, pauses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapPoint {
    /// X (mm).
    pub x_mm: f32,
    /// Y (mm).
    pub y_mm: f32,
    /// Contour error (um).
    pub error_um: f32,
    /// Smoothing (um).
    pub smoothing_um: f32,
    /// Vibration (um).
    pub vibration_um: f32,
    /// Whether the toolhead is printing here.
    pub print: bool,
}

/// Contour errors below this are counted in the first bin (um).
const HIST_MIN_UM: f64 = 1e-3;
/// Relative width of a bin: a percentile is reported as its bin's upper edge, at most
/// 0.1 % above the exact sample quantile.
const HIST_RATIO: f64 = 1.001;
/// Bins from 1e-3 um to 1e5 um (100 mm: beyond is a blow-up, counted in the last bin).
const HIST_BINS: usize = 18_432;

/// The bins' lookup: `ceil(ln(err / HIST_MIN_UM) / ln(HIST_RATIO))`, clamped to the
/// bins, without the logarithm (crate::measure::log_bins).
fn bins() -> &'static LogBins {
    static BINS: std::sync::OnceLock<LogBins> = std::sync::OnceLock::new();
    BINS.get_or_init(|| LogBins::new(HIST_MIN_UM, HIST_RATIO, HIST_BINS))
}

/// A histogram of contour errors with log-spaced bins (bounded memory whatever the job's
/// length). It knows the range of bins it has counted in, so that merging, clearing and
/// reading a histogram of a few samples (a feature type's in one layer) costs that range,
/// not every bin.
#[derive(Debug, Clone)]
pub struct Histogram {
    counts: Vec<u64>,
    total: u64,
    /// The bins counted in are within `lo..=hi` (none when `lo > hi`).
    lo: usize,
    hi: usize,
}

impl Default for Histogram {
    fn default() -> Self {
        Self {
            counts: vec![0; HIST_BINS],
            total: 0,
            lo: usize::MAX,
            hi: 0,
        }
    }
}

/// Histograms are equal when they hold the same counts (however they were counted).
impl PartialEq for Histogram {
    fn eq(&self, other: &Self) -> bool {
        self.total == other.total && self.counts == other.counts
    }
}

impl Histogram {
    /// Count one error (um).
    pub fn push(&mut self, err_um: f64) {
        self.push_all(std::slice::from_ref(&err_um));
    }

    /// Count errors (um): as many [`Histogram::push`]es, the lookups of one not waiting
    /// for the count of the one before.
    pub fn push_all(&mut self, errs_um: &[f64]) {
        let bins = bins();
        let (mut lo, mut hi) = (self.lo, self.hi);
        for &e in errs_um {
            let b = bins.bin(e);
            self.counts[b] += 1;
            lo = lo.min(b);
            hi = hi.max(b);
        }
        (self.lo, self.hi) = (lo, hi);
        self.total += errs_um.len() as u64;
    }

    /// The bins that may hold counts.
    fn range(&self) -> std::ops::Range<usize> {
        match self.lo <= self.hi {
            true => self.lo..self.hi + 1,
            false => 0..0,
        }
    }

    /// Add another histogram's counts.
    pub fn merge(&mut self, other: &Histogram) {
        let r = other.range();
        for (a, b) in self.counts[r.clone()].iter_mut().zip(&other.counts[r]) {
            *a += b;
        }
        self.total += other.total;
        self.lo = self.lo.min(other.lo);
        self.hi = self.hi.max(other.hi);
    }

    /// Forget every count (keeps the bins' memory).
    pub fn clear(&mut self) {
        let r = self.range();
        self.counts[r].fill(0);
        self.total = 0;
        (self.lo, self.hi) = (usize::MAX, 0);
    }

    /// Samples counted.
    pub fn total(&self) -> u64 {
        self.total
    }

    /// The `q` quantile (0..=1) as the upper edge of its bin (um); 0 when empty.
    pub fn quantile_um(&self, q: f64) -> f64 {
        if self.total == 0 {
            return 0.0;
        }
        let rank = ((q * self.total as f64).ceil() as u64).clamp(1, self.total);
        let mut seen = 0;
        let r = self.range();
        for (i, c) in self.counts[r.clone()].iter().enumerate() {
            seen += c;
            if seen >= rank {
                return HIST_MIN_UM * HIST_RATIO.powi((r.start + i) as i32);
            }
        }
        HIST_MIN_UM * HIST_RATIO.powi(HIST_BINS as i32 - 1)
    }
}

/// Where a large contour error is.
#[derive(Debug, Clone, PartialEq)]
pub struct Spot {
    /// The error (um).
    pub error_um: f64,
    /// When (s, print clock).
    pub time_s: f64,
    /// The toolhead there (mm).
    pub x_mm: f64,
    /// The toolhead there (mm).
    pub y_mm: f64,
    /// The G-code line of the move it belongs to (1-based).
    pub line: u64,
    /// Its layer.
    pub layer: u32,
    /// The move's index in the file.
    pub move_index: u64,
    /// The error's two parts here.
    pub split: Split,
}

/// A contour error told apart (um), each part a contour error of its own:
///
/// - *smoothing*: the commanded (shaped) position's distance in XY to the G-code path of
///   the moves active at that time, as the toolhead's contour error is measured. What the
///   shaper trades for speed. Without a shaper it is the planner model's corner bridge
///   only: a profile cannot jump in speed, so each corner's speed jump `dv` is spread over
///   a 100 us window (`settle_planner::firmware::profiles`), off the path by at most
///   `|dv| w / 8 + |da| w^2 / 8` per axis (0.07 um for a 5 mm/s square corner at
///   4,000 mm/s^2).
/// - *vibration*: the toolhead's distance in XY to the command's own recent path
///   ([`crate::studies::gcode::command_path`]): what the machine adds. The lag along the
///   path is not vibration; a rigid machine has none.
///
/// Neither is the contour error's share: the toolhead's distance to the G-code path is at
/// most the sum of its distance to the command's path and that path's distance to the
/// G-code path.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Split {
    /// Commanded position to the G-code path (um).
    pub smoothing_um: f64,
    /// Toolhead to the command's path (um).
    pub vibration_um: f64,
}

impl Split {
    /// Each part's larger value of `self` and `other`.
    pub fn max(self, other: Split) -> Split {
        Split {
            smoothing_um: self.smoothing_um.max(other.smoothing_um),
            vibration_um: self.vibration_um.max(other.vibration_um),
        }
    }
}

/// The largest `n` spots, at most one per move, largest first.
#[derive(Debug, Clone)]
pub struct TopSpots {
    n: usize,
    spots: Vec<Spot>,
}

impl TopSpots {
    /// Keep `n`.
    pub fn new(n: usize) -> Self {
        Self {
            n,
            spots: Vec::with_capacity(n + 1),
        }
    }

    /// Offer a move's worst spot.
    pub fn offer(&mut self, s: Spot) {
        if self.spots.len() == self.n
            && self
                .spots
                .last()
                .is_some_and(|last| last.error_um >= s.error_um)
        {
            return;
        }
        let at = self.spots.partition_point(|x| x.error_um >= s.error_um);
        self.spots.insert(at, s);
        self.spots.truncate(self.n);
    }

    /// The spots, largest first.
    pub fn spots(&self) -> &[Spot] {
        &self.spots
    }
}

/// One layer's contour-error account (working samples only: [`settle_gcode::Move::is_working`]).
#[derive(Debug, Clone)]
pub struct LayerStats {
    /// Layer index.
    pub layer: u32,
    /// Its largest error.
    pub worst: Option<Spot>,
    /// The 95th percentile of its errors (um; [`Histogram::quantile_um`]), set when the
    /// layer ends (the layer's histogram is then merged into the job's and dropped, so
    /// memory does not grow with the number of layers).
    pub p95_um: f64,
    /// Printing moves in it that were simulated.
    pub print_moves: u64,
    /// Mean over its working moves of each move's largest error (um): the typical
    /// ringing after a corner.
    pub mean_move_worst_um: f64,
    /// The last layer of a job that ends the file: the largest distance in XY (um) from
    /// the toolhead to the end point after the last command (the ringing after the final
    /// stop).
    pub end_residual_um: Option<f64>,
    /// The largest smoothing and the largest vibration of its printing samples (each
    /// part's own largest, not the parts of the largest error).
    pub split_worst: Split,
}

impl LayerStats {
    /// An empty account of `layer`.
    pub fn new(layer: u32) -> Self {
        Self {
            layer,
            worst: None,
            p95_um: 0.0,
            print_moves: 0,
            mean_move_worst_um: 0.0,
            end_residual_um: None,
            split_worst: Split::default(),
        }
    }

    /// Its largest error (um), 0 without working samples.
    pub fn worst_um(&self) -> f64 {
        self.worst.as_ref().map_or(0.0, |s| s.error_um)
    }

    /// Count a printing move whose largest error was `spot`.
    pub fn add_move(&mut self, spot: &Spot) {
        self.print_moves += 1;
        let n = self.print_moves as f64;
        self.mean_move_worst_um += (spot.error_um - self.mean_move_worst_um) / n;
        if self.worst.as_ref().is_none_or(|w| spot.error_um > w.error_um) {
            self.worst = Some(spot.clone());
        }
    }
}

/// A layer's ringing map: its toolpath points and worst spots.
#[derive(Debug, Clone)]
pub struct LayerMap {
    /// Layer index.
    pub layer: u32,
    /// The toolpath as simulated, sampled at about 1 kHz.
    pub points: Vec<MapPoint>,
    /// Its worst spots (one per move), largest first.
    pub spots: Vec<Spot>,
}

impl LayerMap {
    /// Its largest error (um).
    pub fn worst_um(&self) -> f64 {
        self.spots.first().map_or(0.0, |s| s.error_um)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_are_within_a_bin_above_the_sample_quantile() {
        let mut h = Histogram::default();
        // 1..=1000 um: the 95th percentile (rank 950) is 950 um.
        for i in 1..=1000 {
            h.push(f64::from(i));
        }
        let q = h.quantile_um(0.95);
        assert!((950.0..=950.0 * HIST_RATIO).contains(&q), "{q}");
        assert!((1000.0..=1000.0 * HIST_RATIO).contains(&h.quantile_um(1.0)));
        assert_eq!(Histogram::default().quantile_um(0.95), 0.0);
    }

    /// Counts past 32 bits stay exact (5e9 errors of 2 um and 1e9 of 1 um: the 95th
    /// percentile is in 2 um's bin, the 10th in 1 um's), merged too.
    #[test]
    fn counts_past_32_bits_stay_exact() {
        let (one, two) = (bins().bin(1.0), bins().bin(2.0));
        let mut h = Histogram::default();
        h.counts[two] += 5_000_000_000 - 1;
        h.push(2.0);
        h.counts[one] += 1_000_000_000 - 1;
        h.push(1.0);
        h.total += 5_000_000_000 - 1 + 1_000_000_000 - 1;
        assert_eq!(h.counts[two], 5_000_000_000);
        assert_eq!(h.counts[one], 1_000_000_000);
        let edge = |i: usize| HIST_MIN_UM * HIST_RATIO.powi(i as i32);
        assert_eq!(h.quantile_um(0.95), edge(two));
        assert_eq!(h.quantile_um(0.1), edge(one));
        let mut m = h.clone();
        m.merge(&h);
        assert_eq!(m.counts[two], 10_000_000_000);
        assert_eq!(m.total(), 12_000_000_000);
        assert_eq!(m.quantile_um(0.5), edge(two));
    }

    #[test]
    fn top_spots_keep_the_largest_in_order() {
        let mut t = TopSpots::new(2);
        for (i, e) in [3.0, 1.0, 5.0, 4.0].into_iter().enumerate() {
            t.offer(Spot {
                error_um: e,
                time_s: 0.0,
                x_mm: 0.0,
                y_mm: 0.0,
                line: i as u64,
                layer: 0,
                move_index: i as u64,
                split: Split::default(),
            });
        }
        let e: Vec<f64> = t.spots().iter().map(|s| s.error_um).collect();
        assert_eq!(e, [5.0, 4.0]);
    }
}
