//! What `fill`, `diff` and `check` print: the fill summary (text on stderr, or JSON), the diff table
//! (or JSON), `check`'s JSON. Diagnostics print the same way everywhere: warnings always, notes with
//! `--verbose`, both in JSON as `{"severity", "code", "message", …}` objects. The JSON documents are
//! the library's `report` types, one record per link for all three.

use super::args::Format;
use super::baseline::Problem;
use super::policy::Policy;
use urdf_inertia::diagnostic::{Diagnostic, Provenance};
use urdf_inertia::report::{
    CheckOutput, DiffOutput, ErrorRecord, FillOutput, LinkRecord, MeshDiagnostic, MeshUser,
    ProblemRecord, Totals, SCHEMA_VERSION,
};
use urdf_inertia::text::significant;
use urdf_inertia::text::{self, Digits};
use urdf_inertia::Robot;
use urdf_inertia::{existing_props, FillReport, LinkReport};

/// Wall times of a fill, s.
#[derive(Debug, Clone, Copy)]
pub struct Times {
    pub seconds: f64,
    pub write: f64,
    /// How many of the computed links were written, when not all were (a xacro source's macro links,
    /// or nothing at all): the summary then says "computed", not "filled".
    pub written: Option<usize>,
}

/// One diagnostic of a mesh file and every (link, collision) that uses the mesh: a mesh shared by
/// four links is reported once.
#[derive(Debug)]
pub struct MeshGroup<'a> {
    /// The URI as the first user wrote it.
    pub what: &'a str,
    pub file: Option<&'a std::path::Path>,
    pub provenance: &'a Provenance,
    pub diagnostic: &'a Diagnostic,
    pub users: Vec<(&'a str, usize)>,
}

/// The diagnostics of the parts, grouped by mesh file (and scale, through the message), in the
/// order they first occur.
pub fn mesh_groups(report: &FillReport) -> Vec<MeshGroup<'_>> {
    let mut groups: Vec<MeshGroup<'_>> = Vec::new();
    for l in &report.links {
        for p in &l.parts {
            for d in &p.diagnostics {
                let same = |g: &MeshGroup<'_>| {
                    g.file == p.file.as_deref()
                        && (p.file.is_some() || g.what == p.what)
                        && g.provenance == &p.provenance
                        && g.diagnostic.code == d.code
                        && g.diagnostic.severity == d.severity
                        && g.diagnostic.message == d.message
                };
                match groups.iter_mut().find(|g| same(g)) {
                    Some(g) => g.users.push((&l.name, p.collision)),
                    None => groups.push(MeshGroup {
                        what: &p.what,
                        file: p.file.as_deref(),
                        provenance: &p.provenance,
                        diagnostic: d,
                        users: vec![(&l.name, p.collision)],
                    }),
                }
            }
        }
    }
    groups
}

/// `link `a`, collision 1`, or `3 links: `a` collision 1, `b` collision 2, `c` collision 1`.
fn users_text(users: &[(&str, usize)]) -> String {
    const SHOWN: usize = 8;
    let name = |(l, c): &(&str, usize)| format!("`{}` collision {c}", text::escape_control(l));
    if let [(l, c)] = users {
        format!("link `{}`, collision {c}", text::escape_control(l))
    } else {
        let mut names: Vec<String> = users.iter().take(SHOWN).map(name).collect();
        if users.len() > SHOWN {
            names.push(format!("and {} more", users.len() - SHOWN));
        }
        format!("{} links: {}", users.len(), names.join(", "))
    }
}

/// The lines of the mesh diagnostics the policy shows, each mesh once with the links using it:
/// `warning[UI101]: MESH: RUNG: MESSAGE (link `a`, collision 1)`.
pub fn mesh_lines(report: &FillReport, policy: &Policy) -> Vec<String> {
    mesh_groups(report)
        .into_iter()
        .filter(|g| policy.shows(g.diagnostic))
        .map(|g| {
            format!(
                "{}: {}: {}: {} ({})",
                g.diagnostic.head(),
                text::escape_control(g.what),
                g.provenance,
                g.diagnostic.message,
                users_text(&g.users)
            )
        })
        .collect()
}

