//! The mesh cache: each file read once and each (file, scale) healed and integrated once, across the
//! links of a robot and across robots (`check a.urdf b.urdf`, a corpus).

use super::health::{HealthOptions, Solid};
use super::{read, solid_from_owned, solid_from_raw, MeshError, RawMesh};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Reads each file once and heals each (file, scale) once. A raw mesh lives only until its scales are
/// healed: the cache keeps the solids (a read error as the error of each scale asked for), and of the
/// files only which were read (a file asked for again with a new scale, by a later call sharing the
/// cache, is read again).
#[derive(Debug, Default)]
pub struct MeshCache {
    read: HashSet<PathBuf>,
    solids: SolidMap,
    pub load_time: Duration,
    pub integrate_time: Duration,
}

impl MeshCache {
    /// Reads and heals every (file, scale) that `needs` names and the cache lacks, in parallel (each
    /// file once, then each of its scales), and runs `task(i, solids)` for each `needs[i]` on the same
    /// threads as soon as the files it names are healed: a robot's links start while its largest
    /// meshes are still being healed, where they used to wait for the last file. The tasks' results
    /// come in their order, and what the cache holds afterwards does not depend on the order in which
    /// things finish. Times are summed over threads (CPU time).
    pub fn load_and_run<R: Send>(
        &mut self,
        needs: &[Vec<(PathBuf, [f64; 3])>],
        options: HealthOptions,
        task: impl Fn(usize, &Solids<'_>) -> R + Sync,
    ) -> Vec<R> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        use std::sync::{Mutex, OnceLock};
        let work = self.missing(needs.iter().flatten());
        let index: HashMap<&PathBuf, usize> = work
            .iter()
            .enumerate()
            .map(|(w, (_, p, _))| (*p, w))
            .collect();
        // The files each task waits for, and the tasks each file may release.
        let waits: Vec<Vec<usize>> = needs
            .iter()
            .map(|n| {
                let mut w: Vec<usize> = n
                    .iter()
                    .filter_map(|(p, _)| index.get(p).copied())
                    .collect();
                w.sort_unstable();
                w.dedup();
                w
            })
            .collect();
        let mut releases = vec![Vec::new(); work.len()];
        for (t, w) in waits.iter().enumerate() {
            for &w in w {
                releases[w].push(t);
            }
        }
        let pending: Vec<AtomicUsize> = waits.iter().map(|w| AtomicUsize::new(w.len())).collect();
        let done: Vec<OnceLock<LoadedFile>> = work.iter().map(|_| OnceLock::new()).collect();
        let results: Mutex<Vec<Option<R>>> = Mutex::new(needs.iter().map(|_| None).collect());
        let solids = Solids {
            cached: &self.solids,
            index: &index,
            done: &done,
            options,
        };
        let load = |w: usize| {
            let (_, path, scales) = &work[w];
            let _ = done[w].set(load_file(path, scales, options));
        };
        let run = |t: usize| {
            let r = task(t, &solids);
            results
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)[t] = Some(r);
        };
        // Nothing to share out: all here, without touching rayon, whose first use starts its global
        // pool (a thread per core, idle workers spinning in sched_yield) and hands the scope to a
        // worker while this thread waits. On URDFs whose collision geometry has no mesh (ur3, a1)
        // that was 0.35–0.65 ms of a 2–2.8 ms task-clock and 22 page faults per process (perf stat
        // -r 50, 2 cores); pre-commit and the benchmarks run one process per URDF.
        if work.len() <= 1 && needs.len() <= 1 {
            (0..work.len()).for_each(load);
            (0..needs.len()).for_each(run);
        } else {
            // Each thread takes the next file (largest first) while there is one; a healed file
            // queues the tasks it completes, which a thread runs once no file is left to take.
            let next = AtomicUsize::new(0);
            crate::threads::install(|| {
                rayon::scope(|s| {
                    for _ in 0..rayon::current_num_threads().min(work.len()) {
                        s.spawn(|s| loop {
                            let w = next.fetch_add(1, Ordering::Relaxed);
                            if w >= work.len() {
                                break;
                            }
                            load(w);
                            for &t in &releases[w] {
                                if pending[t].fetch_sub(1, Ordering::AcqRel) == 1 {
                                    s.spawn(move |_| run(t));
                                }
                            }
                        });
                    }
                    for (t, w) in waits.iter().enumerate() {
                        if w.is_empty() {
                            s.spawn(move |_| run(t));
                        }
                    }
                })
            });
        }
        let loaded: Vec<LoadedFile> = done.into_iter().filter_map(OnceLock::into_inner).collect();
        self.insert(loaded);
        let results = results
            .into_inner()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        results.into_iter().flatten().collect()
    }

    /// The files of `items` with the scales the cache lacks, largest file first.
    fn missing<'p>(
        &self,
        items: impl Iterator<Item = &'p (PathBuf, [f64; 3])>,
    ) -> Vec<(u64, &'p PathBuf, Vec<[f64; 3]>)> {
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
        work
    }

    /// Files read and healed, into the cache in the order given.
    fn insert(&mut self, loaded: Vec<LoadedFile>) {
        for (path, solids, load, integrate) in loaded {
            self.load_time += load;
            self.integrate_time += integrate;
            for (scale, solid) in solids {
                self.solids
                    .insert((path.clone(), scale.map(f64::to_bits)), solid);
            }
            self.read.insert(path);
        }
    }

    /// Number of distinct files read.
    pub fn files(&self) -> usize {
        self.read.len()
    }
}

