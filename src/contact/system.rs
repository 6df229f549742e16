//! The contact stage of a time step: rigid bodies, slave set, parameters and
//! the bookkeeping the time histories need (SPEC §8, SPEC §5).
//!
//! Per step, with `U^n`, `V^{n−½}`, the internal force `f_int(U^n)` and the
//! external loads `f_ext(t^n)` assembled:
//! 1. [`ContactSystem::compute_forces`] predicts the contact-free end of the
//!    step, searches, and writes the contact force of every particle into
//!    `f_contact` (SPEC §5's `f_contact`);
//! 2. the integrator updates the particles,
//!    `V ← V + Δt (f_ext + f_contact − f_int)/m`, `U ← U + Δt V`,
//!    applying its constraints (clamps, axis);
//! 3. [`ContactSystem::advance`] takes the new `V^{n+½}`, moves the rigid
//!    bodies under the reactions, and accumulates the contact work.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::deformable::{DeformableMasters, SegmentContact};
use super::force::{
    coulomb_cap, gap_floor, inverse_distance_weights, mass_weights, one_step_normal_force, stick_force, Spreading,
};
use super::rigid::RigidBody;
use super::search::{check_pairing, search_rigid_polygon, Projection};
use super::slave::{Pairing, SlaveSet};
use super::ContactError;
use crate::math::{Real, Vec2};
use crate::particles::{ParticleFlags, Particles};
use crate::shape::ShapeTable;

/// Tolerance on a shape-function row's partition of unity `Σ_J N_J = 1`
/// before [`Spreading::ShapeFunction`] refuses the row.
const PARTITION_TOLERANCE: Real = 1e-8;

/// Contact parameters (SPEC §8).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactParameters {
    /// Coulomb friction coefficient `μ ≥ 0`, dimensionless. Default 0
    /// (SPEC §8).
    pub friction_coefficient: Real,
    /// How slave forces reach the particles. Default
    /// [`Spreading::ShapeFunction`] (see the `contact` module doc).
    pub spreading: Spreading,
    /// Inverse-distance spreading: the distance below which weights stop
    /// growing, as a fraction of the slave's spacing (dimensionless, > 0).
    /// Default ½: the slave itself weighs twice a neighbour one spacing away.
    pub inverse_distance_floor: Real,
    /// Most Gauss–Seidel sweeps over the penetrating pairs per step
    /// ([`ContactSystem::compute_forces`]). Default 50; the cases measured
    /// need well under 20 (`compare_spreading_on_elastic_impact`); one sweep
    /// is exact where no two slaves share a particle.
    pub max_iterations: u32,
    /// Sweeps stop when no force changed by more than this fraction of the
    /// largest normal force, dimensionless. Default 1e-8: the remaining
    /// penetration is then ~1e-8 of a step's, far below round-off of the
    /// coordinates in any case of interest.
    pub tolerance: Real,
    /// Slaves by exposure ([`ContactSystem::admit_exposed`]): a particle
    /// that comes within one spacing of a rigid body (or inside it) joins
    /// the slave set even if it started in the interior. Default on.
    pub admit_exposed: bool,
    /// Contact between different deformable bodies
    /// ([`super::deformable`]). Default on: bodies do not pass through
    /// each other.
    pub deformable: bool,
    /// Contact of a cracked body with itself: the faces of its cracks, and
    /// a plug cut out against the rest ([`super::deformable`]). Default
    /// off, so that every single-body case keeps its bits. When it was
    /// built it made three of the first four coarse Børvik rows measured
    /// go unstable (plane-strain Case I at 52.7 µs, with the damage
    /// criterion at 16.9 µs, axisymmetric Case I with damage at 33.2 µs);
    /// measured again after the fixes since (a penetration held rather
    /// than pushed out, bounded rebuilt rows, the heat transfer at light
    /// split children), those rows and the default model's two coarse rows
    /// run to their ends with it (`docs/validation.md`, "A plug wider than
    /// its hole"). Without it a plug whose head has spread wider than the
    /// hole its crack cut below passes through the ring, and the ring's
    /// lip squeezed between the two is thrown (1.29 km/s at 96 rows with
    /// the velocity-jump tip); with it the residuals and the limits move
    /// (same section), so it is an option, not yet the default model's.
    pub self_contact: bool,
    /// In axisymmetry, the axis `r = 0` is a frictionless wall for every
    /// particle off it ([`ContactSystem::with_axis`]): no material crosses
    /// to negative radii. Default on; off gives the runs before it (the
    /// same bits wherever no particle reached the axis).
    pub axis: bool,
}

/// Reach of [`ContactSystem::admit_exposed`], in the particle's spacing `h`.
pub const EXPOSED_REACH: Real = 1.0;

impl Default for ContactParameters {
    fn default() -> Self {
        Self {
            friction_coefficient: 0.0,
            spreading: Spreading::default(),
            inverse_distance_floor: 0.5,
            max_iterations: 50,
            tolerance: 1e-8,
            admit_exposed: true,
            deformable: true,
            self_contact: false,
            axis: true,
        }
    }
}

impl ContactParameters {
    fn validate(&self) -> Result<(), ContactError> {
        let mu = self.friction_coefficient;
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(ContactError::InvalidParameter { name: "friction_coefficient", value: mu });
        }
        let r = self.inverse_distance_floor;
        if !(r.is_finite() && r > 0.0) {
            return Err(ContactError::InvalidParameter { name: "inverse_distance_floor", value: r });
        }
        if self.max_iterations == 0 {
            return Err(ContactError::InvalidParameter { name: "max_iterations", value: 0.0 });
        }
        let t = self.tolerance;
        if !(t.is_finite() && t > 0.0) {
            return Err(ContactError::InvalidParameter { name: "tolerance", value: t });
        }
        Ok(())
    }
}

/// What [`ContactSystem::compute_forces`] reads: the particle state at the
/// start of the step. Every slice is indexed by particle.
#[derive(Clone, Copy, Debug)]
pub struct StepInput<'a> {
    /// Reference positions `X`, m.
    pub x0: &'a [Vec2],
    /// Generalized displacements `U^n`, m.
    pub u: &'a [Vec2],
    /// Generalized velocities `V^{n−½}`, m/s.
    pub v: &'a [Vec2],
    /// Lumped masses, kg.
    pub mass: &'a [Real],
    /// External loads at `t^n` (without contact), N.
    pub force_external: &'a [Vec2],
    /// Internal forces at `U^n`, N.
    pub force_internal: &'a [Vec2],
    /// Local spacings `h`, m (inverse-distance floor).
    pub spacing: &'a [Real],
    /// RK support sizes `a`, m (inverse-distance neighbourhood).
    pub support: &'a [Real],
    /// Flags: `FIX_X` / `FIX_Y` components are held (supports, the axis).
    pub flags: &'a [ParticleFlags],
    /// Body of each particle (deformable masters).
    pub body: &'a [u32],
    /// Shape functions at the particles, `N_J(X_I)` in row `I`; needed by
    /// every spreading but [`Spreading::None`].
    pub shape: Option<&'a ShapeTable>,
    /// Time step `Δt = Δt_{n+½}`, s: the displacement step.
    pub dt: Real,
    /// The velocity step `½ (Δt_{n−½} + Δt_{n+½})`, s: `Δt` unless the
    /// step just changed (`Simulation::integrate`).
    pub dt_velocity: Real,
}

