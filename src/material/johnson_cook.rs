//! Johnson–Cook thermo-viscoplasticity with Johnson–Cook damage, integrated
//! by the Peirce–Shih–Needleman tangent-modulus method (SPEC §6,
//! [RL10, Eqs. (2.46)–(2.72), (5.1)–(5.2)]).
//!
//! The model is a set of small pure functions — flow stress [`JohnsonCook::flow_stress`]
//! and its slopes, the inverse rate law [`JohnsonCook::plastic_rate`], the
//! tangent modulus [`JohnsonCook::tangent_modulus`], the failure strain
//! [`JohnsonCook::failure_strain`] — assembled by the [`Constitutive::update`]
//! of [`JohnsonCook`]. Each is testable on its own.
//!
//! Stress is Kirchhoff `τ = J σ` throughout (SPEC §2); `τ̄ = sqrt(3/2 s:s)`.
//!
//! Equation numbers: SPEC §6 restates \[RL10\] Eqs. (2.46)–(2.72) and names
//! (2.70) (the tangent modulus `H`) and (2.72) (the objective stress rate)
//! explicitly; the functions below cite the block where the individual
//! number is not given in SPEC.
//!
//! # Deviations
//!
//! Every regularisation of SPEC §6's formulas, each with the test that pins it
//! (tests in this module unless a path is given):
//!
//! 1. **`ε̄ⁿ⁻¹` at `ε̄ = 0`, `n < 1`.** The hardening slope `g_ε` is evaluated at
//!    `max(ε̄, PLASTIC_STRAIN_FLOOR)` ([`PLASTIC_STRAIN_FLOOR`] = 1e-6, three
//!    orders below the yield strain of any metal); `g` itself is exact. With
//!    the exact slope, `H = ∞` at the virgin state and the tangent update would
//!    keep `ε̄ = 0` forever. Tests: `hardening_slope_is_finite_at_zero_plastic_strain`,
//!    `plastic_flow_starts_from_the_virgin_state`.
//! 2. **`T*ᵐ⁻¹` at `T* = 0`, `m < 1`.** The softening slope `g_T` is evaluated at
//!    `max(T*, HOMOLOGOUS_TEMPERATURE_FLOOR)` (1e-6, micro-kelvins above room
//!    temperature); `g` is exact. Test: `thermal_slope_is_finite_at_room_temperature`.
//! 3. **`T* < 0`** (below room temperature, e.g. after conduction undershoot):
//!    `T*` is clamped to 0 in `g`, `g_T` (= 0 there) and `ε_f`, i.e. no extra
//!    strength below the reference temperature (the convention of Abaqus'
//!    Johnson–Cook model); `T*ᵐ` of a negative number would be NaN.
//!    Test: `below_room_temperature_gives_room_temperature_strength`.
//! 4. **`T* ≥ 1` (melted) or no strength left** (`g ≤ MIN_FLOW_STRESS_RATIO · G`,
//!    which also covers `D → 1` with damage coupling): the point carries no
//!    deviatoric stress. The deviator is dropped, the mean stress follows
//!    `K tr d`, all deviatoric deformation counts as plastic
//!    (`ε̄̇ = sqrt(2/3 d′:d′)`), and neither temperature nor damage change
//!    (no plastic work is done at zero stress; `σ*` is undefined at `τ̄ = 0`).
//!    Tests: `melted_point_has_no_deviatoric_strength`,
//!    `tests/material.rs::melted_point_flows_like_a_fluid_through_the_driver`.
//! 5. **Exponent cap and overstress fallback.** The rate-law exponent
//!    (`(τ̄/g − 1)/C`, or `ln(τ̄/g)/C` for the power law) is capped at
//!    [`MAX_RATE_EXPONENT`] = 50, i.e. rates above `ε̇₀ e⁵⁰` (≥ 2.6·10¹⁸ s⁻¹
//!    for any `ε̇₀` in use) are treated as instantaneous; `∂ε̄̇/∂τ̄` is that of
//!    the law at the capped rate, so the tangent update keeps its implicit
//!    damping. If the tangent update would still end the step above the
//!    range the capped law represents, `τ̄ > τ̄_cap = g(1 + 50C)` (`g e^{50C}`
//!    for the power law) — a huge overstress after a sudden loss of strength,
//!    which the linearised update would relax only by `~2Cg` per step — the
//!    step is redone as a backward-Euler radial return of the elastic
//!    predictor onto the rate law (`τ̄ = g·R(Δε̄/Δt)` with `g` at the
//!    end-of-step `ε̄`, temperature and damage frozen, solved by bisection;
//!    damage with the end-of-step triaxiality). Its heating uses the mean of
//!    the start and end `τ̄`, the elastic energy the return releases (the
//!    start-of-step `τ̄` would count up to twice that). Tests:
//!    `huge_overstress_is_finite_and_relaxes_monotonically`,
//!    `radial_return_from_rest_accumulates_ordinary_damage`.
//! 6. **`H ≤ 0`** (adiabatic softening beyond the elastic stiffness, a
//!    snap-back): `ξ` is formed with `max(H, 0)`, so the softening part of the
//!    linearisation is explicit and `1 + ξ ≥ 1`. The update is written in the
//!    equivalent form `ε̄̇_θ = (ε̄̇ + θΔt f_τ P:d)/(1 + ξ)`, which needs no
//!    division by `H`. Test: `update_is_well_defined_when_tangent_modulus_is_negative`.
//! 7. **Bounds on `ε̄̇_θ`.** The linearised rate is clamped to
//!    `0 ≤ ε̄̇_θ ≤ (τ̄ + Δt P:d)/(3GΔt)`: plastic strain never decreases (the
//!    linearisation goes negative on fast unloading), and the flow in one step
//!    can at most relax the stress component along the flow direction to zero
//!    (never reverse it; with `H ≤ 0` the linearised rate is unbounded).
//!    Neither bound is active in a resolved step. Tests:
//!    `plastic_strain_never_decreases_on_unloading`,
//!    `update_is_well_defined_when_tangent_modulus_is_negative`.
//! 8. **Power law elastic/plastic switch.** Below `τ̄ = g` the power law has
//!    no flow: a step that starts below `g` and whose elastic predictor stays
//!    below is exactly elastic; one whose predictor crosses `g` is split at the
//!    crossing (found exactly: `τ̄²` is quadratic along the explicit elastic
//!    path) and the tangent update, with `f_τ = ε̇₀/(C g)` (the law's
//!    right derivative at the threshold), runs over the remainder. Tests:
//!    `power_law_is_elastic_below_flow_stress`,
//!    `power_law_step_crossing_yield_matches_fine_steps`.
//! 9. **Failure-strain floor.** `ε_f` is floored at [`MIN_FAILURE_STRAIN`]
//!    (1e-6): outside the fitted range (e.g. `1 + D₄ ln ε̇* ≤ 0` at absurd
//!    rates, or `D₁ < 0` with high triaxiality) the formula can go to zero or
//!    negative, which would make `D` decrease; the floor fails the point at
//!    once instead. Test: `failure_strain_stays_positive_beyond_fitted_range`.
//! 10. **No flow direction at `τ̄ = 0`.** `n̂ = 3s/(2τ̄)` is undefined at a
//!     zero deviator (the log law still gives a vanishing rate
//!     `ε̇₀ e^{-1/C}` there). A step from it with `d′ ≠ 0` falls under
//!     Deviation 11 (radial return along the elastic predictor); with `d′ = 0`
//!     it is purely volumetric and elastic. Test: `first_step_from_rest_is_elastic`.
//! 11. **Unresolved flow direction.** The tangent update flows along the
//!     start-of-step direction `n̂`. Where the step's deviatoric elastic
//!     increment exceeds the stress itself, `3GΔt sqrt(2/3 d′:d′) > τ̄`, that
//!     direction is not resolved: a linear analysis of the update gives a
//!     direction error amplified by `1 − 3GΔt ε̇/τ̄` per step, an oscillation
//!     once the ratio passes 1 and an instability past 2. This happens in
//!     shear bands at ≳ 10⁷ s⁻¹ with \[RL10\]'s `Δt = 4·10⁻⁹ s`, and near
//!     melting at any rate. Such a step is the backward-Euler radial return
//!     of Deviation 5, which flows along the elastic predictor and is stable
//!     for any step. In resolved steps (`3GΔt ε̇ ≪ τ̄`) it is never used
//!     except on the first step from rest. Tests:
//!     `tests/material.rs::simple_shear_at_1e7_with_the_paper_step_is_smooth`,
//!     `tests/material.rs::adiabatic_softening_runs_up_to_melting`.
//!
//! The damage factor `(1 − D_C D)` (Børvik's coupling, `damage_coupling` =
//! `D_C`; SPEC §6 writes the switch `damage_coupling = true`, which reads as
//! `D_C = 1`, the plain `(1 − D)`) is clamped to `[0, 1]` and held fixed
//! over a step (not linearised in `H`). `D` itself is
//! not capped at 1: `D ≥ 1` means failed. With Børvik's damage-equivalent
//! strain (`damage_equivalent_strain`; Børvik, Hopperstad, Berstad &
//! Langseth 2001, as recalled in `docs/validation.md`) hardening and
//! damage run on `r`, `dr = (1 − D_C D) dε̄`: `eps_p` holds `r`, each
//! step's increments of `r` and `D` are those over `ε̄` times the factor
//! at the start of the step, the radial return hardens over `r`, and
//! `g_ε` is per unit of `ε̄` (`∂g/∂r (1 − D_C D)`, which enters `H`); the
//! rate law and the heating stay on `ε̄̇`. Deviation from SPEC §6, which
//! knows `ε̄` only; off by default, the same bits then. Test:
//! `tests/material.rs::borvik_coupled_simple_shear_at_1e4_matches_reference_ode`
//! (the reference ODE integrates `r`). The heating and the thermal
//! expansion term use the start-of-step `τ̄`, as SPEC §6 writes (except in
//! the fallback of Deviation 5).
//! 12. **Negligible flow.** Before any flow update, the viscoplastic rate
//!     is evaluated at the elastic trial stress of the step; it bounds the
//!     step's rate from above (the rate grows with `τ̄`, and flow only relaxes
//!     the trial). If that bound would relax the trial stress by less than
//!     [`NEGLIGIBLE_RELAXATION`] of itself (`3GΔt ε̄̇(τ̄_tr) ≤ 1e-8 τ̄_tr`,
//!     with `τ̄_tr` floored at [`NEGLIGIBLE_STRESS_RATIO`]` · g`), the
//!     step is elastic to that tolerance: the trial stress is kept and the
//!     bound's tiny plastic strain, heat and damage are booked. For Weldox
//!     at `Δt = 4·10⁻⁸ s` this covers every point below ~91 % of `g`, which
//!     would otherwise often take the (iterative, costly) radial return of
//!     Deviation 11 while the stress is still small. Test:
//!     `negligible_flow_fast_path_agrees_with_the_full_update`.
//! 13. **Negligible creep (log law).** Where even the rate bound of
//!     Deviation 12 is below `ε̇₀ e⁻⁵⁰` (≈ 2·10⁻²² s⁻¹ for Weldox), it is not
//!     booked: the step keeps Deviation 12's elastic trial stress (the same
//!     bits) and leaves `ε̄`, `T`, `D` unchanged, with `ε̄̇ = 0`. The test
//!     needs no power or exponential: `g` is bounded from below by
//!     `A (1 − t̂)(1 − D)` with `t̂ ≥ T*ᵐ` taken from the binary exponent of
//!     `T*`. For Weldox this is every point below ~43 % of `A(1 − T*ᵐ)` —
//!     some 60 % of all updates in Case I, which no longer evaluate three
//!     transcendental functions. What is dropped is below
//!     `Δt ε̇₀ e⁻⁵⁰ ≤ 10⁻¹⁸` of plastic strain per step (≈ 10⁻²⁶ over a whole
//!     impact), far below any effect on `g`. Tests:
//!     `negligible_creep_fast_path_agrees_with_the_full_update`,
//!     `power_upper_bound_is_a_bound`.
//! 14. **Cut-off triaxiality (optional, beyond \[RL10\]).** With
//!     `damage.cutoff_triaxiality = σ*_c` no damage accrues where
//!     `σ* < σ*_c`: `ε_f = ∞` there. Bao & Wierzbicki (Eng. Fract. Mech. 72
//!     (2005) 1049–1069) found from upsetting tests that ductile metals do
//!     not fracture below `σ* = −1/3` (uniaxial compression), whatever the
//!     strain; the Johnson–Cook exponential, fitted on tension tests, keeps
//!     a finite `ε_f` there (Weldox 460 E: 2.1 at −1/3, 2.7 at −0.8), so
//!     the material under a projectile's face accrues damage that no test
//!     supports. The built-in `weldox_460e_cutoff` is \[RL10\]'s Weldox with
//!     `σ*_c = −1/3`; without the field (every other material) the locus is
//!     \[RL10\]'s. A triaxiality of exactly `σ*_c` still accrues damage. The
//!     cut-off is a property of the locus, so it carries to 3D unchanged
//!     (`σ*` is the same invariant there). Tests:
//!     `the_cut_off_stops_damage_below_it_only`,
//!     `tests/material.rs::upsetting_accrues_no_damage_below_the_cut_off`.
//! 15. **Cockcroft–Latham damage (beyond \[RL10\]; the plate's damage in
//!     the built-in default-model cases since 2026-11-30, `crate::fracture`,
//!     "The default model's tip and damage").** With
//!     `damage.cockcroft_latham = W_c` the damage grows as
//!     `dD = ⟨σ₁⟩ dε̄ / W_c` (Cockcroft & Latham, J. Inst. Metals 96 (1968)
//!     33), `σ₁` the largest principal stress (of `τ`: `J ≈ 1` in plastic
//!     flow), instead of `dε̄/ε_f(σ*)`; a crack still forms where the
//!     fracture criterion reads `D` (per particle or averaged). Why: the
//!     Johnson–Cook locus depends on the triaxiality alone, so the material
//!     under a blunt projectile's rim, sheared under pressure, accrues damage
//!     at `1/ε_f ≈ 0.4–0.5` per unit strain, where no test supports it
//!     (Deviation 14 cuts it off at `σ* = −1/3` by a switch). Cockcroft and
//!     Latham's integrand depends on the Lode parameter as well as on `σ*`:
//!     in generalized shear `σ₁ = σ̄ (σ* + 1/√3)`, so shear fractures at
//!     `√3` times the tensile work and no damage accrues below `σ* = −1/√3`
//!     (in axisymmetric compression below `−1/3`): a continuous cut-off
//!     instead of a switch, and a locus that rises with the flow stress's
//!     fall in a hot band. One constant, fixed by a tension test: the
//!     built-in `weldox_460e_cockcroft_latham` takes `W_c` as the work of
//!     \[RL10\]'s hardening curve up to \[RL10\]'s Johnson–Cook fracture
//!     strain in uniaxial tension, quasi-static and at room temperature
//!     ([`JohnsonCook::tension_fracture_work`]), so the two loci agree
//!     there and differ elsewhere; nothing is taken from a ballistic test.
//!     `σ₁` and `ε̄` are 3D invariants, so it carries to 3D unchanged
//!     ([`crate::math::largest_principal`] has the 3×3 form). Tests:
//!     `tests/material.rs::cockcroft_latham_simple_shear_matches_reference_ode`,
//!     `cockcroft_latham_tension_fails_at_the_johnson_cook_strain`,
//!     `cockcroft_latham_accrues_no_damage_in_compression`,
//!     `tension_fracture_work_is_the_area_under_the_hardening_curve`.

