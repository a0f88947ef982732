//! The XML tree the expander works on: elements with where they were written (file, line, byte
//! span), read with quick-xml, and written back out the way xacro prints (`toprettyxml`, two-space
//! indent, one element per line, an element holding only text on one line).

use crate::text::LineCounter;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;
use std::rc::Rc;

/// One macro call on the way to an element: the macro's name and where it was called.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Call {
    pub macro_name: String,
    /// Index into the expansion's files.
    pub file: usize,
    pub line: usize,
}

/// Where an element was written.
// Four independent facts about the place, each asked on its own (not states of one machine).
#[allow(clippy::struct_excessive_bools)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Src {
    /// Index into the expansion's files.
    pub file: usize,
    pub line: usize,
    /// Byte offset of `<` and just past the element's end in its file.
    pub start: usize,
    pub end: usize,
    /// Inside a `<xacro:macro>` body.
    pub in_macro: bool,
    /// Holds a `xacro:` element somewhere inside (a macro call, a condition, a block).
    pub xacro_inside: bool,
    /// Its `name` attribute holds no `${…}` or `$(…)`.
    pub name_literal: bool,
    /// Values xacro computes inside it: `${…}` or a `$(…)` other than `$(find …)` in one of its own
    /// attributes other than `name`, or in an attribute or text of an element inside it.
    pub computed_inside: bool,
}

/// Whether xacro computes something in `v`: a `${…}`, or a `$(…)` other than `$(find …)` (a
/// package's directory, the same in every expansion).
pub fn computed(v: &str) -> bool {
    v.contains("${")
        || v.match_indices("$(")
            .any(|(i, _)| !v[i..].starts_with("$(find "))
}

/// An element: its tag, attributes in order, children, and origin.
#[derive(Debug, Clone)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Node>,
    pub src: Src,
    /// The macro calls that produced it (set once it is expanded; `None` in a source tree).
    pub calls: Option<Rc<[Call]>>,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    pub fn set_attr(&mut self, name: &str, value: String) {
        match self.attrs.iter_mut().find(|(k, _)| k == name) {
            Some(slot) => slot.1 = value,
            None => self.attrs.push((name.to_string(), value)),
        }
    }

    /// The child elements, in order.
    pub fn elements(&self) -> impl Iterator<Item = &Rc<Element>> {
        self.children.iter().filter_map(|c| match c {
            Node::Element(e) => Some(e),
            _ => None,
        })
    }
}

/// A node of the tree.
#[derive(Debug, Clone)]
pub enum Node {
    Element(Rc<Element>),
    Text(String),
    Comment(String),
    CData(String),
}

/// A parse failure: byte offset and message.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    pub line: usize,
    pub message: String,
}

fn attrs(e: &BytesStart<'_>) -> Result<Vec<(String, String)>, (usize, String)> {
    let mut out = Vec::new();
    for a in e.attributes().with_checks(true) {
        let a = a.map_err(|err| match err {
            AttrError::Duplicated(at, _) => (at, "an attribute is given twice".to_string()),
            AttrError::ExpectedEq(at)
            | AttrError::ExpectedValue(at)
            | AttrError::UnquotedValue(at)
            | AttrError::ExpectedQuote(at, _) => (at, format!("malformed attribute: {err}")),
        })?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let v = a
            .unescape_value()
            .map_err(|e| (0, format!("attribute `{key}`: {e}")))?
            .into_owned();
        out.push((key, v));
    }
    Ok(out)
}

/// Deepest element nesting read (the expansion recurses along it).
const MAX_DEPTH: usize = 1000;

struct Open {
    el: Element,
    in_macro: bool,
}