impl<'a> StepInput<'a> {
    /// Read everything from the particle store; `f_ext` must hold the loads
    /// without contact, `f_int` the internal force of this step.
    pub fn from_particles(p: &'a Particles, shape: Option<&'a ShapeTable>, dt: Real) -> Self {
        Self {
            x0: &p.x0,
            u: &p.u,
            v: &p.v,
            mass: &p.mass,
            force_external: &p.f_ext,
            force_internal: &p.f_int,
            spacing: &p.spacing,
            support: &p.support,
            flags: &p.flags,
            body: &p.body,
            shape,
            dt,
            dt_velocity: dt,
        }
    }

    /// The same input with the velocity step `dt_velocity`.
    pub fn with_velocity_step(self, dt_velocity: Real) -> Self {
        Self { dt_velocity, ..self }
    }

    fn validate(&self, spreading: Spreading) -> Result<(), ContactError> {
        let n = self.x0.len();
        let lens = [
            ("u", self.u.len()),
            ("v", self.v.len()),
            ("mass", self.mass.len()),
            ("force_external", self.force_external.len()),
            ("force_internal", self.force_internal.len()),
            ("spacing", self.spacing.len()),
            ("support", self.support.len()),
            ("flags", self.flags.len()),
            ("body", self.body.len()),
        ];
        for (field, found) in lens {
            if found != n {
                return Err(ContactError::LengthMismatch { field, expected: n, found });
            }
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(ContactError::InvalidParameter { name: "dt", value: self.dt });
        }
        if !(self.dt_velocity.is_finite() && self.dt_velocity > 0.0) {
            return Err(ContactError::InvalidParameter { name: "dt_velocity", value: self.dt_velocity });
        }
        if spreading != Spreading::None {
            let table = self.shape.ok_or(ContactError::MissingShapeTable { spreading })?;
            if table.rows() != n {
                return Err(ContactError::LengthMismatch { field: "shape rows", expected: n, found: table.rows() });
            }
            let entries = table.index.len();
            let consistent = table.value.len() == entries
                && table.offsets.first() == Some(&0)
                && table.offsets.windows(2).all(|w| w[0] <= w[1])
                && table.offsets.last().is_some_and(|&e| e <= entries);
            if !consistent {
                return Err(ContactError::InvalidShapeTable);
            }
        }
        Ok(())
    }

    /// Contact-free prediction for particle `j`: (`Ũ^{n+1}`, `Ṽ`), with the
    /// integrator's constraints applied (module doc of `force`).
    #[inline]
    fn predicted(&self, j: usize) -> Result<(Vec2, Vec2), ContactError> {
        let m = self.mass[j];
        if !(m.is_finite() && m > 0.0) {
            return Err(ContactError::InvalidParticle { particle: j, field: "mass", value: m });
        }
        let flags = self.flags[j];
        let mut v = self.v[j] + (self.force_external[j] - self.force_internal[j]) * (self.dt_velocity / m);
        flags.constrain(&mut v);
        Ok((self.u[j] + v * self.dt, v))
    }
}

/// One active contact of the last step (for diagnostics and tests).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActiveContact {
    /// Slave particle.
    pub particle: u32,
    /// Rigid body and feature it is paired with.
    pub pairing: Pairing,
    /// Predicted gap `g̃` (negative), m.
    pub gap: Real,
    /// Outward master normal `n_m`.
    pub normal: Vec2,
    /// Effective mass of the gap point for its own normal force, kg
    /// (`m_s`, `m_s / w_ss`, `(Σ N_J²/m_J)⁻¹` or `(Σ w_J²/m_J)⁻¹` by
    /// spreading mode).
    pub effective_mass: Real,
    /// Normal force magnitude `f_n`, N.
    pub normal_force: Real,
    /// Tangential force along `t = (−n_y, n_x)`, N.
    pub tangential_force: Real,
    /// Whether friction is at the Coulomb cap.
    pub slipping: bool,
    /// Total force this contact applies to the target (`Σ_J f_J`), N.
    pub force: Vec2,
}

/// Time-history sample of one rigid body (SPEC §8, §5 energy balance).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodySample {
    /// Position of the body frame, m.
    pub position: Vec2,
    /// Velocity, m/s.
    pub velocity: Vec2,
    /// Contact force on the body in the last step (the reaction `−Σ f`), N.
    pub contact_force: Vec2,
    /// Cumulative work of this body's contact forces on the particles,
    /// `Σ f_J·ΔU_J`, J (see [`ContactSystem::advance`] for `ΔU`).
    pub work_on_particles: Real,
    /// Cumulative work of the reaction on the body, `Σ F·Δx`, J. The sum of
    /// the two is the net contact work; its negative is the energy the
    /// contact dissipated.
    pub work_on_body: Real,
    /// Number of slaves in contact with this body in the last step.
    pub active_contacts: usize,
}

/// Summary returned by [`ContactSystem::compute_forces`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Number of active contacts (slave–body pairs with force).
    pub active_contacts: usize,
    /// Total contact force applied to the particles, `Σ_J f_contact_J`, N.
    pub force_on_particles: Vec2,
    /// Gauss–Seidel sweeps used (0 without penetrating pairs).
    pub iterations: u32,
}

