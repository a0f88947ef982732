//! The reports of the commands as data: what `urdf-inertia fill`, `diff`, `check` and `mesh` print
//! with `--format json`, one type per document ([`FillOutput`], [`DiffOutput`], [`CheckOutput`],
//! [`MeshOutput`]), each carrying [`SCHEMA_VERSION`].
//!
//! Every link is reported with one record, [`LinkRecord`], whichever command reports it; each fills
//! in what it knows: `fill` and `diff` the computed values with their parts, the existing values and
//! the comparison; `diff` and `check` whether and how the link differs beyond the tolerance; `check`
//! the problems. The JSON Schemas in the repository's docs/schema/ are generated from these types
//! (feature `json-schema`; the workspace's tests/schema.rs).
//!
//! A number that is not finite has no JSON form: `serde_json` writes it as `null`, and the schema
//! allows `null` where a value can be one (an error estimate that is unbounded, values an existing
//! `<inertial>` gives as `nan`).

use crate::compare::{compare, Difference};
use crate::diagnostic::{Code, Diagnostic, LinkError, Provenance, RobotError, Severity};
use crate::fill::{existing_props, LinkReport, PartReport};
use crate::mass::validity::Violation;
use crate::mass::{MassProperties, Mat3};
use crate::problem::{InertialProblem, ProblemKind};
use crate::text::{self, Digits};
use crate::urdf::write::{tidy, tidy_moments, LinkUpdate};
use crate::urdf::Robot;
use serde::Serialize;

/// The version of the JSON documents' shape, `"schema_version"` in each: raised when a key is
/// removed, renamed or changes its meaning (a new key does not raise it).
pub const SCHEMA_VERSION: u32 = 1;

/// Mass properties as reported: kg, the centre of mass in the link frame (m), the tensor about the
/// centre of mass in the link frame's axes (kg·m²), the principal moments ascending.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct Props {
    /// kg (`null` if not finite: an existing value only).
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub mass: f64,
    /// m.
    #[cfg_attr(feature = "json-schema", schemars(with = "[Option<f64>; 3]"))]
    pub center_of_mass: [f64; 3],
    /// kg·m², rows.
    #[cfg_attr(feature = "json-schema", schemars(with = "[[Option<f64>; 3]; 3]"))]
    pub inertia: Mat3,
    /// kg·m², ascending.
    #[cfg_attr(feature = "json-schema", schemars(with = "[Option<f64>; 3]"))]
    pub principal_moments: [f64; 3],
}

impl Props {
    /// A link's computed values rounded as the file is written with `digits` (within the update's
    /// error bound), the principal moments of the unrounded tensor to the same precision.
    fn rounded(update: &LinkUpdate, digits: Digits) -> Props {
        let mp = tidy(update, digits);
        Props {
            mass: mp.mass,
            center_of_mass: mp.com,
            inertia: mp.inertia,
            principal_moments: tidy_moments(update.props.principal().moments, update.error, digits),
        }
    }

    /// Existing values, every digit kept.
    fn existing(mp: &MassProperties) -> Props {
        let mp_full = tidy(&(0, *mp).into(), Digits::Full);
        Props {
            mass: mp_full.mass,
            center_of_mass: mp_full.com,
            inertia: mp_full.inertia,
            principal_moments: tidy_moments(mp.principal().moments, 0.0, Digits::Auto),
        }
    }
}

/// Existing values against computed ones (both about their centre of mass).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct ComparisonRecord {
    /// Existing mass over computed mass.
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub mass_ratio: f64,
    /// Distance of the centres of mass over the link's size.
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub com_distance_relative: f64,
    /// Frobenius norm of the tensor difference over the computed tensor's.
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub inertia_difference_relative: f64,
    /// Likely causes of a difference (unit slips, tensor about the link origin, mirrored products).
    pub causes: Vec<String>,
    /// Why the existing values cannot belong to a body, if they cannot.
    pub invalid: Vec<Violation>,
}

/// One problem `check` found in a link's existing `<inertial>`: its code, its message, its kind with
/// the values that make it a problem (`kind` and the kind's own keys).
///
/// Its schema leaves other keys open: the kind's keys come from a flattened enum, which
/// `additionalProperties: false` beside it would refuse.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
pub struct ProblemRecord {
    pub code: Code,
    /// The text for people, without the location.
    pub message: String,
    /// The 1-based line of the problem in the URDF: the `<inertial>`, or the `<link>` when it has
    /// none.
    pub line: usize,
    // The doc is the JSON Schema's description (docs/schema/), generated as it is written.
    #[allow(clippy::doc_markdown)]
    /// Where `check` prints it: `FILE:LINE: link `NAME`` (for a xacro source, the file and line
    /// where the link is written).
    pub at: String,
    #[serde(flatten)]
    pub kind: ProblemKind,
}

