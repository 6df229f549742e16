//! Neighbour search (SPEC §3): the uniform cell grid under every spatial
//! search of the code, and which particles' windows cover a given point.
//!
//! [`CellGrid`] bins items into square cells, counting-sorted into one
//! compressed array: a point goes into the cell of its floor index, a box
//! into every cell it overlaps. It is the one implementation of the idea:
//! the particle searches here, in the fracture module and in the plug's flood
//! fill bin points directly; contact's point grid (nearest point, fixed
//! radius) and its grid of master segments (boxes) wrap it with their own
//! fills.
//!
//! [`SupportSearch`] uses a grid with cell size equal to the largest support
//! size, so a point's candidates lie in its own cell and the 8 around it.
//! Built once (total Lagrangian) and again only where cracks change
//! visibility. Results come back sorted by particle index, so the
//! shape-function table — and every sum built on it — is independent of
//! thread count.

use serde::{Deserialize, Serialize};

use crate::math::{Real, Vec2};

/// The inclusive cell rectangle `[x0, x1] × [y0, y1]` of a [`CellLayout`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CellRange {
    /// First and last cell column.
    pub x0: usize,
    pub x1: usize,
    /// First and last cell row.
    pub y0: usize,
    pub y1: usize,
}

impl CellRange {
    /// The single cell `(ix, iy)`.
    pub fn cell((ix, iy): (usize, usize)) -> Self {
        CellRange { x0: ix, x1: ix, y0: iy, y1: iy }
    }

    /// The cells' indices `iy nx + ix` in a layout `nx` cells wide, row by
    /// row (by increasing `iy`, then `ix`); none for an empty range.
    pub fn indices(self, nx: usize) -> impl Iterator<Item = usize> {
        (self.y0..=self.y1).flat_map(move |iy| (self.x0..=self.x1).map(move |ix| iy * nx + ix))
    }
}

/// Where the cells of a [`CellGrid`] lie: `nx × ny` square cells of edge
/// `cell` from `origin`; cell `(ix, iy)` covers
/// `origin + [ix, ix + 1) cell × [iy, iy + 1) cell` and has index
/// `iy nx + ix`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CellLayout {
    /// Lower-left corner of cell (0, 0), m.
    origin: Vec2,
    /// Cell edge length, m.
    cell: Real,
    /// Number of cells along x and y (at least 1 each once laid out).
    nx: usize,
    ny: usize,
}

impl CellLayout {
    /// Cells of edge `cell` (> 0) from `lo` covering the box `[lo, hi]`:
    /// `n = ⌊(hi − lo)/cell⌋ + 1` along each axis.
    pub fn new(lo: Vec2, hi: Vec2, cell: Real) -> Self {
        let nx = ((hi.x - lo.x) / cell).floor() as usize + 1;
        let ny = ((hi.y - lo.y) / cell).floor() as usize + 1;
        CellLayout { origin: lo, cell, nx, ny }
    }

    /// `cell`, doubled until a box of size `extent` needs at most
    /// `4 items + 64` cells, so that a grid's memory stays linear in its
    /// number of items. `extent` finite and `cell` positive and finite.
    pub fn capped_cell(extent: Vec2, cell: Real, items: usize) -> Real {
        let max_cells = (4 * items + 64) as Real;
        let mut cell = cell;
        while ((extent.x / cell).floor() + 1.0) * ((extent.y / cell).floor() + 1.0) > max_cells {
            cell *= 2.0;
        }
        cell
    }

    /// Lower-left corner of cell (0, 0), m.
    pub fn origin(&self) -> Vec2 {
        self.origin
    }

    /// Cell edge length, m.
    pub fn cell_size(&self) -> Real {
        self.cell
    }

