//! The explicit time loop (SPEC §5): one documented stage order, stage
//! timers, energy bookkeeping and instability detection.

use crate::bulk_viscosity::{current_length, BulkViscosity};
use crate::contact::{ContactError, ContactSystem, StepInput};
use crate::fracture::{CrackGrowth, FractureError};
use crate::geometry::GeometryMode;
use crate::material::{Constitutive, StepKinematics};
use crate::math::{is_block_2d, Block2, InPlane, Real, Tensor3, Vec2};
use crate::model::{constrain, Model, PARALLEL_PIECE};
use crate::particles::ParticleFlags;
use crate::quadrature::NO_CARRY;
use crate::stability::{Floors, StableStep};
use crate::thermal::{HeatConduction, HeatError};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// How the time step is chosen (SPEC §5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeStepRule {
    /// `Δt = safety · min_I h_I / c_L`.
    Cfl { safety: Real },
    /// A fixed step, s.
    Fixed(Real),
}

/// Energy account, J (per unit depth in plane strain).
///
/// The deformable bodies gain `kinetic + internal` from the work of contact
/// forces on them (`contact_work`); rigid bodies gain `rigid_kinetic` from
/// the reactions (`rigid_work`). The sum `contact_work + rigid_work` is the
/// energy the contact itself dissipated (≤ 0 for a well-behaved contact).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Energies {
    /// `½ Σ m_I |V_I|²` of the particles at the last full step (see
    /// `full_step_kinetic_terms`).
    pub kinetic: Real,
    /// Stress work `∫∫ τ : d dV₀ dt` (elastic energy + plastic dissipation).
    pub internal: Real,
    /// Kinetic energy of the rigid bodies.
    pub rigid_kinetic: Real,
    /// Work of the contact forces on the particles.
    pub contact_work: Real,
    /// Work of the contact reactions on the rigid bodies.
    pub rigid_work: Real,
    /// Total kinetic energy (particles + rigid bodies) at the start.
    pub initial_kinetic: Real,
    /// Kinetic energy taken out by mass scaling, which adds mass at rest
    /// ([`crate::stability::StableStep::evaluate`]; 0 without it).
    pub mass_scaling: Real,
    /// Kinetic energy taken out by the crack stage's changes: a split's or
    /// a detachment's re-lumped masses, momentum correction and rebuilt
    /// internal force move the full-step kinetic energy
    /// (`Simulation::full_step_kinetic_terms`) without any work; summed
    /// over the changes, the estimate before less the estimate after
    /// (`Simulation::grow_cracks`; 0 without cracks).
    pub crack_changes: Real,
}

impl Energies {
    /// `kinetic + rigid_kinetic + internal − (contact_work + rigid_work)`
    /// `+ mass_scaling + crack_changes`: stays at `initial_kinetic` in an
    /// exact integration.
    pub fn total(&self) -> Real {
        self.kinetic + self.rigid_kinetic + self.internal - (self.contact_work + self.rigid_work)
            + self.mass_scaling
            + self.crack_changes
    }
    /// Energy dissipated by the contact algorithm, `−(contact_work + rigid_work)`.
    pub fn contact_dissipation(&self) -> Real {
        -(self.contact_work + self.rigid_work)
    }
    /// Relative drift of the balance against the initial kinetic energy
    /// (the energy put in).
    pub fn drift(&self) -> Real {
        (self.total() - self.initial_kinetic) / self.initial_kinetic.max(Real::MIN_POSITIVE)
    }
}

/// Wall time spent in each stage.
#[derive(Clone, Debug, Default)]
pub struct StageTimers {
    pub contact: Duration,
    pub integration: Duration,
    pub material: Duration,
    pub heat: Duration,
    pub internal_force: Duration,
    pub crack_growth: Duration,
    pub diagnostics: Duration,
}

impl StageTimers {
    /// `(name, duration)` pairs in stage order.
    pub fn list(&self) -> Vec<(&'static str, Duration)> {
        vec![
            ("contact", self.contact),
            ("time integration", self.integration),
            ("velocity gradient + material", self.material),
            ("heat conduction", self.heat),
            ("internal force", self.internal_force),
            ("crack growth", self.crack_growth),
            ("diagnostics", self.diagnostics),
        ]
    }
}

/// A run that went wrong, with where and when.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolverError {
    #[error(
        "non-finite {field} at {location} {index} in step {step} (t = {time:.6e} s); \
         likely cause: time step too large for the particle spacing, or a support too small"
    )]
    NonFinite { field: &'static str, location: &'static str, index: usize, step: u64, time: Real },
    /// A finite temperature at or below 0 K: no update makes one, so an
    /// unstable transfer has started (a growing one stays finite long
    /// before it overflows).
    #[error(
        "temperature {temperature:.3e} K at quadrature point {point} in step {step} (t = {time:.6e} s), \
         at or below absolute zero; likely cause: an unstable heat transfer"
    )]
    BelowAbsoluteZero { point: usize, temperature: Real, step: u64, time: Real },
    #[error(
        "deformation gradient inverted (J = {jacobian:.3e}) at quadrature point {point} \
         (X = ({x:.4e}, {y:.4e}) m) in step {step} (t = {time:.6e} s); likely cause: \
         time step too large or excessive distortion"
    )]
    Inverted { point: usize, x: Real, y: Real, jacobian: Real, step: u64, time: Real },
    #[error("contact failed in step {step} (t = {time:.6e} s): {source}")]
    Contact {
        #[source]
        source: ContactError,
        step: u64,
        time: Real,
    },
    #[error("heat conduction failed in step {step} (t = {time:.6e} s): {source}")]
    Heat {
        #[source]
        source: HeatError,
        step: u64,
        time: Real,
    },
    #[error(
        "particle {particle} moves at {speed:.3e} m/s, above the bound {bound:.3e} m/s, in step {step} \
         (t = {time:.6e} s); the solution has gone unstable; likely cause: a time step above the stability limit"
    )]
    Runaway { particle: usize, speed: Real, bound: Real, step: u64, time: Real },
    #[error("crack growth failed in step {step} (t = {time:.6e} s): {source}")]
    Fracture {
        #[source]
        source: Box<FractureError>,
        step: u64,
        time: Real,
    },
    #[error(
        "energy blow-up in step {step} (t = {time:.6e} s): the energy balance totals {total:.4e} J, more than \
         {factor} times the {input:.4e} J put in; the fastest particle is {particle} at {speed:.3e} m/s; \
         likely cause: a time step above the stability limit (time.fixed_dt larger than the CFL step), \
         or contact forces feeding energy in",
        factor = ENERGY_BLOWUP_FACTOR
    )]
    EnergyBlowUp { total: Real, input: Real, particle: usize, speed: Real, step: u64, time: Real },
}

