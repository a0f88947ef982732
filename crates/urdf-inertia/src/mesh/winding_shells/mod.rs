//! Shells that overlap: which faces of a repaired surface bound its solid Ω = {x : |w(x)| ≥ ½}, w the
//! winding number of the surface.
//!
//! Integrating every face gives ∫w, which counts a region enclosed by two shells twice (|w| = 2). A
//! shell here is a connected component over edges that two faces share with opposite directions. For
//! two closed shells that do not touch (exact segment–triangle tests with `orient3d`), one lies wholly
//! inside the other or outside it, and the other's winding number on it is an integer that one point
//! decides. Then w on the two sides of each shell is known exactly: `w_out` (the sum over the shells
//! around it) and `w_in` = `w_out` ± 1. A shell bounds Ω only when exactly one side is 0: it counts once,
//! outward when `w_out` = 0 (so an inside-out shell counts once) and inward when `w_in` = 0 (a cavity);
//! when both sides are inside Ω (an internal wall, a doubly enclosed shell) it drops out.
//!
//! Closed shells that touch or cut each other (and the shells around them) are decided face by face
//! ([`correction`]): a piece of face that no other triangle meets has one winding number in front of
//! it, which an exact ray counts; the pieces along the cuts that stay undecided bound the error. A
//! cluster is decided so when its edges balance (a closed cycle), if need be on the surface as the
//! file stores it: cracks welded ([`cracks`]), copies of faces that welding dropped put back; and
//! wherever it balances with them so, the faces the ladder turned round are turned back (the file's
//! winding number defines Ω). Pairs with an open shell even so are not decided: the region they can
//! count twice lies in the intersection of their bounding boxes (a closed shell's winding number is
//! 0 outside its box), whose volume enters the error estimate.

mod bvh;
mod cells;
mod correction;
pub(crate) use correction::MAX_MEETING;
mod cracks;
mod exact;
mod grid;
mod nesting;

use crate::geometry::{cross, dot, norm, solid_angle, starts, sub, sweep_in, sweep_visits, Aabb};
use crate::mass::Polygons;
use crate::mesh::weld;
use grid::orient3d;
use robust::Coord3D;
use rustc_hash::FxHashMap;
use std::ops::ControlFlow;

/// Pairs of shells that need work of their own (they touch, or a shell is open or closed only up to
/// cracks) beyond this many are not decided one by one: all pairs are bounded.
const MAX_PAIRS: usize = 20_000;

/// Pairs of shells with overlapping boxes beyond this many are not decided, and not bounded: those
/// found are not all (the sum of their boxes' intersections bounded only them). Those that need no
/// work of their own (closed shells nested in each other) cost a few words each.
pub(crate) const MAX_BOX_PAIRS: usize = 4_000_000;

/// Box tests beyond which the search for overlapping boxes stops, on the cheapest axis
/// ([`box_pairs`]; about 9 ns each, so about 2 s): the shells are then not decided, and not bounded.
const MAX_SWEEP_VISITS: u64 = 200_000_000;

/// Pairs of shells with overlapping boxes up to this many are decided pair by pair ([`nesting`]);
/// more, all at once ([`nesting::nestings`]). Pair by pair costs pairs × their triangles, all at
/// once a tree over every closed shell's triangles, which costs a real surface of a few shells
/// 12–14% more instructions (G1 `torso_link_rev_1_0.STL`, cassie `hip-yaw.stl`) and wins only when
/// the pairs are many (figures: docs/benchmarks.md, "Shells, round 32").
const FEW_PAIRS: usize = 1_024;

/// Segment–triangle tests per pair of shells, pair by pair, beyond which the pair is bounded, not
/// decided.
const MAX_TESTS: usize = 4_000_000;

/// A shell with boundary edges (cracks left open) is classified like a closed one when its volume
/// moves with the reference point by at most this share of itself; the move enters the bound.
const NEARLY_CLOSED: f64 = 1e-3;

/// A winding number this far from an integer is not trusted to decide nesting (a point too close to
/// the other shell for f64 solid angles).
const NOT_INTEGER: f64 = 0.1;

/// What the shells' classification did to a surface.
#[derive(Debug, Clone, Default)]
pub struct ShellOutcome {
    /// The faces that bound Ω, oriented so that their integral is its volume (as far as decided).
    pub faces: Polygons,
    /// Shells that dropped out (both sides inside Ω) and their faces.
    pub dropped_shells: usize,
    pub dropped_faces: usize,
    /// Shells turned round (inside-out alone, or a cavity wound outward inside another).
    pub turned_shells: usize,
    /// Pairs of shells whose boxes overlap but that touch, cut each other or are open.
    pub undecided_pairs: usize,
    /// Bound on the volume those pairs can count twice or cancel, m³: their boxes' intersections.
    pub overlap_bound: f64,
    /// Pairs of shells decided face by face: two closed shells that touch or cut each other, or a
    /// pair with an open shell whose cluster of open shells closes up (see [`classify_faces`]).
    pub resolved_pairs: usize,
    /// Of `resolved_pairs`, those with an open shell.
    pub resolved_open: usize,
    /// Their boxes' intersections, m³: what those pairs could count twice were they not decided.
    pub resolved_box_overlap: f64,
    /// Their triangles that other triangles cut (split into pieces).
    pub cut_faces: usize,
    /// Copies of faces that welding dropped, put back to decide them; faces the ladder turned round,
    /// turned back; whether cracks were welded (see [`classify`]).
    pub copies_restored: usize,
    pub turned_back: usize,
    /// Faces of cancelling pairs (walls of no thickness) put back to decide the shells.
    pub walls_restored: usize,
    pub cracks_welded: bool,
    /// Faces the ladder turned round, in all (where shells were decided face by face): when
    /// `turned_back` is all of them, the ladder's orientation enters the solid nowhere.
    pub turned: usize,
    /// Every face was decided face by face or lies on a sealed shell, on the surface exactly as
    /// stored (all copies put back, every face turned round turned back, no face added): the solid
    /// is Ω of the file's surface up to the bounds here, whatever the rung assumed about its
    /// closure and orientation.
    pub whole_as_stored: bool,
    /// What the pieces left undecided and the rounding of the cut points can change: volume (m³),
    /// within a ball (centre, radius).
    pub resolved_bound: f64,
    /// The part of `resolved_bound` that the rounding of the cut points can change, m³.
    pub cut_rounding: f64,
    /// Triangles left undecided whole, too many of them meeting to cut them (0 when they were cut).
    pub crowded: usize,
    pub ball: ([f64; 3], f64),
    /// The pieces' corners, numbered on from the surface's vertices.
    pub vertices: Vec<[f64; 3]>,
    /// Whether anything changed (faces dropped, turned or split).
    pub changed: bool,
}

/// The pieces of faces left undecided may change the volume by at most this share of it.
const RESOLVED_TARGET: f64 = 1e-9;

/// One connected shell.
struct Shell {
    faces: Vec<u32>,
    /// Closed, or so nearly closed (cracks) that its volume moves by at most [`NEARLY_CLOSED`] of
    /// itself with the reference point; `motion` is then that move, m³.
    closed: bool,
    motion: f64,
    /// Every edge shared by exactly two of its faces with opposite directions (no cracks at all).
    sealed: bool,
    /// Twice the vector area (Σ of the fans' cross products), zero for a closed shell.
    area2: [f64; 3],
    /// Six times the signed volume about the surface's box centre.
    volume6: f64,
    /// The shell's box.
    bounds: Aabb,
    /// The balanced group of open shells it belongs to ([`groups`]), `u32::MAX` for none.
    group: u32,
    /// The box that pairs it with shells of other groups: its own, or for the first shell of a
    /// balanced group, the group's.
    reach: Aabb,
}

/// Classifies the shells of `faces` (see the module docs). A surface of one shell comes back as it is.
/// The shells decided face by face are decided with the copies of faces that welding dropped put
/// back (`stored.copies`: the winding number of the file's surface counts them), and where their
/// edges balance only so, with the faces the ladder turned round turned back (`stored.faces`).
pub fn classify(vertices: &[[f64; 3]], faces: &Polygons, stored: &AsStored) -> ShellOutcome {
    if stored.pairs.is_empty() || faces.len() != stored.faces.len() {
        return classify_faces(vertices, faces, stored);
    }
    // The walls put back, at the end of both lists (so that the faces stay aligned with their
    // stored orientation): the bodies they separate become shells of their own, open along the
    // walls' rims, whose clusters balance and are decided face by face. That answer is taken where
    // it decided faces so, unless a shell with a wall among its faces was turned or dropped whole
    // and the answer without the walls turned or dropped other shells: pieces of a wall can also
    // make shells closed up to cracks that nesting would turn on their own, leaving the wall's
    // other faces as they were (sweep case 4137: 1.9e-8 off under 1.3e-8). Shells without a wall
    // may be dropped whole in one answer and decided face by face in the other, both right (sweep
    // case 63171: a small prism inside one of two prisms that cut each other over a dropped wall;
    // case 56891: an inward box inside three coincident ones, decided with them once their faces'
    // group reaches it, see [`groups`]). Otherwise the faces are classified without the pairs
    // (which cancel). The answer without the walls is sorted only where it is needed, and only the
    // answer taken is decided face by face, which is most of the cost.
    let mut with = faces.clone();
    let mut stored_with = stored.clone();
    for face in stored.pairs.iter() {
        with.push(face);
        stored_with.faces.push(face);
    }
    stored_with.pairs = Polygons::new();
    let with_sorted = sort(vertices, &with, &stored_with);
    let a = known(&with_sorted);
    let (resolved, charge) = (a.resolved_pairs, a.resolved_box_overlap);
    let decides = resolved > 0 || a.copies_restored > 0;
    let walls_whole = with_sorted.as_ref().map_or(0, |s| s.changed_whole_from(faces.len()));
    if decides && walls_whole == 0 {
        return with_walls(vertices, &with, &stored_with, with_sorted, stored.pairs.len());
    }
    let stored_without = AsStored { pairs: Polygons::new(), ..stored.clone() };
    let without_sorted = sort(vertices, faces, &stored_without);
    let b = known(&without_sorted);
    if decides && (a.turned_shells, a.dropped_shells) == (b.turned_shells, b.dropped_shells) {
        return with_walls(vertices, &with, &stored_with, with_sorted, stored.pairs.len());
    }
    // Refused: the bodies the walls joined may cut each other, and the answer without the walls
    // integrates such a body as one shell, its own overlap twice (sweep case 63171: two prisms
    // leaning into each other over a dropped wall, 7.9e-4 off under 6.2e-15). What they may count
    // twice lies in the intersections of the boxes of the pairs that touch or cut, which enter the
    // bound as undecided pairs.
    let mut without = decided(vertices, faces, &stored_without, without_sorted);
    if resolved > 0 {
        without.undecided_pairs += resolved;
        without.overlap_bound += charge;
    }
    without
}

/// The walls' answer of [`classify`], decided face by face.
fn with_walls(
    vertices: &[[f64; 3]],
    with: &Polygons,
    stored_with: &AsStored,
    sorted: Result<Sorted, ShellOutcome>,
    walls: usize,
) -> ShellOutcome {
    let mut out = decided(vertices, with, stored_with, sorted);
    out.walls_restored = walls;
    out
}

