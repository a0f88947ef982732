//! Convex hull of a point set: the fallback solid for open meshes, via parry3d-f64's quickhull.
//!
//! chull was tried first and dropped: it fails with `RoundOffError("concave")` on real meshes of
//! example-robot-data (go1 trunk.dae).
//!
//! Points are centred and scaled to a unit box first, so the hull's absolute tolerances mean the same for
//! a millimetre part and a metre part. The hull's faces are returned outward.

use parry3d_f64::math::Vector3;
use parry3d_f64::transformation::{try_convex_hull, ConvexHullError};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Vertices and outward triangles.
pub type TriangleMesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Why no hull could be built.
#[derive(Debug, Clone, PartialEq)]
pub enum HullError {
    /// Fewer than four points, or all points (nearly) on a plane or a line.
    Degenerate,
    /// The hull algorithm failed (round-off); the message is parry's.
    Failed(String),
    /// More candidate points than [`MAX_POINTS`] remain after the exact reduction.
    TooManyPoints(usize),
}

/// Largest number of candidate points handed to quickhull. parry's quickhull needs memory quadratic
/// in the points when many are coplanar (40,000 points on four circles: 0.9 GB here, 12 GB in another
/// arrangement); 8,000 keeps the worst case under about 0.5 GB.
pub const MAX_POINTS: usize = 8_000;

/// Size of the subset whose hull pre-filters the points.
const SUBSET: usize = 1_000;

/// The convex hull of `points` as (hull vertices, outward triangles).
pub fn convex_hull(points: &[[f64; 3]]) -> Result<TriangleMesh, HullError> {
    if points.len() < 4 {
        return Err(HullError::Degenerate);
    }
    let centre = crate::mass::integrals::bounding_box_centre(points);
    let size = points.iter().fold(0.0f64, |m, p| {
        m.max((p[0] - centre[0]).abs())
            .max((p[1] - centre[1]).abs())
            .max((p[2] - centre[2]).abs())
    });
    if size == 0.0 || !size.is_finite() {
        return Err(HullError::Degenerate);
    }
    let mut normalised: Vec<Vector3> = points
        .iter()
        .map(|p| {
            Vector3::new(
                (p[0] - centre[0]) / size,
                (p[1] - centre[1]) / size,
                (p[2] - centre[2]) / size,
            )
        })
        .collect();
    if normalised.len() > MAX_POINTS {
        normalised = reduce(normalised)?;
    }
    let result = catch_unwind(AssertUnwindSafe(|| try_convex_hull(&normalised)));
    let (hv, hi) = match result {
        Ok(Ok(h)) => h,
        Ok(Err(ConvexHullError::IncompleteInput))
        | Ok(Err(ConvexHullError::MissingSupportPoint)) => return Err(HullError::Degenerate),
        Ok(Err(e)) => return Err(HullError::Failed(e.to_string())),
        Err(_) => return Err(HullError::Failed("the hull algorithm panicked".into())),
    };
    let verts: Vec<[f64; 3]> = hv.iter().map(|p| [p.x, p.y, p.z]).collect();
    let vertices: Vec<[f64; 3]> = verts
        .iter()
        .map(|p| {
            [
                p[0] * size + centre[0],
                p[1] * size + centre[1],
                p[2] * size + centre[2],
            ]
        })
        .collect();
    let mut tris: Vec<[u32; 3]> = hi;
    // Coplanar input gives a flat "hull" (both sides of a polygon): no volume.
    let volume = crate::mass::integrals::triangle_integrals(
        &verts,
        &tris,
        &crate::mass::IntegrationOptions::accurate(),
    )
    .t1
    .abs();
    if tris.is_empty() || volume < 1e-12 {
        return Err(HullError::Degenerate);
    }
    orient_outward(&verts, &mut tris);
    Ok((vertices, tris))
}

/// Orients every facet outward: away from the hull's interior point (the vertex mean).
fn orient_outward(verts: &[[f64; 3]], tris: &mut [[u32; 3]]) {
    let n = verts.len() as f64;
    let inner = [0, 1, 2].map(|k| verts.iter().map(|p| p[k]).sum::<f64>() / n);
    for t in tris.iter_mut() {
        let (a, b, c) = (
            &verts[t[0] as usize],
            &verts[t[1] as usize],
            &verts[t[2] as usize],
        );
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let nrm = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let out =
            (a[0] - inner[0]) * nrm[0] + (a[1] - inner[1]) * nrm[1] + (a[2] - inner[2]) * nrm[2];
        if out < 0.0 {
            t.swap(1, 2);
        }
    }
}

