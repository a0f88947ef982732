//! The mesh pipeline stage by stage, on generated binary STL meshes of 1 k to 1.3 M faces (5.2 M with
//! `URDF_INERTIA_BENCH_HUGE=1`), reported as time per mesh and faces/s (ns per face = 1e9 / throughput).
//!
//! `cargo bench --bench pipeline`. Stages:
//! * `read`: binary STL bytes (in memory) to a [`RawMesh`], corners welded as they are read;
//! * `weld`: the health step's exact weld of that mesh (bit-identical corners, dropped faces);
//! * `weld-soup`: the same weld of a triangle soup (three vertices per face, as readers without a
//!   welding pass deliver);
//! * `integrate`: one integration of the ten volume integrals (the ladder runs three on a clean mesh:
//!   sign, value, and the round-off estimate about a second reference point);
//! * `heal`: `make_solid`, everything after reading: weld, edge analysis, ladder and integrations;
//! * `end-to-end`: read + heal, what `urdf-inertia mesh` does after the file is in memory.
//!
//! The edge analysis alone is `heal − weld − 3 × integrate` less the ladder's own small passes; the
//! callgrind profile in docs/accuracy.md splits it exactly.

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::path::Path;
use urdf_inertia::mass::integrals::volume_integrals;
use urdf_inertia::mass::IntegrationOptions;
use urdf_inertia::mesh::{self, health, stl, weld, RawMesh};

fn pipeline(c: &mut Criterion) {
    let mut group = c.benchmark_group("pipeline");
    let mut levels = vec![4u32, 5, 6, 7, 8, 9];
    if std::env::var_os("URDF_INERTIA_BENCH_HUGE").is_some() {
        levels.push(10);
    }
    let path = Path::new("bench.stl");
    for level in levels {
        let (v, f) = common::icosphere(level);
        // A 0.1 m part away from the origin, as real parts are.
        let v: Vec<[f64; 3]> = v
            .iter()
            .map(|p| [0.1 * p[0] + 0.3, 0.1 * p[1] - 0.1, 0.1 * p[2] + 0.05])
            .collect();
        let bytes = stl::write_binary(b"bench", &v, &f);
        let n = f.len();
        drop((v, f));
        let raw = stl::parse(&bytes, path).expect("parse");
        let soup = RawMesh {
            vertices: raw
                .faces
                .indices
                .iter()
                .map(|&i| raw.vertices[i as usize])
                .collect(),
            faces: urdf_inertia::mass::Polygons {
                indices: (0..3 * n as u32).collect(),
                starts: (0..=n as u32).map(|i| 3 * i).collect(),
            },
            ..RawMesh::default()
        };
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::new("read", n), &bytes, |b, bytes| {
            b.iter(|| stl::parse(black_box(bytes), path).map(|m| m.faces.len()))
        });
        group.bench_with_input(BenchmarkId::new("weld", n), &raw, |b, raw| {
            b.iter(|| {
                weld::exact(black_box(&raw.vertices), &raw.faces)
                    .faces
                    .len()
            })
        });
        group.bench_with_input(BenchmarkId::new("weld-soup", n), &soup, |b, soup| {
            b.iter(|| {
                weld::exact(black_box(&soup.vertices), &soup.faces)
                    .faces
                    .len()
            })
        });
        let welded = weld::exact(&raw.vertices, &raw.faces);
        group.bench_with_input(BenchmarkId::new("integrate", n), &welded, |b, w| {
            b.iter(|| {
                volume_integrals(
                    black_box(&w.vertices),
                    &w.faces,
                    &IntegrationOptions::accurate(),
                )
            })
        });
        group.bench_with_input(BenchmarkId::new("heal", n), &raw, |b, raw| {
            b.iter(|| {
                health::make_solid_stored_as(black_box(raw), path, Default::default(), || {
                    weld::Precision::F32
                })
                .map(|s| s.unit.mass)
            })
        });
        group.bench_with_input(BenchmarkId::new("end-to-end", n), &bytes, |b, bytes| {
            b.iter(|| {
                stl::parse(black_box(bytes), path).and_then(|raw| {
                    mesh::solid_from_raw(&raw, [1.0; 3], path, Default::default())
                        .map(|s| s.unit.mass)
                })
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(300));
    targets = pipeline
}
criterion_main!(benches);
