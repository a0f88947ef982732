//! Mesh health: from a (scaled) mesh as read to a closed, outward solid, or a precise reason why not.
//!
//! Welding decides the topology ([`super::weld`]): bit-identical corners first (all a clean mesh pays
//! for), then, only when that leaves the surface open or inconsistently wound, corners that coincide up
//! to a tolerance relative to the mesh's size. Welding never moves a vertex; the triangles are
//! integrated as stored. Then the edge structure decides the rung:
//!
//! 1. [`Rung::Exact`]: closed, manifold, consistently wound outward under bit-exact welding.
//! 2. [`Rung::Welded`]: the same after the tolerant weld: a closed surface whose shared corners were
//!    stored in slightly different ways (float-noise cracks). Integrated as stored, no repair.
//! 3. [`Rung::Reoriented`]: closed, but some faces wound against their neighbours: each connected
//!    component is made consistent, then turned outward by its signed volume.
//! 4. [`Rung::Inverted`]: closed and consistent but wound inward (negative volume): flipped.
//! 5. Open (boundary edges) or non-manifold, after orienting what the manifold edges allow:
//!    * [`Rung::Capped`]: each boundary loop is closed by a fan from its centroid, used when the
//!      bound the caps leave on volume and inertia (below) is under 1e-3
//!      ([`super::open::TRUSTED_CAPS`]). When the caps' bound is below 1e-12 (the "holes" are
//!      slivers), the triangles are integrated as stored and the rung is [`Rung::Welded`].
//!    * [`Rung::NonManifold`]: no boundary edges but edges shared by three or more faces: the surface
//!      still bounds a region, integrated as it is (a region enclosed twice counts twice).
//!    * Otherwise the mesh defines no solid to trust: the model the user chose for open meshes
//!      ([`OpenMeshModel`]: the caps whatever their bound, or [`Rung::ConvexHull`], the hull of the
//!      vertices the faces use, an upper bound), or by default an error
//!      ([`MeshErrorKind::NoSolid`]). The hull is never a silent last resort.
//! 6. No volume against the round-off of its faces: an error.
//!
//! Every solid carries an [`ErrorEstimate`]: a bound on the relative error of its volume and central
//! inertia, made of the integration's round-off and, below the exact rungs, the model error (how far
//! the solid integrated can be from the surface stored). See [`ModelError`] for each term.

mod caps;
mod closed;
mod geometry;
mod ladder;
mod model;
mod open_surface;
mod topology;
mod welding;

use super::open::OpenMeshModel;
use super::{weld, winding_shells, MeshError, MeshErrorKind, RawMesh};
use crate::mass::{MassProperties, Polygons};
use closed::{consistent_closed, prove, reoriented, welded_closed};
pub use geometry::Aabb;
use ladder::Ladder;
use open_surface::open_or_nonmanifold;
use std::borrow::Cow;
use std::path::Path;
// The proof on its own, for the tests, benchmarks and examples (`internals`); the healing proves
// through `closed::prove`.
#[cfg(any(test, feature = "internals"))]
pub use topology::closed_consistent;
use topology::{edge_analysis, edges, orient};
use welding::tolerant_welding;

/// Which rung of the repair ladder produced a solid's numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum Rung {
    Exact,
    /// Closed and consistent once corners within `tolerance` (m) are welded; integrated as stored.
    Welded {
        merged_vertices: usize,
        /// Largest distance between corners welded together, m.
        widest_crack: f64,
        tolerance: f64,
    },
    Reoriented {
        faces_flipped: usize,
        components: usize,
    },
    Inverted,
    Capped {
        holes: usize,
        boundary_edges: usize,
        nonmanifold_edges: usize,
        faces_flipped: usize,
        relative_uncertainty: f64,
    },
    NonManifold {
        nonmanifold_edges: usize,
        faces_flipped: usize,
    },
    ConvexHull {
        boundary_edges: usize,
        nonmanifold_edges: usize,
        mesh_volume: f64,
        hull_volume: f64,
        volume_moves_by: f64,
    },
}

