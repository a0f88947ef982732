//! The expansion itself, following ROS 2 xacro 2.x (`xacro/__init__.py`, `substitution_args.py`):
//! `eval_all` over the tree, properties in tables chained by scope and evaluated lazily, macros
//! looked up by (dotted) name and expanded in a new scope whose parent is the caller's, includes
//! read in place (optionally into a name space), `$(…)` substitution arguments.
//!
//! Unlike xacro, the source tree is never changed: each step reads source elements and builds new
//! ones, which carry where they were written and through which macro calls they came.

use super::dom::{self, Call, Element, Node};
use super::expr::{self, Env};
use super::value::Value;
use super::{FileKind, Options, SourceFile, XacroError};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Component, Path, PathBuf};
use std::rc::Rc;

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

    fn warn(&mut self, message: String) {
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
        while let Some(tb) = t {
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
                None => t = tb.parent.clone(),
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

    // ---- the tree ----

    /// xacro's `eval_all` on one ordinary element: its attributes evaluated, its children expanded.
    fn expand_element(
        &mut self,
        el: &Element,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
    ) -> R<Element> {
        self.elements += 1;
        if self.elements > super::MAX_ELEMENTS {
            return Err(self.err(format!(
                "the expansion makes more than {} elements (macros multiplying without end?)",
                super::MAX_ELEMENTS
            )));
        }
        let saved = self.here;
        self.here = (el.src.file, el.src.line);
        let mut out = Element {
            name: el.name.clone(),
            attrs: Vec::with_capacity(el.attrs.len()),
            children: Vec::new(),
            src: el.src,
            calls: Some(el.calls.clone().unwrap_or_else(|| self.calls.clone())),
        };
        for (k, v) in &el.attrs {
            if k.starts_with("xacro:") || k == "xmlns:xacro" {
                continue;
            }
            let v = self.eval_text(v, symbols)?.to_py_str();
            out.attrs.push((k.clone(), v));
        }
        let mut attrs = std::mem::take(&mut out.attrs);
        self.expand_children(&el.children, macros, symbols, &mut out.children, &mut attrs)?;
        out.attrs = attrs;
        self.here = saved;
        Ok(out)
    }

    fn expand_children(
        &mut self,
        children: &[Node],
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
        parent_attrs: &mut Vec<(String, String)>,
    ) -> R<()> {
        let mut eval_comments = false;
        for child in children {
            match child {
                Node::Element(e) => {
                    eval_comments = false;
                    self.node(e, macros, symbols, out, parent_attrs)?;
                }
                Node::Text(t) => {
                    let s = self.eval_text(t, symbols)?.to_py_str();
                    if !s.trim().is_empty() {
                        eval_comments = false;
                    }
                    out.push(Node::Text(s));
                }
                Node::Comment(c) => {
                    if c.contains("xacro:eval-comments") {
                        eval_comments = !c.contains("xacro:eval-comments:off");
                    } else if eval_comments {
                        let s = self.eval_text(c, symbols)?.to_py_str();
                        out.push(Node::Comment(s));
                    } else {
                        out.push(Node::Comment(c.clone()));
                    }
                }
                Node::CData(c) => out.push(Node::CData(c.clone())),
            }
        }
        Ok(())
    }

    /// One child element: a xacro directive, a macro call, or an ordinary element.
    fn node(
        &mut self,
        e: &Rc<Element>,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
        parent_attrs: &mut Vec<(String, String)>,
    ) -> R<()> {
        let saved = self.here;
        self.here = (e.src.file, e.src.line);
        let r = self.node_inner(e, macros, symbols, out, parent_attrs);
        self.here = saved;
        r
    }

    fn node_inner(
        &mut self,
        e: &Rc<Element>,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
        parent_attrs: &mut Vec<(String, String)>,
    ) -> R<()> {
        match e.name.as_str() {
            "xacro:insert_block" => self.insert_block(e, macros, symbols, out)?,
            "xacro:include" => {
                remove_previous_comments(out);
                self.include(e, macros, symbols, out, parent_attrs)?;
            }
            "xacro:property" => {
                remove_previous_comments(out);
                self.property(e, symbols)?;
            }
            "xacro:macro" => {
                remove_previous_comments(out);
                self.define_macro(e, macros)?;
            }
            "xacro:arg" => {
                self.known_attrs(e, &["name", "default"]);
                let name = self.required(e, "name")?;
                let default = self.required(e, "default")?;
                if !self.args.contains_key(&name) {
                    let v = self.eval_text(&default, symbols)?.to_py_str();
                    self.args.insert(name, v);
                }
                remove_previous_comments(out);
            }
            "xacro:element" => {
                let raw = e
                    .attr("xacro:name")
                    .ok_or_else(|| self.err("<xacro:element> needs a xacro:name attribute"))?
                    .to_string();
                let name = self.eval_text(&raw, symbols)?.to_py_str();
                if name.is_empty() {
                    return Err(self.err("xacro:element: empty name"));
                }
                let mut renamed = (**e).clone();
                renamed.attrs.retain(|(k, _)| k != "xacro:name");
                renamed.name = name;
                return self.node_inner(&Rc::new(renamed), macros, symbols, out, parent_attrs);
            }
            "xacro:attribute" => {
                let name = self.required(e, "name")?;
                let value = self.required(e, "value")?;
                let name = self.eval_text(&name, symbols)?.to_py_str();
                let value = self.eval_text(&value, symbols)?.to_py_str();
                if name.is_empty() {
                    return Err(self.err("xacro:attribute: empty name"));
                }
                match parent_attrs.iter_mut().find(|(k, _)| *k == name) {
                    Some(slot) => slot.1 = value,
                    None => parent_attrs.push((name, value)),
                }
            }
            "xacro:if" | "xacro:unless" => {
                remove_previous_comments(out);
                self.known_attrs(e, &["value"]);
                let cond = self.required(e, "value")?;
                let v = self.eval_text(&cond, symbols)?;
                let keep = self.boolean(&v, &cond)? == (e.name == "xacro:if");
                if keep {
                    let mut lost = Vec::new();
                    self.expand_children(&e.children, macros, symbols, out, &mut lost)?;
                }
            }
            name if name.starts_with("xacro:") => {
                remove_previous_comments(out);
                self.call_macro(e, macros, symbols, out, parent_attrs)?;
            }
            _ => {
                let el = self.expand_element(e, macros, symbols)?;
                out.push(Node::Element(Rc::new(el)));
            }
        }
        Ok(())
    }

    /// `<xacro:insert_block name="n"/>`: a `**n` block's content, or a `*n` block itself,
    /// expanded here.
    fn insert_block(
        &mut self,
        e: &Rc<Element>,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
    ) -> R<()> {
        let name = self.required(e, "name")?;
        let (block, content_only) = if symbols.contains(&format!("**{name}")) {
            (self.resolve(symbols, &format!("**{name}"))?, true)
        } else if symbols.contains(&format!("*{name}")) {
            (self.resolve(symbols, &format!("*{name}"))?, false)
        } else {
            return Err(self.err(format!("Undefined block \"{name}\"")));
        };
        let Some(Value::Block(block)) = block else {
            return Err(self.err(format!("\"{name}\" is not a block")));
        };
        let expanded = self.expand_element(&block, macros, symbols)?;
        if content_only {
            out.extend(expanded.children);
        } else {
            out.push(Node::Element(Rc::new(expanded)));
        }
        Ok(())
    }

    fn required(&self, e: &Element, attr: &str) -> R<String> {
        e.attr(attr)
            .map(str::to_string)
            .ok_or_else(|| self.err(format!("<{}> is missing the attribute `{attr}`", e.name)))
    }

    /// xacro warns about attributes a directive does not know.
    fn known_attrs(&mut self, e: &Element, known: &[&str]) {
        let extra: Vec<String> = e
            .attrs
            .iter()
            .map(|(k, _)| k.clone())
            .filter(|k| !known.contains(&k.as_str()) && !k.starts_with("xmlns:"))
            .collect();
        if !extra.is_empty() {
            self.warn(format!(
                "{}: unknown attribute(s): {}",
                e.name,
                extra.join(", ")
            ));
        }
    }

    fn property(&mut self, e: &Rc<Element>, table: &Rc<Table>) -> R<()> {
        self.known_attrs(
            e,
            &["name", "value", "default", "remove", "scope", "lazy_eval"],
        );
        let raw = self.required(e, "name")?;
        let name = self.eval_text(&raw, table)?.to_py_str();
        if !is_identifier(&name) {
            return Err(self.err(format!(
                "Property names must be valid python identifiers: {name}"
            )));
        }
        if name.starts_with("__") {
            return Err(self.err(format!(
                "Property names must not start with double underscore: {name}"
            )));
        }
        let remove = match e.attr("remove") {
            Some(r) => {
                let v = self.eval_text(r, table)?;
                self.boolean(&v, r)?
            }
            None => false,
        };
        let value = e.attr("value").map(str::to_string);
        let default = e.attr("default").map(str::to_string);
        if usize::from(value.is_some()) + usize::from(default.is_some()) + usize::from(remove) > 1 {
            return Err(self.err(format!(
                "Property attributes default, value, and remove are mutually exclusive: {name}"
            )));
        }
        if remove {
            if table.contains(&name) {
                table.remove_everywhere(&name);
            }
            return Ok(());
        }
        let scope = e.attr("scope").map(str::to_string);
        let mut value = value;
        if let Some(d) = default {
            if scope.is_some() {
                self.warn(format!(
                    "{name}: default property value can only be defined on local scope"
                ));
            }
            if table.contains(&name) {
                return Ok(());
            }
            value = Some(d);
        }
        let (key, mut v) = match value {
            Some(text) => (name.clone(), Value::str(&text)),
            None => (format!("**{name}"), Value::Block(e.clone())),
        };
        let mut lazy = match e.attr("lazy_eval") {
            Some(l) => {
                let v = self.eval_text(l, table)?;
                self.boolean(&v, l)?
            }
            None => true,
        };
        let Some(target) = self.property_target(&name, scope.as_deref(), table, &mut lazy)? else {
            return Ok(());
        };
        if !lazy {
            if let Value::Str(s) = &v {
                let s = s.to_string();
                v = self.eval_text(&s, table)?;
            }
        }
        target.set(&key, v, lazy);
        Ok(())
    }

    /// The table a property goes into (`scope`), and whether it stays lazy; `None` when it has
    /// nowhere to go (`scope="parent"` at the top).
    fn property_target(
        &mut self,
        name: &str,
        scope: Option<&str>,
        table: &Rc<Table>,
        lazy: &mut bool,
    ) -> R<Option<Rc<Table>>> {
        Ok(Some(match scope {
            Some("global") => {
                *lazy = false;
                table.top()
            }
            Some("parent") => {
                let Some(mut t) = table.parent.clone() else {
                    self.warn(format!("{name}: no parent scope at global scope"));
                    return Ok(None);
                };
                *lazy = false;
                if !table.namespace {
                    while t.namespace {
                        match t.parent.clone() {
                            Some(p) => t = p,
                            None => break,
                        }
                    }
                }
                t
            }
            Some(other) if other != "local" => {
                return Err(self.err(format!(
                    "{name}: unknown scope=\"{other}\" (local, parent or global)"
                )));
            }
            _ => table.clone(),
        }))
    }

    fn define_macro(&mut self, e: &Rc<Element>, macros: &Rc<MacroTable>) -> R<()> {
        self.known_attrs(e, &["name", "params"]);
        let mut name = self.required(e, "name")?;
        if name == "call" {
            return Err(self.err("Invalid use of macro name 'call'"));
        }
        if name.contains('.') {
            return Err(self.err(format!(
                "macro names must not contain '.' (reserved for namespaces): {name}"
            )));
        }
        if let Some(n) = name.strip_prefix("xacro:") {
            self.warn(format!(
                "macro names must not contain prefix 'xacro:': {name}"
            ));
            name = n.to_string();
        }
        let (params, defaults) = parse_params(e.attr("params").unwrap_or(""));
        let m = Macro {
            name: name.clone(),
            body: e.clone(),
            params,
            defaults,
        };
        macros
            .defs
            .borrow_mut()
            .insert(name, Rc::new(MacroEntry::Macro(Rc::new(m))));
        Ok(())
    }

    /// xacro's `resolve_macro`: the full name first, then `ns.name` through include name spaces.
    fn find_macro(
        &mut self,
        fullname: &str,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
    ) -> R<Option<FoundMacro>> {
        if let Some(entry) = macros.get(fullname) {
            if let MacroEntry::Macro(m) = &*entry {
                return Ok(Some((macros.clone(), symbols.clone(), m.clone())));
            }
        }
        let mut parts: Vec<&str> = fullname.split('.').collect();
        let Some(name) = parts.pop() else {
            return Ok(None);
        };
        if parts.is_empty() {
            return Ok(None);
        }
        let mut m = macros.clone();
        let mut s = symbols.clone();
        for ns in parts {
            let Some(entry) = m.get(ns) else {
                return Ok(None);
            };
            let MacroEntry::Namespace(inner) = &*entry else {
                return Ok(None);
            };
            let inner = inner.clone();
            let Some(Value::Namespace(t)) = self.resolve(&s, ns)? else {
                return Ok(None);
            };
            m = inner;
            s = t;
        }
        match m.get(name).as_deref() {
            Some(MacroEntry::Macro(mac)) => Ok(Some((m.clone(), s, mac.clone()))),
            _ => Ok(None),
        }
    }

    fn call_macro(
        &mut self,
        e: &Rc<Element>,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
        parent_attrs: &mut Vec<(String, String)>,
    ) -> R<()> {
        let mut attrs: Vec<(String, String)> = e.attrs.clone();
        let fullname = if e.name == "xacro:call" {
            let raw = e
                .attr("macro")
                .ok_or_else(|| self.err("xacro:call is missing the 'macro' attribute"))?
                .to_string();
            attrs.retain(|(k, _)| k != "macro");
            self.eval_text(&raw, symbols)?.to_py_str()
        } else {
            e.name["xacro:".len()..].to_string()
        };
        let Some((ns_macros, ns_symbols, m)) = self.find_macro(&fullname, macros, symbols)? else {
            return Err(self.err(format!("unknown macro name: xacro:{fullname}")));
        };
        if self.calls.len() >= MAX_MACRO_DEPTH {
            return Err(self.err(format!(
                "macro calls nested deeper than {MAX_MACRO_DEPTH} (recursion in macro {fullname}?)"
            )));
        }
        let scoped = Table::new(Some(ns_symbols.clone()), false);
        let scoped_macros = MacroTable::new(Some(ns_macros.clone()));
        let mut params = m.params.clone();
        for (k, v) in &attrs {
            let Some(at) = params.iter().position(|p| p == k) else {
                return Err(self.err(format!("Invalid parameter \"{k}\" of macro {fullname}")));
            };
            params.remove(at);
            let value = self.eval_text(v, &ns_symbols)?;
            scoped.set(k, value, false);
        }
        // The call's children (its blocks) are expanded in the caller's scope first.
        let mut kids = Vec::new();
        let mut lost = Vec::new();
        self.expand_children(&e.children, &ns_macros, &ns_symbols, &mut kids, &mut lost)?;
        let mut blocks = kids.into_iter().filter_map(|n| match n {
            Node::Element(b) => Some(b),
            _ => None,
        });
        for p in params.clone() {
            if p.starts_with('*') {
                let Some(b) = blocks.next() else {
                    return Err(self.err(format!(
                        "Not enough blocks for macro {fullname} (parameter {p})"
                    )));
                };
                params.retain(|q| *q != p);
                scoped.set(&p, Value::Block(b), false);
            }
        }
        if let Some(extra) = blocks.next() {
            return Err(self.err(format!(
                "Unused block \"{}\" in the call of macro {fullname}",
                extra.name
            )));
        }
        self.bind_defaults(&m, &fullname, &ns_symbols, &scoped, &mut params)?;
        if !params.is_empty() {
            return Err(self.err(format!(
                "Undefined parameters [{}] of macro {fullname}",
                params.join(",")
            )));
        }
        let caller = self.calls.clone();
        let mut chain: Vec<Call> = caller.to_vec();
        chain.push(Call {
            macro_name: m.name.clone(),
            file: e.src.file,
            line: e.src.line,
        });
        self.calls = Rc::from(chain);
        let r = self.macro_body(&m, &scoped_macros, &scoped, out, parent_attrs);
        self.calls = caller;
        r
    }

    /// Parameters not given in the call take their defaults (forwarded with `^` from the
    /// caller's scope when it has them); those bound leave `params`.
    fn bind_defaults(
        &mut self,
        m: &Macro,
        fullname: &str,
        ns_symbols: &Rc<Table>,
        scoped: &Rc<Table>,
        params: &mut Vec<String>,
    ) -> R<()> {
        for p in params.clone() {
            if p.starts_with('*') {
                continue;
            }
            let Some((forward, default)) = m.defaults.get(&p).cloned() else {
                continue;
            };
            let value = if forward {
                match self.resolve(ns_symbols, &p)? {
                    Some(v) => v,
                    None => match &default {
                        Some(d) => self.eval_text(d, ns_symbols)?,
                        None => {
                            return Err(self.err(format!(
                                "Undefined property to forward: {p} (macro {fullname})"
                            )))
                        }
                    },
                }
            } else {
                match &default {
                    Some(d) => self.eval_text(d, ns_symbols)?,
                    None => continue,
                }
            };
            scoped.set(&p, value, false);
            params.retain(|q| *q != p);
        }
        Ok(())
    }

    fn macro_body(
        &mut self,
        m: &Macro,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
        out: &mut Vec<Node>,
        parent_attrs: &mut Vec<(String, String)>,
    ) -> R<()> {
        let saved = self.here;
        self.here = (m.body.src.file, m.body.src.line);
        // xacro evaluates the body element's own attributes too (`params` defaults included).
        let mut body_attrs = Vec::new();
        for (k, v) in &m.body.attrs {
            let v = self.eval_text(v, symbols)?.to_py_str();
            body_attrs.push((k.clone(), v));
        }
        self.expand_children(&m.body.children, macros, symbols, out, &mut body_attrs)?;
        for (k, v) in body_attrs {
            if k.starts_with("xmlns:")
                && k != "xmlns:xacro"
                && !parent_attrs.iter().any(|(p, _)| *p == k)
            {
                parent_attrs.push((k, v));
            }
        }
        self.here = saved;
        Ok(())
    }

    fn include(
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
            self.warn("Child elements of a <xacro:include> tag are ignored".into());
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
                .map_err(|m| self.err(format!("cannot include {name}: {m}")))?;
            let root = self.parse_file(k)?;
            self.filestack.push(k);
            let r = self.expand_element(&root, &ns_macros, &ns_symbols);
            self.filestack.pop();
            let expanded = r?;
            for (k, v) in &expanded.attrs {
                if k.starts_with("xmlns:") {
                    match parent_attrs.iter().find(|(p, _)| p == k) {
                        Some((_, old)) if old != v => {
                            self.warn(format!("inconsistent namespace redefinitions for {k}"))
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
            self.warn(format!(
                "Include tag's filename spec \"{}\" matched no files.",
                pattern.display()
            ));
        }
        Ok(found)
    }

    fn load_yaml(&mut self, spec: &str) -> Result<Value, String> {
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
        let v = super::yaml::load(&text, &mut units)
            .map_err(|e| format!("{}: {e}", self.files[k].path.display()))?;
        self.yaml.insert(k, v.clone());
        Ok(v)
    }
}

/// Whether `s` is a Python identifier that is not a keyword.
fn is_identifier(s: &str) -> bool {
    const KEYWORDS: [&str; 35] = [
        "False", "None", "True", "and", "as", "assert", "async", "await", "break", "class",
        "continue", "def", "del", "elif", "else", "except", "finally", "for", "from", "global",
        "if", "import", "in", "is", "lambda", "nonlocal", "not", "or", "pass", "raise", "return",
        "try", "while", "with", "yield",
    ];
    let mut cs = s.chars();
    cs.next().is_some_and(|c| c.is_alphabetic() || c == '_')
        && cs.all(|c| c.is_alphanumeric() || c == '_')
        && !KEYWORDS.contains(&s)
}

/// xacro's `remove_previous_comments`: comments right before a directive go with it (one
/// whitespace text of at most one line break may stand between them).
fn remove_previous_comments(out: &mut Vec<Node>) {
    let mut k = out.len();
    loop {
        if k > 0 {
            if let Node::Text(t) = &out[k - 1] {
                if t.trim().is_empty() && t.matches('\n').count() <= 1 {
                    k -= 1;
                }
            }
        }
        if k > 0 && matches!(out[k - 1], Node::Comment(_)) {
            out.remove(k - 1);
            k -= 1;
        } else {
            return;
        }
    }
}

/// xacro's `parse_macro_arg` over a whole `params` string: each parameter's name and, if given,
/// (forward with `^`, default text).
#[allow(clippy::type_complexity)] // A name list and a map of (forward, default): read where used.
fn parse_params(s: &str) -> (Vec<String>, HashMap<String, (bool, Option<String>)>) {
    let mut names = Vec::new();
    let mut defaults = HashMap::new();
    let mut rest = s;
    loop {
        rest = rest.trim_start();
        if rest.is_empty() {
            break;
        }
        match parse_param(rest) {
            Some((name, forward, default, after)) => {
                defaults.insert(name.to_string(), (forward, default.map(str::to_string)));
                names.push(name.to_string());
                rest = after;
            }
            None => {
                let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
                names.push(rest[..end].to_string());
                rest = &rest[end..];
            }
        }
    }
    (names, defaults)
}

/// One `name:=default`, `name:=^`, `name:=^|default` (or `=` instead of `:=`): name, forward,
/// default (`None` when empty) and the rest; `None` when `s` starts with a bare name.
fn parse_param(s: &str) -> Option<(&str, bool, Option<&str>, &str)> {
    let name_end = s.find(|c: char| c.is_whitespace() || c == ':' || c == '=')?;
    if name_end == 0 {
        return None;
    }
    let name = &s[..name_end];
    let mut r = s[name_end..].trim_start();
    r = r.strip_prefix(":=").or_else(|| r.strip_prefix('='))?;
    r = r.trim_start();
    let mut forward = false;
    if let Some(x) = r.strip_prefix('^') {
        forward = true;
        r = x.strip_prefix('|').unwrap_or(x);
    }
    let end = default_end(r);
    let default = &r[..end];
    let after = &r[end..];
    Some((
        name,
        forward,
        (!default.is_empty()).then_some(default),
        after,
    ))
}

/// Where a default value ends: a `${…}` or `$(…)` followed by a space or the end, else a run of
/// quoted strings and non-space characters.
fn default_end(r: &str) -> usize {
    let at_break = |k: usize| r[k..].is_empty() || r[k..].starts_with(char::is_whitespace);
    for (open, close) in [("${", '}'), ("$(", ')')] {
        if r.starts_with(open) {
            for (k, c) in r.char_indices() {
                if c == close && at_break(k + 1) {
                    return k + 1;
                }
            }
        }
    }
    let b = r.as_bytes();
    let mut k = 0;
    while k < b.len() {
        match b[k] {
            q @ (b'\'' | b'"') => match r[k + 1..].find(q as char) {
                Some(j) => k += j + 2,
                None => break,
            },
            c if c.is_ascii_whitespace() => break,
            _ => k += r[k..].chars().next().map_or(1, char::len_utf8),
        }
    }
    if at_break(k) {
        k
    } else {
        0
    }
}

/// Expression names for `${…}`: the current scope's properties and the expander's builtins.
struct ExprEnv<'a, 'o> {
    x: &'a mut Expander<'o>,
    symbols: Rc<Table>,
    /// An expansion error met inside the expression (a lazy property that failed), reported as
    /// it is rather than as the expression's.
    pending: Option<XacroError>,
}

impl ExprEnv<'_, '_> {
    fn keep(&mut self, r: R<Option<Value>>) -> Result<Option<Value>, String> {
        r.map_err(|e| {
            let m = e.message.clone();
            self.pending.get_or_insert(e);
            m
        })
    }
}

impl Env for ExprEnv<'_, '_> {
    fn lookup(&mut self, name: &str) -> Result<Option<Value>, String> {
        let symbols = self.symbols.clone();
        let r = self.x.resolve(&symbols, name);
        self.keep(r)
    }

    fn namespace_get(&mut self, ns: &Rc<Table>, name: &str) -> Result<Option<Value>, String> {
        let r = self.x.resolve(ns, name);
        self.keep(r)
    }

    fn call(&mut self, name: &str, args: &[Value]) -> Option<Result<Value, String>> {
        let one = || match args {
            [a] => Ok(a.to_py_str()),
            _ => Err(format!("{name}() takes one argument")),
        };
        Some(match name {
            "xacro.load_yaml" => one().and_then(|f| self.x.load_yaml(&f)),
            "xacro.abs_filename" => {
                one().map(|f| Value::str(&self.x.relative_to_current(&f).display().to_string()))
            }
            "xacro.arg" => one().and_then(|a| {
                self.x
                    .args
                    .get(&a)
                    .map(|v| Value::str(v))
                    .ok_or_else(|| format!("KeyError: '{a}' (no such xacro arg)"))
            }),
            "xacro.message" | "xacro.warning" | "xacro.error" => {
                let text: Vec<String> = args.iter().map(Value::to_py_str).collect();
                self.x.warn(text.join(" "));
                Ok(Value::str(""))
            }
            "xacro.print_location" => Ok(Value::str("")),
            "xacro.fatal" => {
                let text: Vec<String> = args.iter().map(Value::to_py_str).collect();
                Err(format!("fatal: {}", text.join(" ")))
            }
            _ => return None,
        })
    }
}

/// Names for `$(eval …)`: xacro args (typed as roslaunch's `auto`), `arg()`, `env()`,
/// `optenv()`, `find()`, `dirname()`, `true`/`false`, and the math names.
struct SubstEnv<'a, 'o> {
    x: &'a mut Expander<'o>,
}

/// roslaunch's `convert_value(value, 'auto')`.
fn auto_value(s: &str) -> Value {
    let num = if s.contains('.') {
        super::builtins::parse_float(s).map(Value::Float)
    } else {
        super::builtins::parse_int(s).map(Value::Int)
    };
    if let Some(v) = num {
        return v;
    }
    match s.to_lowercase().as_str() {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => Value::str(s),
    }
}

impl Env for SubstEnv<'_, '_> {
    fn lookup(&mut self, name: &str) -> Result<Option<Value>, String> {
        Ok(match name {
            "true" => Some(Value::Bool(true)),
            "false" => Some(Value::Bool(false)),
            "arg" => Some(Value::Builtin("eval.arg")),
            "env" => Some(Value::Builtin("eval.env")),
            "optenv" => Some(Value::Builtin("eval.optenv")),
            "find" => Some(Value::Builtin("eval.find")),
            "dirname" => Some(Value::Builtin("eval.dirname")),
            _ => self.x.args.get(name).map(|v| auto_value(v)),
        })
    }

    fn namespace_get(&mut self, _: &Rc<Table>, _: &str) -> Result<Option<Value>, String> {
        Ok(None)
    }

    fn call(&mut self, name: &str, args: &[Value]) -> Option<Result<Value, String>> {
        let a: Vec<String> = args.iter().map(Value::to_py_str).collect();
        Some(match (name, a.as_slice()) {
            ("eval.arg", [n]) => self
                .x
                .args
                .get(n)
                .map(|v| auto_value(v))
                .ok_or_else(|| format!("Undefined substitution argument {n}")),
            ("eval.env", [n]) => self
                .x
                .opts
                .env
                .get(n)
                .map(|v| Value::str(v))
                .ok_or_else(|| format!("environment variable {n} is not set")),
            ("eval.optenv", [n, rest @ ..]) => Ok(Value::str(
                &self
                    .x
                    .opts
                    .env
                    .get(n)
                    .cloned()
                    .unwrap_or_else(|| rest.join(" ")),
            )),
            ("eval.find", [p]) => self
                .x
                .find(p)
                .map(|s| Value::str(&s))
                .map_err(|e| e.message),
            ("eval.dirname", []) => Ok(Value::str(&self.x.dirname())),
            (n, _) if n.starts_with("eval.") => {
                Err(format!("{}(): wrong number of arguments", &n[5..]))
            }
            _ => return None,
        })
    }
}

/// Only xacro's globals (for the expressions of YAML unit tags).
struct GlobalsOnly;

impl Env for GlobalsOnly {
    fn lookup(&mut self, _: &str) -> Result<Option<Value>, String> {
        Ok(None)
    }
    fn namespace_get(&mut self, _: &Rc<Table>, _: &str) -> Result<Option<Value>, String> {
        Ok(None)
    }
    fn call(&mut self, _: &str, _: &[Value]) -> Option<Result<Value, String>> {
        None
    }
}

#[cfg(test)]
mod tests {
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
