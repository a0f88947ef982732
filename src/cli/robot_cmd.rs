//! `fill`, `diff` and `check`: the commands that work on a URDF.

use super::args::{CheckArgs, DiffArgs, FillArgs, Format, SourceArgs};
use super::compare::{compare, Comparison};
use super::{output, write, ExitStatus};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;
use urdf_inertia::density::DensityMap;
use urdf_inertia::fill::{
    self, existing_problems, existing_props, FillOptions, FillReport, LinkReport, MeshCache,
};
use urdf_inertia::mass::MassProperties;
use urdf_inertia::text::shortest;
use urdf_inertia::text::{self, significant, Digits};
use urdf_inertia::urdf::resolve::PackageResolver;
use urdf_inertia::urdf::write::{splice, tidy, tidy_moments, LinkUpdate, WriteOptions};
use urdf_inertia::urdf::{scan_bytes, Geometry, NoteLevel, Robot};

/// Validated sources: densities (if any), package paths, link selection.
struct Sources {
    map: Option<DensityMap>,
    resolver: PackageResolver,
    options: FillOptions,
}

fn sources(s: &SourceArgs) -> Result<Sources, String> {
    let map = match (&s.density_map, s.density) {
        (Some(p), _) => Some(DensityMap::load(p).map_err(|e| e.to_string())?),
        (None, Some(d)) => {
            if !(d > 0.0 && d.is_finite()) {
                return Err(format!("--density {d} must be a positive number (kg/m³)"));
            }
            Some(DensityMap::uniform(d))
        }
        (None, None) if s.keep_mass => Some(DensityMap::default()),
        (None, None) => None,
    };
    for g in s.only.iter().chain(&s.skip) {
        urdf_inertia::density::glob(g).map_err(|e| format!("--only/--skip: {e}"))?;
    }
    let mut pkgs = Vec::new();
    for p in &s.package_path {
        pkgs.push(PackageResolver::parse_package_arg(p)?);
    }
    Ok(Sources {
        map,
        resolver: PackageResolver::new(&pkgs),
        options: FillOptions {
            strict: s.strict,
            only: s.only.clone(),
            skip: s.skip.clone(),
            missing_only: false,
            keep_mass: s.keep_mass,
        },
    })
}

/// Sources, a density map (required by `command`) and the scanned URDF, or the error status already reported.
fn prepare(
    source: &SourceArgs,
    urdf: &Path,
    command: &str,
) -> Result<(Sources, DensityMap, Robot), ExitStatus> {
    let report = |e: String| {
        errln!("error: {e}");
        ExitStatus::Error
    };
    let mut src = sources(source).map_err(report)?;
    let map = src
        .map
        .take()
        .ok_or_else(|| report(format!("{command} needs densities: pass --density RHO (kg/m³), --density-map FILE, or --keep-mass")))?;
    let robot = read_robot(urdf).map_err(report)?;
    Ok((src, map, robot))
}

/// Reads, decodes and scans a URDF, printing the scan's warnings and notes to stderr.
fn read_robot(path: &Path) -> Result<Robot, String> {
    let bytes = urdf_inertia::input::read_file(path)
        .map_err(|e| format!("{}: cannot read the URDF: {e}", path.display()))?;
    let robot = scan_bytes(bytes, path).map_err(|e| e.to_string())?;
    for note in &robot.notes {
        errln!("{}", note.render(&robot.path));
    }
    Ok(robot)
}

fn print_failures(robot: &Robot, report: &FillReport) {
    for f in &report.failures {
        if f.name.is_empty() {
            errln!("error: {}: {}", robot.path.display(), f.message);
        } else {
            errln!(
                "error: {}:{}: link `{}`: {}",
                robot.path.display(),
                f.line,
                f.name,
                f.message
            );
        }
    }
}

fn part_lines(l: &LinkReport) -> Vec<String> {
    let mut out = Vec::new();
    for p in &l.parts {
        if fill::repaired(&p.provenance) || !p.warnings.is_empty() {
            for w in &p.warnings {
                out.push(format!(
                    "link `{}`, collision {}, {}: {}: {w}",
                    l.name, p.collision, p.what, p.provenance
                ));
            }
            if p.warnings.is_empty() {
                out.push(format!(
                    "link `{}`, collision {}, {}: {}",
                    l.name, p.collision, p.what, p.provenance
                ));
            }
        }
    }
    for w in &l.warnings {
        out.push(format!("link `{}`: {w}", l.name));
    }
    out
}

