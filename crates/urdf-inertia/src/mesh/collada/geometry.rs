//! `<mesh>` geometry: sources, the VERTEX input, and `<triangles>`, `<polylist>`, `<polygons>`.

use super::syntax_at;
use super::tree::{each_number, not_a_number, numbers, El, Numbers};
use crate::mass::Polygons;
use crate::mesh::{MeshError, MeshErrorKind};
use std::collections::HashMap;
use std::path::Path;

/// A position source: its `<float_array>`, the accessor's stride and offset, and the accessor's line.
type Source<'a> = (&'a El, usize, usize, usize);

/// Geometry of one `<mesh>`: positions and polygons.
pub(super) fn read_geometry(
    geom: &El,
    bytes: &[u8],
    path: &Path,
    notes: &mut Vec<String>,
) -> Result<(Vec<[f64; 3]>, Polygons), MeshError> {
    let Some(mesh) = geom.child("mesh") else {
        notes.push(format!(
            "geometry `{}` is not a <mesh> (skipped)",
            geom.attr("id").unwrap_or("?")
        ));
        return Ok((Vec::new(), Polygons::new()));
    };
    let sources = sources(mesh);
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut faces = Polygons::new();
    let mut cache: HashMap<String, (u32, usize)> = HashMap::new();
    for prim in &mesh.children {
        let kind = prim.name.as_str();
        match kind {
            "triangles" | "polylist" | "polygons" => {}
            "tristrips" | "trifans" => {
                return Err(syntax_at(
                    path,
                    prim.line,
                    format!("<{kind}> is not supported; re-export the mesh with triangles"),
                ));
            }
            // lines, linestrips, source, vertices, extra, and elements unknown: no faces.
            _ => continue,
        }
        let (vin, stride, voff) = vertex_input(prim, kind, path)?;
        let src = vin.attr("source").unwrap_or("");
        // Each distinct source is appended once; its indices may only reach its own vertices.
        let (base, count) = if let Some(&bc) = cache.get(src) { bc } else {
            let pos = positions_of(mesh, &sources, src, vin.line, bytes, path)?;
            let bc = (vertices.len() as u32, pos.len());
            vertices.extend(pos);
            cache.insert(src.to_string(), bc);
            bc
        };
        let input = VertexInput {
            stride,
            voff,
            base,
            count,
        };
        match kind {
            "triangles" => read_triangles(prim, &input, bytes, path, &mut faces)?,
            "polylist" => read_polylist(prim, &input, bytes, path, &mut faces)?,
            _ => read_polygons(prim, &input, bytes, path, &mut faces, notes)?,
        }
    }
    Ok((vertices, faces))
}

/// Sources by id, read only when a VERTEX input asks for their positions (normals and texture
/// coordinates are never parsed).
fn sources(mesh: &El) -> HashMap<&str, Source<'_>> {
    let mut sources: HashMap<&str, Source<'_>> = HashMap::new();
    for src in mesh.children_named("source") {
        let Some(id) = src.attr("id") else { continue };
        let Some(arr) = src.child("float_array") else {
            continue;
        };
        let (stride, offset, line) = src
            .child("technique_common")
            .and_then(|t| t.child("accessor"))
            .map_or((3, 0, src.line), |a| {
                (
                    a.attr("stride")
                        .and_then(|s| s.parse().ok())
                        .unwrap_or(1usize),
                    a.attr("offset")
                        .and_then(|s| s.parse().ok())
                        .unwrap_or(0usize),
                    a.line,
                )
            });
        sources.insert(id, (arr, stride.max(1), offset, line));
    }
    sources
}

