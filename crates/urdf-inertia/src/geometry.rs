//! The few vector operations the integration kernel, the mesh repair, the convex hull and the overlap
//! estimate share, on plain `[f64; 3]` (what the readers produce). `sub` is `inline(always)`: the
//! kernel calls it in its hot loop.

/// The smallest relative error estimate of a computed value: the compensated kernel's results are
/// within a few units of 2⁻⁵³ of the exact value on every stiff case measured (docs/accuracy.md);
/// 4ε = 8·2⁻⁵³ leaves a margin. The mesh health's estimates, the writer and the formatter share it.
pub const ROUND_OFF_FLOOR: f64 = 4.0 * f64::EPSILON;

/// `a − b`.
#[inline(always)]
pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a × b`.
#[inline]
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a · b`.
#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
