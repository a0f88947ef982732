//! Mesh URIs to files: `package://NAME/rest` (also `package:///NAME/rest`), `file://`, and plain paths
//! relative to the URDF.
//!
//! A package is looked up, in order: the packages given by name (`--package-path NAME=DIR`; DIR is the
//! package's own directory), then each entry of the ROS package path (a package directory itself, or a
//! tree containing it), then each ament prefix's `share/NAME`, then walking up from the URDF's
//! directory to a directory that is the package (holds a `package.xml` naming it, or is named like it)
//! or that contains one. The resolver reads no environment: the command line passes
//! `ROS_PACKAGE_PATH` and `AMENT_PREFIX_PATH` in.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// How to find packages.
#[derive(Debug, Clone)]
pub struct PackageResolver {
    explicit: HashMap<String, PathBuf>,
    ros_package_path: Vec<PathBuf>,
    ament_prefix_path: Vec<PathBuf>,
    /// The largest `package.xml` read, in bytes.
    max_file_size: u64,
    cache: Found,
}

/// What walking up from a directory found for a package: its directory, none, or an unreadable
/// `package.xml` on the way.
type WalkResult = Result<Option<PathBuf>, String>;

/// The package directories found by walking up, per (package, directory): shared by the threads that
/// compute links (a lock, as a lookup is rare next to their work).
#[derive(Debug, Default)]
struct Found(std::sync::Mutex<HashMap<(String, PathBuf), WalkResult>>);

impl Found {
    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<(String, PathBuf), WalkResult>> {
        self.0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

impl Clone for Found {
    fn clone(&self) -> Self {
        Found(std::sync::Mutex::new(self.lock().clone()))
    }
}

impl Default for PackageResolver {
    fn default() -> Self {
        Self::new()
    }
}

/// A mesh URI that names no existing file.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct NotFound {
    pub uri: String,
    /// Every place looked at, in order.
    pub searched: Vec<PathBuf>,
    pub hint: String,
}

impl PackageResolver {
    /// A resolver that knows no package by name and no search path: `package://NAME` is found by
    /// walking up from the URDF's directory alone.
    pub fn new() -> Self {
        PackageResolver {
            explicit: HashMap::new(),
            ros_package_path: Vec::new(),
            ament_prefix_path: Vec::new(),
            max_file_size: crate::input::DEFAULT_MAX_FILE_SIZE,
            cache: Found::default(),
        }
    }

    /// The same, with packages given by name and directory (looked up first).
    #[must_use]
    pub fn with_packages(mut self, packages: &[(String, PathBuf)]) -> Self {
        self.explicit.extend(packages.iter().cloned());
        self
    }

    /// The same, with the entries of a ROS package path (`ROS_PACKAGE_PATH`), each a package
    /// directory or a tree containing packages; empty entries are skipped.
    #[must_use]
    pub fn with_ros_package_path(mut self, dirs: impl IntoIterator<Item = PathBuf>) -> Self {
        self.ros_package_path
            .extend(dirs.into_iter().filter(|p| !p.as_os_str().is_empty()));
        self
    }

    /// The same, with ament prefixes (`AMENT_PREFIX_PATH`), whose `share/NAME` is package `NAME`;
    /// empty entries are skipped.
    #[must_use]
    pub fn with_ament_prefix_path(mut self, dirs: impl IntoIterator<Item = PathBuf>) -> Self {
        self.ament_prefix_path
            .extend(dirs.into_iter().filter(|p| !p.as_os_str().is_empty()));
        self
    }

    /// The same, reading no `package.xml` larger than `bytes`.
    #[must_use]
    pub fn with_max_file_size(mut self, bytes: u64) -> Self {
        self.max_file_size = bytes;
        self
    }

    /// The largest file read while resolving, in bytes (xacro reads its includes with it too).
    pub fn max_file_size(&self) -> u64 {
        self.max_file_size
    }