/// Contact of the deformable particles with rigid bodies (SPEC §8).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ContactSystem {
    /// The rigid bodies (masters).
    pub bodies: Vec<RigidBody>,
    /// The slave particles.
    pub slaves: SlaveSet,
    params: ContactParameters,
    /// Active contacts of the last `compute_forces`.
    contacts: Vec<ActiveContact>,
    /// Forces applied in the last `compute_forces`: (particle, body, f_J,
    /// the particle's `V^{n−½}`).
    applied: Vec<(u32, u32, Vec2, Vec2)>,
    /// Reaction on each body in the last `compute_forces`, N.
    reaction: Vec<Vec2>,
    /// Active contacts per body in the last `compute_forces`.
    active_per_body: Vec<usize>,
    /// Predicted body positions at the end of the step.
    predicted_position: Vec<Vec2>,
    /// Cumulative contact work per body on the particles and on the body, J.
    work_on_particles: Vec<Real>,
    work_on_body: Vec<Real>,
    /// `Δt`, `Δt_v` and particle count of a `compute_forces` not yet followed by
    /// `advance`.
    pending: Option<(Real, Real, usize)>,
    /// Deformable master surfaces: other bodies' boundaries and crack faces
    /// ([`super::deformable`]).
    pub deformable: DeformableMasters,
    /// Deformable contacts of the last `compute_forces`.
    segment_contacts: Vec<SegmentContact>,
    /// Forces of the deformable contacts applied in the last
    /// `compute_forces`: (particle, f_J, the particle's `V^{n−½}`).
    applied_deformable: Vec<(u32, Vec2, Vec2)>,
    /// Cumulative work of the deformable contacts' forces on the particles,
    /// `Σ f_J·ΔU_J`, J (both sides of every pair; its negative is the
    /// energy those contacts dissipated).
    deformable_work: Real,
    /// Whether the axis `r = 0` is a wall ([`Self::with_axis`]).
    axis: bool,
    /// Forces of the axis pairs applied in the last `compute_forces`:
    /// (particle, f_J, the particle's `V^{n−½}`).
    applied_axis: Vec<(u32, Vec2, Vec2)>,
    /// Particles held at the axis in the last `compute_forces`.
    axis_contacts: usize,
    /// Cumulative work of the axis forces on the particles, J (≤ 0: the
    /// radial kinetic energy a ring loses when it meets itself).
    axis_work: Real,
    /// Scratch: (particle, weight) rows of the gap points and, for
    /// inverse-distance spreading, of the forces; the pairs being solved.
    /// Not in checkpoints (this and `gap_points`): cleared, or resized and
    /// rewritten, at the start of every `compute_forces` before it is read.
    #[serde(skip)]
    gap_w: Vec<(u32, Real)>,
    #[serde(skip)]
    force_w: Vec<(u32, Real)>,
    #[serde(skip)]
    candidates: Vec<Candidate>,
    /// Scratch: each slave's contact-free gap point of the current step.
    #[serde(skip)]
    gap_points: Vec<GapPoint>,
}

/// A slave's gap point over the step: the shape-weighted sums of its row.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct GapPoint {
    /// Contact-free predicted position `X + Ũ^{n+1}`, m.
    pub predicted: Vec2,
    /// Position at the start of the step `X + U^n`, m.
    pub now: Vec2,
    /// Contact-free predicted velocity `Ṽ`, m/s.
    pub velocity: Vec2,
}

impl ContactSystem {
    /// A contact system; parameters are validated.
    pub fn new(bodies: Vec<RigidBody>, slaves: SlaveSet, params: ContactParameters) -> Result<Self, ContactError> {
        params.validate()?;
        let nb = bodies.len();
        Ok(Self {
            bodies,
            slaves,
            params,
            contacts: Vec::new(),
            applied: Vec::new(),
            reaction: vec![Vec2::zeros(); nb],
            active_per_body: vec![0; nb],
            predicted_position: vec![Vec2::zeros(); nb],
            work_on_particles: vec![0.0; nb],
            work_on_body: vec![0.0; nb],
            pending: None,
            deformable: DeformableMasters::default(),
            segment_contacts: Vec::new(),
            applied_deformable: Vec::new(),
            deformable_work: 0.0,
            axis: false,
            applied_axis: Vec::new(),
            axis_contacts: 0,
            axis_work: 0.0,
            gap_w: Vec::new(),
            force_w: Vec::new(),
            candidates: Vec::new(),
            gap_points: Vec::new(),
        })
    }

    /// The same system with deformable masters ([`super::deformable`]).
    pub fn with_deformable(mut self, masters: DeformableMasters) -> Self {
        self.deformable = masters;
        self
    }

    /// The same system with the axis of an axisymmetric model as a wall
    /// (`axis`: the model is axisymmetric and [`ContactParameters::axis`]
    /// is on).
    ///
    /// # Deviations
    /// SPEC §8 has no contact with the axis: the particles on it are held
    /// radially (`ON_AXIS`, `FIX_X`), and nothing keeps any other particle
    /// from crossing it. A particle at `r < 0` is a ring of negative radius:
    /// its points' hoop stretch `r/R` turns negative, and a free one flies
    /// on to any radius. Both happened: in Case I's plate at 24 rows and
    /// 298 m/s (the default model, lattice phases 0 and ½), the plug's
    /// interior split along a crack toward the axis, crack-face material
    /// was squeezed inward along it at 500–1,000 m/s, and four crack-face and
    /// interior particles crossed the axis and ended at `r` = −37 to
    /// −69 mm (`docs/validation.md`, "Material that crossed the axis").
    /// Here every particle off the axis whose contact-free predicted
    /// position (its physical point, with shape-function spreading) would
    /// end the step at `r < 0` is paired with the axis, normal `+e_r`, in
    /// the same projected Gauss–Seidel solve as the other pairs, without
    /// friction and without a reaction: the axis is where a ring meets
    /// itself, and the radial momentum of an axisymmetric body is no
    /// conserved quantity (its axial momentum is, and the wall's force has
    /// no axial part). The one-step force stops the ring's radial motion
    /// at the axis, a perfectly inelastic meeting; the radial kinetic
    /// energy it takes is the work of the axis forces
    /// ([`Self::axis_work`]), booked with the contact work in the energy
    /// balance. A particle that starts a step across the axis is held at
    /// its depth ([`gap_floor`]). Where no particle reaches the axis
    /// nothing changes, to the bit. A case without a contact stage (no
    /// projectile, one body, no self-contact) has no axis wall, and needs
    /// none: its cracks nucleate only at slave particles
    /// ([`crate::fracture::CrackGrowth`]), which only a contact stage
    /// marks, so its body stays whole and is held on the axis by its axis
    /// particles (a point that inverts stops the run). In 3D there is no
    /// axis; a symmetry plane of a 3D model would be the same wall. Test:
    /// `no_particle_crosses_the_axis`.
    pub fn with_axis(mut self, axis: bool) -> Self {
        self.axis = axis;
        self
    }

    /// Slaves by exposure (SPEC §8 deviation; on with
    /// [`ContactParameters::admit_exposed`]): every particle not yet a slave
    /// whose position `X + U` is inside a rigid body or within
    /// [`EXPOSED_REACH`] `× h` of its outline joins the slave set, and stays.
    /// Returns how many joined.
    ///
    /// SPEC §8 takes the slaves from the target's surface (the boundary
    /// particles, plus crack-face particles). Under large deformation the
    /// surface is not fixed: at a projectile's corner the surface layer can
    /// be extruded sideways and slide away, and the projectile then meets
    /// particles that started in the interior but are not tested at all.
    /// In the fine plane-strain Borvik Case I with the damage criterion the
    /// corner had penetrated six such particles by up to 0.25 mm (one
    /// spacing) when a crushed point inverted at 35.8 µs. Admitting them
    /// before they penetrate keeps the contact surface the current one; one
    /// that joins already inside is held at its depth, not pushed out
    /// ([`gap_floor`]). A particle that joins and never penetrates gets no force and changes
    /// nothing: runs whose interior particles never reach a body keep their
    /// bits (tests `exposed_particles_join_the_slaves_and_go_no_deeper`,
    /// `admitted_interior_slaves_that_never_penetrate_change_no_bits`).
    /// The check is one parallel pass over the particles with a bounding-box
    /// filter per body.
    pub fn admit_exposed(&mut self, x0: &[Vec2], u: &[Vec2], spacing: &[Real]) -> usize {
        if !self.params.admit_exposed {
            return 0;
        }
        let (bodies, slaves) = (&self.bodies, &self.slaves);
        let joining: Vec<usize> = (0..x0.len().min(u.len()).min(spacing.len()))
            .into_par_iter()
            .filter(|&i| {
                let x = x0[i] + u[i];
                bodies.iter().any(|b| b.within_reach(&(x - b.position), EXPOSED_REACH * spacing[i]))
                    && !slaves.contains(i)
            })
            .collect();
        for &i in &joining {
            self.slaves.add(i);
        }
        joining.len()
    }

