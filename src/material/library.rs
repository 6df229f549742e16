//! Named built-in materials, each citing the table its constants come from.
//!
//! Weldox 460 E: the constants of `shared/reference/ren-li-2010.toml` (Ren &
//! Li, Computers and Structures 88 (2010), Table 2, completed by Børvik et
//! al.'s values for the rows the paper does not print). The metals of the
//! Taylor anvil tests (`cases/taylor-*.toml`, [`crate::taylor`]): OFHC
//! copper and 4340 steel of Johnson & Cook (1983), 42CrMo4 of the DynELA
//! Taylor benchmark; each function names its source and what it lacks.

use super::johnson_cook::{DamageConstants, JohnsonCook, RateForm};
use super::Material;

/// Names accepted by [`builtin`], in a stable order.
pub const NAMES: &[&str] = &[
    "weldox_460e",
    "weldox_460e_borvik",
    "weldox_460e_borvik_coupled",
    "weldox_460e_cutoff",
    "weldox_460e_cockcroft_latham",
    "ofhc_copper",
    "steel_4340",
    "steel_42crmo4",
];

/// The built-in material called `name`, or `None`.
pub fn builtin(name: &str) -> Option<Material> {
    match name {
        "weldox_460e" => Some(Material::JohnsonCook(weldox_460e())),
        "weldox_460e_borvik" => Some(Material::JohnsonCook(weldox_460e_borvik())),
        "weldox_460e_borvik_coupled" => Some(Material::JohnsonCook(weldox_460e_borvik_coupled())),
        "weldox_460e_cutoff" => Some(Material::JohnsonCook(weldox_460e_cutoff())),
        "weldox_460e_cockcroft_latham" => Some(Material::JohnsonCook(weldox_460e_cockcroft_latham())),
        "ofhc_copper" => Some(Material::JohnsonCook(ofhc_copper())),
        "steel_4340" => Some(Material::JohnsonCook(steel_4340())),
        "steel_42crmo4" => Some(Material::JohnsonCook(steel_42crmo4())),
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
        damage: DamageConstants {
            d1: 0.0705,
            d2: 1.732,
            d3: -0.54,
            d4: -0.015,
            d5: 0.0,
            cutoff_triaxiality: None,
            cockcroft_latham: None,
        },
        damage_coupling: 0.0,
        damage_equivalent_strain: false,
        theta: JohnsonCook::DEFAULT_THETA,
    }
}

/// Weldox 460 E with Børvik et al.'s modified (power) rate law
/// `τ̄ = g (1 + ε̄̇/ε̇₀)^C`, `ε̇₀ = 5·10⁻⁴ s⁻¹`, `ν = 0.33`, `α = 1.1·10⁻⁵ K⁻¹`;
/// all other constants as [`weldox_460e`].
///
/// Source: the `[material.weldox_460e.borvik_modified]` table of the
/// reference file (Børvik et al.'s fit of this steel, quoted alongside
/// \[RL10\] Table 2). This set keeps `damage_coupling` off, so that
/// comparing it with [`weldox_460e`] isolates the rate law (SPEC §6: "the
/// validation report shows both"); [`weldox_460e_borvik_coupled`] is their
/// coupled model.
pub fn weldox_460e_borvik() -> JohnsonCook {
    JohnsonCook {
        poisson_ratio: 0.33,
        reference_strain_rate: 5.0e-4,
        rate_form: RateForm::Power,
        thermal_expansion: 1.1e-5,
        ..weldox_460e()
    }
}

