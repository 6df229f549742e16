//! Heat conduction by operator split (SPEC §7, \[RL10\] Eqs. (2.14)–(2.21),
//! (2.33)–(2.36)).
//!
//! Each time step is an adiabatic mechanical phase — the material update
//! raises the quadrature-point temperatures by the plastic work (SPEC §6) —
//! followed by this conduction phase at fixed configuration:
//!
//! 1. **Projection.** Particle temperatures are the lumped projection of the
//!    quadrature temperatures, with the capacity weights
//!    `T_I = Σ_q ρ₀ C_p φ_I(X_q) w_q T_q / c_I` and the *transfer weights*
//!    `φ_I = max(N_I, 0) / Σ_J max(N_J, 0)` ([`transfer_weight`]: the
//!    positive part of the RK functions, again a partition of unity; see
//!    the deviations for why not `N_I`).
//! 2. **Conduction.** `C Ṫ = −H T` \[RL10, Eqs. (2.33)–(2.36)\] with the lumped
//!    capacity and the total-Lagrangian conductivity matrix
//!    ```text
//!    c_I  = Σ_q ρ₀ C_p φ_I(X_q) w_q
//!    H_IJ = Σ_q κ J (F⁻¹F⁻ᵀ ∇_X N_I)·∇_X N_J w_q
//!    ```
//!    applied matrix-free: per quadrature point the nominal flux
//!    `q_q = −κ J C⁻¹ ∇_X T(X_q)` (`C = FᵀF`) with `∇_X T(X_q) = Σ_J ∇_X N_J T_J`,
//!    then per particle `(H T)_I = −Σ_q ∇_X N_I · q_q w_q`, gathered over
//!    [`Model::gather`] in its fixed entry order — no two threads write one
//!    particle and the result is bit-identical for any thread count. There is
//!    no boundary term: no flux through outer boundaries (the natural
//!    boundary condition of the Galerkin form).
//! 3. **Sub-cycled explicit Euler** `T_I ← T_I + δt (−H T)_I / c_I` with
//!    `δt = Δt / n`, `n = ⌈Δt / Δt_th⌉` (see [`HeatConduction::stable_time_step`]).
//! 4. **Back to the quadrature points.** Only the conduction increment is
//!    interpolated, `T_q ← T_q + Σ_I φ_I(X_q) ΔT_I`, so the part of the
//!    adiabatic field below the particle resolution (a shear band narrower
//!    than the spacing) is neither smeared nor lost by the projection round
//!    trip: with `κ = 0` the quadrature temperatures are unchanged bit for
//!    bit (test `zero_conductivity_leaves_quadrature_temperatures_untouched`).
//!
//! **Conservation.** `Σ_I H_IJ = 0` because `Σ_I ∇N_I = 0` at every point
//! (partition of unity), so every sub-step keeps `Σ_I c_I T_I`, and since
//! `c_I = Σ_q ρ₀ C_p φ_I w_q` the interpolated increment changes the heat of
//! the quadrature points by `Σ_q ρ₀ C_p w_q Σ_I φ_I ΔT_I = Σ_I c_I ΔT_I = 0`:
//! both `Σ_I c_I T_I` and `Σ_q ρ₀ C_p w_q T_q` are conserved to round-off.
//! The second is the one that persists from step to step (the quadrature
//! points own the temperature); test
//! `tests/thermal.rs::closed_body_conserves_heat_over_many_substeps`.
//!
//! In axisymmetry the weights `w_q` already carry `2πR_q` and the gradient is
//! the in-plane one: an axisymmetric field has no hoop gradient, so there is
//! no hoop conduction (test
//! `tests/thermal.rs::axisymmetric_r_squared_heats_at_four_alpha`).
//!
//! Bodies whose material has no thermal properties are skipped: their
//! particles and points are not touched.
//!
//! # Deviations
//! - \[RL10\] does not say how the conduction phase is integrated in time; we
//!   use forward Euler, sub-cycled below a *guaranteed* stability bound
//!   (Gershgorin, see [`HeatConduction::stable_time_step`]) rather than the
//!   grid estimate `h² ρ C_p / (2 d κ)`, which is not a bound for RK shape
//!   functions near boundaries. Tests `stability_bound_dominates_the_largest_eigenvalue`,
//!   `tests/thermal.rs::sub_cycling_keeps_large_steps_stable_and_relaxes_to_the_mean`.
//! - **Positive transfer weights** (since 2026-11-26; before, `φ = N`, the
//!   RK functions themselves, and `c_I = C_p m_I`). With `N`, the round trip
//!   point → particle → point is `P N` with `P = M_L⁻¹ M_c` in effect
//!   (`M_L = Σ_q N_I w_q` lumped, `M_c = Σ_q N_I N_J w_q` consistent), and a
//!   phase multiplies the conducted increment by the eigenvalues of
//!   `M_L⁻¹ M_c` — at most 1 for positive functions, but RK functions take
//!   both signs, and a particle whose support a crack split has cut can be
//!   left with `Σ_q N_I w_q` a few per cent of `Σ_q N_I² w_q`. Its mode then
//!   grows by that ratio times `λΔt` every phase, and no sub-cycling cures
//!   it (the round trip is per phase, not per sub-step). Found on Case I's
//!   plate, 48 rows, `ℓ = 2 mm`, 150 m/s: one split particle's temperature
//!   grew tenfold per µs from 44 µs, `−3·10¹³ K` at 44 µs and an overflow
//!   at 97 µs; six of ~250 stored runs had such temperatures, none before
//!   the result that docs/validation.md reports was decided, except in one
//!   run of a trial that was not kept (its section "Temperatures that grew
//!   without bound after a crack split"). With `φ ≥ 0` the rows of
//!   `M_L⁻¹ M_c` sum to 1 with no negative entry, so its eigenvalues lie in
//!   `(0, 1]` and, with the sub-cycled Euler's factors in `[0, 1]`, a
//!   phase cannot amplify anything. Conservation is untouched (it needs
//!   only `c_I = Σ_q ρ₀ C_p φ_I w_q`), and so is `H` (the RK gradients).
//!   The capacities are formed each phase from the table (a pass over its
//!   entries), so a split's rebuild is always seen; they are not stored
//!   (house rule: no private per-particle state). Tests
//!   `a_particle_with_a_small_lumped_weight_does_not_amplify_the_round_trip`
//!   (with `N`: ×10 per phase; with `φ`: bounded), `capacity_is_the_row_sum`,
//!   and the analytic ones of `tests/thermal.rs`, unchanged.
//! - Temperature changes by conduction do not enter the thermal strain rate
//!   `d^T = α Ṫ I` of the material update (SPEC §6), which sees only the
//!   adiabatic `Ṫ` of its own step; the conducted `ΔT` reaches the stress
//!   through the temperature-dependent flow stress from the next step on.
//!   With κ = 50 W/(m K) the conducted `ΔT` over an impact (diffusion length
//!   ~40 µm in 100 µs) is far below the adiabatic one.

