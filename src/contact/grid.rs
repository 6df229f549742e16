//! A uniform cell grid over a fixed set of points: nearest-point and
//! fixed-radius queries in O(1) expected cost per query (SPEC §8, the
//! "coarse" stage of the contact search; also the neighbour query of the
//! surface detection).
//!
//! The points are binned in a [`CellGrid`] (counting-sorted by cell into one
//! compressed array), so a grid is three allocations and queries never
//! allocate. The grid is built once: the master vertices live in the rigid
//! body's own frame (the body only translates), and the surface detection
//! runs on a fixed particle set.

use crate::math::{Real, Vec2};
use crate::neighbors::{bounding_box, CellGrid, CellLayout, CellRange};

/// Relative safety margin on the ring-search stopping bound, so that a point
/// whose cell index was rounded across a cell face can never be skipped.
const BOUND_MARGIN: Real = 1e-9;

/// Uniform grid of square cells over a point set.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PointGrid {
    /// Point indices by cell, ascending index within a cell.
    cells: CellGrid,
    /// The points, in their original order.
    points: Vec<Vec2>,
}

impl PointGrid {
    /// Build a grid with cells of (at least) `cell` metres. The cell is
    /// enlarged if the bounding box would need more than `4 n + 64` cells,
    /// so memory stays linear in the number of points
    /// ([`CellLayout::capped_cell`]).
    ///
    /// Returns `None` if `cell` is not positive and finite or a point is not
    /// finite (callers validate their inputs first and map this to their own
    /// error).
    pub fn new(points: &[Vec2], cell: Real) -> Option<Self> {
        if !(cell.is_finite() && cell > 0.0) || points.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return None;
        }
        let (lo, hi) = bounding_box(points);
        let cell = CellLayout::capped_cell(hi - lo, cell, points.len());
        let cells = CellGrid::of_points(CellLayout::new(lo, hi, cell), points);
        Some(Self { cells, points: points.to_vec() })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the grid holds no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The points, in their original order.
    pub fn points(&self) -> &[Vec2] {
        &self.points
    }

    /// Cell edge length actually used, m.
    pub fn cell_size(&self) -> Real {
        self.cells.layout().cell_size()
    }

    /// The nearest point to `p` and its squared distance; among points at
    /// the same distance, the one with the smallest index (so that the
    /// result equals [`nearest_brute_force`]). `None` for an empty grid.
    ///
    /// Ring search: visit the Chebyshev rings of cells around `p`'s cell
    /// until the best distance found is below the distance from `p` to any
    /// cell not yet visited.
    pub fn nearest(&self, p: &Vec2) -> Option<(usize, Real)> {
        if self.points.is_empty() {
            return None;
        }
        let layout = self.cells.layout();
        let (nx, ny) = layout.dims();
        let (origin, c) = (layout.origin(), layout.cell_size());
        let (cx, cy) = layout.cell_coords(p);
        let mut best: Option<(usize, Real)> = None;
        let consider = |i: usize, best: &mut Option<(usize, Real)>| {
            let d2 = (self.points[i] - p).norm_squared();
            match *best {
                Some((bi, bd)) if d2 > bd || (d2 == bd && i > bi) => {}
                _ => *best = Some((i, d2)),
            }
        };
        let visit_box = |x0, x1, y0, y1, best: &mut Option<(usize, Real)>| {
            self.cells.for_each_in(CellRange { x0, x1, y0, y1 }, |i| consider(i, best))
        };
        let mut k = 0usize;
        loop {
            // Ring k: cells at Chebyshev distance exactly k from (cx, cy).
            let x0 = cx.saturating_sub(k);
            let x1 = (cx + k).min(nx - 1);
            let y0 = cy.saturating_sub(k);
            let y1 = (cy + k).min(ny - 1);
            if k == 0 {
                visit_box(cx, cx, cy, cy, &mut best);
            } else {
                if cy >= k {
                    visit_box(x0, x1, cy - k, cy - k, &mut best);
                }
                if cy + k < ny {
                    visit_box(x0, x1, cy + k, cy + k, &mut best);
                }
                let (ry0, ry1) = (cy.saturating_sub(k - 1), (cy + k - 1).min(ny - 1));
                if cx >= k {
                    visit_box(cx - k, cx - k, ry0, ry1, &mut best);
                }
                if cx + k < nx {
                    visit_box(cx + k, cx + k, ry0, ry1, &mut best);
                }
            }
            // Lower bound of the distance from p to any cell outside the
            // visited box, over the faces that have not reached the grid edge.
            let mut bound = Real::INFINITY;
            if x0 > 0 {
                bound = bound.min(p.x - (origin.x + x0 as Real * c));
            }
            if x1 + 1 < nx {
                bound = bound.min(origin.x + (x1 + 1) as Real * c - p.x);
            }
            if y0 > 0 {
                bound = bound.min(p.y - (origin.y + y0 as Real * c));
            }
            if y1 + 1 < ny {
                bound = bound.min(origin.y + (y1 + 1) as Real * c - p.y);
            }
            if bound == Real::INFINITY {
                return best; // every cell visited
            }
            let bound = bound - BOUND_MARGIN * c;
            if let Some((_, bd)) = best {
                if bound > 0.0 && bd < bound * bound {
                    return best;
                }
            }
            k += 1;
        }
    }

