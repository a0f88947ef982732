//! The edge structure of a welded mesh: boundary, manifold and non-manifold edges, the proof that a
//! surface is closed and consistently wound, connected components (union-find) and a consistent
//! orientation of each. Moved out of the ladder ([`super`]) as it is.

use crate::mass::Polygons;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Edge structure of a welded mesh.
// `boundary_half_edges`: half-edge is the term of the trade, not a repetition of `Edges`.
#[allow(clippy::struct_field_names)]
#[derive(Debug, Default)]
pub(super) struct Edges {
    pub(super) boundary: usize,
    pub(super) nonmanifold: usize,
    /// Pairs of faces sharing a manifold edge, and whether they traverse it the same way (inconsistent).
    pub(super) pairs: Vec<(u32, u32, bool)>,
    pub(super) inconsistent: usize,
    /// Boundary edges as directed in their face.
    pub(super) boundary_half_edges: Vec<(u32, u32)>,
    /// Per-face component ids and their number, when [`closed_consistent`] proved the surface clean
    /// (then `pairs` is empty: the components are all a clean surface needs of its topology).
    pub(super) components: Option<(Vec<u32>, usize)>,
    /// The face of each boundary edge.
    pub(super) boundary_faces: Vec<u32>,
}

impl Edges {
    /// Per-face component ids over manifold edges and their number.
    pub(super) fn components(&mut self, nfaces: usize) -> (Vec<u32>, usize) {
        self.components
            .take()
            .unwrap_or_else(|| components(nfaces, &self.pairs))
    }

    pub(super) fn closed(&self) -> bool {
        self.boundary == 0 && self.nonmanifold == 0
    }

    pub(super) fn describe(&self) -> String {
        if self.boundary > 0 && self.nonmanifold > 0 {
            format!(
                "open ({} boundary edges) and non-manifold ({} edges shared by 3+ faces)",
                self.boundary, self.nonmanifold
            )
        } else if self.boundary > 0 {
            format!("open ({} boundary edges)", self.boundary)
        } else if self.nonmanifold > 0 {
            format!(
                "non-manifold ({} edges shared by 3+ faces)",
                self.nonmanifold
            )
        } else {
            "closed but not orientable".to_string()
        }
    }
}

/// The edge structure of `faces`. A closed, consistently wound surface (the common case) is proven so
/// by [`closed_consistent`], which yields only the components; anything else gets the full analysis
/// below (a sort of every half-edge by its undirected key), whose boundary edges come in key order.
pub(super) fn edges(faces: &Polygons) -> Edges {
    if let Some(components) = closed_consistent(faces) {
        return Edges {
            components: Some(components),
            ..Edges::default()
        };
    }
    edge_analysis(faces)
}

/// [`edges`] without the proof, for faces already known not to be a clean surface.
pub(super) fn edge_analysis(faces: &Polygons) -> Edges {
    let mut e = Edges::default();
    for_each_edge(faces, |half: &[(u32, u32, bool)], lo: u32| match half {
        [(hi, face, forward)] => {
            e.boundary += 1;
            e.boundary_faces.push(*face);
            e.boundary_half_edges
                .push(if *forward { (lo, *hi) } else { (*hi, lo) });
        }
        [(_, f, a), (_, g, b)] => {
            let same = a == b;
            if same {
                e.inconsistent += 1;
            }
            e.pairs.push((*f, *g, same));
        }
        _ => e.nonmanifold += 1,
    });
    e
}

/// Calls `visit` for each undirected edge of `faces`, in order of its key (smaller vertex, larger
/// vertex), with its half-edges as (larger vertex, face, whether the face runs from the smaller to
/// the larger) and the smaller vertex. Half-edges are bucketed by their smaller vertex (a counting
/// sort) and each bucket, a handful of entries, sorted by the larger one: linear, where a comparison
/// sort of all (key, face) records took 24% of healing the 48 k-face borinot base.
pub(super) fn for_each_edge(faces: &Polygons, mut visit: impl FnMut(&[(u32, u32, bool)], u32)) {
    let n = faces.indices.iter().max().map_or(0, |&m| m as usize + 1);
    let (start, mut rec) = grouped(n, |put| {
        for (fi, face) in faces.iter().enumerate() {
            for k in 0..face.len() {
                let (u, v) = (face[k], face[(k + 1) % face.len()]);
                put(u.min(v) as usize, (u.max(v), fi as u32, u < v));
            }
        }
    });
    for lo in 0..n {
        let bucket = &mut rec[start[lo] as usize..start[lo + 1] as usize];
        // Stable, so the half-edges of an edge keep their face order.
        bucket.sort_by_key(|r| r.0);
        for half in bucket.chunk_by(|a, b| a.0 == b.0) {
            visit(half, lo as u32);
        }
    }
}

