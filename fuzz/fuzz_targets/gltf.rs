//! The gltf reader, then healing and integration of what it reads.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-fuzz-dir/fuzz.gltf");
    common::heal(urdf_inertia::mesh::gltf::parse(data, path, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE), path);
});
