//! Flat caps over the boundary loops of an open surface, with the bounds they leave: their flatness,
//! and how much the caps of several holes, seen from near one another, can move the solid that the
//! winding number defines ([`Caps::interaction`]).

use super::model::Lever;
use crate::geometry::{cross, dot, norm, sub};
use crate::mass::Polygons;
use plane_boxes::PlaneBoxes;

mod cells;
mod plane_boxes;

/// Boundary loops closed by fans from their centroids.
pub(super) struct Caps {
    /// One new vertex per hole (its centroid), numbered after the mesh's vertices.
    pub(super) centroids: Vec<[f64; 3]>,
    pub(super) faces: Polygons,
    pub(super) holes: usize,
    /// Boundary edges left open (cracks, T-junctions).
    pub(super) cracks: usize,
    /// The flatness term: 2 × deviation × area summed over the caps (0 when flat), m³; the model
    /// error uses the certified cells instead when they are larger ([`Caps::terms`]).
    pub(super) bound: f64,
    /// Total area of the caps, m².
    pub(super) area: f64,
    /// The vertices of the loops closed and the caps' centres: where the flatness term
    /// [`Caps::bound`] sits.
    loop_vertices: Vec<[f64; 3]>,
    /// Each cap's shape, for [`Caps::interaction`].
    loops: Vec<CapShape>,
    /// What the caps seeing each other can change ([`Caps::interaction`]), set once all are closed.
    pub(super) interaction: Interaction,
    /// The certified cells' bound on the volume the caps can change ([`cells`]) with its parts, when
    /// it is used instead of the flatness and interaction terms.
    cells: Option<Interaction>,
}

/// One cap: a fan from `centre` over a loop, within `deviation` of a plane through `centre`.
#[derive(Clone)]
struct CapShape {
    centre: [f64; 3],
    /// Unit normal of the plane (zero when the loop has no vector area).
    normal: [f64; 3],
    /// The loop's vertices: a range of [`Caps::loop_vertices`].
    loop_points: std::ops::Range<usize>,
    /// Largest distance of a loop vertex from the centre, m.
    radius: f64,
    /// Sum of the fan triangles' areas, m² (at least the planar area).
    area: f64,
    /// Largest distance of a loop vertex from the plane, m.
    deviation: f64,
    /// Bounding box of the loop (the fan lies in it).
    lo: [f64; 3],
    hi: [f64; 3],
}

/// The volume by which capping several holes can differ from the winding number's solid, m³, and
/// its parts, each with the ball (centre, radius) it lies in (`INFINITY` and no parts when
/// unbounded).
pub(super) struct Interaction {
    pub(super) volume: f64,
    pub(super) parts: Vec<(f64, [f64; 3], f64)>,
}

/// The share of the mesh's box volume below which the certified cells are not refined further,
/// though the flatness and interaction terms are smaller still: on a nearly flat cap the cells cannot
/// reach those terms at any affordable work, and spent the whole budget trying (40 ms for PR2's
/// 106-face `head_tilt_L.stl`, against 1e-6 of the box: docs/accuracy.md).
const CERTIFIED_ENOUGH: f64 = 1e-5;

/// A boundary edge out of a vertex: the other end, the edge's number, and whether the mesh directs
/// it that way.
type Step = (u32, u32, bool);

/// Each vertex's boundary edges, as [`cap_holes`] walks them: those the mesh directs out of it in
/// the edges' order, then those into it. One flat array with each vertex's start (a counting
/// sort), not a map of vectors: a hole of a million edges cost a million small vectors and a map
/// of them (figures: docs/benchmarks.md, "Figures behind choices in the code").
struct BoundarySteps {
    /// Where each vertex's steps start, as offsets into `steps` (one more than the vertices).
    start: Vec<u32>,
    steps: Vec<Step>,
}

