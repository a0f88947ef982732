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

/// Distinct vertices keyed by their bit patterns: an open-addressing table of vertex indices (with a
/// 32-bit tag of the hash beside each) over the vertex list itself, so a vertex is stored once and a
/// lookup touches one 8-byte slot and, on a tag match, the vertex. Indices are given in order of first
/// appearance, which makes the result independent of the table's size and growth.
///
/// It replaces a `FxHashMap<[u64; 3], u32>` (32-byte buckets and a second copy of every vertex): on a
/// 1.3 M-face binary STL that map alone took 128 MiB, and its misses dominated the weld.
#[derive(Debug, Clone, Default)]
pub struct VertexTable {
    vertices: Vec<[f64; 3]>,
    /// 0: empty; else `tag << 32 | (index + 1)`.
    slots: Vec<u64>,
    /// 64 − log2(slots.len()): the slot is the top bits of the hash.
    shift: u32,
}

impl VertexTable {
    /// A table sized for about `expected` distinct vertices (it grows as needed).
    pub fn with_capacity(expected: usize) -> Self {
        let mut t = VertexTable {
            vertices: Vec::with_capacity(expected),
            slots: Vec::new(),
            shift: 64,
        };
        t.resize((2 * expected).max(16).next_power_of_two());
        t
    }

    fn resize(&mut self, size: usize) {
        self.slots = vec![0; size];
        self.shift = 64 - size.trailing_zeros();
        let mask = size - 1;
        for (i, v) in self.vertices.iter().enumerate() {
            let h = hash(&v.map(f64::to_bits));
            let mut s = (h >> self.shift) as usize;
            while self.slots[s] != 0 {
                s = (s + 1) & mask;
            }
            self.slots[s] = (h << 32) | (i as u64 + 1);
        }
    }

    /// The index of the vertex with exactly the bits of `p`, added if new.
    #[inline]
    pub fn insert(&mut self, p: [f64; 3]) -> u32 {
        let bits = p.map(f64::to_bits);
        let h = hash(&bits);
        let tag = h << 32;
        let mask = self.slots.len() - 1;
        let mut s = (h >> self.shift) as usize;
        loop {
            let slot = self.slots[s];
            if slot == 0 {
                break;
            }
            if slot & 0xffff_ffff_0000_0000 == tag {
                let i = (slot as u32 - 1) as usize;
                if self.vertices[i].map(f64::to_bits) == bits {
                    return i as u32;
                }
            }
            s = (s + 1) & mask;
        }
        let i = self.vertices.len();
        self.vertices.push(p);
        self.slots[s] = tag | (i as u64 + 1);
        if 2 * self.vertices.len() > self.slots.len() {
            self.resize(2 * self.slots.len());
        }
        i as u32
    }

    /// The distinct vertices, in order of first appearance.
    pub fn into_vertices(self) -> Vec<[f64; 3]> {
        self.vertices
    }
}

