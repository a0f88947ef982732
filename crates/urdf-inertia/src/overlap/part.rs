//! A part placed in a link, and the tests of points and cells against it.

use super::{Aabb, PartShape};
use crate::mass::{mat_vec, transpose, Mat3};
use crate::mesh::inside::MeshLocator;
use std::sync::Arc;

/// A part placed in the link frame: `x_link = R x_part + t`.
#[derive(Debug, Clone)]
pub struct PlacedPart {
    pub shape: PartShape,
    pub rotation: Mat3,
    pub translation: [f64; 3],
    /// Bounding box in the link frame.
    pub bbox: Aabb,
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

    /// Where the box of centre `x` and half sides `h` (link frame) lies: `Some(true)` when every
    /// point of it is surely inside the solid, `Some(false)` when surely outside, `None` when the
    /// part's surface may cross it. A verdict is what [`Self::contains`] says of `x`.
    ///
    /// With `decide` false the caller wants only whether the surface may cross the box: a mesh then
    /// answers `Some(false)` for a box its surface misses, inside or not, without the point test
    /// that would tell which (primitives decide at no cost and answer as ever).
    pub(super) fn classify(&self, x: [f64; 3], h: [f64; 3], decide: bool) -> Option<bool> {
        let rt = transpose(&self.rotation);
        let q = mat_vec(&rt, [0, 1, 2].map(|k| x[k] - self.translation[k]));
        // The box's bounding box in the part's frame, grown by far more than the rounding of `q`
        // (a few ulps of its coordinates), so that the verdict holds for the box as it is exactly.
        let size = (0..3).fold(0.0f64, |m, k| m.max(q[k].abs()).max(h[k]));
        let e =
            [0, 1, 2].map(|k| (0..3).map(|m| rt[k][m].abs() * h[m]).sum::<f64>() + 1e-12 * size);
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        // `d` ± `r` against `limit`: the distance `d` of the centre from a centre set, moved by at most
        // the box's radius `r`, either way.
        let verdict = |inside: bool, outside: bool| {
            if inside {
                Some(true)
            } else if outside {
                Some(false)
            } else {
                None
            }
        };
        let around = |d: f64, r: f64, limit: f64| verdict(d + r < limit, d - r > limit);
        match &self.shape {
            PartShape::Box(hb) => verdict(
                (0..3).all(|k| q[k].abs() + e[k] < hb[k]),
                (0..3).any(|k| q[k].abs() - e[k] > hb[k]),
            ),
            PartShape::Sphere(r) => around(norm(q), norm(e), *r),
            PartShape::Cylinder(r, hl) => {
                let (rho, re) = (q[0].hypot(q[1]), e[0].hypot(e[1]));
                verdict(
                    rho + re < *r && q[2].abs() + e[2] < *hl,
                    rho - re > *r || q[2].abs() - e[2] > *hl,
                )
            }
            PartShape::Capsule(r, hl) => {
                let z = q[2].clamp(-hl, *hl);
                around(norm([q[0], q[1], q[2] - z]), norm(e), *r)
            }
            PartShape::Mesh(_) => {
                let locator = self.locator.as_ref()?;
                let surface = locator.surface.as_ref()?;
                let b = Aabb::new(
                    [0, 1, 2].map(|k| q[k] - e[k]),
                    [0, 1, 2].map(|k| q[k] + e[k]),
                );
                (!surface.may_meet(&b)).then(|| decide && locator.contains(q))
            }
        }
    }

    /// Builds the mesh locator if this part is a mesh, over the triangles that can decide a point of
    /// `region` (link frame; the only points it will be tested at). Returns a bound on what one point
    /// test costs, in primitive tests, by the measure [`grid_size`] has always used (the whole-mesh
    /// locator's, [`MeshLocator::whole_mesh_cost`]; `usize::MAX / 4` when that bound says nothing).
    /// `None` when the mesh has more triangles than [`LOCATOR_ENTRIES`] (it cannot be located).
    pub(super) fn prepare(&mut self, region: &Aabb) -> Option<usize> {
        let PartShape::Mesh(solid) = &self.shape else {
            return Some(1);
        };
        let rt = transpose(&self.rotation);
        let Aabb { lo, hi } = Aabb::of((0..8).map(|c| {
            let x = [0, 1, 2].map(|k| {
                if c >> k & 1 == 0 {
                    region.lo[k]
                } else {
                    region.hi[k]
                }
            });
            mat_vec(&rt, [0, 1, 2].map(|k| x[k] - self.translation[k]))
        }));
        // Points are moved into the mesh frame one by one, each with its own rounding (~1e-16 of its
        // coordinates): a margin far above that keeps every triangle that can decide one of them.
        let scale = (0..3).fold(0.0f64, |m, k| m.max(lo[k].abs()).max(hi[k].abs()));
        let pad = 1e-9 * scale;
        let region = Aabb::new(lo.map(|v| v - pad), hi.map(|v| v + pad));
        let (locator, bound) = MeshLocator::within(solid, &region)?;
        self.locator = Some(Arc::new(locator));
        Some(bound.unwrap_or(usize::MAX / 4))
    }
}
