//! Reading input files with two guards: only regular files are read (a FIFO would hang, `/dev/zero`
//! or `/dev/urandom` never end), and no more than a size limit the caller passes
//! ([`DEFAULT_MAX_FILE_SIZE`], 1 GiB, unless it says otherwise; the command line takes it from
//! `--max-file-size` or `URDF_INERTIA_MAX_FILE_SIZE`). The library keeps no limit of its own: each
//! reader is handed the limit by whoever started the work (the mesh cache, the package resolver,
//! xacro's options, the density map's loader).
//!
//! One thing is counted across a run: a budget for all the files read together
//! ([`set_max_total_read`]; none unless a caller sets one, the command line sets 16 GiB by default,
//! `--max-total-read` or `URDF_INERTIA_MAX_TOTAL_READ`). A file is charged its length when it is
//! opened, so that a robot naming thousands of large files (each within the limit) ends with an error
//! naming the file that would exceed the budget instead of reading for hours. It is a process-wide
//! counter because it is about the process (the memory and time one run may take), not about one file.
//!
//! This is the one way the library reads a file: URDFs, meshes, glTF buffers, density maps and
//! `package.xml` all go through [`read_file`] or [`open_file`] (a test in tests/regression.rs puts a
//! FIFO and a `/dev/zero` symlink at each); a new reader (xacro includes, YAML) uses them too.

use std::fmt;
use std::fs::{self, File};
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// The default limit on one input file: 1 GiB.
pub const DEFAULT_MAX_FILE_SIZE: u64 = 1 << 30;

/// The budget of bytes read in one run, all files together, that the command line sets unless told
/// otherwise: 16 GiB, sixteen files at the one-file limit. No real robot comes near it: the largest of
/// example-robot-data's 40 robots reads 40 MB of files, all 40 together 411 MB.
pub const DEFAULT_MAX_TOTAL_READ: u64 = 16 << 30;

/// The budget for all files together and the bytes charged to it so far.
struct Budget {
    total: AtomicU64,
    charged: AtomicU64,
}

impl Budget {
    /// Charges a file of `len` bytes to the budget, or says why it cannot be read (the budget is left
    /// as it was).
    fn charge(&self, len: u64) -> Result<(), InputError> {
        let total = self.total.load(Ordering::Relaxed);
        self.charged
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |c| {
                c.checked_add(len).filter(|&sum| sum <= total)
            })
            .map(drop)
            .map_err(|charged| InputError::OverBudget {
                budget: total,
                len,
                charged,
            })
    }
}

static BUDGET: Budget = Budget {
    total: AtomicU64::new(u64::MAX),
    charged: AtomicU64::new(0),
};

/// Sets the budget of bytes the process may read from all files together (by default there is none).
pub fn set_max_total_read(bytes: u64) {
    BUDGET.total.store(bytes, Ordering::Relaxed);
}

/// The bytes charged to the budget so far: the lengths of the files opened.
pub fn total_read() -> u64 {
    BUDGET.charged.load(Ordering::Relaxed)
}

/// Why a file could not be read; the message names no path (callers name the file and what it is).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputError {
    /// Not a regular file: a directory, a FIFO, a device, a socket.
    NotRegular {
        /// What it is instead (`a directory`, `a FIFO`, …).
        kind: &'static str,
    },
    /// Larger than the limit the caller passed, in bytes.
    TooLarge { limit: u64 },
    /// Over the budget of bytes read from all files together ([`set_max_total_read`]).
    OverBudget {
        /// The budget, in bytes.
        budget: u64,
        /// The file's length.
        len: u64,
        /// The bytes read before it.
        charged: u64,
    },
    /// The operating system's error, as text.
    Io(String),
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::NotRegular { kind } => write!(f, "is not a regular file ({kind})"),
            InputError::TooLarge { limit } => write!(
                f,
                "is larger than the limit of {limit} bytes (raise it with --max-file-size or URDF_INERTIA_MAX_FILE_SIZE)"
            ),
            InputError::OverBudget { budget, len, charged } => write!(
                f,
                "is over the budget of {budget} bytes read from all files together in this run ({len} bytes, after {charged} bytes read before it); raise it with --max-total-read SIZE or URDF_INERTIA_MAX_TOTAL_READ"
            ),
            InputError::Io(e) => f.write_str(e),
        }
    }
}

impl std::error::Error for InputError {}

impl From<std::io::Error> for InputError {
    fn from(e: std::io::Error) -> Self {
        InputError::Io(e.to_string())
    }
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

/// The whole content of a regular file no larger than `limit` bytes.
pub fn read_file(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    let (file, len) = open_file(path, limit)?;
    read_rest(file, Vec::with_capacity(len as usize), limit)
}

/// A regular file no larger than `limit` bytes, opened for reading, and its length: for readers
/// that stream a big file instead of holding all of it (then they must read no more than the
/// length, and treat a shorter file as truncated).
pub fn open_file(path: &Path, limit: u64) -> Result<(File, u64), InputError> {
    let regular = |meta: &fs::Metadata| {
        if meta.is_file() {
            Ok(())
        } else {
            Err(InputError::NotRegular {
                kind: kind(meta.file_type()),
            })
        }
    };
    // Checked before opening: opening a FIFO for reading blocks until someone writes.
    regular(&fs::metadata(path)?)?;
    let file = File::open(path)?;
    let meta = file.metadata()?;
    regular(&meta)?;
    if meta.len() > limit {
        return Err(InputError::TooLarge { limit });
    }
    BUDGET.charge(meta.len())?;
    Ok((file, meta.len()))
}

/// Appends the rest of `file` to `bytes`, up to `limit` bytes in all (a file can grow after its
/// size was checked; stdin has no size).
pub fn read_rest(file: impl Read, mut bytes: Vec<u8>, limit: u64) -> Result<Vec<u8>, InputError> {
    let room = limit.saturating_sub(bytes.len() as u64);
    file.take(room.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(InputError::TooLarge { limit });
    }
    Ok(bytes)
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
        assert_eq!(read_file(&p, 100).map(|b| b.len()), Ok(100));
        assert_eq!(
            read_file(&p, 99).unwrap_err(),
            InputError::TooLarge { limit: 99 }
        );
    }

    #[test]
    fn the_budget_charges_lengths_and_refuses_what_exceeds_it() {
        let budget = Budget {
            total: AtomicU64::new(100),
            charged: AtomicU64::new(0),
        };
        assert_eq!(budget.charge(60), Ok(()));
        assert_eq!(budget.charge(40), Ok(()));
        let e = budget.charge(1).unwrap_err().to_string();
        assert!(
            e.contains("is over the budget of 100 bytes read from all files together")
                && e.contains("(1 bytes, after 100 bytes read before it)")
                && e.contains("--max-total-read"),
            "{e}"
        );
        assert!(budget.charge(u64::MAX).is_err());
        assert_eq!(budget.charged.load(Ordering::Relaxed), 100);
    }

    #[test]
    fn devices_and_directories_are_refused() {
        let limit = DEFAULT_MAX_FILE_SIZE;
        assert!(read_file(Path::new("/dev/zero"), limit)
            .unwrap_err()
            .to_string()
            .contains("is not a regular file (a character device)"));
        assert!(read_file(Path::new("/"), limit)
            .unwrap_err()
            .to_string()
            .contains("is not a regular file (a directory)"));
    }
}
