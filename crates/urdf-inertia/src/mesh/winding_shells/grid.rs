//! A uniform grid of triangles: which triangles may meet a box, and the winding number in front of a
//! point on a face, counted by exact crossings (`orient3d`) of an axis-parallel ray.

use either::Either;
use crate::geometry::{cross, dot, sub, Aabb};
use robust::{orient2d, Coord, Coord3D};

use super::c3;

/// A triangle's three corners.
pub(super) type Corners = [[f64; 3]; 3];

/// Cells per axis at most (the grid has about as many cells as triangles).
const MAX_DIM: usize = 128;
const _: () = assert!(MAX_DIM <= 256, "cell indices are stored as u8 in Grid::new");

/// Grid entries (a triangle in each cell its box covers, 52 bytes each) per triangle beyond which
/// the cells are made coarser ([`Grid::new`]), with [`MIN_ENTRIES`] more for any grid. The most a
/// mesh of the corpus needs is 20.9 per triangle (877 meshes with overlapping shells; typically 8 to
/// 12); two cutting star prisms of long triangles (each box spanning much of the grid) took
/// 0.5 GB at 16,000 triangles and 2.0 GB at 32,000 before this limit, growing as n².
const MAX_ENTRIES_PER_TRIANGLE: u64 = 32;

/// Grid entries any grid may hold before [`MAX_ENTRIES_PER_TRIANGLE`] applies (3.4 MB).
const MIN_ENTRIES: u64 = 1 << 16;

/// Cells of a triangle's box from which [`Grid::of_triangles`] keeps only those the triangle may
/// meet: below, the test costs more than the entries it saves (instructions, `examples/shells_once`
/// and UR5 `visual/upperarm.dae`: docs/benchmarks.md, "Session 40: long triangles in the cells
/// they meet").
const SLANTED: usize = 16;

/// Whether a range of cells holds [`SLANTED`] cells or more.
fn slanted(r: &[(usize, usize); 3]) -> bool {
    r.iter().map(|&(a, z)| z - a + 1).product::<usize>() >= SLANTED
}

/// The factor by which a cell's side grows each time the grid is made coarser (its volume doubles).
const COARSER: f64 = 1.259_921_049_894_873_2;

/// Triangles bucketed by the cells their boxes cover ([`Grid::of_triangles`]: by those of the cells
/// each may meet).
pub(super) struct Grid {
    lo: [f64; 3],
    cell: [f64; 3],
    dims: [usize; 3],
    /// The last index per axis (`dims` less one), as a float for [`Grid::index`].
    last: [f64; 3],
    /// Where each cell's triangles start in `items` (one more entry than cells).
    start: Vec<u32>,
    items: Vec<u32>,
    /// The box of each entry of `items`, beside it: a ray or a box query rejects most entries by
    /// their boxes, and reading them in cell order is cheaper than looking each triangle up.
    item_boxes: Vec<Aabb>,
    /// Per cell, for a row along x and one along y: the entries of the cells before it in its row
    /// ([`Grid::row_entries`]; a row along z is a run of consecutive cells, counted from `start`).
    row_before: Vec<[u32; 2]>,
    /// The box of every triangle in the grid.
    pub(super) bounds: Aabb,
}

/// Which triangles a query has seen already (a triangle sits in several cells).
pub(super) struct Seen {
    mark: Vec<u32>,
    round: u32,
}

impl Seen {
    pub(super) fn new(n: usize) -> Seen {
        Seen {
            mark: vec![0; n],
            round: 0,
        }
    }

    fn next(&mut self) {
        self.round = self.round.wrapping_add(1);
        if self.round == 0 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.round = 1;
        }
    }

    /// Marks `i`; whether it was new in this round.
    fn first(&mut self, i: u32) -> bool {
        let m = &mut self.mark[i as usize];
        let new = *m != self.round;
        *m = self.round;
        new
    }
}

/// [`Grid::row_before`] of a grid of `dims` cells whose entries start at `start`.
fn rows_before([_, d1, d2]: [usize; 3], start: &[u32]) -> Vec<[u32; 2]> {
    let cells = start.len() - 1;
    let mut row_before = vec![[0u32; 2]; cells];
    for c in 0..cells {
        // The cell before `c` along x, then along y, when there is one.
        for (k, back) in [(0, d1 * d2), (1, d2)] {
            let first_in_row = if k == 0 { c < back } else { (c / d2) % d1 == 0 };
            if !first_in_row {
                let b = c - back;
                row_before[c][k] = row_before[b][k] + (start[b + 1] - start[b]);
            }
        }
    }
    row_before
}

/// What an axis-parallel segment does at a triangle.
pub(super) enum Crossing {
    Miss,
    /// Crosses its interior: +1 leaving through its front (the side its normal points to), −1 entering.
    Through(i64),
    /// Touches an edge, a vertex or its plane: the count would not be exact.
    Degenerate,
}

impl Grid {
    /// The grid of boxes `boxes`, each in every cell it covers.
    #[cfg(test)]
    pub(super) fn new(boxes: &[Aabb]) -> Grid {
        Grid::build(boxes, None)
    }

    /// The grid of triangles `corners` (`boxes` their boxes), each in the cells its box covers that
    /// it may meet ([`Slanted::may_meet`]): a long triangle slanting across its box, as CAD fans
    /// have them, sits in a band of the cells its box covers, not in all of them. A query of a box
    /// or a ray then finds every triangle that meets it, as before, and fewer that do not.
    pub(super) fn of_triangles(boxes: &[Aabb], corners: &[Corners]) -> Grid {
        Grid::build(boxes, Some(corners))
    }

