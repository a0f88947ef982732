//! Bad input never panics: every reader gets truncations and byte-level mutations of valid files and must
//! return a value or an error.

mod common;

use common::{box_mesh, Rng};
use std::path::Path;
use urdf_inertia::mesh::health::HealthOptions;
use urdf_inertia::mesh::{self, collada, obj, stl};
use urdf_inertia::write::WriteOptions;

fn mutations(valid: &[u8], rng: &mut Rng, count: usize) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    // Every truncation length on small files, a spread on larger ones.
    let step = (valid.len() / 200).max(1);
    for n in (0..valid.len()).step_by(step) {
        out.push(valid[..n].to_vec());
    }
    for _ in 0..count {
        let mut m = valid.to_vec();
        for _ in 0..=(rng.next_u64() % 8) {
            let i = (rng.next_u64() % m.len() as u64) as usize;
            match rng.next_u64() % 3 {
                0 => m[i] = rng.next_u64() as u8,
                1 => {
                    m.remove(i);
                }
                _ => {
                    let alphabet = b"0123456789 -.e\n<>/\"=fv#";
                    m.insert(
                        i,
                        alphabet[(rng.next_u64() % alphabet.len() as u64) as usize],
                    );
                }
            }
            if m.is_empty() {
                break;
            }
        }
        out.push(m);
    }
    out
}

#[test]
fn mesh_readers_never_panic() {
    let mut rng = Rng(11);
    let (v, f) = box_mesh([1.0, 2.0, 3.0]);
    let binary = stl::write_binary(b"solid box", &v, &f);
    let ascii = stl::write_ascii(&v, &f).into_bytes();
    let objtext =
        b"o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\no b\nf 1 4 3\nf -3 -2 -1\n"
            .to_vec();
    let dae = std::fs::read(
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("robots/demo_arm_description/meshes/forearm.dae"),
    )
    .expect("demo dae");
    let p = Path::new("fuzz");
    for input in mutations(&binary, &mut rng, 3000)
        .iter()
        .chain(mutations(&ascii, &mut rng, 3000).iter())
    {
        if let Ok(m) = stl::parse(input, p) {
            if mesh::validate(&m, p).is_ok() {
                let _ = mesh::solid_from_raw(&m, [1.0; 3], p, HealthOptions::default());
            }
        }
    }
    for input in mutations(&objtext, &mut rng, 5000) {
        if let Ok(m) = obj::parse(&input, p) {
            if mesh::validate(&m, p).is_ok() {
                let _ = mesh::solid_from_raw(&m, [1.0, -1.0, 1.0], p, HealthOptions::default());
            }
        }
    }
    for input in mutations(&dae, &mut rng, 5000) {
        if let Ok(m) = collada::parse(&input, p) {
            if mesh::validate(&m, p).is_ok() {
                let _ = mesh::solid_from_raw(&m, [1.0; 3], p, HealthOptions::default());
            }
        }
    }
}

#[test]
fn urdf_scan_and_splice_never_panic() {
    let mut rng = Rng(12);
    let urdf = std::fs::read(
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("robots/demo_arm_description/urdf/demo_arm.urdf"),
    )
    .expect("demo urdf");
    for input in mutations(&urdf, &mut rng, 4000) {
        let Ok(text) = String::from_utf8(input) else {
            continue;
        };
        if let Ok(robot) = urdf_inertia::urdf::scan(text, Path::new("fuzz.urdf")) {
            let updates: Vec<_> = (0..robot.links.len())
                .map(|i| (i, urdf_inertia::mass::primitives::sphere(0.1, 1000.0)).into())
                .collect();
            let out = urdf_inertia::urdf::write::splice(&robot, &updates, &WriteOptions::default())
                .unwrap_or_default();
            // What was spliced must read back.
            assert!(urdf_inertia::urdf::scan(out, Path::new("fuzz.urdf")).is_ok());
        }
    }
}
