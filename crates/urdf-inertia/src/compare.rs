//! Existing `<inertial>` against computed: one comparison, one set of thresholds, shared by `check` and
//! `diff`.

use crate::mass::validity::{self, Violation};
use crate::mass::{frobenius, MassProperties, Mat3};
use crate::text::significant;
use serde::Serialize;
use std::fmt;

/// Existing against computed, for one link.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Comparison {
    /// Existing mass over computed mass.
    pub mass_ratio: f64,
    /// Distance of the centres of mass over the link's size.
    pub com_distance: f64,
    /// Frobenius norm of the tensor difference over the computed tensor's (both about their COM).
    pub inertia_difference: f64,
    /// Likely causes of a difference (unit slips, tensor about the origin, mirrored products).
    pub causes: Vec<String>,
    /// Why the existing values cannot belong to a body, if they cannot.
    pub invalid: Vec<Violation>,
}

/// One way existing mass properties differ from computed ones by more than a tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(feature = "json-schema", derive(schemars::JsonSchema))]
#[serde(tag = "quantity", rename_all = "snake_case")]
#[non_exhaustive]
pub enum Difference {
    /// The masses (kg) and existing over computed.
    Mass {
        existing: f64,
        computed: f64,
        ratio: f64,
    },
    /// The distance of the centres of mass over the link's size.
    CentreOfMass { relative_distance: f64 },
    /// The Frobenius norm of the tensor difference over the computed tensor's.
    Inertia { relative_difference: f64 },
}

impl fmt::Display for Difference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Difference::Mass {
                existing,
                computed,
                ratio,
            } => write!(
                f,
                "mass {} kg, computed {} kg (ratio {})",
                significant(*existing, 7),
                significant(*computed, 7),
                significant(*ratio, 4)
            ),
            Difference::CentreOfMass { relative_distance } => write!(
                f,
                "centre of mass {} of the link's size from the computed one",
                significant(*relative_distance, 4)
            ),
            Difference::Inertia {
                relative_difference,
            } => write!(
                f,
                "inertia differs from the computed one by {} (relative)",
                significant(*relative_difference, 4)
            ),
        }
    }
}

impl Comparison {
    /// What differs by more than `tolerance` (relative); empty when nothing does.
    pub fn beyond(
        &self,
        existing: &MassProperties,
        computed: &MassProperties,
        tolerance: f64,
    ) -> Vec<Difference> {
        let mut off = Vec::new();
        if (self.mass_ratio - 1.0).abs() > tolerance {
            off.push(Difference::Mass {
                existing: existing.mass,
                computed: computed.mass,
                ratio: self.mass_ratio,
            });
        }
        if self.com_distance > tolerance {
            off.push(Difference::CentreOfMass {
                relative_distance: self.com_distance,
            });
        }
        if self.inertia_difference > tolerance {
            off.push(Difference::Inertia {
                relative_difference: self.inertia_difference,
            });
        }
        off
    }

    /// Whether the link differs beyond `tolerance` or its existing values are invalid.
    pub fn differs(&self, tolerance: f64) -> bool {
        !self.invalid.is_empty()
            || (self.mass_ratio - 1.0).abs() > tolerance
            || self.com_distance > tolerance
            || self.inertia_difference > tolerance
    }
}

/// The decade (a multiple of 3) a ratio sits near, if it is a unit slip (1e3, 1e6, 1e9).
fn near_power(r: f64) -> Option<i32> {
    if !(r > 0.0 && r.is_finite()) {
        return None;
    }
    let e = r.log10();
    let k = (e / 3.0).round() * 3.0;
    if k != 0.0 && (e - k).abs() < 0.15 {
        // |k| ≤ 308 + 3: always an i32.
        #[allow(clippy::cast_possible_truncation)]
        Some(k as i32)
    } else {
        None
    }
}

/// Frobenius norm of `a − b` relative to `b`'s.
fn relative(a: &Mat3, b: &Mat3) -> f64 {
    let d = [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[i][j] - b[i][j]));
    frobenius(&d) / frobenius(b).max(f64::MIN_POSITIVE)
}

/// Whether the tensor has products of inertia worth mirroring (above round-off of its size).
fn has_products(t: &Mat3) -> bool {
    let scale = frobenius(t);
    [(0, 1), (0, 2), (1, 2)]
        .iter()
        .any(|&(i, j)| t[i][j].abs() > 1e-9 * scale)
}

