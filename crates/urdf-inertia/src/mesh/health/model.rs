//! The error model: volumes by which a solid can differ from the stored surface, turned into relative
//! bounds on volume, inertia and centre of mass; the round-off estimate and the empty-solid check.

use super::geometry::{dist, polygon_area};
use super::{ModelError, ROUND_OFF_FLOOR, ZERO_VOLUME_ROUNDOFFS};
use crate::geometry::Aabb;
use crate::mass::integrals::Rounding;
use crate::mass::{frobenius, MassProperties, Polygons};
use crate::mesh::MeshError;
use std::path::Path;

/// Where the volume of a model error may sit: anywhere in the solid, near given points (the loops a
/// cap closes), or in a ball (centre, radius).
pub(super) enum Lever {
    Anywhere,
    Near(Vec<[f64; 3]>),
    Ball([f64; 3], f64),
}

/// A model error: volumes (m³) by which the solid can differ from the stored surface, each with where
/// it sits, and what the largest is made of.
pub(super) struct Model {
    pub(super) terms: Vec<(f64, Lever)>,
    /// What the rung's surface, closed only up to cracks, moves with the reference point, m³,
    /// anywhere ([`super::closed::open_volume`] of the faces as the rung integrates them).
    pub(super) cracks: f64,
    /// What the rung's re-orientation of faces against the file can change, m³, anywhere: components
    /// turned round inside another's box, and faces flipped against the rest of their component
    /// ([`super::closed::Outward`]). Kept apart because it describes nothing once every face turned
    /// round is integrated in its stored orientation ([`Model::as_stored_orientation`]).
    pub(super) orientation: f64,
    pub(super) source: ModelError,
}

impl From<(f64, ModelError)> for Model {
    fn from((delta, source): (f64, ModelError)) -> Model {
        Model {
            terms: vec![(delta, Lever::Anywhere)],
            cracks: 0.0,
            orientation: 0.0,
            source,
        }
    }
}

/// A model error as relative bounds.
pub(super) struct Bound {
    /// On volume and central inertia.
    pub(super) relative: f64,
    /// On the centre of mass, m.
    pub(super) com: f64,
}

impl Model {
    /// A rung that integrates the faces as it re-oriented them: `cracks`, what the surface left
    /// open can move, and `orientation`, what the re-orientation can change; the source is the
    /// orientation when it is in the model at all.
    pub(super) fn reoriented(cracks: f64, orientation: f64) -> Model {
        Model {
            terms: Vec::new(),
            cracks,
            orientation,
            source: if orientation > 0.0 {
                ModelError::Orientation
            } else {
                ModelError::Cracks
            },
        }
    }

    /// Every face the rung turned round is integrated as stored (the shells' decision turned each
    /// back and decided it by the winding number of the file's surface): the re-orientation no
    /// longer enters the solid, so its term goes, and the cracks are what the surface integrated
    /// now leaves open, `cracks` ([`super::closed::open_volume`] of it), not what the rung's
    /// turned faces did. What else the rung assumed stays.
    pub(super) fn as_stored_orientation(&mut self, cracks: f64) {
        self.orientation = 0.0;
        self.cracks = cracks;
        if self.source == ModelError::Orientation {
            self.source = ModelError::Cracks;
        }
    }

    /// No term at all: the solid is Ω of the file's surface up to the bounds added later.
    pub(super) fn clear(&mut self) {
        self.terms.clear();
        self.cracks = 0.0;
        self.orientation = 0.0;
    }

    /// The sum of the terms, m³.
    pub(super) fn total(&self) -> f64 {
        self.terms.iter().map(|t| t.0).sum::<f64>() + self.cracks + self.orientation
    }

