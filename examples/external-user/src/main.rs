//! A caller with a robot model of its own (read by urdf-rs, an SDF or MJCF importer, or made in
//! code) hands the library a link with collision parts, gets its inertia, compares it with the
//! inertial the model had and gets typed problems: the facade alone, no URDF text.
//!
//! The link: a 0.1 × 0.2 × 0.3 m box at the origin, a cylinder (r 0.05 m, length 0.2 m) above it and
//! a tetrahedron mesh (legs 0.1 m, written here as an ASCII STL), all aluminium (2700 kg/m³). Every
//! value checked below comes from the textbook formulas, not from the library.

use std::f64::consts::PI;
use std::process::ExitCode;
use urdf_inertia::{
    check, check_computed, compare, compute, load_solid, Collision, DensityMap, Error, FillOptions,
    Geometry, Inertial, Link, LoadOptions, PackageResolver, Pose, ProblemKind, Robot,
};

const DENSITY: f64 = 2700.0;

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("external-user: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Writes the tetrahedron (0,0,0), (0.1,0,0), (0,0.1,0), (0,0,0.1), faces outward, as ASCII STL.
fn write_tetrahedron(path: &std::path::Path) -> std::io::Result<()> {
    let v = [
        [0.0, 0.0, 0.0],
        [0.1, 0.0, 0.0],
        [0.0, 0.1, 0.0],
        [0.0, 0.0, 0.1],
    ];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut text = String::from("solid tetra\n");
    for f in faces {
        text.push_str("facet normal 0 0 0\nouter loop\n");
        for i in f {
            let p: [f64; 3] = v[i];
            text.push_str(&format!("vertex {} {} {}\n", p[0], p[1], p[2]));
        }
        text.push_str("endloop\nendfacet\n");
    }
    text.push_str("endsolid tetra\n");
    std::fs::write(path, text)
}

fn ensure(what: &str, ok: bool) -> Result<(), String> {
    if ok {
        println!("ok: {what}");
        Ok(())
    } else {
        Err(format!("not as expected: {what}"))
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1e-300)
}

fn run() -> Result<(), String> {
    let dir = std::env::temp_dir().join(format!("urdf-inertia-external-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let stl = dir.join("tetra.stl");
    write_tetrahedron(&stl).map_err(|e| e.to_string())?;
    let result = with_mesh(&stl);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn with_mesh(stl: &std::path::Path) -> Result<(), String> {
    // The mesh alone, with its error estimate: volume 0.1³/6.
    let solid = load_solid(stl, [1.0; 3], LoadOptions::default()).map_err(|e| e.to_string())?;
    ensure(
        "the tetrahedron's volume is 0.1³/6",
        close(solid.unit.mass, 1e-3 / 6.0),
    )?;
    ensure("its error estimate is small", solid.error_estimate < 1e-9)?;
    // A missing file is one typed error, with the mesh stage's error as its source.
    let missing = load_solid(
        &stl.with_extension("none.stl"),
        [1.0; 3],
        LoadOptions::default(),
    );
    let e: Error = missing.err().ok_or("a missing mesh loaded")?.into();
    ensure(
        "a missing mesh is Error::Mesh with a source",
        matches!(e, Error::Mesh(_)) && std::error::Error::source(&e).is_some(),
    )?;

    let parts = vec![
        Collision::new(
            Geometry::Box {
                size: [0.1, 0.2, 0.3],
            },
            Pose::default(),
        ),
        Collision::new(
            Geometry::Cylinder {
                radius: 0.05,
                length: 0.2,
            },
            Pose::new([0.0, 0.0, 0.25], [0.0; 3]),
        ),
        Collision::new(
            Geometry::Mesh {
                filename: stl.display().to_string(),
                scale: [1.0; 3],
            },
            Pose::new([0.0, 0.2, 0.0], [0.0; 3]),
        ),
    ];
    let masses = [
        DENSITY * 0.1 * 0.2 * 0.3,
        DENSITY * PI * 0.05 * 0.05 * 0.2,
        DENSITY * 1e-3 / 6.0,
    ];
    let total: f64 = masses.iter().sum();
    // The centre of mass: box at 0, cylinder at z 0.25, tetrahedron's centroid (0.025, 0.025, 0.025)
    // moved by (0, 0.2, 0).
    let com = [
        masses[2] * 0.025 / total,
        masses[2] * 0.225 / total,
        (masses[1] * 0.25 + masses[2] * 0.025) / total,
    ];

    // What the model said: the box alone, ten times too light (a unit slip in the exporter).
    let box_mass = masses[0] / 10.0;
    let said = Inertial::new(
        Pose::default(),
        box_mass,
        [
            box_mass * (0.04 + 0.09) / 12.0,
            0.0,
            0.0,
            box_mass * (0.01 + 0.09) / 12.0,
            0.0,
            box_mass * (0.01 + 0.04) / 12.0,
        ],
    );
    let forearm = Link::new("forearm", parts).with_inertial(said);
    let gripper = Link::new(
        "gripper",
        vec![Collision::new(
            Geometry::Sphere { radius: 0.03 },
            Pose::default(),
        )],
    );
    let robot = Robot::new("arm", vec![forearm, gripper]);

    let report = compute(
        &robot,
        &DensityMap::uniform(DENSITY),
        &PackageResolver::new(),
        &FillOptions::default(),
    );
    ensure(
        "both links computed, none failed",
        report.links.len() == 2 && report.failures.is_empty(),
    )?;
    let link = &report.links[0];
    ensure(
        "the forearm's mass is the parts' sum",
        close(link.computed.mass, total),
    )?;
    ensure(
        "its centre of mass is the parts' mass-weighted one",
        (0..3).all(|k| (link.computed.com[k] - com[k]).abs() < 1e-12),
    )?;
    println!(
        "forearm: mass {:.6} kg, com {:?}, error estimate {:.1e}",
        link.computed.mass,
        link.computed.com,
        link.error_estimate()
    );

    // The comparison itself, and the problems it makes.
    let existing = urdf_inertia::existing_props(&said_of(&robot)?).ok_or("no existing inertial")?;
    let c = compare(&existing, &link.computed, link.size);
    ensure(
        "the mass ratio is what the model said over the sum",
        close(c.mass_ratio, box_mass / total),
    )?;
    let problems = check_computed(&robot, &report, 0.01);
    ensure(
        "one problem: the forearm differs",
        problems.len() == 1 && problems[0].link == "forearm",
    )?;
    ensure("it is UI603", problems[0].code().as_str() == "UI603")?;
    let ProblemKind::Differs { differences, .. } = &problems[0].kind else {
        return Err(format!("unexpected problem {:?}", problems[0].kind));
    };
    ensure(
        "mass, centre of mass and inertia all differ",
        differences.len() == 3,
    )?;
    for p in &problems {
        println!("{}: {} [{}]", p.link, p.kind, p.code());
    }

    // Without computing: the gripper has collision geometry and no inertial.
    let missing = check(&robot, &FillOptions::default());
    ensure(
        "the gripper's inertial is missing (UI601)",
        missing.len() == 1
            && missing[0].link == "gripper"
            && missing[0].kind == ProblemKind::MissingInertial
            && missing[0].code().as_str() == "UI601",
    )?;
    Ok(())
}

/// The inertial the forearm was given.
fn said_of(robot: &Robot) -> Result<Inertial, String> {
    robot.links[0]
        .inertial
        .as_ref()
        .map(|s| s.value.clone())
        .ok_or_else(|| "the forearm lost its inertial".into())
}
