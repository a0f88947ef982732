//! Error-free arithmetic for the kernels: compensated accumulators, two-sum, two-product and
//! the accurate triple product of ill-conditioned triangles.

use super::triangles::LANES;
use super::Summation;

/// Ten accumulators, summed either plainly or with compensation.
#[derive(Debug, Clone, Copy)]
pub(super) struct Accumulator {
    sum: [f64; 10],
    comp: [f64; 10],
    block: [f64; 10],
    in_block: u32,
    summation: Summation,
}

/// Faces per block before the block total is folded into the compensated sum.
pub(super) const BLOCK: u32 = 8;

impl Accumulator {
    pub(super) fn new(summation: Summation) -> Self {
        Self {
            sum: [0.0; 10],
            comp: [0.0; 10],
            block: [0.0; 10],
            in_block: 0,
            summation,
        }
    }

    #[cfg(any(test, feature = "internals"))]
    #[inline(always)]
    pub(super) fn add(&mut self, x: &[f64; 10]) {
        match self.summation {
            #[cfg(any(test, feature = "internals"))]
            Summation::Plain => {
                for k in 0..10 {
                    self.sum[k] += x[k];
                }
            }
            Summation::Compensated => {
                for k in 0..10 {
                    self.block[k] += x[k];
                }
                self.in_block += 1;
                if self.in_block == BLOCK {
                    self.flush();
                }
            }
        }
    }

    /// Adds the first `len` lanes of a batch, lane by lane: the same additions in the same order as
    /// `len` calls of [`Accumulator::add`]. A batch never straddles a block (it is one).
    #[inline(always)]
    pub(super) fn add_batch(&mut self, t: &[[f64; LANES]; 10], len: usize) {
        match self.summation {
            #[cfg(any(test, feature = "internals"))]
            Summation::Plain => {
                for k in 0..10 {
                    let mut s = self.sum[k];
                    for x in &t[k][..len] {
                        s += x;
                    }
                    self.sum[k] = s;
                }
            }
            Summation::Compensated => {
                for k in 0..10 {
                    let mut s = self.block[k];
                    for x in &t[k][..len] {
                        s += x;
                    }
                    self.block[k] = s;
                }
                self.in_block += len as u32;
                if self.in_block == BLOCK {
                    self.flush();
                }
            }
        }
    }

    #[inline(always)]
    fn flush(&mut self) {
        for k in 0..10 {
            let (s, e) = two_sum(self.sum[k], self.block[k]);
            self.sum[k] = s;
            self.comp[k] += e;
            self.block[k] = 0.0;
        }
        self.in_block = 0;
    }

    /// The sums as double-doubles `(hi, lo)`.
    pub(super) fn total(mut self) -> ([f64; 10], [f64; 10]) {
        self.flush();
        let mut hi = [0.0; 10];
        let mut lo = [0.0; 10];
        for k in 0..10 {
            let (h, l) = two_sum(self.sum[k], self.comp[k]);
            hi[k] = h;
            lo[k] = l;
        }
        (hi, lo)
    }
}

/// Knuth's two-sum: `s + e == a + b` exactly, `s = fl(a + b)`.
#[inline(always)]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Exact product: `p + e == a * b` (barring overflow and underflow), with `mul_add` where the build
/// has FMA and Dekker's `TwoProduct` otherwise (see [`two_prod_in`]).
#[inline(always)]
pub(crate) fn two_prod(a: f64, b: f64) -> (f64, f64) {
    two_prod_in::<{ cfg!(target_feature = "fma") }>(a, b)
}

/// Exact product: `p + e == a * b` (barring overflow and underflow); `FMA`: the code runs where
/// hardware FMA is enabled (the build, or the x86-64-v3 kernel of [`run_kernel`]).
///
/// Without FMA, Dekker's `TwoProduct` with Veltkamp's splitting instead of `mul_add`: on baseline
/// x86-64 (no `fma` in `rustc --print cfg`) `mul_add` is a call into libm that blocks vectorisation
/// of the accurate-face path (figures: docs/benchmarks.md, "Figures behind choices in the code").
/// Both give the same `e`: the product's rounding error is representable and each computes it
/// exactly, so the results are bit for bit those of the FMA version, unless a split overflows (|a|
/// or |b| above ~2^996) or a partial product underflows (|a·b| below ~2^-969), far outside what a
/// mesh's coordinates relative to its centre produce.
#[inline(always)]
pub(super) fn two_prod_in<const FMA: bool>(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    if FMA {
        (p, a.mul_add(b, -p))
    } else {
        let (ah, al) = split(a);
        let (bh, bl) = split(b);
        (p, al * bl - (((p - ah * bh) - al * bh) - ah * bl))
    }
}

/// Veltkamp's splitting: `hi + lo == a` exactly, each half with at most 26 significant bits, so
/// products of halves are exact.
#[inline(always)]
fn split(a: f64) -> (f64, f64) {
    // 2^27 + 1.
    let t = 134_217_729.0 * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `a·(b×c) = Σ sign · a_i b_j c_k` over the six permutations `(i, j, k, sign)`.
pub(super) const TRIPLE_TERMS: [(usize, usize, usize, f64); 6] = [
    (0, 1, 2, 1.0),
    (0, 2, 1, -1.0),
    (1, 2, 0, 1.0),
    (1, 0, 2, -1.0),
    (2, 0, 1, 1.0),
    (2, 1, 0, -1.0),
];

/// Error-free-transformation evaluation of `a · (b × c)`, accurate to a few ulps of the result
/// whatever the cancellation (each triple product is expanded exactly to three terms, then summed
/// with compensation). The reference for the lane-wise [`Batch::accurate_triples`].
#[cfg(test)]
pub(super) fn accurate_triple(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    let mut q = [0.0; 6];
    let mut small = 0.0;
    for (t, &(i, j, k, sign)) in TRIPLE_TERMS.iter().enumerate() {
        let (p, pe) = two_prod(b[j], c[k]);
        let (qq, qe) = two_prod(a[i], p);
        q[t] = sign * qq;
        // The error terms, of order eps relative to the triple products.
        small += sign * qe + sign * (a[i] * pe);
    }
    let (s01, e01) = two_sum(q[0], q[1]);
    let (s23, e23) = two_sum(q[2], q[3]);
    let (s45, e45) = two_sum(q[4], q[5]);
    let (s03, e03) = two_sum(s01, s23);
    let (s, e) = two_sum(s03, s45);
    s + (((e01 + e23) + (e45 + e03) + e) + small)
}
