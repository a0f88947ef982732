//! Collision meshes: reading STL, OBJ, COLLADA and glTF into vertices plus polygons, applying the URDF `scale`,
//! and turning the result into a solid the mass core can integrate (see [`health`]).
//!
//! Each format is a thin module with its own parsing and a `file:line` location where the format has
//! lines. Polygons stay polygons. Coordinates are read as f64 (binary STL's and glTF's f32 values convert
//! exactly).

mod affine;
pub mod cache;
pub mod collada;
pub mod gltf;
pub mod health;
pub mod hull;
pub mod inside;
pub mod obj;
pub mod open;
pub mod stl;
pub mod weld;
mod winding_shells;

use crate::mass::Polygons;
use std::borrow::Cow;
use std::fmt;
use std::path::{Path, PathBuf};

/// The expansion budget shared by the readers whose scene graphs instance geometry (COLLADA's
/// `<instance_node>`, glTF nodes shared by several parents): a few kilobytes can ask for 2^40 copies
/// of a mesh, so what one file may place is bounded. Vertices (24 bytes each) and polygon corners
/// (4 bytes each) bound the mesh at about 650 MB, node visits bound the traversal.
pub(crate) const MAX_INSTANCED_VERTICES: usize = 1 << 24;
/// See [`MAX_INSTANCED_VERTICES`].
pub(crate) const MAX_INSTANCED_CORNERS: usize = 1 << 26;
/// See [`MAX_INSTANCED_VERTICES`].
pub(crate) const MAX_NODE_VISITS: usize = 1 << 20;

/// Whether a mesh of `vertices` and `corners` in all is beyond the expansion budget.
pub(crate) fn beyond_expansion_budget(vertices: usize, corners: usize) -> bool {
    vertices > MAX_INSTANCED_VERTICES || corners > MAX_INSTANCED_CORNERS
}

/// Vertices and faces as read from a file, before any health check.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawMesh {
    pub vertices: Vec<[f64; 3]>,
    pub faces: Polygons,
    /// Things the reader tolerated that leave the solid as the file means it (a wrong triangle
    /// count, several objects), for the report.
    pub notes: Vec<String>,
    /// Things the reader left out of the solid (faces it could not use), for the report.
    pub warnings: Vec<String>,
    /// The reader welded as it read: the vertices are pairwise distinct in their bits and none is
    /// −0.0, so the health step's exact weld has nothing to merge and is skipped (it only drops
    /// collapsed faces). `false` is always safe.
    pub welded: bool,
}

/// The mesh formats urdf-inertia reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    Stl,
    Obj,
    Collada,
    /// glTF 2.0, JSON (.gltf) or binary (.glb).
    Gltf,
}

impl MeshFormat {
    /// The format of a file, by its extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "stl" => Some(MeshFormat::Stl),
            "obj" => Some(MeshFormat::Obj),
            "dae" => Some(MeshFormat::Collada),
            "gltf" | "glb" => Some(MeshFormat::Gltf),
            _ => None,
        }
    }
}

/// Why a mesh file could not become a solid.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct MeshError {
    pub path: PathBuf,
    /// 1-based line, where the format has lines.
    pub line: Option<usize>,
    pub kind: MeshErrorKind,
    /// For [`MeshErrorKind::ZeroVolume`] from the healing: the mesh's largest extent along an axis,
    /// from the box the healing found, for [`out_of_range`] (the mesh itself has moved into the
    /// healing by then, and finding the extent before it was a pass over every vertex that only a
    /// mesh of no volume needs). Not part of the error's identity.
    extent: Option<f64>,
    /// For [`MeshErrorKind::ZeroVolume`]: every face was stored twice, once each way (a
    /// double-sided export), and the pairs cancelled ([`MeshError::is_two_sided`]).
    two_sided: bool,
}

impl PartialEq for MeshError {
    fn eq(&self, other: &Self) -> bool {
        (&self.path, self.line, &self.kind) == (&other.path, other.line, &other.kind)
    }
}

