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
mod compare;
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
    use urdf_inertia::input;
    for (flag, value, env, set) in [
        (
            "--max-file-size",
            max_size,
            input::MAX_FILE_SIZE_ENV,
            input::set_max_file_size as fn(u64),
        ),
        (
            "--max-total-read",
            max_total,
            input::MAX_TOTAL_READ_ENV,
            input::set_max_total_read,
        ),
    ] {
        let from_env = std::env::var(env).ok();
        if let Some((what, s)) = value
            .clone()
            .map(|s| (flag, s))
            .or(from_env.map(|s| (env, s)))
        {
            match input::parse_size(&s) {
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
    if let Some(note) = urdf_inertia::threads::note() {
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