/// A run stops with [`SolverError::EnergyBlowUp`] when its energy balance
/// ([`Energies::total`]) exceeds this multiple of the energy put in
/// ([`Simulation::input_energy`]). Stable runs keep the balance within a
/// few percent (SPEC §5 warns beyond that), so 2 is far outside any
/// integration error; an instability grows exponentially and crosses it
/// within a few e-foldings, usually steps before speeds reach the runaway
/// bound or values overflow, so the run stops with the most telling message
/// while its last snapshot still shows where it started. Runs with no input
/// energy are not checked this way (the other checks still apply). Tests:
/// `unstable_fixed_dt_stops_with_a_message` and
/// `a_driven_punch_is_not_an_energy_blow_up` (tests/robustness.rs).
pub const ENERGY_BLOWUP_FACTOR: Real = 2.0;

/// The fastest particle of a run so far (issue #19: no particle may leave
/// faster than momentum and energy allow; the validation and ballistic
/// reports show this speed). Speeds are physical, `|v(X_I)|` with
/// `v(X_I) = Σ_J N_J(X_I) V_J` (SPEC §2: RK particles are not
/// interpolating; the generalized `V_I` of a particle beside a sharp
/// velocity jump oscillate beyond the field they interpolate), taken
/// after every step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FastestParticle {
    /// `max_I |v(X_I)|` over the steps so far, m/s (0 before the first step).
    pub speed: Real,
    /// The particle that had it.
    pub particle: usize,
    /// When, s.
    pub time: Real,
    /// Its physical position `X_I + Σ_J N_J(X_I) U_J` then, m.
    pub position: Vec2,
    /// Its reference position `X_I`, m: where the material came from.
    pub reference: Vec2,
    /// Its lumped mass then, kg (kg/m in plane strain).
    pub mass: Real,
    /// Whether it lay on a crack face then (a split's child or parent):
    /// the light particles a split makes are the usual fast ones
    /// (docs/validation.md, "Fastest particle").
    pub crack_face: bool,
    /// The share of its lumped material at quadrature points not eroded
    /// then ([`crate::fracture::growth::live_share`]; 1 for intact
    /// material). Near 0 the particle has lost its material, and what moves
    /// it is what its rows still carry: the last live points' pressure, the
    /// contact force spread onto it by the slaves whose rows hold it
    /// (docs/validation.md, "The 610 m/s throw traced"). `None` in a record
    /// written before it was kept.
    #[serde(default)]
    pub live_share: Option<Real>,
}

impl FastestParticle {
    /// For a run summary: "534.0 m/s, particle 114144 (a crack-face
    /// particle from (9.877, 10.200) mm, mass 1.690e-6 kg; kg/m in plane
    /// strain; 1.1 % of its material left) at (12.43, 14.73) mm, t =
    /// 14.880 us"; the share of material is named only where some of it
    /// is gone.
    pub fn describe(&self) -> String {
        let left = match self.live_share {
            Some(s) if s <= 0.0 => "; none of its material left".to_string(),
            Some(s) if s < 1.0 => format!("; {:.1} % of its material left", 100.0 * s),
            _ => String::new(),
        };
        format!(
            "{:.1} m/s, particle {} ({}, mass {:.3e} kg; kg/m in plane strain{left}) at ({:.2}, {:.2}) mm, t = {:.3} us",
            self.speed,
            self.particle,
            particle_origin(self.crack_face, self.reference),
            self.mass,
            self.position.x * 1e3,
            self.position.y * 1e3,
            self.time * 1e6
        )
    }
}

/// What a report says of a particle's kind and origin: "a crack-face
/// particle from (9.877, 10.200) mm" (its reference position `X_I`), or
/// "a particle from …" off the cracks.
pub fn particle_origin(crack_face: bool, reference: Vec2) -> String {
    let kind = if crack_face { "a crack-face particle" } else { "a particle" };
    format!("{kind} from ({:.3}, {:.3}) mm", reference.x * 1e3, reference.y * 1e3)
}

/// `(sqrt(max_I s2(I)), I)` over `n` particles, for a squared norm `s2`
/// (a speed, a gap): the lowest index among equals, so the same for any
/// number of threads; `(0, 0)` without particles.
fn largest_by(n: usize, s2: impl Fn(usize) -> Real + Sync) -> (Real, usize) {
    let (s2, i) = (0..n)
        .into_par_iter()
        .map(|i| (s2(i), i))
        .reduce(|| (0.0, 0), |a, b| if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) { b } else { a });
    (s2.sqrt(), i)
}

/// How far the particles' own coefficients have left the field they
/// interpolate: `(max_I |U_I − u(X_I)| / h_I, I)` with `u(X_I) = Σ_J
/// N_J(X_I) U_J` and `h_I` the particle's spacing. RK particles are not
/// interpolating (SPEC §2), so the gap is never exactly 0 where the field
/// curves, but it stays a small fraction of a spacing in a body that
/// holds its particles; a particle whose material no longer holds it
/// can drift several spacings from the field, which hides its motion
/// until a change of its shape functions (a split, a detachment) shows
/// it at once (docs/validation.md, "Three throws traced with
/// `output.trace_particles`"). A detached particle is its own field: 0.
///
/// What a gap can move: not the moments a run reports. The plug's mass and
/// velocity, a deformable body's sample and the total momentum are sums of
/// `m_I V_I` and `m_I (X_I + U_I)`, which with row-sum masses (SPEC §4) are
/// exactly the field's `∫ ρ v dV` and `∫ ρ x dV`, gaps or not (test
/// `coefficients_off_the_field_leave_its_momentum_and_centre_of_mass_exact`);
/// the fastest particle and the snapshots read the field. What reads a
/// coefficient itself: the gap point of the contact spreadings `none` and
/// `inverse_distance` (\[RL10\]'s, the paper's mode), the axis wall's choice
/// of which particles to predict (those whose coefficient lies within two
/// supports of the axis, four spacings at the default support factor 2),
/// which would miss a particle whose point crosses the axis with a gap of
/// more than two supports. Measured: gaps past four spacings (4.6–5.5)
/// occur in five hemispherical runs of the report and in no blunt one;
/// rerun with every particle predicted, those five logged no particle
/// crossing the axis outside the choice, and their histories were the same
/// bits (docs/validation.md, "Case I's plate over the lattice's phase with
/// the default model; the axis wall's reach").
pub fn coefficient_gap(model: &Model) -> (Real, usize) {
    let (tab, p) = (&model.particle_shape, &model.particles);
    largest_by(p.len(), |i| ((p.u[i] - tab.interpolate(i, &p.u)) / p.spacing[i]).norm_squared())
}

