//! The first hour on a real robot repository, as the real binary meets it: named causes, no silent
//! no-ops, oversized parts, plain text. Every fixture is generated here.

use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(args)
        .output()
        .expect("run urdf-inertia")
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn write(dir: &Path, name: &str, content: &str) -> String {
    let p = dir.join(name);
    if let Some(parent) = p.parent() {
        std::fs::create_dir_all(parent).expect("mkdir");
    }
    std::fs::write(&p, content).expect("write");
    p.to_str().expect("utf-8 path").to_string()
}

/// A 1 × 2 × 3 box of 1000 kg/m³ turned by rpy (0.3, −0.4, 0.5), with `inertial` as its `<inertial>`
/// body.
fn turned_box(inertial: &str) -> String {
    format!(
        "<robot name=\"r\"><link name=\"a\">{inertial}<collision><origin rpy=\"0.3 -0.4 0.5\"/>\
         <geometry><box size=\"1 2 3\"/></geometry></collision></link></robot>"
    )
}

/// The turned box's inertia, from the analytic box tensor diag(m(b²+c²)/12, …) rotated by R·I·Rᵀ
/// (R = Rz·Ry·Rx), computed here rather than by the tool.
fn turned_box_tensor() -> [[f64; 3]; 3] {
    let m = 6000.0;
    let d = [
        m * (4.0 + 9.0) / 12.0,
        m * (1.0 + 9.0) / 12.0,
        m * (1.0 + 4.0) / 12.0,
    ];
    let (r, p, y) = (0.3f64, -0.4f64, 0.5f64);
    let rx = [
        [1.0, 0.0, 0.0],
        [0.0, r.cos(), -r.sin()],
        [0.0, r.sin(), r.cos()],
    ];
    let ry = [
        [p.cos(), 0.0, p.sin()],
        [0.0, 1.0, 0.0],
        [-p.sin(), 0.0, p.cos()],
    ];
    let rz = [
        [y.cos(), -y.sin(), 0.0],
        [y.sin(), y.cos(), 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mul = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
        let mut c = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
            }
        }
        c
    };
    let rot = mul(mul(rz, ry), rx);
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = (0..3).map(|k| rot[i][k] * d[k] * rot[j][k]).sum();
        }
    }
    out
}

fn inertial_with(t: [[f64; 3]; 3]) -> String {
    format!(
        "<inertial><origin xyz=\"0 0 0\"/><mass value=\"6000\"/><inertia ixx=\"{}\" ixy=\"{}\" \
         ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/></inertial>",
        t[0][0], t[0][1], t[0][2], t[1][1], t[1][2], t[2][2]
    )
}

/// Products of inertia written with the CAD sign (+∫xy dm) are named as such, before any mirror; a
/// truly mirrored tensor still gets the mirror cause.
#[test]
fn diff_names_the_cad_sign_of_products_before_mirrors() {
    let tmp = tempfile::tempdir().unwrap();
    let t = turned_box_tensor();
    let mut cad = t;
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        cad[i][j] = -cad[i][j];
        cad[j][i] = -cad[j][i];
    }
    let path = write(tmp.path(), "cad.urdf", &turned_box(&inertial_with(cad)));
    let out = run(&["diff", &path, "--density", "1000"]);
    let s = text(&out);
    assert_eq!(out.status.code(), Some(1), "{s}");
    assert!(
        s.contains("products of inertia have the opposite sign (CAD convention: +∫xy dm)"),
        "{s}"
    );
    assert!(!s.contains("mirrored"), "{s}");

    // Mirrored in y: xy and yz change sign, xz keeps it.
    let mut mirrored = t;
    for (i, j) in [(0, 1), (1, 2)] {
        mirrored[i][j] = -mirrored[i][j];
        mirrored[j][i] = -mirrored[j][i];
    }
    let path = write(
        tmp.path(),
        "mirror.urdf",
        &turned_box(&inertial_with(mirrored)),
    );
    let s = text(&run(&["diff", &path, "--density", "1000"]));
    assert!(s.contains("products of inertia look mirrored in y"), "{s}");
    assert!(!s.contains("opposite sign"), "{s}");

    // The analytic tensor itself agrees: no cause at all, exit 0.
    let path = write(tmp.path(), "right.urdf", &turned_box(&inertial_with(t)));
    let out = run(&["diff", &path, "--density", "1000"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(!text(&out).contains("opposite sign"));
}

/// An ASCII STL of an axis-aligned cube of side `a` centred at the origin, wound outward.
fn cube_stl(a: f64) -> String {
    let h = a / 2.0;
    let v = |i: usize| {
        [
            if i & 1 == 0 { -h } else { h },
            if i & 2 == 0 { -h } else { h },
            if i & 4 == 0 { -h } else { h },
        ]
    };
    // Each face as two triangles, counter-clockwise seen from outside.
    let quads = [
        [0, 2, 3, 1], // z−
        [4, 5, 7, 6], // z+
        [0, 1, 5, 4], // y−
        [2, 6, 7, 3], // y+
        [0, 4, 6, 2], // x−
        [1, 3, 7, 5], // x+
    ];
    let mut s = String::from("solid cube\n");
    for q in quads {
        for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            s.push_str("facet normal 0 0 0\nouter loop\n");
            for i in t {
                let p = v(i);
                let _ = writeln!(s, "vertex {} {} {}", p[0], p[1], p[2]);
            }
            s.push_str("endloop\nendfacet\n");
        }
    }
    s.push_str("endsolid cube\n");
    s
}

