//! Closed, consistently wound meshes whose components overlap: a part modelled inside another, two
//! bodies of an assembly exported as one mesh that cut each other. Every edge is shared by two faces
//! the right way round, so the mesh is clean as stored, but its integral counts a region two
//! components enclose twice, while Ω = {x : |w(x)| ≥ ½} counts it once. Truth: exact rational
//! integrals (boxes through inclusion–exclusion, the enclosing cylinder's own), every estimate at
//! least the real error. Before, each came out as the sum with an estimate of 1e-15: g1's knee
//! (example-robot-data) 7% heavy, cassie's shin 17%, go1's `ultraSound.dae` 53%.

// The test helpers are the library tests' own (exact integrals, mesh generators).
#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;

use common::shells::{assert_estimate_at_most, exact_sum, solid_with, together, within_estimate};
use common::Mesh;
use urdf_inertia::mesh::health::{HealthOptions, Solid};

fn solid(mesh: &Mesh) -> Solid {
    solid_with(mesh, HealthOptions::default(), "closed_overlap.obj")
}

fn assert_small(s: &Solid) {
    assert_estimate_at_most(s, 1e-6);
}

/// Two closed boxes that cut each other, both outward: the union, box + box − their intersection.
#[test]
fn two_clean_boxes_that_cut_each_other_count_their_intersection_once() {
    let a = common::box_at([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let b = common::box_at([0.75, 0.25, 0.25], [1.25, 0.5, 0.5]);
    let both = common::box_at([0.75, 0.25, 0.25], [1.0, 0.5, 0.5]);
    let s = solid(&together(&[(&a, false), (&b, false)]));
    assert_eq!(s.rung.name(), "exact");
    let exact = exact_sum(&[(1, &a), (1, &b), (-1, &both)]);
    let error = within_estimate("two clean boxes", &s, &exact);
    assert!(error <= 1e-8, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// A box wholly inside another, both outward, apart: w is 2 inside the small one, Ω the large box.
#[test]
fn a_clean_box_inside_another_counts_once() {
    let a = common::box_at([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let b = common::box_at([0.25, 0.25, 0.25], [0.5, 0.75, 0.5]);
    let s = solid(&together(&[(&a, false), (&b, false)]));
    let exact = exact_sum(&[(1, &a)]);
    let error = within_estimate("box inside a box", &s, &exact);
    assert!(error <= 1e-12, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// A box wound inward that cuts an outward one: w is −1 in it alone, 1 in the other alone and 0 in
/// both, so Ω is their symmetric difference. The clean rung turned every component wound inward
/// that no larger box contains, which made w = 2 in the intersection and gave the union, 0.125 of
/// 1.0 off under an estimate of 5e-12 (found by `tests/union_sweep.rs`). A component whose box
/// overlaps another's is now left to the shells' classification.
#[test]
fn an_inward_box_cutting_an_outward_one_leaves_their_intersection_out() {
    let a = common::box_at([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let b = common::box_at([0.5, 0.25, 0.25], [1.5, 0.75, 0.75]);
    let both = common::box_at([0.5, 0.25, 0.25], [1.0, 0.75, 0.75]);
    for (name, inward) in [
        ("the second inward", [false, true]),
        ("the first inward", [true, false]),
    ] {
        let s = solid(&together(&[(&a, inward[0]), (&b, inward[1])]));
        let exact = exact_sum(&[(1, &a), (1, &b), (-2, &both)]);
        let error = within_estimate(name, &s, &exact);
        assert!(error <= 1e-12, "{name}: {error:e} {:?}", s.warnings);
        assert_small(&s);
    }
}

/// A box wound inward around an outward one, and a larger outward box apart (so that the mesh is
/// not inward in all, which turns every face and keeps Ω): w is −1 in the first box and 0 in the
/// small one, so Ω is the first box less the small one, and the box apart. Turned alone (no larger
/// box contains it), the first box filled the small one (w = 2).
#[test]
fn an_inward_box_around_an_outward_one_keeps_it_out() {
    let a = common::box_at([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let b = common::box_at([0.25, 0.25, 0.25], [0.5, 0.75, 0.5]);
    let c = common::box_at([3.0, 0.0, 0.0], [5.0, 1.0, 1.0]);
    let s = solid(&together(&[(&a, true), (&b, false), (&c, false)]));
    let exact = exact_sum(&[(1, &a), (-1, &b), (1, &c)]);
    let error = within_estimate("inward box around an outward one", &s, &exact);
    assert!(error <= 1e-12, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// A cavity stays a cavity: the inner box wound inward, w is 0 inside it.
#[test]
fn a_cavity_in_a_clean_mesh_stays_out() {
    let a = common::box_at([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let b = common::box_at([0.25, 0.25, 0.25], [0.5, 0.75, 0.5]);
    let s = solid(&together(&[(&a, false), (&b, true)]));
    let exact = exact_sum(&[(1, &a), (-1, &b)]);
    let error = within_estimate("cavity", &s, &exact);
    assert!(error <= 1e-12, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// Two boxes side by side whose boxes do not overlap: nothing to classify, the stored integral.
#[test]
fn clean_boxes_apart_are_integrated_as_stored() {
    let a = common::box_at([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let b = common::box_at([2.0, 0.0, 0.0], [3.0, 1.0, 0.5]);
    let s = solid(&together(&[(&a, false), (&b, false)]));
    assert!(
        s.warnings.is_empty() && s.notes.is_empty(),
        "{:?} {:?}",
        s.warnings,
        s.notes
    );
    let exact = exact_sum(&[(1, &a), (1, &b)]);
    within_estimate("apart", &s, &exact);
}

/// Two coaxial cylinders of one height, the thin one inside the thick, both outward, their
/// fan-triangulated caps in the same planes around one shared centre vertex (rotated half a segment
/// apart, so no face repeats another): w is 2 inside the thin one, Ω the thick one. Near the centre
/// every cap triangle lies in the plane of dozens of others whose edges meet at that corner, and
/// only a few of them cross it.
#[test]
fn coaxial_cylinders_with_coplanar_fan_caps() {
    let thick = common::cylinder_mesh(1.0, 1.0, 128);
    let (mut v, f) = common::cylinder_mesh(0.5, 1.0, 128);
    let (s, c) = (std::f64::consts::PI / 128.0).sin_cos();
    for p in v.iter_mut().skip(2) {
        *p = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
    }
    let s = solid(&together(&[(&thick, false), (&(v, f), false)]));
    let exact = exact_sum(&[(1, &thick)]);
    let error = within_estimate("coaxial cylinders", &s, &exact);
    assert!(error <= 1e-8, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// More closed components than the nesting check looks at (2,000): a grid of 2,100 small boxes, one
/// of them with a box inside it. The overlap check has no limit on the components, so the inner box
/// still counts once.
#[test]
fn a_box_inside_one_of_many_components_counts_once() {
    let mut boxes: Vec<Mesh> = (0..2_100)
        .map(|i| {
            let (x, y) = (f64::from(i % 50) * 2.0, f64::from(i / 50) * 2.0);
            common::box_at([x, y, 0.0], [x + 1.0, y + 1.0, 1.0])
        })
        .collect();
    let inner = common::box_at([0.25, 0.25, 0.25], [0.75, 0.5, 0.75]);
    boxes.push(inner);
    let parts: Vec<(&Mesh, bool)> = boxes.iter().map(|m| (m, false)).collect();
    let s = solid(&together(&parts));
    let terms: Vec<(i32, &Mesh)> = boxes[..2_100].iter().map(|m| (1, m)).collect();
    let error = within_estimate("many components", &s, &exact_sum(&terms));
    assert!(error <= 1e-12, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// Slices of one long part: 300 boxes that all overlap along x and none in y, more box tests than
/// the overlap check's budget. It stops and classifies, which finds nothing to change.
#[test]
fn slices_beyond_the_overlap_budget_are_classified_and_unchanged() {
    let boxes: Vec<Mesh> = (0..300)
        .map(|i| {
            let y = f64::from(i) * 2.0;
            common::box_at([0.0, y, 0.0], [10.0, y + 1.0, 1.0])
        })
        .collect();
    let parts: Vec<(&Mesh, bool)> = boxes.iter().map(|m| (m, false)).collect();
    let s = solid(&together(&parts));
    let terms: Vec<(i32, &Mesh)> = boxes.iter().map(|m| (1, m)).collect();
    let error = within_estimate("slices", &s, &exact_sum(&terms));
    assert!(error <= 1e-12, "{error:e} {:?}", s.warnings);
    assert_small(&s);
}

/// Two boxes stacked on a face that each triangulates its own way (a 3 × 3 and a 4 × 4 grid), as
/// two bodies of an assembly exported as one mesh: the faces where they touch bound nothing (both
/// sides are inside), the solid is both boxes, and each of those triangles, cut by a dozen of the
/// other's, is decided across the seams between them: exact, not bounded.
#[test]
fn boxes_stacked_on_a_face_triangulated_twice() {
    let (lo, mid, hi) = ([0.0, 0.0, 0.0], [1.0, 0.7, 0.3], [1.0, 0.7, 0.9]);
    let a = common::grid_box(lo, mid, 3);
    let b = common::grid_box([0.0, 0.0, 0.3], hi, 4);
    let s = solid(&together(&[(&a, false), (&b, false)]));
    let exact = exact_sum(&[
        (1, &common::box_at(lo, mid)),
        (1, &common::box_at([0.0, 0.0, 0.3], hi)),
    ]);
    let error = within_estimate("stacked boxes", &s, &exact);
    assert!(error <= 1e-12, "{error:e} {:?}", s.warnings);
    assert_estimate_at_most(&s, 1e-12);
}

/// One box stored twice, triangulated two ways: w is 2 inside, Ω the box once; each face of one
/// copy lies on the other's, facing the same way, and where they coincide the lower-numbered
/// triangle carries both. Also with the faces of the two copies shuffled in the file, so that the
/// triangles on either side of a seam of one copy may be numbered on both sides of a triangle of
/// the other. (This does not pin the seams' numbering condition: the result stays exact without
/// it too; the condition is kept for the argument in `Faces::seams`.)
#[test]
fn a_box_stored_twice_triangulated_two_ways() {
    let (lo, hi) = ([0.1, 0.2, 0.3], [1.1, 0.9, 0.7]);
    let (v, f) = together(&[
        (&common::grid_box(lo, hi, 3), false),
        (&common::grid_box(lo, hi, 5), false),
    ]);
    let exact = exact_sum(&[(1, &common::box_at(lo, hi))]);
    // Every 7th face to the front, in turn: a fixed permutation that mixes the copies.
    let mut mixed = Vec::with_capacity(f.len());
    for start in 0..7 {
        mixed.extend(f.iter().skip(start).step_by(7).copied());
    }
    for (name, faces) in [("a box twice", f), ("a box twice, interleaved", mixed)] {
        let s = solid(&(v.clone(), faces));
        let error = within_estimate(name, &s, &exact);
        assert!(error <= 1e-12, "{name}: {error:e} {:?}", s.warnings);
        // Decided, not bounded by boxes: what is left is the rounding of the cut points.
        assert_estimate_at_most(&s, 1e-11);
    }
}

/// Faces that coincide on part of their plane only: a box standing on part of another's top
/// (the faces touching bound nothing), and one sunk up to that top, part of it outside (the same
/// top plane, facing the same way, covered in part twice). The covering faces end inside the
/// triangles below them (the boxes' sides are off every grid line), so each such triangle is cut
/// where the other box's side faces meet it and decided cell by cell: a side face whose reach
/// were taken too short would leave a cell on both sides of it and show in the exact volume.
/// (Its coplanar edges' reach is pinned by `correction::tests`: on closed shells a side face
/// cuts along the same line.)
#[test]
fn boxes_covering_part_of_a_face() {
    let (lo, hi) = ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let base = common::grid_box(lo, hi, 3);
    let (x, y) = ([0.45, 1.37], [0.21, 0.83]);
    let standing = ([x[0], y[0], 1.0], [x[1], y[1], 1.5]);
    let sunk = ([x[0], y[0], 0.6], [x[1], y[1], 1.0]);
    let inside = ([x[0], y[0], 0.6], [1.0, y[1], 1.0]);
    for (name, other, exact) in [
        (
            "standing on part of the top",
            standing,
            exact_sum(&[
                (1, &common::box_at(lo, hi)),
                (1, &common::box_at(standing.0, standing.1)),
            ]),
        ),
        (
            "sunk up to the top",
            sunk,
            exact_sum(&[
                (1, &common::box_at(lo, hi)),
                (1, &common::box_at(sunk.0, sunk.1)),
                (-1, &common::box_at(inside.0, inside.1)),
            ]),
        ),
    ] {
        let s = solid(&together(&[
            (&base, false),
            (&common::grid_box(other.0, other.1, 4), false),
        ]));
        let error = within_estimate(name, &s, &exact);
        assert!(error <= 1e-12, "{name}: {error:e} {:?}", s.warnings);
        // Decided, not bounded by boxes: what is left is the rounding of the cut points.
        assert_estimate_at_most(&s, 1e-11);
    }
}

/// Known, not fixed (docs/accuracy.md, "Known, not fixed: a lone closed shell that cuts itself"): a
/// square bar bent four times whose last leg passes through its first, stored as one closed,
/// consistently wound shell (every edge shared once each way). w is 2 in the unit cube where the
/// legs cross, so the stored integral ∫w is 20 m³ where Ω is 19 m³, and the estimate is the
/// round-off of a clean mesh (1.1e-14). Finding where one shell meets itself is a test of every
/// pair of its triangles whose boxes overlap, which clean meshes do not pay; run with `--ignored` to
/// see the failure.
#[test]
#[ignore = "known: a lone closed shell through itself is integrated as ∫w (docs/accuracy.md)"]
fn a_bar_through_itself_counts_the_crossing_once() {
    // Mitred corners of a bar of side 1 along (0,0) → (6,0) → (6,4) → (3,4) → (3,−3) at z = 0.
    let path = [[0.0, 0.0], [6.0, 0.0], [6.0, 4.0], [3.0, 4.0], [3.0, -3.0]];
    let mut vertices = Vec::new();
    for (i, p) in path.iter().enumerate() {
        let left = |a: &[f64; 2], b: &[f64; 2]| {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let l = dx.hypot(dy);
            [-dy / l, dx / l]
        };
        let n = match i {
            0 => left(&path[0], &path[1]),
            4 => left(&path[3], &path[4]),
            _ => {
                let (a, b) = (left(&path[i - 1], p), left(p, &path[i + 1]));
                [a[0] + b[0], a[1] + b[1]]
            }
        };
        let (x, y) = (p[0], p[1]);
        vertices.extend([
            [x + 0.5 * n[0], y + 0.5 * n[1], -0.5],
            [x - 0.5 * n[0], y - 0.5 * n[1], -0.5],
            [x - 0.5 * n[0], y - 0.5 * n[1], 0.5],
            [x + 0.5 * n[0], y + 0.5 * n[1], 0.5],
        ]);
    }
    let mut faces = Vec::new();
    for s in 0..4u32 {
        for k in 0..4 {
            let (a, b) = (4 * s, 4 * (s + 1));
            let k2 = (k + 1) % 4;
            faces.extend([[a + k, a + k2, b + k2], [a + k, b + k2, b + k]]);
        }
    }
    faces.extend([[3, 2, 1], [3, 1, 0], [16, 17, 18], [16, 18, 19]]);
    // Wound outward (the rings above run the other way round).
    for f in &mut faces {
        f.swap(1, 2);
    }
    let bar: Mesh = (vertices, faces);
    let s = solid(&bar);
    // Ω as boxes: the four legs, less the four unit cubes two of them share (corners and crossing).
    let z = (-0.5, 0.5);
    let b = |x: (f64, f64), y: (f64, f64)| common::box_at([x.0, y.0, z.0], [x.1, y.1, z.1]);
    let legs = [
        b((0.0, 6.5), (-0.5, 0.5)),
        b((5.5, 6.5), (-0.5, 4.5)),
        b((2.5, 6.5), (3.5, 4.5)),
        b((2.5, 3.5), (-3.0, 4.5)),
    ];
    let shared = [
        b((5.5, 6.5), (-0.5, 0.5)),
        b((5.5, 6.5), (3.5, 4.5)),
        b((2.5, 3.5), (3.5, 4.5)),
        b((2.5, 3.5), (-0.5, 0.5)),
    ];
    let terms: Vec<(i32, &Mesh)> = legs
        .iter()
        .map(|m| (1, m))
        .chain(shared.iter().map(|m| (-1, m)))
        .collect();
    let exact = exact_sum(&terms);
    within_estimate("a bar through itself", &s, &exact);
}
