//! How much of a link's volume its parts count more than once.
//!
//! A link's parts are integrated as a disjoint union (Problem 1). Where parts overlap, the overlap is
//! counted once per part covering it: the excess is the parts' volumes less the volume of their union,
//! `Σ vᵢ − |∪ Pᵢ| = Σᵢ ∫_{Pᵢ} (1 − 1/k(x)) dx` with `k(x)` the number of parts covering `x`. The estimate
//! samples that integral on a grid per part, over the region where the part's bounding box meets its
//! neighbours' (candidate pairs come from a sweep over the bounding boxes, so disjoint parts cost
//! nothing), and tests each point against the solids: analytically for primitives, and for meshes by the
//! parity of a ray along +x, with the mesh's triangles bucketed on a (y, z) grid so that a point meets
//! only the few triangles above and below it. (A mesh here is a healed, closed solid; [`winding_number`]
//! is the slower, exact reference the tests compare with.)
//!
//! The estimate comes with a bound on its error ([`OverlapEstimate::bound`]): a grid cell that no
//! surface crosses has one covering count throughout, so its centre's sample is exact there; the
//! bound is the volume of the cells a surface may cross (primitives decide that analytically, meshes
//! by a 32³ grid of the cells their triangles' bounding boxes meet), plus the boxes' meeting of
//! pairs overlapping too little to be sampled.
//!
//! Bounded work and memory: a triangle is put only in the buckets its projection meets (a sliver
//! crosses a row of cells, not its bounding box of cells), the buckets hold at most
//! [`LOCATOR_ENTRIES`] triangle references (fewer, larger buckets otherwise), the samples per part
//! shrink so that all point tests stay within [`POINT_TEST_BUDGET`], a cap no minimum grid overrides
//! (so a link of N overlapping parts costs O(N); the bound widens instead, and the estimate says
//! so), and more than [`MAX_PAIRS`] overlapping pairs skip the estimate with a reason.

#[cfg(any(test, feature = "internals"))]
use crate::geometry::{dot, sub};
use crate::mass::{mat_vec, transpose, Mat3};
use crate::mesh::health::Solid;
use std::sync::Arc;

/// Most triangle references a mesh's bucket grid may hold (4 bytes each: 64 MiB).
pub const LOCATOR_ENTRIES: usize = 1 << 24;

/// Point tests (in units of one primitive test) the sampling of one link may take: a cap. The grid
/// per part shrinks to keep within it however many parts overlap (down to one sample per part), and
/// the estimate's error bound widens with the grid; see [`OverlapEstimate::bound`].
pub const POINT_TEST_BUDGET: usize = 1 << 25;

/// Pairs of parts whose bounding boxes overlap beyond which the estimate is skipped.
pub const MAX_PAIRS: usize = 1 << 20;

/// Samples per axis of a part's grid, at most.
pub const GRID: usize = 24;
// The sampling keeps one bit per sample along an axis in a `u32`.
const _: () = assert!(GRID <= 32);

/// A part's solid in its own frame.
#[derive(Debug, Clone)]
pub enum PartShape {
    /// Half extents.
    Box([f64; 3]),
    /// Along z: radius, half length.
    Cylinder(f64, f64),
    Sphere(f64),
    /// Along z: radius, half length of the cylindrical part.
    Capsule(f64, f64),
    Mesh(Arc<Solid>),
}

pub use crate::mesh::health::Aabb;

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
    surface: Option<SurfaceCells>,
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
struct SurfaceCells {
    lo: [f64; 3],
    cell: [f64; 3],
    /// `words[a * SURFACE_GRID + b]` bit `c`: cell (a, b, c) is marked.
    words: Vec<u32>,
}

