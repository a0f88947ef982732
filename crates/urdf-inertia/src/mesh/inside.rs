//! Whether a point is inside a closed triangle mesh: the mesh's triangles bucketed on a (y, z) grid
//! ([`MeshLocator`]) so that a ray along +x from the point meets only the few triangles above and below
//! it, and the parity of its crossings decides. [`winding_number`] is the slower, exact reference the
//! tests compare with. The overlap estimate (`crate::overlap`) is what asks; a locator can also be
//! built over only the triangles that can decide points of one region, and then says where in that
//! region the surface may pass (for the estimate's error bound).
//!
//! Bounded work and memory: a triangle is put only in the buckets its projection meets (a sliver
//! crosses a row of cells, not its bounding box of cells), and the buckets hold at most
//! [`LOCATOR_ENTRIES`] triangle references (fewer, larger buckets otherwise).

#[cfg(any(test, feature = "internals"))]
use crate::geometry::sub;
use crate::mesh::health::{Aabb, Solid};

/// Most triangle references a mesh's bucket grid may hold (4 bytes each: 64 MiB).
pub const LOCATOR_ENTRIES: usize = 1 << 24;

/// A closed triangle mesh's triangles bucketed on a (y, z) grid for point-in-solid tests by ray parity:
/// all of them, or (for the overlap estimate) only those that can decide a point in a given region.
///
/// The buckets are one flat list (`entries`, bucket `c` is `entries[starts[c]..starts[c + 1]]`), so the
/// memory is the references themselves and nothing per bucket but an offset.
#[derive(Debug)]
pub struct MeshLocator {
    /// The located triangles, copied as the ray test reads them: a bucket's tests read one block per
    /// triangle instead of three vertices scattered over the mesh (and the locator need not hold it).
    triangles: Vec<RayTriangle>,
    lo: [f64; 2],
    cell: [f64; 2],
    grid: usize,
    starts: Vec<usize>,
    entries: Vec<u32>,
    /// The low corner of the whole mesh's (y, z) extent: a point below it is outside, as it always
    /// was when the grid spanned the whole mesh.
    floor: [f64; 2],
    /// Where in the region the locator was built for the surface may pass (for the estimate's
    /// error bound); `None` for a whole-mesh locator, or when marking would take too long.
    pub(crate) surface: Option<SurfaceCells>,
}

/// Cells per axis of [`SurfaceCells`]' grid (one bit per cell along the third axis in a `u32`).
const SURFACE_GRID: usize = 32;

/// Most words [`SurfaceCells::new`] may set (one word is up to 32 cells): past it, the surface is
/// taken to meet every cell, which only widens the bound.
const SURFACE_MARKS: usize = 1 << 22;

/// The cells of a [`SURFACE_GRID`]³ grid over a region (mesh frame) that some triangle's bounding box
/// meets: a box that meets no marked cell holds no point of the surface, so it lies all inside or all
/// outside the solid. 4 KiB per mesh part.
#[derive(Debug)]
pub(crate) struct SurfaceCells {
    lo: [f64; 3],
    cell: [f64; 3],
    /// `words[a * SURFACE_GRID + b]` bit `c`: cell (a, b, c) is marked.
    words: Vec<u32>,
}

