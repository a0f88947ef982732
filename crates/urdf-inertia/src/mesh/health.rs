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
mod topology;

use super::open::{NoSolid, OpenMeshModel};
use super::{hull, weld, winding_shells, MeshError, MeshErrorKind, RawMesh};
use crate::geometry::{cross, dot, sub};
use crate::mass::integrals::{bounding_box_centre, volume_integrals, VolumeIntegrals};
use crate::mass::{frobenius, IntegrationOptions, MassProperties, Polygons};
use caps::{cap_holes, Caps};
use std::borrow::Cow;
use std::path::Path;
pub use topology::closed_consistent;
use topology::{edge_analysis, edges, grouped, orient, Edges, Orientation};

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
    /// Round-off of the integration: the disagreement of two integrations about different reference
    /// points, and never less than [`ROUND_OFF_FLOOR`].
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

/// Smallest round-off estimate: the compensated kernel's results are within a few units of 2⁻⁵³ of
/// the exact value on every stiff case measured (docs/accuracy.md); 8·2⁻⁵³ leaves a margin.
pub const ROUND_OFF_FLOOR: f64 = 4.0 * f64::EPSILON;

/// The mesh after both welding passes: stored vertices (bit-exact welded), the stored faces, and the
/// topology the tolerant weld gives them.
struct Welding {
    vertices: Vec<[f64; 3]>,
    /// All faces as stored (bit-exact welded), less duplicates.
    stored: Polygons,
    /// The stored faces that survive the tolerant weld, in stored vertex indices.
    kept: Polygons,
    /// The same faces in representative indices: the topology.
    topology: Polygons,
    tolerant: weld::TolerantWeld,
    /// Faces that collapsed under the tolerant weld.
    collapsed: usize,
    /// Faces dropped as extra copies of a face (same direction), which the stored integral counts
    /// twice.
    duplicates: usize,
    /// Faces dropped in pairs, a face and its reverse, which cancel in the integral anyway.
    cancelled: usize,
}

fn tolerant_welding(exact: weld::ExactWeld, precision: weld::Precision) -> Welding {
    let tol = weld::tolerance(&exact.vertices, precision);
    let tolerant = weld::tolerant(&exact.vertices, tol);
    let (all_topology, kept_mask) = weld::remap_faces(&exact.faces, &tolerant.representative);
    let (dropped, duplicates, cancelled) = duplicate_faces(&all_topology);
    let mut stored = Polygons::new();
    let mut kept = Polygons::new();
    let mut topology = Polygons::new();
    let mut t = 0;
    for (i, face) in exact.faces.iter().enumerate() {
        if !kept_mask[i] {
            stored.push(face);
            continue;
        }
        if !dropped[t] {
            stored.push(face);
            kept.push(face);
            topology.push(all_topology.face(t));
        }
        t += 1;
    }
    Welding {
        collapsed: kept_mask.iter().filter(|k| !**k).count(),
        duplicates,
        cancelled,
        vertices: exact.vertices,
        stored,
        kept,
        topology,
        tolerant,
    }
}

/// Faces that repeat another one's vertices in the same cyclic order (a duplicate: kept once) or in
/// the reverse order (a zero-thickness wall: the pair cancels, both dropped). Returns per face whether
/// it is dropped, how many extra copies were dropped and how many faces in cancelling pairs.
fn duplicate_faces(faces: &Polygons) -> (Vec<bool>, usize, usize) {
    // Each face's vertices rotated to start at the smallest index, in whichever direction reads
    // smaller, and whether that was backwards. Sorting the keys groups the copies.
    let canonical = |f: &[u32]| -> (Vec<u32>, bool) {
        let k = (0..f.len()).min_by_key(|&i| f[i]).unwrap_or(0);
        let forward: Vec<u32> = (0..f.len()).map(|i| f[(k + i) % f.len()]).collect();
        let backward: Vec<u32> = (0..f.len())
            .map(|i| f[(k + f.len() - i) % f.len()])
            .collect();
        if forward <= backward {
            (forward, false)
        } else {
            (backward, true)
        }
    };
    // Triangles (nearly every face) without allocating: the key is the rotated triple.
    let mut keys: Vec<([u32; 3], bool, u32)> = Vec::with_capacity(faces.len());
    let mut others: Vec<(Vec<u32>, bool, u32)> = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        if let [a, b, c] = *f {
            let (x, y, z) = if a < b && a < c {
                (a, b, c)
            } else if b < c {
                (b, c, a)
            } else {
                (c, a, b)
            };
            let key = if y <= z {
                ([x, y, z], false)
            } else {
                ([x, z, y], true)
            };
            keys.push((key.0, key.1, i as u32));
        } else {
            let (key, reversed) = canonical(f);
            others.push((key, reversed, i as u32));
        }
    }
    sort_by_first_vertex(&mut keys);
    others.sort_unstable();
    let mut dropped = vec![false; faces.len()];
    let (mut repeated, mut cancelled) = (0, 0);
    let mut drop_group = |members: &[(bool, u32)]| {
        let ahead = members.iter().filter(|m| !m.0).count();
        let back = members.len() - ahead;
        cancelled += 2 * ahead.min(back);
        repeated += (ahead.max(back) - ahead.min(back)).saturating_sub(1);
        // Keep one face of the majority direction (none when the directions balance).
        let keep_dir = back > ahead;
        let mut keep = usize::from(ahead != back);
        for &(reversed, i) in members {
            if reversed == keep_dir && keep > 0 {
                keep -= 1;
            } else {
                dropped[i as usize] = true;
            }
        }
    };
    for group in keys.chunk_by(|a, b| a.0 == b.0).filter(|g| g.len() > 1) {
        let members: Vec<(bool, u32)> = group.iter().map(|m| (m.1, m.2)).collect();
        drop_group(&members);
    }
    for group in others.chunk_by(|a, b| a.0 == b.0).filter(|g| g.len() > 1) {
        let members: Vec<(bool, u32)> = group.iter().map(|m| (m.1, m.2)).collect();
        drop_group(&members);
    }
    (dropped, repeated, cancelled)
}

