//! Construction of RK shape functions with a bilinear basis (SPEC §3,
//! [RL10, Eqs. (2.37)–(2.45)]).

use super::ShapeTable;
use crate::kernel::window_cubic_spline_2d;
use crate::math::{Real, Vec2};
use crate::neighbors::SupportSearch;
use nalgebra::{Matrix4, Vector4};
use rayon::prelude::*;

/// Decides whether particle `i` may contribute to the RK sum at point `x`
/// (SPEC §9 visibility). Without cracks every particle is visible.
pub trait Visibility: Sync {
    fn visible(&self, x: &Vec2, particle: usize) -> bool;
}

/// No cracks: every particle in range is visible.
#[derive(Clone, Copy, Debug, Default)]
pub struct AllVisible;

impl Visibility for AllVisible {
    #[inline]
    fn visible(&self, _x: &Vec2, _particle: usize) -> bool {
        true
    }
}

/// Why a shape-function row could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// The moment matrix is singular or too ill-conditioned to invert
    /// reliably: too few (or collinear) particles cover the point.
    #[error(
        "RK moment matrix is singular at evaluation point {point} (X = ({x:.6e}, {y:.6e}) m): \
         {neighbours} particles cover it, condition number {condition:.3e}; \
         increase the support factor or refine the particles there"
    )]
    SingularMoment { point: usize, x: Real, y: Real, neighbours: usize, condition: Real },
}

/// Largest acceptable condition number of the (scaled) moment matrix.
/// Well-posed points sit around 1e1–1e3; beyond 1e10 the reproducing
/// conditions would lose more than six digits.
pub const MAX_MOMENT_CONDITION: Real = 1e10;

/// One row of a table: `(particle, N, ∇N)` entries.
type Row = Vec<(u32, Real, Vec2)>;

/// Scratch for one row, reused across points of a thread.
#[derive(Default)]
struct RowScratch {
    cand: Vec<u32>,
}

/// Compute the shape-function row at point `x` into `(index, value, grad)`.
///
/// With `Z = X − X_I`, the basis is scaled by a length `L` (the mean support
/// of the covering particles) for conditioning: `p(Z) = [1, Z_x/L, Z_y/L,
/// Z_x Z_y/L²]`, which spans the same space, so `N_I` is unchanged:
/// `N_I = pᵀ(0) M⁻¹ p(Z_I) φ_I ΔV_I`, `M = Σ p pᵀ φ ΔV`. Gradients follow
/// from `∂M⁻¹ = −M⁻¹ ∂M M⁻¹` exactly (SPEC §3).
#[allow(non_snake_case, clippy::too_many_arguments)]
fn row_at(
    point: usize,
    x: &Vec2,
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    search: &SupportSearch,
    vis: &dyn Visibility,
    scratch: &mut RowScratch,
    out: &mut Row,
) -> Result<(), ShapeError> {
    // Legend: Z = X - X_I; p = scaled basis; phi = window; M = moment matrix.
    out.clear();
    search.covering(x, &mut scratch.cand);
    scratch.cand.retain(|&i| vis.visible(x, i as usize));
    let n = scratch.cand.len();
    let L = if n > 0 { scratch.cand.iter().map(|&i| support[i as usize]).sum::<Real>() / n as Real } else { 1.0 };
    let inv_l = 1.0 / L;
    let mut M = Matrix4::<Real>::zeros();
    let mut dM = [Matrix4::<Real>::zeros(); 2];
    for &i in &scratch.cand {
        let i = i as usize;
        let Z = x - x0[i];
        let (phi, dphi) = window_cubic_spline_2d(&Z, support[i]);
        let (phi, dphi) = (phi * volume[i], dphi * volume[i]);
        let z = Z * inv_l;
        let p = Vector4::new(1.0, z.x, z.y, z.x * z.y);
        let dp = [Vector4::new(0.0, inv_l, 0.0, z.y * inv_l), Vector4::new(0.0, 0.0, inv_l, z.x * inv_l)];
        let ppt = p * p.transpose();
        M += ppt * phi;
        for k in 0..2 {
            dM[k] += (dp[k] * p.transpose() + p * dp[k].transpose()) * phi + ppt * dphi[k];
        }
    }
    let singular = |condition: Real| ShapeError::SingularMoment { point, x: x.x, y: x.y, neighbours: n, condition };
    if n < 4 {
        return Err(singular(Real::INFINITY));
    }
    let eig = M.symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if lo <= 0.0 || !(hi / lo).is_finite() || hi / lo > MAX_MOMENT_CONDITION {
        return Err(singular(if lo > 0.0 { hi / lo } else { Real::INFINITY }));
    }
    let chol = M.cholesky().ok_or_else(|| singular(Real::INFINITY))?;
    let b = chol.solve(&Vector4::new(1.0, 0.0, 0.0, 0.0));
    let db = [-chol.solve(&(dM[0] * b)), -chol.solve(&(dM[1] * b))];
    for &i in &scratch.cand {
        let iu = i as usize;
        let Z = x - x0[iu];
        let (phi, dphi) = window_cubic_spline_2d(&Z, support[iu]);
        if phi == 0.0 && dphi == Vec2::zeros() {
            continue;
        }
        let (phi, dphi) = (phi * volume[iu], dphi * volume[iu]);
        let z = Z * inv_l;
        let p = Vector4::new(1.0, z.x, z.y, z.x * z.y);
        let dp = [Vector4::new(0.0, inv_l, 0.0, z.y * inv_l), Vector4::new(0.0, 0.0, inv_l, z.x * inv_l)];
        let bp = b.dot(&p);
        let value = bp * phi;
        let mut grad = Vec2::zeros();
        for k in 0..2 {
            grad[k] = (db[k].dot(&p) + b.dot(&dp[k])) * phi + bp * dphi[k];
        }
        out.push((i, value, grad));
    }
    Ok(())
}

