//! Capsules written as a cylinder and a sphere of its radius on each end: one body, their union.
//!
//! URDF had no capsule until urdfdom 4, so robot descriptions write one as three collisions, a
//! `<cylinder>` and two `<sphere>`s centred on its end faces (example-robot-data's
//! `panda_collision.urdf`, Franka's `collision_capsule` macro). Summed as parts, each sphere's half
//! inside the cylinder counts twice: 23 to 44% of each Panda link's summed volume (UI401). Their
//! union is the capsule exactly, whatever the length (a point of one sphere beyond the far end face
//! is nearer that end's centre, so inside the other sphere), and it is the cylinder plus each
//! sphere's outer half: each sphere part becomes that half, and the three count as one solid in the
//! overlap estimate with the link's other parts.
//!
//! Only primitives take part, and a primitive's density is always the link's (the density map's
//! `[meshes]` rules name mesh files), so the three are of one material; a link mass target is
//! spread over the union.

use super::parts::Part;
use crate::mass::{primitives, Mat3};
use crate::overlap::{PartShape, PlacedPart};

/// How far a sphere's centre may be from the cylinder's end centre, plus how far its radius may be
/// from the cylinder's, as a share of the radius: decimals written with nine significant digits or
/// more, and the rounding of `xyz ± length/2` in f64 (example-robot-data's Panda: 3e-17 m at a
/// radius of 0.09 m). A sphere further off is a part of its own, as before.
const TOLERANCE: f64 = 1e-9;

/// A bound on the relative error of a hemisphere's volume and central inertia (Frobenius norm)
/// per unit of ε/r, where the sphere it stands for misses the cylinder's end and radius by ε in all
/// (centre distance plus radius difference): within [`TOLERANCE`], the rounding of the file's
/// decimals, so it is counted with the round-off. The union of the cylinder and the sphere differs
/// from the exact capsule (a sphere of radius r at the end) within the shell between the balls of
/// radius r ± ε about the end, of volume (4π/3)((r+ε)³ − (r−ε)³) ≈ 8πr²ε; the hemisphere taken
/// (the sphere's own, cut through its centre across the axis) differs from the capsule's within
/// that shell and a slab of thickness ε across the ball, π(r+ε)²ε: 17πr²ε in all, 25.5 ε/r of the
/// hemisphere's (2/3)πr³. Each point of them lies within 1.375 r + ε of the hemisphere's COM (3r/8
/// from the centre), where its second-moment tensor has Frobenius norm √2 ρ² at distance ρ, so the
/// central tensor moves by at most √2 (1.375 r)² 17πr²ε, 126 ε/r of the hemisphere's (0.543 m r²;
/// the shift of the COM enters squared).
const ERROR_PER_MISS: f64 = 128.0;

/// How far (as [`TOLERANCE`]) spheres may miss a cylinder's ends for the three to be named as
/// nearly a capsule in the overlap warning: a rotation written with π/2 as 1.57 puts the end
/// 8e-4 of the half length aside (example-robot-data's Panda hand: 6e-5 m at a radius of 0.05 m).
const NEARLY: f64 = 0.05;

/// A cylinder part and the two sphere parts (on its +Z end, then its −Z end) it is joined with.
#[derive(Debug, Clone, Copy)]
pub(super) struct Capsule {
    pub(super) cylinder: usize,
    pub(super) spheres: [usize; 2],
}

/// A cylinder and two spheres that would be a capsule but for `miss` (m): the most by which a
/// sphere's centre and radius miss the cylinder's end centre and radius.
#[derive(Debug, Clone, Copy)]
pub(super) struct Nearly {
    pub(super) parts: [usize; 3],
    pub(super) miss: f64,
}

/// Finds the capsules among `parts` and makes each of their spheres its outer half (mass
/// properties, volume and error bound): the parts then sum to the union. Each sphere joins one
/// capsule at most, the first cylinder (in collision order) that it ends. Also the cylinders whose
/// ends two spheres miss by more than [`TOLERANCE`] and at most [`NEARLY`] of the radius, left as
/// parts of their own.
pub(super) fn join(parts: &mut [Part]) -> (Vec<Capsule>, Vec<Nearly>) {
    // The spheres by the x of their centres: one within a tolerance of an end has its x within
    // that of the end's, so each end looks at a window of them, not at every part (a link of 5,000
    // cylinders and 10,000 spheres took 1.1 s more than without capsules when each end looked at
    // every part).
    let mut spheres: Vec<(f64, usize)> = (parts.iter().enumerate())
        .filter(|(_, p)| matches!(p.placed.shape, PartShape::Sphere(_)))
        .map(|(j, p)| (p.placed.translation[0], j))
        .collect();
    if spheres.len() < 2 {
        return (Vec::new(), Vec::new());
    }
    spheres.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut used = vec![false; parts.len()];
    let capsules = find_in(parts, &spheres, TOLERANCE, &mut used);
    let nearly = find_in(parts, &spheres, NEARLY, &mut used)
        .into_iter()
        .map(|(cap, miss)| Nearly {
            parts: [cap.cylinder, cap.spheres[0], cap.spheres[1]],
            miss: miss[0].max(miss[1]),
        })
        .collect();
    for (cap, miss) in &capsules {
        let c = &parts[cap.cylinder].placed;
        let PartShape::Cylinder(radius, _) = c.shape else {
            continue;
        };
        let rot = c.rotation;
        for (k, flip) in [(0, false), (1, true)] {
            outer_half(&mut parts[cap.spheres[k]], &rot, flip, miss[k] / radius);
        }
    }
    (capsules.into_iter().map(|(c, _)| c).collect(), nearly)
}

