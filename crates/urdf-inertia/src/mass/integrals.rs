//! The ten volume integrals of a closed polyhedron (Mirtich 1996, equations 18–27).
//!
//! Two kernels compute them in one walk over the boundary:
//!
//! * [`mirtich_polygons`] is the paper's algorithm (Figures 4–6): each face a planar polygon, projected
//!   onto the coordinate plane that maximises `|n_γ|`, reduced by Green's theorem to line integrals.
//! * [`triangle_integrals`] is the triangle-specialised path: the same divergence-theorem integrals, written
//!   per triangle as the signed tetrahedron it spans with the reference point. It never divides, so it has
//!   no projection choice to make. Ill-conditioned triangles (whose plane passes close to the reference
//!   point relative to their size, as in thin plates and needles) are re-evaluated with error-free
//!   products, so their tiny signed volume keeps its digits.
//!
//! Both integrate about a caller-chosen reference point `c` (vertices are shifted by `-c` on the fly), and
//! both sum face contributions in blocks whose totals go into compensated (two-sum) accumulators.
//! [`IntegrationOptions::paper`] reproduces the paper exactly: origin reference, plain summation.

use std::ops::{Index, IndexMut};

/// The ten integrals `T1, Tx, Ty, Tz, Tx², Ty², Tz², Txy, Tyz, Tzx` of a polyhedron about a reference point.
///
/// All are integrals of monomials of the coordinates relative to [`VolumeIntegrals::reference`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeIntegrals {
    /// ∫ 1 dV: the (signed) volume.
    pub t1: f64,
    /// ∫ x dV, ∫ y dV, ∫ z dV.
    pub t: [f64; 3],
    /// ∫ x² dV, ∫ y² dV, ∫ z² dV.
    pub t2: [f64; 3],
    /// ∫ xy dV, ∫ yz dV, ∫ zx dV.
    pub tp: [f64; 3],
    /// The point the coordinates were measured from.
    pub reference: [f64; 3],
    /// Low-order parts, in the order of [`VolumeIntegrals::to_array`]: each integral is the
    /// double-double `hi + low` (all zero when summed plainly). They let the central tensor be rounded
    /// once at the end.
    pub low: [f64; 10],
}

/// How sums over faces are accumulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Summation {
    /// One running sum per integral, as in the paper (the tests' and the accuracy report's
    /// reference).
    #[cfg(any(test, feature = "internals"))]
    Plain,
    /// Blocks of faces summed plainly, block totals added with an error-free two-sum (Neumaier style).
    Compensated,
}

/// Where the integrals are measured from and how they are summed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegrationOptions {
    /// `None`: the centre of the vertices' bounding box (exact shifts for far-away meshes).
    pub reference: Option<[f64; 3]>,
    pub summation: Summation,
    /// Re-evaluate ill-conditioned triangles with error-free products (triangle kernel only).
    pub accurate_faces: bool,
}

impl IntegrationOptions {
    /// The paper as published: integrals about the origin, plain running sums.
    #[cfg(any(test, feature = "internals"))]
    pub const fn paper() -> Self {
        Self {
            reference: Some([0.0; 3]),
            summation: Summation::Plain,
            accurate_faces: false,
        }
    }

    /// The reference point for `vertices`: the given one, or the bounding-box centre.
    pub fn reference_for(&self, vertices: &[[f64; 3]]) -> [f64; 3] {
        self.reference
            .unwrap_or_else(|| bounding_box_centre(vertices))
    }

    /// What urdf-inertia uses: about the bounding-box centre, compensated sums, accurate thin faces.
    pub const fn accurate() -> Self {
        Self {
            reference: None,
            summation: Summation::Compensated,
            accurate_faces: true,
        }
    }
}

impl Default for IntegrationOptions {
    fn default() -> Self {
        Self::accurate()
    }
}

/// A face list in compressed form: face `i` is `indices[starts[i]..starts[i + 1]]`.
///
/// Faces are planar polygons with their vertices counter-clockwise seen from outside.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Polygons {
    pub indices: Vec<u32>,
    pub starts: Vec<u32>,
}

impl Polygons {
    /// An empty face list.
    pub fn new() -> Self {
        Self {
            indices: Vec::new(),
            starts: vec![0],
        }
    }

    /// Faces all given as triangles.
    pub fn from_triangles(tris: &[[u32; 3]]) -> Self {
        let indices: Vec<u32> = tris.iter().flatten().copied().collect();
        let starts = (0..=tris.len() as u32).map(|i| 3 * i).collect();
        Self { indices, starts }
    }

    /// Appends one face.
    pub fn push(&mut self, face: &[u32]) {
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        self.indices.extend_from_slice(face);
        self.starts.push(self.indices.len() as u32);
    }

    /// Number of faces.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The vertex indices of face `i`.
    pub fn face(&self, i: usize) -> &[u32] {
        &self.indices[self.starts[i] as usize..self.starts[i + 1] as usize]
    }

    /// Iterates over the faces.
    pub fn iter(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.len()).map(move |i| self.face(i))
    }

    /// Reverses the orientation of face `i`.
    pub fn reverse_face(&mut self, i: usize) {
        let (a, b) = (self.starts[i] as usize, self.starts[i + 1] as usize);
        self.indices[a..b].reverse();
    }

    /// Whether every face is a triangle.
    pub fn all_triangles(&self) -> bool {
        self.starts.windows(2).all(|w| w[1] - w[0] == 3)
    }

    /// Fan-triangulates every face (for point-in-solid tests; the integrals take polygons directly).
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.indices.len());
        for f in self.iter() {
            for k in 1..f.len().saturating_sub(1) {
                out.push([f[0], f[k], f[k + 1]]);
            }
        }
        out
    }
}