/// Likely causes of a difference, named for the user.
fn causes(
    existing: &MassProperties,
    computed: &MassProperties,
    mass_ratio: f64,
    difference: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(k) = near_power(mass_ratio) {
        out.push(format!("mass off by 1e{k} (unit slip?)"));
    }
    let norm_ratio =
        frobenius(&existing.inertia) / frobenius(&computed.inertia).max(f64::MIN_POSITIVE);
    if let Some(k) = near_power(norm_ratio) {
        out.push(format!("inertia off by 1e{k} (unit slip: mm² or g?)"));
    }
    if difference <= 0.05 {
        return out;
    }
    // Scaled to the same mass, do the values look like the tensor about the link origin?
    let scaled = existing.scaled(1.0 / mass_ratio.max(f64::MIN_POSITIVE));
    let about_origin = computed.inertia_about([0.0; 3]);
    let to_origin = relative(&scaled.inertia, &about_origin);
    let as_computed = relative(&scaled.inertia, &computed.inertia);
    if to_origin < 0.5 * as_computed && to_origin < 0.05 {
        out.push("inertia looks like it is about the link origin, not the COM".into());
    }
    // Scaled to one mass the tensors agree: the geometry matches, and the mass (a density, a
    // weighed mass) is all that differs. No sign slip can then be told apart from the tensor itself.
    if as_computed < 0.05 {
        out.push(
            "scaled to the computed mass, the inertia agrees within 5%: only the mass differs (density?)".into(),
        );
        return out;
    }
    // Mirrored products only mean something when there are products: two diagonal tensors cannot be
    // told apart from their mirror images.
    if !has_products(&computed.inertia) {
        return out;
    }
    // CAD tools (SolidWorks' mass properties among them) report +∫xy dm where URDF wants −∫xy dm: the
    // commonest real tensor slip, so it is named before the rarer mirrors. With one product alone it
    // cannot be told from a mirror, and both are named.
    let mut negated = computed.inertia;
    for (i, j) in [(0usize, 1usize), (0, 2), (1, 2)] {
        negated[i][j] = -negated[i][j];
        negated[j][i] = -negated[j][i];
    }
    // A sign slip is named only where it explains the difference: the tensor with its products
    // flipped agrees, and at most half as far off as the tensor as computed.
    let explains = |m: &Mat3| {
        let d = relative(&scaled.inertia, m);
        d < 0.05 && d < 0.5 * as_computed
    };
    if explains(&negated) {
        out.push("products of inertia have the opposite sign (CAD convention: +∫xy dm)".into());
    }
    for (axis, name) in [(0usize, "x"), (1, "y"), (2, "z")] {
        let mut m = computed.inertia;
        for j in (0..3).filter(|&j| j != axis) {
            m[axis][j] = -m[axis][j];
            m[j][axis] = -m[j][axis];
        }
        if explains(&m) {
            out.push(format!(
                "products of inertia look mirrored in {name} (mesh mirrored, or scale sign lost?)"
            ));
        }
    }
    out
}

