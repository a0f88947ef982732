//! Error against run time: writes `docs/accuracy.md` and `docs/accuracy.svg`.
//!
//! `cargo run --release --example accuracy_report` (a few minutes). With `EXAMPLE_ROBOT_DATA_SHARE` set to
//! the `cmeel.prefix/share` directory of example-robot-data (as `validation/run.sh` installs it), it also
//! times filling every URDF of the corpus and loading every collision mesh once. With `PEERS_PYTHON` set to
//! a Python that has coal and trimesh (e.g. `validation/.venv/bin/python` plus `pip install trimesh`), it
//! runs them on the same meshes through `validation/peers.py`, and on the 1.3 M-face STL of the pipeline
//! section (loading included). The pipeline section runs the `urdf-inertia` binary next to this example
//! (`cargo build --release` first); `URDF_INERTIA_REPORT_HUGE=1` adds a 5.2 M-face sphere to its table.
//!
//! Every error is against exact rational arithmetic on the stored mesh (tests/common's reference).

// The allocator of the `urdf-inertia` binary (see the binary's src/main.rs), so that timings are the binary's.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "report/ladder.rs"]
mod ladder;

use common::{
    box_mesh, com_error, exact_integrals, exact_mass, floor_error, icosphere, inertia_error, rat,
    rel_error, rotation, rounded, transform, ExactMass, Mesh,
};
use num_rational::BigRational;
use num_traits::ToPrimitive;
use std::fmt::Write as _;
use std::time::Instant;
use urdf_inertia::mass::integrals::{mirtich_polygons, triangle_integrals, volume_integrals};
use urdf_inertia::mass::{
    IntegrationOptions, MassProperties, Polygons, Summation, VolumeIntegrals,
};
use urdf_inertia::mesh::health::HealthOptions;
use urdf_inertia::write::WriteOptions;

/// The kernel variants compared.
#[derive(Clone, Copy)]
enum Variant {
    /// Mirtich's Figures 4–6 about the origin, plain sums.
    Paper,
    /// Triangle kernel about the bounding-box centre, plain sums, no accurate faces.
    Recentred,
    /// ... with compensated sums.
    RecentredCompensated,
    /// urdf-inertia's kernel: recentred, compensated, accurate ill-conditioned faces, one final rounding.
    Ours,
    /// urdf-inertia's kernel on vertices rounded to f32 first (what float32 loaders such as assimp feed).
    OursF32Input,
}

const VARIANTS: [(Variant, &str); 5] = [
    (Variant::Paper, "paper (origin, plain sums)"),
    (Variant::Recentred, "recentred, plain sums"),
    (Variant::RecentredCompensated, "recentred, compensated"),
    (
        Variant::Ours,
        "ours (recentred, compensated, accurate faces)",
    ),
    (Variant::OursF32Input, "ours on f32-rounded input"),
];

fn integrate(
    variant: Variant,
    v: &[[f64; 3]],
    f: &[[u32; 3]],
    polys: &Polygons,
) -> VolumeIntegrals {
    match variant {
        Variant::Paper => mirtich_polygons(v, polys, &IntegrationOptions::paper()),
        Variant::Recentred => triangle_integrals(
            v,
            f,
            &IntegrationOptions {
                reference: None,
                summation: Summation::Plain,
                accurate_faces: false,
            },
        ),
        Variant::RecentredCompensated => triangle_integrals(
            v,
            f,
            &IntegrationOptions {
                reference: None,
                summation: Summation::Compensated,
                accurate_faces: false,
            },
        ),
        Variant::Ours => triangle_integrals(v, f, &IntegrationOptions::accurate()),
        Variant::OursF32Input => {
            let v32: Vec<[f64; 3]> = v.iter().map(|p| p.map(|c| f64::from(c as f32))).collect();
            triangle_integrals(&v32, f, &IntegrationOptions::accurate())
        }
    }
}

