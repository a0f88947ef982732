//! How much of a link's volume its parts count twice.
//!
//! A link's parts are integrated as a disjoint union (Problem 1). Where two parts overlap, the overlap is
//! counted twice. The estimate samples a grid over the intersection of the two parts' bounding boxes and
//! tests each point against both solids: analytically for primitives, and for meshes by the parity of a
//! ray along +x, with the mesh's triangles bucketed on a (y, z) grid so that a point meets only the few
//! triangles above and below it. (A mesh here is a healed, closed solid; [`winding_number`] is the slower,
//! exact reference the tests compare with.)

use crate::mass::{mat_vec, transpose, Mat3};
use crate::mesh::health::Solid;
use std::sync::Arc;

/// A part's solid in its own frame.
#[derive(Debug, Clone)]
pub enum PartShape {
    /// Half extents.
    Box([f64; 3]),
    /// Along z: radius, half length.
    Cylinder(f64, f64),
    Sphere(f64),
    /// Along z: radius, half length of the cylindrical part.
    Capsule(f64, f64),
    Mesh(Arc<Solid>),
}

/// A closed triangle mesh bucketed on a (y, z) grid for point-in-solid tests by ray parity.
#[derive(Debug)]
pub struct MeshLocator {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    lo: [f64; 2],
    cell: [f64; 2],
    grid: usize,
    buckets: Vec<Vec<u32>>,
}

impl MeshLocator {
    pub fn new(solid: &Solid) -> Self {
        let triangles = solid.faces.triangles();
        let vertices = solid.vertices.clone();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for v in &vertices {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k + 1]);
                hi[k] = hi[k].max(v[k + 1]);
            }
        }
        let grid = ((triangles.len() as f64 / 4.0).sqrt().ceil() as usize).clamp(1, 256);
        let cell = [0, 1].map(|k| ((hi[k] - lo[k]) / grid as f64).max(f64::MIN_POSITIVE));
        let mut buckets = vec![Vec::new(); grid * grid];
        let index =
            |x: f64, k: usize| (((x - lo[k]) / cell[k]).floor().max(0.0) as usize).min(grid - 1);
        for (t, tri) in triangles.iter().enumerate() {
            let ys = tri.map(|i| vertices[i as usize][1]);
            let zs = tri.map(|i| vertices[i as usize][2]);
            let (y0, y1) = (
                index(ys.iter().cloned().fold(f64::INFINITY, f64::min), 0),
                index(ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max), 0),
            );
            let (z0, z1) = (
                index(zs.iter().cloned().fold(f64::INFINITY, f64::min), 1),
                index(zs.iter().cloned().fold(f64::NEG_INFINITY, f64::max), 1),
            );
            for a in y0..=y1 {
                for b in z0..=z1 {
                    buckets[a * grid + b].push(t as u32);
                }
            }
        }
        MeshLocator {
            vertices,
            triangles,
            lo,
            cell,
            grid,
            buckets,
        }
    }

    /// Whether `q` (mesh frame) is inside: the number of triangles a ray from `q` along +x crosses is odd.
    pub fn contains(&self, q: [f64; 3]) -> bool {
        let a = ((q[1] - self.lo[0]) / self.cell[0]).floor();
        let b = ((q[2] - self.lo[1]) / self.cell[1]).floor();
        if a < 0.0 || b < 0.0 || a >= self.grid as f64 || b >= self.grid as f64 {
            return false;
        }
        let mut crossings = 0usize;
        for &t in &self.buckets[a as usize * self.grid + b as usize] {
            let [i, j, k] = self.triangles[t as usize];
            let (p0, p1, p2) = (
                self.vertices[i as usize],
                self.vertices[j as usize],
                self.vertices[k as usize],
            );
            // Signed areas in the (y, z) plane; the half-open sign rule counts a ray through an edge once.
            let w0 = orient(p1, p2, q);
            let w1 = orient(p2, p0, q);
            let w2 = orient(p0, p1, q);
            let inside = (w0 > 0.0 || w0 == 0.0 && edge_rule(p1, p2))
                && (w1 > 0.0 || w1 == 0.0 && edge_rule(p2, p0))
                && (w2 > 0.0 || w2 == 0.0 && edge_rule(p0, p1))
                || (w0 < 0.0 || w0 == 0.0 && !edge_rule(p1, p2))
                    && (w1 < 0.0 || w1 == 0.0 && !edge_rule(p2, p0))
                    && (w2 < 0.0 || w2 == 0.0 && !edge_rule(p0, p1));
            let sum = w0 + w1 + w2;
            if inside && sum != 0.0 && (w0 * p0[0] + w1 * p1[0] + w2 * p2[0]) / sum > q[0] {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }
}

/// Twice the signed area of (a, b, q) projected on the (y, z) plane.
fn orient(a: [f64; 3], b: [f64; 3], q: [f64; 3]) -> f64 {
    (b[1] - a[1]) * (q[2] - a[2]) - (b[2] - a[2]) * (q[1] - a[1])
}

/// Tie-break for a point exactly on an edge: the edge owns it on one side only.
fn edge_rule(a: [f64; 3], b: [f64; 3]) -> bool {
    (b[1], b[2]) > (a[1], a[2])
}

/// A part placed in the link frame: `x_link = R x_part + t`.
#[derive(Debug, Clone)]
pub struct PlacedPart {
    pub shape: PartShape,
    pub rotation: Mat3,
    pub translation: [f64; 3],
    /// Bounding box in the link frame.
    pub bbox: ([f64; 3], [f64; 3]),
    /// Volume (m³).
    pub volume: f64,
    /// For meshes: the bucketed triangles, built when first needed.
    pub locator: Option<Arc<MeshLocator>>,
}

impl PlacedPart {
    /// Whether the link-frame point `p` is inside the part.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        let d = [
            p[0] - self.translation[0],
            p[1] - self.translation[1],
            p[2] - self.translation[2],
        ];
        let q = mat_vec(&transpose(&self.rotation), d);
        match &self.shape {
            PartShape::Box(h) => q[0].abs() <= h[0] && q[1].abs() <= h[1] && q[2].abs() <= h[2],
            PartShape::Cylinder(r, hl) => q[0] * q[0] + q[1] * q[1] <= r * r && q[2].abs() <= *hl,
            PartShape::Sphere(r) => q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= r * r,
            PartShape::Capsule(r, hl) => {
                let z = q[2].clamp(-hl, *hl);
                q[0] * q[0] + q[1] * q[1] + (q[2] - z) * (q[2] - z) <= r * r
            }
            PartShape::Mesh(_) => self.locator.as_ref().is_some_and(|l| l.contains(q)),
        }
    }

    fn cost(&self) -> usize {
        match &self.shape {
            PartShape::Mesh(_) => 8,
            _ => 1,
        }
    }

    /// Builds the mesh locator if this part is a mesh and has none yet.
    pub fn prepare(&mut self) {
        if let (PartShape::Mesh(solid), None) = (&self.shape, &self.locator) {
            self.locator = Some(Arc::new(MeshLocator::new(solid)));
        }
    }
}

