//! Writing the filled URDF (`-o FILE`, `-o -`, `-i`): the write policy documented in the README.
//!
//! * A regular file (or a symlink to one, followed to its target, dangling ones included) is replaced
//!   atomically: a temporary file `.NAME.urdf-inertia.PID.N.tmp` in the target's directory (NAME cut
//!   to its first 64 bytes, so that a name near `NAME_MAX` still has room), created with the target's
//!   mode (never wider), given the target's owner and group where the process may, and its extended
//!   attributes (POSIX ACLs among them) where the file system and the process allow, synced, then
//!   renamed over the target. It is removed on error and on every catchable signal that would end
//!   the process (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF,
//!   SIGXCPU: exit 130); SIGXFSZ is caught and ignored, so a file-size limit is an EFBIG write error.
//! * A target whose bytes are already the output is not written at all (same inode, same times).
//! * `-i`: the URDF's size, modification time and inode are noted before it is read, and checked
//!   again just before the rename: an edit made meanwhile is kept, and the run fails saying so.
//!   `-i` on something that is not a regular file named by its path (`/dev/stdin`, `/proc/self/fd/0`)
//!   is refused.
//! * Anything else that exists (a character device such as `/dev/null`, a FIFO, `/dev/stdout` and other
//!   `/proc` or `/dev/fd` links) is opened for writing and written directly: never replaced, never
//!   truncated unless it turns out to be a regular file.
//! * `-` is stdout.
//! * Refused, with the reason: a target without any write bit (also as root, who bypasses mode bits), a
//!   target with more than one hard link (a rename would split it from its other names), a directory
//!   without any write bit, a directory as target.

use super::output;
use signal_hook::consts::signal::{
    SIGALRM, SIGHUP, SIGINT, SIGPROF, SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGVTALRM, SIGXCPU,
    SIGXFSZ,
};
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

/// Catchable signals whose default action ends the process: each removes a live temporary file.
/// (SIGPIPE is ignored by the Rust runtime: a closed pipe is an EPIPE error where it is written.)
const ENDING_SIGNALS: [i32; 10] = [
    SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU,
];

/// The longest part of the target's name kept in the temporary file's name, in bytes.
const TEMP_NAME_PART: usize = 64;

static TEMP_COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Exit status after SIGINT, SIGTERM or SIGHUP (128 + SIGINT, as shells report an interrupted command).
const SIGNAL_EXIT: i32 = 130;

/// Test hook: with this variable set, a write pauses after its temporary file is complete and before the
/// rename, says so on stderr and waits for a line on stdin (lets a test deliver a signal at that point
/// without depending on timing).
const HOLD_ENV: &str = "URDF_INERTIA_TEST_HOLD_TEMP";

/// What the signal handler does, without a thread of its own (a handler may only set flags or exit; the
/// `ctrlc` crate used before ran the clean-up on a thread started in every process, 0.15–0.45 ms of
/// task-clock of a ~2 ms `fill` without meshes, perf stat on 2 cores). Outside a write the handler
/// exits 130 at once. While a temporary file exists it only notes the signal: the writer checks
/// between its steps (creating, writing and syncing, the test hold, the rename), removes the file and
/// exits 130 at the next one (a signal during a slow sync acts when the sync returns), so the target
/// is either untouched or wholly replaced.
#[derive(Debug)]
struct Signals {
    /// False while a temporary file exists; the handler exits when true.
    exit_at_once: Arc<AtomicBool>,
    /// Set by the handler on every signal.
    caught: Arc<AtomicBool>,
}

static SIGNALS: OnceLock<Signals> = OnceLock::new();

