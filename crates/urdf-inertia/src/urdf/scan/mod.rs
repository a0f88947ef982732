//! A one-pass scan of a URDF: links, their collisions, their existing `<inertial>` and the byte spans
//! the writer needs.
//!
//! It reads what urdfdom (behind ROS, Gazebo, `MoveIt`, pinocchio) reads: the first `<inertial>` of a link,
//! the first `<origin>` and `<geometry>` of a collision and the first child element of `<geometry>`;
//! later ones are ignored with a warning. Zero-size primitives are valid (they have no volume). Anything
//! wrong inside one collision (an unknown shape, a bad number) is that collision's
//! [`Geometry::Invalid`], the link's failure, not the file's; malformed XML and duplicate link names
//! are the file's.

use std::fmt;
use std::path::{Path, PathBuf};

mod model;
mod scanner;
mod values;

pub use model::{Collision, Geometry, Inertial, InertialSpan, Link, Pose, Robot};
use scanner::Scanner;

pub use super::encoding::SourceEncoding;

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

/// Decodes a URDF file's bytes (UTF-8 with or without a byte-order mark, UTF-16 with one or sniffed
/// from `<?xml`, or an ASCII-compatible encoding the XML declaration names) and scans the text.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostic::{Code, Diagnostic};

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
