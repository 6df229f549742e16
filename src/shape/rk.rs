//! Construction of RK shape functions (SPEC §3, [RL10, Eqs. (2.37)–(2.45)]):
//! one row builder for the method's bilinear basis and the reduced bases
//! a crack may call for, a whole-table build and a local rebuild.

use super::ShapeTable;
use crate::kernel::window_cubic_spline_2d;
use crate::math::{Real, Vec2};
use crate::neighbors::SupportSearch;
use nalgebra::{SMatrix, SVector};
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

/// Largest Lebesgue sum `Λ(X) = Σ_I |N_I(X)|` a rebuilt row may have
/// before [`row_with_fallback`] tries the next, smaller basis.
///
/// `Λ` bounds how much an interpolated field can exceed its nodal values,
/// `|Σ N_I u_I| ≤ Λ max |u_I|`; it also bounds how far the row can move
/// mass in the lumping. Rows of the undisturbed lattice have `Λ` ≈ 1,
/// rows at a crack face up to 2.8 (measured on Case I's 48-row plate at
/// 63–70 µs, 23 000 particles), and the constant basis has `Λ = 1`
/// exactly. A bilinear row with exactly four visible particles is their
/// interpolant, and a nearly degenerate quadrilateral of them gives wild
/// values: on that plate one point behind two crack tips had `Λ` = 80
/// (`N` = −20, −20, +40.6), which cut the stable step 26-fold and left the
/// run crawling at 4.6·10⁻¹⁰ s a step (issue #19), and lumped ten times
/// a particle's nodal mass onto it. Deviation from \[RL10\] (which keeps
/// the bilinear basis wherever it is regular); test:
/// `an_interpolating_row_falls_back_to_a_bounded_one`.
pub const MAX_LEBESGUE_SUM: Real = 4.0;

/// Largest gradient sum `G(X) = L Σ_I |∇N_I(X)|` a rebuilt row may have
/// (`L` the mean support of its particles) before [`row_with_fallback`]
/// tries the next, smaller basis.
///
/// `G` bounds the strain a row reads from a displacement field of unit
/// size per support, so the stiffness the row gives its particles: the
/// frequency bound of [`crate::stability`] grows with it. On Case I's
/// 48-row plate at 63.6 µs the median row has `G` = 4.2, 99.9 % are below
/// 6.3 and the crack-face rows reach 12.3; one point, whose four visible
/// particles lie nearly on a line, had `G` = 119 with the linear basis
/// (`Λ` = 3.6, within its bound), and the next 33: they still held the
/// stable step 11-fold below the spacing step. With four particles on a
/// line and a fifth `ε` off it, the linear row's `∂N/∂Y` of the fifth is
/// exactly `1/ε`. The bound lets every lattice and crack-face row keep its
/// basis. Test: `a_row_across_a_line_of_particles_falls_back_to_shepard`.
pub const MAX_GRADIENT_SUM: Real = 16.0;

/// `(Λ, G)` of a row: its Lebesgue sum `Σ_I |N_I|` ([`MAX_LEBESGUE_SUM`])
/// and its gradient sum `L Σ_I |∇N_I|` ([`MAX_GRADIENT_SUM`]), `L` the mean
/// of its particles' supports `support`.
pub fn row_sums(row: &[(u32, Real, Vec2)], support: &[Real]) -> (Real, Real) {
    if row.is_empty() {
        return (0.0, 0.0);
    }
    let l = row.iter().map(|r| support[r.0 as usize]).sum::<Real>() / row.len() as Real;
    (row.iter().map(|r| r.1.abs()).sum(), l * row.iter().map(|r| r.2.norm()).sum::<Real>())
}

/// Whether a row stays within both of its bounds ([`row_sums`]): the one
/// test [`row_with_fallback`] applies and the fracture tests check.
pub fn is_bounded(row: &[(u32, Real, Vec2)], support: &[Real]) -> bool {
    let (lebesgue, gradient) = row_sums(row, support);
    lebesgue <= MAX_LEBESGUE_SUM && gradient <= MAX_GRADIENT_SUM
}

/// One row of a table: `(particle, N, ∇N)` entries.
pub type Row = Vec<(u32, Real, Vec2)>;

