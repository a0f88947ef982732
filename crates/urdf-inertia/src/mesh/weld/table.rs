//! Bit-identical welding: the vertex table.

/// Distinct vertices keyed by their bit patterns: an open-addressing table of vertex indices (with a
/// 32-bit tag of the hash beside each) over the vertex list itself, so a vertex is stored once and a
/// lookup touches one 8-byte slot and, on a tag match, the vertex. Indices are given in order of first
/// appearance, which makes the result independent of the table's size and growth.
///
/// It replaces a `FxHashMap<[u64; 3], u32>` (32-byte buckets and a second copy of every vertex): on a
/// 1.3 M-face binary STL that map alone took 128 MiB, and its misses dominated the weld.
#[derive(Debug, Clone, Default)]
pub struct VertexTable {
    pub(super) vertices: Vec<[f64; 3]>,
    /// 0: empty; else `tag << 32 | (index + 1)`.
    pub(super) slots: Vec<u64>,
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
    #[inline(always)]
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
                if same_point(&self.vertices[i], &p) {
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

    /// Empties the table for about `expected` vertices, keeping its slots when they are the size
    /// [`VertexTable::with_capacity`] would give (a reader welding chunk after chunk).
    pub fn clear(&mut self, expected: usize) {
        let size = (2 * expected).max(16).next_power_of_two();
        self.vertices.clear();
        self.vertices.reserve(expected);
        if self.slots.len() == size {
            self.slots.fill(0);
        } else {
            self.resize(size);
        }
    }

    /// The distinct vertices so far, in order of first appearance.
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }
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
pub(super) fn hash(b: &[u64; 3]) -> u64 {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;
    let fold = |x: u64| x ^ (x >> 32);
    let h = (fold(b[0]).wrapping_mul(K) ^ fold(b[1])).wrapping_mul(K) ^ fold(b[2]);
    // Folding the high half down before the last product mixes every bit into the high half; a
    // product's low bits still depend on the low bits alone, so the high half, well mixed, is folded
    // onto the low half (the tag and `first_copies`' slot) after it.
    let h = (h ^ (h >> 29)).wrapping_mul(K);
    h ^ (h >> 32)
}

/// Whether two points have exactly the same bits, compared coordinate by coordinate. As arrays
/// (`v.map(f64::to_bits) == bits`) the compare read `bits` back from the stack as one 16-byte and
/// one 8-byte load just after three 8-byte stores, which stalled: `VertexTable::insert` spent
/// about two thirds of its samples there (`perf annotate`, a 1.3 M-face binary STL, one thread).
#[inline(always)]
pub(super) fn same_point(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits() && a[2].to_bits() == b[2].to_bits()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::Polygons;
    use crate::mesh::weld::exact;

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
        // The 37 distinct points and the two of the line above.
        assert_eq!(t.into_vertices().len(), 39);
        let w = exact(&[[-0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], &Polygons::new());
        assert_eq!(w.vertices, vec![[0.0, 0.0, 0.0]]);
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
        type Grid = (&'static str, fn(usize) -> f64);
        let side = 64usize;
        let bits = 18; // 2^18 = 64^3 slots
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
}
