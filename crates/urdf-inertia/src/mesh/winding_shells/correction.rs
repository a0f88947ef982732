//! Closed shells that touch or cut each other, decided face by face.
//!
//! The solid's integral is a sum over faces: across a face the winding number w jumps by one, from
//! W in front of it to W + 1 behind, so a piece of face bounds Ω = {|w| ≥ 1} outward when only the
//! back is in Ω, inward when only the front is, and not at all when both or neither are. W is
//! constant on a piece of face that no other triangle meets, so one exact ray (`orient3d` crossings)
//! decides it. A triangle that another one cuts is split in four, again and again, and its pieces
//! that no triangle meets any more are decided the same way; the pieces still cut when the work or
//! the wanted bound is reached keep the orientation the shells' classification gave, and each adds
//! the cone it spans from the surface's box centre (the volume a wrong orientation can change) to
//! the bound, twice when it may count twice.

use super::bvh::Bvh;
use super::cells::{area, cells, centroid, largest_coordinate, leaves_whole, overhang, split, CellWork, Cut, CutPlane};
use super::grid::{crossing, Corners, Crossing, Grid, Plane, Seen};
use super::{corners_touch, edge_meets, in_order, line_passes, overlap, EdgeUse, LinePass};
use crate::geometry::{cross, dot, norm, sub, Aabb};
use crate::mass::Polygons;
use robust::{orient2d, Coord};
use std::cell::RefCell;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::ops::Range;

/// Splits (one piece into four) beyond which the pieces still cut are bounded, not split.
const MAX_SPLITS: usize = 20_000;

/// The blockers of the pieces split (each split asks each of the four children which of its
/// piece's blockers meet it, then cuts the child along them) beyond which the pieces still cut
/// are bounded, not split: about 0.7–1 µs each. Tetrahedra piled on one another (250 of them, each
/// face blocked by hundreds of others, coplanar along two planes) spent 8 M of them in 20,000
/// splits, 6–8 s for 1,000 triangles (3,000 tetrahedra: 148 s); the most a mesh of the corpus
/// needs is 1.2 M (fourier gr1t1 `head_pitch_link.STL`, at the split limit; the next, 54 k).
const MAX_SPLIT_BLOCKERS: usize = 2_000_000;

/// Pieces that more planes than this would cut (a triangle's, or a coplanar triangle's three edges)
/// are split in four first.
const MAX_CUTS: usize = 40;

/// Pairs of triangles whose grown boxes meet ([`Faces::all_blockers`]) beyond which none is cut:
/// each triangle is left as classified, what it can change in the bound. 3,000 tetrahedra piled on
/// one another (12,000 triangles, about 70 M such pairs) took 17 s and 1.2 GB; the most a mesh
/// of the corpus asks is far below.
pub(crate) const MAX_MEETING: usize = 20_000_000;

/// Pairs that [`Faces::near_groups`] may add beyond which none is cut (as past [`MAX_MEETING`]):
/// a group of triangles within [`NEAR`] of one plane pairs every two whose boxes come near, which
/// under two fans of triangles about one centre is every two. Each pair is 16 bytes; the most a mesh
/// of the corpus adds is far below.
const MAX_GROUPED: usize = 2_000_000;

/// [`Grid::crowding`] beyond which [`Faces::all_blockers`] takes its pairs from a tree, not from the
/// grid's queries: each triangle's query reads every entry of the cells its box covers, so their
/// cost is about the sum of the cells' entries squared. Tetrahedra piled on one another (1,000 of
/// them, 4,000 triangles over one region) spent 17 s in those queries.
const CROWDED_GRID: u64 = 50_000_000;

/// A triangle whose plane is within this share of the diagonal of a piece everywhere on it is taken
/// as lying in the piece's plane.
const NEAR: f64 = 1e-7;

/// Seeds of the weights of the last points [`Faces::decide_where`] tries in a piece.
const GENERIC: [f64; 2] = [0.137, 0.571];

/// Grid cells beyond which a segment is not tested for a join ([`Faces::segment_count`] answers no,
/// and rays decide): a long segment's box crosses cells of triangles far from it, and the test read
/// more entries than the rays it saves (UR5 `visual/upperarm.dae`: 6,009 M instructions unlimited,
/// 4,355 M at 8 cells, 4,279 M at 2, 4,327 M at 1; centauro's wheel 4,315, 4,268, 4,236 and 4,258 M).
const MAX_SEGMENT_CELLS: usize = 2;

/// Rays tried on a patch of uncut faces before it is split like a cut one.
const MAX_TRIES: usize = 8;

/// A face's normal component along a second ray's axis, as a share of its length, from which that
/// ray checks the first (below it, the ray runs so close to the face's plane that a centre rounded
/// a few ulps behind the face could pass behind a neighbour; then one ray decides).
const SECOND_RAY: f64 = 0.3;

/// The faces of the shells that touch or cut each other, as far as the winding number decides them.
pub(super) struct Resolved {
    /// The triangles and pieces, oriented as they bound Ω (the undecided ones as classified).
    pub(super) faces: Polygons,
    /// The pieces' new corners, numbered on from the surface's vertices.
    pub(super) vertices: Vec<[f64; 3]>,
    /// The volume the undecided pieces can change, m³ (cones about `centre`).
    pub(super) bound: f64,
    /// The volume the rounding of the decided pieces' corners can change, m³ ([`Faces::moved`]).
    pub(super) rounding: f64,
    /// Triangles that other triangles cut (split into pieces).
    pub(super) cut: usize,
    /// Whether every triangle was left undecided, more than [`MAX_MEETING`] pairs of them meeting.
    pub(super) crowded: bool,
    /// Whether some face's orientation differs from the classification's.
    pub(super) changed: bool,
    /// Pieces decided from a neighbouring triangle's rays across an edge ([`Faces::joined_across`]).
    pub(super) joined_across: usize,
    /// Pieces decided by a join whose segment passed through triangles ([`Faces::segment_count`]).
    pub(super) joins_counted: usize,
    /// Per triangle: how far the corners of its emitted pieces may lie from the exact pieces'
    /// (rounded cut points and midpoints), m, and the area of the bands about its cuts, m²
    /// ([`Faces::moved`]).
    moved: Vec<(f64, f64)>,
}

/// A piece of triangle `t` waiting to be decided: the volume it may change, its corners and the
/// triangles that may meet it.
struct Piece {
    delta: f64,
    corners: Corners,
    t: u32,
    blockers: Vec<Blocker>,
    /// How far its corners may lie from the points they stand for (midpoints of splits, rounded), m.
    slack: f64,
}

/// A triangle that may meet a piece of triangle `t`: whether it lies exactly in `t`'s plane (an
/// exact zero is orient3d's most expensive answer), and whether it is taken as in it though not
/// exactly ([`Faces::blocker`], [`Faces::near_groups`]). Both are asked once per pair, before the
/// first cut, and carried by the pieces split from that piece, which would ask again for each
/// blocker (14 times per pair on a real gripper with coincident shells). A table of the pairs cost
/// the cut a cache miss per blocker (docs/benchmarks.md, "Fewer cache misses and fewer tests").
#[derive(Clone, Copy)]
struct Blocker {
    u: u32,
    in_plane: bool,
    near: bool,
}

impl PartialEq for Piece {
    fn eq(&self, other: &Self) -> bool {
        self.delta.total_cmp(&other.delta) == Ordering::Equal
    }
}
impl Eq for Piece {}
impl PartialOrd for Piece {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Piece {
    fn cmp(&self, other: &Self) -> Ordering {
        self.delta.total_cmp(&other.delta)
    }
}

/// The triangles and what the decision needs about them.
struct Faces<'a> {
    vertices: &'a [[f64; 3]],
    tris: &'a [[u32; 3]],
    /// The orientation the classification gave each triangle's shell: 1, −1 (turned) or 0 (dropped).
    sign: &'a [i64],
    corners: Vec<Corners>,
    /// Each triangle's plane, for the sides of its neighbours' corners.
    planes: Vec<Plane>,
    grid: Grid,
    centre: [f64; 3],
    /// Distances below this are not trusted to f64 plane tests.
    margin: f64,
    /// Per triangle: the last of its pieces decided at the first try, and the rays' count in front
    /// of it there ([`Faces::decide_linked`]).
    origins: RefCell<Vec<Option<(Origin, i64)>>>,
    /// The triangles near a ray's start or a join's segment ([`Faces::before`], [`Faces::segment_count`]), kept between calls.
    scratch: RefCell<Vec<u32>>,
    /// Whether every edge of the triangles is used as often one way as the other: a closed
    /// cycle, on which [`Faces::joined`] holds.
    closed: bool,
    /// Per triangle and edge (corner k to the next): the triangle on the other side when exactly
    /// two use the edge, one each way ([`Faces::joined_across`]); `u32::MAX` otherwise.
    across: Vec<[u32; 3]>,
    /// Per triangle and edge (corner k to the next): the one other triangle that uses the edge
    /// (either way), [`ALONE`] when none does, [`SHARED`] when more do ([`Faces::seam`]); made
    /// from `uses` when a seam is first asked (most surfaces have no coplanar triangles).
    pairs: std::cell::OnceCell<Vec<[u32; 3]>>,
    /// Every use of an edge by the triangles, sorted by edge ([`super::edge_uses`]).
    uses: &'a [EdgeUse],
    /// Whether pieces take decisions from other pieces' rays ([`Faces::decide_linked`]).
    joins: bool,
    /// Pieces decided by [`Faces::joined_across`], and joins that counted triangles passed through.
    joins_across: std::cell::Cell<usize>,
    joins_counted: std::cell::Cell<usize>,
    /// [`Faces::cut`]'s lists, kept between calls: made afresh, their allocations and growth were
    /// about a tenth of the instructions of a mesh of coincident shells (centauro's
    /// `mesh_wheel23.stl`: 0.49 M allocations and 0.22 M reallocations for 34.9 k cuts).
    cut_work: RefCell<CutWork>,
}

/// The lists a cut fills and empties (see [`Faces::cut_work`]).
#[derive(Default)]
struct CutWork {
    planes: Vec<Cut>,
    coplanar: Vec<Coplanar>,
    /// Per coplanar triangle, whether its edges may be seams ([`Faces::seam_sides`]).
    sides: Vec<bool>,
    /// Per triangle, its place in `coplanar` plus one, 0 when it is not there (set during a cut).
    slot: Vec<u32>,
    /// The coplanar triangles' edges that are not seams ([`Faces::seam`]): their place in
    /// `coplanar` and the edge. Those that cross the piece join `planes` as cuts.
    edges: Vec<(u32, u8)>,
    crossing: Vec<usize>,
    cells: CellWork,
}

/// Decides the triangles `tris` (closed shells whose pairs the classification left open; `sign` per
/// triangle) until the pieces left undecided change at most `target` m³, or the work is spent.
/// The triangles of each range of `sealed` are a shell of their own whose every edge two of its
/// triangles share with opposite directions: a shell that [`embedded`] certifies is not searched
/// for pairs of its own triangles that meet, as none do.
pub(super) fn resolve(
    vertices: &[[f64; 3]],
    tris: &[[u32; 3]],
    sign: &[i64],
    sealed: &[Range<usize>],
    centre: [f64; 3],
    target: f64,
) -> Resolved {
    resolve_with(vertices, tris, sign, (centre, target), (true, CROWDED_GRID, MAX_GROUPED), sealed)
}

/// Whether the triangles of a shell (every edge shared by two of them with opposite directions)
/// meet one another only where they share a corner or an edge, certified exactly: some point `c`
/// (the mean of the corners, or one of two points near it) lies strictly on one side of every
/// triangle's plane, the same side for all (`orient3d`), and one axis-parallel ray from `c`
/// crosses exactly one triangle, through its interior ([`crossing`], exact).
/// Then the shell seen from `c` covers the sphere of directions once (the degree of the radial
/// projection is the one crossing, and no triangle is seen edge-on or from behind), so two of its
/// triangles that met elsewhere than at what they share would cover an open set of directions
/// twice: a point of one triangle inside another, or on an edge other than a shared one, puts the
/// other in front of the triangles around that point, whose directions surround it. Convex shells
/// and shells star-shaped about their mean corner pass; others (and rays through an edge on all
/// three axes) are not certified, and keep the search.
fn embedded(corners: &[Corners], planes: &[Plane]) -> bool {
    if corners.len() < 4 {
        return false;
    }
    let mut sum = [0.0; 3];
    let mut b = Aabb::EMPTY;
    for p in corners.iter().flatten() {
        sum = in_order(|k| sum[k] + p[k]);
        b.add(*p);
    }
    let mean = sum.map(|x| x / (3 * corners.len()) as f64);
    let extent = b.extent();
    // The mean, then two points a little off it in no special direction: a box's mean sees the
    // middle of each side, on the diagonal its two triangles share, along all three axes.
    for shift in [[0.0; 3], [0.0137, 0.0291, 0.0071], [-0.0219, 0.0113, 0.0257]] {
        let c = in_order(|k| mean[k] + shift[k] * extent[k]);
        if !c.iter().all(|x| x.is_finite()) {
            return false;
        }
        let first = planes[0].side(c);
        if first == 0.0 || !planes.iter().all(|p| p.side(c) * first.signum() > 0.0) {
            continue;
        }
        for axis in 0..3 {
            let mut e = c;
            e[axis] = b.hi[axis] + b.hi[axis].abs() + 1.0;
            if !e[axis].is_finite() {
                return false;
            }
            if let Some(hits) = hits(c, e, axis, corners, planes) {
                return hits == 1;
            }
        }
    }
    false
}

/// The triangles that the segment `s e` along `axis` crosses through their interiors, or `None`
/// when it touches one's edge, corner or plane.
fn hits(s: [f64; 3], e: [f64; 3], axis: usize, corners: &[Corners], planes: &[Plane]) -> Option<usize> {
    let mut hits = 0;
    for (t, plane) in corners.iter().zip(planes) {
        match crossing(s, e, axis, t, plane) {
            Crossing::Miss => {}
            Crossing::Through(_) => hits += 1,
            Crossing::Degenerate => return None,
        }
    }
    Some(hits)
}

/// Per triangle: the end of its range of `sealed` when [`embedded`] certifies it, else 0.
fn certified_ends(corners: &[Corners], planes: &[Plane], sealed: &[Range<usize>]) -> Vec<u32> {
    let mut end = vec![0u32; corners.len()];
    for r in sealed {
        if embedded(&corners[r.clone()], &planes[r.clone()]) {
            end[r.clone()].fill(r.end as u32);
        }
    }
    end
}

