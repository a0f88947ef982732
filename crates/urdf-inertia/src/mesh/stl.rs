//! STL, binary and ASCII.
//!
//! The format is decided by content, not by the first five bytes: a binary file whose 80-byte header
//! begins with `solid` (common from CAD exporters) is binary when its length is `84 + 50·n`. A binary
//! header with a wrong triangle count is tolerated when the length still holds whole records (noted);
//! a file shorter than its records is an error.
//!
//! Both are streamed from a file: binary records in pieces of a few megabytes, ASCII text in pieces
//! of [`ASCII_PIECE`] bytes cut into chunks at `facet` lines; chunks are parsed and welded on their own
//! in parallel and their vertices welded across chunks at the end, so the file is never held whole
//! and the result is one sequential parse's, bit for bit (the ASCII reader is tested against the
//! whole-text reader it replaced, kept in the tests).
//!
//! Why not stl_io (the brief's choice): measured on example-robot-data 6.0.0, stl_io 0.8 reads all 410 STL
//! files with the same face counts as this reader, so it does not fail real files. This reader is kept
//! because it parses a 1.3 M-face binary file 3.6× faster (153 ms against 556 ms: stl_io merges vertices
//! while reading, and the health step welds anyway), gives ASCII errors a line number, and reports a
//! truncated or miscounted binary file with the numbers a user needs.

use super::weld::VertexTable;
use super::{parse_f64, short_decimal, MeshError, MeshErrorKind, RawMesh};
use crate::mass::Polygons;
#[cfg(any(test, feature = "internals"))]
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::Path;

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

fn binary(bytes: &[u8], n: usize, header_count: Option<usize>) -> RawMesh {
    let mut reader = Binary::new(n, CHUNK, None);
    reader.feed(&bytes[84..84 + 50 * n]);
    reader.finish(header_count)
}

/// Reads an STL file. A binary file whose length matches its header (nearly every one) is read in
/// pieces of a few megabytes, each welded as it arrives, so the file is never held whole:
/// on a 1.3 M-face file (65.5 MB) that saves the 65.5 MB buffer, and the page faults of filling it.
/// Anything else is read whole and given to [`parse`].
pub fn read(path: &Path, max_file_size: u64) -> Result<RawMesh, MeshError> {
    let (file, len) = crate::input::open_file(path, max_file_size)
        .map_err(|e| MeshError::new(path, None, MeshErrorKind::Io(e.to_string())))?;
    read_split(file, len, path, CHUNK, None)
}

/// [`read`] from `source`, `len` bytes long, welding chunks of `chunk` records and joining them in
/// `runs` runs (`None`: as many as [`super::weld::join`] picks for the vertex count; chunks of at
/// least 1 record, 1 to 256 runs).
///
/// [`read`] passes [`CHUNK`] and `None`. It exists for the `stl_stream` fuzz target and the tests:
/// with a chunk of 16 Ki records, no input the fuzzer makes (64 KiB at most) crosses a chunk or a
/// run border; with a few records and a forced run count, every one does, and the result must still
/// be [`parse`]'s, bit for bit.
#[doc(hidden)]
pub fn read_split(
    mut source: impl std::io::Read,
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
            return ascii_stream(head, rest, path, ASCII_PIECE, ASCII_CHUNK);
        }
        // No more than the length checked when the file was opened.
        let rest = source.take(len.saturating_sub(head.len() as u64));
        let bytes = crate::input::read_rest(rest, head, len).map_err(|e| io(e.to_string()))?;
        return parse(&bytes, path);
    }
    let n = n as usize;
    let mut reader = Binary::new(n, chunk, runs);
    // No bigger than the file: zeroing a 3.3 MB buffer for every small STL was 2.5% of filling ERD.
    let mut buf = vec![0u8; 50 * n.min(chunk * PIECE)];
    let mut left = n;
    while left > 0 {
        let m = left.min(chunk * PIECE);
        source.read_exact(&mut buf[..50 * m]).map_err(|e| {
            MeshError::new(
                path,
                None,
                MeshErrorKind::Truncated(format!(
                    "binary STL of {n} triangles ended after {} while it was read ({e})",
                    n - left
                )),
            )
        })?;
        reader.feed(&buf[..50 * m]);
        left -= m;
    }
    Ok(reader.finish(None))
}

/// Chunks read and welded at a time: two per thread on two cores, 1.6 MB each.
const PIECE: usize = 4;