/// Sorts triangle keys as `sort_unstable` would (they are all distinct, so the order is the same):
/// a counting sort by the first vertex, then each bucket, a handful of keys, on its own. A comparison
/// sort of all keys took 6% of healing the 381 ERD meshes.
fn sort_by_first_vertex(keys: &mut Vec<([u32; 3], bool, u32)>) {
    let n = keys.iter().map(|k| k.0[0] as usize + 1).max().unwrap_or(0);
    let (start, mut sorted) = grouped(n, |put| {
        for k in keys.iter() {
            put(k.0[0] as usize, *k);
        }
    });
    for w in start.windows(2) {
        sorted[w[0] as usize..w[1] as usize].sort_unstable();
    }
    *keys = sorted;
}

/// Shared by the rungs: where the mesh came from and what has been said about it.
#[derive(Clone)]
struct Ladder<'a> {
    path: &'a Path,
    options: HealthOptions,
    warnings: Vec<HealthMessage>,
    notes: Vec<HealthMessage>,
    faces_read: usize,
    /// The integrals of the faces `finish` gets, when a rung already has them (a clean mesh is then
    /// integrated twice, not three times: once here, once about a second reference point).
    known: Option<VolumeIntegrals>,
}

impl<'a> Ladder<'a> {
    /// A ladder starting with what the reader said about `mesh`.
    fn new(mesh: &RawMesh, path: &'a Path, options: HealthOptions) -> Self {
        Ladder {
            path,
            options,
            warnings: mesh
                .warnings
                .iter()
                .map(|w| HealthMessage::new(HealthKind::ReaderSkipped, w.clone()))
                .collect(),
            notes: mesh
                .notes
                .iter()
                .map(|n| HealthMessage::new(HealthKind::ReaderNote, n.clone()))
                .collect(),
            faces_read: mesh.faces.len(),
            known: None,
        }
    }

    fn warn(&mut self, kind: HealthKind, text: String) {
        self.warnings.push(HealthMessage::new(kind, text));
    }

    fn note(&mut self, kind: HealthKind, text: String) {
        self.notes.push(HealthMessage::new(kind, text));
    }

    fn strict(&self, what: &str) -> Result<(), MeshError> {
        if self.options.strict {
            Err(MeshError::new(
                self.path,
                None,
                MeshErrorKind::Strict(what.to_string()),
            ))
        } else {
            Ok(())
        }
    }

    /// On the repaired rungs, the faces that bound the solid when shells overlap (see
    /// [`super::winding_shells`]): doubly enclosed shells dropped, inside-out ones turned, and what is
    /// left undecided bounded in `model`. The surfaces integrated as stored pay nothing.
    fn shells(
        &mut self,
        vertices: &[[f64; 3]],
        faces: Polygons,
        rung: &Rung,
        model: &mut Model,
    ) -> Polygons {
        if !matches!(
            rung,
            Rung::Capped { .. } | Rung::NonManifold { .. } | Rung::Reoriented { .. }
        ) {
            return faces;
        }
        let s = winding_shells::classify(vertices, &faces);
        if s.overlap_bound > 0.0 {
            let others: f64 = model.terms.iter().map(|t| t.0).sum();
            if s.overlap_bound > others {
                model.source = ModelError::Overlap;
            }
            model.terms.push((s.overlap_bound, Lever::Anywhere));
            self.warn(HealthKind::Repaired, format!(
                "{} pair(s) of shells touch or cut each other (or are open) where their boxes overlap: the volume they may count twice, at most {:.2e} m³ (their boxes' intersections), is in the error estimate",
                s.undecided_pairs, s.overlap_bound
            ));
        }
        if !s.changed {
            return faces;
        }
        self.known = None;
        let mut done = Vec::new();
        if s.dropped_shells > 0 {
            done.push(format!(
                "{} shell(s) ({} faces) inside the solid on both sides left out (an internal wall or a region enclosed twice would count twice)",
                s.dropped_shells, s.dropped_faces
            ));
        }
        if s.turned_shells > 0 {
            done.push(format!(
                "{} shell(s) turned round (inside-out, or a cavity wound outward), so each counts once",
                s.turned_shells
            ));
        }
        self.warn(
            HealthKind::Repaired,
            format!("overlapping shells: {}", done.join("; ")),
        );
        s.faces
    }

