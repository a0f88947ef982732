//! COLLADA (.dae), read with quick-xml.
//!
//! Convention (what ROS tools and pinocchio do with robot meshes):
//! * every `<instance_geometry>` reachable from the scene's `<instance_visual_scene>` counts, each moved
//!   by the product of its ancestors' node transforms (`<matrix>`, `<translate>`, `<rotate>`, `<scale>`,
//!   in document order; `<instance_node>` follows `<library_nodes>`); without a scene, every geometry
//!   counts once, untransformed;
//! * `<unit meter="s">` scales all coordinates by `s` (as RViz and Gazebo do);
//! * `<up_axis>` is **not** applied: coordinates are taken as authored in the URDF link frame, which is
//!   what RViz, Gazebo and pinocchio (coal's assimp loader) show for `Y_UP` files; the mesh validation
//!   on example-robot-data compares this against coal.
//! * `<triangles>`, `<polylist>` and `<polygons>` are read (polygons stay polygons; holes in `<ph>` are
//!   not supported and reported); `<lines>` and `<linestrips>` carry no surface and are skipped.

use super::affine::{self, compose, Affine, IDENTITY};
use super::{
    beyond_expansion_budget, parse_f64_bytes, short_decimal, MeshError, MeshErrorKind, RawMesh,
    MAX_INSTANCED_CORNERS, MAX_INSTANCED_VERTICES, MAX_NODE_VISITS,
};
use crate::mass::{Mat3, Polygons};
use crate::text::line_of;
use quick_xml::events::Event;
use quick_xml::reader::Reader;
use std::collections::HashMap;
use std::path::Path;

/// A minimal element tree: enough of COLLADA for geometry and scene graphs.
///
/// The tree holds no copy of the text: an element's text is a span of the file's bytes, parsed where
/// it is used (a `<float_array>` or `<p>` is most of a file's size).
#[derive(Debug, Default)]
struct El {
    name: String,
    attrs: Vec<(String, String)>,
    children: Vec<El>,
    text: Text,
    line: usize,
}

/// An element's character data, whitespace-only pieces left out.
#[derive(Debug, Default)]
enum Text {
    #[default]
    None,
    /// One piece: a byte range of the file.
    Span(usize, usize),
    /// Several pieces (text around a comment or child), joined as XML joins them.
    Joined(String),
}

impl El {
    /// The element's text (borrowed from the file unless it came in several pieces).
    fn text<'a>(&'a self, bytes: &'a [u8]) -> std::borrow::Cow<'a, str> {
        match &self.text {
            Text::None => "".into(),
            Text::Span(a, b) => String::from_utf8_lossy(bytes.get(*a..*b).unwrap_or_default()),
            Text::Joined(s) => s.as_str().into(),
        }
    }
    /// The element's text as bytes, as stored: numbers are ASCII, so they need no UTF-8 decoding
    /// (`from_utf8_lossy` took 5 instructions a byte of go1's trunk.dae, 133 M of its 1,167 M).
    fn raw_text<'a>(&'a self, bytes: &'a [u8]) -> &'a [u8] {
        match &self.text {
            Text::None => b"",
            Text::Span(a, b) => bytes.get(*a..*b).unwrap_or_default(),
            Text::Joined(s) => s.as_bytes(),
        }
    }
    fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
    fn child(&self, name: &str) -> Option<&El> {
        self.children.iter().find(|c| c.name == name)
    }
    fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a El> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
    /// Every element of the tree, in document order (iterative: deep files must not overflow the stack).
    fn walk<'a>(&'a self, out: &mut Vec<&'a El>) {
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            out.push(e);
            stack.extend(e.children.iter().rev());
        }
    }
}

/// Deepest element nesting accepted. The tree is dropped recursively (and real files nest a few dozen
/// levels), so a bound keeps a hostile file from overflowing a worker thread's stack.
const MAX_DEPTH: usize = 512;

fn local(name: &[u8]) -> String {
    let s = String::from_utf8_lossy(name);
    match s.rfind(':') {
        Some(i) => s[i + 1..].to_string(),
        None => s.into_owned(),
    }
}

