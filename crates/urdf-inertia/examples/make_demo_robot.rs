//! Writes the demo robot's meshes under `robots/demo_arm_description/meshes/` (the URDF and the density
//! map there are hand-written). Every file is made by this project: `cargo run --example make_demo_robot`.
//!
//! The meshes cover each reader: a binary STL in millimetres (scaled 0.001 in the URDF) whose header
//! starts with `solid`, an ASCII STL, an OBJ of quads and hexagons in two objects, a COLLADA file with
//! `<unit meter="0.001">` and a node `<matrix>`, and an asymmetric wedge used with a mirroring scale.

#[path = "../tests/common/mod.rs"]
mod common;

use common::box_mesh;
use std::fmt::Write as _;
use std::path::Path;
use urdf_inertia::mesh::stl::{write_ascii, write_binary};

#[allow(clippy::too_many_lines)] // a script writing the demo robot's files one after another
fn main() -> std::io::Result<()> {
    let dir = Path::new("robots/demo_arm_description/meshes");
    std::fs::create_dir_all(dir)?;

    // Shoulder: an 80 × 80 × 200 mm box, binary STL whose header starts with "solid".
    let (v, f) = box_mesh([80.0, 80.0, 200.0]);
    let v: Vec<[f64; 3]> = v.iter().map(|p| [p[0], p[1], p[2] + 100.0]).collect();
    std::fs::write(
        dir.join("shoulder.STL"),
        write_binary(b"solid shoulder exported by a CAD tool", &v, &f),
    )?;

    // Battery in the base: ASCII STL, 0.12 × 0.08 × 0.04 m.
    let (v, f) = box_mesh([0.12, 0.08, 0.04]);
    std::fs::write(dir.join("battery.stl"), write_ascii(&v, &f))?;

    // Upper arm: a hexagonal prism (radius 0.04 m, 0.3 m long along z) as quads and two hexagons,
    // split into two OBJ objects (the sides, and the caps).
    let mut obj = String::from("# demo upper arm: hexagonal prism\nmtllib missing.mtl\no sides\n");
    for k in 0..6 {
        let a = std::f64::consts::PI / 3.0 * f64::from(k);
        writeln!(obj, "v {} {} 0", 0.04 * a.cos(), 0.04 * a.sin()).ok();
    }
    for k in 0..6 {
        let a = std::f64::consts::PI / 3.0 * f64::from(k);
        writeln!(obj, "v {} {} 0.3", 0.04 * a.cos(), 0.04 * a.sin()).ok();
    }
    obj.push_str("usemtl grey\n");
    for k in 0..6 {
        let (a, b) = (k + 1, (k + 1) % 6 + 1);
        writeln!(obj, "f {a}//1 {b}//1 {}//1 {}//1", b + 6, a + 6).ok();
    }
    obj.push_str("o caps\nf 6 5 4 3 2 1\nf -6 -5 -4 -3 -2 -1\n");
    std::fs::write(dir.join("upper_arm.obj"), obj)?;

    // Forearm: a 60 × 60 × 250 mm box in COLLADA, millimetre units, moved by a node matrix.
    let (v, f) = box_mesh([60.0, 60.0, 250.0]);
    let positions: Vec<String> = v
        .iter()
        .map(|p| format!("{} {} {}", p[0], p[1], p[2]))
        .collect();
    let indices: Vec<String> = f
        .iter()
        .map(|t| format!("{} {} {}", t[0], t[1], t[2]))
        .collect();
    let dae = format!(
        r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <unit name="millimeter" meter="0.001"/>
    <up_axis>Z_UP</up_axis>
  </asset>
  <library_geometries>
    <geometry id="forearm-mesh" name="forearm">
      <mesh>
        <source id="forearm-positions">
          <float_array id="forearm-positions-array" count="24">{}</float_array>
          <technique_common>
            <accessor source="#forearm-positions-array" count="8" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="forearm-vertices"><input semantic="POSITION" source="#forearm-positions"/></vertices>
        <triangles count="12"><input semantic="VERTEX" source="#forearm-vertices" offset="0"/><p>{}</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="forearm" name="forearm" type="NODE">
        <matrix sid="transform">1 0 0 0 0 1 0 0 0 0 1 125 0 0 0 1</matrix>
        <instance_geometry url="#forearm-mesh" name="forearm"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"##,
        positions.join(" "),
        indices.join(" ")
    );
    std::fs::write(dir.join("forearm.dae"), dae)?;

    // Wrist: an asymmetric wedge (right triangle 0.06 × 0.04 extruded 0.05 along z), used mirrored.
    let v = vec![
        [0.0, 0.0, 0.0],
        [0.06, 0.0, 0.0],
        [0.0, 0.04, 0.0],
        [0.0, 0.0, 0.05],
        [0.06, 0.0, 0.05],
        [0.0, 0.04, 0.05],
    ];
    let f: Vec<[u32; 3]> = vec![
        [0, 2, 1],
        [3, 4, 5],
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [2, 0, 3],
        [2, 3, 5],
    ];
    std::fs::write(dir.join("wrist_wedge.stl"), write_binary(b"wedge", &v, &f))?;
    println!("wrote the demo meshes under {}", dir.display());
    Ok(())
}