/// Welds vertices that repeat across independently welded chunks: `vertices` are the chunks'
/// distinct vertices one chunk after the other, `indices` point into them. Returns the distinct
/// vertices in order of first appearance and rewrites `indices` to them: what one table fed the
/// vertices in order gives, bit for bit.
///
/// One table over all vertices is what this replaces: on the 1.3 M-face binary STL (32 MB of table
/// and vertices against a 32 MB L3 shared by the machine) its inserts were DRAM and TLB misses,
/// 55–65 ms of a 0.26 s run, and 0.77 s at 10 M faces; this takes 18–23 ms and 0.52 s. Here the
/// vertices are first partitioned by the top bits of their hash into at most 256 runs (8 bytes each:
/// the hash's low half and the position), so each run is welded in its own small table (in
/// parallel); a run keeps file order, so its first copy of a vertex is the first in the file.
/// Numbers then follow in one pass in file order.
///
/// `runs` forces the number of runs (clamped to 1–256), for tests and the `stl_stream` fuzz target:
/// the inputs they can afford have a few thousand vertices at most, one run by the choice here.
pub fn join(vertices: Vec<[f64; 3]>, indices: &mut [u32], runs: Option<usize>) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let n = vertices.len();
    // About 2 Ki vertices a run; at most 256 runs, each written as one stream.
    let runs = runs.map_or_else(
        || (n / 2048).next_power_of_two().clamp(1, 256),
        |r| r.clamp(1, 256),
    );
    let run_of = |h: u64| ((h >> 32) as usize * runs) >> 32;
    let hashes: Vec<u64> = crate::threads::install(|| {
        vertices
            .par_iter()
            .map(|v| hash(&v.map(f64::to_bits)))
            .collect()
    });
    let mut starts = vec![0usize; runs + 1];
    for &h in &hashes {
        starts[run_of(h) + 1] += 1;
    }
    for r in 0..runs {
        starts[r + 1] += starts[r];
    }
    let mut entries = vec![0u64; n];
    let mut fill = starts.clone();
    for (p, &h) in hashes.iter().enumerate() {
        let r = run_of(h);
        entries[fill[r]] = (h << 32) | p as u64;
        fill[r] += 1;
    }
    drop(hashes);
    let firsts: Vec<Vec<u32>> = crate::threads::install(|| {
        (0..runs)
            .into_par_iter()
            .map(|r| first_copies(&entries[starts[r]..starts[r + 1]], &vertices))
            .collect()
    });
    // Each vertex's first copy, in file order.
    let mut first = vec![0u32; n];
    for (&e, &f) in entries.iter().zip(firsts.iter().flatten()) {
        first[e as u32 as usize] = f;
    }
    drop(entries);
    // In place: a vertex's first copy comes no later than it, so `first[f]` already holds f's number
    // and the distinct vertices move only towards the front.
    let mut vertices = vertices;
    let mut distinct = 0;
    for p in 0..n {
        let f = first[p] as usize;
        first[p] = if f == p {
            vertices[distinct] = vertices[p];
            distinct += 1;
            distinct as u32 - 1
        } else {
            first[f]
        };
    }
    vertices.truncate(distinct);
    for i in indices.iter_mut() {
        *i = first[*i as usize];
    }
    vertices
}

/// For each entry of a run (the hash's low half above the position, in file order), the position of
/// the first entry with the same vertex.
fn first_copies(entries: &[u64], vertices: &[[f64; 3]]) -> Vec<u32> {
    let size = (2 * entries.len()).max(16).next_power_of_two();
    let mask = size - 1;
    let mut slots = vec![u32::MAX; size];
    let bits = |e: u64| vertices[e as u32 as usize].map(f64::to_bits);
    entries
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            // The hash's low half picks the slot (its top bits picked the run).
            let mut s = (e >> 32) as usize & mask;
            loop {
                match slots[s] {
                    u32::MAX => {
                        slots[s] = i as u32;
                        return e as u32;
                    }
                    j => {
                        let f = entries[j as usize];
                        if f >> 32 == e >> 32 && bits(f) == bits(e) {
                            return f as u32;
                        }
                    }
                }
                s = (s + 1) & mask;
            }
        })
        .collect()
}