use crate::material::Constitutive;
use crate::math::{Real, Tensor3, Vec2};
use crate::model::{Gather, Model, PARALLEL_PIECE};
use crate::shape::ShapeTable;
use nalgebra::Matrix2;
use rayon::prelude::*;

/// Default conduction safety factor `s` in `Δt_th = s · 2 / λ̂`: 0.5 keeps
/// `λ δt ≤ 1` for every mode of `C⁻¹H`, so forward Euler damps every mode
/// monotonically (amplification `1 − λδt ∈ [0, 1]`) instead of letting the
/// stiffest ones flip sign each sub-step — no spurious temperature
/// oscillations (undershoots below room temperature are a Johnson–Cook
/// pitfall, SPEC §6). Conduction in steel is so slow that the mechanical step
/// is far below this limit anyway (κ = 50 W/(m K), h = 0.5 mm: `Δt_th` ≈ 1 ms
/// against a mechanical step of ~40 ns), so the factor only matters for
/// exaggerated conductivities.
pub const DEFAULT_SAFETY_FACTOR: Real = 0.5;

/// Errors of the conduction phase.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HeatError {
    /// A body's thermal constants cannot be used.
    #[error("body '{body}': {message}")]
    InvalidMaterial { body: String, message: String },
    /// The sub-step safety factor is outside (0, 1].
    #[error("heat conduction safety factor must lie in (0, 1], got {0}")]
    InvalidSafetyFactor(Real),
    /// `F` cannot be inverted at a conducting quadrature point.
    #[error(
        "deformation gradient not invertible (J = {jacobian:.3e}) at quadrature point {point}: conduction needs F^-1"
    )]
    Inverted { point: usize, jacobian: Real },
    /// A temperature became NaN or infinite.
    #[error("non-finite temperature at quadrature point {point} after conduction")]
    NonFinite { point: usize },
}

/// Thermal constants of one conducting body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyThermal {
    /// `C_p`, J/(kg K).
    pub specific_heat: Real,
    /// `κ`, W/(m K).
    pub conductivity: Real,
    /// `ρ₀`, kg/m³ (the body's reference density).
    pub density: Real,
}

/// What one conduction phase did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeatReport {
    /// Sub-steps taken.
    pub substeps: usize,
    /// Stable conduction step `Δt_th` at this configuration, s (infinite when
    /// nothing conducts).
    pub stable_dt: Real,
}

/// The conduction phase of SPEC §7. Holds the per-body thermal constants
/// and scratch; all per-particle and per-point state lives in the
/// [`Model`]'s stores (particle temperature, lumped mass, quadrature
/// temperature), so nothing here goes stale when particles are split.
/// Scratch is resized on every call if the stores changed size and carries
/// nothing from one call to the next.
#[derive(Clone, Debug)]
pub struct HeatConduction {
    /// Per body (index = body number); `None`: the body does not conduct.
    pub bodies: Vec<Option<BodyThermal>>,
    /// `s` in `Δt_th = s · 2 / λ̂`, in (0, 1]; see [`DEFAULT_SAFETY_FACTOR`].
    pub safety_factor: Real,
    /// What the last call did.
    pub last: HeatReport,
    scratch: Scratch,
    /// The reference factor of [`Self::quick_stable_step`] and the state
    /// it was computed for.
    reference: Option<(ReferenceSignature, Real)>,
}

/// What the reference factor of [`HeatConduction::quick_stable_step`]
/// depends on, cheaply: the sizes of the stores and the table, and hashes of
/// the capacities and the table's row starts. A crack split adds
/// particles; its local rebuild changes rows, shape values and so the
/// capacities of the particles it touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ReferenceSignature {
    particles: usize,
    points: usize,
    entries: usize,
    capacities: u64,
    rows: u64,
}

impl ReferenceSignature {
    fn of(model: &Model, capacity: &[Real]) -> Self {
        let hash = |it: &mut dyn Iterator<Item = u64>| {
            it.fold(0xcbf29ce484222325u64, |h, x| (h ^ x).wrapping_mul(0x100000001b3).rotate_left(5))
        };
        ReferenceSignature {
            particles: model.particles.len(),
            points: model.quad.len(),
            entries: model.qp_shape.nnz(),
            capacities: hash(&mut capacity.iter().map(|c| c.to_bits())),
            rows: hash(&mut model.qp_shape.offsets.iter().map(|&o| o as u64)),
        }
    }
}

#[derive(Clone, Debug, Default)]
struct Scratch {
    /// Per point: `κ J C⁻¹ w_q` (in-plane block), W·m/K (per unit depth in
    /// plane strain); zero if not conducting.
    kw: Vec<Matrix2<Real>>,
    /// Per point: `q_q w_q = −κ J C⁻¹ ∇_X T w_q`.
    flux: Vec<Vec2>,
    /// Per point: `Σ_J |∇N_J|_{Kw}` (stability bound).
    row_norm: Vec<Real>,
    /// Per point: `s_q = Σ_J max(N_J(X_q), 0)`, the normalizer of the
    /// transfer weights ([`transfer_weight`]).
    positive: Vec<Real>,
    /// Per particle: heat capacity `c_I = ρ₀ C_p Σ_q φ_I(X_q) w_q`, J/K
    /// (per unit depth in plane strain); zero outside conducting bodies.
    capacity: Vec<Real>,
    /// Per particle: temperature at the start of the phase.
    start: Vec<Real>,
    /// Per particle: accumulated conduction increment `ΔT_I`.
    delta: Vec<Real>,
    /// Per particle: `−(H T)_I / c_I`, K/s.
    rate: Vec<Real>,
    /// Per particle: Gershgorin bound of its row of `C⁻¹H`, 1/s.
    bound: Vec<Real>,
}

