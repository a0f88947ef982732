//! `xacro`: a xacro file expanded to URDF on stdout, as the `xacro` tool prints it; expansion
//! errors as `FILE:LINE: …` on stderr with exit 2.

use super::args::XacroArgs;
use super::ExitStatus;
use urdf_inertia::xacro;

pub fn run(a: &XacroArgs) -> ExitStatus {
    let parsed = (|| -> Result<_, String> {
        let args = a
            .args
            .iter()
            .map(|s| super::parse_xacro_arg(s))
            .collect::<Result<Vec<_>, String>>()?;
        let pkgs = a
            .package_path
            .iter()
            .map(|p| super::parse_package_arg(p))
            .collect::<Result<Vec<_>, String>>()?;
        Ok((args, pkgs))
    })();
    let (args, pkgs) = match parsed {
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
            for w in &e.warnings {
                errln!(
                    "warning[{}]: {w}",
                    urdf_inertia::diagnostic::Code::XacroWarning
                );
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
