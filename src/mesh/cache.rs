//! The mesh cache: each file read once and each (file, scale) healed and integrated once, across the
//! links of a robot and across robots (`check a.urdf b.urdf`, a corpus).

use super::health::{HealthOptions, Solid};
use super::{read, solid_from_owned, solid_from_raw, MeshError, RawMesh};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Reads each file once and heals each (file, scale) once. A raw mesh lives only until its scales are
/// healed: the cache keeps the solids, and of each file read only whether it failed (a file asked for
/// again with a new scale, by a later call sharing the cache, is read again).
#[derive(Debug, Default)]
pub struct MeshCache {
    read: HashMap<PathBuf, Option<MeshError>>,
    solids: HashMap<(PathBuf, [u64; 3]), Result<Arc<Solid>, MeshError>>,
    pub load_time: Duration,
    pub integrate_time: Duration,
}

impl MeshCache {
    pub fn solid(
        &mut self,
        path: &PathBuf,
        scale: [f64; 3],
        options: HealthOptions,
    ) -> Result<Arc<Solid>, MeshError> {
        let key = (path.clone(), scale.map(f64::to_bits));
        if let Some(r) = self.solids.get(&key) {
            return r.clone();
        }
        let t0 = Instant::now();
        let raw = match self.read.get(path) {
            Some(Some(e)) => Err(e.clone()),
            _ => {
                let r = read(path);
                self.read.insert(path.clone(), r.as_ref().err().cloned());
                r
            }
        };
        let t1 = Instant::now();
        self.load_time += t1 - t0;
        let solid = raw
            .and_then(|raw| solid_from_owned(raw, scale, path, options))
            .map(Arc::new);
        self.integrate_time += t1.elapsed();
        self.solids.insert(key, solid.clone());
        solid
    }

    /// Reads and heals every not yet cached (file, scale) pair on all cores: each file once, then each
    /// of its scales. Times are summed over threads (CPU time).
    pub fn preload(&mut self, items: &[(PathBuf, [f64; 3])], options: HealthOptions) {
        let mut by_file: HashMap<&PathBuf, Vec<[f64; 3]>> = HashMap::new();
        for (path, scale) in items {
            if !self
                .solids
                .contains_key(&(path.clone(), scale.map(f64::to_bits)))
            {
                let scales = by_file.entry(path).or_default();
                if !scales
                    .iter()
                    .any(|s| s.map(f64::to_bits) == scale.map(f64::to_bits))
                {
                    scales.push(*scale);
                }
            }
        }
        // Largest files first, each taken by the next free thread (greedy longest-first): with the
        // hash map's random order, or rayon's halving of a sorted list, a robot's largest mesh could
        // start last on a core while the other idled. The results do not depend on the order.
        let mut work: Vec<(u64, &PathBuf, Vec<[f64; 3]>)> = by_file
            .into_iter()
            .map(|(p, s)| (std::fs::metadata(p).map_or(0, |m| m.len()), p, s))
            .collect();
        work.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(b.1)));
        let loaded = in_order_of_need(&work, |(_, path, scales)| load_file(path, scales, options));
        for (path, raw, solids, load, integrate) in loaded {
            self.load_time += load;
            self.integrate_time += integrate;
            for (scale, solid) in solids {
                self.solids
                    .insert((path.clone(), scale.map(f64::to_bits)), solid);
            }
            self.read.insert(path, raw);
        }
    }

    /// Number of distinct files read.
    pub fn files(&self) -> usize {
        self.read.len()
    }
}

/// The solids of one read mesh at each of its scales, and the read error if there was one. The last
/// scale takes the mesh itself, so a file used at one scale (the common case) is not copied.
fn heal_scales(
    raw: Result<RawMesh, MeshError>,
    scales: &[[f64; 3]],
    path: &Path,
    options: HealthOptions,
) -> (SolidsByScale, Option<MeshError>) {
    let raw = match raw {
        Ok(raw) => raw,
        Err(e) => {
            let solids = scales.iter().map(|&s| (s, Err(e.clone()))).collect();
            return (solids, Some(e));
        }
    };
    let Some((&last, rest)) = scales.split_last() else {
        return (Vec::new(), None);
    };
    let mut solids: SolidsByScale = rest
        .iter()
        .map(|&s| (s, solid_from_raw(&raw, s, path, options).map(Arc::new)))
        .collect();
    solids.push((
        last,
        solid_from_owned(raw, last, path, options).map(Arc::new),
    ));
    (solids, None)
}

type SolidsByScale = Vec<([f64; 3], Result<Arc<Solid>, MeshError>)>;

/// A file read and its scales healed: the path, the read error, the solids, read and heal times.
type Loaded = (
    PathBuf,
    Option<MeshError>,
    SolidsByScale,
    Duration,
    Duration,
);

fn load_file(path: &Path, scales: &[[f64; 3]], options: HealthOptions) -> Loaded {
    let t0 = Instant::now();
    let raw = read(path);
    let t1 = Instant::now();
    let (solids, error) = heal_scales(raw, scales, path, options);
    // The raw mesh has ended, before the next file of this thread is read.
    (path.to_path_buf(), error, solids, t1 - t0, t1.elapsed())
}

/// `f` of every item on all of rayon's threads, each thread taking the next item in order when it is
/// free; the results in the items' order.
fn in_order_of_need<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;
    // Nothing to share out with zero or one file: run it here, without touching rayon, whose first
    // use starts its global pool (a thread per core, idle workers spinning in sched_yield) and hands
    // the scope to a worker while this thread waits. On URDFs whose collision geometry has no mesh
    // (ur3, a1) that was 0.35–0.65 ms of a 2–2.8 ms task-clock and 22 page faults per process
    // (perf stat -r 50, 2 cores); pre-commit and the benchmarks run one process per URDF.
    if items.len() <= 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, R)>> = Mutex::new(Vec::with_capacity(items.len()));
    rayon::scope(|s| {
        for _ in 0..rayon::current_num_threads().min(items.len()) {
            s.spawn(|_| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                let r = f(item);
                done.lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner)
                    .push((i, r));
            });
        }
    });
    let mut done = done
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    done.sort_by_key(|d| d.0);
    done.into_iter().map(|d| d.1).collect()
}