/// A robot of two links: `base_link` (a 0.1 m box) and `battery` (meshes/big_battery.stl, a 0.1 m
/// cube), in `dir`; returns the URDF's path.
fn battery_robot(dir: &Path) -> String {
    write(dir, "meshes/big_battery.stl", &cube_stl(0.1));
    write(
        dir,
        "robot.urdf",
        "<robot name=\"r\">\n  <link name=\"base_link\">\n    <collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision>\n  </link>\n  <link name=\"battery\">\n    <collision><geometry><mesh filename=\"meshes/big_battery.stl\"/></geometry></collision>\n  </link>\n</robot>\n",
    )
}

/// The `<mass value>` of `link` in URDF text.
fn mass_of(urdf: &str, link: &str) -> f64 {
    let at = urdf.find(&format!("<link name=\"{link}\"")).expect("link");
    let body = &urdf[at..];
    let body = &body[..body.find("</link>").expect("end")];
    let m = body.find("<mass value=\"").expect("mass") + 13;
    body[m..m + body[m..].find('"').expect("quote")]
        .parse()
        .expect("number")
}

/// A density rule that matches nothing is named with its line and a near name; the battery then
/// gets the default density (1000 kg/m³ × 0.001 m³ = 1 kg), as the warning says.
#[test]
fn density_rules_that_match_nothing_are_warnings() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = battery_robot(tmp.path());
    let map = write(
        tmp.path(),
        "d.toml",
        "default = 1000\n[links]\nbase_lnk = 2000\n[meshes]\n\"*batery*\" = 2500\n",
    );
    let out = run(&["fill", &urdf, "--density-map", &map]);
    let s = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{s}");
    assert!(
        s.contains(&format!("{map}:3: [links] rule \"base_lnk\" matches no link: it is ignored; did you mean \"base_link\"?")),
        "{s}"
    );
    assert!(
        s.contains(&format!("{map}:5: [meshes] rule \"*batery*\" matches no collision mesh: it is ignored; did you mean \"*battery*\" (it matches `big_battery.stl`)?")),
        "{s}"
    );
    let filled = String::from_utf8_lossy(&out.stdout);
    assert!((mass_of(&filled, "battery") - 1.0).abs() < 1e-12);
    assert!((mass_of(&filled, "base_link") - 1.0).abs() < 1e-12);
    // Corrected, the rules are used and nothing is said.
    let map = write(
        tmp.path(),
        "d.toml",
        "default = 1000\n[links]\nbase_link = 2000\n[meshes]\n\"*battery*\" = 2500\n",
    );
    let out = run(&["fill", &urdf, "--density-map", &map]);
    let s = String::from_utf8_lossy(&out.stderr);
    assert!(!s.contains("matches no"), "{s}");
    let filled = String::from_utf8_lossy(&out.stdout);
    assert!((mass_of(&filled, "battery") - 2.5).abs() < 1e-12);
    assert!((mass_of(&filled, "base_link") - 2.0).abs() < 1e-12);
}