    /// Slaves admitted by exposure so far (those without the
    /// [`ParticleFlags::SLAVE`] flag of the surface and crack faces), and
    /// how many of them were in contact in the last step.
    pub fn exposed_counts(&self, flags: &[ParticleFlags]) -> (usize, usize) {
        let exposed = |i: u32| flags.get(i as usize).is_some_and(|f| !f.has(ParticleFlags::SLAVE));
        let admitted = self.slaves.particles().iter().filter(|&&i| exposed(i)).count();
        let touching = self.contacts.iter().filter(|c| exposed(c.particle)).count();
        (admitted, touching)
    }

    /// The parameters.
    pub fn parameters(&self) -> &ContactParameters {
        &self.params
    }

    /// Active contacts of the last [`Self::compute_forces`].
    pub fn contacts(&self) -> &[ActiveContact] {
        &self.contacts
    }

    /// Total cumulative contact work over all bodies, J (see
    /// [`BodySample::work_on_particles`] and [`BodySample::work_on_body`]),
    /// with that of the deformable contacts ([`Self::deformable_work`]) and
    /// of the axis ([`Self::axis_work`]).
    pub fn contact_work(&self) -> Real {
        self.work_on_particles.iter().chain(&self.work_on_body).sum::<Real>() + self.deformable_work + self.axis_work
    }

    /// Cumulative work of the deformable contacts' forces on the particles
    /// (both sides of every pair), J; its negative is the energy they
    /// dissipated (≥ 0 for a well-behaved contact).
    pub fn deformable_work(&self) -> Real {
        self.deformable_work
    }

    /// Cumulative work of the axis forces on the particles, J
    /// ([`Self::with_axis`]); its negative is the radial kinetic energy the
    /// axis took.
    pub fn axis_work(&self) -> Real {
        self.axis_work
    }

    /// Particles held at the axis in the last [`Self::compute_forces`].
    pub fn axis_contacts(&self) -> usize {
        self.axis_contacts
    }

    /// Deformable contacts of the last [`Self::compute_forces`].
    pub fn segment_contacts(&self) -> &[SegmentContact] {
        &self.segment_contacts
    }

    /// Number of the last step's contacts that touched deformable body
    /// `body`: rigid pairs whose slave is its particle, deformable pairs with
    /// its particle as the slave or a master end.
    pub fn contacts_touching(&self, body_of: &[u32], body: u32) -> usize {
        let of = |i: u32| body_of.get(i as usize) == Some(&body);
        let rigid = self.contacts.iter().filter(|c| of(c.particle)).count();
        rigid + self.segment_contacts.iter().filter(|c| of(c.particle) || of(c.segment[0]) || of(c.segment[1])).count()
    }

    /// Total linear momentum of the rigid bodies, kg m/s.
    pub fn body_momentum(&self) -> Vec2 {
        self.bodies.iter().map(RigidBody::momentum).sum()
    }

    /// Time-history sample of body `b`.
    pub fn sample(&self, b: usize) -> Option<BodySample> {
        let body = self.bodies.get(b)?;
        Some(BodySample {
            position: body.position,
            velocity: body.velocity,
            contact_force: self.reaction.get(b).copied().unwrap_or_else(Vec2::zeros),
            work_on_particles: self.work_on_particles.get(b).copied().unwrap_or(0.0),
            work_on_body: self.work_on_body.get(b).copied().unwrap_or(0.0),
            active_contacts: self.active_per_body.get(b).copied().unwrap_or(0),
        })
    }

    /// Error unless the state is one the steps can work on: one entry per
    /// body in every per-body list, the slaves ascending particle indices
    /// below `n` with one pairing each, every pairing naming a body and one
    /// of its features (checks of a state read from a checkpoint).
    pub fn check_state(&self, n: usize) -> Result<(), ContactError> {
        let nb = self.bodies.len();
        let lens = [
            ("reaction", self.reaction.len()),
            ("active_per_body", self.active_per_body.len()),
            ("predicted_position", self.predicted_position.len()),
            ("work_on_particles", self.work_on_particles.len()),
            ("work_on_body", self.work_on_body.len()),
        ];
        for (field, found) in lens {
            if found != nb {
                return Err(ContactError::LengthMismatch { field, expected: nb, found });
            }
        }
        let vertices: Vec<usize> = self.bodies.iter().map(RigidBody::vertex_count).collect();
        self.slaves.check(n, &vertices)?;
        self.deformable.check(n)
    }

    fn resize_per_body(&mut self) {
        let nb = self.bodies.len();
        self.reaction.resize(nb, Vec2::zeros());
        self.active_per_body.resize(nb, 0);
        self.predicted_position.resize(nb, Vec2::zeros());
        self.work_on_particles.resize(nb, 0.0);
        self.work_on_body.resize(nb, 0.0);
    }