/// Items grouped by a key below `groups` (a counting sort), in the order `each` gives them within a
/// group: key k's items are `items[starts[k]..starts[k + 1]]`. `each` hands every (key, item) to its
/// argument; it is called twice, to count and then to place.
pub(super) fn grouped<T: Copy + Default>(
    groups: usize,
    each: impl Fn(&mut dyn FnMut(usize, T)),
) -> (Vec<u32>, Vec<T>) {
    let mut starts = vec![0u32; groups + 1];
    each(&mut |k, _| starts[k + 1] += 1);
    for i in 0..groups {
        starts[i + 1] += starts[i];
    }
    let mut fill = starts[..groups].to_vec();
    let mut items = vec![T::default(); starts[groups] as usize];
    each(&mut |k, t| {
        let s = &mut fill[k];
        items[*s as usize] = t;
        *s += 1;
    });
    (starts, items)
}

/// The face components (as [`components`] numbers them) when every directed edge `u → v` of `faces`
/// has exactly one twin `v → u` (then each undirected edge has one half-edge each way: closed,
/// edge-manifold, consistently wound); `None` otherwise.
///
/// The corners are bucketed by their vertex (a counting sort of the corner numbers, 4 bytes each).
/// A corner of `u` in face `f` stands for the half-edge leaving `u` for the corner after it in `f`
/// and for the one arriving at `u` from the corner before it, so each vertex is decided from its own
/// bucket ([`decide`]): the twin of `u → v` is a corner of `u` whose face arrives from `v`, and that
/// face is the twin's. Faces are joined as twins are found (union-find), so no list of face pairs is
/// built. Buckets of (end, face) pairs searched at the other end, as before, took 8 bytes a
/// half-edge: at 1.3 M faces the corners take 15.6 MB of fresh memory less, the peak 89 → 74 MB on
/// one thread (figures: docs/benchmarks.md, "Peak memory against file size, every format").
pub fn closed_consistent(faces: &Polygons) -> Option<(Vec<u32>, usize)> {
    let n = *faces.indices.iter().max()? as usize + 1;
    closed_consistent_of(faces, n, || identity(faces.len()))
}

/// [`closed_consistent`] of `faces` on `n` vertices (no corner at `n` or beyond; a vertex no face
/// uses has an empty bucket), its union-find forest `parent()` (`faces.len()` singletons, asked for
/// once the corners are bucketed): the caller knows `n` without a pass over the corners, and may
/// have made the forest on another thread.
pub(super) fn closed_consistent_of(
    faces: &Polygons,
    n: usize,
    parent: impl FnOnce() -> Vec<u32>,
) -> Option<(Vec<u32>, usize)> {
    let (ends, corners) = corners_by_vertex(faces, n);
    let mut parent = parent();
    debug_assert_eq!(parent.len(), faces.len());
    let face_of = (!faces.all_triangles()).then(|| corner_faces(faces));
    let paired = decide_faces(faces, face_of.as_deref(), (&ends, |i| corners[i]), 0..n, &mut parent)?;
    (2 * paired == faces.indices.len()).then(|| label(parent))
}

