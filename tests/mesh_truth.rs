//! Mesh truth (issue: closed meshes with float-noise cracks keep their exact numbers, and every error
//! estimate bounds the real error), against exact rational integrals of the stored triangles.

mod common;

use common::wild::{self, Expect};
use urdf_inertia::mesh::health::HealthOptions;

#[test]
fn generators_make_closed_outward_meshes() {
    for (name, base) in wild::bases() {
        let exact = common::exact_mass(&common::exact_integrals(&base.0, &base.1));
        assert!(
            num_traits::Signed::is_positive(&exact.volume),
            "{name} is wound inward"
        );
        let raw = urdf_inertia::mesh::RawMesh {
            vertices: base.0.clone(),
            faces: urdf_inertia::mass::Polygons::from_triangles(&base.1),
            ..Default::default()
        };
        let s = urdf_inertia::mesh::solid_from_raw(
            &raw,
            [1.0; 3],
            std::path::Path::new(&name),
            HealthOptions::default(),
        )
        .expect("solid");
        assert_eq!(s.rung.name(), "exact", "{name}");
    }
}

#[test]
fn every_estimate_bounds_the_real_error() {
    let mut failures = Vec::new();
    for case in wild::cases() {
        let o = match wild::run(&case) {
            Ok(o) => o,
            Err(e) => {
                failures.push(format!("{}: {e}", case.name));
                continue;
            }
        };
        println!(
            "{:<55} {:<12} volume {:.1e} inertia {:.1e} estimate {:.1e} ({})",
            case.name, o.rung, o.volume_error, o.inertia_error, o.estimate, o.source
        );
        if o.estimate < o.real() {
            failures.push(format!(
                "{}: estimate {:.1e} below the real error {:.1e} (rung {})",
                case.name,
                o.estimate,
                o.real(),
                o.rung
            ));
        }
        if case.expect == Expect::AsStored {
            if !(o.rung == "exact" || o.rung == "welded") {
                failures.push(format!(
                    "{}: rung {}, not exact or welded",
                    case.name, o.rung
                ));
            }
            if o.real() > 1e-9 {
                failures.push(format!(
                    "{}: {:.1e} from the stored triangles' exact value",
                    case.name,
                    o.real()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
