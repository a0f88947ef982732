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

use crate::geometry::sub;
use std::ops::Index;

mod exact;
// The paper's polygon kernel: the reference of the tests, benchmarks and accuracy report, not used by
// the tool itself.
#[cfg(any(test, feature = "internals"))]
mod polygons;
mod rounding;
mod triangles;

use exact::Accumulator;
pub use rounding::Rounding;
pub(crate) use exact::{two_prod, two_sum};
#[cfg(any(test, feature = "internals"))]
pub use polygons::mirtich_polygons;
pub use triangles::triangle_integrals;
use triangles::{run_kernel, Batch, KernelLoop, RawSums, LANES};

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

    /// An empty face list with room for `faces` faces of `corners` corners in all.
    pub fn with_capacity(faces: usize, corners: usize) -> Self {
        let mut starts = Vec::with_capacity(faces + 1);
        starts.push(0);
        Self {
            indices: Vec::with_capacity(corners),
            starts,
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
    box_centre(lo, hi)
}

/// The centre of the box from `lo` to `hi`, as [`bounding_box_centre`] takes it.
pub(crate) fn box_centre(lo: [f64; 3], hi: [f64; 3]) -> [f64; 3] {
    // lo + (hi - lo)/2 stays inside [lo, hi] without overflow; the centre only has to be near the mesh.
    [0, 1, 2].map(|k| lo[k] + 0.5 * (hi[k] - lo[k]))
}

/// Scales raw double-double accumulations into the integrals (the divisions of Figure 4 and of the
/// tetrahedron form), dividing the double-double by small integers without losing its low part.
pub(super) fn finish(
    raw: ([f64; 10], [f64; 10]),
    reference: [f64; 3],
    divisors: [f64; 4],
) -> VolumeIntegrals {
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
        let chunks: Vec<RawSums> = crate::threads::install(|| {
            (0..n.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let range = c * CHUNK..((c + 1) * CHUNK).min(n);
                    fan_sums(vertices, range.map(|i| faces.face(i)), reference, options)
                })
                .collect()
        });
        combine(chunks.iter())
    } else {
        fan_sums(vertices, faces.iter(), reference, options)
    };
    finish(raw, reference, [6.0, 24.0, 120.0, 120.0])
}

/// The chunks' double-double sums combined in order.
fn combine<'a>(chunks: impl Iterator<Item = &'a RawSums>) -> RawSums {
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
}

/// [`volume_integrals`] with a bound on its round-off ([`Rounding`]), in one pass over the faces:
/// the integrals are, bit for bit, those of [`volume_integrals`] (the same kernel, sums and chunks),
/// and the bound is added up from the corners the kernel holds.
pub fn volume_integrals_and_rounding(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    options: &IntegrationOptions,
) -> (VolumeIntegrals, Rounding) {
    let reference = options.reference_for(vertices);
    let n = faces.len();
    let (raw, rounding) = if options.summation == Summation::Compensated && n > CHUNK {
        use rayon::prelude::*;
        let chunks: Vec<(RawSums, Rounding)> = crate::threads::install(|| {
            (0..n.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| {
                    let range = c * CHUNK..((c + 1) * CHUNK).min(n);
                    fan_sums_rounding(vertices, range.map(|i| faces.face(i)), reference, options)
                })
                .collect()
        });
        let rounding = chunks
            .iter()
            .fold(Rounding::default(), |sum, c| sum.plus(&c.1));
        (combine(chunks.iter().map(|c| &c.0)), rounding)
    } else {
        fan_sums_rounding(vertices, faces.iter(), reference, options)
    };
    (finish(raw, reference, [6.0, 24.0, 120.0, 120.0]), rounding)
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

/// [`fan_sums`] with the bound on their round-off.
fn fan_sums_rounding<'a>(
    vertices: &[[f64; 3]],
    faces: impl Iterator<Item = &'a [u32]>,
    reference: [f64; 3],
    options: &IntegrationOptions,
) -> (RawSums, Rounding) {
    run_kernel(FanLoopRounding(FanLoop {
        vertices,
        faces,
        reference,
        options,
    }))
}

/// [`fan_sums`]'s loop: polygons fanned into triangles, vertices shifted on the fly.
struct FanLoop<'a, I> {
    vertices: &'a [[f64; 3]],
    faces: I,
    reference: [f64; 3],
    options: &'a IntegrationOptions,
}

impl<'f, I: Iterator<Item = &'f [u32]>> KernelLoop for FanLoop<'_, I> {
    type Output = RawSums;

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

