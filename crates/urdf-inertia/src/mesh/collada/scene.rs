//! The scene graph: node transforms, and geometries placed once per instance within the budgets.

use super::geometry::read_geometry;
use super::tree::{numbers, El};
use super::unit_range_loss;
use crate::mass::{Mat3, Polygons};
use crate::mesh::affine::{self, compose, Affine, IDENTITY};
use crate::mesh::{
    beyond_expansion_budget, MeshError, MeshErrorKind, RawMesh, MAX_INSTANCED_CORNERS,
    MAX_INSTANCED_VERTICES, MAX_NODE_VISITS,
};
use std::collections::HashMap;
use std::path::Path;

fn node_transform(node: &El, bytes: &[u8], path: &Path) -> Result<Affine, MeshError> {
    let mut acc = IDENTITY;
    for c in &node.children {
        let step: Affine = match c.name.as_str() {
            "matrix" => {
                let m = numbers(c, bytes, path)?;
                if m.len() != 16 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax(format!("<matrix> has {} numbers, not 16", m.len())),
                    ));
                }
                (
                    [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]],
                    [m[3], m[7], m[11]],
                )
            }
            "translate" => {
                let t = numbers(c, bytes, path)?;
                if t.len() != 3 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax("<translate> needs 3 numbers".into()),
                    ));
                }
                (IDENTITY.0, [t[0], t[1], t[2]])
            }
            "scale" => {
                let s = numbers(c, bytes, path)?;
                if s.len() != 3 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax("<scale> needs 3 numbers".into()),
                    ));
                }
                (
                    [[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]],
                    [0.0; 3],
                )
            }
            "rotate" => {
                let r = numbers(c, bytes, path)?;
                if r.len() != 4 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax("<rotate> needs 4 numbers".into()),
                    ));
                }
                (axis_angle([r[0], r[1], r[2]], r[3].to_radians()), [0.0; 3])
            }
            _ => continue,
        };
        acc = compose(&acc, &step);
    }
    Ok(acc)
}

fn axis_angle(axis: [f64; 3], angle: f64) -> Mat3 {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if n == 0.0 {
        return IDENTITY.0;
    }
    let [x, y, z] = axis.map(|a| a / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// Places geometries into one mesh, each read once however often the scene instances it, within the
/// instancing budget.
pub(super) struct Instancer<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) path: &'a Path,
    /// Metres per unit of the file.
    pub(super) unit: f64,
    /// Keyed by element, not by id: id-less geometries are each their own.
    pub(super) geom_cache: HashMap<*const El, (Vec<[f64; 3]>, Polygons)>,
    /// Polygon corners instanced so far.
    pub(super) corners: usize,
    /// Set when the unit made a coordinate overflow or underflow (see [`unit_range_loss`]).
    pub(super) unit_loss: Option<&'static str>,
    pub(super) out: RawMesh,
    /// Reader messages; those starting `warning: ` become warnings.
    pub(super) notes: Vec<String>,
}