/// The centre of the axis-aligned bounding box of `vertices` (the origin for an empty slice).
pub fn bounding_box_centre(vertices: &[[f64; 3]]) -> [f64; 3] {
    if vertices.is_empty() {
        return [0.0; 3];
    }
    let mut lo = vertices[0];
    let mut hi = vertices[0];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    // lo + (hi - lo)/2 stays inside [lo, hi] without overflow; the centre only has to be near the mesh.
    [0, 1, 2].map(|k| lo[k] + 0.5 * (hi[k] - lo[k]))
}

/// Ten accumulators, summed either plainly or with compensation.
#[derive(Debug, Clone, Copy)]
struct Accumulator {
    sum: [f64; 10],
    comp: [f64; 10],
    block: [f64; 10],
    in_block: u32,
    summation: Summation,
}

/// Faces per block before the block total is folded into the compensated sum.
const BLOCK: u32 = 8;

impl Accumulator {
    fn new(summation: Summation) -> Self {
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
    fn add(&mut self, x: &[f64; 10]) {
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
    fn add_batch(&mut self, t: &[[f64; LANES]; 10], len: usize) {
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
    fn total(mut self) -> ([f64; 10], [f64; 10]) {
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
/// has FMA and Dekker's TwoProduct otherwise (see [`two_prod_in`]).
#[inline(always)]
pub(crate) fn two_prod(a: f64, b: f64) -> (f64, f64) {
    two_prod_in::<{ cfg!(target_feature = "fma") }>(a, b)
}

/// Exact product: `p + e == a * b` (barring overflow and underflow); `FMA`: the code runs where
/// hardware FMA is enabled (the build, or the x86-64-v3 kernel of [`run_kernel`]).
///
/// Without FMA, Dekker's TwoProduct with Veltkamp's splitting instead of `mul_add`: on baseline x86-64
/// (no `fma` in `rustc --print cfg`) `mul_add` is a call into libm that blocks vectorisation of the
/// accurate-face path (with the lane-wise evaluation: ~53 → ~28 ns/face at 4k–67k faces, bench
/// kernel-accurate on a shared machine; callgrind 621 → 473 instructions/face). Both give the same `e`:
/// the product's rounding error is representable and each computes it exactly, so the results are bit
/// for bit those of the FMA version, unless a split overflows (|a| or |b| above ~2^996) or a partial
/// product underflows (|a·b| below ~2^-969), far outside what a mesh's coordinates relative to its
/// centre produce.
#[inline(always)]
fn two_prod_in<const FMA: bool>(a: f64, b: f64) -> (f64, f64) {
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
const TRIPLE_TERMS: [(usize, usize, usize, f64); 6] = [
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
fn accurate_triple(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
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

/// Scales raw double-double accumulations into the integrals (the divisions of Figure 4 and of the
/// tetrahedron form), dividing the double-double by small integers without losing its low part.
fn finish(raw: ([f64; 10], [f64; 10]), reference: [f64; 3], divisors: [f64; 4]) -> VolumeIntegrals {
    let mut hi = [0.0; 10];
    let mut low = [0.0; 10];
    for k in 0..10 {
        let div = divisors[match k {
            0 => 0,
            1..=3 => 1,
            4..=6 => 2,
            _ => 3,
        }];
        let q = raw.0[k] / div;
        // The remainder of hi/div is exact (fma), so hi + lo = div · (q + low) to about eps².
        let rem = (-q).mul_add(div, raw.0[k]);
        let l = (rem + raw.1[k]) / div;
        let (h, e) = two_sum(q, l);
        hi[k] = h;
        low[k] = e;
    }
    VolumeIntegrals {
        t1: hi[0],
        t: [hi[1], hi[2], hi[3]],
        t2: [hi[4], hi[5], hi[6]],
        tp: [hi[7], hi[8], hi[9]],
        reference,
        low,
    }
}

#[inline(always)]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Triangle kernel: the integrals of the solid bounded by `triangles`, about the options' reference point.
///
/// Each triangle `(a, b, c)` (relative to the reference) contributes the signed tetrahedron it spans with
/// the reference point: with `d = a · ((b − a) × (c − a))` (six times the signed volume) and `S`, `Q` the
/// sums of the coordinates and of their pairwise products over `a, b, c`,
/// `∫1 = d/6`, `∫x = d·Sx/24`, `∫x² = d·(Qxx + Sx²)/120`, `∫xy = d·(Qxy + Sx·Sy)/120`.
/// Indices must be in range (the mesh layer checks them).
pub fn triangle_integrals(
    vertices: &[[f64; 3]],
    triangles: &[[u32; 3]],
    options: &IntegrationOptions,
) -> VolumeIntegrals {
    let reference = options.reference_for(vertices);
    // Shift every vertex once (a vertex is shared by about six triangles).
    let shifted: Vec<[f64; 3]> = vertices.iter().map(|&v| sub(v, reference)).collect();
    let raw = run_kernel(TriangleLoop {
        shifted: &shifted,
        triangles,
        options,
    });
    finish(raw, reference, [6.0, 24.0, 120.0, 120.0])
}

/// Double-double sums of the ten integrals, before [`finish`].
type RawSums = ([f64; 10], [f64; 10]);

/// A loop over triangles feeding [`Batch`]es, compiled for the build's CPU and for x86-64-v3.
trait KernelLoop {
    /// The sums; `FMA`: compiled where hardware FMA is enabled (selects [`two_prod_in`]).
    fn sums<const FMA: bool>(self) -> RawSums;
}

/// Runs a kernel loop in the best instruction set the CPU has, detected at run time (the binary
/// targets baseline x86-64): AVX2 (4 lanes instead of SSE2's 2) and FMA through pulp's safe
/// dispatch. Every path performs the same IEEE operations in the same order (no contraction into
/// FMA; the exact products are exact either way), so the bits do not depend on the CPU
/// (`kernel_paths_agree` checks it). Measured with callgrind (instructions per face, one core,
/// the SSE2 build against this dispatch): triangle kernel 184 → 121, polygon fan 225 → 157,
/// kernel-accurate plate 473 → 396; criterion on a loaded shared 2-core EPYC: kernel/ours ~15 → ~12
/// ns/face, the thin plate ~28–42 → ~33–39 ns/face (noise of ±30%).
#[inline(always)]
fn run_kernel<L: KernelLoop>(kernel: L) -> RawSums {
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = pulp::x86::V3::try_new() {
        return v3.vectorize(WithFma(kernel));
    }
    kernel.sums::<{ cfg!(target_feature = "fma") }>()
}

/// A kernel loop to run inside pulp's x86-64-v3 context (AVX2 and FMA enabled).
struct WithFma<L>(L);

impl<L: KernelLoop> pulp::NullaryFnOnce for WithFma<L> {
    type Output = RawSums;

    // Inlined into pulp's `#[target_feature]` function, so that the whole loop is compiled with it.
    #[inline(always)]
    fn call(self) -> RawSums {
        self.0.sums::<true>()
    }
}

/// [`triangle_integrals`]'s loop over indexed triangles of shifted vertices.
struct TriangleLoop<'a> {
    shifted: &'a [[f64; 3]],
    triangles: &'a [[u32; 3]],
    options: &'a IntegrationOptions,
}

impl KernelLoop for TriangleLoop<'_> {
    #[inline(always)]
    fn sums<const FMA: bool>(self) -> RawSums {
        let (shifted, accurate) = (self.shifted, self.options.accurate_faces);
        let mut acc = Accumulator::new(self.options.summation);
        let mut batch = Batch::new();
        for t in self.triangles {
            batch.add::<FMA>(
                shifted[t[0] as usize],
                shifted[t[1] as usize],
                shifted[t[2] as usize],
                &mut acc,
                accurate,
            );
        }
        batch.finish::<FMA>(acc, accurate)
    }
}

/// Triangles gathered for one block of the compensated sum, as lanes (structure of arrays) so that the
/// per-triangle arithmetic runs on all of them at once and the compiler vectorises it. The lanes are
/// summed in order, so the results are bit for bit those of one triangle at a time.
struct Batch {
    /// Corner coordinates relative to the reference point: `p[corner][axis][lane]`.
    p: [[[f64; LANES]; 3]; 3],
    len: usize,
}

/// Triangles per batch: the compensated block.
const LANES: usize = BLOCK as usize;

impl Batch {
    fn new() -> Self {
        Batch {
            p: [[[0.0; LANES]; 3]; 3],
            len: 0,
        }
    }

    #[inline(always)]
    fn push(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3]) {
        let l = self.len;
        for k in 0..3 {
            self.p[0][k][l] = a[k];
            self.p[1][k][l] = b[k];
            self.p[2][k][l] = c[k];
        }
        self.len += 1;
    }

    /// Adds a triangle; a full batch goes into `acc`.
    #[inline(always)]
    fn add<const FMA: bool>(
        &mut self,
        a: [f64; 3],
        b: [f64; 3],
        c: [f64; 3],
        acc: &mut Accumulator,
        accurate: bool,
    ) {
        self.push(a, b, c);
        if self.len == LANES {
            acc.add_batch(&self.terms::<FMA>(accurate), LANES);
            self.len = 0;
        }
    }

    /// The sums, with the triangles still in the batch.
    #[inline(always)]
    fn finish<const FMA: bool>(&self, mut acc: Accumulator, accurate: bool) -> RawSums {
        if self.len > 0 {
            acc.add_batch(&self.terms::<FMA>(accurate), self.len);
        }
        acc.total()
    }

    /// [`accurate_triple`] for every lane, written lane-wise so that it vectorises: the same
    /// operations per lane in the same order, so the same bits as one triangle at a time.
    #[inline(always)]
    fn accurate_triples<const FMA: bool>(&self) -> [f64; LANES] {
        let [a, b, c] = &self.p;
        // The six leading products q cancel: they are summed with error-free two-sums, pairwise
        // (depth 3 instead of a chain of 6), and every rounding error is kept in `comp` (Sum2 of
        // Ogita, Rump and Oishi, in a tree). Each product's own error terms (q's rounding, and a_i
        // times the rounding of b_j·c_k) are below eps·|q|: summed plainly they add an error of order
        // 12·eps²·Σ|q|, the size of Sum2's own second-order term. Against the 18 two-sums in a chain
        // before: the same bound, and on the 66,560-face thin plate of bench kernel-accurate (one
        // thread) 400 → 153 instructions per face (callgrind; the fast path takes 117) and 27 → 12 ns
        // per face (fast path 8–10 ns, a shared machine).
        let mut q = [[0.0; LANES]; 6];
        let mut small = [0.0; LANES];
        for (t, &(i, j, k, sign)) in TRIPLE_TERMS.iter().enumerate() {
            for l in 0..LANES {
                let (p, pe) = two_prod_in::<FMA>(b[j][l], c[k][l]);
                let (qq, qe) = two_prod_in::<FMA>(a[i][l], p);
                q[t][l] = sign * qq;
                small[l] += sign * qe + sign * (a[i][l] * pe);
            }
        }
        let mut out = [0.0; LANES];
        for l in 0..LANES {
            let (s01, e01) = two_sum(q[0][l], q[1][l]);
            let (s23, e23) = two_sum(q[2][l], q[3][l]);
            let (s45, e45) = two_sum(q[4][l], q[5][l]);
            let (s03, e03) = two_sum(s01, s23);
            let (s, e) = two_sum(s03, s45);
            let comp = (e01 + e23) + (e45 + e03) + e;
            out[l] = s + (comp + small[l]);
        }
        out
    }

    /// The raw contributions of the batch's triangles, `terms[integral][lane]` (lanes past `len` are
    /// zero triangles and contribute 0).
    #[inline(always)]
    fn terms<const FMA: bool>(&self, accurate: bool) -> [[f64; LANES]; 10] {
        let [a, b, c] = &self.p;
        let mut d = [0.0; LANES];
        let mut slow = [false; LANES];
        for l in 0..LANES {
            let e1 = [b[0][l] - a[0][l], b[1][l] - a[1][l], b[2][l] - a[2][l]];
            let e2 = [c[0][l] - a[0][l], c[1][l] - a[1][l], c[2][l] - a[2][l]];
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            d[l] = a[0][l] * n[0] + a[1][l] * n[1] + a[2][l] * n[2];
            // The rounding error of d is about eps·|a|·|e1|·|e2|: large against d when the plane
            // passes near the reference point (a thin plate's big faces) or when the edges are nearly
            // parallel (its long side faces, a needle). Then d is re-evaluated from a, b, c with
            // error-free products. 2^-12 keeps the plain evaluation within ~4096 eps of d, near-ulp
            // for the sum; well-shaped faces of a mesh around its centre never take the slow path.
            let aa = a[0][l] * a[0][l] + a[1][l] * a[1][l] + a[2][l] * a[2][l];
            let ee = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2])
                * (e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]);
            slow[l] = d[l] * d[l] * 16_777_216.0 < aa * ee;
        }
        if accurate && slow[..self.len].contains(&true) {
            // All lanes at once, then select: branch-free lanes vectorise (see `accurate_triples`).
            let exact = self.accurate_triples::<FMA>();
            for l in 0..self.len {
                if slow[l] {
                    d[l] = exact[l];
                }
            }
        }
        let mut out = [[0.0; LANES]; 10];
        for l in 0..LANES {
            let s = [
                a[0][l] + b[0][l] + c[0][l],
                a[1][l] + b[1][l] + c[1][l],
                a[2][l] + b[2][l] + c[2][l],
            ];
            let q = |i: usize, j: usize| a[i][l] * a[j][l] + b[i][l] * b[j][l] + c[i][l] * c[j][l];
            let dl = d[l];
            out[0][l] = dl;
            out[1][l] = dl * s[0];
            out[2][l] = dl * s[1];
            out[3][l] = dl * s[2];
            out[4][l] = dl * (q(0, 0) + s[0] * s[0]);
            out[5][l] = dl * (q(1, 1) + s[1] * s[1]);
            out[6][l] = dl * (q(2, 2) + s[2] * s[2]);
            out[7][l] = dl * (q(0, 1) + s[0] * s[1]);
            out[8][l] = dl * (q(1, 2) + s[1] * s[2]);
            out[9][l] = dl * (q(2, 0) + s[2] * s[0]);
        }
        out
    }
}

/// The paper's algorithm (Figures 4–6) over planar polygons, about the options' reference point.
///
/// For each face the projection `α-β-γ` is the right-handed permutation of `x-y-z` maximising `|n_γ|`.
/// The face normal is Newell's (the exact area vector of the polygon's projections), so a slightly
/// non-planar polygon gets the best-fit plane; a zero-area face contributes nothing.
/// Indices must be in range (the mesh layer checks them).
#[cfg(any(test, feature = "internals"))]
pub fn mirtich_polygons(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    options: &IntegrationOptions,
) -> VolumeIntegrals {
    let reference = options.reference_for(vertices);
    let mut acc = Accumulator::new(options.summation);
    let mut local: Vec<[f64; 3]> = Vec::with_capacity(8);
    for face in faces.iter() {
        if face.len() < 3 {
            continue;
        }
        local.clear();
        local.extend(face.iter().map(|&i| sub(vertices[i as usize], reference)));
        if let Some(terms) = polygon_terms(&local) {
            acc.add(&terms);
        }
    }
    finish(acc.total(), reference, [1.0, 2.0, 3.0, 2.0])
}

/// A face's unit normal from Newell's formula (robust for non-planar polygons), or `None` for zero area.
#[cfg(any(test, feature = "internals"))]
fn unit_normal(p: &[[f64; 3]]) -> Option<[f64; 3]> {
    // Newell's normal: twice the vector area.
    let mut n = [0.0f64; 3];
    for i in 0..p.len() {
        let (u, v) = (p[i], p[(i + 1) % p.len()]);
        n[0] += (u[1] - v[1]) * (u[2] + v[2]);
        n[1] += (u[2] - v[2]) * (u[0] + v[0]);
        n[2] += (u[0] - v[0]) * (u[1] + v[1]);
    }
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len == 0.0 || !len.is_finite() {
        return None;
    }
    Some([n[0] / len, n[1] / len, n[2] / len])
}

/// Mirtich's (α, β, γ): γ is the axis of the largest normal component (the best-conditioned
/// projection); α, β follow cyclically (right-handed).
#[cfg(any(test, feature = "internals"))]
fn projection_axes(n: &[f64; 3]) -> (usize, usize, usize) {
    if n[0].abs() > n[1].abs() && n[0].abs() > n[2].abs() {
        (1, 2, 0)
    } else if n[1].abs() > n[2].abs() {
        (2, 0, 1)
    } else {
        (0, 1, 2)
    }
}

/// One face's contribution to the (not yet halved/thirded) sums of Figure 4, or `None` for zero area.
#[cfg(any(test, feature = "internals"))]
fn polygon_terms(p: &[[f64; 3]]) -> Option<[f64; 10]> {
    let n = unit_normal(p)?;
    let (ax, bx, cx) = projection_axes(&n);
    let pr = projection_integrals(p, ax, bx);
    // w = -n·p for a point on the face; the mean of the vertices is the best-fit choice.
    let inv = 1.0 / p.len() as f64;
    let mut w = 0.0;
    for v in p {
        w -= (n[0] * v[0] + n[1] * v[1] + n[2] * v[2]) * inv;
    }
    let (na, nb, nc) = (n[ax], n[bx], n[cx]);
    let k1 = 1.0 / nc;
    let k2 = k1 * k1;
    let k3 = k2 * k1;
    let k4 = k3 * k1;
    let [p1, pa, pb, paa, pab, pbb, paaa, paab, pabb, pbbb] = pr;

    let fa = k1 * pa;
    let fb = k1 * pb;
    let fc = -k2 * (na * pa + nb * pb + w * p1);
    let faa = k1 * paa;
    let fbb = k1 * pbb;
    let fcc = k3
        * (na * na * paa
            + 2.0 * na * nb * pab
            + nb * nb * pbb
            + 2.0 * na * w * pa
            + 2.0 * nb * w * pb
            + w * w * p1);
    let faaa = k1 * paaa;
    let fbbb = k1 * pbbb;
    let fccc = -k4
        * (na * na * na * paaa
            + 3.0 * na * na * nb * paab
            + 3.0 * na * nb * nb * pabb
            + nb * nb * nb * pbbb
            + 3.0 * na * na * w * paa
            + 6.0 * na * nb * w * pab
            + 3.0 * nb * nb * w * pbb
            + 3.0 * na * w * w * pa
            + 3.0 * nb * w * w * pb
            + w * w * w * p1);
    let faab = k1 * paab;
    let fbbc = -k2 * (na * pabb + nb * pbbb + w * pbb);
    let fcca = k3
        * (na * na * paaa
            + 2.0 * na * nb * paab
            + nb * nb * pabb
            + 2.0 * na * w * paa
            + 2.0 * nb * w * pab
            + w * w * pa);

    let mut out = [0.0; 10];
    // T1 from whichever of α, β, γ is x (Figure 4).
    out[0] = if ax == 0 {
        na * fa
    } else if bx == 0 {
        nb * fb
    } else {
        nc * fc
    };
    out[1 + ax] = na * faa;
    out[1 + bx] = nb * fbb;
    out[1 + cx] = nc * fcc;
    out[4 + ax] = na * faaa;
    out[4 + bx] = nb * fbbb;
    out[4 + cx] = nc * fccc;
    // Products: index 7 + k holds the product (k, k+1): xy, yz, zx. The cyclic choice of (α, β, γ)
    // makes αβ, βγ, γα exactly those slots.
    out[7 + ax] = na * faab;
    out[7 + bx] = nb * fbbc;
    out[7 + cx] = nc * fcca;
    Some(out)
}

/// Figure 6: the integrals over the face's projection onto the α-β plane, as
/// `[π1, πα, πβ, πα², παβ, πβ², πα³, πα²β, παβ², πβ³]`.
#[cfg(any(test, feature = "internals"))]
fn projection_integrals(p: &[[f64; 3]], ax: usize, bx: usize) -> [f64; 10] {
    let (mut p1, mut pa, mut pb, mut paa, mut pab, mut pbb) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut paaa, mut paab, mut pabb, mut pbbb) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let a0 = p[i][ax];
        let b0 = p[i][bx];
        let a1 = p[(i + 1) % p.len()][ax];
        let b1 = p[(i + 1) % p.len()][bx];
        let da = a1 - a0;
        let db = b1 - b0;
        let a0_2 = a0 * a0;
        let a0_3 = a0_2 * a0;
        let a0_4 = a0_3 * a0;
        let b0_2 = b0 * b0;
        let b0_3 = b0_2 * b0;
        let b0_4 = b0_3 * b0;
        let a1_2 = a1 * a1;
        let a1_3 = a1_2 * a1;
        let b1_2 = b1 * b1;
        let b1_3 = b1_2 * b1;

        let c1 = a1 + a0;
        let ca = a1 * c1 + a0_2;
        let caa = a1 * ca + a0_3;
        let caaa = a1 * caa + a0_4;
        let cb = b1 * (b1 + b0) + b0_2;
        let cbb = b1 * cb + b0_3;
        let cbbb = b1 * cbb + b0_4;
        let cab = 3.0 * a1_2 + 2.0 * a1 * a0 + a0_2;
        let kab = a1_2 + 2.0 * a1 * a0 + 3.0 * a0_2;
        let caab = a0 * cab + 4.0 * a1_3;
        let kaab = a1 * kab + 4.0 * a0_3;
        let cabb = 4.0 * b1_3 + 3.0 * b1_2 * b0 + 2.0 * b1 * b0_2 + b0_3;
        let kabb = b1_3 + 2.0 * b1_2 * b0 + 3.0 * b1 * b0_2 + 4.0 * b0_3;

        p1 += db * c1;
        pa += db * ca;
        paa += db * caa;
        paaa += db * caaa;
        pb += da * cb;
        pbb += da * cbb;
        pbbb += da * cbbb;
        pab += db * (b1 * cab + b0 * kab);
        paab += db * (b1 * caab + b0 * kaab);
        pabb += da * (a1 * cabb + a0 * kabb);
    }
    [
        p1 / 2.0,
        pa / 6.0,
        -pb / 6.0,
        paa / 12.0,
        pab / 24.0,
        -pbb / 12.0,
        paaa / 20.0,
        paab / 60.0,
        -pabb / 60.0,
        -pbbb / 20.0,
    ]
}

