//! Per-link composition (the paper's Problem 1): each link's collision parts, each with a density or a
//! mass, as one body in the link frame.
//!
//! Work a robot does not need is left out: only links with collision geometry (and selected by
//! `--only/--skip/--missing-only`) are computed, visual meshes are never read, each mesh file is read
//! once and each (file, scale) healed and integrated once.

use crate::density::{DensityMap, Spec};
use crate::diagnostic::{
    self, Code, CollisionRef, Diagnostic, LinkError, LinkErrorKind, Location, Provenance,
    RobotError,
};
use crate::mass::{mat_vec, primitives, rpy_matrix, validity, MassProperties};
pub use crate::mesh::cache::MeshCache;
use crate::mesh::cache::Solids;
use crate::mesh::health::{ErrorEstimate, HealthOptions, ModelError, ROUND_OFF_FLOOR};
use crate::overlap::{self, Overlap, PartShape, PlacedPart};
use crate::urdf::resolve::PackageResolver;
use crate::urdf::{Collision, Geometry, Inertial, Link, Robot};
use std::path::PathBuf;
use std::time::Duration;

/// A collision mesh larger than this (bounding-box diagonal, m) is almost surely in millimetres.
const MILLIMETRE_SLIP: f64 = 10.0;

/// A primitive's formulas are exact; their f64 evaluation is within a few ulps.
const PRIMITIVE_ERROR: ErrorEstimate = ErrorEstimate {
    round_off: ROUND_OFF_FLOOR,
    model: 0.0,
    source: ModelError::None,
    com: 0.0,
};

/// What to compute.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct FillOptions {
    pub strict: bool,
    /// What an open mesh whose caps cannot be trusted becomes (`--open-mesh`).
    pub open_mesh: crate::mesh::open::OpenMeshModel,
    /// `--only` / `--skip`: links selected by name, compiled once.
    pub only: Vec<crate::density::Glob>,
    pub skip: Vec<crate::density::Glob>,
    /// Only links whose inertial is absent or invalid.
    pub missing_only: bool,
    /// Each link's existing `<mass>` is its mass target.
    pub keep_mass: bool,
    /// `--allow-large-parts`: a mesh over 10 m across is a warning, not its link's error.
    pub allow_large_parts: bool,
}

/// One collision element's contribution.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PartReport {
    /// 1-based collision index in the link.
    pub collision: usize,
    /// `box 0.1 0.2 0.3`, or the mesh URI.
    pub what: String,
    pub file: Option<PathBuf>,
    /// A primitive, or the mesh rung that produced the solid.
    pub provenance: Provenance,
    /// Warnings and notes about this part (mesh health, its reader, its size).
    pub diagnostics: Vec<Diagnostic>,
    pub faces: usize,
    pub volume: f64,
    pub mass: f64,
    pub density: f64,
    /// Where the density came from (`[meshes] "*battery*"`, `[links] base_link`, `default`, …).
    pub density_source: String,
    pub error_estimate: f64,
    /// What the error estimate is made of (round-off, model error and its source).
    pub error: ErrorEstimate,
    /// Relative precision of the input's coordinates: 2⁻²⁴ for a mesh stored in f32 (binary STL,
    /// glTF), 0 for one whose corners are known to every f64 bit (a primitive, most text formats).
    pub input_precision: f64,
}

/// A link whose inertial was computed.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct LinkReport {
    /// Index into `Robot::links`.
    pub index: usize,
    pub name: String,
    pub line: usize,
    pub computed: MassProperties,
    pub parts: Vec<PartReport>,
    /// Estimated volume counted more than once by overlapping parts (m³: their volumes less their
    /// union's), which parts, and the sampling grid size.
    pub overlap: Option<(f64, String, usize)>,
    /// Diagonal of the link's collision geometry's bounding box (link frame), m.
    pub size: f64,
    /// Warnings and notes about the link as a whole (overlapping parts, an overridden mass rule).
    pub diagnostics: Vec<Diagnostic>,
}

impl PartReport {
    /// The warnings (printed always).
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| d.is_warning())
    }

    /// The notes (printed with `--verbose`).
    pub fn notes(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| !d.is_warning())
    }
}

impl LinkReport {
    /// The link's relative error bound: the largest of its parts' (the round-off floor at least).
    pub fn error_estimate(&self) -> f64 {
        self.parts
            .iter()
            .map(|p| p.error_estimate)
            .fold(ROUND_OFF_FLOOR, f64::max)
    }

    /// What the splice writes for this link.
    pub fn update(&self) -> crate::urdf::write::LinkUpdate {
        crate::urdf::write::LinkUpdate {
            index: self.index,
            props: self.computed,
            error: self.error_estimate(),
            input_precision: self
                .parts
                .iter()
                .map(|p| p.input_precision)
                .fold(0.0, f64::max),
            size: self.size,
        }
    }
}

