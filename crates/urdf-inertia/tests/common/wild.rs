//! Closed meshes turned into the shapes exporters write (issue: mesh truth): each facet's corners
//! rounded independently (to f32, to 6–9 significant decimal digits, or nudged by a few ulps), sliver
//! cracks of 1e-9 of the size, faces genuinely missing, a component wound inward, duplicated faces.
//!
//! Every generator returns the mesh as a file would store it; the tests take its ground truth from the
//! exact rational integrals of those stored triangles (or of the closed mesh it came from, for real
//! holes), never from the code under test.

use super::{Mesh, Rng};
use urdf_inertia::mesh::health::HealthOptions;

/// Each facet with three corners of its own, each computed independently by `corner`.
pub fn per_facet(mesh: &Mesh, mut corner: impl FnMut([f64; 3]) -> [f64; 3]) -> Mesh {
    let (v, f) = mesh;
    let mut out_v = Vec::with_capacity(3 * f.len());
    let mut out_f = Vec::with_capacity(f.len());
    for t in f {
        let base = out_v.len() as u32;
        for &i in t {
            out_v.push(corner(v[i as usize]));
        }
        out_f.push([base, base + 1, base + 2]);
    }
    (out_v, out_f)
}

/// The distance from `x` to the next f32 above it in magnitude.
fn f32_ulp(x: f64) -> f64 {
    let y = (x as f32).abs();
    f64::from(f32::from_bits(y.to_bits() + 1) - y)
}

/// A corner as an exporter that computes it in f64 with its own round-off, then stores f32: the value
/// moved by up to half an f32 ulp, then rounded (so a shared corner lands on one of two f32 values).
pub fn f32_corner(rng: &mut Rng) -> impl FnMut([f64; 3]) -> [f64; 3] + '_ {
    move |p| p.map(|x| f64::from((x + (rng.f64() - 0.5) * f32_ulp(x)) as f32))
}

/// A corner written with `digits` significant decimal digits, after the same kind of jitter.
pub fn decimal_corner(rng: &mut Rng, digits: usize) -> impl FnMut([f64; 3]) -> [f64; 3] + '_ {
    move |p| {
        p.map(|x| {
            if x == 0.0 {
                return 0.0;
            }
            let unit = 10f64.powi(x.abs().log10().floor() as i32 + 1 - digits as i32);
            let jittered = x + (rng.f64() - 0.5) * unit;
            format!("{:.*e}", digits - 1, jittered)
                .parse()
                .expect("a decimal")
        })
    }
}

/// A corner nudged by up to `ulps` f64 ulps in each coordinate.
pub fn nudged_corner(rng: &mut Rng, ulps: i64) -> impl FnMut([f64; 3]) -> [f64; 3] + '_ {
    move |p| {
        p.map(|x| {
            if x == 0.0 {
                return 0.0;
            }
            let k = (rng.next_u64() % (2 * ulps as u64 + 1)) as i64 - ulps;
            f64::from_bits((x.to_bits() as i64 + k) as u64)
        })
    }
}

/// A corner moved by up to 0.25e-9 × `size` in each coordinate: two copies of a shared corner end up
/// to 0.9e-9 × `size` apart, cracks of the order of 1e-9 of the part.
pub fn sliver_corner(rng: &mut Rng, size: f64) -> impl FnMut([f64; 3]) -> [f64; 3] + '_ {
    move |p| p.map(|x| x + (rng.f64() - 0.5) * 0.5e-9 * size)
}

/// The mesh without the faces listed.
pub fn without_faces(mesh: &Mesh, gone: &[usize]) -> Mesh {
    let f = mesh
        .1
        .iter()
        .enumerate()
        .filter(|(i, _)| !gone.contains(i))
        .map(|(_, t)| *t)
        .collect();
    (mesh.0.clone(), f)
}

/// The mesh with the faces listed stored twice.
pub fn with_duplicates(mesh: &Mesh, twice: &[usize]) -> Mesh {
    let mut f = mesh.1.clone();
    f.extend(twice.iter().map(|&i| mesh.1[i]));
    (mesh.0.clone(), f)
}

