//! Welding: which stored corners are the same vertex.
//!
//! Two passes. The first merges bit-identical coordinates (after scaling) and is all a clean mesh pays
//! for. The second, run only when the first leaves the surface open or inconsistent, merges vertices that
//! coincide up to a tolerance relative to the mesh's size: CAD exporters write each facet's corners
//! independently, so one vertex shared by six facets is stored six ways that differ in the last bits, and
//! bit-exact welding sees those cracks as holes.
//!
//! The tolerance is `max(1e-9 × extent, 16 ulp of the largest coordinate)`, and for files that store
//! f32 coordinates (binary STL, glTF) at least two f32 ulps of the largest coordinate:
//! * 16 ulp of the largest |coordinate| covers round-off noise of any f64 computation on the
//!   coordinates, also for a small part far from the origin;
//! * 1e-9 of the largest bounding-box side covers the widest f64 float-noise cracks measured on real
//!   meshes (example-robot-data 6.0.0: at most 4e-14 of the extent) with four orders of margin;
//! * an exporter that rounds each facet's corners to f32 independently stores a shared corner one f32
//!   ulp apart in each coordinate when its f64 value lies near a rounding boundary (measured: the g1
//!   and ur3 meshes of example-robot-data, cracks of 7.45e-9 m = one f32 ulp at 0.1 m); such a file
//!   cannot tell apart points closer than that anyway;
//! * features are kept apart down to the tolerance: a 10 µm slot in a 1 m part is 1e-5 of it, four
//!   orders above the f64 tolerance and 40 times the f32 one (tested).
//!
//! The tolerant pass clusters greedily on a hash grid whose cells are one tolerance wide: each vertex,
//! in file order, joins the first earlier representative within the tolerance found in the 27 cells
//! around it, or becomes a representative itself. Representatives are more than a tolerance apart, so
//! a cell holds a bounded number of them and the pass is linear. The result is deterministic.
//!
//! Welding never moves a vertex: it only decides the topology (which faces share which edges). The mass
//! core integrates the triangles as stored.

use crate::mass::Polygons;
use rustc_hash::FxHashMap;

/// Relative tolerance of the second pass, against the largest side of the bounding box.
pub const RELATIVE_TOLERANCE: f64 = 1e-9;

/// Round-off allowance of the second pass, in ulps of the largest |coordinate|.
pub const ULPS: f64 = 16.0;

/// A mesh welded by bit-identical coordinates.
#[derive(Debug, Clone)]
pub struct ExactWeld {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Polygons,
    /// Faces that collapsed to fewer than three distinct vertices (dropped).
    pub dropped: usize,
}

/// Welds bit-identical vertices and drops faces that collapse to fewer than three distinct vertices.
pub fn exact(vertices: &[[f64; 3]], faces: &Polygons) -> ExactWeld {
    let mut map: FxHashMap<[u64; 3], u32> =
        FxHashMap::with_capacity_and_hasher(vertices.len() / 2, Default::default());
    let mut out = Vec::new();
    let remap: Vec<u32> = vertices
        .iter()
        .map(|p| {
            // +0.0 folds -0.0 into 0.0 so that both weld.
            let q = [p[0] + 0.0, p[1] + 0.0, p[2] + 0.0];
            *map.entry(q.map(f64::to_bits)).or_insert_with(|| {
                out.push(q);
                (out.len() - 1) as u32
            })
        })
        .collect();
    let (faces, kept) = remap_faces(faces, &remap);
    let dropped = kept.iter().filter(|k| !**k).count();
    ExactWeld {
        vertices: out,
        faces,
        dropped,
    }
}

/// Faces through a vertex map: runs of a repeated vertex are folded, and faces left with fewer than
/// three distinct vertices are dropped. Returns the faces kept and, per input face, whether it was kept.
pub fn remap_faces(faces: &Polygons, remap: &[u32]) -> (Polygons, Vec<bool>) {
    let mut out = Polygons::new();
    let mut kept = Vec::with_capacity(faces.len());
    let mut f: Vec<u32> = Vec::new();
    let mut distinct: Vec<u32> = Vec::new();
    for face in faces.iter() {
        f.clear();
        for &i in face {
            let j = remap[i as usize];
            if f.last() != Some(&j) {
                f.push(j);
            }
        }
        while f.len() > 1 && f.first() == f.last() {
            f.pop();
        }
        let ok = if f.len() == 3 {
            f[0] != f[1] && f[1] != f[2] && f[0] != f[2]
        } else {
            distinct.clear();
            distinct.extend_from_slice(&f);
            distinct.sort_unstable();
            distinct.dedup();
            distinct.len() >= 3
        };
        if ok {
            out.push(&f);
        }
        kept.push(ok);
    }
    (out, kept)
}

/// How a file stored the coordinates: a mesh stored in f32 (binary STL, glTF) cannot tell apart
/// corners closer than its own rounding, so its cracks are up to an f32 ulp of the largest coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    F32,
    F64,
}

