//! The numeric core: volume integrals, mass properties as values, primitives and validity checks.
//!
//! It knows nothing of files, XML or paths: it takes slices of points and faces and returns values.
//!
//! Conventions (URDF's): metres, kilograms, kg/m³; the inertia tensor is about the centre of mass, in the
//! axes of the frame the geometry was given in, with products of inertia as off-diagonal entries
//! `I_xy = −∫ρ xy dV` (so the matrix is positive definite).
//!
//! ```
//! use urdf_inertia::mass::{MassProperties, primitives};
//! // Problem 1 of the paper: a body made of parts, each with a density or a mass.
//! let a = primitives::cuboid([0.2, 0.1, 0.1], 2700.0);            // aluminium block
//! let b = primitives::sphere(0.05, 7850.0).translated([0.2, 0.0, 0.0]); // steel ball beside it
//! let body: MassProperties = [a, b].into_iter().sum();
//! assert!((body.mass - (2700.0 * 0.002 + 7850.0 * 4.0 / 3.0 * std::f64::consts::PI * 1.25e-4)).abs() < 1e-12);
//! ```

pub mod integrals;
pub mod jacobi;
pub mod primitives;
pub mod validity;

use std::iter::Sum;
use std::ops::Add;

#[cfg(any(test, feature = "internals"))]
pub use integrals::Summation;
pub use integrals::{IntegrationOptions, Polygons, VolumeIntegrals};

/// A 3×3 matrix as rows.
pub type Mat3 = [[f64; 3]; 3];

/// Mass, centre of mass and the full inertia tensor about the centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MassProperties {
    /// kg.
    pub mass: f64,
    /// Centre of mass, m, in the frame of the geometry.
    pub com: [f64; 3],
    /// Inertia about the centre of mass, kg·m², in the axes of the frame of the geometry.
    pub inertia: Mat3,
}

/// Principal moments (ascending) and the principal axes as the columns of a rotation (right-handed).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Principal {
    pub moments: [f64; 3],
    pub axes: Mat3,
}

impl MassProperties {
    /// Mass (kg), centre of mass (m) and the inertia tensor about the centre of mass (kg·m²), in
    /// the axes of the frame the centre of mass is given in.
    pub fn new(mass: f64, com: [f64; 3], inertia: Mat3) -> MassProperties {
        MassProperties { mass, com, inertia }
    }

    /// Nothing: the identity of `+`.
    pub const ZERO: MassProperties = MassProperties {
        mass: 0.0,
        com: [0.0; 3],
        inertia: [[0.0; 3]; 3],
    };

    /// From volume integrals and a uniform density.
    ///
    /// The central tensor is formed from the integrals about their (nearby) reference point and moved by
    /// the transfer-of-axis relations (12–14); each moment is computed directly (`Izz` from `Tx² + Ty²`).
    pub fn from_integrals(t: &VolumeIntegrals, density: f64) -> MassProperties {
        // Carried in double-double (the integrals' high and low parts) and rounded once per entry.
        let lo = &t.low;
        let v = Dd(t.t1, lo[0]);
        let first = [0, 1, 2].map(|k| Dd(t.t[k], lo[1 + k]));
        let vf = v.value();
        // COM relative to the reference, then absolute.
        let r = [0, 1, 2].map(|k| first[k].value() / vf);
        // Second moments about the COM (per unit density): ∫x² − rx ∫x, ∫xy − ry ∫x.
        let c2 = [0, 1, 2].map(|k| Dd(t.t2[k], lo[4 + k]).add(first[k].mul(-r[k])));
        let cp = [0, 1, 2].map(|k| Dd(t.tp[k], lo[7 + k]).add(first[k].mul(-r[(k + 1) % 3])));
        let ixx = c2[1].add(c2[2]).mul(density).value();
        let iyy = c2[2].add(c2[0]).mul(density).value();
        let izz = c2[0].add(c2[1]).mul(density).value();
        let ixy = -cp[0].mul(density).value();
        let iyz = -cp[1].mul(density).value();
        let izx = -cp[2].mul(density).value();
        MassProperties {
            mass: v.mul(density).value(),
            com: [
                t.reference[0] + r[0],
                t.reference[1] + r[1],
                t.reference[2] + r[2],
            ],
            inertia: [[ixx, ixy, izx], [ixy, iyy, iyz], [izx, iyz, izz]],
        }
    }