impl Rung {
    /// Every rung's [`name`](Rung::name), up the ladder.
    pub const NAMES: [&'static str; 7] = [
        "exact",
        "welded",
        "reoriented",
        "inverted",
        "capped",
        "non-manifold",
        "convex-hull",
    ];

    /// A short name for tables and JSON.
    pub fn name(&self) -> &'static str {
        match self {
            Rung::Exact => "exact",
            Rung::Welded { .. } => "welded",
            Rung::Reoriented { .. } => "reoriented",
            Rung::Inverted => "inverted",
            Rung::Capped { .. } => "capped",
            Rung::NonManifold { .. } => "non-manifold",
            Rung::ConvexHull { .. } => "convex-hull",
        }
    }

    /// Whether the numbers are the stored surface's own, without repair (exact or welded).
    pub fn is_as_stored(&self) -> bool {
        matches!(self, Rung::Exact | Rung::Welded { .. })
    }
}

/// Where the model error of a solid comes from: how far the solid integrated can be from the surface
/// stored in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelError {
    /// The solid is the stored surface: no model error.
    None,
    /// A surface closed only up to cracks: the volume that moves with the reference point
    /// (|vector area| × diagonal / 6).
    Cracks,
    /// Re-oriented components, any of which could be a cavity (their volumes).
    Orientation,
    /// Flat caps over holes (each loop's deviation from its plane times the cap's area).
    Caps,
    /// The convex hull instead of the mesh (|mesh − hull| / hull, with the mesh's own volume taken at
    /// its least favourable reference point).
    Hull,
    /// Shells that touch or cut each other: the intersection of their bounding boxes, which a region
    /// they both enclose lies in.
    Overlap,
}

impl ModelError {
    /// A short name for JSON and the summary.
    pub fn name(self) -> &'static str {
        match self {
            ModelError::None => "none",
            ModelError::Cracks => "cracks",
            ModelError::Orientation => "orientation",
            ModelError::Caps => "caps",
            ModelError::Hull => "convex hull",
            ModelError::Overlap => "overlapping shells",
        }
    }
}

/// A bound on the relative error of a solid's volume and central inertia (Frobenius norm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    /// Round-off of the integration: the kernel's rounding bounded face by face in the pass that
    /// integrated (`mass::integrals::Rounding`), never less than 4ε; where the winding number
    /// decided the faces, at least the disagreement of two integrations about different reference
    /// points.
    pub round_off: f64,
    /// How far the solid can be from the stored surface (0 for exact and clean welded meshes).
    pub model: f64,
    /// What the model error is made of (the largest term).
    pub source: ModelError,
    /// Bound on the error of the centre of mass, m: the relative bound times the solid's reach (its
    /// farthest vertex from the centre of mass), plus the round-off of the centre's own coordinates.
    pub com: f64,
}

impl ErrorEstimate {
    /// The bound: round-off plus model error.
    pub fn total(&self) -> f64 {
        self.round_off + self.model
    }

    /// One line for people: `3.1e-16 (round-off)` or `2.0e-4 (mesh repair: holes capped; round-off
    /// 3.1e-16)`.
    pub fn describe(&self) -> String {
        // Plain words for people; `name()` stays the short key for JSON.
        let cause = match self.source {
            ModelError::None => "none",
            ModelError::Cracks => "cracks between faces",
            ModelError::Orientation => "faces re-oriented",
            ModelError::Caps => "holes capped",
            ModelError::Hull => "replaced by its convex hull",
            ModelError::Overlap => "shells overlapping",
        };
        if !self.total().is_finite() {
            return format!("unbounded (mesh repair: {cause})");
        }
        if self.source == ModelError::None || self.model == 0.0 {
            format!("{:.1e} (round-off)", self.total())
        } else {
            format!(
                "{:.1e} (mesh repair: {cause}; round-off {:.1e})",
                self.total(),
                self.round_off
            )
        }
    }
}

/// What a health message is about (the diagnostic layer gives each kind its code).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HealthKind {
    /// The solid is not the stored surface as it is: re-oriented, inverted, capped, non-manifold, hull.
    Repaired,
    /// Degenerate faces or faces stored twice left out.
    FacesDropped,
    /// A face and its reverse left out in pairs (they cancel).
    FacesCancelled,
    /// Closed once float-noise cracks are welded; integrated as stored.
    Welded,
    /// The reader left something out of the solid (faces it could not use).
    ReaderSkipped,
    /// The reader tolerated something harmless.
    ReaderNote,
}

