//! glTF 2.0 (.glb and .gltf): known solids written by the test's own generator, checked against analytic
//! mass, COM and inertia; refused extensions and broken files give named errors, never panics.

// The test helpers are the library tests' own (exact integrals, mesh generators).
#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;
#[path = "../crates/urdf-inertia/tests/common/gltf_gen.rs"]
mod gltf_gen;

use common::Rng;
use gltf_gen::*;
use serde_json::json;
use std::path::{Path, PathBuf};
use urdf_inertia::mesh::health::{HealthOptions, Rung, Solid};
use urdf_inertia::mesh::{self, MeshErrorKind};

/// The reference box: 0.5 × 0.25 × 0.125 centred at (1, 2, 3), every coordinate exact in f32.
const SIZE: [f32; 3] = [0.5, 0.25, 0.125];
const CENTRE: [f32; 3] = [1.0, 2.0, 3.0];

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write fixture");
    p
}

fn load(path: &Path) -> Solid {
    mesh::load_solid(path, [1.0; 3], HealthOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Central inertia of a solid box of unit density, `size` along its own axes: m(b²+c²)/12, ...
fn box_inertia(size: [f64; 3]) -> [[f64; 3]; 3] {
    let m = size[0] * size[1] * size[2];
    let d = |i: usize, j: usize| m * (size[i] * size[i] + size[j] * size[j]) / 12.0;
    [
        [d(1, 2), 0.0, 0.0],
        [0.0, d(0, 2), 0.0],
        [0.0, 0.0, d(0, 1)],
    ]
}

/// Checks volume, COM and central inertia against expected values, relative to the tensor's size.
fn assert_solid(
    s: &Solid,
    volume: f64,
    com: [f64; 3],
    inertia: [[f64; 3]; 3],
    tol: f64,
    what: &str,
) {
    assert!(
        rel(s.unit.mass, volume) <= tol,
        "{what}: volume {} want {volume}",
        s.unit.mass
    );
    let size = volume.cbrt();
    for k in 0..3 {
        assert!(
            (s.unit.com[k] - com[k]).abs() <= tol * size.max(com[k].abs()),
            "{what}: com {:?} want {com:?}",
            s.unit.com
        );
    }
    let scale = inertia.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
    for i in 0..3 {
        for j in 0..3 {
            assert!(
                (s.unit.inertia[i][j] - inertia[i][j]).abs() <= tol * scale,
                "{what}: I[{i}][{j}] {} want {}",
                s.unit.inertia[i][j],
                inertia[i][j]
            );
        }
    }
    assert_eq!(s.rung, Rung::Exact, "{what}");
}

fn f64s(a: [f32; 3]) -> [f64; 3] {
    a.map(f64::from)
}

fn assert_reference_box(path: &Path) {
    let size = f64s(SIZE);
    assert_solid(
        &load(path),
        size[0] * size[1] * size[2],
        f64s(CENTRE),
        box_inertia(size),
        1e-14,
        &path.display().to_string(),
    );
}

#[test]
fn box_through_glb_data_uri_and_external_bin() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    let b = box_builder(SIZE, CENTRE, json!({}));
    assert_reference_box(&write(d, "box.glb", &b.glb()));
    assert_reference_box(&write(d, "BOX.GLB", &b.glb()));
    assert_reference_box(&write(d, "box_data.gltf", b.gltf_data_uri().as_bytes()));
    // External buffer, percent-encoded URI, relative to the .gltf file (not to the working directory).
    std::fs::create_dir(d.join("sub")).unwrap();
    std::fs::write(d.join("sub/box data.bin"), &b.bin).unwrap();
    assert_reference_box(&write(
        d,
        "sub/box_external.gltf",
        b.gltf_external("box%20data.bin").as_bytes(),
    ));
    // A missing external buffer names the file.
    let e = mesh::read(
        &write(d, "missing.gltf", b.gltf_external("nowhere.bin").as_bytes()),
        urdf_inertia::input::DEFAULT_MAX_FILE_SIZE,
    )
    .unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::Io(_)), "{e}");
    assert!(e.to_string().contains("nowhere.bin"), "{e}");
}

