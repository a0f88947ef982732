//! glTF 2.0 (.gltf and .glb), read with the `gltf` crate.
//!
//! Convention:
//! * every mesh instanced by a node of the default scene (the first scene without a default; every mesh
//!   once, untransformed, when the file has no scene) counts, moved by the composition of its ancestors'
//!   node transforms (`matrix`, or translation · rotation · scale), composed in f64;
//! * positions are taken as written: glTF's +Y up is **not** rotated into +Z. That is what pinocchio
//!   (coal's assimp loader) and `RViz` do; Drake rotates Y-up into Z-up for glTF, and the README says so.
//!   Coal also skips the transform of a single root node for the nodes below it (the heuristic it uses to
//!   drop assimp's COLLADA up-axis node); this reader applies every node transform, as the format says;
//! * triangles, triangle strips and triangle fans, indexed or not; points and lines carry no surface and
//!   are skipped with a note; a node with a negative determinant mirrors its triangles, whose winding is
//!   reversed to stay outward;
//! * buffers from the GLB `BIN` chunk, base64 `data:` URIs, or relative URI references resolved against
//!   the .gltf file's directory (percent-decoded, `../` allowed as RFC 3986 resolves it); absolute paths
//!   and other schemes are refused. Each distinct URI is read once however many buffers name it, and
//!   the buffers' bytes together count against the one-file size limit (`--max-file-size`);
//! * what the scene instances is bounded by the expansion budget COLLADA has too (vertices, triangle
//!   corners, node visits);
//! * positions are f32 by the format and convert exactly to f64.
//!
//! Refused with an error naming them: Draco (`KHR_draco_mesh_compression`) and meshopt
//! (`EXT_meshopt_compression`) compression, sparse accessors, and any other `extensionsRequired` that can
//! change geometry (material-only extensions are accepted). Every offset and length is checked before the
//! crate reads an accessor, and the crate call is also guarded against panics, so no input panics.

use super::affine::{self, compose, Affine, IDENTITY};
use super::{
    beyond_expansion_budget, MeshError, MeshErrorKind, RawMesh, MAX_INSTANCED_CORNERS,
    MAX_INSTANCED_VERTICES, MAX_NODE_VISITS,
};
use crate::mass::Polygons;
use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;
use std::rc::Rc;

/// Required extensions that only touch materials, textures or lights: geometry reads the same.
const GEOMETRY_NEUTRAL_PREFIXES: &[&str] = &[
    "KHR_materials_",
    "KHR_texture_",
    "EXT_texture_",
    "KHR_lights_punctual",
];

/// A node tree deeper than this is malformed (glTF node hierarchies are trees).
const MAX_DEPTH: usize = 256;

fn syntax(path: &Path, msg: String) -> MeshError {
    MeshError::new(path, None, MeshErrorKind::Syntax(msg))
}

fn unsupported(path: &Path, msg: String) -> MeshError {
    MeshError::new(path, None, MeshErrorKind::Unsupported(msg))
}

/// What the user can do about an extension we do not read.
fn extension_advice(name: &str) -> String {
    match name {
        "KHR_draco_mesh_compression" => format!(
            "`{name}` (Draco compression) is not supported; export the collision mesh without compression (e.g. `gltf-transform copy` or Blender with Draco off)"
        ),
        "EXT_meshopt_compression" => format!(
            "`{name}` (meshopt compression) is not supported; export the collision mesh without compression (e.g. `gltf-transform copy`)"
        ),
        _ => format!(
            "the file requires the extension `{name}`, which urdf-inertia does not read; export the collision mesh without it"
        ),
    }
}

