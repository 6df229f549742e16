//! Plane strain versus axisymmetry: the one place where the two geometry
//! modes differ (SPEC §1, §2, §4).
//!
//! Coordinates are (x, y) in plane strain and (r, z) = (x, y) in
//! axisymmetry, with the axis at x = 0. The out-of-plane tensor component
//! (index 2) is z in plane strain (`F_zz = 1`) and the hoop direction θ in
//! axisymmetry (`F_θθ = 1 + u_r/R`, `d_θθ = v_r/r`).

use crate::math::{Block2, InPlane, Real, Tensor3, Vec2};
use serde::{Deserialize, Serialize};

/// How a 2D section represents the 3D body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GeometryMode {
    /// Per unit depth; `ε_zz = 0`.
    PlaneStrain,
    /// r–z half section revolved about the axis x = 0.
    Axisymmetric,
}

impl GeometryMode {
    /// Factor turning an area at reference point `x0` into a volume: 1 (per
    /// unit depth) or `2πR` (SPEC §1).
    #[inline]
    pub fn volume_factor(self, x0: &Vec2) -> Real {
        match self {
            GeometryMode::PlaneStrain => 1.0,
            GeometryMode::Axisymmetric => 2.0 * std::f64::consts::PI * x0.x,
        }
    }

    /// Whether [`Self::deformation_gradient`] reads the interpolated
    /// displacement `u` (the hoop stretch `u_r/R` of axisymmetry); in plane
    /// strain only the gradient is needed.
    #[inline]
    pub fn needs_point_values(self) -> bool {
        self == GeometryMode::Axisymmetric
    }

    /// Deformation gradient from the in-plane displacement gradient
    /// `grad_u[i][J] = ∂u_i/∂X_J` and the interpolated displacement `u` at
    /// reference point `x0` (SPEC §2). Also used with velocities to get `Ḟ`
    /// (then `identity_part = 0`).
    ///
    /// The hoop term `u_r/R` needs `R > 0`; quadrature points never lie on
    /// the axis (Gauss points are interior to their cells), and at `R = 0`
    /// its limit `∂u_r/∂R` is used.
    #[inline]
    pub fn deformation_gradient(
        self,
        grad_u: &nalgebra::Matrix2<Real>,
        u: &Vec2,
        x0: &Vec2,
        identity_part: Real,
    ) -> Tensor3 {
        let mut f = Tensor3::zeros();
        for i in 0..2 {
            for j in 0..2 {
                f[(i, j)] = grad_u[(i, j)];
            }
        }
        f[(2, 2)] = self.out_of_plane_gradient(grad_u, u, x0);
        f + Tensor3::identity() * identity_part
    }

    /// The out-of-plane entry of `∇u`: 0 in plane strain, the hoop strain
    /// `u_r/R` in axisymmetry (`∂u_r/∂R` on the axis, its limit there).
    #[inline]
    fn out_of_plane_gradient(self, grad_u: &nalgebra::Matrix2<Real>, u: &Vec2, x0: &Vec2) -> Real {
        match self {
            GeometryMode::PlaneStrain => 0.0,
            GeometryMode::Axisymmetric => {
                if x0.x > 0.0 {
                    u.x / x0.x
                } else {
                    grad_u[(0, 0)]
                }
            }
        }
    }

    /// [`Self::deformation_gradient`] as a [`Block2`] (which it always is),
    /// with the same bits: nalgebra's `f + I·identity_part` adds
    /// `0·identity_part` to the off-diagonal entries, and so does this (test
    /// `block_deformation_gradient_has_the_same_bits`).
    #[inline]
    pub fn deformation_gradient_2d(
        self,
        grad_u: &nalgebra::Matrix2<Real>,
        u: &Vec2,
        x0: &Vec2,
        identity_part: Real,
    ) -> Block2 {
        let zz = self.out_of_plane_gradient(grad_u, u, x0);
        let off = 0.0 * identity_part;
        Block2 {
            xx: grad_u[(0, 0)] + identity_part,
            xy: grad_u[(0, 1)] + off,
            yx: grad_u[(1, 0)] + off,
            yy: grad_u[(1, 1)] + identity_part,
            zz: zz + identity_part,
        }
    }

    /// Force on particle `I` from quadrature point `q`: `f_i = (P w_q)_{iJ}
    /// ∂N_I/∂X_J`, plus in axisymmetry the hoop term `(P w_q)_θθ N_I / R_q`
    /// on the radial component ([RL10, Eq. (2.31)], SPEC §4); `pw` is the
    /// in-plane block of `P w_q`, `pw_zz` its out-of-plane entry (read only
    /// in axisymmetry).
    #[inline]
    pub fn internal_force(self, pw: &InPlane, pw_zz: Real, n: Real, grad_n: &Vec2, x0_q: &Vec2) -> Vec2 {
        let mut f = Vec2::new(pw.xx * grad_n.x + pw.xy * grad_n.y, pw.yx * grad_n.x + pw.yy * grad_n.y);
        if self == GeometryMode::Axisymmetric {
            f.x += pw_zz * n / x0_q.x;
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axisymmetric_hoop_stretch_of_uniform_radial_expansion() {
        // u_r = e R  =>  F_rr = F_tt = 1 + e, F_zz = 1
        let e = 0.01;
        let g = nalgebra::Matrix2::new(e, 0.0, 0.0, 0.0);
        let x0 = Vec2::new(0.3, 0.1);
        let f = GeometryMode::Axisymmetric.deformation_gradient(
            &g,
            &(x0 * e).component_mul(&Vec2::new(1.0, 0.0)),
            &x0,
            1.0,
        );
        assert!((f[(0, 0)] - 1.01).abs() < 1e-15);
        assert!((f[(2, 2)] - 1.01).abs() < 1e-15);
        let fp = GeometryMode::PlaneStrain.deformation_gradient(&g, &Vec2::new(0.003, 0.0), &x0, 1.0);
        assert_eq!(fp[(2, 2)], 1.0);
        // on the axis the limit du_r/dR is used
        let fa = GeometryMode::Axisymmetric.deformation_gradient(&g, &Vec2::zeros(), &Vec2::new(0.0, 0.1), 1.0);
        assert!((fa[(2, 2)] - 1.01).abs() < 1e-15);
    }

    #[test]
    fn block_deformation_gradient_has_the_same_bits() {
        let bits = |t: &Tensor3| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for g in [nalgebra::Matrix2::new(0.01, -0.0, 0.0, -0.02), nalgebra::Matrix2::new(-0.0, -0.3, -0.0, 0.0)] {
            for (u, x0) in [(Vec2::new(1e-3, 0.0), Vec2::new(0.3, 0.1)), (Vec2::new(-0.0, 2.0), Vec2::new(0.0, 0.1))] {
                for mode in [GeometryMode::PlaneStrain, GeometryMode::Axisymmetric] {
                    for ip in [1.0, 0.0] {
                        let full = mode.deformation_gradient(&g, &u, &x0, ip);
                        assert_eq!(bits(&mode.deformation_gradient_2d(&g, &u, &x0, ip).to_tensor()), bits(&full));
                    }
                }
            }
        }
    }
}
