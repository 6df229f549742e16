//! Neighbour search in the reference configuration (SPEC §3): which particles'
//! windows cover a given point.
//!
//! A uniform cell grid with cell size equal to the largest support size, so a
//! point's candidates lie in its own cell and the 8 around it. Built once
//! (total Lagrangian) and again only where cracks change visibility. Results
//! come back sorted by particle index, so the shape-function table — and every
//! sum built on it — is independent of thread count.

use crate::math::{Real, Vec2};

/// Particles binned into square cells.
#[derive(Clone, Debug)]
pub struct CellGrid {
    origin: Vec2,
    cell: Real,
    nx: usize,
    ny: usize,
    /// Cell starts into `items`, length `nx*ny + 1`.
    starts: Vec<usize>,
    /// Particle indices grouped by cell.
    items: Vec<u32>,
}

impl CellGrid {
    /// Bin `points` into cells of size `cell` (> 0).
    pub fn new(points: &[Vec2], cell: Real) -> Self {
        assert!(cell > 0.0 && cell.is_finite(), "cell size must be positive");
        let (mut lo, mut hi) = (Vec2::repeat(Real::INFINITY), Vec2::repeat(Real::NEG_INFINITY));
        for p in points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        if points.is_empty() {
            lo = Vec2::zeros();
            hi = Vec2::zeros();
        }
        let nx = (((hi.x - lo.x) / cell).floor() as usize) + 1;
        let ny = (((hi.y - lo.y) / cell).floor() as usize) + 1;
        let mut g = CellGrid { origin: lo, cell, nx, ny, starts: vec![0; nx * ny + 1], items: vec![0; points.len()] };
        let ids: Vec<usize> = points.iter().map(|p| g.cell_of(p)).collect();
        for &c in &ids {
            g.starts[c + 1] += 1;
        }
        for c in 0..nx * ny {
            g.starts[c + 1] += g.starts[c];
        }
        let mut fill = g.starts.clone();
        for (i, &c) in ids.iter().enumerate() {
            g.items[fill[c]] = i as u32;
            fill[c] += 1;
        }
        g
    }

    #[inline]
    fn clamp_index(&self, v: Real, n: usize) -> usize {
        (v.floor().max(0.0) as usize).min(n - 1)
    }

    #[inline]
    fn cell_of(&self, p: &Vec2) -> usize {
        let ix = self.clamp_index((p.x - self.origin.x) / self.cell, self.nx);
        let iy = self.clamp_index((p.y - self.origin.y) / self.cell, self.ny);
        iy * self.nx + ix
    }

    /// Call `f(i)` for every binned point within `reach` (≤ cell size) of `x`
    /// in each coordinate direction — a superset filter; the caller tests exactly.
    pub fn for_each_candidate(&self, x: &Vec2, reach: Real, mut f: impl FnMut(usize)) {
        let lo_x = ((x.x - reach - self.origin.x) / self.cell).floor();
        let hi_x = ((x.x + reach - self.origin.x) / self.cell).floor();
        let lo_y = ((x.y - reach - self.origin.y) / self.cell).floor();
        let hi_y = ((x.y + reach - self.origin.y) / self.cell).floor();
        if hi_x < 0.0 || hi_y < 0.0 || lo_x >= self.nx as Real || lo_y >= self.ny as Real {
            return;
        }
        let (x0, x1) = (self.clamp_index(lo_x, self.nx), self.clamp_index(hi_x, self.nx));
        let (y0, y1) = (self.clamp_index(lo_y, self.ny), self.clamp_index(hi_y, self.ny));
        for iy in y0..=y1 {
            for ix in x0..=x1 {
                let c = iy * self.nx + ix;
                for &i in &self.items[self.starts[c]..self.starts[c + 1]] {
                    f(i as usize);
                }
            }
        }
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
}
