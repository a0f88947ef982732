//! Test helpers: mesh generators and an exact rational reference for the volume integrals.
//!
//! Every f64 is a rational m·2^e. Scaling all coordinates of a mesh by 2^-emin makes them integers, so the
//! divergence-theorem sums (polynomials of degree ≤ 5 in the coordinates) are computed exactly with big
//! integers, independent of the code under test.
#![allow(dead_code)] // each test binary uses a different subset of the helpers

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{ToPrimitive, Zero};
use std::collections::HashMap;

pub mod rational;
pub mod shells;
pub mod wild;
pub mod winding;

/// The workspace's root: these helpers serve the library's tests (manifest at the root) and the
/// command line's (manifest in `cli/`).
pub fn workspace_root() -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    if dir.join("robots").is_dir() {
        dir.to_path_buf()
    } else {
        dir.join("../..")
    }
}

pub type Mesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Decomposes a finite f64 into (mantissa, exponent) with value = mantissa · 2^exponent.
fn decompose(x: f64) -> (i64, i32) {
    if x == 0.0 {
        return (0, 0);
    }
    let bits = x.to_bits();
    let sign = if bits >> 63 == 0 { 1i64 } else { -1 };
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    let (m, e) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1i64 << 52), exp - 1075)
    };
    (sign * m, e)
}

/// The exact integrals `[T1, Tx, Ty, Tz, Tx², Ty², Tz², Txy, Tyz, Tzx]` of a closed triangle mesh about the origin.
pub fn exact_integrals(v: &[[f64; 3]], tris: &[[u32; 3]]) -> [BigRational; 10] {
    exact_integrals_with(v, tris, false)
}

/// The same integrals with every coordinate taken relative to the exact centre of the vertices'
/// bounding box. For a surface that is closed only up to round-off (cracks, slivers), this is its
/// "as stored" value, independent of where the mesh sits; for a closed surface the central inertia
/// is the same either way.
pub fn exact_integrals_about_centre(v: &[[f64; 3]], tris: &[[u32; 3]]) -> [BigRational; 10] {
    exact_integrals_with(v, tris, true)
}

#[allow(clippy::too_many_lines)] // Mirtich's sums in exact arithmetic, written out term by term like the kernel
fn exact_integrals_with(v: &[[f64; 3]], tris: &[[u32; 3]], centred: bool) -> [BigRational; 10] {
    let mut emin = v
        .iter()
        .flatten()
        .filter(|x| **x != 0.0)
        .map(|&x| decompose(x).1)
        .min()
        .unwrap_or(0);
    if centred {
        // One more bit: the centre (lo + hi) / 2 is then an integer too.
        emin -= 1;
    }
    let mut ints: Vec<[BigInt; 3]> = v
        .iter()
        .map(|p| {
            p.map(|x| {
                let (m, e) = decompose(x);
                BigInt::from(m) << ((e - emin) as usize)
            })
        })
        .collect();
    if centred && !ints.is_empty() {
        for k in 0..3 {
            let lo = ints
                .iter()
                .map(|p| &p[k])
                .min()
                .cloned()
                .unwrap_or_default();
            let hi = ints
                .iter()
                .map(|p| &p[k])
                .max()
                .cloned()
                .unwrap_or_default();
            let c: BigInt = (lo + hi) >> 1usize;
            for p in &mut ints {
                p[k] -= &c;
            }
        }
    }
    let mut acc: [BigInt; 10] = std::array::from_fn(|_| BigInt::zero());
    for t in tris {
        let a = &ints[t[0] as usize];
        let b = &ints[t[1] as usize];
        let c = &ints[t[2] as usize];
        let bxc = [
            &b[1] * &c[2] - &b[2] * &c[1],
            &b[2] * &c[0] - &b[0] * &c[2],
            &b[0] * &c[1] - &b[1] * &c[0],
        ];
        let d = &a[0] * &bxc[0] + &a[1] * &bxc[1] + &a[2] * &bxc[2];
        let s: [BigInt; 3] = std::array::from_fn(|k| &a[k] + &b[k] + &c[k]);
        let q = |i: usize, j: usize| &a[i] * &a[j] + &b[i] * &b[j] + &c[i] * &c[j];
        acc[0] += &d;
        for k in 0..3 {
            acc[1 + k] += &d * &s[k];
            acc[4 + k] += &d * (q(k, k) + &s[k] * &s[k]);
            let j = (k + 1) % 3;
            acc[7 + k] += &d * (q(k, j) + &s[k] * &s[j]);
        }
    }
    // Undo the scaling: a term of degree n carries 2^(n·emin).
    let pow2 = |n: i32| -> BigRational {
        let e = n * emin;
        if e >= 0 {
            BigRational::from_integer(BigInt::from(1) << (e as usize))
        } else {
            BigRational::new(BigInt::from(1), BigInt::from(1) << ((-e) as usize))
        }
    };
    let r = |x: &BigInt, deg: i32, div: i64| {
        BigRational::from_integer(x.clone()) * pow2(deg)
            / BigRational::from_integer(BigInt::from(div))
    };
    [
        r(&acc[0], 3, 6),
        r(&acc[1], 4, 24),
        r(&acc[2], 4, 24),
        r(&acc[3], 4, 24),
        r(&acc[4], 5, 120),
        r(&acc[5], 5, 120),
        r(&acc[6], 5, 120),
        r(&acc[7], 5, 120),
        r(&acc[8], 5, 120),
        r(&acc[9], 5, 120),
    ]
}

