//! The `urdf-inertia` binary: everything lives in the library's `cli` module.

fn main() {
    std::process::exit(urdf_inertia::cli::main());
}