/// The integrals of a polygon mesh with any mix of face sizes, as urdf-inertia computes them.
///
/// Each polygon is integrated as the fan of triangles from its first vertex through the triangle kernel:
/// for a planar polygon that is the same solid as Mirtich's projection, for a slightly non-planar one
/// (common in OBJ quads) it is a well-defined surface, and it avoids the expansion of γ³ on slanted faces
/// that costs Mirtich's formulas a few ulps (4.5e-15 on the paper's own tetrahedron, see the tests).
pub fn volume_integrals(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    options: &IntegrationOptions,
) -> VolumeIntegrals {
    let reference = options.reference_for(vertices);
    let n = faces.len();
    let raw = if options.summation == Summation::Compensated && n > CHUNK {
        // Fixed chunks, whatever the number of threads, each summed with compensation and combined
        // in chunk order as double-doubles: the same bits for any thread count.
        use rayon::prelude::*;
        let chunks: Vec<([f64; 10], [f64; 10])> = crate::threads::install(|| {
            (0..n.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let range = c * CHUNK..((c + 1) * CHUNK).min(n);
                    fan_sums(vertices, range.map(|i| faces.face(i)), reference, options)
                })
                .collect()
        });
        let mut hi = [0.0; 10];
        let mut lo = [0.0; 10];
        for (h, l) in chunks {
            for k in 0..10 {
                let (s, e) = two_sum(hi[k], h[k]);
                hi[k] = s;
                lo[k] += e + l[k];
            }
        }
        (hi, lo)
    } else {
        fan_sums(vertices, faces.iter(), reference, options)
    };
    finish(raw, reference, [6.0, 24.0, 120.0, 120.0])
}

