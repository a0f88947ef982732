//! The densities of a link's parts (their own rules, the link's, its kept mass), the body they make
//! and the `total_mass` scaling.

use super::parts::Part;
use super::{FillOptions, FillReport, PartReport};
use crate::density::{DensityMap, Spec};
use crate::diagnostic::{Code, Diagnostic, LinkError, LinkErrorKind, RobotError};
use crate::mass::MassProperties;
use crate::urdf::Link;

/// A rule and where it came from (`[links] "arm_*"`, `default`, …).
pub(super) type Rule = (String, Spec);

/// The densities of a link's parts: each part's own `[meshes]` rule, else the link's rule, and the
/// density the parts without their own rule share.
pub(super) struct Densities {
    pub(super) own: Vec<Option<Rule>>,
    pub(super) link_spec: Option<Rule>,
    pub(super) shared: f64,
    pub(super) diagnostics: Vec<Diagnostic>,
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
pub(super) fn densities(
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
pub(super) fn body(parts: &[Part], d: &Densities) -> (MassProperties, Vec<PartReport>) {
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
pub(super) fn scale_to_total_mass(report: &mut FillReport, density_links: &[usize], total: f64) {
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