impl SurfaceCells {
    fn new<'a>(triangles: impl Iterator<Item = &'a [[f64; 3]; 3]>, region: &Aabb) -> Option<Self> {
        let g = SURFACE_GRID;
        let lo = region.lo;
        let cell = [0, 1, 2].map(|k| ((region.hi[k] - lo[k]) / g as f64).max(f64::MIN_POSITIVE));
        let mut out = SurfaceCells {
            lo,
            cell,
            words: vec![0; g * g],
        };
        let mut marks = 0usize;
        for t in triangles {
            let b = triangle_box(t);
            if (0..3).any(|k| b.hi[k] < region.lo[k] || b.lo[k] > region.hi[k]) {
                continue;
            }
            let [(a0, a1), (b0, b1), (c0, c1)] = out.range(&b);
            marks += (a1 - a0 + 1) * (b1 - b0 + 1);
            if marks > SURFACE_MARKS {
                return None;
            }
            let mask = bits(c0, c1);
            for a in a0..=a1 {
                for w in &mut out.words[a * g + b0..=a * g + b1] {
                    *w |= mask;
                }
            }
        }
        Some(out)
    }

    /// The cells a box meets along each axis (with [`cells`]' slack; clamped into the grid).
    fn range(&self, b: &Aabb) -> [(usize, usize); 3] {
        [0, 1, 2].map(|k| cells(b.lo[k], b.hi[k], self.lo[k], self.cell[k], SURFACE_GRID))
    }

    /// Whether the surface may meet the box `b` (mesh frame).
    pub(crate) fn may_meet(&self, b: &Aabb) -> bool {
        let [(a0, a1), (b0, b1), (c0, c1)] = self.range(b);
        let mask = bits(c0, c1);
        (a0..=a1).any(|a| {
            self.words[a * SURFACE_GRID + b0..=a * SURFACE_GRID + b1]
                .iter()
                .any(|w| w & mask != 0)
        })
    }
}

/// Bits `c0..=c1` of a `u32` (`c1 < 32`).
fn bits(c0: usize, c1: usize) -> u32 {
    (u32::MAX >> (31 - c1)) & (u32::MAX << c0)
}

/// A triangle as [`MeshLocator::contains`] reads it: for each edge (opposite corner 0, 1, 2) the end
/// its signed area is taken from, the edge vector from there (negated where the end is the other
/// triangle's: see [`Self::new`]), and whether the edge owns points on it
/// ([`edge_rule`]); and the corners' x. Computed once per triangle instead of once per point test.
#[derive(Debug, Clone, Copy)]
struct RayTriangle {
    from: [[f64; 2]; 3],
    edge: [[f64; 2]; 3],
    owns: [bool; 3],
    x: [f64; 3],
    /// No point at `x ≥ reach` sees a crossing here: the crossing [`MeshLocator::contains`] computes
    /// is a rounded weighted mean of the corners' x with weights of one sign, so it exceeds the
    /// largest corner x by at most about 8 ε times the largest |x| (1e-12 of it is far above that).
    reach: f64,
}

impl RayTriangle {
    fn new(p: &[[f64; 3]; 3]) -> Self {
        let mut t = RayTriangle {
            from: [[0.0; 2]; 3],
            edge: [[0.0; 2]; 3],
            owns: [false; 3],
            x: p.map(|v| v[0]),
            reach: 0.0,
        };
        t.reach = reach(p);
        for e in 0..3 {
            let (a, b) = (p[(e + 1) % 3], p[(e + 2) % 3]);
            let owns = edge_rule(a, b);
            let (o, f) = if owns { (a, b) } else { (b, a) };
            t.from[e] = [o[1], o[2]];
            // Negated for an edge taken from the other end: the area then comes out with this
            // triangle's orientation, exactly the negation of the other triangle's (negating a
            // factor negates a rounded product and difference exactly; only the sign of a zero
            // can differ, which no test below tells apart), with no branch per point test.
            let d = [f[1] - o[1], f[2] - o[2]];
            t.edge[e] = if owns { d } else { [-d[0], -d[1]] };
            t.owns[e] = owns;
        }
        t
    }

    /// Twice the signed area of edge `e` and `q` projected on the (y, z) plane, evaluated from the
    /// edge's own first end (by [`edge_rule`]) so that the two triangles sharing an edge get exactly
    /// opposite values: rounding must not put a point on that edge inside both or neither.
    fn orient(&self, e: usize, q: [f64; 3]) -> f64 {
        let ([oy, oz], [dy, dz]) = (self.from[e], self.edge[e]);
        dy * (q[2] - oz) - dz * (q[1] - oy)
    }
}

/// See [`RayTriangle::reach`].
fn reach(p: &[[f64; 3]; 3]) -> f64 {
    let top = p[0][0].max(p[1][0]).max(p[2][0]);
    let size = p[0][0].abs().max(p[1][0].abs()).max(p[2][0].abs());
    top + 1e-12 * size
}

