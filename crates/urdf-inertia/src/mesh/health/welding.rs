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
    /// What dropping the extra copies can change, m³: a copy stands for nothing only where its
    /// corners are stored at the kept face's places; welded from corners apart, the solid with the
    /// copy differs from the one without within the region between the two ([`copies_volume`]).
    pub(super) copies_volume: f64,
    /// What the faces that collapse under the tolerant weld can change, m³: they stay in the file's
    /// surface (and in `stored`), but out of the topology that decides the rung and the shells
    /// ([`collapsed_volume`]).
    pub(super) collapsed_volume: f64,
    /// The extra copies dropped, as stored (a face kept once stands for them): the winding number of
    /// the surface as stored counts them, so deciding overlapping shells face by face puts them back.
    pub(super) copies: Polygons,
    /// The faces dropped in cancelling pairs, as stored: a pair adds nothing to the winding number,
    /// but the wall it leaves out may have joined two bodies into one shell that cuts itself where
    /// they overlap, which the shells' classification finds only with the wall put back.
    pub(super) pairs: Polygons,
}

pub(super) fn tolerant_welding(exact: weld::ExactWeld, precision: weld::Precision) -> Welding {
    let tol = weld::tolerance(&exact.vertices, precision);
    let tolerant = weld::tolerant(&exact.vertices, tol);
    let (all_topology, kept_mask) = weld::remap_faces(&exact.faces, &tolerant.representative);
    let (dropped, duplicates, cancelled, extra, facing, paired) = duplicate_faces(&all_topology);
    let cancelled_volume = cancelled_volume(&exact, &tolerant, &kept_mask, (&dropped, &facing));
    let copies_volume = copies_volume(&exact, &tolerant, &all_topology, &kept_mask, (&dropped, &facing));
    let collapsed_volume = collapsed_volume(&exact, &tolerant, &kept_mask);
    let mut copies = Polygons::new();
    let mut pairs = Polygons::new();
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
        if paired[t] {
            pairs.push(face);
        }
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
        copies_volume,
        collapsed_volume,
        vertices: exact.vertices,
        stored,
        kept,
        topology,
        tolerant,
        copies,
        pairs,
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

/// A bound on what dropping the extra copies of faces (same direction, no reverse in their group)
/// changes, m³. A copy f' welded onto the kept face f (`topology` gives both the same corners, the
/// representatives) has each corner a'ₖ within Δ of f's corner aₖ on the same representative.
/// Moving f' onto f (where dropping it is exact) changes the winding number only where the moving
/// face passes, inside the convex hull of f and f' (each point of the moving face is a convex
/// combination of their corners), and that lies in f' grown by Δ ([`grown`]); summed over every
/// copy dropped: 0 where the copies are stored at the kept face's places.
fn copies_volume(
    exact: &weld::ExactWeld,
    tolerant: &weld::TolerantWeld,
    topology: &Polygons,
    kept: &[bool],
    (dropped, facing): (&[bool], &[bool]),
) -> f64 {
    let v = &exact.vertices;
    let rep = &tolerant.representative;
    // The stored faces in the topology's numbering.
    let stored: Vec<&[u32]> = exact
        .faces
        .iter()
        .zip(kept)
        .filter_map(|(f, k)| k.then_some(f))
        .collect();
    // The corners from the smallest, in the face's direction (a group without a reverse has one).
    let key = |t: usize| {
        let f = topology.face(t);
        let m = (0..f.len()).min_by_key(|&i| f[i]).unwrap_or(0);
        (0..f.len()).map(|i| f[(m + i) % f.len()]).collect::<Vec<u32>>()
    };
    // The face kept of each group with copies dropped beside it (one direction only).
    let mut kept_of: rustc_hash::FxHashMap<Vec<u32>, usize> = rustc_hash::FxHashMap::default();
    if (0..stored.len()).any(|t| dropped[t] && !facing[t]) {
        for t in 0..stored.len() {
            if !dropped[t] && !facing[t] {
                kept_of.entry(key(t)).or_insert(t);
            }
        }
    }
    let mut bound = 0.0;
    for t in (0..stored.len()).filter(|&t| dropped[t] && !facing[t]) {
        let face = stored[t];
        let Some(&k) = kept_of.get(&key(t)) else {
            continue;
        };
        let other = stored[k];
        // Each corner's distance from the kept face's corner on the same representative.
        let delta = face
            .iter()
            .map(|&c| {
                let r = rep[c as usize];
                other
                    .iter()
                    .filter(|&&o| rep[o as usize] == r)
                    .map(|&o| norm(sub(v[c as usize], v[o as usize])))
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        bound += grown(v, face, delta);
    }
    // The sums' own rounding: a few ulps of each term, far below the bound's slack.
    bound * (1.0 + 1e-12)
}

/// The volume of the face's fan triangles each grown by `delta` (Steiner: 2 Δ A + (π/2) Δ² P +
/// (4π/3) Δ³ for a triangle of area A and perimeter P), 0 when `delta` is.
fn grown(v: &[[f64; 3]], face: &[u32], delta: f64) -> f64 {
    if delta <= 0.0 {
        return 0.0;
    }
    let at = |k: usize| v[face[k] as usize];
    let mut sum = 0.0;
    for k in 1..face.len() - 1 {
        let (a, b, c) = (at(0), at(k), at(k + 1));
        let area = norm(crate::geometry::cross(sub(b, a), sub(c, a))) / 2.0;
        let perimeter = norm(sub(b, a)) + norm(sub(c, b)) + norm(sub(a, c));
        sum += delta
            * (2.0 * area
                + std::f64::consts::FRAC_PI_2 * delta * perimeter
                + 4.0 * std::f64::consts::PI / 3.0 * delta * delta);
    }
    sum
}

/// A bound on what the faces that collapse under the tolerant weld (two corners or more on one
/// representative) can change, m³. Moved linearly onto their representatives (each corner by at
/// most Δ, its largest distance from its representative), such a face ends with no area, where it
/// bounds nothing; on its way it passes only through its own corners' convex combinations, within
/// its stored face grown by Δ ([`grown`]). So the winding number with the face and without it
/// differ only there, by the number of times the moving face passes a point, whose integral is at
/// most Δ times its mean area on the way, Δ (A + Δ P / 2 + 2 Δ² / 3) for a triangle of area A and
/// perimeter P; where w without the face is 0 or 1, the solid with it and the integral with it
/// differ by at most twice that, 2 Δ A + Δ² P + (4/3) Δ³, below the grown face's volume. That
/// holds whether the rung integrates these faces or not: the whole parts smaller than the weld's
/// tolerance that collapse so are left out of the topology that decides how shells overlap, and a
/// region one encloses inside another part counted twice in the stored integral (`union_sweep`
/// case 331: 4.1e-13 of the volume off under an estimate of 1.4e-15 before this was in the bound).
fn collapsed_volume(exact: &weld::ExactWeld, tolerant: &weld::TolerantWeld, kept: &[bool]) -> f64 {
    let v = &exact.vertices;
    let rep = &tolerant.representative;
    let bound: f64 = exact
        .faces
        .iter()
        .zip(kept)
        .filter(|(_, k)| !**k)
        .map(|(face, _)| {
            let delta = face
                .iter()
                .map(|&c| norm(sub(v[c as usize], v[rep[c as usize] as usize])))
                .fold(0.0, f64::max);
            grown(v, face, delta)
        })
        .sum();
    bound * (1.0 + 1e-12)
}

/// Faces that repeat another one's vertices in the same cyclic order (a duplicate: kept once) or in
/// the reverse order (a zero-thickness wall: the pair cancels, both dropped). Returns per face whether
/// it is dropped, how many extra copies were dropped, how many faces in cancelling pairs, and per
/// face kept how many extra copies it stands for, per face whether its group has both
/// directions (its drop is a cancelling pair's, or a copy's beside one), and per face whether it
/// was dropped as one of a cancelling pair (not as a copy).
pub(super) type Duplicates = (Vec<bool>, usize, usize, Vec<u32>, Vec<bool>, Vec<bool>);

pub(super) fn duplicate_faces(faces: &Polygons) -> Duplicates {
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
    let mut paired = vec![false; faces.len()];
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
        // Of the majority's faces dropped, the first `copies` are the copies; the rest, and every
        // face of the minority, are pairs.
        let mut as_copies = copies;
        for &(reversed, i) in members {
            if reversed == keep_dir && keep > 0 {
                keep -= 1;
                extra[i as usize] = copies as u32;
            } else {
                dropped[i as usize] = true;
                if reversed == keep_dir && as_copies > 0 {
                    as_copies -= 1;
                } else {
                    paired[i as usize] = true;
                }
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
    (dropped, repeated, cancelled, extra, facing, paired)
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
