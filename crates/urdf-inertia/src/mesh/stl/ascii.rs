//! ASCII STL, parsed in chunks cut at `facet` lines, in parallel, with the sequential parse's result.

use super::Keyword;
use crate::mass::Polygons;
use crate::mesh::{parse_f64, short_decimal, MeshError, MeshErrorKind, RawMesh};
use scan::{
    coordinates, is_word, line_hash, load, newline, newline_at, plain_text, text_to_newline, FixedLine, HIGHS,
    SPACES,
};
use std::io::Read as _;
use std::path::Path;

mod scan;

/// Parses ASCII STL held in memory; errors carry the line. The same reader as [`ascii_stream`]'s,
/// fed the whole text at once.
pub(super) fn ascii(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let mut reader = Ascii::new(path, ASCII_CHUNK);
    reader.feed(bytes);
    reader.finish()
}

/// Reads ASCII STL from `head` (the bytes already read) and then `source`, `len` bytes in all, in
/// pieces of `piece` bytes ([`ASCII_PIECE`]; chunks of `chunk`, [`ASCII_CHUNK`]): memory is the
/// mesh and two pieces (a line longer than a piece is held whole), not the file. The next piece is read while the chunks
/// of the one before are parsed (`rayon::join`), so that on two threads the kernel's copy of the
/// file is not a serial stretch; on one thread, where the two would run in turn anyway, pieces of
/// one chunk are read one after the other into one buffer. The result, errors included, is
/// [`ascii`]'s on the whole text.
pub(super) fn ascii_stream(
    head: Vec<u8>,
    mut source: impl std::io::Read + Send,
    len: u64,
    path: &Path,
    piece: usize,
    chunk: usize,
) -> Result<RawMesh, MeshError> {
    let mut reader = Ascii::new(path, chunk);
    reader.reserve(usize::try_from(len).unwrap_or(usize::MAX));
    // Both buffers at their size from the start: growing them by doubling would copy and fault in
    // every smaller size on the way. On one thread the next piece would be read after this one is
    // parsed (`rayon::join` runs the two in turn), so there is one buffer of one chunk: a second
    // buffer, and pieces of two chunks, only faulted in more pages (the 101.6 MB torus of
    // `validation/threads.sh`, one thread: 6,735 page faults against 5,712, a fault costing about
    // what 20,000 instructions do on this machine; docs/benchmarks.md, round twelve).
    let pipelined = rayon::current_num_threads() > 1;
    let piece = if pipelined { piece } else { piece.min(chunk) };
    let mut buf = head;
    buf.reserve(piece.saturating_sub(buf.len()));
    let mut next = if pipelined { Vec::with_capacity(piece) } else { Vec::new() };
    let mut end = top_up(&mut buf, &mut source, piece, path)?;
    loop {
        if end {
            reader.feed(&buf);
            return reader.finish();
        }
        // Whole chunks only, the last one (or the only one) cut at a `facet` line; the rest waits
        // for the next piece, so that no chunk begins inside a facet (to be parsed again from the
        // state before it).
        let lines = memchr::memrchr(b'\n', &buf).map(|i| i + 1);
        let mut chunks = lines.map_or_else(Vec::new, |l| facet_chunks(&buf[..l], reader.chunk));
        let rest = chunks.pop();
        let (Some(lines), Some(mut rest)) = (lines, rest) else {
            end = top_up(&mut buf, &mut source, piece, path)?;
            continue;
        };
        // The last chunk is parsed too, up to its last `facet` line: only that facet is copied into
        // the next piece, not the whole chunk (a copy of about half a chunk every piece, 14.5 M of
        // the 101.6 MB torus's instructions at 512 KiB chunks).
        if let Some(cut) = last_facet_line(rest).filter(|&c| c > 0) {
            chunks.push(&rest[..cut]);
            rest = &rest[cut..];
        }
        if chunks.is_empty() {
            end = top_up(&mut buf, &mut source, piece, path)?;
            continue;
        }
        let parsed = lines - rest.len();
        if !pipelined {
            reader.feed_chunks(&chunks);
            if reader.utf8.is_some() {
                return reader.finish();
            }
            buf.drain(..parsed);
            end = top_up(&mut buf, &mut source, piece, path)?;
            continue;
        }
        // The next piece begins with the rest of this one, and is read while this one is parsed.
        next.clear();
        next.extend_from_slice(&buf[parsed..]);
        let ((), read) = rayon::join(
            || reader.feed_chunks(&chunks),
            || top_up(&mut next, &mut source, piece, path),
        );
        if reader.utf8.is_some() {
            return reader.finish();
        }
        end = read?;
        std::mem::swap(&mut buf, &mut next);
    }
}