fn element(e: &quick_xml::events::BytesStart<'_>, line: usize) -> El {
    let mut el = El {
        name: local(e.name().as_ref()),
        line,
        ..Default::default()
    };
    // Without the duplicate check, which compares each attribute with all before it (quadratic).
    for a in e.attributes().with_checks(false).flatten() {
        let v = a
            .unescape_value()
            .map(|v| v.into_owned())
            .unwrap_or_default();
        el.attrs.push((local(a.key.as_ref()), v));
    }
    el
}

/// Reads the document into a tree of elements, with each element's text kept as a span of the file
/// where it can be.
fn parse_tree(bytes: &[u8], path: &Path) -> Result<El, MeshError> {
    let mut reader = Reader::from_reader(bytes);
    reader.config_mut().trim_text(false);
    let mut stack: Vec<El> = vec![El {
        name: "#document".into(),
        ..Default::default()
    }];
    let mut lines = crate::text::LineCounter::new(bytes);
    let syntax = |pos: usize, msg: String| {
        MeshError::new(path, Some(line_of(bytes, pos)), MeshErrorKind::Syntax(msg))
    };
    loop {
        let pos = reader.buffer_position() as usize;
        let event = reader.read_event().map_err(|e| {
            syntax(
                reader.error_position() as usize,
                format!("malformed XML: {e}"),
            )
        })?;
        match event {
            Event::Start(e) => {
                if stack.len() > MAX_DEPTH {
                    return Err(syntax(
                        pos,
                        format!("elements nested deeper than {MAX_DEPTH} levels"),
                    ));
                }
                stack.push(element(&e, lines.at(pos)));
            }
            Event::Empty(e) => {
                let el = element(&e, lines.at(pos));
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(el);
                }
            }
            Event::End(_) => {
                if stack.len() < 2 {
                    return Err(syntax(pos, "unexpected closing tag".into()));
                }
                let done = stack.pop().unwrap_or_default();
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(done);
                }
            }
            Event::Text(t) => {
                if let Some(top) = stack.last_mut() {
                    add_text(top, t.as_ref(), pos, bytes);
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if stack.len() != 1 {
        return Err(MeshError::new(
            path,
            Some(line_of(bytes, bytes.len())),
            MeshErrorKind::Syntax("the XML ends before its elements are closed".into()),
        ));
    }
    Ok(stack.pop().unwrap_or_default())
}

/// Adds a piece of text to `top`: a span of `bytes` while it is one piece borrowed from the file at `pos`,
/// joined text otherwise. Whitespace only matters between two pieces.
fn add_text(top: &mut El, piece: &[u8], pos: usize, bytes: &[u8]) {
    if piece.iter().all(u8::is_ascii_whitespace) {
        // Nothing to keep, unless it separates two pieces.
        if !matches!(top.text, Text::None) {
            top.text = Text::Joined(format!("{} ", top.text(bytes)));
        }
        return;
    }
    // The event borrows the file's bytes from `pos` on; the span is checked anyway.
    let span = (pos, pos + piece.len());
    let borrowed = bytes.get(span.0..span.1) == Some(piece);
    top.text = match std::mem::take(&mut top.text) {
        Text::None if borrowed => Text::Span(span.0, span.1),
        Text::None => Text::Joined(String::from_utf8_lossy(piece).into_owned()),
        Text::Span(a, b) => {
            let mut s = String::from_utf8_lossy(&bytes[a..b]).into_owned();
            s.push_str(&String::from_utf8_lossy(piece));
            Text::Joined(s)
        }
        Text::Joined(mut s) => {
            s.push_str(&String::from_utf8_lossy(piece));
            Text::Joined(s)
        }
    };
}

/// The numbers of an element's text, one at a time (a `<p>` of millions of indices is never a list).
///
/// Words are runs of bytes between ASCII whitespace (what `split_ascii_whitespace` gave on the decoded
/// text: an invalid byte is never whitespace, and its word is no number either way); a short decimal
/// is scanned where it stands, anything else is cut out and parsed by `str::parse`. go1's trunk.dae
/// (28 MB, 2.6 M numbers): reading its geometry took 941 M instructions with `from_utf8_lossy`,
/// `split_ascii_whitespace` and `str::parse`, 533 M so.
fn each_number<'a>(
    el: &'a El,
    text: &'a [u8],
    path: &'a Path,
) -> impl Iterator<Item = Result<f64, MeshError>> + 'a {
    Numbers { rest: text }.map(move |n| n.map_err(|w| not_a_number(el, w, path)))
}