impl HeatConduction {
    /// Set up conduction for every body of `model` whose material has
    /// thermal properties (SPEC §7). `safety_factor` in (0, 1], see
    /// [`DEFAULT_SAFETY_FACTOR`].
    pub fn new(model: &Model, safety_factor: Real) -> Result<Self, HeatError> {
        if !(safety_factor > 0.0 && safety_factor <= 1.0) {
            return Err(HeatError::InvalidSafetyFactor(safety_factor));
        }
        let mut bodies = Vec::with_capacity(model.materials.len());
        for (b, m) in model.materials.iter().enumerate() {
            let name = || model.bodies.get(b).map_or_else(|| format!("#{b}"), |i| i.name.clone());
            bodies.push(match m.thermal() {
                None => None,
                Some(t) => {
                    if !(t.specific_heat.is_finite() && t.specific_heat > 0.0) {
                        return Err(HeatError::InvalidMaterial {
                            body: name(),
                            message: format!("specific heat must be > 0 J/(kg K), got {}", t.specific_heat),
                        });
                    }
                    if !(t.conductivity.is_finite() && t.conductivity >= 0.0) {
                        return Err(HeatError::InvalidMaterial {
                            body: name(),
                            message: format!("conductivity must be >= 0 W/(m K), got {}", t.conductivity),
                        });
                    }
                    Some(BodyThermal {
                        specific_heat: t.specific_heat,
                        conductivity: t.conductivity,
                        density: m.density(),
                    })
                }
            });
        }
        Ok(HeatConduction {
            bodies,
            safety_factor,
            last: HeatReport::default(),
            scratch: Scratch::default(),
            reference: None,
        })
    }

    /// Whether any body conducts.
    pub fn is_active(&self) -> bool {
        self.bodies.iter().any(|b| b.is_some())
    }

    /// Lumped heat capacity `c_I = Σ_q ρ₀ C_p φ_I(X_q) w_q` with the
    /// transfer weights `φ` ([`transfer_weight`]), J/K (per unit depth in
    /// plane strain); `None` for a non-conducting body.
    pub fn capacity(&self, model: &Model, i: usize) -> Option<Real> {
        let t = self.body(model.particles.body[i])?;
        let tab = &model.qp_shape;
        let sum = transfer_volume(&model.gather, &model.quad.weight, i, |q| positive_sum(tab, q));
        Some(t.density * t.specific_heat * sum)
    }

    #[inline]
    fn body(&self, b: u32) -> Option<&BodyThermal> {
        self.bodies.get(b as usize).and_then(|t| t.as_ref())
    }

    /// The conduction phase over `dt` at the model's current configuration
    /// (SPEC §7): project, sub-cycle `C Ṫ = −H T`, interpolate the increment
    /// back to the quadrature points. Leaves the conducted particle field in
    /// `model.particles.temperature` for conducting bodies.
    ///
    /// The number of sub-steps comes from the Gershgorin bound of
    /// [`Self::stable_time_step`] — unless the cruder bound of
    /// [`Self::quick_stable_step`], which costs one pass over the points, already
    /// allows the whole `dt` in one sub-step (steel at impact time steps: by
    /// three orders of magnitude); then the sub-step is the same and so is
    /// every bit of the result, and the report gives the cruder step.
    pub fn conduct(&mut self, model: &mut Model, dt: Real) -> Result<HeatReport, HeatError> {
        // The first sub-step's point pass also forms `κ J C⁻¹ w_q` and the
        // largest row sum the quick step needs: one pass over the points
        // instead of three, the same values.
        self.size_scratch(model);
        self.project(model);
        let k_hat = self.prepare_with_flux(model)?;
        let quick_dt = self.quick_step_from(model, k_hat);
        let stable_dt = if dt <= quick_dt {
            self.gather_pass(model, false);
            quick_dt
        } else {
            self.stable_step_from_prepared(model)
        };
        let substeps = if dt > 0.0 { (dt / stable_dt).ceil().max(1.0) as usize } else { 0 };
        let sub_dt = if substeps > 0 { dt / substeps as Real } else { 0.0 };
        for k in 0..substeps {
            if k > 0 {
                self.flux_pass(model, false);
                self.gather_pass(model, false);
            }
            self.advance(model, sub_dt);
        }
        self.interpolate_back(model)?;
        self.last = HeatReport { substeps, stable_dt };
        Ok(self.last)
    }

    /// Stable conduction step `Δt_th = s · 2 / λ̂` at the current
    /// configuration, s, with the particle temperatures projected from the
    /// quadrature points (a side effect that [`Self::conduct`] repeats).
    ///
    /// `λ̂` bounds the largest eigenvalue of `C⁻¹H` by Gershgorin's theorem
    /// with Cauchy–Schwarz in the metric `K_q = κ J C⁻¹ w_q`:
    /// `|H_IJ| ≤ Σ_q |∇N_I|_{K_q} |∇N_J|_{K_q}`, so
    /// `λ_max ≤ λ̂ = max_I (1/c_I) Σ_q |∇N_I|_{K_q} Σ_{J ∈ q} |∇N_J|_{K_q}`.
    /// It is a guaranteed bound for any grid, grading, boundary or
    /// deformation, computed matrix-free in the passes the first sub-step
    /// needs anyway. Forward Euler is stable for `δt ≤ 2/λ_max`, so any
    /// `s ≤ 1` is stable. The price of the guarantee: on uniform, graded,
    /// axisymmetric and sheared grids with support factor 2, `λ̂` is 2.9–4.0 ×
    /// the true `λ_max` (power iteration on the assembled matrix, test
    /// `stability_bound_dominates_the_largest_eigenvalue`), i.e. 3–4 times
    /// more sub-steps than strictly needed. The grid estimate
    /// `h² ρ C_p / (2 d κ)` (d = 2) fell between this step (s = 1) and the
    /// true limit there (0.7–1.4 × this step), but it is an estimate, not a
    /// bound.
    pub fn stable_time_step(&mut self, model: &mut Model) -> Result<Real, HeatError> {
        self.prepare(model)?;
        self.project(model);
        Ok(self.stable_step_from_prepared(model))
    }