/// Parses a document into its root element (comments and text around the root are dropped, as
/// xacro drops them: only the root's content is expanded).
pub fn parse(text: &str, file: usize) -> Result<Rc<Element>, ParseError> {
    let bom = if text.starts_with('\u{feff}') { 3 } else { 0 };
    let mut reader = Reader::from_str(&text[bom..]);
    reader.config_mut().check_end_names = true;
    let mut lines = LineCounter::new(text.as_bytes());
    let mut stack: Vec<Open> = Vec::new();
    let mut root: Option<Rc<Element>> = None;
    let err = |lines: &mut LineCounter, pos: usize, message: String| ParseError {
        line: lines.at(pos),
        message,
    };
    loop {
        let pos = bom + reader.buffer_position() as usize;
        let event = match reader.read_event() {
            Ok(e) => e,
            Err(e) => {
                let at = bom + reader.error_position() as usize;
                return Err(err(&mut lines, at, format!("malformed XML: {e}")));
            }
        };
        let end = bom + reader.buffer_position() as usize;
        let (start, empty) = match event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                let Some(open) = stack.pop() else {
                    return Err(err(
                        &mut lines,
                        pos,
                        "an end tag without a start tag".into(),
                    ));
                };
                close(open, end, &mut stack, &mut root);
                continue;
            }
            Event::Text(t) => {
                if let Some(top) = stack.last_mut() {
                    let s = t
                        .unescape()
                        .map_err(|e| err(&mut lines, pos, format!("malformed text: {e}")))?;
                    push_text(top, &s);
                } else if !t.iter().all(u8::is_ascii_whitespace) {
                    return Err(err(&mut lines, pos, "text outside the root element".into()));
                }
                continue;
            }
            Event::CData(c) => {
                let s = String::from_utf8_lossy(&c).into_owned();
                push_child(&mut stack, Node::CData(s));
                continue;
            }
            Event::Comment(c) => {
                push_child(
                    &mut stack,
                    Node::Comment(String::from_utf8_lossy(&c).into_owned()),
                );
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        if root.is_some() {
            return Err(err(&mut lines, pos, "a second root element".into()));
        }
        if stack.len() >= MAX_DEPTH {
            return Err(err(
                &mut lines,
                pos,
                format!("elements nested deeper than {MAX_DEPTH} levels"),
            ));
        }
        let open = open_element(&start, pos, end, file, &mut lines, &stack)?;
        if empty {
            close(open, end, &mut stack, &mut root);
        } else {
            stack.push(open);
        }
    }
    finish(&stack, root)
}

/// The end of the document: every element closed, a root read.
fn finish(stack: &[Open], root: Option<Rc<Element>>) -> Result<Rc<Element>, ParseError> {
    if let Some(open) = stack.last() {
        return Err(ParseError {
            line: open.el.src.line,
            message: format!("<{}> is not closed", open.el.name),
        });
    }
    root.ok_or_else(|| ParseError {
        line: 1,
        message: "no root element".into(),
    })
}

/// A start (or empty) tag as a new element, with where it is.
fn open_element(
    start: &BytesStart<'_>,
    pos: usize,
    end: usize,
    file: usize,
    lines: &mut LineCounter,
    stack: &[Open],
) -> Result<Open, ParseError> {
    let name = String::from_utf8_lossy(start.name().as_ref()).into_owned();
    let a = attrs(start).map_err(|(at, m)| ParseError {
        line: lines.at(pos + 1 + at),
        message: m,
    })?;
    let in_macro = stack
        .last()
        .is_some_and(|o| o.in_macro || o.el.name == "xacro:macro");
    let name_literal = a
        .iter()
        .find(|(k, _)| k == "name")
        .is_some_and(|(_, v)| !v.contains("${") && !v.contains("$("));
    let computed_inside = a.iter().any(|(k, v)| k != "name" && computed(v));
    let el = Element {
        name,
        attrs: a,
        children: Vec::new(),
        src: Src {
            file,
            line: lines.at(pos),
            start: pos,
            end,
            in_macro,
            xacro_inside: false,
            name_literal,
            computed_inside,
        },
        calls: None,
    };
    Ok(Open { el, in_macro })
}

/// Adds a node to the open element (nothing outside the root is kept).
fn push_child(stack: &mut [Open], node: Node) {
    if let Some(top) = stack.last_mut() {
        // CDATA is text to xacro: `${…}` there is computed too.
        if let Node::CData(s) = &node {
            top.el.src.computed_inside |= computed(s);
        }
        top.el.children.push(node);
    }
}

/// Text into the open element (joined to text before it), which then computes something inside
/// when the text holds `${…}`.
fn push_text(open: &mut Open, s: &str) {
    open.el.src.computed_inside |= computed(s);
    let children = &mut open.el.children;
    if let Some(Node::Text(t)) = children.last_mut() {
        t.push_str(s);
    } else {
        children.push(Node::Text(s.to_string()));
    }
}

fn close(mut open: Open, end: usize, stack: &mut [Open], root: &mut Option<Rc<Element>>) {
    open.el.src.end = end;
    let is_xacro = open.el.name.starts_with("xacro:");
    let inside = open.el.src.xacro_inside;
    // Seen from its parent, an element's own name counts too.
    let computed_inside = open.el.src.computed_inside || open.el.attr("name").is_some_and(computed);
    let el = Rc::new(open.el);
    match stack.last_mut() {
        Some(parent) => {
            if is_xacro || inside {
                parent.el.src.xacro_inside = true;
            }
            parent.el.src.computed_inside |= computed_inside;
            parent.el.children.push(Node::Element(el));
        }
        None => *root = Some(el),
    }
}

/// Escapes text for XML content (`&`, `<`, `>`) or, with `quote`, an attribute value (also `"`).
pub fn escape(s: &str, quote: bool) -> std::borrow::Cow<'_, str> {
    if !s.contains(['&', '<', '>', '"']) {
        return std::borrow::Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' if quote => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// The serialised document and, per output line (index 0 is line 1), the element that starts
/// there, if any.
#[derive(Debug)]
pub struct Printed<'a> {
    pub text: String,
    pub line_elements: Vec<Option<&'a Element>>,
}

