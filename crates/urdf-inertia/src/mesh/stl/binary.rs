//! Binary STL records, welded a chunk at a time in parallel and joined across chunks.

use crate::mass::Polygons;
use crate::mesh::weld::VertexTable;
use crate::mesh::RawMesh;
#[cfg(any(unix, windows))]
use std::{fs::File, io};

pub(super) fn binary(bytes: &[u8], n: usize, header_count: Option<usize>) -> RawMesh {
    let mut reader = Binary::new(n, CHUNK, None);
    reader.feed(&bytes[84..84 + 50 * n]);
    reader.finish(header_count)
}

/// Chunks read and welded at a time from a source without positioned reads: two per thread on two
/// cores, 1.6 MB each.
pub(super) const PIECE: usize = 4;

/// A binary STL reader fed whole 50-byte records.
///
/// Records are welded in two steps. Each chunk of [`CHUNK`] records (fewer for [`read_split`](super::read_split)'s
/// tests) is welded on its own first, in parallel (rayon), into a table small enough for the L2
/// cache; the chunks' distinct vertices are then welded across chunks once the file is read
/// ([`crate::mesh::weld::join_chunks`]). A vertex is numbered where it first appears in the file
/// either way, so the result is the sequential weld's, bit for bit, for any number of threads; and
/// the cross-chunk weld sees each vertex about once instead of at each of its six or so corners.
///
/// Each chunk writes where its results end up, so that no thread waits for a serial copy and the
/// pages are touched by the thread that fills them: its corners into its own part of one array made
/// for all of them (as indices into the chunk's vertices, which the join rebases), and its vertices
/// into its own region of one array of [`region`] vertices a chunk, in which the join then moves
/// the distinct ones together ([`crate::mesh::weld::join_in_place`]), so that no second array is
/// faulted in for them. A chunk with more vertices than its region (faces in no order, a soup of
/// unshared corners) keeps them in a list of its own, and the join copies them all out instead.
pub(super) struct Binary {
    /// Chunk `c`'s vertices from `c · region` on, unless they are in `overflow[c]`.
    vertices: Vec<[f64; 3]>,
    /// Each chunk's number of vertices.
    lens: Vec<usize>,
    /// Each chunk's vertices when they did not fit its region.
    overflow: Vec<Option<Vec<[f64; 3]>>>,
    /// Corners, each chunk's as indices into its own vertices until [`Binary::finish`].
    indices: Vec<u32>,
    /// Records in a chunk: [`CHUNK`], but for [`read_split`](super::read_split).
    chunk: usize,
    /// Runs of the cross-chunk join: `None` (the join's choice), but for [`read_split`](super::read_split).
    runs: Option<usize>,
}

/// Vertices a chunk of `chunk` records has room for in [`Binary`]'s array: a closed mesh has about
/// half as many vertices as faces, and a chunk repeats those on its border, a larger share the fewer
/// rows of a long strip of faces it holds (a torus of 10 M faces, five rows of 1,581 quads a chunk:
/// 0.6 vertices a face). Only the pages a chunk writes are touched, so room to spare costs address
/// space, not memory.
fn region(chunk: usize) -> usize {
    3 * chunk / 4 + 16
}

/// Records welded on their own before the cross-chunk join: 16 Ki faces make about 8 Ki vertices, a
/// table of 128 KiB (in L2, so each insert is one probe; grouping inserts to overlap their misses,
/// which the one big table of all vertices needed, measured no faster here).
pub(super) const CHUNK: usize = 16 * 1024;

/// Welds a chunk of records: its corners, as indices into its distinct vertices, go to `out` (three
/// per record), and its distinct vertices in order of first appearance to `room` when they fit
/// (their number is returned), in a list of their own when they do not. `table` is reused from
/// chunk to chunk.
fn weld_chunk(
    records: &[u8],
    table: &mut VertexTable,
    out: &mut [u32],
    room: &mut [[f64; 3]],
) -> (usize, Option<Vec<[f64; 3]>>) {
    table.clear(room.len());
    for (r, out) in records.chunks_exact(50).zip(out.chunks_exact_mut(3)) {
        // + 0.0 folds −0.0 into 0.0, so that both weld (`RawMesh::welded`).
        let f =
            |o: usize| f64::from(f32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]])) + 0.0;
        // Skip the normal (bytes 0..12); the corners follow.
        out[0] = table.insert([f(12), f(16), f(20)]);
        out[1] = table.insert([f(24), f(28), f(32)]);
        out[2] = table.insert([f(36), f(40), f(44)]);
    }
    let v = table.vertices();
    match room.get_mut(..v.len()) {
        Some(room) => {
            room.copy_from_slice(v);
            (v.len(), None)
        }
        None => (v.len(), Some(v.to_vec())),
    }
}

