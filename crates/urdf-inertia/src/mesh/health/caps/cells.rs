//! A certified bound on the volume where caps can change the solid: the cells of an octree on which
//! the caps' own winding number stays below ½, proven from its value at the cell's centre and the
//! Biot–Savart bound on its gradient.
//!
//! Let S be the open surface, C the caps (fans over its hole loops), `w_S`, `w_C` their winding
//! numbers. S ∪ C is closed (cracks aside: they keep their own term), so off the surfaces
//! `w_{S∪C}` = k(x) ∈ ℤ and `w_S` = k − `w_C`. The capped solid is {k ≠ 0}, Ω = {|`w_S`| ≥ ½}. Where
//! |`w_C`(x)| < ½ the two agree at x: k = 0 gives |`w_S`| < ½, k ≠ 0 gives |`w_S`| ≥ |k| − |`w_C`| > ½.
//! So they differ only inside D = {x : |`w_C`(x)| ≥ ½}, and where k is 0 or 1 the capped volume is
//! within vol(D) of Ω's.
//!
//! Off C, `w_C` is harmonic and its gradient is the Biot–Savart field of the loops over 4π:
//! |∇`w_C`(x)| ≤ (1/4π) Σₑ lenₑ / dist(x, e)², e the loop edges. On a ball of radius r about c that
//! does not meet C (every segment from c stays off C, where `w_C` jumps), |`w_C`| ≤ |`w_C`(c)| + r ·
//! (1/4π) Σₑ lenₑ / (dist(c, e) − r)²; a box cell (r its half-diagonal) where that is below ½ lies
//! outside D. A group of cap triangles at distance d ≥ r from c, seen from far, contributes at most
//! A/(4π d²) to |`w_C`(c)| (a surface of area A subtends at most A/d²) instead of its exact solid
//! angle. Outside the caps' box grown by g = √(ΣA / 2π) every point is farther than g from C, so
//! |`w_C`| ≤ ΣA / (4π g²) ≤ ½ there (equality only on a null set): that box is the octree's root.
//! Uncertified cells are split in eight, largest first, while the work (cells × triangles looked at)
//! stays within a budget; every cell left uncertified, or not looked at when the budget runs out,
//! counts whole into vol(D)'s bound, which therefore widens honestly rather than failing.
//!
//! Each triangle's solid angle is computed in f64 by Van Oosterom and Strackee's formula; numerator
//! and denominator are sums of products of magnitude at most |a||b||c| (the corners seen from c),
//! computed to a few ε of that, and their hypotenuse is small only when c is close to the triangle
//! relative to its size. The allowance per triangle is [`SOLID_ANGLE_ALLOWANCE`] × (1 + ρ/δ), ρ the
//! largest corner distance and δ the distance to the triangle, several hundred times that
//! conditioning, and a cell's sum must also stay below ½ by a relative margin of 1e-9.

use crate::geometry::{cross, dot, norm, solid_angle, sub};
use std::collections::VecDeque;
use std::f64::consts::PI;

/// Work units (a triangle or a far group of triangles looked at from one cell) before the cells
/// left count whole.
const WORK_BUDGET: u64 = 1 << 19;

/// Levels of the octree below its root: its cells are then 1/65536 of the root's sides.
const MAX_DEPTH: u32 = 16;

/// Consecutive cap triangles grouped for the far bounds.
const GROUP: usize = 32;

/// A group is seen from far when the cell's centre is at least this many of its box's diagonals away.
const FAR: f64 = 4.0;

/// Allowance on one f64 solid angle over 4π, before the conditioning factor (see the module's doc).
const SOLID_ANGLE_ALLOWANCE: f64 = 1e-12;

/// Levels of the octree whose cells gather the uncertified cells below them into one part.
const PART_DEPTH: u32 = 3;

/// The bound: vol(D) ≤ `volume`, made of `parts`, each a volume inside a box (lo, hi).
pub(super) struct Certified {
    pub(super) volume: f64,
    pub(super) parts: Vec<(f64, [f64; 3], [f64; 3])>,
}

/// Consecutive triangles of one fan, with their box, loop-edge box, edge length and area.
struct Group {
    tris: std::ops::Range<usize>,
    lo: [f64; 3],
    hi: [f64; 3],
    edge_lo: [f64; 3],
    edge_hi: [f64; 3],
    length: f64,
    area: f64,
    diagonal: f64,
}