    /// Integrates, checks the volume and estimates the error: the last step of every rung. `model`
    /// is the volume (m³) by which the solid can differ from the stored surface, and what it is made
    /// of; `message` turns the relative model error into the rung's warning, if it has one.
    fn finish(
        mut self,
        vertices: Vec<[f64; 3]>,
        faces: Polygons,
        rung: Rung,
        model: impl Into<Model>,
        message: impl FnOnce(f64, f64) -> Option<String>,
    ) -> Result<Solid, MeshError> {
        let mut model = model.into();
        let faces = self.shells(&vertices, faces, &rung, &mut model);
        let unit = match self.known.take() {
            Some(t) => MassProperties::from_integrals(&t, 1.0),
            None => unit_props(&vertices, &faces, None),
        };
        // One pass for the box both checks use.
        let bounds = bbox(&vertices);
        check_volume(&vertices, &faces, bounds, unit.mass, self.path)?;
        let round_off = round_off(&vertices, &faces, bounds.0, &unit);
        let source = model.source;
        let bound = model.bound(&unit, &vertices);
        let model_error = bound.relative;
        if let Some(m) = message(model_error, unit.mass) {
            self.warn(HealthKind::Repaired, m);
        }
        let mut rung = rung;
        if let Rung::Capped {
            relative_uncertainty,
            ..
        } = &mut rung
        {
            *relative_uncertainty = model_error;
        }
        // Round-off shifts the centre by the relative round-off of the first moments, about the
        // reference point.
        let com =
            bound.com + round_off * (reach(&unit, &vertices) + dot(unit.com, unit.com).sqrt());
        let error = ErrorEstimate {
            round_off,
            model: model_error,
            com,
            source: if model_error > 0.0 {
                source
            } else {
                ModelError::None
            },
        };
        Ok(Solid {
            vertices,
            faces,
            rung,
            warnings: self.warnings,
            notes: self.notes,
            unit,
            error_estimate: error.total(),
            error,
            faces_read: self.faces_read,
        })
    }
}

/// Where the volume of a model error may sit: anywhere in the solid, or near given points (the
/// loops a cap closes).
enum Lever {
    Anywhere,
    Near(Vec<[f64; 3]>),
}

/// A model error: volumes (m³) by which the solid can differ from the stored surface, each with where
/// it sits, and what the largest is made of.
struct Model {
    terms: Vec<(f64, Lever)>,
    source: ModelError,
}

impl From<(f64, ModelError)> for Model {
    fn from((delta, source): (f64, ModelError)) -> Model {
        Model {
            terms: vec![(delta, Lever::Anywhere)],
            source,
        }
    }
}

/// A model error as relative bounds.
struct Bound {
    /// On volume and central inertia.
    relative: f64,
    /// On the centre of mass, m.
    com: f64,
}

impl Model {
    /// The relative error that volumes δᵢ moved, added or removed at distances up to Rᵢ from the
    /// centre of mass can cause, against the true value (at least the computed one less the change):
    /// for the volume Σδ/(V − Σδ); for the central inertia 3·Σδ·R²/(‖I‖ − 3·Σδ·R²) (a point mass δ at
    /// distance R changes the tensor by at most √2·δ·R², and the centre of mass it moves by as much
    /// again); for the centre of mass Σδ·R/(V − Σδ). Unbounded when the change could be as large as
    /// the value itself.
    fn bound(&self, unit: &MassProperties, vertices: &[[f64; 3]]) -> Bound {
        let (mut volume, mut inertia, mut moment) = (0.0, 0.0, 0.0);
        for (delta, lever) in &self.terms {
            if *delta == 0.0 {
                continue;
            }
            let r = match lever {
                Lever::Anywhere => reach(unit, vertices),
                Lever::Near(points) => reach(unit, points),
            };
            volume += delta;
            inertia += 3.0 * delta * r * r;
            moment += delta * r;
        }
        if volume == 0.0 {
            return Bound {
                relative: 0.0,
                com: 0.0,
            };
        }
        let bounded = |change: f64, value: f64| {
            if change < value {
                change / (value - change)
            } else {
                f64::INFINITY
            }
        };
        Bound {
            relative: bounded(volume, unit.mass).max(bounded(inertia, frobenius(&unit.inertia))),
            com: bounded(moment, unit.mass - volume + moment),
        }
    }
}

/// The largest distance of a vertex from the centre of mass.
fn reach(unit: &MassProperties, vertices: &[[f64; 3]]) -> f64 {
    vertices
        .iter()
        .map(|v| dist(*v, unit.com))
        .fold(0.0, f64::max)
}

/// Turns a scaled mesh into a solid by the ladder in the module docs, its coordinates taken as f64
/// values (see [`heal`] for meshes stored in f32 or as decimals).
#[cfg(any(test, feature = "internals"))]
pub fn make_solid(mesh: &RawMesh, path: &Path, options: HealthOptions) -> Result<Solid, MeshError> {
    heal(Cow::Borrowed(mesh), path, options, |_| weld::Precision::F64)
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
    if let Some(components) = closed_consistent(&exact.faces) {
        return consistent_closed(
            ladder,
            exact.vertices,
            exact.faces,
            None,
            components,
            Rung::Exact,
        );
    }
    let precision = precision(&exact.vertices);
    let w = tolerant_welding(exact, precision);
    // Nothing merged or dropped: the topology is the exact weld's faces, which just failed the proof.
    let unchanged =
        w.tolerant.merged == 0 && w.collapsed == 0 && w.duplicates == 0 && w.cancelled == 0;
    let mut te = if unchanged {
        edge_analysis(&w.topology)
    } else {
        edges(&w.topology)
    };
    if w.duplicates > 0 {
        ladder.warn(
            HealthKind::FacesDropped,
            format!(
            "{} faces stored more than once dropped (the copies would count their volume twice)",
            w.duplicates
        ),
        );
    }
    if w.cancelled > 0 {
        ladder.note(HealthKind::FacesCancelled, format!(
            "{} faces dropped in pairs, each a face and its reverse (a wall of no thickness; they cancel)",
            w.cancelled
        ));
    }
    if w.collapsed > 0 {
        ladder.note(HealthKind::Welded, format!(
            "{} sliver faces collapse when corners within {:.1e} m are welded; left out of the topology",
            w.collapsed, w.tolerant.tolerance.largest
        ));
    }
    if te.closed() && te.inconsistent == 0 {
        let rung = Rung::Welded {
            merged_vertices: w.tolerant.merged,
            widest_crack: w.tolerant.widest,
            tolerance: w.tolerant.tolerance.largest,
        };
        let components = te.components(w.topology.len());
        return consistent_closed(ladder, w.vertices, w.stored, Some(w.kept), components, rung);
    }
    if te.closed() {
        if let Some(o) = orient(w.topology.len(), &te.pairs) {
            return reoriented(ladder, w, &te, &o);
        }
    }
    open_or_nonmanifold(ladder, w, &te)
}

