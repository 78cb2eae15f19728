//! The error per slicer feature type (`;TYPE:External perimeter`, Cura's
//! `;TYPE:WALL-OUTER`, ...; [`settle_gcode::Reader::features`]): over each type's working
//! samples, the worst (with its spot) and the 95th percentile, and per layer the worst
//! and the 95th percentile of each type (the error-against-Z figure, layer_features.csv,
//! the outer wall's columns of the layers table). The outer wall is what a print is judged
//! by ([`is_outer_wall`]).
//!
//! A sample is counted in its type's current-layer histogram only (its error binned a
//! batch at a time, [`Histogram::push_all`]); each layer's end adds those into the types'
//! whole-job histograms and the layer's own ([`FeatureAccount::end_layer`]): the same
//! counts, one histogram touched per sample instead of three.
//!
//! Memory: two histograms per type (the whole job's and the current layer's; at most
//! [`settle_gcode::MAX_FEATURES`] types) and two numbers per layer and type.

use std::collections::BTreeMap;

use super::stats::{Histogram, Spot};

/// Errors binned at a time ([`FeatureAccount::sample`]).
const BATCH: usize = 256;

/// One feature type's account.
#[derive(Debug, Clone, Default)]
pub struct FeatureStats {
    /// Its errors (um), up to the last layer ended ([`FeatureAccount::end_layer`]).
    pub errors: Histogram,
    /// Its largest error.
    pub worst: Option<Spot>,
}

impl FeatureStats {
    /// Its largest error (um), 0 without samples.
    pub fn worst_um(&self) -> f64 {
        self.worst.as_ref().map_or(0.0, |s| s.error_um)
    }
}

/// The account by feature type: index as [`settle_gcode::Move::feature`].
#[derive(Debug, Clone, Default)]
pub struct FeatureAccount {
    /// Per feature index.
    pub stats: BTreeMap<u16, FeatureStats>,
    /// Per (layer, feature index), its worst error (um).
    pub layer_worst: BTreeMap<(u32, u16), f64>,
    /// Per (layer, feature index), the 95th percentile of its errors (um); NaN when the
    /// layer's samples came in two separate runs (its percentile is then not known).
    pub layer_p95: BTreeMap<(u32, u16), f64>,
    /// Per feature index, the current layer's errors (cleared at each layer's end).
    current: BTreeMap<u16, Histogram>,
    /// The account of the feature and layer of the last sample, taken out of the maps
    /// while their samples come (samples come feature after feature: one look-up per
    /// change, not per sample), put back when another comes or the layer ends.
    hot: Option<Hot>,
    /// The errors (um) of the hot account's samples not counted in its current layer's
    /// histogram yet (fewer than [`BATCH`]).
    pending: Vec<f64>,
}

/// One feature's account in one layer, out of [`FeatureAccount`]'s maps.
#[derive(Debug, Clone)]
struct Hot {
    feature: u16,
    layer: u32,
    stats: FeatureStats,
    current: Histogram,
    /// The largest error (um) of its samples since it was taken out, from 0.
    layer_worst: f64,
}

impl FeatureAccount {
    /// A working sample of feature `feature` in `layer`: its error (um), and, when it may
    /// be the feature's worst ([`FeatureAccount::is_worst`]), where it is (`spot` is
    /// called only then).
    pub fn sample(&mut self, feature: u16, layer: u32, err_um: f64, spot: impl FnOnce() -> Spot) {
        let h = match &mut self.hot {
            Some(h) if h.feature == feature && h.layer == layer => h,
            _ => {
                self.put_back();
                self.hot.insert(Hot {
                    feature,
                    layer,
                    stats: self.stats.remove(&feature).unwrap_or_default(),
                    current: self.current.remove(&feature).unwrap_or_default(),
                    layer_worst: 0.0,
                })
            }
        };
        if h.stats.worst.as_ref().is_none_or(|w| err_um > w.error_um) {
            h.stats.worst = Some(spot());
        }
        h.layer_worst = h.layer_worst.max(err_um);
        self.pending.push(err_um);
        if self.pending.len() >= BATCH {
            h.current.push_all(&self.pending);
            self.pending.clear();
        }
    }

    /// Whether an error of `err_um` of feature `feature` would be its worst so far.
    pub fn is_worst(&self, feature: u16, err_um: f64) -> bool {
        let stats = match &self.hot {
            Some(h) if h.feature == feature => Some(&h.stats),
            _ => self.stats.get(&feature),
        };
        stats.is_none_or(|s| s.worst.as_ref().is_none_or(|w| err_um > w.error_um))
    }