/// Reads from `source` onto `buf` up to `piece` bytes (twice what it holds when one line is
/// longer); whether nothing more came (the end of the text).
fn top_up(
    buf: &mut Vec<u8>,
    source: &mut impl std::io::Read,
    piece: usize,
    path: &Path,
) -> Result<bool, MeshError> {
    let want = piece.max(2 * buf.len());
    let before = buf.len();
    source
        .take((want - before) as u64)
        .read_to_end(buf)
        .map_err(|e| MeshError::new(path, None, MeshErrorKind::Io(e.to_string())))?;
    Ok(buf.len() == before)
}

/// Bytes of ASCII STL read at a time by [`ascii_stream`] on more than one thread (on one, a chunk).
pub(super) const ASCII_PIECE: usize = 4 << 20;

/// Bytes of ASCII STL parsed as one chunk (in parallel, each on its own, as binary records).
pub(super) const ASCII_CHUNK: usize = 512 << 10;

/// Bytes a chunk of a streamed text of `len` bytes: when the text is four pieces or more, the
/// largest of [`ASCII_CHUNK`], twice and four times it with which a piece still gives every thread
/// of the pool two chunks (2 MiB on one thread, 1 MiB on two), else [`ASCII_CHUNK`]. Each chunk
/// border parses again the vertex texts the chunks on both sides share, and welds them again
/// across chunks: on the 101.6 MB torus of `validation/threads.sh`, one thread, 1 MiB chunks
/// take 921.6 M instructions down to 887.9 M, and 2 MiB chunks 763.6 M down to 754.8 M. A robot
/// mesh of a few megabytes keeps its chunks of 512 KiB for the threads.
pub(super) fn stream_chunk(len: u64) -> usize {
    let threads = rayon::current_num_threads().max(1);
    if len < 4 * ASCII_PIECE as u64 {
        return ASCII_CHUNK;
    }
    let mut chunk = ASCII_CHUNK;
    while chunk < 4 * ASCII_CHUNK && ASCII_PIECE / (2 * chunk) >= 2 * threads {
        chunk *= 2;
    }
    chunk
}

/// What a line left for the next: inside `outer loop` … `endloop`, and the corners since `outer`.
#[derive(Debug, Clone, Default, PartialEq)]
struct AsciiState {
    in_loop: bool,
    current: Vec<u32>,
}

/// One chunk of whole lines parsed on its own: a vertex for each distinct vertex text in order of
/// first appearance (welded by value later, across chunks), faces as indices into them (plus
/// `base`).
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

/// Parses whole lines of ASCII STL starting in `start`, numbering new vertices from `base` plus
/// the length of `vertices`, to which they are added (and the corners to `indices`: both empty
/// but for the reader's own lists when the chunks are parsed in turn). `slots` is a table's empty
/// slots from a chunk before, or none (see [`SeenLines::with_slots`]); this chunk's, empty again,
/// are left in it.
fn ascii_chunk(
    text: &[u8],
    start: AsciiState,
    base: u32,
    slots: &mut Vec<u64>,
    (vertices, indices): (Vec<[f64; 3]>, Vec<u32>),
) -> AsciiChunk {
    let empty = |end: AsciiState| AsciiChunk {
        vertices: Vec::new(),
        indices: Vec::new(),
        sizes: Vec::new(),
        lines: 0,
        end,
        dependent: false,
        outer: false,
        error: None,
        utf8: None,
    };
    let mut out = empty(AsciiState::default());
    // The fast path takes a corner only inside a loop, and before the chunk's first `outer` it is
    // in one only when it started in one: then a corner there makes the chunk dependent, and so
    // does starting in a loop (when an `outer` comes first instead, the state it leaves is its end
    // either way). Set here, it need not be or-ed at each corner.
    out.dependent = start.in_loop;
    // About 250 bytes a facet, half a new vertex a facet, and the vertices a chunk shares with the
    // one before parsed again in it (a third more on a closed mesh written row by row): a vertex
    // for every 320 bytes holds them all without growing the lists (a copy of each on every chunk
    // at 400) and takes as many slots (4 Ki for a 512 KiB chunk).
    out.indices = indices;
    out.indices.reserve(text.len() / 80);
    out.sizes.reserve(text.len() / 240);
    let mut vertices = vertices;
    vertices.reserve(text.len() / 320 + 16);
    let mut p = ChunkParse {
        out,
        vertices,
        seen: SeenLines::with_slots(text.len() / 320 + 16, std::mem::take(slots)),
        in_loop: start.in_loop,
        current: start.current.clone(),
        base,
        outer_line: FixedLine::NONE,
        endloop_line: FixedLine::NONE,
        endfacet_line: FixedLine::NONE,
        vertex_start: FixedLine::NONE,
        facet_start: FixedLine::NONE,
        key_len: 0,
        facet_len: 0,
    };
    // The bitwise or of the words the fast path loaded ([`HIGHS`] after a line of the general path).
    let mut bytes = 0;
    let mut at = 0;
    while at < text.len() {
        p.out.lines += 1;
        if let Some(next) = p.fast_line(text, at, &mut bytes) {
            at = next;
            continue;
        }
        // Anything the fast path does not take (an error included) goes through the general one.
        let (line, next) = match memchr::memchr(b'\n', &text[at..]) {
            Some(i) => (&text[at..at + i], at + i + 1),
            None => (&text[at..], text.len()),
        };
        at = next;
        bytes |= HIGHS;
        let mut words = AsciiWords { rest: line };
        let Some(word) = words.next() else { continue };
        if let Err(kind) = p.line(word, words) {
            p.out.error = Some((p.out.lines, kind));
            break;
        }
    }
    // Every byte the fast path took was in a word it loaded: when none had its top bit set, the
    // text is ASCII, so UTF-8; else (and after a line of the general path, or an error) the whole
    // chunk is checked, and text that is not UTF-8 gives nothing but where it stops being so.
    if bytes & HIGHS != 0 {
        if let Err(e) = std::str::from_utf8(text) {
            let mut out = empty(start);
            out.utf8 = Some(e.valid_up_to());
            return out;
        }
    }
    *slots = p.seen.into_slots();
    let mut out = p.out;
    out.vertices = p.vertices;
    out.end = AsciiState {
        in_loop: p.in_loop,
        current: p.current,
    };
    out
}

