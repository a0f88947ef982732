//! Binary STL records, welded a chunk at a time in parallel and joined across chunks.

use crate::mass::Polygons;
use crate::mesh::weld::VertexTable;
use crate::mesh::RawMesh;

pub(super) fn binary(bytes: &[u8], n: usize, header_count: Option<usize>) -> RawMesh {
    let mut reader = Binary::new(n, CHUNK, None);
    reader.feed(&bytes[84..84 + 50 * n]);
    reader.finish(header_count)
}

/// Chunks read and welded at a time: two per thread on two cores, 1.6 MB each.
pub(super) const PIECE: usize = 4;

/// A binary STL reader fed whole 50-byte records.
///
/// Records are welded in two steps. Each chunk of [`CHUNK`] records (fewer for [`read_split`](super::read_split)'s
/// tests) is welded on its own first, in parallel (rayon), into a table small enough for the L2
/// cache; the chunks' distinct vertices are then welded across chunks once the file is read
/// ([`crate::mesh::weld::join`]). A vertex is numbered where it first appears in the file either way, so
/// the result is the sequential weld's, bit for bit, for any number of threads; and the cross-chunk
/// weld sees each vertex about once instead of at each of its six or so corners.
pub(super) struct Binary {
    /// The chunks' distinct vertices, one chunk after the other.
    vertices: Vec<[f64; 3]>,
    /// Corners as indices into `vertices`.
    indices: Vec<u32>,
    /// Records in a chunk: [`CHUNK`], but for [`read_split`](super::read_split).
    chunk: usize,
    /// Runs of the cross-chunk join: `None` (the join's choice), but for [`read_split`](super::read_split).
    runs: Option<usize>,
}

/// Records welded on their own before the cross-chunk join: 16 Ki faces make about 8 Ki vertices, a
/// table of 128 KiB (in L2, so each insert is one probe; grouping inserts to overlap their misses,
/// which the one big table of all vertices needed, measured no faster here).
pub(super) const CHUNK: usize = 16 * 1024;

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
    pub(super) fn new(n: usize, chunk: usize, runs: Option<usize>) -> Self {
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
    pub(super) fn feed(&mut self, records: &[u8]) {
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

    pub(super) fn finish(mut self, header_count: Option<usize>) -> RawMesh {
        let n = self.indices.len() / 3;
        let vertices = crate::mesh::weld::join(self.vertices, &mut self.indices, self.runs);
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