fn summary_json(
    robot: &Robot,
    report: &FillReport,
    digits: Digits,
    seconds: f64,
) -> serde_json::Value {
    let links: Vec<serde_json::Value> = report
        .links
        .iter()
        .map(|l| {
            let written = tidy(&l.update(), digits);
            json!({
                "link": l.name,
                "line": l.line,
                "mass": written.mass,
                "center_of_mass": written.com,
                "inertia": written.inertia,
                "principal_moments": tidy_moments(l.computed.principal().moments, l.error_estimate(), digits),
                "size": l.size,
                "warnings": l.warnings,
                "parts": l.parts.iter().map(|p| json!({
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
                    "warnings": p.warnings,
                    "notes": p.notes,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({
        "urdf": robot.path.display().to_string(),
        "robot": robot.name,
        "links_filled": report.links.len(),
        "links_without_geometry": report.without_geometry,
        "links_not_selected": report.not_selected,
        "mesh_files": report.mesh_files,
        "faces": report.faces,
        "errors": report.failures.iter().map(|f| json!({"link": f.name, "line": f.line, "message": f.message})).collect::<Vec<_>>(),
        "notes": robot.notes.iter().map(|n| json!({"level": match n.level { NoteLevel::Warning => "warning", NoteLevel::Note => "note" }, "line": n.line, "link": n.link, "message": n.message})).collect::<Vec<_>>(),
        "seconds": seconds,
        "seconds_load": report.timing.load.as_secs_f64(),
        "seconds_integrate": report.timing.integrate.as_secs_f64(),
        "links": links,
    })
}

pub fn fill(a: &FillArgs) -> ExitStatus {
    let start = Instant::now();
    let to_stdout = !a.in_place && a.output.as_ref().is_none_or(|p| p.as_os_str() == "-");
    if a.format == Format::Json && to_stdout {
        errln!("error: --format json prints the summary on stdout, where the URDF goes without -o OUT or -i");
        return ExitStatus::Error;
    }
    let (mut src, map, robot) = match prepare(&a.source, &a.urdf, "fill") {
        Ok(p) => p,
        Err(status) => return status,
    };
    src.options.missing_only = a.missing_only;
    let report = fill::compute(&robot, &map, &src.resolver, &src.options);
    print_failures(&robot, &report);
    let t_write = Instant::now();
    let updates: Vec<LinkUpdate> = report.links.iter().map(LinkReport::update).collect();
    let text = match splice(
        &robot,
        &updates,
        &WriteOptions {
            digits: a.digits,
            principal: a.principal,
        },
    ) {
        Ok(t) => t,
        Err(errors) => {
            for e in errors {
                let link = &robot.links[e.index];
                errln!(
                    "error: {}:{}: link `{}`: {}",
                    robot.path.display(),
                    link.line,
                    link.name,
                    e.message
                );
            }
            errln!("error: nothing written");
            return ExitStatus::Error;
        }
    };
    // Written back in the file's own encoding (UTF-16 and declared single-byte files included).
    let text = match robot.encoding.encode(&text) {
        Ok(bytes) => bytes,
        Err(e) => {
            errln!("error: {}: {e}", robot.path.display());
            return ExitStatus::Error;
        }
    };
    let target: Option<PathBuf> = if a.in_place {
        Some(a.urdf.clone())
    } else {
        a.output.clone().filter(|p| p.as_os_str() != "-")
    };
    let where_to = target
        .as_ref()
        .map_or_else(|| "stdout".to_string(), |p| p.display().to_string());
    // Selected links with geometry that were not computed.
    let failed_links = report.failures.len();
    if !report.failures.is_empty() && !a.keep_going {
        errln!(
            "error: {} link(s) could not be computed: nothing written to {where_to} (--keep-going writes the links that worked, and still exits 2)",
            failed_links
        );
        return ExitStatus::Error;
    }
    let written = match &target {
        Some(path) => write::write_output(path, &text),
        None => write::write_output(Path::new("-"), &text),
    };
    if let Err(e) = written {
        // A failing stdout was reported where it failed.
        if target.is_some() {
            errln!("error: {e}");
        }
        return ExitStatus::Error;
    }
    if target.is_some() {
        output::stdout_is_summary();
    }
    let write_time = t_write.elapsed();
    let seconds = start.elapsed().as_secs_f64();
    if a.format == Format::Json && target.is_some() {
        outln!(
            "{}",
            serde_json::to_string_pretty(&summary_json(&robot, &report, a.digits, seconds))
                .unwrap_or_default()
        );
    } else {
        let parts: usize = report.links.iter().map(|l| l.parts.len()).sum();
        errln!(
            "urdf-inertia: robot `{}`: filled {} link(s) ({} parts, {} mesh files, {} faces) in {:.3} s (CPU time over all cores: mesh loading {:.3} s, healing and integration {:.3} s; writing {:.3} s)",
            robot.name,
            report.links.len(),
            parts,
            report.mesh_files,
            report.faces,
            seconds,
            report.timing.load.as_secs_f64(),
            report.timing.integrate.as_secs_f64(),
            write_time.as_secs_f64()
        );
        if robot.name.is_empty() {
            errln!("  warning: <robot> has no name attribute: urdfdom (ROS, pinocchio) refuses such a file");
        }
        if !report.failures.is_empty() {
            errln!(
                "  not written (--keep-going): {failed_links} link(s) that failed, left as they were"
            );
        }
        if report.without_geometry + report.not_selected > 0 {
            errln!(
                "  left as they are: {} link(s) without collision geometry, {} not selected",
                report.without_geometry,
                report.not_selected
            );
        }
        for l in &report.links {
            for line in part_lines(l) {
                errln!("  warning: {line}");
            }
        }
        let worst = report
            .links
            .iter()
            .flat_map(|l| l.parts.iter().map(move |p| (p.error_estimate, l, p)))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, l, p)) = worst {
            errln!(
                "  worst error estimate: {} (relative bound on volume and inertia; link `{}`, collision {}: {})",
                p.error.describe(),
                l.name,
                p.collision,
                p.provenance
            );
        }
    }
    if report.failures.is_empty() {
        ExitStatus::Success
    } else {
        ExitStatus::Error
    }
}

/// One existing `<inertial>` against the computed one.
struct Row<'a> {
    link: &'a LinkReport,
    existing: Option<MassProperties>,
    comparison: Option<Comparison>,
}

impl Row<'_> {
    /// Whether `fill` would change this link beyond `tolerance` (or its values are invalid).
    fn differs(&self, tolerance: f64) -> bool {
        self.comparison
            .as_ref()
            .is_none_or(|c| c.differs(tolerance))
    }
}

/// Compare once: every computed link against its existing `<inertial>`.
fn compare_all<'a>(robot: &Robot, report: &'a FillReport) -> Vec<Row<'a>> {
    report
        .links
        .iter()
        .map(|l| {
            let existing = robot.links[l.index]
                .inertial
                .as_ref()
                .and_then(|s| existing_props(&s.value));
            let comparison = existing.as_ref().map(|e| compare(e, &l.computed, l.size));
            Row {
                link: l,
                existing,
                comparison,
            }
        })
        .collect()
}

fn validated_tolerance(tolerance: f64) -> Result<f64, ExitStatus> {
    if tolerance > 0.0 && tolerance.is_finite() {
        Ok(tolerance)
    } else {
        errln!("error: --tolerance {tolerance} must be a positive number");
        Err(ExitStatus::Error)
    }
}

/// Reported principal moments (rounded like the rest of the output).
fn moments(mp: &MassProperties, error: f64) -> [f64; 3] {
    tidy_moments(mp.principal().moments, error, Digits::Auto)
}

fn props_json(mp: &MassProperties, error: f64) -> serde_json::Value {
    json!({"mass": mp.mass, "center_of_mass": mp.com, "inertia": mp.inertia, "principal_moments": moments(mp, error)})
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
                "notes": c.map_or_else(|| vec!["no existing <inertial>".to_string()], |c| {
                    c.causes.iter().cloned().chain(c.invalid.iter().map(|p| format!("existing is invalid: {p}"))).collect()
                }),
                "provenance": l.parts.iter().map(|p| p.provenance.clone()).collect::<Vec<_>>(),
            })
        })
        .collect();
    serde_json::Value::Array(v)
}

