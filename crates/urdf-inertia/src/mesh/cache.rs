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
///
/// Between calls it holds at most 256 MiB of solids (and half the memory budget), dropping
/// those used least recently (a later call that needs one reads it again). With a memory budget
/// ([`MeshCache::with_memory_budget`]) a file whose reading would need more than what is left of it
/// fails with an error naming it instead of exhausting the machine.
#[derive(Debug)]
pub struct MeshCache {
    read: HashSet<PathBuf>,
    solids: SolidMap,
    /// When each held solid was last asked for (the call's number) and the bytes it holds.
    usage: HashMap<SolidKey, (u64, u64)>,
    calls: u64,
    memory_budget: u64,
    /// The largest mesh file read, in bytes.
    max_file_size: u64,
    pub load_time: Duration,
    pub integrate_time: Duration,
}

impl Default for MeshCache {
    fn default() -> Self {
        Self::with_memory_budget(u64::MAX)
    }
}

/// Most bytes of solids held between calls: a check over many URDFs keeps the meshes that recent
/// files used, not every mesh of the run. 256 MiB holds the healed meshes of all 69 URDFs of
/// example-robot-data (1.46 M faces) several times over, so robots that share meshes read them once.
const HELD_AT_MOST: u64 = 256 << 20;

/// Peak memory of reading, welding and healing a mesh file, as a multiple of its size, per format:
/// the largest ratio measured for each format on a 1 M-face torus (docs/reliability.md, "Large
/// inputs"), rounded up. Instancing in COLLADA and glTF can multiply a file beyond this; their
/// expansion budget bounds that separately.
fn peak_per_byte(path: &Path) -> f64 {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("stl" | "obj") => 2.5,
        Some("glb" | "gltf") => 7.5,
        // COLLADA (`dae`) and anything else.
        _ => 3.0,
    }
}

/// The estimated peak memory of reading and healing `path`, `size` bytes long.
fn peak_of(path: &Path, size: u64) -> u64 {
    (size as f64 * peak_per_byte(path)) as u64
}

/// Bytes of memory a healed solid holds.
fn solid_bytes(solid: &Result<Arc<Solid>, MeshError>) -> u64 {
    solid.as_ref().map_or(256, |s| {
        (s.vertices.capacity() * 24
            + (s.faces.indices.capacity() + s.faces.starts.capacity()) * 4
            + 512) as u64
    })
}

/// `bytes` for people: KiB, MiB or GiB with one decimal.
fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= f64::from(1u32 << 30) {
        format!("{:.1} GiB", b / f64::from(1u32 << 30))
    } else if b >= f64::from(1u32 << 20) {
        format!("{:.1} MiB", b / f64::from(1u32 << 20))
    } else {
        format!("{:.1} KiB", b / 1024.0)
    }
}

impl MeshCache {
    /// An empty cache whose work stays within `bytes` of memory: a mesh file whose reading and
    /// healing would need more (its size times the format's measured peak ratio) fails with an
    /// error naming it, and solids held between calls are dropped, least recently used first,
    /// beyond half of it. `u64::MAX` (the default) sets no budget (the cache still holds no more
    /// than 256 MiB between calls).
    pub fn with_memory_budget(bytes: u64) -> Self {
        Self {
            read: HashSet::new(),
            solids: SolidMap::new(),
            usage: HashMap::new(),
            calls: 0,
            memory_budget: bytes,
            max_file_size: crate::input::DEFAULT_MAX_FILE_SIZE,
            load_time: Duration::ZERO,
            integrate_time: Duration::ZERO,
        }
    }

    /// The same, reading no mesh file larger than `bytes` (a glTF's buffers together as well);
    /// [`crate::input::DEFAULT_MAX_FILE_SIZE`] unless set.
    #[must_use]
    pub fn with_max_file_size(mut self, bytes: u64) -> Self {
        self.max_file_size = bytes;
        self
    }

    /// Bytes the held solids take.
    pub fn held_bytes(&self) -> u64 {
        self.usage.values().map(|&(_, b)| b).sum()
    }

    /// Counts a new call, marks the solids `needs` names as used by it, and drops old ones.
    fn start_call(&mut self, needs: &[Vec<(PathBuf, [f64; 3])>]) {
        self.calls += 1;
        let wanted: HashSet<SolidKey> = needs
            .iter()
            .flatten()
            .map(|(p, s)| (p.clone(), s.map(f64::to_bits)))
            .collect();
        for key in &wanted {
            if let Some(u) = self.usage.get_mut(key) {
                u.0 = self.calls;
            }
        }
        self.evict(&wanted);
    }

