//! Unions of two to five closed convex parts in one mesh, each wound outward or inward, against
//! the exact mass properties of Ω = {x : |w(x)| ≥ ½}: every error within the estimate.
//!
//! The parts are boxes (axis-aligned, gridded, or turned by a rotation of rational entries),
//! tetrahedra, octahedra and prisms, placed apart, nested, on one another's faces (sharing the
//! face's corners exactly, or a part of an axis-aligned face), sharing an edge or a corner, cutting
//! one another, moved by 1e-12 to 1e-6 of the part, or tiny beside large; scaled by 1 mm to 100 m,
//! moved up to 1e5 m from the origin, mirrored, their corners rounded to f32 or not. The library
//! sees one mesh and finds the shells itself.
//!
//! Truth, independent of the library: inside the parts in S and no other (a Venn atom), w is
//! Σ_{i∈S} sᵢ (sᵢ = ±1 the winding), so Ω is the union of the atoms with |Σ sᵢ| ≥ 1, and its
//! integrals are `Σ_T c(T) I(T)` over the intersections T of parts, `c(T) = Σ_{S⊆T, S in Ω}`
//! (−1)^{|T|−|S|} (inclusion–exclusion). Each intersection is convex: the first part's polyhedron
//! clipped in rationals by every face plane of the others, its integrals those of the fans of its
//! faces about the origin.

#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;

use common::shells::together;
use common::Mesh;
use num_bigint::BigInt;
use num_traits::{Signed, ToPrimitive, Zero};
use std::fmt::Write;
use urdf_inertia::mesh::health::HealthOptions;

use common::rational::{boxes_meet, q, ring, vcross, vdot, vsub, Q, V};

/// A convex polyhedron: its faces, each a ring of corners counter-clockwise seen from outside.
#[derive(Clone)]
struct Poly {
    faces: Vec<Vec<V>>,
}

/// The outward plane n·x ≤ d of a triangle wound outward.
fn plane(a: &V, b: &V, c: &V) -> (V, Q) {
    let n = vcross(&vsub(b, a), &vsub(c, a));
    let d = vdot(&n, a);
    (n, d)
}

/// `p` ∩ {x : n·x ≤ d}; `None` when that has no volume.
fn clip(p: &Poly, n: &V, d: &Q) -> Option<Poly> {
    let side: Vec<Vec<Q>> = p
        .faces
        .iter()
        .map(|f| f.iter().map(|x| vdot(n, x) - d).collect())
        .collect();
    if !side.iter().flatten().any(Signed::is_negative) {
        return None;
    }
    if !side.iter().flatten().any(Signed::is_positive) {
        return Some(p.clone());
    }
    let mut faces = Vec::new();
    let mut cap: Vec<V> = Vec::new();
    for (f, s) in p.faces.iter().zip(&side) {
        let mut out: Vec<V> = Vec::new();
        for i in 0..f.len() {
            let j = (i + 1) % f.len();
            let (a, b, sa, sb) = (&f[i], &f[j], &s[i], &s[j]);
            if !sa.is_positive() {
                out.push(a.clone());
                if sa.is_zero() && !cap.contains(a) {
                    cap.push(a.clone());
                }
            }
            if (sa.is_negative() && sb.is_positive()) || (sa.is_positive() && sb.is_negative()) {
                let t = sa / (sa - sb);
                let x: V = std::array::from_fn(|k| &a[k] + (&b[k] - &a[k]) * &t);
                if !cap.contains(&x) {
                    cap.push(x.clone());
                }
                out.push(x);
            }
        }
        if out.len() >= 3 {
            faces.push(out);
        }
    }
    if cap.len() >= 3 {
        faces.push(ring(n, &cap));
    }
    Some(Poly { faces })
}

/// `[T1, Tx, Ty, Tz, Tx², Ty², Tz², Txy, Tyz, Tzx]` of the polyhedron: the sums of
/// `common::exact_integrals` over the fans of its faces.
fn integrals(p: &Poly) -> [Q; 10] {
    let mut acc: [Q; 10] = std::array::from_fn(|_| Q::zero());
    for f in &p.faces {
        for w in 1..f.len() - 1 {
            let (a, b, c) = (&f[0], &f[w], &f[w + 1]);
            let d = vdot(a, &vcross(b, c));
            if d.is_zero() {
                continue;
            }
            let s: V = std::array::from_fn(|k| &a[k] + &b[k] + &c[k]);
            let qq = |i: usize, j: usize| &a[i] * &a[j] + &b[i] * &b[j] + &c[i] * &c[j];
            acc[0] += &d;
            for k in 0..3 {
                acc[1 + k] += &d * &s[k];
                acc[4 + k] += &d * (qq(k, k) + &s[k] * &s[k]);
                let j = (k + 1) % 3;
                acc[7 + k] += &d * (qq(k, j) + &s[k] * &s[j]);
            }
        }
    }
    let div = [6, 24, 24, 24, 120, 120, 120, 120, 120, 120];
    std::array::from_fn(|k| &acc[k] / Q::from_integer(BigInt::from(div[k])))
}

/// One part as stored: its triangles, wound outward, over its own corners.
struct Part {
    mesh: Mesh,
    inward: bool,
    label: String,
}

impl Part {
    fn poly(&self) -> Poly {
        Poly {
            faces: self
                .mesh
                .1
                .iter()
                .map(|t| t.iter().map(|&i| self.mesh.0[i as usize].map(q)).collect())
                .collect(),
        }
    }

    fn planes(&self) -> Vec<(V, Q)> {
        let mut out: Vec<(V, Q)> = Vec::new();
        for t in &self.mesh.1 {
            let [a, b, c] = t.map(|i| self.mesh.0[i as usize].map(q));
            let p = plane(&a, &b, &c);
            if !out.contains(&p) {
                out.push(p);
            }
        }
        out
    }

    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::MAX; 3];
        let mut hi = [f64::MIN; 3];
        for p in &self.mesh.0 {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}

/// The exact integrals of Ω for the parts: `Σ_T c(T) I(T)` over the intersections T.
fn omega_integrals(parts: &[Part]) -> [Q; 10] {
    let n = parts.len();
    let planes: Vec<Vec<(V, Q)>> = parts.iter().map(Part::planes).collect();
    let bounds: Vec<_> = parts.iter().map(Part::bounds).collect();
    let sign: Vec<i32> = parts
        .iter()
        .map(|p| if p.inward { -1 } else { 1 })
        .collect();
    let mut polys: Vec<Option<Poly>> = vec![None; 1 << n];
    let mut total: [Q; 10] = std::array::from_fn(|_| Q::zero());
    for t in 1usize..(1 << n) {
        let members: Vec<usize> = (0..n).filter(|i| t >> i & 1 == 1).collect();
        let last = *members.last().expect("not empty");
        let poly = if members.len() == 1 {
            Some(parts[last].poly())
        } else {
            let meet = boxes_meet(&members, &bounds);
            let rest = t & !(1 << last);
            match (&polys[rest], meet) {
                (Some(p), true) => {
                    let mut p = Some(p.clone());
                    for (pn, pd) in &planes[last] {
                        p = p.and_then(|p| clip(&p, pn, pd));
                    }
                    p
                }
                _ => None,
            }
        };
        if let Some(p) = &poly {
            // c(T): the atoms S ⊆ T in Ω, signed by |T| − |S|.
            let mut c = 0i64;
            for s in 1usize..(1 << n) {
                if s & !t != 0 {
                    continue;
                }
                let w: i32 = (0..n).filter(|i| s >> i & 1 == 1).map(|i| sign[i]).sum();
                if w.abs() >= 1 {
                    let parity = (t.count_ones() - s.count_ones()) % 2;
                    c += if parity == 0 { 1 } else { -1 };
                }
            }
            if c != 0 {
                let ig = integrals(p);
                let c = Q::from_integer(BigInt::from(c));
                for k in 0..10 {
                    total[k] += &ig[k] * &c;
                }
            }
        }
        polys[t] = poly;
    }
    total
}

// ---------------------------------------------------------------------------------------------
// Random parts.

fn uniform(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

fn log_uniform(state: &mut u64, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * uniform(state)).exp()
}

fn below(state: &mut u64, n: usize) -> usize {
    ((uniform(state) * n as f64) as usize).min(n - 1)
}

/// A part in the unit frame: corners and its faces as cycles of corners (either way round).
#[derive(Clone)]
struct Shape {
    points: Vec<[f64; 3]>,
    faces: Vec<Vec<usize>>,
    family: &'static str,
    /// Axis-aligned box: its lower and upper corner.
    aabb: Option<([f64; 3], [f64; 3])>,
}

