use super::*;

/// A unit cube without its top face, one top corner raised 1e-3, beside a closed 1 cm
/// tetrahedron `far` metres away: the caps' uncertainty sits at the hole, not at the far part.
fn open_cube_and_far_tetrahedron(far: f64) -> RawMesh {
    let mut v: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            [
                f64::from(i & 1),
                f64::from((i >> 1) & 1),
                f64::from((i >> 2) & 1),
            ]
        })
        .collect();
    v[7][2] += 1e-3;
    let quads = [
        [0, 2, 3, 1],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut tris: Vec<[u32; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    let t = 0.01;
    v.extend([
        [far, 0.0, 0.0],
        [far + t, 0.0, 0.0],
        [far, t, 0.0],
        [far, 0.0, t],
    ]);
    tris.extend([[8, 10, 9], [8, 9, 11], [8, 11, 10], [9, 10, 11]]);
    RawMesh {
        vertices: v,
        faces: Polygons::from_triangles(&tris),
        ..Default::default()
    }
}

// Corpus finding: a capped mesh reported an unbounded estimate when a small part lay far away.
#[test]
fn caps_bound_does_not_grow_with_far_parts() {
    // The bound (about 4e-3) is above the 1e-3 caps are trusted to: asked for explicitly.
    let caps = HealthOptions {
        open_mesh: OpenMeshModel::Caps,
        ..HealthOptions::default()
    };
    for far in [10.0, 30.0, 1000.0] {
        let e = make_solid(
            &open_cube_and_far_tetrahedron(far),
            Path::new("t"),
            HealthOptions::default(),
        )
        .expect_err("not trusted by default");
        assert!(matches!(e.kind, MeshErrorKind::NoSolid(_)), "{e}");
        let s =
            make_solid(&open_cube_and_far_tetrahedron(far), Path::new("t"), caps).expect("solid");
        assert_eq!(s.rung.name(), "capped", "{far}");
        // The cap over the raised corner is bounded by the certified cells (a layer of cells about
        // it, a few 1e-3 m³ within 1.5 m of the cube's centre), against 1 m³ and the cube's
        // inertia: finite, and the same however far the tetrahedron lies.
        assert!(s.error_estimate < 0.5, "{far}: {}", s.error_estimate);
        assert!(s.error.com < 0.1, "{far}: {}", s.error.com);
    }
}

/// A torus of `k` × 2k quads (faces as quads, or split in two), its vertices numbered in a
/// shuffled order, its faces shuffled and each started at a random corner.
fn shuffled_torus(k: u32, quads: bool, rng: &mut u64) -> Vec<Vec<u32>> {
    let (m, n) = (k, 2 * k);
    let mut label: Vec<u32> = (0..m * n).collect();
    for i in (1..label.len()).rev() {
        label.swap(i, crate::xorshift(rng) as usize % (i + 1));
    }
    let at = |i: u32, j: u32| label[((i % m) * n + j % n) as usize];
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for i in 0..m {
        for j in 0..n {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            if quads {
                faces.push(q.to_vec());
            } else {
                faces.push(vec![q[0], q[1], q[2]]);
                faces.push(vec![q[0], q[2], q[3]]);
            }
        }
    }
    for i in (1..faces.len()).rev() {
        faces.swap(i, crate::xorshift(rng) as usize % (i + 1));
    }
    for f in &mut faces {
        let r = crate::xorshift(rng) as usize % f.len();
        f.rotate_left(r);
    }
    faces
}

/// Whether every directed edge appears once and its reverse once: the definition, by a map.
fn twins_by_map(faces: &[Vec<u32>]) -> bool {
    let mut count = std::collections::HashMap::<(u32, u32), i32>::new();
    for f in faces {
        for k in 0..f.len() {
            *count.entry((f[k], f[(k + 1) % f.len()])).or_default() += 1;
        }
    }
    count
        .iter()
        .all(|(&(u, v), &c)| c == 1 && count.get(&(v, u)) == Some(&1))
}

fn polygons(faces: &[Vec<u32>]) -> Polygons {
    let mut p = Polygons::new();
    for f in faces {
        p.push(f);
    }
    p
}

/// The proof of a clean surface agrees with the definition (a map of directed edges): on clean
/// tori whatever the numbering, the face order and the corner each face starts at, triangles or
/// quads, and on each with one face removed or reversed.
#[test]
fn the_proof_of_a_clean_surface_is_the_definition() {
    let mut rng = 0x5eed_u64;
    for (k, quads) in [(3, false), (3, true), (10, false), (10, true), (40, false)] {
        for _ in 0..5 {
            let clean = shuffled_torus(k, quads, &mut rng);
            assert!(twins_by_map(&clean));
            let (comp, ncomp) = closed_consistent(&polygons(&clean)).expect("clean");
            assert_eq!((comp.len(), ncomp), (clean.len(), 1));
            for change in 0..40 {
                let mut faces = clean.clone();
                let f = crate::xorshift(&mut rng) as usize % faces.len();
                if change % 2 == 0 {
                    faces.remove(f);
                } else {
                    faces[f].reverse();
                }
                assert!(!twins_by_map(&faces));
                assert!(closed_consistent(&polygons(&faces)).is_none());
            }
        }
    }
}

#[test]
fn duplicated_faces_are_dropped() {
    // A tetrahedron with one face stored twice.
    let v = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let f = Polygons::from_triangles(&[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [0, 1, 3]]);
    let raw = RawMesh {
        vertices: v,
        faces: f,
        ..Default::default()
    };
    let s = make_solid(&raw, Path::new("t"), HealthOptions::default()).expect("solid");
    assert_eq!(s.rung.name(), "welded", "{:?}", s.warnings);
    assert!((s.unit.mass - 1.0 / 6.0).abs() < 1e-15, "{}", s.unit.mass);
}

/// `Rung::NAMES` (the JSON Schema's list of provenances) is every rung's name, in ladder order; the
/// match keeps this list complete when a rung is added.
#[test]
fn rung_names_list_every_rung() {
    let rungs = [
        Rung::Exact,
        Rung::Welded {
            merged_vertices: 0,
            widest_crack: 0.0,
            tolerance: 0.0,
        },
        Rung::Reoriented {
            faces_flipped: 0,
            components: 0,
        },
        Rung::Inverted,
        Rung::Capped {
            holes: 0,
            boundary_edges: 0,
            nonmanifold_edges: 0,
            faces_flipped: 0,
            relative_uncertainty: 0.0,
        },
        Rung::NonManifold {
            nonmanifold_edges: 0,
            faces_flipped: 0,
        },
        Rung::ConvexHull {
            boundary_edges: 0,
            nonmanifold_edges: 0,
            mesh_volume: 0.0,
            hull_volume: 0.0,
            volume_moves_by: 0.0,
        },
    ];
    for (k, r) in rungs.iter().enumerate() {
        // A new rung fails to compile here until it is listed above and in `Rung::NAMES`.
        let position = match r {
            Rung::Exact => 0,
            Rung::Welded { .. } => 1,
            Rung::Reoriented { .. } => 2,
            Rung::Inverted => 3,
            Rung::Capped { .. } => 4,
            Rung::NonManifold { .. } => 5,
            Rung::ConvexHull { .. } => 6,
        };
        assert_eq!(position, k);
    }
    assert_eq!(rungs.map(|r| r.name()), Rung::NAMES);
}