/// Closed and consistent (bit-exact or after the tolerant weld): as stored, flipped if inward, or with
/// the components re-oriented whose winding contradicts their nesting.
///
/// `kept` are the faces the topology (the component ids `comp`) numbers, `None` when they are `stored`
/// themselves.
fn consistent_closed(
    mut ladder: Ladder<'_>,
    vertices: Vec<[f64; 3]>,
    stored: Polygons,
    kept: Option<Polygons>,
    (comp, ncomp): (Vec<u32>, usize),
    rung: Rung,
) -> Result<Solid, MeshError> {
    // Closed only once welded within tolerance: the stored surface's vector area is not exactly 0.
    let welded = kept.is_some();
    let t = volume_integrals(&vertices, &stored, &IntegrationOptions::accurate());
    let inverted = t.t1 < 0.0;
    let mut faces = stored;
    let mut kept = kept;
    let mut rung = rung;
    if inverted {
        ladder.strict("closed mesh wound inward")?;
        let all = vec![true; faces.len()];
        apply(&mut faces, &all);
        if let Some(k) = kept.as_mut() {
            let all = vec![true; k.len()];
            apply(k, &all);
        }
        ladder.warn(
            HealthKind::Repaired,
            format!(
                "all {} faces wound inward (negative volume); flipped",
                faces.len()
            ),
        );
        rung = Rung::Inverted;
    }
    let topology_faces = kept.as_ref().unwrap_or(&faces);
    if ncomp > 1 {
        let flip = misoriented(&vertices, topology_faces, &comp, ncomp);
        if flip.iter().any(|f| *f) {
            ladder.strict("a closed component is wound inward")?;
            let reversed: Vec<bool> = comp.iter().map(|&c| flip[c as usize]).collect();
            let mut out = topology_faces.clone();
            apply(&mut out, &reversed);
            let flipped = reversed.iter().filter(|r| **r).count();
            let turned = flip.iter().filter(|f| **f).count();
            ladder.warn(HealthKind::Repaired, format!(
                "{turned} of {ncomp} closed components wound inward although no other component encloses them (a cavity must lie inside a solid); {flipped} faces flipped"
            ));
            let model = open_volume(&vertices, &out);
            let rung = Rung::Reoriented {
                faces_flipped: flipped,
                components: ncomp,
            };
            return ladder.finish(vertices, out, rung, (model, ModelError::Cracks), |_, _| {
                None
            });
        }
    }
    if let Rung::Welded {
        merged_vertices,
        widest_crack,
        tolerance,
    } = rung
    {
        ladder.note(HealthKind::Welded, format!(
            "closed once {merged_vertices} corners stored up to {widest_crack:.1e} m apart are welded (tolerance {tolerance:.1e} m); integrated as stored"
        ));
    }
    let model = if welded {
        open_volume(&vertices, &faces)
    } else {
        0.0
    };
    // The faces are the stored ones, or all of them reversed: their integrals are known.
    ladder.known = Some(if inverted { t.negated() } else { t });
    ladder.finish(
        vertices,
        faces,
        rung,
        (model, ModelError::Cracks),
        |_, _| None,
    )
}

/// Components beyond this many are not checked for nesting (quadratic in the components).
const NESTING_CHECK: usize = 2_000;

/// Which components to flip: those wound inward (negative volume) at an even nesting depth, where a
/// component's depth is the number of larger components whose bounding boxes contain its own. A
/// component wound inward that nothing encloses cannot be a cavity. An outward component at an odd
/// depth is kept: bounding boxes cannot tell a cavity wound the wrong way from a part lying in
/// another's concavity.
fn misoriented(vertices: &[[f64; 3]], faces: &Polygons, comp: &[u32], ncomp: usize) -> Vec<bool> {
    if ncomp > NESTING_CHECK {
        return vec![false; ncomp];
    }
    let vol = component_volumes(vertices, faces, comp, ncomp);
    if vol.iter().all(|v| *v >= 0.0) {
        return vec![false; ncomp];
    }
    let boxes = component_boxes(vertices, faces, comp, ncomp);
    (0..ncomp)
        .map(|c| {
            let depth = (0..ncomp)
                .filter(|&d| {
                    d != c && vol[d].abs() > vol[c].abs() && contains(&boxes[d], &boxes[c])
                })
                .count();
            vol[c] < 0.0 && depth % 2 == 0
        })
        .collect()
}

