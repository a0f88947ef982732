//! The scanner: one pass over the XML events, keeping what urdfdom keeps and noting what it ignores.

use super::model::{Collision, Geometry, Inertial, InertialSpan, Link, Pose};
use super::values::{attrs, geometry, num, pose};
use super::{describe, line_col, UrdfError};
use crate::diagnostic::{Code, Diagnostic, Location};
use crate::text::LineCounter;
use quick_xml::events::Event;
use quick_xml::reader::Reader;
use std::collections::HashMap;
use std::path::Path;

fn indent_before(text: &str, pos: usize) -> Option<String> {
    let line_start = text[..pos].rfind('\n').map_or(0, |i| i + 1);
    let ws = &text[line_start..pos];
    if ws.chars().all(|c| c == ' ' || c == '\t') {
        Some(ws.to_string())
    } else {
        None
    }
}
/// Adds the xacro hint to a message that holds an unexpanded `${…}` or `$(…)`.
fn xacro_hint(message: String) -> String {
    if message.contains("${") || message.contains("$(") {
        format!("{message} (an unexpanded xacro expression: run `xacro FILE.urdf.xacro > FILE.urdf` first)")
    } else {
        message
    }
}

/// The `<collision>` being read.
struct CollisionInProgress {
    /// A `<visual>`: read the same way, its warnings left out (urdfdom's rules for collisions are
    /// what the tool checks; visuals are read only for `--geometry collision,visual`).
    visual: bool,
    index: usize,
    line: usize,
    name: Option<String>,
    origin: Pose,
    /// Line of the first `<origin>` (the one urdfdom reads).
    origin_line: Option<usize>,
    /// `<geometry>` elements seen so far.
    geometries: usize,
    /// The first child element of the first `<geometry>`: what it became, its name and line.
    shape: Option<(Geometry, String, usize)>,
    /// A problem with the collision's own `<origin>` (a [`Geometry::Invalid`]).
    error: Option<Geometry>,
}

/// The `<inertial>` being read.
struct InertialInProgress {
    span: InertialSpan,
    /// Whether it is the link's first (only the first is read).
    first: bool,
    /// Lines of the `<origin>`, `<mass>` and `<inertia>` read so far.
    seen: HashMap<String, usize>,
}

/// A diagnostic of the scan at `line`, about `link` if any (the file is added when the scan ends).
fn diagnostic(code: Code, line: usize, link: Option<&str>, message: String) -> Diagnostic {
    Diagnostic::new(code, message).at(Location {
        file: None,
        line: Some(line),
        link: link.map(str::to_string),
        collision: None,
    })
}

/// An element urdfdom ignores, in the link being read.
fn warning(line: usize, link: Option<&Link>, message: String) -> Diagnostic {
    diagnostic(
        Code::UrdfIgnoredElement,
        line,
        link.map(|l| l.name.as_str()),
        message,
    )
}

/// One start (or empty) tag as the scanner sees it.
struct Tag<'a> {
    /// Its attributes.
    a: &'a HashMap<String, String>,
    /// Byte offset of its `<`.
    pos: usize,
    /// Byte offset just after its `>`.
    end: usize,
    /// Its line.
    line: usize,
    /// Whether it is self-closing (`<x/>`).
    empty: bool,
}

/// The state of one scan: the open elements and the link, collision and inertial being read. One method
/// per element kind keeps each of urdfdom's reading rules in a small place.
pub(super) struct Scanner<'t> {
    text: &'t str,
    path: &'t Path,
    /// Length of a UTF-8 byte-order mark, which quick-xml does not count in its positions.
    bom: usize,
    stack: Vec<String>,
    robot_name: Option<String>,
    links: Vec<Link>,
    current: Option<Link>,
    collision: Option<CollisionInProgress>,
    inertial: Option<InertialInProgress>,
    /// The line of each link name seen so far.
    seen: HashMap<String, usize>,
    notes: Vec<Diagnostic>,
    /// Line of the first sign of xacro (xmlns:xacro on the root, a <xacro:…> element).
    xacro: Option<usize>,
    /// Line of the root if it declares xmlns:xacro (xacro's own output keeps the declaration).
    xacro_namespace: Option<usize>,
}

