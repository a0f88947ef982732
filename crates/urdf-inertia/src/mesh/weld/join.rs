//! Welding vertices that repeat across chunks welded on their own, every pass in parallel.

use super::table::{hash, same_point};
use rayon::prelude::*;

/// Welds vertices that repeat across independently welded chunks: `vertices` are the chunks'
/// distinct vertices one chunk after the other, `indices` point into them. Returns the distinct
/// vertices in order of first appearance and rewrites `indices` to them: what one table fed the
/// vertices in order gives, bit for bit.
///
/// `runs` forces the number of runs (clamped to 1–256; see [`join_chunks`]), for tests and the
/// `stl_stream` fuzz target: the inputs they can afford have a few thousand vertices at most, one
/// run by the choice here.
pub fn join(vertices: Vec<[f64; 3]>, indices: &mut [u32], runs: Option<usize>) -> Vec<[f64; 3]> {
    let lens: Vec<usize> = vertices.chunks(BLOCK).map(<[_]>::len).collect();
    let mut vertices = vertices;
    join_in_place(&mut vertices, BLOCK, &lens, indices, None, runs);
    vertices
}

/// Vertices a block of [`join`]'s input, the unit of its parallel passes (a chunk's worth).
const BLOCK: usize = 1 << 13;

/// [`join`] of vertices given in blocks, one after the other, into a new list. With `rebase`
/// `Some(corners)`, the corners come in chunks of `corners`, chunk `c` pointing into block `c` (a
/// reader that welds chunks in parallel writes each chunk's corners in place, and this pass rebases
/// them); with `None`, into the blocks as one list.
///
/// One table over all vertices is what this replaces: once table and vertices outgrow the L3 cache
/// its inserts are DRAM and TLB misses (figures: docs/benchmarks.md, "Figures behind choices in the
/// code"). Here each block's vertices are first partitioned by the top bits of their hash into at
/// most 256 runs (8 bytes each: the hash's low half and the position), so each run is welded in its
/// own small table; a run, read block after block, keeps file order, so its first copy of a vertex
/// is the first in the file. Each vertex's number is then the count of first copies before it: one
/// count per block, then every block numbered on its own. Every pass runs a block or a run at a time
/// on the pool, and none depends on how the work is shared out: the result is the same bits for any
/// number of threads.
pub fn join_chunks(
    blocks: &[&[[f64; 3]]],
    indices: &mut [u32],
    rebase: Option<usize>,
    runs: Option<usize>,
) -> Vec<[f64; 3]> {
    let numbered = numbered(blocks, runs);
    let Numbered {
        first,
        bases,
        starts,
    } = &numbered;
    let mut out = vec![[0.0; 3]; starts[blocks.len()]];
    crate::threads::install(|| {
        split(&mut out, starts)
            .into_par_iter()
            .enumerate()
            .for_each(|(c, out)| {
                let first = &first[bases[c]..bases[c + 1]];
                let mut k = 0;
                for (&f, p) in first.iter().zip(blocks[c]) {
                    if f as usize == starts[c] + k {
                        out[k] = *p;
                        k += 1;
                    }
                }
            });
    });
    renumber(first, indices, rebase, bases);
    out
}

/// [`join_chunks`] of blocks held in `vertices` itself, block `c`'s `lens[c]` vertices (at most
/// `cap`) from `c · cap` on, welded in place: `vertices` becomes the distinct vertices. No memory is
/// taken for them beyond the blocks': each block moves its first copies to its front on the pool,
/// then the blocks move down one after the other (each to no later than where it is).
pub fn join_in_place(
    vertices: &mut Vec<[f64; 3]>,
    cap: usize,
    lens: &[usize],
    indices: &mut [u32],
    rebase: Option<usize>,
    runs: Option<usize>,
) {
    let cap = cap.max(1);
    debug_assert!(lens.iter().all(|&l| l <= cap));
    let blocks: Vec<&[[f64; 3]]> = (lens.iter().enumerate())
        .map(|(c, &l)| &vertices[c * cap..c * cap + l])
        .collect();
    let Numbered {
        first,
        bases,
        starts,
    } = numbered(&blocks, runs);
    drop(blocks);
    crate::threads::install(|| {
        vertices
            .par_chunks_mut(cap)
            .zip(lens)
            .enumerate()
            .for_each(|(c, (block, &len))| {
                let first = &first[bases[c]..bases[c] + len];
                let mut k = 0;
                for (i, &f) in first.iter().enumerate() {
                    if f as usize == starts[c] + k {
                        block[k] = block[i];
                        k += 1;
                    }
                }
            });
    });
    move_down(vertices, cap, &starts);
    vertices.truncate(starts[lens.len()]);
    renumber(&first, indices, rebase, &bases);
}

