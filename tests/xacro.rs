//! The real binary on xacro sources made by this project: `xacro`, `check`, `diff` and `fill` with
//! messages at source lines, write-back into the sources, expansion errors, stdin.

// The xacro and yaml fuzz targets' code itself, so that their seeds replay through it.
#[path = "../fuzz/fuzz_targets/xacro_check.rs"]
mod xacro_check;

use std::path::Path;
use std::process::{Command, Output, Stdio};

fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run urdf-inertia")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

const ARM_MACRO: &str = "<?xml version=\"1.0\"?>
<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:macro name=\"arm\" params=\"prefix mass\">
    <link name=\"${prefix}shoulder_link\">
      <inertial>
        <mass value=\"${mass}\"/>
        <inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>
      </inertial>
      <collision><geometry><box size=\"0.1 0.1 0.2\"/></geometry></collision>
    </link>
  </xacro:macro>
  <link name=\"mount\">
    <collision><geometry><cylinder radius=\"0.05\" length=\"0.02\"/></geometry></collision>
  </link>
</robot>
";

const TOP: &str = "<?xml version=\"1.0\"?>
<robot name=\"demo\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:include filename=\"../arms/arm_macro.xacro\"/>
  <xacro:arg name=\"m\" default=\"-1.3773\"/>
  <!-- the base -->
  <link name=\"base_link\">
    <collision>
      <geometry><box size=\"0.2 0.2 0.1\"/></geometry>
    </collision>
  </link>
  <xacro:arm prefix=\"left_\" mass=\"$(arg m)\"/>
</robot>
";

/// A robot of two xacro files in a temp dir: `robots/robot.urdf.xacro` includes
/// `arms/arm_macro.xacro`, whose macro makes a link with mass `m` (default -1.3773).
fn robot() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().expect("tempdir");
    for (name, body) in [
        ("arms/arm_macro.xacro", ARM_MACRO),
        ("robots/robot.urdf.xacro", TOP),
    ] {
        let p = tmp.path().join(name);
        std::fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
        std::fs::write(p, body).expect("write");
    }
    tmp
}

