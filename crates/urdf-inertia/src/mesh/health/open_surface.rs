//! The open and non-manifold rungs: integrated as they are, capped, or the convex hull when asked.

use super::caps::{cap_holes, Caps};
use super::closed::{apply, open_volume, outward, stored_orientation};
use super::geometry::{bbox, signed_volume, unit_props, vector_area};
use super::ladder::Ladder;
use super::model::Model;
use super::topology::{orient, Edges};
use super::welding::Welding;
use super::{HealthKind, ModelError, Rung, Solid, CAPPED, SLIVERS};
use crate::mass::Polygons;
use crate::mesh::open::{NoSolid, OpenMeshModel};
use crate::mesh::{hull, MeshError, MeshErrorKind};

/// One way to wind an open or non-manifold mesh: the stored faces kept by the weld with some faces
/// reversed, and the boundary edges of their topology as directed then.
pub(super) struct Winding {
    pub(super) faces: Polygons,
    /// What `edges(topology)` gives as `boundary_half_edges` for the topology with the same faces
    /// reversed: the same edges in the same (key) order, each turned round if its face is. Derived
    /// from the topology's edges rather than analysing each winding again (a third and fourth pass
    /// over every half-edge).
    pub(super) boundary: Vec<(u32, u32)>,
    pub(super) flipped: usize,
    /// Volume of components re-oriented inside another's bounding box (m³).
    pub(super) nested: f64,
    /// What flipping faces against the rest of their component changes (m³, [`flip_change`]).
    pub(super) flip_volume: f64,
}

impl Winding {
    fn flips(&self) -> String {
        if self.flipped > 0 {
            format!(", {} faces re-oriented", self.flipped)
        } else {
            String::new()
        }
    }
}

/// Orient what the manifold edges allow, each component outward; failing that (contradicting edges,
/// or open sheets whose sign is meaningless), the winding as the file gives it.
pub(super) fn windings(w: &Welding, te: &Edges) -> Vec<Winding> {
    let mut out = Vec::new();
    if let Some(o) = orient(w.topology.len(), &te.pairs) {
        let turned = outward(&w.vertices, &w.kept, &o, &te.pairs);
        if turned.flipped > 0 {
            let mut faces = w.kept.clone();
            apply(&mut faces, &turned.reversed);
            let boundary = (te.boundary_half_edges.iter().zip(&te.boundary_faces))
                .map(|(&(u, v), &f)| {
                    if turned.reversed[f as usize] {
                        (v, u)
                    } else {
                        (u, v)
                    }
                })
                .collect();
            out.push(Winding {
                faces,
                boundary,
                flipped: turned.flipped,
                nested: turned.nested,
                flip_volume: turned.flip_volume,
            });
        }
    }
    out.push(Winding {
        faces: w.kept.clone(),
        boundary: te.boundary_half_edges.clone(),
        flipped: 0,
        nested: 0.0,
        flip_volume: 0.0,
    });
    out
}

/// Open or non-manifold: integration as it is, caps, or the convex hull.
pub(super) fn open_or_nonmanifold(ladder: Ladder<'_>, w: Welding, te: &Edges) -> Result<Solid, MeshError> {
    let what = te.describe();
    let mut fallback: Option<(f64, Winding, CappedSolid)> = None;
    for winding in windings(&w, te) {
        if te.boundary == 0 {
            if signed_volume(&w.vertices, &winding.faces) > 0.0 {
                return non_manifold(ladder, w, te, winding, &what);
            }
            continue;
        }
        let Some(caps) = cap_holes(&w.vertices, &winding.boundary) else {
            continue;
        };
        // Made to measure: a clone extended would double its room (48 MB more for a hole of a
        // million edges).
        let mut vertices = Vec::with_capacity(w.vertices.len() + caps.centroids.len());
        vertices.extend_from_slice(&w.vertices);
        vertices.extend_from_slice(&caps.centroids);
        let corners = winding.faces.indices.len() + caps.faces.indices.len();
        let mut capped = Polygons::with_capacity(winding.faces.len() + caps.faces.len(), corners);
        for f in winding.faces.iter().chain(caps.faces.iter()) {
            capped.push(f);
        }
        let unit = unit_props(&vertices, &capped, None);
        let volume = unit.mass;
        let cracks = open_volume(&vertices, &capped);
        // The caps are used when the bound they leave on volume and inertia is small enough.
        let relative = caps_model(&caps, cracks, winding.nested)
            .bound(&unit, &vertices)
            .relative;
        // An unbounded cap is still what `--open-mesh caps` asks for, with its bound.
        if volume.is_nan() || volume <= 0.0 || relative.is_nan() {
            continue;
        }
        let plan = CappedSolid {
            cracks,
            vertices,
            faces: capped,
            volume,
            caps,
        };
        if relative <= CAPPED {
            return with_caps(ladder, w, te, &winding, plan, &what);
        }
        if fallback.as_ref().is_none_or(|f| relative < f.0) {
            fallback = Some((relative, winding, plan));
        }
    }
    // Caps too uncertain to trust: the model the user chose, or no solid (never a silent hull).
    let no_solid = |caps_bound, holes_see_each_other| {
        MeshError::new(
            ladder.path,
            None,
            MeshErrorKind::NoSolid(NoSolid {
                what: what.clone(),
                caps_bound,
                holes_see_each_other,
            }),
        )
    };
    match (ladder.options.open_mesh, fallback) {
        (OpenMeshModel::Hull, _) => convex_hull(ladder, &w, te, &what),
        (OpenMeshModel::Caps, Some((_, winding, plan))) => {
            with_caps(ladder, w, te, &winding, plan, &what)
        }
        (OpenMeshModel::Trusted, Some((relative, _, plan))) => Err(no_solid(
            Some(relative),
            plan.caps.interaction.volume > plan.caps.bound,
        )),
        // No closing encloses a volume: a flat plate or a two-sided sheet has none to speak of (the
        // part contributes nothing); anything else defines no solid.
        (_, None) if crate::mesh::open::encloses_nothing(&w.vertices, &w.stored) => {
            Err(MeshError::zero_volume(
                ladder.path,
                signed_volume(&w.vertices, &w.stored),
                bbox(&w.vertices),
            ))
        }
        (_, None) => Err(no_solid(None, false)),
    }
}

