//! Issue 11: the real binary reads every URDF the way urdfdom (ROS, Gazebo, `MoveIt`, pinocchio) reads it,
//! and one bad link does not cost the rest of the robot. Fixtures are written here, in a temp dir.

use std::path::{Path, PathBuf};
use std::process::Output;

fn run(args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(args)
        .output()
        .expect("run urdf-inertia")
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write fixture");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// The text of link `name`, from `<link name="NAME"` to its `</link>`.
fn link_body<'a>(text: &'a str, name: &str) -> &'a str {
    let start = text
        .find(&format!("<link name=\"{name}\""))
        .unwrap_or_else(|| panic!("no link {name}"));
    let end = start + text[start..].find("</link>").expect("</link>");
    &text[start..end]
}

/// A number attribute `key` of the first `<tag …>` in `body`.
fn attr(body: &str, tag: &str, key: &str) -> f64 {
    let t = body.find(&format!("<{tag} ")).expect("tag");
    let rest = &body[t..];
    let k = rest.find(&format!(" {key}=\"")).expect("key") + key.len() + 3;
    let v = &rest[k..];
    v[..v.find('"').expect("quote")].parse().expect("number")
}

/// A three-number attribute `key` of the first `<tag …>` in `body`.
fn attr3(body: &str, tag: &str, key: &str) -> [f64; 3] {
    let t = body.find(&format!("<{tag} ")).expect("tag");
    let rest = &body[t..];
    let k = rest.find(&format!(" {key}=\"")).expect("key") + key.len() + 3;
    let v = &rest[k..];
    let n: Vec<f64> = v[..v.find('"').expect("quote")]
        .split_whitespace()
        .map(|x| x.parse().expect("number"))
        .collect();
    [n[0], n[1], n[2]]
}

fn close(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-12 * want.abs().max(1e-300),
        "{what}: got {got}, want {want}"
    );
}

/// Mass and diagonal of a solid box of density `rho` (about its centre).
fn box_props(rho: f64, [x, y, z]: [f64; 3]) -> (f64, [f64; 3]) {
    let m = rho * x * y * z;
    (
        m,
        [
            m * (y * y + z * z) / 12.0,
            m * (x * x + z * z) / 12.0,
            m * (x * x + y * y) / 12.0,
        ],
    )
}

fn assert_box(body: &str, rho: f64, size: [f64; 3], com: [f64; 3]) {
    let (m, d) = box_props(rho, size);
    close(attr(body, "mass", "value"), m, "mass");
    let c = attr3(body, "origin", "xyz");
    for k in 0..3 {
        assert!((c[k] - com[k]).abs() <= 1e-15, "com {c:?}, want {com:?}");
    }
    close(attr(body, "inertia", "ixx"), d[0], "ixx");
    close(attr(body, "inertia", "iyy"), d[1], "iyy");
    close(attr(body, "inertia", "izz"), d[2], "izz");
    for k in ["ixy", "ixz", "iyz"] {
        assert_eq!(attr(body, "inertia", k), 0.0, "{k}");
    }
}

const DUPLICATE_INERTIALS: &str = "<?xml version=\"1.0\"?>
<robot name=\"dup\">
  <!-- the second inertial is what a careless merge leaves behind -->
  <link name=\"a\">
    <inertial>
      <mass value=\"1\"/>
      <inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>
    </inertial>
    <collision>
      <geometry><box size=\"1 2 3\"/></geometry>
    </collision>
    <inertial>
      <mass value=\"2\"/>
      <inertia ixx=\"2\" ixy=\"0\" ixz=\"0\" iyy=\"2\" iyz=\"0\" izz=\"2\"/>
    </inertial>
  </link>
  <link name=\"frame\">
    <inertial><mass value=\"0\"/><inertia ixx=\"0\" ixy=\"0\" ixz=\"0\" iyy=\"0\" iyz=\"0\" izz=\"0\"/></inertial>
    <inertial><mass value=\"3\"/><inertia ixx=\"3\" ixy=\"0\" ixz=\"0\" iyy=\"3\" iyz=\"0\" izz=\"3\"/></inertial>
  </link>
</robot>
";