impl BoundarySteps {
    fn new(half: &[(u32, u32)]) -> Self {
        let n = half.iter().map(|&(u, v)| u.max(v) as usize + 1).max().unwrap_or(0);
        let mut start = vec![0u32; n + 1];
        for &(u, v) in half {
            start[u as usize + 1] += 1;
            start[v as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut steps = vec![(0, 0, false); 2 * half.len()];
        let mut put = |at: u32, step: Step| {
            steps[fill[at as usize] as usize] = step;
            fill[at as usize] += 1;
        };
        for (i, &(u, v)) in (0u32..).zip(half) {
            put(u, (v, i, true));
        }
        for (i, &(u, v)) in (0u32..).zip(half) {
            put(v, (u, i, false));
        }
        BoundarySteps { start, steps }
    }

    /// The steps out of vertex `at` (none for a vertex on no boundary edge).
    fn of(&self, at: u32) -> &[Step] {
        let at = at as usize;
        match (self.start.get(at), self.start.get(at + 1)) {
            (Some(&a), Some(&b)) => &self.steps[a as usize..b as usize],
            _ => &[],
        }
    }
}

/// Closes every boundary loop of `faces` with a fan from the loop's centroid, wound against the loop's
/// edges so the result is consistently oriented. The volume uncertainty bound ([`Caps::certify`]):
/// none for flat caps over one hole, [`Caps::interaction`] for several flat ones, and otherwise the
/// flatness and interaction terms or, when larger, the cells' certified volume where the caps'
/// winding number can reach ½ ([`cells`]); boundary chains
/// that do not close are the caller's (the capped surface's vector area).
/// `None` when there are no boundary edges. `half` are the boundary edges as directed in their faces,
/// in the order of [`edges`].
pub(super) fn cap_holes(vertices: &[[f64; 3]], half: &[(u32, u32)]) -> Option<Caps> {
    if half.is_empty() {
        return None;
    }
    // Walk boundary edges as undirected (cracks and slivers often have both sides in one direction),
    // preferring the mesh's own direction; each cap triangle is wound against its own edge.
    let out_of = BoundarySteps::new(half);
    // Where in each vertex's steps the unused ones start: edges are only ever marked used, so the
    // walk's "first unused edge" is found from there, not from the list's start (which made a
    // vertex on many boundary edges quadratic in their number).
    let mut from = vec![0u32; out_of.start.len()];
    let mut used = vec![false; half.len()];
    let base = vertices.len() as u32;
    let mut caps = Caps::empty();
    for start in 0..half.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        // (vertex, edge into the next vertex as directed in the mesh)
        let mut steps: Vec<(u32, u32, u32)> = vec![(half[start].0, half[start].0, half[start].1)];
        let mut at = half[start].1;
        let mut closed = true;
        while at != half[start].0 {
            let o = out_of.of(at);
            let first = &mut from[at as usize];
            while o.get(*first as usize).is_some_and(|e| used[e.1 as usize]) {
                *first += 1;
            }
            let Some(&(next, i, forward)) = o.get(*first as usize) else {
                closed = false;
                break;
            };
            used[i as usize] = true;
            let (mu, mv) = if forward { (at, next) } else { (next, at) };
            steps.push((at, mu, mv));
            at = next;
        }
        if !closed {
            // A chain that does not close is a crack or a T-junction, not a hole: left open, and
            // accounted for below by the vector area that remains.
            caps.cracks += steps.len();
            continue;
        }
        caps.close(vertices, base, &steps);
    }
    // What cracks leave open is accounted for by the caller: the capped surface's vector area.
    let b = crate::geometry::Aabb::of(vertices.iter().copied());
    let enough = CERTIFIED_ENOUGH * (0..3).map(|k| b.hi[k] - b.lo[k]).product::<f64>();
    caps.certify(vertices, base, enough);
    Some(caps)
}

impl Caps {
    /// No caps yet.
    fn empty() -> Caps {
        Caps {
            centroids: Vec::new(),
            faces: Polygons::new(),
            holes: 0,
            cracks: 0,
            bound: 0.0,
            area: 0.0,
            loop_vertices: Vec::new(),
            loops: Vec::new(),
            interaction: Interaction {
                volume: 0.0,
                parts: Vec::new(),
            },
            cells: None,
        }
    }

    /// Sets [`Caps::interaction`] and, when they bound more, the certified cells once every hole is
    /// closed.
    ///
    /// Flat caps (every loop in its plane, exactly): one hole is exact, several are bounded by
    /// [`Caps::interaction`]. (The cells bound them too, sometimes with less volume, but their
    /// parts sit elsewhere: the smaller volume is not the smaller bound on inertia.)
    /// A cap that is not flat has no proven closed-form bound (2 × deviation × area, the flatness
    /// term, is a heuristic): the certified cells bound every cap together, their flatness and
    /// their seeing each other at once, each part in the ball of its cells. The bound reported is
    /// the larger of the cells' and the flatness and interaction terms: both rest on the capped
    /// surface's winding number being 0 or 1, which overlapping shells can break (a mesh of
    /// example-robot-data whose shells cut each other is off by more than the cells' bound and
    /// was covered only by the terms), so the terms are never undercut; the cells widen them
    /// where they are too small.
    fn certify(&mut self, vertices: &[[f64; 3]], base: u32, enough: f64) {
        let flat = self.loops.iter().all(|c| c.deviation == 0.0);
        self.interaction = self.interaction();
        if flat {
            return;
        }
        // Not flat: the larger of the proven cells and the flatness and interaction terms, whose
        // proof assumes what the cells assume (the capped surface's winding number is 0 or 1),
        // and which the ladder's overlapping shells may break: the larger stays honest where
        // today's terms were, and the certification stops once it is below them or `enough`.
        let terms = self.bound + self.interaction.volume;
        // The caps' triangles as (centre, b, a), from their faces (kept only when needed: 72 MB
        // for a hole of a million edges, flat and so never certified).
        let triangles: Vec<[[f64; 3]; 3]> = (self.faces.iter())
            .map(|f| {
                let c = self.centroids[(f[0] - base) as usize];
                [c, vertices[f[1] as usize], vertices[f[2] as usize]]
            })
            .collect();
        let cert = cells::certify(&triangles, terms.max(enough));
        if cert.volume <= terms {
            return;
        }
        // The flatness and interaction terms stay as they were, for what the warnings say of them.
        self.cells = Some(Interaction {
            volume: cert.volume,
            parts: (cert.parts.iter())
                .map(|&(volume, lo, hi)| {
                    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                    (volume, centre, 0.5 * norm(sub(hi, lo)))
                })
                .collect(),
        });
    }

    /// The caps' terms of the model error, each where it sits: the certified cells' parts when they
    /// bound the caps, else the flatness term near the loops and the interaction's parts.
    pub(super) fn terms(&self) -> Vec<(f64, Lever)> {
        let mut terms = Vec::new();
        let parts = if let Some(cells) = &self.cells {
            cells
        } else {
            terms.push((self.bound, Lever::Near(self.loop_vertices.clone())));
            &self.interaction
        };
        if parts.volume.is_finite() {
            terms.extend(
                (parts.parts.iter())
                    .map(|&(volume, centre, radius)| (volume, Lever::Ball(centre, radius))),
            );
        } else {
            terms.push((parts.volume, Lever::Anywhere));
        }
        terms
    }

