//! Typed diagnostics: the warnings and notes of a run, each with a stable [`Code`], and the errors of
//! one link ([`LinkError`]) or of a whole robot ([`RobotError`]).
//!
//! A warning asks the user to look (a repaired mesh, overlapping parts, an element urdfdom ignores); a
//! note needs no action (a mesh welded within tolerance, a zero-size part). Codes are stable: tools
//! and people match them, never the message text. They are grouped by hundreds: mesh health (1xx),
//! URDF reading (2xx), density (3xx), overlap (4xx), output and run (5xx), problems `check` finds in
//! existing `<inertial>` elements (6xx), errors that fail a link or a robot (7xx). README's
//! "Diagnostics" table lists them.

use crate::mesh::health::{HealthKind, Rung, Solid};
use crate::mesh::{MeshError, MeshErrorKind};
use serde::{Serialize, Serializer};
use std::fmt;
use std::fmt::Write as _;
use std::path::PathBuf;

/// How much a diagnostic matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[non_exhaustive]
pub enum Severity {
    /// Worth knowing, needs no action; printed with `--verbose` or in JSON.
    Note,
    /// The user should look; always printed.
    Warning,
    /// A problem or an error: the run fails (a warning becomes one with `--warn-as-error`).
    Error,
}

impl Severity {
    /// `note` or `warning`.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

impl Serialize for Severity {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// A string naming its values, for the manual `JsonSchema`s of types serialised as names.
#[cfg(feature = "json-schema")]
fn names_schema(description: &str, names: &[&str]) -> schemars::Schema {
    schemars::json_schema!({"type": "string", "description": description, "enum": names})
}

#[cfg(feature = "json-schema")]
impl schemars::JsonSchema for Severity {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Severity".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        names_schema(
            "How much a diagnostic matters.",
            &[Severity::Note, Severity::Warning, Severity::Error].map(Severity::as_str),
        )
    }
}

/// A stable diagnostic code (`UI101`, …); each has one severity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Code {
    /// UI101: a mesh needed a repair below `exact`/`welded` (re-oriented, inverted, capped,
    /// non-manifold, convex hull).
    MeshRepaired,
    /// UI102: degenerate or duplicated faces dropped.
    MeshFacesDropped,
    /// UI103: closed once corners within a tolerance are welded; integrated as stored.
    MeshWelded,
    /// UI104: the mesh reader left something out of the solid (faces it could not use).
    MeshReaderSkipped,
    /// UI105: the mesh reader tolerated something that leaves the solid as the file means it.
    MeshReaderNote,
    /// UI106: a mesh over 10 m across (likely millimetres without `scale`).
    MeshTooLarge,
    /// UI107: faces dropped in pairs, a face and its reverse (they cancel in the integral).
    MeshFacesCancelled,
    /// UI108: an open mesh whose flat caps cannot be trusted, or that encloses no volume however its
    /// holes are closed, and no model for open meshes was chosen (`--open-mesh`): the part fails.
    /// Carried by the link's error ([`LinkErrorKind::code`]).
    MeshNoSolid,
    /// UI109: a collision mesh that encloses no volume however it is closed (a flat plate, a
    /// two-sided sheet): the part contributes nothing; a link with no other part is left as it is.
    MeshNoVolume,
    /// UI201: an element urdfdom ignores (a second `<origin>`, `<geometry>`, shape, `<inertial>`).
    UrdfIgnoredElement,
    /// UI202: a `<collision>` without a shape, ignored.
    UrdfEmptyCollision,
    /// UI203: a zero-size primitive, which contributes nothing.
    UrdfZeroVolume,
    /// UI204: the file uses xacro elements: links inside macros are not seen.
    UrdfXacro,
    /// UI205: the root declares `xmlns:xacro` (xacro's output keeps it).
    UrdfXacroNamespace,
    /// UI206: `<robot>` has no name attribute.
    UrdfNoRobotName,
    /// UI207: an invalid `<inertial>` on a link `fill` cannot compute: without collision geometry, or
    /// whose collision geometry has no volume (`check`).
    UrdfFrameInertial,
    /// UI301: a link's mass target is overridden by its parts' own `[meshes]` rules.
    DensityRuleOverridden,
    /// UI302: a density-map rule that matches no link or mesh of the robots (a typo?), ignored.
    DensityRuleUnused,
    /// UI303: an `--only`/`--skip` pattern that matches no link.
    SelectionUnused,
    /// UI210: no collision geometry in the whole robot (`--geometry collision,visual` offered).
    NoCollisionGeometry,
    /// UI211: a link filled from its visual geometry (`--geometry collision,visual`).
    VisualGeometryUsed,
    /// UI401: parts of a link overlap: their common volume is counted twice.
    PartsOverlap,
    /// UI402: a cylinder and a sphere of its radius on each end, counted as the capsule they make.
    PartsCapsule,
    /// UI501: links that failed were left as they were (`--keep-going`).
    OutputNotWritten,
    /// UI208: a warning of the xacro expansion (an unknown builtin, a deprecated form).
    XacroWarning,
    /// UI209: a xacro file that expands to no links (a file of macros).
    XacroNoLinks,
    /// UI502: a computed link not written into its xacro source (it comes from a macro).
    OutputNotInSource,
    /// UI503: the thread setting was capped or ignored.
    RunThreads,
    /// UI504: the settings of a configuration file (`urdf-inertia.toml`) are in effect.
    RunConfig,
    /// UI601: a link with collision geometry and no `<inertial>` (`check`).
    CheckMissingInertial,
    /// UI602: an invalid `<inertial>` (non-finite, mass <= 0, not positive definite, triangle
    /// inequality, several of them).
    CheckInvalidInertial,
    /// UI603: an existing `<inertial>` off the computed one by more than the tolerance.
    CheckDiffers,
    /// UI701: a collision that cannot be read (unknown shape, bad vector, negative size).
    ErrorInvalidGeometry,
    /// UI702: a mesh URI that resolves to no file.
    ErrorMeshNotFound,
    /// UI703: a mesh that cannot become a solid (unreadable, empty, `--strict` repair).
    ErrorMesh,
    /// UI704: a mass target below what the parts with their own rules weigh.
    ErrorMassTarget,
    /// UI705: values that cannot be written: beyond f64, or no body's (a geometry that is no solid).
    ErrorUnrepresentable,
    /// UI706: `--keep-mass` on a `<mass>` that is no positive number.
    ErrorKeptMass,
    /// UI707: links with collision geometry and no density from anywhere.
    ErrorMissingDensity,
    /// UI708: the density map's `total_mass` cannot be met.
    ErrorTotalMass,
    /// UI710: a part over 10 m across (likely millimetres without `scale`), refused without
    /// `--allow-large-parts`.
    ErrorPartTooLarge,
    /// UI709: a link's values cannot be written validly (`--digits N` rounding broke the tensor).
    ErrorWrite,
}

