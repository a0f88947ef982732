//! `urdf-inertia mesh FILE`: the mass properties of one mesh, with its health.

use super::args::{Format, MeshArgs};
use super::policy::Policy;
use super::ExitStatus;
use urdf_inertia::diagnostic::{Code, Diagnostic, Provenance, Severity};
use urdf_inertia::report::{MeshErrorRecord, MeshFailure, MeshOutput, SCHEMA_VERSION};
use urdf_inertia::text::{round_significant, shortest, within, Digits};
use urdf_inertia::MeshErrorKind;
use urdf_inertia::{LoadOptions, Solid};
use urdf_inertia::{MassProperties, Principal};

pub fn run(args: &MeshArgs) -> ExitStatus {
    let scale = match args.scale.as_deref() {
        Some([x, y, z]) => [*x, *y, *z],
        _ => [1.0; 3],
    };
    if !options_valid(args) {
        return ExitStatus::Error;
    }
    // The report is the mesh's whole health: its notes print too, unless --quiet.
    let policy = match Policy::new(&args.diagnostics, true, Some(&args.file)) {
        Ok((policy, _)) => policy,
        Err(e) => {
            errln!("error: {e}");
            return ExitStatus::Error;
        }
    };
    let start = std::time::Instant::now();
    let options = LoadOptions::default()
        .strict(args.strict)
        .open_mesh(super::args::OpenMesh::model(args.open_mesh))
        .max_file_size(super::max_file_size());
    let solid = match urdf_inertia::load_solid(&args.file, scale, options) {
        Ok(s) => s,
        Err(e) => {
            // An open mesh with no solid to trust has a code of its own; reading errors have none.
            match e.kind {
                MeshErrorKind::NoSolid(_) => errln!("error[{}]: {e}", Code::MeshNoSolid),
                _ => errln!("error: {e}"),
            }
            print_failure(args, scale, MeshErrorRecord::from_mesh_error(&e));
            return ExitStatus::Error;
        }
    };
    let volume = solid.unit.mass;
    let density = match (args.density, args.mass) {
        (Some(d), _) => d,
        (None, Some(m)) => m / volume,
        (None, None) => 1.0,
    };
    let mp = solid.unit.scaled(density);
    if let Some(why) = urdf_inertia::unrepresentable(&mp) {
        errln!("error: {}: {why}", args.file.display());
        print_failure(args, scale, MeshErrorRecord::unrepresentable(&why));
        return ExitStatus::Error;
    }
    let diagnostics = diagnostics(&solid, scale, &policy);
    // Text shows what the policy shows (with --quiet, errors only); JSON carries them all.
    let shown: Vec<Diagnostic> = diagnostics
        .iter()
        .filter(|d| policy.shows(d))
        .cloned()
        .collect();
    for d in shown.iter().filter(|d| d.code == Code::MeshTooLarge) {
        errln!("{}: {}: {}", d.head(), args.file.display(), d.message);
    }
    let out = rounded(args, &solid, volume, density, &mp);
    let elapsed = start.elapsed();
    match args.format {
        Format::Json => print_json(args, scale, &solid, &out, &diagnostics),
        Format::Text => print_text(args, scale, &solid, &out, elapsed, &shown),
    }
    if diagnostics.iter().any(|d| d.severity == Severity::Error) {
        // A warning made an error (--warn-as-error): the numbers are shown, the status says so.
        errln!(
            "error: {}: a warning was made an error (--warn-as-error)",
            args.file.display()
        );
        return ExitStatus::Error;
    }
    ExitStatus::Success
}

/// The mesh's diagnostics as the policy has them, as `fill` has a part's: its health and a part
/// over 10 m across (UI106), repairs whose bound is below `--note-below` as notes, then `--ignore`
/// and `--warn-as-error`.
fn diagnostics(solid: &Solid, scale: [f64; 3], policy: &Policy) -> Vec<Diagnostic> {
    let mut ds = urdf_inertia::diagnostic::mesh_health(solid);
    if let Some(m) = solid.millimetre_slip(scale) {
        ds.push(Diagnostic::new(Code::MeshTooLarge, m));
    }
    if solid.error_estimate < policy.note_below {
        for d in &mut ds {
            if matches!(d.code, Code::MeshRepaired | Code::MeshFacesDropped) {
                d.severity = Severity::Note;
            }
        }
    }
    policy.apply_all(&mut ds);
    ds
}

/// Whether `--density` and `--mass`, if given, are positive numbers (an error is printed if not).
fn options_valid(args: &MeshArgs) -> bool {
    for (name, v) in [("--density", args.density), ("--mass", args.mass)] {
        if let Some(v) = v {
            if !(v > 0.0 && v.is_finite()) {
                errln!("error: {name} {v} must be a positive number");
                return false;
            }
        }
    }
    true
}

/// The numbers `mesh` prints, rounded.
struct Rounded {
    volume: f64,
    density: f64,
    mp: MassProperties,
    pr: Principal,
}