/// The solids of one read mesh at each of its scales (the read error for each, if it failed). The last
/// scale takes the mesh itself, so a file used at one scale (the common case) is not copied.
fn heal_scales(
    raw: Result<RawMesh, MeshError>,
    scales: &[[f64; 3]],
    path: &Path,
    options: HealthOptions,
) -> SolidsByScale {
    let raw = match raw {
        Ok(raw) => raw,
        Err(e) => return scales.iter().map(|&s| (s, Err(e.clone()))).collect(),
    };
    let Some((&last, rest)) = scales.split_last() else {
        return Vec::new();
    };
    let mut solids: SolidsByScale = rest
        .iter()
        .map(|&s| (s, solid_from_raw(&raw, s, path, options).map(Arc::new)))
        .collect();
    solids.push((
        last,
        solid_from_owned(raw, last, path, options).map(Arc::new),
    ));
    solids
}

/// Each (file, scale bits) healed, or why not.
type SolidMap = HashMap<(PathBuf, [u64; 3]), Result<Arc<Solid>, MeshError>>;

type SolidsByScale = Vec<([f64; 3], Result<Arc<Solid>, MeshError>)>;

/// The solids a task of [`MeshCache::load_and_run`] reads: those its call healed, and those the cache
/// held before.
#[derive(Debug)]
pub struct Solids<'a> {
    cached: &'a SolidMap,
    index: &'a HashMap<&'a PathBuf, usize>,
    done: &'a [std::sync::OnceLock<LoadedFile>],
    options: HealthOptions,
}

impl Solids<'_> {
    /// The solid of `path` at `scale`. One the call was not asked for (never, as `fill` asks) is read
    /// and healed here, and not kept.
    pub fn get(&self, path: &PathBuf, scale: [f64; 3]) -> Result<Arc<Solid>, MeshError> {
        let bits = scale.map(f64::to_bits);
        let healed = self.index.get(path).and_then(|&w| self.done[w].get());
        let found = healed
            .and_then(|l| l.1.iter().find(|(s, _)| s.map(f64::to_bits) == bits))
            .map(|(_, solid)| solid)
            .or_else(|| self.cached.get(&(path.clone(), bits)));
        match found {
            Some(solid) => solid.clone(),
            None => load_file(path, &[scale], self.options).1.remove(0).1,
        }
    }
}

/// A file read and its scales healed: the path, the solids, read and heal times.
type LoadedFile = (PathBuf, SolidsByScale, Duration, Duration);

fn load_file(path: &Path, scales: &[[f64; 3]], options: HealthOptions) -> LoadedFile {
    let t0 = Instant::now();
    let raw = read(path);
    let t1 = Instant::now();
    let solids = heal_scales(raw, scales, path, options);
    // The raw mesh has ended, before the next file of this thread is read.
    (path.to_path_buf(), solids, t1 - t0, t1.elapsed())
}
