//! Constitutive models: the per-quadrature-point stress update (SPEC §6).
//!
//! A model is a small pure function `(parameters, old state, rate of
//! deformation, Δt) → new state`, behind the [`Constitutive`] trait. The
//! solver only ever sees [`Material`], an enum over the models, so that case
//! files stay serializable and the hot loop stays monomorphic.

pub mod elastic;
pub mod johnson_cook;
pub mod library;

pub use elastic::Elastic;
pub use johnson_cook::JohnsonCook;

use crate::math::{mul_2d, Real, Tensor3};

/// State carried by a quadrature point from step to step (SPEC §4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointState {
    /// Kirchhoff stress `τ = J σ`, Pa.
    pub tau: Tensor3,
    /// Equivalent plastic strain `ε̄`, dimensionless.
    pub eps_p: Real,
    /// Equivalent plastic strain rate `ε̄̇` of the last step, 1/s.
    pub eps_p_rate: Real,
    /// Temperature, K.
    pub temperature: Real,
    /// Johnson–Cook damage `D` (0 = intact, 1 = failed).
    pub damage: Real,
}

impl PointState {
    /// A stress-free, undamaged point at temperature `t0`.
    pub fn at_rest(t0: Real) -> Self {
        Self { tau: Tensor3::zeros(), eps_p: 0.0, eps_p_rate: 0.0, temperature: t0, damage: 0.0 }
    }
}

/// The kinematic input of one update: rate of deformation `d = sym ℓ`,
/// spin `w = skw ℓ` (both at mid-step, 1/s) and the step `Δt` (s).
#[derive(Clone, Copy, Debug)]
pub struct StepKinematics {
    pub d: Tensor3,
    pub w: Tensor3,
    pub dt: Real,
}

/// Thermal constants a material provides to heat conduction (SPEC §7).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalProperties {
    /// Specific heat `C_p`, J/(kg K).
    pub specific_heat: Real,
    /// Conductivity `κ`, W/(m K).
    pub conductivity: Real,
}

/// What the solver asks of a material at each quadrature point.
pub trait Constitutive {
    /// Advance the point's state over one step. Pure: no side effects.
    fn update(&self, old: &PointState, k: &StepKinematics) -> PointState;
    /// Reference mass density `ρ₀`, kg/m³.
    fn density(&self) -> Real;
    /// Bulk modulus `K`, Pa.
    fn bulk_modulus(&self) -> Real;
    /// Shear modulus `G`, Pa.
    fn shear_modulus(&self) -> Real;
    /// Initial (room) temperature, K.
    fn initial_temperature(&self) -> Real;
    /// Thermal constants, if the model carries them.
    fn thermal(&self) -> Option<ThermalProperties>;
    /// Elastic longitudinal (dilatational) wave speed `c_L = sqrt((K + 4G/3)/ρ₀)`,
    /// the speed that limits the explicit time step (SPEC §5).
    fn longitudinal_wave_speed(&self) -> Real {
        ((self.bulk_modulus() + 4.0 * self.shear_modulus() / 3.0) / self.density()).sqrt()
    }
}

/// Whether a point with Johnson–Cook damage `damage` is fractured by the
/// damage model's own measure (`D ≥ 1`): while cracks grow, such a point
/// carries only pressure, and only while closed ([`fractured`]).
#[inline]
pub fn is_fractured(damage: Real) -> bool {
    damage >= 1.0
}

/// One step's share of `∫ η dε̄`, the stress triaxiality integrated over
/// the plastic strain path ([`crate::quadrature::QuadraturePoints::triaxiality_strain`]):
/// the end-of-step triaxiality `η = τ_m/τ̄` of the Kirchhoff stress `tau`
/// (the ratio is the same for Cauchy's) times the step's plastic strain
/// increment `d_eps`; zero where the point did not flow or carries no
/// deviator. Divided by `ε̄` the sum is the average triaxiality of the
/// strain path, the measure Bao and Wierzbicki's cut-off at `η = −1/3`
/// is stated in (Bao & Wierzbicki 2005); the damage itself integrates
/// the locus at the current `η`.
#[inline]
pub fn strain_path_increment(tau: &Tensor3, d_eps: Real) -> Real {
    if d_eps <= 0.0 {
        return 0.0;
    }
    let tau_bar = crate::math::von_mises_2d(tau);
    if tau_bar > 0.0 {
        crate::math::mean_stress(tau) / tau_bar * d_eps
    } else {
        0.0
    }
}