/// What a scan yields besides the text: the robot's name, its links and the diagnostics.
pub(super) type Scanned = (String, Vec<Link>, Vec<Diagnostic>);

impl<'t> Scanner<'t> {
    pub(super) fn new(text: &'t str, path: &'t Path) -> Self {
        // quick-xml does not count a UTF-8 byte-order mark in its positions: read after it and add it back.
        let bom = if text.starts_with('\u{feff}') {
            '\u{feff}'.len_utf8()
        } else {
            0
        };
        Scanner {
            text,
            path,
            bom,
            stack: Vec::new(),
            robot_name: None,
            links: Vec::new(),
            current: None,
            collision: None,
            inertial: None,
            seen: HashMap::new(),
            notes: Vec::new(),
            xacro: None,
            xacro_namespace: None,
        }
    }

    /// The error at byte offset `pos`, with its line and column.
    fn err(&self, pos: usize, message: String) -> UrdfError {
        let (line, column) = line_col(self.text, pos);
        UrdfError {
            path: self.path.to_path_buf(),
            line,
            column,
            message: xacro_hint(message),
        }
    }

    /// Reads every event of the document, then checks how it ended.
    pub(super) fn run(mut self) -> Result<Scanned, UrdfError> {
        let mut reader = Reader::from_str(&self.text[self.bom..]);
        reader.config_mut().check_end_names = true;
        let mut lines = LineCounter::new(self.text.as_bytes());
        loop {
            let pos = self.bom + reader.buffer_position() as usize;
            let event = match reader.read_event() {
                Ok(e) => e,
                Err(e) => {
                    return Err(self.err(
                        self.bom + reader.error_position() as usize,
                        format!("malformed XML: {e}"),
                    ))
                }
            };
            let end = self.bom + reader.buffer_position() as usize;
            let (e, empty) = match event {
                Event::Start(e) => (e, false),
                Event::Empty(e) => (e, true),
                Event::End(_) => {
                    self.end_element(end);
                    continue;
                }
                Event::Eof => break,
                _ => continue,
            };
            let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
            if self.stack.is_empty() && self.robot_name.is_some() {
                // A second root: urdfdom reads the first root element only, so the rest is left
                // alone (filling it too would give the file inertials no consumer reads).
                let message = format!("a second root element <{name}> is ignored, with everything after it (urdfdom reads the first <robot> only); keep one <robot> per file");
                self.notes.push(warning(
                    lines.at(pos),
                    None,
                    crate::text::escape_control(&message).into_owned(),
                ));
                break;
            }
            let a = attrs(&e).map_err(|(at, m)| self.err(pos + 1 + at, m))?;
            let tag = Tag {
                a: &a,
                pos,
                end,
                line: lines.at(pos),
                empty,
            };
            self.start_element(&name, &tag)?;
            if !empty {
                self.stack.push(name);
            }
        }
        self.finish()
    }

    /// An end tag: finishes the link, collision or inertial it closes.
    fn end_element(&mut self, end: usize) {
        let name = self.stack.pop().unwrap_or_default();
        match (self.stack.len(), name.as_str()) {
            (1, "link") => {
                if let Some(link) = self.current.take() {
                    finish_link(link, &mut self.links, &mut self.notes);
                }
            }
            (2, "collision" | "visual") => {
                finish_collision(self.collision.take(), &mut self.current, &mut self.notes);
            }
            (2, "inertial") => {
                if let Some(mut i) = self.inertial.take() {
                    i.span.end = end;
                    finish_inertial(i, &mut self.current, &mut self.notes);
                }
            }
            _ => {}
        }
    }

