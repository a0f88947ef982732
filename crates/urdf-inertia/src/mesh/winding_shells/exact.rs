//! The one sign the face-by-face decision needs that `robust`'s predicates do not give: along a line
//! parallel to an axis, which of two planes it meets first. A degree-five polynomial in the
//! coordinates, evaluated in integers: every f64 is an integer times a power of two, so the inputs
//! scaled by the smallest of those powers are integers, and the sign is exact. It is asked only
//! where two triangles lie within a few ulps of each other without meeting, each straddling the
//! other's plane ([`super::correction`]'s ray starts), so its cost (big integers, a few
//! microseconds) is rare.

use num_bigint::BigInt;
use num_traits::Signed;

type Corners = [[f64; 3]; 3];

/// An f64 as `m · 2^e` with `m` an integer (`None` for zero, and for NaN or an infinity).
fn decode(x: f64) -> Option<(i64, i32)> {
    if x == 0.0 || !x.is_finite() {
        return None;
    }
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | (1i64 << 52), exp - 1075) };
    Some((if x < 0.0 { -m } else { m }, e))
}

/// Whether the line through `s` parallel to axis `k` meets `u`'s plane strictly on `s`'s side of
/// `t`'s plane, exactly: `None` where `s` lies in `t`'s plane, where the line is parallel to either
/// plane, where it meets the two planes at one point, or for a coordinate that is not finite.
pub(super) fn meets_first(t: &Corners, u: &Corners, s: [f64; 3], k: usize) -> Option<bool> {
    let all = t.iter().chain(u.iter()).chain(std::iter::once(&s));
    if all.clone().flatten().any(|x| !x.is_finite()) {
        return None;
    }
    let low = all.clone().flatten().filter_map(|&x| decode(x)).map(|(_, e)| e).min().unwrap_or(0);
    let int = |x: f64| match decode(x) {
        Some((m, e)) => BigInt::from(m) << ((e - low) as usize),
        None => BigInt::from(0),
    };
    let v = |p: &[f64; 3]| p.map(int);
    let sub = |a: &[BigInt; 3], b: &[BigInt; 3]| -> [BigInt; 3] { std::array::from_fn(|i| &a[i] - &b[i]) };
    let cross = |a: &[BigInt; 3], b: &[BigInt; 3]| -> [BigInt; 3] {
        std::array::from_fn(|i| {
            let (j, l) = ((i + 1) % 3, (i + 2) % 3);
            &a[j] * &b[l] - &a[l] * &b[j]
        })
    };
    let dot = |a: &[BigInt; 3], b: &[BigInt; 3]| -> BigInt { &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2] };
    let s = v(&s);
    // The plane of corners a, b, c: O(x) = (x − a) · N with N = (b − a) × (c − a), so along the
    // line x = s + μ e_k, O = O(s) + μ N_k.
    let plane = |c: &Corners| {
        let [a, b, c] = c.map(|p| v(&p));
        let n = cross(&sub(&b, &a), &sub(&c, &a));
        (dot(&sub(&s, &a), &n), n[k].clone())
    };
    let ((ot, nt), (ou, nu)) = (plane(t), plane(u));
    if ot.sign() == num_bigint::Sign::NoSign || nt.sign() == num_bigint::Sign::NoSign || nu.sign() == num_bigint::Sign::NoSign {
        return None;
    }
    // u's plane is met at μ = −O_u(s) / N_u,k, where t's O is O_t(s) − O_u(s) N_t,k / N_u,k: its
    // sign is that of O_t(s) N_u,k − O_u(s) N_t,k times that of N_u,k.
    let at = &ot * &nu - &ou * &nt;
    if at.sign() == num_bigint::Sign::NoSign {
        return None;
    }
    Some((at.is_positive() == nu.is_positive()) == ot.is_positive())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two planes z = ε x and z = 0 seen along z from points on either side of their meeting line
    /// x = 0, with ε down to one ulp: the order flips where the line does.
    #[test]
    fn the_plane_met_first_is_exact_at_one_ulp() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        for eps in [1e-3, 1e-12, f64::EPSILON, 1e-300] {
            let u = [[0.0, 0.0, 0.0], [1.0, 0.0, eps], [0.0, 1.0, 0.0]];
            // From below t (z < 0), at x > 0 u's plane (z = ε x > 0) lies beyond t's: not first.
            assert_eq!(meets_first(&t, &u, [0.25, 0.25, -1.0], 2), Some(false));
            // At x < 0 u's plane is below t's: met first.
            assert_eq!(meets_first(&t, &u, [-0.25, 0.25, -1.0], 2), Some(true));
            // From above, the other way round.
            assert_eq!(meets_first(&t, &u, [0.25, 0.25, 1.0], 2), Some(true));
            assert_eq!(meets_first(&t, &u, [-0.25, 0.25, 1.0], 2), Some(false));
            // On the meeting line: one point.
            assert_eq!(meets_first(&t, &u, [0.0, 0.25, 1.0], 2), None);
        }
        // Parallel to the line: no answer.
        let wall = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]];
        assert_eq!(meets_first(&t, &wall, [0.25, 0.25, 1.0], 2), None);
    }
}
