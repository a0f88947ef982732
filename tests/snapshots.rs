//! Snapshots (insta) of every command the README shows, run on the demo robot exactly as written:
//! exit code, stdout and stderr, with timings and temporary paths redacted. A change of output shows
//! up as a reviewed snapshot diff; CI never writes snapshots (insta's default there).
//!
//! The README's commands name `robot.urdf`, `other.urdf`, `densities.toml` and `meshes/part.stl`:
//! they are the demo robot's URDF, its density map and its shoulder mesh, copied under those names
//! into the `urdf/` folder of a temporary copy of the demo package, where the commands run.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

fn demo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/demo_arm_description")
}

/// A copy of the demo package; returns (temp dir, the folder the commands run in).
fn workspace() -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let src = demo_root();
    let pkg = tmp.path().join("demo_arm_description");
    for sub in ["urdf", "meshes"] {
        std::fs::create_dir_all(pkg.join(sub)).expect("mkdir");
        for e in std::fs::read_dir(src.join(sub)).expect("read_dir") {
            let e = e.expect("entry");
            std::fs::copy(e.path(), pkg.join(sub).join(e.file_name())).expect("copy");
        }
    }
    std::fs::copy(src.join("package.xml"), pkg.join("package.xml")).expect("copy");
    let dir = pkg.join("urdf");
    let urdf = dir.join("demo_arm.urdf");
    std::fs::copy(&urdf, dir.join("robot.urdf")).expect("copy");
    std::fs::copy(&urdf, dir.join("other.urdf")).expect("copy");
    std::fs::copy(src.join("densities.toml"), dir.join("densities.toml")).expect("copy");
    std::fs::create_dir_all(dir.join("meshes")).expect("mkdir");
    std::fs::copy(src.join("meshes/shoulder.STL"), dir.join("meshes/part.stl")).expect("copy");
    (tmp, dir)
}

/// Runs the binary in `dir` with a shell-like command line; the transcript to snapshot.
fn transcript(dir: &Path, line: &str) -> String {
    let args: Vec<&str> = line.split_whitespace().collect();
    assert_eq!(args[0], "urdf-inertia");
    let out = Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(&args[1..])
        .current_dir(dir)
        .env_remove("ROS_PACKAGE_PATH")
        .env_remove("AMENT_PREFIX_PATH")
        .env_remove("URDF_INERTIA_MAX_FILE_SIZE")
        .output()
        .expect("run urdf-inertia");
    format!(
        "$ {line}\nexit: {}\n--- stdout\n{}--- stderr\n{}",
        out.status.code().map_or("signal".into(), |c| c.to_string()),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Timings and temporary paths redacted.
fn settings(dir: &Path) -> insta::Settings {
    let mut s = insta::Settings::clone_current();
    s.set_prepend_module_to_snapshot(false);
    let root = dir
        .parent()
        .and_then(Path::parent)
        .expect("temp root")
        .display()
        .to_string();
    s.add_filter(&regex_escape(&root), "[TMP]");
    s.add_filter(r"\d+\.\d{3} (m?s)\b", "[TIME] $1");
    s.add_filter(r#""(seconds\w*)": [0-9.e-]+"#, r#""$1": "[SECONDS]""#);
    s
}

fn regex_escape(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '/' || c == '_' || c == '-' {
                c.to_string()
            } else {
                format!("\\{c}")
            }
        })
        .collect()
}

/// The README's set-up command, from the repository root as written there.
#[test]
fn readme_fill_demo_to_stdout() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let line = "urdf-inertia fill robots/demo_arm_description/urdf/demo_arm.urdf --density-map robots/demo_arm_description/densities.toml";
    settings(&root.join("a/b")).bind(|| {
        insta::assert_snapshot!("fill_demo_stdout", transcript(root, line));
    });
}

