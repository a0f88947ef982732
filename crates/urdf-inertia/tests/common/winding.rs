//! An independent generalized winding number and the volume of the solid it defines, for the tests
//! that check open and overlapping meshes against it (not the library's own winding number).

/// The winding number of a triangle mesh at `x`: its triangles' solid angles over 4π (Van Oosterom
/// and Strackee 1983), computed here independently of the library.
pub fn winding_number(v: &[[f64; 3]], f: &[[u32; 3]], x: [f64; 3]) -> f64 {
    let sub = |a: [f64; 3]| [a[0] - x[0], a[1] - x[1], a[2] - x[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let norm = |a: [f64; 3]| dot(a, a).sqrt();
    let mut sum = 0.0;
    for t in f {
        let [a, b, c] = t.map(|i| sub(v[i as usize]));
        let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]);
        let (la, lb, lc) = (norm(a), norm(b), norm(c));
        let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        sum += 2.0 * det.atan2(den);
    }
    sum / (4.0 * std::f64::consts::PI)
}

/// The volume of Ω = {x : |w(x)| ≥ ½} in the bounding box of the vertices `f` uses, and its
/// standard error: stratified sampling, two uniform points in each cell of a `g` grid (the same
/// estimator as validation/winding.py).
pub fn omega_volume(v: &[[f64; 3]], f: &[[u32; 3]], g: [usize; 3], seed: u64) -> (f64, f64) {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for &i in f.iter().flatten() {
        for k in 0..3 {
            lo[k] = lo[k].min(v[i as usize][k]);
            hi[k] = hi[k].max(v[i as usize][k]);
        }
    }
    let cell = [0, 1, 2].map(|k| (hi[k] - lo[k]) / g[k] as f64);
    let cell_volume = cell[0] * cell[1] * cell[2];
    let mut rng = super::Rng(seed);
    let (mut inside, mut var) = (0.0, 0.0);
    for i in 0..g[0] {
        for j in 0..g[1] {
            for k in 0..g[2] {
                let mut point = || {
                    let x = [i, j, k].map(|n| n as f64);
                    let p = [0, 1, 2].map(|a| lo[a] + (x[a] + rng.f64()) * cell[a]);
                    f64::from(u8::from(winding_number(v, f, p).abs() >= 0.5))
                };
                let (a, b) = (point(), point());
                inside += a + b;
                var += (a - b) * (a - b);
            }
        }
    }
    (cell_volume * inside / 2.0, cell_volume * (var / 4.0).sqrt())
}