fn not_a_number(el: &El, word: &[u8], path: &Path) -> MeshError {
    MeshError::new(
        path,
        Some(el.line),
        MeshErrorKind::Syntax(format!(
            "`{}` is not a number in <{}>",
            String::from_utf8_lossy(word),
            el.name
        )),
    )
}

/// The words of a text as numbers, `Err` a word that is none (see [`each_number`]).
struct Numbers<'a> {
    rest: &'a [u8],
}

impl<'a> Numbers<'a> {
    /// The text from the next word on (leading whitespace skipped).
    #[inline]
    fn word_start(&self) -> &'a [u8] {
        let mut r = self.rest;
        while let [b, tail @ ..] = r {
            if !b.is_ascii_whitespace() {
                break;
            }
            r = tail;
        }
        r
    }

    /// Takes the first `n` bytes of `r` (from [`Self::word_start`]) as a word if the word ends there:
    /// at the end of the text, or at whitespace, which is passed over with it.
    #[inline]
    fn take_word(&mut self, r: &'a [u8], n: usize) -> bool {
        match r.get(n) {
            None => self.rest = &[],
            Some(b) if b.is_ascii_whitespace() => self.rest = &r[n + 1..],
            Some(_) => return false,
        }
        true
    }

    /// Passes over the next word as [`Iterator::next`] would, without converting it when it is plain
    /// digits (a number, whatever its value); any other word is parsed, so a word that is no number
    /// is the same error. The index lists of `<p>` hold a normal and a texture coordinate index for
    /// every vertex index, and only the vertex's is used.
    #[inline]
    fn pass_word(&mut self) -> Option<Result<(), &'a [u8]>> {
        let r = self.word_start();
        let digits = r.iter().take_while(|b| b.is_ascii_digit()).count();
        if digits > 0 && self.take_word(r, digits) {
            return Some(Ok(()));
        }
        self.rest = r;
        self.next().map(|n| n.map(|_| ()))
    }
}

impl<'a> Iterator for Numbers<'a> {
    type Item = Result<f64, &'a [u8]>;

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let r = self.word_start();
        if r.is_empty() {
            self.rest = r;
            return None;
        }
        if let Some((x, n)) = short_decimal(r) {
            if self.take_word(r, n) {
                return Some(Ok(x));
            }
        }
        let len = r
            .iter()
            .position(u8::is_ascii_whitespace)
            .unwrap_or(r.len());
        let (w, after) = r.split_at(len);
        self.rest = after;
        Some(parse_f64_bytes(w).ok_or(w))
    }
}

fn numbers(el: &El, bytes: &[u8], path: &Path) -> Result<Vec<f64>, MeshError> {
    each_number(el, el.raw_text(bytes), path).collect()
}

fn node_transform(node: &El, bytes: &[u8], path: &Path) -> Result<Affine, MeshError> {
    let mut acc = IDENTITY;
    for c in &node.children {
        let step: Affine = match c.name.as_str() {
            "matrix" => {
                let m = numbers(c, bytes, path)?;
                if m.len() != 16 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax(format!("<matrix> has {} numbers, not 16", m.len())),
                    ));
                }
                (
                    [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]],
                    [m[3], m[7], m[11]],
                )
            }
            "translate" => {
                let t = numbers(c, bytes, path)?;
                if t.len() != 3 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax("<translate> needs 3 numbers".into()),
                    ));
                }
                (IDENTITY.0, [t[0], t[1], t[2]])
            }
            "scale" => {
                let s = numbers(c, bytes, path)?;
                if s.len() != 3 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax("<scale> needs 3 numbers".into()),
                    ));
                }
                (
                    [[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]],
                    [0.0; 3],
                )
            }
            "rotate" => {
                let r = numbers(c, bytes, path)?;
                if r.len() != 4 {
                    return Err(MeshError::new(
                        path,
                        Some(c.line),
                        MeshErrorKind::Syntax("<rotate> needs 4 numbers".into()),
                    ));
                }
                (axis_angle([r[0], r[1], r[2]], r[3].to_radians()), [0.0; 3])
            }
            _ => continue,
        };
        acc = compose(&acc, &step);
    }
    Ok(acc)
}

