//! PNG plots: x–y line plots (time histories, convergence curves) and 2D
//! scatter "field plots" of particles coloured by a scalar with a colour bar.
//!
//! Rendering uses plotters' bitmap backend with the DejaVu Sans font
//! embedded in the binary (`assets/DejaVuSans.ttf`, licence in
//! `assets/DEJAVU-LICENSE`), so no system font library is needed. Files are
//! written through a temporary file and a rename, like the VTU frames.

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

/// Default image size in pixels (width, height).
pub const DEFAULT_SIZE: (u32, u32) = (1000, 700);

/// Smallest accepted image size (width, height); below it the axis labels
/// and colour bar leave no room for the data.
pub const MIN_SIZE: (u32, u32) = (400, 300);

/// One named curve.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend entry; an empty name gives no legend entry.
    pub name: String,
    /// Points `(x, y)` joined in order. Non-finite points are skipped and
    /// break the line; a lone point is drawn as a dot.
    pub points: Vec<(f64, f64)>,
}

/// A simple x–y line plot with optional horizontal reference lines.
#[derive(Clone, Debug, Default)]
pub struct LinePlot {
    /// Caption above the plot (none if empty).
    pub title: String,
    /// Label of the x axis.
    pub x_label: String,
    /// Label of the y axis.
    pub y_label: String,
    /// The curves, coloured in order from a fixed palette.
    pub series: Vec<Series>,
    /// Horizontal reference lines `(label, y)`, drawn dashed and labelled at
    /// their right end; the y range always includes them.
    pub hlines: Vec<(String, f64)>,
}

/// A 2D scatter plot of points coloured by a scalar (viridis colour map)
/// with a colour bar, and polylines drawn on top (e.g. the deformed plate
/// coloured by effective stress, with the crack paths).
///
/// Axes have equal scale, so shapes are not distorted.
#[derive(Clone, Debug, Default)]
pub struct FieldPlot {
    /// Caption above the plot (none if empty).
    pub title: String,
    /// Label of the x axis.
    pub x_label: String,
    /// Label of the y axis.
    pub y_label: String,
    /// Point positions `(x, y)`; points with a non-finite coordinate are
    /// skipped.
    pub points: Vec<(f64, f64)>,
    /// One value per point. Higher values are drawn on top; non-finite
    /// values are drawn grey, below the rest, and ignored for the colour
    /// range.
    pub values: Vec<f64>,
    /// Label of the colour bar (quantity and unit).
    pub value_label: String,
    /// The quantity's physical lower bound (0 for an effective stress, a
    /// plastic strain or a damage), if it has one: the colour bar starts
    /// there, and values below it (the projection onto the particles can
    /// undershoot by round-off) take its colour.
    pub value_floor: Option<f64>,
    /// Polylines drawn in black over the points (crack paths).
    pub lines: Vec<Vec<(f64, f64)>>,
}