/// What a classification [`sort`]ed knows before any face is decided.
fn known(sorted: &Result<Sorted, ShellOutcome>) -> &ShellOutcome {
    match sorted {
        Ok(s) => &s.out,
        Err(out) => out,
    }
}

/// The shells' classification: [`sort`], then the faces of the shells that touch or cut decided
/// face by face.
fn classify_faces(vertices: &[[f64; 3]], faces: &Polygons, stored: &AsStored) -> ShellOutcome {
    decided(vertices, faces, stored, sort(vertices, faces, stored))
}

/// What the classification knows before any face is decided: the shells, which are decided face by
/// face (`relevant`) and how the others are turned or dropped whole, with the counts that
/// [`classify`] compares in `out`.
struct Sorted {
    shells: Vec<Shell>,
    tris: Vec<Vec<[u32; 3]>>,
    clusters: Clusters,
    flip: Vec<bool>,
    welded: Option<Vec<u32>>,
    relevant: Vec<bool>,
    copied: Vec<(usize, Vec<[u32; 3]>)>,
    keep: Vec<bool>,
    turn: Vec<bool>,
    sign: Vec<i64>,
    out: ShellOutcome,
}

impl Sorted {
    /// How many shells with a face from `walls` on were turned round or dropped whole (by their
    /// nesting), not left to the face-by-face decision.
    fn changed_whole_from(&self, walls: usize) -> usize {
        (self.shells.iter().zip(&self.relevant).zip(&self.sign))
            .filter(|((s, &r), &g)| !r && g != 1 && s.faces.iter().any(|&f| f as usize >= walls))
            .count()
    }
}

/// The classification up to the face-by-face decision: `Err` with the outcome where no face is
/// decided so (one shell, no pairs, too many, or none to decide).
// Both variants are large and made once or twice per surface, moved, never stored in bulk.
#[allow(clippy::result_large_err)]
fn sort(vertices: &[[f64; 3]], faces: &Polygons, stored: &AsStored) -> Result<Sorted, ShellOutcome> {
    let (shells, uses) = shells(vertices, faces);
    let unchanged = |undecided_pairs, overlap_bound| ShellOutcome {
        faces: faces.clone(),
        undecided_pairs,
        overlap_bound,
        ..ShellOutcome::default()
    };
    if shells.len() < 2 {
        return Err(unchanged(0, 0.0));
    }
    let Some(pairs) = overlapping_pairs(&shells) else {
        return Err(unchanged(MAX_BOX_PAIRS + 1, f64::INFINITY));
    };
    let tris: Vec<Vec<[u32; 3]>> = shells.iter().map(|s| fan(faces, &s.faces)).collect();
    // w_out per shell (the others' winding numbers on it), and whether every pair around it is
    // decided: for all pairs at once ([`nesting`]).
    let nestings = if pairs.len() <= FEW_PAIRS {
        Some(pair_by_pair(vertices, &shells, (&tris, &uses), &pairs))
    } else {
        nesting::nestings(vertices, &shells, &tris, &pairs)
    };
    let Some((w_out, decided)) = nestings else {
        let bound = pairs.iter().map(|&(a, b)| box_overlap(&shells[a], &shells[b])).sum();
        return Err(unchanged(pairs.len(), bound));
    };
    let mut out = ShellOutcome::default();
    // A pair with an undecided side is bounded whatever the other side's classification, unless
    // its cluster is a closed cycle, or both shells are: then it is decided face by face (the open
    // shells around sealed ones keep their pairs' bounds).
    let (clusters, flip, welded) = clusters(vertices, faces, stored, &shells, (&pairs, &decided), &uses);
    let mut relevant = clusters.relevant.clone();
    undecided_pairs(&shells, (&pairs, &decided), &mut relevant, &mut out);
    let (mut keep, mut turn) = (vec![true; faces.len()], vec![false; faces.len()]);
    let sign = orient(&shells, &decided, &w_out, &mut keep, &mut turn, &mut out);
    out.changed = out.dropped_shells > 0 || out.turned_shells > 0;
    if !relevant.iter().any(|&r| r) {
        out.faces = rebuilt(faces, &keep, &turn);
        return Err(out);
    }
    let copied = copied(&stored.copies, &clusters, &relevant);
    out.copies_restored = copied.len();
    Ok(Sorted {
        shells,
        tris,
        clusters,
        flip,
        welded,
        relevant,
        copied,
        keep,
        turn,
        sign,
        out,
    })
}

/// The faces of the `relevant` shells of `sorted` decided face by face ([`resolve_pairs`]), the
/// others as sorted.
fn decided(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    stored: &AsStored,
    sorted: Result<Sorted, ShellOutcome>,
) -> ShellOutcome {
    let Sorted {
        shells,
        tris,
        clusters,
        flip,
        welded,
        relevant,
        copied,
        mut keep,
        turn,
        sign,
        mut out,
    } = match sorted {
        Ok(s) => s,
        Err(out) => return out,
    };
    for (i, s) in shells.iter().enumerate() {
        if relevant[i] {
            s.faces.iter().for_each(|&f| keep[f as usize] = false);
        }
    }
    out.faces = rebuilt(faces, &keep, &turn);
    let welded = welded.as_deref();
    out.cracks_welded = welded.is_some();
    let (tris, turned) = as_stored(faces, &shells, &tris, &clusters.unflip, &flip);
    out.turned_back = turned;
    out.turned = flip.iter().filter(|&&f| f).count();
    out.whole_as_stored = (shells.iter().enumerate()).all(|(i, s)| relevant[i] || s.sealed)
        && copied.len() == stored.copies.len()
        && out.turned_back == out.turned
        && faces.len() == stored.faces.len();
    let set = ShellSet {
        shells: &shells,
        tris: &tris,
        relevant: &relevant,
        sign: &sign,
    };
    resolve_pairs(vertices, &set, &copied, welded, &mut out);
    // The decided faces differ from those given wherever faces were turned back or copies put
    // back, even where every face is kept as it came to `resolve` (which compares with those):
    // otherwise the faces given, turned, were integrated (sweep case 29472: an inward box
    // inside an outward one, turned by the ladder and decided as stored, counted outward,
    // 5.7% off under an estimate of 3e-14).
    out.changed |= out.turned_back > 0 || out.copies_restored > 0;
    out
}

/// Sorts the pairs with an undecided side: decided face by face where a shell of the pair is
/// `relevant` (its cluster a closed cycle) or both are sealed, which makes both relevant; bounded
/// otherwise (see [`classify_faces`]).
fn undecided_pairs(
    shells: &[Shell],
    (pairs, decided): (&[(usize, usize)], &[bool]),
    relevant: &mut [bool],
    out: &mut ShellOutcome,
) {
    for &(a, b) in pairs {
        if decided[a] && decided[b] {
            continue;
        }
        if relevant[a] || (shells[a].sealed && shells[b].sealed) {
            (relevant[a], relevant[b]) = (true, true);
            out.resolved_pairs += 1;
            out.resolved_open += usize::from(!shells[a].closed || !shells[b].closed);
            out.resolved_box_overlap += box_overlap(&shells[a], &shells[b]);
        } else {
            out.undecided_pairs += 1;
            out.overlap_bound += box_overlap(&shells[a], &shells[b]);
        }
    }
}

/// The surface as the file stores it, where the ladder's repairs changed it: its winding number
/// defines Ω.
#[derive(Debug, Clone, Default)]
pub struct AsStored {
    /// The faces in the same order as those classified, each in its stored orientation (the ladder
    /// may have turned some round to agree with their neighbours).
    pub faces: Polygons,
    /// Extra copies of faces, in their stored orientation, that welding dropped as duplicates.
    pub copies: Polygons,
    /// Faces that welding dropped in cancelling pairs (a face and its reverse: a wall of no
    /// thickness), as stored. Where they are, the faces are classified with them put back: a wall
    /// between two bodies joins them into one shell, which cuts itself where the bodies overlap.
    pub pairs: Polygons,
    /// The precision of the file's own numbers, which set the ladder's tolerant weld; cracks are
    /// welded with the same tolerance. Taken from the vertices when not given: of scaled
    /// coordinates (f32 times 0.001) that says f64, a tolerance far below the file's cracks.
    pub precision: Option<weld::Precision>,
}

/// [`resolvable`] on the faces as given (and the stored orientation of those `flip` marks), then,
/// when a cluster does not balance so, on welded corners: clusters left open by cracks alone
/// balance once welded, and are decided on welded corners (then returned too). `uses`: the faces'
/// edge uses ([`edge_uses`]).
fn clusters(
    vertices: &[[f64; 3]],
    faces: &Polygons,
    stored: &AsStored,
    shells: &[Shell],
    pairs: (&[(usize, usize)], &[bool]),
    uses: &[EdgeUse],
) -> (Clusters, Vec<bool>, Option<Vec<u32>>) {
    let flip = turned_round(faces, &stored.faces);
    let copies = (&stored.copies, &stored.faces, &flip[..]);
    let mut clusters = resolvable(faces, copies, shells, pairs, (uses, None));
    let welded = clusters
        .unbalanced
        .then(|| cracks::representatives(vertices, stored.precision));
    if let Some(rep) = &welded {
        let uses = edge_uses(vertices.len(), &numbered(faces), Some(rep));
        clusters = resolvable(faces, copies, shells, pairs, (&uses, Some(rep)));
    }
    (clusters, flip, welded)
}

/// Per edge: the shell of its first use, and its uses one way less the other, with the faces as
/// classified and as stored.
type EdgeSums = (u32, i64, i64);

/// Which shells [`resolvable`] gives to the face-by-face decision.
struct Clusters {
    relevant: Vec<bool>,
    /// Per shell: decided with its faces in their stored orientation (its cluster balances so).
    unflip: Vec<bool>,
    /// Whether some cluster holding an undecided pair does not balance.
    unbalanced: bool,
    /// Per extra copy of a face: the shell of the face it copies, when it has one.
    copy_shell: Vec<Option<usize>>,
    /// Per extra copy: whether the face it copies was turned round by the ladder (the copy is then
    /// turned with it on the surface as classified).
    copy_turned: Vec<bool>,
}

