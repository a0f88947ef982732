//! The tolerant pass: the input's precision, the tolerance it gives, and greedy clustering on a
//! hash grid.

use super::{RELATIVE_TOLERANCE, ULPS};
use rustc_hash::{FxBuildHasher, FxHashMap};

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
/// of formatting `x`, which was a sixth of healing a mesh of 6-digit decimals (figures:
/// docs/benchmarks.md, "Figures behind choices in the code").
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
// The two `None`s differ (documented above): no 9-digit decimal, or outside the exact fast path.
#[allow(clippy::option_option)]
fn nine_digits(x: f64) -> Option<Option<u64>> {
    use crate::mesh::EXACT_POWERS_OF_TEN as POW10;
    let x = x.abs();
    // floor(log10 x) is e or e + 1 for e = floor(e2·log10 2), e2 the binary exponent (78913/2^18 is
    // log10 2 to 1e-7; the shift floors): no log10, floor or round calls, which are library calls on
    // baseline x86-64 (figures: docs/benchmarks.md, "Figures behind choices in the code").
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
    let mut bounds = crate::geometry::Aabb::EMPTY;
    let mut largest = 0.0f64;
    for &v in vertices {
        bounds.add(v);
        largest = largest.max(v[0].abs()).max(v[1].abs()).max(v[2].abs());
    }
    let extent = bounds.largest_extent().max(0.0);
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

/// The end of a list of representatives.
const NONE: u32 = u32::MAX;

/// A block whose list reaches this many representatives is searched by tolerance level from then
/// on ([`Crowd`]). Real meshes rarely come near it: their representatives are further apart than
/// their tolerances, and the cells are the largest tolerance wide (figures: docs/benchmarks.md,
/// "Figures behind choices in the code").
const CROWDED: u32 = 32;

/// The representatives of a block of 2×2×2 cells.
#[derive(Clone, Copy)]
enum Block {
    /// The latest one, the rest through `next`; `NONE` when empty.
    List(u32),
    /// Crowded: its representatives are in [`Crowd`], at the levels `Crowd::blocks[id]`.
    Crowded(u32),
}

/// `reach` = max(tp, level's tolerance) × `REACH_SLACK` + `REACH_FLOOR` covers what rounding adds
/// to a distance (see `weld`).
const REACH_SLACK: f64 = 1.0 + 1.0 / 1_048_576.0;
const REACH_FLOOR: f64 = 1e-140;

/// The representatives of crowded blocks, sorted by their own tolerance t into levels, each level a
/// hash grid of sub-cells 2^e wide, 2^e in (2t, 4t].
///
/// Representatives crowd a cell of the coarse grid when their tolerances are far below the largest
/// one, which sets the cells' size: a binary STL's corners scattered within 1e-7 m of the origin,
/// where the tolerance is 1e-9 m, in cells of 2.4e-7 m (2 f32 ulps of 1 m). Each vertex there
/// scanned every one of them, quadratic work; in a level it looks only at the sub-cells within its
/// reach, usually 8.
#[derive(Default)]
struct Crowd {
    /// For each crowded block, the levels of its representatives (indices into `levels`).
    blocks: Vec<Vec<u32>>,
    levels: Vec<Level>,
    /// The level of each sub-cell exponent e.
    by_exponent: FxHashMap<i32, u32>,
    /// The latest representative of each sub-cell (level, cell), the rest through `next`.
    heads: FxHashMap<(u32, [i64; 3]), u32>,
}

/// The representatives of crowded blocks whose sub-cells are 2^e wide.
struct Level {
    /// 2^-e, exact: e is clamped to ±1000, which only makes sub-cells coarser or finer than ideal.
    scale: f64,
    /// The largest tolerance of a member.
    tolerance: f64,
    /// Every member, searched whole by a vertex whose reach spans more sub-cells than this.
    members: Vec<u32>,
}

impl Crowd {
    /// The level of a representative of tolerance `t`: e = ⌊log₂ t⌋ + 2 from its exponent bits.
    fn level(&mut self, t: f64) -> u32 {
        let e = (((t.to_bits() >> 52) & 0x7ff) as i32 - 1021).clamp(-1000, 1000);
        let levels = &mut self.levels;
        *self.by_exponent.entry(e).or_insert_with(|| {
            levels.push(Level {
                scale: f64::from_bits(((1023 - e) as u64) << 52),
                tolerance: 0.0,
                members: Vec::new(),
            });
            (levels.len() - 1) as u32
        })
    }

    /// Adds the representative `at`, at `q` with tolerance `t`, to the crowded block `block`.
    fn insert(&mut self, block: u32, at: u32, q: &[f64; 3], t: f64, next: &mut [u32]) {
        let l = self.level(t);
        let level = &mut self.levels[l as usize];
        level.tolerance = level.tolerance.max(t);
        level.members.push(at);
        let key = (l, q.map(|x| (x * level.scale).floor() as i64));
        let levels = &mut self.blocks[block as usize];
        if !levels.contains(&l) {
            levels.push(l);
        }
        let head = self.heads.entry(key).or_insert(NONE);
        next[at as usize] = *head;
        *head = at;
    }

    /// Visits every representative of the crowded blocks `blocks` that is a candidate for the
    /// vertex `p` of tolerance `tp` (and others); how many levels were visited whole. `levels` is
    /// room for the levels to search.
    fn search(
        &self,
        blocks: &[u32],
        levels: &mut Vec<u32>,
        (p, tp): (&[f64; 3], f64),
        next: &[u32],
        mut visit: impl FnMut(usize),
    ) -> usize {
        levels.clear();
        for &b in blocks {
            levels.extend_from_slice(&self.blocks[b as usize]);
        }
        levels.sort_unstable();
        levels.dedup();
        let mut whole = 0;
        for &l in levels.iter() {
            let level = &self.levels[l as usize];
            let reach = tp.max(level.tolerance) * REACH_SLACK + REACH_FLOOR;
            let lo = p.map(|x| ((x - reach) * level.scale).floor() as i64);
            let hi = p.map(|x| ((x + reach) * level.scale).floor() as i64);
            let span = |k: usize| hi[k].abs_diff(lo[k]).saturating_add(1);
            let cells = span(0).saturating_mul(span(1)).saturating_mul(span(2));
            if cells > level.members.len() as u64 {
                // A reach far wider than the level's tolerance (tolerances that vary steeply):
                // the members are fewer than the sub-cells.
                whole += 1;
                level.members.iter().for_each(|&at| visit(at as usize));
                continue;
            }
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        let mut r = self.heads.get(&(l, [x, y, z])).copied().unwrap_or(NONE);
                        while r != NONE {
                            visit(r as usize);
                            r = next[r as usize];
                        }
                    }
                }
            }
        }
        whole
    }
}