impl SurfaceCells {
    fn new<'a>(triangles: impl Iterator<Item = &'a [[f64; 3]; 3]>, region: &Aabb) -> Option<Self> {
        let g = SURFACE_GRID;
        let lo = region.0;
        let cell = [0, 1, 2].map(|k| ((region.1[k] - lo[k]) / g as f64).max(f64::MIN_POSITIVE));
        let mut out = SurfaceCells {
            lo,
            cell,
            words: vec![0; g * g],
        };
        let mut marks = 0usize;
        for t in triangles {
            let b = triangle_box(t);
            if (0..3).any(|k| b.1[k] < region.0[k] || b.0[k] > region.1[k]) {
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
        [0, 1, 2].map(|k| cells(b.0[k], b.1[k], self.lo[k], self.cell[k], SURFACE_GRID))
    }

    /// Whether the surface may meet the box `b` (mesh frame).
    fn may_meet(&self, b: &Aabb) -> bool {
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
/// its signed area is taken from, the edge vector from there, and whether the edge owns points on it
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
            t.edge[e] = [f[1] - o[1], f[2] - o[2]];
            t.owns[e] = owns;
        }
        t
    }

    /// Twice the signed area of edge `e` and `q` projected on the (y, z) plane, evaluated from the
    /// edge's own first end (by [`edge_rule`]) so that the two triangles sharing an edge get exactly
    /// opposite values: rounding must not put a point on that edge inside both or neither.
    fn orient(&self, e: usize, q: [f64; 3]) -> f64 {
        let ([oy, oz], [dy, dz]) = (self.from[e], self.edge[e]);
        let area = dy * (q[2] - oz) - dz * (q[1] - oy);
        if self.owns[e] {
            area
        } else {
            -area
        }
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
    // The cast saturates (below 0 and NaN give 0): `floor().max(0.0)`'s cell without its libm call
    // (floor was 1.7% of the ERD fill).
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
    (lo, hi)
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
        let (a0, a1) = cells(b.0[1], b.1[1], self.lo[0], self.cell[0], self.grid);
        let (b0, b1) = cells(b.0[2], b.1[2], self.lo[1], self.cell[1], self.grid);
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
    fn within(solid: &Solid, region: &Aabb) -> Option<(Self, Option<usize>)> {
        let mut bound = WholeMeshBound::new(solid);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut triangles = Vec::new();
        let mut all = 0usize;
        for t in corners(solid) {
            all += 1;
            let b = triangle_box(&t);
            bound.add(&b);
            if b.1[0] >= region.0[0]
                && (1..3).all(|k| b.1[k] >= region.0[k] && b.0[k] <= region.1[k])
            {
                for k in 0..2 {
                    lo[k] = lo[k].min(b.0[k + 1]);
                    hi[k] = hi[k].max(b.1[k + 1]);
                }
                triangles.push(t);
            }
        }
        if all > LOCATOR_ENTRIES {
            return None;
        }
        // The grid spans where the region and the triangles meet.
        for k in 0..2 {
            lo[k] = lo[k].max(region.0[k + 1]);
            hi[k] = hi[k].min(region.1[k + 1]).max(lo[k]);
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

/// A part placed in the link frame: `x_link = R x_part + t`.
#[derive(Debug, Clone)]
pub struct PlacedPart {
    pub shape: PartShape,
    pub rotation: Mat3,
    pub translation: [f64; 3],
    /// Bounding box in the link frame.
    pub bbox: ([f64; 3], [f64; 3]),
    /// Volume (m³).
    pub volume: f64,
    /// For meshes: the bucketed triangles, built when first needed.
    pub locator: Option<Arc<MeshLocator>>,
}

impl PlacedPart {
    /// Whether the link-frame point `p` is inside the part.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        let d = [
            p[0] - self.translation[0],
            p[1] - self.translation[1],
            p[2] - self.translation[2],
        ];
        let q = mat_vec(&transpose(&self.rotation), d);
        match &self.shape {
            PartShape::Box(h) => q[0].abs() <= h[0] && q[1].abs() <= h[1] && q[2].abs() <= h[2],
            PartShape::Cylinder(r, hl) => q[0] * q[0] + q[1] * q[1] <= r * r && q[2].abs() <= *hl,
            PartShape::Sphere(r) => q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= r * r,
            PartShape::Capsule(r, hl) => {
                let z = q[2].clamp(-hl, *hl);
                q[0] * q[0] + q[1] * q[1] + (q[2] - z) * (q[2] - z) <= r * r
            }
            PartShape::Mesh(_) => self.locator.as_ref().is_some_and(|l| l.contains(q)),
        }
    }

    /// Where the box of centre `x` and half sides `h` (link frame) lies: `Some(true)` when every
    /// point of it is surely inside the solid, `Some(false)` when surely outside, `None` when the
    /// part's surface may cross it. A verdict is what [`Self::contains`] says of `x`.
    fn classify(&self, x: [f64; 3], h: [f64; 3]) -> Option<bool> {
        let rt = transpose(&self.rotation);
        let q = mat_vec(&rt, [0, 1, 2].map(|k| x[k] - self.translation[k]));
        // The box's bounding box in the part's frame, grown by far more than the rounding of `q`
        // (a few ulps of its coordinates), so that the verdict holds for the box as it is exactly.
        let size = (0..3).fold(0.0f64, |m, k| m.max(q[k].abs()).max(h[k]));
        let e =
            [0, 1, 2].map(|k| (0..3).map(|m| rt[k][m].abs() * h[m]).sum::<f64>() + 1e-12 * size);
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        // `d` ± `r` against `limit`: the distance `d` of the centre from a centre set, moved by at most
        // the box's radius `r`, either way.
        let verdict = |inside: bool, outside: bool| {
            if inside {
                Some(true)
            } else if outside {
                Some(false)
            } else {
                None
            }
        };
        let around = |d: f64, r: f64, limit: f64| verdict(d + r < limit, d - r > limit);
        match &self.shape {
            PartShape::Box(hb) => verdict(
                (0..3).all(|k| q[k].abs() + e[k] < hb[k]),
                (0..3).any(|k| q[k].abs() - e[k] > hb[k]),
            ),
            PartShape::Sphere(r) => around(norm(q), norm(e), *r),
            PartShape::Cylinder(r, hl) => {
                let (rho, re) = (q[0].hypot(q[1]), e[0].hypot(e[1]));
                verdict(
                    rho + re < *r && q[2].abs() + e[2] < *hl,
                    rho - re > *r || q[2].abs() - e[2] > *hl,
                )
            }
            PartShape::Capsule(r, hl) => {
                let z = q[2].clamp(-hl, *hl);
                around(norm([q[0], q[1], q[2] - z]), norm(e), *r)
            }
            PartShape::Mesh(_) => {
                let locator = self.locator.as_ref()?;
                let surface = locator.surface.as_ref()?;
                let b = (
                    [0, 1, 2].map(|k| q[k] - e[k]),
                    [0, 1, 2].map(|k| q[k] + e[k]),
                );
                (!surface.may_meet(&b)).then(|| locator.contains(q))
            }
        }
    }

    /// Builds the mesh locator if this part is a mesh, over the triangles that can decide a point of
    /// `region` (link frame; the only points it will be tested at). Returns a bound on what one point
    /// test costs, in primitive tests, by the measure [`grid_size`] has always used (the whole-mesh
    /// locator's, [`MeshLocator::whole_mesh_cost`]; `usize::MAX / 4` when that bound says nothing).
    /// `None` when the mesh has more triangles than [`LOCATOR_ENTRIES`] (it cannot be located).
    fn prepare(&mut self, region: &Aabb) -> Option<usize> {
        let PartShape::Mesh(solid) = &self.shape else {
            return Some(1);
        };
        let rt = transpose(&self.rotation);
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for c in 0..8 {
            let x = [0, 1, 2].map(|k| {
                if c >> k & 1 == 0 {
                    region.0[k]
                } else {
                    region.1[k]
                }
            });
            let q = mat_vec(&rt, [0, 1, 2].map(|k| x[k] - self.translation[k]));
            for k in 0..3 {
                lo[k] = lo[k].min(q[k]);
                hi[k] = hi[k].max(q[k]);
            }
        }
        // Points are moved into the mesh frame one by one, each with its own rounding (~1e-16 of its
        // coordinates): a margin far above that keeps every triangle that can decide one of them.
        let scale = (0..3).fold(0.0f64, |m, k| m.max(lo[k].abs()).max(hi[k].abs()));
        let pad = 1e-9 * scale;
        let region = (lo.map(|v| v - pad), hi.map(|v| v + pad));
        let (locator, bound) = MeshLocator::within(solid, &region)?;
        self.locator = Some(Arc::new(locator));
        Some(bound.unwrap_or(usize::MAX / 4))
    }
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
            let (la, lb, lc) = (norm(a), norm(b), norm(c));
            let num = a[0] * (b[1] * c[2] - b[2] * c[1])
                + a[1] * (b[2] * c[0] - b[0] * c[2])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
            total += 2.0 * num.atan2(den);
        }
    }
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(any(test, feature = "internals"))]
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The volume a link's parts count more than once.
#[derive(Debug, Clone, PartialEq)]
pub struct OverlapEstimate {
    /// The parts' volumes less the volume of their union (m³).
    pub excess: f64,
    /// The parts (indices into the slice given) found inside another part somewhere.
    pub parts: Vec<usize>,
    /// The most parts found covering one sample point.
    pub most: usize,
    /// Samples per axis of each part's grid.
    pub grid: usize,
    /// The volume the estimate can be off by, at most: `|excess − true excess| ≤ bound` (m³). The
    /// cells a part's or a neighbour's surface may cross (each sample there is off by less than its
    /// cell's volume; elsewhere it is exact), and twice the box meeting of every pair too little
    /// overlapping to be sampled. Coarser grids make it wider.
    pub bound: f64,
    /// The work cap ([`POINT_TEST_BUDGET`]) set a grid coarser than [`GRID`] (many or costly parts):
    /// the bound is wider than the finest grid's.
    pub capped: bool,
}

