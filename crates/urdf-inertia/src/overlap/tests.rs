use super::*;
use crate::mass::Mat3;
use crate::mesh::health::{HealthOptions, Solid};
use sample::neighbours;

/// A box as its corners `(lo, hi)`, the shape these tests build boxes in.
type Corners = ([f64; 3], [f64; 3]);

const ID: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn placed(shape: PartShape, t: [f64; 3], half: [f64; 3], volume: f64) -> PlacedPart {
    PlacedPart {
        shape,
        rotation: ID,
        translation: t,
        bbox: Aabb::new(
            [t[0] - half[0], t[1] - half[1], t[2] - half[2]],
            [t[0] + half[0], t[1] + half[1], t[2] + half[2]],
        ),
        volume,
        locator: None,
    }
}

fn estimated(parts: &mut [PlacedPart]) -> OverlapEstimate {
    match estimate(parts) {
        Overlap::Estimated(e) => e,
        other => panic!("expected an estimate, got {other:?}"),
    }
}

#[test]
fn two_boxes_overlapping_by_half() {
    let mut parts = [
        placed(PartShape::Box([0.5; 3]), [0.0; 3], [0.5; 3], 1.0),
        placed(PartShape::Box([0.5; 3]), [0.5, 0.0, 0.0], [0.5; 3], 1.0),
    ];
    let e = estimated(&mut parts);
    assert!((e.excess - 0.5).abs() < 1e-12, "{e:?}");
    assert_eq!((e.parts.clone(), e.most, e.grid), (vec![0, 1], 2, GRID));
}

#[test]
fn boxes_overlap_but_solids_do_not() {
    // A small box in the corner of a sphere's bounding box, outside the sphere.
    let mut parts = [
        placed(
            PartShape::Sphere(1.0),
            [0.0; 3],
            [1.0; 3],
            4.0 / 3.0 * std::f64::consts::PI,
        ),
        placed(PartShape::Box([0.1; 3]), [0.9, 0.9, 0.9], [0.1; 3], 0.008),
    ];
    assert_eq!(estimate(&mut parts), Overlap::None);
}

/// Every copy of a part counts: 200 coincident boxes count the box 200 times: 199 of 200 copies
/// (99.5% of the summed volume) are excess, where the largest pair showed 0.5%.
#[test]
fn coincident_boxes_sum_every_copy() {
    let mut parts: Vec<PlacedPart> = (0..200)
        .map(|_| placed(PartShape::Box([0.5; 3]), [0.0; 3], [0.5; 3], 1.0))
        .collect();
    let e = estimated(&mut parts);
    assert!((e.excess - 199.0).abs() < 1e-9, "{e:?}");
    assert_eq!((e.parts.len(), e.most), (200, 200));
}

/// Three spheres in a row, each overlapping the next: the excess is the two lens volumes (exact:
/// π(4r + d)(2r − d)²/12 for radius r at distance d), within the grid's resolution.
#[test]
fn a_chain_of_spheres_sums_its_lenses() {
    let (r, d) = (1.0, 1.5);
    let v = 4.0 / 3.0 * std::f64::consts::PI;
    let mut parts: Vec<PlacedPart> = (0..3)
        .map(|i| {
            placed(
                PartShape::Sphere(r),
                [d * f64::from(i), 0.0, 0.0],
                [r; 3],
                v,
            )
        })
        .collect();
    let lens = std::f64::consts::PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
    let e = estimated(&mut parts);
    assert!(
        (e.excess / (2.0 * lens) - 1.0).abs() < 0.05,
        "{e:?} against {}",
        2.0 * lens
    );
    assert_eq!((e.parts.len(), e.most), (3, 2));
}

/// Disjoint parts cost only the sweep: 2000 disjoint spheres make no pair and no sample.
#[test]
fn disjoint_spheres_have_no_overlap() {
    let v = 4.0 / 3.0 * std::f64::consts::PI * 0.001;
    let mut parts: Vec<PlacedPart> = (0..2000)
        .map(|i| {
            let t = [
                f64::from(i % 20) * 0.25,
                f64::from(i / 20 % 10) * 0.25,
                f64::from(i / 200) * 0.25,
            ];
            placed(PartShape::Sphere(0.1), t, [0.1; 3], v)
        })
        .collect();
    assert_eq!(
        neighbours(&parts).map(|n| n.0.iter().map(Vec::len).sum::<usize>()),
        Some(0)
    );
    assert_eq!(estimate(&mut parts), Overlap::None);
}

