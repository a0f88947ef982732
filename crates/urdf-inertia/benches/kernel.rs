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
            });
        });
        let plain = IntegrationOptions {
            summation: urdf_inertia::mass::Summation::Plain,
            ..IntegrationOptions::accurate()
        };
        group.bench_with_input(BenchmarkId::new("ours-plain-sum", f.len()), &f, |b, f| {
            b.iter(|| triangle_integrals(black_box(&v), black_box(f), &plain));
        });
        if level <= 6 {
            let polys = Polygons::from_triangles(&f);
            group.bench_with_input(BenchmarkId::new("paper", f.len()), &polys, |b, p| {
                b.iter(|| {
                    mirtich_polygons(black_box(&v), black_box(p), &IntegrationOptions::paper())
                });
            });
        }
    }
    group.finish();
}

/// A thin plate 1 × 1 × 1e-6 tessellated into `n × n` squares per side, rotated and moved 1e4 away:
/// nearly every face (the big ones) takes the accurate-face path.
fn thin_plate(n: u32) -> common::Mesh {
    let w = n + 1;
    let mut v = Vec::new();
    for z in [-0.5e-6, 0.5e-6] {
        for j in 0..w {
            for i in 0..w {
                let at = |k: u32| f64::from(k) / f64::from(n) - 0.5;
                v.push([at(i), at(j), z]);
            }
        }
    }
    let top = w * w;
    let mut f = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * w + i;
            let (b, c, d) = (a + 1, a + w, a + w + 1);
            f.extend([[a, c, b], [b, c, d]]);
            f.extend([[top + a, top + b, top + c], [top + b, top + d, top + c]]);
        }
    }
    // The rim, walked around the bottom boundary.
    let ring: Vec<u32> = (0..n)
        .chain((0..n).map(|j| j * w + n))
        .chain((1..=n).rev().map(|i| n * w + i))
        .chain((1..=n).rev().map(|j| j * w))
        .collect();
    for k in 0..ring.len() {
        let (p, q) = (ring[k], ring[(k + 1) % ring.len()]);
        f.extend([[p, q, top + q], [p, top + q, top + p]]);
    }
    let rot = common::rotation([0.7, -1.3, 2.9]);
    common::transform(&(v, f), 1.0, &rot, [1e4, -2e4, 3e4])
}

/// The accurate-face path (error-free products for ill-conditioned faces) against the fast path on
/// the same number of faces: `accurate` re-evaluates nearly every face, `fast` none.
fn accurate(c: &mut Criterion) {
    let mut group = c.benchmark_group("kernel-accurate");
    for n in [32u32, 128, 512] {
        let (v, f) = thin_plate(n);
        group.throughput(Throughput::Elements(f.len() as u64));
        group.bench_with_input(BenchmarkId::new("accurate", f.len()), &f, |b, f| {
            b.iter(|| {
                triangle_integrals(black_box(&v), black_box(f), &IntegrationOptions::accurate())
            });
        });
        let fast = IntegrationOptions {
            accurate_faces: false,
            ..IntegrationOptions::accurate()
        };
        group.bench_with_input(BenchmarkId::new("fast", f.len()), &f, |b, f| {
            b.iter(|| triangle_integrals(black_box(&v), black_box(f), &fast));
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = kernel, accurate
}
criterion_main!(benches);
