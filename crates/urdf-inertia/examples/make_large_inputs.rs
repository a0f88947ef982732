//! Writes the inputs of the whole-process measurements in docs/benchmarks.md (run by
//! `validation/memory.sh` and `validation/overlap.sh`, not by CI):
//!
//! - `make_large_inputs meshes DIR FACES`: one closed torus of about FACES triangles in every format
//!   the tool reads (binary and ASCII STL, OBJ, COLLADA, glTF binary), as `DIR/torus.{stl,ascii.stl,
//!   obj,dae,glb}`.
//! - `make_large_inputs torus-stl DIR FACES`: the same torus as binary STL only, `DIR/torus.stl` (the
//!   10 M-face input of `validation/threads.sh`, where the other formats would take gigabytes).
//! - `make_large_inputs pieces DIR N`: one link made of N overlapping convex pieces, what a convex
//!   decomposition (V-HACD, `CoACD`) gives: `DIR/pieces_N.urdf` and its N binary STL files. Each piece
//!   is the 320-triangle icosphere of `benches/overlap.rs` made an ellipsoid of semi-axes 0.55 to
//!   0.75 m, turned, and placed on a unit lattice (transform baked into the vertices, as
//!   decompositions write their hulls), so that each overlaps its lattice neighbours.

#[path = "../tests/common/mod.rs"]
mod common;

use std::fmt::Write as _;
use std::path::Path;
use urdf_inertia::mass::mat_vec;
use urdf_inertia::mesh::stl;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: make_large_inputs (meshes DIR FACES | torus-stl DIR FACES | pieces DIR N)";
    let (Some(what), Some(dir), Some(count)) = (args.first(), args.get(1), args.get(2)) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let Ok(count) = count.parse::<u32>() else {
        eprintln!("{usage}: {count} is not a count");
        std::process::exit(2);
    };
    let dir = Path::new(dir);
    let written = match what.as_str() {
        "meshes" => meshes(dir, count),
        "torus-stl" => {
            let (v, f) = faces_torus(count);
            std::fs::write(dir.join("torus.stl"), stl::write_binary(b"torus", &v, &f))
        }
        "pieces" => pieces(dir, count),
        _ => {
            eprintln!("{usage}");
            std::process::exit(2);
        }
    };
    if let Err(e) = written {
        eprintln!("cannot write into {}: {e}", dir.display());
        std::process::exit(2);
    }
}

/// A closed torus about z (radii 1 and 0.3) of `2 n m` outward triangles.
fn torus(n: u32, m: u32) -> common::Mesh {
    let tau = 2.0 * std::f64::consts::PI;
    let mut v = Vec::with_capacity((n * m) as usize);
    for i in 0..n {
        let u = tau * f64::from(i) / f64::from(n);
        for j in 0..m {
            let w = tau * f64::from(j) / f64::from(m);
            let r = 1.0 + 0.3 * w.cos();
            v.push([r * u.cos(), r * u.sin(), 0.3 * w.sin()]);
        }
    }
    let at = |i: u32, j: u32| (i % n) * m + j % m;
    let mut f = Vec::with_capacity(2 * (n * m) as usize);
    for i in 0..n {
        for j in 0..m {
            f.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            f.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (v, f)
}

/// The torus of about `faces` triangles: 2 n m of them with n = 2 m.
fn faces_torus(faces: u32) -> common::Mesh {
    let m = ((f64::from(faces) / 4.0).sqrt().round() as u32).max(3);
    torus(2 * m, m)
}

fn meshes(dir: &Path, faces: u32) -> std::io::Result<()> {
    let (v, f) = faces_torus(faces);
    std::fs::write(dir.join("torus.stl"), stl::write_binary(b"torus", &v, &f))?;
    std::fs::write(dir.join("torus.ascii.stl"), stl::write_ascii(&v, &f))?;
    let mut obj = String::new();
    for p in &v {
        let _ = writeln!(obj, "v {} {} {}", p[0], p[1], p[2]);
    }
    for t in &f {
        let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(dir.join("torus.obj"), obj)?;
    std::fs::write(dir.join("torus.dae"), dae(&v, &f))?;
    std::fs::write(dir.join("torus.glb"), glb(&v, &f))?;
    println!("{} triangles, {} vertices", f.len(), v.len());
    Ok(())
}

/// COLLADA with one `<triangles>` over shared positions, as the simplest exporters write it.
fn dae(v: &[[f64; 3]], f: &[[u32; 3]]) -> String {
    let mut pos = String::new();
    for p in v {
        let _ = write!(pos, "{} {} {} ", p[0], p[1], p[2]);
    }
    let mut idx = String::new();
    for t in f {
        let _ = write!(idx, "{} {} {} ", t[0], t[1], t[2]);
    }
    format!(
        "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n<library_geometries><geometry id=\"t\"><mesh>\n<source id=\"pos\"><float_array id=\"pa\" count=\"{}\">{pos}</float_array>\n<technique_common><accessor source=\"#pa\" count=\"{}\" stride=\"3\"/></technique_common></source>\n<vertices id=\"vx\"><input semantic=\"POSITION\" source=\"#pos\"/></vertices>\n<triangles count=\"{}\"><input semantic=\"VERTEX\" source=\"#vx\" offset=\"0\"/><p>{idx}</p></triangles>\n</mesh></geometry></library_geometries>\n</COLLADA>\n",
        3 * v.len(),
        v.len(),
        f.len()
    )
}

/// A binary glTF: f32 positions and u32 indices in one buffer, one mesh, one node, one scene.
fn glb(v: &[[f64; 3]], f: &[[u32; 3]]) -> Vec<u8> {
    let mut bin = Vec::with_capacity(12 * v.len() + 12 * f.len());
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in v {
        for k in 0..3 {
            let x = p[k] as f32;
            lo[k] = lo[k].min(x);
            hi[k] = hi[k].max(x);
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    let positions = bin.len();
    for i in f.iter().flatten() {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": positions},
            {"buffer": 0, "byteOffset": positions, "byteLength": bin.len() - positions}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": v.len(), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": 3 * f.len(), "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let mut json = json.to_string().into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn pieces(dir: &Path, n: u32) -> std::io::Result<()> {
    let n = n as usize;
    let side = (1..=n.max(1)).find(|s: &usize| s * s * s >= n).unwrap_or(1);
    let (v, f) = common::icosphere(3);
    let mut rng = common::Rng(25);
    let mut urdf = String::from(
        "<?xml version=\"1.0\"?>\n<robot name=\"pieces\">\n  <link name=\"decomposed\">\n",
    );
    for i in 0..n {
        let axes = [0, 1, 2].map(|_| rng.range(0.55, 0.75));
        let rpy = [0, 1, 2].map(|_| rng.range(-1.0, 1.0));
        let rotation = common::rotation(rpy);
        let at = [i % side, i / side % side, i / (side * side)].map(|c| c as f64);
        let vertices: Vec<[f64; 3]> = v
            .iter()
            .map(|p| {
                let q = mat_vec(&rotation, [0, 1, 2].map(|k| p[k] * axes[k]));
                [0, 1, 2].map(|k| q[k] + at[k])
            })
            .collect();
        let name = format!("pieces_{n}_{i}.stl");
        std::fs::write(dir.join(&name), stl::write_binary(b"piece", &vertices, &f))?;
        let _ = writeln!(
            urdf,
            "    <collision><geometry><mesh filename=\"{name}\"/></geometry></collision>"
        );
    }
    urdf.push_str("  </link>\n</robot>\n");
    std::fs::write(dir.join(format!("pieces_{n}.urdf")), urdf)?;
    Ok(())
}
