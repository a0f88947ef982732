//! Flat caps over the boundary loops of an open surface, with the bound their flatness leaves. Moved
//! out of the ladder ([`super`]) as it is.

use crate::geometry::{cross, dot, sub};
use crate::mass::Polygons;
use rustc_hash::FxHashMap;

/// Boundary loops closed by fans from their centroids.
pub(super) struct Caps {
    /// One new vertex per hole (its centroid), numbered after the mesh's vertices.
    pub(super) centroids: Vec<[f64; 3]>,
    pub(super) faces: Polygons,
    pub(super) holes: usize,
    /// Boundary edges left open (cracks, T-junctions).
    pub(super) cracks: usize,
    /// Bound on the volume uncertainty the caps and cracks leave, m³.
    pub(super) bound: f64,
    /// Total area of the caps, m².
    pub(super) area: f64,
    /// The vertices of the loops closed and the caps' centres: where the caps' uncertainty sits.
    pub(super) points: Vec<[f64; 3]>,
}

/// Closes every boundary loop of `faces` with a fan from the loop's centroid, wound against the loop's
/// edges so the result is consistently oriented. The volume uncertainty bound: two surfaces spanning
/// a loop that both lie within the loop's largest distance `d` from its mean plane enclose at most
/// 2·d × (cap area) between them; boundary chains that do not close add |vector area| × diagonal / 6.
/// `None` when there are no boundary edges. `half` are the boundary edges as directed in their faces,
/// in the order of [`edges`].
pub(super) fn cap_holes(vertices: &[[f64; 3]], half: &[(u32, u32)]) -> Option<Caps> {
    if half.is_empty() {
        return None;
    }
    // Walk boundary edges as undirected (cracks and slivers often have both sides in one direction),
    // preferring the mesh's own direction; each cap triangle is wound against its own edge.
    let mut out_of: FxHashMap<u32, Vec<(u32, usize, bool)>> = FxHashMap::default();
    for (i, &(u, v)) in half.iter().enumerate() {
        out_of.entry(u).or_default().push((v, i, true));
    }
    for (i, &(u, v)) in half.iter().enumerate() {
        out_of.entry(v).or_default().push((u, i, false));
    }
    let mut used = vec![false; half.len()];
    let base = vertices.len() as u32;
    let mut caps = Caps {
        centroids: Vec::new(),
        faces: Polygons::new(),
        holes: 0,
        cracks: 0,
        bound: 0.0,
        area: 0.0,
        points: Vec::new(),
    };
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
            let Some((next, i, forward)) = out_of
                .get(&at)
                .and_then(|o| o.iter().find(|(_, i, _)| !used[*i]).copied())
            else {
                closed = false;
                break;
            };
            used[i] = true;
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
    Some(caps)
}

impl Caps {
    /// Closes one boundary loop, given as (vertex, edge a → b as directed in the mesh) steps, with a
    /// fan from its centroid (numbered `base` + the centroids so far), and adds its bound.
    pub(super) fn close(&mut self, vertices: &[[f64; 3]], base: u32, steps: &[(u32, u32, u32)]) {
        self.holes += 1;
        let n = steps.len() as f64;
        let c = [0, 1, 2].map(|k| steps.iter().map(|s| vertices[s.0 as usize][k]).sum::<f64>() / n);
        let ci = base + self.centroids.len() as u32;
        self.centroids.push(c);
        self.points.push(c);
        self.points
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
        if len > 0.0 {
            let nrm = area.map(|x| x / len);
            let dev = steps
                .iter()
                .map(|s| dot(sub(vertices[s.0 as usize], c), nrm).abs())
                .fold(0.0, f64::max);
            self.bound += 2.0 * dev * len;
        }
    }
}
