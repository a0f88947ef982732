//! Which parts' boxes meet (the sweep), and the sampling of one part over where they meet.

use super::{Aabb, PlacedPart, GRID, MAX_PAIRS};

/// The volume of the intersection of two bounding boxes (0 when they do not meet).
fn box_overlap(a: &PlacedPart, b: &PlacedPart) -> f64 {
    (0..3)
        .map(|k| (a.bbox.hi[k].min(b.bbox.hi[k]) - a.bbox.lo[k].max(b.bbox.lo[k])).max(0.0))
        .product()
}

/// For each part, the parts whose bounding boxes share more than 1% of the smaller one's volume
/// with its own: a sweep along the axis where the boxes are most spread, so that far apart parts
/// are never compared. `None` past [`MAX_PAIRS`] pairs.
pub(super) fn neighbours(parts: &[PlacedPart]) -> Option<(Vec<Vec<usize>>, f64)> {
    let usable: Vec<usize> = (0..parts.len())
        .filter(|&i| {
            let p = &parts[i];
            p.volume > 0.0 && (0..3).all(|k| p.bbox.lo[k].is_finite() && p.bbox.hi[k].is_finite())
        })
        .collect();
    let spread = |k: usize| {
        let (lo, hi) = usable
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &i| {
                let c = 0.5 * (parts[i].bbox.lo[k] + parts[i].bbox.hi[k]);
                (lo.min(c), hi.max(c))
            });
        let mean_size: f64 = usable
            .iter()
            .map(|&i| parts[i].bbox.hi[k] - parts[i].bbox.lo[k])
            .sum::<f64>()
            / usable.len().max(1) as f64;
        (hi - lo) / mean_size.max(f64::MIN_POSITIVE)
    };
    let axis = (0..3)
        .max_by(|&a, &b| spread(a).total_cmp(&spread(b)))
        .unwrap_or(0);
    let mut order = usable;
    order.sort_by(|&a, &b| parts[a].bbox.lo[axis].total_cmp(&parts[b].bbox.lo[axis]));
    let mut out = vec![Vec::new(); parts.len()];
    let mut active: Vec<usize> = Vec::new();
    let mut pairs = 0usize;
    let mut ignored = 0.0;
    for &i in &order {
        let start = parts[i].bbox.lo[axis];
        active.retain(|&j| parts[j].bbox.hi[axis] > start);
        for &j in &active {
            let (a, b) = (&parts[i], &parts[j]);
            let shared = box_overlap(a, b);
            if shared > 0.01 * a.volume.min(b.volume) {
                out[i].push(j);
                out[j].push(i);
                pairs += 1;
                if pairs > MAX_PAIRS {
                    return None;
                }
            } else {
                ignored += shared;
            }
        }
        active.push(i);
    }
    Some((out, ignored))
}

/// The grid size for every part: one size for all that keeps the point tests of every part and its
/// neighbours within `budget`, with `cost[i]` what one point test of part `i` costs.
pub(super) fn grid_size(
    cost: &[usize],
    nb: &[Vec<usize>],
    involved: &[usize],
    budget: usize,
) -> usize {
    let cost: usize = involved
        .iter()
        .map(|&i| {
            nb[i]
                .iter()
                .fold(cost[i], |c, &j| c.saturating_add(cost[j]))
        })
        .fold(0usize, usize::saturating_add);
    let samples = budget / cost.max(1);
    // No floor above one sample: a floor would let the work grow past the cap with the parts.
    ((samples as f64).cbrt().floor() as usize).clamp(1, GRID)
}

/// Where part `i`'s box meets its neighbours' (the box around those meetings): the only place a
/// point can be covered twice, so the only place the part is sampled or tested.
pub(super) fn region(parts: &[PlacedPart], nb: &[Vec<usize>], i: usize) -> Aabb {
    let p = &parts[i];
    (nb[i].iter()).fold(Aabb::EMPTY, |r, &j| r.union(p.bbox.intersection(parts[j].bbox)))
}

/// What sampling one part found: the volume it shares (each point covered k times counts 1 − 1/k),
/// whether any point is shared, the most parts covering one point, and the volume of the cells a
/// surface may cross (where the samples may be wrong).
pub(super) struct PartSample {
    pub(super) shared: f64,
    pub(super) found: bool,
    pub(super) most: usize,
    pub(super) uncertain: f64,
}

/// For each neighbour of part `i` whose box meets the sampled region, along each axis as bits
/// (`n` ≤ 24): the samples within its box (a point is in the box iff its three bits are set), and
/// the cells that meet its box. This is the box test per point and neighbour, done n times per axis
/// instead of n³.
type Masks = Vec<(usize, [u32; 3], [u32; 3])>;

fn neighbour_masks(
    parts: &[PlacedPart],
    nb: &[Vec<usize>],
    i: usize,
    axes: &[Vec<f64>; 3],
    half: [f64; 3],
) -> Masks {
    nb[i]
        .iter()
        .map(|&j| {
            let b = &parts[j].bbox;
            let points = [0, 1, 2].map(|k| {
                axes[k].iter().enumerate().fold(0u32, |m, (a, &x)| {
                    m | (u32::from(x >= b.lo[k] && x <= b.hi[k]) << a)
                })
            });
            let cells = [0, 1, 2].map(|k| {
                axes[k].iter().enumerate().fold(0u32, |m, (a, &x)| {
                    m | (u32::from(x + half[k] >= b.lo[k] && x - half[k] <= b.hi[k]) << a)
                })
            });
            (j, points, cells)
        })
        .filter(|(_, _, m)| m.iter().all(|&m| m != 0))
        .collect()
}

