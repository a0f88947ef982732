//! Convex pieces of a triangle: cut along planes into cells, split in four, their area and centre
//! (plain f64 geometry: which pieces are decided, and how, is [`super::correction`]'s).

use super::grid::Corners;
use crate::geometry::{cross, dot, norm, sub};

/// Cells beyond which a piece is split in four rather than cut.
const MAX_CELLS: usize = 256;

/// A cutting plane: a point on it, its normal, and the margin within which a corner counts as on it.
pub(super) type CutPlane = ([f64; 3], [f64; 3], f64);

/// Convex polygons in one buffer (the cut used a `Vec` per cell and per plane, whose allocations
/// cost more than the clipping): their corners in order, and where each polygon ends. Kept
/// between cuts ([`CellWork`]), the lists grow to what the largest cut needs and stay.
#[derive(Default)]
pub(super) struct Cells {
    corners: Vec<[f64; 3]>,
    ends: Vec<usize>,
}

impl Cells {
    pub(super) fn len(&self) -> usize {
        self.ends.len()
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = &[[f64; 3]]> {
        let starts = std::iter::once(0).chain(self.ends.iter().copied());
        starts.zip(&self.ends).map(|(s, &e)| &self.corners[s..e])
    }

    fn clear(&mut self) {
        self.corners.clear();
        self.ends.clear();
    }

    /// Ends the polygon whose corners were pushed since the last one ended.
    fn close(&mut self) {
        self.ends.push(self.corners.len());
    }
}

/// Whether a plane leaves a convex polygon whole: its corners' signed distances `d` from the plane
/// are all at least −`m` or all at most `m` (the polygon lies on one side, up to the margin).
pub(super) fn leaves_whole(d: &[f64], m: f64) -> bool {
    d.iter().all(|&x| x >= -m) || d.iter().all(|&x| x <= m)
}

/// The part of a convex polygon that a plane [`leaves_whole`] while crossing it (corners strictly
/// on both sides, those on one side within the margin): the sliver on the side of the corners
/// nearer the plane, which is decided with the rest of the polygon from a point on the other
/// side, so perhaps wrongly. Its area, m² (0 when the plane does not cross); `d` are the corners'
/// signed distances, `scratch` a list to clip into.
pub(super) fn overhang(poly: &[[f64; 3]], d: &[f64], scratch: &mut Vec<[f64; 3]>) -> f64 {
    let lo = d.iter().fold(0.0f64, |a, &x| a.min(x));
    let hi = d.iter().fold(0.0f64, |a, &x| a.max(x));
    if lo == 0.0 || hi == 0.0 {
        return 0.0;
    }
    scratch.clear();
    clip(poly, d, if -lo <= hi { -1.0 } else { 1.0 }, scratch);
    if scratch.len() < 3 {
        return 0.0;
    }
    area(scratch)
}

/// A cut: the plane, and the corners of what lies along it in the piece's plane (a blocker's
/// three corners, or a coplanar triangle's edge with its end repeated), if any. A cell that these
/// corners lie beyond is left whole by the cut, even where the plane crosses it: what the plane
/// stands for does not reach the cell. Without a reach, the plane cuts wherever it crosses.
pub(super) struct Cut {
    pub(super) plane: CutPlane,
    pub(super) reach: Option<[[f64; 3]; 3]>,
    /// How far the rounded normal may turn, in units of ε: the scale of its components' rounding
    /// over its length (8 |ab| |ac| / |n| for a blocker's `ab × ac`).
    pub(super) skew: f64,
    /// How far the plane may lie from what it stands for, beyond rounding (a sliver's line: its
    /// height), m.
    pub(super) offset: f64,
}

impl Cut {
    /// How far the line along which this cut crosses a piece of `piece`'s plane (normal `nt`) may
    /// lie from the line it stands for, within that plane, where that matters, m (infinite when
    /// the plane runs along the piece's plane); and the length along which it matters. The
    /// winding number jumps across the line only along what the cut stands for (its reach: a
    /// blocker's intersection with the piece's plane, a coplanar triangle's edge), so only there
    /// does a line off its place move the solid; elsewhere the cells on both sides are decided
    /// alike. `inherited` is how far the piece's corners may lie from their exact places.
    ///
    /// The line is where `d = n · (x − a)` is 0, `a` a stored corner: the rounded normal turns
    /// the plane about `a` by `skew` ε, which moves it by `skew ε |x − a|` along the reach; the
    /// difference and the dot product at the cells' corners (5 ε |n| |x − a|, |x − a| up to the
    /// piece's reach from `a`) and the corners' own displacement move the crossings on the
    /// cells' sides, and so the straight side between two of them; all of it over the sine of
    /// the angle between the two planes, within the piece's plane. A corner made where the line
    /// crosses a side (`p + s (q − p)`) adds 4 ε (|p|∞ + |q − p|). Twice the sum, for the
    /// second-order terms left out.
    pub(super) fn slack(&self, piece: &[[f64; 3]], nt: [f64; 3], inherited: f64) -> (f64, f64) {
        let (a, n, _) = self.plane;
        let reach = piece.iter().map(|x| norm(sub(*x, a))).fold(0.0, f64::max);
        let big = largest_coordinate(piece).max(largest_coordinate(&[a]));
        let sin = norm(cross(n, nt)) / (norm(n) * norm(nt));
        let local = self.reach.map_or(reach, |r| {
            let d = |i: usize, j: usize| norm(sub(r[i], r[j]));
            d(0, 1).max(d(1, 2)).max(d(0, 2)).max(r.iter().map(|x| norm(sub(*x, a))).fold(0.0, f64::max))
        });
        let moved = f64::EPSILON * (self.skew * local + 5.0 * reach) + self.offset + inherited;
        (2.0 * (moved / sin + 4.0 * f64::EPSILON * (big + reach)), local)
    }

