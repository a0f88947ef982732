//! What a scan returns: the robot, its links, their collisions and existing inertials, with the
//! lines and byte spans the writer and the messages need.

use super::SourceEncoding;
use crate::diagnostic::Diagnostic;
use crate::mass::primitives;
use std::path::PathBuf;

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
