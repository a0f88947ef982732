//! The density map parser, then the rule lookups fill makes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(map) = urdf_inertia::density::DensityMap::parse(text, Path::new("densities.toml"))
    else {
        return;
    };
    for name in ["base_link", "wrist_1", "left_finger_tip", ""] {
        let _ = map.link_rule(name);
        let _ = map.mesh_rule(&format!("package://robot/meshes/{name}.stl"));
    }
});