/// Every face wound the other way.
pub fn inverted(mesh: &Mesh) -> Mesh {
    (
        mesh.0.clone(),
        mesh.1.iter().map(|t| [t[0], t[2], t[1]]).collect(),
    )
}

/// Two meshes as one file.
pub fn joined(a: &Mesh, b: &Mesh) -> Mesh {
    let n = a.0.len() as u32;
    let mut v = a.0.clone();
    v.extend_from_slice(&b.0);
    let mut f = a.1.clone();
    f.extend(b.1.iter().map(|t| t.map(|i| i + n)));
    (v, f)
}

/// A torus about Z: major radius `big`, minor `small`, `n` × `m` quads split in two.
pub fn torus(big: f64, small: f64, n: u32, m: u32) -> Mesh {
    use std::f64::consts::TAU;
    let mut v = Vec::new();
    for i in 0..n {
        let a = TAU * f64::from(i) / f64::from(n);
        for j in 0..m {
            let b = TAU * f64::from(j) / f64::from(m);
            let r = big + small * b.cos();
            v.push([r * a.cos(), r * a.sin(), small * b.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m);
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            f.push([a, b, c]);
            f.push([a, c, d]);
        }
    }
    (v, f)
}

/// A thin L-shaped bracket: a 2 mm plate bent at a right angle, legs 80 mm and 50 mm, 30 mm wide,
/// with the corner at (0.1, -0.2, 0.3) (a prism over an L-shaped profile in the x–z plane).
pub fn bracket() -> Mesh {
    let t = 0.002;
    // Profile in (x, z), counter-clockwise.
    let profile = [
        [0.0, 0.0],
        [0.08, 0.0],
        [0.08, t],
        [t, t],
        [t, 0.05],
        [0.0, 0.05],
    ];
    let o = [0.1, -0.2, 0.3];
    let w = 0.03;
    let n = profile.len() as u32;
    let mut v = Vec::new();
    for y in [0.0, w] {
        for p in &profile {
            v.push([o[0] + p[0], o[1] + y, o[2] + p[1]]);
        }
    }
    let mut f = Vec::new();
    // Sides: the profile is counter-clockwise seen from -y, so the y = 0 side is wound as given.
    for k in 0..n {
        let j = (k + 1) % n;
        f.push([k, j, n + j]);
        f.push([k, n + j, n + k]);
    }
    // Caps: the L split into two rectangles (0,1,2,3 + 0,3,4,5).
    for quad in [[0, 1, 2, 3], [0, 3, 4, 5]] {
        f.push([quad[0], quad[2], quad[1]]);
        f.push([quad[0], quad[3], quad[2]]);
        f.push([n + quad[0], n + quad[1], n + quad[2]]);
        f.push([n + quad[0], n + quad[2], n + quad[3]]);
    }
    (v, f)
}

/// The largest side of the mesh's bounding box.
pub fn extent(mesh: &Mesh) -> f64 {
    (0..3)
        .map(|k| {
            let lo = mesh.0.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
            let hi = mesh
                .0
                .iter()
                .map(|p| p[k])
                .fold(f64::NEG_INFINITY, f64::max);
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// What a case must come out as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Expect {
    /// Closed up to float noise: rung exact or welded, within 1e-9 of the stored triangles' value.
    AsStored,
    /// Really damaged: any rung, with an error estimate at least the real error against the closed
    /// mesh it came from.
    Bounded,
}

/// A synthetic case: the mesh as a file stores it, and the closed mesh whose exact integrals (about
/// their bounding-box centre) are the truth.
pub struct Case {
    pub name: String,
    pub stored: Mesh,
    pub truth: Mesh,
    pub expect: Expect,
}

/// The closed meshes the cases start from: a sphere, a box, a torus, a thin bracket (all moved away
/// from the origin and turned), and the demo robot's meshes (welded bit-exactly).
pub fn bases() -> Vec<(String, Mesh)> {
    let r = super::rotation([0.3, -0.2, 0.7]);
    let mut out = vec![
        (
            "sphere".to_string(),
            super::transform(&super::icosphere(3), 0.05, &r, [0.21, -0.13, 0.42]),
        ),
        (
            "box".to_string(),
            super::transform(
                &super::box_mesh([0.1, 0.2, 0.3]),
                1.0,
                &r,
                [0.5, 0.25, -0.3],
            ),
        ),
        (
            "torus".to_string(),
            super::transform(&torus(0.1, 0.03, 48, 24), 1.0, &r, [-0.2, 0.1, 0.05]),
        ),
        ("bracket".to_string(), inverted(&bracket())),
    ];
    let demo = super::workspace_root().join("robots/demo_arm_description/meshes");
    for name in [
        "shoulder.STL",
        "battery.stl",
        "wrist_wedge.stl",
        "upper_arm.obj",
    ] {
        let raw =
            urdf_inertia::mesh::read(&demo.join(name), urdf_inertia::input::DEFAULT_MAX_FILE_SIZE)
                .expect("demo mesh");
        let w = urdf_inertia::mesh::weld::exact(&raw.vertices, &raw.faces);
        out.push((format!("demo {name}"), (w.vertices, w.faces.triangles())));
    }
    out
}

/// Every case: each base stored five wild ways (closed up to noise), plus real holes, an inward
/// component, a cavity and duplicated faces.
#[allow(clippy::too_many_lines)] // a table of cases
pub fn cases() -> Vec<Case> {
    let mut rng = Rng(0x5EED);
    let mut out = Vec::new();
    let as_stored = |name: String, stored: Mesh| Case {
        name,
        truth: stored.clone(),
        stored,
        expect: Expect::AsStored,
    };
    for (name, base) in bases() {
        let size = extent(&base);
        out.push(as_stored(
            format!("{name}, f32 per facet"),
            per_facet(&base, f32_corner(&mut rng)),
        ));
        for digits in [6, 9] {
            out.push(as_stored(
                format!("{name}, {digits} digits per facet"),
                per_facet(&base, decimal_corner(&mut rng, digits)),
            ));
        }
        out.push(as_stored(
            format!("{name}, ±4 ulp per facet"),
            per_facet(&base, nudged_corner(&mut rng, 4)),
        ));
        let slivers = per_facet(&base, sliver_corner(&mut rng, size));
        out.push(as_stored(format!("{name}, 1e-9 slivers"), slivers.clone()));
        out.push(Case {
            name: format!("{name}, 1e-9 slivers, faces stored twice"),
            stored: with_duplicates(&slivers, &[0, 3, 7]),
            truth: slivers,
            expect: Expect::AsStored,
        });
        // A real hole: two faces that share an edge (a non-planar quad loop), and one lone face.
        let soup = per_facet(&base, f32_corner(&mut rng));
        let pair = adjacent_pair(&base);
        let lone = (0..base.1.len())
            .find(|i| !shares_vertex(&base, *i, pair.0) && !shares_vertex(&base, *i, pair.1))
            .unwrap_or(0);
        out.push(Case {
            name: format!("{name}, f32, 3 faces missing"),
            stored: without_faces(&soup, &[pair.0, pair.1, lone]),
            truth: soup,
            expect: Expect::Bounded,
        });
    }
    let sphere = super::icosphere(3);
    let small_far = super::transform(&sphere, 0.2, &super::rotation([0.0; 3]), [3.0, 0.0, 0.0]);
    let small_inside = super::transform(&sphere, 0.2, &super::rotation([0.0; 3]), [0.1, 0.0, 0.0]);
    out.push(Case {
        name: "sphere + a sphere beside it wound inward".into(),
        stored: joined(&sphere, &inverted(&small_far)),
        truth: joined(&sphere, &small_far),
        expect: Expect::Bounded,
    });
    let mut rng2 = Rng(7);
    let cracked = per_facet(
        &joined(&sphere, &inverted(&small_far)),
        f32_corner(&mut rng2),
    );
    out.push(Case {
        name: "f32 sphere + a sphere beside it wound inward".into(),
        truth: (cracked.0.clone(), {
            let n = sphere.1.len();
            cracked
                .1
                .iter()
                .enumerate()
                .map(|(i, t)| if i < n { *t } else { [t[0], t[2], t[1]] })
                .collect()
        }),
        stored: cracked,
        expect: Expect::Bounded,
    });
    out.push(as_stored(
        "sphere with a cavity (inner sphere wound inward)".into(),
        joined(&sphere, &inverted(&small_inside)),
    ));
    let cavity = per_facet(
        &joined(&sphere, &inverted(&small_inside)),
        f32_corner(&mut rng2),
    );
    out.push(as_stored("f32 sphere with a cavity".into(), cavity));
    out
}

/// Two faces of `mesh` that share an edge.
fn adjacent_pair(mesh: &Mesh) -> (usize, usize) {
    let f = &mesh.1;
    for i in 0..f.len() {
        for j in i + 1..f.len() {
            let shared = f[i].iter().filter(|v| f[j].contains(v)).count();
            if shared == 2 {
                return (i, j);
            }
        }
    }
    (0, 1)
}

fn shares_vertex(mesh: &Mesh, a: usize, b: usize) -> bool {
    mesh.1[a].iter().any(|v| mesh.1[b].contains(v))
}

/// How one case came out: the rung, the real relative errors of volume and central inertia against
/// the exact truth, and the estimate.
pub struct Outcome {
    pub rung: String,
    pub volume_error: f64,
    pub inertia_error: f64,
    pub estimate: f64,
    pub source: String,
    /// Distance of the computed centre of mass from the exact one, m, and its bound.
    pub com_error: f64,
    pub com_bound: f64,
}

impl Outcome {
    pub fn real(&self) -> f64 {
        self.volume_error.max(self.inertia_error)
    }
}

/// Runs a case through the reader-independent part of the pipeline (scale 1, then the ladder, with
/// the precision found in the stored numbers) and measures it against the exact truth.
pub fn run(case: &Case) -> Result<Outcome, String> {
    let raw = urdf_inertia::mesh::RawMesh {
        vertices: case.stored.0.clone(),
        faces: urdf_inertia::mass::Polygons::from_triangles(&case.stored.1),
        ..Default::default()
    };
    let path = std::path::Path::new(&case.name);
    let solid = urdf_inertia::mesh::solid_from_raw(&raw, [1.0; 3], path, HealthOptions::default())
        .map_err(|e| e.to_string())?;
    let exact = super::exact_mass(&super::exact_integrals_about_centre(
        &case.truth.0,
        &case.truth.1,
    ));
    // The exact centre of mass is about the exact bounding-box centre of the truth's vertices.
    let centre: [num_rational::BigRational; 3] = std::array::from_fn(|k| {
        let lo = case
            .truth
            .0
            .iter()
            .map(|p| p[k])
            .fold(f64::INFINITY, f64::min);
        let hi = case
            .truth
            .0
            .iter()
            .map(|p| p[k])
            .fold(f64::NEG_INFINITY, f64::max);
        (super::rat(lo) + super::rat(hi)) / super::rat(2.0)
    });
    let com_error = (0..3)
        .map(|k| {
            let d = super::rat(solid.unit.com[k]) - &centre[k] - &exact.com[k];
            num_traits::ToPrimitive::to_f64(&d)
                .unwrap_or(f64::INFINITY)
                .powi(2)
        })
        .sum::<f64>()
        .sqrt();
    Ok(Outcome {
        com_error,
        com_bound: solid.error.com,
        rung: solid.rung.name().to_string(),
        volume_error: super::rel_error(solid.unit.mass, &exact.volume),
        inertia_error: super::inertia_error(&solid.unit.inertia, &exact.inertia),
        estimate: solid.error_estimate,
        source: solid.error.source.name().to_string(),
    })
}