/// The centre of a cylinder's end face: its +Z end, or −Z when `flip`.
fn end(centre: [f64; 3], rot: &Mat3, half: f64, flip: bool) -> [f64; 3] {
    let s = if flip { -half } else { half };
    std::array::from_fn(|k| centre[k] + s * rot[k][2])
}

/// How far a sphere part misses the end centre `e` of a cylinder of `radius`: centre distance plus
/// radius difference (infinite for a part that is not a sphere).
fn sphere_miss(p: &PlacedPart, e: [f64; 3], radius: f64) -> f64 {
    match p.shape {
        PartShape::Sphere(r) => {
            let t = p.translation;
            (0..3).map(|k| (t[k] - e[k]).powi(2)).sum::<f64>().sqrt() + (r - radius).abs()
        }
        _ => f64::INFINITY,
    }
}

/// The capsules within `tolerance` among the parts not `used` (marked as they are taken), each with
/// the misses of its two spheres; `spheres` are the sphere parts by the x of their centres.
fn find_in(parts: &[Part], spheres: &[(f64, usize)], tolerance: f64, used: &mut [bool]) -> Vec<(Capsule, [f64; 2])> {
    let mut capsules = Vec::new();
    for c in 0..parts.len() {
        if used[c] {
            continue;
        }
        let PartShape::Cylinder(radius, half) = parts[c].placed.shape else {
            continue;
        };
        let (rot, centre) = (parts[c].placed.rotation, parts[c].placed.translation);
        // The first sphere (in part order) not used ending the cylinder within the tolerance, and
        // its miss.
        let sphere_at = |flip: bool, used: &[bool]| {
            let e = end(centre, &rot, half, flip);
            let reach = tolerance * radius;
            let from = spheres.partition_point(|s| s.0 < e[0] - reach);
            (spheres[from..].iter())
                .take_while(|s| s.0 <= e[0] + reach)
                .filter(|&&(_, j)| !used[j] && j != c)
                .map(|&(_, j)| (j, sphere_miss(&parts[j].placed, e, radius)))
                .filter(|&(_, miss)| miss <= reach)
                .min_by_key(|&(j, _)| j)
        };
        let Some(top) = sphere_at(false, used) else {
            continue;
        };
        used[top.0] = true;
        let Some(bottom) = sphere_at(true, used) else {
            used[top.0] = false;
            continue;
        };
        used[bottom.0] = true;
        used[c] = true;
        let cap = Capsule {
            cylinder: c,
            spheres: [top.0, bottom.0],
        };
        capsules.push((cap, [top.1, bottom.1]));
    }
    capsules
}

/// Makes a sphere part the half of it on the far side of its centre along the cylinder's axis
/// (`rot`'s Z, or −Z when `flip`), with `miss` (ε/r) in its error bound.
fn outer_half(part: &mut Part, rot: &Mat3, flip: bool, miss: f64) {
    let PartShape::Sphere(r) = part.placed.shape else {
        return;
    };
    // A rotation taking Z to the outward axis: `rot`, or `rot` turned half way about its X.
    let s = if flip { -1.0 } else { 1.0 };
    let turn: Mat3 = std::array::from_fn(|i| [rot[i][0], s * rot[i][1], s * rot[i][2]]);
    let half = primitives::hemisphere(r, 1.0);
    part.unit = half.transformed(&turn, part.placed.translation);
    part.placed.volume = part.unit.mass;
    part.error.round_off = part.error.round_off.max(ERROR_PER_MISS * miss);
    part.error_estimate = part.error.total();
}

/// The parts as the overlap estimate sees them: each capsule one solid (the cylinder's part made a
/// capsule over the three parts' boxes), its spheres left out; with each solid's index in `parts`.
pub(super) fn placed(parts: &[Part], capsules: &[Capsule]) -> (Vec<PlacedPart>, Vec<usize>) {
    let mut skip = vec![false; parts.len()];
    let mut solids: Vec<(PlacedPart, usize)> = parts
        .iter()
        .enumerate()
        .map(|(i, p)| (p.placed.clone(), i))
        .collect();
    for cap in capsules {
        let c = &parts[cap.cylinder].placed;
        let PartShape::Cylinder(radius, half) = c.shape else {
            continue;
        };
        let [a, b] = cap.spheres.map(|s| &parts[s].placed);
        solids[cap.cylinder].0 = PlacedPart {
            shape: PartShape::Capsule(radius, half),
            bbox: c.bbox.union(a.bbox).union(b.bbox),
            volume: c.volume + a.volume + b.volume,
            ..c.clone()
        };
        cap.spheres.iter().for_each(|&s| skip[s] = true);
    }
    solids.into_iter().filter(|(_, i)| !skip[*i]).unzip()
}
