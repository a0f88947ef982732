//! What `fill` and `diff` print: the fill summary (text on stderr, or JSON), the diff table (or
//! JSON). Diagnostics print the same way everywhere: warnings always, notes with `--verbose`, both in
//! JSON as `{"severity", "code", "message", …}` objects.

use super::args::Format;
use super::robot_cmd::Row;
use serde_json::json;
use urdf_inertia::diagnostic::Diagnostic;
use urdf_inertia::fill::{FillReport, LinkReport, PartReport};
use urdf_inertia::mass::MassProperties;
use urdf_inertia::text::{self, shortest, significant, Digits};
use urdf_inertia::urdf::write::{tidy, tidy_moments};
use urdf_inertia::urdf::Robot;

/// Wall times of a fill, s.
#[derive(Debug, Clone, Copy)]
pub struct Times {
    pub seconds: f64,
    pub write: f64,
}

fn by_severity<'a>(ds: impl Iterator<Item = &'a Diagnostic>, warning: bool) -> Vec<&'a Diagnostic> {
    ds.filter(|d| d.is_warning() == warning).collect()
}

/// A part's lines of the text summary: each warning, or the repair alone; notes with `verbose`.
fn part_lines(l: &LinkReport, p: &PartReport, verbose: bool, out: &mut Vec<String>) {
    let head = format!(
        "link `{}`, collision {}, {}: {}",
        urdf_inertia::text::escape_control(&l.name),
        p.collision,
        p.what,
        p.provenance
    );
    let warnings: Vec<&Diagnostic> = p.warnings().collect();
    for w in &warnings {
        out.push(format!("  warning: {head}: {}", w.message));
    }
    if warnings.is_empty() && p.provenance.is_repaired() {
        out.push(format!("  warning: {head}"));
    }
    if verbose {
        for n in p.notes() {
            out.push(format!("  note: {head}: {}", n.message));
        }
    }
}

/// The diagnostics of the text summary, link by link.
fn link_lines(l: &LinkReport, verbose: bool) -> Vec<String> {
    let mut out = Vec::new();
    for p in &l.parts {
        part_lines(l, p, verbose, &mut out);
    }
    for d in l.diagnostics.iter().filter(|d| verbose || d.is_warning()) {
        out.push(format!(
            "  {}: link `{}`: {}",
            d.severity.as_str(),
            urdf_inertia::text::escape_control(&l.name),
            d.message
        ));
    }
    out
}

/// The text summary of `fill` on stderr; `name_file` when several URDFs were filled.
pub fn fill_text(
    robot: &Robot,
    report: &FillReport,
    run: &[Diagnostic],
    verbose: bool,
    t: Times,
    name_file: bool,
) {
    let parts: usize = report.links.iter().map(|l| l.parts.len()).sum();
    let file = if name_file {
        format!("{}: ", robot.path.display())
    } else {
        String::new()
    };
    errln!(
        "urdf-inertia: {file}robot `{}`: filled {} link(s) ({} parts, {} mesh files, {} faces) in {:.3} s (CPU time over all cores: mesh loading {:.3} s, healing and integration {:.3} s; writing {:.3} s)",
        robot.name,
        report.links.len(),
        parts,
        report.mesh_files,
        report.faces,
        t.seconds,
        report.timing.load.as_secs_f64(),
        report.timing.integrate.as_secs_f64(),
        t.write
    );
    for d in run {
        // The run's own diagnostics keep their historical wording (`not written` needs no prefix).
        if d.code == urdf_inertia::diagnostic::Code::OutputNotWritten {
            errln!("  {}", d.message);
        } else {
            errln!("  {}: {}", d.severity.as_str(), d.message);
        }
    }
    if report.without_geometry + report.not_selected > 0 {
        errln!(
            "  left as they are: {} link(s) without collision geometry, {} not selected",
            report.without_geometry,
            report.not_selected
        );
    }
    for l in &report.links {
        for line in link_lines(l, verbose) {
            errln!("{line}");
        }
    }
    worst_error(report);
}

fn worst_error(report: &FillReport) {
    let worst = report
        .links
        .iter()
        .flat_map(|l| l.parts.iter().map(move |p| (p.error_estimate, l, p)))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    if let Some((_, l, p)) = worst {
        errln!(
            "  worst error estimate: {} (relative bound on volume and inertia; link `{}`, collision {}: {})",
            p.error.describe(),
            urdf_inertia::text::escape_control(&l.name),
            p.collision,
            p.provenance
        );
    }
}

fn part_json(p: &PartReport) -> serde_json::Value {
    json!({
        "collision": p.collision,
        "geometry": p.what,
        "file": p.file.as_ref().map(|f| f.display().to_string()),
        "provenance": p.provenance,
        "faces": p.faces,
        "volume": text::within(p.volume, p.error_estimate * p.volume),
        "mass": text::within(p.mass, p.error_estimate * p.mass),
        "density": p.density,
        "density_source": p.density_source,
        "error_estimate": p.error_estimate,
        "error_round_off": p.error.round_off,
        "error_model": p.error.model,
        "error_model_source": p.error.source.name(),
        "error_center_of_mass": p.error.com,
        "warnings": by_severity(p.diagnostics.iter(), true),
        "notes": by_severity(p.diagnostics.iter(), false),
    })
}