/// Wall time per stage.
#[derive(Debug, Clone, Copy, Default)]
#[non_exhaustive]
pub struct Timing {
    pub load: Duration,
    pub integrate: Duration,
}

impl FillReport {
    /// Links that failed plus robot-wide errors: nonzero means the run failed.
    pub fn error_count(&self) -> usize {
        self.failures.len() + self.robot_errors.len()
    }
}

/// Everything `fill`, `diff` and `check` need to report.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct FillReport {
    pub links: Vec<LinkReport>,
    /// Links that could not be computed.
    pub failures: Vec<LinkError>,
    /// What stopped the robot as a whole (no density for some links, an unreachable `total_mass`).
    pub robot_errors: Vec<RobotError>,
    /// Links with no collision geometry (left as they are).
    pub without_geometry: usize,
    /// Links not selected (--only/--skip/--missing-only).
    pub not_selected: usize,
    /// Distinct mesh files the selected links use (read by this call, or before it with a shared
    /// cache).
    pub mesh_files: usize,
    pub faces: usize,
    pub timing: Timing,
}

/// Whether `fill` computes this link (it must also have collision geometry): selected by the globs and,
/// with `--missing-only`, lacking a valid inertial.
fn is_target(link: &Link, opts: &FillOptions) -> bool {
    selected(&link.name, opts)
        && !(opts.missing_only && crate::problem::link_problems(link).is_empty())
}

/// The `--only` and `--skip` patterns that match none of `names` (the links of every robot of a
/// run): a typo there fills or skips nothing without a word otherwise.
pub fn unused_selection<'o>(opts: &'o FillOptions, names: &[&str]) -> (Vec<&'o str>, Vec<&'o str>) {
    let unused = |globs: &'o [crate::density::Glob]| {
        globs
            .iter()
            .filter(|g| !names.iter().any(|n| g.is_match(n)))
            .map(crate::density::Glob::as_str)
            .collect()
    };
    (unused(&opts.only), unused(&opts.skip))
}

/// Every collision mesh of the selected links whose path resolves to no file, as the error `fill`
/// would give: a stat, no reading (what `check` does without densities).
pub fn unresolved_meshes(
    robot: &Robot,
    resolver: &PackageResolver,
    opts: &FillOptions,
) -> Vec<LinkError> {
    let mut out = Vec::new();
    for link in robot.links.iter().filter(|l| selected(&l.name, opts)) {
        for c in &link.collisions {
            if let Geometry::Mesh { filename, .. } = &c.geometry {
                if let Err(nf) = resolver.resolve(filename, &robot.path) {
                    let kind = LinkErrorKind::MeshNotFound {
                        uri: nf.uri,
                        searched: nf.searched,
                        hint: nf.hint,
                    };
                    out.push(link_error(link, c, kind));
                }
            }
        }
    }
    out
}

/// Whether a link is selected by `--only` / `--skip` globs.
pub fn selected(name: &str, opts: &FillOptions) -> bool {
    let only = opts.only.is_empty() || opts.only.iter().any(|g| g.is_match(name));
    only && !opts.skip.iter().any(|g| g.is_match(name))
}

/// An existing inertial as mass properties in link coordinates (tensor rotated out of its origin frame).
pub fn existing_props(inertial: &Inertial) -> Option<MassProperties> {
    let mass = inertial.mass?;
    let i = inertial.inertia?;
    let local = [[i[0], i[1], i[2]], [i[1], i[3], i[4]], [i[2], i[4], i[5]]];
    let r = rpy_matrix(inertial.origin.rpy);
    let mp = MassProperties {
        mass,
        com: [0.0; 3],
        inertia: local,
    };
    Some(mp.transformed(&r, inertial.origin.xyz))
}

/// One collision, resolved and integrated at density 1, in the link frame.
struct Part {
    collision: usize,
    what: String,
    file: Option<PathBuf>,
    uri: Option<String>,
    unit: MassProperties,
    provenance: Provenance,
    diagnostics: Vec<Diagnostic>,
    faces: usize,
    error_estimate: f64,
    error: ErrorEstimate,
    /// Relative precision of the input's coordinates ([`input_precision`]).
    input_precision: f64,
    /// The solid in the link frame (for bounding boxes and the overlap estimate).
    placed: PlacedPart,
}

fn transformed_bbox(
    points: impl Iterator<Item = [f64; 3]>,
    r: &crate::mass::Mat3,
    t: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        let q = mat_vec(r, p);
        for k in 0..3 {
            lo[k] = lo[k].min(q[k] + t[k]);
            hi[k] = hi[k].max(q[k] + t[k]);
        }
    }
    (lo, hi)
}

fn box_corners(h: [f64; 3]) -> impl Iterator<Item = [f64; 3]> {
    (0..8).map(move |i| {
        [
            if i & 1 == 0 { -h[0] } else { h[0] },
            if i & 2 == 0 { -h[1] } else { h[1] },
            if i & 4 == 0 { -h[2] } else { h[2] },
        ]
    })
}