/// Too many overlapping pairs skip the estimate with the reason.
#[test]
fn too_many_pairs_are_skipped() {
    let mut parts: Vec<PlacedPart> = (0..1500)
        .map(|_| placed(PartShape::Sphere(1.0), [0.0; 3], [1.0; 3], 4.0))
        .collect();
    assert!(matches!(estimate(&mut parts), Overlap::Skipped(m) if m.contains("pairs of parts")));
}

/// A box of half sides `h` centred at the origin as a closed, outward mesh solid.
fn box_solid(h: [f64; 3]) -> Solid {
    let v: Vec<[f64; 3]> = (0..8)
        .map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { h[k] } else { -h[k] }))
        .collect();
    let quads = [
        [0u32, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let tris: Vec<[u32; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    let raw = crate::mesh::RawMesh {
        vertices: v,
        faces: crate::mass::Polygons::from_triangles(&tris),
        ..Default::default()
    };
    crate::mesh::health::make_solid(&raw, std::path::Path::new("box"), HealthOptions::default())
        .expect("solid")
}

/// The volume of a union of axis-aligned boxes, exact: on the grid of all their coordinates each
/// elementary cell is in the union or not, and with coordinates that are multiples of 1/8 below
/// 2^20 every difference and product here is exact in f64.
fn union_volume(boxes: &[Corners]) -> f64 {
    let coords = |k: usize| {
        let mut c: Vec<f64> = boxes.iter().flat_map(|b| [b.0[k], b.1[k]]).collect();
        c.sort_by(f64::total_cmp);
        c.dedup();
        c
    };
    let [xs, ys, zs] = [0, 1, 2].map(coords);
    let mut total = 0.0;
    for x in xs.windows(2) {
        for y in ys.windows(2) {
            for z in zs.windows(2) {
                let m = [x[0] + x[1], y[0] + y[1], z[0] + z[1]].map(|c| 0.5 * c);
                if boxes
                    .iter()
                    .any(|b| (0..3).all(|k| b.0[k] < m[k] && m[k] < b.1[k]))
                {
                    total += (x[1] - x[0]) * (y[1] - y[0]) * (z[1] - z[0]);
                }
            }
        }
    }
    total
}

/// Random axis-aligned boxes (corners on a 1/8 grid), as primitives, some of them turned a quarter
/// about z, and as meshes: the estimate is within its bound of the exact excess (volumes less
/// the exact union), on the finest grid and on the coarse grid a small work cap gives, whose
/// bound is wider and says so.
#[test]
fn the_bound_holds_against_an_exact_union_of_boxes() {
    let quarter: Mat3 = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let mut seed = 25u64;
    let mut eighths = |lo: f64, hi: f64| {
        let u = crate::lcg_unit(&mut seed);
        (8.0 * (lo + (hi - lo) * u)).round() / 8.0
    };
    let boxes: Vec<(Corners, bool)> = (0..40)
        .map(|i| {
            let lo = [0, 1, 2].map(|_| eighths(0.0, 3.0));
            let size = [0, 1, 2].map(|_| eighths(0.25, 1.5));
            ((lo, [0, 1, 2].map(|k| lo[k] + size[k])), i % 3 == 0)
        })
        .collect();
    let exact = boxes
        .iter()
        .map(|(b, _)| (0..3).map(|k| b.1[k] - b.0[k]).product::<f64>())
        .sum::<f64>()
        - union_volume(&boxes.iter().map(|b| b.0).collect::<Vec<_>>());
    assert!(exact > 1.0, "{exact}");
    for as_mesh in [false, true] {
        let parts: Vec<PlacedPart> = boxes
            .iter()
            .map(|&((lo, hi), turned)| {
                let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                let mut h = [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k]));
                if turned {
                    // The quarter turn about z maps the part's x to the link's y.
                    h.swap(0, 1);
                }
                let shape = if as_mesh {
                    PartShape::Mesh(Arc::new(box_solid(h)))
                } else {
                    PartShape::Box(h)
                };
                let mut p = placed(shape, c, [0.0; 3], 8.0 * h[0] * h[1] * h[2]);
                p.bbox = Aabb::new(lo, hi);
                if turned {
                    p.rotation = quarter;
                }
                p
            })
            .collect();
        let mut bounds = Vec::new();
        for budget in [POINT_TEST_BUDGET, 1 << 14] {
            let e = match estimate_within(&mut parts.clone(), budget) {
                Overlap::Estimated(e) => e,
                other => panic!("expected an estimate, got {other:?}"),
            };
            let error = (e.excess - exact).abs();
            assert!(
                error <= e.bound,
                "{as_mesh} {budget}: {error} > {e:?} ({exact})"
            );
            assert_eq!(e.capped, e.grid < GRID);
            bounds.push((e.bound, e.capped, e.grid));
        }
        // The finest grid (24³ at most) against a capped one.
        assert!(!bounds[0].1 && bounds[1].1, "{bounds:?}");
        assert!(bounds[1].0 > bounds[0].0, "{bounds:?}");
    }
}

