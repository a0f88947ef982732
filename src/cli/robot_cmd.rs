//! `fill`, `diff` and `check`: one pipeline over URDFs. Each command becomes a [`Config`] with a
//! [`Mode`]; every URDF is read, computed once and compared once, then the mode decides what is
//! printed or written, and [`Outcome::status`] decides the exit status in one place.

use super::args::{CheckArgs, DiffArgs, FillArgs, Format, SourceArgs};
use super::baseline::{Baseline, Problem};
use super::policy::{Policy, Settings};
use super::summary;
use super::{write, ExitStatus};
use std::path::{Path, PathBuf};
use std::time::Instant;
use urdf_inertia::diagnostic::{Code, Diagnostic, Location, Severity};
use urdf_inertia::report::LinkRecord;
use urdf_inertia::text::Digits;
use urdf_inertia::write::{splice, LinkUpdate, WriteOptions};
use urdf_inertia::xacro::{self, Expansion};
use urdf_inertia::PackageResolver;
use urdf_inertia::ProblemKind;
use urdf_inertia::{scan_bytes, Geometry, Robot};
use urdf_inertia::{DensityMap, Glob};
use urdf_inertia::{FillOptions, FillReport};
use urdf_inertia::{LinkReport, MeshCache};

/// Validated sources: densities (if any), package paths, link selection.
struct Sources {
    map: Option<DensityMap>,
    resolver: PackageResolver,
    /// `--arg NAME:=VALUE` for xacro inputs.
    xacro_args: Vec<(String, String)>,
    options: FillOptions,
    /// `--max-memory`, or the machine's available memory.
    memory_budget: u64,
    /// The density map's file (`--density-map`), for the rules that match nothing.
    map_path: Option<PathBuf>,
    /// `--geometry collision,visual`.
    visual_fallback: bool,
}

/// `--max-memory`, or by default the memory the kernel reports available (Linux: `MemAvailable` in
/// /proc/meminfo); no budget where neither is known.
fn memory_budget(s: &SourceArgs) -> Result<u64, String> {
    if let Some(v) = &s.max_memory {
        return urdf_inertia::input::parse_size(v).map_err(|e| format!("--max-memory: {e}"));
    }
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
    Ok(meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(u64::MAX, |kib| kib.saturating_mul(1024)))
}

fn density_map(s: &SourceArgs, settings: &Settings) -> Result<Option<DensityMap>, String> {
    Ok(match (&s.density_map, s.density) {
        (Some(p), _) => {
            Some(DensityMap::load(p, super::max_file_size()).map_err(|e| e.to_string())?)
        }
        (None, None) if settings.density_map.is_some() => {
            let p = settings.density_map.as_deref().unwrap_or(Path::new(""));
            Some(DensityMap::load(p, super::max_file_size()).map_err(|e| {
                let file = settings
                    .file
                    .as_ref()
                    .map_or(String::new(), |f| format!("{}: density-map: ", f.display()));
                format!("{file}{e}")
            })?)
        }
        (None, Some(d)) => {
            if !(d > 0.0 && d.is_finite()) {
                return Err(format!("--density {d} must be a positive number (kg/m³)"));
            }
            Some(DensityMap::uniform(d))
        }
        (None, None) if s.keep_mass => Some(DensityMap::default()),
        (None, None) => None,
    })
}

fn sources(s: &SourceArgs, settings: &Settings) -> Result<Sources, String> {
    let map = density_map(s, settings)?;
    let globs = |patterns: &[String]| {
        patterns
            .iter()
            .map(|g| Glob::new(g).map_err(|e| format!("--only/--skip: {e}")))
            .collect::<Result<Vec<_>, String>>()
    };
    let pkgs = s
        .package_path
        .iter()
        .chain(&settings.package_path)
        .map(|p| super::parse_package_arg(p))
        .collect::<Result<Vec<_>, String>>()?;
    let xacro_args = s
        .xacro_args
        .iter()
        .map(|a| super::parse_xacro_arg(a))
        .collect::<Result<Vec<_>, String>>()?;
    let visual_fallback = match s.geometry.replace(' ', "").as_str() {
        "collision" => false,
        "collision,visual" => true,
        other => {
            return Err(format!(
                "--geometry `{other}`: give `collision` (the default) or `collision,visual`"
            ))
        }
    };
    let mut options = FillOptions::default();
    options.strict = s.strict;
    options.open_mesh = super::args::OpenMesh::model(s.open_mesh);
    options.only = globs(&s.only)?;
    options.skip = globs(&s.skip)?;
    options.keep_mass = s.keep_mass;
    options.allow_large_parts = s.allow_large_parts;
    Ok(Sources {
        map,
        map_path: s.density_map.clone(),
        visual_fallback,
        resolver: super::package_resolver(&pkgs),
        xacro_args,
        options,
        memory_budget: memory_budget(s)?,
    })
}

/// Sources that must include densities (`fill`, `diff`).
fn sources_with_densities(
    s: &SourceArgs,
    settings: &Settings,
    command: &str,
) -> Result<Sources, String> {
    let src = sources(s, settings)?;
    if src.map.is_none() {
        return Err(format!("{command} needs densities: pass --density RHO (kg/m³), --density-map FILE or --keep-mass, or set `density-map = \"FILE\"` in urdf-inertia.toml at the repository's root (the pre-commit hook reads it there)"));
    }
    Ok(src)
}