    /// Contact forces of this step (SPEC §8), written into `f_contact`
    /// (overwritten, one entry per particle). Call after the internal and
    /// external forces of the step are known and before the velocity update
    /// (module doc); follow with [`Self::advance`]. On error, `f_contact`
    /// and the pairing hints are unspecified and the step must not go on.
    ///
    /// 1. For each slave: predict its gap point and velocity at the end of
    ///    the step without contact (`force` module doc), pair it with each
    ///    body whose predicted bounding box contains the point (reusing last
    ///    step's pairing while its local test holds), and keep the pairs with
    ///    `g̃ < 0`.
    /// 2. Find the forces `F_c = f_n n + f_t t` of those pairs such that,
    ///    after the step, every gap point with `f_n > 0` lies on the master
    ///    surface (a pair that started the step inside beyond round-off: at
    ///    its depth then, [`gap_floor`]) and every
    ///    sticking one moves tangentially with the body
    ///    (`f_n ≥ 0`, `|f_t| ≤ μ f_n`): projected Gauss–Seidel over the pairs,
    ///    each update being the one-step force `−m g/Δt²` (and stick force
    ///    `−m v_t/Δt`) of the pair's remaining gap (velocity) with its own
    ///    effective mass. A pair that no other pair shares particles with is
    ///    exact after one sweep — the formula of SPEC §8.
    /// 3. Spread each `F_c` per [`ContactParameters::spreading`]; the
    ///    reaction on the body is minus the sum of the forces applied, so
    ///    momentum is conserved to round-off.
    ///
    /// # Deviations
    /// SPEC §8 computes each slave's force alone. When the forces are
    /// spread, neighbouring slaves move shared particles, and forces computed
    /// alone no longer remove the penetration. With
    /// [`Spreading::ShapeFunction`] on a uniformly loaded face each top
    /// particle receives about one whole slave force while the isolated
    /// effective mass is about twice the particle's, so the face was thrown
    /// out by the full penetration every step: before this solve was added,
    /// `compare_spreading_on_elastic_impact` (case A) measured a step-to-step
    /// force variation of 137 % of the mean (2.9 % with it). With
    /// inverse-distance weights and [RL10, §3]'s `m_s` the error has the other
    /// sign (the slave keeps only part of its force): residual penetration
    /// 1.6e-3 h in case A, 5e-8 h with the solve. Tests:
    /// `compare_spreading_on_elastic_impact`,
    /// `shape_function_contact_of_an_isolated_point_is_exact`.
    pub fn compute_forces(&mut self, input: &StepInput, f_contact: &mut [Vec2]) -> Result<StepReport, ContactError> {
        self.pending = None;
        self.params.validate()?;
        let spreading = self.params.spreading;
        input.validate(spreading)?;
        let n = input.x0.len();
        if f_contact.len() != n {
            return Err(ContactError::LengthMismatch { field: "f_contact", expected: n, found: f_contact.len() });
        }
        self.slaves.check_indices(n)?;
        self.resize_per_body();
        f_contact.fill(Vec2::zeros());
        self.contacts.clear();
        self.applied.clear();
        self.segment_contacts.clear();
        self.applied_deformable.clear();
        self.applied_axis.clear();
        self.axis_contacts = 0;
        self.candidates.clear();
        self.gap_w.clear();
        self.force_w.clear();
        self.reaction.fill(Vec2::zeros());
        self.active_per_body.fill(0);
        let (dt, dt_v) = (input.dt, input.dt_velocity);
        for (b, body) in self.bodies.iter().enumerate() {
            self.predicted_position[b] = body.position + body.predicted_velocity() * dt;
        }

        // 1. Prediction (in parallel: every slave's gap point) and search.
        let slaves = self.slaves.particles();
        self.gap_points
            .resize(slaves.len(), GapPoint { predicted: Vec2::zeros(), now: Vec2::zeros(), velocity: Vec2::zeros() });
        let predicted = self.gap_points.par_iter_mut().zip(slaves.par_iter()).try_for_each(|(g, &s)| {
            *g = predict_gap_point(input, s as usize, spreading)?;
            Ok(())
        });
        if let Err(e) = predicted {
            // Name the first slave in order that fails, as a serial loop would.
            return Err(slaves
                .iter()
                .find_map(|&s| predict_gap_point(input, s as usize, spreading).err())
                .unwrap_or(e));
        }
        for k in 0..self.slaves.len() {
            let s = self.slaves.particles()[k] as usize;
            let GapPoint { predicted: x, now: x_now, velocity: vel } = self.gap_points[k];
            // The gap point's row, written into `gap_w` once the slave
            // penetrates a body.
            let mut gap_rows: Option<(u32, u32)> = None;
            let last = self.slaves.pairing(k);
            let mut found: Option<Pairing> = None;
            for (b, body) in self.bodies.iter().enumerate() {
                let at = self.predicted_position[b];
                if !body.bounding_box_contains(&(x - at)) {
                    continue;
                }
                let reuse = match last {
                    Some(p) if p.body as usize == b => check_pairing(body, &at, p.feature, &x),
                    _ => None,
                };
                let from = x_now - body.position + at;
                let fresh = || search_rigid_polygon(body, &at, &x, &from);
                let Some(Projection { feature, gap, normal }) = reuse.or_else(fresh) else {
                    continue;
                };
                let pairing = Pairing { body: b as u32, feature };
                found = Some(pairing);
                if gap >= 0.0 {
                    continue;
                }
                let gap_rows = match gap_rows {
                    Some(rows) => rows,
                    None => {
                        let start = self.gap_w.len();
                        gap_row(input, s, spreading, &mut self.gap_w)?;
                        *gap_rows.insert((start as u32, self.gap_w.len() as u32))
                    }
                };
                let force_rows = match spreading {
                    Spreading::None | Spreading::ShapeFunction | Spreading::MassWeighted => gap_rows,
                    Spreading::InverseDistance => {
                        let start = self.force_w.len();
                        inverse_distance_neighbours(input, s, self.params.inverse_distance_floor, &mut self.force_w)?;
                        (start as u32, self.force_w.len() as u32)
                    }
                };
                let tangent = Vec2::new(-normal.y, normal.x);
                let rows = |r: (u32, u32)| r.0 as usize..r.1 as usize;
                let force_w = match spreading {
                    Spreading::InverseDistance => &self.force_w[rows(force_rows)],
                    Spreading::None | Spreading::ShapeFunction | Spreading::MassWeighted => &self.gap_w[rows(gap_rows)],
                };
                let (c_n, c_t) = row_compliance(input, &self.gap_w[rows(gap_rows)], force_w, &normal, &tangent);
                let relative = vel - body.predicted_velocity();
                let start_gap = gap - dt * relative.dot(&normal);
                self.candidates.push(
                    Candidate::new(s as u32, Master::Rigid(pairing), gap_rows, force_rows, gap, normal)
                        .with_motion(relative.dot(&tangent), c_n, c_t)
                        .with_start_gap(start_gap, input.spacing[s]),
                );
            }
            self.slaves.set_pairing(k, found);
        }
        // Deformable masters (after the rigid pairs, so that a run without
        // deformable pairs solves exactly what it did before).
        let physical = (spreading == Spreading::ShapeFunction).then_some(&self.gap_points[..]);
        self.deformable.candidates(input, self.slaves.particles(), physical, &mut self.gap_w, &mut self.candidates)?;
        // The axis last, for the same reason.
        if self.axis {
            self.axis_candidates(input, spreading)?;
        }

        // 2. Projected Gauss–Seidel on the penetrating pairs; f_contact holds
        // the forces of the current iterate.
        let mu = self.params.friction_coefficient;
        let id = spreading == Spreading::InverseDistance;
        let mut iterations = 0;
        let sweeps = if self.candidates.is_empty() { 0 } else { self.params.max_iterations };
        for _ in 0..sweeps {
            iterations += 1;
            let (mut change, mut scale): (Real, Real) = (0.0, 0.0);
            for c in self.candidates.iter_mut() {
                // displacement response of the gap point per unit Δt²
                let mut du = Vec2::zeros();
                for &(j, w) in &self.gap_w[c.gap_rows.0 as usize..c.gap_rows.1 as usize] {
                    du += mobility(input, j as usize).component_mul(&f_contact[j as usize]) * w;
                }
                let gap = (c.gap - c.gap_floor) + dt * dt_v * c.normal.dot(&du);
                let f_n = (c.f_n + one_step_normal_force(c.mass_normal, gap, dt * dt_v)).max(0.0);
                let v_t = c.slip_velocity + dt_v * c.tangent.dot(&du);
                let mu = if matches!(c.master, Master::Axis) { 0.0 } else { mu };
                let (f_t, slipping) = coulomb_cap(c.f_t + stick_force(c.mass_tangent, v_t, dt_v), mu * f_n);
                let delta = c.normal * (f_n - c.f_n) + c.tangent * (f_t - c.f_t);
                if delta != Vec2::zeros() {
                    let rows = if id { &self.force_w[..] } else { &self.gap_w[..] };
                    for &(j, w) in &rows[c.force_rows.0 as usize..c.force_rows.1 as usize] {
                        f_contact[j as usize] += delta * w;
                    }
                }
                change = change.max((f_n - c.f_n).abs()).max((f_t - c.f_t).abs());
                scale = scale.max(f_n);
                (c.f_n, c.f_t, c.slipping) = (f_n, f_t, slipping);
            }
            if !(change.is_finite() && scale.is_finite()) {
                let particle = self.candidates.first().map_or(0, |c| c.particle as usize);
                return Err(ContactError::NonFinite { particle, quantity: "contact force" });
            }
            if change <= self.params.tolerance * scale {
                break;
            }
        }

        // 3. Apply the converged forces (once, so that the reaction is
        // exactly minus the sum of what the particles receive).
        f_contact.fill(Vec2::zeros());
        let mut total = Vec2::zeros();
        for c in &self.candidates {
            if c.f_n == 0.0 && c.f_t == 0.0 {
                continue; // released by its neighbours
            }
            let force = c.normal * c.f_n + c.tangent * c.f_t;
            let pairing = match c.master {
                Master::Rigid(pairing) => pairing,
                Master::Axis => {
                    // The ring meets itself: nothing to react.
                    let rows = if id { &self.force_w[..] } else { &self.gap_w[..] };
                    for &(j, w) in &rows[c.force_rows.0 as usize..c.force_rows.1 as usize] {
                        let f = force * w;
                        f_contact[j as usize] += f;
                        total += f;
                        self.applied_axis.push((j, f, input.v[j as usize]));
                    }
                    self.axis_contacts += 1;
                    continue;
                }
                Master::Segment { segment, lambda } => {
                    // Both sides are in the one row: nothing to react.
                    for &(j, w) in &self.gap_w[c.force_rows.0 as usize..c.force_rows.1 as usize] {
                        let f = force * w;
                        f_contact[j as usize] += f;
                        total += f;
                        self.applied_deformable.push((j, f, input.v[j as usize]));
                    }
                    self.segment_contacts.push(SegmentContact {
                        particle: c.particle,
                        segment,
                        lambda,
                        gap: c.gap,
                        normal: c.normal,
                        normal_force: c.f_n,
                        tangential_force: c.f_t,
                        slipping: c.slipping,
                        force,
                    });
                    continue;
                }
            };
            let rows = if id { &self.force_w[..] } else { &self.gap_w[..] };
            let mut applied = Vec2::zeros();
            for &(j, w) in &rows[c.force_rows.0 as usize..c.force_rows.1 as usize] {
                let f = force * w;
                f_contact[j as usize] += f;
                applied += f;
                self.applied.push((j, pairing.body, f, input.v[j as usize]));
            }
            let b = pairing.body as usize;
            self.reaction[b] -= applied;
            self.active_per_body[b] += 1;
            total += applied;
            self.contacts.push(ActiveContact {
                particle: c.particle,
                pairing,
                gap: c.gap,
                normal: c.normal,
                effective_mass: c.mass_normal,
                normal_force: c.f_n,
                tangential_force: c.f_t,
                slipping: c.slipping,
                force: applied,
            });
        }
        self.deformable.remember(self.segment_contacts.iter().map(|c| (c.particle, c.segment)));
        self.pending = Some((dt, dt_v, n));
        Ok(StepReport { active_contacts: self.contacts.len(), force_on_particles: total, iterations })
    }