/// What went wrong with a mesh.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MeshErrorKind {
    /// The file could not be read at all.
    Io(String),
    /// The extension is not one of .stl, .obj, .dae, .gltf, .glb.
    UnknownFormat(String),
    /// The content does not follow the format.
    Syntax(String),
    /// A binary STL shorter than its header says, or than one triangle record.
    Truncated(String),
    /// A NaN or infinite coordinate.
    NotFinite,
    /// A face refers to a vertex that does not exist.
    IndexOutOfRange { index: i64, vertices: usize },
    /// No faces at all.
    Empty,
    /// The solid (or its convex hull) has no volume to speak of.
    ZeroVolume { volume: f64, bbox_volume: f64 },
    /// A rung below "exact" was needed and strict mode forbids it.
    Strict(String),
    /// A scale with a zero or non-finite factor.
    BadScale([f64; 3]),
    /// An open mesh whose convex hull could not be built either.
    Hull(String),
    /// An open mesh with no solid to trust under the model chosen for open meshes (`--open-mesh`).
    NoSolid(open::NoSolid),
    /// A reader or the healing panicked (a bug): caught, so that it fails only this mesh.
    Internal(String),
    /// A feature of the format urdf-inertia does not read (a glTF compression extension, ...), named.
    Unsupported(String),
    /// A mesh too large or too small for f64 (its volume and inertia overflow or underflow).
    OutOfRange(String),
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let path = self.path.display().to_string();
        write!(f, "{}", crate::text::escape_control(&path))?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": ")?;
        match &self.kind {
            MeshErrorKind::Io(e) => write!(f, "cannot read the file: {e}"),
            MeshErrorKind::UnknownFormat(ext) => write!(
                f,
                "unsupported mesh format `{ext}`; urdf-inertia reads .stl, .obj, .dae, .gltf and .glb (convert the collision mesh, e.g. with meshlab or blender)"
            ),
            MeshErrorKind::Truncated(msg) => write!(f, "truncated file: {msg}; re-export the mesh"),
            MeshErrorKind::NotFinite => write!(f, "a vertex coordinate is NaN or infinite; fix or re-export the mesh"),
            MeshErrorKind::IndexOutOfRange { index, vertices } => {
                write!(f, "a face refers to vertex {index}, but the file has {vertices} vertices")
            }
            MeshErrorKind::Empty => write!(f, "the mesh has no faces"),
            MeshErrorKind::ZeroVolume { .. } if self.two_sided => write!(
                f,
                "the mesh encloses no volume: every face is stored twice, once each way (a double-sided export, as SketchUp writes), so its two sides cancel; export it single-sided, or give the link a primitive collision shape"
            ),
            MeshErrorKind::ZeroVolume { volume, bbox_volume } => write!(
                f,
                "the mesh encloses no volume ({} m³ against a bounding box of {} m³): it is flat or degenerate; give the link a primitive collision shape or a closed mesh",
                crate::text::significant(*volume, 4),
                crate::text::significant(*bbox_volume, 4)
            ),
            MeshErrorKind::Strict(msg) => write!(f, "{msg} (an error under --strict)"),
            MeshErrorKind::Hull(msg) => write!(f, "{msg}; close the mesh or give the link a primitive collision shape"),
            MeshErrorKind::NoSolid(why) => write!(f, "{why}"),
            MeshErrorKind::BadScale(s) => {
                write!(f, "scale \"{} {} {}\" has a zero or non-finite factor", s[0], s[1], s[2])
            }
            MeshErrorKind::Internal(msg) => write!(
                f,
                "internal error while processing the mesh (a bug in urdf-inertia; please report it with the file): {msg}"
            ),
            MeshErrorKind::Syntax(msg) | MeshErrorKind::Unsupported(msg) | MeshErrorKind::OutOfRange(msg) => {
                write!(f, "{msg}")
            }
        }
    }
}