fn validated_tolerance(tolerance: f64) -> Result<f64, String> {
    if tolerance > 0.0 && tolerance.is_finite() {
        Ok(tolerance)
    } else {
        Err(format!("--tolerance {tolerance} must be a positive number"))
    }
}

/// Where and how `fill` writes.
// Independent yes/no settings of `fill` (`-i`, `--keep-going`, ...), not a state machine.
#[allow(clippy::struct_excessive_bools)]
pub struct WriteConfig {
    /// `-o OUT` (`None`: stdout, unless in place).
    target: Option<PathBuf>,
    /// `-i`: each URDF is its own target.
    in_place: bool,
    /// Several URDFs (in place): each summary names its file.
    several: bool,
    keep_going: bool,
    digits: Digits,
    principal: bool,
    /// The summary as JSON on stdout (only when the URDF goes to a file).
    json: bool,
}

/// What the pipeline does with the computed values.
pub enum Mode {
    /// `fill`: splice them into the URDF.
    Write(WriteConfig),
    /// `check`: report invalid, missing or (with densities) differing `<inertial>` elements.
    Check { all_links: bool, format: Format },
    /// `diff`: show existing against computed.
    Diff { format: Format },
}

/// What `check` does with a baseline file.
pub enum BaselineUse {
    /// `--baseline FILE`: problems recorded there do not fail the run.
    Read(Baseline),
    /// `--write-baseline FILE`: today's problems are recorded there.
    Write(PathBuf),
}

/// A validated command.
// `config_file`: the configuration file (urdf-inertia.toml) in effect, named as users call it.
#[allow(clippy::struct_field_names)]
pub struct Config {
    mode: Mode,
    files: Vec<PathBuf>,
    src: Sources,
    tolerance: f64,
    policy: Policy,
    /// The configuration file in effect, if any.
    config_file: Option<PathBuf>,
    baseline: Option<BaselineUse>,
}

impl Config {
    fn fill(a: &FillArgs) -> Result<Config, String> {
        let to_stdout = !a.in_place && a.output.as_ref().is_none_or(|p| p.as_os_str() == "-");
        if a.format == Format::Json && to_stdout {
            return Err("--format json prints the summary on stdout, where the URDF goes without -o OUT or -i".into());
        }
        if a.urdf.len() > 1 && !a.in_place {
            return Err(format!(
                "{} URDFs given: several are filled in place only (-i); stdout and -o OUT take one",
                a.urdf.len()
            ));
        }
        if a.urdf.len() > 1 && a.format == Format::Json {
            return Err(
                "--format json summarises one URDF: fill several without it, or one at a time"
                    .into(),
            );
        }
        if a.in_place && a.urdf.iter().any(|p| p.as_os_str() == "-") {
            return Err(
                "-i writes files in place: stdin (`-`) has none; use -o OUT or stdout".into(),
            );
        }
        let (policy, settings) = Policy::new(
            &a.source.diagnostics,
            a.verbose,
            a.urdf.first().map(PathBuf::as_path),
        )?;
        let mut src = sources_with_densities(&a.source, &settings, "fill")?;
        src.options.missing_only = a.missing_only;
        let write = WriteConfig {
            target: a.output.clone().filter(|p| p.as_os_str() != "-"),
            in_place: a.in_place,
            several: a.urdf.len() > 1,
            keep_going: a.keep_going,
            digits: a.digits,
            principal: a.principal,
            json: a.format == Format::Json,
        };
        Ok(Config {
            mode: Mode::Write(write),
            files: a.urdf.clone(),
            src,
            tolerance: 0.05,
            policy,
            config_file: settings.file,
            baseline: None,
        })
    }

    fn diff(a: &DiffArgs) -> Result<Config, String> {
        let tolerance = validated_tolerance(a.tolerance)?;
        let (policy, settings) = Policy::new(&a.source.diagnostics, a.verbose, Some(&a.urdf))?;
        Ok(Config {
            mode: Mode::Diff { format: a.format },
            files: vec![a.urdf.clone()],
            src: sources_with_densities(&a.source, &settings, "diff")?,
            tolerance,
            policy,
            config_file: settings.file,
            baseline: None,
        })
    }

    fn check(a: &CheckArgs) -> Result<Config, String> {
        let (policy, settings) = Policy::new(
            &a.source.diagnostics,
            a.verbose,
            a.urdf.first().map(PathBuf::as_path),
        )?;
        let src = sources(&a.source, &settings)?;
        let baseline = match (&a.write_baseline, &a.baseline, &settings.baseline) {
            (Some(w), _, _) => Some(BaselineUse::Write(w.clone())),
            (None, Some(b), _) if a.update => Some(BaselineUse::Write(b.clone())),
            (None, Some(b), _) | (None, None, Some(b)) => {
                Some(BaselineUse::Read(Baseline::read(b)?))
            }
            (None, None, None) => None,
        };
        Ok(Config {
            mode: Mode::Check {
                all_links: a.all_links,
                format: a.format,
            },
            files: a.urdf.clone(),
            src,
            tolerance: validated_tolerance(a.tolerance)?,
            policy,
            config_file: settings.file,
            baseline,
        })
    }
}

/// What the pipeline found: problems in the robots (exit 1) and errors (exit 2).
#[derive(Debug, Default, Clone, Copy)]
pub struct Outcome {
    problems: usize,
    errors: usize,
}

impl Outcome {
    fn error() -> Outcome {
        Outcome {
            problems: 0,
            errors: 1,
        }
    }

    /// The exit status: any error is 2, else any problem 1, else 0.
    pub fn status(self) -> ExitStatus {
        if self.errors > 0 {
            ExitStatus::Error
        } else if self.problems > 0 {
            ExitStatus::Problems
        } else {
            ExitStatus::Success
        }
    }
}

