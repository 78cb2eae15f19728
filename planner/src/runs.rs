//! Sorting numbers that arrive as a few sorted runs (the breakpoints of several
//! profiles, or of shifted copies of one): merging the runs gives the order a full sort
//! gives, at a fraction of its cost.

use std::cmp::Ordering;

/// Sorts numbers given as runs (module doc); keeps its buffers between sorts.
#[derive(Debug, Clone, Default)]
pub(crate) struct RunSort {
    /// Where the runs start (non-decreasing), then the bounds of the runs being merged.
    bounds: Vec<usize>,
    /// The other buffer of the merge.
    spare: Vec<f64>,
}

impl RunSort {
    /// A run starts at index `at` of the numbers to sort (marks do not decrease).
    pub(crate) fn mark(&mut self, at: usize) {
        self.bounds.push(at);
    }

    /// Sort `v` by [`f64::total_cmp`], `v` being the runs that start at the marked
    /// indices (and at 0; marks past the end are ignored), then forget the marks. A run
    /// out of order is sorted on its own first, so any marks give the right result; the
    /// fewer and longer the runs that are in order or nearly, the less it costs.
    ///
    /// The result is exactly `v.sort_by(f64::total_cmp)`: that order is total, and two
    /// numbers it finds equal have the same bits, so there is only one sorted
    /// arrangement.
    pub(crate) fn sort(&mut self, v: &mut Vec<f64>) {
        let n = v.len();
        let b = &mut self.bounds;
        b.retain(|&s| s > 0 && s < n);
        b.insert(0, 0);
        b.push(n);
        b.dedup();
        for w in b.windows(2) {
            sort_nearly_sorted(&mut v[w[0]..w[1]]);
        }
        // Merge neighbouring runs pairwise until one is left; the merged runs' bounds
        // overwrite the ones already read.
        while b.len() > 2 {
            self.spare.clear();
            let runs = b.len() - 1;
            let mut k = 1;
            for i in (0..runs).step_by(2) {
                let (lo, mid) = (b[i], b[i + 1]);
                let hi = b.get(i + 2).copied().unwrap_or(mid);
                merge(&v[lo..mid], &v[mid..hi], &mut self.spare);
                b[k] = self.spare.len();
                k += 1;
            }
            b.truncate(k);
            std::mem::swap(v, &mut self.spare);
        }
        b.clear();
    }
}

/// Sort `run` by [`f64::total_cmp`]: by insertion while it is nearly in order (a few
/// neighbours swapped by rounding cost a few moves), by a full sort once that has moved
/// more than a few times its length (any order is then sorted correctly, only slower).
fn sort_nearly_sorted(run: &mut [f64]) {
    let budget = 4 * run.len() + 16;
    let mut moved = 0;
    for i in 1..run.len() {
        let x = run[i];
        let mut j = i;
        while j > 0 && run[j - 1].total_cmp(&x) == Ordering::Greater {
            run[j] = run[j - 1];
            j -= 1;
        }
        run[j] = x;
        moved += i - j;
        if moved > budget {
            run.sort_by(f64::total_cmp);
            return;
        }
    }
}

/// Append the merge of the sorted `a` and `b` to `out`.
fn merge(a: &[f64], b: &[f64], out: &mut Vec<f64>) {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if b[j].total_cmp(&a[i]) == Ordering::Less {
            out.push(b[j]);
            j += 1;
        } else {
            out.push(a[i]);
            i += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (xorshift64*), so the test needs no dependency.
    fn next(state: &mut u64) -> u64 {
        *state ^= *state >> 12;
        *state ^= *state << 25;
        *state ^= *state >> 27;
        state.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Bit for bit the full sort, on random runs: in order or not, empty, with repeated
    /// values, both zeros, infinities and NaNs of both signs, run starts repeated or
    /// past the end.
    #[test]
    fn merging_runs_gives_the_full_sort_bit_for_bit() {
        let specials = [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -f64::NAN,
            1.0,
        ];
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        // One sorter for every case: its buffers carry over.
        let mut sorter = RunSort::default();
        for case in 0..2000 {
            // Short and long runs: a long run out of order takes the full sort.
            let n = (next(&mut state) % if case % 5 == 0 { 300 } else { 40 }) as usize;
            let mut v: Vec<f64> = (0..n)
                .map(|_| match next(&mut state) % 8 {
                    0 => specials[(next(&mut state) % 7) as usize],
                    _ => ((next(&mut state) % 1000) as f64 - 500.0) * 0.125,
                })
                .collect();
            let mut starts = vec![];
            let mut s = if case % 3 == 0 {
                0
            } else {
                (next(&mut state) % 3) as usize
            };
            let step = 1 + n / 4;
            while s <= n + 2 {
                starts.push(s);
                if next(&mut state).is_multiple_of(8) {
                    // A run of none.
                    starts.push(s);
                }
                s += 1 + (next(&mut state) as usize) % step;
            }
            // Most runs in order or nearly (neighbours swapped), as the callers' are.
            for w in starts.windows(2) {
                let (lo, hi) = (w[0].min(n), w[1].min(n));
                let run = &mut v[lo..hi.max(lo)];
                match next(&mut state) % 4 {
                    0 => {}
                    1 => {
                        run.sort_by(f64::total_cmp);
                        for _ in 0..run.len() / 4 {
                            let i = (next(&mut state) as usize) % run.len();
                            run.swap(i, (i + 1).min(run.len() - 1));
                        }
                    }
                    _ => run.sort_by(f64::total_cmp),
                }
            }
            let mut want = v.clone();
            want.sort_by(f64::total_cmp);
            for &s in &starts {
                sorter.mark(s);
            }
            sorter.sort(&mut v);
            let bits = |x: &[f64]| x.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&v), bits(&want), "case {case}, starts {starts:?}");
        }
    }
}
