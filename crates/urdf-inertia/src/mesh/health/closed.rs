//! The closed rungs: as stored, welded, inverted or re-oriented component by component.

use super::geometry::{
    bbox, component_boxes, component_volumes, vector_area, Aabb,
};
use super::ladder::{Known, Ladder};
use super::model::Model;
use super::topology::{closed_consistent_of, closed_consistent_split, identity, Edges, Orientation};
use super::welding::Welding;
use super::{HealthKind, ModelError, Rung, Solid};
use crate::geometry::{cross, dot, sub, x_sweep};
use crate::mass::integrals::bounding_box_centre;
use crate::mass::Polygons;
use crate::mesh::MeshError;
use std::ops::ControlFlow;
use std::sync::{Mutex, PoisonError};

/// [`closed_consistent`](super::topology::closed_consistent) on `faces` (of `vertices`, so that their number needs no pass over the
/// corners), and beside it, when the pool has more than one thread, the integrals of `faces` as
/// stored that [`consistent_closed`] starts from.
///
/// The proof is mostly serial and the kernel parallel: run one after the other, the second thread
/// idles through the proof; run side by side (`rayon::join`), the threads share them. On a pool of
/// two threads the proof runs whole on one thread while the other makes the proof's union-find
/// forest (when the proof has not yet asked for it) and then takes the kernel's chunks: the proof
/// takes a little longer than the kernel on one thread, and its scan split in two halves
/// ([`closed_consistent_split`]: a second forest, counts per half, a serial join of the forests)
/// cost more than it saved (the 1.3 M-face torus of `validation/threads.sh`, two threads, wall
/// median: 101.0 ms split, 94.6 ms whole; the 10 M-face torus 842.6 ms and 796.7 ms;
/// docs/benchmarks.md, "Round fourteen"). On more threads, where the kernel's chunks go to the
/// others, the split proof's halves keep two of them on it (not measured: this machine has two
/// cores). Integrals are the same bits on any thread (fixed chunks summed in order), and the proof's
/// answer is the same on any path. On one thread nothing runs beside the proof, so a mesh that
/// fails it pays for no integral; on more, a failed proof wastes the integral unless the tolerant
/// weld leaves the stored faces as they are (the common case of cracks only), where it is used.
pub(super) fn prove(
    vertices: &[[f64; 3]],
    faces: &Polygons,
) -> (Option<(Vec<u32>, usize)>, Option<Known>) {
    let n = vertices.len();
    let whole = || closed_consistent_of(faces, n, || identity(faces.len()));
    // Below two of the kernel's chunks the integral is one sequence anyway.
    if faces.len() < 1 << 16 {
        return (whole(), None);
    }
    crate::threads::install(|| {
        let threads = rayon::current_num_threads();
        if threads < 2 {
            return (whole(), None);
        }
        if threads > 2 {
            let (proof, t) = rayon::join(
                || closed_consistent_split(faces, n),
                || Known::of(vertices, faces),
            );
            return (proof, Some(t));
        }
        // The forest, made by the kernel's side unless the proof asked for it first (then the
        // proof makes its own: neither side waits for the other, which on a pool busy elsewhere
        // may run both closures in turn on one thread).
        let forest = Mutex::new((false, None::<Vec<u32>>));
        let lock = || forest.lock().unwrap_or_else(PoisonError::into_inner);
        let (proof, t) = rayon::join(
            || {
                closed_consistent_of(faces, n, || {
                    let mut f = lock();
                    f.0 = true;
                    f.1.take().unwrap_or_else(|| identity(faces.len()))
                })
            },
            || {
                if !lock().0 {
                    let made = identity(faces.len());
                    let mut f = lock();
                    if !f.0 {
                        f.1 = Some(made);
                    }
                }
                Known::of(vertices, faces)
            },
        );
        (proof, Some(t))
    })
}

/// The note of a mesh closed by the tolerant weld: the corners it merged, or the faces it dropped.
fn welded_note(ladder: &mut Ladder<'_>, rung: &Rung) {
    if let Rung::Welded {
        merged_vertices,
        widest_crack,
        tolerance,
    } = *rung
    {
        let text = if merged_vertices > 0 {
            format!("closed once {merged_vertices} corners stored up to {widest_crack:.1e} m apart are welded (tolerance {tolerance:.1e} m); integrated as stored")
        } else {
            // No corner moved: the faces dropped (copies, cancelling pairs, collapsed) closed it.
            "closed once the faces dropped above are left out; no corner welded".to_string()
        };
        ladder.note(HealthKind::Welded, text);
    }
}

