//! See xacro_check.rs: one input per run, written to a directory of this process's own.
#![no_main]

#[path = "xacro_check.rs"]
#[allow(dead_code)] // the other target's half
mod xacro_check;

use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("urdf-inertia-fuzz-yaml-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("a temp directory");
        d
    })
}

fuzz_target!(|data: &[u8]| {
    xacro_check::yaml(data, dir());
});