impl std::error::Error for MeshError {}

impl MeshError {
    pub fn new(path: &Path, line: Option<usize>, kind: MeshErrorKind) -> Self {
        MeshError {
            path: path.to_path_buf(),
            line,
            kind,
            extent: None,
            two_sided: false,
        }
    }

    /// Whether the mesh encloses no volume because every face is stored twice, once each way (a
    /// double-sided export: as `SketchUp` writes, rtb-data's `kuka_kr210/.../visual/link_1.dae`).
    pub fn is_two_sided(&self) -> bool {
        self.two_sided
    }

    /// This error, said of a mesh whose every face was stored twice, once each way.
    pub(crate) fn stored_two_sided(self) -> Self {
        MeshError {
            two_sided: matches!(self.kind, MeshErrorKind::ZeroVolume { .. }),
            ..self
        }
    }

    /// A [`MeshErrorKind::ZeroVolume`] of signed volume `volume` for a mesh whose vertices' box is
    /// `bounds`.
    pub(crate) fn zero_volume(path: &Path, volume: f64, bounds: crate::geometry::Aabb) -> Self {
        let e = bounds.extent();
        MeshError {
            extent: Some(e.iter().fold(0.0, |m, &x| f64::max(m, x))),
            ..MeshError::new(
                path,
                None,
                MeshErrorKind::ZeroVolume {
                    volume,
                    bbox_volume: e.iter().product(),
                },
            )
        }
    }
}

/// Runs `f`, turning a panic into this mesh's [`MeshErrorKind::Internal`] error: a backstop so that a
/// bug in a reader or in the healing fails one mesh (one link), never the whole run.
fn catching_panics<T>(
    path: &Path,
    f: impl FnOnce() -> Result<T, MeshError>,
) -> Result<T, MeshError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(std::string::ToString::to_string)
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic".into());
        Err(MeshError::new(path, None, MeshErrorKind::Internal(msg)))
    })
}

/// Reads a mesh file of any supported format (by extension), no larger than `max_file_size` bytes
/// (a glTF's external buffers together as well).
pub fn read(path: &Path, max_file_size: u64) -> Result<RawMesh, MeshError> {
    catching_panics(path, || read_unguarded(path, max_file_size))
}

fn read_unguarded(path: &Path, max_file_size: u64) -> Result<RawMesh, MeshError> {
    let format = MeshFormat::from_path(path).ok_or_else(|| {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map_or_else(|| "(no extension)".into(), |e| format!(".{e}"));
        MeshError::new(path, None, MeshErrorKind::UnknownFormat(ext))
    })?;
    if format == MeshFormat::Stl {
        // Streamed: a big binary file is never held whole.
        let mesh = stl::read(path, max_file_size)?;
        validate(&mesh, path)?;
        return Ok(mesh);
    }
    let bytes = crate::input::read_file(path, max_file_size)
        .map_err(|e| MeshError::new(path, None, MeshErrorKind::Io(e.to_string())))?;
    let mesh = match format {
        MeshFormat::Stl => stl::parse(&bytes, path)?,
        MeshFormat::Obj => obj::parse(&bytes, path)?,
        MeshFormat::Collada => collada::parse(&bytes, path)?,
        MeshFormat::Gltf => gltf::parse(&bytes, path, max_file_size)?,
    };
    validate(&mesh, path)?;
    Ok(mesh)
}

/// Items per chunk of [`chunked`].
const PASS_CHUNK: usize = 1 << 16;

