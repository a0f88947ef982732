//! Shells that overlap, for the tests of the solid Ω = {x : |w(x)| ≥ ½}: a raw mesh healed as the
//! ladder heals a file, boxes opened and put together, and exact rational sums of their integrals
//! with the check that every error is within the estimate.

use super::{ExactMass, Mesh};
use num_rational::BigRational;
use std::path::Path;
use urdf_inertia::mass::Polygons;
use urdf_inertia::mesh::health::{HealthOptions, Solid};
use urdf_inertia::mesh::RawMesh;

/// `mesh` healed with `options`, as a file named `name` would be.
pub fn solid_with(mesh: &Mesh, options: HealthOptions, name: &str) -> Solid {
    let raw = RawMesh {
        vertices: mesh.0.clone(),
        faces: Polygons::from_triangles(&mesh.1),
        ..Default::default()
    };
    urdf_inertia::mesh::solid_from_raw(&raw, [1.0; 3], Path::new(name), options).expect("a solid")
}

/// The box's faces without those on its top (largest z): open, so the mesh reaches the capped rung.
pub fn open_top(b: &Mesh) -> Mesh {
    let top = b.0.iter().map(|p| p[2]).fold(f64::MIN, f64::max);
    let f =
        b.1.iter()
            .copied()
            .filter(|t| !t.iter().all(|&i| b.0[i as usize][2] == top))
            .collect();
    (b.0.clone(), f)
}

/// The meshes in one vertex list, those marked `true` wound inward.
pub fn together(parts: &[(&Mesh, bool)]) -> Mesh {
    let (mut v, mut f) = (Vec::new(), Vec::new());
    for (m, inward) in parts {
        let n = v.len() as u32;
        v.extend_from_slice(&m.0);
        f.extend(m.1.iter().map(|t| {
            let t = t.map(|i| i + n);
            if *inward {
                [t[0], t[2], t[1]]
            } else {
                t
            }
        }));
    }
    (v, f)
}

/// Σ cᵢ × (integrals of mesh i): a union or difference of boxes through inclusion–exclusion.
pub fn exact_sum(terms: &[(i32, &Mesh)]) -> ExactMass {
    let mut t: [BigRational; 10] = std::array::from_fn(|_| super::rat(0.0));
    for (c, m) in terms {
        let u = super::exact_integrals(&m.0, &m.1);
        let c = BigRational::from_integer((*c).into());
        t = std::array::from_fn(|k| &t[k] + &u[k] * &c);
    }
    super::exact_mass(&t)
}

/// Volume, inertia and centre errors of `s` against `exact`, asserted within its estimate; the
/// larger of the first two.
pub fn within_estimate(name: &str, s: &Solid, exact: &ExactMass) -> f64 {
    let volume = super::rel_error(s.unit.mass, &exact.volume);
    let inertia = super::inertia_error(&s.unit.inertia, &exact.inertia);
    let com = super::com_error(s.unit.com, &exact.com, 1.0);
    assert!(
        volume <= s.error_estimate && inertia <= s.error_estimate && com <= s.error.com,
        "{name}: volume {volume:e}, inertia {inertia:e}, com {com:e}, estimate {:e} (com {:e})\n{:?}",
        s.error_estimate,
        s.error.com,
        s.warnings
    );
    volume.max(inertia)
}

/// Asserts that `s`'s estimate is at most `bound`: the classification decided the shells, not their
/// boxes' bound.
pub fn assert_estimate_at_most(s: &Solid, bound: f64) {
    assert!(
        s.error_estimate <= bound,
        "estimate {:e} above {bound:e}: {:?}",
        s.error_estimate,
        s.warnings
    );
}

/// An icosphere of level 6 without its first face (a planar hole: exact caps), and for each
/// (offset, radius) a whole one scaled by `radius` and moved by `offset` along x: the shells rows
/// of `benches/open_mesh.rs` and `examples/shells_once.rs`.
pub fn spheres(others: &[(f64, f64)]) -> RawMesh {
    let (v, f) = super::icosphere(6);
    let mut vertices = v.clone();
    let mut tris: Vec<[u32; 3]> = f[1..].to_vec();
    for &(offset, radius) in others {
        let n = vertices.len() as u32;
        vertices.extend(
            v.iter()
                .map(|p| [p[0] * radius + offset, p[1] * radius, p[2] * radius]),
        );
        tris.extend(f.iter().map(|t| t.map(|i| i + n)));
    }
    RawMesh {
        vertices,
        faces: Polygons::from_triangles(&tris),
        ..RawMesh::default()
    }
}
