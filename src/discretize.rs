//! Particle and quadrature-point generators for rectangular bodies
//! (SPEC §4, \[RL10\] §5.2).
//!
//! Spacing along x is graded: uniform and finest within a zone around a given
//! point, then growing geometrically up to a coarsest spacing; through the
//! thickness (y) it is uniform. Background cells join neighbouring particle
//! columns and rows and carry n×n Gauss points each — with 24 × 480 particles
//! this gives \[RL10\]'s coarse model exactly (11,520 particles, 44,068 points).

use crate::geometry::GeometryMode;
use crate::math::{Real, Vec2};
use serde::{Deserialize, Serialize};

/// A rectangular body filled with a graded particle grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectangleGrid {
    /// Left edge (m). In axisymmetry `x` is the radius, so `x_min ≥ 0`.
    pub x_min: Real,
    /// Right edge (m).
    pub x_max: Real,
    /// Bottom face (m).
    pub y_min: Real,
    /// Top face (m).
    pub y_max: Real,
    /// Particles through the thickness (rows), at least 2.
    pub layers: usize,
    /// x where the particles are finest (m). Default: the middle, or the axis
    /// (`x_min`) in axisymmetry.
    #[serde(default)]
    pub refine_at: Option<Real>,
    /// Half-width of the uniform fine zone around `refine_at` (m). Default 0.
    #[serde(default)]
    pub fine_half_width: Real,
    /// Spacing along x in the fine zone (m). Default: the thickness spacing
    /// `(y_max − y_min)/(layers − 1)`, giving square cells under the projectile.
    #[serde(default)]
    pub fine_spacing: Option<Real>,
    /// x of a particle column the fine zone is fitted to (m): the fine
    /// spacing becomes `|column_at − refine_at| / n`, `n` the nearest whole
    /// number of fine spacings (at least 1), so that a column falls on it
    /// at every resolution ([`RectangleGrid::resolve`]; a change of the
    /// spacing by at most half a spacing over the distance). For a plate
    /// under a flat-nosed projectile: the projectile's radius, so that the
    /// rim's crack can run through particles on the projectile's edge
    /// instead of a fraction of a spacing inside or outside it, a fraction
    /// that otherwise changes from one resolution to the next
    /// (`docs/validation.md`, "A particle column on the projectile's
    /// edge"). Must lie inside the fine zone, not at `refine_at`. Default:
    /// none (the fine spacing as given).
    #[serde(default)]
    pub column_at: Option<Real>,
    /// Ratio between consecutive spacings outside the fine zone, ≥ 1.
    /// Default 1 (uniform).
    #[serde(default = "one")]
    pub growth: Real,
    /// Largest spacing along x (m). Default: no cap.
    #[serde(default)]
    pub coarse_spacing: Option<Real>,
    /// RK support size over local spacing, `a_I = factor · h_I`. Default 2.0:
    /// the smallest that keeps the bilinear moment matrix well conditioned
    /// with margin on graded grids (SPEC §3).
    #[serde(default = "two")]
    pub support_factor: Real,
    /// Gauss points per cell direction (1–4). Default 2, as \[RL10\].
    #[serde(default = "gauss_default")]
    pub gauss: usize,
}

fn one() -> Real {
    1.0
}
fn two() -> Real {
    2.0
}
fn gauss_default() -> usize {
    2
}

/// A generated body: particles and quadrature points, before shape functions.
#[derive(Clone, Debug, Default)]
pub struct GeneratedBody {
    /// Particle reference positions.
    pub particles: Vec<Vec2>,
    /// Particle nodal areas (m²; the kernel weight `ΔV_I`).
    pub volume: Vec<Real>,
    /// Local spacing `h_I` (m).
    pub spacing: Vec<Real>,
    /// Support size `a_I` (m).
    pub support: Vec<Real>,
    /// On the outer boundary of the rectangle.
    pub on_boundary: Vec<bool>,
    /// Quadrature points.
    pub quad_points: Vec<Vec2>,
    /// Quadrature weights including the geometry factor.
    pub quad_weights: Vec<Real>,
    /// Length of each quadrature point's background cell, `√(Δx Δy)`, m.
    pub quad_lengths: Vec<Real>,
    /// Columns and rows of the particle grid.
    pub columns: usize,
    pub rows: usize,
}