    /// A stable conduction step no larger than [`Self::stable_time_step`]'s,
    /// for the prepared configuration: Gershgorin's bound with
    /// `|g|_{K_q} ≤ sqrt(μ_q) |g|`, `μ_q = λ_max(K_q) ≤ w_q k̂`, where
    /// `k̂ = max_q ‖κ J C⁻¹‖_∞` (the largest Gershgorin row sum of the points'
    /// conductivities, one pass over the points) and
    /// `λ̂ ≤ k̂ · max_I (1/c_I) Σ_q w_q |∇N_I| Σ_{J ∈ q} |∇N_J|`, whose second
    /// factor depends on the reference configuration only and is cached
    /// until the particles, their masses or the table's rows change (cracks).
    /// Test `quick_stable_step_is_below_the_gershgorin_step`.
    pub fn quick_stable_step(&mut self, model: &Model) -> Real {
        let k_hat = (&self.scratch.kw, &model.quad.weight)
            .into_par_iter()
            .map(|(k, w)| row_sum(k) / w)
            .reduce(|| 0.0, Real::max);
        self.quick_step_from(model, k_hat)
    }

    /// [`Self::quick_stable_step`] given `k̂ = max_q ‖κ J C⁻¹‖_∞`.
    fn quick_step_from(&mut self, model: &Model, k_hat: Real) -> Real {
        let signature = ReferenceSignature::of(model, &self.scratch.capacity);
        let reference = match self.reference {
            Some((sig, r)) if sig == signature => r,
            _ => {
                let r = self.reference_factor(model);
                self.reference = Some((signature, r));
                r
            }
        };
        // The margin keeps the step below the Gershgorin one through the
        // round-off of both (they coincide on an undeformed uniform grid).
        let lambda = k_hat * reference * (1.0 + 1e-9);
        if lambda > 0.0 {
            self.safety_factor * 2.0 / lambda
        } else {
            Real::INFINITY
        }
    }

    /// `max_I (1/c_I) Σ_q w_q |∇N_I(X_q)| Σ_{J ∈ q} |∇N_J(X_q)|` over the
    /// particles of conducting bodies, 1/(m² J/K) per unit conductivity.
    fn reference_factor(&mut self, model: &Model) -> Real {
        let (tab, gather) = (&model.qp_shape, &model.gather);
        let s = &mut self.scratch;
        s.row_norm.resize(model.quad.len(), 0.0);
        s.row_norm.par_iter_mut().enumerate().for_each(|(q, n)| {
            *n = tab.range(q).map(|k| tab.grad[k].norm()).sum();
        });
        let (row_norm, w) = (&s.row_norm, &model.quad.weight);
        s.capacity
            .par_iter()
            .enumerate()
            .map(|(i, &c)| {
                if c <= 0.0 {
                    return 0.0;
                }
                let sum: Real = gather
                    .range(i)
                    .map(|j| {
                        let q = gather.point[j] as usize;
                        w[q] * gather.grad[j].norm() * row_norm[q]
                    })
                    .sum();
                sum / c
            })
            .reduce(|| 0.0, Real::max)
    }

    fn stable_step_from_prepared(&mut self, model: &Model) -> Real {
        self.flux_pass(model, true);
        self.gather_pass(model, true);
        let lambda = self.scratch.bound.par_iter().cloned().reduce(|| 0.0, Real::max);
        if lambda > 0.0 {
            self.safety_factor * 2.0 / lambda
        } else {
            Real::INFINITY
        }
    }

    /// Size the scratch columns for the model; zero the increments; form
    /// the transfer weights' normalizers and the capacities (they change
    /// only where a crack split rebuilt the table, but a pass over the
    /// entries costs less than tracking that).
    fn size_scratch(&mut self, model: &Model) {
        let (np, nq) = (model.particles.len(), model.quad.len());
        let s = &mut self.scratch;
        s.kw.resize(nq, Matrix2::zeros());
        s.flux.resize(nq, Vec2::zeros());
        s.row_norm.resize(nq, 0.0);
        s.positive.resize(nq, 0.0);
        for v in [&mut s.capacity, &mut s.start, &mut s.delta, &mut s.rate, &mut s.bound] {
            v.resize(np, 0.0);
        }
        s.delta.iter_mut().for_each(|d| *d = 0.0);
        let tab = &model.qp_shape;
        s.positive.par_iter_mut().with_max_len(PARALLEL_PIECE).enumerate().for_each(|(q, p)| {
            *p = positive_sum(tab, q);
        });
        let (gather, w, positive, bodies) = (&model.gather, &model.quad.weight, &s.positive, &self.bodies);
        (s.capacity.par_iter_mut(), &model.particles.body)
            .into_par_iter()
            .with_max_len(PARALLEL_PIECE)
            .enumerate()
            .for_each(|(i, (c, b))| {
                *c = match bodies.get(*b as usize).and_then(|t| t.as_ref()) {
                    None => 0.0,
                    Some(t) => t.density * t.specific_heat * transfer_volume(gather, w, i, |q| positive[q]),
                };
            });
    }

    /// Size scratch, compute `κ J C⁻¹ w_q` per point.
    fn prepare(&mut self, model: &Model) -> Result<(), HeatError> {
        self.size_scratch(model);
        self.point_pass(model, false).map(|_| ())
    }

    /// [`Self::prepare`] and the first [`Self::flux_pass`] (without the
    /// bound) in one pass over the points, from the projected particle
    /// temperatures; returns `k̂ = max_q ‖κ J C⁻¹‖_∞` (as
    /// [`Self::quick_stable_step`] forms it).
    fn prepare_with_flux(&mut self, model: &Model) -> Result<Real, HeatError> {
        self.point_pass(model, true)
    }