/// Median time of `f` in seconds, repeated until about `budget` seconds are spent.
fn time<T>(budget: f64, mut f: impl FnMut() -> T) -> f64 {
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 3 || (start.elapsed().as_secs_f64() < budget && samples.len() < 2000) {
        let t = Instant::now();
        std::hint::black_box(f());
        samples.push(t.elapsed().as_secs_f64());
    }
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

struct Errors {
    mass: f64,
    com: f64,
    inertia: f64,
    smallest: f64,
}

fn smallest_exact(exact: &ExactMass) -> f64 {
    // The Rayleigh quotient of the exact tensor at the eigenvector of its f64 rounding: second-order
    // accurate in the eigenvector's error, so exact to far below f64 for the smallest moment.
    let (_, axes) = urdf_inertia::mass::jacobi::symmetric_eigen(rounded(&exact.inertia));
    let n: Vec<BigRational> = (0..3).map(|r| rat(axes[r][0])).collect();
    let mut num = BigRational::from_integer(0.into());
    for i in 0..3 {
        for j in 0..3 {
            num += &n[i] * &exact.inertia[i][j] * &n[j];
        }
    }
    let den: BigRational = n
        .iter()
        .map(|x| x * x)
        .fold(BigRational::from_integer(0.into()), |a, b| a + b);
    (num / den).to_f64().unwrap()
}

fn errors(mp: &MassProperties, exact: &ExactMass, size: f64, small: f64) -> Errors {
    let finite = mp.inertia.iter().flatten().all(|x| x.is_finite()) && mp.mass.is_finite();
    if !finite {
        return Errors {
            mass: f64::INFINITY,
            com: f64::INFINITY,
            inertia: f64::INFINITY,
            smallest: f64::INFINITY,
        };
    }
    Errors {
        mass: rel_error(mp.mass, &exact.volume),
        com: com_error(mp.com, &exact.com, size),
        inertia: inertia_error(&mp.inertia, &exact.inertia),
        smallest: ((mp.principal().moments[0] - small) / small).abs(),
    }
}

fn e(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.is_finite() {
        format!("{x:.1e}")
    } else {
        "inf".into()
    }
}

fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    format!(
        "{cpu}, {cores} cores visible, one core used; {} {}",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

#[allow(clippy::too_many_lines)] // a script: the report's sections in order
fn main() -> std::io::Result<()> {
    // Section 6 alone, printed rather than written, to iterate on the ERD fill's speed.
    if std::env::var("URDF_INERTIA_REPORT_ONLY").as_deref() == Ok("erd") {
        let mut md = String::new();
        match std::env::var("EXAMPLE_ROBOT_DATA_SHARE") {
            Ok(share) => corpus(&mut md, std::path::Path::new(&share)),
            Err(_) => md.push_str("Set `EXAMPLE_ROBOT_DATA_SHARE` to time the ERD corpus.\n"),
        }
        print!("{md}");
        return Ok(());
    }
    let mut md = String::new();
    writeln!(md, "# Accuracy against run time\n").ok();
    writeln!(md, "Generated by `cargo run --release --example accuracy_report` on {}. Errors are against exact rational arithmetic on the stored meshes (every f64 is a rational); times are medians of repeated runs on one core.\n", machine()).ok();

    // 1. Table 1.
    writeln!(md, "## 1. The paper's Table 1\n").ok();
    writeln!(md, "Integrals about the origin. Paper: 15 significant digits, 64 µs (tetrahedron) and 110 µs (cube) on an R4400.\n").ok();
    writeln!(
        md,
        "| object | integral | ours | exact | relative error |\n|---|---|---|---|---|"
    )
    .ok();
    let names = [
        "T1", "Tx", "Ty", "Tz", "Tx²", "Ty²", "Tz²", "Txy", "Tyz", "Tzx",
    ];
    let tet_v = vec![
        [0.0, 0.0, 0.0],
        [5.0, 0.0, 0.0],
        [0.0, 4.0, 0.0],
        [0.0, 0.0, 3.0],
    ];
    let tet_f = vec![[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let cube = box_mesh([20.0, 20.0, 20.0]);
    let mut cube_quads = Polygons::new();
    for q in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        cube_quads.push(&q);
    }
    let mut times = Vec::new();
    for (name, v, polys, tris) in [
        (
            "cube (quads)",
            cube.0.clone(),
            cube_quads.clone(),
            cube.1.clone(),
        ),
        (
            "tetrahedron",
            tet_v.clone(),
            Polygons::from_triangles(&tet_f),
            tet_f.clone(),
        ),
    ] {
        let ours = volume_integrals(&v, &polys, &IntegrationOptions::accurate()).about([0.0; 3]);
        let exact = exact_integrals(&v, &tris);
        for k in 0..10 {
            let ex = exact[k].to_f64().unwrap();
            writeln!(
                md,
                "| {name} | {} | {} | {} | {} |",
                names[k],
                ours[k],
                ex,
                e(rel_error(ours[k], &exact[k]))
            )
            .ok();
        }
        times.push((
            name,
            time(0.3, || {
                volume_integrals(&v, &polys, &IntegrationOptions::accurate())
            }),
            time(0.3, || {
                mirtich_polygons(&v, &polys, &IntegrationOptions::paper())
            }),
        ));
    }
    writeln!(md).ok();
    for (name, t_ours, t_paper) in &times {
        writeln!(
            md,
            "Time for all ten integrals of the {name}: ours {:.2} µs, paper-faithful {:.2} µs.",
            t_ours * 1e6,
            t_paper * 1e6
        )
        .ok();
    }

    // 2. Table 2.
    writeln!(md, "\n## 2. The paper's Table 2: the sphere series\n").ok();
    writeln!(md, "Icosahedron refined by projecting edge midpoints onto the unit sphere. Error: relative Frobenius error of the central inertia against the exact value for that polyhedron. Paper times on an R4400.\n").ok();
    writeln!(md, "| approx. | verts | edges | faces | T1 | Tx | Tx² | Tyz | error (ours) | error (paper variant) | time (ours) | ns/face | growth | paper time |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|").ok();
    let paper_times = [
        "500 µs", "1.2 ms", "4.9 ms", "21 ms", "82 ms", "350 ms", "-", "-", "-",
    ];
    let mut last = None;
    let mut plot: Vec<(usize, f64, f64)> = Vec::new(); // (variant, ns/face, error)
    let mut plot_faces: Vec<usize> = Vec::new();
    for level in 1..=9u32 {
        let (v, f) = icosphere(level);
        let polys = Polygons::from_triangles(&f);
        let t = integrate(Variant::Ours, &v, &f, &polys).about([0.0; 3]);
        let exact = exact_mass(&exact_integrals(&v, &f));
        let ours = MassProperties::from_integrals(&integrate(Variant::Ours, &v, &f, &polys), 1.0);
        let paper = MassProperties::from_integrals(&integrate(Variant::Paper, &v, &f, &polys), 1.0);
        let secs = time(if level > 6 { 2.0 } else { 0.5 }, || {
            integrate(Variant::Ours, &v, &f, &polys)
        });
        let growth = last.map_or_else(|| "-".into(), |l: f64| format!("{:.2}", secs / l));
        last = Some(secs);
        writeln!(
            md,
            "| {level} | {} | {} | {} | {:.4} | {:+.1e} | {:.4} | {:+.1e} | {} | {} | {:.3} ms | {:.1} | {growth} | {} |",
            v.len(),
            3 * f.len() / 2,
            f.len(),
            t.t1,
            t.t[0],
            t.t2[0],
            t.tp[1],
            e(inertia_error(&ours.inertia, &exact.inertia)),
            e(inertia_error(&paper.inertia, &exact.inertia)),
            secs * 1e3,
            secs * 1e9 / f.len() as f64,
            paper_times[level as usize - 1]
        )
        .ok();
        eprintln!("sphere level {level} done");
    }
    writeln!(md, "\nLinear time means a growth of 4 per refinement.").ok();

    // 3. Stiff and extreme cases, every variant.
    writeln!(md, "\n## 3. Stiff and extreme cases\n").ok();
    writeln!(md, "Relative errors against exact rationals: mass, COM (distance over the body's size), central inertia (Frobenius), smallest principal moment (against the exact tensor's Rayleigh quotient). The floor is the exact central tensor rounded to f64. Binary STL and glTF store positions as f32 by the format (read exactly as f64, so the stored mesh is integrated at the floor): the rows \"ours on f32-rounded input\" show how far that one rounding moves the result from the designed f64 shape.\n").ok();
    let sphere = icosphere(6);
    let cubem = box_mesh([1.0, 1.0, 1.0]);
    let plate = box_mesh([1.0, 1.0, 1e-6]);
    let needle = box_mesh([1e-6, 1e-6, 1.0]);
    let id = rotation([0.0; 3]);
    let rot = rotation([0.7, -1.3, 2.9]);
    let far = [1e4, -2e4, 3e4];
    let cases: Vec<(&str, Mesh, f64)> = vec![
        ("cube 1e3 away", transform(&cubem, 1.0, &id, [1e3; 3]), 1.0),
        (
            "cube 1e6 away",
            transform(&cubem, 1.0, &id, [1e6, -1e6, 1e6]),
            1.0,
        ),
        (
            "cube 1e8 away",
            transform(&cubem, 1.0, &id, [1e8, 1e8, -1e8]),
            1.0,
        ),
        (
            "sphere 1e8 away",
            transform(&sphere, 1.0, &id, [1e8; 3]),
            2.0,
        ),
        (
            "sphere scaled 1e-6",
            transform(&sphere, 1e-6, &id, [0.0; 3]),
            2e-6,
        ),
        (
            "sphere scaled 1e6",
            transform(&sphere, 1e6, &id, [0.0; 3]),
            2e6,
        ),
        (
            "sphere rotated, 1e4 away",
            transform(&sphere, 1.0, &rot, far),
            2.0,
        ),
        (
            "plate 1×1×1e-6 rotated, 1e4 away",
            transform(&plate, 1.0, &rot, far),
            1.4,
        ),
        (
            "needle 1e-6×1e-6×1 rotated, 1e4 away",
            transform(&needle, 1.0, &rot, far),
            1.0,
        ),
    ];
    // Mirrored (a file loaded with scale "-1 1 1") and inside-out meshes: the raw kernels see inward
    // winding (negative volume); the mesh layer reverses or flips the faces. Reference: the outward solid.
    let moved_cube = transform(&cubem, 1.0, &rot, [3.0, -1.0, 2.0]);
    let mirrored_raw: Mesh = (
        moved_cube.0.iter().map(|p| [-p[0], p[1], p[2]]).collect(),
        moved_cube.1.clone(),
    );
    let mirrored_outward: Mesh = (
        mirrored_raw.0.clone(),
        mirrored_raw.1.iter().map(|t| [t[0], t[2], t[1]]).collect(),
    );
    let inside_out: Mesh = (
        moved_cube.0.clone(),
        moved_cube.1.iter().map(|t| [t[0], t[2], t[1]]).collect(),
    );
    let repair_cases: Vec<(&str, Mesh, Mesh)> = vec![
        (
            "cube mirrored by scale (−1, 1, 1)",
            mirrored_raw,
            mirrored_outward,
        ),
        ("cube inside-out", inside_out, moved_cube.clone()),
    ];
    writeln!(md, "| case | variant | mass | COM | inertia | smallest moment | floor |\n|---|---|---|---|---|---|---|").ok();
    for (name, (v, f), size) in &cases {
        let exact = exact_mass(&exact_integrals(v, f));
        let small = smallest_exact(&exact);
        let floor = floor_error(&exact.inertia);
        let polys = Polygons::from_triangles(f);
        for (variant, vname) in VARIANTS {
            let mp = MassProperties::from_integrals(&integrate(variant, v, f, &polys), 1.0);
            let er = errors(&mp, &exact, *size, small);
            writeln!(
                md,
                "| {name} | {vname} | {} | {} | {} | {} | {} |",
                e(er.mass),
                e(er.com),
                e(er.inertia),
                e(er.smallest),
                e(floor)
            )
            .ok();
        }
        eprintln!("{name} done");
    }
    for (name, raw, outward) in &repair_cases {
        let exact = exact_mass(&exact_integrals(&outward.0, &outward.1));
        let small = smallest_exact(&exact);
        let floor = floor_error(&exact.inertia);
        let polys = Polygons::from_triangles(&raw.1);
        for (variant, vname) in VARIANTS {
            let mp =
                MassProperties::from_integrals(&integrate(variant, &raw.0, &raw.1, &polys), 1.0);
            let er = errors(&mp, &exact, 1.7, small);
            writeln!(
                md,
                "| {name} | {vname}, raw winding | {} | {} | {} | {} | {} |",
                e(er.mass),
                e(er.com),
                e(er.inertia),
                e(er.smallest),
                e(floor)
            )
            .ok();
        }
        // Through the mesh layer, as urdf-inertia loads it.
        let path = std::path::Path::new("case.stl");
        let solid = if name.contains("mirrored") {
            // The file holds the unmirrored cube; the URDF scale mirrors it.
            let file = urdf_inertia::mesh::RawMesh {
                vertices: moved_cube.0.clone(),
                faces: Polygons::from_triangles(&moved_cube.1),
                ..Default::default()
            };
            urdf_inertia::mesh::solid_from_raw(
                &file,
                [-1.0, 1.0, 1.0],
                path,
                HealthOptions::default(),
            )
        } else {
            let mesh = urdf_inertia::mesh::RawMesh {
                vertices: raw.0.clone(),
                faces: polys.clone(),
                ..Default::default()
            };
            urdf_inertia::mesh::health::make_solid(&mesh, path, HealthOptions::default())
        }
        .expect("solid");
        let er = errors(&solid.unit, &exact, 1.7, small);
        writeln!(
            md,
            "| {name} | ours through the mesh layer ({}) | {} | {} | {} | {} | {} |",
            solid.rung.name(),
            e(er.mass),
            e(er.com),
            e(er.inertia),
            e(er.smallest),
            e(floor)
        )
        .ok();
    }

    // Peers in the same run: parry3d-f64 (a dependency already, for convex hulls).
    writeln!(md, "\n### Peers in the same run\n").ok();
    let peers = python_peers(&cases);
    let peer_names: Vec<String> = peers.as_ref().map(|p| p.0.clone()).unwrap_or_default();
    writeln!(
        md,
        "parry3d-f64 0.31 (`MassProperties::from_trimesh`), and {} on the same stored meshes, each timed for one computation of the mass properties (median). Relative Frobenius error of the central inertia against exact rationals; time in ns per face.\n",
        if peer_names.is_empty() { "no Python peers (set `PEERS_PYTHON` to an interpreter with coal and trimesh)".to_string() } else { peer_names.join(" and ") }
    )
    .ok();
    let mut header = String::from("| case | ours | parry3d-f64 |");
    let mut rule = String::from("|---|---|---|");
    for p in &peer_names {
        let _ = write!(header, " {p} |");
        rule += "---|";
    }
    header += " ours ns/face | parry3d-f64 ns/face |";
    rule += "---|---|";
    for p in &peer_names {
        let _ = write!(header, " {p} ns/face |");
        rule += "---|";
    }
    writeln!(md, "{header}\n{rule}").ok();
    for (ci, (name, (v, f), _)) in cases.iter().enumerate() {
        let exact = exact_mass(&exact_integrals(v, f));
        let pv: Vec<parry3d_f64::math::Vector> = v
            .iter()
            .map(|p| parry3d_f64::math::Vector::new(p[0], p[1], p[2]))
            .collect();
        let pm = parry3d_f64::mass_properties::MassProperties::from_trimesh(1.0, &pv, f);
        let m = pm.reconstruct_inertia_matrix();
        let pi = [0, 1, 2].map(|i| [0, 1, 2].map(|j| m.col(j)[i]));
        let polys = Polygons::from_triangles(f);
        let ours = MassProperties::from_integrals(&integrate(Variant::Ours, v, f, &polys), 1.0);
        let t_parry = time(0.3, || {
            parry3d_f64::mass_properties::MassProperties::from_trimesh(1.0, &pv, f)
        });
        let t_ours = time(0.3, || integrate(Variant::Ours, v, f, &polys));
        let finite = pi.iter().flatten().all(|x| x.is_finite());
        let pe = if finite {
            inertia_error(&pi, &exact.inertia)
        } else {
            f64::INFINITY
        };
        let per_face = |t: f64| t * 1e9 / f.len() as f64;
        let mut row = format!(
            "| {name} | {} | {} |",
            e(inertia_error(&ours.inertia, &exact.inertia)),
            e(pe)
        );
        let mut times = format!(" {:.1} | {:.1} |", per_face(t_ours), per_face(t_parry));
        if let Some((tools, results)) = &peers {
            for tool in tools {
                match results.get(&(ci, tool.clone())) {
                    Some(Ok((inertia, secs))) => {
                        let finite = inertia.iter().flatten().all(|x| x.is_finite());
                        let _ = write!(
                            row,
                            " {} |",
                            if finite {
                                e(inertia_error(inertia, &exact.inertia))
                            } else {
                                "inf".into()
                            }
                        );
                        let _ = write!(times, " {:.1} |", per_face(*secs));
                    }
                    Some(Err(msg)) => {
                        let _ = write!(
                            row,
                            " fails: {} |",
                            msg.split_whitespace()
                                .collect::<Vec<_>>()
                                .join(" ")
                                .chars()
                                .take(40)
                                .collect::<String>()
                        );
                        times += " - |";
                    }
                    None => {
                        row += " - |";
                        times += " - |";
                    }
                }
            }
        }
        writeln!(md, "{row}{times}").ok();
    }

    // 4. Error against run time, on a sphere moved 100 radii away, every variant and size.
    for level in 3..=9u32 {
        let (v, f) = transform(&icosphere(level), 1.0, &id, [100.0, -50.0, 30.0]);
        let polys = Polygons::from_triangles(&f);
        let exact = exact_mass(&exact_integrals(&v, &f));
        for (vi, (variant, _)) in VARIANTS.iter().enumerate() {
            let secs = time(if level > 6 { 1.0 } else { 0.3 }, || {
                integrate(*variant, &v, &f, &polys)
            });
            let mp = MassProperties::from_integrals(&integrate(*variant, &v, &f, &polys), 1.0);
            plot.push((
                vi,
                secs * 1e9 / f.len() as f64,
                inertia_error(&mp.inertia, &exact.inertia),
            ));
            plot_faces.push(f.len());
        }
        eprintln!("plot level {level} done");
    }
    writeln!(md, "\n## 4. Error against run time\n").ok();
    writeln!(md, "![error against time](accuracy.svg)\n").ok();
    writeln!(md, "Sphere series (levels 3–9, 320 to 1.3 M faces) moved 100 radii away from the origin. x: ns per face; y: relative Frobenius error of the central inertia against exact rationals on the stored mesh. Two floors are drawn: the physical one, the f64 round-off of the inputs (coordinates near 100 × the size are stored to 2⁻⁵³ × 101 of the size, about 1.1e-14: the stored sphere is only known that well), and the f64 round-off of the result (2⁻⁵³). A kernel below the first line adds no error of its own to what the file already carries. Points at zero error are drawn on the bottom edge.\n").ok();
    writeln!(
        md,
        "| variant | faces | ns/face | error |\n|---|---|---|---|"
    )
    .ok();
    for ((vi, ns, err), faces) in plot.iter().zip(&plot_faces) {
        writeln!(
            md,
            "| {} | {faces} | {:.1} | {} |",
            VARIANTS[*vi].1,
            ns,
            e(*err)
        )
        .ok();
    }
    std::fs::create_dir_all("docs")?;
    std::fs::write("docs/accuracy.svg", svg(&plot))?;

    // 5. Loading, and the corpus end to end.
    writeln!(md, "\n## 5. Loading\n").ok();
    let (v, f) = icosphere(9);
    let bytes = urdf_inertia::mesh::stl::write_binary(b"bench", &v, &f);
    let file = std::env::temp_dir().join(format!("urdf-inertia-bench-{}.stl", std::process::id()));
    std::fs::write(&file, &bytes)?;
    let secs = time(3.0, || {
        urdf_inertia::mesh::read(&file, urdf_inertia::input::DEFAULT_MAX_FILE_SIZE)
            .map_or(0, |m| m.faces.len())
    });
    let _ = std::fs::remove_file(&file);
    writeln!(md, "Binary STL file, {} faces ({:.1} MB), read and parsed (page cache warm): {:.1} ms, {:.0} MB/s, {:.1} M faces/s.", f.len(), bytes.len() as f64 / 1e6, secs * 1e3, bytes.len() as f64 / 1e6 / secs, f.len() as f64 / 1e6 / secs).ok();
    let raw =
        urdf_inertia::mesh::stl::parse(&bytes, std::path::Path::new("bench.stl")).expect("parse");
    let secs = time(3.0, || {
        urdf_inertia::mesh::health::make_solid(
            &raw,
            std::path::Path::new("bench.stl"),
            HealthOptions::default(),
        )
        .map_or(0, |s| s.faces.len())
    });
    writeln!(
        md,
        "Welding, edge analysis and integration of the same mesh: {:.1} ms ({:.0} ns/face).",
        secs * 1e3,
        secs * 1e9 / f.len() as f64
    )
    .ok();
    match std::env::var("EXAMPLE_ROBOT_DATA_SHARE") {
        Ok(share) => corpus(&mut md, std::path::Path::new(&share)),
        Err(_) => {
            writeln!(md, "\nSet `EXAMPLE_ROBOT_DATA_SHARE` to time the example-robot-data corpus end to end.").ok();
        }
    }
    pipeline_section(&mut md)?;
    let share = std::env::var("EXAMPLE_ROBOT_DATA_SHARE").ok();
    ladder::section(&mut md, share.as_deref().map(std::path::Path::new));
    std::fs::write("docs/accuracy.md", md)?;
    println!("wrote docs/accuracy.md and docs/accuracy.svg");
    Ok(())
}

/// Every `.urdf` file below `dir`, sorted.
fn urdfs_under(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut urdfs = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().and_then(|e| e.to_str()) == Some("urdf") {
                urdfs.push(p);
            }
        }
    }
    urdfs.sort();
    urdfs
}

fn corpus(md: &mut String, share: &std::path::Path) {
    use urdf_inertia::density::DensityMap;
    use urdf_inertia::fill::{compute_with, FillOptions, MeshCache};
    use urdf_inertia::urdf::resolve::PackageResolver;
    let robots = share.join("example-robot-data/robots");
    let urdfs = urdfs_under(&robots);
    let resolver = PackageResolver::new().with_packages(&[(
        "example-robot-data".into(),
        share.join("example-robot-data"),
    )]);
    let map = DensityMap::uniform(1000.0);
    writeln!(md, "\n## 6. End to end on example-robot-data\n").ok();
    writeln!(md, "Each URDF filled with a fresh cache, as the command does (the median of three fills by total time): meshes are read and healed in parallel on all cores, largest first, and each link (its overlap estimate) is computed as soon as its own meshes are healed, so the load and heal+integrate columns are CPU time summed over threads; parse, write and total are wall time.\n").ok();
    writeln!(md, "| URDF | links | faces | parse ms | load ms | heal+integrate ms | write ms | total ms | M faces/s |\n|---|---|---|---|---|---|---|---|---|").ok();
    let mut shared = MeshCache::default();
    let mut shared_faces = 0usize;
    let mut sum_total = 0.0;
    for u in &urdfs {
        // The median of three fills by total time (a single run on a shared machine is noisy).
        let fill_once = || {
            let t0 = Instant::now();
            let text = std::fs::read_to_string(u).unwrap_or_default();
            let robot = urdf_inertia::urdf::scan(text, u).ok()?;
            let parse = t0.elapsed().as_secs_f64();
            let mut cache = MeshCache::default();
            let report = compute_with(&robot, &map, &resolver, &FillOptions::default(), &mut cache);
            let t1 = Instant::now();
            let updates: Vec<_> = report
                .links
                .iter()
                .map(urdf_inertia::LinkReport::update)
                .collect();
            let out = urdf_inertia::urdf::write::splice(&robot, &updates, &WriteOptions::default())
                .unwrap_or_default();
            std::hint::black_box(out.len());
            let write = t1.elapsed().as_secs_f64();
            Some((t0.elapsed().as_secs_f64(), parse, write, report, robot))
        };
        let mut runs: Vec<_> = (0..3).filter_map(|_| fill_once()).collect();
        if runs.len() < 3 {
            continue;
        }
        runs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (total, parse, write, report, robot) = runs.swap_remove(1);
        sum_total += total;
        let rel = u.strip_prefix(&robots).unwrap_or(u).display().to_string();
        writeln!(
            md,
            "| {rel} | {} | {} | {:.2} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} |",
            report.links.len(),
            report.faces,
            parse * 1e3,
            report.timing.load.as_secs_f64() * 1e3,
            report.timing.integrate.as_secs_f64() * 1e3,
            write * 1e3,
            total * 1e3,
            report.faces as f64 / total / 1e6
        )
        .ok();
        let r2 = compute_with(
            &robot,
            &map,
            &resolver,
            &FillOptions::default(),
            &mut shared,
        );
        shared_faces += r2.faces;
    }
    writeln!(md, "\nSum of the total column: {:.1} ms.", sum_total * 1e3).ok();
    writeln!(
        md,
        "\nEvery collision mesh of the corpus loaded once (one cache across all {} URDFs): {} files, loading {:.2} s, healing and integration {:.2} s (CPU time).",
        urdfs.len(),
        shared.files(),
        shared.load_time.as_secs_f64(),
        shared.integrate_time.as_secs_f64()
    )
    .ok();
    let _ = shared_faces;
    trimesh_filler(md, share, &urdfs);
}

/// The whole corpus filled by `urdf-inertia fill`, one process per URDF as a user runs it and one
/// process for all (`fill -i` of copies, one mesh cache), against `validation/trimesh_fill.py` (one
/// Python process for all URDFs, so trimesh's import is paid once; a fresh mesh cache per URDF, and
/// one shared cache), in the same run; only with `PEERS_PYTHON` set (it needs trimesh, pinned in
/// validation/trimesh-requirements.txt).
fn trimesh_filler(md: &mut String, share: &std::path::Path, urdfs: &[std::path::PathBuf]) {
    let Ok(python) = std::env::var("PEERS_PYTHON") else {
        return;
    };
    let exe = std::env::current_exe().ok().and_then(|e| {
        let bin = e.parent()?.parent()?.join("urdf-inertia");
        bin.exists().then_some(bin)
    });
    let Some(exe) = exe else {
        writeln!(
            md,
            "\n`cargo build --release` first to compare the whole fill with a trimesh filler."
        )
        .ok();
        return;
    };
    let package = format!(
        "example-robot-data={}",
        share.join("example-robot-data").display()
    );
    let (per_process, per_failed) = median_of_3(|| ours_per_process(&exe, &package, urdfs));
    let (one_process, one_failed) = median_of_3(|| ours_one_process(&exe, &package, urdfs));
    let (Some(fresh), Some(shared)) = (
        trimesh_run(&python, share, false),
        trimesh_run(&python, share, true),
    ) else {
        writeln!(md, "\nThe trimesh filler (validation/trimesh_fill.py) did not run with `{python}`: it needs trimesh (validation/trimesh-requirements.txt).").ok();
        return;
    };
    writeln!(md, "\n### The whole corpus against a trimesh filler\n").ok();
    writeln!(md, "All {} URDFs filled at 1000 kg/m³, same machine, same run. Ours: `urdf-inertia fill` once per URDF (a new process each, as a user runs it, each with its own mesh cache), and `urdf-inertia fill -i` of copies of all of them in one process (as a pre-commit hook passes files; one mesh cache), medians of 3 passes. trimesh {}: validation/trimesh_fill.py, which parses each URDF, loads every collision mesh with its scale and origin (`trimesh.load`), takes the primitives analytically, sums the parts per link and writes the inertials, with no mesh healing; one Python process for all URDFs, so its imports are paid once, with a fresh mesh cache per URDF and (`--shared-cache`) with one cache for all.\n", urdfs.len(), fresh.3).ok();
    writeln!(md, "| filler | whole corpus s | failed |\n|---|---|---|").ok();
    let n = urdfs.len();
    writeln!(
        md,
        "| urdf-inertia fill, {n} processes | {per_process:.2} | {per_failed} URDFs |"
    )
    .ok();
    writeln!(md, "| trimesh filler, fresh cache per URDF (its own clock, imports excluded) | {:.2} | {} parts or URDFs |", fresh.0, fresh.2).ok();
    writeln!(
        md,
        "| trimesh filler, fresh cache per URDF (wall, imports included) | {:.2} | |",
        fresh.1
    )
    .ok();
    writeln!(
        md,
        "| urdf-inertia fill -i, one process for all {n} | {one_process:.2} | exit {one_failed} |"
    )
    .ok();
    writeln!(md, "| trimesh filler, one cache (its own clock, imports excluded) | {:.2} | {} parts or URDFs |", shared.0, shared.2).ok();
    writeln!(
        md,
        "| trimesh filler, one cache (wall, imports included) | {:.2} | |",
        shared.1
    )
    .ok();
    writeln!(md, "\nA process per URDF: urdf-inertia is {:.0}× faster than the trimesh filler's own clock ({:.0}× against its whole process). One process with one cache: {:.0}× ({:.0}×).", fresh.0 / per_process, fresh.1 / per_process, shared.0 / one_process, shared.1 / one_process).ok();
}

/// The median by time of three runs of `f` (seconds, and what failed).
fn median_of_3(f: impl Fn() -> (f64, usize)) -> (f64, usize) {
    let mut runs: Vec<(f64, usize)> = (0..3).map(|_| f()).collect();
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    runs[1]
}

/// `urdf-inertia fill` once per URDF: seconds, and the URDFs that failed.
fn ours_per_process(
    exe: &std::path::Path,
    package: &str,
    urdfs: &[std::path::PathBuf],
) -> (f64, usize) {
    let out = std::env::temp_dir().join(format!("urdf-inertia-erd-{}.urdf", std::process::id()));
    let t0 = Instant::now();
    let failed = urdfs
        .iter()
        .filter(|u| {
            let status = std::process::Command::new(exe)
                .arg("fill")
                .arg(u)
                .args(["--density", "1000", "--package-path", package, "-o"])
                .arg(&out)
                .stderr(std::process::Stdio::null())
                .status();
            !status.is_ok_and(|s| s.success())
        })
        .count();
    let seconds = t0.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&out);
    (seconds, failed)
}