    /// The relative error that volumes δᵢ moved, added or removed at distances up to Rᵢ from the
    /// centre of mass can cause, against the true value (at least the computed one less the change):
    /// for the volume Σδ/(V − Σδ); for the central inertia 3·Σδ·R²/(‖I‖ − 3·Σδ·R²) (a point mass δ at
    /// distance R changes the tensor by at most √2·δ·R², and the centre of mass it moves by as much
    /// again); for the centre of mass Σδ·R/(V − Σδ). Unbounded when the change could be as large as
    /// the value itself.
    pub(super) fn bound(&self, unit: &MassProperties, vertices: &[[f64; 3]]) -> Bound {
        let (mut volume, mut inertia, mut moment) = (0.0, 0.0, 0.0);
        let rung = [(self.cracks, &Lever::Anywhere), (self.orientation, &Lever::Anywhere)];
        let terms = self.terms.iter().map(|(d, l)| (*d, l));
        // One pass over the vertices for every term that may sit anywhere.
        let mut anywhere = None;
        for (delta, lever) in terms.chain(rung) {
            if delta == 0.0 {
                continue;
            }
            let r = match lever {
                Lever::Anywhere => *anywhere.get_or_insert_with(|| reach(unit, vertices)),
                Lever::Near(points) => reach(unit, points),
                Lever::Ball(centre, radius) => dist(*centre, unit.com) + radius,
            };
            volume += delta;
            inertia += 3.0 * delta * r * r;
            moment += delta * r;
        }
        if volume == 0.0 {
            return Bound {
                relative: 0.0,
                com: 0.0,
            };
        }
        let bounded = |change: f64, value: f64| {
            if change < value {
                change / (value - change)
            } else {
                f64::INFINITY
            }
        };
        Bound {
            relative: bounded(volume, unit.mass).max(bounded(inertia, frobenius(&unit.inertia))),
            com: bounded(moment, unit.mass - volume + moment),
        }
    }
}

/// The largest distance of a vertex from the centre of mass.
/// A large mesh's on the pool ([`crate::mesh::chunked`]; the largest of the chunks' largest is the
/// largest).
pub(super) fn reach(unit: &MassProperties, vertices: &[[f64; 3]]) -> f64 {
    let largest = |c: &[[f64; 3]]| c.iter().map(|v| dist(*v, unit.com)).fold(0.0, f64::max);
    crate::mesh::chunked(vertices, largest, f64::max)
}

/// The round-off estimate: the relative disagreement of volume and central inertia integrated about
/// two reference points (`base` about the bounding-box centre, `other` about its corner), never
/// below [`ROUND_OFF_FLOOR`].
pub(super) fn round_off_against(other: &MassProperties, base: &MassProperties) -> f64 {
    let mut d = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = other.inertia[i][j] - base.inertia[i][j];
        }
    }
    let n = frobenius(&base.inertia);
    let inertia = if n > 0.0 {
        frobenius(&d) / n
    } else {
        f64::INFINITY
    };
    let volume = ((other.mass - base.mass) / base.mass).abs();
    inertia.max(volume).max(ROUND_OFF_FLOOR)
}

/// A solid is empty when its volume is within a thousand round-offs of its faces' contributions
/// (Σ face area × diagonal): relative to the surface, so a needle 1e-6 × 1e-6 × 1 (volume 1e-12 of
/// its diagonal cubed), rotated or not, is a solid, and a flat or doubly covered sheet is not.
pub(super) fn check_volume(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    bounds: Aabb,
    volume: f64,
    path: &Path,
) -> Result<(), MeshError> {
    if empty(vertices, faces, bounds.diagonal(), volume) {
        return Err(MeshError::zero_volume(path, volume, bounds));
    }
    Ok(())
}

/// Whether `volume` is NaN or at most the floor of [`check_volume`], the floor taken from the area
/// summed face by face in order. On more than one thread a large mesh's area is summed in chunks on
/// the pool first: that sum and the sequential one differ by less than `slack` of either (each is
/// within (n − 1)·u of the exact sum of n non-negative terms), and the floor grows with the area
/// (products by positive factors round monotonically), so a volume outside the floors of the area
/// ± `slack` is decided as the sequential sum decides it; only a volume inside that band, which a
/// solid is not, sums again in order.
///
/// Most solids are decided before any sum, by a bound on the area: `diagonal` is that of a box
/// holding every vertex, so each side of a fan triangle is at most D = `diagonal` long and its area at
/// most D²/2, and a face of k corners has k − 2 of them. The sequential sum as computed is within a
/// factor (1 + n·u)(1 + c·k·u) of the exact sum (n faces, u the unit round-off), well below 2, so it is at most (corners) · D²: a
/// volume above the floor of that bound is above the floor of the sum (the floor grows with the
/// area, as above), which is what the sum would decide. The floor is 1e-13 of the area times D, so
/// only meshes thin next to their number of faces (a 1.3 M-face torus would need a volume below
/// 2e-5 of D³) go on to the sums. This skips a pass over every face and its corners (77
/// instructions a face of 1,302 on a 1.3 M-face binary STL; docs/benchmarks.md, round seven).
fn empty(vertices: &[[f64; 3]], faces: &Polygons, diagonal: f64, volume: f64) -> bool {
    let floor = |area: f64| ZERO_VOLUME_ROUNDOFFS * f64::EPSILON * area * diagonal;
    if volume.is_nan() {
        return true;
    }
    let area_bound = faces.indices.len() as f64 * diagonal * diagonal;
    if volume > floor(area_bound) {
        return false;
    }
    if let Some(area) = chunked_area(vertices, faces) {
        let slack = 4.0 * faces.len() as f64 * f64::EPSILON;
        if area.is_finite() && slack < 0.5 {
            if volume <= floor(area * (1.0 - slack)) {
                return true;
            }
            if volume > floor(area * (1.0 + slack)) {
                return false;
            }
        }
    }
    let area: f64 = faces.iter().map(|f| polygon_area(vertices, f)).sum();
    volume <= floor(area)
}