/// [`volume_integrals_and_rounding`]'s loop: [`FanLoop`], each full batch also added to the bound.
struct FanLoopRounding<'a, I>(FanLoop<'a, I>);

impl<'f, I: Iterator<Item = &'f [u32]>> KernelLoop for FanLoopRounding<'_, I> {
    type Output = (RawSums, Rounding);

    #[inline(always)]
    fn sums<const FMA: bool>(self) -> (RawSums, Rounding) {
        let FanLoop {
            vertices,
            faces,
            reference,
            options,
        } = self.0;
        let accurate = options.accurate_faces;
        let mut acc = Accumulator::new(options.summation);
        let mut bound = rounding::Lanes::new();
        let mut batch = Batch::new();
        // Each lane's corners as stored, for the exact error of their shift ([`rounding::Lanes`]).
        let mut stored = [[[0.0; LANES]; 3]; 3];
        for face in faces {
            if face.len() < 3 {
                continue;
            }
            let va = vertices[face[0] as usize];
            let a = sub(va, reference);
            for k in 1..face.len() - 1 {
                let (vb, vc) = (vertices[face[k] as usize], vertices[face[k + 1] as usize]);
                let l = batch.len;
                for (corner, v) in [va, vb, vc].into_iter().enumerate() {
                    for axis in 0..3 {
                        stored[corner][axis][l] = v[axis];
                    }
                }
                batch.push(a, sub(vb, reference), sub(vc, reference));
                if batch.len == LANES {
                    flush::<FMA>(&batch, (&stored, reference), (&mut acc, &mut bound), accurate, LANES);
                    batch.len = 0;
                }
            }
        }
        if batch.len > 0 {
            flush::<FMA>(&batch, (&stored, reference), (&mut acc, &mut bound), accurate, batch.len);
        }
        (acc.total(), bound.total(options.summation != Summation::Compensated))
    }
}

/// [`FanLoopRounding`]'s batch of `len` triangles into the sums and the bound (a function, not a
/// closure, so that it is inlined into the loop compiled for the CPU's instruction set).
#[inline(always)]
fn flush<const FMA: bool>(
    batch: &Batch,
    stored: (&[[[f64; LANES]; 3]; 3], [f64; 3]),
    (acc, bound): (&mut Accumulator, &mut rounding::Lanes),
    accurate: bool,
    len: usize,
) {
    let (d, slow) = batch.volumes::<FMA>(accurate);
    acc.add_batch(&batch.terms_of(&d), len);
    bound.add(batch, &d, slow, stored, len);
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
    #[must_use]
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
    #[must_use]
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

#[cfg(test)]
mod tests {
    use super::exact::accurate_triple;
    use super::triangles::{TriangleLoop, LANES};
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

    /// [`volume_integrals_about_two`] gives, bit for bit, what [`volume_integrals`] gives about each
    /// reference point: on polygons (fans) and on a mesh of more than two chunks (the chunked sums),
    /// with plain and compensated sums, on one thread and on three.
    #[test]
    fn the_pass_with_its_rounding_bound_is_the_plain_pass() {
        let (v, f) = cube_quads(0.37);
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = || (crate::xorshift(&mut rng) >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        let n = 3 * CHUNK + 11;
        let big_v: Vec<[f64; 3]> = (0..n + 2).map(|_| [next(), 1e3 * next(), next() + 7.0]).collect();
        let tris: Vec<[u32; 3]> = (0..n as u32).map(|i| [i, i + 1, i + 2]).collect();
        let big_f = Polygons::from_triangles(&tris);
        let bits = |t: &VolumeIntegrals| (t.to_array().map(f64::to_bits), t.low.map(f64::to_bits), t.reference.map(f64::to_bits));
        let mut bounds = Vec::new();
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            pool.install(|| {
                for (v, f) in [(&v, &f), (&big_v, &big_f)] {
                    for summation in [Summation::Compensated, Summation::Plain] {
                        for accurate_faces in [true, false] {
                            let opts = IntegrationOptions {
                                summation,
                                accurate_faces,
                                reference: Some([-0.4, 3.0e-3, 9.5]),
                            };
                            let (t, rounding) = volume_integrals_and_rounding(v, f, &opts);
                            assert_eq!(bits(&t), bits(&volume_integrals(v, f, &opts)));
                            assert_eq!(rounding.triangles, f.triangles().len() as u64);
                            bounds.push(rounding);
                        }
                    }
                }
            });
        }
        // The same bound on any number of threads.
        assert_eq!(bounds[..8], bounds[8..]);
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