/// The stored orientation of the faces [`consistent_closed`] integrates, when it is not the ladder's
/// so far. Those faces are `stored` (all reversed when inverted), which hold the faces the tolerant
/// weld collapsed where `kept` (the ladder's stored orientation so far) does not: the stored
/// orientation the shells' classification compares them with must be theirs, face for face, or
/// faces of other shells count as turned round (sweep case 49295: two inward octahedra cutting
/// each other behind two collapsed tetrahedra, one turned back to inward and one left outward,
/// their overlap integrated as a hole, 0.13% off under 2.7e-4).
pub(super) fn stored_orientation(stored: &Polygons, kept: Option<&Polygons>) -> Option<Polygons> {
    kept.filter(|k| k.len() != stored.len()).map(|_| stored.clone())
}

/// Closed and consistent (bit-exact or after the tolerant weld): as stored, flipped if inward, or with
/// the components re-oriented whose winding contradicts their nesting.
///
/// `kept` are the faces the topology (the component ids `comp`) numbers, `None` when they are `stored`
/// themselves. `known` are `stored`'s integrals when [`prove`] computed them.
pub(super) fn consistent_closed(
    mut ladder: Ladder<'_>,
    vertices: Vec<[f64; 3]>,
    (stored, known): (Polygons, Option<Known>),
    kept: Option<Polygons>,
    (comp, ncomp): (Vec<u32>, usize),
    rung: Rung,
) -> Result<Solid, MeshError> {
    // Closed only once welded within tolerance: the stored surface's vector area is not exactly 0.
    let welded = kept.is_some();
    let stored_orientation = stored_orientation(&stored, kept.as_ref());
    let known = known.unwrap_or_else(|| Known::of(&vertices, &stored));
    let t = known.integrals;
    let inverted = t.t1 < 0.0;
    let mut faces = stored;
    let mut kept = kept;
    let mut rung = rung;
    if inverted {
        ladder.strict("closed mesh wound inward")?;
        let all = vec![true; faces.len()];
        apply(&mut faces, &all);
        if let Some(k) = kept.as_mut() {
            let all = vec![true; k.len()];
            apply(k, &all);
        }
        ladder.warn(
            HealthKind::Repaired,
            format!(
                "all {} faces wound inward (negative volume); flipped",
                faces.len()
            ),
        );
        rung = Rung::Inverted;
    }
    let topology_faces = kept.as_ref().unwrap_or(&faces);
    if ncomp > 1 {
        let flip = misoriented(&vertices, topology_faces, &comp, ncomp);
        if flip.iter().any(|f| *f) {
            ladder.strict("a closed component is wound inward")?;
            let reversed: Vec<bool> = comp.iter().map(|&c| flip[c as usize]).collect();
            let mut out = topology_faces.clone();
            apply(&mut out, &reversed);
            let flipped = reversed.iter().filter(|r| **r).count();
            let turned = flip.iter().filter(|f| **f).count();
            ladder.warn(HealthKind::Repaired, format!(
                "{turned} of {ncomp} closed components wound inward although no other component's box overlaps theirs (a cavity must lie inside a solid); {flipped} faces flipped"
            ));
            let model = open_volume(&vertices, &out);
            let rung = Rung::Reoriented {
                faces_flipped: flipped,
                components: ncomp,
            };
            return ladder.finish(vertices, out, rung, (model, ModelError::Cracks), |_, _| {
                None
            });
        }
    }
    // Closed components whose boxes overlap may enclose a region twice (one inside the other, or
    // two bodies of an assembly cutting each other): the stored integral counts it twice while Ω
    // = {|w| ≥ ½} counts it once, so the shells are classified ([`Ladder::shells`]). A mesh of one
    // component, or of components apart, pays one pass for the boxes at most. There is no limit on
    // the components: the sweep's work is capped, and a sweep that reaches its cap classifies (the
    // classification has caps of its own, whose bounds enter the estimate).
    if ncomp > 1 {
        let boxes = component_boxes(&vertices, topology_faces, &comp, ncomp);
        ladder.overlapping_components = any_overlap(&boxes);
    }
    welded_note(&mut ladder, &rung);
    let model = if welded {
        open_volume(&vertices, &faces)
    } else {
        0.0
    };
    // The faces are the stored ones, or all of them reversed: their integrals are known, negated
    // for reversed faces, whose rounding is then the stored faces' (negation is exact).
    ladder.known = Some(Known {
        integrals: if inverted { t.negated() } else { t },
        ..known
    });
    if let Some(s) = stored_orientation {
        ladder.as_stored.faces = s;
    }
    ladder.finish(
        vertices,
        faces,
        rung,
        (model, ModelError::Cracks),
        |_, _| None,
    )
}