/// Faces per chunk of [`chunked_area`]; meshes of fewer than two chunks are summed in order.
const AREA_CHUNK: usize = 1 << 15;

/// The faces' area summed in fixed chunks on the pool, when it has more than one thread and the mesh
/// at least two chunks: on one thread the sequential sum is all [`empty`] needs.
fn chunked_area(vertices: &[[f64; 3]], faces: &Polygons) -> Option<f64> {
    use rayon::prelude::*;
    let n = faces.len();
    if n < 2 * AREA_CHUNK {
        return None;
    }
    crate::threads::install(|| {
        if rayon::current_num_threads() < 2 {
            return None;
        }
        let sums: Vec<f64> = (0..n.div_ceil(AREA_CHUNK))
            .into_par_iter()
            .map(|c| {
                (c * AREA_CHUNK..((c + 1) * AREA_CHUNK).min(n))
                    .map(|i| polygon_area(vertices, faces.face(i)))
                    .sum()
            })
            .collect();
        Some(sums.iter().sum())
    })
}

/// A bound on the kernel's round-off: the relative error of volume and central inertia that the
/// triangle kernel's arithmetic, about `reference` (the point it integrated about), can make, from
/// the bounds on its ten integrals that the same pass added up face by face ([`Rounding`]), first
/// order in ε with generous constants, never below [`ROUND_OFF_FLOOR`].
///
/// [`round_off_against`] compares two evaluations; it sees how much the faces' contributions
/// cancel, but only as one sample of the error. Where the winding number leaves a thin solid of
/// large faces (two shells an ulp apart, one wound outward and one inward, leave a slab between
/// them), the contributions about the reference cancel by a factor of a thousand and the sample
/// fell 1.2 to 2.75 times below the error (sweep cases 587, 1654, 1725 and 4371 of
/// `tests/union_sweep.rs`); on clean closed surfaces far from the origin 1.10 and 1.49 times
/// (cases 10598 and 25299). So every solid reports this bound, and the sample serves only to find
/// decided faces that do not close ([`super::ladder::Ladder::finish`]).
pub(super) fn round_off_bound(rounding: &Rounding, reference: [f64; 3], unit: &MassProperties) -> f64 {
    central_rounding(&rounding.bounds(), reference, unit)
}

/// Half an ulp of 1.
const EPS: f64 = f64::EPSILON / 2.0;

/// [`round_off_bound`] from the bounds `t` on the ten integrals about `reference`: the central
/// tensor is `C_ij = T_ij − r_i·T_j` with `r = T_i / T1` ([`MassProperties::from_integrals`]), so
/// first order in the integrals' errors, and 4ε of each value it adds.
fn central_rounding(t: &[f64; 10], reference: [f64; 3], unit: &MassProperties) -> f64 {
    let m = unit.mass.abs();
    if m.is_nan() || m == 0.0 || !t.iter().all(|x| x.is_finite()) {
        return f64::INFINITY;
    }
    let r: [f64; 3] = std::array::from_fn(|k| (unit.com[k] - reference[k]).abs());
    let i = &unit.inertia;
    let trace = i[0][0] + i[1][1] + i[2][2];
    let c_diag = [0, 1, 2].map(|k| (trace / 2.0 - i[k][k]).abs());
    let diag = |k: usize| {
        t[4 + k] + 2.0 * r[k] * t[1 + k] + r[k] * r[k] * t[0] + 4.0 * EPS * (c_diag[k] + m * r[k] * r[k])
    };
    // The product of axes x and x + 1 (xy, yz, zx: the integrals' order) with its entry.
    let pair = |x: usize| {
        let y = (x + 1) % 3;
        t[7 + x]
            + r[x] * t[1 + y]
            + r[y] * t[1 + x]
            + r[x] * r[y] * t[0]
            + 4.0 * EPS * (i[x][y].abs() + m * r[x] * r[y])
    };
    let dc = [diag(0), diag(1), diag(2)];
    let di = [
        [dc[1] + dc[2], pair(0), pair(2)],
        [pair(0), dc[2] + dc[0], pair(1)],
        [pair(2), pair(1), dc[0] + dc[1]],
    ];
    let n = frobenius(&unit.inertia);
    let inertia = if n > 0.0 {
        frobenius(&di) / n
    } else {
        f64::INFINITY
    };
    (t[0] / m).max(inertia).max(ROUND_OFF_FLOOR)
}