    /// Per point, `κ J C⁻¹ w_q` and, `with_flux`, the weighted nominal flux;
    /// returns `k̂`, or the first point (in index order) whose `F` is not
    /// invertible.
    fn point_pass(&mut self, model: &Model, with_flux: bool) -> Result<Real, HeatError> {
        let (tab, temp) = (&model.qp_shape, &model.particles.temperature);
        let bodies = &self.bodies;
        let q = &model.quad;
        let s = &mut self.scratch;
        let piece = PARALLEL_PIECE;
        let (bad, k_hat) = (s.kw.par_chunks_mut(piece), s.flux.par_chunks_mut(piece))
            .into_par_iter()
            .enumerate()
            .map(|(c, (kws, fluxes))| {
                let mut k_hat: Real = 0.0;
                for (k, (kw, flux)) in kws.iter_mut().zip(fluxes).enumerate() {
                    let qi = c * piece + k;
                    let (f, w) = (&q.f[qi], q.weight[qi]);
                    match bodies.get(q.body[qi] as usize).and_then(|t| t.as_ref()) {
                        None => *kw = Matrix2::zeros(),
                        Some(t) => match reference_conductivity(&f.to_tensor(), t.conductivity) {
                            Some(m) => *kw = m * w,
                            None => return (Some((qi, f.determinant())), k_hat),
                        },
                    }
                    k_hat = k_hat.max(row_sum(kw) / w);
                    if with_flux {
                        *flux = point_flux(tab, temp, qi, kw, false).0;
                    }
                }
                (None, k_hat)
            })
            .reduce(|| (None, 0.0), |a, b| (a.0.or(b.0), a.1.max(b.1)));
        match bad {
            Some((point, jacobian)) => Err(HeatError::Inverted { point, jacobian }),
            None => Ok(k_hat),
        }
    }

    /// Particle temperatures of conducting bodies: the capacity-weighted
    /// projection of the quadrature temperatures with the transfer weights,
    /// `T_I = Σ_q φ_I(X_q) w_q T_q / Σ_q φ_I(X_q) w_q`; remember them as the
    /// start.
    fn project(&mut self, model: &mut Model) {
        let (gather, tq, wq) = (&model.gather, &model.quad.temperature, &model.quad.weight);
        let bodies = &self.bodies;
        let positive = &self.scratch.positive;
        let p = &mut model.particles;
        (p.temperature.par_iter_mut(), self.scratch.start.par_iter_mut(), &p.body)
            .into_par_iter()
            .enumerate()
            .for_each(|(i, (t, start, b))| {
                if !conducts(bodies, *b) {
                    return;
                }
                let (mut acc, mut wsum) = (0.0, 0.0);
                for j in gather.range(i) {
                    let q = gather.point[j] as usize;
                    let w = transfer_weight(gather.value[j], positive[q]) * wq[q];
                    acc += w * tq[q];
                    wsum += w;
                }
                if wsum > 0.0 {
                    *t = acc / wsum;
                }
                *start = *t;
            });
    }

    /// Per point: `∇_X T`, the weighted nominal flux, and (for the bound)
    /// `Σ_J |∇N_J|_{Kw}`.
    fn flux_pass(&mut self, model: &Model, with_bound: bool) {
        let (tab, temp) = (&model.qp_shape, &model.particles.temperature);
        let s = &mut self.scratch;
        (s.flux.par_iter_mut(), s.row_norm.par_iter_mut(), &s.kw)
            .into_par_iter()
            .with_max_len(PARALLEL_PIECE)
            .enumerate()
            .for_each(|(q, (flux, norm, kw))| {
                let (f, n) = point_flux(tab, temp, q, kw, with_bound);
                *flux = f;
                if with_bound || *kw == Matrix2::zeros() {
                    *norm = n;
                }
            });
    }

    /// Per particle: `−(H T)_I / c_I = Σ_q ∇N_I · (q_q w_q) / c_I`, gathered
    /// in fixed order; and its row's Gershgorin bound.
    fn gather_pass(&mut self, model: &Model, with_bound: bool) {
        let gather = &model.gather;
        let s = &mut self.scratch;
        let (flux, kw, row_norm) = (&s.flux, &s.kw, &s.row_norm);
        (s.rate.par_iter_mut(), s.bound.par_iter_mut(), &s.capacity)
            .into_par_iter()
            .with_max_len(PARALLEL_PIECE)
            .enumerate()
            .for_each(|(i, (rate, bound, &c))| {
                // not conducting, or no positive weight anywhere (then no
                // point receives its increment either)
                if c <= 0.0 {
                    *rate = 0.0;
                    *bound = 0.0;
                    return;
                }
                let (mut r, mut bnd) = (0.0, 0.0);
                for j in gather.range(i) {
                    let (q, g) = (gather.point[j] as usize, gather.grad[j]);
                    r += g.dot(&flux[q]);
                    if with_bound {
                        bnd += kw_norm(&kw[q], &g) * row_norm[q];
                    }
                }
                *rate = r / c;
                if with_bound {
                    *bound = bnd / c;
                }
            });
    }

    /// One explicit Euler sub-step on the particles of conducting bodies.
    fn advance(&mut self, model: &mut Model, sub_dt: Real) {
        let bodies = &self.bodies;
        let s = &mut self.scratch;
        let p = &mut model.particles;
        (p.temperature.par_iter_mut(), s.delta.par_iter_mut(), &s.start, &s.rate, &p.body).into_par_iter().for_each(
            |(t, d, start, rate, b)| {
                if conducts(bodies, *b) {
                    *d += sub_dt * rate;
                    *t = start + *d;
                }
            },
        );
    }

    /// `T_q ← T_q + Σ_I φ_I(X_q) ΔT_I` at conducting points; NaN check.
    fn interpolate_back(&mut self, model: &mut Model) -> Result<(), HeatError> {
        let tab = &model.qp_shape;
        let s = &self.scratch;
        let (delta, positive) = (&s.delta, &s.positive);
        let bodies = &self.bodies;
        let q = &mut model.quad;
        let bad = (q.temperature.par_iter_mut(), &q.body)
            .into_par_iter()
            .enumerate()
            .filter(|(_, (_, b))| conducts(bodies, **b))
            .map(|(qi, (t, _))| {
                let mut dt = 0.0;
                for k in tab.range(qi) {
                    dt += transfer_weight(tab.value[k], positive[qi]) * delta[tab.index[k] as usize];
                }
                *t += dt;
                (!t.is_finite()).then_some(qi)
            })
            .find_first(|r| r.is_some())
            .flatten();
        match bad {
            Some(point) => Err(HeatError::NonFinite { point }),
            None => Ok(()),
        }
    }
}

/// The transfer weight `φ_I(X_q) = max(N_I(X_q), 0) / s_q` of a shape
/// value `n` at a point whose positive values sum to `positive_sum` (`s_q ≥ 1`
/// by the partition of unity): the positive part of the RK function,
/// normalized so that the weights at each point again sum to one. It carries
/// temperatures between points and particles (projection, capacity,
/// interpolation of the increment); see the module doc's deviations for why
/// not `N` itself.
#[inline]
pub fn transfer_weight(n: Real, positive_sum: Real) -> Real {
    if positive_sum > 0.0 {
        n.max(0.0) / positive_sum
    } else {
        0.0
    }
}