    /// The axis pairs of this step ([`Self::with_axis`]): every particle
    /// off the axis whose contact-free predicted gap point ends the step at
    /// `r < 0`, in particle order. Only particles whose generalized
    /// position lies within two supports of the axis are predicted: a
    /// particle whose point crosses the axis is missed only if its
    /// coefficient lies more than two supports from that point. Not
    /// guaranteed; measured on the runs whose coefficients left the field
    /// furthest, at [`crate::step::coefficient_gap`].
    fn axis_candidates(&mut self, input: &StepInput, spreading: Spreading) -> Result<(), ContactError> {
        let near_axis = |i: usize| {
            !input.flags[i].has(ParticleFlags::ON_AXIS) && input.x0[i].x + input.u[i].x < 2.0 * input.support[i]
        };
        let crossing: Result<Vec<(usize, GapPoint)>, ContactError> = (0..input.x0.len())
            .into_par_iter()
            .filter(|&i| near_axis(i))
            .map(|i| predict_gap_point(input, i, spreading).map(|g| (i, g)))
            .filter(|r| r.as_ref().map_or(true, |(_, g)| g.predicted.x < 0.0))
            .collect();
        // On an error, name the first particle in order that fails, as a
        // serial loop would (and as the slaves' prediction does).
        let near = crossing.map_err(|e| {
            (0..input.x0.len())
                .filter(|&i| near_axis(i))
                .find_map(|i| predict_gap_point(input, i, spreading).err())
                .unwrap_or(e)
        })?;
        let normal = Vec2::new(1.0, 0.0);
        for (i, g) in near {
            let start = self.gap_w.len() as u32;
            gap_row(input, i, spreading, &mut self.gap_w)?;
            let gap_rows = (start, self.gap_w.len() as u32);
            // Inverse-distance spreading reads the forces' rows from
            // `force_w`: the axis spreads its force as the gap point reads.
            let force_rows = if spreading == Spreading::InverseDistance {
                let from = self.force_w.len() as u32;
                self.force_w.extend_from_slice(&self.gap_w[gap_rows.0 as usize..gap_rows.1 as usize]);
                (from, self.force_w.len() as u32)
            } else {
                gap_rows
            };
            let row = &self.gap_w[gap_rows.0 as usize..gap_rows.1 as usize];
            let tangent = Vec2::new(0.0, 1.0);
            let (c_n, c_t) = row_compliance(input, row, row, &normal, &tangent);
            self.candidates.push(
                Candidate::new(i as u32, Master::Axis, gap_rows, force_rows, g.predicted.x, normal)
                    .with_motion(0.0, c_n, c_t)
                    .with_start_gap(g.now.x, input.spacing[i]),
            );
        }
        Ok(())
    }

