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

/// Whether the boxes (lowest and highest corners) of the `members` have a common point (closed).
pub fn boxes_meet(members: &[usize], boxes: &[([f64; 3], [f64; 3])]) -> bool {
    (0..3).all(|k| {
        let lo = members
            .iter()
            .map(|&i| boxes[i].0[k])
            .fold(f64::MIN, f64::max);
        let hi = members
            .iter()
            .map(|&i| boxes[i].1[k])
            .fold(f64::MAX, f64::min);
        lo <= hi
    })
}