/// Errors from plotting; each names the output file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Drawing or saving the image failed (unwritable path, ...).
    #[error("cannot draw plot {path}: {message}")]
    Draw {
        /// The output file.
        path: String,
        /// What failed.
        message: String,
    },
    /// The plot description is inconsistent (e.g. fewer values than points,
    /// an image size below [`MIN_SIZE`]).
    #[error("invalid plot {path}: {message}")]
    InvalidInput {
        /// The output file.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// Renders `plot` to a PNG file at `path`, [`DEFAULT_SIZE`] pixels.
pub fn save_line_plot(path: &Path, plot: &LinePlot) -> Result<(), PlotError> {
    save_line_plot_sized(path, plot, DEFAULT_SIZE)
}

/// Renders `plot` to a PNG file at `path`, `size` = (width, height) pixels,
/// at least [`MIN_SIZE`].
///
/// Ranges are automatic: the finite data (and reference lines) plus 5 %
/// padding; a constant or single-point series gets a range of ±5 % of its
/// value (±1 around zero).
pub fn save_line_plot_sized(path: &Path, plot: &LinePlot, size: (u32, u32)) -> Result<(), PlotError> {
    render_png(path, size, MIN_SIZE, |root| draw_line_plot(root, plot))
}

/// Renders `plot` to a PNG file at `path`, [`DEFAULT_SIZE`] pixels.
pub fn save_field_plot(path: &Path, plot: &FieldPlot) -> Result<(), PlotError> {
    save_field_plot_sized(path, plot, DEFAULT_SIZE)
}

/// Renders `plot` to a PNG file at `path`, `size` = (width, height) pixels,
/// at least [`MIN_SIZE`]. `plot.values` must have one value per point.
pub fn save_field_plot_sized(path: &Path, plot: &FieldPlot, size: (u32, u32)) -> Result<(), PlotError> {
    if plot.points.len() != plot.values.len() {
        return Err(PlotError::InvalidInput {
            path: path.display().to_string(),
            message: format!("{} points but {} values", plot.points.len(), plot.values.len()),
        });
    }
    render_png(path, size, MIN_SIZE, |root| draw_field_plot(root, plot))
}

/// Font family name under which the embedded font is registered; plotters'
/// default label style asks for it.
const FONT: &str = "sans-serif";

static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// Registers the embedded font with plotters, once per process. Without it
/// every text element fails with `FontUnavailable`.
fn register_embedded_font() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok())
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Draws with `draw` onto a white `size` canvas and saves it as PNG at
/// `path` via a temporary file and a rename.
fn render_png(
    path: &Path,
    size: (u32, u32),
    min_size: (u32, u32),
    draw: impl FnOnce(&Area) -> Result<(), String>,
) -> Result<(), PlotError> {
    let display = path.display().to_string();
    if size.0 < min_size.0 || size.1 < min_size.1 {
        return Err(PlotError::InvalidInput {
            path: display,
            message: format!("size {}x{} is below the minimum {}x{}", size.0, size.1, min_size.0, min_size.1),
        });
    }
    let fail = |message: String| PlotError::Draw { path: display.clone(), message };
    if !register_embedded_font() {
        return Err(fail("the embedded font could not be loaded".into()));
    }
    // The temporary name ends in `.png`: the encoder picks the format from it.
    let tmp = super::temporary_sibling(path, ".png").map_err(|e| fail(e.to_string()))?;
    let result = (|| {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
        drop(root);
        std::fs::rename(&tmp, path).map_err(|e| e.to_string())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(fail)
}

/// Series colours (Tableau 10), cycled.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

const REFERENCE_LINE: RGBColor = RGBColor(90, 90, 90);
const MARGIN: u32 = 20;
const X_LABEL_AREA: u32 = 60;
const Y_LABEL_AREA: u32 = 100;

/// The caption's font size, px: 28, or smaller so that `title` fits in 95 %
/// of the image's `width` (px) at an average glyph width of 0.55 em.
fn caption_size(title: &str, width: u32) -> u32 {
    let fit = 0.95 * width as f64 / (0.55 * title.chars().count().max(1) as f64);
    (fit.floor() as u32).clamp(12, 28)
}

fn draw_line_plot(root: &Area, plot: &LinePlot) -> Result<(), String> {
    let xs = plot.series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = plot.series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).chain(plot.hlines.iter().map(|h| h.1));
    let (x0, x1) = padded_range(finite_min_max(xs));
    let (y0, y1) = padded_range(finite_min_max(ys));

    let mut builder = ChartBuilder::on(root);
    builder.margin(MARGIN).x_label_area_size(X_LABEL_AREA).y_label_area_size(Y_LABEL_AREA);
    if !plot.title.is_empty() {
        builder.caption(&plot.title, (FONT, caption_size(&plot.title, root.dim_in_pixel().0)));
    }
    let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1).map_err(|e| e.to_string())?;
    draw_axes(&mut chart, ((x0, x1), (y0, y1)), (&plot.x_label, &plot.y_label), true)?;

    for (i, series) in plot.series.iter().enumerate() {
        let style = PALETTE[i % PALETTE.len()].stroke_width(2);
        let mut runs = finite_runs(&series.points);
        if runs.is_empty() {
            // Keeps the legend entry of a series with no finite point.
            runs.push(Vec::new());
        }
        for (k, run) in runs.iter().enumerate() {
            let annotation =
                chart.draw_series(LineSeries::new(run.iter().copied(), style)).map_err(|e| e.to_string())?;
            if k == 0 && !series.name.is_empty() {
                annotation
                    .label(series.name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 25, y)], style));
            }
            if run.len() == 1 {
                chart
                    .draw_series(std::iter::once(Circle::new(run[0], 4, style.filled())))
                    .map_err(|e| e.to_string())?;
            }
        }
    }

    let label_style =
        TextStyle::from((FONT, 16).into_font()).color(&REFERENCE_LINE).pos(Pos::new(HPos::Right, VPos::Bottom));
    for (label, y) in plot.hlines.iter().filter(|h| h.1.is_finite()) {
        let y = &y.clamp(-AXIS_LIMIT, AXIS_LIMIT);
        chart
            .draw_series(DashedLineSeries::new([(x0, *y), (x1, *y)], 10, 6, REFERENCE_LINE.stroke_width(2)))
            .map_err(|e| e.to_string())?;
        if !label.is_empty() {
            let text = EmptyElement::at((x1, *y)) + Text::new(label.clone(), (-6, -4), label_style.clone());
            chart.draw_series(std::iter::once(text)).map_err(|e| e.to_string())?;
        }
    }

    let names: Vec<&str> = plot.series.iter().map(|s| s.name.as_str()).filter(|n| !n.is_empty()).collect();
    if !names.is_empty() {
        let area = chart.plotting_area().dim_in_pixel();
        let legend = legend_box_fraction(&names, (area.0 as f64, area.1 as f64));
        let samples = plot_samples(plot, ((x0, x1), (y0, y1)));
        chart
            .configure_series_labels()
            .position(least_covered_place(&samples, legend).position())
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font((FONT, 16))
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A place in the plot area for the legend: a corner or the middle of a
/// side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LegendPlace {
    UpperRight,
    UpperLeft,
    LowerRight,
    LowerLeft,
    MiddleRight,
    MiddleLeft,
}

