//! xacro sources: expanding `.xacro` / `.urdf.xacro` files in process, with the semantics of ROS 2
//! xacro 2.x, and a source map from the expanded URDF back to the files and lines it came from.
//!
//! This module owns the xacro language: properties (lazy, `scope="parent"`/`"global"`, property
//! blocks, `default`, `remove`), macros (parameters with `:=` defaults, `^` and `^|` forwarding,
//! `*block` and `**block` parameters, `xacro:insert_block`, `xacro:call`), `xacro:include`
//! (relative paths, `$(find pkg)`, `ns`, `optional`, wildcards in the file name), `xacro:arg` with
//! `$(arg …)`, `xacro:if`/`xacro:unless`, `xacro:element`/`xacro:attribute`, `${…}` Python-subset
//! expressions (see [`expr`] for the subset), `$(eval …)`, `$(env …)`, `$(optenv …)`,
//! `$(dirname)`, `$(cwd)`, the `$$` escapes and `xacro:eval-comments`. Numbers print as Python's
//! `str` prints them. An unknown `xacro:` element is an error (`unknown macro name`), as in xacro;
//! so are an undefined property or argument, a missing include, a bad expression and recursion,
//! each at the file and line of the element being expanded, with the macro calls that led there.
//!
//! Deliberate differences from xacro 2.1.1, all on inputs xacro refuses or mishandles:
//! `$(dirname)` is the directory of the file being expanded (xacro 2.1.1 leaves its context unset
//! and fails); Python's unbounded integers are 64-bit here (an overflow is an error, never a wrong
//! value); `lambda` is refused with a message; an `xacro:attribute` whose value is not a string
//! (`value="${3}"`) is written as Python's `str` of it (xacro 2.1.1 stops with an `AttributeError`
//! while printing the document).
//!
//! Packages for `$(find pkg)` are found by the resolver meshes use
//! ([`crate::urdf::resolve::PackageResolver`]); `package://` URIs stay as they are written. Every
//! file read (xacro, YAML) goes through the input guard ([`crate::input`]). No process-wide state:
//! arguments, the environment, the working directory and the resolver are passed in [`Options`].
//!
//! Why not the `xacro-rs` crate (0.2.2, the Rust xacro on crates.io): measured against xacrodoc
//! 2.0.1 on the 26 top-level expansions of the shared corpus (docs/xacro.md), it expands the 18 UR
//! and 2 Robotiq ones identically but fails all 6 Franka ones (`xyz.split(' ')[2]` does not
//! parse; `'' if no_prefix else …` is a type error); its documentation lists
//! `xacro:element`/`xacro:attribute`, `in` and `%` formatting as missing too. And it builds an
//! `xmltree` without source positions, so nothing in its output can be traced to a file and line,
//! which diagnostics and write-back need. This expander matches xacrodoc on all 26.
//!
//! The YAML of `load_yaml` is read with saphyr-parser and resolved as `PyYAML` resolves it
//! (`yaml`).

mod builtins;
pub mod dom;
mod expand;
pub mod expr;
pub mod value;
mod yaml;

use crate::urdf::resolve::PackageResolver;
use crate::urdf::scan::SourceEncoding;
use crate::urdf::Robot;
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::rc::Rc;

pub use dom::Call;

/// Longest text a value may grow to (a property doubling itself a few dozen times would
/// otherwise take all memory).
pub(crate) const MAX_TEXT: usize = 1 << 24;

/// Most elements one expansion may produce (macros calling macros multiply): 1000 times the UR
/// description's expansion; each element held costs about 600 bytes (docs/xacro.md).
pub(crate) const MAX_ELEMENTS: usize = 250_000;
pub use expand::Table;

/// What an expansion reads from the outside: everything is passed in.
#[derive(Debug)]
pub struct Options<'r> {
    /// `NAME:=VALUE` arguments, before the files' own `xacro:arg` defaults.
    pub args: Vec<(String, String)>,
    /// Finds packages for `$(find pkg)`.
    pub resolver: &'r PackageResolver,
    /// The environment for `$(env …)` and `$(optenv …)`.
    pub env: HashMap<String, String>,
    /// The working directory, for `$(cwd)` and to make `$(find)`/`$(dirname)` absolute.
    pub cwd: PathBuf,
}

/// What a file read during the expansion is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Xacro,
    Yaml,
}

/// A file the expansion read, with its text.
#[derive(Debug, Clone)]
pub struct SourceFile {
    pub path: PathBuf,
    pub text: String,
    pub encoding: SourceEncoding,
    pub kind: FileKind,
}

