//! A bound on the fan kernel's round-off, added up face by face in the same pass as the integrals.
//!
//! Two evaluations about different points only sample the rounding: sweep cases 10598 and 25299 of
//! `tests/union_sweep.rs` (clean closed surfaces far from the origin) were 1.10 and 1.49 times
//! beyond that sample. This bound follows each step of [`super::triangles::Batch`]'s arithmetic
//! instead, first order in ε with generous constants, so it holds for every input; it is what the
//! health ladder reports as round-off (`mesh::health::model::round_off_bound`). Computed in the
//! kernel's lanes from the corners the kernel already holds, it replaced a second integration about
//! another point and costs less than that did (docs/benchmarks.md, "The round-off bound in the
//! integrating pass").

use super::triangles::{Batch, LANES};

/// Half an ulp of 1: the unit round-off.
const U: f64 = f64::EPSILON / 2.0;

/// What the kernel's arithmetic can round in each of its ten raw integrals (`T1, Tx, Ty, Tz, Tx²,
/// Ty², Tz², Txy, Tyz, Tzx` before the divisions by 6, 24 and 120), and the sums of the absolute
/// values of the terms it adds, over `triangles` triangles.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Rounding {
    pub(super) rounded: [f64; 10],
    pub(super) terms: [f64; 10],
    pub(super) triangles: u64,
    /// Whether the terms were summed one running sum each ([`super::Summation::Plain`], the
    /// paper's way: tests and the accuracy report only) rather than compensated.
    pub(super) plain: bool,
}

impl Rounding {
    /// Bounds on the errors of the ten integrals as the kernel returns them (after the divisions),
    /// in [`super::VolumeIntegrals::to_array`]'s order.
    ///
    /// Beside the per-triangle terms of [`Lanes::add`]:
    /// - the kernel sums its terms plainly in blocks of eight (`exact::BLOCK`) before the
    ///   error-free two-sum of each block: at most 7u of the terms' absolute values, taken as 8u;
    /// - the compensation terms are summed plainly, as are the chunks' double-doubles: second order,
    ///   at most (n u)² + 4u² n of the terms for n triangles;
    /// - the divisions and the double-double normalisation of `finish`: u² of the value;
    /// - the bound's own plain sums (n u relative, below 1% for n below 10^13): the factor 1.01.
    ///
    /// Summed plainly instead, the terms' sums can round by n u of them.
    pub fn bounds(&self) -> [f64; 10] {
        let n = self.triangles as f64;
        let summed = if self.plain {
            n * U
        } else {
            8.0 * U + (n * U) * (n * U) + 4.0 * U * U * n
        };
        let scale = [6.0, 24.0, 24.0, 24.0, 120.0, 120.0, 120.0, 120.0, 120.0, 120.0];
        std::array::from_fn(|k| (self.rounded[k] + summed * self.terms[k]) / scale[k] * 1.01)
    }

    /// Two parts' bounds added: the same integrals summed over both.
    pub(super) fn plus(self, other: &Rounding) -> Rounding {
        Rounding {
            rounded: std::array::from_fn(|k| self.rounded[k] + other.rounded[k]),
            terms: std::array::from_fn(|k| self.terms[k] + other.terms[k]),
            triangles: self.triangles + other.triangles,
            plain: self.plain || other.plain,
        }
    }
}

/// [`Rounding`]'s sums, one per lane, so that the per-triangle work vectorises as the kernel's does.
pub(super) struct Lanes {
    rounded: [[f64; LANES]; 10],
    terms: [[f64; LANES]; 10],
    triangles: u64,
}

impl Lanes {
    pub(super) fn new() -> Self {
        Lanes {
            rounded: [[0.0; LANES]; 10],
            terms: [[0.0; LANES]; 10],
            triangles: 0,
        }
    }

