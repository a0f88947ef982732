//! The tree: xacro's `eval_all` over elements, the directives dispatched, blocks inserted.

use super::{Expander, MacroTable, Table, R};
use crate::xacro::dom::{Element, Node};
use crate::xacro::value::Value;
use std::rc::Rc;

impl Expander<'_> {
    /// xacro's `eval_all` on one ordinary element: its attributes evaluated, its children expanded.
    pub(super) fn expand_element(
        &mut self,
        el: &Element,
        macros: &Rc<MacroTable>,
        symbols: &Rc<Table>,
    ) -> R<Element> {
        self.elements += 1;
        if self.elements > crate::xacro::MAX_ELEMENTS {
            return Err(self.err(format!(
                "the expansion makes more than {} elements (macros multiplying without end?)",
                crate::xacro::MAX_ELEMENTS
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

    pub(super) fn expand_children(
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

    pub(super) fn required(&self, e: &Element, attr: &str) -> R<String> {
        e.attr(attr)
            .map(str::to_string)
            .ok_or_else(|| self.err(format!("<{}> is missing the attribute `{attr}`", e.name)))
    }

    /// xacro warns about attributes a directive does not know.
    pub(super) fn known_attrs(&mut self, e: &Element, known: &[&str]) {
        let extra: Vec<String> = e
            .attrs
            .iter()
            .map(|(k, _)| k.clone())
            .filter(|k| !known.contains(&k.as_str()) && !k.starts_with("xmlns:"))
            .collect();
        if !extra.is_empty() {
            self.warn(&format!(
                "{}: unknown attribute(s): {}",
                e.name,
                extra.join(", ")
            ));
        }
    }
}

/// xacro's `remove_previous_comments`: comments right before a directive go with it (one
/// whitespace text of at most one line break may stand between them).
pub(super) fn remove_previous_comments(out: &mut Vec<Node>) {
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
