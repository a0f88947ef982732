//! Each collision as a part: a primitive's exact formulas or a mesh read, healed and integrated
//! through the cache, placed in the link frame.

use super::Context;
use crate::diagnostic::{
    self, Code, CollisionRef, Diagnostic, LinkError, LinkErrorKind, Location, Provenance,
};
use crate::geometry::Aabb;
use crate::mass::{mat_vec, primitives, rpy_matrix, MassProperties};
use crate::mesh::cache::Solids;
use crate::mesh::health::{ErrorEstimate, ModelError, ROUND_OFF_FLOOR};
use crate::overlap::{PartShape, PlacedPart};
use crate::urdf::{Collision, Geometry, Link};
use std::path::PathBuf;

/// A collision mesh larger than this (bounding-box diagonal, m) is almost surely in millimetres.
const MILLIMETRE_SLIP: f64 = 10.0;

/// A primitive's formulas are exact; their f64 evaluation is within a few ulps.
const PRIMITIVE_ERROR: ErrorEstimate = ErrorEstimate {
    round_off: ROUND_OFF_FLOOR,
    model: 0.0,
    source: ModelError::None,
    com: 0.0,
};

/// One collision, resolved and integrated at density 1, in the link frame.
pub(super) struct Part {
    pub(super) collision: usize,
    pub(super) what: String,
    pub(super) file: Option<PathBuf>,
    pub(super) uri: Option<String>,
    pub(super) unit: MassProperties,
    pub(super) provenance: Provenance,
    pub(super) diagnostics: Vec<Diagnostic>,
    pub(super) faces: usize,
    pub(super) error_estimate: f64,
    pub(super) error: ErrorEstimate,
    /// Relative precision of the input's coordinates ([`input_precision`]).
    pub(super) input_precision: f64,
    /// The solid in the link frame (for bounding boxes and the overlap estimate).
    pub(super) placed: PlacedPart,
}

pub(super) fn transformed_bbox(
    points: impl Iterator<Item = [f64; 3]>,
    r: &crate::mass::Mat3,
    t: [f64; 3],
) -> Aabb {
    Aabb::of(points.map(|p| {
        let q = mat_vec(r, p);
        [q[0] + t[0], q[1] + t[1], q[2] + t[2]]
    }))
}

fn box_corners(h: [f64; 3]) -> impl Iterator<Item = [f64; 3]> {
    (0..8).map(move |i| {
        [
            if i & 1 == 0 { -h[0] } else { h[0] },
            if i & 2 == 0 { -h[1] } else { h[1] },
            if i & 4 == 0 { -h[2] } else { h[2] },
        ]
    })
}

/// Where the link's failures point: the link and one of its collisions.
pub(super) fn link_error(link: &Link, c: &Collision, kind: LinkErrorKind) -> LinkError {
    LinkError {
        link: link.name.clone(),
        line: link.line,
        collision: Some(CollisionRef {
            index: c.index,
            line: c.line,
        }),
        kind: Box::new(kind),
    }
}

/// Where a part's diagnostics point.
pub(super) fn part_location(link: &Link, c: &Collision) -> Location {
    Location {
        file: None,
        line: Some(c.line),
        link: Some(link.name.clone()),
        collision: Some(c.index),
    }
}

/// A primitive collision: exact formulas.
fn primitive_part(c: &Collision, what: String, unit: MassProperties, shape: PartShape) -> Part {
    let r = rpy_matrix(c.origin.rpy);
    let t = c.origin.xyz;
    let half = match &shape {
        PartShape::Box(h) => *h,
        PartShape::Cylinder(radius, half) => [*radius, *radius, *half],
        PartShape::Capsule(radius, half) => [*radius, *radius, half + radius],
        PartShape::Sphere(radius) => [*radius; 3],
        PartShape::Mesh(_) => [0.0; 3],
    };
    Part {
        collision: c.index,
        what,
        file: None,
        uri: None,
        unit: unit.transformed(&r, t),
        provenance: Provenance::Primitive,
        diagnostics: Vec::new(),
        faces: 0,
        error_estimate: PRIMITIVE_ERROR.total(),
        error: PRIMITIVE_ERROR,
        input_precision: 0.0,
        placed: PlacedPart {
            shape,
            rotation: r,
            translation: t,
            bbox: transformed_bbox(box_corners(half), &r, t),
            volume: unit.mass,
            locator: None,
        },
    }
}