/// Drops points that cannot be hull vertices: those strictly inside the hull of an evenly spaced
/// subset (by more than 1e-9 of the unit box the points are scaled to). The hull of what remains is
/// the hull of all points. Fails when more than [`MAX_POINTS`] remain.
fn reduce(points: Vec<Vector3>) -> Result<Vec<Vector3>, HullError> {
    let step = points.len().div_ceil(SUBSET);
    let subset: Vec<Vector3> = points.iter().step_by(step).copied().collect();
    let planes: Vec<(Vector3, f64)> =
        match catch_unwind(AssertUnwindSafe(|| try_convex_hull(&subset))) {
            Ok(Ok((hv, hi))) => {
                let n = hv.len() as f64;
                let inner = hv.iter().fold(Vector3::ZERO, |a, p| a + p) / n;
                hi.iter()
                    .filter_map(|t| {
                        let (a, b, c) = (hv[t[0] as usize], hv[t[1] as usize], hv[t[2] as usize]);
                        let mut nrm = (b - a).cross(c - a);
                        let len = nrm.length();
                        if len == 0.0 {
                            return None;
                        }
                        nrm /= len;
                        if nrm.dot(a - inner) < 0.0 {
                            nrm = -nrm;
                        }
                        Some((nrm, nrm.dot(a)))
                    })
                    .collect()
            }
            _ => Vec::new(),
        };
    let kept: Vec<Vector3> = if planes.is_empty() {
        points
    } else {
        points
            .into_iter()
            .filter(|p| planes.iter().any(|(n, d)| n.dot(*p) - d > -1e-9))
            .collect()
    };
    if kept.len() > MAX_POINTS {
        return Err(HullError::TooManyPoints(kept.len()));
    }
    Ok(kept)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_cube_corners_and_interior_points() {
        let mut pts: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                [
                    f64::from(i & 1),
                    f64::from((i >> 1) & 1),
                    f64::from((i >> 2) & 1),
                ]
            })
            .collect();
        pts.push([0.5, 0.5, 0.5]);
        pts.push([0.2, 0.7, 0.1]);
        let (v, t) = convex_hull(&pts).expect("hull");
        let mp = crate::mass::MassProperties::from_trimesh(&v, &t, 1.0);
        assert!((mp.mass - 1.0).abs() < 1e-14, "{}", mp.mass);
        for k in 0..3 {
            assert!((mp.com[k] - 0.5).abs() < 1e-14);
        }
    }

    #[test]
    fn millimetre_points_hull() {
        let pts: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                [
                    1e-3 * f64::from(i & 1) + 5.0,
                    1e-3 * f64::from((i >> 1) & 1),
                    1e-3 * f64::from((i >> 2) & 1),
                ]
            })
            .collect();
        let (v, t) = convex_hull(&pts).expect("hull");
        let mp = crate::mass::MassProperties::from_trimesh(&v, &t, 1.0);
        assert!((mp.mass - 1e-9).abs() < 1e-20, "{}", mp.mass);
    }

    #[test]
    fn flat_points_are_degenerate() {
        let pts: Vec<[f64; 3]> = (0..10)
            .map(|i| [f64::from(i), f64::from(i * i), 0.0])
            .collect();
        assert!(matches!(convex_hull(&pts), Err(HullError::Degenerate)));
    }

    #[test]
    fn many_points_inside_are_filtered_and_many_on_the_hull_refused() {
        // 20,000 points in a cube plus its corners: the hull is the cube.
        let mut rng = 1u64;
        let mut next = || crate::lcg_unit(&mut rng);
        let mut pts: Vec<[f64; 3]> = (0..20_000).map(|_| [next(), next(), next()]).collect();
        pts.extend((0..8).map(|i| {
            [
                f64::from(i & 1),
                f64::from((i >> 1) & 1),
                f64::from((i >> 2) & 1),
            ]
        }));
        let (v, t) = convex_hull(&pts).expect("hull");
        let mp = crate::mass::MassProperties::from_trimesh(&v, &t, 1.0);
        assert!((mp.mass - 1.0).abs() < 1e-14, "{}", mp.mass);
        // 40,000 points on four circles are all hull vertices: refused, not gigabytes.
        let circles: Vec<[f64; 3]> = (0..40_000)
            .map(|i| {
                let t = f64::from(i) * 2.0 * std::f64::consts::PI / 10_000.0;
                [t.cos(), t.sin(), f64::from(i % 4)]
            })
            .collect();
        assert!(
            matches!(convex_hull(&circles), Err(HullError::TooManyPoints(n)) if n > MAX_POINTS)
        );
    }
}