/// Faces per chunk of a parallel integration (meshes up to this size are summed in one sequence).
const CHUNK: usize = 1 << 15;

/// The sums of [`volume_integrals`] over `faces`, each fanned into triangles (as double-doubles).
fn fan_sums<'a>(
    vertices: &[[f64; 3]],
    faces: impl Iterator<Item = &'a [u32]>,
    reference: [f64; 3],
    options: &IntegrationOptions,
) -> RawSums {
    run_kernel(FanLoop {
        vertices,
        faces,
        reference,
        options,
    })
}

/// [`fan_sums`]'s loop: polygons fanned into triangles, vertices shifted on the fly.
struct FanLoop<'a, I> {
    vertices: &'a [[f64; 3]],
    faces: I,
    reference: [f64; 3],
    options: &'a IntegrationOptions,
}

impl<'f, I: Iterator<Item = &'f [u32]>> KernelLoop for FanLoop<'_, I> {
    #[inline(always)]
    fn sums<const FMA: bool>(self) -> RawSums {
        let (vertices, reference) = (self.vertices, self.reference);
        let accurate = self.options.accurate_faces;
        let mut acc = Accumulator::new(self.options.summation);
        let mut batch = Batch::new();
        for face in self.faces {
            if face.len() < 3 {
                continue;
            }
            let a = sub(vertices[face[0] as usize], reference);
            for k in 1..face.len() - 1 {
                let b = sub(vertices[face[k] as usize], reference);
                let c = sub(vertices[face[k + 1] as usize], reference);
                batch.add::<FMA>(a, b, c, &mut acc, accurate);
            }
        }
        batch.finish::<FMA>(acc, accurate)
    }
}