/// `--only` matching nothing is an error before anything is written; `--skip` matching nothing a
/// warning.
#[test]
fn only_and_skip_patterns_that_match_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = battery_robot(tmp.path());
    let out_file = tmp.path().join("out.urdf");
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--only",
        "base_lnk",
        "-o",
        out_file.to_str().unwrap(),
    ]);
    let s = text(&out);
    assert_eq!(out.status.code(), Some(2), "{s}");
    assert!(s.contains("--only `base_lnk`: no link matches"), "{s}");
    assert!(s.contains("did you mean `--only base_link`?"), "{s}");
    assert!(!out_file.exists());
    // One of two patterns unused: a warning, the other still fills.
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--only",
        "base_link",
        "--only",
        "batery",
        "--skip",
        "nothing_*",
    ]);
    let s = text(&out);
    assert_eq!(out.status.code(), Some(0), "{s}");
    assert!(
        s.contains(
            "--only `batery` matches no link: it does nothing; did you mean `--only battery`?"
        ),
        "{s}"
    );
    assert!(
        s.contains("--skip `nothing_*` matches no link: it does nothing"),
        "{s}"
    );
    // check, several files: a pattern unused in one file but used in the other is not reported.
    let other = write(
        tmp.path(),
        "other.urdf",
        "<robot name=\"o\"><link name=\"arm\"/></robot>",
    );
    let out = run(&["check", &urdf, &other, "--skip", "arm"]);
    assert!(!text(&out).contains("matches no link"), "{}", text(&out));
    let out = run(&["check", &urdf, &other, "--only", "leg"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
}

/// `check` without densities still stats every collision mesh: a missing one is an error with the
/// file, line, link, the path searched and the file one slip away.
#[test]
fn check_without_densities_finds_a_missing_mesh() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "meshes/Forearm.STL", &cube_stl(0.1));
    let urdf = write(
        tmp.path(),
        "robot.urdf",
        "<robot name=\"r\">\n<link name=\"forearm\">\n<inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>\n<collision><geometry><mesh filename=\"meshes/forearm.stl\"/></geometry></collision>\n</link>\n</robot>\n",
    );
    let out = run(&["check", &urdf]);
    let s = text(&out);
    assert_eq!(out.status.code(), Some(2), "{s}");
    assert!(
        s.contains(&format!(
            "{urdf}:2: link `forearm`: collision 1 (line 4): mesh `meshes/forearm.stl` not found"
        )),
        "{s}"
    );
    assert!(
        s.contains(&tmp.path().join("meshes/forearm.stl").display().to_string()),
        "{s}"
    );
    assert!(s.contains("did you mean `Forearm.STL`?"), "{s}");
}

/// A robot with visual geometry only: fill says so and offers `--geometry collision,visual`,
/// which computes the links from their visuals (a 0.1 × 0.2 × 0.3 box of 1000 kg/m³: 6 kg).
#[test]
fn a_visual_only_robot_is_named_and_can_be_filled_from_visuals() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = write(
        tmp.path(),
        "robot.urdf",
        "<robot name=\"r\">\n  <link name=\"a\">\n    <visual><geometry><box size=\"0.1 0.2 0.3\"/></geometry></visual>\n  </link>\n  <link name=\"frame\"/>\n</robot>\n",
    );
    let out = run(&["fill", &urdf, "--density", "1000"]);
    let s = text(&out);
    assert_eq!(out.status.code(), Some(0), "{s}");
    assert!(s.contains("no link has collision geometry"), "{s}");
    assert!(s.contains("--geometry collision,visual"), "{s}");
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--geometry",
        "collision,visual",
    ]);
    let s = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{s}");
    assert!(s.contains("filled 1 link(s)"), "{s}");
    assert!(
        s.contains("link `a`: computed from its visual geometry"),
        "{s}"
    );
    let filled = String::from_utf8_lossy(&out.stdout);
    assert!((mass_of(&filled, "a") - 6.0).abs() < 1e-12, "{filled}");
    assert!(!filled[filled.find("\"frame\"").unwrap()..].contains("<inertial>"));
    // Collision geometry, where a link has it, still comes first.
    let urdf = write(
        tmp.path(),
        "both.urdf",
        "<robot name=\"r\"><link name=\"a\"><visual><geometry><box size=\"1 1 1\"/></geometry></visual><collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision></link></robot>",
    );
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--geometry",
        "collision,visual",
    ]);
    assert!((mass_of(&String::from_utf8_lossy(&out.stdout), "a") - 6.0).abs() < 1e-12);
    assert!(!text(&out).contains("visual geometry"));
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--geometry",
        "visual,collision",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// A mesh 20 m on a side (a millimetre export without `scale`) fails its link by default, with the
