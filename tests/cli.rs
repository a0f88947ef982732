//! The real binary on URDFs made by this project: analytic values, lossless output, exit codes.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

// The test helpers are the library tests' own (mesh generators).
#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;

const PI: f64 = std::f64::consts::PI;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run urdf-inertia")
}

fn demo() -> (PathBuf, PathBuf) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/demo_arm_description");
    (root.join("urdf/demo_arm.urdf"), root.join("densities.toml"))
}

/// A copy of the demo package in a temp dir (so tests may write next to it).
fn demo_copy() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let (urdf, map) = demo();
    let src = urdf
        .parent()
        .and_then(Path::parent)
        .expect("package dir")
        .to_path_buf();
    let dst = tmp.path().join("demo_arm_description");
    for sub in ["urdf", "meshes"] {
        std::fs::create_dir_all(dst.join(sub)).expect("mkdir");
        for e in std::fs::read_dir(src.join(sub)).expect("read_dir") {
            let e = e.expect("entry");
            std::fs::copy(e.path(), dst.join(sub).join(e.file_name())).expect("copy");
        }
    }
    std::fs::copy(src.join("package.xml"), dst.join("package.xml")).expect("copy");
    std::fs::copy(&map, dst.join("densities.toml")).expect("copy");
    let urdf = dst.join("urdf/demo_arm.urdf");
    let map = dst.join("densities.toml");
    (tmp, urdf, map)
}

/// `fill URDF --density-map MAP -i`, which must succeed.
fn fill_in_place(urdf: &Path, map: &Path) {
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "-i",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Parsed `<inertial>` of one link from URDF text: (mass, com, [ixx, ixy, ixz, iyy, iyz, izz]).
fn inertial_of(text: &str, link: &str) -> Option<(f64, [f64; 3], [f64; 6])> {
    let start = text.find(&format!("<link name=\"{link}\""))?;
    let end = start + text[start..].find("</link>")?;
    let body = &text[start..end];
    let i = body.find("<inertial>")?;
    let body = &body[i..];
    let attr = |tag: &str, key: &str| -> f64 {
        let t = body.find(&format!("<{tag} ")).expect("tag");
        let s = &body[t..];
        let k = s.find(&format!(" {key}=\"")).expect("key") + key.len() + 3;
        let v = &s[k..];
        v[..v.find('"').expect("quote")].parse().expect("number")
    };
    let xyz = {
        let t = body.find("<origin ").expect("origin");
        let s = &body[t..];
        let k = s.find("xyz=\"").expect("xyz") + 5;
        let v: Vec<f64> = s[k..k + s[k..].find('"').expect("q")]
            .split_whitespace()
            .map(|x| x.parse().expect("n"))
            .collect();
        [v[0], v[1], v[2]]
    };
    Some((
        attr("mass", "value"),
        xyz,
        [
            attr("inertia", "ixx"),
            attr("inertia", "ixy"),
            attr("inertia", "ixz"),
            attr("inertia", "iyy"),
            attr("inertia", "iyz"),
            attr("inertia", "izz"),
        ],
    ))
}

fn close(got: f64, want: f64, rel: f64, scale: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * scale,
        "{what}: got {got}, want {want}"
    );
}

fn assert_inertial(text: &str, link: &str, mass: f64, com: [f64; 3], inertia: [f64; 6], rel: f64) {
    let (m, c, i) = inertial_of(text, link).unwrap_or_else(|| panic!("no inertial for {link}"));
    close(m, mass, rel, mass, &format!("{link} mass"));
    let size = com.iter().fold(0.1f64, |a, x| a.max(x.abs()));
    for k in 0..3 {
        close(c[k], com[k], rel, size, &format!("{link} com[{k}]"));
    }
    let norm = inertia.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for k in 0..6 {
        close(i[k], inertia[k], rel, norm, &format!("{link} inertia[{k}]"));
    }
}

/// Box inertia about its centre: [ixx, 0, 0, iyy, 0, izz].
fn box_i(m: f64, s: [f64; 3]) -> [f64; 6] {
    [
        m * (s[1] * s[1] + s[2] * s[2]) / 12.0,
        0.0,
        0.0,
        m * (s[0] * s[0] + s[2] * s[2]) / 12.0,
        0.0,
        m * (s[0] * s[0] + s[1] * s[1]) / 12.0,
    ]
}

/// Adds a body (mass, com, central inertia) to an accumulation about the origin (second moments).
fn combine(parts: &[(f64, [f64; 3], [f64; 6])]) -> (f64, [f64; 3], [f64; 6]) {
    let m: f64 = parts.iter().map(|p| p.0).sum();
    let c = [0, 1, 2].map(|k| parts.iter().map(|p| p.0 * p.1[k]).sum::<f64>() / m);
    let mut i = [0.0; 6];
    for (pm, pc, pi) in parts {
        let d = [pc[0] - c[0], pc[1] - c[1], pc[2] - c[2]];
        i[0] += pi[0] + pm * (d[1] * d[1] + d[2] * d[2]);
        i[3] += pi[3] + pm * (d[0] * d[0] + d[2] * d[2]);
        i[5] += pi[5] + pm * (d[0] * d[0] + d[1] * d[1]);
        i[1] += pi[1] - pm * d[0] * d[1];
        i[2] += pi[2] - pm * d[0] * d[2];
        i[4] += pi[4] - pm * d[1] * d[2];
    }
    (m, c, i)
}

#[test]
#[allow(clippy::too_many_lines)] // one check per value of the demo robot, in its order
fn fill_demo_robot_gives_analytic_values() {
    let (urdf, map) = demo();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("utf8");

    // base_link: aluminium plate 0.3 × 0.3 × 0.05 at z 0.025, battery box 0.12 × 0.08 × 0.04 at z 0.07 (2500).
    let plate = (
        2700.0 * 0.3 * 0.3 * 0.05,
        [0.0, 0.0, 0.025],
        box_i(2700.0 * 0.3 * 0.3 * 0.05, [0.3, 0.3, 0.05]),
    );
    let batt = (
        2500.0 * 0.12 * 0.08 * 0.04,
        [0.0, 0.0, 0.07],
        box_i(2500.0 * 0.12 * 0.08 * 0.04, [0.12, 0.08, 0.04]),
    );
    let (m, c, i) = combine(&[plate, batt]);
    assert_inertial(&text, "base_link", m, c, i, 1e-12);

    // shoulder: 80 × 80 × 200 mm box (binary STL in mm, scale 0.001), from z 0 to 0.2.
    let m = 2700.0 * 0.08 * 0.08 * 0.2;
    assert_inertial(
        &text,
        "shoulder_link",
        m,
        [0.0, 0.0, 0.1],
        box_i(m, [0.08, 0.08, 0.2]),
        1e-12,
    );

    // upper arm: regular hexagonal prism, circumradius R = 0.04, length 0.3 (OBJ quads and hexagons).
    let (r, l) = (0.04f64, 0.3f64);
    let area = 1.5 * 3f64.sqrt() * r * r;
    let m = 2700.0 * area * l;
    let polar = 5.0 * 3f64.sqrt() / 8.0 * r.powi(4); // ∫(x²+y²) dA of the hexagon
    let izz = 2700.0 * l * polar;
    let ixx = 2700.0 * (l * polar / 2.0 + area * l.powi(3) / 12.0);
    assert_inertial(
        &text,
        "upper_arm_link",
        m,
        [0.0, 0.0, 0.15],
        [ixx, 0.0, 0.0, ixx, 0.0, izz],
        1e-12,
    );

    // forearm: 60 × 60 × 250 mm box (COLLADA in mm, node matrix lifts it by 125 mm), yawed 45°.
    let m = 2700.0 * 0.06 * 0.06 * 0.25;
    assert_inertial(
        &text,
        "forearm_link",
        m,
        [0.0, 0.0, 0.125],
        box_i(m, [0.06, 0.06, 0.25]),
        1e-12,
    );

    // wrist: right-triangle prism (legs a = 0.06, b = 0.04, height h = 0.05), mirrored in y, mass 0.15.
    let (a, b, h, m) = (0.06f64, 0.04f64, 0.05f64, 0.15f64);
    let want = [
        m * (b * b / 18.0 + h * h / 12.0),
        -m * a * b / 36.0,
        0.0,
        m * (a * a / 18.0 + h * h / 12.0),
        0.0,
        m * (a * a + b * b) / 18.0,
    ];
    // Binary STL stores f32 coordinates: 1e-7 relative.
    assert_inertial(
        &text,
        "wrist_link",
        m,
        [a / 3.0, -b / 3.0, h / 2.0],
        want,
        1e-7,
    );

    // gripper (PLA 1240): capsule r 0.02 l 0.06 at z 0.05; cylinder r 0.01 l 0.04 along x at (0.04, 0, 0.04);
    // sphere r 0.015 at z 0.12.
    let rho = 1240.0;
    let (rc, lc) = (0.02f64, 0.06f64);
    let mcyl = rho * PI * rc * rc * lc;
    let mhemi = rho * 2.0 / 3.0 * PI * rc.powi(3);
    // Hemisphere: COM 3r/8 from its flat face, central Ixx = (83/320) m r².
    let d = lc / 2.0 + 3.0 * rc / 8.0;
    let cap_ixx = mcyl * (3.0 * rc * rc + lc * lc) / 12.0
        + 2.0 * (83.0 / 320.0 * mhemi * rc * rc + mhemi * d * d);
    let cap_izz = mcyl * rc * rc / 2.0 + 2.0 * 0.4 * mhemi * rc * rc;
    let capsule = (
        mcyl + 2.0 * mhemi,
        [0.0, 0.0, 0.05],
        [cap_ixx, 0.0, 0.0, cap_ixx, 0.0, cap_izz],
    );
    let (rr, lr) = (0.01f64, 0.04f64);
    let mr = rho * PI * rr * rr * lr;
    let along = mr * rr * rr / 2.0;
    let across = mr * (3.0 * rr * rr + lr * lr) / 12.0;
    let rod = (
        mr,
        [0.04, 0.0, 0.04],
        [along, 0.0, 0.0, across, 0.0, across],
    );
    let ms = rho * 4.0 / 3.0 * PI * 0.015f64.powi(3);
    let is = 0.4 * ms * 0.015 * 0.015;
    let ball = (ms, [0.0, 0.0, 0.12], [is, 0.0, 0.0, is, 0.0, is]);
    let (m, c, i) = combine(&[capsule, rod, ball]);
    assert_inertial(&text, "gripper_link", m, c, i, 1e-12);

    // tool0 is a frame: untouched.
    assert!(text.contains("  <link name=\"tool0\"/>\n"));
    assert!(inertial_of(&text, "tool0").is_none());
}