/// Diagonal of a bounding box.
fn diagonal(lo: [f64; 3], hi: [f64; 3]) -> f64 {
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Where the link's failures point: the link and one of its collisions.
fn link_error(link: &Link, c: &Collision, kind: LinkErrorKind) -> LinkError {
    LinkError {
        link: link.name.clone(),
        line: link.line,
        collision: Some(CollisionRef {
            index: c.index,
            line: c.line,
        }),
        kind: Box::new(kind),
    }
}

/// Where a part's diagnostics point.
fn part_location(link: &Link, c: &Collision) -> Location {
    Location {
        file: None,
        line: Some(c.line),
        link: Some(link.name.clone()),
        collision: Some(c.index),
    }
}

/// A primitive collision: exact formulas.
fn primitive_part(c: &Collision, what: String, unit: MassProperties, shape: PartShape) -> Part {
    let r = rpy_matrix(c.origin.rpy);
    let t = c.origin.xyz;
    let half = match &shape {
        PartShape::Box(h) => *h,
        PartShape::Cylinder(radius, half) => [*radius, *radius, *half],
        PartShape::Capsule(radius, half) => [*radius, *radius, half + radius],
        PartShape::Sphere(radius) => [*radius; 3],
        PartShape::Mesh(_) => [0.0; 3],
    };
    Part {
        collision: c.index,
        what,
        file: None,
        uri: None,
        unit: unit.transformed(&r, t),
        provenance: Provenance::Primitive,
        diagnostics: Vec::new(),
        faces: 0,
        error_estimate: PRIMITIVE_ERROR.total(),
        error: PRIMITIVE_ERROR,
        input_precision: 0.0,
        placed: PlacedPart {
            shape,
            rotation: r,
            translation: t,
            bbox: transformed_bbox(box_corners(half), &r, t),
            volume: unit.mass,
            locator: None,
        },
    }
}

/// The message for a mesh so large it was likely exported in millimetres (its corners `vertices`,
/// already scaled by `scale`), if it is: a link's error by default, a warning with
/// `--allow-large-parts`, and `mesh`'s warning.
pub fn millimetre_slip(vertices: &[[f64; 3]], scale: [f64; 3]) -> Option<String> {
    let (lo, hi) = vertices.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                [0, 1, 2].map(|k| lo[k].min(p[k])),
                [0, 1, 2].map(|k| hi[k].max(p[k])),
            )
        },
    );
    let extent = diagonal(lo, hi);
    if extent <= MILLIMETRE_SLIP {
        return None;
    }
    let s = if scale == [1.0; 3] {
        String::new()
    } else {
        format!(" (after scale {} {} {})", scale[0], scale[1], scale[2])
    };
    Some(format!(
        "the mesh is {extent:.1} m across{s}: if it was exported in millimetres, give it scale=\"0.001 0.001 0.001\""
    ))
}

/// The unit round-off of f32 (2⁻²⁴): how well a corner stored as an f32 is known, relative to
/// itself.
const F32_UNIT_ROUNDOFF: f64 = 1.0 / 16_777_216.0;

/// The relative precision of a mesh's corners (`vertices`, already multiplied by `scale`): 2⁻²⁴ when
/// every coordinate is an f32 times its axis's scale and some show f32 noise (the file stored f32:
/// binary STL, most glTF), else 0 (known to every f64 bit, as far as the tool can tell: integer or
/// dyadic corners, in any format, are exact). Written numbers are rounded within it, so an f32
/// corner of 0.02 writes as 0.02, not 0.0199999995529652.
fn input_precision(vertices: &[[f64; 3]], scale: [f64; 3]) -> f64 {
    // One multiplication rounded in f64: dividing by the scale recovers the f32 to within an f64
    // ulp, which the f32 cast removes, and multiplying again gives the same f64.
    #[allow(clippy::cast_possible_truncation)] // The point: whether the value survives f32.
    let as_f32 = |x: f64, s: f64| {
        let v = (x / s) as f32;
        (s != 0.0 && f64::from(v) * s == x).then_some(v)
    };
    // Noise: the f32's shortest decimal is shorter than the same value's as an f64 (0.02 against
    // 0.019999999552965164). Looked for in the first corners only: the noise of f32 data shows at
    // once, and a mesh without any is treated as exact (what it was before this check).
    let noisy = |v: f32| v.to_string().len() < f64::from(v).to_string().len();
    let mut noise = false;
    for (i, p) in vertices.iter().enumerate() {
        for k in 0..3 {
            let Some(v) = as_f32(p[k], scale[k]) else {
                return 0.0;
            };
            noise = noise || (i < 10_000 && noisy(v));
        }
    }
    if noise {
        F32_UNIT_ROUNDOFF
    } else {
        0.0
    }
}

