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
//! Bounded work and memory: the point tests are [`crate::mesh::inside`]'s (bounded buckets), the
//! samples per part shrink so that all point tests stay within [`POINT_TEST_BUDGET`], a cap no
//! minimum grid overrides (so a link of N overlapping parts costs O(N); the bound widens instead,
//! and the estimate says so), and more than [`MAX_PAIRS`] overlapping pairs skip the estimate with a
//! reason.

use crate::mesh::health::Solid;
use rayon::prelude::*;
use std::sync::Arc;

mod part;
mod sample;
#[cfg(test)]
mod tests;

pub use crate::mesh::inside::LOCATOR_ENTRIES;
#[cfg(any(test, feature = "internals"))]
pub use crate::mesh::inside::{winding_number, MeshLocator};
pub use part::PlacedPart;
use sample::{grid_size, neighbours, region, sample_part, PartSample};

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
    /// The work cap ([`POINT_TEST_BUDGET`]) set a grid coarser than [`GRID`] (many or costly
    /// parts): the bound is wider than the finest grid's.
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
    // bound allows a coarser grid than the finest was a second pass over every mesh, costly for a grid
    // one or two samples finer: docs/benchmarks.md.)
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
            let r = regions[i].as_ref().map_or(0.0, |r| {
                (0..3).map(|k| (r.hi[k] - r.lo[k]).max(0.0)).product::<f64>()
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