#[test]
fn check_names_the_macro_file_line_and_call() {
    let tmp = robot();
    let out = run_in(tmp.path(), &["check", "robots/robot.urdf.xacro"]);
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}{}", text(&out.stderr));
    assert!(
        stdout.contains("arms/arm_macro.xacro:5: link `left_shoulder_link` (macro arm called at robots/robot.urdf.xacro:11): mass -1.3773 is not positive"),
        "{stdout}"
    );
    assert!(
        stdout.contains(
            "robots/robot.urdf.xacro:6: link `base_link`: has collision geometry but no <inertial>"
        ),
        "{stdout}"
    );
    assert!(
        stdout.contains(
            "arms/arm_macro.xacro:12: link `mount`: has collision geometry but no <inertial>"
        ),
        "{stdout}"
    );
    // The same robot given through --arg with a valid mass: only the missing inertials remain.
    let out = run_in(
        tmp.path(),
        &["check", "robots/robot.urdf.xacro", "--arg", "m:=2"],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        !text(&out.stdout).contains("not positive"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn xacro_prints_the_expansion() {
    let tmp = robot();
    let out = run_in(tmp.path(), &["xacro", "robots/robot.urdf.xacro", "m:=3.5"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let urdf = text(&out.stdout);
    let body: Vec<&str> = urdf.lines().skip(5).collect();
    assert_eq!(
        body.join("\n"),
        "<robot name=\"demo\">
  <link name=\"mount\">
    <collision>
      <geometry>
        <cylinder radius=\"0.05\" length=\"0.02\"/>
      </geometry>
    </collision>
  </link>
  <!-- the base -->
  <link name=\"base_link\">
    <collision>
      <geometry>
        <box size=\"0.2 0.2 0.1\"/>
      </geometry>
    </collision>
  </link>
  <link name=\"left_shoulder_link\">
    <inertial>
      <mass value=\"3.5\"/>
      <inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>
    </inertial>
    <collision>
      <geometry>
        <box size=\"0.1 0.1 0.2\"/>
      </geometry>
    </collision>
  </link>
</robot>"
    );
}

/// The `<inertial>…</inertial>` text of link `name` in a URDF, whitespace-normalised.
fn inertial_of(urdf: &str, name: &str) -> String {
    let start = urdf
        .find(&format!("<link name=\"{name}\""))
        .unwrap_or_else(|| panic!("link {name} in {urdf}"));
    let link = &urdf[start..start + urdf[start..].find("</link>").expect("end")];
    let a = link
        .find("<inertial>")
        .unwrap_or_else(|| panic!("inertial of {name}: {link}"));
    let b = link.find("</inertial>").expect("inertial end");
    link[a..b].split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The reference for a write-back: `xacro ARGS` (the file and its `NAME:=VALUE`s) saved as
/// `expanded.urdf` in `dir`, and the URDF `fill expanded.urdf FILL` prints.
fn filled_expansion(dir: &Path, xacro: &[&str], fill: &[&str]) -> String {
    let out = run_in(dir, &[&["xacro"], xacro].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    std::fs::write(dir.join("expanded.urdf"), &out.stdout).expect("write");
    let out = run_in(dir, &[&["fill", "expanded.urdf"], fill].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    text(&out.stdout)
}

/// `fill -i ARGS`, which must succeed: its standard error.
fn fill_in_place(dir: &Path, args: &[&str]) -> String {
    let out = run_in(dir, &[&["fill", "-i"], args].concat());
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    stderr
}

#[test]
fn fill_in_place_writes_literal_links_into_their_files() {
    let tmp = robot();
    let dir = tmp.path();
    let filled = filled_expansion(
        dir,
        &["robots/robot.urdf.xacro", "m:=2"],
        &["--density", "1000"],
    );
    let stderr = fill_in_place(
        dir,
        &[
            "robots/robot.urdf.xacro",
            "--arg",
            "m:=2",
            "--density",
            "1000",
        ],
    );
    assert!(
        stderr.contains("warning[UI502]: arms/arm_macro.xacro:4: link `left_shoulder_link` (macro arm called at robots/robot.urdf.xacro:11): not written into the xacro source: it is written in the body of macro arm with values xacro computes inside it (`${…}` or `$(…)`), which may differ from call to call; `urdf-inertia fill robots/robot.urdf.xacro -o filled.urdf` writes the filled expansion"),
        "{stderr}"
    );
    // The summary counts what was written: the macro's link was computed, not filled.
    assert!(
        stderr.contains("computed 3 link(s), 2 written") && !stderr.contains("filled 3 link(s)"),
        "{stderr}"
    );
    // The top file and the included file got their links' inertials, nothing else changed.
    let top = std::fs::read_to_string(dir.join("robots/robot.urdf.xacro")).expect("read");
    let arm = std::fs::read_to_string(dir.join("arms/arm_macro.xacro")).expect("read");
    assert!(
        top.contains("  <link name=\"base_link\">\n    <inertial>\n"),
        "{top}"
    );
    let without = |s: &str| {
        let a = s
            .find("    <inertial>\n      <origin")
            .expect("new inertial");
        let b = s[a..].find("</inertial>\n").expect("end") + a + "</inertial>\n".len();
        format!("{}{}", &s[..a], &s[b..])
    };
    assert_eq!(without(&top), TOP);
    assert_eq!(without(&arm), ARM_MACRO);
    // Expanding the written sources gives the inertials fill gives on the expansion, for every
    // literal link; the macro's link is as it was.
    let out = run_in(dir, &["xacro", "robots/robot.urdf.xacro", "m:=2"]);
    let again = text(&out.stdout);
    for link in ["base_link", "mount"] {
        assert_eq!(
            inertial_of(&again, link),
            inertial_of(&filled, link),
            "{link}"
        );
    }
    assert!(inertial_of(&again, "left_shoulder_link").contains("<mass value=\"2\"/>"));
    // Running it again changes nothing (idempotent).
    let out = run_in(
        dir,
        &[
            "fill",
            "-i",
            "robots/robot.urdf.xacro",
            "--arg",
            "m:=2",
            "--density",
            "1000",
        ],
    );
    assert!(out.status.success());
    assert_eq!(
        std::fs::read_to_string(dir.join("robots/robot.urdf.xacro")).expect("read"),
        top
    );
}

/// Pads and fingers made by macros that compute nothing inside their links but the names, and a tip
/// whose box size is a macro parameter ([`fill_in_place_writes_a_macro_body_that_computes_nothing`]).
const PADS: &str = "<?xml version=\"1.0\"?>
<robot name=\"pads\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:macro name=\"pad\" params=\"side\">
    <link name=\"${side}_pad\">
      <collision>
        <origin xyz=\"0 0 0.01\" rpy=\"0 0 0\"/>
        <geometry><box size=\"0.03 0.07 0.0075\"/></geometry>
      </collision>
    </link>
  </xacro:macro>
  <xacro:macro name=\"finger\" params=\"side\">
    <link name=\"${side}_finger\">
      <collision><geometry><cylinder radius=\"0.01\" length=\"0.05\"/></geometry></collision>
    </link>
  </xacro:macro>
  <xacro:macro name=\"tip\" params=\"side length\">
    <link name=\"${side}_tip\">
      <collision><geometry><box size=\"0.01 0.01 ${length}\"/></geometry></collision>
    </link>
  </xacro:macro>
  <xacro:pad side=\"left\"/>
  <xacro:pad side=\"right\"/>
  <xacro:finger side=\"left\"/>
  <xacro:finger side=\"right\"/>
  <xacro:tip side=\"left\" length=\"0.02\"/>
</robot>
";

/// A macro whose link has nothing computed inside it but its name (Robotiq's 2F-85 writes the
/// whole gripper so) expands to the same link on every call: `fill -i` writes its `<inertial>` into
/// the macro body, once for a macro called twice, and the expansion then carries the values `fill`
/// gives on the expansion. A macro link whose density a `[links]` rule gives by the name one call
/// made stays as it was, named, with every link made from that place (another call, another name);
/// so does one with `${…}` inside it.
#[test]
fn fill_in_place_writes_a_macro_body_that_computes_nothing() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = tmp.path();
    std::fs::write(dir.join("pads.urdf.xacro"), PADS).expect("write");
    std::fs::write(
        dir.join("densities.toml"),
        "default = 1000\n[links]\nright_finger = 2000\n",
    )
    .expect("write");
    let map = ["--density-map", "densities.toml"];
    let filled = filled_expansion(dir, &["pads.urdf.xacro"], &map);
    let stderr = fill_in_place(dir, &["pads.urdf.xacro", map[0], map[1]]);
    assert!(
        stderr.contains("wrote 2 of 5 computed link(s) into 1 xacro source file(s) (2 of them from macro bodies with nothing computed inside the link, the same for every call)"),
        "{stderr}"
    );
    for side in ["left", "right"] {
        assert!(
            stderr.contains(&format!("link `{side}_finger` (macro finger called at pads.urdf.xacro:{}): not written into the xacro source: the density of `right_finger` comes from the density map's [links] \"right_finger\", matched by the name this call of macro finger gives it, and another call may give it another name", if side == "left" { 23 } else { 24 })),
            "{stderr}"
        );
    }
    assert!(
        stderr.contains("link `left_tip` (macro tip called at pads.urdf.xacro:25): not written into the xacro source: it is written in the body of macro tip with values xacro computes inside it"),
        "{stderr}"
    );
    // One <inertial> written, in the pad macro's body; nothing else changed.
    let source = std::fs::read_to_string(dir.join("pads.urdf.xacro")).expect("read");
    assert_eq!(source.matches("<inertial>").count(), 1, "{source}");
    let a = source.find("      <inertial>\n").expect("written");
    assert!(
        source[..a].ends_with("<link name=\"${side}_pad\">\n"),
        "{source}"
    );
    let b = source[a..].find("</inertial>\n").expect("end") + a + "</inertial>\n".len();
    assert_eq!(format!("{}{}", &source[..a], &source[b..]), PADS);
    // Both pads expand with the inertial fill gives on the expansion: 0.03 × 0.07 × 0.0075 m of
    // 1000 kg/m³, 0.01575 kg at (0, 0, 0.01).
    let out = run_in(dir, &["xacro", "pads.urdf.xacro"]);
    let again = text(&out.stdout);
    for side in ["left", "right"] {
        let link = format!("{side}_pad");
        assert_eq!(
            inertial_of(&again, &link),
            inertial_of(&filled, &link),
            "{link}"
        );
        assert!(inertial_of(&again, &link).contains("<mass value=\"0.01575\"/>"));
    }
    // And check passes on the written source.
    let out = run_in(
        dir,
        &[
            "check",
            "pads.urdf.xacro",
            "--density-map",
            "densities.toml",
            "--only",
            "*_pad",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[test]
fn diff_reads_xacro_sources() {
    let tmp = robot();
    let out = run_in(
        tmp.path(),
        &[
            "diff",
            "robots/robot.urdf.xacro",
            "--arg",
            "m:=0.1",
            "--density",
            "1000",
        ],
    );
    let stdout = text(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}{}", text(&out.stderr));
    assert!(stdout.contains("left_shoulder_link"), "{stdout}");
}

#[test]
fn expansion_errors_are_file_line_with_exit_2() {
    let tmp = tempfile::tempdir().expect("tempdir");
    std::fs::write(
        tmp.path().join("bad.urdf.xacro"),
        "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:macro name=\"m\" params=\"a\">\n    <link name=\"${a + b}\"/>\n  </xacro:macro>\n  <xacro:m a=\"1\"/>\n</robot>\n",
    )
    .expect("write");
    for cmd in [
        &["xacro", "bad.urdf.xacro"][..],
        &["check", "bad.urdf.xacro"][..],
    ] {
        let out = run_in(tmp.path(), cmd);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd:?}: {stderr}");
        assert!(
            stderr.contains("error: bad.urdf.xacro:3: name 'b' is not defined (when evaluating expression 'a + b') (in macro m called at bad.urdf.xacro:5)"),
            "{cmd:?}: {stderr}"
        );
        assert!(out.stdout.is_empty());
    }
    let out = run_in(tmp.path(), &["xacro", "missing.urdf.xacro"]);
    assert_eq!(out.status.code(), Some(2));
    let out = run_in(tmp.path(), &["xacro", "bad.urdf.xacro", "notanarg"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("NAME:=VALUE"));
}

#[test]
fn a_urdf_is_read_from_stdin() {
    use std::io::Write;
    let tmp = tempfile::tempdir().expect("tempdir");
    let urdf = "<robot name=\"r\"><link name=\"a\"><inertial><mass value=\"-1\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link></robot>\n";
    let run_stdin = |args: &[&str]| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
            .current_dir(tmp.path())
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn");
        // A command refused before it reads stdin (`fill - -i`) may exit before the write: a
        // closed pipe is its answer, not a failure of the test.
        let written = child
            .stdin
            .take()
            .expect("stdin")
            .write_all(urdf.as_bytes());
        if let Err(e) = written {
            assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe, "write: {e}");
        }
        child.wait_with_output().expect("wait")
    };
    let out = run_stdin(&["check", "-"]);
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("<stdin>:1: link `a`: mass -1 is not positive"),
        "{}",
        text(&out.stdout)
    );
    let out = run_stdin(&["fill", "-", "--density", "1000"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("<mass value=\"1000\"/>"));
    let out = run_stdin(&["fill", "-", "--density", "1000", "-i"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn fill_to_a_file_writes_the_filled_expansion() {
    let tmp = robot();
    let dir = tmp.path();
    let out = run_in(dir, &["xacro", "robots/robot.urdf.xacro", "m:=2"]);
    std::fs::write(dir.join("expanded.urdf"), &out.stdout).expect("write");
    let out = run_in(dir, &["fill", "expanded.urdf", "--density", "1000"]);
    let filled = text(&out.stdout);
    // -o writes the filled expansion, the macro's link included.
    let out = run_in(
        dir,
        &[
            "fill",
            "robots/robot.urdf.xacro",
            "--arg",
            "m:=2",
            "--density",
            "1000",
            "-o",
            "filled.urdf",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let f = std::fs::read_to_string(dir.join("filled.urdf")).expect("read");
    assert_eq!(
        inertial_of(&f, "left_shoulder_link"),
        inertial_of(&filled, "left_shoulder_link")
    );
    assert_eq!(
        inertial_of(&f, "base_link"),
        inertial_of(&filled, "base_link")
    );
    // The sources are untouched.
    assert_eq!(
        std::fs::read_to_string(dir.join("robots/robot.urdf.xacro")).expect("read"),
        TOP
    );
}

/// A file of macros alone expands to a nameless robot without links: pre-commit hands it to the fill
/// hook on every commit that touches it, which once warned each time that `<robot>` had no name.
#[test]
fn a_macro_file_alone_gets_no_robot_name_warning() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let only_macros = "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:macro name=\"m\" params=\"p\">\n    <link name=\"${p}\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>\n  </xacro:macro>\n</robot>\n";
    std::fs::write(tmp.path().join("m.xacro"), only_macros).expect("write");
    let out = run_in(tmp.path(), &["fill", "-i", "m.xacro", "--density", "1000"]);
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("UI206"), "{stderr}");
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("m.xacro")).expect("read"),
        only_macros
    );
}

// ---------------------------------------------------------------------------------------------------
// Fuzzing seeds for the `xacro` and `yaml` targets (fuzz/seeds/xacro, fuzz/seeds/yaml): regenerate with
//   cargo test --release --test xacro -- --ignored write_xacro_fuzz_seeds

/// Small xacro sources, each using a different part of the language.
const XACRO_SEEDS: [(&str, &str); 6] = [
    ("arm_macro.xacro", ARM_MACRO),
    (
        "properties.xacro",
        "<robot name=\"p\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:property name=\"r\" value=\"${0.05 * 2}\"/>
  <xacro:property name=\"later\" value=\"${r + 1}\"/>
  <xacro:property name=\"block\"><origin xyz=\"0 0 ${r}\" rpy=\"0 0 ${pi/2}\"/></xacro:property>
  <xacro:arg name=\"side\" default=\"left\"/>
  <link name=\"$(arg side)_${'%s_%d' % ('l', 3)}\">
    <collision><xacro:insert_block name=\"block\"/><geometry><sphere radius=\"${later}\"/></geometry></collision>
  </link>
  <xacro:if value=\"${r > 0.01 and not False}\"><link name=\"yes\"/></xacro:if>
  <xacro:unless value=\"true\"><link name=\"no\"/></xacro:unless>
</robot>
",
    ),
    (
        "blocks.xacro",
        "<robot name=\"b\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:macro name=\"part\" params=\"name *geom **extra m:=1.5 scale:=^|2\">
    <link name=\"${name}\">
      <inertial><mass value=\"${m}\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>
      <collision><geometry><xacro:insert_block name=\"geom\"/></geometry></collision>
      <xacro:insert_block name=\"extra\"/>
    </link>
  </xacro:macro>
  <xacro:part name=\"a\"><box size=\"1 2 3\"/><extra><visual/></extra></xacro:part>
  <xacro:part name=\"b\" m=\"${max(1, 2)}\"><cylinder radius=\"0.1\" length=\"0.2\"/><extra/></xacro:part>
</robot>
",
    ),
    (
        "elements.xacro",
        "<robot name=\"e\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:property name=\"d\" value=\"${dict(a=1, b=[1, 2, 3])}\"/>
  <xacro:element xacro:name=\"link\" name=\"${'x' if d['a'] == 1 else 'y'}\">
    <xacro:attribute name=\"type\" value=\"${str(len(d['b']))}\"/>
  </xacro:element>
  <link name=\"$${not_expanded}\"/>
  <link name=\"${str(radians(180))}_${int(round(degrees(pi)))}_${-2 if 1 in [1, 2] else 0}_${float('1e3')}\"/>
  <link name=\"$(eval 1 + 2)\"/>
</robot>
",
    ),
    (
        "scope.xacro",
        "<robot name=\"s\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:macro name=\"set\" params=\"v\">
    <xacro:property name=\"out\" value=\"${v}\" scope=\"parent\"/>
    <xacro:property name=\"g\" value=\"${v * 2}\" scope=\"global\"/>
  </xacro:macro>
  <xacro:set v=\"3\"/>
  <link name=\"l${out}_${g}\"/>
  <xacro:macro name=\"rec\" params=\"n\">
    <xacro:if value=\"${n > 0}\"><link name=\"r${n}\"/><xacro:rec n=\"${n - 1}\"/></xacro:if>
  </xacro:macro>
  <xacro:rec n=\"3\"/>
</robot>
",
    ),
    (
        "include.xacro",
        "<robot name=\"i\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">
  <xacro:include filename=\"missing/*.xacro\" ns=\"none\"/>
  <xacro:include filename=\"missing.xacro\" optional=\"true\"/>
  <xacro:property name=\"unused\" value=\"${xacro.load_yaml('missing.yaml')}\"/>
  <link name=\"$(optenv NO_SUCH_VARIABLE fallback)\"/>
</robot>
",
    ),
];

/// Small YAML files as robot descriptions write them (UR's kinematics, joint limits), and YAML 1.1
/// scalars `PyYAML` resolves differently from YAML 1.2.
const YAML_SEEDS: [(&str, &str); 4] = [
    (
        "kinematics.yaml",
        "kinematics:\n  shoulder:\n    x: 0\n    y: 0\n    z: 0.1625\n    roll: 0\n    pitch: 0\n    yaw: 0\n  hash: calib_12345\n",
    ),
    (
        "limits.yaml",
        "joint_limits:\n  shoulder_pan:\n    has_velocity_limits: true\n    max_position: !degrees  360.0\n    max_velocity: !degrees  180.0\n    min_position: !degrees -360.0\n  elbow:\n    max_effort: 150.0\n    length: !millimeters 425\n",
    ),
    (
        "scalars.yaml",
        "a: yes\nb: off\nc: 1e-3\nd: 1.0e-3\ne: 0755\nf: 0x1F\ng: ~\nh: .inf\ni: -.NaN\nj: '007'\nk: 1_000\nl: 2001-12-14\nm: [1, 2.5, 'x', {n: null}]\n",
    ),
    (
        "anchors.yaml",
        "base: &b {mass: 4.0, xyz: [0, 0, 0.5]}\narm:\n  <<: *b\n  mass: 2.0\nlist:\n  - *b\n  - |\n    block text\n  - >\n    folded\n",
    ),
];

#[test]
#[ignore = "writes fuzz/seeds/xacro and fuzz/seeds/yaml; run on purpose"]
fn write_xacro_fuzz_seeds() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    for (target, files) in [("xacro", &XACRO_SEEDS[..]), ("yaml", &YAML_SEEDS[..])] {
        let dir = seeds.join(target);
        std::fs::create_dir_all(&dir).expect("mkdir");
        for (name, text) in files {
            std::fs::write(dir.join(name), text).expect("write");
        }
    }
}

/// The xacro and yaml fuzzing seeds go through the fuzz targets' code (expansion, URDF scan, the
/// write-back splice; `load_yaml` and printing): nothing panics. The seeds on disk must be the ones
/// these constants write.
#[test]
fn xacro_fuzz_seeds_replay() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    let tmp = tempfile::tempdir().expect("tempdir");
    for (name, text) in XACRO_SEEDS {
        let on_disk = std::fs::read_to_string(seeds.join("xacro").join(name)).expect("seed");
        assert_eq!(
            on_disk, text,
            "fuzz/seeds/xacro/{name} is stale: regenerate"
        );
        xacro_check::xacro(text.as_bytes(), tmp.path());
    }
    for (name, text) in YAML_SEEDS {
        let on_disk = std::fs::read_to_string(seeds.join("yaml").join(name)).expect("seed");
        assert_eq!(on_disk, text, "fuzz/seeds/yaml/{name} is stale: regenerate");
        xacro_check::yaml(text.as_bytes(), tmp.path());
    }
}

/// A corpus grown by `bash fuzz/run.sh SECONDS xacro yaml` (fuzz/corpus, not committed), replayed
/// without instrumentation.
#[test]
#[ignore = "replays fuzz/corpus/xacro and fuzz/corpus/yaml after a fuzzing run"]
fn xacro_fuzz_corpus_replay() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let tmp = tempfile::tempdir().expect("tempdir");
    let mut n = 0;
    for (target, one) in [
        ("xacro", xacro_check::xacro as fn(&[u8], &Path)),
        ("yaml", xacro_check::yaml),
    ] {
        let Ok(dir) = std::fs::read_dir(corpus.join(target)) else {
            continue;
        };
        for entry in dir.flatten() {
            one(&std::fs::read(entry.path()).expect("read"), tmp.path());
            n += 1;
        }
    }
    eprintln!("{n} inputs replayed");
}