/// A mesh collision: resolved, read, healed and integrated (through the cache).
fn mesh_part(
    link: &Link,
    c: &Collision,
    (filename, scale): (&str, [f64; 3]),
    ctx: &Context<'_>,
    solids: &Solids<'_>,
) -> Result<Part, LinkError> {
    let path = ctx
        .resolver
        .resolve(filename, &ctx.robot.path)
        .map_err(|nf| {
            let kind = LinkErrorKind::MeshNotFound {
                uri: nf.uri,
                searched: nf.searched,
                hint: nf.hint,
            };
            link_error(link, c, kind)
        })?;
    let solid = solids
        .get(&path, scale)
        .map_err(|e| link_error(link, c, LinkErrorKind::Mesh(e)))?;
    let mut diagnostics = diagnostic::mesh_health(&solid);
    if let Some(m) = millimetre_slip(&solid.vertices, scale) {
        if !ctx.opts.allow_large_parts {
            // 10⁹ times the mass, written without a word but a warning, is worse than no value.
            return Err(link_error(link, c, LinkErrorKind::PartTooLarge(m)));
        }
        diagnostics.push(Diagnostic::new(Code::MeshTooLarge, m));
    }
    for d in &mut diagnostics {
        d.location = Some(part_location(link, c));
    }
    let r = rpy_matrix(c.origin.rpy);
    let t = c.origin.xyz;
    Ok(Part {
        collision: c.index,
        what: filename.to_string(),
        file: Some(path),
        uri: Some(filename.to_string()),
        unit: solid.unit.transformed(&r, t),
        provenance: Provenance::Mesh(solid.rung.clone()),
        diagnostics,
        faces: solid.faces_read,
        error_estimate: solid.error_estimate,
        error: solid.error,
        input_precision: input_precision(&solid.vertices, scale),
        placed: PlacedPart {
            bbox: transformed_bbox(solid.vertices.iter().copied(), &r, t),
            volume: solid.unit.mass,
            shape: PartShape::Mesh(solid),
            rotation: r,
            translation: t,
            locator: None,
        },
    })
}

/// One collision as a part, or the link's error.
fn geometry_part(
    link: &Link,
    c: &Collision,
    ctx: &Context<'_>,
    solids: &Solids<'_>,
) -> Result<Part, LinkError> {
    let fmt3 = |v: [f64; 3]| format!("{} {} {}", v[0], v[1], v[2]);
    Ok(match &c.geometry {
        Geometry::Invalid { line, message } => {
            let kind = LinkErrorKind::InvalidGeometry {
                line: *line,
                message: message.clone(),
            };
            return Err(link_error(link, c, kind));
        }
        Geometry::Box { size } => primitive_part(
            c,
            format!("box {}", fmt3(*size)),
            primitives::cuboid(*size, 1.0),
            PartShape::Box(size.map(|s| s / 2.0)),
        ),
        Geometry::Cylinder { radius, length } => primitive_part(
            c,
            format!("cylinder r={radius} l={length}"),
            primitives::cylinder(*radius, *length, 1.0),
            PartShape::Cylinder(*radius, length / 2.0),
        ),
        Geometry::Capsule { radius, length } => primitive_part(
            c,
            format!("capsule r={radius} l={length}"),
            primitives::capsule(*radius, *length, 1.0),
            PartShape::Capsule(*radius, length / 2.0),
        ),
        Geometry::Sphere { radius } => primitive_part(
            c,
            format!("sphere r={radius}"),
            primitives::sphere(*radius, 1.0),
            PartShape::Sphere(*radius),
        ),
        Geometry::Mesh { filename, scale } => mesh_part(link, c, (filename, *scale), ctx, solids)?,
    })
}

/// What every stage of a robot's computation reads.
struct Context<'a> {
    robot: &'a Robot,
    map: &'a DensityMap,
    resolver: &'a PackageResolver,
    opts: &'a FillOptions,
}

/// Computes every selected link with collision geometry.
pub fn compute(
    robot: &Robot,
    map: &DensityMap,
    resolver: &PackageResolver,
    opts: &FillOptions,
) -> FillReport {
    compute_with(robot, map, resolver, opts, &mut MeshCache::default())
}