/// The volume that moves with the reference point, over reference points in the bounding box, for a
/// surface that is closed only up to cracks: |vector area| × diagonal / 6 (the signed volume about
/// r is V(0) − r·A/3). Zero for a closed surface; its round-off for one closed bit for bit.
fn open_volume(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    let (lo, hi) = bbox(vertices);
    vector_area(vertices, faces) * dist(lo, hi) / 6.0
}

/// Closed after the tolerant weld but wound inconsistently: each component made consistent and outward.
fn reoriented(
    mut ladder: Ladder<'_>,
    w: Welding,
    te: &Edges,
    o: &Orientation,
) -> Result<Solid, MeshError> {
    let Outward {
        reversed,
        flipped,
        nested,
        flip_volume,
    } = outward(&w.vertices, &w.kept, o);
    let mut faces = w.kept.clone();
    apply(&mut faces, &reversed);
    ladder.strict(&format!(
        "{} faces wound against their neighbours",
        te.inconsistent
    ))?;
    ladder.warn(HealthKind::Repaired, format!(
        "closed, but {flipped} of {} faces were wound against their neighbours ({} edges disagreed); re-oriented each of {} component(s) outward",
        faces.len(),
        te.inconsistent,
        o.ncomp
    ));
    let rung = Rung::Reoriented {
        faces_flipped: flipped,
        components: o.ncomp,
    };
    let model = open_volume(&w.vertices, &faces) + nested + flip_volume;
    let source = if nested + flip_volume > 0.0 {
        ModelError::Orientation
    } else {
        ModelError::Cracks
    };
    ladder.finish(w.vertices, faces, rung, (model, source), |_, _| None)
}

/// Each face's reversal under an orientation that turns every component outward by its own signed
/// volume, how many faces that flips, and the volume of components lying inside another one's
/// bounding box (counted twice: a cavity turned outward adds its volume instead of removing it).
/// `flip_volume` is what the faces flipped against the rest of their component change ([`flip_change`]).
struct Outward {
    reversed: Vec<bool>,
    flipped: usize,
    nested: f64,
    flip_volume: f64,
}

/// The volume that re-orienting faces within components can change, m³: per component, the smaller
/// of the sets flipped and kept (flipping a whole shell changes nothing the winding number rule does
/// not already decide) changes the integral by twice its signed volume, which moves with the
/// reference point by twice its vector area × the diagonal / 6; both are counted.
fn flip_change(vertices: &[[f64; 3]], faces: &Polygons, o: &Orientation, reversed: &[bool]) -> f64 {
    let centre = bounding_box_centre(vertices);
    let (lo, hi) = bbox(vertices);
    let diag = dist(lo, hi);
    let mut count = vec![[0usize; 2]; o.ncomp];
    for (i, r) in reversed.iter().enumerate() {
        count[o.comp[i] as usize][usize::from(*r)] += 1;
    }
    let mut volume6 = vec![0.0f64; o.ncomp];
    let mut area2 = vec![[0.0f64; 3]; o.ncomp];
    for (i, face) in faces.iter().enumerate() {
        let c = o.comp[i] as usize;
        // The minority side (ties: the flipped side); nothing when the whole component turned.
        let minority = usize::from(count[c][1] <= count[c][0]);
        if usize::from(reversed[i]) != minority || count[c][0].min(count[c][1]) == 0 {
            continue;
        }
        let a = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let b = sub(vertices[face[k] as usize], centre);
            let d = sub(vertices[face[k + 1] as usize], centre);
            volume6[c] += dot(a, cross(b, d));
            let n = cross(sub(b, a), sub(d, a));
            (0..3).for_each(|j| area2[c][j] += n[j]);
        }
    }
    (0..o.ncomp)
        .map(|c| 2.0 * volume6[c].abs() / 6.0 + dot(area2[c], area2[c]).sqrt() * diag / 6.0)
        .sum()
}

fn outward(vertices: &[[f64; 3]], faces: &Polygons, o: &Orientation) -> Outward {
    let mut trial = faces.clone();
    apply(&mut trial, &o.flip);
    let vol = component_volumes(vertices, &trial, &o.comp, o.ncomp);
    let reversed: Vec<bool> = (0..faces.len())
        .map(|i| o.flip[i] ^ (vol[o.comp[i] as usize] < 0.0))
        .collect();
    let flipped = reversed.iter().filter(|r| **r).count();
    let mut nested = 0.0;
    if o.ncomp > 1 {
        let boxes = component_boxes(vertices, faces, &o.comp, o.ncomp);
        for c in 0..o.ncomp {
            if (0..o.ncomp).any(|d| d != c && contains(&boxes[d], &boxes[c])) {
                nested += 2.0 * vol[c].abs() / 6.0;
            }
        }
    }
    let flip_volume = flip_change(vertices, faces, o, &reversed);
    Outward {
        reversed,
        flipped,
        nested,
        flip_volume,
    }
}

/// Reverses the faces marked.
fn apply(faces: &mut Polygons, reversed: &[bool]) {
    for (i, r) in reversed.iter().enumerate() {
        if *r {
            faces.reverse_face(i);
        }
    }
}

