//! The JSON of `fill`, `diff`, `check` and `mesh` against docs/schema/: the committed schemas are the
//! ones the report types generate (`urdf_inertia::report`, schemars), and every command's output on
//! the repository's robots and on robots made here validates against them with a validator that is
//! not the generator (the `jsonschema` crate).
//!
//! Regenerate the schemas after changing a report type:
//! `UPDATE_SCHEMA=1 cargo test --release --test schema`, then commit docs/schema/.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

// The test helpers are the library tests' own (mesh generators).
#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;

const REGENERATE: &str = "UPDATE_SCHEMA=1 cargo test --release --test schema";

fn schema_path(command: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("docs/schema/{command}.schema.json"))
}

/// The committed schema of a command, parsed.
fn committed(command: &str) -> Value {
    let path = schema_path(command);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}; `{REGENERATE}` writes it", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_committed_schemas_are_the_ones_the_types_generate() {
    let update = std::env::var_os("UPDATE_SCHEMA").is_some();
    let mut stale = Vec::new();
    for (command, schema) in urdf_inertia::report::schemas() {
        let text = serde_json::to_string_pretty(&schema).expect("schema as JSON") + "\n";
        let path = schema_path(command);
        if update {
            std::fs::create_dir_all(path.parent().expect("docs/schema")).expect("mkdir");
            std::fs::write(&path, &text).expect("write the schema");
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
            stale.push(path.display().to_string());
        }
        // A schema itself valid against its meta-schema (2020-12).
        jsonschema::meta::validate(&schema)
            .unwrap_or_else(|e| panic!("{command}: not a valid JSON Schema: {e}"));
    }
    assert!(
        stale.is_empty(),
        "{} differ from what the report types generate: run `{REGENERATE}` and commit docs/schema/",
        stale.join(", ")
    );
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
}

/// Runs the binary (without the user's configuration file) and parses its stdout as JSON.
fn json_of(args: &[&str], exit: i32) -> Value {
    let out: Output = bin()
        .args(args)
        .arg("--no-config")
        .output()
        .expect("run urdf-inertia");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(exit), "{args:?}: {stderr}");
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{args:?}: no JSON on stdout ({e}): {}\n{stderr}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

/// Validates `document` against the committed schema of `command`, listing every error.
fn assert_valid(command: &str, document: &Value, what: &str) {
    let schema = committed(command);
    let validator = jsonschema::validator_for(&schema).expect("the schema compiles");
    let errors: Vec<String> = validator
        .iter_errors(document)
        .map(|e| format!("{} at {}", e, e.instance_path()))
        .collect();
    assert!(
        errors.is_empty(),
        "{what}: {command}'s JSON does not validate against docs/schema/{command}.schema.json:\n{}\n{document:#}",
        errors.join("\n")
    );
    assert_eq!(document["schema_version"], 1, "{what}");
}

fn demo() -> (PathBuf, PathBuf) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/demo_arm_description");
    (root.join("urdf/demo_arm.urdf"), root.join("densities.toml"))
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// A robot with a bit of everything a report can say: two overlapping boxes (a link warning) with
/// a unit slip in their `<inertial>` and a second `<inertial>`, an inside-out mesh (a repaired
/// part), an `<inertial>` whose mass is `nan`, a link without an `<inertial>`, a frame.
const MIXED: &str = r#"<robot name="mixed">
  <link name="trunk">
    <inertial><mass value="0.0015"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <collision><origin xyz="0.05 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="leg">
    <collision><geometry><mesh filename="cube.stl"/></geometry></collision>
  </link>
  <link name="odd">
    <inertial><mass value="nan"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <link name="frame"/>
</robot>
"#;

/// `text` as mixed.urdf beside the inside-out cube.stl it uses, in a temp dir.
fn mixed_robot(text: &str) -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().expect("tempdir");
    common::inside_out_cube_stl(&tmp.path().join("cube.stl"));
    let urdf = tmp.path().join("mixed.urdf");
    std::fs::write(&urdf, text).expect("write");
    (tmp, urdf)
}

/// The same robot with a link whose mesh is missing: `fill` fails that link.
fn failing(text: &str) -> String {
    text.replace(
        "  <link name=\"frame\"/>",
        "  <link name=\"hand\">\n    <collision><geometry><mesh filename=\"missing.stl\"/></geometry></collision>\n  </link>\n  <link name=\"frame\"/>",
    )
}

/// The demo robot, as the README runs it: every command.
#[test]
fn the_demo_robots_json_validates() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let out = tmp.path().join("out.urdf");
    let (urdf, map) = demo();
    let (u, m, o) = (s(&urdf), s(&map), s(&out));

    let fill = json_of(
        &["fill", u, "--density-map", m, "-o", o, "--format", "json"],
        0,
    );
    assert_valid("fill", &fill, "fill demo");
    assert_eq!(fill["written"], true);
    assert_eq!(fill["links"].as_array().map(Vec::len), Some(6));
    let diff = json_of(&["diff", u, "--density-map", m, "--format", "json"], 1);
    assert_valid("diff", &diff, "diff demo");
    let check = json_of(&["check", u, "--format", "json"], 1);
    assert_valid("check", &check, "check demo");
    let check = json_of(&["check", u, "--density-map", m, "--format", "json"], 1);
    assert_valid("check", &check, "check demo with densities");
    let meshes = urdf
        .parent()
        .and_then(Path::parent)
        .expect("package")
        .join("meshes");
    for mesh in [
        "battery.stl",
        "forearm.dae",
        "upper_arm.obj",
        "shoulder.STL",
    ] {
        let p = meshes.join(mesh);
        let v = json_of(&["mesh", s(&p), "--density", "1000", "--format", "json"], 0);
        assert_valid("mesh", &v, mesh);
    }
    // A mesh that gives no solid is a document too (exit 2): the file and why, with a code.
    let empty = tmp.path().join("empty.stl");
    std::fs::write(&empty, "solid x\nendsolid x\n").expect("write");
    let v = json_of(&["mesh", s(&empty), "--format", "json"], 2);
    assert_valid("mesh", &v, "mesh without faces");
    assert_eq!(v["error"]["code"], "UI703");
    assert_eq!(v["error"]["kind"], "mesh");
    assert!(v.get("volume").is_none(), "{v:#}");
}