/// The node transform as an affine map in f64 (column-major matrix, or T · R · S).
fn node_transform(node: &gltf::Node<'_>, path: &Path) -> Result<Affine, MeshError> {
    let xf = match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            let c = |col: usize, row: usize| f64::from(matrix[col][row]);
            (
                [
                    [c(0, 0), c(1, 0), c(2, 0)],
                    [c(0, 1), c(1, 1), c(2, 1)],
                    [c(0, 2), c(1, 2), c(2, 2)],
                ],
                [c(3, 0), c(3, 1), c(3, 2)],
            )
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let [x, y, z, w] = rotation.map(f64::from);
            let n = (x * x + y * y + z * z + w * w).sqrt();
            if n == 0.0 || !n.is_finite() {
                return Err(syntax(
                    path,
                    format!(
                        "node {} has a rotation quaternion of zero or non-finite length",
                        node.index()
                    ),
                ));
            }
            // Unit quaternions are stored in f32; normalising in f64 keeps the rotation orthogonal.
            let (x, y, z, w) = (x / n, y / n, z / n, w / n);
            let r = [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - z * w),
                    2.0 * (x * z + y * w),
                ],
                [
                    2.0 * (x * y + z * w),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - x * w),
                ],
                [
                    2.0 * (x * z - y * w),
                    2.0 * (y * z + x * w),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ];
            let s = scale.map(f64::from);
            let m = [0, 1, 2].map(|i| [0, 1, 2].map(|j| r[i][j] * s[j]));
            (m, translation.map(f64::from))
        }
    };
    if xf
        .0
        .iter()
        .flatten()
        .chain(xf.1.iter())
        .any(|v| !v.is_finite())
    {
        return Err(syntax(
            path,
            format!("node {} has a non-finite transform", node.index()),
        ));
    }
    Ok(xf)
}

/// A buffer's bytes, shared by every buffer that names the same source.
type Buffer = Rc<Vec<u8>>;

/// Buffer contents, by buffer index: each distinct source (the BIN chunk, a URI) read once, and all
/// of them together within the one-file size limit (2,000 buffers naming one 5 MB file once read
/// 10 GB).
fn load_buffers(
    doc: &gltf::Document,
    blob: Option<Vec<u8>>,
    path: &Path,
    meshopt_used: bool,
    max_file_size: u64,
) -> Result<Vec<Buffer>, MeshError> {
    let mut out = Vec::new();
    let blob = blob.map(Rc::new);
    let mut by_uri: HashMap<&str, Buffer> = HashMap::new();
    let mut total = blob.as_ref().map_or(0, |b| b.len() as u64);
    for buffer in doc.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => Rc::clone(blob.as_ref().ok_or_else(|| {
                syntax(
                    path,
                    format!(
                        "buffer {} refers to the GLB BIN chunk, but the file has none",
                        buffer.index()
                    ),
                )
            })?),
            gltf::buffer::Source::Uri(uri) => if let Some(data) = by_uri.get(uri) { Rc::clone(data) } else {
                let data = Rc::new(read_uri(uri, path, buffer.index(), max_file_size)?);
                total = total.saturating_add(data.len() as u64);
                if total > max_file_size {
                    return Err(MeshError::new(
                        path,
                        None,
                        MeshErrorKind::Io(format!(
                            "buffer {}: the file's buffers together are larger than the limit of {max_file_size} bytes (raise it with --max-file-size or URDF_INERTIA_MAX_FILE_SIZE)",
                            buffer.index(),
                        )),
                    ));
                }
                by_uri.insert(uri, Rc::clone(&data));
                data
            },
        };
        if data.len() < buffer.length() {
            let what = format!(
                "buffer {} declares {} bytes but holds {}",
                buffer.index(),
                buffer.length(),
                data.len()
            );
            return Err(if meshopt_used {
                unsupported(
                    path,
                    format!("{what}; {}", extension_advice("EXT_meshopt_compression")),
                )
            } else {
                MeshError::new(path, None, MeshErrorKind::Truncated(what))
            });
        }
        out.push(data);
    }
    Ok(out)
}

fn read_uri(
    uri: &str,
    path: &Path,
    index: usize,
    max_file_size: u64,
) -> Result<Vec<u8>, MeshError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or_else(|| syntax(path, format!("buffer {index}: a data URI without a comma")))?;
        if !header.ends_with(";base64") {
            return Err(syntax(
                path,
                format!("buffer {index}: only base64 data URIs are supported"),
            ));
        }
        return base64::engine::general_purpose::STANDARD
            .decode(payload.trim())
            .map_err(|e| {
                syntax(
                    path,
                    format!("buffer {index}: invalid base64 data URI: {e}"),
                )
            });
    }
    let decoded = urlencoding::decode(uri).map_err(|_| {
        syntax(
            path,
            format!("buffer {index}: URI `{uri}` is not valid percent-encoded UTF-8"),
        )
    })?;
    // A scheme (`file:`, `http:`) or an absolute path, also once percent-decoded: glTF buffers are
    // relative references or data URIs.
    let has_scheme = |u: &str| {
        u.split_once(':').is_some_and(|(scheme, _)| {
            !scheme.is_empty()
                && scheme
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"+-.".contains(&b))
        })
    };
    if has_scheme(uri) || uri.starts_with('/') || Path::new(decoded.as_ref()).is_absolute() {
        return Err(syntax(
            path,
            format!("buffer {index}: URI `{}` is absolute; only relative references (resolved against the glTF's directory) and data URIs are read", crate::text::escape_control(uri)),
        ));
    }
    let file = path
        .parent()
        .unwrap_or(Path::new("."))
        .join(decoded.as_ref());
    // Through the same guard as every input: regular files only, at most --max-file-size.
    crate::input::read_file(&file, max_file_size).map_err(|e| {
        MeshError::new(
            path,
            None,
            MeshErrorKind::Io(format!("buffer {index}, `{}`: {e}", file.display())),
        )
    })
}