    /// Closes one boundary loop, given as (vertex, edge a → b as directed in the mesh) steps, with a
    /// fan from its centroid (numbered `base` + the centroids so far), and adds its bound.
    pub(super) fn close(&mut self, vertices: &[[f64; 3]], base: u32, steps: &[(u32, u32, u32)]) {
        self.holes += 1;
        let n = steps.len() as f64;
        let c = [0, 1, 2].map(|k| steps.iter().map(|s| vertices[s.0 as usize][k]).sum::<f64>() / n);
        let ci = base + self.centroids.len() as u32;
        self.centroids.push(c);
        self.loop_vertices.push(c);
        let first = self.loop_vertices.len();
        self.loop_vertices
            .extend(steps.iter().map(|s| vertices[s.0 as usize]));
        let mut area = [0.0f64; 3];
        for &(_, a, b) in steps {
            // The mesh has a → b on its boundary; the cap runs b → a.
            self.faces.push(&[ci, b, a]);
            let x = cross(sub(vertices[b as usize], c), sub(vertices[a as usize], c));
            for k in 0..3 {
                area[k] += 0.5 * x[k];
            }
        }
        let len = dot(area, area).sqrt();
        self.area += len;
        let mut shape = CapShape {
            centre: c,
            normal: [0.0; 3],
            loop_points: first..self.loop_vertices.len(),
            radius: 0.0,
            area: 0.0,
            deviation: 0.0,
            lo: c,
            hi: c,
        };
        for &(v, a, b) in steps {
            let p = vertices[v as usize];
            shape.radius = shape.radius.max(norm(sub(p, c)));
            let x = cross(sub(vertices[b as usize], c), sub(vertices[a as usize], c));
            shape.area += 0.5 * norm(x);
            for k in 0..3 {
                shape.lo[k] = shape.lo[k].min(p[k]);
                shape.hi[k] = shape.hi[k].max(p[k]);
            }
        }
        if len > 0.0 {
            let nrm = area.map(|x| x / len);
            let dev = steps
                .iter()
                .map(|s| dot(sub(vertices[s.0 as usize], c), nrm).abs())
                .fold(0.0, f64::max);
            self.bound += 2.0 * dev * len;
            shape.deviation = dev;
            shape.normal = nrm;
        } else {
            // No plane: the cap may be anywhere within its loop's reach.
            shape.deviation = shape.radius;
        }
        self.loops.push(shape);
    }

    /// A bound on the volume by which the capped solid differs from Ω = {x : |w(x)| ≥ ½}, w the
    /// winding number of the open surface, that comes from the caps seeing each other.
    ///
    /// The capped surface has an integer winding number `w_c`, and w = `w_c` − Σⱼ wⱼ, wⱼ the winding
    /// number of cap j; where `w_c` is 0 or 1 the two solids differ only where Σⱼ |wⱼ| ≥ ½. A flat cap
    /// alone has |wⱼ| < ½ off its plane (it subtends less than a half-space), so one hole is exact and
    /// this bound is 0 (caps that are not flat are bounded by [`cells`] instead). With several flat
    /// caps of areas Aⱼ:
    ///
    /// * |wⱼ(x)| ≤ Aⱼ / (4π dⱼ²), dⱼ the distance from x to cap j (a surface of area Aⱼ subtends at
    ///   most Aⱼ/dⱼ²). Where they differ, some cap k has |wₖ| ≥ ½·√Aₖ/Σ√A (the thresholds sum to
    ///   ½), so x lies within ρₖ = Aₖ^¼·√(Σ√A / 2π) of cap k: in a cylinder about its plane of radius
    ///   R + ρₖ (R the loop's largest distance from its centre) and half-height ρₖ plus the loop's
    ///   deviation, and in the loop's box grown by ρₖ.
    /// * Moreover ½ − |wₖ(x)| ≤ Σ_{j≠k} |wⱼ(x)| ≤ δₖ, the other caps' bound over that neighbourhood
    ///   (at their boxes' distance from its box). For a flat cap inside a disc of radius R, at height
    ///   h above its plane and in-plane distance ρ' from its centre, ½ − |wₖ| ≥ ½·h / √(h² +
    ///   (R + ρ')²) (the plane outside the disc of radius R + ρ' about x's foot), so when δₖ < ½, x
    ///   lies in a slab of half-thickness 2δₖ(R + ρ') / √(1 − 4δₖ²) (plus the deviation) over a disc
    ///   of radius R + d, d ≤ ρ the distance |wₖ| ≥ ½ − δₖ allows.
    ///
    /// The bound is the sum over the caps (coplanar groups of them: [`Caps::coplanar_groups`]) of
    /// the smallest of these volumes. It is the caps of an
    /// open band (a tube open at both ends, whose caps see each other at a large solid angle: the
    /// winding number is fractional between them) that make it large.
    pub(super) fn interaction(&self) -> Interaction {
        let mut out = Interaction {
            volume: 0.0,
            parts: Vec::new(),
        };
        // Every pair of caps is looked at: beyond this many holes, not bounded (the caps are then
        // used only if the user asks for them).
        let Some(groups) = self.coplanar_groups() else {
            out.volume = f64::INFINITY;
            return out;
        };
        let n = groups.len();
        if n < 2 {
            return out;
        }
        let pi = std::f64::consts::PI;
        // Thresholds τₖ = ½·√Aₖ / Σ√A (they sum to ½): |wₖ| ≥ τₖ within ρₖ = √(Aₖ / 4πτₖ) of cap k,
        // so small caps get small neighbourhoods.
        let roots: f64 = groups.iter().map(|c| c.area.sqrt()).sum();
        // The other caps' largest winding number anywhere in the box `lo..hi`.
        let others = |k: usize, lo: [f64; 3], hi: [f64; 3]| -> f64 {
            (0..n)
                .filter(|&j| j != k)
                .map(|j| {
                    let c = &groups[j];
                    let d = box_distance(lo, hi, c.lo, c.hi);
                    if d > 0.0 {
                        c.area / (4.0 * pi * d * d)
                    } else {
                        f64::INFINITY
                    }
                })
                .sum()
        };
        let grown = |c: &CapShape, by: f64| (c.lo.map(|x| x - by), c.hi.map(|x| x + by));
        for (k, c) in groups.iter().enumerate() {
            let rho = c.area.sqrt().sqrt() * (roots / (2.0 * pi)).sqrt();
            // The neighbourhood where cap k can be the one that tips the sum.
            let (disc, half) = (c.radius + rho, c.deviation + rho);
            let (lo, hi) = grown(c, rho);
            // The cylinder, or the box grown by ρ (a sliver along an axis).
            let boxed = (0..3).map(|i| hi[i] - lo[i]).product::<f64>();
            let mut volume = (2.0 * half * pi * disc * disc).min(boxed);
            let mut delta = others(k, lo, hi);
            if delta < 0.5 {
                // Where |w_k| ≥ ½ − δ: within d ≤ ρ; the other caps seen from there, once more.
                let mut d = rho.min((c.area / (4.0 * pi * (0.5 - delta))).sqrt());
                let (lo, hi) = grown(c, d);
                delta = delta.min(others(k, lo, hi));
                d = d.min((c.area / (4.0 * pi * (0.5 - delta))).sqrt());
                let a = 2.0 * c.radius + d;
                let t = 2.0 * delta * a / (1.0 - 4.0 * delta * delta).sqrt() + c.deviation;
                let r = c.radius + d;
                volume = volume.min(2.0 * t * pi * r * r);
            }
            if volume.is_nan() {
                return Interaction {
                    volume: f64::INFINITY,
                    parts: Vec::new(),
                };
            }
            if volume == 0.0 {
                continue;
            }
            out.volume += volume;
            // The ball around the cylinder: where this part sits.
            let ball = (disc * disc + half * half).sqrt();
            out.parts.push((volume, c.centre, ball));
        }
        out
    }