/// `pass` over `items` in fixed chunks of [`PASS_CHUNK`], the chunks' results folded in order by
/// `join`: the same result on any number of threads. The chunks run on the library's pool when it
/// has more than one thread (one thread runs them in turn); fewer than two chunks are one pass.
/// For the passes over a large mesh's vertices or corners that would otherwise run on one thread
/// while the pool waits (checks, boxes, largest distances).
pub(crate) fn chunked<T: Sync, R: Send>(
    items: &[T],
    pass: impl Fn(&[T]) -> R + Sync + Send,
    join: impl Fn(R, R) -> R,
) -> R {
    use rayon::prelude::*;
    if items.len() < 2 * PASS_CHUNK {
        return pass(items);
    }
    let parts: Vec<R> = crate::threads::install(|| {
        if rayon::current_num_threads() < 2 {
            items.chunks(PASS_CHUNK).map(&pass).collect()
        } else {
            items.par_chunks(PASS_CHUNK).map(&pass).collect()
        }
    });
    let mut parts = parts.into_iter();
    let first = parts.next().unwrap_or_else(|| pass(&[]));
    parts.fold(first, join)
}

/// The bounding box of `vertices` ([`chunked`]: a large mesh's on the pool).
pub(crate) fn bounds(vertices: &[[f64; 3]]) -> crate::geometry::Aabb {
    chunked(
        vertices,
        |c| crate::geometry::Aabb::of(c.iter().copied()),
        crate::geometry::Aabb::union,
    )
}

/// Checks what every reader must guarantee: finite coordinates, indices in range, at least one face.
/// Both passes are [`chunked`]: a large mesh is checked on the pool.
pub fn validate(mesh: &RawMesh, path: &Path) -> Result<(), MeshError> {
    let finite = |c: &[[f64; 3]]| c.iter().flatten().all(|x| x.is_finite());
    if !chunked(&mesh.vertices, finite, |a, b| a && b) {
        return Err(MeshError::new(path, None, MeshErrorKind::NotFinite));
    }
    let n = mesh.vertices.len();
    // The first index out of range, as one pass in order finds it.
    let beyond = |c: &[u32]| c.iter().copied().find(|&i| i as usize >= n);
    if let Some(bad) = chunked(&mesh.faces.indices, beyond, Option::or) {
        return Err(MeshError::new(
            path,
            None,
            MeshErrorKind::IndexOutOfRange {
                index: i64::from(bad),
                vertices: n,
            },
        ));
    }
    if mesh.faces.is_empty() {
        return Err(MeshError::new(path, None, MeshErrorKind::Empty));
    }
    Ok(())
}

/// Applies a per-axis scale. A negative determinant mirrors the solid, so every face is reversed to keep
/// it outward.
pub fn apply_scale(mesh: &RawMesh, scale: [f64; 3], path: &Path) -> Result<RawMesh, MeshError> {
    if scale.iter().any(|s| *s == 0.0 || !s.is_finite()) {
        return Err(MeshError::new(path, None, MeshErrorKind::BadScale(scale)));
    }
    let mut out = mesh.clone();
    if scale == [1.0; 3] {
        // Nothing to do.
    } else if out.welded && scale_keeps_distinct(&out.vertices, scale) {
        // Distinct vertices stay distinct, so the mesh stays welded once −0.0 is folded into 0.0
        // (+ 0.0, as the weld itself does) and is not welded again. Of example-robot-data's mesh
        // references, 137 are mirrored and 82 are millimetre binary STLs at 0.001.
        for v in &mut out.vertices {
            *v = [0, 1, 2].map(|k| v[k] * scale[k] + 0.0);
        }
    } else {
        // A product can round two distinct coordinates to one value: weld again.
        out.welded = false;
        for v in &mut out.vertices {
            *v = [v[0] * scale[0], v[1] * scale[1], v[2] * scale[2]];
        }
    }
    if scale[0] * scale[1] * scale[2] < 0.0 {
        for i in 0..out.faces.len() {
            out.faces.reverse_face(i);
        }
    }
    Ok(out)
}

