//! Everything the commands print goes through here, so that a closed pipe or a full disk never panics
//! (`println!` does) and never goes unreported.
//!
//! * stdout closed by the reader (`diff … | head`, EPIPE): further output is dropped quietly and the exit
//!   status stays the one the work earned;
//! * any other stdout error (`>/dev/full`): reported once as "cannot write to stdout: …", and
//!   [`stdout_failed`] makes the command exit 2 — unless what failed was only the summary printed after
//!   the URDF was already written to a file ([`stdout_is_summary`]);
//! * stderr errors are ignored: there is nowhere left to report them.
//!
//! Colour: the `error[…]`, `warning[…]`, `note[…]` and `help` heads of stderr lines are coloured when
//! stderr is a terminal (as anstream decides: `NO_COLOR` wins, then `CLICOLOR_FORCE`, then
//! `CLICOLOR=0`, then a terminal whose `TERM` is not `dumb`). stdout (the URDF, tables, JSON) is
//! never coloured.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::OnceLock;

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

/// One line on stderr, control characters escaped (see [`sanitised_line`]), its head coloured on a
/// terminal (see [`coloured`]).
pub fn err_line(line: &str) {
    let line = sanitised_line(line);
    if stderr_colour() {
        write_stderr(coloured(&line).as_bytes());
    } else {
        write_stderr(line.as_bytes());
    }
}

/// Whether stderr gets colours, as anstream (clap's own) decides: `NO_COLOR`, `CLICOLOR_FORCE`,
/// `CLICOLOR`, a terminal that supports colour; decided once.
fn stderr_colour() -> bool {
    static CHOICE: OnceLock<bool> = OnceLock::new();
    *CHOICE
        .get_or_init(|| anstream::AutoStream::choice(&io::stderr()) != anstream::ColorChoice::Never)
}

/// `line` (already sanitised: it holds no ESC of its own) with its head coloured as compilers do:
/// `error[…]` bold red, `warning[…]` bold yellow, `note[…]` bold green, `help` bold cyan; the
/// indentation before it is kept.
fn coloured(line: &str) -> String {
    let body = line.trim_start_matches(' ');
    let indent = &line[..line.len() - body.len()];
    for (word, colour) in [("error", 31), ("warning", 33), ("note", 32), ("help", 36)] {
        let Some(rest) = body.strip_prefix(word) else {
            continue;
        };
        let code_len = if rest.starts_with('[') {
            rest.find(']').map_or(0, |i| i + 1)
        } else {
            0
        };
        if rest[code_len..].starts_with(':') {
            let head = &body[..word.len() + code_len];
            return format!(
                "{indent}\x1b[1;{colour}m{head}\x1b[0m{}",
                &body[word.len() + code_len..]
            );
        }
    }
    line.to_string()
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

#[cfg(test)]
mod tests {
    use super::coloured;

    #[test]
    fn only_the_head_is_coloured() {
        assert_eq!(
            coloured("  warning[UI101]: a: b\n"),
            "  \x1b[1;33mwarning[UI101]\x1b[0m: a: b\n"
        );
        assert_eq!(coloured("error: x\n"), "\x1b[1;31merror\x1b[0m: x\n");
        assert_eq!(coloured("warnings: x\n"), "warnings: x\n");
        assert_eq!(coloured("urdf-inertia: x\n"), "urdf-inertia: x\n");
    }
}