    /// Call `f(i, d2)` for every point `i` with squared distance `d2 < r²`
    /// from `p`, in cell order.
    pub fn for_each_within(&self, p: &Vec2, r: Real, mut f: impl FnMut(usize, Real)) {
        if self.points.is_empty() || r.is_nan() || r <= 0.0 {
            return;
        }
        let range = self.cells.layout().cells_of_box(&Vec2::new(p.x - r, p.y - r), &Vec2::new(p.x + r, p.y + r));
        let r2 = r * r;
        self.cells.for_each_in(range, |i| {
            let d2 = (self.points[i] - p).norm_squared();
            if d2 < r2 {
                f(i, d2);
            }
        });
    }
}

/// Reference for [`PointGrid::nearest`]: an O(n) loop, ties to the smallest
/// index. For tests and small sets only.
pub fn nearest_brute_force(points: &[Vec2], p: &Vec2) -> Option<(usize, Real)> {
    let mut best: Option<(usize, Real)> = None;
    for (i, q) in points.iter().enumerate() {
        let d2 = (q - p).norm_squared();
        if best.is_none_or(|(_, bd)| d2 < bd) {
            best = Some((i, d2));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64: a tiny deterministic generator for seeded test loops.
    fn splitmix(state: &mut u64) -> Real {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as Real / (1u64 << 53) as Real
    }

    #[test]
    fn nearest_matches_brute_force_on_random_sets() {
        let mut s = 42u64;
        for trial in 0..200 {
            let n = 1 + (splitmix(&mut s) * 300.0) as usize;
            let pts: Vec<Vec2> = (0..n).map(|_| Vec2::new(splitmix(&mut s), 3.0 * splitmix(&mut s))).collect();
            let cell = 0.01 + 0.5 * splitmix(&mut s);
            let g = PointGrid::new(&pts, cell).unwrap();
            for _ in 0..50 {
                // queries inside and well outside the bounding box
                let q = Vec2::new(4.0 * splitmix(&mut s) - 1.5, 9.0 * splitmix(&mut s) - 3.0);
                assert_eq!(g.nearest(&q), nearest_brute_force(&pts, &q), "trial {trial}, q = {q:?}");
            }
        }
    }

    #[test]
    fn nearest_breaks_ties_by_smallest_index() {
        // a regular lattice queried at cell centres: four equidistant points
        let pts: Vec<Vec2> = (0..100).map(|k| Vec2::new((k % 10) as Real, (k / 10) as Real)).collect();
        let g = PointGrid::new(&pts, 1.0).unwrap();
        for k in 0..81 {
            let q = Vec2::new((k % 9) as Real + 0.5, (k / 9) as Real + 0.5);
            assert_eq!(g.nearest(&q), nearest_brute_force(&pts, &q));
        }
    }

    #[test]
    fn within_matches_brute_force() {
        let mut s = 7u64;
        let pts: Vec<Vec2> = (0..500).map(|_| Vec2::new(splitmix(&mut s), splitmix(&mut s))).collect();
        let g = PointGrid::new(&pts, 0.05).unwrap();
        for _ in 0..100 {
            let q = Vec2::new(1.2 * splitmix(&mut s) - 0.1, 1.2 * splitmix(&mut s) - 0.1);
            let r = 0.2 * splitmix(&mut s);
            let mut got = Vec::new();
            g.for_each_within(&q, r, |i, _| got.push(i));
            got.sort_unstable();
            let want: Vec<usize> = (0..pts.len()).filter(|&i| (pts[i] - q).norm_squared() < r * r).collect();
            assert_eq!(got, want);
        }
    }

    #[test]
    fn degenerate_inputs_are_refused_or_empty() {
        assert!(PointGrid::new(&[Vec2::new(0.0, 0.0)], 0.0).is_none());
        assert!(PointGrid::new(&[Vec2::new(Real::NAN, 0.0)], 1.0).is_none());
        let g = PointGrid::new(&[], 1.0).unwrap();
        assert_eq!(g.nearest(&Vec2::zeros()), None);
        // a huge cell request on a tiny set, and a tiny cell on a wide set
        let pts = [Vec2::new(0.0, 0.0), Vec2::new(1e6, 1e6)];
        let g = PointGrid::new(&pts, 1e-9).unwrap();
        let (nx, ny) = g.cells.layout().dims();
        assert!(nx * ny <= 4 * 2 + 64);
        assert_eq!(g.nearest(&Vec2::new(2e6, 2e6)), Some((1, 2e12)));
    }
}
