//! The in-plane boxes of a coplanar group's loops, and whether a new one meets any of them: a grid
//! of cells of the boxes' median size, chosen again each time their number doubles, so a cap
//! looks only at the boxes near its own instead of every member's (quadratic in the holes of one
//! flat side: 100,000 in a strip, 5·10⁹ box tests).

use rustc_hash::FxHashMap;

/// Boxes before which the grid is not worth it: all are looked at.
const FIRST_GRID: usize = 16;

/// Cells beyond which a box is not put in the grid, or a query not answered from it: such a box
/// is kept aside and looked at by every query, such a query looks at every box (boxes of one group
/// are disjoint, so few are many times the median; a mesh made of them is as slow as before).
const MAX_CELLS: i64 = 64;

/// Boxes `[x_lo, y_lo, x_hi, y_hi]`, closed: two meet when they share a point.
pub(super) struct PlaneBoxes {
    boxes: Vec<[f64; 4]>,
    /// The cells' side (0: no grid yet, every box is looked at) and the grid's origin.
    cell: f64,
    origin: [f64; 2],
    /// The boxes meeting each cell, by the cell's (column, row).
    grid: FxHashMap<(i64, i64), Vec<u32>>,
    /// Boxes kept out of the grid (over too many cells, not finite, or inverted).
    aside: Vec<u32>,
    /// The number of boxes at which the grid is made again.
    regrid_at: usize,
}

impl PlaneBoxes {
    pub(super) fn new() -> Self {
        PlaneBoxes {
            boxes: Vec::new(),
            cell: 0.0,
            origin: [0.0; 2],
            grid: FxHashMap::default(),
            aside: Vec::new(),
            regrid_at: FIRST_GRID,
        }
    }

    /// Whether `b` meets one of the boxes (exactly the test of each box in turn: a box that meets
    /// `b` shares a point with it, and that point's cell is among both boxes' cells, because the
    /// cell of a coordinate, `⌊(x − origin) / cell⌋` in f64, never decreases as it grows).
    pub(super) fn meets(&self, b: [f64; 4]) -> bool {
        if let Some([x0, y0, x1, y1]) = self.cells(b) {
            let near = (x0..=x1)
                .flat_map(|i| (y0..=y1).map(move |j| (i, j)))
                .filter_map(|ij| self.grid.get(&ij))
                .flatten();
            return (self.aside.iter().chain(near)).any(|&i| meet(b, self.boxes[i as usize]));
        }
        self.boxes.iter().any(|o| meet(b, *o))
    }

    pub(super) fn push(&mut self, b: [f64; 4]) {
        self.boxes.push(b);
        if self.boxes.len() >= self.regrid_at {
            self.regrid();
        } else if self.cell > 0.0 {
            self.insert(self.boxes.len() - 1);
        }
    }

    /// A grid of cells of the boxes' median size (their larger side); none when no box has a
    /// finite positive size.
    fn regrid(&mut self) {
        self.regrid_at = 2 * self.boxes.len();
        self.grid.clear();
        self.aside.clear();
        let mut sizes: Vec<f64> = (self.boxes.iter())
            .map(|b| (b[2] - b[0]).max(b[3] - b[1]))
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect();
        if sizes.is_empty() {
            self.cell = 0.0;
            return;
        }
        let half = sizes.len() / 2;
        self.cell = *sizes.select_nth_unstable_by(half, f64::total_cmp).1;
        let first = self.boxes.iter().find(|b| b.iter().all(|x| x.is_finite()));
        self.origin = first.map_or([0.0; 2], |b| [b[0], b[1]]);
        for i in 0..self.boxes.len() {
            self.insert(i);
        }
    }

    fn insert(&mut self, i: usize) {
        let Some([x0, y0, x1, y1]) = self.cells(self.boxes[i]) else {
            self.aside.push(i as u32);
            return;
        };
        for x in x0..=x1 {
            for y in y0..=y1 {
                self.grid.entry((x, y)).or_default().push(i as u32);
            }
        }
    }

    /// The range of cells `b` covers, when there is a grid, `b` is a finite box (not inverted) and
    /// it covers at most [`MAX_CELLS`].
    fn cells(&self, b: [f64; 4]) -> Option<[i64; 4]> {
        let proper = b.iter().all(|x| x.is_finite()) && b[0] <= b[2] && b[1] <= b[3];
        if self.cell <= 0.0 || !proper {
            return None;
        }
        let at = |x: f64, o: f64| ((x - o) / self.cell).floor() as i64;
        let [x0, y0] = [at(b[0], self.origin[0]), at(b[1], self.origin[1])];
        let [x1, y1] = [at(b[2], self.origin[0]), at(b[3], self.origin[1])];
        let span = |lo: i64, hi: i64| hi.saturating_sub(lo).saturating_add(1);
        (span(x0, x1).saturating_mul(span(y0, y1)) <= MAX_CELLS).then_some([x0, y0, x1, y1])
    }
}

/// Whether two closed boxes share a point (as [`super::Caps::coplanar_groups`] always tested it,
/// NaN included: a box with NaN meets every box).
fn meet(b: [f64; 4], o: [f64; 4]) -> bool {
    !(b[2] < o[0] || o[2] < b[0] || b[3] < o[1] || o[3] < b[1])
}