/// What [`estimate`] found.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlap {
    /// No two parts' bounding boxes share more than 1% of the smaller part's volume.
    None,
    Estimated(OverlapEstimate),
    /// Not estimated, and why.
    Skipped(String),
}

/// The volume of the intersection of two bounding boxes (0 when they do not meet).
fn box_overlap(a: &PlacedPart, b: &PlacedPart) -> f64 {
    (0..3)
        .map(|k| (a.bbox.1[k].min(b.bbox.1[k]) - a.bbox.0[k].max(b.bbox.0[k])).max(0.0))
        .product()
}

/// For each part, the parts whose bounding boxes share more than 1% of the smaller one's volume with
/// its own: a sweep along the axis where the boxes are most spread, so that far apart parts are never
/// compared. `None` past [`MAX_PAIRS`] pairs.
fn neighbours(parts: &[PlacedPart]) -> Option<(Vec<Vec<usize>>, f64)> {
    let usable: Vec<usize> = (0..parts.len())
        .filter(|&i| {
            let p = &parts[i];
            p.volume > 0.0 && (0..3).all(|k| p.bbox.0[k].is_finite() && p.bbox.1[k].is_finite())
        })
        .collect();
    let spread = |k: usize| {
        let (lo, hi) = usable
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &i| {
                let c = 0.5 * (parts[i].bbox.0[k] + parts[i].bbox.1[k]);
                (lo.min(c), hi.max(c))
            });
        let mean_size: f64 = usable
            .iter()
            .map(|&i| parts[i].bbox.1[k] - parts[i].bbox.0[k])
            .sum::<f64>()
            / usable.len().max(1) as f64;
        (hi - lo) / mean_size.max(f64::MIN_POSITIVE)
    };
    let axis = (0..3)
        .max_by(|&a, &b| spread(a).total_cmp(&spread(b)))
        .unwrap_or(0);
    let mut order = usable;
    order.sort_by(|&a, &b| parts[a].bbox.0[axis].total_cmp(&parts[b].bbox.0[axis]));
    let mut out = vec![Vec::new(); parts.len()];
    let mut active: Vec<usize> = Vec::new();
    let mut pairs = 0usize;
    let mut ignored = 0.0;
    for &i in &order {
        let start = parts[i].bbox.0[axis];
        active.retain(|&j| parts[j].bbox.1[axis] > start);
        for &j in &active {
            let (a, b) = (&parts[i], &parts[j]);
            let shared = box_overlap(a, b);
            if shared > 0.01 * a.volume.min(b.volume) {
                out[i].push(j);
                out[j].push(i);
                pairs += 1;
                if pairs > MAX_PAIRS {
                    return None;
                }
            } else {
                ignored += shared;
            }
        }
        active.push(i);
    }
    Some((out, ignored))
}

