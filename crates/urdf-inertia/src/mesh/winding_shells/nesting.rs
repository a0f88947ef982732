//! Which shells of a surface touch each other, and each shell's `w_out` (the others' winding
//! numbers on it), for all pairs of overlapping boxes at once.
//!
//! Decided pair by pair, shells nested in each other (concentric spheres: every pair's boxes
//! overlap) cost shells² × faces per shell. Here one tree of boxes over every closed shell's
//! triangles ([`Bvh`]) gives the pairs of triangles of two shells whose boxes meet, which the
//! exact test of each pair of shells looked at (its triangles whose boxes meet the other's are
//! all there is to test: a triangle of one whose box meets one of the other's lies in the
//! shells' common box), so a pair of shells with no such pair is known not to touch without
//! work of its own. Of two sealed shells that do not touch, the winding number of one on the
//! other is an integer, constant on the other; one exact ray (`orient3d` crossings, as
//! [`super::grid`] counts them) from a corner of a shell counts the sum over all the shells
//! around it at once, in time of the triangles along the ray. A neighbour closed only up to
//! cracks could let a ray slip through one: its count is confirmed by a ray along another axis.
//! Where no ray counts, the pairs' solid angles decide with their
//! [`NOT_INTEGER`](super::NOT_INTEGER) guard, as pair by pair.

use std::ops::ControlFlow;

use rustc_hash::FxHashSet;

use super::bvh::Bvh;
use super::grid::{crossing, Corners, Crossing, Plane};
use super::{box_overlap, corners_touch, integer, winding, Shell, MAX_PAIRS};
use crate::geometry::Aabb;

/// Tests of pairs of triangles (whose boxes meet) beyond which no pair is decided: all are
/// bounded (a surface of many shells whose triangles pile up in one place). About 4 s: 400
/// nested spheres of 224 faces (radii 1 to 40.9, 0.1 apart) ask 21.8 million.
const MAX_TRIANGLE_TESTS: usize = 30_000_000;

/// Per shell: the others' winding numbers on it, summed over the pairs with overlapping boxes,
/// and whether every such pair is decided (both closed, not touching, winding numbers whole).
/// `None` when more than [`MAX_PAIRS`] pairs need work of their own (they touch, or a shell is
/// open) or the tests of triangles exceed [`MAX_TRIANGLE_TESTS`].
pub(super) fn nestings(
    vertices: &[[f64; 3]],
    shells: &[Shell],
    tris: &[Vec<[u32; 3]>],
    pairs: &[(usize, usize)],
) -> Option<(Vec<i64>, Vec<bool>)> {
    let n = shells.len();
    let mut decided = vec![true; n];
    let mut paired = vec![false; n];
    // A shell closed up to cracks around it (see [`rays`]).
    let mut cracked = vec![false; n];
    for &(a, b) in pairs {
        paired[a] = true;
        paired[b] = true;
        if !shells[a].closed || !shells[b].closed {
            decided[a] = false;
            decided[b] = false;
        }
        cracked[a] |= !shells[b].sealed;
        cracked[b] |= !shells[a].sealed;
    }
    let tree = Tree::new(vertices, shells, tris, &paired);
    let touching = touching(&tree, shells, &mut decided)?;
    // A pair is undecided, whatever else, when a shell is open or they touch: those need work of
    // their own (bounded, or decided face by face).
    let undecided = |a: usize, b: usize| {
        !shells[a].closed || !shells[b].closed || touching.contains(&pair_key(a as u32, b as u32))
    };
    if pairs.iter().filter(|&&(a, b)| undecided(a, b)).count() > MAX_PAIRS {
        return None;
    }
    // Each closed shell: rays from one of its corners count the closed shells around it; when no
    // ray does, the pairs' solid angles decide, rounded within `NOT_INTEGER` as they were pair
    // by pair.
    let mut w_out = vec![0i64; n];
    let mut by_pairs = vec![false; n];
    for a in 0..n {
        if !(decided[a] && paired[a]) {
            continue;
        }
        match rays(&tree, shells, (a, cracked[a]), &tris[a], vertices) {
            Some(w) => w_out[a] += w,
            None => by_pairs[a] = true,
        }
    }
    for &(a, b) in pairs {
        if undecided(a, b) {
            continue;
        }
        for (x, y) in [(a, b), (b, a)] {
            if by_pairs[x] {
                let p = vertices[tris[x][0][0] as usize];
                if let Some(w) = integer(winding(vertices, &tris[y], p)) {
                    w_out[x] += w;
                } else {
                    decided[x] = false;
                    decided[y] = false;
                }
            }
        }
    }
    Some((w_out, decided))
}

/// An unordered pair of shells as one word.
fn pair_key(a: u32, b: u32) -> u64 {
    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
}

/// The triangles of the closed shells that have pairs, in one tree, grouped by shell: their
/// corners' numbers, their corners and their shells.
struct Tree {
    bvh: Bvh,
    corners: Vec<Corners>,
    /// Their planes, computed once: a triangle meets some tens of others' boxes in nested shells.
    planes: Vec<Plane>,
    shell_of: Vec<u32>,
}

impl Tree {
    fn new(vertices: &[[f64; 3]], shells: &[Shell], tris: &[Vec<[u32; 3]>], paired: &[bool]) -> Tree {
        let (mut shell_of, mut corners) = (Vec::new(), Vec::<Corners>::new());
        for (i, ts) in tris.iter().enumerate() {
            if shells[i].closed && paired[i] {
                for t in ts {
                    shell_of.push(i as u32);
                    corners.push(t.map(|v| vertices[v as usize]));
                }
            }
        }
        let boxes: Vec<Aabb> = corners.iter().map(|c| Aabb::of(*c)).collect();
        Tree {
            bvh: Bvh::new(boxes, &shell_of),
            planes: corners.iter().map(Plane::new).collect(),
            corners,
            shell_of,
        }
    }
}