impl Code {
    /// Every code, in table order.
    pub const ALL: [Code; 42] = [
        Code::MeshRepaired,
        Code::MeshFacesDropped,
        Code::MeshWelded,
        Code::MeshReaderSkipped,
        Code::MeshReaderNote,
        Code::MeshTooLarge,
        Code::MeshFacesCancelled,
        Code::MeshNoSolid,
        Code::MeshNoVolume,
        Code::UrdfIgnoredElement,
        Code::UrdfEmptyCollision,
        Code::UrdfZeroVolume,
        Code::UrdfXacro,
        Code::UrdfXacroNamespace,
        Code::UrdfNoRobotName,
        Code::UrdfFrameInertial,
        Code::XacroWarning,
        Code::XacroNoLinks,
        Code::DensityRuleOverridden,
        Code::DensityRuleUnused,
        Code::SelectionUnused,
        Code::NoCollisionGeometry,
        Code::VisualGeometryUsed,
        Code::PartsOverlap,
        Code::PartsCapsule,
        Code::OutputNotWritten,
        Code::OutputNotInSource,
        Code::RunThreads,
        Code::RunConfig,
        Code::CheckMissingInertial,
        Code::CheckInvalidInertial,
        Code::CheckDiffers,
        Code::ErrorInvalidGeometry,
        Code::ErrorMeshNotFound,
        Code::ErrorMesh,
        Code::ErrorMassTarget,
        Code::ErrorUnrepresentable,
        Code::ErrorKeptMass,
        Code::ErrorMissingDensity,
        Code::ErrorTotalMass,
        Code::ErrorWrite,
        Code::ErrorPartTooLarge,
    ];