impl RectangleGrid {
    /// A uniform lattice of spacing `h` on `[x.0, x.1] × [y.0, y.1]` (the
    /// extents multiples of `h`): no grading, support factor 2, 2×2 Gauss
    /// points. For tests and small examples.
    pub fn uniform(x: (Real, Real), y: (Real, Real), h: Real) -> Self {
        RectangleGrid {
            x_min: x.0,
            x_max: x.1,
            y_min: y.0,
            y_max: y.1,
            layers: ((y.1 - y.0) / h).round() as usize + 1,
            refine_at: None,
            fine_half_width: 0.0,
            fine_spacing: Some(h),
            column_at: None,
            growth: 1.0,
            coarse_spacing: None,
            support_factor: 2.0,
            gauss: 2,
        }
    }

    /// Thickness spacing `(y_max − y_min)/(layers − 1)`.
    pub fn layer_spacing(&self) -> Real {
        (self.y_max - self.y_min) / (self.layers as Real - 1.0)
    }

    /// `refine_at`, or its default in `mode`: the middle, or the axis
    /// (`x_min`) in axisymmetry.
    pub fn refine_point(&self, mode: GeometryMode) -> Real {
        self.refine_at.unwrap_or(match mode {
            GeometryMode::Axisymmetric => self.x_min,
            GeometryMode::PlaneStrain => 0.5 * (self.x_min + self.x_max),
        })
    }

    /// Fill in the defaults that depend on other fields, so that a resolved
    /// case file states every value used.
    pub fn resolve(&mut self, mode: GeometryMode) {
        let x_f = self.refine_point(mode);
        self.refine_at = Some(x_f);
        let h = self.fine_spacing.unwrap_or_else(|| self.layer_spacing());
        self.fine_spacing = Some(match self.column_at {
            Some(x) if (x - x_f).abs() > 0.0 && h > 0.0 => {
                let d = (x - x_f).abs();
                d / (d / h).round().max(1.0)
            }
            _ => h,
        });
    }

    /// Column x-coordinates: finest at `refine_at`, growing outward.
    pub fn columns(&self) -> Vec<Real> {
        let x_f = self.refine_at.unwrap_or(0.5 * (self.x_min + self.x_max)).clamp(self.x_min, self.x_max);
        let h_f = self.fine_spacing.unwrap_or_else(|| self.layer_spacing());
        let cap = self.coarse_spacing.unwrap_or(Real::INFINITY).max(h_f);
        let walk = |dir: Real, end: Real| -> Vec<Real> {
            let mut pts = Vec::new();
            let mut p = x_f;
            let mut h = h_f;
            loop {
                let dist = (p - x_f).abs();
                let next_h = if dist + 0.5 * h_f < self.fine_half_width { h_f } else { (h * self.growth).min(cap) };
                h = if dist < 1e-15 { h_f } else { next_h };
                let q = p + dir * h;
                if (end - q) * dir < 0.5 * h {
                    break;
                }
                pts.push(q);
                p = q;
            }
            pts.push(end);
            pts
        };
        let mut xs = vec![];
        if x_f > self.x_min {
            let mut left = walk(-1.0, self.x_min);
            left.reverse();
            xs.extend(left);
        }
        xs.push(x_f);
        if x_f < self.x_max {
            xs.extend(walk(1.0, self.x_max));
        }
        xs.dedup_by(|a, b| (*a - *b).abs() < 1e-12 * (self.x_max - self.x_min));
        xs
    }

    /// Where `x` lies against the particle columns ([`Self::columns`]; a
    /// resolved grid): the nearest column and the offset `(x − column) / h`
    /// in [−½, ½], `h` the gap from that column to its neighbour on `x`'s
    /// side. `None` outside `[x_min, x_max]`. Under a flat-nosed projectile
    /// the offset of its edge is the lattice's phase at the rim, which
    /// changes from one resolution to the next unless `column_at` holds it
    /// at 0 (`docs/validation.md`, "A particle column on the projectile's
    /// edge").
    pub fn column_offset(&self, x: Real) -> Option<(Real, Real)> {
        if !(self.x_min..=self.x_max).contains(&x) {
            return None;
        }
        let xs = self.columns();
        let k = (0..xs.len()).min_by(|&a, &b| (xs[a] - x).abs().total_cmp(&(xs[b] - x).abs()))?;
        let neighbour = if x >= xs[k] { xs.get(k + 1) } else { k.checked_sub(1).map(|j| &xs[j]) };
        let h = neighbour.map_or(Real::INFINITY, |n| (n - xs[k]).abs());
        Some((xs[k], if h > 0.0 { (x - xs[k]) / h } else { 0.0 }))
    }