use super::{jaumann_update, Constitutive, PointState, StepKinematics, ThermalProperties};
use crate::math::{
    ddot, deviator, identity, largest_principal, mean_stress, von_mises, von_mises_2d, Block2, Real, Tensor3,
};

/// Floor on `ε̄` where the hardening slope `g_ε = B n ε̄ⁿ⁻¹ …` is evaluated
/// (Deviation 1). 1e-6 is three orders below a metal's yield strain, so it
/// only matters in the first plastic step.
pub const PLASTIC_STRAIN_FLOOR: Real = 1e-6;

/// Floor on `T*` where the softening slope `g_T ∝ T*ᵐ⁻¹` is evaluated
/// (Deviation 2): 1e-6 is 1.5 mK above room temperature for steel.
pub const HOMOLOGOUS_TEMPERATURE_FLOOR: Real = 1e-6;

/// Cap on the rate-law exponent (Deviation 5): `ε̄̇ ≤ ε̇₀ e⁵⁰ ≈ 5·10²¹ ε̇₀`,
/// physically instantaneous, far from `f64` overflow (`e⁷⁰⁹`) even after the
/// products the tangent update forms.
pub const MAX_RATE_EXPONENT: Real = 50.0;

/// A point whose flow stress is below this fraction of the shear modulus is
/// treated as strengthless (Deviation 4). 1e-9 G ≈ 80 Pa for steel; keeps
/// `∂ε̄̇/∂τ̄ ∝ 1/g` finite.
pub const MIN_FLOW_STRESS_RATIO: Real = 1e-9;

/// Largest relative relaxation of the elastic trial stress that a step may
/// neglect (Deviation 12): far below the 1 % accuracy the driver tests ask
/// and below the round-off growth of an explicit run.
pub const NEGLIGIBLE_RELAXATION: Real = 1e-8;

/// Stress scale below which relaxation is measured against `1e-6 g`
/// rather than `τ̄` itself (Deviation 12): the neglected stress change is
/// then at most `1e-14 g`, about 5 µPa for Weldox.
pub const NEGLIGIBLE_STRESS_RATIO: Real = 1e-6;

/// Log-law exponent below which creep is not booked (Deviation 13): at
/// `(τ̄/g − 1)/C ≤ −50` the rate is below `ε̇₀ e⁻⁵⁰ ≈ 2·10⁻²² ε̇₀`.
pub const NEGLIGIBLE_CREEP_EXPONENT: Real = -MAX_RATE_EXPONENT;

/// Largest plastic strain per step that Deviation 13 may leave unbooked
/// (the same bound below which Deviation 12 skips the damage increment).
pub const NEGLIGIBLE_CREEP_STRAIN: Real = 1e-18;

/// Floor on the Johnson–Cook failure strain (Deviation 9).
pub const MIN_FAILURE_STRAIN: Real = 1e-6;

/// Which strain-rate law multiplies the flow stress (SPEC §6, "Two rate laws").
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RateForm {
    /// Classic Johnson–Cook, `τ̄ = g (1 + C ln(ε̄̇/ε̇₀))`, the form of \[RL10\]
    /// (with `ε̇₀ = 1 s⁻¹`). Flows (vanishingly slowly) at any stress.
    Log,
    /// Børvik's modified law `τ̄ = g (1 + ε̄̇/ε̇₀)^C` (Børvik used
    /// `ε̇₀ = 5·10⁻⁴ s⁻¹`). No flow below `τ̄ = g`.
    Power,
}

/// Johnson–Cook failure-strain constants `D₁ … D₅` ([RL10, Eqs. (5.1)–(5.2)]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DamageConstants {
    /// `D₁`, dimensionless.
    pub d1: Real,
    /// `D₂`, dimensionless.
    pub d2: Real,
    /// `D₃`, dimensionless (multiplies the triaxiality).
    pub d3: Real,
    /// `D₄`, dimensionless (rate term).
    pub d4: Real,
    /// `D₅`, dimensionless (temperature term).
    pub d5: Real,
    /// Cut-off triaxiality `σ*_c` (≤ 0): below it no damage accrues
    /// (`ε_f = ∞`; Deviation 14). `None` (the default, and \[RL10\]'s
    /// locus): the formula at every triaxiality.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_triaxiality: Option<Real>,
    /// Cockcroft–Latham critical plastic work `W_c`, Pa (Deviation 15):
    /// where given, the damage grows as `dD = ⟨σ₁⟩ dε̄ / W_c` instead of
    /// `dε̄/ε_f`, and `D₁ … D₅` are not used. `None` (the default, and
    /// \[RL10\]'s): the Johnson–Cook locus.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cockcroft_latham: Option<Real>,
}

/// Johnson–Cook thermo-viscoplastic material with isotropic hypoelasticity
/// (SPEC §6). All fields SI.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JohnsonCook {
    /// Reference mass density `ρ₀`, kg/m³.
    pub density: Real,
    /// Young's modulus `E`, Pa.
    pub youngs_modulus: Real,
    /// Poisson's ratio `ν`, in (−1, 0.5).
    pub poisson_ratio: Real,
    /// Yield stress `A`, Pa.
    pub yield_stress: Real,
    /// Hardening modulus `B`, Pa.
    pub hardening_modulus: Real,
    /// Hardening exponent `n`, dimensionless (> 0).
    pub hardening_exponent: Real,
    /// Rate sensitivity `C`, dimensionless (> 0).
    pub rate_sensitivity: Real,
    /// Thermal-softening exponent `m`, dimensionless (> 0).
    pub softening_exponent: Real,
    /// Melting temperature `T_m`, K.
    pub melting_temperature: Real,
    /// Room (reference) temperature `T₀`, K; also the initial temperature.
    pub room_temperature: Real,
    /// Reference strain rate `ε̇₀`, 1/s.
    pub reference_strain_rate: Real,
    /// Which rate law (log or power).
    #[serde(default = "default_rate_form")]
    pub rate_form: RateForm,
    /// Specific heat `C_p`, J/(kg K).
    pub specific_heat: Real,
    /// Taylor–Quinney coefficient `χ`, fraction of plastic work turned into
    /// heat, in [0, 1]. `χ = 0` makes the model isothermal.
    #[serde(default = "default_taylor_quinney")]
    pub taylor_quinney: Real,
    /// Linear thermal expansion coefficient `α`, 1/K.
    pub thermal_expansion: Real,
    /// Thermal conductivity `κ`, W/(m K) (used by heat conduction, SPEC §7).
    pub conductivity: Real,
    /// Johnson–Cook damage constants.
    pub damage: DamageConstants,
    /// Børvik's critical damage `D_C` in [0, 1]: the flow stress is scaled
    /// by `(1 − D_C D)`, `D` the Johnson–Cook damage (fracture at `D = 1`).
    /// Børvik et al.'s damage variable is `D_C D`, which grows at
    /// `D_C/ε_f` per unit plastic strain and reaches `D_C` as the locus is
    /// used up, so their Weldox 460 E (`D_C = 0.3`) loses 30 % of its flow
    /// stress at fracture. `1` is the plain `(1 − D)`; `0` (the default)
    /// uncouples, as in \[RL10\], where cracks, not softening, carry the
    /// failure. A case file may also write `true` / `false` for 1 / 0.
    #[serde(default, deserialize_with = "coupling_from_case")]
    pub damage_coupling: Real,
    /// Børvik et al.'s damage-equivalent plastic strain `r`, with
    /// `dr = (1 − D_C D) dε̄`: hardening and damage accumulate over `r`
    /// instead of `ε̄` (`g = (A + B rⁿ)…(1 − D_C D)`, `dD = dr/ε_f`), and
    /// the point's `eps_p` holds `r` (module doc, "The damage factor").
    /// Needs `damage_coupling > 0`. Default false.
    #[serde(default)]
    pub damage_equivalent_strain: bool,
    /// Tangent-method parameter `θ` in [0, 1]; see [`JohnsonCook::DEFAULT_THETA`].
    #[serde(default = "default_theta")]
    pub theta: Real,
}

/// The flow stress `g` and its partial derivatives at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowStress {
    /// `g(ε̄, T)`, Pa (times `(1 − D)` with damage coupling).
    pub g: Real,
    /// `∂g/∂ε̄`, Pa (regularised at `ε̄ = 0`, Deviation 1).
    pub g_eps: Real,
    /// `∂g/∂T`, Pa/K (regularised at `T* = 0`, Deviation 2).
    pub g_temp: Real,
}

/// The plastic strain rate given by the inverse rate law and its derivative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlasticRate {
    /// `ε̄̇ = φ(τ̄, g)`, 1/s.
    pub rate: Real,
    /// `f_τ = ∂ε̄̇/∂τ̄`, 1/(Pa s).
    pub d_rate_d_tau: Real,
}

/// The factors of the flow stress at one state (see
/// [`JohnsonCook::flow_stress`]): `g = (A + B ε̄ⁿ) · thermal · dmg`.
#[derive(Clone, Copy, Debug)]
struct FlowFactors {
    /// `max(ε̄, 0)`.
    eps: Real,
    /// `ε̄ⁿ`.
    eps_n: Real,
    /// `A + B ε̄ⁿ`, Pa.
    strain_part: Real,
    /// `1 − T*ᵐ` (Deviation 3).
    thermal: Real,
    /// `1 − D` with damage coupling, else 1.
    dmg: Real,
}

impl FlowFactors {
    #[inline]
    fn g(&self) -> Real {
        self.strain_part * self.thermal * self.dmg
    }
}

/// A parameter outside its admissible range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("Johnson-Cook parameter `{parameter}` = {value} must be {requirement}")]
pub struct ParameterError {
    /// Field name.
    pub parameter: &'static str,
    /// Its value.
    pub value: Real,
    /// The admissible range, in words.
    pub requirement: &'static str,
}

fn default_taylor_quinney() -> Real {
    0.9
}
/// `damage_coupling` from a case file: a number (`D_C`), or `true` /
/// `false` for 1 / 0 (the switch of the plain `(1 − D)` it was before).
fn coupling_from_case<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<Real, D::Error> {
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum Coupling {
        Switch(bool),
        Critical(Real),
    }
    Ok(match <Coupling as serde::Deserialize>::deserialize(deserializer)? {
        Coupling::Switch(on) => Real::from(u8::from(on)),
        Coupling::Critical(d_c) => d_c,
    })
}
fn default_theta() -> Real {
    JohnsonCook::DEFAULT_THETA
}
fn default_rate_form() -> RateForm {
    RateForm::Log
}

impl JohnsonCook {
    /// Default tangent parameter `θ = 0.5`: the midpoint rule, second-order
    /// accurate in a resolved step, and the choice of Peirce, Shih &
    /// Needleman (SPEC §6).
    pub const DEFAULT_THETA: Real = 0.5;