    /// Whether the cut's reach lies [`beyond`] the polygon.
    pub(super) fn misses(&self, poly: &[[f64; 3]], nt: [f64; 3], margin: f64) -> bool {
        self.reach.as_ref().is_some_and(|r| beyond(poly, nt, r, margin))
    }
}

/// Whether a cut's `reach` lies beyond one side of a polygon in the plane of normal `nt`, by more
/// than `margin` (a distance): the side's line, across that plane, leaves every corner of the
/// polygon on one side (up to the margin) and every point of the reach beyond the margin on the
/// other, so what the cut stands for cannot meet the polygon. Both are checked, not assumed: a
/// side a few ulps long (two corners that clipping made almost one) points anywhere.
pub(super) fn beyond(poly: &[[f64; 3]], nt: [f64; 3], reach: &[[f64; 3]; 3], margin: f64) -> bool {
    let n = poly.len();
    (0..n).any(|i| {
        let (p, q) = (poly[i], poly[(i + 1) % n]);
        let out = cross(sub(q, p), nt);
        let m = margin * norm(out);
        m > 0.0
            && reach.iter().all(|x| dot(out, sub(*x, p)) > m)
            && poly.iter().all(|x| dot(out, sub(*x, p)) <= m)
    })
}

/// The lists [`cells`] cuts into, kept between calls (see `correction::Faces::cut_work`).
#[derive(Default)]
pub(super) struct CellWork {
    cells: Cells,
    next: Cells,
    d: Vec<f64>,
    /// Per cut (in the order of `which`), the area of the slivers ([`overhang`]) of the cells it
    /// left whole while crossing them within the margin, its reach not beyond them, m².
    slivers: Vec<f64>,
    /// The list [`overhang`] clips into.
    pub(super) sliver: Vec<[f64; 3]>,
}

/// `piece` (in the plane of normal `nt`) cut along the cuts `which` of `cuts` in turn into convex
/// cells, in order, each cell cut only where the cut's reach is not [`beyond`] it (`margin`, a
/// distance); `None` when they are more than [`MAX_CELLS`]. The cells are `work`'s.
pub(super) fn cells<'w>(
    piece: &Corners,
    (cuts, which): (&[Cut], &[usize]),
    nt: [f64; 3],
    margin: f64,
    work: &'w mut CellWork,
) -> Option<(&'w Cells, &'w [f64])> {
    let CellWork { cells, next, d, slivers, sliver } = work;
    cells.clear();
    cells.corners.extend_from_slice(piece);
    cells.close();
    slivers.clear();
    for cut in which.iter().map(|&i| &cuts[i]) {
        let (a, n, m) = cut.plane;
        next.clear();
        let mut total = 0.0;
        for cell in cells.iter() {
            d.clear();
            d.extend(cell.iter().map(|x| dot(n, sub(*x, a))));
            // A plane along the cell's side (one cut already, or a shared edge), or one whose
            // reach ends before the cell, leaves it whole; one that crosses it within the margin
            // too, and the sliver it leaves ([`overhang`]) is in the bound.
            let whole = leaves_whole(d, m);
            if whole || cut.misses(cell, nt, margin) {
                if whole {
                    let o = overhang(cell, d, sliver);
                    if o > 0.0 && !cut.misses(cell, nt, margin) {
                        total += o;
                    }
                }
                next.corners.extend_from_slice(cell);
                next.close();
                continue;
            }
            for side in [1.0, -1.0] {
                let start = next.corners.len();
                clip(cell, d, side, &mut next.corners);
                if next.corners.len() - start >= 3 {
                    next.close();
                } else {
                    next.corners.truncate(start);
                }
            }
        }
        slivers.push(total);
        std::mem::swap(cells, next);
        if cells.len() > MAX_CELLS {
            return None;
        }
    }
    Some((cells, slivers))
}

