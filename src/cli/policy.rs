//! Which diagnostics reach the user and how: `--quiet`, `--ignore CODE`, `--warn-as-error CODE`,
//! `--note-below BOUND`, and the same settings in a configuration file (`urdf-inertia.toml`) found by
//! walking up from the current directory to the repository root.

use super::args::DiagnosticArgs;
use serde::Deserialize;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use urdf_inertia::diagnostic::{Code, Diagnostic, Severity};
use urdf_inertia::FillReport;

/// The configuration file's name.
pub const CONFIG_FILE: &str = "urdf-inertia.toml";

/// A repair warning (UI101, UI102) whose relative error bound is below this becomes a note: under
/// half a unit of the 8th significant digit of any number (5e-9 at worst), the precision of an f32
/// export and more than `diff` prints, so it moves a number written with 8 digits or fewer only
/// where the number sits on a rounding boundary.
pub const NOTE_BELOW: f64 = 1e-9;

/// What a configuration file may say (kebab-case keys, unknown keys refused).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct FileConfig {
    #[serde(default)]
    ignore: Vec<String>,
    #[serde(default)]
    warn_as_error: Vec<String>,
    note_below: Option<f64>,
    quiet: Option<bool>,
    /// Relative to the configuration file.
    density_map: Option<PathBuf>,
    #[serde(default)]
    package_path: Vec<String>,
    /// Relative to the configuration file (`check`).
    baseline: Option<PathBuf>,
}

/// A configuration file as read: its path and settings (paths made relative to the current
/// directory's view of it).
#[derive(Debug, Default)]
pub struct Settings {
    pub file: Option<PathBuf>,
    pub density_map: Option<PathBuf>,
    pub package_path: Vec<String>,
    pub baseline: Option<PathBuf>,
}

/// How diagnostics are filtered and printed.
#[derive(Debug, Clone)]
pub struct Policy {
    pub quiet: bool,
    pub verbose: bool,
    ignore: HashSet<Code>,
    warn_as_error: HashSet<Code>,
    pub note_below: f64,
}

impl Default for Policy {
    fn default() -> Self {
        Policy {
            quiet: false,
            verbose: false,
            ignore: HashSet::new(),
            warn_as_error: HashSet::new(),
            note_below: NOTE_BELOW,
        }
    }
}

/// `UI101,UI102` and repeated flags as codes; `what` names the flag or key in the error.
fn codes(lists: &[String], what: &str) -> Result<Vec<Code>, String> {
    let mut out = Vec::new();
    for s in lists.iter().flat_map(|l| l.split(',')) {
        if s.trim().is_empty() {
            continue;
        }
        let c = Code::parse(s).ok_or_else(|| {
            format!(
                "{what}: unknown code `{}`; the codes are listed in the README's Diagnostics table (UI101 … UI709)",
                s.trim()
            )
        })?;
        if c.is_error() {
            return Err(format!(
                "{what}: {c} is an error, which fails the link or the robot: it cannot be silenced or promoted"
            ));
        }
        out.push(c);
    }
    Ok(out)
}

/// The configuration file that applies from `start`: `urdf-inertia.toml` in `start` or a parent, up
/// to the repository root (the first directory holding `.git`); without a repository, only `start`.
pub fn find_config(start: &Path) -> Option<PathBuf> {
    let start = std::fs::canonicalize(start).ok()?;
    let ancestors: Vec<&Path> = start.ancestors().collect();
    let root = ancestors.iter().position(|d| d.join(".git").exists());
    let searched = root.map_or(&ancestors[..1], |r| &ancestors[..=r]);
    searched
        .iter()
        .map(|d| d.join(CONFIG_FILE))
        .find(|p| p.is_file())
}

impl Policy {
    /// The policy of the flags and the configuration file they point to (`--config FILE`, or the one
    /// found from the current directory, else from the first input's directory; none with
    /// `--no-config`). Flags add to the file's lists and override its values.
    pub fn new(
        a: &DiagnosticArgs,
        verbose: bool,
        first_input: Option<&Path>,
    ) -> Result<(Policy, Settings), String> {
        let file = if a.no_config {
            None
        } else if let Some(f) = &a.config {
            Some(f.clone())
        } else {
            find_config(Path::new(".")).or_else(|| {
                first_input
                    .and_then(Path::parent)
                    .map(|d| {
                        if d.as_os_str().is_empty() {
                            Path::new(".")
                        } else {
                            d
                        }
                    })
                    .and_then(find_config)
            })
        };
        let (fc, settings) = match &file {
            None => (FileConfig::default(), Settings::default()),
            Some(path) => read_config(path)?,
        };
        let mut ignore = codes(&fc.ignore, &config_key(&settings, "ignore"))?;
        ignore.extend(codes(&a.ignore, "--ignore")?);
        let mut promote = codes(&fc.warn_as_error, &config_key(&settings, "warn-as-error"))?;
        promote.extend(codes(&a.warn_as_error, "--warn-as-error")?);
        let note_below = a.note_below.or(fc.note_below).unwrap_or(NOTE_BELOW);
        if !(note_below >= 0.0 && note_below.is_finite()) {
            return Err(format!(
                "note-below {note_below} must be a relative bound (a number >= 0, 0 keeps every repair a warning)"
            ));
        }
        let policy = Policy {
            quiet: a.quiet || fc.quiet.unwrap_or(false),
            verbose,
            ignore: ignore.into_iter().collect(),
            warn_as_error: promote.into_iter().collect(),
            note_below,
        };
        Ok((policy, settings))
    }

