//! Small integrals and boxes the rungs share.

use crate::geometry::{cross, dot, sub};
use crate::mass::integrals::{bounding_box_centre, volume_integrals};
use crate::mass::{IntegrationOptions, MassProperties, Polygons};

pub(super) fn unit_props(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    reference: Option<[f64; 3]>,
) -> MassProperties {
    let opts = IntegrationOptions {
        reference,
        ..IntegrationOptions::accurate()
    };
    MassProperties::from_integrals(&volume_integrals(vertices, faces, &opts), 1.0)
}

pub(super) fn signed_volume(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    volume_integrals(vertices, faces, &IntegrationOptions::accurate()).t1
}

/// The bounding box of `vertices`, a large mesh's on the pool ([`crate::mesh::chunked`]).
pub(super) fn bbox(vertices: &[[f64; 3]]) -> Aabb {
    crate::mesh::bounds(vertices)
}


/// Six times the signed volume of each connected component (about the bounding-box centre).
pub(super) fn component_volumes(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    comp: &[u32],
    ncomp: usize,
) -> Vec<f64> {
    let centre = bounding_box_centre(vertices);
    let mut vol = vec![0.0f64; ncomp];
    for (i, face) in faces.iter().enumerate() {
        let a = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let b = sub(vertices[face[k] as usize], centre);
            let c = sub(vertices[face[k + 1] as usize], centre);
            vol[comp[i] as usize] += dot(a, cross(b, c));
        }
    }
    vol
}

pub use crate::geometry::Aabb;

pub(super) fn component_boxes(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    comp: &[u32],
    ncomp: usize,
) -> Vec<Aabb> {
    let mut boxes = vec![Aabb::EMPTY; ncomp];
    for (i, face) in faces.iter().enumerate() {
        let b = &mut boxes[comp[i] as usize];
        for &v in face {
            b.add(vertices[v as usize]);
        }
    }
    boxes
}


/// The length of the surface's vector area `Σ N/2` (zero for a closed surface).
pub(super) fn vector_area(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    let centre = bounding_box_centre(vertices);
    let mut a = [0.0f64; 3];
    for face in faces.iter() {
        let p = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let e1 = sub(sub(vertices[face[k] as usize], centre), p);
            let e2 = sub(sub(vertices[face[k + 1] as usize], centre), p);
            let x = cross(e1, e2);
            for j in 0..3 {
                a[j] += 0.5 * x[j];
            }
        }
    }
    dot(a, a).sqrt()
}

/// Area of a planar polygon (fan from its first vertex).
#[inline(always)]
pub(super) fn polygon_area(vertices: &[[f64; 3]], face: &[u32]) -> f64 {
    let p = vertices[face[0] as usize];
    let mut a = [0.0f64; 3];
    for k in 1..face.len().saturating_sub(1) {
        let x = cross(
            sub(vertices[face[k] as usize], p),
            sub(vertices[face[k + 1] as usize], p),
        );
        for j in 0..3 {
            a[j] += 0.5 * x[j];
        }
    }
    dot(a, a).sqrt()
}

pub(super) fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

impl super::Solid {
    /// [`crate::millimetre_slip`] of the solid's vertices, from the box found with the integrals
    /// instead of a pass over them.
    pub fn millimetre_slip(&self, scale: [f64; 3]) -> Option<String> {
        crate::fill::slip_message(self.bbox().diagonal(), scale)
    }

    /// [`super::Solid::bounds`] as a box.
    fn bbox(&self) -> Aabb {
        Aabb::new(self.bounds[0], self.bounds[1])
    }

    /// The largest magnitude of a vertex coordinate (0 without vertices): the scale of the centre
    /// of mass, which `mesh` rounds against. Read from the box found with the integrals.
    pub fn largest_coordinate(&self) -> f64 {
        if self.vertices.is_empty() {
            return 0.0;
        }
        let b = self.bbox();
        // On each axis the coordinate of largest magnitude is the box's lowest or highest.
        b.lo.iter().chain(&b.hi).fold(0.0, |m, x| m.max(x.abs()))
    }
}