impl ProblemRecord {
    /// A problem and where it is printed.
    pub fn new(problem: &InertialProblem, at: impl Into<String>) -> ProblemRecord {
        ProblemRecord {
            code: problem.code(),
            message: problem.kind.to_string(),
            line: problem.line,
            at: at.into(),
            kind: problem.kind.clone(),
        }
    }
}

/// One collision element's contribution to its link.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct PartRecord {
    /// 1-based collision index in the link.
    pub collision: usize,
    /// `box 0.1 0.2 0.3`, or the mesh URI.
    pub geometry: String,
    /// The mesh file read (`null` for a primitive).
    pub file: Option<String>,
    pub provenance: Provenance,
    pub faces: usize,
    /// m³.
    pub volume: f64,
    /// kg.
    pub mass: f64,
    /// kg/m³.
    pub density: f64,
    /// Where the density came from (`[meshes] "*battery*"`, `[links] base_link`, `default`, …).
    pub density_source: String,
    /// Relative bound on volume and inertia: round-off plus model error (`null`: unbounded).
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub error_estimate: f64,
    pub error_round_off: f64,
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub error_model: f64,
    /// What the model error is made of: `none`, `cracks`, `orientation`, `caps`, `convex hull`,
    /// `overlapping shells`.
    pub error_model_source: String,
    /// Bound on the centre of mass's error, m.
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub error_center_of_mass: f64,
    pub warnings: Vec<Diagnostic>,
    pub notes: Vec<Diagnostic>,
}

impl From<&PartReport> for PartRecord {
    fn from(p: &PartReport) -> PartRecord {
        PartRecord {
            collision: p.collision,
            geometry: p.what.clone(),
            file: p.file.as_ref().map(|f| f.display().to_string()),
            provenance: p.provenance.clone(),
            faces: p.faces,
            volume: text::within(p.volume, p.error_estimate * p.volume),
            mass: text::within(p.mass, p.error_estimate * p.mass),
            density: p.density,
            density_source: p.density_source.clone(),
            error_estimate: p.error_estimate,
            error_round_off: p.error.round_off,
            error_model: p.error.model,
            error_model_source: p.error.source.name().to_string(),
            error_center_of_mass: p.error.com,
            warnings: p.warnings().cloned().collect(),
            notes: p.notes().cloned().collect(),
        }
    }
}

/// One link, as every command reports it; each fills in what it knows and leaves the rest `null` or
/// empty.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct LinkRecord {
    /// The link's name.
    pub link: String,
    /// The URDF (or xacro source) the link is in.
    pub urdf: String,
    /// The 1-based line of the `<link>` (of the expanded text for a xacro source).
    pub line: usize,
    /// The computed values, rounded as `fill` writes them (`null` where nothing was computed:
    /// `check` without densities, a link without collision geometry).
    pub computed: Option<Props>,
    /// The diagonal of the bounding box of the link's collision geometry, m (with `computed`).
    pub size: Option<f64>,
    /// The link's relative error bound: the largest of its parts' (with `computed`; also `null`
    /// when unbounded).
    pub error_estimate: Option<f64>,
    /// The values of the link's existing `<inertial>`, every digit (`null`: none, or not readable).
    pub existing: Option<Props>,
    /// Existing against computed (when both are there).
    pub comparison: Option<ComparisonRecord>,
    /// Whether `fill` would change the link beyond the tolerance, or its existing values are
    /// invalid or missing (`diff`, `check`; `null` for `fill`, which has no tolerance).
    pub differs: Option<bool>,
    /// What differs beyond the tolerance (`diff`, `check`).
    pub differences: Vec<Difference>,
    /// The problems of the existing `<inertial>` (`check`: the ones that fail the run).
    pub problems: Vec<ProblemRecord>,
    /// The link's own warnings (overlapping parts, an overridden mass rule); a part's are its own.
    pub warnings: Vec<Diagnostic>,
    pub notes: Vec<Diagnostic>,
    /// The collision elements computed, in order.
    pub parts: Vec<PartRecord>,
}

