//! Per-link composition (the paper's Problem 1): each link's collision parts, each with a density or a
//! mass, as one body in the link frame.
//!
//! Work a robot does not need is left out: only links with collision geometry (and selected by
//! `--only/--skip/--missing-only`) are computed, visual meshes are never read, each mesh file is read
//! once and each (file, scale) healed and integrated once.

use crate::density::{DensityMap, Spec};
use crate::diagnostic::{
    Code, Diagnostic, LinkError, LinkErrorKind, Location, Provenance, RobotError,
};
use crate::geometry::Aabb;
use crate::mass::{validity, MassProperties};
pub use crate::mesh::cache::MeshCache;
use crate::mesh::cache::Solids;
use crate::mesh::health::{ErrorEstimate, HealthOptions, ROUND_OFF_FLOOR};
use crate::overlap::{self, Overlap, PlacedPart};
use crate::urdf::resolve::{NotFound, PackageResolver};
use crate::urdf::{Geometry, Link, Robot};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Duration;

mod capsules;
mod densities;
mod parts;
mod select;

use densities::{body, densities, scale_to_total_mass};
pub use parts::millimetre_slip;
pub(crate) use parts::slip_message;
use parts::{geometry_part, part_location, Part};
use select::is_target;
pub use select::{existing_props, selected, unresolved_meshes, unused_selection};

/// What to compute.
// Independent switches, one per command-line flag; no two of them form a state machine.
#[allow(clippy::struct_excessive_bools)]
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
    /// The volume its overlapping parts count more than once, when they overlap.
    pub overlap: Option<LinkOverlap>,
    /// Diagonal of the link's collision geometry's bounding box (link frame), m.
    pub size: f64,
    /// Warnings and notes about the link as a whole (overlapping parts, an overridden mass rule).
    pub diagnostics: Vec<Diagnostic>,
}

/// The volume a link's overlapping parts count more than once (UI401).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct LinkOverlap {
    /// Estimated volume counted more than once (m³: the parts' volumes less their union's).
    pub excess: f64,
    /// Which parts, as the warning names them (`1 and 2`, `1, 2, 3, 4, 5 and 195 others`).
    pub parts: String,
    /// The sampling grid's cells per side, per part.
    pub grid: usize,
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
    /// Links with no collision geometry (left as they are), counting those whose every part is a mesh
    /// that encloses no volume.
    pub without_geometry: usize,
    /// One warning (UI109) per link left as it is because every part of it is a mesh that encloses
    /// no volume (a flat plate, a two-sided sheet).
    pub no_volume: Vec<Diagnostic>,
    /// Links not selected (--only/--skip/--missing-only).
    pub not_selected: usize,
    /// Distinct mesh files the selected links use (read by this call, or before it with a shared
    /// cache).
    pub mesh_files: usize,
    pub faces: usize,
    pub timing: Timing,
}

/// What every stage of a robot's computation reads.
struct Context<'a> {
    robot: &'a Robot,
    map: &'a DensityMap,
    resolver: &'a PackageResolver,
    opts: &'a FillOptions,
    /// Each mesh URI of the selected links, resolved once (a URI several links or collisions use is
    /// looked up once; the stage that loads the meshes and the one that builds the parts share it).
    resolved: HashMap<&'a str, Result<PathBuf, NotFound>>,
}

/// [`Context::resolved`]: every mesh URI of `targets` (the links to compute), resolved.
fn resolve_meshes<'a>(
    robot: &Robot,
    resolver: &PackageResolver,
    targets: &[(usize, &'a Link)],
) -> HashMap<&'a str, Result<PathBuf, NotFound>> {
    let mut resolved = HashMap::new();
    for c in targets.iter().flat_map(|(_, l)| &l.collisions) {
        if let Geometry::Mesh { filename, .. } = &c.geometry {
            (resolved.entry(filename.as_str()))
                .or_insert_with(|| resolver.resolve(filename, &robot.path));
        }
    }
    resolved
}

