//! Wavefront OBJ.
//!
//! Every object (`o`) and group (`g`) belongs to the mesh: a collision part exported as several objects is
//! one solid made of all of them. Polygons stay polygons. Indices may be negative (relative to the
//! vertices read so far); texture and normal indices (`f 1/2/3`) are ignored; `mtllib` and `usemtl` are
//! ignored, so a missing `.mtl` file or texture is no error.
//!
//! Why not tobj (the brief's choice): tobj 4 splits pentagons even with `triangulate: false` (3 of the 81
//! OBJ files of example-robot-data, e.g. alexander's LeftThigh.obj: 985 faces against the file's 983),
//! re-indexes each object separately, and its errors carry no line number.

use super::weld::VertexTable;
use super::{parse_f64_bytes, short_decimal, MeshError, MeshErrorKind, RawMesh};
use crate::mass::Polygons;
use std::path::Path;

/// Parses OBJ text. Vertices with bit-identical coordinates are welded as they are read (the health
/// step's exact weld, done here so that it is not done again): faces index the distinct vertices.
///
/// The text is read as bytes: keywords, numbers and separators are ASCII, so a stray non-UTF-8 byte
/// (a Latin-1 comment) needs no decoding, and only an error message decodes its word; numbers are
/// scanned where they stand ([`Words::number`]). laikago's trunk.obj (1.9 MB): 78 M instructions
/// with a `from_utf8_lossy` and `str` splitting per line and `str::parse`, 38 M so.
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let mut reader = Reader {
        vertices: VertexTable::with_capacity(bytes.len() / 128 + 16),
        remap: Vec::new(),
        faces: Polygons::new(),
        face: Vec::new(),
        objects: 0,
        degenerate: None,
        degenerate_count: 0,
        path,
    };
    let mut pending: Vec<u8> = Vec::new();
    let mut start_line = 0;
    // memchr finds the line ends (`split` on a byte took 7 instructions a byte).
    let ends = memchr::memchr_iter(b'\n', bytes).chain([bytes.len()]);
    let mut from = 0;
    for (index, end) in ends.enumerate() {
        let raw = &bytes[from..end];
        from = end + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        // Backslash continues a line.
        if let Some(stripped) = raw.strip_suffix(b"\\") {
            if pending.is_empty() {
                start_line = index + 1;
            }
            pending.extend_from_slice(stripped);
            pending.push(b' ');
            continue;
        }
        if pending.is_empty() {
            reader.line(raw, index + 1)?;
        } else {
            pending.extend_from_slice(raw);
            reader.line(&pending, start_line)?;
            pending.clear();
        }
    }
    Ok(reader.finish())
}

/// What [`parse`] has read so far.
struct Reader<'p> {
    vertices: VertexTable,
    /// The distinct vertex of each `v` line, in file order (what face indices count).
    remap: Vec<u32>,
    faces: Polygons,
    face: Vec<u32>,
    objects: usize,
    /// Faces with fewer than three vertices: the line of the first, and how many.
    degenerate: Option<usize>,
    degenerate_count: usize,
    path: &'p Path,
}

impl Reader<'_> {
    /// Reads one (joined) line.
    fn line(&mut self, line: &[u8], lineno: usize) -> Result<(), MeshError> {
        let mut words = Words { rest: line };
        match words.next() {
            Some(b"v") => {
                let p = vertex(words, lineno, self.path)?;
                // + 0.0 folds −0.0 into 0.0, so that both weld (`RawMesh::welded`).
                let p = [p[0] + 0.0, p[1] + 0.0, p[2] + 0.0];
                self.remap.push(self.vertices.insert(p));
            }
            Some(b"f") => {
                let face = &mut self.face;
                face_indices(words, self.remap.len(), face, lineno, self.path)?;
                for i in face.iter_mut() {
                    *i = self.remap[*i as usize];
                }
                // A face of fewer than three vertices encloses nothing: skipped and counted, as other
                // OBJ readers (assimp, tinyobjloader) do.
                if face.len() < 3 {
                    self.degenerate.get_or_insert(lineno);
                    self.degenerate_count += 1;
                } else {
                    self.faces.push(face);
                }
            }
            Some(b"o" | b"g") => self.objects += 1,
            // Everything else is irrelevant to the solid: vt, vn, vp, s, l, p, usemtl, mtllib, curves.
            _ => {}
        }
        Ok(())
    }

    fn finish(self) -> RawMesh {
        let mut notes = Vec::new();
        if self.objects > 1 {
            notes.push(format!(
                "{} objects/groups, all counted as one solid",
                self.objects
            ));
        }
        let mut warnings = Vec::new();
        if let Some(line) = self.degenerate {
            warnings.push(format!(
                "{} face(s) with fewer than three vertices skipped (the first on line {line})",
                self.degenerate_count
            ));
        }
        RawMesh {
            vertices: self.vertices.into_vertices(),
            faces: self.faces,
            notes,
            warnings,
            welded: true,
        }
    }
}

