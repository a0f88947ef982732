//! Silent no-ops made loud: density-map rules and `--only`/`--skip` patterns that match nothing in
//! the robots of a run, and a robot with no collision geometry at all.

use std::path::Path;
use urdf_inertia::diagnostic::{Code, Diagnostic, Location};
use urdf_inertia::text::escape_control;
use urdf_inertia::{near_miss, DensityMap};
use urdf_inertia::{unused_selection, FillOptions};
use urdf_inertia::{Geometry, Robot};

/// The link names and collision mesh URIs of every robot of a run (a rule or pattern is unused only
/// when it matches nothing in any of them: pre-commit passes several URDFs of one repository).
#[derive(Debug, Default)]
pub struct Seen {
    links: Vec<String>,
    meshes: Vec<String>,
}

impl Seen {
    pub fn record(&mut self, robot: &Robot) {
        for l in &robot.links {
            self.links.push(l.name.clone());
            for c in &l.collisions {
                if let Geometry::Mesh { filename, .. } = &c.geometry {
                    self.meshes.push(filename.clone());
                }
            }
        }
    }

    fn links(&self) -> Vec<&str> {
        self.links.iter().map(String::as_str).collect()
    }
}

/// `--only` patterns of which none matches a link: an error (the run would fill nothing).
pub fn only_error(opts: &FillOptions, seen: &Seen) -> Option<String> {
    let links = seen.links();
    let (only, _) = unused_selection(opts, &links);
    if opts.only.is_empty() || only.len() < opts.only.len() {
        return None;
    }
    let hints: Vec<String> = only
        .iter()
        .filter_map(|p| {
            near_miss(p, &links)
                .map(|(k, _)| format!("did you mean `--only {}`?", escape_control(&k)))
        })
        .collect();
    let hint = if hints.is_empty() {
        "check the pattern (a glob: `*` for any run of characters, quoted so the shell keeps it)"
            .to_string()
    } else {
        hints.join(" ")
    };
    Some(format!(
        "--only {}: no link matches, so nothing would be computed; {hint}",
        only.iter()
            .map(|p| format!("`{}`", escape_control(p)))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// The warnings of a run's end: density rules (UI302) and `--only`/`--skip` patterns (UI303) that
/// match nothing. `map` is the density map with its file.
pub fn warnings(
    map: Option<(&DensityMap, &Path)>,
    opts: &FillOptions,
    seen: &Seen,
) -> Vec<Diagnostic> {
    let links = seen.links();
    let mut out = Vec::new();
    if let Some((map, path)) = map {
        let meshes: Vec<&str> = seen.meshes.iter().map(String::as_str).collect();
        out.extend(
            map.unused_rules(&links, &meshes)
                .iter()
                .map(|u| u.diagnostic(path)),
        );
    }
    let (only, skip) = unused_selection(opts, &links);
    // Every --only pattern unused is the error of `only_error`.
    let only = if only.len() == opts.only.len() {
        Vec::new()
    } else {
        only
    };
    for (flag, patterns) in [("--only", only), ("--skip", skip)] {
        for p in patterns {
            let hint = near_miss(p, &links)
                .map(|(k, _)| format!("; did you mean `{flag} {}`?", escape_control(&k)))
                .unwrap_or_default();
            out.push(Diagnostic::new(
                Code::SelectionUnused,
                format!(
                    "{flag} `{}` matches no link: it does nothing{hint}",
                    escape_control(p)
                ),
            ));
        }
    }
    out
}

/// UI210 for a robot where no link has collision geometry but some have visual geometry: `fill`
/// would compute nothing, and `--geometry collision,visual` would.
pub fn no_collision_geometry(robot: &Robot) -> Option<Diagnostic> {
    if !robot.visual_only() {
        return None;
    }
    let visual = robot.links.iter().filter(|l| !l.visuals.is_empty()).count();
    Some(
        Diagnostic::new(
            Code::NoCollisionGeometry,
            format!(
                "no link has collision geometry, so nothing is computed; {visual} link(s) have visual geometry: `--geometry collision,visual` computes a link without collision geometry from its visual geometry"
            ),
        )
        .at(Location::in_file(robot.path.clone())),
    )
}