/// Removes every `<inertial>…</inertial>` block together with the line it stands on.
fn strip_inertials(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(s) = rest.find("<inertial>") {
        let line_start = rest[..s].rfind('\n').map_or(0, |i| i + 1);
        out.push_str(&rest[..line_start]);
        let e = s + rest[s..].find("</inertial>").expect("closing") + "</inertial>".len();
        rest = &rest[e..];
        // Drop the newline that ended the block's last line.
        rest = rest
            .strip_prefix("\r\n")
            .or_else(|| rest.strip_prefix('\n'))
            .unwrap_or(rest);
    }
    out.push_str(rest);
    out
}

#[test]
fn only_inertials_change_and_fill_is_idempotent() {
    let (_tmp, urdf, map) = demo_copy();
    let original = std::fs::read_to_string(&urdf).expect("read");
    fill_in_place(&urdf, &map);
    let once = std::fs::read_to_string(&urdf).expect("read");
    // Outside <inertial>, every byte is the same (the original's one stale block is removed on both sides).
    assert_eq!(strip_inertials(&once), strip_inertials(&original));
    // New blocks follow the link's indentation: tabs for forearm_link.
    assert!(
        once.contains("\t<link name=\"forearm_link\">\n\t\t<inertial>\n\t\t\t<origin "),
        "{once}"
    );
    fill_in_place(&urdf, &map);
    assert_eq!(
        std::fs::read_to_string(&urdf).expect("read"),
        once,
        "second fill changed the file"
    );
    // No temp files left beside it.
    let leftovers: Vec<_> = std::fs::read_dir(urdf.parent().unwrap())
        .unwrap()
        .filter_map(std::result::Result::ok)
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
    // And the filled file passes check.
    let out = run(&["check", urdf.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

#[test]
fn crlf_comments_and_unknown_tags_survive() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let text = "<?xml version=\"1.0\"?>\r\n<!-- keep me -->\r\n<robot name=\"r\" xmlns:xacro=\"http://ros.org/wiki/xacro\">\r\n   <link name=\"a\"   >\r\n      <collision><geometry><box size=\"1 2 3\"/></geometry></collision>\r\n   </link>\r\n   <mujoco><compiler meshdir=\"m\"/></mujoco>\r\n   <ros2_control name=\"c\" type=\"system\"/>\r\n</robot>\r\n";
    let path = tmp.path().join("r.urdf");
    std::fs::write(&path, text).expect("write");
    let out = run(&["fill", path.to_str().unwrap(), "--density", "1000"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let filled = String::from_utf8(out.stdout).expect("utf8");
    assert_eq!(strip_inertials(&filled), text);
    assert!(filled.contains("   <link name=\"a\"   >\r\n      <inertial>\r\n         <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\r\n"), "{filled:?}");
    assert!(
        !filled.replace("\r\n", "").contains('\n'),
        "a bare LF was written into a CRLF file"
    );
    // 1 × 2 × 3 box of 1000 kg/m³.
    assert_inertial(
        &filled,
        "a",
        6000.0,
        [0.0; 3],
        [6500.0, 0.0, 0.0, 5000.0, 0.0, 2500.0],
        1e-15,
    );
}

#[test]
fn package_paths_resolve_through_the_option_and_walking_up() {
    let (_tmp, urdf, map) = demo_copy();
    // Move the URDF out of the package: walking up no longer finds it, --package-path does.
    let outside = urdf
        .parent()
        .unwrap()
        .parent()
        .unwrap()
        .parent()
        .unwrap()
        .join("robot.urdf");
    let text = std::fs::read_to_string(&urdf).unwrap().replace(
        "../meshes/upper_arm.obj",
        "package://demo_arm_description/meshes/upper_arm.obj",
    );
    std::fs::write(&outside, text).unwrap();
    let pkg = urdf.parent().unwrap().parent().unwrap().to_path_buf();
    let out = run(&[
        "fill",
        outside.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "--package-path",
        &format!("demo_arm_description={}", pkg.display()),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Without it, the sibling-directory walk finds demo_arm_description next to robot.urdf.
    let out = run(&[
        "fill",
        outside.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn check_exit_codes() {
    let (urdf, map) = demo();
    // The demo ships links without <inertial> and one stale value: problems, exit 1.
    let out = run(&["check", urdf.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(
            "demo_arm.urdf:5: link `base_link`: has collision geometry but no <inertial> [UI601]"
        ),
        "{stdout}"
    );
    // With a density source, the stale upper arm is reported with its line.
    let out = run(&[
        "check",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("demo_arm.urdf:41: link `upper_arm_link`: mass 1.2 kg"),
        "{stdout}"
    );
    // A missing file: exit 2.
    let out = run(&["check", "/nonexistent/robot.urdf"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn diff_names_unit_slips() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // Mass written in grams: 1000 × the computed 6000 kg → off by 1e3.
    let text = "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"6000000\"/><inertia ixx=\"6500\" ixy=\"0\" ixz=\"0\" iyy=\"5000\" iyz=\"0\" izz=\"2500\"/></inertial><collision><geometry><box size=\"1 2 3\"/></geometry></collision></link></robot>";
    let path = tmp.path().join("r.urdf");
    std::fs::write(&path, text).unwrap();
    let out = run(&["diff", path.to_str().unwrap(), "--density", "1000"]);
    // Differs beyond the tolerance: exit 1, as `ruff format --diff` does.
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("mass off by 1e3"), "{stdout}");
    // Products are all zero: no mirror can be seen, none is named.
    assert!(!stdout.contains("mirrored"), "{stdout}");
    let out = run(&[
        "diff",
        path.to_str().unwrap(),
        "--density",
        "1000",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let link = &v["links"][0];
    assert_eq!(link["comparison"]["mass_ratio"].as_f64(), Some(1000.0));
    assert_eq!(link["differs"], true);
    assert_eq!(link["differences"][0]["quantity"], "mass");
    assert_eq!(link["differences"][0]["ratio"].as_f64(), Some(1000.0));
    assert!(link["comparison"]["causes"][0]
        .as_str()
        .is_some_and(|c| c.contains("mass off by 1e3")));
}

#[test]
fn bad_input_is_reported_and_files_are_never_damaged() {
    let (_tmp, urdf, map) = demo_copy();
    let dir = urdf.parent().unwrap().to_path_buf();
    let cases: Vec<(&str, String, &[&str], &str)> = vec![
        ("malformed.urdf", "<robot name=\"r\">\n  <link name=\"a\">\n  </lnk>\n</robot>\n".into(), &[], "malformed.urdf:3:"),
        ("norobot.urdf", "<sdf version=\"1.6\"/>\n".into(), &[], "not a URDF"),
        ("dup.urdf", "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"a\"/>\n</robot>\n".into(), &[], "duplicate link name `a`"),
        ("scale.urdf", "<robot name=\"r\"><link name=\"a\"><collision><geometry><mesh filename=\"../meshes/battery.stl\" scale=\"1 0 1\"/></geometry></collision></link></robot>".into(), &[], "zero factor"),
        ("rpy.urdf", "<robot name=\"r\"><link name=\"a\"><collision><origin rpy=\"0 x 0\"/><geometry><box size=\"1 1 1\"/></geometry></collision></link></robot>".into(), &[], "rpy"),
        ("missing.urdf", "<robot name=\"r\">\n<link name=\"arm\"><collision><geometry><mesh filename=\"package://nope_description/meshes/arm.stl\"/></geometry></collision></link></robot>".into(), &[], "link `arm`: collision 1 (line 2): mesh `package://nope_description/meshes/arm.stl` not found"),
        ("format.urdf", "<robot name=\"r\"><link name=\"a\"><collision><geometry><mesh filename=\"../meshes/part.ply\"/></geometry></collision></link></robot>".into(), &[], "unsupported mesh format `.ply`"),
    ];
    std::fs::write(dir.parent().unwrap().join("meshes/part.ply"), b"ply").unwrap();
    for (name, text, extra, expect) in cases {
        let path = dir.join(name);
        std::fs::write(&path, &text).unwrap();
        let mut args = vec!["fill", path.to_str().unwrap(), "--density", "1000", "-i"];
        args.extend_from_slice(extra);
        let out = run(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
        assert!(
            stderr.contains(expect),
            "{name}: expected `{expect}` in: {stderr}"
        );
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            text,
            "{name} was modified"
        );
    }
    // Bad densities: negative, and a density map with an unknown material (line named).
    let out = run(&["fill", urdf.to_str().unwrap(), "--density", "-3"]);
    assert_eq!(out.status.code(), Some(2));
    let bad_map = dir.join("bad.toml");
    std::fs::write(
        &bad_map,
        "default = 1000\n[links]\nbase_link = \"unobtainium\"\n",
    )
    .unwrap();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        bad_map.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.contains("bad.toml:3: [links] `base_link`: unknown material `unobtainium`"),
        "{stderr}"
    );
    // No density at all for some links: every such link listed.
    let partial = dir.join("partial.toml");
    std::fs::write(&partial, "[links]\nbase_link = \"steel\"\n").unwrap();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        partial.to_str().unwrap(),
        "-o",
        dir.join("out.urdf").to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.contains("no density for 5 link(s)") && stderr.contains("`shoulder_link` (line 25)"),
        "{stderr}"
    );
    // An unwritable output path: exit 2, input untouched.
    let before = std::fs::read(&urdf).unwrap();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "-o",
        "/nonexistent/dir/out.urdf",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read(&urdf).unwrap(), before);
}

#[test]
fn mesh_command_json() {
    let (urdf, _) = demo();
    let stl = urdf
        .parent()
        .unwrap()
        .parent()
        .unwrap()
        .join("meshes/shoulder.STL");
    let out = run(&[
        "mesh",
        stl.to_str().unwrap(),
        "--scale",
        "0.001",
        "0.001",
        "0.001",
        "--mass",
        "2",
        "--format",
        "json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    for key in [
        "volume",
        "mass",
        "center_of_mass",
        "inertia",
        "principal_moments",
        "principal_axes",
        "provenance",
        "warnings",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert!((v["volume"].as_f64().unwrap() - 0.08 * 0.08 * 0.2).abs() < 1e-15);
    assert_eq!(v["mass"].as_f64(), Some(2.0));
    assert_eq!(v["provenance"], "exact");
    let izz = v["inertia"][2][2].as_f64().unwrap();
    assert!((izz - 2.0 * (0.08f64 * 0.08 + 0.08 * 0.08) / 12.0).abs() < 1e-15);
}

fn rpy_of(text: &str, link: &str) -> [f64; 3] {
    let start = text.find(&format!("<link name=\"{link}\"")).expect("link");
    let body = &text[start..];
    let o = body.find("<inertial>").expect("inertial");
    let s = &body[o..];
    let k = s.find("rpy=\"").expect("rpy") + 5;
    let v: Vec<f64> = s[k..k + s[k..].find('"').unwrap()]
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect();
    [v[0], v[1], v[2]]
}

#[test]
fn principal_frame_reproduces_the_tensor() {
    let (urdf, map) = demo();
    let plain = String::from_utf8(
        run(&[
            "fill",
            urdf.to_str().unwrap(),
            "--density-map",
            map.to_str().unwrap(),
        ])
        .stdout,
    )
    .unwrap();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "--principal",
    ]);
    assert!(out.status.success());
    let principal = String::from_utf8(out.stdout).unwrap();
    for link in ["wrist_link", "gripper_link", "base_link"] {
        let (m, c, i) = inertial_of(&plain, link).unwrap();
        let (pm, pc, d) = inertial_of(&principal, link).unwrap();
        assert_eq!((m, c), (pm, pc));
        assert_eq!(
            (d[1], d[2], d[4]),
            (0.0, 0.0, 0.0),
            "{link}: principal tensor must be diagonal"
        );
        // R diag(d) Rᵀ with URDF's fixed-axis rpy gives back the tensor in link axes.
        let r = urdf_inertia::mass::rpy_matrix(rpy_of(&principal, link));
        let dd = [d[0], d[3], d[5]];
        let full = [[i[0], i[1], i[2]], [i[1], i[3], i[4]], [i[2], i[4], i[5]]];
        let norm = i.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for a in 0..3 {
            for b in 0..3 {
                let got: f64 = (0..3).map(|k| r[a][k] * dd[k] * r[b][k]).sum();
                // Both are written within the input's precision (the demo's binary STLs store f32
                // corners, known to 2⁻²⁴ relative): the rpy's rounding moves the tensor by as much.
                assert!(
                    (got - full[a][b]).abs() < 1e-6 * norm,
                    "{link}[{a}][{b}]: {got} vs {}",
                    full[a][b]
                );
            }
        }
    }
}

#[test]
fn digits_round_and_stay_valid() {
    let (_tmp, urdf, map) = demo_copy();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "--digits",
        "4",
        "-i",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&urdf).unwrap();
    let (m, _, _) = inertial_of(&text, "shoulder_link").unwrap();
    assert_eq!(m, 3.456);
    assert!(text.contains("<mass value=\"13.11\"/>"), "{text}");
    let out = run(&["check", urdf.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    // Idempotent with --digits too.
    let before = text.clone();
    run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "--digits",
        "4",
        "-i",
    ]);
    assert_eq!(std::fs::read_to_string(&urdf).unwrap(), before);
}

#[test]
fn selection_options() {
    let (urdf, map) = demo();
    let u = urdf.to_str().unwrap();
    let m = map.to_str().unwrap();
    let only = String::from_utf8(
        run(&[
            "fill",
            u,
            "--density-map",
            m,
            "--only",
            "*arm*",
            "--skip",
            "forearm_link",
        ])
        .stdout,
    )
    .unwrap();
    assert!(inertial_of(&only, "upper_arm_link").is_some());
    assert!(inertial_of(&only, "forearm_link").is_none());
    assert!(inertial_of(&only, "base_link").is_none());
    // --missing-only: a valid existing inertial (even a stale one) stays; missing ones are filled.
    let (_tmp, copy, map2) = demo_copy();
    let text = std::fs::read_to_string(&copy).unwrap().replace(
        "<inertia ixx=\"0.1\" ixy=\"0\" ixz=\"0\" iyy=\"0.1\" iyz=\"0\" izz=\"0.3\"/>",
        "<inertia ixx=\"0.2\" ixy=\"0\" ixz=\"0\" iyy=\"0.2\" iyz=\"0\" izz=\"0.3\"/>",
    );
    std::fs::write(&copy, &text).unwrap();
    let out = run(&[
        "fill",
        copy.to_str().unwrap(),
        "--density-map",
        map2.to_str().unwrap(),
        "--missing-only",
    ]);
    let filled = String::from_utf8(out.stdout).unwrap();
    let (mass, _, _) = inertial_of(&filled, "upper_arm_link").unwrap();
    assert_eq!(
        mass, 1.2,
        "a valid existing inertial is kept with --missing-only"
    );
    assert!(inertial_of(&filled, "base_link").is_some());
}

#[test]
fn keep_mass_and_total_mass() {
    let (urdf, _) = demo();
    let u = urdf.to_str().unwrap();
    // --keep-mass: upper_arm keeps its weighed 1.2 kg; links without a mass need a density (none: error).
    let out = run(&["fill", u, "--keep-mass"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no density for 5 link(s)"));
    let out = run(&["fill", u, "--keep-mass", "--density", "1000"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let (m, c, i) = inertial_of(&text, "upper_arm_link").unwrap();
    assert_eq!(m, 1.2);
    assert!((c[2] - 0.15).abs() < 1e-15);
    // Same shape as at 2700 kg/m³, scaled to 1.2 kg.
    let full = String::from_utf8(run(&["fill", u, "--density", "2700"]).stdout).unwrap();
    let (m2, _, i2) = inertial_of(&full, "upper_arm_link").unwrap();
    // Each written value is the shortest decimal within its error estimate (the mesh's round-off
    // bound, 8.3e-15 by `urdf-inertia mesh`), so they agree within two of those.
    assert!((i[5] - i2[5] * 1.2 / m2).abs() < 2e-14 * i[5]);
    // total_mass: the links sum to it.
    let tmp = tempfile::tempdir().unwrap();
    let map = tmp.path().join("total.toml");
    std::fs::write(&map, "default = 1000\ntotal_mass = 20.0\n").unwrap();
    let out = run(&["fill", u, "--density-map", map.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let sum: f64 = [
        "base_link",
        "shoulder_link",
        "upper_arm_link",
        "forearm_link",
        "wrist_link",
        "gripper_link",
    ]
    .iter()
    .map(|l| inertial_of(&text, l).unwrap().0)
    .sum();
    // Each mass is written within its input's precision (f32 STL corners: 2⁻²⁴ relative, a mass
    // to about 2e-7).
    assert!((sum - 20.0).abs() < 20.0 * 2e-7, "{sum}");
}

#[test]
fn json_summary_names_repairs() {
    let tmp = tempfile::tempdir().unwrap();
    // An inside-out box mesh: the summary must say it was flipped.
    common::inside_out_cube_stl(&tmp.path().join("inside.stl"));
    let urdf = tmp.path().join("r.urdf");
    std::fs::write(&urdf, "<robot name=\"r\">\n  <link name=\"box\">\n    <collision><geometry><mesh filename=\"inside.stl\"/></geometry></collision>\n  </link>\n</robot>\n").unwrap();
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density",
        "1000",
        "-o",
        tmp.path().join("out.urdf").to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["links_filled"], 1);
    assert_eq!(v["links"][0]["parts"][0]["provenance"], "inverted");
    assert_eq!(v["links"][0]["computed"]["mass"].as_f64(), Some(1000.0));
    // Under --strict the same mesh is an error naming link, collision and file.
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density",
        "1000",
        "--strict",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr.contains("link `box`: collision 1 (line 3)")
            && stderr.contains("inside.stl: closed mesh wound inward (an error under --strict)"),
        "{stderr}"
    );
    // The text summary names the repair too, with its code: a note by default, since turning the
    // box outside in is exact (its bound is round-off, below --note-below's 1e-9), a warning with
    // --note-below 0.
    let out = run(&["fill", urdf.to_str().unwrap(), "--density", "1000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("UI101"), "{stderr}");
    let out = run(&["fill", urdf.to_str().unwrap(), "--density", "1000", "-v"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("note[UI101]: inside.stl: inside out: all 12 faces wound inward")
            && stderr.contains("(link `box`, collision 1)"),
        "{stderr}"
    );
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density",
        "1000",
        "--note-below",
        "0",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning[UI101]: inside.stl: inside out: all 12 faces wound inward"),
        "{stderr}"
    );
}

#[test]
fn millimetre_meshes_without_scale_are_flagged() {
    let (_tmp, urdf, _) = demo_copy();
    let text = std::fs::read_to_string(&urdf)
        .unwrap()
        .replace(" scale=\"0.001 0.001 0.001\"", "");
    std::fs::write(&urdf, text).unwrap();
    // By default the link fails (tests/first_hour.rs); accepted, the size stays a warning.
    let out = run(&[
        "fill",
        urdf.to_str().unwrap(),
        "--density",
        "1000",
        "--allow-large-parts",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("warning[UI106]: package://demo_arm_description/meshes/shoulder.STL: closed mesh: the mesh is 229.8 m across: if it was exported in millimetres, give it scale=\"0.001 0.001 0.001\" (link `shoulder_link`, collision 1)"), "{stderr}");
    // diff and check show it too (they compute the same meshes), with the same acceptance; without
    // it the link fails there as well (UI710).
    let (_, map) = demo();
    for command in ["diff", "check"] {
        let out = run(&[
            command,
            urdf.to_str().unwrap(),
            "--density-map",
            map.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{command}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("error[UI710]"));
        let out = run(&[
            command,
            urdf.to_str().unwrap(),
            "--density-map",
            map.to_str().unwrap(),
            "--allow-large-parts",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("warning[UI106]: package://demo_arm_description/meshes/shoulder.STL: closed mesh: the mesh is 229.8 m across"), "{command}: {stderr}");
    }
}

#[test]
fn ros_package_path_and_ament_prefix_path() {
    let (tmp, urdf, _) = demo_copy();
    // The URDF moved far from its package, so walking up cannot find it.
    let far = tempfile::tempdir().unwrap();
    let moved = far.path().join("robot.urdf");
    let text = std::fs::read_to_string(&urdf).unwrap().replace(
        "../meshes/upper_arm.obj",
        "package://demo_arm_description/meshes/upper_arm.obj",
    );
    std::fs::write(&moved, text).unwrap();
    let m = moved.to_str().unwrap();
    let out = bin()
        .args(["fill", m, "--density", "1000"])
        .env_remove("ROS_PACKAGE_PATH")
        .env_remove("AMENT_PREFIX_PATH")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("pass --package-path demo_arm_description=DIR"),
        "{stderr}"
    );
    // ROS 1: a directory holding the package.
    let out = bin()
        .args(["fill", m, "--density", "1000"])
        .env("ROS_PACKAGE_PATH", tmp.path())
        .env_remove("AMENT_PREFIX_PATH")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // ROS 2: PREFIX/share/NAME.
    let prefix = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(prefix.path().join("share")).unwrap();
    std::fs::rename(
        tmp.path().join("demo_arm_description"),
        prefix.path().join("share/demo_arm_description"),
    )
    .unwrap();
    let out = bin()
        .args(["fill", m, "--density", "1000"])
        .env_remove("ROS_PACKAGE_PATH")
        .env("AMENT_PREFIX_PATH", prefix.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn diff_names_origin_and_mirror_mistakes() {
    let tmp = tempfile::tempdir().unwrap();
    // A 1 × 2 × 3 box of 1000 kg/m³ centred at (1, 0, 0): central tensor diag(6500, 5000, 2500) with mass 6000.
    let body = |inertial: &str| {
        format!("<robot name=\"r\"><link name=\"a\"><inertial>{inertial}</inertial><collision><origin xyz=\"1 0 0\"/><geometry><box size=\"1 2 3\"/></geometry></collision></link></robot>")
    };
    // About the link origin instead of the COM: Iyy and Izz grow by m·1².
    let origin = body("<origin xyz=\"1 0 0\"/><mass value=\"6000\"/><inertia ixx=\"6500\" ixy=\"0\" ixz=\"0\" iyy=\"11000\" iyz=\"0\" izz=\"8500\"/>");
    let path = tmp.path().join("origin.urdf");
    std::fs::write(&path, origin).unwrap();
    let out = run(&["diff", path.to_str().unwrap(), "--density", "1000"]);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("about the link origin, not the COM"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    // Products of inertia with mirrored signs: a rotated box whose ixy sign was flipped.
    let text = "<robot name=\"r\"><link name=\"a\"><collision><origin rpy=\"0 0 0.5\"/><geometry><box size=\"1 2 3\"/></geometry></collision></link></robot>";
    let path = tmp.path().join("rot.urdf");
    std::fs::write(&path, text).unwrap();
    let filled =
        String::from_utf8(run(&["fill", path.to_str().unwrap(), "--density", "1000"]).stdout)
            .unwrap();
    let (_, _, i) = inertial_of(&filled, "a").unwrap();
    assert!(i[1].abs() > 1.0);
    let mirrored = filled.replacen(
        &format!("ixy=\"{}\"", urdf_inertia::text::shortest(i[1])),
        &format!("ixy=\"{}\"", urdf_inertia::text::shortest(-i[1])),
        1,
    );
    assert_ne!(mirrored, filled);
    std::fs::write(&path, mirrored).unwrap();
    let out = run(&["diff", path.to_str().unwrap(), "--density", "1000"]);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("products of inertia look mirrored"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
}

/// The diff's table keeps its columns under a link name longer than the link column's 28
/// characters (Robotiq's `robotiq_85_right_inner_knuckle_link` has 35): each number ends where its
/// header does, on every row.
#[test]
fn diff_columns_stay_aligned_under_long_link_names() {
    let tmp = tempfile::tempdir().unwrap();
    let link = |name: &str, inertial: &str| {
        format!("<link name=\"{name}\">{inertial}<collision><geometry><box size=\"1 2 3\"/></geometry></collision></link>")
    };
    // 1 × 2 × 3 at 1000 kg/m³: 6000 kg, central tensor diag(6500, 5000, 2500).
    let weighed = "<inertial><mass value=\"5000\"/><inertia ixx=\"6500\" ixy=\"0\" ixz=\"0\" iyy=\"5000\" iyz=\"0\" izz=\"2500\"/></inertial>";
    let text = format!(
        "<robot name=\"r\">{}{}{}</robot>",
        link("a", weighed),
        link(
            "robotiq_85_right_inner_knuckle_link_of_the_left_hand",
            weighed
        ),
        link("b_without_inertial", "")
    );
    let path = tmp.path().join("long.urdf");
    std::fs::write(&path, text).unwrap();
    let out = run(&["diff", path.to_str().unwrap(), "--density", "1000"]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    let header = lines[0];
    let end = |h: &str| header.find(h).unwrap() + h.len();
    let rows: Vec<&str> = lines[1..]
        .iter()
        .copied()
        .filter(|l| !l.starts_with(' '))
        .collect();
    assert_eq!(rows.len(), 3, "{stdout}");
    for row in rows {
        // The byte where each number ends: the existing and computed masses, and the ratio.
        for (h, value) in [
            (
                "existing kg",
                if row.starts_with("b_") { "-" } else { "5000" },
            ),
            ("computed kg", "6000"),
            ("ratio", if row.starts_with("b_") { "-" } else { "0.8333" }),
        ] {
            let at = end(h);
            assert_eq!(
                &row[at - value.len()..at],
                value,
                "{h} in {row:?}\n{stdout}"
            );
            assert!(row[at..].starts_with(' '), "{h} in {row:?}\n{stdout}");
        }
    }
}

/// Regression: `-i` on a symlinked URDF once replaced the link with a regular file.
#[cfg(unix)]
/// What a pre-commit fixing hook runs: several URDFs in place in one process. Each file ends as a
/// fill of it alone would leave it; a file that cannot be read fails alone (exit 2), the rest are
/// written; without -i, or with --format json, several files are refused before anything is read.
#[test]
fn several_urdfs_fill_in_place_in_one_process() {
    let (_tmp, urdf, map) = demo_copy();
    let (_tmp2, alone, _) = demo_copy();
    let second = urdf.with_file_name("second.urdf");
    std::fs::copy(&urdf, &second).unwrap();
    let original = std::fs::read(&urdf).unwrap();
    fill_in_place(&alone, &map);
    let want = std::fs::read(&alone).unwrap();
    for extra in [None, Some("/nonexistent/robot.urdf")] {
        std::fs::write(&urdf, &original).unwrap();
        std::fs::write(&second, &original).unwrap();
        let mut args = vec!["fill", urdf.to_str().unwrap(), second.to_str().unwrap()];
        args.extend(extra);
        args.extend(["--density-map", map.to_str().unwrap(), "-i"]);
        let out = run(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(if extra.is_some() { 2 } else { 0 }),
            "{stderr}"
        );
        assert_eq!(std::fs::read(&urdf).unwrap(), want);
        assert_eq!(std::fs::read(&second).unwrap(), want);
        // Each summary names its file, and counts the meshes the second robot uses though the
        // first one read them.
        assert!(
            stderr.contains(&format!(
                "urdf-inertia: {}: robot `demo_arm`: filled 6 link(s) (9 parts, 5 mesh files, 52 faces)",
                second.display()
            )),
            "{stderr}"
        );
    }
    for refused in [
        vec!["--density", "1000"],
        vec!["--density", "1000", "-i", "--format", "json"],
    ] {
        std::fs::write(&urdf, &original).unwrap();
        let mut args = vec!["fill", urdf.to_str().unwrap(), second.to_str().unwrap()];
        args.extend(refused);
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).starts_with("error: "));
        assert!(out.stdout.is_empty());
        assert_eq!(std::fs::read(&urdf).unwrap(), original);
    }
}

#[test]
fn in_place_through_a_symlink_keeps_the_link() {
    let (_tmp, urdf, map) = demo_copy();
    let link = urdf.with_file_name("linked.urdf");
    std::os::unix::fs::symlink(&urdf, &link).unwrap();
    fill_in_place(&link, &map);
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(inertial_of(&std::fs::read_to_string(&urdf).unwrap(), "base_link").is_some());
}

#[test]
fn overlapping_parts_are_reported_with_the_doubly_counted_volume() {
    let tmp = tempfile::tempdir().unwrap();
    // Two unit cubes overlapping by half (0.5 m³), and a sphere with a small box in its bounding box's
    // corner but outside the sphere (no overlap).
    let text = "<robot name=\"r\">\n<link name=\"cubes\">\n<collision><geometry><box size=\"1 1 1\"/></geometry></collision>\n<collision><origin xyz=\"0.5 0 0\"/><geometry><box size=\"1 1 1\"/></geometry></collision>\n</link>\n<link name=\"ball\">\n<collision><geometry><sphere radius=\"1\"/></geometry></collision>\n<collision><origin xyz=\"0.9 0.9 0.9\"/><geometry><box size=\"0.2 0.2 0.2\"/></geometry></collision>\n</link>\n</robot>\n";
    let path = tmp.path().join("r.urdf");
    std::fs::write(&path, text).unwrap();
    let out = run(&["fill", path.to_str().unwrap(), "--density", "1000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("warning[UI401]: link `cubes`: parts 1 and 2 overlap: about 0.5 m³ (25.0% of the link's volume) is counted twice"), "{stderr}");
    // The summary's worst error estimate is the overlap, not the primitives' round-off: 0.5 m³ of
    // the parts' 2 m³. The total mass: 2 m³ of cubes and a 4/3·π m³ ball with a 0.008 m³ box.
    assert!(stderr.contains("worst error estimate: 25.0% of link `cubes`'s volume, counted more than once where its parts 1 and 2 overlap (UI401)"), "{stderr}");
    let total = 1000.0 * (2.0 + 4.0 / 3.0 * PI + 0.008);
    let line = stderr
        .lines()
        .find(|l| l.contains("total mass: "))
        .expect("total mass line");
    let got: f64 = line
        .split_whitespace()
        .nth(2)
        .expect("value")
        .parse()
        .expect("number");
    assert!(
        (got - total).abs() <= 1e-5 * total,
        "{line} against {total}"
    );
    assert!(!stderr.contains("link `ball`: parts"), "{stderr}");
}

/// A robot of four links sharing one inside-out cube mesh, in `dir` (a `.git` there makes it a
/// repository root for the configuration file's search).
fn shared_mesh_robot(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir.join(".git")).unwrap();
    common::inside_out_cube_stl(&dir.join("cube.stl"));
    let links = ["a", "b", "c", "d"].iter().fold(String::new(), |mut s, l| {
        let _ = write!(s, "  <link name=\"{l}\">\n    <collision><geometry><mesh filename=\"cube.stl\"/></geometry></collision>\n  </link>\n");
        s
    });
    let text = format!("<robot name=\"r\">\n{links}</robot>\n");
    let urdf = dir.join("r.urdf");
    std::fs::write(&urdf, text).unwrap();
    urdf
}

fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

// A mesh shared by four links is reported once by fill, diff and check (the first hour: diff and
// check printed no mesh warning, fill printed one per link).
#[test]
fn mesh_warnings_once_per_file_in_fill_diff_and_check() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = shared_mesh_robot(tmp.path());
    let u = urdf.to_str().unwrap();
    let once = "warning[UI101]: cube.stl: inside out: all 12 faces wound inward (negative volume); flipped (4 links: `a` collision 1, `b` collision 1, `c` collision 1, `d` collision 1)";
    for command in ["fill", "diff", "check"] {
        let out = run(&[command, u, "--density", "1000", "--note-below", "0"]);
        let stderr = stderr_of(&out);
        assert_eq!(stderr.matches("[UI101]").count(), 1, "{command}: {stderr}");
        assert!(stderr.contains(once), "{command}: {stderr}");
    }
    // JSON: one entry naming the four links.
    let out = run(&[
        "diff",
        u,
        "--density",
        "1000",
        "--note-below",
        "0",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    let d = v["mesh_diagnostics"].as_array().expect("array");
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0]["code"], "UI101");
    assert_eq!(d[0]["severity"], "warning");
    assert_eq!(d[0]["links"].as_array().map(Vec::len), Some(4));
    // Four unit cubes of 1000 kg/m³.
    assert_eq!(v["total_mass"].as_f64(), Some(4000.0));
    // By default the exact repair is a note: printed with -v only.
    let out = run(&["diff", u, "--density", "1000"]);
    assert!(!stderr_of(&out).contains("UI101"), "{}", stderr_of(&out));
    let out = run(&["diff", u, "--density", "1000", "-v"]);
    assert!(stderr_of(&out).contains("note[UI101]: cube.stl"));
}

#[test]
fn quiet_ignore_and_warn_as_error() {
    let tmp = tempfile::tempdir().unwrap();
    let urdf = shared_mesh_robot(tmp.path());
    let u = urdf.to_str().unwrap();
    let out_file = tmp.path().join("out.urdf");
    let o = out_file.to_str().unwrap();
    let fill = |extra: &[&str]| {
        let mut args = vec!["fill", u, "--density", "1000", "--note-below", "0", "-o", o];
        args.extend(extra);
        run(&args)
    };
    // --quiet: no warnings, no summary.
    let out = fill(&["-q"]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(stderr_of(&out), "");
    // --ignore: that code is gone, the summary stays.
    let out = fill(&["--ignore", "UI102,UI101"]);
    assert!(!stderr_of(&out).contains("UI101"), "{}", stderr_of(&out));
    assert!(
        stderr_of(&out).contains("total mass: 4000 kg"),
        "{}",
        stderr_of(&out)
    );
    // --warn-as-error: fill writes nothing and exits 2.
    std::fs::remove_file(&out_file).unwrap();
    let out = fill(&["--warn-as-error", "UI101"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("error[UI101]: cube.stl: inside out"));
    assert!(stderr_of(&out).contains("nothing written"));
    assert!(!out_file.exists());
    // check on the filled robot: clean, unless the warning is an error.
    fill(&[]);
    let check = |extra: &[&str], dir: &Path| {
        let mut args = vec!["check", o, "--density", "1000", "--note-below", "0"];
        args.extend(extra);
        bin().args(&args).current_dir(dir).output().unwrap()
    };
    assert_eq!(check(&[], tmp.path()).status.code(), Some(0));
    assert_eq!(
        check(&["--warn-as-error", "UI101"], tmp.path())
            .status
            .code(),
        Some(1)
    );
    // Unknown codes and errors are refused.
    let out = check(&["--ignore", "UI999"], tmp.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr_of(&out).contains("unknown code `UI999`"));
    let out = check(&["--ignore", "UI702"], tmp.path());
    assert_eq!(out.status.code(), Some(2));
    // The same in urdf-inertia.toml, found from a subdirectory up to the repository root.
    std::fs::write(
        tmp.path().join("urdf-inertia.toml"),
        "warn-as-error = [\"UI101\"]\n",
    )
    .unwrap();
    let sub = tmp.path().join("sub/dir");
    std::fs::create_dir_all(&sub).unwrap();
    let out = check(&[], &sub);
    assert_eq!(out.status.code(), Some(1), "{}", stderr_of(&out));
    assert!(stderr_of(&out).contains("error[UI101]"));
    assert_eq!(check(&["--no-config"], &sub).status.code(), Some(0));
    // From elsewhere (no configuration there), it is found from the input file's directory.
    let elsewhere = tempfile::tempdir().unwrap();
    assert_eq!(check(&[], elsewhere.path()).status.code(), Some(1));
    // A mistyped key names the file and the keys.
    std::fs::write(
        tmp.path().join("urdf-inertia.toml"),
        "ignroe = [\"UI101\"]\n",
    )
    .unwrap();
    let out = check(&[], &sub);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr_of(&out).contains("urdf-inertia.toml")
            && stderr_of(&out).contains("ignore, warn-as-error, note-below"),
        "{}",
        stderr_of(&out)
    );
}

#[test]
fn colours_on_request_only_and_never_in_json() {
    let (urdf, map) = demo();
    let args = [
        "diff",
        urdf.to_str().unwrap(),
        "--density-map",
        map.to_str().unwrap(),
        "-v",
    ];
    // Through a pipe: plain text with the codes.
    let out = run(&args);
    assert!(stderr_of(&out)
        .contains("note[UI105]: ../meshes/upper_arm.obj: closed mesh: 2 objects/groups"));
    assert!(!stderr_of(&out).contains('\x1b'));
    let forced = bin()
        .args(args)
        .env("CLICOLOR_FORCE", "1")
        .env_remove("NO_COLOR")
        .output()
        .unwrap();
    assert!(
        stderr_of(&forced).contains("\x1b[1;32mnote[UI105]\x1b[0m: ../meshes/upper_arm.obj"),
        "{}",
        stderr_of(&forced)
    );
    assert!(!String::from_utf8_lossy(&forced.stdout).contains('\x1b'));
    let no_color = bin()
        .args(args)
        .env("CLICOLOR_FORCE", "1")
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    assert!(!stderr_of(&no_color).contains('\x1b'));
    let mut json = args.to_vec();
    json.extend(["--format", "json"]);
    let out = bin()
        .args(&json)
        .env("CLICOLOR_FORCE", "1")
        .output()
        .unwrap();
    assert!(!String::from_utf8_lossy(&out.stdout).contains('\x1b'));
    serde_json::from_slice::<serde_json::Value>(&out.stdout).expect("json");
}

// Adopting the check on a repository with known problems: record them, then only new ones fail.
#[test]
#[allow(clippy::too_many_lines)] // one adoption scenario checked step by step
fn check_baseline_fails_only_on_new_problems() {
    let (tmp, urdf, _) = demo_copy();
    let root = tmp.path().join("demo_arm_description");
    let check = |extra: &[&str]| {
        let mut args = vec!["check", "urdf/demo_arm.urdf"];
        args.extend(extra);
        bin().args(&args).current_dir(&root).output().unwrap()
    };
    // Without a baseline the first failure says how to adopt the check.
    let out = check(&[]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains(
        "demo_arm.urdf:5: link `base_link`: has collision geometry but no <inertial> [UI601]"
    ));
    assert!(stderr_of(&out).contains("--write-baseline") && stderr_of(&out).contains("--skip"));
    // --ignore selects problems too: only the invalid upper arm is left.
    let out = check(&["--ignore", "UI601"]);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert!(
        stdout.contains("link `upper_arm_link`: ") && stdout.ends_with("[UI602]\n"),
        "{stdout}"
    );
    // --quiet keeps the problems and their count, not the advice.
    let out = check(&["-q"]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 6);
    assert!(!stderr_of(&out).contains("help:"), "{}", stderr_of(&out));
    // Record: exit 0, one sorted line per problem (5 links without <inertial>, 1 invalid).
    let out = check(&["--write-baseline", "known.txt"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr_of(&out));
    let text = std::fs::read_to_string(root.join("known.txt")).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(lines.len(), 6, "{text}");
    let mut sorted = lines.clone();
    sorted.sort_unstable();
    assert_eq!(lines, sorted);
    assert!(
        lines.contains(
            &"urdf/demo_arm.urdf\tbase_link\tUI601\thas collision geometry but no <inertial>"
        ),
        "{text}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("urdf/demo_arm.urdf\tupper_arm_link\tUI602\t")),
        "{text}"
    );
    // Old problems pass.
    let out = check(&["--baseline", "known.txt"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr_of(&out));
    assert_eq!(String::from_utf8_lossy(&out.stdout), "");
    // A new one fails, and is the only one printed.
    let text = std::fs::read_to_string(&urdf).unwrap().replace(
        "</robot>",
        "  <link name=\"extra\">\n    <collision><geometry><box size=\"1 1 1\"/></geometry></collision>\n  </link>\n</robot>",
    );
    std::fs::write(&urdf, text).unwrap();
    let out = check(&["--baseline", "known.txt"]);
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert!(
        stdout.contains("link `extra`: has collision geometry but no <inertial> [UI601]"),
        "{stdout}"
    );
    assert!(
        stderr_of(&out)
            .contains("6 problem(s) recorded in the baseline known.txt (not failing), 1 new"),
        "{}",
        stderr_of(&out)
    );
    // Fixing a recorded problem is said, and passes.
    let out = check(&[
        "--baseline",
        "known.txt",
        "--skip",
        "extra",
        "--skip",
        "base_link",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr_of(&out));
    assert!(
        stderr_of(&out).contains("1 problem(s) of the baseline known.txt are gone"),
        "{}",
        stderr_of(&out)
    );
    // From the configuration file as well.
    std::fs::write(root.join("urdf-inertia.toml"), "baseline = \"known.txt\"\n").unwrap();
    let out = check(&[]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 1);
    // --baseline FILE --update records the new problem too: then nothing fails.
    let out = check(&["--baseline", "known.txt", "--update"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr_of(&out));
    assert_eq!(check(&[]).status.code(), Some(0));
}

/// `check --format json` (what CI consumes): the same problems as the text lines, each with its
/// file, link, code and message, and the counts; exit code as in text.
#[test]
fn check_format_json_lists_the_problems_of_the_text_output() {
    let (urdf, _) = demo();
    let u = urdf.to_str().unwrap();
    let text = run(&["check", u]);
    let json = run(&["check", u, "--format", "json"]);
    assert_eq!(text.status.code(), Some(1));
    assert_eq!(json.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).expect("JSON on stdout");
    assert_eq!(v["schema_version"], 1);
    // One record per link (the shape `fill` and `diff` use), each with its problems.
    let links = v["links"].as_array().expect("links");
    let problems: Vec<&serde_json::Value> = links
        .iter()
        .flat_map(|l| {
            let p = l["problems"].as_array().expect("problems");
            assert!(!p.is_empty(), "{l}");
            p.iter().inspect(move |p| {
                assert!(p["at"]
                    .as_str()
                    .unwrap()
                    .contains(&format!("link `{}`", l["link"].as_str().unwrap())));
            })
        })
        .collect();
    let mut lines: Vec<String> = String::from_utf8_lossy(&text.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    assert_eq!(problems.len(), lines.len());
    assert_eq!(v["problem_count"], lines.len());
    let mut rebuilt: Vec<String> = problems
        .iter()
        .map(|p| {
            format!(
                "{}: {} [{}]",
                p["at"].as_str().unwrap(),
                p["message"].as_str().unwrap(),
                p["code"].as_str().unwrap()
            )
        })
        .collect();
    // JSON groups them by link, text prints them in the order found: compared as sets.
    rebuilt.sort();
    lines.sort();
    assert_eq!(rebuilt, lines);
    // The demo's upper arm carries a tensor that breaks the triangle inequality (0.1, 0.1, 0.3),
    // typed: the kind and the principal moments, on the line of its <inertial>.
    let upper_link = links
        .iter()
        .find(|l| l["link"] == "upper_arm_link")
        .expect("the upper arm");
    // Without densities nothing is computed; the existing values are there as read.
    assert!(upper_link["computed"].is_null());
    assert_eq!(upper_link["existing"]["mass"].as_f64(), Some(1.2));
    let upper = upper_link["problems"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["code"] == "UI602")
        .expect("the upper arm's problem");
    assert_eq!(upper["kind"], "invalid_tensor");
    let broken = &upper["violation"]["triangle_inequality"];
    assert_eq!(broken["moments"], serde_json::json!([0.1, 0.1, 0.3]));
    assert!(upper["line"].as_u64().is_some_and(|l| l > 0));
    assert!(upper["at"]
        .as_str()
        .unwrap()
        .ends_with(&format!(":{}: link `upper_arm_link`", upper["line"])));
}

/// An `<inertial>` that already says what `fill` computes (each number within the tolerance it
/// would round within) keeps its bytes: the demo filled with every bit (`--digits full`), filled
/// again with the default digits, is the same file, where the default would write shorter
/// decimals. One that disagrees beyond that tolerance (a mass 0.1% off) is rewritten.
#[test]
fn fill_keeps_an_inertial_that_already_agrees() {
    let (_tmp, copy, map) = demo_copy();
    let (u, m) = (copy.to_str().unwrap(), map.to_str().unwrap());
    // The default digits are shorter than every bit for this link.
    let fresh = String::from_utf8(run(&["fill", u, "--density-map", m, "-o", "-"]).stdout).unwrap();
    assert!(fresh.contains("izz=\"0.0022447378466093\""), "{fresh}");
    let full = run(&["fill", u, "--density-map", m, "--digits", "full", "-i"]);
    assert!(full.status.success());
    let before = std::fs::read_to_string(&copy).unwrap();
    assert!(before.contains("izz=\"0.002244737846609265\""), "{before}");
    let again = run(&["fill", u, "--density-map", m, "-i"]);
    assert!(again.status.success());
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), before);
    // A mass 0.1% off is no longer what `fill` computes: that link is rewritten, only that one.
    let (mass, _, _) = inertial_of(&before, "upper_arm_link").unwrap();
    let off = before.replacen(
        &format!("<mass value=\"{}\"", urdf_inertia::text::shortest(mass)),
        &format!("<mass value=\"{}\"", mass * 1.001),
        1,
    );
    assert_ne!(off, before);
    std::fs::write(&copy, &off).unwrap();
    assert!(run(&["fill", u, "--density-map", m, "-i"]).status.success());
    let after = std::fs::read_to_string(&copy).unwrap();
    let (fixed, _, _) = inertial_of(&after, "upper_arm_link").unwrap();
    assert!((fixed - mass).abs() <= 1e-12 * mass, "{fixed} {mass}");
    let changed = after
        .lines()
        .zip(before.lines())
        .filter(|(a, b)| a != b)
        .count();
    assert!((1..=3).contains(&changed), "{changed} lines changed");
}

/// A capsule about its centre, along `axis` (0, 1 or 2): cylinder of radius `r` and length `l`
/// (mass `mc`) plus a ball of radius `r` (mass `ms`) split over its ends, density `rho`; the
/// textbook formula: `mc (l²/12 + r²/4) + ms (2r²/5 + l²/4 + 3lr/8)` across, `mc r²/2 + 2 ms r²/5`
/// along.
fn capsule_i(rho: f64, r: f64, l: f64, axis: usize) -> (f64, [f64; 6]) {
    let (mc, ms) = (rho * PI * r * r * l, rho * 4.0 / 3.0 * PI * r * r * r);
    let across =
        mc * (l * l / 12.0 + r * r / 4.0) + ms * (0.4 * r * r + l * l / 4.0 + 0.375 * l * r);
    let along = mc * r * r / 2.0 + ms * 0.4 * r * r;
    let mut d = [across; 3];
    d[axis] = along;
    (mc + ms, [d[0], 0.0, 0.0, d[1], 0.0, d[2]])
}

/// One link of collisions (origin xyz, rpy, geometry element).
fn collisions_link(name: &str, parts: &[(&str, &str, &str)]) -> String {
    let mut text = format!("<link name=\"{name}\">\n");
    for (xyz, rpy, g) in parts {
        let c = format!("<collision><origin xyz=\"{xyz}\" rpy=\"{rpy}\"/><geometry>{g}</geometry></collision>\n");
        text.push_str(&c);
    }
    text + "</link>\n"
}

/// Links of a cylinder with spheres of its radius on its ends (capsules), and three that are not.
fn capsule_links() -> String {
    let cyl = |r: f64, l: f64| format!("<cylinder radius=\"{r}\" length=\"{l}\"/>");
    let ball = |r: f64| format!("<sphere radius=\"{r}\"/>");
    [
        // example-robot-data's panda_link1, its sphere centres as the file writes them (3e-17 m
        // from the ends as f64 computes them).
        collisions_link(
            "panda",
            &[
                ("0 0 -0.1915", "0 0 0", &cyl(0.09, 0.283)),
                ("0 0 -0.05000000000000002", "0 0 0", &ball(0.09)),
                ("0 0 -0.33299999999999996", "0 0 0", &ball(0.09)),
            ],
        ),
        // Franka's collision_capsule macro along x (pitch π/2), spheres listed first.
        collisions_link(
            "along_x",
            &[
                ("-0.06 0 0.06", "0 0 0", &ball(0.06)),
                ("-0.09 0 0.06", "0 0 0", &ball(0.06)),
                ("-0.075 0 0.06", "0 1.5707963267948966 0", &cyl(0.06, 0.03)),
            ],
        ),
        // Shorter than its radius: the spheres overlap each other, and the union is still the capsule.
        collisions_link(
            "short",
            &[
                ("1 2 3", "0 0 0", &cyl(1.0, 0.5)),
                ("1 2 3.25", "0 0 0", &ball(1.0)),
                ("1 2 2.75", "0 0 0", &ball(1.0)),
            ],
        ),
        // π/2 written as 1.57: the ends are 6e-5 m from the spheres, which stay parts of their own.
        collisions_link(
            "sloppy",
            &[
                ("0 0 0.03", "1.57 0 0", &cyl(0.05, 0.15)),
                ("0 -0.075 0.03", "0 0 0", &ball(0.05)),
                ("0 0.075 0.03", "0 0 0", &ball(0.05)),
            ],
        ),
        // A capsule and a box through its middle: their overlap is the capsule's with the box.
        collisions_link(
            "with_box",
            &[
                ("0 0 0", "0 0 0", &cyl(0.1, 0.4)),
                ("0 0 0.2", "0 0 0", &ball(0.1)),
                ("0 0 -0.2", "0 0 0", &ball(0.1)),
                ("0 0 0", "0 0 0", "<box size=\"0.5 0.05 0.05\"/>"),
            ],
        ),
        // One sphere: not a capsule.
        collisions_link(
            "one_end",
            &[
                ("0 0 0", "0 0 0", &cyl(0.1, 0.4)),
                ("0 0 0.2", "0 0 0", &ball(0.1)),
            ],
        ),
    ]
    .concat()
}

/// `fill` of a robot of `links` with `args`: the filled URDF and the summary.
fn fill_links(links: &str, args: &[&str]) -> (String, String) {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("c.urdf");
    std::fs::write(&path, format!("<robot name=\"c\">\n{links}</robot>\n")).unwrap();
    let mut all = vec!["fill", path.to_str().unwrap()];
    all.extend(args);
    let out = run(&all);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    (String::from_utf8(out.stdout).unwrap(), stderr)
}

#[test]
fn a_cylinder_with_a_sphere_on_each_end_is_its_capsule() {
    let (filled, stderr) = fill_links(&capsule_links(), &["--density", "1000", "--verbose"]);
    for (name, centre, r, l, axis) in [
        ("panda", [0.0, 0.0, -0.1915], 0.09, 0.283, 2),
        ("along_x", [-0.075, 0.0, 0.06], 0.06, 0.03, 0),
        ("short", [1.0, 2.0, 3.0], 1.0, 0.5, 2),
    ] {
        let (m, i) = capsule_i(1000.0, r, l, axis);
        assert_inertial(&filled, name, m, centre, i, 1e-12);
        assert!(
            stderr.contains(&format!(
                "note[UI402]: link `{name}`: collisions 1, 2 and 3 are a capsule"
            )),
            "{stderr}"
        );
        assert!(
            !stderr.contains(&format!("link `{name}`: parts")),
            "{stderr}"
        );
    }
    // Not capsules: the parts summed, their overlap counted twice and said (UI401).
    let sphere_mass = |r: f64| 1000.0 * 4.0 / 3.0 * PI * r * r * r;
    let cyl_mass = |r: f64, l: f64| 1000.0 * PI * r * r * l;
    let (m, _, _) = inertial_of(&filled, "sloppy").unwrap();
    close(
        m,
        cyl_mass(0.05, 0.15) + 2.0 * sphere_mass(0.05),
        1e-12,
        m,
        "sloppy mass",
    );
    assert!(
        stderr.contains("warning[UI401]: link `sloppy`: parts 1, 2 and 3 overlap"),
        "{stderr}"
    );
    assert!(stderr.contains("collisions 1, 2 and 3 are nearly a capsule: its spheres miss the cylinder's end centres (or radius) by up to 6e-5 m"), "{stderr}");
    let (m, _, _) = inertial_of(&filled, "one_end").unwrap();
    close(
        m,
        cyl_mass(0.1, 0.4) + sphere_mass(0.1),
        1e-12,
        m,
        "one_end mass",
    );
    assert!(
        stderr.contains("warning[UI401]: link `one_end`: parts 1 and 2 overlap"),
        "{stderr}"
    );
    assert!(!stderr.contains("link `one_end`: collisions"), "{stderr}");
    // The box's middle, inside the capsule's cylinder, counts twice: the capsule is named with its
    // three collisions.
    assert!(
        stderr.contains(
            "warning[UI401]: link `with_box`: parts 1 (a capsule with 2 and 3) and 4 overlap"
        ),
        "{stderr}"
    );
}

#[test]
fn a_kept_mass_is_spread_over_a_capsule() {
    // The capsule's shape at 3 kg: the mass over the union's volume, not the parts'.
    let kept = capsule_links().replacen("</link>", "<inertial><mass value=\"3\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>\n</link>", 1);
    let (filled, _) = fill_links(&kept, &["--keep-mass", "--density", "1000"]);
    let (m, i) = capsule_i(1000.0, 0.09, 0.283, 2);
    assert_inertial(
        &filled,
        "panda",
        3.0,
        [0.0, 0.0, -0.1915],
        i.map(|x| x * 3.0 / m),
        1e-12,
    );
}

#[test]
fn a_capsule_whose_spheres_miss_by_rounding_is_within_its_estimate() {
    // Radius 1, length 2: the top sphere's radius 5e-10 too large, the bottom one's centre 5e-10
    // beyond its end. The union's volume in closed form: the cylinder, each ball, less each ball's
    // part inside the cylinder (the top ball's, whose radius exceeds the cylinder's, clipped to it;
    // the bottom ball's a cap of height 1 − 5e-10).
    let (r, l, rs, d) = (1.0f64, 2.0f64, 1.000_000_000_5f64, 5e-10f64);
    let sphere = |xyz: &str, r: f64| (xyz.to_string(), format!("<sphere radius=\"{r}\"/>"));
    let (top, bottom) = (sphere("0 0 1", rs), sphere(&format!("0 0 {}", -1.0 - d), r));
    let link = collisions_link(
        "a",
        &[
            ("0 0 0", "0 0 0", "<cylinder radius=\"1\" length=\"2\"/>"),
            (&top.0, "0 0 0", &top.1),
            (&bottom.0, "0 0 0", &bottom.1),
        ],
    );
    let z0 = (rs * rs - r * r).sqrt();
    let top_inside = PI * r * r * z0
        + PI * ((rs * rs * rs - rs.powi(3) / 3.0) - (rs * rs * z0 - z0.powi(3) / 3.0));
    let bottom_inside = PI * (r - d).powi(2) * (2.0 * r + d) / 3.0;
    let union =
        PI * r * r * l + 4.0 / 3.0 * PI * (rs.powi(3) + r.powi(3)) - top_inside - bottom_inside;
    let tmp = tempfile::tempdir().unwrap();
    let (path, out) = (tmp.path().join("a.urdf"), tmp.path().join("out.urdf"));
    std::fs::write(&path, format!("<robot name=\"a\">\n{link}</robot>\n")).unwrap();
    let o = run(&[
        "fill",
        path.to_str().unwrap(),
        "--density",
        "1",
        "--digits",
        "full",
        "--format",
        "json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let link = &json["links"][0];
    let (ours, estimate) = (
        link["computed"]["mass"].as_f64().unwrap(),
        link["error_estimate"].as_f64().unwrap(),
    );
    let error = (ours - union).abs() / union;
    assert!(
        error <= estimate && estimate < 1e-7,
        "error {error:e}, estimate {estimate:e}"
    );
    assert!(link["notes"].to_string().contains("UI402"), "{link}");
}