/// The grid size for every part: one size for all that keeps the point tests of every part and its
/// neighbours within `budget`, with `cost[i]` what one point test of part `i` costs.
fn grid_size(cost: &[usize], nb: &[Vec<usize>], involved: &[usize], budget: usize) -> usize {
    let cost: usize = involved
        .iter()
        .map(|&i| {
            nb[i]
                .iter()
                .fold(cost[i], |c, &j| c.saturating_add(cost[j]))
        })
        .fold(0usize, usize::saturating_add);
    let samples = budget / cost.max(1);
    // No floor above one sample: a floor would let the work grow past the cap with the parts.
    ((samples as f64).cbrt().floor() as usize).clamp(1, GRID)
}

/// Where part `i`'s box meets its neighbours' (the box around those meetings): the only place a
/// point can be covered twice, so the only place the part is sampled or tested.
fn region(parts: &[PlacedPart], nb: &[Vec<usize>], i: usize) -> Aabb {
    let p = &parts[i];
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &j in &nb[i] {
        let q = &parts[j];
        for k in 0..3 {
            lo[k] = lo[k].min(p.bbox.0[k].max(q.bbox.0[k]));
            hi[k] = hi[k].max(p.bbox.1[k].min(q.bbox.1[k]));
        }
    }
    (lo, hi)
}

/// What sampling one part found: the volume it shares (each point covered k times counts 1 − 1/k),
/// whether any point is shared, the most parts covering one point, and the volume of the cells a
/// surface may cross (where the samples may be wrong).
struct PartSample {
    shared: f64,
    found: bool,
    most: usize,
    uncertain: f64,
}