/// Whether scaling keeps distinct coordinates distinct: always for a mirror (negation is exact); and for
/// coordinates that are all f32 values (binary STL) at a scale within [1e-200, 1e200] in magnitude,
/// since two distinct f32 values differ by at least 2⁻²⁴ of the larger, far above the 2⁻⁵³ each
/// rounded product may move, and no product can underflow or overflow.
fn scale_keeps_distinct(vertices: &[[f64; 3]], scale: [f64; 3]) -> bool {
    if scale.iter().all(|s| s.abs() == 1.0) {
        return true;
    }
    scale.iter().all(|s| (1e-200..=1e200).contains(&s.abs()))
        && vertices.iter().flatten().all(|&x| f64::from(x as f32) == x)
}

/// How a mesh file becomes a solid: the repair ladder's options and the limit on the file's size.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct LoadOptions {
    /// The repair ladder's options (`strict`, what an open mesh becomes).
    pub health: health::HealthOptions,
    /// The largest file read, in bytes ([`crate::input::DEFAULT_MAX_FILE_SIZE`] by default).
    pub max_file_size: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            health: health::HealthOptions::default(),
            max_file_size: crate::input::DEFAULT_MAX_FILE_SIZE,
        }
    }
}

impl LoadOptions {
    /// Every repair below a welded mesh is an error.
    #[must_use]
    pub fn strict(mut self, strict: bool) -> Self {
        self.health.strict = strict;
        self
    }

    /// What an open mesh whose caps cannot be trusted becomes.
    #[must_use]
    pub fn open_mesh(mut self, model: open::OpenMeshModel) -> Self {
        self.health.open_mesh = model;
        self
    }

    /// The largest file read, in bytes.
    #[must_use]
    pub fn max_file_size(mut self, bytes: u64) -> Self {
        self.max_file_size = bytes;
        self
    }
}

/// The default limit on the file's size.
impl From<health::HealthOptions> for LoadOptions {
    fn from(health: health::HealthOptions) -> Self {
        LoadOptions {
            health,
            ..LoadOptions::default()
        }
    }
}

/// Reads, scales and heals a mesh file: the solid the mass core integrates, with its provenance and
/// its error estimate.
pub fn load_solid(
    path: &Path,
    scale: [f64; 3],
    options: impl Into<LoadOptions>,
) -> Result<health::Solid, MeshError> {
    let options = options.into();
    let raw = read(path, options.max_file_size)?;
    solid_from_owned(raw, scale, path, options.health)
}

/// Scales and heals an already read mesh (a file used with several scales is read once).
pub fn solid_from_raw(
    raw: &RawMesh,
    scale: [f64; 3],
    path: &Path,
    options: health::HealthOptions,
) -> Result<health::Solid, MeshError> {
    solid_from(Cow::Borrowed(raw), scale, path, options)
}

/// [`solid_from_raw`] for a mesh used once: at unit scale its vertices and faces become the solid's
/// without a copy.
pub fn solid_from_owned(
    raw: RawMesh,
    scale: [f64; 3],
    path: &Path,
    options: health::HealthOptions,
) -> Result<health::Solid, MeshError> {
    solid_from(Cow::Owned(raw), scale, path, options)
}

fn solid_from(
    raw: Cow<'_, RawMesh>,
    scale: [f64; 3],
    path: &Path,
    options: health::HealthOptions,
) -> Result<health::Solid, MeshError> {
    catching_panics(path, || {
        if scale == [1.0; 3] {
            // A unit scale (the common case) uses the mesh as read. The healing takes the mesh;
            // a mesh of no volume comes back with its extent from the healing's box (every
            // no-volume error of the healing carries it: [`MeshError::zero_volume`]).
            return health::heal(raw, path, options, weld::Precision::of).map_err(|e| {
                let size = e.extent.unwrap_or(0.0);
                out_of_range(e, || size, scale)
            });
        }
        let scaled = apply_scale(&raw, scale, path)?;
        // The precision of the file's own numbers, before the scale multiplies them; the largest
        // coordinate scales with them, so the tolerance in ulps of it stays right.
        health::heal(Cow::Owned(scaled), path, options, |_| {
            weld::Precision::of(&raw.vertices)
        })
        .map_err(|e| out_of_range(e, flat_or_out_of_range(&raw, scale), scale))
    })
}

