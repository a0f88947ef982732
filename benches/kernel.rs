//! The integration kernel on in-memory meshes, 1k to 1.3M triangles, reported as time per face.
//!
//! `cargo bench --bench kernel`; criterion prints the time per mesh and the throughput in faces/s
//! (ns per face = 1e9 / throughput).

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use urdf_inertia::mass::integrals::{mirtich_polygons, triangle_integrals};
use urdf_inertia::mass::{IntegrationOptions, Polygons};

fn kernel(c: &mut Criterion) {
    let mut group = c.benchmark_group("kernel");
    for level in [4u32, 5, 6, 7, 8, 9] {
        let (v, f) = common::icosphere(level);
        // Moved away from the origin, as real parts are.
        let v: Vec<[f64; 3]> = v
            .iter()
            .map(|p| [p[0] + 3.0, p[1] - 1.0, p[2] + 0.5])
            .collect();
        group.throughput(Throughput::Elements(f.len() as u64));
        group.bench_with_input(BenchmarkId::new("ours", f.len()), &f, |b, f| {
            b.iter(|| {
                triangle_integrals(black_box(&v), black_box(f), &IntegrationOptions::accurate())
            })
        });
        let plain = IntegrationOptions {
            summation: urdf_inertia::mass::Summation::Plain,
            ..IntegrationOptions::accurate()
        };
        group.bench_with_input(BenchmarkId::new("ours-plain-sum", f.len()), &f, |b, f| {
            b.iter(|| triangle_integrals(black_box(&v), black_box(f), &plain))
        });
        if level <= 6 {
            let polys = Polygons::from_triangles(&f);
            group.bench_with_input(BenchmarkId::new("paper", f.len()), &polys, |b, p| {
                b.iter(|| {
                    mirtich_polygons(black_box(&v), black_box(p), &IntegrationOptions::paper())
                })
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = kernel
}
criterion_main!(benches);
