//! Mesh health: from a (scaled) mesh as read to a closed, outward solid, or a precise reason why not.
//!
//! Coincident vertices are welded (bit-exact, after scaling) and degenerate faces dropped. Then the edge
//! structure decides the rung:
//!
//! 1. [`Rung::Exact`]: closed, manifold, consistently wound outward. No message.
//! 2. [`Rung::Reoriented`]: closed, but some faces wound against their neighbours: each connected
//!    component is made consistent, then turned outward by its signed volume.
//! 3. [`Rung::Inverted`]: closed and consistent but wound inward (negative volume): flipped.
//! 4. Open (boundary edges) or non-manifold, after orienting what the manifold edges allow:
//!    * [`Rung::Capped`]: each boundary loop is closed by a fan from its centroid. For a planar hole that
//!      cap is exact; for a non-planar one, any cap spanning the loop differs from it by at most about
//!      (the loop's largest distance from its mean plane) × (the cap's area). When that bound, summed over
//!      the holes, is below 1e-3 of the volume, the capped mesh is used and the bound reported.
//!    * [`Rung::NonManifold`]: no boundary edges but edges shared by three or more faces (solids touching
//!      along an edge, or overlapping shells): the surface still bounds a region, integrated as it is
//!      (a region enclosed twice counts twice: a warning says so).
//!    * [`Rung::ConvexHull`] otherwise: the convex hull of its vertices, with the numbers that say how far
//!      that is from the mesh.
//! 5. Zero or near-zero volume: an error.
//!
//! A consistently wound closed mesh is only flipped when its *total* volume is negative, so a shell with
//! an inward cavity keeps its cavity.

use super::{hull, MeshError, MeshErrorKind, RawMesh};
use crate::mass::integrals::{bounding_box_centre, volume_integrals};
use crate::mass::{frobenius, IntegrationOptions, MassProperties, Polygons};
use std::collections::HashMap;
use std::path::Path;

/// Which rung of the repair ladder produced a solid's numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum Rung {
    Exact,
    Reoriented {
        faces_flipped: usize,
        components: usize,
    },
    Inverted,
    Capped {
        holes: usize,
        boundary_edges: usize,
        nonmanifold_edges: usize,
        faces_flipped: usize,
        relative_uncertainty: f64,
    },
    NonManifold {
        nonmanifold_edges: usize,
        faces_flipped: usize,
    },
    ConvexHull {
        boundary_edges: usize,
        nonmanifold_edges: usize,
        mesh_volume: f64,
        hull_volume: f64,
        volume_moves_by: f64,
    },
}

impl Rung {
    /// A short name for tables and JSON.
    pub fn name(&self) -> &'static str {
        match self {
            Rung::Exact => "exact",
            Rung::Reoriented { .. } => "reoriented",
            Rung::Inverted => "inverted",
            Rung::Capped { .. } => "capped",
            Rung::NonManifold { .. } => "non-manifold",
            Rung::ConvexHull { .. } => "convex-hull",
        }
    }

    /// Whether the solid is the mesh itself (possibly re-wound), not a stand-in.
    pub fn is_mesh_itself(&self) -> bool {
        !matches!(self, Rung::ConvexHull { .. })
    }
}

/// A closed, outward solid ready to integrate, with its unit-density mass properties.
#[derive(Debug, Clone)]
pub struct Solid {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Polygons,
    pub rung: Rung,
    /// Messages for the user: what was done to the mesh and why.
    pub warnings: Vec<String>,
    /// Mass properties at density 1 (mass = volume), in the mesh frame.
    pub unit: MassProperties,
    /// Relative disagreement of the central inertia integrated about two reference points (a closed
    /// surface gives the same result about any point; round-off alone separates them).
    pub error_estimate: f64,
    /// Faces in the file (before welding and dropping degenerate ones).
    pub faces_read: usize,
}

/// Options of the ladder.
#[derive(Debug, Clone, Copy, Default)]
pub struct HealthOptions {
    /// Every rung below [`Rung::Exact`] is an error.
    pub strict: bool,
}

/// Relative volume below which a solid counts as empty (against the bounding-box diagonal cubed).
const ZERO_VOLUME: f64 = 1e-12;

