//! Mesh truth (issue: closed meshes with float-noise cracks keep their exact numbers, and every error
//! estimate bounds the real error), against exact rational integrals of the stored triangles.

// The test helpers are the library tests' own (exact integrals, mesh generators).
#[path = "../crates/urdf-inertia/tests/common/mod.rs"]
mod common;

use common::wild::{self, Expect};
use std::fmt::Write as _;
use urdf_inertia::mesh::health::HealthOptions;

/// Runs the real binary and returns its stdout, asserting exit 0.
fn urdf_inertia(args: &[&str]) -> Vec<u8> {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_urdf-inertia"))
        .args(args)
        .output()
        .expect("run");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

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
            // An open mesh whose caps cannot be trusted gives no numbers by default (UI108):
            // nothing claimed, nothing to bound.
            Err(e) if case.expect == Expect::Bounded && e.contains("defines no solid to trust") => {
                println!("{:<55} no solid (UI108)", case.name);
                continue;
            }
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
        if o.com_bound < o.com_error {
            failures.push(format!(
                "{}: centre of mass off by {:.1e} m, bound {:.1e} m",
                case.name, o.com_error, o.com_bound
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

/// The needle 1e-6 × 1e-6 × 1 m (volume 1e-12 m³, as much as its bounding box) and the same needle
/// rotated 1e4 m away are solids, and `urdf-inertia mesh` gives them within 2× the kernel's own error
/// (issue: the zero-volume test relative to the faces, not diag³).
#[test]
fn needles_through_the_mesh_command() {
    let needle = common::box_mesh([1e-6, 1e-6, 1.0]);
    let rot = common::rotation([0.7, -1.3, 2.9]);
    let cases = [
        ("needle.obj", needle.clone()),
        (
            "far_needle.obj",
            common::transform(&needle, 1.0, &rot, [1e4, -2e4, 3e4]),
        ),
    ];
    let tmp = tempfile::tempdir().expect("tempdir");
    for (name, (v, f)) in cases {
        // `{:?}` writes the shortest text that reads back as the same f64: the file is exact.
        let mut obj = String::new();
        for p in &v {
            let _ = writeln!(obj, "v {:?} {:?} {:?}", p[0], p[1], p[2]);
        }
        for t in &f {
            let _ = writeln!(obj, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        let path = tmp.path().join(name);
        std::fs::write(&path, obj).expect("write");
        let stdout = urdf_inertia(&[
            "mesh",
            path.to_str().expect("utf-8"),
            "--format",
            "json",
            "--digits",
            "full",
        ]);
        let json: serde_json::Value = serde_json::from_slice(&stdout).expect("json");
        let inertia: [[f64; 3]; 3] =
            serde_json::from_value(json["inertia"].clone()).expect("inertia");
        let volume = json["volume"].as_f64().expect("volume");
        let exact = common::exact_mass(&common::exact_integrals(&v, &f));
        let kernel = urdf_inertia::mass::MassProperties::from_trimesh(&v, &f, 1.0);
        let floor = common::floor_error(&exact.inertia);
        let kernel_error = common::inertia_error(&kernel.inertia, &exact.inertia).max(floor);
        let cli_error = common::inertia_error(&inertia, &exact.inertia);
        assert!(
            cli_error <= 2.0 * kernel_error,
            "{name}: {cli_error:.1e} against the kernel's {kernel_error:.1e}"
        );
        assert!(common::rel_error(volume, &exact.volume) <= 1e-15, "{name}");
        let estimate = json["error_estimate"].as_f64().expect("estimate");
        assert!(
            estimate >= cli_error,
            "{name}: estimate {estimate:.1e} below {cli_error:.1e}"
        );
    }
}

/// CI finding: with `--digits auto`, a part whose model error is large (caps, a hull) had its numbers
/// rounded within that error, down to `mass value="0"`. Rounding keeps six digits at least.
#[test]
fn large_error_estimates_do_not_round_numbers_away() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // A unit cube without its top, one top corner raised 0.1: flat caps are uncertain by a few %
    // (above the 1e-3 they are trusted to, so asked for with `--open-mesh caps`).
    let mut obj = String::new();
    for i in 0..8 {
        let z = f64::from((i >> 2) & 1) + if i == 7 { 0.1 } else { 0.0 };
        let _ = writeln!(obj, "v {} {} {z}", i & 1, (i >> 1) & 1);
    }
    for q in [
        [0, 2, 3, 1],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        let _ = writeln!(obj, "f {} {} {} {}", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
    }
    std::fs::write(tmp.path().join("open.obj"), obj).expect("write");
    let urdf = tmp.path().join("r.urdf");
    std::fs::write(
        &urdf,
        "<robot name=\"r\"><link name=\"l\"><collision><geometry><mesh filename=\"open.obj\"/></geometry></collision></link></robot>\n",
    )
    .expect("write");
    let fill = |digits: &str| {
        let stdout = urdf_inertia(&[
            "fill",
            urdf.to_str().expect("utf-8"),
            "--density",
            "1",
            "--digits",
            digits,
            "--open-mesh",
            "caps",
        ]);
        let text = String::from_utf8(stdout).expect("utf-8");
        let mass: f64 = text
            .split("<mass value=\"")
            .nth(1)
            .and_then(|r| r.split('"').next())
            .and_then(|m| m.parse().ok())
            .expect("a mass");
        (text, mass)
    };
    let (_, full) = fill("full");
    let (auto_text, auto) = fill("auto");
    assert!(full > 1.0 && full < 1.1, "{full}");
    assert!((auto - full).abs() <= 1e-6 * full, "{auto} against {full}");
    let filled = tmp.path().join("filled.urdf");
    std::fs::write(&filled, auto_text).expect("write");
    // `check` exits 0 on the rounded output.
    urdf_inertia(&["check", filled.to_str().expect("utf-8")]);
}

/// The round-off half of the estimate is measured, not only its floor: a box whose cavity is a box a
/// hair smaller (walls 1e-7 of its size, rotated, off the origin) has a volume far below its faces'
/// contributions, so cancellation costs digits: its real error exceeds the 4ε floor, and the estimate
/// (then above the floor too) still bounds it.
#[test]
fn round_off_estimate_above_its_floor_bounds_the_exact_error() {
    let r = common::rotation([0.3, 1.1, -0.7]);
    let t = [12.5, -7.25, 3.0];
    let outer = common::transform(&common::box_mesh([1.0, 0.75, 0.5]), 1.0, &r, t);
    let wall = 1e-7;
    let inner = common::box_mesh([1.0 - wall, 0.75 - wall, 0.5 - wall]);
    let inner = common::transform(&inner, 1.0, &r, t);
    let mut v = outer.0.clone();
    v.extend_from_slice(&inner.0);
    let mut f = outer.1.clone();
    f.extend(inner.1.iter().map(|t| [t[0] + 8, t[2] + 8, t[1] + 8]));
    let raw = urdf_inertia::mesh::RawMesh {
        vertices: v.clone(),
        faces: urdf_inertia::mass::Polygons::from_triangles(&f),
        ..Default::default()
    };
    let s = urdf_inertia::mesh::health::make_solid(
        &raw,
        std::path::Path::new("shell"),
        HealthOptions::default(),
    )
    .expect("solid");
    let exact = common::exact_mass(&common::exact_integrals(&v, &f));
    let volume = common::rel_error(s.unit.mass, &exact.volume);
    let inertia = common::inertia_error(&s.unit.inertia, &exact.inertia);
    let floor = urdf_inertia::mesh::health::ROUND_OFF_FLOOR;
    assert!(
        volume.max(inertia) > floor,
        "the real error {:e} must exceed the floor {floor:e} for this test to pin the estimate",
        volume.max(inertia)
    );
    assert!(
        volume <= s.error.round_off && inertia <= s.error.round_off,
        "volume {volume:e}, inertia {inertia:e}, round-off estimate {:e}",
        s.error.round_off
    );
}

/// A random rotation: the Gram–Schmidt frame of three random vectors.
fn random_axes(rng: &mut common::Rng) -> Vec<[f64; 3]> {
    let mut axes: Vec<[f64; 3]> = Vec::new();
    while axes.len() < 3 {
        let mut a: [f64; 3] = std::array::from_fn(|_| rng.range(-1.0, 1.0));
        for b in &axes {
            let d: f64 = (0..3).map(|k| a[k] * b[k]).sum();
            a = std::array::from_fn(|k| a[k] - d * b[k]);
        }
        let n = a.iter().map(|x| x * x).sum::<f64>().sqrt();
        if n > 0.1 {
            axes.push(a.map(|x| x / n));
        }
    }
    axes
}

/// Case `case` of [`flat_and_far_shapes_are_within_the_round_off_bound`]: its corners, triangles
/// (outward unless `inward`) and a name that says how it was made.
fn flat_or_far_shape(rng: &mut common::Rng, case: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>, String) {
    let size = 10f64.powf(rng.range(-3.0, 3.0));
    let far = size * 10f64.powf(rng.range(0.0, 5.0));
    let offset: [f64; 3] = std::array::from_fn(|_| far * rng.range(-1.0, 1.0));
    let thin = 10f64.powf(rng.range(-8.0, 0.0));
    let f32 = rng.f64() < 0.3;
    let inward = rng.f64() < 0.3;
    let axes = random_axes(rng);
    let place = |p: [f64; 3]| -> [f64; 3] {
        let q: [f64; 3] = std::array::from_fn(|k| {
            offset[k] + size * (0..3).map(|i| p[i] * axes[i][k]).sum::<f64>()
        });
        if f32 {
            q.map(|x| f64::from(x as f32))
        } else {
            q
        }
    };
    let tetrahedron = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
    let kind = case % 3;
    let (vertices, mut tris): (Vec<[f64; 3]>, Vec<[u32; 3]>) = match kind {
        // A tetrahedron whose fourth corner is `thin` above the plane of the other three.
        0 => {
            let mut c: Vec<[f64; 3]> = (0..3)
                .map(|_| [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0])
                .collect();
            c.push([rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), thin]);
            (c.into_iter().map(place).collect(), tetrahedron)
        }
        // A needle: a tetrahedron `thin` across and 1 long.
        1 => {
            let c = [
                [0.0, 0.0, 0.0],
                [thin, 0.0, 0.0],
                [0.0, thin, 0.0],
                [0.3 * thin, 0.3 * thin, 1.0],
            ];
            (c.into_iter().map(place).collect(), tetrahedron)
        }
        // A slab 1 × 0.7 × thin.
        _ => {
            let h = [0.5, 0.35, 0.5 * thin];
            let c: Vec<[f64; 3]> = (0..8)
                .map(|i| std::array::from_fn(|k| if i >> k & 1 == 1 { h[k] } else { -h[k] }))
                .collect();
            let t = vec![
                [0, 2, 3],
                [0, 3, 1],
                [4, 5, 7],
                [4, 7, 6],
                [0, 1, 5],
                [0, 5, 4],
                [2, 6, 7],
                [2, 7, 3],
                [0, 4, 6],
                [0, 6, 2],
                [1, 3, 7],
                [1, 7, 5],
            ];
            (c.into_iter().map(place).collect(), t)
        }
    };
    // Outward (a positive exact volume: a rotation may mirror), then reversed when `inward`.
    let outward = num_traits::Signed::is_positive(&common::exact_integrals(&vertices, &tris)[0]);
    if outward == inward {
        for t in &mut tris {
            t.swap(1, 2);
        }
    }
    let name = format!("case {case} (kind {kind}, size {size:.1e}, far {far:.1e}, thin {thin:.1e}, f32 {f32}, inward {inward})");
    (vertices, tris, name)
}

/// The round-off bound of a clean surface (`mass::integrals::Rounding`, the only estimate such a
/// surface gets) against exact rationals, on the shapes whose rounding is largest relative to
/// their size: tetrahedra flattened toward the plane of three corners (a fourth corner 1e-8 to 1
/// of the size above it: the faces' contributions cancel), needles, and rotated slabs 1e-8 to 1
/// thick, 1e-3 to 1e3 across, up to 1e5 of their size from the origin, wound either way, some
/// with f32 corners. Every volume, central inertia and centre of mass within its bound.
#[test]
fn flat_and_far_shapes_are_within_the_round_off_bound() {
    let mut rng = common::Rng(0x5eed_0042);
    let mut worst = (0.0f64, String::new());
    let (mut failures, mut clean) = (Vec::new(), 0);
    for case in 0..600 {
        let (vertices, tris, name) = flat_or_far_shape(&mut rng, case);
        let t = common::exact_integrals(&vertices, &tris);
        if num_traits::Zero::is_zero(&t[0]) {
            continue;
        }
        // The solid is the region the surface encloses, whichever way it is wound.
        let t = if num_traits::Signed::is_negative(&t[0]) {
            t.map(|x| -x)
        } else {
            t
        };
        let exact = common::exact_mass(&t);
        let raw = urdf_inertia::mesh::RawMesh {
            vertices,
            faces: urdf_inertia::mass::Polygons::from_triangles(&tris),
            ..Default::default()
        };
        let path = std::path::Path::new(&name);
        let solid = match urdf_inertia::mesh::solid_from_raw(
            &raw,
            [1.0; 3],
            path,
            HealthOptions::default(),
        ) {
            Ok(s) => s,
            // Flatter than the empty-solid check allows: refused, nothing claimed.
            Err(e)
                if e.to_string().contains("no volume") || e.to_string().contains("zero volume") =>
            {
                continue
            }
            Err(e) => panic!("{name}: {e}"),
        };
        // Corners an f32 apart can collapse a thin slab: welded, with the cracks in the model.
        if matches!(solid.rung.name(), "exact" | "inverted") {
            clean += 1;
        }
        let error = common::rel_error(solid.unit.mass, &exact.volume)
            .max(common::inertia_error(&solid.unit.inertia, &exact.inertia));
        let com: f64 = (0..3)
            .map(|k| {
                let d = common::rat(solid.unit.com[k]) - &exact.com[k];
                num_traits::ToPrimitive::to_f64(&d).unwrap().powi(2)
            })
            .sum::<f64>()
            .sqrt();
        let ratio = (error / solid.error_estimate).max(com / solid.error.com);
        if ratio > worst.0 {
            worst = (ratio, name.clone());
        }
        if ratio > 1.0 {
            failures.push(format!(
                "{name}: error {error:.2e} under {:.2e}, centre {com:.2e} m under {:.2e} m",
                solid.error_estimate, solid.error.com
            ));
        }
    }
    println!(
        "{clean} clean; largest error / bound {:.3} ({})",
        worst.0, worst.1
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(clean >= 500, "{clean} clean");
}
