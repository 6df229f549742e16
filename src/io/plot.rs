//! PNG line plots (interface; the implementation lands with the output work).

use std::path::Path;

/// One named curve.
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// A simple x–y line plot with optional horizontal reference lines.
#[derive(Clone, Debug, Default)]
pub struct LinePlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Horizontal reference lines `(label, y)`.
    pub hlines: Vec<(String, f64)>,
}

/// Errors from plotting.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("cannot draw plot {path}: {message}")]
    Draw { path: String, message: String },
}

/// Render `plot` to a PNG file at `path`.
pub fn save_line_plot(_path: &Path, _plot: &LinePlot) -> Result<(), PlotError> {
    unimplemented!("filled in by the output work")
}
