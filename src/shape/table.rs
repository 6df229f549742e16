//! Compressed-row storage of shape-function values and gradients.

use crate::math::{Real, Vec2};
use nalgebra::Matrix2;

/// Shape functions `N_I(X_p)` and gradients `∇_X N_I(X_p)` of a set of
/// evaluation points `p` (quadrature points, or particles themselves), one
/// row per point: row `p` holds entries `offsets[p]..offsets[p+1]`, each
/// naming a particle `index[k]` with value `value[k]` and gradient `grad[k]`.
/// Computed once in the reference configuration (total Lagrangian) and
/// patched locally when a crack changes visibility.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShapeTable {
    /// Row starts, length `rows + 1`.
    pub offsets: Vec<usize>,
    /// Particle index of each entry.
    pub index: Vec<u32>,
    /// `N_I(X_p)`.
    pub value: Vec<Real>,
    /// `∇_X N_I(X_p)`, 1/m.
    pub grad: Vec<Vec2>,
}

impl ShapeTable {
    /// Number of rows (evaluation points).
    pub fn rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
    /// Entry range of row `p`.
    #[inline]
    pub fn range(&self, p: usize) -> std::ops::Range<usize> {
        self.offsets[p]..self.offsets[p + 1]
    }
    /// Total number of stored entries.
    pub fn nnz(&self) -> usize {
        self.index.len()
    }
    /// Interpolate a particle field at evaluation point `p`: `Σ_I N_I(X_p) f_I`.
    #[inline]
    pub fn interpolate(&self, p: usize, field: &[Vec2]) -> Vec2 {
        let mut s = Vec2::zeros();
        for k in self.range(p) {
            s += field[self.index[k] as usize] * self.value[k];
        }
        s
    }

    /// Gradients of two particle fields at evaluation point `p`:
    /// `(Σ_I a_I ⊗ ∇N_I(X_p), Σ_I b_I ⊗ ∇N_I(X_p))`, entries in row order.
    /// The velocity-gradient sweep of every step: one pass over the row's
    /// indices and gradients, without the values.
    #[inline]
    pub fn gradient_pair(&self, p: usize, a: &[Vec2], b: &[Vec2]) -> (Matrix2<Real>, Matrix2<Real>) {
        let r = self.range(p);
        let (index, grad) = (&self.index[r.clone()], &self.grad[r]);
        let (mut ga, mut gb) = (Matrix2::zeros(), Matrix2::zeros());
        for (&i, g) in index.iter().zip(grad) {
            let i = i as usize;
            ga += a[i] * g.transpose();
            gb += b[i] * g.transpose();
        }
        (ga, gb)
    }

    /// [`ShapeTable::gradient_pair`] and [`ShapeTable::interpolate`] of
    /// both fields at evaluation point `p` in one pass over the row:
    /// `(∇a, ∇b, a, b)`, each sum in row order as the two would form it
    /// (the same bits). The axisymmetric sweep needs the point values too
    /// (the hoop stretch `u_r/R`); reading the row once instead of three
    /// times took 11 % of a 96-row run's profile down to (see
    /// `docs/performance.md`).
    #[inline]
    pub fn gradient_pair_and_values(&self, p: usize, a: &[Vec2], b: &[Vec2]) -> GradientsAndValues {
        let r = self.range(p);
        let (index, grad, value) = (&self.index[r.clone()], &self.grad[r.clone()], &self.value[r]);
        let (mut ga, mut gb) = (Matrix2::zeros(), Matrix2::zeros());
        let (mut va, mut vb) = (Vec2::zeros(), Vec2::zeros());
        for ((&i, g), &n) in index.iter().zip(grad).zip(value) {
            let i = i as usize;
            ga += a[i] * g.transpose();
            gb += b[i] * g.transpose();
            va += a[i] * n;
            vb += b[i] * n;
        }
        (ga, gb, va, vb)
    }
}

/// `(∇a, ∇b, a, b)` at one evaluation point
/// ([`ShapeTable::gradient_pair_and_values`]).
pub type GradientsAndValues = (Matrix2<Real>, Matrix2<Real>, Vec2, Vec2);