/// A chunk being parsed: what it has produced, its vertex texts, and the facet it is in.
struct ChunkParse<'t> {
    out: AsciiChunk,
    /// The coordinates of each distinct vertex text, in order of first appearance. Not welded
    /// here: two texts of the same value (`1e0`, `1.000000e+00`) are two vertices until the weld
    /// across chunks ([`crate::mesh::weld::join`], which welds every repeat, within a chunk too,
    /// to its first copy: the same result as a table here). A table of the coordinates' bits
    /// was 26 M of the 101.6 MB torus's 865.5 M instructions, for texts that are distinct there.
    vertices: Vec<[f64; 3]>,
    seen: SeenLines<'t>,
    in_loop: bool,
    /// The corners since `outer`.
    current: Vec<u32>,
    /// The number of the chunk's first new vertex.
    base: u32,
    /// The last `outer`, `endloop` and `endfacet` lines the fast path took, byte for byte (with
    /// their `\n`): the line after a `facet` line, and the two after a facet's last corner, are
    /// compared with them whole and, when they are the same bytes, done as they were.
    outer_line: FixedLine,
    endloop_line: FixedLine,
    endfacet_line: FixedLine,
    /// The start of the last `vertex` line the fast path took, up to the blank after the keyword:
    /// a line inside a loop that begins with the same bytes is a `vertex` line whose text starts
    /// at that blank.
    vertex_start: FixedLine,
    /// The same for `facet` lines outside a loop.
    facet_start: FixedLine,
    /// The length of the last vertex text read to its `\n`.
    key_len: usize,
    /// The length of the rest of the last `facet` line read to its `\n` (from the blank after
    /// the keyword).
    facet_len: usize,
}

impl<'t> ChunkParse<'t> {
    /// One line, whose first word is `word` and the rest `words`.
    #[inline]
    fn line(&mut self, word: &[u8], words: AsciiWords<'t>) -> Result<(), MeshErrorKind> {
        match Keyword::of(word) {
            Keyword::Vertex => {
                self.out.dependent |= !self.out.outer;
                if !self.in_loop {
                    return Err(MeshErrorKind::Syntax(
                        "`vertex` outside `outer loop`".into(),
                    ));
                }
                let index = self.vertex(words)?;
                self.current.push(self.base + index);
            }
            Keyword::Outer => {
                self.out.outer = true;
                self.in_loop = true;
                self.current.clear();
            }
            Keyword::EndLoop => {
                self.out.dependent |= !self.out.outer;
                self.in_loop = false;
                if self.current.len() < 3 {
                    return Err(MeshErrorKind::Syntax(format!(
                        "a facet with {} vertices",
                        self.current.len()
                    )));
                }
                self.out.indices.extend_from_slice(&self.current);
                self.out.sizes.push(self.current.len() as u32);
            }
            Keyword::Ignored => {}
            Keyword::Other => {
                return Err(MeshErrorKind::Syntax(format!(
                    "unexpected `{}` in ASCII STL",
                    String::from_utf8_lossy(word)
                )));
            }
        }
        Ok(())
    }