/// The words of a line: runs of bytes between ASCII whitespace, up to the first `#` (what
/// `line.split('#').next()` then `split_ascii_whitespace` gave, in one pass).
struct Words<'a> {
    rest: &'a [u8],
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a [u8];

    fn next(&mut self) -> Option<&'a [u8]> {
        let start = self.rest.iter().position(|b| !b.is_ascii_whitespace())?;
        let rest = &self.rest[start..];
        let len = rest
            .iter()
            .position(|&b| b.is_ascii_whitespace() || b == b'#')
            .unwrap_or(rest.len());
        let (word, after) = rest.split_at(len);
        self.rest = if after.first() == Some(&b'#') {
            &[]
        } else {
            after
        };
        // A word starting with `#` is the comment.
        (!word.is_empty()).then_some(word)
    }
}

impl<'a> Words<'a> {
    /// Whether the next word ends at `n` bytes from its start (`rest` starting at it): if so, it is
    /// consumed.
    fn ends_at(&mut self, n: usize) -> bool {
        match self.rest.get(n) {
            None | Some(b'#') => self.rest = &[],
            Some(b) if b.is_ascii_whitespace() => self.rest = &self.rest[n..],
            Some(_) => return false,
        }
        true
    }

    /// The next word as a number: scanned in place when it is a short decimal (one pass over its
    /// bytes, not a split and a parse), else cut out and parsed (`Err` the word if it is no number).
    fn number(&mut self) -> Option<Result<f64, &'a [u8]>> {
        let start = self.rest.iter().position(|b| !b.is_ascii_whitespace())?;
        self.rest = &self.rest[start..];
        if let Some((x, n)) = short_decimal(self.rest) {
            if self.ends_at(n) {
                return Some(Ok(x));
            }
        }
        let w = self.next()?;
        Some(parse_f64_bytes(w).ok_or(w))
    }

    /// The next word's vertex index (what comes before a `/`), scanned in place when it is a short
    /// integer, else cut out and parsed (`Err` the word if it is no integer).
    fn index(&mut self) -> Option<Result<i64, &'a [u8]>> {
        let start = self.rest.iter().position(|b| !b.is_ascii_whitespace())?;
        self.rest = &self.rest[start..];
        let r = self.rest;
        let sign = usize::from(matches!(r.first(), Some(b'-' | b'+')));
        let mut i = sign;
        let mut value = 0i64;
        // Up to 18 digits cannot overflow; longer words go to `str::parse`.
        while i < sign + 18 {
            match r.get(i) {
                Some(&d @ b'0'..=b'9') => value = 10 * value + i64::from(d - b'0'),
                _ => break,
            }
            i += 1;
        }
        if i > sign {
            let value = if r[0] == b'-' { -value } else { value };
            if r.get(i) == Some(&b'/') {
                // Texture and normal indices: the rest of the word.
                self.next();
                return Some(Ok(value));
            }
            if self.ends_at(i) {
                return Some(Ok(value));
            }
        }
        let w = self.next()?;
        let idx = w.split(|&b| b == b'/').next().unwrap_or_default();
        Some(parse_i64(idx).ok_or(w))
    }
}

/// A word as the user wrote it, for a message.
fn shown(w: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(w)
}