impl LinkRecord {
    /// Link `index` of `robot` as read: its name, file, line and existing values; with `computed`
    /// (its [`LinkReport`]) the computed values rounded as `digits` writes them, its parts and
    /// diagnostics and the comparison; with a `tolerance` too, whether and how it differs.
    ///
    /// # Panics
    ///
    /// If `index` is not a link of `robot`.
    pub fn new(
        robot: &Robot,
        index: usize,
        computed: Option<&LinkReport>,
        digits: Digits,
        tolerance: Option<f64>,
    ) -> LinkRecord {
        let link = &robot.links[index];
        let existing = link
            .inertial
            .as_ref()
            .and_then(|s| existing_props(&s.value));
        let mut record = LinkRecord {
            link: link.name.clone(),
            urdf: robot.path.display().to_string(),
            line: link.line,
            computed: None,
            size: None,
            error_estimate: None,
            existing: existing.as_ref().map(Props::existing),
            comparison: None,
            differs: None,
            differences: Vec::new(),
            problems: Vec::new(),
            warnings: Vec::new(),
            notes: Vec::new(),
            parts: Vec::new(),
        };
        let Some(l) = computed else {
            return record;
        };
        let update = l.update();
        record.computed = Some(Props::rounded(&update, digits));
        record.size = Some(l.size);
        record.error_estimate = Some(l.error_estimate());
        record.warnings = of_severity(&l.diagnostics, true);
        record.notes = of_severity(&l.diagnostics, false);
        record.parts = l.parts.iter().map(PartRecord::from).collect();
        let c = existing
            .as_ref()
            .map(|e| (e, compare(e, &l.computed, l.size)));
        if let Some(tolerance) = tolerance {
            record.differs = Some(c.as_ref().is_none_or(|(_, c)| c.differs(tolerance)));
            if let Some((e, c)) = &c {
                record.differences = c.beyond(e, &l.computed, tolerance);
            }
        }
        record.comparison = c.map(|(_, c)| ComparisonRecord {
            mass_ratio: c.mass_ratio,
            com_distance_relative: c.com_distance,
            inertia_difference_relative: c.inertia_difference,
            causes: c.causes,
            invalid: c.invalid,
        });
        record
    }
}

/// The warnings (`true`: what is not a note, so warnings made errors too) or the notes (`false`).
fn of_severity(ds: &[Diagnostic], warning: bool) -> Vec<Diagnostic> {
    ds.iter()
        .filter(|d| (d.severity != Severity::Note) == warning)
        .cloned()
        .collect()
}

/// Why a link, or the robot as a whole, could not be computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct ErrorRecord {
    /// The link (`null`: the robot as a whole).
    pub link: Option<String>,
    /// The line of the `<link>`.
    pub line: Option<usize>,
    /// The collision at fault, where one is.
    pub collision: Option<usize>,
    /// A short stable name: `invalid-geometry`, `mesh-not-found`, `mesh`, `open-mesh`,
    /// `mass-target`, `unrepresentable`, `invalid-kept-mass`, `part-too-large`, `missing-density`,
    /// `total-mass`.
    pub kind: String,
    pub code: Code,
    pub message: String,
}

impl From<&LinkError> for ErrorRecord {
    fn from(f: &LinkError) -> ErrorRecord {
        ErrorRecord {
            link: Some(f.link.clone()),
            line: Some(f.line),
            collision: f.collision.map(|c| c.index),
            kind: f.kind.name().to_string(),
            code: f.kind.code(),
            message: f.to_string(),
        }
    }
}

impl From<&RobotError> for ErrorRecord {
    fn from(e: &RobotError) -> ErrorRecord {
        ErrorRecord {
            link: None,
            line: None,
            collision: None,
            kind: e.name().to_string(),
            code: e.code(),
            message: e.to_string(),
        }
    }
}

/// A (link, collision) that uses a mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct MeshUser {
    pub link: String,
    pub collision: usize,
}

/// One diagnostic of a mesh file, once, with every (link, collision) that uses the mesh.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct MeshDiagnostic {
    /// The URI as the first user wrote it.
    pub mesh: String,
    pub file: Option<String>,
    pub provenance: Provenance,
    pub severity: Severity,
    pub code: Code,
    pub message: String,
    pub links: Vec<MeshUser>,
}

/// The robot's mass after the run and the run's worst error bound.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct Totals {
    /// kg: the computed links and the others' existing `<mass>` (`null` if not finite: a link left
    /// as it is says `nan`).
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub total_mass: f64,
    /// kg: the computed links.
    pub total_mass_computed: f64,
    /// kg: the links left as they are that carry a `<mass>` (`null` if not finite).
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub total_mass_as_they_are: f64,
    /// The largest relative error of the run: a part's bound, or the volume overlapping parts count
    /// more than once (`null`: nothing computed, or unbounded).
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub worst_error_estimate: Option<f64>,
}

