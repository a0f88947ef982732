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
use super::{parse_f64, MeshError, MeshErrorKind, RawMesh};
use crate::mass::Polygons;
use std::path::Path;

/// Parses OBJ text. Vertices with bit-identical coordinates are welded as they are read (the health
/// step's exact weld, done here so that it is not done again): faces index the distinct vertices.
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let mut vertices = VertexTable::with_capacity(bytes.len() / 128 + 16);
    // The distinct vertex of each `v` line, in file order (what face indices count).
    let mut remap: Vec<u32> = Vec::new();
    let mut faces = Polygons::new();
    let mut face: Vec<u32> = Vec::new();
    let mut objects = 0usize;
    // Faces with fewer than three vertices: how many, and the line of the first.
    let mut degenerate: Option<usize> = None;
    let mut degenerate_count = 0usize;
    let mut pending = String::new();
    let mut start_line = 0;
    // Line by line from the bytes: a stray non-UTF-8 byte (a Latin-1 comment) costs a copy of its
    // line, not of the file.
    for (lineno, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let raw = String::from_utf8_lossy(raw.strip_suffix(b"\r").unwrap_or(raw));
        let raw: &str = &raw;
        // Backslash continues a line.
        if let Some(stripped) = raw.strip_suffix('\\') {
            if pending.is_empty() {
                start_line = lineno + 1;
            }
            pending.push_str(stripped);
            pending.push(' ');
            continue;
        }
        let owned;
        let (line, lineno) = if pending.is_empty() {
            (raw, lineno + 1)
        } else {
            pending.push_str(raw);
            owned = std::mem::take(&mut pending);
            (owned.as_str(), start_line)
        };
        let line = line.split('#').next().unwrap_or("");
        let mut words = line.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let p = vertex(words, lineno, path)?;
                // + 0.0 folds −0.0 into 0.0, so that both weld (`RawMesh::welded`).
                remap.push(vertices.insert(p.map(|x| x + 0.0)));
            }
            "f" => {
                face_indices(words, remap.len(), &mut face, lineno, path)?;
                for i in face.iter_mut() {
                    *i = remap[*i as usize];
                }
                // A face of fewer than three vertices encloses nothing: skipped and counted, as other
                // OBJ readers (assimp, tinyobjloader) do.
                if face.len() < 3 {
                    degenerate.get_or_insert(lineno);
                    degenerate_count += 1;
                    continue;
                }
                faces.push(&face);
            }
            "o" | "g" => objects += 1,
            // Everything else is irrelevant to the solid: vt, vn, vp, s, l, p, usemtl, mtllib, curves.
            _ => {}
        }
    }
    let mut notes = Vec::new();
    if objects > 1 {
        notes.push(format!(
            "{objects} objects/groups, all counted as one solid"
        ));
    }
    let mut warnings = Vec::new();
    if let Some(line) = degenerate {
        warnings.push(format!(
            "{degenerate_count} face(s) with fewer than three vertices skipped (the first on line {line})"
        ));
    }
    Ok(RawMesh {
        vertices: vertices.into_vertices(),
        faces,
        notes,
        warnings,
        welded: true,
    })
}

/// The three coordinates of a `v` line.
fn vertex<'a>(
    mut words: impl Iterator<Item = &'a str>,
    lineno: usize,
    path: &Path,
) -> Result<[f64; 3], MeshError> {
    let err =
        |line: usize, msg: String| MeshError::new(path, Some(line), MeshErrorKind::Syntax(msg));
    let mut p = [0.0; 3];
    for c in p.iter_mut() {
        let w = words
            .next()
            .ok_or_else(|| err(lineno, "`v` needs three coordinates".into()))?;
        *c = parse_f64(w).ok_or_else(|| err(lineno, format!("`{w}` is not a number")))?;
        if !c.is_finite() {
            return Err(MeshError::new(path, Some(lineno), MeshErrorKind::NotFinite));
        }
    }
    Ok(p)
}

/// The vertex indices of an `f` line into `face` (0-based; negative ones count back from the
/// `vertices` read so far; texture and normal indices ignored).
fn face_indices<'a>(
    words: impl Iterator<Item = &'a str>,
    vertices: usize,
    face: &mut Vec<u32>,
    lineno: usize,
    path: &Path,
) -> Result<(), MeshError> {
    face.clear();
    for w in words {
        let idx = w.split('/').next().unwrap_or("");
        let i: i64 = idx.parse().map_err(|_| {
            MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::Syntax(format!("`{w}` is not a vertex index")),
            )
        })?;
        let n = vertices as i64;
        let resolved = if i > 0 {
            i - 1
        } else if i < 0 {
            n + i
        } else {
            -1
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