/// A binary STL reader fed whole 50-byte records.
///
/// Records are welded in two steps. Each chunk of [`CHUNK`] records (fewer for [`read_split`]'s
/// tests) is welded on its own first, in parallel (rayon), into a table small enough for the L2
/// cache; the chunks' distinct vertices are then welded across chunks once the file is read
/// ([`super::weld::join`]). A vertex is numbered where it first appears in the file either way, so
/// the result is the sequential weld's, bit for bit, for any number of threads; and the cross-chunk
/// weld sees each vertex about once instead of at each of its six or so corners.
struct Binary {
    /// The chunks' distinct vertices, one chunk after the other.
    vertices: Vec<[f64; 3]>,
    /// Corners as indices into `vertices`.
    indices: Vec<u32>,
    /// Records in a chunk: [`CHUNK`], but for [`read_split`].
    chunk: usize,
    /// Runs of the cross-chunk join: `None` (the join's choice), but for [`read_split`].
    runs: Option<usize>,
}

/// Records welded on their own before the cross-chunk join: 16 Ki faces make about 8 Ki vertices, a
/// table of 128 KiB (in L2, so each insert is one probe; grouping inserts to overlap their misses,
/// which the one big table of all vertices needed, measured no faster here).
const CHUNK: usize = 16 * 1024;

/// The distinct vertices of a chunk of records in order of first appearance, and its corners as
/// indices into them.
fn weld_chunk(records: &[u8]) -> (Vec<[f64; 3]>, Vec<u32>) {
    let n = records.len() / 50;
    let mut table = VertexTable::with_capacity(n / 2 + 16);
    let mut indices = Vec::with_capacity(3 * n);
    for r in records.chunks_exact(50) {
        // + 0.0 folds −0.0 into 0.0, so that both weld (`RawMesh::welded`).
        let f =
            |o: usize| f64::from(f32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]])) + 0.0;
        // Skip the normal (bytes 0..12); the corners follow.
        for o in [12, 24, 36] {
            indices.push(table.insert([f(o), f(o + 4), f(o + 8)]));
        }
    }
    (table.into_vertices(), indices)
}

impl Binary {
    fn new(n: usize, chunk: usize, runs: Option<usize>) -> Self {
        Binary {
            chunk,
            runs,
            // A closed triangle mesh has about half as many vertices as faces; chunks repeat the
            // ones on their borders.
            vertices: Vec::with_capacity(n / 2 + n / 16 + 16),
            indices: Vec::with_capacity(3 * n),
        }
    }

    /// Reads whole records, [`PIECE`] chunks at a time.
    fn feed(&mut self, records: &[u8]) {
        use rayon::prelude::*;
        for piece in records.chunks(50 * self.chunk * PIECE) {
            let welded: Vec<(Vec<[f64; 3]>, Vec<u32>)> = crate::threads::install(|| {
                piece.par_chunks(50 * self.chunk).map(weld_chunk).collect()
            });
            for (vertices, indices) in welded {
                let base = self.vertices.len() as u32;
                self.vertices.extend(vertices);
                self.indices.extend(indices.iter().map(|&i| base + i));
            }
        }
    }

    fn finish(mut self, header_count: Option<usize>) -> RawMesh {
        let n = self.indices.len() / 3;
        let vertices = super::weld::join(self.vertices, &mut self.indices, self.runs);
        let starts = (0..=n as u32).map(|i| 3 * i).collect();
        let mut notes = Vec::new();
        if let Some(h) = header_count {
            notes.push(format!(
                "binary STL header says {h} triangles; read the {n} whole triangles the file holds"
            ));
        }
        RawMesh {
            vertices,
            faces: Polygons {
                indices: self.indices,
                starts,
            },
            notes,
            warnings: Vec::new(),
            welded: true,
        }
    }
}

/// Parses ASCII STL held in memory; errors carry the line. The same reader as [`ascii_stream`]'s,
/// fed the whole text at once.
fn ascii(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let mut reader = Ascii::new(path, ASCII_CHUNK);
    reader.feed(bytes);
    reader.finish()
}

