//! Hypoelastic isotropic material integrated with the Jaumann rate.

use super::{jaumann_update, Constitutive, PointState, StepKinematics, ThermalProperties};
use crate::math::{identity, Real};

/// Isotropic hypoelasticity `τ^∇ = λ tr(d) I + 2 G d` (SPEC §6 with no
/// plastic or thermal strain rate).
#[derive(Clone, Debug, PartialEq)]
pub struct Elastic {
    /// `ρ₀`, kg/m³.
    pub density: Real,
    /// Young's modulus `E`, Pa.
    pub youngs_modulus: Real,
    /// Poisson's ratio `ν`, in (−1, 0.5).
    pub poisson_ratio: Real,
    /// Initial temperature, K (carried, not used by the stress).
    pub room_temperature: Real,
    /// Optional thermal constants, so an elastic body can still conduct heat.
    pub thermal: Option<ThermalProperties>,
}

impl Elastic {
    /// Lamé's first parameter `λ = E ν / ((1 + ν)(1 − 2ν))`.
    pub fn lame_lambda(&self) -> Real {
        let (e, nu) = (self.youngs_modulus, self.poisson_ratio);
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    }
}

impl Constitutive for Elastic {
    #[inline]
    fn update(&self, old: &PointState, k: &StepKinematics) -> PointState {
        let g = self.shear_modulus();
        let rate = identity() * (self.lame_lambda() * k.d.trace()) + k.d * (2.0 * g);
        PointState { tau: jaumann_update(&old.tau, &rate, &k.w, k.dt), ..*old }
    }
    fn density(&self) -> Real {
        self.density
    }
    fn bulk_modulus(&self) -> Real {
        super::isotropic_moduli(self.youngs_modulus, self.poisson_ratio).0
    }
    fn shear_modulus(&self) -> Real {
        super::isotropic_moduli(self.youngs_modulus, self.poisson_ratio).1
    }
    fn initial_temperature(&self) -> Real {
        self.room_temperature
    }
    fn thermal(&self) -> Option<ThermalProperties> {
        self.thermal
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Tensor3;

    fn steel() -> Elastic {
        Elastic { density: 7850.0, youngs_modulus: 200e9, poisson_ratio: 0.3, room_temperature: 293.0, thermal: None }
    }

    #[test]
    fn uniaxial_strain_increment_gives_lambda_plus_2g() {
        let m = steel();
        let mut d = Tensor3::zeros();
        d[(0, 0)] = 1.0;
        let s = m.update(&PointState::at_rest(293.0), &StepKinematics { d, w: Tensor3::zeros(), dt: 1e-6 });
        let expect = (m.lame_lambda() + 2.0 * m.shear_modulus()) * 1e-6;
        assert!((s.tau[(0, 0)] - expect).abs() < 1e-9 * expect);
        assert!((s.tau[(1, 1)] - m.lame_lambda() * 1e-6).abs() < 1e-3);
        // K + 4G/3 == λ + 2G
        let m_p = m.bulk_modulus() + 4.0 * m.shear_modulus() / 3.0;
        assert!((m_p - (m.lame_lambda() + 2.0 * m.shear_modulus())).abs() < 1e-3);
    }
}