    /// The chunk's index of the vertex after `vertex`. The coordinates are a function of the line's
    /// text after the keyword: a text seen before in the chunk is the vertex it gave then, unparsed
    /// (each vertex of a closed mesh is written at its six or so corners).
    #[inline]
    fn vertex(&mut self, mut words: AsciiWords<'t>) -> Result<u32, MeshErrorKind> {
        let key = words.rest;
        let h = line_hash(key);
        let (slot, seen) = self.seen.find(key, h);
        if let Some(i) = seen {
            return Ok(i);
        }
        let i = self.new_vertex(words.vertex()?);
        self.seen.insert(slot, key, h, i);
        Ok(i)
    }

    /// The line that starts at `at` when it is a well-formed line of the common shapes (a keyword
    /// in any case after blanks, a vertex whose text was seen or parses), done as [`Self::line`] does
    /// it, and where the next line starts; `None`, with nothing changed, for anything else (errors
    /// included), which [`Self::line`] then decides. Each byte is read about once, eight at a time
    /// (every word loaded is or-ed into `bytes`, for the UTF-8 check):
    /// the blanks, the keyword (one load, its case folded), and the rest of the line up to its `\n`,
    /// hashed on the way when it is a vertex's text.
    #[inline]
    fn fast_line(&mut self, text: &'t [u8], mut at: usize, bytes: &mut u64) -> Option<usize> {
        let line_start = at;
        if self.in_loop {
            if self.vertex_start.at(text, at) {
                return self.corner(text, at + self.vertex_start.len() - 1, bytes);
            }
        } else if self.facet_start.at(text, at) {
            return Some(self.facet(text, at + self.facet_start.len() - 1, bytes));
        }
        loop {
            let v = load(text, at);
            *bytes |= v;
            let blanks = v ^ SPACES;
            if blanks == 0 {
                at += 8;
                continue;
            }
            at += blanks.trailing_zeros() as usize / 8;
            match *text.get(at)? {
                b'\t' | b'\r' | b'\x0c' => at += 1,
                b'\n' => return Some(at + 1),
                _ => break,
            }
        }
        let w = load(text, at);
        *bytes |= w;
        match w as u8 | 0x20 {
            b'v' if is_word(text, at, w, b"vertex") => {
                if !self.in_loop {
                    return None;
                }
                let next = self.corner(text, at + 6, bytes)?;
                self.vertex_start = FixedLine::of(text, line_start, at + 7);
                return Some(next);
            }
            b'o' if is_word(text, at, w, b"outer") => {
                self.outer();
                let end = newline(text, at + 5, bytes).map_or(text.len(), |i| i + 1);
                self.outer_line = FixedLine::line(text, line_start, end);
                return Some(end);
            }
            b'e' if is_word(text, at, w, b"endloop") => {
                if self.current.len() < 3 {
                    return None;
                }
                self.end_loop();
                let end = newline(text, at + 7, bytes).map_or(text.len(), |i| i + 1);
                self.endloop_line = FixedLine::line(text, line_start, end);
                return Some(end);
            }
            b'f' if is_word(text, at, w, b"facet") => {
                self.facet_start = FixedLine::of(text, line_start, at + 6);
                return Some(self.facet(text, at + 5, bytes));
            }
            b'e' if is_word(text, at, w, b"endfacet") => {
                let end = newline(text, at + 8, bytes).map_or(text.len(), |i| i + 1);
                self.endfacet_line = FixedLine::line(text, line_start, end);
                return Some(end);
            }
            b'e' if is_word(text, at, w, b"endsolid") => at += 8,
            b's' if is_word(text, at, w, b"solid") => at += 5,
            _ => return None,
        }
        // The rest of a line other than `vertex` is not read (as `Keyword::of` decides on the
        // first word alone).
        Some(newline(text, at, bytes).map_or(text.len(), |i| i + 1))
    }