/// Børvik et al.'s coupled model of Weldox 460 E: [`weldox_460e_borvik`]
/// with the flow stress scaled by `(1 − D_C D)`, `D_C = 0.3`.
///
/// Source: `critical_damage_coupled = 0.3` of the reference file's
/// `[material.weldox_460e.borvik_modified]` table. How it enters is read
/// from Børvik, Hopperstad, Berstad & Langseth's model (Eur. J. Mech.
/// A/Solids 20 (2001) 685–712; quoted from memory, the paper is not in the
/// stored literature): their damage grows at `D_C/ε_f` per unit plastic
/// strain from a threshold `p_d = 0` for this steel and fracture comes when
/// it reaches `D_C`, that is when the Johnson–Cook damage `D` of this crate
/// (`∫ dε̄/ε_f`) reaches 1 — the locus as it stands, with 30 % of the flow
/// stress lost by then. Hardening and damage run, as theirs, over the
/// damage-equivalent strain `r = ∫ (1 − D_C D) dε̄`
/// ([`JohnsonCook::damage_equivalent_strain`]; on a steady path `r` is
/// about 15 % smaller than `ε̄` at fracture, so a point fails at more
/// plastic strain and hardens less on the way; before 2026-11-28 this set
/// ran over `ε̄`). One difference from their model: the fracture criterion
/// is the case's (`critical_damage = 1` of the per-particle damage
/// criterion is theirs: an element erodes at `D_C`).
pub fn weldox_460e_borvik_coupled() -> JohnsonCook {
    JohnsonCook { damage_coupling: 0.3, damage_equivalent_strain: true, ..weldox_460e_borvik() }
}

/// Weldox 460 E as [`weldox_460e`], with the damage locus cut off below
/// the triaxiality `−1/3` (no damage accrues in stronger compression).
///
/// Source of the cut-off: Y. Bao, T. Wierzbicki, "On the cut-off value of
/// negative triaxiality for fracture", Eng. Fract. Mech. 72 (2005)
/// 1049–1069 (upsetting tests: no fracture below `σ* = −1/3`). A material
/// test, not a fit to any impact; every other constant is \[RL10\]'s. See
/// Deviation 14 of [`super::johnson_cook`].
pub fn weldox_460e_cutoff() -> JohnsonCook {
    let mut m = weldox_460e();
    m.damage.cutoff_triaxiality = Some(-1.0 / 3.0);
    m
}

/// \[RL10\]'s Weldox 460 E ([`weldox_460e`]) with Cockcroft and Latham's
/// damage (`johnson_cook` Deviation 15): `dD = ⟨σ₁⟩ dε̄ / W_c`, with `W_c`
/// the work of \[RL10\]'s hardening curve to \[RL10\]'s Johnson–Cook
/// fracture strain in uniaxial tension
/// ([`JohnsonCook::tension_fracture_work`], 1.70 GPa), so that the two
/// loci agree in a tension test. Everything else is [`weldox_460e`]'s.
pub fn weldox_460e_cockcroft_latham() -> JohnsonCook {
    let mut m = weldox_460e();
    m.damage.cockcroft_latham = Some(m.tension_fracture_work());
    m
}

/// Damage constants of a metal whose Johnson–Cook failure constants the
/// source does not give: `D₁ = 10³⁰`, the others 0, so the failure strain is
/// 10³⁰ and the damage stays at 0 (it is only an output here: the Taylor
/// cases grow no cracks). Not a fit of anything.
pub const NO_DAMAGE: DamageConstants = DamageConstants {
    d1: 1.0e30,
    d2: 0.0,
    d3: 0.0,
    d4: 0.0,
    d5: 0.0,
    cutoff_triaxiality: None,
    cockcroft_latham: None,
};