/// [`compute`] with a mesh cache shared across calls (several URDFs of one robot, or a whole corpus).
/// The report's timings are this call's share (a mesh read before is not read again); its file count is
/// the distinct mesh files the robot uses.
///
/// The stages: preload the meshes → each link's parts → their densities → the link's body → the
/// overlap estimate → `total_mass` scaling → the overflow backstop.
pub fn compute_with(
    robot: &Robot,
    map: &DensityMap,
    resolver: &PackageResolver,
    opts: &FillOptions,
    cache: &mut MeshCache,
) -> FillReport {
    let (load0, integrate0) = (cache.load_time, cache.integrate_time);
    let ctx = Context {
        robot,
        map,
        resolver,
        opts,
    };
    let mut report = FillReport::default();
    let (mesh_files, results) = compute_links(&ctx, cache, &mut report);
    let mut missing_density: Vec<(String, usize)> = Vec::new();
    // Links whose mass follows from densities (scaled by total_mass), as indices into report.links.
    let mut density_links: Vec<usize> = Vec::new();
    for (link, result) in results {
        match result {
            Ok(Some((l, density_based))) => {
                if density_based {
                    density_links.push(report.links.len());
                }
                report.faces += l.faces;
                report.links.push(l.report);
            }
            Ok(None) => missing_density.push((link.name.clone(), link.line)),
            Err(e) => report.failures.push(e),
        }
    }
    if !missing_density.is_empty() {
        report.robot_errors.push(RobotError::MissingDensity {
            links: missing_density,
        });
    }
    if let Some(total) = map.total_mass {
        scale_to_total_mass(&mut report, &density_links, total);
    }
    reject_unrepresentable(&mut report);
    report.mesh_files = mesh_files;
    // The cache's clocks only accumulate, so these never saturate.
    report.timing = Timing {
        load: cache.load_time.saturating_sub(load0),
        integrate: cache.integrate_time.saturating_sub(integrate0),
    };
    report
}

/// A link's result: computed (with whether its mass follows from densities alone), without a density
/// (`None`), or failed.
type LinkResult = Result<Option<(ComputedLink, bool)>, LinkError>;

/// Every selected link computed, in link order, and the number of distinct mesh files they use (read
/// now or before); counts the links left alone into `report`. The meshes are read and healed in
/// parallel, largest first, and each link is computed (its parts, densities, body and overlap
/// estimate) as soon as its meshes are healed, on the same threads: a link waits only for its own
/// meshes. A path that does not resolve is the link's error.
fn compute_links<'r>(
    ctx: &Context<'r>,
    cache: &mut MeshCache,
    report: &mut FillReport,
) -> (usize, Vec<(&'r Link, LinkResult)>) {
    let (robot, map, opts) = (ctx.robot, ctx.map, ctx.opts);
    let mut targets = Vec::new();
    for (li, link) in robot.links.iter().enumerate() {
        // Links without collision geometry, or whose only parts are zero-size primitives, are left as
        // they are (the scan notes the latter).
        if !link.has_collision_geometry() {
            report.without_geometry += 1;
            continue;
        }
        if !is_target(link, opts) {
            report.not_selected += 1;
            continue;
        }
        targets.push((li, link));
    }
    let needs: Vec<Vec<(PathBuf, [f64; 3])>> = targets
        .iter()
        .map(|(_, link)| {
            link.collisions
                .iter()
                .filter_map(|c| match &c.geometry {
                    Geometry::Mesh { filename, scale } => ctx
                        .resolver
                        .resolve(filename, &robot.path)
                        .ok()
                        .map(|p| (p, *scale)),
                    _ => None,
                })
                .collect()
        })
        .collect();
    let files: std::collections::HashSet<&PathBuf> = needs.iter().flatten().map(|n| &n.0).collect();
    let mesh_files = files.len();
    let health = HealthOptions {
        strict: opts.strict,
        open_mesh: opts.open_mesh,
    };
    let results = cache.load_and_run(&needs, health, |t, solids| {
        let (li, link) = targets[t];
        link_parts(link, ctx, solids)
            .and_then(|(parts, flat)| compute_link(li, link, parts, flat, map, opts))
    });
    let links = targets.iter().map(|(_, link)| *link).zip(results).collect();
    (mesh_files, links)
}

/// A computed link and its face count.
struct ComputedLink {
    report: LinkReport,
    faces: usize,
}

/// A link's parts (its collisions but the zero-size ones), or the first that fails; with the notes
/// of the meshes that enclose no volume (a flat plate, a two-sided sheet), which contribute nothing
/// as a zero-size primitive does (UI203). A link left with no part fails with the first such mesh's
/// error: it has nothing to compute from.
fn link_parts(
    link: &Link,
    ctx: &Context<'_>,
    solids: &Solids<'_>,
) -> Result<(Vec<Part>, Vec<Diagnostic>), LinkError> {
    let mut parts = Vec::new();
    let mut flat = Vec::new();
    let mut first_flat = None;
    for c in link
        .collisions
        .iter()
        .filter(|c| !c.geometry.is_zero_size())
    {
        match geometry_part(link, c, ctx, solids) {
            Ok(p) => parts.push(p),
            Err(e) => {
                let Some((path, volume, bbox)) = is_flat(&e) else {
                    return Err(e);
                };
                let message = format!(
                    "collision {}: {} encloses no volume ({} m³ against a bounding box of {} m³: a flat plate or a two-sided sheet); it contributes nothing, as a zero-size shape does",
                    c.index,
                    crate::text::escape_control(&path),
                    crate::text::significant(volume, 4),
                    crate::text::significant(bbox, 4)
                );
                let note = Diagnostic::new(Code::UrdfZeroVolume, message);
                flat.push(note.at(part_location(link, c)));
                first_flat.get_or_insert(e);
            }
        }
    }
    match first_flat {
        Some(e) if parts.is_empty() => Err(e),
        _ => Ok((parts, flat)),
    }
}

/// The mesh (its path, volume and bounding-box volume) when a part failed only because its mesh
/// encloses no volume (not because it is beyond f64's range: that is another error).
fn is_flat(e: &LinkError) -> Option<(String, f64, f64)> {
    match &*e.kind {
        LinkErrorKind::Mesh(m) => match m.kind {
            crate::mesh::MeshErrorKind::ZeroVolume {
                volume,
                bbox_volume,
            } => Some((m.path.display().to_string(), volume, bbox_volume)),
            _ => None,
        },
        _ => None,
    }
}

/// One link: its parts, their densities, the body, the overlap estimate. `Ok(None)` when the link has
/// no density from anywhere (reported for all such links at once); the flag says whether the link's
/// mass follows from densities alone (what `total_mass` scales).
fn compute_link(
    index: usize,
    link: &Link,
    mut parts: Vec<Part>,
    flat: Vec<Diagnostic>,
    map: &DensityMap,
    opts: &FillOptions,
) -> LinkResult {
    let Some(densities) = densities(link, &parts, map, opts)? else {
        return Ok(None);
    };
    let (computed, part_reports) = body(&parts, &densities);
    let size = parts.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                [0, 1, 2].map(|k| lo[k].min(p.placed.bbox.0[k])),
                [0, 1, 2].map(|k| hi[k].max(p.placed.bbox.1[k])),
            )
        },
    );
    let size = diagonal(size.0, size.1);
    let mut diagnostics = densities.diagnostics;
    if link.from_visual {
        diagnostics.push(Diagnostic::new(
            Code::VisualGeometryUsed,
            "computed from its visual geometry (it has no collision geometry; --geometry collision,visual)",
        ));
    }
    let (overlap, message) = overlap_estimate(&mut parts);
    if let Some(message) = message {
        diagnostics.push(Diagnostic::new(Code::PartsOverlap, message));
    }
    for d in &mut diagnostics {
        d.location = Some(Location {
            line: Some(link.line),
            link: Some(link.name.clone()),
            ..Location::default()
        });
    }
    diagnostics.extend(flat);
    let density_based = matches!(densities.link_spec, Some((_, Spec::Density(_))))
        && densities.own.iter().all(Option::is_none);
    let report = LinkReport {
        index,
        name: link.name.clone(),
        line: link.line,
        computed,
        parts: part_reports,
        overlap,
        size,
        diagnostics,
    };
    let faces = parts.iter().map(|p| p.faces).sum();
    Ok(Some((ComputedLink { report, faces }, density_based)))
}

