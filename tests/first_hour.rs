//! The first hour on a real robot repository, as the real binary meets it: named causes, no silent
//! no-ops, oversized parts, plain text. Every fixture is generated here.

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