/// Multiplicative hash of three coordinates' bits: the slot is its top bits and the tag its low half,
/// both depending on every input bit.
///
/// A product's low bits depend only on its factors' low bits, and a coordinate's low bits are often
/// all zero: binary STL's f32 values have 29 zero low bits as f64, an integer or a whole number of
/// millimetres 40 and more. Each coordinate's high half (sign, exponent, leading mantissa) is
/// therefore folded onto its low half before it is multiplied (a bijection, so no two keys are made
/// equal). Without it, the low half (the tag, and `first_copies`' slot) of a 48³ grid of integer
/// points took 16,266 distinct values for 110,592 points, and the weld turned quadratic (test
/// `integer_and_millimetre_grids_hash_apart`).
#[inline(always)]
fn hash(b: &[u64; 3]) -> u64 {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;
    let fold = |x: u64| x ^ (x >> 32);
    let h = (fold(b[0]).wrapping_mul(K) ^ fold(b[1])).wrapping_mul(K) ^ fold(b[2]);
    // Folding the high half down before the last product mixes every bit into the high half; a
    // product's low bits still depend on the low bits alone, so the high half, well mixed, is folded
    // onto the low half (the tag and `first_copies`' slot) after it.
    let h = (h ^ (h >> 29)).wrapping_mul(K);
    h ^ (h >> 32)
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
    if !faces.iter().any(collapsed) {
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

/// Faces through a vertex map: runs of a repeated vertex are folded, and faces left with fewer than
/// three distinct vertices are dropped. Returns the faces kept and, per input face, whether it was kept.
pub fn remap_faces(faces: &Polygons, remap: &[u32]) -> (Polygons, Vec<bool>) {
    let mut out = Polygons {
        indices: Vec::with_capacity(faces.indices.len()),
        starts: Vec::with_capacity(faces.starts.len().max(1)),
    };
    out.starts.push(0);
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

/// How a file stored the coordinates. A file that rounds each facet's corners independently stores a
/// shared corner up to one unit in the last place apart in each coordinate: an f32 ulp (binary STL,
/// glTF), or a unit of the last decimal digit (ASCII exporters writing 6 to 9 significant digits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    F64,
    F32,
    /// Every coordinate has at most this many significant decimal digits (6 to 9).
    Decimal(u8),
}

impl Precision {
    /// The precision of coordinates as read (before scaling): f32 when every one is an f32 value;
    /// else decimal when every one has at most 9 significant digits and some have 6 or more (fewer
    /// everywhere is a designed shape, 0.5 and 0.25, not a rounded one); else f64.
    pub fn of(vertices: &[[f64; 3]]) -> Precision {
        let f32_exact = |x: f64| f64::from(x as f32) == x;
        if vertices.iter().flatten().all(|&x| f32_exact(x)) {
            return Precision::F32;
        }
        let mut most = 0;
        for &x in vertices.iter().flatten() {
            let digits = digits_up_to_ten(x);
            if digits > 9 {
                return Precision::F64;
            }
            most = most.max(digits);
        }
        if most >= 6 {
            Precision::Decimal(most as u8)
        } else {
            Precision::F64
        }
    }

    /// A unit in the last place, relative to the magnitude (an upper bound).
    pub fn relative_ulp(self) -> f64 {
        match self {
            Precision::F64 => 0.0,
            Precision::F32 => f64::from(f32::EPSILON),
            Precision::Decimal(d) => 10f64.powi(1 - i32::from(d)),
        }
    }
}

/// [`significant_digits`] where [`Precision::of`] needs it: exact up to 9, 10 for any count above.
/// Found by asking which decimal of 9 digits reads back as `x` (Clinger's exact fast path) instead
/// of formatting `x`: formatting took 16% of healing the 48 k-face borinot base (a DAE of 6-digit
/// decimals, ~150 ns per coordinate).
fn digits_up_to_ten(x: f64) -> usize {
    if x == 0.0 {
        return 0;
    }
    match nine_digits(x) {
        None => significant_digits(x).min(10),
        Some(None) => 10,
        Some(Some(mut m)) => {
            // Decimals of 9 digits are more than 2 ulps apart, so at most one reads back as `x`;
            // a shorter one that did would be it with zeros appended.
            while m % 10 == 0 {
                m /= 10;
            }
            m.ilog10() as usize + 1
        }
    }
}

/// The mantissa m < 10⁹ of a decimal m·10^k that reads back as `x` (≠ 0), `Some(None)` when there
/// is none, `None` when the decimal exponent is out of the range where the fast path is exact.
///
/// Clinger's fast path: for an integer m < 2⁵³ and |k| ≤ 22, m and 10^|k| are exact f64 values, so
/// one correctly rounded product or quotient is the correctly rounded value of m·10^k, which is what
/// parsing the decimal gives. A decimal reading back as `x` lies within half an ulp of it, so its
/// exponent is within one of the one giving `x` 9 digits, and its mantissa within one of `x`/10^k
/// rounded.
fn nine_digits(x: f64) -> Option<Option<u64>> {
    use super::EXACT_POWERS_OF_TEN as POW10;
    let x = x.abs();
    // floor(log10 x) is e or e + 1 for e = floor(e2·log10 2), e2 the binary exponent (78913/2^18 is
    // log10 2 to 1e-7; the shift floors): no log10, floor or round calls, which are library calls on
    // baseline x86-64 (the 48 k-face borinot DAE: 12% of its healing went to them).
    let e2 = ((x.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    let e = (e2 * 78_913) >> 18;
    // Rounds to the nearest integer (ties to even) for 0 ≤ y < 2^52: adding 2^52 leaves no fraction
    // bits.
    let round = |y: f64| (y + 4_503_599_627_370_496.0) - 4_503_599_627_370_496.0;
    let k0 = e - 8;
    // The exponent the decimal needs is within one of floor(log10 x) − 8: all four are tried.
    let ks = [k0, k0 + 1, k0 - 1, k0 + 2];
    for k in ks {
        POW10.get(k.unsigned_abs() as usize)?;
    }
    for k in ks {
        let p = POW10[k.unsigned_abs() as usize];
        let y = round(if k >= 0 { x / p } else { x * p });
        for m in [y, y - 1.0, y + 1.0] {
            let value = if k >= 0 { m * p } else { m / p };
            if (1.0..1e9).contains(&m) && value == x {
                return Some(Some(m as u64));
            }
        }
    }
    Some(None)
}

/// Significant digits of the shortest decimal that reads back as `x`.
fn significant_digits(x: f64) -> usize {
    if x == 0.0 {
        return 0;
    }
    let text = format!("{:e}", x.abs());
    let mantissa = text.split('e').next().unwrap_or("");
    mantissa.bytes().filter(u8::is_ascii_digit).count()
}

/// The tolerance of the second pass: `max(base, 2 × relative ulp × |p|∞)` at a vertex `p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// `max(1e-9 × extent, 16 ulp of the largest |coordinate|)`, m.
    pub base: f64,
    /// The stored precision's relative ulp (0 for f64).
    pub relative_ulp: f64,
    /// The largest tolerance at any vertex, m.
    pub largest: f64,
}

impl Tolerance {
    /// The tolerance at `p`: two units in the last place of its largest coordinate (a corner rounded
    /// up in one facet and down in the next is one unit off in each coordinate, √3 in distance).
    pub fn at(&self, p: &[f64; 3]) -> f64 {
        let m = p[0].abs().max(p[1].abs()).max(p[2].abs());
        self.base.max(2.0 * self.relative_ulp * m)
    }
}

/// The tolerance of the second pass for these (scaled) vertices stored with `precision`.
pub fn tolerance(vertices: &[[f64; 3]], precision: Precision) -> Tolerance {
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
    let base = (RELATIVE_TOLERANCE * extent).max(ULPS * f64::EPSILON * largest);
    let relative_ulp = precision.relative_ulp();
    Tolerance {
        base,
        relative_ulp,
        largest: base.max(2.0 * relative_ulp * largest),
    }
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
    pub tolerance: Tolerance,
}

/// A representative within the tolerance of a vertex being welded.
#[derive(Clone, Copy)]
struct Candidate {
    d: f64,
    /// Position of its cell in the scan of the 27 cells around the vertex's, (dx, dy, dz) order.
    scan: i64,
    index: u32,
}

impl Candidate {
    /// Whether the 27-cell scan (each cell's latest representative first, the first strictly
    /// nearer one kept) picks `self` over `other`.
    fn before(&self, other: &Candidate) -> bool {
        (self.d, self.scan, std::cmp::Reverse(self.index)).partial_cmp(&(
            other.d,
            other.scan,
            std::cmp::Reverse(other.index),
        )) == Some(std::cmp::Ordering::Less)
    }
}

/// Merges each vertex into the nearest earlier representative within the larger of their two
/// tolerances (Euclidean distance), greedily in index order, on a hash grid whose cells are the
/// largest tolerance wide.
pub fn tolerant(vertices: &[[f64; 3]], tol: Tolerance) -> TolerantWeld {
    let n = vertices.len();
    let mut representative: Vec<u32> = (0..n as u32).collect();
    let cell_size = tol.largest;
    if !(cell_size > 0.0 && cell_size.is_finite()) || n == 0 {
        return TolerantWeld {
            representative,
            merged: 0,
            widest: 0.0,
            tolerance: tol,
        };
    }
    let origin = vertices[0];
    // Cell indices stay within ±1e9 for a mesh whose extent is at most 1e9 tolerances (the base
    // tolerance is 1e-9 of the extent); `as` saturates rather than wrapping beyond that.
    let cell = |p: &[f64; 3]| -> [i64; 3] {
        [0, 1, 2].map(|k| ((p[k] - origin[k]) / cell_size).floor() as i64)
    };
    // Representatives per block of 2×2×2 cells as linked lists: the first in `head`, the rest
    // through `next`. The 27 cells around a vertex's own span exactly two blocks along each axis, so
    // 8 lookups replace 27 (the misses of those lookups were nearly all of this function: 14% of
    // healing the 48 k-face borinot base); a representative found counts only if its own cell is one
    // of the 27, and ties in distance go the way the 27-cell scan went (cells in (dx, dy, dz) order,
    // the latest representative of a cell first), so the result is that scan's.
    let block = |c: [i64; 3]| c.map(|x| x.div_euclid(2));
    let mut head: FxHashMap<[i64; 3], u32> =
        FxHashMap::with_capacity_and_hasher(n, Default::default());
    let mut next: Vec<u32> = vec![u32::MAX; n];
    let mut cells: Vec<[i64; 3]> = vec![[0; 3]; n];
    let mut merged = 0;
    let mut widest = 0.0f64;
    for i in 0..n {
        let p = &vertices[i];
        let tp = tol.at(p);
        let c = cell(p);
        let first = block(c.map(|x| x - 1));
        let mut found: Option<Candidate> = None;
        for b in 0..8 {
            let key = [
                first[0] + (b >> 2),
                first[1] + ((b >> 1) & 1),
                first[2] + (b & 1),
            ];
            let mut r = head.get(&key).copied().unwrap_or(u32::MAX);
            while r != u32::MAX {
                let at = r as usize;
                r = next[at];
                let off = [0, 1, 2].map(|k| cells[at][k] - c[k]);
                if off.iter().any(|o| o.abs() > 1) {
                    continue;
                }
                let q = &vertices[at];
                let d =
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                let cand = Candidate {
                    d,
                    scan: (off[0] + 1) * 9 + (off[1] + 1) * 3 + off[2] + 1,
                    index: at as u32,
                };
                if d <= tp.max(tol.at(q)) && found.is_none_or(|f| cand.before(&f)) {
                    found = Some(cand);
                }
            }
        }
        match found {
            Some(f) => {
                representative[i] = f.index;
                merged += 1;
                widest = widest.max(f.d);
            }
            None => {
                cells[i] = c;
                let slot = head.entry(block(c)).or_insert(u32::MAX);
                next[i] = *slot;
                *slot = i as u32;
            }
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
        // The same in f32: two f32 ulps of 1 m is 2.4e-7 m, forty times below the slot.
        let v32: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| f64::from(x as f32))).collect();
        let mut nudged = v32[1];
        nudged[0] = f64::from(f32::from_bits((nudged[0] as f32).to_bits() + 1));
        let mut v32 = v32;
        v32.push(nudged);
        let t = tolerant(&v32, tolerance(&v32, Precision::of(&v32)));
        assert_eq!(Precision::of(&v32), Precision::F32);
        assert_eq!(t.representative, vec![0, 1, 1, 3, 4, 1]);
    }

    #[test]
    fn decimal_precision_is_recognised() {
        let v = vec![[0.123457, 1.5, 2.0], [0.5, 0.25, 100.001]];
        assert_eq!(Precision::of(&v), Precision::Decimal(6));
        let designed = vec![[0.5, 0.25, 1.0], [2.0, 3.0, 4.0]];
        // f32 values, so F32; a shape with few digits that is not f32 stays F64.
        assert_eq!(Precision::of(&designed), Precision::F32);
        assert_eq!(Precision::of(&[[0.1, 0.2, 0.3]]), Precision::F64);
        assert_eq!(Precision::of(&[[0.1 + 0.2, 0.2, 0.3]]), Precision::F64);
    }

    #[test]
    fn digit_counts_agree_with_formatting() {
        // Decimals of 1 to 17 digits over 40 decades, their neighbours one ulp away, and f32 values.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rand = move || crate::xorshift(&mut state);
        for _ in 0..200_000 {
            let digits = (rand() % 17 + 1) as i32;
            let mantissa = (rand() % 10u64.pow(digits as u32)) as f64;
            let exponent = (rand() % 40) as i32 - 25 - digits;
            let x: f64 = format!("{mantissa}e{exponent}").parse().unwrap();
            let f32_value = f64::from(x as f32);
            for y in [x, f64::from_bits(x.to_bits() + 1), -x, f32_value] {
                let want = significant_digits(y);
                let got = digits_up_to_ten(y);
                assert_eq!(got, want.min(10), "{y:e}");
            }
        }
    }

    /// The 27-cell scan `tolerant` replaced, as it was.
    fn tolerant_27(vertices: &[[f64; 3]], tol: Tolerance) -> Vec<u32> {
        let n = vertices.len();
        let mut representative: Vec<u32> = (0..n as u32).collect();
        let (cell_size, origin) = (tol.largest, vertices[0]);
        let cell = |p: &[f64; 3]| -> [i64; 3] {
            [0, 1, 2].map(|k| ((p[k] - origin[k]) / cell_size).floor() as i64)
        };
        let mut head: FxHashMap<[i64; 3], u32> = FxHashMap::default();
        let mut next: Vec<u32> = vec![u32::MAX; n];
        for i in 0..n {
            let (p, tp, c) = (&vertices[i], tol.at(&vertices[i]), cell(&vertices[i]));
            let mut found: Option<(u32, f64)> = None;
            for d in 0..27 {
                let key = [c[0] + d / 9 - 1, c[1] + (d / 3) % 3 - 1, c[2] + d % 3 - 1];
                let mut r = head.get(&key).copied().unwrap_or(u32::MAX);
                while r != u32::MAX {
                    let q = &vertices[r as usize];
                    let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2))
                        .sqrt();
                    if d <= tp.max(tol.at(q)) && found.is_none_or(|(_, best)| d < best) {
                        found = Some((r, d));
                    }
                    r = next[r as usize];
                }
            }
            match found {
                Some((r, _)) => representative[i] = r,
                None => {
                    let slot = head.entry(c).or_insert(u32::MAX);
                    next[i] = *slot;
                    *slot = i as u32;
                }
            }
        }
        representative
    }

    #[test]
    fn blocks_of_cells_weld_as_the_27_cell_scan() {
        // Clusters of points on a lattice a fraction of the tolerance apart: many ties in distance,
        // representatives in neighbouring cells, blocks and cells crossing zero.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = move |m: u64| crate::xorshift(&mut state) % m;
        for step in [0.25, 0.5, 0.7, 1.0] {
            let tol = Tolerance {
                base: 1.0,
                relative_ulp: 0.0,
                largest: 1.0,
            };
            let v: Vec<[f64; 3]> = (0..4000)
                .map(|_| [0, 1, 2].map(|_| (rand(41) as f64 - 20.0) * step))
                .collect();
            let t = tolerant(&v, tol);
            assert_eq!(t.representative, tolerant_27(&v, tol), "step {step}");
        }
    }

    #[test]
    fn tolerance_covers_parts_far_from_the_origin() {
        // A 1 mm part 1 km away: its round-off is 16 ulp of 1e3, above 1e-9 of 1e-3.
        let v = vec![[1e3, 0.0, 0.0], [1e3 + 1e-3, 1e-3, 1e-3]];
        assert_eq!(
            tolerance(&v, Precision::F64).base,
            16.0 * f64::EPSILON * (1e3 + 1e-3)
        );
    }

    #[test]
    fn vertex_table_numbers_by_first_appearance_through_growth() {
        let mut t = VertexTable::with_capacity(1);
        let pts: Vec<[f64; 3]> = (0..1000)
            .map(|i| [f64::from(i % 37), 0.5, -f64::from(i % 37)])
            .collect();
        let ids: Vec<u32> = pts.iter().map(|&p| t.insert(p)).collect();
        assert!(ids.iter().enumerate().all(|(i, &id)| id == (i % 37) as u32));
        // -0.0 and 0.0 are different bits to the table; `exact` folds them first.
        assert_ne!(t.insert([-0.0, 0.5, 0.0]), t.insert([0.0, 0.5, 0.0]));
        assert_eq!(t.into_vertices().len(), 39);
        let w = exact(&[[-0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], &Polygons::new());
        assert_eq!(w.vertices, vec![[0.0, 0.0, 0.0]]);
    }

    /// Chunks welded on their own and then joined number every vertex as one weld of all corners in
    /// order does: corners drawn from a small pool (so most repeat, within and across chunks), in
    /// chunks of several sizes, from one run of entries to the most, and with run counts forced
    /// (powers of two or not) on the smaller cases.
    #[test]
    fn joined_chunks_are_the_sequential_weld() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let pool: Vec<[f64; 3]> = (0..40_000)
            .map(|_| [0; 3].map(|_| f64::from(crate::xorshift(&mut state) as u32 as f32) * 1e-6))
            .collect();
        let cases: [(usize, usize, &[Option<usize>]); 3] = [
            (300, 7, &[None, Some(1), Some(3), Some(256)]),
            (50_000, 1_000, &[None, Some(5), Some(256)]),
            (1_500_000, 65_536, &[None]),
        ];
        for (corners, chunk, runs) in cases {
            let picks: Vec<[f64; 3]> = (0..corners)
                .map(|_| pool[(crate::xorshift(&mut state) % pool.len() as u64) as usize])
                .collect();
            let mut reference = VertexTable::with_capacity(16);
            let want: Vec<u32> = picks.iter().map(|&p| reference.insert(p)).collect();
            let bits = |v: &[[f64; 3]]| v.iter().map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
            let reference = bits(&reference.into_vertices());
            for &runs in runs {
                let (mut vertices, mut indices) = (Vec::new(), Vec::new());
                for c in picks.chunks(chunk) {
                    let mut table = VertexTable::with_capacity(16);
                    let local: Vec<u32> = c.iter().map(|&p| table.insert(p)).collect();
                    let base = vertices.len() as u32;
                    vertices.extend(table.into_vertices());
                    indices.extend(local.iter().map(|&i| base + i));
                }
                let joined = join(vertices, &mut indices, runs);
                let case = format!("{corners} corners in chunks of {chunk}, runs {runs:?}");
                assert_eq!(indices, want, "{case}");
                assert_eq!(bits(&joined), reference, "{case}");
            }
        }
    }

    /// Integer-grid and whole-millimetre coordinates (40 and more zero low bits) spread over the
    /// slots as random keys do. Both halves of the hash are used: the top bits pick `VertexTable`'s
    /// slot and `join`'s run, the low half is the tag and picks `first_copies`' slot. n keys thrown
    /// into n slots fill 1 − 1/e ≈ 63.2% of them; these grids fill between 55% and 72% by either
    /// half, every key has its own low half, and linear probing takes as few probes as random keys
    /// (about 1.4 a key at a load of a half). Without the fold, a 48³ integer grid had 16,266
    /// distinct low halves for its 110,592 points: tags matched falsely and `first_copies` probed
    /// long runs, the quadratic weld.
    #[test]
    fn integer_and_millimetre_grids_hash_apart() {
        let side = 64usize;
        let bits = 18; // 2^18 = 64^3 slots
        type Grid = (&'static str, fn(usize) -> f64);
        let grids: [Grid; 5] = [
            ("integers", |n| n as f64),
            ("integers far out", |n| 1e6 + n as f64),
            ("half units", |n| n as f64 * 0.5 - 16.0),
            // Whole millimetres in a binary STL in metres: f32 values, 29 zero low bits as f64.
            ("f32 millimetres", |n| f64::from(n as f32 * 0.001)),
            ("f32 whole millimetres", |n| f64::from(n as f32 * 8.0)),
        ];
        for (name, c) in grids {
            let mut points = Vec::with_capacity(side * side * side);
            for i in 0..side {
                for j in 0..side {
                    for k in 0..side {
                        points.push([c(i), c(j), c(k)]);
                    }
                }
            }
            let hashes: Vec<u64> = points.iter().map(|p| hash(&p.map(f64::to_bits))).collect();
            let top = |h: u64, b: u32| (h >> (64 - b)) as usize;
            let low = |h: u64, b: u32| (h as u32 as usize) & ((1 << b) - 1);
            for (half, slot) in [("top", &top as &dyn Fn(u64, u32) -> usize), ("low", &low)] {
                let mut seen = vec![false; 1 << bits];
                for &h in &hashes {
                    seen[slot(h, bits)] = true;
                }
                let filled = seen.iter().filter(|&&s| s).count() as f64 / points.len() as f64;
                assert!(
                    (0.55..0.72).contains(&filled),
                    "{name}, {half} half: {filled}"
                );
                // Every insert's probes into a table at the weld's load (at most a half), against a
                // generous bound of 4 a key.
                let mut slots = vec![false; 1 << (bits + 1)];
                let mask = slots.len() - 1;
                let mut probes = 0usize;
                for &h in &hashes {
                    let mut s = slot(h, bits + 1);
                    probes += 1;
                    while slots[s] {
                        s = (s + 1) & mask;
                        probes += 1;
                    }
                    slots[s] = true;
                }
                assert!(
                    probes < 4 * points.len(),
                    "{name}, {half} half: {probes} probes"
                );
            }
            let mut tags: Vec<u32> = hashes.iter().map(|&h| h as u32).collect();
            tags.sort_unstable();
            tags.dedup();
            assert!(
                tags.len() * 1000 >= points.len() * 999,
                "{name}: {} tags",
                tags.len()
            );
            // The weld's result is the distinct points in order, whatever the hash.
            let mut table = VertexTable::with_capacity(16);
            for p in &points {
                table.insert(*p);
            }
            assert_eq!(table.into_vertices(), points, "{name}");
        }
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
