//! `xacro`: a xacro file expanded to URDF on stdout, as the `xacro` tool prints it; expansion
//! errors as `FILE:LINE: …` on stderr with exit 2. Its warnings (UI208) follow the diagnostic flags
//! and `urdf-inertia.toml` as the other commands' do; the file's `package-path` applies too.

use super::args::XacroArgs;
use super::policy::Policy;
use super::ExitStatus;
use urdf_inertia::diagnostic::{Code, Diagnostic, Severity};
use urdf_inertia::xacro;

pub fn run(a: &XacroArgs) -> ExitStatus {
    let parsed = (|| -> Result<_, String> {
        let (policy, settings) = Policy::new(&a.diagnostics, false, Some(&a.file))?;
        let args = a
            .args
            .iter()
            .map(|s| super::parse_xacro_arg(s))
            .collect::<Result<Vec<_>, String>>()?;
        let pkgs = a
            .package_path
            .iter()
            .chain(&settings.package_path)
            .map(|p| super::parse_package_arg(p))
            .collect::<Result<Vec<_>, String>>()?;
        Ok((policy, args, pkgs))
    })();
    let (policy, args, pkgs) = match parsed {
        Ok(p) => p,
        Err(e) => {
            errln!("error: {e}");
            return ExitStatus::Error;
        }
    };
    let resolver = super::package_resolver(&pkgs);
    let opts = super::xacro_options(args, &resolver);
    match xacro::expand_file(&a.file, &opts) {
        Ok(e) => {
            let mut warnings: Vec<Diagnostic> = e
                .warnings
                .iter()
                .map(|w| Diagnostic::new(Code::XacroWarning, w.as_str()))
                .collect();
            policy.apply_all(&mut warnings);
            for d in warnings.iter().filter(|d| policy.shows(d)) {
                errln!("{}: {}", d.head(), d.message);
            }
            if warnings.iter().any(|d| d.severity == Severity::Error) {
                errln!(
                    "error: {}: a warning was made an error (--warn-as-error); nothing printed",
                    a.file.display()
                );
                return ExitStatus::Error;
            }
            // A failure is reported there and turns the exit status to 2 (`output::stdout_failed`).
            let _ = super::output::write_stdout(e.text.as_bytes());
            ExitStatus::Success
        }
        Err(e) => {
            errln!("error: {e}");
            ExitStatus::Error
        }
    }
}
