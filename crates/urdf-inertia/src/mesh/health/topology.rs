//! The edge structure of a welded mesh: boundary, manifold and non-manifold edges, the proof that a
//! surface is closed and consistently wound, connected components (union-find) and a consistent
//! orientation of each. Moved out of the ladder ([`super`]) as it is.

use crate::mass::Polygons;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

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
/// Half-edges are bucketed by their start vertex (a counting sort), each entry holding its end and its
/// face, so a twin is found by scanning the handful of entries of its start: a few linear passes and
/// no sort. Faces are joined as twins are found (union-find), so no list of face pairs is built.
/// Measured on a 1.3 M-face sphere (callgrind): 503 → 329 instructions per face for the proof and the
/// components together.
pub fn closed_consistent(faces: &Polygons) -> Option<(Vec<u32>, usize)> {
    let n = *faces.indices.iter().max()? as usize + 1;
    let h = faces.indices.len();
    let (start, mut out) = half_edges(faces, n);
    let mut parent: Vec<u32> = (0..faces.len() as u32).collect();
    let paired = if sort_long(0, &start[..n], &mut out, |&(v, f)| (v, f)) {
        pair_twins::<true>(&start[..n], &out, &mut parent)
    } else {
        pair_twins::<false>(&start[..n], &out, &mut parent)
    }?;
    (2 * paired == h).then(|| label(parent))
}

/// The twin scan of [`closed_consistent`] (`ends`: each vertex's bucket's end in `out`): the pairs
/// found, faces joined in `parent` as they are; `None` at the first half-edge without exactly one
/// twin. `LONG` when some bucket is longer than [`SCAN`] (sorted): without, the scan is the one
/// before long buckets, instruction for instruction.
#[inline(always)]
fn pair_twins<const LONG: bool>(ends: &[u32], out: &[(u32, u32)], parent: &mut [u32]) -> Option<usize> {
    let bucket = |u: usize| {
        let lo = if u == 0 { 0 } else { ends[u - 1] as usize };
        &out[lo..ends[u] as usize]
    };
    // Each half-edge u → v with u < v must be alone in u's list and find exactly one v → u; when
    // those pairs account for every half-edge, no half-edge v → u is left without its twin.
    let mut paired = 0usize;
    for u in 0..ends.len() {
        let mine = bucket(u);
        for (i, &(v, f)) in mine.iter().enumerate() {
            if v as usize <= u {
                if v as usize == u {
                    return None;
                }
                continue;
            }
            if seen_before::<LONG, _>(mine, i, v, |e| e.0) {
                return None;
            }
            let &(_, g) = only_twin::<LONG, _>(bucket(v as usize), u as u32, |e| e.0)?;
            union(parent, f, g);
            paired += 1;
        }
    }
    Some(paired)
}