/// Checks an accessor before the crate reads it: no sparse data, the expected type, and every byte it
/// covers inside its buffer view and buffer.
fn check_accessor(
    acc: &gltf::Accessor<'_>,
    buffers: &[Buffer],
    path: &Path,
    what: &str,
    draco_used: bool,
) -> Result<(), MeshError> {
    let i = acc.index();
    if acc.sparse().is_some() {
        return Err(unsupported(
            path,
            format!("{what} accessor {i} is sparse, which urdf-inertia does not read; export the collision mesh without sparse accessors"),
        ));
    }
    let Some(view) = acc.view() else {
        let msg = format!("{what} accessor {i} has no buffer view");
        return Err(if draco_used {
            unsupported(
                path,
                format!("{msg}: {}", extension_advice("KHR_draco_mesh_compression")),
            )
        } else {
            syntax(path, msg)
        });
    };
    let elem = acc.size();
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        return Err(syntax(
            path,
            format!(
                "{what} accessor {i}: byte stride {stride} is shorter than its {elem}-byte element"
            ),
        ));
    }
    let count = acc.count();
    let need = (count.max(1) - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(elem))
        .and_then(|n| n.checked_add(acc.offset()));
    let buffer = buffers.get(view.buffer().index()).map_or(0, |b| b.len());
    let view_end = view.offset().checked_add(view.length());
    match (need, view_end) {
        (Some(need), Some(view_end)) if count == 0 || (need <= view.length() && view_end <= buffer) => Ok(()),
        _ => Err(MeshError::new(
            path,
            None,
            MeshErrorKind::Truncated(format!(
                "{what} accessor {i} ({count} elements) reaches past its buffer view {} or buffer {}",
                view.index(),
                view.buffer().index()
            )),
        )),
    }
}

/// Positions (world frame) and triangles of one primitive, appended to `out`.
fn add_primitive(
    prim: &gltf::Primitive<'_>,
    xf: &Affine,
    buffers: &[Buffer],
    path: &Path,
    draco_used: bool,
    out: &mut RawMesh,
) -> Result<(), MeshError> {
    let mode = prim.mode();
    if matches!(
        mode,
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
    ) {
        out.notes
            .push(format!("a {mode:?} primitive carries no surface (skipped)"));
        return Ok(());
    }
    let Some(pos) = prim.get(&gltf::Semantic::Positions) else {
        out.notes
            .push("a primitive without POSITION (skipped)".into());
        return Ok(());
    };
    check_primitive_accessors(prim, &pos, buffers, path, draco_used)?;
    if pos.count() == 0 {
        return Ok(());
    }
    if beyond_expansion_budget(
        out.vertices.len().saturating_add(pos.count()),
        out.faces
            .indices
            .len()
            .saturating_add(corners_at_most(prim, &pos)),
    ) {
        return Err(over_budget(path));
    }
    let reader = prim.reader(|b| buffers.get(b.index()).map(|b| b.as_slice()));
    let cannot =
        |what: &str, index: usize| syntax(path, format!("{what} accessor {index} cannot be read"));
    let positions = reader
        .read_positions()
        .ok_or_else(|| cannot("POSITION", pos.index()))?;
    // Positions are transformed straight into the mesh, and triangle indices streamed into its
    // faces: the primitive's data is not copied first.
    let base = out.vertices.len();
    out.vertices.extend(positions.map(|p| {
        let q = crate::mass::mat_vec(&xf.0, p.map(f64::from));
        [q[0] + xf.1[0], q[1] + xf.1[1], q[2] + xf.1[2]]
    }));
    let n = out.vertices.len() - base;
    let (base, mirrored) = (base as u32, affine::mirrors(xf));
    match prim.indices() {
        Some(acc) if acc.count() == 0 => Ok(()),
        Some(acc) => {
            let indices = reader
                .read_indices()
                .ok_or_else(|| cannot("index", acc.index()))?
                .into_u32();
            if mode == Mode::Triangles {
                return stream_triangles(indices, acc.count(), n, base, mirrored, out, path);
            }
            let indices: Vec<u32> = indices.collect();
            check_indices(&indices, n, path)?;
            push_triangles(mode, &indices, base, mirrored, out);
            Ok(())
        }
        None if mode == Mode::Triangles => {
            stream_triangles(0..n as u32, n, n, base, mirrored, out, path)
        }
        None => {
            let indices: Vec<u32> = (0..n as u32).collect();
            push_triangles(mode, &indices, base, mirrored, out);
            Ok(())
        }
    }
}