type R = [[f64; 3]; 3];

/// A rotation with rational entries: the quaternion (a, b, c, d) of small integers.
fn rotation(state: &mut u64) -> R {
    loop {
        let v: [f64; 4] = std::array::from_fn(|_| below(state, 7) as f64 - 3.0);
        let [a, b, c, d] = v;
        let n = a * a + b * b + c * c + d * d;
        if n == 0.0 {
            continue;
        }
        return [
            [
                (a * a + b * b - c * c - d * d) / n,
                2.0 * (b * c - a * d) / n,
                2.0 * (b * d + a * c) / n,
            ],
            [
                2.0 * (b * c + a * d) / n,
                (a * a - b * b + c * c - d * d) / n,
                2.0 * (c * d - a * b) / n,
            ],
            [
                2.0 * (b * d - a * c) / n,
                2.0 * (c * d + a * b) / n,
                (a * a - b * b - c * c + d * d) / n,
            ],
        ];
    }
}

fn apply(r: &R, c: [f64; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| c[i] + r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

const IDENTITY: R = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn box_shape(c: [f64; 3], h: [f64; 3], r: Option<&R>) -> Shape {
    let points = (0..8)
        .map(|i| {
            let v = std::array::from_fn(|k| if i >> k & 1 == 1 { h[k] } else { -h[k] });
            match r {
                Some(r) => apply(r, c, v),
                None => std::array::from_fn(|k| c[k] + v[k]),
            }
        })
        .collect();
    let faces = [
        [0, 2, 6, 4],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 5, 7, 6],
    ]
    .iter()
    .map(|f| f.to_vec())
    .collect();
    let aabb = r.is_none().then(|| {
        (
            std::array::from_fn(|k| c[k] - h[k]),
            std::array::from_fn(|k| c[k] + h[k]),
        )
    });
    Shape {
        points,
        faces,
        family: if r.is_some() { "turned box" } else { "box" },
        aabb,
    }
}

fn aabb_shape(lo: [f64; 3], hi: [f64; 3]) -> Shape {
    let points = (0..8)
        .map(|i| std::array::from_fn(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] }))
        .collect();
    let mut s = box_shape([0.0; 3], [1.0; 3], None);
    s.points = points;
    s.aabb = Some((lo, hi));
    s
}

fn grid_shape(lo: [f64; 3], hi: [f64; 3], n: u32) -> Shape {
    let (points, tris) = common::grid_box(lo, hi, n);
    Shape {
        points,
        faces: tris
            .iter()
            .map(|t| t.map(|i| i as usize).to_vec())
            .collect(),
        family: "grid box",
        aabb: Some((lo, hi)),
    }
}

fn tet_shape(p: [[f64; 3]; 4]) -> Shape {
    Shape {
        points: p.to_vec(),
        faces: vec![vec![0, 1, 2], vec![0, 1, 3], vec![0, 2, 3], vec![1, 2, 3]],
        family: "tetrahedron",
        aabb: None,
    }
}

fn octa_shape(c: [f64; 3], r3: [f64; 3], rot: &R) -> Shape {
    let mut points = Vec::new();
    for k in 0..3 {
        for s in [1.0, -1.0] {
            let mut v = [0.0; 3];
            v[k] = s * r3[k];
            points.push(apply(rot, c, v));
        }
    }
    let mut faces = Vec::new();
    for x in [0, 1] {
        for y in [2, 3] {
            for z in [4, 5] {
                faces.push(vec![x, y, z]);
            }
        }
    }
    Shape {
        points,
        faces,
        family: "octahedron",
        aabb: None,
    }
}

/// A prism over a convex n-gon (radius `r`, height `h` along `axis`), turned by `rot` when a
/// triangle (its caps stay triangles).
fn prism_shape(
    state: &mut u64,
    c: [f64; 3],
    r: f64,
    h: f64,
    axis: usize,
    rot: Option<&R>,
) -> Shape {
    let n = if rot.is_some() {
        3
    } else {
        3 + below(state, 5)
    };
    let mut angles: Vec<f64> = (0..n)
        .map(|i| (i as f64 + 0.2 + 0.6 * uniform(state)) * std::f64::consts::TAU / n as f64)
        .collect();
    angles.sort_by(f64::total_cmp);
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut points = Vec::new();
    for z in [-h / 2.0, h / 2.0] {
        for t in &angles {
            let mut v = [0.0; 3];
            v[a] = r * t.cos();
            v[b] = r * t.sin();
            v[axis] = z;
            points.push(match rot {
                Some(rot) => apply(rot, c, v),
                None => apply(&IDENTITY, c, v),
            });
        }
    }
    Shape {
        points,
        faces: prism_faces(n),
        family: "prism",
        aabb: None,
    }
}

/// The faces of a prism whose two rings of `n` corners are numbered 0..n and n..2n: the two ends,
/// then a quad per side.
fn prism_faces(n: usize) -> Vec<Vec<usize>> {
    let mut faces = vec![(0..n).collect::<Vec<_>>(), (n..2 * n).collect()];
    for i in 0..n {
        let j = (i + 1) % n;
        faces.push(vec![i, j, n + j, n + i]);
    }
    faces
}

fn centre(s: &Shape) -> [f64; 3] {
    let n = s.points.len() as f64;
    std::array::from_fn(|k| s.points.iter().map(|p| p[k]).sum::<f64>() / n)
}

fn random_point(state: &mut u64, c: [f64; 3], r: f64) -> [f64; 3] {
    std::array::from_fn(|k| c[k] + r * (2.0 * uniform(state) - 1.0))
}

/// A random part of any family about `c`, of size about `size`.
fn random_shape(state: &mut u64, c: [f64; 3], size: f64) -> Shape {
    match below(state, 6) {
        0 => {
            let h: [f64; 3] = std::array::from_fn(|_| size * (0.2 + 0.8 * uniform(state)));
            box_shape(c, h, None)
        }
        1 => {
            let lo: [f64; 3] = std::array::from_fn(|k| c[k] - size * (0.2 + 0.8 * uniform(state)));
            let hi: [f64; 3] = std::array::from_fn(|k| c[k] + size * (0.2 + 0.8 * uniform(state)));
            grid_shape(lo, hi, 2 + below(state, 3) as u32)
        }
        2 => {
            let r = rotation(state);
            let h: [f64; 3] = std::array::from_fn(|_| size * (0.2 + 0.8 * uniform(state)));
            box_shape(c, h, Some(&r))
        }
        3 => tet_shape(std::array::from_fn(|_| random_point(state, c, size))),
        4 => {
            let r = rotation(state);
            let r3: [f64; 3] = std::array::from_fn(|_| size * (0.3 + 0.7 * uniform(state)));
            octa_shape(c, r3, &r)
        }
        _ => {
            let rot = (uniform(state) < 0.5).then(|| rotation(state));
            let axis = below(state, 3);
            let (r, hh) = (
                size * (0.3 + 0.7 * uniform(state)),
                size * (0.3 + 1.4 * uniform(state)),
            );
            prism_shape(state, c, r, hh, axis, rot.as_ref())
        }
    }
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / n)
}

