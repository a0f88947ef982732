//! Writes the glTF fixtures the coal comparison reads (`validation/gltf_coal.py`): boxes through every
//! buffer kind and primitive mode, a node tree, a mirrored node and a box standing along +Y.
//!
//! Usage: cargo run --release --example `make_gltf_fixtures` -- OUTDIR

#[path = "../tests/common/gltf_gen.rs"]
mod gltf_gen;

use gltf_gen::{box_builder, box_strip_fan, box_two_primitives, box_unindexed, GltfBuilder};
use serde_json::json;
use std::path::Path;

const SIZE: [f32; 3] = [0.5, 0.25, 0.125];
const CENTRE: [f32; 3] = [1.0, 2.0, 3.0];

/// A box under a child node (quarter turn about X and a translation, as a matrix); with `parent`, under
/// a TRS parent too; with `extra_root`, beside an empty second root node.
fn tree(parent: bool, extra_root: bool) -> GltfBuilder {
    let matrix = [
        1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.25, 0.0, -0.5, 1.0,
    ];
    let mut b = box_builder(SIZE, CENTRE, json!({ "matrix": matrix }));
    let mut roots = vec![0];
    if parent {
        let half = 0.35f64;
        let q = [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0].map(|a: f64| (a * half.sin()) as f32);
        let p = b.node(json!({"children": [0], "translation": [0.5, -1.25, 2.0], "rotation": [q[0], q[1], q[2], half.cos() as f32], "scale": [2.0, 2.0, 2.0]}));
        roots = vec![p];
    }
    if extra_root {
        roots.push(b.node(json!({"name": "empty"})));
    }
    b.scenes[0] = json!({ "nodes": roots });
    b
}

fn main() -> std::io::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "gltf_fixtures".into());
    let dir = Path::new(&out);
    std::fs::create_dir_all(dir)?;
    let b = box_builder(SIZE, CENTRE, json!({}));
    std::fs::write(dir.join("box.glb"), b.glb())?;
    std::fs::write(dir.join("box_data_uri.gltf"), b.gltf_data_uri())?;
    std::fs::write(
        dir.join("box_external.gltf"),
        b.gltf_external("box_external.bin"),
    )?;
    std::fs::write(dir.join("box_external.bin"), &b.bin)?;
    std::fs::write(
        dir.join("strip_fan.glb"),
        box_strip_fan(SIZE, CENTRE, false).glb(),
    )?;
    std::fs::write(
        dir.join("strip_fan_nodes.glb"),
        box_strip_fan(SIZE, CENTRE, true).glb(),
    )?;
    std::fs::write(
        dir.join("two_primitives.glb"),
        box_two_primitives(SIZE, CENTRE).glb(),
    )?;
    std::fs::write(dir.join("unindexed.glb"), box_unindexed(SIZE, CENTRE).glb())?;
    std::fs::write(
        dir.join("standing_y.glb"),
        box_builder([0.25, 2.0, 0.5], [0.0, 1.0, 0.0], json!({})).glb(),
    )?;
    std::fs::write(dir.join("child_only.glb"), tree(false, false).glb())?;
    std::fs::write(dir.join("tree_two_roots.glb"), tree(true, true).glb())?;
    std::fs::write(dir.join("tree_single_root.glb"), tree(true, false).glb())?;
    std::fs::write(
        dir.join("mirrored.glb"),
        box_builder(SIZE, CENTRE, json!({"scale": [-1.0, 1.0, 1.0]})).glb(),
    )?;
    println!("wrote glTF fixtures to {}", dir.display());
    Ok(())
}