/// Reads ASCII STL from `head` (the bytes already read) and then `source`, in pieces of `piece`
/// bytes ([`ASCII_PIECE`]; chunks of `chunk`, [`ASCII_CHUNK`]): memory is the mesh and one piece (a
/// line longer than a piece is held whole), not the file. The result, errors included, is
/// [`ascii`]'s on the whole text.
fn ascii_stream(
    head: Vec<u8>,
    mut source: impl std::io::Read,
    path: &Path,
    piece: usize,
    chunk: usize,
) -> Result<RawMesh, MeshError> {
    let mut reader = Ascii::new(path, chunk);
    let mut buf = head;
    loop {
        // Top the piece up to its size (twice what is held when one line is longer).
        let want = piece.max(2 * buf.len());
        let before = buf.len();
        (&mut source)
            .take((want - before) as u64)
            .read_to_end(&mut buf)
            .map_err(|e| MeshError::new(path, None, MeshErrorKind::Io(e.to_string())))?;
        let end = buf.len() == before;
        if end {
            reader.feed(&buf);
            return reader.finish();
        }
        // Whole lines only; the rest waits for the next piece.
        let Some(cut) = memchr::memrchr(b'\n', &buf).map(|i| i + 1) else {
            continue;
        };
        reader.feed(&buf[..cut]);
        if reader.utf8.is_some() {
            return reader.finish();
        }
        buf.drain(..cut);
    }
}

/// Bytes of ASCII STL read at a time by [`ascii_stream`].
const ASCII_PIECE: usize = 4 << 20;

/// Bytes of ASCII STL parsed as one chunk (in parallel, each welded on its own, as binary records).
const ASCII_CHUNK: usize = 512 << 10;

/// What a line left for the next: inside `outer loop` … `endloop`, and the corners since `outer`.
#[derive(Debug, Clone, Default, PartialEq)]
struct AsciiState {
    in_loop: bool,
    current: Vec<u32>,
}

/// One chunk of whole lines parsed on its own: vertices welded within it in order of first
/// appearance, faces as indices into them (plus `base`).
struct AsciiChunk {
    vertices: Vec<[f64; 3]>,
    indices: Vec<u32>,
    /// Corners of each face.
    sizes: Vec<u32>,
    /// Lines started in the chunk (its `\n`s, and one for a last line without one).
    lines: usize,
    end: AsciiState,
    /// A `vertex` or `endloop` came before the chunk's first `outer`: the result depends on the
    /// state the chunk started in.
    dependent: bool,
    /// An `outer` began a facet in the chunk.
    outer: bool,
    /// The first error: the line within the chunk (from 1) and what.
    error: Option<(usize, MeshErrorKind)>,
    /// Not UTF-8 from this byte of the chunk on.
    utf8: Option<usize>,
}

/// Parses whole lines of ASCII STL starting in `start`, numbering new vertices from `base`.
#[allow(clippy::too_many_lines)] // one match over the line kinds, each with its error
fn ascii_chunk(text: &[u8], start: AsciiState, base: u32) -> AsciiChunk {
    let mut out = AsciiChunk {
        vertices: Vec::new(),
        indices: Vec::new(),
        sizes: Vec::new(),
        lines: 0,
        end: start,
        dependent: false,
        outer: false,
        error: None,
        utf8: None,
    };
    if let Err(e) = std::str::from_utf8(text) {
        out.utf8 = Some(e.valid_up_to());
        return out;
    }
    // About 250 bytes a facet, half a new vertex a facet.
    let mut table = VertexTable::with_capacity(text.len() / 400 + 16);
    out.indices.reserve(text.len() / 80);
    out.sizes.reserve(text.len() / 240);
    let AsciiState {
        mut in_loop,
        mut current,
    } = std::mem::take(&mut out.end);
    let mut rest = text;
    while !rest.is_empty() {
        let (line, after) = match memchr::memchr(b'\n', rest) {
            Some(i) => (&rest[..i], &rest[i + 1..]),
            None => (rest, &rest[rest.len()..]),
        };
        rest = after;
        out.lines += 1;
        let mut words = AsciiWords { rest: line };
        let Some(word) = words.next() else { continue };
        let lineno = out.lines;
        let fail = |kind| Some((lineno, kind));
        match Keyword::of(word) {
            Keyword::Vertex => {
                out.dependent |= !out.outer;
                if !in_loop {
                    out.error = fail(MeshErrorKind::Syntax(
                        "`vertex` outside `outer loop`".into(),
                    ));
                    break;
                }
                match words.vertex() {
                    Ok(p) => current.push(base + table.insert(p)),
                    Err(kind) => {
                        out.error = fail(kind);
                        break;
                    }
                }
            }
            Keyword::Outer => {
                out.outer = true;
                in_loop = true;
                current.clear();
            }
            Keyword::EndLoop => {
                out.dependent |= !out.outer;
                in_loop = false;
                if current.len() < 3 {
                    out.error = fail(MeshErrorKind::Syntax(format!(
                        "a facet with {} vertices",
                        current.len()
                    )));
                    break;
                }
                out.indices.extend_from_slice(&current);
                out.sizes.push(current.len() as u32);
            }
            Keyword::Ignored => {}
            Keyword::Other => {
                out.error = fail(MeshErrorKind::Syntax(format!(
                    "unexpected `{}` in ASCII STL",
                    String::from_utf8_lossy(word)
                )));
                break;
            }
        }
    }
    out.vertices = table.into_vertices();
    out.end = AsciiState { in_loop, current };
    out
}