/// A rule and where it came from (`[links] "arm_*"`, `default`, …).
type Rule = (String, Spec);

/// The densities of a link's parts: each part's own `[meshes]` rule, else the link's rule, and the
/// density the parts without their own rule share.
struct Densities {
    own: Vec<Option<Rule>>,
    link_spec: Option<Rule>,
    shared: f64,
    diagnostics: Vec<Diagnostic>,
}

/// The link's rule: its kept mass (`--keep-mass`), a `[links]` rule, or the default. A `<mass>`
/// that `--keep-mass` cannot keep (`1,5`, `nan`, `-0`, `0`) is an error naming its line: replacing
/// it with the density's mass would drop the number the user asked to keep without a word.
fn link_rule(link: &Link, map: &DensityMap, opts: &FillOptions) -> Result<Option<Rule>, LinkError> {
    let kept = match link.inertial.as_ref().filter(|_| opts.keep_mass) {
        Some(span) => match (span.mass_line, span.value.mass) {
            (Some(_), Some(m)) if m > 0.0 && m.is_finite() => Some(m),
            (Some(line), value) => {
                let value = match value {
                    Some(m) => format!("value=\"{m}\""),
                    None => span
                        .problem
                        .as_deref()
                        .and_then(|p| p.split_once("<mass>: "))
                        .map_or_else(|| "its value".into(), |(_, m)| m.to_string()),
                };
                return Err(LinkError {
                    link: link.name.clone(),
                    line: link.line,
                    collision: None,
                    kind: Box::new(LinkErrorKind::KeptMassInvalid { line, value }),
                });
            }
            (None, _) => None,
        },
        None => None,
    };
    Ok(match kept {
        Some(m) => Some(("existing <mass> (--keep-mass)".into(), Spec::Mass(m))),
        None => map
            .link_rule(&link.name)
            .map(|(k, s)| (format!("[links] \"{k}\""), s))
            .or_else(|| map.default.map(|d| ("default".into(), Spec::Density(d)))),
    })
}