    /// A start or empty tag: dispatches on its depth and name (and its parents').
    fn start_element(&mut self, name: &str, tag: &Tag<'_>) -> Result<(), UrdfError> {
        if name.starts_with("xacro:") {
            self.xacro.get_or_insert(tag.line);
        }
        let in_collision = self
            .stack
            .get(2)
            .is_some_and(|s| s == "collision" || s == "visual");
        match (self.stack.len(), name) {
            (0, "robot") => {
                self.robot_name = Some(tag.a.get("name").cloned().unwrap_or_default());
                if tag.a.contains_key("xmlns:xacro") {
                    self.xacro_namespace = Some(tag.line);
                }
            }
            (0, other) => return Err(self.err(tag.pos, format!("the root element is <{other}>, not <robot>: this is not a URDF (run xacro first if it is a .xacro file)"))),
            (1, "link") => self.link(tag)?,
            (2, child) if self.current.is_some() => self.link_child(child, tag),
            (3, "origin") if in_collision => self.collision_origin(tag),
            (3, "geometry") if in_collision => self.collision_geometry(tag.line),
            (4, g) if in_collision && self.stack[3] == "geometry" => self.shape(g, tag),
            (3, child @ ("origin" | "mass" | "inertia")) if self.stack[2] == "inertial" => {
                self.inertial_child(child, tag);
            }
            _ => {}
        }
        Ok(())
    }

    /// `<link>`: a new link (names must be unique, as urdfdom requires).
    fn link(&mut self, tag: &Tag<'_>) -> Result<(), UrdfError> {
        let (pos, line) = (tag.pos, tag.line);
        let lname = tag
            .a
            .get("name")
            .cloned()
            .ok_or_else(|| self.err(pos, "<link> without a name".into()))?;
        if let Some(first) = self.seen.insert(lname.clone(), line) {
            return Err(self.err(pos, format!("duplicate link name `{lname}` on lines {first} and {line}; link names must be unique (urdfdom refuses the file too)")));
        }
        let link = Link {
            name: lname,
            line,
            start: pos,
            open_end: tag.end,
            self_closing: tag.empty,
            indent: indent_before(self.text, pos).unwrap_or_default(),
            child_indent: None,
            inertial: None,
            extra_inertials: Vec::new(),
            collisions: Vec::new(),
            visuals: Vec::new(),
            from_visual: false,
        };
        if tag.empty {
            finish_link(link, &mut self.links, &mut self.notes);
        } else {
            self.current = Some(link);
        }
        Ok(())
    }

    /// A child of `<link>`: starts a `<collision>` or an `<inertial>`; notes the children's indent.
    fn link_child(&mut self, child: &str, tag: &Tag<'_>) {
        if let Some(link) = self.current.as_mut() {
            if link.child_indent.is_none() {
                link.child_indent = indent_before(self.text, tag.pos);
            }
        }
        match child {
            "collision" | "visual" => {
                let visual = child == "visual";
                let index = self.current.as_ref().map_or(1, |l| {
                    1 + if visual {
                        l.visuals.len()
                    } else {
                        l.collisions.len()
                    }
                });
                self.collision = Some(CollisionInProgress {
                    visual,
                    index,
                    line: tag.line,
                    name: tag.a.get("name").cloned(),
                    origin: Pose::default(),
                    origin_line: None,
                    geometries: 0,
                    shape: None,
                    error: None,
                });
                if tag.empty {
                    finish_collision(self.collision.take(), &mut self.current, &mut self.notes);
                }
            }
            "inertial" => {
                let first = self.current.as_ref().is_some_and(|l| l.inertial.is_none());
                let span = InertialSpan {
                    start: tag.pos,
                    end: tag.end,
                    line: tag.line,
                    value: Inertial::default(),
                    problem: None,
                    mass_line: None,
                };
                let i = InertialInProgress {
                    span,
                    first,
                    seen: HashMap::new(),
                };
                if tag.empty {
                    finish_inertial(i, &mut self.current, &mut self.notes);
                } else {
                    self.inertial = Some(i);
                }
            }
            _ => {}
        }
    }

    /// `<origin>` in `<collision>`: the first is read, later ones are ignored with a warning.
    fn collision_origin(&mut self, tag: &Tag<'_>) {
        let line = tag.line;
        let Some(c) = self.collision.as_mut() else {
            return;
        };
        match c.origin_line {
            None => {
                c.origin_line = Some(line);
                match pose(tag.a) {
                    Ok(p) => c.origin = p,
                    Err(m) => c.error = Some(Geometry::Invalid { line, message: xacro_hint(format!("<origin> {m}")) }),
                }
            }
            Some(_) if c.visual => {}
            Some(first) => self.notes.push(warning(line, self.current.as_ref(), format!("collision {}: a second <origin> is ignored (urdfdom reads the first, on line {first}); remove one", c.index))),
        }
    }

