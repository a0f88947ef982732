//! The worker threads: one rayon pool for the library's parallel work, started on first use (a run
//! that never shares work out starts no thread), no larger than [`MAX_THREADS_PER_CORE`] threads a
//! core, and falling back to the calling thread alone when no thread can be started (a container's
//! process limit, `ulimit -u`): rayon's own global pool panics then.
//!
//! Every parallel section of the library runs inside [`install`]; the size comes from
//! `RAYON_NUM_THREADS` (rayon's own variable, read as rayon reads it: a positive integer, anything
//! else means one thread per core).

use std::sync::OnceLock;

/// At most this many worker threads a core: `RAYON_NUM_THREADS=5000` once turned a run of
/// milliseconds into a minute of thread start-up and idle spinning (docs/benchmarks.md). More
/// threads than cores give no speed; a few more are allowed so that a test can run on more threads
/// than the machine has.
pub const MAX_THREADS_PER_CORE: usize = 4;

/// The pool, and a note when it is not what was asked for (capped, or the calling thread alone).
struct Pool {
    pool: rayon::ThreadPool,
    note: Option<String>,
}

static POOL: OnceLock<Option<Pool>> = OnceLock::new();

/// The pool's size: `requested` threads (one per core when `None`), capped.
pub fn pool_size(requested: Option<usize>, cores: usize) -> (usize, Option<String>) {
    let cap = (MAX_THREADS_PER_CORE * cores).max(8);
    match requested {
        Some(n) if n > cap => (
            cap,
            Some(format!(
                "RAYON_NUM_THREADS={n} is more threads than {cores} cores can use; {cap} are used"
            )),
        ),
        Some(n) => (n, None),
        None => (cores, None),
    }
}

fn start() -> Option<Pool> {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let requested = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|s| s.trim().parse::<usize>().ok())
        .filter(|&n| n > 0);
    let (n, note) = pool_size(requested, cores);
    match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
        Ok(pool) => Some(Pool { pool, note }),
        Err(e) => rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .use_current_thread()
            .build()
            .ok()
            .map(|pool| Pool {
                pool,
                note: Some(format!(
                    "cannot start {n} worker threads ({e}); working on one thread"
                )),
            }),
    }
}

/// Runs `f` in the library's pool: its rayon calls (`par_iter`, `scope`) use that pool. Called on a
/// thread of a rayon pool already (the library's, or one a program or a test runs the library in),
/// `f` runs there, in that pool. Without a pool at all (not even the calling thread could be made its
/// worker) `f` runs here, and would use rayon's global pool.
pub fn install<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_thread_index().is_some() {
        return f();
    }
    match POOL.get_or_init(start) {
        Some(p) => p.pool.install(f),
        None => f(),
    }
}

/// What to tell the user about the pool, once it has started: `RAYON_NUM_THREADS` capped, or no
/// thread could be started.
pub fn note() -> Option<&'static str> {
    POOL.get()?.as_ref()?.note.as_deref()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_counts_are_capped_at_four_a_core() {
        assert_eq!(pool_size(None, 2), (2, None));
        assert_eq!(pool_size(Some(3), 2), (3, None));
        assert_eq!(pool_size(Some(8), 2), (8, None));
        let (n, note) = pool_size(Some(5000), 2);
        assert_eq!(n, 8);
        assert!(note.unwrap().contains("RAYON_NUM_THREADS=5000"));
        assert_eq!(pool_size(Some(5000), 16).0, 64);
    }
}
