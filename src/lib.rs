//! plugsim: explicit total-Lagrangian RKPM simulation of high-speed impact,
//! plugging and ductile fracture. See `ARCHITECTURE.md` for the module map
//! and `SPEC.md` (shared) for the physics.

pub mod ballistic;
pub mod bench;
pub mod bulk_viscosity;
pub mod case;
pub mod cases;
pub mod checkpoint;
pub mod contact;
pub mod convergence;
pub mod discretize;
pub mod fracture;
pub mod geometry;
pub mod io;
pub mod kernel;
pub mod material;
pub mod material_point;
pub mod math;
pub mod memory;
pub mod model;
pub mod neighbors;
pub mod output;
pub mod particles;
pub mod plug;
pub mod quadrature;
pub mod residual;
pub mod run;
pub mod shape;
pub mod stability;
pub mod step;
pub mod taylor;
pub mod thermal;
pub mod validation;