/// The mesh's largest extent along an axis once scaled, computed only when healing reports no
/// volume (see [`out_of_range`]): a closure, so the common case pays nothing.
fn flat_or_out_of_range(raw: &RawMesh, scale: [f64; 3]) -> impl Fn() -> f64 + '_ {
    move || {
        let e = bounds(&raw.vertices).extent();
        (0..3).map(|k| e[k] * scale[k].abs()).fold(0.0, f64::max)
    }
}

/// A "no volume" error of a mesh whose size is beyond f64 becomes what it is: inertia grows as the
/// fifth power of the size, so an extent above about 1e61 m (1e150 coordinates, `--scale 1e150`)
/// overflows and one below about 1e-61 m (subnormal coordinates, 1e-310) underflows, as primitives of
/// those sizes are reported. Flat meshes of ordinary size keep their error.
fn out_of_range(e: MeshError, extent: impl Fn() -> f64, scale: [f64; 3]) -> MeshError {
    if !matches!(e.kind, MeshErrorKind::ZeroVolume { .. }) {
        return e;
    }
    let size = extent();
    let fifth = size.powi(5);
    let what = if !fifth.is_finite() {
        "overflow"
    } else if size > 0.0 && fifth < f64::MIN_POSITIVE {
        "underflow"
    } else {
        return e;
    };
    let scaled = if scale == [1.0; 3] {
        String::new()
    } else {
        format!(" at scale \"{} {} {}\"", scale[0], scale[1], scale[2])
    };
    MeshError {
        kind: MeshErrorKind::OutOfRange(format!(
            "the mesh spans {} m{scaled}: its volume or inertia {what}s a 64-bit float (check the units and the scale: metres)",
            crate::text::significant(size, 4)
        )),
        ..e
    }
}

/// Parses a float the way all three formats write them, NaN and infinities included (they are caught
/// afterwards with a clearer message).
pub(crate) fn parse_f64(s: &str) -> Option<f64> {
    parse_f64_bytes(s.as_bytes())
}

/// [`parse_f64`] of a word of bytes (a word that is not UTF-8 is no number). Short decimals, what
/// mesh files hold, take Clinger's fast path here without a UTF-8 check or a second scan; the rest go
/// to `str::parse`. Both round correctly, so the result is `str::parse`'s to the bit (tested against it
/// in obj.rs). A number of laikago's trunk.obj: 188 instructions, where `str::parse` took 205 after
/// the word was cut out and checked as UTF-8; the gain is in the scanning around it.
pub(crate) fn parse_f64_bytes(w: &[u8]) -> Option<f64> {
    match short_decimal(w) {
        Some((x, n)) if n == w.len() => Some(x),
        _ => std::str::from_utf8(w).ok()?.parse::<f64>().ok(),
    }
}

/// The powers of ten an f64 holds exactly (Clinger's fast path, here and in `weld`).
pub(crate) const EXACT_POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The decimal `[+-]digits[.digits][(e|E)[+-]digits]` at the start of `w` and its length in bytes,
/// if it has at most 19 digits and its value is m·10^e with m ≤ 2^53 and |e| ≤ 22: m and 10^|e| are
/// exact f64s, so one multiplication or division rounds the value correctly (Clinger 1990, std's own
/// first path). `None` for anything else (longer numbers, `inf`, `nan`, malformed words), which
/// `str::parse` decides. A caller that scans a word with it checks that the word ends where it stops.
#[inline]
pub(crate) fn short_decimal(w: &[u8]) -> Option<(f64, usize)> {
    let (negative, mut i) = match w.first()? {
        b'-' => (true, 1),
        b'+' => (false, 1),
        _ => (false, 0),
    };
    // Integer digits, then fraction digits.
    let mut mantissa = 0u64;
    let whole = accumulate_digits(&w[i..], &mut mantissa);
    i += whole;
    // A whole number (an index), exact as it is: done.
    if (1..=15).contains(&whole) && !matches!(w.get(i), Some(b'.' | b'e' | b'E')) {
        let x = mantissa as f64;
        return Some((if negative { -x } else { x }, i));
    }
    let mut fraction = 0;
    if w.get(i) == Some(&b'.') {
        i += 1;
        fraction = accumulate_digits(&w[i..], &mut mantissa);
        i += fraction;
    }
    let digits = whole + fraction;
    if digits == 0 || digits > 19 {
        return None;
    }
    let (e, i) = exponent_suffix(w, i, 4)?;
    let exponent = e - fraction as i32;
    if mantissa > 1 << 53 {
        return None;
    }
    let power = *EXACT_POWERS_OF_TEN.get(exponent.unsigned_abs() as usize)?;
    let x = mantissa as f64;
    let x = if exponent < 0 { x / power } else { x * power };
    Some((if negative { -x } else { x }, i))
}

