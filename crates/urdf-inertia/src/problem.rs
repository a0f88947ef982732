//! Problems of existing `<inertial>` elements, typed: what `check` finds in a robot, each with its
//! [`Code`], the link and URDF line it is about, and the values that make it a problem. The library
//! finds them; the command line renders them ([`InertialProblem`]'s `Display` is its text).

use crate::compare::{compare, Difference};
use crate::diagnostic::Code;
use crate::fill::{existing_props, selected, FillOptions, FillReport};
use crate::mass::validity::{self, Violation};
use crate::urdf::{Link, Robot};
use serde::Serialize;
use std::fmt;
use std::path::PathBuf;

/// One problem of a link's existing `<inertial>`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct InertialProblem {
    /// The URDF the link is in ([`Robot::path`]).
    #[serde(serialize_with = "path_text")]
    pub file: PathBuf,
    /// The link's name.
    pub link: String,
    /// The 1-based line the problem is on: the `<inertial>`, or the `<link>` when it has none.
    pub line: usize,
    /// What is wrong, with its values.
    #[serde(flatten)]
    pub kind: ProblemKind,
}

/// What is wrong with an existing `<inertial>`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum ProblemKind {
    /// The link has collision geometry but no `<inertial>` (urdfdom then gives it no mass).
    MissingInertial,
    /// Several `<inertial>` elements: urdfdom reads the first and ignores the rest.
    Duplicates {
        /// The line of the first, which urdfdom reads.
        first_line: usize,
        /// The lines of the others.
        ignored_lines: Vec<usize>,
    },
    /// Its numbers cannot be read. (`reason` in JSON, beside the problem's own `message`.)
    Unreadable {
        #[serde(rename = "reason")]
        message: String,
    },
    /// It has no `<mass>`.
    NoMass,
    /// It has no `<inertia>`.
    NoInertia,
    /// Its values cannot belong to a body (not finite, mass ≤ 0, tensor not positive definite,
    /// triangle inequality broken).
    InvalidTensor { violation: Violation },
    /// It differs from the computed one by more than `tolerance` (relative).
    Differs {
        differences: Vec<Difference>,
        /// Likely causes (unit slips, tensor about the link origin, mirrored products).
        causes: Vec<String>,
        tolerance: f64,
    },
}

fn path_text<S: serde::Serializer>(p: &std::path::Path, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&p.display())
}

impl InertialProblem {
    fn new(robot: &Robot, link: &Link, line: usize, kind: ProblemKind) -> Self {
        InertialProblem {
            file: robot.path.clone(),
            link: link.name.clone(),
            line,
            kind,
        }
    }

    /// The problem's stable code: UI601 (missing), UI602 (invalid), UI603 (differs).
    pub fn code(&self) -> Code {
        match self.kind {
            ProblemKind::MissingInertial => Code::CheckMissingInertial,
            ProblemKind::Differs { .. } => Code::CheckDiffers,
            _ => Code::CheckInvalidInertial,
        }
    }
}

/// The message, without the location (`check` prints `FILE:LINE: link `NAME`: ` before it).
impl fmt::Display for ProblemKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProblemKind::MissingInertial => f.write_str("has collision geometry but no <inertial>"),
            ProblemKind::Duplicates {
                first_line,
                ignored_lines,
            } => {
                let lines: Vec<String> = ignored_lines.iter().map(ToString::to_string).collect();
                write!(
                    f,
                    "{} <inertial> elements: urdfdom reads the first (line {first_line}) and ignores the rest (line {}); remove them, or let `fill` replace them all with one",
                    1 + ignored_lines.len(),
                    lines.join(", ")
                )
            }
            ProblemKind::Unreadable { message } => {
                write!(f, "<inertial> cannot be read: {message}")
            }
            ProblemKind::NoMass => f.write_str("<inertial> has no <mass>"),
            ProblemKind::NoInertia => f.write_str("<inertial> has no <inertia>"),
            ProblemKind::InvalidTensor { violation } => write!(f, "{violation}"),
            ProblemKind::Differs {
                differences,
                causes,
                tolerance,
            } => {
                let off: Vec<String> = differences.iter().map(ToString::to_string).collect();
                write!(f, "{}", off.join("; "))?;
                if !causes.is_empty() {
                    write!(f, " [{}]", causes.join("; "))?;
                }
                write!(f, " (tolerance {tolerance})")
            }
        }
    }
}