/// [`consistent_closed`] for a mesh closed by the tolerant weld; `known` are the integrals of the exact
/// weld's faces from [`prove`], which are the stored faces unless duplicates were dropped.
pub(super) fn welded_closed(
    ladder: Ladder<'_>,
    w: Welding,
    components: (Vec<u32>, usize),
    rung: Rung,
    known: Option<Known>,
) -> Result<Solid, MeshError> {
    // The integrals about the centre, and the bound on their rounding, stand for the welded faces;
    // the welded vertices have a box of their own.
    let known = known
        .filter(|_| w.duplicates == 0 && w.cancelled == 0)
        .map(|k| Known { bounds: None, ..k });
    consistent_closed(ladder, w.vertices, (w.stored, known), Some(w.kept), components, rung)
}

/// Components beyond this many are not checked for nesting (quadratic in the components).
pub(super) const NESTING_CHECK: usize = 2_000;

/// Which components to flip: those wound inward (negative volume) whose boxes overlap no other
/// component's box in a positive volume. Such a component alone has w = −1 inside, so turned it
/// bounds the same Ω = {|w| ≥ ½}. One whose box overlaps another's is left as stored: there its
/// winding number adds to the other's, and turning it changes Ω where they overlap (an inward box
/// cutting an outward one: Ω is their symmetric difference, w = 0 in both, and turned the union
/// counted the intersection, 0.125 of 1.0, under an estimate of 5e-12; an inward box around an
/// outward part: Ω is the box less the part, and turned the box alone filled it). Those components'
/// boxes overlap, so the shells are classified by their winding numbers ([`any_overlap`],
/// `Ladder::shells`), which turns, drops or cuts their faces as Ω needs.
pub(super) fn misoriented(vertices: &[[f64; 3]], faces: &Polygons, comp: &[u32], ncomp: usize) -> Vec<bool> {
    if ncomp > NESTING_CHECK {
        return vec![false; ncomp];
    }
    let vol = component_volumes(vertices, faces, comp, ncomp);
    if vol.iter().all(|v| *v >= 0.0) {
        return vec![false; ncomp];
    }
    let boxes = component_boxes(vertices, faces, comp, ncomp);
    (0..ncomp)
        .map(|c| vol[c] < 0.0 && !(0..ncomp).any(|d| d != c && boxes[c].overlaps(&boxes[d])))
        .collect()
}

/// Box tests per box beyond which [`any_overlap`] stops and answers yes: boxes that overlap along x
/// but not in y or z (slices of one long part) would otherwise make the sweep quadratic.
const OVERLAP_TESTS_PER_BOX: usize = 64;

/// Whether two of the boxes overlap in a positive volume (a sweep along x), or whether the sweep ran
/// out of its budget of tests before it could say they do not.
fn any_overlap(boxes: &[Aabb]) -> bool {
    let mut budget = OVERLAP_TESTS_PER_BOX * boxes.len();
    let overlap = |a: &Aabb, b: &Aabb| (1..3).all(|k| a.lo[k].max(b.lo[k]) < a.hi[k].min(b.hi[k]));
    x_sweep(boxes, |a, b| {
        if budget == 0 || overlap(&boxes[a], &boxes[b]) {
            return ControlFlow::Break(());
        }
        budget -= 1;
        ControlFlow::Continue(())
    })
    .is_break()
}