/// Moves each block's distinct vertices, the first `starts[c + 1] − starts[c]` from `c · cap`, down
/// to `starts[c]`: no later than `bases[c]` (the vertices before it), no later than `c · cap`, so
/// that blocks moved in order never overwrite one still to move. In waves on the pool: a wave from
/// the first block `a` still to move takes the blocks after it whose places all lie below `a · cap`,
/// where no block from `a` on has vertices left, so the wave's places and its vertices are all
/// apart and its blocks move at once. A block whose place meets its own vertices (the first few)
/// is a wave of its own. Each block lands where the moves in order put it.
fn move_down(vertices: &mut [[f64; 3]], cap: usize, starts: &[usize]) {
    let blocks = starts.len() - 1;
    let mut a = 0;
    crate::threads::install(|| {
        while a < blocks {
            if starts[a + 1] > a * cap {
                vertices.copy_within(a * cap..a * cap + starts[a + 1] - starts[a], starts[a]);
                a += 1;
                continue;
            }
            let b = (a + 1..=blocks)
                .find(|&b| b == blocks || starts[b + 1] > a * cap)
                .unwrap_or(blocks);
            let (places, from) = vertices.split_at_mut(a * cap);
            let mut rest = &mut places[starts[a]..starts[b]];
            let mut moves = Vec::with_capacity(b - a);
            for c in a..b {
                let (place, after) = rest.split_at_mut(starts[c + 1] - starts[c]);
                moves.push((place, &from[(c - a) * cap..][..starts[c + 1] - starts[c]]));
                rest = after;
            }
            moves
                .into_par_iter()
                .for_each(|(place, from)| place.copy_from_slice(from));
            a = b;
        }
    });
}

/// Each vertex's number among the distinct ones (`first`), where each block starts among all the
/// vertices (`bases`) and among the distinct ones (`starts`), both with the end.
struct Numbered {
    first: Vec<u32>,
    bases: Vec<usize>,
    starts: Vec<usize>,
}

fn numbered(blocks: &[&[[f64; 3]]], runs: Option<usize>) -> Numbered {
    let mut bases = Vec::with_capacity(blocks.len() + 1);
    bases.push(0usize);
    for b in blocks {
        bases.push(bases[bases.len() - 1] + b.len());
    }
    let n = bases[blocks.len()];
    debug_assert!(n < u32::MAX as usize, "positions fit 32 bits");
    // About 2 Ki vertices a run; at most 256 runs, each written as one stream.
    let runs = runs.map_or_else(
        || (n / 2048).next_power_of_two().clamp(1, 256),
        |r| r.clamp(1, 256),
    );
    crate::threads::install(|| {
        let parts: Vec<Part> = blocks
            .par_iter()
            .zip(&bases)
            .map(|(b, &base)| Part::new(b, base, runs))
            .collect();
        let firsts: Vec<Vec<u32>> = (0..runs)
            .into_par_iter()
            .map(|r| first_copies(r, &parts, blocks, &bases))
            .collect();
        let first = scatter(&parts, &firsts, &bases, n);
        drop(firsts);
        let (first, starts) = number(first, &bases);
        Numbered {
            first,
            bases,
            starts,
        }
    })
}

/// A block's entries (the hash's low half above the position), grouped by run, each run's in file
/// order.
struct Part {
    entries: Vec<u64>,
    /// Where each run's entries start, and the end.
    starts: Vec<u32>,
}

impl Part {
    fn new(block: &[[f64; 3]], base: usize, runs: usize) -> Part {
        let run_of = |h: u64| ((h >> 32) as usize * runs) >> 32;
        let hashes: Vec<u64> = block.iter().map(|v| hash(&v.map(f64::to_bits))).collect();
        let mut starts = vec![0u32; runs + 1];
        for &h in &hashes {
            starts[run_of(h) + 1] += 1;
        }
        for r in 0..runs {
            starts[r + 1] += starts[r];
        }
        let mut entries = vec![0u64; block.len()];
        let mut fill = starts.clone();
        for (i, &h) in hashes.iter().enumerate() {
            let r = run_of(h);
            entries[fill[r] as usize] = (h << 32) | (base + i) as u64;
            fill[r] += 1;
        }
        Part { entries, starts }
    }

    fn run(&self, r: usize) -> &[u64] {
        &self.entries[self.starts[r] as usize..self.starts[r + 1] as usize]
    }
}

