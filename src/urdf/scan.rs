//! A one-pass scan of a URDF: links, their collisions, their existing `<inertial>` and the byte spans
//! the writer needs.

use crate::text::LineCounter;
use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;
use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

/// A pose: translation and URDF roll-pitch-yaw (fixed axes X, Y, Z).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    pub xyz: [f64; 3],
    pub rpy: [f64; 3],
}

/// A collision geometry as the URDF gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum Geometry {
    Mesh { filename: String, scale: [f64; 3] },
    Box { size: [f64; 3] },
    Cylinder { radius: f64, length: f64 },
    Sphere { radius: f64 },
    Capsule { radius: f64, length: f64 },
}

/// One `<collision>` of a link.
#[derive(Debug, Clone, PartialEq)]
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
pub struct Inertial {
    pub origin: Pose,
    pub mass: Option<f64>,
    /// ixx, ixy, ixz, iyy, iyz, izz.
    pub inertia: Option<[f64; 6]>,
}

/// The existing `<inertial>` of a link: where it is and what it says.
#[derive(Debug, Clone, PartialEq)]
pub struct InertialSpan {
    pub start: usize,
    pub end: usize,
    pub line: usize,
    pub value: Inertial,
    /// A problem reading its numbers, if any (the link is then treated as having an invalid inertial).
    pub problem: Option<String>,
}

/// A `<link>` with everything the tool needs.
#[derive(Debug, Clone, PartialEq)]
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
    pub inertial: Option<InertialSpan>,
    pub collisions: Vec<Collision>,
}

/// A scanned URDF.
#[derive(Debug, Clone)]
pub struct Robot {
    pub path: PathBuf,
    pub name: String,
    pub text: String,
    pub links: Vec<Link>,
    /// "\r\n" when the file uses CRLF line endings.
    pub newline: &'static str,
}

/// Why a URDF cannot be read.
#[derive(Debug, Clone, PartialEq)]
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
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let col = 1 + pos
        - before
            .iter()
            .rposition(|&b| b == b'\n')
            .map(|i| i + 1)
            .unwrap_or(0);
    (line, col)
}

fn attrs(e: &BytesStart<'_>) -> HashMap<String, String> {
    let mut m = HashMap::new();
    for a in e.attributes().with_checks(false).flatten() {
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let v = a
            .unescape_value()
            .map(|v| v.into_owned())
            .unwrap_or_else(|_| String::from_utf8_lossy(&a.value).into_owned());
        m.insert(key, v);
    }
    m
}

fn indent_before(text: &str, pos: usize) -> Option<String> {
    let line_start = text[..pos].rfind('\n').map(|i| i + 1).unwrap_or(0);
    let ws = &text[line_start..pos];
    if ws.chars().all(|c| c == ' ' || c == '\t') {
        Some(ws.to_string())
    } else {
        None
    }
}

