//! The same solid through every reader, and each broken fixture to its documented rung or error.

mod common;

use common::box_mesh;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use urdf_inertia::mesh::health::{HealthOptions, Rung};
use urdf_inertia::mesh::stl::{write_ascii, write_binary};
use urdf_inertia::mesh::{self, MeshErrorKind};

/// The reference solid: a 0.5 × 0.25 × 0.125 box (exact in binary), centred at (1, 2, 3).
const SIZE: [f64; 3] = [0.5, 0.25, 0.125];
const CENTRE: [f64; 3] = [1.0, 2.0, 3.0];

fn solid() -> common::Mesh {
    let (v, f) = box_mesh(SIZE);
    (
        v.iter()
            .map(|p| [p[0] + CENTRE[0], p[1] + CENTRE[1], p[2] + CENTRE[2]])
            .collect(),
        f,
    )
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write fixture");
    p
}

/// Checks volume, COM and central inertia against the box's exact values (all representable here).
fn assert_box(path: &Path, scale: [f64; 3], size: [f64; 3], centre: [f64; 3]) {
    let s =
        mesh::load_solid(path, scale, HealthOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let v = size[0] * size[1] * size[2];
    assert!(
        (s.unit.mass - v).abs() <= 1e-15 * v,
        "{}: volume {} want {v}",
        path.display(),
        s.unit.mass
    );
    for k in 0..3 {
        assert!(
            (s.unit.com[k] - centre[k]).abs() <= 1e-15 * centre[k].abs().max(1.0),
            "{}: com {:?}",
            path.display(),
            s.unit.com
        );
    }
    let want = [
        v * (size[1] * size[1] + size[2] * size[2]) / 12.0,
        v * (size[0] * size[0] + size[2] * size[2]) / 12.0,
        v * (size[0] * size[0] + size[1] * size[1]) / 12.0,
    ];
    for k in 0..3 {
        assert!(
            (s.unit.inertia[k][k] - want[k]).abs() <= 1e-14 * want[k],
            "{}: I[{k}] {} want {}",
            path.display(),
            s.unit.inertia[k][k],
            want[k]
        );
    }
    assert_eq!(s.rung, Rung::Exact, "{}", path.display());
}

fn obj_text(v: &[[f64; 3]]) -> String {
    // Two objects: the four side quads, then the two caps; quads stay quads; one face uses negative indices.
    let mut s = String::from("mtllib does_not_exist.mtl\no sides\n");
    for p in v {
        writeln!(s, "v {} {} {}", p[0], p[1], p[2]).ok();
    }
    s.push_str("vt 0 0\nvn 0 0 1\nusemtl nothing\n");
    // Box vertex i has bits (x, y, z); faces as in box_mesh, 1-based.
    s.push_str("f 1/1/1 5/1/1 7/1/1 3/1/1\nf 2 4 8 6\nf 1 2 6 5\no caps\ng cap_group\nf 3 7 8 4\nf -8 -6 -5 -7\nf 5 6 8 7\n");
    s
}

fn dae_text(v: &[[f64; 3]], f: &[[u32; 3]], unit: f64, up: &str, matrix: &str) -> String {
    let pos: Vec<String> = v
        .iter()
        .map(|p| format!("{} {} {}", p[0], p[1], p[2]))
        .collect();
    let idx: Vec<String> = f
        .iter()
        .map(|t| format!("{} 0 {} 0 {} 0", t[0], t[1], t[2]))
        .collect();
    format!(
        r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="u" meter="{unit}"/><up_axis>{up}</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="{}">{}</float_array>
      <technique_common><accessor source="#pa" count="{}" stride="3"/></technique_common></source>
    <source id="n"><float_array id="na" count="3">0 0 1</float_array>
      <technique_common><accessor source="#na" count="1" stride="3"/></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="{}"><input semantic="VERTEX" source="#v" offset="0"/><input semantic="NORMAL" source="#n" offset="1"/><p>{}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s">
    <node id="outer"><matrix>{matrix}</matrix><node id="inner"><translate>0 0 0</translate><instance_geometry url="#g"/></node></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"##,
        3 * v.len(),
        pos.join(" "),
        v.len(),
        f.len(),
        idx.join(" ")
    )
}

const IDENTITY: &str = "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1";

#[test]
#[allow(clippy::too_many_lines)] // one solid written and read back in every format, format after format
fn same_solid_through_every_reader() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    let (v, f) = solid();
    assert_box(
        &write(d, "bin.stl", &write_binary(b"binary", &v, &f)),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    assert_box(
        &write(
            d,
            "solidheader.STL",
            &write_binary(b"solid but binary", &v, &f),
        ),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    assert_box(
        &write(d, "ascii.stl", write_ascii(&v, &f).as_bytes()),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    // Header count wrong (0) but whole records: read, with a note.
    let mut bad_count = write_binary(b"x", &v, &f);
    bad_count[80..84].copy_from_slice(&0u32.to_le_bytes());
    let p = write(d, "count.stl", &bad_count);
    assert_box(&p, [1.0; 3], SIZE, CENTRE);
    let s = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap();
    assert!(
        s.notes
            .iter()
            .any(|w| w.contains("header says 0 triangles")),
        "{:?}",
        s.notes
    );
    assert_box(
        &write(d, "quads.obj", obj_text(&v).as_bytes()),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    assert_box(
        &write(
            d,
            "plain.dae",
            dae_text(&v, &f, 1.0, "Z_UP", IDENTITY).as_bytes(),
        ),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    // Y_UP is not applied (see the COLLADA module docs): same result.
    assert_box(
        &write(
            d,
            "yup.dae",
            dae_text(&v, &f, 1.0, "Y_UP", IDENTITY).as_bytes(),
        ),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    // Millimetre units: the same box written in mm.
    let mm: Vec<[f64; 3]> = v.iter().map(|p| p.map(|c| c * 1000.0)).collect();
    assert_box(
        &write(
            d,
            "mm.dae",
            dae_text(&mm, &f, 0.001, "Z_UP", IDENTITY).as_bytes(),
        ),
        [1.0; 3],
        SIZE,
        CENTRE,
    );
    // A node matrix: rotate 90° about z and move by (10, 0, 0): the box becomes 0.25 × 0.5 × 0.125 at (8, 1, 3).
    let m = "0 -1 0 10 1 0 0 0 0 0 1 0 0 0 0 1";
    assert_box(
        &write(d, "matrix.dae", dae_text(&v, &f, 1.0, "Z_UP", m).as_bytes()),
        [1.0; 3],
        [SIZE[1], SIZE[0], SIZE[2]],
        [8.0, 1.0, 3.0],
    );
    // Scale (mm file with URDF scale 0.001): same solid.
    assert_box(
        &write(d, "mm.stl", &write_binary(b"mm", &mm, &f)),
        [0.001; 3],
        SIZE,
        CENTRE,
    );
    // Mirrored scale: the solid is mirrored, its volume stays positive.
    let p = write(d, "mirror.stl", &write_binary(b"m", &v, &f));
    assert_box(&p, [1.0, -1.0, 1.0], SIZE, [1.0, -2.0, 3.0]);
}

#[test]
#[allow(clippy::too_many_lines)] // a table of cases
fn broken_meshes_take_the_documented_rung() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    let (v, f) = solid();
    // Open box: the top face (two triangles) missing → a flat hole, capped: exact numbers.
    let open: Vec<[u32; 3]> = f
        .iter()
        .copied()
        .filter(|t| !(t.iter().all(|&i| i & 4 != 0)))
        .collect();
    assert_eq!(open.len(), 10);
    let p = write(d, "open.stl", &write_binary(b"open", &v, &open));
    let s = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap();
    assert!(
        matches!(
            s.rung,
            Rung::Capped {
                holes: 1,
                boundary_edges: 4,
                ..
            }
        ),
        "{:?}",
        s.rung
    );
    assert!((s.unit.mass - 0.5 * 0.25 * 0.125).abs() < 1e-15);
    assert!(
        s.warnings[0].contains("open (4 boundary edges): closed its 1 hole(s) with flat caps"),
        "{:?}",
        s.warnings
    );
    assert!(mesh::load_solid(
        &p,
        [1.0; 3],
        HealthOptions {
            strict: true,
            ..HealthOptions::default()
        }
    )
    .is_err());
    // Top and one side missing: an L-shaped, far from flat hole → no solid to trust by default
    // (UI108), the convex hull with the numbers when asked for.
    let open2: Vec<[u32; 3]> = open
        .iter()
        .copied()
        .filter(|t| !(t.iter().all(|&i| i & 1 != 0)))
        .collect();
    assert_eq!(open2.len(), 8);
    let p = write(d, "open2.stl", &write_binary(b"open", &v, &open2));
    let e = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::NoSolid(_)), "{e}");
    assert!(
        e.to_string().contains("defines no solid to trust")
            && e.to_string().contains("--open-mesh hull"),
        "{e}"
    );
    let hull = HealthOptions {
        open_mesh: mesh::open::OpenMeshModel::Hull,
        ..HealthOptions::default()
    };
    let s = mesh::load_solid(&p, [1.0; 3], hull).unwrap();
    match &s.rung {
        Rung::ConvexHull {
            boundary_edges,
            hull_volume,
            ..
        } => {
            assert_eq!(*boundary_edges, 6);
            assert!((hull_volume - 0.5 * 0.25 * 0.125).abs() < 1e-15);
        }
        other => panic!("open box gave {other:?}"),
    }
    assert!(
        s.warnings[0].contains("open (6 boundary edges); used its convex hull"),
        "{:?}",
        s.warnings
    );
    // Two flipped faces → reoriented, exact numbers.
    let mut flipped = f.clone();
    flipped[0].swap(1, 2);
    flipped[7].swap(1, 2);
    let p = write(d, "flipped.stl", &write_binary(b"flip", &v, &flipped));
    let s = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap();
    assert_eq!(
        s.rung,
        Rung::Reoriented {
            faces_flipped: 2,
            components: 1
        }
    );
    assert!((s.unit.mass - 0.5 * 0.25 * 0.125).abs() < 1e-15);
    assert!(matches!(
        mesh::load_solid(
            &p,
            [1.0; 3],
            HealthOptions {
                strict: true,
                ..HealthOptions::default()
            }
        )
        .unwrap_err()
        .kind,
        MeshErrorKind::Strict(_)
    ));
    // Inside-out box → inverted, exact numbers.
    let inside: Vec<[u32; 3]> = f.iter().map(|t| [t[0], t[2], t[1]]).collect();
    let p = write(d, "inside.stl", &write_binary(b"in", &v, &inside));
    let s = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap();
    assert_eq!(s.rung, Rung::Inverted);
    assert!((s.unit.mass - 0.5 * 0.25 * 0.125).abs() < 1e-15);
    // Truncated binary STL → error naming the counts.
    let bytes = write_binary(b"t", &v, &f);
    let p = write(d, "trunc.stl", &bytes[..bytes.len() - 7]);
    let e = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::Truncated(_)), "{e}");
    assert!(e.to_string().contains("header says 12 triangles"), "{e}");
    // NaN vertices (ASCII STL: with the line) and OBJ.
    let ascii = write_ascii(&v, &f).replacen("vertex 0.75", "vertex nan", 1);
    let e = mesh::load_solid(
        &write(d, "nan.stl", ascii.as_bytes()),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.kind, MeshErrorKind::NotFinite);
    assert_eq!(e.line, Some(4), "{e}");
    let e = mesh::load_solid(
        &write(d, "nan.obj", b"v 0 0 0\nv 1 0 0\nv 0 NaN 0\nf 1 2 3\n"),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert_eq!((e.kind, e.line), (MeshErrorKind::NotFinite, Some(3)));
    // Empty OBJ.
    let e = mesh::load_solid(
        &write(d, "empty.obj", b"# nothing\n"),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.kind, MeshErrorKind::Empty);
    // Out-of-range index.
    let e = mesh::load_solid(
        &write(d, "index.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.line, Some(4));
    assert!(matches!(
        e.kind,
        MeshErrorKind::IndexOutOfRange {
            index: 9,
            vertices: 3
        }
    ));
    // .ply and .3mf: unsupported format, named.
    for name in ["part.ply", "part.3mf"] {
        let e = mesh::load_solid(&write(d, name, b"data"), [1.0; 3], HealthOptions::default())
            .unwrap_err();
        assert!(matches!(e.kind, MeshErrorKind::UnknownFormat(_)), "{e}");
    }
    // A flat mesh (a single square, both sides) has no volume.
    let flat = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let ft = [[0u32, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]];
    let e = mesh::load_solid(
        &write(d, "flat.stl", &write_binary(b"f", &flat, &ft)),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e.kind, MeshErrorKind::ZeroVolume { .. }), "{e}");
    // A COLLADA index past its source's vertices: an error naming the line, never another vertex.
    let mut bad_f = f.clone();
    bad_f[3][1] = 8;
    let e = mesh::load_solid(
        &write(
            d,
            "index.dae",
            dae_text(&v, &bad_f, 1.0, "Z_UP", IDENTITY).as_bytes(),
        ),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(
            e.kind,
            MeshErrorKind::IndexOutOfRange {
                index: 8,
                vertices: 8
            }
        ),
        "{e}"
    );
    assert!(e.line.is_some());
    // Malformed COLLADA: line named.
    let e = mesh::load_solid(
        &write(
            d,
            "bad.dae",
            b"<?xml version=\"1.0\"?>\n<COLLADA>\n<asset>\n</COLLADA>\n",
        ),
        [1.0; 3],
        HealthOptions::default(),
    )
    .unwrap_err();
    assert!(e.line.is_some(), "{e}");
}

#[test]
fn small_hole_is_capped_exactly() {
    // A closed 1 × 1 × 1 box of 16 × 16 quads per side minus one triangle: one flat hole, capped exactly.
    let n = 16;
    let mut v = Vec::new();
    let mut idx = std::collections::HashMap::new();
    let mut id = |p: [i32; 3], v: &mut Vec<[f64; 3]>| -> u32 {
        *idx.entry(p).or_insert_with(|| {
            v.push(p.map(|c| f64::from(c) / f64::from(n)));
            (v.len() - 1) as u32
        })
    };
    let mut f: Vec<[u32; 3]> = Vec::new();
    for axis in 0..3 {
        for side in [0, n] {
            for a in 0..n {
                for b in 0..n {
                    let pt = |da: i32, db: i32| {
                        let mut p = [0; 3];
                        p[axis] = side;
                        p[(axis + 1) % 3] = a + da;
                        p[(axis + 2) % 3] = b + db;
                        p
                    };
                    let q = [pt(0, 0), pt(1, 0), pt(1, 1), pt(0, 1)];
                    let q: Vec<u32> = q.iter().map(|p| id(*p, &mut v)).collect();
                    if side == n {
                        f.push([q[0], q[1], q[2]]);
                        f.push([q[0], q[2], q[3]]);
                    } else {
                        f.push([q[0], q[2], q[1]]);
                        f.push([q[0], q[3], q[2]]);
                    }
                }
            }
        }
    }
    f.remove(5);
    let tmp = tempfile::tempdir().expect("tempdir");
    let p = write(tmp.path(), "crack.stl", &write_binary(b"c", &v, &f));
    let s = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).unwrap();
    assert!(
        matches!(
            s.rung,
            Rung::Capped {
                holes: 1,
                boundary_edges: 3,
                ..
            }
        ),
        "{:?}",
        s.rung
    );
    assert!((s.unit.mass - 1.0).abs() < 1e-15, "{}", s.unit.mass);
}

/// Regression (validation on alex UJointLink.obj): holes whose vector areas cancel, as at the two ends of
/// an open tube, leave the signed volume origin-independent but a third too small; they must be capped.
/// Issue #22: the two ends of a tube four radii long see each other, so the winding number between
/// their caps is fractional and the capped cylinder is not the solid the surface defines: by default
/// no solid (the caps' bound is unbounded), and the caps only when asked, with that bound.
#[test]
fn open_tube_is_capped_only_when_asked() {
    let (v, f) = common::cylinder_mesh(0.5, 2.0, 64);
    // cylinder_mesh's faces come in fours per segment: bottom cap, top cap, two side triangles.
    let sides: Vec<[u32; 3]> = f.chunks(4).flat_map(|c| [c[2], c[3]]).collect();
    let tmp = tempfile::tempdir().expect("tempdir");
    let p = write(tmp.path(), "tube.stl", &write_binary(b"tube", &v, &sides));
    let e = mesh::load_solid(&p, [1.0; 3], HealthOptions::default()).expect_err("no solid");
    assert!(
        matches!(&e.kind, mesh::MeshErrorKind::NoSolid(n) if n.holes_see_each_other),
        "{e:?}"
    );
    let caps = HealthOptions {
        open_mesh: mesh::open::OpenMeshModel::Caps,
        ..HealthOptions::default()
    };
    let s = mesh::load_solid(&p, [1.0; 3], caps).unwrap();
    assert!(s.error_estimate.is_infinite(), "{}", s.error_estimate);
    assert!(
        matches!(s.rung, Rung::Capped { holes: 2, .. }),
        "{:?}",
        s.rung
    );
    let closed = urdf_inertia::mass::MassProperties::from_trimesh(&v, &f, 1.0);
    assert!(
        (s.unit.mass - closed.mass).abs() < 1e-7 * closed.mass,
        "{} vs {}",
        s.unit.mass,
        closed.mass
    );
}

/// The overlap estimate's point-in-mesh test (ray parity over a bucket grid) against the exact winding
/// number, on a grid of points through a sphere, including points level with its vertices.
#[test]
fn mesh_locator_agrees_with_the_winding_number() {
    use urdf_inertia::overlap::{winding_number, MeshLocator};
    let (v, f) = common::icosphere(4);
    let raw = mesh::RawMesh {
        vertices: v,
        faces: urdf_inertia::mass::Polygons::from_triangles(&f),
        ..Default::default()
    };
    let solid = mesh::health::make_solid(&raw, Path::new("sphere"), HealthOptions::default())
        .expect("solid");
    let locator = MeshLocator::new(&solid);
    let mut disagree = 0;
    for i in 0..21 {
        for j in 0..21 {
            for k in 0..21 {
                let q = [
                    -1.0 + 0.1 * f64::from(i),
                    -1.0 + 0.1 * f64::from(j),
                    -1.0 + 0.1 * f64::from(k),
                ];
                let w = winding_number(&solid, q);
                if w.abs() > 1e-6 && (w - 1.0).abs() > 1e-6 {
                    continue; // on the surface
                }
                if locator.contains(q) != (w > 0.5) {
                    disagree += 1;
                }
            }
        }
    }
    assert_eq!(disagree, 0);
}

/// Issue 14: binary STL is read in pieces and welded chunk by chunk in parallel. The result must be
/// the plain sequential weld (every corner in file order, numbered at first appearance, −0.0 folded),
/// for the file read whole or streamed and for any number of threads.
#[test]
fn chunked_parallel_weld_is_the_sequential_weld() {
    // 81,920 faces: five chunks of 16 Ki faces, the last partial; with −0.0 corners and a repeated
    // triangle-soup ordering that shuffles where vertices first appear.
    let (v, f) = common::icosphere(6);
    let v: Vec<[f64; 3]> = v
        .iter()
        .map(|p| {
            let q = p.map(|x| if x.abs() < 1e-9 { -0.0 } else { x });
            [q[0] + 0.25, q[1], q[2]]
        })
        .collect();
    let mut f = f;
    f.reverse();
    let bytes = write_binary(b"chunks", &v, &f);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = write(dir.path(), "chunks.stl", &bytes);
    // The reference: corners in file order, welded by their f32 bits with −0.0 as 0.0.
    let mut first: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    for r in bytes[84..].chunks_exact(50) {
        for c in 0..3 {
            let p: [f32; 3] = std::array::from_fn(|k| {
                let o = 12 + 12 * c + 4 * k;
                f32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]]) + 0.0
            });
            let id = *first.entry(p.map(f32::to_bits)).or_insert_with(|| {
                vertices.push(p.map(f64::from));
                vertices.len() as u32 - 1
            });
            indices.push(id);
        }
    }
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let (whole, streamed) = pool.install(|| {
            (
                mesh::stl::parse(&bytes, &path).expect("parse"),
                mesh::read(&path, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE).expect("read"),
            )
        });
        for m in [whole, streamed] {
            assert!(m.welded);
            assert_eq!(m.faces.indices, indices, "{threads} threads");
            assert_eq!(
                m.vertices
                    .iter()
                    .map(|p| p.map(f64::to_bits))
                    .collect::<Vec<_>>(),
                vertices
                    .iter()
                    .map(|p| p.map(f64::to_bits))
                    .collect::<Vec<_>>()
            );
        }
    }
}