/// A robot with repairs, warnings, a unit slip, a `nan` and duplicates: `fill`, `diff`, `check`
/// (with a baseline too) and `mesh` on its inside-out cube.
#[test]
fn repairs_warnings_and_problems_validate() {
    let (tmp, mixed) = mixed_robot(MIXED);
    let x = s(&mixed);
    let out = tmp.path().join("out.urdf");
    let o = s(&out);
    let warn = ["--note-below", "0"];
    let fill = json_of(
        &[
            &["fill", x, "--density", "1000", "-o", o, "--format", "json"],
            &warn[..],
        ]
        .concat(),
        0,
    );
    assert_valid("fill", &fill, "fill mixed");
    let leg = &fill["links"][1];
    assert_eq!(leg["link"], "leg");
    assert_eq!(leg["parts"][0]["provenance"], "inverted");
    assert_eq!(leg["parts"][0]["warnings"][0]["code"], "UI101");
    assert_eq!(fill["links"][0]["warnings"][0]["code"], "UI401");
    // The `nan` has no JSON form: null, which the schema allows for an existing value.
    let odd = &fill["links"][2];
    assert_eq!(odd["link"], "odd");
    assert!(odd["existing"]["mass"].is_null(), "{odd:#}");
    let diff = json_of(
        &[
            &["diff", x, "--density", "1000", "--format", "json"],
            &warn[..],
        ]
        .concat(),
        1,
    );
    assert_valid("diff", &diff, "diff mixed");
    let trunk = &diff["links"][0];
    assert_eq!(trunk["differs"], true);
    assert_eq!(trunk["differences"][0]["quantity"], "mass");
    let check = json_of(
        &[
            &["check", x, "--density", "1000", "--format", "json"],
            &warn[..],
        ]
        .concat(),
        1,
    );
    assert_valid("check", &check, "check mixed");
    let codes: Vec<&str> = check["links"]
        .as_array()
        .expect("links")
        .iter()
        .flat_map(|l| l["problems"].as_array().expect("problems"))
        .filter_map(|p| p["code"].as_str())
        .collect();
    assert!(
        codes.contains(&"UI603") && codes.contains(&"UI602"),
        "{codes:?}"
    );
    // With a baseline of today's problems nothing fails, and the counts say so.
    let baseline = tmp.path().join("known.txt");
    let b = s(&baseline);
    bin()
        .args(["check", x, "--no-config", "--write-baseline", b])
        .output()
        .expect("run");
    let check = json_of(&["check", x, "--baseline", b, "--format", "json"], 0);
    assert_valid("check", &check, "check mixed against its baseline");
    assert_eq!(check["problem_count"], 0);
    assert!(check["known_in_baseline"].as_u64().is_some_and(|k| k > 0));

    // An inside-out mesh alone, with its warning.
    let cube = tmp.path().join("cube.stl");
    let v = json_of(
        &[
            "mesh",
            s(&cube),
            "--density",
            "1000",
            "--format",
            "json",
            "--note-below",
            "0",
        ],
        0,
    );
    assert_valid("mesh", &v, "mesh inside out");
    assert_eq!(v["warnings"][0]["code"], "UI101");
}

/// Links that fail and a robot-wide error: the JSON all the same, with the errors.
#[test]
fn failures_validate() {
    // A failing link: nothing written, the errors in the JSON, exit 2; with --keep-going written.
    let (tmp, failing_urdf) = mixed_robot(&failing(MIXED));
    let f = s(&failing_urdf);
    let out = tmp.path().join("out.urdf");
    let o = s(&out);
    let fill = json_of(
        &["fill", f, "--density", "1000", "-o", o, "--format", "json"],
        2,
    );
    assert_valid("fill", &fill, "fill failing");
    assert_eq!(fill["written"], false);
    assert_eq!(fill["errors"][0]["kind"], "mesh-not-found");
    let fill = json_of(
        &[
            "fill",
            f,
            "--density",
            "1000",
            "-o",
            o,
            "--format",
            "json",
            "--keep-going",
        ],
        2,
    );
    assert_valid("fill", &fill, "fill failing --keep-going");
    assert_eq!(fill["written"], true);
    let check = json_of(&["check", f, "--density", "1000", "--format", "json"], 2);
    assert_valid("check", &check, "check failing");
    assert!(check["errors"].as_u64().is_some_and(|e| e > 0));

    // A robot-wide error: densities for some links only.
    let partial = tmp.path().join("partial.toml");
    std::fs::write(&partial, "[links]\ntrunk = 1000\n").expect("write");
    let fill = json_of(
        &[
            "fill",
            f,
            "--density-map",
            s(&partial),
            "-o",
            o,
            "--format",
            "json",
        ],
        2,
    );
    assert_valid("fill", &fill, "fill without every density");
    assert!(fill["errors"]
        .as_array()
        .expect("errors")
        .iter()
        .any(|e| e["link"].is_null() && e["code"] == "UI707"));
}