    /// Put the hot account back into the maps.
    fn put_back(&mut self) {
        let Some(mut h) = self.hot.take() else {
            return;
        };
        h.current.push_all(&self.pending);
        self.pending.clear();
        self.stats.insert(h.feature, h.stats);
        self.current.insert(h.feature, h.current);
        let w = self.layer_worst.entry((h.layer, h.feature)).or_insert(0.0);
        *w = w.max(h.layer_worst);
    }

    /// The end of layer `layer`'s samples: each type's 95th percentile over them, its
    /// errors added to its whole job's and to `layer_errors` (every account back in the
    /// maps, where they are read).
    pub fn end_layer(&mut self, layer: u32, layer_errors: &mut Histogram) {
        self.put_back();
        // The two maps hold the same types (put back together).
        for ((&f, h), s) in self.current.iter_mut().zip(self.stats.values_mut()) {
            if h.total() == 0 {
                continue;
            }
            let p95 = h.quantile_um(0.95);
            self.layer_p95
                .entry((layer, f))
                .and_modify(|v| *v = f64::NAN)
                .or_insert(p95);
            s.errors.merge(h);
            layer_errors.merge(h);
            h.clear();
        }
    }

    /// Whether any sample came from a named feature type (index above 0).
    pub fn has_named(&self) -> bool {
        self.stats.keys().any(|&f| f > 0)
    }
}

/// Whether a slicer's feature name is the outer wall: PrusaSlicer and SuperSlicer's
/// `External perimeter`, OrcaSlicer and BambuStudio's `Outer wall`, Cura's `WALL-OUTER`.
pub fn is_outer_wall(name: &str) -> bool {
    let n = name.trim().to_ascii_lowercase();
    matches!(n.as_str(), "external perimeter" | "outer wall" | "wall-outer")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::studies::gcode::stats::Split;

    /// The deferred account counts what counting every sample in every histogram at once
    /// counts: each type's whole-job histogram, each layer's, each type's percentile per
    /// layer, on random runs of samples (types switching within layers, a type back in a
    /// later layer, errors over the histogram's whole range).
    #[test]
    fn deferred_counts_are_the_direct_counts() {
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        let mut next = |n: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % n
        };
        let mut acc = FeatureAccount::default();
        let mut layer_errors = Histogram::default();
        let (mut direct_job, mut direct_layer) = (BTreeMap::new(), Histogram::default());
        let mut direct_current: BTreeMap<u16, Histogram> = BTreeMap::new();
        let quantiles = |h: &Histogram| -> Vec<u64> {
            (0..=50).map(|i| h.quantile_um(f64::from(i) / 50.0).to_bits()).collect()
        };
        for layer in 0..6u32 {
            for _ in 0..40 {
                let feature = next(5) as u16;
                for _ in 0..next(700) {
                    // 1e-4 um to 1e6 um: below the first bin's edge to past the last.
                    let err_um = 10f64.powf(next(1_000_000) as f64 / 1e5 - 4.0);
                    let spot = || Spot {
                        error_um: err_um,
                        time_s: 0.0,
                        x_mm: 0.0,
                        y_mm: 0.0,
                        line: 0,
                        layer,
                        move_index: 0,
                        split: Split::default(),
                    };
                    acc.sample(feature, layer, err_um, spot);
                    direct_job
                        .entry(feature)
                        .or_insert_with(Histogram::default)
                        .push(err_um);
                    direct_current.entry(feature).or_default().push(err_um);
                    direct_layer.push(err_um);
                }
            }
            acc.end_layer(layer, &mut layer_errors);
            assert!(layer_errors == direct_layer, "layer {layer}");
            assert_eq!(quantiles(&layer_errors), quantiles(&direct_layer));
            for (f, h) in &mut direct_current {
                if h.total() > 0 {
                    let p95 = acc.layer_p95[&(layer, *f)];
                    assert_eq!(p95.to_bits(), h.quantile_um(0.95).to_bits());
                }
                h.clear();
            }
            layer_errors.clear();
            direct_layer.clear();
        }
        assert_eq!(acc.stats.len(), direct_job.len());
        for (f, h) in &direct_job {
            let got = &acc.stats[f].errors;
            assert!(got == h, "feature {f}");
            assert_eq!(quantiles(got), quantiles(h), "feature {f}");
        }
    }
}