/// A chain of ten boxes (corners on a 1/8 grid), each overlapping the next by a quarter of its
/// length and shifted sideways: the exact excess is within the bound, and the bound is a small
/// part of it (every box's region is one meeting, crossed by few faces).
#[test]
fn the_bound_of_a_chain_of_boxes_is_tight() {
    let boxes: Vec<Corners> = (0..10)
        .map(|i| {
            let lo = [0.75 * f64::from(i), 0.125 * f64::from(i % 3), 0.0];
            (lo, [lo[0] + 1.0, lo[1] + 1.0, lo[2] + 1.0])
        })
        .collect();
    let exact = 10.0 - union_volume(&boxes);
    let mut parts: Vec<PlacedPart> = boxes
        .iter()
        .map(|&(lo, hi)| {
            let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
            placed(PartShape::Box([0.5; 3]), c, [0.5; 3], 1.0)
        })
        .collect();
    let e = estimated(&mut parts);
    let error = (e.excess - exact).abs();
    assert!(error <= e.bound, "{error} > {e:?} ({exact})");
    assert!(!e.capped && e.bound < 0.25 * exact, "{e:?} against {exact}");
}

/// 1000 boxes of side 1.5 on a unit lattice: their union is one box of side 10.5, so the excess is
/// exactly 1000 · 1.5³ − 10.5³. The work cap (no minimum grid) takes a coarse grid, and the bound
/// still holds.
#[test]
fn a_thousand_overlapping_boxes_stay_within_the_cap_and_the_bound() {
    let mut parts: Vec<PlacedPart> = (0..1000)
        .map(|i| {
            let t = [i % 10, i / 10 % 10, i / 100].map(f64::from);
            placed(PartShape::Box([0.75; 3]), t, [0.75; 3], 3.375)
        })
        .collect();
    let exact = 1000.0 * 3.375 - 10.5f64.powi(3);
    let e = estimated(&mut parts);
    assert!(e.capped && e.grid < GRID, "{e:?}");
    let error = (e.excess - exact).abs();
    assert!(
        error <= e.bound,
        "{error} > {} ({e:?}, exact {exact})",
        e.bound
    );
    assert_eq!(e.most, 8);
}

/// Boxes that meet only in pairs, each pair's intersection known exactly: a chain of unit cubes
/// (corners on a 1/8 grid) each overlapping the next by `d` along x and shifted sideways by `s`,
/// so that the double-counted volume is `Σ d · (1 − s)`. The reported excess plus its bound is at
/// least that volume (and within the bound of it) on the finest grid and under caps down to one
/// sample per part, where the bound widens and the estimate says it was capped.
#[test]
fn the_bound_covers_exact_pairwise_intersections_under_any_cap() {
    let (d, s) = (0.375, 0.125);
    let boxes: Vec<Corners> = (0..12)
        .map(|i| {
            let lo = [(1.0 - d) * f64::from(i), s * f64::from(i % 2), 0.0];
            (lo, [lo[0] + 1.0, lo[1] + 1.0, lo[2] + 1.0])
        })
        .collect();
    let exact = 11.0 * d * (1.0 - s);
    assert_eq!(exact, 12.0 - union_volume(&boxes));
    for as_mesh in [false, true] {
        let parts: Vec<PlacedPart> = boxes
            .iter()
            .map(|&(lo, hi)| {
                let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                let shape = if as_mesh {
                    PartShape::Mesh(Arc::new(box_solid([0.5; 3])))
                } else {
                    PartShape::Box([0.5; 3])
                };
                placed(shape, c, [0.5; 3], 1.0)
            })
            .collect();
        let mut widths = Vec::new();
        for budget in [POINT_TEST_BUDGET, 1 << 16, 1 << 10, 1] {
            let e = match estimate_within(&mut parts.clone(), budget) {
                Overlap::Estimated(e) => e,
                other => panic!("{as_mesh} {budget}: expected an estimate, got {other:?}"),
            };
            assert!(
                e.excess + e.bound >= exact,
                "{as_mesh} {budget}: {e:?} < {exact}"
            );
            assert!(
                (e.excess - exact).abs() <= e.bound,
                "{as_mesh} {budget}: {e:?}"
            );
            assert_eq!(e.capped, budget != POINT_TEST_BUDGET, "{e:?}");
            widths.push((e.grid, e.bound));
        }
        assert_eq!(widths.last().map(|w| w.0), Some(1), "{widths:?}");
        assert!(widths[3].1 > widths[0].1, "{widths:?}");
    }
}