    /// Drops the least recently used solids, other than those `keep` names, until what is held
    /// fits in [`HELD_AT_MOST`] and half the budget.
    fn evict(&mut self, keep: &HashSet<SolidKey>) {
        let cap = (self.memory_budget / 2).min(HELD_AT_MOST);
        let mut held = self.held_bytes();
        if held <= cap {
            return;
        }
        let mut old: Vec<(u64, SolidKey, u64)> = self
            .usage
            .iter()
            .filter(|(k, _)| !keep.contains(*k))
            .map(|(k, &(used, bytes))| (used, k.clone(), bytes))
            .collect();
        old.sort_by(|a, b| a.0.cmp(&b.0).then_with(|| a.1.cmp(&b.1)));
        for (_, key, bytes) in old {
            if held <= cap {
                break;
            }
            self.solids.remove(&key);
            self.usage.remove(&key);
            // `read` keeps the file: it counts distinct files read, and whether a solid is read
            // again is decided by `solids` alone (`missing`).
            held -= bytes;
        }
    }

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
        self.start_call(needs);
        let work = self.missing(needs.iter().flatten());
        // The budget left beside what is held, and each file's estimated peak. When the files
        // together may not fit, they are read one after another on this thread, never two at once
        // (a wait for room inside rayon's pool could deadlock: a waiting worker may hold a part of
        // the very read it waits for); a file that alone does not fit is refused.
        let room = self.memory_budget.saturating_sub(self.held_bytes());
        let peaks: Vec<u64> = work
            .iter()
            .map(|(size, path, _)| peak_of(path, *size))
            .collect();
        let one_at_a_time = self.memory_budget != u64::MAX && peaks.iter().sum::<u64>() > room;
        let index: HashMap<&PathBuf, usize> = work
            .iter()
            .enumerate()
            .map(|(w, (_, p, _))| (*p, w))
            .collect();
        let (waits, releases) = schedule(needs, &index, work.len());
        let pending: Vec<AtomicUsize> = waits.iter().map(|w| AtomicUsize::new(w.len())).collect();
        let done: Vec<OnceLock<LoadedFile>> = work.iter().map(|_| OnceLock::new()).collect();
        let results: Mutex<Vec<Option<R>>> = Mutex::new(needs.iter().map(|_| None).collect());
        let solids = Solids {
            cached: &self.solids,
            index: &index,
            done: &done,
            options,
            max_file_size: self.max_file_size,
        };
        let load = |w: usize| {
            let (size, path, scales) = &work[w];
            let loaded = if self.memory_budget != u64::MAX && peaks[w] > room {
                refused(path, scales, peaks[w], *size, room)
            } else {
                load_file(path, scales, options, self.max_file_size)
            };
            let _ = done[w].set(loaded);
        };
        let run = |t: usize| {
            let r = task(t, &solids);
            results
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)[t] = Some(r);
        };
        // Nothing to share out: all here, without touching rayon, whose first use starts its global
        // pool (a thread per core, idle workers spinning in sched_yield) and hands the scope to a
        // worker while this thread waits: a fifth of a run on a URDF without meshes, which
        // pre-commit runs one process at a time (docs/benchmarks.md, figures behind choices).
        if one_at_a_time || (work.len() <= 1 && needs.len() <= 1) {
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
                });
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
                let key = (path.clone(), scale.map(f64::to_bits));
                self.usage
                    .insert(key.clone(), (self.calls, solid_bytes(&solid)));
                self.solids.insert(key, solid);
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

/// The files (indices into the work) each task waits for, and the tasks each file may release.
fn schedule(
    needs: &[Vec<(PathBuf, [f64; 3])>],
    index: &HashMap<&PathBuf, usize>,
    files: usize,
) -> (Vec<Vec<usize>>, Vec<Vec<usize>>) {
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
    let mut releases = vec![Vec::new(); files];
    for (t, w) in waits.iter().enumerate() {
        for &w in w {
            releases[w].push(t);
        }
    }
    (waits, releases)
}

/// A file and the bits of a scale.
type SolidKey = (PathBuf, [u64; 3]);

/// Each (file, scale bits) healed, or why not.
type SolidMap = HashMap<SolidKey, Result<Arc<Solid>, MeshError>>;

/// A file refused by the memory budget: the same error at every scale asked for.
fn refused(path: &Path, scales: &[[f64; 3]], peak: u64, size: u64, room: u64) -> LoadedFile {
    let why = format!(
        "reading and healing it needs about {} of memory ({} file), more than the {} left of the \
         memory budget (--max-memory)",
        human(peak),
        human(size),
        human(room)
    );
    let e = MeshError::new(path, None, super::MeshErrorKind::Io(why));
    let solids = scales.iter().map(|&s| (s, Err(e.clone()))).collect();
    (path.to_path_buf(), solids, Duration::ZERO, Duration::ZERO)
}

type SolidsByScale = Vec<([f64; 3], Result<Arc<Solid>, MeshError>)>;

/// The solids a task of [`MeshCache::load_and_run`] reads: those its call healed, and those the cache
/// held before.
#[derive(Debug)]
pub struct Solids<'a> {
    cached: &'a SolidMap,
    index: &'a HashMap<&'a PathBuf, usize>,
    done: &'a [std::sync::OnceLock<LoadedFile>],
    options: HealthOptions,
    max_file_size: u64,
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
            None => {
                load_file(path, &[scale], self.options, self.max_file_size)
                    .1
                    .remove(0)
                    .1
            }
        }
    }
}