/// One way to wind an open or non-manifold mesh: the stored faces kept by the weld with some faces
/// reversed, and the boundary edges of their topology as directed then.
struct Winding {
    faces: Polygons,
    /// What `edges(topology)` gives as `boundary_half_edges` for the topology with the same faces
    /// reversed: the same edges in the same (key) order, each turned round if its face is. Derived
    /// from the topology's edges rather than analysing each winding again (a third and fourth pass
    /// over every half-edge).
    boundary: Vec<(u32, u32)>,
    flipped: usize,
    /// Volume of components re-oriented inside another's bounding box (m³).
    nested: f64,
    /// What flipping faces against the rest of their component changes (m³, [`flip_change`]).
    flip_volume: f64,
}

impl Winding {
    fn flips(&self) -> String {
        if self.flipped > 0 {
            format!(", {} faces re-oriented", self.flipped)
        } else {
            String::new()
        }
    }
}

/// Orient what the manifold edges allow, each component outward; failing that (contradicting edges,
/// or open sheets whose sign is meaningless), the winding as the file gives it.
fn windings(w: &Welding, te: &Edges) -> Vec<Winding> {
    let mut out = Vec::new();
    if let Some(o) = orient(w.topology.len(), &te.pairs) {
        let turned = outward(&w.vertices, &w.kept, &o);
        if turned.flipped > 0 {
            let mut faces = w.kept.clone();
            apply(&mut faces, &turned.reversed);
            let boundary = (te.boundary_half_edges.iter().zip(&te.boundary_faces))
                .map(|(&(u, v), &f)| {
                    if turned.reversed[f as usize] {
                        (v, u)
                    } else {
                        (u, v)
                    }
                })
                .collect();
            out.push(Winding {
                faces,
                boundary,
                flipped: turned.flipped,
                nested: turned.nested,
                flip_volume: turned.flip_volume,
            });
        }
    }
    out.push(Winding {
        faces: w.kept.clone(),
        boundary: te.boundary_half_edges.clone(),
        flipped: 0,
        nested: 0.0,
        flip_volume: 0.0,
    });
    out
}

/// Open or non-manifold: integration as it is, caps, or the convex hull.
fn open_or_nonmanifold(ladder: Ladder<'_>, w: Welding, te: &Edges) -> Result<Solid, MeshError> {
    let what = te.describe();
    let mut fallback: Option<(f64, Winding, CappedSolid)> = None;
    for winding in windings(&w, te) {
        if te.boundary == 0 {
            if signed_volume(&w.vertices, &winding.faces) > 0.0 {
                return non_manifold(ladder, w, te, winding, &what);
            }
            continue;
        }
        let Some(caps) = cap_holes(&w.vertices, &winding.boundary) else {
            continue;
        };
        let mut vertices = w.vertices.clone();
        vertices.extend_from_slice(&caps.centroids);
        let mut capped = winding.faces.clone();
        for f in caps.faces.iter() {
            capped.push(f);
        }
        let unit = unit_props(&vertices, &capped, None);
        let volume = unit.mass;
        let cracks = open_volume(&vertices, &capped);
        // The caps are used when the bound they leave on volume and inertia is small enough.
        let relative = caps_model(&caps, cracks, winding.nested)
            .bound(&unit, &vertices)
            .relative;
        // An unbounded cap is still what `--open-mesh caps` asks for, with its bound.
        if volume.is_nan() || volume <= 0.0 || relative.is_nan() {
            continue;
        }
        let plan = CappedSolid {
            cracks,
            vertices,
            faces: capped,
            volume,
            caps,
        };
        if relative <= CAPPED {
            return with_caps(ladder, w, te, winding, plan, &what);
        }
        if fallback.as_ref().is_none_or(|f| relative < f.0) {
            fallback = Some((relative, winding, plan));
        }
    }
    // Caps too uncertain to trust: the model the user chose, or no solid (never a silent hull).
    let no_solid = |caps_bound| {
        MeshError::new(
            ladder.path,
            None,
            MeshErrorKind::NoSolid(NoSolid {
                what: what.clone(),
                caps_bound,
            }),
        )
    };
    match (ladder.options.open_mesh, fallback) {
        (OpenMeshModel::Hull, _) => convex_hull(ladder, &w, te, &what),
        (OpenMeshModel::Caps, Some((_, winding, plan))) => {
            with_caps(ladder, w, te, winding, plan, &what)
        }
        (OpenMeshModel::Trusted, Some((relative, ..))) => Err(no_solid(Some(relative))),
        // No closing encloses a volume: a flat plate or a two-sided sheet has none to speak of (the
        // part contributes nothing); anything else defines no solid.
        (_, None) if super::open::encloses_nothing(&w.vertices, &w.stored) => {
            let (lo, hi) = bbox(&w.vertices);
            Err(MeshError::new(
                ladder.path,
                None,
                MeshErrorKind::ZeroVolume {
                    volume: signed_volume(&w.vertices, &w.stored),
                    bbox_volume: (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]),
                },
            ))
        }
        (_, None) => Err(no_solid(None)),
    }
}

/// No boundary edges but edges shared by three or more faces: integrated as stored (up to the faces
/// re-oriented). A region that two shells enclose counts twice here exactly as in the stored surface,
/// which the warning says.
fn non_manifold(
    mut ladder: Ladder<'_>,
    w: Welding,
    te: &Edges,
    winding: Winding,
    what: &str,
) -> Result<Solid, MeshError> {
    ladder.strict(&format!("mesh is {what}"))?;
    ladder.warn(HealthKind::Repaired, format!("mesh is {what} but has no holes: integrated as it is{} (shells that overlap are classified by the winding number on their sides)", winding.flips()));
    let model = open_volume(&w.vertices, &winding.faces) + winding.nested + winding.flip_volume;
    let rung = Rung::NonManifold {
        nonmanifold_edges: te.nonmanifold,
        faces_flipped: winding.flipped,
    };
    let source = if winding.nested + winding.flip_volume > 0.0 {
        ModelError::Orientation
    } else {
        ModelError::Cracks
    };
    ladder.finish(w.vertices, winding.faces, rung, (model, source), |_, _| {
        None
    })
}

