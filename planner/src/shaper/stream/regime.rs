//! One shaper's share of a stream: the impulses, and the span of input it shapes.
//!
//! Regime `r` shapes `x_r(s)`: the input on its span `[T_r, T_{r+1}]`, continued outside
//! it at the velocity it has at the span's ends (the first regime's span is open below,
//! the last's above). The stream's output is
//! `q(t) = sum_r sum_i w_ri x_r(t - tau_ri) - sum_{r >= 1} L_r(t - c_r)` with
//! `L_r(s) = p(T_r) + v(T_r) (s - T_r)` the continuation every later regime starts from
//! and `c_r` its centroid: shaping a straight line `L_r` only delays it by `c_r`, so
//! subtracting `L_r(t - c_r)` removes what `x_r` shares with the regimes before it.

use super::alignment::Alignment;
use crate::Sample;
use crate::shaper::Shaper;

/// A boundary of a span: time (s), input position and velocity there.
type Edge = (f64, f64, f64);

/// One shaper and the input span it shapes (module doc).
#[derive(Debug, Clone)]
pub(super) struct Regime {
    weights: Vec<f64>,
    taus: Vec<f64>,
    centroid_s: f64,
    /// Lower end of the span (`None`: open).
    pub(super) from: Option<Edge>,
    /// Upper end of the span (`None`: open).
    pub(super) until: Option<Edge>,
    /// Whether `L_r(t - c_r)` is subtracted (every regime but the first).
    corrects: bool,
}

impl Regime {
    /// The regime of `shaper` (`None`: the identity) starting at `from`.
    pub(super) fn new(shaper: Option<&Shaper>, alignment: Alignment, from: Option<Edge>) -> Self {
        let (weights, times): (Vec<f64>, Vec<f64>) = match shaper {
            Some(s) => (s.weights().collect(), s.times_s().to_vec()),
            None => (vec![1.0], vec![0.0]),
        };
        let centroid: f64 = weights.iter().zip(&times).map(|(w, t)| w * t).sum();
        let (taus, centroid_s) = match alignment {
            Alignment::Causal => (times, centroid),
            Alignment::Centred => (times.iter().map(|t| t - centroid).collect(), 0.0),
        };
        Self {
            weights,
            taus,
            centroid_s,
            corrects: from.is_some(),
            from,
            until: None,
        }
    }

    /// Whether this is the only regime and shapes nothing (one impulse of weight 1 at 0).
    pub(super) fn is_identity(&self) -> bool {
        !self.corrects && self.weights == [1.0] && self.taus == [0.0]
    }

    /// The impulse times (s), increasing.
    pub(super) fn taus(&self) -> &[f64] {
        &self.taus
    }

    /// The earliest impulse time, at most 0 (s).
    pub(super) fn min_tau(&self) -> f64 {
        self.taus.first().copied().unwrap_or(0.0).min(0.0)
    }

    /// The latest impulse time, at least 0 (s).
    pub(super) fn max_tau(&self) -> f64 {
        self.taus.last().copied().unwrap_or(0.0).max(0.0)
    }

    /// The times of the span's ends.
    pub(super) fn bounds(&self) -> [Option<f64>; 2] {
        [self.from.map(|e| e.0), self.until.map(|e| e.0)]
    }

    /// Add this regime's share of the output at `t` to `out`; `input(i, s)` evaluates the
    /// stream's input at `s` for impulse `i` (its index in [`Self::taus`]).
    pub(super) fn add_to(
        &self,
        out: &mut Sample,
        t: f64,
        mut input: impl FnMut(usize, f64) -> Sample,
    ) {
        let line = |e: Edge, s: f64| Sample {
            p: e.1 + e.2 * (s - e.0),
            v: e.2,
            a: 0.0,
            j: 0.0,
        };
        for (i, (w, tau)) in self.weights.iter().zip(&self.taus).enumerate() {
            let s = t - tau;
            let x = match (self.from, self.until) {
                (Some(e), _) if s < e.0 => line(e, s),
                (_, Some(e)) if s > e.0 => line(e, s),
                _ => input(i, s),
            };
            out.p += w * x.p;
            out.v += w * x.v;
            out.a += w * x.a;
            out.j += w * x.j;
        }
        if let (true, Some(e)) = (self.corrects, self.from) {
            let l = line(e, t - self.centroid_s);
            out.p -= l.p;
            out.v -= l.v;
        }
    }

    /// Whether every shifted copy has passed the span's end by `t` (from then on the
    /// regime's share is a straight line).
    pub(super) fn done_by(&self, t: f64) -> bool {
        self.until.is_some_and(|e| t - self.max_tau() >= e.0)
    }

    /// The constant this regime leaves once done, given the regime after it: its straight
    /// line minus the next regime's correction, `v(T) (c_next - c_self)`.
    pub(super) fn retire_offset(&self, next: &Regime) -> f64 {
        next.from
            .map_or(0.0, |e| e.2 * (next.centroid_s - self.centroid_s))
    }

    /// This regime is now the oldest: nothing before it to correct for.
    pub(super) fn becomes_first(&mut self) {
        self.corrects = false;
    }
}