/// The points of the position source `source_ref` names (through a `<vertices>` element if it names
/// one), read straight from the text.
fn positions_of(
    mesh: &El,
    sources: &HashMap<&str, Source<'_>>,
    source_ref: &str,
    line: usize,
    bytes: &[u8],
    path: &Path,
) -> Result<Vec<[f64; 3]>, MeshError> {
    let id = source_ref.trim_start_matches('#');
    // A <vertices> element forwards to its POSITION input.
    let id = if let Some(v) = mesh
        .children_named("vertices")
        .find(|v| v.attr("id") == Some(id))
    {
        v.children_named("input")
            .find(|i| i.attr("semantic") == Some("POSITION"))
            .and_then(|i| i.attr("source"))
            .map(|s| s.trim_start_matches('#'))
            .ok_or_else(|| syntax_at(path, v.line, "<vertices> without a POSITION input".into()))?
    } else {
        id
    };
    let &(arr, stride, offset, accessor_line) = sources
        .get(id)
        .ok_or_else(|| syntax_at(path, line, format!("no <source id=\"{id}\">")))?;
    if stride < 3 {
        return Err(syntax_at(
            path,
            line,
            format!("position source `{id}` has stride {stride}"),
        ));
    }
    if offset.checked_add(3).is_none_or(|end| end > stride) {
        return Err(syntax_at(path,
            accessor_line,
            format!("<accessor> of `{id}`: offset {offset} leaves no room for x, y, z in its stride {stride}"),
        ));
    }
    // Straight from the text into points: one stride of numbers at a time.
    // As many points as the array's `count` says, if its text can hold that many numbers.
    let text = arr.raw_text(bytes);
    let count = arr.attr("count").and_then(|c| c.parse::<usize>().ok());
    let mut out = Vec::with_capacity(count.unwrap_or(0).min(text.len().div_ceil(2)) / stride);
    let mut record = vec![0.0; stride];
    let mut filled = 0;
    for x in each_number(arr, text, path) {
        record[filled] = x?;
        filled += 1;
        if filled == stride {
            out.push([record[offset], record[offset + 1], record[offset + 2]]);
            filled = 0;
        }
    }
    Ok(out)
}

/// A primitive's VERTEX input, the number of interleaved inputs per corner, and the VERTEX one's offset.
fn vertex_input<'a>(
    prim: &'a El,
    kind: &str,
    path: &Path,
) -> Result<(&'a El, usize, usize), MeshError> {
    let inputs: Vec<&El> = prim.children_named("input").collect();
    let stride = inputs
        .iter()
        .filter_map(|i| i.attr("offset").and_then(|o| o.parse::<usize>().ok()))
        .max()
        .unwrap_or(0)
        .checked_add(1)
        .ok_or_else(|| {
            syntax_at(
                path,
                prim.line,
                format!("<{kind}> has an <input> offset too large"),
            )
        })?;
    let vin = inputs
        .iter()
        .find(|i| i.attr("semantic") == Some("VERTEX"))
        .ok_or_else(|| syntax_at(path, prim.line, format!("<{kind}> has no VERTEX input")))?;
    let voff: usize = vin.attr("offset").and_then(|o| o.parse().ok()).unwrap_or(0);
    Ok((vin, stride, voff))
}

/// Where a primitive's VERTEX indices are among its interleaved inputs, and where the vertices they
/// reach are in the geometry's list.
struct VertexInput {
    stride: usize,
    voff: usize,
    base: u32,
    count: usize,
}

impl VertexInput {
    /// The geometry vertex of a raw VERTEX index, which must be a whole number below the source's count.
    fn index(&self, raw: f64, line: usize, path: &Path) -> Result<u32, MeshError> {
        // `raw as u64` truncates exactly in range (no `fract`, a libm call on baseline x86-64).
        if !(raw >= 0.0 && raw < self.count as f64 && (raw as u64) as f64 == raw) {
            return Err(MeshError::new(
                path,
                Some(line),
                MeshErrorKind::IndexOutOfRange {
                    index: raw as i64,
                    vertices: self.count,
                },
            ));
        }
        Ok(self.base + raw as u32)
    }
}