    fn build(boxes: &[Aabb], corners: Option<&[Corners]>) -> Grid {
        let bounds = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        let ext = bounds.extent();
        let largest = ext.iter().copied().fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let ext = ext.map(|e| e.max(largest * 1e-6));
        let mut h = (ext.iter().product::<f64>() / boxes.len().max(1) as f64).cbrt();
        let sized = |h: f64| {
            let dims = ext.map(|e| ((e / h).ceil() as usize).clamp(1, MAX_DIM));
            Grid {
                lo: bounds.lo,
                cell: [0, 1, 2].map(|k| ext[k] / dims[k] as f64),
                dims,
                last: dims.map(|d| (d - 1) as f64),
                start: Vec::new(),
                items: Vec::new(),
                item_boxes: Vec::new(),
                row_before: Vec::new(),
                bounds,
            }
        };
        let mut grid = sized(h);
        // Coarser cells while the entries would pass the budget: triangles whose boxes span much
        // of the grid (a star-shaped prism's sides) would otherwise fill about n² entries.
        let budget = MAX_ENTRIES_PER_TRIANGLE * boxes.len() as u64 + MIN_ENTRIES;
        while grid.dims != [1, 1, 1] && boxes.iter().map(|b| grid.cells_in(b) as u64).sum::<u64>() > budget {
            h *= COARSER;
            grid = sized(h);
        }
        let dims = grid.dims;
        let cells = dims.iter().product::<usize>();
        let mut count = vec![0u32; cells + 1];
        // Each box's range of cells, found once for both passes (an index is below `MAX_DIM`).
        let ranges: Vec<[[u8; 2]; 3]> = boxes
            .iter()
            .map(|b| grid.cell_range(b).map(|(a, z)| [a as u8, z as u8]))
            .collect();
        let range = |r: &[[u8; 2]; 3]| r.map(|[a, z]| (usize::from(a), usize::from(z)));
        // With corners, the cells of each triangle's box that it may meet, for the triangles
        // whose boxes cover [`SLANTED`] cells or more, found once for both passes: their runs
        // one after the other in `kept`.
        let kept: Vec<u32> = corners.map_or_else(Vec::new, |corners| {
            let cell_boxes = CellBoxes::new(&grid);
            let mut kept = Vec::new();
            for (t, r) in corners.iter().zip(&ranges) {
                let r = range(r);
                if slanted(&r) {
                    let t = cell_boxes.triangle(t);
                    for x in r[0].0..=r[0].1 {
                        for y in r[1].0..=r[1].1 {
                            for z in r[2].0..=r[2].1 {
                                if t.may_meet([x, y, z]) {
                                    kept.push(grid.cell_number([x, y, z]) as u32);
                                }
                            }
                        }
                    }
                    kept.push(u32::MAX);
                }
            }
            kept
        });
        let slanted = |r: &[(usize, usize); 3]| corners.is_some() && slanted(r);
        grid.entries(&ranges, &kept, slanted, |_, c| count[c + 1] += 1);
        for c in 0..cells {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[cells] as usize];
        let mut item_boxes = vec![Aabb::EMPTY; count[cells] as usize];
        grid.entries(&ranges, &kept, slanted, |i, c| {
            items[fill[c] as usize] = i as u32;
            item_boxes[fill[c] as usize] = boxes[i];
            fill[c] += 1;
        });
        grid.row_before = rows_before(dims, &count);
        grid.start = count;
        grid.items = items;
        grid.item_boxes = item_boxes;
        grid
    }

    fn index(&self, k: usize, x: f64) -> usize {
        // Truncation is the floor for the non-negative values that reach the cast; the last index
        // is a whole number, so clamping before the cast gives the index clamping after it gave,
        // and a cast to u32 of a value below 128 costs less than a saturating one to usize.
        let i = (x - self.lo[k]) / self.cell[k];
        if i >= 0.0 {
            i.min(self.last[k]) as u32 as usize
        } else {
            0 // below the grid, or NaN
        }
    }

    /// The cells a box `b` covers: per axis, the first and last index.
    fn cell_range(&self, b: &Aabb) -> [(usize, usize); 3] {
        let r = |k| (self.index(k, b.lo[k]), self.index(k, b.hi[k]));
        [r(0), r(1), r(2)]
    }

    fn each_cell(&self, b: &Aabb, f: impl FnMut(usize)) {
        self.each_cell_in(self.cell_range(b), f);
    }

    /// Calls `f` on each cell of a [`Grid::cell_range`], in the order of their numbers.
    fn each_cell_in(&self, r: [(usize, usize); 3], mut f: impl FnMut(usize)) {
        for x in r[0].0..=r[0].1 {
            for y in r[1].0..=r[1].1 {
                for z in r[2].0..=r[2].1 {
                    f(self.cell_number([x, y, z]));
                }
            }
        }
    }

    /// The number of the cell of indices `[x, y, z]`.
    fn cell_number(&self, [x, y, z]: [usize; 3]) -> usize {
        (x * self.dims[1] + y) * self.dims[2] + z
    }

    /// Calls `f(i, c)` for each cell `c` of triangle `i`, triangle by triangle, each one's cells in
    /// the order of their numbers: all those of its range of cells (`ranges`), or where `slanted`
    /// holds of the range, those of its run in `kept` (the runs one after the other, each ended by
    /// `u32::MAX`).
    #[inline(always)]
    fn entries(&self, ranges: &[[[u8; 2]; 3]], kept: &[u32], slanted: impl Fn(&[(usize, usize); 3]) -> bool, mut f: impl FnMut(usize, usize)) {
        let mut run = kept.iter();
        for (i, r) in ranges.iter().enumerate() {
            let r = r.map(|[a, z]| (usize::from(a), usize::from(z)));
            if slanted(&r) {
                run.by_ref().take_while(|&&c| c != u32::MAX).for_each(|&c| f(i, c as usize));
            } else {
                self.each_cell_in(r, |c| f(i, c));
            }
        }
    }

    /// A cell's triangles and their boxes.
    fn cell_items(&self, c: usize) -> (&[u32], &[Aabb]) {
        let r = self.start[c] as usize..self.start[c + 1] as usize;
        (&self.items[r.clone()], &self.item_boxes[r])
    }

    /// The triangles numbered above `after` (all when `None`) whose boxes meet `b` (closed
    /// boxes) and that are listed in a cell `b` covers, each once, in the order of those cells:
    /// in a grid of boxes every one whose box meets `b`; in one of triangles every triangle that
    /// meets `b`, and fewer that do not.
    pub(super) fn overlapping(&self, b: &Aabb, after: Option<u32>, seen: &mut Seen, out: &mut Vec<u32>) {
        out.clear();
        seen.next();
        let after = after.map_or(0, |a| u64::from(a) + 1);
        self.each_cell(b, |c| {
            let (items, boxes) = self.cell_items(c);
            // A cell's entries are in the order of their numbers ([`Grid::new`] fills them so): those
            // up to `after`, about half, are passed by a binary search, not one by one.
            let from = if after == 0 { 0 } else { items.partition_point(|&i| u64::from(i) < after) };
            for (&i, x) in items[from..].iter().zip(&boxes[from..]) {
                if super::overlap(b, x) && seen.first(i) {
                    out.push(i);
                }
            }
        });
    }

    /// The sum over the cells of their entries squared: about what querying each entry's box costs
    /// ([`Grid::overlapping`] reads every entry of each cell it visits).
    pub(super) fn crowding(&self) -> u64 {
        self.start.windows(2).map(|w| u64::from(w[1] - w[0]).pow(2)).sum()
    }

    /// How many cells [`Grid::overlapping`] visits for a query box `b`.
    pub(super) fn cells_in(&self, b: &Aabb) -> usize {
        (0..3).map(|k| self.index(k, b.hi[k]) - self.index(k, b.lo[k]) + 1).product()
    }

    /// The cell of a point, per axis (clamped to the grid).
    pub(super) fn cell_of(&self, p: [f64; 3]) -> [usize; 3] {
        super::in_order(|k| self.index(k, p[k]))
    }

