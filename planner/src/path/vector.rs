//! Small 3-vector helpers for path geometry (2-D paths use `z = 0`).

/// A point or direction in space (m, m/s, ... by context).
pub type V3 = [f64; 3];

/// `a + b`.
#[inline]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `k a`.
#[inline]
pub fn scale(a: V3, k: f64) -> V3 {
    [k * a[0], k * a[1], k * a[2]]
}

/// `a + k b`.
#[inline]
pub fn axpy(a: V3, k: f64, b: V3) -> V3 {
    [a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]]
}

/// Dot product.
#[inline]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Euclidean norm.
#[inline]
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// Distance between two points.
#[inline]
pub fn dist(a: V3, b: V3) -> f64 {
    norm(sub(a, b))
}

/// The point `q` given as a slice of 2 or 3 coordinates, as a `V3` (missing z = 0).
#[inline]
pub fn from_slice(q: &[f64]) -> V3 {
    [
        q.first().copied().unwrap_or(0.0),
        q.get(1).copied().unwrap_or(0.0),
        q.get(2).copied().unwrap_or(0.0),
    ]
}
