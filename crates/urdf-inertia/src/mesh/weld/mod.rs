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

/// Relative tolerance of the second pass, against the largest side of the bounding box.
mod join;
mod table;
mod tolerant;

pub use join::{join, join_chunks, join_in_place};
pub use table::VertexTable;
pub use tolerant::{tolerance, tolerant, Precision, TolerantWeld};
#[cfg(any(test, feature = "internals"))]
pub use tolerant::Tolerance;

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
    // Readers that weld as they read (STL) hand over distinct vertices already; raw triangle soups
    // have about one distinct vertex in six. The table grows either way.
    let mut table = VertexTable::with_capacity(vertices.len() / 4 + 16);
    let remap: Vec<u32> = vertices
        .iter()
        // +0.0 folds -0.0 into 0.0 so that both weld.
        .map(|p| table.insert([p[0] + 0.0, p[1] + 0.0, p[2] + 0.0]))
        .collect();
    drop(table.slots);
    let (faces, kept) = remap_faces(faces, &remap);
    let dropped = kept.iter().filter(|k| !**k).count();
    ExactWeld {
        vertices: table.vertices,
        faces,
        dropped,
    }
}

/// [`exact`] for vertices already pairwise distinct in their bits with no −0.0 (a reader that welded
/// as it read, [`crate::mesh::RawMesh::welded`]): nothing to merge, so only collapsed faces are
/// dropped, and the vectors are kept when none is (the common case: no copy, no hashing).
pub fn already_welded(vertices: Vec<[f64; 3]>, faces: Polygons) -> ExactWeld {
    let collapsed = |f: &[u32]| match *f {
        [a, b, c] => a == b || b == c || a == c,
        // Polygons fold runs of a repeated corner: `remap_faces` decides.
        _ => true,
    };
    if !any_face(&faces, collapsed) {
        return ExactWeld {
            vertices,
            faces,
            dropped: 0,
        };
    }
    let identity: Vec<u32> = (0..vertices.len() as u32).collect();
    let (faces, kept) = remap_faces(&faces, &identity);
    let dropped = kept.iter().filter(|k| !**k).count();
    ExactWeld {
        vertices,
        faces,
        dropped,
    }
}

/// Faces per chunk of [`any_face`]; meshes of fewer than two chunks are searched in order.
const ANY_CHUNK: usize = 1 << 15;

/// Whether some face is `hit`: on the pool in fixed chunks when it has more than one thread and the
/// mesh at least two chunks (the answer is the same), in order otherwise.
fn any_face(faces: &Polygons, hit: impl Fn(&[u32]) -> bool + Sync) -> bool {
    use rayon::prelude::*;
    let n = faces.len();
    if n < 2 * ANY_CHUNK {
        return faces.iter().any(hit);
    }
    crate::threads::install(|| {
        if rayon::current_num_threads() < 2 {
            return faces.iter().any(&hit);
        }
        (0..n.div_ceil(ANY_CHUNK)).into_par_iter().any(|c| {
            (c * ANY_CHUNK..((c + 1) * ANY_CHUNK).min(n)).any(|i| hit(faces.face(i)))
        })
    })
}

/// Faces through a vertex map: runs of a repeated vertex are folded, and faces left with fewer than
/// three distinct vertices are dropped. Returns the faces kept and, per input face, whether it was kept.
pub fn remap_faces(faces: &Polygons, remap: &[u32]) -> (Polygons, Vec<bool>) {
    let mut out = Polygons::with_capacity(faces.len(), faces.indices.len());
    let mut kept = Vec::with_capacity(faces.len());
    let mut f: Vec<u32> = Vec::new();
    let mut distinct: Vec<u32> = Vec::new();
    for face in faces.iter() {
        if let &[a, b, c] = face {
            // Triangles, the common case: no folding to do unless two corners meet.
            let (a, b, c) = (remap[a as usize], remap[b as usize], remap[c as usize]);
            let ok = a != b && b != c && a != c;
            if ok {
                out.indices.extend_from_slice(&[a, b, c]);
                out.starts.push(out.indices.len() as u32);
            }
            kept.push(ok);
            continue;
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collapsed_faces_are_dropped_and_counted() {
        let v = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let f = Polygons::from_triangles(&[[0, 1, 2], [0, 1, 3]]);
        let w = exact(&v, &f);
        assert_eq!(w.vertices.len(), 3);
        assert_eq!(w.faces.len(), 1);
        assert_eq!(w.dropped, 1);
    }

    /// A collapsed face found on the pool in any chunk, the last face included, or none: as the
    /// search in order finds it.
    #[test]
    fn collapsed_faces_are_found_in_any_chunk_on_the_pool() {
        let n = 5 * ANY_CHUNK + 3;
        let vertices: Vec<[f64; 3]> = (0..n + 2).map(|i| [i as f64, 0.0, 0.0]).collect();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("pool");
        for at in [None, Some(0), Some(2 * ANY_CHUNK + 1), Some(n - 1)] {
            let triangles: Vec<[u32; 3]> = (0..n as u32)
                .map(|i| match at {
                    Some(a) if a == i as usize => [i, i + 1, i],
                    _ => [i, i + 1, i + 2],
                })
                .collect();
            let faces = Polygons::from_triangles(&triangles);
            let w = pool.install(|| already_welded(vertices.clone(), faces.clone()));
            assert_eq!(w.dropped, usize::from(at.is_some()), "{at:?}");
            assert_eq!(w.faces.len(), n - w.dropped, "{at:?}");
        }
    }
}