/// The shells to decide face by face: clusters of shells (joined by overlapping boxes, and by edges
/// they share where the surface is non-manifold) that hold an undecided pair and whose edges all
/// balance (as many uses each way: a closed cycle, whose winding number is an integer everywhere and
/// is counted exactly by a ray's crossings), counting the extra `copies` of faces and taking
/// vertices as their representatives `rep` when given (`uses`: the edge uses on them). A cluster
/// that balances in its stored orientation is decided so (the faces marked in `flip` turned back),
/// since the file's winding number defines Ω: a re-orientation that broke a closed cycle of the
/// file is undone, and so is one that kept the cycle closed, which still changes Ω (an inward box
/// whose sides the ladder turned one by one, each a component of its own where its corners weld
/// to an outward box's, made the two boxes' union, which the file's surface does not enclose:
/// sweep case 14946, one box off under an estimate of 1.5e-8). Otherwise it is decided with its
/// faces as classified (the ladder's repairs kept), where they balance so.
fn resolvable(
    faces: &Polygons,
    (copies, stored, flip): (&Polygons, &Polygons, &[bool]),
    shells: &[Shell],
    (pairs, decided): (&[(usize, usize)], &[bool]),
    (uses, rep): (&[EdgeUse], Option<&[u32]>),
) -> Clusters {
    let mut shell_of = vec![0u32; faces.len()];
    for (i, s) in shells.iter().enumerate() {
        s.faces.iter().for_each(|&f| shell_of[f as usize] = i as u32);
    }
    let mut parent: Vec<u32> = (0..shells.len() as u32).collect();
    for &(a, b) in pairs {
        join(&mut parent, a as u32, b as u32);
    }
    // The faces' edges, in order (each with the shell of its first use in face order), then the
    // edges that only copies use.
    // Two uses per edge on closed shells: room for as many edges, grown where there are more.
    let mut edges: Vec<(u64, EdgeSums)> = Vec::with_capacity(uses.len() / 2);
    for group in uses.chunk_by(|x, y| x.key == y.key) {
        if group[0].key >> 32 == group[0].key & 0xFFFF_FFFF {
            continue;
        }
        let first = shell_of[group[0].face as usize];
        let (mut net, mut as_stored) = (0, 0);
        for e in group {
            let d = if e.forward { 1 } else { -1 };
            net += d;
            as_stored += if flip[e.face as usize] { -d } else { d };
            join(&mut parent, first, shell_of[e.face as usize]);
        }
        edges.push((group[0].key, (first, net, as_stored)));
    }
    let copy_turned = copies_turned(copies, stored, flip, (uses, rep));
    let (copy_shell, extra) = copied_edges((copies, &copy_turned), rep, &mut edges, &mut parent);
    // Per cluster: open as classified, open as stored.
    let mut open = vec![(false, false); shells.len()];
    for &(s, net, as_stored) in edges.iter().map(|e| &e.1).chain(extra.values()) {
        let r = root(&mut parent, s) as usize;
        open[r].0 |= net != 0;
        open[r].1 |= as_stored != 0;
    }
    // A shell some of whose faces welding dropped as copies: the file's surface winds around it
    // once more per copy, which the nesting of shells (one winding number per shell) does not count,
    // so a cluster where it overlaps another shell is decided face by face, the copies put back (a
    // box stored twice around a box wound inward: w = 2 − 1 inside the inner one, which is in Ω,
    // not a cavity).
    let mut copied = vec![false; shells.len()];
    copy_shell.iter().flatten().for_each(|&s| copied[s] = true);
    let mut wanted = vec![false; shells.len()];
    for &(a, b) in pairs {
        if !decided[a] || !decided[b] || copied[a] || copied[b] {
            wanted[root(&mut parent, a as u32) as usize] = true;
        }
    }
    let roots: Vec<usize> = (0..shells.len() as u32)
        .map(|i| root(&mut parent, i) as usize)
        .collect();
    Clusters {
        relevant: roots.iter().map(|&r| wanted[r] && !(open[r].0 && open[r].1)).collect(),
        unflip: roots.iter().map(|&r| wanted[r] && !open[r].1).collect(),
        unbalanced: (0..shells.len()).any(|r| wanted[r] && open[r].0 && open[r].1),
        copy_shell,
        copy_turned,
    }
}

/// Per extra copy of a face: whether the face it copies (the stored face it repeats, found among the
/// uses of its first edge) was turned round by the ladder. A copy is the same face stored again: the
/// surface as classified turns it with its face, or else the two would cancel where the file's
/// surface counts the face twice (two coincident shells wound inward, one turned outward by the
/// ladder, cancelled each other: the sweep's case 1002).
fn copies_turned(
    copies: &Polygons,
    stored: &Polygons,
    flip: &[bool],
    (uses, rep): (&[EdgeUse], Option<&[u32]>),
) -> Vec<bool> {
    let at = |v: u32| rep.map_or(v, |r| r[v as usize]);
    copies
        .iter()
        .map(|face| {
            let key = edge_key(at(face[0]), at(face[1]));
            let from = uses.partition_point(|e| e.key < key);
            uses[from..]
                .iter()
                .take_while(|e| e.key == key)
                .map(|e| e.face as usize)
                .find(|&f| f < stored.len() && stored.face(f) == face)
                .is_some_and(|f| flip[f])
        })
        .collect()
}

/// The extra copies of faces counted in the faces' `edges` (sorted by edge), in order: each joins
/// the shell of the first use of its first edge (by a face, or by an earlier copy), when there is
/// one. Per copy, that shell; and the edges only copies use. A copy counts as stored, and as
/// classified turned with its face when the ladder turned that (`turned`).
fn copied_edges(
    (copies, turned): (&Polygons, &[bool]),
    rep: Option<&[u32]>,
    edges: &mut [(u64, EdgeSums)],
    parent: &mut [u32],
) -> (Vec<Option<usize>>, FxHashMap<u64, EdgeSums>) {
    let at = |v: u32| rep.map_or(v, |r| r[v as usize]);
    let mut extra: FxHashMap<u64, EdgeSums> = FxHashMap::default();
    let mut copy_shell = Vec::with_capacity(copies.len());
    for (c, face) in copies.iter().enumerate() {
        let key = edge_key(at(face[0]), at(face[1]));
        let shell = match edges.binary_search_by_key(&key, |e| e.0) {
            Ok(i) => Some(edges[i].1 .0),
            Err(_) => extra.get(&key).map(|e| e.0),
        };
        copy_shell.push(shell.map(|s| s as usize));
        let Some(shell) = shell else { continue };
        for k in 0..face.len() {
            let (u, v) = (at(face[k]), at(face[(k + 1) % face.len()]));
            if u == v {
                continue;
            }
            let key = edge_key(u, v);
            let e = match edges.binary_search_by_key(&key, |e| e.0) {
                Ok(i) => &mut edges[i].1,
                Err(_) => extra.entry(key).or_insert((shell, 0, 0)),
            };
            let d = if u < v { 1 } else { -1 };
            e.1 += if turned[c] { -d } else { d };
            e.2 += d;
            join(parent, e.0, shell);
        }
    }
    (copy_shell, extra)
}

pub(super) fn join(parent: &mut [u32], a: u32, b: u32) {
    let (a, b) = (root(parent, a), root(parent, b));
    parent[a.max(b) as usize] = a.min(b);
}

/// Turns and drops the decided closed shells (see the module docs); each shell's orientation as
/// kept: 1, −1 (turned) or 0 (dropped).
fn orient(
    shells: &[Shell],
    decided: &[bool],
    w_out: &[i64],
    keep: &mut [bool],
    turn: &mut [bool],
    out: &mut ShellOutcome,
) -> Vec<i64> {
    let mut sign = vec![1; shells.len()];
    for (i, s) in shells.iter().enumerate() {
        if !decided[i] || !s.closed || s.volume6 == 0.0 {
            continue;
        }
        // A nearly closed shell's classification holds up to the volume its cracks leave undefined.
        out.overlap_bound += s.motion;
        let own = if s.volume6 > 0.0 { 1 } else { -1 };
        let (outside, inside) = (w_out[i], w_out[i] + own);
        let wanted_outward = match (outside == 0, inside == 0) {
            (true, false) => true,
            (false, true) => false,
            _ => {
                out.dropped_shells += 1;
                out.dropped_faces += s.faces.len();
                s.faces.iter().for_each(|&f| keep[f as usize] = false);
                sign[i] = 0;
                continue;
            }
        };
        if wanted_outward != (own > 0) {
            out.turned_shells += 1;
            s.faces.iter().for_each(|&f| turn[f as usize] = true);
            sign[i] = -1;
        }
    }
    sign
}

/// The shells, their triangles, which are decided face by face and their orientation as classified.
#[derive(Clone, Copy)]
struct ShellSet<'a> {
    shells: &'a [Shell],
    tris: &'a [Vec<[u32; 3]>],
    relevant: &'a [bool],
    sign: &'a [i64],
}

/// Decides the faces of the `relevant` shells one by one ([`correction::resolve`]) and appends them
/// to `out.faces`; on welded corners when `welded` gives representatives ([`cracks`]).
fn resolve_pairs(
    vertices: &[[f64; 3]],
    set: &ShellSet<'_>,
    copied: &[(usize, Vec<[u32; 3]>)],
    welded: Option<&[u32]>,
    out: &mut ShellOutcome,
) {
    let (mut all, mut signs, mut sealed) = (Vec::new(), Vec::new(), Vec::new());
    let mut swept = 0.0;
    let ShellSet {
        shells,
        tris,
        relevant,
        sign,
    } = *set;
    let own = (0..shells.len()).filter(|&i| relevant[i]).map(|i| (i, &tris[i], true));
    let all_shells = own.chain(copied.iter().map(|(i, t)| (*i, t, false)));
    // Room for every triangle (a weld may drop some), each shell's appended without a copy.
    let room = all_shells.clone().map(|(_, t, _)| t.len()).sum();
    all.reserve(room);
    signs.reserve(room);
    for (i, tris, whole) in all_shells {
        let before = all.len();
        match welded {
            Some(rep) => {
                let (t, s) = cracks::welded_triangles(vertices, tris, rep);
                swept += s;
                all.extend(t);
            }
            None => all.extend_from_slice(tris),
        }
        signs.extend(std::iter::repeat_n(sign[i], all.len() - before));
        // A sealed shell's triangles as they are (not welded again), which `resolve` may certify
        // to meet one another only where they share corners or edges (a copy's come after them).
        if whole && welded.is_none() && shells[i].sealed {
            sealed.push(before..all.len());
        }
    }
    let volume: f64 = shells.iter().map(|s| s.volume6.abs() / 6.0).sum();
    let bounds = Aabb::of(vertices.iter().copied());
    let centre = crate::mass::integrals::bounding_box_centre(vertices);
    let r = correction::resolve(vertices, &all, &signs, &sealed, centre, RESOLVED_TARGET * volume);
    for face in r.faces.iter() {
        out.faces.push(face);
    }
    out.vertices = r.vertices;
    out.resolved_bound = r.bound + swept + r.rounding;
    out.cut_rounding = r.rounding;
    out.crowded = if r.crowded { all.len() } else { 0 };
    out.ball = (centre, bounds.diagonal() / 2.0);
    out.cut_faces = r.cut;
    out.changed |= r.changed;
}

/// The triangles of the copies whose shells are decided face by face, with their shells: as
/// stored where the shell is decided so, else turned with the face they copy.
fn copied(copies: &Polygons, clusters: &Clusters, relevant: &[bool]) -> Vec<(usize, Vec<[u32; 3]>)> {
    let all: Vec<u32> = (0..copies.len() as u32).collect();
    let tris = |c: usize, s: usize| {
        let t = fan(copies, &all[c..=c]);
        if clusters.copy_turned[c] && !clusters.unflip[s] {
            t.into_iter().map(|t| [t[2], t[1], t[0]]).collect()
        } else {
            t
        }
    };
    (0..copies.len())
        .filter_map(|c| (clusters.copy_shell[c].filter(|&s| relevant[s])).map(|s| (s, tris(c, s))))
        .collect()
}

