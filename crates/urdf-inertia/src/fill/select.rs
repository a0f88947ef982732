//! Which links `fill` computes (`--only`, `--skip`, `--missing-only`) and what is wrong with the
//! `<inertial>` a link already has.

use super::parts::link_error;
use super::FillOptions;
use crate::diagnostic::{LinkError, LinkErrorKind};
use crate::mass::{rpy_matrix, MassProperties};
use crate::urdf::resolve::PackageResolver;
use crate::urdf::{Geometry, Inertial, Link, Robot};

/// Whether `fill` computes this link (it must also have collision geometry): selected by the globs and,
/// with `--missing-only`, lacking a valid inertial.
pub(super) fn is_target(link: &Link, opts: &FillOptions) -> bool {
    selected(&link.name, opts)
        && !(opts.missing_only && crate::problem::link_problems(link).is_empty())
}

/// The `--only` and `--skip` patterns that match none of `names` (the links of every robot of a
/// run): a typo there fills or skips nothing without a word otherwise.
pub fn unused_selection<'o>(opts: &'o FillOptions, names: &[&str]) -> (Vec<&'o str>, Vec<&'o str>) {
    let unused = |globs: &'o [crate::density::Glob]| {
        globs
            .iter()
            .filter(|g| !names.iter().any(|n| g.is_match(n)))
            .map(crate::density::Glob::as_str)
            .collect()
    };
    (unused(&opts.only), unused(&opts.skip))
}

/// Every collision mesh of the selected links whose path resolves to no file, as the error `fill`
/// would give: a stat, no reading (what `check` does without densities).
pub fn unresolved_meshes(
    robot: &Robot,
    resolver: &PackageResolver,
    opts: &FillOptions,
) -> Vec<LinkError> {
    let mut out = Vec::new();
    for link in robot.links.iter().filter(|l| selected(&l.name, opts)) {
        for c in &link.collisions {
            if let Geometry::Mesh { filename, .. } = &c.geometry {
                if let Err(nf) = resolver.resolve(filename, &robot.path) {
                    let kind = LinkErrorKind::MeshNotFound {
                        uri: nf.uri,
                        searched: nf.searched,
                        hint: nf.hint,
                    };
                    out.push(link_error(link, c, kind));
                }
            }
        }
    }
    out
}

/// Whether a link is selected by `--only` / `--skip` globs.
pub fn selected(name: &str, opts: &FillOptions) -> bool {
    let only = opts.only.is_empty() || opts.only.iter().any(|g| g.is_match(name));
    only && !opts.skip.iter().any(|g| g.is_match(name))
}

/// An existing inertial as mass properties in link coordinates (tensor rotated out of its origin frame).
pub fn existing_props(inertial: &Inertial) -> Option<MassProperties> {
    let mass = inertial.mass?;
    let i = inertial.inertia?;
    let local = [[i[0], i[1], i[2]], [i[1], i[3], i[4]], [i[2], i[4], i[5]]];
    let r = rpy_matrix(inertial.origin.rpy);
    let mp = MassProperties {
        mass,
        com: [0.0; 3],
        inertia: local,
    };
    Some(mp.transformed(&r, inertial.origin.xyz))
}
