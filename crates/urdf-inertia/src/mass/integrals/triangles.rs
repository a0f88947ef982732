//! The triangle kernel: each triangle the signed tetrahedron it spans with the reference point,
//! in lanes, dispatched to the best instruction set the CPU has.

use super::exact::{two_prod_in, two_sum, Accumulator, BLOCK, TRIPLE_TERMS};
use super::{finish, sub, IntegrationOptions, VolumeIntegrals};

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
pub(super) type RawSums = ([f64; 10], [f64; 10]);

/// A loop over triangles feeding [`Batch`]es, compiled for the build's CPU and for x86-64-v3.
pub(super) trait KernelLoop {
    /// [`RawSums`], or several of them for a loop that feeds several batches.
    type Output;
    /// The sums; `FMA`: compiled where hardware FMA is enabled (selects [`two_prod_in`]).
    fn sums<const FMA: bool>(self) -> Self::Output;
}

/// Runs a kernel loop in the best instruction set the CPU has, detected at run time (the binary
/// targets baseline x86-64): AVX2 (4 lanes instead of SSE2's 2) and FMA through pulp's safe
/// dispatch. Every path performs the same IEEE operations in the same order (no contraction into
/// FMA; the exact products are exact either way), so the bits do not depend on the CPU
/// (`kernel_paths_agree` checks it). The dispatch takes a third fewer instructions per face than
/// the SSE2 build (figures: docs/benchmarks.md, "Figures behind choices in the code").
#[inline(always)]
pub(super) fn run_kernel<L: KernelLoop>(kernel: L) -> L::Output {
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = pulp::x86::V3::try_new() {
        return v3.vectorize(WithFma(kernel));
    }
    kernel.sums::<{ cfg!(target_feature = "fma") }>()
}

/// A kernel loop to run inside pulp's x86-64-v3 context (AVX2 and FMA enabled).
struct WithFma<L>(L);

impl<L: KernelLoop> pulp::NullaryFnOnce for WithFma<L> {
    type Output = L::Output;

    // Inlined into pulp's `#[target_feature]` function, so that the whole loop is compiled with it.
    #[inline(always)]
    fn call(self) -> L::Output {
        self.0.sums::<true>()
    }
}

/// [`triangle_integrals`]'s loop over indexed triangles of shifted vertices.
pub(super) struct TriangleLoop<'a> {
    pub(super) shifted: &'a [[f64; 3]],
    pub(super) triangles: &'a [[u32; 3]],
    pub(super) options: &'a IntegrationOptions,
}

impl KernelLoop for TriangleLoop<'_> {
    type Output = RawSums;

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
pub(super) struct Batch {
    /// Corner coordinates relative to the reference point: `p[corner][axis][lane]`.
    pub(super) p: [[[f64; LANES]; 3]; 3],
    pub(super) len: usize,
}

/// Triangles per batch: the compensated block.
pub(super) const LANES: usize = BLOCK as usize;

impl Batch {
    pub(super) fn new() -> Self {
        Batch {
            p: [[[0.0; LANES]; 3]; 3],
            len: 0,
        }
    }

    #[inline(always)]
    pub(super) fn push(&mut self, a: [f64; 3], b: [f64; 3], c: [f64; 3]) {
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
    pub(super) fn add<const FMA: bool>(
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
    pub(super) fn finish<const FMA: bool>(&self, mut acc: Accumulator, accurate: bool) -> RawSums {
        if self.len > 0 {
            acc.add_batch(&self.terms::<FMA>(accurate), self.len);
        }
        acc.total()
    }

    /// [`accurate_triple`] for every lane, written lane-wise so that it vectorises: the same
    /// operations per lane in the same order, so the same bits as one triangle at a time.
    #[inline(always)]
    pub(super) fn accurate_triples<const FMA: bool>(&self) -> [f64; LANES] {
        let [a, b, c] = &self.p;
        // The six leading products q cancel: they are summed with error-free two-sums, pairwise
        // (depth 3 instead of a chain of 6), and every rounding error is kept in `comp` (Sum2 of
        // Ogita, Rump and Oishi, in a tree). Each product's own error terms (q's rounding, and a_i
        // times the rounding of b_j·c_k) are below eps·|q|: summed plainly they add an error of
        // order 12·eps²·Σ|q|, the size of Sum2's own second-order term. Against the 18 two-sums in
        // a chain before: the same bound at well under half the work (figures: docs/benchmarks.md,
        // "Figures behind choices in the code").
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
        let (d, _) = self.volumes::<FMA>(accurate);
        self.terms_of(&d)
    }

    /// Six times each lane's signed tetrahedron with the reference point, `d`, and whether the lane
    /// took the slow path (re-evaluated with error-free products; only where `accurate`).
    #[inline(always)]
    pub(super) fn volumes<const FMA: bool>(
        &self,
        accurate: bool,
    ) -> ([f64; LANES], [bool; LANES]) {
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
        } else {
            slow = [false; LANES];
        }
        (d, slow)
    }

    /// The raw contributions of the batch's triangles from their `d` ([`Batch::volumes`]).
    #[inline(always)]
    pub(super) fn terms_of(&self, d: &[f64; LANES]) -> [[f64; LANES]; 10] {
        let [a, b, c] = &self.p;
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
