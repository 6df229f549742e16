//! The stable time step of the explicit integration (SPEC §5).
//!
//! SPEC §5 takes `Δt = s · min_I h_I / c_L` once, from the particle
//! spacing of the reference lattice. That is the step of a lattice whose
//! particles all carry a full share of mass and whose shape functions all
//! see a full neighbourhood. A crack split breaks both: a split child
//! carries a fraction of its parent's mass while its one-sided row keeps
//! (or steepens) its gradients, so its own frequency can rise above the
//! one the spacing step was chosen for, and the central difference then
//! amplifies its motion step by step.
//!
//! [`frequency_bounds`] bounds every particle's frequency from the
//! stiffness it sees: by Gershgorin's theorem applied to the symmetric
//! `M^{-1/2} K M^{-1/2}` (whose eigenvalues are the squared frequencies),
//! ```text
//! ω_max² ≤ max_I ω_I²,
//! ω_I² = Σ_q k_q w_q (|b_I(q)|/√m_I) Σ_J |b_J(q)|/√m_J  ≥  Σ_J |K_IJ| / √(m_I m_J)
//! ```
//! with `k_q` the point's modulus (`point_modulus`) and `b_I(q)` the
//! particle's column of the strain operator at point `q`: the spatial
//! gradient `F⁻ᵀ ∇_X N_I` and, in axisymmetry, the hoop entry
//! `N_I / (F_θθ R_q)`, so that compression (the impact face of a Taylor
//! bar, the material under a projectile's corner) and a child's smaller
//! mass both raise it. With the moduli's norm replaced by the P-wave
//! modulus `ρ c_L²` the bound is not rigorous, and it is loose by a factor
//! of the lattice (1.7 against the exact highest frequency of a regular
//! plate); so it is used **relative to the reference lattice**
//! ([`StableStep`]): the step stays the rule's `Δt₀` as long as no
//! particle's bound exceeds the largest of the reference lattice, and
//! shrinks as `Δt₀ ω_ref / ω_max` where one does, keeping the margin the
//! spacing step has on the undeformed lattice (there, about 2.5: the
//! coarse axisymmetric Børvik Case II runs with twice the spacing step and
//! fails at 2.5 times). `tests/stability.rs` checks the bound's growth
//! against the exact frequency of a plate whose particle loses mass or
//! which is compressed (within −15 % / +50 %).
//!
//! # Deviations
//! - The step is no longer fixed for the run (SPEC §5 computes it once):
//!   it is re-evaluated after every crack change and every
//!   [`EVALUATE_EVERY`] steps. Issue #19: a split child's one-step kick
//!   stopped the coarse axisymmetric Børvik Case II with the damage
//!   criterion at 114 µs with a particle at 14 km/s; the same run at half
//!   the spacing step runs to 216 µs (fastest particle 301 m/s), and so
//!   does it with the adaptive step (which goes down to 0.65 of the
//!   spacing step, set by crack-face children under the projectile's rim;
//!   `docs/validation.md`). Tests: `the_step_follows_a_light_particle`,
//!   `frequency_bound_tracks_the_exact_highest_frequency`.
//!   The step follows a stiff row as faithfully as a light particle, so
//!   a row rebuilt at a crack is kept bounded where it is built
//!   ([`crate::shape::rk::MAX_LEBESGUE_SUM`],
//!   [`crate::shape::rk::MAX_GRADIENT_SUM`]): one unbounded row had held a
//!   48-row run at a twentieth of the spacing step.
//! - A change of step keeps the central difference second order: the
//!   velocity update spans the mean of the two steps,
//!   `V^{n+½} = V^{n−½} + ½ (Δt_{n−½} + Δt_{n+½}) a^n`
//!   (`Simulation::integrate`; the contact stage and the rigid bodies use
//!   the same velocity step). Test:
//!   `changes_of_step_keep_the_central_difference_second_order` (with the
//!   new step alone, alternating steps pump the energy up until it blows
//!   up).

use crate::bulk_viscosity::step_factor;
use crate::material::{Constitutive, Material};
use crate::math::{Block2, Real, Vec2};
use crate::model::{Model, PARALLEL_PIECE};
use crate::particles::ParticleFlags;
use rayon::prelude::*;

/// The strain-operator column norm `|b_I(q)|` of one table entry: the
/// spatial gradient `F⁻ᵀ ∇_X N` (the reference one where `f_inv` is
/// `None`) and, in axisymmetry (`hoop`, the point's reference radius), the
/// hoop entry `N / (F_θθ R)`.
#[inline]
fn column_norm(grad: &Vec2, n: Real, f_inv: Option<&Block2>, hoop: Option<Real>) -> Real {
    let (g, h) = match f_inv {
        // F⁻ᵀ ∇N: (F⁻¹)ᵀ applied to the gradient.
        Some(fi) => (Vec2::new(fi.xx * grad.x + fi.yx * grad.y, fi.xy * grad.x + fi.yy * grad.y), fi.zz),
        None => (*grad, 1.0),
    };
    let hoop_entry = hoop.map_or(0.0, |r| h * n / r);
    (g.norm_squared() + hoop_entry * hoop_entry).sqrt()
}