/// The range of cells a closed interval `[a, b]` meets along axis `k` of a grid.
fn cells(a: f64, b: f64, lo: f64, cell: f64, grid: usize) -> (usize, usize) {
    // The cast saturates (below 0 and NaN give 0): `floor().max(0.0)`'s cell without its libm call,
    // which showed in profiles (docs/benchmarks.md).
    let index = |x: f64| (((x - lo) / cell) as usize).min(grid - 1);
    // A little slack: a point on a cell border goes to the upper cell, and rounding must not lose it.
    let pad = 1e-7 * cell;
    (index(a - pad), index(b + pad))
}

/// The z extent of a triangle projected on (y, z), cut to the band `y0 ≤ y ≤ y1`.
fn z_extent_in_band(p: &[[f64; 2]; 3], y0: f64, y1: f64) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in p {
        if v[0] >= y0 && v[0] <= y1 {
            lo = lo.min(v[1]);
            hi = hi.max(v[1]);
        }
    }
    for e in 0..3 {
        let (a, b) = (p[e], p[(e + 1) % 3]);
        for y in [y0, y1] {
            if (a[0] - y) * (b[0] - y) < 0.0 {
                let z = a[1] + (y - a[0]) / (b[0] - a[0]) * (b[1] - a[1]);
                lo = lo.min(z);
                hi = hi.max(z);
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// The solid's faces fan-triangulated, as corner coordinates.
fn corners(solid: &Solid) -> impl Iterator<Item = [[f64; 3]; 3]> + '_ {
    let v = &solid.vertices;
    solid.faces.iter().flat_map(move |f| {
        (1..f.len().saturating_sub(1)).map(move |k| [f[0], f[k], f[k + 1]].map(|i| v[i as usize]))
    })
}

/// The triangles of the solid's fan triangulation.
fn triangle_count(solid: &Solid) -> usize {
    solid.faces.iter().map(|f| f.len().saturating_sub(2)).sum()
}

/// The cells per axis for `triangles` triangles at about four per cell, at most 256 × 256.
fn default_grid(triangles: usize) -> usize {
    ((triangles as f64 / 4.0).sqrt().ceil() as usize).clamp(1, 256)
}

/// A triangle's bounding box.
fn triangle_box(t: &[[f64; 3]; 3]) -> Aabb {
    let lo = [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k]));
    let hi = [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k]));
    Aabb::new(lo, hi)
}

/// Cell references a grid over the whole mesh holds, bounded above (a triangle's rows of cells lie
/// within its bounding box of cells), with that grid's size: what [`MeshLocator::with_budget`] builds.
struct WholeMeshBound {
    lo: [f64; 2],
    cell: [f64; 2],
    grid: usize,
    entries: usize,
}

impl WholeMeshBound {
    fn new(solid: &Solid) -> Self {
        let grid = default_grid(triangle_count(solid));
        let (lo, cell) = MeshLocator::frame(&solid.vertices, grid);
        WholeMeshBound {
            lo,
            cell,
            grid,
            entries: 0,
        }
    }

    fn add(&mut self, b: &Aabb) {
        let (a0, a1) = cells(b.lo[1], b.hi[1], self.lo[0], self.cell[0], self.grid);
        let (b0, b1) = cells(b.lo[2], b.hi[2], self.lo[1], self.cell[1], self.grid);
        self.entries += (a1 - a0 + 1) * (b1 - b0 + 1);
    }

    /// The bound on the whole-mesh locator's point cost, if its grid is surely the first tried.
    fn cost(&self) -> Option<usize> {
        (self.entries <= LOCATOR_ENTRIES).then(|| 2 + self.entries / (self.grid * self.grid))
    }
}

impl MeshLocator {
    /// Buckets `solid`'s triangles within [`LOCATOR_ENTRIES`] references; a mesh of more triangles than
    /// that gets one bucket holding them all.
    #[cfg(any(test, feature = "internals"))]
    pub fn new(solid: &Solid) -> Self {
        Self::with_budget(solid, LOCATOR_ENTRIES).unwrap_or_else(|| {
            let triangles: Vec<_> = corners(solid).collect();
            let (lo, cell) = Self::frame(&solid.vertices, 1);
            Self::bucket(triangles, lo, cell, 1, usize::MAX, Self::floor(solid)).expect("no budget")
        })
    }

