//! Reading input files with two guards: only regular files are read (a FIFO would hang, `/dev/zero`
//! or `/dev/urandom` never end), and no more than a size limit, 1 GiB by default, set with
//! `--max-file-size` or the `URDF_INERTIA_MAX_FILE_SIZE` environment variable (the CLI reads both);
//! and a budget for all the files of one run together, 16 GiB by default (`--max-total-read`,
//! `URDF_INERTIA_MAX_TOTAL_READ`): a file is charged its length when it is opened, so that a robot
//! naming thousands of large files (each within the limit) ends with an error naming the file that
//! would exceed the budget instead of reading for hours.
//!
//! This is the one way the library reads a file: URDFs, meshes, glTF buffers, density maps and
//! `package.xml` all go through [`read_file`] or [`open_file`] (a test in tests/regression.rs puts a
//! FIFO and a `/dev/zero` symlink at each); a new reader (xacro includes, YAML) uses them too. The
//! `_within` forms take the limit as an argument, for callers that carry their own.

use std::fs::{self, File};
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// The default limit on one input file: 1 GiB.
pub const DEFAULT_MAX_FILE_SIZE: u64 = 1 << 30;

/// The environment variable that sets the limit when `--max-file-size` is not given.
pub const MAX_FILE_SIZE_ENV: &str = "URDF_INERTIA_MAX_FILE_SIZE";

/// The default budget of bytes read in one run, all files together: 16 GiB, sixteen files at the
/// one-file limit. No real robot comes near it: the largest of example-robot-data's 40 robots reads
/// 40 MB of files, all 40 together 411 MB.
pub const DEFAULT_MAX_TOTAL_READ: u64 = 16 << 30;

/// The environment variable that sets the run's budget when `--max-total-read` is not given.
pub const MAX_TOTAL_READ_ENV: &str = "URDF_INERTIA_MAX_TOTAL_READ";

/// What the gate lets a run read: the limit on one file, the budget for all files together, and
/// the bytes charged to that budget so far.
struct ReadLimits {
    per_file: AtomicU64,
    total: AtomicU64,
    charged: AtomicU64,
}

impl ReadLimits {
    /// Charges a file of `len` bytes to the budget, or says why it cannot be read (the budget is left
    /// as it was).
    fn charge(&self, len: u64) -> Result<(), String> {
        let total = self.total.load(Ordering::Relaxed);
        self.charged
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |c| {
                c.checked_add(len).filter(|&sum| sum <= total)
            })
            .map(drop)
            .map_err(|charged| {
                format!(
                    "is over the budget of {total} bytes read from all files together in this run ({len} bytes, after {charged} bytes read before it); raise it with --max-total-read SIZE or {MAX_TOTAL_READ_ENV}"
                )
            })
    }
}

// The one process-wide value of the gate (it held the one-file limit alone before the budget).
static LIMITS: ReadLimits = ReadLimits {
    per_file: AtomicU64::new(DEFAULT_MAX_FILE_SIZE),
    total: AtomicU64::new(DEFAULT_MAX_TOTAL_READ),
    charged: AtomicU64::new(0),
};

/// Sets the process-wide limit on the size of one input file, in bytes.
pub fn set_max_file_size(bytes: u64) {
    LIMITS.per_file.store(bytes, Ordering::Relaxed);
}

/// The process-wide limit on the size of one input file, in bytes.
pub fn max_file_size() -> u64 {
    LIMITS.per_file.load(Ordering::Relaxed)
}

/// Sets the budget of bytes the process may read from all files together.
pub fn set_max_total_read(bytes: u64) {
    LIMITS.total.store(bytes, Ordering::Relaxed);
}

/// The budget of bytes the process may read from all files together.
pub fn max_total_read() -> u64 {
    LIMITS.total.load(Ordering::Relaxed)
}

/// The bytes charged to the budget so far: the lengths of the files opened.
pub fn total_read() -> u64 {
    LIMITS.charged.load(Ordering::Relaxed)
}

/// Parses a size: bytes, or a number with a `K`, `M` or `G` suffix (powers of 1024).
pub fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, unit) = match t.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((i, _)) => (&t[..i], &t[i..]),
        None => (t, ""),
    };
    let factor: u64 = match unit.to_ascii_uppercase().trim_end_matches(['B', 'I']) {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => {
            return Err(format!(
                "`{s}` is not a size (bytes, or a number with K, M or G)"
            ))
        }
    };
    digits
        .parse::<u64>()
        .ok()
        .and_then(|n| n.checked_mul(factor))
        .ok_or_else(|| format!("`{s}` is not a size (bytes, or a number with K, M or G)"))
}

/// What a file that is not a regular file is, for the message.
fn kind(ft: fs::FileType) -> &'static str {
    if ft.is_dir() {
        "a directory"
    } else {
        special_kind(ft)
    }
}