/// Corner numbers bucketed by their vertex (a counting sort), in corner order within a bucket:
/// after the fill, u's corners are `out[ends[u - 1]..ends[u]]` (from 0 for u = 0). Out of line, as
/// the half-edge buckets it replaced were: inlined into [`closed_consistent`], those cost one
/// thread more instructions (figures: docs/benchmarks.md, "One thread against two").
#[inline(never)]
fn corners_by_vertex(faces: &Polygons, n: usize) -> (Vec<u32>, Vec<u32>) {
    let idx = &faces.indices;
    // Entries of vertex u, after the fill: `out[start[u]..start[u + 1]]`, with start[0] = 0.
    let mut start = vec![0u32; n + 1];
    for &u in idx {
        start[u as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    // Filling advances start[u] to where u's entries end, which is where u + 1's begin: after the
    // fill, u's entries are `start[u - 1]..start[u]` (a shift instead of a second cursor array).
    let mut out = vec![0u32; idx.len()];
    for (c, &u) in idx.iter().enumerate() {
        let s = &mut start[u as usize];
        out[*s as usize] = c as u32;
        *s += 1;
    }
    (start, out)
}

/// The face of each corner, for faces that are not all triangles (a triangle's is its corner / 3).
fn corner_faces(faces: &Polygons) -> Vec<u32> {
    let mut face_of = vec![0u32; faces.indices.len()];
    for (f, w) in faces.starts.windows(2).enumerate() {
        face_of[w[0] as usize..w[1] as usize].fill(f as u32);
    }
    face_of
}

/// [`decide`] with the ring of `faces`' corners: a triangle's from its corner number, a polygon's
/// through `face_of` ([`corner_faces`], `None` when every face is a triangle).
#[inline(always)]
fn decide_faces(
    faces: &Polygons,
    face_of: Option<&[u32]>,
    (ends, get): (&[u32], impl Fn(usize) -> u32),
    vertices: std::ops::Range<usize>,
    parent: &mut [u32],
) -> Option<usize> {
    match face_of {
        None => decide(ends, get, vertices, triangle_ring(&faces.indices), parent),
        Some(fo) => decide(ends, get, vertices, polygon_ring(faces, fo), parent),
    }
}

/// A triangle corner's face, the vertex after it and the vertex before it.
#[inline(always)]
fn triangle_ring(idx: &[u32]) -> impl Fn(u32) -> (u32, u32, u32) + Copy + '_ {
    move |c: u32| {
        let (f, k) = (c / 3, (c % 3) as usize);
        let base = 3 * f as usize;
        let t = &idx[base..base + 3];
        // After corner k comes `ring[k]`, before it `ring[k + 1]`.
        let ring = [t[1], t[2], t[0], t[1]];
        (f, ring[k], ring[k + 1])
    }
}

/// A polygon corner's face (`face_of`), the vertex after it and the vertex before it.
#[inline(always)]
fn polygon_ring<'a>(faces: &'a Polygons, face_of: &'a [u32]) -> impl Fn(u32) -> (u32, u32, u32) + Copy + 'a {
    move |c: u32| {
        let f = face_of[c as usize];
        let (lo, hi) = (faces.starts[f as usize], faces.starts[f as usize + 1]);
        let next = if c + 1 == hi { lo } else { c + 1 };
        let prev = if c == lo { hi - 1 } else { c - 1 };
        (f, faces.indices[next as usize], faces.indices[prev as usize])
    }
}

/// Buckets longer than this are sorted before they are matched; shorter ones, nearly all, are
/// matched by a scan (a vertex of degree d costs d²; figures: docs/benchmarks.md, "Figures behind
/// choices in the code").
const SCAN: usize = 32;

/// Decides the vertices `vertices` from their buckets (`ends`: each bucket's end, `get`: the corner
/// number at a place, `ring`: a corner's face and the vertices after and before it): each half-edge
/// leaving a vertex `u` for a larger `v` must be the only one from `u` to `v` and find a half-edge
/// arriving from `v` (its twin), and none may return to `u`. Each face is joined in `parent` with its
/// twin's face; the pairs found are returned, `None` at the first vertex where these fail. A pair
/// stands for two half-edges of its edge and an edge has one pair at most, so when the pairs account
/// for every half-edge, each edge has one half-edge each way: a second `v → u`, or one without its
/// twin, leaves the count short (see [`closed_consistent`]). A bucket longer than [`SCAN`] is sorted
/// and must leave for and arrive from the same distinct vertices.
#[inline(always)]
fn decide(
    ends: &[u32],
    get: impl Fn(usize) -> u32,
    vertices: std::ops::Range<usize>,
    ring: impl Fn(u32) -> (u32, u32, u32),
    parent: &mut [u32],
) -> Option<usize> {
    // The short bucket's faces, ends leaving and ends arriving, one array each.
    let (mut face, mut next, mut prev) = ([0u32; SCAN], [0u32; SCAN], [0u32; SCAN]);
    let (mut leaving, mut arriving) = (Vec::new(), Vec::new());
    let mut paired = 0usize;
    for u in vertices {
        let lo = if u == 0 { 0 } else { ends[u - 1] as usize };
        let hi = ends[u] as usize;
        let u = u as u32;
        let d = hi - lo;
        if d <= SCAN {
            for (k, i) in (lo..hi).enumerate() {
                (face[k], next[k], prev[k]) = ring(get(i));
            }
            for i in 0..d {
                let v = next[i];
                if v <= u {
                    if v == u {
                        return None;
                    }
                    continue;
                }
                if next[..i].contains(&v) {
                    return None;
                }
                // A twin, not the only one: a second `v → u` leaves the count short.
                let k = prev[..d].iter().position(|&p| p == v)?;
                union(parent, face[i], face[k]);
                paired += 1;
            }
        } else {
            // Sorted, the ends leaving and arriving must be the same distinct ones, place for place.
            leaving.clear();
            arriving.clear();
            for i in lo..hi {
                let (f, next, prev) = ring(get(i));
                leaving.push((next, f));
                arriving.push((prev, f));
            }
            leaving.sort_unstable();
            arriving.sort_unstable();
            for (k, (&(v, f), &(p, g))) in leaving.iter().zip(&arriving).enumerate() {
                if v == u || v != p || (k > 0 && leaving[k - 1].0 == v) {
                    return None;
                }
                if u < v {
                    union(parent, f, g);
                    paired += 1;
                }
            }
        }
    }
    Some(paired)
}

/// [`closed_consistent`] for a pool of two threads or more, each stage split in two on `rayon::join`,
/// `n` the vertices (no face's corner at `n` or beyond). The corners are bucketed as
/// [`corners_by_vertex`] buckets them, by two halves of the corners at once: each counts its corners
/// by vertex, the counts give each half its place in every bucket (the first half's entries before
/// the second's, so each bucket holds what one pass puts in it, in the same order), and each half
/// fills its places. The buckets are shared by both halves' writes, hence atomic, written and read
/// with relaxed ordering (plain loads and stores; `rayon::join` orders the stages); they are made on
/// the pool, so both threads fault their pages in. Then the vertices are decided in two halves, each
/// joining faces in a union-find forest of its own, and the second forest's sets are joined into the
/// first afterwards, so the sets and the components numbered from them are the one pass's. The second
/// forest and the counts of each half are what one thread does not pay for.
pub(super) fn closed_consistent_split(faces: &Polygons, n: usize) -> Option<(Vec<u32>, usize)> {
    use rayon::prelude::*;
    let nfaces = faces.len();
    let h = faces.indices.len();
    let half = h / 2;
    // The first half counts in what becomes the first forest once the buckets are filled: a
    // second array of the vertices' size would be fresh pages.
    let ((mut parent, mut second), (mut other, face_of)) = rayon::join(
        || {
            rayon::join(
                || {
                    let mut parent = vec![0u32; nfaces.max(n)];
                    count(&faces.indices[..half], &mut parent[..n]);
                    parent
                },
                || {
                    let mut second = vec![0u32; n];
                    count(&faces.indices[half..], &mut second);
                    second
                },
            )
        },
        || (identity(nfaces), (!faces.all_triangles()).then(|| corner_faces(faces))),
    );
    let first = &mut parent[..n];
    // Each half's first place in every bucket.
    let mut at = 0u32;
    for (a, b) in first.iter_mut().zip(&mut second) {
        let (ca, cb) = (*a, *b);
        *a = at;
        *b = at + ca;
        at += ca + cb;
    }
    let out: Vec<AtomicU32> = (0..h).into_par_iter().map(|_| AtomicU32::new(0)).collect();
    rayon::join(
        || fill(&faces.indices, 0..half, first, &out),
        || fill(&faces.indices, half..h, &mut second, &out),
    );
    parent.truncate(nfaces);
    // Filling advanced each of the second half's places to where its bucket ends: u's entries are
    // `out[second[u - 1]..second[u]]`, as after [`corners_by_vertex`].
    let get = |i: usize| out[i].load(Relaxed);
    let ends = second.as_slice();
    let mid = n / 2;
    let (a, b) = rayon::join(
        || {
            (parent.iter_mut().zip(0..)).for_each(|(p, f)| *p = f);
            decide_faces(faces, face_of.as_deref(), (ends, get), 0..mid, &mut parent)
        },
        || decide_faces(faces, face_of.as_deref(), (ends, get), mid..n, &mut other),
    );
    let paired = a? + b?;
    // A forest's links span its sets: joining each face to its parent in `other` joins them all.
    for f in 0..nfaces as u32 {
        let p = other[f as usize];
        if p != f {
            union(&mut parent, f, p);
        }
    }
    (2 * paired == h).then(|| label(parent))
}

/// A union-find forest of `n` singletons.
pub(super) fn identity(n: usize) -> Vec<u32> {
    (0..n as u32).collect()
}

/// Adds to `count` how many of the corners `corners` each vertex has.
fn count(corners: &[u32], count: &mut [u32]) {
    for &u in corners {
        count[u as usize] += 1;
    }
}

/// Puts the corners `range` of `corners` (the faces' vertex indices) into their vertices' buckets at
/// `place` (each vertex's next free entry, advanced as it fills).
fn fill(corners: &[u32], range: std::ops::Range<usize>, place: &mut [u32], out: &[AtomicU32]) {
    for (c, &u) in range.clone().zip(&corners[range]) {
        let s = &mut place[u as usize];
        out[*s as usize].store(c as u32, Relaxed);
        *s += 1;
    }
}

/// The root of `x` in a union-find forest, halving the path on the way.
#[inline]
pub(super) fn root(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

/// Joins the sets of `a` and `b`; the smaller root becomes the root.
#[inline]
pub(super) fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (root(parent, a), root(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// Per-element set ids numbered by first appearance, and their number.
pub(super) fn label(mut parent: Vec<u32>) -> (Vec<u32>, usize) {
    // One set (the common case) needs no root walks: every id is 0.
    let roots = parent
        .iter()
        .enumerate()
        .filter(|&(i, &p)| p as usize == i)
        .count();
    if roots == 1 {
        parent.fill(0);
        return (parent, 1);
    }
    let mut id = vec![u32::MAX; parent.len()];
    let mut comp = Vec::with_capacity(parent.len());
    let mut n = 0u32;
    for f in 0..parent.len() as u32 {
        let r = root(&mut parent, f) as usize;
        if id[r] == u32::MAX {
            id[r] = n;
            n += 1;
        }
        comp.push(id[r]);
    }
    (comp, n as usize)
}

/// A consistent orientation of each connected component (over manifold edges): per-face flips,
/// component ids and the number of components; `None` when a component is not orientable.
pub(super) struct Orientation {
    pub(super) flip: Vec<bool>,
    pub(super) comp: Vec<u32>,
    pub(super) ncomp: usize,
}

/// The flips are forced within a component once its first face is fixed, and the component ids go
/// by first face, so neither depends on the order of `pairs` or of the search.
pub(super) fn orient(nfaces: usize, pairs: &[(u32, u32, bool)]) -> Option<Orientation> {
    // Neighbours in one flat array (`adj[at[f]..at[f + 1]]`) instead of a Vec per face: the
    // per-face allocations and frees took half of this function on the 48 k-face borinot base.
    let (at, adj) = grouped(nfaces, |put| {
        for &(a, b, same) in pairs {
            put(a as usize, (b, same));
            put(b as usize, (a, same));
        }
    });
    let adj = |f: usize| &adj[at[f] as usize..at[f + 1] as usize];
    let mut flip = vec![false; nfaces];
    let mut comp = vec![u32::MAX; nfaces];
    let mut ncomp = 0u32;
    let mut stack = Vec::new();
    for start in 0..nfaces {
        if comp[start] != u32::MAX {
            continue;
        }
        comp[start] = ncomp;
        stack.push(start);
        while let Some(f) = stack.pop() {
            for &(g, same) in adj(f) {
                // Same traversal direction on the shared edge: exactly one of the two must flip.
                let want = flip[f] ^ same;
                if comp[g as usize] == u32::MAX {
                    comp[g as usize] = ncomp;
                    flip[g as usize] = want;
                    stack.push(g as usize);
                } else if flip[g as usize] != want {
                    return None;
                }
            }
        }
        ncomp += 1;
    }
    Some(Orientation {
        flip,
        comp,
        ncomp: ncomp as usize,
    })
}

/// Connected components of faces over manifold edges (union-find): per-face component ids and the
/// number of components.
pub(super) fn components(nfaces: usize, pairs: &[(u32, u32, bool)]) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..nfaces as u32).collect();
    for &(a, b, _) in pairs {
        union(&mut parent, a, b);
    }
    label(parent)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polygons(faces: &[&[u32]]) -> Polygons {
        let mut p = Polygons::new();
        for f in faces {
            p.push(f);
        }
        p
    }

    /// A tetrahedron wound outward (every edge traversed once each way), and the same offset by 4.
    const TET: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];

    /// A cube of six quads wound outward.
    const CUBE: [[u32; 4]; 6] = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];

    fn tets(n: u32) -> Vec<Vec<u32>> {
        (0..n)
            .flat_map(|t| TET.iter().map(move |f| f.map(|v| v + 4 * t).to_vec()))
            .collect()
    }

    fn faces(v: &[Vec<u32>]) -> Polygons {
        polygons(&v.iter().map(Vec::as_slice).collect::<Vec<_>>())
    }

    /// A double cone of `n` sides: apex 0, ring 1..=n, base centre n + 1 (every edge once each
    /// way). Apex and centre have n edges each: the apex's lead to larger vertices (its own bucket is
    /// scanned for copies), the centre's to smaller ones (its bucket is searched for twins).
    fn cone(n: u32) -> Vec<Vec<u32>> {
        let ring = |i: u32| 1 + i % n;
        (0..n)
            .flat_map(|i| [vec![0, ring(i), ring(i + 1)], vec![n + 1, ring(i + 1), ring(i)]])
            .collect()
    }

    /// Long buckets (a cone's apex and base centre) are searched, not scanned, and give what the
    /// scan gives: the proof and its one component when closed, none when a face is reversed, stored
    /// twice or missing, on one thread and split on a pool; two cones on one apex, two components.
    /// Sides from below [`SCAN`] to far above it, faces in file order and mixed.
    #[test]
    fn long_buckets_give_what_the_scan_gives() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("pool");
        for n in [3, SCAN as u32 - 1, SCAN as u32, SCAN as u32 + 1, 100, 5_000] {
            for mixed in [false, true] {
                let mut v = cone(n);
                let m = v.len();
                if mixed {
                    v = (0..m).map(|i| v[(i * 7919) % m].clone()).collect();
                }
                let nv = n as usize + 2;
                let f = faces(&v);
                let want = Some((vec![0; m], 1));
                assert_eq!(closed_consistent(&f), want, "{n} sides");
                assert_eq!(pool.install(|| closed_consistent_split(&f, nv)), want, "{n} sides");
                let mut reversed = v.clone();
                reversed[m / 2].reverse();
                let mut twice = v.clone();
                twice.push(v[m / 3].clone());
                let mut missing = v.clone();
                missing.remove(m / 4);
                for bad in [reversed, twice, missing] {
                    let f = faces(&bad);
                    assert_eq!(closed_consistent(&f), None, "{n} sides");
                    assert_eq!(pool.install(|| closed_consistent_split(&f, nv)), None, "{n} sides");
                }
                // A second cone on the same apex (its ring after the first's): two components.
                let mut two = v.clone();
                let moved = |x: u32| if x == 0 { 0 } else { x + n + 1 };
                two.extend(cone(n).into_iter().map(|f| f.into_iter().map(moved).collect()));
                let ids: Vec<u32> = (0..2 * m).map(|i| u32::from(i >= m)).collect();
                let f = faces(&two);
                assert_eq!(closed_consistent(&f), Some((ids.clone(), 2)), "{n} sides");
                let nv2 = 2 * n as usize + 3;
                assert_eq!(pool.install(|| closed_consistent_split(&f, nv2)), Some((ids, 2)), "{n} sides");
            }
        }
    }

    /// The proof with long buckets against the full analysis (a sort of every edge's half-edges,
    /// [`edge_analysis`]): cones of 40 and 200 sides changed at random (faces reversed, stored twice,
    /// stored twice reversed, removed, a corner moved to another vertex), on one thread and split.
    #[test]
    fn long_buckets_prove_what_the_full_analysis_finds() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("pool");
        let mut rng = 0x5ca1_ab1e_u64;
        let mut rand = |n: usize| crate::xorshift(&mut rng) as usize % n;
        let mut found = [0usize; 2];
        for trial in 0..600 {
            let n = if trial % 2 == 0 { 40 } else { 200 };
            let mut v = cone(n);
            let m = v.len();
            let step = [1, 7919, 104_729][trial % 3];
            v = (0..m).map(|i| v[(i * step) % m].clone()).collect();
            for _ in 0..rand(4) {
                let f = rand(v.len());
                match rand(5) {
                    0 => v[f].reverse(),
                    1 => v.push(v[f].clone()),
                    2 => v.push(v[f].iter().rev().copied().collect()),
                    3 => drop(v.remove(f)),
                    _ => v[f][rand(3)] = rand(n as usize + 2) as u32,
                }
            }
            let f = faces(&v);
            let full = edge_analysis(&f);
            let want = (full.boundary == 0 && full.nonmanifold == 0 && full.inconsistent == 0)
                .then(|| components(v.len(), &full.pairs));
            found[usize::from(want.is_some())] += 1;
            assert_eq!(closed_consistent(&f), want, "trial {trial}");
            let nv = n as usize + 2;
            assert_eq!(pool.install(|| closed_consistent_split(&f, nv)), want, "trial {trial}");
        }
        // Both answers were met: proofs and failures.
        assert!(found[0] > 100 && found[1] > 100, "{found:?}");
    }

    /// Short buckets and polygons against the full analysis: 2,000 soups of tetrahedra and cubes of
    /// quads (some quads split in two, some cubes sharing a corner with the one before), faces in a
    /// mixed order, changed at random (a face reversed, stored twice, stored twice reversed,
    /// removed, a corner moved to another vertex, a corner repeated), on one thread and split.
    #[test]
    fn the_proof_is_what_the_full_analysis_finds() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("pool");
        let mut rng = 0x00c0_ffee_u64;
        let mut rand = |n: usize| crate::xorshift(&mut rng) as usize % n;
        let mut found = [0usize; 2];
        for trial in 0..2_000 {
            let mut v: Vec<Vec<u32>> = Vec::new();
            let mut next = 0u32;
            for _ in 0..=rand(6) {
                if rand(2) == 0 {
                    v.extend(TET.iter().map(|f| f.map(|x| x + next).to_vec()));
                    next += 4;
                } else {
                    // Every other cube shares its first corner with the last vertex before it.
                    let shared = next > 0 && rand(2) == 0;
                    let at = |x: u32| if x == 0 && shared { next - 1 } else { x + next };
                    for q in CUBE {
                        let q = q.map(at);
                        if rand(3) == 0 {
                            v.extend([vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]);
                        } else {
                            v.push(q.to_vec());
                        }
                    }
                    next += 8;
                }
            }
            let m = v.len();
            let step = [1, 7, 13][trial % 3];
            if m % step != 0 {
                v = (0..m).map(|i| v[(i * step) % m].clone()).collect();
            }
            for _ in 0..rand(3) {
                let f = rand(v.len());
                let k = rand(v[f].len());
                match rand(6) {
                    0 => v[f].reverse(),
                    1 => v.push(v[f].clone()),
                    2 => v.push(v[f].iter().rev().copied().collect()),
                    3 => drop(v.remove(f)),
                    4 => v[f][k] = rand(next as usize) as u32,
                    _ => {
                        let c = v[f][k];
                        v[f].insert(k, c);
                    }
                }
                if v.is_empty() {
                    break;
                }
            }
            if v.is_empty() {
                continue;
            }
            let f = faces(&v);
            let full = edge_analysis(&f);
            let want = (full.boundary == 0 && full.nonmanifold == 0 && full.inconsistent == 0)
                .then(|| components(v.len(), &full.pairs));
            found[usize::from(want.is_some())] += 1;
            assert_eq!(closed_consistent(&f), want, "trial {trial}: {v:?}");
            let nv = next as usize;
            assert_eq!(pool.install(|| closed_consistent_split(&f, nv)), want, "trial {trial}: {v:?}");
        }
        // Both answers were met: proofs and failures.
        assert!(found[0] > 300 && found[1] > 300, "{found:?}");
    }

    #[test]
    fn a_clean_tetrahedron_is_proven_closed_with_one_component() {
        let f = faces(&tets(1));
        assert_eq!(closed_consistent(&f), Some((vec![0; 4], 1)));
        let e = edges(&f);
        assert!(e.closed() && e.inconsistent == 0 && e.pairs.is_empty());
        // The full analysis agrees: six manifold edges, each traversed both ways.
        let full = edge_analysis(&f);
        assert_eq!((full.boundary, full.nonmanifold, full.inconsistent), (0, 0, 0));
        assert_eq!(full.pairs.len(), 6);
    }

    /// The proof split in two halves on a pool gives the one scan's components: 20,000 tetrahedra,
    /// their faces in an order that mixes them (also with vertices beyond the last corner), the
    /// same with one face reversed (no proof), and 10,000 cubes of quads and triangles mixed.
    #[test]
    fn the_split_scan_gives_the_components_of_one_scan() {
        let mut v = tets(20_000);
        let n = v.len();
        v = (0..n).map(|i| v[(i * 7919) % n].clone()).collect();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("pool");
        let f = faces(&v);
        let one = closed_consistent(&f).expect("clean");
        assert_eq!(one.1, 20_000);
        assert_eq!(pool.install(|| closed_consistent_split(&f, 80_000)), Some(one.clone()));
        // Vertices beyond the last corner have empty buckets.
        assert_eq!(pool.install(|| closed_consistent_split(&f, 80_007)), Some(one));
        v[n - 1].reverse();
        assert_eq!(pool.install(|| closed_consistent_split(&faces(&v), 80_000)), None);
        // Quads and triangles: cubes of six quads, every other one with a face split in two.
        let mut cubes: Vec<Vec<u32>> = Vec::new();
        for c in 0..10_000u32 {
            for (k, q) in CUBE.iter().enumerate() {
                let q = q.map(|v| v + 8 * c);
                if k == 1 && c % 2 == 1 {
                    cubes.extend([vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]]);
                } else {
                    cubes.push(q.to_vec());
                }
            }
        }
        let m = cubes.len();
        let cubes: Vec<Vec<u32>> = (0..m).map(|i| cubes[(i * 7919) % m].clone()).collect();
        let f = faces(&cubes);
        let one = closed_consistent(&f).expect("clean");
        assert_eq!(one.1, 10_000);
        assert_eq!(pool.install(|| closed_consistent_split(&f, 80_000)), Some(one));
    }

    #[test]
    fn components_are_numbered_by_first_face() {
        // Two tetrahedra, their faces interleaved: ids follow the first face of each.
        let mut v = tets(2);
        v.swap(0, 4);
        let (comp, n) = closed_consistent(&faces(&v)).expect("clean");
        assert_eq!(n, 2);
        assert_eq!(comp, vec![0, 1, 1, 1, 1, 0, 0, 0]);
    }

    #[test]
    fn a_reversed_face_is_inconsistent_and_orientation_flips_it_alone() {
        let mut v = tets(1);
        v[2].reverse();
        let f = faces(&v);
        assert_eq!(closed_consistent(&f), None);
        let e = edges(&f);
        // Its three edges are traversed the same way by both faces; the surface is still closed.
        assert!(e.closed());
        assert_eq!(e.inconsistent, 3);
        let o = orient(4, &e.pairs).expect("orientable");
        assert_eq!(o.ncomp, 1);
        // The first face is kept; exactly the reversed face is flipped.
        assert_eq!(o.flip, vec![false, false, true, false]);
    }

    #[test]
    fn a_removed_face_leaves_three_boundary_edges_directed_as_their_face() {
        let v = tets(1)[..3].to_vec();
        let e = edges(&faces(&v));
        assert_eq!((e.boundary, e.nonmanifold), (3, 0));
        assert!(!e.closed());
        assert_eq!(e.describe(), "open (3 boundary edges)");
        // The hole is the missing face [0, 3, 2]: its edges, traversed by the other faces the
        // other way, are (3, 0), (2, 3) and (0, 2), in the sort's key order.
        let mut half = e.boundary_half_edges.clone();
        half.sort_unstable();
        assert_eq!(half, vec![(0, 2), (2, 3), (3, 0)]);
        assert_eq!(e.boundary_faces.len(), 3);
    }

    #[test]
    fn three_faces_on_one_edge_are_non_manifold() {
        let f = polygons(&[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]]);
        let e = edges(&f);
        assert_eq!(e.nonmanifold, 1);
        assert!(!e.closed());
        assert!(e.describe().contains("non-manifold (1 edges shared by 3+ faces)"));
    }

    #[test]
    fn a_moebius_band_is_not_orientable() {
        // Four quads in a ring, the last joined to the first with a half twist: going round once
        // flips the orientation, so no consistent one exists.
        let band: [&[u32]; 4] = [&[0, 1, 3, 2], &[2, 3, 5, 4], &[4, 5, 7, 6], &[6, 7, 0, 1]];
        let e = edges(&polygons(&band));
        assert!(orient(4, &e.pairs).is_none());
    }

    #[test]
    fn union_find_joins_sets_and_labels_them_by_first_element() {
        let mut parent: Vec<u32> = (0..6).collect();
        union(&mut parent, 4, 5);
        union(&mut parent, 1, 4);
        union(&mut parent, 2, 3);
        assert_eq!(root(&mut parent, 5), 1);
        assert_eq!(root(&mut parent, 3), 2);
        assert_eq!(label(parent), (vec![0, 1, 2, 2, 1, 1], 3));
        // One set: every id 0, without root walks.
        assert_eq!(label(vec![0, 0, 1, 2]), (vec![0; 4], 1));
        assert_eq!(components(3, &[(0, 2, false)]), (vec![0, 1, 0], 2));
    }
}
