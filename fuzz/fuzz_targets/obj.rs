//! The obj reader, then healing and integration of what it reads.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-fuzz-dir/fuzz.obj");
    common::heal(urdf_inertia::mesh::obj::parse(data, path), path);
});
