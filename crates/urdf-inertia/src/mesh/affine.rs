//! Node transforms of the scene-graph formats (COLLADA, glTF): a linear part and a translation,
//! composed parent first.

use crate::mass::{mat_mul, mat_vec, Mat3};

/// `p ↦ m·p + t`.
pub(crate) type Affine = (Mat3, [f64; 3]);

pub(crate) const IDENTITY: Affine = (
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    [0.0; 3],
);

/// `a` after `b`: `p ↦ a(b(p))`.
pub(crate) fn compose(a: &Affine, b: &Affine) -> Affine {
    let m = mat_mul(&a.0, &b.0);
    let t = mat_vec(&a.0, b.1);
    (m, [t[0] + a.1[0], t[1] + a.1[1], t[2] + a.1[2]])
}

/// Whether the transform mirrors (negative determinant): faces must then be reversed to stay outward.
pub(crate) fn mirrors(xf: &Affine) -> bool {
    let m = &xf.0;
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    det < 0.0
}