/// How many components hold component `c`: larger in volume, their boxes containing its box.
fn nesting_depth(c: usize, vol: &[f64], boxes: &[Aabb]) -> usize {
    (0..vol.len())
        .filter(|&d| d != c && vol[d].abs() > vol[c].abs() && boxes[d].contains(&boxes[c]))
        .count()
}

/// The volume that moves with the reference point, over reference points in the bounding box, for a
/// surface that is closed only up to cracks: |vector area| × diagonal / 6 (the signed volume about
/// r is V(0) − r·A/3). Zero for a closed surface; its round-off for one closed bit for bit.
pub(super) fn open_volume(vertices: &[[f64; 3]], faces: &Polygons) -> f64 {
    vector_area(vertices, faces) * bbox(vertices).diagonal() / 6.0
}

/// Closed after the tolerant weld but wound inconsistently: each component made consistent and outward.
pub(super) fn reoriented(
    mut ladder: Ladder<'_>,
    w: Welding,
    te: &Edges,
    o: &Orientation,
) -> Result<Solid, MeshError> {
    let Outward {
        reversed,
        flipped,
        nested,
        flip_volume,
    } = outward(&w.vertices, &w.kept, o, &te.pairs);
    let mut faces = w.kept.clone();
    apply(&mut faces, &reversed);
    ladder.strict(&format!(
        "{} faces wound against their neighbours",
        te.inconsistent
    ))?;
    ladder.warn(HealthKind::Repaired, format!(
        "closed, but {flipped} of {} faces were wound against their neighbours ({} edges disagreed); re-oriented each of {} component(s) outward",
        faces.len(),
        te.inconsistent,
        o.ncomp
    ));
    let rung = Rung::Reoriented {
        faces_flipped: flipped,
        components: o.ncomp,
    };
    let model = Model::reoriented(open_volume(&w.vertices, &faces), nested + flip_volume);
    ladder.finish(w.vertices, faces, rung, model, |_, _| None)
}

/// Each face's reversal under an orientation that turns every component outward by its own signed
/// volume (a closed cavity inside another component's box stays inward: [`turned_components`]), how
/// many faces that flips, and the volume of components lying inside another one's
/// bounding box (counted twice: a cavity turned outward adds its volume instead of removing it).
/// `flip_volume` is what the faces flipped against the rest of their component change ([`flip_change`]).
pub(super) struct Outward {
    pub(super) reversed: Vec<bool>,
    pub(super) flipped: usize,
    pub(super) nested: f64,
    pub(super) flip_volume: f64,
}

/// The volume that re-orienting faces within components can change, m³: per component, the smaller
/// of the sets flipped and kept (flipping a whole shell changes nothing the winding number rule does
/// not already decide) changes the integral by twice its signed volume, which moves with the
/// reference point by twice its vector area × the diagonal / 6; both are counted.
pub(super) fn flip_change(vertices: &[[f64; 3]], faces: &Polygons, o: &Orientation, reversed: &[bool]) -> f64 {
    let centre = bounding_box_centre(vertices);
    let diag = bbox(vertices).diagonal();
    let count = reversed_counts(o, reversed);
    let mut volume6 = vec![0.0f64; o.ncomp];
    let mut area2 = vec![[0.0f64; 3]; o.ncomp];
    for (i, face) in faces.iter().enumerate() {
        let c = o.comp[i] as usize;
        // The minority side (ties: the flipped side); nothing when the whole component turned.
        let minority = usize::from(count[c][1] <= count[c][0]);
        if usize::from(reversed[i]) != minority || count[c][0].min(count[c][1]) == 0 {
            continue;
        }
        let a = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let b = sub(vertices[face[k] as usize], centre);
            let d = sub(vertices[face[k + 1] as usize], centre);
            volume6[c] += dot(a, cross(b, d));
            let n = cross(sub(b, a), sub(d, a));
            (0..3).for_each(|j| area2[c][j] += n[j]);
        }
    }
    (0..o.ncomp)
        .map(|c| 2.0 * volume6[c].abs() / 6.0 + dot(area2[c], area2[c]).sqrt() * diag / 6.0)
        .sum()
}