fn newell(s: &Shape, f: &[usize]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for i in 0..f.len() {
        let (a, b) = (s.points[f[i]], s.points[f[(i + 1) % f.len()]]);
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

fn extent(s: &Shape) -> f64 {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &s.points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
}

/// A part placed against `base` (an earlier part) in one of the ways of the sweep, or on its own.
#[allow(clippy::too_many_lines)] // one arm per way of placing a part, each short
fn related_shape(state: &mut u64, base: &Shape) -> (Shape, String) {
    let c = centre(base);
    let size = extent(base) / 2.0;
    match below(state, 10) {
        // Nested: the base shrunk about its centre, or another part inside it.
        0 => {
            let t = if uniform(state) < 0.2 {
                log_uniform(state, 1e-4, 1e-2)
            } else {
                0.1 + 0.85 * uniform(state)
            };
            let mut s = base.clone();
            for p in &mut s.points {
                *p = std::array::from_fn(|k| c[k] + t * (p[k] - c[k]));
            }
            s.aabb = s.aabb.map(|(lo, hi)| {
                (
                    std::array::from_fn(|k| c[k] + t * (lo[k] - c[k])),
                    std::array::from_fn(|k| c[k] + t * (hi[k] - c[k])),
                )
            });
            (s, format!("nested {t:.3e}"))
        }
        1 => {
            let t = 0.05 + 0.25 * uniform(state);
            (random_shape(state, c, t * size), format!("inside {t:.3}"))
        }
        // On a face: a prism or a pyramid over the face itself (its corners shared exactly).
        2 | 3 => {
            let fi = below(state, base.faces.len());
            let f = &base.faces[fi];
            let n = unit(newell(base, f));
            let fc: [f64; 3] = {
                let m = f.len() as f64;
                std::array::from_fn(|k| f.iter().map(|&i| base.points[i][k]).sum::<f64>() / m)
            };
            let out = {
                let d: f64 = (0..3).map(|k| n[k] * (fc[k] - c[k])).sum();
                if d < 0.0 {
                    n.map(|x| -x)
                } else {
                    n
                }
            };
            let h = size * log_uniform(state, 0.05, 1.0);
            let shear: [f64; 3] = std::array::from_fn(|_| h * 0.5 * (2.0 * uniform(state) - 1.0));
            let mut points: Vec<[f64; 3]> = f.iter().map(|&i| base.points[i]).collect();
            let m = f.len();
            if uniform(state) < 0.5 {
                points.extend(
                    f.iter().map(|&i| {
                        std::array::from_fn(|k| base.points[i][k] + out[k] * h + shear[k])
                    }),
                );
                (
                    Shape {
                        points,
                        faces: prism_faces(m),
                        family: "prism on a face",
                        aabb: None,
                    },
                    format!("on face {fi}"),
                )
            } else {
                points.push(std::array::from_fn(|k| fc[k] + out[k] * h + shear[k]));
                let mut faces = vec![(0..m).collect::<Vec<_>>()];
                for i in 0..m {
                    faces.push(vec![i, (i + 1) % m, m]);
                }
                (
                    Shape {
                        points,
                        faces,
                        family: "pyramid on a face",
                        aabb: None,
                    },
                    format!("on face {fi}"),
                )
            }
        }
        // Beside an axis-aligned box: touching on part of a side, or 1e-12..1e-6 off it.
        4 if base.aabb.is_some() => {
            let (lo, hi) = base.aabb.expect("a box");
            let k = below(state, 3);
            let up = uniform(state) < 0.5;
            let d = hi[k] - lo[k];
            let mut nlo: [f64; 3] =
                std::array::from_fn(|j| lo[j] + (hi[j] - lo[j]) * (uniform(state) - 0.3));
            let mut nhi: [f64; 3] =
                std::array::from_fn(|j| nlo[j] + (hi[j] - lo[j]) * (0.2 + 0.9 * uniform(state)));
            let gap = match below(state, 3) {
                0 => 0.0,
                1 => d * log_uniform(state, 1e-12, 1e-6),
                _ => -d * log_uniform(state, 1e-12, 1e-6),
            };
            let depth = d * log_uniform(state, 1e-3, 1.0);
            if up {
                nlo[k] = hi[k] + gap;
                nhi[k] = nlo[k] + depth;
            } else {
                nhi[k] = lo[k] - gap;
                nlo[k] = nhi[k] - depth;
            }
            let s = if uniform(state) < 0.3 {
                grid_shape(nlo, nhi, 2 + below(state, 2) as u32)
            } else {
                aabb_shape(nlo, nhi)
            };
            (s, format!("beside axis {k} gap {gap:.2e}"))
        }
        // Sharing an edge or a corner.
        5 | 6 => {
            let f = &base.faces[below(state, base.faces.len())];
            let i = below(state, f.len());
            let a = base.points[f[i]];
            let b = base.points[f[(i + 1) % f.len()]];
            let h = size * log_uniform(state, 0.05, 1.0);
            let dir = |p: [f64; 3], state: &mut u64| -> [f64; 3] {
                let d = unit(std::array::from_fn(|k| p[k] - c[k]));
                std::array::from_fn(|k| p[k] + h * (d[k] + 0.6 * (2.0 * uniform(state) - 1.0)))
            };
            if uniform(state) < 0.5 {
                let m = std::array::from_fn(|k| f64::midpoint(a[k], b[k]));
                let (p, r) = (dir(m, state), dir(m, state));
                (tet_shape([a, b, p, r]), "on an edge".into())
            } else {
                let (p, r, s) = (dir(a, state), dir(a, state), dir(a, state));
                (tet_shape([a, p, r, s]), "on a corner".into())
            }
        }
        // Near-coincident: the base moved or scaled by 1e-12..1e-6 of itself.
        7 => {
            let e = log_uniform(state, 1e-12, 1e-6);
            let mut s = base.clone();
            if uniform(state) < 0.5 {
                let d = unit(random_point(state, [0.0; 3], 1.0));
                for p in &mut s.points {
                    *p = std::array::from_fn(|k| p[k] + e * size * d[k]);
                }
            } else {
                let t = if uniform(state) < 0.5 {
                    1.0 + e
                } else {
                    1.0 - e
                };
                for p in &mut s.points {
                    *p = std::array::from_fn(|k| c[k] + t * (p[k] - c[k]));
                }
            }
            s.aabb = None;
            (s, format!("near {e:.2e}"))
        }
        // Tiny, at a corner of the base.
        8 => {
            let p = base.points[below(state, base.points.len())];
            let t = log_uniform(state, 1e-4, 1e-2);
            (
                random_shape(state, p, t * size),
                format!("tiny {t:.2e} at a corner"),
            )
        }
        // Cutting it obliquely, or apart.
        _ => {
            let p = random_point(state, c, size * 1.5);
            let t = log_uniform(state, 0.2, 1.0);
            (random_shape(state, p, t * size), "cutting".into())
        }
    }
}

/// Where the unit frame goes: x ↦ x·scale + offset, mirrored in x or not, rounded to f32 or not.
#[derive(Clone, Copy, Debug)]
struct Place {
    scale: f64,
    offset: [f64; 3],
    mirrored: bool,
    f32: bool,
}

impl Place {
    fn at(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| {
            let x = p[k] * self.scale + self.offset[k];
            let x = if self.mirrored && k == 0 { -x } else { x };
            if self.f32 {
                f64::from(x as f32)
            } else {
                x
            }
        })
    }
}

/// Exactly: the n·x − d of the point for the outward plane of (a, b, c).
fn side_of(a: &V, b: &V, c: &V, p: &V) -> Q {
    let (n, d) = plane(a, b, c);
    vdot(&n, p) - d
}

/// The shape placed and triangulated, wound outward: each quad split along the diagonal that keeps
/// it convex (either, at random, when flat), larger faces fanned. `None` when what the rounding
/// left is not a convex solid.
fn triangulate(s: &Shape, place: &Place, state: &mut u64) -> Option<Mesh> {
    let points: Vec<[f64; 3]> = s.points.iter().map(|&p| place.at(p)).collect();
    let qp: Vec<V> = points.iter().map(|p| p.map(q)).collect();
    let n = qp.len();
    let count = Q::from_integer(BigInt::from(n));
    let g: V = std::array::from_fn(|m| qp.iter().fold(Q::zero(), |s, p| s + &p[m]) / &count);
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for f in &s.faces {
        // Outward: the centre below the face's plane (through three of its corners).
        let mut f = f.clone();
        let mut turned = None;
        'find: for i in 0..f.len() {
            for j in i + 1..f.len() {
                for k in j + 1..f.len() {
                    let v = side_of(&qp[f[i]], &qp[f[j]], &qp[f[k]], &g);
                    if !v.is_zero() {
                        turned = Some(v.is_positive());
                        break 'find;
                    }
                }
            }
        }
        // Whether the order i < j < k turns the same way as the cycle: true for a convex cycle.
        if turned? {
            f.reverse();
        }
        let u = |i: usize| f[i] as u32;
        if f.len() == 4 {
            let s = side_of(&qp[f[0]], &qp[f[1]], &qp[f[2]], &qp[f[3]]);
            let first = if s.is_zero() {
                uniform(state) < 0.5
            } else {
                s.is_negative()
            };
            if first {
                tris.extend([[u(0), u(1), u(2)], [u(0), u(2), u(3)]]);
            } else {
                tris.extend([[u(0), u(1), u(3)], [u(1), u(2), u(3)]]);
            }
        } else {
            for w in 1..f.len() - 1 {
                tris.push([u(0), u(w), u(w + 1)]);
            }
        }
    }
    // Convex, closed up to its triangulation, and solid: every corner on the inner side of every
    // triangle's plane, no triangle degenerate, a positive volume.
    for t in &tris {
        let [a, b, c] = t.map(|i| &qp[i as usize]);
        let (nn, d) = plane(a, b, c);
        if nn.iter().all(Zero::is_zero) {
            return None;
        }
        if qp.iter().any(|p| vdot(&nn, p) > d) {
            return None;
        }
    }
    let m = (points, tris);
    if !common::exact_integrals(&m.0, &m.1)[0].is_positive() {
        return None;
    }
    Some(m)
}