#[test]
fn strips_fans_and_unindexed_primitives() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    assert_reference_box(&write(
        d,
        "strip_fan.glb",
        &box_strip_fan(SIZE, CENTRE, false).glb(),
    ));
    // The same on three nodes, and a box split into two triangle primitives of one mesh.
    assert_reference_box(&write(
        d,
        "strip_fan_nodes.glb",
        &box_strip_fan(SIZE, CENTRE, true).glb(),
    ));
    assert_reference_box(&write(
        d,
        "two_primitives.glb",
        &box_two_primitives(SIZE, CENTRE).glb(),
    ));
    assert_reference_box(&write(
        d,
        "unindexed.glb",
        &box_unindexed(SIZE, CENTRE).glb(),
    ));
    // Points and lines carry no surface: skipped with a note, the box still counts.
    let mut b = box_builder(SIZE, CENTRE, json!({}));
    let (v, _) = box_corners(SIZE, CENTRE);
    let pos = b.positions(&v);
    let lines = b.indices(&[0, 1, 1, 2], U16);
    b.meshes[0]["primitives"].as_array_mut().unwrap().extend([
        json!({"attributes": {"POSITION": pos}, "indices": lines, "mode": LINES}),
        json!({"attributes": {"POSITION": pos}, "mode": POINTS}),
    ]);
    let p = write(d, "lines.glb", &b.glb());
    assert_reference_box(&p);
    let raw = mesh::read(&p, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE).unwrap();
    assert_eq!(
        raw.notes
            .iter()
            .filter(|n| n.contains("no surface"))
            .count(),
        2,
        "{:?}",
        raw.notes
    );
}

/// Rotation about a unit axis by `angle` (Rodrigues), written independently of the reader's quaternions.
fn axis_angle(axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let [x, y, z] = axis.map(|a| a / n);
    let k = [[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]];
    let (s, c) = angle.sin_cos();
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let kk: f64 = (0..3).map(|m| k[i][m] * k[m][j]).sum();
            r[i][j] = f64::from(u8::from(i == j)) + s * k[i][j] + (1.0 - c) * kk;
        }
    }
    r
}

fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(a: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn transpose(a: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}

#[test]
fn node_tree_with_trs_parent_and_matrix_child() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // Parent: translation, rotation of 0.7 rad about (1, 2, 2)/3, uniform scale 2.
    let (theta, axis) = (0.7f64, [1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0]);
    let half = theta / 2.0;
    let q = [
        axis[0] * half.sin(),
        axis[1] * half.sin(),
        axis[2] * half.sin(),
        half.cos(),
    ];
    let t_parent = [0.5, -1.25, 2.0];
    // Child: a quarter turn about X (exact), then a translation; column-major matrix.
    let t_child = [0.25, 0.0, -0.5];
    let matrix = [
        1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0, t_child[0], t_child[1],
        t_child[2], 1.0,
    ];
    let mut b = box_builder(SIZE, CENTRE, json!({}));
    // box_builder made node 0 (the mesh) a root; re-parent it under a new TRS root.
    b.nodes[0] = json!({"mesh": 0, "matrix": matrix});
    let parent = b.node(json!({"children": [0], "translation": t_parent, "rotation": q.map(|x| x as f32), "scale": [2.0, 2.0, 2.0]}));
    b.scenes[0] = json!({"nodes": [parent]});
    let p = write(tmp.path(), "tree.glb", &b.glb());

    let r_child = axis_angle([1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2);
    let r_parent = axis_angle(axis, theta);
    let r = mul(&r_parent, &r_child);
    let c_child = apply(&r_child, f64s(CENTRE));
    let c_child = [0, 1, 2].map(|k| c_child[k] + t_child[k]);
    let c = apply(&r_parent, c_child.map(|x| 2.0 * x));
    let com = [0, 1, 2].map(|k| c[k] + t_parent[k]);
    let size = f64s(SIZE).map(|x| 2.0 * x);
    let inertia = mul(&mul(&r, &box_inertia(size)), &transpose(&r));
    // The rotation is stored as an f32 quaternion: 1e-6 relative.
    assert_solid(
        &load(&p),
        size[0] * size[1] * size[2],
        com,
        inertia,
        1e-6,
        "tree.glb",
    );
}

#[test]
fn mirrored_nodes_keep_the_solid_outward() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let size = f64s(SIZE);
    let v = size[0] * size[1] * size[2];
    // Scale -1 on X (TRS) and a matrix flipping Z: volume stays positive, the COM is mirrored.
    let trs = write(
        tmp.path(),
        "mirror_trs.glb",
        &box_builder(SIZE, CENTRE, json!({"scale": [-1.0, 1.0, 1.0]})).glb(),
    );
    assert_solid(
        &load(&trs),
        v,
        [-1.0, 2.0, 3.0],
        box_inertia(size),
        1e-14,
        "mirror_trs",
    );
    let m = [
        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.5, 1.0,
    ];
    let mat = write(
        tmp.path(),
        "mirror_matrix.gltf",
        box_builder(SIZE, CENTRE, json!({"matrix": m}))
            .gltf_data_uri()
            .as_bytes(),
    );
    assert_solid(
        &load(&mat),
        v,
        [1.0, 2.0, -2.5],
        box_inertia(size),
        1e-14,
        "mirror_matrix",
    );
}