/// A point whose Johnson–Cook damage has reached 1 — fractured by the
/// damage model's own measure — carries no shear and no tension, and
/// carries pressure only while it is **closed**: its Kirchhoff stress is
/// reduced to its compressive mean part, `τ → min(τ_m, 0) I`, if its volume
/// ratio `J = det F < 1`, and to zero otherwise. Only pressure from closing
/// material remains.
///
/// Deviation from SPEC §6 (which carries no such rule; \[RL10\] uses `D`
/// only as a crack criterion): cracks advance by one particle per step at
/// most and wait for the material ahead of the tip to meet the crack
/// criterion; meanwhile the opening crack stretches the points just ahead
/// of the tip. In the Borvik plane-strain Case I with the damage criterion
/// the tip waited 2 µs for `D ≥ 0.5` ahead of it while points behind it
/// reached `D ≈ 4` and a volume ratio `J = 1.8`; their stress, held by
/// nothing but the material model, blew the run up at 5 µs. The same rule
/// is element erosion at `D = 1` in LS-DYNA's and Abaqus's Johnson–Cook
/// failure, here without deleting the point (the crack algorithm decides
/// where the body separates). The solver applies it to every point's
/// update while crack growth is on (`Simulation::update_material`), except
/// with the non-local criterion unless asked
/// (`FractureParameters::fractures_points`); the
/// models and the material-point driver stay the models of SPEC §6.
///
/// # Deviations
/// - **Open fractured material pushes nothing** (`J ≥ 1`: no stress at
///   all). The rate form `τ̇_m = K tr d` measures pressure from the last
///   state, not from the closed one: a fractured point stretched to
///   `J = 1.16` and then squeezed by 1 % carried a pressure of
///   `K · 0.01 ≈ 1.7 GPa`, as if its voids had closed. Such a point is a
///   spring that pushes and never pulls, with its rest length reset to
///   its largest stretch: in the coarse plane-strain Borvik Case I the
///   surface particles beside the projectile's corners, torn off the
///   plate at ~400 m/s, were pushed on by the opened, fractured points
///   between them and the plate to 650–700 m/s and flew 80 mm above it
///   (the crack polylines with them). With the closure condition they
///   keep the speed they had when they were torn off
///   (`fractured_points_carry_only_compression`,
///   `open_fractured_material_does_not_push` in tests/material.rs,
///   `no_particle_leaves_faster_than_the_rear_face_doubling` in
///   tests/ejection.rs).
#[inline]
pub fn fractured(mut s: PointState, jacobian: Real) -> PointState {
    if is_fractured(s.damage) {
        let mean = if jacobian < 1.0 { s.tau.trace() / 3.0 } else { 0.0 };
        s.tau = Tensor3::identity() * mean.min(0.0);
    }
    s
}

/// Volume ratio `J` beyond which a fractured point (`D ≥ 1`, while cracks
/// grow) is torn open: the solver erodes it, and it carries no stress from
/// then on, closed or not.
///
/// # Deviations
/// [`fractured`] lets an opened point carry pressure again once it closes
/// (`J < 1`). Material that has opened by 5 % in volume is no continuum any
/// more: the particles its deformation gradient is interpolated from have
/// been torn apart, `F` is nearly singular (in the coarse axisymmetric
/// Borvik Case I at 72 µs, points behind the ring crack had `J` from 1.09
/// to 13 and singular-value ratios of `F` up to 1,000), and its `J`, a
/// difference of large products, can swing from above 1 to near 0 in one
/// step of an ordinary displacement. There the closure pressure
/// `K |ln J|` reached hundreds of GPa: a surface particle beside the crack
/// took 3·10⁸ N in one step at 98 µs, and the energy balance went from
/// 8.7 kJ to 518 kJ (an energy blow-up, with the step of
/// [`crate::stability`]; the fixed step of the spacing had missed it by
/// chance). A torn point's closure is the meeting of two crack faces,
/// which is contact's work, not the point's. 5 % is far beyond the elastic
/// dilatation of steel (`p/K ≈ 1 GPa / 167 GPa = 0.6 %`), so no intact or
/// merely damaged point is eroded by it. Test:
/// `torn_fractured_points_are_eroded` (tests/fracture.rs).
pub const TORN_VOLUME_RATIO: Real = 1.05;