/// One cell of part `p`'s grid, of centre `x` and core half sides `core`, at position `c` along the
/// row whose neighbours' masks are `row` (neighbour, samples in its box, cells meeting its box):
/// whether a surface may cross the core, and how many parts cover the centre when `p` does and the
/// centre is in some neighbour's box (`None` otherwise: covered once at most).
fn sample_cell(
    parts: &[PlacedPart],
    p: &PlacedPart,
    row: &[(usize, u32, u32)],
    x: [f64; 3],
    core: [f64; 3],
    c: usize,
) -> (bool, Option<usize>) {
    // A core the part's surface misses is all outside the part or all inside it; outside, the part
    // covers none of it, whatever the neighbours do.
    let own = p.classify(x, core, true);
    if own == Some(false) {
        return (false, None);
    }
    let inside = own.unwrap_or_else(|| p.contains(x));
    // Each neighbour whose box the cell meets: whether its surface may cross the core, and (where
    // the part covers the centre and the centre is in the neighbour's box) whether the neighbour
    // covers it too, which its verdict on the core already says when there is one. Only then is
    // that asked: elsewhere the answer would not be used, and a mesh's costs a point test.
    let mut crossed = own.is_none();
    let mut k = 1;
    let mut in_a_box = false;
    for r in row.iter().filter(|r| r.2 >> c & 1 == 1) {
        let in_box = r.1 >> c & 1 == 1;
        in_a_box |= in_box;
        let v = parts[r.0].classify(x, core, inside && in_box);
        crossed |= v.is_none();
        if inside && in_box && v.unwrap_or_else(|| parts[r.0].contains(x)) {
            k += 1;
        }
    }
    (crossed, (inside && in_a_box).then_some(k))
}

/// Samples part `i` on an `n`³ grid over its [`region`]. A cell that no surface of the part or of a
/// neighbour whose box it meets crosses has one covering count throughout, which its centre's
/// sample gets exactly; every other cell's sample is off by less than the cell's volume.
pub(super) fn sample_part(
    parts: &[PlacedPart],
    nb: &[Vec<usize>],
    i: usize,
    n: usize,
) -> PartSample {
    let p = &parts[i];
    let Aabb { lo, hi } = region(parts, nb, i);
    let cell_volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) / (n * n * n) as f64;
    let half = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]) / n as f64);
    // The surfaces are tested against each cell's core, the cell shrunk by `SHRINK` of its size: a
    // face on a cell's border (common: regions end at faces) leaves the core alone, and the shell
    // around the cores, a `3 SHRINK` part of the volume, counts as uncertain throughout.
    let core = half.map(|h| h * (1.0 - SHRINK));
    let axes = [0, 1, 2].map(|k| {
        (0..n)
            .map(|a| lo[k] + (hi[k] - lo[k]) * (a as f64 + 0.5) / n as f64)
            .collect::<Vec<f64>>()
    });
    let masks = neighbour_masks(parts, nb, i, &axes, half);
    let mut most = 1;
    let mut sum = 0.0;
    let mut uncertain = 0usize;
    let mut row: Vec<(usize, u32, u32)> = Vec::with_capacity(masks.len());
    for a in 0..n {
        for b in 0..n {
            row.clear();
            row.extend(
                masks
                    .iter()
                    .filter(|(_, _, m)| m[0] >> a & 1 == 1 && m[1] >> b & 1 == 1)
                    .map(|&(j, pm, cm)| {
                        let in_row = pm[0] >> a & 1 == 1 && pm[1] >> b & 1 == 1;
                        (j, if in_row { pm[2] } else { 0 }, cm[2])
                    }),
            );
            // A cell that meets no neighbour's box is covered once at most and adds nothing: skip
            // the part's own (costlier) tests there.
            let mut cs = row.iter().fold(0u32, |u, r| u | r.2);
            while cs != 0 {
                let c = cs.trailing_zeros() as usize;
                cs &= cs - 1;
                let x = [axes[0][a], axes[1][b], axes[2][c]];
                let (crossed, cover) = sample_cell(parts, p, &row, x, core, c);
                uncertain += usize::from(crossed);
                if let Some(k) = cover {
                    most = most.max(k);
                    sum += 1.0 - 1.0 / k as f64;
                }
            }
        }
    }
    PartSample {
        // A part shares at most its own volume: on a coarse grid, a sample can stand for more.
        // (The true share lies in [0, volume], so this only brings the estimate closer to it.)
        shared: (sum * cell_volume).min(p.volume),
        found: most > 1,
        most,
        uncertain: (uncertain as f64 + 3.0 * SHRINK * (n * n * n) as f64) * cell_volume,
    }
}

/// How much of its size a cell's core is smaller than the cell, per side (see [`sample_part`]).
const SHRINK: f64 = 1e-7;