/// Installs the handling of [`ENDING_SIGNALS`] that removes a live temporary file, then exits 130,
/// and catches SIGXFSZ so that exceeding a file-size limit is a write error, not a killed process.
pub fn remove_temp_files_on_signal() {
    SIGNALS.get_or_init(|| {
        let s = Signals {
            exit_at_once: Arc::new(AtomicBool::new(true)),
            caught: Arc::new(AtomicBool::new(false)),
        };
        let _ = signal_hook::flag::register(SIGXFSZ, Arc::new(AtomicBool::new(false)));
        for signal in ENDING_SIGNALS {
            // These can always be caught; were one refused, it would keep its default action
            // (ending the process), which leaves a temporary file but never a damaged target.
            let _ = signal_hook::flag::register(signal, Arc::clone(&s.caught));
            let _ = signal_hook::flag::register_conditional_shutdown(
                signal,
                SIGNAL_EXIT,
                Arc::clone(&s.exit_at_once),
            );
        }
        s
    });
}

/// Whether a signal came while the handler only noted it.
fn signalled() -> bool {
    SIGNALS
        .get()
        .is_some_and(|s| s.caught.load(Ordering::SeqCst))
}

/// Removes `tmp` and exits 130 if a signal came.
fn exit_if_signalled(tmp: &Path) {
    if signalled() {
        let _ = fs::remove_file(tmp);
        std::process::exit(SIGNAL_EXIT);
    }
}

/// Whether the handler exits at once (false while a temporary file exists).
fn exit_at_once(yes: bool) {
    if let Some(s) = SIGNALS.get() {
        s.exit_at_once.store(yes, Ordering::SeqCst);
    }
}

/// Where a path leads once symlinks are followed.
#[derive(Debug)]
enum Resolved {
    /// A regular file: replace it through a temporary file.
    Regular(PathBuf, fs::Metadata),
    /// Nothing there yet (the path, or a dangling symlink's target): create it through a temporary file.
    New(PathBuf),
    /// A device, FIFO, socket or a `/proc` fd link: write it directly.
    Direct(PathBuf),
}

fn resolve(path: &Path) -> Result<Resolved, String> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        // /dev/stdout, /dev/fd/N and /proc/self/fd/N lead to whatever the descriptor is: open them.
        if p.starts_with("/proc") || p.starts_with("/dev/fd") {
            return Ok(Resolved::Direct(path.to_path_buf()));
        }
        let meta = match fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Resolved::New(p)),
            Err(e) => return Err(format!("{}: cannot write: {e}", p.display())),
        };
        let ft = meta.file_type();
        if ft.is_symlink() {
            let target = fs::read_link(&p)
                .map_err(|e| format!("{}: cannot read the symlink: {e}", p.display()))?;
            p = match p.parent() {
                Some(dir) if target.is_relative() => dir.join(target),
                _ => target,
            };
        } else if ft.is_dir() {
            return Err(format!("{}: is a directory", p.display()));
        } else if ft.is_file() {
            return Ok(Resolved::Regular(p, meta));
        } else {
            return Ok(Resolved::Direct(p));
        }
    }
    Err(format!(
        "{}: too many levels of symbolic links",
        path.display()
    ))
}

/// What identifies a file's content without reading it: device, inode, size and modification time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stamp {
    dev: u64,
    ino: u64,
    size: u64,
    mtime: (i64, i64),
}

impl Stamp {
    fn of(meta: &fs::Metadata) -> Stamp {
        Stamp {
            dev: meta.dev(),
            ino: meta.ino(),
            size: meta.size(),
            mtime: (meta.mtime(), meta.mtime_nsec()),
        }
    }
}

/// The stamps of the URDFs read, by the path they were read by (for `-i`'s changed-since-read check).
static READ_STAMPS: Mutex<Vec<(PathBuf, Stamp)>> = Mutex::new(Vec::new());

/// Notes the state of `path` before it is read, for [`write_in_place`].
pub fn remember_before_reading(path: &Path) {
    if let Ok(meta) = fs::metadata(path) {
        READ_STAMPS
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push((path.to_path_buf(), Stamp::of(&meta)));
    }
}

fn stamp_when_read(path: &Path) -> Option<Stamp> {
    READ_STAMPS
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .iter()
        .rev()
        .find(|(p, _)| p == path)
        .map(|(_, s)| *s)
}