    /// The caps gathered into coplanar groups: caps in one plane (within their own deviation from
    /// it, up to 1e-9 of the group's size) whose loops' boxes in that plane are disjoint. Such a
    /// group is one flat region (its caps do not overlap), so its winding number is below ½ in
    /// magnitude off its plane like a single cap's: the caps of one group do not tip each other.
    /// A hole split at a pinch vertex, or several holes in one flat side, are one group.
    /// `None` once there are more than [`MAX_INTERACTING`] groups (their number never falls as caps
    /// are added): each cap was compared with every group, and [`Caps::interaction`] compares every
    /// pair, so going on would be quadratic in the holes (figures: docs/benchmarks.md, "Figures
    /// behind choices in the code"). Past [`FEW_GROUPS`] a cap looks only at the groups whose
    /// normals are near its own ([`ParallelGroups`]).
    ///
    /// Each cap goes to the first group it fits, as the groups are when it comes, and a group's
    /// radius and deviation are its members' farthest points from the centre of their box: a new
    /// member that moves that centre (each of a row of holes does) would mean going over every
    /// member again, quadratic in the holes of a row (20,000 in a strip: 5.3 s). A group keeps them
    /// exact while its centre stays put and bounds them after it moves ([`Group`]); they are
    /// computed over every member only when a cap's tolerance cannot be decided from the bounds,
    /// and once at the end, so the groups and their shapes are the same, bit for bit.
    fn coplanar_groups(&self) -> Option<Vec<CapShape>> {
        let mut groups: Vec<Group> = Vec::new();
        let mut parallel = ParallelGroups::default();
        for (k, c) in self.loops.iter().enumerate() {
            let mut joined = None;
            if c.normal != [0.0; 3] {
                let candidates = (groups.len() > FEW_GROUPS)
                    .then(|| parallel.candidates(c.normal))
                    .flatten();
                let order = candidates.unwrap_or_else(|| (0..groups.len() as u32).collect());
                for i in order {
                    if let Some(b) = self.joins(&mut groups[i as usize], c) {
                        joined = Some((i as usize, b));
                        break;
                    }
                }
            }
            if let Some((i, b)) = joined {
                groups[i].boxes.push(b);
                self.merge(&mut groups[i], k);
            } else {
                if c.normal != [0.0; 3] {
                    parallel.insert(c.normal, groups.len() as u32);
                }
                // A cap without a plane joins no group: its group needs no boxes.
                let mut boxes = PlaneBoxes::new();
                if c.normal != [0.0; 3] {
                    let u = any_perpendicular(c.normal);
                    boxes.push(self.flat_box(c, u, cross(c.normal, u)));
                }
                groups.push(Group {
                    shape: c.clone(),
                    members: vec![k],
                    exact: true,
                    radius_hi: c.radius,
                    deviation_hi: c.deviation,
                    deviations: c.deviation,
                    boxes,
                });
            }
            if groups.len() > MAX_INTERACTING {
                return None;
            }
        }
        let shapes = groups.into_iter().map(|mut g| {
            if !g.exact {
                self.settle(&mut g);
            }
            g.shape
        });
        Some(shapes.collect())
    }