impl fmt::Display for InertialProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: link `{}`: {} [{}]",
            self.file.display(),
            self.line,
            crate::text::escape_control(&self.link),
            self.kind,
            self.code()
        )
    }
}

/// The problems of a link's existing `<inertial>` itself, no computation needed: none, duplicates,
/// unreadable or missing numbers, values no body has.
///
/// One exception: an all-zero inertial (mass 0, zero tensor) on a link *without* collision geometry is
/// the usual way to write a massless frame (IMU, tool or sensor frames on fixed joints) and is accepted.
pub(crate) fn link_problems(link: &Link) -> Vec<ProblemKind> {
    let Some(span) = &link.inertial else {
        return vec![ProblemKind::MissingInertial];
    };
    let mut out = Vec::new();
    if !link.extra_inertials.is_empty() {
        out.push(ProblemKind::Duplicates {
            first_line: span.line,
            ignored_lines: link.extra_inertials.iter().map(|s| s.line).collect(),
        });
    }
    if !link.has_collision_geometry()
        && span.problem.is_none()
        && span.value.mass == Some(0.0)
        && span
            .value
            .inertia
            .is_none_or(|i| i.iter().all(|x| *x == 0.0))
    {
        return out;
    }
    if let Some(p) = &span.problem {
        out.push(ProblemKind::Unreadable { message: p.clone() });
        return out;
    }
    if span.value.mass.is_none() {
        out.push(ProblemKind::NoMass);
    }
    if span.value.inertia.is_none() {
        out.push(ProblemKind::NoInertia);
    }
    if let Some(mp) = existing_props(&span.value) {
        for violation in validity::check(&mp, validity::DEFAULT_TOLERANCE) {
            out.push(ProblemKind::InvalidTensor { violation });
        }
    }
    out
}

/// Every problem of the existing `<inertial>` elements of `robot`'s links selected by `options`
/// (`only`, `skip`), in link order: none where there is collision geometry, duplicates, unreadable
/// or missing numbers, values no body has. Nothing is computed.
///
/// A link without collision geometry and no `<inertial>` is a frame, not a problem; a frame's
/// invalid `<inertial>` is one (the command line reports those as notes unless `--all-links`).
pub fn check(robot: &Robot, options: &FillOptions) -> Vec<InertialProblem> {
    let mut out = Vec::new();
    for link in robot.links.iter().filter(|l| selected(&l.name, options)) {
        let line = link.inertial.as_ref().map_or(link.line, |s| s.line);
        for kind in link_problems(link) {
            if kind != ProblemKind::MissingInertial || link.has_collision_geometry() {
                out.push(InertialProblem::new(robot, link, line, kind));
            }
        }
    }
    out
}

/// Every link of `computed` (what [`compute`](crate::compute) returned for `robot`) whose existing
/// `<inertial>` differs from the computed one by more than `tolerance` (relative: mass ratio,
/// centre-of-mass distance over the link's size, tensor difference over the computed tensor), as
/// [`ProblemKind::Differs`], in link order. Links without a readable existing `<inertial>` are
/// [`check`]'s.
pub fn check_computed(
    robot: &Robot,
    computed: &FillReport,
    tolerance: f64,
) -> Vec<InertialProblem> {
    let mut out = Vec::new();
    for l in &computed.links {
        let Some(link) = robot.links.get(l.index) else {
            continue;
        };
        let Some(span) = &link.inertial else {
            continue;
        };
        let Some(existing) = existing_props(&span.value) else {
            continue;
        };
        let c = compare(&existing, &l.computed, l.size);
        let differences = c.beyond(&existing, &l.computed, tolerance);
        if !differences.is_empty() {
            let kind = ProblemKind::Differs {
                differences,
                causes: c.causes,
                tolerance,
            };
            out.push(InertialProblem::new(robot, link, span.line, kind));
        }
    }
    out
}