/// Compares existing mass properties with computed ones of a link whose bounding box has the
/// diagonal `size` (m): the centre-of-mass distance is relative to it.
pub fn compare(existing: &MassProperties, computed: &MassProperties, size: f64) -> Comparison {
    let mass_ratio = existing.mass / computed.mass;
    let dc = [0, 1, 2].map(|k| existing.com[k] - computed.com[k]);
    let com_distance =
        (dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]).sqrt() / size.max(f64::MIN_POSITIVE);
    let inertia_difference = relative(&existing.inertia, &computed.inertia);
    Comparison {
        mass_ratio,
        com_distance,
        inertia_difference,
        causes: causes(existing, computed, mass_ratio, inertia_difference),
        invalid: validity::check(existing, validity::DEFAULT_TOLERANCE),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mass::primitives;

    #[test]
    fn diagonal_tensors_are_never_called_mirrored() {
        // A box and the same box 10 % heavier: products are zero in both, so no mirror can be seen.
        let computed = primitives::cuboid([0.1, 0.2, 0.3], 1000.0);
        let existing = computed.scaled(1.5);
        let c = compare(&existing, &computed, 0.37);
        assert!(
            c.causes.iter().all(|n| !n.contains("mirrored")),
            "{:?}",
            c.causes
        );
        assert!(c.differs(0.05));
        assert!(!compare(&computed, &computed, 0.37).differs(0.05));
    }

    /// A 0.1 × 0.2 × 0.3 box turned about a skew axis, so all three products are non-zero.
    fn turned_box() -> MassProperties {
        let b = primitives::cuboid([0.1, 0.2, 0.3], 1000.0);
        let r = crate::mass::rpy_matrix([0.3, -0.4, 0.5]);
        b.transformed(&r, [0.0; 3])
    }

    /// The tensor's products with their signs flipped per `sign[(0,1)], sign[(0,2)], sign[(1,2)]`,
    /// built by hand (not through the code under test).
    fn with_product_signs(mp: &MassProperties, s: [f64; 3]) -> MassProperties {
        let mut out = *mp;
        for (k, (i, j)) in [(0usize, 1usize), (0, 2), (1, 2)].into_iter().enumerate() {
            out.inertia[i][j] *= s[k];
            out.inertia[j][i] *= s[k];
        }
        out
    }

    #[test]
    fn products_with_the_opposite_sign_are_the_cad_convention() {
        let computed = turned_box();
        // Every product clearly present (a mirror and the CAD slip can then be told apart).
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            assert!(computed.inertia[i][j].abs() > 0.01 * frobenius(&computed.inertia));
        }
        let cad = with_product_signs(&computed, [-1.0, -1.0, -1.0]);
        let c = compare(&cad, &computed, 0.37);
        assert!(c.differs(0.05));
        assert_eq!(
            c.causes,
            vec![
                "products of inertia have the opposite sign (CAD convention: +∫xy dm)".to_string()
            ]
        );
        // The same slip on a link 2 % heavier is still named (the tensor is compared at one mass).
        let c = compare(&cad.scaled(1.02), &computed, 0.37);
        assert_eq!(c.causes.len(), 1, "{:?}", c.causes);
        assert!(c.causes[0].contains("opposite sign"));
    }

    #[test]
    fn a_truly_mirrored_tensor_gets_the_mirror_cause() {
        let computed = turned_box();
        // Mirrored in x: the x row's products change sign (xy and xz), yz keeps its sign.
        let mirrored = with_product_signs(&computed, [-1.0, -1.0, 1.0]);
        let c = compare(&mirrored, &computed, 0.37);
        assert_eq!(
            c.causes,
            vec![
                "products of inertia look mirrored in x (mesh mirrored, or scale sign lost?)"
                    .to_string()
            ]
        );
        // The other two mirrors likewise, each named by its own axis.
        let c = compare(
            &with_product_signs(&computed, [-1.0, 1.0, -1.0]),
            &computed,
            0.37,
        );
        assert_eq!(c.causes.len(), 1, "{:?}", c.causes);
        assert!(c.causes[0].contains("mirrored in y"));
        let c = compare(
            &with_product_signs(&computed, [1.0, -1.0, -1.0]),
            &computed,
            0.37,
        );
        assert!(c.causes[0].contains("mirrored in z"), "{:?}", c.causes);
    }

    #[test]
    fn one_product_alone_names_the_cad_slip_first() {
        // Turned about z only: ixy alone, so flipping it is both the CAD slip and a mirror in x or y.
        let b = primitives::cuboid([0.1, 0.2, 0.3], 1000.0);
        let computed = b.transformed(&crate::mass::rpy_matrix([0.0, 0.0, 0.5]), [0.0; 3]);
        let c = compare(
            &with_product_signs(&computed, [-1.0, 1.0, 1.0]),
            &computed,
            0.37,
        );
        assert!(c.causes[0].contains("opposite sign"), "{:?}", c.causes);
        assert!(c.causes[1..].iter().all(|n| n.contains("mirrored")));
    }

    /// Robotiq's 2F-85 base link under `check --density 1000`: the tensor is the computed one at
    /// 2.149 times the mass, with products of about 1e-3 of its size. Each sign slip then also
    /// agrees within 5% at one mass, and all four were named, though only the mass differs.
    #[test]
    fn a_tensor_that_agrees_at_one_mass_names_the_mass_alone() {
        let b = primitives::cuboid([0.1, 0.2, 0.3], 1000.0);
        let computed = b.transformed(&crate::mass::rpy_matrix([0.001, -0.0015, 0.002]), [0.0; 3]);
        let products = [(0, 1), (0, 2), (1, 2)].map(|(i, j)| computed.inertia[i][j].abs());
        let size = frobenius(&computed.inertia);
        assert!(products.iter().all(|&p| p > 1e-5 * size && p < 1e-2 * size), "{products:?}");
        let heavier = computed.scaled(2.149);
        // The products flipped agree within 5% too: the old rule named every slip.
        assert!(relative(&with_product_signs(&computed, [-1.0; 3]).inertia, &computed.inertia) < 0.05);
        let c = compare(&heavier, &computed, 0.37);
        assert!(c.differs(0.05));
        assert_eq!(
            c.causes,
            vec!["scaled to the computed mass, the inertia agrees within 5%: only the mass differs (density?)".to_string()]
        );
        // A real slip at another mass is still named by itself: the turned box mirrored in y, 1.5
        // times heavier.
        let mirrored = with_product_signs(&turned_box(), [-1.0, 1.0, -1.0]).scaled(1.5);
        let c = compare(&mirrored, &turned_box(), 0.37);
        assert_eq!(c.causes.len(), 1, "{:?}", c.causes);
        assert!(c.causes[0].contains("mirrored in y"), "{:?}", c.causes);
    }
}
