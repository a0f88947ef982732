//! The `urdf-inertia` binary: the command line (`cli`) over the library's one-way pipeline.
//!
//! The command line is the binary's own: the library never depends on it (a test in
//! `tests/layering.rs` keeps it so).
#![forbid(unsafe_code)]

mod cli;

fn main() {
    std::process::exit(cli::main());
}