    /// Buckets `solid`'s triangles on the finest grid (at most 256 × 256, about four triangles per
    /// cell) whose buckets hold at most `entries` references in all; `None` if none does.
    #[cfg(any(test, feature = "internals"))]
    pub fn with_budget(solid: &Solid, entries: usize) -> Option<Self> {
        let mut triangles: Vec<_> = corners(solid).collect();
        if triangles.len() > entries {
            return None;
        }
        let mut grid = default_grid(triangles.len());
        loop {
            let (lo, cell) = Self::frame(&solid.vertices, grid);
            match Self::bucket(triangles, lo, cell, grid, entries, Self::floor(solid)) {
                Ok(l) => return Some(l),
                Err(_) if grid == 1 => return None,
                Err(t) => triangles = t,
            }
            grid /= 2;
        }
    }

    /// What one point test of the locator [`Self::with_budget`] builds over the whole mesh costs, in
    /// primitive tests: the triangles of an average bucket. (The overlap estimate sizes its sampling
    /// grid by a bound on it, whatever locator it tests with; the tests check the bound.)
    #[cfg(test)]
    fn whole_mesh_cost(solid: &Solid) -> usize {
        let triangles: Vec<_> = corners(solid).collect();
        let mut grid = default_grid(triangles.len());
        let mut starts = Vec::new();
        while triangles.len() <= LOCATOR_ENTRIES {
            let (lo, cell) = Self::frame(&solid.vertices, grid);
            match Self::count(&triangles, lo, cell, grid, LOCATOR_ENTRIES, &mut starts) {
                Some(n) => return 2 + n / (grid * grid),
                None if grid == 1 => break,
                None => grid /= 2,
            }
        }
        usize::MAX / 4
    }

    /// Buckets the triangles of `solid` that can decide a point in `region` (mesh frame): those whose
    /// (y, z) projection meets the region's and that reach past its low x (rays go along +x), on a grid
    /// over the region. Also returns the bound on the whole-mesh locator's cost (see
    /// [`WholeMeshBound`]), `None` when the bound says nothing. `None` when the mesh has more triangles
    /// than [`LOCATOR_ENTRIES`].
    pub(crate) fn within(solid: &Solid, region: &Aabb) -> Option<(Self, Option<usize>)> {
        let mut bound = WholeMeshBound::new(solid);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut triangles = Vec::new();
        let mut all = 0usize;
        for t in corners(solid) {
            all += 1;
            let b = triangle_box(&t);
            bound.add(&b);
            if b.hi[0] >= region.lo[0]
                && (1..3).all(|k| b.hi[k] >= region.lo[k] && b.lo[k] <= region.hi[k])
            {
                for k in 0..2 {
                    lo[k] = lo[k].min(b.lo[k + 1]);
                    hi[k] = hi[k].max(b.hi[k + 1]);
                }
                triangles.push(t);
            }
        }
        if all > LOCATOR_ENTRIES {
            return None;
        }
        // The grid spans where the region and the triangles meet.
        for k in 0..2 {
            lo[k] = lo[k].max(region.lo[k + 1]);
            hi[k] = hi[k].min(region.hi[k + 1]).max(lo[k]);
        }
        if triangles.is_empty() {
            (lo, hi) = ([0.0; 2], [0.0; 2]);
        }
        // Only these triangles can meet the region (the others are left of it or beside it).
        let surface = SurfaceCells::new(triangles.iter(), region);
        let mut grid = default_grid(triangles.len());
        loop {
            let cell = [0, 1].map(|k| ((hi[k] - lo[k]) / grid as f64).max(f64::MIN_POSITIVE));
            // One bucket holds every triangle, within the budget since the mesh is.
            let budget = if grid == 1 {
                usize::MAX
            } else {
                LOCATOR_ENTRIES
            };
            let floor = Self::floor(solid);
            match Self::bucket(triangles, lo, cell, grid, budget, floor) {
                Ok(mut l) => {
                    l.surface = surface;
                    return Some((l, bound.cost()));
                }
                Err(t) => triangles = t,
            }
            grid /= 2;
        }
    }

