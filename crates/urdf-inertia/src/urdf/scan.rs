//! A one-pass scan of a URDF: links, their collisions, their existing `<inertial>` and the byte spans
//! the writer needs.
//!
//! It reads what urdfdom (behind ROS, Gazebo, MoveIt, pinocchio) reads: the first `<inertial>` of a link,
//! the first `<origin>` and `<geometry>` of a collision and the first child element of `<geometry>`;
//! later ones are ignored with a warning. Zero-size primitives are valid (they have no volume). Anything
//! wrong inside one collision (an unknown shape, a bad number) is that collision's
//! [`Geometry::Invalid`], the link's failure, not the file's; malformed XML and duplicate link names
//! are the file's.

use crate::diagnostic::{Code, Diagnostic, Location};
use crate::mass::primitives;
use crate::text::LineCounter;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

pub use super::encoding::SourceEncoding;

/// A pose: translation and URDF roll-pitch-yaw (fixed axes X, Y, Z).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Pose {
    pub xyz: [f64; 3],
    pub rpy: [f64; 3],
}

/// A collision geometry as the URDF gives it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Geometry {
    Mesh {
        filename: String,
        scale: [f64; 3],
    },
    Box {
        size: [f64; 3],
    },
    Cylinder {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    Capsule {
        radius: f64,
        length: f64,
    },
    /// A collision that cannot be computed (an unknown shape, a bad or overflowing number): the failure
    /// of its link only. `line` is where the problem is.
    Invalid {
        line: usize,
        message: String,
    },
}

impl Geometry {
    /// Whether this is a primitive without volume (`<sphere radius="0"/>`, `<box size="0 0 0"/>`, a
    /// zero-length cylinder): valid URDF that contributes nothing.
    pub fn is_zero_size(&self) -> bool {
        match self {
            Geometry::Box { size } => primitives::cuboid(*size, 1.0).mass == 0.0,
            Geometry::Cylinder { radius, length } => {
                primitives::cylinder(*radius, *length, 1.0).mass == 0.0
            }
            Geometry::Sphere { radius } => primitives::sphere(*radius, 1.0).mass == 0.0,
            Geometry::Capsule { radius, length } => {
                primitives::capsule(*radius, *length, 1.0).mass == 0.0
            }
            Geometry::Mesh { .. } | Geometry::Invalid { .. } => false,
        }
    }
}

/// One `<collision>` of a link.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Collision {
    /// 1-based position among the link's collisions.
    pub index: usize,
    pub name: Option<String>,
    pub line: usize,
    pub origin: Pose,
    pub geometry: Geometry,
}

/// An existing `<inertial>` as parsed (missing parts are `None`).
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Inertial {
    pub origin: Pose,
    pub mass: Option<f64>,
    /// ixx, ixy, ixz, iyy, iyz, izz.
    pub inertia: Option<[f64; 6]>,
}

/// The existing `<inertial>` of a link: where it is and what it says.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct InertialSpan {
    pub start: usize,
    pub end: usize,
    pub line: usize,
    pub value: Inertial,
    /// A problem reading its numbers, if any (the link is then treated as having an invalid inertial).
    pub problem: Option<String>,
    /// The line of its (first) `<mass>`, if it has one: `--keep-mass` names it when the value is no
    /// usable mass.
    pub mass_line: Option<usize>,
}

/// A `<link>` with everything the tool needs.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Link {
    pub name: String,
    pub line: usize,
    /// Byte offset of `<link`.
    pub start: usize,
    /// Byte offset just after the start tag's `>`.
    pub open_end: usize,
    pub self_closing: bool,
    /// Whitespace before `<link` on its line.
    pub indent: String,
    /// Whitespace before the link's first child element on its line, if the link has children on lines of their own.
    pub child_indent: Option<String>,
    /// The first `<inertial>`: the one urdfdom reads.
    pub inertial: Option<InertialSpan>,
    /// Further `<inertial>` elements, which urdfdom ignores (only their spans are read: `fill` removes them).
    pub extra_inertials: Vec<InertialSpan>,
    pub collisions: Vec<Collision>,
    /// The `<visual>` elements, read as collisions are (without their warnings): what
    /// `--geometry collision,visual` computes a link from when it has no collision geometry.
    pub visuals: Vec<Collision>,
    /// Whether `collisions` were taken from `visuals` ([`Robot::use_visual_geometry`]).
    pub from_visual: bool,
}