/// One message of the ladder: its kind and its text (which it reads as, for printing and matching).
#[derive(Debug, Clone, PartialEq)]
pub struct HealthMessage {
    pub kind: HealthKind,
    pub text: String,
}

impl HealthMessage {
    fn new(kind: HealthKind, text: String) -> Self {
        HealthMessage { kind, text }
    }
}

impl std::ops::Deref for HealthMessage {
    type Target = str;
    fn deref(&self) -> &str {
        &self.text
    }
}

impl std::fmt::Display for HealthMessage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.text)
    }
}

impl serde::Serialize for HealthMessage {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.text)
    }
}

/// A closed, outward solid ready to integrate, with its unit-density mass properties.
#[derive(Debug, Clone)]
pub struct Solid {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Polygons,
    pub rung: Rung,
    /// Messages for the user: what was done to the mesh and why.
    pub warnings: Vec<HealthMessage>,
    /// What the user may want to know but need not act on (a weld within tolerance, reader notes).
    pub notes: Vec<HealthMessage>,
    /// Mass properties at density 1 (mass = volume), in the mesh frame.
    pub unit: MassProperties,
    /// Bound on the relative error of volume and central inertia: `error.total()`.
    pub error_estimate: f64,
    /// The bound's parts.
    pub error: ErrorEstimate,
    /// Faces in the file (before welding and dropping degenerate ones).
    pub faces_read: usize,
    /// The box of `vertices`: its lowest and its highest corner, found with the integrals (one
    /// pass over the vertices fewer for each of [`Solid::largest_coordinate`] and
    /// [`Solid::millimetre_slip`]: at 1.3 M faces each pass is a few milliseconds of reading).
    pub bounds: [[f64; 3]; 2],
}

/// Options of the ladder.
#[derive(Debug, Clone, Copy, Default)]
pub struct HealthOptions {
    /// Every rung below [`Rung::Welded`] is an error.
    pub strict: bool,
    /// What an open mesh whose caps cannot be trusted becomes (`--open-mesh`).
    pub open_mesh: OpenMeshModel,
}

/// A solid's volume below this many f64 round-offs of its faces' contributions counts as empty.
const ZERO_VOLUME_ROUNDOFFS: f64 = 1e3;

/// Largest relative bound of the caps for which a capped mesh is used without asking.
const CAPPED: f64 = super::open::TRUSTED_CAPS;

/// Caps whose uncertainty is below this (relative) close slivers, not holes: integrate as stored.
const SLIVERS: f64 = 1e-12;

pub use crate::geometry::ROUND_OFF_FLOOR;


/// Turns a scaled mesh into a solid by the ladder in the module docs, its coordinates taken as f64
/// values (see [`heal`] for meshes stored in f32 or as decimals).
#[cfg(any(test, feature = "internals"))]
pub fn make_solid(mesh: &RawMesh, path: &Path, options: HealthOptions) -> Result<Solid, MeshError> {
    heal(Cow::Borrowed(mesh), path, options, |_| weld::Precision::F64)
}

