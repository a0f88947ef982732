//! Density-map lookups: N links against N glob rules, for N = 100, 300, 1000. Globs are compiled once
//! into glob sets when the map is read, so the cost per lookup does not grow with the rules the way
//! compiling every pattern at every lookup did (`cargo bench --bench globs`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::fmt::Write;
use std::path::Path;
use urdf_inertia::density::DensityMap;

fn map(n: usize) -> String {
    let mut text = String::from("[links]\n");
    for i in 0..n {
        let p = match i % 3 {
            0 => format!("arm_{i}_*"),
            1 => format!("*_finger_{i}"),
            _ => format!("*leg_{i}*"),
        };
        let _ = writeln!(text, "\"{p}\" = {}.0", 1000 + i);
    }
    text
}

fn lookups(c: &mut Criterion) {
    let mut g = c.benchmark_group("links_x_rules");
    for n in [100usize, 300, 1000] {
        let text = map(n);
        let links: Vec<String> = (0..n).map(|i| format!("leg_{i}_link")).collect();
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                let m = DensityMap::parse(&text, Path::new("d.toml")).expect("map");
                links.iter().filter(|l| m.link_rule(l).is_some()).count()
            });
        });
    }
    g.finish();
}

criterion_group!(benches, lookups);
criterion_main!(benches);
