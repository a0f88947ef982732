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

/// A robot of two links: `base_link` (a 0.1 m box) and `battery` (`meshes/big_battery.stl`, a 0.1 m
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

/// An ASCII STL of the cube of side `a` wound inward (every face reversed): read, it is flipped, a
/// repair (UI101) whose bound is round-off.
fn inside_out_cube_stl(a: f64) -> String {
    let outward = cube_stl(a);
    let mut out = String::new();
    let mut corners: Vec<&str> = Vec::new();
    for line in outward.lines() {
        if line.trim_start().starts_with("vertex") {
            corners.push(line);
            if corners.len() == 3 {
                for c in [corners[0], corners[2], corners[1]] {
                    out.push_str(c);
                    out.push('\n');
                }
                corners.clear();
            }
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// `mesh` takes the diagnostic flags and `urdf-inertia.toml` as the other commands do: a flipped
/// cube's repair (UI101, bound round-off) is a note by default (below `--note-below`), a warning with
/// `--note-below 0`, gone with `--ignore` or `--quiet` (the numbers stay), an error with
/// `--warn-as-error` (exit 2), in text and JSON; a part over 10 m across (UI106) is silenced the same
/// way. The cube's volume is a³ whatever is printed.
#[test]
fn mesh_takes_the_diagnostic_flags_and_the_configuration() {
    let tmp = tempfile::tempdir().unwrap();
    let stl = write(tmp.path(), "inv.stl", &inside_out_cube_stl(2.0));
    let mesh = |extra: &[&str]| {
        let mut args = vec!["mesh", stl.as_str(), "--no-config"];
        args.extend_from_slice(extra);
        run(&args)
    };
    let out = mesh(&[]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    assert!(text(&out).contains("note[UI101]"), "{}", text(&out));
    assert!(
        text(&out).contains("volume            8 m³"),
        "{}",
        text(&out)
    );
    let out = mesh(&["--note-below", "0"]);
    assert!(text(&out).contains("warning[UI101]"), "{}", text(&out));
    for quiet in [
        &["--note-below", "0", "--quiet"][..],
        &["--note-below", "0", "--ignore", "UI101"],
    ] {
        let out = mesh(quiet);
        assert_eq!(out.status.code(), Some(0), "{quiet:?}");
        assert!(!text(&out).contains("UI101"), "{quiet:?}: {}", text(&out));
        assert!(
            text(&out).contains("volume            8 m³"),
            "{}",
            text(&out)
        );
    }
    let out = mesh(&["--note-below", "0", "--warn-as-error", "UI101"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("error[UI101]"), "{}", text(&out));
    assert!(
        text(&out).contains("made an error (--warn-as-error)"),
        "{}",
        text(&out)
    );
    // JSON: the promoted repair under "errors", the exit status 2, the volume all the same.
    let out = mesh(&[
        "--note-below",
        "0",
        "--warn-as-error",
        "UI101",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["errors"][0]["code"], "UI101", "{json}");
    assert_eq!(json["volume"], 8.0);
    let out = mesh(&["--ignore", "UI101", "--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(!json.to_string().contains("UI101"), "{json}");
    // The same from urdf-inertia.toml (found in the current directory).
    write(
        tmp.path(),
        "urdf-inertia.toml",
        "note-below = 0\nwarn-as-error = [\"UI101\"]\n",
    );
    let out = Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(["mesh", "inv.stl"])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("error[UI101]"), "{}", text(&out));
    // A 20 m cube (a millimetre export without scale): UI106, which --ignore silences.
    let big = write(tmp.path(), "big.stl", &cube_stl(20.0));
    let out = run(&["mesh", &big, "--no-config"]);
    assert!(text(&out).contains("warning[UI106]"), "{}", text(&out));
    let out = run(&["mesh", &big, "--no-config", "--ignore", "UI106"]);
    assert_eq!(out.status.code(), Some(0));
    assert!(!text(&out).contains("across"), "{}", text(&out));
}

/// `xacro` takes the diagnostic flags and `urdf-inertia.toml` too: its warning (UI208, here an
/// unknown attribute) is printed by default, gone with `--quiet` or `--ignore`, and with
/// `--warn-as-error` nothing is printed on stdout and the exit status is 2.
#[test]
fn xacro_takes_the_diagnostic_flags_and_the_configuration() {
    let tmp = tempfile::tempdir().unwrap();
    let file = write(
        tmp.path(),
        "r.urdf.xacro",
        "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:property name=\"w\" value=\"2\" colour=\"red\"/>\n  <link name=\"a\"><collision><geometry><box size=\"${w} 1 1\"/></geometry></collision></link>\n</robot>\n",
    );
    let xacro = |extra: &[&str]| {
        let mut args = vec!["xacro", file.as_str(), "--no-config"];
        args.extend_from_slice(extra);
        run(&args)
    };
    let out = xacro(&[]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        err.contains("warning[UI208]") && err.contains("unknown attribute(s): colour"),
        "{err}"
    );
    let expanded = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(expanded.contains("<box size=\"2 1 1\"/>"), "{expanded}");
    for quiet in [&["--quiet"][..], &["--ignore", "UI208"]] {
        let out = xacro(quiet);
        assert_eq!(out.status.code(), Some(0), "{quiet:?}");
        assert!(out.stderr.is_empty(), "{quiet:?}: {}", text(&out));
        assert_eq!(String::from_utf8_lossy(&out.stdout), expanded);
    }
    let out = xacro(&["--warn-as-error", "UI208"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(out.stdout.is_empty());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("error[UI208]"),
        "{}",
        text(&out)
    );
    write(tmp.path(), "urdf-inertia.toml", "ignore = [\"UI208\"]\n");
    let out = Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(["xacro", "r.urdf.xacro"])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stderr.is_empty(), "{}", text(&out));
}

/// `fill --format json` printed no JSON when a link failed without `--keep-going`: it prints its
/// summary with the errors and `"written": false`, writes nothing and exits 2; with `--keep-going`
/// `"written"` is true. The same when a warning is made an error.
#[test]
fn fill_json_reports_a_failure_and_exits_2() {
    let tmp = tempfile::tempdir().unwrap();
    let text_in = "<robot name=\"r\">\n  <link name=\"good\">\n    <collision><geometry><box size=\"1 2 3\"/></geometry></collision>\n  </link>\n  <link name=\"bad\">\n    <collision><geometry><box size=\"1 -2 3\"/></geometry></collision>\n  </link>\n</robot>\n";
    let urdf = write(tmp.path(), "r.urdf", text_in);
    let out_file = tmp.path().join("out.urdf");
    let out_s = out_file.to_str().unwrap();
    for target in [&["-o", out_s][..], &["-i"]] {
        let mut args = vec![
            "fill",
            urdf.as_str(),
            "--density",
            "1000",
            "--format",
            "json",
        ];
        args.extend_from_slice(target);
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{target:?}: {}", text(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{target:?}: no JSON ({e}): {}", text(&out)));
        assert_eq!(json["written"], false, "{json}");
        let errors = json["errors"].as_array().expect("errors");
        assert_eq!(errors.len(), 1, "{json}");
        assert_eq!(errors[0]["link"], "bad");
        assert_eq!(errors[0]["code"], "UI701");
        assert!(!out_file.exists());
        assert_eq!(std::fs::read_to_string(&urdf).unwrap(), text_in);
    }
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--format",
        "json",
        "-o",
        out_s,
        "--keep-going",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["written"], true, "{json}");
    assert!(out_file.exists());
    // A warning made an error: nothing written, the JSON says so.
    std::fs::remove_file(&out_file).unwrap();
    let stl = write(tmp.path(), "inv.stl", &inside_out_cube_stl(1.0));
    let urdf = write(
        tmp.path(),
        "m.urdf",
        "<robot name=\"m\"><link name=\"c\"><collision><geometry><mesh filename=\"inv.stl\"/></geometry></collision></link></robot>",
    );
    assert!(std::path::Path::new(&stl).exists());
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--format",
        "json",
        "-o",
        out_s,
        "--note-below",
        "0",
        "--warn-as-error",
        "UI101",
        "--no-config",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["written"], false, "{json}");
    assert!(!out_file.exists());
}

/// The fill hook's default `args: [--density-map, densities.toml]` failed in a repository without
/// that file. The hooks of both manifests (built from source, and the `language: python` mirror)
/// pass no density arguments: run as pre-commit runs them (the manifest's `entry` and the changed
/// file, from the repository's root), the fill hook takes the density map that `urdf-inertia.toml`
/// names; without one it fails saying how to give one.
#[test]
fn the_fill_hook_takes_its_densities_from_the_configuration() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifests = [
        root.join(".pre-commit-hooks.yaml"),
        root.join("packaging/pre-commit-mirror/.pre-commit-hooks.yaml"),
    ];
    for manifest in &manifests {
        let yaml = std::fs::read_to_string(manifest).unwrap();
        let fill_hook = yaml
            .split("- id: ")
            .find(|h| h.starts_with("urdf-inertia-fill"))
            .expect("fill hook");
        assert!(
            !fill_hook.contains("args:"),
            "{}: {fill_hook}",
            manifest.display()
        );
        let entry = fill_hook
            .lines()
            .find_map(|l| l.trim().strip_prefix("entry: "))
            .expect("entry");
        let argv: Vec<&str> = entry.split_whitespace().collect();
        assert_eq!(argv[..2], ["urdf-inertia", "fill"], "{entry}");
        for with_config in [true, false] {
            let tmp = tempfile::tempdir().unwrap();
            std::fs::create_dir(tmp.path().join(".git")).unwrap();
            write(tmp.path(), "densities.toml", "default = 1000\n");
            if with_config {
                write(
                    tmp.path(),
                    "urdf-inertia.toml",
                    "density-map = \"densities.toml\"\n",
                );
            }
            let urdf = write(
                tmp.path(),
                "urdf/r.urdf",
                "<robot name=\"r\">\n  <link name=\"a\">\n    <collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>\n  </link>\n</robot>\n",
            );
            let out = Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
                .args(&argv[1..])
                .arg("urdf/r.urdf")
                .current_dir(tmp.path())
                .output()
                .unwrap();
            let filled = std::fs::read_to_string(&urdf).unwrap();
            if with_config {
                assert_eq!(out.status.code(), Some(0), "{}", text(&out));
                // 0.1 × 0.2 × 0.3 m of 1000 kg/m³.
                assert!((mass_of(&filled, "a") - 6.0).abs() < 1e-12, "{filled}");
            } else {
                assert_eq!(out.status.code(), Some(2));
                assert!(
                    text(&out).contains("fill needs densities")
                        && text(&out).contains("density-map = \"FILE\"")
                        && text(&out).contains("urdf-inertia.toml"),
                    "{}",
                    text(&out)
                );
                assert!(!filled.contains("<inertial>"));
            }
        }
    }
}

/// Messages speak plain words: none of the repair ladder's terms (`rung`, `ladder`, a bare `exact:`
/// or `welded:` before a message, `model: cracks`, "by 1 of it") in what `fill`, `diff`, `check`
/// and `mesh` print about a flipped cube, a cube whose corners need joining and a closed one, with
/// every note shown; `mesh` names the health in words ("closed mesh", "inside out").
#[test]
fn messages_use_plain_words() {
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), "inv.stl", &inside_out_cube_stl(0.2));
    write(tmp.path(), "ok.stl", &cube_stl(0.2));
    // The same cube with one corner of one face off by 1e-9 m: closed once corners are joined.
    let cracked =
        cube_stl(0.2).replacen("vertex -0.1 -0.1 -0.1", "vertex -0.100000001 -0.1 -0.1", 1);
    assert_ne!(cracked, cube_stl(0.2));
    write(tmp.path(), "cracked.stl", &cracked);
    let urdf = write(
        tmp.path(),
        "r.urdf",
        "<robot name=\"r\">\n  <link name=\"a\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"3\"/></inertial><collision><geometry><mesh filename=\"inv.stl\"/></geometry></collision></link>\n  <link name=\"b\"><collision><geometry><mesh filename=\"cracked.stl\"/></geometry></collision></link>\n  <link name=\"c\"><collision><geometry><mesh filename=\"ok.stl\"/></geometry></collision></link>\n</robot>\n",
    );
    let mut printed = String::new();
    for cmd in ["fill", "diff", "check"] {
        let out = run(&[
            cmd,
            &urdf,
            "--density",
            "1000",
            "--note-below",
            "0",
            "-v",
            "--no-config",
        ]);
        printed.push_str(&text(&out));
    }
    for mesh in ["inv.stl", "ok.stl", "cracked.stl"] {
        let p = tmp.path().join(mesh);
        let out = run(&[
            "mesh",
            p.to_str().unwrap(),
            "--note-below",
            "0",
            "--no-config",
        ]);
        printed.push_str(&text(&out));
    }
    assert!(printed.contains("warning[UI101]"), "{printed}");
    assert!(
        printed.contains("health            inside out"),
        "{printed}"
    );
    assert!(
        printed.contains("health            closed mesh"),
        "{printed}"
    );
    for jargon in [
        "rung",
        "ladder",
        ": exact:",
        ": welded:",
        "model: cracks",
        "by 1 of it",
    ] {
        assert!(
            !printed.to_lowercase().contains(jargon),
            "`{jargon}` in:\n{printed}"
        );
    }
}

