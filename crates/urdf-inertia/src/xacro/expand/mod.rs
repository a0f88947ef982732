//! The expansion itself, following ROS 2 xacro 2.x (`xacro/__init__.py`, `substitution_args.py`):
//! `eval_all` over the tree, properties in tables chained by scope and evaluated lazily, macros
//! looked up by (dotted) name and expanded in a new scope whose parent is the caller's, includes
//! read in place (optionally into a name space), `$(…)` substitution arguments.
//!
//! Unlike xacro, the source tree is never changed: each step reads source elements and builds new
//! ones, which carry where they were written and through which macro calls they came.

use super::dom::{self, Call, Element};
use super::expr::{self};
use super::value::Value;
use super::{FileKind, Options, SourceFile, XacroError};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};
use std::rc::Rc;

mod env;
mod include;
mod macros;
mod tree;

use env::{ExprEnv, SubstEnv};

/// Deepest nesting of macro calls (xacro stops at Python's recursion limit).
const MAX_MACRO_DEPTH: usize = 250;
/// Deepest nesting of includes.
const MAX_INCLUDE_DEPTH: usize = 64;

#[derive(Debug, Clone)]
enum Slot {
    /// Text evaluated at first use, in the table that holds it.
    Lazy(String),
    Val(Value),
}

/// A symbol table: properties of one scope, chained to the enclosing one.
#[derive(Debug)]
pub struct Table {
    vars: RefCell<HashMap<String, Slot>>,
    parent: Option<Rc<Table>>,
    /// An include's `ns` table (skipped by `scope="parent"` from a macro).
    namespace: bool,
}

impl Table {
    fn new(parent: Option<Rc<Table>>, namespace: bool) -> Rc<Table> {
        Rc::new(Table {
            vars: RefCell::new(HashMap::new()),
            parent,
            namespace,
        })
    }

    /// Whether `key` is defined here or in an enclosing scope, or is one of xacro's globals.
    fn contains(&self, key: &str) -> bool {
        self.vars.borrow().contains_key(key)
            || self
                .parent
                .as_ref()
                .map_or_else(|| expr::is_global(key), |p| p.contains(key))
    }

    /// The outermost table (xacro's `top()`: the global scope of the document).
    fn top(self: &Rc<Self>) -> Rc<Table> {
        let mut t = self.clone();
        while let Some(p) = t.parent.clone() {
            t = p;
        }
        t
    }

    fn remove_everywhere(&self, key: &str) {
        self.vars.borrow_mut().remove(key);
        if let Some(p) = &self.parent {
            p.remove_everywhere(key);
        }
    }

    /// xacro's `_setitem`: numbers and booleans written as text become typed values; text left
    /// as text is evaluated lazily when `lazy`.
    fn set(&self, key: &str, value: Value, lazy: bool) {
        let value = eval_literal(value);
        let slot = match value {
            Value::Str(s) if lazy => Slot::Lazy(s.to_string()),
            v => Slot::Val(v),
        };
        self.vars.borrow_mut().insert(key.to_string(), slot);
    }
}

/// xacro's `_eval_literal`: `'text'` loses its quotes; a text that reads as an int, a float or a
/// boolean becomes one (text with `_` stays text: Python would drop the underscores).
fn eval_literal(v: Value) -> Value {
    let Value::Str(s) = &v else { return v };
    if s.len() >= 2 && s.starts_with('\'') && s.ends_with('\'') {
        return Value::str(&s[1..s.len() - 1]);
    }
    if s.contains('_') {
        return v;
    }
    if let Some(i) = super::builtins::parse_int(s) {
        return Value::Int(i);
    }
    if let Some(f) = super::builtins::parse_float(s) {
        return Value::Float(f);
    }
    match &**s {
        "true" | "True" => Value::Bool(true),
        "false" | "False" => Value::Bool(false),
        _ => v,
    }
}