/// [`resolve`], deciding pieces from other pieces' rays ([`Faces::decide_linked`]) when `joins`, and
/// finding the pairs of triangles that meet from a tree past `crowded` ([`Faces::all_blockers`]).
fn resolve_with(
    vertices: &[[f64; 3]],
    tris: &[[u32; 3]],
    sign: &[i64],
    (centre, target): ([f64; 3], f64),
    (joins, crowded, grouped): (bool, u64, usize),
    sealed: &[Range<usize>],
) -> Resolved {
    let corners: Vec<Corners> = tris
        .iter()
        .map(|t| t.map(|i| vertices[i as usize]))
        .collect();
    let boxes: Vec<Aabb> = corners.iter().map(|c| Aabb::of(*c)).collect();
    // Each triangle in the cells it may meet, not in every cell of its box: CAD fans' long
    // slivers slant across their boxes (UR5 `visual/upperarm.dae`: 4,830 M → 3,274 M instructions).
    let grid = Grid::of_triangles(&boxes, &corners);
    let margin = 1e-12 * grid.bounds.diagonal();
    let planes: Vec<Plane> = corners.iter().map(Plane::new).collect();
    let free = certified_ends(&corners, &planes, sealed);
    let numbered = (0..tris.len()).map(|i| (i as u32, &tris[i][..]));
    let uses = super::edge_uses(vertices.len(), &numbered, None);
    let closed = balanced(&uses);
    let across = if joins {
        across(tris, &uses)
    } else {
        vec![[u32::MAX; 3]; tris.len()]
    };
    let f = Faces {
        vertices,
        tris,
        sign,
        corners,
        planes,
        grid,
        centre,
        margin,
        origins: RefCell::new(vec![None; tris.len()]),
        scratch: RefCell::new(Vec::new()),
        closed,
        across,
        pairs: std::cell::OnceCell::new(),
        uses: &uses,
        joins,
        joins_across: std::cell::Cell::new(0),
        joins_counted: std::cell::Cell::new(0),
        cut_work: RefCell::new(CutWork::default()),
    };
    let mut seen = Seen::new(tris.len());
    let blockers = f.all_blockers((&boxes, &free), crowded, &mut seen);
    let cut = blockers.as_ref().map_or(0, |b| b.iter().filter(|b| !b.is_empty()).count());
    let lists = blockers.and_then(|b| f.blocker_lists(b, &boxes, grouped));
    let mut out = Resolved {
        faces: Polygons::new(),
        vertices: Vec::new(),
        bound: 0.0,
        rounding: 0.0,
        cut,
        crowded: lists.is_none(),
        changed: false,
        joined_across: 0,
        joins_counted: 0,
        moved: vec![(0.0, 0.0); tris.len()],
    };
    let Some(lists) = lists else {
        // Each triangle as classified, the most it can change in the bound (as the pieces left
        // when the splits run out).
        for t in 0..tris.len() {
            out.bound += f.delta(&f.corners[t], t as u32);
            f.emit_whole(t as u32, sign[t], &mut out);
        }
        return out;
    };
    let mut heap = BinaryHeap::new();
    f.patches((&lists, &uses), &mut seen, &mut out, &mut heap);
    for (t, b) in lists.into_iter().enumerate() {
        let Some(mut b) = b else { continue };
        if !f.cut(&f.corners[t], (t as u32, 0.0), &mut b, &mut seen, &mut out) {
            heap.push(f.piece(f.corners[t], t as u32, b, 0.0));
        }
    }
    f.refine(heap, target, &mut seen, &mut out);
    out.joined_across = f.joins_across.get();
    out.joins_counted = f.joins_counted.get();
    out.rounding = f.moved(&out.moved);
    out
}