/// The polynomial basis of a row, `p(Z)` in `N_I = pᵀ(0) M⁻¹ p(Z_I) φ_I ΔV_I`.
///
/// The method's basis is bilinear ([RL10, Eq. (2.39)]). Next to a crack an
/// evaluation point may see too few or nearly collinear particles for it
/// (a wedge between a crack and a free surface): such a row falls back to
/// the linear basis, still exactly linear-reproducing, and then to the
/// constant one (Shepard functions: partition of unity only)
/// ([`row_with_fallback`]; SPEC §9, a deviation the fracture module
/// documents).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
pub enum Basis {
    /// `[1, Z_x, Z_y, Z_x Z_y]`, the method's basis ([RL10, Eq. (2.39)]).
    Bilinear,
    /// `[1, Z_x, Z_y]`: linear reproduction.
    Linear,
    /// `[1]`: partition of unity only.
    Constant,
}

/// Basis `p` at scaled `z = Z / L` and its derivatives with respect to X
/// (`inv_l = 1/L`): the first `M` terms of `[1, z_x, z_y, z_x z_y]`, so
/// `M = 4, 3, 1` are the bilinear, linear and constant bases.
#[inline(always)]
fn basis_terms<const M: usize>(z: &Vec2, inv_l: Real) -> (SVector<Real, M>, [SVector<Real, M>; 2]) {
    let all = [1.0, z.x, z.y, z.x * z.y];
    let dx = [0.0, inv_l, 0.0, z.y * inv_l];
    let dy = [0.0, 0.0, inv_l, z.x * inv_l];
    (SVector::from_fn(|i, _| all[i]), [SVector::from_fn(|i, _| dx[i]), SVector::from_fn(|i, _| dy[i])])
}

/// The row at `x` of the visible covering particles `cand` with the first
/// `M` basis terms ([`basis_terms`]), appended to `out` (cleared first).
///
/// With `Z = X − X_I`, the basis is scaled by a length `L` (the mean support
/// of the covering particles) for conditioning: `p(Z) = [1, Z_x/L, Z_y/L,
/// Z_x Z_y/L²]`, which spans the same space, so `N_I` is unchanged:
/// `N_I = pᵀ(0) M⁻¹ p(Z_I) φ_I ΔV_I`, `M = Σ p pᵀ φ ΔV`. Gradients follow
/// from `∂M⁻¹ = −M⁻¹ ∂M M⁻¹` exactly (SPEC §3, [RL10, Eqs. (2.37)–(2.45)]).
/// Fixed-size matrices for every basis: the bilinear instance is the fast
/// path of every table build. `Err(condition)` if the moment matrix is
/// singular or worse conditioned than [`MAX_MOMENT_CONDITION`].
/// `eigenvalues` is nalgebra's symmetric eigenvalue solver at the caller's
/// concrete size (its trait bounds do not name a generic size).
#[allow(non_snake_case)]
fn row_of_size<const M: usize>(
    x: &Vec2,
    cand: &[u32],
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    eigenvalues: impl Fn(SMatrix<Real, M, M>) -> SVector<Real, M>,
    out: &mut Row,
) -> Result<(), Real> {
    // Legend: Z = X - X_I; p = scaled basis; phi = window x volume; M = moment matrix.
    out.clear();
    if cand.len() < M {
        return Err(Real::INFINITY);
    }
    let L = cand.iter().map(|&i| support[i as usize]).sum::<Real>() / cand.len() as Real;
    let inv_l = 1.0 / L;
    let mut Mm = SMatrix::<Real, M, M>::zeros();
    let mut dM = [SMatrix::<Real, M, M>::zeros(); 2];
    for &i in cand {
        let i = i as usize;
        let Z = x - x0[i];
        let (phi, dphi) = window_cubic_spline_2d(&Z, support[i]);
        let (phi, dphi) = (phi * volume[i], dphi * volume[i]);
        let (p, dp) = basis_terms::<M>(&(Z * inv_l), inv_l);
        let ppt = p * p.transpose();
        Mm += ppt * phi;
        for k in 0..2 {
            dM[k] += (dp[k] * p.transpose() + p * dp[k].transpose()) * phi + ppt * dphi[k];
        }
    }
    let eig = eigenvalues(Mm);
    let (lo, hi) = (eig.min(), eig.max());
    if lo <= 0.0 || !(hi / lo).is_finite() || hi / lo > MAX_MOMENT_CONDITION {
        return Err(if lo > 0.0 { hi / lo } else { Real::INFINITY });
    }
    let chol = Mm.cholesky().ok_or(Real::INFINITY)?;
    let b = chol.solve(&SVector::<Real, M>::from_fn(|i, _| if i == 0 { 1.0 } else { 0.0 }));
    let db = [-chol.solve(&(dM[0] * b)), -chol.solve(&(dM[1] * b))];
    for &i in cand {
        let iu = i as usize;
        let Z = x - x0[iu];
        let (phi, dphi) = window_cubic_spline_2d(&Z, support[iu]);
        if phi == 0.0 && dphi == Vec2::zeros() {
            continue;
        }
        let (phi, dphi) = (phi * volume[iu], dphi * volume[iu]);
        let (p, dp) = basis_terms::<M>(&(Z * inv_l), inv_l);
        let bp = b.dot(&p);
        let mut grad = Vec2::zeros();
        for k in 0..2 {
            grad[k] = (db[k].dot(&p) + b.dot(&dp[k])) * phi + bp * dphi[k];
        }
        out.push((i, bp * phi, grad));
    }
    Ok(())
}

