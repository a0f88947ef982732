//! What the `xacro` and `yaml` fuzz targets do with one input, shared with tests/xacro.rs so that
//! the seeds (and a grown corpus) replay through the same code without instrumentation.
//!
//! The expander reads files (includes, `load_yaml`), so an input is written to a file in a
//! directory of its own first; nothing outside that directory is written.

use std::collections::HashMap;
use std::path::Path;
use urdf_inertia::urdf::resolve::PackageResolver;
use urdf_inertia::write::WriteOptions;
use urdf_inertia::xacro::{self, Options};

/// A xacro source that loads `f.yaml` and prints what it holds, for the `yaml` target.
const LOAD_YAML: &str = r#"<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="y">
  <xacro:property name="y" value="${xacro.load_yaml('f.yaml')}"/>
  <link name="${str(y)}"/>
  <link name="${y}"/>
</robot>
"#;

fn expand(path: &Path, dir: &Path) -> Option<xacro::Expansion> {
    let resolver = PackageResolver::new();
    let opts = Options {
        args: Vec::new(),
        resolver: &resolver,
        env: HashMap::new(),
        cwd: dir.to_path_buf(),
    };
    xacro::expand_file(path, &opts).ok()
}

/// One xacro source: expanded; when it expands, the result scanned as a URDF and, as `fill -i`
/// does, a sphere's inertial spliced into every link written literally in its source file.
/// Errors are the expected outcome of most inputs; a panic is the bug.
pub fn xacro(data: &[u8], dir: &Path) {
    let path = dir.join("fuzz.urdf.xacro");
    std::fs::write(&path, data).expect("write the input");
    let Some(x) = expand(&path, dir) else { return };
    let Ok(robot) = urdf_inertia::urdf::scan(x.text.clone(), &path) else {
        return;
    };
    let mut spans: HashMap<usize, Vec<(usize, usize)>> = HashMap::new();
    for link in &robot.links {
        if let Some(o) = x.origin(link.line) {
            let _ = (x.at(o), x.calls_text(o));
            if o.literal.is_ok() {
                spans.entry(o.file).or_default().push((o.start, o.end));
            }
        }
    }
    for (file, spans) in spans {
        let Ok(source) = x.source_robot(file, &spans) else {
            continue;
        };
        let updates: Vec<_> = (0..source.links.len())
            .map(|i| (i, urdf_inertia::mass::primitives::sphere(0.1, 1000.0)).into())
            .collect();
        let _ = urdf_inertia::urdf::write::splice(&source, &updates, &WriteOptions::default());
    }
}

/// One YAML file, loaded by `xacro.load_yaml` from a fixed source and printed.
pub fn yaml(data: &[u8], dir: &Path) {
    let top = dir.join("load_yaml.urdf.xacro");
    if !top.exists() {
        std::fs::write(&top, LOAD_YAML).expect("write the loader");
    }
    std::fs::write(dir.join("f.yaml"), data).expect("write the input");
    let _ = expand(&top, dir);
}