/// The physically fastest particle of `model` now, `(|v(X_I)|, I)`
/// ([`FastestParticle`]); one pass over the particle shape table, no
/// allocation.
pub fn fastest_particle(model: &Model) -> (Real, usize) {
    let (tab, v) = (&model.particle_shape, &model.particles.v);
    largest_by(v.len(), |i| tab.interpolate(i, v).norm_squared())
}

/// The running simulation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Simulation {
    pub model: Model,
    /// Simulated time, s.
    pub time: Real,
    /// Steps taken.
    pub step: u64,
    /// Time step, s.
    pub dt: Real,
    pub energies: Energies,
    /// Wall-clock time per stage: not in checkpoints (a resumed run times
    /// its own steps).
    #[serde(skip)]
    pub timers: StageTimers,
    /// Speed above which a particle is declared runaway, m/s.
    pub speed_bound: Real,
    /// The fastest particle of the run so far.
    pub fastest: FastestParticle,
    /// Contact with rigid bodies, if the case has any.
    pub contact: Option<ContactSystem>,
    /// Heat conduction (SPEC §7), if the case asks for it. Not in
    /// checkpoints: it keeps no state between steps (each call rewrites its
    /// scratch and report; its cached stable-step factor depends on the
    /// reference configuration only) and is rebuilt from the case and the
    /// model on reading, as a fresh run builds it.
    #[serde(skip)]
    pub heat: Option<HeatConduction>,
    /// Artificial bulk viscosity ([`crate::bulk_viscosity`]; none by
    /// default). Not in checkpoints: set from the case, as `heat`.
    #[serde(skip, default = "BulkViscosity::none")]
    pub bulk_viscosity: BulkViscosity,
    /// The largest damping ratio of the bulk viscosity at the last material
    /// update (0 without it), for the stable step. Not in checkpoints: every
    /// step's material update sets it before the step is evaluated.
    #[serde(skip)]
    viscous_damping: Real,
    /// Some held (FIX_X / FIX_Y) component moves at a non-zero velocity:
    /// kinematic driving, whose work the energy account does not tally.
    pub driven_constraints: bool,
    /// Conduct heat once every this many steps (1: every step).
    pub heat_every: u64,
    /// Time accumulated since the last conduction, s.
    pub heat_pending: Real,
    /// Contact forces of the current step, per particle (scratch).
    pub f_contact: Vec<Vec2>,
    /// Crack growth (SPEC §9), if the case has a fracture criterion.
    pub cracks: Option<CrackGrowth>,
    /// The adaptive stable step ([`crate::stability`]); `None` with a
    /// fixed step.
    pub stable: Option<StableStep>,
    /// The step before this one, s (`dt` at the first step).
    pub dt_previous: Real,
    /// The step's floors ([`crate::stability::Floors`]): mass scaling, the
    /// smallest elastic step as a fraction of the rule's step `Δt₀`, held
    /// by adding mass to the particles that would take it lower (`[time]
    /// mass_scaling`), and erosion of the fractured points that would
    /// (`[time] erode_failed_below`); none by default (SPEC §5). Not in
    /// checkpoints: set from the case, as `bulk_viscosity`.
    #[serde(skip)]
    pub floors: Floors,
    /// Per-point internal-energy increments of the last step (scratch; this
    /// and `kinetic_scratch` are not in checkpoints: each step resizes and
    /// rewrites them before reading them).
    #[serde(skip)]
    work_scratch: Vec<Real>,
    /// Per-particle full-step kinetic energies of the last step (scratch).
    #[serde(skip)]
    kinetic_scratch: Vec<Real>,
}

impl Simulation {
    /// Start a run at t = 0 with the step chosen by `rule`, with contact
    /// against the rigid bodies of `contact`.
    pub fn with_contact(model: Model, rule: TimeStepRule, contact: ContactSystem) -> Self {
        let mut sim = Simulation::new(model, rule);
        let rigid = rigid_kinetic_energy(&contact);
        sim.energies.rigid_kinetic = rigid;
        sim.energies.initial_kinetic += rigid;
        let vmax = contact.bodies.iter().map(|b| b.velocity.norm()).fold(0.0, Real::max);
        sim.speed_bound = sim.speed_bound.max(10.0 * vmax);
        sim.contact = Some(contact);
        sim
    }

    /// Start a run at t = 0 with the step chosen by `rule`.
    pub fn new(model: Model, rule: TimeStepRule) -> Self {
        let dt = match rule {
            TimeStepRule::Cfl { safety } => safety * model.min_spacing() / model.max_wave_speed(),
            TimeStepRule::Fixed(dt) => dt,
        };
        let ke = kinetic_energy(&model.particles.mass, &model.particles.v);
        let vmax = model.particles.v.iter().map(|v| v.norm()).fold(0.0, Real::max);
        let nq = model.quad.len();
        let np = model.particles.len();
        let driven_constraints = (0..np).any(|i| {
            let (f, v) = (model.particles.flags[i], model.particles.v[i]);
            (f.has(ParticleFlags::FIX_X) && v.x != 0.0) || (f.has(ParticleFlags::FIX_Y) && v.y != 0.0)
        });
        let stable = match rule {
            TimeStepRule::Cfl { .. } => Some(StableStep::new(&model, dt)),
            TimeStepRule::Fixed(_) => None,
        };
        Simulation {
            stable,
            dt_previous: dt,
            floors: Floors::default(),
            model,
            time: 0.0,
            step: 0,
            dt,
            energies: Energies { kinetic: ke, initial_kinetic: ke, ..Default::default() },
            timers: StageTimers::default(),
            speed_bound: 10.0 * vmax.max(1000.0),
            fastest: FastestParticle::default(),
            driven_constraints,
            contact: None,
            heat: None,
            bulk_viscosity: BulkViscosity::NONE,
            viscous_damping: 0.0,
            heat_every: 1,
            heat_pending: 0.0,
            f_contact: vec![Vec2::zeros(); np],
            cracks: None,
            work_scratch: vec![0.0; nq],
            kinetic_scratch: vec![0.0; np],
        }
    }