/// One random case: its parts and where they are.
struct Case {
    parts: Vec<Part>,
    place: Place,
}

fn random_case(seed: u64) -> Option<Case> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let state = &mut state;
    for _ in 0..4 {
        uniform(state);
    }
    let count = 2 + below(state, 4);
    let scale = log_uniform(state, 1e-3, 1e2);
    let offset: [f64; 3] = std::array::from_fn(|_| match below(state, 3) {
        0 => 0.0,
        1 => log_uniform(state, 1e-3, 1e5) * if uniform(state) < 0.5 { -1.0 } else { 1.0 },
        _ => (uniform(state) * 1e5).round(),
    });
    let far = offset.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let place = Place {
        scale,
        offset,
        mirrored: uniform(state) < 0.3,
        f32: uniform(state) < 0.3 && far < scale * 1e3,
    };
    let mut shapes: Vec<(Shape, String)> = Vec::new();
    let first = random_shape(state, [0.5; 3], 0.4);
    shapes.push((first, "first".into()));
    while shapes.len() < count {
        let j = below(state, shapes.len());
        let (s, how) = related_shape(state, &shapes[j].0);
        shapes.push((s, format!("{how} of {j}")));
    }
    let mut parts = Vec::new();
    for (s, how) in &shapes {
        let Some(mesh) = triangulate(s, &place, state) else {
            continue;
        };
        // `OUTWARD=1`: every part outward (the ladder then turns nothing round).
        let inward = uniform(state) < 0.3 && std::env::var_os("OUTWARD").is_none();
        parts.push(Part {
            mesh,
            inward,
            label: format!(
                "{}{} ({how})",
                s.family,
                if inward { " inward" } else { "" }
            ),
        });
    }
    (parts.len() >= 2).then_some(Case { parts, place })
}

/// The outcome of one case.
enum Outcome {
    /// Ω is empty (every part cancelled).
    Empty,
    /// The ladder gave no solid.
    Refused(String),
    /// The errors (volume, inertia, relative; centre, m) and the estimates (relative; centre, m).
    Checked {
        volume: f64,
        inertia: f64,
        com: f64,
        estimate: f64,
        com_estimate: f64,
        value: f64,
        exact: f64,
        /// The ladder turned faces or shells round (its warnings say so).
        turned: bool,
    },
}

/// The parts as one mesh, through the ladder.
fn solid(case: &Case) -> Result<urdf_inertia::mesh::health::Solid, String> {
    let list: Vec<(&Mesh, bool)> = case.parts.iter().map(|p| (&p.mesh, p.inward)).collect();
    let (vertices, tris) = together(&list);
    let raw = urdf_inertia::mesh::RawMesh {
        vertices,
        faces: urdf_inertia::mass::Polygons::from_triangles(&tris),
        ..Default::default()
    };
    urdf_inertia::mesh::solid_from_raw(
        &raw,
        [1.0; 3],
        std::path::Path::new("union.stl"),
        HealthOptions::default(),
    )
    .map_err(|e| format!("{e}"))
}

fn run(case: &Case) -> Outcome {
    let t = omega_integrals(&case.parts);
    if !t[0].is_positive() {
        return Outcome::Empty;
    }
    let s = match solid(case) {
        Ok(s) => s,
        Err(e) => return Outcome::Refused(e),
    };
    let exact = common::exact_mass(&t);
    Outcome::Checked {
        volume: common::rel_error(s.unit.mass, &exact.volume),
        inertia: common::inertia_error(&s.unit.inertia, &exact.inertia),
        com: common::com_error(s.unit.com, &exact.com, 1.0),
        estimate: s.error_estimate,
        com_estimate: s.error.com,
        value: s.unit.mass,
        exact: exact.volume.to_f64().unwrap_or(f64::NAN),
        turned: s.warnings.iter().any(|w| {
            ["flipped", "re-oriented", "turned round"]
                .iter()
                .any(|k| w.text.contains(k))
        }),
    }
}

fn describe(seed: u64, case: &Case) -> String {
    let mut out = format!("seed {seed}: {:?}", case.place);
    for (i, p) in case.parts.iter().enumerate() {
        let _ = write!(out, "\n  {i}: {}", p.label);
    }
    out
}

/// Tallies of a run of cases.
#[derive(Default)]
struct Tally {
    checked: usize,
    empty: usize,
    refused: usize,
    skipped: usize,
    off: usize,
    turned: usize,
    worst: (f64, String),
    worst_kept: (f64, String),
    /// Breaches where the ladder turned no face round.
    breaches: Vec<String>,
    /// Breaches where it did: the known breach of turned shells (see
    /// `a_shell_turned_round_around_a_cavity_is_within_the_estimate`).
    breaches_turned: usize,
}

impl Tally {
    fn case(&mut self, seed: u64, verbose: bool) {
        let Some(case) = random_case(seed) else {
            self.skipped += 1;
            return;
        };
        match run(&case) {
            Outcome::Empty => self.empty += 1,
            Outcome::Refused(e) => {
                self.refused += 1;
                if verbose {
                    eprintln!("refused: {}: {e}", describe(seed, &case));
                }
            }
            Outcome::Checked {
                volume,
                inertia,
                com,
                estimate,
                com_estimate,
                value,
                exact,
                turned,
            } => {
                self.checked += 1;
                if turned {
                    self.turned += 1;
                }
                if volume.max(inertia) > 1e-14 {
                    self.off += 1;
                }
                let line = format!(
                    "{}\n  volume {value:e} (exact {exact:e}): error {volume:e}, inertia {inertia:e}, estimate {estimate:e}; centre {com:e}, estimate {com_estimate:e}",
                    describe(seed, &case)
                );
                let ratio = (volume / estimate)
                    .max(inertia / estimate)
                    .max(com / com_estimate);
                let tag = if turned { " (turned)" } else { "" };
                if ratio.is_nan() || ratio > 1.0 {
                    eprintln!("BREACH{tag} ratio {ratio:.2e} {line}");
                    if turned {
                        self.breaches_turned += 1;
                    } else {
                        self.breaches.push(line.clone());
                    }
                } else if verbose {
                    eprintln!("{line}");
                }
                if !turned && (ratio > self.worst_kept.0 || ratio.is_nan()) {
                    self.worst_kept = (ratio, line.clone());
                }
                if ratio > self.worst.0 || ratio.is_nan() {
                    self.worst = (ratio, line);
                }
            }
        }
    }

    fn report(&self) {
        eprintln!(
            "{} checked ({} more than 1e-14 off), {} with Ω empty, {} refused, {} not made; the largest error / estimate {:e}: {}",
            self.checked, self.off, self.empty, self.refused, self.skipped, self.worst.0, self.worst.1
        );
        eprintln!(
            "{} breaches where the ladder turned no face round, {} where it did ({} cases turned); without turning, the largest error / estimate {:e}: {}",
            self.breaches.len(), self.breaches_turned, self.turned, self.worst_kept.0, self.worst_kept.1
        );
    }
}

/// The reference: a part alone is its mesh's own integrals; a part with its copy shrunk inside it
/// and wound inward is the shell between; two parts touching along a face have no intersection.
#[test]
fn the_exact_reference_agrees_with_the_meshes() {
    let place = Place {
        scale: 1.0,
        offset: [0.0; 3],
        mirrored: false,
        f32: false,
    };
    let mut state = 7;
    for seed in 0..20u64 {
        let mut st = seed * 31 + 1;
        let s = random_shape(&mut st, [0.5; 3], 0.4);
        let Some(m) = triangulate(&s, &place, &mut state) else {
            continue;
        };
        let own = common::exact_integrals(&m.0, &m.1);
        let part = Part {
            mesh: m,
            inward: false,
            label: String::new(),
        };
        assert_eq!(integrals(&part.poly()), own);
        assert_eq!(omega_integrals(&[part]), own, "{}", s.family);
    }
    let outer = common::box_at([0.0; 3], [1.0; 3]);
    let inner = common::box_at([0.25; 3], [0.5; 3]);
    let side = common::box_at([1.0, 0.2, 0.3], [1.5, 0.7, 0.9]);
    let part = |m: &Mesh, inward| Part {
        mesh: m.clone(),
        inward,
        label: String::new(),
    };
    let v = |m: &Mesh| common::exact_integrals(&m.0, &m.1)[0].clone();
    assert_eq!(
        omega_integrals(&[part(&outer, false), part(&inner, true)])[0],
        v(&outer) - v(&inner)
    );
    assert_eq!(
        omega_integrals(&[part(&outer, false), part(&inner, false)])[0],
        v(&outer)
    );
    assert_eq!(
        omega_integrals(&[part(&outer, true), part(&inner, true)])[0],
        v(&outer)
    );
    assert_eq!(
        omega_integrals(&[part(&outer, false), part(&side, true)])[0],
        v(&outer) + v(&side)
    );
}

