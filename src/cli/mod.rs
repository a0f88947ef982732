//! Command line: clap parses raw arguments, they are validated into a configuration before any work
//! starts, and each command returns an [`ExitStatus`]: 0 ok, 1 check found problems, 2 error.

/// `println!` through [`output`]: never panics on a closed pipe or a full disk.
macro_rules! outln {
    ($($t:tt)*) => { $crate::cli::output::out_line(&format!($($t)*)) };
}

/// `eprintln!` that ignores a failing stderr.
macro_rules! errln {
    ($($t:tt)*) => { $crate::cli::output::err_line(&format!($($t)*)) };
}

mod args;
mod baseline;
mod mesh_cmd;
mod noops;
pub mod output;
mod policy;
mod robot_cmd;
mod summary;
pub mod write;
mod xacro_cmd;

use clap::Parser;

pub use args::{Args, Command};

/// The process exit code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitStatus {
    /// Everything done, nothing found.
    Success = 0,
    /// `check` (or `diff`) found problems in the robot.
    Problems = 1,
    /// The tool could not do its job: bad input, unreadable files, missing meshes.
    Error = 2,
}

/// The environment variable that sets the limit on one input file when `--max-file-size` is not given.
const MAX_FILE_SIZE_ENV: &str = "URDF_INERTIA_MAX_FILE_SIZE";

/// The environment variable that sets the run's budget of bytes read from all files together when
/// `--max-total-read` is not given (default [`urdf_inertia::input::DEFAULT_MAX_TOTAL_READ`]).
const MAX_TOTAL_READ_ENV: &str = "URDF_INERTIA_MAX_TOTAL_READ";

/// The run's limit on one input file, decided once from the command line and the environment
/// before any command starts; the library is handed it wherever it reads.
static MAX_FILE_SIZE: std::sync::OnceLock<u64> = std::sync::OnceLock::new();

/// The limit on one input file: `--max-file-size`, else `URDF_INERTIA_MAX_FILE_SIZE`, else the
/// library's default.
pub fn max_file_size() -> u64 {
    MAX_FILE_SIZE
        .get()
        .copied()
        .unwrap_or(urdf_inertia::input::DEFAULT_MAX_FILE_SIZE)
}

/// Parses `--package-path NAME=DIR`.
pub fn parse_package_arg(arg: &str) -> Result<(String, std::path::PathBuf), String> {
    match arg.split_once('=') {
        Some((name, dir)) if !name.is_empty() && !dir.is_empty() => {
            Ok((name.to_string(), std::path::PathBuf::from(dir)))
        }
        _ => Err(format!("--package-path `{arg}` should be NAME=DIR")),
    }
}

/// The package resolver of a run: `--package-path` packages first, then `ROS_PACKAGE_PATH` and
/// `AMENT_PREFIX_PATH` from the environment (the library reads no environment).
pub fn package_resolver(
    packages: &[(String, std::path::PathBuf)],
) -> urdf_inertia::PackageResolver {
    let split = |var: &str| -> Vec<std::path::PathBuf> {
        std::env::var_os(var)
            .map(|v| std::env::split_paths(&v).collect())
            .unwrap_or_default()
    };
    urdf_inertia::PackageResolver::new()
        .with_packages(packages)
        .with_ros_package_path(split("ROS_PACKAGE_PATH"))
        .with_ament_prefix_path(split("AMENT_PREFIX_PATH"))
        .with_max_file_size(max_file_size())
}

/// Parses `NAME:=VALUE` (a xacro argument on the command line).
pub fn parse_xacro_arg(s: &str) -> Result<(String, String), String> {
    match s.split_once(":=") {
        Some((k, v)) if !k.is_empty() => Ok((k.to_string(), v.to_string())),
        _ => Err(format!("`{s}` is not a xacro argument: write NAME:=VALUE")),
    }
}

/// xacro's options for this process: its environment (`$(env)`, `$(optenv)`) and working directory
/// (`$(cwd)`), which the library does not read itself.
pub fn xacro_options(
    args: Vec<(String, String)>,
    resolver: &urdf_inertia::PackageResolver,
) -> urdf_inertia::xacro::Options<'_> {
    urdf_inertia::xacro::Options {
        args,
        resolver,
        env: std::env::vars().collect(),
        cwd: std::env::current_dir().unwrap_or_default(),
    }
}

/// Parses the command line and runs the command; returns the exit code.
pub fn main() -> i32 {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let code = if e.use_stderr() {
                ExitStatus::Error as i32
            } else {
                0
            };
            let _ = e.print();
            return code;
        }
    };
    write::remove_temp_files_on_signal();
    let (max_size, max_total) = match &args.command {
        Command::Mesh(m) => (&m.max_file_size, &m.max_total_read),
        Command::Fill(f) => (&f.source.max_file_size, &f.source.max_total_read),
        Command::Diff(d) => (&d.source.max_file_size, &d.source.max_total_read),
        Command::Check(c) => (&c.source.max_file_size, &c.source.max_total_read),
        Command::Xacro(x) => (&x.max_file_size, &x.max_total_read),
    };
    // The library has no budget unless told; a run of the command has one.
    urdf_inertia::input::set_max_total_read(urdf_inertia::input::DEFAULT_MAX_TOTAL_READ);
    let set_file_size = |n: u64| {
        let _ = MAX_FILE_SIZE.set(n);
    };
    for (flag, value, env, set) in [
        (
            "--max-file-size",
            max_size,
            MAX_FILE_SIZE_ENV,
            &set_file_size as &dyn Fn(u64),
        ),
        (
            "--max-total-read",
            max_total,
            MAX_TOTAL_READ_ENV,
            &urdf_inertia::input::set_max_total_read,
        ),
    ] {
        let from_env = std::env::var(env).ok();
        if let Some((what, s)) = value
            .clone()
            .map(|s| (flag, s))
            .or(from_env.map(|s| (env, s)))
        {
            match urdf_inertia::input::parse_size(&s) {
                Ok(n) => set(n),
                Err(e) => {
                    errln!("error: {what}: {e}");
                    return ExitStatus::Error as i32;
                }
            }
        }
    }
    let status = match args.command {
        Command::Mesh(m) => mesh_cmd::run(&m),
        Command::Fill(f) => robot_cmd::fill(&f),
        Command::Diff(d) => robot_cmd::diff(&d),
        Command::Check(c) => robot_cmd::check(&c),
        Command::Xacro(x) => xacro_cmd::run(&x),
    };
    if let Some(note) = urdf_inertia::thread_note() {
        errln!(
            "warning[{}]: {note}",
            urdf_inertia::diagnostic::Code::RunThreads
        );
    }
    if output::stdout_failed() {
        return ExitStatus::Error as i32;
    }
    status as i32
}