    /// Advance one step `t → t + Δt`. Stages, in order:
    /// 0. contact (SPEC §8): particles the projectile reaches join the slaves
    ///    ([`ContactSystem::admit_exposed`]), then search and one-step forces
    ///    from the contact-free predictor, which needs this step's
    ///    `f_int(U^n)` — so contact runs after the previous step's internal
    ///    force and before integration;
    /// 1. time integration: `a = (f_ext + f_contact − f_int)/m`, `V ← V + Δt a`,
    ///    `U ← U + Δt V`, constraints (SPEC §5); rigid bodies advance under
    ///    the contact reactions;
    /// 2. velocity gradient and deformation gradient at each quadrature point
    ///    (`F` at the new step, `ℓ = Ḟ F_mid⁻¹` at mid-step; SPEC §2);
    /// 3. material update (SPEC §6) and `P w = τ F⁻ᵀ w_q`: the adiabatic
    ///    phase, which heats the quadrature points by the plastic work;
    /// 4. heat: conduction at the configuration of this step, sub-cycled if
    ///    `Δt` exceeds its stable step (SPEC §7; `heat` set); the new
    ///    temperatures act on the stress from the next step on;
    /// 5. internal force by gather over particles (SPEC §4);
    /// 6. crack growth (SPEC §9): nucleation, propagation, arrest at the
    ///    state `t^{n+1}`; a split patches the tables and masses locally,
    ///    adds the new faces to the contact slaves, and the internal force
    ///    is recomputed from the new table;
    /// 7. diagnostics: energies, non-finite values, runaway speeds.
    pub fn step(&mut self) -> Result<(), SolverError> {
        let dt = self.dt;
        let tc = Instant::now();
        self.contact_forces(dt)?;
        let t0 = Instant::now();
        self.integrate(dt);
        self.advance_rigid_bodies()?;
        let t1 = Instant::now();
        self.update_material(dt)?;
        let th = Instant::now();
        self.conduct_heat(dt)?;
        let t2 = Instant::now();
        // The internal energy's increment is summed in point order (the
        // same bits for any number of threads) on one worker while the
        // others gather the internal force: the serial sum costs no wall
        // time of its own.
        let work = &self.work_scratch;
        let (increment, ()) = rayon::join(|| work.iter().sum::<Real>(), || internal_force(&mut self.model));
        self.energies.internal += increment;
        let t3 = Instant::now();
        // The full-step kinetic terms of the state the crack stage starts
        // from; after a change it forms them again (and books the
        // difference, `Energies::crack_changes`).
        self.full_step_kinetic_terms();
        let t3k = Instant::now();
        let cracked = self.grow_cracks(dt)?;
        let t3c = Instant::now();
        self.time += dt;
        self.step += 1;
        // The checks run beside the kinetic energy's serial sum.
        let terms = &self.kinetic_scratch;
        let (health, kinetic) = rayon::join(|| self.diagnose(), || terms.iter().sum::<Real>());
        health?;
        self.energies.kinetic = kinetic;
        self.record_fastest();
        self.check_energy()?;
        self.dt_previous = dt;
        self.adapt_time_step(cracked);
        let t4 = Instant::now();
        self.timers.contact += t0 - tc;
        self.timers.integration += t1 - t0;
        self.timers.material += th - t1;
        self.timers.heat += t2 - th;
        self.timers.internal_force += t3 - t2;
        self.timers.crack_growth += t3c - t3k;
        self.timers.diagnostics += (t4 - t3c) + (t3k - t3);
        Ok(())
    }

    /// Crack growth at `t + Δt`; after a change the new crack-face
    /// particles join the contact slaves, the internal force is
    /// recomputed with the patched table, and the full-step kinetic terms
    /// (formed by the caller before the stage) are formed again, the
    /// change of their sum booked. Whether the cracks changed.
    fn grow_cracks(&mut self, dt: Real) -> Result<bool, SolverError> {
        let Some(cracks) = self.cracks.as_mut() else {
            return Ok(false);
        };
        let (step, time) = (self.step + 1, self.time + dt);
        if cracks.params.critical_value().is_none() {
            return Ok(false);
        }
        let fracture_error = |source| SolverError::Fracture { source: Box::new(source), step, time };
        let faces = cracks.grow(&mut self.model, time, step).map_err(fracture_error)?;
        // Particles that erosion (this step's, or the grown cracks') left
        // without material leave the shape functions.
        let detached = cracks.detach_isolated(&mut self.model, time).map_err(fracture_error)?;
        if faces.is_empty() && detached.is_empty() {
            return Ok(false);
        }
        // The terms still hold the state before the changes.
        let before: Real = self.kinetic_scratch.iter().sum();
        if !faces.is_empty() {
            self.crack_faces_changed(&faces);
        }
        internal_force(&mut self.model);
        self.full_step_kinetic_terms();
        self.energies.crack_changes += before - self.kinetic_scratch.iter().sum::<Real>();
        Ok(true)
    }

    /// Re-evaluate the stable step after a crack change and every
    /// [`StableStep::every`] steps ([`crate::stability`]); a new step takes
    /// effect from the next step on ([`Simulation::integrate`]).
    fn adapt_time_step(&mut self, cracked: bool) {
        let every = self.stable.as_ref().map_or(u64::MAX, |s| s.every);
        if cracked || self.step.is_multiple_of(every) {
            self.refresh_time_step();
        }
    }