/// Per component, its faces kept as stored and reversed against the file.
fn reversed_counts(o: &Orientation, reversed: &[bool]) -> Vec<[usize; 2]> {
    let mut count = vec![[0usize; 2]; o.ncomp];
    for (i, r) in reversed.iter().enumerate() {
        count[o.comp[i] as usize][usize::from(*r)] += 1;
    }
    count
}

pub(super) fn outward(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    o: &Orientation,
    pairs: &[(u32, u32, bool)],
) -> Outward {
    let mut trial = faces.clone();
    apply(&mut trial, &o.flip);
    let vol = component_volumes(vertices, &trial, &o.comp, o.ncomp);
    let boxes = (o.ncomp > 1).then(|| component_boxes(vertices, faces, &o.comp, o.ncomp));
    let closed = closed_components(faces, o, pairs);
    let turn = turned_components(&vol, &closed, boxes.as_deref());
    let reversed: Vec<bool> = (0..faces.len())
        .map(|i| o.flip[i] ^ turn[o.comp[i] as usize])
        .collect();
    let flipped = reversed.iter().filter(|r| **r).count();
    // A component that ends mostly reversed was turned round as a whole (up to the faces
    // [`flip_change`] counts).
    let count = reversed_counts(o, reversed.as_slice());
    // Turning every face keeps |w|, so Ω: the reference is the file's surface, or all of it turned
    // when it is wound inward in all ([`turned_components`]).
    let inward = vol.iter().sum::<f64>() < 0.0;
    let mut nested = 0.0;
    if let Some(boxes) = &boxes {
        for c in 0..o.ncomp {
            // Only a component turned against the reference can make the solid differ from Ω of the
            // file's surface: one kept so (a cavity left inward, a solid outward) is what the
            // file's winding number says it is, and nesting is decided by it. Turned, it changes
            // w by 2 inside it, and so Ω only inside it where another component's w is not 0:
            // within its box where another's overlaps, inside another's box (a cavity turned
            // outward), around another (a part enclosed by it) or cutting another. Only a box
            // inside another's was charged: a box wound inward cutting an outward one, and a box
            // turned round an outward part, were up to 0.125 of their volume off under 1e-12
            // (`tests/union_sweep.rs`).
            if (count[c][1] > count[c][0]) == inward {
                continue;
            }
            if (0..o.ncomp).any(|d| d != c && (boxes[c].overlaps(&boxes[d]) || boxes[d].contains(&boxes[c]))) {
                nested += 2.0 * vol[c].abs() / 6.0;
            }
        }
    }
    let flip_volume = flip_change(vertices, faces, o, &reversed);
    Outward {
        reversed,
        flipped,
        nested,
        flip_volume,
    }
}

/// Whether each component is closed: every edge of its faces shared with one other face (`pairs`
/// holds the manifold edges).
fn closed_components(faces: &Polygons, o: &Orientation, pairs: &[(u32, u32, bool)]) -> Vec<bool> {
    let mut shared = vec![0usize; faces.len()];
    for &(a, b, _) in pairs {
        shared[a as usize] += 1;
        shared[b as usize] += 1;
    }
    let mut closed = vec![true; o.ncomp];
    for (i, face) in faces.iter().enumerate() {
        if shared[i] < face.len() {
            closed[o.comp[i] as usize] = false;
        }
    }
    closed
}

/// Which components to turn round (given each one's signed volume, consistently wound, whether it
/// is closed, and their boxes): the whole surface when it is wound inward in all (which leaves
/// {|w| >= 1/2} as it is), then each component wound inward, except a closed one at an odd nesting
/// depth, as [`misoriented`] decides for closed meshes: that is a cavity, and turned outward the
/// winding number inside it would be 2 instead of 0, so the solid would fill it. An open
/// component's sign depends on where it is measured from; it is turned as before. Beyond
/// [`NESTING_CHECK`] components, every component wound inward is turned.
fn turned_components(vol: &[f64], closed: &[bool], boxes: Option<&[Aabb]>) -> Vec<bool> {
    let inward = vol.iter().sum::<f64>() < 0.0;
    let n = vol.len();
    (0..n)
        .map(|c| {
            let own = if inward { -vol[c] } else { vol[c] };
            let depth = match boxes {
                Some(b) if closed[c] && n <= NESTING_CHECK => nesting_depth(c, vol, b),
                _ => 0,
            };
            inward ^ (own < 0.0 && depth % 2 == 0)
        })
        .collect()
}