    /// The file a mesh URI names, relative to the URDF at `urdf`.
    pub fn resolve(&self, uri: &str, urdf: &Path) -> Result<PathBuf, NotFound> {
        let base = urdf.parent().map(Path::to_path_buf).unwrap_or_default();
        if let Some(rest) = uri.strip_prefix("package://") {
            let rest = rest.trim_start_matches('/');
            let (pkg, inner) = rest.split_once('/').unwrap_or((rest, ""));
            let mut searched = Vec::new();
            let dirs = self
                .package_dirs(pkg, &base, &mut searched)
                .map_err(|hint| NotFound {
                    uri: uri.to_string(),
                    searched: searched.clone(),
                    hint,
                })?;
            for dir in dirs {
                let p = dir.join(inner);
                if p.is_file() {
                    return Ok(p);
                }
                searched.push(p);
            }
            // Something that is there but not a file (a directory, a FIFO): reading it says so.
            if let Some(p) = searched.iter().find(|p| !inner.is_empty() && p.exists()) {
                return Ok(p.clone());
            }
            let hint = near_file(&searched).unwrap_or_else(|| format!("pass --package-path {pkg}=DIR (DIR is the package's directory), or set ROS_PACKAGE_PATH"));
            return Err(NotFound {
                uri: uri.to_string(),
                searched,
                hint,
            });
        }
        if uri.contains("$(") || uri.contains("${") {
            return Err(NotFound {
                uri: uri.to_string(),
                searched: Vec::new(),
                hint: "this is an unexpanded xacro expression: run `xacro FILE.urdf.xacro > FILE.urdf` first".into(),
            });
        }
        let path = if let Some(rest) = uri.strip_prefix("file://") {
            // As ROS's resource_retriever (curl) reads it: `file://localhost/…` is `file:///…`, and
            // percent escapes (`my%20robot`) are decoded.
            let rest = rest
                .strip_prefix("localhost")
                .filter(|r| r.starts_with('/'))
                .unwrap_or(rest);
            let p = PathBuf::from(percent_decode(rest));
            if p.is_absolute() {
                p
            } else {
                base.join(p)
            }
        } else if uri.contains("://") {
            return Err(NotFound {
                uri: uri.to_string(),
                searched: Vec::new(),
                hint: "only package:// and file:// URIs and plain paths are supported".into(),
            });
        } else {
            let p = PathBuf::from(uri);
            if p.is_absolute() {
                p
            } else {
                base.join(p)
            }
        };
        // Anything that exists: reading a directory or a device says "is not a regular file".
        if path.exists() {
            Ok(path)
        } else {
            let searched = vec![path];
            let hint = near_file(&searched).unwrap_or_else(|| {
                "check the path (relative paths are relative to the URDF's directory)".into()
            });
            Err(NotFound {
                uri: uri.to_string(),
                searched,
                hint,
            })
        }
    }

    /// The directory of package `pkg` as xacro's `$(find pkg)` gives it, searched the way mesh
    /// `package://` URIs are (explicit paths, `ROS_PACKAGE_PATH`, `AMENT_PREFIX_PATH`, walking up
    /// from the directory of `from_file`).
    pub fn package_dir(&self, pkg: &str, from_file: &Path) -> Result<PathBuf, NotFound> {
        let base = from_file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut searched = Vec::new();
        let dirs = self
            .package_dirs(pkg, &base, &mut searched)
            .map_err(|e| NotFound {
                uri: format!("$(find {pkg})"),
                searched: Vec::new(),
                hint: e,
            })?;
        let found = dirs.into_iter().find(|d| d.is_dir());
        found.ok_or_else(|| NotFound {
            uri: format!("$(find {pkg})"),
            searched,
            hint: format!("pass --package-path {pkg}=DIR (DIR is the package's directory), or set ROS_PACKAGE_PATH"),
        })
    }