    /// Generate particles and Gauss points.
    pub fn generate(&self, mode: GeometryMode) -> GeneratedBody {
        let xs = self.columns();
        let ys: Vec<Real> = (0..self.layers)
            .map(|j| self.y_min + (self.y_max - self.y_min) * j as Real / (self.layers as Real - 1.0))
            .collect();
        let (nx, ny) = (xs.len(), ys.len());
        let trib = |c: &[Real], k: usize| -> (Real, Real) {
            let left = if k > 0 { c[k] - c[k - 1] } else { 0.0 };
            let right = if k + 1 < c.len() { c[k + 1] - c[k] } else { 0.0 };
            (0.5 * (left + right), left.max(right))
        };
        let mut b = GeneratedBody { columns: nx, rows: ny, ..Default::default() };
        for (j, &y) in ys.iter().enumerate() {
            let (ty, hy) = trib(&ys, j);
            for (i, &x) in xs.iter().enumerate() {
                let (tx, hx) = trib(&xs, i);
                let h = hx.max(hy);
                b.particles.push(Vec2::new(x, y));
                b.volume.push(tx * ty);
                b.spacing.push(h);
                b.support.push(self.support_factor * h);
                b.on_boundary.push(i == 0 || j == 0 || i + 1 == nx || j + 1 == ny);
            }
        }
        let (gp, gw) = gauss_legendre(self.gauss);
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let (x0, x1, y0, y1) = (xs[i], xs[i + 1], ys[j], ys[j + 1]);
                for (a, wa) in gp.iter().zip(&gw) {
                    for (c, wc) in gp.iter().zip(&gw) {
                        let p = Vec2::new(0.5 * (x0 + x1) + 0.5 * (x1 - x0) * c, 0.5 * (y0 + y1) + 0.5 * (y1 - y0) * a);
                        let w = wa * wc * 0.25 * (x1 - x0) * (y1 - y0) * mode.volume_factor(&p);
                        b.quad_points.push(p);
                        b.quad_weights.push(w);
                        b.quad_lengths.push(((x1 - x0) * (y1 - y0)).sqrt());
                    }
                }
            }
        }
        b
    }
}

impl GeneratedBody {
    /// Reorder particles and quadrature points along a Morton (Z-order)
    /// curve of their reference positions, so that points close in space are
    /// close in memory: the shape-function rows, the force gather and the
    /// material sweep then touch few cache lines per neighbourhood.
    pub fn sort_along_space_filling_curve(&mut self) {
        let order = morton_order(&self.particles);
        self.particles = order.iter().map(|&i| self.particles[i]).collect();
        self.volume = order.iter().map(|&i| self.volume[i]).collect();
        self.spacing = order.iter().map(|&i| self.spacing[i]).collect();
        self.support = order.iter().map(|&i| self.support[i]).collect();
        self.on_boundary = order.iter().map(|&i| self.on_boundary[i]).collect();
        let order = morton_order(&self.quad_points);
        self.quad_points = order.iter().map(|&i| self.quad_points[i]).collect();
        self.quad_weights = order.iter().map(|&i| self.quad_weights[i]).collect();
        self.quad_lengths = order.iter().map(|&i| self.quad_lengths[i]).collect();
    }
}

/// Indices of `points` sorted by their Morton (Z-order) key on a 2^20 grid
/// over the bounding box; ties keep their original order.
pub fn morton_order(points: &[Vec2]) -> Vec<usize> {
    let (mut lo, mut hi) = (Vec2::repeat(Real::INFINITY), Vec2::repeat(Real::NEG_INFINITY));
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let extent = (hi - lo).max().max(Real::MIN_POSITIVE);
    let scale = ((1u64 << 20) - 1) as Real / extent;
    let spread = |mut v: u64| {
        // interleave the low 21 bits with zeros
        v &= 0x1f_ffff;
        v = (v | (v << 32)) & 0x1f00000000ffff;
        v = (v | (v << 16)) & 0x1f0000ff0000ff;
        v = (v | (v << 8)) & 0x100f00f00f00f00f;
        v = (v | (v << 4)) & 0x10c30c30c30c30c3;
        (v | (v << 2)) & 0x1249249249249249
    };
    let key = |p: &Vec2| {
        let ix = ((p.x - lo.x) * scale) as u64;
        let iy = ((p.y - lo.y) * scale) as u64;
        spread(ix) | (spread(iy) << 1)
    };
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by_key(|&i| key(&points[i]));
    order
}