/// Per face: whether it is `stored`'s face at the same place turned round.
fn turned_round(faces: &Polygons, stored: &Polygons) -> Vec<bool> {
    // Face for face (faces added after the stored ones, such as caps, have no stored orientation):
    // a stored orientation of other faces would count faces of other shells as turned (sweep case
    // 49295, `health/closed.rs`'s `stored_orientation`).
    debug_assert!(
        stored.len() <= faces.len()
            && (0..stored.len()).all(|i| {
                let (f, s) = (faces.face(i), stored.face(i));
                f == s || f.iter().eq(s.iter().rev())
            }),
        "the stored orientation is not the classified faces' own"
    );
    (0..faces.len())
        .map(|i| {
            i < stored.len() && {
                let (f, s) = (faces.face(i), stored.face(i));
                f.len() == s.len() && f != s && f.iter().eq(s.iter().rev())
            }
        })
        .collect()
}

/// The shells' triangles, those of the shells marked in `unflip` with their faces in the stored
/// orientation (the faces in `flip` turned back), and how many faces were turned back.
fn as_stored(
    faces: &Polygons,
    shells: &[Shell],
    tris: &[Vec<[u32; 3]>],
    unflip: &[bool],
    flip: &[bool],
) -> (Vec<Vec<[u32; 3]>>, usize) {
    let mut out = tris.to_vec();
    let mut turned = 0;
    for (i, s) in shells.iter().enumerate() {
        if unflip[i] && s.faces.iter().any(|&f| flip[f as usize]) {
            turned += s.faces.iter().filter(|&&f| flip[f as usize]).count();
            out[i] = s
                .faces
                .iter()
                .flat_map(|&f| {
                    let t = fan(faces, &[f]);
                    let back = flip[f as usize];
                    t.into_iter().map(move |t| if back { [t[2], t[1], t[0]] } else { t })
                })
                .collect();
        }
    }
    (out, turned)
}

/// The faces kept, those marked turned reversed.
fn rebuilt(faces: &Polygons, keep: &[bool], turn: &[bool]) -> Polygons {
    let mut out = Polygons::new();
    for (i, face) in faces.iter().enumerate() {
        if !keep[i] {
            continue;
        }
        if turn[i] {
            let mut r = face.to_vec();
            r.reverse();
            out.push(&r);
        } else {
            out.push(face);
        }
    }
    out
}

/// Shells: components over edges that exactly two faces share with opposite directions; a shell is
/// closed when every edge of its faces is such an edge. Also the faces' edge uses ([`edge_uses`]).
fn shells(vertices: &[[f64; 3]], faces: &Polygons) -> (Vec<Shell>, Vec<EdgeUse>) {
    let mut parent: Vec<u32> = (0..faces.len() as u32).collect();
    let mut open_face = vec![false; faces.len()];
    let uses = edge_uses(vertices.len(), &numbered(faces), None);
    for users in uses.chunk_by(|x, y| x.key == y.key) {
        if users.len() == 2 && users[0].forward != users[1].forward {
            let (a, b) = (root(&mut parent, users[0].face), root(&mut parent, users[1].face));
            parent[a.max(b) as usize] = a.min(b);
        } else {
            for e in users {
                open_face[e.face as usize] = true;
            }
        }
    }
    let centre = crate::mass::integrals::bounding_box_centre(vertices);
    // Per root (its component's lowest face): its shell.
    let mut index = vec![u32::MAX; faces.len()];
    let mut out: Vec<Shell> = Vec::new();
    for (i, face) in faces.iter().enumerate() {
        let r = root(&mut parent, i as u32) as usize;
        if index[r] == u32::MAX {
            index[r] = out.len() as u32;
            out.push(Shell {
                faces: Vec::new(),
                closed: true,
                motion: 0.0,
                sealed: true,
                area2: [0.0; 3],
                volume6: 0.0,
                bounds: Aabb::EMPTY,
                group: u32::MAX,
                reach: Aabb::EMPTY,
            });
        }
        let s = &mut out[index[r] as usize];
        s.faces.push(i as u32);
        s.closed &= !open_face[i];
        let a = sub(vertices[face[0] as usize], centre);
        for k in 1..face.len() - 1 {
            let b = sub(vertices[face[k] as usize], centre);
            let c = sub(vertices[face[k + 1] as usize], centre);
            s.volume6 += dot(a, cross(b, c));
            let n = cross(sub(b, a), sub(c, a));
            (0..3).for_each(|j| s.area2[j] += n[j]);
        }
        for &v in face {
            s.bounds.add(vertices[v as usize]);
        }
    }
    for s in &mut out {
        s.sealed = s.closed;
        if !s.closed {
            let diag = s.bounds.diagonal();
            s.motion = dot(s.area2, s.area2).sqrt() / 2.0 * diag / 6.0;
            s.closed = s.motion <= NEARLY_CLOSED * s.volume6.abs() / 6.0;
        }
        s.reach = s.bounds;
    }
    groups(&mut out, &uses, &index, &mut parent);
    (out, uses)
}

/// Open shells joined by the edges they share (where more than two faces, or two with the same
/// direction, meet) into groups whose every edge balances (as many uses each way): a group is then
/// a closed cycle, whose winding number is an integer around it though each of its shells may be
/// as small as one face (three coincident boxes, every edge used six times: sweep case 56891, an
/// inward box inside them decided by nesting with none of the faces' boxes around it, so
/// counted once more, 3.3e-5 off under 2.3e-12). The group's first shell reaches over the group's
/// box ([`Shell::reach`]), so that [`overlapping_pairs`] pairs it with the shells inside, which
/// nesting (closed shells only) does not decide: they are decided face by face with the group.
fn groups(shells: &mut [Shell], uses: &[EdgeUse], index: &[u32], parent: &mut [u32]) {
    let shell_of = |parent: &mut [u32], f: u32| index[root(parent, f) as usize];
    let mut group: Vec<u32> = (0..shells.len() as u32).collect();
    let mut shared = false;
    // A shell on each edge that does not balance: its group is not a closed cycle.
    let mut unbalanced = Vec::new();
    for users in uses.chunk_by(|x, y| x.key == y.key) {
        if users.len() == 2 && users[0].forward != users[1].forward {
            continue;
        }
        let first = shell_of(parent, users[0].face);
        for e in &users[1..] {
            let other = shell_of(parent, e.face);
            shared |= other != first;
            join(&mut group, first, other);
        }
        if users.iter().map(|e| if e.forward { 1i64 } else { -1 }).sum::<i64>() != 0 {
            unbalanced.push(first);
        }
    }
    if !shared {
        return;
    }
    // Per group root: balanced, members, box.
    let mut balanced = vec![true; shells.len()];
    for s in unbalanced {
        balanced[root(&mut group, s) as usize] = false;
    }
    let mut members = vec![0u32; shells.len()];
    let mut reach = vec![Aabb::EMPTY; shells.len()];
    for i in 0..shells.len() {
        let r = root(&mut group, i as u32) as usize;
        members[r] += 1;
        reach[r] = reach[r].union(shells[i].bounds);
    }
    for i in 0..shells.len() {
        let r = root(&mut group, i as u32) as usize;
        if members[r] >= 2 && balanced[r] {
            shells[i].group = r as u32;
            if r == i {
                shells[i].reach = reach[r];
            }
        }
    }
}

/// One use of an edge by a face.
#[derive(Clone, Copy)]
pub(super) struct EdgeUse {
    /// The edge ([`edge_key`]).
    pub(super) key: u64,
    pub(super) face: u32,
    /// Whether the face runs along it from its lower corner.
    pub(super) forward: bool,
}