/// The words of an ASCII STL line: runs of bytes between ASCII whitespace (what
/// `split_ascii_whitespace` gives).
struct AsciiWords<'a> {
    rest: &'a [u8],
}

impl<'a> Iterator for AsciiWords<'a> {
    type Item = &'a [u8];

    fn next(&mut self) -> Option<&'a [u8]> {
        let start = self.rest.iter().position(|b| !b.is_ascii_whitespace())?;
        let rest = &self.rest[start..];
        let len = rest
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(rest.len());
        let (word, after) = rest.split_at(len);
        self.rest = after;
        Some(word)
    }
}

impl AsciiWords<'_> {
    /// The three coordinates after `vertex` (−0.0 folded into 0.0, so that both weld:
    /// `RawMesh::welded`). A short decimal is scanned in place; any other word is cut out and
    /// parsed as [`parse_f64`] parses it.
    fn vertex(&mut self) -> Result<[f64; 3], MeshErrorKind> {
        let mut p = [0.0; 3];
        for c in p.iter_mut() {
            let skip = self
                .rest
                .iter()
                .position(|b| !b.is_ascii_whitespace())
                .unwrap_or(self.rest.len());
            self.rest = &self.rest[skip..];
            let fast = short_decimal(self.rest)
                .filter(|&(_, n)| self.rest.get(n).is_none_or(|b| b.is_ascii_whitespace()));
            *c = match fast {
                Some((x, n)) => {
                    self.rest = &self.rest[n..];
                    x
                }
                None => {
                    let w = self.next().ok_or_else(|| {
                        MeshErrorKind::Syntax("`vertex` needs three coordinates".into())
                    })?;
                    // The chunk is UTF-8 and `w` is cut at ASCII bytes, so `from_utf8` succeeds.
                    let w = std::str::from_utf8(w).unwrap_or_default();
                    parse_f64(w)
                        .ok_or_else(|| MeshErrorKind::Syntax(format!("`{w}` is not a number")))?
                }
            };
            if !c.is_finite() {
                return Err(MeshErrorKind::NotFinite);
            }
            *c += 0.0;
        }
        Ok(p)
    }
}

/// An ASCII STL reader fed whole lines (and at the end the last line, with or without its `\n`).
///
/// Each feed is cut into chunks of about [`ASCII_CHUNK`] bytes at lines that begin a `facet`,
/// parsed and welded on their own in parallel (rayon), as if each began outside a facet; then the
/// chunks are taken in order, and one whose start did matter (a `vertex` or `endloop` before its
/// first `outer`, in a file with `facet` inside a loop) and did not hold is parsed again from the
/// state the one before left. The chunks' vertices are welded across chunks at the end
/// ([`super::weld::join`]): the result is the one sequential parse's, bit for bit, for any thread
/// count.
struct Ascii<'p> {
    path: &'p Path,
    /// Bytes a chunk: [`ASCII_CHUNK`], but for the tests.
    chunk: usize,
    vertices: Vec<[f64; 3]>,
    indices: Vec<u32>,
    starts: Vec<u32>,
    state: AsciiState,
    /// Lines before the next feed.
    lines: usize,
    /// Bytes before the next feed.
    offset: usize,
    /// The first syntax error: the line and what. Later text is only checked to be UTF-8 (that
    /// error would be reported instead, as the whole-text reader checks it first).
    error: Option<(usize, MeshErrorKind)>,
    /// The first byte that is not UTF-8: reading stops.
    utf8: Option<usize>,
}