/// Densities for a link's parts; `Ok(None)` when a part needs the link's rule and there is none.
fn densities(
    link: &Link,
    parts: &[Part],
    map: &DensityMap,
    opts: &FillOptions,
) -> Result<Option<Densities>, LinkError> {
    let own: Vec<Option<Rule>> = parts
        .iter()
        .map(|p| {
            p.uri
                .as_deref()
                .and_then(|u| map.mesh_rule(u))
                .map(|(k, s)| (format!("[meshes] \"{k}\""), s))
        })
        .collect();
    let link_spec = link_rule(link, map, opts)?;
    if link_spec.is_none() && own.iter().any(Option::is_none) {
        return Ok(None);
    }
    let own_mass: f64 = parts
        .iter()
        .zip(&own)
        .map(|(p, o)| match o {
            Some((_, Spec::Density(d))) => p.unit.mass * d,
            Some((_, Spec::Mass(m))) => *m,
            None => 0.0,
        })
        .sum();
    let other_volume: f64 = parts
        .iter()
        .zip(&own)
        .filter(|(_, o)| o.is_none())
        .map(|(p, _)| p.unit.mass)
        .sum();
    let mut diagnostics = Vec::new();
    let shared = match &link_spec {
        Some((_, Spec::Density(d))) => *d,
        Some((source, Spec::Mass(m))) if other_volume > 0.0 => {
            let d = (m - own_mass) / other_volume;
            if d.is_nan() || d <= 0.0 {
                let kind = LinkErrorKind::MassTarget {
                    source: source.clone(),
                    mass: *m,
                    own_mass,
                };
                return Err(LinkError {
                    link: link.name.clone(),
                    line: link.line,
                    collision: None,
                    kind: Box::new(kind),
                });
            }
            d
        }
        Some((source, Spec::Mass(m))) => {
            if (m - own_mass).abs() > 1e-9 * m {
                diagnostics.push(Diagnostic::new(Code::DensityRuleOverridden, format!("{source} asks for {m} kg, but every part has its own rule ({own_mass} kg); the parts' rules win")));
            }
            0.0
        }
        None => 0.0,
    };
    Ok(Some(Densities {
        own,
        link_spec,
        shared,
        diagnostics,
    }))
}

/// The link's body (the parts at their densities, summed) and each part's report.
fn body(parts: &[Part], d: &Densities) -> (MassProperties, Vec<PartReport>) {
    let mut reports = Vec::new();
    let mut bodies = Vec::new();
    for (p, o) in parts.iter().zip(&d.own) {
        let (density, source) = match o {
            Some((src, Spec::Density(rho))) => (*rho, src.clone()),
            Some((src, Spec::Mass(m))) => (m / p.unit.mass, src.clone()),
            None => (
                d.shared,
                d.link_spec
                    .as_ref()
                    .map(|l| l.0.clone())
                    .unwrap_or_default(),
            ),
        };
        let body = p.unit.scaled(density);
        bodies.push(body);
        reports.push(PartReport {
            collision: p.collision,
            what: p.what.clone(),
            file: p.file.clone(),
            provenance: p.provenance.clone(),
            diagnostics: p.diagnostics.clone(),
            faces: p.faces,
            volume: p.unit.mass,
            mass: body.mass,
            density,
            density_source: source,
            error_estimate: p.error_estimate,
            error: p.error,
            input_precision: p.input_precision,
        });
    }
    (bodies.into_iter().sum(), reports)
}

/// Scales the density-based links so that the filled links weigh `total` kg, or reports why not.
fn scale_to_total_mass(report: &mut FillReport, density_links: &[usize], total: f64) {
    let variable: f64 = density_links
        .iter()
        .map(|&i| report.links[i].computed.mass)
        .sum();
    let fixed: f64 = report.links.iter().map(|l| l.computed.mass).sum::<f64>() - variable;
    if !(variable > 0.0 && total > fixed) {
        report.robot_errors.push(RobotError::TotalMass {
            total,
            fixed,
            variable,
        });
        return;
    }
    let factor = (total - fixed) / variable;
    for &i in density_links {
        let l = &mut report.links[i];
        l.computed = l.computed.scaled(factor);
        for p in &mut l.parts {
            p.mass *= factor;
            p.density *= factor;
            p.density_source =
                format!("{} × {factor:.6} (total_mass {total} kg)", p.density_source);
        }
    }
}