fn axis_angle(axis: [f64; 3], angle: f64) -> Mat3 {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if n == 0.0 {
        return IDENTITY.0;
    }
    let [x, y, z] = axis.map(|a| a / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

/// A syntax error at `line`.
fn syntax_at(path: &Path, line: usize, msg: String) -> MeshError {
    MeshError::new(path, Some(line), MeshErrorKind::Syntax(msg))
}

/// A position source: its `<float_array>`, the accessor's stride and offset, and the accessor's line.
type Source<'a> = (&'a El, usize, usize, usize);

/// Geometry of one `<mesh>`: positions and polygons.
fn read_geometry(
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
            "lines" | "linestrips" | "source" | "vertices" | "extra" => continue,
            "tristrips" | "trifans" => {
                return Err(syntax_at(
                    path,
                    prim.line,
                    format!("<{kind}> is not supported; re-export the mesh with triangles"),
                ));
            }
            _ => continue,
        }
        let (vin, stride, voff) = vertex_input(prim, kind, path)?;
        let src = vin.attr("source").unwrap_or("");
        // Each distinct source is appended once; its indices may only reach its own vertices.
        let (base, count) = match cache.get(src) {
            Some(&bc) => bc,
            None => {
                let pos = positions_of(mesh, &sources, src, vin.line, bytes, path)?;
                let bc = (vertices.len() as u32, pos.len());
                vertices.extend(pos);
                cache.insert(src.to_string(), bc);
                bc
            }
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
        // Only the VERTEX index is converted (go1 trunk.dae, `mesh`: 1,784 → 1,691 M instructions).
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

/// Parses a COLLADA document into one mesh in the file's frame (see the module docs for the convention).
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let doc = parse_tree(bytes, path)?;
    let root = doc
        .children
        .iter()
        .find(|c| c.name == "COLLADA")
        .ok_or_else(|| {
            MeshError::new(
                path,
                Some(1),
                MeshErrorKind::Syntax("no <COLLADA> root element".into()),
            )
        })?;
    let unit_el = root.child("asset").and_then(|a| a.child("unit"));
    let unit = unit_of(unit_el, path)?;

    let mut all: Vec<&El> = Vec::new();
    root.walk(&mut all);
    let by_id: HashMap<&str, &El> = all
        .iter()
        .filter_map(|e| e.attr("id").map(|id| (id, *e)))
        .collect();

    let mut inst = Instancer {
        bytes,
        path,
        unit,
        geom_cache: HashMap::new(),
        corners: 0,
        unit_loss: None,
        out: RawMesh {
            faces: Polygons::new(),
            ..Default::default()
        },
        notes: Vec::new(),
    };
    let scene = root
        .child("scene")
        .and_then(|s| s.child("instance_visual_scene"))
        .and_then(|i| i.attr("url"))
        .and_then(|u| by_id.get(u.trim_start_matches('#')).copied())
        .or_else(|| {
            root.child("library_visual_scenes")
                .and_then(|l| l.child("visual_scene"))
        });
    match scene {
        Some(scene) => add_scene(scene, &by_id, &mut inst)?,
        None => {
            if let Some(lib) = root.child("library_geometries") {
                for g in lib.children_named("geometry") {
                    inst.add(g, &IDENTITY)?;
                }
            }
            inst.notes
                .push("no visual scene: every geometry counted once, untransformed".into());
        }
    }
    let Instancer {
        mut out,
        notes,
        unit_loss: inst_unit_loss,
        ..
    } = inst;
    let inst_unit_loss = inst_unit_loss.or_else(|| unit_extent_loss(&out.vertices, unit));
    if let (Some(what), Some(u)) = (inst_unit_loss, unit_el) {
        return Err(MeshError::new(
            path,
            Some(u.line),
            MeshErrorKind::Syntax(format!(
                "with <unit meter=\"{}\">, the mesh's coordinates, volume or inertia {what} a 64-bit float; fix the unit or the mesh's coordinates",
                crate::text::escape_control(u.attr("meter").unwrap_or_default())
            )),
        ));
    }
    // Reader messages that say something was left out are warnings; the rest are notes.
    for n in notes {
        match n.strip_prefix("warning: ") {
            Some(w) => out.warnings.push(w.to_string()),
            None => out.notes.push(n),
        }
    }
    Ok(out)
}

/// Metres per unit: `<unit meter="s">`'s value, 1 without the element or the attribute. Anything but
/// a positive finite decimal (`0,001`, `1 mm`, `0`, `-1`, `inf`) is an error: read as 1 m, a millimetre
/// file would weigh 10⁹ times too much without a word.
fn unit_of(unit: Option<&El>, path: &Path) -> Result<f64, MeshError> {
    let Some((el, text)) = unit.and_then(|u| u.attr("meter").map(|m| (u, m))) else {
        return Ok(1.0);
    };
    match text.trim().parse::<f64>() {
        Ok(m) if m.is_finite() && m > 0.0 => Ok(m),
        _ => Err(MeshError::new(
            path,
            Some(el.line),
            MeshErrorKind::Syntax(format!(
                "<unit meter=\"{}\"> is not a positive number of metres (write a decimal with a point, e.g. meter=\"0.001\" for millimetres)",
                crate::text::escape_control(text)
            )),
        )),
    }
}

/// What multiplying an authored coordinate by the unit did to it, when it lost it: `<unit
/// meter="1e308">` overflows, `meter="1e-310"` underflows, and either would otherwise be reported as
/// a flat mesh of NaN or zero volume.
fn unit_range_loss(authored: f64, scaled: f64) -> Option<&'static str> {
    if authored.is_finite() && !scaled.is_finite() {
        Some("overflows")
    } else if authored.is_normal() && !scaled.is_normal() {
        Some("underflows")
    } else {
        None
    }
}

