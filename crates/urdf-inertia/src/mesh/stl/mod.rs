//! STL, binary and ASCII.
//!
//! The format is decided by content, not by the first five bytes: a binary file whose 80-byte header
//! begins with `solid` (common from CAD exporters) is binary when its length is `84 + 50·n`. A binary
//! header with a wrong triangle count is tolerated when the length still holds whole records (noted);
//! a file shorter than its records is an error.
//!
//! Both are streamed from a file: binary records a chunk at a time, each read (positioned reads) by
//! the thread that welds it, ASCII text in pieces of [`ASCII_PIECE`] bytes cut into chunks at `facet`
//! lines; chunks are parsed and welded on their own
//! in parallel and their vertices welded across chunks at the end, so the file is never held whole
//! and the result is one sequential parse's, bit for bit (the ASCII reader is tested against the
//! whole-text reader it replaced, kept in the tests).
//!
//! Why not `stl_io` (the brief's choice): measured on example-robot-data 6.0.0, `stl_io` 0.8 reads all
//! 410 STL files with the same face counts as this reader, so it does not fail real files. This
//! reader is kept because it parses binary files several times faster (`stl_io` merges vertices while
//! reading, and the health step welds anyway; figures: docs/benchmarks.md, "Figures behind choices
//! in the code"), gives ASCII errors a line number, and reports a truncated or miscounted binary
//! file with the numbers a user needs.

use super::{MeshError, MeshErrorKind, RawMesh};
#[cfg(any(test, feature = "internals"))]
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::Path;

mod ascii;
mod binary;
#[cfg(test)]
mod tests;

#[cfg(test)]
use ascii::ASCII_CHUNK;
use ascii::{ascii, ascii_stream, stream_chunk, ASCII_PIECE};
use binary::{binary, Binary, CHUNK, PIECE};

/// Parses STL bytes (binary or ASCII). Corners with bit-identical coordinates share one vertex, in
/// order of first appearance: the exact weld the health step does anyway, done while reading so that
/// three vertices per triangle are never stored. Faces are kept as the file has them (a triangle with
/// two equal corners included; the health step drops and counts it).
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let looks_ascii = looks_ascii(bytes);
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        let exact_binary = 84 + 50 * n == bytes.len();
        if exact_binary && !(looks_ascii && n == 0) {
            return Ok(binary(bytes, n, None));
        }
        if looks_ascii {
            match ascii(bytes, path) {
                Ok(mesh) => return Ok(mesh),
                Err(e) => {
                    // A binary file with a `solid` header and a wrong count: whole records after the header.
                    if (bytes.len() - 84) % 50 == 0 && bytes.len() > 84 && !is_text(bytes) {
                        let m = (bytes.len() - 84) / 50;
                        return Ok(binary(bytes, m, Some(n)));
                    }
                    return Err(e);
                }
            }
        }
        if (bytes.len() - 84) % 50 == 0 && bytes.len() > 84 {
            let m = (bytes.len() - 84) / 50;
            return Ok(binary(bytes, m, Some(n)));
        }
        let whole = (bytes.len() - 84) / 50;
        return Err(MeshError::new(
            path,
            None,
            MeshErrorKind::Truncated(format!(
                "binary STL header says {n} triangles ({} bytes), the file has {} bytes ({whole} whole triangles)",
                84 + 50 * n,
                bytes.len()
            )),
        ));
    }
    if looks_ascii {
        return ascii(bytes, path);
    }
    Err(MeshError::new(
        path,
        None,
        MeshErrorKind::Truncated(format!(
            "{} bytes is shorter than a binary STL header (84 bytes)",
            bytes.len()
        )),
    ))
}

/// Whether the first word is `solid` in any case (the ASCII keyword; also the start of many binary
/// headers). Some exporters write every keyword in upper case (`SOLID`, `FACET NORMAL`, `VERTEX`).
fn looks_ascii(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    bytes[start..]
        .get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"solid"))
}

/// The words an ASCII STL line can begin with. Keywords are matched without regard to case: the
/// format's grammar gives them in lower case, but exporters writing `SOLID`/`VERTEX` exist and every
/// peer reader (assimp, trimesh, numpy-stl) accepts them.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Keyword {
    Vertex,
    Outer,
    EndLoop,
    /// `solid`, `facet`, `endfacet`, `endsolid`: structure this reader does not need.
    Ignored,
    Other,
}

impl Keyword {
    fn of(word: &[u8]) -> Keyword {
        // The common case first, exactly: one comparison per vertex line.
        if word == b"vertex" || word.eq_ignore_ascii_case(b"vertex") {
            Keyword::Vertex
        } else if word.eq_ignore_ascii_case(b"outer") {
            Keyword::Outer
        } else if word.eq_ignore_ascii_case(b"endloop") {
            Keyword::EndLoop
        } else if [b"facet" as &[u8], b"endfacet", b"solid", b"endsolid"]
            .iter()
            .any(|k| word.eq_ignore_ascii_case(k))
        {
            Keyword::Ignored
        } else {
            Keyword::Other
        }
    }
}

fn is_text(bytes: &[u8]) -> bool {
    bytes
        .iter()
        .take(4096)
        .all(|&b| b.is_ascii_graphic() || b.is_ascii_whitespace())
}

/// Reads an STL file. A binary file whose length matches its header (nearly every one) is read a
/// chunk at a time, each chunk by the thread that welds it (positioned reads), so the file is never
/// held whole and reading overlaps welding: on a 1.3 M-face file (65.5 MB) that saves the 65.5 MB
/// buffer, and the page faults of filling it. Anything else is read as [`read_split`] reads it.
pub fn read(path: &Path, max_file_size: u64) -> Result<RawMesh, MeshError> {
    let (file, len) = crate::input::open_file(path, max_file_size)
        .map_err(|e| MeshError::new(path, None, MeshErrorKind::Io(e.to_string())))?;
    read_file(file, len, path, CHUNK, None)
}