    /// Check every parameter; returns all problems at once.
    pub fn validate(&self) -> Result<(), Vec<ParameterError>> {
        let mut errors = Vec::new();
        let mut check = |parameter: &'static str, value: Real, ok: bool, requirement: &'static str| {
            if !(ok && value.is_finite()) {
                errors.push(ParameterError { parameter, value, requirement });
            }
        };
        check("density", self.density, self.density > 0.0, "> 0");
        check("youngs_modulus", self.youngs_modulus, self.youngs_modulus > 0.0, "> 0");
        let nu = self.poisson_ratio;
        check("poisson_ratio", nu, nu > -1.0 && nu < 0.5, "in (-1, 0.5)");
        check("yield_stress", self.yield_stress, self.yield_stress >= 0.0, ">= 0");
        check("hardening_modulus", self.hardening_modulus, self.hardening_modulus >= 0.0, ">= 0");
        check("hardening_exponent", self.hardening_exponent, self.hardening_exponent > 0.0, "> 0");
        check("rate_sensitivity", self.rate_sensitivity, self.rate_sensitivity > 0.0, "> 0");
        check("softening_exponent", self.softening_exponent, self.softening_exponent > 0.0, "> 0");
        check("room_temperature", self.room_temperature, self.room_temperature >= 0.0, ">= 0");
        check(
            "melting_temperature",
            self.melting_temperature,
            self.melting_temperature > self.room_temperature,
            "> room_temperature",
        );
        check("reference_strain_rate", self.reference_strain_rate, self.reference_strain_rate > 0.0, "> 0");
        check("specific_heat", self.specific_heat, self.specific_heat > 0.0, "> 0");
        let chi = self.taylor_quinney;
        check("taylor_quinney", chi, (0.0..=1.0).contains(&chi), "in [0, 1]");
        check("thermal_expansion", self.thermal_expansion, true, "finite");
        check("conductivity", self.conductivity, self.conductivity >= 0.0, ">= 0");
        let dc = &self.damage;
        let constants = [
            ("damage.d1", dc.d1),
            ("damage.d2", dc.d2),
            ("damage.d3", dc.d3),
            ("damage.d4", dc.d4),
            ("damage.d5", dc.d5),
        ];
        for (name, v) in constants {
            check(name, v, true, "finite");
        }
        if let Some(c) = dc.cutoff_triaxiality {
            check("damage.cutoff_triaxiality", c, c <= 0.0, "<= 0 (no damage below it)");
            if dc.cockcroft_latham.is_some() {
                check(
                    "damage.cutoff_triaxiality",
                    c,
                    false,
                    "not with damage.cockcroft_latham (its <σ1> is the cut-off)",
                );
            }
        }
        if let Some(w) = dc.cockcroft_latham {
            check("damage.cockcroft_latham", w, w > 0.0, "> 0 (Pa)");
        }
        let d_c = self.damage_coupling;
        check("damage_coupling", d_c, (0.0..=1.0).contains(&d_c), "in [0, 1] (Børvik's critical damage D_C)");
        let with_coupling = !self.damage_equivalent_strain || d_c > 0.0;
        check(
            "damage_equivalent_strain",
            d_c,
            with_coupling,
            "false while damage_coupling is 0 (the value shown is damage_coupling)",
        );
        check("theta", self.theta, (0.0..=1.0).contains(&self.theta), "in [0, 1]");
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }

    /// Lamé's first parameter `λ = K − 2G/3`, Pa.
    pub fn lame_lambda(&self) -> Real {
        self.bulk_modulus() - 2.0 * self.shear_modulus() / 3.0
    }

    /// Homologous temperature `T* = (T − T₀)/(T_m − T₀)`, unclamped
    /// (SPEC §6).
    pub fn homologous_temperature(&self, temperature: Real) -> Real {
        (temperature - self.room_temperature) / (self.melting_temperature - self.room_temperature)
    }

    /// Thermal factor `1 − T*ᵐ` with `T*` clamped to [0, 1] (Deviation 3;
    /// 0 when melted). SPEC §6, [RL10, Eqs. (2.46)–(2.72)].
    pub fn thermal_factor(&self, temperature: Real) -> Real {
        let t_star = self.homologous_temperature(temperature);
        if t_star <= 0.0 {
            1.0
        } else if t_star >= 1.0 {
            0.0
        } else {
            1.0 - t_star.powf(self.softening_exponent)
        }
    }

