//! Scalar, vector and tensor types shared by every physics module, and the
//! handful of tensor operations the constitutive models need (SPEC §2).
//!
//! Tensors are 3×3 even in 2D: index 0 is x (or r), 1 is y (or z), 2 is the
//! out-of-plane direction (z in plane strain, θ in axisymmetry).

/// The floating-point type of the whole solver.
pub type Real = f64;
/// A point or vector in the 2D reference plane (x, y) or (r, z).
pub type Vec2 = nalgebra::Vector2<Real>;
/// A second-order tensor (stress, deformation gradient, rates).
pub type Tensor3 = nalgebra::Matrix3<Real>;

/// The identity tensor.
#[inline]
pub fn identity() -> Tensor3 {
    Tensor3::identity()
}

/// Deviatoric part `s = τ − (tr τ / 3) I`.
#[inline]
pub fn deviator(t: &Tensor3) -> Tensor3 {
    t - identity() * (t.trace() / 3.0)
}

/// Mean (hydrostatic) part `tr τ / 3`; pressure is its negative.
#[inline]
pub fn mean_stress(t: &Tensor3) -> Real {
    t.trace() / 3.0
}

/// Von Mises equivalent value `sqrt(3/2 s:s)` of a tensor's deviator.
#[inline]
pub fn von_mises(t: &Tensor3) -> Real {
    let s = deviator(t);
    (1.5 * s.component_mul(&s).sum()).sqrt()
}

/// Symmetric part.
#[inline]
pub fn sym(t: &Tensor3) -> Tensor3 {
    (t + t.transpose()) * 0.5
}

/// Skew-symmetric part.
#[inline]
pub fn skew(t: &Tensor3) -> Tensor3 {
    (t - t.transpose()) * 0.5
}

/// Double contraction `a : b`.
#[inline]
pub fn ddot(a: &Tensor3, b: &Tensor3) -> Real {
    a.component_mul(b).sum()
}

/// Lift a 2D vector into 3D with a zero out-of-plane component.
#[inline]
pub fn lift(v: &Vec2) -> nalgebra::Vector3<Real> {
    nalgebra::Vector3::new(v.x, v.y, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn von_mises_of_uniaxial_stress_is_the_stress() {
        let mut t = Tensor3::zeros();
        t[(0, 0)] = 250.0;
        assert!((von_mises(&t) - 250.0).abs() < 1e-12);
        assert!((mean_stress(&t) - 250.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn von_mises_of_pure_shear_is_sqrt3_tau() {
        let mut t = Tensor3::zeros();
        t[(0, 1)] = 10.0;
        t[(1, 0)] = 10.0;
        assert!((von_mises(&t) - 10.0 * 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn sym_plus_skew_is_whole() {
        let t = Tensor3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0);
        assert!((sym(&t) + skew(&t) - t).norm() < 1e-14);
        assert!(deviator(&t).trace().abs() < 1e-14);
        assert!((ddot(&t, &identity()) - t.trace()).abs() < 1e-14);
    }
}