    /// Candidate directories for package `pkg`, in search order (recording what was looked at); an
    /// unreadable `package.xml` on the way is an error.
    fn package_dirs(
        &self,
        pkg: &str,
        base: &Path,
        searched: &mut Vec<PathBuf>,
    ) -> Result<Vec<PathBuf>, String> {
        let mut out = Vec::new();
        if let Some(d) = self.explicit.get(pkg) {
            out.push(d.clone());
        }
        for root in &self.ros_package_path {
            if is_package(root, pkg, self.max_file_size)? {
                out.push(root.clone());
            } else {
                let cand = root.join(pkg);
                if cand.is_dir() {
                    out.push(cand);
                } else {
                    searched.push(cand);
                }
            }
        }
        for prefix in &self.ament_prefix_path {
            let cand = prefix.join("share").join(pkg);
            if cand.is_dir() {
                out.push(cand);
            } else {
                searched.push(cand);
            }
        }
        let key = (pkg.to_string(), base.to_path_buf());
        let found = self.cache.lock().get(&key).cloned();
        let found = if let Some(f) = found { f } else {
            let f = walk_up(base, pkg, self.max_file_size);
            self.cache.lock().insert(key, f.clone());
            f
        };
        match found? {
            Some(d) => out.push(d),
            None => searched.push(base.join(format!("..(each parent)/{pkg}"))),
        }
        Ok(out)
    }
}

/// `did you mean …?` for a missing file whose name differs from a file in the same directory only
/// in case or by one edit (an inserted, dropped or changed character): the commonest slips in a
/// hand-written mesh path. Only directories that exist are listed, each once.
fn near_file(searched: &[PathBuf]) -> Option<String> {
    let mut seen = std::collections::HashSet::new();
    for p in searched {
        let (Some(dir), Some(name)) = (p.parent(), p.file_name().and_then(|n| n.to_str())) else {
            continue;
        };
        if !seen.insert(dir.to_path_buf()) {
            continue;
        }
        let Ok(entries) = std::fs::read_dir(dir) else {
            continue;
        };
        // A directory of a million files is not worth listing for a hint.
        let mut best: Option<(usize, String)> = None;
        for e in entries.take(100_000).flatten() {
            let Some(other) = e.file_name().to_str().map(str::to_string) else {
                continue;
            };
            let rank = if other.eq_ignore_ascii_case(name) {
                0
            } else if one_edit(&other, name) {
                1
            } else {
                continue;
            };
            if best
                .as_ref()
                .is_none_or(|(r, n)| rank < *r || (rank == *r && other < *n))
            {
                best = Some((rank, other));
            }
        }
        if let Some((_, other)) = best {
            return Some(format!(
                "did you mean `{}`? (in {})",
                crate::text::escape_control(&other),
                crate::text::escape_control(&dir.display().to_string())
            ));
        }
    }
    None
}

/// Whether `a` and `b` differ by exactly one inserted, dropped or changed character.
fn one_edit(a: &str, b: &str) -> bool {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let (short, long) = if a.len() <= b.len() {
        (&a, &b)
    } else {
        (&b, &a)
    };
    if long.len() - short.len() > 1 || a == b {
        return false;
    }
    let head = short
        .iter()
        .zip(long.iter())
        .take_while(|(x, y)| x == y)
        .count();
    if short.len() == long.len() {
        short[head + 1..] == long[head + 1..]
    } else {
        short[head..] == long[head + 1..]
    }
}

/// Decodes `%XX` escapes (an invalid escape stays as it is). Bytes that do not form UTF-8 are replaced.
pub fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|&c| hex(c)),
            b.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8(out).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned())
}

/// Whether `dir` is package `pkg`: its `package.xml` names it, or the directory has the package's name.
/// A `package.xml` that is there but cannot be read through the input guard (a FIFO, a symlink to
/// `/dev/zero`, a file over the size limit) is an error naming it, not a hang or a read without end.
fn is_package(dir: &Path, pkg: &str, max_file_size: u64) -> Result<bool, String> {
    let xml = dir.join("package.xml");
    if xml.exists() {
        let bytes = crate::input::read_file(&xml, max_file_size).map_err(|e| {
            // A limit says how to raise it; anything else is the file's fault.
            let what_to_do = match e {
                crate::input::InputError::TooLarge { .. }
                | crate::input::InputError::OverBudget { .. } => "",
                _ => "; remove or fix it",
            };
            format!(
                "{} {e}{what_to_do} (urdf-inertia reads it to find package `{pkg}`)",
                xml.display()
            )
        })?;
        let text = String::from_utf8_lossy(&bytes);
        if let (Some(a), Some(b)) = (text.find("<name>"), text.find("</name>")) {
            if a < b && text[a + 6..b].trim() == pkg {
                return Ok(true);
            }
        }
    }
    Ok(dir.file_name().and_then(|n| n.to_str()) == Some(pkg))
}