/// Writes `root` (after `leading` comments) as xacro prints it: an XML declaration, then one
/// element per line with two spaces per level; whitespace-only text between elements is dropped
/// and an element whose only child is text keeps it on its line.
pub fn print<'a>(leading: &[String], root: &'a Element) -> Printed<'a> {
    let mut p = Printer {
        text: String::from("<?xml version=\"1.0\" ?>\n"),
        line_elements: vec![None],
    };
    for c in leading {
        p.line(&format!("<!--{c}-->"), None);
    }
    p.element(root, 0);
    Printed {
        text: p.text,
        line_elements: p.line_elements,
    }
}

struct Printer<'a> {
    text: String,
    line_elements: Vec<Option<&'a Element>>,
}

impl<'a> Printer<'a> {
    fn line(&mut self, s: &str, el: Option<&'a Element>) {
        self.text.push_str(s);
        self.text.push('\n');
        // A line may hold newlines of its own (a multi-line comment or text): each counts.
        let extra = s.bytes().filter(|b| *b == b'\n').count();
        self.line_elements.push(el);
        for _ in 0..extra {
            self.line_elements.push(None);
        }
    }

    fn open_tag(e: &Element, indent: &str) -> String {
        let mut s = format!("{indent}<{}", e.name);
        for (k, v) in &e.attrs {
            s.push(' ');
            s.push_str(k);
            s.push_str("=\"");
            s.push_str(&escape(v, true));
            s.push('"');
        }
        s
    }

    fn element(&mut self, e: &'a Element, depth: usize) {
        let indent = "  ".repeat(depth);
        let mut tag = Self::open_tag(e, &indent);
        let kids: Vec<&Node> = e
            .children
            .iter()
            .filter(|c| !matches!(c, Node::Text(t) if t.trim().is_empty()))
            .collect();
        match kids.as_slice() {
            [] => {
                tag.push_str("/>");
                self.line(&tag, Some(e));
            }
            [Node::Text(t)] => {
                tag.push('>');
                tag.push_str(&escape(t, false));
                tag.push_str("</");
                tag.push_str(&e.name);
                tag.push('>');
                self.line(&tag, Some(e));
            }
            _ => {
                tag.push('>');
                self.line(&tag, Some(e));
                let inner = "  ".repeat(depth + 1);
                for k in kids {
                    match k {
                        Node::Element(c) => self.element(c, depth + 1),
                        Node::Text(t) => {
                            self.line(&format!("{inner}{}", escape(t.trim(), false)), None);
                        }
                        Node::Comment(c) => self.line(&format!("{inner}<!--{c}-->"), None),
                        Node::CData(c) => self.line(&format!("{inner}<![CDATA[{c}]]>"), None),
                    }
                }
                self.line(&format!("{indent}</{}>", e.name), None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_lines_and_macro_bodies_are_recorded() {
        let text = "<?xml version=\"1.0\"?>\n<robot xmlns:xacro=\"x\">\n  <link name=\"a\"/>\n  <xacro:macro name=\"m\">\n    <link name=\"${n}\"><inertial/></link>\n  </xacro:macro>\n</robot>\n";
        let root = parse(text, 0).expect("parses");
        let els: Vec<&Rc<Element>> = root.elements().collect();
        assert_eq!(els[0].src.line, 3);
        assert_eq!(
            &text[els[0].src.start..els[0].src.end],
            "<link name=\"a\"/>"
        );
        assert!(!els[0].src.in_macro && els[0].src.name_literal);
        let inner = els[1].elements().next().expect("link in macro");
        assert!(inner.src.in_macro && !inner.src.name_literal);
        assert_eq!(inner.src.line, 5);
        assert!(root.src.xacro_inside && !els[0].src.xacro_inside);
    }

    #[test]
    fn malformed_xml_names_its_line() {
        let e = parse("<robot>\n<link>\n</robot>", 0).expect_err("mismatched");
        assert_eq!(e.line, 3, "{e:?}");
    }

    #[test]
    fn printing_is_xacro_s_pretty_form() {
        let root = parse(
            "<robot name=\"r\">\n  <link name=\"a &amp; b\">\n    <mass value=\"1\"/>\n    <note>x &lt; y</note>\n  </link>\n  <!-- c -->\n</robot>",
            0,
        )
        .expect("parses");
        let p = print(&[], &root);
        assert_eq!(
            p.text,
            "<?xml version=\"1.0\" ?>\n<robot name=\"r\">\n  <link name=\"a &amp; b\">\n    <mass value=\"1\"/>\n    <note>x &lt; y</note>\n  </link>\n  <!-- c -->\n</robot>\n"
        );
        assert_eq!(p.line_elements[2].map(|e| e.name.as_str()), Some("link"));
        assert_eq!(p.line_elements[3].map(|e| e.src.line), Some(3));
    }
}