/// Gauss–Legendre points and weights on [−1, 1] for `n` = 1..=4 points.
pub fn gauss_legendre(n: usize) -> (Vec<Real>, Vec<Real>) {
    match n {
        1 => (vec![0.0], vec![2.0]),
        2 => {
            let a = 1.0 / 3f64.sqrt();
            (vec![-a, a], vec![1.0, 1.0])
        }
        3 => {
            let a = (0.6f64).sqrt();
            (vec![-a, 0.0, a], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
        }
        4 => {
            let a = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let b = (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let wa = (18.0 + 30f64.sqrt()) / 36.0;
            let wb = (18.0 - 30f64.sqrt()) / 36.0;
            (vec![-b, -a, a, b], vec![wb, wa, wa, wb])
        }
        _ => panic!("gauss_legendre: n must be 1..=4 (validated by the case reader)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate(layers: usize, half_width: Real, growth: Real, coarse: Real) -> RectangleGrid {
        RectangleGrid {
            x_min: -0.1,
            x_max: 0.1,
            y_min: 0.0,
            y_max: 0.0111,
            layers,
            refine_at: None,
            fine_half_width: half_width,
            fine_spacing: None,
            column_at: None,
            growth,
            coarse_spacing: Some(coarse),
            support_factor: 2.0,
            gauss: 2,
        }
    }

    #[test]
    fn volumes_and_weights_tile_the_rectangle() {
        let g = plate(8, 0.02, 1.1, 0.004).generate(GeometryMode::PlaneStrain);
        let area = 0.2 * 0.0111;
        let v: Real = g.volume.iter().sum();
        let w: Real = g.quad_weights.iter().sum();
        assert!((v - area).abs() < 1e-12 * area);
        assert!((w - area).abs() < 1e-12 * area);
        assert_eq!(g.quad_points.len(), 4 * (g.columns - 1) * (g.rows - 1));
        // spacing grows monotonically away from the centre
        let xs = plate(8, 0.02, 1.1, 0.004).columns();
        let gaps: Vec<Real> = xs.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = gaps.len() / 2;
        for k in mid..gaps.len() - 2 {
            assert!(gaps[k + 1] >= gaps[k] * (1.0 - 1e-9), "gap {k}");
        }
        assert!(gaps.iter().cloned().fold(0.0, Real::max) <= 0.004 * 1.5 + 1e-12);
    }

    /// `column_at`: a column on the given x at every resolution (both sides
    /// in plane strain, the fine zone symmetric), the fine spacing moved by
    /// at most half a spacing over the distance, resolving twice the same;
    /// without it the thickness spacing as before.
    #[test]
    fn a_column_falls_on_column_at_at_every_resolution() {
        for (mode, x_min) in [(GeometryMode::Axisymmetric, 0.0), (GeometryMode::PlaneStrain, -0.1)] {
            for layers in [6, 12, 24, 36, 48, 72, 96] {
                let mut g = RectangleGrid { x_min, column_at: Some(0.01), ..plate(layers, 0.02, 1.03, 0.004) };
                let mut plain = RectangleGrid { x_min, ..plate(layers, 0.02, 1.03, 0.004) };
                g.resolve(mode);
                plain.resolve(mode);
                let (h, h0) = (g.fine_spacing.unwrap(), plain.fine_spacing.unwrap());
                assert_eq!(h0, g.layer_spacing(), "no column_at: the thickness spacing");
                let n = 0.01 / h;
                assert!(
                    (n - n.round()).abs() < 1e-9 && (0.01 - n.round() * h0).abs() <= 0.5 * h0 + 1e-15,
                    "{layers}: {h} vs {h0}"
                );
                let xs = g.columns();
                let on = |x: Real| xs.iter().any(|c| (c - x).abs() < 1e-12);
                assert!(on(0.01), "{mode:?} {layers} rows: no column at 0.01 m");
                if mode == GeometryMode::PlaneStrain {
                    assert!(on(-0.01), "{layers} rows: no column at -0.01 m");
                }
                let again = {
                    let mut r = g.clone();
                    r.resolve(mode);
                    r.fine_spacing
                };
                assert_eq!(again, g.fine_spacing, "resolving twice");
            }
        }
    }

    /// The edge's phase against the columns, by hand: in axisymmetry the
    /// fine zone's columns lie at `k h` from the axis, so a radius of 10 mm
    /// lies `10/h − round(10/h)` spacings from the nearest; with
    /// `column_at` on it, 0. Outside the body, none.
    #[test]
    fn the_offset_of_an_edge_from_the_nearest_column_by_hand() {
        for layers in [12, 24, 48, 72, 96] {
            let mut g = RectangleGrid { x_min: 0.0, ..plate(layers, 0.02, 1.03, 0.004) };
            g.resolve(GeometryMode::Axisymmetric);
            let h = 0.0111 / (layers - 1) as Real;
            let n = 0.01 / h;
            let (column, offset) = g.column_offset(0.01).unwrap();
            assert!((offset - (n - n.round())).abs() < 1e-9, "{layers}: {offset} against {}", n - n.round());
            assert!((column - n.round() * h).abs() < 1e-12 && offset.abs() <= 0.5);
            let mut on = RectangleGrid { column_at: Some(0.01), ..g.clone() };
            on.resolve(GeometryMode::Axisymmetric);
            assert!(on.column_offset(0.01).unwrap().1.abs() < 1e-9, "{layers}: column_at");
            assert_eq!(g.column_offset(0.1 + 1e-6), None);
            assert_eq!(g.column_offset(-1e-6), None);
        }
        // graded: the gap on the edge's side, not the fine spacing
        let mut g = RectangleGrid { x_min: 0.0, ..plate(24, 0.005, 1.2, 0.004) };
        g.resolve(GeometryMode::Axisymmetric);
        let xs = g.columns();
        let k = xs.iter().position(|&c| c > 0.03).unwrap();
        let x = xs[k] + 0.25 * (xs[k + 1] - xs[k]);
        let (column, offset) = g.column_offset(x).unwrap();
        assert_eq!(column, xs[k]);
        assert!((offset - 0.25).abs() < 1e-12, "{offset}");
    }

    #[test]
    fn morton_order_is_a_permutation_that_keeps_neighbours_close() {
        let mut g = plate(10, 0.02, 1.1, 0.004).generate(GeometryMode::PlaneStrain);
        let before = g.particles.clone();
        g.sort_along_space_filling_curve();
        let mut a: Vec<(u64, u64)> = before.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
        let mut b: Vec<(u64, u64)> = g.particles.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        // neighbours (within 2.5 spacings) sit closer in memory than in row-major order
        let index_spread = |v: &[Vec2]| {
            let (mut sum, mut n) = (0usize, 0usize);
            for i in 0..v.len() {
                for j in 0..v.len() {
                    if i != j && (v[i] - v[j]).norm() < 2.5 * 0.0111 / 9.0 {
                        sum += i.abs_diff(j);
                        n += 1;
                    }
                }
            }
            sum as Real / n as Real
        };
        let ws: Real = g.quad_weights.iter().sum();
        assert!((ws - 0.2 * 0.0111).abs() < 1e-12 * ws);
        let (morton, row_major) = (index_spread(&g.particles), index_spread(&before));
        assert!(morton < 0.8 * row_major, "Morton {morton} vs row-major {row_major}");
    }

    #[test]
    fn axisymmetric_weights_give_the_volume_of_revolution() {
        let mut r = plate(6, 0.01, 1.05, 0.003);
        r.x_min = 0.0;
        r.resolve(GeometryMode::Axisymmetric);
        let g = r.generate(GeometryMode::Axisymmetric);
        let w: Real = g.quad_weights.iter().sum();
        let exact = std::f64::consts::PI * 0.1 * 0.1 * 0.0111;
        assert!((w - exact).abs() < 1e-12 * exact);
        assert_eq!(g.particles[0].x, 0.0);
    }
}
