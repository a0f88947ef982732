//! urdf-inertia: correct `<inertial>` elements for URDF robot descriptions, computed from the collision
//! geometry with Mirtich's polyhedral mass properties (1996).
//!
//! Data flows one way: a robot ([`Robot`], from [`scan()`] of a URDF's text, or built by the caller from
//! its own model with [`Link::new`] and [`Collision::new`]) → its collision parts resolved and loaded
//! ([`PackageResolver`], [`load_solid`]) → the mass core ([`MassProperties`], [`primitives`]) → each
//! link's parts composed with their densities ([`DensityMap`], [`compute`]) → compared with what the
//! file says ([`compare`], [`check`], [`check_computed`]: typed [`InertialProblem`]s) → spliced into
//! the original bytes ([`write::splice`]). xacro sources are expanded first ([`xacro`]), with a map
//! back to their files and lines. Failures are one [`Error`]; warnings and notes are
//! [`diagnostic::Diagnostic`]s with stable codes.
//!
//! A link built by hand, computed and compared with an inertial it had:
//!
//! ```
//! use urdf_inertia::{
//!     check_computed, compute, Collision, DensityMap, FillOptions, Geometry, Inertial, Link,
//!     PackageResolver, Pose, ProblemKind, Robot,
//! };
//!
//! // A 0.1 × 0.2 × 0.3 m box of aluminium (2700 kg/m³): 16.2 kg.
//! let part = Collision::new(Geometry::Box { size: [0.1, 0.2, 0.3] }, Pose::default());
//! // What the link said: ten times too light (a unit slip), same tensor shape.
//! let said = Inertial::new(Pose::default(), 1.62, [0.01755, 0.0, 0.0, 0.0135, 0.0, 0.00675]);
//! let robot = Robot::new("arm", vec![Link::new("forearm", vec![part]).with_inertial(said)]);
//!
//! let densities = DensityMap::uniform(2700.0);
//! let report = compute(&robot, &densities, &PackageResolver::new(), &FillOptions::default());
//! let link = &report.links[0];
//! assert!((link.computed.mass - 16.2).abs() < 1e-12);
//!
//! let problems = check_computed(&robot, &report, 0.05);
//! assert_eq!(problems.len(), 1);
//! assert!(matches!(problems[0].kind, ProblemKind::Differs { .. }));
//! assert_eq!(problems[0].code().as_str(), "UI603");
//! ```
#![forbid(unsafe_code)]

/// The implementation modules, private: what a user reaches is re-exported below. The `internals`
/// feature makes them public for this repository's own tests, benchmarks and fuzz targets, which
/// test the stages one by one; it carries no stability promise and no user should enable it.
macro_rules! internal {
    ($($m:ident),* $(,)?) => {$(
        #[cfg(feature = "internals")]
        #[doc(hidden)]
        pub mod $m;
        #[cfg(not(feature = "internals"))]
        mod $m;
    )*};
}

internal!(compare, density, error, fill, mass, mesh, overlap, problem, threads, urdf);

pub mod diagnostic;
mod geometry;
pub mod input;
pub mod report;
pub mod text;
pub mod xacro;

pub use compare::{compare, Comparison, Difference};
pub use density::{near_miss, DensityMap, Glob, MapError};
pub use error::Error;
pub use fill::{
    compute, compute_with, existing_props, millimetre_slip, selected, unrepresentable,
    unresolved_meshes, unused_selection, FillOptions, FillReport, LinkOverlap, LinkReport,
    MeshCache, PartReport, Timing,
};
pub use mass::validity::Violation;
pub use mass::{primitives, rpy_matrix, MassProperties, Mat3, Principal};
pub use mesh::health::{ErrorEstimate, Rung, Solid};
pub use mesh::open::OpenMeshModel;
pub use mesh::{load_solid, LoadOptions, MeshError, MeshErrorKind};
pub use problem::{check, check_computed, InertialProblem, ProblemKind};
pub use threads::note as thread_note;
pub use urdf::resolve::{NotFound, PackageResolver};
pub use urdf::{scan, scan_bytes, Collision, Geometry, Inertial, Link, Pose, Robot, UrdfError};

/// Writing computed values back: spliced into the original bytes, every other byte unchanged.
pub mod write {
    pub use crate::urdf::write::{
        splice, tidy, tidy_moments, LinkUpdate, WriteError, WriteOptions,
    };
}

/// A small deterministic generator for the unit tests (xorshift64; the same sequence on every run).
#[cfg(test)]
pub(crate) fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// A uniform f64 in [0, 1) for the unit tests, from a 64-bit LCG (Knuth's MMIX constants).
#[cfg(test)]
pub(crate) fn lcg_unit(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}