/// OFHC copper, Johnson & Cook's 1983 set (the material of their cylinder
/// impact tests, the Taylor cases `taylor-cu-*`).
///
/// Source: G. R. Johnson, W. H. Cook, "A constitutive model and data for
/// metals subjected to large strains, high strain rates and high
/// temperatures", Proc. 7th Int. Symp. Ballistics, The Hague (1983)
/// 541–547, as transcribed with `E = 124 GPa`, `ν = 0.34`, `ρ = 8960 kg/m³`,
/// `C_p = 383 J/(kg K)` in public simulation inputs that cite it
/// (`molanocortes/OpenPhysicsAI`, `src/lab/impact/impact_materials.c`,
/// checked there against LANL LA-UR-22-29965): `A = 90 MPa`, `B = 292 MPa`,
/// `n = 0.31`, `C = 0.025`, `m = 1.09`, `T_m = 1356 K`, `ε̇₀ = 1 s⁻¹`,
/// room temperature 294 K. Not in the source, and chosen here: `χ = 0.9`
/// (the usual Taylor–Quinney value), no thermal expansion and no
/// conductivity (the Taylor references are adiabatic computations), no
/// damage ([`NO_DAMAGE`]).
pub fn ofhc_copper() -> JohnsonCook {
    JohnsonCook {
        density: 8960.0,
        youngs_modulus: 124.0e9,
        poisson_ratio: 0.34,
        yield_stress: 90.0e6,
        hardening_modulus: 292.0e6,
        hardening_exponent: 0.31,
        rate_sensitivity: 0.025,
        softening_exponent: 1.09,
        melting_temperature: 1356.0,
        room_temperature: 294.0,
        reference_strain_rate: 1.0,
        rate_form: RateForm::Log,
        specific_heat: 383.0,
        taylor_quinney: 0.9,
        thermal_expansion: 0.0,
        conductivity: 0.0,
        damage: NO_DAMAGE,
        damage_coupling: 0.0,
        damage_equivalent_strain: false,
        theta: JohnsonCook::DEFAULT_THETA,
    }
}

/// 4340 steel, Johnson & Cook's 1983 set (the Taylor cases `taylor-4340-*`).
///
/// Source: Johnson & Cook (1983) (see [`ofhc_copper`]) as tabulated with
/// its elastic and thermal constants in a public material table citing it
/// (stored file id 62562932481, "Johnson & Cook (1983) 7th Int. Symp.
/// Ballistics"; the same `A, B, n, C, m, T_m` appear, divided by √3, in
/// `ijd2104/ShearBands`): `A = 792 MPa`, `B = 510 MPa`, `n = 0.26`,
/// `C = 0.014`, `m = 1.03`, `T_m = 1793 K`, `ρ = 7830 kg/m³`, `E = 207 GPa`,
/// `ν = 0.29`, `C_p = 477 J/(kg K)`, `ε̇₀ = 1 s⁻¹`. Chosen here as for
/// [`ofhc_copper`]: `χ = 0.9`, no thermal expansion, no conductivity, no
/// damage; room temperature 295 K (the tests').
pub fn steel_4340() -> JohnsonCook {
    JohnsonCook {
        density: 7830.0,
        youngs_modulus: 207.0e9,
        poisson_ratio: 0.29,
        yield_stress: 792.0e6,
        hardening_modulus: 510.0e6,
        hardening_exponent: 0.26,
        rate_sensitivity: 0.014,
        softening_exponent: 1.03,
        melting_temperature: 1793.0,
        room_temperature: 295.0,
        specific_heat: 477.0,
        ..ofhc_copper()
    }
}

/// 42CrMo4 steel of the DynELA Taylor benchmark (`taylor-42crmo4-287`).
///
/// Source: O. Pantalé, DynELA v.4.0 documentation,
/// `Documentation/Samples-Impacts.tex` (`pantale/DynELA-v.-4.0`), the
/// material table of its Taylor impact: `E = 206.9 GPa`, `ν = 0.3`,
/// `ρ = 7830 kg/m³`, `A = 806 MPa`, `B = 614 MPa`, `n = 0.168`,
/// `C = 0.0089`, `m = 1.1`, `ε̇₀ = 1 s⁻¹`, `T₀ = 20 °C`, `T_m = 1540 °C`,
/// `C_p = 460 J/(kg K)`, conductivity 34 W/(m K), Taylor–Quinney 0.9. Not
/// given there: thermal expansion (none here) and damage ([`NO_DAMAGE`]).
pub fn steel_42crmo4() -> JohnsonCook {
    JohnsonCook {
        density: 7830.0,
        youngs_modulus: 206.9e9,
        poisson_ratio: 0.3,
        yield_stress: 806.0e6,
        hardening_modulus: 614.0e6,
        hardening_exponent: 0.168,
        rate_sensitivity: 0.0089,
        softening_exponent: 1.1,
        melting_temperature: 1540.0 + 273.15,
        room_temperature: 20.0 + 273.15,
        specific_heat: 460.0,
        conductivity: 34.0,
        ..ofhc_copper()
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