/// The winding number of a closed, outward surface around `q`: 1 inside, 0 outside.
pub fn winding_number(solid: &Solid, q: [f64; 3]) -> f64 {
    let mut total = 0.0;
    for face in solid.faces.iter() {
        let a = sub(solid.vertices[face[0] as usize], q);
        for k in 1..face.len().saturating_sub(1) {
            let b = sub(solid.vertices[face[k] as usize], q);
            let c = sub(solid.vertices[face[k + 1] as usize], q);
            let (la, lb, lc) = (norm(a), norm(b), norm(c));
            let num = a[0] * (b[1] * c[2] - b[2] * c[1])
                + a[1] * (b[2] * c[0] - b[0] * c[2])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
            let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
            total += 2.0 * num.atan2(den);
        }
    }
    total / (4.0 * std::f64::consts::PI)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Samples per axis of the grid over the intersection of the bounding boxes.
const GRID: usize = 24;

/// The estimated volume inside both parts (m³) and the grid size used, or `None` when their bounding
/// boxes do not overlap.
pub fn overlap_volume(a: &PlacedPart, b: &PlacedPart) -> Option<(f64, usize)> {
    let lo = [0, 1, 2].map(|k| a.bbox.0[k].max(b.bbox.0[k]));
    let hi = [0, 1, 2].map(|k| a.bbox.1[k].min(b.bbox.1[k]));
    if (0..3).any(|k| hi[k] <= lo[k]) {
        return None;
    }
    let box_volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    let n = GRID;
    let mut inside = 0usize;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = [
                    lo[0] + (hi[0] - lo[0]) * (i as f64 + 0.5) / n as f64,
                    lo[1] + (hi[1] - lo[1]) * (j as f64 + 0.5) / n as f64,
                    lo[2] + (hi[2] - lo[2]) * (k as f64 + 0.5) / n as f64,
                ];
                // The cheap test first.
                let (first, second) = if a.cost() <= b.cost() { (a, b) } else { (b, a) };
                if first.contains(p) && second.contains(p) {
                    inside += 1;
                }
            }
        }
    }
    Some((box_volume * inside as f64 / (n * n * n) as f64, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    const ID: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn placed(shape: PartShape, t: [f64; 3], half: [f64; 3], volume: f64) -> PlacedPart {
        PlacedPart {
            shape,
            rotation: ID,
            translation: t,
            bbox: (
                [t[0] - half[0], t[1] - half[1], t[2] - half[2]],
                [t[0] + half[0], t[1] + half[1], t[2] + half[2]],
            ),
            volume,
            locator: None,
        }
    }

    #[test]
    fn two_boxes_overlapping_by_half() {
        let a = placed(PartShape::Box([0.5; 3]), [0.0; 3], [0.5; 3], 1.0);
        let b = placed(PartShape::Box([0.5; 3]), [0.5, 0.0, 0.0], [0.5; 3], 1.0);
        let (v, _) = overlap_volume(&a, &b).expect("overlap");
        assert!((v - 0.5).abs() < 1e-12, "{v}");
    }

    #[test]
    fn boxes_overlap_but_solids_do_not() {
        // A small box in the corner of a sphere's bounding box, outside the sphere.
        let s = placed(
            PartShape::Sphere(1.0),
            [0.0; 3],
            [1.0; 3],
            4.0 / 3.0 * std::f64::consts::PI,
        );
        let b = placed(PartShape::Box([0.1; 3]), [0.9, 0.9, 0.9], [0.1; 3], 0.008);
        let (v, _) = overlap_volume(&s, &b).expect("boxes overlap");
        assert_eq!(v, 0.0);
    }

    #[test]
    fn winding_number_of_a_closed_box() {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let quads = [
            [0u32, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let tris: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        let raw = crate::mesh::RawMesh {
            vertices: v,
            faces: crate::mass::Polygons::from_triangles(&tris),
            ..Default::default()
        };
        let solid =
            crate::mesh::health::make_solid(&raw, std::path::Path::new("box"), Default::default())
                .expect("solid");
        assert!((winding_number(&solid, [0.5, 0.5, 0.5]) - 1.0).abs() < 1e-12);
        assert!(winding_number(&solid, [1.5, 0.5, 0.5]).abs() < 1e-12);
    }
}