/// Merges each vertex into the nearest earlier representative within the larger of their two
/// tolerances (Euclidean distance), greedily in index order, on a hash grid whose cells are the
/// largest tolerance wide.
pub fn tolerant(vertices: &[[f64; 3]], tol: Tolerance) -> TolerantWeld {
    weld(vertices, tol).0
}

/// How a weld used [`Crowd`], for tests: crowded blocks, levels searched whole.
#[derive(Debug, Default)]
struct Crowding {
    blocks: usize,
    whole_levels: usize,
}

/// [`tolerant`], and how crowded it found the grid.
///
/// The result is the 27-cell scan's, crowded blocks or not. A vertex `p`'s candidates are the
/// representatives `q` in the 27 cells around its own whose distance `d`, computed as below, is at
/// most max(tp, tq). The one kept is the least by [`Candidate::before`], a strict total order on
/// candidates (indices differ; a NaN distance is no candidate), so it is the same whatever order
/// they are met in, and however often. Every candidate is in one of the 8 blocks: on a list, walked
/// whole, or in a crowded block, whose levels are all searched. A candidate at a level has tq at
/// most the level's tolerance T, so d ≤ R = max(tp, T); a computed distance d ≤ R bounds each
/// coordinate's difference by R(1 + 2⁻⁵⁰) + 2⁻⁵³⁶ (each step rounds by a relative 2⁻⁵³ at most, or
/// an absolute 2⁻¹⁰⁷⁵ below the normal range), which `reach` exceeds. So q's coordinate is in
/// [p − reach, p + reach], and, rounding being monotone and the coordinate a float, in
/// [fl(p − reach), fl(p + reach)]; its sub-cell, a monotone function of it (a product by a power of
/// two, a floor, a saturating cast), is in the range searched. A vertex visited that is no
/// candidate fails the same test as in the scan.
// One loop over the vertices, searching and then inserting; its parts share most of its locals.
#[allow(clippy::too_many_lines)]
fn weld(vertices: &[[f64; 3]], tol: Tolerance) -> (TolerantWeld, Crowding) {
    let n = vertices.len();
    let mut representative: Vec<u32> = (0..n as u32).collect();
    let mut crowding = Crowding::default();
    let cell_size = tol.largest;
    if !(cell_size > 0.0 && cell_size.is_finite()) || n == 0 {
        let weld = TolerantWeld {
            representative,
            merged: 0,
            widest: 0.0,
            tolerance: tol,
        };
        return (weld, crowding);
    }
    let origin = vertices[0];
    // Cell indices stay within ±1e9 for a mesh whose extent is at most 1e9 tolerances (the base
    // tolerance is 1e-9 of the extent); `as` saturates rather than wrapping beyond that.
    let cell = |p: &[f64; 3]| -> [i64; 3] {
        [0, 1, 2].map(|k| ((p[k] - origin[k]) / cell_size).floor() as i64)
    };
    // Representatives per block of 2×2×2 cells as linked lists: the first in `head`, the rest
    // through `next`. The 27 cells around a vertex's own span exactly two blocks along each axis, so
    // 8 lookups replace 27 (the misses of those lookups were nearly all of this function; figures:
    // docs/benchmarks.md, "Figures behind choices in the code"); a representative found counts only
    // if its own cell is one of the 27, and ties in distance go the way the 27-cell scan went (cells
    // in (dx, dy, dz) order, the latest representative of a cell first), so the result is that
    // scan's.
    let block = |c: [i64; 3]| c.map(|x| x.div_euclid(2));
    let mut head: FxHashMap<[i64; 3], Block> =
        FxHashMap::with_capacity_and_hasher(n, FxBuildHasher);
    let mut next: Vec<u32> = vec![NONE; n];
    let mut cells: Vec<[i64; 3]> = vec![[0; 3]; n];
    let mut crowd = Crowd::default();
    let (mut crowded, mut levels, mut moved) = (Vec::new(), Vec::new(), Vec::new());
    let mut merged = 0;
    let mut widest = 0.0f64;
    for i in 0..n {
        let p = &vertices[i];
        let tp = tol.at(p);
        let c = cell(p);
        let first = block(c.map(|x| x - 1));
        // The vertex's own block is the second of the two along an axis where its cell is even.
        let own = (!c[0] & 1) << 2 | (!c[1] & 1) << 1 | (!c[2] & 1);
        let mut found: Option<Candidate> = None;
        let mut consider = |at: usize| {
            let off = [0, 1, 2].map(|k| cells[at][k] - c[k]);
            if off.iter().any(|o| o.abs() > 1) {
                return;
            }
            let q = &vertices[at];
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            let cand = Candidate {
                d,
                scan: (off[0] + 1) * 9 + (off[1] + 1) * 3 + off[2] + 1,
                index: at as u32,
            };
            if d <= tp.max(tol.at(q)) && found.is_none_or(|f| cand.before(&f)) {
                found = Some(cand);
            }
        };
        let mut own_len = 0;
        crowded.clear();
        for b in 0..8 {
            let key = [
                first[0] + (b >> 2),
                first[1] + ((b >> 1) & 1),
                first[2] + (b & 1),
            ];
            match head.get(&key) {
                None => {}
                Some(&Block::Crowded(id)) => crowded.push(id),
                Some(&Block::List(mut r)) => {
                    let mut len = 0;
                    while r != NONE {
                        let at = r as usize;
                        r = next[at];
                        len += 1;
                        consider(at);
                    }
                    if b == own {
                        own_len = len;
                    }
                }
            }
        }
        if !crowded.is_empty() {
            crowding.whole_levels +=
                crowd.search(&crowded, &mut levels, (p, tp), &next, &mut consider);
        }
        if let Some(f) = found {
            representative[i] = f.index;
            merged += 1;
            widest = widest.max(f.d);
            continue;
        }
        cells[i] = c;
        let slot = head.entry(block(c)).or_insert(Block::List(NONE));
        match *slot {
            Block::List(r) if own_len < CROWDED => {
                next[i] = r;
                *slot = Block::List(i as u32);
            }
            Block::List(mut r) => {
                // The list reaches `CROWDED`: its representatives move to the crowd, by level.
                let id = crowd.blocks.len() as u32;
                crowd.blocks.push(Vec::new());
                crowding.blocks += 1;
                *slot = Block::Crowded(id);
                moved.clear();
                while r != NONE {
                    moved.push(r);
                    r = next[r as usize];
                }
                for &at in &moved {
                    let q = &vertices[at as usize];
                    crowd.insert(id, at, q, tol.at(q), &mut next);
                }
                crowd.insert(id, i as u32, p, tp, &mut next);
            }
            Block::Crowded(id) => crowd.insert(id, i as u32, p, tp, &mut next),
        }
    }
    let weld = TolerantWeld {
        representative,
        merged,
        widest,
        tolerance: tol,
    };
    (weld, crowding)
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
            if let Some((r, _)) = found { representative[i] = r } else {
                let slot = head.entry(c).or_insert(u32::MAX);
                next[i] = *slot;
                *slot = i as u32;
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
    fn crowded_blocks_weld_as_the_27_cell_scan() {
        let mut state = 0x5851_f42d_4c95_7f2du64;
        let mut rand = move |m: u64| crate::xorshift(&mut state) % m;
        // Binary STL triangles whose corners lie within 1e-7 of (0,0,0), (1,0,0) and (0,1,0), some
        // corners repeated and some on a lattice (ties): cells of 2 f32 ulps of 1 m crowded by
        // corners near the origin, whose tolerance is 1e-9 m.
        let mut v: Vec<[f64; 3]> = Vec::new();
        for _ in 0..2500 {
            for corner in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
                let p = match rand(4) {
                    0 if !v.is_empty() => v[rand(v.len() as u64) as usize],
                    1 => corner.map(|x| x + (rand(21) as f64 - 10.0) * 1e-9),
                    _ => corner.map(|x| x + (rand(2001) as f64 - 1000.0) * 1e-10),
                };
                v.push(p.map(|x| f64::from(x as f32)));
            }
        }
        assert_eq!(Precision::of(&v), Precision::F32);
        let tol = tolerance(&v, Precision::F32);
        let (t, crowding) = weld(&v, tol);
        assert!(crowding.blocks > 0, "{crowding:?}");
        assert_eq!(t.representative, tolerant_27(&v, tol), "{crowding:?}");
        // Tolerances that vary steeply with the distance from the origin (ulps of 25% to 1%): many levels
        // in a block, vertices whose reach spans more sub-cells than a level has members, lattices
        // of several steps crossing zero, in shuffled order.
        for (base, relative_ulp) in [(1e-6, 0.25), (1e-6, 0.05), (1e-7, 0.01), (3e-5, 0.0)] {
            let mut v: Vec<[f64; 3]> = (0..6000)
                .map(|_| {
                    let step = [1e-6, 1e-5, 1e-4, 1e-3][rand(4) as usize];
                    [0, 1, 2].map(|_| (rand(41) as f64 - 20.0) * step)
                })
                .collect();
            for i in (1..v.len()).rev() {
                v.swap(i, rand(i as u64 + 1) as usize);
            }
            let mut tol = Tolerance {
                base,
                relative_ulp,
                largest: 0.0,
            };
            tol.largest = v.iter().map(|p| tol.at(p)).fold(0.0, f64::max);
            let (t, crowding) = weld(&v, tol);
            // One tolerance everywhere (f64 data) leaves no block crowded.
            assert_eq!(crowding.blocks > 0, relative_ulp > 0.0, "{base} {crowding:?}");
            if relative_ulp > 0.01 {
                assert!(crowding.whole_levels > 0, "{base} {crowding:?}");
            }
            assert_eq!(t.representative, tolerant_27(&v, tol), "{base} {crowding:?}");
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
}