/// `Σ_q φ_I(X_q) w_q` of particle `i` over its gather entries, given each
/// point's `s_q` (`positive`): the volume a particle's capacity weighs.
#[inline]
fn transfer_volume(gather: &Gather, w: &[Real], i: usize, positive: impl Fn(usize) -> Real) -> Real {
    gather
        .range(i)
        .map(|j| {
            let q = gather.point[j] as usize;
            transfer_weight(gather.value[j], positive(q)) * w[q]
        })
        .sum()
}

/// `s_q = Σ_J max(N_J(X_q), 0)` over point `q`'s row of `tab`.
#[inline]
fn positive_sum(tab: &ShapeTable, q: usize) -> Real {
    tab.range(q).map(|k| tab.value[k].max(0.0)).sum()
}

/// Whether body `b` conducts.
#[inline]
fn conducts(bodies: &[Option<BodyThermal>], b: u32) -> bool {
    matches!(bodies.get(b as usize), Some(Some(_)))
}

/// Point `q`'s weighted nominal flux `−(κ J C⁻¹ w_q) ∇_X T` from the
/// particle temperatures `temp`, and, `with_bound`, `Σ_J |∇N_J|_{Kw}`
/// (zero flux and bound where `kw` is zero: a non-conducting point).
#[inline]
fn point_flux(tab: &ShapeTable, temp: &[Real], q: usize, kw: &Matrix2<Real>, with_bound: bool) -> (Vec2, Real) {
    if *kw == Matrix2::zeros() {
        return (Vec2::zeros(), 0.0);
    }
    let mut grad = Vec2::zeros();
    let mut n = 0.0;
    for k in tab.range(q) {
        let g = tab.grad[k];
        grad += g * temp[tab.index[k] as usize];
        if with_bound {
            n += kw_norm(kw, &g);
        }
    }
    (-(kw * grad), n)
}

/// The largest absolute row sum `‖k‖_∞` of a 2×2 block.
#[inline]
fn row_sum(k: &Matrix2<Real>) -> Real {
    (k[(0, 0)].abs() + k[(0, 1)].abs()).max(k[(1, 0)].abs() + k[(1, 1)].abs())
}

/// `|g|_K = sqrt(gᵀ K g)`.
#[inline]
fn kw_norm(k: &Matrix2<Real>, g: &Vec2) -> Real {
    g.dot(&(k * g)).max(0.0).sqrt()
}