/// Appends to `out` the part of a convex polygon on one side (`side` = ±1) of a plane, given its
/// corners' signed distances `d` (corners on the plane belong to both sides).
fn clip(poly: &[[f64; 3]], d: &[f64], side: f64, out: &mut Vec<[f64; 3]>) {
    for i in 0..poly.len() {
        let j = (i + 1) % poly.len();
        let (di, dj) = (d[i] * side, d[j] * side);
        if di >= 0.0 {
            out.push(poly[i]);
        }
        if (di > 0.0 && dj < 0.0) || (di < 0.0 && dj > 0.0) {
            let s = di / (di - dj);
            out.push([0, 1, 2].map(|k| poly[i][k] + s * (poly[j][k] - poly[i][k])));
        }
    }
}

/// The largest magnitude of the points' coordinates (what their rounding scales with).
pub(super) fn largest_coordinate(points: &[[f64; 3]]) -> f64 {
    points.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()))
}

pub(super) fn area(poly: &[[f64; 3]]) -> f64 {
    (1..poly.len() - 1)
        .map(|k| norm(cross(sub(poly[k], poly[0]), sub(poly[k + 1], poly[0]))) / 2.0)
        .sum()
}

pub(super) fn centroid(poly: &[[f64; 3]]) -> [f64; 3] {
    let n = poly.len() as f64;
    [0, 1, 2].map(|k| poly.iter().map(|p| p[k]).sum::<f64>() / n)
}

/// The four halves-of-edges triangles of a triangle.
pub(super) fn split(t: Corners) -> [Corners; 4] {
    let mid = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
    let (ab, bc, ca) = (mid(t[0], t[1]), mid(t[1], t[2]), mid(t[2], t[0]));
    [[t[0], ab, ca], [ab, t[1], bc], [ca, bc, t[2]], [ab, bc, ca]]
}


#[cfg(test)]
mod tests {
    use super::*;