/// Every use of an edge by the `faces` (numbered) on `n` vertices, on the vertices'
/// representatives `rep` when given, sorted by edge and, along one edge, by face. A counting sort
/// by the lower corner, then a sort of each corner's few edges: no map of lists, and no sort of
/// the whole, on every face of a surface of several shells.
pub(super) fn edge_uses<'a, F>(n: usize, faces: &F, rep: Option<&[u32]>) -> Vec<EdgeUse>
where
    F: Iterator<Item = (u32, &'a [u32])> + Clone,
{
    let at = |v: u32| rep.map_or(v, |r| r[v as usize]);
    let each = |f: &mut dyn FnMut(u32, u32, u32)| {
        for (i, face) in faces.clone() {
            for k in 0..face.len() {
                f(i, at(face[k]), at(face[(k + 1) % face.len()]));
            }
        }
    };
    let mut start = vec![0u32; n + 1];
    each(&mut |_, u, v| start[u.min(v) as usize + 1] += 1);
    for k in 0..n {
        start[k + 1] += start[k];
    }
    let blank = EdgeUse {
        key: 0,
        face: 0,
        forward: false,
    };
    let mut uses = vec![blank; start[n] as usize];
    let mut fill = start.clone();
    each(&mut |i, u, v| {
        let at = &mut fill[u.min(v) as usize];
        uses[*at as usize] = EdgeUse {
            key: edge_key(u, v),
            face: i,
            forward: u < v,
        };
        *at += 1;
    });
    // Each corner's uses are in face order: a stable sort by edge keeps them so along each edge.
    for k in 0..n {
        uses[start[k] as usize..start[k + 1] as usize].sort_by_key(|e| e.key);
    }
    uses
}

/// The faces with their numbers, for [`edge_uses`].
fn numbered(faces: &Polygons) -> impl Iterator<Item = (u32, &[u32])> + Clone {
    (0..faces.len()).map(|i| (i as u32, faces.face(i)))
}

/// An undirected edge as one word, its lower corner first.
pub(super) fn edge_key(u: u32, v: u32) -> u64 {
    (u64::from(u.min(v)) << 32) | u64::from(u.max(v))
}

pub(super) fn root(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

/// Pairs of shells whose boxes overlap in a region of positive volume, or where one is a flat open
/// shell across the other's box ([`flat_across`]) ([`box_pairs`]: in the order of a sweep along
/// x); `None` beyond [`MAX_BOX_PAIRS`] of them or [`MAX_SWEEP_VISITS`] box tests.
fn overlapping_pairs(shells: &[Shell]) -> Option<Vec<(usize, usize)>> {
    let boxes: Vec<Aabb> = shells.iter().map(|s| s.reach).collect();
    let pairs = box_pairs(&boxes, (MAX_BOX_PAIRS, MAX_SWEEP_VISITS), |a, b| {
        let (a, b) = (&shells[a], &shells[b]);
        box_overlap(a, b) > 0.0 || flat_across(a, b) || flat_across(b, a)
    })?;
    Some(pairs.into_iter().map(|(a, b)| (a.min(b), a.max(b))).collect())
}

/// The pairs of `boxes` that `keep` keeps, each as [`x_sweep`](crate::geometry::x_sweep) passes it
/// (the box that starts first along x first) and in the order it visits them; but found by a sweep
/// along the axis on which the fewest pairs overlap, or, when each axis has more than `budget`,
/// from a tree of the boxes ([`bvh::Bvh::pairs`]). Boxes overlapping along x only (parts in a row
/// along y) made the sweep along x quadratic: 40,000 tetrahedra in a row took 7.0 s, all of it in
/// the sweep, now 0.13 s; 45,000 boxes in three groups, each overlapping two by two along two axes
/// but not in space, 10.0 s, now 0.3 s. `keep` must keep only boxes that overlap along every axis
/// (which a sweep along any axis visits, and the tree meets). `None` when more than `limit` are
/// kept, or when the tree meets more than `budget` pairs of boxes (touching counts).
fn box_pairs(
    boxes: &[Aabb],
    (limit, budget): (usize, u64),
    keep: impl FnMut(usize, usize) -> bool,
) -> Option<Vec<(usize, usize)>> {
    // Each axis's order sorted once: for the counts, the sweep and the x sweep's order.
    let orders = [0, 1, 2].map(|k| starts(boxes, k));
    let visits = [0, 1, 2].map(|k| sweep_visits(boxes, (k, &orders[k])));
    let axis = (0..3).min_by_key(|&k| visits[k]).unwrap_or(0);
    box_pairs_along((boxes, &orders), (visits[axis] <= budget).then_some(axis), (limit, budget), keep)
}

/// [`box_pairs`] by a sweep along `axis`, or from the tree when `None`; `orders`: the boxes'
/// [`starts`] along each axis.
fn box_pairs_along(
    (boxes, orders): (&[Aabb], &[Vec<usize>; 3]),
    axis: Option<usize>,
    (limit, budget): (usize, u64),
    mut keep: impl FnMut(usize, usize) -> bool,
) -> Option<Vec<(usize, usize)>> {
    let mut pairs = Vec::new();
    let mut take = |a: usize, b: usize| {
        if keep(a, b) {
            pairs.push((a, b));
            if pairs.len() > limit {
                return ControlFlow::Break(());
            }
        }
        ControlFlow::Continue(())
    };
    let full = if let Some(axis) = axis {
        sweep_in(boxes, (axis, &orders[axis]), &mut take)
    } else {
        let own: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut met = 0u64;
        bvh::Bvh::new(boxes.to_vec(), &own).pairs(|a, b| {
            met += 1;
            if met > budget {
                return ControlFlow::Break(());
            }
            take(a as usize, b as usize)
        })
    };
    if full.is_break() {
        return None;
    }
    if axis != Some(0) {
        let mut place = vec![0; boxes.len()];
        for (i, &b) in orders[0].iter().enumerate() {
            place[b] = i;
        }
        for p in &mut pairs {
            if place[p.1] < place[p.0] {
                *p = (p.1, p.0);
            }
        }
        pairs.sort_unstable_by_key(|&(a, b)| (place[a], place[b]));
    }
    Some(pairs)
}

/// Whether `flat` is an open shell in a plane along an axis (its box of no extent along it) strictly
/// within `other`'s box along that axis, their boxes overlapping in a region of positive area in
/// that plane. Its faces may then lie inside `other` and bound nothing there, though the boxes
/// meet in no volume: the faces of a box that another box's face, one f32 unit below them, wholly
/// covers (sweep case 37374 of `tests/union_sweep.rs`, the boxes' faces each an open shell of a
/// non-manifold cluster: the slab between counted twice, 1.5e-8 off under an estimate of
/// 3.6e-11). Faces of one closed body meeting at its edges are not so (each lies on a side of the
/// other's box, not strictly within it).
fn flat_across(flat: &Shell, other: &Shell) -> bool {
    let (f, o) = (&flat.bounds, &other.bounds);
    !flat.closed
        && (0..3).any(|k| {
            f.lo[k] == f.hi[k]
                && o.lo[k] < f.lo[k]
                && f.lo[k] < o.hi[k]
                && (0..3).filter(|&j| j != k).all(|j| f.hi[j].min(o.hi[j]) > f.lo[j].max(o.lo[j]))
        })
}

/// A bound on the volume two shells can both enclose: the intersection of their boxes, and for closed
/// shells also the smaller one's volume.
fn box_overlap(a: &Shell, b: &Shell) -> f64 {
    // Shells of one group by their own boxes; of others, a group's first shell by the group's.
    let (p, q) = if a.group == b.group && a.group != u32::MAX {
        (&a.bounds, &b.bounds)
    } else {
        (&a.reach, &b.reach)
    };
    let boxes: f64 = (0..3)
        .map(|k| (p.hi[k].min(q.hi[k]) - p.lo[k].max(q.lo[k])).max(0.0))
        .product();
    if a.closed && b.closed {
        boxes.min(a.volume6.abs().min(b.volume6.abs()) / 6.0)
    } else {
        boxes
    }
}

/// Triangles of the given faces (fans).
fn fan(faces: &Polygons, which: &[u32]) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(which.len()); // one triangle per face, more for polygons
    for &f in which {
        let face = faces.face(f as usize);
        for k in 1..face.len() - 1 {
            out.push([face[0], face[k], face[k + 1]]);
        }
    }
    out
}

/// Per shell: the others' winding numbers on it, and whether every pair around it is decided, pair
/// by pair ([`nesting`]). `uses`: the faces' edge uses ([`edge_uses`]).
fn pair_by_pair(
    vertices: &[[f64; 3]],
    shells: &[Shell],
    (tris, uses): (&[Vec<[u32; 3]>], &[EdgeUse]),
    pairs: &[(usize, usize)],
) -> (Vec<i64>, Vec<bool>) {
    let mut w_out = vec![0i64; shells.len()];
    let mut decided = vec![true; shells.len()];
    // The triangles' boxes of each closed shell in a pair of closed shells, once: a shell is in
    // many pairs (b1's trunk.dae: 882 pairs, 3.9 M triangles' boxes made again for each).
    let mut boxes: Vec<Vec<Aabb>> = vec![Vec::new(); shells.len()];
    for &(a, b) in pairs {
        if shells[a].closed && shells[b].closed {
            for s in [a, b] {
                if boxes[s].is_empty() {
                    boxes[s] = tris[s].iter().map(|t| Aabb::of(t.map(|i| vertices[i as usize]))).collect();
                }
            }
        }
    }
    // The caps of each shell closed only up to cracks in a pair of closed shells, once.
    let cracked: Vec<usize> = (0..shells.len()).filter(|&s| !shells[s].sealed && !boxes[s].is_empty()).collect();
    let caps = if cracked.is_empty() {
        vec![Vec::new(); shells.len()]
    } else {
        let mut shell_of = vec![u32::MAX; shells.iter().map(|s| s.faces.len()).sum()];
        for &s in &cracked {
            for &f in &shells[s].faces {
                shell_of[f as usize] = s as u32;
            }
        }
        cracks::caps(uses, &shell_of, shells.len())
    };
    let closed = Closed { tris, boxes: &boxes, caps: &caps };
    for &(a, b) in pairs {
        if let Some((wa, wb)) = nesting(vertices, shells, &closed, a, b) {
            w_out[a] += wa;
            w_out[b] += wb;
        } else {
            decided[a] = false;
            decided[b] = false;
        }
    }
    (w_out, decided)
}

/// Per shell: its triangles, and for each closed shell in a pair of closed shells their boxes and
/// the triangles that close its cracks ([`cracks::caps`]; none for a sealed shell).
struct Closed<'a> {
    tris: &'a [Vec<[u32; 3]>],
    boxes: &'a [Vec<Aabb>],
    caps: &'a [Vec<[u32; 3]>],
}

/// For two closed shells that do not touch: the winding number of `b` on `a` and of `a` on `b`.
/// `None` when either is open, they touch or cut each other, or the test is too large.
fn nesting(vertices: &[[f64; 3]], shells: &[Shell], closed: &Closed, a: usize, b: usize) -> Option<(i64, i64)> {
    let (tris, boxes) = (closed.tris, closed.boxes);
    let (sa, sb) = (&shells[a], &shells[b]);
    if !sa.closed || !sb.closed {
        return None;
    }
    // The triangles whose boxes meet the two shells' common box, with their boxes.
    let common = sa.bounds.intersection(sb.bounds);
    let near = |s: usize| -> (Vec<[u32; 3]>, Vec<Aabb>) {
        (tris[s].iter().zip(&boxes[s]))
            .filter(|(_, b)| overlap(b, &common))
            .map(|(t, b)| (*t, *b))
            .unzip()
    };
    let ((ta, boxes_a), (tb, boxes_b)) = (near(a), near(b));
    if ta.len().saturating_mul(tb.len()) > MAX_TESTS {
        return None;
    }
    let touch = |x: usize, y: usize| {
        if triangles_touch(vertices, &ta[x], &tb[y]) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    // A shell with no triangle in the other's box cannot touch it (nested shells, most often):
    // the sweep then looks at nothing.
    if closed_boxes_meeting(&boxes_a, &boxes_b, touch).is_break() {
        return None;
    }
    let wa = winding_on(vertices, shells, closed, a, b)?;
    let wb = winding_on(vertices, shells, closed, b, a)?;
    Some((wa, wb))
}

/// The winding number of the closed shell `b` on the shell `a`, which does not touch it: one
/// integer on all of `a` (a connected surface), so any corner of `a` gives it. A sealed `b` has 0
/// outside its box, where a corner of `a` lies unless `a`'s box is within `b`'s (the corner with
/// `a`'s coordinate beyond it): no sum is needed. Within `b`'s box, an exact ray from `a`'s first
/// corner counts it ([`ray_winding`]). A `b` closed only up to cracks has solid angles that need
/// not be whole near a crack, nor 0 outside its box; where its caps ([`capped`]) show that the sum
/// at `a`'s first corner is within half of [`NOT_INTEGER`] of the count of `b` and its caps, that
/// count. Otherwise (every ray grazes, or a cap is in sight), the solid angles of `b`'s triangles at
/// `a`'s first corner, rounded within [`NOT_INTEGER`].
fn winding_on(vertices: &[[f64; 3]], shells: &[Shell], closed: &Closed, a: usize, b: usize) -> Option<i64> {
    let Closed { tris, boxes, caps } = *closed;
    let (sb, p) = (&shells[b], vertices[tris[a][0][0] as usize]);
    if sb.sealed {
        if !sb.bounds.contains(&shells[a].bounds) {
            return Some(0);
        }
        if let Some(w) = ray_winding(vertices, (&tris[b], &boxes[b]), (&[], &[]), &sb.bounds, p) {
            return Some(w);
        }
    } else if let Some(w) = capped(vertices, (&tris[b], &boxes[b]), &caps[b], &sb.bounds, p) {
        return Some(w);
    }
    integer(winding(vertices, &tris[b], p))
}

/// What the solid angles at `p` of the triangles `tris` (with their boxes) of a shell closed only up
/// to cracks round to, without their sum. The shell and its caps `cap` ([`cracks::caps`], within
/// `bounds`) are a closed cycle, whose winding number at `p` (off the shell) is an integer counted
/// exactly by a ray ([`ray_winding`]; 0 outside `bounds`, along the axis that leaves them); the
/// shell's own is that less the caps', which is at most the sum of the sizes of their solid angles
/// over 4π. Where that is within half of [`NOT_INTEGER`], the shell's sum rounds to the count, with
/// room to spare for its rounding. `None` when the caps are larger at `p` (a corner close to a
/// crack), `p` is within a cap's box, or every ray grazes.
fn capped(vertices: &[[f64; 3]], tris: (&[[u32; 3]], &[Aabb]), cap: &[[u32; 3]], bounds: &Aabb, p: [f64; 3]) -> Option<i64> {
    let mut seen = 0.0;
    let cap_boxes: Vec<Aabb> = cap.iter().map(|t| Aabb::of(t.map(|v| vertices[v as usize]))).collect();
    for (t, near) in cap.iter().zip(&cap_boxes) {
        let corners = t.map(|v| vertices[v as usize]);
        // Within a millionth of a cap's size of its box, its solid angle's formula may lose its
        // digits (near an edge, where a ray still counts): the sum is taken instead.
        let margin = 1e-6 * near.diagonal();
        if (0..3).all(|k| p[k] >= near.lo[k] - margin && p[k] <= near.hi[k] + margin) {
            return None;
        }
        let [a, b, c] = corners.map(|q| sub(q, p));
        seen += solid_angle(a, b, c, norm(a), norm(b), norm(c)).abs();
    }
    if seen.is_nan() || seen > 0.5 * NOT_INTEGER * 4.0 * std::f64::consts::PI {
        return None;
    }
    if (0..3).any(|k| p[k] < bounds.lo[k] || p[k] > bounds.hi[k]) {
        return Some(0);
    }
    ray_winding(vertices, tris, (cap, &cap_boxes), bounds, p)
}

/// The winding number at `p` (off them) of the triangles of a closed cycle within `bounds` (a
/// sealed shell's `tris`, and a shell's `cap` of its cracks, each with their boxes), counted
/// exactly along a ray parallel to an axis ([`grid::crossing`]): the first of the six that grazes
/// no edge, corner or plane of a triangle. `None` when all six graze.
fn ray_winding(
    vertices: &[[f64; 3]],
    (tris, boxes): (&[[u32; 3]], &[Aabb]),
    (cap, cap_boxes): (&[[u32; 3]], &[Aabb]),
    bounds: &Aabb,
    p: [f64; 3],
) -> Option<i64> {
    let corners = |t: &[u32; 3]| t.map(|i| vertices[i as usize]);
    let capped = cap.iter().zip(cap_boxes.iter().copied());
    'rays: for (axis, sign) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0), (2, 1.0), (2, -1.0)] {
        let (j, l) = ((axis + 1) % 3, (axis + 2) % 3);
        // An end beyond every triangle.
        let mut end = p;
        end[axis] = sign * 2.0 * (bounds.hi[axis].abs().max(bounds.lo[axis].abs()).max(p[axis].abs()) + 1.0);
        let mut w = 0;
        for (t, b) in tris.iter().zip(boxes.iter().copied()).chain(capped.clone()) {
            // A triangle whose box is wholly to one side of the ray's line, or behind its start, it
            // cannot meet (its box from its corners: the same comparisons of the same numbers).
            let behind = if sign > 0.0 { b.hi[axis] < p[axis] } else { b.lo[axis] > p[axis] };
            if b.lo[j] > p[j] || b.hi[j] < p[j] || b.lo[l] > p[l] || b.hi[l] < p[l] || behind {
                continue;
            }
            let c = corners(t);
            match grid::crossing(p, end, axis, &c, &grid::Plane::new(&c)) {
                grid::Crossing::Miss => {}
                grid::Crossing::Through(d) => w += d,
                grid::Crossing::Degenerate => continue 'rays,
            }
        }
        return Some(w);
    }
    None
}