/// `urdf-inertia fill --format json` (on stdout when the URDF goes to a file).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct FillOutput {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    pub urdf: String,
    /// The robot's name.
    pub robot: String,
    /// Whether the URDF was written: false when links failed without `--keep-going`, or a warning
    /// was made an error (the run then exits 2).
    pub written: bool,
    pub links_filled: usize,
    pub links_without_geometry: usize,
    pub links_not_selected: usize,
    pub mesh_files: usize,
    pub faces: usize,
    pub errors: Vec<ErrorRecord>,
    /// The robot's own diagnostics and the run's (a robot without a name, links not written).
    pub notes: Vec<Diagnostic>,
    pub mesh_diagnostics: Vec<MeshDiagnostic>,
    #[serde(flatten)]
    pub totals: Totals,
    /// Wall time of the run, s.
    pub seconds: f64,
    /// CPU time over all cores reading meshes, s.
    pub seconds_load: f64,
    /// CPU time over all cores healing and integrating, s.
    pub seconds_integrate: f64,
    /// The computed links.
    pub links: Vec<LinkRecord>,
}

/// `urdf-inertia diff --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct DiffOutput {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    pub urdf: String,
    pub robot: String,
    /// `--tolerance`: the relative difference beyond which a link differs.
    pub tolerance: f64,
    /// The computed links.
    pub links: Vec<LinkRecord>,
    pub mesh_diagnostics: Vec<MeshDiagnostic>,
    #[serde(flatten)]
    pub totals: Totals,
}

/// `urdf-inertia check --format json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct CheckOutput {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    /// The links with problems that fail the run (not those recorded in a baseline), in the order
    /// they were found, each with its problems.
    pub links: Vec<LinkRecord>,
    /// How many problems the links carry.
    pub problem_count: usize,
    /// Problems recorded in the baseline (`--baseline`): found, but not failing the run.
    pub known_in_baseline: usize,
    /// How many errors (links that could not be computed, files that could not be read) the run
    /// had; they are printed on stderr.
    pub errors: usize,
}

/// `urdf-inertia mesh --format json`: one mesh file's solid and its mass properties.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct MeshOutput {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    pub file: String,
    pub scale: [f64; 3],
    /// m³.
    pub volume: f64,
    /// kg/m³.
    pub density: f64,
    /// kg.
    pub mass: f64,
    /// m, in the mesh's axes.
    pub center_of_mass: [f64; 3],
    /// kg·m² about the centre of mass, in the mesh's axes (rows).
    pub inertia: Mat3,
    /// kg·m², ascending.
    pub principal_moments: [f64; 3],
    /// The principal axes, one unit vector each, in the order of the moments.
    pub principal_axes: [[f64; 3]; 3],
    /// The rung of the repair ladder that produced the solid.
    pub provenance: Provenance,
    /// Faces of the solid integrated.
    pub faces: usize,
    /// Faces in the file.
    pub faces_read: usize,
    pub vertices: usize,
    /// Relative bound on volume and central inertia (`null`: unbounded).
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub error_estimate: f64,
    pub error_round_off: f64,
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub error_model: f64,
    pub error_model_source: String,
    #[cfg_attr(feature = "json-schema", schemars(with = "Option<f64>"))]
    pub error_center_of_mass: f64,
    /// Diagnostics made errors (`--warn-as-error`), warnings, notes.
    pub errors: Vec<Diagnostic>,
    pub warnings: Vec<Diagnostic>,
    pub notes: Vec<Diagnostic>,
}

/// `urdf-inertia mesh --format json` when the file gives no solid (unreadable, malformed, an open
/// mesh whose caps cannot be trusted, a mass past f64): the file and why, so that a program reading
/// the output always gets a document (the command exits 2).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct MeshFailure {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    pub file: String,
    pub scale: [f64; 3],
    pub error: MeshErrorRecord,
}

/// Why a mesh gave no solid.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "json-schema", schemars(deny_unknown_fields))]
pub struct MeshErrorRecord {
    /// `mesh` (unreadable or no solid), `open-mesh` (an open mesh whose caps cannot be trusted:
    /// `--open-mesh caps|hull` chooses a model), `unrepresentable` (a mass or inertia past f64).
    pub kind: String,
    pub code: Code,
    pub message: String,
}