/// Each command of the README's "Commands" block, each on a fresh copy of the demo package.
#[test]
fn readme_commands() {
    let cases = [
        ("fill_in_place", "urdf-inertia fill robot.urdf --density-map densities.toml -i", Some("robot.urdf")),
        ("fill_two_in_place", "urdf-inertia fill robot.urdf other.urdf --density-map densities.toml -i", Some("other.urdf")),
        ("fill_uniform_density_to_file", "urdf-inertia fill robot.urdf --density 2700 -o filled.urdf", Some("filled.urdf")),
        ("fill_keep_mass", "urdf-inertia fill robot.urdf --keep-mass --density-map densities.toml -i", Some("robot.urdf")),
        ("diff", "urdf-inertia diff robot.urdf --density-map densities.toml", None),
        ("check_two_files", "urdf-inertia check robot.urdf other.urdf", None),
        ("check_write_baseline", "urdf-inertia check robot.urdf --write-baseline urdf-inertia.baseline", Some("urdf-inertia.baseline")),
        ("fill_quiet", "urdf-inertia fill robot.urdf --density 2700 -o filled.urdf -q --ignore UI102", None),
        ("mesh_json", "urdf-inertia mesh meshes/part.stl --scale 0.001 0.001 0.001 --density 1240 --format json", None),
        ("fill_json_summary", "urdf-inertia fill robot.urdf --density-map densities.toml -o filled.urdf --format json", None),
        ("diff_json", "urdf-inertia diff robot.urdf --density-map densities.toml --format json", None),
        ("mesh_text", "urdf-inertia mesh meshes/part.stl --scale 0.001 0.001 0.001 --density 1240", None),
    ];
    for (name, line, written) in cases {
        let (_tmp, dir) = workspace();
        let mut text = transcript(&dir, line);
        if let Some(file) = written {
            let _ = writeln!(text, "--- {file}");
            text.push_str(&std::fs::read_to_string(dir.join(file)).expect("written file"));
        }
        settings(&dir).bind(|| insta::assert_snapshot!(name, text));
    }
}

/// Numbers without round-off noise: no run of six 9s or 0s inside a number of an `<inertial>`.
fn noisy(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.contains("<mass") || l.contains("<inertia ") || l.contains("<origin xyz"))
        .flat_map(|l| l.split('"'))
        .flat_map(str::split_whitespace)
        .filter(|w| w.parse::<f64>().is_ok())
        .filter(|w| {
            let digits = w.split(['e', 'E']).next().unwrap_or("");
            digits.contains("999999") || digits.contains("000000") && !digits.ends_with("000000")
        })
        .map(String::from)
        .collect()
}

/// Issue 12: the demo's default output has no round-off noise and no warning, filling it again changes
/// nothing, and the rounded values pass `check` and `diff`.
#[test]
#[allow(clippy::too_many_lines)] // one scenario checked step by step
fn demo_output_is_clean_idempotent_and_passes_check() {
    let (_tmp, dir) = workspace();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
            .args(args)
            .current_dir(&dir)
            .output()
            .expect("run")
    };
    let first = run(&[
        "fill",
        "robot.urdf",
        "--density-map",
        "densities.toml",
        "-o",
        "once.urdf",
    ]);
    assert_eq!(first.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(!stderr.contains("warning["), "{stderr}");
    let once = std::fs::read_to_string(dir.join("once.urdf")).expect("once");
    // wrist_link's mesh is a binary STL: its vertices are f32 (0.02 is stored as 0.0199999995529652),
    // so those digits are the file's, not round-off, and are kept.
    let wrist = once.find("<link name=\"wrist_link\"").expect("wrist");
    let wrist_end = wrist + once[wrist..].find("</link>").expect("end");
    let others = format!("{}{}", &once[..wrist], &once[wrist_end..]);
    assert!(noisy(&others).is_empty(), "{:?}", noisy(&others));
    assert!(once.contains("<mass value=\"13.11\"/>"), "{once}");
    let second = run(&[
        "fill",
        "once.urdf",
        "--density-map",
        "densities.toml",
        "-o",
        "twice.urdf",
    ]);
    assert_eq!(second.status.code(), Some(0));
    let twice = std::fs::read_to_string(dir.join("twice.urdf")).expect("twice");
    assert_eq!(once, twice, "fill(fill(x)) differs from fill(x)");
    // Rounded, and still valid and equal to the computed values within check's tolerance.
    let check = run(&["check", "once.urdf", "--density-map", "densities.toml"]);
    assert_eq!(
        check.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&check.stdout)
    );
    let diff = run(&["diff", "once.urdf", "--density-map", "densities.toml"]);
    assert_eq!(
        diff.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&diff.stdout)
    );
    // The same with every --digits mode: idempotent, valid.
    for digits in ["full", "4", "17"] {
        let a = run(&[
            "fill",
            "robot.urdf",
            "--density-map",
            "densities.toml",
            "--digits",
            digits,
            "-o",
            "a.urdf",
        ]);
        assert_eq!(a.status.code(), Some(0), "--digits {digits}");
        let b = run(&[
            "fill",
            "a.urdf",
            "--density-map",
            "densities.toml",
            "--digits",
            digits,
            "-o",
            "b.urdf",
        ]);
        assert_eq!(b.status.code(), Some(0), "--digits {digits}");
        let (ta, tb) = (
            std::fs::read_to_string(dir.join("a.urdf")).expect("a"),
            std::fs::read_to_string(dir.join("b.urdf")).expect("b"),
        );
        assert_eq!(ta, tb, "--digits {digits} is not idempotent");
        let check = run(&["check", "a.urdf"]);
        assert_eq!(
            check.status.code(),
            Some(0),
            "--digits {digits}: {}",
            String::from_utf8_lossy(&check.stdout)
        );
    }
}