/// Cases 1 to 60 of the sweep: every error within the estimate, also where the ladder turned faces
/// round (case 14, three boxes wound inward, two of them 1e-12 and 1.6e-9 from the first, and a
/// tetrahedron on an edge, was 3.8e-2 off under 2.1e-3 until a copy of a face was turned with it).
/// The long sweep counts those apart (`breaches_turned`): case 587 of 1–1500 was one until the
/// round-off of solids decided by the winding number was bounded face by face
/// (`thin_solids_of_turned_shells_are_within_the_round_off_bound`).
#[test]
fn unions_of_convex_parts_are_within_the_estimate() {
    let mut tally = Tally::default();
    for seed in 1..=60u64 {
        tally.case(seed, false);
    }
    tally.report();
    assert!(tally.breaches.is_empty(), "{}", tally.breaches.join("\n"));
    assert_eq!(tally.breaches_turned, 0, "a breach where faces were turned");
    assert!(tally.turned >= 20, "too few cases turned: {}", tally.turned);
    assert!(tally.checked >= 40, "too few cases checked");
}

/// The long sweep: `CASES=n` cases from `FROM=m` (default 1..=5000), `SEED=n` one case alone,
/// printed whole; `OUTWARD=1` winds every part outward.
#[test]
#[ignore = "long: run by hand"]
fn union_sweep() {
    let var = |k: &str| std::env::var(k).ok().map(|x| x.parse::<u64>().unwrap());
    let mut tally = Tally::default();
    if let Some(seed) = var("SEED") {
        tally.case(seed, true);
    } else {
        let from = var("FROM").unwrap_or(1);
        let cases = var("CASES").unwrap_or(5000);
        for seed in from..from + cases {
            tally.case(seed, false);
            if seed % 500 == 0 {
                tally.report();
            }
        }
    }
    tally.report();
    eprintln!("{} breaches", tally.breaches.len());
    for b in &tally.breaches {
        eprintln!("{b}");
    }
}

/// A sampled check of the exact volume (for a case that looks wrong): the fraction of random
/// points of the parts' box where |Σ sᵢ [x ∈ Pᵢ]| ≥ 1.
fn sampled_volume(case: &Case, samples: usize) -> (f64, f64) {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in &case.parts {
        let (a, b) = p.bounds();
        for k in 0..3 {
            lo[k] = lo[k].min(a[k]);
            hi[k] = hi[k].max(b[k]);
        }
    }
    // Relative to the box's corner, in f64: planes n·(x − lo) ≤ d.
    let planes: Vec<Vec<([f64; 3], f64)>> = case
        .parts
        .iter()
        .map(|p| {
            p.mesh
                .1
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| {
                        let v = p.mesh.0[i as usize];
                        std::array::from_fn::<f64, 3, _>(|k| v[k] - lo[k])
                    });
                    let u: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
                    let v: [f64; 3] = std::array::from_fn(|k| c[k] - a[k]);
                    let n = [
                        u[1] * v[2] - u[2] * v[1],
                        u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0],
                    ];
                    (n, n[0] * a[0] + n[1] * a[1] + n[2] * a[2])
                })
                .collect()
        })
        .collect();
    let mut state = 12345u64;
    let mut hits = 0usize;
    for _ in 0..samples {
        let x: [f64; 3] = std::array::from_fn(|k| (hi[k] - lo[k]) * uniform(&mut state));
        let w: i32 = case
            .parts
            .iter()
            .zip(&planes)
            .filter(|(_, pl)| {
                pl.iter()
                    .all(|(n, d)| n[0] * x[0] + n[1] * x[1] + n[2] * x[2] <= *d)
            })
            .map(|(p, _)| if p.inward { -1 } else { 1 })
            .sum();
        if w != 0 {
            hits += 1;
        }
    }
    let vol = (0..3).map(|k| hi[k] - lo[k]).product::<f64>();
    let f = hits as f64 / samples as f64;
    (vol * f, vol * (f * (1.0 - f) / samples as f64).sqrt())
}

/// `SEED=n` with the sampled volume beside the exact one.
#[test]
#[ignore = "by hand"]
fn sampled() {
    let seed: u64 = std::env::var("SEED").unwrap().parse().unwrap();
    let case = random_case(seed).expect("made");
    let t = omega_integrals(&case.parts);
    let (v, sd) = sampled_volume(&case, 4_000_000);
    eprintln!(
        "{}\nexact {:e}, sampled {v:e} ± {sd:e}",
        describe(seed, &case),
        t[0].to_f64().unwrap()
    );
}

/// Case `seed` with only the parts that `keep` keeps (by their place in the case).
fn case_with(seed: u64, keep: impl Fn(usize) -> bool) -> Case {
    let mut case = random_case(seed).expect("made");
    let parts = std::mem::take(&mut case.parts);
    case.parts = (parts.into_iter().enumerate())
        .filter(|(i, _)| keep(*i))
        .map(|(_, p)| p)
        .collect();
    case
}

/// `SEED=n KEEP=0,2` runs case n with only those parts (to minimise a breach); `OFFSET=0` moves it
/// back to the origin (as it was made, then shifted in f64).
#[test]
#[ignore = "by hand"]
fn subset() {
    let seed: u64 = std::env::var("SEED").unwrap().parse().unwrap();
    let keep: Option<Vec<usize>> = std::env::var("KEEP")
        .ok()
        .map(|keep| keep.split(',').map(|x| x.parse().unwrap()).collect());
    let mut case = case_with(seed, |i| keep.as_ref().is_none_or(|k| k.contains(&i)));
    if std::env::var("FLIP").is_ok() {
        for p in &mut case.parts {
            p.inward = !p.inward;
        }
    }
    if std::env::var("SHIFT").is_ok() {
        let o = case.place.offset.map(f64::floor);
        for p in &mut case.parts {
            for v in &mut p.mesh.0 {
                *v = std::array::from_fn(|k| v[k] - o[k]);
            }
        }
    }
    if std::env::var("DUMP").is_ok() {
        for p in &case.parts {
            eprintln!("inward {}: {:?}\n{:?}", p.inward, p.mesh.0, p.mesh.1);
        }
    }
    if std::env::var("WARN").is_ok() {
        let list: Vec<(&Mesh, bool)> = case.parts.iter().map(|p| (&p.mesh, p.inward)).collect();
        let m = together(&list);
        let s = common::shells::solid_with(&m, HealthOptions::default(), "x.stl");
        eprintln!(
            "rung {:?} error {:?}\n warnings {:?}\n notes {:?}",
            s.rung, s.error, s.warnings, s.notes
        );
    }
    let line = match run(&case) {
        Outcome::Checked {
            volume,
            inertia,
            com,
            estimate,
            com_estimate,
            value,
            exact,
            turned,
        } => format!("volume {value:e} (exact {exact:e}): error {volume:e}, inertia {inertia:e}, estimate {estimate:e}; centre {com:e}, estimate {com_estimate:e}; turned {turned}"),
        Outcome::Empty => "empty".into(),
        Outcome::Refused(e) => format!("refused {e}"),
    };
    eprintln!("{}\n{line}", describe(seed, &case));
}

fn part(mesh: Mesh, inward: bool) -> Part {
    Part {
        mesh,
        inward,
        label: String::new(),
    }
}

fn check(parts: Vec<Part>) -> Option<(f64, f64)> {
    let case = Case {
        parts,
        place: Place {
            scale: 1.0,
            offset: [0.0; 3],
            mirrored: false,
            f32: false,
        },
    };
    match run(&case) {
        Outcome::Checked {
            volume,
            inertia,
            estimate,
            ..
        } => Some((volume.max(inertia), estimate)),
        _ => None,
    }
}

/// The parts' error, asserted within the estimate.
fn within(parts: Vec<Part>) -> f64 {
    let Some((volume, estimate)) = check(parts) else {
        panic!("no solid");
    };
    assert!(
        volume <= estimate,
        "error {volume:e}, estimate {estimate:e}"
    );
    volume
}