/// Gershgorin bound `ω_I²` of every particle (module doc), rad²/s², in the
/// reference configuration (`deformed = false`) or the current one, with
/// each point's modulus from `point_modulus` (`fracturing`: crack growth
/// is on, so fractured points carry pressure only). The row of a particle
/// is that of its free components: none for one held in both (a clamp),
/// and for one held radially (the axis, a roller) its axial row, whose
/// column has no hoop entry (the hoop entry `N/R` grows without bound
/// toward the axis, where the revolved mass vanishes).
pub fn frequency_bounds(model: &Model, deformed: bool, fracturing: bool) -> Vec<Real> {
    let mut scratch = BoundScratch::default();
    scratch.fill(model, deformed, fracturing);
    scratch.bounds
}

/// Reused buffers of [`frequency_bounds`]: the time loop evaluates the
/// bound without allocating once they have their size. Scratch: its
/// `Debug` shows nothing of its content (a resumed run starts with it
/// empty and fills it at its first evaluation).
#[derive(Clone, Default)]
pub struct BoundScratch {
    /// Per point: `F⁻¹` (none in the reference configuration) and the
    /// point's modulus times its weight, `k_q w_q`.
    points: Vec<(Option<Block2>, Real)>,
    /// Per point: `k_q w_q Σ_J |b_J(q)|`.
    row_factor: Vec<Real>,
    /// Per piece of [`PARALLEL_PIECE`] points, per table entry `k` of its
    /// points (of point `q`, particle `J`; from the piece's first entry):
    /// `|b_J(q)| / √m_J`, summed into the point's row factor and read
    /// again by the particle's bound (written only for points whose
    /// `k_q w_q` is not zero, and read only for those). One buffer per
    /// piece, so that the pieces fill theirs side by side and keep them
    /// from step to step.
    entries: Vec<Vec<Real>>,
    /// Per particle: the bound `ω_I²`.
    pub bounds: Vec<Real>,
}

impl std::fmt::Debug for BoundScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("BoundScratch")
    }
}

impl BoundScratch {
    /// Fill [`BoundScratch::bounds`] for `model` ([`frequency_bounds`]). In
    /// parallel over points, then over particles, each summing its own
    /// entries in fixed order: the same bits for any thread count.
    pub fn fill(&mut self, model: &Model, deformed: bool, fracturing: bool) {
        let (table, quad) = (&model.qp_shape, &model.quad);
        let hoop = |q: usize| model.mode.needs_point_values().then(|| quad.x0[q].x);
        self.points.resize(quad.len(), (None, 0.0));
        self.row_factor.resize(quad.len(), 0.0);
        self.bounds.resize(model.particles.len(), 0.0);
        self.points.par_iter_mut().with_max_len(PARALLEL_PIECE).enumerate().for_each(|(q, point)| {
            let f = &quad.f[q];
            let fractured = fracturing.then(|| (quad.damage[q], f.determinant()));
            let modulus = point_modulus(&model.materials[quad.body[q] as usize], quad.eroded[q], fractured);
            let f_inv = if deformed && modulus > 0.0 { f.try_inverse() } else { None };
            *point = (f_inv, modulus * quad.weight[q]);
        });
        let points = &self.points;
        let (mass, flags) = (&model.particles.mass, &model.particles.flags);
        // `|b_J(q)| / √m_J` over the rows of J's free components.
        let scaled = |k: usize, q: usize, j: usize| -> Real {
            let (held_x, held_y) = (flags[j].has(ParticleFlags::FIX_X), flags[j].has(ParticleFlags::FIX_Y));
            if held_x && held_y {
                return 0.0;
            }
            // Held radially, only the axial row moves: no hoop entry.
            let r = if held_x { None } else { hoop(q) };
            column_norm(&table.grad[k], table.value[k], points[q].0.as_ref(), r) / mass[j].sqrt()
        };
        // The entries of each piece of PARALLEL_PIECE points are one
        // contiguous run of the table, from the piece's first point's.
        self.entries.resize_with(quad.len().div_ceil(PARALLEL_PIECE), Vec::new);
        self.row_factor.par_chunks_mut(PARALLEL_PIECE).zip(&mut self.entries).enumerate().for_each(
            |(n, (factors, entries))| {
                let q0 = n * PARALLEL_PIECE;
                let first = table.offsets[q0];
                entries.resize(table.offsets[q0 + factors.len()] - first, 0.0);
                for (dq, factor) in factors.iter_mut().enumerate() {
                    let q = q0 + dq;
                    let modulus_w = points[q].1;
                    *factor = if modulus_w == 0.0 {
                        0.0
                    } else {
                        let mut s = 0.0;
                        for k in table.range(q) {
                            let e = scaled(k, q, table.index[k] as usize);
                            entries[k - first] = e;
                            s += e;
                        }
                        s * modulus_w
                    };
                }
            },
        );
        let (gather, row_factor, entries) = (&model.gather, &self.row_factor, &self.entries);
        self.bounds.par_iter_mut().with_max_len(PARALLEL_PIECE).enumerate().for_each(|(i, bound)| {
            let mut sum = 0.0;
            for j in gather.range(i) {
                let (k, q) = (gather.entry[j] as usize, gather.point[j] as usize);
                if row_factor[q] != 0.0 {
                    let q0 = q - q % PARALLEL_PIECE;
                    sum += entries[q / PARALLEL_PIECE][k - table.offsets[q0]] * row_factor[q];
                }
            }
            *bound = sum;
        });
    }
}