/// Largest relative volume uncertainty of the caps for which a capped mesh is used.
const CAPPED: f64 = 1e-3;

/// A multiply-rotate hasher (rustc's Fx hash, with a finalising mix) for integer keys: welding 4 M
/// vertices with the default SipHash took 390 ns per face, most of the healing time.
#[derive(Debug, Default, Clone, Copy)]
struct FxHasher(u64);

impl std::hash::Hasher for FxHasher {
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }
    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
    fn finish(&self) -> u64 {
        // Coordinates read from f32 have 29 zero low bits, which a plain multiply keeps in the low bits
        // the table indexes by: fold the high half down (MurmurHash3's finaliser step).
        let h = self.0 ^ (self.0 >> 33);
        h.wrapping_mul(0xff51_afd7_ed55_8ccd) ^ (h >> 29)
    }
}

type FxMap<K, V> = HashMap<K, V, std::hash::BuildHasherDefault<FxHasher>>;

/// Welds bit-identical vertices and drops faces that collapse to fewer than three distinct vertices.
pub fn weld(mesh: &RawMesh) -> (Vec<[f64; 3]>, Polygons, usize) {
    let mut map: FxMap<[u64; 3], u32> =
        FxMap::with_capacity_and_hasher(mesh.vertices.len() / 2, Default::default());
    let mut vertices = Vec::new();
    let remap: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|p| {
            // +0.0 folds -0.0 into 0.0 so that both weld.
            let key = [
                (p[0] + 0.0).to_bits(),
                (p[1] + 0.0).to_bits(),
                (p[2] + 0.0).to_bits(),
            ];
            *map.entry(key).or_insert_with(|| {
                vertices.push([p[0] + 0.0, p[1] + 0.0, p[2] + 0.0]);
                (vertices.len() - 1) as u32
            })
        })
        .collect();
    let mut faces = Polygons::new();
    let mut dropped = 0;
    let mut f: Vec<u32> = Vec::new();
    for face in mesh.faces.iter() {
        f.clear();
        for &i in face {
            let j = remap[i as usize];
            if f.last() != Some(&j) {
                f.push(j);
            }
        }
        while f.len() > 1 && f.first() == f.last() {
            f.pop();
        }
        let mut distinct = f.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 3 {
            dropped += 1;
        } else {
            faces.push(&f);
        }
    }
    (vertices, faces, dropped)
}

/// Edge structure of a welded mesh.
#[derive(Debug, Default)]
struct Edges {
    boundary: usize,
    nonmanifold: usize,
    /// Pairs of faces sharing a manifold edge, and whether they traverse it the same way (inconsistent).
    pairs: Vec<(u32, u32, bool)>,
    inconsistent: usize,
    /// Boundary edges as directed in their face.
    boundary_half_edges: Vec<(u32, u32)>,
}

fn edges(faces: &Polygons) -> Edges {
    let mut rec: Vec<(u64, u32, bool)> = Vec::with_capacity(faces.indices.len());
    for (fi, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            let (u, v) = (face[k], face[(k + 1) % face.len()]);
            let key = ((u.min(v) as u64) << 32) | u.max(v) as u64;
            rec.push((key, fi as u32, u < v));
        }
    }
    let key_edge = |key: u64, forward: bool| {
        let (a, b) = ((key >> 32) as u32, key as u32);
        if forward {
            (a, b)
        } else {
            (b, a)
        }
    };
    rec.sort_unstable_by_key(|r| r.0);
    let mut e = Edges::default();
    let mut i = 0;
    while i < rec.len() {
        let mut j = i + 1;
        while j < rec.len() && rec[j].0 == rec[i].0 {
            j += 1;
        }
        match j - i {
            1 => {
                e.boundary += 1;
                e.boundary_half_edges.push(key_edge(rec[i].0, rec[i].2));
            }
            2 => {
                let same = rec[i].2 == rec[i + 1].2;
                if same {
                    e.inconsistent += 1;
                }
                e.pairs.push((rec[i].1, rec[i + 1].1, same));
            }
            _ => e.nonmanifold += 1,
        }
        i = j;
    }
    e
}

