//! The `urdf-inertia` binary: the command line (`cli`) over the library's one-way pipeline.
//!
//! The command line is the binary's own: the library never depends on it (a test in
//! `tests/layering.rs` keeps it so).
#![forbid(unsafe_code)]

mod cli;

/// mimalloc instead of the system allocator. The pipeline allocates a few large arrays per mesh
/// (vertex table, corner indices, edge buckets); glibc maps each one fresh and unmaps it when freed,
/// so every 4 KiB page is faulted in and zeroed again by the next array. mimalloc reuses what it
/// frees: on a 1.3 M-face STL, `urdf-inertia mesh` (one thread) made 25,300 page faults instead of
/// 37,400 and took 0.16–0.18 s instead of 0.19–0.22 s (15 runs each). Its transparent huge pages
/// (cargo feature `no_thp` off) were faster still, 0.13 s with 237 faults, but a run now and then
/// stalled in the kernel's page compaction (0.36 s, 0.25 s of it system time): predictable wins.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(cli::main());
}
