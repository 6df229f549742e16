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

/// Whether `t` has the block form of 2D kinematics: an in-plane 2×2 block
/// and the out-of-plane `(2, 2)` entry, zeros elsewhere. `F`, `ℓ` and `τ`
/// keep this form in plane strain and in axisymmetry alike (SPEC §2: no
/// out-of-plane shear), which the `*_2d` functions below exploit.
#[inline]
pub fn is_block_2d(t: &Tensor3) -> bool {
    t[(0, 2)] == 0.0 && t[(1, 2)] == 0.0 && t[(2, 0)] == 0.0 && t[(2, 1)] == 0.0
}

/// `det t`: for a tensor of block form, nalgebra's 3×3 formula with its
/// products of known zeros left out (`x − 0·y = x` exactly, so the result
/// has the same bits as `t.determinant()`); otherwise nalgebra's.
#[inline]
pub fn determinant_2d(t: &Tensor3) -> Real {
    if !is_block_2d(t) {
        return t.determinant();
    }
    let (m11, m12, m21, m22, m33) = (t[(0, 0)], t[(0, 1)], t[(1, 0)], t[(1, 1)], t[(2, 2)]);
    m11 * (m22 * m33) - m12 * (m21 * m33)
}

/// `t⁻¹`, `None` if `det t = 0`: for a tensor of block form, nalgebra's
/// cofactor formula with the products of known zeros left out — 5 divisions
/// instead of 9 and the same bits as `t.try_inverse()` (test
/// `block_2d_operations_match_nalgebra_bit_for_bit`); otherwise nalgebra's.
#[inline]
pub fn try_inverse_2d(t: &Tensor3) -> Option<Tensor3> {
    if !is_block_2d(t) {
        return t.try_inverse();
    }
    let (m11, m12, m21, m22, m33) = (t[(0, 0)], t[(0, 1)], t[(1, 0)], t[(1, 1)], t[(2, 2)]);
    let minor_m12_m23 = m22 * m33;
    let minor_m11_m23 = m21 * m33;
    let det = m11 * minor_m12_m23 - m12 * minor_m11_m23;
    if det == 0.0 {
        return None;
    }
    Some(Tensor3::new(
        minor_m12_m23 / det,
        -(m33 * m12) / det,
        0.0,
        -minor_m11_m23 / det,
        (m11 * m33) / det,
        0.0,
        0.0,
        0.0,
        (m11 * m22 - m21 * m12) / det,
    ))
}

/// `a b`: for two tensors of block form, the 2×2 block product and the
/// `(2, 2)` product, summed in nalgebra's order (so the same bits as
/// `a * b`); otherwise nalgebra's product.
#[inline]
pub fn mul_2d(a: &Tensor3, b: &Tensor3) -> Tensor3 {
    if !(is_block_2d(a) && is_block_2d(b)) {
        return a * b;
    }
    Tensor3::new(
        a[(0, 0)] * b[(0, 0)] + a[(0, 1)] * b[(1, 0)],
        a[(0, 0)] * b[(0, 1)] + a[(0, 1)] * b[(1, 1)],
        0.0,
        a[(1, 0)] * b[(0, 0)] + a[(1, 1)] * b[(1, 0)],
        a[(1, 0)] * b[(0, 1)] + a[(1, 1)] * b[(1, 1)],
        0.0,
        0.0,
        0.0,
        a[(2, 2)] * b[(2, 2)],
    )
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

    /// Random tensors of block form, some singular, some with negative
    /// entries: the block functions give exactly nalgebra's values; other
    /// tensors take nalgebra's path.
    #[test]
    fn block_2d_operations_match_nalgebra_bit_for_bit() {
        let mut seed = 11u64;
        let mut r = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as Real / (1u64 << 53) as Real - 0.5) * 4.0
        };
        let mut block = || {
            let mut t = Tensor3::zeros();
            for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1), (2, 2)] {
                t[(i, j)] = r();
            }
            t
        };
        let same = |a: &Tensor3, b: &Tensor3| a.iter().zip(b.iter()).all(|(x, y)| x == y);
        for k in 0..10_000 {
            let (mut a, b) = (block(), block());
            if k % 100 == 0 {
                a[(1, 0)] = a[(0, 0)] * a[(1, 1)] / a[(0, 1)]; // (nearly) singular
            }
            assert!(is_block_2d(&a) && is_block_2d(&b));
            assert_eq!(determinant_2d(&a).to_bits(), a.determinant().to_bits());
            match (try_inverse_2d(&a), a.try_inverse()) {
                (Some(x), Some(y)) => assert!(same(&x, &y), "{a}"),
                (None, None) => {}
                (x, y) => panic!("{x:?} vs {y:?}"),
            }
            assert!(same(&mul_2d(&a, &b), &(a * b)));
            assert!(same(&mul_2d(&a, &b.transpose()), &(a * b.transpose())));
        }
        let mut a = Tensor3::zeros();
        assert_eq!(try_inverse_2d(&a), None);
        a[(2, 2)] = 1.0;
        assert_eq!(try_inverse_2d(&a), None);
        let full = Tensor3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0);
        assert!(!is_block_2d(&full));
        assert_eq!(try_inverse_2d(&full), full.try_inverse());
        assert_eq!(determinant_2d(&full), full.determinant());
        assert_eq!(mul_2d(&full, &identity()), full);
    }
}