impl<'p> Ascii<'p> {
    fn new(path: &'p Path, chunk: usize) -> Self {
        Ascii {
            path,
            chunk: chunk.max(1),
            vertices: Vec::new(),
            indices: Vec::new(),
            starts: vec![0],
            state: AsciiState::default(),
            lines: 0,
            offset: 0,
            error: None,
            utf8: None,
        }
    }

    fn feed(&mut self, text: &[u8]) {
        use rayon::prelude::*;
        if self.utf8.is_some() {
            return;
        }
        let offset = self.offset;
        self.offset += text.len();
        if self.error.is_some() {
            if let Err(e) = std::str::from_utf8(text) {
                self.utf8 = Some(offset + e.valid_up_to());
            }
            return;
        }
        let chunks = facet_chunks(text, self.chunk);
        let parsed: Vec<AsciiChunk> = chunks
            .par_iter()
            .map(|c| ascii_chunk(c, AsciiState::default(), 0))
            .collect();
        let mut at = offset;
        for (text, mut chunk) in chunks.iter().zip(parsed) {
            let here = at;
            at += text.len();
            if self.error.is_none() {
                if chunk.dependent && self.state != AsciiState::default() {
                    let start = std::mem::take(&mut self.state);
                    chunk = ascii_chunk(text, start, self.vertices.len() as u32);
                } else {
                    let base = self.vertices.len() as u32;
                    chunk.indices.iter_mut().for_each(|i| *i += base);
                    chunk.end.current.iter_mut().for_each(|i| *i += base);
                }
            }
            if let Some(u) = chunk.utf8 {
                self.utf8 = Some(here + u);
                return;
            }
            if self.error.is_some() {
                continue;
            }
            if let Some((line, kind)) = chunk.error {
                self.error = Some((self.lines + line, kind));
                continue;
            }
            self.vertices.extend_from_slice(&chunk.vertices);
            let mut s = *self.starts.last().unwrap_or(&0);
            for &n in &chunk.sizes {
                s += n;
                self.starts.push(s);
            }
            self.indices.extend_from_slice(&chunk.indices);
            // A chunk that neither began a facet nor touched the state leaves it as it was.
            if chunk.outer || chunk.dependent {
                self.state = chunk.end;
            }
            self.lines += chunk.lines;
        }
    }

    fn finish(self) -> Result<RawMesh, MeshError> {
        if let Some(at) = self.utf8 {
            return Err(MeshError::new(
                self.path,
                None,
                MeshErrorKind::Syntax(format!("ASCII STL is not valid UTF-8 at byte {at}")),
            ));
        }
        if let Some((line, kind)) = self.error {
            return Err(MeshError::new(self.path, Some(line), kind));
        }
        if self.state.in_loop {
            return Err(MeshError::new(
                self.path,
                Some(self.lines),
                MeshErrorKind::Truncated("ASCII STL ends inside a facet".into()),
            ));
        }
        let mut indices = self.indices;
        let vertices = super::weld::join(self.vertices, &mut indices, None);
        Ok(RawMesh {
            vertices,
            faces: Polygons {
                indices,
                starts: self.starts,
            },
            notes: Vec::new(),
            warnings: Vec::new(),
            welded: true,
        })
    }
}

/// `text` cut into chunks of about `size` bytes, each but the last ending with a `\n` before a line
/// whose first word is `facet` (outside a facet, in a well-formed file), or (when none comes within
/// 64 KiB) before any line.
fn facet_chunks(text: &[u8], size: usize) -> Vec<&[u8]> {
    let mut out = Vec::new();
    let mut from = 0;
    while text.len() - from > size {
        let target = from + size;
        let mut cut = None;
        let mut first = None;
        let mut at = target;
        while let Some(i) = memchr::memchr(b'\n', &text[at..]) {
            let next = at + i + 1;
            first.get_or_insert(next);
            let line = &text[next..];
            let word = line
                .iter()
                .position(|&b| !matches!(b, b' ' | b'\t' | b'\r' | b'\x0c'))
                .map_or(&line[line.len()..], |w| &line[w..]);
            if word
                .get(..5)
                .is_some_and(|w| w.eq_ignore_ascii_case(b"facet"))
                && word.get(5).is_none_or(|b| b.is_ascii_whitespace())
            {
                cut = Some(next);
                break;
            }
            if next - target > 64 << 10 {
                break;
            }
            at = next;
        }
        let Some(cut) = cut.or(first).filter(|&c| c < text.len()) else {
            break;
        };
        out.push(&text[from..cut]);
        from = cut;
    }
    out.push(&text[from..]);
    out
}

