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

/// The binary uses the library's facade alone. Its own build (`cargo install`, `cargo build -p
/// urdf-inertia-cli`) enforces that, as the implementation modules are private; but `cargo test`
/// builds it with the `internals` feature its tests enable, so this test reads its sources for a
/// path into a private module.
#[test]
fn the_binary_names_no_private_module() {
    let private = [
        "compare", "density", "error", "fill", "mass", "mesh", "overlap", "problem", "threads",
        "urdf",
    ];
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../src");
    let mut files = vec![src.join("main.rs")];
    let cli = std::fs::read_dir(src.join("cli")).expect("src/cli");
    files.extend(cli.filter_map(Result::ok).map(|e| e.path()));
    let mut found = Vec::new();
    for f in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "rs"))
    {
        let text = std::fs::read_to_string(f).expect("read");
        for (n, line) in text.lines().enumerate() {
            for m in &private {
                if line.contains(&format!("urdf_inertia::{m}::")) {
                    found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}