/// For each entry of run `r`, block after block, the position of the first entry with the same
/// vertex.
fn first_copies(r: usize, parts: &[Part], blocks: &[&[[f64; 3]]], bases: &[usize]) -> Vec<u32> {
    let len: usize = parts.iter().map(|p| p.run(r).len()).sum();
    let size = (2 * len).max(16).next_power_of_two();
    let mask = size - 1;
    // An entry's position is below `u32::MAX`, so no entry is all ones.
    let mut slots = vec![u64::MAX; size];
    let vertex = |p: usize| {
        // The last block starting at or before `p` (empty blocks start where the next does).
        let c = bases.partition_point(|&b| b <= p) - 1;
        &blocks[c][p - bases[c]]
    };
    let mut out = Vec::with_capacity(len);
    for (part, (block, &base)) in parts.iter().zip(blocks.iter().zip(bases)) {
        for &e in part.run(r) {
            let p = e as u32 as usize;
            // Read only when a tag matches (a copy, nearly always): a vertex read for every entry
            // is a cache miss for every entry once the vertices outgrow the cache.
            let point = || &block[p - base];
            // The hash's low half picks the slot (its top bits picked the run).
            let mut s = (e >> 32) as usize & mask;
            loop {
                match slots[s] {
                    u64::MAX => {
                        slots[s] = e;
                        out.push(p as u32);
                        break;
                    }
                    f if f >> 32 == e >> 32 && same_point(vertex(f as u32 as usize), point()) => {
                        out.push(f as u32);
                        break;
                    }
                    _ => s = (s + 1) & mask,
                }
            }
        }
    }
    out
}

/// Each vertex's first copy, in file order, from the runs' answers: each block fills its own part,
/// taking its entries' answers from where its entries sit in each run.
fn scatter(parts: &[Part], firsts: &[Vec<u32>], bases: &[usize], n: usize) -> Vec<u32> {
    let runs = firsts.len();
    // Where each block's entries start in each run's answers.
    let mut at = vec![0usize; runs * parts.len()];
    for r in 0..runs {
        let mut o = 0;
        for (c, part) in parts.iter().enumerate() {
            at[c * runs + r] = o;
            o += part.run(r).len();
        }
    }
    let mut first = vec![0u32; n];
    let slices = split(&mut first, bases);
    slices
        .into_par_iter()
        .zip(parts)
        .enumerate()
        .for_each(|(c, (out, part))| {
            let base = bases[c];
            for (r, answers) in firsts.iter().enumerate() {
                let entries = part.run(r);
                let answers = &answers[at[c * runs + r]..][..entries.len()];
                for (&e, &f) in entries.iter().zip(answers) {
                    out[e as u32 as usize - base] = f;
                }
            }
        });
    first
}

/// `first` turned from each vertex's first copy into the number of that copy among the first
/// copies, and where each block's first copies start among them (with the end): each block counts
/// its first copies, and with those counts summed in order, numbers its own.
fn number(mut first: Vec<u32>, bases: &[usize]) -> (Vec<u32>, Vec<usize>) {
    let blocks = bases.len() - 1;
    let counts: Vec<usize> = (0..blocks)
        .into_par_iter()
        .map(|c| {
            let base = bases[c];
            let f = &first[base..bases[c + 1]];
            f.iter().enumerate().filter(|&(i, &f)| f as usize == base + i).count()
        })
        .collect();
    let mut starts = Vec::with_capacity(blocks + 1);
    starts.push(0usize);
    for c in &counts {
        starts.push(starts[starts.len() - 1] + c);
    }
    // A first copy's number; the others' are read from their first copy's below.
    let mut numbers = vec![0u32; first.len()];
    split(&mut numbers, bases)
        .into_par_iter()
        .enumerate()
        .for_each(|(c, numbers)| {
            let (base, mut k) = (bases[c], 0);
            for (i, &f) in first[base..bases[c + 1]].iter().enumerate() {
                if f as usize == base + i {
                    numbers[i] = (starts[c] + k) as u32;
                    k += 1;
                }
            }
        });
    first.par_chunks_mut(1 << 16).for_each(|c| {
        for f in c {
            *f = numbers[*f as usize];
        }
    });
    (first, starts)
}

/// `v` cut at `bounds` (ascending, from 0 to `v.len()`) into consecutive slices.
fn split<'a, T>(mut v: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(bounds.len().saturating_sub(1));
    for w in bounds.windows(2) {
        let (head, tail) = v.split_at_mut(w[1] - w[0]);
        out.push(head);
        v = tail;
    }
    out
}