/// The ASCII reader as it was before it streamed, kept to check the streaming one against it.
#[cfg(test)]
/// Parses ASCII STL; errors carry the line.
fn ascii_reference(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        MeshError::new(
            path,
            None,
            MeshErrorKind::Syntax(format!(
                "ASCII STL is not valid UTF-8 at byte {}",
                e.valid_up_to()
            )),
        )
    })?;
    let mut vertices = VertexTable::with_capacity(bytes.len() / 512 + 16);
    let mut faces = Polygons::new();
    let mut current: Vec<u32> = Vec::new();
    let mut in_loop = false;
    for (lineno, line) in text.lines().enumerate() {
        let lineno = lineno + 1;
        let mut words = line.split_ascii_whitespace();
        let Some(word) = words.next() else { continue };
        match Keyword::of(word.as_bytes()) {
            Keyword::Vertex => {
                if !in_loop {
                    return Err(MeshError::new(
                        path,
                        Some(lineno),
                        MeshErrorKind::Syntax("`vertex` outside `outer loop`".into()),
                    ));
                }
                let p = ascii_vertex(words, lineno, path)?;
                current.push(vertices.insert(p));
            }
            Keyword::Outer => {
                in_loop = true;
                current.clear();
            }
            Keyword::EndLoop => {
                in_loop = false;
                if current.len() < 3 {
                    return Err(MeshError::new(
                        path,
                        Some(lineno),
                        MeshErrorKind::Syntax(format!("a facet with {} vertices", current.len())),
                    ));
                }
                faces.push(&current);
            }
            Keyword::Ignored => {}
            Keyword::Other => {
                return Err(MeshError::new(
                    path,
                    Some(lineno),
                    MeshErrorKind::Syntax(format!("unexpected `{word}` in ASCII STL")),
                ));
            }
        }
    }
    if in_loop {
        return Err(MeshError::new(
            path,
            Some(text.lines().count()),
            MeshErrorKind::Truncated("ASCII STL ends inside a facet".into()),
        ));
    }
    Ok(RawMesh {
        vertices: vertices.into_vertices(),
        faces,
        notes: Vec::new(),
        warnings: Vec::new(),
        welded: true,
    })
}