/// The three coordinates of a `v` line.
fn vertex(mut words: Words<'_>, lineno: usize, path: &Path) -> Result<[f64; 3], MeshError> {
    let err =
        |line: usize, msg: String| MeshError::new(path, Some(line), MeshErrorKind::Syntax(msg));
    let mut p = [0.0; 3];
    for c in &mut p {
        *c = words
            .number()
            .ok_or_else(|| err(lineno, "`v` needs three coordinates".into()))?
            .map_err(|w| err(lineno, format!("`{}` is not a number", shown(w))))?;
        if !c.is_finite() {
            return Err(MeshError::new(path, Some(lineno), MeshErrorKind::NotFinite));
        }
    }
    Ok(p)
}

/// An integer as `str::parse::<i64>` reads it: up to 18 digits directly, longer words by std.
fn parse_i64(w: &[u8]) -> Option<i64> {
    let digits = match w.split_first()? {
        (b'-' | b'+', rest) => rest,
        _ => w,
    };
    if digits.is_empty() || digits.len() > 18 || !digits.iter().all(u8::is_ascii_digit) {
        return std::str::from_utf8(w).ok()?.parse().ok();
    }
    let n = digits
        .iter()
        .fold(0i64, |n, &d| 10 * n + i64::from(d - b'0'));
    Some(if w[0] == b'-' { -n } else { n })
}

/// The vertex indices of an `f` line into `face` (0-based; negative ones count back from the
/// `vertices` read so far; texture and normal indices ignored).
fn face_indices(
    mut words: Words<'_>,
    vertices: usize,
    face: &mut Vec<u32>,
    lineno: usize,
    path: &Path,
) -> Result<(), MeshError> {
    face.clear();
    while let Some(i) = words.index() {
        let i = i.map_err(|w| {
            MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::Syntax(format!("`{}` is not a vertex index", shown(w))),
            )
        })?;
        let n = vertices as i64;
        let resolved = match i.cmp(&0) {
            std::cmp::Ordering::Greater => i - 1,
            std::cmp::Ordering::Less => n + i,
            std::cmp::Ordering::Equal => -1,
        };
        if resolved < 0 || resolved >= n {
            return Err(MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::IndexOutOfRange { index: i, vertices },
            ));
        }
        face.push(resolved as u32);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    // Issue 11: a face with two vertices is skipped and counted, not the whole file's failure.
    #[test]
    fn degenerate_faces_are_skipped_with_a_warning() {
        let text =
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2\nf 1 2 4\nf 1 4 3\nf 3\nf 2 3 4\n";
        let m = parse(text, Path::new("t.obj")).expect("degenerate faces are skipped");
        assert_eq!(m.faces.len(), 4);
        assert_eq!(
            m.warnings,
            vec![
                "2 face(s) with fewer than three vertices skipped (the first on line 6)"
                    .to_string()
            ]
        );
    }

    /// Lines end with LF or CRLF; a non-UTF-8 byte in a comment does not stop the file.
    #[test]
    fn crlf_and_latin1_comments() {
        let text = b"# caf\xe9\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 0 0 1\r\nf 1 3 2\r\nf 1 2 4\r\nf 1 4 \\\r\n 3\r\nf 2 3 4";
        let m = parse(text, Path::new("t.obj")).expect("reads");
        assert_eq!(m.vertices[3], [0.0, 0.0, 1.0]);
        assert_eq!(m.faces.indices, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
    }
}

#[cfg(test)]
mod number_tests {
    use super::super::parse_f64_bytes;
    use super::{parse_i64, Words};

