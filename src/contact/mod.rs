//! Contact of the deformable bodies with rigid bodies (SPEC §8,
//! [RL10, §3, Eqs. (3.1)–(3.10)]), with each other and of a cracked body
//! with itself ([`deformable`], issue #20).
//!
//! - [`rigid`]: rigid bodies with polygonal outlines (the masters), their
//!   mass from a section (plane strain) or a volume of revolution
//!   (axisymmetry), and their explicit update; [`projectile`]: the
//!   outlines of projectiles by nose shape (blunt, hemispherical, conical,
//!   ogival).
//! - [`surface`]: geometric detection of surface particles, the initial
//!   slave set; [`slave`]: the slave set and its pairing cache.
//! - [`grid`]: the point grid of the coarse search (nearest point, fixed
//!   radius) over [`crate::neighbors::CellGrid`];
//!   [`search`]: nearest vertex → segment (or vertex) → signed gap.
//! - [`force`]: one-step normal force, Coulomb friction, spreading weights.
//! - [`deformable`]: deformable masters (the bodies' boundaries and crack
//!   faces as particle polylines, at their physical points), their search,
//!   and the signed gap rows that put both sides of a pair into one force
//!   row; solved with the rigid pairs in one Gauss–Seidel solve.
//! - [`system`]: [`ContactSystem`], the stage the time loop calls.
//!
//! # Use in the time loop
//! Per step, with `U^n`, `V^{n−½}`, `f_int(U^n)` and the loads `f_ext(t^n)`
//! (without contact) in the particle store:
//! ```text
//! let report = contact.compute_forces(&StepInput::from_particles(&p, Some(&shape), dt), &mut f_contact)?;
//! V += dt (f_ext + f_contact − f_int)/m;  apply clamps / axis;  U += dt V;
//! contact.advance(&p.v)?;     // rigid bodies, contact work
//! contact.sample(0)           // projectile history: x, V, force, work, active contacts
//! ```
//! `shape` is the particle shape table (`N_J(X_I)`, rows = particles). The
//! contact forces need this step's internal force (the predictor in
//! [`force`]), so the contact stage, search included, sits between the
//! internal force and the time integration. After a crack splits particles,
//! add the new face particles with [`SlaveSet::add`]; after a permutation,
//! [`SlaveSet::permute`].
//!
//! # Default spreading
//! [`Spreading::ShapeFunction`]. RK particles are not interpolating, so the
//! target's surface is the physical point set `x(X) = X + Σ N_J(X) U_J`,
//! not `X_s + U_s`. Measuring the gap there and applying `f_J = N_J F`
//! removes the penetration of the physical surface at the slaves, is the
//! virtual work of the contact force (so the contact work enters the energy
//! balance consistently), and conserves force exactly.
//! `compare_spreading_on_elastic_impact` (tests/contact.rs) drives a rigid
//! punch into an elastic RK block: (A) uniaxial strain, where all three
//! modes give the plane-wave pressure `ρ c_L v` within 2 %; (B) a 10 h punch
//! with corners, where ShapeFunction leaves the least physical penetration
//! (0.024 h against 0.035 h for InverseDistance and 0.070 h for None) with
//! the smooth force (step-to-step variation 1.9 % of the mean, against 6 %)
//! and low contact dissipation (1.5 % of the contact work, against 11 %) of
//! the point contact. Provisional: one geometry, elastic, 50–120 steps; to
//! be confirmed on the plugging case itself (residual velocity per mode).
//! [`Spreading::MassWeighted`] (an option) holds the row's local centre of
//! mass instead of the physical point ([`force`], # Deviations).
//!
//! # Deviations (details and tests in the submodules)
//! - One-step force with factor 1, not the 2 of [RL10, §3], for SPEC §5's half-step
//!   velocities ([`force`]).
//! - Effective mass of the gap point, and a projected Gauss–Seidel solve
//!   over slaves that share particles ([`system`]).
//! - Closed projection interval and an entry-face rule at corners
//!   ([`search`]).
//! - Contact work with the step-centred displacement increment
//!   ([`ContactSystem::advance`]).
//! - Rigid bodies translate only ([`rigid`]).
//! - Slaves by exposure: interior particles that come within a spacing of
//!   a rigid body join the slaves ([`ContactSystem::admit_exposed`]).

pub mod deformable;
pub mod force;
pub mod grid;
pub mod projectile;
pub mod rigid;
pub mod search;
pub mod slave;
pub mod surface;
pub mod system;

pub use deformable::{rectangle_boundary, DeformableMasters, DeformableSwitches, Segment, SegmentContact};
pub use force::Spreading;
pub use projectile::{NoseShape, Projectile};
pub use rigid::{mass_axisymmetric, mass_plane_strain, polygons_overlap, rectangle_outline, RigidBody};
pub use search::{search_rigid_polygon, search_rigid_polygon_brute_force, Projection};
pub use slave::{MasterFeature, Pairing, SlaveSet};
pub use surface::{detect_surface, SurfaceDetection};
pub use system::{
    deformable_sample, ActiveContact, BodySample, ContactParameters, ContactSystem, StepInput, StepReport,
    EXPOSED_REACH,
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
    InvalidParticle { particle: usize, field: &'static str, value: Real },
    #[error("`{field}` has {found} entries, expected {expected}")]
    LengthMismatch { field: &'static str, expected: usize, found: usize },
    #[error("slave particle {particle} does not exist ({particles} particles)")]
    SlaveOutOfRange { particle: usize, particles: usize },
    #[error("slave {slave}: {reason}")]
    InvalidSlave { slave: usize, reason: &'static str },
    #[error("not a permutation: entry {position} repeats or exceeds the length")]
    InvalidPermutation { position: usize },
    #[error("spreading `{spreading:?}` needs the particle shape-function table")]
    MissingShapeTable { spreading: Spreading },
    #[error("shape table is malformed (offsets not monotone from 0, or entry arrays of different lengths)")]
    InvalidShapeTable,
    #[error("shape table row {row} names particle {particle} ({particles} particles)")]
    ShapeIndexOutOfRange { row: usize, particle: usize, particles: usize },
    #[error("shape functions at particle {particle} sum to {sum}, not 1")]
    PartitionOfUnity { particle: usize, sum: Real },
    #[error("particle {particle}: {quantity} is not finite")]
    NonFinite { particle: usize, quantity: &'static str },
    #[error("ContactSystem::advance called without a preceding compute_forces")]
    AdvanceWithoutForces,
}
