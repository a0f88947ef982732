//! Exact rational vectors for the tests' own geometry (convex volumes, planes), independent of the
//! library's predicates.

use num_rational::BigRational;

pub type Q = BigRational;
pub type V = [Q; 3];

/// The f64 as the exact rational it is.
pub fn q(x: f64) -> Q {
    super::rat(x)
}

pub fn vsub(a: &V, b: &V) -> V {
    std::array::from_fn(|k| &a[k] - &b[k])
}

pub fn vdot(a: &V, b: &V) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}

pub fn vcross(a: &V, b: &V) -> V {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}
