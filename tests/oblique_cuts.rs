//! Closed shells that cut each other at angles no grid lines up with, against exact rational
//! volumes: where the cut points are rounded, the estimate must still bound the error.
//!
//! `crossing_shells.rs` checks oblique cuts against a sampled winding number, whose σ (about 1e-3)
//! cannot see what rounding a cut point does (about 1e-16 of the part). Here the truth is exact: an
//! open box (capped, exactly, by one flat cap) and tetrahedra through its walls, whose union is
//! box + tetrahedra − the intersections, and the intersection of two convex polyhedra is the convex
//! polyhedron of their planes, whose corners and volume are computed here in rationals from the
//! stored f64 corners (an implementation independent of the library's).

#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;

use common::shells::{open_top, solid_with, together};
use common::Mesh;
use num_bigint::BigInt;
use num_traits::{Signed, Zero};
use urdf_inertia::mesh::health::HealthOptions;

use common::rational::{boxes_meet, q, ring, vcross, vdot, vsub, Q, V};

/// The half-spaces n·x ≤ d of a convex closed mesh wound outward: one per triangle, exact.
fn halfspaces(m: &Mesh) -> Vec<(V, Q)> {
    m.1.iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.0[i as usize].map(q));
            let n = vcross(&vsub(&b, &a), &vsub(&c, &a));
            let d = vdot(&n, &a);
            (n, d)
        })
        .collect()
}

/// The exact volume of the convex polyhedron {x : n·x ≤ d for every plane}: its corners are the
/// points where three planes meet that satisfy all of them; each plane holding three corners or
/// more is a facet, its corners ordered about their centre (counter-clockwise seen along n), and the
/// volume is the divergence theorem's sum of the facets' fans.
fn convex_volume(planes: &[(V, Q)]) -> Q {
    volume_from(planes, &convex_corners(planes))
}

/// The points where three of the planes meet that satisfy all of them.
fn convex_corners(planes: &[(V, Q)]) -> Vec<V> {
    let mut corners: Vec<V> = Vec::new();
    let n = planes.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (&planes[i], &planes[j], &planes[k]);
                let (bc, ca, ab) = (vcross(&b.0, &c.0), vcross(&c.0, &a.0), vcross(&a.0, &b.0));
                let det = vdot(&a.0, &bc);
                if det.is_zero() {
                    continue;
                }
                let x: V =
                    std::array::from_fn(|m| (&a.1 * &bc[m] + &b.1 * &ca[m] + &c.1 * &ab[m]) / &det);
                if planes.iter().all(|(pn, pd)| vdot(pn, &x) <= *pd) && !corners.contains(&x) {
                    corners.push(x);
                }
            }
        }
    }
    corners
}

/// The volume of the convex polyhedron of `planes` with these `corners` ([`convex_volume`]).
fn volume_from(planes: &[(V, Q)], corners: &[V]) -> Q {
    let mut facets: Vec<Vec<usize>> = Vec::new();
    let mut volume = Q::zero();
    for (pn, pd) in planes {
        let on: Vec<usize> = (0..corners.len())
            .filter(|&i| vdot(pn, &corners[i]) == *pd)
            .collect();
        if on.len() < 3 || facets.contains(&on) {
            continue;
        }
        facets.push(on.clone());
        let points: Vec<V> = on.iter().map(|&i| corners[i].clone()).collect();
        let p = ring(pn, &points);
        for w in 1..p.len() - 1 {
            volume += vdot(&p[0], &vcross(&p[w], &p[w + 1]));
        }
    }
    volume / Q::from_integer(BigInt::from(6))
}

fn mesh_volume(m: &Mesh) -> Q {
    common::exact_integrals(&m.0, &m.1)[0].clone()
}

