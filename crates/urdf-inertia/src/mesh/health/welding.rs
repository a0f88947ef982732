//! The mesh after both welding passes, less the faces stored twice: duplicates kept once, a face and
//! its reverse dropped in pairs.

use super::topology::grouped;
use crate::mass::Polygons;
use crate::mesh::weld;

/// The mesh after both welding passes: stored vertices (bit-exact welded), the stored faces, and the
/// topology the tolerant weld gives them.
pub(super) struct Welding {
    pub(super) vertices: Vec<[f64; 3]>,
    /// All faces as stored (bit-exact welded), less duplicates.
    pub(super) stored: Polygons,
    /// The stored faces that survive the tolerant weld, in stored vertex indices.
    pub(super) kept: Polygons,
    /// The same faces in representative indices: the topology.
    pub(super) topology: Polygons,
    pub(super) tolerant: weld::TolerantWeld,
    /// Faces that collapsed under the tolerant weld.
    pub(super) collapsed: usize,
    /// Faces dropped as extra copies of a face (same direction), which the stored integral counts
    /// twice.
    pub(super) duplicates: usize,
    /// Faces dropped in pairs, a face and its reverse, which cancel in the integral anyway.
    pub(super) cancelled: usize,
    /// The extra copies dropped, as stored (a face kept once stands for them): the winding number of
    /// the surface as stored counts them, so deciding overlapping shells face by face puts them back.
    pub(super) copies: Polygons,
}

pub(super) fn tolerant_welding(exact: weld::ExactWeld, precision: weld::Precision) -> Welding {
    let tol = weld::tolerance(&exact.vertices, precision);
    let tolerant = weld::tolerant(&exact.vertices, tol);
    let (all_topology, kept_mask) = weld::remap_faces(&exact.faces, &tolerant.representative);
    let (dropped, duplicates, cancelled, extra) = duplicate_faces(&all_topology);
    let mut copies = Polygons::new();
    // Room for every face: most are kept, and growing three lists face by face copied them.
    let room = || Polygons::with_capacity(exact.faces.len(), exact.faces.indices.len());
    let (mut stored, mut kept, mut topology) = (room(), room(), room());
    let mut t = 0;
    for (i, face) in exact.faces.iter().enumerate() {
        if !kept_mask[i] {
            stored.push(face);
            continue;
        }
        (0..extra[t]).for_each(|_| copies.push(face));
        if !dropped[t] {
            stored.push(face);
            kept.push(face);
            topology.push(all_topology.face(t));
        }
        t += 1;
    }
    Welding {
        collapsed: kept_mask.iter().filter(|k| !**k).count(),
        duplicates,
        cancelled,
        vertices: exact.vertices,
        stored,
        kept,
        topology,
        tolerant,
        copies,
    }
}

/// Faces that repeat another one's vertices in the same cyclic order (a duplicate: kept once) or in
/// the reverse order (a zero-thickness wall: the pair cancels, both dropped). Returns per face whether
/// it is dropped, how many extra copies were dropped, how many faces in cancelling pairs, and per
/// face kept how many extra copies it stands for.
pub(super) fn duplicate_faces(faces: &Polygons) -> (Vec<bool>, usize, usize, Vec<u32>) {
    // Each face's vertices rotated to start at the smallest index, in whichever direction reads
    // smaller, and whether that was backwards. Sorting the keys groups the copies.
    let canonical = |f: &[u32]| -> (Vec<u32>, bool) {
        let k = (0..f.len()).min_by_key(|&i| f[i]).unwrap_or(0);
        let forward: Vec<u32> = (0..f.len()).map(|i| f[(k + i) % f.len()]).collect();
        let backward: Vec<u32> = (0..f.len())
            .map(|i| f[(k + f.len() - i) % f.len()])
            .collect();
        if forward <= backward {
            (forward, false)
        } else {
            (backward, true)
        }
    };
    // Triangles (nearly every face) without allocating: the key is the rotated triple.
    let mut keys: Vec<([u32; 3], bool, u32)> = Vec::with_capacity(faces.len());
    let mut others: Vec<(Vec<u32>, bool, u32)> = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        if let [a, b, c] = *f {
            let (x, y, z) = if a < b && a < c {
                (a, b, c)
            } else if b < c {
                (b, c, a)
            } else {
                (c, a, b)
            };
            let key = if y <= z {
                ([x, y, z], false)
            } else {
                ([x, z, y], true)
            };
            keys.push((key.0, key.1, i as u32));
        } else {
            let (key, reversed) = canonical(f);
            others.push((key, reversed, i as u32));
        }
    }
    sort_by_first_vertex(&mut keys);
    others.sort_unstable();
    let mut dropped = vec![false; faces.len()];
    let mut extra = vec![0u32; faces.len()];
    let (mut repeated, mut cancelled) = (0, 0);
    let mut drop_group = |members: &[(bool, u32)]| {
        let ahead = members.iter().filter(|m| !m.0).count();
        let back = members.len() - ahead;
        cancelled += 2 * ahead.min(back);
        let copies = (ahead.max(back) - ahead.min(back)).saturating_sub(1);
        repeated += copies;
        // Keep one face of the majority direction (none when the directions balance).
        let keep_dir = back > ahead;
        let mut keep = usize::from(ahead != back);
        for &(reversed, i) in members {
            if reversed == keep_dir && keep > 0 {
                keep -= 1;
                extra[i as usize] = copies as u32;
            } else {
                dropped[i as usize] = true;
            }
        }
    };
    for group in keys.chunk_by(|a, b| a.0 == b.0).filter(|g| g.len() > 1) {
        let members: Vec<(bool, u32)> = group.iter().map(|m| (m.1, m.2)).collect();
        drop_group(&members);
    }
    for group in others.chunk_by(|a, b| a.0 == b.0).filter(|g| g.len() > 1) {
        let members: Vec<(bool, u32)> = group.iter().map(|m| (m.1, m.2)).collect();
        drop_group(&members);
    }
    (dropped, repeated, cancelled, extra)
}

/// Sorts triangle keys as `sort_unstable` would (they are all distinct, so the order is the same):
/// a counting sort by the first vertex, then each bucket, a handful of keys, on its own. A comparison
/// sort of all keys took 6% of healing the 381 ERD meshes.
pub(super) fn sort_by_first_vertex(keys: &mut Vec<([u32; 3], bool, u32)>) {
    let n = keys.iter().map(|k| k.0[0] as usize + 1).max().unwrap_or(0);
    let (start, mut sorted) = grouped(n, |put| {
        for k in keys.iter() {
            put(k.0[0] as usize, *k);
        }
    });
    for w in start.windows(2) {
        sorted[w[0] as usize..w[1] as usize].sort_unstable();
    }
    *keys = sorted;
}