/// The total-Lagrangian conductivity `κ J C⁻¹` (in-plane block, `C = FᵀF`)
/// that turns `∇_X T` into the nominal heat flux `q = −κ J C⁻¹ ∇_X T` (per
/// unit reference area), SPEC §7 (the pull-back of Fourier's law, \[RL10\]
/// Eqs. (2.14)–(2.21)). `None` if `F` is not invertible or `J ≤ 0`. Only the
/// in-plane block matters: a 2D field has no out-of-plane (hoop) gradient.
#[allow(non_snake_case)]
pub fn reference_conductivity(F: &Tensor3, kappa: Real) -> Option<Matrix2<Real>> {
    // Legend: F deformation gradient, J = det F, C_inv = (F^T F)^-1 = F^-1 F^-T.
    let J = F.determinant();
    if !(J > 0.0 && J.is_finite()) {
        return None;
    }
    let F_inv = F.try_inverse()?;
    let C_inv = F_inv * F_inv.transpose();
    Some(Matrix2::new(C_inv[(0, 0)], C_inv[(0, 1)], C_inv[(1, 0)], C_inv[(1, 1)]) * (kappa * J))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretize::RectangleGrid;
    use crate::geometry::GeometryMode;
    use crate::material::{Elastic, Material, ThermalProperties};
    use crate::model::BodySetup;

    fn grid(nx: usize, ny: usize, h: Real) -> RectangleGrid {
        RectangleGrid::uniform((0.0, (nx - 1) as Real * h), (0.0, (ny - 1) as Real * h), h)
    }

    fn model(mode: GeometryMode, g: RectangleGrid, kappa: Real) -> Model {
        let m = Material::Elastic(Elastic {
            density: 2000.0,
            youngs_modulus: 1e9,
            poisson_ratio: 0.3,
            room_temperature: 300.0,
            thermal: Some(ThermalProperties { specific_heat: 500.0, conductivity: kappa }),
        });
        let b = BodySetup { name: "b".into(), grid: g, material: m, initial_velocity: vec![], supports: vec![] };
        Model::build(mode, &[b]).unwrap()
    }

    /// Deterministic pseudo-random numbers in [0, 1).
    fn lcg(s: &mut u64) -> Real {
        *s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*s >> 11) as Real / (1u64 << 53) as Real
    }

    /// `−C⁻¹ H T` evaluated by assembling `H` entry by entry (test only).
    fn dense_operator(m: &Model, heat: &HeatConduction) -> Vec<Vec<Real>> {
        let n = m.particles.len();
        let mut a = vec![vec![0.0; n]; n];
        let tab = &m.qp_shape;
        for q in 0..m.quad.len() {
            let k = reference_conductivity(&m.quad.f[q].to_tensor(), 1.0).unwrap() * m.quad.weight[q];
            let kappa = heat.bodies[m.quad.body[q] as usize].unwrap().conductivity;
            for a_ in tab.range(q) {
                for b_ in tab.range(q) {
                    let (i, j) = (tab.index[a_] as usize, tab.index[b_] as usize);
                    a[i][j] += kappa * tab.grad[a_].dot(&(k * tab.grad[b_]));
                }
            }
        }
        for (i, row) in a.iter_mut().enumerate() {
            let c = heat.capacity(m, i).unwrap();
            row.iter_mut().for_each(|x| *x /= c);
        }
        a
    }

    fn largest_eigenvalue(a: &[Vec<Real>]) -> Real {
        let n = a.len();
        let mut s = 7u64;
        let mut v: Vec<Real> = (0..n).map(|_| lcg(&mut s) - 0.5).collect();
        let mut lambda = 0.0;
        for _ in 0..3000 {
            let w: Vec<Real> = a.iter().map(|row| row.iter().zip(&v).map(|(x, y)| x * y).sum()).collect();
            let norm = w.iter().map(|x| x * x).sum::<Real>().sqrt();
            lambda = norm / v.iter().map(|x| x * x).sum::<Real>().sqrt();
            v = w.iter().map(|x| x / norm).collect();
        }
        lambda
    }

    /// `c_I` is the row sum of the positive weights over the point rows,
    /// the capacities add up to the body's `ρ₀ C_p V`, and every one is
    /// positive (the corner particles, whose RK values dip below zero, too).
    #[test]
    fn capacity_is_the_row_sum() {
        let mut m = model(GeometryMode::Axisymmetric, grid(7, 5, 1e-3), 40.0);
        let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
        let tab = &m.qp_shape;
        let mut c = vec![0.0; m.particles.len()];
        for q in 0..m.quad.len() {
            let positive: Real = tab.range(q).map(|k| tab.value[k].max(0.0)).sum();
            for k in tab.range(q) {
                c[tab.index[k] as usize] += 2000.0 * 500.0 * tab.value[k].max(0.0) / positive * m.quad.weight[q];
            }
        }
        heat.stable_time_step(&mut m).unwrap();
        for (i, ci) in c.iter().enumerate() {
            let got = heat.capacity(&m, i).unwrap();
            assert!(*ci > 0.0 && (got - ci).abs() <= 1e-12 * ci, "particle {i}: {got} vs {ci}");
            assert_eq!(got, heat.scratch.capacity[i], "particle {i}: the phase's column");
        }
        let volume: Real = m.quad.weight.iter().sum();
        let total: Real = c.iter().sum();
        assert!((total - 2000.0 * 500.0 * volume).abs() <= 1e-12 * total, "{total} vs {}", 2000.0 * 500.0 * volume);
    }

    /// A particle whose lumped weight `Σ_q N_I w_q` is a small part of its
    /// consistent weight `Σ_q N_I² w_q`, as a crack split leaves one when
    /// its support is cut (shape values of both signs): with `N` as the
    /// transfer weights the projection/interpolation round trip multiplies
    /// that particle's conducted increment by the ratio every phase, and a
    /// run at a stable sub-step blows up (found on a 48-row plate: 10× per
    /// µs, overflow after 50 µs; here tenfold per phase). With the positive
    /// weights the round trip cannot amplify: over 400 phases the largest
    /// departure from the mean peaks at 1.27 × its start (63 K from 50 K:
    /// the RK conductivity has positive off-diagonal entries, so there is no
    /// strict maximum principle) and then decays.
    #[test]
    fn a_particle_with_a_small_lumped_weight_does_not_amplify_the_round_trip() {
        let mut m = model(GeometryMode::PlaneStrain, grid(9, 7, 1e-3), 40.0);
        let (tab, w) = (&mut m.qp_shape, &m.quad.weight);
        // the particle in the middle; per point of its support, move a share
        // of its value to the point's largest other entry (each row keeps
        // its sum, the partition of unity), alternating the sign so that
        // its lumped weight falls to a few per cent of what it was
        let i = 4 * 9 + 4;
        let rows: Vec<(usize, usize, usize)> = (0..w.len())
            .filter_map(|q| {
                let own = tab.range(q).find(|&k| tab.index[k] as usize == i)?;
                let other =
                    tab.range(q).filter(|&k| k != own).max_by(|&a, &b| tab.value[a].total_cmp(&tab.value[b]))?;
                Some((q, own, other))
            })
            .collect();
        let lumped = |tab: &ShapeTable| rows.iter().map(|&(q, own, _)| tab.value[own] * w[q]).sum::<Real>();
        let before = lumped(tab);
        // values ±0.5 in turn, then one common offset to 5 % of the weight
        let sign = |n: usize| if n.is_multiple_of(2) { 0.5 } else { -0.5 };
        let alternating: Real = rows.iter().enumerate().map(|(n, &(q, _, _))| sign(n) * w[q]).sum();
        let support: Real = rows.iter().map(|&(q, _, _)| w[q]).sum();
        let offset = (0.05 * before - alternating) / support;
        for (n, &(_, own, other)) in rows.iter().enumerate() {
            let shift = sign(n) + offset - tab.value[own];
            tab.value[own] += shift;
            tab.value[other] -= shift;
        }
        let after = lumped(tab);
        let consistent: Real = rows.iter().map(|&(q, own, _)| tab.value[own].powi(2) * w[q]).sum();
        assert!(after > 0.0 && after < 0.2 * before && consistent > 2.0 * after, "{before:e} {after:e} {consistent:e}");
        m.gather.copy_entries(&m.qp_shape);
        // masses lumped from the changed table, as a split re-lumps them
        m.lump_masses();
        let mut s = 11u64;
        for t in m.quad.temperature.iter_mut() {
            *t = 300.0 + 100.0 * lcg(&mut s);
        }
        let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
        let dt = heat.stable_time_step(&mut m).unwrap();
        // the largest departure from 350 K: 50 K at the start
        let spread = |m: &Model| m.quad.temperature.iter().fold(0.0, |a: Real, t| a.max((t - 350.0).abs()));
        for phase in 0..400 {
            heat.conduct(&mut m, dt).unwrap();
            assert!(spread(&m) < 75.0, "phase {phase}: a temperature {:.3e} K from 350 K", spread(&m));
        }
    }

    #[test]
    fn reference_conductivity_of_stretch_and_rotation() {
        // a stretch λ along x: the bar is longer (κ/λ along x) and its
        // faces normal to y are wider (κλ along y)
        let mut f = Tensor3::identity();
        f[(0, 0)] = 2.0;
        let k = reference_conductivity(&f, 3.0).unwrap();
        assert!((k[(0, 0)] - 1.5).abs() < 1e-15 && (k[(1, 1)] - 6.0).abs() < 1e-15 && k[(0, 1)] == 0.0);
        // a hoop stretch in axisymmetry widens the faces in both in-plane directions
        let mut f = Tensor3::identity();
        f[(2, 2)] = 1.5;
        let k = reference_conductivity(&f, 2.0).unwrap();
        assert!((k[(0, 0)] - 3.0).abs() < 1e-15 && (k[(1, 1)] - 3.0).abs() < 1e-15);
        // a rigid rotation changes nothing
        let (c, s) = (0.6, 0.8);
        let r = Tensor3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        let k = reference_conductivity(&r, 5.0).unwrap();
        assert!((k - Matrix2::identity() * 5.0).norm() < 1e-14);
        let mut bad = Tensor3::identity();
        bad[(0, 0)] = -1.0;
        assert!(reference_conductivity(&bad, 1.0).is_none());
    }

    /// The Gershgorin bound is a true upper bound on `λ_max(C⁻¹H)` (so any
    /// `s ≤ 1` is stable) and not wildly pessimistic, on a uniform grid, a
    /// graded one, an axisymmetric one and a sheared configuration.
    #[test]
    fn stability_bound_dominates_the_largest_eigenvalue() {
        let mut graded = grid(13, 4, 1e-3);
        graded.x_max = 0.03;
        graded.growth = 1.3;
        graded.fine_half_width = 0.002;
        let mut sheared = model(GeometryMode::PlaneStrain, grid(9, 6, 1e-3), 10.0);
        for f in sheared.quad.f.iter_mut() {
            f.xy = 0.5;
            f.yy = 0.8;
        }
        let cases = [
            model(GeometryMode::PlaneStrain, grid(10, 6, 1e-3), 10.0),
            model(GeometryMode::PlaneStrain, graded, 10.0),
            model(GeometryMode::Axisymmetric, grid(8, 6, 1e-3), 10.0),
            sheared,
        ];
        for (n, mut m) in cases.into_iter().enumerate() {
            let mut heat = HeatConduction::new(&m, 1.0).unwrap();
            let dt = heat.stable_time_step(&mut m).unwrap();
            let bound = 2.0 / dt;
            let lambda = largest_eigenvalue(&dense_operator(&m, &heat));
            assert!(bound >= lambda, "case {n}: bound {bound:.4e} below lambda_max {lambda:.4e}");
            assert!(bound < 5.0 * lambda, "case {n}: bound {bound:.4e} too pessimistic vs {lambda:.4e}");
        }
    }

    /// The projection/interpolation round trip adds no smoothing of its own.
    #[test]
    fn zero_conductivity_leaves_quadrature_temperatures_untouched() {
        let mut m = model(GeometryMode::PlaneStrain, grid(8, 5, 1e-3), 0.0);
        let mut s = 3u64;
        for t in m.quad.temperature.iter_mut() {
            *t = 300.0 + 100.0 * lcg(&mut s);
        }
        let before = m.quad.temperature.clone();
        let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
        let r = heat.conduct(&mut m, 1.0).unwrap();
        assert_eq!(r.substeps, 1);
        assert_eq!(m.quad.temperature, before);
    }

    /// A body without thermal properties is skipped; bad constants are errors.
    #[test]
    fn non_conducting_bodies_are_skipped_and_bad_constants_rejected() {
        let mut m = model(GeometryMode::PlaneStrain, grid(6, 4, 1e-3), 10.0);
        if let Material::Elastic(e) = &mut m.materials[0] {
            e.thermal = None;
        }
        m.quad.temperature[3] = 1000.0;
        let before = (m.quad.temperature.clone(), m.particles.temperature.clone());
        let mut heat = HeatConduction::new(&m, 0.5).unwrap();
        assert!(!heat.is_active());
        heat.conduct(&mut m, 1e-3).unwrap();
        assert_eq!((m.quad.temperature.clone(), m.particles.temperature.clone()), before);
        if let Material::Elastic(e) = &mut m.materials[0] {
            e.thermal = Some(ThermalProperties { specific_heat: 0.0, conductivity: 1.0 });
        }
        assert!(matches!(HeatConduction::new(&m, 0.5), Err(HeatError::InvalidMaterial { .. })));
        assert!(matches!(HeatConduction::new(&m, 1.5), Err(HeatError::InvalidSafetyFactor(_))));
    }

    /// The quick step is a stable step: never above the Gershgorin step,
    /// also after the configuration is sheared and after shape values
    /// change (which the cache must notice).
    #[test]
    fn quick_stable_step_is_below_the_gershgorin_step() {
        for mode in [GeometryMode::PlaneStrain, GeometryMode::Axisymmetric] {
            let mut m = model(mode, grid(9, 6, 1e-3), 10.0);
            let mut heat = HeatConduction::new(&m, 1.0).unwrap();
            for stage in 0..3 {
                if stage == 1 {
                    for f in m.quad.f.iter_mut() {
                        f.xy = 0.7;
                        f.yy = 0.6;
                    }
                }
                if stage == 2 {
                    // a split's local rebuild: other shape values in a row
                    let r = m.qp_shape.range(5);
                    m.qp_shape.value[r.start] += 0.2;
                    m.qp_shape.value[r.start + 1] -= 0.2;
                    m.gather.copy_entries(&m.qp_shape);
                }
                let exact = heat.stable_time_step(&mut m).unwrap();
                let quick = heat.quick_stable_step(&m);
                let mut fresh = HeatConduction::new(&m, 1.0).unwrap();
                fresh.stable_time_step(&mut m).unwrap();
                assert_eq!(quick, fresh.quick_stable_step(&m), "{mode:?} stage {stage}: stale cache");
                assert!(quick <= exact && quick > 0.02 * exact, "{mode:?} stage {stage}: {quick:e} vs {exact:e}");
            }
            // one sub-step either way gives the same bits
            let before = m.quad.temperature.clone();
            let mut t = m.clone();
            for (k, x) in t.quad.temperature.iter_mut().enumerate() {
                *x = 300.0 + (k % 7) as Real;
            }
            let mut a = t.clone();
            let small = 0.5 * heat.quick_stable_step(&t);
            let ra = HeatConduction::new(&a, 1.0).unwrap().conduct(&mut a, small).unwrap();
            let mut b = t.clone();
            let mut hb = HeatConduction::new(&b, 1.0).unwrap();
            hb.prepare(&b).unwrap();
            hb.project(&mut b);
            hb.stable_step_from_prepared(&b);
            hb.advance(&mut b, small);
            hb.interpolate_back(&mut b).unwrap();
            assert_eq!(ra.substeps, 1);
            assert_eq!(a.quad.temperature, b.quad.temperature);
            assert_ne!(a.quad.temperature, before);
        }
    }
}