/// Why computed mass properties cannot be written, if they cannot: every check of
/// [`validity::check`], plus finite principal axes (what `--principal` writes).
pub fn unrepresentable(mp: &MassProperties) -> Option<String> {
    let mut problems: Vec<String> = validity::check(mp, validity::DEFAULT_TOLERANCE)
        .iter()
        .map(ToString::to_string)
        .collect();
    let largest_moment = (0..3).fold(0.0f64, |a, k| a.max(mp.inertia[k][k].abs()));
    if problems.is_empty() && (mp.mass < f64::MIN_POSITIVE || largest_moment < f64::MIN_POSITIVE) {
        // Subnormal: representable, but with most of its digits gone.
        problems.push(format!(
            "mass {:e} kg and largest moment {largest_moment:e} kg·m² are below the smallest normal f64 ({:e})",
            mp.mass,
            f64::MIN_POSITIVE
        ));
    }
    if problems.is_empty() {
        let p = mp.principal();
        if !p
            .moments
            .iter()
            .chain(p.axes.iter().flatten())
            .all(|x| x.is_finite())
        {
            problems.push("its principal axes are not finite".into());
        }
    }
    (!problems.is_empty()).then(|| {
        format!(
            "overflow/underflow: the computed inertial is not usable ({}); sizes, positions, scales or densities this large or small are beyond f64",
            problems.join("; ")
        )
    })
}

/// The backstop after composition: a link whose values overflowed or underflowed (mass `inf`, a NaN,
/// an all-zero tensor) becomes that link's failure instead of being written.
fn reject_unrepresentable(report: &mut FillReport) {
    let links = std::mem::take(&mut report.links);
    for l in links {
        match unrepresentable(&l.computed) {
            None => report.links.push(l),
            Some(message) => report.failures.push(LinkError {
                link: l.name,
                line: l.line,
                collision: None,
                kind: Box::new(LinkErrorKind::Unrepresentable(message)),
            }),
        }
    }
}

/// The volume the link's parts count more than once (their volumes less their union's, estimated by
/// [`overlap::estimate`]), which parts and the grid, with the warning that says so; or only a warning
/// when the estimate was skipped.
fn overlap_estimate(parts: &mut [Part]) -> (Option<(f64, String, usize)>, Option<String>) {
    let mut placed: Vec<PlacedPart> = parts.iter().map(|p| p.placed.clone()).collect();
    let e = match crate::threads::install(|| overlap::estimate(&mut placed)) {
        Overlap::None => return (None, None),
        Overlap::Skipped(why) => {
            return (
                None,
                Some(format!("the overlap of the parts was not estimated ({why}): any volume they share is counted more than once")),
            )
        }
        Overlap::Estimated(e) => e,
    };
    let names: Vec<String> = e
        .parts
        .iter()
        .map(|&i| parts[i].collision.to_string())
        .collect();
    let which = match names.len() {
        0..=6 => match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => names.join(""),
        },
        n => format!("{} and {} others", names[..5].join(", "), n - 5),
    };
    let total: f64 = parts.iter().map(|p| p.unit.mass).sum();
    let (v, n) = (e.excess, e.grid);
    let how = if e.most <= 2 {
        "is counted twice".to_string()
    } else {
        format!("is counted more than once (up to {} times)", e.most)
    };
    let capped = if e.capped {
        format!(
            " (coarser than {g}³: the work cap for this many overlapping parts; the bound widens with the grid)",
            g = overlap::GRID
        )
    } else {
        String::new()
    };
    let message = format!(
        "parts {which} overlap: about {} m³ ({:.1}% of the link's volume) {how}; the parts' volumes less their union's, estimated on a {n}³ grid per part{capped}, within ±{} m³",
        crate::text::significant(v, 4),
        100.0 * v / total,
        crate::text::significant(e.bound, 2),
    );
    (Some((v, which, n)), Some(message))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_corners_are_known_to_f32_precision_only_when_they_show_it() {
        let f = |x: f32| f64::from(x);
        // f32 noise (0.02 stored as f32): 2⁻²⁴.
        let wedge = [
            [0.0, 0.0, 0.0],
            [f(0.06), 0.0, f(0.04)],
            [0.0, f(0.03), 0.0],
        ];
        assert_eq!(input_precision(&wedge, [1.0; 3]), 1.0 / 16_777_216.0);
        // The same through a scale: each coordinate an f32 times the scale, rounded once.
        let s = [0.001, -0.001, 0.001];
        let scaled = wedge.map(|p| [p[0] * s[0], p[1] * s[1], p[2] * s[2]]);
        assert_eq!(input_precision(&scaled, s), 1.0 / 16_777_216.0);
        // Integer or dyadic corners (an OBJ's `v 1 0 0`) are exact in any format.
        let tet = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.5, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert_eq!(input_precision(&tet, [1.0; 3]), 0.0);
        // f64 decimals (text formats): not f32 values, exact as far as the tool can tell.
        let text = [[0.02, 0.0, 0.0], [0.0, 0.03, 0.0]];
        assert_eq!(input_precision(&text, [1.0; 3]), 0.0);
    }
}