/// Certifies vol({|`w_C`| ≥ ½}) from above, `tris` the caps' triangles as (centre, b, a) with the
/// loop edge b–a (the winding numbers' sign does not matter: only |`w_C`| does). Stops as soon as
/// the bound (cells counted and cells still queued) is at most `enough`.
pub(super) fn certify(tris: &[[[f64; 3]; 3]], enough: f64) -> Certified {
    let mut out = Certified {
        volume: 0.0,
        parts: Vec::new(),
    };
    if tris.is_empty() {
        return out;
    }
    let groups = groups(tris);
    let area: f64 = groups.iter().map(|g| g.area).sum();
    let (mut lo, mut hi) = (groups[0].lo, groups[0].hi);
    for g in &groups {
        for k in 0..3 {
            lo[k] = lo[k].min(g.lo[k]);
            hi[k] = hi[k].max(g.hi[k]);
        }
    }
    let grow = (area / (2.0 * PI)).sqrt() * (1.0 + 1e-6);
    let root = (lo.map(|x| x - grow), hi.map(|x| x + grow));
    if !(root.0.iter().chain(&root.1)).all(|x| x.is_finite()) {
        out.volume = f64::INFINITY;
        return out;
    }
    let mut work = 0u64;
    // Uncertified volume per part: the cell of depth `PART_DEPTH` (or less) it lies in, by its path.
    let mut parts: rustc_hash::FxHashMap<u32, (f64, [f64; 3], [f64; 3])> =
        rustc_hash::FxHashMap::default();
    let cell_volume = |lo: [f64; 3], hi: [f64; 3]| (0..3).map(|k| hi[k] - lo[k]).product::<f64>();
    // Counted and still queued: the bound if the work stopped now.
    let mut open = cell_volume(root.0, root.1);
    let mut queue = VecDeque::from([(root.0, root.1, 0u32, 0u32)]);
    while let Some((lo, hi, depth, part)) = queue.pop_front() {
        let stop = work >= WORK_BUDGET || open <= enough;
        if !stop && outside(tris, &groups, lo, hi, &mut work) {
            open -= cell_volume(lo, hi);
            continue;
        }
        if stop || depth == MAX_DEPTH {
            let volume = cell_volume(lo, hi);
            let p = parts.entry(part).or_insert((0.0, lo, hi));
            p.0 += volume;
            p.1 = [0, 1, 2].map(|k| p.1[k].min(lo[k]));
            p.2 = [0, 1, 2].map(|k| p.2[k].max(hi[k]));
            continue;
        }
        let mid = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
        for octant in 0..8u32 {
            let pick = |k: usize| {
                if octant >> k & 1 == 0 {
                    (lo[k], mid[k])
                } else {
                    (mid[k], hi[k])
                }
            };
            let (x, y, z) = (pick(0), pick(1), pick(2));
            // Paths in base 8 with digits 1..=8 name the cells down to `PART_DEPTH` uniquely.
            let part = if depth < PART_DEPTH {
                part * 8 + octant + 1
            } else {
                part
            };
            queue.push_back(([x.0, y.0, z.0], [x.1, y.1, z.1], depth + 1, part));
        }
    }
    let mut parts: Vec<_> = parts.into_iter().collect();
    parts.sort_unstable_by_key(|p| p.0);
    out.parts = parts.into_iter().map(|p| p.1).collect();
    out.volume = out.parts.iter().map(|p| p.0).sum();
    out
}

/// The triangles in groups of [`GROUP`] consecutive ones.
fn groups(tris: &[[[f64; 3]; 3]]) -> Vec<Group> {
    (0..tris.len())
        .step_by(GROUP)
        .map(|start| {
            let range = start..(start + GROUP).min(tris.len());
            let mut g = Group {
                tris: range.clone(),
                lo: [f64::INFINITY; 3],
                hi: [f64::NEG_INFINITY; 3],
                edge_lo: [f64::INFINITY; 3],
                edge_hi: [f64::NEG_INFINITY; 3],
                length: 0.0,
                area: 0.0,
                diagonal: 0.0,
            };
            for t in &tris[range] {
                for (i, p) in t.iter().enumerate() {
                    for k in 0..3 {
                        g.lo[k] = g.lo[k].min(p[k]);
                        g.hi[k] = g.hi[k].max(p[k]);
                        if i > 0 {
                            g.edge_lo[k] = g.edge_lo[k].min(p[k]);
                            g.edge_hi[k] = g.edge_hi[k].max(p[k]);
                        }
                    }
                }
                g.length += norm(sub(t[2], t[1]));
                g.area += 0.5 * norm(cross(sub(t[1], t[0]), sub(t[2], t[0])));
            }
            g.diagonal = norm(sub(g.hi, g.lo));
            g
        })
        .collect()
}

