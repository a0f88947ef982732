//! Physical validity of mass properties, with tolerances relative to the tensor's own size.
//!
//! No absolute floor: a 1 mm part has moments near 1e-10 kg·m² and must pass, which a floor such as
//! 1e-5 or 1e-15 on the moments would break.

use super::{jacobi, MassProperties};
use crate::text::significant as sig;

/// One way in which mass properties cannot belong to a physical body.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum Violation {
    /// A NaN or infinite value.
    NotFinite,
    /// Mass zero or negative.
    NonPositiveMass(f64),
    /// The tensor is not symmetric beyond round-off.
    NotSymmetric { asymmetry: f64 },
    /// The smallest principal moment is not positive (relative to the largest).
    NotPositiveDefinite { moments: [f64; 3] },
    /// A principal moment exceeds the sum of the other two (`I_a > I_b + I_c`).
    TriangleInequality { moments: [f64; 3], excess: f64 },
}

impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Violation::NotFinite => write!(f, "a value is NaN or infinite"),
            Violation::NonPositiveMass(m) => write!(f, "mass {m} is not positive"),
            Violation::NotSymmetric { asymmetry } => {
                write!(f, "inertia tensor is not symmetric (relative asymmetry {})", sig(*asymmetry, 4))
            }
            Violation::NotPositiveDefinite { moments } => write!(
                f,
                "inertia tensor is not positive definite (principal moments {}, {}, {})",
                sig(moments[0], 7), sig(moments[1], 7), sig(moments[2], 7)
            ),
            Violation::TriangleInequality { moments, excess } => write!(
                f,
                "principal moments {}, {}, {} break the triangle inequality: no body has them (the largest is {}% more than the sum of the other two)",
                sig(moments[0], 7), sig(moments[1], 7), sig(moments[2], 7), sig(*excess * 100.0 * largest_over_rest(moments), 3)
            ),
        }
    }
}

/// The largest principal moment over the sum of the other two: `excess` (relative to the largest)
/// becomes a share of that sum, the number a person checks (0.3 against 0.1 + 0.1: 50% more).
fn largest_over_rest(m: &[f64; 3]) -> f64 {
    let mut s = *m;
    s.sort_by(f64::total_cmp);
    let rest = s[0] + s[1];
    if rest > 0.0 {
        s[2] / rest
    } else {
        f64::INFINITY
    }
}

/// Default relative tolerance: round-off of an 8-significant-digit file is far above f64 eps.
pub const DEFAULT_TOLERANCE: f64 = 1e-9;

/// Every violation of `mp`, each judged relative to the largest principal moment.
pub fn check(mp: &MassProperties, rel_tol: f64) -> Vec<Violation> {
    let mut out = Vec::new();
    let finite = mp.mass.is_finite()
        && mp.com.iter().all(|x| x.is_finite())
        && mp.inertia.iter().flatten().all(|x| x.is_finite());
    if !finite {
        out.push(Violation::NotFinite);
        return out;
    }
    if mp.mass <= 0.0 {
        out.push(Violation::NonPositiveMass(mp.mass));
    }
    let i = &mp.inertia;
    let scale = i.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
    let asym = [(0, 1), (0, 2), (1, 2)]
        .iter()
        .map(|&(a, b)| (i[a][b] - i[b][a]).abs())
        .fold(0.0, f64::max);
    if scale > 0.0 && asym > rel_tol * scale {
        out.push(Violation::NotSymmetric {
            asymmetry: asym / scale,
        });
    }
    let (m, _) = jacobi::symmetric_eigen(*i);
    let largest = m[2].abs().max(m[0].abs());
    // Positive definite up to round-off: the smallest moment may sit a tolerance below zero (a rod
    // computed in floating point), never further, and the tensor may not vanish.
    if largest <= 0.0 || m[0] < -rel_tol * largest {
        out.push(Violation::NotPositiveDefinite { moments: m });
    }
    let excess = m[2] - (m[0] + m[1]);
    if largest > 0.0 && excess > rel_tol * largest {
        out.push(Violation::TriangleInequality {
            moments: m,
            excess: excess / largest,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::primitives;

    #[test]
    fn millimetre_part_is_valid() {
        // A 1 mm aluminium cube: moments near 4.5e-13 kg·m².
        let mp = primitives::cuboid([1e-3; 3], 2700.0);
        assert!(check(&mp, DEFAULT_TOLERANCE).is_empty());
    }

    #[test]
    fn flags_each_violation() {
        let mut mp = primitives::cuboid([1.0, 2.0, 3.0], 1.0);
        mp.inertia[2][2] = mp.inertia[0][0] + mp.inertia[1][1] + 1.0;
        assert!(matches!(
            check(&mp, DEFAULT_TOLERANCE)[..],
            [Violation::TriangleInequality { .. }]
        ));
        mp.inertia[0][0] = -1.0;
        assert!(check(&mp, DEFAULT_TOLERANCE)
            .iter()
            .any(|v| matches!(v, Violation::NotPositiveDefinite { .. })));
        mp.mass = 0.0;
        assert!(check(&mp, DEFAULT_TOLERANCE)
            .iter()
            .any(|v| matches!(v, Violation::NonPositiveMass(_))));
        mp.com[0] = f64::NAN;
        assert_eq!(check(&mp, DEFAULT_TOLERANCE), vec![Violation::NotFinite]);
    }

    #[test]
    fn rod_on_the_triangle_boundary_is_valid() {
        // A thin rod: Ixx = Iyy, Izz ≈ 0, so Ixx + Izz ≈ Iyy within round-off: valid.
        let mp = primitives::cylinder(1e-6, 1.0, 1.0);
        assert!(check(&mp, DEFAULT_TOLERANCE).is_empty());
    }
}