struct Macro {
    name: String,
    body: Rc<Element>,
    params: Vec<String>,
    /// Per parameter: forwarded from the caller (`^`), and the default text.
    defaults: HashMap<String, (bool, Option<String>)>,
}

enum MacroEntry {
    Macro(Rc<Macro>),
    Namespace(Rc<MacroTable>),
}

struct MacroTable {
    defs: RefCell<HashMap<String, Rc<MacroEntry>>>,
    parent: Option<Rc<MacroTable>>,
}

impl MacroTable {
    fn new(parent: Option<Rc<MacroTable>>) -> Rc<MacroTable> {
        Rc::new(MacroTable {
            defs: RefCell::new(HashMap::new()),
            parent,
        })
    }

    fn get(&self, name: &str) -> Option<Rc<MacroEntry>> {
        if let Some(e) = self.defs.borrow().get(name) {
            return Some(e.clone());
        }
        self.parent.as_ref().and_then(|p| p.get(name))
    }
}

/// The state of one expansion.
pub(super) struct Expander<'o> {
    opts: &'o Options<'o>,
    pub files: Vec<SourceFile>,
    parsed: HashMap<usize, Rc<Element>>,
    yaml: HashMap<usize, Value>,
    args: HashMap<String, String>,
    filestack: Vec<usize>,
    calls: Rc<[Call]>,
    /// The element being expanded: where an error is reported.
    here: (usize, usize),
    resolving: Vec<String>,
    pub warnings: Vec<String>,
    /// Elements produced so far (against [`super::MAX_ELEMENTS`]).
    elements: usize,
}

type R<T> = Result<T, XacroError>;

/// A macro found by name, with the macro and symbol tables of its name space.
type FoundMacro = (Rc<MacroTable>, Rc<Table>, Rc<Macro>);