impl VolumeIntegrals {
    /// From the paper-ordered array of high parts and their low parts.
    pub fn from_arrays(hi: [f64; 10], low: [f64; 10], reference: [f64; 3]) -> Self {
        VolumeIntegrals {
            t1: hi[0],
            t: [hi[1], hi[2], hi[3]],
            t2: [hi[4], hi[5], hi[6]],
            tp: [hi[7], hi[8], hi[9]],
            reference,
            low,
        }
    }

    /// The same integrals about another reference point `q` (exact algebra; transfer of axes).
    pub fn about(&self, q: [f64; 3]) -> VolumeIntegrals {
        // Coordinates relative to q are x' = x + δ with δ = c − q.
        let d = sub(self.reference, q);
        let hi = self.to_array();
        let me: [f64; 10] = std::array::from_fn(|k| hi[k] + self.low[k]);
        let this = VolumeIntegrals::from_arrays(me, [0.0; 10], self.reference);
        let v = this.t1;
        let t = [0, 1, 2].map(|k| this.t[k] + d[k] * v);
        let t2 = [0, 1, 2].map(|k| this.t2[k] + 2.0 * d[k] * this.t[k] + d[k] * d[k] * v);
        let tp = [0, 1, 2].map(|k| {
            let j = (k + 1) % 3;
            this.tp[k] + d[k] * this.t[j] + d[j] * this.t[k] + d[k] * d[j] * v
        });
        VolumeIntegrals {
            t1: v,
            t,
            t2,
            tp,
            reference: q,
            low: [0.0; 10],
        }
    }

