//! The paper's algorithm (Figures 4–6): each face a planar polygon projected onto the coordinate
//! plane that maximises `|n_γ|`, reduced by Green's theorem to line integrals.

use super::exact::Accumulator;
use super::{finish, sub, IntegrationOptions, Polygons, VolumeIntegrals};

/// The paper's algorithm (Figures 4–6) over planar polygons, about the options' reference point.
///
/// For each face the projection `α-β-γ` is the right-handed permutation of `x-y-z` maximising `|n_γ|`.
/// The face normal is Newell's (the exact area vector of the polygon's projections), so a slightly
/// non-planar polygon gets the best-fit plane; a zero-area face contributes nothing.
/// Indices must be in range (the mesh layer checks them).
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