/// A density map with an unquoted glob key (the likeliest slip) is an error with the line, the
/// column, the line itself, a caret and the hint to quote it, through the binary.
#[test]
fn a_density_map_error_shows_line_column_and_hint() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = battery_robot(tmp.path());
    let map = write(
        tmp.path(),
        "d.toml",
        "default = 1000\n[links]\n*battery* = 2000\n",
    );
    let out = run(&["fill", &urdf, "--density-map", &map, "--no-config"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(err.contains("d.toml:3:1"), "{err}");
    assert!(err.contains("*battery* = 2000"), "{err}");
    assert!(err.contains('^'), "{err}");
    assert!(
        err.contains("hint: a key with glob characters must be quoted: \"*battery*\" = …"),
        "{err}"
    );
}

/// A new `<inertial>` follows the style of the file's existing ones (attribute order, ` />`), as the
/// real binary writes it.
#[test]
fn a_new_inertial_follows_the_files_style() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = write(
        tmp.path(),
        "r.urdf",
        "<robot name=\"r\">\n  <link name=\"kept\">\n    <inertial>\n      <origin rpy=\"0 0 0\" xyz=\"0 0 0\" />\n      <mass value=\"6\" />\n      <inertia ixx=\"0.065\" iyy=\"0.05\" izz=\"0.025\" ixy=\"0\" ixz=\"0\" iyz=\"0\" />\n    </inertial>\n    <collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>\n  </link>\n  <link name=\"new\">\n    <collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>\n  </link>\n</robot>\n",
    );
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--missing-only",
        "--no-config",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let filled = String::from_utf8_lossy(&out.stdout).into_owned();
    let new = &filled[filled.find("<link name=\"new\">").unwrap()..];
    assert!(new.contains("<origin rpy=\"0 0 0\" xyz=\""), "{new}");
    assert!(new.contains("<mass value=\"6\" />"), "{new}");
    assert!(
        new.contains(
            "<inertia ixx=\"0.065\" iyy=\"0.05\" izz=\"0.025\" ixy=\"0\" ixz=\"0\" iyz=\"0\" />"
        ),
        "{new}"
    );
}

