//! A static bounding-box tree for nearest-primitive queries: the distance from a point to a
//! path of `n` pieces in about `O(log n)` box tests and a handful of exact distances,
//! instead of `O(n)`. Built once per plan; queries do not allocate.

use super::vector::V3;

/// Primitives per leaf.
const LEAF: usize = 4;
/// Query stack depth (the tree is balanced: depth ~ log2(n / LEAF) + 1).
const STACK: usize = 64;

#[derive(Debug, Clone, PartialEq)]
struct Node {
    lo: V3,
    hi: V3,
    /// Leaf: primitives `order[first..first + count]`; `count == 0` for inner nodes.
    first: u32,
    count: u32,
    /// Inner node: the children.
    left: u32,
    right: u32,
}

/// The tree. Leaves hold primitive indices.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// Each primitive's box, to skip exact distances that cannot win.
    boxes: Vec<(V3, V3)>,
}

fn union(boxes: &[(V3, V3)], idx: &[u32]) -> (V3, V3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in idx {
        let (l, h) = boxes[i as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(l[k]);
            hi[k] = hi[k].max(h[k]);
        }
    }
    (lo, hi)
}

/// Squared distance from `q` to the box (0 inside).
#[inline]
fn box_dist2(q: V3, lo: V3, hi: V3) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let e = (lo[k] - q[k]).max(q[k] - hi[k]).max(0.0);
        d2 += e * e;
    }
    d2
}

impl Bvh {
    /// Build over primitives with bounding boxes `boxes` (`(lo, hi)` each).
    pub(crate) fn build(boxes: &[(V3, V3)]) -> Self {
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = Vec::new();
        if !boxes.is_empty() {
            let n = order.len();
            split(boxes, &mut order, 0, n, &mut nodes);
        }
        Self {
            nodes,
            order,
            boxes: boxes.to_vec(),
        }
    }

    /// The nearest primitive to `q` by the exact distance `dist(index)`, starting from the
    /// bound given by `hint` (a primitive likely to be close, e.g. the last answer).
    /// Returns `(distance, index)`; `(inf, usize::MAX)` for an empty tree.
    pub(crate) fn nearest(
        &self,
        q: V3,
        dist: impl Fn(usize) -> f64,
        hint: Option<usize>,
    ) -> (f64, usize) {
        let mut best = (f64::INFINITY, usize::MAX);
        if let Some(h) = hint.filter(|&h| h < self.order.len()) {
            best = (dist(h), h);
        }
        if self.nodes.is_empty() {
            return best;
        }
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            let bd = box_dist2(q, node.lo, node.hi);
            if bd >= best.0 * best.0 {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for &i in &self.order[first..first + node.count as usize] {
                    let (lo, hi) = self.boxes[i as usize];
                    if box_dist2(q, lo, hi) >= best.0 * best.0 {
                        continue;
                    }
                    let d = dist(i as usize);
                    if d < best.0 {
                        best = (d, i as usize);
                    }
                }
            } else {
                let (l, r) = (
                    &self.nodes[node.left as usize],
                    &self.nodes[node.right as usize],
                );
                let (dl, dr) = (box_dist2(q, l.lo, l.hi), box_dist2(q, r.lo, r.hi));
                // Push the farther child first so the nearer is searched first.
                let (near, far) = if dl <= dr {
                    (node.left, node.right)
                } else {
                    (node.right, node.left)
                };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        best
    }
}

/// Build the subtree over `order[start..end]`, returning its node index.
fn split(
    boxes: &[(V3, V3)],
    order: &mut [u32],
    start: usize,
    end: usize,
    nodes: &mut Vec<Node>,
) -> u32 {
    let (lo, hi) = union(boxes, &order[start..end]);
    let me = nodes.len() as u32;
    nodes.push(Node {
        lo,
        hi,
        first: start as u32,
        count: (end - start) as u32,
        left: 0,
        right: 0,
    });
    if end - start <= LEAF {
        return me;
    }
    // Split at the median centroid along the longest box axis.
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let centre = |i: u32| {
        let (l, h) = boxes[i as usize];
        l[axis] + h[axis]
    };
    let mid = (start + end) / 2;
    order[start..end].select_nth_unstable_by(mid - start, |&a, &b| centre(a).total_cmp(&centre(b)));
    let left = split(boxes, order, start, mid, nodes);
    let right = split(boxes, order, mid, end, nodes);
    let n = &mut nodes[me as usize];
    n.count = 0;
    n.left = left;
    n.right = right;
    me
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_equals_brute_force() {
        // Unit boxes around points on a spiral; the distance is to the box centre.
        let centres: Vec<V3> = (0..500)
            .map(|i| {
                let t = i as f64 * 0.1;
                [t.cos() * t, t.sin() * t, 0.01 * t]
            })
            .collect();
        let boxes: Vec<(V3, V3)> = centres.iter().map(|&c| (c, c)).collect();
        let tree = Bvh::build(&boxes);
        let d = |q: V3, i: usize| super::super::vector::dist(q, centres[i]);
        for k in 0..200 {
            let q = [
                (k as f64 * 0.37).sin() * 40.0,
                (k as f64 * 0.11).cos() * 40.0,
                0.3,
            ];
            let (best, i) = tree.nearest(q, |i| d(q, i), None);
            let brute = (0..centres.len())
                .map(|i| d(q, i))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(best, brute);
            assert_eq!(d(q, i), brute);
            let (hinted, _) = tree.nearest(q, |i| d(q, i), Some(k));
            assert_eq!(hinted, brute);
        }
    }
}