/// ASCII and binary STL of one mesh with f32 corners are one solid, to the bit: the ASCII text is
/// each corner's shortest f64 decimal (what `write_ascii` writes), which parses back to the f32's
/// value, and the binary reader widens the same f32. The torus spans more than one streamed piece
/// and many parse chunks, so the ASCII reader's chunking, its cache of vertex lines and its
/// cross-chunk weld are all on the path; its vertices are shared by six faces each.
#[test]
fn ascii_and_binary_stl_of_one_f32_mesh_give_bit_identical_mass_properties() {
    let (v, f) = common::wild::torus(1.0, 0.4, 160, 80);
    #[allow(clippy::cast_possible_truncation)] // The point: corners that are f32 values.
    let v: Vec<[f64; 3]> = v
        .iter()
        .map(|p| p.map(|c| f64::from((0.1 * c + 0.2) as f32)))
        .collect();
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    let ascii = write_ascii(&v, &f);
    assert!(ascii.len() > 4 << 20, "{} bytes", ascii.len());
    let load = |p: &Path| {
        mesh::load_solid(p, [1.0; 3], HealthOptions::default()).unwrap_or_else(|e| panic!("{e}"))
    };
    let a = load(&write(d, "torus_ascii.stl", ascii.as_bytes()));
    let b = load(&write(
        d,
        "torus_binary.stl",
        &write_binary(b"torus", &v, &f),
    ));
    let bits = |s: &urdf_inertia::mesh::health::Solid| {
        let u = s.unit;
        let mut out = vec![u.mass.to_bits()];
        out.extend(u.com.map(f64::to_bits));
        out.extend(u.inertia.iter().flatten().map(|x| x.to_bits()));
        out
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.faces_read, f.len());
    assert_eq!(a.vertices, b.vertices);
}
