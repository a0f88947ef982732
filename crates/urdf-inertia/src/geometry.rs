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

/// `|a|`.
#[inline]
pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The signed solid angle of the triangle with corners `a`, `b`, `c` seen from the origin, their
/// lengths given (Van Oosterom and Strackee 1983): 4π times its share of a winding number.
pub(crate) fn solid_angle(a: [f64; 3], b: [f64; 3], c: [f64; 3], la: f64, lb: f64, lc: f64) -> f64 {
    let det = dot(a, cross(b, c));
    let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    2.0 * det.atan2(den)
}

/// An axis-aligned box. [`Aabb::EMPTY`] (lo = +∞, hi = −∞) is the fold's start: adding a point
/// makes it that point's box. NaN coordinates are skipped, as `f64::min`/`max` skip them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl Aabb {
    /// The box of no point.
    pub const EMPTY: Aabb = Aabb {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    /// The box from its corners.
    pub const fn new(lo: [f64; 3], hi: [f64; 3]) -> Aabb {
        Aabb { lo, hi }
    }

    /// The box of `points` ([`Aabb::EMPTY`] for none).
    pub fn of(points: impl IntoIterator<Item = [f64; 3]>) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in points {
            b.add(p);
        }
        b
    }

    /// Grows the box to hold `p`.
    #[inline]
    pub fn add(&mut self, p: [f64; 3]) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(p[k]);
            self.hi[k] = self.hi[k].max(p[k]);
        }
    }

    /// The box of both.
    #[must_use]
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            lo: [0, 1, 2].map(|k| self.lo[k].min(other.lo[k])),
            hi: [0, 1, 2].map(|k| self.hi[k].max(other.hi[k])),
        }
    }

    /// Where both meet (empty along an axis where they do not: lo > hi).
    #[must_use]
    pub fn intersection(self, other: Aabb) -> Aabb {
        Aabb {
            lo: [0, 1, 2].map(|k| self.lo[k].max(other.lo[k])),
            hi: [0, 1, 2].map(|k| self.hi[k].min(other.hi[k])),
        }
    }

    /// Whether the two boxes share a positive volume (touching faces, edges or corners do not).
    pub fn overlaps(&self, other: &Aabb) -> bool {
        (0..3).all(|k| self.lo[k].max(other.lo[k]) < self.hi[k].min(other.hi[k]))
    }

    /// Whether `inner` lies within the box (faces included).
    pub fn contains(&self, inner: &Aabb) -> bool {
        (0..3).all(|k| self.lo[k] <= inner.lo[k] && inner.hi[k] <= self.hi[k])
    }

    /// The extent along each axis (`hi − lo`).
    pub fn extent(&self) -> [f64; 3] {
        sub(self.hi, self.lo)
    }

    /// The largest extent along an axis (0 for a point, −∞ for the empty box).
    pub fn largest_extent(&self) -> f64 {
        let e = self.extent();
        e[0].max(e[1]).max(e[2])
    }

    /// The length of the diagonal.
    pub fn diagonal(&self) -> f64 {
        let e = self.extent();
        dot(e, e).sqrt()
    }
}

/// Each pair of `boxes` whose ranges along x overlap (the second starts before the first ends),
/// found by a sweep along x: `visit(a, b)` with `a` the box that starts first, until it breaks.
/// The pairs the overlap checks of components go through; each applies its own test and its own
/// limit.
pub(crate) fn x_sweep(
    boxes: &[Aabb],
    visit: impl FnMut(usize, usize) -> std::ops::ControlFlow<()>,
) -> std::ops::ControlFlow<()> {
    sweep(boxes, 0, visit)
}

/// [`x_sweep`] along `axis`.
pub(crate) fn sweep(
    boxes: &[Aabb],
    axis: usize,
    visit: impl FnMut(usize, usize) -> std::ops::ControlFlow<()>,
) -> std::ops::ControlFlow<()> {
    sweep_in(boxes, (axis, &starts(boxes, axis)), visit)
}

/// [`sweep`] along `axis`, given the boxes' [`starts`] along it (`order`).
pub(crate) fn sweep_in(
    boxes: &[Aabb],
    (axis, order): (usize, &[usize]),
    mut visit: impl FnMut(usize, usize) -> std::ops::ControlFlow<()>,
) -> std::ops::ControlFlow<()> {
    for (i, &a) in order.iter().enumerate() {
        for &b in &order[i + 1..] {
            if boxes[b].lo[axis] >= boxes[a].hi[axis] {
                break;
            }
            visit(a, b)?;
        }
    }
    std::ops::ControlFlow::Continue(())
}

/// The boxes' numbers in the order of their starts along `axis` (ties in number order).
pub(crate) fn starts(boxes: &[Aabb], axis: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&a, &b| boxes[a].lo[axis].total_cmp(&boxes[b].lo[axis]));
    order
}

/// How many pairs [`sweep`] along `axis` visits, from the sorted starts alone: for the box at place
/// `i` of the order, the boxes that start before it ends, less itself and those before it (all of
/// which start before it ends, but for boxes of no width starting where it starts: a count to
/// choose an axis by, not a bound).
/// `order`: the boxes' [`starts`] along `axis`.
pub(crate) fn sweep_visits(boxes: &[Aabb], (axis, order): (usize, &[usize])) -> u64 {
    let lo: Vec<f64> = order.iter().map(|&b| boxes[b].lo[axis]).collect();
    order
        .iter()
        .enumerate()
        .map(|(i, &b)| {
            let before_end = lo.partition_point(|&x| x < boxes[b].hi[axis]);
            before_end.saturating_sub(i + 1) as u64
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::Aabb;

    #[test]
    fn a_box_folds_its_points_and_skips_nan() {
        let b = Aabb::of([[1.0, -2.0, 3.0], [f64::NAN, 4.0, -1.0], [0.5, 0.0, 0.0]]);
        assert_eq!(b, Aabb::new([0.5, -2.0, -1.0], [1.0, 4.0, 3.0]));
        assert_eq!(b.extent(), [0.5, 6.0, 4.0]);
        assert_eq!(b.largest_extent(), 6.0);
        assert_eq!(b.diagonal(), (0.25f64 + 36.0 + 16.0).sqrt());
        let c = Aabb::new([0.0; 3], [2.0; 3]);
        assert_eq!(
            b.intersection(c),
            Aabb::new([0.5, 0.0, 0.0], [1.0, 2.0, 2.0])
        );
        assert_eq!(b.union(c), Aabb::new([0.0, -2.0, -1.0], [2.0, 4.0, 3.0]));
        assert!(b.union(c).contains(&c) && !c.contains(&b));
        assert_eq!(Aabb::of([]), Aabb::EMPTY);
    }
}