    /// Two planes across a right triangle of legs 2 (x = ½, y = ½) cut it into four cells, in the
    /// order of the cuts (x ≥ ½ first, each side's y ≥ ½ first), whose areas are, by hand,
    /// ½ (legs 1), 9/8 − ½, then ∫₀^½ (3/2 − x) dx = 5/8 and 7/8 − 5/8; a plane along a side
    /// (y = 0) leaves the cells whole, and they stay in the triangle's plane.
    #[test]
    fn cells_cut_along_planes_in_order() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let line = |a, n| Cut {
            plane: (a, n, 1e-12),
            reach: None,
            skew: 0.0,
            offset: 0.0,
        };
        let planes = [
            line([0.5, 0.0, 0.0], [1.0, 0.0, 0.0]),
            line([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            line([0.0, 0.5, 0.0], [0.0, 1.0, 0.0]),
        ];
        let mut work = CellWork::default();
        let (c, _) = cells(&t, (&planes, &[0, 1, 2]), [0.0, 0.0, 1.0], 1e-12, &mut work).expect("few cells");
        assert_eq!(c.len(), 4);
        let areas: Vec<f64> = c.iter().map(area).collect();
        assert_eq!(areas, vec![0.5, 0.625, 0.625, 0.25]);
        assert_eq!(areas.iter().sum::<f64>(), 2.0);
        assert!(c.iter().flatten().all(|p| p[2] == 0.0));
        assert_eq!(centroid(&t), [2.0 / 3.0, 2.0 / 3.0, 0.0]);
    }

    /// A plane 1e-3 inside a unit square's side, parallel to it, leaves it whole within a margin
    /// of 2e-3 and cuts off a sliver of 1e-3 × 1, on whichever side lies nearer; a plane along the
    /// side or beyond the square cuts off nothing.
    #[test]
    fn the_sliver_a_plane_leaves_within_the_margin() {
        let square = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let mut scratch = Vec::new();
        let mut sliver = |offset: f64, sign: f64| {
            let d: Vec<f64> = square.iter().map(|p| sign * (p[0] - offset)).collect();
            assert!(leaves_whole(&d, 2e-3));
            overhang(&square, &d, &mut scratch)
        };
        for sign in [1.0, -1.0] {
            assert!((sliver(1e-3, sign) - 1e-3).abs() < 1e-15);
            assert!((sliver(1.0 - 1e-3, sign) - 1e-3).abs() < 1e-15);
            assert_eq!(sliver(0.0, sign), 0.0);
            assert_eq!(sliver(-1e-3, sign), 0.0);
        }
    }

    /// A cut's reach lies beyond a unit square (turning about +z) when one of its sides' lines
    /// separates them: a segment to its right, one on the extension of its diagonal past a
    /// corner, a triangle above it. A segment crossing it, or one ending on its side, is not.
    /// Nor is any reach seen from the square turned the other way, whose sides' outward normals
    /// point in: the check finds the corners on the wrong side. A side of no length (two corners
    /// a few ulps apart, as clipping makes them) separates nothing whichever way it points; a
    /// square flattened to a segment still lies apart from what is away from it.
    #[test]
    fn reach_beyond_a_cell_by_its_sides() {
        let square = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let up = [0.0, 0.0, 1.0];
        let seg = |a: [f64; 3], b: [f64; 3]| [a, b, b];
        let m = 1e-12;
        assert!(beyond(&square, up, &seg([2.0, -5.0, 0.0], [2.0, 5.0, 0.0]), m));
        assert!(beyond(&square, up, &seg([1.5, 1.5, 0.0], [3.0, 3.0, 0.0]), m));
        assert!(beyond(&square, up, &[[0.0, 2.0, -1.0], [1.0, 2.0, 1.0], [0.5, 3.0, 0.0]], m));
        assert!(!beyond(&square, up, &seg([0.5, -5.0, 0.0], [0.5, 5.0, 0.0]), m));
        assert!(!beyond(&square, up, &seg([1.0, 0.5, 0.0], [3.0, 0.5, 0.0]), m));
        assert!(!beyond(&square, up, &seg([-1.0, 0.5, 0.0], [3.0, 0.5, 0.0]), m));
        let mut turned = square;
        turned.reverse();
        assert!(!beyond(&turned, up, &seg([2.0, -5.0, 0.0], [2.0, 5.0, 0.0]), m));
        // The square with its corner (1, 1) doubled one ulp away: that side points into the
        // square, so what lies inside is beyond it.
        let ulp = [1.0 + f64::EPSILON, 1.0 - f64::EPSILON / 2.0, 0.0];
        let near = [square[0], square[1], square[2], ulp, square[3]];
        assert!(!beyond(&near, up, &seg([0.5, 0.2, 0.0], [0.2, 0.5, 0.0]), m));
        let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(beyond(&flat, up, &seg([0.5, 3.0, 0.0], [0.5, 5.0, 0.0]), m));
        assert!(!beyond(&flat, up, &seg([0.5, -1.0, 0.0], [0.5, 1.0, 0.0]), m));
    }
}