    /// Whether cap `c` joins the group `g`: parallel, within the tolerance of its plane, and with
    /// its loop's in-plane box apart from every member's; that box when it does. The tolerance
    /// grows with the group's radius and deviation, so bounds on them decide it when `off` is
    /// below it with their lower bounds or above it with their upper ones (the sums and maxima
    /// of nonnegative numbers round monotonically); otherwise they are computed ([`Caps::settle`]).
    fn joins(&self, g: &mut Group, c: &CapShape) -> Option<[f64; 4]> {
        let n = g.shape.normal;
        if n == [0.0; 3] || dot(n, c.normal).abs() < 1.0 - 1e-12 {
            return None;
        }
        let off = (self.points(c).iter())
            .map(|p| dot(sub(*p, g.shape.centre), n).abs())
            .fold(0.0, f64::max);
        let beyond = |g: &CapShape, radius: f64, deviation: f64| {
            let size = radius + c.radius + norm(sub(g.centre, c.centre));
            off > deviation.max(c.deviation) + 1e-9 * size
        };
        if beyond(&g.shape, g.shape.radius, g.shape.deviation) {
            if g.exact || beyond(&g.shape, g.radius_hi, g.deviation_hi) {
                return None;
            }
            self.settle(g);
            if beyond(&g.shape, g.shape.radius, g.shape.deviation) {
                return None;
            }
        }
        let u = any_perpendicular(n);
        let b = self.flat_box(c, u, cross(n, u));
        (!g.boxes.meets(b)).then_some(b)
    }

    /// Adds cap `k` to the group `g`: its area and box, the box's centre, and the radius and
    /// deviation about it, exact when the centre stays put (bit for bit: the same maxima of the same
    /// numbers) and bounded when it moves.
    ///
    /// Why the bounds after a move hold (ε = 2⁻⁵³): a point p's computed distance from the
    /// centre C is within 5ε of |p − C| relative to it (a rounding in each difference, square and
    /// sum, and in the square root), and its computed distance from the plane within 5ε·|p − C|
    /// of |(p − C)·n| (n the stored normal, |n| ≤ 1 + 2ε); underflow adds at most 1e-161 to
    /// either, and nothing overflows while the bounds stay below 1e150. When the centre moves to
    /// C′, every exact distance moves by at most |C′ − C|, itself within 5ε (and 1e-161) of the
    /// computed d. So the computed radius about C′ is at most (1 + 5ε)((hi + 1e-161)/(1 − 5ε) +
    /// (1 + 5ε)d + 1e-161) + 1e-161, hi the bound about C, which (hi + d)(1 + 1e-12) + 1e-150
    /// exceeds even as rounded in f64 (three roundings of ε each: [`widened`]); the deviation
    /// likewise, with 5ε of the radius about C and about C′ added before widening (1e-12 × the sum
    /// of their bounds). Past 1e150 (or NaN) a bound is infinite: the tolerance is then decided
    /// exactly.
    fn merge(&self, g: &mut Group, k: usize) {
        let c = &self.loops[k];
        g.members.push(k);
        g.deviations = g.deviations.max(c.deviation);
        if g.members.len() == 2 {
            self.settle(g);
            return;
        }
        let before = g.shape.centre;
        grow_box(&mut g.shape, c);
        g.shape.centre = box_centre(&g.shape);
        let (radius, deviation) = self.reach(&g.shape, c);
        if g.shape.centre.map(f64::to_bits) == before.map(f64::to_bits) {
            g.shape.radius = g.shape.radius.max(radius);
            g.shape.deviation = g.shape.deviation.max(deviation);
            g.radius_hi = g.radius_hi.max(radius);
            g.deviation_hi = g.deviation_hi.max(deviation);
        } else {
            let moved = norm(sub(g.shape.centre, before));
            let radius_hi = widened(g.radius_hi, moved);
            let spread = g.deviation_hi + 1e-12 * (g.radius_hi + radius_hi);
            g.deviation_hi = widened(spread, moved).max(deviation);
            g.radius_hi = radius_hi.max(radius);
            // What is known about the new centre: the new member's own reach, every member's
            // deviation.
            g.shape.radius = radius;
            g.shape.deviation = deviation.max(g.deviations);
            g.exact = false;
        }
    }

    /// The group's radius and deviation computed over every member.
    fn settle(&self, g: &mut Group) {
        g.shape = self.merged_in_full(g.shape.normal, &g.members);
        (g.radius_hi, g.deviation_hi) = (g.shape.radius, g.shape.deviation);
        g.exact = true;
    }

    /// One flat region made of the caps `members`, in the plane of the unit `normal` through the
    /// centre of their loops' box: the area as the running sum in member order, the box, and the
    /// largest distances of the members' points from that centre and plane.
    fn merged_in_full(&self, normal: [f64; 3], members: &[usize]) -> CapShape {
        let mut g = self.loops[members[0]].clone();
        for &m in &members[1..] {
            grow_box(&mut g, &self.loops[m]);
        }
        g.normal = normal;
        g.centre = box_centre(&g);
        (g.radius, g.deviation) = (0.0, 0.0);
        for &m in members {
            let (radius, deviation) = self.reach(&g, &self.loops[m]);
            g.radius = g.radius.max(radius);
            g.deviation = g.deviation.max(deviation);
        }
        g
    }