/// The lines of the links' own diagnostics (overlaps, overridden rules, links left as they are for
/// want of volume) the policy shows.
pub fn link_lines(report: &FillReport, policy: &Policy) -> Vec<String> {
    report
        .links
        .iter()
        .flat_map(|l| l.diagnostics.iter().map(move |d| (l.name.as_str(), d)))
        .chain(report.no_volume.iter().map(|d| {
            (
                d.location
                    .as_ref()
                    .and_then(|l| l.link.as_deref())
                    .unwrap_or(""),
                d,
            )
        }))
        .filter(|(_, d)| policy.shows(d))
        .map(|(name, d)| {
            format!(
                "{}: link `{}`: {}",
                d.head(),
                text::escape_control(name),
                d.message
            )
        })
        .collect()
}

/// The diagnostics of a computed robot on stderr (what `diff` and `check` show of the meshes they
/// computed).
pub fn computed_diagnostics(report: &FillReport, policy: &Policy) {
    for line in mesh_lines(report, policy)
        .into_iter()
        .chain(link_lines(report, policy))
    {
        errln!("{line}");
    }
}

/// The mesh diagnostics as JSON, each mesh once with the links that use it.
fn mesh_json(report: &FillReport) -> Vec<MeshDiagnostic> {
    mesh_groups(report)
        .into_iter()
        .map(|g| MeshDiagnostic {
            mesh: g.what.to_string(),
            file: g.file.map(|f| f.display().to_string()),
            provenance: g.provenance.clone(),
            severity: g.diagnostic.severity,
            code: g.diagnostic.code,
            message: g.diagnostic.message.clone(),
            links: g
                .users
                .iter()
                .map(|(l, c)| MeshUser {
                    link: (*l).to_string(),
                    collision: *c,
                })
                .collect(),
        })
        .collect()
}

/// The robot's mass after the run: the computed links, and the others' existing `<mass>`; (total,
/// computed, as they are, how many links as they are carry a mass).
pub fn total_mass(robot: &Robot, report: &FillReport) -> (f64, f64, f64, usize) {
    let computed = report.links.iter().fold(0.0, |a, l| a + l.computed.mass);
    let done: std::collections::HashSet<usize> = report.links.iter().map(|l| l.index).collect();
    let kept: Vec<f64> = robot
        .links
        .iter()
        .enumerate()
        .filter(|(i, _)| !done.contains(i))
        .filter_map(|(_, l)| existing_props(&l.inertial.as_ref()?.value).map(|p| p.mass))
        .collect();
    // Folded from +0: an empty f64 sum is -0.
    let kept_sum = kept.iter().fold(0.0, |a, m| a + m);
    let err = report
        .links
        .iter()
        .map(LinkReport::error_estimate)
        .fold(0.0, f64::max);
    let tidy = |x: f64| text::within(x, text::rounding_tolerance(err) * x);
    (
        tidy(computed + kept_sum),
        tidy(computed),
        tidy(kept_sum),
        kept.len(),
    )
}

/// The worst relative error of the run: a part's bound, or the volume overlapping parts count more
/// than once relative to their link's volume, whichever is larger; (value, what it is).
pub fn worst_error(report: &FillReport) -> Option<(f64, String)> {
    let part = report
        .links
        .iter()
        .flat_map(|l| l.parts.iter().map(move |p| (p.error_estimate, l, p)))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(e, l, p)| {
            (
                e,
                format!(
                    "{} (relative bound on volume and inertia; link `{}`, collision {}: {})",
                    p.error.describe(),
                    text::escape_control(&l.name),
                    p.collision,
                    p.provenance
                ),
            )
        });
    let overlap = report
        .links
        .iter()
        .filter_map(|l| {
            let o = l.overlap.as_ref()?;
            let volume: f64 = l.parts.iter().map(|p| p.volume).sum();
            (volume > 0.0).then(|| (o.excess / volume, l, &o.parts))
        })
        .max_by(|a, b| a.0.total_cmp(&b.0));
    match (part, overlap) {
        (Some(p), Some((o, l, which))) if o > p.0 => Some((
            o,
            format!(
                "{:.1}% of link `{}`'s volume, counted more than once where its parts {which} overlap (UI401); the largest bound of a part alone: {}",
                100.0 * o,
                text::escape_control(&l.name),
                p.1
            ),
        )),
        (p, _) => p,
    }
}