    /// Finish the step (module doc, stage 3): `v` holds the particles' new
    /// velocities `V^{n+½}`. Advances every body under its reaction
    /// ([`RigidBody::advance`]) and accumulates the contact work `Σ f·Δx`
    /// with the displacement increment centred on the instant `t^n` at which
    /// the forces act, `Δx^n = ½ Δt (V^{n−½} + V^{n+½})`, for the particles
    /// and the bodies alike.
    ///
    /// # Deviations
    /// The centred increment (rather than `Δt V^{n+½}`) is chosen because it
    /// makes the discrete identity `½m|V^{n+½}|² − ½m|V^{n−½}|² = f^n·Δx^n`
    /// exact for the central difference: the contact work then equals the
    /// kinetic energy the contact exchanged, even for the impulsive one-step
    /// forces (with `Δt V^{n+½}` a slave stopped in one step would show no
    /// work at all). The integrator should count internal and external work
    /// the same way to close the energy balance of SPEC §5. Test:
    /// `momentum_and_energy_with_a_free_body`.
    pub fn advance(&mut self, v: &[Vec2]) -> Result<(), ContactError> {
        let (dt, dt_v, n) = self.pending.ok_or(ContactError::AdvanceWithoutForces)?;
        if v.len() != n {
            return Err(ContactError::LengthMismatch { field: "v", expected: n, found: v.len() });
        }
        self.pending = None;
        self.resize_per_body(); // bodies added since compute_forces feel no force
        for &(j, b, f, v_old) in &self.applied {
            let v_new = v[j as usize];
            self.work_on_particles[b as usize] += 0.5 * dt_v * f.dot(&(v_old + v_new));
        }
        for &(j, f, v_old) in &self.applied_deformable {
            self.deformable_work += 0.5 * dt_v * f.dot(&(v_old + v[j as usize]));
        }
        for &(j, f, v_old) in &self.applied_axis {
            self.axis_work += 0.5 * dt_v * f.dot(&(v_old + v[j as usize]));
        }
        for (b, body) in self.bodies.iter_mut().enumerate() {
            let v_old = body.velocity;
            body.advance(self.reaction[b], dt_v, dt);
            self.work_on_body[b] += 0.5 * dt_v * self.reaction[b].dot(&(v_old + body.velocity));
        }
        Ok(())
    }
}

/// What a slave is pressed against.
#[derive(Clone, Copy, Debug)]
pub(super) enum Master {
    /// A rigid body's feature: the reaction acts on the body.
    Rigid(Pairing),
    /// A deformable master segment at parameter `lambda`: the gap row holds
    /// both sides, and so does the force ([`super::deformable`]).
    Segment { segment: [u32; 2], lambda: Real },
    /// The axis `r = 0` of an axisymmetric model, frictionless and without
    /// a reaction ([`ContactSystem::with_axis`]).
    Axis,
}

/// A penetrating slave–master pair during the force solve.
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    particle: u32,
    master: Master,
    /// Range of the gap point's (particle, weight) entries in `gap_w`.
    gap_rows: (u32, u32),
    /// Range of the force's entries in `force_w` (inverse distance) or `gap_w`.
    force_rows: (u32, u32),
    /// Contact-free predicted gap `g̃`, m.
    gap: Real,
    /// The end-of-step gap the normal force restores, m (≤ 0):
    /// [`gap_floor`] of the pair's start-of-step gap.
    gap_floor: Real,
    normal: Vec2,
    tangent: Vec2,
    /// Contact-free predicted relative tangential velocity, m/s.
    slip_velocity: Real,
    /// Effective masses for the pair's own normal and tangential force, kg
    /// (infinite: the gap point cannot move in that direction).
    mass_normal: Real,
    mass_tangent: Real,
    f_n: Real,
    f_t: Real,
    slipping: bool,
}

impl Candidate {
    /// A pair with no force yet: slave `particle`, its `master`, the ranges
    /// of its gap and force rows, its predicted gap and the master's normal.
    pub(super) fn new(
        particle: u32,
        master: Master,
        gap_rows: (u32, u32),
        force_rows: (u32, u32),
        gap: Real,
        normal: Vec2,
    ) -> Self {
        Candidate {
            particle,
            master,
            gap_rows,
            force_rows,
            gap,
            gap_floor: 0.0,
            normal,
            tangent: Vec2::new(-normal.y, normal.x),
            slip_velocity: 0.0,
            mass_normal: Real::INFINITY,
            mass_tangent: Real::INFINITY,
            f_n: 0.0,
            f_t: 0.0,
            slipping: false,
        }
    }

    /// With the predicted relative tangential velocity (m/s) and the gap
    /// point's compliances along the normal and the tangent (1/kg).
    pub(super) fn with_motion(mut self, slip_velocity: Real, c_n: Real, c_t: Real) -> Self {
        self.slip_velocity = slip_velocity;
        self.mass_normal = effective_mass(c_n);
        self.mass_tangent = effective_mass(c_t);
        self
    }

    /// With the pair's gap at the start of the step, `start_gap` (m, with
    /// the pair's own master point and normal), and the slave's `spacing`
    /// (m): the normal force's end-of-step target becomes
    /// [`gap_floor`]`(start_gap, spacing)` instead of 0.
    pub(super) fn with_start_gap(mut self, start_gap: Real, spacing: Real) -> Self {
        self.gap_floor = gap_floor(start_gap, spacing);
        self
    }
}

/// Compliance of a gap point to its own force, per direction (1/kg):
/// `Σ_J (gap weight)(force weight) (d·P_J d)/m_J` over the entries of the
/// two rows that name the same particle, for `d` the normal and the tangent.
pub(super) fn row_compliance(
    input: &StepInput,
    gap: &[(u32, Real)],
    force: &[(u32, Real)],
    normal: &Vec2,
    tangent: &Vec2,
) -> (Real, Real) {
    let (mut c_n, mut c_t) = (0.0, 0.0);
    for &(j, wg) in gap {
        for &(jf, wf) in force {
            if jf == j {
                let r = mobility(input, j as usize);
                c_n += wg * wf * (normal.x * normal.x * r.x + normal.y * normal.y * r.y);
                c_t += wg * wf * (tangent.x * tangent.x * r.x + tangent.y * tangent.y * r.y);
            }
        }
    }
    (c_n, c_t)
}

/// Displacement response `P_J / m_J` of particle `j` per unit force (per
/// component; zero where the integrator holds the component).
#[inline]
fn mobility(input: &StepInput, j: usize) -> Vec2 {
    let inv = 1.0 / input.mass[j];
    let mut m = Vec2::new(inv, inv);
    input.flags[j].constrain(&mut m);
    m
}