    /// The stable code, `UI101` …
    pub fn as_str(self) -> &'static str {
        match self {
            Code::MeshRepaired => "UI101",
            Code::MeshFacesDropped => "UI102",
            Code::MeshWelded => "UI103",
            Code::MeshReaderSkipped => "UI104",
            Code::MeshReaderNote => "UI105",
            Code::MeshTooLarge => "UI106",
            Code::MeshFacesCancelled => "UI107",
            Code::MeshNoSolid => "UI108",
            Code::MeshNoVolume => "UI109",
            Code::UrdfIgnoredElement => "UI201",
            Code::UrdfEmptyCollision => "UI202",
            Code::UrdfZeroVolume => "UI203",
            Code::UrdfXacro => "UI204",
            Code::UrdfXacroNamespace => "UI205",
            Code::UrdfNoRobotName => "UI206",
            Code::UrdfFrameInertial => "UI207",
            Code::DensityRuleOverridden => "UI301",
            Code::DensityRuleUnused => "UI302",
            Code::SelectionUnused => "UI303",
            Code::NoCollisionGeometry => "UI210",
            Code::VisualGeometryUsed => "UI211",
            Code::PartsOverlap => "UI401",
            Code::PartsCapsule => "UI402",
            Code::OutputNotWritten => "UI501",
            Code::XacroWarning => "UI208",
            Code::XacroNoLinks => "UI209",
            Code::OutputNotInSource => "UI502",
            Code::RunThreads => "UI503",
            Code::RunConfig => "UI504",
            Code::CheckMissingInertial => "UI601",
            Code::CheckInvalidInertial => "UI602",
            Code::CheckDiffers => "UI603",
            Code::ErrorInvalidGeometry => "UI701",
            Code::ErrorMeshNotFound => "UI702",
            Code::ErrorMesh => "UI703",
            Code::ErrorMassTarget => "UI704",
            Code::ErrorUnrepresentable => "UI705",
            Code::ErrorKeptMass => "UI706",
            Code::ErrorMissingDensity => "UI707",
            Code::ErrorTotalMass => "UI708",
            Code::ErrorWrite => "UI709",
            Code::ErrorPartTooLarge => "UI710",
        }
    }

    /// The code named `s` (`UI101` or `ui101`), if there is one.
    pub fn parse(s: &str) -> Option<Code> {
        Code::ALL
            .into_iter()
            .find(|c| c.as_str().eq_ignore_ascii_case(s.trim()))
    }

    /// Whether a run can go on past it: warnings and notes, which `--ignore` may silence and
    /// `--warn-as-error` promote, and `check`'s problems (6xx), which `--ignore` may silence; not
    /// the errors (7xx).
    pub fn is_error(self) -> bool {
        // UI108 (an open mesh with no solid to trust) fails its part like the UI7xx errors; its
        // number keeps it beside the other mesh codes.
        self.as_str().starts_with("UI7") || self == Code::MeshNoSolid
    }

    /// The code's severity.
    pub fn severity(self) -> Severity {
        match self {
            Code::MeshWelded
            | Code::MeshReaderNote
            | Code::MeshFacesCancelled
            | Code::UrdfZeroVolume
            | Code::UrdfXacroNamespace
            | Code::UrdfFrameInertial
            | Code::XacroNoLinks
            | Code::PartsCapsule
            | Code::RunConfig => Severity::Note,
            Code::CheckMissingInertial
            | Code::CheckInvalidInertial
            | Code::CheckDiffers
            | Code::ErrorInvalidGeometry
            | Code::ErrorMeshNotFound
            | Code::ErrorMesh
            | Code::ErrorMassTarget
            | Code::ErrorUnrepresentable
            | Code::ErrorKeptMass
            | Code::ErrorMissingDensity
            | Code::ErrorTotalMass
            | Code::ErrorWrite
            | Code::ErrorPartTooLarge
            | Code::MeshNoSolid => Severity::Error,
            _ => Severity::Warning,
        }
    }
}

impl fmt::Display for Code {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Serialize for Code {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

#[cfg(feature = "json-schema")]
impl schemars::JsonSchema for Code {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Code".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        names_schema(
            "A stable diagnostic code (the README's table).",
            &Code::ALL.map(Code::as_str),
        )
    }
}

/// Where a diagnostic points; every part is optional.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[non_exhaustive]
pub struct Location {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// 1-based line in `file` (the URDF, unless a mesh is named).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub link: Option<String>,
    /// 1-based collision index in the link.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collision: Option<usize>,
}

impl Location {
    /// A location in `file` alone (no line, link or collision).
    pub fn in_file(file: impl Into<PathBuf>) -> Location {
        Location {
            file: Some(file.into()),
            ..Location::default()
        }
    }
}