/// `<triangles>`: one triangle's numbers at a time from its `<p>`.
fn read_triangles(
    prim: &El,
    input: &VertexInput,
    bytes: &[u8],
    path: &Path,
    faces: &mut Polygons,
) -> Result<(), MeshError> {
    let Some(p) = prim.child("p") else {
        return Ok(());
    };
    // Room for as many triangles as `count` says, if `<p>` can hold that many numbers.
    let text = p.raw_text(bytes);
    let count = prim.attr("count").and_then(|c| c.parse::<usize>().ok());
    let room = text.len().div_ceil(2) / (3 * input.stride);
    faces.indices.reserve(3 * count.unwrap_or(0).min(room));
    faces.starts.reserve(count.unwrap_or(0).min(room));
    // Where in the triangle a number falls: its corner, and its input within the corner (counted,
    // not divided out). Only each corner's VERTEX index is kept; a trailing incomplete triangle is
    // ignored.
    let mut corner = [0.0; 3];
    let (mut at, mut slot) = (0usize, 0usize);
    let mut words = Numbers { rest: text };
    loop {
        // Only the VERTEX index is converted (figures: docs/benchmarks.md, "Figures behind choices
        // in the code").
        if slot == input.voff {
            match words.next() {
                Some(x) => corner[at] = x.map_err(|w| not_a_number(p, w, path))?,
                None => break,
            }
        } else {
            match words.pass_word() {
                Some(x) => x.map_err(|w| not_a_number(p, w, path))?,
                None => break,
            }
        }
        slot += 1;
        if slot < input.stride {
            continue;
        }
        slot = 0;
        at += 1;
        if at == 3 {
            at = 0;
            let mut face = [0; 3];
            for (f, c) in face.iter_mut().zip(corner) {
                *f = input.index(c, p.line, path)?;
            }
            faces.push(&face);
        }
    }
    Ok(())
}

/// `<polylist>`: polygons of `<vcount>` corners each from one `<p>`.
fn read_polylist(
    prim: &El,
    input: &VertexInput,
    bytes: &[u8],
    path: &Path,
    faces: &mut Polygons,
) -> Result<(), MeshError> {
    let mut face: Vec<u32> = Vec::new();
    let Some(p) = prim.child("p") else {
        return Ok(());
    };
    let vcount = prim
        .child("vcount")
        .map(|v| numbers(v, bytes, path))
        .transpose()?
        .unwrap_or_default();
    let more = || {
        syntax_at(
            path,
            p.line,
            "<polylist> <vcount> asks for more indices than <p> holds".into(),
        )
    };
    let text = p.raw_text(bytes);
    // The bound is the length of the decoded text, which is the bytes' unless one is not UTF-8.
    let within = |n: f64| n <= text.len() as f64 || n <= p.text(bytes).len() as f64;
    let mut words = Numbers { rest: text };
    for n in vcount {
        if !(n >= 0.0 && n.fract() == 0.0 && within(n)) {
            return Err(more());
        }
        face.clear();
        for _ in 0..n as usize {
            let mut vertex = None;
            for k in 0..input.stride {
                // Only the VERTEX index is converted (see `read_triangles`).
                if k == input.voff {
                    let x = words.next().ok_or_else(more)?;
                    vertex = Some(x.map_err(|w| not_a_number(p, w, path))?);
                } else {
                    let x = words.pass_word().ok_or_else(more)?;
                    x.map_err(|w| not_a_number(p, w, path))?;
                }
            }
            face.push(input.index(vertex.unwrap_or(-1.0), p.line, path)?);
        }
        if face.len() >= 3 {
            faces.push(&face);
        }
    }
    Ok(())
}

/// `<polygons>`: one `<p>` per polygon.
fn read_polygons(
    prim: &El,
    input: &VertexInput,
    bytes: &[u8],
    path: &Path,
    faces: &mut Polygons,
    notes: &mut Vec<String>,
) -> Result<(), MeshError> {
    let mut face: Vec<u32> = Vec::new();
    // <polygons>: one <p> per polygon; <ph> (polygons with holes) are not supported.
    if prim.child("ph").is_some() {
        notes.push("warning: <polygons> with holes (<ph>) skipped".into());
    }
    for p in prim.children_named("p") {
        let idx = numbers(p, bytes, path)?;
        face.clear();
        for chunk in idx.chunks_exact(input.stride) {
            face.push(input.index(chunk[input.voff], p.line, path)?);
        }
        if face.len() >= 3 {
            faces.push(&face);
        }
    }
    Ok(())
}