    /// A `vertex` line inside a loop whose text after the keyword starts at `from` (with the
    /// blank after it): its corner, and where the fast path goes on ([`Self::after_corner`]);
    /// `None`, with nothing changed, when the text is not three decimals and a newline.
    #[inline(always)]
    fn corner(&mut self, text: &'t [u8], from: usize, bytes: &mut u64) -> Option<usize> {
        // The text as long as the last one, when a `\n` ends it there and it was seen: being a text
        // seen (whole lines, or-ed into `bytes`), it holds no `\n` and needs no or.
        let guess = from + self.key_len;
        // The text, its hash, and the slot of the lookup already made with them, if one was.
        let (end, h, looked) = if text.get(guess) == Some(&b'\n') {
            let key = &text[from..guess];
            let h = line_hash(key);
            let (slot, seen) = self.seen.find(key, h);
            if let Some(i) = seen {
                self.current.push(self.base + i);
                return Some(self.after_corner(text, guess + 1));
            }
            // A text not seen: its hash and its lookup stand when it holds no `\n` and is ASCII
            // (nothing for the UTF-8 accumulator).
            if plain_text(key) {
                (guess, h, Some(slot))
            } else {
                let (end, h) = text_to_newline(text, from, bytes)?;
                (end, h, None)
            }
        } else {
            let (end, h) = text_to_newline(text, from, bytes)?;
            (end, h, None)
        };
        self.key_len = end - from;
        let key = &text[from..end];
        let (slot, seen) = looked.map_or_else(|| self.seen.find(key, h), |slot| (slot, None));
        let i = if let Some(i) = seen {
            i
        } else {
            let p = coordinates(text, from)?;
            let i = self.new_vertex(p);
            self.seen.insert(slot, key, h, i);
            i
        };
        self.current.push(self.base + i);
        Some(self.after_corner(text, end + 1))
    }

    /// A `facet` line whose rest after the keyword starts at `from` (not read but for its `\n`):
    /// where the fast path goes on, past the next line too when it is the last `outer` line taken,
    /// byte for byte (done as it was).
    #[inline(always)]
    fn facet(&mut self, text: &[u8], from: usize, bytes: &mut u64) -> usize {
        // As long as the last `facet` line's rest, most often (exporters write the normal's three
        // numbers in one format): checked in one pass without a branch a word.
        let end = if let Some(i) = newline_at(text, from, self.facet_len) {
            i + 1
        } else {
            let i = newline(text, from, bytes);
            self.facet_len = i.map_or(0, |i| i - from);
            i.map_or(text.len(), |i| i + 1)
        };
        if self.outer_line.at(text, end) {
            self.out.lines += 1;
            self.outer();
            return end + self.outer_line.len();
        }
        end
    }

    /// The index of a vertex text not seen before in the chunk, whose coordinates are `p`.
    #[inline(always)]
    fn new_vertex(&mut self, p: [f64; 3]) -> u32 {
        self.vertices.push(p);
        self.vertices.len() as u32 - 1
    }

    /// `outer`: a facet's corners begin.
    #[inline(always)]
    fn outer(&mut self) {
        self.out.outer = true;
        self.in_loop = true;
        self.current.clear();
    }

    /// `endloop` after at least three corners: the face.
    #[inline(always)]
    fn end_loop(&mut self) {
        self.out.dependent |= !self.out.outer;
        self.in_loop = false;
        // A triangle as three stores: `extend_from_slice` of a length known only at run time is a
        // `memcpy` call a face.
        if let [a, b, c] = self.current[..] {
            self.out.indices.extend_from_slice(&[a, b, c]);
        } else {
            self.out.indices.extend_from_slice(&self.current);
        }
        self.out.sizes.push(self.current.len() as u32);
    }

    /// Where the fast path goes on after a corner's line that ends before `at`: past the next line
    /// and the one after it when they are the last `endloop` and `endfacet` lines taken, byte for
    /// byte (and the facet has three corners or more), done as they were; else `at`.
    #[inline(always)]
    fn after_corner(&mut self, text: &[u8], at: usize) -> usize {
        if self.current.len() < 3 || !self.endloop_line.at(text, at) {
            return at;
        }
        self.out.lines += 1;
        self.end_loop();
        let at = at + self.endloop_line.len();
        if !self.endfacet_line.at(text, at) {
            return at;
        }
        self.out.lines += 1;
        at + self.endfacet_line.len()
    }
}

/// The vertex lines of a chunk already parsed, by their text after `vertex`, and the vertex each
/// gave: an open-addressing table of slices of the chunk's text (the text is the key, so a hit is
/// exactly the vertex a parse would give, and a miss parses as before).
struct SeenLines<'t> {
    /// Each text, its vertex, and the slot it was put in.
    lines: Vec<(&'t [u8], u32, u32)>,
    /// 0: empty; else `tag << 32 | (index into lines + 1)`.
    slots: Vec<u64>,
    /// 64 − log2(slots.len()): the slot is the top bits of the hash.
    shift: u32,
    /// The slots were made anew for more lines (the slots of `lines` are stale).
    grown: bool,
}

impl<'t> SeenLines<'t> {
    #[cfg(test)]
    fn with_capacity(expected: usize) -> Self {
        Self::with_slots(expected, Vec::new())
    }

