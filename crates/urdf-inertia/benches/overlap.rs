//! The overlap estimate of one link made of N overlapping convex pieces, what a convex decomposition
//! (V-HACD, `CoACD`) gives: 1, 10, 100, 300 and 1000 pieces.
//!
//! `cargo bench --bench overlap`. Each piece is a 320-triangle convex mesh (an icosphere of level 3
//! squashed into an ellipsoid of semi-axes 0.55 to 0.75, turned), placed on a unit lattice filled
//! x first, then y, then z (a cube of side ⌈N^⅓⌉), so that each piece overlaps its lattice neighbours
//! as the hulls of a decomposition overlap theirs, and its bounding box meets up to 26 others; and
//! (`cluster`, 10 to 1000) at random in a cube of side 2, where the pairs grow as N². Each
//! iteration is [`overlap::estimate`] from scratch (the locators built again), on one thread as the
//! target says ("one core"); `URDF_INERTIA_BENCH_THREADS` sets another count.

// The allocator of the `urdf-inertia` binary (see the binary's src/main.rs), so that timings are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{black_box, criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};
use std::path::Path;
use std::sync::Arc;
use urdf_inertia::mass::{mat_vec, Polygons};
use urdf_inertia::mesh::{health, RawMesh};
use urdf_inertia::overlap::{self, Aabb, PartShape, PlacedPart};

/// `n` convex pieces on a lattice (see the module docs), or (`cluster`) at random in a cube of side
/// 2, where each overlaps most others, placed as the link's parts.
fn pieces(n: usize, cluster: bool) -> Vec<PlacedPart> {
    let side = (1..=n.max(1)).find(|s: &usize| s * s * s >= n).unwrap_or(1);
    let (v, f) = common::icosphere(3);
    let mut rng = common::Rng(25);
    (0..n)
        .map(|i| {
            let axes = [0, 1, 2].map(|_| rng.range(0.55, 0.75));
            let rpy = [0, 1, 2].map(|_| rng.range(-1.0, 1.0));
            let vertices: Vec<[f64; 3]> = v
                .iter()
                .map(|p| [0, 1, 2].map(|k| p[k] * axes[k]))
                .collect();
            let raw = RawMesh {
                vertices,
                faces: Polygons::from_triangles(&f),
                ..RawMesh::default()
            };
            let solid = health::make_solid(
                &raw,
                Path::new("piece.stl"),
                health::HealthOptions::default(),
            )
            .expect("a closed convex piece");
            let rotation = common::rotation(rpy);
            let lattice = [i % side, i / side % side, i / (side * side)].map(|c| c as f64);
            let translation = if cluster {
                [0, 1, 2].map(|_| rng.range(0.0, 2.0))
            } else {
                lattice
            };
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for p in &solid.vertices {
                let q = mat_vec(&rotation, *p);
                for k in 0..3 {
                    lo[k] = lo[k].min(q[k] + translation[k]);
                    hi[k] = hi[k].max(q[k] + translation[k]);
                }
            }
            PlacedPart {
                volume: solid.unit.mass,
                shape: PartShape::Mesh(Arc::new(solid)),
                rotation,
                translation,
                bbox: Aabb::new(lo, hi),
                locator: None,
            }
        })
        .collect()
}

fn estimate(c: &mut Criterion) {
    let threads = std::env::var("URDF_INERTIA_BENCH_THREADS")
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool");
    let mut group = c.benchmark_group("overlap");
    group.sample_size(10);
    for (name, n) in [1usize, 10, 100, 300, 1000]
        .map(|n| ("lattice", n))
        .into_iter()
        .chain([10, 100, 300, 1000].map(|n| ("cluster", n)))
    {
        let parts = pieces(n, name == "cluster");
        // What the estimate says, once: the grid the cap gives and the bound that comes with it.
        let volume: f64 = parts.iter().map(|p| p.volume).sum();
        match pool.install(|| overlap::estimate(&mut parts.clone())) {
            overlap::Overlap::Estimated(mut e) => {
                e.parts.clear();
                eprintln!("{name} of {n} pieces, {volume:.4} m³ in all: {e:?}");
            }
            other => eprintln!("{name} of {n} pieces: {other:?}"),
        }
        group.bench_with_input(BenchmarkId::new(name, n), &parts, |b, parts| {
            b.iter_batched(
                || parts.clone(),
                |mut parts| pool.install(|| overlap::estimate(black_box(&mut parts))),
                BatchSize::LargeInput,
            );
        });
    }
    group.finish();
}

criterion_group!(benches, estimate);
criterion_main!(benches);
