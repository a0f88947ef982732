//! Robots built by the caller instead of scanned: a model read by urdf-rs, an SDF or MJCF importer or
//! made in code becomes links with collision parts the library computes and compares. A built robot
//! has no text, so nothing can be spliced into it; its lines are 0.

use super::scan::{Collision, Geometry, Inertial, InertialSpan, Link, Pose, Robot};
use std::path::PathBuf;

impl Robot {
    /// A robot of `links` without a source file: relative mesh paths are resolved against the
    /// working directory (see [`Robot::with_path`]).
    pub fn new(name: impl Into<String>, links: Vec<Link>) -> Robot {
        Robot {
            path: PathBuf::new(),
            name: name.into(),
            text: String::new(),
            links,
            newline: "\n",
            encoding: super::encoding::SourceEncoding::default(),
            notes: Vec::new(),
        }
    }

    /// The same, as if read from `path`: relative mesh paths resolve against its directory, and
    /// problems name it.
    #[must_use]
    pub fn with_path(mut self, path: impl Into<PathBuf>) -> Robot {
        self.path = path.into();
        self
    }
}

impl Link {
    /// A link with collision parts (numbered 1, 2, … in the order given) and no `<inertial>`.
    pub fn new(name: impl Into<String>, collisions: Vec<Collision>) -> Link {
        let collisions = collisions
            .into_iter()
            .enumerate()
            .map(|(i, c)| Collision { index: i + 1, ..c })
            .collect();
        Link {
            name: name.into(),
            line: 0,
            start: 0,
            open_end: 0,
            self_closing: false,
            indent: String::new(),
            child_indent: None,
            inertial: None,
            extra_inertials: Vec::new(),
            collisions,
            visuals: Vec::new(),
            from_visual: false,
        }
    }

    /// The same, with the `<inertial>` it has now (what [`check`](crate::check) and
    /// [`check_computed`](crate::check_computed) compare).
    #[must_use]
    pub fn with_inertial(mut self, inertial: Inertial) -> Link {
        self.inertial = Some(InertialSpan {
            start: 0,
            end: 0,
            line: 0,
            value: inertial,
            problem: None,
            mass_line: None,
        });
        self
    }
}

impl Collision {
    /// A collision part: its shape, placed at `origin` in the link frame.
    pub fn new(geometry: Geometry, origin: Pose) -> Collision {
        Collision {
            index: 1,
            name: None,
            line: 0,
            origin,
            geometry,
        }
    }
}

impl Inertial {
    /// An inertial: mass (kg) and the tensor `[ixx, ixy, ixz, iyy, iyz, izz]` (kg·m²) about the
    /// centre of mass, in the frame of `origin` (whose translation is the centre of mass).
    pub fn new(origin: Pose, mass: f64, inertia: [f64; 6]) -> Inertial {
        Inertial {
            origin,
            mass: Some(mass),
            inertia: Some(inertia),
        }
    }
}

impl Pose {
    /// A translation (m) and URDF roll-pitch-yaw (rad, fixed axes X, then Y, then Z).
    pub fn new(xyz: [f64; 3], rpy: [f64; 3]) -> Pose {
        Pose { xyz, rpy }
    }
}