/// Orients each connected component consistently. Returns per-face flips and component ids, or `None`
/// when a component cannot be oriented (a Möbius-like surface).
fn orient(nfaces: usize, pairs: &[(u32, u32, bool)]) -> Option<(Vec<bool>, Vec<u32>, usize)> {
    let mut adj: Vec<Vec<(u32, bool)>> = vec![Vec::new(); nfaces];
    for &(a, b, same) in pairs {
        adj[a as usize].push((b, same));
        adj[b as usize].push((a, same));
    }
    let mut flip = vec![false; nfaces];
    let mut comp = vec![u32::MAX; nfaces];
    let mut ncomp = 0u32;
    let mut stack = Vec::new();
    for start in 0..nfaces {
        if comp[start] != u32::MAX {
            continue;
        }
        comp[start] = ncomp;
        stack.push(start);
        while let Some(f) = stack.pop() {
            for &(g, same) in &adj[f] {
                // Same traversal direction on the shared edge: exactly one of the two must flip.
                let want = flip[f] ^ same;
                if comp[g as usize] == u32::MAX {
                    comp[g as usize] = ncomp;
                    flip[g as usize] = want;
                    stack.push(g as usize);
                } else if flip[g as usize] != want {
                    return None;
                }
            }
        }
        ncomp += 1;
    }
    Some((flip, comp, ncomp as usize))
}

fn unit_props(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    reference: Option<[f64; 3]>,
) -> MassProperties {
    let opts = IntegrationOptions {
        reference,
        ..IntegrationOptions::accurate()
    };
    MassProperties::from_integrals(&volume_integrals(vertices, faces, &opts), 1.0)
}

fn bbox(vertices: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

/// The relative disagreement of the central inertia about two reference points.
fn estimate(vertices: &[[f64; 3]], faces: &Polygons, base: &MassProperties) -> f64 {
    let (lo, _) = bbox(vertices);
    let other = unit_props(vertices, faces, Some(lo));
    let mut d = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = other.inertia[i][j] - base.inertia[i][j];
        }
    }
    let n = frobenius(&base.inertia);
    if n > 0.0 {
        frobenius(&d) / n
    } else {
        f64::INFINITY
    }
}