    /// `d` as this policy shows it: `None` if ignored, an error if promoted.
    pub fn apply(&self, d: &Diagnostic) -> Option<Diagnostic> {
        if self.ignore.contains(&d.code) {
            return None;
        }
        let mut d = d.clone();
        if self.warn_as_error.contains(&d.code) {
            d.severity = Severity::Error;
        }
        Some(d)
    }

    /// Applies the policy to a list in place.
    pub fn apply_all(&self, ds: &mut Vec<Diagnostic>) {
        *ds = ds.iter().filter_map(|d| self.apply(d)).collect();
    }

    /// Whether a problem of `check` (`UI6xx`) is reported.
    pub fn reports(&self, code: Code) -> bool {
        !self.ignore.contains(&code)
    }

    /// Whether text output shows a diagnostic of this severity: errors always, warnings unless
    /// `--quiet`, notes with `--verbose` (and not `--quiet`).
    pub fn shows(&self, d: &Diagnostic) -> bool {
        match d.severity {
            Severity::Warning => !self.quiet,
            Severity::Note => self.verbose && !self.quiet,
            // Errors, and any severity added later.
            _ => true,
        }
    }

    /// The report as this policy shows it: a repaired part without a repair diagnostic gets one
    /// (UI101), repairs whose bound is below `note_below` become notes, then `--ignore` and
    /// `--warn-as-error` apply to every part's and link's diagnostics.
    pub fn apply_report(&self, report: &mut FillReport) {
        for l in &mut report.links {
            for p in &mut l.parts {
                if p.provenance.is_repaired()
                    && !p.diagnostics.iter().any(|d| d.code == Code::MeshRepaired)
                {
                    let location = p.diagnostics.first().and_then(|d| d.location.clone());
                    let mut d = Diagnostic::new(
                        Code::MeshRepaired,
                        format!("repaired; relative error bound {}", p.error.describe()),
                    );
                    d.location = location;
                    p.diagnostics.insert(0, d);
                }
                if p.error_estimate < self.note_below {
                    for d in &mut p.diagnostics {
                        if matches!(d.code, Code::MeshRepaired | Code::MeshFacesDropped) {
                            d.severity = Severity::Note;
                        }
                    }
                }
                self.apply_all(&mut p.diagnostics);
            }
            self.apply_all(&mut l.diagnostics);
        }
        self.apply_all(&mut report.no_volume);
    }
}

/// `FILE: KEY` for messages about a configuration key.
fn config_key(s: &Settings, key: &str) -> String {
    s.file
        .as_ref()
        .map_or_else(|| key.to_string(), |f| format!("{}: {key}", f.display()))
}

fn read_config(path: &Path) -> Result<(FileConfig, Settings), String> {
    let bytes = urdf_inertia::input::read_file(path, super::max_file_size())
        .map_err(|e| format!("{}: cannot read the configuration: {e}", path.display()))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| format!("{}: the configuration is not UTF-8", path.display()))?;
    let fc: FileConfig = toml::from_str(&text).map_err(|e| {
        format!(
            "{}: {}; the keys are ignore, warn-as-error, note-below, quiet, density-map, package-path, baseline (README, \"Configuration file\")",
            path.display(),
            e.to_string().trim_end()
        )
    })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let rel = |p: &PathBuf| {
        if p.is_absolute() {
            p.clone()
        } else {
            dir.join(p)
        }
    };
    let settings = Settings {
        file: Some(path.to_path_buf()),
        density_map: fc.density_map.as_ref().map(rel),
        package_path: fc
            .package_path
            .iter()
            .map(|p| match p.split_once('=') {
                Some((name, d)) if Path::new(d).is_relative() => {
                    format!("{name}={}", dir.join(d).display())
                }
                _ => p.clone(),
            })
            .collect(),
        baseline: fc.baseline.as_ref().map(rel),
    };
    Ok((fc, settings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_split_on_commas_and_refuse_errors_and_unknown_ones() {
        let c = codes(&["UI101,ui102".into(), "UI401".into()], "--ignore").unwrap();
        assert_eq!(
            c,
            [
                Code::MeshRepaired,
                Code::MeshFacesDropped,
                Code::PartsOverlap
            ]
        );
        assert!(codes(&["UI999".into()], "--ignore")
            .unwrap_err()
            .contains("unknown code `UI999`"));
        assert!(codes(&["UI702".into()], "--ignore")
            .unwrap_err()
            .contains("is an error"));
    }
}