impl LegendPlace {
    /// In order of preference when the data leave more than one free.
    const ALL: [LegendPlace; 6] = [
        LegendPlace::UpperRight,
        LegendPlace::UpperLeft,
        LegendPlace::LowerRight,
        LegendPlace::LowerLeft,
        LegendPlace::MiddleRight,
        LegendPlace::MiddleLeft,
    ];

    fn position(self) -> SeriesLabelPosition {
        match self {
            LegendPlace::UpperRight => SeriesLabelPosition::UpperRight,
            LegendPlace::UpperLeft => SeriesLabelPosition::UpperLeft,
            LegendPlace::LowerRight => SeriesLabelPosition::LowerRight,
            LegendPlace::LowerLeft => SeriesLabelPosition::LowerLeft,
            LegendPlace::MiddleRight => SeriesLabelPosition::MiddleRight,
            LegendPlace::MiddleLeft => SeriesLabelPosition::MiddleLeft,
        }
    }

    /// Whether `p` (x, y as fractions of the plot area, y up) lies inside
    /// a box of `size` (width, height fractions) at this place.
    fn covers(self, size: (f64, f64), p: (f64, f64)) -> bool {
        use LegendPlace::*;
        let in_x = match self {
            UpperRight | LowerRight | MiddleRight => p.0 >= 1.0 - size.0,
            UpperLeft | LowerLeft | MiddleLeft => p.0 <= size.0,
        };
        let in_y = match self {
            UpperRight | UpperLeft => p.1 >= 1.0 - size.1,
            LowerRight | LowerLeft => p.1 <= size.1,
            MiddleRight | MiddleLeft => (p.1 - 0.5).abs() <= 0.5 * size.1,
        };
        in_x && in_y
    }
}

/// The legend's box as fractions (width, height) of a plot area of `area`
/// pixels, for the entries `names` at the legend's 16 px font: a 25 px
/// line sample, an average glyph width of 0.55 em, a row of about 22 px
/// and plotters' padding, with a few pixels' allowance for the dots.
fn legend_box_fraction(names: &[&str], area: (f64, f64)) -> (f64, f64) {
    let chars = names.iter().map(|n| n.chars().count()).max().unwrap_or(0) as f64;
    let width = 25.0 + 0.55 * 16.0 * chars + 40.0;
    let height = 22.0 * names.len() as f64 + 24.0;
    ((width / area.0.max(1.0)).min(1.0), (height / area.1.max(1.0)).min(1.0))
}

/// Where `plot` draws, as fractions of its `ranges` (x, y): points every
/// [`SAMPLE_STEP`] along each line (so a line counts by its drawn length,
/// not by how densely its data were recorded: a history's rows crowd
/// where the time step is small), [`DOT_WEIGHT`] copies of each lone point
/// (drawn as a dot), and points every [`SAMPLE_STEP`] along each
/// reference line.
fn plot_samples(plot: &LinePlot, ranges: ((f64, f64), (f64, f64))) -> Vec<(f64, f64)> {
    let ((x0, x1), (y0, y1)) = ranges;
    let unit = |p: (f64, f64)| ((p.0 - x0) / (x1 - x0), (p.1 - y0) / (y1 - y0));
    let mut samples = Vec::new();
    for series in &plot.series {
        for run in finite_runs(&series.points) {
            let run: Vec<_> = run.into_iter().map(unit).collect();
            if let [dot] = run[..] {
                samples.extend(std::iter::repeat_n(dot, DOT_WEIGHT));
            }
            resample(&run, &mut samples);
        }
    }
    for (_, y) in plot.hlines.iter().filter(|h| h.1.is_finite()) {
        let y = (y.clamp(-AXIS_LIMIT, AXIS_LIMIT) - y0) / (y1 - y0);
        resample(&[(0.0, y), (1.0, y)], &mut samples);
    }
    samples
}

/// Appends to `samples` the points every [`SAMPLE_STEP`] of length along
/// the polyline `run`, from its start (none for a single point): however
/// densely its vertices lie, a stretch counts by its length.
fn resample(run: &[(f64, f64)], samples: &mut Vec<(f64, f64)>) {
    let mut to_next = 0.0;
    for pair in run.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let length = (b.0 - a.0).hypot(b.1 - a.1);
        if !length.is_finite() {
            continue;
        }
        let mut at = to_next;
        while at < length && samples.len() < MAX_SAMPLES {
            let t = at / length;
            samples.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
            at += SAMPLE_STEP;
        }
        to_next = at - length;
    }
}

/// A bound on the samples: a long history that swings up and down every
/// row draws a line many plot-widths long.
const MAX_SAMPLES: usize = 1_000_000;

/// Spacing of the legend's samples along a drawn line, as a fraction of
/// the plot area (about 4 px on a default plot).
const SAMPLE_STEP: f64 = 0.005;

/// A lone point (a dot: an experiment, one run) counts as this many
/// samples, as much as a line across a tenth of the plot.
const DOT_WEIGHT: usize = 20;

