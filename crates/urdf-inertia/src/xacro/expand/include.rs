//! Includes (read in place, optionally into a name space), their globs, and `xacro.load_yaml`.

use super::env::GlobalsOnly;
use super::{Expander, MacroEntry, MacroTable, Slot, Table, MAX_INCLUDE_DEPTH, R};
use crate::xacro::dom::{Element, Node};
use crate::xacro::expr::{self};
use crate::xacro::value::Value;
use crate::xacro::FileKind;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// What to write instead of a URI in an include's filename: xacro (2.1.1, `abs_filename_spec`)
/// takes it as a path relative to the including file, so `package://` fails there too (seen in
/// example-robot-data's hector `quadrotor_base.xacro`).
fn uri_hint(name: &str) -> String {
    if let Some(rest) = name.strip_prefix("package://") {
        let (package, file) = rest.split_once('/').unwrap_or((rest, ""));
        format!(
            " (xacro reads an include's filename as a path, not a URI, and fails here too: \
             write filename=\"$(find {package})/{file}\")"
        )
    } else if let Some(path) = name.strip_prefix("file://") {
        format!(
            " (xacro reads an include's filename as a path, not a URI: write filename=\"{path}\")"
        )
    } else {
        String::new()
    }
}

impl Expander<'_> {
    pub(super) fn include(
        &mut self,
        e: &Rc<Element>,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
        parent_attrs: &mut Vec<(String, String)>,
    ) -> R<()> {
        self.known_attrs(e, &["filename", "ns", "optional"]);
        let spec = self.required(e, "filename")?;
        let (ns_macros, ns_symbols) = match e.attr("ns") {
            Some(ns) if !ns.is_empty() => {
                let ns = self.eval_text(ns, symbols)?.to_py_str();
                let m = MacroTable::new(None);
                let s = Table::new(Some(symbols.clone()), true);
                macros
                    .defs
                    .borrow_mut()
                    .insert(ns.clone(), Rc::new(MacroEntry::Namespace(m.clone())));
                symbols
                    .vars
                    .borrow_mut()
                    .insert(ns, Slot::Val(Value::Namespace(s.clone())));
                (m, s)
            }
            _ => (macros.clone(), symbols.clone()),
        };
        let optional = match e.attr("optional") {
            Some(o) => self.boolean(&Value::str(o), o)?,
            None => false,
        };
        if e.elements().next().is_some() {
            self.warn("Child elements of a <xacro:include> tag are ignored");
        }
        let name = self.eval_text(&spec, symbols)?.to_py_str();
        let path = self.relative_to_current(&name);
        let files = if name.contains(['*', '[', '?']) {
            self.glob(&path)?
        } else {
            vec![path]
        };
        if self.filestack.len() >= MAX_INCLUDE_DEPTH {
            return Err(self.err(format!(
                "includes nested deeper than {MAX_INCLUDE_DEPTH} (a file including itself?)"
            )));
        }
        for path in files {
            if optional && !path.exists() {
                continue;
            }
            let k = self
                .read(&path, FileKind::Xacro)
                .map_err(|m| self.err(format!("cannot include {name}: {m}{}", uri_hint(&name))))?;
            let root = self.parse_file(k)?;
            self.filestack.push(k);
            let r = self.expand_element(&root, &ns_macros, &ns_symbols);
            self.filestack.pop();
            let expanded = r?;
            for (k, v) in &expanded.attrs {
                if k.starts_with("xmlns:") {
                    match parent_attrs.iter().find(|(p, _)| p == k) {
                        Some((_, old)) if old != v => {
                            self.warn(&format!("inconsistent namespace redefinitions for {k}"));
                        }
                        Some(_) => {}
                        None => parent_attrs.push((k.clone(), v.clone())),
                    }
                }
            }
            out.extend(expanded.children);
        }
        Ok(())
    }

    /// Files matching a glob in their last path component, sorted (xacro's include globbing).
    fn glob(&mut self, pattern: &Path) -> R<Vec<PathBuf>> {
        let dir = pattern.parent().unwrap_or(Path::new("."));
        let name = pattern
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if dir.to_string_lossy().contains(['*', '[', '?']) {
            return Err(self.err(format!(
                "include pattern {}: wildcards are supported in the file name only",
                pattern.display()
            )));
        }
        let matcher = globset::Glob::new(&name)
            .map_err(|e| self.err(format!("include pattern {name}: {e}")))?
            .compile_matcher();
        let dir_for_read = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        let mut found: Vec<PathBuf> = std::fs::read_dir(dir_for_read)
            .map(|rd| {
                rd.filter_map(Result::ok)
                    .filter(|d| matcher.is_match(d.file_name()))
                    .map(|d| dir.join(d.file_name()))
                    .collect()
            })
            .unwrap_or_default();
        found.sort();
        if found.is_empty() {
            self.warn(&format!(
                "Include tag's filename spec \"{}\" matched no files.",
                pattern.display()
            ));
        }
        Ok(found)
    }

    pub(super) fn load_yaml(&mut self, spec: &str) -> Result<Value, String> {
        let path = self.relative_to_current(spec);
        let k = self.read(&path, FileKind::Yaml)?;
        if let Some(v) = self.yaml.get(&k) {
            return Ok(v.clone());
        }
        let text = self.files[k].text.clone();
        let mut units = |s: &str| -> Result<f64, String> {
            let mut env = GlobalsOnly;
            let v = expr::eval_str(s, &mut env)?;
            v.as_f64().ok_or_else(|| format!("invalid expression: {s}"))
        };
        let v = crate::xacro::yaml::load(&text, &mut units)
            .map_err(|e| format!("{}: {e}", self.files[k].path.display()))?;
        self.yaml.insert(k, v.clone());
        Ok(v)
    }
}