/// The row at `x` from the visible covering particles `cand` with `basis`
/// (`row_of_size`); `Err(condition number)` if its moment matrix is
/// singular.
pub fn row_with_basis(
    x: &Vec2,
    cand: &[u32],
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    basis: Basis,
    out: &mut Row,
) -> Result<(), Real> {
    match basis {
        Basis::Bilinear => row_of_size::<4>(x, cand, x0, support, volume, |m| m.symmetric_eigenvalues(), out),
        Basis::Linear => row_of_size::<3>(x, cand, x0, support, volume, |m| m.symmetric_eigenvalues(), out),
        Basis::Constant => row_of_size::<1>(x, cand, x0, support, volume, |m| m.symmetric_eigenvalues(), out),
    }
}

/// The particles whose windows cover `x` and that `vis` lets through, into
/// `cand`.
fn visible_covering(x: &Vec2, search: &SupportSearch, vis: &dyn Visibility, cand: &mut Vec<u32>) {
    search.covering(x, cand);
    cand.retain(|&i| vis.visible(x, i as usize));
}

/// The bilinear row at evaluation point number `point` (for the error),
/// the method's row everywhere a crack leaves enough particles.
#[allow(clippy::too_many_arguments)]
fn bilinear_row(
    point: usize,
    x: &Vec2,
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    search: &SupportSearch,
    vis: &dyn Visibility,
    cand: &mut Vec<u32>,
    out: &mut Row,
) -> Result<(), ShapeError> {
    visible_covering(x, search, vis, cand);
    row_with_basis(x, cand, x0, support, volume, Basis::Bilinear, out).map_err(|condition| ShapeError::SingularMoment {
        point,
        x: x.x,
        y: x.y,
        neighbours: cand.len(),
        condition,
    })
}

/// The row at `x` (evaluation point number `point`, for the error) with the
/// richest basis whose moment matrix is regular ([`Basis`]) and whose
/// Lebesgue and gradient sums stay within [`MAX_LEBESGUE_SUM`] and
/// [`MAX_GRADIENT_SUM`] (the constant basis always qualifies: its values
/// are positive and sum to one); an error only if no particle is visible
/// at all.
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
    visible_covering(x, search, vis, cand);
    let mut row = Row::new();
    for basis in [Basis::Bilinear, Basis::Linear, Basis::Constant] {
        if row_with_basis(x, cand, x0, support, volume, basis, &mut row).is_ok()
            && (basis == Basis::Constant || is_bounded(&row, support))
        {
            return Ok((row, basis));
        }
    }
    Err(ShapeError::SingularMoment { point, x: x.x, y: x.y, neighbours: cand.len(), condition: Real::INFINITY })
}

/// Build the shape-function table at `points` for particles with reference
/// positions `x0`, supports `support` and volumes `volume`, honouring `vis`,
/// with the method's bilinear basis everywhere (an error where it is
/// singular). Rows are computed in parallel; the result does not depend on
/// thread count.
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
        .map_init(Vec::new, |cand, (p, x)| {
            let mut out = Vec::new();
            bilinear_row(p, x, x0, support, volume, &search, vis, cand, &mut out).map(|_| out)
        })
        .collect::<Result<_, _>>()?;
    Ok(assemble(rows))
}