/// Whether the unit made the mesh's size overflow or underflow what its inertia (the fifth power of
/// the size) can hold, when the authored size could: `<unit meter="1e308">` on a 1-unit box.
fn unit_extent_loss(vertices: &[[f64; 3]], unit: f64) -> Option<&'static str> {
    if unit == 1.0 || vertices.is_empty() {
        return None;
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let authored = size / unit;
    unit_range_loss(authored.powi(5), size.powi(5))
}

/// Places geometries into one mesh, each read once however often the scene instances it, within the
/// instancing budget.
struct Instancer<'a> {
    bytes: &'a [u8],
    path: &'a Path,
    /// Metres per unit of the file.
    unit: f64,
    /// Keyed by element, not by id: id-less geometries are each their own.
    geom_cache: HashMap<*const El, (Vec<[f64; 3]>, Polygons)>,
    /// Polygon corners instanced so far.
    corners: usize,
    /// Set when the unit made a coordinate overflow or underflow (see [`unit_range_loss`]).
    unit_loss: Option<&'static str>,
    out: RawMesh,
    /// Reader messages; those starting `warning: ` become warnings.
    notes: Vec<String>,
}

impl Instancer<'_> {
    /// Adds one instance of `geom` transformed by `xf` (faces reversed if `xf` mirrors).
    fn add(&mut self, geom: &El, xf: &Affine) -> Result<(), MeshError> {
        let key: *const El = geom;
        let (v, f) = match self.geom_cache.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => &*e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                &*e.insert(read_geometry(geom, self.bytes, self.path, &mut self.notes)?)
            }
        };
        self.corners = self.corners.saturating_add(f.indices.len());
        if beyond_expansion_budget(
            self.out.vertices.len().saturating_add(v.len()),
            self.corners,
        ) {
            return Err(MeshError::new(
                self.path,
                Some(geom.line),
                MeshErrorKind::Syntax(format!(
                    "the scene instances more than {MAX_INSTANCED_VERTICES} vertices or {MAX_INSTANCED_CORNERS} polygon corners (nested <instance_node> multiply their geometry); simplify the collision mesh"
                )),
            ));
        }
        let base = self.out.vertices.len() as u32;
        self.out.vertices.reserve(v.len());
        let a = &xf.0;
        let check_unit = self.unit != 1.0;
        for p in v {
            // `mass::mat_vec`'s sums in its order, written out: its `[0, 1, 2].map` is a call here
            // (`core::array::try_map` in profiles), 7 of the 37 M instructions placing go1's trunk.dae.
            let q = [
                a[0][0] * p[0] + a[0][1] * p[1] + a[0][2] * p[2],
                a[1][0] * p[0] + a[1][1] * p[1] + a[1][2] * p[2],
                a[2][0] * p[0] + a[2][1] * p[1] + a[2][2] * p[2],
            ];
            let authored = [q[0] + xf.1[0], q[1] + xf.1[1], q[2] + xf.1[2]];
            let placed = [
                authored[0] * self.unit,
                authored[1] * self.unit,
                authored[2] * self.unit,
            ];
            if check_unit {
                for i in 0..3 {
                    self.unit_loss = self
                        .unit_loss
                        .or_else(|| unit_range_loss(authored[i], placed[i]));
                }
            }
            self.out.vertices.push(placed);
        }
        // A mirroring node transform reverses the faces' orientation.
        let mirrored = affine::mirrors(xf);
        // Appended in bulk, not a face at a time (a `Vec` per face was 130 of the 1,167 M instructions
        // go1's trunk.dae took to read).
        let out = &mut self.out.faces;
        if out.starts.is_empty() {
            out.starts.push(0);
        }
        out.indices.reserve(f.indices.len());
        out.starts.reserve(f.len());
        for face in f.iter() {
            if mirrored {
                out.indices.extend(face.iter().rev().map(|i| i + base));
            } else {
                out.indices.extend(face.iter().map(|i| i + base));
            }
            out.starts.push(out.indices.len() as u32);
        }
        Ok(())
    }
}

