//! Named built-in materials, each citing the table its constants come from.
//!
//! Constants are those of `shared/reference/ren-li-2010.toml` (Ren & Li,
//! Computers and Structures 88 (2010), Table 2, completed by Børvik et al.'s
//! values for the rows the paper does not print).

use super::johnson_cook::{DamageConstants, JohnsonCook, RateForm};
use super::Material;

/// Names accepted by [`builtin`], in a stable order.
pub const NAMES: &[&str] = &["weldox_460e", "weldox_460e_borvik"];

/// The built-in material called `name`, or `None`.
pub fn builtin(name: &str) -> Option<Material> {
    match name {
        "weldox_460e" => Some(Material::JohnsonCook(weldox_460e())),
        "weldox_460e_borvik" => Some(Material::JohnsonCook(weldox_460e_borvik())),
        _ => None,
    }
}

/// Weldox 460 E as \[RL10\] models it: classic (log) Johnson–Cook rate law
/// with `ε̇₀ = 1 s⁻¹`.
///
/// Source: \[RL10\] Table 2 (E, ν, ρ, A, B, n, m, C_p, α, χ, D₁–D₅,
/// `ε̇₀ = 1`). Not printed there and taken from Børvik et al.'s Weldox 460 E
/// set: `C = 0.0114`, `T_m = 1800 K`, `T₀ = 293 K`. Conductivity: \[RL10\]'s
/// Table 2 prints "452 J/(kg K)" in that row (a typo, it is `C_p`); a typical
/// structural-steel value, 50 W/(m K), is used (SPEC §7). Damage coupling off
/// and `θ = 0.5`, as in \[RL10\].
pub fn weldox_460e() -> JohnsonCook {
    JohnsonCook {
        density: 7850.0,
        youngs_modulus: 200.0e9,
        poisson_ratio: 0.3,
        yield_stress: 490.0e6,
        hardening_modulus: 807.0e6,
        hardening_exponent: 0.73,
        rate_sensitivity: 0.0114,
        softening_exponent: 0.94,
        melting_temperature: 1800.0,
        room_temperature: 293.0,
        reference_strain_rate: 1.0,
        rate_form: RateForm::Log,
        specific_heat: 452.0,
        taylor_quinney: 0.9,
        thermal_expansion: 11.2e-6,
        conductivity: 50.0,
        damage: DamageConstants { d1: 0.0705, d2: 1.732, d3: -0.54, d4: -0.015, d5: 0.0 },
        damage_coupling: false,
        theta: JohnsonCook::DEFAULT_THETA,
    }
}

/// Weldox 460 E with Børvik et al.'s modified (power) rate law
/// `τ̄ = g (1 + ε̄̇/ε̇₀)^C`, `ε̇₀ = 5·10⁻⁴ s⁻¹`, `ν = 0.33`, `α = 1.1·10⁻⁵ K⁻¹`;
/// all other constants as [`weldox_460e`].
///
/// Source: the `[material.weldox_460e.borvik_modified]` table of the
/// reference file (Børvik et al.'s fit of this steel, quoted alongside
/// \[RL10\] Table 2). Børvik's coupled damage model would also scale the flow
/// stress by `(1 − D)` and fracture at `D = 0.3`; this set keeps
/// `damage_coupling` off, so that comparing it with [`weldox_460e`] isolates
/// the rate law (SPEC §6: "the validation report shows both"). Switch it on
/// for the coupled model.
pub fn weldox_460e_borvik() -> JohnsonCook {
    JohnsonCook {
        poisson_ratio: 0.33,
        reference_strain_rate: 5.0e-4,
        rate_form: RateForm::Power,
        thermal_expansion: 1.1e-5,
        ..weldox_460e()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Constitutive;

    #[test]
    fn every_name_resolves_and_validates() {
        for name in NAMES {
            match builtin(name) {
                Some(Material::JohnsonCook(m)) => assert_eq!(m.validate(), Ok(()), "{name}"),
                other => panic!("{name}: {other:?}"),
            }
        }
        assert!(builtin("weldox").is_none());
    }

    #[test]
    fn borvik_set_differs_only_in_its_four_constants() {
        let log = weldox_460e();
        let pow = weldox_460e_borvik();
        assert_eq!(pow.rate_form, RateForm::Power);
        assert_eq!(pow.reference_strain_rate, 5.0e-4);
        assert_eq!(pow.poisson_ratio, 0.33);
        assert_eq!(pow.thermal_expansion, 1.1e-5);
        let same = JohnsonCook {
            poisson_ratio: log.poisson_ratio,
            reference_strain_rate: log.reference_strain_rate,
            rate_form: log.rate_form,
            thermal_expansion: log.thermal_expansion,
            ..pow
        };
        assert_eq!(same, log);
    }

    #[test]
    fn weldox_elastic_wave_speed_is_that_of_steel() {
        // SPEC §4: c_L ≈ 5.9 mm/µs in steel.
        let c = Material::JohnsonCook(weldox_460e()).longitudinal_wave_speed();
        assert!((c - 5.86e3).abs() < 0.05e3, "{c}");
    }
}