/// Why a file cannot be expanded: where (the file and line of the element being expanded) and
/// through which macro calls (innermost first: macro name, file, line of the call).
#[derive(Debug, Clone, PartialEq)]
pub struct XacroError {
    pub file: PathBuf,
    pub line: usize,
    pub message: String,
    pub calls: Vec<(String, PathBuf, usize)>,
}

impl fmt::Display for XacroError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "{}:{}: {}", self.file.display(), self.line, self.message)?;
        } else {
            write!(f, "{}: {}", self.file.display(), self.message)?;
        }
        for (k, (name, file, line)) in self.calls.iter().enumerate() {
            let sep = if k == 0 {
                " (in macro"
            } else {
                ", called from macro"
            };
            write!(f, "{sep} {name} called at {}:{line}", file.display())?;
        }
        if !self.calls.is_empty() {
            write!(f, ")")?;
        }
        Ok(())
    }
}

impl std::error::Error for XacroError {}

/// Where an element of the expanded document was written.
#[derive(Debug, Clone)]
pub struct Origin {
    /// Index into [`Expansion::files`].
    pub file: usize,
    pub line: usize,
    /// The macro calls that produced it, outermost first (empty: written where it stands).
    pub calls: Rc<[Call]>,
    /// The element's byte span in its file.
    pub start: usize,
    pub end: usize,
    /// For a `<link>`: `Ok` when every expansion of the place makes the same link (no xacro
    /// element inside; in a macro body, nothing computed inside but its name), so a value can be
    /// written into it there; else why not.
    pub literal: Result<(), String>,
    /// Its `name` attribute is written without `${…}` or `$(…)`: every expansion gives it that name.
    pub name_literal: bool,
}

/// An expanded document and its source map.
#[derive(Debug)]
pub struct Expansion {
    /// The URDF text.
    pub text: String,
    /// Every file read, the top-level one first.
    pub files: Vec<SourceFile>,
    /// Per line of `text` (index 0 is line 1), the element that starts there.
    origins: Vec<Option<Origin>>,
    /// Warnings of the expansion (`file:line: message`), as xacro prints them.
    pub warnings: Vec<String>,
    cwd: PathBuf,
}

impl Expansion {
    /// The origin of the element starting on line `line` of the expanded text.
    pub fn origin(&self, line: usize) -> Option<&Origin> {
        self.origins.get(line.checked_sub(1)?)?.as_ref()
    }

    /// A path as messages show it: relative to the working directory when it lies under it.
    pub fn display_path(&self, path: &Path) -> String {
        path.strip_prefix(&self.cwd)
            .unwrap_or(path)
            .display()
            .to_string()
    }

    /// `file:line` of an origin.
    pub fn at(&self, o: &Origin) -> String {
        format!("{}:{}", self.display_path(&self.files[o.file].path), o.line)
    }

    /// The macro calls of an origin, innermost first, as ` (macro m called at f:l, from macro n
    /// called at g:l)`; empty for an element written where it stands.
    pub fn calls_text(&self, o: &Origin) -> String {
        if o.calls.is_empty() {
            return String::new();
        }
        let parts: Vec<String> = o
            .calls
            .iter()
            .rev()
            .map(|c| {
                format!(
                    "macro {} called at {}:{}",
                    c.macro_name,
                    self.display_path(&self.files[c.file].path),
                    c.line
                )
            })
            .collect();
        format!(" ({})", parts.join(", from "))
    }

    /// The source file `file` as a URDF [`Robot`] holding the given literal links (by their byte
    /// spans there), for [`crate::urdf::write::splice`]: every span is in the file's own text,
    /// so splicing writes into the source, byte for byte elsewhere.
    pub fn source_robot(&self, file: usize, spans: &[(usize, usize)]) -> Result<Robot, String> {
        const PREFIX: &str = "<robot name=\"source\">";
        let src = &self.files[file];
        // The links alone, at their own offsets and lines: everything else blanked (line breaks
        // and tabs kept, so lines and indentation stay).
        let mut blank: Vec<u8> = src
            .text
            .bytes()
            .map(|b| {
                if matches!(b, b'\n' | b'\r' | b'\t') {
                    b
                } else {
                    b' '
                }
            })
            .collect();
        for &(s, e) in spans {
            let (s, e) = (s.min(blank.len()), e.min(blank.len()));
            blank[s..e].copy_from_slice(&src.text.as_bytes()[s..e]);
        }
        let body = String::from_utf8(blank).map_err(|e| e.to_string())?;
        let synthetic = format!("{PREFIX}{body}</robot>");
        let mut robot = crate::urdf::scan(synthetic, &src.path).map_err(|e| e.message)?;
        let shift = PREFIX.len();
        for l in &mut robot.links {
            l.start -= shift;
            l.open_end -= shift;
            for s in l.inertial.iter_mut().chain(l.extra_inertials.iter_mut()) {
                s.start -= shift;
                s.end -= shift;
            }
        }
        robot.text.clone_from(&src.text);
        robot.encoding = src.encoding;
        robot.newline = if src.text.contains("\r\n") {
            "\r\n"
        } else {
            "\n"
        };
        robot.notes.clear();
        Ok(robot)
    }
}