impl MeshErrorRecord {
    /// The record of a mesh that did not load.
    pub fn from_mesh_error(e: &crate::mesh::MeshError) -> MeshErrorRecord {
        let open = matches!(e.kind, crate::mesh::MeshErrorKind::NoSolid(_));
        MeshErrorRecord {
            kind: if open { "open-mesh" } else { "mesh" }.to_string(),
            code: if open {
                Code::MeshNoSolid
            } else {
                Code::ErrorMesh
            },
            message: e.to_string(),
        }
    }

    /// The record of mass properties past f64 (`why`, from [`crate::unrepresentable`]).
    pub fn unrepresentable(why: &str) -> MeshErrorRecord {
        MeshErrorRecord {
            kind: "unrepresentable".to_string(),
            code: Code::ErrorUnrepresentable,
            message: why.to_string(),
        }
    }
}

/// What `mesh --format json` prints: the solid's mass properties, or why there is none.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[serde(untagged)]
#[allow(clippy::large_enum_variant)] // Printed once per run.
pub enum MeshDocument {
    Solid(MeshOutput),
    Failure(MeshFailure),
}

/// The JSON Schemas of the four documents, by command (`fill`, `diff`, `check`, `mesh`), as
/// docs/schema/COMMAND.schema.json holds them.
#[cfg(feature = "json-schema")]
pub fn schemas() -> Vec<(&'static str, serde_json::Value)> {
    // Generated for JSON Schema 2020-12 (schemars' default), the `$id` naming the command.
    fn one<T: schemars::JsonSchema>(id: &str) -> serde_json::Value {
        let mut s = schemars::schema_for!(T).to_value();
        if let Some(o) = s.as_object_mut() {
            o.insert("$id".into(), serde_json::Value::String(id.into()));
        }
        s
    }
    vec![
        ("fill", one::<FillOutput>("urdf-inertia/fill.schema.json")),
        ("diff", one::<DiffOutput>("urdf-inertia/diff.schema.json")),
        (
            "check",
            one::<CheckOutput>("urdf-inertia/check.schema.json"),
        ),
        ("mesh", one::<MeshDocument>("urdf-inertia/mesh.schema.json")),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::urdf::{Collision, Geometry, Inertial, Link, Pose};
    use crate::{compute, DensityMap, FillOptions, PackageResolver};

    /// A 0.1 × 0.2 × 0.3 m aluminium box (16.2 kg) whose `<inertial>` says `said` kg.
    fn record(said: Option<f64>, tolerance: Option<f64>) -> LinkRecord {
        let part = Collision::new(
            Geometry::Box {
                size: [0.1, 0.2, 0.3],
            },
            Pose::default(),
        );
        let mut link = Link::new("forearm", vec![part]);
        if let Some(m) = said {
            let i = [
                0.1755 * m / 16.2,
                0.0,
                0.0,
                0.135 * m / 16.2,
                0.0,
                0.0675 * m / 16.2,
            ];
            link = link.with_inertial(Inertial::new(Pose::default(), m, i));
        }
        let robot = Robot::new("arm", vec![link]);
        let report = compute(
            &robot,
            &DensityMap::uniform(2700.0),
            &PackageResolver::new(),
            &FillOptions::default(),
        );
        LinkRecord::new(&robot, 0, report.links.first(), Digits::Auto, tolerance)
    }

    #[test]
    fn a_link_record_holds_what_each_command_knows() {
        // `fill`: computed, existing, comparison; no tolerance, so no verdict.
        let r = record(Some(1.62), None);
        assert_eq!(r.computed.as_ref().map(|c| c.mass), Some(16.2));
        assert_eq!(r.existing.as_ref().map(|e| e.mass), Some(1.62));
        let ratio = r.comparison.as_ref().map_or(0.0, |c| c.mass_ratio);
        assert!((ratio - 0.1).abs() < 1e-12, "{ratio}");
        assert_eq!(r.differs, None);
        assert!(r.differences.is_empty());
        assert_eq!(r.parts.len(), 1);
        // `diff`: the verdict and what differs; the tensor is the same shape, scaled with the mass.
        let r = record(Some(1.62), Some(0.05));
        assert_eq!(r.differs, Some(true));
        assert!(matches!(r.differences[0], Difference::Mass { .. }));
        // A link without `<inertial>` differs, with nothing to compare.
        let r = record(None, Some(0.05));
        assert_eq!(r.differs, Some(true));
        assert!(r.existing.is_none() && r.comparison.is_none());
        // The same values: nothing differs.
        let r = record(Some(16.2), Some(0.05));
        assert_eq!(r.differs, Some(false), "{r:?}");
    }
}