/// `scale` hint, and nothing is written; `--allow-large-parts` accepts it (8000 m³ × 1000 kg/m³);
/// `mesh` prints the same warning.
#[test]
fn a_part_over_ten_metres_fails_its_link() {
    let tmp = tempfile::tempdir().unwrap();
    let stl = write(tmp.path(), "meshes/hull.stl", &cube_stl(20.0));
    let urdf = write(
        tmp.path(),
        "robot.urdf",
        "<robot name=\"r\">\n<link name=\"hull\">\n<collision><geometry><mesh filename=\"meshes/hull.stl\"/></geometry></collision>\n</link>\n</robot>\n",
    );
    let out_file = tmp.path().join("out.urdf");
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "-o",
        out_file.to_str().unwrap(),
    ]);
    let s = text(&out);
    assert_eq!(out.status.code(), Some(2), "{s}");
    assert!(s.contains(&format!("{urdf}:2: link `hull`: collision 1 (line 3): the mesh is 34.6 m across: if it was exported in millimetres, give it scale=\"0.001 0.001 0.001\" (or pass --allow-large-parts")), "{s}");
    assert!(!out_file.exists());
    // check with densities fails the same way; diff too.
    for cmd in ["check", "diff"] {
        let out = run(&[cmd, &urdf, "--density", "1000"]);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {}", text(&out));
    }
    let out = run(&["fill", &urdf, "--density", "1000", "--allow-large-parts"]);
    let s = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{s}");
    assert!(s.contains("the mesh is 34.6 m across"), "{s}");
    assert!((mass_of(&String::from_utf8_lossy(&out.stdout), "hull") - 8.0e6).abs() < 1e-3);
    let out = run(&["mesh", &stl]);
    let s = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{s}");
    assert!(
        s.contains("the mesh is 34.6 m across: if it was exported in millimetres"),
        "{s}"
    );
    // Scaled to metres it is a 2 cm cube, and nothing is said.
    let out = run(&["mesh", &stl, "--scale", "0.001", "0.001", "0.001"]);
    assert!(!text(&out).contains("across"), "{}", text(&out));
}

/// A binary STL (f32 corners) of the right-triangle prism with legs `a` (x) and `b` (y), from z = 0
/// to `h`, wound outward.
fn wedge_stl(a: f32, b: f32, h: f32) -> Vec<u8> {
    let p = [
        [0.0, 0.0, 0.0],
        [a, 0.0, 0.0],
        [0.0, b, 0.0],
        [0.0, 0.0, h],
        [a, 0.0, h],
        [0.0, b, h],
    ];
    let tris: [[usize; 3]; 8] = [
        [0, 2, 1],
        [3, 4, 5],
        [0, 1, 4],
        [0, 4, 3],
        [0, 3, 5],
        [0, 5, 2],
        [1, 2, 5],
        [1, 5, 4],
    ];
    let mut out = vec![0u8; 80];
    out.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        out.extend_from_slice(&[0u8; 12]);
        for i in t {
            for x in p[i] {
                out.extend_from_slice(&f32::to_le_bytes(x));
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

/// The `xyz` of the `<origin>` in `link`'s `<inertial>`, as written.
fn com_text(urdf: &str, link: &str) -> Vec<String> {
    let at = urdf.find(&format!("<link name=\"{link}\"")).expect("link");
    let body = &urdf[at..];
    let i = body.find("<inertial>").expect("inertial");
    let body = &body[i..];
    let x = body.find("xyz=\"").expect("xyz") + 5;
    body[x..x + body[x..].find('"').expect("quote")]
        .split(' ')
        .map(str::to_string)
        .collect()
}

/// Written numbers are rounded within the input's own precision: a wedge whose f32 corners are
/// 0.06, 0.03 and 0.04 has its COM at (0.02, 0.01, 0.02) as the file means it, though the f32
/// values put it at 0.019999999552965164 for z (f32(0.04) / 2, computed here).
#[test]
fn f32_corners_write_the_decimals_the_file_means() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("wedge.stl");
    std::fs::write(&p, wedge_stl(0.06, 0.03, 0.04)).unwrap();
    let urdf = write(
        tmp.path(),
        "robot.urdf",
        "<robot name=\"r\"><link name=\"w\"><collision><geometry><mesh filename=\"wedge.stl\"/></geometry></collision></link></robot>",
    );
    let out = run(&["fill", &urdf, "--density", "1000"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let filled = String::from_utf8_lossy(&out.stdout);
    assert_eq!(com_text(&filled, "w"), ["0.02", "0.01", "0.02"], "{filled}");
    // Every bit: the f32 noise is really there.
    let out = run(&["fill", &urdf, "--density", "1000", "--digits", "full"]);
    let full = String::from_utf8_lossy(&out.stdout);
    let z: f64 = com_text(&full, "w")[2].parse().unwrap();
    assert_eq!(z, f64::from(0.04f32) / 2.0);
    // The wedge's product of inertia keeps its digits: over the triangle the covariance of x and y
    // is a·b/12 − (a/3)(b/3) = −a·b/36, so ixy = −∫xy dm = +m·a·b/36 with m = 1000 · a·b/2 · h
    // = 0.036 kg: 1.8e-6.
    let ixy = {
        let i = filled.find("ixy=\"").unwrap() + 5;
        filled[i..i + filled[i..].find('"').unwrap()]
            .parse::<f64>()
            .unwrap()
    };
    let want = 0.036 * 0.06 * 0.03 / 36.0;
    assert!((ixy - want).abs() < 1e-6 * want.abs(), "{ixy} {want}");
}