/// Recompute rows `which` (ascending, unique) of `table` at `points` after a
/// local visibility change, each with the richest regular basis
/// ([`row_with_fallback`]), keeping every other row; a row for which
/// `given` returns one takes that row instead (a detached particle's own,
/// an orphaned point's empty one: `crate::fracture::CrackGrowth::detach_isolated`).
/// Returns the built rows that needed a reduced basis, with that basis.
/// The new table is written into `spare` (its allocations reused) and
/// swapped with `table`: `spare` then holds the table as it was. On an
/// error `table` is unchanged. A rebuilt row whose visibility did not
/// change equals the row [`build_table`] made, bit for bit (same builder).
#[allow(clippy::too_many_arguments)]
pub fn rebuild_rows(
    table: &mut ShapeTable,
    spare: &mut ShapeTable,
    which: &[usize],
    points: &[Vec2],
    x0: &[Vec2],
    support: &[Real],
    volume: &[Real],
    vis: &dyn Visibility,
    given: &(dyn Fn(usize) -> Option<Row> + Sync),
) -> Result<ReducedRows, ShapeError> {
    let search = SupportSearch::new(x0, support);
    // Rows are independent: built in parallel, collected in `which` order.
    let built: Vec<(Row, Option<Basis>)> = which
        .par_iter()
        .map_init(Vec::new, |cand, &r| match given(r) {
            Some(row) => Ok((row, None)),
            None => {
                row_with_fallback(r, &points[r], &search, x0, support, volume, vis, cand).map(|(row, b)| (row, Some(b)))
            }
        })
        .collect::<Result<_, _>>()?;
    let reduced: ReducedRows = which
        .iter()
        .zip(&built)
        .filter_map(|(&r, &(_, b))| b.filter(|&b| b != Basis::Bilinear).map(|b| (r, b)))
        .collect();
    splice_rows(table, spare, which, built.into_iter().map(|(row, _)| row).collect());
    Ok(reduced)
}

/// The rows a rebuild built with a reduced basis, and that basis.
pub type ReducedRows = Vec<(usize, Basis)>;

/// `rebuild(given)`, a [`rebuild_rows`] of rows `which` with rows
/// `given`, where a point that no particle sees (a crack has cut it off
/// from every particle of its body) takes an empty row instead of failing
/// the rebuild with [`ShapeError::SingularMoment`] at 0 particles: such a
/// point has no displacement field to follow. Returns
/// the reduced rows and those points ("orphans"), ascending; the caller
/// erodes them (`crate::fracture::CrackGrowth`). Found by the builder,
/// which leaves `table` as it was on an error: each is set aside and the
/// rebuild retried. Any other error is returned. A deviation from \[RL10\],
/// whose crack paths never met one; before, a run stopped there (the
/// hemispherical nose at 48 rows and 292.1 m/s, at 25.9 µs:
/// docs/validation.md, "A point cut off from every particle"). Test:
/// `a_point_no_particle_sees_takes_an_empty_row`.
pub fn rebuild_rows_setting_aside_orphans(
    which: &[usize],
    given: &(dyn Fn(usize) -> Option<Row> + Sync),
    mut rebuild: impl FnMut(&(dyn Fn(usize) -> Option<Row> + Sync)) -> Result<ReducedRows, ShapeError>,
) -> Result<(ReducedRows, Vec<usize>), ShapeError> {
    let mut orphans: Vec<usize> = Vec::new();
    loop {
        let row_of = |r: usize| if orphans.binary_search(&r).is_ok() { Some(Row::new()) } else { given(r) };
        match rebuild(&row_of) {
            Err(ShapeError::SingularMoment { point, neighbours: 0, .. })
                if which.binary_search(&point).is_ok() && orphans.binary_search(&point).is_err() =>
            {
                let at = orphans.binary_search(&point).unwrap_err();
                orphans.insert(at, point);
            }
            built => return built.map(|reduced| (reduced, orphans)),
        }
    }
}