/// The triangles of a TRIANGLES primitive's `count` indices into its `n` vertices (offset by `base`),
/// each index checked as it is read; reversed if the node's transform mirrors.
fn stream_triangles(
    mut indices: impl Iterator<Item = u32>,
    count: usize,
    n: usize,
    base: u32,
    mirrored: bool,
    out: &mut RawMesh,
    path: &Path,
) -> Result<(), MeshError> {
    if count % 3 != 0 {
        out.notes.push(format!(
            "a triangle primitive has {count} indices, not a multiple of 3 (the last {} ignored)",
            count % 3
        ));
    }
    for _ in 0..count / 3 {
        let mut t = [0u32; 3];
        for i in &mut t {
            *i = indices.next().unwrap_or(u32::MAX);
            check_indices(std::slice::from_ref(i), n, path)?;
            *i += base;
        }
        out.faces
            .push(&if mirrored { [t[0], t[2], t[1]] } else { t });
    }
    Ok(())
}

/// Every index below the primitive's vertex count `n`.
fn check_indices(indices: &[u32], n: usize, path: &Path) -> Result<(), MeshError> {
    match indices.iter().find(|&&i| i as usize >= n) {
        Some(&bad) => Err(MeshError::new(
            path,
            None,
            MeshErrorKind::IndexOutOfRange {
                index: i64::from(bad),
                vertices: n,
            },
        )),
        None => Ok(()),
    }
}

/// Checks a primitive's POSITION accessor (float VEC3) and its index accessor (unsigned scalars) before
/// anything is read through them.
fn check_primitive_accessors(
    prim: &gltf::Primitive<'_>,
    pos: &gltf::Accessor<'_>,
    buffers: &[Buffer],
    path: &Path,
    draco_used: bool,
) -> Result<(), MeshError> {
    if pos.data_type() != DataType::F32 || pos.dimensions() != Dimensions::Vec3 {
        return Err(unsupported(
            path,
            format!(
                "POSITION accessor {} is {:?} {:?}, not float VEC3 (quantized positions, KHR_mesh_quantization, are not read)",
                pos.index(),
                pos.data_type(),
                pos.dimensions()
            ),
        ));
    }
    check_accessor(pos, buffers, path, "POSITION", draco_used)?;
    if let Some(acc) = &prim.indices() {
        if acc.dimensions() != Dimensions::Scalar
            || !matches!(
                acc.data_type(),
                DataType::U8 | DataType::U16 | DataType::U32
            )
        {
            return Err(syntax(
                path,
                format!(
                    "index accessor {} is not an unsigned integer scalar",
                    acc.index()
                ),
            ));
        }
        check_accessor(acc, buffers, path, "index", draco_used)?;
    }
    Ok(())
}