    /// Where [`Grid::overlapping`] of a query box whose lowest corner is in cell `query`
    /// ([`Grid::cell_of`]) finds a triangle whose box `b` meets it (closed boxes) in a grid of
    /// boxes: the first cell it visits that holds the triangle, the corner of the two boxes'
    /// ranges of cells lowest on every axis (the cells are visited in order of their number, and a
    /// cell's entries in order of theirs). Sorting by (this, number) puts triangles in that order
    /// without a second query; in a grid of triangles, which lists a triangle in fewer cells, the
    /// order is the same, a function of the boxes alone.
    pub(super) fn first_shared_cell(&self, query: [usize; 3], b: &Aabb) -> usize {
        let idx = super::in_order(|k| query[k].max(self.index(k, b.lo[k])));
        (idx[0] * self.dims[1] + idx[1]) * self.dims[2] + idx[2]
    }

    /// How many entries the ray of [`Grid::winding`] from `p` along `sign`·e_`axis` reads: those of
    /// the row of cells from `p`'s to the grid's end. A ray may leave a face on either side (the
    /// count behind it is the count in front plus its jump), and one way is often much shorter.
    pub(super) fn row_entries(&self, p: [f64; 3], axis: usize, sign: f64) -> usize {
        let (first, stride, cells) = self.row(p, axis, sign);
        if stride == 1 {
            return (self.start[first + cells.end] - self.start[first + cells.start]) as usize;
        }
        // The entries of the row's cells before its `i`-th, for `i` up to the row's length.
        let before = |i: usize| {
            if i < self.dims[axis] {
                self.row_before[first + i * stride][axis]
            } else {
                let c = first + (i - 1) * stride;
                self.row_before[c][axis] + (self.start[c + 1] - self.start[c])
            }
        };
        (before(cells.end) - before(cells.start)) as usize
    }

    /// The cells a ray from `p` along `sign`·e_`axis` passes, from `p`'s to the grid's end: cell
    /// `first + i · stride` for each `i` of the range.
    fn row(&self, p: [f64; 3], axis: usize, sign: f64) -> (usize, usize, std::ops::Range<usize>) {
        let idx = super::in_order(|k| self.index(k, p[k]));
        let stride = match axis {
            0 => self.dims[1] * self.dims[2],
            1 => self.dims[2],
            _ => 1,
        };
        let first = ((idx[0] * self.dims[1] + idx[1]) * self.dims[2] + idx[2]) - idx[axis] * stride;
        let cells = if sign > 0.0 {
            idx[axis]..self.dims[axis]
        } else {
            0..idx[axis] + 1
        };
        (first, stride, cells)
    }

    /// The winding number of the triangles (all but those in `skip`) at `p`, counted along the ray from `p`
    /// in direction `sign`·e_`axis` to beyond the grid; `None` when the ray touches an edge, a
    /// vertex or a plane of one of them. With `near`, the triangles it passes through whose boxes
    /// begin (seen from `p`) no further along `axis` than `near`'s coordinate are listed there.
    pub(super) fn winding(
        &self,
        tris: (&[Corners], &[Plane]),
        p: [f64; 3],
        axis: usize,
        sign: f64,
        skip: &[u32],
        seen: &mut Seen,
        near: Option<(f64, &mut Vec<u32>)>,
    ) -> Option<i64> {
        // One loop per axis and way, so that the box test compares fixed fields.
        match (axis, sign > 0.0) {
            (0, true) => self.winding_along::<0, true>(tris, p, sign, skip, seen, near),
            (0, false) => self.winding_along::<0, false>(tris, p, sign, skip, seen, near),
            (1, true) => self.winding_along::<1, true>(tris, p, sign, skip, seen, near),
            (1, false) => self.winding_along::<1, false>(tris, p, sign, skip, seen, near),
            (_, true) => self.winding_along::<2, true>(tris, p, sign, skip, seen, near),
            (_, false) => self.winding_along::<2, false>(tris, p, sign, skip, seen, near),
        }
    }

    /// [`Grid::winding`] along `sign`·e_`A`, `UP` whether `sign` > 0.
    fn winding_along<const A: usize, const UP: bool>(
        &self,
        (corners, planes): (&[Corners], &[Plane]),
        p: [f64; 3],
        sign: f64,
        skip: &[u32],
        seen: &mut Seen,
        mut near: Option<(f64, &mut Vec<u32>)>,
    ) -> Option<i64> {
        let mut end = p;
        let margin = self.cell[A];
        end[A] = if UP {
            self.bounds.hi[A].max(p[A]) + margin
        } else {
            self.bounds.lo[A].min(p[A]) - margin
        };
        seen.next();
        // The row of cells from the start's on, in either order: which triangles the ray meets,
        // and whether one of them only touches it, do not depend on the order. Along z the row's
        // cells are consecutive, and so are their entries.
        let (first, stride, cells) = self.row(p, A, sign);
        let runs = if stride == 1 {
            let run = self.start[first + cells.start] as usize..self.start[first + cells.end] as usize;
            Either::Left(std::iter::once(run))
        } else {
            Either::Right(cells.map(move |ck| {
                let c = first + ck * stride;
                self.start[c] as usize..self.start[c + 1] as usize
            }))
        };
        let (j, l) = ((A + 1) % 3, (A + 2) % 3);
        let (pj, pl, pa) = (p[j], p[l], p[A]);
        let mut w = 0;
        for run in runs {
            let items = &self.items[run.clone()];
            for (k, b) in self.item_boxes[run].iter().enumerate() {
                // A triangle whose box misses the ray's line, or lies wholly behind its start, is
                // missed (exact comparisons; a NaN corner is not rejected here). The line first:
                // most boxes of the row miss it; along `A` only the start's side can reject.
                if b.hi[j] < pj || b.lo[j] > pj || b.hi[l] < pl || b.lo[l] > pl || (UP && b.hi[A] < pa) || (!UP && b.lo[A] > pa) {
                    continue;
                }
                let i = items[k];
                if skip.contains(&i) || !seen.first(i) {
                    continue;
                }
                match crossing(p, end, A, &corners[i as usize], &planes[i as usize]) {
                    Crossing::Miss => {}
                    Crossing::Through(d) => {
                        w += d;
                        if let Some((reach, list)) = near.as_mut() {
                            if (sign > 0.0 && b.lo[A] <= *reach) || (sign < 0.0 && b.hi[A] >= *reach) {
                                list.push(i);
                            }
                        }
                    }
                    Crossing::Degenerate => return None,
                }
            }
        }
        Some(w)
    }
}

/// The cells of a [`Grid`] as closed boxes that hold every point [`Grid::index`] puts in them,
/// for [`Grid::of_triangles`]: cell `i` along axis k is `lo + (i + ½)·cell ± (½·cell + δ)`, δ a
/// millionth of a cell, far above what rounding can move a point across a cell's side (the
/// index's subtraction and division err by at most 2ε of the grid's extent, which is at most 128
/// cells). Positions are taken from `lo`, so a mesh far from the origin loses nothing.
struct CellBoxes {
    lo: [f64; 3],
    cell: [f64; 3],
    half: [f64; 3],
    /// The grid's largest extent.
    ext: f64,
}

/// A triangle as [`Slanted::may_meet`] tests it: per candidate separating axis `a` (its normal,
/// and each edge crossed with each axis), what its corners project to (least and most, from the
/// grid's `lo`), what a cell's box reaches from its centre with the slack for rounding, and `a`'s
/// components times a cell's sides.
struct Slanted {
    axes: [Axis; 10],
}

