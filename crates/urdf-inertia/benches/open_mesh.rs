//! Open meshes of 41,598 and 62,075 faces through the ladder, per model for open meshes: an
//! icosphere of level 7 (81,920 faces) without its upper half (a bowl whose loop zig-zags along the
//! equator by a facet's height, so its flat cap is uncertain by a few % and not trusted), and without
//! the quarter x > 0, z > 0 (an L-shaped hole). Neither is trusted: `none` (the default) is the cost
//! of the UI108 error, `caps` and `hull` of the solids asked for. Each iteration is `make_solid` from
//! the raw mesh: welding, edges, caps or the hull, integration and the estimate, on one core. The
//! hull of a sphere's vertices is the worst case for it: every vertex is a corner.
//!
//! The `shells_` rows are shells in one open mesh: the cost of deciding that one lies inside the
//! other (exact segment–triangle tests where their boxes overlap, one winding number each way), or
//! of deciding their faces piece by piece where they touch or cut each other (`crossing`: two
//! shells touching inside; `cutting`: three, 61,439 faces, two of which cut the third along
//! circles; `coincident`: one box stored twice, triangulated as two grids, 51,852 faces).
//!
//! `cargo bench --bench open_mesh`. The figures go to docs/benchmarks.md.

// The allocator of the `urdf-inertia` binary (see the binary's src/main.rs), so that timings are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::path::Path;
use urdf_inertia::mass::Polygons;
use urdf_inertia::mesh::health::{self, HealthOptions};
use urdf_inertia::mesh::open::OpenMeshModel;
use urdf_inertia::mesh::RawMesh;

/// An icosphere of level 7 without the faces whose corners all satisfy `cut`.
fn cut_sphere(cut: impl Fn([f64; 3]) -> bool) -> RawMesh {
    let (v, f) = common::icosphere(7);
    let kept: Vec<[u32; 3]> = f
        .iter()
        .copied()
        .filter(|t| !t.iter().all(|&i| cut(v[i as usize])))
        .collect();
    RawMesh {
        vertices: v,
        faces: Polygons::from_triangles(&kept),
        ..RawMesh::default()
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("open_mesh");
    g.sample_size(10);
    let meshes = [
        ("bowl", cut_sphere(|p| p[2] > 0.0)),
        ("quarter_cut", cut_sphere(|p| p[0] > 0.0 && p[2] > 0.0)),
    ];
    for (name, mesh) in meshes {
        for model in [
            OpenMeshModel::Trusted,
            OpenMeshModel::Caps,
            OpenMeshModel::Hull,
        ] {
            let options = HealthOptions {
                open_mesh: model,
                ..HealthOptions::default()
            };
            let faces = mesh.faces.len();
            g.bench_function(format!("{name}_{faces}faces_{}", model.name()), |b| {
                b.iter(|| {
                    let s = health::make_solid(black_box(&mesh), Path::new("open.stl"), options);
                    black_box(s.map(|s| s.unit.mass).ok())
                });
            });
        }
    }
    // Shells classified by the winding number: a level-6 icosphere (20,480 faces) with one face
    // removed (a planar hole: exact caps) around a second one at half the radius (doubly enclosed:
    // dropped), or moved half a radius so that the two touch inside (decided face by face), or two
    // at 0.6 of the radius moved 0.7 each way, which cut the outer one (decided face by face).
    // And coincident shells as CAD assemblies export them: one box stored twice, its faces a 36 × 36
    // and a 55 × 55 grid (each triangle of one under a dozen of the other's).
    let twice = {
        let (lo, hi) = ([0.0; 3], [1.0; 3]);
        let (v, f) = common::shells::together(&[
            (&common::grid_box(lo, hi, 36), false),
            (&common::grid_box(lo, hi, 55), false),
        ]);
        RawMesh {
            vertices: v,
            faces: Polygons::from_triangles(&f),
            ..RawMesh::default()
        }
    };
    let meshes = [
        ("nested", common::shells::spheres(&[(0.0, 0.5)])),
        ("crossing", common::shells::spheres(&[(0.5, 0.5)])),
        (
            "cutting",
            common::shells::spheres(&[(-0.7, 0.6), (0.7, 0.6)]),
        ),
        ("coincident", twice),
    ];
    for (name, mesh) in meshes {
        let faces = mesh.faces.len();
        g.bench_function(format!("shells_{name}_{faces}faces"), |b| {
            b.iter(|| {
                let s = health::make_solid(
                    black_box(&mesh),
                    Path::new("shells.stl"),
                    HealthOptions::default(),
                );
                black_box(s.map(|s| s.unit.mass).ok())
            });
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