impl std::ops::AddAssign for Outcome {
    fn add_assign(&mut self, o: Outcome) {
        self.problems += o.problems;
        self.errors += o.errors;
    }
}

pub fn fill(a: &FillArgs) -> ExitStatus {
    run_command(Config::fill(a))
}

/// `diff` exits 1 when a link differs beyond `--tolerance` or its existing values are invalid (as
/// `ruff format --diff` exits 1 when a file would change).
pub fn diff(a: &DiffArgs) -> ExitStatus {
    run_command(Config::diff(a))
}

/// `check` exits 1 when an `<inertial>` is invalid, missing or (with densities) off by more than the
/// tolerance. Several URDFs (what pre-commit passes) share one mesh cache: a mesh is read once.
pub fn check(a: &CheckArgs) -> ExitStatus {
    run_command(Config::check(a))
}

fn run_command(config: Result<Config, String>) -> ExitStatus {
    match config {
        Ok(c) => run(&c).status(),
        Err(e) => {
            errln!("error: {e}");
            ExitStatus::Error
        }
    }
}

/// The pipeline: every URDF read, computed (with densities), compared, then handed to the mode.
fn run(config: &Config) -> Outcome {
    let mut cache = MeshCache::with_memory_budget(config.src.memory_budget)
        .with_max_file_size(super::max_file_size());
    let mut outcome = Outcome::default();
    if let Some(f) = &config.config_file {
        let d = Diagnostic::new(
            Code::RunConfig,
            format!("settings read from {}", f.display()),
        );
        if config.policy.shows(&d) {
            errln!("{}", d.render());
        }
    }
    let mut found = Findings::default();
    let mut seen = super::noops::Seen::default();
    for path in &config.files {
        outcome += run_one(config, path, &mut cache, &mut found, &mut seen);
    }
    // One file's --only error stopped it before anything was computed (in `run_one`).
    if config.files.len() > 1 && outcome.errors == 0 {
        if let Some(e) = super::noops::only_error(&config.src.options, &seen) {
            errln!("error: {e}");
            outcome.errors += 1;
        }
    }
    let map = config.src.map.as_ref().zip(config.src.map_path.as_deref());
    print_diagnostics(
        &super::noops::warnings(map, &config.src.options, &seen),
        &config.policy,
    );
    if matches!(config.mode, Mode::Check { .. }) {
        outcome.problems += report_problems(config, &found, outcome.errors);
    }
    outcome
}

/// What `check` found over its files: the problems, and each link with one as read (and computed,
/// with densities), for the JSON.
#[derive(Default)]
struct Findings {
    problems: Vec<Problem>,
    links: Vec<LinkRecord>,
    /// Links (file, name) `fill` leaves as they are because their collision geometry has no volume
    /// (UI109): a problem of their own `<inertial>` is not one `fill` can correct.
    uncomputable: Vec<(PathBuf, String)>,
}

impl Findings {
    /// The links of `robot` with a problem from `from` on (the problems found in `robot`), each
    /// recorded once.
    fn record_links(
        &mut self,
        robot: &Robot,
        report: Option<&FillReport>,
        from: usize,
        tolerance: f64,
    ) {
        let first = self.links.len();
        for p in &self.problems[from..] {
            if self.links[first..].iter().any(|r| r.link == p.problem.link) {
                continue;
            }
            let Some(index) = robot.links.iter().position(|l| l.name == p.problem.link) else {
                continue;
            };
            let computed = report.and_then(|r| r.links.iter().find(|l| l.index == index));
            let tolerance = computed.map(|_| tolerance);
            self.links.push(LinkRecord::new(
                robot,
                index,
                computed,
                Digits::Auto,
                tolerance,
            ));
        }
    }
}

/// `check`'s problems against the baseline (if any): the new ones printed on stdout and counted,
/// the known ones counted, a baseline to write written; then the closing line on stderr.
fn report_problems(config: &Config, found: &Findings, errors: usize) -> usize {
    let problems = &found.problems;
    let (new, known): (Vec<&Problem>, Vec<&Problem>) = match &config.baseline {
        Some(BaselineUse::Read(b)) => problems.iter().partition(|p| !b.contains(p)),
        _ => (problems.iter().collect(), Vec::new()),
    };
    if let Some(BaselineUse::Write(path)) = &config.baseline {
        return match Baseline::write(path, problems) {
            Ok(()) => {
                errln!(
                    "urdf-inertia check: recorded {} problem(s) in {}; `urdf-inertia check --baseline {}` now fails only on new ones",
                    problems.len(),
                    path.display(),
                    path.display()
                );
                0
            }
            Err(e) => {
                errln!("error: {e}");
                // Not a problem of the robot, but the run failed all the same.
                1
            }
        };
    }
    if matches!(
        config.mode,
        Mode::Check {
            format: Format::Json,
            ..
        }
    ) {
        summary::check_json(&new, &found.links, known.len(), errors);
    } else {
        for p in &new {
            outln!("{}", p.line());
        }
    }
    if let Some(BaselineUse::Read(b)) = &config.baseline {
        if !known.is_empty() || !new.is_empty() {
            errln!(
                "urdf-inertia check: {} problem(s) recorded in the baseline {} (not failing), {} new",
                known.len(),
                b.path.display(),
                new.len()
            );
        }
        let fixed = b.unmatched(problems);
        if fixed > 0 && !config.policy.quiet {
            errln!(
                "urdf-inertia check: {fixed} problem(s) of the baseline {} are gone: `--write-baseline {}` records the shorter list",
                b.path.display(),
                b.path.display()
            );
        }
    }
    if errors == 0 && !new.is_empty() {
        errln!(
            "urdf-inertia check: {}",
            closing_line(&new, &found.uncomputable)
        );
        if config.baseline.is_none() && !config.policy.quiet {
            errln!(
                "help: problems that were there before your change? record them once with `urdf-inertia check FILES --write-baseline urdf-inertia.baseline` (commit it; `baseline = \"urdf-inertia.baseline\"` in urdf-inertia.toml) and later runs fail only on new ones; or leave a link alone with --skip NAME"
            );
        }
    }
    new.len()
}