/// Turns a scaled mesh into a solid by the ladder in the module docs.
pub fn make_solid(mesh: &RawMesh, path: &Path, options: HealthOptions) -> Result<Solid, MeshError> {
    let faces_read = mesh.faces.len();
    let (vertices, mut faces, dropped) = weld(mesh);
    let mut warnings: Vec<String> = mesh.notes.clone();
    if dropped > 0 {
        warnings.push(format!(
            "{dropped} degenerate faces (repeated vertices) dropped"
        ));
    }
    if faces.is_empty() {
        return Err(MeshError::new(path, None, MeshErrorKind::Empty));
    }
    let (lo, hi) = bbox(&vertices);
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let bbox_volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    let strict = |what: String| -> Result<(), MeshError> {
        if options.strict {
            Err(MeshError::new(path, None, MeshErrorKind::Strict(what)))
        } else {
            Ok(())
        }
    };
    let e = edges(&faces);
    let closed = e.boundary == 0 && e.nonmanifold == 0;
    // Orientation is only worked out when some edge says it is needed.
    let oriented = if closed && e.inconsistent > 0 {
        orient(faces.len(), &e.pairs)
    } else {
        None
    };

    let rung;
    let mut integrals = None;
    if closed && e.inconsistent == 0 {
        let t = volume_integrals(&vertices, &faces, &IntegrationOptions::accurate());
        if t.t1 < 0.0 {
            strict("closed mesh wound inward".into())?;
            for i in 0..faces.len() {
                faces.reverse_face(i);
            }
            warnings.push(format!(
                "all {} faces wound inward (negative volume); flipped",
                faces.len()
            ));
            integrals = Some(t.negated());
            rung = Rung::Inverted;
        } else {
            integrals = Some(t);
            rung = Rung::Exact;
        }
    } else if let Some((flip, comp, ncomp)) = oriented {
        {
            for (i, f) in flip.iter().enumerate() {
                if *f {
                    faces.reverse_face(i);
                }
            }
            // Each component outward by its own signed volume.
            let vol = component_volumes(&vertices, &faces, &comp, ncomp);
            let mut flipped = 0usize;
            for i in 0..faces.len() {
                let turned = flip[i] ^ (vol[comp[i] as usize] < 0.0);
                if vol[comp[i] as usize] < 0.0 {
                    faces.reverse_face(i);
                }
                if turned {
                    flipped += 1;
                }
            }
            strict(format!(
                "{} faces wound against their neighbours",
                e.inconsistent
            ))?;
            warnings.push(format!(
                "closed, but {flipped} of {} faces were wound against their neighbours ({} edges disagreed); re-oriented each of {ncomp} component(s) outward",
                faces.len(),
                e.inconsistent
            ));
            rung = Rung::Reoriented {
                faces_flipped: flipped,
                components: ncomp,
            };
        }
    } else {
        let what = if e.boundary > 0 && e.nonmanifold > 0 {
            format!(
                "open ({} boundary edges) and non-manifold ({} edges shared by 3+ faces)",
                e.boundary, e.nonmanifold
            )
        } else if e.boundary > 0 {
            format!("open ({} boundary edges)", e.boundary)
        } else if e.nonmanifold > 0 {
            format!("non-manifold ({} edges shared by 3+ faces)", e.nonmanifold)
        } else {
            "closed but not orientable".to_string()
        };
        // Orient what the manifold edges allow, each component outward; failing that (contradicting
        // edges, or open sheets whose sign is meaningless), the winding as the file gives it. Then close
        // the holes, if they are small enough for flat caps to be trusted.
        let mut candidates: Vec<(Polygons, usize)> = Vec::new();
        if let Some((flip, comp, ncomp)) = orient(faces.len(), &e.pairs) {
            let mut trial = faces.clone();
            for (i, f) in flip.iter().enumerate() {
                if *f {
                    trial.reverse_face(i);
                }
            }
            let vol = component_volumes(&vertices, &trial, &comp, ncomp);
            let mut flipped = 0;
            for i in 0..trial.len() {
                if vol[comp[i] as usize] < 0.0 {
                    trial.reverse_face(i);
                }
                if flip[i] ^ (vol[comp[i] as usize] < 0.0) {
                    flipped += 1;
                }
            }
            if flipped > 0 {
                candidates.push((trial, flipped));
            }
        }
        candidates.push((faces.clone(), 0));
        for (trial, flipped) in candidates {
            let flips = if flipped > 0 {
                format!(", {flipped} faces re-oriented")
            } else {
                String::new()
            };
            if e.boundary == 0 {
                let unit = unit_props(&vertices, &trial, None);
                if unit.mass > 0.0 {
                    strict(format!("mesh is {what}"))?;
                    warnings.push(format!("mesh is {what} but has no holes: integrated as it is{flips} (a region enclosed by two overlapping shells would count twice)"));
                    check_volume(unit.mass, diag, bbox_volume, path)?;
                    let error_estimate = estimate(&vertices, &trial, &unit);
                    let rung = Rung::NonManifold {
                        nonmanifold_edges: e.nonmanifold,
                        faces_flipped: flipped,
                    };
                    return Ok(Solid {
                        vertices,
                        faces: trial,
                        rung,
                        warnings,
                        unit,
                        error_estimate,
                        faces_read,
                    });
                }
                continue;
            }
            let Some(Capping {
                vertices: cv,
                faces: cf,
                holes,
                cracks,
                bound,
            }) = cap_holes(&vertices, &trial)
            else {
                continue;
            };
            let unit = unit_props(&cv, &cf, None);
            let uncertainty = bound / unit.mass.abs();
            if unit.mass > 0.0 && uncertainty <= CAPPED {
                strict(format!("mesh is {what}"))?;
                let mut done = Vec::new();
                if holes > 0 {
                    done.push(format!("closed its {holes} hole(s) with flat caps"));
                }
                if cracks > 0 {
                    done.push(format!(
                        "left {cracks} edge(s) of cracks or T-junctions open"
                    ));
                }
                warnings.push(format!(
                    "mesh is {what}: {}{flips}; its volume {:.6e} m³ is uncertain by at most {:.1e} (relative) because of them",
                    done.join(", "),
                    unit.mass,
                    uncertainty
                ));
                check_volume(unit.mass, diag, bbox_volume, path)?;
                let rung = Rung::Capped {
                    holes,
                    boundary_edges: e.boundary,
                    nonmanifold_edges: e.nonmanifold,
                    faces_flipped: flipped,
                    relative_uncertainty: uncertainty,
                };
                let error_estimate = uncertainty.max(estimate(&cv, &cf, &unit));
                return Ok(Solid {
                    vertices: cv,
                    faces: cf,
                    rung,
                    warnings,
                    unit,
                    error_estimate,
                    faces_read,
                });
            }
        }
        // Open or non-manifold: the mesh's own signed volume depends on the reference point.
        let own = unit_props(&vertices, &faces, None).mass;
        let own_corner = unit_props(&vertices, &faces, Some(lo)).mass;
        let (hv, ht) = hull::convex_hull(&vertices).map_err(|err| match err {
            hull::HullError::Degenerate => MeshError::new(
                path,
                None,
                MeshErrorKind::ZeroVolume {
                    volume: 0.0,
                    bbox_volume,
                },
            ),
            hull::HullError::Failed(m) => MeshError::new(
                path,
                None,
                MeshErrorKind::Syntax(format!("open mesh, and its convex hull failed: {m}")),
            ),
        })?;
        let hull_faces = Polygons::from_triangles(&ht);
        let hull_volume = unit_props(&hv, &hull_faces, None).mass;
        strict(format!("mesh is {what}"))?;
        let moves = (own - own_corner).abs();
        warnings.push(format!(
            "mesh is {what}; used its convex hull ({} vertices, volume {:.6e} m³). The mesh's own signed volume is {:.6e} m³ ({:+.1}% of the hull) and moves by {:.2e} m³ when the reference point moves, so it is not a solid",
            hv.len(),
            hull_volume,
            own,
            if hull_volume != 0.0 { 100.0 * (own - hull_volume) / hull_volume } else { 0.0 },
            moves
        ));
        rung = Rung::ConvexHull {
            boundary_edges: e.boundary,
            nonmanifold_edges: e.nonmanifold,
            mesh_volume: own,
            hull_volume,
            volume_moves_by: moves,
        };
        let unit = unit_props(&hv, &hull_faces, None);
        check_volume(unit.mass, diag, bbox_volume, path)?;
        let error_estimate = estimate(&hv, &hull_faces, &unit);
        return Ok(Solid {
            vertices: hv,
            faces: hull_faces,
            rung,
            warnings,
            unit,
            error_estimate,
            faces_read,
        });
    }
    let unit = match integrals {
        Some(t) => MassProperties::from_integrals(&t, 1.0),
        None => unit_props(&vertices, &faces, None),
    };
    check_volume(unit.mass, diag, bbox_volume, path)?;
    let error_estimate = estimate(&vertices, &faces, &unit);
    Ok(Solid {
        vertices,
        faces,
        rung,
        warnings,
        unit,
        error_estimate,
        faces_read,
    })
}

