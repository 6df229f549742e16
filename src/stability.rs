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
//! - **Mass scaling** (`[time] mass_scaling = f`, off by default; not in
//!   SPEC §5 or \[RL10\]). On the fine rungs the step falls far below the
//!   spacing step once cracks run: at 96 rows through the 12 mm plate from
//!   10.8 ns to 2.5 ns by 60 µs, set by a few particles out of 160,000:
//!   crack-face children, and from 45 µs on a failed sliver of the
//!   impact face between the rim crack and the projectile's edge, whose
//!   points the punch shears at constant volume to a stretch of about 12
//!   (its bound's own term 100 times its undeformed value;
//!   `docs/performance.md`, "The fine rungs: what sets their step"); a
//!   held run then takes hours. With `f`, every evaluation first adds mass to each
//!   particle whose bound would take the elastic step below `f · Δt₀`,
//!   as little as brings its bound to the target
//!   ([`BoundScratch::scale_masses`]), as the common explicit codes do
//!   (LS-DYNA's `DT2MS`). The mass is added at rest: the particle's
//!   velocity drops so that its momentum stays, and the kinetic energy
//!   this takes out is booked in the balance
//!   ([`crate::step::Energies::mass_scaling`]). Added mass stays on its
//!   particle ([`crate::particles::Particles::added_mass`]): a split
//!   halves it with the mass, the re-lumping at a crack keeps it. The run
//!   summary reports it. It changes a crack face's inertia slightly (the
//!   particles it touches are a crack's first rows), so it is an option
//!   whose effect is measured (`docs/performance.md`), not the default.
//!   Tests: `mass_scaling_holds_the_step_at_its_floor_and_keeps_the_margin`
//!   (the step, the mass only where needed, momentum, the energy account,
//!   and the exact highest frequency of the scaled system),
//!   `splits_keep_the_mass_that_mass_scaling_added` (`tests/fracture.rs`).
//! - **Erosion at the step's floor** (`[time] erode_failed_below = f`,
//!   off by default; not in SPEC §5 or \[RL10\]). Mass scaling treats the
//!   failed sliver above as it treats a light particle, by slowing it
//!   down. The other remedy of the explicit codes is to remove a failed
//!   element whose step falls below a floor (LS-DYNA's erosion at a
//!   minimum step). With `f`, every evaluation first erodes fractured
//!   points (`D ≥ 1` while cracks grow, pressure only,
//!   [`crate::material::fractured`]) that take a particle's bound above
//!   the floor's target `(ω_ref / f)²`, as few as bring it there, largest
//!   term first, and none where all of them would not
//!   ([`BoundScratch::erode_failed`]); an eroded point carries
//!   no stress from then on ([`crate::quadrature::QuadraturePoints::erode`]),
//!   its particles keep their mass. Intact or merely damaged points are
//!   never eroded: where they set the step it falls as before. What it
//!   removes is the pressure a crushed, failed crumb still carries, so it
//!   is an option whose effect is measured (`docs/performance.md`), not the
//!   default. Test: `erosion_at_the_floor_removes_a_failed_sliver_and_only_it`
//!   (the sliver makes the spacing step unstable by the exact highest
//!   frequency; after erosion the step keeps half the stability limit;
//!   intact, damaged and mildly sheared fractured points stay).

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