/// glTF says +Y is up; like pinocchio (coal's assimp loader) and `RViz`, positions are read as they are:
/// a box standing along +Y keeps its long axis on Y (Drake would turn it onto Z).
#[test]
fn gltf_y_up_is_not_rotated_into_z() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let size = [0.25f32, 2.0, 0.5];
    let centre = [0.0f32, 1.0, 0.0];
    let p = write(
        tmp.path(),
        "standing.glb",
        &box_builder(size, centre, json!({})).glb(),
    );
    let s = f64s(size);
    assert_solid(
        &load(&p),
        s[0] * s[1] * s[2],
        [0.0, 1.0, 0.0],
        box_inertia(s),
        1e-14,
        "standing.glb",
    );
}

#[test]
fn scene_selection() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // Two scenes, `scene` = 1: only the second scene's box counts.
    let mut b = box_builder(SIZE, CENTRE, json!({}));
    let other = b.node(json!({"mesh": 0, "translation": [10.0, 0.0, 0.0]}));
    b.add_scene(&[other]);
    b.scene = Some(1);
    let size = f64s(SIZE);
    let v = size[0] * size[1] * size[2];
    let p = write(tmp.path(), "scenes.glb", &b.glb());
    assert_solid(
        &load(&p),
        v,
        [11.0, 2.0, 3.0],
        box_inertia(size),
        1e-14,
        "scene 1",
    );
    // No default scene: the first.
    b.scene = None;
    assert_reference_box(&write(tmp.path(), "first.glb", &b.glb()));
    // No scene at all: every mesh once, untransformed.
    b.nodes.clear();
    b.scenes.clear();
    let p = write(tmp.path(), "noscene.glb", &b.glb());
    assert_reference_box(&p);
    assert!(mesh::read(&p, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE)
        .unwrap()
        .notes
        .iter()
        .any(|n| n.contains("no scene")));
}

#[test]
fn compression_and_sparse_are_refused_by_name() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    for ext in [
        "KHR_draco_mesh_compression",
        "EXT_meshopt_compression",
        "KHR_mesh_quantization",
    ] {
        let mut b = box_builder(SIZE, CENTRE, json!({}));
        b.extensions_used = vec![ext.into()];
        b.extensions_required = vec![ext.into()];
        let e = mesh::read(
            &write(d, &format!("{ext}.glb"), &b.glb()),
            urdf_inertia::input::DEFAULT_MAX_FILE_SIZE,
        )
        .unwrap_err();
        assert!(matches!(e.kind, MeshErrorKind::Unsupported(_)), "{e}");
        assert!(e.to_string().contains(ext), "{e}");
        assert!(
            e.to_string().contains(&format!("{ext}.glb")),
            "the path: {e}"
        );
    }
    // Draco only "used": a POSITION accessor without a buffer view is the compressed one.
    let mut b = box_builder(SIZE, CENTRE, json!({}));
    b.extensions_used = vec!["KHR_draco_mesh_compression".into()];
    b.accessors[0].as_object_mut().unwrap().remove("bufferView");
    let e = mesh::read(
        &write(d, "draco_used.glb", &b.glb()),
        urdf_inertia::input::DEFAULT_MAX_FILE_SIZE,
    )
    .unwrap_err();
    assert!(e.to_string().contains("KHR_draco_mesh_compression"), "{e}");
    // A sparse POSITION accessor.
    let mut b = box_builder(SIZE, CENTRE, json!({}));
    b.accessors[0]["sparse"] = json!({"count": 1, "indices": {"bufferView": 1, "componentType": U16}, "values": {"bufferView": 0}});
    let e = mesh::read(
        &write(d, "sparse.glb", &b.glb()),
        urdf_inertia::input::DEFAULT_MAX_FILE_SIZE,
    )
    .unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::Unsupported(_)), "{e}");
    assert!(e.to_string().contains("sparse"), "{e}");
    // A material-only required extension does not change geometry: accepted.
    let mut b = box_builder(SIZE, CENTRE, json!({}));
    b.extensions_used = vec!["KHR_materials_unlit".into()];
    b.extensions_required = vec!["KHR_materials_unlit".into()];
    assert_reference_box(&write(d, "unlit.glb", &b.glb()));
}