impl Link {
    /// Whether the link has collision geometry to compute (or to fail on): a collision that is not a
    /// zero-size primitive. A link with none is left as it is, like a frame without collisions.
    pub fn has_collision_geometry(&self) -> bool {
        self.collisions.iter().any(|c| !c.geometry.is_zero_size())
    }
}

/// A scanned URDF.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Robot {
    pub path: PathBuf,
    pub name: String,
    /// The file's text, decoded to UTF-8 (see [`SourceEncoding`]).
    pub text: String,
    pub links: Vec<Link>,
    /// "\r\n" when the file uses CRLF line endings.
    pub newline: &'static str,
    /// The file's encoding, to write it back in.
    pub encoding: SourceEncoding,
    /// Warnings and notes, in file order, located in this file.
    pub notes: Vec<Diagnostic>,
}

impl Robot {
    /// Whether no link has collision geometry while some have visual geometry (a visual-only
    /// robot: `fill` would compute nothing).
    pub fn visual_only(&self) -> bool {
        !self.links.iter().any(Link::has_collision_geometry)
            && self
                .links
                .iter()
                .any(|l| l.visuals.iter().any(|v| !v.geometry.is_zero_size()))
    }

    /// `--geometry collision,visual`: each link without collision geometry gets its visual
    /// geometry as its collisions (marked [`Link::from_visual`]); the names of those links.
    pub fn use_visual_geometry(&mut self) -> Vec<String> {
        let mut out = Vec::new();
        for l in &mut self.links {
            if !l.has_collision_geometry() && l.visuals.iter().any(|v| !v.geometry.is_zero_size()) {
                l.collisions = l.visuals.clone();
                l.from_visual = true;
                out.push(l.name.clone());
            }
        }
        out
    }
}

/// Why a URDF cannot be read.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct UrdfError {
    pub path: PathBuf,
    pub line: usize,
    pub column: usize,
    pub message: String,
}

impl fmt::Display for UrdfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: {}",
            self.path.display(),
            self.line,
            self.column,
            self.message
        )
    }
}

impl std::error::Error for UrdfError {}

/// Line and column (1-based) of a byte offset.
pub fn line_col(text: &str, pos: usize) -> (usize, usize) {
    let pos = pos.min(text.len());
    let before = &text.as_bytes()[..pos];
    let line = 1 + crate::text::count_newlines(before);
    let col = 1 + pos
        - before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
    (line, col)
}

/// The attributes of a start tag. A duplicate or malformed attribute is malformed XML (urdfdom's
/// TinyXML refuses the file): its offset in the tag (after `<`) and the message.
fn attrs(e: &BytesStart<'_>) -> Result<HashMap<String, String>, (usize, String)> {
    let mut m = HashMap::new();
    for a in e.attributes().with_checks(true) {
        let a = a.map_err(|err| match err {
            AttrError::Duplicated(at, _) => {
                let key: String = String::from_utf8_lossy(e.get(at..).unwrap_or_default())
                    .chars()
                    .take_while(|c| *c != '=' && !c.is_whitespace())
                    .collect();
                (at, format!("attribute `{key}` is given twice in <{}>; an attribute may appear once (which value is meant?)", String::from_utf8_lossy(e.name().as_ref())))
            }
            AttrError::ExpectedEq(at)
            | AttrError::ExpectedValue(at)
            | AttrError::UnquotedValue(at)
            | AttrError::ExpectedQuote(at, _) => (at, format!("malformed attribute: {err}")),
        })?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let v = a.unescape_value().map_or_else(
            |_| String::from_utf8_lossy(&a.value).into_owned(),
            |v| v.into_owned(),
        );
        m.insert(key, v);
    }
    Ok(m)
}

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