/// Replace rows `which` (ascending, unique) of `table` by `rows`, keeping
/// every other row: the new table is written into `spare` (its allocations
/// reused) and swapped with `table`, so `spare` then holds the table as it
/// was.
fn splice_rows(table: &mut ShapeTable, spare: &mut ShapeTable, which: &[usize], rows: Vec<Row>) {
    debug_assert_eq!(which.len(), rows.len());
    // Sized up front: growing the columns entry by entry reallocated and
    // copied the whole table a few times per split.
    let nnz = table.nnz() - which.iter().map(|&r| table.range(r).len()).sum::<usize>()
        + rows.iter().map(|row| row.len()).sum::<usize>();
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
    let mut next = which.iter().zip(rows).peekable();
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(n: usize, h: Real) -> (Vec<Vec2>, Vec<Real>, Vec<Real>) {
        let x0: Vec<Vec2> = (0..n * n).map(|k| Vec2::new((k % n) as Real * h, (k / n) as Real * h)).collect();
        (x0, vec![2.0 * h; n * n], vec![h * h; n * n])
    }

    /// A point whose every covering particle is hidden has no row to build:
    /// [`rebuild_rows`] fails naming it with 0 particles and leaves the
    /// table as it was; [`rebuild_rows_setting_aside_orphans`] gives it an
    /// empty row, reports it, and builds every other row as
    /// [`rebuild_rows`] does.
    #[test]
    fn a_point_no_particle_sees_takes_an_empty_row() {
        struct HideFrom(Vec2);
        impl Visibility for HideFrom {
            fn visible(&self, x: &Vec2, _particle: usize) -> bool {
                (x - self.0).norm() > 1e-12
            }
        }
        let h = 1e-3;
        let (x0, a, v) = lattice(8, h);
        let pts = vec![Vec2::new(3.3 * h, 2.7 * h), Vec2::new(2.5 * h, 4.5 * h), Vec2::new(5.1 * h, 5.2 * h)];
        let reference = build_table(&pts, &x0, &a, &v, &AllVisible).unwrap();
        let hide = HideFrom(pts[1]);
        let mut t = reference.clone();
        let e = rebuild_rows(&mut t, &mut ShapeTable::default(), &[0, 1, 2], &pts, &x0, &a, &v, &hide, &|_| None);
        assert!(matches!(e, Err(ShapeError::SingularMoment { point: 1, neighbours: 0, .. })), "{e:?}");
        assert_eq!(t, reference, "the table is left as it was");
        let mut spare = ShapeTable::default();
        let (reduced, orphans) = rebuild_rows_setting_aside_orphans(&[0, 1, 2], &|_| None, |given| {
            rebuild_rows(&mut t, &mut spare, &[0, 1, 2], &pts, &x0, &a, &v, &hide, given)
        })
        .unwrap();
        assert!(reduced.is_empty());
        assert_eq!(orphans, vec![1]);
        assert!(t.range(1).is_empty(), "its row is empty");
        for r in [0, 2] {
            let (got, want) = (t.range(r), reference.range(r));
            assert_eq!(&t.index[got.clone()], &reference.index[want.clone()]);
            assert_eq!(&t.value[got], &reference.value[want], "row {r} as before");
        }
    }

    /// Without a crack, a rebuilt row is the row of the whole-table build,
    /// bit for bit (one builder); the linear and constant bases keep their
    /// reproduction properties (partition of unity, and for the linear basis
    /// `Σ N_I X_I = X`, with gradients summing to zero); three collinear
    /// particles make the bilinear and linear moment matrices singular but
    /// not the constant one.
    #[test]
    fn reduced_basis_rows_stay_consistent() {
        let h = 1e-3;
        let (x0, a, v) = lattice(8, h);
        let pts = vec![Vec2::new(3.3 * h, 2.7 * h), Vec2::new(0.1 * h, 0.2 * h)];
        let reference = build_table(&pts, &x0, &a, &v, &AllVisible).unwrap();
        let mut t = reference.clone();
        let reduced =
            rebuild_rows(&mut t, &mut ShapeTable::default(), &[0, 1], &pts, &x0, &a, &v, &AllVisible, &|_| None)
                .unwrap();
        assert!(reduced.is_empty());
        assert_eq!(t, reference);
        let search = SupportSearch::new(&x0, &a);
        let mut cand = Vec::new();
        search.covering(&pts[0], &mut cand);
        let mut row = Row::new();
        for basis in [Basis::Linear, Basis::Constant] {
            row_with_basis(&pts[0], &cand, &x0, &a, &v, basis, &mut row).unwrap();
            let s: Real = row.iter().map(|r| r.1).sum();
            let g: Vec2 = row.iter().map(|r| r.2).sum();
            assert!((s - 1.0).abs() < 1e-12 && g.norm() < 1e-8 / h, "{basis:?}: sum {s}, gradient sum {g}");
            if basis == Basis::Linear {
                let sx: Vec2 = row.iter().map(|r| x0[r.0 as usize] * r.1).sum();
                assert!((sx - pts[0]).norm() < 1e-12 * h);
            }
        }
        let line: Vec<u32> = vec![0, 1, 2];
        for (basis, regular) in [(Basis::Bilinear, false), (Basis::Linear, false), (Basis::Constant, true)] {
            assert_eq!(row_with_basis(&pts[1], &line, &x0, &a, &v, basis, &mut row).is_ok(), regular, "{basis:?}");
        }
    }

    /// Four visible particles make the bilinear row an interpolant; when
    /// they nearly lose the quadrilateral (the fourth a twentieth of a
    /// spacing off the line of two others) its regular moment matrix still
    /// gives values of +5 and −4.5 between them: by hand, the cardinal
    /// functions of `[1, X, Y, XY]` on (0, 0), (h, 0), (0, h), (h, ε) are
    /// `N₁ = 1 − X/h − Y/h + XY/h²`, `N₂ = X/h − XY/(hε)`,
    /// `N₃ = Y/h − XY/h²`, `N₄ = XY/(hε)`: at (h/2, h/2) with ε = h/20,
    /// `¼, −4½, ¼, 5`, Λ = 10. The
    /// fallback takes the linear basis there, which reproduces linear
    /// fields with `Λ` within the bound and gradients of the spacing's
    /// order. The rows of an uncracked lattice, inside and at a corner,
    /// stay far below the bound, so the guard leaves them bilinear.
    #[test]
    fn an_interpolating_row_falls_back_to_a_bounded_one() {
        let h = 1e-3;
        let x0 = vec![Vec2::new(0.0, 0.0), Vec2::new(h, 0.0), Vec2::new(0.0, h), Vec2::new(h, 0.05 * h)];
        let (a, v) = (vec![2.0 * h; 4], vec![h * h; 4]);
        let x = Vec2::new(0.5 * h, 0.5 * h);
        let (cand, mut row) = (vec![0, 1, 2, 3], Row::new());
        row_with_basis(&x, &cand, &x0, &a, &v, Basis::Bilinear, &mut row).expect("regular");
        let bilinear = row_sums(&row, &a).0;
        assert!((bilinear - 10.0).abs() < 1e-9, "the degenerate quadrilateral's Λ = {bilinear}, by hand 10");
        assert!(bilinear > 2.0 * MAX_LEBESGUE_SUM);
        let search = SupportSearch::new(&x0, &a);
        let (fallback, basis) = row_with_fallback(0, &x, &search, &x0, &a, &v, &AllVisible, &mut Vec::new()).unwrap();
        assert_eq!(basis, Basis::Linear);
        assert!(is_bounded(&fallback, &a));
        let s: Real = fallback.iter().map(|r| r.1).sum();
        let sx: Vec2 = fallback.iter().map(|r| x0[r.0 as usize] * r.1).sum();
        assert!((s - 1.0).abs() < 1e-12 && (sx - x).norm() < 1e-12 * h, "linear reproduction: {s}, {sx}");
        let steepest = |r: &Row| r.iter().map(|e| e.2.norm()).fold(0.0, Real::max);
        assert!(steepest(&fallback) * h < 3.0, "gradients of the spacing's order: {}", steepest(&fallback) * h);
        assert!(steepest(&row) > 3.0 * steepest(&fallback));
        let (x0, a, v) = lattice(8, h);
        let search = SupportSearch::new(&x0, &a);
        for x in [Vec2::new(3.3 * h, 2.7 * h), Vec2::new(0.1 * h, 0.2 * h)] {
            let (row, basis) = row_with_fallback(0, &x, &search, &x0, &a, &v, &AllVisible, &mut Vec::new()).unwrap();
            assert_eq!(basis, Basis::Bilinear);
            let (lebesgue, gradient) = row_sums(&row, &a);
            assert!(
                lebesgue < 0.5 * MAX_LEBESGUE_SUM && gradient < 0.5 * MAX_GRADIENT_SUM,
                "lattice row: {lebesgue}, {gradient}"
            );
        }
    }

    /// Four particles on a line and a fifth ε = h/20 off it: the bilinear
    /// moment matrix is singular (its `Y` and `XY` columns are
    /// proportional), and the linear row, which reproduces `Y`, must give
    /// the fifth particle `N₅ = Y/ε` exactly, so `∂N₅/∂Y = 1/ε` = 20/h: a
    /// gradient sum far past the bound with values inside theirs. The
    /// fallback goes on to Shepard's functions: positive, summing to one,
    /// gradients of the support's order.
    #[test]
    fn a_row_across_a_line_of_particles_falls_back_to_shepard() {
        let (h, eps) = (1e-3, 0.05e-3);
        let mut x0: Vec<Vec2> = (0..4).map(|i| Vec2::new(i as Real * h, 0.0)).collect();
        x0.push(Vec2::new(1.5 * h, eps));
        let (a, v) = (vec![2.0 * h; 5], vec![h * h; 5]);
        let x = Vec2::new(1.4 * h, 0.3 * eps);
        let (cand, mut row) = ((0..5).collect::<Vec<u32>>(), Row::new());
        assert!(row_with_basis(&x, &cand, &x0, &a, &v, Basis::Bilinear, &mut row).is_err());
        row_with_basis(&x, &cand, &x0, &a, &v, Basis::Linear, &mut row).expect("regular");
        let fifth = row.iter().find(|r| r.0 == 4).expect("the fifth particle covers x");
        assert!((fifth.1 - 0.3).abs() < 1e-9, "N5 = Y/eps = 0.3, got {}", fifth.1);
        assert!((fifth.2.y * eps - 1.0).abs() < 1e-6, "dN5/dY = 1/eps, got {} eps", fifth.2.y * eps);
        let (lebesgue, gradient) = row_sums(&row, &a);
        assert!(lebesgue <= MAX_LEBESGUE_SUM && gradient > MAX_GRADIENT_SUM, "linear row: {lebesgue}, {gradient}");
        let search = SupportSearch::new(&x0, &a);
        let (shepard, basis) = row_with_fallback(0, &x, &search, &x0, &a, &v, &AllVisible, &mut Vec::new()).unwrap();
        assert_eq!(basis, Basis::Constant);
        let s: Real = shepard.iter().map(|r| r.1).sum();
        assert!((s - 1.0).abs() < 1e-12 && shepard.iter().all(|r| r.1 >= 0.0));
        assert!(row_sums(&shepard, &a).1 < MAX_GRADIENT_SUM, "Shepard's gradient sum {}", row_sums(&shepard, &a).1);
    }

    /// The gradients of every basis are the derivatives of the values: a
    /// central finite difference of each `N_I` at a point matches `∇N_I`.
    #[test]
    fn gradients_are_derivatives_for_every_basis() {
        let h = 1e-3;
        let (x0, a, v) = lattice(8, h);
        let search = SupportSearch::new(&x0, &a);
        let x = Vec2::new(3.3 * h, 2.7 * h);
        let d = 1e-7 * h;
        for basis in [Basis::Bilinear, Basis::Linear, Basis::Constant] {
            let row_at = |x: &Vec2| {
                let (mut cand, mut row) = (Vec::new(), Row::new());
                search.covering(x, &mut cand);
                row_with_basis(x, &cand, &x0, &a, &v, basis, &mut row).unwrap();
                row
            };
            let centre = row_at(&x);
            for k in 0..2 {
                let e = if k == 0 { Vec2::new(d, 0.0) } else { Vec2::new(0.0, d) };
                let (plus, minus) = (row_at(&(x + e)), row_at(&(x - e)));
                for (c, (p, m)) in centre.iter().zip(plus.iter().zip(&minus)) {
                    assert!(c.0 == p.0 && c.0 == m.0, "same particles at the shifted points");
                    let fd = (p.1 - m.1) / (2.0 * d);
                    assert!((fd - c.2[k]).abs() < 1e-5 / h, "{basis:?}: particle {}, d/dX{k}: {fd} vs {}", c.0, c.2[k]);
                }
            }
        }
    }
}
