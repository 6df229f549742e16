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

use serde::{Deserialize, Serialize};

use super::force::{friction_force, inverse_distance_weights, normal_force_one_step, Spreading};
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
    /// (SPEC §8: [RL10] runs frictionless).
    pub friction_coefficient: Real,
    /// How slave forces reach the particles. Default
    /// [`Spreading::ShapeFunction`] (see the `contact` module doc).
    pub spreading: Spreading,
    /// Inverse-distance spreading: the distance below which weights stop
    /// growing, as a fraction of the slave's spacing (dimensionless, > 0).
    /// Default ½: the slave itself weighs twice a neighbour one spacing away.
    pub inverse_distance_floor: Real,
}

impl Default for ContactParameters {
    fn default() -> Self {
        Self { friction_coefficient: 0.0, spreading: Spreading::default(), inverse_distance_floor: 0.5 }
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
    /// Flags: `CLAMPED` particles do not move, `ON_AXIS` ones not radially.
    pub flags: &'a [ParticleFlags],
    /// Shape functions at the particles, `N_J(X_I)` in row `I`; needed by
    /// [`Spreading::InverseDistance`] and [`Spreading::ShapeFunction`].
    pub shape: Option<&'a ShapeTable>,
    /// Time step `Δt`, s.
    pub dt: Real,
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
            shape,
            dt,
        }
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
        ];
        for (field, found) in lens {
            if found != n {
                return Err(ContactError::LengthMismatch { field, expected: n, found });
            }
        }
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(ContactError::InvalidParameter { name: "dt", value: self.dt });
        }
        if spreading != Spreading::None {
            let table = self.shape.ok_or(ContactError::MissingShapeTable { spreading })?;
            if table.rows() != n {
                return Err(ContactError::LengthMismatch { field: "shape rows", expected: n, found: table.rows() });
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
        let mut v = self.v[j] + (self.force_external[j] - self.force_internal[j]) * (self.dt / m);
        if flags.has(ParticleFlags::CLAMPED) {
            v = Vec2::zeros();
        }
        if flags.has(ParticleFlags::ON_AXIS) {
            v.x = 0.0;
        }
        Ok((self.u[j] + v * self.dt, v))
    }
}

/// One active contact of the last step (for diagnostics and tests).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveContact {
    /// Slave particle.
    pub particle: u32,
    /// Rigid body and feature it is paired with.
    pub pairing: Pairing,
    /// Predicted gap `g̃` (negative), m.
    pub gap: Real,
    /// Outward master normal `n_m`.
    pub normal: Vec2,
    /// Effective mass of the gap point, kg.
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
}

