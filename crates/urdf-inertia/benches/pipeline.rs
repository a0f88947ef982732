//! The mesh pipeline stage by stage, on generated binary STL tori of 1 k to 1 M faces (4.2 M and
//! 10.2 M with `URDF_INERTIA_BENCH_HUGE=1`), reported as time per mesh and faces/s (ns per face =
//! 1e9 / throughput).
//!
//! `cargo bench --bench pipeline`. Stages:
//! * `read`: binary STL bytes (in memory) to a [`RawMesh`], corners welded as they are read (in
//!   chunks, in parallel when there are threads);
//! * `weld-soup`: the health step's exact weld of a triangle soup (three vertices per face, what a
//!   reader that does not weld delivers; a welded STL skips this step);
//! * `edges`: the proof that the surface is closed and consistently wound, with its components;
//! * `integrate`: one integration of the ten volume integrals (a clean mesh takes two, in one pass
//!   over its faces: the value, and the round-off estimate about a second reference point);
//! * `heal`: `make_solid`, everything after reading: edge analysis, ladder and integrations;
//! * `end-to-end`: read + heal, what `urdf-inertia mesh` does after the file is in memory.

// The allocator of the `urdf-inertia` binary (see the binary's src/main.rs), so that timings are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{
    black_box, criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput,
};
use std::borrow::Cow;
use std::path::Path;
use urdf_inertia::mass::integrals::volume_integrals;
use urdf_inertia::mass::IntegrationOptions;
use urdf_inertia::mesh::{self, health, stl, weld, RawMesh};

fn pipeline(c: &mut Criterion) {
    let mut group = c.benchmark_group("pipeline");
    // Tori of 2k × k quads: 4k² faces.
    let mut sizes = vec![16u32, 32, 64, 128, 256, 512];
    if std::env::var_os("URDF_INERTIA_BENCH_HUGE").is_some() {
        sizes.extend([1024, 1600]);
    }
    let path = Path::new("bench.stl");
    for k in sizes {
        let (v, f) = common::wild::torus(1.0, 0.4, 2 * k, k);
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
            b.iter(|| stl::parse(black_box(bytes), path).map(|m| m.faces.len()));
        });
        group.bench_with_input(BenchmarkId::new("edges", n), &raw, |b, raw| {
            b.iter(|| health::closed_consistent(black_box(&raw.faces)).map(|c| c.1));
        });
        group.bench_with_input(BenchmarkId::new("weld-soup", n), &soup, |b, soup| {
            b.iter(|| {
                weld::exact(black_box(&soup.vertices), &soup.faces)
                    .faces
                    .len()
            });
        });
        group.bench_with_input(BenchmarkId::new("integrate", n), &raw, |b, w| {
            b.iter(|| {
                volume_integrals(
                    black_box(&w.vertices),
                    &w.faces,
                    &IntegrationOptions::accurate(),
                )
            });
        });
        // The mesh as the binary hands it over (owned: a welded mesh becomes the solid without a copy);
        // the clone is set-up, not timed.
        group.bench_with_input(BenchmarkId::new("heal", n), &raw, |b, raw| {
            b.iter_batched(
                || raw.clone(),
                |raw| {
                    health::heal(
                        Cow::Owned(raw),
                        path,
                        health::HealthOptions::default(),
                        |_| weld::Precision::F32,
                    )
                    .map(|s| s.unit.mass)
                },
                BatchSize::LargeInput,
            );
        });
        group.bench_with_input(BenchmarkId::new("end-to-end", n), &bytes, |b, bytes| {
            b.iter(|| {
                stl::parse(black_box(bytes), path).and_then(|raw| {
                    mesh::solid_from_owned(raw, [1.0; 3], path, health::HealthOptions::default())
                        .map(|s| s.unit.mass)
                })
            });
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