    /// A table for about `expected` lines, in `slots` when they are all empty and the size it
    /// takes (what [`Self::into_slots`] gave back from a chunk before): a chunk's fresh slots
    /// (64 KiB at 1 MiB chunks) were zeroed, where emptying only the slots its lines took costs a
    /// store a line (the 101.6 MB torus of `validation/threads.sh`: 817.5 M instructions down to
    /// 809.5 M).
    fn with_slots(expected: usize, slots: Vec<u64>) -> Self {
        let size = (2 * expected).next_power_of_two().max(16);
        let slots = if slots.len() == size { slots } else { vec![0; size] };
        SeenLines {
            lines: Vec::with_capacity(expected),
            slots,
            shift: 64 - size.trailing_zeros(),
            grown: false,
        }
    }

    /// The slots, all empty again, for [`Self::with_slots`] (none when they grew).
    fn into_slots(self) -> Vec<u64> {
        if self.grown {
            return Vec::new();
        }
        let mut slots = self.slots;
        for &(_, _, s) in &self.lines {
            slots[s as usize] = 0;
        }
        slots
    }

    /// Where `key` is (its vertex), or the empty slot where it would go; neither when the probe
    /// runs past [`MAX_PROBES`] slots.
    #[inline]
    fn find(&self, key: &[u8], h: u64) -> (Option<usize>, Option<u32>) {
        let tag = h << 32;
        let mask = self.slots.len() - 1;
        let mut s = (h >> self.shift) as usize;
        for _ in 0..MAX_PROBES {
            let slot = self.slots[s];
            if slot == 0 {
                return (Some(s), None);
            }
            if slot & 0xffff_ffff_0000_0000 == tag {
                let (text, vertex, _) = self.lines[(slot as u32 - 1) as usize];
                if text == key {
                    return (Some(s), Some(vertex));
                }
            }
            s = (s + 1) & mask;
        }
        (None, None)
    }

    #[cfg(test)]
    fn get(&self, key: &[u8]) -> Option<u32> {
        self.find(key, line_hash(key)).1
    }

    /// Records that `key` (not yet seen) gave `vertex`, in the `slot` [`Self::find`] gave, unless
    /// its probe was too long (no slot): then the line is simply parsed again wherever it comes back.
    #[inline(always)]
    fn insert(&mut self, slot: Option<usize>, key: &'t [u8], h: u64, vertex: u32) {
        let Some(s) = slot else {
            return;
        };
        self.lines.push((key, vertex, s as u32));
        self.slots[s] = (h << 32) | self.lines.len() as u64;
        if 2 * self.lines.len() > self.slots.len() {
            self.grow();
        }
    }

    /// Twice the slots, the lines put in them again.
    #[cold]
    #[inline(never)]
    fn grow(&mut self) {
        let size = 2 * self.slots.len();
        self.slots = vec![0; size];
        self.shift = 64 - size.trailing_zeros();
        self.grown = true;
        for (i, &(text, _, _)) in self.lines.iter().enumerate() {
            let h = line_hash(text);
            if let (Some(s), _) = self.find(text, h) {
                self.slots[s] = (h << 32) | (i as u64 + 1);
            }
        }
    }
}