    /// Whether fractured points carry pressure only (the cracks' criterion
    /// fractures points): the stable step's bound then takes their bulk
    /// modulus ([`crate::stability::frequency_bounds`]).
    pub fn fractures_points(&self) -> bool {
        self.cracks.as_ref().is_some_and(|c| c.params.fractures_points())
    }

    /// Re-evaluate the stable step now (with the adaptive rule; a fixed
    /// step stays), as the time loop does after every crack change: for a
    /// change of the model made outside the loop.
    pub fn refresh_time_step(&mut self) {
        let fracturing = self.fractures_points();
        let Some(stable) = self.stable.as_mut() else {
            return;
        };
        let (dt, removed) = stable.evaluate(&mut self.model, self.time, fracturing, self.viscous_damping, self.floors);
        self.energies.mass_scaling += removed;
        self.dt = dt;
    }

    /// After cracks changed (grown here, or inserted with
    /// [`CrackGrowth::insert_crack`]): the new face particles `faces` join
    /// the contact slaves and the crack faces become master surfaces
    /// (`contact::deformable`).
    pub fn crack_faces_changed(&mut self, faces: &[usize]) {
        let (Some(contact), Some(cracks)) = (self.contact.as_mut(), self.cracks.as_ref()) else {
            return;
        };
        for &i in faces {
            contact.slaves.add(i);
        }
        let chains = cracks.cracks.iter().map(|c| c.face_chains()).collect();
        contact.deformable.set_crack_faces(chains, &self.model.particle_shape, &self.model.particles.body);
    }

    /// Contact forces of this step into `f_contact` (zero without contact).
    fn contact_forces(&mut self, dt: Real) -> Result<(), SolverError> {
        let Some(contact) = self.contact.as_mut() else {
            return Ok(());
        };
        let p = &self.model.particles;
        contact.admit_exposed(&p.x0, &p.u, &p.spacing);
        self.f_contact.resize(p.len(), Vec2::zeros());
        let dt_v = 0.5 * (self.dt_previous + dt);
        let input = StepInput::from_particles(p, Some(&self.model.particle_shape), dt).with_velocity_step(dt_v);
        contact.compute_forces(&input, &mut self.f_contact).map_err(|source| SolverError::Contact {
            source,
            step: self.step + 1,
            time: self.time + dt,
        })?;
        Ok(())
    }

    /// Move the rigid bodies under the reactions and book the contact work.
    fn advance_rigid_bodies(&mut self) -> Result<(), SolverError> {
        let Some(contact) = self.contact.as_mut() else {
            return Ok(());
        };
        contact.advance(&self.model.particles.v).map_err(|source| SolverError::Contact {
            source,
            step: self.step + 1,
            time: self.time + self.dt,
        })?;
        let (mut wp, mut wb) = (0.0, 0.0);
        for b in 0..contact.bodies.len() {
            let s = contact.sample(b).expect("body exists");
            wp += s.work_on_particles;
            wb += s.work_on_body;
        }
        self.energies.contact_work = wp + contact.deformable_work() + contact.axis_work();
        self.energies.rigid_work = wb;
        self.energies.rigid_kinetic = rigid_kinetic_energy(contact);
        Ok(())
    }

    /// Central-difference update of velocities and displacements,
    /// `V^{n+½} = V^{n−½} + ½ (Δt_{n−½} + Δt_{n+½}) a^n`,
    /// `U^{n+1} = U^n + Δt_{n+½} V^{n+½}` (second order across a change of
    /// step too; with a constant step, `V += Δt a`, `U += Δt V`). The
    /// contact stage removes its penetration with `Δt_{n+½}` for both: on
    /// the step after a change, its force moves the slave by the ratio of
    /// the two, a few per cent at most, and the next step removes the rest.
    fn integrate(&mut self, dt: Real) {
        let dt_v = 0.5 * (self.dt_previous + dt);
        let p = &mut self.model.particles;
        if self.f_contact.len() != p.len() {
            self.f_contact.resize(p.len(), Vec2::zeros());
        }
        (
            p.v.par_iter_mut(),
            p.u.par_iter_mut(),
            p.a.par_iter_mut(),
            &p.f_int,
            &p.f_ext,
            &self.f_contact,
            &p.mass,
            &p.flags,
        )
            .into_par_iter()
            .for_each(|(v, u, a, fi, fe, fc, m, flags)| {
                let mut acc = (fe + fc - fi) / *m;
                constrain(*flags, &mut acc);
                *a = acc;
                *v += acc * dt_v;
                *u += *v * dt;
            });
    }

    /// Kinetic energy at the full step `t_{n+1}`, from the full-step velocity
    /// `V^{n+1} = V^{n+½} + ½ Δt a^{n+1}` (velocity-Verlet form of the central
    /// difference), so that it is reported at the same instant as the
    /// internal energy, whose state is `τ^{n+1}`. The particles' terms are
    /// formed here in parallel into `kinetic_scratch`; `step` sums them in
    /// index order (the same bits for any number of threads).
    fn full_step_kinetic_terms(&mut self) {
        let p = &self.model.particles;
        let half = 0.5 * self.dt;
        // Particles added by a crack split this step carry no contact force;
        // the column keeps one entry per particle (a checkpoint written
        // after the step checks it).
        self.f_contact.resize(p.len(), Vec2::zeros());
        self.kinetic_scratch.resize(p.len(), 0.0);
        (self.kinetic_scratch.par_iter_mut(), &p.f_ext, &self.f_contact, &p.f_int, &p.mass, &p.flags, &p.v)
            .into_par_iter()
            .with_max_len(PARALLEL_PIECE)
            .for_each(|(e, fe, fc, fi, m, flags, v)| {
                let mut acc = (fe + fc - fi) / *m;
                constrain(*flags, &mut acc);
                *e = 0.5 * m * (v + acc * half).norm_squared();
            });
    }