    /// Member `c`'s largest distances from `g`'s centre and plane, over its loop and fan centre,
    /// and at least `c`'s own deviation (its fan is within it of its loop's plane).
    fn reach(&self, g: &CapShape, c: &CapShape) -> (f64, f64) {
        let (mut radius, mut deviation) = (0.0f64, c.deviation);
        for p in self.points(c).iter().chain([&c.centre]) {
            radius = radius.max(norm(sub(*p, g.centre)));
            deviation = deviation.max(dot(sub(*p, g.centre), g.normal).abs());
        }
        (radius, deviation)
    }

    /// The vertices of cap `c`'s loop.
    fn points(&self, c: &CapShape) -> &[[f64; 3]] {
        &self.loop_vertices[c.loop_points.clone()]
    }

    /// The box of cap `c`'s loop in the plane's basis (u, v).
    fn flat_box(&self, c: &CapShape, u: [f64; 3], v: [f64; 3]) -> [f64; 4] {
        let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        for p in self.points(c) {
            let (x, y) = (dot(*p, u), dot(*p, v));
            b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
        }
        b
    }
}

/// Groups beyond which a cap looks only at the groups whose normals are near its own
/// ([`ParallelGroups`]); up to it, at every group (fewer than the 54 cells it would look in).
const FEW_GROUPS: usize = 64;

/// The side of the cells of normals in [`ParallelGroups`].
const NORMAL_CELL: f64 = 1e-5;

/// The groups by their normals, in cells of [`NORMAL_CELL`] a side, so that a cap need not be
/// compared with every group (up to [`MAX_INTERACTING`] of them, each a dot product: 4,000 lone
/// triangles before a strip of 50,000 holes, 1.9 s).
///
/// A group that passes [`Caps::joins`]'s parallel test is in a cell next to the cap's normal's
/// or its opposite's: both normals are unit vectors within 1e-12 (their squared lengths; else
/// they have no cell), so |dot| ≥ 1 − 1e-12 (computed, within 4ε of exact) leaves them at most
/// √(4·1e-12 + 14ε) < 2.1e-6 apart (or from each other's opposite), about a fifth of a cell in each
/// coordinate, and the cell of a coordinate, ⌊x / cell⌋ in f64, never decreases as it grows. The
/// groups without a cell are always looked at, and a cap without one looks at every group; the
/// rest fail the parallel test before anything else, so going over the candidates in the groups'
/// order finds the same first group.
#[derive(Default)]
struct ParallelGroups {
    cells: rustc_hash::FxHashMap<[i64; 3], Vec<u32>>,
    /// Groups whose normal has no cell.
    elsewhere: Vec<u32>,
}

impl ParallelGroups {
    fn insert(&mut self, normal: [f64; 3], group: u32) {
        match normal_cell(normal) {
            Some(cell) => self.cells.entry(cell).or_default().push(group),
            None => self.elsewhere.push(group),
        }
    }