#[derive(Clone, Copy, Default)]
struct Axis {
    least: f64,
    most: f64,
    reach: f64,
    step: [f64; 3],
}

impl CellBoxes {
    fn new(grid: &Grid) -> CellBoxes {
        let ext = (0..3).map(|k| grid.cell[k] * grid.dims[k] as f64).fold(0.0, f64::max);
        CellBoxes {
            lo: grid.lo,
            cell: grid.cell,
            half: grid.cell.map(|c| 0.5 * c + 1e-6 * c + 4.0 * f64::EPSILON * ext),
            ext,
        }
    }

    fn triangle(&self, t: &Corners) -> Slanted {
        let v = t.map(|v| sub(v, self.lo));
        let edges = [0, 1, 2].map(|i| sub(v[(i + 1) % 3], v[i]));
        let mut axes = [Axis::default(); 10];
        let mut put = |i: usize, a: [f64; 3]| {
            let p = v.map(|x| dot(a, x));
            let r: f64 = (0..3).map(|k| self.half[k] * a[k].abs()).sum();
            let size: f64 = a.iter().map(|x| x.abs()).sum::<f64>() * self.ext;
            axes[i] = Axis {
                least: p[0].min(p[1]).min(p[2]),
                most: p[0].max(p[1]).max(p[2]),
                // Rounding errs by a few ε of `size` in the projections and the centres'.
                reach: r + 1e-9 * size,
                step: std::array::from_fn(|k| a[k] * self.cell[k]),
            };
        };
        put(0, cross(edges[0], edges[1]));
        for (i, e) in edges.iter().enumerate() {
            // e × x, e × y, e × z: the edge's other two components, turned (no rounding).
            put(1 + 3 * i, [0.0, e[2], -e[1]]);
            put(2 + 3 * i, [-e[2], 0.0, e[0]]);
            put(3 + 3 * i, [e[1], -e[0], 0.0]);
        }
        Slanted { axes }
    }
}

impl Slanted {
    /// Whether the triangle may meet the cell of indices `idx`: false only where one of its axes
    /// parts the cell's box from the corners by more than rounding could (any axis that parts the
    /// projections of two convex sets parts the sets, so the axes' own rounding does not matter);
    /// a NaN parts nothing.
    fn may_meet(&self, idx: [usize; 3]) -> bool {
        let mid = idx.map(|i| i as f64 + 0.5);
        !self.axes.iter().any(|a| {
            let centre = a.step[0] * mid[0] + a.step[1] * mid[1] + a.step[2] * mid[2];
            a.least - centre > a.reach || a.most - centre < -a.reach
        })
    }
}

/// Half the gap between 1 and the next f64 (Shewchuk's ε).
const EPSILON: f64 = f64::EPSILON / 2.0;

/// Shewchuk's error bound of orient3d's floating-point stage, as `robust` computes it.
const O3DERRBOUND_A: f64 = (7.0 + 56.0 * EPSILON) * EPSILON;

/// `robust::orient3d`, whose first stage (the determinant in f64 and its error bound) is inlined
/// here: most calls end there, and the crate's function is not inlined across crates. The value
/// is the crate's: the same determinant when the bound certifies its sign, zero where the four
/// points are exactly degenerate in a way seen without arithmetic ([`plainly_flat`]), else the
/// crate's adaptive stages.
#[inline(always)] // a few dozen flops run for every ray crossing and neighbour test
pub(super) fn orient3d(pa: Coord3D<f64>, pb: Coord3D<f64>, pc: Coord3D<f64>, pd: Coord3D<f64>) -> f64 {
    let (adx, bdx, cdx) = (pa.x - pd.x, pb.x - pd.x, pc.x - pd.x);
    let (ady, bdy, cdy) = (pa.y - pd.y, pb.y - pd.y, pc.y - pd.y);
    let (adz, bdz, cdz) = (pa.z - pd.z, pb.z - pd.z, pc.z - pd.z);
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    let errbound = O3DERRBOUND_A * permanent;
    if det > errbound || -det > errbound {
        return det;
    }
    if plainly_flat([pa, pb, pc, pd]) {
        return 0.0;
    }
    robust::orient3d(pa, pb, pc, pd)
}

/// Whether four points are coplanar by equal coordinates alone: two of them are the same point,
/// or all four have the same x, the same y or the same z. Their orientation is then exactly zero,
/// the answer the adaptive stages reach at their dearest. Shells that share vertices, or lie on
/// one face of a CAD part (coincident shells), ask it of most pairs of triangles that touch: on
/// centauro's wheel (81 pairs of touching shells) the adaptive stages were 13% of the
/// instructions.
fn plainly_flat(p: [Coord3D<f64>; 4]) -> bool {
    let same = |a: &Coord3D<f64>, b: &Coord3D<f64>| a.x == b.x && a.y == b.y && a.z == b.z;
    let level = |k: fn(&Coord3D<f64>) -> f64| p.iter().all(|q| k(q) == k(&p[0]));
    (0..4).any(|i| (i + 1..4).any(|j| same(&p[i], &p[j])))
        || level(|q| q.x)
        || level(|q| q.y)
        || level(|q| q.z)
}

/// A triangle's plane, for the side of many points: `orient3d(a, b, c, d)`'s sign for any `d`, with
/// the part that depends on the triangle alone computed once.
///
/// The filter is Shewchuk's first stage applied to the transposed matrix of the rows b − a, c − a,
/// d − a: its entries are rounded differences of input coordinates as in `orient3d`, the
/// expansion and the error bound are the same expressions of them, and the determinant is
/// unchanged by transposition, so the same bound certifies the sign. That determinant is
/// ((b − a) × (c − a)) · (d − a) = −orient3d(a, b, c, d); when the bound does not certify it, the
/// crate's exact `orient3d` decides.
#[derive(Clone, Copy)]
pub(super) struct Plane {
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
    /// The 2×2 minors of b − a and c − a (the normal), and the sums of their products' magnitudes.
    minor: [f64; 3],
    size: [f64; 3],
    /// An axis along which the three corners have one coordinate, and that coordinate: the plane
    /// is perpendicular to it, and a point with that coordinate lies in it (orient3d is exactly
    /// zero), which the filter cannot certify and the adaptive stages find at their dearest.
    /// Flat faces of CAD parts often are so (coincident shells: every corner of the other shell's
    /// triangles in the face asks).
    level: Option<(usize, f64)>,
}

impl Plane {
    pub(super) fn new(t: &Corners) -> Plane {
        let [a, b, c] = *t;
        // Shewchuk's names on the transposed matrix: (adx, ady, adz) = (b − a)ₓ, (c − a)ₓ,
        // (d − a)ₓ, and so on for y (bd…) and z (cd…).
        let (adx, ady) = (b[0] - a[0], c[0] - a[0]);
        let (bdx, bdy) = (b[1] - a[1], c[1] - a[1]);
        let (cdx, cdy) = (b[2] - a[2], c[2] - a[2]);
        let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
        let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
        let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
        let level = (0..3).find(|&k| a[k] == b[k] && b[k] == c[k]).map(|k| (k, a[k]));
        Plane {
            a,
            b,
            c,
            level,
            minor: [bdxcdy - cdxbdy, cdxady - adxcdy, adxbdy - bdxady],
            size: [
                bdxcdy.abs() + cdxbdy.abs(),
                cdxady.abs() + adxcdy.abs(),
                adxbdy.abs() + bdxady.abs(),
            ],
        }
    }