/// Writes `text` over the URDF it was computed from (`-i`): only a regular file named by its path,
/// and only if it has not changed since it was read (see the module docs).
pub fn write_in_place(path: &Path, text: &[u8]) -> Result<(), String> {
    match resolve(path)? {
        Resolved::Regular(..) => {}
        _ => {
            return Err(format!(
                "{}: -i rewrites a regular file named by its path, and this is not one (stdin, a device or a descriptor link); write with -o FILE instead",
                path.display()
            ))
        }
    }
    write_checked(path, text, stamp_when_read(path))
}

/// Writes `text` to `path` (`-` is stdout) following the module's write policy.
pub fn write_output(path: &Path, text: &[u8]) -> Result<(), String> {
    write_checked(path, text, None)
}

/// Whether the regular file `meta` describes at `p` holds exactly `text` (read only when the sizes
/// agree).
fn holds(p: &Path, meta: &fs::Metadata, text: &[u8]) -> bool {
    meta.len() == text.len() as u64 && fs::read(p).is_ok_and(|bytes| bytes == text)
}

fn write_checked(path: &Path, text: &[u8], expected: Option<Stamp>) -> Result<(), String> {
    if path.as_os_str() == "-" {
        return output::write_stdout(text).map_err(|e| format!("cannot write to stdout: {e}"));
    }
    match resolve(path)? {
        Resolved::Direct(p) => write_direct(&p, text),
        Resolved::New(p) => replace_through_temp(&p, None, text, None),
        Resolved::Regular(p, meta) => {
            if expected.is_some_and(|s| s != Stamp::of(&meta)) {
                return Err(changed(&p));
            }
            if holds(&p, &meta, text) {
                return Ok(());
            }
            let mode = meta.permissions().mode() & 0o7777;
            if mode & 0o222 == 0 {
                return Err(format!(
                    "{}: the file is read-only (mode {mode:04o}); make it writable (chmod u+w) to let urdf-inertia rewrite it",
                    p.display()
                ));
            }
            if meta.nlink() > 1 {
                return Err(format!(
                    "{}: the file has {} hard links; replacing it would split this name from the others (write with -o NEW and copy NEW over it to update every link)",
                    p.display(),
                    meta.nlink()
                ));
            }
            // The permission check the kernel would do for an ordinary writer (root passes it).
            OpenOptions::new()
                .write(true)
                .open(&p)
                .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
            replace_through_temp(&p, Some(&meta), text, expected)
        }
    }
}

fn changed(p: &Path) -> String {
    format!(
        "{}: the file changed while urdf-inertia worked on it; nothing written (the change is kept): run again",
        p.display()
    )
}

fn write_direct(p: &Path, text: &[u8]) -> Result<(), String> {
    let fail = |e: io::Error| format!("{}: cannot write: {e}", p.display());
    let mut f = OpenOptions::new().write(true).open(p).map_err(fail)?;
    // `/dev/stdout` redirected to a file: start it afresh, as `>` does. Devices and FIFOs are not touched.
    if f.metadata().is_ok_and(|m| m.is_file()) {
        f.set_len(0).map_err(fail)?;
    }
    f.write_all(text).and_then(|()| f.flush()).map_err(fail)
}