    /// The groups that may be parallel to `normal`, in their order; `None` when `normal` has no
    /// cell (every group may be).
    fn candidates(&self, normal: [f64; 3]) -> Option<Vec<u32>> {
        let mut out = self.elsewhere.clone();
        for n in [normal, normal.map(|x| -x)] {
            let [a, b, c] = normal_cell(n)?;
            for i in a - 1..=a + 1 {
                for j in b - 1..=b + 1 {
                    for k in c - 1..=c + 1 {
                        out.extend(self.cells.get(&[i, j, k]).into_iter().flatten());
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        Some(out)
    }
}

/// The cell of a unit normal ([`ParallelGroups`]); `None` unless it is finite and of unit length
/// within 1e-12 (squared).
fn normal_cell(n: [f64; 3]) -> Option<[i64; 3]> {
    let unit = n.iter().all(|x| x.is_finite()) && (dot(n, n) - 1.0).abs() <= 1e-12;
    unit.then(|| n.map(|x| (x / NORMAL_CELL).floor() as i64))
}

/// A coplanar group being gathered ([`Caps::coplanar_groups`]).
struct Group {
    /// Its area, box, centre and normal; its radius and deviation when `exact`, else lower bounds
    /// on them (what is known about the current centre: maxima over some of the members).
    shape: CapShape,
    members: Vec<usize>,
    exact: bool,
    /// Upper bounds on the radius and deviation that [`Caps::merged_in_full`] would compute
    /// ([`Caps::merge`]); equal to them when `exact`.
    radius_hi: f64,
    deviation_hi: f64,
    /// The largest of the members' own deviations.
    deviations: f64,
    /// The members' loops' boxes in the group's plane (the normal never changes once the group
    /// is made, so neither do they).
    boxes: PlaneBoxes,
}

/// `hi` + `d` with the margin [`Caps::merge`] proves enough: relative 1e-12 (the roundings, a few
/// ε) and absolute 1e-150 (underflow); infinite past 1e150 (or NaN), where squares could overflow.
fn widened(hi: f64, d: f64) -> f64 {
    let w = (hi + d) * (1.0 + 1e-12) + 1e-150;
    if w <= 1e150 {
        w
    } else {
        f64::INFINITY
    }
}

/// Adds member `c`'s area and box to the group `g`'s.
fn grow_box(g: &mut CapShape, c: &CapShape) {
    g.area += c.area;
    for k in 0..3 {
        g.lo[k] = g.lo[k].min(c.lo[k]);
        g.hi[k] = g.hi[k].max(c.hi[k]);
    }
}

/// The centre of a group's box.
fn box_centre(g: &CapShape) -> [f64; 3] {
    [0, 1, 2].map(|k| 0.5 * (g.lo[k] + g.hi[k]))
}

/// Holes beyond which [`Caps::interaction`] (quadratic in them) is not computed but unbounded.
const MAX_INTERACTING: usize = 4_096;

/// A unit vector perpendicular to the unit vector `n`.
fn any_perpendicular(n: [f64; 3]) -> [f64; 3] {
    let axis = if n[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = cross(n, axis);
    let l = norm(u);
    u.map(|x| x / l)
}


/// The distance between two boxes (0 when they meet).
fn box_distance(alo: [f64; 3], ahi: [f64; 3], blo: [f64; 3], bhi: [f64; 3]) -> f64 {
    let gap = [0, 1, 2].map(|k| (blo[k] - ahi[k]).max(alo[k] - bhi[k]).max(0.0));
    norm(gap)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The caps of `k` square holes in the plane z = 0.25, of sides and places that vary (so the
    /// group's box grows at some holes and not at others), in a scrambled order.
    fn perforated(k: u32) -> Caps {
        let (mut vertices, mut half) = (Vec::new(), Vec::new());
        for i in 0..k {
            let j = (i * 7919) % k;
            let (x, y, s) = (f64::from(j % 17) * 3.0, f64::from(j / 17) * 3.0, 1.0 + 0.1 * f64::from(j % 5));
            let n = vertices.len() as u32;
            vertices.extend([[x, y, 0.25], [x + s, y, 0.25], [x + s, y + s, 0.25], [x, y + s, 0.25]]);
            half.extend((0..4).map(|e| (n + e, n + (e + 1) % 4)));
        }
        cap_holes(&vertices, &half).unwrap()
    }

    /// Caps closed over the given loops of `vertices` (no certification: the loops need not be
    /// flat).
    fn caps_over(vertices: &[[f64; 3]], loops: &[Vec<u32>]) -> Caps {
        let mut caps = Caps::empty();
        for l in loops {
            let steps: Vec<(u32, u32, u32)> =
                (0..l.len()).map(|i| (l[i], l[i], l[(i + 1) % l.len()])).collect();
            caps.close(vertices, vertices.len() as u32, &steps);
        }
        caps
    }

    /// Holes in random layouts: squares and triangles of random sizes and places (overlapping
    /// each other's boxes or not), in a few planes (one tilted, parallel ones a tolerance apart, a
    /// normal within the parallel test's reach) and in a pool of 100 planes at random angles
    /// (past [`FEW_GROUPS`]), some slightly bent, some wound the other way, in random order.
    fn random_layout(seed: u64, k: usize) -> Caps {
        let mut rng = seed;
        let mut unit = || (crate::xorshift(&mut rng) >> 11) as f64 / (1u64 << 53) as f64;
        let c = 0.6f64;
        let s = 0.8f64;
        let tilt = |p: [f64; 3]| [c * p[0] - s * p[2], p[1], s * p[0] + c * p[2]];
        // A pool of 100 planes through the origin at random angles (θ, φ).
        let turns: Vec<(f64, f64)> = (0..100).map(|_| (6.0 * unit(), 3.0 * unit())).collect();
        let (mut vertices, mut loops) = (Vec::new(), Vec::new());
        for _ in 0..k {
            let (x, y) = (40.0 * unit(), 40.0 * unit());
            let side = 0.2 + 2.0 * unit();
            let plane = (unit() * 8.0) as u32;
            // z = 1 ± a tolerance of the group's size (1e-9 of ~60 m) and a tiny bend.
            let z = match plane {
                0 | 1 => 1.0,
                2 => 1.0 + 6e-8 * unit(),
                3 => 1.0 + 1e-3,
                _ => 0.0,
            };
            let bend = if unit() < 0.1 { 1e-9 * unit() } else { 0.0 };
            let mut corners = vec![[x, y, z], [x + side, y, z + bend], [x + side, y + side, z]];
            if unit() < 0.7 {
                corners.push([x, y + side, z - bend]);
            }
            if plane == 1 {
                // A normal 1e-7 off the plane's: parallel within the test's 1e-12.
                corners = corners.iter().map(|p| [p[0], p[1], p[2] + 1e-7 * p[0]]).collect();
            }
            if plane == 5 {
                corners = corners.into_iter().map(tilt).collect();
            }
            if plane >= 6 {
                // One of the pool's planes, sometimes turned by 1e-7 (parallel within 1e-12).
                let (mut t, f) = turns[(unit() * 100.0) as usize];
                if unit() < 0.3 {
                    t += 1e-7 * unit();
                }
                let turn = |p: [f64; 3]| {
                    let q = [t.cos() * p[0] - t.sin() * p[2], p[1], t.sin() * p[0] + t.cos() * p[2]];
                    [q[0], f.cos() * q[1] - f.sin() * q[2], f.sin() * q[1] + f.cos() * q[2]]
                };
                corners = corners.into_iter().map(turn).collect();
            }
            if unit() < 0.3 {
                // Wound the other way: an opposite normal.
                corners.reverse();
            }
            let n = vertices.len() as u32;
            loops.push((n..n + corners.len() as u32).collect::<Vec<u32>>());
            vertices.extend(corners);
        }
        caps_over(&vertices, &loops)
    }

    /// The coplanar groups as they were computed before round 33 (every member gone over again
    /// whenever the group's centre moved, every member's box tested): the reference.
    fn coplanar_groups_as_before(caps: &Caps) -> Option<Vec<CapShape>> {
        let pts = |c: &CapShape| caps.points(c);
        let mut groups: Vec<(CapShape, Vec<usize>, Vec<[f64; 4]>)> = Vec::new();
        for (k, c) in caps.loops.iter().enumerate() {
            let joined = (c.normal != [0.0; 3])
                .then(|| {
                    groups.iter_mut().find(|(g, _, boxes)| {
                        if g.normal == [0.0; 3] || dot(g.normal, c.normal).abs() < 1.0 - 1e-12 {
                            return false;
                        }
                        let n = g.normal;
                        let size = g.radius + c.radius + norm(sub(g.centre, c.centre));
                        let off = pts(c)
                            .iter()
                            .map(|p| dot(sub(*p, g.centre), n).abs())
                            .fold(0.0, f64::max);
                        if off > g.deviation.max(c.deviation) + 1e-9 * size {
                            return false;
                        }
                        let u = any_perpendicular(n);
                        let b = caps.flat_box(c, u, cross(n, u));
                        boxes.iter().all(|o| {
                            b[2] < o[0] || o[2] < b[0] || b[3] < o[1] || o[3] < b[1]
                        })
                    })
                })
                .flatten();
            if let Some((g, members, boxes)) = joined {
                let n = g.normal;
                let u = any_perpendicular(n);
                boxes.push(caps.flat_box(c, u, cross(n, u)));
                members.push(k);
                *g = merged_as_before(caps, g, members);
            } else {
                let boxes = if c.normal == [0.0; 3] {
                    Vec::new()
                } else {
                    let u = any_perpendicular(c.normal);
                    vec![caps.flat_box(c, u, cross(c.normal, u))]
                };
                groups.push((c.clone(), vec![k], boxes));
            }
            if groups.len() > MAX_INTERACTING {
                return None;
            }
        }
        Some(groups.into_iter().map(|g| g.0).collect())
    }

    /// The group widened by its last member as before round 33: one member at a time while the
    /// box's centre stays put, else over every member, each point in turn.
    fn merged_as_before(caps: &Caps, group: &CapShape, members: &[usize]) -> CapShape {
        let grow_reach = |g: &mut CapShape, c: &CapShape| {
            for p in caps.points(c).iter().chain([&c.centre]) {
                g.radius = g.radius.max(norm(sub(*p, g.centre)));
                g.deviation = g.deviation.max(dot(sub(*p, g.centre), g.normal).abs());
            }
            g.deviation = g.deviation.max(c.deviation);
        };
        let c = &caps.loops[*members.last().unwrap()];
        if members.len() > 2 {
            let mut g = group.clone();
            grow_box(&mut g, c);
            g.centre = box_centre(&g);
            if g.centre.map(f64::to_bits) == group.centre.map(f64::to_bits) {
                grow_reach(&mut g, c);
                return g;
            }
        }
        let mut g = caps.loops[members[0]].clone();
        for &m in &members[1..] {
            grow_box(&mut g, &caps.loops[m]);
        }
        g.normal = group.normal;
        g.centre = box_centre(&g);
        (g.radius, g.deviation) = (0.0, 0.0);
        for &m in members {
            grow_reach(&mut g, &caps.loops[m]);
        }
        g
    }

    fn same(a: &CapShape, b: &CapShape) -> bool {
        let bits = |c: &CapShape| {
            let mut v: Vec<u64> = [c.radius, c.area, c.deviation].map(f64::to_bits).to_vec();
            for p in [c.centre, c.normal, c.lo, c.hi] {
                v.extend(p.map(f64::to_bits));
            }
            v
        };
        bits(a) == bits(b) && a.loop_points == b.loop_points
    }

    fn same_groups(caps: &Caps) -> usize {
        let (new, old) = (caps.coplanar_groups().unwrap(), coplanar_groups_as_before(caps).unwrap());
        assert_eq!(new.len(), old.len());
        assert!(new.iter().zip(&old).all(|(a, b)| same(a, b)));
        new.len()
    }

    /// The groups with bounds in place of the radius and deviation after a move, and the grid of
    /// boxes, are the groups computed as before, bit for bit: on holes in one plane, and on random
    /// layouts whose caps are near the tolerance of several planes' groups (so some joins are
    /// decided from the bounds and some need the group computed in full).
    #[test]
    fn coplanar_groups_are_as_before() {
        let caps = perforated(300);
        assert_eq!(caps.holes, 300);
        assert_eq!(same_groups(&caps), 1);
        let normal = caps.loops[0].normal;
        let all: Vec<usize> = (0..caps.loops.len()).collect();
        assert!(same(&caps.coplanar_groups().unwrap()[0], &caps.merged_in_full(normal, &all)));
        assert_eq!(caps.interaction().volume, 0.0);
        let mut sizes = Vec::new();
        for seed in 1..=40u64 {
            let caps = random_layout(seed * 0x9e37_79b9, 30 + 20 * seed as usize);
            sizes.push(same_groups(&caps));
        }
        assert!(sizes.iter().all(|&n| n > 3), "{sizes:?}");
        assert!(sizes.iter().filter(|&&n| n > FEW_GROUPS).count() >= 25, "{sizes:?}");
    }
}
