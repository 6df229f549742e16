//! Reproducing-kernel shape functions (SPEC §3).

pub mod rk;
pub mod table;

pub use rk::{
    build_table, rebuild_rows, row_with_basis, row_with_fallback, AllVisible, Basis, Row, ShapeError, Visibility,
};
pub use table::ShapeTable;