    /// The integrals of the same surface wound the other way (every integral changes sign).
    pub fn negated(&self) -> VolumeIntegrals {
        VolumeIntegrals {
            t1: -self.t1,
            t: self.t.map(|x| -x),
            t2: self.t2.map(|x| -x),
            tp: self.tp.map(|x| -x),
            reference: self.reference,
            low: self.low.map(|x| -x),
        }
    }

    /// The integrals as an array in the paper's order `T1, Tx, Ty, Tz, Tx², Ty², Tz², Txy, Tyz, Tzx`.
    pub fn to_array(self) -> [f64; 10] {
        [
            self.t1, self.t[0], self.t[1], self.t[2], self.t2[0], self.t2[1], self.t2[2],
            self.tp[0], self.tp[1], self.tp[2],
        ]
    }
}

impl Index<usize> for VolumeIntegrals {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        match i {
            0 => &self.t1,
            1..=3 => &self.t[i - 1],
            4..=6 => &self.t2[i - 4],
            7..=9 => &self.tp[i - 7],
            _ => panic!("VolumeIntegrals has ten entries, index {i}"),
        }
    }
}

impl IndexMut<usize> for VolumeIntegrals {
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        match i {
            0 => &mut self.t1,
            1..=3 => &mut self.t[i - 1],
            4..=6 => &mut self.t2[i - 4],
            7..=9 => &mut self.tp[i - 7],
            _ => panic!("VolumeIntegrals has ten entries, index {i}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_quads(h: f64) -> (Vec<[f64; 3]>, Polygons) {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                [
                    if i & 1 == 0 { -h } else { h },
                    if i & 2 == 0 { -h } else { h },
                    if i & 4 == 0 { -h } else { h },
                ]
            })
            .collect();
        let mut f = Polygons::new();
        for q in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            f.push(&q);
        }
        (v, f)
    }

    #[test]
    fn paper_table1_cube() {
        let (v, f) = cube_quads(10.0);
        let at_origin = IntegrationOptions {
            reference: Some([0.0; 3]),
            ..IntegrationOptions::accurate()
        };
        for opts in [IntegrationOptions::paper(), at_origin] {
            let t = mirtich_polygons(&v, &f, &opts);
            let want = [
                8000.0,
                0.0,
                0.0,
                0.0,
                8e5 / 3.0,
                8e5 / 3.0,
                8e5 / 3.0,
                0.0,
                0.0,
                0.0,
            ];
            let fan = volume_integrals(&v, &f, &opts).about([0.0; 3]);
            for k in 0..10 {
                assert!(
                    (fan[k] - want[k]).abs() <= 1e-15 * want[k].abs().max(1.0),
                    "fan T[{k}] = {}",
                    fan[k]
                );
                assert!(
                    (t[k] - want[k]).abs() <= 1e-15 * want[k].abs().max(1.0),
                    "T[{k}] = {} want {}",
                    t[k],
                    want[k]
                );
            }
        }
    }

    #[test]
    fn paper_table1_tetrahedron() {
        let v = [
            [0.0, 0.0, 0.0],
            [5.0, 0.0, 0.0],
            [0.0, 4.0, 0.0],
            [0.0, 0.0, 3.0],
        ];
        let tris = [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let want = [10.0, 12.5, 10.0, 7.5, 25.0, 16.0, 9.0, 10.0, 6.0, 7.5];
        let polys = Polygons::from_triangles(&tris);
        let at_origin = IntegrationOptions {
            reference: Some([0.0; 3]),
            ..IntegrationOptions::accurate()
        };
        for opts in [
            IntegrationOptions::paper(),
            at_origin,
            IntegrationOptions::accurate(),
        ] {
            let a = mirtich_polygons(&v, &polys, &opts).about([0.0; 3]);
            let b = triangle_integrals(&v, &tris, &opts).about([0.0; 3]);
            // The paper's projection formulas expand γ³ on the slanted face into ten terms that cancel
            // to a few ulps (T_z² = 8.99999999999996 as published, 4.5e-15 off); the triangle kernel
            // has no such expansion and is exact here in every variant (the reason the product path
            // integrates n-gons as triangle fans, see `volume_integrals`).
            let paper_tol = 1e-14;
            for k in 0..10 {
                assert!(
                    (a[k] - want[k]).abs() <= paper_tol * want[k],
                    "mirtich T[{k}] = {} ({opts:?})",
                    a[k]
                );
                assert!(
                    (b[k] - want[k]).abs() <= 1e-15 * want[k],
                    "triangles T[{k}] = {}",
                    b[k]
                );
            }
        }
    }

    #[test]
    fn zero_area_faces_contribute_nothing() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let mut f = Polygons::new();
        f.push(&[0, 1, 2]);
        f.push(&[0, 0, 0, 1]);
        let t = mirtich_polygons(&v, &f, &IntegrationOptions::paper());
        assert_eq!(t.to_array(), [0.0; 10]);
        let t = triangle_integrals(&v, &[[0, 1, 2], [1, 1, 1]], &IntegrationOptions::accurate());
        assert_eq!(t.to_array(), [0.0; 10]);
    }

    /// Issue 14: a mesh integrated in parallel chunks gives the same bits on any number of threads.
    #[test]
    fn parallel_chunks_are_deterministic() {
        // A (non-closed, it does not matter here) grid of 2 · 200² triangles, above one chunk.
        let n = 201u32;
        let v: Vec<[f64; 3]> = (0..n * n)
            .map(|i| {
                let (x, y) = (f64::from(i % n), f64::from(i / n));
                [
                    x * 0.01 + 3.0,
                    y * 0.01 - 1.0,
                    (x * 0.3).sin() * (y * 0.2).cos(),
                ]
            })
            .collect();
        let mut tris = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let i = y * n + x;
                tris.push([i, i + 1, i + n]);
                tris.push([i + 1, i + n + 1, i + n]);
            }
        }
        let faces = Polygons::from_triangles(&tris);
        assert!(faces.len() > CHUNK);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let t = pool.install(|| volume_integrals(&v, &faces, &IntegrationOptions::accurate()));
            (t.to_array().map(f64::to_bits), t.low.map(f64::to_bits))
        };
        let one = run(1);
        assert_eq!(one, run(2));
        assert_eq!(one, run(3));
        // And the chunked sum agrees with one sequential triangle sum to round-off.
        let seq = triangle_integrals(&v, &tris, &IntegrationOptions::accurate()).to_array();
        for k in 0..10 {
            let par = f64::from_bits(one.0[k]);
            assert!(
                (par - seq[k]).abs() <= 1e-15 * seq[k].abs().max(1e-300),
                "T[{k}]"
            );
        }
    }

    #[test]
    fn accurate_triple_matches_exact_small_case() {
        // 2^-30 offsets: the plain formula loses ~30 bits here, the error-free one none.
        let e = 2f64.powi(-30);
        let a = [1.0, 1.0, 1.0 + e];
        let b = [1.0 + e, 1.0, 1.0];
        let c = [1.0, 1.0 + e, 1.0];
        // det = 1·(1·1 − 1·(1+e)) − 1·((1+e)·1 − 1·1) + (1+e)·((1+e)(1+e) − 1) = e(e² + 3e + ... ) computed exactly:
        // expand: -e - e + (1+e)(2e + e²) = -2e + 2e + e² + 2e² + e³ = 3e² + e³
        let want = 3.0 * e * e + e * e * e;
        assert_eq!(accurate_triple(&a, &b, &c), want);
    }

    /// The kernel compiled for the CPU baseline (Dekker products, SSE2) and the one run where the CPU
    /// has x86-64-v3 (AVX2, FMA) give the same bits: results do not depend on the machine.
    #[test]
    fn kernel_paths_agree() {
        // A thin plate, rotated and far from the origin: most faces take the accurate path.
        let s = [1.0, 1e-7, 1e-6];
        let (c, r) = ([1e4, -2e4, 3e4], [0.6, -0.8, 0.0]);
        let mut v = Vec::new();
        for i in 0..8u32 {
            let p = [0, 1, 2].map(|k| if i >> k & 1 == 0 { -s[k] } else { s[k] });
            v.push([
                c[0] + r[0] * p[0] - r[1] * p[1] + 0.3 * p[2],
                c[1] + r[1] * p[0] + r[0] * p[1] - 0.1 * p[2],
                c[2] + 0.2 * p[0] + p[2],
            ]);
        }
        let (_, f) = cube_quads(1.0);
        let tris = f.triangles();
        let options = IntegrationOptions::accurate();
        let reference = options.reference_for(&v);
        let shifted: Vec<[f64; 3]> = v.iter().map(|&p| sub(p, reference)).collect();
        let kernel = || TriangleLoop {
            shifted: &shifted,
            triangles: &tris,
            options: &options,
        };
        let bits = |raw: RawSums| (raw.0.map(f64::to_bits), raw.1.map(f64::to_bits));
        let dispatched = bits(run_kernel(kernel()));
        assert_eq!(dispatched, bits(kernel().sums::<false>()));
        if cfg!(target_feature = "fma") {
            assert_eq!(dispatched, bits(kernel().sums::<true>()));
        }
    }

    /// The lane-wise accurate evaluation is the scalar one, bit for bit, in every lane.
    #[test]
    fn accurate_triples_match_scalar_per_lane() {
        let mut x = 0x2545_f491_4f6c_dd1d_u64;
        // Mixed magnitudes and signs: near-cancelling triples come from the shared offset.
        let mut next = || (crate::xorshift(&mut x) >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        let mut batch = Batch::new();
        for round in 0..100 {
            let offset = [next(), next(), next()].map(|o| o * 1e4);
            let scale = 10f64.powi(round % 12 - 6);
            for corner in 0..3 {
                for axis in 0..3 {
                    for l in 0..LANES {
                        batch.p[corner][axis][l] = offset[axis] + scale * next();
                    }
                }
            }
            let lanes = batch.accurate_triples::<false>();
            for l in 0..LANES {
                let g = |c: usize| [0, 1, 2].map(|k| batch.p[c][k][l]);
                let want = accurate_triple(&g(0), &g(1), &g(2));
                assert_eq!(lanes[l].to_bits(), want.to_bits(), "round {round} lane {l}");
            }
        }
    }
}
