//! Exact rational vectors for the tests' own geometry (convex volumes, planes), independent of the
//! library's predicates.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};
use std::cmp::Ordering;

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

/// Points of one convex polygon in the plane of normal `n`, ordered counter-clockwise seen along n
/// (by half-plane about the first point, then by the sign of the cross product: exact).
#[allow(dead_code)]
pub fn ring(n: &V, points: &[V]) -> Vec<V> {
    let count = Q::from_integer(BigInt::from(points.len()));
    let g: V = std::array::from_fn(|m| points.iter().fold(Q::zero(), |s, p| s + &p[m]) / &count);
    let r = vsub(&points[0], &g);
    let half = |v: &V| {
        let s = vdot(n, &vcross(&r, v));
        !(s.is_positive() || (s.is_zero() && vdot(&r, v).is_positive()))
    };
    let mut rel: Vec<V> = points.iter().map(|p| vsub(p, &g)).collect();
    rel.sort_by(|u, v| {
        half(u).cmp(&half(v)).then_with(|| {
            let s = vdot(n, &vcross(u, v));
            if s.is_positive() {
                Ordering::Less
            } else if s.is_negative() {
                Ordering::Greater
            } else {
                Ordering::Equal
            }
        })
    });
    rel.iter()
        .map(|u| std::array::from_fn(|m| &u[m] + &g[m]))
        .collect()
}