    /// Deformation and velocity gradients, material update, `P w`.
    #[allow(non_snake_case)]
    fn update_material(&mut self, dt: Real) -> Result<(), SolverError> {
        // While cracks grow, points fractured by their damage carry only
        // compression (`material::fractured`).
        let cracking = self.cracks.as_ref().is_some_and(|c| c.params.critical_value().is_some());
        // Erosion of inverted failed points (`crate::fracture` module doc).
        let erosion = self.cracks.as_ref().map(|c| c.params).filter(|p| cracking && p.erode_inverted);
        // Not with the non-local criterion (`FractureParameters::fractures_points`).
        let fracturing = self.fractures_points();
        // One increment per point (a simulation read from a checkpoint
        // starts with none).
        self.work_scratch.resize(self.model.quad.len(), 0.0);
        let m = &mut self.model;
        let (tab, u, v, mode, mats) = (&m.qp_shape, &m.particles.u, &m.particles.v, m.mode, &m.materials);
        let q = &mut m.quad;
        let (carried, x0s, weights, bodies) = (&q.f_carry, &q.x0, &q.weight, &q.body);
        let (viscosity, lengths) = (self.bulk_viscosity, &q.length);
        // One point's update, entry `k` of piece `c`; `Some((point, J))` if it
        // inverts and is not eroded.
        let point = |c: &mut PieceColumns, k: usize| {
            let qi = c.first + k;
            if c.eroded[k] {
                c.work[k] = 0.0;
                return None;
            }
            let (x0, w, body) = (&x0s[qi], weights[qi], bodies[qi]);
            // Legend: gu = grad U, gv = grad V (2x2), uq/vq = interpolated U, V
            // (only read in axisymmetry). The 3x3 algebra works on the five
            // entries of the block form of 2D kinematics (`Block2`; same
            // bits as the general products).
            let (gu, gv, uq, vq) = if mode.needs_point_values() {
                tab.gradient_pair_and_values(qi, u, v)
            } else {
                let (gu, gv) = tab.gradient_pair(qi, u, v);
                (gu, gv, Vec2::zeros(), Vec2::zeros())
            };
            let F_dot = mode.deformation_gradient_2d(&gv, &vq, x0, 0.0);
            let mut F_new = mode.deformation_gradient_2d(&gu, &uq, x0, 1.0);
            let carry = c.carry[k];
            if carry != NO_CARRY {
                // The jump carried over crack changes (`crate::fracture`).
                F_new = F_new.add(&Block2::block_part(&carried[carry as usize]));
            }
            let J = F_new.determinant();
            let kin = match PointKinematics::new(&c.f[k], &F_new, &F_dot) {
                Some(kin) if J > 0.0 && J.is_finite() => kin,
                _ if erosion.is_some_and(|p| p.point_failed(c.eps_p[k], c.damage[k])) => {
                    // Inverted after failing: eroded, the run goes on.
                    c.erode(k);
                    return None;
                }
                _ => return Some((qi, J)),
            };
            if fracturing && crate::material::is_fractured(c.damage[k]) && J >= crate::material::TORN_VOLUME_RATIO {
                // Torn open (`crate::material::TORN_VOLUME_RATIO`): eroded.
                c.erode(k);
                return None;
            }
            let old = crate::material::PointState {
                tau: c.tau[k].to_tensor(),
                eps_p: c.eps_p[k],
                eps_p_rate: c.eps_p_rate[k],
                temperature: c.temperature[k],
                damage: c.damage[k],
            };
            let new = mats[body as usize].update(&old, &StepKinematics { d: kin.d, w: kin.w, dt });
            c.triaxiality_strain[k] += crate::material::strain_path_increment(&new.tau, new.eps_p - old.eps_p);
            let new = if fracturing { crate::material::fractured(new, J) } else { new };
            // Block-form kinematics keep a block-form stress (the models'
            // updates are sums and block products of `τ`, `d` and `w`).
            debug_assert!(is_block_2d(&new.tau), "material update left the block form at point {qi}");
            let new_tau = Block2::block_part(&new.tau);
            let d = kin.l.sym();
            c.work[k] = 0.5 * c.tau[k].add(&new_tau).ddot(&d) * dt * w;
            // The force's stress: the material's, less the viscous pressure
            // (Kirchhoff, `J q`; `crate::bulk_viscosity`), whose work joins
            // the internal energy.
            let mut force_tau = new_tau;
            if viscosity.is_active() {
                let mat = &mats[body as usize];
                let length = current_length(lengths[qi], F_new.xx * F_new.yy - F_new.xy * F_new.yx);
                let (rate, wave_speed) = (d.trace(), mat.longitudinal_wave_speed());
                c.damping = c.damping.max(viscosity.damping_ratio(wave_speed, length, rate));
                let q = viscosity.pressure(mat.density() / J, wave_speed, length, rate);
                // A fractured point carries no tension (`material::fractured`), viscous or not.
                let q = if fracturing && crate::material::is_fractured(new.damage) { q.max(0.0) } else { q };
                force_tau = new_tau.sub(&Block2::identity_scaled(J * q));
                c.work[k] -= J * q * rate * dt * w;
            }
            c.f[k] = F_new;
            c.tau[k] = new_tau;
            (c.eps_p[k], c.eps_p_rate[k], c.temperature[k], c.damage[k]) =
                (new.eps_p, new.eps_p_rate, new.temperature, new.damage);
            c.set_pw(k, &force_tau.mul_transpose(&kin.f_inv).scale(w));
            None
        };
        // Pieces of points, each swept by a plain loop: cheaper than
        // handing rayon every point (dropping its per-point search
        // bookkeeping took 8-10 % off the sweep on one thread). A piece
        // stops at its first inverted point, and the run stops there.
        let piece = PARALLEL_PIECE;
        let (bad, damping) = (
            q.f.par_chunks_mut(piece),
            q.tau.par_chunks_mut(piece),
            q.eps_p.par_chunks_mut(piece),
            q.eps_p_rate.par_chunks_mut(piece),
            q.temperature.par_chunks_mut(piece),
            q.damage.par_chunks_mut(piece),
            q.triaxiality_strain.par_chunks_mut(piece),
            q.pw.par_chunks_mut(piece),
            q.pw_zz.par_chunks_mut(piece),
            self.work_scratch.par_chunks_mut(piece),
            q.eroded.par_chunks_mut(piece),
            q.f_carry_slot.par_chunks(piece),
        )
            .into_par_iter()
            .enumerate()
            .map(|(i, (f, tau, eps_p, eps_p_rate, temperature, damage, path, pw, pw_zz, work, eroded, carry))| {
                let mut c = PieceColumns {
                    first: i * piece,
                    f,
                    tau,
                    eps_p,
                    eps_p_rate,
                    temperature,
                    damage,
                    triaxiality_strain: path,
                    pw,
                    pw_zz,
                    work,
                    eroded,
                    carry,
                    damping: 0.0,
                };
                let bad = (0..c.f.len()).find_map(|k| point(&mut c, k));
                (bad, c.damping)
            })
            // The first inverted point in index order, the largest ratio.
            .reduce(|| (None, 0.0), |a, b| (a.0.or(b.0), a.1.max(b.1)));
        self.viscous_damping = damping;
        if let Some((point, jacobian)) = bad {
            let x = self.model.quad.x0[point];
            return Err(SolverError::Inverted {
                point,
                x: x.x,
                y: x.y,
                jacobian,
                step: self.step + 1,
                time: self.time + dt,
            });
        }
        Ok(())
    }