    /// The damage factor `(1 − D_C D)` clamped to [0, 1] (`D_C` the
    /// [`JohnsonCook::damage_coupling`]; 1 when uncoupled).
    pub fn damage_factor(&self, damage: Real) -> Real {
        if self.damage_coupling > 0.0 {
            (1.0 - self.damage_coupling * damage).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// `dr/dε̄` of the hardening and damage variable at damage factor
    /// `dmg` ([`JohnsonCook::damage_factor`]): `dmg` with Børvik's
    /// damage-equivalent strain ([`JohnsonCook::damage_equivalent_strain`]),
    /// else 1 (the variable is `ε̄`).
    pub fn strain_scale(&self, dmg: Real) -> Real {
        if self.damage_equivalent_strain {
            dmg
        } else {
            1.0
        }
    }

    /// Johnson–Cook flow stress at the reference rate,
    /// `g = (A + B ε̄ⁿ)(1 − T*ᵐ)` (× `(1 − D)` with damage coupling), Pa.
    /// SPEC §6, [RL10, Eqs. (2.46)–(2.72)].
    pub fn flow_stress(&self, eps_p: Real, temperature: Real, damage: Real) -> Real {
        self.flow_factors(eps_p, temperature, damage).g()
    }

    /// `g` with its partial derivatives
    /// `g_ε = B n ε̄ⁿ⁻¹ (1 − T*ᵐ)` and
    /// `g_T = −m T*ᵐ⁻¹ g / ((1 − T*ᵐ)(T_m − T₀)) = −m T*ᵐ⁻¹ (A + B ε̄ⁿ)/(T_m − T₀)`
    /// (the second form has no `0/0` at melting), both × `(1 − D)` with damage
    /// coupling. SPEC §6, [RL10, Eqs. (2.46)–(2.72)]. Regularised by
    /// Deviations 1–3.
    pub fn flow_stress_slopes(&self, eps_p: Real, temperature: Real, damage: Real) -> FlowStress {
        self.slopes_from(&self.flow_factors(eps_p, temperature, damage), temperature)
    }

    /// The factors of `g` at one state. A step evaluates each power once and
    /// shares it between `g` and its slopes (the same operations, in the same
    /// order, as evaluating each on its own).
    fn flow_factors(&self, eps_p: Real, temperature: Real, damage: Real) -> FlowFactors {
        self.hardening_factors(eps_p, self.thermal_factor(temperature), self.damage_factor(damage))
    }

    /// [`FlowFactors`] at plastic strain `eps_p` with the thermal and damage
    /// factors given (the radial return varies `ε̄` only).
    fn hardening_factors(&self, eps_p: Real, thermal: Real, dmg: Real) -> FlowFactors {
        let eps = eps_p.max(0.0);
        let eps_n = eps.powf(self.hardening_exponent);
        FlowFactors { eps, eps_n, strain_part: self.yield_stress + self.hardening_modulus * eps_n, thermal, dmg }
    }

    /// `g_ε = B n ε̄ⁿ⁻¹ (1 − T*ᵐ)(1 − D)`, regularised by Deviation 1; per
    /// unit of `ε̄` also with Børvik's damage-equivalent strain `r` (there
    /// `∂g/∂r · dr/dε̄`, [`JohnsonCook::strain_scale`]).
    fn hardening_slope(&self, f: &FlowFactors) -> Real {
        let n = self.hardening_exponent;
        // ε̄ⁿ⁻¹ = ε̄ⁿ/ε̄ above the floor: one power instead of two.
        let eps_n_minus_1 =
            if f.eps >= PLASTIC_STRAIN_FLOOR { f.eps_n / f.eps } else { PLASTIC_STRAIN_FLOOR.powf(n - 1.0) };
        self.hardening_modulus * n * eps_n_minus_1 * f.thermal * f.dmg * self.strain_scale(f.dmg)
    }

    /// [`JohnsonCook::flow_stress_slopes`] from the factors at `temperature`.
    fn slopes_from(&self, f: &FlowFactors, temperature: Real) -> FlowStress {
        let m = self.softening_exponent;
        let t_star = self.homologous_temperature(temperature);
        let g_temp = if !(0.0..1.0).contains(&t_star) {
            0.0
        } else {
            -m * t_star.max(HOMOLOGOUS_TEMPERATURE_FLOOR).powf(m - 1.0) * f.strain_part * f.dmg
                / (self.melting_temperature - self.room_temperature)
        };
        FlowStress { g: f.g(), g_eps: self.hardening_slope(f), g_temp }
    }

    /// The rate factor `τ̄/g` of steady flow at plastic rate `rate`: `1 + C ln(ε̄̇/ε̇₀)`
    /// (log) or `(1 + ε̄̇/ε̇₀)^C` (power). The forward form of
    /// [`JohnsonCook::plastic_rate`]. SPEC §6, [RL10, Eqs. (2.46)–(2.72)].
    pub fn rate_factor(&self, rate: Real) -> Real {
        let c = self.rate_sensitivity;
        let ratio = rate / self.reference_strain_rate;
        match self.rate_form {
            RateForm::Log => 1.0 + c * ratio.ln(),
            RateForm::Power => (1.0 + ratio).powf(c),
        }
    }

    /// The inverse rate law (flow rule) `ε̄̇ = φ(τ̄, g)` and `f_τ = ∂ε̄̇/∂τ̄`
    /// (SPEC §6, [RL10, Eqs. (2.46)–(2.72)]):
    /// - log: `ε̄̇ = ε̇₀ exp{(τ̄/g − 1)/C}`, `f_τ = ε̄̇/(C g)`;
    /// - power: `ε̄̇ = ε̇₀ ((τ̄/g)^{1/C} − 1)` for `τ̄ ≥ g`, else 0;
    ///   `f_τ = (ε̄̇ + ε̇₀)/(C τ̄)` for `τ̄ ≥ g`, else 0.
    ///
    /// The exponent is capped at [`MAX_RATE_EXPONENT`] (Deviation 5); `f_τ`
    /// is then the law's derivative at the capped rate. Requires `g > 0`.
    pub fn plastic_rate(&self, tau_bar: Real, g: Real) -> PlasticRate {
        let c = self.rate_sensitivity;
        let rate0 = self.reference_strain_rate;
        match self.rate_form {
            RateForm::Log => {
                let x = ((tau_bar / g - 1.0) / c).min(MAX_RATE_EXPONENT);
                let rate = rate0 * x.exp();
                PlasticRate { rate, d_rate_d_tau: rate / (c * g) }
            }
            RateForm::Power => {
                if tau_bar < g {
                    return PlasticRate { rate: 0.0, d_rate_d_tau: 0.0 };
                }
                let x = ((tau_bar / g).ln() / c).min(MAX_RATE_EXPONENT);
                let rate = rate0 * x.exp_m1();
                PlasticRate { rate, d_rate_d_tau: (rate + rate0) / (c * tau_bar) }
            }
        }
    }

    /// The largest `τ̄/g` the capped rate law represents (Deviation 5):
    /// `1 + C·MAX_RATE_EXPONENT` (log) or `e^{C·MAX_RATE_EXPONENT}` (power).
    pub fn max_overstress_ratio(&self) -> Real {
        let cx = self.rate_sensitivity * MAX_RATE_EXPONENT;
        match self.rate_form {
            RateForm::Log => 1.0 + cx,
            RateForm::Power => cx.exp(),
        }
    }

    /// Tangent modulus ([RL10, Eq. (2.70)], simplified as in SPEC §6):
    /// `H = 3G + τ̄ g_ε/g + χ τ̄² g_T/(ρ₀ C_p g)`. The same for both rate laws.
    /// May be ≤ 0 (adiabatic instability); the update handles that
    /// (Deviation 6).
    pub fn tangent_modulus(&self, tau_bar: Real, fs: &FlowStress) -> Real {
        let heat = self.heating_coefficient();
        3.0 * self.shear_modulus() + tau_bar * fs.g_eps / fs.g + heat * tau_bar * tau_bar * fs.g_temp / fs.g
    }

    /// Adiabatic hardening at a constant plastic rate, `(1/τ̄) dτ̄/dε̄`
    /// (dimensionless): the slope of the flow stress `τ̄ = R(ε̄̇) g` when the
    /// plastic work heats the point where it is done (`dT = χ τ̄ dε̄/(ρ₀ C_p)`),
    ///
    /// `(1/τ̄) dτ̄/dε̄ = (g_ε + g_T χ τ̄/(ρ₀ C_p))/g = (H − 3G)/τ̄`,
    ///
    /// with `H` the update's [`JohnsonCook::tangent_modulus`] (one place for
    /// the equation) and `R ≥ 1` the rate factor at `rate`. Where it is
    /// ≤ 0 thermal softening has overtaken strain hardening: Recht's (1964)
    /// condition for catastrophic thermoplastic shear, the onset of
    /// adiabatic shear localization in its simplest form (no delay by the
    /// rate sensitivity or by conduction, so an early bound). At `g ≤ 0`
    /// (melted or fully damaged and coupled) the point carries no shear:
    /// `−∞`. A diagnostic (output field `adiabatic_hardening`); no crack
    /// criterion reads it. Tests (`tests/material.rs`):
    /// `adiabatic_hardening_vanishes_at_the_peak_of_the_closed_form_adiabatic_curve`,
    /// `adiabatic_hardening_changes_sign_at_the_peak_of_the_driven_shear_curve`.
    pub fn adiabatic_hardening(&self, eps_p: Real, temperature: Real, damage: Real, rate: Real) -> Real {
        let fs = self.flow_stress_slopes(eps_p, temperature, damage);
        if fs.g <= 0.0 {
            return Real::NEG_INFINITY;
        }
        let tau_bar = self.rate_factor(rate).max(1.0) * fs.g;
        (self.tangent_modulus(tau_bar, &fs) - 3.0 * self.shear_modulus()) / tau_bar
    }

    /// `χ/(ρ₀ C_p)`, K/Pa: temperature rise per unit plastic work.
    pub fn heating_coefficient(&self) -> Real {
        self.taylor_quinney / (self.density * self.specific_heat)
    }

    /// Johnson–Cook failure strain ([RL10, Eqs. (5.1)–(5.2)], SPEC §6)
    /// `ε_f = [D₁ + D₂ exp(D₃ σ*)] R(ε̇*) [1 + D₅ T*]` with `ε̇* = ε̄̇/ε̇₀` and
    /// `R = 1 + D₄ ln max(ε̇*, 1)` (log law) or `R = (1 + ε̇*)^{D₄}` (power
    /// law, Børvik). `T*` clamped to [0, 1] (Deviation 3), result floored at
    /// [`MIN_FAILURE_STRAIN`] (Deviation 9). Below the cut-off
    /// triaxiality, where the locus has one, `ε_f = ∞` (Deviation 14).
    pub fn failure_strain(&self, triaxiality: Real, rate: Real, temperature: Real) -> Real {
        let dc = &self.damage;
        if dc.cutoff_triaxiality.is_some_and(|c| triaxiality < c) {
            return Real::INFINITY;
        }
        let rate_star = rate / self.reference_strain_rate;
        let stress_term = dc.d1 + dc.d2 * (dc.d3 * triaxiality).exp();
        let rate_term = match self.rate_form {
            RateForm::Log => 1.0 + dc.d4 * rate_star.max(1.0).ln(),
            RateForm::Power => (1.0 + rate_star).powf(dc.d4),
        };
        let t_star = self.homologous_temperature(temperature).clamp(0.0, 1.0);
        let eps_f = stress_term * rate_term * (1.0 + dc.d5 * t_star);
        // `max` would turn a NaN input into the floor, i.e. a silent failure;
        // let it propagate to the solver's NaN check instead.
        if eps_f.is_nan() {
            eps_f
        } else {
            eps_f.max(MIN_FAILURE_STRAIN)
        }
    }

    /// Cockcroft–Latham's critical work `W_c` from a tension test on this
    /// material's own curves (Deviation 15), Pa: the area under the
    /// hardening curve, `∫₀^{ε_f} (A + B εⁿ) dε = A ε_f + B ε_f^{n+1}/(n+1)`,
    /// up to the Johnson–Cook fracture strain of uniaxial tension
    /// `ε_f = D₁ + D₂ exp(D₃/3)`, at the reference rate and room
    /// temperature (rate and temperature factors 1), where `σ₁ = σ̄`.
    pub fn tension_fracture_work(&self) -> Real {
        let dc = &self.damage;
        let eps_f = dc.d1 + dc.d2 * (dc.d3 / 3.0).exp();
        let n = self.hardening_exponent;
        self.yield_stress * eps_f + self.hardening_modulus * eps_f.powf(n + 1.0) / (n + 1.0)
    }

    /// The damage a plastic increment `d_eps` adds at stress `tau` (mean
    /// value `mean`, von Mises value `tau_bar`, rate `rate`, temperature
    /// `temperature`): the Johnson–Cook `Δε̄/ε_f(σ*)` with `σ* = mean/τ̄`
    /// ([RL10, Eq. (5.2)], SPEC §6), or, where the locus is
    /// Cockcroft–Latham's (Deviation 15), `⟨σ₁⟩ Δε̄ / W_c` with `σ₁` the
    /// largest principal value of `tau`. The caller passes `mean` as its
    /// update formed it (the radial return's before it rebuilds `tau`).
    pub fn damage_increment(
        &self,
        tau: &Tensor3,
        mean: Real,
        tau_bar: Real,
        d_eps: Real,
        rate: Real,
        temperature: Real,
    ) -> Real {
        match self.damage.cockcroft_latham {
            Some(w) => largest_principal(tau).max(0.0) * d_eps / w,
            None => d_eps / self.failure_strain(mean / tau_bar, rate, temperature),
        }
    }

    /// Elastic part of the objective rate, `C : d = K tr(d) I + 2G d′`.
    pub fn elastic_stress_rate(&self, d: &Tensor3) -> Tensor3 {
        identity() * (self.bulk_modulus() * d.trace()) + deviator(d) * (2.0 * self.shear_modulus())
    }

    /// Von Mises measure of the step's deviatoric elastic increment,
    /// `3G Δt sqrt(2/3 d′:d′)`, Pa (Deviation 11).
    pub fn elastic_increment(&self, d: &Tensor3, dt: Real) -> Real {
        let dev_d = deviator(d);
        3.0 * self.shear_modulus() * dt * (2.0 / 3.0 * ddot(&dev_d, &dev_d)).sqrt()
    }

    fn is_strengthless(&self, g: Real) -> bool {
        // NaN counts as no strength.
        g.is_nan() || g <= MIN_FLOW_STRESS_RATIO * self.shear_modulus()
    }

    /// Deviation 4: no deviatoric strength.
    fn update_strengthless(&self, old: &PointState, k: &StepKinematics) -> PointState {
        let dev_d = deviator(&k.d);
        let rate = (2.0 / 3.0 * ddot(&dev_d, &dev_d)).sqrt();
        let mean = mean_stress(&old.tau) + k.dt * self.bulk_modulus() * k.d.trace();
        PointState { tau: identity() * mean, eps_p: old.eps_p + k.dt * rate, eps_p_rate: rate, ..*old }
    }

    /// Deviation 8: a power-law step that starts below the flow stress.
    fn update_power_below_flow_stress(&self, old: &PointState, k: &StepKinematics, fs: &FlowStress) -> PointState {
        let elastic = self.elastic_stress_rate(&k.d);
        let trial = jaumann_update(&old.tau, &elastic, &k.w, k.dt);
        if von_mises(&trial) <= fs.g {
            return PointState { tau: trial, eps_p_rate: 0.0, ..*old };
        }
        // τ̄² along the explicit elastic path τ + s R is a s² + b s + c;
        // one root in (0, Δt] because c < 0 < a s² + b s + c at s = Δt.
        let s0 = deviator(&old.tau);
        let r = deviator(&(elastic + k.w * old.tau - old.tau * k.w));
        let a = 1.5 * ddot(&r, &r);
        let b = 3.0 * ddot(&s0, &r);
        let c = 1.5 * ddot(&s0, &s0) - fs.g * fs.g;
        let s_cross = (-2.0 * c / (b + (b * b - 4.0 * a * c).sqrt())).clamp(0.0, k.dt);
        let mid = PointState { tau: jaumann_update(&old.tau, &elastic, &k.w, s_cross), ..*old };
        let at_threshold =
            PlasticRate { rate: 0.0, d_rate_d_tau: self.reference_strain_rate / (self.rate_sensitivity * fs.g) };
        let mut new = self.flow_step(&mid, &k.d, &k.w, k.dt - s_cross, fs, &at_threshold);
        new.eps_p_rate = if k.dt > 0.0 { (new.eps_p - old.eps_p) / k.dt } else { 0.0 };
        new
    }

    /// One step of viscoplastic flow from `old` with the flow rule's rate and
    /// slope `pr`: the backward-Euler radial return where the step's elastic
    /// increment exceeds `τ̄` (Deviation 11; this includes every step from a
    /// zero deviator, whose `n̂` is undefined), else the tangent update.
    fn flow_step(
        &self,
        old: &PointState,
        d: &Tensor3,
        w: &Tensor3,
        dt: Real,
        fs: &FlowStress,
        pr: &PlasticRate,
    ) -> PointState {
        if dt <= 0.0 {
            return *old;
        }
        if self.elastic_increment(d, dt) > von_mises(&old.tau) {
            return self.radial_return(old, &self.elastic_stress_rate(d), w, dt, fs);
        }
        self.update_tangent(old, d, w, dt, fs, pr)
    }

    /// Deviation 13: whether a log-law step whose elastic trial stress has
    /// von Mises value `tau_trial` creeps at a rate below `ε̇₀ e⁻⁵⁰`, decided
    /// without evaluating `g` or the rate law: `g ≥ g_lo = A (1 − t̂)(1 − D)`
    /// with `t̂ ≥ T*ᵐ` read off the binary exponent of `T*` (`B ε̄ⁿ ≥ 0`), and
    /// the rate grows with `τ̄` and falls with `g`, so
    /// `(τ_tr/g_lo − 1)/C ≤ −50` bounds the step's rate — the rate that
    /// Deviation 12 books — by `ε̇₀ e⁻⁵⁰`. Also required: that rate relaxes the
    /// stress by less than Deviation 12's tolerance, and its strain per step
    /// `Δt ε̇₀ e⁻⁵⁰` stays below [`NEGLIGIBLE_CREEP_STRAIN`], so the step is
    /// exactly Deviation 12's elastic trial with the creep left unbooked.
    fn creep_is_negligible(&self, old: &PointState, tau_trial: Real, dt: Real) -> bool {
        let creep_rate = self.reference_strain_rate * NEGLIGIBLE_CREEP_EXPONENT.exp();
        let t_star = self.homologous_temperature(old.temperature);
        let thermal_lo = if t_star <= 0.0 {
            1.0
        } else if t_star < 1.0 {
            1.0 - power_upper_bound(t_star, self.softening_exponent)
        } else {
            0.0
        };
        let g_lo = self.yield_stress * thermal_lo * self.damage_factor(old.damage);
        let three_g = 3.0 * self.shear_modulus();
        !self.is_strengthless(g_lo)
            && (tau_trial / g_lo - 1.0) / self.rate_sensitivity <= NEGLIGIBLE_CREEP_EXPONENT
            && dt * creep_rate <= NEGLIGIBLE_CREEP_STRAIN
            && three_g * dt * creep_rate <= NEGLIGIBLE_RELAXATION * NEGLIGIBLE_STRESS_RATIO * g_lo
    }

    /// Deviation 12: the elastic trial step when flow cannot matter, else `None`
    /// (the update itself starts from the trial it has already formed).
    #[cfg(test)]
    fn negligible_flow_step(
        &self,
        old: &PointState,
        d: &Tensor3,
        w: &Tensor3,
        dt: Real,
        g: Real,
    ) -> Option<PointState> {
        if dt <= 0.0 {
            return None;
        }
        let trial = jaumann_update(&old.tau, &self.elastic_stress_rate(d), w, dt);
        self.negligible_flow_from_trial(old, &trial, von_mises(&trial), dt, g)
    }

    /// The elastic trial stress of a step, `τ + Δt (C:d + wτ − τw)`
    /// ([`jaumann_update`] of [`JohnsonCook::elastic_stress_rate`]), and its
    /// von Mises value. Where `τ`, `d` and `w` have the block form of 2D
    /// kinematics (always, in the solver) it is formed on [`Block2`]s, the
    /// same arithmetic on the five entries that can be non-zero: the same
    /// bits (test `block_elastic_trial_has_the_same_bits`).
    #[inline(always)]
    fn elastic_trial(&self, tau: &Tensor3, k: &StepKinematics) -> (Tensor3, Real) {
        if let (Some(tau), Some(d), Some(w)) =
            (Block2::from_tensor(tau), Block2::from_tensor(&k.d), Block2::from_tensor(&k.w))
        {
            let tr = d.trace();
            let elastic = Block2::identity_scaled(self.bulk_modulus() * tr)
                .add(&d.sub(&Block2::identity_scaled(tr / 3.0)).scale(2.0 * self.shear_modulus()));
            let trial = tau.add(&elastic.add(&w.mul(&tau)).sub(&tau.mul(&w)).scale(k.dt));
            return (trial.to_tensor(), trial.von_mises());
        }
        let trial = jaumann_update(tau, &self.elastic_stress_rate(&k.d), &k.w, k.dt);
        (trial, von_mises(&trial))
    }

    /// [`JohnsonCook::negligible_flow_step`] from the step's elastic trial
    /// stress and its von Mises value `tau_bar` (`dt > 0`).
    fn negligible_flow_from_trial(
        &self,
        old: &PointState,
        trial: &Tensor3,
        tau_bar: Real,
        dt: Real,
        g: Real,
    ) -> Option<PointState> {
        let trial = *trial;
        let rate = self.plastic_rate(tau_bar, g).rate;
        // Absolute floor: the log law creeps at ε̇₀ e^{−1/C} > 0 even at zero
        // stress, so round-off-sized stresses (seen ahead of wave fronts)
        // would otherwise never pass a purely relative test.
        let scale = tau_bar.max(NEGLIGIBLE_STRESS_RATIO * g);
        let relaxation = 3.0 * self.shear_modulus() * dt * rate;
        if relaxation.is_nan() || relaxation > NEGLIGIBLE_RELAXATION * scale {
            return None;
        }
        // No deviator, no flow direction: nothing to book. A damage
        // increment below 1e-18/ε_f is not evaluated (its failure strain
        // costs two transcendental calls; the sum over a whole run stays
        // below 1e-14).
        let rate = if tau_bar > 0.0 { rate } else { 0.0 };
        let damage = if dt * rate > 1e-18 {
            old.damage + self.damage_increment(&trial, mean_stress(&trial), tau_bar, dt * rate, rate, old.temperature)
        } else {
            old.damage
        };
        Some(PointState {
            tau: trial,
            eps_p: old.eps_p + dt * rate,
            eps_p_rate: rate,
            temperature: old.temperature + dt * self.heating_coefficient() * tau_bar * rate,
            damage,
        })
    }

    /// The tangent-modulus update of SPEC §6 over `dt` from `old`, with the
    /// flow rule's rate and slope `pr` at the start of the step
    /// ([RL10, Eqs. (2.46)–(2.72)]; (2.70) for `H`, (2.72) for `τ^∇`):
    ///
    /// - `P = 2G n̂`, `n̂ = 3s/(2τ̄)`; `ξ = θΔt f_τ max(H, 0)`;
    /// - `ε̄̇_θ = ε̄̇/(1+ξ) + ξ/((1+ξ)H) P:d = (ε̄̇ + θΔt f_τ P:d)/(1+ξ)`,
    ///   clamped by Deviation 7;
    /// - `τ^∇ = C:d − ε̄̇_θ (P + 3Kα χ τ̄/(ρ₀C_p) I)`,
    ///   `τ ← τ + Δt(τ^∇ + wτ − τw)` via [`jaumann_update`];
    /// - `ε̄ += Δt ε̄̇_θ`, `T += Δt χ τ̄ ε̄̇_θ/(ρ₀C_p)`, `D += Δt ε̄̇_θ/ε_f`.
    ///
    /// Falls back to [`JohnsonCook::radial_return`] when the result lies
    /// beyond the capped law (Deviation 5).
    #[allow(non_snake_case)]
    fn update_tangent(
        &self,
        old: &PointState,
        d: &Tensor3,
        w: &Tensor3,
        dt: Real,
        fs: &FlowStress,
        pr: &PlasticRate,
    ) -> PointState {
        // Legend: G shear modulus, P = C:n̂, H tangent modulus, tau_bar = τ̄.
        let G = self.shear_modulus();
        let elastic = self.elastic_stress_rate(d);
        let tau_bar = von_mises(&old.tau);
        if tau_bar <= 0.0 {
            // Only reached with d′ = 0 (flow_step): a purely volumetric step.
            return PointState { tau: jaumann_update(&old.tau, &elastic, w, dt), eps_p_rate: 0.0, ..*old };
        }
        let P = deviator(&old.tau) * (3.0 * G / tau_bar);
        let p_d = ddot(&P, d);
        let H = self.tangent_modulus(tau_bar, fs);
        let theta_dt_f = self.theta * dt * pr.d_rate_d_tau;
        let xi = theta_dt_f * H.max(0.0);
        let linearised = (pr.rate + theta_dt_f * p_d) / (1.0 + xi);
        // The stress along n̂ after the step is τ̄ + Δt P:d − 3GΔt ε̄̇_θ ≥ 0.
        let upper = ((tau_bar + dt * p_d) / (3.0 * G * dt)).max(0.0);
        let rate = linearised.clamp(0.0, upper);

        let heat = self.heating_coefficient();
        let temp_rate = heat * tau_bar * rate;
        let thermal = 3.0 * self.bulk_modulus() * self.thermal_expansion * temp_rate;
        let tau_rate = elastic - (P * rate + identity() * thermal);
        let tau = jaumann_update(&old.tau, &tau_rate, w, dt);
        if von_mises(&tau) > self.max_overstress_ratio() * fs.g {
            return self.radial_return(old, &elastic, w, dt, fs);
        }
        let damage = self.damage_increment(&old.tau, mean_stress(&old.tau), tau_bar, dt * rate, rate, old.temperature);
        PointState {
            tau,
            eps_p: old.eps_p + dt * rate,
            eps_p_rate: rate,
            temperature: old.temperature + dt * temp_rate,
            damage: old.damage + damage,
        }
    }

    /// Backward-Euler viscoplastic radial return (the fallback of
    /// Deviation 5): from the elastic predictor `τ_tr`, find `τ̄_e` with
    /// `Δε̄ = (τ̄_tr − τ̄_e)/(3G) = Δt φ(τ̄_e, g(ε̄ + Δε̄))` (hardening implicit,
    /// temperature and damage frozen at the start of the step; the left side
    /// falls and the right rises with `τ̄_e`, so the root is unique and a
    /// safeguarded Newton iteration finds it), scale the predictor's deviator by
    /// `τ̄_e/τ̄_tr`, heat by `χ (τ̄ + τ̄_e)/2 Δε̄/(ρ₀C_p)`, take the thermal
    /// pressure `3Kα ΔT` off the mean stress, and accumulate damage with the
    /// end-of-step triaxiality. SPEC §6 (flow rule, heating,
    /// damage), [RL10, Eqs. (2.46)–(2.72)].
    fn radial_return(&self, old: &PointState, elastic: &Tensor3, w: &Tensor3, dt: Real, fs: &FlowStress) -> PointState {
        let three_g = 3.0 * self.shear_modulus();
        let trial = jaumann_update(&old.tau, elastic, w, dt);
        let s_trial = deviator(&trial);
        let tau_trial = von_mises(&trial);
        if tau_trial <= 0.0 {
            return PointState { tau: trial, eps_p_rate: 0.0, ..*old };
        }
        // r(τ̄_e) = Δt φ(τ̄_e, g(ε̄ + Δε̄)) − Δε̄ rises monotonically from r(0) < 0
        // to r(τ̄_tr) ≥ 0. Safeguarded Newton: a Newton step from the
        // bracket's current end, bisection whenever it would leave the
        // bracket or stall. Derivative: dr/dτ̄_e = Δt (f_τ + f_τ τ̄_e g_ε /
        // (3G g)) + 1/(3G), using ∂φ/∂g = −f_τ τ̄_e/g (both rate laws).
        // Temperature and damage are frozen: their factors are evaluated once.
        let (thermal, dmg) = (self.thermal_factor(old.temperature), self.damage_factor(old.damage));
        let residual = |tau_e: Real| {
            let d_eps = (tau_trial - tau_e) / three_g;
            let f = self.hardening_factors(old.eps_p + self.strain_scale(dmg) * d_eps, thermal, dmg);
            let g = f.g().max(fs.g);
            let pr = self.plastic_rate(tau_e, g);
            let r = dt * pr.rate - d_eps;
            let dr = dt * pr.d_rate_d_tau * (1.0 + tau_e * self.hardening_slope(&f) / (three_g * g)) + 1.0 / three_g;
            (r, dr)
        };
        // rtsafe-style: Newton while it stays inside the bracket and halves
        // the step at least as fast as bisection would, bisection otherwise.
        let (mut lo, mut hi) = (0.0, tau_trial);
        let mut x = tau_trial;
        let (mut dx, mut dx_old) = (tau_trial, tau_trial);
        for _ in 0..200 {
            let (r, dr) = residual(x);
            if r == 0.0 {
                break;
            }
            if r > 0.0 {
                hi = x;
            } else {
                lo = x;
            }
            let leaves = ((x - hi) * dr - r) * ((x - lo) * dr - r) > 0.0;
            if leaves || !dr.is_finite() || (2.0 * r).abs() > (dx_old * dr).abs() {
                dx_old = dx;
                dx = 0.5 * (hi - lo);
                x = lo + dx;
            } else {
                dx_old = dx;
                dx = r / dr;
                x -= dx;
            }
            if dx.abs() <= 2.0 * Real::EPSILON * tau_trial || hi - lo <= 4.0 * Real::EPSILON * hi {
                break;
            }
        }
        let tau_end = x.clamp(lo, hi);
        let d_eps = (tau_trial - tau_end) / three_g;
        let tau_bar = von_mises(&old.tau);
        let d_temp = self.heating_coefficient() * 0.5 * (tau_bar + tau_end) * d_eps;
        let mean = mean_stress(&trial) - 3.0 * self.bulk_modulus() * self.thermal_expansion * d_temp;
        let rate = d_eps / dt;
        // End-of-step stress state, as befits backward Euler (and defined
        // even from a zero deviator, where the start-of-step one is 0/0).
        let tau = s_trial * (tau_end / tau_trial) + identity() * mean;
        let damage = self.damage_increment(&tau, mean, tau_end, d_eps, rate, old.temperature);
        PointState {
            tau,
            eps_p: old.eps_p + d_eps,
            eps_p_rate: rate,
            temperature: old.temperature + d_temp,
            damage: old.damage + damage,
        }
    }

    /// One step of SPEC §6 over the plastic strain `ε̄` (module doc):
    /// strengthless points (Deviation 4), the power law's elastic branch
    /// (Deviation 8), the radial return where the flow direction is not
    /// resolved (Deviation 11), else the tangent-modulus update.
    fn update_over_plastic_strain(&self, old: &PointState, k: &StepKinematics) -> PointState {
        let mut log_trial = None;
        if self.rate_form == RateForm::Log && k.dt > 0.0 {
            let (t, tau_trial) = self.elastic_trial(&old.tau, k);
            if self.creep_is_negligible(old, tau_trial, k.dt) {
                return PointState { tau: t, eps_p_rate: 0.0, ..*old };
            }
            log_trial = Some((t, tau_trial));
        }
        let factors = self.flow_factors(old.eps_p, old.temperature, old.damage);
        let g = factors.g();
        if self.is_strengthless(g) {
            return self.update_strengthless(old, k);
        }
        let tau_bar = von_mises_2d(&old.tau);
        if (self.rate_form == RateForm::Log || tau_bar >= g) && k.dt > 0.0 {
            let (t, tau_trial) = log_trial.unwrap_or_else(|| self.elastic_trial(&old.tau, k));
            if let Some(elastic_step) = self.negligible_flow_from_trial(old, &t, tau_trial, k.dt, g) {
                return elastic_step;
            }
        }
        let fs = self.slopes_from(&factors, old.temperature);
        if self.rate_form == RateForm::Power && tau_bar < fs.g {
            return self.update_power_below_flow_stress(old, k, &fs);
        }
        let pr = self.plastic_rate(tau_bar, fs.g);
        self.flow_step(old, &k.d, &k.w, k.dt, &fs, &pr)
    }
}

impl Constitutive for JohnsonCook {
    /// One step of SPEC §6 (`JohnsonCook::update_over_plastic_strain`),
    /// over Børvik's damage-equivalent strain where the material asks.
    fn update(&self, old: &PointState, k: &StepKinematics) -> PointState {
        let new = self.update_over_plastic_strain(old, k);
        if !self.damage_equivalent_strain {
            return new;
        }
        // Børvik's damage-equivalent strain: the step's increments of the
        // hardening variable and of the damage scale by `dr/dε̄ = 1 − D_C D`
        // at the start of the step (the radial return's hardening and every
        // `g_ε` already use it); `eps_p_rate` stays `ε̄̇`.
        let scale = self.strain_scale(self.damage_factor(old.damage));
        PointState {
            eps_p: old.eps_p + scale * (new.eps_p - old.eps_p),
            damage: old.damage + scale * (new.damage - old.damage),
            ..new
        }
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
        Some(ThermalProperties { specific_heat: self.specific_heat, conductivity: self.conductivity })
    }
}

/// An upper bound of `xᵖ` for `0 < x < 1`, `p > 0`, without a transcendental
/// call: `x < 2ᵏ` with `k` from the binary exponent of `x`, so
/// `xᵖ < 2^{kp} ≤ 2^{⌈kp⌉ + 1}` (the `+ 1` absorbs the rounding of `kp`).
/// At most `2^{p+2} xᵖ` (`x ≥ 2^{k−1}`; test `power_upper_bound_is_a_bound`).
fn power_upper_bound(x: Real, p: Real) -> Real {
    debug_assert!(x > 0.0 && x < 1.0 && p > 0.0);
    // x = 1.f · 2^(e − 1023) < 2^(e − 1022) for normal x; x < 2^-1022 for subnormal x (e = 0).
    let e = ((x.to_bits() >> 52) & 0x7ff) as i32;
    let k = (e - 1022).min(0);
    let c = ((k as Real) * p).ceil() as i32 + 1;
    if c >= 0 {
        1.0
    } else if c < -1022 {
        Real::MIN_POSITIVE
    } else {
        Real::from_bits(((c + 1023) as u64) << 52)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::library::{weldox_460e, weldox_460e_borvik};
    use crate::material::Elastic;

    fn kin(d: Tensor3, w: Tensor3, dt: Real) -> StepKinematics {
        StepKinematics { d, w, dt }
    }

    /// Deviatoric uniaxial stress state with von Mises value `tau_bar`.
    fn uniaxial(tau_bar: Real) -> Tensor3 {
        Tensor3::from_diagonal(&nalgebra::Vector3::new(2.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0)) * tau_bar
    }

    fn diag(x: Real, y: Real, z: Real) -> Tensor3 {
        Tensor3::from_diagonal(&nalgebra::Vector3::new(x, y, z))
    }

    fn state(tau: Tensor3, eps_p: Real, temperature: Real) -> PointState {
        PointState { tau, eps_p, eps_p_rate: 0.0, temperature, damage: 0.0 }
    }

    fn is_finite(s: &PointState) -> bool {
        s.tau.iter().all(|v| v.is_finite())
            && s.eps_p.is_finite()
            && s.eps_p_rate.is_finite()
            && s.temperature.is_finite()
            && s.damage.is_finite()
    }

    fn rel(a: Real, b: Real) -> Real {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn hardening_slope_matches_finite_differences() {
        for m in [weldox_460e(), weldox_460e_borvik()] {
            for eps in [1e-3, 0.05, 0.3, 2.0] {
                for t in [293.0, 500.0, 1200.0] {
                    let h = 1e-6 * eps;
                    let fd = (m.flow_stress(eps + h, t, 0.0) - m.flow_stress(eps - h, t, 0.0)) / (2.0 * h);
                    let g_eps = m.flow_stress_slopes(eps, t, 0.0).g_eps;
                    assert!(rel(g_eps, fd) < 1e-6, "eps {eps} T {t}: {g_eps} vs {fd}");
                }
            }
        }
    }

    #[test]
    fn softening_slope_matches_finite_differences() {
        let mut m = weldox_460e();
        for damage_coupling in [0.0, 0.3, 1.0] {
            m.damage_coupling = damage_coupling;
            for t_star in [0.01, 0.2, 0.5, 0.9, 0.99] {
                let t = m.room_temperature + t_star * (m.melting_temperature - m.room_temperature);
                let h = 1e-4;
                let fd = (m.flow_stress(0.2, t + h, 0.3) - m.flow_stress(0.2, t - h, 0.3)) / (2.0 * h);
                let g_t = m.flow_stress_slopes(0.2, t, 0.3).g_temp;
                assert!(rel(g_t, fd) < 1e-6, "T* {t_star}: {g_t} vs {fd}");
            }
        }
    }

    #[test]
    fn rate_slope_matches_finite_differences() {
        for m in [weldox_460e(), weldox_460e_borvik()] {
            let g = 600e6;
            for ratio in [0.97, 1.001, 1.02, 1.1, 1.3] {
                if m.rate_form == RateForm::Power && ratio < 1.0 {
                    continue;
                }
                let tau = ratio * g;
                let h = 1e-7 * tau;
                let fd = (m.plastic_rate(tau + h, g).rate - m.plastic_rate(tau - h, g).rate) / (2.0 * h);
                let f_tau = m.plastic_rate(tau, g).d_rate_d_tau;
                assert!(rel(f_tau, fd) < 1e-5, "{:?} ratio {ratio}: {f_tau} vs {fd}", m.rate_form);
            }
        }
    }

    /// SPEC §6's simplified `H` against the general form
    /// `H = 3G − f_ε/f_τ − (χτ̄/(ρ₀C_p)) f_T/f_τ` with the partials of the flow
    /// rule taken by finite differences.
    #[test]
    fn tangent_modulus_matches_general_formula() {
        for m in [weldox_460e(), weldox_460e_borvik()] {
            for (eps, t, ratio) in [(0.05, 400.0, 1.05), (0.5, 900.0, 1.2), (1.5, 1500.0, 1.01)] {
                let g0 = m.flow_stress(eps, t, 0.0);
                let tau = ratio * g0;
                let phi = |e: Real, temp: Real| m.plastic_rate(tau, m.flow_stress(e, temp, 0.0)).rate;
                let (he, ht) = (1e-6 * eps, 1e-3);
                let f_eps = (phi(eps + he, t) - phi(eps - he, t)) / (2.0 * he);
                let f_t = (phi(eps, t + ht) - phi(eps, t - ht)) / (2.0 * ht);
                let f_tau = m.plastic_rate(tau, g0).d_rate_d_tau;
                let general = 3.0 * m.shear_modulus() - f_eps / f_tau - m.heating_coefficient() * tau * f_t / f_tau;
                let h = m.tangent_modulus(tau, &m.flow_stress_slopes(eps, t, 0.0));
                assert!(rel(h, general) < 1e-6, "{:?}: {h} vs {general}", m.rate_form);
            }
        }
    }

    #[test]
    fn plastic_rate_inverts_the_rate_law() {
        for m in [weldox_460e(), weldox_460e_borvik()] {
            let g = 700e6;
            for rate in [1e-2, 1.0, 1e3, 1e6] {
                let got = m.plastic_rate(g * m.rate_factor(rate), g).rate;
                assert!(rel(got, rate) < 1e-9, "{:?} {rate}: {got}", m.rate_form);
            }
        }
    }

    #[test]
    fn failure_strain_follows_the_johnson_cook_formula() {
        let m = weldox_460e();
        let base = |s: Real| 0.0705 + 1.732 * (-0.54 * s).exp();
        // Log law: 1 + D4 ln max(rate*, 1).
        assert!(rel(m.failure_strain(0.4, 1e4, 293.0), base(0.4) * (1.0 - 0.015 * 1e4f64.ln())) < 1e-14);
        assert!(rel(m.failure_strain(-0.2, 0.5, 293.0), base(-0.2)) < 1e-14);
        // Power law (Børvik): (1 + rate*)^D4.
        let p = weldox_460e_borvik();
        let want = base(1.0 / 3.0) * (1.0 + 1e3 / 5e-4f64).powf(-0.015);
        assert!(rel(p.failure_strain(1.0 / 3.0, 1e3, 293.0), want) < 1e-14);
        // Temperature term with D5 ≠ 0, T* = 0.5.
        let mut hot = weldox_460e();
        hot.damage.d5 = 0.6;
        let t = 293.0 + 0.5 * 1507.0;
        assert!(rel(hot.failure_strain(0.0, 1.0, t), base(0.0) * 1.3) < 1e-14);
    }

    #[test]
    fn failure_strain_stays_positive_beyond_fitted_range() {
        let mut m = weldox_460e();
        // 1 + D4 ln(rate*) < 0 at this rate.
        m.damage.d4 = -0.2;
        assert!(1.0 + m.damage.d4 * 1e10f64.ln() < 0.0);
        assert_eq!(m.failure_strain(0.3, 1e10, 293.0), MIN_FAILURE_STRAIN);
        // Negative D1 at high triaxiality.
        m.damage.d4 = 0.0;
        m.damage.d1 = -0.5;
        assert_eq!(m.failure_strain(5.0, 1.0, 293.0), MIN_FAILURE_STRAIN);
        // Compression so strong that exp overflows: ε_f = ∞, no NaN, no damage.
        let mut c = weldox_460e();
        c.damage.d3 = -10.0;
        assert_eq!(c.failure_strain(-1e3, 1.0, 293.0), Real::INFINITY);
    }

    #[test]
    fn the_cut_off_stops_damage_below_it_only() {
        let m = weldox_460e();
        let c = crate::material::library::weldox_460e_cutoff();
        assert_eq!(c.damage.cutoff_triaxiality, Some(-1.0 / 3.0));
        // Below −1/3: no damage, whatever the rate and temperature.
        for s in [-0.34, -1.0, -20.0] {
            assert_eq!(c.failure_strain(s, 1e4, 600.0), Real::INFINITY);
            assert!(m.failure_strain(s, 1e4, 600.0).is_finite());
        }
        // At and above it: the Johnson–Cook locus, to the bit.
        for s in [-1.0 / 3.0, -0.2, 0.0, 1.0 / 3.0, 2.0] {
            assert_eq!(c.failure_strain(s, 1e4, 600.0).to_bits(), m.failure_strain(s, 1e4, 600.0).to_bits());
        }
        // A plastic step in strong compression books no damage with the
        // cut-off, and exactly what it books without it otherwise.
        let g = m.flow_stress(0.1, 293.0, 0.0);
        let compressed = uniaxial(-1.05 * g) - identity() * (2.0 * g);
        let old = state(compressed, 0.1, 293.0);
        let k = kin(diag(-1e4, 0.5e4, 0.5e4), Tensor3::zeros(), 1e-8);
        let (with, without) = (c.update(&old, &k), m.update(&old, &k));
        assert!(without.damage > 0.0 && with.damage == 0.0, "{} {}", without.damage, with.damage);
        assert_eq!(with.tau, without.tau);
        assert_eq!(with.eps_p, without.eps_p);
    }

    #[test]
    fn hardening_slope_is_finite_at_zero_plastic_strain() {
        let m = weldox_460e();
        assert!(m.hardening_exponent < 1.0);
        let fs = m.flow_stress_slopes(0.0, 293.0, 0.0);
        let want = m.hardening_modulus * 0.73 * PLASTIC_STRAIN_FLOOR.powf(-0.27);
        assert!(fs.g_eps.is_finite() && rel(fs.g_eps, want) < 1e-12);
        assert_eq!(fs.g, m.yield_stress);
        assert!(m.tangent_modulus(fs.g, &fs).is_finite());
    }

    #[test]
    fn plastic_flow_starts_from_the_virgin_state() {
        // A virgin point (ε̄ = 0) loaded past yield must flow: with the exact
        // slope (H = ∞) the tangent update would return ε̄̇_θ = 0 for ever.
        for m in [weldox_460e(), weldox_460e_borvik()] {
            let g = m.flow_stress(0.0, 293.0, 0.0);
            let mut s = state(uniaxial(1.001 * g), 0.0, 293.0);
            let k = kin(diag(1e3, 0.0, 0.0), Tensor3::zeros(), 1e-7);
            let after_one = m.update(&s, &k);
            assert!(after_one.eps_p > 0.0, "{:?}", m.rate_form);
            for _ in 0..2000 {
                s = m.update(&s, &k);
            }
            // 2000 steps = 0.2 axial strain: plastic, stress near the flow stress.
            assert!(s.eps_p > 0.1, "{:?}: {}", m.rate_form, s.eps_p);
            let tau_bar = von_mises(&s.tau);
            let g_now = m.flow_stress(s.eps_p, s.temperature, 0.0);
            assert!(tau_bar < 1.2 * g_now && tau_bar > g_now, "{:?}: {tau_bar} vs {g_now}", m.rate_form);
        }
    }

    #[test]
    fn thermal_slope_is_finite_at_room_temperature() {
        let m = weldox_460e();
        assert!(m.softening_exponent < 1.0);
        let fs = m.flow_stress_slopes(0.1, m.room_temperature, 0.0);
        assert!(fs.g_temp.is_finite() && fs.g_temp < 0.0);
        let h = m.tangent_modulus(1.05 * fs.g, &fs);
        assert!(h.is_finite() && h > 0.0);
        // At the floor the slope is the exact one there.
        let t_floor = m.room_temperature + HOMOLOGOUS_TEMPERATURE_FLOOR * 1507.0;
        assert!(rel(m.flow_stress_slopes(0.1, t_floor, 0.0).g_temp, fs.g_temp) < 1e-9);
    }

    #[test]
    fn below_room_temperature_gives_room_temperature_strength() {
        let m = weldox_460e();
        let cold = m.room_temperature - 50.0;
        assert_eq!(m.flow_stress(0.2, cold, 0.0), m.flow_stress(0.2, m.room_temperature, 0.0));
        let fs = m.flow_stress_slopes(0.2, cold, 0.0);
        assert_eq!(fs.g_temp, 0.0);
        assert!(fs.g.is_finite() && fs.g_eps.is_finite());
        assert_eq!(m.failure_strain(0.3, 1e3, cold), m.failure_strain(0.3, 1e3, m.room_temperature));
        let s = m.update(&state(uniaxial(1.1 * fs.g), 0.2, cold), &kin(diag(1e4, 0.0, 0.0), Tensor3::zeros(), 1e-8));
        assert!(is_finite(&s) && s.eps_p > 0.2 && s.temperature > cold);
    }

    #[test]
    fn melted_point_has_no_deviatoric_strength() {
        let m = weldox_460e();
        let mut tau = uniaxial(400e6) + identity() * 1e8;
        tau[(0, 1)] = 5e7;
        tau[(1, 0)] = 5e7;
        let mut d = diag(1e4, -2e3, 0.0);
        d[(0, 1)] = 3e3;
        d[(1, 0)] = 3e3;
        let mut w = Tensor3::zeros();
        w[(0, 1)] = 2e3;
        w[(1, 0)] = -2e3;
        let dt = 1e-8;
        for t in [m.melting_temperature, m.melting_temperature + 10.0] {
            let old = PointState { tau, eps_p: 0.5, eps_p_rate: 1e4, temperature: t, damage: 0.4 };
            let new = m.update(&old, &kin(d, w, dt));
            assert!(is_finite(&new));
            assert!(von_mises(&new.tau) <= 1e-15 * mean_stress(&new.tau).abs());
            let mean = 1e8 + dt * m.bulk_modulus() * d.trace();
            assert!(rel(mean_stress(&new.tau), mean) < 1e-14);
            let dd = deviator(&d);
            let eq = (2.0 / 3.0 * ddot(&dd, &dd)).sqrt();
            assert!(rel(new.eps_p - 0.5, dt * eq) < 1e-12);
            assert_eq!((new.temperature, new.damage), (t, 0.4));
        }
    }

    #[test]
    fn huge_overstress_is_finite_and_relaxes_monotonically() {
        for mut m in [weldox_460e(), weldox_460e_borvik()] {
            m.taylor_quinney = 0.0; // isolate the rate law from heating
            let g = m.flow_stress(0.1, 293.0, 0.0);
            let tau0 = 100.0 * g;
            // The uncapped law would overflow: exp(~8700) or (100)^(1/C) = 1e175…
            let pr = m.plastic_rate(tau0, g);
            assert!(pr.rate.is_finite() && pr.d_rate_d_tau.is_finite() && pr.rate > 0.0);
            let mut s = state(uniaxial(tau0), 0.1, 293.0);
            let k = kin(Tensor3::zeros(), Tensor3::zeros(), 1e-8);
            let mut previous = tau0;
            for step in 0..400 {
                let next = m.update(&s, &k);
                assert!(is_finite(&next), "{:?} step {step}", m.rate_form);
                let tau_bar = von_mises(&next.tau);
                assert!(tau_bar <= previous && tau_bar > 0.0, "{:?} step {step}: {tau_bar}", m.rate_form);
                assert!(next.eps_p >= s.eps_p);
                if step == 0 {
                    // The fallback's backward-Euler return: radial, and on the
                    // rate law at the step's mean plastic rate, g frozen.
                    let d_eps = next.eps_p - s.eps_p;
                    assert!((tau_bar + 3.0 * m.shear_modulus() * d_eps - tau0).abs() < 1e-9 * tau0);
                    let g_new = m.flow_stress(next.eps_p, 293.0, 0.0);
                    assert!(rel(tau_bar, g_new * m.rate_factor(d_eps / k.dt)) < 1e-9, "{tau_bar}");
                    assert!(tau_bar < m.max_overstress_ratio() * g_new);
                }
                previous = tau_bar;
                s = next;
            }
            // Below the cap the relaxation goes at the law's own (finite) pace.
            let g_end = m.flow_stress(s.eps_p, 293.0, 0.0);
            let ratio = previous / g_end;
            assert!(ratio > 1.0 && ratio < m.max_overstress_ratio(), "{:?}: {ratio}", m.rate_form);
        }
    }

    #[test]
    fn update_is_well_defined_when_tangent_modulus_is_negative() {
        // (a) Near melting with a large overstress: the thermal term dominates.
        let m = weldox_460e();
        let t = m.room_temperature + 0.9995 * (m.melting_temperature - m.room_temperature);
        let fs = m.flow_stress_slopes(0.3, t, 0.0);
        let tau_bar = 1e9;
        assert!(m.tangent_modulus(tau_bar, &fs) < 0.0);
        // (b) A small softening exponent just above room temperature, no overstress.
        let mut soft = weldox_460e();
        soft.softening_exponent = 0.2;
        let t_b = soft.room_temperature + 2.0 * HOMOLOGOUS_TEMPERATURE_FLOOR * 1507.0;
        let fs_b = soft.flow_stress_slopes(0.3, t_b, 0.0);
        assert!(soft.tangent_modulus(1.01 * fs_b.g, &fs_b) < 0.0);

        for (mat, temp, tb) in [(&m, t, tau_bar), (&soft, t_b, 1.01 * fs_b.g)] {
            for dt in [1e-9, 1e-7, 1e-5] {
                let old = state(uniaxial(tb), 0.3, temp);
                let d = diag(1e3, 0.0, 0.0);
                let new = mat.update(&old, &kin(d, Tensor3::zeros(), dt));
                assert!(is_finite(&new), "dt {dt}");
                assert!(new.eps_p_rate >= 0.0 && new.eps_p >= old.eps_p);
                assert!(new.temperature >= old.temperature);
                // Never reversed: the new deviator still points along the old one.
                let n_hat = deviator(&old.tau) * (1.5 / tb);
                assert!(ddot(&deviator(&new.tau), &n_hat) >= -1e-9 * tb, "dt {dt}");
            }
        }
        // (b) at a resolved step is the tangent update with ξ = 0, i.e.
        // ε̄̇_θ = ε̄̇ + θΔt f_τ P:d (Deviation 6), not a division by 1 + ξ < 1.
        let dt = 1e-7;
        let tb = 1.01 * fs_b.g;
        let new = soft.update(&state(uniaxial(tb), 0.3, t_b), &kin(diag(1e3, 0.0, 0.0), Tensor3::zeros(), dt));
        let pr = soft.plastic_rate(tb, fs_b.g);
        let p_d = 2.0 * soft.shear_modulus() * 1e3; // P:d for uniaxial n̂ and d
        let want = pr.rate + 0.5 * dt * pr.d_rate_d_tau * p_d;
        assert!(rel(new.eps_p_rate, want) < 1e-12, "{} vs {want}", new.eps_p_rate);
    }

    #[test]
    fn plastic_strain_never_decreases_on_unloading() {
        let m = weldox_460e();
        let g = m.flow_stress(0.1, 293.0, 0.0);
        let old = state(uniaxial(1.1 * g), 0.1, 293.0);
        let (d, dt) = (diag(-1e4, 0.0, 0.0), 1e-7);
        // Precondition: the unclamped linearised rate is negative here.
        let pr = m.plastic_rate(1.1 * g, g);
        let fs = m.flow_stress_slopes(0.1, 293.0, 0.0);
        let p_d = -2.0 * m.shear_modulus() * 1e4;
        let xi = 0.5 * dt * pr.d_rate_d_tau * m.tangent_modulus(1.1 * g, &fs);
        assert!((pr.rate + 0.5 * dt * pr.d_rate_d_tau * p_d) / (1.0 + xi) < 0.0);
        let new = m.update(&old, &kin(d, Tensor3::zeros(), dt));
        // The unloaded trial lies far below g, so the step is elastic
        // (Deviation 12): at most the log law's vanishing rate is booked.
        assert!(new.eps_p >= old.eps_p && new.eps_p - old.eps_p < 1e-12);
        assert!(new.eps_p_rate >= 0.0 && new.eps_p_rate < 1e-3);
        assert!(new.temperature >= old.temperature && new.temperature - old.temperature < 1e-6);
        assert!(new.damage >= old.damage && new.damage - old.damage < 1e-10);
        // and with the fast path bypassed the tangent clamp gives exactly zero
        let pr_old = m.plastic_rate(1.1 * g, g);
        let t = m.update_tangent(&old, &d, &Tensor3::zeros(), dt, &fs, &pr_old);
        assert_eq!(t.eps_p, old.eps_p);
        assert_eq!(t.eps_p_rate, 0.0);
    }

    #[test]
    fn first_step_from_rest_is_elastic() {
        let m = weldox_460e();
        let rest = PointState::at_rest(293.0);
        let mut d = diag(1e3, -300.0, 0.0);
        d[(0, 1)] = 100.0;
        d[(1, 0)] = 100.0;
        let new = m.update(&rest, &kin(d, Tensor3::zeros(), 1e-7));
        // Below the flow stress the log law's creep is ~e^(-26) 1/s.
        assert!(new.eps_p < 1e-15);
        assert!((new.tau - m.elastic_stress_rate(&d) * 1e-7).norm() <= 1e-9 * new.tau.norm());
        // Purely volumetric from rest: exactly elastic.
        let p = m.update(&rest, &kin(identity() * 1e3, Tensor3::zeros(), 1e-7));
        assert_eq!(p.eps_p, 0.0);
        assert_eq!(p.tau, identity() * (m.bulk_modulus() * 3e3 * 1e-7));
    }

    #[test]
    fn negligible_flow_fast_path_agrees_with_the_full_update() {
        // A point at 40 % of its flow stress loaded by a step whose elastic
        // increment exceeds its stress: without the fast path this step takes
        // the radial return (Deviation 11). Both must agree to the tolerance.
        let m = weldox_460e();
        let mut old = PointState::at_rest(m.room_temperature);
        old.tau[(0, 1)] = 0.4 * m.yield_stress / 3f64.sqrt();
        old.tau[(1, 0)] = old.tau[(0, 1)];
        let mut d = Tensor3::zeros();
        d[(0, 1)] = 2e4;
        d[(1, 0)] = 2e4;
        let dt = 4e-8;
        let k = kin(d, Tensor3::zeros(), dt);
        assert!(m.elastic_increment(&d, dt) > von_mises(&old.tau));
        let fs = m.flow_stress_slopes(old.eps_p, old.temperature, old.damage);
        let fast = m.negligible_flow_step(&old, &d, &k.w, dt, fs.g).expect("fast path applies");
        let full = m.radial_return(&old, &m.elastic_stress_rate(&d), &k.w, dt, &fs);
        let rel = (fast.tau - full.tau).norm() / full.tau.norm();
        assert!(rel < 1e-7, "relative stress difference {rel:e}");
        assert!(fast.eps_p >= old.eps_p && fast.eps_p - old.eps_p < 1e-12);
        // near the flow stress the fast path must step aside
        let mut near = old;
        near.tau *= 0.98 / 0.4;
        assert!(m.negligible_flow_step(&near, &d, &k.w, dt, fs.g).is_none());
    }

    /// Regression: the radial return from a zero deviator took the
    /// start-of-step triaxiality 0/0 = NaN, which the failure-strain floor
    /// turned into ε_f = 1e-6, i.e. D ≈ 300 after the first step.
    #[test]
    fn radial_return_from_rest_accumulates_ordinary_damage() {
        let m = weldox_460e();
        let mut l = Tensor3::zeros();
        l[(0, 1)] = 1e5;
        let k = kin(crate::math::sym(&l), crate::math::skew(&l), 1e-7);
        // Δγ = 1e-2, well beyond the yield strain: the step flows.
        assert!(m.elastic_increment(&k.d, k.dt) > m.yield_stress);
        let new = m.update(&PointState::at_rest(293.0), &k);
        assert!(new.eps_p > 1e-4);
        let triaxiality = mean_stress(&new.tau) / von_mises(&new.tau);
        let want = new.eps_p / m.failure_strain(triaxiality, new.eps_p_rate, 293.0);
        assert!(rel(new.damage, want) < 1e-12, "{} vs {want}", new.damage);
        assert!(m.failure_strain(Real::NAN, 1.0, 293.0).is_nan());
    }

    #[test]
    fn power_law_is_elastic_below_flow_stress() {
        let m = weldox_460e_borvik();
        let elastic = Elastic {
            density: m.density,
            youngs_modulus: m.youngs_modulus,
            poisson_ratio: m.poisson_ratio,
            room_temperature: m.room_temperature,
            thermal: None,
        };
        let g = m.flow_stress(0.2, 400.0, 0.0);
        let mut tau = uniaxial(0.5 * g) - identity() * 2e8;
        tau[(0, 1)] = 0.1 * g;
        tau[(1, 0)] = 0.1 * g;
        let old = state(tau, 0.2, 400.0);
        let mut w = Tensor3::zeros();
        w[(0, 1)] = 5e3;
        w[(1, 0)] = -5e3;
        let k = kin(diag(1e3, -500.0, -500.0), w, 1e-6);
        let new = m.update(&old, &k);
        let want = elastic.update(&old, &k);
        assert!(von_mises(&new.tau) < g);
        assert!((new.tau - want.tau).norm() <= 1e-12 * want.tau.norm());
        assert_eq!((new.eps_p, new.eps_p_rate, new.temperature, new.damage), (0.2, 0.0, 400.0, 0.0));
    }

    /// One step whose elastic predictor crosses `g` (from `τ̄ = g(1 − aC)`
    /// to a predictor of `g(1 + aC)`), against the same interval in 1000
    /// steps. The step is split at the crossing, so flow starts there and the
    /// error is that of the linearised rate over the plastic part, first order
    /// in the step (without the split the step would not flow at all).
    #[test]
    fn power_law_step_crossing_yield_matches_fine_steps() {
        let m = weldox_460e_borvik();
        let (eps, t) = (0.2, 293.0);
        let g = m.flow_stress(eps, t, 0.0);
        let c = m.rate_sensitivity;
        let rate = 1.0;
        let d = diag(rate, -0.5 * rate, -0.5 * rate);
        let error = |a: Real| {
            // Isochoric uniaxial: τ̄ rises at 3G·rate while elastic.
            let dt = 2.0 * a * c * g / (3.0 * m.shear_modulus() * rate);
            let old = state(uniaxial((1.0 - a * c) * g), eps, t);
            let coarse = m.update(&old, &kin(d, Tensor3::zeros(), dt));
            let mut fine = old;
            let n = 1000;
            for _ in 0..n {
                fine = m.update(&fine, &kin(d, Tensor3::zeros(), dt / n as Real));
            }
            let (dp_c, dp_f) = (coarse.eps_p - eps, fine.eps_p - eps);
            assert!(dp_f > 0.0 && dp_c > 0.0);
            assert!(rel(von_mises(&coarse.tau), von_mises(&fine.tau)) < 1e-6);
            rel(dp_c, dp_f)
        };
        let (e1, e2) = (error(0.4), error(0.2));
        assert!(e2 < 0.1, "{e2}");
        assert!((e1 / e2 - 2.0).abs() < 0.3, "order {} ({e1}, {e2})", e1 / e2);
    }

    #[test]
    fn damage_coupling_scales_flow_stress_only_when_on() {
        let mut m = weldox_460e();
        let g0 = m.flow_stress(0.2, 500.0, 0.0);
        assert_eq!(m.flow_stress(0.2, 500.0, 0.4), g0);
        m.damage_coupling = 1.0;
        assert!(rel(m.flow_stress(0.2, 500.0, 0.4), 0.6 * g0) < 1e-14);
        assert_eq!(m.flow_stress(0.2, 500.0, 1.3), 0.0);
        // A fully damaged coupled point carries no deviatoric stress.
        let old = PointState { damage: 1.0, ..state(uniaxial(g0), 0.2, 500.0) };
        let new = m.update(&old, &kin(diag(1e3, 0.0, 0.0), Tensor3::zeros(), 1e-7));
        assert_eq!(von_mises(&new.tau), 0.0);
        // Børvik's D_C = 0.3: 30 % of the flow stress gone when the locus is
        // used up (D = 1), 12 % at D = 0.4, and never more than 100 %.
        m.damage_coupling = 0.3;
        assert!(rel(m.flow_stress(0.2, 500.0, 0.4), 0.88 * g0) < 1e-14);
        assert!(rel(m.flow_stress(0.2, 500.0, 1.0), 0.7 * g0) < 1e-14);
        assert_eq!(m.flow_stress(0.2, 500.0, 4.0), 0.0);
    }

    #[test]
    fn damage_coupling_reads_a_critical_damage_or_the_old_switch() {
        let read = |value: &str| -> Result<Real, String> {
            let mut table: toml::Table = toml::to_string(&weldox_460e()).unwrap().parse().unwrap();
            table.remove("damage_coupling");
            // Before the table's sub-tables, so that it stays a top-level key.
            let text = format!("damage_coupling = {value}\n{}", toml::to_string(&table).unwrap());
            let m: JohnsonCook = toml::from_str(&text).map_err(|e| e.to_string())?;
            m.validate().map_err(|e| format!("{e:?}"))?;
            Ok(m.damage_coupling)
        };
        assert_eq!(read("0.3"), Ok(0.3));
        assert_eq!(read("1"), Ok(1.0));
        assert_eq!(read("true"), Ok(1.0));
        assert_eq!(read("false"), Ok(0.0));
        let err = read("1.5").unwrap_err();
        assert!(err.contains("damage_coupling"), "{err}");
        assert!(read("\"yes\"").is_err());
        // The damage-equivalent strain asks for a coupling.
        let m = JohnsonCook { damage_equivalent_strain: true, ..weldox_460e() };
        let err = format!("{:?}", m.validate().unwrap_err());
        assert!(err.contains("damage_equivalent_strain"), "{err}");
        assert!(JohnsonCook { damage_coupling: 0.3, ..m }.validate().is_ok());
    }

    #[test]
    fn damage_equivalent_strain_scales_the_increments_of_hardening_and_damage() {
        // One plastic step from a damaged state: over r, the increments of
        // eps_p and D are those over eps times (1 − D_C D), the stress the
        // same to the hardening's change.
        let base = JohnsonCook { damage_coupling: 0.3, ..weldox_460e() };
        let over_r = JohnsonCook { damage_equivalent_strain: true, ..base.clone() };
        let g = base.flow_stress(0.2, 500.0, 0.5);
        let old = PointState { damage: 0.5, ..state(uniaxial(g), 0.2, 500.0) };
        let k = kin(diag(1e4, -5e3, -5e3), Tensor3::zeros(), 1e-8);
        let (a, b) = (base.update(&old, &k), over_r.update(&old, &k));
        let factor = 1.0 - 0.3 * 0.5;
        assert!(a.eps_p > old.eps_p && a.damage > old.damage);
        assert!(rel(b.eps_p - old.eps_p, factor * (a.eps_p - old.eps_p)) < 1e-3, "{} {}", b.eps_p, a.eps_p);
        assert!(rel(b.damage - old.damage, factor * (a.damage - old.damage)) < 1e-3);
        assert!(rel(b.eps_p_rate, a.eps_p_rate) < 1e-3, "the rate stays that of eps");
        assert!(rel(von_mises(&b.tau), von_mises(&a.tau)) < 1e-6);
    }

    #[test]
    fn thermal_expansion_term_gives_the_pressure_of_constrained_heating() {
        // Isochoric shear heats the point; the term 3Kα Ṫ I of τ^∇ is then the
        // only source of mean stress: tr τ/3 = −3Kα ΔT exactly.
        for alpha in [0.0, 11.2e-6] {
            let mut m = weldox_460e();
            m.thermal_expansion = alpha;
            let mut l = Tensor3::zeros();
            l[(0, 1)] = 1e4;
            let k = kin(crate::math::sym(&l), crate::math::skew(&l), 1e-7);
            let mut s = PointState::at_rest(293.0);
            for _ in 0..500 {
                s = m.update(&s, &k);
            }
            let dt_heat = s.temperature - 293.0;
            assert!(dt_heat > 50.0);
            let want = -3.0 * m.bulk_modulus() * alpha * dt_heat;
            assert!((mean_stress(&s.tau) - want).abs() <= 1e-9 * want.abs().max(1.0), "α {alpha}");
        }
    }

    #[test]
    fn isothermal_when_taylor_quinney_is_zero() {
        let mut m = weldox_460e();
        m.taylor_quinney = 0.0;
        let g = m.flow_stress(0.2, 293.0, 0.0);
        let new = m.update(&state(uniaxial(1.1 * g), 0.2, 293.0), &kin(diag(1e4, 0.0, 0.0), Tensor3::zeros(), 1e-7));
        assert!(new.eps_p > 0.2);
        assert_eq!(new.temperature, 293.0);
    }

    #[test]
    fn validate_lists_every_bad_parameter() {
        let mut m = weldox_460e();
        assert_eq!(m.validate(), Ok(()));
        m.poisson_ratio = 0.5;
        m.melting_temperature = 200.0;
        m.theta = 1.5;
        m.damage.d2 = Real::NAN;
        let names: Vec<&str> = m.validate().unwrap_err().iter().map(|e| e.parameter).collect();
        assert_eq!(names, ["poisson_ratio", "melting_temperature", "damage.d2", "theta"]);
        let mut c = weldox_460e();
        for (cut, ok) in [(-1.0 / 3.0, true), (0.0, true), (0.1, false), (Real::NEG_INFINITY, false)] {
            c.damage.cutoff_triaxiality = Some(cut);
            let names: Vec<&str> = c.validate().err().unwrap_or_default().iter().map(|e| e.parameter).collect();
            assert_eq!(names.is_empty(), ok, "cut-off {cut}: {names:?}");
            assert!(ok || names == ["damage.cutoff_triaxiality"]);
        }
        // Cockcroft–Latham's work: positive and finite, and not with a
        // cut-off (its ⟨σ₁⟩ is one).
        let mut w = weldox_460e();
        for (wc, ok) in [(1.7e9, true), (0.0, false), (-1.0, false), (Real::INFINITY, false), (Real::NAN, false)] {
            w.damage.cockcroft_latham = Some(wc);
            let names: Vec<&str> = w.validate().err().unwrap_or_default().iter().map(|e| e.parameter).collect();
            assert_eq!(names.is_empty(), ok, "W_c {wc}: {names:?}");
            assert!(ok || names == ["damage.cockcroft_latham"]);
        }
        w.damage.cockcroft_latham = Some(1.7e9);
        w.damage.cutoff_triaxiality = Some(-1.0 / 3.0);
        let names: Vec<&str> = w.validate().unwrap_err().iter().map(|e| e.parameter).collect();
        assert_eq!(names, ["damage.cutoff_triaxiality"]);
    }

    #[test]
    fn power_upper_bound_is_a_bound() {
        let mut seed = 5u64;
        let mut r = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as Real / (1u64 << 53) as Real
        };
        for _ in 0..100_000 {
            let x = (r() * -700.0).exp2() * (0.5 + 0.5 * r());
            let p = 0.05 + 3.0 * r();
            if !(x > 0.0 && x < 1.0) {
                continue;
            }
            let (exact, bound) = (x.powf(p), power_upper_bound(x, p));
            assert!(bound >= exact, "{x:e}^{p}: {bound:e} < {exact:e}");
            assert!(
                bound <= (p + 2.0).exp2() * exact || bound == Real::MIN_POSITIVE,
                "{x:e}^{p}: {bound:e} vs {exact:e}"
            );
        }
        assert_eq!(power_upper_bound(0.75, 0.94), 1.0);
        assert!(power_upper_bound(1e-300, 5.0) > 0.0);
    }

    /// Deviation 13 against the full update (which takes Deviation 12 there):
    /// random far-field states of Weldox, stressed below the cut, at room
    /// temperature and heated, damaged or not. The stress is the same to the
    /// bit; only a creep below `Δt ε̇₀ e⁻⁵⁰` is left unbooked.
    /// The block-form elastic trial (the hot path of every update) has the
    /// bits of the nine-entry expression, for random block tensors with
    /// signed zeros; a tensor without the block form takes the general path.
    #[test]
    fn block_elastic_trial_has_the_same_bits() {
        let m = weldox_460e();
        let mut r = crate::math::bit_test_entries(3, 1.0);
        let bits = |t: &Tensor3| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for k in 0..20_000 {
            let mut block = |scale: Real| {
                let mut t = Tensor3::zeros();
                for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1), (2, 2)] {
                    t[(i, j)] = r() * scale;
                }
                t
            };
            let (tau, d, w) = (block(1e9), block(1e5), block(1e5));
            let kin = StepKinematics { d, w, dt: if k % 7 == 0 { 0.0 } else { 4e-8 } };
            let (t, tau_bar) = m.elastic_trial(&tau, &kin);
            let reference = jaumann_update(&tau, &m.elastic_stress_rate(&d), &w, kin.dt);
            assert_eq!(bits(&t), bits(&reference));
            assert_eq!(tau_bar.to_bits(), von_mises(&reference).to_bits());
            assert_eq!(von_mises_2d(&tau).to_bits(), von_mises(&tau).to_bits());
        }
        let mut full = uniaxial(3e8);
        full[(0, 2)] = 1e7;
        let kin = StepKinematics { d: diag(1e3, -5e2, -5e2), w: Tensor3::zeros(), dt: 4e-8 };
        let reference = jaumann_update(&full, &m.elastic_stress_rate(&kin.d), &kin.w, kin.dt);
        assert_eq!(m.elastic_trial(&full, &kin), (reference, von_mises(&reference)));
    }

    #[test]
    fn negligible_creep_fast_path_agrees_with_the_full_update() {
        let m = weldox_460e();
        let mut seed = 9u64;
        let mut r = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as Real / (1u64 << 53) as Real
        };
        let dt = 4e-8;
        let creep = m.reference_strain_rate * NEGLIGIBLE_CREEP_EXPONENT.exp();
        let mut taken = 0;
        for i in 0..20_000 {
            let temperature = if i % 3 == 0 { 293.0 } else { 293.0 + 10f64.powf(-12.0 + 14.5 * r()) };
            let eps_p = if i % 2 == 0 { 0.0 } else { 10f64.powf(-30.0 + 29.5 * r()) };
            let mut tau = identity() * (2e8 * (r() - 0.5));
            tau[(0, 0)] += 3e8 * (r() - 0.5);
            tau[(0, 1)] = 1.5e8 * (r() - 0.5);
            tau[(1, 0)] = tau[(0, 1)];
            let old = PointState { tau, eps_p, eps_p_rate: 0.0, temperature, damage: 0.1 * r() };
            let mut d = diag(2e3 * (r() - 0.5), 2e3 * (r() - 0.5), 0.0);
            d[(0, 1)] = 1e3 * (r() - 0.5);
            d[(1, 0)] = d[(0, 1)];
            let mut w = Tensor3::zeros();
            w[(0, 1)] = 1e3 * (r() - 0.5);
            w[(1, 0)] = -w[(0, 1)];
            let k = kin(d, w, dt);
            let trial = jaumann_update(&old.tau, &m.elastic_stress_rate(&d), &w, dt);
            let g = m.flow_stress(eps_p, temperature, old.damage);
            let exponent = (von_mises(&trial) / g - 1.0) / m.rate_sensitivity;
            let fast = m.creep_is_negligible(&old, von_mises(&trial), dt);
            // never taken above the cut (g_lo <= g)
            assert!(!fast || exponent <= NEGLIGIBLE_CREEP_EXPONENT, "{exponent}");
            if !fast {
                continue;
            }
            taken += 1;
            let new = m.update(&old, &k);
            let full = m.negligible_flow_step(&old, &d, &w, dt, g).expect("Deviation 12 applies below the cut");
            assert_eq!(new.tau, full.tau);
            assert_eq!((new.eps_p, new.temperature, new.damage, new.eps_p_rate), (eps_p, temperature, old.damage, 0.0));
            assert!(full.eps_p_rate <= creep * (1.0 + 1e-12), "{:e}", full.eps_p_rate);
            assert!(full.eps_p - eps_p <= dt * creep * (1.0 + 1e-12));
            assert!(full.damage - old.damage <= dt * creep / MIN_FAILURE_STRAIN);
            assert!((full.temperature - temperature).abs() <= 1e-20);
        }
        // the cut is reached by most of these states (the bound is tight)
        assert!(taken > 8_000, "{taken}");
        // and a point near its flow stress is not taken
        let near = state(uniaxial(0.6 * m.yield_stress), 0.0, 293.0);
        assert!(!m.creep_is_negligible(&near, 0.6 * m.yield_stress, dt));
    }
}