/// Rounds the results within the solid's own error estimate (see `text`), like every other number;
/// with `--digits full` every bit, with N digits to N significant digits.
fn rounded(
    args: &MeshArgs,
    solid: &Solid,
    volume: f64,
    density: f64,
    mp: &MassProperties,
) -> Rounded {
    let round = |x: f64, delta: f64| match args.digits {
        Digits::Auto => within(x, delta),
        Digits::Full => x,
        Digits::Fixed(n) => round_significant(x, n),
    };
    let err = urdf_inertia::text::rounding_tolerance(solid.error_estimate);
    let volume = round(volume, err * volume);
    let length = (mp.com.iter()).fold(solid.largest_coordinate(), |m, x| m.max(x.abs()));
    let pr = mp.principal();
    let largest = pr.moments[2].abs();
    let mp = MassProperties::new(
        round(mp.mass, err * mp.mass),
        mp.com.map(|x| round(x, err * length)),
        mp.inertia.map(|r| r.map(|x| round(x, err * largest))),
    );
    let mut pr = pr;
    pr.moments = pr.moments.map(|x| round(x, err * largest));
    Rounded {
        volume,
        density,
        mp,
        pr,
    }
}

/// `--format json`: one object with the results, the solid's health and its diagnostics.
/// With `--format json`, the document of a mesh that gave no solid (the error is on stderr too).
fn print_failure(args: &MeshArgs, scale: [f64; 3], error: MeshErrorRecord) {
    if !matches!(args.format, Format::Json) {
        return;
    }
    let document = MeshFailure {
        schema_version: SCHEMA_VERSION,
        file: args.file.display().to_string(),
        scale,
        error,
    };
    super::summary::print_json(&document);
}

fn print_json(
    args: &MeshArgs,
    scale: [f64; 3],
    solid: &Solid,
    out: &Rounded,
    diagnostics: &[Diagnostic],
) {
    let Rounded {
        volume,
        density,
        ref mp,
        ref pr,
    } = *out;
    let of = |s: Severity| {
        diagnostics
            .iter()
            .filter(|d| d.severity == s)
            .cloned()
            .collect::<Vec<_>>()
    };
    let document = MeshOutput {
        schema_version: SCHEMA_VERSION,
        file: args.file.display().to_string(),
        scale,
        volume,
        density,
        mass: mp.mass,
        center_of_mass: mp.com,
        inertia: mp.inertia,
        principal_moments: pr.moments,
        principal_axes: [0, 1, 2].map(|c| [0, 1, 2].map(|r| pr.axes[r][c])),
        provenance: Provenance::Mesh(solid.rung.clone()),
        faces: solid.faces.len(),
        faces_read: solid.faces_read,
        vertices: solid.vertices.len(),
        error_estimate: solid.error_estimate,
        error_round_off: solid.error.round_off,
        error_model: solid.error.model,
        error_model_source: solid.error.source.name().to_string(),
        error_center_of_mass: solid.error.com,
        errors: of(Severity::Error),
        warnings: of(Severity::Warning),
        notes: of(Severity::Note),
    };
    super::summary::print_json(&document);
}

/// `--format text`: the results one per line, for people.
fn print_text(
    args: &MeshArgs,
    scale: [f64; 3],
    solid: &Solid,
    out: &Rounded,
    elapsed: std::time::Duration,
    diagnostics: &[Diagnostic],
) {
    let Rounded {
        volume,
        density,
        ref mp,
        ref pr,
    } = *out;
    outln!(
        "{}  (scale {} {} {})",
        args.file.display(),
        scale[0],
        scale[1],
        scale[2]
    );
    outln!(
        "  health            {} ({} faces read; the solid has {} faces, {} vertices)",
        urdf_inertia::diagnostic::Provenance::Mesh(solid.rung.clone()),
        solid.faces_read,
        solid.faces.len(),
        solid.vertices.len()
    );
    outln!("  volume            {} m³", shortest(volume));
    outln!("  density           {} kg/m³", shortest(density));
    outln!("  mass              {} kg", shortest(mp.mass));
    outln!(
        "  centre of mass    {} {} {} m",
        shortest(mp.com[0]),
        shortest(mp.com[1]),
        shortest(mp.com[2])
    );
    outln!("  inertia about the COM (kg·m², mesh axes)");
    for row in &mp.inertia {
        outln!(
            "    {:>24} {:>24} {:>24}",
            shortest(row[0]),
            shortest(row[1]),
            shortest(row[2])
        );
    }
    outln!(
        "  principal moments {} {} {}",
        shortest(pr.moments[0]),
        shortest(pr.moments[1]),
        shortest(pr.moments[2])
    );
    for (k, name) in ["axis 1", "axis 2", "axis 3"].iter().enumerate() {
        outln!(
            "  principal {name}  {:.9} {:.9} {:.9}",
            pr.axes[0][k],
            pr.axes[1][k],
            pr.axes[2][k]
        );
    }
    outln!(
        "  error estimate    {} (relative bound on volume and central inertia)",
        solid.error.describe()
    );
    outln!("  time              {:.3} ms", elapsed.as_secs_f64() * 1e3);
    for d in diagnostics.iter().filter(|d| d.code != Code::MeshTooLarge) {
        outln!("  {}: {}", d.head(), d.message);
    }
}
