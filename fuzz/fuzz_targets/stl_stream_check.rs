//! The `stl_stream` target's check, one copy for the target and for `tests/regression.rs`
//! (`fuzz_seeds_replay`, `fuzz_corpus_replay`), which includes this file.
//!
//! The streaming binary STL reader welds chunks of 16 Ki records on their own and joins them in up
//! to 256 runs; an input of 64 KiB (at most 1,309 records) would reach one chunk and one run. Here
//! the input picks a chunk of 1 to 64 records and 1 to 256 runs, so every input crosses chunk,
//! piece and run borders, and the result must be `stl::parse`'s bit for bit (which welds an input
//! this small in one table, the sequential weld), on a pool of 1 thread and of 2.

use std::path::Path;
use std::sync::LazyLock;
use urdf_inertia::mesh::{stl, MeshError, RawMesh};

/// Built once: a pool per input would cost more than the input.
static POOLS: LazyLock<[rayon::ThreadPool; 2]> = LazyLock::new(|| {
    [1, 2].map(|threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("rayon pool")
    })
});

/// Byte 0 picks the chunk (1 + b % 64 records), byte 1 the runs (1 + b), byte 2 whether the rest's
/// header is made to fit: its count set to the whole records the rest holds and a partial record
/// cut, unless the byte's low three bits are 0, so that 7 inputs in 8 take the streaming path and
/// the others test which inputs fall back to reading whole.
pub fn check(data: &[u8]) -> Result<(), String> {
    let [c, r, fit, ..] = *data else {
        return Ok(());
    };
    let (chunk, runs) = (1 + usize::from(c) % 64, 1 + usize::from(r));
    let mut bytes = data[3..].to_vec();
    if fit & 7 != 0 && bytes.len() >= 84 + 50 {
        let m = (bytes.len() - 84) / 50;
        bytes.truncate(84 + 50 * m);
        bytes[80..84].copy_from_slice(&(m as u32).to_le_bytes());
    }
    let path = Path::new("/nonexistent-fuzz-dir/fuzz.stl");
    let want = stl::parse(&bytes, path);
    for pool in POOLS.iter() {
        let got = pool
            .install(|| stl::read_split(&bytes[..], bytes.len() as u64, path, chunk, Some(runs)));
        same(&got, &want).map_err(|e| {
            format!(
                "streamed in chunks of {chunk} records, {runs} runs, {} thread(s), against parse: {e}",
                pool.current_num_threads()
            )
        })?;
    }
    Ok(())
}

/// Equal in every field, vertices by their bits (NaN and −0.0 included); errors equal when both fail.
fn same(got: &Result<RawMesh, MeshError>, want: &Result<RawMesh, MeshError>) -> Result<(), String> {
    let (got, want) = match (got, want) {
        (Ok(g), Ok(w)) => (g, w),
        (Err(g), Err(w)) if g == w => return Ok(()),
        (g, w) => return Err(format!("got {}, want {}", outcome(g), outcome(w))),
    };
    // Destructured, so that a field added to RawMesh must be compared here too.
    let RawMesh {
        vertices,
        faces,
        notes,
        warnings,
        welded,
    } = got;
    let bits = |v: &[[f64; 3]]| v.iter().map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
    if bits(vertices) != bits(&want.vertices) {
        let at = (vertices.iter().zip(&want.vertices))
            .position(|(a, b)| a.map(f64::to_bits) != b.map(f64::to_bits));
        return Err(format!(
            "vertices differ ({} against {}, first at {at:?})",
            vertices.len(),
            want.vertices.len()
        ));
    }
    if faces.indices != want.faces.indices || faces.starts != want.faces.starts {
        let at = (faces.indices.iter().zip(&want.faces.indices)).position(|(a, b)| a != b);
        return Err(format!(
            "faces differ ({} against {} corners, first at {at:?})",
            faces.indices.len(),
            want.faces.indices.len()
        ));
    }
    if (notes, warnings, welded) != (&want.notes, &want.warnings, &want.welded) {
        return Err(format!(
            "notes, warnings or welded differ: {:?} against {:?}",
            (notes, warnings, welded),
            (&want.notes, &want.warnings, &want.welded)
        ));
    }
    Ok(())
}

fn outcome(r: &Result<RawMesh, MeshError>) -> String {
    match r {
        Ok(m) => format!("a mesh of {} faces", m.faces.len()),
        Err(e) => format!("error `{e}`"),
    }
}
