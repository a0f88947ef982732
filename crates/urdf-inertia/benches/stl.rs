//! ASCII STL against binary STL: the same generated torus (16 Ki to 1 Mi faces; 4 Mi with
//! `URDF_INERTIA_BENCH_HUGE=1`) as binary records and as ASCII text written as CAD exporters write it
//! (`%e` with 6 digits, two-space indents), read from a file to a welded mesh by [`stl::read`], on
//! one thread and on two, reported as faces/s (ns per face = 1e9 / throughput). The peer:
//! `mesh-loader` (one thread; it reads the whole file into memory, parses to f32 and does not weld)
//! on the same two files.
//!
//! `cargo bench --bench stl`.

// The allocator of the `urdf-inertia` binary (see the binary's src/main.rs), so that timings are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::fmt::Write as _;
use urdf_inertia::mesh::stl;

/// ASCII STL as exporters write it: six digits after the point, an exponent always.
fn exporter_ascii(v: &[[f64; 3]], f: &[[u32; 3]]) -> String {
    let mut s = String::from("solid part\n");
    for t in f {
        s.push_str("  facet normal 0.000000e+00 0.000000e+00 1.000000e+00\n    outer loop\n");
        for &i in t {
            let p = v[i as usize];
            let _ = writeln!(s, "      vertex {:.6e} {:.6e} {:.6e}", p[0], p[1], p[2]);
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid part\n");
    s
}

fn read(c: &mut Criterion) {
    let mut group = c.benchmark_group("stl");
    group.sample_size(10);
    let mut sizes = vec![64u32, 256, 512];
    if std::env::var_os("URDF_INERTIA_BENCH_HUGE").is_some() {
        sizes.push(1024);
    }
    let dir = tempfile::tempdir().expect("a temp dir");
    let pools: Vec<(usize, rayon::ThreadPool)> = [1, 2]
        .into_iter()
        .map(|t| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build();
            (t, pool.expect("a thread pool"))
        })
        .collect();
    for k in sizes {
        let (v, f) = common::wild::torus(1.0, 0.4, 2 * k, k);
        // f32 corners, as the binary file stores them, so both files hold the same mesh.
        let v: Vec<[f64; 3]> = v
            .iter()
            .map(|p| p.map(|c| f64::from((0.1 * c + 0.2) as f32)))
            .collect();
        let n = f.len();
        let binary = dir.path().join(format!("b{n}.stl"));
        let ascii = dir.path().join(format!("a{n}.stl"));
        std::fs::write(&binary, stl::write_binary(b"bench", &v, &f)).expect("write");
        std::fs::write(&ascii, exporter_ascii(&v, &f)).expect("write");
        group.throughput(Throughput::Elements(n as u64));
        for (name, path) in [
            ("mesh-loader binary", &binary),
            ("mesh-loader ascii", &ascii),
        ] {
            let id = BenchmarkId::new(name, n);
            group.bench_with_input(id, path, |b, path| {
                b.iter(|| {
                    let bytes = std::fs::read(black_box(path)).expect("read");
                    mesh_loader::stl::from_slice(&bytes).map(|s| s.meshes[0].faces.len())
                });
            });
        }
        for (threads, pool) in &pools {
            for (name, path) in [("binary", &binary), ("ascii", &ascii)] {
                let id = BenchmarkId::new(format!("{name}, {threads} thread(s)"), n);
                group.bench_with_input(id, path, |b, path| {
                    b.iter(|| {
                        pool.install(|| {
                            stl::read(black_box(path), urdf_inertia::input::DEFAULT_MAX_FILE_SIZE)
                                .map(|m| m.faces.len())
                        })
                    });
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, read);
criterion_main!(benches);