/// The message for a mesh so large it was likely exported in millimetres (its corners `vertices`,
/// already scaled by `scale`), if it is: a link's error by default, a warning with
/// `--allow-large-parts`, and `mesh`'s warning.
pub fn millimetre_slip(vertices: &[[f64; 3]], scale: [f64; 3]) -> Option<String> {
    slip_message(crate::mesh::bounds(vertices).diagonal(), scale)
}

/// [`millimetre_slip`] of vertices whose box has the diagonal `extent`, m.
pub(crate) fn slip_message(extent: f64, scale: [f64; 3]) -> Option<String> {
    if extent <= MILLIMETRE_SLIP {
        return None;
    }
    let s = if scale == [1.0; 3] {
        String::new()
    } else {
        format!(" (after scale {} {} {})", scale[0], scale[1], scale[2])
    };
    Some(format!(
        "the mesh is {extent:.1} m across{s}: if it was exported in millimetres, give it scale=\"0.001 0.001 0.001\""
    ))
}

/// The unit round-off of f32 (2⁻²⁴): how well a corner stored as an f32 is known, relative to
/// itself.
const F32_UNIT_ROUNDOFF: f64 = 1.0 / 16_777_216.0;

/// The relative precision of a mesh's corners (`vertices`, already multiplied by `scale`): 2⁻²⁴ when
/// every coordinate is an f32 times its axis's scale and some show f32 noise (the file stored f32:
/// binary STL, most glTF), else 0 (known to every f64 bit, as far as the tool can tell: integer or
/// dyadic corners, in any format, are exact). Written numbers are rounded within it, so an f32
/// corner of 0.02 writes as 0.02, not 0.0199999995529652.
fn input_precision(vertices: &[[f64; 3]], scale: [f64; 3]) -> f64 {
    // One multiplication rounded in f64: dividing by the scale recovers the f32 to within an f64
    // ulp, which the f32 cast removes, and multiplying again gives the same f64.
    #[allow(clippy::cast_possible_truncation)] // The point: whether the value survives f32.
    let as_f32 = |x: f64, s: f64| {
        let v = (x / s) as f32;
        (s != 0.0 && f64::from(v) * s == x).then_some(v)
    };
    // Noise: the f32's shortest decimal is shorter than the same value's as an f64 (0.02 against
    // 0.019999999552965164). Looked for in the first corners only: the noise of f32 data shows at
    // once, and a mesh without any is treated as exact (what it was before this check).
    let noisy = |v: f32| v.to_string().len() < f64::from(v).to_string().len();
    let mut noise = false;
    for (i, p) in vertices.iter().enumerate() {
        for k in 0..3 {
            let Some(v) = as_f32(p[k], scale[k]) else {
                return 0.0;
            };
            noise = noise || (i < 10_000 && noisy(v));
        }
    }
    if noise {
        F32_UNIT_ROUNDOFF
    } else {
        0.0
    }
}