/// One warning or note.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[non_exhaustive]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: Code,
    /// The text for people (stable enough for humans, not for tools: match `code`).
    pub message: String,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub location: Option<Location>,
}

impl Diagnostic {
    /// A diagnostic with the code's severity and no location.
    pub fn new(code: Code, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: code.severity(),
            code,
            message: message.into(),
            location: None,
        }
    }

    /// The same, located.
    #[must_use]
    pub fn at(mut self, location: Location) -> Self {
        self.location = Some(location);
        self
    }

    pub fn is_warning(&self) -> bool {
        self.severity == Severity::Warning
    }

    /// The URDF line, if located on one.
    pub fn line(&self) -> Option<usize> {
        self.location.as_ref().and_then(|l| l.line)
    }

    /// The link, if about one.
    pub fn link(&self) -> Option<&str> {
        self.location.as_ref().and_then(|l| l.link.as_deref())
    }

    /// The prefix compilers print: `warning[UI101]`, `note[UI103]`, `error[UI702]`.
    pub fn head(&self) -> String {
        format!("{}[{}]", self.severity.as_str(), self.code)
    }

    /// `warning[UI101]: PATH:LINE: link `NAME`: MESSAGE` (the parts the location has).
    pub fn render(&self) -> String {
        let mut s = format!("{}: ", self.head());
        if let Some(l) = &self.location {
            if let Some(f) = &l.file {
                s.push_str(&crate::text::escape_control(&f.display().to_string()));
                if let Some(line) = l.line {
                    let _ = write!(s, ":{line}");
                }
                s.push_str(": ");
            }
            if let Some(link) = &l.link {
                let _ = write!(s, "link `{}`: ", crate::text::escape_control(link));
            }
        }
        s.push_str(&self.message);
        s
    }
}

/// What a part's numbers were computed from.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Provenance {
    /// A box, cylinder, sphere or capsule: exact formulas.
    Primitive,
    /// A mesh, with the rung of the health ladder that produced its solid.
    Mesh(Rung),
}

impl Provenance {
    /// `primitive` or the rung's name (`exact`, `welded`, `capped`, …).
    pub fn name(&self) -> &'static str {
        match self {
            Provenance::Primitive => "primitive",
            Provenance::Mesh(r) => r.name(),
        }
    }

    /// Whether the solid was repaired (a rung below exact and welded, which integrate as stored).
    pub fn is_repaired(&self) -> bool {
        matches!(self, Provenance::Mesh(r) if !r.is_as_stored())
    }
}

/// Plain words for people (messages, the summary, `mesh`'s health line); `name()` stays the short key
/// for JSON and tables.
impl fmt::Display for Provenance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Provenance::Primitive => "primitive shape",
            Provenance::Mesh(Rung::Exact) => "closed mesh",
            Provenance::Mesh(Rung::Welded { .. }) => "corners joined",
            Provenance::Mesh(Rung::Reoriented { .. }) => "faces re-oriented",
            Provenance::Mesh(Rung::Inverted) => "inside out",
            Provenance::Mesh(Rung::Capped { .. }) => "holes capped",
            Provenance::Mesh(Rung::NonManifold { .. }) => "non-manifold",
            Provenance::Mesh(Rung::ConvexHull { .. }) => "replaced by its convex hull",
        })
    }
}

impl Serialize for Provenance {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

#[cfg(feature = "json-schema")]
impl schemars::JsonSchema for Provenance {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "Provenance".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        names_schema(
            "What a part's numbers were computed from: a primitive, or the rung of the mesh repair ladder.",
            &crate::mesh::health::Rung::NAMES
                .iter()
                .copied()
                .chain(["primitive"])
                .collect::<Vec<_>>(),
        )
    }
}

/// The diagnostics of a solid's health and of its reader.
///
/// `mesh::health` (owned elsewhere) still says these in strings; they are typed here, at the
/// boundary, by their wording: a reader's warning says what it *skipped*, the ladder's drops say
/// *dropped*, every other warning is the rung's repair; a note about welding is the ladder's, the
/// rest are the reader's. When `Solid` carries codes itself, this becomes a plain copy.
pub fn mesh_health(solid: &Solid) -> Vec<Diagnostic> {
    let code = |kind: HealthKind| match kind {
        HealthKind::Repaired => Code::MeshRepaired,
        HealthKind::FacesDropped => Code::MeshFacesDropped,
        HealthKind::FacesCancelled => Code::MeshFacesCancelled,
        HealthKind::Welded => Code::MeshWelded,
        HealthKind::ReaderSkipped => Code::MeshReaderSkipped,
        HealthKind::ReaderNote => Code::MeshReaderNote,
    };
    solid
        .warnings
        .iter()
        .chain(&solid.notes)
        .map(|m| Diagnostic::new(code(m.kind), m.text.clone()))
        .collect()
}