    /// `<geometry>` in `<collision>`: counted, since urdfdom reads only the first.
    fn collision_geometry(&mut self, line: usize) {
        if let Some(c) = self.collision.as_mut() {
            c.geometries += 1;
            if c.geometries > 1 && !c.visual {
                self.notes.push(warning(line, self.current.as_ref(), format!("collision {}: a second <geometry> is ignored (urdfdom reads the first); give each shape its own <collision>", c.index)));
            }
        }
    }

    /// A child `g` of the first `<geometry>`: the first is the shape, later ones are ignored with a warning.
    fn shape(&mut self, g: &str, tag: &Tag<'_>) {
        let line = tag.line;
        let Some(c) = self.collision.as_mut().filter(|c| c.geometries == 1) else {
            return;
        };
        match &c.shape {
            None => {
                let geometry = if g == "origin" {
                    Geometry::Invalid { line, message: "<origin> is the first element of <geometry>, where the shape (box, cylinder, sphere, capsule or mesh) must be, so urdfdom refuses this collision; move the <origin> into <collision>, before <geometry>".into() }
                } else {
                    geometry(g, tag.a).unwrap_or_else(|m| Geometry::Invalid {
                        line,
                        message: xacro_hint(m),
                    })
                };
                c.shape = Some((geometry, g.to_string(), line));
            }
            Some(_) if c.visual => {}
            Some((_, first, first_line)) => {
                let message = if g == "origin" {
                    format!("collision {}: <origin> inside <geometry> is ignored (as urdfdom does): an origin belongs in <collision>, before <geometry>", c.index)
                } else {
                    format!("collision {}: a second shape <{g}> in <geometry> is ignored (urdfdom reads only the first, <{first}> on line {first_line}); give each shape its own <collision>", c.index)
                };
                self.notes.push(warning(line, self.current.as_ref(), message));
            }
        }
    }

    /// `<origin>`, `<mass>` or `<inertia>` in the link's first `<inertial>`: the first of each is read.
    fn inertial_child(&mut self, child: &str, tag: &Tag<'_>) {
        let (a, line) = (tag.a, tag.line);
        let Some(i) = self.inertial.as_mut().filter(|i| i.first) else {
            return;
        };
        if let Some(first) = i.seen.get(child) {
            self.notes.push(warning(line, self.current.as_ref(), format!("a second <{child}> in <inertial> is ignored (urdfdom reads the first, on line {first})")));
            return;
        }
        i.seen.insert(child.to_string(), line);
        let span = &mut i.span;
        if child == "mass" {
            span.mass_line = Some(line);
        }
        let r = match child {
            "origin" => pose(a).map(|p| span.value.origin = p),
            "mass" => num(a, "value").map(|m| span.value.mass = Some(m)),
            _ => (|| {
                Ok([
                    num(a, "ixx")?,
                    num(a, "ixy")?,
                    num(a, "ixz")?,
                    num(a, "iyy")?,
                    num(a, "iyz")?,
                    num(a, "izz")?,
                ])
            })()
            .map(|i| span.value.inertia = Some(i)),
        };
        if let Err(m) = r {
            span.problem
                .get_or_insert(format!("line {line}: <{child}>: {m}"));
        }
    }

