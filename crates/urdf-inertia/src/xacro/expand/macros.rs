//! Properties and macros: definitions, lookup by dotted name, calls with their parameters bound.

use super::{Expander, FoundMacro, Macro, MacroEntry, MacroTable, Table, MAX_MACRO_DEPTH, R};
use crate::xacro::dom::{Call, Element, Node};
use crate::xacro::value::Value;
use std::collections::HashMap;
use std::rc::Rc;

impl Expander<'_> {
    pub(super) fn property(&mut self, e: &Rc<Element>, table: &Rc<Table>) -> R<()> {
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
                self.warn(&format!(
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
                    self.warn(&format!("{name}: no parent scope at global scope"));
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

    pub(super) fn define_macro(&mut self, e: &Rc<Element>, macros: &Rc<MacroTable>) -> R<()> {
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
            self.warn(&format!(
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

    pub(super) fn call_macro(
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
}

/// Whether `s` is a Python identifier that is not a keyword.
pub(super) fn is_identifier(s: &str) -> bool {
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

/// xacro's `parse_macro_arg` over a whole `params` string: each parameter's name and, if given,
/// (forward with `^`, default text).
#[allow(clippy::type_complexity)] // A name list and a map of (forward, default): read where used.
pub(super) fn parse_params(s: &str) -> (Vec<String>, HashMap<String, (bool, Option<String>)>) {
    let mut names = Vec::new();
    let mut defaults = HashMap::new();
    let mut rest = s;
    loop {
        rest = rest.trim_start();
        if rest.is_empty() {
            break;
        }
        if let Some((name, forward, default, after)) = parse_param(rest) {
            defaults.insert(name.to_string(), (forward, default.map(str::to_string)));
            names.push(name.to_string());
            rest = after;
        } else {
            let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
            names.push(rest[..end].to_string());
            rest = &rest[end..];
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