// Issue 11: urdfdom reads the first <inertial>; fill leaves exactly one (the computed one), check flags it.
#[test]
fn duplicate_inertials_are_replaced_by_one_and_flagged() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let urdf = write(tmp.path(), "dup.urdf", DUPLICATE_INERTIALS);
    let out = run(&["check", s(&urdf)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    assert!(
        stdout.contains("dup.urdf:5: link `a`: 2 <inertial> elements: urdfdom reads the first (line 5) and ignores the rest (line 12)"),
        "{stdout}"
    );
    // Also on a link without collision geometry, whose values are not judged without --all-links.
    assert!(
        stdout.contains("dup.urdf:18: link `frame`: 2 <inertial> elements"),
        "{stdout}"
    );

    let filled = tmp.path().join("filled.urdf");
    let out = run(&["fill", s(&urdf), "--density", "1000", "-o", s(&filled)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning[UI201]: ") && stderr.contains("dup.urdf:12: link `a`: a second <inertial> is ignored (urdfdom reads the first, on line 5)"),
        "{stderr}"
    );
    let text = std::fs::read_to_string(&filled).expect("filled");
    let a = link_body(&text, "a");
    assert_eq!(a.matches("<inertial").count(), 1, "{a}");
    assert_box(a, 1000.0, [1.0, 2.0, 3.0], [0.0; 3]);
    // Byte-identical apart from the new inertial and the removed duplicate (with its lines).
    let new_start = text.find("    <inertial>").expect("new");
    let new_end = text.find("</inertial>").expect("end") + "</inertial>".len();
    let orig_start = DUPLICATE_INERTIALS.find("    <inertial>").expect("old");
    let orig_end = DUPLICATE_INERTIALS.find("</inertial>").expect("end") + "</inertial>".len();
    let dup = "    <inertial>\n      <mass value=\"2\"/>\n      <inertia ixx=\"2\" ixy=\"0\" ixz=\"0\" iyy=\"2\" iyz=\"0\" izz=\"2\"/>\n    </inertial>\n";
    let expected_rest = format!(
        "{}{}",
        &DUPLICATE_INERTIALS[..orig_start],
        &DUPLICATE_INERTIALS[orig_end..].replacen(dup, "", 1)
    );
    assert_eq!(
        format!("{}{}", &text[..new_start], &text[new_end..]),
        expected_rest
    );
    // The frame without collision geometry is not touched; only its duplicate is still reported.
    assert!(link_body(&text, "frame").contains("<mass value=\"3\"/>"));
    let out = run(&["check", s(&filled), "--density", "1000"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(!stdout.contains("link `a`"), "{stdout}");
}

// Issue 11: one bad collision is its link's failure; the other links are filled, exit 2.
#[test]
fn one_bad_link_does_not_cost_the_rest() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // A tetrahedron with a two-vertex face in its OBJ (skipped with a note).
    write(
        tmp.path(),
        "tet.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    );
    let text = "<robot name=\"r\">
  <link name=\"plane\"><collision><geometry><plane normal=\"0 0 1\"/></geometry></collision></link>
  <link name=\"cdf\"><collision><geometry><cdf filename=\"x.cdf\"/></geometry></collision></link>
  <link name=\"scale4\">
    <collision><geometry><box size=\"1 1 1\"/></geometry></collision>
    <collision><geometry><mesh filename=\"tet.obj\" scale=\"1 1 1 1\"/></geometry></collision>
  </link>
  <link name=\"negative\"><collision><geometry><sphere radius=\"-0.1\"/></geometry></collision></link>
  <link name=\"infinite\"><collision><geometry><cylinder radius=\"inf\" length=\"1\"/></geometry></collision></link>
  <link name=\"huge\"><collision><geometry><box size=\"1e120 1e120 1e120\"/></geometry></collision></link>
  <link name=\"tet\"><collision><geometry><mesh filename=\"tet.obj\"/></geometry></collision></link>
  <link name=\"good\"><collision><origin xyz=\"0 0 0.5\"/><geometry><box size=\"0.1 0.2 0.3\"/></geometry></collision></link>
</robot>
";
    let urdf = write(tmp.path(), "bad.urdf", text);
    let filled = tmp.path().join("filled.urdf");
    // Without --keep-going nothing is written (the hardening issue's policy); with it, the rest is.
    let out = run(&["fill", s(&urdf), "--density", "1000", "-o", s(&filled)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(!filled.exists());
    let out = run(&[
        "fill",
        s(&urdf),
        "--density",
        "1000",
        "-o",
        s(&filled),
        "--keep-going",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for expect in [
        "bad.urdf:2: link `plane`: collision 1 (line 2): unknown geometry <plane>",
        "bad.urdf:3: link `cdf`: collision 1 (line 3): unknown geometry <cdf>",
        "bad.urdf:4: link `scale4`: collision 2 (line 6): mesh scale \"1 1 1 1\" should be three numbers, not 4",
        "bad.urdf:8: link `negative`: collision 1 (line 8): radius=\"-0.1\" must not be negative",
        "bad.urdf:9: link `infinite`: collision 1 (line 9): radius=\"inf\" is not a finite number",
        "bad.urdf:10: link `huge`: collision 1 (line 10): box size 1e120 1e120 1e120 is too large",
    ] {
        assert!(stderr.contains(expect), "expected `{expect}` in:\n{stderr}");
    }
    assert!(
        stderr.contains("1 face(s) with fewer than three vertices skipped (the first on line 6)"),
        "{stderr}"
    );
    let out_text = std::fs::read_to_string(&filled).expect("the others are written");
    assert_box(
        link_body(&out_text, "good"),
        1000.0,
        [0.1, 0.2, 0.3],
        [0.0, 0.0, 0.5],
    );
    // Unit tetrahedron: V = 1/6, COM (1/4, 1/4, 1/4); central Ixx = ρ/80, Ixy = -∫(x-cx)(y-cy) dm = ρ/480.
    let tet = link_body(&out_text, "tet");
    close(attr(tet, "mass", "value"), 1000.0 / 6.0, "tet mass");
    for c in attr3(tet, "origin", "xyz") {
        close(c, 0.25, "tet com");
    }
    close(attr(tet, "inertia", "ixx"), 1000.0 / 80.0, "tet ixx");
    close(attr(tet, "inertia", "ixy"), 1000.0 / 480.0, "tet ixy");
    for name in ["plane", "cdf", "scale4", "negative", "huge"] {
        assert!(!link_body(&out_text, name).contains("<inertial"), "{name}");
    }
    // check without densities reports the same collisions as errors (exit 2), with file:line.
    let out = run(&["check", s(&urdf)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("bad.urdf:2: link `plane`: collision 1 (line 2): unknown geometry <plane>"),
        "{stderr}"
    );
}

// Issue 11: zero-size primitives are valid URDF; a link left without volume is left as it is.
#[test]
fn zero_size_primitives_contribute_nothing() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let text = "<robot name=\"r\">
  <link name=\"contact_point\">
    <collision><geometry><sphere radius=\"0\"/></geometry></collision>
    <collision><geometry><box size=\"0 0 0\"/></geometry></collision>
    <collision><geometry><cylinder radius=\"0.1\" length=\"0\"/></geometry></collision>
  </link>
  <link name=\"body\">
    <collision><geometry><box size=\"1 2 3\"/></geometry></collision>
    <collision><origin xyz=\"5 0 0\"/><geometry><sphere radius=\"0\"/></geometry></collision>
  </link>
  <link name=\"ball\"><collision><geometry><capsule radius=\"0.5\" length=\"0\"/></geometry></collision></link>
</robot>
";
    let urdf = write(tmp.path(), "zero.urdf", text);
    // Zero-size parts are notes (UI203): printed with --verbose.
    let out = run(&["fill", s(&urdf), "--density", "1000", "--verbose"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("note[UI203]: ")
            && stderr.contains(
                "zero.urdf:2: link `contact_point`: its collision geometry has no volume"
            ),
        "{stderr}"
    );
    assert!(
        stderr.contains("zero.urdf:9: link `body`: collision 2: sphere radius 0 has no volume and contributes nothing"),
        "{stderr}"
    );
    let filled = String::from_utf8(out.stdout).expect("utf-8");
    assert_eq!(
        link_body(&filled, "contact_point"),
        link_body(text, "contact_point")
    );
    // The zero sphere 5 m away moves nothing.
    assert_box(
        link_body(&filled, "body"),
        1000.0,
        [1.0, 2.0, 3.0],
        [0.0; 3],
    );
    // A zero-length capsule is a sphere: m = 4/3 π r³ ρ, I = 2/5 m r².
    let ball = link_body(&filled, "ball");
    let m = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.125;
    close(attr(ball, "mass", "value"), m, "ball mass");
    close(attr(ball, "inertia", "izz"), 0.4 * m * 0.25, "ball izz");
    // check does not ask for an inertial on the link without volume.
    let filled_path = write(tmp.path(), "filled.urdf", &filled);
    let out = run(&["check", s(&filled_path)]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
}

// Issue 11: what urdfdom ignores inside one <collision> is ignored here too, with a warning.
#[test]
fn repeated_collision_parts_use_the_first() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let text = "<robot name=\"r\">
  <link name=\"a\">
    <collision>
      <origin xyz=\"0 0 1\"/>
      <origin xyz=\"0 0 7\"/>
      <geometry>
        <box size=\"1 2 3\"/>
        <origin xyz=\"5 5 5\"/>
        <sphere radius=\"2\"/>
      </geometry>
      <geometry><sphere radius=\"9\"/></geometry>
    </collision>
  </link>
</robot>
";
    let urdf = write(tmp.path(), "rep.urdf", text);
    let out = run(&["fill", s(&urdf), "--density", "1000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for expect in [
        "warning[UI201]: ",
        "rep.urdf:5: link `a`: collision 1: a second <origin> is ignored (urdfdom reads the first, on line 4)",
        "rep.urdf:8: link `a`: collision 1: <origin> inside <geometry> is ignored (as urdfdom does): an origin belongs in <collision>",
        "rep.urdf:9: link `a`: collision 1: a second shape <sphere> in <geometry> is ignored (urdfdom reads only the first, <box> on line 7)",
        "rep.urdf:11: link `a`: collision 1: a second <geometry> is ignored",
    ] {
        assert!(stderr.contains(expect), "expected `{expect}` in:\n{stderr}");
    }
    let filled = String::from_utf8(out.stdout).expect("utf-8");
    assert_box(
        link_body(&filled, "a"),
        1000.0,
        [1.0, 2.0, 3.0],
        [0.0, 0.0, 1.0],
    );
}

// Issue 11: malformed XML and duplicate link names refuse the file, naming where.
#[test]
fn duplicate_attributes_and_link_names_refuse_the_file() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let text = "<robot name=\"r\">\n  <link name=\"a\">\n    <collision><geometry><box size=\"1 2 3\" size=\"4 5 6\"/></geometry></collision>\n  </link>\n</robot>\n";
    let urdf = write(tmp.path(), "attr.urdf", text);
    let out = run(&["fill", s(&urdf), "--density", "1000", "-i"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("attr.urdf:3:44: attribute `size` is given twice in <box>"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&urdf).expect("read"), text);
    let urdf = write(
        tmp.path(),
        "links.urdf",
        "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n<link name=\"a\"/>\n</robot>\n",
    );
    let out = run(&["check", s(&urdf)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("links.urdf:4:1: duplicate link name `a` on lines 2 and 4"),
        "{stderr}"
    );
}

/// A URDF with a non-ASCII comment and link name, one box link without an inertial.
fn encoded_robot() -> String {
    "<?xml version=\"1.0\" encoding=\"ENC\"?>\n<robot name=\"r\">\n  <!-- Gelenk für den Greifer: 30 °C -->\n  <link name=\"greifer_é\">\n    <collision><geometry><box size=\"1 2 3\"/></geometry></collision>\n  </link>\n</robot>\n".into()
}

// Issue 11: UTF-16 and declared Latin-1 files are read and written back in their own encoding.
#[test]
fn utf16_and_latin1_files_keep_their_encoding() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let utf16_text = encoded_robot().replace("ENC", "UTF-16");
    let utf16: Vec<u8> = [0xfeff_u16]
        .into_iter()
        .chain(utf16_text.encode_utf16())
        .flat_map(u16::to_le_bytes)
        .collect();
    let latin1_text = encoded_robot().replace("ENC", "ISO-8859-1");
    let latin1: Vec<u8> = latin1_text.chars().map(|c| c as u32 as u8).collect();
    for (name, bytes, text) in [
        ("utf16.urdf", utf16, utf16_text),
        ("latin1.urdf", latin1, latin1_text),
    ] {
        let urdf = write(tmp.path(), name, &bytes);
        let out = run(&["fill", s(&urdf), "--density", "1000", "-i"]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {stderr}");
        let written = std::fs::read(&urdf).expect("read back");
        // Decode what was written the way it was read, then compare as text.
        let decoded: String = if name == "utf16.urdf" {
            assert_eq!(&written[..2], &[0xff, 0xfe], "BOM kept");
            let units: Vec<u16> = written[2..]
                .chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect();
            String::from_utf16(&units).expect("utf-16")
        } else {
            assert!(written.contains(&0xe9) && std::str::from_utf8(&written).is_err());
            written.iter().map(|&b| b as char).collect()
        };
        let body = link_body(&decoded, "greifer_é");
        assert_box(body, 1000.0, [1.0, 2.0, 3.0], [0.0; 3]);
        let start = decoded.find("\n    <inertial>").expect("inserted");
        let end = decoded.find("</inertial>").expect("end") + "</inertial>".len();
        assert_eq!(format!("{}{}", &decoded[..start], &decoded[end..]), text);
        // A second run changes nothing.
        let out = run(&["fill", s(&urdf), "--density", "1000", "-i"]);
        assert!(out.status.success());
        assert_eq!(std::fs::read(&urdf).expect("read"), written, "{name}");
    }
    // Latin-1 bytes without a declaration: where and what to do, never "byte 0".
    let urdf = write(
        tmp.path(),
        "undeclared.urdf",
        b"<robot name=\"r\">\n  <link name=\"greifer_\xe9\"/>\n</robot>\n",
    );
    let out = run(&["check", s(&urdf)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("undeclared.urdf:2:23: not valid UTF-8 (byte 0xe9)")
            && stderr.contains("encoding=\"ISO-8859-1\""),
        "{stderr}"
    );
    assert!(!stderr.contains("(byte 0)"), "{stderr}");
}

// Issue 11: file:// URIs are percent-decoded, as ROS's resource_retriever reads them.
#[test]
fn file_uris_are_percent_decoded() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = tmp.path().join("my robot");
    std::fs::create_dir_all(&dir).expect("mkdir");
    write(
        &dir,
        "part.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    );
    let uri = format!("file://{}/my%20robot/part.obj", tmp.path().display());
    let urdf = write(
        tmp.path(),
        "uri.urdf",
        format!("<robot name=\"r\"><link name=\"a\"><collision><geometry><mesh filename=\"{uri}\"/></geometry></collision></link></robot>"),
    );
    let out = run(&["fill", s(&urdf), "--density", "600"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("utf-8");
    close(attr(link_body(&text, "a"), "mass", "value"), 100.0, "mass");
}

// Issue 21: a xacro source is expanded, so the links of its macros are seen and filled (issue 11
// only noted that they were not).
#[test]
fn xacro_sources_are_expanded() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let urdf = write(
        tmp.path(),
        "arm.urdf.xacro",
        "<robot name=\"arm\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:macro name=\"limb\" params=\"n\">\n    <link name=\"${n}\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>\n  </xacro:macro>\n  <xacro:limb n=\"a\"/>\n  <link name=\"base\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>\n</robot>\n",
    );
    let out = run(&["fill", s(&urdf), "--density", "1000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("run `xacro"), "{stderr}");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    close(
        attr(link_body(&text, "a"), "mass", "value"),
        1000.0,
        "mass of the macro's link",
    );
    close(
        attr(link_body(&text, "base"), "mass", "value"),
        1000.0,
        "mass",
    );
    // Only the declaration (xacro's output keeps it): a softer note, still one.
    let urdf = write(
        tmp.path(),
        "expanded.urdf",
        "<robot name=\"arm\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <link name=\"base\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>\n</robot>\n",
    );
    // A note (UI205): printed with --verbose only.
    let out = run(&["fill", s(&urdf), "--density", "1000"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("xacro"));
    let out = run(&["fill", s(&urdf), "--density", "1000", "-v"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(stderr.matches("run `xacro").count(), 1, "{stderr}");
    assert!(
        stderr
            .contains("expanded.urdf:1: the root declares xmlns:xacro: if this is a xacro source"),
        "{stderr}"
    );
}