    /// The mass properties of a closed polygon mesh of uniform `density`, integrated as urdf-inertia does
    /// (about the bounding-box centre, compensated sums, accurate thin faces).
    pub fn from_mesh(vertices: &[[f64; 3]], faces: &Polygons, density: f64) -> MassProperties {
        let t = integrals::volume_integrals(vertices, faces, &IntegrationOptions::accurate());
        MassProperties::from_integrals(&t, density)
    }

    /// The same as [`MassProperties::from_mesh`] for a triangle mesh.
    pub fn from_trimesh(
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        density: f64,
    ) -> MassProperties {
        let t = integrals::triangle_integrals(vertices, triangles, &IntegrationOptions::accurate());
        MassProperties::from_integrals(&t, density)
    }

    /// The same body with every density multiplied by `factor` (mass and inertia scale, COM does not).
    #[must_use]
    pub fn scaled(&self, factor: f64) -> MassProperties {
        MassProperties {
            mass: self.mass * factor,
            com: self.com,
            inertia: self.inertia.map(|r| r.map(|x| x * factor)),
        }
    }

    /// The body moved by `t`: only the centre of mass changes.
    #[must_use]
    pub fn translated(&self, t: [f64; 3]) -> MassProperties {
        MassProperties {
            com: [self.com[0] + t[0], self.com[1] + t[1], self.com[2] + t[2]],
            ..*self
        }
    }

    /// The body rotated by `r` about the frame origin, then moved by `t`: `c' = R c + t`, `I' = R I Rᵀ`.
    #[must_use]
    pub fn transformed(&self, r: &Mat3, t: [f64; 3]) -> MassProperties {
        let c = mat_vec(r, self.com);
        MassProperties {
            mass: self.mass,
            com: [c[0] + t[0], c[1] + t[1], c[2] + t[2]],
            inertia: symmetrise(&mat_mul(&mat_mul(r, &self.inertia), &transpose(r))),
        }
    }

    /// The inertia tensor about point `p` (parallel-axis theorem), in the same axes.
    pub fn inertia_about(&self, p: [f64; 3]) -> Mat3 {
        let d = [self.com[0] - p[0], self.com[1] - p[1], self.com[2] - p[2]];
        let mut out = self.inertia;
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        for i in 0..3 {
            for j in 0..3 {
                let delta = if i == j { dd } else { 0.0 };
                out[i][j] += self.mass * (delta - d[i] * d[j]);
            }
        }
        out
    }

    /// Principal moments (ascending) and axes (right-handed), by Jacobi rotations.
    pub fn principal(&self) -> Principal {
        let (moments, axes) = jacobi::symmetric_eigen(self.inertia);
        Principal { moments, axes }
    }
}

impl Add for MassProperties {
    type Output = MassProperties;

    /// The disjoint union of two bodies (Problem 1): masses add, the COM is the mass-weighted mean, and
    /// each tensor is moved to the common COM by the parallel-axis theorem before adding.
    fn add(self, other: MassProperties) -> MassProperties {
        let mass = self.mass + other.mass;
        if mass == 0.0 {
            return MassProperties::ZERO;
        }
        let wb = other.mass / mass;
        // Weighted mean written as a + wb (b − a): exact when both COMs coincide, no cancellation far away.
        let com = [0, 1, 2].map(|k| self.com[k] + wb * (other.com[k] - self.com[k]));
        let ia = self.inertia_about(com);
        let ib = other.inertia_about(com);
        let mut inertia = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                inertia[i][j] = ia[i][j] + ib[i][j];
            }
        }
        MassProperties { mass, com, inertia }
    }
}

impl Sum for MassProperties {
    fn sum<I: Iterator<Item = MassProperties>>(iter: I) -> MassProperties {
        iter.fold(
            MassProperties::ZERO,
            |a, b| if a.mass == 0.0 { b } else { a + b },
        )
    }
}