/// The model error of caps: their bound near the loops they close, cracks left open and components
/// re-oriented anywhere.
fn caps_model(caps: &Caps, cracks: f64, nested: f64) -> Model {
    Model {
        terms: vec![
            (caps.bound, Lever::Near(caps.points.clone())),
            (cracks, Lever::Anywhere),
            (nested, Lever::Anywhere),
        ],
        source: ModelError::Caps,
    }
}

/// A mesh with its holes capped, ready to integrate.
struct CappedSolid {
    vertices: Vec<[f64; 3]>,
    faces: Polygons,
    volume: f64,
    caps: Caps,
    /// Volume that moves with the reference point after capping (cracks left open), m³.
    cracks: f64,
}

/// The capped solid, or, when the "holes" are slivers whose caps change nothing measurable, the
/// stored triangles as they are (rung welded).
fn with_caps(
    mut ladder: Ladder<'_>,
    w: Welding,
    te: &Edges,
    winding: Winding,
    plan: CappedSolid,
    what: &str,
) -> Result<Solid, MeshError> {
    let caps = &plan.caps;
    // Whatever surface really spans the loops, its contribution is at most (its area) × diagonal.
    let (lo, hi) = bbox(&w.vertices);
    let spans = caps.area * dist(lo, hi);
    if (spans + caps.bound + plan.cracks) / plan.volume <= SLIVERS && winding.flipped == 0 {
        ladder.note(HealthKind::Welded, format!(
            "closed up to slivers once corners within {:.1e} m are welded ({} boundary edges bound {:.1e} m² in all); integrated as stored",
            w.tolerant.tolerance.largest, te.boundary, caps.area
        ));
        let rung = Rung::Welded {
            merged_vertices: w.tolerant.merged,
            widest_crack: w.tolerant.widest,
            tolerance: w.tolerant.tolerance.largest,
        };
        let model = spans + caps.bound + plan.cracks;
        return ladder.finish(
            w.vertices,
            w.stored,
            rung,
            (model, ModelError::Cracks),
            |_, _| None,
        );
    }
    ladder.strict(&format!("mesh is {what}"))?;
    let mut done = Vec::new();
    if caps.holes > 0 {
        done.push(format!("closed its {} hole(s) with flat caps", caps.holes));
    }
    if caps.cracks > 0 {
        done.push(format!(
            "left {} edge(s) of cracks or T-junctions open",
            caps.cracks
        ));
    }
    let mut model = caps_model(caps, plan.cracks, winding.nested);
    // The flips are in the estimate, not in the choice whether caps are trusted (that is about caps).
    model.terms.push((winding.flip_volume, Lever::Anywhere));
    let rung = Rung::Capped {
        holes: caps.holes,
        boundary_edges: te.boundary,
        nonmanifold_edges: te.nonmanifold,
        faces_flipped: winding.flipped,
        relative_uncertainty: 0.0,
    };
    let done = done.join(", ");
    let flips = winding.flips();
    ladder.finish(plan.vertices, plan.faces, rung, model, |m, volume| {
        Some(if m > 0.0 {
            format!(
                "mesh is {what}: {done}{flips}; its volume {volume:.6e} m³ and inertia are uncertain by at most {m:.1e} (relative) because of them"
            )
        } else {
            format!(
                "mesh is {what}: {done}{flips}; the holes' edges are planar, so the caps are exact if the missing surface was flat (volume {volume:.6e} m³); if it was not, this number is off by the missing volume"
            )
        })
    })
}

/// The convex hull of the vertices, with the numbers that say how far that is from the mesh.
fn convex_hull(
    ladder: Ladder<'_>,
    w: &Welding,
    te: &Edges,
    what: &str,
) -> Result<Solid, MeshError> {
    let (lo, hi) = bbox(&w.vertices);
    let diag = dist(lo, hi);
    // The stored surface's signed volume, and how much it moves over reference points in the box.
    let own = signed_volume(&w.vertices, &w.stored);
    let moves = vector_area(&w.vertices, &w.stored) * diag / 6.0;
    // The hull of the vertices the faces use: unused stored positions are not the surface's.
    let (hv, ht) = hull::convex_hull_of_used(&w.vertices, &w.stored).map_err(|err| match err {
        hull::HullError::Degenerate => MeshError::new(
            ladder.path,
            None,
            MeshErrorKind::ZeroVolume {
                volume: own,
                bbox_volume: (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]),
            },
        ),
    })?;
    let hull_faces = Polygons::from_triangles(&ht);
    let hull_volume = signed_volume(&hv, &hull_faces);
    ladder.strict(&format!("mesh is {what}"))?;
    // The mesh's own volume is the truth up to `moves`; the hull differs from it by this much.
    let model = (own - hull_volume).abs() + moves;
    let nv = hv.len();
    let share = if hull_volume != 0.0 {
        100.0 * (own - hull_volume) / hull_volume
    } else {
        0.0
    };
    let message = move |m: f64, _| {
        let bound = if m.is_finite() {
            format!("uncertain by at most {m:.1e} (relative)")
        } else {
            "not bounded: the mesh's own volume is too uncertain to compare".to_string()
        };
        Some(format!(
            "mesh is {what}; used its convex hull as `--open-mesh hull` asks ({nv} vertices, volume {hull_volume:.6e} m³): an upper bound, as the solid the surface encloses lies inside it. The mesh's own signed volume is {own:.6e} m³ ({share:+.1}% of the hull) and moves by up to {moves:.2e} m³ with the reference point, so it is not a solid; the hull's numbers are {bound}"
        ))
    };
    let rung = Rung::ConvexHull {
        boundary_edges: te.boundary,
        nonmanifold_edges: te.nonmanifold,
        mesh_volume: own,
        hull_volume,
        volume_moves_by: moves,
    };
    ladder.finish(hv, hull_faces, rung, (model, ModelError::Hull), message)
}