/// `check`'s closing line for the `new` problems. Problems on links `fill` cannot compute
/// (`uncomputable`: their collision geometry has no volume, UI109) are not promised to `fill`.
fn closing_line(new: &[&Problem], uncomputable: &[(PathBuf, String)]) -> String {
    let on_flat: Vec<&str> = (new.iter())
        .filter(|p| {
            uncomputable
                .iter()
                .any(|(f, l)| *f == p.problem.file && *l == p.problem.link)
        })
        .map(|p| p.problem.link.as_str())
        .collect();
    let n = new.len();
    let fill = "`urdf-inertia fill -i FILE --density-map …` computes correct values";
    let by_hand = "give them a primitive collision shape or a closed mesh, or correct their <inertial> by hand";
    if on_flat.is_empty() {
        format!("{n} problem(s) found; {fill}")
    } else if on_flat.len() == n {
        format!("{n} problem(s) found, on links whose collision geometry has no volume (UI109), which `fill` cannot compute: {by_hand}")
    } else {
        let mut links = on_flat;
        links.sort_unstable();
        links.dedup();
        format!("{n} problem(s) found; {fill}, except for links whose collision geometry has no volume (UI109: {}): {by_hand}", links.join(", "))
    }
}

fn run_one(
    config: &Config,
    path: &Path,
    cache: &mut MeshCache,
    found: &mut Findings,
    seen: &mut super::noops::Seen,
) -> Outcome {
    let start = Instant::now();
    let mut input = match read_input(path, &config.src, &config.policy) {
        Ok(r) => r,
        Err(e) => {
            errln!("error: {e}");
            return Outcome::error();
        }
    };
    if config.src.visual_fallback {
        input.robot.use_visual_geometry();
    } else if let Some(d) = super::noops::no_collision_geometry(&input.robot) {
        print_diagnostics(&[d], &config.policy);
    }
    seen.record(&input.robot);
    if config.files.len() == 1 {
        if let Some(e) = super::noops::only_error(&config.src.options, seen) {
            errln!("error: {e}");
            return Outcome::error();
        }
    }
    let robot = &input.robot;
    let mut outcome = Outcome::default();
    let from = found.problems.len();
    if let Mode::Check { all_links, .. } = config.mode {
        check_existing(&input, config, all_links, &mut found.problems);
    }
    let promoted_notes = promoted(&robot.notes);
    let Some(map) = &config.src.map else {
        // Only `check` runs without densities: nothing is computed, but a collision that cannot be
        // is still an error.
        outcome.errors += check_collisions(&input, &config.src);
        outcome.problems += promoted_notes;
        // Every collision mesh path must resolve (a stat, no reading).
        let missing =
            urdf_inertia::unresolved_meshes(robot, &config.src.resolver, &config.src.options);
        for f in &missing {
            errln!("error: {}: {f}", input.link_at(f.line, &f.link));
        }
        outcome.errors += missing.len();
        if found.problems.len() > from {
            let flat = flat_links_without_densities(robot, &config.src, cache);
            set_aside_flat_links(&input, config, &flat, found, from);
        }
        found.record_links(robot, None, from, config.tolerance);
        return outcome;
    };
    let src = &config.src;
    let mut report = urdf_inertia::compute_with(robot, map, &src.resolver, &src.options, cache);
    // Before the policy, which may drop their UI109 warnings.
    let flat_links: Vec<String> = (report.no_volume.iter())
        .filter_map(|d| d.location.as_ref()?.link.clone())
        .collect();
    config.policy.apply_report(&mut report);
    print_failures(&input, &report);
    outcome.errors += report.error_count();
    let promoted = promoted_notes + promoted_in(&report);
    match &config.mode {
        Mode::Write(w) => {
            if write_robot(&input, &report, w, &config.policy, start, promoted).is_err() {
                outcome.errors += 1;
            }
        }
        Mode::Diff { format } => {
            summary::computed_diagnostics(&report, &config.policy);
            let records = summary::diff_records(robot, &report, config.tolerance);
            outcome.problems += records.iter().filter(|r| r.differs == Some(true)).count();
            summary::diff(records, *format, config.tolerance, robot, &report);
            outcome.problems += promoted;
        }
        Mode::Check { .. } => {
            summary::computed_diagnostics(&report, &config.policy);
            set_aside_flat_links(&input, config, &flat_links, found, from);
            check_against_computed(&input, &report, config, &mut found.problems);
            found.record_links(robot, Some(&report), from, config.tolerance);
            outcome.problems += promoted;
        }
    }
    outcome
}

/// How many diagnostics `--warn-as-error` made errors.
fn promoted(ds: &[Diagnostic]) -> usize {
    ds.iter().filter(|d| d.severity == Severity::Error).count()
}