/// A file read and its scales healed: the path, the solids, read and heal times.
type LoadedFile = (PathBuf, SolidsByScale, Duration, Duration);

fn load_file(
    path: &Path,
    scales: &[[f64; 3]],
    options: HealthOptions,
    max_file_size: u64,
) -> LoadedFile {
    let t0 = Instant::now();
    let raw = read(path, max_file_size);
    let t1 = Instant::now();
    let solids = heal_scales(raw, scales, path, options);
    // The raw mesh has ended, before the next file of this thread is read.
    (path.to_path_buf(), solids, t1 - t0, t1.elapsed())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A binary STL of a closed box `size` across, made of `split`² squares a side (two triangles
    /// each), so that its size in bytes can be chosen.
    fn box_stl(path: &Path, size: f64, split: u32) {
        let mut tris: Vec<[[f64; 3]; 3]> = Vec::new();
        let step = size / f64::from(split);
        for axis in 0..3 {
            for side in [0.0, size] {
                for i in 0..split {
                    for j in 0..split {
                        let (u0, v0) = (f64::from(i) * step, f64::from(j) * step);
                        let p = |u: f64, v: f64| {
                            let mut q = [0.0; 3];
                            q[axis] = side;
                            q[(axis + 1) % 3] = u;
                            q[(axis + 2) % 3] = v;
                            q
                        };
                        let (a, b, c, d) = (
                            p(u0, v0),
                            p(u0 + step, v0),
                            p(u0 + step, v0 + step),
                            p(u0, v0 + step),
                        );
                        // Outward: counter-clockwise seen from outside on the far side.
                        if side > 0.0 {
                            tris.push([a, b, c]);
                            tris.push([a, c, d]);
                        } else {
                            tris.push([a, c, b]);
                            tris.push([a, d, c]);
                        }
                    }
                }
            }
        }
        let mut bytes = vec![0u8; 80];
        bytes.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in &tris {
            bytes.extend_from_slice(&[0u8; 12]);
            for p in t {
                for c in p {
                    bytes.extend_from_slice(&(*c as f32).to_le_bytes());
                }
            }
            bytes.extend_from_slice(&[0u8; 2]);
        }
        std::fs::write(path, bytes).unwrap();
    }

    fn volume(cache: &mut MeshCache, path: &Path) -> Result<f64, MeshError> {
        let needs = vec![vec![(path.to_path_buf(), [1.0; 3])]];
        let mut out = cache.load_and_run(&needs, HealthOptions::default(), |_, solids| {
            solids.get(&needs[0][0].0, [1.0; 3]).map(|s| s.unit.mass)
        });
        out.remove(0)
    }

    /// Solids no call asks for again are dropped beyond half the budget, least recently used first,
    /// and read again (with the same result) when asked for; a file that alone needs more than the
    /// budget fails with an error that names the budget, and the cache goes on with the next.
    #[test]
    fn the_memory_budget_bounds_what_is_held_and_refuses_what_cannot_fit() {
        let tmp = tempfile::tempdir().unwrap();
        let files: Vec<PathBuf> = (0..6)
            .map(|i| {
                let p = tmp.path().join(format!("b{i}.stl"));
                box_stl(&p, 1.0 + f64::from(i), 20);
                p
            })
            .collect();
        let file_size = std::fs::metadata(&files[0]).unwrap().len();
        // Room to read one file at a time, not to keep all six.
        let budget = 2 * peak_of(&files[0], file_size);
        let mut cache = MeshCache::with_memory_budget(budget);
        let mut unbounded = MeshCache::default();
        for (i, f) in files.iter().enumerate() {
            let side = 1.0 + i as f64;
            let v = volume(&mut cache, f).unwrap();
            assert!((v - side.powi(3)).abs() < 1e-12 * side.powi(3), "{v}");
            assert_eq!(v.to_bits(), volume(&mut unbounded, f).unwrap().to_bits());
            assert!(
                cache.held_bytes()
                    <= budget / 2 + cache.usage[&(f.clone(), [1.0f64; 3].map(f64::to_bits))].1
            );
        }
        // Every solid stays in the unbounded cache; the bounded one dropped some.
        assert_eq!(unbounded.usage.len(), 6);
        assert!(cache.usage.len() < 6, "{}", cache.usage.len());
        // The first file was dropped, and reading it again gives the same numbers.
        let again = volume(&mut cache, &files[0]).unwrap();
        assert!((again - 1.0).abs() < 1e-12);
        // A file bigger than the whole budget is refused, by name of the budget.
        let big = tmp.path().join("big.stl");
        box_stl(&big, 1.0, 120);
        let e = volume(&mut cache, &big).unwrap_err().to_string();
        assert!(e.contains("memory budget (--max-memory)"), "{e}");
        assert!(e.contains("big.stl"), "{e}");
        // The cache goes on: a small file after it is read.
        assert!((volume(&mut cache, &files[1]).unwrap() - 8.0).abs() < 1e-11);
    }
}