/// Contact of the deformable particles with rigid bodies (SPEC §8).
#[derive(Clone, Debug)]
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
    /// `Δt` of a `compute_forces` not yet followed by `advance`.
    pending_dt: Option<Real>,
    /// Scratch: (particle, weight) of the gap point and of the spreading.
    gap_weights: Vec<(u32, Real)>,
    force_weights: Vec<(u32, Real)>,
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
            pending_dt: None,
            gap_weights: Vec::new(),
            force_weights: Vec::new(),
        })
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
    /// [`BodySample::work_on_particles`] and [`BodySample::work_on_body`]).
    pub fn contact_work(&self) -> Real {
        self.work_on_particles.iter().chain(&self.work_on_body).sum()
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
            work_on_particles: self.work_on_particles[b],
            work_on_body: self.work_on_body[b],
            active_contacts: self.active_per_body.get(b).copied().unwrap_or(0),
        })
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
    /// (module doc); follow with [`Self::advance`].
    ///
    /// For each slave: predict its gap point and velocity at the end of the
    /// step without contact, pair it with each body whose predicted bounding
    /// box contains the point (reusing last step's pairing while its local
    /// test holds), and where `g̃ < 0` apply `f_n n + f_t t` with
    /// `f_n = m |g̃|/Δt²` and the capped stick force, spread per
    /// [`ContactParameters::spreading`]. The reaction on the body is minus
    /// the sum of the forces actually applied, so momentum is conserved to
    /// round-off.
    pub fn compute_forces(&mut self, input: &StepInput, f_contact: &mut [Vec2]) -> Result<StepReport, ContactError> {
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
        self.reaction.fill(Vec2::zeros());
        self.active_per_body.fill(0);
        let dt = input.dt;
        for (b, body) in self.bodies.iter().enumerate() {
            self.predicted_position[b] = body.position + body.predicted_velocity() * dt;
        }
        let mu = self.params.friction_coefficient;
        let mut total = Vec2::zeros();
        for k in 0..self.slaves.len() {
            let s = self.slaves.particles()[k] as usize;
            // Gap point of the slave: weights over particles, predicted
            // position and velocity, effective mass.
            self.gap_weights.clear();
            match spreading {
                Spreading::None | Spreading::InverseDistance => self.gap_weights.push((s as u32, 1.0)),
                Spreading::ShapeFunction => shape_row(input, s, &mut self.gap_weights)?,
            }
            let mut x = input.x0[s];
            let mut vel = Vec2::zeros();
            let mut inv_mass = 0.0;
            for &(j, w) in &self.gap_weights {
                let (u_pred, v_pred) = input.predicted(j as usize)?;
                x += u_pred * w;
                vel += v_pred * w;
                if !input.flags[j as usize].has(ParticleFlags::CLAMPED) {
                    inv_mass += w * w / input.mass[j as usize];
                }
            }
            if !x.iter().chain(vel.iter()).all(|c| c.is_finite()) {
                return Err(ContactError::NonFinite { particle: s, quantity: "predicted position or velocity" });
            }
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
                let Some(Projection { feature, gap, normal }) = reuse.or_else(|| search_rigid_polygon(body, &at, &x)) else {
                    continue;
                };
                let pairing = Pairing { body: b as u32, feature };
                found = Some(pairing);
                if gap >= 0.0 || inv_mass == 0.0 {
                    continue; // no penetration, or nothing that can move
                }
                let m_eff = match spreading {
                    Spreading::ShapeFunction => 1.0 / inv_mass,
                    Spreading::None | Spreading::InverseDistance => input.mass[s],
                };
                let f_n = normal_force_one_step(m_eff, gap, dt);
                let tangent = Vec2::new(-normal.y, normal.x);
                let v_t = (vel - body.predicted_velocity()).dot(&tangent);
                let (f_t, slipping) = friction_force(m_eff, v_t, dt, mu, f_n);
                let force = normal * f_n + tangent * f_t;
                if !force.iter().all(|c| c.is_finite()) {
                    return Err(ContactError::NonFinite { particle: s, quantity: "contact force" });
                }
                // Spread and apply; the reaction is minus what was applied.
                let weights: &[(u32, Real)] = match spreading {
                    Spreading::None | Spreading::ShapeFunction => &self.gap_weights,
                    Spreading::InverseDistance => {
                        inverse_distance_neighbours(input, s, self.params.inverse_distance_floor, &mut self.force_weights)?;
                        &self.force_weights
                    }
                };
                let mut applied = Vec2::zeros();
                for &(j, w) in weights {
                    let f = force * w;
                    f_contact[j as usize] += f;
                    applied += f;
                    self.applied.push((j, b as u32, f, input.v[j as usize]));
                }
                self.reaction[b] -= applied;
                self.active_per_body[b] += 1;
                total += applied;
                self.contacts.push(ActiveContact {
                    particle: s as u32,
                    pairing,
                    gap,
                    normal,
                    effective_mass: m_eff,
                    normal_force: f_n,
                    tangential_force: f_t,
                    slipping,
                    force: applied,
                });
            }
            self.slaves.set_pairing(k, found);
        }
        self.pending_dt = Some(dt);
        Ok(StepReport { active_contacts: self.contacts.len(), force_on_particles: total })
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
        let dt = self.pending_dt.take().ok_or(ContactError::AdvanceWithoutForces)?;
        for &(j, b, f, v_old) in &self.applied {
            let v_new = v.get(j as usize).ok_or(ContactError::LengthMismatch {
                field: "v",
                expected: j as usize + 1,
                found: v.len(),
            })?;
            self.work_on_particles[b as usize] += 0.5 * dt * f.dot(&(v_old + v_new));
        }
        for (b, body) in self.bodies.iter_mut().enumerate() {
            let v_old = body.velocity;
            body.advance(self.reaction[b], dt);
            self.work_on_body[b] += 0.5 * dt * self.reaction[b].dot(&(v_old + body.velocity));
        }
        Ok(())
    }
}

/// Row `s` of the particle shape table as (particle, N) pairs, with its
/// partition of unity checked.
fn shape_row(input: &StepInput, s: usize, out: &mut Vec<(u32, Real)>) -> Result<(), ContactError> {
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
        out.push((j, table.value[e]));
    }
    if sum.is_nan() || (sum - 1.0).abs() > PARTITION_TOLERANCE {
        return Err(ContactError::PartitionOfUnity { particle: s, sum });
    }
    Ok(())
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