/// Every geometry a visual scene's node hierarchy instances, with its node transforms (depth and node
/// visits bounded: a cycle of `<instance_node>` is an error, not a hang).
fn add_scene<'a>(
    scene: &'a El,
    by_id: &HashMap<&str, &'a El>,
    inst: &mut Instancer<'_>,
) -> Result<(), MeshError> {
    let mut stack: Vec<(&El, Affine, usize)> = scene
        .children_named("node")
        .map(|n| (n, IDENTITY, 0))
        .collect();
    let mut visits = 0usize;
    while let Some((node, parent, depth)) = stack.pop() {
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(MeshError::new(
                inst.path,
                Some(node.line),
                MeshErrorKind::Syntax(format!(
                    "the scene instances more than {MAX_NODE_VISITS} nodes (nested <instance_node> multiply); simplify the collision mesh"
                )),
            ));
        }
        if depth > 64 {
            return Err(MeshError::new(
                inst.path,
                Some(node.line),
                MeshErrorKind::Syntax(
                    "node hierarchy deeper than 64 (a cycle of <instance_node>?)".into(),
                ),
            ));
        }
        let xf = compose(&parent, &node_transform(node, inst.bytes, inst.path)?);
        for c in &node.children {
            match c.name.as_str() {
                "instance_geometry" => {
                    let url = c.attr("url").unwrap_or("").trim_start_matches('#');
                    let geom = by_id.get(url).ok_or_else(|| {
                        MeshError::new(
                            inst.path,
                            Some(c.line),
                            MeshErrorKind::Syntax(format!(
                                "<instance_geometry url=\"#{url}\"> names no geometry"
                            )),
                        )
                    })?;
                    inst.add(geom, &xf)?;
                }
                "node" => stack.push((c, xf, depth + 1)),
                "instance_node" => {
                    let url = c.attr("url").unwrap_or("").trim_start_matches('#');
                    if let Some(n) = by_id.get(url) {
                        stack.push((n, xf, depth + 1));
                    }
                }
                _ => {}
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit tetrahedron whose `<p>` text is `p` and whose document has `extra` sources.
    fn tetra(p: &str, extra: &str) -> String {
        format!(
            "<COLLADA><library_geometries><geometry id=\"g\"><mesh>\n<source id=\"pos\"><float_array id=\"a\">0 0 0 1 0 0 0 1 0 0 0 1</float_array><technique_common><accessor source=\"#a\" stride=\"3\"/></technique_common></source>{extra}\n<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#pos\" offset=\"0\"/><p>{p}</p></triangles>\n</mesh></geometry></library_geometries></COLLADA>"
        )
    }

    const FACES: &str = "0 2 1 0 1 3 0 3 2 1 2 3";

    #[test]
    fn text_is_read_in_place_and_joined_across_comments() {
        let m = parse(tetra(FACES, "").as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.faces.indices, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
        // XML joins the text around a comment: "1<!-- -->3" is 13 (out of range), "1 <!-- -->3" two.
        let joined = tetra("0 2 1 0 1<!-- c -->3 0 3 2 1 2 3", "");
        let e = parse(joined.as_bytes(), Path::new("t.dae")).unwrap_err();
        assert!(
            matches!(e.kind, MeshErrorKind::IndexOutOfRange { index: 13, .. }),
            "{e}"
        );
        let spaced = tetra("0 2 1 0 1<!-- c --> <!-- d -->3 0 3 2 1 2 3", "");
        let m = parse(spaced.as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.faces.indices, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
    }

    /// Sources no VERTEX input names (normals, texture coordinates) are never parsed.
    #[test]
    fn unused_sources_are_not_parsed() {
        let normals = "<source id=\"n\"><float_array id=\"na\">not numbers</float_array></source>";
        let m = parse(tetra(FACES, normals).as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.faces.len(), 4);
    }

    /// A trailing incomplete triangle is ignored; a bad number anywhere in `<p>` is an error.
    #[test]
    fn triangles_stream_their_indices() {
        let m = parse(
            tetra(&format!("{FACES} 0 1"), "").as_bytes(),
            Path::new("t.dae"),
        )
        .unwrap();
        assert_eq!(m.faces.len(), 4);
        let e = parse(
            tetra(&format!("{FACES} x"), "").as_bytes(),
            Path::new("t.dae"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("`x` is not a number in <p>"), "{e}");
    }

    /// The indices of other inputs (here a normal's) are passed over unconverted, but still have to be
    /// numbers: any spelling of one is taken, anything else is the same error as in a vertex slot.
    #[test]
    fn other_inputs_indices_are_passed_over_but_checked() {
        let with_normals = |normal: &str| {
            let p: Vec<String> = FACES.split(' ').map(|v| format!("{v} {normal}")).collect();
            format!(
                "<COLLADA><library_geometries><geometry id=\"g\"><mesh>\n<source id=\"pos\"><float_array id=\"a\">0 0 0 1 0 0 0 1 0 0 0 1</float_array><technique_common><accessor source=\"#a\" stride=\"3\"/></technique_common></source>\n<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#pos\" offset=\"0\"/><input semantic=\"NORMAL\" source=\"#n\" offset=\"1\"/><p>{}</p></triangles>\n</mesh></geometry></library_geometries></COLLADA>",
                p.join("\n")
            )
        };
        for normal in [
            "7",
            "0",
            "123456789012345678901234",
            "1.0",
            "+2",
            "3e0",
            "-1",
            ".5",
        ] {
            let m = parse(with_normals(normal).as_bytes(), Path::new("t.dae")).unwrap();
            assert_eq!(
                m.faces.indices,
                [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
                "{normal}"
            );
        }
        for bad in ["x", "1x", "7,"] {
            let e = parse(with_normals(bad).as_bytes(), Path::new("t.dae")).unwrap_err();
            assert!(
                e.to_string()
                    .contains(&format!("`{bad}` is not a number in <p>")),
                "{e}"
            );
        }
    }
}
