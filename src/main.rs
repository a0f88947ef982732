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
/// (cargo feature `no_thp` off) are faster in back-to-back runs, but not in a virtual machine that
/// hands freed memory back to its host (virtio-balloon free page reporting, order 9 and up: whole
/// huge pages). On such a 2-core VM (1.3 M faces, one thread, interleaved): back to back, median
/// 146 ms against 190 ms, but 16 of 100 runs took 1.4 to 3× the median (1 of 100 with small pages); with
/// 3 s between runs, as a user runs it, 319 ms against 196 ms (189 ms of system time: the host
/// faults each huge page in again). The kernel's compaction stalled none of them (`compact_stall`
/// unchanged), as an earlier note here had guessed. Small pages cost the same either way.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(cli::main());
}