// FIFOs, devices and sockets are Unix file types; elsewhere the library names them generically.
#[cfg(unix)]
fn special_kind(ft: fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if ft.is_fifo() {
        "a FIFO"
    } else if ft.is_char_device() {
        "a character device"
    } else if ft.is_block_device() {
        "a block device"
    } else if ft.is_socket() {
        "a socket"
    } else {
        "not a file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: fs::FileType) -> &'static str {
    "not a file"
}

/// The whole content of a regular file no larger than [`max_file_size`]. The error says why, without
/// the path (callers name the file and what it is).
pub fn read_file(path: &Path) -> Result<Vec<u8>, String> {
    read_file_within(path, max_file_size())
}

/// [`read_file`] with the size limit `limit` instead of the process-wide one.
pub fn read_file_within(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let (file, len) = open_file_within(path, limit)?;
    read_rest_within(file, Vec::with_capacity(len as usize), limit)
}

/// A regular file no larger than [`max_file_size`], opened for reading, and its length: for readers
/// that stream a big file instead of holding all of it (then they must read no more than the
/// length, and treat a shorter file as truncated).
pub fn open_file(path: &Path) -> Result<(File, u64), String> {
    open_file_within(path, max_file_size())
}

/// [`open_file`] with the size limit `limit` instead of the process-wide one (the file is charged to
/// the run's budget all the same).
pub fn open_file_within(path: &Path, limit: u64) -> Result<(File, u64), String> {
    let regular = |meta: &fs::Metadata| {
        if meta.is_file() {
            Ok(())
        } else {
            Err(format!(
                "is not a regular file ({})",
                kind(meta.file_type())
            ))
        }
    };
    // Checked before opening: opening a FIFO for reading blocks until someone writes.
    regular(&fs::metadata(path).map_err(|e| e.to_string())?)?;
    let file = File::open(path).map_err(|e| e.to_string())?;
    let meta = file.metadata().map_err(|e| e.to_string())?;
    regular(&meta)?;
    if meta.len() > limit {
        return Err(too_large(limit));
    }
    LIMITS.charge(meta.len())?;
    Ok((file, meta.len()))
}

/// Appends the rest of `file` to `bytes`, up to [`max_file_size`] in all (a file can grow after its
/// size was checked).
pub fn read_rest(file: impl Read, bytes: Vec<u8>) -> Result<Vec<u8>, String> {
    read_rest_within(file, bytes, max_file_size())
}

/// [`read_rest`] with the size limit `limit` instead of the process-wide one.
pub fn read_rest_within(
    file: impl Read,
    mut bytes: Vec<u8>,
    limit: u64,
) -> Result<Vec<u8>, String> {
    let room = limit.saturating_sub(bytes.len() as u64);
    file.take(room.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(too_large(limit));
    }
    Ok(bytes)
}

fn too_large(limit: u64) -> String {
    format!(
        "is larger than the limit of {limit} bytes (raise it with --max-file-size or {MAX_FILE_SIZE_ENV})"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("123"), Ok(123));
        assert_eq!(parse_size("2K"), Ok(2048));
        assert_eq!(parse_size("1GiB"), Ok(1 << 30));
        assert_eq!(parse_size("3m"), Ok(3 << 20));
        assert!(parse_size("x").is_err());
        assert!(parse_size("99999999999999999999G").is_err());
    }

    #[test]
    fn a_limit_passed_in_is_the_limit() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let p = tmp.path().join("f");
        std::fs::write(&p, [7u8; 100]).expect("write");
        assert_eq!(read_file_within(&p, 100).map(|b| b.len()), Ok(100));
        assert!(read_file_within(&p, 99)
            .unwrap_err()
            .contains("larger than the limit of 99 bytes"));
    }

    #[test]
    fn the_budget_charges_lengths_and_refuses_what_exceeds_it() {
        let limits = ReadLimits {
            per_file: AtomicU64::new(DEFAULT_MAX_FILE_SIZE),
            total: AtomicU64::new(100),
            charged: AtomicU64::new(0),
        };
        assert_eq!(limits.charge(60), Ok(()));
        assert_eq!(limits.charge(40), Ok(()));
        let e = limits.charge(1).unwrap_err();
        assert!(
            e.contains("is over the budget of 100 bytes read from all files together")
                && e.contains("(1 bytes, after 100 bytes read before it)")
                && e.contains("--max-total-read"),
            "{e}"
        );
        assert!(limits.charge(u64::MAX).is_err());
        assert_eq!(limits.charged.load(Ordering::Relaxed), 100);
    }

    #[test]
    fn devices_and_directories_are_refused() {
        assert!(read_file(Path::new("/dev/zero"))
            .unwrap_err()
            .contains("is not a regular file (a character device)"));
        assert!(read_file(Path::new("/"))
            .unwrap_err()
            .contains("is not a regular file (a directory)"));
    }
}