fn tet4(p: [[f64; 3]; 4]) -> Mesh {
    let place = Place {
        scale: 1.0,
        offset: [0.0; 3],
        mirrored: false,
        f32: false,
    };
    triangulate(&tet_shape(p), &place, &mut 1).expect("a tetrahedron")
}

/// A tetrahedron and a copy of it moved by `d` (1e-13 to 1e-9 m), beside a tetrahedron with another
/// on one of its faces (a face and its reverse, which sends the mesh to the tolerant weld): the
/// weld puts the copy's corners on the first's and drops its faces as copies, while Ω holds both
/// (1.2e-9 of the volume off at d = 1e-9 under an estimate of 1.8e-15 before the copies' distance
/// was in the bound, sweep case 13 in its minimal form).
#[test]
fn copies_welded_from_apart_are_within_the_estimate() {
    for o in [0.0, 0.7, 100.0, 1e4] {
        for d in [1e-13, 1e-12, 1e-11, 1e-10, 1e-9] {
            let at = |p: [f64; 3]| p.map(|x| x + o);
            let a = tet4([
                at([0.0, 0.0, 0.0]),
                at([1.0, 0.1, 0.0]),
                at([0.2, 0.9, 0.1]),
                at([0.3, 0.3, 0.8]),
            ]);
            let f = a.1[0].map(|i| a.0[i as usize]);
            let on_face = tet4([f[0], f[1], f[2], at([0.4, 0.3, -0.7])]);
            let b = tet4([
                at([2.0, 0.0, 0.0]),
                at([3.0, 0.1, 0.0]),
                at([2.2, 0.9, 0.1]),
                at([2.3, 0.3, 0.8]),
            ]);
            let mut c = b.clone();
            c.0.iter_mut().for_each(|p| p[1] += d);
            let parts = vec![
                part(a, false),
                part(on_face, false),
                part(b, false),
                part(c, false),
            ];
            let case = Case {
                parts,
                place: Place {
                    scale: 1.0,
                    offset: [o; 3],
                    mirrored: false,
                    f32: false,
                },
            };
            let Outcome::Checked {
                volume,
                inertia,
                com,
                estimate,
                com_estimate,
                ..
            } = run(&case)
            else {
                panic!("o {o}, d {d:e}: no solid");
            };
            assert!(
                volume <= estimate && inertia <= estimate && com <= com_estimate,
                "o {o}, d {d:e}: volume {volume:e}, inertia {inertia:e}, estimate {estimate:e}; centre {com:e}, estimate {com_estimate:e}"
            );
        }
    }
}

/// Sweep cases that were off before the copies and the collapsed faces of the tolerant weld were in
/// the bound: case 13 (a tetrahedron and a copy of it moved by 1.1e-8 of the part, welded together
/// and the copy dropped: 4.5e-10 of the volume off under 6.8e-14) and case 331 (a tetrahedron 5 mm
/// across at a corner of one 47 m across, with a prism on its face, all rounded to f32, welded
/// flat by the weld's tolerance of 3.9 mm and left out of the topology, while the stored integral
/// counts their overlap twice: 4.1e-13 off under 1.4e-15).
///
/// And case 1002, a breach where the ladder turned faces round (so the sweep only counted it): two
/// grid boxes wound inward 1.8e-12 apart, welded into one whose faces are each stored twice, a
/// small rotated box at a corner and a tetrahedron on an edge. The non-manifold rung turned the
/// kept box outward while its dropped copies were put back as stored, inward: the two cancelled and
/// Ω lost the box, 0.17 m³ against 20,933 under an estimate of 7.1e-3. A copy is now turned with
/// the face it copies. And case 2616 whole (see `a_wall_between_bodies_that_overlap_is_put_back`),
/// and case 4137, which putting walls back first broke: pieces of a wall made shells closed up to
/// cracks that nesting turned on their own (1.9e-8 off under 1.3e-8); the walls' answer is now
/// refused where a shell with a wall among its faces was turned or dropped whole (and the counts
/// of shells turned and dropped differ from the answer without them). And case 56891, which that
/// guard broke in session 44: three grid boxes within 1e-10 of each other, f32, wound inward,
/// outward and inward, whose faces the weld drops in 384 cancelling pairs, with two inward boxes.
/// With the walls put back every edge of the three boxes is used six times, so each of their faces
/// is a shell of its own, and an inward box inside them was decided by nesting with none of those
/// faces' boxes around it: counted once more, 3.3e-5 off under 2.3e-12. The faces' group (open
/// shells joined by their shared edges, balanced) now reaches over its box, and the inward box is
/// decided face by face with it: right to 1e-9 (the answer without the walls, with the counts
/// guard, was right too but charged 26 pairs).
#[test]
fn sweep_cases_once_off_are_within_the_estimate() {
    let mut tally = Tally::default();
    for seed in [13, 331, 1002, 2616, 4137, 56891] {
        tally.case(seed, false);
    }
    assert!(tally.breaches.is_empty(), "{}", tally.breaches.join("\n"));
    let (error, estimate, _) = checked_within(&random_case(56891).expect("made"), "56891");
    assert!(
        error < 1e-9,
        "56891: error {error:e} (estimate {estimate:e})"
    );
    assert_eq!(tally.breaches_turned, 0);
    assert_eq!(tally.checked, 6);
}

/// Sweep cases 587, 1654, 1725 and 4371: shells an ulp or a few apart, wound against each other,
/// leave thin solids whose faces the ladder turned or dropped whole. The faces it emits are Ω's
/// boundary to 1e-16 (their exact rational integrals against Ω's), so what is off is the kernel's
/// arithmetic alone: about the box's centre the faces' contributions cancel by a factor of a
/// thousand, and the inertia came out 1.9e-15 to 4.3e-13 off, 1.2 to 2.75 times the round-off
/// estimate that compares two reference points. The bound added up face by face
/// (`health::model::round_off_bound`) is taken where the winding number decided the faces: every
/// error within it, and the bound above the floor (it is what carries the case) but below 1e-9.
/// Since session 44 case 1725 takes the walls' answer (20 faces of cancelling pairs put back, 29
/// triangles cut; before, the pairs were charged and its estimate was unbounded): its faces are cut at
/// rounded points, so its surface is Ω's boundary up to the cuts' rounding, within the model term
/// (inertia 4.0e-11 against 1.4e-9), and its value still within the round-off bound.
#[test]
fn thin_solids_of_turned_shells_are_within_the_round_off_bound() {
    for seed in [587, 1654, 1725, 4371] {
        let case = random_case(seed).expect("made");
        let exact = common::exact_mass(&omega_integrals(&case.parts));
        let s = solid(&case).expect("a solid");
        // The emitted surface is Ω's boundary: its exact integrals are Ω's to 1e-15, or within the
        // model term where faces were cut at rounded points.
        let tris = s.faces.triangles();
        let surface = common::exact_mass(&common::exact_integrals(&s.vertices, &tris));
        let surface_inertia: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| surface.inertia[i][j].to_f64().unwrap())
        });
        let volume = surface.volume.to_f64().unwrap();
        let cut = s.warnings.iter().any(|w| w.text.contains("cut by others"));
        assert_eq!(cut, seed == 1725, "seed {seed}");
        let allowed = if cut { s.error.model } else { 1e-15 };
        let surface_error = common::rel_error(volume, &exact.volume)
            .max(common::inertia_error(&surface_inertia, &exact.inertia));
        assert!(
            surface_error < allowed,
            "seed {seed}: surface {surface_error:e}, allowed {allowed:e}"
        );
        let inertia = common::inertia_error(&s.unit.inertia, &exact.inertia);
        let volume = common::rel_error(s.unit.mass, &exact.volume);
        assert!(
            inertia.max(volume) <= s.error.round_off,
            "seed {seed}: inertia {inertia:e}, volume {volume:e}, round-off {:e}",
            s.error.round_off
        );
        assert!(
            s.error.round_off > 10.0 * urdf_inertia::mesh::health::ROUND_OFF_FLOOR
                && s.error.round_off < 1e-9,
            "seed {seed}: round-off {:e}",
            s.error.round_off
        );
    }
}