/// The entries of point `q`'s piece of [`BoundScratch::entries`], and the
/// table index of the piece's first entry (entry `k` of `q` is at `k −
/// first`).
#[inline]
fn piece<'a>(entries: &'a [Vec<Real>], offsets: &[usize], q: usize) -> (&'a [Real], usize) {
    (&entries[q / PARALLEL_PIECE], offsets[q - q % PARALLEL_PIECE])
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
                    let (entries, first) = piece(entries, &table.offsets, q);
                    sum += entries[k - first] * row_factor[q];
                }
            }
            *bound = sum;
        });
    }

    /// The particles whose bound exceeds `target`, stiffest first (ties by
    /// index): the order both floors take them in.
    fn stiffest_over(&self, target: Real) -> Vec<usize> {
        let mut over: Vec<usize> = (0..self.bounds.len()).filter(|&i| self.bounds[i] > target).collect();
        over.sort_by(|&a, &b| self.bounds[b].total_cmp(&self.bounds[a]).then(a.cmp(&b)));
        over
    }

    /// Mass scaling: the factors `m_new / m_I` (> 1) that bring every
    /// particle's bound `ω_I²` ([`BoundScratch::bounds`], as filled for
    /// `model`) down to `target`, with as little mass added as this
    /// bound allows.
    ///
    /// A particle's bound is its own term and its neighbours':
    /// `ω_I² = S_I + O_I`, `S_I = Σ_q k_q w_q |b_I(q)|² / m_I` and
    /// `O_I = Σ_q k_q w_q (|b_I(q)|/√m_I) Σ_{J≠I} |b_J(q)|/√m_J`. Scaling
    /// `m_I` by `s` scales `S_I` by `1/s` and `O_I` by `1/√s`, so with
    /// `y = 1/√s` the bound meets the target at the root of
    /// `S_I y² + O_I y = target`. The particles above the target are taken
    /// stiffest first (ties by index), each with its neighbours' masses as
    /// scaled before it; scaling one lowers its neighbours' bounds, so a
    /// particle the ones before it brought down gets no mass, and no bound
    /// rises: afterwards every bound is at most `target` (to round-off).
    pub fn scale_masses(&self, model: &Model, target: Real) -> Vec<(usize, Real)> {
        let over = self.stiffest_over(target);
        if over.is_empty() {
            return Vec::new();
        }
        let (table, gather) = (&model.qp_shape, &model.gather);
        // `1/√s_J` of the particles scaled so far.
        let mut shrink: std::collections::HashMap<usize, Real> = std::collections::HashMap::new();
        let mut scaled = Vec::new();
        for i in over {
            let (mut own, mut others) = (0.0, 0.0);
            for j in gather.range(i) {
                let (k, q) = (gather.entry[j] as usize, gather.point[j] as usize);
                let modulus_w = self.points[q].1;
                if self.row_factor[q] == 0.0 || modulus_w == 0.0 {
                    continue;
                }
                let (entries, first) = piece(&self.entries, &table.offsets, q);
                let factor = |k: usize| shrink.get(&(table.index[k] as usize)).copied().unwrap_or(1.0);
                let e_i = entries[k - first] * factor(k);
                let rest: Real = table.range(q).filter(|&m| m != k).map(|m| entries[m - first] * factor(m)).sum();
                own += modulus_w * e_i * e_i;
                others += modulus_w * e_i * rest;
            }
            if own + others <= target {
                continue;
            }
            let y = if own > 0.0 {
                (-others + (others * others + 4.0 * own * target).sqrt()) / (2.0 * own)
            } else {
                target / others
            };
            shrink.insert(i, y);
            scaled.push(i);
        }
        scaled.into_iter().map(|i| (i, 1.0 / shrink[&i].powi(2))).collect()
    }

    /// Erosion at the step's floor: the points to erode so that every
    /// particle's bound ([`BoundScratch::bounds`], as filled for `model`)
    /// falls to `target`, taken only among the points `failed` admits (and
    /// that still carry stress).
    ///
    /// A particle's bound is the sum of its points' terms,
    /// `ω_I² = Σ_q c_Iq`, `c_Iq = k_q w_q (|b_I(q)|/√m_I) Σ_J |b_J(q)|/√m_J`;
    /// an eroded point's `k_q` is 0, so eroding `q` takes its `c_Iq` off
    /// every particle it reaches and raises no bound. The particles above
    /// the target are taken stiffest first (ties by index), each with the
    /// points eroded before it left out; each erodes its admitted points,
    /// largest term first (ties by index), until its bound is at most the
    /// target, and none where all of them would not bring it there (its
    /// bound is then set by intact points or its own mass, which erosion
    /// does not treat). Returns the points in increasing order.
    pub fn erode_failed(&self, model: &Model, target: Real, failed: impl Fn(usize) -> bool) -> Vec<usize> {
        let over = self.stiffest_over(target);
        let (table, gather) = (&model.qp_shape, &model.gather);
        let mut eroded = std::collections::BTreeSet::new();
        for i in over {
            let (mut bound, mut admitted) = (0.0, Vec::new());
            for j in gather.range(i) {
                let (k, q) = (gather.entry[j] as usize, gather.point[j] as usize);
                if self.row_factor[q] == 0.0 || eroded.contains(&q) {
                    continue;
                }
                let (entries, first) = piece(&self.entries, &table.offsets, q);
                let term = entries[k - first] * self.row_factor[q];
                bound += term;
                if failed(q) {
                    admitted.push((term, q));
                }
            }
            // Where the failed points cannot bring the bound down (a light
            // crack-face child sets it), none goes: erosion would not help.
            if bound - admitted.iter().map(|&(term, _)| term).sum::<Real>() > target {
                continue;
            }
            admitted.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            for (term, q) in admitted {
                if bound <= target {
                    break;
                }
                eroded.insert(q);
                bound -= term;
            }
        }
        eroded.into_iter().collect()
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

/// One particle's part in the stable step, for `plugsim time-step`: what
/// a run's step is waiting on, and why (a light particle, a distorted
/// row, a failed crumb still carrying pressure).
#[derive(Clone, Debug, PartialEq)]
pub struct StepSetter {
    pub particle: usize,
    /// The elastic step this particle alone allows, s: `Δt₀ min(1,
    /// ω_ref / ω_I)` ([`StableStep::evaluate`]; the run's step is the least
    /// of these, times the bulk viscosity's factor where it damps).
    pub step: Real,
    /// `ω_I²` over its bound with the undeformed gradients (the same
    /// masses, moduli and rows): 1 on an undistorted lattice, the factor
    /// its points' distortion alone raised it by.
    pub distortion: Real,
    /// Its mass, kg (per unit depth in plane strain), and the mass
    /// scaling added to it.
    pub mass: Real,
    pub added_mass: Real,
    /// The points of its support: how many, how many eroded, how many
    /// fractured (`D ≥ 1`).
    pub points: usize,
    pub eroded: usize,
    pub fractured: usize,
    /// Over its live points: the least `J = det F`, and the largest
    /// in-plane stretch ratio `σ₁/σ₂` of `F` (1 for a pure dilatation; a
    /// point sheared at constant volume to a stretch `λ` reads `λ²`).
    pub least_j: Real,
    pub largest_stretch: Real,
}

/// The singular-value ratio `σ₁/σ₂ ≥ 1` of the in-plane block of `f`
/// (infinite for a singular block): from `σ₁² + σ₂² = |F|²` and `σ₁ σ₂ =
/// |det F|`.
pub fn stretch_ratio(f: &Block2) -> Real {
    let sum = f.xx * f.xx + f.xy * f.xy + f.yx * f.yx + f.yy * f.yy;
    let det = (f.xx * f.yy - f.xy * f.yx).abs();
    if det == 0.0 {
        return Real::INFINITY;
    }
    let root = (sum * sum - 4.0 * det * det).max(0.0).sqrt();
    ((sum + root) / (sum - root).max(Real::MIN_POSITIVE)).sqrt()
}

/// The `top` particles that allow the smallest steps in `model`'s current
/// configuration, stiffest first (ties by index), for the adaptive step
/// `stable` (`fracturing` as the run evaluates it:
/// [`crate::step::Simulation::fractures_points`]).
pub fn step_setters(model: &Model, stable: &StableStep, fracturing: bool, top: usize) -> Vec<StepSetter> {
    let deformed = frequency_bounds(model, true, fracturing);
    let undeformed = frequency_bounds(model, false, fracturing);
    let mut order: Vec<usize> = (0..deformed.len()).collect();
    order.sort_by(|&a, &b| deformed[b].total_cmp(&deformed[a]).then(a.cmp(&b)));
    let (p, quad) = (&model.particles, &model.quad);
    order
        .into_iter()
        .take(top)
        .map(|i| {
            let step = stable.elastic_step(deformed[i].sqrt());
            // Each of its points once (a row holds a particle once).
            let points: Vec<usize> = model.gather.range(i).map(|j| model.gather.point[j] as usize).collect();
            let live = || points.iter().copied().filter(|&q| !quad.eroded[q]);
            StepSetter {
                particle: i,
                step,
                distortion: if undeformed[i] > 0.0 { deformed[i] / undeformed[i] } else { Real::NAN },
                mass: p.mass[i],
                added_mass: p.added_mass[i],
                points: points.len(),
                eroded: points.iter().filter(|&&q| quad.eroded[q]).count(),
                fractured: points.iter().filter(|&&q| crate::material::is_fractured(quad.damage[q])).count(),
                least_j: live().map(|q| quad.f[q].determinant()).fold(Real::INFINITY, Real::min),
                largest_stretch: live().map(|q| stretch_ratio(&quad.f[q])).fold(1.0, Real::max),
            }
        })
        .collect()
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
    /// Mass scaling's account ([`StableStep::evaluate`] with a floor; the
    /// kinetic energy it took out is in
    /// [`crate::step::Energies::mass_scaling`], the mass per particle in
    /// [`crate::particles::Particles::added_mass`]).
    pub added: AddedMass,
    /// Fractured points eroded at the step's floor so far
    /// ([`StableStep::evaluate`] with an erosion floor).
    pub eroded: u64,
    /// Not in checkpoints: rewritten by every evaluation.
    #[serde(skip)]
    scratch: BoundScratch,
}

/// The floors of the stable step ([`StableStep::evaluate`]), each a
/// fraction of the rule's step `Δt₀` in (0, 1], or none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Floors {
    /// Mass scaling (`[time] mass_scaling`).
    pub mass_scaling: Option<Real>,
    /// Erosion of fractured points (`[time] erode_failed_below`).
    pub erosion: Option<Real>,
}

