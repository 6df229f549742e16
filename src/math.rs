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

/// [`von_mises`], on the five entries of a tensor of block form
/// ([`Block2::von_mises`], the same bits), else nalgebra's.
#[inline]
pub fn von_mises_2d(t: &Tensor3) -> Real {
    match Block2::from_tensor(t) {
        Some(b) => b.von_mises(),
        None => von_mises(t),
    }
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

/// The largest principal value `σ₁` of a symmetric tensor (the
/// Cockcroft–Latham criterion's stress, [`crate::material::johnson_cook`]).
/// In block form (2D kinematics, [`is_block_2d`]) the larger of the in-plane
/// pair `c + √(((a₀₀ − a₁₁)/2)² + a₀₁²)` and the out-of-plane entry; otherwise
/// the trigonometric closed form of the symmetric 3×3 eigenproblem (Smith,
/// Comm. ACM 4 (1961) 168), so that the same function serves 3D. Test:
/// `largest_principal_matches_the_symmetric_eigenvalues`.
#[inline]
pub fn largest_principal(t: &Tensor3) -> Real {
    if is_block_2d(t) {
        let c = 0.5 * (t[(0, 0)] + t[(1, 1)]);
        let h = 0.5 * (t[(0, 0)] - t[(1, 1)]);
        let r = h.hypot(t[(0, 1)]);
        return (c + r).max(t[(2, 2)]);
    }
    let off = t[(0, 1)] * t[(0, 1)] + t[(0, 2)] * t[(0, 2)] + t[(1, 2)] * t[(1, 2)];
    if off == 0.0 {
        return t[(0, 0)].max(t[(1, 1)]).max(t[(2, 2)]);
    }
    let q = t.trace() / 3.0;
    let p2 = (t[(0, 0)] - q).powi(2) + (t[(1, 1)] - q).powi(2) + (t[(2, 2)] - q).powi(2) + 2.0 * off;
    let p = (p2 / 6.0).sqrt();
    let b = (t - identity() * q) / p;
    let r = (0.5 * b.determinant()).clamp(-1.0, 1.0);
    q + 2.0 * p * (r.acos() / 3.0).cos()
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

/// A tensor of block form (see [`is_block_2d`]) held by its five possibly
/// non-zero entries: the in-plane block `xx xy / yx yy` and the
/// out-of-plane `zz`. The hot per-point kinematics and the elastic trial
/// stress work on these instead of nine-entry [`Tensor3`]s.
///
/// Every operation repeats, entry by entry, the arithmetic nalgebra does
/// on the corresponding [`Tensor3`] — including its products with the
/// identity's zeros (`0·s`), which can flip the sign of a zero — so that
/// [`Block2::to_tensor`] of a result has the same bits as the [`Tensor3`]
/// expression (test `block2_operations_match_nalgebra_bit_for_bit`). The
/// entries outside the block are `+0` in every result, as nalgebra gives
/// them for block-form operands and the non-negative scale factors used; the ones left out of sums (`ddot`, `von
/// Mises`) are `±0` terms, which never change a running sum that starts at
/// `+0` (such a sum is never `−0`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Block2 {
    pub xx: Real,
    pub xy: Real,
    pub yx: Real,
    pub yy: Real,
    pub zz: Real,
}

/// The in-plane block `xx xy / yx yy` of a [`Block2`] on its own, 32
/// bytes aligned to 32: two to a cache line and none across two, so that
/// a gather that reads it at scattered points never loads one block from
/// two lines (a five-entry [`Block2`] of 40 bytes straddles a line at
/// three offsets in eight). The force gather reads `P w` this way
/// ([`crate::quadrature::QuadraturePoints::pw`]); measured on the fine
/// Case I's gather, one thread, 1.2–1.4× faster than from `Block2`s.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[repr(C, align(32))]
pub struct InPlane {
    pub xx: Real,
    pub xy: Real,
    pub yx: Real,
    pub yy: Real,
}

impl Block2 {
    /// The in-plane block.
    #[inline]
    pub fn in_plane(&self) -> InPlane {
        InPlane { xx: self.xx, xy: self.xy, yx: self.yx, yy: self.yy }
    }
    /// The block of in-plane entries `p` and out-of-plane entry `zz`.
    #[inline]
    pub fn from_parts(p: &InPlane, zz: Real) -> Block2 {
        Block2 { xx: p.xx, xy: p.xy, yx: p.yx, yy: p.yy, zz }
    }
    /// The block entries of `t`, `None` unless `t` has the block form.
    #[inline]
    pub fn from_tensor(t: &Tensor3) -> Option<Block2> {
        is_block_2d(t).then(|| Block2 { xx: t[(0, 0)], xy: t[(0, 1)], yx: t[(1, 0)], yy: t[(1, 1)], zz: t[(2, 2)] })
    }
    /// The five block entries of any tensor (those outside are dropped).
    #[inline]
    pub fn block_part(t: &Tensor3) -> Block2 {
        Block2 { xx: t[(0, 0)], xy: t[(0, 1)], yx: t[(1, 0)], yy: t[(1, 1)], zz: t[(2, 2)] }
    }
    /// Whether every entry is finite.
    #[inline]
    pub fn is_finite(&self) -> bool {
        self.xx.is_finite() && self.xy.is_finite() && self.yx.is_finite() && self.yy.is_finite() && self.zz.is_finite()
    }
    /// The zero tensor.
    #[inline]
    pub fn zeros() -> Block2 {
        Block2 { xx: 0.0, xy: 0.0, yx: 0.0, yy: 0.0, zz: 0.0 }
    }
    /// The full tensor, `+0` outside the block.
    #[inline]
    pub fn to_tensor(&self) -> Tensor3 {
        Tensor3::new(self.xx, self.xy, 0.0, self.yx, self.yy, 0.0, 0.0, 0.0, self.zz)
    }
    /// The block entries of `identity() * s` (outside the block nalgebra
    /// has `0·s`, `−0` for `s < 0`; added to or subtracted from a block
    /// tensor, as it is used here, those give `+0`).
    #[inline]
    pub fn identity_scaled(s: Real) -> Block2 {
        Block2 { xx: s, xy: 0.0 * s, yx: 0.0 * s, yy: s, zz: s }
    }
    /// `self + b`.
    #[inline]
    pub fn add(&self, b: &Block2) -> Block2 {
        Block2 { xx: self.xx + b.xx, xy: self.xy + b.xy, yx: self.yx + b.yx, yy: self.yy + b.yy, zz: self.zz + b.zz }
    }
    /// `self − b`.
    #[inline]
    pub fn sub(&self, b: &Block2) -> Block2 {
        Block2 { xx: self.xx - b.xx, xy: self.xy - b.xy, yx: self.yx - b.yx, yy: self.yy - b.yy, zz: self.zz - b.zz }
    }
    /// `self * s` for `s ≥ 0` (a negative factor would give nalgebra's `−0`
    /// outside the block; the solver scales by `½`, `Δt`, moduli and
    /// weights).
    #[inline]
    pub fn scale(&self, s: Real) -> Block2 {
        Block2 { xx: self.xx * s, xy: self.xy * s, yx: self.yx * s, yy: self.yy * s, zz: self.zz * s }
    }
    /// `tr self`, summed as nalgebra does (from `+0`, in index order).
    #[inline]
    pub fn trace(&self) -> Real {
        0.0 + self.xx + self.yy + self.zz
    }
    /// `det self`, as [`determinant_2d`].
    #[inline]
    pub fn determinant(&self) -> Real {
        self.xx * (self.yy * self.zz) - self.xy * (self.yx * self.zz)
    }
    /// `self⁻¹`, as [`try_inverse_2d`]; `None` if the determinant is 0.
    #[inline]
    pub fn try_inverse(&self) -> Option<Block2> {
        let (m11, m12, m21, m22, m33) = (self.xx, self.xy, self.yx, self.yy, self.zz);
        let minor_m12_m23 = m22 * m33;
        let minor_m11_m23 = m21 * m33;
        let det = m11 * minor_m12_m23 - m12 * minor_m11_m23;
        if det == 0.0 {
            return None;
        }
        Some(Block2 {
            xx: minor_m12_m23 / det,
            xy: -(m33 * m12) / det,
            yx: -minor_m11_m23 / det,
            yy: (m11 * m33) / det,
            zz: (m11 * m22 - m21 * m12) / det,
        })
    }
    /// `self b`, as [`mul_2d`].
    #[inline]
    pub fn mul(&self, b: &Block2) -> Block2 {
        Block2 {
            xx: self.xx * b.xx + self.xy * b.yx,
            xy: self.xx * b.xy + self.xy * b.yy,
            yx: self.yx * b.xx + self.yy * b.yx,
            yy: self.yx * b.xy + self.yy * b.yy,
            zz: self.zz * b.zz,
        }
    }
    /// `self bᵀ`, as [`mul_2d`] with a transposed second factor.
    #[inline]
    pub fn mul_transpose(&self, b: &Block2) -> Block2 {
        Block2 {
            xx: self.xx * b.xx + self.xy * b.xy,
            xy: self.xx * b.yx + self.xy * b.yy,
            yx: self.yx * b.xx + self.yy * b.xy,
            yy: self.yx * b.yx + self.yy * b.yy,
            zz: self.zz * b.zz,
        }
    }
    /// Symmetric part, as [`sym`].
    #[inline]
    pub fn sym(&self) -> Block2 {
        Block2 {
            xx: (self.xx + self.xx) * 0.5,
            xy: (self.xy + self.yx) * 0.5,
            yx: (self.yx + self.xy) * 0.5,
            yy: (self.yy + self.yy) * 0.5,
            zz: (self.zz + self.zz) * 0.5,
        }
    }
    /// Skew-symmetric part, as [`skew`] (whose diagonal `x − x` is `0`
    /// for finite `x` and NaN otherwise: kept, not written as `0`).
    #[allow(clippy::eq_op)]
    #[inline]
    pub fn skew(&self) -> Block2 {
        Block2 {
            xx: (self.xx - self.xx) * 0.5,
            xy: (self.xy - self.yx) * 0.5,
            yx: (self.yx - self.xy) * 0.5,
            yy: (self.yy - self.yy) * 0.5,
            zz: (self.zz - self.zz) * 0.5,
        }
    }
    /// Deviatoric part, as [`deviator`].
    #[inline]
    pub fn deviator(&self) -> Block2 {
        self.sub(&Block2::identity_scaled(self.trace() / 3.0))
    }
    /// `self : b`, as [`ddot`] (nalgebra's column-major order).
    #[inline]
    pub fn ddot(&self, b: &Block2) -> Real {
        0.0 + self.xx * b.xx + self.yx * b.yx + self.xy * b.xy + self.yy * b.yy + self.zz * b.zz
    }
    /// Von Mises value, as [`von_mises`].
    #[inline]
    pub fn von_mises(&self) -> Real {
        let s = self.deviator();
        (1.5 * s.ddot(&s)).sqrt()
    }
}

/// Entries for the bit-identity tests of the block form: a fixed
/// pseudo-random stream (seeded by `seed`) uniform in `(−scale, scale)`,
/// with `+0`, `−0` and tiny negative values (`−1e-300`) mixed in, one draw
/// in 13 each — the values whose signs a reordered product would flip.
#[cfg(test)]
pub(crate) fn bit_test_entries(mut seed: u64, scale: Real) -> impl FnMut() -> Real {
    move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let u = (seed >> 11) as Real / (1u64 << 53) as Real;
        match seed % 13 {
            0 => 0.0,
            1 => -0.0,
            2 => -1e-300 * u,
            _ => (u - 0.5) * 2.0 * scale,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn largest_principal_matches_the_symmetric_eigenvalues() {
        // Block form (2D) and full 3×3 tensors, against nalgebra's
        // symmetric eigenvalue solver.
        let mut seed = 12345u64;
        let mut r = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as Real / (1u64 << 53) as Real) * 2.0 - 1.0
        };
        for case in 0..2000 {
            let mut t = Tensor3::new(r(), r(), r(), 0.0, r(), r(), 0.0, 0.0, r()) * 1e9;
            if case % 2 == 0 {
                t[(0, 2)] = 0.0;
                t[(1, 2)] = 0.0;
            }
            let t = sym(&(t + t.transpose()));
            let want = t.symmetric_eigenvalues().max();
            let got = largest_principal(&t);
            assert!((got - want).abs() <= 1e-9 * t.norm(), "{t} {got} {want}");
        }
        // Pure shear τ: σ₁ = τ; uniaxial tension σ: σ₁ = σ; equal triaxial
        // compression: σ₁ = −p.
        let shear = Tensor3::new(0.0, 3.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(largest_principal(&shear), 3.0);
        assert_eq!(largest_principal(&Tensor3::from_diagonal(&nalgebra::Vector3::new(0.0, 5.0, 0.0))), 5.0);
        assert_eq!(largest_principal(&(identity() * -2.0)), -2.0);
        let mut rotated = Tensor3::new(1.0, 0.0, 2.0, 0.0, -1.0, 0.0, 2.0, 0.0, 1.0);
        rotated = sym(&rotated);
        assert!((largest_principal(&rotated) - 3.0).abs() < 1e-12);
    }

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

    /// Random block tensors with signed zeros, singular and special
    /// entries: every [`Block2`] operation gives nalgebra's bits, and `+0`
    /// outside the block.
    #[test]
    fn block2_operations_match_nalgebra_bit_for_bit() {
        let mut r = bit_test_entries(5, 2.0);
        let bits = |t: &Tensor3| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for k in 0..20_000 {
            let (mut ta, mut tb) = (Tensor3::zeros(), Tensor3::zeros());
            for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1), (2, 2)] {
                ta[(i, j)] = r();
                tb[(i, j)] = r();
            }
            if k % 50 == 0 {
                ta[(1, 0)] = ta[(0, 0)] * ta[(1, 1)] / ta[(0, 1)];
            }
            let (a, b) = (Block2::from_tensor(&ta).unwrap(), Block2::from_tensor(&tb).unwrap());
            assert_eq!(bits(&a.to_tensor()), bits(&ta));
            let s = r();
            // Alone, `I s` has `0·s = −0` outside the block for `s < 0`; in
            // a sum or difference with a block tensor those become `+0`.
            assert_eq!(bits(&a.sub(&Block2::identity_scaled(s)).to_tensor()), bits(&(ta - identity() * s)));
            assert_eq!(bits(&a.add(&Block2::identity_scaled(s)).to_tensor()), bits(&(ta + identity() * s)));
            assert_eq!(bits(&a.add(&b).to_tensor()), bits(&(ta + tb)));
            assert_eq!(bits(&a.sub(&b).to_tensor()), bits(&(ta - tb)));
            assert_eq!(bits(&a.scale(s.abs()).to_tensor()), bits(&(ta * s.abs())));
            assert_eq!(a.trace().to_bits(), ta.trace().to_bits());
            assert_eq!(a.determinant().to_bits(), determinant_2d(&ta).to_bits());
            match (a.try_inverse(), try_inverse_2d(&ta)) {
                (Some(x), Some(y)) => assert_eq!(bits(&x.to_tensor()), bits(&y)),
                (None, None) => {}
                (x, y) => panic!("{x:?} vs {y:?}"),
            }
            assert_eq!(bits(&a.mul(&b).to_tensor()), bits(&mul_2d(&ta, &tb)));
            assert_eq!(bits(&a.mul_transpose(&b).to_tensor()), bits(&mul_2d(&ta, &tb.transpose())));
            assert_eq!(bits(&a.sym().to_tensor()), bits(&sym(&ta)));
            assert_eq!(bits(&a.skew().to_tensor()), bits(&skew(&ta)));
            assert_eq!(bits(&a.deviator().to_tensor()), bits(&deviator(&ta)));
            assert_eq!(a.ddot(&b).to_bits(), ddot(&ta, &tb).to_bits());
            assert_eq!(a.von_mises().to_bits(), von_mises(&ta).to_bits());
        }
        assert_eq!(Block2::from_tensor(&Tensor3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0)), None);
    }

    /// The force gather's `P w` column: one in-plane block per 32 bytes,
    /// each on a 32-byte boundary (so none spans two cache lines), and a
    /// block split into its in-plane part and `zz` and joined again keeps
    /// every bit, signed zeros included.
    #[test]
    fn in_plane_blocks_are_aligned_and_split_without_loss() {
        assert_eq!(std::mem::size_of::<InPlane>(), 32);
        assert_eq!(std::mem::align_of::<InPlane>(), 32);
        let column = vec![InPlane::default(); 7];
        assert!(column.iter().all(|p| (p as *const InPlane as usize).is_multiple_of(32)));
        let bits = |t: &Tensor3| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut r = bit_test_entries(3, 1e9);
        for _ in 0..1000 {
            let b = Block2 { xx: r(), xy: r(), yx: r(), yy: r(), zz: r() };
            let joined = Block2::from_parts(&b.in_plane(), b.zz);
            assert_eq!(bits(&joined.to_tensor()), bits(&b.to_tensor()));
        }
    }
}