/// A mesh collision: resolved, read, healed and integrated (through the cache).
fn mesh_part(
    link: &Link,
    c: &Collision,
    (filename, scale): (&str, [f64; 3]),
    ctx: &Context<'_>,
    solids: &Solids<'_>,
) -> Result<Part, LinkError> {
    // Resolved beforehand with the link's other meshes ([`super::resolve_meshes`]).
    let resolved = (ctx.resolved.get(filename).cloned())
        .unwrap_or_else(|| ctx.resolver.resolve(filename, &ctx.robot.path));
    let path = resolved.map_err(|nf| {
            let kind = LinkErrorKind::MeshNotFound {
                uri: nf.uri,
                searched: nf.searched,
                hint: nf.hint,
            };
            link_error(link, c, kind)
        })?;
    let solid = solids
        .get(&path, scale)
        .map_err(|e| link_error(link, c, LinkErrorKind::Mesh(e)))?;
    let mut diagnostics = diagnostic::mesh_health(&solid);
    if let Some(m) = solid.millimetre_slip(scale) {
        if !ctx.opts.allow_large_parts {
            // 10⁹ times the mass, written without a word but a warning, is worse than no value.
            return Err(link_error(link, c, LinkErrorKind::PartTooLarge(m)));
        }
        diagnostics.push(Diagnostic::new(Code::MeshTooLarge, m));
    }
    for d in &mut diagnostics {
        d.location = Some(part_location(link, c));
    }
    let r = rpy_matrix(c.origin.rpy);
    let t = c.origin.xyz;
    Ok(Part {
        collision: c.index,
        what: filename.to_string(),
        file: Some(path),
        uri: Some(filename.to_string()),
        unit: solid.unit.transformed(&r, t),
        provenance: Provenance::Mesh(solid.rung.clone()),
        diagnostics,
        faces: solid.faces_read,
        error_estimate: solid.error_estimate,
        error: solid.error,
        input_precision: input_precision(&solid.vertices, scale),
        placed: PlacedPart {
            bbox: transformed_bbox(solid.vertices.iter().copied(), &r, t),
            volume: solid.unit.mass,
            shape: PartShape::Mesh(solid),
            rotation: r,
            translation: t,
            locator: None,
        },
    })
}

/// One collision as a part, or the link's error.
pub(super) fn geometry_part(
    link: &Link,
    c: &Collision,
    ctx: &Context<'_>,
    solids: &Solids<'_>,
) -> Result<Part, LinkError> {
    let fmt3 = |v: [f64; 3]| format!("{} {} {}", v[0], v[1], v[2]);
    Ok(match &c.geometry {
        Geometry::Invalid { line, message } => {
            let kind = LinkErrorKind::InvalidGeometry {
                line: *line,
                message: message.clone(),
            };
            return Err(link_error(link, c, kind));
        }
        Geometry::Box { size } => primitive_part(
            c,
            format!("box {}", fmt3(*size)),
            primitives::cuboid(*size, 1.0),
            PartShape::Box(size.map(|s| s / 2.0)),
        ),
        Geometry::Cylinder { radius, length } => primitive_part(
            c,
            format!("cylinder r={radius} l={length}"),
            primitives::cylinder(*radius, *length, 1.0),
            PartShape::Cylinder(*radius, length / 2.0),
        ),
        Geometry::Capsule { radius, length } => primitive_part(
            c,
            format!("capsule r={radius} l={length}"),
            primitives::capsule(*radius, *length, 1.0),
            PartShape::Capsule(*radius, length / 2.0),
        ),
        Geometry::Sphere { radius } => primitive_part(
            c,
            format!("sphere r={radius}"),
            primitives::sphere(*radius, 1.0),
            PartShape::Sphere(*radius),
        ),
        Geometry::Mesh { filename, scale } => mesh_part(link, c, (filename, *scale), ctx, solids)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_corners_are_known_to_f32_precision_only_when_they_show_it() {
        let f = |x: f32| f64::from(x);
        // f32 noise (0.02 stored as f32): 2⁻²⁴.
        let wedge = [
            [0.0, 0.0, 0.0],
            [f(0.06), 0.0, f(0.04)],
            [0.0, f(0.03), 0.0],
        ];
        assert_eq!(input_precision(&wedge, [1.0; 3]), 1.0 / 16_777_216.0);
        // The same through a scale: each coordinate an f32 times the scale, rounded once.
        let s = [0.001, -0.001, 0.001];
        let scaled = wedge.map(|p| [p[0] * s[0], p[1] * s[1], p[2] * s[2]]);
        assert_eq!(input_precision(&scaled, s), 1.0 / 16_777_216.0);
        // Integer or dyadic corners (an OBJ's `v 1 0 0`) are exact in any format.
        let tet = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.5, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert_eq!(input_precision(&tet, [1.0; 3]), 0.0);
        // f64 decimals (text formats): not f32 values, exact as far as the tool can tell.
        let text = [[0.02, 0.0, 0.0], [0.0, 0.03, 0.0]];
        assert_eq!(input_precision(&text, [1.0; 3]), 0.0);
    }
}