/// A collision of a link: its 1-based index and line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct CollisionRef {
    pub index: usize,
    pub line: usize,
}

/// Why one link could not be computed (the others still are).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct LinkError {
    pub link: String,
    /// Line of the `<link>`.
    pub line: usize,
    /// The collision at fault, where one is.
    pub collision: Option<CollisionRef>,
    /// Boxed: the error travels through every stage's `Result`.
    pub kind: Box<LinkErrorKind>,
}

/// What went wrong with a link.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum LinkErrorKind {
    /// A collision the scan could not read (unknown shape, bad vector, negative size), at `line`.
    InvalidGeometry { line: usize, message: String },
    /// A mesh URI that resolves to no file.
    MeshNotFound {
        uri: String,
        searched: Vec<PathBuf>,
        hint: String,
    },
    /// A mesh that could not become a solid.
    Mesh(MeshError),
    /// A mass target (`source`: `[links] "x"`, `--keep-mass`) below what the parts with their own
    /// rules already weigh.
    MassTarget {
        source: String,
        mass: f64,
        own_mass: f64,
    },
    /// Values that cannot be written: beyond f64 (overflow or underflow), or no body's; with the reasons.
    Unrepresentable(String),
    /// `--keep-mass` on a `<mass>` (at `line`) that is no positive finite number: `value` as read.
    KeptMassInvalid { line: usize, value: String },
    /// A mesh over 10 m across (likely millimetres without `scale`), without `--allow-large-parts`.
    PartTooLarge(String),
}

impl LinkErrorKind {
    /// A short stable name for JSON: `invalid-geometry`, `mesh-not-found`, `mesh`, `open-mesh`,
    /// `mass-target`, `unrepresentable`, `invalid-kept-mass`.
    pub fn name(&self) -> &'static str {
        match self {
            LinkErrorKind::InvalidGeometry { .. } => "invalid-geometry",
            LinkErrorKind::MeshNotFound { .. } => "mesh-not-found",
            LinkErrorKind::Mesh(e) if matches!(e.kind, MeshErrorKind::NoSolid(_)) => "open-mesh",
            LinkErrorKind::Mesh(_) => "mesh",
            LinkErrorKind::MassTarget { .. } => "mass-target",
            LinkErrorKind::Unrepresentable(_) => "unrepresentable",
            LinkErrorKind::KeptMassInvalid { .. } => "invalid-kept-mass",
            LinkErrorKind::PartTooLarge(_) => "part-too-large",
        }
    }

    /// The stable code (`UI701` …).
    pub fn code(&self) -> Code {
        match self {
            LinkErrorKind::InvalidGeometry { .. } => Code::ErrorInvalidGeometry,
            LinkErrorKind::MeshNotFound { .. } => Code::ErrorMeshNotFound,
            LinkErrorKind::Mesh(e) if matches!(e.kind, MeshErrorKind::NoSolid(_)) => {
                Code::MeshNoSolid
            }
            LinkErrorKind::Mesh(_) => Code::ErrorMesh,
            LinkErrorKind::MassTarget { .. } => Code::ErrorMassTarget,
            LinkErrorKind::Unrepresentable(_) => Code::ErrorUnrepresentable,
            LinkErrorKind::KeptMassInvalid { .. } => Code::ErrorKeptMass,
            LinkErrorKind::PartTooLarge(_) => Code::ErrorPartTooLarge,
        }
    }
}