/// Each pair of a box of `a` and a box of `b` that meet as closed boxes (touching counts), found
/// by a sweep along x over the two lists, each sorted by where its boxes start: `visit(i, j)` with
/// `i` in `a` and `j` in `b`, until it breaks. Every such pair is visited once (from the box that
/// starts first, the one of `a` at a tie), so a test that holds for some pair finds one, as the loop
/// over all pairs did, in time linear in the pairs whose x ranges meet rather than in all |a|·|b|;
/// pairs within one list are never looked at (an empty list costs nothing).
fn closed_boxes_meeting(
    a: &[Aabb],
    b: &[Aabb],
    mut visit: impl FnMut(usize, usize) -> ControlFlow<()>,
) -> ControlFlow<()> {
    if a.is_empty() || b.is_empty() {
        return ControlFlow::Continue(());
    }
    let sorted = |boxes: &[Aabb]| {
        let mut order: Vec<usize> = (0..boxes.len()).collect();
        order.sort_by(|&p, &q| boxes[p].lo[0].total_cmp(&boxes[q].lo[0]));
        order
    };
    let (oa, ob) = (sorted(a), sorted(b));
    let (mut i, mut j) = (0, 0);
    while i < oa.len() && j < ob.len() {
        let (x, y) = (&a[oa[i]], &b[ob[j]]);
        if x.lo[0] <= y.lo[0] {
            // x starts first: the boxes of b from y on that start within x's range along x.
            for &q in ob[j..].iter().take_while(|&&q| b[q].lo[0] <= x.hi[0]) {
                if overlap(x, &b[q]) {
                    visit(oa[i], q)?;
                }
            }
            i += 1;
        } else {
            for &p in oa[i..].iter().take_while(|&&p| a[p].lo[0] <= y.hi[0]) {
                if overlap(&a[p], y) {
                    visit(p, ob[j])?;
                }
            }
            j += 1;
        }
    }
    ControlFlow::Continue(())
}

/// Whether two boxes meet as closed boxes (touching counts).
// `&`, not `&&`: six comparisons and no branch, as a grid query's boxes fail on any axis (figures:
// docs/benchmarks.md, "Shells, round 31").
#[allow(clippy::needless_bitwise_bool)]
pub(super) fn overlap(a: &Aabb, b: &Aabb) -> bool {
    (a.lo[0] <= b.hi[0]) & (b.lo[0] <= a.hi[0]) & (a.lo[1] <= b.hi[1]) & (b.lo[1] <= a.hi[1]) & (a.lo[2] <= b.hi[2]) & (b.lo[2] <= a.hi[2])
}

fn integer(w: f64) -> Option<i64> {
    let r = w.round();
    ((w - r).abs() <= NOT_INTEGER).then_some(r as i64)
}

pub(super) fn c3(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Whether two triangles may touch: exact, and conservative for coplanar ones (any coplanar pair
/// whose boxes meet counts as touching). Non-coplanar triangles meet only where an edge of one
/// crosses the other.
pub(super) fn triangles_touch(v: &[[f64; 3]], x: &[u32; 3], y: &[u32; 3]) -> bool {
    let p = |t: &[u32; 3]| t.map(|i| v[i as usize]);
    let (px, py) = (p(x), p(y));
    let side = |t: [[f64; 3]; 3]| move |q: [f64; 3]| orient3d(c3(t[0]), c3(t[1]), c3(t[2]), c3(q));
    corners_touch(&px, &py, (side(px), side(py)))
}

/// `[f(0), f(1), f(2)]`, the calls inlined. `[T; 3]::map` and `[0, 1, 2].map` ran the closure out
/// of line in the shells' hot loops, and their results, stored one by one on the stack and read
/// back as one, stalled the loads (`perf annotate`: about a third of `Faces::cut`'s samples
/// under coincident shells were on the loads after such maps). Arrays of corners are passed by
/// reference for the same reason: a copy made for a call and read by it at once stalled too.
#[inline(always)]
pub(super) fn in_order<T>(mut f: impl FnMut(usize) -> T) -> [T; 3] {
    [f(0), f(1), f(2)]
}

/// [`triangles_touch`] of the triangles of corners `px` and `py`, given for each a function with
/// the sign of `orient3d` of its corners and a point (a precomputed plane's side).
pub(super) fn corners_touch(
    px: &[[f64; 3]; 3],
    py: &[[f64; 3]; 3],
    (side_x, side_y): (impl Fn([f64; 3]) -> f64, impl Fn([f64; 3]) -> f64),
) -> bool {
    let boxes_meet = (0..3).all(|k| {
        let (xl, xh) = px
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                (l.min(q[k]), h.max(q[k]))
            });
        let (yl, yh) = py
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                (l.min(q[k]), h.max(q[k]))
            });
        xl <= yh && yl <= xh
    });
    if !boxes_meet {
        return false;
    }
    // Each corner's side of the other's plane once (both edges at a corner use it).
    let edges_meet = |p: &[[f64; 3]; 3], o: [f64; 3], t| {
        (0..3).any(|i| {
            let j = (i + 1) % 3;
            edge_meets(p[i], p[j], o[i], o[j], t)
        })
    };
    edges_meet(px, in_order(|i| side_y(px[i])), py) || edges_meet(py, in_order(|i| side_x(py[i])), px)
}

/// Whether the closed segment `s e` meets the closed triangle `t` (coplanar: yes, conservatively),
/// given `s`'s and `e`'s sides of `t`'s plane (`orient3d` of `t`'s corners and each).
///
/// Inlined: most segments have both ends on one side and end here, before any copy of the corners;
/// the rest go on in [`edge_crosses`].
#[inline(always)]
pub(super) fn edge_meets(s: [f64; 3], e: [f64; 3], o1: f64, o2: f64, t: &[[f64; 3]; 3]) -> bool {
    if (o1 > 0.0 && o2 > 0.0) || (o1 < 0.0 && o2 < 0.0) {
        return false;
    }
    if o1 == 0.0 && o2 == 0.0 {
        return true;
    }
    edge_crosses(&s, &e, t)
}

/// [`edge_meets`] of a segment whose ends are not both on one side of `t`'s plane, nor both in it.
#[inline(never)]
fn edge_crosses(s: &[f64; 3], e: &[f64; 3], t: &[[f64; 3]; 3]) -> bool {
    line_passes(s, e, t) != LinePass::Beside
}

/// Where the line through `s` and `e` passes a triangle `t` (exact `orient3d` of the line against
/// its three edges).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum LinePass {
    /// Two edges see it on opposite sides.
    Beside,
    /// Through an edge or a corner: a zero among the three, the others of one sign.
    Edge,
    /// Through the interior: all three of one sign, strictly.
    Through,
}

/// [`LinePass`] of the line through `s` and `e` and triangle `t`.
#[inline]
pub(super) fn line_passes(s: &[f64; 3], e: &[f64; 3], t: &[[f64; 3]; 3]) -> LinePass {
    let (a, b, c) = (c3(t[0]), c3(t[1]), c3(t[2]));
    let (cs, ce) = (c3(*s), c3(*e));
    // The line passes beside the triangle when two of its edges see it on opposite sides: the
    // first two often do, and the third is then not asked.
    let (q0, q1) = (orient3d(cs, ce, a, b), orient3d(cs, ce, b, c));
    if (q0 > 0.0 && q1 < 0.0) || (q0 < 0.0 && q1 > 0.0) {
        return LinePass::Beside;
    }
    let q = [q0, q1, orient3d(cs, ce, c, a)];
    if q.iter().any(|x| *x > 0.0) && q.iter().any(|x| *x < 0.0) {
        LinePass::Beside
    } else if q.contains(&0.0) {
        LinePass::Edge
    } else {
        LinePass::Through
    }
}