thread_local! {
    /// The emptied slots of the last chunk's [`SeenLines`] on this thread, for the next chunk it
    /// parses, in this feed or a later one (at most 128 KiB a thread, kept after the read): made
    /// afresh for each piece's first chunk instead, the 101.6 MB torus of `validation/threads.sh`
    /// took 754.8 M instructions on one thread, against 747.1 M.
    static SLOTS: std::cell::RefCell<Vec<u64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Slots a lookup in [`SeenLines`] probes at most: the table is at most half full, so an honest
/// file's probes are a few slots; a file made for its hash to collide gets its lines parsed (as
/// without the table) instead of a lookup that grows with the chunk.
const MAX_PROBES: usize = 32;

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
            .position(u8::is_ascii_whitespace)
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
        for c in &mut p {
            let skip = self
                .rest
                .iter()
                .position(|b| !b.is_ascii_whitespace())
                .unwrap_or(self.rest.len());
            self.rest = &self.rest[skip..];
            let fast = short_decimal(self.rest)
                .filter(|&(_, n)| self.rest.get(n).is_none_or(u8::is_ascii_whitespace));
            *c = if let Some((x, n)) = fast {
                self.rest = &self.rest[n..];
                x
            } else {
                let w = self.next().ok_or_else(|| {
                    MeshErrorKind::Syntax("`vertex` needs three coordinates".into())
                })?;
                // The chunk is UTF-8 and `w` is cut at ASCII bytes, so `from_utf8` succeeds.
                let w = std::str::from_utf8(w).unwrap_or_default();
                parse_f64(w)
                    .ok_or_else(|| MeshErrorKind::Syntax(format!("`{w}` is not a number")))?
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
/// ([`crate::mesh::weld::join`]): the result is the one sequential parse's, bit for bit, for any thread
/// count. On one thread the chunks are parsed in turn instead, each from the state the one before
/// left, into the reader's own lists ([`Self::feed_in_turn`]).
pub(super) struct Ascii<'p> {
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
    pub(super) fn new(path: &'p Path, chunk: usize) -> Self {
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

    /// Makes room in the mesh's lists for the facets of a text of `len` bytes, as exporters write
    /// it (about 250 bytes a facet, half a vertex a facet; room is made for twice that): grown by
    /// doubling instead, the lists were copied at every size and each copy's pages faulted in
    /// afresh. Room never written is never faulted in, so a text of shorter facets costs no memory
    /// for it (and grows its lists as before past it).
    fn reserve(&mut self, len: usize) {
        let facets = len / 128;
        self.indices.reserve(3 * facets);
        self.starts.reserve(facets);
        self.vertices.reserve(facets);
    }

    pub(super) fn feed(&mut self, text: &[u8]) {
        self.feed_chunks(&facet_chunks(text, self.chunk));
    }

    /// [`Self::feed`] of the text `chunks` cut ([`facet_chunks`]).
    fn feed_chunks(&mut self, chunks: &[&[u8]]) {
        use rayon::prelude::*;
        if self.utf8.is_some() {
            return;
        }
        let offset = self.offset;
        self.offset += chunks.iter().map(|c| c.len()).sum::<usize>();
        if self.error.is_some() {
            let mut at = offset;
            for c in chunks {
                if let Err(e) = std::str::from_utf8(c) {
                    self.utf8 = Some(at + e.valid_up_to());
                    return;
                }
                at += c.len();
            }
            return;
        }
        if rayon::current_num_threads() == 1 {
            self.feed_in_turn(chunks, offset);
            return;
        }
        let parsed: Vec<AsciiChunk> = chunks
            .par_iter()
            .map(|c| {
                SLOTS.with_borrow_mut(|slots| {
                    ascii_chunk(c, AsciiState::default(), 0, slots, Default::default())
                })
            })
            .collect();
        let mut at = offset;
        for (text, mut chunk) in chunks.iter().zip(parsed) {
            let here = at;
            at += text.len();
            // What the chunk's corners need added (a chunk parsed again below numbers its own).
            let mut rebase = 0;
            if self.error.is_none() {
                if chunk.dependent && self.state != AsciiState::default() {
                    let start = std::mem::take(&mut self.state);
                    let base = self.vertices.len() as u32;
                    chunk = ascii_chunk(text, start, base, &mut Vec::new(), Default::default());
                } else {
                    rebase = self.vertices.len() as u32;
                    chunk.end.current.iter_mut().for_each(|i| *i += rebase);
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
            // Rebased as they are copied: one pass, not a pass in place and a `memcpy`.
            self.indices.extend(chunk.indices.iter().map(|&i| i + rebase));
            // A chunk that neither began a facet nor touched the state leaves it as it was.
            if chunk.outer || chunk.dependent {
                self.state = chunk.end;
            }
            self.lines += chunk.lines;
        }
    }

    /// [`Self::feed_chunks`] on one thread: each chunk parsed from the state the one before left,
    /// its vertices and corners added to the reader's lists as it parses them, where chunks parsed
    /// apart (for the threads) are parsed from the state outside a facet, parsed again when that
    /// was wrong, and copied into the lists with their corners renumbered.
    fn feed_in_turn(&mut self, chunks: &[&[u8]], mut at: usize) {
        for text in chunks {
            let here = at;
            at += text.len();
            if self.error.is_some() {
                if let Err(e) = std::str::from_utf8(text) {
                    self.utf8 = Some(here + e.valid_up_to());
                    return;
                }
                continue;
            }
            let start = std::mem::take(&mut self.state);
            let lists = (std::mem::take(&mut self.vertices), std::mem::take(&mut self.indices));
            let chunk = SLOTS.with_borrow_mut(|slots| ascii_chunk(text, start, 0, slots, lists));
            if let Some(u) = chunk.utf8 {
                self.utf8 = Some(here + u);
                return;
            }
            self.vertices = chunk.vertices;
            self.indices = chunk.indices;
            if let Some((line, kind)) = chunk.error {
                self.error = Some((self.lines + line, kind));
                continue;
            }
            let mut s = *self.starts.last().unwrap_or(&0);
            for &n in &chunk.sizes {
                s += n;
                self.starts.push(s);
            }
            self.state = chunk.end;
            self.lines += chunk.lines;
        }
    }

    pub(super) fn finish(self) -> Result<RawMesh, MeshError> {
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
        let vertices = crate::mesh::weld::join(self.vertices, &mut indices, None);
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
            if is_facet_line(&text[next..]) {
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

/// Whether the line at the start of `line` has `facet` as its first word.
fn is_facet_line(line: &[u8]) -> bool {
    let word = line
        .iter()
        .position(|&b| !matches!(b, b' ' | b'\t' | b'\r' | b'\x0c'))
        .map_or(&line[line.len()..], |w| &line[w..]);
    word.get(..5)
        .is_some_and(|w| w.eq_ignore_ascii_case(b"facet"))
        && word.get(5).is_none_or(u8::is_ascii_whitespace)
}

/// Where the last line of `text` whose first word is `facet` starts, when one starts within its
/// last 64 KiB.
fn last_facet_line(text: &[u8]) -> Option<usize> {
    memchr::memrchr_iter(b'\n', text)
        .take_while(|&i| text.len() - i <= 64 << 10)
        .map(|i| i + 1)
        .chain(std::iter::once(0).filter(|_| text.len() <= 64 << 10))
        .find(|&start| is_facet_line(&text[start..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The last line whose first word is `facet`, in any case and after blanks, and none when no
    /// line begins with that word.
    #[test]
    fn last_facet_line_is_the_last_facet() {
        let text = b"solid a\n facet normal 0 0 1\nouter loop\n\tFACET\nendloop\nfacets\n";
        assert_eq!(last_facet_line(text), Some(39));
        assert_eq!(last_facet_line(&text[..39]), Some(8));
        assert_eq!(last_facet_line(b"facet\n"), Some(0));
        assert_eq!(last_facet_line(b"outer loop\nfacets\nendfacet\n"), None);
    }

    /// Texts of the same value in one chunk (the vertices are not welded there) are one vertex
    /// after the weld across chunks, numbered by first appearance, as a table welding each chunk
    /// gave: `-0` with `0` too.
    #[test]
    fn texts_of_one_value_are_one_vertex() {
        let text = b"solid s\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1.000000e+00 0 0\nvertex 0 1e0 -0\nvertex 0 0 10e-1\nendloop\nendfacet\nendsolid s\n";
        let mesh = ascii(text, Path::new("t.stl")).unwrap();
        assert_eq!(mesh.vertices, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert_eq!(mesh.faces.indices, [0, 1, 2, 0, 1, 2]);
    }

    /// The slots given back are all empty, the table's own when it did not grow (and then taken
    /// again as they are), none when it grew.
    #[test]
    fn seen_slots_come_back_empty() {
        let texts: Vec<String> = (0..40).map(|i| format!(" {i}.5 0 0")).collect();
        let mut slots = Vec::new();
        for n in [40, 30, 10, 40] {
            let mut seen = SeenLines::with_slots(n, std::mem::take(&mut slots));
            for (i, t) in texts.iter().take(n).enumerate() {
                let h = line_hash(t.as_bytes());
                seen.insert(seen.find(t.as_bytes(), h).0, t.as_bytes(), h, i as u32);
            }
            slots = seen.into_slots();
            assert_eq!(slots.len(), (2 * n).next_power_of_two());
            assert!(slots.iter().all(|&s| s == 0));
        }
        let mut seen = SeenLines::with_slots(4, slots);
        for (i, t) in texts.iter().enumerate() {
            let h = line_hash(t.as_bytes());
            seen.insert(seen.find(t.as_bytes(), h).0, t.as_bytes(), h, i as u32);
        }
        assert!(seen.into_slots().is_empty());
    }

    /// Every line recorded is found with its vertex through the table's growth, a line never
    /// recorded is not, and texts that differ only in their last byte or their length are apart.
    #[test]
    fn seen_lines_give_back_what_was_recorded() {
        let texts: Vec<String> = (0..20_000)
            .map(|i| format!(" {}.000000e-01 2.5e+00 {}", i % 977, i / 977))
            .collect();
        let mut seen = SeenLines::with_capacity(4);
        for (i, t) in texts.iter().enumerate() {
            assert_eq!(seen.get(t.as_bytes()), None, "{t}");
            let h = line_hash(t.as_bytes());
            seen.insert(seen.find(t.as_bytes(), h).0, t.as_bytes(), h, i as u32);
        }
        for (i, t) in texts.iter().enumerate() {
            assert_eq!(seen.get(t.as_bytes()), Some(i as u32), "{t}");
        }
        assert_eq!(seen.get(b" 1.000000e-01 2.5e+00 1 "), None);
        assert_eq!(seen.get(b" 1.000000e-01 2.5e+00 "), None);
        assert_eq!(seen.get(b""), None);
    }
}