/// A breach found by the sweep, now within the estimate: a box wound inward, a tetrahedron wound outward inside it with an
/// edge on its side x = 1, and a box outside on that side whose edge is the tetrahedron's. Ω is
/// the box less the tetrahedron (w = 0 there) and the outer box: 1.015. The shared edge (four
/// faces) makes the mesh non-manifold; the ladder's orientation (`closed::outward` and
/// `turned_components`: the surface is inward in all, so every component is turned, and those
/// then wound inward turned back, the tetrahedron at depth 0 as it is not closed over manifold
/// edges) turns the large box alone, which makes w = 2 in the tetrahedron, and charges nothing:
/// only a component turned against the file inside another's box is charged (`nested`), while
/// here the component turned encloses the one whose w changes. The shells are then decided face by
/// face as classified (the cluster balances so, so the stored orientation is not restored):
/// 1.015625, 6.2e-4 off under an estimate of 9.1e-13. Now every component turned against the
/// reference whose box overlaps another's is charged twice its volume (`closed::outward`).
#[test]
fn a_shell_turned_round_around_a_cavity_is_within_the_estimate() {
    let a = common::box_at([0.0; 3], [1.0; 3]);
    let t = tet4([
        [1.0, 0.5, 0.25],
        [1.0, 0.5, 0.5],
        [0.8, 0.45, 0.4],
        [0.9, 0.55, 0.35],
    ]);
    let b = common::box_at([1.0, 0.5, 0.25], [1.25, 0.75, 0.5]);
    within(vec![part(a, true), part(b, false), part(t, false)]);
}

/// The same breach's other path, now fixed: a closed, consistently wound mesh of a box and a box
/// wound inward that cuts it. Ω is their symmetric difference (w = 0 in both): 1.0. The clean
/// rung's `closed::misoriented` turns every component wound inward at an even nesting depth by
/// boxes (here 0: the inward box is not inside the other's box) and charges nothing (the model is
/// the cracks' alone), so w = 2 in the intersection and the shells, decided as classified, give
/// the union: 1.125. Now a component whose box overlaps another's is left as stored and the shells'
/// classification decides Ω (`tests/closed_overlap.rs` has the same case, and one around a part).
#[test]
fn an_inward_shell_cutting_another_is_within_the_estimate() {
    let a = common::box_at([0.0; 3], [1.0; 3]);
    let b = common::box_at([0.5, 0.25, 0.25], [1.5, 0.75, 0.75]);
    within(vec![part(a, false), part(b, true)]);
}

/// A second breach, now fixed (sweep case 3657 in its minimal form): a box stored twice (every
/// face twice, the same way round) and a box wound inward inside it. w is 2 − 1 = 1 inside the inner
/// box, so Ω is the outer box: 1. The weld drops the copies ("the copies would count their volume
/// twice"), which lowers w by 1 everywhere inside the box, and the inner box, then a cavity, was
/// decided by nesting alone, where the copies were not put back (only the shells decided face by
/// face counted them): 0.875, 0.125 off under an estimate of about 1e-15. Now a shell with copies
/// whose box overlaps another's is decided face by face, its copies put back: the value is exact.
#[test]
fn a_doubled_shell_around_a_cavity_is_within_the_estimate() {
    let a = common::box_at([0.0; 3], [1.0; 3]);
    let b = common::box_at([0.25; 3], [0.75; 3]);
    let volume = within(vec![part(a.clone(), false), part(a, false), part(b, true)]);
    assert!(volume < 1e-14, "error {volume:e}");
}

/// A breach found by the sweep (case 2616 less its inward tetrahedron), now fixed: a grid box, a
/// prism on one of its faces and a second prism on a face of the first, which reaches back into
/// the box. Each prism's base is a face of the part below it, reversed: the weld drops each such
/// pair (a wall of no thickness, which cancels), and the three bodies become one closed shell
/// that cuts itself where the second prism enters the box. That shell alone was integrated as ∫w,
/// counting the overlap twice: 1.7e-4 of the volume off under an estimate of 1.7e-15. The walls are
/// now put back where shells are classified, so the bodies are shells of their own and are
/// decided face by face.
#[test]
fn a_wall_between_bodies_that_overlap_is_put_back() {
    let case = case_with(2616, |i| i != 2);
    assert!(case.parts.iter().all(|p| !p.inward));
    let Outcome::Checked {
        volume,
        inertia,
        estimate,
        turned,
        ..
    } = run(&case)
    else {
        panic!("no solid");
    };
    assert!(!turned);
    assert!(
        volume.max(inertia) <= estimate && volume < 1e-10,
        "error {volume:e} (inertia {inertia:e}), estimate {estimate:e}"
    );
}

/// Breaches until session 38 (sweep cases 11638 and 11883, first found by cases 10001–12500).
/// 11638: two boxes a millimetre across, 1.95e-12 of their size apart, rounded to f32 onto each
/// other but with other diagonals on three sides, and a prism on a face: the faces decided leave
/// the sides with different diagonals doubled, which cancel in the volume's dependence on the
/// reference point (1e-16) but not in the inertia's (5.5%), and the volume was 56% off under an
/// estimate of 5.5%. 11883: inward boxes beside each other, a prism and a pyramid on faces, 3.7%
/// off under 2.4%. Now a disagreement of the inertia beyond 1% is as one of the volume: the value
/// is not bounded, and a warning says why.
#[test]
fn faces_that_do_not_close_in_their_inertia_are_not_bounded() {
    for (seed, off) in [(11638, 0.5), (11883, 0.03)] {
        let case = random_case(seed).expect("made");
        off_and_unbounded(&case, off, "volume or inertia differs", seed);
    }
}

/// That `case` is more than `off` of its volume off Ω (exact rationals), and that its value is
/// left unbounded with a warning that says `says`; `what` names the case in the messages.
fn off_and_unbounded(case: &Case, off: f64, says: &str, what: impl std::fmt::Display) {
    let Outcome::Checked { volume, .. } = run(case) else {
        panic!("{what}: no solid");
    };
    assert!(volume > off, "{what}: error {volume:e}");
    let s = solid(case).expect("a solid");
    assert!(
        s.error_estimate.is_infinite(),
        "{what}: {:e}",
        s.error_estimate
    );
    assert!(
        s.warnings.iter().any(|w| w.text.contains(says)),
        "{what}: {:?}",
        s.warnings
    );
}

/// Breaches until session 39 (sweep cases 13113 and 14946, found by cases 12501–15000), in their
/// least forms. 14946 (parts 0, 1, 3): an outward box, a tetrahedron on one of its edges, and an
/// inward box 8.9e-12 of their size from the first, 3,231 m from the origin; Ω is about the
/// tetrahedron, 9.0e-6 m³. 13113 (parts 0–3): an inward box and an outward box 5.3e-8 of their
/// size apart and a cancelling pair of tetrahedra on a corner; Ω is the slivers between the boxes,
/// 4.4e-18 m³. The boxes' corners weld in the topology, so every side of a box is a component of
/// its own, and the ladder turned the inward box's sides outward (a side is open: nothing charged
/// it). Their cluster balances both as turned and as stored, and was decided as turned: the union,
/// one box (3.76e-3 m³ under an estimate of 1.5e-8; 2.77e-11 under 5.2e-4). Now a cluster that
/// balances as stored is decided as stored, whose winding number defines Ω, and the values are
/// within their estimates (exact rationals): 14946 2.9e-9 off under 4.3e-4; 13113 not bounded.
/// Case 29472 (found by cases 27501–30000 on that change): an outward box, an inward box inside
/// it and an inward tetrahedron on the inner one's edge. The ladder turned the inner box and the
/// tetrahedron outward (each a component of its own, open at the shared edge), the cluster was
/// decided as stored and every face kept as it came, which `resolve` reported as no change, so
/// the turned faces were integrated: the cavity filled, 5.7% off under 3.1e-14. Now exact.
#[test]
fn boxes_the_ladder_turned_side_by_side_are_decided_as_stored() {
    for (seed, keep) in [
        (14946, &[0, 1, 3][..]),
        (13113, &[0, 1, 2, 3][..]),
        (29472, &[0, 1, 2][..]),
    ] {
        turned_and_within(&case_with(seed, |i| keep.contains(&i)), &seed.to_string());
    }
}

/// Asserts that the ladder turned faces of `case` and that its value is within its estimate
/// (volume and inertia, against exact rationals); the estimate.
fn turned_and_within(case: &Case, what: &str) -> f64 {
    let (_, estimate, turned) = checked_within(case, what);
    assert!(turned, "{what}: the ladder turned no face");
    estimate
}

