//! Primitives against their tessellations (moved and rotated), and the algebra of mass properties on
//! random inputs: rotation gives R·I·Rᵀ, composition is additive and order-free, translation moves only
//! the centre of mass, every solid is valid.

mod common;

use common::*;
use urdf_inertia::mass::{mat_mul, primitives, transpose, validity, MassProperties};

fn rel_diff(a: &MassProperties, b: &MassProperties) -> (f64, f64, f64) {
    let dm = (a.mass - b.mass).abs() / b.mass.abs();
    let dc = (0..3)
        .map(|k| (a.com[k] - b.com[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let mut num = 0.0;
    let mut den = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            num += (a.inertia[i][j] - b.inertia[i][j]).powi(2);
            den += b.inertia[i][j].powi(2);
        }
    }
    (dm, dc, (num / den).sqrt())
}

/// A closed surface of revolution about z from a profile (r, z) running from the bottom pole (r = 0) to
/// the top pole (r = 0), with `n` segments around.
fn revolve(profile: &[(f64, f64)], n: u32) -> Mesh {
    let mut v = vec![[0.0, 0.0, profile[0].1]];
    let rings = &profile[1..profile.len() - 1];
    for &(r, z) in rings {
        for i in 0..n {
            let a = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(n);
            v.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    v.push([0.0, 0.0, profile[profile.len() - 1].1]);
    let top = (v.len() - 1) as u32;
    let ring = |k: usize, i: u32| 1 + k as u32 * n + (i % n);
    let mut f = Vec::new();
    for i in 0..n {
        f.push([0, ring(0, i + 1), ring(0, i)]);
        f.push([top, ring(rings.len() - 1, i), ring(rings.len() - 1, i + 1)]);
    }
    for k in 0..rings.len() - 1 {
        for i in 0..n {
            f.push([ring(k, i), ring(k, i + 1), ring(k + 1, i + 1)]);
            f.push([ring(k, i), ring(k + 1, i + 1), ring(k + 1, i)]);
        }
    }
    (v, f)
}

fn capsule_profile(r: f64, l: f64, m: usize) -> Vec<(f64, f64)> {
    let mut p = Vec::new();
    for k in 0..=m {
        let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::FRAC_PI_2 * k as f64 / m as f64;
        p.push((r * a.cos(), -l / 2.0 + r * a.sin()));
    }
    for k in 0..=m {
        let a = std::f64::consts::FRAC_PI_2 * k as f64 / m as f64;
        p.push((r * a.cos(), l / 2.0 + r * a.sin()));
    }
    p[0].0 = 0.0;
    let last = p.len() - 1;
    p[last].0 = 0.0;
    p
}

#[test]
fn primitives_against_their_tessellations_moved_and_rotated() {
    let r = rotation([0.4, -0.9, 2.2]);
    let t = [0.3, -1.2, 5.0];
    // Box: the tessellation is exact.
    let prim = primitives::cuboid([0.2, 0.5, 0.1], 1.0).transformed(&r, t);
    let (v, f) = transform(&box_mesh([0.2, 0.5, 0.1]), 1.0, &r, t);
    let (dm, dc, di) = rel_diff(&MassProperties::from_trimesh(&v, &f, 1.0), &prim);
    // The rotated vertices are rounded to f64, so the stored box differs from the analytic one by ulps.
    assert!(
        dm < 1e-14 && dc < 1e-14 && di < 1e-14,
        "box {dm:e} {dc:e} {di:e}"
    );
    // Cylinder: an n-gon prism converges as O(1/n²).
    let prim = primitives::cylinder(0.05, 0.3, 1.0).transformed(&r, t);
    let (v, f) = transform(&cylinder_mesh(0.05, 0.3, 4096), 1.0, &r, t);
    let (dm, dc, di) = rel_diff(&MassProperties::from_trimesh(&v, &f, 1.0), &prim);
    assert!(
        dm < 1e-6 && dc < 1e-12 && di < 1e-6,
        "cylinder {dm:e} {dc:e} {di:e}"
    );
    // Sphere: an icosphere of 327,680 faces (level 8).
    let prim = primitives::sphere(1.0, 1.0).transformed(&r, t);
    let (v, f) = transform(&icosphere(8), 1.0, &r, t);
    let (dm, _, di) = rel_diff(&MassProperties::from_trimesh(&v, &f, 1.0), &prim);
    assert!(dm < 1e-4 && di < 1e-4, "sphere {dm:e} {di:e}");
    // Capsule (along z): a surface of revolution.
    let prim = primitives::capsule(0.04, 0.1, 1.0).transformed(&r, t);
    let (v, f) = transform(&revolve(&capsule_profile(0.04, 0.1, 512), 2048), 1.0, &r, t);
    let (dm, dc, di) = rel_diff(&MassProperties::from_trimesh(&v, &f, 1.0), &prim);
    assert!(
        dm < 1e-5 && dc < 1e-8 && di < 1e-5,
        "capsule {dm:e} {dc:e} {di:e}"
    );
}

#[test]
fn regular_prism_matches_its_exact_formula() {
    // n-gon prism, circumradius R, length L: A = n R² sin θ / 2, J = n R⁴ sin θ (2 + cos θ) / 12, θ = 2π/n.
    for n in [3u32, 6, 17, 100] {
        let (rr, l) = (0.7f64, 1.3f64);
        let th = 2.0 * std::f64::consts::PI / f64::from(n);
        let area = f64::from(n) * rr * rr * th.sin() / 2.0;
        let j = f64::from(n) * rr.powi(4) * th.sin() * (2.0 + th.cos()) / 12.0;
        let (v, f) = cylinder_mesh(rr, l, n);
        let mp = MassProperties::from_trimesh(&v, &f, 1.0);
        assert!((mp.mass - area * l).abs() < 1e-14 * area * l);
        assert!((mp.inertia[2][2] - l * j).abs() < 1e-14 * l * j, "n {n}");
        let ixx = l * j / 2.0 + area * l.powi(3) / 12.0;
        assert!((mp.inertia[0][0] - ixx).abs() < 1e-14 * ixx, "n {n}");
    }
}

#[test]
fn algebra_on_random_bodies() {
    let mut rng = Rng(2024);
    for _ in 0..25 {
        let (v, f) = random_blob(&mut rng, 3);
        let density = rng.range(100.0, 9000.0);
        let base = MassProperties::from_trimesh(&v, &f, density);
        assert!(validity::check(&base, validity::DEFAULT_TOLERANCE).is_empty());
        // Rotation about the origin gives R I Rᵀ (and R c).
        let r = rotation([
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
        ]);
        let rotated = transform(&(v.clone(), f.clone()), 1.0, &r, [0.0; 3]);
        let got = MassProperties::from_trimesh(&rotated.0, &rotated.1, density);
        let want = mat_mul(&mat_mul(&r, &base.inertia), &transpose(&r));
        let (_, dc, di) = rel_diff(
            &got,
            &MassProperties::new(base.mass, urdf_inertia::mass::mat_vec(&r, base.com), want),
        );
        assert!(dc < 1e-14 && di < 1e-13, "rotation {dc:e} {di:e}");
        // Translation moves only the COM.
        let t = [
            rng.range(-100.0, 100.0),
            rng.range(-100.0, 100.0),
            rng.range(-100.0, 100.0),
        ];
        let moved = transform(&(v.clone(), f.clone()), 1.0, &rotation([0.0; 3]), t);
        let got = MassProperties::from_trimesh(&moved.0, &moved.1, density);
        let (dm, dc, di) = rel_diff(&got, &base.translated(t));
        assert!(
            dm < 1e-14 && dc < 1e-12 && di < 1e-12,
            "translation {dm:e} {dc:e} {di:e}"
        );
    }
}

#[test]
fn composition_is_additive_and_order_free() {
    let mut rng = Rng(99);
    // Two disjoint boxes as one mesh equal the sum of the two (Problem 1 with one density).
    let (a, fa) = transform(
        &box_mesh([0.3, 0.2, 0.1]),
        1.0,
        &rotation([0.1, 0.2, 0.3]),
        [1.0, 0.0, 0.0],
    );
    let (b, fb) = transform(
        &box_mesh([0.1, 0.4, 0.2]),
        1.0,
        &rotation([-0.5, 0.0, 1.0]),
        [-1.0, 0.5, 0.2],
    );
    let mut v = a.clone();
    v.extend_from_slice(&b);
    let mut f = fa.clone();
    f.extend(fb.iter().map(|t| t.map(|i| i + a.len() as u32)));
    let whole = MassProperties::from_trimesh(&v, &f, 2.0);
    let sum =
        MassProperties::from_trimesh(&a, &fa, 2.0) + MassProperties::from_trimesh(&b, &fb, 2.0);
    let (dm, dc, di) = rel_diff(&sum, &whole);
    assert!(
        dm < 1e-15 && dc < 1e-15 && di < 1e-14,
        "{dm:e} {dc:e} {di:e}"
    );
    // Random parts, each with its own density, summed in two orders.
    let parts: Vec<MassProperties> = (0..8)
        .map(|_| {
            let (v, f) = random_blob(&mut rng, 2);
            let t = [
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            ];
            MassProperties::from_trimesh(&v, &f, rng.range(10.0, 10000.0)).translated(t)
        })
        .collect();
    let forward: MassProperties = parts.iter().copied().sum();
    let backward: MassProperties = parts.iter().rev().copied().sum();
    let (dm, dc, di) = rel_diff(&forward, &backward);
    assert!(
        dm < 1e-15 && dc < 1e-14 && di < 1e-14,
        "{dm:e} {dc:e} {di:e}"
    );
    assert!(validity::check(&forward, validity::DEFAULT_TOLERANCE).is_empty());
    // The tensor about any point: parallel-axis theorem against a direct shift of the mesh.
    let p = [0.3, -0.7, 1.1];
    let about = whole.inertia_about(p);
    let shifted: Vec<[f64; 3]> = v
        .iter()
        .map(|q| [q[0] - p[0], q[1] - p[1], q[2] - p[2]])
        .collect();
    let t = urdf_inertia::mass::integrals::triangle_integrals(
        &shifted,
        &f,
        &urdf_inertia::mass::IntegrationOptions {
            reference: Some([0.0; 3]),
            ..Default::default()
        },
    );
    let ixx = 2.0 * (t.t2[1] + t.t2[2]);
    assert!((about[0][0] - ixx).abs() < 1e-13 * ixx);
}

#[test]
fn principal_frame_of_a_stiff_body() {
    // A rotated needle: the smallest principal moment (1e12 below the others) and its axis.
    let r = rotation([0.7, -1.3, 2.9]);
    let (v, f) = transform(&box_mesh([1e-6, 1e-6, 1.0]), 1.0, &r, [1e4, -2e4, 3e4]);
    let mp = MassProperties::from_trimesh(&v, &f, 1.0);
    let p = mp.principal();
    // The smallest moment is 1e12 below the others, so any f64 tensor fixes it only to about
    // eps·1e12 ≈ 1e-4 relative (docs/accuracy.md measures it): it must stay tiny, and the long axis must
    // be recovered to full precision.
    assert!(p.moments[0].abs() < 1e-6 * p.moments[2], "{:?}", p.moments);
    let axis = [r[0][2], r[1][2], r[2][2]];
    let got = [p.axes[0][0], p.axes[1][0], p.axes[2][0]];
    let dot: f64 = (0..3).map(|k| axis[k] * got[k]).sum();
    assert!((dot.abs() - 1.0).abs() < 1e-12, "{dot}");
    // Right-handed.
    let a = &p.axes;
    let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    assert!((det - 1.0).abs() < 1e-12);
}