/// [`read`] from an open `file` of `len` bytes, with [`read_split`]'s `chunk` and `runs` (for the
/// tests: chunk borders everywhere). Where the platform has no positioned reads, [`read_split`].
#[doc(hidden)]
pub fn read_file(
    file: std::fs::File,
    len: u64,
    path: &Path,
    chunk: usize,
    runs: Option<usize>,
) -> Result<RawMesh, MeshError> {
    #[cfg(any(unix, windows))]
    {
        use std::io::Seek as _;
        let chunk = chunk.max(1);
        let mut header = [0u8; 84];
        let n = if len >= 84 && binary::read_exact_at(&file, &mut header, 0).is_ok() {
            u64::from(u32::from_le_bytes([header[80], header[81], header[82], header[83]]))
        } else {
            0
        };
        if n > 0 && 84 + 50 * n == len {
            let n = n as usize;
            let mut reader = Binary::new(n, chunk, runs);
            reader
                .read_at(&file, 84)
                .map_err(|(read, e)| truncated(path, n, read, &e))?;
            return Ok(reader.finish(None));
        }
        // Anything else from the start, as a stream (`seek_read` moves the cursor).
        let mut file = file;
        file.rewind()
            .map_err(|e| MeshError::new(path, None, MeshErrorKind::Io(e.to_string())))?;
        read_split(file, len, path, chunk, runs)
    }
    #[cfg(not(any(unix, windows)))]
    read_split(file, len, path, chunk, runs)
}

/// A binary file that ended before its `n` records while it was read (it shrank after it was opened),
/// after `read` of them.
fn truncated(path: &Path, n: usize, read: usize, e: &std::io::Error) -> MeshError {
    MeshError::new(
        path,
        None,
        MeshErrorKind::Truncated(format!(
            "binary STL of {n} triangles ended after {read} while it was read ({e})"
        )),
    )
}

/// [`read`] from `source`, `len` bytes long, welding chunks of `chunk` records and joining them in
/// `runs` runs (`None`: as many as [`crate::mesh::weld::join`] picks for the vertex count; chunks of at
/// least 1 record, 1 to 256 runs).
///
/// [`read`] passes [`CHUNK`] and `None`. It exists for the `stl_stream` fuzz target and the tests:
/// with a chunk of 16 Ki records, no input the fuzzer makes (64 KiB at most) crosses a chunk or a
/// run border; with a few records and a forced run count, every one does, and the result must still
/// be [`parse`]'s, bit for bit.
#[doc(hidden)]
pub fn read_split(
    mut source: impl std::io::Read + Send,
    len: u64,
    path: &Path,
    chunk: usize,
    runs: Option<usize>,
) -> Result<RawMesh, MeshError> {
    let io = |e: String| MeshError::new(path, None, MeshErrorKind::Io(e));
    let chunk = chunk.max(1);
    let mut header = vec![0u8; 84.min(len as usize)];
    source
        .read_exact(&mut header)
        .map_err(|e| io(e.to_string()))?;
    let n = header.get(80..84).map_or(0, |c| {
        u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
    });
    if n == 0 || 84 + 50 * n != len {
        // `parse` reads a text that starts with `solid` as ASCII, and falls back to binary records
        // only when its first 4 KiB are not all text: with those bytes in hand, a text file is
        // streamed instead of held whole (the result is `parse`'s).
        let mut head = header;
        (&mut source)
            .take(4096u64.saturating_sub(head.len() as u64))
            .read_to_end(&mut head)
            .map_err(|e| io(e.to_string()))?;
        if looks_ascii(&head) && is_text(&head) {
            let rest = source.take(len.saturating_sub(head.len() as u64));
            return ascii_stream(head, rest, len, path, ASCII_PIECE, stream_chunk(len));
        }
        // No more than the length checked when the file was opened.
        let rest = source.take(len.saturating_sub(head.len() as u64));
        let bytes = crate::input::read_rest(rest, head, len).map_err(|e| io(e.to_string()))?;
        return parse(&bytes, path);
    }
    let n = n as usize;
    let mut reader = Binary::new(n, chunk, runs);
    // No bigger than the file: zeroing a buffer of several megabytes for every small STL showed in
    // profiles of filling a whole robot collection (figures: docs/benchmarks.md, "Figures behind
    // choices in the code").
    let mut buf = vec![0u8; 50 * n.min(chunk * PIECE)];
    let mut left = n;
    while left > 0 {
        let m = left.min(chunk * PIECE);
        source
            .read_exact(&mut buf[..50 * m])
            .map_err(|e| truncated(path, n, n - left, &e))?;
        reader.feed(&buf[..50 * m]);
        left -= m;
    }
    Ok(reader.finish(None))
}

/// Writes a binary STL (used by tests and fixture generators).
#[cfg(any(test, feature = "internals"))]
pub fn write_binary(header: &[u8], vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out[..header.len().min(80)].copy_from_slice(&header[..header.len().min(80)]);
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for t in triangles {
        out.extend_from_slice(&[0u8; 12]);
        for &i in t {
            for c in vertices[i as usize] {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

/// Writes an ASCII STL (used by tests and fixture generators).
#[cfg(any(test, feature = "internals"))]
pub fn write_ascii(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> String {
    let mut s = String::from("solid fixture\n");
    for t in triangles {
        s.push_str("  facet normal 0 0 0\n    outer loop\n");
        for &i in t {
            let v = vertices[i as usize];
            let _ = writeln!(s, "      vertex {} {} {}", v[0], v[1], v[2]);
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid fixture\n");
    s
}