/// Scans URDF text. `path` is used in messages and for resolving relative mesh paths.
pub fn scan(text: String, path: &Path) -> Result<Robot, UrdfError> {
    let err = |pos: usize, message: String| {
        let (line, column) = line_col(&text, pos);
        let message = if message.contains("${") || message.contains("$(") {
            format!("{message} (an unexpanded xacro expression: run `xacro FILE.urdf.xacro > FILE.urdf` first)")
        } else {
            message
        };
        UrdfError {
            path: path.to_path_buf(),
            line,
            column,
            message,
        }
    };
    // quick-xml does not count a UTF-8 byte-order mark in its positions: read after it and add it back.
    let bom = if text.starts_with('\u{feff}') {
        '\u{feff}'.len_utf8()
    } else {
        0
    };
    let mut reader = Reader::from_str(&text[bom..]);
    reader.config_mut().check_end_names = true;
    let mut lines = LineCounter::new(text.as_bytes());
    let mut stack: Vec<String> = Vec::new();
    let mut robot_name: Option<String> = None;
    let mut links: Vec<Link> = Vec::new();
    let mut current: Option<Link> = None;
    let mut collision: CollisionInProgress = None;
    let mut inertial: Option<InertialSpan> = None;
    let mut seen: HashMap<String, usize> = HashMap::new();

    loop {
        let pos = bom + reader.buffer_position() as usize;
        let event = match reader.read_event() {
            Ok(e) => e,
            Err(e) => {
                return Err(err(
                    bom + reader.error_position() as usize,
                    format!("malformed XML: {e}"),
                ))
            }
        };
        let (e, empty) = match event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                let name = stack.pop().unwrap_or_default();
                let end = bom + reader.buffer_position() as usize;
                match (stack.len(), name.as_str()) {
                    (1, "link") => {
                        if let Some(mut link) = current.take() {
                            link.inertial = link.inertial.take();
                            links.push(link);
                        }
                    }
                    (2, "collision") => finish_collision(&mut collision, &mut current),
                    (2, "inertial") => {
                        if let (Some(mut span), Some(link)) = (inertial.take(), current.as_mut()) {
                            span.end = end;
                            link.inertial = Some(span);
                        }
                    }
                    _ => {}
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
        let depth = stack.len();
        let a = attrs(&e);
        match (depth, name.as_str()) {
            (0, "robot") => robot_name = Some(a.get("name").cloned().unwrap_or_default()),
            (0, other) => return Err(err(pos, format!("the root element is <{other}>, not <robot>: this is not a URDF (run xacro first if it is a .xacro file)"))),
            (1, "link") => {
                let lname = a.get("name").cloned().ok_or_else(|| err(pos, "<link> without a name".into()))?;
                let line = lines.at(pos);
                if let Some(first) = seen.insert(lname.clone(), line) {
                    return Err(err(pos, format!("duplicate link name `{lname}` (first defined on line {first}); link names must be unique")));
                }
                let link = Link {
                    name: lname,
                    line,
                    start: pos,
                    open_end: bom + reader.buffer_position() as usize,
                    self_closing: empty,
                    indent: indent_before(&text, pos).unwrap_or_default(),
                    child_indent: None,
                    inertial: None,
                    collisions: Vec::new(),
                };
                if empty {
                    links.push(link);
                } else {
                    current = Some(link);
                }
            }
            (2, child) if current.is_some() => {
                if let Some(link) = current.as_mut() {
                    if link.child_indent.is_none() {
                        link.child_indent = indent_before(&text, pos);
                    }
                }
                match child {
                    "collision" => {
                        let index = current.as_ref().map(|l| l.collisions.len() + 1).unwrap_or(1);
                        collision = Some((index, lines.at(pos), a.get("name").cloned(), Pose::default(), None));
                        if empty {
                            finish_collision(&mut collision, &mut current);
                        }
                    }
                    "inertial" => {
                        let line = lines.at(pos);
                        let span = InertialSpan { start: pos, end: bom + reader.buffer_position() as usize, line, value: Inertial::default(), problem: None };
                        if empty {
                            if let Some(link) = current.as_mut() {
                                link.inertial = Some(span);
                            }
                        } else {
                            inertial = Some(span);
                        }
                    }
                    _ => {}
                }
            }
            (3, "origin") if stack[2] == "collision" => {
                if let Some(c) = collision.as_mut() {
                    c.3 = pose(&a).map_err(|m| err(pos, format!("link `{}`: collision origin: {m}", link_name(&current))))?;
                }
            }
            (4, g) if stack[2] == "collision" && stack[3] == "geometry" => {
                if let Some(c) = collision.as_mut() {
                    let lname = link_name(&current);
                    c.4 = Some(geometry(g, &a).map_err(|m| err(pos, format!("link `{lname}`, collision {}: {m}", c.0)))?);
                }
            }
            (3, child) if stack[2] == "inertial" => {
                if let Some(span) = inertial.as_mut() {
                    let r = match child {
                        "origin" => pose(&a).map(|p| span.value.origin = p),
                        "mass" => num(&a, "value").map(|m| span.value.mass = Some(m)),
                        "inertia" => (|| {
                            Ok([num(&a, "ixx")?, num(&a, "ixy")?, num(&a, "ixz")?, num(&a, "iyy")?, num(&a, "iyz")?, num(&a, "izz")?])
                        })()
                        .map(|i| span.value.inertia = Some(i)),
                        _ => Ok(()),
                    };
                    if let Err(m) = r {
                        span.problem.get_or_insert(format!("line {}: <{child}>: {m}", lines.at(pos)));
                    }
                }
            }
            _ => {}
        }
        if !empty {
            stack.push(name);
        }
    }
    let name = robot_name.ok_or_else(|| err(0, "no <robot> element: this is not a URDF".into()))?;
    if !stack.is_empty() {
        return Err(err(
            text.len(),
            format!(
                "the file ends inside <{}>",
                stack.last().cloned().unwrap_or_default()
            ),
        ));
    }
    let newline = if text.contains("\r\n") { "\r\n" } else { "\n" };
    Ok(Robot {
        path: path.to_path_buf(),
        name,
        text,
        links,
        newline,
    })
}

fn link_name(link: &Option<Link>) -> String {
    link.as_ref().map(|l| l.name.clone()).unwrap_or_default()
}

type CollisionInProgress = Option<(usize, usize, Option<String>, Pose, Option<Geometry>)>;

/// Ends the `<collision>` being read. One without geometry (urdfdom rejects it; some generators emit
/// it) contributes nothing.
fn finish_collision(collision: &mut CollisionInProgress, current: &mut Option<Link>) {
    if let (Some((index, line, name, origin, Some(geometry))), Some(link)) =
        (collision.take(), current.as_mut())
    {
        link.collisions.push(Collision {
            index,
            name,
            line,
            origin,
            geometry,
        });
    }
}

fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<&str> = s.split_ascii_whitespace().collect();
    if v.len() != 3 {
        return Err(format!("\"{s}\" should be three numbers"));
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
    s.trim()
        .parse::<f64>()
        .map_err(|_| format!("{key}=\"{s}\" is not a number"))
}

fn positive(a: &HashMap<String, String>, key: &str) -> Result<f64, String> {
    let v = num(a, key)?;
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{key}=\"{v}\" must be a positive number"))
    }
}