/// The place whose legend box of `size` (fractions of the plot area)
/// covers the fewest of `samples` (fractions, y up): the first of
/// [`LegendPlace::ALL`] among equals, upper right when nothing is drawn. A
/// ballistic curve rises to the upper right, where a fixed legend hid its
/// fastest runs and the experiments beside them.
fn least_covered_place(samples: &[(f64, f64)], size: (f64, f64)) -> LegendPlace {
    let covered = |place: LegendPlace| samples.iter().filter(|p| place.covers(size, **p)).count();
    LegendPlace::ALL.into_iter().min_by_key(|c| covered(*c)).unwrap_or(LegendPlace::UpperRight)
}

/// Width of the colour-bar strip at the right of a field plot, pixels.
const COLORBAR_STRIP: u32 = 190;
const COLORBAR_LABEL_AREA: u32 = 120;

fn draw_field_plot(root: &Area, plot: &FieldPlot) -> Result<(), String> {
    let root = if plot.title.is_empty() {
        root.clone()
    } else {
        root.margin(10, 0, 0, 0).titled(&plot.title, (FONT, 28)).map_err(|e| e.to_string())?
    };
    let (width, height) = root.dim_in_pixel();
    let (main, bar) = root.split_horizontally(width.saturating_sub(COLORBAR_STRIP));

    // Equal scale on both axes: pad the data box by 5 % of its larger side,
    // then widen the shorter direction to the plot area's aspect ratio.
    let coords = plot.points.iter().chain(plot.lines.iter().flatten()).filter(|p| p.0.is_finite() && p.1.is_finite());
    let xs = finite_min_max(coords.clone().map(|p| p.0));
    let ys = finite_min_max(coords.map(|p| p.1));
    let plot_px = (
        f64::from((main.dim_in_pixel().0.saturating_sub(2 * MARGIN + Y_LABEL_AREA)).max(1)),
        f64::from((height.saturating_sub(2 * MARGIN + X_LABEL_AREA)).max(1)),
    );
    let ((x0, x1), (y0, y1)) = equal_scale_ranges(xs, ys, plot_px);

    let mut chart = ChartBuilder::on(&main)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| e.to_string())?;
    draw_axes(&mut chart, ((x0, x1), (y0, y1)), (&plot.x_label, &plot.y_label), false)?;

    let finite_values = finite_min_max(plot.values.iter().copied())
        .map(|(lo, hi)| plot.value_floor.map_or((lo, hi), |floor| (floor, hi.max(floor))));
    let (v0, v1) = match finite_values {
        Some((lo, hi)) if hi > lo => (lo, hi),
        other => padded_range(other),
    };
    let colour = |v: f64| {
        if v.is_finite() {
            viridis(((v - v0) / (v1 - v0)).clamp(0.0, 1.0))
        } else {
            RGBColor(170, 170, 170)
        }
    };

    // Non-finite values first (underneath), then ascending value.
    let mut order: Vec<usize> =
        (0..plot.points.len()).filter(|&i| plot.points[i].0.is_finite() && plot.points[i].1.is_finite()).collect();
    order.sort_by(|&a, &b| {
        let (va, vb) = (plot.values[a], plot.values[b]);
        (va.is_finite(), va).partial_cmp(&(vb.is_finite(), vb)).unwrap_or(std::cmp::Ordering::Equal)
    });
    // Marker radius: half the mean point spacing in pixels, estimated from
    // the points' bounding box (its diagonal for points along a line),
    // within 1..=8 px.
    let bbox = finite_min_max(order.iter().map(|&i| plot.points[i].0))
        .zip(finite_min_max(order.iter().map(|&i| plot.points[i].1)));
    let radius = bbox.map_or(4.0, |((xa, xb), (ya, yb))| {
        let (w, h) = ((xb - xa) / (x1 - x0) * plot_px.0, (yb - ya) / (y1 - y0) * plot_px.1);
        let n = order.len() as f64;
        let spacing = if w * h > 0.0 { (w * h / n).sqrt() } else { w.hypot(h) / n };
        (0.5 * spacing).round().clamp(1.0, 8.0)
    }) as i32;
    chart
        .draw_series(order.iter().map(|&i| Circle::new(clip(plot.points[i]), radius, colour(plot.values[i]).filled())))
        .map_err(|e| e.to_string())?;
    for line in &plot.lines {
        for run in finite_runs(line) {
            chart.draw_series(LineSeries::new(run, BLACK.stroke_width(2))).map_err(|e| e.to_string())?;
        }
    }

    // Colour bar, aligned with the plot area.
    let mut bar_chart = ChartBuilder::on(&bar)
        .margin_top(MARGIN)
        .margin_bottom(MARGIN + X_LABEL_AREA)
        .margin_left(10)
        .margin_right(MARGIN)
        .y_label_area_size(0)
        .right_y_label_area_size(COLORBAR_LABEL_AREA)
        .build_cartesian_2d(0.0..1.0, v0..v1)
        .map_err(|e| e.to_string())?;
    let v_ticks = tick_formatter(v0, v1);
    bar_chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .set_tick_mark_size(LabelAreaPosition::Right, 6)
        .y_desc(plot.value_label.as_str())
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 20))
        .y_label_formatter(&v_ticks)
        .draw()
        .map_err(|e| e.to_string())?;
    const STEPS: usize = 128;
    bar_chart
        .draw_series((0..STEPS).map(|k| {
            let lo = v0 + (v1 - v0) * k as f64 / STEPS as f64;
            let hi = v0 + (v1 - v0) * (k + 1) as f64 / STEPS as f64;
            Rectangle::new([(0.0, lo), (1.0, hi)], viridis((k as f64 + 0.5) / STEPS as f64).filled())
        }))
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// The axes of a chart over `ranges` (x, y): tick labels as many as fit,
/// formatted to the range, the axis `labels` (x, y), and the grid lines
/// when `mesh` (the line plots; a field plot draws none over its points).
fn draw_axes<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    ranges: ((f64, f64), (f64, f64)),
    labels: (&str, &str),
    mesh: bool,
) -> Result<(), String> {
    let ((x0, x1), (y0, y1)) = ranges;
    let x_ticks = tick_formatter(x0, x1);
    let y_ticks = tick_formatter(y0, y1);
    let (x_count, y_count) = label_counts(chart.plotting_area().dim_in_pixel());
    let mut axes = chart.configure_mesh();
    if !mesh {
        axes.disable_mesh();
    }
    axes.x_labels(x_count)
        .y_labels(y_count)
        .x_desc(labels.0)
        .y_desc(labels.1)
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 20))
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .draw()
        .map_err(|e| e.to_string())
}

