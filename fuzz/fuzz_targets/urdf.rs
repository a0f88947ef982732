//! The URDF scan (decoding included), then splicing an `<inertial>` into every link and scanning the
//! result again, which must read.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-fuzz-dir/fuzz.urdf");
    let Ok(robot) = urdf_inertia::urdf::scan_bytes(data.to_vec(), path) else {
        return;
    };
    let _ = urdf_inertia::check(&robot, &urdf_inertia::FillOptions::default());
    let updates: Vec<_> = (0..robot.links.len())
        .map(|i| (i, urdf_inertia::mass::primitives::sphere(0.1, 1000.0)).into())
        .collect();
    // A text that would not re-encode to the same bytes is refused, not written.
    let Ok(out) = urdf_inertia::urdf::write::splice(&robot, &updates, &Default::default()) else {
        return;
    };
    assert!(
        urdf_inertia::urdf::scan(out, path).is_ok(),
        "what was spliced does not read back"
    );
});