/// What welding dropped or collapsed, and what dropping copies apart, cancelling pairs and collapsed
/// faces can change.
fn welding_notes(ladder: &mut Ladder<'_>, w: &welding::Welding) {
    // "; {what} {volume} m³, which is in the error estimate", or nothing where the bound is 0.
    let bound = |what: &str, volume: f64| {
        if volume > 0.0 {
            format!("; {what} {volume:.2e} m³, which is in the error estimate")
        } else {
            String::new()
        }
    };
    if w.duplicates > 0 {
        let apart = bound(
            "stored apart from the faces kept before welding, the copies may change at most",
            w.copies_volume,
        );
        ladder.warn(
            HealthKind::FacesDropped,
            format!(
                "{} faces stored more than once dropped (the copies would count their volume twice){apart}",
                w.duplicates
            ),
        );
        ladder.cancelled += w.copies_volume;
    }
    if w.cancelled > 0 {
        let apart = bound("stored apart before welding, they may enclose at most", w.cancelled_volume);
        ladder.note(HealthKind::FacesCancelled, format!(
            "{} faces dropped in pairs, each a face and its reverse (a wall of no thickness; they cancel){apart}",
            w.cancelled
        ));
        ladder.cancelled += w.cancelled_volume;
    }
    if w.collapsed > 0 {
        let apart = bound("they may change at most", w.collapsed_volume);
        ladder.note(HealthKind::Welded, format!(
            "{} sliver faces collapse when corners within {:.1e} m are welded; left out of the topology{apart}",
            w.collapsed, w.tolerant.tolerance.largest
        ));
        ladder.cancelled += w.collapsed_volume;
    }
}

/// Turns a scaled mesh into a solid by the ladder in the module docs. `precision` tells how its file
/// stored the coordinates, which sets the tolerance of the second welding pass: it gets the (scaled,
/// welded) vertices and is asked only when that pass runs. A mesh its reader welded
/// ([`RawMesh::welded`]) and that is owned becomes the solid without a copy and without a second weld.
pub fn heal(
    mesh: Cow<'_, RawMesh>,
    path: &Path,
    options: HealthOptions,
    precision: impl FnOnce(&[[f64; 3]]) -> weld::Precision,
) -> Result<Solid, MeshError> {
    let mut ladder = Ladder::new(&mesh, path, options);
    let exact = if mesh.welded {
        let mesh = mesh.into_owned();
        weld::already_welded(mesh.vertices, mesh.faces)
    } else {
        weld::exact(&mesh.vertices, &mesh.faces)
    };
    if exact.dropped > 0 {
        ladder.warn(
            HealthKind::FacesDropped,
            format!(
                "{} degenerate faces (repeated vertices) dropped",
                exact.dropped
            ),
        );
    }
    if exact.faces.is_empty() {
        return Err(MeshError::new(path, None, MeshErrorKind::Empty));
    }
    // Only a clean surface stops here, so only the proof that it is one runs: when it fails, the full
    // edge analysis is done once, on the tolerant weld's topology (on ERD's 152 meshes that are not
    // clean as stored, it ran twice before).
    let (proof, stored_integrals) = prove(&exact.vertices, &exact.faces);
    if let Some(components) = proof {
        return consistent_closed(
            ladder,
            exact.vertices,
            (exact.faces, stored_integrals),
            None,
            components,
            Rung::Exact,
        );
    }
    let precision = precision(&exact.vertices);
    let mut w = tolerant_welding(exact, precision);
    ladder.as_stored = winding_shells::AsStored {
        faces: w.kept.clone(),
        copies: std::mem::take(&mut w.copies),
        pairs: std::mem::take(&mut w.pairs),
        precision: Some(precision),
    };
    // Nothing merged or dropped: the topology is the exact weld's faces, which just failed the proof.
    let unchanged =
        w.tolerant.merged == 0 && w.collapsed == 0 && w.duplicates == 0 && w.cancelled == 0;
    let mut te = if unchanged {
        edge_analysis(&w.topology)
    } else {
        edges(&w.topology)
    };
    welding_notes(&mut ladder, &w);
    if te.closed() && te.inconsistent == 0 {
        let rung = Rung::Welded {
            merged_vertices: w.tolerant.merged,
            widest_crack: w.tolerant.widest,
            tolerance: w.tolerant.tolerance.largest,
        };
        let components = te.components(w.topology.len());
        // Every face dropped with its reverse: a double-sided export, which the error names.
        let two_sided = w.topology.is_empty() && w.cancelled > 0;
        return welded_closed(ladder, w, components, rung, stored_integrals)
            .map_err(|e| if two_sided { e.stored_two_sided() } else { e });
    }
    if te.closed() {
        if let Some(o) = orient(w.topology.len(), &te.pairs) {
            return reoriented(ladder, w, &te, &o);
        }
    }
    open_or_nonmanifold(ladder, w, &te)
}

#[cfg(test)]
mod tests;