/// A breach until session 40 (sweep case 37374, found by cases 32501–37500): five parts with f32
/// corners, 34.7 m across. After the rounding the first two boxes are one box with other
/// diagonals, whose faces (each side a shell of its own in a non-manifold cluster) lie flat; the
/// last box's bottom face is one f32 unit below their top faces over its whole 29.6 m² footprint.
/// Shell pairs were only those whose boxes meet in a volume, which a flat face's box never does:
/// the last box was decided whole, the top faces were decided without it, and the slab between,
/// inside both, was counted twice (1.5e-8 off, 5.65e-5 m³, under an estimate of 3.6e-11). A flat
/// open shell across another's box now makes a pair, and the value is exact.
#[test]
fn a_face_one_f32_unit_inside_a_box_is_decided_with_it() {
    let estimate = turned_and_within(&random_case(37374).expect("made"), "37374");
    assert!(estimate < 1e-9, "estimate {estimate:e}");
}

/// A breach until session 43 (found by cases 61501–64000, the same on 424b005): sweep case 63171
/// less its last part, and whole. A grid box, two oblique prisms on the two triangles of one of its
/// face cells (their bases are the box's triangles reversed, so the weld drops the pairs and box
/// and prisms become one closed shell; the prisms lean into each other over their shared edge, so
/// that shell cuts itself), and a small prism inside the first. With the walls put back the prisms'
/// overlap can be decided face by face, but that answer is taken only where it turns and drops as
/// many whole shells as the answer without the walls (`winding_shells::classify`, for case 4137);
/// here it is not, and the shell that cuts itself was integrated as ∫w, the prisms' overlap counted
/// twice: 7.9e-4 of the volume off under an estimate of 6.2e-15 (the whole case: 7.5e-4 under
/// 2.5e-14). Session 43 charged the pairs the walls' answer decided (their boxes' intersections:
/// within, but an estimate of 2.7e-2 for an error of 7.5e-4). Now the walls' answer is refused only
/// where a shell with a wall among its faces was turned or dropped whole, which case 4137 was; here
/// the small prism is decided face by face with the walls and dropped whole without them, so the
/// counts differ but no wall is in a shell changed whole: the prisms' overlap is decided face by face
/// and the value is right to 1e-9 (exact rationals), with and without the small prism.
#[test]
fn prisms_leaning_into_each_other_over_a_dropped_wall_are_within_the_estimate() {
    for keep in [4, 5] {
        let case = case_with(63171, |i| i < keep);
        let (error, estimate, _) = checked_within(&case, &format!("63171, {keep} parts"));
        assert!(
            error < 1e-9,
            "{keep} parts: error {error:e} (estimate {estimate:e})"
        );
    }
}

/// A breach until session 36 (sweep case 3187, whole and less its last two parts): three
/// tetrahedra ~3 cm across, 9,000 m from the origin, stored within about an ulp of each other
/// (1e-11 of their size apart, where an ulp of the coordinates is 6e-11 of it), wound outward,
/// inward and outward. Ω is where w = 1 − 1 + 1 = 1, about the tetrahedron: 2.707e-6 m³. The
/// decided faces did not close: 1.37 of the volume off under an estimate of 0.58 (the round-off
/// term, the faces' dependence on the reference point); the whole case 2.6 of its volume off under
/// 0.61. From session 36 to 40 such a value was left unbounded (the pieces' gap beyond what their
/// rounding allows), taken then for cuts at rounded points. The cause was the faces taken as in
/// one plane: two of the tetrahedra's faces near the plane of a third's did not meet each other,
/// each carried the third's jump, and whole sides were dropped (session 41, sweep case 33740;
/// `faces_near_one_plane_through_a_third_are_decided_as_one_plane` in `correction.rs`). Now the
/// faces near one plane are decided as one plane, and the value is right to 1.3e-10 (exact
/// rationals), within its estimate.
#[test]
fn three_tetrahedra_within_an_ulp_are_within_the_estimate() {
    for keep in [3, 5] {
        let mut case = random_case(3187).expect("made");
        case.parts.truncate(keep);
        let (error, estimate, _) = checked_within(&case, &keep.to_string());
        assert!(error < 1e-9, "{keep}: error {error:e}");
        assert!(estimate.is_finite(), "{keep}: estimate {estimate:e}");
    }
}

/// A breach until session 41 (sweep case 33740, found by cases 32501–35000): a turned box 2.9 mm
/// across, 63 km from the origin, an inward tetrahedron on one of its corners and two tetrahedra
/// 2.6e-12 and 4.7e-10 of their size from that one. Two of the four sides of the tetrahedra were
/// dropped on all three (see `three_tetrahedra_within_an_ulp_are_within_the_estimate`), the
/// surface left open by a face and a half: about the two reference points its inertia differed by
/// 0.42%, carried as round-off, and the inertia was 0.48% off. Now the value is right to 3e-11.
#[test]
fn a_tetrahedron_between_two_others_within_ulps_is_decided_once() {
    let (error, _, _) = checked_within(&random_case(33740).expect("made"), "33740");
    assert!(error < 1e-9, "error {error:e}");
}

/// Known from session 36 to 41, not fixed then: clean closed surfaces whose round-off was beyond
/// the estimate that compared the integrals about two points, which is only a sample of it. Case
/// 10598: two inward tetrahedra 2 mm across touching at a corner, 68,804 m from the origin (rung
/// inverted), volume 4.7ε off under 4.27ε (1.10 times); case 25299: a tetrahedron, one on its
/// corner and a turned box cutting the first, one component (rung exact, nothing classified),
/// central inertia 19ε off under 2.8e-15 (1.49 times). Every solid now reports the kernel's
/// rounding bounded face by face in the pass that integrates (`mass::integrals::Rounding`): each
/// error within it, by a margin (at most a fifth of it), and the bound still tight enough to keep
/// 12 digits.
#[test]
fn clean_surfaces_far_from_the_origin_are_within_the_round_off_bound() {
    for seed in [10598, 25299] {
        let (error, estimate, _) =
            checked_within(&random_case(seed).expect("made"), &seed.to_string());
        assert!(
            error < 0.2 * estimate,
            "{seed}: error {error:e} under {estimate:e}"
        );
        assert!(estimate < 1e-12, "{seed}: estimate {estimate:e}");
    }
}

/// The first part of each of the first 120 sweep cases alone: one closed shell (a box, a rotated
/// box, a tetrahedron, an octahedron, a prism or a grid of boxes, wound either way, up to 83 km from
/// the origin, some of them f32 or mirrored): nothing is classified, and the value is the kernel's
/// integral, within the bound on its rounding (exact rationals).
#[test]
fn single_closed_shells_are_within_the_round_off_bound() {
    let mut checked = 0;
    for seed in 1..=120u64 {
        let Some(case) = random_case(seed) else {
            continue;
        };
        let mut case = case;
        case.parts.truncate(1);
        if let Outcome::Checked { .. } = run(&case) {
            checked_within(&case, &seed.to_string());
            checked += 1;
        }
    }
    assert!(checked >= 100, "{checked} checked");
}

/// A breach until session 42 (sweep case 49295, found by cases 49001–51500, the same on every
/// earlier build): two inward octahedra cutting each other and two tetrahedra ~2 f32 units across,
/// an inward and an outward one stored 1.3e-10 apart, 54 km from the origin. The tolerant weld
/// collapses both tetrahedra; the whole surface is wound inward and flipped. The faces classified
/// kept the collapsed ones in place while the stored orientation they were compared with did not,
/// so from the second octahedron on, each face was compared with another's: the first octahedron
/// was turned back to inward as stored and the second left outward, and the face-by-face decision
/// integrated their overlap as a hole (0.094 m³ of 74.3, 1.3e-3 off, inertia 2.6e-3, under 2.7e-4).
/// Now the stored orientation is the faces' own, face for face.
#[test]
fn octahedra_behind_collapsed_tetrahedra_keep_their_overlap() {
    let mut case = random_case(49295).expect("made");
    let (error, _, turned) = checked_within(&case, "49295");
    assert!(turned && error < 1e-9, "error {error:e}");
    case.parts.remove(0);
    let (error, _, turned) = checked_within(&case, "49295, parts 1-4");
    assert!(turned && error < 1e-9, "parts 1-4: error {error:e}");
}

/// Asserts that `case` has a solid whose volume and inertia are within its estimate (against exact
/// rationals); the larger error, the estimate, and whether the ladder turned faces.
fn checked_within(case: &Case, what: &str) -> (f64, f64, bool) {
    let Outcome::Checked {
        volume,
        inertia,
        estimate,
        turned,
        ..
    } = run(case)
    else {
        panic!("{what}: no solid");
    };
    assert!(
        volume <= estimate && inertia <= estimate,
        "{what}: errors {volume:e} {inertia:e} under {estimate:e}"
    );
    (volume.max(inertia), estimate, turned)
}
