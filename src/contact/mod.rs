//! Contact of the deformable target with rigid bodies (SPEC §8, [RL10, §3],
//! Eqs. (3.1)–(3.10)).
//!
//! - [`rigid`]: rigid bodies with polygonal outlines (the masters), their
//!   mass from a section (plane strain) or a volume of revolution
//!   (axisymmetry), and their explicit update.
//! - [`surface`]: geometric detection of surface particles, the initial
//!   slave set; [`slave`]: the slave set and its pairing cache.
//! - [`grid`]: the uniform cell grid of the coarse search;
//!   [`search`]: nearest vertex → segment (or vertex) → signed gap.
//! - [`force`]: one-step normal force, Coulomb friction, spreading.
//! - [`system`]: [`ContactSystem`], the stage the time loop calls.
//!
//! # Use in the time loop
//! Per step, with `U^n`, `V^{n−½}`, `f_int(U^n)` and `f_ext(t^n)` known:
//! ```text
//! contact.compute_forces(&StepInput::from_particles(&p, Some(&shape), dt), &mut f_contact)?;
//! V += dt (f_ext + f_contact − f_int)/m;  apply clamps/axis;  U += dt V;
//! contact.advance(&p.v)?;          // rigid bodies, contact work
//! ```
//! The contact forces need this step's internal force (the predictor of
//! [`force`]), so the contact stage sits between the internal force and the
//! time integration; the search is part of it.
//!
//! # Default spreading
//! [`Spreading::ShapeFunction`]. RK particles are not interpolating, so the
//! target's surface is the physical point set `x(X) = X + Σ N_J(X) U_J`,
//! not `X_s + U_s`. Measuring the gap there and applying `f_J = N_J F`
//! (with the matching effective mass) removes the physical penetration in
//! one step, is the virtual work of the contact force (so the contact work
//! is consistent with the energy balance), and conserves force exactly.
//! `tests/contact.rs::compare_spreading_on_elastic_impact` compares the three
//! modes on a rigid punch driven into an elastic RK block in uniaxial
//! strain (analytic pressure `ρ c_L v`); its numbers are quoted in that
//! test. The comparison covers one configuration: the choice is
//! provisional until the full plugging case has been run with each mode.

pub mod force;
pub mod grid;
pub mod rigid;
pub mod search;
pub mod slave;
pub mod surface;
pub mod system;

pub use force::Spreading;
pub use rigid::{mass_axisymmetric, mass_plane_strain, rectangle_outline, RigidBody};
pub use search::{search_rigid_polygon, search_rigid_polygon_brute_force, Projection};
pub use slave::{MasterFeature, Pairing, SlaveSet};
pub use surface::{detect_surface, SurfaceDetection};
pub use system::{
    ActiveContact, BodySample, ContactParameters, ContactSystem, StepInput, StepReport,
};

use crate::math::Real;

/// Errors of the contact module. Each names the offending item.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    #[error("rigid body `{body}`: invalid outline: {reason}")]
    InvalidOutline { body: String, reason: String },
    #[error("rigid body `{body}`: mass {mass} kg must be positive and finite")]
    InvalidBodyMass { body: String, mass: Real },
    #[error("rigid body `{body}`: position or velocity is not finite")]
    NonFiniteBodyState { body: String },
    #[error("body section has no area on the revolved side (area {area} m²)")]
    EmptyBody { area: Real },
    #[error("parameter `{name}` = {value} is out of range")]
    InvalidParameter { name: &'static str, value: Real },
    #[error("particle {particle}: invalid {field} = {value}")]
    InvalidParticle {
        particle: usize,
        field: &'static str,
        value: Real,
    },
    #[error("`{field}` has {found} entries, expected {expected}")]
    LengthMismatch {
        field: &'static str,
        expected: usize,
        found: usize,
    },
    #[error("slave particle {particle} does not exist ({particles} particles)")]
    SlaveOutOfRange { particle: usize, particles: usize },
    #[error("not a permutation: entry {position} repeats or exceeds the length")]
    InvalidPermutation { position: usize },
    #[error("spreading `{spreading:?}` needs the particle shape-function table")]
    MissingShapeTable { spreading: Spreading },
    #[error("shape table is malformed (offsets not monotone from 0, or entry arrays of different lengths)")]
    InvalidShapeTable,
    #[error("shape table row {row} names particle {particle} ({particles} particles)")]
    ShapeIndexOutOfRange {
        row: usize,
        particle: usize,
        particles: usize,
    },
    #[error("shape functions at particle {particle} sum to {sum}, not 1")]
    PartitionOfUnity { particle: usize, sum: Real },
    #[error("particle {particle}: {quantity} is not finite")]
    NonFinite {
        particle: usize,
        quantity: &'static str,
    },
    #[error("ContactSystem::advance called without a preceding compute_forces")]
    AdvanceWithoutForces,
}
