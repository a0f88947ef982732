//! Shells closed up to cracks: corners that one face stores a float's rounding apart from its
//! neighbour's. Their edges do not balance as stored, so rays could slip through a crack and the
//! winding number is not an integer there; welded within the reader's tolerance (the ladder's second
//! weld) they are closed cycles, which the face-by-face decision counts exactly. The welded
//! triangles differ from the stored ones by at most the volume they sweep moving to the welded
//! corners, which enters the bound.
//!
//! Nesting pair by pair counts such a shell's winding number without its solid angles by closing
//! its cracks with caps of its own corners ([`caps`]).

use rustc_hash::FxHashMap;

use super::{join, root, EdgeUse};
use crate::geometry::{dot, sub};
use crate::mesh::weld;

/// Each vertex's representative under the tolerant weld the ladder uses: the tolerance from the
/// file's `precision` when known, else as far as the coordinates tell it.
pub(super) fn representatives(vertices: &[[f64; 3]], precision: Option<weld::Precision>) -> Vec<u32> {
    let precision = precision.unwrap_or_else(|| weld::Precision::of(vertices));
    let tol = weld::tolerance(vertices, precision);
    weld::tolerant(vertices, tol).representative
}

/// The triangles with welded corners (those that collapse left out), and a bound on the volume
/// between them and the stored ones, m³.
pub(super) fn welded_triangles(
    vertices: &[[f64; 3]],
    tris: &[[u32; 3]],
    rep: &[u32],
) -> (Vec<[u32; 3]>, f64) {
    let mut out = Vec::with_capacity(tris.len());
    let mut swept = 0.0;
    for t in tris {
        let w = t.map(|v| rep[v as usize]);
        if w != *t {
            swept += sweep(t.map(|v| vertices[v as usize]), w.map(|v| vertices[v as usize]));
        }
        if w[0] != w[1] && w[1] != w[2] && w[2] != w[0] {
            out.push(w);
        }
    }
    (out, swept)
}

/// Per shell of `shells` that has faces in `shell_of` (each face's shell, `u32::MAX` for none):
/// triangles that close its cracks, so that the shell's triangles and these are a closed cycle. The shell's
/// boundary (its faces' edges, each direction counted against the other, over the edges that do not
/// join exactly two of its faces in opposite directions) falls into loops; each connected loop is
/// capped by the cone from one of its corners (a triangle per edge, reversed, those through the
/// apex left out). A cap lies within the convex hull of its loop, so within the shell's box; a crack
/// of corners a rounding apart is capped by slivers.
pub(super) fn caps(uses: &[EdgeUse], shell_of: &[u32], shells: usize) -> Vec<Vec<[u32; 3]>> {
    // Per shell: its boundary's directed edges.
    let mut edges: Vec<Vec<(u32, u32)>> = vec![Vec::new(); shells];
    let mut net: Vec<(u32, i64)> = Vec::new();
    for users in uses.chunk_by(|x, y| x.key == y.key) {
        if users.len() == 2 && users[0].forward != users[1].forward {
            continue;
        }
        net.clear();
        for e in users {
            let s = shell_of[e.face as usize];
            if s == u32::MAX {
                continue;
            }
            let d = if e.forward { 1 } else { -1 };
            match net.iter_mut().find(|x| x.0 == s) {
                Some(x) => x.1 += d,
                None => net.push((s, d)),
            }
        }
        let (lo, hi) = ((users[0].key >> 32) as u32, users[0].key as u32);
        if lo == hi {
            continue;
        }
        for &(s, d) in &net {
            let edge = if d > 0 { (lo, hi) } else { (hi, lo) };
            edges[s as usize].extend(std::iter::repeat_n(edge, d.unsigned_abs() as usize));
        }
    }
    edges
        .iter()
        .map(|edges| {
            // The loops' corners, numbered in order of first use, joined by their edges.
            let mut local: FxHashMap<u32, u32> = FxHashMap::default();
            let mut corner = Vec::new();
            let mut number = |v: u32| {
                *local.entry(v).or_insert_with(|| {
                    corner.push(v);
                    corner.len() as u32 - 1
                })
            };
            let ends: Vec<(u32, u32)> = edges.iter().map(|&(u, v)| (number(u), number(v))).collect();
            let mut parent: Vec<u32> = (0..corner.len() as u32).collect();
            for &(u, v) in &ends {
                join(&mut parent, u, v);
            }
            let mut cap = Vec::new();
            for (&(u, v), &(lu, _)) in edges.iter().zip(&ends) {
                let apex = corner[root(&mut parent, lu) as usize];
                if apex != u && apex != v {
                    cap.push([apex, v, u]);
                }
            }
            cap
        })
        .collect()
}

/// The volume a triangle sweeps while its corners move in straight lines from `a` to `b`: each
/// point moves at most δ (the largest corner move), through triangles whose edges grow by at most
/// 2δ, so at most δ · ½ (|e₁| + 2δ)(|e₂| + 2δ).
fn sweep(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> f64 {
    let len = |x: [f64; 3]| dot(x, x).sqrt();
    let delta = (0..3).map(|k| len(sub(b[k], a[k]))).fold(0.0, f64::max);
    let (e1, e2) = (len(sub(a[1], a[0])), len(sub(a[2], a[0])));
    // One part in 1e6 over, for the rounding of these products.
    delta * 0.5 * (e1 + 2.0 * delta) * (e2 + 2.0 * delta) * (1.0 + 1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_moved_sweeps_at_most_the_bound() {
        // Moving one corner of a right triangle of legs 1 by h along the normal sweeps a
        // tetrahedron of volume h/6.
        let a = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut b = a;
        b[0][2] = 1e-3;
        let s = sweep(a, b);
        assert!(s >= 1e-3 / 6.0);
        assert!(s <= 1e-3);
    }

    #[test]
    fn collapsed_triangles_are_left_out() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1e-12, 0.0]];
        let rep = [0, 1, 2, 1];
        let (t, swept) = welded_triangles(&v, &[[0, 1, 2], [1, 3, 2], [3, 2, 0]], &rep);
        assert_eq!(t, vec![[0, 1, 2], [1, 2, 0]]);
        assert!(swept > 0.0 && swept < 1e-11);
    }
}