/// The modulus a point resists a change of its strain with, Pa: the
/// P-wave modulus `K + 4G/3 = ρ c_L²` of its material; none if it is eroded;
/// and while cracks grow (`fractured`: its damage and `J`), the bulk
/// modulus of a point fractured by its damage (`D ≥ 1`) while it is closed
/// (`J < 1`: it carries pressure only) and none once it has opened
/// ([`crate::material::fractured`]).
fn point_modulus(material: &Material, eroded: bool, fractured: Option<(Real, Real)>) -> Real {
    match (eroded, fractured) {
        (true, _) => 0.0,
        (false, Some((damage, j))) if crate::material::is_fractured(damage) => {
            if j < 1.0 {
                material.bulk_modulus()
            } else {
                0.0
            }
        }
        _ => material.density() * material.longitudinal_wave_speed().powi(2),
    }
}

/// The largest entry of `bounds` and its particle (the first on ties).
pub fn stiffest(bounds: &[Real]) -> (Real, usize) {
    bounds.iter().enumerate().fold((0.0, 0), |(best, at), (i, &w2)| if w2 > best { (w2, i) } else { (best, at) })
}

/// `(ω, particle)` of the stiffest particle ([`frequency_bounds`]), in the
/// reference configuration or the current one.
pub fn stiffest_particle(model: &Model, deformed: bool, fracturing: bool) -> (Real, usize) {
    let (w2, i) = stiffest(&frequency_bounds(model, deformed, fracturing));
    (w2.sqrt(), i)
}

/// The adaptive stable step (module doc): `Δt = Δt₀ min(1, ω_ref / ω_max)`,
/// with `ω_ref` the bound of the stiffest free particle of the reference
/// lattice, for which the rule's step `Δt₀` was chosen, and `ω_max` that
/// of the current configuration, re-evaluated after every crack change and
/// every [`StableStep::every`] steps.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct StableStep {
    /// The rule's step `Δt₀`, s.
    pub base: Real,
    /// `ω_ref`, rad/s.
    pub reference: Real,
    /// Steps between evaluations without a crack change.
    pub every: u64,
    /// The smallest step taken so far, s, the time it was chosen at, s,
    /// and the particle that set it.
    pub smallest: (Real, Real, usize),
    /// Not in checkpoints: rewritten by every evaluation.
    #[serde(skip)]
    scratch: BoundScratch,
}

/// Steps between two evaluations of the stable step when no crack changed:
/// one evaluation costs about two force gathers; every 10 steps that is a
/// few per cent of a step's work, and 10 steps of the spacing step are
/// about 5 % of the time a wave takes to cross one spacing... of the
/// deformation a point undergoes in them (measured in `docs/performance.md`).
pub const EVALUATE_EVERY: u64 = 10;

impl StableStep {
    /// The reference bound of `model` (undeformed) for the rule's step `base`.
    pub fn new(model: &Model, base: Real) -> Self {
        let (reference, i) = stiffest_particle(model, false, false);
        StableStep {
            base,
            reference,
            every: EVALUATE_EVERY,
            smallest: (base, 0.0, i),
            scratch: BoundScratch::default(),
        }
    }

    /// The stable step of `model` in its current configuration at `time`,
    /// with `damping_ratio` the largest damping ratio of the bulk viscosity
    /// on a full lattice (0 without it; the step is then the elastic one bit
    /// for bit), and the particle that sets it.
    pub fn evaluate(&mut self, model: &Model, time: Real, fracturing: bool, damping_ratio: Real) -> Real {
        self.scratch.fill(model, true, fracturing);
        let (w2, i) = stiffest(&self.scratch.bounds);
        let w = w2.sqrt();
        let elastic =
            if w > self.reference && self.reference > 0.0 { self.base * (self.reference / w) } else { self.base };
        // A light particle's damping ratio grows with its frequency
        // (`crate::bulk_viscosity`, "The stable step").
        let dt = elastic * step_factor(damping_ratio * (self.base / elastic));
        if dt < self.smallest.0 {
            self.smallest = (dt, time, i);
        }
        dt
    }
}