/// The triangles of a primitive's `indices` (offset by `base`) in its `mode`, reversed if the node's
/// transform mirrors.
fn push_triangles(mode: Mode, indices: &[u32], base: u32, mirrored: bool, out: &mut RawMesh) {
    let mut push = |a: u32, b: u32, c: u32| {
        let tri = if mirrored {
            [base + a, base + c, base + b]
        } else {
            [base + a, base + b, base + c]
        };
        out.faces.push(&tri);
    };
    match mode {
        Mode::TriangleStrip => {
            // Triangle i is (v_i, v_{i+1}, v_{i+2}) with every other one reversed; triangles with a
            // repeated vertex join strips and carry no area.
            for i in 0..indices.len().saturating_sub(2) {
                let (a, b, c) = (indices[i], indices[i + 1], indices[i + 2]);
                if a == b || b == c || a == c {
                    continue;
                }
                if i % 2 == 0 {
                    push(a, b, c);
                } else {
                    push(b, a, c);
                }
            }
        }
        Mode::TriangleFan => {
            for i in 1..indices.len().saturating_sub(1) {
                let (a, b, c) = (indices[0], indices[i], indices[i + 1]);
                if a == b || b == c || a == c {
                    continue;
                }
                push(a, b, c);
            }
        }
        // TRIANGLES primitives are streamed by `stream_triangles`.
        _ => {}
    }
}

/// Checks the GLB container header before the crate parses it (the crate assumes a sane length).
fn check_glb_header(bytes: &[u8], path: &Path) -> Result<(), MeshError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 20 {
        return Err(MeshError::new(
            path,
            None,
            MeshErrorKind::Truncated(format!(
                "a GLB file needs at least 20 bytes of headers, the file has {}",
                bytes.len()
            )),
        ));
    }
    let word = |at: usize| {
        u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize
    };
    let (version, length) = (word(4), word(8));
    if version != 2 {
        return Err(unsupported(
            path,
            format!("GLB version {version}; only glTF 2.0 is read"),
        ));
    }
    if length < 20 || length > bytes.len() {
        return Err(MeshError::new(
            path,
            None,
            MeshErrorKind::Truncated(format!(
                "the GLB header says {length} bytes, the file has {}",
                bytes.len()
            )),
        ));
    }
    Ok(())
}

/// Parses a .gltf or .glb file into one mesh in the file's frame (see the module docs for the convention).
/// External buffers are read relative to `path`, all of them together no larger than `max_file_size`.
pub fn parse(bytes: &[u8], path: &Path, max_file_size: u64) -> Result<RawMesh, MeshError> {
    check_glb_header(bytes, path)?;
    // Offsets are checked before every read; the guard turns any panic left in the crate into an error.
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        parse_checked(bytes, path, max_file_size)
    })) {
        Ok(result) => result,
        Err(_) => Err(syntax(
            path,
            "the glTF reader failed on this file (malformed data); re-export the mesh".into(),
        )),
    }
}

/// Parses a glTF document whose GLB header was checked; may panic inside the crate (see [`parse`]).
fn parse_checked(bytes: &[u8], path: &Path, max_file_size: u64) -> Result<RawMesh, MeshError> {
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| syntax(path, format!("not a valid glTF file: {e}")))?;
    let mut root = document.into_json();
    let (draco_used, meshopt_used) = check_json(&root, path)?;
    // Material-only required extensions are accepted above; the crate's validation would refuse them.
    root.extensions_required.clear();
    let doc = gltf::Document::from_json(root).map_err(|e| syntax(path, format!("{e}")))?;
    let buffers = load_buffers(&doc, blob, path, meshopt_used, max_file_size)?;

    let mut out = RawMesh {
        faces: Polygons::new(),
        ..Default::default()
    };
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    if let Some(scene) = scene { add_scene(&scene, &buffers, path, draco_used, &mut out)? } else {
        for mesh in doc.meshes() {
            for prim in mesh.primitives() {
                add_primitive(&prim, &IDENTITY, &buffers, path, draco_used, &mut out)?;
            }
        }
        if doc.meshes().len() > 0 {
            out.notes
                .push("no scene: every mesh counted once, untransformed".into());
        }
    }
    Ok(out)
}

