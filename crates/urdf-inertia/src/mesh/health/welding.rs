//! The mesh after both welding passes, less the faces stored twice: duplicates kept once, a face and
//! its reverse dropped in pairs.

use super::topology::grouped;
use crate::geometry::{norm, sub};
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
    /// What dropping them can change, m³: a pair cancels exactly only where its corners are stored
    /// at the same places; welded from corners apart, the two stored faces enclose a sliver
    /// ([`cancelled_volume`]).
    pub(super) cancelled_volume: f64,
    /// The extra copies dropped, as stored (a face kept once stands for them): the winding number of
    /// the surface as stored counts them, so deciding overlapping shells face by face puts them back.
    pub(super) copies: Polygons,
}

pub(super) fn tolerant_welding(exact: weld::ExactWeld, precision: weld::Precision) -> Welding {
    let tol = weld::tolerance(&exact.vertices, precision);
    let tolerant = weld::tolerant(&exact.vertices, tol);
    let (all_topology, kept_mask) = weld::remap_faces(&exact.faces, &tolerant.representative);
    let (dropped, duplicates, cancelled, extra, facing) = duplicate_faces(&all_topology);
    let cancelled_volume = cancelled_volume(&exact, &tolerant, &kept_mask, (&dropped, &facing));
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
        cancelled_volume,
        vertices: exact.vertices,
        stored,
        kept,
        topology,
        tolerant,
        copies,
    }
}

/// A bound on what dropping the faces of cancelling pairs changes, m³. A face (a, b, c) and its
/// reverse (a', c', b') welded onto the same corners contribute det(a − r, b − r, c − r)/6 and
/// −det(a' − r, b' − r, c' − r)/6 about the reference point r. About a, the pair's sum is
/// −det(a' − a, c' − a, b' − a)/6, at most Δ (L + Δ)² / 6 (Δ the largest distance between matched
/// corners, L the longest side); moving the reference to r adds (a − r) · (A + A') / 3, A + A' the
/// pair's vector area, at most 2 Δ L in length, so at most 2 D Δ L / 3 with D the box's diagonal.
/// Δ ≤ δ + δ' (each face's largest distance of a corner from its representative) and L + Δ ≤ each
/// face's longest side + 6 w (w the weld's widest move), so each face dropped adds
/// δ (ℓ²/6 + 2 D ℓ/3) with ℓ its longest side + 6 w. Summed over every face dropped in a group with
/// both directions (pairs and any copies beside them): 0 where the pairs are stored at the same
/// places. A tetrahedron 4.5e-12 m thick, welded flat into such a pair, was dropped 3.9e-11 off
/// its part's volume under an estimate of 1.1e-15.
fn cancelled_volume(
    exact: &weld::ExactWeld,
    tolerant: &weld::TolerantWeld,
    kept: &[bool],
    (dropped, facing): (&[bool], &[bool]),
) -> f64 {
    let v = &exact.vertices;
    let rep = &tolerant.representative;
    let mut bound = 0.0;
    let mut diagonal = None;
    let mut t = 0;
    for (i, face) in exact.faces.iter().enumerate() {
        if !kept[i] {
            continue;
        }
        if dropped[t] && facing[t] {
            let at = |k: usize| v[face[k % face.len()] as usize];
            let moved = face
                .iter()
                .map(|&c| norm(sub(v[c as usize], v[rep[c as usize] as usize])))
                .fold(0.0, f64::max);
            if moved > 0.0 {
                let d = *diagonal.get_or_insert_with(|| crate::geometry::Aabb::of(v.iter().copied()).diagonal());
                let side = (0..face.len()).map(|k| norm(sub(at(k + 1), at(k)))).fold(0.0, f64::max);
                let l = side + 6.0 * tolerant.widest;
                bound += moved * (l * l / 6.0 + 2.0 * d * l / 3.0);
            }
        }
        t += 1;
    }
    bound
}

/// Faces that repeat another one's vertices in the same cyclic order (a duplicate: kept once) or in
/// the reverse order (a zero-thickness wall: the pair cancels, both dropped). Returns per face whether
/// it is dropped, how many extra copies were dropped, how many faces in cancelling pairs, and per
/// face kept how many extra copies it stands for, and per face whether its group has both
/// directions (its drop is a cancelling pair's, or a copy's beside one).
pub(super) fn duplicate_faces(faces: &Polygons) -> (Vec<bool>, usize, usize, Vec<u32>, Vec<bool>) {
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
    let mut facing = vec![false; faces.len()];
    let (mut repeated, mut cancelled) = (0, 0);
    let mut drop_group = |members: &[(bool, u32)]| {
        let ahead = members.iter().filter(|m| !m.0).count();
        let back = members.len() - ahead;
        if ahead > 0 && back > 0 {
            for &(_, i) in members {
                facing[i as usize] = true;
            }
        }
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
    (dropped, repeated, cancelled, extra, facing)
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