/// Decodes a URDF file's bytes (see [`super::encoding`]) and scans the text.
pub fn scan_bytes(bytes: Vec<u8>, path: &Path) -> Result<Robot, UrdfError> {
    let (text, encoding) = match super::encoding::decode(bytes) {
        Ok(d) => d,
        Err(e) => {
            return Err(UrdfError {
                path: path.to_path_buf(),
                line: e.line,
                column: e.column,
                message: e.message,
            })
        }
    };
    let mut robot = scan(text, path)?;
    robot.encoding = encoding;
    Ok(robot)
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
fn warning(line: usize, link: &Option<Link>, message: String) -> Diagnostic {
    diagnostic(
        Code::UrdfIgnoredElement,
        line,
        link.as_ref().map(|l| l.name.as_str()),
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
struct Scanner<'t> {
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
type Scanned = (String, Vec<Link>, Vec<Diagnostic>);

impl<'t> Scanner<'t> {
    fn new(text: &'t str, path: &'t Path) -> Self {
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
    fn run(mut self) -> Result<Scanned, UrdfError> {
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
                    &None,
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
            Some(first) => self.notes.push(warning(line, &self.current, format!("collision {}: a second <origin> is ignored (urdfdom reads the first, on line {first}); remove one", c.index))),
        }
    }

    /// `<geometry>` in `<collision>`: counted, since urdfdom reads only the first.
    fn collision_geometry(&mut self, line: usize) {
        if let Some(c) = self.collision.as_mut() {
            c.geometries += 1;
            if c.geometries > 1 && !c.visual {
                self.notes.push(warning(line, &self.current, format!("collision {}: a second <geometry> is ignored (urdfdom reads the first); give each shape its own <collision>", c.index)));
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
                self.notes.push(warning(line, &self.current, message));
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
            self.notes.push(warning(line, &self.current, format!("a second <{child}> in <inertial> is ignored (urdfdom reads the first, on line {first})")));
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

/// Scans URDF text. `path` is used in messages and for resolving relative mesh paths.
pub fn scan(text: String, path: &Path) -> Result<Robot, UrdfError> {
    // Lines ended by CR alone (classic Mac OS): scanned as XML reads them (end-of-line handling turns
    // each CR into LF, XML 1.0 section 2.11), byte for byte the same length, so every span stays
    // right, every message gets its own line, and the writer ends inserted lines with CR.
    let cr_only = !text.contains('\n') && text.contains('\r');
    let (name, links, notes) = if cr_only {
        Scanner::new(&text.replace('\r', "\n"), path).run()?
    } else {
        Scanner::new(&text, path).run()?
    };
    let newline = if text.contains("\r\n") {
        "\r\n"
    } else if cr_only {
        "\r"
    } else {
        "\n"
    };
    Ok(Robot {
        path: path.to_path_buf(),
        name,
        text,
        links,
        newline,
        encoding: SourceEncoding::Utf8,
        notes,
    })
}

/// A short description of a geometry for messages: `box 1 2 3`, `sphere radius 0`.
pub fn describe(g: &Geometry) -> String {
    let n = crate::text::shortest;
    match g {
        Geometry::Mesh { filename, .. } => format!("mesh {filename}"),
        Geometry::Box { size } => format!("box size {} {} {}", n(size[0]), n(size[1]), n(size[2])),
        Geometry::Cylinder { radius, length } => {
            format!("cylinder radius {} length {}", n(*radius), n(*length))
        }
        Geometry::Sphere { radius } => format!("sphere radius {}", n(*radius)),
        Geometry::Capsule { radius, length } => {
            format!("capsule radius {} length {}", n(*radius), n(*length))
        }
        Geometry::Invalid { message, .. } => message.clone(),
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

fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<&str> = s.split_ascii_whitespace().collect();
    if v.len() != 3 {
        return Err(format!(
            "\"{s}\" should be three numbers, not {} (urdfdom logs an error and drops this link's collision geometry)",
            v.len()
        ));
    }
    let mut out = [0.0; 3];
    for (o, w) in out.iter_mut().zip(v) {
        *o = w
            .parse::<f64>()
            .map_err(|_| format!("\"{w}\" in \"{s}\" is not a number"))?;
        if !o.is_finite() {
            return Err(format!("\"{s}\" is not finite"));
        }
    }
    Ok(out)
}

fn pose(a: &HashMap<String, String>) -> Result<Pose, String> {
    Ok(Pose {
        xyz: a
            .get("xyz")
            .map(|s| parse_vec3(s).map_err(|m| format!("xyz {m}")))
            .transpose()?
            .unwrap_or([0.0; 3]),
        rpy: a
            .get("rpy")
            .map(|s| parse_vec3(s).map_err(|m| format!("rpy {m}")))
            .transpose()?
            .unwrap_or([0.0; 3]),
    })
}

fn num(a: &HashMap<String, String>, key: &str) -> Result<f64, String> {
    let s = a
        .get(key)
        .ok_or_else(|| format!("missing attribute `{key}`"))?;
    s.trim().parse::<f64>().map_err(|_| {
        format!(
            "{key}=\"{}\" is not a number",
            crate::text::escape_control(s)
        )
    })
}

/// A primitive's size: finite and not negative (zero is valid URDF).
fn size(a: &HashMap<String, String>, key: &str) -> Result<f64, String> {
    let v = num(a, key)?;
    if !v.is_finite() {
        Err(format!("{key}=\"{v}\" is not a finite number"))
    } else if v < 0.0 {
        Err(format!("{key}=\"{v}\" must not be negative"))
    } else {
        Ok(v)
    }
}

fn geometry(kind: &str, a: &HashMap<String, String>) -> Result<Geometry, String> {
    let g = match kind {
        "mesh" => {
            let filename = a
                .get("filename")
                .cloned()
                .ok_or("<mesh> without filename")?;
            let scale = match a.get("scale") {
                None => [1.0; 3],
                Some(s) => {
                    let v: Vec<&str> = s.split_ascii_whitespace().collect();
                    // urdfdom accepts one number for a uniform scale as well as three.
                    if v.len() == 1 {
                        let x: f64 = v[0]
                            .parse()
                            .map_err(|_| format!("scale \"{s}\" is not a number"))?;
                        if !x.is_finite() {
                            return Err(format!("scale \"{s}\" is not finite"));
                        }
                        [x; 3]
                    } else {
                        parse_vec3(s).map_err(|m| format!("mesh scale {m}"))?
                    }
                }
            };
            if scale.contains(&0.0) {
                return Err(format!(
                    "mesh scale \"{} {} {}\" has a zero factor",
                    scale[0], scale[1], scale[2]
                ));
            }
            return Ok(Geometry::Mesh { filename, scale });
        }
        "box" => {
            let size = parse_vec3(a.get("size").ok_or("<box> without size")?)
                .map_err(|m| format!("box size {m}"))?;
            if size.iter().any(|x| *x < 0.0) {
                return Err(format!(
                    "box size \"{} {} {}\" must not be negative",
                    size[0], size[1], size[2]
                ));
            }
            Geometry::Box { size }
        }
        "cylinder" => Geometry::Cylinder {
            radius: size(a, "radius")?,
            length: size(a, "length")?,
        },
        "capsule" => Geometry::Capsule {
            radius: size(a, "radius")?,
            length: size(a, "length")?,
        },
        "sphere" => Geometry::Sphere {
            radius: size(a, "radius")?,
        },
        other => {
            return Err(format!(
                "unknown geometry <{other}> (urdfdom logs an error and drops this link's collision geometry); give this collision a <box>, <cylinder>, <sphere>, <capsule> or <mesh>"
            ))
        }
    };
    // A finite size can still overflow the volume or inertia (a box of 1e120 m): refuse it here.
    let unit = match &g {
        Geometry::Box { size } => primitives::cuboid(*size, 1.0),
        Geometry::Cylinder { radius, length } => primitives::cylinder(*radius, *length, 1.0),
        Geometry::Capsule { radius, length } => primitives::capsule(*radius, *length, 1.0),
        Geometry::Sphere { radius } => primitives::sphere(*radius, 1.0),
        Geometry::Mesh { .. } | Geometry::Invalid { .. } => return Ok(g),
    };
    if unit.mass.is_finite() && unit.inertia.iter().flatten().all(|x| x.is_finite()) {
        Ok(g)
    } else {
        Err(format!(
            "{} is too large: its volume or inertia overflows a 64-bit float (check the units: metres)",
            describe(&g)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scans_links_collisions_and_spans() {
        let text = "<?xml version=\"1.0\"?>\n<!-- c -->\n<robot name=\"r\">\n  <link name=\"a\">\n    <inertial>\n      <mass value=\"2\"/>\n    </inertial>\n    <collision>\n      <origin xyz=\"1 2 3\" rpy=\"0 0 1\"/>\n      <geometry><box size=\"1 2 3\"/></geometry>\n    </collision>\n  </link>\n  <link name=\"b\"/>\n  <gazebo><link name=\"fake\"/></gazebo>\n</robot>\n";
        let r = scan(text.to_string(), Path::new("r.urdf")).expect("scan");
        assert_eq!(r.links.len(), 2);
        let a = &r.links[0];
        assert_eq!(a.name, "a");
        assert_eq!(a.line, 4);
        assert_eq!(a.indent, "  ");
        assert_eq!(a.child_indent.as_deref(), Some("    "));
        let span = a.inertial.as_ref().expect("inertial");
        assert_eq!(
            &text[span.start..span.end],
            "<inertial>\n      <mass value=\"2\"/>\n    </inertial>"
        );
        assert_eq!(span.value.mass, Some(2.0));
        assert_eq!(a.collisions[0].origin.xyz, [1.0, 2.0, 3.0]);
        assert_eq!(
            a.collisions[0].geometry,
            Geometry::Box {
                size: [1.0, 2.0, 3.0]
            }
        );
        assert!(r.links[1].self_closing);
    }

    #[test]
    fn byte_order_mark_keeps_spans_right() {
        let text = "\u{feff}<robot name=\"r\">\n  <link name=\"a\">\n    <inertial><mass value=\"1\"/></inertial>\n  </link>\n</robot>\n";
        let r = scan(text.to_string(), Path::new("r.urdf")).expect("scan");
        let l = &r.links[0];
        assert_eq!(&text[l.start..l.open_end], "<link name=\"a\">");
        let span = l.inertial.as_ref().expect("inertial");
        assert_eq!(
            &text[span.start..span.end],
            "<inertial><mass value=\"1\"/></inertial>"
        );
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = scan(
            "<robot name=\"r\">\n  <link name=\"a\">\n  </lnk>\n</robot>".into(),
            Path::new("x.urdf"),
        )
        .unwrap_err();
        assert_eq!(e.line, 3, "{e}");
        let e = scan(
            "<robot name=\"r\"><link name=\"a\"/><link name=\"a\"/></robot>".into(),
            Path::new("x.urdf"),
        )
        .unwrap_err();
        assert!(e.message.contains("duplicate link name `a`"), "{e}");
        let e = scan("<sdf/>".into(), Path::new("x.urdf")).unwrap_err();
        assert!(e.message.contains("not a URDF"), "{e}");
    }

    /// The geometry of each collision of link `name`.
    fn geometries(r: &Robot, name: &str) -> Vec<Geometry> {
        r.links
            .iter()
            .find(|l| l.name == name)
            .map(|l| l.collisions.iter().map(|c| c.geometry.clone()).collect())
            .unwrap_or_default()
    }

    fn invalid(g: &Geometry) -> (usize, String) {
        match g {
            Geometry::Invalid { line, message } => (*line, message.clone()),
            other => panic!("expected Invalid, got {other:?}"),
        }
    }

    // Issue 11: a problem inside one collision is that link's, not the file's.
    #[test]
    fn bad_collisions_fail_their_link_only() {
        let text = "<robot name=\"r\">\n<link name=\"plane\"><collision><geometry><plane normal=\"0 0 1\"/></geometry></collision></link>\n<link name=\"scale\"><collision><geometry><mesh filename=\"m.stl\" scale=\"1 1 1 1\"/></geometry></collision></link>\n<link name=\"neg\"><collision><geometry><cylinder radius=\"-1\" length=\"1\"/></geometry></collision></link>\n<link name=\"nan\"><collision><geometry><sphere radius=\"nan\"/></geometry></collision></link>\n<link name=\"huge\"><collision><geometry><box size=\"1e120 1e120 1e120\"/></geometry></collision></link>\n<link name=\"xacro\"><collision><origin xyz=\"${x} 0 0\"/><geometry><box size=\"1 1 1\"/></geometry></collision></link>\n<link name=\"good\"><collision><geometry><box size=\"1 2 3\"/></geometry></collision></link>\n</robot>\n";
        let r =
            scan(text.into(), Path::new("x.urdf")).expect("one bad link does not refuse the file");
        let (line, m) = invalid(&geometries(&r, "plane")[0]);
        assert_eq!(line, 2);
        assert!(m.contains("unknown geometry <plane>"), "{m}");
        let (line, m) = invalid(&geometries(&r, "scale")[0]);
        assert_eq!(line, 3);
        assert!(m.contains("should be three numbers, not 4"), "{m}");
        assert!(invalid(&geometries(&r, "neg")[0])
            .1
            .contains("radius=\"-1\" must not be negative"));
        assert!(invalid(&geometries(&r, "nan")[0])
            .1
            .contains("not a finite number"));
        let (_, m) = invalid(&geometries(&r, "huge")[0]);
        assert!(m.contains("overflows"), "{m}");
        assert!(invalid(&geometries(&r, "xacro")[0])
            .1
            .contains("unexpanded xacro"));
        assert_eq!(
            geometries(&r, "good"),
            vec![Geometry::Box {
                size: [1.0, 2.0, 3.0]
            }]
        );
    }

    // Issue 11: urdfdom reads the first <inertial>, <origin>, <geometry> and shape; later ones warn.
    #[test]
    fn the_first_of_repeated_elements_wins() {
        let text = "<robot name=\"r\">\n<link name=\"a\">\n<inertial><mass value=\"1\"/><mass value=\"5\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>\n<inertial><mass value=\"2\"/></inertial>\n<collision>\n<origin xyz=\"1 0 0\"/>\n<origin xyz=\"2 0 0\"/>\n<geometry><box size=\"1 1 1\"/><sphere radius=\"3\"/>\n<origin xyz=\"5 5 5\"/></geometry>\n<geometry><sphere radius=\"4\"/></geometry>\n</collision>\n</link>\n</robot>\n";
        let r = scan(text.into(), Path::new("x.urdf")).expect("scan");
        let a = &r.links[0];
        let first = a.inertial.as_ref().expect("inertial");
        assert_eq!((first.line, first.value.mass), (3, Some(1.0)));
        assert_eq!(a.extra_inertials.len(), 1);
        assert_eq!(
            &text[a.extra_inertials[0].start..a.extra_inertials[0].end],
            "<inertial><mass value=\"2\"/></inertial>"
        );
        assert_eq!(a.collisions.len(), 1);
        assert_eq!(a.collisions[0].origin.xyz, [1.0, 0.0, 0.0]);
        assert_eq!(a.collisions[0].geometry, Geometry::Box { size: [1.0; 3] });
        let notes: Vec<(usize, &str)> = r
            .notes
            .iter()
            .map(|n| (n.line().unwrap_or(0), n.message.as_str()))
            .collect();
        let has =
            |line: usize, what: &str| notes.iter().any(|(l, m)| *l == line && m.contains(what));
        assert!(
            has(3, "a second <mass> in <inertial> is ignored"),
            "{notes:?}"
        );
        assert!(
            has(
                4,
                "a second <inertial> is ignored (urdfdom reads the first, on line 3)"
            ),
            "{notes:?}"
        );
        assert!(
            has(
                7,
                "a second <origin> is ignored (urdfdom reads the first, on line 6)"
            ),
            "{notes:?}"
        );
        assert!(has(8, "a second shape <sphere>"), "{notes:?}");
        assert!(
            has(9, "<origin> inside <geometry> is ignored") && has(9, "belongs in <collision>"),
            "{notes:?}"
        );
        assert!(has(10, "a second <geometry> is ignored"), "{notes:?}");
        assert!(r
            .notes
            .iter()
            .all(|n| n.code == Code::UrdfIgnoredElement && n.link() == Some("a")));
        // An <origin> where the shape should be is what urdfdom refuses: that collision's failure.
        let r = scan("<robot name=\"r\"><link name=\"a\"><collision><geometry><origin/><box size=\"1 1 1\"/></geometry></collision></link></robot>".into(), Path::new("x.urdf")).expect("scan");
        assert!(invalid(&geometries(&r, "a")[0])
            .1
            .contains("move the <origin> into <collision>"));
    }

    // Issue 11: zero-size primitives are valid URDF; a link left without volume has no collision geometry.
    #[test]
    fn zero_size_primitives_are_valid() {
        let text = "<robot name=\"r\">\n<link name=\"point\"><collision><geometry><sphere radius=\"0\"/></geometry></collision><collision><geometry><box size=\"0 0 0\"/></geometry></collision><collision><geometry><cylinder radius=\"1\" length=\"0\"/></geometry></collision></link>\n<link name=\"mixed\">\n<collision><geometry><capsule radius=\"0\" length=\"1\"/></geometry></collision>\n<collision><geometry><capsule radius=\"1\" length=\"0\"/></geometry></collision>\n</link>\n</robot>\n";
        let r = scan(text.into(), Path::new("x.urdf")).expect("zero sizes are valid");
        assert!(!r.links[0].has_collision_geometry());
        assert!(r.links[1].has_collision_geometry()); // a zero-length capsule is a sphere
        assert!(r.links[1].collisions[0].geometry.is_zero_size());
        assert!(!r.links[1].collisions[1].geometry.is_zero_size());
        assert!(
            r.notes
                .iter()
                .any(|n| n.line() == Some(2) && n.message.contains("left as it is")),
            "{:?}",
            r.notes
        );
        assert!(
            r.notes.iter().any(|n| n.line() == Some(4)
                && n.message
                    .contains("capsule radius 0 length 1 has no volume")),
            "{:?}",
            r.notes
        );
    }

    // Issue 11: duplicate attributes are malformed XML; duplicate link names name both lines.
    #[test]
    fn duplicate_attributes_and_links_are_errors() {
        let e = scan("<robot name=\"r\">\n  <link name=\"a\"><collision><geometry><box size=\"1 2 3\" size=\"4 5 6\"/></geometry></collision></link>\n</robot>".into(), Path::new("x.urdf")).unwrap_err();
        assert_eq!((e.line, e.column), (2, 57), "{e}");
        assert!(
            e.message
                .contains("attribute `size` is given twice in <box>"),
            "{e}"
        );
        let e = scan(
            "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"a\"/>\n</robot>".into(),
            Path::new("x.urdf"),
        )
        .unwrap_err();
        assert_eq!(e.line, 3);
        assert!(
            e.message
                .contains("duplicate link name `a` on lines 2 and 3"),
            "{e}"
        );
    }

    // Issue 11: xacro in the file gets one note.
    #[test]
    fn xacro_gets_one_note() {
        let text = "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n<xacro:macro name=\"m\"><link name=\"hidden\"/></xacro:macro>\n<xacro:m/>\n</robot>";
        let r = scan(text.into(), Path::new("x.urdf")).expect("scan");
        assert!(r.links.is_empty());
        let xacro: Vec<&Diagnostic> = r
            .notes
            .iter()
            .filter(|n| n.message.contains("run `xacro"))
            .collect();
        assert_eq!(xacro.len(), 1);
        assert_eq!((xacro[0].line(), xacro[0].code), (Some(2), Code::UrdfXacro));
        let r = scan(
            "<robot name=\"r\"><xacro:include filename=\"x.xacro\"/></robot>".into(),
            Path::new("x.urdf"),
        )
        .expect("scan");
        assert_eq!(r.notes.len(), 1);
    }

    #[test]
    fn latin1_bytes_scan_with_their_declaration() {
        let bytes = b"<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n<robot name=\"r\xe9\"><link name=\"\xe9\"/></robot>".to_vec();
        let r = scan_bytes(bytes, Path::new("x.urdf")).expect("latin-1");
        assert_eq!(r.links[0].name, "\u{e9}");
        let e = scan_bytes(
            b"<robot name=\"r\">\n<link name=\"\xe9\"/></robot>".to_vec(),
            Path::new("x.urdf"),
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (2, 13), "{e}");
        assert!(!e.to_string().contains("byte 0)"), "{e}");
    }
}
