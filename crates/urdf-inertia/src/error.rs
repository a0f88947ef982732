//! The library's one error type: each stage keeps its own error (with its file, line and what to do),
//! and [`Error`] holds whichever stage failed, as its [`source`](std::error::Error::source).

use crate::density::MapError;
use crate::diagnostic::{LinkError, RobotError};
use crate::input::InputError;
use crate::mesh::MeshError;
use crate::urdf::write::WriteError;
use crate::urdf::UrdfError;
use crate::xacro::XacroError;
use std::fmt;
use std::path::PathBuf;

/// Why the library could not do what it was asked.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read: not a regular file, over the size limit, an I/O error.
    Input { path: PathBuf, source: InputError },
    /// A URDF that is not well-formed, or has duplicate links.
    Urdf(UrdfError),
    /// A xacro source that cannot be expanded.
    Xacro(XacroError),
    /// A mesh file that cannot become a solid.
    Mesh(MeshError),
    /// A density map that cannot be read or is not valid.
    DensityMap(MapError),
    /// A link or mesh name pattern that is not a glob (the message names it).
    Pattern { pattern: String, message: String },
    /// One link that could not be computed.
    Link(LinkError),
    /// A robot-wide failure (links without a density, a mass target below the fixed parts).
    Robot(RobotError),
    /// A link whose `<inertial>` cannot be written as asked.
    Write(WriteError),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input { path, source } => write!(f, "{}: {source}", path.display()),
            Error::Urdf(e) => e.fmt(f),
            Error::Xacro(e) => e.fmt(f),
            Error::Mesh(e) => e.fmt(f),
            Error::DensityMap(e) => e.fmt(f),
            Error::Pattern { message, .. } => f.write_str(message),
            Error::Link(e) => e.fmt(f),
            Error::Robot(e) => e.fmt(f),
            Error::Write(e) => write!(f, "link {}: {}", e.index, e.message),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Input { source, .. } => Some(source),
            Error::Urdf(e) => Some(e),
            Error::Xacro(e) => Some(e),
            Error::Mesh(e) => Some(e),
            Error::DensityMap(e) => Some(e),
            Error::Link(e) => Some(e),
            Error::Robot(e) => Some(e),
            Error::Pattern { .. } | Error::Write(_) => None,
        }
    }
}

macro_rules! from_stage {
    ($($variant:ident($t:ty)),* $(,)?) => {$(
        impl From<$t> for Error {
            fn from(e: $t) -> Self {
                Error::$variant(e)
            }
        }
    )*};
}

from_stage!(
    Urdf(UrdfError),
    Xacro(XacroError),
    Mesh(MeshError),
    DensityMap(MapError),
    Link(LinkError),
    Robot(RobotError),
    Write(WriteError),
);

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    #[test]
    fn a_stage_error_is_the_source_and_the_message() {
        let path = PathBuf::from("meshes/a.stl");
        let e = Error::Input {
            path: path.clone(),
            source: InputError::TooLarge { limit: 10 },
        };
        assert!(e.to_string().starts_with("meshes/a.stl: is larger than the limit of 10 bytes"));
        assert_eq!(
            e.source().map(ToString::to_string),
            Some(InputError::TooLarge { limit: 10 }.to_string())
        );
        let mesh = MeshError::new(&path, None, crate::mesh::MeshErrorKind::Empty);
        let e: Error = mesh.clone().into();
        assert_eq!(e.to_string(), mesh.to_string());
        assert!(e.source().is_some());
    }
}
