//! The layering of the workspace: the library (`urdf-inertia`) is what a Rust user depends on, the
//! command line (`urdf-inertia-cli`) is a crate of its own over it. Cargo keeps the library from naming
//! the CLI (a dependency cycle); this test keeps the binary's dependencies out of the library's tree.

use std::process::Command;

#[test]
fn the_library_tree_has_no_binary_dependencies() {
    let out = Command::new(env!("CARGO"))
        .args([
            "tree",
            "--offline",
            "--locked",
            "-p",
            "urdf-inertia",
            "-e",
            "normal,build",
            "--prefix",
            "none",
            "--format",
            "{p}",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let tree = String::from_utf8_lossy(&out.stdout);
    let crates: Vec<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(crates.contains(&"urdf-inertia"), "{tree}");
    assert!(crates.contains(&"quick-xml"), "{tree}");
    for binary_only in ["clap", "signal-hook", "mimalloc", "urdf-inertia-cli"] {
        assert!(
            !crates.contains(&binary_only),
            "the library depends on {binary_only}:\n{tree}"
        );
    }
}