/// Exact rational of an f64.
pub fn rat(x: f64) -> BigRational {
    BigRational::from_float(x).expect("finite")
}

/// Exact mass, COM and central inertia (density 1) from exact integrals.
pub struct ExactMass {
    pub volume: BigRational,
    pub com: [BigRational; 3],
    pub inertia: [[BigRational; 3]; 3],
}

pub fn exact_mass(t: &[BigRational; 10]) -> ExactMass {
    let v = t[0].clone();
    let com: [BigRational; 3] = std::array::from_fn(|k| &t[1 + k] / &v);
    let c2: [BigRational; 3] = std::array::from_fn(|k| &t[4 + k] - &t[1 + k] * &com[k]);
    let cp: [BigRational; 3] = std::array::from_fn(|k| &t[7 + k] - &t[1 + k] * &com[(k + 1) % 3]);
    let ixx = &c2[1] + &c2[2];
    let iyy = &c2[2] + &c2[0];
    let izz = &c2[0] + &c2[1];
    let ixy = -cp[0].clone();
    let iyz = -cp[1].clone();
    let izx = -cp[2].clone();
    ExactMass {
        volume: v,
        com,
        inertia: [
            [ixx, ixy.clone(), izx.clone()],
            [ixy, iyy, iyz.clone()],
            [izx, iyz, izz],
        ],
    }
}

/// The exact central tensor rounded to f64: the best any f64 result can be.
pub fn rounded(exact: &[[BigRational; 3]; 3]) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| exact[i][j].to_f64().unwrap()))
}

/// The f64 floor: the relative Frobenius error of the correctly rounded exact tensor.
pub fn floor_error(exact: &[[BigRational; 3]; 3]) -> f64 {
    inertia_error(&rounded(exact), exact)
}

/// Relative Frobenius error of a computed central inertia against the exact one.
pub fn inertia_error(got: &[[f64; 3]; 3], exact: &[[BigRational; 3]; 3]) -> f64 {
    let mut num = 0.0;
    let mut den = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let d = (rat(got[i][j]) - &exact[i][j]).to_f64().unwrap();
            let e = exact[i][j].to_f64().unwrap();
            num += d * d;
            den += e * e;
        }
    }
    (num / den).sqrt()
}

/// Relative error of a scalar against an exact rational.
pub fn rel_error(got: f64, exact: &BigRational) -> f64 {
    let e = exact.to_f64().unwrap();
    if e == 0.0 {
        return (rat(got) - exact).to_f64().unwrap().abs();
    }
    ((rat(got) - exact) / exact).to_f64().unwrap().abs()
}

/// COM distance error relative to a length `size`.
pub fn com_error(got: [f64; 3], exact: &[BigRational; 3], size: f64) -> f64 {
    let mut s = 0.0;
    for k in 0..3 {
        let d = (rat(got[k]) - &exact[k]).to_f64().unwrap();
        s += d * d;
    }
    s.sqrt() / size
}

/// The paper's Table 2 series: icosahedron (level 1), each refinement splitting every edge at its midpoint
/// projected onto the unit sphere. Level n has 20·4^(n−1) faces.
pub fn icosphere(level: u32) -> Mesh {
    let p = f64::midpoint(1.0, 5f64.sqrt());
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, p, 0.0],
        [1.0, p, 0.0],
        [-1.0, -p, 0.0],
        [1.0, -p, 0.0],
        [0.0, -1.0, p],
        [0.0, 1.0, p],
        [0.0, -1.0, -p],
        [0.0, 1.0, -p],
        [p, 0.0, -1.0],
        [p, 0.0, 1.0],
        [-p, 0.0, -1.0],
        [-p, 0.0, 1.0],
    ];
    for x in &mut v {
        let n = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        *x = x.map(|c| c / n);
    }
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 1..level {
        let mut cache: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, v: &mut Vec<[f64; 3]>| -> u32 {
            let key = (a.min(b), a.max(b));
            *cache.entry(key).or_insert_with(|| {
                let (pa, pb) = (v[a as usize], v[b as usize]);
                let m = [pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]];
                let n = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                v.push(m.map(|c| c / n));
                (v.len() - 1) as u32
            })
        };
        let mut nf = Vec::with_capacity(f.len() * 4);
        for t in &f {
            let ab = mid(t[0], t[1], &mut v);
            let bc = mid(t[1], t[2], &mut v);
            let ca = mid(t[2], t[0], &mut v);
            nf.push([t[0], ab, ca]);
            nf.push([t[1], bc, ab]);
            nf.push([t[2], ca, bc]);
            nf.push([ab, bc, ca]);
        }
        f = nf;
    }
    (v, f)
}