/// The three coordinates after an ASCII STL `vertex` (for [`ascii_reference`]).
#[cfg(test)]
fn ascii_vertex<'a>(
    mut words: impl Iterator<Item = &'a str>,
    lineno: usize,
    path: &Path,
) -> Result<[f64; 3], MeshError> {
    let mut p = [0.0; 3];
    for c in p.iter_mut() {
        let w = words.next().ok_or_else(|| {
            MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::Syntax("`vertex` needs three coordinates".into()),
            )
        })?;
        *c = parse_f64(w).ok_or_else(|| {
            MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::Syntax(format!("`{w}` is not a number")),
            )
        })?;
        if !c.is_finite() {
            return Err(MeshError::new(path, Some(lineno), MeshErrorKind::NotFinite));
        }
        // −0.0 folds into 0.0, so that both weld (`RawMesh::welded`).
        *c += 0.0;
    }
    Ok(p)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed mesh of quads and triangles on a sphere-like grid, with coordinates of every sign
    /// (−0.0 included) and magnitudes from 1e-7 to 1e5.
    fn mesh() -> (Vec<[f64; 3]>, Vec<Vec<u32>>) {
        let (n, m) = (9u32, 7u32);
        let mut v = vec![[0.0, 0.0, 1.0], [-0.0, 0.0, -1.0]];
        for j in 1..m {
            for i in 0..n {
                let (a, b) = (
                    std::f64::consts::TAU * f64::from(i) / f64::from(n),
                    std::f64::consts::PI * f64::from(j) / f64::from(m),
                );
                let r = [1e-7, 1.0, 3.5, 1e5][(i % 4) as usize];
                v.push([r * b.sin() * a.cos(), r * b.sin() * a.sin(), b.cos()]);
            }
        }
        let at = |i: u32, j: u32| 2 + (j - 1) * n + i % n;
        let mut f = Vec::new();
        for i in 0..n {
            f.push(vec![0, at(i, 1), at(i + 1, 1)]);
            f.push(vec![1, at(i + 1, m - 1), at(i, m - 1)]);
            for j in 1..m - 1 {
                if (i + j) % 3 == 0 {
                    f.push(vec![at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
                } else {
                    f.push(vec![at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                    f.push(vec![at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
                }
            }
        }
        (v, f)
    }

    /// How a writer spells things: the number format, and the whitespace around lines and words.
    struct Style {
        number: fn(f64) -> String,
        indent: &'static str,
        gap: &'static str,
        eol: &'static str,
        solid: &'static str,
        end: &'static str,
    }

    fn write(style: &Style, v: &[[f64; 3]], f: &[Vec<u32>]) -> Vec<u8> {
        let Style {
            indent: ind,
            gap: g,
            eol,
            ..
        } = style;
        let mut s = format!("{}{eol}", style.solid);
        for face in f {
            let _ = write!(
                s,
                "{ind}facet{g}normal{g}0{g}0{g}1{eol}{ind}{ind}outer{g}loop{eol}"
            );
            for &i in face {
                let p = v[i as usize].map(style.number);
                let _ = write!(
                    s,
                    "{ind}{ind}{ind}vertex{g}{}{g}{}{g}{}{eol}",
                    p[0], p[1], p[2]
                );
            }
            let _ = write!(s, "{ind}{ind}endloop{eol}{ind}endfacet{eol}");
        }
        s += style.end;
        s.into_bytes()
    }

    fn styles() -> Vec<Style> {
        vec![
            Style {
                number: |x| format!("{x}"),
                indent: "  ",
                gap: " ",
                eol: "\n",
                solid: "solid fixture",
                end: "endsolid fixture\n",
            },
            Style {
                number: |x| format!("{x:.6e}"),
                indent: "\t",
                gap: "  ",
                eol: "\r\n",
                solid: "solid Part 1 (exported) ÄÖ",
                end: "endsolid\r\n",
            },
            Style {
                // C's %E: an uppercase exponent with a sign and two digits.
                number: |x| {
                    let t = format!("{x:.8E}");
                    let (m, e) = t.split_once('E').unwrap_or((&t, "0"));
                    let e: i32 = e.parse().unwrap_or(0);
                    format!("{m}E{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
                },
                indent: "",
                gap: " \t ",
                eol: " \n\n",
                solid: "  \n solid",
                end: "endsolid  name with spaces",
            },
            Style {
                number: |x| format!("{:+.17}", x),
                indent: "    ",
                gap: "\x0c ",
                eol: "\r\n \r\n",
                solid: "solid",
                end: "",
            },
        ]
    }

    fn same(a: &Result<RawMesh, MeshError>, b: &Result<RawMesh, MeshError>, what: &str) {
        match (a, b) {
            (Ok(a), Ok(b)) => {
                let bits = |m: &RawMesh| -> Vec<[u64; 3]> {
                    m.vertices.iter().map(|p| p.map(f64::to_bits)).collect()
                };
                assert_eq!(bits(a), bits(b), "{what}: vertices");
                assert_eq!(a.faces.indices, b.faces.indices, "{what}: corners");
                assert_eq!(a.faces.starts, b.faces.starts, "{what}: faces");
                assert_eq!(
                    (&a.notes, &a.warnings, a.welded),
                    (&b.notes, &b.warnings, b.welded),
                    "{what}"
                );
            }
            (Err(a), Err(b)) => assert_eq!(format!("{a:?}"), format!("{b:?}"), "{what}"),
            (a, b) => panic!(
                "{what}: {:?} against {:?}",
                a.as_ref().err(),
                b.as_ref().err()
            ),
        }
    }

    /// Every way in: in memory (one chunk, and tiny chunks), streamed in tiny pieces and chunks (lines
    /// longer than a piece, chunk borders everywhere), and through `read_split` as a file is read.
    fn check(bytes: &[u8], what: &str) {
        let path = Path::new("t.stl");
        let reference = ascii_reference(bytes, path);
        same(&reference, &ascii(bytes, path), what);
        for (piece, chunk) in [(7, 1), (64, 40), (300, 100), (1 << 20, 1000)] {
            let mut tiny = Ascii::new(path, chunk);
            tiny.feed(bytes);
            same(
                &reference,
                &tiny.finish(),
                &format!("{what}, chunks of {chunk}"),
            );
            let head = bytes[..bytes.len().min(5)].to_vec();
            let streamed = ascii_stream(head, &bytes[bytes.len().min(5)..], path, piece, chunk);
            same(
                &reference,
                &streamed,
                &format!("{what}, pieces of {piece}, chunks of {chunk}"),
            );
        }
        if looks_ascii(bytes) && is_text(&bytes[..bytes.len().min(4096)]) {
            let read = read_split(bytes, bytes.len() as u64, path, CHUNK, None);
            same(&reference, &read, &format!("{what}, read"));
        }
    }

    /// The streaming reader gives the whole-text reader's vertices and faces bit for bit, on files
    /// written in several styles (exponents, CRLF, tabs and form feeds, blank lines, `solid` names,
    /// no final newline, quads), and on text spanning many chunks.
    #[test]
    fn streamed_ascii_is_the_whole_text_parse() {
        let (v, f) = mesh();
        for (k, style) in styles().iter().enumerate() {
            let bytes = write(style, &v, &f);
            check(&bytes, &format!("style {k}"));
            assert!(ascii(&bytes, Path::new("t")).is_ok_and(|m| m.faces.len() == f.len()));
        }
        // Large enough for several default chunks, written as a common exporter writes.
        let mut big_v = Vec::new();
        let mut big_f = Vec::new();
        for copy in 0..400u32 {
            let base = big_v.len() as u32;
            big_v.extend(v.iter().map(|p| [p[0] + f64::from(copy % 3), p[1], p[2]]));
            big_f.extend(f.iter().map(|face| face.iter().map(|i| i + base).collect()));
        }
        let bytes = write(&styles()[1], &big_v, &big_f);
        assert!(bytes.len() > 3 * ASCII_CHUNK, "{}", bytes.len());
        check(&bytes, "big");
        let m = ascii(&bytes, Path::new("t")).expect("parses");
        // Copies 0 and 3 coincide: their corners weld across chunks.
        assert_eq!(m.vertices.len(), 3 * v.len());
    }

    /// Files the reader accepts although they are odd, and files it refuses: the same faces, or the
    /// same error (line, message), as the whole-text reader, however the text is cut.
    #[test]
    fn streamed_ascii_errors_and_oddities_are_the_whole_text_parse() {
        let facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
        let cases: Vec<(String, &str)> = vec![
            (format!("solid a\n{facet}{facet}endsolid a\n"), "two facets"),
            (String::new() + "solid", "no facets"),
            ("solid x\n".to_string(), "no facets, newline"),
            (
                format!("solid a\nfacet\nouter loop\nvertex 0 0 0\nfacet normal 1 2 3\nvertex 1 0 0\nvertex 0 1 0\nendloop\n{facet}"),
                "`facet` inside a loop",
            ),
            (format!("solid a\n{facet}endloop\nendloop\n{facet}"), "endloop repeated"),
            (format!("solid a\n{facet}vertex 1 2 3 4 extra\n"), "vertex outside a loop"),
            (format!("solid a\n{facet}outer\nvertex 1 2\n"), "two coordinates"),
            (format!("solid a\n{facet}outer\nvertex 1 2 x3\n"), "not a number"),
            (format!("solid a\n{facet}outer\nvertex 1 2 1e999\n"), "not finite"),
            (format!("solid a\n{facet}outer\nvertex 1 2 3\nendloop\n"), "two vertices"),
            (format!("solid a\n{facet}bogus line\n{facet}"), "unexpected word"),
            (format!("solid a\n{facet}outer loop\nvertex 1 2 3\n"), "ends in a facet"),
            (format!("solid a\n{facet}outer loop\nvertex 1 2 3"), "ends in a facet, no newline"),
            (
                format!("solid a\n{facet}outer loop\nvertex .5 5. -0 +1e+2\nvertex 0x1 0 0\n"),
                "odd numbers",
            ),
            (
                format!("solid a\n{facet}outer\nvertex 1 1 1\nvertex 0 1 1\nvertex 1 0 1\nvertex 0.5 0.5 0.5\nendloop\n"),
                "a polygon",
            ),
        ];
        for (text, what) in &cases {
            check(text.as_bytes(), what);
        }
        // Not UTF-8: that error wins over a syntax error before it, as the whole text was checked first.
        let mut bad = format!("solid a\n{facet}bogus\n{facet}").into_bytes();
        bad.extend_from_slice(b"vertex \xff\n");
        check(&bad, "syntax error, then not UTF-8");
        let mut bad = format!("solid a\n{facet}").into_bytes();
        bad.extend_from_slice(b"outer loop\nvertex 1 \xc3\n");
        bad.extend_from_slice(facet.repeat(40).as_bytes());
        check(&bad, "not UTF-8");
    }
}