    /// The end of the document: a `<robot>` must have been read and closed; adds the xacro note and
    /// puts the diagnostics in line order with the file.
    fn finish(mut self) -> Result<Scanned, UrdfError> {
        let Some(name) = self.robot_name.take() else {
            return Err(self.err(0, "no <robot> element: this is not a URDF".into()));
        };
        if !self.stack.is_empty() {
            return Err(self.err(
                self.text.len(),
                format!(
                    "the file ends inside <{}>",
                    self.stack.last().cloned().unwrap_or_default()
                ),
            ));
        }
        let xacro_note = match (self.xacro, self.xacro_namespace) {
            (Some(line), _) => Some((Code::UrdfXacro, line, "this file uses xacro (<xacro:…> elements): links inside xacro macros are not seen and ${…} expressions are not expanded; run `xacro FILE.urdf.xacro > FILE.urdf` first and give urdf-inertia the result")),
            // xacro's output keeps the declaration, so most expanded URDFs have it: a softer note.
            (None, Some(line)) => Some((Code::UrdfXacroNamespace, line, "the root declares xmlns:xacro: if this is a xacro source rather than xacro's output, links inside its macros are not seen; run `xacro FILE.urdf.xacro > FILE.urdf` first")),
            (None, None) => None,
        };
        let mut notes = self.notes;
        if let Some((code, line, message)) = xacro_note {
            notes.push(diagnostic(code, line, None, message.into()));
        }
        notes.sort_by_key(Diagnostic::line);
        for n in &mut notes {
            if let Some(l) = n.location.as_mut() {
                l.file = Some(self.path.to_path_buf());
            }
        }
        Ok((name, self.links, notes))
    }
}

/// Ends a link: notes for its zero-size parts, then into the list.
fn finish_link(link: Link, links: &mut Vec<Link>, notes: &mut Vec<Diagnostic>) {
    let zero: Vec<&Collision> = link
        .collisions
        .iter()
        .filter(|c| c.geometry.is_zero_size())
        .collect();
    let note = |line: usize, message: String| {
        diagnostic(Code::UrdfZeroVolume, line, Some(&link.name), message)
    };
    if !zero.is_empty() && !link.has_collision_geometry() {
        let parts: Vec<String> = zero
            .iter()
            .map(|c| format!("collision {}: {}", c.index, describe(&c.geometry)))
            .collect();
        notes.push(note(link.line, format!("its collision geometry has no volume ({}): the link is left as it is, like a link without collision geometry", parts.join("; "))));
    } else {
        for c in zero {
            notes.push(note(
                c.line,
                format!(
                    "collision {}: {} has no volume and contributes nothing",
                    c.index,
                    describe(&c.geometry)
                ),
            ));
        }
    }
    links.push(link);
}

/// Ends the `<collision>` being read. One without a shape (urdfdom refuses it; some generators emit it)
/// contributes nothing, with a warning.
fn finish_collision(
    collision: Option<CollisionInProgress>,
    current: &mut Option<Link>,
    notes: &mut Vec<Diagnostic>,
) {
    let (Some(c), Some(link)) = (collision, current.as_mut()) else {
        return;
    };
    let geometry = match (c.error, c.shape) {
        (Some(e), _) => e,
        (None, Some((g, _, _))) => g,
        (None, None) if c.visual => return,
        (None, None) => {
            let what = if c.geometries == 0 {
                "has no <geometry>"
            } else {
                "has an empty <geometry>"
            };
            notes.push(diagnostic(
                Code::UrdfEmptyCollision,
                c.line,
                Some(&link.name),
                format!("a collision {what}: it is ignored (urdfdom refuses such a collision)"),
            ));
            return;
        }
    };
    let list = if c.visual {
        &mut link.visuals
    } else {
        &mut link.collisions
    };
    list.push(Collision {
        index: c.index,
        name: c.name,
        line: c.line,
        origin: c.origin,
        geometry,
    });
}

/// Ends an `<inertial>`: the first is the link's, later ones are kept only to be removed by `fill`.
fn finish_inertial(i: InertialInProgress, current: &mut Option<Link>, notes: &mut Vec<Diagnostic>) {
    let Some(link) = current.as_mut() else {
        return;
    };
    if i.first {
        link.inertial = Some(i.span);
    } else {
        let first = link.inertial.as_ref().map_or(link.line, |s| s.line);
        notes.push(diagnostic(
            Code::UrdfIgnoredElement,
            i.span.line,
            Some(&link.name),
            format!("a second <inertial> is ignored (urdfdom reads the first, on line {first}); `fill` replaces them all with one"),
        ));
        link.extra_inertials.push(i.span);
    }
}