/// The links to compute, with their indices; counts the links left alone into `report`: those
/// without collision geometry, or whose only parts are zero-size primitives (the scan notes the
/// latter), and those not selected.
fn targets<'r>(robot: &'r Robot, opts: &FillOptions, report: &mut FillReport) -> Vec<(usize, &'r Link)> {
    let mut targets = Vec::new();
    for (li, link) in robot.links.iter().enumerate() {
        if !link.has_collision_geometry() {
            report.without_geometry += 1;
        } else if !is_target(link, opts) {
            report.not_selected += 1;
        } else {
            targets.push((li, link));
        }
    }
    targets
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
    let mut report = FillReport::default();
    let targets = targets(robot, opts, &mut report);
    let ctx = Context {
        robot,
        map,
        resolver,
        opts,
        resolved: resolve_meshes(robot, resolver, &targets),
    };
    let (mesh_files, results) = compute_links(&ctx, &targets, cache);
    let mut missing_density: Vec<(String, usize)> = Vec::new();
    // Links whose mass follows from densities (scaled by total_mass), as indices into report.links.
    let mut density_links: Vec<usize> = Vec::new();
    for (link, result) in results {
        match result {
            Ok(LinkOutcome::Computed(l, density_based)) => {
                if density_based {
                    density_links.push(report.links.len());
                }
                report.faces += l.faces;
                report.links.push(l.report);
            }
            Ok(LinkOutcome::NoDensity) => missing_density.push((link.name.clone(), link.line)),
            Ok(LinkOutcome::NoVolume(d)) => {
                report.without_geometry += 1;
                report.no_volume.push(d);
            }
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

/// A link's result: computed (with whether its mass follows from densities alone), without a density,
/// left as it is because none of its parts has a volume, or failed.
type LinkResult = Result<LinkOutcome, LinkError>;

/// What became of a link that did not fail.
enum LinkOutcome {
    /// Computed, and whether its mass follows from densities alone (what `total_mass` scales).
    Computed(ComputedLink, bool),
    /// No density from anywhere (reported for all such links at once).
    NoDensity,
    /// Every part a mesh that encloses no volume: left as it is, like a link whose parts are all
    /// zero-size primitives, with this warning (UI109).
    NoVolume(Diagnostic),
}

/// Every link of `targets` computed, in link order, and the number of distinct mesh files they use
/// (read now or before). The meshes are read and healed in
/// parallel, largest first, and each link is computed (its parts, densities, body and overlap
/// estimate) as soon as its meshes are healed, on the same threads: a link waits only for its own
/// meshes. A path that does not resolve is the link's error.
fn compute_links<'r>(
    ctx: &Context<'r>,
    targets: &[(usize, &'r Link)],
    cache: &mut MeshCache,
) -> (usize, Vec<(&'r Link, LinkResult)>) {
    let (map, opts) = (ctx.map, ctx.opts);
    let needs: Vec<Vec<(PathBuf, [f64; 3])>> = targets
        .iter()
        .map(|(_, link)| {
            link.collisions
                .iter()
                .filter_map(|c| match &c.geometry {
                    Geometry::Mesh { filename, scale } => match ctx.resolved.get(filename.as_str()) {
                        Some(Ok(p)) => Some((p.clone(), *scale)),
                        _ => None,
                    },
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
        link_parts(link, ctx, solids).and_then(|(parts, flat)| {
            if parts.is_empty() {
                Ok(LinkOutcome::NoVolume(no_volume(link, &flat)))
            } else {
                compute_link(li, link, parts, flat, map, opts)
            }
        })
    });
    let links = targets.iter().map(|(_, link)| *link).zip(results).collect();
    (mesh_files, links)
}

/// A computed link and its face count.
struct ComputedLink {
    report: LinkReport,
    faces: usize,
}

/// A link's parts (its collisions but the zero-size ones), or the first that fails; with a warning
/// (UI109) for each mesh that encloses no volume (a flat plate, a two-sided sheet), which contributes
/// nothing as a zero-size primitive does. The parts are empty when every collision is such a mesh.
fn link_parts(
    link: &Link,
    ctx: &Context<'_>,
    solids: &Solids<'_>,
) -> Result<(Vec<Part>, Vec<Diagnostic>), LinkError> {
    let mut parts = Vec::new();
    let mut flat = Vec::new();
    for c in link
        .collisions
        .iter()
        .filter(|c| !c.geometry.is_zero_size())
    {
        match geometry_part(link, c, ctx, solids) {
            Ok(p) => parts.push(p),
            Err(e) => {
                let Some((path, volume, bbox, two_sided)) = is_flat(&e) else {
                    return Err(e);
                };
                let message = if two_sided {
                    format!(
                        "collision {}: {} encloses no volume (every face is stored twice, once each way: a double-sided export, whose two sides cancel); it contributes nothing, as a zero-size shape does; if it stands for a solid, export it single-sided",
                        c.index,
                        crate::text::escape_control(&path),
                    )
                } else {
                    format!(
                        "collision {}: {} encloses no volume ({} m³ against a bounding box of {} m³: a flat plate or a two-sided sheet); it contributes nothing, as a zero-size shape does",
                        c.index,
                        crate::text::escape_control(&path),
                        crate::text::significant(volume, 4),
                        crate::text::significant(bbox, 4)
                    )
                };
                let warning = Diagnostic::new(Code::MeshNoVolume, message);
                flat.push(warning.at(part_location(link, c)));
            }
        }
    }
    Ok((parts, flat))
}

/// The warning of a link whose every part encloses no volume: it is left as it is, as a link whose
/// parts are all zero-size primitives is (the scan's UI203).
fn no_volume(link: &Link, flat: &[Diagnostic]) -> Diagnostic {
    let parts: Vec<&str> = flat.iter().map(|d| d.message.as_str()).collect();
    Diagnostic::new(
        Code::MeshNoVolume,
        format!(
            "its collision geometry has no volume ({}): the link is left as it is, like a link without collision geometry",
            parts.join("; ")
        ),
    )
    .at(Location {
        line: Some(link.line),
        link: Some(link.name.clone()),
        ..Location::default()
    })
}

/// The mesh (its path, volume, bounding-box volume and whether it is stored double-sided) when a
/// part failed only because its mesh encloses no volume (not because it is beyond f64's range: that
/// is another error).
fn is_flat(e: &LinkError) -> Option<(String, f64, f64, bool)> {
    match &*e.kind {
        LinkErrorKind::Mesh(m) => match m.kind {
            crate::mesh::MeshErrorKind::ZeroVolume {
                volume,
                bbox_volume,
            } => Some((m.path.display().to_string(), volume, bbox_volume, m.is_two_sided())),
            _ => None,
        },
        _ => None,
    }
}

/// One link: its parts, their densities, the body, the overlap estimate. `NoDensity` when the link has
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
    // Before the densities: a link mass target is spread over the union.
    let (capsules, nearly) = capsules::join(&mut parts);
    let Some(densities) = densities(link, &parts, map, opts)? else {
        return Ok(LinkOutcome::NoDensity);
    };
    let (computed, part_reports) = body(&parts, &densities);
    let size = (parts.iter())
        .fold(Aabb::EMPTY, |b, p| b.union(p.placed.bbox))
        .diagonal();
    let mut diagnostics = densities.diagnostics;
    if link.from_visual {
        diagnostics.push(Diagnostic::new(
            Code::VisualGeometryUsed,
            "computed from its visual geometry (it has no collision geometry; --geometry collision,visual)",
        ));
    }
    for cap in &capsules {
        let [a, b, c] = collisions(&parts, [cap.cylinder, cap.spheres[0], cap.spheres[1]]);
        diagnostics.push(Diagnostic::new(
            Code::PartsCapsule,
            format!("collisions {a}, {b} and {c} are a capsule (a cylinder with a sphere of its radius centred on each end): counted as their union, each sphere's half inside the cylinder once"),
        ));
    }
    let (overlap, message) = overlap_estimate(&parts, (&capsules, &nearly));
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
    Ok(LinkOutcome::Computed(
        ComputedLink { report, faces },
        density_based,
    ))
}

/// Why computed mass properties cannot be written, if they cannot: every check of
/// `validity::check`, plus finite principal axes (what `--principal` writes). The message names the
/// cause: values beyond f64 (not finite, or a mass or moment near the ends of its range), or else a
/// geometry that is no solid of positive density (gymnasium-robotics' `stoverim.stl`, an open ring
/// under `--open-mesh caps`: its caps count part of it negatively, and its principal moments break
/// the triangle inequality by 0.33%; that is no overflow).
pub fn unrepresentable(mp: &MassProperties) -> Option<String> {
    let beyond_f64 = |why: &str| {
        format!(
            "overflow/underflow: the computed inertial is not usable ({why}); sizes, positions, scales or densities this large or small are beyond f64"
        )
    };
    let violations = validity::check(mp, validity::DEFAULT_TOLERANCE);
    let largest_moment = (0..3).fold(0.0f64, |a, k| a.max(mp.inertia[k][k].abs()));
    if violations.is_empty() {
        if mp.mass < f64::MIN_POSITIVE || largest_moment < f64::MIN_POSITIVE {
            // Subnormal: representable, but with most of its digits gone.
            return Some(beyond_f64(&format!(
                "mass {:e} kg and largest moment {largest_moment:e} kg·m² are below the smallest normal f64 ({:e})",
                mp.mass,
                f64::MIN_POSITIVE
            )));
        }
        let p = mp.principal();
        let finite = p.moments.iter().chain(p.axes.iter().flatten()).all(|x| x.is_finite());
        return (!finite).then(|| beyond_f64("its principal axes are not finite"));
    }
    let problems: Vec<String> = violations.iter().map(ToString::to_string).collect();
    // Far from both ends of f64, the values are what the geometry gives.
    let in_range = |x: f64| (1e-250..=1e250).contains(&x.abs());
    let extreme = violations.contains(&validity::Violation::NotFinite)
        || !in_range(mp.mass)
        || !in_range(largest_moment)
        || mp.com.iter().any(|x| x.abs() > 1e250);
    Some(if extreme {
        beyond_f64(&problems.join("; "))
    } else {
        format!(
            "the computed inertial is no body's ({}): the geometry, as computed, is not a solid of positive density (as where flat caps over an open band or dish count part of it negatively); close the mesh, choose another model for open meshes (`--open-mesh hull`: an upper bound), or give the link a primitive collision shape",
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

/// The collision numbers of three parts, in order.
fn collisions(parts: &[Part], which: [usize; 3]) -> [usize; 3] {
    let mut c = which.map(|i| parts[i].collision);
    c.sort_unstable();
    c
}

/// The volume the link's parts count more than once (their volumes less their union's, estimated by
/// [`overlap::estimate`]), which parts and the grid, with the warning that says so; or only a warning
/// when the estimate was skipped. A capsule's three parts count as one solid, named by its cylinder.
fn overlap_estimate(
    parts: &[Part],
    (capsules, nearly): (&[capsules::Capsule], &[capsules::Nearly]),
) -> (Option<LinkOverlap>, Option<String>) {
    // A capsule's three parts as one solid: their union, which the parts now sum to.
    let (mut placed, index): (Vec<PlacedPart>, Vec<usize>) = capsules::placed(parts, capsules);
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
    // Each capsule's spheres by its cylinder, which names it.
    let mut spheres_of = vec![None; parts.len()];
    for cap in capsules {
        spheres_of[cap.cylinder] = Some(cap.spheres);
    }
    let names: Vec<String> = e
        .parts
        .iter()
        .map(|&i| {
            let c = parts[index[i]].collision;
            match spheres_of[index[i]] {
                Some(spheres) => {
                    let [a, b] = spheres.map(|s| parts[s].collision);
                    format!("{c} (a capsule with {} and {})", a.min(b), a.max(b))
                }
                None => c.to_string(),
            }
        })
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
    // Three parts that are a capsule but for how their numbers were written say so.
    let mut near = String::new();
    for n in nearly {
        let [a, b, c] = collisions(parts, n.parts);
        let _ = write!(
            near,
            "; collisions {a}, {b} and {c} are nearly a capsule: its spheres miss the cylinder's end centres (or radius) by up to {} m (as an rpy of 1.57 for π/2 does); within a billionth of the radius they would count as their union",
            crate::text::significant(n.miss, 2)
        );
    }
    let message = format!(
        "parts {which} overlap: about {} m³ ({:.1}% of the link's volume) {how}; the parts' volumes less their union's, estimated on a {n}³ grid per part{capped}, within ±{} m³{near}",
        crate::text::significant(v, 4),
        100.0 * v / total,
        crate::text::significant(e.bound, 2),
    );
    let overlap = LinkOverlap {
        excess: v,
        parts: which,
        grid: n,
    };
    (Some(overlap), Some(message))
}
