//! One `make_solid` of a `shells_` row of `benches/open_mesh.rs` (`crossing` or `cutting`), for
//! instruction counts under callgrind (docs/benchmarks.md, the shells rows):
//! `RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/shells_once cutting`.

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::Path;
use urdf_inertia::mass::Polygons;
use urdf_inertia::mesh::health::{self, HealthOptions};
use urdf_inertia::mesh::RawMesh;

/// The benchmark's `spheres`: an icosphere of level 6 without its first face, and for each
/// (offset, radius) a whole one scaled by `radius` and moved by `offset` along x.
fn spheres(others: &[(f64, f64)]) -> RawMesh {
    let (v, f) = common::icosphere(6);
    let mut vertices = v.clone();
    let mut tris: Vec<[u32; 3]> = f[1..].to_vec();
    for &(offset, radius) in others {
        let n = vertices.len() as u32;
        vertices.extend(
            v.iter()
                .map(|p| [p[0] * radius + offset, p[1] * radius, p[2] * radius]),
        );
        tris.extend(f.iter().map(|t| t.map(|i| i + n)));
    }
    RawMesh {
        vertices,
        faces: Polygons::from_triangles(&tris),
        ..RawMesh::default()
    }
}

fn main() {
    let name = std::env::args().nth(1).unwrap_or_default();
    let mesh = match name.as_str() {
        "nested" => spheres(&[(0.0, 0.5)]),
        "crossing" => spheres(&[(0.5, 0.5)]),
        "cutting" => spheres(&[(-0.7, 0.6), (0.7, 0.6)]),
        _ => {
            eprintln!("usage: shells_once (nested | crossing | cutting)");
            std::process::exit(2);
        }
    };
    let s = health::make_solid(&mesh, Path::new("shells.stl"), HealthOptions::default());
    match s {
        Ok(s) => println!("{name}: {} faces, mass {:e}", mesh.faces.len(), s.unit.mass),
        Err(e) => println!("{name}: {e}"),
    }
}