    /// The conduction phase (SPEC §7), if the case has one.
    /// Heat conduction over the time accumulated since the last conduction,
    /// once every `heat_every` steps (SPEC §7: a larger conduction step is
    /// allowed when stable; `conduct` sub-cycles below its stable step).
    fn conduct_heat(&mut self, dt: Real) -> Result<(), SolverError> {
        let Some(heat) = self.heat.as_mut() else {
            return Ok(());
        };
        self.heat_pending += dt;
        if !(self.step + 1).is_multiple_of(self.heat_every.max(1)) {
            return Ok(());
        }
        let span = std::mem::take(&mut self.heat_pending);
        heat.conduct(&mut self.model, span).map_err(|source| SolverError::Heat {
            source,
            step: self.step + 1,
            time: self.time + dt,
        })?;
        Ok(())
    }

    /// Catch NaN/Inf and runaway speeds right after the stages that make them.
    ///
    /// One fused pass over the particles finds whether anything is wrong (a
    /// NaN stress reaches the internal force of every particle it touches);
    /// only then do the detailed passes name the culprit.
    fn diagnose(&self) -> Result<(), SolverError> {
        let p = &self.model.particles;
        let (step, time) = (self.step, self.time);
        let bound2 = self.speed_bound * self.speed_bound;
        // Pieces folded without a branch per item (a short-circuiting test
        // per item cost more than the test itself).
        let piece = PARALLEL_PIECE;
        let healthy = (p.v.par_chunks(piece), p.f_int.par_chunks(piece)).into_par_iter().all(|(v, f)| {
            v.iter()
                .zip(f)
                .fold(true, |ok, (v, f)| ok & (v.norm_squared() <= bound2) & f.x.is_finite() & f.y.is_finite())
        });
        let q = &self.model.quad;
        let scalars = [("plastic strain", &q.eps_p), ("temperature", &q.temperature), ("damage", &q.damage)];
        let scalars_ok = (q.eps_p.par_chunks(piece), q.temperature.par_chunks(piece), q.damage.par_chunks(piece))
            .into_par_iter()
            .all(|(a, b, c)| {
                a.iter()
                    .zip(b)
                    .zip(c)
                    .fold(true, |ok, ((a, b), c)| ok & a.is_finite() & (*b > 0.0) & b.is_finite() & c.is_finite())
            });
        if healthy && scalars_ok {
            return Ok(());
        }
        if let Some(q) = self.model.quad.tau.par_iter().position_first(|t| !t.is_finite()) {
            return Err(SolverError::NonFinite { field: "stress", location: "quadrature point", index: q, step, time });
        }
        if let Some(k) = (0..q.len()).into_par_iter().position_first(|k| scalars.iter().any(|(_, c)| !c[k].is_finite()))
        {
            let field = scalars.iter().find(|(_, c)| !c[k].is_finite()).map_or("state", |(f, _)| f);
            return Err(SolverError::NonFinite { field, location: "quadrature point", index: k, step, time });
        }
        if let Some(i) = p.v.par_iter().position_first(|v| !v.x.is_finite() || !v.y.is_finite()) {
            return Err(SolverError::NonFinite { field: "velocity", location: "particle", index: i, step, time });
        }
        if let Some(i) = p.f_int.par_iter().position_first(|f| !f.x.is_finite() || !f.y.is_finite()) {
            return Err(SolverError::NonFinite { field: "internal force", location: "particle", index: i, step, time });
        }
        if let Some(point) = q.temperature.par_iter().position_first(|t| *t <= 0.0) {
            let temperature = q.temperature[point];
            return Err(SolverError::BelowAbsoluteZero { point, temperature, step, time });
        }
        if let Some(i) = p.v.par_iter().position_first(|v| v.norm_squared() > bound2) {
            return Err(SolverError::Runaway {
                particle: i,
                speed: p.v[i].norm(),
                bound: self.speed_bound,
                step,
                time,
            });
        }
        Ok(())
    }
}

/// `f_int,I = Σ_q (P w)_q ∇N_I(X_q)` (+ hoop term) into the particles'
/// `f_int`, gathered per particle ([`gather_internal_force`]).
fn internal_force(m: &mut Model) {
    let mut f_int = std::mem::take(&mut m.particles.f_int);
    gather_internal_force(m, &mut f_int);
    m.particles.f_int = f_int;
}

/// `f_int,I = Σ_q (P w)_q ∇N_I(X_q)` (+ the hoop term in axisymmetry; SPEC
/// §4) into `f` (one entry per particle): each particle sums its own
/// entries of the gather in their fixed order, so the result is the same
/// for any number of threads.
pub fn gather_internal_force(m: &Model, f: &mut [Vec2]) {
    match m.mode {
        GeometryMode::PlaneStrain => gather_in_mode::<false>(m, f),
        GeometryMode::Axisymmetric => gather_in_mode::<true>(m, f),
    }
}