/// Whether the box `lo..hi` is proven outside D: |`w_C`| + allowance + r × gradient bound < ½.
fn outside(
    tris: &[[[f64; 3]; 3]],
    groups: &[Group],
    lo: [f64; 3],
    hi: [f64; 3],
    work: &mut u64,
) -> bool {
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let r = 0.5 * norm(sub(hi, lo));
    // Exact part of w, far bounds on |w|, the allowance, and the gradient bound times 4π.
    let (mut w, mut far, mut allowance, mut gradient) = (0.0, 0.0, 0.0, 0.0);
    for g in groups {
        *work += 1;
        let d = box_distance(c, g.lo, g.hi);
        if d > r && d >= FAR * g.diagonal {
            far += g.area / (4.0 * PI * d * d);
            let e = box_distance(c, g.edge_lo, g.edge_hi) - r;
            gradient += g.length / (e * e);
            continue;
        }
        for t in &tris[g.tris.clone()] {
            *work += 1;
            // The triangle's box is a cheap lower bound on its distance; the exact one only near.
            let (tlo, thi) = (
                [0, 1, 2].map(|k| t[0][k].min(t[1][k]).min(t[2][k])),
                [0, 1, 2].map(|k| t[0][k].max(t[1][k]).max(t[2][k])),
            );
            let boxed = box_distance(c, tlo, thi);
            let d = if boxed > 2.0 * r {
                boxed
            } else {
                triangle_distance(c, t)
            };
            if d <= r {
                return false;
            }
            let [a, b, e] = t.map(|p| sub(p, c));
            let (la, lb, le) = (norm(a), norm(b), norm(e));
            w += solid_angle(a, b, e, la, lb, le);
            allowance += SOLID_ANGLE_ALLOWANCE * (1.0 + la.max(lb).max(le) / d);
            gradient += edge_field(c, r, t[1], t[2]);
        }
    }
    let bound = (w / (4.0 * PI)).abs() + far + allowance + r * gradient / (4.0 * PI);
    bound < 0.5 * (1.0 - 1e-9)
}

/// A bound on ∫ dl / |x − y|² over the segment `a..b` (y on it) for every x within `r` of `c`, the
/// segment farther than `r` from `c`: with m = dist(c, segment), |x − y| ≥ |c − y| − r ≥ |c − y|·(1 −
/// r/m), and ∫ dl / |c − y|² = θ / p in closed form, θ the angle the segment subtends at c and p the
/// distance from c to its line (L / (t₁t₂) on the line, t the signed positions of its ends). Never
/// above L / (m − r)², the bound with the nearest distance throughout.
fn edge_field(c: [f64; 3], r: f64, a: [f64; 3], b: [f64; 3]) -> f64 {
    let m = segment_distance(c, a, b);
    let ab = sub(b, a);
    let l = norm(ab);
    let crude = l / ((m - r) * (m - r));
    if l == 0.0 {
        return 0.0;
    }
    let u = ab.map(|x| x / l);
    let (t1, t2) = (dot(sub(a, c), u), dot(sub(b, c), u));
    let p = norm(cross(sub(a, c), u));
    let along = if p > 0.0 {
        (p * l).atan2(p * p + t1 * t2) / p
    } else {
        l / (t1 * t2)
    };
    let shrink = 1.0 - r / m;
    // A relative margin for the rounding of the closed form.
    (along * (1.0 + 1e-9) / (shrink * shrink)).min(crude)
}

/// The distance from `p` to the box `lo..hi` (0 inside).
fn box_distance(p: [f64; 3], lo: [f64; 3], hi: [f64; 3]) -> f64 {
    norm([0, 1, 2].map(|k| (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0)))
}

/// The distance from `p` to the segment `a..b`.
fn segment_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let l = dot(ab, ab);
    let t = if l > 0.0 {
        (dot(sub(p, a), ab) / l).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, [0, 1, 2].map(|k| a[k] + t * ab[k])))
}