/// Build the shape-function table at `points` for particles with reference
/// positions `x0`, supports `support` and volumes `volume`, honouring `vis`.
/// Rows are computed in parallel; the result does not depend on thread count.
pub fn build_table(
    points: &[Vec2],
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    vis: &dyn Visibility,
) -> Result<ShapeTable, ShapeError> {
    let search = SupportSearch::new(x0, support);
    let rows: Vec<Row> = points
        .par_iter()
        .enumerate()
        .map_init(RowScratch::default, |scratch, (p, x)| {
            let mut out = Vec::new();
            row_at(p, x, x0, support, volume, &search, vis, scratch, &mut out).map(|_| out)
        })
        .collect::<Result<_, _>>()?;
    Ok(assemble(rows))
}

/// Recompute only the rows `which` of `table` (after a local visibility
/// change); all other rows are kept as they are.
pub fn rebuild_rows(
    table: &mut ShapeTable,
    which: &[usize],
    points: &[Vec2],
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    vis: &dyn Visibility,
) -> Result<(), ShapeError> {
    let search = SupportSearch::new(x0, support);
    let fresh: Vec<(usize, Row)> = which
        .par_iter()
        .map_init(RowScratch::default, |scratch, &p| {
            let mut out = Vec::new();
            row_at(p, &points[p], x0, support, volume, &search, vis, scratch, &mut out).map(|_| (p, out))
        })
        .collect::<Result<_, _>>()?;
    let mut replaced: Vec<Option<Row>> = vec![None; table.rows()];
    for (p, row) in fresh {
        replaced[p] = Some(row);
    }
    let rows: Vec<Row> = (0..table.rows())
        .map(|p| match replaced[p].take() {
            Some(r) => r,
            None => table.range(p).map(|k| (table.index[k], table.value[k], table.grad[k])).collect(),
        })
        .collect();
    *table = assemble(rows);
    Ok(())
}

fn assemble(rows: Vec<Row>) -> ShapeTable {
    let nnz = rows.iter().map(|r| r.len()).sum();
    let mut t = ShapeTable {
        offsets: Vec::with_capacity(rows.len() + 1),
        index: Vec::with_capacity(nnz),
        value: Vec::with_capacity(nnz),
        grad: Vec::with_capacity(nnz),
    };
    t.offsets.push(0);
    for r in rows {
        for (i, v, g) in r {
            t.index.push(i);
            t.value.push(v);
            t.grad.push(g);
        }
        t.offsets.push(t.index.len());
    }
    t
}