/// [`gather_internal_force`] in one geometry mode (`AXI`: axisymmetric),
/// so that plane strain's loop reads neither `(P w)_zz`, the values nor
/// the points' radii.
fn gather_in_mode<const AXI: bool>(m: &Model, f: &mut [Vec2]) {
    let mode = if AXI { GeometryMode::Axisymmetric } else { GeometryMode::PlaneStrain };
    let (gather, pw, pw_zz, xq) = (&m.gather, &m.quad.pw, &m.quad.pw_zz, &m.quad.x0);
    f.par_iter_mut().with_max_len(PARALLEL_PIECE).enumerate().for_each(|(i, f)| {
        let r = gather.range(i);
        let entries = gather.point[r.clone()].iter().zip(&gather.grad[r.clone()]).zip(&gather.value[r]);
        let mut acc = Vec2::zeros();
        for ((&q, grad), &n) in entries {
            let q = q as usize;
            let (zz, n, x) = if AXI { (pw_zz[q], n, xq[q]) } else { (0.0, 0.0, Vec2::zeros()) };
            acc += mode.internal_force(&pw[q], zz, n, grad, &x);
        }
        *f = acc;
    });
}

/// One piece of the quadrature points' columns, as the material sweep
/// updates them: entry `k` is point `first + k`.
struct PieceColumns<'a> {
    first: usize,
    f: &'a mut [Block2],
    tau: &'a mut [Block2],
    eps_p: &'a mut [Real],
    eps_p_rate: &'a mut [Real],
    temperature: &'a mut [Real],
    damage: &'a mut [Real],
    triaxiality_strain: &'a mut [Real],
    pw: &'a mut [InPlane],
    pw_zz: &'a mut [Real],
    work: &'a mut [Real],
    eroded: &'a mut [bool],
    carry: &'a [u32],
    /// The largest damping ratio of the bulk viscosity in the piece.
    damping: Real,
}

impl PieceColumns<'_> {
    /// Store `P w` of entry `k` in its two columns.
    #[inline]
    fn set_pw(&mut self, k: usize, pw: &Block2) {
        (self.pw[k], self.pw_zz[k]) = (pw.in_plane(), pw.zz);
    }

    /// Erode entry `k` in the sweep: no stress, no work from now on (the
    /// sweep's view of [`crate::quadrature::QuadraturePoints::erode`]).
    fn erode(&mut self, k: usize) {
        self.eroded[k] = true;
        self.tau[k] = Block2::zeros();
        self.set_pw(k, &Block2::zeros());
        self.work[k] = 0.0;
    }
}

/// The kinematics of one quadrature point over a step: `d` and `w` of the
/// mid-step velocity gradient `ℓ = Ḟ F_mid⁻¹`, `F_mid = (F_old + F_new)/2`,
/// and `F_new⁻¹` (SPEC §2), on the five entries of the block form of 2D
/// kinematics ([`Block2`]: the same bits as nalgebra's 3×3 products).
#[allow(non_snake_case)]
struct PointKinematics {
    /// `d`, `w` as the material models take them.
    d: Tensor3,
    w: Tensor3,
    l: Block2,
    f_inv: Block2,
}

impl PointKinematics {
    /// `None` if `F_mid` or `F_new` is singular.
    #[allow(non_snake_case)]
    #[inline]
    fn new(F_old: &Block2, F_new: &Block2, F_dot: &Block2) -> Option<PointKinematics> {
        let F_mid_inv = F_old.add(F_new).scale(0.5).try_inverse()?;
        let f_inv = F_new.try_inverse()?;
        let l = F_dot.mul(&F_mid_inv);
        Some(PointKinematics { d: l.sym().to_tensor(), w: l.skew().to_tensor(), l, f_inv })
    }
}

impl Simulation {
    /// Energy put into the run so far, J: the initial kinetic energy, plus
    /// the work of whatever drives the rigid bodies whose velocity is
    /// prescribed (it holds their velocity against the contact reaction, so
    /// it does minus the reaction's work on them).
    pub fn input_energy(&self) -> Real {
        let driven: Real = self.contact.as_ref().map_or(0.0, |c| {
            (0..c.bodies.len())
                .filter(|&b| c.bodies[b].prescribed_velocity.is_some())
                .filter_map(|b| c.sample(b))
                .map(|s| -s.work_on_body)
                .sum()
        });
        self.energies.initial_kinetic + driven
    }

    /// Keep [`Self::fastest`] up to date after a step.
    fn record_fastest(&mut self) {
        let (speed, i) = fastest_particle(&self.model);
        if speed > self.fastest.speed {
            let m = &self.model;
            let p = &m.particles;
            let position = p.x0[i] + m.particle_shape.interpolate(i, &p.u);
            self.fastest = FastestParticle {
                speed,
                particle: i,
                time: self.time,
                position,
                reference: p.x0[i],
                mass: p.mass[i],
                crack_face: p.flags[i].has(crate::particles::ParticleFlags::CRACK_FACE),
                live_share: Some(crate::fracture::growth::live_share(m, i)),
            };
        }
    }

    /// Stop on an energy balance above [`ENERGY_BLOWUP_FACTOR`] times the
    /// input energy (or not finite), naming the fastest particle.
    ///
    /// Skipped when particles are driven through their constraints (a held
    /// component with a non-zero velocity, set up in code): the work those
    /// kinematic drivers do is not tallied, so the balance cannot be judged.
    fn check_energy(&self) -> Result<(), SolverError> {
        if self.driven_constraints {
            return Ok(());
        }
        let (total, input) = (self.energies.total(), self.input_energy());
        if input > 0.0 && (total.is_nan() || total > ENERGY_BLOWUP_FACTOR * input) {
            let v = &self.model.particles.v;
            let (speed, particle) = largest_by(v.len(), |i| v[i].norm_squared());
            return Err(SolverError::EnergyBlowUp { total, input, particle, speed, step: self.step, time: self.time });
        }
        Ok(())
    }
}

/// `½ Σ M |V|²` of the rigid bodies.
fn rigid_kinetic_energy(contact: &ContactSystem) -> Real {
    contact.bodies.iter().map(|b| 0.5 * b.mass * b.velocity.norm_squared()).sum()
}

/// `½ Σ m |v|²`, summed in index order.
pub fn kinetic_energy(mass: &[Real], v: &[Vec2]) -> Real {
    mass.iter().zip(v).map(|(m, v)| 0.5 * m * v.norm_squared()).sum()
}