impl Precision {
    /// The precision of coordinates as read (before scaling): f32 when every one is an f32 value.
    pub fn of(vertices: &[[f64; 3]]) -> Precision {
        let f32_exact = |x: f64| f64::from(x as f32) == x;
        if vertices.iter().flatten().all(|&x| f32_exact(x)) {
            Precision::F32
        } else {
            Precision::F64
        }
    }
}

/// The tolerance of the second pass for these vertices: `max(1e-9 × extent, 16 ulp of the largest
/// coordinate)`, and for coordinates stored as f32 at least two f32 ulps of the largest one (a corner
/// rounded up in one facet and down in the next is one ulp off in each coordinate).
pub fn tolerance(vertices: &[[f64; 3]], precision: Precision) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut largest = 0.0f64;
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
            largest = largest.max(v[k].abs());
        }
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
    let stored = match precision {
        Precision::F32 => 2.0 * f64::from(f32::EPSILON) * largest,
        Precision::F64 => 0.0,
    };
    (RELATIVE_TOLERANCE * extent)
        .max(ULPS * f64::EPSILON * largest)
        .max(stored)
}

/// Vertices merged within a tolerance.
#[derive(Debug, Clone)]
pub struct TolerantWeld {
    /// For each vertex, the index of its representative (an earlier vertex, or itself).
    pub representative: Vec<u32>,
    /// Vertices that joined another one.
    pub merged: usize,
    /// Largest distance of a vertex from its representative.
    pub widest: f64,
    pub tolerance: f64,
}

/// Merges vertices within `tol` of an earlier representative (Euclidean distance), greedily in index
/// order, on a hash grid of cell size `tol`.
pub fn tolerant(vertices: &[[f64; 3]], tol: f64) -> TolerantWeld {
    let n = vertices.len();
    let mut representative: Vec<u32> = (0..n as u32).collect();
    if !(tol > 0.0 && tol.is_finite()) || n == 0 {
        return TolerantWeld {
            representative,
            merged: 0,
            widest: 0.0,
            tolerance: tol,
        };
    }
    let origin = vertices[0];
    let cell = |p: &[f64; 3]| -> [i64; 3] {
        // Saturating casts: a cell index beyond i64 cannot happen for finite meshes whose extent is
        // at most 1e9 tolerances, but the cast must not wrap if it did.
        [0, 1, 2].map(|k| ((p[k] - origin[k]) / tol).floor() as i64)
    };
    let mut grid: FxHashMap<[i64; 3], Vec<u32>> =
        FxHashMap::with_capacity_and_hasher(n, Default::default());
    let tol2 = tol * tol;
    let mut merged = 0;
    let mut widest = 0.0f64;
    for i in 0..n {
        let p = &vertices[i];
        let c = cell(p);
        let mut found: Option<(u32, f64)> = None;
        'search: for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                for dz in -1..=1i64 {
                    let key = [
                        c[0].saturating_add(dx),
                        c[1].saturating_add(dy),
                        c[2].saturating_add(dz),
                    ];
                    let Some(reps) = grid.get(&key) else { continue };
                    for &r in reps {
                        let q = &vertices[r as usize];
                        let d2 =
                            (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                        if d2 <= tol2 && found.is_none_or(|(_, best)| d2 < best) {
                            found = Some((r, d2));
                            if d2 == 0.0 {
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        match found {
            Some((r, d2)) => {
                representative[i] = r;
                merged += 1;
                widest = widest.max(d2.sqrt());
            }
            None => grid.entry(c).or_default().push(i as u32),
        }
    }
    TolerantWeld {
        representative,
        merged,
        widest,
        tolerance: tol,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_merges_and_features_stay() {
        // Two copies of a corner a few ulps apart, and a point 10 µm away on a 1 m part.
        let a = [0.3, 0.7, 0.1];
        let b = [0.3 + 2.0 * f64::EPSILON, 0.7, 0.1 - f64::EPSILON];
        let slot = [0.3 + 1e-5, 0.7, 0.1];
        let far = [1.0, 1.0, 1.0];
        let v = vec![[0.0; 3], a, b, slot, far];
        let t = tolerant(&v, tolerance(&v, Precision::F64));
        assert_eq!(t.representative, vec![0, 1, 1, 3, 4]);
        assert_eq!(t.merged, 1);
    }

    #[test]
    fn tolerance_covers_parts_far_from_the_origin() {
        // A 1 mm part 1 km away: its round-off is 16 ulp of 1e3, above 1e-9 of 1e-3.
        let v = vec![[1e3, 0.0, 0.0], [1e3 + 1e-3, 1e-3, 1e-3]];
        assert_eq!(
            tolerance(&v, Precision::F64),
            16.0 * f64::EPSILON * (1e3 + 1e-3)
        );
    }

    #[test]
    fn collapsed_faces_are_dropped_and_counted() {
        let v = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let f = Polygons::from_triangles(&[[0, 1, 2], [0, 1, 3]]);
        let w = exact(&v, &f);
        assert_eq!(w.vertices.len(), 3);
        assert_eq!(w.faces.len(), 1);
        assert_eq!(w.dropped, 1);
    }
}
