//! Local rebuild of shape-function rows next to a crack, with a reduced
//! basis where the crack leaves too few visible particles (SPEC §3, §9).
//!
//! A crack that meets a free surface at an acute angle leaves a wedge of
//! material in which an evaluation point near the apex sees only a few,
//! nearly collinear particles: the bilinear moment matrix is singular
//! there. Such a row falls back to the linear basis `[1, Z_x, Z_y]` (still
//! exactly linear-reproducing) and, if that is singular too, to the
//! constant basis (Shepard functions: partition of unity only). Every other
//! row is the bilinear RK row of [`crate::shape`] (same scaled basis, same
//! conditioning limit), so a rebuilt row without a crack nearby equals the
//! original to round-off. `reduced_basis_rows_stay_consistent` (unit test
//! below) and the invariants in `tests/fracture.rs` check both.

use crate::kernel::window_cubic_spline_2d;
use crate::math::{Real, Vec2};
use crate::neighbors::SupportSearch;
use crate::shape::rk::MAX_MOMENT_CONDITION;
use crate::shape::{ShapeError, ShapeTable, Visibility};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// One table row: `(particle, N, ∇N)` per visible particle.
pub type Row = Vec<(u32, Real, Vec2)>;

/// The polynomial basis of a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Basis {
    /// `[1, Z_x, Z_y, Z_x Z_y]`, the method's basis ([RL10, Eq. (2.39)]).
    Bilinear,
    /// `[1, Z_x, Z_y]`: linear reproduction.
    Linear,
    /// `[1]`: partition of unity only.
    Constant,
}

impl Basis {
    fn size(self) -> usize {
        match self {
            Basis::Bilinear => 4,
            Basis::Linear => 3,
            Basis::Constant => 1,
        }
    }
    /// Basis at scaled `z` and its derivatives with respect to X (scale `inv_l`).
    fn eval(self, z: &Vec2, inv_l: Real) -> (DVector<Real>, [DVector<Real>; 2]) {
        let all = [1.0, z.x, z.y, z.x * z.y];
        let dx = [0.0, inv_l, 0.0, z.y * inv_l];
        let dy = [0.0, 0.0, inv_l, z.x * inv_l];
        let n = self.size();
        (
            DVector::from_iterator(n, all.iter().cloned().take(n)),
            [
                DVector::from_iterator(n, dx.iter().cloned().take(n)),
                DVector::from_iterator(n, dy.iter().cloned().take(n)),
            ],
        )
    }
}

/// One row `(particle, N, ∇N)` at `x` from the visible covering particles
/// `cand`, with `basis`; `None` if the moment matrix is singular.
#[allow(non_snake_case)]
fn row_with_basis(x: &Vec2, cand: &[u32], x0: &[Vec2], support: &[Real], volume: &[Real], basis: Basis) -> Option<Row> {
    // Legend: Z = X - X_I; p = scaled basis; phi = window x volume; M = moment matrix.
    let m = basis.size();
    if cand.len() < m {
        return None;
    }
    let L = cand.iter().map(|&i| support[i as usize]).sum::<Real>() / cand.len() as Real;
    let inv_l = 1.0 / L;
    let mut M = DMatrix::<Real>::zeros(m, m);
    let mut dM = [DMatrix::<Real>::zeros(m, m), DMatrix::<Real>::zeros(m, m)];
    for &i in cand {
        let i = i as usize;
        let Z = x - x0[i];
        let (phi, dphi) = window_cubic_spline_2d(&Z, support[i]);
        let (phi, dphi) = (phi * volume[i], dphi * volume[i]);
        let (p, dp) = basis.eval(&(Z * inv_l), inv_l);
        let ppt = &p * p.transpose();
        M += &ppt * phi;
        for k in 0..2 {
            dM[k] += (&dp[k] * p.transpose() + &p * dp[k].transpose()) * phi + &ppt * dphi[k];
        }
    }
    let eig = M.clone().symmetric_eigenvalues();
    let (lo, hi) = (eig.min(), eig.max());
    if lo <= 0.0 || !(hi / lo).is_finite() || hi / lo > MAX_MOMENT_CONDITION {
        return None;
    }
    let chol = M.cholesky()?;
    let mut e0 = DVector::<Real>::zeros(m);
    e0[0] = 1.0;
    let b = chol.solve(&e0);
    let db = [-chol.solve(&(&dM[0] * &b)), -chol.solve(&(&dM[1] * &b))];
    let mut out = Vec::with_capacity(cand.len());
    for &i in cand {
        let iu = i as usize;
        let Z = x - x0[iu];
        let (phi, dphi) = window_cubic_spline_2d(&Z, support[iu]);
        if phi == 0.0 && dphi == Vec2::zeros() {
            continue;
        }
        let (phi, dphi) = (phi * volume[iu], dphi * volume[iu]);
        let (p, dp) = basis.eval(&(Z * inv_l), inv_l);
        let bp = b.dot(&p);
        let mut grad = Vec2::zeros();
        for k in 0..2 {
            grad[k] = (db[k].dot(&p) + b.dot(&dp[k])) * phi + bp * dphi[k];
        }
        out.push((i, bp * phi, grad));
    }
    Some(out)
}