impl fmt::Display for LinkError {
    /// The message after `link `NAME`: ` (the caller names the file, line and link).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let index = self.collision.map_or(0, |c| c.index);
        let cline = self.collision.map_or(self.line, |c| c.line);
        match &*self.kind {
            LinkErrorKind::InvalidGeometry { line, message } => {
                write!(f, "collision {index} (line {line}): {message}")
            }
            LinkErrorKind::MeshNotFound {
                uri,
                searched,
                hint,
            } => {
                let list: Vec<String> = searched
                    .iter()
                    .map(|p| format!("    {}", crate::text::escape_control(&p.display().to_string())))
                    .collect();
                let uri = crate::text::escape_control(uri);
                let list = if list.is_empty() {
                    "    (nothing)".to_string()
                } else {
                    list.join("\n")
                };
                write!(
                    f,
                    "collision {index} (line {cline}): mesh `{uri}` not found; searched:\n{list}\n  {hint}"
                )
            }
            LinkErrorKind::Mesh(e) => write!(f, "collision {index} (line {cline}): {e}"),
            LinkErrorKind::MassTarget {
                source,
                mass,
                own_mass,
            } => write!(
                f,
                "{source} gives the link {mass} kg, but its parts with their own [meshes] rule already weigh {own_mass} kg"
            ),
            LinkErrorKind::Unrepresentable(m) => f.write_str(m),
            LinkErrorKind::PartTooLarge(m) => write!(
                f,
                "collision {index} (line {cline}): {m} (or pass --allow-large-parts if the part really is that large)"
            ),
            LinkErrorKind::KeptMassInvalid { line, value } => write!(
                f,
                "--keep-mass: <mass> on line {line}: {value} is not a positive number of kilograms; fix the value (a decimal with a point) or drop --keep-mass for this link"
            ),
        }
    }
}

impl std::error::Error for LinkError {}

/// Why the robot as a whole could not be computed (no single link is at fault).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum RobotError {
    /// Links with collision geometry and no density from anywhere: names and lines.
    MissingDensity { links: Vec<(String, usize)> },
    /// The density map's `total_mass` cannot be met by scaling the density-based links.
    TotalMass {
        total: f64,
        fixed: f64,
        variable: f64,
    },
}

impl RobotError {
    /// A short stable name for JSON: `missing-density`, `total-mass`.
    pub fn name(&self) -> &'static str {
        match self {
            RobotError::MissingDensity { .. } => "missing-density",
            RobotError::TotalMass { .. } => "total-mass",
        }
    }

    /// The stable code (`UI707`, `UI708`).
    pub fn code(&self) -> Code {
        match self {
            RobotError::MissingDensity { .. } => Code::ErrorMissingDensity,
            RobotError::TotalMass { .. } => Code::ErrorTotalMass,
        }
    }
}

impl fmt::Display for RobotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RobotError::MissingDensity { links } => {
                let list: Vec<String> = links
                    .iter()
                    .map(|(n, l)| format!("`{}` (line {l})", crate::text::escape_control(n)))
                    .collect();
                write!(
                    f,
                    "no density for {} link(s) with collision geometry: {}; give --density RHO, a `default` in the density map, or a [links] rule",
                    links.len(),
                    list.join(", ")
                )
            }
            RobotError::TotalMass {
                total,
                fixed,
                variable,
            } => write!(
                f,
                "total_mass {total} kg cannot be met: links with fixed masses already weigh {fixed} kg and density-based links {variable} kg"
            ),
        }
    }
}

impl std::error::Error for RobotError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_are_unique_and_grouped() {
        let mut seen = std::collections::HashSet::new();
        for c in Code::ALL {
            let s = c.as_str();
            assert!(seen.insert(s), "{s} twice");
            assert!(s.starts_with("UI") && s.len() == 5, "{s}");
            assert_eq!(Code::parse(&s.to_lowercase()), Some(c));
            assert_eq!(
                c.is_error(),
                c.severity() == Severity::Error && !s.starts_with("UI6")
            );
        }
        assert_eq!(Code::parse("UI999"), None);
    }

    #[test]
    fn rendered_with_the_code_as_compilers_print_it() {
        let d = Diagnostic::new(Code::MeshRepaired, "re-oriented").at(Location {
            file: Some("r.urdf".into()),
            line: Some(3),
            link: Some("arm".into()),
            collision: None,
        });
        assert_eq!(
            d.render(),
            "warning[UI101]: r.urdf:3: link `arm`: re-oriented"
        );
    }

    #[test]
    fn json_carries_severity_code_message_and_location() {
        let d = Diagnostic::new(Code::PartsOverlap, "parts 1 and 2 overlap").at(Location {
            link: Some("arm".into()),
            ..Location::default()
        });
        let v = serde_json::to_value(&d).expect("json");
        assert_eq!(
            v,
            serde_json::json!({"severity": "warning", "code": "UI401", "message": "parts 1 and 2 overlap", "link": "arm"})
        );
    }
}