/// Maximum numbers of tick labels on the x and y axes of a plot area of
/// `pixels` (width, height), so that labels do not overlap.
fn label_counts(pixels: (u32, u32)) -> (usize, usize) {
    ((pixels.0 / 90).clamp(2, 10) as usize, (pixels.1 / 50).clamp(2, 10) as usize)
}

/// Largest magnitude an axis range reaches: plotters' tick generator loops
/// forever on a range whose width overflows to infinity, so data beyond
/// ±1e300 are clipped at the edge of the plot.
const AXIS_LIMIT: f64 = 1e300;

/// Minimum and maximum of the finite values, clamped to ±[`AXIS_LIMIT`];
/// `None` if there are no finite values.
fn finite_min_max(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).map(|v| v.clamp(-AXIS_LIMIT, AXIS_LIMIT)).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// The padding on each side of data spanning `span` with values up to
/// `magnitude`: 5 % of the span, or of the magnitude where the span is
/// below 1e-12 of it (plotters' tick generator cannot resolve that), or 1
/// where everything is zero.
fn padding(span: f64, magnitude: f64) -> f64 {
    if span > 1e-12 * magnitude {
        0.05 * span
    } else if magnitude > 0.0 {
        0.05 * magnitude
    } else {
        1.0
    }
}

/// An axis range around `min_max` with [`padding`] on each side: a
/// degenerate range (one value) is widened to ±5 % of the value, ±1 at
/// zero; no data gives 0..1.
fn padded_range(min_max: Option<(f64, f64)>) -> (f64, f64) {
    let Some((lo, hi)) = min_max else {
        return (0.0, 1.0);
    };
    let pad = padding(hi - lo, lo.abs().max(hi.abs()));
    let (a, b) = (lo - pad, hi + pad);
    if a.is_finite() && b.is_finite() {
        (a, b)
    } else {
        (lo, hi)
    }
}

/// x and y ranges containing the boxes `xs` and `ys` with equal data units
/// per pixel on both axes, for a plot area of `pixels` (width, height).
fn equal_scale_ranges(xs: Option<(f64, f64)>, ys: Option<(f64, f64)>, pixels: (f64, f64)) -> ((f64, f64), (f64, f64)) {
    let (Some(xs), Some(ys)) = (xs, ys) else {
        return ((0.0, 1.0), (0.0, 1.0));
    };
    let span = (xs.1 - xs.0).max(ys.1 - ys.0);
    let magnitude = [xs.0, xs.1, ys.0, ys.1].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let pad = padding(span, magnitude);
    let (x0, x1) = (xs.0 - pad, xs.1 + pad);
    let (y0, y1) = (ys.0 - pad, ys.1 + pad);
    let scale = ((x1 - x0) / pixels.0).max((y1 - y0) / pixels.1);
    let (xc, yc) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * scale * pixels.0, 0.5 * scale * pixels.1);
    if [xc - hx, xc + hx, yc - hy, yc + hy].iter().all(|v| v.is_finite()) {
        ((xc - hx, xc + hx), (yc - hy, yc + hy))
    } else {
        ((x0, x1), (y0, y1))
    }
}

/// `point` with both coordinates clamped to ±[`AXIS_LIMIT`], so it lies
/// inside the automatic ranges (plotters' pixel mapping overflows on points
/// far outside the range).
fn clip(point: (f64, f64)) -> (f64, f64) {
    (point.0.clamp(-AXIS_LIMIT, AXIS_LIMIT), point.1.clamp(-AXIS_LIMIT, AXIS_LIMIT))
}

/// Splits `points` into runs of consecutive finite points, [`clip`]ped.
fn finite_runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    points
        .split(|p| !(p.0.is_finite() && p.1.is_finite()))
        .filter(|run| !run.is_empty())
        .map(|run| run.iter().copied().map(clip).collect())
        .collect()
}