/// Reverses the faces marked.
pub(super) fn apply(faces: &mut Polygons, reversed: &[bool]) {
    for (i, r) in reversed.iter().enumerate() {
        if *r {
            faces.reverse_face(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{make_solid, HealthOptions};
    use crate::mass::Polygons;
    use crate::mesh::RawMesh;
    use std::path::Path;

    /// A torus of `n` × `m` quads, each split in two triangles wound outward: 2·n·m faces.
    fn torus(n: u32, m: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut v = Vec::new();
        for i in 0..n {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            for j in 0..m {
                let b = std::f64::consts::TAU * f64::from(j) / f64::from(m);
                let r = 1.0 + 0.3 * b.cos();
                v.push([r * a.cos(), r * a.sin(), 0.3 * b.sin()]);
            }
        }
        let at = |i: u32, j: u32| (i % n) * m + j % m;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..m {
                let (p, q, r, s) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                t.extend([[p, q, r], [p, r, s]]);
            }
        }
        (v, t)
    }

    /// The rung of the solid healed in a pool of `threads` threads, and every field of it in its
    /// shortest round-trip form (equal strings, equal bits).
    fn healed(threads: usize, mesh: &RawMesh) -> (&'static str, String) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let s = pool
            .install(|| make_solid(mesh, Path::new("t"), HealthOptions::default()))
            .expect("a solid");
        (s.rung.name(), format!("{s:?}"))
    }

    /// The proof beside the kernel (more than one thread, 2^16 faces and more), whole with its forest
    /// made by the kernel's side (two threads) or its scan split in two (three), gives the solid one
    /// thread gives, bit for bit: clean, clean with a vertex no face uses (the proof's vertices are
    /// all those stored), two components, wound inward, and closed only by the tolerant weld, with
    /// and without a duplicate face dropped (the integrals computed beside the proof are used only
    /// without).
    #[test]
    fn the_proof_beside_the_kernel_gives_the_one_thread_solid() {
        let (v, t) = torus(256, 160);
        let mesh = |v: &[[f64; 3]], t: &[[u32; 3]]| RawMesh {
            vertices: v.to_vec(),
            faces: Polygons::from_triangles(t),
            ..Default::default()
        };
        let inward: Vec<[u32; 3]> = t.iter().map(|f| [f[0], f[2], f[1]]).collect();
        // Vertex 0 stored a second time 1e-12 away and used by one of its faces: a crack.
        let mut cracked_v = v.clone();
        cracked_v.push([v[0][0] + 1e-12, v[0][1], v[0][2]]);
        let mut cracked = t.clone();
        let f = cracked.iter().position(|f| f.contains(&0)).expect("a face at 0");
        cracked[f] = cracked[f].map(|i| if i == 0 { v.len() as u32 } else { i });
        let mut doubled = cracked.clone();
        doubled.push(t[7]);
        // A second, smaller torus beside the first and wound inward, their faces interleaved: two
        // components, and the faces flipped are those of the component ids the split scan gives.
        let mut two_v = v.clone();
        two_v.extend(v.iter().map(|p| [0.5 * p[0] + 5.0, 0.5 * p[1], 0.5 * p[2]]));
        let shift = v.len() as u32;
        let two: Vec<[u32; 3]> = t
            .iter()
            .flat_map(|f| [[f[0], f[2], f[1]].map(|i| i + shift), *f])
            .collect();
        let mut unused = v.clone();
        unused.push([9.0, 9.0, 9.0]);
        let cases = [
            ("clean", mesh(&v, &t), "exact"),
            ("clean, a vertex unused", mesh(&unused, &t), "exact"),
            ("two tori", mesh(&two_v, &two), "reoriented"),
            ("inward", mesh(&v, &inward), "inverted"),
            ("cracked", mesh(&cracked_v, &cracked), "welded"),
            ("cracked, a face twice", mesh(&cracked_v, &doubled), "welded"),
        ];
        for (name, m, rung) in cases {
            let one = healed(1, &m);
            assert_eq!(one.0, rung, "{name}");
            for threads in [2, 3] {
                assert_eq!(healed(threads, &m), one, "{name}, {threads} threads");
            }
        }
    }
}