#[test]
fn broken_files_are_errors_never_panics() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let b = box_builder(SIZE, CENTRE, json!({}));
    let glb = b.glb();
    let p = tmp.path().join("t.glb");
    // Every truncation of a GLB is an error; past the headers, a truncation named as such.
    for n in 0..glb.len() {
        let e = mesh::gltf::parse(&glb[..n], &p, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE)
            .unwrap_err();
        if n >= 20 {
            assert!(matches!(e.kind, MeshErrorKind::Truncated(_)), "{n}: {e}");
        }
    }
    let e = mesh::read(
        &write(tmp.path(), "half.glb", &glb[..glb.len() / 2]),
        urdf_inertia::input::DEFAULT_MAX_FILE_SIZE,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("half.glb") && e.to_string().contains("truncated"),
        "{e}"
    );
    // An accessor reaching past its buffer, an index past the vertices.
    let mut bad = b.clone();
    bad.accessors[0]["count"] = json!(1000);
    let e =
        mesh::gltf::parse(&bad.glb(), &p, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::Truncated(_)), "{e}");
    let mut bad = b.clone();
    let idx = bad.indices(&[0, 1, 99], U32);
    bad.meshes[0]["primitives"][0]["indices"] = json!(idx);
    let e =
        mesh::gltf::parse(&bad.glb(), &p, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE).unwrap_err();
    assert!(
        matches!(
            e.kind,
            MeshErrorKind::IndexOutOfRange {
                index: 99,
                vertices: 8
            }
        ),
        "{e}"
    );
    // Byte mutations of GLB and of JSON glTF: any result but a panic.
    let text = b.gltf_data_uri().into_bytes();
    let mut rng = Rng(7);
    for valid in [&glb, &text] {
        for _ in 0..3000 {
            let mut m = valid.clone();
            for _ in 0..=(rng.next_u64() % 6) {
                let i = (rng.next_u64() % m.len() as u64) as usize;
                match rng.next_u64() % 3 {
                    0 => m[i] = rng.next_u64() as u8,
                    1 => {
                        m.remove(i);
                    }
                    _ => m.insert(i, b"0123456789-.e,:[]{}\""[(rng.next_u64() % 20) as usize]),
                }
            }
            let _ = mesh::gltf::parse(&m, &p, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE);
        }
    }
}

/// The binary fills a link whose collision is a .glb, with the mesh `scale` applied (×2 on every axis).
#[test]
fn fill_a_urdf_with_a_glb_collision() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    write(d, "part.glb", &box_builder(SIZE, CENTRE, json!({})).glb());
    let urdf = write(
        d,
        "r.urdf",
        br#"<robot name="r"><link name="a"><collision><geometry><mesh filename="part.glb" scale="2 2 2"/></geometry></collision></link></robot>"#,
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(["fill", urdf.to_str().unwrap(), "--density", "1000"])
        .output()
        .expect("run urdf-inertia");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // 8 × 0.015625 m³ × 1000 kg/m³ = 125 kg, COM at 2 × (1, 2, 3).
    assert!(stdout.contains(r#"<mass value="125"/>"#), "{stdout}");
    assert!(stdout.contains(r#"xyz="2 4 6""#), "{stdout}");
}