/// Tick-label formatter for an axis spanning `lo..hi`: fixed-point with
/// enough decimals for the tick spacing, or scientific notation when the
/// magnitudes are very large or very small.
fn tick_formatter(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let magnitude = lo.abs().max(hi.abs());
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    // Ticks are about span/10 apart: one more significant digit than that.
    let digits_below_point = (-(span / 10.0).log10()).ceil() + 1.0;
    let scientific = !(1e-3..1e5).contains(&magnitude) && magnitude > 0.0;
    let mantissa_digits = ((magnitude / span).log10().ceil() + 1.0).clamp(1.0, 15.0) as usize;
    let decimals = digits_below_point.clamp(0.0, 12.0) as usize;
    move |&v: &f64| {
        if v == 0.0 {
            "0".to_string()
        } else if scientific {
            let text = format!("{v:.mantissa_digits$e}");
            let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
            format!("{}e{exponent}", trim_zeros(mantissa))
        } else {
            trim_zeros(&format!("{v:.decimals$}")).to_string()
        }
    }
}

/// `v` for a title or a legend: at most four significant digits, trailing
/// zeros dropped (a thickness of `10.2e-3 * 1e3` reads `10.2`, not
/// `10.200000000000001`).
pub fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (3.0 - v.abs().log10().floor()).clamp(0.0, 12.0) as usize;
    trim_zeros(&format!("{v:.decimals$}")).to_string()
}

/// Removes trailing zeros after a decimal point, and the point itself.
fn trim_zeros(text: &str) -> &str {
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        text
    }
}