/// An axis-aligned box with edge lengths `s`, centred at the origin, as 12 outward triangles.
pub fn box_mesh(s: [f64; 3]) -> Mesh {
    let h = s.map(|x| x / 2.0);
    let v: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { -h[0] } else { h[0] },
                if i & 2 == 0 { -h[1] } else { h[1] },
                if i & 4 == 0 { -h[2] } else { h[2] },
            ]
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let f = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (v, f)
}

/// A box from `lo` to `hi` (outward triangles).
pub fn box_at(lo: [f64; 3], hi: [f64; 3]) -> Mesh {
    let (v, f) = box_mesh([hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]]);
    let v = v
        .iter()
        .map(|p| std::array::from_fn(|k| p[k] + f64::midpoint(lo[k], hi[k])))
        .collect();
    (v, f)
}

/// A box from `lo` to `hi` whose every face is an `n` × `n` grid of squares, each two triangles
/// (outward): the same solid as [`box_at`], triangulated otherwise.
pub fn grid_box(lo: [f64; 3], hi: [f64; 3], n: u32) -> Mesh {
    // The last line at `hi` itself (lo + (hi − lo) need not round to it: the faces would not meet).
    let at = |k: usize, i: u32| {
        if i == n {
            hi[k]
        } else {
            lo[k] + (hi[k] - lo[k]) * f64::from(i) / f64::from(n)
        }
    };
    let (mut v, mut f) = (Vec::new(), Vec::new());
    // Each face: the axis it is perpendicular to, its side, and two in-plane axes in the order
    // that makes the grid's squares turn outward.
    for (k, top) in [
        (0, false),
        (0, true),
        (1, false),
        (1, true),
        (2, false),
        (2, true),
    ] {
        let (mut a, mut b) = ((k + 1) % 3, (k + 2) % 3);
        if !top {
            std::mem::swap(&mut a, &mut b);
        }
        let base = v.len() as u32;
        for i in 0..=n {
            for j in 0..=n {
                let mut p = [0.0; 3];
                p[k] = if top { hi[k] } else { lo[k] };
                (p[a], p[b]) = (at(a, i), at(b, j));
                v.push(p);
            }
        }
        let id = |i: u32, j: u32| base + i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
                f.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
            }
        }
    }
    (v, f)
}

/// A closed cylinder along Z with `n` segments (outward triangles).
pub fn cylinder_mesh(r: f64, l: f64, n: u32) -> Mesh {
    let mut v = vec![[0.0, 0.0, -l / 2.0], [0.0, 0.0, l / 2.0]];
    for i in 0..n {
        let a = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(n);
        v.push([r * a.cos(), r * a.sin(), -l / 2.0]);
        v.push([r * a.cos(), r * a.sin(), l / 2.0]);
    }
    let mut f = Vec::new();
    for i in 0..n {
        let j = (i + 1) % n;
        let (b0, t0, b1, t1) = (2 + 2 * i, 3 + 2 * i, 2 + 2 * j, 3 + 2 * j);
        f.push([0, b1, b0]);
        f.push([1, t0, t1]);
        f.push([b0, b1, t1]);
        f.push([b0, t1, t0]);
    }
    (v, f)
}

/// A small deterministic generator (`SplitMix64`) so tests need no rand crate.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
}

/// A random star-shaped closed mesh: an icosphere with each vertex's radius drawn from [0.5, 1.5].
pub fn random_blob(rng: &mut Rng, level: u32) -> Mesh {
    let (mut v, f) = icosphere(level);
    for p in &mut v {
        let r = rng.range(0.5, 1.5);
        *p = p.map(|c| c * r);
    }
    (v, f)
}

/// Rotation matrix from roll, pitch, yaw (fixed axes X, Y, Z).
pub fn rotation(rpy: [f64; 3]) -> [[f64; 3]; 3] {
    urdf_inertia::mass::rpy_matrix(rpy)
}

/// Applies `x ↦ R (s ∘ x) + t` to every vertex (the stored result is what gets integrated, exactly).
pub fn transform(mesh: &Mesh, scale: f64, r: &[[f64; 3]; 3], t: [f64; 3]) -> Mesh {
    let v = mesh
        .0
        .iter()
        .map(|p| {
            let q = p.map(|c| c * scale);
            let y = urdf_inertia::mass::mat_vec(r, q);
            [y[0] + t[0], y[1] + t[1], y[2] + t[2]]
        })
        .collect();
    (v, mesh.1.clone())
}

/// A unit cube (corners 0 and 1) whose faces are all wound inward, as a binary STL at `path`:
/// turned outside out exactly by the repair (UI101), so its bound is round-off.
pub fn inside_out_cube_stl(path: &std::path::Path) {
    let (v, f) = box_mesh([1.0; 3]);
    let v: Vec<[f64; 3]> = v.iter().map(|p| p.map(|x| x + 0.5)).collect();
    let inward: Vec<[u32; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
    std::fs::write(
        path,
        urdf_inertia::mesh::stl::write_binary(b"in", &v, &inward),
    )
    .expect("write the cube");
}