/// The same over a computed robot's parts and links.
fn promoted_in(report: &FillReport) -> usize {
    report
        .links
        .iter()
        .map(|l| {
            promoted(&l.diagnostics)
                + l.parts
                    .iter()
                    .map(|p| promoted(&p.diagnostics))
                    .sum::<usize>()
        })
        .sum()
}

/// A robot as read: the scanned URDF and, for a xacro source, its expansion (whose source map
/// turns lines of the expanded text into files and lines of the sources).
pub struct Input {
    robot: Robot,
    xacro: Option<Expansion>,
}

impl Input {
    /// ``FILE:LINE: link `name` `` for an element on `line` of the scanned text; for a xacro source
    /// the file and line where it was written, and the macro calls that produced it.
    fn link_at(&self, line: usize, name: &str) -> String {
        let name = urdf_inertia::text::escape_control(name);
        match self.xacro.as_ref().and_then(|x| Some((x, x.origin(line)?))) {
            Some((x, o)) => format!("{}: link `{name}`{}", x.at(o), x.calls_text(o)),
            None => format!("{}:{line}: link `{name}`", self.robot.path.display()),
        }
    }

    /// A diagnostic's location moved from the expanded text to the source.
    fn located(&self, d: &Diagnostic) -> Diagnostic {
        let mut d = d.clone();
        if let (Some(x), Some(l)) = (&self.xacro, d.location.as_mut()) {
            if l.file.as_deref() == Some(self.robot.path.as_path()) {
                if let Some(o) = l.line.and_then(|line| x.origin(line)) {
                    l.file = Some(x.files[o.file].path.clone());
                    l.line = Some(o.line);
                    d.message.push_str(&x.calls_text(o));
                }
            }
        }
        d
    }
}

/// Reads, decodes and scans a URDF (a file, or stdin for `-`), expanding a xacro source first,
/// and prints the scan's warnings (and notes, if `verbose`) to stderr.
fn read_input(path: &Path, src: &Sources, policy: &Policy) -> Result<Input, String> {
    let stdin = path.as_os_str() == "-";
    let bytes = if stdin {
        urdf_inertia::input::read_rest(std::io::stdin().lock(), Vec::new(), super::max_file_size())
            .map_err(|e| format!("stdin: cannot read the URDF: {e}"))?
    } else {
        write::remember_before_reading(path);
        urdf_inertia::input::read_file(path, super::max_file_size())
            .map_err(|e| format!("{}: cannot read the URDF: {e}", path.display()))?
    };
    if stdin {
        let mut robot = scan_bytes(bytes, Path::new("<stdin>")).map_err(|e| e.to_string())?;
        policy.apply_all(&mut robot.notes);
        print_diagnostics(&robot.notes, policy);
        return Ok(Input { robot, xacro: None });
    }
    if !xacro::is_xacro(path, &bytes) {
        let mut robot = scan_bytes(bytes, path).map_err(|e| e.to_string())?;
        policy.apply_all(&mut robot.notes);
        print_diagnostics(&robot.notes, policy);
        return Ok(Input { robot, xacro: None });
    }
    let opts = super::xacro_options(src.xacro_args.clone(), &src.resolver);
    let x = xacro::expand_source(path, Some(bytes), &opts).map_err(|e| e.to_string())?;
    let mut warnings: Vec<Diagnostic> = x
        .warnings
        .iter()
        .map(|w| Diagnostic::new(Code::XacroWarning, w.clone()))
        .collect();
    policy.apply_all(&mut warnings);
    print_diagnostics(&warnings, policy);
    let robot =
        scan_bytes(x.text.clone().into_bytes(), path).map_err(|e| match x.origin(e.line) {
            Some(o) => format!(
                "{}: {}{} (in the expansion of {})",
                x.at(o),
                e.message,
                x.calls_text(o),
                path.display()
            ),
            None => format!(
                "{} (line {} of the expansion): {}",
                path.display(),
                e.line,
                e.message
            ),
        })?;
    if robot.links.is_empty() {
        // A file of macros (what pre-commit passes along with the top-level files): nothing to
        // check on its own; its links are checked through the files that include it.
        let note = Diagnostic::new(
            Code::XacroNoLinks,
            "expands to no links (a file of macros?): its links are checked through the top-level xacro files that include it",
        )
        .at(Location::in_file(path));
        print_diagnostics(&policy.apply(&note).into_iter().collect::<Vec<_>>(), policy);
    }
    let mut input = Input {
        robot,
        xacro: Some(x),
    };
    let mut notes: Vec<Diagnostic> = input.robot.notes.iter().map(|d| input.located(d)).collect();
    policy.apply_all(&mut notes);
    print_diagnostics(&notes, policy);
    input.robot.notes = notes;
    Ok(input)
}

/// One diagnostic without a location of its own (its message names it), as the policy shows it.
fn print_one(policy: &Policy, d: &Diagnostic) {
    if let Some(d) = policy.apply(d).filter(|d| policy.shows(d)) {
        errln!("{}: {}", d.head(), d.message);
    }
}

/// What the policy shows: errors always, warnings unless `--quiet`, notes with `--verbose`.
fn print_diagnostics(diagnostics: &[Diagnostic], policy: &Policy) {
    for d in diagnostics.iter().filter(|d| policy.shows(d)) {
        errln!("{}", d.render());
    }
}