impl Faces<'_> {
    /// Each triangle's blockers as the cut takes them ([`Faces::blocker`], [`Faces::near_groups`]),
    /// `None` for a triangle no other may meet; `None` in all when the groups would add more than
    /// `budget` pairs.
    fn blocker_lists(&self, blockers: Vec<Vec<u32>>, boxes: &[Aabb], budget: usize) -> Option<Vec<Option<Vec<Blocker>>>> {
        let mut flat: Option<Vec<bool>> = None;
        let mut lists: Vec<Option<Vec<Blocker>>> = Vec::with_capacity(blockers.len());
        for (t, b) in blockers.into_iter().enumerate() {
            // The triangles others may meet are cut, even where every blocker is flat.
            if b.is_empty() {
                lists.push(None);
                continue;
            }
            // A triangle with collinear corners (exactly) bounds no area: the winding number does
            // not jump across it, so it cuts nothing. Kept, its plane (undefined: every point lies
            // in it) left every cell near it undecided (robosuite b1's `calf.obj`: a zero-area
            // sliver across eleven faces, an estimate of 1.3e-1 against 8.4e-6 without it).
            // (Asked once per triangle, not once per pair: under coincident shells each triangle
            // blocks a dozen others.)
            let flat = flat.get_or_insert_with(|| self.corners.iter().map(|&c| collinear(c)).collect());
            let mut list = Vec::with_capacity(b.len());
            list.extend(b.into_iter().filter(|&u| !flat[u as usize]).map(|u| self.blocker(t as u32, u)));
            lists.push(Some(list));
        }
        self.near_groups(&mut lists, boxes, budget)?;
        Some(lists)
    }

    /// Triangle `u` as a blocker of `t`: whether it lies in `t`'s plane exactly (a corner of `t`
    /// is, without a predicate; the others by orient3d), or within [`NEAR`] of the surface's
    /// diagonal of it ([`gap`]), where a cut is taken as in it.
    fn blocker(&self, t: u32, u: u32) -> Blocker {
        let (tc, cu) = (&self.corners[t as usize], &self.corners[u as usize]);
        let plane = &self.planes[t as usize];
        let exact = cu.iter().all(|&x| tc.contains(&x) || plane.side(x) == 0.0);
        Blocker {
            u,
            in_plane: exact,
            near: !exact && gap(tc, cu) <= NEAR * self.grid.bounds.diagonal(),
        }
    }

    /// Makes the triangles taken as in one plane a relation that is closed: where a triangle is
    /// in a plane with two others ([`Faces::blocker`]) and one of those pairs is only near it,
    /// the two others are a pair too, blockers of each other taken as in one plane, and so on
    /// through each group so joined, among those of its triangles whose boxes come near. `None`
    /// past `budget` pairs added ([`MAX_GROUPED`]).
    ///
    /// A cell's decision counts the jumps of the triangles in its plane that cover its point, and
    /// the lowest-numbered of them carries the sum, the others nothing ([`Faces::decide_where`]).
    /// That needs each of them to list the same triangles as in its plane: two in one plane
    /// exactly that cover a point meet there, so each lists the other. Two faces 7e-16 apart and
    /// parallel do not meet, and a third cutting both at a slant of 1e-12 is near the plane of
    /// each: that third triangle's jump was carried by both, each of the two believing itself the
    /// lowest, while the third carried nothing (sweep case 33740: three tetrahedra stacked on one
    /// another, two faces of the one they bound dropped on all three, 0.48% off under an
    /// estimate of 0.42%). Within a group every pair is now taken as in one plane, which moves
    /// the solid by at most the slab between the two ([`gap`]), charged as for any near pair.
    fn near_groups(&self, lists: &mut [Option<Vec<Blocker>>], boxes: &[Aabb], budget: usize) -> Option<()> {
        let n = lists.len();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        // Per group (at its root, once joined): whether it has a near pair, and the sum of their
        // gaps, which bounds how far apart along the normal two of its triangles can be.
        let mut near = vec![false; n];
        let mut reach = vec![0.0f64; n];
        for (t, list) in lists.iter().enumerate() {
            for b in list.iter().flatten().filter(|b| b.near || b.in_plane) {
                let (x, y) = (super::root(&mut parent, t as u32), super::root(&mut parent, b.u));
                let g = if b.near { gap(&self.corners[t], &self.corners[b.u as usize]) } else { 0.0 };
                let (lo, hi) = (x.min(y) as usize, x.max(y) as usize);
                parent[hi] = lo as u32;
                let joined = if lo == hi { 0.0 } else { reach[hi] };
                reach[lo] += joined + g;
                near[lo] = near[lo] || near[hi] || b.near;
            }
        }
        // The members of the groups with a near pair, by root, each group along x.
        let mut members: Vec<(u32, f64, u32)> = Vec::new();
        for t in 0..n as u32 {
            let r = super::root(&mut parent, t);
            if near[r as usize] {
                members.push((r, boxes[t as usize].lo[0], t));
            }
        }
        members.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let mut added = 0;
        for group in members.chunk_by(|a, b| a.0 == b.0) {
            // Two members that cover one point seen along an axis lie within the gaps of the
            // chain that joins them of each other, along the normal: their boxes, grown by twice
            // that, overlap.
            let pad = 2.0 * reach[group[0].0 as usize] + self.margin;
            for (i, &(_, _, t)) in group.iter().enumerate() {
                let grown = inflated(boxes[t as usize], pad);
                for &(_, lo, u) in &group[i + 1..] {
                    if lo > grown.hi[0] {
                        break;
                    }
                    if !overlap(&grown, &boxes[u as usize])
                        || apart_seen_along_normal(&self.corners[t as usize], &self.corners[u as usize], pad)
                        || lists[t as usize].iter().flatten().any(|b| b.u == u)
                    {
                        continue;
                    }
                    // Two exactly in one plane that cover one point meet there: already a pair.
                    let mut b = self.blocker(t, u);
                    if b.in_plane {
                        continue;
                    }
                    b.near = true;
                    // Members of a group have lists (their pairs in one plane are blockers).
                    lists[t as usize].get_or_insert_with(Vec::new).push(b);
                    lists[u as usize].get_or_insert_with(Vec::new).push(Blocker { u: t, ..b });
                    added += 1;
                    if added > budget {
                        return None;
                    }
                }
            }
        }
        Some(())
    }

    /// For each triangle, the others that may meet it other than along a shared edge or at a
    /// shared corner: those whose boxes meet its box grown by the margin, in the order of the
    /// grid's cells over that box. Each pair of triangles is found once, from the lower-numbered
    /// one's query over a box grown enough to hold both conditions (the margin twice, and the
    /// rounding of the coordinates), and each condition is then checked as stated; the lists of
    /// two or more are put back in the order a grid of boxes' query over `t`'s grown box finds
    /// them (sorted by [`Grid::first_shared_cell`], not asked again). `None` past [`MAX_MEETING`]
    /// pairs. The grid lists each triangle in the cells it may meet ([`Grid::of_triangles`]), so
    /// a pair whose boxes meet but not the triangles' cells is not found; it meets nowhere within
    /// the margin.
    fn all_blockers(&self, (boxes, free): (&[Aabb], &[u32]), crowded: u64, seen: &mut Seen) -> Option<Vec<Vec<u32>>> {
        let n = self.tris.len();
        // Each box grown by the margin where it is asked (a list of them was 48 bytes a triangle
        // of fresh memory).
        let grown = |t: usize| inflated(boxes[t], self.margin);
        let Aabb { lo, hi } = self.grid.bounds;
        let largest = (0..3).map(|k| lo[k].abs().max(hi[k].abs())).fold(0.0, f64::max);
        let pad = 2.0 * self.margin + 4.0 * f64::EPSILON * largest;
        let mut out = vec![Vec::new(); n];
        let mut meeting = 0;
        let mut pair = |t: usize, u: usize| {
            meeting += 1;
            let asked = (overlap(&grown(t), &boxes[u]), overlap(&grown(u), &boxes[t]));
            let (tu, ut) = self.blocks_both(t, u, asked);
            // Room for a dozen at the first (coincident shells: each triangle under a dozen of
            // the other's), not grown from four.
            let push = |list: &mut Vec<u32>, x: usize| {
                if list.capacity() == 0 {
                    list.reserve(12);
                }
                list.push(x as u32);
            };
            if tu {
                push(&mut out[t], u);
            }
            if ut {
                push(&mut out[u], t);
            }
            meeting
        };
        if self.grid.crowding() > crowded {
            // The pairs whose grown boxes meet, from a tree (the grid's, and those whose
            // triangles its cells part, which meet nowhere within the margin), each asked as the
            // grid asks it, in another order, which the sort below undoes.
            let padded: Vec<Aabb> = boxes.iter().map(|b| inflated(*b, pad)).collect();
            let own: Vec<u32> = (0..n as u32).collect();
            let all = Bvh::new(padded, &own).pairs(|i, j| {
                let (t, u) = (i.min(j) as usize, i.max(j) as usize);
                if (u as u32) < free[t] {
                    return std::ops::ControlFlow::Continue(());
                }
                if overlap(&inflated(boxes[t], pad), &boxes[u]) && pair(t, u) > MAX_MEETING {
                    return std::ops::ControlFlow::Break(());
                }
                std::ops::ControlFlow::Continue(())
            });
            if all.is_break() {
                return None;
            }
        } else {
            let mut near = Vec::new();
            for t in 0..n {
                // A certified shell's own triangles are passed (see [`embedded`]).
                let after = (t as u32).max(free[t].saturating_sub(1));
                self.grid.overlapping(&inflated(boxes[t], pad), Some(after), seen, &mut near);
                for &u in &near {
                    if pair(t, u as usize) > MAX_MEETING {
                        return None;
                    }
                }
            }
        }
        let mut keyed = Vec::new();
        for (t, list) in out.iter_mut().enumerate() {
            if list.len() > 1 {
                let corner = self.grid.cell_of(grown(t).lo);
                keyed.clear();
                keyed.extend(list.iter().map(|&u| (self.grid.first_shared_cell(corner, &boxes[u as usize]), u)));
                keyed.sort_unstable();
                list.clear();
                list.extend(keyed.iter().map(|&(_, u)| u));
            }
        }
        Some(out)
    }

    /// [`Faces::blocks`] of `t` by `u` and of `u` by `t`, each when `asked`, with what the two
    /// share (the corners they have in common, the same seen from either when each has three
    /// distinct corners) found once.
    fn blocks_both(&self, t: usize, u: usize, asked: (bool, bool)) -> (bool, bool) {
        if !asked.0 && !asked.1 {
            return (false, false);
        }
        let (tt, tu) = (self.tris[t], self.tris[u]);
        let distinct = |x: [u32; 3]| x[0] != x[1] && x[1] != x[2] && x[2] != x[0];
        if !distinct(tt) || !distinct(tu) {
            // The corners shared may then differ seen from each.
            return (asked.0 && self.blocks(t, u), asked.1 && self.blocks(u, t));
        }
        let in_u = in_order(|k| tu.contains(&tt[k]));
        match in_u.iter().filter(|&&x| x).count() {
            // Symmetric: whether an edge of either crosses the other.
            0 => {
                let touch = self.touch(t, u);
                (asked.0 && touch, asked.1 && touch)
            }
            1 => {
                let i = in_u.iter().position(|&x| x).unwrap_or(0);
                let j = tu.iter().position(|&x| x == tt[i]).unwrap_or(0);
                let (pt, pu) = (&self.corners[t], &self.corners[u]);
                let (plane_t, plane_u) = (&self.planes[t], &self.planes[u]);
                (
                    asked.0 && blocks_at_corner((pt, i), (pu, j), (plane_t, plane_u)),
                    asked.1 && blocks_at_corner((pu, j), (pt, i), (plane_u, plane_t)),
                )
            }
            // An edge shared: each is blocked when the other's third corner is in its plane
            // ([`Faces::blocks`]), tested here with the corners found once.
            2 => {
                let i = in_u.iter().position(|&x| !x).unwrap_or(0);
                let j = tu.iter().position(|x| !tt.contains(x)).unwrap_or(0);
                let (pt, pu) = (&self.corners[t], &self.corners[u]);
                (
                    asked.0 && self.planes[t].side(pu[j]) == 0.0 && self.coplanar_blocks(t, u),
                    asked.1 && self.planes[u].side(pt[i]) == 0.0 && self.coplanar_blocks(u, t),
                )
            }
            _ => asked,
        }
    }

    /// Whether triangle `u` may meet the relative interior of triangle `t` (exact, conservative).
    /// This runs for every pair of neighbours: the common cases (a corner shared, the other two on
    /// one side of `t`'s plane; an edge shared, the planes apart) end before any copy.
    fn blocks(&self, t: usize, u: usize) -> bool {
        let (tt, tu) = (self.tris[t], self.tris[u]);
        let in_u = in_order(|k| tu.contains(&tt[k]));
        match in_u.iter().filter(|&&x| x).count() {
            0 => self.touch(t, u),
            1 => {
                let i = in_u.iter().position(|&x| x).unwrap_or(0);
                let j = tu.iter().position(|&x| x == tt[i]).unwrap_or(0);
                let corners = ((&self.corners[t], i), (&self.corners[u], j));
                blocks_at_corner(corners.0, corners.1, (&self.planes[t], &self.planes[u]))
            }
            2 => {
                // `t`'s plane is that of the shared corners and its third.
                let j = tu.iter().position(|x| !tt.contains(x)).unwrap_or(0);
                self.planes[t].side(self.corners[u][j]) == 0.0 && self.coplanar_blocks(t, u)
            }
            _ => true,
        }
    }

    /// [`super::triangles_touch`] of `t` and `u`, with their planes' sides precomputed.
    fn touch(&self, t: usize, u: usize) -> bool {
        let (pt, pu) = (&self.planes[t], &self.planes[u]);
        corners_touch(&self.corners[t], &self.corners[u], (|q| pt.side(q), |q| pu.side(q)))
    }

    /// [`Faces::blocks`] for triangles sharing an edge, in one plane: a blocker unless the two lie
    /// on opposite sides of the shared edge.
    fn coplanar_blocks(&self, t: usize, u: usize) -> bool {
        let (tt, tu) = (self.tris[t], self.tris[u]);
        let (mut shared, mut n) = ([0u32; 3], 0);
        for v in tt.into_iter().filter(|v| tu.contains(v)) {
            shared[n] = v;
            n += 1;
        }
        let shared = &shared[..n];
        let (pt, pu) = (self.corners[t], self.corners[u]);
        let other = |tri: [u32; 3], p: Corners| {
            let i = tri.iter().position(|x| !shared.contains(x)).unwrap_or(0);
            p[i]
        };
        let (a, b) = (self.vertices[shared[0] as usize], self.vertices[shared[1] as usize]);
        let (x, y) = (other(tt, pt), other(tu, pu));
        let k = normal_axis(pt);
        let s = orient2d(c2(a, k), c2(b, k), c2(x, k)) * orient2d(c2(a, k), c2(b, k), c2(y, k));
        s >= 0.0
    }

    /// Uncut triangles joined across the edges they share, each patch decided by one ray; the
    /// patches no ray decides go to `heap` whole. Only an edge that the two alone use joins them:
    /// where other triangles use it too, they may lie between the two, whose fronts are then in
    /// different regions (a test shows one with w = 0 in front and one with w = 1; joined, centauro's
    /// `Forearm.STL` left its surface open: its integrals about two origins 4.7e-3 apart).
    /// `uses`: the edge uses of all the triangles ([`super::edge_uses`]), of which those of uncut
    /// ones join them.
    fn patches(
        &self,
        (blockers, uses): (&[Option<Vec<Blocker>>], &[EdgeUse]),
        seen: &mut Seen,
        out: &mut Resolved,
        heap: &mut BinaryHeap<Piece>,
    ) {
        let n = self.tris.len();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        for users in uses.chunk_by(|x, y| x.key == y.key) {
            if let [x, y] = users {
                if x.forward != y.forward && blockers[x.face as usize].is_none() && blockers[y.face as usize].is_none() {
                    let (a, b) = (super::root(&mut parent, x.face), super::root(&mut parent, y.face));
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
        // The uncut triangles grouped by patch root (a counting sort): the patches in the order of
        // their roots (each root is its patch's lowest triangle), each patch's triangles in order,
        // as a sort of (root, triangle) pairs gives them.
        let mut start = vec![0u32; n + 1];
        for t in 0..n {
            if blockers[t].is_none() {
                let r = super::root(&mut parent, t as u32);
                parent[t] = r;
                start[r as usize + 1] += 1;
            }
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut members = vec![0u32; start[n] as usize];
        for t in 0..n {
            if blockers[t].is_none() {
                let at = &mut fill[parent[t] as usize];
                members[*at as usize] = t as u32;
                *at += 1;
            }
        }
        for w in start.windows(2).filter(|w| w[0] < w[1]) {
            let patch = &members[w[0] as usize..w[1] as usize];
            let kappa = patch
                .iter()
                .take(MAX_TRIES)
                .find_map(|&t| self.decide(&self.corners[t as usize], t, seen));
            for &t in patch {
                match kappa {
                    Some(k) => self.emit_whole(t, k, out),
                    None => heap.push(self.piece(self.corners[t as usize], t, Vec::new(), 0.0)),
                }
            }
        }
    }

    /// Splits the pieces that may change the most until those left change at most `target`.
    fn refine(&self, mut heap: BinaryHeap<Piece>, target: f64, seen: &mut Seen, out: &mut Resolved) {
        let mut pending: f64 = heap.iter().map(|p| p.delta).sum();
        let (mut splits, mut asked) = (0, 0);
        while pending > target && splits < MAX_SPLITS && asked < MAX_SPLIT_BLOCKERS {
            let Some(p) = heap.pop() else { break };
            pending -= p.delta;
            splits += 1;
            asked += p.blockers.len();
            for child in split(p.corners) {
                // Each midpoint is rounded once (a sum, then an exact halving): within 2 ε of its
                // largest coordinate, twice that here.
                let slack = p.slack + 4.0 * f64::EPSILON * largest_coordinate(&child);
                let b = inflated(Aabb::of(child), self.margin);
                // A blocker taken as in the plane stays while it may cover a point of the child
                // seen along an axis, whether or not it meets the child: the triangles in a plane
                // must list each other where they cover one point ([`Faces::near_groups`]).
                let keeps = |x: &Blocker| {
                    let cu = &self.corners[x.u as usize];
                    if x.near {
                        let g = gap(&self.corners[p.t as usize], cu);
                        overlap(&inflated(b, 2.0 * g), &Aabb::of(*cu))
                    } else {
                        overlap(&b, &Aabb::of(*cu)) && self.may_meet(&child, x.u)
                    }
                };
                let mut blockers: Vec<Blocker> = p.blockers.iter().copied().filter(keeps).collect();
                if blockers.is_empty() {
                    if let Some(k) = self.decide_linked(&child, p.t, seen, |_| true, &[]) {
                        self.emit_moved(&child, k, (p.t, slack), out);
                        continue;
                    }
                } else if self.cut(&child, (p.t, slack), &mut blockers, seen, out) {
                    continue;
                }
                let piece = self.piece(child, p.t, blockers, slack);
                pending += piece.delta;
                heap.push(piece);
            }
        }
        for p in heap {
            out.bound += p.delta;
            self.emit(&p.corners, self.sign[p.t as usize], out);
        }
    }

    fn piece(&self, corners: Corners, t: u32, blockers: Vec<Blocker>, slack: f64) -> Piece {
        Piece {
            delta: self.delta(&corners, t),
            corners,
            t,
            blockers,
            slack,
        }
    }

    /// The most a piece of triangle `t` oriented wrongly can change the volume: its cone from the
    /// centre, twice when the classification kept it (it may count −1 instead of 1).
    fn delta(&self, poly: &[[f64; 3]], t: u32) -> f64 {
        let reach = poly
            .iter()
            .map(|c| norm(sub(*c, self.centre)))
            .fold(0.0, f64::max);
        let s = self.sign[t as usize].abs() as f64;
        (1.0 + s) * area(poly) * reach / 3.0
    }

    /// Whether triangle `u` may meet the piece: not when the piece lies beyond the margin on one
    /// side of `u`'s plane.
    fn may_meet(&self, piece: &Corners, u: u32) -> bool {
        let [a, b, c] = self.corners[u as usize];
        let (ab, ac) = (sub(b, a), sub(c, a));
        let n = cross(ab, ac);
        let m = self.margin * norm(ab) * norm(ac);
        let d = piece.map(|p| dot(n, sub(p, a)));
        !(d.iter().all(|x| *x > m) || d.iter().all(|x| *x < -m))
    }

    /// How a piece of triangle `t` no other triangle meets bounds Ω: 1 outward, −1 inward, 0 not
    /// at all; `None` when no ray from its centre counts exactly.
    fn decide(&self, piece: &[[f64; 3]], t: u32, seen: &mut Seen) -> Option<i64> {
        self.decide_where(piece, t, seen, |_| true, &[]).map(|d| d.kappa)
    }

    /// [`Faces::decide`] from the first of a few points inside the piece that `usable` accepts and
    /// from which a ray counts exactly (a ray along a face's edge or plane does not). Triangles in
    /// `t`'s plane that cover the point add their jumps to `t`'s; the lowest-numbered of them
    /// carries the sum, the others nothing.
    fn decide_where(
        &self,
        piece: &[[f64; 3]],
        t: u32,
        seen: &mut Seen,
        usable: impl Fn([f64; 3]) -> bool,
        coplanar: &[Coplanar],
    ) -> Option<Decided> {
        let c = self.corners[t as usize];
        let n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        let mut axes = [0, 1, 2];
        axes.sort_by(|&a, &b| n[b].abs().total_cmp(&n[a].abs()));
        let mid = centroid(piece);
        let inner = piece.iter().map(|v| [0, 1, 2].map(|k| (3.0 * mid[k] + v[k]) / 4.0));
        // Then points of no regular position: a cell that spans seams ([`Faces::seam`]) of two
        // regular triangulations can have its centre and the points above on one of them.
        let generic = GENERIC.iter().map(|&seed| {
            let w: Vec<f64> = (0..piece.len())
                .map(|i| 1.0 + (seed + 0.618_033_988_749_895 * i as f64).fract())
                .collect();
            let sum: f64 = w.iter().sum();
            [0, 1, 2].map(|k| piece.iter().zip(&w).map(|(v, w)| v[k] * w).sum::<f64>() / sum)
        });
        let mut skip = vec![t];
        // Whether no point and no ray was refused before the one that decides.
        let mut first = true;
        for p in std::iter::once(mid).chain(inner).chain(generic) {
            if !usable(p) {
                first = false;
                continue;
            }
            skip.truncate(1);
            let mut jump = 1;
            for cp in coplanar.iter().filter(|cp| cp.covers(p, axes[0])) {
                skip.push(cp.u);
                jump += if cp.same { 1 } else { -1 };
            }
            // A lower-numbered triangle in the plane covers the point, and with it the whole cell
            // (cells are cut along their edges, and seams change no lower one's covering): it
            // carries the jumps, whatever the count in front, so no ray is asked.
            if skip.iter().any(|&u| u < t) {
                return Some(Decided { kappa: 0, from: None });
            }
            // The count in front of the piece along axis k: counted forward, or counted behind
            // it and less the jump when that way reads fewer of the grid's entries.
            let mut ray = |k: usize| {
                let ahead = n[k].signum();
                let back = self.grid.row_entries(p, k, -ahead) < self.grid.row_entries(p, k, ahead);
                let sign = if back { -ahead } else { ahead };
                let Some((lo, hi)) = self.straddle(t, p, k) else {
                    first = false;
                    return None;
                };
                let (s, reach) = if sign > 0.0 { (lo, hi[k]) } else { (hi, lo[k]) };
                let mut passed = self.scratch.borrow_mut();
                passed.clear();
                let tris = (&self.corners[..], &self.planes[..]);
                let w = self.grid.winding(tris, s, k, sign, &skip, seen, Some((reach, &mut passed)));
                let (fix, clear) = match w.map(|_| self.before(t, (lo, hi, s), k, &passed)) {
                    Some(Some(found)) => found,
                    Some(None) => {
                        first = false;
                        return None;
                    }
                    None => (0, false),
                };
                first &= w.is_some() && clear;
                w.map(|w| (k, if back { w - fix - jump } else { w - fix }))
            };
            let mut rest = axes.iter().filter(|&&k| n[k] != 0.0);
            let Some((k, front)) = rest.by_ref().find_map(|&k| ray(k)) else {
                continue;
            };
            // A second ray, where one leaves the face steeply enough, must count the same:
            // on a surface that is not watertight near `p` (a cap's crack, a sliver whose
            // centre rounds a few ulps behind a neighbour) rays disagree, and the piece is
            // left undecided, so it enters the bound.
            let again = rest
                .filter(|&&k| n[k].abs() >= SECOND_RAY * norm(n))
                .find_map(|&k| ray(k));
            if again.is_some_and(|(_, w)| w != front) {
                first = false;
                continue;
            }
            let origin = Origin {
                p,
                axes: [Some(k), again.map(|(k, _)| k)],
            };
            return Some(Decided {
                kappa: bounds(front, jump),
                from: (first && skip.len() == 1).then_some((origin, front)),
            });
        }
        None
    }

    /// [`Faces::decide_where`], or the decision of the last piece of `t` decided at the first try
    /// when the piece's centre is [`Faces::joined`] to it, or else of the last such piece of a
    /// triangle across one of `t`'s edges when [`Faces::joined_across`] to it (no coplanar triangle
    /// in the way: their jumps depend on the point). Every piece of a triangle cut into many asks
    /// rays otherwise, most of them counting what its neighbour's counted; the first piece of a
    /// cut triangle asked them for itself until its neighbours' could answer (centauro's
    /// `mesh_wheel23.stl`: 14.6 k of its 34 k cut triangles).
    fn decide_linked(
        &self,
        piece: &[[f64; 3]],
        t: u32,
        seen: &mut Seen,
        usable: impl Fn([f64; 3]) -> bool,
        coplanar: &[Coplanar],
    ) -> Option<i64> {
        let mid = centroid(piece);
        let last = self.origins.borrow()[t as usize];
        // A piece with no coplanar triangle over it jumps by 1 across `t`: how it bounds Ω
        // follows from the count in front of it.
        let kappa = |front: i64, change: i64| {
            if change != 0 {
                self.joins_counted.set(self.joins_counted.get() + 1);
            }
            bounds(front + change, 1)
        };
        if self.joins && self.closed && coplanar.is_empty() && usable(mid) {
            if let Some((from, front)) = last {
                if let Some(change) = self.joined(t, &from, mid, seen) {
                    return Some(kappa(front, change));
                }
            }
            for (e, &u) in self.across[t as usize].iter().enumerate() {
                let Some(Some((from, front))) = self.origins.borrow().get(u as usize).copied() else {
                    continue;
                };
                if let Some(change) = self.joined_across(t, e, u, &from, mid, seen) {
                    self.joins_across.set(self.joins_across.get() + 1);
                    // Rays from `mid` along `from`'s axes count what those from `from.p` did,
                    // changed where the segment between passes through triangles.
                    self.origins.borrow_mut()[t as usize] = Some((Origin { p: mid, axes: from.axes }, front + change));
                    return Some(kappa(front, change));
                }
            }
        }
        let d = self.decide_where(piece, t, seen, usable, coplanar)?;
        if d.from.is_some() {
            self.origins.borrow_mut()[t as usize] = d.from;
        }
        Some(d.kappa)
    }

    /// How much the rays from `q`, in the piece of triangle `t` around it, along `from`'s axes
    /// count more than those from `from.p` (see [`Origin`]); `None` when that is not known
    /// without rays of their own.
    ///
    /// A ray's count from a point x (all triangles but `t`) changes as x moves only where x
    /// passes through a triangle other than `t`, or where the ray sweeps across an edge that does
    /// not balance: the surface decided here is a closed cycle, whose only such edges, once `t`
    /// is left out, are `t`'s own. Passing through a triangle's interior from its front to its
    /// back, x leaves or enters the part of it the ray sees: the count grows by 1 along every
    /// axis and way (a triangle facing the ray's way is crossed leaving through its front, +1,
    /// while x is in front of it and not once x is behind; one facing against it is entered
    /// through its front, −1, only once x is in front); from back to front it falls by 1. So the
    /// count changes by those steps along a segment that meets other triangles only through
    /// their interiors (exact: [`Faces::segment_count`]) and whose ends lie strictly inside `t`
    /// seen along the ray (exact `orient2d`, which keeps the swept strip off `t`'s edges).
    fn joined(&self, t: u32, from: &Origin, q: [f64; 3], seen: &mut Seen) -> Option<i64> {
        let c = self.corners[t as usize];
        let p = from.p;
        if !from.axes.iter().flatten().all(|&k| strictly_inside(c, p, k) && strictly_inside(c, q, k)) {
            return None;
        }
        self.segment_count(p, q, [t, t], from, seen)
    }

    /// A segment along axis `k` through `p`, a rounded point of `t` (a centre, a weighted mean of
    /// corners, a few ulps off its plane), whose ends lie strictly on either side of `t`'s plane
    /// (exact; grown from a few ulps until they do): it holds the point `x` where `p`'s line along
    /// `k` meets the plane.
    ///
    /// A triangle that passes that close to `t` without meeting it (nearly coincident faces of two
    /// shells: 1e-18 apart on go1's `ultraSound.dae`, whose volume was 0.3% off under an estimate
    /// of 0.12%) may lie between `p` and `x`, where a ray from `p` counts it on the wrong side. So a
    /// ray starts at the segment's end behind it (against the ray's way), and each triangle it
    /// passes through within the segment is sorted out by [`Faces::before`].
    fn straddle(&self, t: u32, p: [f64; 3], k: usize) -> Option<([f64; 3], [f64; 3])> {
        let plane = &self.planes[t as usize];
        let n = plane.normal();
        if n[k] == 0.0 {
            return None;
        }
        let size = p.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
        let mut delta = 4.0 * f64::EPSILON * size * (norm(n) / n[k].abs());
        (0..6).find_map(|_| {
            let (mut lo, mut hi) = (p, p);
            lo[k] -= delta;
            hi[k] += delta;
            delta *= 4.0;
            (plane.side(lo) * plane.side(hi) < 0.0).then_some((lo, hi))
        })
    }

    /// What a ray from `s`, the end of [`Faces::straddle`]'s segment `lo hi` behind it, counted of
    /// the triangles of `passed` (those it passed through whose boxes reach the segment) between
    /// `s` and `t`'s plane, the count from `t` itself being the ray's less this; and whether none
    /// met the segment. Each triangle `u` that meets the segment (exact, conservative) crosses the
    /// line at a point y, and whether y lies on `s`'s side of `t`'s plane is exact: where `u`'s
    /// corners lie strictly on one side of it, so does y (a mean of them); where `t`'s lie
    /// strictly on one side of `u`'s plane, so does `x`, and y lies between when `s` does not;
    /// otherwise in integers ([`super::exact::meets_first`]). `None` where that cannot be told.
    fn before(&self, t: u32, (lo, hi, s): ([f64; 3], [f64; 3], [f64; 3]), k: usize, passed: &[u32]) -> Option<(i64, bool)> {
        let c = self.corners[t as usize];
        let plane = &self.planes[t as usize];
        let s_side = plane.side(s).signum();
        let (mut fix, mut clear) = (0, true);
        for &u in passed {
            let pu = &self.planes[u as usize];
            let cu = self.corners[u as usize];
            if !edge_meets(lo, hi, pu.side(lo), pu.side(hi), &cu) {
                continue;
            }
            clear = false;
            let from_s = pu.side(s);
            if from_s == 0.0 {
                return None;
            }
            let between = match strict_sign(cu.map(|q| plane.side(q))) {
                Some(y) => y == s_side,
                None => match strict_sign(c.map(|q| pu.side(q))) {
                    Some(x) => x != from_s.signum(),
                    None => super::exact::meets_first(&c, &cu, s, k)?,
                },
            };
            if between {
                fix += if from_s > 0.0 { 1 } else { -1 };
            }
        }
        Some((fix, clear))
    }

    /// The triangles but those of `but` that the closed segment `p q` passes through, each
    /// through its interior with `p` and `q` strictly on either side of its plane (exact), counted
    /// +1 where `q` is behind it and −1 where in front (see [`Faces::joined`]); `None` where one
    /// meets the segment otherwise (an edge, a corner, its plane: exact, conservative), where a
    /// triangle but `but[0]` (the triangle `q` is a point of) meets [`Faces::straddle`]'s segment
    /// at `q` along any of `from`'s axes, or where the segment's box spans more than
    /// [`MAX_SEGMENT_CELLS`] cells of the grid: rays from `q` then count what rays from `p`
    /// counted, plus this.
    fn segment_count(&self, p: [f64; 3], q: [f64; 3], but: [u32; 2], from: &Origin, seen: &mut Seen) -> Option<i64> {
        let mut starts = [None; 2];
        for (s, k) in starts.iter_mut().zip(from.axes) {
            if let Some(k) = k {
                *s = Some(self.straddle(but[0], q, k)?);
            }
        }
        let starts = starts.iter().flatten();
        let b = Aabb::of(starts.clone().flat_map(|&(lo, hi)| [lo, hi]).chain([p, q]));
        if self.grid.cells_in(&b) > MAX_SEGMENT_CELLS {
            return None;
        }
        let mut near = self.scratch.borrow_mut();
        self.grid.overlapping(&b, None, seen, &mut near);
        let mut change = 0;
        for &u in near.iter() {
            let plane = &self.planes[u as usize];
            let corners = &self.corners[u as usize];
            let meets = |(s, e): ([f64; 3], [f64; 3])| edge_meets(s, e, plane.side(s), plane.side(e), corners);
            if u != but[0] && starts.clone().any(|&s| meets(s)) {
                return None;
            }
            if but.contains(&u) {
                continue;
            }
            let (sp, sq) = (plane.side(p), plane.side(q));
            if (sp > 0.0 && sq > 0.0) || (sp < 0.0 && sq < 0.0) {
                continue;
            }
            if sp == 0.0 || sq == 0.0 {
                if edge_meets(p, q, sp, sq, corners) {
                    return None;
                }
                continue;
            }
            match line_passes(&p, &q, corners) {
                LinePass::Beside => {}
                LinePass::Edge => return None,
                LinePass::Through => change += if sq > 0.0 { 1 } else { -1 },
            }
        }
        Some(change)
    }

    /// How much rays from `q`, in the piece of triangle `t` around it, count in front of `t` more
    /// than rays from `from.p` counted in front of triangle `u`, `u` lying across `t`'s edge `e`
    /// (corner e to the next), which only the two use, one each way, along each of `from`'s axes;
    /// `None` when that is not known without rays of their own.
    ///
    /// Leave both triangles out: the rest's count from x changes as x moves only where x passes
    /// through one of its triangles or where the ray sweeps across an edge of the rest that does
    /// not balance, and those are the other two edges of `t` and of `u` (the shared one is used by
    /// no other). Seen along axis k, let `t` and `u` lie on opposite sides of their shared edge
    /// (exact `orient2d`: then both face the same way along k, and the rays of both run the
    /// same way), `from.p` strictly inside `u`, `q` strictly inside `t`, and the segment between
    /// them cross the shared edge strictly between its ends: each half then lies in one
    /// triangle's open projection, so the strip the ray sweeps keeps off the four other edges.
    /// The rest's count then changes from one end of the segment to the other by the steps of
    /// the triangles it passes through ([`Faces::joined`], [`Faces::segment_count`]); and a ray
    /// from a point strictly inside one triangle's projection misses the other, so the count in
    /// front of `t` at `q` is the rest's, which is the count in front of `u` at `from.p` plus those
    /// steps.
    fn joined_across(&self, t: u32, e: usize, u: u32, from: &Origin, q: [f64; 3], seen: &mut Seen) -> Option<i64> {
        let (ct, cu) = (self.corners[t as usize], self.corners[u as usize]);
        let (a, b, c) = (ct[e], ct[NEXT[e]], ct[NEXT[NEXT[e]]]);
        let shared = [self.tris[t as usize][e], self.tris[t as usize][NEXT[e]]];
        let i = self.tris[u as usize].iter().position(|v| !shared.contains(v))?;
        let d = cu[i];
        let p = from.p;
        let fits = |k: usize| {
            let (a2, b2) = (c2(a, k), c2(b, k));
            let (p2, q2) = (c2(p, k), c2(q, k));
            orient2d(a2, b2, c2(c, k)) * orient2d(a2, b2, c2(d, k)) < 0.0
                && strictly_inside(cu, p, k)
                && strictly_inside(ct, q, k)
                && orient2d(p2, q2, a2) * orient2d(p2, q2, b2) < 0.0
        };
        if !from.axes.iter().flatten().all(|&k| fits(k)) {
            return None;
        }
        self.segment_count(p, q, [t, u], from, seen)
    }

    /// Per coplanar triangle, which of its edges a piece of `t` need not be cut along, where
    /// two coplanar triangles tile the plane on either side (two triangulations of one face, as
    /// coincident shells have). Each is used by exactly two of the `coplanar` triangles, both
    /// exactly in the plane, one each way, that face the same way relative to `t` (exact
    /// `orient2d` in projection, neither degenerate) and are both numbered below `t` or both above
    /// it. The two then lie on its two sides (a triangle lies to the left of its edges seen from
    /// its own normal), so crossing it one of them stops covering a point and the other starts:
    /// the jumps covering a point add up the same on both sides, and whether a lower-numbered
    /// triangle covers it does not change. In front of the piece nothing changes either: a
    /// triangle leaving the plane along the edge would meet `t`'s interior, a blocker whose plane
    /// still cuts there. So a cell may span a seam and one decision holds on all of it; its
    /// decision's point still keeps off the seam (`apart`), where covering is not clear.
    ///
    /// The edge's other use is looked up in [`Faces::pairs`] (the surface's, made once) and its
    /// triangle in `coplanar` by `slot` (each coplanar triangle's place there plus one); only an
    /// edge more than two triangles use is paired by a pass over `coplanar`. Sorting every
    /// coplanar edge of every cut to pair them cost more than the rest of the cut's own work
    /// under fans of hundreds of coplanar triangles (centauro's `mesh_wheel23.stl`: 161 M
    /// instructions of 3,569 M). `sides`: [`Faces::seam_sides`].
    fn seam(&self, t: u32, (coplanar, sides, slot): (&[Coplanar], &[bool], &[u32]), (i, e): (usize, usize)) -> bool {
        if !sides[i] {
            return false;
        }
        let u = coplanar[i].u;
        let v = self.tris[u as usize];
        let (a, b) = (v[e], v[NEXT[e]]);
        if a == b {
            return false;
        }
        let key = super::edge_key(a, b);
        // The edge's other use among the triangles that may hold seams, when it is the only one.
        let pairs = self.pairs.get_or_init(|| pairs(self.tris, self.uses));
        let other = match pairs[u as usize][e] {
            ALONE => None,
            SHARED => {
                // Used by more than two triangles of the surface: count its uses here.
                let (mut count, mut other) = (0, None);
                for (j, cp) in coplanar.iter().enumerate().filter(|&(j, _)| sides[j]) {
                    let w = self.tris[cp.u as usize];
                    for f in 0..3 {
                        if w[f] != w[NEXT[f]] && super::edge_key(w[f], w[NEXT[f]]) == key {
                            count += 1;
                            if (j, f) != (i, e) {
                                other = Some((j, w[f] < w[NEXT[f]]));
                            }
                        }
                    }
                }
                other.filter(|_| count == 2)
            }
            p => {
                let j = slot[p as usize];
                if j == 0 || !sides[j as usize - 1] {
                    return false;
                }
                let w = self.tris[p as usize];
                (0..3)
                    .find(|&f| super::edge_key(w[f], w[NEXT[f]]) == key)
                    .map(|f| (j as usize - 1, w[f] < w[NEXT[f]]))
            }
        };
        let Some((j, forward)) = other else {
            return false;
        };
        let (cx, cy) = (&coplanar[i], &coplanar[j]);
        forward != (a < b) && cx.same == cy.same && (cx.u < t) == (cy.u < t)
    }

    /// Per coplanar triangle, whether its edges may be [`Faces::seam`]s: it lies exactly in `t`'s
    /// plane and faces, certainly, the way `same` says. And each one's place in `coplanar` plus
    /// one in `slot` (per triangle; the cut sets it back to 0 when done).
    fn seam_sides(&self, t: u32, coplanar: &[Coplanar], sides: &mut Vec<bool>, slot: &mut Vec<u32>) {
        if !coplanar.is_empty() && slot.len() < self.tris.len() {
            slot.resize(self.tris.len(), 0);
        }
        for (i, cp) in coplanar.iter().enumerate() {
            slot[cp.u as usize] = i as u32 + 1;
        }
        let k = normal_axis(self.corners[t as usize]);
        let turn = |c: Corners| orient2d(c2(c[0], k), c2(c[1], k), c2(c[2], k));
        let facing = turn(self.corners[t as usize]);
        sides.clear();
        sides.extend(coplanar.iter().map(|cp| {
            if !cp.exact {
                return false;
            }
            let s = turn(self.corners[cp.u as usize]) * facing;
            s != 0.0 && (s > 0.0) == cp.same
        }));
    }

    fn emit_whole(&self, t: u32, kappa: i64, out: &mut Resolved) {
        let tri = self.tris[t as usize];
        out.changed |= kappa != self.sign[t as usize];
        match kappa {
            1 => out.faces.push(&tri),
            -1 => out.faces.push(&[tri[2], tri[1], tri[0]]),
            _ => {}
        }
    }

    /// [`Faces::emit`] for a piece of triangle `t` whose corners lie within `slack` of the exact
    /// piece's (rounded cut points and midpoints), kept for [`Faces::moved`].
    fn emit_moved(&self, piece: &[[f64; 3]], kappa: i64, (t, slack): (u32, f64), out: &mut Resolved) {
        if kappa != 0 {
            let s = &mut out.moved[t as usize].0;
            *s = s.max(slack);
        }
        self.emit(piece, kappa, out);
    }

    /// What the rounding of the pieces' corners can change, m³. The exact pieces of a triangle
    /// tile it; the emitted ones differ from them only within the bands about the cuts (the
    /// area `band`, [`Faces::cut`], and no more than the triangle's area: the bands lie in it,
    /// which bounds a sliver's), within `s` of the triangle's sides (its midpoints and cut
    /// points there, against the neighbouring triangles' corners), and by their corners off its
    /// plane, by at most `s` (the largest displacement of an emitted piece's corners). A region of
    /// area A in the plane changes the cone about the centre by at most A × reach / 3, twice
    /// that when it may count −1 for 1; the corners off the plane change it by at most s ×
    /// area. (`tests/oblique_cuts.rs`: a millimetre part 0.7 m from the origin, cut by three
    /// tetrahedra, was 2.7e-15 off its exact volume with an estimate of 2.2e-15 before this
    /// term.)
    fn moved(&self, moved: &[(f64, f64)]) -> f64 {
        let mut bound = 0.0;
        for (t, &(s, band)) in moved.iter().enumerate() {
            if s > 0.0 || band > 0.0 {
                let c = self.corners[t];
                let perimeter: f64 = (0..3).map(|i| norm(sub(c[(i + 1) % 3], c[i]))).sum();
                let reach = c.iter().map(|x| norm(sub(*x, self.centre))).fold(0.0, f64::max);
                let a = area(&c);
                bound += 2.0 / 3.0 * reach * (band.min(a) + s * perimeter) + s * a;
            }
        }
        bound
    }

    fn emit(&self, piece: &[[f64; 3]], kappa: i64, out: &mut Resolved) {
        out.changed = true;
        if kappa == 0 {
            return;
        }
        let base = (self.vertices.len() + out.vertices.len()) as u32;
        out.vertices.extend_from_slice(piece);
        // The corners' numbers on the stack where they fit (a cell has a few corners).
        let mut room = [0u32; 16];
        let mut long = Vec::new();
        let face = if piece.len() <= room.len() {
            &mut room[..piece.len()]
        } else {
            long.resize(piece.len(), 0);
            &mut long[..]
        };
        for (i, v) in face.iter_mut().enumerate() {
            *v = base + i as u32;
        }
        if kappa < 0 {
            face.reverse();
        }
        out.faces.push(face);
    }

    /// When no blocker lies in `t`'s plane (and they are few): the piece cut along the blockers'
    /// planes into convex cells that no triangle meets any more, each decided by a ray, or bounded
    /// when it is a sliver the plane tests cannot tell from a cut. Whether it did so.
    /// `slack` is how far the piece's corners may lie from the points they stand for.
    fn cut(&self, piece: &Corners, (t, slack): (u32, f64), blockers: &mut [Blocker], seen: &mut Seen, out: &mut Resolved) -> bool {
        let (nt, skew) = normal_and_skew(self.corners[t as usize]);
        let mut work = self.cut_work.borrow_mut();
        let CutWork {
            planes,
            coplanar,
            sides,
            slot,
            edges,
            crossing,
            cells: cell_work,
        } = &mut *work;
        planes.clear();
        coplanar.clear();
        edges.clear();
        let tc = &self.corners[t as usize];
        for blocker in blockers.iter_mut() {
            let u = blocker.u;
            // Read through the reference: an array of the corners made here and read back at
            // once stalled its loads (see [`in_order`]).
            let cu = &self.corners[u as usize];
            // How the pair lies was asked once for the pair ([`Faces::blocker`]), not per piece.
            let exact = blocker.in_plane;
            if exact || blocker.near {
                // Nearly in t's plane: taken as in it, which moves the solid by at most the slab
                // between the two over the piece (on both sides).
                if !exact {
                    out.bound += 2.0 * area(piece) * gap(tc, cu);
                }
                coplanar.push(Coplanar::new(u, *cu, nt, self.margin, exact));
            } else {
                let [a, b, c] = *cu;
                let n = cross(sub(b, a), sub(c, a));
                planes.push(blocker_cut(*cu, n, nt, (self.margin, skew)));
            }
        }
        // Every plane cuts but the seams between coplanar triangles: the other edges' planes
        // follow the blockers', as cuts once they cross the piece. (Every edge was a cut, seams
        // skipped by each test: building and copying cuts most of which cut nothing was about
        // a tenth of the time of coincident shells.)
        self.seam_sides(t, coplanar, sides, slot);
        for i in 0..coplanar.len() {
            for e in 0..3 {
                if !self.seam(t, (coplanar, sides, slot), (i, e)) {
                    edges.push((i as u32, e as u8));
                }
            }
        }
        for cp in coplanar.iter() {
            slot[cp.u as usize] = 0;
        }
        // Only planes that cross the piece can cut it (its cells lie inside it, so a plane that
        // leaves the piece whole leaves each of its cells whole in `cells`): those along its
        // sides or beyond it leave every cell whole, so they neither count against the limit nor
        // are tried. Under coincident shells most of a piece's coplanar neighbours are such (a
        // fan's edges meet at a shared corner); counted, they sent it to be split in four again
        // and again until the work ran out, and the pieces left entered the bound. The same holds
        // for a plane whose reach (the blocker, or the coplanar triangle's edge) ends before the
        // piece ([`Cut`]): a fan's long edges, extended, cross every piece of the face.
        // A plane that crosses the piece by less than the margin leaves it whole too, and the
        // sliver beyond it is decided with the rest: its area is in the bound (`shallow`).
        let blocking = planes.len();
        let shallow = self.crossing(piece, (nt, skew), (planes, coplanar, edges), crossing, &mut cell_work.sliver);
        if crossing.len() > MAX_CUTS {
            return false;
        }
        let Some((cells, slivers)) = cells(piece, (planes, crossing), nt, self.margin, cell_work) else {
            return false;
        };
        let (band, slack) = rounded(piece, nt, (planes, crossing), slack);
        // Twice the slivers' area, for the rounding of their corners and of the planes.
        out.moved[t as usize].1 += band + 2.0 * (shallow + slivers.iter().sum::<f64>());
        for cell in cells.iter() {
            // The decision's point keeps off every plane whose reach is not beyond the cell: off
            // the blockers and the coplanar triangles' edges that come near, whose sides of the
            // point decide what covers it. (Off every plane, points on the lines of edges that
            // end before the cell were refused for nothing: go1's `calf.dae` then left 2.4e-6 m³
            // undecided, an estimate of 3.5e-2, against 1.4e-13 m³.) The reach is asked only of
            // a plane the point is near: most points are far from most planes, and the reach
            // costs a pass over the cell's sides.
            // The blockers' cuts, then every coplanar edge, seam or not (those that cross the
            // piece are also in `planes`, after the blockers).
            let far = |x: [f64; 3], (a, n, m): CutPlane| dot(n, sub(x, a)).abs() > m;
            let apart = |x: [f64; 3]| {
                planes[..blocking].iter().all(|cut| far(x, cut.plane) || cut.misses(cell, nt, self.margin))
                    && coplanar.iter().all(|cp| {
                        (0..3).all(|e| far(x, cp.edges[e]) || cp.cut(e, skew).misses(cell, nt, self.margin))
                    })
            };
            if let Some(k) = self.decide_linked(cell, t, seen, apart, coplanar) {
                self.emit_moved(cell, k, (t, slack), out);
            } else {
                out.bound += self.delta(cell, t);
                self.emit(cell, self.sign[t as usize], out);
            }
        }
        true
    }
}

impl Faces<'_> {
    /// Fills `crossing` with the cuts that cross the piece (of normal `nt`) beyond the margin and
    /// whose reach is not beyond it: of `planes` (the blockers'), then of the coplanar triangles'
    /// `edges` (place in `coplanar`, edge), which join `planes` when they do (`skew`: the piece's
    /// normal's, [`Cut::skew`]). Returns the area of the slivers ([`overhang`]) that the others cut
    /// off within the margin where their reach is not beyond the piece, m². `sliver` is a list to
    /// clip into.
    fn crossing(
        &self,
        piece: &Corners,
        (nt, skew): ([f64; 3], f64),
        (planes, coplanar, edges): (&mut Vec<Cut>, &[Coplanar], &[(u32, u8)]),
        crossing: &mut Vec<usize>,
        sliver: &mut Vec<[f64; 3]>,
    ) -> f64 {
        crossing.clear();
        let mut shallow = 0.0;
        // Whether the plane crosses, the sliver's area when it leaves the piece whole, each asked
        // of the cut only when the plane alone does not settle it.
        let mut test = |(a, n, m): CutPlane, misses: &dyn Fn() -> bool| {
            let d = in_order(|k| dot(n, sub(piece[k], a)));
            if leaves_whole(&d, m) {
                let o = overhang(piece, &d, sliver);
                if o > 0.0 && !misses() {
                    shallow += o;
                }
                false
            } else {
                !misses()
            }
        };
        for i in 0..planes.len() {
            let cut = &planes[i];
            if test(cut.plane, &|| cut.misses(piece, nt, self.margin)) {
                crossing.push(i);
            }
        }
        for &(i, e) in edges {
            let (cp, e) = (&coplanar[i as usize], e as usize);
            if test(cp.edges[e], &|| cp.cut(e, skew).misses(piece, nt, self.margin)) {
                crossing.push(planes.len());
                planes.push(cp.cut(e, skew));
            }
        }
        shallow
    }
}

/// A triangle's normal `ab × ac`, and the skew of a coplanar triangle's edge planes `nt × e` made
/// from it ([`Cut::skew`]): the normal's rounding, then the product's.
fn normal_and_skew(c: Corners) -> ([f64; 3], f64) {
    let (ab, ac) = (sub(c[1], c[0]), sub(c[2], c[0]));
    let nt = cross(ab, ac);
    (nt, 8.0 * norm(ab) * norm(ac) / norm(nt) + 2.0)
}

/// The cut along which blocker `c` (normal `n`) cuts a piece of normal `nt` ([`blocker_plane`]);
/// `skew` is the piece's edge planes' (a sliver's line's plane turns with `nt`).
fn blocker_cut(c: Corners, n: [f64; 3], nt: [f64; 3], (margin, skew): (f64, f64)) -> Cut {
    let (plane, offset, own) = blocker_plane(c, n, nt, margin);
    let own_skew = || 8.0 * norm(sub(c[1], c[0])) * norm(sub(c[2], c[0])) / norm(n);
    Cut {
        plane,
        reach: Some(c),
        skew: if own { own_skew() } else { skew },
        offset,
    }
}

/// Where the cells of `piece` cut along `which` of `cuts` may differ from the exact ones, its
/// corners within `slack` of their exact places: within each cut's slack of its line, a band at
/// most the piece's diameter (or the cut's reach) long on both sides of the line, of area `band`;
/// and how far the cells' corners may lie from theirs (the rounding of `p + s (q − p)` on the
/// piece's sides, beyond `slack`).
fn rounded(piece: &Corners, nt: [f64; 3], (cuts, which): (&[Cut], &[usize]), slack: f64) -> (f64, f64) {
    let diameter = (0..3).map(|i| norm(sub(piece[(i + 1) % 3], piece[i]))).fold(0.0, f64::max);
    let band = which
        .iter()
        .map(|&i| {
            let (w, local) = cuts[i].slack(piece, nt, slack);
            2.0 * w * diameter.min(local)
        })
        .sum::<f64>();
    (band, slack + 8.0 * f64::EPSILON * (largest_coordinate(piece) + diameter))
}

/// How a piece bounds Ω (1 outward, −1 inward, 0 not at all) from the count in front of it and the
/// jump across it: whether each side is in Ω (|w| ≥ 1), behind less in front.
fn bounds(front: i64, jump: i64) -> i64 {
    let solid = |w: i64| i64::from(w.abs() >= 1);
    solid(front + jump) - solid(front)
}

/// How a piece bounds Ω (1 outward, −1 inward, 0 not at all), and where its rays started when
/// they decided it at the first try.
struct Decided {
    kappa: i64,
    /// Where its rays started, with their count in front of the piece (whose jump is then 1).
    from: Option<(Origin, i64)>,
}

/// The point whose rays decided a piece at the first try (its centre, no ray refused, no
/// coplanar triangle covering it), and their axes: the first and, when there is one, the second;
/// or a piece's centre [`Faces::joined_across`] to such a point, whose rays along the same axes
/// count the same.
#[derive(Clone, Copy)]
struct Origin {
    p: [f64; 3],
    axes: [Option<usize>; 2],
}

/// Whether every edge of the triangles whose edge `uses` these are is used as often one way as
/// the other.
fn balanced(uses: &[EdgeUse]) -> bool {
    uses.chunk_by(|x, y| x.key == y.key)
        .all(|g| g.iter().map(|e| if e.forward { 1i64 } else { -1 }).sum::<i64>() == 0)
}

/// Per triangle and edge (corner k to the next): the other triangle when exactly two triangles use
/// the edge, one each way; `u32::MAX` otherwise. `uses`: the triangles' edge uses, sorted by edge.
fn across(tris: &[[u32; 3]], uses: &[EdgeUse]) -> Vec<[u32; 3]> {
    let mut out = vec![[u32::MAX; 3]; tris.len()];
    for g in uses.chunk_by(|x, y| x.key == y.key) {
        if let [x, y] = g {
            if x.forward == y.forward || x.face == y.face {
                continue;
            }
            for (f, other) in [(x.face, y.face), (y.face, x.face)] {
                let tri = tris[f as usize];
                if let Some(e) = (0..3).find(|&e| super::edge_key(tri[e], tri[NEXT[e]]) == x.key) {
                    out[f as usize][e] = other;
                }
            }
        }
    }
    out
}

/// [`Faces::pairs`] of an edge no other triangle uses.
const ALONE: u32 = u32::MAX;

/// [`Faces::pairs`] of an edge that more than two triangles use (or one triangle twice).
const SHARED: u32 = u32::MAX - 1;

/// Per triangle and edge (corner k to the next): the other triangle when exactly two distinct
/// triangles use the edge (either way), [`ALONE`] when one does, [`SHARED`] otherwise. `uses`: the
/// triangles' edge uses, sorted by edge.
fn pairs(tris: &[[u32; 3]], uses: &[EdgeUse]) -> Vec<[u32; 3]> {
    let mut out = vec![[ALONE; 3]; tris.len()];
    for g in uses.chunk_by(|x, y| x.key == y.key) {
        let other = |f: u32| match g {
            [_] => ALONE,
            [x, y] if x.face != y.face => if f == x.face { y.face } else { x.face },
            _ => SHARED,
        };
        for x in g {
            let tri = tris[x.face as usize];
            for e in (0..3).filter(|&e| super::edge_key(tri[e], tri[NEXT[e]]) == x.key) {
                out[x.face as usize][e] = other(x.face);
            }
        }
    }
    out
}

/// A triangle in the plane of the one being decided: its edges as planes across that plane (normals
/// pointing into it), and whether it faces the same way.
struct Coplanar {
    u: u32,
    corners: Corners,
    /// The corners' box: a point strictly inside the triangle seen along an axis is strictly
    /// inside it on the other two (most points a piece asks about are not).
    bounds: Aabb,
    edges: [([f64; 3], [f64; 3], f64); 3],
    same: bool,
    /// Exactly in the plane (not only within [`NEAR`] of it).
    exact: bool,
}

impl Coplanar {
    fn new(u: u32, c: Corners, nt: [f64; 3], margin: f64, exact: bool) -> Coplanar {
        let nu = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        // Three calls, not `[0, 1, 2].map`: the array's map ran out of line, and its results,
        // stored piece by piece and read back whole, stalled (see [`in_order`]).
        let edge = |(a, b, o): ([f64; 3], [f64; 3], [f64; 3])| {
            let mut n = cross(nt, sub(b, a));
            if dot(n, sub(o, a)) < 0.0 {
                n = [-n[0], -n[1], -n[2]];
            }
            (a, n, margin * norm(nt) * norm(sub(b, a)))
        };
        let edges = [edge((c[0], c[1], c[2])), edge((c[1], c[2], c[0])), edge((c[2], c[0], c[1]))];
        Coplanar {
            u,
            corners: c,
            bounds: Aabb::of(c),
            edges,
            same: dot(nu, nt) > 0.0,
            exact,
        }
    }

    /// Its edge `k` as a cut, reaching along the edge only; `skew` is the piece's normal's (the
    /// edges' planes are `nt × (b − a)`).
    fn cut(&self, k: usize, skew: f64) -> Cut {
        let end = self.corners[(k + 1) % 3];
        Cut {
            plane: self.edges[k],
            reach: Some([self.corners[k], end, end]),
            skew,
            offset: 0.0,
        }
    }

    /// Whether `p` lies strictly inside, seen along axis `k` (exact `orient2d`). The point keeps
    /// off the edges that come near its cell; an edge's line beyond the edge may pass close by,
    /// where a rounded side would not do.
    fn covers(&self, p: [f64; 3], k: usize) -> bool {
        let b = &self.bounds;
        let within = |i: usize| p[i] > b.lo[i] && p[i] < b.hi[i];
        if !within((k + 1) % 3) || !within((k + 2) % 3) {
            return false;
        }
        strictly_inside(self.corners, p, k)
    }
}

/// Whether `x` lies strictly inside triangle `c` seen along axis `k` (exact `orient2d`).
fn strictly_inside(c: Corners, x: [f64; 3], k: usize) -> bool {
    strict_sign(in_order(|i| orient2d(c2(c[i], k), c2(c[NEXT[i]], k), c2(x, k)))).is_some()
}

/// 1 when all three are positive, −1 when all are negative, else `None` (a zero among them, or
/// mixed signs): three orientations of one point, or three points' sides of one plane.
fn strict_sign(s: [f64; 3]) -> Option<f64> {
    if s.iter().all(|&v| v > 0.0) {
        Some(1.0)
    } else if s.iter().all(|&v| v < 0.0) {
        Some(-1.0)
    } else {
        None
    }
}

/// Two triangles `[v, …]` sharing their first corner: whether `u` may meet `t` anywhere but at
/// `v` (exact where `u` meets `t` at `v` alone; where it runs along an edge of `t`, it is taken as
/// meeting `t`, so that `t` is not joined across that edge: [`Faces::patches`]), given the sides
/// of `u`'s other corners of `t`'s plane (not both strictly on one side) and `u`'s plane (a turn
/// of the corners leaves a plane's sides as they are).
#[inline(always)]
fn shares_corner(t: Corners, u: Corners, (ub, uc): (f64, f64), plane_u: &Plane) -> bool {
    if ub == 0.0 && uc == 0.0 {
        return !coplanar_apart((&t, 0), (&u, 0));
    }
    // One other corner of `u` in `t`'s plane and the third off it: `u` meets that plane along
    // the segment from `v` to that corner, which meets `t` beyond `v` when it points into `t`'s
    // angle at `v` or along one of its edges.
    if ub == 0.0 {
        return within_angle(t, u[1]);
    }
    if uc == 0.0 {
        return within_angle(t, u[2]);
    }
    // `u` crosses `t`'s plane along a segment from `v` (towards a point strictly between `u`'s
    // other corners, so strictly inside `u`'s angle at `v`) on the line where the two planes meet.
    // A corner of `t` in `u`'s plane lies on that line: the segment runs along `t`'s edge to it
    // when that corner lies inside `u`'s angle, and away from `t` otherwise.
    let (tb, tc) = (plane_u.side(t[1]), plane_u.side(t[2]));
    if tb == 0.0 {
        return within_angle(u, t[1]);
    }
    if tc == 0.0 {
        return within_angle(u, t[2]);
    }
    edge_meets(u[1], u[2], ub, uc, &t) || edge_meets(t[1], t[2], tb, tc, &u)
}

/// Whether the segment from `t`'s first corner to `x` (in `t`'s plane, exactly) meets `t` beyond
/// that corner: `x` inside `t`'s angle there or on one of its two edges' rays. `true` when `t` is
/// a segment seen along the axis of its normal (conservative).
fn within_angle(t: Corners, x: [f64; 3]) -> bool {
    let k = normal_axis(t);
    let p = |x: [f64; 3]| c2(x, k);
    let s = orient2d(p(t[0]), p(t[1]), p(t[2]));
    if s == 0.0 {
        return true;
    }
    let (a, b) = (orient2d(p(t[0]), p(t[1]), p(x)), orient2d(p(t[0]), p(x), p(t[2])));
    let with = |o: f64| o == 0.0 || (o > 0.0) == (s > 0.0);
    with(a) && with(b) && (a != 0.0 || b != 0.0)
}

/// [`Faces::blocks`] of a triangle with corners `p` by one with corners `q` (their planes), where
/// the two share only the corner `p[i]` = `q[j]`: the common case (`q`'s other two corners on one
/// side of `p`'s plane) ends before any copy. Inlined: it runs for most pairs of neighbours.
#[inline(always)]
fn blocks_at_corner((p, i): (&Corners, usize), (q, j): (&Corners, usize), (plane_p, plane_q): (&Plane, &Plane)) -> bool {
    let sides = (plane_p.side(q[NEXT[j]]), plane_p.side(q[NEXT[NEXT[j]]]));
    if (sides.0 > 0.0 && sides.1 > 0.0) || (sides.0 < 0.0 && sides.1 < 0.0) {
        return false;
    }
    // Coplanar (most such pairs under coincident shells): read from the corners as stored, not
    // from turned copies, whose loads stalled (see [`in_order`]).
    if sides.0 == 0.0 && sides.1 == 0.0 {
        return !coplanar_apart((p, i), (q, j));
    }
    shares_corner(rotated(p, i), rotated(q, j), sides, plane_q)
}

/// The next corner of a triangle.
const NEXT: [usize; 3] = [1, 2, 0];

/// A triangle's corners from its `i`-th on.
fn rotated(p: &Corners, i: usize) -> Corners {
    match i {
        0 => *p,
        1 => [p[1], p[2], p[0]],
        _ => [p[2], p[0], p[1]],
    }
}

/// [`coplanar_apart`]'s test: the line from the shared corner `v` along edge `e`, with the other
/// corner `o` of the same triangle strictly on one side and the other triangle's two corners `y1`,
/// `y2` not on that side. A function inlined, not a closure: the closure ran out of line, its
/// points read from memory just written (see [`in_order`]).
#[inline(always)]
fn apart(v: Coord<f64>, e: Coord<f64>, o: Coord<f64>, y1: Coord<f64>, y2: Coord<f64>) -> bool {
    let s = orient2d(v, e, o);
    s != 0.0 && orient2d(v, e, y1) * s <= 0.0 && orient2d(v, e, y2) * s <= 0.0
}

/// Two coplanar triangles sharing corner `t[i]` = `u[j]`: whether a line through it along one of
/// their edges separates them.
#[inline(always)]
fn coplanar_apart((t, i): (&Corners, usize), (u, j): (&Corners, usize)) -> bool {
    let (t0, t1, t2) = (t[i], t[NEXT[i]], t[NEXT[NEXT[i]]]);
    let k = normal_axis_of(t0, t1, t2);
    // Each corner seen along `k` once (the shared one is the same point in both).
    let (v, t1, t2) = (c2(t0, k), c2(t1, k), c2(t2, k));
    let (u1, u2) = (c2(u[NEXT[j]], k), c2(u[NEXT[NEXT[j]]], k));
    apart(v, t1, t2, u1, u2) || apart(v, t2, t1, u1, u2) || apart(v, u1, u2, t1, t2) || apart(v, u2, u1, t1, t2)
}

/// The plane along which a blocker `c` (normal `n`, not in the plane of normal `nt` of the piece it
/// blocks) cuts that piece, and its margin: points within the margin of the plane may lie on the
/// blocker. Its own plane, with the margin `margin · |ab| · |ac|` that covers the normal's
/// rounding, is a band of width `margin / sin θ` (θ its angle at `a`): for a sliver (corners a
/// rounding from one line, as exporters leave along seams) that band holds the whole piece, so no
/// point of it could be decided (laikago's `chassis.obj`: a sliver of float area 0 across a
/// face left 1.4e-3 of the volume undecided). A sliver lies within its height `h` of the line of
/// its longest edge, so within `h` of the plane through that line across the piece's plane;
/// that plane is taken when its band is the narrower. `h` is bounded from the float normal and
/// the rounding of the differences and products (each component within `6 ε |ab| |ac|`, the
/// norm within `16 ε |ab| |ac|`).
/// Also how far the plane taken may lie from the blocker's own within the piece's plane beyond
/// rounding (`h` for the line's plane, 0 for its own), and whether it is its own (the line's
/// plane `e × nt` turns with the piece's normal, not the blocker's).
fn blocker_plane(c: Corners, n: [f64; 3], nt: [f64; 3], margin: f64) -> (CutPlane, f64, bool) {
    let [a, b, cc] = c;
    let (ab, ac) = (sub(b, a), sub(cc, a));
    let own = (a, n, margin * norm(ab) * norm(ac));
    let own_band = own.2 / norm(n);
    let edges = [(a, b), (b, cc), (cc, a)];
    let (p, q) = edges
        .into_iter()
        .max_by(|x, y| norm(sub(x.1, x.0)).total_cmp(&norm(sub(y.1, y.0))))
        .unwrap_or((a, b));
    let e = sub(q, p);
    let len = norm(e);
    let h = (norm(n) + 16.0 * f64::EPSILON * norm(ab) * norm(ac)) / len;
    let across = cross(e, nt);
    let m = (margin + h) * len * norm(nt);
    let band = m / norm(across);
    if band < own_band {
        ((p, across, m), h, false)
    } else {
        (own, 0.0, true)
    }
}

/// Whether the corners lie on one line, exactly: the normal's three components, which are the
/// corners' `orient2d` seen along each axis, are all zero.
fn collinear(c: Corners) -> bool {
    (0..3).all(|k| orient2d(c2(c[0], k), c2(c[1], k), c2(c[2], k)) == 0.0)
}

/// The axis along which a triangle's normal is largest (dropping it projects the triangle without
/// folding it).
#[inline(always)]
fn normal_axis(t: Corners) -> usize {
    normal_axis_of(t[0], t[1], t[2])
}

/// [`normal_axis`] of the triangle `a b c`.
#[inline(always)]
fn normal_axis_of(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> usize {
    let n = cross(sub(b, a), sub(c, a));
    (0..3)
        .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
        .unwrap_or(2)
}

/// `p` seen along axis `drop`: its next two coordinates, in turn. The axes come from a table:
/// the two remainders by 3 of a run-time axis were about 2% of the instructions of coincident
/// shells (`benches/open_mesh.rs`, callgrind), where every coplanar test projects its corners.
fn c2(p: [f64; 3], drop: usize) -> Coord<f64> {
    const NEXT_TWO: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];
    let [i, j] = NEXT_TWO[drop];
    Coord { x: p[i], y: p[j] }
}

/// Whether triangles `t` and `u` lie apart by more than `pad`, seen along the axis nearest `t`'s
/// normal and along the axis nearest `u`'s: in each view some side of one has the other wholly
/// beyond it by more than `pad` (the separating axes of two triangles in a plane, with room), but
/// for corners seen at that side's ends, which the two share (fans about one corner, triangles
/// across an edge): their interiors are then apart, however near they come at those corners. A
/// cell's decision asks which triangles cover its point seen along the axis nearest its own
/// triangle's normal, so two such triangles are never both asked of one point and need not be
/// paired ([`Faces::near_groups`]). Fans of triangles about one corner have boxes that all meet; without
/// this every two were paired (three coincident cylinders of 200 sides took 18 times as long).
fn apart_seen_along_normal(t: &Corners, u: &Corners, pad: f64) -> bool {
    [normal_axis(*t), normal_axis(*u)].iter().all(|&k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let flat = |c: &Corners| c.map(|p| [p[i], p[j]]);
        let (a, b) = (flat(t), flat(u));
        let beyond = |x: &[[f64; 2]; 3], y: &[[f64; 2]; 3]| {
            (0..3).any(|e| {
                let (p, q) = (x[e], x[(e + 1) % 3]);
                let n = [q[1] - p[1], p[0] - q[0]];
                let side = |r: [f64; 2]| n[0] * (r[0] - p[0]) + n[1] * (r[1] - p[1]);
                let own = side(x[(e + 2) % 3]);
                let room = pad * n[0].hypot(n[1]);
                own != 0.0 && y.iter().all(|&r| r == p || r == q || side(r) * own.signum() < -room)
            })
        };
        beyond(&a, &b) || beyond(&b, &a)
    })
}

/// The gap between two triangles, the same seen from either: the farthest of each one's corners
/// from the other's plane, m. Asked per piece, a small piece took its neighbour as in its plane
/// where the neighbour's larger pieces did not take it so, and one of two faces 1e-9 apart was
/// dropped where the other was kept (g1's `left_hip_pitch_link.STL`: its decided surface open,
/// 1.1e-3 off).
fn gap(t: &Corners, u: &Corners) -> f64 {
    let from = |p: &Corners, xs: &Corners| {
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        xs.iter().map(|x| dot(n, sub(*x, p[0])).abs() / norm(n)).fold(0.0, f64::max)
    };
    from(u, t).max(from(t, u))
}

fn inflated(b: Aabb, m: f64) -> Aabb {
    Aabb::new(b.lo.map(|x| x - m), b.hi.map(|x| x + m))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The faces `r` emits, as a sum of area vectors (corners from the input `vertices`, then
    /// the pieces' own).
    fn area_vector(vertices: &[[f64; 3]], r: &Resolved) -> [f64; 3] {
        let at = |i: u32| {
            let i = i as usize;
            vertices.get(i).copied().unwrap_or_else(|| r.vertices[i - vertices.len()])
        };
        let mut sum = [0.0; 3];
        for face in r.faces.iter() {
            for k in 1..face.len() - 1 {
                let (a, b, c) = (at(face[0]), at(face[k]), at(face[k + 1]));
                let n = cross(sub(b, a), sub(c, a));
                (0..3).for_each(|i| sum[i] += n[i] / 2.0);
            }
        }
        sum
    }

    /// The signed volume the faces `r` emits enclose (corners as in [`area_vector`]).
    fn enclosed(vertices: &[[f64; 3]], r: &Resolved) -> f64 {
        let at = |i: u32| {
            let i = i as usize;
            vertices.get(i).copied().unwrap_or_else(|| r.vertices[i - vertices.len()])
        };
        let mut sum = 0.0;
        for face in r.faces.iter() {
            for k in 1..face.len() - 1 {
                sum += dot(at(face[0]), cross(at(face[k]), at(face[k + 1]))) / 6.0;
            }
        }
        sum
    }

    /// An axis-aligned box's 12 triangles, facing out, on new vertices.
    fn push_box(vertices: &mut Vec<[f64; 3]>, tris: &mut Vec<[u32; 3]>, lo: [f64; 3], hi: [f64; 3]) {
        let base = vertices.len() as u32;
        for i in 0..8 {
            vertices.push([0, 1, 2].map(|k| if i >> k & 1 == 1 { hi[k] } else { lo[k] }));
        }
        // Corner i has bit k set when at `hi` on axis k; each side as a quad seen from outside.
        for q in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
            tris.push([q[0], q[1], q[2]].map(|c| base + c));
            tris.push([q[0], q[2], q[3]].map(|c| base + c));
        }
    }

    /// A tetrahedron's four triangles on the vertices numbered `v`, facing out.
    fn push_tetra(vertices: &[[f64; 3]], tris: &mut Vec<[u32; 3]>, v: [u32; 4]) {
        for skip in 0..4 {
            let f: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| v[i]).collect();
            let p = |i: u32| vertices[i as usize];
            let n = cross(sub(p(f[1]), p(f[0])), sub(p(f[2]), p(f[0])));
            if dot(n, sub(p(v[skip]), p(f[0]))) < 0.0 {
                tris.push([f[0], f[1], f[2]]);
            } else {
                tris.push([f[0], f[2], f[1]]);
            }
        }
    }

    /// Four triangles share an edge: two of a tetrahedron (at 0° and 90° about the edge) and two
    /// of a thinner one inside it (at 30° and 60°, so twice enclosed). The edge is used twice each
    /// way, so the faces on either side are not one surface there. Two small boxes pierce the
    /// triangles at 90° and 30°, so that only those at 0° (front: outside, w = 0) and 60° (front:
    /// inside the outer one, w = 1) are uncut, and they use the edge one each way. One decision
    /// carried from either to the other across the edge would keep the inner side at 60° (or drop
    /// the outer at 0°); the solid is the outer tetrahedron and the part of the first box
    /// outside it, exactly.
    #[test]
    fn uncut_faces_are_not_joined_across_an_edge_others_use() {
        let at = |deg: f64| {
            let a = deg.to_radians();
            [0.3 * a.cos(), 0.3 * a.sin(), 0.5]
        };
        let mut vertices = vec![[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5], at(30.0), at(60.0)];
        let mut tris = Vec::new();
        push_tetra(&vertices, &mut tris, [0, 1, 2, 3]);
        push_tetra(&vertices, &mut tris, [0, 1, 4, 5]);
        push_box(&mut vertices, &mut tris, [-0.02, 0.18, 0.48], [0.02, 0.22, 0.52]);
        let c = at(30.0).map(|x| x / 3.0);
        push_box(&mut vertices, &mut tris, [c[0] - 0.01, c[1] - 0.01, 0.49], [c[0] + 0.01, c[1] + 0.01, 0.51]);
        let signs = vec![1; tris.len()];
        let r = resolve(&vertices, &tris, &signs, &[], [0.3, 0.3, 0.5], 0.0);
        let want = 1.0 / 6.0 + 0.02 * 0.04 * 0.04;
        assert_eq!(r.bound, 0.0);
        let got = enclosed(&vertices, &r);
        assert!((got - want).abs() < 1e-14, "{got} against {want}");
    }

    /// A triangle of collinear corners through a box's bottom (a zero-area sliver, as exporters
    /// leave along seams) changes no winding number, so the bottom is decided as if it were not
    /// there: the box exactly, nothing undecided. Taken as a blocker, its plane (every point lies
    /// in it) kept every point of the bottom too near to be decided.
    #[test]
    fn a_triangle_of_collinear_corners_cuts_nothing() {
        let (r, got) = unit_box_and([[0.25, 0.5, -0.25], [0.5, 0.5, 0.0], [0.75, 0.5, 0.25]]);
        assert_eq!(r.bound, 0.0);
        assert!((got - 1.0).abs() < 1e-15, "{got}");
    }

    /// The unit box and one more triangle, resolved: what was decided and the volume it encloses.
    fn unit_box_and(triangle: Corners) -> (Resolved, f64) {
        let mut vertices = Vec::new();
        let mut tris = Vec::new();
        push_box(&mut vertices, &mut tris, [0.0; 3], [1.0; 3]);
        let base = vertices.len() as u32;
        vertices.extend(triangle);
        tris.push([base, base + 1, base + 2]);
        let signs = vec![1; tris.len()];
        let r = resolve(&vertices, &tris, &signs, &[], [0.5; 3], 0.0);
        let got = enclosed(&vertices, &r);
        (r, got)
    }

    /// A sliver through a box's bottom: corners 2⁻⁵⁰ from one line, so its own plane's band
    /// (the margin over the sine of its angle, about 1e3 here) holds the whole bottom. Cut along
    /// the plane through its longest edge across the bottom instead, the bottom is two cells,
    /// each decided: the box, with nothing undecided but the sliver's own pieces (area 1e-16).
    #[test]
    fn a_sliver_cuts_along_its_longest_edge() {
        let off = 0.5 + 2f64.powi(-50);
        let (r, got) = unit_box_and([[0.25, 0.5, -0.25], [0.75, 0.5, 0.25], [0.5, off, 0.0]]);
        assert!(r.bound < 1e-15, "{}", r.bound);
        assert!((got - 1.0).abs() < 1e-15, "{got}");
    }

    /// Two closed shells touching along an edge, a wall of no thickness between them: the unit box,
    /// and a box from x ≈ 1 to 2 whose face at x ≈ 1 shares the unit box's edge at y = 0, x = 1
    /// and bends by ε = 2⁻³⁰ (its corners (1 − ε, 1, 1) and (1 + ε, 1, 0)), so that it dips into
    /// the unit box over part of its face and stays out of it over the rest. That face's triangles
    /// lie within [`NEAR`] of the unit box's, share an edge with one of them and a corner with
    /// the other, and cross one of them: some pairs are taken as in one plane, some decided by
    /// rays. The decided surface closes up to the wall's thickness, and the volume is the union's
    /// within the bound. By hand: the second box 1 + ε/6 (its face's mean depth), of which ε/4
    /// lies inside the unit box (ε/6 under the triangle at z ≥ y, ε/12 under the other), so
    /// 2 − ε/12.
    #[test]
    fn a_wall_of_no_thickness_closes_and_keeps_the_union() {
        let e = 2f64.powi(-30);
        let mut vertices = Vec::new();
        let mut tris = Vec::new();
        push_box(&mut vertices, &mut tris, [0.0; 3], [1.0; 3]);
        // The unit box's corners (1, 0, 0) and (1, 0, 1); then the second box's own.
        let (p0, p1) = (1, 5);
        let base = vertices.len() as u32;
        vertices.extend([[1.0 - e, 1.0, 1.0], [1.0 + e, 1.0, 0.0]]);
        vertices.extend([[2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [2.0, 1.0, 1.0], [2.0, 0.0, 1.0]]);
        let (a, b, f00, f10, f11, f01) = (base, base + 1, base + 2, base + 3, base + 4, base + 5);
        tris.extend([
            [p0, p1, a],
            [p0, a, b],
            [f00, f10, f11],
            [f00, f11, f01],
            [p0, f00, f01],
            [p0, f01, p1],
            [b, a, f11],
            [b, f11, f10],
            [p0, b, f10],
            [p0, f10, f00],
            [p1, f01, f11],
            [p1, f11, a],
        ]);
        let signs = vec![1; tris.len()];
        let r = resolve(&vertices, &tris, &signs, &[], [1.0, 0.5, 0.5], 0.0);
        let open = norm(area_vector(&vertices, &r));
        assert!(open < 4.0 * e, "decided surface open: vector area {open:e}");
        let got = enclosed(&vertices, &r);
        let want = 2.0 - e / 12.0;
        assert!((got - want).abs() <= r.bound + 1e-15, "{got} against {want}, bound {}", r.bound);
    }

    /// The pair test with the planes' precomputed sides ([`Faces::touch`]) answers as the one with
    /// `orient3d` ([`super::super::triangles_touch`]): on pairs of triangles whose corners lie on
    /// a lattice of three steps of 0.1 (inexact in binary), many of them coplanar, touching along
    /// an edge or at a corner, crossing, or degenerate.
    #[test]
    fn plane_sides_touch_as_orient3d_does() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            f64::from((seed >> 33) as u32 % 3) * 0.1
        };
        let (mut touching, mut apart) = (0, 0);
        for _ in 0..20_000 {
            let vertices: Vec<[f64; 3]> = (0..6).map(|_| [next(), next(), next()]).collect();
            let (x, y) = ([0, 1, 2], [3, 4, 5]);
            let (px, py) = (x.map(|i| vertices[i as usize]), y.map(|i| vertices[i as usize]));
            let (plane_x, plane_y) = (Plane::new(&px), Plane::new(&py));
            let got = corners_touch(&px, &py, (|q| plane_x.side(q), |q| plane_y.side(q)));
            assert_eq!(got, super::super::triangles_touch(&vertices, &x, &y), "{vertices:?}");
            if got {
                touching += 1;
            } else {
                apart += 1;
            }
        }
        assert!(touching > 1000 && apart > 1000, "{touching} {apart}");
    }

    /// Whether triangle `u` meets triangle `t` (integer corners, `t` not flat, `u` not in `t`'s
    /// plane) anywhere but at `t`'s first corner, in exact rationals: `u`'s section by `t`'s plane
    /// (a segment or a point) against the barycentric coordinates of `t`.
    fn meets_beyond_first(t: [[i64; 3]; 3], u: [[i64; 3]; 3]) -> bool {
        use num_rational::Ratio;
        type Q = Ratio<i128>;
        let d3 = |a: [i64; 3], b: [i64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let (e1, e2) = (d3(t[1], t[0]), d3(t[2], t[0]));
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let dist = |p: [i64; 3]| {
            let q = d3(p, t[0]);
            i128::from(n[0] * q[0] + n[1] * q[1] + n[2] * q[2])
        };
        let q = |p: [i64; 3]| p.map(|x| Q::from_integer(i128::from(x)));
        let mut section: Vec<[Q; 3]> = Vec::new();
        for i in 0..3 {
            let (a, b) = (u[i], u[(i + 1) % 3]);
            let (da, db) = (dist(a), dist(b));
            if da == 0 {
                section.push(q(a));
            }
            if (da < 0 && db > 0) || (da > 0 && db < 0) {
                let s = Q::new(da, da - db);
                let (qa, qb) = (q(a), q(b));
                section.push([0, 1, 2].map(|k| qa[k] + s * (qb[k] - qa[k])));
            }
        }
        if section.is_empty() {
            return false;
        }
        let k = (0..3).max_by_key(|&k| n[k].abs()).unwrap_or(2);
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let orient = |a: &[Q; 3], b: &[Q; 3], c: &[Q; 3]| (b[i] - a[i]) * (c[j] - a[j]) - (b[j] - a[j]) * (c[i] - a[i]);
        let tq = t.map(q);
        let area = orient(&tq[0], &tq[1], &tq[2]);
        // The section's ends: the two of its points farthest apart.
        let (mut a, mut b) = (section[0], section[0]);
        for x in &section {
            for y in &section {
                let len = |p: &[Q; 3], r: &[Q; 3]| (0..3).map(|k| (p[k] - r[k]) * (p[k] - r[k])).sum::<Q>();
                if len(x, y) > len(&a, &b) {
                    (a, b) = (*x, *y);
                }
            }
        }
        // λ_m(s) = α + β s along a + s (b − a), s in [0, 1]: in `t` where every λ_m ≥ 0, and
        // not its first corner where λ_1 + λ_2 > 0.
        let lambda = |m: usize, x: &[Q; 3]| orient(&tq[(m + 1) % 3], &tq[(m + 2) % 3], x) / area;
        let zero = Q::from_integer(0);
        let (mut lo, mut hi) = (zero, Q::from_integer(1));
        for m in 0..3 {
            let alpha = lambda(m, &a);
            let beta = lambda(m, &b) - alpha;
            if beta == zero {
                if alpha < zero {
                    return false;
                }
                continue;
            }
            let bound = -alpha / beta;
            if beta > zero {
                lo = lo.max(bound);
            } else {
                hi = hi.min(bound);
            }
        }
        let beyond = |s: Q| {
            let x = [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]));
            lambda(1, &x) + lambda(2, &x) > zero
        };
        lo <= hi && (beyond(lo) || beyond(hi))
    }

    /// Triangles sharing a corner on a small integer lattice, one not in the other's plane:
    /// `shares_corner` says whether one meets the other anywhere but at that corner exactly, as
    /// exact rationals do (it was conservative where a corner of either lay in the other's plane:
    /// it took every such pair as meeting).
    #[test]
    fn a_triangle_sharing_a_corner_blocks_exactly_where_it_meets_the_other_beyond_it() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            i64::from((seed >> 33) as u32 % 5) - 2
        };
        let (mut meet, mut apart, mut on_plane) = (0, 0, 0);
        for _ in 0..200_000 {
            let v = [next(), next(), next()];
            let p: Vec<[i64; 3]> = (0..4).map(|_| [next(), next(), next()]).collect();
            let (t, u) = ([v, p[0], p[1]], [v, p[2], p[3]]);
            let f = |x: [[i64; 3]; 3]| x.map(|c| c.map(|a| a as f64));
            let (ft, fu) = (f(t), f(u));
            if collinear(ft) || collinear(fu) {
                continue;
            }
            let (plane_t, plane_u) = (Plane::new(&ft), Plane::new(&fu));
            let sides = (plane_t.side(fu[1]), plane_t.side(fu[2]));
            if (sides.0 == 0.0 && sides.1 == 0.0) || (sides.0 > 0.0 && sides.1 > 0.0) || (sides.0 < 0.0 && sides.1 < 0.0) {
                continue;
            }
            let tu = (plane_u.side(ft[1]), plane_u.side(ft[2]));
            if sides.0 == 0.0 || sides.1 == 0.0 || tu.0 == 0.0 || tu.1 == 0.0 {
                on_plane += 1;
            }
            let got = shares_corner(ft, fu, sides, &plane_u);
            assert_eq!(got, meets_beyond_first(t, u), "{t:?} {u:?}");
            if got {
                meet += 1;
            } else {
                apart += 1;
            }
        }
        assert!(meet > 1000 && apart > 1000 && on_plane > 1000, "{meet} {apart} {on_plane}");
    }

    /// A sphere of `n` rings of `2n` quads (triangles at the poles), facing out: no two of its
    /// triangles lie in one plane.
    fn push_sphere(vertices: &mut Vec<[f64; 3]>, tris: &mut Vec<[u32; 3]>, centre: [f64; 3], r: f64, n: u32) {
        let base = vertices.len() as u32;
        let m = 2 * n;
        vertices.push([centre[0], centre[1], centre[2] + r]);
        for i in 1..n {
            let theta = std::f64::consts::PI * f64::from(i) / f64::from(n);
            for j in 0..m {
                let phi = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(m);
                let (st, ct, sp, cp) = (theta.sin(), theta.cos(), phi.sin(), phi.cos());
                vertices.push([centre[0] + r * st * cp, centre[1] + r * st * sp, centre[2] + r * ct]);
            }
        }
        vertices.push([centre[0], centre[1], centre[2] - r]);
        let ring = |i: u32, j: u32| base + 1 + (i - 1) * m + j % m;
        let south = base + 1 + (n - 1) * m;
        for j in 0..m {
            tris.push([base, ring(1, j), ring(1, j + 1)]);
            tris.push([south, ring(n - 1, j + 1), ring(n - 1, j)]);
            for i in 1..n - 1 {
                tris.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
                tris.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
            }
        }
    }

    /// A torus about the z axis (radii `big` and `small`, `n` × `m` quads as two triangles each),
    /// facing out.
    fn push_torus(vertices: &mut Vec<[f64; 3]>, tris: &mut Vec<[u32; 3]>, (big, small): (f64, f64), (n, m): (u32, u32)) {
        let base = vertices.len() as u32;
        for i in 0..n {
            let u = 2.0 * std::f64::consts::PI * f64::from(i) / f64::from(n);
            for j in 0..m {
                let v = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(m);
                let r = big + small * v.cos();
                vertices.push([r * u.cos(), r * u.sin(), small * v.sin()]);
            }
        }
        let at = |i: u32, j: u32| base + (i % n) * m + j % m;
        for i in 0..n {
            for j in 0..m {
                tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }

    /// A bipyramid over a pentagram: five corners 144° apart around the axis (the equator winds
    /// twice), an apex above and one below, a little off the axis. Every edge is shared by two of
    /// its ten triangles with opposite directions, and each triangle is seen from the front from
    /// the mean of its corners, but the triangles cross one another: the surface covers the
    /// directions around that point twice.
    fn pentagram_bipyramid() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut vertices = vec![[0.1, 0.05, 1.0], [-0.07, 0.03, -1.0]];
        for k in 0..5 {
            let a = 0.3 + 4.0 * std::f64::consts::PI * f64::from(k) / 5.0;
            vertices.push([a.cos(), a.sin(), 0.2]);
        }
        let ring = |k: u32| 2 + k % 5;
        let mut tris = Vec::new();
        for k in 0..5 {
            tris.push([0, ring(k), ring(k + 1)]);
            tris.push([1, ring(k + 1), ring(k)]);
        }
        (vertices, tris)
    }

    fn corners_and_planes(vertices: &[[f64; 3]], tris: &[[u32; 3]]) -> (Vec<Corners>, Vec<Plane>) {
        let corners: Vec<Corners> = tris.iter().map(|t| t.map(|i| vertices[i as usize])).collect();
        let planes = corners.iter().map(Plane::new).collect();
        (corners, planes)
    }

    /// The certificate that a sealed shell's triangles meet only where they share corners or
    /// edges: a box (also turned inside out), a sphere and a box with a dent it can see past are
    /// certified; a torus (seen from its hole, its inner side faces away) is not; nor is the
    /// pentagram bipyramid, whose every triangle faces the mean corner as a convex shell's would
    /// but whose triangles cross one another: one ray from that point crosses two of them.
    #[test]
    fn embedded_certifies_shells_seen_once_from_a_point() {
        let certified = |vertices: &[[f64; 3]], tris: &[[u32; 3]]| {
            let (corners, planes) = corners_and_planes(vertices, tris);
            embedded(&corners, &planes)
        };
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_box(&mut vertices, &mut tris, [0.0; 3], [1.0, 2.0, 3.0]);
        assert!(certified(&vertices, &tris));
        let inward: Vec<[u32; 3]> = tris.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert!(certified(&vertices, &inward));
        // The top's centre pushed down a little: a fan of four triangles in place of the top's two.
        let mut dented = tris[..2].to_vec();
        dented.extend_from_slice(&tris[4..]);
        let centre = vertices.len() as u32;
        vertices.push([0.5, 1.0, 2.5]);
        let top = [4, 5, 7, 6];
        for k in 0..4 {
            dented.push([top[k], top[(k + 1) % 4], centre]);
        }
        assert_eq!(dented.len(), 14);
        assert!(certified(&vertices, &dented));
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_sphere(&mut vertices, &mut tris, [0.3, -0.2, 0.1], 0.8, 12);
        assert!(certified(&vertices, &tris));
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_torus(&mut vertices, &mut tris, (1.0, 0.3), (24, 12));
        assert!(!certified(&vertices, &tris));
        let (vertices, tris) = pentagram_bipyramid();
        let (corners, planes) = corners_and_planes(&vertices, &tris);
        let c = corners.iter().flatten().fold([0.0; 3], |s, p| in_order(|k| s[k] + p[k])).map(|x| x / 30.0);
        let first = planes[0].side(c);
        assert!(planes.iter().all(|p| p.side(c) * first > 0.0), "every triangle faces the same way");
        assert_eq!(hits(c, [10.0, c[1], c[2]], 0, &corners, &planes), Some(2));
        assert!(!embedded(&corners, &planes));
    }

    /// Certified shells are not searched for their own pairs, and decide as the search decides:
    /// two spheres cutting each other enclose the same volume, with nothing undecided, and no
    /// more triangles cut. The pentagram bipyramid with a box through it is not certified, and
    /// comes out the same bit for bit with its range given or not.
    #[test]
    fn certified_shells_decide_as_the_search_does() {
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_sphere(&mut vertices, &mut tris, [0.0; 3], 1.0, 24);
        let first = tris.len();
        push_sphere(&mut vertices, &mut tris, [0.83, 0.21, 0.13], 0.7, 20);
        let signs = vec![1; tris.len()];
        let at = ([0.4, 0.1, 0.1], 0.0);
        let sealed = [0..first, first..tris.len()];
        let (corners, planes) = corners_and_planes(&vertices, &tris);
        let ends = certified_ends(&corners, &planes, &sealed);
        assert!(ends[..first].iter().all(|&e| e as usize == first));
        assert!(ends[first..].iter().all(|&e| e as usize == tris.len()));
        let searched = resolve_with(&vertices, &tris, &signs, at, (true, CROWDED_GRID, MAX_GROUPED), &[]);
        let passed = resolve_with(&vertices, &tris, &signs, at, (true, CROWDED_GRID, MAX_GROUPED), &sealed);
        let tree = resolve_with(&vertices, &tris, &signs, at, (true, 0, MAX_GROUPED), &sealed);
        assert_eq!((searched.bound, passed.bound, tree.bound), (0.0, 0.0, 0.0));
        assert!(passed.cut <= searched.cut && passed.cut > 0, "{} against {}", passed.cut, searched.cut);
        let (want, got) = (enclosed(&vertices, &searched), enclosed(&vertices, &passed));
        assert!((got - want).abs() < 1e-14 * want, "{got} against {want}");
        assert_eq!(enclosed(&vertices, &tree).to_bits(), got.to_bits());

        let (mut vertices, mut tris) = pentagram_bipyramid();
        let star = tris.len();
        push_box(&mut vertices, &mut tris, [-0.2, -0.15, -0.3], [0.25, 0.2, 0.45]);
        let signs = vec![1; tris.len()];
        let plain = resolve_with(&vertices, &tris, &signs, at, (true, CROWDED_GRID, MAX_GROUPED), &[]);
        let given = resolve_with(&vertices, &tris, &signs, at, (true, CROWDED_GRID, MAX_GROUPED), &[0..star, star..tris.len()]);
        let faces = |r: &Resolved| r.faces.iter().map(<[u32]>::to_vec).collect::<Vec<_>>();
        assert!(plain.cut > 0 && faces(&plain) == faces(&given) && plain.vertices == given.vertices);
        assert_eq!((plain.bound, plain.cut), (given.bound, given.cut));
    }

    /// Two spheres that cut each other: the pieces decided from another piece's rays (of their own
    /// triangle, or across a shared edge, counting the triangles between) are decided as their own
    /// rays decide them (the same faces, in the same order, with nothing left undecided), and
    /// those across an edge are most first pieces of the cut triangles.
    #[test]
    fn pieces_joined_across_edges_are_decided_as_their_own_rays_decide() {
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_sphere(&mut vertices, &mut tris, [0.0; 3], 1.0, 24);
        push_sphere(&mut vertices, &mut tris, [0.83, 0.21, 0.13], 0.7, 20);
        let signs = vec![1; tris.len()];
        let joined = resolve_with(&vertices, &tris, &signs, ([0.4, 0.1, 0.1], 0.0), (true, CROWDED_GRID, MAX_GROUPED), &[]);
        let alone = resolve_with(&vertices, &tris, &signs, ([0.4, 0.1, 0.1], 0.0), (false, CROWDED_GRID, MAX_GROUPED), &[]);
        assert_eq!(alone.joined_across, 0);
        // Joins that pass through the other sphere count its triangles (`alone` asks rays for
        // every piece): the same decisions.
        assert!(joined.joins_counted > 0 && alone.joins_counted == 0);
        assert!(joined.joined_across * 2 > joined.cut, "{} of {}", joined.joined_across, joined.cut);
        assert_eq!((joined.bound, alone.bound), (0.0, 0.0));
        let faces = |r: &Resolved| r.faces.iter().map(<[u32]>::to_vec).collect::<Vec<_>>();
        assert!(faces(&joined) == faces(&alone), "the faces emitted differ");
        assert!(joined.vertices == alone.vertices, "the pieces' corners differ");
    }

    /// The pairs of triangles that meet, from the tree and from the grid: the same blockers in the
    /// same order, so the same faces, corners and bound (spheres cutting each other, and a pile of
    /// coplanar, crossing tetrahedra).
    #[test]
    fn blockers_from_the_tree_are_the_grids() {
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_sphere(&mut vertices, &mut tris, [0.0; 3], 1.0, 24);
        push_sphere(&mut vertices, &mut tris, [0.83, 0.21, 0.13], 0.7, 20);
        let spheres = (vertices, tris);
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        for i in 0..40u32 {
            let x = f64::from(i) / 64.0;
            vertices.extend([[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0], [x, 0.0, 1.0]]);
            let b = 4 * i;
            tris.extend([[b, b + 2, b + 1], [b, b + 1, b + 3], [b + 1, b + 2, b + 3], [b, b + 3, b + 2]]);
        }
        for (vertices, tris) in [spheres, (vertices, tris)] {
            let signs = vec![1; tris.len()];
            let at = ([0.4, 0.1, 0.1], 0.0);
            let grid = resolve_with(&vertices, &tris, &signs, at, (true, u64::MAX, MAX_GROUPED), &[]);
            let tree = resolve_with(&vertices, &tris, &signs, at, (true, 0, MAX_GROUPED), &[]);
            assert!(grid.cut > 0 && !grid.crowded && !tree.crowded);
            assert_eq!((grid.cut, grid.bound, grid.rounding), (tree.cut, tree.bound, tree.rounding));
            let faces = |r: &Resolved| r.faces.iter().map(<[u32]>::to_vec).collect::<Vec<_>>();
            assert!(faces(&grid) == faces(&tree), "the faces emitted differ");
            assert!(grid.vertices == tree.vertices, "the pieces' corners differ");
        }
    }

    /// A triangle of area 8 with a smaller one turned the other way lying in its plane (area
    /// 0.53, off its edges and of no regular position): where the small one covers it the two
    /// cancel and the big one carries nothing, elsewhere it bounds alone. So the faces emitted add
    /// up to 8 − 0.53 along +z, exactly as the small one's edges cut the big one: a cut along an edge's line
    /// beyond the edge's end would be harmless, none where the edge runs would decide a cell on
    /// both sides of it from one point. Also moved elsewhere inside, and across the big one's
    /// long edge (there, outside it, the small one bounds alone, facing −z).
    #[test]
    fn a_coplanar_triangle_cuts_where_its_edges_run() {
        for shift in [[0.0, 0.0], [0.7, 0.3], [1.3, 0.2]] {
            let small = [[1.1, 0.9], [1.3, 1.9], [2.2, 1.1]];
            let mut vertices = vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
            // Turned round (clockwise seen from +z).
            for p in small {
                vertices.push([p[0] + shift[0], p[1] + shift[1], 0.0]);
            }
            let small_area = {
                let [a, b, c] = [vertices[3], vertices[4], vertices[5]];
                -cross(sub(b, a), sub(c, a))[2] / 2.0
            };
            assert!(small_area > 0.0);
            let tris = [[0, 1, 2], [3, 4, 5]];
            let r = resolve(&vertices, &tris, &[1, 1], &[], [1.0, 1.0, 1.0], 0.0);
            let got = area_vector(&vertices, &r);
            assert_eq!(r.bound, 0.0, "shift {shift:?}");
            assert!((got[2] - (8.0 - small_area)).abs() < 1e-12, "shift {shift:?}: {got:?}");
            assert!(got[0].abs() < 1e-15 && got[1].abs() < 1e-15);
        }
    }

    /// A block over the square `[x0, x1] × [y0, y1]` (`n` × `n` cells, two triangles each), from
    /// `bottom` up to `top(x, y)`, on new vertices, facing out (the block is convex, so each
    /// triangle faces away from its centre).
    fn push_block(
        vertices: &mut Vec<[f64; 3]>,
        tris: &mut Vec<[u32; 3]>,
        ((x0, x1), (y0, y1), n): ((f64, f64), (f64, f64), usize),
        bottom: f64,
        top: impl Fn(f64, f64) -> f64,
    ) {
        let base = vertices.len() as u32;
        let at = |i: usize, j: usize| (x0 + (x1 - x0) * i as f64 / n as f64, y0 + (y1 - y0) * j as f64 / n as f64);
        for floor in [false, true] {
            for i in 0..=n {
                for j in 0..=n {
                    let (x, y) = at(i, j);
                    vertices.push([x, y, if floor { bottom } else { top(x, y) }]);
                }
            }
        }
        let v = |floor: usize, i: usize, j: usize| base + (floor * (n + 1) * (n + 1) + i * (n + 1) + j) as u32;
        let mut quads = Vec::new();
        for floor in 0..2 {
            for i in 0..n {
                for j in 0..n {
                    quads.push([v(floor, i, j), v(floor, i + 1, j), v(floor, i + 1, j + 1), v(floor, i, j + 1)]);
                }
            }
        }
        for k in 0..n {
            for (a, b) in [((k, 0), (k + 1, 0)), ((k, n), (k + 1, n)), ((0, k), (0, k + 1)), ((n, k), (n, k + 1))] {
                quads.push([v(0, a.0, a.1), v(0, b.0, b.1), v(1, b.0, b.1), v(1, a.0, a.1)]);
            }
        }
        let (xm, ym) = (f64::midpoint(x0, x1), f64::midpoint(y0, y1));
        let centre = [xm, ym, f64::midpoint(bottom, top(xm, ym))];
        for q in quads {
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                let p = t.map(|i| vertices[i as usize]);
                let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
                let mid = [0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0);
                tris.push(if dot(n, sub(mid, centre)) > 0.0 { t } else { [t[0], t[2], t[1]] });
            }
        }
    }

    /// A block whose top (triangles of one tilted plane P, far from the origin) has another
    /// block's top one ulp above it, over a square inside it: the two shells do not meet there, so
    /// the top's triangles under the other top are uncut, decided by rays from their centres. A
    /// centre is rounded by up to 1e-13 on x and y (coordinates near 1024), which moves it off P
    /// by up to 1e-14 along z, a hundred times the ulp between the tops: a ray from the centre
    /// upwards starts above the other top about half the time. Counted from there, the lower top
    /// had nothing in front (w = 0) and was kept, where in front of it is the other block (w = 1
    /// in the sliver, 2 behind): the union's top counted twice. The solid is the lower block and
    /// the sliver, whose volume is below 1e-16.
    #[test]
    fn a_face_an_ulp_below_another_is_decided_from_the_face_not_from_its_rounded_centre() {
        let plane = |x: f64, y: f64| 1.0 + (x - 1024.0) / 8.0 + (y - 1024.0) / 16.0;
        let up = |z: f64| f64::from_bits(z.to_bits() + 1);
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        push_block(&mut vertices, &mut tris, ((1024.0, 1025.0), (1024.0, 1025.0), 16), 0.0, plane);
        // Over odd multiples of 1/64 (A's grid lines are at multiples of 1/16), several squares.
        for (x, y) in [(1024.328125, 1024.234375), (1024.015625, 1024.578125), (1024.640625, 1024.703125)] {
            let square = ((x, x + 0.28125), (y, y + 0.171875), 1);
            push_block(&mut vertices, &mut tris, square, 0.5, |x, y| up(plane(x, y)));
        }
        let signs = vec![1; tris.len()];
        let r = resolve(&vertices, &tris, &signs, &[], [1024.5, 1024.5, 0.5], 0.0);
        assert_eq!(r.bound, 0.0);
        // The volume about (1024, 1024, 0), whose coordinates are exact differences.
        let moved: Vec<[f64; 3]> = vertices.iter().map(|v| [v[0] - 1024.0, v[1] - 1024.0, v[2]]).collect();
        let pieces: Vec<[f64; 3]> = r.vertices.iter().map(|v| [v[0] - 1024.0, v[1] - 1024.0, v[2]]).collect();
        let got = enclosed(&moved, &Resolved { vertices: pieces, ..r });
        let want = 1.0 + 1.0 / 16.0 + 1.0 / 32.0;
        assert!((got - want).abs() < 1e-13, "{got} against {want}");
    }

    /// A triangle lying across the edge two faces share, meeting neither face's interior (in a
    /// plane through the edge, crossing it), is a blocker of both, so neither joins a patch across
    /// that edge: with no corner shared (closed edges against closed triangles) and with the
    /// edge's end shared (the edge's other end then lies in its plane).
    #[test]
    fn a_triangle_across_a_shared_edge_blocks_both_faces() {
        let vertices = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.3, 0.0, -1.0],
            [0.7, 0.0, -1.0],
            [0.5, 0.0, 1.0],
            [0.8, 0.0, -0.5],
            [0.8, 0.0, 0.5],
        ];
        let (t1, t2) = ([0, 1, 2], [1, 0, 3]);
        let across = [4, 5, 6];
        assert!(super::super::triangles_touch(&vertices, &t1, &across));
        assert!(super::super::triangles_touch(&vertices, &t2, &across));
        // Sharing corner 0: `u` from it through the edge, its other corners on either side.
        let u = [0u32, 7, 8];
        let at = |t: [u32; 3]| t.map(|i| vertices[i as usize]);
        for t in [t1, t2] {
            let i = t.iter().position(|&v| v == 0).unwrap();
            let (pt, pu) = (rotated(&at(t), i), at(u));
            let plane_t = Plane::new(&at(t));
            let sides = (plane_t.side(pu[1]), plane_t.side(pu[2]));
            assert!(sides.0 * sides.1 < 0.0);
            assert!(shares_corner(pt, pu, sides, &Plane::new(&pu)));
        }
    }

    /// Sweep case 33740's three tetrahedra (a box on a corner of the first changes nothing here):
    /// the first wound inward, the second the first moved 7.2e-16 along y (parallel faces that do
    /// not meet), the third the first with its corners moved by up to 1.6e-13, whose faces cut
    /// the other two's at slants near 1e-12. Ω is about the third (w = −1 + 1 + 1). The third's
    /// faces are near the planes of both others' and taken as in them, but the first two's do not
    /// meet: each of those two carried the third's jump as the lowest-numbered triangle of its
    /// plane, and the third carried nothing, so on two of the four sides all three were dropped
    /// and the surface was left open (its area vector 8.7e-8 m², a face's 5.9e-8). Taken as in
    /// one plane all three, each side is decided once.
    #[test]
    fn faces_near_one_plane_through_a_third_are_decided_as_one_plane() {
        let first = [
            [-94.38519640341579, 0.0037677824734437836, 0.0030094996909610927],
            [-94.3857382149314, 0.0034564920956139836, 0.002992742825881578],
            [-94.38580073521106, 0.0035166878615596787, 0.0027537564892554656],
            [-94.38541544227293, 0.0037932171617656787, 0.003040723444428295],
        ];
        let second = [
            [-94.38519640341579, 0.0037677824734445044, 0.0030094996909610927],
            [-94.3857382149314, 0.0034564920956147043, 0.002992742825881578],
            [-94.38580073521106, 0.0035166878615603995, 0.0027537564892554656],
            [-94.38541544227293, 0.0037932171617664, 0.003040723444428295],
        ];
        let third = [
            [-94.38519640341595, 0.003767782473380246, 0.0030094996909610927],
            [-94.38573821493131, 0.0034564920956977867, 0.002992742825881578],
            [-94.38580073521095, 0.0035166878616149895, 0.0027537564892554656],
            [-94.38541544227299, 0.003793217161690102, 0.003040723444428295],
        ];
        let (mut vertices, mut tris) = (Vec::new(), Vec::new());
        for (corners, inward) in [(first, true), (second, false), (third, false)] {
            let base = vertices.len() as u32;
            vertices.extend_from_slice(&corners);
            for t in [[0, 1, 2], [3, 1, 0], [0, 2, 3], [3, 2, 1]] {
                let t = if inward { [t[2], t[1], t[0]] } else { t };
                tris.push(t.map(|i| base + i));
            }
        }
        let signs = vec![1; tris.len()];
        let centre = [-94.3855, 0.0036, 0.0029];
        // The third tetrahedron's volume; the slivers between the three are below 1e-20 m³.
        let c = third.map(|x| sub(x, third[0]));
        let want = dot(c[1], cross(c[2], c[3])).abs() / 6.0;
        let about: Vec<[f64; 3]> = vertices.iter().map(|v| sub(*v, third[0])).collect();
        let volume = |r: Resolved| {
            let pieces: Vec<[f64; 3]> = r.vertices.iter().map(|v| sub(*v, third[0])).collect();
            enclosed(&about, &Resolved { vertices: pieces, ..r })
        };
        let r = resolve(&vertices, &tris, &signs, &[], centre, 0.0);
        let open = norm(area_vector(&vertices, &r));
        assert!(open < 1e-15, "the decided faces leave {open:e} m² open");
        assert!(!r.crowded);
        let got = volume(r);
        assert!((got - want).abs() < 1e-19, "{got:e} against {want:e}");
        // Past the budget of pairs the groups may add, no triangle is cut: each is left as
        // classified, and the bound holds what that can change.
        let r = resolve_with(&vertices, &tris, &signs, (centre, 0.0), (true, CROWDED_GRID, 0), &[]);
        assert!(r.crowded);
        let bound = r.bound;
        let got = volume(r);
        assert!((got - want).abs() <= bound, "{got:e} against {want:e}, bound {bound:e}");
    }
}
