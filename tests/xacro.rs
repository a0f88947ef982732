//! The real binary on xacro sources made by this project: `xacro`, `check`, `diff` and `fill` with
//! messages at source lines, write-back into the sources, expansion errors, stdin.

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

#[test]
fn fill_in_place_writes_literal_links_into_their_files() {
    let tmp = robot();
    let dir = tmp.path();
    // The reference: fill of the expansion.
    let out = run_in(dir, &["xacro", "robots/robot.urdf.xacro", "m:=2"]);
    assert!(out.status.success());
    std::fs::write(dir.join("expanded.urdf"), &out.stdout).expect("write");
    let out = run_in(dir, &["fill", "expanded.urdf", "--density", "1000"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let filled = text(&out.stdout);

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
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: arms/arm_macro.xacro:4: link `left_shoulder_link` (macro arm called at robots/robot.urdf.xacro:11): not written into the xacro source: it is written in the body of macro arm; `urdf-inertia fill robots/robot.urdf.xacro -o filled.urdf` writes the filled expansion"),
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
        use std::io::Write;
        // A command refused before it reads stdin (`fill - -i`) may exit before this write: a
        // broken pipe is then the expected race, not a failure.
        if let Err(e) = child
            .stdin
            .take()
            .expect("stdin")
            .write_all(urdf.as_bytes())
        {
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