#[cfg(test)]
mod tests {
    use super::super::geometry::bbox;
    use super::*;

    /// The area bound decides only volumes the sum decides the same way: the faces' area as
    /// [`empty`] sums it stays below corners × D² for faces as large as the box allows (triangles on
    /// three corners of the box, a polygon of 1,000 corners around it), and volumes just above and
    /// below each floor are decided as the sequential sum decides them.
    #[test]
    fn the_area_bound_decides_as_the_sequential_floor() {
        let (lo, hi) = ([-1.0, -2.0, -0.5], [3.0, 0.5, 2.5]);
        let mut vertices: Vec<[f64; 3]> = (0..8)
            .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] }))
            .collect();
        let mut triangles = Vec::new();
        for a in 0..8u32 {
            for b in a + 1..8 {
                for c in b + 1..8 {
                    triangles.push([a, b, c]);
                }
            }
        }
        let mut faces = Polygons::from_triangles(&triangles);
        let ring = vertices.len() as u32;
        for i in 0..1000 {
            let t = f64::from(i) * std::f64::consts::TAU / 1000.0;
            vertices.push([1.0 + 2.0 * t.cos(), -0.75 + 1.25 * t.sin(), 1.0 + 1.5 * (3.0 * t).sin()]);
        }
        faces.push(&(ring..ring + 1000).collect::<Vec<_>>());
        let diagonal = bbox(&vertices).diagonal();
        let area: f64 = faces.iter().map(|f| polygon_area(&vertices, f)).sum();
        let bound = faces.indices.len() as f64 * diagonal * diagonal;
        assert!(2.0 * area <= bound, "{area} {bound}");
        let floor = |a: f64| ZERO_VOLUME_ROUNDOFFS * f64::EPSILON * a * diagonal;
        let step = |x: f64, d: i64| f64::from_bits((x.to_bits() as i64 + d) as u64);
        for volume in [
            floor(area),
            step(floor(area), 1),
            step(floor(area), -1),
            floor(bound),
            step(floor(bound), 1),
            step(floor(bound), -1),
            1.0,
        ] {
            assert_eq!(empty(&vertices, &faces, diagonal, volume), volume <= floor(area), "{volume}");
        }
    }

    /// On more than one thread, the chunked area decides as the sequential floor does, also for
    /// volumes on, just above and just below that floor (where it falls back to the sequential sum).
    #[test]
    fn the_chunked_area_decides_as_the_sequential_floor() {
        // A strip of 2^17 + 5 unequal triangles (more than two chunks, the last one short).
        let n = (1u32 << 17) + 5;
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..n {
            let x = f64::from(i);
            vertices.extend([[x, 0.0, 0.0], [x + 1.0, 0.1, 0.0], [x, 1.0 + x.sin() * 0.3, 0.7]]);
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let faces = Polygons::from_triangles(&triangles);
        let diagonal = 1.0e5;
        let area: f64 = faces.iter().map(|f| polygon_area(&vertices, f)).sum();
        let floor = ZERO_VOLUME_ROUNDOFFS * f64::EPSILON * area * diagonal;
        let step = |x: f64, d: i64| f64::from_bits((x.to_bits() as i64 + d) as u64);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("pool");
        pool.install(|| {
            assert!(chunked_area(&vertices, &faces).is_some());
            for volume in [
                0.0,
                floor,
                step(floor, 1),
                step(floor, -1),
                floor * (1.0 + 1e-9),
                floor * (1.0 - 1e-9),
                2.0 * floor,
                0.5 * floor,
                1.0,
            ] {
                assert_eq!(empty(&vertices, &faces, diagonal, volume), volume <= floor, "{volume}");
            }
            assert!(empty(&vertices, &faces, diagonal, f64::NAN));
        });
    }
}