    /// The grid's origin and cell size over the vertices' (y, z) extent.
    fn frame(vertices: &[[f64; 3]], grid: usize) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for v in vertices {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k + 1]);
                hi[k] = hi[k].max(v[k + 1]);
            }
        }
        if vertices.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let cell = [0, 1].map(|k| ((hi[k] - lo[k]) / grid as f64).max(f64::MIN_POSITIVE));
        (lo, cell)
    }

    /// The low corner of the (y, z) extent of the solid's vertices.
    fn floor(solid: &Solid) -> [f64; 2] {
        Self::frame(&solid.vertices, 1).0
    }

    /// Calls `f(row, first column, last column)` for each row of cells the triangle's projection meets.
    fn rows(
        t: &[[f64; 3]; 3],
        lo: [f64; 2],
        cell: [f64; 2],
        grid: usize,
        mut f: impl FnMut(usize, usize, usize),
    ) {
        let p = t.map(|v| [v[1], v[2]]);
        let ymin = p[0][0].min(p[1][0]).min(p[2][0]);
        let ymax = p[0][0].max(p[1][0]).max(p[2][0]);
        let zmin = p[0][1].min(p[1][1]).min(p[2][1]);
        let zmax = p[0][1].max(p[1][1]).max(p[2][1]);
        let (a0, a1) = cells(ymin, ymax, lo[0], cell[0], grid);
        for a in a0..=a1 {
            let pad = 1e-7 * cell[0];
            let y0 = lo[0] + a as f64 * cell[0] - pad;
            let y1 = lo[0] + (a + 1) as f64 * cell[0] + pad;
            // The first and last rows reach to the grid's border (points there are clamped into them).
            let y0 = if a == 0 { f64::NEG_INFINITY } else { y0 };
            let y1 = if a == grid - 1 { f64::INFINITY } else { y1 };
            if ymin >= y0 && ymax <= y1 {
                // The whole triangle is in the band (most are: a cell holds about four), so its cut
                // is itself; the same cells as below, without the clipping.
                let (b0, b1) = cells(zmin, zmax, lo[1], cell[1], grid);
                f(a, b0, b1);
                continue;
            }
            let (z0, z1) = z_extent_in_band(&p, y0, y1).unwrap_or((zmin, zmax));
            let (b0, b1) = cells(z0.max(zmin), z1.min(zmax), lo[1], cell[1], grid);
            f(a, b0, b1);
        }
    }

    /// Counts each bucket's references into `starts[c + 1]`; the total, or `None` past `budget`.
    fn count(
        triangles: &[[[f64; 3]; 3]],
        lo: [f64; 2],
        cell: [f64; 2],
        grid: usize,
        budget: usize,
        starts: &mut Vec<usize>,
    ) -> Option<usize> {
        starts.clear();
        starts.resize(grid * grid + 1, 0);
        let mut total = 0usize;
        for t in triangles {
            Self::rows(t, lo, cell, grid, |a, b0, b1| {
                total += b1 - b0 + 1;
                for b in b0..=b1 {
                    starts[a * grid + b + 1] += 1;
                }
            });
            if total > budget {
                return None;
            }
        }
        Some(total)
    }

    /// Buckets the triangles on the given grid if they take at most `budget` references; the triangles
    /// back otherwise. One counting pass into the final offsets, one filling pass.
    fn bucket(
        triangles: Vec<[[f64; 3]; 3]>,
        lo: [f64; 2],
        cell: [f64; 2],
        grid: usize,
        budget: usize,
        floor: [f64; 2],
    ) -> Result<Self, Vec<[[f64; 3]; 3]>> {
        let mut starts = Vec::new();
        let Some(total) = Self::count(&triangles, lo, cell, grid, budget, &mut starts) else {
            return Err(triangles);
        };
        for c in 0..grid * grid {
            starts[c + 1] += starts[c];
        }
        let mut fill = starts.clone();
        let mut entries = vec![0u32; total];
        for (i, t) in triangles.iter().enumerate() {
            Self::rows(t, lo, cell, grid, |a, b0, b1| {
                for f in &mut fill[a * grid + b0..=a * grid + b1] {
                    entries[*f] = i as u32;
                    *f += 1;
                }
            });
        }
        let triangles: Vec<RayTriangle> = triangles.iter().map(RayTriangle::new).collect();
        Ok(MeshLocator {
            triangles,
            lo,
            cell,
            grid,
            starts,
            entries,
            floor,
            surface: None,
        })
    }

    /// Cells per axis of the bucket grid.
    #[cfg(any(test, feature = "internals"))]
    pub fn grid(&self) -> usize {
        self.grid
    }

    /// Triangle references held by all buckets.
    #[cfg(any(test, feature = "internals"))]
    pub fn entries(&self) -> usize {
        self.entries.len()
    }

    /// Whether `q` (mesh frame) is inside: the number of triangles a ray from `q` along +x crosses is odd.
    pub fn contains(&self, q: [f64; 3]) -> bool {
        if !(q[1] >= self.floor[0] && q[2] >= self.floor[1]) {
            return false;
        }
        // Points off the grid go to its border cells, which reach to infinity (see `rows`).
        let index =
            |x: f64, k: usize| (((x - self.lo[k]) / self.cell[k]) as usize).min(self.grid - 1);
        let c = index(q[1], 0) * self.grid + index(q[2], 1);
        let mut crossings = 0usize;
        for &t in &self.entries[self.starts[c]..self.starts[c + 1]] {
            let t = &self.triangles[t as usize];
            if t.reach < q[0] {
                continue;
            }
            // Signed areas in the (y, z) plane; the half-open sign rule counts a ray through an edge once.
            let w0 = t.orient(0, q);
            let w1 = t.orient(1, q);
            let w2 = t.orient(2, q);
            let [o0, o1, o2] = t.owns;
            let inside = (w0 > 0.0 || w0 == 0.0 && o0)
                && (w1 > 0.0 || w1 == 0.0 && o1)
                && (w2 > 0.0 || w2 == 0.0 && o2)
                || (w0 < 0.0 || w0 == 0.0 && !o0)
                    && (w1 < 0.0 || w1 == 0.0 && !o1)
                    && (w2 < 0.0 || w2 == 0.0 && !o2);
            let sum = w0 + w1 + w2;
            if inside && sum != 0.0 && (w0 * t.x[0] + w1 * t.x[1] + w2 * t.x[2]) / sum > q[0] {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }
}

/// Tie-break for a point exactly on an edge: the edge owns it on one side only.
fn edge_rule(a: [f64; 3], b: [f64; 3]) -> bool {
    (b[1], b[2]) > (a[1], a[2])
}

/// The winding number of a closed, outward surface around `q`: 1 inside, 0 outside.
#[cfg(any(test, feature = "internals"))]
pub fn winding_number(solid: &Solid, q: [f64; 3]) -> f64 {
    let mut total = 0.0;
    for face in solid.faces.iter() {
        let a = sub(solid.vertices[face[0] as usize], q);
        for k in 1..face.len().saturating_sub(1) {
            let b = sub(solid.vertices[face[k] as usize], q);
            let c = sub(solid.vertices[face[k + 1] as usize], q);
            let n = crate::geometry::norm;
            total += crate::geometry::solid_angle(a, b, c, n(a), n(b), n(c));
        }
    }
    total / (4.0 * std::f64::consts::PI)
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::health::HealthOptions;

    /// A cone along +x (base radius 1 at x = 0, apex at x = 1) of `2 n` sliver triangles seen along x.
    fn cone(n: u32) -> Solid {
        let mut v = vec![[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        for i in 0..n {
            let a = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(n);
            v.push([0.0, a.cos(), a.sin()]);
        }
        let mut f = Vec::new();
        for i in 0..n {
            let (p, q) = (2 + i, 2 + (i + 1) % n);
            f.push([0, p, q]);
            f.push([1, q, p]);
        }
        let raw = crate::mesh::RawMesh {
            vertices: v,
            faces: crate::mass::Polygons::from_triangles(&f),
            ..Default::default()
        };
        crate::mesh::health::make_solid(&raw, std::path::Path::new("cone"), HealthOptions::default())
            .expect("solid")
    }

    /// Bounded buckets: slivers go only into the cells their projection meets, the references stay
    /// within the budget (a coarser grid otherwise), and points are still located right, those
    /// level with the slivers' shared edges included.
    #[test]
    fn sliver_buckets_stay_within_the_budget() {
        let solid = cone(4096);
        let fine = MeshLocator::with_budget(&solid, LOCATOR_ENTRIES).expect("fits");
        // 8192 slivers from the axis to the rim of a 46-cell grid: each crosses at most the 23 rows and
        // 23 columns it spans, 46 cells and a few for the slack (its bounding box of cells is up to
        // 23 × 23 = 529).
        assert_eq!(fine.grid(), 46);
        assert!(fine.entries() <= 8192 * 49, "{}", fine.entries());
        let coarse = MeshLocator::with_budget(&solid, 60_000).expect("fits when coarser");
        assert!(coarse.grid() < 46 && coarse.entries() <= 60_000);
        assert!(MeshLocator::with_budget(&solid, 8000).is_none());
        for l in [&fine, &coarse] {
            for a in 0..12 {
                for b in 0..12 {
                    for c in 0..12 {
                        let q = [
                            0.05 + 0.9 * f64::from(a) / 11.0,
                            -1.0 + 2.0 * f64::from(b) / 11.0 + 1e-3,
                            -1.0 + 2.0 * f64::from(c) / 11.0 + 1e-3,
                        ];
                        let r = (q[1] * q[1] + q[2] * q[2]).sqrt();
                        let inside = r < 0.99 * (1.0 - q[0]);
                        let outside = r > 1.01 * (1.0 - q[0]);
                        if inside || outside {
                            assert_eq!(l.contains(q), inside, "{q:?}");
                        }
                    }
                }
            }
            // On the diagonal, level with shared edges (vertex 512 is at 45°).
            assert!(l.contains([0.3, 0.1, 0.1]) && l.contains([0.3, -0.2, -0.2]));
        }
    }

    /// A region suffices: a locator over only the triangles that can decide points of a region
    /// answers as the whole-mesh one and as the winding number at many random points of that
    /// region, and the cost bound from its pass bounds the whole-mesh locator's cost (the grid size
    /// depends on it).
    #[test]
    fn a_region_locator_agrees_with_the_winding_number() {
        let solid = cone(500);
        let whole = MeshLocator::new(&solid);
        let region = Aabb::new([0.1, -0.3, 0.05], [0.7, 0.6, 0.5]);
        let (part, bound) = MeshLocator::within(&solid, &region).expect("fits");
        assert!(part.triangles.len() < whole.triangles.len() / 2);
        let exact = MeshLocator::whole_mesh_cost(&solid);
        assert!(bound.is_some_and(|b| b >= exact), "{bound:?} < {exact}");
        let mut seed = 14u64;
        let mut unit = || crate::lcg_unit(&mut seed);
        let mut inside = 0;
        for _ in 0..4000 {
            let q = [0, 1, 2].map(|k| region.lo[k] + (region.hi[k] - region.lo[k]) * unit());
            let w = winding_number(&solid, q);
            assert_eq!(part.contains(q), whole.contains(q), "{q:?}");
            if w.abs() > 1e-6 && (w - 1.0).abs() > 1e-6 {
                continue; // on the surface
            }
            assert_eq!(part.contains(q), w > 0.5, "{q:?}");
            inside += usize::from(w > 0.5);
        }
        assert!(inside > 400, "{inside}");
    }

    #[test]
    fn winding_number_of_a_closed_box() {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                [
                    f64::from(i & 1),
                    f64::from((i >> 1) & 1),
                    f64::from((i >> 2) & 1),
                ]
            })
            .collect();
        let quads = [
            [0u32, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let tris: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let raw = crate::mesh::RawMesh {
            vertices: v,
            faces: crate::mass::Polygons::from_triangles(&tris),
            ..Default::default()
        };
        let solid =
            crate::mesh::health::make_solid(&raw, std::path::Path::new("box"), HealthOptions::default())
                .expect("solid");
        assert!((winding_number(&solid, [0.5, 0.5, 0.5]) - 1.0).abs() < 1e-12);
        assert!(winding_number(&solid, [1.5, 0.5, 0.5]).abs() < 1e-12);
    }
}