/// Fills `buf` from `file` at `offset` without moving a shared cursor, so that several threads read
/// their chunks at once.
#[cfg(unix)]
pub(super) fn read_exact_at(file: &File, buf: &mut [u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, offset)
}

/// Fills `buf` from `file` at `offset` (`seek_read` moves the cursor, which the threads do not use).
#[cfg(windows)]
pub(super) fn read_exact_at(file: &File, mut buf: &mut [u8], mut offset: u64) -> io::Result<()> {
    use std::os::windows::fs::FileExt;
    while !buf.is_empty() {
        match file.seek_read(buf, offset) {
            Ok(0) => return Err(io::ErrorKind::UnexpectedEof.into()),
            Ok(k) => {
                buf = &mut buf[k..];
                offset += k as u64;
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

impl Binary {
    pub(super) fn new(n: usize, chunk: usize, runs: Option<usize>) -> Self {
        let chunks = n.div_ceil(chunk.max(1));
        Binary {
            chunk,
            runs,
            // Zeroed memory from the allocator: fresh pages, faulted in by the threads that write
            // them, and a region's end that no vertex reaches is never touched.
            vertices: vec![[0.0; 3]; chunks * region(chunk)],
            lens: Vec::with_capacity(chunks),
            overflow: Vec::with_capacity(chunks),
            indices: vec![0; 3 * n],
        }
    }

    /// Welds whole records, in chunks on the pool.
    pub(super) fn feed(&mut self, records: &[u8]) {
        use rayon::prelude::*;
        let (chunk, done) = (self.chunk, self.lens.len());
        let corners = &mut self.indices[3 * chunk * done..][..3 * (records.len() / 50)];
        let rooms = &mut self.vertices[region(chunk) * done..];
        let welded: Vec<(usize, Option<Vec<[f64; 3]>>)> = crate::threads::install(|| {
            records
                .par_chunks(50 * chunk)
                .zip(corners.par_chunks_mut(3 * chunk))
                .zip(rooms.par_chunks_mut(region(chunk)))
                .map_init(VertexTable::default, |table, ((r, o), room)| {
                    weld_chunk(r, table, o, room)
                })
                .collect()
        });
        self.keep(welded);
    }

    fn keep(&mut self, welded: Vec<(usize, Option<Vec<[f64; 3]>>)>) {
        for (len, overflow) in welded {
            self.lens.push(len);
            self.overflow.push(overflow);
        }
    }

    /// Reads and welds all the records from `file`, the first at `offset`: each chunk is read by
    /// the thread that welds it, so reading overlaps welding. On a read error, the records before
    /// the first chunk that could not be read.
    #[cfg(any(unix, windows))]
    pub(super) fn read_at(&mut self, file: &File, offset: u64) -> Result<(), (usize, io::Error)> {
        use rayon::prelude::*;
        let chunk = self.chunk;
        let rooms = &mut self.vertices[..];
        let welded: Vec<io::Result<_>> = crate::threads::install(|| {
            self.indices
                .par_chunks_mut(3 * chunk)
                .zip(rooms.par_chunks_mut(region(chunk)))
                .enumerate()
                .map_init(
                    || (Vec::new(), VertexTable::default()),
                    |(buf, table), (c, (o, room))| {
                        buf.resize(50 * (o.len() / 3), 0);
                        read_exact_at(file, buf, offset + 50 * (chunk * c) as u64)?;
                        Ok(weld_chunk(buf, table, o, room))
                    },
                )
                .collect()
        });
        let welded = (welded.into_iter().enumerate())
            .map(|(c, w)| w.map_err(|e| (c * chunk, e)))
            .collect::<Result<Vec<_>, _>>()?;
        self.keep(welded);
        Ok(())
    }

    pub(super) fn finish(self, header_count: Option<usize>) -> RawMesh {
        let Binary {
            mut vertices,
            lens,
            overflow,
            mut indices,
            chunk,
            runs,
        } = self;
        let n = indices.len() / 3;
        let rebase = Some(3 * chunk);
        let room = region(chunk);
        let vertices = if overflow.iter().all(Option::is_none) {
            crate::mesh::weld::join_in_place(&mut vertices, room, &lens, &mut indices, rebase, runs);
            vertices
        } else {
            let blocks: Vec<&[[f64; 3]]> = (overflow.iter().zip(&lens).enumerate())
                .map(|(c, (o, &len))| match o {
                    Some(o) => o.as_slice(),
                    None => &vertices[c * room..][..len],
                })
                .collect();
            crate::mesh::weld::join_chunks(&blocks, &mut indices, rebase, runs)
        };
        let starts = crate::threads::install(|| {
            use rayon::prelude::*;
            (0..=n as u32).into_par_iter().map(|i| 3 * i).collect()
        });
        let mut notes = Vec::new();
        if let Some(h) = header_count {
            notes.push(format!(
                "binary STL header says {h} triangles; read the {n} whole triangles the file holds"
            ));
        }
        RawMesh {
            vertices,
            faces: Polygons { indices, starts },
            notes,
            warnings: Vec::new(),
            welded: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{parse, read_file, read_split, write_binary};
    use super::CHUNK;
    use crate::mesh::{MeshError, RawMesh};
    use std::path::Path;

    /// `n` triangles whose corners come from a pool of 600 points (so most repeat, within and across
    /// chunks), a few at −0.0, and one collapsed triangle.
    fn soup(n: usize) -> Vec<u8> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut points: Vec<[f64; 3]> = (0..600)
            .map(|_| [0; 3].map(|_| f64::from((crate::xorshift(&mut state) % 1000) as u32) * 0.5))
            .collect();
        points[7] = [-0.0, 1.0, 0.0];
        points[8] = [0.0, 1.0, 0.0];
        let mut triangles: Vec<[u32; 3]> = (0..n)
            .map(|_| [0; 3].map(|_| (crate::xorshift(&mut state) % 600) as u32))
            .collect();
        triangles[n / 2] = [3, 3, 4];
        write_binary(b"soup", &points, &triangles)
    }

    /// `got` is `want`, bit for bit (the stream tests' comparison).
    fn same(got: &Result<RawMesh, MeshError>, want: &RawMesh, what: &str) {
        crate::mesh::stl::tests::same(got, &Ok(want.clone()), what);
    }

    /// A file read a chunk at a time by the threads that weld it (positioned reads), and streamed
    /// through a reader, gives [`parse`]'s mesh bit for bit: chunks of one record to the default,
    /// runs forced or not, on a pool of one thread and of three. A file that is not a binary STL
    /// of the length its header says goes the streamed way from its first byte.
    #[test]
    fn positioned_reads_are_the_whole_parse() {
        let dir = tempfile::tempdir().expect("temp dir");
        let bytes = soup(5_000);
        let mut wrong_count = bytes.clone();
        wrong_count[80..84].copy_from_slice(&4_000u32.to_le_bytes());
        let ascii = super::super::write_ascii(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]]);
        for (name, bytes) in [("soup", &bytes), ("wrong count", &wrong_count), ("ascii", &ascii.into_bytes())] {
            let path = dir.path().join("t.stl");
            std::fs::write(&path, bytes).expect("write");
            let want = parse(bytes, &path).expect("parses");
            for threads in [1, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("pool");
                for (chunk, runs) in [(1, Some(1)), (7, Some(5)), (1_000, None), (CHUNK, None)] {
                    let what = format!("{name}: chunks of {chunk}, runs {runs:?}, {threads} threads");
                    let file = std::fs::File::open(&path).expect("open");
                    let len = bytes.len() as u64;
                    same(&pool.install(|| read_file(file, len, &path, chunk, runs)), &want, &what);
                    let streamed = pool.install(|| read_split(&bytes[..], len, &path, chunk, runs));
                    same(&streamed, &want, &format!("{what}, streamed"));
                }
            }
        }
    }

    /// A binary file that ends before the records its header and its length (as opened) promise,
    /// having shrunk while it was read, is an error naming the records read before the first chunk
    /// that could not be.
    #[test]
    fn a_file_that_shrank_while_read_is_truncated() {
        let dir = tempfile::tempdir().expect("temp dir");
        let bytes = soup(5_000);
        let path = dir.path().join("t.stl");
        std::fs::write(&path, &bytes[..84 + 50 * 2_500]).expect("write");
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let file = std::fs::File::open(&path).expect("open");
            let e = pool
                .install(|| read_file(file, bytes.len() as u64, Path::new("t.stl"), 1_000, None))
                .expect_err("truncated");
            let text = e.to_string();
            assert!(text.contains("t.stl"), "{text}");
            assert!(
                text.contains("binary STL of 5000 triangles ended after 2000 while it was read"),
                "{text}"
            );
        }
    }
}
