//! A hierarchy of boxes over the triangles of many shells: the pairs of triangles of different
//! shells whose boxes meet, and the triangles whose boxes an axis-parallel ray meets.
//!
//! A uniform grid ([`super::grid`]) puts a triangle in every cell its box covers (or, a large one,
//! in those of them it may meet); shells nested in each other (concentric spheres of growing
//! radius) have triangles of every size, and the large ones cover thousands of cells each. A tree
//! of boxes holds each triangle once.

use crate::geometry::Aabb;
use std::ops::ControlFlow;

use super::overlap;

/// Triangles per leaf at most.
const LEAF: usize = 4;

/// One node: a leaf holds `order[start..start + len]`, an inner node has children `left` and
/// `left + 1`.
#[derive(Clone, Copy)]
struct Node {
    bounds: Aabb,
    start: u32,
    len: u32,
    left: u32,
    /// The one group (shell) all its triangles belong to, or `u32::MAX`.
    group: u32,
}

pub(super) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    boxes: Vec<Aabb>,
    group: Vec<u32>,
}

impl Bvh {
    /// The tree over triangles with boxes `boxes`, each in group `group[i]` (its shell): a median
    /// split of the centres along the axis of their widest spread, down to leaves of [`LEAF`].
    pub(super) fn new(boxes: Vec<Aabb>, group: &[u32]) -> Bvh {
        let n = boxes.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF + 1);
        let centre = |i: u32, k: usize| boxes[i as usize].lo[k] + boxes[i as usize].hi[k];
        nodes.push(Node {
            bounds: Aabb::EMPTY,
            start: 0,
            len: n as u32,
            left: 0,
            group: u32::MAX,
        });
        let mut stack = vec![0usize];
        while let Some(at) = stack.pop() {
            let (start, len) = (nodes[at].start as usize, nodes[at].len as usize);
            let items = &mut order[start..start + len];
            let bounds = items.iter().fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
            let first = items.first().map_or(u32::MAX, |&i| group[i as usize]);
            let one = items.iter().all(|&i| group[i as usize] == first);
            nodes[at].bounds = bounds;
            nodes[at].group = if one { first } else { u32::MAX };
            if len <= LEAF {
                continue;
            }
            // Along the widest spread of the centres, not the box's longest side: boxes all as
            // long as the node along one axis (parts in rows, a long box each) have their centres
            // in one place there, and split there every node's halves kept its box, so that every
            // pair of nodes met (45,000 such boxes: 20 s for their pairs).
            let spread = items.iter().fold(Aabb::EMPTY, |b, &i| {
                let c = [0, 1, 2].map(|k| centre(i, k));
                b.union(Aabb::new(c, c))
            });
            let ext = spread.extent();
            let k = (0..3).fold(0, |m, k| if ext[k] > ext[m] { k } else { m });
            let half = len / 2;
            items.select_nth_unstable_by(half, |&p, &q| centre(p, k).total_cmp(&centre(q, k)));
            let left = nodes.len();
            for (s, l) in [(start, half), (start + half, len - half)] {
                nodes.push(Node {
                    bounds: Aabb::EMPTY,
                    start: s as u32,
                    len: l as u32,
                    left: 0,
                    group: u32::MAX,
                });
            }
            nodes[at].left = left as u32;
            nodes[at].len = 0;
            stack.extend([left, left + 1]);
        }
        if n == 0 {
            nodes.clear();
        }
        Bvh {
            nodes,
            order,
            boxes,
            group: group.to_vec(),
        }
    }

    pub(super) fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    fn leaf(&self, n: &Node) -> &[u32] {
        &self.order[n.start as usize..(n.start + n.len) as usize]
    }

    /// Each pair of triangles of different groups whose boxes meet as closed boxes (touching
    /// counts), once, until `visit` breaks. Subtrees of one group are not paired with themselves.
    pub(super) fn pairs(&self, mut visit: impl FnMut(u32, u32) -> ControlFlow<()>) -> ControlFlow<()> {
        if self.nodes.is_empty() {
            return ControlFlow::Continue(());
        }
        let mut stack = vec![(0u32, 0u32)];
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            if na.group != u32::MAX && na.group == nb.group {
                continue;
            }
            if a == b {
                if na.len > 0 {
                    let items = self.leaf(na);
                    for (x, &i) in items.iter().enumerate() {
                        for &j in &items[x + 1..] {
                            self.pair(i, j, &mut visit)?;
                        }
                    }
                } else {
                    let l = na.left;
                    stack.extend([(l, l), (l + 1, l + 1), (l, l + 1)]);
                }
                continue;
            }
            if !overlap(&na.bounds, &nb.bounds) {
                continue;
            }
            match (na.len > 0, nb.len > 0) {
                (true, true) => {
                    for &i in self.leaf(na) {
                        for &j in self.leaf(nb) {
                            self.pair(i, j, &mut visit)?;
                        }
                    }
                }
                // Descend the inner node, the larger one when both are.
                (true, false) => stack.extend([(a, nb.left), (a, nb.left + 1)]),
                (false, true) => stack.extend([(na.left, b), (na.left + 1, b)]),
                (false, false) => {
                    if na.bounds.diagonal() >= nb.bounds.diagonal() {
                        stack.extend([(na.left, b), (na.left + 1, b)]);
                    } else {
                        stack.extend([(a, nb.left), (a, nb.left + 1)]);
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }

    fn pair(&self, i: u32, j: u32, visit: &mut impl FnMut(u32, u32) -> ControlFlow<()>) -> ControlFlow<()> {
        if self.group[i as usize] != self.group[j as usize] && overlap(&self.boxes[i as usize], &self.boxes[j as usize]) {
            visit(i, j)
        } else {
            ControlFlow::Continue(())
        }
    }

    /// Each triangle whose box meets the ray from `p` along `sign`·e_`axis` (closed boxes).
    pub(super) fn ray(&self, p: [f64; 3], axis: usize, sign: f64, mut visit: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let (mut lo, mut hi) = (p, p);
        if sign > 0.0 {
            hi[axis] = f64::INFINITY;
        } else {
            lo[axis] = f64::NEG_INFINITY;
        }
        let ray = Aabb::new(lo, hi);
        let mut stack = vec![0u32];
        while let Some(at) = stack.pop() {
            let n = &self.nodes[at as usize];
            if !overlap(&n.bounds, &ray) {
                continue;
            }
            if n.len > 0 {
                for &i in self.leaf(n) {
                    if overlap(&self.boxes[i as usize], &ray) {
                        visit(i);
                    }
                }
            } else {
                stack.extend([n.left, n.left + 1]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree finds exactly the pairs of boxes of different groups that meet, each once, and
    /// the boxes a ray meets: against all pairs, on boxes of a coarse lattice (many touch).
    #[test]
    fn the_tree_finds_what_all_pairs_find() {
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = |n: u64| crate::xorshift(&mut state) % n;
        for count in [0, 1, 5, 37, 300] {
            let boxes: Vec<Aabb> = (0..count)
                .map(|_| {
                    let lo = [0; 3].map(|_| next(12) as f64);
                    let size = [0; 3].map(|_| next(4) as f64);
                    Aabb::new(lo, [0, 1, 2].map(|k| lo[k] + size[k]))
                })
                .collect();
            let group: Vec<u32> = (0..count).map(|_| next(5) as u32).collect();
            let bvh = Bvh::new(boxes.clone(), &group);
            let mut want = Vec::new();
            for i in 0..count {
                for j in i + 1..count {
                    if group[i] != group[j] && overlap(&boxes[i], &boxes[j]) {
                        want.push((i as u32, j as u32));
                    }
                }
            }
            let mut got = Vec::new();
            let _ = bvh.pairs(|i, j| {
                got.push((i.min(j), i.max(j)));
                ControlFlow::Continue(())
            });
            got.sort_unstable();
            assert_eq!(got, want, "{count}");
            for (axis, sign) in [(0, 1.0), (1, -1.0), (2, 1.0)] {
                let p = [5.0, 6.0, 7.0];
                let mut got = Vec::new();
                bvh.ray(p, axis, sign, |i| got.push(i));
                got.sort_unstable();
                let want: Vec<u32> = (0..count as u32)
                    .filter(|&i| {
                        let b = &boxes[i as usize];
                        (0..3).all(|k| {
                            if k == axis {
                                if sign > 0.0 { b.hi[k] >= p[k] } else { b.lo[k] <= p[k] }
                            } else {
                                b.lo[k] <= p[k] && p[k] <= b.hi[k]
                            }
                        })
                    })
                    .collect();
                assert_eq!(got, want, "{count} {axis}");
            }
        }
    }
}
