//! Reproducing-kernel shape functions (SPEC §3).

pub mod rk;
pub mod table;

pub use rk::{build_table, rebuild_rows, AllVisible, ShapeError, Visibility};
pub use table::ShapeTable;