/// Samples part `i` on an `n`³ grid over its [`region`]. A cell that no surface of the part or of a
/// neighbour whose box it meets crosses has one covering count throughout, which its centre's
/// sample gets exactly; every other cell's sample is off by less than the cell's volume.
#[allow(clippy::too_many_lines)] // one pass over the cells: masks, sample and verdict together
fn sample_part(parts: &[PlacedPart], nb: &[Vec<usize>], i: usize, n: usize) -> PartSample {
    let p = &parts[i];
    let (lo, hi) = region(parts, nb, i);
    let cell_volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) / (n * n * n) as f64;
    let half = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]) / n as f64);
    // The surfaces are tested against each cell's core, the cell shrunk by `SHRINK` of its size: a
    // face on a cell's border (common: regions end at faces) leaves the core alone, and the shell
    // around the cores, a `3 SHRINK` part of the volume, counts as uncertain throughout.
    let core = half.map(|h| h * (1.0 - SHRINK));
    // The sample coordinates along each axis, and for each neighbour the samples within its box along
    // each axis as bits (`n` ≤ 24): a point is in the box iff its three bits are set. This is the
    // box test per point and neighbour, done n times per axis instead of n³. Likewise the cells
    // that meet its box.
    let axes = [0, 1, 2].map(|k| {
        (0..n)
            .map(|a| lo[k] + (hi[k] - lo[k]) * (a as f64 + 0.5) / n as f64)
            .collect::<Vec<f64>>()
    });
    let masks: Vec<(usize, [u32; 3], [u32; 3])> = nb[i]
        .iter()
        .map(|&j| {
            let b = &parts[j].bbox;
            let points = [0, 1, 2].map(|k| {
                axes[k].iter().enumerate().fold(0u32, |m, (a, &x)| {
                    m | (u32::from(x >= b.0[k] && x <= b.1[k]) << a)
                })
            });
            let cells = [0, 1, 2].map(|k| {
                axes[k].iter().enumerate().fold(0u32, |m, (a, &x)| {
                    m | (u32::from(x + half[k] >= b.0[k] && x - half[k] <= b.1[k]) << a)
                })
            });
            (j, points, cells)
        })
        .filter(|(_, _, m)| m.iter().all(|&m| m != 0))
        .collect();
    let mut out = PartSample {
        shared: 0.0,
        found: false,
        most: 1,
        uncertain: 0.0,
    };
    let mut sum = 0.0;
    let mut uncertain = 0usize;
    let mut row: Vec<(usize, u32, u32)> = Vec::with_capacity(masks.len());
    for a in 0..n {
        for b in 0..n {
            row.clear();
            row.extend(
                masks
                    .iter()
                    .filter(|(_, _, m)| m[0] >> a & 1 == 1 && m[1] >> b & 1 == 1)
                    .map(|&(j, pm, cm)| {
                        let in_row = pm[0] >> a & 1 == 1 && pm[1] >> b & 1 == 1;
                        (j, if in_row { pm[2] } else { 0 }, cm[2])
                    }),
            );
            // A cell that meets no neighbour's box is covered once at most and adds nothing: skip
            // the part's own (costlier) tests there.
            let mut cs = row.iter().fold(0u32, |u, r| u | r.2);
            while cs != 0 {
                let c = cs.trailing_zeros() as usize;
                cs &= cs - 1;
                let x = [axes[0][a], axes[1][b], axes[2][c]];
                // A core the part's surface misses is all outside the part or all inside it; outside,
                // the part covers none of it, whatever the neighbours do.
                let own = p.classify(x, core);
                if own == Some(false) {
                    continue;
                }
                let inside = own.unwrap_or_else(|| p.contains(x));
                // Each neighbour whose box the cell meets: whether its surface may cross the core,
                // and (where the centre is in its box) whether it covers the centre, which its
                // verdict on the core already says when there is one.
                let mut crossed = own.is_none();
                let mut k = 1;
                let mut in_a_box = false;
                for r in row.iter().filter(|r| r.2 >> c & 1 == 1) {
                    let v = parts[r.0].classify(x, core);
                    crossed |= v.is_none();
                    if r.1 >> c & 1 == 1 {
                        in_a_box = true;
                        if inside && v.unwrap_or_else(|| parts[r.0].contains(x)) {
                            k += 1;
                        }
                    }
                }
                if crossed {
                    uncertain += 1;
                }
                // A centre in no neighbour's box is covered once at most.
                if !inside || !in_a_box {
                    continue;
                }
                out.most = out.most.max(k);
                sum += 1.0 - 1.0 / k as f64;
            }
        }
    }
    // A part shares at most its own volume: on a coarse grid, a sample can stand for more.
    // (The true share lies in [0, volume], so this only brings the estimate closer to it.)
    out.shared = (sum * cell_volume).min(p.volume);
    out.found = out.most > 1;
    out.uncertain = (uncertain as f64 + 3.0 * SHRINK * (n * n * n) as f64) * cell_volume;
    out
}

/// How much of its size a cell's core is smaller than the cell, per side (see [`sample_part`]).
const SHRINK: f64 = 1e-7;

/// Estimates the volume the parts count more than once (see the module docs). Builds the mesh
/// locators it needs.
pub fn estimate(parts: &mut [PlacedPart]) -> Overlap {
    estimate_within(parts, POINT_TEST_BUDGET)
}