/// The distance from `p` to the triangle `t` (Ericson, Real-Time Collision Detection, 5.1.5),
/// never above the distance to its edges (a degenerate triangle is its edges).
fn triangle_distance(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    let edges = segment_distance(p, t[0], t[1])
        .min(segment_distance(p, t[1], t[2]))
        .min(segment_distance(p, t[2], t[0]));
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let nn = dot(n, n);
    if nn == 0.0 {
        return edges;
    }
    // The foot of p on the plane is inside when it is on the inner side of all three edges.
    let foot = sub(p, n.map(|x| x * dot(sub(p, t[0]), n) / nn));
    let inside = (0..3).all(|i| {
        let (u, v) = (t[i], t[(i + 1) % 3]);
        dot(cross(sub(v, u), sub(foot, u)), n) >= 0.0
    });
    if inside {
        // Rounding in the foot: never report more than the edges' distance.
        (dot(sub(p, t[0]), n).abs() / nn.sqrt()).min(edges)
    } else {
        edges
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square cap (flat, area 1) has D of measure zero: the bound shrinks with the cells but
    /// is positive (the cap's own plane is never certified), and it lies near the square.
    #[test]
    fn a_flat_square_leaves_a_thin_layer() {
        let c = [0.5, 0.5, 0.0];
        let sq = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let tris: Vec<_> = (0..4).map(|i| [c, sq[(i + 1) % 4], sq[i]]).collect();
        let cert = certify(&tris, 0.0);
        assert!(cert.volume > 0.0 && cert.volume < 0.05, "{}", cert.volume);
        for (_, lo, hi) in &cert.parts {
            assert!(lo[2] > -0.5 && hi[2] < 0.5 && lo[0] > -0.5 && hi[0] < 1.5);
        }
    }

    /// Every sampled point where the caps' winding number, summed independently here, reaches ½ lies
    /// in a part's box, and the sampled volume of those points is within the bound: a bent loop (a
    /// cube's two adjacent faces' rim) and a wavy one, fanned from their centroids.
    #[test]
    fn sampled_points_with_half_lie_in_the_parts() {
        let bent = [
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
        ];
        let wavy: Vec<[f64; 3]> = (0..40)
            .map(|i| {
                let a = f64::from(i) * std::f64::consts::TAU / 40.0;
                [a.cos(), a.sin(), 0.3 * (3.0 * a).sin()]
            })
            .collect();
        for ring in [bent.to_vec(), wavy] {
            let n = ring.len() as f64;
            let c = [0, 1, 2].map(|k| ring.iter().map(|p| p[k]).sum::<f64>() / n);
            let tris: Vec<_> = (0..ring.len())
                .map(|i| [c, ring[(i + 1) % ring.len()], ring[i]])
                .collect();
            let cert = certify(&tris, 0.0);
            let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
            for t in &tris {
                for p in t {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k] - 1.0);
                        hi[k] = hi[k].max(p[k] + 1.0);
                    }
                }
            }
            let mut rng = 0x9e37_79b9_7f4a_7c15u64;
            let mut uniform = || {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                (rng >> 11) as f64 / (1u64 << 53) as f64
            };
            let samples = 40_000;
            let mut inside = 0;
            for _ in 0..samples {
                let x: [f64; 3] = std::array::from_fn(|k| lo[k] + uniform() * (hi[k] - lo[k]));
                let w: f64 = tris
                    .iter()
                    .map(|t| {
                        let [a, b, e] = t.map(|p| sub(p, x));
                        solid_angle(a, b, e, norm(a), norm(b), norm(e))
                    })
                    .sum::<f64>()
                    / (4.0 * PI);
                if w.abs() >= 0.5 {
                    inside += 1;
                    let held = cert.parts.iter().any(|(_, plo, phi)| {
                        (0..3).all(|k| plo[k] <= x[k] && x[k] <= phi[k])
                    });
                    assert!(held, "{x:?}: w {w}");
                }
            }
            let volume = (0..3).map(|k| hi[k] - lo[k]).product::<f64>();
            let sampled = volume * f64::from(inside) / f64::from(samples);
            let sigma = volume * (f64::from(inside).max(1.0)).sqrt() / f64::from(samples);
            assert!(sampled <= cert.volume + 3.0 * sigma, "{sampled} ± {sigma} > {}", cert.volume);
            assert!(inside > 0 && cert.volume < 0.5 * volume, "{}", cert.volume);
        }
    }

    /// The distances against points whose distances are known exactly.
    #[test]
    fn distances_to_a_triangle() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        assert_eq!(triangle_distance([0.5, 0.5, 3.0], &t), 3.0);
        assert_eq!(triangle_distance([-3.0, 0.0, 4.0], &t), 5.0);
        assert_eq!(triangle_distance([2.0, 2.0, 0.0], &t), 2f64.sqrt());
        assert_eq!(segment_distance([1.0, 1.0, 0.0], [0.0, 0.0, 0.0], [2.0, 0.0, 0.0]), 1.0);
    }
}