/// The winding number of triangles at `p`: their solid angles (van Oosterom and Strackee) over 4π.
fn winding(vertices: &[[f64; 3]], tris: &[[u32; 3]], p: [f64; 3]) -> f64 {
    let mut total = 0.0;
    for t in tris {
        let a = sub(vertices[t[0] as usize], p);
        let b = sub(vertices[t[1] as usize], p);
        let c = sub(vertices[t[2] as usize], p);
        total += solid_angle(a, b, c, norm(a), norm(b), norm(c));
    }
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pairs found along the cheapest axis are `x_sweep`'s, in its order, on random boxes (some of
    /// no width, many with equal starts) laid out so that each axis is the cheapest in turn, and from the tree.
    #[test]
    fn box_pairs_are_the_x_sweeps() {
        let mut state = 7u64;
        for (case, stretch) in [
            [1.0, 1.0, 1.0],
            [50.0, 1.0, 1.0],
            [1.0, 50.0, 1.0],
            [1.0, 1.0, 50.0],
        ]
        .into_iter()
        .enumerate()
        {
            let mut boxes = Vec::new();
            for _ in 0..400 {
                let mut r = || (crate::xorshift(&mut state) % 40) as f64;
                let lo = [r() * stretch[0], r() * stretch[1], r() * stretch[2]];
                let size = [r() / 4.0, r() / 4.0, r() / 4.0];
                boxes.push(Aabb::new(
                    lo,
                    [0, 1, 2].map(|k| lo[k] + size[k] * stretch[k]),
                ));
            }
            let meet =
                |a: &Aabb, b: &Aabb| (0..3).all(|k| a.lo[k].max(b.lo[k]) < a.hi[k].min(b.hi[k]));
            let mut want = Vec::new();
            let _ = crate::geometry::x_sweep(&boxes, |a, b| {
                if meet(&boxes[a], &boxes[b]) {
                    want.push((a, b));
                }
                ControlFlow::Continue(())
            });
            assert!(want.len() > 20, "case {case}: {}", want.len());
            let got = box_pairs(&boxes, (usize::MAX, u64::MAX), |a, b| {
                meet(&boxes[a], &boxes[b])
            });
            assert_eq!(got.as_ref(), Some(&want), "case {case}");
            let over = box_pairs(&boxes, (want.len() - 1, u64::MAX), |a, b| {
                meet(&boxes[a], &boxes[b])
            });
            assert_eq!(over, None, "case {case}");
            assert_eq!(
                box_pairs(&boxes, (usize::MAX, 10), |_, _| true),
                None,
                "case {case}"
            );
        }
    }

    /// The sweep visits exactly the pairs (one box of each list) that meet as closed boxes, each
    /// once: boxes on a coarse lattice, so that many touch at a face, an edge or a corner only.
    #[test]
    fn the_sweep_visits_each_meeting_pair_once() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut next = |n: u64| (crate::xorshift(&mut state) % n) as f64;
        let mut boxes = |count: usize| -> Vec<Aabb> {
            (0..count)
                .map(|_| {
                    let lo = [next(6), next(6), next(6)];
                    let size = [next(3), next(3), next(3)];
                    Aabb::new(lo, [0, 1, 2].map(|k| lo[k] + size[k]))
                })
                .collect()
        };
        for (na, nb) in [(0, 5), (7, 0), (40, 30), (120, 90)] {
            let (a, b) = (boxes(na), boxes(nb));
            let mut want = Vec::new();
            for (i, x) in a.iter().enumerate() {
                for (j, y) in b.iter().enumerate() {
                    if (0..3).all(|k| x.lo[k] <= y.hi[k] && y.lo[k] <= x.hi[k]) {
                        want.push((i, j));
                    }
                }
            }
            let mut got = Vec::new();
            let all = closed_boxes_meeting(&a, &b, |i, j| {
                got.push((i, j));
                ControlFlow::Continue(())
            });
            assert!(all.is_continue());
            got.sort_unstable();
            assert_eq!(got, want, "{na} × {nb}");
            assert!(na * nb < 1000 || want.len() > 100, "{}", want.len());
            // A visit that breaks stops the sweep.
            if let Some(&first) = want.first() {
                let mut seen = 0;
                let stop = closed_boxes_meeting(&a, &b, |_, _| {
                    seen += 1;
                    ControlFlow::Break(())
                });
                assert!(stop.is_break() && seen == 1, "{first:?}");
            }
        }
    }

    /// `count` boxes nested in each other (each 1 wider on every side, sides of different lengths,
    /// centres moving along x by ⅛), every other one inward from the outermost, which is outward,
    /// when `alternate`; as quads.
    fn nested_boxes(count: usize, alternate: bool) -> (Vec<[f64; 3]>, Polygons, Vec<f64>) {
        let (mut vertices, mut faces, mut volumes) = (Vec::new(), Polygons::new(), Vec::new());
        for k in 0..count {
            let kf = k as f64;
            let (c, h) = ([0.125 * kf, 0.0, 0.0], [1.0 + kf, 1.0 + 1.25 * kf, 1.0 + 0.5 * kf]);
            let base = vertices.len() as u32;
            for i in 0..8 {
                let s = |b: usize| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
                vertices.push([c[0] + s(0) * h[0], c[1] + s(1) * h[1], c[2] + s(2) * h[2]]);
            }
            // The outermost (last) box outward.
            let inward = alternate && (count - 1 - k) % 2 == 1;
            for q in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
                let mut q = q.map(|i| base + i);
                if inward {
                    q.reverse();
                }
                faces.push(&q);
            }
            let v = 8.0 * h[0] * h[1] * h[2];
            volumes.push(if inward { -v } else { v });
        }
        (vertices, faces, volumes)
    }

    /// Of 300 boxes nested in each other, all outward, only the outermost bounds Ω (every inner
    /// one is enclosed twice or more and drops out); inward every other one, each bounds a
    /// shell of Ω (w alternates 1, 0, 1, … inwards) and all stay as they are. Exact, with no
    /// bound, where deciding pair by pair met the cap on pairs (44,850 of them).
    #[test]
    fn many_nested_boxes_are_decided_exactly() {
        for alternate in [false, true] {
            let (vertices, faces, volumes) = nested_boxes(300, alternate);
            let out = classify(&vertices, &faces, &AsStored::default());
            assert_eq!((out.undecided_pairs, out.overlap_bound, out.resolved_pairs), (0, 0.0, 0));
            assert_eq!(out.turned_shells, 0);
            let kept: Vec<Vec<u32>> = out.faces.iter().map(<[u32]>::to_vec).collect();
            let want: Vec<Vec<u32>> = if alternate {
                assert_eq!(out.dropped_shells, 0);
                faces.iter().map(<[u32]>::to_vec).collect()
            } else {
                // The outermost box is the last.
                assert_eq!((out.dropped_shells, out.dropped_faces), (299, 6 * 299));
                faces.iter().skip(6 * 299).map(<[u32]>::to_vec).collect()
            };
            assert_eq!(kept, want, "alternate: {alternate}");
            // Ω's volume from the boxes' sides: the kept shells' signed volumes.
            let omega: f64 = if alternate { volumes.iter().sum() } else { volumes[299] };
            assert!(omega > 0.0);
        }
    }

    /// A box stored three times on the same corners, outward, inward and outward (every edge used
    /// six times, so each side is a shell of its own and none of their boxes holds anything), around
    /// a box wound inward: w is 1 − 1 + 1 = 1 between them and 0 inside the inner one, a cavity, so
    /// Ω is 4³ − 1 = 63 m³. The sides' group reaches over the outer box, so the inner box is paired
    /// with it and decided face by face with it; decided by nesting alone (no shell around it), it
    /// was turned outward and counted: 65 m³ (sweep case 56891 of `tests/union_sweep.rs`).
    #[test]
    fn a_box_inside_coincident_layers_is_decided_with_them() {
        let mut vertices = Vec::new();
        let mut faces = Polygons::new();
        let corners = |lo: f64, hi: f64| -> Vec<[f64; 3]> {
            (0..8).map(|i| [0, 1, 2].map(|k| if i >> k & 1 == 1 { hi } else { lo })).collect()
        };
        let sides = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        vertices.extend(corners(0.0, 4.0));
        for inward in [false, true, false] {
            for q in sides {
                faces.push(&if inward { [q[3], q[2], q[1], q[0]] } else { q });
            }
        }
        vertices.extend(corners(1.0, 2.0));
        for q in sides {
            faces.push(&[q[3], q[2], q[1], q[0]].map(|c| c + 8));
        }
        let (shells, _) = shells(&vertices, &faces);
        assert_eq!(shells.len(), 19);
        assert!(shells[..18].iter().all(|s| s.group == 0 && !s.closed));
        assert_eq!(shells[0].reach, Aabb::new([0.0; 3], [4.0; 3]));
        assert!(overlapping_pairs(&shells).expect("few").contains(&(0, 18)));
        let out = classify(&vertices, &faces, &AsStored::default());
        let at = |i: u32| vertices.get(i as usize).copied().unwrap_or_else(|| out.vertices[i as usize - vertices.len()]);
        let mut volume = 0.0;
        for face in out.faces.iter() {
            for k in 1..face.len() - 1 {
                volume += dot(at(face[0]), cross(at(face[k]), at(face[k + 1]))) / 6.0;
            }
        }
        assert!((volume - 63.0).abs() < 1e-12, "{volume}");
        // Its pairs are of open shells (the faces) with the closed box: counted as such in the
        // message, not as pairs of closed shells.
        assert!(out.resolved_pairs > 0 && out.resolved_open == out.resolved_pairs, "{out:?}");
    }

    /// The same boxes with every other one moved so that it cuts its neighbours: those pairs
    /// touch and go face by face, while the boxes that touch nothing stay decided whole.
    #[test]
    fn nested_boxes_that_cut_each_other_are_not_decided_whole() {
        let (mut vertices, faces, _) = nested_boxes(6, false);
        // Box 2 moved by 1.5 along y: it cuts boxes 1 and 3 (1 wider on each side), not 0, 4 or 5.
        for v in &mut vertices[16..24] {
            v[1] += 1.5;
        }
        let out = classify(&vertices, &faces, &AsStored::default());
        assert_eq!(out.undecided_pairs, 0);
        assert!(out.resolved_pairs >= 2, "{}", out.resolved_pairs);
        assert_eq!(out.resolved_open, 0);
    }

    /// A prism over `outline` (counter-clockwise seen from +z) from `z.0` to `z.1`, its caps fanned
    /// from the outline's first corner (a corner that sees every other one), outward or inward.
    fn prism(vertices: &mut Vec<[f64; 3]>, faces: &mut Polygons, outline: &[[f64; 2]], z: (f64, f64), outward: bool) {
        let (n, base) = (outline.len() as u32, vertices.len() as u32);
        for h in [z.0, z.1] {
            vertices.extend(outline.iter().map(|p| [p[0], p[1], h]));
        }
        let mut add = |mut f: Vec<u32>| {
            if !outward {
                f.reverse();
            }
            faces.push(&f);
        };
        for k in 1..n - 1 {
            add(vec![base + n, base + n + k, base + n + k + 1]);
            add(vec![base, base + k + 1, base + k]);
        }
        for i in 0..n {
            let j = (i + 1) % n;
            add(vec![base + i, base + j, base + n + j, base + n + i]);
        }
    }

    /// The outline of an L-shaped prism (counter-clockwise seen from +z): its box holds the notch
    /// between its arms.
    const L_OUTLINE: [[f64; 2]; 6] = [[1.0, 1.0], [1.0, 2.0], [0.0, 2.0], [0.0, 0.0], [2.0, 0.0], [2.0, 1.0]];

    /// A cube's outline beside the L of [`L_OUTLINE`], whether the L is wound outward, and the L's
    /// winding number on the cube: in its arm (±1), in the notch (0: within the L's box, outside the
    /// L), and reaching from the notch out of the L's box (0).
    fn l_and_cube() -> [([[f64; 2]; 4], bool, i64); 6] {
        let square = |x: (f64, f64), y: (f64, f64)| [[x.0, y.0], [x.1, y.0], [x.1, y.1], [x.0, y.1]];
        [
            (square((0.2, 0.8), (0.2, 0.8)), true, 1),
            (square((0.2, 0.8), (0.2, 0.8)), false, -1),
            (square((0.2, 0.8), (1.2, 1.8)), true, 1),
            (square((1.2, 1.8), (1.2, 1.8)), true, 0),
            (square((1.2, 1.8), (1.2, 1.8)), false, 0),
            (square((1.2, 2.5), (1.2, 1.8)), true, 0),
        ]
    }

    /// Issue #22: a pair's winding numbers are those of the geometry, and those the solid angles
    /// give at every corner, whichever way they are found (a sealed shell outside whose box the
    /// other reaches has 0 there, with no sum). An L-shaped prism (its box holds the notch
    /// between its arms) and a cube in its arm (w = 1, or −1 with the L inward), in the notch
    /// (0: within the L's box but outside the L), or reaching from the notch out of the L's box
    /// (0); the cube is outside the L, and the L, reaching beyond the cube's box, outside it.
    #[test]
    fn nesting_is_the_solid_angles_at_every_corner_issue_22() {
        let l = L_OUTLINE;
        for (cube, outward, w) in l_and_cube() {
            let (mut vertices, mut faces) = (Vec::new(), Polygons::new());
            prism(&mut vertices, &mut faces, &l, (0.0, 1.0), outward);
            prism(&mut vertices, &mut faces, &cube, (0.25, 0.75), true);
            let (shells, uses) = shells(&vertices, &faces);
            assert_eq!(shells.len(), 2);
            assert!(shells.iter().all(|s| s.sealed));
            let pairs = overlapping_pairs(&shells).expect("within the limits");
            assert_eq!(pairs, [(0, 1)]);
            let tris: Vec<Vec<[u32; 3]>> = shells.iter().map(|s| fan(&faces, &s.faces)).collect();
            // The L's winding number on the cube, the cube's on the L.
            let want = [0, w];
            assert_eq!(pair_by_pair(&vertices, &shells, (&tris, &uses), &pairs), (want.to_vec(), vec![true; 2]));
            for (a, b) in [(0, 1), (1, 0)] {
                for v in tris[a].iter().flatten() {
                    let p = vertices[*v as usize];
                    let sum = integer(winding(&vertices, &tris[b], p));
                    assert_eq!(sum, Some(want[a]), "{cube:?} {outward} {a}");
                    // The first ray from each corner that grazes nothing counts the same.
                    let ray = ray_winding(&vertices, (&tris[b], &boxes_of(&vertices, &tris[b])), (&[], &[]), &shells[b].bounds, p);
                    assert_eq!(ray, Some(want[a]), "{cube:?} {outward} {a}");
                }
            }
        }
        // From the centre of a box every ray meets a face on its diagonal: no ray counts. Off
        // the diagonals the first one does, inside and out.
        let (vertices, faces, _) = nested_boxes(1, false);
        let tris = fan(&faces, &[0, 1, 2, 3, 4, 5]);
        let bounds = Aabb::of(vertices.iter().copied());
        let boxes = boxes_of(&vertices, &tris);
        let ray = |p| ray_winding(&vertices, (&tris, &boxes), (&[], &[]), &bounds, p);
        assert_eq!([ray([0.0; 3]), ray([0.5, 0.25, 0.1]), ray([0.5, 0.25, 1.5])], [None, Some(1), Some(0)]);
    }

    /// The boxes of triangles.
    fn boxes_of(vertices: &[[f64; 3]], tris: &[[u32; 3]]) -> Vec<Aabb> {
        tris.iter().map(|t| Aabb::of(t.map(|i| vertices[i as usize]))).collect()
    }

    /// The faces with a corner put into edge `k` of face `f` (its midpoint moved by `offset`), so
    /// that the face's neighbour across that edge no longer shares it: a crack, of no width when
    /// `offset` is 0 (the corner on the edge, a T-junction).
    fn cracked(vertices: &mut Vec<[f64; 3]>, faces: &Polygons, (f, k): (usize, usize), offset: [f64; 3]) -> Polygons {
        let face = faces.face(f);
        let (u, v) = (vertices[face[k] as usize], vertices[face[(k + 1) % face.len()] as usize]);
        vertices.push([0, 1, 2].map(|i| 0.5 * (u[i] + v[i]) + offset[i]));
        let mut out = Polygons::new();
        for (i, g) in faces.iter().enumerate() {
            let mut g = g.to_vec();
            if i == f {
                g.insert(k + 1, vertices.len() as u32 - 1);
            }
            out.push(&g);
        }
        out
    }

    /// Shells closed only up to cracks nest as their solid angles say, counted without them where
    /// the caps of the cracks are out of sight: the L-shaped prism and cube of
    /// `nesting_is_the_solid_angles_at_every_corner_issue_22`, each with a crack in a side (a
    /// T-junction, or a sliver 1e-3 wide), in every placement (w = ±1, 0 in the notch within the
    /// L's box, 0 reaching out of it). At every corner of each, the count of the other and its caps
    /// ([`capped`]) is the geometry's winding number and what the sum rounds to; close in front of
    /// the sliver its cap is in sight, and the count is not taken.
    #[test]
    fn cracked_shells_nest_by_their_caps() {
        let l = L_OUTLINE;
        for (cube, outward, w) in l_and_cube() {
            for width in [0.0, 1e-3] {
                let (mut vertices, mut faces) = (Vec::new(), Polygons::new());
                prism(&mut vertices, &mut faces, &l, (0.0, 1.0), outward);
                prism(&mut vertices, &mut faces, &cube, (0.25, 0.75), true);
                // The L's first side (x = 1, the notch's wall: 8 cap triangles before it) and the
                // cube's (y = its lowest), each at its lower edge, opened downwards.
                let faces = cracked(&mut vertices, &faces, (8, 0), [0.0, 0.0, -width]);
                let faces = cracked(&mut vertices, &faces, (14 + 4, 0), [0.0, 0.0, -width]);
                let (shells, uses) = shells(&vertices, &faces);
                assert_eq!(shells.len(), 2);
                assert!(shells.iter().all(|s| s.closed && !s.sealed));
                let pairs = overlapping_pairs(&shells).expect("within the limits");
                assert_eq!(pairs, [(0, 1)]);
                let tris: Vec<Vec<[u32; 3]>> = shells.iter().map(|s| fan(&faces, &s.faces)).collect();
                let shell_of: Vec<u32> = (0..faces.len() as u32).map(|f| u32::from(f >= 14)).collect();
                let caps = cracks::caps(&uses, &shell_of, 2);
                assert!(caps.iter().all(|c| !c.is_empty()));
                // Each shell and its caps: every edge as often one way as the other.
                for (t, c) in tris.iter().zip(&caps) {
                    let mut net: FxHashMap<u64, i64> = FxHashMap::default();
                    for [x, y, z] in t.iter().chain(c) {
                        for (u, v) in [(x, y), (y, z), (z, x)] {
                            *net.entry(edge_key(*u, *v)).or_default() += if u < v { 1 } else { -1 };
                        }
                    }
                    assert!(net.values().all(|&n| n == 0));
                }
                let want = [0, w];
                assert_eq!(pair_by_pair(&vertices, &shells, (&tris, &uses), &pairs), (want.to_vec(), vec![true; 2]));
                for (a, b) in [(0, 1), (1, 0)] {
                    for v in tris[a].iter().flatten() {
                        let p = vertices[*v as usize];
                        let counted = capped(&vertices, (&tris[b], &boxes_of(&vertices, &tris[b])), &caps[b], &shells[b].bounds, p);
                        assert_eq!(counted, Some(want[a]), "{cube:?} {outward} {width} {a}");
                        assert_eq!(integer(winding(&vertices, &tris[b], p)), Some(want[a]), "{cube:?} {outward} {width} {a}");
                    }
                }
                if width > 0.0 && outward {
                    // In front of the L's sliver (in x = 1, y from 1 to 2, below z = 0 to 1e-3 at
                    // y = 1.5), a tenth of its width off it.
                    let p = [1.0 + 1e-4, 1.5, -3e-4];
                    let stray = winding(&vertices, &tris[0], p);
                    assert!((stray - stray.round()).abs() > NOT_INTEGER, "{stray}");
                    let boxes = boxes_of(&vertices, &tris[0]);
                    assert_eq!(capped(&vertices, (&tris[0], &boxes), &caps[0], &shells[0].bounds, p), None);
                }
            }
        }
    }

    /// Pair by pair and all at once decide alike: nested boxes (all outward, or alternating), some
    /// moved so that they cut their neighbours, one left open.
    #[test]
    fn pair_by_pair_and_all_at_once_agree() {
        for (count, alternate, moved, open) in [
            (12, false, None, false),
            (12, true, None, false),
            (40, true, Some(7), false),
            (40, false, Some(20), true),
        ] {
            let (mut vertices, mut faces, _) = nested_boxes(count, alternate);
            if let Some(k) = moved {
                for v in &mut vertices[8 * k..8 * k + 8] {
                    v[1] += 1.5;
                }
            }
            if open {
                let kept: Vec<Vec<u32>> = faces.iter().skip(1).map(<[u32]>::to_vec).collect();
                faces = Polygons::new();
                for f in &kept {
                    faces.push(f);
                }
            }
            let (shells, uses) = shells(&vertices, &faces);
            let pairs = overlapping_pairs(&shells).expect("within the limits");
            assert!(pairs.len() >= count - 1, "{}", pairs.len());
            let tris: Vec<Vec<[u32; 3]>> = shells.iter().map(|s| fan(&faces, &s.faces)).collect();
            // `w_out` counts only where the shell is decided ([`orient`]).
            let kept = |(w, d): (Vec<i64>, Vec<bool>)| -> Vec<Option<i64>> {
                w.iter().zip(&d).map(|(&w, &d)| d.then_some(w)).collect()
            };
            let one = kept(pair_by_pair(&vertices, &shells, (&tris, &uses), &pairs));
            let all = kept(nesting::nestings(&vertices, &shells, &tris, &pairs).expect("within the caps"));
            assert_eq!(one, all, "{count} {alternate} {moved:?} {open}");
            // An open shell leaves every pair around it undecided: all of them, nested.
            assert_eq!(one.iter().any(Option::is_some), !open);
        }
    }
}