/// `urdf-inertia fill -i` of fresh copies of all URDFs in one process: seconds (the copying not
/// counted), and the exit code (0 when every URDF was filled).
fn ours_one_process(
    exe: &std::path::Path,
    package: &str,
    urdfs: &[std::path::PathBuf],
) -> (f64, usize) {
    let dir = std::env::temp_dir().join(format!("urdf-inertia-erd-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let copies: Vec<std::path::PathBuf> = urdfs
        .iter()
        .enumerate()
        .map(|(i, u)| {
            let copy = dir.join(format!("{i:02}.urdf"));
            let _ = std::fs::copy(u, &copy);
            copy
        })
        .collect();
    let t0 = Instant::now();
    let status = std::process::Command::new(exe)
        .arg("fill")
        .args(&copies)
        .args(["--density", "1000", "--package-path", package, "-i"])
        .stderr(std::process::Stdio::null())
        .status();
    let seconds = t0.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    let code = status.ok().and_then(|s| s.code()).unwrap_or(-1);
    (seconds, usize::try_from(code).unwrap_or(usize::MAX))
}

/// `validation/trimesh_fill.py` on the whole corpus: its own seconds, the wall seconds, its failures
/// and trimesh's version.
fn trimesh_run(
    python: &str,
    share: &std::path::Path,
    shared_cache: bool,
) -> Option<(f64, f64, usize, String)> {
    let t0 = Instant::now();
    let mut cmd = std::process::Command::new(python);
    cmd.arg("validation/trimesh_fill.py")
        .arg("--share")
        .arg(share);
    if shared_cache {
        cmd.arg("--shared-cache");
    }
    let run = cmd.output().ok().filter(|o| o.status.success())?;
    let wall = t0.elapsed().as_secs_f64();
    let json = serde_json::from_slice::<serde_json::Value>(&run.stdout).ok()?;
    Some((
        json["seconds"].as_f64().unwrap_or(f64::NAN),
        wall,
        json["failures"].as_array().map_or(0, Vec::len),
        json["trimesh"].as_str().unwrap_or("?").to_string(),
    ))
}

type PeerResults = std::collections::HashMap<(usize, String), Result<([[f64; 3]; 3], f64), String>>;

/// Runs validation/peers.py (coal, trimesh) on the cases with the interpreter in `PEERS_PYTHON`.
fn python_peers(cases: &[(&str, Mesh, f64)]) -> Option<(Vec<String>, PeerResults)> {
    let python = std::env::var("PEERS_PYTHON").ok()?;
    let dir = std::env::temp_dir().join(format!("urdf-inertia-peers-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    for (i, (_, (v, f), _)) in cases.iter().enumerate() {
        let vb: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let fb: Vec<u8> = f.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        std::fs::write(dir.join(format!("case{i:02}.v")), vb).ok()?;
        std::fs::write(dir.join(format!("case{i:02}.f")), fb).ok()?;
    }
    let out = std::process::Command::new(python)
        .arg("validation/peers.py")
        .arg(&dir)
        .output()
        .ok()?;
    let _ = std::fs::remove_dir_all(&dir);
    if !out.status.success() {
        eprintln!("peers.py failed: {}", String::from_utf8_lossy(&out.stderr));
        return None;
    }
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).ok()?;
    let mut tools: Vec<String> = Vec::new();
    let mut results = PeerResults::new();
    for r in v["results"].as_array()? {
        let case: usize = r["case"]
            .as_str()?
            .trim_start_matches("case")
            .parse()
            .ok()?;
        let version = v["versions"][r["tool"].as_str()?].as_str().unwrap_or("");
        let tool = format!("{} {version}", r["tool"].as_str()?)
            .trim()
            .to_string();
        if !tools.contains(&tool) {
            tools.push(tool.clone());
        }
        let entry = match (r.get("error"), r.get("inertia")) {
            (Some(err), _) => Err(err.as_str().unwrap_or("error").to_string()),
            (None, Some(m)) => {
                let mut i = [[0.0; 3]; 3];
                for (a, row) in m.as_array()?.iter().enumerate() {
                    for (b, x) in row.as_array()?.iter().enumerate() {
                        i[a][b] = x.as_f64().unwrap_or(f64::NAN);
                    }
                }
                Ok((i, r["seconds"].as_f64().unwrap_or(f64::NAN)))
            }
            _ => continue,
        };
        results.insert((case, tool), entry);
    }
    Some((tools, results))
}

/// A log-log scatter plot, one colour per variant, with the f64 floor as a dashed line.
fn svg(points: &[(usize, f64, f64)]) -> String {
    let (w, h, l, b, t, r) = (760.0, 460.0, 70.0, 50.0, 20.0, 250.0);
    let xs: Vec<f64> = points.iter().map(|p| p.1.log10()).collect();
    let (x0, x1) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min).floor(),
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil(),
    );
    let (y0, y1) = (-18.0f64, 0.0f64);
    let px = |x: f64| l + (x.log10() - x0) / (x1 - x0) * (w - l - r);
    let py = |y: f64| {
        let ly = if y > 0.0 { y.log10().clamp(y0, y1) } else { y0 };
        t + (y1 - ly) / (y1 - y0) * (h - t - b)
    };
    let colours = ["#d62728", "#ff7f0e", "#2ca02c", "#1f77b4", "#9467bd"];
    let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
    for k in (y0 as i32)..=(y1 as i32) {
        let y = py(10f64.powi(k));
        if k % 2 == 0 {
            let _ = writeln!(s, "<line x1=\"{l}\" x2=\"{}\" y1=\"{y}\" y2=\"{y}\" stroke=\"#eee\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{k}</text>", w - r, l - 5.0, y + 4.0);
        }
    }
    for k in (x0 as i32)..=(x1 as i32) {
        let x = px(10f64.powi(k));
        let _ = writeln!(s, "<line x1=\"{x}\" x2=\"{x}\" y1=\"{t}\" y2=\"{}\" stroke=\"#eee\"/><text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">{}</text>", h - b, h - b + 16.0, 10f64.powi(k));
    }
    for (value, label) in [
        (2f64.powi(-53), "f64 round-off of the result, 2^-53"),
        (101.0 * 2f64.powi(-53), "f64 round-off of the inputs"),
    ] {
        let y = py(value);
        let _ = writeln!(s, "<line x1=\"{l}\" x2=\"{}\" y1=\"{y}\" y2=\"{y}\" stroke=\"black\" stroke-dasharray=\"5,4\"/><text x=\"{}\" y=\"{}\">{label}</text>", w - r, w - r + 5.0, y + 4.0);
    }
    for (vi, ns, err) in points {
        let _ = writeln!(
            s,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"{}\" fill-opacity=\"0.8\"/>",
            px(*ns),
            py(*err),
            colours[*vi]
        );
    }
    for (vi, (_, name)) in VARIANTS.iter().enumerate() {
        let y = t + 20.0 + 20.0 * vi as f64;
        let _ =
            writeln!(s,
            "<circle cx=\"{}\" cy=\"{y}\" r=\"5\" fill=\"{}\"/><text x=\"{}\" y=\"{}\">{}</text>",
            w - r + 15.0,
            colours[vi],
            w - r + 25.0,
            y + 4.0,
            name.replace('&', "and")
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">ns per face</text>",
        (l + w - r) / 2.0,
        h - 10.0
    );
    let _ = write!(s, "<text x=\"15\" y=\"{}\" transform=\"rotate(-90 15 {})\" text-anchor=\"middle\">relative error, central inertia</text>\n</svg>\n", (t + h - b) / 2.0, (t + h - b) / 2.0);
    s
}

/// The 1.3 M-face sphere of the whole-process measurement (icosphere `level` 9), as binary STL.
fn pipeline_stl(level: u32) -> (Vec<u8>, usize) {
    pipeline_bytes(icosphere(level))
}

/// A torus of 2k × k quads (4k² faces), 0.14 m across and away from the origin, as binary STL.
fn pipeline_torus(k: u32) -> (Vec<u8>, usize) {
    pipeline_bytes(common::wild::torus(1.0, 0.4, 2 * k, k))
}

/// A mesh shrunk to a tenth and moved off the origin, as real parts are: binary STL bytes and faces.
fn pipeline_bytes((v, f): Mesh) -> (Vec<u8>, usize) {
    let v: Vec<[f64; 3]> = v
        .iter()
        .map(|p| [0.1 * p[0] + 0.3, 0.1 * p[1] - 0.1, 0.1 * p[2] + 0.05])
        .collect();
    (
        urdf_inertia::mesh::stl::write_binary(b"pipeline", &v, &f),
        f.len(),
    )
}

/// The mesh pipeline per stage and size on one core, the whole `urdf-inertia mesh` process on 1 and
/// 2 threads with its peak memory, and coal and trimesh loading and integrating the same file.
#[allow(clippy::too_many_lines)] // one report section written top to bottom, table after table
fn pipeline_section(md: &mut String) -> std::io::Result<()> {
    use std::path::Path;
    use urdf_inertia::mesh::{health, solid_from_owned, solid_from_raw, stl};
    let path = Path::new("pipeline.stl");
    writeln!(md, "\n## The mesh pipeline per face\n").ok();
    writeln!(md, "Binary STL tori (2k × k quads split in two, 1 k to 10 M faces) read from memory and turned into a solid on one core (a one-thread rayon pool): medians of repeated runs. read: bytes to a mesh, corners welded as they are read (16 Ki-face chunks welded on their own, then joined); edges: the proof that the surface is closed and consistently wound, with its components; integrate: one evaluation of the ten integrals (with the bound on its round-off added up face by face in the same pass; the value's sign also decides inversion); heal: everything after reading, timed on its own from the read mesh (the proof of closure, the integration, the volume check, the error estimate, the solid's own passes; from a borrowed mesh, as the cache heals a file used at several scales, so its arrays are copied once); end to end: read and heal of the file's bytes, as `urdf-inertia mesh` does after reading the file, also on two threads. A welded STL needs no second weld. Linear time is a flat column.\n").ok();
    writeln!(md, "| faces | file MB | read | edges | integrate | heal | end to end | end to end, 2 threads |\n|---|---|---|---|---|---|---|---|").ok();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("pool");
    let mut e2e_per_face: Vec<(usize, f64)> = Vec::new();
    for k in [16u32, 32, 64, 128, 256, 512, 1024, 1600] {
        let (bytes, n) = pipeline_torus(k);
        let budget = if k >= 256 { 3.0 } else { 0.5 };
        let per = |secs: f64| secs * 1e9 / n as f64;
        let raw = stl::parse(&bytes, path).expect("parse");
        let e2e_once = || {
            stl::parse(&bytes, path)
                .and_then(|m| solid_from_owned(m, [1.0; 3], path, HealthOptions::default()))
                .map(|s| s.unit.mass)
        };
        let (read, edges, integrate, heal, e2e) = one.install(|| {
            let read = time(budget, || stl::parse(&bytes, path).map(|m| m.faces.len()));
            let edges = time(budget, || {
                health::closed_consistent(&raw.faces).map(|c| c.1)
            });
            let integrate = time(budget, || {
                volume_integrals(&raw.vertices, &raw.faces, &IntegrationOptions::accurate())
            });
            let heal = time(budget, || {
                solid_from_raw(&raw, [1.0; 3], path, HealthOptions::default()).map(|s| s.unit.mass)
            });
            (read, edges, integrate, heal, time(budget, e2e_once))
        });
        let e2e2 = two.install(|| time(budget, e2e_once));
        writeln!(
            md,
            "| {n} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
            bytes.len() as f64 / 1e6,
            per(read),
            per(edges),
            per(integrate),
            per(heal),
            per(e2e),
            per(e2e2)
        )
        .ok();
        e2e_per_face.push((n, per(e2e)));
        eprintln!("pipeline torus {n} faces done");
    }
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into());
    if let (Some(first), Some(last)) = (e2e_per_face.first(), e2e_per_face.last()) {
        let worst = e2e_per_face.iter().map(|e| e.1).fold(0.0, f64::max);
        let best = e2e_per_face
            .iter()
            .map(|e| e.1)
            .fold(f64::INFINITY, f64::min);
        writeln!(md, "\nAll figures in ns per face. End to end, from {} to {} faces the cost per face changes {:.2}× (largest over smallest per-face cost across sizes {:.2}×). Load average at the end of these runs: {load} (timings on a shared machine are noisy; callgrind instruction counts in the commit messages are not).", first.0, last.0, last.1 / first.1, worst / best).ok();
    }

    // The whole process on the 1.3 M-face file, and the peers on the same file.
    let (bytes, n) = pipeline_stl(9);
    let file =
        std::env::temp_dir().join(format!("urdf-inertia-pipeline-{}.stl", std::process::id()));
    std::fs::write(&file, &bytes)?;
    let exe = std::env::current_exe()?
        .parent()
        .and_then(|p| p.parent())
        .map(|p| p.join("urdf-inertia"));
    writeln!(
        md,
        "\n### `urdf-inertia mesh` on a {n}-face binary STL ({:.1} MB)\n",
        bytes.len() as f64 / 1e6
    )
    .ok();
    match exe.filter(|e| e.exists()) {
        Some(exe) if Path::new("/usr/bin/time").exists() => {
            writeln!(md, "The whole process (start, read the file, heal, integrate, print JSON), page cache warm: wall time (this program's clock around the process), CPU time (user + system) and peak resident memory from `/usr/bin/time -v`; the run with the median wall time of 9, one and two threads interleaved, and the fastest of the 9 (on a shared machine noise only adds time).\n").ok();
            writeln!(md, "| threads | wall s | ns/face | fastest wall s | fastest ns/face | CPU s | peak MB | peak / file size |\n|---|---|---|---|---|---|---|---|").ok();
            let mut runs: [Vec<(f64, f64, f64)>; 2] = [Vec::new(), Vec::new()];
            for _ in 0..9 {
                for threads in [1, 2] {
                    let t0 = Instant::now();
                    let out = std::process::Command::new("/usr/bin/time")
                        .arg("-v")
                        .arg(&exe)
                        .args(["mesh", "--format", "json"])
                        .arg(&file)
                        .env("RAYON_NUM_THREADS", threads.to_string())
                        .output()?;
                    let err = String::from_utf8_lossy(&out.stderr);
                    let field = |name: &str| {
                        err.lines()
                            .find_map(|l| l.trim().strip_prefix(name))
                            .map(|v| v.trim().to_string())
                    };
                    let wall = t0.elapsed().as_secs_f64();
                    let seconds = |name: &str| {
                        field(name)
                            .and_then(|t| t.parse::<f64>().ok())
                            .unwrap_or(f64::NAN)
                    };
                    let cpu = seconds("User time (seconds):") + seconds("System time (seconds):");
                    let kb = seconds("Maximum resident set size (kbytes):");
                    runs[threads - 1].push((wall, cpu, kb * 1024.0));
                }
            }
            for (threads, runs) in [1, 2].into_iter().zip(&mut runs) {
                runs.sort_by(|a, b| a.0.total_cmp(&b.0));
                let (wall, cpu, peak) = runs[runs.len() / 2];
                let fastest = runs[0].0;
                writeln!(
                    md,
                    "| {threads} | {wall:.3} | {:.0} | {fastest:.3} | {:.0} | {cpu:.2} | {:.0} | {:.2} |",
                    wall * 1e9 / n as f64,
                    fastest * 1e9 / n as f64,
                    peak / 1e6,
                    peak / bytes.len() as f64
                )
                .ok();
            }
        }
        _ => {
            writeln!(md, "Build the binary (`cargo build --release`) and install GNU time to measure the whole process.").ok();
        }
    }
    if let Ok(python) = std::env::var("PEERS_PYTHON") {
        // Exact rationals of the stored (f32) mesh, and ours through the pipeline.
        let raw = urdf_inertia::mesh::stl::parse(&bytes, path).expect("parse");
        let tris: Vec<[u32; 3]> = raw.faces.iter().map(|f| [f[0], f[1], f[2]]).collect();
        let exact = exact_mass(&exact_integrals(&raw.vertices, &tris));
        let t0 = Instant::now();
        let ours = urdf_inertia::mesh::load_solid(
            &file,
            [1.0; 3],
            urdf_inertia::mesh::LoadOptions::default(),
        )
        .expect("solid");
        let ours_secs = t0.elapsed().as_secs_f64();
        let script = r#"
import json, sys, time
import numpy as np
path = sys.argv[1]
out = {}
try:
    import coal
    t = time.perf_counter(); m = coal.MeshLoader().load(path); load = time.perf_counter() - t
    t = time.perf_counter(); m.computeVolume(); m.computeCOM(); i = m.computeMomentofInertiaRelatedToCOM(); comp = time.perf_counter() - t
    out["coal " + coal.__version__] = {"load": load, "compute": comp, "inertia": np.asarray(i).tolist()}
except Exception as e:
    out["coal"] = {"error": str(e)}
try:
    import trimesh
    t = time.perf_counter(); m = trimesh.load(path, force="mesh"); load = time.perf_counter() - t
    t = time.perf_counter(); mp = trimesh.triangles.mass_properties(m.triangles, density=1.0, skip_inertia=False); comp = time.perf_counter() - t
    out["trimesh " + trimesh.__version__] = {"load": load, "compute": comp, "inertia": np.asarray(mp["inertia"]).tolist()}
except Exception as e:
    out["trimesh"] = {"error": str(e)}
print(json.dumps(out))
"#;
        let out = std::process::Command::new(python)
            .args(["-c", script])
            .arg(&file)
            .output()?;
        writeln!(md, "\nPeers on the same file in the same run, loading included (one run each; coal loads through assimp and builds its BVH). Error: relative Frobenius error of the central inertia against exact rationals on the stored mesh.\n").ok();
        writeln!(
            md,
            "| tool | load s | mass properties s | total ns/face | error |\n|---|---|---|---|---|"
        )
        .ok();
        writeln!(
            md,
            "| urdf-inertia (load_solid, all threads) | - | - | {:.0} | {} |",
            ours_secs * 1e9 / n as f64,
            e(inertia_error(&ours.unit.inertia, &exact.inertia))
        )
        .ok();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
        if let Some(tools) = v.as_object() {
            for (tool, r) in tools {
                if let Some(err) = r.get("error") {
                    writeln!(
                        md,
                        "| {tool} | fails: {} | | | |",
                        err.as_str().unwrap_or("?")
                    )
                    .ok();
                    continue;
                }
                let load = r["load"].as_f64().unwrap_or(f64::NAN);
                let comp = r["compute"].as_f64().unwrap_or(f64::NAN);
                let mut i = [[f64::NAN; 3]; 3];
                if let Some(rows) = r["inertia"].as_array() {
                    for (a, row) in rows.iter().enumerate().take(3) {
                        for (b, x) in row.as_array().into_iter().flatten().enumerate().take(3) {
                            i[a][b] = x.as_f64().unwrap_or(f64::NAN);
                        }
                    }
                }
                let err = if i.iter().flatten().all(|x| x.is_finite()) {
                    e(inertia_error(&i, &exact.inertia))
                } else {
                    "inf".into()
                };
                writeln!(
                    md,
                    "| {tool} | {load:.2} | {comp:.3} | {:.0} | {err} |",
                    (load + comp) * 1e9 / n as f64
                )
                .ok();
            }
        }
    }
    let _ = std::fs::remove_file(&file);
    Ok(())
}