    /// Adds the first `len` lanes of `batch`, whose `d` (six times the signed tetrahedron with the
    /// reference point, as the kernel summed it) and slow-path flags [`Batch::volumes`] gave, and
    /// the lanes' corners as `stored` before their shift by `reference`.
    ///
    /// Per triangle, its corners `a, b, c` as the kernel holds them (shifted by the reference), with
    /// `s_k = |a_k| + |b_k| + |c_k|` and `cross_k` the sum of the absolute values of the two
    /// products of the cross product's component `k`:
    /// - the shift: a corner's coordinates moved by at most `moved` each, the same for every face
    ///   at that corner (the surface stays closed), so a closed surface's integrals move by at most
    ///   each face's area (`|n|/2`, below `Σ cross / 2`) times the move (√3 `moved`) times the
    ///   integrand's largest value on the face (1, below `s_k`, below `p_k`); in units of `d`: 6,
    ///   21 and 104 times `moved · Σ cross`;
    /// - `d` evaluated plainly (the differences, the cross product and the dot product): 8u times
    ///   the sum of the absolute values of its products, `Σ |a_k| cross_k`; where the kernel
    ///   re-evaluated it with error-free products (Sum2 of six triple products, each below
    ///   `largest³`, `largest` at most `max s_k`), `4u |d|` and `256 u² largest³`;
    /// - the corners' sums and products, and their products with `d`: `4u |d|` times `s_k` and
    ///   `8u |d|` times `p_ij`, which is at least the kernel's `Σ |q_ij| + s_i s_j` (`Σ |q_ij|` over
    ///   the corners is at most `s_i s_j`, a sum of some of its terms): `p_ij = 2 s_i s_j`.
    #[inline(always)]
    pub(super) fn add(
        &mut self,
        batch: &Batch,
        d: &[f64; LANES],
        slow: [bool; LANES],
        (stored, reference): (&[[[f64; LANES]; 3]; 3], [f64; 3]),
        len: usize,
    ) {
        let [a, b, c] = &batch.p;
        // How far the shift moved each lane's corners: the largest error of their coordinates,
        // exactly (the error of the two-sum of the stored coordinate and the reference's negation,
        // whose sum the kernel holds).
        let mut moved = [0.0f64; LANES];
        for (corner, shifted) in batch.p.iter().enumerate() {
            for k in 0..3 {
                for l in 0..LANES {
                    let (v, s) = (stored[corner][k][l], shifted[k][l]);
                    let r = -reference[k];
                    let bb = s - v;
                    let e = (v - (s - bb)) + (r - bb);
                    moved[l] = moved[l].max(e.abs());
                }
            }
        }
        let mut rounded = [[0.0; LANES]; 10];
        let mut terms = [[0.0; LANES]; 10];
        for l in 0..LANES {
            let e1 = [b[0][l] - a[0][l], b[1][l] - a[1][l], b[2][l] - a[2][l]];
            let e2 = [c[0][l] - a[0][l], c[1][l] - a[1][l], c[2][l] - a[2][l]];
            let cross = [
                (e1[1] * e2[2]).abs() + (e1[2] * e2[1]).abs(),
                (e1[2] * e2[0]).abs() + (e1[0] * e2[2]).abs(),
                (e1[0] * e2[1]).abs() + (e1[1] * e2[0]).abs(),
            ];
            let s: [f64; 3] =
                std::array::from_fn(|k| a[k][l].abs() + b[k][l].abs() + c[k][l].abs());
            let largest = s[0].max(s[1]).max(s[2]);
            let products =
                a[0][l].abs() * cross[0] + a[1][l].abs() * cross[1] + a[2][l].abs() * cross[2];
            let d_abs = d[l].abs();
            let evaluated = if slow[l] {
                4.0 * U * d_abs + 256.0 * U * U * (largest * largest * largest)
            } else {
                8.0 * U * products
            };
            let moved = moved[l] * (cross[0] + cross[1] + cross[2]);
            let q = |i: usize, j: usize| 2.0 * s[i] * s[j];
            let p = [q(0, 0), q(1, 1), q(2, 2), q(0, 1), q(1, 2), q(2, 0)];
            rounded[0][l] = evaluated + 6.0 * moved;
            terms[0][l] = d_abs;
            for k in 0..3 {
                rounded[1 + k][l] = (evaluated + 4.0 * U * d_abs + 21.0 * moved) * s[k];
                terms[1 + k][l] = d_abs * s[k];
            }
            for k in 0..6 {
                rounded[4 + k][l] = (evaluated + 8.0 * U * d_abs + 104.0 * moved) * p[k];
                terms[4 + k][l] = d_abs * p[k];
            }
        }
        for k in 0..10 {
            for l in 0..len {
                self.rounded[k][l] += rounded[k][l];
                self.terms[k][l] += terms[k][l];
            }
        }
        self.triangles += len as u64;
    }

    /// The lanes' sums, for terms summed plainly or not (`plain`).
    pub(super) fn total(&self, plain: bool) -> Rounding {
        Rounding {
            rounded: self.rounded.map(|r| r.iter().sum()),
            terms: self.terms.map(|t| t.iter().sum()),
            triangles: self.triangles,
            plain,
        }
    }
}