/// The running account of mass scaling ([`StableStep::evaluate`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AddedMass {
    /// Mass added so far, kg (per unit depth in plane strain).
    pub mass: Real,
    /// Evaluations that added mass.
    pub evaluations: u64,
    /// The largest mass added to one particle at once, as a multiple of
    /// its mass before.
    pub largest_factor: Real,
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
            added: AddedMass::default(),
            eroded: 0,
            scratch: BoundScratch::default(),
        }
    }

    /// The elastic step for a stiffest bound `w` (rad/s): `Δt₀ min(1,
    /// ω_ref / w)` (module doc), the rule's step while no particle is
    /// stiffer than the reference lattice's stiffest.
    pub fn elastic_step(&self, w: Real) -> Real {
        if w > self.reference && self.reference > 0.0 {
            self.base * (self.reference / w)
        } else {
            self.base
        }
    }

    /// The stable step of `model` in its current configuration at `time`,
    /// with `damping_ratio` the largest damping ratio of the bulk viscosity
    /// on a full lattice (0 without it; the step is then the elastic one bit
    /// for bit), and the particle that sets it.
    ///
    /// With `floors.mass_scaling` (`[time] mass_scaling`), mass is
    /// first added to every particle whose bound would take the elastic
    /// step below `floors.mass_scaling · Δt₀` ([`BoundScratch::scale_masses`]),
    /// at rest: its velocity drops so that its momentum stays, and the
    /// kinetic energy this takes out is returned (J; 0 without mass
    /// added), for the energy account.
    ///
    /// With `floors.erosion` (`[time] erode_failed_below`) and `fracturing`,
    /// before that, the fractured points (`D ≥ 1`) that would take the
    /// elastic step below `floors.erosion · Δt₀` are eroded, as few as
    /// bring every bound they reach to that floor
    /// ([`BoundScratch::erode_failed`]).
    pub fn evaluate(
        &mut self,
        model: &mut Model,
        time: Real,
        fracturing: bool,
        damping_ratio: Real,
        floors: Floors,
    ) -> (Real, Real) {
        self.scratch.fill(model, true, fracturing);
        if let Some(floor) = floors.erosion.filter(|_| fracturing) {
            let quad = &model.quad;
            let failed = |q: usize| crate::material::is_fractured(quad.damage[q]);
            let points = self.scratch.erode_failed(model, (self.reference / floor).powi(2), failed);
            if !points.is_empty() {
                for &q in &points {
                    model.quad.erode(q);
                }
                self.eroded += points.len() as u64;
                self.scratch.fill(model, true, fracturing);
            }
        }
        let mut removed = 0.0;
        if let Some(floor) = floors.mass_scaling {
            let target = (self.reference / floor).powi(2);
            let scaled = self.scratch.scale_masses(model, target);
            if !scaled.is_empty() {
                let p = &mut model.particles;
                for &(i, factor) in &scaled {
                    let (m, v) = (p.mass[i], p.v[i]);
                    let dm = m * (factor - 1.0);
                    // Held components keep their velocity (zero, or driven).
                    let keep = |fix: u8| if p.flags[i].has(fix) { 1.0 } else { 1.0 / factor };
                    let v_new = Vec2::new(v.x * keep(ParticleFlags::FIX_X), v.y * keep(ParticleFlags::FIX_Y));
                    removed += 0.5 * m * v.norm_squared() - 0.5 * (m + dm) * v_new.norm_squared();
                    p.mass[i] = m + dm;
                    p.added_mass[i] += dm;
                    p.v[i] = v_new;
                    self.added.mass += dm;
                    self.added.largest_factor = self.added.largest_factor.max(factor);
                }
                self.added.evaluations += 1;
                self.scratch.fill(model, true, fracturing);
            }
        }
        let (w2, i) = stiffest(&self.scratch.bounds);
        let elastic = self.elastic_step(w2.sqrt());
        // A light particle's damping ratio grows with its frequency
        // (`crate::bulk_viscosity`, "The stable step").
        let dt = elastic * step_factor(damping_ratio * (self.base / elastic));
        if dt < self.smallest.0 {
            self.smallest = (dt, time, i);
        }
        (dt, removed)
    }
}