/// Half-edges bucketed by their start vertex (a counting sort), each entry holding its end and its
/// face: after the fill, u's entries are `out[start[u - 1]..start[u]]` (from 0 for u = 0). Out of
/// line: inlined into [`closed_consistent`] the two cost one thread more instructions (figures:
/// docs/benchmarks.md, "One thread against two").
#[inline(never)]
fn half_edges(faces: &Polygons, n: usize) -> (Vec<u32>, Vec<(u32, u32)>) {
    let idx = &faces.indices;
    let h = idx.len();
    // Entries starting at vertex u, after the fill: `out[start[u]..start[u + 1]]`, with start[0] = 0.
    let mut start = vec![0u32; n + 1];
    for &u in idx {
        start[u as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    // Filling advances start[u] to where u's entries end, which is where u + 1's begin: after the
    // fill, u's entries are `start[u - 1]..start[u]` (a shift instead of a second cursor array).
    let mut out = vec![(0u32, 0u32); h];
    let mut put = |u: u32, v: u32, f: u32| {
        let s = &mut start[u as usize];
        out[*s as usize] = (v, f);
        *s += 1;
    };
    if faces.all_triangles() {
        for (f, t) in idx.chunks_exact(3).enumerate() {
            let f = f as u32;
            put(t[0], t[1], f);
            put(t[1], t[2], f);
            put(t[2], t[0], f);
        }
    } else {
        for (f, face) in faces.iter().enumerate() {
            for k in 0..face.len() {
                put(face[k], face[(k + 1) % face.len()], f as u32);
            }
        }
    }
    (start, out)
}

/// [`closed_consistent`] for a pool of two threads or more, each stage split in two on `rayon::join`,
/// `n` the vertices (no face's corner at `n` or beyond). The half-edges are bucketed as
/// [`half_edges`] buckets them, by two halves of the faces at once: each counts its half-edges by
/// start vertex, the counts give each half its place in every bucket (the first half's entries
/// before the second's, so each bucket holds what one pass puts in it, in the same order), and each
/// half fills its places. The buckets are shared by both halves' writes, hence atomic, written and
/// read with relaxed ordering (plain loads and stores; `rayon::join` orders the stages); they are
/// made on the pool, so both threads fault their pages in. Then the twin scan runs in two halves of
/// the vertices, each joining faces in a union-find forest of its own, and the second forest's sets
/// are joined into the first afterwards, so the sets and the components numbered from them are the
/// one scan's. The second forest and the counts of each half are what one thread does not pay for.
/// (The scan is [`closed_consistent`]'s, written twice: as one function called by both it cost
/// one thread instructions; figures: docs/benchmarks.md, "One thread against two".)
pub(super) fn closed_consistent_split(faces: &Polygons, n: usize) -> Option<(Vec<u32>, usize)> {
    use rayon::prelude::*;
    let nfaces = faces.len();
    let h = faces.indices.len();
    let half = nfaces / 2;
    // The first half counts in what becomes the first forest once the buckets are filled: a
    // second array of the vertices' size would be fresh pages.
    let ((mut parent, mut second), mut other) = rayon::join(
        || {
            rayon::join(
                || {
                    let mut parent = vec![0u32; nfaces.max(n)];
                    count(faces, 0..half, &mut parent[..n]);
                    parent
                },
                || {
                    let mut second = vec![0u32; n];
                    count(faces, half..nfaces, &mut second);
                    second
                },
            )
        },
        || identity(nfaces),
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
    let mut out: Vec<AtomicU64> = (0..h).into_par_iter().map(|_| AtomicU64::new(0)).collect();
    rayon::join(
        || fill(faces, 0..half, first, &out),
        || fill(faces, half..nfaces, &mut second, &out),
    );
    parent.truncate(nfaces);
    let key = |e: &AtomicU64| {
        let e = e.load(Relaxed);
        (e as u32, (e >> 32) as u32)
    };
    let mid = n / 2;
    let split = if mid == 0 { 0 } else { second[mid - 1] as usize };
    let (low, high) = out.split_at_mut(split);
    let long = rayon::join(
        || sort_long(0, &second[..mid], low, key),
        || sort_long(split, &second[mid..n], high, key),
    );
    // Filling advanced each of the second half's places to where its bucket ends: u's entries are
    // `out[second[u - 1]..second[u]]`, as after [`half_edges`].
    let buckets = (second.as_slice(), out.as_slice());
    let scan = if long.0 || long.1 { twins::<true> } else { twins::<false> };
    let (a, b) = rayon::join(
        || {
            (parent.iter_mut().zip(0..)).for_each(|(p, f)| *p = f);
            scan(buckets, 0..mid, &mut parent)
        },
        || scan(buckets, mid..n, &mut other),
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

/// Buckets longer than this are sorted by end vertex before the twin scan, which then searches
/// them instead of scanning them: scanned, a vertex of degree d costs d² (figures:
/// docs/benchmarks.md, "Figures behind choices in the code"). Shorter buckets, nearly all, are
/// scanned as before.
const SCAN: usize = 32;

/// Sorts by `key` (end vertex, then face) each bucket of more than [`SCAN`] entries, and says
/// whether there was one: `ends` are the buckets' ends as the fill left them, counted from entry
/// `base` of the whole list, whose part from there on is `out`.
fn sort_long<T>(base: usize, ends: &[u32], out: &mut [T], key: impl Fn(&T) -> (u32, u32) + Copy) -> bool {
    let (mut lo, mut any) = (0, false);
    for &end in ends {
        let hi = end as usize - base;
        if hi - lo > SCAN {
            out[lo..hi].sort_unstable_by_key(key);
            any = true;
        }
        lo = hi;
    }
    any
}

/// Whether an entry before the `i`th of `mine` ends at `v`: in a sorted (long) bucket, the one
/// right before it.
#[inline(always)]
fn seen_before<const LONG: bool, T>(mine: &[T], i: usize, v: u32, end: impl Fn(&T) -> u32) -> bool {
    if LONG && mine.len() > SCAN {
        i > 0 && end(&mine[i - 1]) == v
    } else {
        mine[..i].iter().any(|e| end(e) == v)
    }
}

/// The entry of `bucket` ending at `u` when exactly one does: in a sorted (long) bucket, found by
/// a binary search and the entry after it.
#[inline(always)]
fn only_twin<const LONG: bool, T>(bucket: &[T], u: u32, end: impl Fn(&T) -> u32) -> Option<&T> {
    let near = if LONG && bucket.len() > SCAN {
        let i = bucket.partition_point(|e| end(e) < u);
        &bucket[i..bucket.len().min(i + 2)]
    } else {
        bucket
    };
    let mut twins = near.iter().filter(|e| end(e) == u);
    let t = twins.next()?;
    twins.next().is_none().then_some(t)
}

/// A union-find forest of `n` singletons.
fn identity(n: usize) -> Vec<u32> {
    (0..n as u32).collect()
}

/// Adds to `count` how many corners of the faces `range` each vertex has: the half-edges leaving it.
fn count(faces: &Polygons, range: std::ops::Range<usize>, count: &mut [u32]) {
    let (lo, hi) = (faces.starts[range.start], faces.starts[range.end]);
    for &u in &faces.indices[lo as usize..hi as usize] {
        count[u as usize] += 1;
    }
}

/// Puts the half-edges of the faces `range` into their buckets at `place` (each vertex's next free
/// entry, advanced as it fills), each entry its end and its face packed as `end | face << 32`.
fn fill(faces: &Polygons, range: std::ops::Range<usize>, place: &mut [u32], out: &[AtomicU64]) {
    let mut put = |u: u32, v: u32, f: u32| {
        let s = &mut place[u as usize];
        out[*s as usize].store(u64::from(v) | u64::from(f) << 32, Relaxed);
        *s += 1;
    };
    let starts = &faces.starts[range.start..=range.end];
    let (lo, hi) = (starts[0] as usize, starts[starts.len() - 1] as usize);
    if 3 * range.len() == hi - lo && starts.windows(2).all(|w| w[1] - w[0] == 3) {
        for (f, t) in faces.indices[lo..hi].chunks_exact(3).enumerate() {
            let f = (range.start + f) as u32;
            put(t[0], t[1], f);
            put(t[1], t[2], f);
            put(t[2], t[0], f);
        }
    } else {
        for f in range {
            let face = faces.face(f);
            for k in 0..face.len() {
                put(face[k], face[(k + 1) % face.len()], f as u32);
            }
        }
    }
}

/// The twin scan of [`closed_consistent_split`] over the half-edges leaving `vertices` (the buckets
/// as its fill left them: the end of each vertex's, and the entries): the number of pairs found,
/// faces joined in `parent` as they are; `None` at the first half-edge without exactly one twin.
fn twins<const LONG: bool>(
    (end, out): (&[u32], &[AtomicU64]),
    vertices: std::ops::Range<usize>,
    parent: &mut [u32],
) -> Option<usize> {
    let bucket = |u: usize| {
        let lo = if u == 0 { 0 } else { end[u - 1] as usize };
        &out[lo..end[u] as usize]
    };
    let target = |e: &AtomicU64| e.load(Relaxed) as u32;
    // Each half-edge u → v with u < v must be alone in u's list and find exactly one v → u; when
    // those pairs account for every half-edge, no half-edge v → u is left without its twin.
    let mut paired = 0usize;
    for u in vertices {
        let mine = bucket(u);
        for (i, e) in mine.iter().enumerate() {
            let e = e.load(Relaxed);
            let (v, f) = (e as u32, (e >> 32) as u32);
            if v as usize <= u {
                if v as usize == u {
                    return None;
                }
                continue;
            }
            if seen_before::<LONG, _>(mine, i, v, target) {
                return None;
            }
            let g = (only_twin::<LONG, _>(bucket(v as usize), u as u32, target)?.load(Relaxed) >> 32) as u32;
            union(parent, f, g);
            paired += 1;
        }
    }
    Some(paired)
}

/// The root of `x` in a union-find forest, halving the path on the way.
pub(super) fn root(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

/// Joins the sets of `a` and `b`; the smaller root becomes the root.
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

    /// On a sorted bucket longer than [`SCAN`], `seen_before` and `only_twin` answer what a scan of
    /// the whole bucket answers: random buckets of ends with repeats, every entry and end asked.
    #[test]
    fn searched_buckets_answer_as_scanned_ones() {
        let mut rng = 0x0b0c_4e75_u64;
        let mut rand = |n: usize| crate::xorshift(&mut rng) as usize % n;
        for _ in 0..300 {
            let len = SCAN + 1 + rand(60);
            let mut bucket: Vec<(u32, u32)> = (0..len).map(|f| (rand(len) as u32, f as u32)).collect();
            bucket.sort_unstable();
            for (i, &(v, _)) in bucket.iter().enumerate() {
                assert_eq!(seen_before::<true, _>(&bucket, i, v, |e| e.0), bucket[..i].iter().any(|e| e.0 == v));
            }
            for u in 0..=len as u32 {
                let scanned: Vec<_> = bucket.iter().filter(|e| e.0 == u).collect();
                let want = (scanned.len() == 1).then(|| scanned[0]);
                assert_eq!(only_twin::<true, _>(&bucket, u, |e| e.0), want, "{bucket:?} {u}");
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
        let cube: [[u32; 4]; 6] = [
            [0, 3, 2, 1],
            [4, 5, 6, 7],
            [0, 1, 5, 4],
            [1, 2, 6, 5],
            [2, 3, 7, 6],
            [3, 0, 4, 7],
        ];
        let mut cubes: Vec<Vec<u32>> = Vec::new();
        for c in 0..10_000u32 {
            for (k, q) in cube.iter().enumerate() {
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