impl Instancer<'_> {
    /// Adds one instance of `geom` transformed by `xf` (faces reversed if `xf` mirrors).
    pub(super) fn add(&mut self, geom: &El, xf: &Affine) -> Result<(), MeshError> {
        let key: *const El = geom;
        let (v, f) = match self.geom_cache.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => &*e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                &*e.insert(read_geometry(geom, self.bytes, self.path, &mut self.notes)?)
            }
        };
        self.corners = self.corners.saturating_add(f.indices.len());
        if beyond_expansion_budget(
            self.out.vertices.len().saturating_add(v.len()),
            self.corners,
        ) {
            return Err(MeshError::new(
                self.path,
                Some(geom.line),
                MeshErrorKind::Syntax(format!(
                    "the scene instances more than {MAX_INSTANCED_VERTICES} vertices or {MAX_INSTANCED_CORNERS} polygon corners (nested <instance_node> multiply their geometry); simplify the collision mesh"
                )),
            ));
        }
        let base = self.out.vertices.len() as u32;
        self.out.vertices.reserve(v.len());
        let a = &xf.0;
        let check_unit = self.unit != 1.0;
        for p in v {
            // `mass::mat_vec`'s sums in its order, written out: its `[0, 1, 2].map` is a call here
            // (`core::array::try_map` in profiles; figures: docs/benchmarks.md, "Figures behind
            // choices in the code").
            let q = [
                a[0][0] * p[0] + a[0][1] * p[1] + a[0][2] * p[2],
                a[1][0] * p[0] + a[1][1] * p[1] + a[1][2] * p[2],
                a[2][0] * p[0] + a[2][1] * p[1] + a[2][2] * p[2],
            ];
            let authored = [q[0] + xf.1[0], q[1] + xf.1[1], q[2] + xf.1[2]];
            let placed = [
                authored[0] * self.unit,
                authored[1] * self.unit,
                authored[2] * self.unit,
            ];
            if check_unit {
                for i in 0..3 {
                    self.unit_loss = self
                        .unit_loss
                        .or_else(|| unit_range_loss(authored[i], placed[i]));
                }
            }
            self.out.vertices.push(placed);
        }
        // A mirroring node transform reverses the faces' orientation.
        let mirrored = affine::mirrors(xf);
        // Appended in bulk, not a face at a time: a `Vec` per face was a tenth of reading a large
        // file (figures: docs/benchmarks.md, "Figures behind choices in the code").
        let out = &mut self.out.faces;
        if out.starts.is_empty() {
            out.starts.push(0);
        }
        out.indices.reserve(f.indices.len());
        out.starts.reserve(f.len());
        for face in f.iter() {
            if mirrored {
                out.indices.extend(face.iter().rev().map(|i| i + base));
            } else {
                out.indices.extend(face.iter().map(|i| i + base));
            }
            out.starts.push(out.indices.len() as u32);
        }
        Ok(())
    }
}

/// Every geometry a visual scene's node hierarchy instances, with its node transforms (depth and node
/// visits bounded: a cycle of `<instance_node>` is an error, not a hang).
pub(super) fn add_scene<'a>(
    scene: &'a El,
    by_id: &HashMap<&str, &'a El>,
    inst: &mut Instancer<'_>,
) -> Result<(), MeshError> {
    let mut stack: Vec<(&El, Affine, usize)> = scene
        .children_named("node")
        .map(|n| (n, IDENTITY, 0))
        .collect();
    let mut visits = 0usize;
    while let Some((node, parent, depth)) = stack.pop() {
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(MeshError::new(
                inst.path,
                Some(node.line),
                MeshErrorKind::Syntax(format!(
                    "the scene instances more than {MAX_NODE_VISITS} nodes (nested <instance_node> multiply); simplify the collision mesh"
                )),
            ));
        }
        if depth > 64 {
            return Err(MeshError::new(
                inst.path,
                Some(node.line),
                MeshErrorKind::Syntax(
                    "node hierarchy deeper than 64 (a cycle of <instance_node>?)".into(),
                ),
            ));
        }
        let xf = compose(&parent, &node_transform(node, inst.bytes, inst.path)?);
        for c in &node.children {
            match c.name.as_str() {
                "instance_geometry" => {
                    let url = c.attr("url").unwrap_or("").trim_start_matches('#');
                    let geom = by_id.get(url).ok_or_else(|| {
                        MeshError::new(
                            inst.path,
                            Some(c.line),
                            MeshErrorKind::Syntax(format!(
                                "<instance_geometry url=\"#{url}\"> names no geometry"
                            )),
                        )
                    })?;
                    inst.add(geom, &xf)?;
                }
                "node" => stack.push((c, xf, depth + 1)),
                "instance_node" => {
                    let url = c.attr("url").unwrap_or("").trim_start_matches('#');
                    if let Some(n) = by_id.get(url) {
                        stack.push((n, xf, depth + 1));
                    }
                }
                _ => {}
            }
        }
    }
    Ok(())
}