/// Every constitutive model the solver knows.
#[derive(Clone, Debug, PartialEq)]
pub enum Material {
    /// Hypoelastic, Jaumann rate.
    Elastic(Elastic),
    /// Johnson–Cook thermo-viscoplasticity with Johnson–Cook damage.
    JohnsonCook(JohnsonCook),
}

impl Material {
    /// The hypoelastic material with this one's density, moduli, room
    /// temperature and thermal constants (itself if already elastic): what
    /// the model would be without plasticity, thermal softening or damage.
    /// For measurements (`plugsim bench`'s material floor) and tests.
    pub fn elastic_twin(&self) -> Material {
        match self {
            Material::Elastic(_) => self.clone(),
            Material::JohnsonCook(m) => Material::Elastic(Elastic {
                density: m.density,
                youngs_modulus: m.youngs_modulus,
                poisson_ratio: m.poisson_ratio,
                room_temperature: m.room_temperature,
                thermal: m.thermal(),
            }),
        }
    }

    /// [`JohnsonCook::adiabatic_hardening`] of a point in this material at
    /// plastic strain `eps_p`, `temperature`, `damage` and plastic rate
    /// `rate`; `None` for an elastic material (no flow stress).
    pub fn adiabatic_hardening(&self, eps_p: Real, temperature: Real, damage: Real, rate: Real) -> Option<Real> {
        match self {
            Material::Elastic(_) => None,
            Material::JohnsonCook(m) => Some(m.adiabatic_hardening(eps_p, temperature, damage, rate)),
        }
    }
}

impl Constitutive for Material {
    #[inline]
    fn update(&self, old: &PointState, k: &StepKinematics) -> PointState {
        match self {
            Material::Elastic(m) => m.update(old, k),
            Material::JohnsonCook(m) => m.update(old, k),
        }
    }
    fn density(&self) -> Real {
        match self {
            Material::Elastic(m) => m.density(),
            Material::JohnsonCook(m) => m.density(),
        }
    }
    fn bulk_modulus(&self) -> Real {
        match self {
            Material::Elastic(m) => m.bulk_modulus(),
            Material::JohnsonCook(m) => m.bulk_modulus(),
        }
    }
    fn shear_modulus(&self) -> Real {
        match self {
            Material::Elastic(m) => m.shear_modulus(),
            Material::JohnsonCook(m) => m.shear_modulus(),
        }
    }
    fn initial_temperature(&self) -> Real {
        match self {
            Material::Elastic(m) => m.initial_temperature(),
            Material::JohnsonCook(m) => m.initial_temperature(),
        }
    }
    fn thermal(&self) -> Option<ThermalProperties> {
        match self {
            Material::Elastic(m) => m.thermal(),
            Material::JohnsonCook(m) => m.thermal(),
        }
    }
}

/// Isotropic elastic constants from Young's modulus and Poisson's ratio:
/// `(K, G) = (E / (3(1 − 2ν)), E / (2(1 + ν)))`. The one place both models
/// take them from.
#[inline]
pub fn isotropic_moduli(youngs_modulus: Real, poisson_ratio: Real) -> (Real, Real) {
    (youngs_modulus / (3.0 * (1.0 - 2.0 * poisson_ratio)), youngs_modulus / (2.0 * (1.0 + poisson_ratio)))
}

/// Objective (Jaumann) update `τ ← τ + Δt (τ^∇ + w τ − τ w)` (SPEC §6, last
/// line of the tangent update). The single place where the Jaumann rate is
/// integrated, shared by every model.
#[inline]
pub fn jaumann_update(tau: &Tensor3, tau_rate_objective: &Tensor3, w: &Tensor3, dt: Real) -> Tensor3 {
    // The block form of 2D kinematics saves most products (same bits).
    tau + (tau_rate_objective + mul_2d(w, tau) - mul_2d(tau, w)) * dt
}

/// A built-in material by name (see [`library`]), if one exists.
pub fn builtin(name: &str) -> Option<Material> {
    library::builtin(name)
}

/// Names of the built-in materials.
pub fn builtin_names() -> Vec<&'static str> {
    library::NAMES.to_vec()
}
