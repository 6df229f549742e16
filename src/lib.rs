//! plugsim: explicit total-Lagrangian RKPM simulation of high-speed impact,
//! plugging and ductile fracture. See `ARCHITECTURE.md` for the module map
//! and `SPEC.md` (shared) for the physics.

pub mod contact;
pub mod io;
pub mod kernel;
pub mod material;
pub mod math;
pub mod particles;
pub mod quadrature;
pub mod shape;
pub mod discretize;
pub mod geometry;
pub mod model;
pub mod fracture;
pub mod neighbors;
pub mod step;
pub mod thermal;
pub mod case;
pub mod output;
pub mod run;
pub mod checkpoint;
pub mod memory;
pub mod cases;
pub mod material_point;
pub mod bench;