    /// The spellings files use and the corners of the fast paths (19 digits, 2^53, 10^±22, signs,
    /// zeros).
    const SPELLINGS: &[&str] = &[
        "0",
        "-0",
        "+0",
        "-0.0",
        "0e0",
        "-0e-5",
        "1",
        "+1.5",
        "-.5",
        ".5",
        "5.",
        "1.e3",
        "1e",
        "1e+",
        "e5",
        ".",
        "-",
        "+",
        "",
        " 1",
        "1 ",
        "1..2",
        "1.2.3",
        "1e5e5",
        "0x10",
        "1_0",
        "inf",
        "-Infinity",
        "NaN",
        "nan",
        "+inf",
        "infx",
        "9007199254740992",
        "9007199254740993",
        "9007199254740993e-3",
        "1234567890123456789",
        "12345678901234567890",
        "0.0000000000000000001",
        "1e22",
        "1e23",
        "1e-22",
        "1e-23",
        "1e0000000308",
        "1e-400",
        "1e400",
        "-1e400",
        "4.9e-324",
        "2.2250738585072014e-308",
        "1.7976931348623157e308",
        "0.1",
        "0.3",
        "123.456e-7",
        "1E5",
        "1E-05",
        "1e+05",
        "00000000000000000001",
        "-0.0763199",
        "0.00260979",
        "-0.057",
        "1.\u{e9}",
        "\u{e9}",
        "-9223372036854775808",
        "9223372036854775807",
        "9223372036854775808",
        "999999999999999999",
        "-999999999999999999",
    ];

    /// [`SPELLINGS`], then random short decimals in the form exporters write.
    fn words() -> Vec<String> {
        let mut words: Vec<String> = SPELLINGS.iter().map(std::string::ToString::to_string).collect();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || crate::xorshift(&mut state);
        for _ in 0..200_000 {
            let r = next();
            let digits = (r % 21) as usize;
            let mut s = String::new();
            match r >> 8 & 3 {
                0 => s.push('-'),
                1 => s.push('+'),
                _ => {}
            }
            let dot = (r >> 12) as usize % (digits + 2);
            for k in 0..digits {
                if k == dot {
                    s.push('.');
                }
                s.push(char::from(b'0' + (next() % 10) as u8));
            }
            if (r >> 20).trailing_zeros() >= 2 {
                s.push('e');
                s.push_str(["", "-", "+"][(r >> 30) as usize % 3]);
                s.push_str(&((r >> 24) % 40).to_string());
            }
            words.push(s);
        }
        words
    }

    /// The first word of `line` as `str` splitting cut it (before the fast paths).
    fn cut(line: &str) -> Option<String> {
        let line = line.split('#').next().unwrap_or("");
        line.split_ascii_whitespace().next().map(str::to_string)
    }

    /// Scanned in place within a line, a word reads as cut out and parsed, and the words after it stay.
    fn check_in_line(line: &str) {
        let word = cut(line);
        let mut words = Words {
            rest: line.as_bytes(),
        };
        let got = words.number().map(|r| r.map(f64::to_bits));
        let want = word
            .as_ref()
            .map(|w| w.parse::<f64>().map(f64::to_bits).map_err(|_| w.as_bytes()));
        assert_eq!(got, want, "{line:?}");
        let mut words = Words {
            rest: line.as_bytes(),
        };
        let got = words.index();
        let want = word.as_ref().map(|w| {
            let idx = w.split('/').next().unwrap_or("");
            idx.parse::<i64>().map_err(|_| w.as_bytes())
        });
        assert_eq!(got, want, "{line:?}");
        let rest: Vec<&[u8]> = words.collect();
        let line = line.split('#').next().unwrap_or("");
        let want: Vec<&[u8]> = line
            .split_ascii_whitespace()
            .skip(1)
            .map(str::as_bytes)
            .collect();
        assert_eq!(rest, want, "{line:?}");
    }

    /// The fast paths of `parse_f64_bytes`, `parse_i64` and `Words` agree with `str::parse` to the bit.
    #[test]
    fn numbers_read_as_std_reads_them() {
        for w in &words() {
            let std = w.parse::<f64>().ok().map(f64::to_bits);
            assert_eq!(
                parse_f64_bytes(w.as_bytes()).map(f64::to_bits),
                std,
                "{w:?}"
            );
            assert_eq!(parse_i64(w.as_bytes()), w.parse::<i64>().ok(), "{w:?}");
            for (before, after) in [("", ""), (" \t", " 7"), ("", "#c 8"), ("", "/2/3 4")] {
                check_in_line(&format!("{before}{w}{after}"));
            }
        }
        assert_eq!(parse_f64_bytes(b"1.\xe9"), None);
    }
}