fn diff_text(rows: &[Row]) {
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
            continue;
        };
        let notes: Vec<String> = c
            .causes
            .iter()
            .cloned()
            .chain(
                c.invalid
                    .iter()
                    .map(|p| format!("existing is invalid: {p}")),
            )
            .collect();
        outln!(
            "{:<28} {:>12} {:>12} {:>9} {:>10} {:>10}  {}",
            l.name,
            significant(e.mass, 6),
            significant(computed.mass, 6),
            significant(c.mass_ratio, 4),
            significant(text::within(c.com_distance, l.error_estimate()), 4),
            significant(text::within(c.inertia_difference, l.error_estimate()), 4),
            notes.join("; ")
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
}

/// `diff`: the comparison as a table (or JSON); exit 1 when a link differs beyond `--tolerance` or
/// its existing values are invalid (as `ruff format --diff` exits 1 when a file would change).
pub fn diff(a: &DiffArgs) -> ExitStatus {
    let tolerance = match validated_tolerance(a.tolerance) {
        Ok(t) => t,
        Err(status) => return status,
    };
    let (src, map, robot) = match prepare(&a.source, &a.urdf, "diff") {
        Ok(p) => p,
        Err(status) => return status,
    };
    let report = fill::compute(&robot, &map, &src.resolver, &src.options);
    print_failures(&robot, &report);
    let rows = compare_all(&robot, &report);
    match a.format {
        Format::Json => outln!(
            "{}",
            serde_json::to_string_pretty(&diff_json(&rows, tolerance)).unwrap_or_default()
        ),
        Format::Text => diff_text(&rows),
    }
    if !report.failures.is_empty() {
        ExitStatus::Error
    } else if rows.iter().any(|r| r.differs(tolerance)) {
        ExitStatus::Problems
    } else {
        ExitStatus::Success
    }
}

