//! `check --baseline FILE`: adopting the check on a repository with known problems. The baseline is
//! a text file for review, one problem a line (`FILE<TAB>LINK<TAB>CODE<TAB>MESSAGE`, sorted), written
//! by `--write-baseline FILE`; a later run fails only on problems whose file, link and code are not
//! in it (the message is for the reader: its numbers may change without making a problem new).

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use urdf_inertia::diagnostic::Code;
use urdf_inertia::text::escape_control;
use urdf_inertia::InertialProblem;

/// One problem `check` found, with where to print it (its JSON is `summary::check_json`'s).
#[derive(Debug, Clone)]
pub struct Problem {
    /// The problem, typed (file, link, line, code, values).
    pub problem: InertialProblem,
    /// ``FILE:LINE: link `NAME` `` (the source file and line for xacro).
    pub at: String,
}

impl Problem {
    /// The line `check` prints: `FILE:LINE: link `NAME`: MESSAGE [UI601]` (the code last, as
    /// `ESLint` puts its rule: the line reads as before, and the code is there to look up or silence).
    pub fn line(&self) -> String {
        format!(
            "{}: {} [{}]",
            self.at,
            self.problem.kind,
            self.problem.code()
        )
    }
}

/// A baseline as read.
#[derive(Debug)]
pub struct Baseline {
    pub path: PathBuf,
    /// The directory file names are relative to.
    dir: PathBuf,
    known: HashSet<(String, String, String)>,
}

const HEADER: &str = "# urdf-inertia check baseline: problems known when the check was adopted; `urdf-inertia check --baseline FILE` fails only on others.
# One problem a line: file (relative to this file), link, code, message, separated by tabs. Regenerate with `urdf-inertia check FILES --write-baseline FILE`.
";

/// `file` relative to `dir` where it is inside it (both canonical), else as given; `/` separators.
fn relative(dir: &Path, file: &Path) -> String {
    let rel = std::fs::canonicalize(file)
        .ok()
        .and_then(|f| f.strip_prefix(dir).ok().map(Path::to_path_buf))
        .unwrap_or_else(|| file.to_path_buf());
    let parts: Vec<String> = rel
        .components()
        .filter(|c| !matches!(c, std::path::Component::CurDir))
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    escape_control(&parts.join("/")).into_owned()
}

/// The canonical directory of a baseline file (which need not exist yet).
fn base_dir(path: &Path) -> PathBuf {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::canonicalize(parent).unwrap_or_else(|_| parent.to_path_buf())
}

/// One field of a line: no tab or line break (escaped, as everywhere in output).
fn field(s: &str) -> String {
    escape_control(s).into_owned()
}

impl Baseline {
    fn key(&self, p: &Problem) -> (String, String, String) {
        (
            relative(&self.dir, &p.problem.file),
            field(&p.problem.link),
            p.problem.code().to_string(),
        )
    }

    /// Reads a baseline; a missing file is an error that says how to make one.
    pub fn read(path: &Path) -> Result<Baseline, String> {
        let bytes = urdf_inertia::input::read_file(path, super::max_file_size()).map_err(|e| {
            format!(
                "{}: cannot read the baseline: {e}; `urdf-inertia check FILES --write-baseline {}` records today's problems",
                path.display(),
                path.display()
            )
        })?;
        let text = String::from_utf8(bytes)
            .map_err(|_| format!("{}: the baseline is not UTF-8", path.display()))?;
        let mut known = HashSet::new();
        for (i, line) in text.lines().enumerate() {
            if line.trim().is_empty() || line.starts_with('#') {
                continue;
            }
            let f: Vec<&str> = line.splitn(4, '\t').collect();
            if f.len() < 3 || Code::parse(f[2]).is_none() {
                return Err(format!(
                    "{}:{}: not a baseline line (FILE<TAB>LINK<TAB>CODE<TAB>MESSAGE): {}",
                    path.display(),
                    i + 1,
                    escape_control(line)
                ));
            }
            known.insert((f[0].to_string(), f[1].to_string(), f[2].to_uppercase()));
        }
        Ok(Baseline {
            path: path.to_path_buf(),
            dir: base_dir(path),
            known,
        })
    }

    /// Whether a problem is recorded (same file, link and code).
    pub fn contains(&self, p: &Problem) -> bool {
        self.known.contains(&self.key(p))
    }

    /// How many recorded problems this run did not meet (fixed since).
    pub fn unmatched(&self, problems: &[Problem]) -> usize {
        let seen: HashSet<_> = problems.iter().map(|p| self.key(p)).collect();
        self.known.difference(&seen).count()
    }

    /// Writes `problems` as a baseline at `path`: sorted, one a line, duplicates once.
    pub fn write(path: &Path, problems: &[Problem]) -> Result<(), String> {
        let dir = base_dir(path);
        let mut lines: Vec<String> = problems
            .iter()
            .map(|p| {
                format!(
                    "{}\t{}\t{}\t{}",
                    relative(&dir, &p.problem.file),
                    field(&p.problem.link),
                    p.problem.code(),
                    field(&p.problem.kind.to_string())
                )
            })
            .collect();
        lines.sort();
        lines.dedup();
        let mut text = HEADER.to_string();
        for l in lines {
            text.push_str(&l);
            text.push('\n');
        }
        super::write::write_output(path, text.as_bytes())
            .map_err(|e| format!("cannot write the baseline: {e}"))
    }
}