/// No boundary edges but edges shared by three or more faces: integrated as stored (up to the faces
/// re-oriented). A region that two shells enclose counts twice here exactly as in the stored surface,
/// which the warning says.
pub(super) fn non_manifold(
    mut ladder: Ladder<'_>,
    w: Welding,
    te: &Edges,
    winding: Winding,
    what: &str,
) -> Result<Solid, MeshError> {
    ladder.strict(&format!("mesh is {what}"))?;
    ladder.warn(HealthKind::Repaired, format!("mesh is {what} but has no holes: integrated as it is{} (shells that overlap are classified by the winding number on their sides)", winding.flips()));
    let model = Model::reoriented(
        open_volume(&w.vertices, &winding.faces),
        winding.nested + winding.flip_volume,
    );
    let rung = Rung::NonManifold {
        nonmanifold_edges: te.nonmanifold,
        faces_flipped: winding.flipped,
    };
    ladder.finish(w.vertices, winding.faces, rung, model, |_, _| None)
}

/// The model error of caps: their flatness near the loops they close, what the caps of several holes
/// seeing each other can change near them ([`Caps::interaction`]), cracks left open and components
/// re-oriented anywhere.
pub(super) fn caps_model(caps: &Caps, cracks: f64, nested: f64) -> Model {
    Model {
        terms: caps.terms(),
        cracks,
        orientation: nested,
        source: ModelError::Caps,
    }
}

/// A mesh with its holes capped, ready to integrate.
pub(super) struct CappedSolid {
    pub(super) vertices: Vec<[f64; 3]>,
    pub(super) faces: Polygons,
    pub(super) volume: f64,
    pub(super) caps: Caps,
    /// Volume that moves with the reference point after capping (cracks left open), m³.
    pub(super) cracks: f64,
}

