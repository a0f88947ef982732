//! One `make_solid` of a `shells_` row of `benches/open_mesh.rs` (`nested`, `crossing`, `cutting` or `coincident`), for
//! instruction counts under callgrind (docs/benchmarks.md, the shells rows):
//! `RAYON_NUM_THREADS=1 valgrind --tool=callgrind target/release/examples/shells_once cutting`.

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::Path;
use urdf_inertia::mesh::health::{self, HealthOptions};

fn main() {
    let name = std::env::args().nth(1).unwrap_or_default();
    let mesh = match name.as_str() {
        "nested" => common::shells::spheres(&[(0.0, 0.5)]),
        "crossing" => common::shells::spheres(&[(0.5, 0.5)]),
        "cutting" => common::shells::spheres(&[(-0.7, 0.6), (0.7, 0.6)]),
        "coincident" => {
            let (lo, hi) = ([0.0; 3], [1.0; 3]);
            let (v, f) = common::shells::together(&[
                (&common::grid_box(lo, hi, 36), false),
                (&common::grid_box(lo, hi, 55), false),
            ]);
            urdf_inertia::mesh::RawMesh {
                vertices: v,
                faces: urdf_inertia::mass::Polygons::from_triangles(&f),
                ..urdf_inertia::mesh::RawMesh::default()
            }
        }
        _ => {
            eprintln!("usage: shells_once (nested | crossing | cutting | coincident)");
            std::process::exit(2);
        }
    };
    let s = health::make_solid(&mesh, Path::new("shells.stl"), HealthOptions::default());
    match s {
        Ok(s) => println!("{name}: {} faces, mass {:e}", mesh.faces.len(), s.unit.mass),
        Err(e) => println!("{name}: {e}"),
    }
}