/// The viridis colour map at `t` in [0, 1] (clamped): linear
/// interpolation between ten samples of matplotlib's viridis.
fn viridis(t: f64) -> RGBColor {
    const SAMPLES: [(u8, u8, u8); 10] = [
        (0x44, 0x01, 0x54),
        (0x48, 0x28, 0x78),
        (0x3e, 0x4a, 0x89),
        (0x31, 0x68, 0x8e),
        (0x26, 0x82, 0x8e),
        (0x1f, 0x9e, 0x89),
        (0x35, 0xb7, 0x79),
        (0x6d, 0xcd, 0x59),
        (0xb4, 0xde, 0x2c),
        (0xfd, 0xe7, 0x25),
    ];
    let x = t.clamp(0.0, 1.0) * (SAMPLES.len() - 1) as f64;
    let i = (x.floor() as usize).min(SAMPLES.len() - 2);
    let f = x - i as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + f * (f64::from(b) - f64::from(a))).round() as u8;
    let (a, b) = (SAMPLES[i], SAMPLES[i + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_util::{scratch_dir, unwritable_path};

    /// Width and height from a PNG's IHDR chunk, after checking the
    /// signature and chunk order.
    fn png_size(path: &Path) -> (u32, u32) {
        let bytes = std::fs::read(path).unwrap();
        assert!(bytes.len() > 100, "PNG suspiciously small");
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
        assert_eq!(u32::from_be_bytes(bytes[8..12].try_into().unwrap()), 13);
        assert_eq!(&bytes[12..16], b"IHDR");
        let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        (width, height)
    }

    #[test]
    fn a_long_caption_shrinks_to_the_width_a_short_one_keeps_its_size() {
        assert_eq!(caption_size("Plug velocity", 1000), 28);
        let long = "x".repeat(120);
        let size = caption_size(&long, 1000);
        assert!(size < 28 && 0.55 * size as f64 * 120.0 <= 0.95 * 1000.0, "{size}");
        assert_eq!(caption_size(&"x".repeat(1000), 1000), 12);
    }

    fn sample_line_plot() -> LinePlot {
        LinePlot {
            title: "Plug velocity".into(),
            x_label: "time (µs)".into(),
            y_label: "velocity (m/s)".into(),
            series: vec![
                Series {
                    name: "RKPM".into(),
                    points: (0..200).map(|i| (i as f64 * 0.1, 300.0 * (-(i as f64) / 80.0).exp())).collect(),
                },
                Series {
                    name: "experiment".into(),
                    points: vec![(0.0, 300.0), (5.0, 200.0), (f64::NAN, 1.0), (15.0, 90.0)],
                },
            ],
            hlines: vec![("ballistic limit".into(), 120.0), ("zero".into(), 0.0)],
        }
    }

    #[test]
    fn the_legend_takes_the_place_the_data_leave_free() {
        let size = (0.4, 0.2);
        // A ballistic curve: held runs along the bottom, then rising to
        // the upper right; the upper left is free.
        let curve = LinePlot {
            series: vec![Series {
                name: "simulated".into(),
                points: vec![(80.0, 0.0), (120.0, 0.0), (125.0, 40.0), (200.0, 150.0), (300.0, 250.0)],
            }],
            ..LinePlot::default()
        };
        let samples = plot_samples(&curve, ((75.0, 310.0), (-10.0, 260.0)));
        assert!(samples.iter().all(|p| (0.0..=1.0).contains(&p.0) && (0.0..=1.0).contains(&p.1)));
        assert_eq!(least_covered_place(&samples, size), LegendPlace::UpperLeft);
        // A decaying history fills the upper left and the bottom; the upper
        // right is free and stays preferred.
        let samples = plot_samples(&sample_line_plot(), ((0.0, 20.0), (-15.0, 315.0)));
        assert_eq!(least_covered_place(&samples, size), LegendPlace::UpperRight);
        // One point in each upper corner, none below: the lower right.
        assert_eq!(least_covered_place(&[(0.95, 0.95), (0.05, 0.95)], size), LegendPlace::LowerRight);
        assert_eq!(least_covered_place(&[], size), LegendPlace::UpperRight);
        // A reference line across the top counts in both upper corners.
        let hline = LinePlot { hlines: vec![("limit".into(), 0.95)], ..LinePlot::default() };
        let samples = plot_samples(&hline, ((0.0, 1.0), (0.0, 1.0)));
        assert_eq!(least_covered_place(&samples, size), LegendPlace::LowerRight);
        // An energy history: a constant total along the top, recorded
        // ever more densely to the right (a shrinking time step), and the
        // projectile's energy falling from the top at the left, two
        // sparse lines along the bottom. Each line counts by its length,
        // so the upper right is the freest; counted by points, the dense
        // total would have sent the legend down over the two.
        let crowded: Vec<(f64, f64)> = (0..=400).map(|k| (1.0 - (1.0 - k as f64 / 400.0).powi(3), 1.0)).collect();
        let energy = LinePlot {
            series: vec![
                Series { name: "total".into(), points: crowded },
                Series { name: "projectile".into(), points: vec![(0.0, 1.0), (0.05, 0.5), (1.0, 0.5)] },
                Series { name: "kinetic".into(), points: vec![(0.0, 0.0), (1.0, 0.1)] },
                Series { name: "internal".into(), points: vec![(0.0, 0.0), (1.0, 0.15)] },
            ],
            ..LinePlot::default()
        };
        let samples = plot_samples(&energy, ((-0.05, 1.05), (-0.05, 1.05)));
        assert_eq!(least_covered_place(&samples, (0.4, 0.2)), LegendPlace::UpperRight);
        // With the middle free of lines, the middle of a side: nothing hidden.
        let mut energy = energy;
        energy.series[1].points = vec![(0.0, 1.0), (0.05, 0.9), (1.0, 0.9)];
        let samples = plot_samples(&energy, ((-0.05, 1.05), (-0.05, 1.05)));
        assert_eq!(least_covered_place(&samples, (0.4, 0.2)), LegendPlace::MiddleRight);
        // A lone point (an experiment) outweighs a short stretch of line.
        let dot = LinePlot {
            series: vec![
                Series { name: "a".into(), points: vec![(0.9, 0.9)] },
                Series { name: "b".into(), points: vec![(0.0, 0.9), (0.05, 0.9)] },
            ],
            ..LinePlot::default()
        };
        let samples = plot_samples(&dot, ((0.0, 1.0), (0.0, 1.0)));
        assert_eq!(least_covered_place(&samples, size), LegendPlace::LowerRight);
        let only_line = LinePlot { series: vec![dot.series[1].clone()], ..LinePlot::default() };
        assert_eq!(
            least_covered_place(&plot_samples(&only_line, ((0.0, 1.0), (0.0, 1.0))), size),
            LegendPlace::UpperRight
        );
        // The box grows with the longest entry and the number of entries.
        let (w1, h1) = legend_box_fraction(&["a"], (800.0, 500.0));
        let (w2, h2) = legend_box_fraction(&["a", "Recht-Ipson a = 0.843, p = 3.20"], (800.0, 500.0));
        assert!(w2 > w1 && h2 > h1 && w2 <= 1.0 && h2 <= 1.0, "{w1} {h1} {w2} {h2}");
    }

    #[test]
    fn line_plot_writes_png_of_requested_size() {
        let dir = scratch_dir("plot-line");
        let path = dir.join("velocity.png");
        save_line_plot(&path, &sample_line_plot()).unwrap();
        assert_eq!(png_size(&path), DEFAULT_SIZE);
        let small = dir.join("small.png");
        save_line_plot_sized(&small, &sample_line_plot(), (640, 480)).unwrap();
        assert_eq!(png_size(&small), (640, 480));
        // Only the two plots: no temporary files left.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn degenerate_line_plots_do_not_panic() {
        let dir = scratch_dir("plot-degenerate");
        let cases = [
            vec![(1.0, 1.0)],
            vec![(0.0, 0.0)],
            vec![(0.0, 5.0), (1.0, 5.0), (2.0, 5.0)],
            vec![(3.0, 0.0), (3.0, 1.0)],
            vec![(1e-20, 1e-20), (2e-20, 1e-20)],
            vec![(1e10, 1.0), (1e10 + 1e-6, 1.0 + 1e-15)],
            vec![(0.0, f64::NAN), (f64::INFINITY, 1.0)],
            // A range wider than an f64 can hold: hung plotters' tick
            // generator, then overflowed its pixel mapping, before the
            // ±AXIS_LIMIT clamp.
            vec![(0.0, -f64::MAX), (1.0, f64::MAX)],
            vec![],
        ];
        for (i, points) in cases.into_iter().enumerate() {
            let plot = LinePlot { series: vec![Series { name: format!("case {i}"), points }], ..LinePlot::default() };
            let path = dir.join(format!("case{i}.png"));
            save_line_plot(&path, &plot).unwrap();
            assert_eq!(png_size(&path), DEFAULT_SIZE);
        }
        let empty = dir.join("empty.png");
        save_line_plot(&empty, &LinePlot::default()).unwrap();
        assert_eq!(png_size(&empty), DEFAULT_SIZE);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unwritable_or_invalid_plots_return_errors() {
        let path = unwritable_path("plot.png");
        let err = save_line_plot(&path, &sample_line_plot()).unwrap_err();
        assert!(matches!(&err, PlotError::Draw { path: p, .. } if p.contains("no-such-dir")));
        let err = save_field_plot(&path, &sample_field_plot()).unwrap_err();
        assert!(matches!(err, PlotError::Draw { .. }));

        let dir = scratch_dir("plot-invalid");
        let mismatched = FieldPlot { values: vec![1.0], ..sample_field_plot() };
        let out = dir.join("f.png");
        assert!(matches!(save_field_plot(&out, &mismatched), Err(PlotError::InvalidInput { .. })));
        assert!(matches!(
            save_line_plot_sized(&out, &sample_line_plot(), (10, 10)),
            Err(PlotError::InvalidInput { .. })
        ));
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn sample_field_plot() -> FieldPlot {
        // A plate 0.1 m x 0.02 m with a stress concentration and a crack.
        let mut points = Vec::new();
        let mut values = Vec::new();
        for i in 0..100 {
            for j in 0..20 {
                let (x, y) = (i as f64 * 1e-3, j as f64 * 1e-3);
                points.push((x, y - 0.01 * (-((x - 0.05) / 0.01).powi(2)).exp()));
                values.push(1e8 + 4e8 * (-((x - 0.05) / 0.005).powi(2)).exp());
            }
        }
        values[7] = f64::NAN;
        FieldPlot {
            title: "Effective stress".into(),
            x_label: "x (m)".into(),
            y_label: "y (m)".into(),
            points,
            values,
            value_label: "σ_eq (Pa)".into(),
            value_floor: Some(0.0),
            lines: vec![vec![(0.05, 0.019), (0.052, 0.012), (0.049, 0.004)]],
        }
    }

    #[test]
    fn field_plot_writes_png_and_handles_degenerate_data() {
        let dir = scratch_dir("plot-field");
        let path = dir.join("stress.png");
        save_field_plot(&path, &sample_field_plot()).unwrap();
        assert_eq!(png_size(&path), DEFAULT_SIZE);

        let degenerate = [
            (vec![], vec![]),
            (vec![(0.0, 0.0)], vec![3.0]),
            (vec![(0.0, 0.0), (1.0, 0.0)], vec![2.0, 2.0]),
            (vec![(1.0, 1.0), (1.0, 1.0)], vec![f64::NAN, f64::INFINITY]),
            (vec![(-f64::MAX, 0.0), (f64::MAX, f64::MAX), (0.0, f64::NAN)], vec![-f64::MAX, f64::MAX, 0.0]),
        ];
        for (i, (points, values)) in degenerate.into_iter().enumerate() {
            let plot = FieldPlot { points, values, ..FieldPlot::default() };
            let path = dir.join(format!("degenerate{i}.png"));
            save_field_plot_sized(&path, &plot, (500, 400)).unwrap();
            assert_eq!(png_size(&path), (500, 400));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn equal_scale_ranges_have_equal_units_per_pixel() {
        let ((x0, x1), (y0, y1)) = equal_scale_ranges(Some((0.0, 0.1)), Some((-0.01, 0.02)), (700.0, 500.0));
        assert!(x0 <= 0.0 && x1 >= 0.1 && y0 <= -0.01 && y1 >= 0.02);
        let (sx, sy) = ((x1 - x0) / 700.0, (y1 - y0) / 500.0);
        assert!((sx - sy).abs() <= 1e-12 * sx, "{sx} {sy}");
    }

    #[test]
    fn short_numbers_for_titles() {
        assert_eq!(short_number(10.2e-3 * 1e3), "10.2");
        assert_eq!(short_number(11.1), "11.1");
        assert_eq!(short_number(173.7), "173.7");
        assert_eq!(short_number(298.0), "298");
        assert_eq!(short_number(0.000123456), "0.0001235");
        assert_eq!(short_number(-2.5), "-2.5");
        assert_eq!(short_number(0.0), "0");
    }

    #[test]
    fn tick_labels_are_short_and_distinct() {
        let f = tick_formatter(0.0, 2e-5);
        assert_eq!(f(&1.5e-5), "1.5e-5");
        assert_eq!(f(&0.0), "0");
        let f = tick_formatter(-1.0, 1.0);
        assert_eq!(f(&0.30000000000000004), "0.3");
        let f = tick_formatter(299.0, 301.0);
        assert_eq!(f(&300.25), "300.25");
        let f = tick_formatter(1e9, 1e9 + 10.0);
        assert_ne!(f(&(1e9 + 2.0)), f(&(1e9 + 4.0)));
    }

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), RGBColor(0x44, 0x01, 0x54));
        assert_eq!(viridis(1.0), RGBColor(0xfd, 0xe7, 0x25));
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
    }
}