fn print_failures(input: &Input, report: &FillReport) {
    let path = input.robot.path.display();
    for f in &report.failures {
        errln!(
            "error[{}]: {}: {f}",
            f.kind.code(),
            input.link_at(f.line, &f.link)
        );
    }
    for e in &report.robot_errors {
        errln!("error[{}]: {path}: {e}", e.code());
    }
}

/// `fill`'s output: the spliced URDF, written (unless links failed without `--keep-going`), then
/// the summary. `Err` carries the status of a failure already reported.
fn write_robot(
    input: &Input,
    report: &FillReport,
    w: &WriteConfig,
    policy: &Policy,
    start: Instant,
    promoted: usize,
) -> Result<(), ExitStatus> {
    let robot = &input.robot;
    let t_write = Instant::now();
    let file = if w.in_place {
        Some(robot.path.as_path())
    } else {
        w.target.as_deref()
    };
    let json_unwritten = || unwritten_summary(robot, report, w, policy, start, false);
    if promoted > 0 {
        unwritten_summary(robot, report, w, policy, start, true);
        errln!(
            "error: {}: {promoted} warning(s) made errors by --warn-as-error (or warn-as-error in urdf-inertia.toml): nothing written",
            robot.path.display()
        );
        return Err(ExitStatus::Error);
    }
    let where_to = file.map_or_else(|| "stdout".to_string(), |p| p.display().to_string());
    let failed = report.error_count();
    let check_failed = || {
        if failed > 0 && !w.keep_going {
            json_unwritten();
            errln!(
                "error: {failed} link(s) could not be computed: nothing written to {where_to} (--keep-going writes the links that worked, and still exits 2)"
            );
            return Err(ExitStatus::Error);
        }
        Ok(())
    };
    let mut written = None;
    if let (Some(x), true) = (&input.xacro, w.in_place) {
        check_failed()?;
        let k = write_into_sources(input, x, report, w, policy)?;
        written = (k < report.links.len()).then_some(k);
    } else {
        let text = spliced(robot, report, w)?;
        check_failed()?;
        let target = file.unwrap_or(Path::new("-"));
        let written = if w.in_place {
            write::write_in_place(target, &text)
        } else {
            write::write_output(target, &text)
        };
        if let Err(e) = written {
            // A failing stdout was reported where it failed.
            if file.is_some() {
                errln!("error: {e}");
            }
            return Err(ExitStatus::Error);
        }
    }
    if file.is_some() {
        super::output::stdout_is_summary();
    }
    let times = summary::Times {
        seconds: start.elapsed().as_secs_f64(),
        write: t_write.elapsed().as_secs_f64(),
        written,
    };
    let mut run = run_diagnostics(robot, report);
    policy.apply_all(&mut run);
    if w.json && file.is_some() {
        summary::fill_json(robot, report, &run, w.digits, times.seconds, true);
    } else {
        summary::fill_text(robot, report, &run, policy, times, w.several);
    }
    Ok(())
}

/// The summary when nothing is written: `--format json` prints its JSON (with the errors,
/// `"written": false`) when the URDF was to go to a file; otherwise, with `text`, the text summary.
fn unwritten_summary(
    robot: &Robot,
    report: &FillReport,
    w: &WriteConfig,
    policy: &Policy,
    start: Instant,
    text: bool,
) {
    let run = run_diagnostics(robot, report);
    let seconds = start.elapsed().as_secs_f64();
    if w.json && (w.in_place || w.target.is_some()) {
        let mut run = run;
        policy.apply_all(&mut run);
        summary::fill_json(robot, report, &run, w.digits, seconds, false);
    } else if text {
        let times = summary::Times {
            seconds,
            write: 0.0,
            written: Some(0),
        };
        summary::fill_text(robot, report, &run, policy, times, w.several);
    }
}

/// The places of the sources `fill -i` writes into, per file (span, update), and how many links
/// they hold, of which how many from macro bodies; every computed link not written is named
/// ([`write_into_sources`]).
fn places_to_write(
    input: &Input,
    x: &Expansion,
    report: &FillReport,
    policy: &Policy,
) -> (PerFile, usize, usize) {
    let robot = &input.robot;
    let not_written = |line: usize, name: &str, why: &str| {
        let d = Diagnostic::new(
            Code::OutputNotInSource,
            format!(
                "{}: not written into the xacro source: {why}; `urdf-inertia fill {} -o filled.urdf` writes the filled expansion",
                input.link_at(line, name),
                robot.path.display()
            ),
        );
        print_one(policy, &d);
    };
    // Per place in the sources (file, span): the links expanded from it, with their updates and,
    // in a macro body whose link name is computed, a `[links]` rule that gave a density by the
    // name this call gave (another call, from another top-level file, gives another name, which
    // the rule may not match). A link in a macro body called more than once is one place for
    // several links.
    let mut places = std::collections::BTreeMap::<
        (usize, usize, usize),
        Vec<(usize, LinkUpdate, Option<String>)>,
    >::new();
    for l in &report.links {
        let link = &robot.links[l.index];
        let Some(o) = x.origin(link.line) else {
            continue;
        };
        let by_name = (!o.calls.is_empty() && !o.name_literal)
            .then(|| l.parts.iter().find(|p| p.density_source.starts_with("[links]")))
            .flatten()
            .map(|p| {
                let m = o.calls.last().map_or("a", |c| c.macro_name.as_str());
                format!(
                    "the density of `{}` comes from the density map's {}, matched by the name this call of macro {m} gives it, and another call may give it another name",
                    link.name, p.density_source
                )
            });
        match &o.literal {
            Ok(()) => places.entry((o.file, o.start, o.end)).or_default().push((
                l.index,
                l.update(),
                by_name,
            )),
            Err(why) => not_written(link.line, &link.name, why),
        }
    }
    // A place written once, when every link expanded from it computes the same `<inertial>`.
    let mut per_file = PerFile::new();
    let (mut written, mut in_macros) = (0, 0);
    for ((file, start, end), links) in places {
        let first = links[0].1;
        let names = || {
            let n: Vec<String> = links
                .iter()
                .map(|(i, ..)| format!("`{}`", robot.links[*i].name))
                .collect();
            n.join(", ")
        };
        let why = links.iter().find_map(|(.., b)| b.clone()).or_else(|| {
            (!links.iter().all(|(_, u, _)| same_values(u, &first))).then(|| {
                format!(
                    "its source expands to {} links ({}) whose computed <inertial> differ",
                    links.len(),
                    names()
                )
            })
        });
        if let Some(why) = why {
            for (i, ..) in &links {
                not_written(robot.links[*i].line, &robot.links[*i].name, &why);
            }
            continue;
        }
        written += links.len();
        if x.origin(robot.links[links[0].0].line)
            .is_some_and(|o| !o.calls.is_empty())
        {
            in_macros += links.len();
        }
        per_file.entry(file).or_default().push((start, end, first));
    }
    (per_file, written, in_macros)
}