fn walk_up(base: &Path, pkg: &str, max_file_size: u64) -> Result<Option<PathBuf>, String> {
    // `robot.urdf` given relative to the working directory: its folder is "", which is ".".
    let base = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    let start = std::fs::canonicalize(base).unwrap_or_else(|_| base.to_path_buf());
    let mut dir = Some(start.as_path());
    while let Some(d) = dir {
        if is_package(d, pkg, max_file_size)? {
            return Ok(Some(d.to_path_buf()));
        }
        let child = d.join(pkg);
        if child.is_dir() {
            return Ok(Some(child));
        }
        dir = d.parent();
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolves_package_uris_three_ways() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let pkg = tmp.path().join("src").join("my_robot_description");
        std::fs::create_dir_all(pkg.join("meshes")).expect("mkdir");
        std::fs::create_dir_all(pkg.join("urdf")).expect("mkdir");
        std::fs::write(
            pkg.join("package.xml"),
            "<package><name>my_robot_description</name></package>",
        )
        .expect("write");
        std::fs::write(pkg.join("meshes/a.stl"), "solid x\nendsolid x\n").expect("write");
        let urdf = pkg.join("urdf/robot.urdf");
        let r = PackageResolver::new();
        // Walking up from the URDF finds the package.
        assert!(r
            .resolve("package://my_robot_description/meshes/a.stl", &urdf)
            .is_ok());
        assert!(r
            .resolve("package:///my_robot_description/meshes/a.stl", &urdf)
            .is_ok());
        // Explicit path.
        let elsewhere = tmp.path().join("robot.urdf");
        let r2 = PackageResolver::new().with_packages(&[("other".into(), pkg.clone())]);
        assert_eq!(
            r2.resolve("package://other/meshes/a.stl", &elsewhere)
                .expect("explicit"),
            pkg.join("meshes/a.stl")
        );
        // Relative and file://.
        assert!(r.resolve("../meshes/a.stl", &urdf).is_ok());
        assert!(r
            .resolve(
                &format!("file://{}", pkg.join("meshes/a.stl").display()),
                &urdf
            )
            .is_ok());
        assert!(r
            .resolve("$(find my_robot_description)/meshes/a.stl", &urdf)
            .unwrap_err()
            .hint
            .contains("xacro"));
        // file:// percent-decoded, as resource_retriever does.
        let spaced = tmp.path().join("my robot");
        std::fs::create_dir_all(&spaced).expect("mkdir");
        std::fs::write(spaced.join("part one.stl"), "solid x\nendsolid x\n").expect("write");
        let uri = format!("file://{}/my%20robot/part%20one.stl", tmp.path().display());
        assert_eq!(
            r.resolve(&uri, &urdf).expect("percent"),
            spaced.join("part one.stl")
        );
        let uri = format!(
            "file://localhost{}/my%20robot/part%20one.stl",
            tmp.path().display()
        );
        assert_eq!(
            r.resolve(&uri, &urdf).expect("localhost"),
            spaced.join("part one.stl")
        );
        assert_eq!(percent_decode("a%2"), "a%2");
        let nf = r.resolve("package://nope/meshes/a.stl", &urdf).unwrap_err();
        assert!(nf.hint.contains("--package-path nope=DIR"));
    }

    #[test]
    fn a_missing_mesh_names_the_file_one_slip_away() {
        let tmp = tempfile::tempdir().expect("tempdir");
        std::fs::create_dir_all(tmp.path().join("meshes")).expect("mkdir");
        for f in ["Forearm.STL", "wrist.stl", "base.stl"] {
            std::fs::write(tmp.path().join("meshes").join(f), "solid x\nendsolid x\n")
                .expect("write");
        }
        let urdf = tmp.path().join("robot.urdf");
        let r = PackageResolver::new();
        let hint = |uri: &str| r.resolve(uri, &urdf).unwrap_err().hint;
        // Case only.
        assert!(hint("meshes/forearm.stl").starts_with("did you mean `Forearm.STL`?"));
        // One dropped, one inserted, one changed character.
        assert!(hint("meshes/wrst.stl").starts_with("did you mean `wrist.stl`?"));
        assert!(hint("meshes/wristt.stl").starts_with("did you mean `wrist.stl`?"));
        assert!(hint("meshes/wrist.stk").starts_with("did you mean `wrist.stl`?"));
        // Two edits away: the usual hint.
        assert!(hint("meshes/wr.stl").starts_with("check the path"));
        // Through a package:// URI too.
        std::fs::write(
            tmp.path().join("package.xml"),
            "<package><name>p</name></package>",
        )
        .expect("write");
        assert!(hint("package://p/meshes/bse.stl").starts_with("did you mean `base.stl`?"));
        assert!(one_edit("ab", "abc") && one_edit("abc", "axc") && !one_edit("abc", "abc"));
        assert!(!one_edit("abcd", "ab") && !one_edit("abc", "bca"));
    }
}