/// A tetrahedron on `corners`, wound outward.
fn tetrahedron(corners: [[f64; 3]; 4]) -> Mesh {
    let mut tris = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    let p = corners.map(|c| c.map(q));
    let n = vcross(&vsub(&p[1], &p[0]), &vsub(&p[2], &p[0]));
    if vdot(&n, &vsub(&p[3], &p[0])).is_negative() {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    (corners.to_vec(), tris)
}

/// Uniform in [0, 1), not dyadic once scaled and shifted.
fn uniform(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// `count` tetrahedra through the wall x = hi of the box `lo..hi` (each has a corner inside the box
/// and three outside, in its own slot of the wall so they do not meet), scaled by `scale` and moved
/// by `offset`; the union's exact volume, and the healed solid's relative error and estimate.
fn pierced_box(count: usize, scale: f64, offset: f64, seed: u64) -> (f64, f64) {
    let mut state = seed;
    let at = |x: f64| x * scale + offset;
    let (lo, hi) = ([at(0.0); 3], [at(1.0); 3]);
    let b = common::box_at(lo, hi);
    let mut parts = vec![(open_top(&b), false)];
    let mut exact = mesh_volume(&b);
    let box_planes = halfspaces(&b);
    for i in 0..count {
        // The slot: a band of the wall in y, a tetrahedron inside it.
        let (y0, y1) = (i as f64 / count as f64, (i + 1) as f64 / count as f64);
        let mut r = |a: f64, b: f64| a + (b - a) * uniform(&mut state);
        let ym = |r: &mut dyn FnMut(f64, f64) -> f64| r(y0 + 0.2 * (y1 - y0), y1 - 0.2 * (y1 - y0));
        let inside = [at(r(0.6, 0.9)), at(ym(&mut r)), at(r(0.3, 0.6))];
        let outside: Vec<[f64; 3]> = (0..3)
            .map(|_| [at(r(1.1, 1.4)), at(ym(&mut r)), at(r(0.1, 0.8))])
            .collect();
        let t = tetrahedron([inside, outside[0], outside[1], outside[2]]);
        let mut both = box_planes.clone();
        both.extend(halfspaces(&t));
        exact += mesh_volume(&t) - convex_volume(&both);
        parts.push((t, false));
    }
    let parts: Vec<(&Mesh, bool)> = parts.iter().map(|(m, f)| (m, *f)).collect();
    let s = solid_with(&together(&parts), HealthOptions::default(), "pierced.stl");
    let error = common::rel_error(s.unit.mass, &exact);
    assert!(
        error <= s.error_estimate,
        "{count} tetrahedra, scale {scale}, offset {offset}: error {error:e} above the estimate {:e}\n{:?}",
        s.error_estimate,
        s.warnings
    );
    (error, s.error_estimate)
}

/// The reference itself: a box and a tetrahedron alone, and a tetrahedron wholly inside the box,
/// whose intersection is itself.
#[test]
fn the_exact_convex_volume_is_the_mesh_volume() {
    let b = common::box_at([0.1, -0.3, 0.7], [1.3, 0.9, 1.1]);
    assert_eq!(convex_volume(&halfspaces(&b)), mesh_volume(&b));
    let t = tetrahedron([
        [0.2, 0.0, 0.8],
        [1.1, 0.3, 0.9],
        [0.5, 0.7, 1.05],
        [0.9, -0.1, 1.0],
    ]);
    assert_eq!(convex_volume(&halfspaces(&t)), mesh_volume(&t));
    let mut both = halfspaces(&b);
    both.extend(halfspaces(&t));
    assert_eq!(convex_volume(&both), mesh_volume(&t));
}

#[test]
fn oblique_cuts_are_within_the_estimate() {
    for (count, scale, offset, seed) in [
        (1, 1.0, 0.0, 1),
        (4, 1.0, 0.0, 2),
        (16, 1.0, 0.0, 3),
        (8, 1e-3, 0.0, 4),
        (8, 1e-3, 0.7, 5),
        (8, 1.0, 1000.0, 6),
        (32, 0.05, -3.0, 7),
        // 2.7e-15 off under an estimate of 2.2e-15 before the cuts' rounding was in the bound.
        (3, 1e-3, 0.7, 21 * 7919),
    ] {
        let (error, estimate) = pierced_box(count, scale, offset, seed);
        eprintln!("{count} tetrahedra, scale {scale}, offset {offset}: error {error:e}, estimate {estimate:e}");
    }
}

/// 199 random cases (1 to 40 tetrahedra; parts of 1 mm to 30 m, 0 to 3e5 m from the origin): every
/// error within the estimate (the largest error over estimate, 2.4e-4, was a 20 mm part with one
/// tetrahedron). About four minutes; `SEED=n` runs case n alone.
#[test]
#[ignore = "four minutes: run by hand after changing the cuts or the bound"]
fn sweep() {
    let only: Option<u64> = std::env::var("SEED").ok().map(|x| x.parse().unwrap());
    let mut worst = (0.0, String::new());
    for seed in 1..200u64 {
        if only.is_some_and(|o| o != seed) {
            continue;
        }
        let count = [1, 3, 10, 40][seed as usize % 4];
        let scale: f64 = [1.0, 1e-3, 0.02, 30.0][(seed as usize / 4) % 4];
        let offset = [0.0, 0.7, -3.0, 1000.0, 1e4][(seed as usize / 16) % 5] * scale.max(1.0);
        let (e, est) = pierced_box(count, scale, offset, seed * 7919);
        if e / est > worst.0 {
            worst = (
                e / est,
                format!("{count} {scale} {offset} {seed}: {e:e} / {est:e}"),
            );
        }
    }
    eprintln!("largest error / estimate {:e}: {}", worst.0, worst.1);
}

/// A tetrahedron whose face crosses the box's wall at a shallow angle (its corners `s` inside and
/// outside the wall, the face about 0.4 across): the cut line within the wall is ill-conditioned
/// by 1/s, and the bound grows with it; at s = 1e-8 the face is taken as in the wall's plane (its
/// slab in the bound) and the volume moves by 1.6e-9, within it.
#[test]
fn shallow_cuts_are_within_the_estimate() {
    for s in [1e-1, 1e-3, 1e-5, 1e-7, 1e-8] {
        for (scale, offset) in [(1.0, 0.0), (1e-3, 0.7), (1.0, 100.0)] {
            let at = |x: f64| x * scale + offset;
            let b = common::box_at([at(0.0); 3], [at(1.0); 3]);
            let t = tetrahedron([
                [at(0.8), at(0.3), at(0.3)],
                [at(1.0 - s), at(0.2), at(0.2)],
                [at(1.0 + s), at(0.6), at(0.25)],
                [at(1.0 + 0.3 * s), at(0.4), at(0.7)],
            ]);
            let mut both = halfspaces(&b);
            both.extend(halfspaces(&t));
            let exact = mesh_volume(&b) + mesh_volume(&t) - convex_volume(&both);
            let m = together(&[(&open_top(&b), false), (&t, false)]);
            let solid = solid_with(&m, HealthOptions::default(), "shallow.stl");
            let error = common::rel_error(solid.unit.mass, &exact);
            assert!(
                error <= solid.error_estimate,
                "s {s:e}, scale {scale}, offset {offset}: error {error:e}, estimate {:e}",
                solid.error_estimate
            );
        }
    }
}

/// A tetrahedron whose face crosses the box's wall x = 1 along a line `d` from the wall's bottom
/// edge, nearly along it (tilted by `tilt` over the wall): the slivers of the wall and of the
/// bottom inside the tetrahedron are narrower than the decision margin (1e-12 of the diagonal, so
/// about 4e-12 here, over the sine of the blocker's angle), so a plane that crosses a cell by less
/// leaves it whole. Where the wall's and the bottom's slivers and the face's wedge between them
/// are all left whole, the decided surface is closed and holds the intersection twice: the error
/// is its volume, about d² (5e-23 at d = 1e-11), and rounding elsewhere. But the margins differ
/// (the face's plane's is the margin over the sine of its first angle, the box's the margin times
/// √2), so a sliver can be left whole on one side and cut on the other: at d = 1e-11 and tilt
/// 3e-13 the surface is open along the edge and 1.3e-12 off, about d times the edge. The
/// estimate's round-off term (the volume integrated about two points, 6.4e-12) held that before
/// the slivers' areas were in the bound; `slivers_left_whole_within_the_margin_are_within_the_estimate`
/// cancels that term with a mirrored tetrahedron, and was off before.
#[test]
fn cuts_within_the_margin_are_within_the_estimate() {
    for d in [1e-9, 1e-11, 1e-12, 3e-13, 1e-13, 1e-14] {
        for tilt in [0.0, 1e-13, 3e-13] {
            let b = common::box_at([0.0; 3], [1.0; 3]);
            let z = |x: f64, y: f64| d + 0.5 * (x - 1.0) + tilt * y;
            let t = tetrahedron([
                [1.5, -1.0, z(1.5, -1.0)],
                [1.5, 2.0, z(1.5, 2.0)],
                [0.5, 0.5, z(0.5, 0.5)],
                [1.0, 0.5, -2.0],
            ]);
            let mut both = halfspaces(&b);
            both.extend(halfspaces(&t));
            let exact = mesh_volume(&b) + mesh_volume(&t) - convex_volume(&both);
            let m = together(&[(&open_top(&b), false), (&t, false)]);
            let solid = solid_with(&m, HealthOptions::default(), "margin.stl");
            let error = common::rel_error(solid.unit.mass, &exact);
            assert!(
                error <= solid.error_estimate,
                "d {d:e}, tilt {tilt:e}: error {error:e}, estimate {:e}",
                solid.error_estimate
            );
        }
    }
}

/// Whether the points lie in one plane (or fewer dimensions), exactly.
fn flat(points: &[V]) -> bool {
    let Some(p0) = points.first() else {
        return true;
    };
    let mut basis: Vec<V> = Vec::new();
    for p in &points[1..] {
        let d = vsub(p, p0);
        match basis.len() {
            0 if d.iter().any(|x| !x.is_zero()) => basis.push(d),
            1 if vcross(&basis[0], &d).iter().any(|x| !x.is_zero()) => basis.push(d),
            2 if !vdot(&vcross(&basis[0], &basis[1]), &d).is_zero() => return false,
            _ => {}
        }
    }
    true
}

/// The exact volume of the union of convex closed meshes (wound outward), by inclusion–exclusion
/// over the convex intersections of every subset whose boxes meet.
fn union_volume(parts: &[&Mesh]) -> Q {
    let boxes: Vec<([f64; 3], [f64; 3])> = parts
        .iter()
        .map(|m| {
            let lo = std::array::from_fn(|k| m.0.iter().map(|p| p[k]).fold(f64::MAX, f64::min));
            let hi = std::array::from_fn(|k| m.0.iter().map(|p| p[k]).fold(f64::MIN, f64::max));
            (lo, hi)
        })
        .collect();
    let planes: Vec<Vec<(V, Q)>> = parts.iter().map(|m| halfspaces(m)).collect();
    let mut total = Q::zero();
    for subset in 1u32..(1 << parts.len()) {
        let members: Vec<usize> = (0..parts.len()).filter(|i| subset >> i & 1 == 1).collect();
        if !boxes_meet(&members, &boxes) {
            continue;
        }
        let v = if members.len() == 1 {
            mesh_volume(parts[members[0]])
        } else {
            let all: Vec<(V, Q)> = members.iter().flat_map(|&i| planes[i].clone()).collect();
            convex_volume_or_flat(&all)
        };
        if members.len() % 2 == 1 {
            total += v;
        } else {
            total -= v;
        }
    }
    total
}

/// [`convex_volume`], 0 when the polyhedron is flat (two boxes touching along a face).
fn convex_volume_or_flat(planes: &[(V, Q)]) -> Q {
    let corners = convex_corners(planes);
    if flat(&corners) {
        return Q::zero();
    }
    volume_from(planes, &corners)
}

/// The union of `parts` (the first opened at its top) healed: its relative error against the
/// exact union and its estimate, not asserted; `None` when the ladder refuses it (a part through
/// the open top leaves its cap untrusted).
fn healed_union(parts: &[&Mesh]) -> Option<(f64, f64)> {
    let first = open_top(parts[0]);
    let mut list: Vec<(&Mesh, bool)> = vec![(&first, false)];
    list.extend(parts[1..].iter().map(|m| (*m, false)));
    let (vertices, tris) = together(&list);
    let raw = urdf_inertia::mesh::RawMesh {
        vertices,
        faces: urdf_inertia::mass::Polygons::from_triangles(&tris),
        ..Default::default()
    };
    let options = HealthOptions::default();
    let s = urdf_inertia::mesh::solid_from_raw(
        &raw,
        [1.0; 3],
        std::path::Path::new("margin.stl"),
        options,
    )
    .ok()?;
    let exact = union_volume(parts);
    Some((common::rel_error(s.unit.mass, &exact), s.error_estimate))
}

/// The mesh reflected through the point (c/2, c/2, c/2), still wound outward (a point reflection
/// turns orientation: the triangles are turned back).
fn reflected(m: &Mesh, c: f64) -> Mesh {
    let tris = m.1.iter().map(|t| [t[0], t[2], t[1]]).collect();
    (m.0.iter().map(|p| p.map(|x| c - x)).collect(), tris)
}

/// A tetrahedron through the wall x = 1 of the unit box, as the box is scaled by `scale` and
/// moved by `offset`: its section by the wall is the triangle of P1 and P2, `len` apart on the
/// line through `(y, z)` along `dir` (in the wall), and P3, `width` from that line on the `side`
/// (±1) left of `dir`; its face through P1 and P2 makes the angle `theta` with the wall (its apex
/// is `width` tan `theta` outside the wall, over P3), so that face's angle at the apex, its first
/// corner, has a sine of about 4 `width` / `len`. `None` when a corner would come near the box's
/// open top (whose cap is flat), or, `mirrored` through the box's centre, near its bottom, or
/// when it is too thin for its coordinates.
#[derive(Clone, Copy, Debug)]
struct WallTet {
    at: [f64; 2],
    dir: [f64; 2],
    len: f64,
    width: f64,
    side: f64,
    theta: f64,
}

impl WallTet {
    fn mesh(&self, (scale, offset): (f64, f64), mirrored: bool) -> Option<Mesh> {
        let norm = self.dir[0].hypot(self.dir[1]);
        let u = self.dir.map(|x| x / norm);
        let v = [-u[1] * self.side, u[0] * self.side];
        let on = |s: f64, w: f64| {
            [
                self.at[0] + s * u[0] + w * v[0],
                self.at[1] + s * u[1] + w * v[1],
            ]
        };
        let (p1, p2, p3) = (
            on(-self.len / 2.0, 0.0),
            on(self.len / 2.0, 0.0),
            on(0.0, self.width),
        );
        let h = self.width * self.theta.tan();
        let base = |p: [f64; 2]| [1.0 - h, 2.0 * p[0] - p3[0], 2.0 * p[1] - p3[1]];
        let corners = [[1.0 + h, p3[0], p3[1]], base(p1), base(p2), base(p3)];
        if corners
            .iter()
            .any(|c| c[2] > 0.95 || (mirrored && c[2] < 0.05))
        {
            return None;
        }
        // A tetrahedron a few ulps thick (1 mm parts 1e4 m from the origin) is welded flat into a
        // cancelling pair of faces: `a_tetrahedron_welded_flat_is_within_the_estimate`.
        if h * scale < 1e3 * f64::EPSILON * (offset.abs() + scale) {
            return None;
        }
        Some(tetrahedron(corners.map(|c| c.map(|x| x * scale + offset))))
    }
}

/// A tetrahedron through the wall, 4.5e-12 m to 4.5e-10 m thick on a 1 mm box 1e4 m from the
/// origin (a few ulps of its coordinates to a few hundred): the tolerant weld makes two of its
/// faces one face and its reverse, dropped as a cancelling pair, whose stored faces enclose its
/// sliver (3.9e-11 of the volume off under an estimate of 1.1e-15 before that was in the bound).
#[test]
fn a_tetrahedron_welded_flat_is_within_the_estimate() {
    let (scale, offset) = (1e-3, 1e4);
    for h in [4.5e-9, 4.5e-8, 4.5e-7] {
        let t = WallTet {
            at: [0.5, 0.5],
            dir: [1.0, 0.3],
            len: 0.5,
            width: 0.2,
            side: 1.0,
            theta: (h / 0.2f64).atan(),
        };
        let thick = WallTet { theta: 0.3, ..t };
        let m = thick
            .mesh((scale, offset), false)
            .expect("a thick one is made");
        // The same tetrahedron, its apex and base moved to `h` from the wall.
        let (v, f) = m;
        let v: Vec<[f64; 3]> = v
            .iter()
            .map(|c| {
                let x = (c[0] - offset) / scale;
                let x = if x > 1.0 { 1.0 + h } else { 1.0 - h };
                [x * scale + offset, c[1], c[2]]
            })
            .collect();
        let (error, estimate) =
            healed_union(&[&common::box_at([offset; 3], [scale + offset; 3]), &(v, f)])
                .expect("not refused");
        assert!(
            error <= estimate,
            "h {h:e}: error {error:e}, estimate {estimate:e}"
        );
    }
}

/// The unit box (opened at its top), scaled and moved, with the tetrahedra through its wall
/// x = 1 and, when `mirrored`, each reflected through the box's centre too (through the wall
/// x = 0, its sliver's normal the opposite: the disagreement of the volumes integrated about two
/// reference points, which the estimate holds, cancels); the relative error of the healed union
/// against its exact volume, and its estimate. `None` when a tetrahedron is not made or the
/// union is refused.
fn margin_case(
    tets: &[WallTet],
    mirrored: bool,
    (scale, offset): (f64, f64),
) -> Option<(f64, f64)> {
    let b = common::box_at([offset; 3], [scale + offset; 3]);
    let mut parts = vec![b];
    for t in tets {
        let m = t.mesh((scale, offset), mirrored)?;
        if mirrored {
            parts.push(reflected(&m, 2.0 * offset + scale));
        }
        parts.push(m);
    }
    let refs: Vec<&Mesh> = parts.iter().collect();
    healed_union(&refs)
}

/// A wall line `delta` from the diagonal (1, 0, 0)–(1, 1, 1), on the side of the triangle
/// (1, 0, 0), (1, 1, 1), (1, 0, 1), turned from it by `turn`; the tetrahedron's section crosses the
/// diagonal (P3 on its other side).
fn along_the_diagonal(delta: f64, turn: f64, (len, width): (f64, f64), theta: f64) -> WallTet {
    let a = std::f64::consts::FRAC_PI_4 + turn;
    WallTet {
        at: [0.5, 0.5 + delta],
        dir: [a.cos(), a.sin()],
        len,
        width,
        side: -1.0,
        theta,
    }
}

/// The breach the decision margin made before its slivers were in the bound: a thin face (the sine
/// of its first angle 1.3e-3, so its plane's margin is 1.3e-9 of the part, over the sine of 1e-3
/// between it and the wall) crossing the wall 1e-6 from its diagonal, nearly along it, left the
/// wall's triangle beside the diagonal whole, decided from beyond the line: a sliver 7e-7 wide and
/// 0.3 long counted on the wrong side, while the face itself was cut along the wall exactly. The
/// decided surface is open there, which the estimate's round-off term (the volume integrated about
/// two points) would catch but for the mirrored tetrahedron, whose sliver on the opposite wall
/// cancels it: 7.0e-8 off under an estimate of 1.8e-8 (now 1.8e-5). The tetrahedra alone (no
/// mirror), a face of moderate angles, and a line turned off the diagonal or along the bottom edge
/// are the same mechanism; the estimate now holds the area of the sliver beyond each plane that
/// left a piece or cell whole within the margin.
#[test]
fn slivers_left_whole_within_the_margin_are_within_the_estimate() {
    let diagonal = |delta, thin: (f64, f64), theta| along_the_diagonal(delta, 0.0, thin, theta);
    let bottom = |delta: f64, turn: f64, theta| WallTet {
        at: [0.5, delta],
        dir: [turn.cos(), turn.sin()],
        len: 0.6,
        width: 0.05,
        side: 1.0,
        theta,
    };
    for (tets, mirrored, place) in [
        (vec![diagonal(1e-6, (0.3, 1e-4), 1e-3)], true, (1.0, 0.0)),
        (vec![diagonal(1e-7, (0.3, 1e-4), 1e-2)], true, (1.0, 0.0)),
        (vec![diagonal(1e-6, (0.3, 1e-4), 1e-3)], false, (1.0, 0.0)),
        (vec![diagonal(3e-9, (0.5, 0.05), 1e-3)], true, (1.0, 0.0)),
        (vec![diagonal(3e-8, (0.02, 1e-5), 1e-3)], true, (1e-3, 0.7)),
        (
            vec![along_the_diagonal(1e-8, 1e-9, (0.3, 1e-4), 1e-3)],
            true,
            (30.0, 1e3),
        ),
        (vec![bottom(1e-9, 1e-10, 1e-2)], false, (1.0, 0.0)),
        (vec![bottom(-1e-9, 0.0, 1e-3)], false, (1.0, 0.0)),
    ] {
        let (error, estimate) = margin_case(&tets, mirrored, place).expect("below the top");
        assert!(
            error <= estimate,
            "{tets:?} (mirrored {mirrored}, scale and offset {place:?}): error {error:e}, estimate {estimate:e}"
        );
    }
}

/// Log-uniform in [lo, hi).
fn log_uniform(state: &mut u64, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * uniform(state)).exp()
}

/// A random tetrahedron of one of the families of the margin's sweep: its face 1e-15 to 1e-6 of
/// the part from the wall's diagonal, bottom edge, edge y = 0 or corner (1, 0, 0), nearly along
/// the first three (turned by 0 or 1e-12 to 1e-3) and at any angle through the corner; the face
/// thin or not (sine of its first angle 1e-4 to 1) and at 1e-4 to 1 rad from the wall.
fn random_wall_tet(family: usize, state: &mut u64) -> WallTet {
    let delta = log_uniform(state, 1e-15, 1e-6) * if uniform(state) < 0.2 { -1.0 } else { 1.0 };
    let turn = if uniform(state) < 0.3 {
        0.0
    } else {
        log_uniform(state, 1e-12, 1e-3)
    } * if uniform(state) < 0.5 { -1.0 } else { 1.0 };
    let len = 0.05 + 0.5 * uniform(state);
    let width = len * log_uniform(state, 2.5e-5, 0.25);
    let theta = log_uniform(state, 1e-4, 1.0);
    let side = if uniform(state) < 0.5 { -1.0 } else { 1.0 };
    let (at, angle) = match family {
        0 => ([0.5, 0.5 + delta], std::f64::consts::FRAC_PI_4 + turn),
        1 => ([0.5, delta], turn),
        2 => ([delta, 0.5], std::f64::consts::FRAC_PI_2 + turn),
        _ => {
            let a = std::f64::consts::PI * uniform(state) / 2.0;
            (
                [delta * a.cos(), delta * a.sin()],
                a + std::f64::consts::FRAC_PI_2,
            )
        }
    };
    WallTet {
        at,
        dir: [angle.cos(), angle.sin()],
        len,
        width,
        side,
        theta,
    }
}

/// The unit box (opened at its top) and a closed box beside its wall x = 1, each of the other's
/// coinciding sides `s` off (0, or 1e-15 to 1e-10 either way), scaled and moved; the relative error
/// and the estimate.
fn touching_boxes(s: [f64; 5], (scale, offset): (f64, f64)) -> Option<(f64, f64)> {
    let at = |x: f64| x * scale + offset;
    let a = common::box_at([at(0.0); 3], [at(1.0); 3]);
    let b = common::box_at(
        [at(1.0 - s[0]), at(s[1]), at(s[3])],
        [at(1.6), at(1.0 + s[2]), at(0.9 + s[4])],
    );
    healed_union(&[&a, &b])
}

/// The decision margin's sweep: 2,000 random cases of tetrahedra through a box's wall whose faces
/// cross its triangles within the margin (one, or two to four, each mirrored through the box's
/// centre or not) and of two boxes side by side, each coinciding side off by less than the
/// margin; parts of 1 mm to 30 m, 0 to 3e5 m from the origin. 1,549 cases made, 569 of them more
/// than 1e-14 off, all within (the largest error 0.18 of its estimate; 5.6e-2 among errors above
/// 1e-12). `SEED=n` runs case n alone.
#[test]
#[ignore = "five minutes: run by hand after changing the margin or the bound"]
fn margin_sweep() {
    let only: Option<u64> = std::env::var("SEED").ok().map(|x| x.parse().unwrap());
    let (mut worst, mut ran, mut off, mut skipped) = (vec![(0.0, String::new()); 6], 0, 0, 0);
    for seed in 1..2001u64 {
        if only.is_some_and(|o| o != seed) {
            continue;
        }
        let mut state = seed * 7919;
        let scale: f64 = [1.0, 1e-3, 0.02, 30.0][seed as usize % 4];
        let offset = [0.0, 0.7, -3.0, 1000.0, 1e4][(seed as usize / 4) % 5] * scale.max(1.0);
        let kind = (seed as usize / 20) % 6;
        let (label, result) = if kind == 5 {
            let s: [f64; 5] = std::array::from_fn(|_| {
                let x = log_uniform(&mut state, 1e-15, 1e-10);
                match (uniform(&mut state) * 3.0) as usize {
                    0 => 0.0,
                    1 => x,
                    _ => -x,
                }
            });
            (format!("boxes {s:?}"), touching_boxes(s, (scale, offset)))
        } else {
            let count = if kind == 4 { 2 + seed as usize % 3 } else { 1 };
            // Those along the bottom edge and through its corner, mirrored, would reach the top.
            let mirrored = matches!(kind, 0 | 2 | 4) && uniform(&mut state) < 0.5;
            let tets: Vec<WallTet> = (0..count)
                .map(|_| {
                    let family = if kind == 4 {
                        (uniform(&mut state) * 4.0) as usize
                    } else {
                        kind
                    };
                    random_wall_tet(family, &mut state)
                })
                .collect();
            (
                format!("{tets:?} mirrored {mirrored}"),
                margin_case(&tets, mirrored, (scale, offset)),
            )
        };
        let Some((error, estimate)) = result else {
            skipped += 1;
            continue;
        };
        ran += 1;
        if error > 1e-14 {
            off += 1;
        }
        let label = format!("case {seed}, scale {scale}, offset {offset}: {label}: error {error:e}, estimate {estimate:e}");
        assert!(error <= estimate, "{label}");
        if error / estimate > worst[kind].0 {
            worst[kind] = (error / estimate, label);
        }
    }
    eprintln!("{ran} cases ({skipped} not made or refused), {off} more than 1e-14 off");
    for (kind, (ratio, label)) in worst.iter().enumerate() {
        eprintln!("kind {kind}: the largest error / estimate {ratio:e}: {label}");
    }
}