/// [`estimate`] with a cap of `budget` point tests instead of [`POINT_TEST_BUDGET`].
fn estimate_within(parts: &mut [PlacedPart], budget: usize) -> Overlap {
    let Some((nb, ignored)) = neighbours(parts) else {
        return Overlap::Skipped(format!(
            "more than {MAX_PAIRS} pairs of parts have overlapping bounding boxes"
        ));
    };
    let involved: Vec<usize> = (0..parts.len()).filter(|&i| !nb[i].is_empty()).collect();
    if involved.is_empty() {
        return Overlap::None;
    }
    use rayon::prelude::*;
    let regions: Vec<Option<Aabb>> = (0..parts.len())
        .map(|i| (!nb[i].is_empty()).then(|| region(parts, &nb, i)))
        .collect();
    let bounds: Vec<Option<usize>> = parts
        .par_iter_mut()
        .zip(&regions)
        .map(|(p, r)| r.as_ref().map_or(Some(1), |r| p.prepare(r)))
        .collect();
    if let Some(i) = bounds.iter().position(Option::is_none) {
        return Overlap::Skipped(format!(
            "part {} has more than {LOCATOR_ENTRIES} triangles",
            i + 1
        ));
    }
    let bounds: Vec<usize> = bounds.into_iter().flatten().collect();
    // The grid size is from the whole-mesh locators' cost (outputs must not depend on how points
    // are located), as bounded by the pass that picks the triangles. (Counting it exactly where the
    // bound allows a coarser grid than the finest was a second pass over every mesh: a fifth of the
    // time of 100 overlapping convex pieces, for a grid one or two samples finer.)
    let n = grid_size(&bounds, &nb, &involved, budget);
    let parts: &[PlacedPart] = parts;
    let results: Vec<PartSample> = involved
        .par_iter()
        .map(|&i| sample_part(parts, &nb, i, n))
        .collect();
    let excess: f64 = results.iter().map(|r| r.shared).sum();
    // Each part's samples are off by less than its uncertain cells' volume; the pairs left out as
    // neighbours share at most their boxes' meeting, which each of the two counts.
    let bound = results.iter().map(|r| r.uncertain).sum::<f64>() + 2.0 * ignored;
    // And the true excess lies between 0 and what the parts' regions can hold (a point counts
    // 1 − 1/k < 1, and only where parts meet): the bound need not be wider than that interval.
    let most_excess = involved
        .iter()
        .map(|&i| {
            let r = regions[i].as_ref().map_or(0.0, |(lo, hi)| {
                (0..3).map(|k| (hi[k] - lo[k]).max(0.0)).product::<f64>()
            });
            parts[i].volume.min(r)
        })
        .sum::<f64>()
        + 2.0 * ignored;
    let bound = bound.min(excess.max(most_excess - excess));
    let found: Vec<usize> = involved
        .iter()
        .zip(&results)
        .filter(|(_, r)| r.found)
        .map(|(&i, _)| i)
        .collect();
    let smallest = found
        .iter()
        .map(|&i| parts[i].volume)
        .fold(f64::INFINITY, f64::min);
    let capped = n < GRID;
    if (found.is_empty() || excess <= 0.01 * smallest) && !(capped && bound > 0.01 * smallest) {
        return Overlap::None;
    }
    // A coarse grid may miss what the bound says can be there: the parts whose boxes meet.
    let parts_named = if found.is_empty() { involved } else { found };
    Overlap::Estimated(OverlapEstimate {
        excess,
        parts: parts_named,
        most: results.iter().map(|r| r.most).max().unwrap_or(1),
        grid: n,
        bound,
        capped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const ID: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn placed(shape: PartShape, t: [f64; 3], half: [f64; 3], volume: f64) -> PlacedPart {
        PlacedPart {
            shape,
            rotation: ID,
            translation: t,
            bbox: (
                [t[0] - half[0], t[1] - half[1], t[2] - half[2]],
                [t[0] + half[0], t[1] + half[1], t[2] + half[2]],
            ),
            volume,
            locator: None,
        }
    }

    fn estimated(parts: &mut [PlacedPart]) -> OverlapEstimate {
        match estimate(parts) {
            Overlap::Estimated(e) => e,
            other => panic!("expected an estimate, got {other:?}"),
        }
    }

    #[test]
    fn two_boxes_overlapping_by_half() {
        let mut parts = [
            placed(PartShape::Box([0.5; 3]), [0.0; 3], [0.5; 3], 1.0),
            placed(PartShape::Box([0.5; 3]), [0.5, 0.0, 0.0], [0.5; 3], 1.0),
        ];
        let e = estimated(&mut parts);
        assert!((e.excess - 0.5).abs() < 1e-12, "{e:?}");
        assert_eq!((e.parts.clone(), e.most, e.grid), (vec![0, 1], 2, GRID));
    }

    #[test]
    fn boxes_overlap_but_solids_do_not() {
        // A small box in the corner of a sphere's bounding box, outside the sphere.
        let mut parts = [
            placed(
                PartShape::Sphere(1.0),
                [0.0; 3],
                [1.0; 3],
                4.0 / 3.0 * std::f64::consts::PI,
            ),
            placed(PartShape::Box([0.1; 3]), [0.9, 0.9, 0.9], [0.1; 3], 0.008),
        ];
        assert_eq!(estimate(&mut parts), Overlap::None);
    }

    /// Issue 13: 200 coincident boxes count the box 200 times: 199 of 200 copies (99.5% of the summed
    /// volume) are excess, where the largest pair showed 0.5%.
    #[test]
    fn coincident_boxes_sum_every_copy() {
        let mut parts: Vec<PlacedPart> = (0..200)
            .map(|_| placed(PartShape::Box([0.5; 3]), [0.0; 3], [0.5; 3], 1.0))
            .collect();
        let e = estimated(&mut parts);
        assert!((e.excess - 199.0).abs() < 1e-9, "{e:?}");
        assert_eq!((e.parts.len(), e.most), (200, 200));
    }

    /// Three spheres in a row, each overlapping the next: the excess is the two lens volumes (exact:
    /// π(4r + d)(2r − d)²/12 for radius r at distance d), within the grid's resolution.
    #[test]
    fn a_chain_of_spheres_sums_its_lenses() {
        let (r, d) = (1.0, 1.5);
        let v = 4.0 / 3.0 * std::f64::consts::PI;
        let mut parts: Vec<PlacedPart> = (0..3)
            .map(|i| {
                placed(
                    PartShape::Sphere(r),
                    [d * f64::from(i), 0.0, 0.0],
                    [r; 3],
                    v,
                )
            })
            .collect();
        let lens = std::f64::consts::PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
        let e = estimated(&mut parts);
        assert!(
            (e.excess / (2.0 * lens) - 1.0).abs() < 0.05,
            "{e:?} against {}",
            2.0 * lens
        );
        assert_eq!((e.parts.len(), e.most), (3, 2));
    }

    /// Issue 13: 2000 disjoint spheres cost nothing but the sweep (no pair, no sampling).
    #[test]
    fn disjoint_spheres_have_no_overlap() {
        let v = 4.0 / 3.0 * std::f64::consts::PI * 0.001;
        let mut parts: Vec<PlacedPart> = (0..2000)
            .map(|i| {
                let t = [
                    f64::from(i % 20) * 0.25,
                    f64::from(i / 20 % 10) * 0.25,
                    f64::from(i / 200) * 0.25,
                ];
                placed(PartShape::Sphere(0.1), t, [0.1; 3], v)
            })
            .collect();
        assert_eq!(
            neighbours(&parts).map(|n| n.0.iter().map(Vec::len).sum::<usize>()),
            Some(0)
        );
        assert_eq!(estimate(&mut parts), Overlap::None);
    }

    /// Too many overlapping pairs skip the estimate with the reason.
    #[test]
    fn too_many_pairs_are_skipped() {
        let mut parts: Vec<PlacedPart> = (0..1500)
            .map(|_| placed(PartShape::Sphere(1.0), [0.0; 3], [1.0; 3], 4.0))
            .collect();
        assert!(
            matches!(estimate(&mut parts), Overlap::Skipped(m) if m.contains("pairs of parts"))
        );
    }

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
        crate::mesh::health::make_solid(&raw, std::path::Path::new("cone"), Default::default())
            .expect("solid")
    }

    /// Issue 13: slivers go only into the cells their projection meets, the references stay within the
    /// budget (a coarser grid otherwise), and points are still located right, those level with the
    /// slivers' shared edges included.
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

    /// Issue 14: a locator over only the triangles that can decide points of a region answers as the
    /// whole-mesh one and as the winding number at many random points of that region, and the cost
    /// bound from its pass bounds the whole-mesh locator's cost (the grid size depends on it).
    #[test]
    fn a_region_locator_agrees_with_the_winding_number() {
        let solid = cone(500);
        let whole = MeshLocator::new(&solid);
        let region = ([0.1, -0.3, 0.05], [0.7, 0.6, 0.5]);
        let (part, bound) = MeshLocator::within(&solid, &region).expect("fits");
        assert!(part.triangles.len() < whole.triangles.len() / 2);
        let exact = MeshLocator::whole_mesh_cost(&solid);
        assert!(bound.is_some_and(|b| b >= exact), "{bound:?} < {exact}");
        let mut seed = 14u64;
        let mut unit = || crate::lcg_unit(&mut seed);
        let mut inside = 0;
        for _ in 0..4000 {
            let q = [0, 1, 2].map(|k| region.0[k] + (region.1[k] - region.0[k]) * unit());
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

    /// A box of half sides `h` centred at the origin as a closed, outward mesh solid.
    fn box_solid(h: [f64; 3]) -> Solid {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { h[k] } else { -h[k] }))
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
        crate::mesh::health::make_solid(&raw, std::path::Path::new("box"), Default::default())
            .expect("solid")
    }

    /// The volume of a union of axis-aligned boxes, exact: on the grid of all their coordinates each
    /// elementary cell is in the union or not, and with coordinates that are multiples of 1/8 below
    /// 2^20 every difference and product here is exact in f64.
    fn union_volume(boxes: &[Aabb]) -> f64 {
        let coords = |k: usize| {
            let mut c: Vec<f64> = boxes.iter().flat_map(|b| [b.0[k], b.1[k]]).collect();
            c.sort_by(f64::total_cmp);
            c.dedup();
            c
        };
        let [xs, ys, zs] = [0, 1, 2].map(coords);
        let mut total = 0.0;
        for x in xs.windows(2) {
            for y in ys.windows(2) {
                for z in zs.windows(2) {
                    let m = [x[0] + x[1], y[0] + y[1], z[0] + z[1]].map(|c| 0.5 * c);
                    if boxes
                        .iter()
                        .any(|b| (0..3).all(|k| b.0[k] < m[k] && m[k] < b.1[k]))
                    {
                        total += (x[1] - x[0]) * (y[1] - y[0]) * (z[1] - z[0]);
                    }
                }
            }
        }
        total
    }

    /// Random axis-aligned boxes (corners on a 1/8 grid), as primitives, some of them turned a quarter
    /// about z, and as meshes: the estimate is within its bound of the exact excess (volumes less
    /// the exact union), on the finest grid and on the coarse grid a small work cap gives, whose
    /// bound is wider and says so.
    #[test]
    fn the_bound_holds_against_an_exact_union_of_boxes() {
        let quarter: Mat3 = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        let mut seed = 25u64;
        let mut eighths = |lo: f64, hi: f64| {
            let u = crate::lcg_unit(&mut seed);
            (8.0 * (lo + (hi - lo) * u)).round() / 8.0
        };
        let boxes: Vec<(Aabb, bool)> = (0..40)
            .map(|i| {
                let lo = [0, 1, 2].map(|_| eighths(0.0, 3.0));
                let size = [0, 1, 2].map(|_| eighths(0.25, 1.5));
                ((lo, [0, 1, 2].map(|k| lo[k] + size[k])), i % 3 == 0)
            })
            .collect();
        let exact = boxes
            .iter()
            .map(|(b, _)| (0..3).map(|k| b.1[k] - b.0[k]).product::<f64>())
            .sum::<f64>()
            - union_volume(&boxes.iter().map(|b| b.0).collect::<Vec<_>>());
        assert!(exact > 1.0, "{exact}");
        for as_mesh in [false, true] {
            let parts: Vec<PlacedPart> = boxes
                .iter()
                .map(|&((lo, hi), turned)| {
                    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                    let mut h = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]));
                    if turned {
                        // The quarter turn about z maps the part's x to the link's y.
                        h.swap(0, 1);
                    }
                    let shape = if as_mesh {
                        PartShape::Mesh(Arc::new(box_solid(h)))
                    } else {
                        PartShape::Box(h)
                    };
                    let mut p = placed(shape, c, [0.0; 3], 8.0 * h[0] * h[1] * h[2]);
                    p.bbox = (lo, hi);
                    if turned {
                        p.rotation = quarter;
                    }
                    p
                })
                .collect();
            let mut bounds = Vec::new();
            for budget in [POINT_TEST_BUDGET, 1 << 14] {
                let e = match estimate_within(&mut parts.clone(), budget) {
                    Overlap::Estimated(e) => e,
                    other => panic!("expected an estimate, got {other:?}"),
                };
                let error = (e.excess - exact).abs();
                assert!(
                    error <= e.bound,
                    "{as_mesh} {budget}: {error} > {e:?} ({exact})"
                );
                assert_eq!(e.capped, e.grid < GRID);
                bounds.push((e.bound, e.capped, e.grid));
            }
            // The finest grid (24³ at most) against a capped one.
            assert!(!bounds[0].1 && bounds[1].1, "{bounds:?}");
            assert!(bounds[1].0 > bounds[0].0, "{bounds:?}");
        }
    }

    /// A chain of ten boxes (corners on a 1/8 grid), each overlapping the next by a quarter of its
    /// length and shifted sideways: the exact excess is within the bound, and the bound is a small
    /// part of it (every box's region is one meeting, crossed by few faces).
    #[test]
    fn the_bound_of_a_chain_of_boxes_is_tight() {
        let boxes: Vec<Aabb> = (0..10)
            .map(|i| {
                let lo = [0.75 * f64::from(i), 0.125 * f64::from(i % 3), 0.0];
                (lo, [lo[0] + 1.0, lo[1] + 1.0, lo[2] + 1.0])
            })
            .collect();
        let exact = 10.0 - union_volume(&boxes);
        let mut parts: Vec<PlacedPart> = boxes
            .iter()
            .map(|&(lo, hi)| {
                let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                placed(PartShape::Box([0.5; 3]), c, [0.5; 3], 1.0)
            })
            .collect();
        let e = estimated(&mut parts);
        let error = (e.excess - exact).abs();
        assert!(error <= e.bound, "{error} > {e:?} ({exact})");
        assert!(!e.capped && e.bound < 0.25 * exact, "{e:?} against {exact}");
    }

    /// 1000 boxes of side 1.5 on a unit lattice: their union is one box of side 10.5, so the excess is
    /// exactly 1000 · 1.5³ − 10.5³. The work cap (no minimum grid) takes a coarse grid, and the bound
    /// still holds.
    #[test]
    fn a_thousand_overlapping_boxes_stay_within_the_cap_and_the_bound() {
        let mut parts: Vec<PlacedPart> = (0..1000)
            .map(|i| {
                let t = [i % 10, i / 10 % 10, i / 100].map(f64::from);
                placed(PartShape::Box([0.75; 3]), t, [0.75; 3], 3.375)
            })
            .collect();
        let exact = 1000.0 * 3.375 - 10.5f64.powi(3);
        let e = estimated(&mut parts);
        assert!(e.capped && e.grid < GRID, "{e:?}");
        let error = (e.excess - exact).abs();
        assert!(
            error <= e.bound,
            "{error} > {} ({e:?}, exact {exact})",
            e.bound
        );
        assert_eq!(e.most, 8);
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
            crate::mesh::health::make_solid(&raw, std::path::Path::new("box"), Default::default())
                .expect("solid");
        assert!((winding_number(&solid, [0.5, 0.5, 0.5]) - 1.0).abs() < 1e-12);
        assert!(winding_number(&solid, [1.5, 0.5, 0.5]).abs() < 1e-12);
    }
}