/// The exponent `(e|E)[+-]digits` of a decimal at `w[i..]`, with at most `max_digits` digits, and
/// the index after it: `(0, i)` when there is none, `None` when it is malformed or longer.
#[inline]
pub(crate) fn exponent_suffix(w: &[u8], mut i: usize, max_digits: usize) -> Option<(i32, usize)> {
    if !matches!(w.get(i), Some(b'e' | b'E')) {
        return Some((0, i));
    }
    i += 1;
    let negative = w.get(i) == Some(&b'-');
    if let Some(b'-' | b'+') = w.get(i) {
        i += 1;
    }
    let from = i;
    let mut e = 0i32;
    while let Some(&d @ b'0'..=b'9') = w.get(i) {
        if i - from == max_digits {
            return None;
        }
        e = 10 * e + i32::from(d - b'0');
        i += 1;
    }
    if i == from {
        return None;
    }
    Some((if negative { -e } else { e }, i))
}

/// Appends the leading decimal digits of `w` to `mantissa` (wrapping: a caller refuses more than 19
/// digits) and returns how many there were. (Four digits at a time by SWAR, as `fast_float` does eight,
/// cost more on ERD's 5- and 6-digit indices: go1's trunk.dae 533 M -> 567 M instructions.)
fn accumulate_digits(w: &[u8], mantissa: &mut u64) -> usize {
    let mut n = 0;
    for &d in w {
        if !d.is_ascii_digit() {
            break;
        }
        *mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d - b'0'));
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checks and the box of a mesh of several of [`chunked`]'s chunks are those of one pass in
    /// order, on one thread and on three: the first index out of range of two (in later chunks), a
    /// non-finite coordinate in the last chunk, and the box against the coordinates sorted.
    #[test]
    fn chunked_passes_agree_with_one_pass() {
        let n = 5 * PASS_CHUNK + 17;
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || (crate::xorshift(&mut rng) >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        let vertices: Vec<[f64; 3]> = (0..n).map(|_| [next(), 1e3 * next(), -next()]).collect();
        let corners = (0..3 * n as u32).map(|i| i % n as u32).collect::<Vec<u32>>();
        let mesh = RawMesh {
            vertices,
            faces: Polygons {
                starts: (0..=n as u32).map(|i| 3 * i).collect(),
                indices: corners,
            },
            ..Default::default()
        };
        let p = Path::new("m.stl");
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            pool.install(|| {
                assert_eq!(validate(&mesh, p), Ok(()));
                let mut bad = mesh.clone();
                bad.faces.indices[4 * PASS_CHUNK + 3] = n as u32 + 7;
                bad.faces.indices[2 * PASS_CHUNK + 1] = n as u32 + 5;
                let e = validate(&bad, p).expect_err("out of range");
                let want = MeshErrorKind::IndexOutOfRange {
                    index: n as i64 + 5,
                    vertices: n,
                };
                assert_eq!(e.kind, want);
                let mut nan = mesh.clone();
                nan.vertices[n - 2][1] = f64::NAN;
                assert_eq!(validate(&nan, p).expect_err("NaN").kind, MeshErrorKind::NotFinite);
                let b = bounds(&mesh.vertices);
                for k in 0..3 {
                    let mut c: Vec<f64> = mesh.vertices.iter().map(|v| v[k]).collect();
                    c.sort_by(f64::total_cmp);
                    assert_eq!((b.lo[k], b.hi[k]), (c[0], c[n - 1]));
                }
            });
        }
    }

    /// Issue 13.7: a panic in a reader or in the healing fails that mesh, not the run.
    #[test]
    fn a_panic_becomes_the_meshs_error() {
        let p = Path::new("m.dae");
        let r: Result<(), MeshError> = catching_panics(p, || panic!("boom"));
        let e = r.unwrap_err();
        assert_eq!(e.kind, MeshErrorKind::Internal("boom".into()));
        assert!(e.to_string().starts_with("m.dae: internal error"));
        let r: Result<(), MeshError> = catching_panics(p, || panic!("{} {}", "formatted", 1));
        assert_eq!(
            r.unwrap_err().kind,
            MeshErrorKind::Internal("formatted 1".into())
        );
    }

    /// A welded mesh stays welded under a scale only when no two of its vertices can become one: the
    /// kept flag is checked against the scaled vertices' bits themselves (distinct, no −0.0), on f32
    /// coordinates packed as tightly as f32 allows (neighbouring values, ±0, tiny and huge ones).
    #[test]
    fn a_scale_keeps_a_mesh_welded_only_when_vertices_stay_distinct() {
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = || crate::xorshift(&mut rng);
        let mut coords: Vec<f32> = vec![0.0, -0.0, 1e-45, -1e-45, 3.0e38, f32::MIN_POSITIVE];
        for _ in 0..3000 {
            let x = f32::from_bits(next() as u32);
            if x.is_finite() {
                // A value and its neighbour: the closest two distinct f32 can be.
                coords.extend([x, f32::from_bits(x.to_bits() + 1)]);
            }
        }
        let all: Vec<[f64; 3]> = coords
            .chunks_exact(3)
            .map(|c| [0, 1, 2].map(|k| f64::from(c[k]) + 0.0))
            .collect();
        // Distinct vertices (as a welding reader leaves them).
        let mut seen = std::collections::HashSet::new();
        let vertices: Vec<[f64; 3]> = all
            .into_iter()
            .filter(|v| seen.insert(v.map(f64::to_bits)))
            .collect();
        let mesh = RawMesh {
            vertices,
            faces: Polygons::new(),
            notes: vec![],
            warnings: vec![],
            welded: true,
        };
        let p = Path::new("m.stl");
        for scale in [
            [0.001, -0.001, 0.001],
            [1.0, -1.0, 1.0],
            [1e-200, 7.3, -1e200],
            [0.1; 3],
        ] {
            let out = apply_scale(&mesh, scale, p).unwrap();
            assert!(out.welded, "{scale:?}");
            let bits: std::collections::HashSet<[u64; 3]> =
                out.vertices.iter().map(|v| v.map(f64::to_bits)).collect();
            assert_eq!(bits.len(), out.vertices.len(), "{scale:?}: merged");
            assert!(out
                .vertices
                .iter()
                .flatten()
                .all(|x| x.to_bits() != (-0.0f64).to_bits()));
        }
        // Coordinates that are not f32 values (a decimal OBJ) are welded again.
        let mut f64_mesh = mesh.clone();
        f64_mesh.vertices.push([0.1, 0.2, 0.3]);
        assert!(!apply_scale(&f64_mesh, [0.001; 3], p).unwrap().welded);
        assert!(apply_scale(&f64_mesh, [-1.0, 1.0, 1.0], p).unwrap().welded);
        // Beyond the bounded range a product may underflow: welded again.
        assert!(!apply_scale(&mesh, [1e-300, 1.0, 1.0], p).unwrap().welded);
    }
}