/// The release binary was 50 MB with `debug = 1` in the release profile: the profile keeps no debug
/// information beyond line tables (the profiling profile may).
#[test]
fn the_release_profile_keeps_no_full_debug_info() {
    let manifest =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml")).unwrap();
    let doc: toml::Table = manifest.parse().unwrap();
    let release = doc
        .get("profile")
        .and_then(|p| p.get("release"))
        .and_then(toml::Value::as_table);
    let debug = release.and_then(|r| r.get("debug"));
    let allowed = |v: &toml::Value| {
        matches!(v.as_integer(), Some(0))
            || matches!(v.as_bool(), Some(false))
            || matches!(
                v.as_str(),
                Some("none" | "line-tables-only" | "line-directives-only")
            )
    };
    assert!(debug.is_none_or(allowed), "release debug = {debug:?}");
}

/// The README's quick start for one's own robot, run as written (each `urdf-inertia` line of the
/// block, comments cut) in a repository holding `urdf/my_robot.urdf` and `densities.toml`: every
/// command does its work (none is a placeholder that errors), the fill keeps the weighed mass, and
/// the final check passes. The robot: a 0.1 × 0.2 × 0.3 m box weighed at 5 kg, without inertia,
/// and a 0.1 m cube without `<inertial>` (1 kg at 1000 kg/m³).
#[test]
fn the_readme_quick_start_runs_as_written() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let start = readme
        .find("### Quick start on your own robot")
        .expect("quick start section");
    let block = &readme[start..];
    let block = &block[block.find("```sh\n").expect("sh block") + 6..];
    let block = &block[..block.find("```").expect("block end")];
    let commands: Vec<Vec<&str>> = block
        .lines()
        .filter_map(|l| l.trim().strip_prefix("urdf-inertia "))
        .map(|l| l.split(" #").next().unwrap().split_whitespace().collect())
        .collect();
    assert!(commands.len() >= 3, "{block}");
    let tmp = tempfile::tempdir().unwrap();
    let urdf = write(
        tmp.path(),
        "urdf/my_robot.urdf",
        "<robot name=\"mine\">\n  <link name=\"base\">\n    <inertial><mass value=\"5\"/></inertial>\n    <collision><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision>\n  </link>\n  <link name=\"head\">\n    <collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision>\n  </link>\n</robot>\n",
    );
    write(tmp.path(), "densities.toml", "default = 1000\n");
    let mut masses = Vec::new();
    for args in &commands {
        let out = Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
            .args(args)
            .arg("--no-config")
            .current_dir(tmp.path())
            .output()
            .unwrap();
        // diff and check report what they find (exit 1); nothing may be an error.
        let expected: &[i32] = if args[0] == "fill" { &[0] } else { &[0, 1] };
        assert!(
            out.status.code().is_some_and(|c| expected.contains(&c)),
            "{args:?}: {}",
            text(&out)
        );
        if args[0] == "fill" {
            let filled = std::fs::read_to_string(&urdf).unwrap();
            masses.push((mass_of(&filled, "base"), mass_of(&filled, "head")));
        }
        if args[0] == "check" {
            assert_eq!(out.status.code(), Some(0), "{}", text(&out));
        }
    }
    // --keep-mass kept the weighed 5 kg; the map's fill then computes every link from 1000 kg/m³.
    assert_eq!(masses.first().map(|m| m.0), Some(5.0), "{masses:?}");
    assert!(
        masses.iter().all(|m| (m.1 - 1.0).abs() < 1e-12),
        "{masses:?}"
    );
    assert!((masses.last().unwrap().0 - 6.0).abs() < 1e-12, "{masses:?}");
}