/// Checks the document's JSON before the crate validates it: required extensions, Draco accessors
/// and accessor indices the crate's validation would trip on. Returns whether Draco and meshopt
/// compression are used.
fn check_json(root: &gltf::json::Root, path: &Path) -> Result<(bool, bool), MeshError> {
    if let Some(name) = root.extensions_required.iter().find(|name| {
        !GEOMETRY_NEUTRAL_PREFIXES
            .iter()
            .any(|p| name.starts_with(p))
    }) {
        return Err(unsupported(path, extension_advice(name)));
    }
    let draco_used = root
        .extensions_used
        .iter()
        .any(|e| e == "KHR_draco_mesh_compression");
    let meshopt_used = root
        .extensions_used
        .iter()
        .any(|e| e == "EXT_meshopt_compression");
    // Draco's compressed accessors have no buffer view (the crate's validation would only say "missing").
    if draco_used
        && root
            .accessors
            .iter()
            .any(|a| a.buffer_view.is_none() && a.sparse.is_none())
    {
        return Err(unsupported(
            path,
            format!(
                "an accessor has no buffer view: {}",
                extension_advice("KHR_draco_mesh_compression")
            ),
        ));
    }
    // gltf-json 1.4.1's validation indexes a primitive's POSITION accessor before checking it exists.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for prim in &mesh.primitives {
            if let Some(bad) = prim
                .attributes
                .values()
                .find(|a| a.value() >= root.accessors.len())
            {
                return Err(syntax(
                    path,
                    format!(
                        "mesh {m}: a primitive names accessor {}, but the file has {}",
                        bad.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    Ok((draco_used, meshopt_used))
}

/// What the scene would instance, counted from the accessors' declared counts before anything is
/// placed, against the expansion budget: a file asking for too much fails at once, before it has
/// taken the budget's memory. (The placing checks again as it goes; this pass only fails early.)
fn check_scene_budget(scene: &gltf::Scene<'_>, path: &Path) -> Result<(), MeshError> {
    let (mut vertices, mut corners, mut visits) = (0usize, 0usize, 0usize);
    let mut stack: Vec<(gltf::Node<'_>, usize)> = scene.nodes().map(|n| (n, 0)).collect();
    while let Some((node, depth)) = stack.pop() {
        visits += 1;
        if depth > MAX_DEPTH || visits > MAX_NODE_VISITS {
            // Reported by the placing pass, with its message.
            return Ok(());
        }
        for prim in node.mesh().iter().flat_map(gltf::Mesh::primitives) {
            if let Some(pos) = prim.get(&gltf::Semantic::Positions) {
                vertices = vertices.saturating_add(pos.count());
                corners = corners.saturating_add(corners_at_most(&prim, &pos));
            }
        }
        if beyond_expansion_budget(vertices, corners) {
            return Err(over_budget(path));
        }
        stack.extend(node.children().map(|c| (c, depth + 1)));
    }
    Ok(())
}

/// The triangle corners a primitive can make: one per index of TRIANGLES, three per index of a strip
/// or fan (each index adds at most one triangle).
fn corners_at_most(prim: &gltf::Primitive<'_>, pos: &gltf::Accessor<'_>) -> usize {
    let indices = prim.indices().map_or(pos.count(), |a| a.count());
    match prim.mode() {
        Mode::Triangles => indices,
        Mode::TriangleStrip | Mode::TriangleFan => indices.saturating_mul(3),
        _ => 0,
    }
}

fn over_budget(path: &Path) -> MeshError {
    syntax(
        path,
        format!("the scene instances more than {MAX_INSTANCED_VERTICES} vertices or {MAX_INSTANCED_CORNERS} triangle corners (nodes shared by several parents multiply their mesh); simplify the collision mesh"),
    )
}

/// Every primitive of the meshes a scene's node hierarchy reaches, in the world frame (depth and
/// visits are bounded: a cycle is an error, not a hang).
fn add_scene(
    scene: &gltf::Scene<'_>,
    buffers: &[Buffer],
    path: &Path,
    draco_used: bool,
    out: &mut RawMesh,
) -> Result<(), MeshError> {
    check_scene_budget(scene, path)?;
    let mut visits = 0usize;
    let mut stack: Vec<(gltf::Node<'_>, Affine, usize)> =
        scene.nodes().map(|n| (n, IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        visits += 1;
        if depth > MAX_DEPTH || visits > MAX_NODE_VISITS {
            return Err(syntax(
                path,
                format!("the node hierarchy is deeper than {MAX_DEPTH} or reaches more than {MAX_NODE_VISITS} nodes (a cycle?)"),
            ));
        }
        let xf = compose(&parent, &node_transform(&node, path)?);
        if let Some(mesh) = node.mesh() {
            if node.skin().is_some() {
                out.notes.push(format!(
                    "mesh {} is skinned: its bind pose is used",
                    mesh.index()
                ));
            }
            for prim in mesh.primitives() {
                add_primitive(&prim, &xf, buffers, path, draco_used, out)?;
            }
        }
        for child in node.children() {
            stack.push((child, xf, depth + 1));
        }
    }
    Ok(())
}