/// The summary's closing lines: the robot's total mass and the worst error estimate.
fn closing_lines(robot: &Robot, report: &FillReport) {
    let (total, computed, kept, n) = total_mass(robot, report);
    let kept_text = if n > 0 {
        format!(
            "; {n} link(s) left as they are: {} kg",
            text::significant(kept, 6)
        )
    } else {
        String::new()
    };
    errln!(
        "  total mass: {} kg ({} link(s) computed: {} kg{kept_text})",
        text::significant(total, 6),
        report.links.len(),
        text::significant(computed, 6)
    );
    if let Some((_, what)) = worst_error(report) {
        errln!("  worst error estimate: {what}");
    }
}

/// The text summary of `fill` on stderr; `name_file` when several URDFs were filled.
pub fn fill_text(
    robot: &Robot,
    report: &FillReport,
    run: &[Diagnostic],
    policy: &Policy,
    t: Times,
    name_file: bool,
) {
    let parts: usize = report.links.iter().map(|l| l.parts.len()).sum();
    let file = if name_file {
        format!("{}: ", robot.path.display())
    } else {
        String::new()
    };
    if !policy.quiet {
        errln!(
            "urdf-inertia: {file}robot `{}`: {} ({} parts, {} mesh files, {} faces) in {:.3} s (CPU time over all cores: mesh loading {:.3} s, healing and integration {:.3} s; writing {:.3} s)",
            robot.name,
            match t.written {
                None => format!("filled {} link(s)", report.links.len()),
                Some(k) => format!(
                    "computed {} link(s), {k} written",
                    report.links.len()
                ),
            },
            parts,
            report.mesh_files,
            report.faces,
            t.seconds,
            report.timing.load.as_secs_f64(),
            report.timing.integrate.as_secs_f64(),
            t.write
        );
    }
    for d in run.iter().filter(|d| policy.shows(d)) {
        errln!("  {}: {}", d.head(), d.message);
    }
    if report.without_geometry + report.not_selected > 0 && !policy.quiet {
        errln!(
            "  left as they are: {} link(s) without collision geometry, {} not selected",
            report.without_geometry,
            report.not_selected
        );
    }
    for line in mesh_lines(report, policy)
        .into_iter()
        .chain(link_lines(report, policy))
    {
        errln!("  {line}");
    }
    if !policy.quiet {
        closing_lines(robot, report);
    }
}

/// The robot's totals and the run's worst error, as the JSON documents carry them.
fn totals(robot: &Robot, report: &FillReport) -> Totals {
    let (total, computed, kept, _) = total_mass(robot, report);
    Totals {
        total_mass: total,
        total_mass_computed: computed,
        total_mass_as_they_are: kept,
        worst_error_estimate: worst_error(report).map(|w| w.0),
    }
}

/// A JSON document on stdout, pretty-printed.
pub fn print_json(document: &impl serde::Serialize) {
    match serde_json::to_string_pretty(document) {
        Ok(text) => outln!("{text}"),
        Err(e) => errln!("error: cannot write the JSON: {e}"),
    }
}

/// The JSON summary of `fill` on stdout (the URDF went to a file; `written` false when links failed
/// without `--keep-going`, or a warning was made an error, so nothing was).
pub fn fill_json(
    robot: &Robot,
    report: &FillReport,
    run: &[Diagnostic],
    digits: Digits,
    seconds: f64,
    written: bool,
) {
    let mut notes: Vec<Diagnostic> = robot.notes.clone();
    notes.extend_from_slice(run);
    notes.extend_from_slice(&report.no_volume);
    let errors = report.failures.iter().map(ErrorRecord::from);
    let robot_errors = report.robot_errors.iter().map(ErrorRecord::from);
    print_json(&FillOutput {
        schema_version: SCHEMA_VERSION,
        urdf: robot.path.display().to_string(),
        robot: robot.name.clone(),
        written,
        links_filled: report.links.len(),
        links_without_geometry: report.without_geometry,
        links_not_selected: report.not_selected,
        mesh_files: report.mesh_files,
        faces: report.faces,
        errors: errors.chain(robot_errors).collect(),
        notes,
        mesh_diagnostics: mesh_json(report),
        totals: totals(robot, report),
        seconds,
        seconds_load: report.timing.load.as_secs_f64(),
        seconds_integrate: report.timing.integrate.as_secs_f64(),
        links: report
            .links
            .iter()
            .map(|l| LinkRecord::new(robot, l.index, Some(l), digits, None))
            .collect(),
    });
}

