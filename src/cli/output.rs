//! Everything the commands print goes through here, so that a closed pipe or a full disk never panics
//! (`println!` does) and never goes unreported.
//!
//! * stdout closed by the reader (`diff … | head`, EPIPE): further output is dropped quietly and the exit
//!   status stays the one the work earned;
//! * any other stdout error (`>/dev/full`): reported once as "cannot write to stdout: …", and
//!   [`stdout_failed`] makes the command exit 2 — unless what failed was only the summary printed after
//!   the URDF was already written to a file ([`stdout_is_summary`]);
//! * stderr errors are ignored: there is nowhere left to report them.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};

const OK: u8 = 0;
const BROKEN_PIPE: u8 = 1;
const FAILED: u8 = 2;

static STDOUT: AtomicU8 = AtomicU8::new(OK);
static SUMMARY_ONLY: AtomicBool = AtomicBool::new(false);

/// Writes `bytes` to stdout and flushes. A closed pipe is not an error (the reader has all it wanted);
/// any other error is reported on stderr once and returned.
pub fn write_stdout(bytes: &[u8]) -> io::Result<()> {
    match STDOUT.load(Ordering::Relaxed) {
        OK => {}
        BROKEN_PIPE => return Ok(()),
        _ => return Err(io::Error::other("stdout failed earlier")),
    }
    let mut out = io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => {
            STDOUT.store(BROKEN_PIPE, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => {
            STDOUT.store(FAILED, Ordering::Relaxed);
            write_stderr(format!("error: cannot write to stdout: {e}\n").as_bytes());
            Err(e)
        }
    }
}

/// Writes to stderr, ignoring failure.
pub fn write_stderr(bytes: &[u8]) {
    let mut err = io::stderr().lock();
    let _ = err.write_all(bytes).and_then(|()| err.flush());
}

/// `line` with every control character but its line breaks escaped (`\x1b`, `\r`, `\t`, ...), and a
/// line break: text from input files (a link name holding ESC) never reaches the terminal raw. Line
/// breaks inside names are escaped where the names are put into messages
/// ([`urdf_inertia::text::escape_control`]); the ones left here are the messages' own.
fn sanitised_line(line: &str) -> String {
    let mut s = String::with_capacity(line.len() + 1);
    for (i, piece) in line.split('\n').enumerate() {
        if i > 0 {
            s.push('\n');
        }
        s.push_str(&urdf_inertia::text::escape_control(piece));
    }
    s.push('\n');
    s
}

/// One line on stdout (see [`write_stdout`]; the error is already reported and remembered), control
/// characters escaped (see [`sanitised_line`]).
pub fn out_line(line: &str) {
    let _ = write_stdout(sanitised_line(line).as_bytes());
}

/// One line on stderr, control characters escaped (see [`sanitised_line`]).
pub fn err_line(line: &str) {
    write_stderr(sanitised_line(line).as_bytes());
}

/// From now on stdout carries only a summary of work already done (the URDF went to a file): failing to
/// print it does not change the exit status.
pub fn stdout_is_summary() {
    SUMMARY_ONLY.store(true, Ordering::Relaxed);
}

/// Whether writing to stdout failed (other than a closed pipe) where it matters for the exit status.
pub fn stdout_failed() -> bool {
    STDOUT.load(Ordering::Relaxed) == FAILED && !SUMMARY_ONLY.load(Ordering::Relaxed)
}