/// A double-double number `hi + lo` (only what the final rounding of the tensor needs).
#[derive(Debug, Clone, Copy)]
struct Dd(f64, f64);

impl Dd {
    fn value(self) -> f64 {
        self.0 + self.1
    }
    fn add(self, o: Dd) -> Dd {
        let (s, e) = integrals::two_sum(self.0, o.0);
        let (h, l) = integrals::two_sum(s, e + self.1 + o.1);
        Dd(h, l)
    }
    fn mul(self, f: f64) -> Dd {
        let (p, e) = integrals::two_prod(self.0, f);
        let (h, l) = integrals::two_sum(p, e + self.1 * f);
        Dd(h, l)
    }
}

/// URDF's roll-pitch-yaw: fixed axes X, then Y, then Z, i.e. `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.
///
/// ```
/// let r = urdf_inertia::mass::rpy_matrix([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
/// // yaw 90°: x goes to y.
/// assert!((r[1][0] - 1.0).abs() < 1e-15 && r[0][0].abs() < 1e-15);
/// ```
pub fn rpy_matrix(rpy: [f64; 3]) -> Mat3 {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// The roll-pitch-yaw angles of a rotation matrix (inverse of [`rpy_matrix`]).
pub fn matrix_rpy(r: &Mat3) -> [f64; 3] {
    let pitch = (-r[2][0]).clamp(-1.0, 1.0).asin();
    if r[2][0].abs() < 1.0 - 1e-12 {
        [r[2][1].atan2(r[2][2]), pitch, r[1][0].atan2(r[0][0])]
    } else {
        // Gimbal lock: put everything into yaw.
        [0.0, pitch, (-r[0][1]).atan2(r[1][1])]
    }
}

pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    m
}

pub fn mat_vec(a: &Mat3, v: [f64; 3]) -> [f64; 3] {
    // Written out: `[0, 1, 2].map(..)` was a call per vector in profiles (core::array::try_map).
    let row = |r: &[f64; 3]| r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
    [row(&a[0]), row(&a[1]), row(&a[2])]
}

pub fn transpose(a: &Mat3) -> Mat3 {
    [
        [a[0][0], a[1][0], a[2][0]],
        [a[0][1], a[1][1], a[2][1]],
        [a[0][2], a[1][2], a[2][2]],
    ]
}

fn symmetrise(a: &Mat3) -> Mat3 {
    let mut m = *a;
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let s = 0.5 * (a[i][j] + a[j][i]);
        m[i][j] = s;
        m[j][i] = s;
    }
    m
}

/// Frobenius norm of a matrix.
pub fn frobenius(a: &Mat3) -> f64 {
    a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_is_fixed_axis_xyz() {
        // roll 90° then yaw 90° (fixed axes): z → -y (roll) → x (yaw).
        let r = rpy_matrix([
            std::f64::consts::FRAC_PI_2,
            0.0,
            std::f64::consts::FRAC_PI_2,
        ]);
        let z = mat_vec(&r, [0.0, 0.0, 1.0]);
        assert!(
            (z[0] - 1.0).abs() < 1e-15 && z[1].abs() < 1e-15 && z[2].abs() < 1e-15,
            "{z:?}"
        );
        let back = matrix_rpy(&rpy_matrix([0.1, -0.4, 2.5]));
        for (a, b) in back.iter().zip([0.1, -0.4, 2.5]) {
            assert!((a - b).abs() < 1e-14);
        }
    }

    #[test]
    fn parallel_axis_of_point_masses() {
        let a = MassProperties {
            mass: 1.0,
            com: [1.0, 0.0, 0.0],
            inertia: [[0.0; 3]; 3],
        };
        let b = MassProperties {
            mass: 1.0,
            com: [-1.0, 0.0, 0.0],
            inertia: [[0.0; 3]; 3],
        };
        let s = a + b;
        assert_eq!(s.com, [0.0; 3]);
        assert_eq!(
            s.inertia,
            [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]]
        );
    }
}