fn check_volume(volume: f64, diag: f64, bbox_volume: f64, path: &Path) -> Result<(), MeshError> {
    if volume.is_nan() || volume <= ZERO_VOLUME * diag.powi(3) {
        return Err(MeshError::new(
            path,
            None,
            MeshErrorKind::ZeroVolume {
                volume,
                bbox_volume,
            },
        ));
    }
    Ok(())
}

/// Six times the signed volume of each connected component (about the bounding-box centre).
fn component_volumes(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    comp: &[u32],
    ncomp: usize,
) -> Vec<f64> {
    let centre = bounding_box_centre(vertices);
    let mut vol = vec![0.0f64; ncomp];
    for (i, face) in faces.iter().enumerate() {
        let a = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let b = sub(vertices[face[k] as usize], centre);
            let c = sub(vertices[face[k + 1] as usize], centre);
            vol[comp[i] as usize] += a[0] * (b[1] * c[2] - b[2] * c[1])
                + a[1] * (b[2] * c[0] - b[0] * c[2])
                + a[2] * (b[0] * c[1] - b[1] * c[0]);
        }
    }
    vol
}

/// Closes every boundary loop of `faces` with a fan from the loop's centroid, wound against the loop's
/// edges so the result is consistently oriented. Returns the new vertices and faces, the number of holes,
/// and the volume uncertainty bound Σ (largest distance of a loop vertex from the loop's mean plane) ×
/// (cap area). `None` when the boundary edges do not chain into loops (inconsistent winding at a hole).
fn cap_holes(vertices: &[[f64; 3]], faces: &Polygons) -> Option<Capping> {
    let half = edges(faces).boundary_half_edges;
    // Walk boundary edges as undirected (cracks and slivers often have both sides in one direction),
    // preferring the mesh's own direction; each cap triangle is wound against its own edge.
    let mut out_of: HashMap<u32, Vec<(u32, usize, bool)>> = HashMap::new();
    for (i, &(u, v)) in half.iter().enumerate() {
        out_of.entry(u).or_default().push((v, i, true));
    }
    for (i, &(u, v)) in half.iter().enumerate() {
        out_of.entry(v).or_default().push((u, i, false));
    }
    let mut used = vec![false; half.len()];
    let mut v_out = vertices.to_vec();
    let mut f_out = faces.clone();
    let mut holes = 0;
    let mut cracks = 0;
    let mut bound = 0.0;
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
            cracks += steps.len();
            continue;
        }
        let lp: Vec<u32> = steps.iter().map(|s| s.0).collect();
        holes += 1;
        let n = lp.len() as f64;
        let c = [0, 1, 2].map(|k| lp.iter().map(|&i| vertices[i as usize][k]).sum::<f64>() / n);
        let ci = v_out.len() as u32;
        v_out.push(c);
        let mut area = [0.0f64; 3];
        for &(_, a, b) in &steps {
            // The mesh has a → b on its boundary; the cap runs b → a.
            f_out.push(&[ci, b, a]);
            let p = sub(vertices[b as usize], c);
            let q = sub(vertices[a as usize], c);
            area[0] += 0.5 * (p[1] * q[2] - p[2] * q[1]);
            area[1] += 0.5 * (p[2] * q[0] - p[0] * q[2]);
            area[2] += 0.5 * (p[0] * q[1] - p[1] * q[0]);
        }
        let len = (area[0] * area[0] + area[1] * area[1] + area[2] * area[2]).sqrt();
        if len > 0.0 {
            let nrm = area.map(|x| x / len);
            let dev = lp.iter().map(|&i| {
                let d = sub(vertices[i as usize], c);
                (d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2]).abs()
            });
            bound += dev.fold(0.0, f64::max) * len;
        }
    }
    if cracks > 0 {
        // What is left open makes the result depend on the reference point by at most |A|·diag/6.
        let (lo, hi) = bbox(vertices);
        let diag =
            ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
        bound += vector_area(&v_out, &f_out) * diag / 6.0;
    }
    Some(Capping {
        vertices: v_out,
        faces: f_out,
        holes,
        cracks,
        bound,
    })
}

/// A mesh with its holes capped.
struct Capping {
    vertices: Vec<[f64; 3]>,
    faces: Polygons,
    holes: usize,
    /// Boundary edges left open (cracks, T-junctions).
    cracks: usize,
    /// Bound on the volume uncertainty the caps and cracks leave, m³.
    bound: f64,
}

/// The length of the surface's vector area `Σ N/2` (zero for a closed surface).
fn vector_area(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    let centre = bounding_box_centre(vertices);
    let mut a = [0.0f64; 3];
    for face in faces.iter() {
        let p = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let e1 = sub(sub(vertices[face[k] as usize], centre), p);
            let e2 = sub(sub(vertices[face[k + 1] as usize], centre), p);
            a[0] += 0.5 * (e1[1] * e2[2] - e1[2] * e2[1]);
            a[1] += 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]);
            a[2] += 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
        }
    }
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