    /// (b − a) × (c − a), the same bits as `geometry::cross` of the two gives (its minors).
    pub(super) fn normal(&self) -> [f64; 3] {
        self.minor
    }

    /// A value with the sign of `orient3d(a, b, c, d)` (zero exactly when `d` is in the plane).
    #[inline(always)] // a few flops run for every pair of neighbouring triangles
    pub(super) fn side(&self, d: [f64; 3]) -> f64 {
        if let Some((k, x)) = self.level {
            if d[k] == x {
                return 0.0;
            }
        }
        let (adz, bdz, cdz) = (d[0] - self.a[0], d[1] - self.a[1], d[2] - self.a[2]);
        let det = adz * self.minor[0] + bdz * self.minor[1] + cdz * self.minor[2];
        let permanent = self.size[0] * adz.abs() + self.size[1] * bdz.abs() + self.size[2] * cdz.abs();
        let errbound = O3DERRBOUND_A * permanent;
        if det > errbound || -det > errbound {
            return -det;
        }
        self.exact_side(d)
    }

    /// [`Plane::side`] where the filter cannot certify the sign: the crate's exact `orient3d`, out
    /// of line, so that the callers' inlined filter stays small (its value is unchanged).
    #[inline(never)]
    fn exact_side(&self, d: [f64; 3]) -> f64 {
        robust::orient3d(c3(self.a), c3(self.b), c3(self.c), c3(d))
    }
}