/// `1 / compliance`, infinite for a point that cannot move.
#[inline]
fn effective_mass(compliance: Real) -> Real {
    if compliance > 0.0 {
        1.0 / compliance
    } else {
        Real::INFINITY
    }
}

/// The (particle, weight) row of slave `s`'s gap point, appended to `out`:
/// the slave alone, its shape-function row `N_J(X_s)` (partition of unity
/// checked) or that row weighted by mass ([`mass_weights`]), by
/// `spreading`. The weights sum to 1.
fn gap_row(input: &StepInput, s: usize, spreading: Spreading, out: &mut Vec<(u32, Real)>) -> Result<(), ContactError> {
    match spreading {
        Spreading::None | Spreading::InverseDistance => out.push((s as u32, 1.0)),
        Spreading::ShapeFunction => {
            let table = checked_shape_row(input, s)?;
            out.extend(table.range(s).map(|e| (table.index[e], table.value[e])));
        }
        Spreading::MassWeighted => out.extend(mass_weighted_row(input, s)?),
    }
    Ok(())
}

/// Slave `s`'s shape-function row weighted by mass ([`mass_weights`]).
fn mass_weighted_row<'a>(
    input: &StepInput<'a>,
    s: usize,
) -> Result<impl Iterator<Item = (u32, Real)> + 'a, ContactError> {
    let table = checked_shape_row(input, s)?;
    let row = table.range(s).map(move |e| (table.index[e], table.value[e]));
    mass_weights(row, input.mass).map_err(|sum| ContactError::InvalidParticle {
        particle: s,
        field: "mass-weighted row sum",
        value: sum,
    })
}

/// The particle shape table, once row `s` is checked: indices in range and
/// the partition of unity.
fn checked_shape_row<'a>(input: &StepInput<'a>, s: usize) -> Result<&'a ShapeTable, ContactError> {
    // `validate` guarantees the table exists with one row per particle.
    let Some(table) = input.shape else {
        return Err(ContactError::MissingShapeTable { spreading: Spreading::ShapeFunction });
    };
    let n = input.x0.len();
    let mut sum = 0.0;
    for e in table.range(s) {
        let j = table.index[e];
        if j as usize >= n {
            return Err(ContactError::ShapeIndexOutOfRange { row: s, particle: j as usize, particles: n });
        }
        sum += table.value[e];
    }
    if sum.is_nan() || (sum - 1.0).abs() > PARTITION_TOLERANCE {
        return Err(ContactError::PartitionOfUnity { particle: s, sum });
    }
    Ok(table)
}

/// The contact-free gap point of slave `s` over the step (SPEC §8): the
/// predicted position and velocity and the current position, weighted by
/// its shape-function row in row order (by the particle alone without
/// shape-function spreading).
pub(super) fn predict_gap_point(input: &StepInput, s: usize, spreading: Spreading) -> Result<GapPoint, ContactError> {
    let mut g = GapPoint { predicted: input.x0[s], now: input.x0[s], velocity: Vec2::zeros() };
    let mut add = |j: usize, w: Real| -> Result<(), ContactError> {
        let (u_pred, v_pred) = input.predicted(j)?;
        g.predicted += u_pred * w;
        g.now += input.u[j] * w;
        g.velocity += v_pred * w;
        Ok(())
    };
    match spreading {
        Spreading::None | Spreading::InverseDistance => add(s, 1.0)?,
        Spreading::ShapeFunction => {
            let table = checked_shape_row(input, s)?;
            for e in table.range(s) {
                add(table.index[e] as usize, table.value[e])?;
            }
        }
        Spreading::MassWeighted => {
            for (j, w) in mass_weighted_row(input, s)? {
                add(j as usize, w)?;
            }
        }
    }
    if !g.predicted.iter().chain(g.velocity.iter()).all(|c| c.is_finite()) {
        return Err(ContactError::NonFinite { particle: s, quantity: "predicted position or velocity" });
    }
    Ok(g)
}

/// Inverse-distance spreading weights of slave `s` over the particles of its
/// shape-function row inside its own window (module doc of `force`).
fn inverse_distance_neighbours(
    input: &StepInput,
    s: usize,
    floor: Real,
    out: &mut Vec<(u32, Real)>,
) -> Result<(), ContactError> {
    let Some(table) = input.shape else {
        return Err(ContactError::MissingShapeTable { spreading: Spreading::InverseDistance });
    };
    let n = input.x0.len();
    let xs = input.x0[s];
    let a = input.support[s];
    if let Some(e) = table.range(s).find(|&e| table.index[e] as usize >= n) {
        return Err(ContactError::ShapeIndexOutOfRange { row: s, particle: table.index[e] as usize, particles: n });
    }
    let candidates = table.range(s).map(|e| table.index[e]).filter_map(|j| {
        let d = input.x0[j as usize] - xs;
        (d.x.abs() < a && d.y.abs() < a).then_some((j, input.x0[j as usize]))
    });
    // The slave itself is always a candidate, even if its row omits it.
    let has_self = table.range(s).any(|e| table.index[e] as usize == s);
    let own = (!has_self).then_some((s as u32, xs));
    inverse_distance_weights(&xs, floor * input.spacing[s], candidates.chain(own), out);
    for &(j, _) in out.iter() {
        let m = input.mass[j as usize];
        if !(m.is_finite() && m > 0.0) {
            return Err(ContactError::InvalidParticle { particle: j as usize, field: "mass", value: m });
        }
    }
    Ok(())
}

/// Time-history sample of deformable body `body` as a projectile: the
/// centre of mass of its generalized positions `X + U` and its mass-averaged
/// velocity (its momentum over its mass, what the lumped dynamics conserves,
/// as for the plug), the contact force on it in the last step
/// (`Σ f_contact` over its particles: every pair, rigid or deformable, that
/// touched it) and the number of those pairs
/// ([`ContactSystem::contacts_touching`]; 0 without a contact stage). The
/// work fields are 0 (its contact work is in
/// [`ContactSystem::contact_work`]).
pub fn deformable_sample(
    particles: &Particles,
    f_contact: &[Vec2],
    body: u32,
    contact: Option<&ContactSystem>,
) -> BodySample {
    let (mut mass, mut moment, mut momentum, mut force) = (0.0, Vec2::zeros(), Vec2::zeros(), Vec2::zeros());
    for i in (0..particles.len()).filter(|&i| particles.body[i] == body) {
        let m = particles.mass[i];
        mass += m;
        moment += (particles.x0[i] + particles.u[i]) * m;
        momentum += particles.v[i] * m;
        force += f_contact.get(i).copied().unwrap_or_else(Vec2::zeros);
    }
    let mass: Real = mass.max(Real::MIN_POSITIVE);
    BodySample {
        position: moment / mass,
        velocity: momentum / mass,
        contact_force: force,
        work_on_particles: 0.0,
        work_on_body: 0.0,
        active_contacts: contact.map_or(0, |c| c.contacts_touching(&particles.body, body)),
    }
}