/// The capped solid, or, when the "holes" are slivers whose caps change nothing measurable, the
/// stored triangles as they are (rung welded).
pub(super) fn with_caps(
    mut ladder: Ladder<'_>,
    w: Welding,
    te: &Edges,
    winding: &Winding,
    plan: CappedSolid,
    what: &str,
) -> Result<Solid, MeshError> {
    let caps = &plan.caps;
    // Whatever surface really spans the loops, its contribution is at most (its area) × diagonal.
    let spans = caps.area * bbox(&w.vertices).diagonal();
    if (spans + caps.bound + plan.cracks) / plan.volume <= SLIVERS && winding.flipped == 0 {
        ladder.note(HealthKind::Welded, format!(
            "closed up to slivers once corners within {:.1e} m are welded ({} boundary edges bound {:.1e} m² in all); integrated as stored",
            w.tolerant.tolerance.largest, te.boundary, caps.area
        ));
        let rung = Rung::Welded {
            merged_vertices: w.tolerant.merged,
            widest_crack: w.tolerant.widest,
            tolerance: w.tolerant.tolerance.largest,
        };
        let model = spans + caps.bound + plan.cracks;
        // The faces integrated are `w.stored`: the classification compares them with their own
        // stored orientation (`stored_orientation`).
        if let Some(s) = stored_orientation(&w.stored, Some(&w.kept)) {
            ladder.as_stored.faces = s;
        }
        return ladder.finish(
            w.vertices,
            w.stored,
            rung,
            (model, ModelError::Cracks),
            |_, _| None,
        );
    }
    ladder.strict(&format!("mesh is {what}"))?;
    let mut done = Vec::new();
    if caps.holes > 0 {
        done.push(format!("closed its {} hole(s) with flat caps", caps.holes));
    }
    if caps.cracks > 0 {
        done.push(format!(
            "left {} edge(s) of cracks or T-junctions open",
            caps.cracks
        ));
    }
    let mut model = caps_model(caps, plan.cracks, winding.nested);
    // The flips are in the estimate, not in the choice whether caps are trusted (that is about caps).
    model.orientation += winding.flip_volume;
    let rung = Rung::Capped {
        holes: caps.holes,
        boundary_edges: te.boundary,
        nonmanifold_edges: te.nonmanifold,
        faces_flipped: winding.flipped,
        relative_uncertainty: 0.0,
    };
    let done = done.join(", ");
    let flips = winding.flips();
    let seen = caps.interaction.volume > caps.bound;
    // The caps and the welded surface are not needed past here: freed before the capped solid is
    // checked and integrated (over 90 MB for a hole of a million edges).
    let (vertices, faces) = (plan.vertices, plan.faces);
    drop((plan.caps, w));
    ladder.finish(vertices, faces, rung, model, |m, volume| {
        let seen = if seen {
            " (mostly because its holes see each other: between their caps the winding number can be fractional)"
        } else {
            ""
        };
        Some(if !m.is_finite() {
            format!(
                "mesh is {what}: {done}{flips}; its volume {volume:.6e} m³ and inertia are not bounded (what the caps and the cracks left open can change is as large as the values)"
            )
        } else if m > 0.0 {
            format!(
                "mesh is {what}: {done}{flips}; its volume {volume:.6e} m³ and inertia are uncertain by at most {m:.1e} (relative) because of them{seen}"
            )
        } else {
            format!(
                "mesh is {what}: {done}{flips}; the holes' edges are planar, so the caps are exact if the missing surface was flat (volume {volume:.6e} m³); if it was not, this number is off by the missing volume"
            )
        })
    })
}

/// The convex hull of the vertices, with the numbers that say how far that is from the mesh.
pub(super) fn convex_hull(
    ladder: Ladder<'_>,
    w: &Welding,
    te: &Edges,
    what: &str,
) -> Result<Solid, MeshError> {
    let bounds = bbox(&w.vertices);
    let diag = bounds.diagonal();
    // The stored surface's signed volume, and how much it moves over reference points in the box.
    let own = signed_volume(&w.vertices, &w.stored);
    let moves = vector_area(&w.vertices, &w.stored) * diag / 6.0;
    // The hull of the vertices the faces use: unused stored positions are not the surface's.
    let (hv, ht) = hull::convex_hull_of_used(&w.vertices, &w.stored).map_err(|err| match err {
        hull::HullError::Degenerate => MeshError::zero_volume(ladder.path, own, bounds),
    })?;
    let hull_faces = Polygons::from_triangles(&ht);
    let hull_volume = signed_volume(&hv, &hull_faces);
    ladder.strict(&format!("mesh is {what}"))?;
    // The mesh's own volume is the truth up to `moves`; the hull differs from it by this much.
    let model = (own - hull_volume).abs() + moves;
    let nv = hv.len();
    let share = if hull_volume == 0.0 {
        0.0
    } else {
        100.0 * (own - hull_volume) / hull_volume
    };
    let message = move |m: f64, _| {
        let bound = if m.is_finite() {
            format!("uncertain by at most {m:.1e} (relative)")
        } else {
            "not bounded: the mesh's own volume is too uncertain to compare".to_string()
        };
        Some(format!(
            "mesh is {what}; used its convex hull as `--open-mesh hull` asks ({nv} vertices, volume {hull_volume:.6e} m³): an upper bound, as the solid the surface encloses lies inside it. The mesh's own signed volume is {own:.6e} m³ ({share:+.1}% of the hull) and moves by up to {moves:.2e} m³ with the reference point, so it is not a solid; the hull's numbers are {bound}"
        ))
    };
    let rung = Rung::ConvexHull {
        boundary_edges: te.boundary,
        nonmanifold_edges: te.nonmanifold,
        mesh_volume: own,
        hull_volume,
        volume_moves_by: moves,
    };
    ladder.finish(hv, hull_faces, rung, (model, ModelError::Hull), message)
}