/// Whether a file is a xacro source: by its extension (`.xacro`), or by a root element that
/// declares the xacro namespace in a document that uses it (`<xacro:…>` elements). A URDF that
/// only carries the declaration (older xacro output) stays a URDF.
pub fn is_xacro(path: &Path, bytes: &[u8]) -> bool {
    if path.extension().is_some_and(|e| e == "xacro") {
        return true;
    }
    let head = &bytes[..bytes.len().min(1 << 16)];
    let text = String::from_utf8_lossy(head);
    let Some(root) = text
        .match_indices('<')
        .map(|(k, _)| &text[k..])
        .find(|t| !t.starts_with("<?") && !t.starts_with("<!"))
    else {
        return false;
    };
    let tag_end = root.find('>').unwrap_or(root.len());
    root[..tag_end].contains("xmlns:xacro") && String::from_utf8_lossy(bytes).contains("<xacro:")
}

/// Expands the xacro file at `path`.
pub fn expand_file(path: &Path, opts: &Options) -> Result<Expansion, XacroError> {
    expand_source(path, None, opts)
}

/// Expands the xacro file at `path` whose bytes the caller has read already (`Some`), or reads it
/// (`None`); the files it includes are read as [`expand_file`] reads them.
pub fn expand_source(
    path: &Path,
    bytes: Option<Vec<u8>>,
    opts: &Options,
) -> Result<Expansion, XacroError> {
    let mut x = expand::Expander::new(opts);
    if let Some(bytes) = bytes {
        x.preload(path, bytes).map_err(|message| XacroError {
            file: path.to_path_buf(),
            line: 0,
            message,
            calls: Vec::new(),
        })?;
    }
    let root = x.run(path)?;
    let top = x.files[0].path.display().to_string();
    let banner = [
        format!(" {} ", "=".repeat(83)),
        format!(" |    This document was autogenerated by xacro from {top:<30} | "),
        format!(
            " |    EDITING THIS FILE BY HAND IS NOT RECOMMENDED  {:<30} | ",
            ""
        ),
        format!(" {} ", "=".repeat(83)),
    ];
    let printed = dom::print(&banner, &root);
    let origins = printed
        .line_elements
        .iter()
        .map(|e| {
            e.map(|e| {
                let calls = e.calls.clone().unwrap_or_else(|| Rc::from(Vec::new()));
                let literal = if e.name == "link" {
                    literal(e, &calls)
                } else {
                    Err("not a link".to_string())
                };
                Origin {
                    file: e.src.file,
                    line: e.src.line,
                    calls,
                    start: e.src.start,
                    end: e.src.end,
                    literal,
                    name_literal: e.src.name_literal,
                }
            })
        })
        .collect();
    Ok(Expansion {
        text: printed.text,
        files: x.files,
        origins,
        warnings: x.warnings,
        cwd: opts.cwd.clone(),
    })
}

/// Whether `fill -i` may write the link's `<inertial>` where the link is written: nothing inside
/// it comes from xacro elements, and, in a macro body, nothing inside it is computed (`${…}`,
/// `$(arg …)`; its name may be), so every call of the macro expands it to the same link. A link
/// expanded several times (a macro called more than once) is written when every expansion computes
/// the same `<inertial>` (the writer compares them).
fn literal(e: &dom::Element, calls: &[Call]) -> Result<(), String> {
    if e.src.xacro_inside {
        return Err(
            "part of it comes from xacro (a macro call, condition or block inside it)".into(),
        );
    }
    if e.src.in_macro && e.src.computed_inside {
        let m = calls.last().map_or("a", |c| c.macro_name.as_str());
        return Err(format!(
            "it is written in the body of macro {m} with values xacro computes inside it (`${{…}}` or `$(…)`), which may differ from call to call"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests;