/// `check --format json`: the links of the new problems (those not in a baseline), each with its
/// problems, in the order they were found; `records` holds the links as read (and computed).
pub fn check_json(new: &[&Problem], records: &[LinkRecord], known: usize, errors: usize) {
    let mut links: Vec<LinkRecord> = Vec::new();
    let same = |r: &LinkRecord, p: &Problem| {
        r.link == p.problem.link && r.urdf == p.problem.file.display().to_string()
    };
    for p in new {
        let i = if let Some(i) = links.iter().position(|r| same(r, p)) {
            i
        } else {
            let Some(r) = records.iter().find(|r| same(r, p)) else {
                continue;
            };
            links.push(r.clone());
            links.len() - 1
        };
        links[i]
            .problems
            .push(ProblemRecord::new(&p.problem, &p.at));
    }
    print_json(&CheckOutput {
        schema_version: SCHEMA_VERSION,
        problem_count: links.iter().map(|l| l.problems.len()).sum(),
        links,
        known_in_baseline: known,
        errors,
    });
}

/// The causes and validity problems of a link, as the diff's notes.
fn diff_notes(r: &LinkRecord) -> Vec<String> {
    r.comparison.as_ref().map_or_else(
        || vec!["no existing <inertial>".to_string()],
        |c| {
            c.causes
                .iter()
                .cloned()
                .chain(
                    c.invalid
                        .iter()
                        .map(|p| format!("existing is invalid: {p}")),
                )
                .collect()
        },
    )
}

/// Every computed link as `diff` reports it: with the comparison against `tolerance`.
pub fn diff_records(robot: &Robot, report: &FillReport, tolerance: f64) -> Vec<LinkRecord> {
    report
        .links
        .iter()
        .map(|l| LinkRecord::new(robot, l.index, Some(l), Digits::Auto, Some(tolerance)))
        .collect()
}

/// One link of the diff's table: its masses and relative differences, then both sides' principal
/// moments.
fn diff_row(r: &LinkRecord, w: usize) {
    let Some(computed) = &r.computed else {
        return;
    };
    let (Some(e), Some(c)) = (&r.existing, &r.comparison) else {
        outln!(
            "{:<w$} {:>12} {:>12} {:>9} {:>10} {:>10}  no existing <inertial>",
            r.link,
            "-",
            significant(computed.mass, 6),
            "-",
            "-",
            "-"
        );
        return;
    };
    let tolerance = text::rounding_tolerance(r.error_estimate.unwrap_or(0.0));
    outln!(
        "{:<w$} {:>12} {:>12} {:>9} {:>10} {:>10}  {}",
        r.link,
        significant(e.mass, 6),
        significant(computed.mass, 6),
        significant(c.mass_ratio, 4),
        significant(text::within(c.com_distance_relative, tolerance), 4),
        significant(text::within(c.inertia_difference_relative, tolerance), 4),
        diff_notes(r).join("; ")
    );
    // Both sides with one formatter, seven significant digits: a table to compare by eye (the JSON
    // and the written file keep every digit the estimate allows).
    let pe = e.principal_moments.map(|x| significant(x, 7));
    let pc = computed.principal_moments.map(|x| significant(x, 7));
    outln!(
        "{:<w$} principal moments existing {} {} {}, computed {} {} {}",
        "",
        pe[0],
        pe[1],
        pe[2],
        pc[0],
        pc[1],
        pc[2]
    );
}

/// The diff of `records` ([`diff_records`]): a table, or JSON with each mesh's diagnostics once and
/// the totals.
pub fn diff(
    records: Vec<LinkRecord>,
    format: Format,
    tolerance: f64,
    robot: &Robot,
    report: &FillReport,
) {
    match format {
        Format::Json => print_json(&DiffOutput {
            schema_version: SCHEMA_VERSION,
            urdf: robot.path.display().to_string(),
            robot: robot.name.clone(),
            tolerance,
            links: records,
            mesh_diagnostics: mesh_json(report),
            totals: totals(robot, report),
        }),
        Format::Text => {
            // The link column as wide as the longest name (28 at least), so that the numbers stay
            // in their columns: Robotiq's `robotiq_85_right_inner_knuckle_link` has 35 characters.
            let w = records
                .iter()
                .map(|r| r.link.chars().count())
                .max()
                .unwrap_or(0)
                .max(28);
            outln!(
                "{:<w$} {:>12} {:>12} {:>9} {:>10} {:>10}  notes",
                "link",
                "existing kg",
                "computed kg",
                "ratio",
                "COM Δ/size",
                "inertia Δ"
            );
            for r in &records {
                diff_row(r, w);
            }
        }
    }
}
