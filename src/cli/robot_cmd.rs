//! `fill`, `diff` and `check`: the commands that work on a URDF.

use super::args::{CheckArgs, DiffArgs, FillArgs, Format, SourceArgs};
use super::{output, shortest, write, ExitStatus};
use crate::density::DensityMap;
use crate::fill::{self, existing_problems, existing_props, FillOptions, FillReport, LinkReport};
use crate::mass::{frobenius, MassProperties};
use crate::urdf::resolve::PackageResolver;
use crate::urdf::write::{splice, WriteOptions};
use crate::urdf::{scan_bytes, Geometry, NoteLevel, Robot};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
    let bytes = crate::input::read_file(path)
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

fn summary_json(robot: &Robot, report: &FillReport, seconds: f64) -> serde_json::Value {
    let links: Vec<serde_json::Value> = report
        .links
        .iter()
        .map(|l| {
            json!({
                "link": l.name,
                "line": l.line,
                "mass": l.computed.mass,
                "center_of_mass": l.computed.com,
                "inertia": l.computed.inertia,
                "principal_moments": l.computed.principal().moments,
                "size": l.size,
                "warnings": l.warnings,
                "parts": l.parts.iter().map(|p| json!({
                    "collision": p.collision,
                    "geometry": p.what,
                    "file": p.file.as_ref().map(|f| f.display().to_string()),
                    "provenance": p.provenance,
                    "faces": p.faces,
                    "volume": p.volume,
                    "mass": p.mass,
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
    let updates: Vec<(usize, MassProperties)> =
        report.links.iter().map(|l| (l.index, l.computed)).collect();
    let text = splice(
        &robot,
        &updates,
        &WriteOptions {
            digits: a.digits,
            principal: a.principal,
        },
    );
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
            serde_json::to_string_pretty(&summary_json(&robot, &report, seconds))
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

/// Existing against computed, for one link.
struct Comparison {
    mass_ratio: f64,
    com_distance: f64,
    inertia_difference: f64,
    notes: Vec<String>,
}

fn near_power(r: f64) -> Option<i32> {
    if !(r > 0.0 && r.is_finite()) {
        return None;
    }
    let e = r.log10();
    let k = (e / 3.0).round() as i32 * 3;
    if k != 0 && (e - k as f64).abs() < 0.15 {
        Some(k)
    } else {
        None
    }
}

fn compare(existing: &MassProperties, computed: &MassProperties, size: f64) -> Comparison {
    let rel = |a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]| {
        let mut d = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                d[i][j] = a[i][j] - b[i][j];
            }
        }
        frobenius(&d) / frobenius(b).max(f64::MIN_POSITIVE)
    };
    let mass_ratio = existing.mass / computed.mass;
    let dc = [0, 1, 2].map(|k| existing.com[k] - computed.com[k]);
    let com_distance =
        (dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]).sqrt() / size.max(f64::MIN_POSITIVE);
    let inertia_difference = rel(&existing.inertia, &computed.inertia);
    let mut notes = Vec::new();
    if let Some(k) = near_power(mass_ratio) {
        notes.push(format!("mass off by 1e{k} (unit slip?)"));
    }
    let norm_ratio =
        frobenius(&existing.inertia) / frobenius(&computed.inertia).max(f64::MIN_POSITIVE);
    if let Some(k) = near_power(norm_ratio) {
        notes.push(format!("inertia off by 1e{k} (unit slip: mm² or g?)"));
    }
    // Scaled to the same mass, do the values look like the tensor about the link origin?
    let scaled = existing.scaled(1.0 / mass_ratio.max(f64::MIN_POSITIVE));
    let about_origin = computed.inertia_about([0.0; 3]);
    if inertia_difference > 0.05
        && rel(&scaled.inertia, &about_origin) < 0.5 * rel(&scaled.inertia, &computed.inertia)
        && rel(&scaled.inertia, &about_origin) < 0.05
    {
        notes.push("inertia looks like it is about the link origin, not the COM".into());
    }
    for (axis, name) in [(0usize, "x"), (1, "y"), (2, "z")] {
        let mut m = computed.inertia;
        for j in 0..3 {
            if j != axis {
                m[axis][j] = -m[axis][j];
                m[j][axis] = -m[j][axis];
            }
        }
        if inertia_difference > 0.05 && rel(&scaled.inertia, &m) < 0.05 {
            notes.push(format!(
                "products of inertia look mirrored in {name} (mesh mirrored, or scale sign lost?)"
            ));
        }
    }
    let problems = crate::mass::validity::check(existing, crate::mass::validity::DEFAULT_TOLERANCE);
    for p in problems {
        notes.push(format!("existing is invalid: {p}"));
    }
    Comparison {
        mass_ratio,
        com_distance,
        inertia_difference,
        notes,
    }
}

pub fn diff(a: &DiffArgs) -> ExitStatus {
    let (src, map, robot) = match prepare(&a.source, &a.urdf, "diff") {
        Ok(p) => p,
        Err(status) => return status,
    };
    let report = fill::compute(&robot, &map, &src.resolver, &src.options);
    print_failures(&robot, &report);
    let mut rows = Vec::new();
    for l in &report.links {
        let link = &robot.links[l.index];
        let existing = link
            .inertial
            .as_ref()
            .and_then(|s| existing_props(&s.value));
        let cmp = existing.as_ref().map(|e| compare(e, &l.computed, l.size));
        rows.push((l, existing, cmp));
    }
    match a.format {
        Format::Json => {
            let v: Vec<serde_json::Value> = rows
                .iter()
                .map(|(l, e, c)| {
                    json!({
                        "link": l.name,
                        "line": l.line,
                        "computed": {"mass": l.computed.mass, "center_of_mass": l.computed.com, "inertia": l.computed.inertia, "principal_moments": l.computed.principal().moments},
                        "existing": e.map(|e| json!({"mass": e.mass, "center_of_mass": e.com, "inertia": e.inertia, "principal_moments": e.principal().moments})),
                        "mass_ratio": c.as_ref().map(|c| c.mass_ratio),
                        "com_distance_relative": c.as_ref().map(|c| c.com_distance),
                        "inertia_difference_relative": c.as_ref().map(|c| c.inertia_difference),
                        "notes": c.as_ref().map(|c| c.notes.clone()).unwrap_or_else(|| vec!["no existing <inertial>".to_string()]),
                        "provenance": l.parts.iter().map(|p| p.provenance.clone()).collect::<Vec<_>>(),
                    })
                })
                .collect();
            outln!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        }
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
            for (l, e, c) in &rows {
                match (e, c) {
                    (Some(e), Some(c)) => {
                        outln!(
                            "{:<28} {:>12.5} {:>12.5} {:>9.4} {:>10.3e} {:>10.3e}  {}",
                            l.name,
                            e.mass,
                            l.computed.mass,
                            c.mass_ratio,
                            c.com_distance,
                            c.inertia_difference,
                            c.notes.join("; ")
                        );
                        let pe = e.principal().moments;
                        let pc = l.computed.principal().moments;
                        outln!(
                            "{:<28} principal moments existing {} {} {}, computed {} {} {}",
                            "",
                            shortest(pe[0]),
                            shortest(pe[1]),
                            shortest(pe[2]),
                            shortest(pc[0]),
                            shortest(pc[1]),
                            shortest(pc[2])
                        );
                    }
                    _ => outln!(
                        "{:<28} {:>12} {:>12.5} {:>9} {:>10} {:>10}  no existing <inertial>",
                        l.name,
                        "-",
                        l.computed.mass,
                        "-",
                        "-",
                        "-"
                    ),
                }
            }
        }
    }
    if report.failures.is_empty() {
        ExitStatus::Success
    } else {
        ExitStatus::Error
    }
}

pub fn check(a: &CheckArgs) -> ExitStatus {
    let src = match sources(&a.source) {
        Ok(s) => s,
        Err(e) => {
            errln!("error: {e}");
            return ExitStatus::Error;
        }
    };
    if !(a.tolerance > 0.0 && a.tolerance.is_finite()) {
        errln!(
            "error: --tolerance {} must be a positive number",
            a.tolerance
        );
        return ExitStatus::Error;
    }
    let mut findings = 0usize;
    let mut errors = 0usize;
    for path in &a.urdf {
        let robot = match read_robot(path) {
            Ok(r) => r,
            Err(e) => {
                errln!("error: {e}");
                errors += 1;
                continue;
            }
        };
        let mut report_line = |line: usize, link: &str, msg: &str| {
            outln!("{}:{line}: link `{link}`: {msg}", path.display());
            findings += 1;
        };
        for link in &robot.links {
            if !fill::selected(&link.name, &src.options) {
                continue;
            }
            if link.inertial.is_none() {
                if link.has_collision_geometry() {
                    report_line(
                        link.line,
                        &link.name,
                        "has collision geometry but no <inertial>",
                    );
                }
                continue;
            }
            let line = link.inertial.as_ref().map(|s| s.line).unwrap_or(link.line);
            // Several <inertial> elements are a problem whatever the link: the file says two things.
            let duplicates = fill::duplicate_inertials(link);
            for p in existing_problems(link) {
                if !link.has_collision_geometry() && !a.all_links && duplicates.as_ref() != Some(&p)
                {
                    errln!("note: {}:{line}: link `{}` (no collision geometry, so fill cannot compute it): {p}", path.display(), link.name);
                } else {
                    report_line(line, &link.name, &p);
                }
            }
        }
        if src.map.is_none() {
            // Without densities nothing is computed, but a collision that cannot be is still an error.
            for link in robot
                .links
                .iter()
                .filter(|l| fill::selected(&l.name, &src.options))
            {
                for c in &link.collisions {
                    if let Geometry::Invalid { line, message } = &c.geometry {
                        errln!(
                            "error: {}:{}: link `{}`: collision {} (line {line}): {message}",
                            path.display(),
                            link.line,
                            link.name,
                            c.index
                        );
                        errors += 1;
                    }
                }
            }
        }
        if let Some(map) = &src.map {
            let report = fill::compute(&robot, map, &src.resolver, &src.options);
            print_failures(&robot, &report);
            errors += report.failures.len();
            for l in &report.links {
                let link = &robot.links[l.index];
                let Some(span) = &link.inertial else { continue };
                let Some(e) = existing_props(&span.value) else {
                    continue;
                };
                let c = compare(&e, &l.computed, l.size);
                let tol = a.tolerance;
                let mut off = Vec::new();
                if (c.mass_ratio - 1.0).abs() > tol {
                    off.push(format!(
                        "mass {} kg, computed {} kg (ratio {:.4})",
                        shortest(e.mass),
                        shortest(l.computed.mass),
                        c.mass_ratio
                    ));
                }
                if c.com_distance > tol {
                    off.push(format!(
                        "centre of mass {:.3e} of the link's size from the computed one",
                        c.com_distance
                    ));
                }
                if c.inertia_difference > tol {
                    off.push(format!(
                        "inertia differs from the computed one by {:.3e} (relative)",
                        c.inertia_difference
                    ));
                }
                if !off.is_empty() {
                    let notes = c
                        .notes
                        .iter()
                        .filter(|n| !n.starts_with("existing is invalid"))
                        .cloned()
                        .collect::<Vec<_>>();
                    let notes = if notes.is_empty() {
                        String::new()
                    } else {
                        format!(" [{}]", notes.join("; "))
                    };
                    report_line(
                        span.line,
                        &link.name,
                        &format!("{}{notes} (tolerance {tol})", off.join("; ")),
                    );
                }
            }
        }
    }
    if errors > 0 {
        ExitStatus::Error
    } else if findings > 0 {
        errln!("urdf-inertia check: {findings} problem(s) found; `urdf-inertia fill -i FILE --density-map …` computes correct values");
        ExitStatus::Problems
    } else {
        ExitStatus::Success
    }
}