    /// Number of cells along x and y.
    pub fn dims(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// `⌊(p − origin)/cell⌋`, unclamped.
    #[inline]
    fn floor_index(&self, p: &Vec2) -> (Real, Real) {
        (((p.x - self.origin.x) / self.cell).floor(), ((p.y - self.origin.y) / self.cell).floor())
    }

    /// A floor index clamped to the grid.
    #[inline]
    fn clamp(&self, (fx, fy): (Real, Real)) -> (usize, usize) {
        // `as usize` saturates (and maps NaN to 0): no panic on any input.
        (fx.clamp(0.0, (self.nx - 1) as Real) as usize, fy.clamp(0.0, (self.ny - 1) as Real) as usize)
    }

    /// Cell coordinates `(ix, iy)` of `p`: its floor index, clamped to the
    /// grid (a point outside goes to the nearest edge cell, a NaN
    /// coordinate to 0).
    #[inline]
    pub fn cell_coords(&self, p: &Vec2) -> (usize, usize) {
        self.clamp(self.floor_index(p))
    }

    /// Index of the cell holding `p`, `None` outside the grid (or for a
    /// NaN coordinate).
    #[inline]
    pub fn cell_at(&self, p: &Vec2) -> Option<usize> {
        let (fx, fy) = ((p.x - self.origin.x) / self.cell, (p.y - self.origin.y) / self.cell);
        if !(fx >= 0.0 && fy >= 0.0 && fx < self.nx as Real && fy < self.ny as Real) {
            return None;
        }
        Some(fy as usize * self.nx + fx as usize)
    }

    /// The cells of the box `[lo, hi]`, its corners clamped to the grid
    /// (a box outside the grid gets the edge cells nearest to it).
    #[inline]
    pub fn cells_of_box(&self, lo: &Vec2, hi: &Vec2) -> CellRange {
        let ((x0, y0), (x1, y1)) = (self.cell_coords(lo), self.cell_coords(hi));
        CellRange { x0, x1, y0, y1 }
    }

    /// The cells of the box `[lo, hi]` clamped to the grid, `None` if the
    /// box lies wholly outside it.
    #[inline]
    pub fn cells_overlapping(&self, lo: &Vec2, hi: &Vec2) -> Option<CellRange> {
        let (flo, fhi) = (self.floor_index(lo), self.floor_index(hi));
        if fhi.0 < 0.0 || fhi.1 < 0.0 || flo.0 >= self.nx as Real || flo.1 >= self.ny as Real {
            return None;
        }
        let ((x0, y0), (x1, y1)) = (self.clamp(flo), self.clamp(fhi));
        Some(CellRange { x0, x1, y0, y1 })
    }
}

/// Items binned into the square cells of a [`CellLayout`], counting-sorted
/// into one compressed array: two allocations, reused by [`Self::fill`];
/// queries never allocate. An item may be listed in several cells (a box).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CellGrid {
    layout: CellLayout,
    /// Cell `c = iy nx + ix` holds `items[start[c]..start[c + 1]]`; length
    /// `nx ny + 1`.
    start: Vec<u32>,
    /// Item indices grouped by cell, ascending within a cell.
    items: Vec<u32>,
}