/// Each corner becomes its vertex's number: corner `i` of chunk `c` (chunks of `corners`) is
/// `first[bases[c] + i]` with `rebase` `Some(corners)`, `first[i]` with `None`. The corners, 5 or 6 a
/// vertex, are renumbered on the pool when it has more than one thread (on one, rayon's split costs
/// more instructions than the plain loop).
fn renumber(first: &[u32], indices: &mut [u32], rebase: Option<usize>, bases: &[usize]) {
    let renumber = |c: &mut [u32], base: usize| {
        let first = &first[base..];
        for i in c {
            *i = first[*i as usize];
        }
    };
    let corners = rebase.unwrap_or(indices.len()).max(1);
    let bases = if rebase.is_some() { bases } else { &[0] };
    debug_assert!(indices.len().div_ceil(corners) <= bases.len());
    crate::threads::install(|| {
        if rayon::current_num_threads() < 2 {
            for (c, &b) in indices.chunks_mut(corners).zip(bases) {
                renumber(c, b);
            }
        } else {
            indices
                .par_chunks_mut(corners)
                .zip(bases)
                .for_each(|(c, &b)| c.par_chunks_mut(1 << 16).for_each(|s| renumber(s, b)));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::weld::VertexTable;

    /// Chunks welded on their own and then joined number every vertex as one weld of all corners in
    /// order does: corners drawn from a small pool (so most repeat, within and across chunks), in
    /// chunks of several sizes, from one run of entries to the most, with run counts forced (powers
    /// of two or not) on the smaller cases; the chunks' vertices given as one list ([`join`], cut in
    /// blocks of its own, welded in place), as the chunks themselves with their corners local
    /// ([`join_chunks`]) and in regions of one array ([`join_in_place`]), on a pool of one thread
    /// and of three.
    #[test]
    fn joined_chunks_are_the_sequential_weld() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let pool: Vec<[f64; 3]> = (0..40_000)
            .map(|_| [0; 3].map(|_| f64::from(crate::xorshift(&mut state) as u32 as f32) * 1e-6))
            .collect();
        let cases: [(usize, usize, &[Option<usize>]); 4] = [
            (300, 7, &[None, Some(1), Some(3), Some(256)]),
            (50_000, 1_000, &[None, Some(5), Some(256)]),
            (200_000, 30_000, &[None, Some(7)]),
            (1_500_000, 65_536, &[None]),
        ];
        let pools = [1, 3].map(|t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .expect("pool")
        });
        let bits = |v: &[[f64; 3]]| v.iter().map(|p| p.map(f64::to_bits)).collect::<Vec<_>>();
        for (corners, chunk, runs) in cases {
            let picks: Vec<[f64; 3]> = (0..corners)
                .map(|_| pool[(crate::xorshift(&mut state) % pool.len() as u64) as usize])
                .collect();
            let mut reference = VertexTable::with_capacity(16);
            let want: Vec<u32> = picks.iter().map(|&p| reference.insert(p)).collect();
            let reference = bits(&reference.into_vertices());
            // Each chunk welded on its own: its vertices, and its corners local to them.
            let (mut chunks, mut local) = (Vec::new(), Vec::new());
            for c in picks.chunks(chunk) {
                let mut table = VertexTable::with_capacity(16);
                local.extend(c.iter().map(|&p| table.insert(p)));
                chunks.push(table.into_vertices());
            }
            let blocks: Vec<&[[f64; 3]]> = chunks.iter().map(Vec::as_slice).collect();
            for &runs in runs {
                for p in &pools {
                    let case = format!(
                        "{corners} corners in chunks of {chunk}, runs {runs:?}, {} threads",
                        p.current_num_threads()
                    );
                    let mut indices = local.clone();
                    let joined = p.install(|| join_chunks(&blocks, &mut indices, Some(chunk), runs));
                    assert_eq!(indices, want, "{case}, in chunks");
                    assert_eq!(bits(&joined), reference, "{case}, in chunks");
                    // In regions of one array, a little larger than the largest chunk.
                    let cap = blocks.iter().map(|b| b.len()).max().unwrap_or(0) + 3;
                    let mut regions = vec![[f64::NAN; 3]; cap * blocks.len()];
                    for (r, b) in regions.chunks_mut(cap).zip(&blocks) {
                        r[..b.len()].copy_from_slice(b);
                    }
                    let lens: Vec<usize> = blocks.iter().map(|b| b.len()).collect();
                    let mut indices = local.clone();
                    p.install(|| {
                        join_in_place(&mut regions, cap, &lens, &mut indices, Some(chunk), runs);
                    });
                    assert_eq!(indices, want, "{case}, in place");
                    assert_eq!(bits(&regions), reference, "{case}, in place");
                    let mut base = 0;
                    let mut indices = local.clone();
                    for (c, b) in indices.chunks_mut(chunk).zip(&blocks) {
                        for i in c.iter_mut() {
                            *i += base;
                        }
                        base += b.len() as u32;
                    }
                    let joined = p.install(|| join(chunks.concat(), &mut indices, runs));
                    assert_eq!(indices, want, "{case}, as one list");
                    assert_eq!(bits(&joined), reference, "{case}, as one list");
                }
            }
        }
    }
}
