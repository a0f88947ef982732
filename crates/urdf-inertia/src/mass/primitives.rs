//! Analytic mass properties of URDF's primitives, centred at the frame origin.
//!
//! Cylinders and capsules run along **Z** (URDF's convention; parry's run along Y). A capsule's `length`
//! is that of its cylindrical part, as in URDF's `<capsule radius length>` and SDF.

use super::MassProperties;
use std::f64::consts::PI;

fn diagonal(mass: f64, d: [f64; 3]) -> MassProperties {
    MassProperties {
        mass,
        com: [0.0; 3],
        inertia: [[d[0], 0.0, 0.0], [0.0, d[1], 0.0], [0.0, 0.0, d[2]]],
    }
}

/// A box with edge lengths `size` (x, y, z).
pub fn cuboid(size: [f64; 3], density: f64) -> MassProperties {
    let [x, y, z] = size;
    let m = density * x * y * z;
    diagonal(
        m,
        [
            m * (y * y + z * z) / 12.0,
            m * (z * z + x * x) / 12.0,
            m * (x * x + y * y) / 12.0,
        ],
    )
}

/// A solid cylinder of `radius` and `length` along Z.
pub fn cylinder(radius: f64, length: f64, density: f64) -> MassProperties {
    let r2 = radius * radius;
    let m = density * PI * r2 * length;
    let ixx = m * (3.0 * r2 + length * length) / 12.0;
    diagonal(m, [ixx, ixx, m * r2 / 2.0])
}

/// A solid sphere of `radius`.
pub fn sphere(radius: f64, density: f64) -> MassProperties {
    let m = density * 4.0 / 3.0 * PI * radius.powi(3);
    let i = 0.4 * m * radius * radius;
    diagonal(m, [i, i, i])
}

/// The half of a solid sphere of `radius` centred at the origin on the side of +Z (its flat face in
/// the XY plane): COM 3r/8 above the face; 2/5 m r² about Z, and about X and Y through the COM
/// 2/5 m r² less m (3r/8)², that is 83/320 m r².
pub fn hemisphere(radius: f64, density: f64) -> MassProperties {
    let r2 = radius * radius;
    let m = density * 2.0 / 3.0 * PI * r2 * radius;
    let ixx = m * r2 * 83.0 / 320.0;
    MassProperties {
        com: [0.0, 0.0, 0.375 * radius],
        ..diagonal(m, [ixx, ixx, 0.4 * m * r2])
    }
}

/// A capsule along Z: a cylinder of `radius` and `length` capped by two hemispheres.
pub fn capsule(radius: f64, length: f64, density: f64) -> MassProperties {
    let r2 = radius * radius;
    let mc = density * PI * r2 * length;
    let ms = density * 4.0 / 3.0 * PI * r2 * radius;
    // Each hemisphere: 2/5 m r² about an axis through its flat face, COM 3r/8 from that face, moved to
    // L/2 + 3r/8 from the centre: m (2r²/5 + L²/4 + 3Lr/8) for both together.
    let ixx = mc * (3.0 * r2 + length * length) / 12.0
        + ms * (0.4 * r2 + length * length / 4.0 + 0.375 * length * radius);
    let izz = mc * r2 / 2.0 + ms * 0.4 * r2;
    diagonal(mc + ms, [ixx, ixx, izz])
}
