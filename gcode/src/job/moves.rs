//! The moves in flight: which planned segments belong to which G-code move, when each
//! move runs, and the per-layer print-time account.
//!
//! Planned segments come out of the planner in order, each with the id (`seq`) it was
//! pushed with; a G-code move owns a contiguous run of ids (an arc one per segment). A
//! move is complete once a segment with a later id has come out (or the planner is done):
//! its span is then from its first segment's start to its last segment's end. Segments
//! the firmware dropped or merged into the next block never come out; a move with none is
//! placed, with no duration, where the next segment starts.

use std::collections::VecDeque;
use std::sync::Arc;

use super::chunk::{LayerTime, MoveInfo};
use crate::LayerSource;

/// A move whose segments are still coming.
#[derive(Debug)]
struct Pending {
    info: MoveInfo,
    /// Its ids: `first..end`.
    first: u64,
    end: u64,
    started: bool,
}

/// Moves in flight and finished moves a chunk may still need (module doc).
#[derive(Debug, Default)]
pub(crate) struct MoveTable {
    pending: VecDeque<Pending>,
    done: VecDeque<Arc<MoveInfo>>,
    /// End of the last segment seen (s).
    last_end_s: f64,
    account: Account,
    /// The first move planned longer than [`crate::MAX_STEP_DURATION_S`]: its line and
    /// duration (s).
    too_long: Option<(u64, f64)>,
}

impl MoveTable {
    /// A move owning ids `first..end` (times unset).
    pub(crate) fn add(&mut self, info: MoveInfo, first: u64, end: u64) {
        self.pending.push_back(Pending {
            info,
            first,
            end,
            started: false,
        });
    }

    /// A planned segment `seq` runs from `t0_s` to `t1_s`; returns the layer of its move.
    pub(crate) fn planned(&mut self, seq: u64, t0_s: f64, t1_s: f64) -> Option<u32> {
        while self.pending.front().is_some_and(|p| p.end <= seq) {
            self.complete_front(t0_s);
        }
        let p = self.pending.front_mut()?;
        if seq < p.first {
            return None;
        }
        if !p.started {
            p.started = true;
            p.info.start_time_s = t0_s;
        }
        p.info.duration_s = t1_s - p.info.start_time_s;
        if p.info.duration_s > crate::MAX_STEP_DURATION_S {
            self.too_long
                .get_or_insert((p.info.line, p.info.duration_s));
        }
        self.last_end_s = t1_s;
        let layer = p.info.layer;
        if seq + 1 >= p.end {
            self.complete_front(t1_s);
        }
        Some(layer)
    }

    /// The first move planned longer than [`crate::MAX_STEP_DURATION_S`] (its line and
    /// duration, s), once.
    pub(crate) fn take_too_long(&mut self) -> Option<(u64, f64)> {
        self.too_long.take()
    }

    /// The planner is done: every move is complete (those without segments at `at_s`).
    pub(crate) fn flush(&mut self, at_s: f64) {
        while !self.pending.is_empty() {
            self.complete_front(at_s);
        }
    }

    fn complete_front(&mut self, at_s: f64) {
        if let Some(mut p) = self.pending.pop_front() {
            if !p.started {
                p.info.start_time_s = at_s;
                p.info.duration_s = 0.0;
            }
            self.account.add(&p.info);
            self.done.push_back(Arc::new(p.info));
        }
    }

    /// Up to when every move that has started is complete (s): chunks ending there can
    /// list all their moves.
    pub(crate) fn complete_until_s(&self) -> f64 {
        match self.pending.front() {
            Some(p) if p.started => p.info.start_time_s,
            Some(_) => self.last_end_s,
            None => f64::INFINITY,
        }
    }

    /// The finished moves meeting `[a, b]`; forgets those ending before `a`.
    pub(crate) fn overlapping(&mut self, a: f64, b: f64) -> Vec<Arc<MoveInfo>> {
        while self.done.front().is_some_and(|m| m.end_time_s() < a) {
            self.done.pop_front();
        }
        self.done
            .iter()
            .take_while(|m| m.start_time_s <= b)
            .filter(|m| m.end_time_s() >= a)
            .cloned()
            .collect()
    }

    /// Forget finished moves ending before `t_s` (no chunk will ask for them).
    pub(crate) fn forget_before(&mut self, t_s: f64) {
        while self.done.front().is_some_and(|m| m.end_time_s() < t_s) {
            self.done.pop_front();
        }
    }

    /// The layer `z_mm` starts (from the file's layer markers or a change of Z, `source`).
    pub(crate) fn layer_z(&mut self, layer: u32, z_mm: Option<f64>, source: LayerSource) {
        self.account.z.push((layer, z_mm, source));
        if self.account.z.len() > 64 {
            self.account.z.remove(0);
        }
    }

    /// The account so far, with the current layer closed at `end_s`.
    pub(crate) fn layers(&self, end_s: f64) -> Vec<LayerTime> {
        let mut out = self.account.closed.clone();
        if let Some(mut c) = self.account.current.clone() {
            c.duration_s = end_s - c.start_time_s;
            out.push(c);
        }
        out
    }
}

/// Print time per layer: a layer runs from its first move's start to the next layer's.
#[derive(Debug, Default)]
struct Account {
    closed: Vec<LayerTime>,
    current: Option<LayerTime>,
    /// Recent layer changes: (layer, Z, what found it).
    z: Vec<(u32, Option<f64>, LayerSource)>,
}

impl Account {
    fn add(&mut self, m: &MoveInfo) {
        let same = self.current.as_ref().is_some_and(|c| c.layer == m.layer);
        if !same {
            let start = match self.current.take() {
                Some(mut c) => {
                    c.duration_s = m.start_time_s - c.start_time_s;
                    self.closed.push(c);
                    m.start_time_s
                }
                None => 0.0,
            };
            let change = self.z.iter().rev().find(|(l, _, _)| *l == m.layer);
            let (z_mm, opened_by) = change.map_or((None, None), |&(_, z, s)| (z, Some(s)));
            self.current = Some(LayerTime {
                layer: m.layer,
                z_mm,
                start_time_s: start,
                duration_s: 0.0,
                moves: 0,
                working_s: 0.0,
                print_z_mm: None,
                opened_by,
            });
        }
        if let Some(c) = self.current.as_mut() {
            c.moves += 1;
            if m.working {
                c.working_s += m.duration_s;
                // A marker without a Z (Cura's `;LAYER:n`): the layer is where its first
                // working move in a plane runs.
                if c.z_mm.is_none() && m.start_mm.z_mm == m.end_mm.z_mm {
                    c.z_mm = Some(m.end_mm.z_mm);
                }
                if m.tool == crate::Tool::Off {
                    let (a, b) = (m.start_mm.z_mm, m.end_mm.z_mm);
                    let [lo, hi] = c.print_z_mm.get_or_insert([a, a]);
                    (*lo, *hi) = (lo.min(a).min(b), hi.max(a).max(b));
                }
            }
        }
    }
}