/// The row at `x` (evaluation point number `point`, for the error), with
/// the richest basis whose moment matrix is regular. Error only if no
/// particle is visible at all.
#[allow(clippy::too_many_arguments)]
pub fn row_with_fallback(
    point: usize,
    x: &Vec2,
    search: &SupportSearch,
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    vis: &dyn Visibility,
    cand: &mut Vec<u32>,
) -> Result<(Row, Basis), ShapeError> {
    search.covering(x, cand);
    cand.retain(|&i| vis.visible(x, i as usize));
    for basis in [Basis::Bilinear, Basis::Linear, Basis::Constant] {
        if let Some(row) = row_with_basis(x, cand, x0, support, volume, basis) {
            return Ok((row, basis));
        }
    }
    Err(ShapeError::SingularMoment { point, x: x.x, y: x.y, neighbours: cand.len(), condition: Real::INFINITY })
}

/// Recompute rows `which` (ascending, unique) of `table` at `points`,
/// keeping every other row; returns the rows that needed a reduced basis,
/// with that basis. The new table is written into `spare` (its
/// allocations reused) and swapped with `table`: `spare` then holds the
/// table as it was. On an error `table` is unchanged.
#[allow(clippy::too_many_arguments)]
pub fn rebuild_rows_with_fallback(
    table: &mut ShapeTable,
    spare: &mut ShapeTable,
    which: &[usize],
    points: &[Vec2],
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    vis: &dyn Visibility,
) -> Result<Vec<(usize, Basis)>, ShapeError> {
    let search = SupportSearch::new(x0, support);
    // Rows are independent: built in parallel, collected in `which` order.
    let built: Vec<(Row, Basis)> = which
        .par_iter()
        .map_init(Vec::new, |cand, &r| row_with_fallback(r, &points[r], &search, x0, support, volume, vis, cand))
        .collect::<Result<_, _>>()?;
    let reduced: Vec<(usize, Basis)> =
        which.iter().zip(&built).filter(|(_, (_, b))| *b != Basis::Bilinear).map(|(&r, &(_, b))| (r, b)).collect();
    // Sized up front: growing the columns entry by entry reallocated and
    // copied the whole table a few times per split.
    let nnz = table.nnz() - which.iter().map(|&r| table.range(r).len()).sum::<usize>()
        + built.iter().map(|(row, _)| row.len()).sum::<usize>();
    let out = spare;
    out.offsets.clear();
    out.index.clear();
    out.value.clear();
    out.grad.clear();
    out.offsets.reserve(table.offsets.len());
    out.index.reserve(nnz);
    out.value.reserve(nnz);
    out.grad.reserve(nnz);
    out.offsets.push(0);
    let mut next = which.iter().zip(built.into_iter().map(|(row, _)| row)).peekable();
    for r in 0..table.rows() {
        match next.peek() {
            Some((&w, _)) if w == r => {
                let (_, row) = next.next().expect("peeked");
                for (i, v, g) in row {
                    out.index.push(i);
                    out.value.push(v);
                    out.grad.push(g);
                }
            }
            _ => {
                let range = table.range(r);
                out.index.extend_from_slice(&table.index[range.clone()]);
                out.value.extend_from_slice(&table.value[range.clone()]);
                out.grad.extend_from_slice(&table.grad[range]);
            }
        }
        out.offsets.push(out.index.len());
    }
    std::mem::swap(table, out);
    Ok(reduced)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::{build_table, AllVisible};

    fn lattice(n: usize, h: Real) -> (Vec<Vec2>, Vec<Real>, Vec<Real>) {
        let x0: Vec<Vec2> = (0..n * n).map(|k| Vec2::new((k % n) as Real * h, (k / n) as Real * h)).collect();
        (x0, vec![2.0 * h; n * n], vec![h * h; n * n])
    }

    /// Without a crack, a rebuilt row equals the shape module's row; the
    /// linear and constant bases keep their reproduction properties.
    #[test]
    fn reduced_basis_rows_stay_consistent() {
        let h = 1e-3;
        let (x0, a, v) = lattice(8, h);
        let pts = vec![Vec2::new(3.3 * h, 2.7 * h), Vec2::new(0.1 * h, 0.2 * h)];
        let reference = build_table(&pts, &x0, &a, &v, &AllVisible).unwrap();
        let mut t = reference.clone();
        let reduced =
            rebuild_rows_with_fallback(&mut t, &mut ShapeTable::default(), &[0, 1], &pts, &x0, &a, &v, &AllVisible)
                .unwrap();
        assert!(reduced.is_empty());
        for k in 0..t.nnz() {
            assert_eq!(t.index[k], reference.index[k]);
            assert!((t.value[k] - reference.value[k]).abs() < 1e-12);
            assert!((t.grad[k] - reference.grad[k]).norm() < 1e-8 / h);
        }
        let search = SupportSearch::new(&x0, &a);
        let mut cand = Vec::new();
        search.covering(&pts[0], &mut cand);
        for basis in [Basis::Linear, Basis::Constant] {
            let row = row_with_basis(&pts[0], &cand, &x0, &a, &v, basis).unwrap();
            let s: Real = row.iter().map(|r| r.1).sum();
            let g: Vec2 = row.iter().map(|r| r.2).sum();
            assert!((s - 1.0).abs() < 1e-12 && g.norm() < 1e-8 / h);
            if basis == Basis::Linear {
                let sx: Vec2 = row.iter().map(|r| x0[r.0 as usize] * r.1).sum();
                assert!((sx - pts[0]).norm() < 1e-12 * h);
            }
        }
        // three collinear particles: bilinear and linear singular, constant fine
        let line: Vec<u32> = vec![0, 1, 2];
        assert!(row_with_basis(&pts[1], &line, &x0, &a, &v, Basis::Linear).is_none());
        assert!(row_with_basis(&pts[1], &line, &x0, &a, &v, Basis::Constant).is_some());
    }
}