fn link_json(l: &LinkReport, digits: Digits) -> serde_json::Value {
    let written = tidy(&l.update(), digits);
    json!({
        "link": l.name,
        "line": l.line,
        "mass": written.mass,
        "center_of_mass": written.com,
        "inertia": written.inertia,
        "principal_moments": tidy_moments(l.computed.principal().moments, l.error_estimate(), digits),
        "size": l.size,
        "warnings": by_severity(l.diagnostics.iter(), true),
        "notes": by_severity(l.diagnostics.iter(), false),
        "parts": l.parts.iter().map(part_json).collect::<Vec<_>>(),
    })
}

fn errors_json(report: &FillReport) -> Vec<serde_json::Value> {
    let links = report.failures.iter().map(|f| {
        json!({
            "link": f.link,
            "line": f.line,
            "collision": f.collision.map(|c| c.index),
            "kind": f.kind.name(),
            "message": f.to_string(),
        })
    });
    let robot = report
        .robot_errors
        .iter()
        .map(|e| json!({"link": null, "kind": e.name(), "message": e.to_string()}));
    links.chain(robot).collect()
}

/// The JSON summary of `fill` on stdout (the URDF went to a file).
pub fn fill_json(
    robot: &Robot,
    report: &FillReport,
    run: &[Diagnostic],
    digits: Digits,
    seconds: f64,
) {
    let mut notes: Vec<&Diagnostic> = robot.notes.iter().collect();
    notes.extend(run);
    let v = json!({
        "urdf": robot.path.display().to_string(),
        "robot": robot.name,
        "links_filled": report.links.len(),
        "links_without_geometry": report.without_geometry,
        "links_not_selected": report.not_selected,
        "mesh_files": report.mesh_files,
        "faces": report.faces,
        "errors": errors_json(report),
        "notes": notes,
        "seconds": seconds,
        "seconds_load": report.timing.load.as_secs_f64(),
        "seconds_integrate": report.timing.integrate.as_secs_f64(),
        "links": report.links.iter().map(|l| link_json(l, digits)).collect::<Vec<_>>(),
    });
    outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
}

/// Reported principal moments (rounded like the rest of the output).
fn moments(mp: &MassProperties, error: f64) -> [f64; 3] {
    tidy_moments(mp.principal().moments, error, Digits::Auto)
}

fn props_json(mp: &MassProperties, error: f64) -> serde_json::Value {
    json!({"mass": mp.mass, "center_of_mass": mp.com, "inertia": mp.inertia, "principal_moments": moments(mp, error)})
}

/// The causes and validity problems of a row, as the diff's notes.
fn row_notes(r: &Row) -> Vec<String> {
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

fn diff_json(rows: &[Row], tolerance: f64) -> serde_json::Value {
    let v: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| {
            let l = r.link;
            let c = r.comparison.as_ref();
            let existing = r.existing.map(|e| tidy(&(l.index, e).into(), Digits::Full));
            json!({
                "link": l.name,
                "line": l.line,
                "computed": props_json(&tidy(&l.update(), Digits::Auto), l.error_estimate()),
                "existing": existing.map(|e| props_json(&e, 0.0)),
                "mass_ratio": c.map(|c| c.mass_ratio),
                "com_distance_relative": c.map(|c| c.com_distance),
                "inertia_difference_relative": c.map(|c| c.inertia_difference),
                "differs": r.differs(tolerance),
                "notes": row_notes(r),
                "provenance": l.parts.iter().map(|p| p.provenance.clone()).collect::<Vec<_>>(),
            })
        })
        .collect();
    serde_json::Value::Array(v)
}

fn diff_row(r: &Row) {
    let l = r.link;
    let computed = tidy(&l.update(), Digits::Auto);
    let (Some(e), Some(c)) = (&r.existing, &r.comparison) else {
        outln!(
            "{:<28} {:>12} {:>12} {:>9} {:>10} {:>10}  no existing <inertial>",
            l.name,
            "-",
            significant(computed.mass, 6),
            "-",
            "-",
            "-"
        );
        return;
    };
    outln!(
        "{:<28} {:>12} {:>12} {:>9} {:>10} {:>10}  {}",
        l.name,
        significant(e.mass, 6),
        significant(computed.mass, 6),
        significant(c.mass_ratio, 4),
        significant(
            text::within(c.com_distance, text::rounding_tolerance(l.error_estimate())),
            4
        ),
        significant(
            text::within(
                c.inertia_difference,
                text::rounding_tolerance(l.error_estimate())
            ),
            4
        ),
        row_notes(r).join("; ")
    );
    let pe = moments(e, 0.0).map(|x| significant(x, 7));
    let pc = moments(&l.computed, l.error_estimate()).map(shortest);
    outln!(
        "{:<28} principal moments existing {} {} {}, computed {} {} {}",
        "",
        pe[0],
        pe[1],
        pe[2],
        pc[0],
        pc[1],
        pc[2]
    );
}

/// The diff: a table, or JSON.
pub fn diff(rows: &[Row], format: Format, tolerance: f64) {
    match format {
        Format::Json => outln!(
            "{}",
            serde_json::to_string_pretty(&diff_json(rows, tolerance)).unwrap_or_default()
        ),
        Format::Text => {
            outln!(
                "{:<28} {:>12} {:>12} {:>9} {:>10} {:>10}  notes",
                "link",
                "existing kg",
                "computed kg",
                "ratio",
                "COM Δ/size",
                "inertia Δ"
            );
            for r in rows {
                diff_row(r);
            }
        }
    }
}