fn geometry(kind: &str, a: &HashMap<String, String>) -> Result<Geometry, String> {
    Ok(match kind {
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
                        [x; 3]
                    } else {
                        parse_vec3(s).map_err(|m| format!("scale {m}"))?
                    }
                }
            };
            if scale.contains(&0.0) {
                return Err(format!(
                    "mesh scale \"{} {} {}\" has a zero factor",
                    scale[0], scale[1], scale[2]
                ));
            }
            Geometry::Mesh { filename, scale }
        }
        "box" => {
            let size = parse_vec3(a.get("size").ok_or("<box> without size")?)
                .map_err(|m| format!("box size {m}"))?;
            if size.iter().any(|x| *x <= 0.0) {
                return Err(format!(
                    "box size \"{} {} {}\" must be positive",
                    size[0], size[1], size[2]
                ));
            }
            Geometry::Box { size }
        }
        "cylinder" => Geometry::Cylinder {
            radius: positive(a, "radius")?,
            length: positive(a, "length")?,
        },
        "capsule" => Geometry::Capsule {
            radius: positive(a, "radius")?,
            length: positive(a, "length")?,
        },
        "sphere" => Geometry::Sphere {
            radius: positive(a, "radius")?,
        },
        other => return Err(format!("unknown geometry <{other}>")),
    })
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
        let e = scan("<robot name=\"r\"><link name=\"a\"><collision><origin xyz=\"${x} 0 0\"/><geometry><box size=\"1 1 1\"/></geometry></collision></link></robot>".into(), Path::new("x.urdf")).unwrap_err();
        assert!(e.message.contains("unexpanded xacro"), "{e}");
        let e = scan("<sdf/>".into(), Path::new("x.urdf")).unwrap_err();
        assert!(e.message.contains("not a URDF"), "{e}");
        let e = scan("<robot name=\"r\"><link name=\"a\"><collision><geometry><mesh filename=\"m.stl\" scale=\"1 x 1\"/></geometry></collision></link></robot>".into(), Path::new("x.urdf")).unwrap_err();
        assert!(e.message.contains("link `a`, collision 1: scale"), "{e}");
    }
}
