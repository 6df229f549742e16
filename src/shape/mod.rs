//! Reproducing-kernel shape functions (SPEC §3).

pub mod table;

pub use table::ShapeTable;