/// Whether two updates write the same `<inertial>`: the same values, bit for bit.
fn same_values(a: &LinkUpdate, b: &LinkUpdate) -> bool {
    a.props == b.props
        && a.error.to_bits() == b.error.to_bits()
        && a.input_precision.to_bits() == b.input_precision.to_bits()
        && a.size.to_bits() == b.size.to_bits()
}

/// Per source file: the places written there (span, update).
type PerFile = std::collections::BTreeMap<usize, Vec<(usize, usize, LinkUpdate)>>;

/// `fill -i` on a xacro source: each computed `<inertial>` spliced into the file where its link is
/// written (an included file too), every other byte unchanged, each file replaced atomically, where
/// that place makes the same link for every expansion (`Origin::literal`) and every link made
/// from it computes the same values; in a macro body whose link name is computed, not when a
/// `[links]` rule gave the density (it matched this call's name). Any other link is named with the
/// reason and left alone: `-o FILE` writes the filled expansion instead.
fn write_into_sources(
    input: &Input,
    x: &Expansion,
    report: &FillReport,
    w: &WriteConfig,
    policy: &Policy,
) -> Result<usize, ExitStatus> {
    let robot = &input.robot;
    let mut options = WriteOptions::default();
    options.digits = w.digits;
    options.principal = w.principal;
    let (per_file, written, in_macros) = places_to_write(input, x, report, policy);
    let files = per_file.len();
    for (file, links) in per_file {
        let path = &x.files[file].path;
        let spans: Vec<(usize, usize)> = links.iter().map(|(s, e, _)| (*s, *e)).collect();
        let source = x.source_robot(file, &spans).map_err(|e| {
            errln!(
                "error: {}: cannot write into this file: {e}",
                path.display()
            );
            ExitStatus::Error
        })?;
        let updates: Vec<LinkUpdate> = links
            .iter()
            .filter_map(|(s, _, u)| {
                let index = source.links.iter().position(|l| l.start == *s)?;
                let mut u = *u;
                u.index = index;
                Some(u)
            })
            .collect();
        let text = splice(&source, &updates, &options).map_err(|errors| {
            for e in errors {
                let link = &source.links[e.index];
                errln!(
                    "error[{}]: {}:{}: link `{}`: {}",
                    Code::ErrorWrite,
                    path.display(),
                    link.line,
                    urdf_inertia::text::escape_control(&link.name),
                    e.message
                );
            }
            errln!("error: nothing written to {}", path.display());
            ExitStatus::Error
        })?;
        let bytes = source.encoding.encode(&text).map_err(|e| {
            errln!("error: {}: {e}", path.display());
            ExitStatus::Error
        })?;
        if let Err(e) = write::write_output(path, &bytes) {
            errln!("error: {e}");
            return Err(ExitStatus::Error);
        }
    }
    let macros = if in_macros > 0 {
        format!(" ({in_macros} of them from macro bodies with nothing computed inside the link, the same for every call)")
    } else {
        String::new()
    };
    errln!(
        "urdf-inertia: {}: wrote {written} of {} computed link(s) into {files} xacro source file(s){macros}",
        robot.path.display(),
        report.links.len()
    );
    Ok(written)
}

/// Warnings about the run as a whole: a robot without a name, links left as they were.
fn run_diagnostics(robot: &Robot, report: &FillReport) -> Vec<Diagnostic> {
    let at = || Location::in_file(robot.path.clone());
    let mut out = Vec::new();
    // A file of xacro macros expands to a nameless robot with no links: pre-commit passes every
    // such file to the hooks, where the name warning would be noise on each run.
    if robot.name.is_empty() && !robot.links.is_empty() {
        out.push(
            Diagnostic::new(
                Code::UrdfNoRobotName,
                "<robot> has no name attribute: urdfdom (ROS, pinocchio) refuses such a file",
            )
            .at(at()),
        );
    }
    let failed = report.error_count();
    if failed > 0 {
        out.push(
            Diagnostic::new(
                Code::OutputNotWritten,
                format!(
                    "not written (--keep-going): {failed} link(s) that failed, left as they were"
                ),
            )
            .at(at()),
        );
    }
    out
}

