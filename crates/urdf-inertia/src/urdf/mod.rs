//! URDF: scanning the few elements the tool needs (with their byte spans), resolving mesh paths, and
//! writing `<inertial>` back by splicing text into the original bytes.
//!
//! The scan reads with quick-xml instead of urdf-rs: urdf-rs 0.10 refuses URDFs that urdfdom reads
//! (icub.urdf, romeo_laas_small.urdf: a `<texture>` without `filename`) and its writer loses comments,
//! attribute order and unknown tags. Unknown elements (`<gazebo>`, `<transmission>`, namespaced tags) are
//! skipped and kept byte for byte. What is read follows urdfdom (see [`scan`]); the text may be UTF-8,
//! UTF-16 or a declared single-byte encoding (see [`encoding`]).

mod build;
pub mod encoding;
pub mod resolve;
pub mod scan;
pub mod write;

pub use scan::{scan, scan_bytes, Collision, Geometry, Inertial, Link, Pose, Robot, UrdfError};