fn unit_props(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    reference: Option<[f64; 3]>,
) -> MassProperties {
    let opts = IntegrationOptions {
        reference,
        ..IntegrationOptions::accurate()
    };
    MassProperties::from_integrals(&volume_integrals(vertices, faces, &opts), 1.0)
}

fn signed_volume(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    volume_integrals(vertices, faces, &IntegrationOptions::accurate()).t1
}

fn bbox(vertices: &[[f64; 3]]) -> Aabb {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

/// The round-off estimate: the relative disagreement of volume and central inertia integrated about
/// two reference points (bounding-box centre and corner), never below [`ROUND_OFF_FLOOR`].
fn round_off(vertices: &[[f64; 3]], faces: &Polygons, lo: [f64; 3], base: &MassProperties) -> f64 {
    let other = unit_props(vertices, faces, Some(lo));
    let mut d = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = other.inertia[i][j] - base.inertia[i][j];
        }
    }
    let n = frobenius(&base.inertia);
    let inertia = if n > 0.0 {
        frobenius(&d) / n
    } else {
        f64::INFINITY
    };
    let volume = ((other.mass - base.mass) / base.mass).abs();
    inertia.max(volume).max(ROUND_OFF_FLOOR)
}

/// A solid is empty when its volume is within a thousand round-offs of its faces' contributions
/// (Σ face area × diagonal): relative to the surface, so a needle 1e-6 × 1e-6 × 1 (volume 1e-12 of
/// its diagonal cubed), rotated or not, is a solid, and a flat or doubly covered sheet is not.
fn check_volume(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    (lo, hi): ([f64; 3], [f64; 3]),
    volume: f64,
    path: &Path,
) -> Result<(), MeshError> {
    let area: f64 = faces.iter().map(|f| polygon_area(vertices, f)).sum();
    let floor = ZERO_VOLUME_ROUNDOFFS * f64::EPSILON * area * dist(lo, hi);
    if volume.is_nan() || volume <= floor {
        return Err(MeshError::new(
            path,
            None,
            MeshErrorKind::ZeroVolume {
                volume,
                bbox_volume: (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]),
            },
        ));
    }
    Ok(())
}

/// Six times the signed volume of each connected component (about the bounding-box centre).
fn component_volumes(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    comp: &[u32],
    ncomp: usize,
) -> Vec<f64> {
    let centre = bounding_box_centre(vertices);
    let mut vol = vec![0.0f64; ncomp];
    for (i, face) in faces.iter().enumerate() {
        let a = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let b = sub(vertices[face[k] as usize], centre);
            let c = sub(vertices[face[k + 1] as usize], centre);
            vol[comp[i] as usize] += dot(a, cross(b, c));
        }
    }
    vol
}

/// A box `(lo, hi)`.
pub type Aabb = ([f64; 3], [f64; 3]);

fn component_boxes(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    comp: &[u32],
    ncomp: usize,
) -> Vec<Aabb> {
    let mut boxes = vec![([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]); ncomp];
    for (i, face) in faces.iter().enumerate() {
        let b = &mut boxes[comp[i] as usize];
        for &v in face {
            for k in 0..3 {
                b.0[k] = b.0[k].min(vertices[v as usize][k]);
                b.1[k] = b.1[k].max(vertices[v as usize][k]);
            }
        }
    }
    boxes
}

fn contains(outer: &Aabb, inner: &Aabb) -> bool {
    (0..3).all(|k| outer.0[k] <= inner.0[k] && inner.1[k] <= outer.1[k])
}

/// The length of the surface's vector area `Σ N/2` (zero for a closed surface).
fn vector_area(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    let centre = bounding_box_centre(vertices);
    let mut a = [0.0f64; 3];
    for face in faces.iter() {
        let p = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let e1 = sub(sub(vertices[face[k] as usize], centre), p);
            let e2 = sub(sub(vertices[face[k + 1] as usize], centre), p);
            let x = cross(e1, e2);
            for j in 0..3 {
                a[j] += 0.5 * x[j];
            }
        }
    }
    dot(a, a).sqrt()
}

/// Area of a planar polygon (fan from its first vertex).
fn polygon_area(vertices: &[[f64; 3]], face: &[u32]) -> f64 {
    let p = vertices[face[0] as usize];
    let mut a = [0.0f64; 3];
    for k in 1..face.len().saturating_sub(1) {
        let x = cross(
            sub(vertices[face[k] as usize], p),
            sub(vertices[face[k + 1] as usize], p),
        );
        for j in 0..3 {
            a[j] += 0.5 * x[j];
        }
    }
    dot(a, a).sqrt()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

#[cfg(test)]
mod tests;