/// The segment `s e`, parallel to axis `axis`, at the triangle `t` (whose plane is `plane`), exactly.
///
/// Whether the segment's line passes through the triangle is read in the projection along `axis`:
/// `e` is `s` with one coordinate changed, so e − s is L times the unit vector of `axis` exactly
/// and orient3d(s, e, a, b) = ±L · orient2d(a′, b′, s′) exactly (a′ the projection of a, one sign
/// for all three edges). The three signs are thus orient3d's up to one common factor, which the
/// tests below (mixed signs, a zero) do not see, and two-dimensional ones cost less and reject
/// most triangles (those coplanar with the face the ray starts from, whose sides of the start are
/// zero, included) before the sides of their planes are asked. The answer is the one the two
/// conditions give in either order.
pub(super) fn crossing(s: [f64; 3], e: [f64; 3], axis: usize, t: &Corners, plane: &Plane) -> Crossing {
    let (j, l) = ((axis + 1) % 3, (axis + 2) % 3);
    let p2 = |x: [f64; 3]| Coord { x: x[j], y: x[l] };
    let (a, b, c, sp) = (p2(t[0]), p2(t[1]), p2(t[2]), p2(s));
    // Two of the three signs apart already mean a miss: the third is then not asked.
    let (q0, q1) = (orient2d(a, b, sp), orient2d(b, c, sp));
    if (q0 > 0.0 && q1 < 0.0) || (q0 < 0.0 && q1 > 0.0) {
        return Crossing::Miss;
    }
    let q = [q0, q1, orient2d(c, a, sp)];
    if q.iter().any(|x| *x > 0.0) && q.iter().any(|x| *x < 0.0) {
        return Crossing::Miss;
    }
    let (os, oe) = (plane.side(s), plane.side(e));
    if (os > 0.0 && oe > 0.0) || (os < 0.0 && oe < 0.0) {
        return Crossing::Miss;
    }
    if os == 0.0 || oe == 0.0 || q.contains(&0.0) {
        return Crossing::Degenerate;
    }
    // orient3d > 0: the point is behind the triangle (its corners turn clockwise seen from it).
    Crossing::Through(if os > 0.0 { 1 } else { -1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Xorshift numbers uniform in [−½, ½) from `state`.
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// The unit cube's twelve triangles, outward.
    fn cube() -> Vec<Corners> {
        let p = |i: usize| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64];
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        quads
            .iter()
            .flat_map(|q| [[p(q[0]), p(q[1]), p(q[2])], [p(q[0]), p(q[2]), p(q[3])]])
            .collect()
    }

    /// The inlined first stage gives `robust::orient3d`'s value, bit for bit, also where it hands
    /// over to the adaptive stages (points on or within rounding of the plane).
    #[test]
    fn orient3d_is_robusts() {
        let mut next = uniform(0x9E37_79B9_7F4A_7C15_u64);
        for i in 0..20_000 {
            let [a, b, c] = [0; 3].map(|_| [next(), next(), next()]);
            let d = match i % 3 {
                0 => [next(), next(), next()],
                // On the plane of a, b, c up to the rounding of the combination.
                1 => {
                    let (s, t) = (next(), next());
                    [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]))
                }
                // The midpoint of an edge: on the plane up to its rounding.
                _ => [0, 1, 2].map(|k| 0.5 * (a[k] + b[k])),
            };
            let ours = orient3d(c3(a), c3(b), c3(c), c3(d));
            let theirs = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
            assert_eq!(ours.to_bits(), theirs.to_bits(), "{a:?} {b:?} {c:?} {d:?}");
        }
    }

    /// Four points that [`plainly_flat`] takes as flat (two the same, or one coordinate shared by
    /// all) have orientation zero by the crate's exact stages too; points that only nearly are so
    /// (one coordinate one ulp off) are left to those stages, whose value comes back unchanged.
    #[test]
    fn plainly_flat_points_are_flat_for_robust() {
        let mut next = uniform(0x51_7CC1_B727_220A_u64);
        let (mut flat, mut near) = (0, 0);
        for i in 0..30_000 {
            let mut p = [0; 4].map(|_| [next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0]);
            match i % 4 {
                // Two points the same, in every pair of places.
                0 => p[(i / 4) % 4] = p[((i / 4) % 4 + 1 + (i / 16) % 3) % 4],
                // All on one level of one axis (a face of a CAD part).
                1 => {
                    let k = (i / 4) % 3;
                    (1..4).for_each(|j| p[j][k] = p[0][k]);
                }
                // The same, one coordinate one ulp off: not plainly flat.
                2 => {
                    let k = (i / 4) % 3;
                    (1..4).for_each(|j| p[j][k] = p[0][k]);
                    p[3][k] = f64::from_bits(p[3][k].to_bits() + 1);
                }
                _ => {}
            }
            let q = p.map(c3);
            let ours = orient3d(q[0], q[1], q[2], q[3]);
            let theirs = robust::orient3d(q[0], q[1], q[2], q[3]);
            if plainly_flat(q) {
                flat += 1;
                assert_eq!((ours, theirs), (0.0, 0.0), "{p:?}");
            } else {
                near += usize::from(i % 4 == 2);
                assert_eq!(ours.to_bits(), theirs.to_bits(), "{p:?}");
            }
        }
        assert!(flat >= 15_000 && near >= 7_000, "{flat} {near}");
    }

    /// The plane's side has `robust::orient3d`'s sign (and zero exactly where it is zero), also for
    /// points on the plane up to rounding and for flat or degenerate triangles.
    #[test]
    fn plane_side_is_orient3ds_sign() {
        let mut next = uniform(0x2545_F491_4F6C_DD1D_u64);
        for i in 0..30_000 {
            let [a, mut b, mut c] = [0; 3].map(|_| [next(), next(), next()]);
            if i % 7 == 0 {
                // Collinear corners: every point is on the (undefined) plane.
                c = [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
            }
            if i % 11 == 0 {
                b = a;
            }
            let d = match i % 4 {
                0 => [next(), next(), next()],
                1 => {
                    let (s, t) = (next(), next());
                    [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]))
                }
                2 => [0, 1, 2].map(|k| 0.5 * (b[k] + c[k])),
                _ => [a, b, c][i % 3],
            };
            let ours = Plane::new(&[a, b, c]).side(d);
            let theirs = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
            assert_eq!(ours.partial_cmp(&0.0), theirs.partial_cmp(&0.0), "{a:?} {b:?} {c:?} {d:?}");
        }
    }

    /// A triangle perpendicular to an axis (its corners share that coordinate exactly, as on the
    /// flat faces of CAD parts): its side of points at that coordinate is zero without the
    /// adaptive stages, and of every other point `robust::orient3d`'s sign; also for collinear
    /// corners and coordinates of no exact binary value.
    #[test]
    fn a_level_plane_side_is_orient3ds_sign() {
        let mut next = uniform(0x1405_7B7E_F767_814F_u64);
        let mut zeros = 0;
        for i in 0..30_000 {
            let k = i % 3;
            let level = [0.3, -1.0 / 3.0, 1e-7, 0.0][i % 4];
            let mut t = [0; 3].map(|_| [next(), next(), next()]);
            for c in &mut t {
                c[k] = level;
            }
            if i % 9 == 0 {
                t[2] = [0, 1, 2].map(|j| 0.5 * (t[0][j] + t[1][j]));
            }
            let plane = Plane::new(&t);
            assert_eq!(plane.level, Some((k, level)));
            let mut d = [next(), next(), next()];
            match i % 5 {
                0 | 1 => d[k] = level,
                2 => d[k] = level + f64::EPSILON * next(),
                _ => {}
            }
            let ours = plane.side(d);
            let theirs = robust::orient3d(c3(t[0]), c3(t[1]), c3(t[2]), c3(d));
            zeros += usize::from(ours == 0.0);
            assert_eq!(ours.partial_cmp(&0.0), theirs.partial_cmp(&0.0), "{t:?} {d:?}");
        }
        assert!(zeros > 10_000, "{zeros}");
        // Corners that share no coordinate: no level.
        assert_eq!(Plane::new(&[[0.0, 0.0, 0.0], [1.0, 0.5, 0.2], [0.3, 1.0, 0.7]]).level, None);
    }

    /// The crossing as orient3d alone decides it: the segment's sides of the plane, then the sides
    /// of the segment's line of the three edges.
    fn crossing_by_orient3d(s: [f64; 3], e: [f64; 3], t: &Corners) -> Crossing {
        let (a, b, c) = (c3(t[0]), c3(t[1]), c3(t[2]));
        let (os, oe) = (orient3d(a, b, c, c3(s)), orient3d(a, b, c, c3(e)));
        if (os > 0.0 && oe > 0.0) || (os < 0.0 && oe < 0.0) {
            return Crossing::Miss;
        }
        let (cs, ce) = (c3(s), c3(e));
        let q = [
            orient3d(cs, ce, a, b),
            orient3d(cs, ce, b, c),
            orient3d(cs, ce, c, a),
        ];
        if q.iter().any(|x| *x > 0.0) && q.iter().any(|x| *x < 0.0) {
            return Crossing::Miss;
        }
        if os == 0.0 || oe == 0.0 || q.contains(&0.0) {
            return Crossing::Degenerate;
        }
        Crossing::Through(if os > 0.0 { 1 } else { -1 })
    }

    fn same(x: &Crossing, y: &Crossing) -> bool {
        match (x, y) {
            (Crossing::Miss, Crossing::Miss) | (Crossing::Degenerate, Crossing::Degenerate) => true,
            (Crossing::Through(a), Crossing::Through(b)) => a == b,
            _ => false,
        }
    }

    /// The projected edge tests give orient3d's answer for axis-parallel segments: random ones,
    /// segments through corners, along edges, starting in the plane, and coplanar triangles.
    #[test]
    fn crossing_is_orient3ds() {
        let mut next = uniform(0x5851_F42D_4C95_7F2D_u64);
        let (mut through, mut degenerate) = (0, 0);
        for i in 0..40_000 {
            let [a, b, mut c] = [0; 3].map(|_| [next(), next(), next()]);
            let axis = i % 3;
            if i % 13 == 0 {
                // Parallel to the axis.
                c = b;
                c[axis] += 0.25;
            }
            let t = [a, b, c];
            let mut s = match (i / 3) % 5 {
                0 | 1 => [next(), next(), next()],
                // In the plane, up to the rounding of the combination.
                2 => {
                    let (u, v) = (next() + 0.5, next() + 0.5);
                    [0, 1, 2].map(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]))
                }
                // On an edge's line (projected) or at a corner.
                3 => [0, 1, 2].map(|k| 0.5 * (a[k] + b[k])),
                _ => t[i % 3],
            };
            if (i / 3) % 5 >= 3 {
                s[axis] += next();
            }
            let mut e = s;
            e[axis] = if i % 2 == 0 { 2.0 } else { -2.0 };
            let ours = crossing(s, e, axis, &t, &Plane::new(&t));
            let theirs = crossing_by_orient3d(s, e, &t);
            through += usize::from(matches!(ours, Crossing::Through(_)));
            degenerate += usize::from(matches!(ours, Crossing::Degenerate));
            assert!(same(&ours, &theirs), "{t:?} {s:?} {e:?}");
        }
        assert!(through > 1000 && degenerate > 100, "{through} {degenerate}");
    }

    #[test]
    fn winding_inside_and_outside_a_cube() {
        let corners = cube();
        let boxes: Vec<Aabb> = corners.iter().map(|t| Aabb::of(*t)).collect();
        let grid = Grid::new(&boxes);
        let planes: Vec<Plane> = corners.iter().map(Plane::new).collect();
        let tris = (&corners[..], &planes[..]);
        let mut seen = Seen::new(corners.len());
        let inside = [0.3, 0.4, 0.45];
        for axis in 0..3 {
            for sign in [1.0, -1.0] {
                let w = grid.winding(tris, inside, axis, sign, &[], &mut seen, None);
                assert_eq!(w, Some(1));
                let w = grid.winding(tris, [1.5, 0.3, 0.4], axis, sign, &[], &mut seen, None);
                assert_eq!(w, Some(0));
            }
        }
        // Through the diagonal of a face: degenerate.
        let w = grid.winding(tris, [0.5, 0.5, 0.5], 2, 1.0, &[], &mut seen, None);
        assert_eq!(w, None);
    }

    /// `n` cubes scattered over a region of 3 × 2 × 1, of many sizes up to a quarter of `size` (the
    /// product of two uniform numbers: mostly small), so that a grid over them has cells of several
    /// entries and empty ones.
    fn scattered_boxes(next: &mut impl FnMut() -> f64, n: usize, size: f64) -> Vec<Aabb> {
        (0..n)
            .map(|_| {
                let lo = [next() * 3.0, next() * 2.0, next()];
                let s = size * next() * next();
                Aabb::of([lo, lo.map(|x| x + s)])
            })
            .collect()
    }

    /// [`Grid::index`] (clamp, then a cast to u32) is the saturating cast to usize, then the clamp,
    /// that it replaced: on points in and about the grid, far off it, at its edges, and NaN.
    #[test]
    fn cell_index_is_the_saturating_casts() {
        let mut next = uniform(0x1d3c_55aa_0f0f_7e21);
        let boxes = scattered_boxes(&mut next, 500, 0.05);
        let grid = Grid::new(&boxes);
        let old = |k: usize, x: f64| {
            let i = (x - grid.lo[k]) / grid.cell[k];
            if i.is_nan() || i < 0.0 {
                0
            } else {
                (i as usize).min(grid.dims[k] - 1)
            }
        };
        for k in 0..3 {
            let (lo, hi) = (grid.bounds.lo[k], grid.bounds.hi[k]);
            let mut xs = vec![lo, hi, -0.0, 0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300];
            xs.extend((0..=grid.dims[k]).map(|i| lo + i as f64 * grid.cell[k]));
            xs.extend((0..2000).map(|_| lo + (next() * 1.5 + 0.5) * (hi - lo)));
            for x in xs {
                assert_eq!(grid.index(k, x), old(k, x), "axis {k}, x = {x:e}");
            }
        }
    }

    /// Sorting what a box query finds by (first shared cell, number) is the query's own order.
    #[test]
    fn first_shared_cells_give_the_query_order() {
        let mut next = uniform(11);
        let boxes = scattered_boxes(&mut next, 600, 0.75);
        let grid = Grid::new(&boxes);
        assert!(grid.dims.iter().all(|&d| d > 2), "{:?}", grid.dims);
        let mut seen = Seen::new(boxes.len());
        let (mut found, mut several) = (Vec::new(), 0);
        for q in 0..300 {
            // Query boxes of the triangles themselves (as `all_blockers` asks) and others.
            let query = if q % 2 == 0 {
                boxes[q]
            } else {
                let lo = [next() * 3.0, next() * 2.0, next()];
                Aabb::of([lo, lo.map(|x| x + next())])
            };
            grid.overlapping(&query, None, &mut seen, &mut found);
            let mut sorted = found.clone();
            sorted.reverse();
            let corner = grid.cell_of(query.lo);
            sorted.sort_unstable_by_key(|&u| (grid.first_shared_cell(corner, &boxes[u as usize]), u));
            assert_eq!(sorted, found, "query {q}");
            several += usize::from(found.len() > 1);
        }
        assert!(several > 50, "{several}");
    }

    /// Boxes that each span much of the region (the long triangles of star prisms) would fill about
    /// n² entries: the grid is made coarser until they fit the budget, and a query still finds
    /// exactly the boxes that meet it, each once. Scattered small boxes keep the finer grid.
    #[test]
    fn a_grid_of_spanning_boxes_is_made_coarser() {
        let mut next = uniform(0x5eed_0b0c_1234_9876);
        let n = 6_000;
        let boxes: Vec<Aabb> = (0..n)
            .map(|_| {
                let lo = [next() * 0.3, next() * 0.3, next() * 0.3];
                Aabb::of([lo, [0.7 + next() * 0.3, 0.7 + next() * 0.3, 0.7 + next() * 0.3]])
            })
            .collect();
        let budget = MAX_ENTRIES_PER_TRIANGLE * n as u64 + MIN_ENTRIES;
        let fine: u64 = {
            // The entries of the grid that the count alone would choose (about as many cells as boxes).
            let h = (1.0f64 / n as f64).cbrt();
            let d = (1.0 / h).ceil();
            let cells = |lo: f64, hi: f64| ((hi * d).floor().min(d - 1.0) - (lo * d).floor().max(0.0) + 1.0) as u64;
            boxes.iter().map(|b| (0..3).map(|k| cells(b.lo[k], b.hi[k])).product::<u64>()).sum()
        };
        assert!(fine > 50 * budget, "{fine} entries against {budget}");
        let grid = Grid::new(&boxes);
        assert!(grid.items.len() as u64 <= budget, "{} entries against {budget}", grid.items.len());
        assert!(grid.dims.iter().all(|&d| d > 1), "{:?}", grid.dims);
        let mut seen = Seen::new(n);
        let mut found = Vec::new();
        for q in 0..200 {
            let lo = [next(), next(), next()];
            let query = Aabb::of([lo, lo.map(|x| x + 0.1 * next())]);
            grid.overlapping(&query, None, &mut seen, &mut found);
            found.sort_unstable();
            let want: Vec<u32> = (0..n as u32).filter(|&i| super::super::overlap(&boxes[i as usize], &query)).collect();
            assert_eq!(found, want, "query {q}");
        }
        let small = scattered_boxes(&mut next, 6_000, 0.05);
        let grid = Grid::new(&small);
        let ext = grid.bounds.extent();
        let h = (ext.iter().product::<f64>() / 6_000.0).cbrt();
        assert_eq!(grid.dims, ext.map(|e| (e / h).ceil() as usize));
    }

    #[test]
    fn row_entries_count_the_cells_a_ray_reads() {
        let mut next = uniform(7);
        let boxes = scattered_boxes(&mut next, 400, 0.4);
        let grid = Grid::new(&boxes);
        assert!(grid.dims.iter().all(|&d| d > 2), "{:?}", grid.dims);
        for _ in 0..200 {
            let p = [next() * 3.0, next() * 2.0, next()];
            let idx = [0, 1, 2].map(|k| grid.index(k, p[k]));
            for axis in 0..3 {
                for sign in [1.0, -1.0] {
                    // The cells the ray walks, as `winding` walks them, and their entries.
                    let mut want = 0;
                    for ck in 0..grid.dims[axis] {
                        let ahead = if sign > 0.0 { ck >= idx[axis] } else { ck <= idx[axis] };
                        if ahead {
                            let mut i = idx;
                            i[axis] = ck;
                            let c = (i[0] * grid.dims[1] + i[1]) * grid.dims[2] + i[2];
                            want += grid.cell_items(c).0.len();
                        }
                    }
                    assert_eq!(grid.row_entries(p, axis, sign), want, "{p:?} {axis} {sign}");
                }
            }
        }
    }

    /// A dyadic number near `x`: a multiple of 2⁻¹², so that the points of [`on_triangle`] are
    /// exact also 68,000 m from the origin.
    fn dyadic(x: f64) -> f64 {
        (x * 4096.0).round() / 4096.0
    }

    /// Points of triangle `t` exactly (dyadic corners, weights in 64ths): its corners, points
    /// along its edges and inside it.
    fn on_triangle(t: &Corners) -> Vec<[f64; 3]> {
        let mut out = Vec::new();
        for i in (0..=64).step_by(4) {
            for j in (0..=64 - i).step_by(4) {
                let w = [f64::from(i) / 64.0, f64::from(j) / 64.0, f64::from(64 - i - j) / 64.0];
                out.push(std::array::from_fn(|k| w[0] * t[0][k] + w[1] * t[1][k] + w[2] * t[2][k]));
            }
        }
        out
    }

    /// Triangles as CAD fans have them, `offset` from the origin, corners dyadic: long slivers
    /// slanting across the region, fans in planes along the axes (a cap), small triangles, and
    /// triangles with collinear corners.
    fn slanted_triangles(next: &mut impl FnMut() -> f64, offset: f64) -> Vec<Corners> {
        let mut point = |scale: f64, at: [f64; 3]| -> [f64; 3] { std::array::from_fn(|k| dyadic(offset + at[k] + scale * next())) };
        let mut out = Vec::new();
        for _ in 0..300 {
            let (a, b) = (point(4.0, [0.0; 3]), point(4.0, [0.0; 3]));
            let c: [f64; 3] = std::array::from_fn(|k| dyadic(b[k] + 0.01 * (k as f64 - 1.0)));
            out.push([a, b, c]);
        }
        for axis in 0..3 {
            let n = 96;
            let centre = point(2.0, [0.0; 3]);
            let rim = |i: usize| -> [f64; 3] {
                let angle = std::f64::consts::TAU * i as f64 / n as f64;
                let (j, l) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut p = centre;
                p[j] = dyadic(centre[j] + 1.5 * angle.cos());
                p[l] = dyadic(centre[l] + 1.5 * angle.sin());
                p
            };
            out.extend((0..n).map(|i| [centre, rim(i), rim(i + 1)]));
        }
        for _ in 0..600 {
            let a = point(4.0, [0.0; 3]);
            let near = a.map(|x| x - offset);
            out.push([a, point(0.05, near), point(0.05, near)]);
        }
        for _ in 0..100 {
            let (a, b) = (point(4.0, [0.0; 3]), point(4.0, [0.0; 3]));
            out.push([a, b, std::array::from_fn(|k| 0.5 * (a[k] + b[k]))]);
        }
        out
    }

    /// Every point of a triangle is in a cell that lists it, as [`Grid::index`] finds the cell
    /// (that is how rays and box queries look cells up), for slanted triangles at the origin and
    /// far from it; the entries are some of those of the grid of their boxes, and far fewer.
    #[test]
    fn triangles_sit_in_the_cell_of_each_of_their_points() {
        let mut next = uniform(0x0dd5_1a7e_5eed_2026);
        for offset in [0.0, 68_000.0, -4096.5] {
            let tris = slanted_triangles(&mut next, offset);
            let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::of(*t)).collect();
            let grid = Grid::of_triangles(&boxes, &tris);
            let full = Grid::new(&boxes);
            assert_eq!(grid.dims, full.dims);
            for (i, t) in tris.iter().enumerate() {
                for p in on_triangle(t) {
                    let c = grid.cell_number(grid.cell_of(p));
                    let listed = grid.cell_items(c).0.contains(&(i as u32));
                    assert!(listed, "offset {offset}: triangle {i} {t:?} not in the cell of {p:?}");
                }
            }
            for c in 0..grid.start.len() - 1 {
                let (ours, all) = (grid.cell_items(c).0, full.cell_items(c).0);
                assert!(ours.iter().all(|i| all.contains(i)), "cell {c}");
            }
            let (ours, all) = (grid.items.len(), full.items.len());
            assert!(3 * ours < 2 * all, "offset {offset}: {ours} entries against {all}");
        }
    }

    /// A closed cylinder of long triangles (its side two long slivers a segment, its caps fans):
    /// rays through the grid of the triangles count the winding number the grid of their boxes
    /// counts, and what the cylinder is, 1 inside and 0 outside, at the origin and far from it.
    #[test]
    fn rays_count_in_the_grid_of_triangles_what_they_count_in_the_grid_of_boxes() {
        let mut next = uniform(0xc711_4de2_0bad_cafe);
        for offset in [0.0, 68_000.0] {
            let n = 128;
            let (r, h) = (1.0, 6.0);
            let rim = |i: usize, z: f64| {
                let a = std::f64::consts::TAU * (i % n) as f64 / n as f64;
                [offset + r * a.cos(), offset + r * a.sin(), offset + z]
            };
            let (bottom, top) = ([offset, offset, offset], [offset, offset, offset + h]);
            let mut tris = Vec::new();
            for i in 0..n {
                tris.push([rim(i, 0.0), rim(i + 1, 0.0), rim(i + 1, h)]);
                tris.push([rim(i, 0.0), rim(i + 1, h), rim(i, h)]);
                tris.push([bottom, rim(i + 1, 0.0), rim(i, 0.0)]);
                tris.push([top, rim(i, h), rim(i + 1, h)]);
            }
            let boxes: Vec<Aabb> = tris.iter().map(|t| Aabb::of(*t)).collect();
            let planes: Vec<Plane> = tris.iter().map(Plane::new).collect();
            let (grid, full) = (Grid::of_triangles(&boxes, &tris), Grid::new(&boxes));
            let (ours, all) = (grid.items.len(), full.items.len());
            assert!(ours < all, "{ours} entries against {all}");
            let mut seen = Seen::new(tris.len());
            let mut counted = 0;
            for _ in 0..4000 {
                let p = [offset + 2.4 * next(), offset + 2.4 * next(), offset + h / 2.0 + 7.0 * next()];
                let (x, y, z) = (p[0] - offset, p[1] - offset, p[2] - offset);
                let inside = x * x + y * y < 0.98 * r * r && z > 0.01 && z < h - 0.01;
                let outside = x * x + y * y > r * r * 1.001 || !(-0.01..=h + 0.01).contains(&z);
                let axis = (next() * 6.0 + 3.0) as usize % 3;
                let sign = if next() < 0.0 { -1.0 } else { 1.0 };
                let ours = grid.winding((&tris, &planes), p, axis, sign, &[], &mut seen, None);
                let theirs = full.winding((&tris, &planes), p, axis, sign, &[], &mut seen, None);
                assert_eq!(ours, theirs, "{p:?} along {axis} ({sign})");
                if let Some(w) = ours {
                    if inside || outside {
                        assert_eq!(w, i64::from(inside), "{p:?} along {axis} ({sign})");
                        counted += 1;
                    }
                }
            }
            assert!(counted > 3000, "{counted}");
        }
    }
}