/// Writes `text` to a temporary file beside `target` and renames it over `target`. `original` is the
/// target's metadata when it exists (mode, owner, group and extended attributes to keep); with
/// `expected`, the target must still have that stamp just before the rename.
fn replace_through_temp(
    target: &Path,
    original: Option<&fs::Metadata>,
    text: &[u8],
    expected: Option<Stamp>,
) -> Result<(), String> {
    let dir = target
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut name = target
        .file_name()
        .map_or_else(|| "urdf".into(), |n| n.to_string_lossy().into_owned());
    if name.len() > TEMP_NAME_PART {
        let mut end = TEMP_NAME_PART;
        while !name.is_char_boundary(end) {
            end -= 1;
        }
        name.truncate(end);
    }
    let tmp = dir.join(format!(
        ".{name}.urdf-inertia.{}.{}.tmp",
        std::process::id(),
        TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let dir_error = |e: &dyn std::fmt::Display| {
        format!(
            "{}: cannot write {}: the temporary file {} cannot be created in directory {}: {e}",
            target.display(),
            target.display(),
            tmp.display(),
            dir.display()
        )
    };
    // Root ignores a directory's mode bits; the policy does not.
    if let Ok(m) = fs::metadata(dir) {
        let mode = m.permissions().mode() & 0o7777;
        if mode & 0o222 == 0 {
            return Err(dir_error(&format!(
                "the directory is read-only (mode {mode:04o})"
            )));
        }
    }
    let mode = original.map_or(0o666, |m| m.permissions().mode() & 0o7777);
    // From here until the temporary file is renamed or removed, a signal is only noted (see [`Signals`]).
    exit_at_once(false);
    let result = OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(mode)
        .open(&tmp)
        .map_err(|e| dir_error(&e))
        .and_then(|mut file| {
            let result = fill_temp(&mut file, &tmp, original, mode, text).and_then(|()| {
                if original.is_some() {
                    copy_xattrs(target, &tmp);
                }
                exit_if_signalled(&tmp);
                hold_for_test(&tmp);
                exit_if_signalled(&tmp);
                if let Some(expected) = expected {
                    if fs::metadata(target).map(|m| Stamp::of(&m)).ok() != Some(expected) {
                        return Err(changed(target));
                    }
                }
                fs::rename(&tmp, target).map_err(|e| {
                    format!(
                        "{}: cannot replace it with the temporary file {}: {e}",
                        target.display(),
                        tmp.display()
                    )
                })
            });
            if result.is_err() {
                let _ = fs::remove_file(&tmp);
            }
            result
        });
    exit_at_once(true);
    // A signal during the rename, or during a write that failed: the temporary file is gone.
    if signalled() {
        std::process::exit(SIGNAL_EXIT);
    }
    result
}

fn fill_temp(
    file: &mut File,
    tmp: &Path,
    original: Option<&fs::Metadata>,
    mode: u32,
    text: &[u8],
) -> Result<(), String> {
    let fail = |e: io::Error| format!("{}: cannot write the temporary file: {e}", tmp.display());
    if let Some(m) = original {
        // Keep the owner and group; only root may give a file away, others may still keep the group.
        let mine = file.metadata().map_err(fail)?;
        if (mine.uid() != m.uid() || mine.gid() != m.gid())
            && std::os::unix::fs::chown(tmp, Some(m.uid()), Some(m.gid())).is_err()
        {
            let _ = std::os::unix::fs::chown(tmp, None, Some(m.gid()));
        }
        // Exactly the original's mode: creation masked it with the umask, and chown clears set-id bits.
        file.set_permissions(fs::Permissions::from_mode(mode))
            .map_err(fail)?;
    }
    file.write_all(text).map_err(fail)?;
    file.sync_all().map_err(fail)
}

/// Copies the target's extended attributes (POSIX ACLs are `system.posix_acl_*` attributes) to the
/// temporary file, each one the process may set: an attribute the file system or the process's
/// privileges refuse (`security.*` without root, a file system without xattrs) is left out, as `cp -a`
/// does.
fn copy_xattrs(target: &Path, tmp: &Path) {
    let Ok(names) = xattr::list(target) else {
        return;
    };
    for name in names {
        if let Ok(Some(value)) = xattr::get(target, &name) {
            let _ = xattr::set(tmp, &name, &value);
        }
    }
}

fn hold_for_test(tmp: &Path) {
    if std::env::var_os(HOLD_ENV).is_some() {
        output::err_line(&format!("holding temporary file {}", tmp.display()));
        // The line is awaited on a helper thread: this one keeps checking for a signal, which the
        // handler only notes while the temporary file exists (stdin's read would just resume).
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = io::stdin().read_line(&mut line);
            let _ = tx.send(());
        });
        while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
            rx.recv_timeout(std::time::Duration::from_millis(5))
        {
            exit_if_signalled(tmp);
        }
    }
}