/// Lexically normalised path (`a/b/../c` is `a/c`), so that messages name files plainly.
pub(super) fn clean(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if out.file_name().is_some() {
                    out.pop();
                } else {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    if out.as_os_str().is_empty() {
        out.push(".");
    }
    out
}

impl<'o> Expander<'o> {
    pub(super) fn new(opts: &'o Options<'o>) -> Self {
        Expander {
            opts,
            files: Vec::new(),
            parsed: HashMap::new(),
            yaml: HashMap::new(),
            args: opts.args.iter().cloned().collect(),
            filestack: Vec::new(),
            calls: Rc::from(Vec::new()),
            here: (0, 0),
            resolving: Vec::new(),
            warnings: Vec::new(),
            elements: 0,
        }
    }

    /// An error at the element being expanded.
    fn err(&self, message: impl Into<String>) -> XacroError {
        let (file, line) = self.here;
        XacroError {
            file: self
                .files
                .get(file)
                .map_or_else(PathBuf::new, |f| f.path.clone()),
            line,
            message: message.into(),
            calls: self
                .calls
                .iter()
                .rev()
                .map(|c| {
                    (
                        c.macro_name.clone(),
                        self.files[c.file].path.clone(),
                        c.line,
                    )
                })
                .collect(),
        }
    }

    fn warn(&mut self, message: &str) {
        let (file, line) = self.here;
        let path = self
            .files
            .get(file)
            .map_or_else(String::new, |f| f.path.display().to_string());
        self.warnings.push(format!("{path}:{line}: {message}"));
    }

    /// Reads a file through the input guard; its index among the expansion's files.
    fn read(&mut self, path: &Path, kind: FileKind) -> Result<usize, String> {
        let path = clean(path);
        if let Some(k) = self.files.iter().position(|f| f.path == path) {
            return Ok(k);
        }
        let limit = self.opts.resolver.max_file_size();
        let bytes = crate::input::read_file(&path, limit)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        self.add_file(path, bytes, kind)
    }

    /// Takes a file's bytes already read (the top file, which the caller read to tell xacro from
    /// URDF): read once, and charged once to the run's read budget.
    pub(super) fn preload(&mut self, path: &Path, bytes: Vec<u8>) -> Result<(), String> {
        self.add_file(clean(path), bytes, FileKind::Xacro).map(drop)
    }

    fn add_file(&mut self, path: PathBuf, bytes: Vec<u8>, kind: FileKind) -> Result<usize, String> {
        let (text, encoding) = crate::urdf::encoding::decode(bytes)
            .map_err(|e| format!("{}:{}:{}: {}", path.display(), e.line, e.column, e.message))?;
        self.files.push(SourceFile {
            path,
            text,
            encoding,
            kind,
        });
        Ok(self.files.len() - 1)
    }

    fn parse_file(&mut self, k: usize) -> R<Rc<Element>> {
        if let Some(root) = self.parsed.get(&k) {
            return Ok(root.clone());
        }
        let root = dom::parse(&self.files[k].text, k).map_err(|e| XacroError {
            file: self.files[k].path.clone(),
            line: e.line,
            message: e.message,
            calls: Vec::new(),
        })?;
        self.parsed.insert(k, root.clone());
        Ok(root)
    }

    fn current_file(&self) -> &Path {
        self.filestack
            .last()
            .map_or(Path::new(""), |k| self.files[*k].path.as_path())
    }

    /// A path relative to the file being processed (xacro's `abs_filename_spec`).
    fn relative_to_current(&self, spec: &str) -> PathBuf {
        let p = Path::new(spec);
        if p.is_absolute() {
            return p.to_path_buf();
        }
        let base = self.current_file().parent().unwrap_or(Path::new(""));
        clean(&base.join(p))
    }

    /// Expands the document at `path`: its root element, fully expanded.
    pub(super) fn run(&mut self, path: &Path) -> R<Element> {
        let k = self
            .read(path, FileKind::Xacro)
            .map_err(|message| XacroError {
                file: path.to_path_buf(),
                line: 0,
                message,
                calls: Vec::new(),
            })?;
        self.filestack.push(k);
        let root = self.parse_file(k)?;
        let mut root = (*root).clone();
        if let Some(ns) = root.attr("xacro:targetNamespace").map(str::to_string) {
            root.attrs.retain(|(k, _)| k != "xacro:targetNamespace");
            root.set_attr("xmlns", ns);
        }
        let macros = MacroTable::new(None);
        let symbols = Table::new(None, false);
        self.expand_element(&root, &macros, &symbols)
    }

    // ---- text and substitution arguments ----

    /// xacro's `eval_text`: `${…}` expressions, `$(…)` substitution arguments, `$$` escapes; one
    /// piece alone keeps its type, several are joined as text.
    fn eval_text(&mut self, text: &str, symbols: &Rc<Table>) -> R<Value> {
        if !text.contains('$') {
            return Ok(Value::str(text));
        }
        let mut parts: Vec<Value> = Vec::new();
        let mut rest = text;
        while !rest.is_empty() {
            let b = rest.as_bytes();
            if b[0] != b'$' {
                let end = rest.find('$').unwrap_or(rest.len());
                parts.push(Value::str(&rest[..end]));
                rest = &rest[end..];
                continue;
            }
            let dollars = b.iter().take_while(|c| **c == b'$').count();
            if dollars >= 2 && matches!(b.get(dollars), Some(b'{' | b'(')) {
                // `$${` is a literal `${` (one `$` dropped), `$$$(` a literal `$$(`.
                parts.push(Value::str(&rest[1..=dollars]));
                rest = &rest[dollars + 1..];
                continue;
            }
            match b.get(1) {
                Some(b'{') => {
                    let close = rest.find('}').ok_or_else(|| {
                        self.err(format!("invalid expression: {rest} (no closing `}}`)"))
                    })?;
                    let v = self.eval_expr(&rest[2..close], symbols)?;
                    parts.push(v);
                    rest = &rest[close + 1..];
                }
                Some(b'(') => {
                    let close = rest.find(')').ok_or_else(|| {
                        self.err(format!("invalid expression: {rest} (no closing `)`)"))
                    })?;
                    let inner = self.eval_text(&rest[2..close], symbols)?.to_py_str();
                    parts.push(Value::str(&self.extension(&inner)?));
                    rest = &rest[close + 1..];
                }
                None => {
                    parts.push(Value::str("$"));
                    rest = "";
                }
                Some(b'$') => {
                    return Err(self.err(format!("invalid expression: {rest}")));
                }
                Some(_) => {
                    let end = rest[1..]
                        .find(['{', '(', '$'])
                        .map_or(rest.len(), |k| k + 1);
                    parts.push(Value::str(&rest[..end]));
                    rest = &rest[end..];
                }
            }
        }
        if parts.len() == 1 {
            return Ok(parts.pop().unwrap_or(Value::None));
        }
        let joined: String = parts.iter().map(Value::to_py_str).collect();
        if joined.len() > super::MAX_TEXT {
            return Err(self.err("text too long (over 16 MiB) after expansion"));
        }
        Ok(Value::str(&joined))
    }

    fn eval_expr(&mut self, src: &str, symbols: &Rc<Table>) -> R<Value> {
        let code = self.eval_text(src, symbols)?.to_py_str();
        if code.contains("__") {
            return Err(self.err(format!(
                "use of invalid name(s) with `__` in expression '{src}'"
            )));
        }
        let mut env = ExprEnv {
            x: self,
            symbols: symbols.clone(),
            pending: None,
        };
        let r = expr::eval_str(&code, &mut env);
        if let Some(e) = env.pending.take() {
            return Err(e);
        }
        r.map_err(|e| self.err(format!("{e} (when evaluating expression '{src}')")))
    }

    /// A substitution argument `$(…)` (its content already expanded).
    fn extension(&mut self, inner: &str) -> R<String> {
        if inner == "cwd" {
            return Ok(self.opts.cwd.display().to_string());
        }
        if let Some(code) = inner.strip_prefix("eval ") {
            if code.contains("__") {
                return Err(self.err("$(eval ...) may not contain double underscore expressions"));
            }
            let mut env = SubstEnv { x: self };
            return expr::eval_str(code, &mut env)
                .map(|v| v.to_py_str())
                .map_err(|e| self.err(format!("$(eval {code}): {e}")));
        }
        let words: Vec<&str> = inner.split(' ').filter(|w| !w.is_empty()).collect();
        let Some((&command, args)) = words.split_first() else {
            return Err(self.err("empty substitution argument $()"));
        };
        match (command, args) {
            ("arg", [name]) => self
                .args
                .get(*name)
                .cloned()
                .ok_or_else(|| self.err(format!("Undefined substitution argument {name} (give it as {name}:=VALUE)"))),
            ("arg", _) => Err(self.err(format!("$(arg var) takes one name [{inner}]"))),
            ("env", [name]) => self
                .opts
                .env
                .get(*name)
                .cloned()
                .ok_or_else(|| self.err(format!("environment variable {name} is not set"))),
            ("env", _) => Err(self.err(format!("$(env var) command only accepts one argument [{inner}]"))),
            ("optenv", [name, default @ ..]) => Ok(self
                .opts
                .env
                .get(*name)
                .cloned()
                .unwrap_or_else(|| default.join(" "))),
            ("find", [pkg]) => self.find(pkg),
            ("find", _) => Err(self.err(format!("$(find pkg) accepts exactly one argument [{inner}]"))),
            ("dirname", []) => Ok(self.dirname()),
            _ => Err(self.err(format!(
                "Unknown substitution command [{inner}]. Valid commands are ['find', 'env', 'optenv', 'dirname', 'arg', 'eval', 'cwd']"
            ))),
        }
    }

    fn dirname(&self) -> String {
        let dir = self.current_file().parent().unwrap_or(Path::new(""));
        let abs = if dir.is_absolute() {
            dir.to_path_buf()
        } else {
            clean(&self.opts.cwd.join(dir))
        };
        abs.display().to_string()
    }

    fn find(&self, pkg: &str) -> R<String> {
        let from = self.current_file().to_path_buf();
        match self.opts.resolver.package_dir(pkg, &from) {
            Ok(d) => {
                let abs = if d.is_absolute() {
                    d
                } else {
                    self.opts.cwd.join(d)
                };
                Ok(clean(&abs).display().to_string())
            }
            Err(nf) => Err(self.err(format!("package not found: $(find {pkg}): {}", nf.hint))),
        }
    }

    /// A property (or block) by name, evaluating a lazy one in the table that holds it.
    fn resolve(&mut self, table: &Rc<Table>, key: &str) -> R<Option<Value>> {
        let mut t = Some(table.clone());
        while let Some(tb) = t.take() {
            let slot = tb.vars.borrow().get(key).cloned();
            match slot {
                Some(Slot::Val(v)) => return Ok(Some(v)),
                Some(Slot::Lazy(text)) => {
                    if self.resolving.iter().any(|k| k == key) {
                        let chain = self.resolving.join(" -> ");
                        return Err(
                            self.err(format!("circular variable definition: {chain} -> {key}"))
                        );
                    }
                    self.resolving.push(key.to_string());
                    let v = self.eval_text(&text, &tb);
                    self.resolving.pop();
                    let v = eval_literal(v?);
                    tb.vars
                        .borrow_mut()
                        .insert(key.to_string(), Slot::Val(v.clone()));
                    return Ok(Some(v));
                }
                None => t.clone_from(&tb.parent),
            }
        }
        Ok(None)
    }

    /// xacro's `get_boolean_value`.
    fn boolean(&self, v: &Value, condition: &str) -> R<bool> {
        match v {
            Value::Str(s) => match &**s {
                "true" | "True" => Ok(true),
                "false" | "False" => Ok(false),
                other => super::builtins::parse_int(other).map(|i| i != 0).ok_or_else(|| {
                    self.err(format!(
                        "Xacro conditional \"{condition}\" evaluated to \"{other}\", which is not a boolean expression."
                    ))
                }),
            },
            other => Ok(other.truthy()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::macros::parse_params;
    use super::*;

    #[test]
    fn macro_params_parse_as_xacro_does() {
        let (names, d) = parse_params(
            "name  *origin **blocks x:=1.5 y:=^ z:=^|${pi/2} s:='a b' t=${a + b} u:=$(arg u)",
        );
        assert_eq!(
            names,
            ["name", "*origin", "**blocks", "x", "y", "z", "s", "t", "u"]
        );
        assert_eq!(d["x"], (false, Some("1.5".to_string())));
        assert_eq!(d["y"], (true, None));
        assert_eq!(d["z"], (true, Some("${pi/2}".to_string())));
        assert_eq!(d["s"], (false, Some("'a b'".to_string())));
        assert_eq!(d["t"], (false, Some("${a + b}".to_string())));
        assert_eq!(d["u"], (false, Some("$(arg u)".to_string())));
        assert!(!d.contains_key("name"));
    }

    #[test]
    fn literals_become_typed() {
        assert!(matches!(eval_literal(Value::str("3")), Value::Int(3)));
        assert!(matches!(eval_literal(Value::str("0.5")), Value::Float(x) if x == 0.5));
        assert!(matches!(
            eval_literal(Value::str("True")),
            Value::Bool(true)
        ));
        assert!(matches!(eval_literal(Value::str("'12'")), Value::Str(s) if &*s == "12"));
        assert!(matches!(eval_literal(Value::str("1_0")), Value::Str(_)));
        assert!(matches!(eval_literal(Value::str("ur5e")), Value::Str(_)));
    }

    #[test]
    fn paths_are_cleaned_lexically() {
        assert_eq!(
            clean(Path::new("a/b/../c/./d.xacro")),
            PathBuf::from("a/c/d.xacro")
        );
        assert_eq!(clean(Path::new("../x")), PathBuf::from("../x"));
    }
}