/// What `check` found in one URDF.
#[derive(Default)]
struct Found {
    problems: usize,
    errors: usize,
}

/// Problems of the existing `<inertial>` elements themselves (no computation needed).
fn check_existing(robot: &Robot, src: &Sources, all_links: bool, found: &mut Found) {
    let path = robot.path.display();
    for link in robot
        .links
        .iter()
        .filter(|l| fill::selected(&l.name, &src.options))
    {
        let Some(span) = &link.inertial else {
            if link.has_collision_geometry() {
                outln!(
                    "{path}:{}: link `{}`: has collision geometry but no <inertial>",
                    link.line,
                    link.name
                );
                found.problems += 1;
            }
            continue;
        };
        // Several <inertial> elements are a problem whatever the link: the file says two things.
        let duplicates = fill::duplicate_inertials(link);
        for p in existing_problems(link) {
            if !link.has_collision_geometry() && !all_links && duplicates.as_ref() != Some(&p) {
                errln!("note: {path}:{}: link `{}` (no collision geometry, so fill cannot compute it): {p}", span.line, link.name);
            } else {
                outln!("{path}:{}: link `{}`: {p}", span.line, link.name);
                found.problems += 1;
            }
        }
    }
}

/// Without densities nothing is computed, but a collision that cannot be is still an error.
fn check_collisions(robot: &Robot, src: &Sources, found: &mut Found) {
    for link in robot
        .links
        .iter()
        .filter(|l| fill::selected(&l.name, &src.options))
    {
        for c in &link.collisions {
            if let Geometry::Invalid { line, message } = &c.geometry {
                errln!(
                    "error: {}:{}: link `{}`: collision {} (line {line}): {message}",
                    robot.path.display(),
                    link.line,
                    link.name,
                    c.index
                );
                found.errors += 1;
            }
        }
    }
}

/// Existing against computed, beyond the tolerance (invalid values are reported by `check_existing`).
fn check_against_computed(robot: &Robot, report: &FillReport, tolerance: f64, found: &mut Found) {
    for r in compare_all(robot, report) {
        let (Some(e), Some(c)) = (&r.existing, &r.comparison) else {
            continue;
        };
        let off = c.beyond(e, &r.link.computed, tolerance);
        if off.is_empty() {
            continue;
        }
        let causes = if c.causes.is_empty() {
            String::new()
        } else {
            format!(" [{}]", c.causes.join("; "))
        };
        let line = robot.links[r.link.index]
            .inertial
            .as_ref()
            .map_or(r.link.line, |s| s.line);
        outln!(
            "{}:{line}: link `{}`: {}{causes} (tolerance {tolerance})",
            robot.path.display(),
            r.link.name,
            off.join("; ")
        );
        found.problems += 1;
    }
}

/// `check`: exit 1 when an `<inertial>` is invalid, missing or (with densities) off by more than the
/// tolerance. Several URDFs (what pre-commit passes) share one mesh cache: a mesh is read once.
pub fn check(a: &CheckArgs) -> ExitStatus {
    let src = match sources(&a.source) {
        Ok(s) => s,
        Err(e) => {
            errln!("error: {e}");
            return ExitStatus::Error;
        }
    };
    let tolerance = match validated_tolerance(a.tolerance) {
        Ok(t) => t,
        Err(status) => return status,
    };
    let mut cache = MeshCache::default();
    let mut found = Found::default();
    for path in &a.urdf {
        let robot = match read_robot(path) {
            Ok(r) => r,
            Err(e) => {
                errln!("error: {e}");
                found.errors += 1;
                continue;
            }
        };
        check_existing(&robot, &src, a.all_links, &mut found);
        let Some(map) = &src.map else {
            check_collisions(&robot, &src, &mut found);
            continue;
        };
        let report = fill::compute_with(&robot, map, &src.resolver, &src.options, &mut cache);
        print_failures(&robot, &report);
        found.errors += report.failures.len();
        check_against_computed(&robot, &report, tolerance, &mut found);
    }
    if found.errors > 0 {
        ExitStatus::Error
    } else if found.problems > 0 {
        errln!("urdf-inertia check: {} problem(s) found; `urdf-inertia fill -i FILE --density-map …` computes correct values", found.problems);
        ExitStatus::Problems
    } else {
        ExitStatus::Success
    }
}