/// The bounding box `(lo, hi)` of `points`; `(0, 0)` for none.
pub fn bounding_box(points: &[Vec2]) -> (Vec2, Vec2) {
    if points.is_empty() {
        return (Vec2::zeros(), Vec2::zeros());
    }
    let (mut lo, mut hi) = (Vec2::repeat(Real::INFINITY), Vec2::repeat(Real::NEG_INFINITY));
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

impl CellGrid {
    /// Bin `points` into cells of size `cell` (> 0) over their bounding box.
    pub fn new(points: &[Vec2], cell: Real) -> Self {
        assert!(cell > 0.0 && cell.is_finite(), "cell size must be positive");
        let (lo, hi) = bounding_box(points);
        Self::of_points(CellLayout::new(lo, hi, cell), points)
    }

    /// Bin `points` into the cells of `layout`, each into the cell of
    /// [`CellLayout::cell_coords`].
    pub fn of_points(layout: CellLayout, points: &[Vec2]) -> Self {
        let mut grid = CellGrid::default();
        grid.fill(layout, points.len(), |i| CellRange::cell(layout.cell_coords(&points[i])));
        grid
    }

    /// Lay the grid out as `layout` and list each item `k < count` in every
    /// cell of `cells_of(k)` (counting sort: two calls per item, the items
    /// of a cell in ascending order). Reuses the grid's allocations.
    pub fn fill(&mut self, layout: CellLayout, count: usize, cells_of: impl Fn(usize) -> CellRange) {
        let (nx, cells) = (layout.nx, layout.nx * layout.ny);
        let each_cell = |r: CellRange| r.indices(nx);
        self.layout = layout;
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for k in 0..count {
            for c in each_cell(cells_of(k)) {
                self.start[c + 1] += 1;
            }
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        self.items.clear();
        self.items.resize(self.start[cells] as usize, 0);
        // Place each item at its cell's cursor `start[c]`, which ends at
        // the next cell's start; then shift the starts back by one cell.
        for k in 0..count {
            for c in each_cell(cells_of(k)) {
                self.items[self.start[c] as usize] = k as u32;
                self.start[c] += 1;
            }
        }
        self.start.copy_within(0..cells, 1);
        self.start[0] = 0;
    }

    /// Where the cells lie.
    pub fn layout(&self) -> &CellLayout {
        &self.layout
    }

    /// The items listed in cell `c` (`iy nx + ix`), ascending.
    #[inline]
    pub fn cell_items(&self, c: usize) -> &[u32] {
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// The items listed in the cell holding `p` ([`CellLayout::cell_at`]);
    /// none outside the grid.
    #[inline]
    pub fn items_at(&self, p: &Vec2) -> &[u32] {
        match self.layout.cell_at(p) {
            Some(c) => self.cell_items(c),
            None => &[],
        }
    }

    /// Call `f(k)` for every item listed in the cells of `range`, row by
    /// row (cells by increasing `iy`, then `ix`; ascending within a cell;
    /// an item once per cell it is listed in).
    #[inline]
    pub fn for_each_in(&self, range: CellRange, mut f: impl FnMut(usize)) {
        if range.x0 > range.x1 {
            return;
        }
        for iy in range.y0..=range.y1 {
            let row = iy * self.layout.nx;
            let (a, b) = (self.start[row + range.x0] as usize, self.start[row + range.x1 + 1] as usize);
            for &i in &self.items[a..b] {
                f(i as usize);
            }
        }
    }

    /// Call `f(i)` for every binned point within `reach` (≤ cell size) of `x`
    /// in each coordinate direction — a superset filter; the caller tests
    /// exactly. Nothing if that box lies wholly outside the grid.
    pub fn for_each_candidate(&self, x: &Vec2, reach: Real, f: impl FnMut(usize)) {
        if let Some(range) = self.cells_near(x, reach) {
            self.for_each_in(range, f);
        }
    }

    /// The cells [`Self::for_each_candidate`] visits for `x` and `reach`:
    /// those the box `x ± reach` overlaps; none if it lies wholly outside
    /// the grid.
    pub fn cells_near(&self, x: &Vec2, reach: Real) -> Option<CellRange> {
        let lo = Vec2::new(x.x - reach, x.y - reach);
        let hi = Vec2::new(x.x + reach, x.y + reach);
        self.layout.cells_overlapping(&lo, &hi)
    }
}

/// Particles whose square window `|X − X_I|_∞ < a_I` covers a point.
#[derive(Clone, Debug)]
pub struct SupportSearch<'a> {
    x0: &'a [Vec2],
    support: &'a [Real],
    max_support: Real,
    grid: CellGrid,
}

impl<'a> SupportSearch<'a> {
    /// Index the particles at reference positions `x0` with supports `support`.
    pub fn new(x0: &'a [Vec2], support: &'a [Real]) -> Self {
        let max_support = support.iter().cloned().fold(0.0, Real::max);
        let cell = if max_support > 0.0 { max_support } else { 1.0 };
        SupportSearch { x0, support, max_support, grid: CellGrid::new(x0, cell) }
    }

    /// Indices of the particles covering `x`, sorted ascending, into `out`.
    pub fn covering(&self, x: &Vec2, out: &mut Vec<u32>) {
        out.clear();
        self.grid.for_each_candidate(x, self.max_support, |i| {
            let z = x - self.x0[i];
            let a = self.support[i];
            if z.x.abs() < a && z.y.abs() < a {
                out.push(i as u32);
            }
        });
        out.sort_unstable();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(x: &Vec2, x0: &[Vec2], a: &[Real]) -> Vec<u32> {
        (0..x0.len())
            .filter(|&i| (x.x - x0[i].x).abs() < a[i] && (x.y - x0[i].y).abs() < a[i])
            .map(|i| i as u32)
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(7), ..ProptestConfig::default() })]
        #[test]
        fn grid_search_equals_brute_force(
            pts in proptest::collection::vec((-1.0f64..1.0, -0.5f64..0.5, 0.01f64..0.4), 1..200),
            q in proptest::collection::vec((-1.5f64..1.5, -1.0f64..1.0), 1..20),
        ) {
            let x0: Vec<Vec2> = pts.iter().map(|p| Vec2::new(p.0, p.1)).collect();
            let a: Vec<Real> = pts.iter().map(|p| p.2).collect();
            let s = SupportSearch::new(&x0, &a);
            let mut out = Vec::new();
            for (qx, qy) in q {
                let x = Vec2::new(qx, qy);
                s.covering(&x, &mut out);
                prop_assert_eq!(&out, &brute(&x, &x0, &a));
            }
        }
    }
    /// The items of the cells of `range` in row order, from the item
    /// ranges alone: the reference for [`CellGrid::for_each_in`].
    fn brute_cells(range: CellRange, ranges: &[CellRange]) -> Vec<usize> {
        let mut out = Vec::new();
        for iy in range.y0..=range.y1 {
            for ix in range.x0..=range.x1 {
                out.extend((0..ranges.len()).filter(|&k| {
                    let r = ranges[k];
                    (r.x0..=r.x1).contains(&ix) && (r.y0..=r.y1).contains(&iy)
                }));
            }
        }
        out
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(11), ..ProptestConfig::default() })]
        #[test]
        fn box_query_returns_the_items_of_exactly_the_overlapping_cells(
            boxes in proptest::collection::vec((-1.0f64..1.0, -0.5f64..0.5, 0.0f64..0.3, 0.0f64..0.2), 0..60),
            q in proptest::collection::vec((-1.5f64..1.5, -1.0f64..1.0, 0.0f64..0.5, 0.0f64..0.5), 1..20),
            cell in 0.02f64..0.5,
        ) {
            let boxes: Vec<(Vec2, Vec2)> =
                boxes.iter().map(|b| (Vec2::new(b.0, b.1), Vec2::new(b.0 + b.2, b.1 + b.3))).collect();
            let corners: Vec<Vec2> = boxes.iter().flat_map(|b| [b.0, b.1]).collect();
            let (lo, hi) = bounding_box(&corners);
            let layout = CellLayout::new(lo, hi, cell);
            let ranges: Vec<CellRange> = boxes.iter().map(|(a, b)| layout.cells_of_box(a, b)).collect();
            // Refilling a grid that held something else equals a fresh fill.
            let mut grid = CellGrid::new(&[Vec2::new(5.0, 5.0), Vec2::new(-3.0, 0.0)], 0.1);
            grid.fill(layout, boxes.len(), |k| ranges[k]);
            let mut fresh = CellGrid::default();
            fresh.fill(layout, boxes.len(), |k| ranges[k]);
            prop_assert_eq!(&grid, &fresh);
            let (nx, ny) = layout.dims();
            for c in 0..nx * ny {
                prop_assert!(grid.cell_items(c).windows(2).all(|w| w[0] < w[1]));
            }
            for (qx, qy, w, h) in q {
                let (a, b) = (Vec2::new(qx, qy), Vec2::new(qx + w, qy + h));
                let range = layout.cells_of_box(&a, &b);
                let mut got = Vec::new();
                grid.for_each_in(range, |k| got.push(k));
                prop_assert_eq!(&got, &brute_cells(range, &ranges));
                // The unclamped query agrees where the box meets the grid.
                let outside = b.x < lo.x || b.y < lo.y
                    || a.x >= lo.x + nx as Real * cell || a.y >= lo.y + ny as Real * cell;
                prop_assert_eq!(layout.cells_overlapping(&a, &b), (!outside).then_some(range));
            }
        }
    }

    #[test]
    fn a_point_lies_in_the_cell_of_its_floor_index() {
        let mut s = 3u64;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as Real / (1u64 << 53) as Real
        };
        for _ in 0..50 {
            let n = 1 + (300.0 * next()) as usize;
            let pts: Vec<Vec2> = (0..n).map(|_| Vec2::new(2.0 * next() - 1.0, next())).collect();
            let cell = 0.01 + 0.3 * next();
            let grid = CellGrid::new(&pts, cell);
            let (lo, hi) = bounding_box(&pts);
            let layout = grid.layout();
            assert_eq!(layout.origin(), lo);
            let dims = (((hi.x - lo.x) / cell).floor() as usize + 1, ((hi.y - lo.y) / cell).floor() as usize + 1);
            assert_eq!(layout.dims(), dims);
            let (nx, ny) = layout.dims();
            let mut seen = vec![0; n];
            for c in 0..nx * ny {
                for &i in grid.cell_items(c) {
                    seen[i as usize] += 1;
                }
            }
            assert!(seen.iter().all(|&k| k == 1), "every point in exactly one cell");
            for (i, p) in pts.iter().enumerate() {
                let (ix, iy) = (((p.x - lo.x) / cell).floor() as usize, ((p.y - lo.y) / cell).floor() as usize);
                assert_eq!(layout.cell_coords(p), (ix, iy));
                assert_eq!(layout.cell_at(p), Some(iy * nx + ix));
                assert!(grid.items_at(p).contains(&(i as u32)));
            }
        }
    }

    #[test]
    fn empty_and_non_finite_inputs_find_nothing_or_an_edge_cell() {
        let empty = CellGrid::new(&[], 1.0);
        assert_eq!(empty.layout().dims(), (1, 1));
        assert_eq!(empty.layout().origin(), Vec2::zeros());
        let mut n = 0;
        empty.for_each_candidate(&Vec2::zeros(), 1.0, |_| n += 1);
        assert_eq!(n, 0);
        assert!(empty.items_at(&Vec2::zeros()).is_empty());

        // Four points, one per cell of a 2 x 2 grid.
        let pts = [Vec2::new(0.0, 0.0), Vec2::new(1.5, 0.0), Vec2::new(0.0, 1.5), Vec2::new(1.5, 1.5)];
        let grid = CellGrid::new(&pts, 1.0);
        let layout = grid.layout();
        assert_eq!(layout.dims(), (2, 2));
        let nan = Vec2::new(Real::NAN, 0.5);
        assert_eq!(layout.cell_coords(&nan), (0, 0));
        assert_eq!(layout.cell_at(&nan), None);
        let inf = Vec2::new(Real::INFINITY, Real::NEG_INFINITY);
        assert_eq!(layout.cell_coords(&inf), (1, 0));
        assert_eq!(layout.cell_at(&inf), None);
        // Outside the grid: the clamped box query keeps the nearest edge
        // cells, the candidate query finds nothing, the point query none.
        let far = Vec2::new(5.0, 0.2);
        assert_eq!(layout.cells_of_box(&far, &far), CellRange::cell((1, 0)));
        assert_eq!(layout.cells_overlapping(&far, &far), None);
        let mut got = Vec::new();
        grid.for_each_candidate(&far, 0.5, |i| got.push(i));
        assert!(got.is_empty());
        assert!(grid.items_at(&far).is_empty());
        grid.for_each_candidate(&Vec2::new(2.2, 0.2), 0.5, |i| got.push(i));
        assert_eq!(got, [1]);
        // A box with lo > hi (a negative reach) visits nothing.
        got.clear();
        grid.for_each_candidate(&Vec2::new(1.0, 1.0), -1.0, |i| got.push(i));
        assert!(got.is_empty());
    }

    #[test]
    #[should_panic(expected = "cell size must be positive")]
    fn a_cell_of_zero_is_refused() {
        CellGrid::new(&[Vec2::zeros()], 0.0);
    }

    #[test]
    fn capped_cell_keeps_the_cell_count_linear() {
        let extent = Vec2::new(1e6, 1e6);
        let cell = CellLayout::capped_cell(extent, 1e-9, 2);
        let layout = CellLayout::new(Vec2::zeros(), extent, cell);
        assert!(layout.dims().0 * layout.dims().1 <= 4 * 2 + 64);
        assert_eq!((cell / 1e-9).log2().fract(), 0.0, "the cell is doubled, not rescaled");
        // Wide enough already: unchanged.
        assert_eq!(CellLayout::capped_cell(Vec2::new(1.0, 1.0), 0.5, 0), 0.5);
    }
}