/// A binary STL (f32 corners) of a regular `n`-gon prism about the vertical axis through `(cx, cy)`,
/// circumradius `r`, from z = 0 to `h`, wound outward.
fn prism_stl_f32(n: u32, r: f64, h: f64, cx: f64, cy: f64) -> Vec<u8> {
    let corner = |i: u32, z: f64| {
        let t = 2.0 * std::f64::consts::PI * f64::from(i % n) / f64::from(n);
        [cx + r * t.cos(), cy + r * t.sin(), z]
    };
    let mut tris = Vec::new();
    for i in 0..n {
        let (a0, b0, a1, b1) = (
            corner(i, 0.0),
            corner(i + 1, 0.0),
            corner(i, h),
            corner(i + 1, h),
        );
        tris.push([[cx, cy, 0.0], b0, a0]);
        tris.push([[cx, cy, h], a1, b1]);
        tris.push([a0, b0, b1]);
        tris.push([a0, b1, a1]);
    }
    let mut out = vec![0u8; 80];
    out.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        out.extend_from_slice(&[0u8; 12]);
        for p in t {
            for x in p {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

/// Products of inertia that are f32 round-off (`ixy="4.28736e-14"` beside `iyy="2.83e-5"` once) are
/// written as `0`: a regular 64-gon prism has none about its axis, but its f32 corners, away from
/// the origin, leave one of about 1e-19 (`--digits full` shows it). Its moments are the prism's:
/// m·R²(1 + 2cos²(π/n))/6 about the axis, half that plus m·h²/12 across it.
#[test]
fn f32_noise_in_products_of_inertia_is_written_as_zero() {
    let tmp = tempfile::tempdir().unwrap();
    let (n, r, h) = (64u32, 0.021, 0.05);
    std::fs::write(
        tmp.path().join("prism.stl"),
        prism_stl_f32(n, r, h, 0.13, -0.07),
    )
    .unwrap();
    let urdf = write(
        tmp.path(),
        "robot.urdf",
        "<robot name=\"r\"><link name=\"p\"><collision><geometry><mesh filename=\"prism.stl\"/></geometry></collision></link></robot>",
    );
    let attr = |filled: &str, name: &str| {
        let i = filled.find(&format!("{name}=\"")).expect(name) + name.len() + 2;
        filled[i..i + filled[i..].find('"').unwrap()].to_string()
    };
    let out = run(&[
        "fill",
        &urdf,
        "--density",
        "1000",
        "--digits",
        "full",
        "--no-config",
    ]);
    let full = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_ne!(attr(&full, "ixy"), "0", "the noise is there: {full}");
    let out = run(&["fill", &urdf, "--density", "1000", "--no-config"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let filled = String::from_utf8_lossy(&out.stdout).into_owned();
    for product in ["ixy", "ixz", "iyz"] {
        assert_eq!(attr(&filled, product), "0", "{filled}");
    }
    let nf = f64::from(n);
    let area = nf / 2.0 * r * r * (2.0 * std::f64::consts::PI / nf).sin();
    let m = 1000.0 * area * h;
    let polar = m * r * r * (1.0 + 2.0 * (std::f64::consts::PI / nf).cos().powi(2)) / 6.0;
    for (name, value) in [
        ("ixx", polar / 2.0 + m * h * h / 12.0),
        ("iyy", polar / 2.0 + m * h * h / 12.0),
        ("izz", polar),
    ] {
        let got: f64 = attr(&filled, name).parse().unwrap();
        // The f32 corners are within 6e-8 of 0.15 m, so r within about 5e-7 relative.
        assert!((got - value).abs() <= 1e-5 * value, "{name} {got} {value}");
    }
}