/// The pairs of closed shells with overlapping boxes that touch or cut each other (exact
/// `triangles_touch`, as [`corners_touch`] with the planes computed once, of each pair of their
/// triangles whose boxes meet), their shells marked undecided. A pair of shells both undecided
/// already is not asked. `None` past [`MAX_TRIANGLE_TESTS`].
fn touching(tree: &Tree, shells: &[Shell], decided: &mut [bool]) -> Option<FxHashSet<u64>> {
    let mut touching: FxHashSet<u64> = FxHashSet::default();
    let mut tests = 0usize;
    // The last pair of shells asked, and whether it is to be tested: the tree's pairs come in
    // runs of the same two shells.
    let mut last = (u64::MAX, false);
    let swept = tree.bvh.pairs(|i, j| {
        let (a, b) = (tree.shell_of[i as usize], tree.shell_of[j as usize]);
        let key = pair_key(a, b);
        if key != last.0 {
            let (sa, sb) = (&shells[a as usize], &shells[b as usize]);
            // Only pairs of shells whose boxes overlap are asked (as `overlapping_pairs` finds them).
            last = (key, (decided[a as usize] || decided[b as usize]) && box_overlap(sa, sb) > 0.0);
        }
        if !last.1 || touching.contains(&key) {
            return ControlFlow::Continue(());
        }
        tests += 1;
        if tests > MAX_TRIANGLE_TESTS {
            return ControlFlow::Break(());
        }
        let (i, j) = (i as usize, j as usize);
        let sides = (|q| tree.planes[i].side(q), |q| tree.planes[j].side(q));
        if corners_touch(&tree.corners[i], &tree.corners[j], sides) {
            touching.insert(key);
            decided[a as usize] = false;
            decided[b as usize] = false;
            last.1 = false;
        }
        ControlFlow::Continue(())
    });
    swept.is_continue().then_some(touching)
}

/// The sum of the winding numbers of the closed shells whose boxes overlap `a`'s (other than `a`)
/// at a corner of `a`, counted exactly along axis-parallel rays: the first that counts exactly,
/// or when `a` has neighbours closed up to cracks (`cracked`), the first two along different
/// axes that count the same of each such neighbour. `None` when no ray of six directions from
/// the corners of `a`'s first three triangles does.
fn rays(tree: &Tree, shells: &[Shell], (a, cracked): (usize, bool), own: &[[u32; 3]], vertices: &[[f64; 3]]) -> Option<i64> {
    let mut starts: Vec<u32> = own.iter().take(3).flatten().copied().collect();
    // The first corner first (where the pairs' solid angles were taken), each once.
    let mut seen = FxHashSet::default();
    starts.retain(|v| seen.insert(*v));
    // The first exact ray's axis and counts.
    let mut first: Option<(usize, RayCount)> = None;
    for v in starts {
        for (axis, sign) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0)] {
            if first.as_ref().is_some_and(|f| f.0 == axis) {
                continue;
            }
            let Some((w, each)) = ray(tree, shells, a, vertices[v as usize], (axis, sign)) else {
                continue;
            };
            if !cracked {
                return Some(w);
            }
            match &first {
                None => first = Some((axis, (w, each))),
                Some((_, (w0, each0))) => {
                    return (*w0 == w && *each0 == each).then(|| w + each.iter().map(|e| e.1).sum::<i64>());
                }
            }
        }
    }
    None
}

/// A ray's count of the sealed shells, and of each shell closed up to cracks it crosses.
type RayCount = (i64, Vec<(u32, i64)>);

/// What the ray from `p` along `sign`·e_`axis` counts of the closed shells whose boxes overlap
/// `a`'s (other than `a`): the sealed ones' sum, and the others' non-zero counts by shell; `None`
/// when it grazes an edge, a corner or a plane of one of them.
fn ray(tree: &Tree, shells: &[Shell], a: usize, p: [f64; 3], (axis, sign): (usize, f64)) -> Option<RayCount> {
    let (bvh, shell_of) = (&tree.bvh, &tree.shell_of);
    let bounds = bvh.bounds();
    // An end beyond every triangle's box.
    let mut end = p;
    let reach = bounds.hi[axis].abs().max(bounds.lo[axis].abs()).max(p[axis].abs()) + 1.0;
    end[axis] = sign * 2.0 * reach;
    let (mut w, mut each) = (0i64, Vec::new());
    let mut exact = true;
    bvh.ray(p, axis, sign, |i| {
        let b = shell_of[i as usize] as usize;
        if !exact || b == a || box_overlap(&shells[a], &shells[b]) <= 0.0 {
            return;
        }
        let t = &tree.corners[i as usize];
        match crossing(p, end, axis, t, &tree.planes[i as usize]) {
            Crossing::Miss => {}
            Crossing::Through(d) if shells[b].sealed => w += d,
            Crossing::Through(d) => each.push((b as u32, d)),
            Crossing::Degenerate => exact = false,
        }
    });
    if !exact {
        return None;
    }
    each.sort_unstable_by_key(|e| e.0);
    let mut by_shell: Vec<(u32, i64)> = Vec::new();
    for (b, d) in each {
        match by_shell.last_mut() {
            Some(last) if last.0 == b => last.1 += d,
            _ => by_shell.push((b, d)),
        }
    }
    by_shell.retain(|e| e.1 != 0);
    Some((w, by_shell))
}