/// The URDF with the computed links spliced in, in the file's own encoding.
fn spliced(robot: &Robot, report: &FillReport, w: &WriteConfig) -> Result<Vec<u8>, ExitStatus> {
    let updates: Vec<LinkUpdate> = report.links.iter().map(LinkReport::update).collect();
    let mut options = WriteOptions::default();
    options.digits = w.digits;
    options.principal = w.principal;
    let text = splice(robot, &updates, &options).map_err(|errors| {
        for e in errors {
            let link = &robot.links[e.index];
            errln!(
                "error[{}]: {}:{}: link `{}`: {}",
                Code::ErrorWrite,
                robot.path.display(),
                link.line,
                urdf_inertia::text::escape_control(&link.name),
                e.message
            );
        }
        errln!("error: nothing written");
        ExitStatus::Error
    })?;
    // Written back in the file's own encoding (UTF-16 and declared single-byte files included).
    robot.encoding.encode(&text).map_err(|e| {
        errln!("error: {}: {e}", robot.path.display());
        ExitStatus::Error
    })
}

/// Problems of the existing `<inertial>` elements themselves (no computation needed), added to
/// `problems`; those of frames (links without collision geometry) are notes unless `--all-links`.
/// The links `fill` leaves as they are because every part is a mesh without volume (UI109), found
/// without densities: only the links `check` reports (`missing_only`) are computed, so their meshes
/// alone are read, and only when there is something to report.
fn flat_links_without_densities(
    robot: &Robot,
    src: &Sources,
    cache: &mut MeshCache,
) -> Vec<String> {
    let mut options = src.options.clone();
    options.missing_only = true;
    let report = urdf_inertia::compute_with(
        robot,
        &DensityMap::uniform(1.0),
        &src.resolver,
        &options,
        cache,
    );
    (report.no_volume.iter())
        .filter_map(|d| d.location.as_ref()?.link.clone())
        .collect()
}

/// A link `fill` leaves as it is for want of volume (`flat`: every part a flat mesh, UI109) is
/// checked as a link without collision geometry is: it misses no `<inertial>`, and a problem of its
/// own `<inertial>` is a note (UI207, fill cannot compute it) unless `--all-links`, when it stays a
/// problem that the closing line says `fill` cannot correct. `from`: this robot's first problem.
fn set_aside_flat_links(
    input: &Input,
    config: &Config,
    flat: &[String],
    found: &mut Findings,
    from: usize,
) {
    let all_links = matches!(
        config.mode,
        Mode::Check {
            all_links: true,
            ..
        }
    );
    let robot = &input.robot;
    let ours = |p: &Problem| p.problem.file == robot.path && flat.contains(&p.problem.link);
    let (aside, kept): (Vec<Problem>, Vec<Problem>) = (found.problems.drain(from..))
        .partition(|p| ours(p) && !matches!(p.problem.kind, ProblemKind::Duplicates { .. }));
    found.problems.extend(kept);
    for p in aside {
        if p.problem.kind == ProblemKind::MissingInertial {
            continue;
        }
        if all_links {
            found.problems.push(p);
        } else {
            let note = Diagnostic::new(
                Code::UrdfFrameInertial,
                format!(
                    "{} (its collision geometry has no volume, so fill cannot compute it): {}",
                    p.at, p.problem.kind
                ),
            );
            print_one(&config.policy, &note);
        }
    }
    (found.uncomputable).extend(flat.iter().map(|l| (robot.path.clone(), l.clone())));
}

fn check_existing(input: &Input, config: &Config, all_links: bool, problems: &mut Vec<Problem>) {
    let robot = &input.robot;
    for p in urdf_inertia::check(robot, &config.src.options) {
        // Several <inertial> elements are a problem whatever the link: the file says two things.
        let frame = robot
            .links
            .iter()
            .find(|l| l.name == p.link)
            .is_some_and(|l| !l.has_collision_geometry());
        let at = input.link_at(p.line, &p.link);
        if frame && !all_links && !matches!(p.kind, ProblemKind::Duplicates { .. }) {
            let note = Diagnostic::new(
                Code::UrdfFrameInertial,
                format!(
                    "{at} (no collision geometry, so fill cannot compute it): {}",
                    p.kind
                ),
            );
            print_one(&config.policy, &note);
        } else if config.policy.reports(p.code()) {
            problems.push(Problem { problem: p, at });
        }
    }
}

/// Without densities nothing is computed, but a collision that cannot be is still an error; their
/// count.
fn check_collisions(input: &Input, src: &Sources) -> usize {
    let robot = &input.robot;
    let mut errors = 0;
    for link in robot
        .links
        .iter()
        .filter(|l| urdf_inertia::selected(&l.name, &src.options))
    {
        for c in &link.collisions {
            if let Geometry::Invalid { line, message } = &c.geometry {
                errln!(
                    "error[{}]: {}: collision {} (line {line}): {message}",
                    Code::ErrorInvalidGeometry,
                    input.link_at(link.line, &link.name),
                    c.index
                );
                errors += 1;
            }
        }
    }
    errors
}

/// Existing against computed, beyond the tolerance (invalid values are reported by
/// `check_existing`), added to `problems`.
fn check_against_computed(
    input: &Input,
    report: &FillReport,
    config: &Config,
    problems: &mut Vec<Problem>,
) {
    if !config.policy.reports(Code::CheckDiffers) {
        return;
    }
    let found = urdf_inertia::check_computed(&input.robot, report, config.tolerance);
    for p in found {
        let at = input.link_at(p.line, &p.link);
        problems.push(Problem { problem: p, at });
    }
}
