//! Memory footprint of a discretization, estimated from the grid parameters
//! before anything is generated, and the guard that refuses a case whose
//! model cannot fit in this machine's memory.
//!
//! A case file can ask for any grid: `layers = 100000000` or
//! `fine_spacing = 1e-300` parse and validate. Generating such a grid would
//! exhaust memory (or loop for hours) before any error could be reported, so
//! `plugsim check` and `plugsim run` first count particles, quadrature points
//! and shape-function entries from the parameters alone ([`estimate_grid`]),
//! multiply by the bytes each of them costs ([`Footprint::bytes`]) and compare
//! with the memory available ([`available_memory`]).

use crate::discretize::RectangleGrid;
use crate::math::Real;

/// Bytes held per particle outside the shape tables: the particle store
/// (6 vectors, 5 scalars, body and flags: 141 B), the contact force scratch
/// (16 B), table and gather row offsets (16 B) and the per-particle arrays of
/// a VTU snapshot (displacement, velocity, projected stress and scalars:
/// about 250 B), rounded up.
pub const BYTES_PER_PARTICLE: Real = 450.0;
/// Bytes held per quadrature point outside the shape tables: position,
/// weight, cell length, body, `F`, `τ` and `P w` (their five block
/// entries) and four scalars (188 B), the step's work scratch (8 B) and the
/// table row offset (8 B), rounded up.
pub const BYTES_PER_QUADRATURE_POINT: Real = 256.0;
/// Bytes per entry of a shape table: particle index (4 B), value (8 B),
/// gradient (16 B), and for the quadrature table its gather entry (table
/// entry and point indices, 8 B, and its copies of the value and gradient,
/// 24 B; [`crate::model::Gather`]).
pub const BYTES_PER_QUADRATURE_ENTRY: Real = 60.0;
/// See [`BYTES_PER_QUADRATURE_ENTRY`]: the particle table has no gather.
pub const BYTES_PER_PARTICLE_ENTRY: Real = 28.0;
/// Factor for what the builders hold while the tables are assembled
/// (neighbour lists, per-body tables before concatenation, the worker
/// threads' allocator arenas).
///
/// With it, the estimate against the measured peak resident memory of
/// short runs (`plugsim run`, which prints both; 1–3 µs, 2 threads):
///
/// | case | shape entries (counted / built) | estimate | peak |
/// |---|---|---|---|
/// | Taylor bar, 20 × 128, axisymmetric (`tests/memory.rs`) | 188,384 / 197,703 | 28.7 MiB | 25.3 MiB |
/// | `elastic-strike` | 95,240 / 91,134 | 17.0 MiB | 15.7 MiB |
/// | `elastic-disc-axisym` | 47,452 / 45,416 | 11.5 MiB | 12.7 MiB |
/// | `borvik-1-plane-strain` (cracks) | 1,029,360 / 989,374 | 126.6 MiB | 150.6 MiB |
/// | `borvik-1-axisymmetric` (cracks) | 514,320 / 494,334 | 66.3 MiB | 84.3 MiB |
/// | `borvik-2-plane-strain-fine` (cracks) | 5,330,592 / 5,137,921 | 629.2 MiB | 676.2 MiB |
///
/// Within 30 % on every shape (−21 % to +13 %); the runs with cracks peak
/// above the estimate (crack growth, contact and conduction keep state of
/// their own). The bar's estimate was 655 MiB before the entries were
/// counted from the grid ([`count_entries`]).
pub const BUILD_OVERHEAD: Real = 1.5;
/// Resident memory of the process before any model: the binary, its
/// libraries, the thread stacks and allocator arenas of the worker pool and
/// the snapshot writer. Measured: `plugsim check` of the 468-particle
/// `elastic-disc-axisym` peaks at 9.5 MiB against a model estimate of
/// 5.4 MiB (`tests/memory.rs` checks the estimate on several shapes).
pub const PROCESS_BASE_BYTES: Real = 6.0 * 1024.0 * 1024.0;
/// Memory assumed available where `/proc/meminfo` cannot be read (other
/// operating systems, restricted containers): 16 GiB, a typical workstation.
pub const FALLBACK_AVAILABLE_BYTES: u64 = 16 << 30;
/// Largest shape-table size the solver can index: entries and particles are
/// addressed by `u32`.
pub const MAX_INDEX: Real = u32::MAX as Real;

/// Counts of one discretization, as real numbers so that absurd grids
/// (1e300 columns) are counted without overflow.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// Particles.
    pub particles: Real,
    /// Quadrature points.
    pub quadrature_points: Real,
    /// Entries of the quadrature-point shape table (`N_I(X_q)`).
    pub quadrature_entries: Real,
    /// Entries of the particle shape table (`N_J(X_I)`).
    pub particle_entries: Real,
}

impl Footprint {
    /// Estimated peak memory of building and running the model, bytes: the
    /// process's own ([`PROCESS_BASE_BYTES`]) and the larger of the build (the model times [`BUILD_OVERHEAD`]) and the run
    /// with cracks, which holds a spare copy of the tables and the gather
    /// (crack growth rewrites them into it after each split,
    /// `crate::fracture::growth`).
    pub fn bytes(&self) -> Real {
        let tables =
            self.quadrature_entries * BYTES_PER_QUADRATURE_ENTRY + self.particle_entries * BYTES_PER_PARTICLE_ENTRY;
        let model = self.particles * BYTES_PER_PARTICLE + self.quadrature_points * BYTES_PER_QUADRATURE_POINT + tables;
        PROCESS_BASE_BYTES + (BUILD_OVERHEAD * model).max(model + tables)
    }

    /// Size of a checkpoint of this model, bytes, in its postcard encoding
    /// (see `checkpoint`; integers as varints): per particle its columns
    /// (139 B), the contact force and two row offsets (24 B); per
    /// quadrature point its columns (183 B) and a row offset (4 B); per
    /// quadrature-table entry its value and gradient (24 B), its particle
    /// index and the gather's entry and point (11 B for a model of a
    /// million particles); per particle-table entry 27 B. The coarse Case I
    /// at 10 µs measured 40.3 MB; these sizes with its counts of particles,
    /// points and entries give 43.3 MB (its indices are shorter varints).
    pub fn checkpoint_bytes(&self) -> Real {
        self.particles * 163.0
            + self.quadrature_points * 187.0
            + self.quadrature_entries * 35.0
            + self.particle_entries * 27.0
    }
}

impl std::ops::Add for Footprint {
    type Output = Footprint;
    fn add(self, o: Footprint) -> Footprint {
        Footprint {
            particles: self.particles + o.particles,
            quadrature_points: self.quadrature_points + o.quadrature_points,
            quadrature_entries: self.quadrature_entries + o.quadrature_entries,
            particle_entries: self.particle_entries + o.particle_entries,
        }
    }
}

/// Number of particle columns [`RectangleGrid::columns`] will generate,
/// computed in closed form (fine zone, geometric growth, then the cap), an
/// estimate within a few columns (`column_estimate_matches_the_generator`).
/// Infinite or NaN for grids that make no sense (those fail validation).
pub fn estimate_columns(grid: &RectangleGrid) -> Real {
    let x_f = grid.refine_at.unwrap_or(0.5 * (grid.x_min + grid.x_max)).clamp(grid.x_min, grid.x_max);
    let h_f = grid.fine_spacing.unwrap_or_else(|| grid.layer_spacing());
    let cap = grid.coarse_spacing.unwrap_or(Real::INFINITY).max(h_f);
    let side = |d: Real| -> Real {
        if d.is_nan() || d <= 0.0 {
            return 0.0;
        }
        let fine = d.min(grid.fine_half_width.max(0.0));
        let n_fine = fine / h_f;
        let rest = d - fine;
        let g = grid.growth;
        let n_rest = if rest <= 0.0 {
            0.0
        } else if g <= 1.0 + 1e-12 {
            rest / h_f
        } else {
            // Spacings h_f g, h_f g², ... up to the cap, then the cap.
            let ramp = |k: Real| h_f * g * (g.powf(k) - 1.0) / (g - 1.0);
            let k_cap = if cap.is_finite() { ((cap / h_f).ln() / g.ln()).max(0.0) } else { Real::INFINITY };
            if k_cap.is_finite() && ramp(k_cap) < rest {
                k_cap + (rest - ramp(k_cap)) / cap
            } else {
                (1.0 + rest * (g - 1.0) / (h_f * g)).ln() / g.ln()
            }
        };
        n_fine + n_rest + 2.0
    };
    1.0 + side(x_f - grid.x_min) + side(grid.x_max - x_f)
}

/// Largest grid whose shape-table entries [`estimate_grid`] counts from the
/// generated column coordinates (a cheap 1D list) rather than in closed
/// form: columns and particle rows.
pub const COUNTED_GRID: (Real, Real) = (1.0e6, 2.0e4);

/// Counts of a rectangular body's discretization, from its parameters alone.
///
/// Grids up to [`COUNTED_GRID`] count their shape-table entries from the
/// column coordinates and the rows ([`count_entries`]), as the table
/// builder will find them, within a few per cent; larger grids (which the
/// guard mostly refuses) use a closed form that errs high
/// ([`closed_form_entries`]).
pub fn estimate_grid(grid: &RectangleGrid) -> Footprint {
    let columns = estimate_columns(grid);
    let rows = grid.layers as Real;
    let gauss = grid.gauss as Real;
    let quadrature_points = gauss * gauss * (columns - 1.0).max(0.0) * (rows - 1.0).max(0.0);
    if columns <= COUNTED_GRID.0 && rows <= COUNTED_GRID.1 && grid.layers >= 2 {
        let xs = grid.columns();
        let (quadrature_entries, particle_entries) = count_entries(grid, &xs);
        let n = xs.len() as Real;
        return Footprint {
            particles: n * rows,
            quadrature_points: gauss * gauss * (n - 1.0) * (rows - 1.0),
            quadrature_entries,
            particle_entries,
        };
    }
    let per_row = closed_form_entries(grid);
    Footprint {
        particles: columns * rows,
        quadrature_points,
        quadrature_entries: quadrature_points * per_row,
        particle_entries: columns * rows * per_row,
    }
}

/// Entries per shape-table row in closed form: a window of half-width
/// `a = f h` with `h = max(h_x, h_y)` covers about `2f + 1` particles along
/// x and `(2f + 1) h / h_y` rows through the thickness (at most all of
/// them), with the grid's largest column spacing for `h_x`, so the count
/// errs high where the grid is graded.
pub fn closed_form_entries(grid: &RectangleGrid) -> Real {
    let rows = grid.layers as Real;
    let h_y = grid.layer_spacing();
    let h_f = grid.fine_spacing.unwrap_or(h_y);
    let graded = grid.growth > 1.0 && grid.fine_half_width < grid.x_max - grid.x_min;
    let largest = if graded { grid.coarse_spacing.unwrap_or(grid.x_max - grid.x_min).max(h_f) } else { h_f };
    let across = 2.0 * grid.support_factor + 1.0;
    across * rows.min(across * (largest / h_y).max(1.0))
}

/// Relative width of a window's edge in [`count_entries`].
const EDGE: Real = 1e-9;

/// Entries counted from the `inner` particles strictly inside a window and
/// the `outer` ones up to its edge: those exactly on the edge (a particle
/// two spacings from another on a uniform grid with support factor 2) count
/// half. In exact arithmetic the window is zero there; with the rounding of
/// coordinate differences about half of them come in with values of order
/// 1e-16 (measured: 13.6 entries per particle row on a uniform grid, between
/// the 9 strictly inside and the 25 up to the edge).
fn edge_weighted(inner: usize, outer: usize) -> Real {
    inner as Real + 0.5 * (outer - inner) as Real
}

/// Shape-table entries `(quadrature table, particle table)` of the grid
/// with column coordinates `xs`, counted as the builder covers points.
///
/// Particle `(i, j)` has the window half-width `a_i = f max(h_x,i, h_y)`
/// ([`RectangleGrid::generate`]: the larger neighbouring gap of its column
/// and of its row; rows are uniform) and contributes to a point within
/// `a_i` of it along both axes (the tensor-product window is zero on its
/// edge, where rounding lets about half in: `edge_weighted`). So the entries of all points at one abscissa `x` are
/// `Σ_{i: |x − x_i| < a_i} Y(a_i)`, with `Y(a)` the number of
/// (point row, particle row) pairs closer than `a`, which depends on `a`
/// alone and is counted once per distinct support.
pub fn count_entries(grid: &RectangleGrid, xs: &[Real]) -> (Real, Real) {
    let (ny, h_y) = (grid.layers, grid.layer_spacing());
    let ys: Vec<Real> = (0..ny).map(|j| j as Real * h_y).collect();
    let (gp, _) = crate::discretize::gauss_legendre(grid.gauss);
    let across = |lines: &[Real]| -> Vec<Real> {
        let mut pts = Vec::with_capacity(lines.len().saturating_sub(1) * gp.len());
        for w in lines.windows(2) {
            pts.extend(gp.iter().map(|g| 0.5 * (w[0] + w[1]) + 0.5 * (w[1] - w[0]) * g));
        }
        pts
    };
    let (gauss_x, gauss_y) = (across(xs), across(&ys));
    let gap = |k: usize| {
        let left = if k > 0 { xs[k] - xs[k - 1] } else { 0.0 };
        let right = if k + 1 < xs.len() { xs[k + 1] - xs[k] } else { 0.0 };
        left.max(right)
    };
    let reach: Vec<Real> = (0..xs.len()).map(|k| grid.support_factor * gap(k).max(h_y)).collect();
    let widest = reach.iter().cloned().fold(0.0, Real::max) * (1.0 + EDGE);
    // Particle rows within `a` of each point row, summed over point rows.
    let rows_within = |points: &[Real], a: Real| -> Real {
        points
            .iter()
            .map(|&y| {
                let inner = ys.partition_point(|&yj| yj < y + a * (1.0 - EDGE))
                    - ys.partition_point(|&yj| yj <= y - a * (1.0 - EDGE));
                let outer = ys.partition_point(|&yj| yj <= y + a * (1.0 + EDGE))
                    - ys.partition_point(|&yj| yj < y - a * (1.0 + EDGE));
                edge_weighted(inner, outer)
            })
            .sum()
    };
    // Keyed by the support to nine digits: equal spacings differ in their
    // last bits once they are differences of coordinates.
    let key = |a: Real| (a / widest * 1e9).round() as u64;
    let mut memo: std::collections::HashMap<(u64, bool), Real> = std::collections::HashMap::new();
    let mut count = |points_x: &[Real], points_y: &[Real], quadrature: bool| -> Real {
        let mut total = 0.0;
        for &x in points_x {
            let lo = xs.partition_point(|&xi| xi < x - widest);
            let hi = xs.partition_point(|&xi| xi <= x + widest);
            for i in lo..hi {
                let d = (x - xs[i]).abs();
                let w =
                    edge_weighted(usize::from(d < reach[i] * (1.0 - EDGE)), usize::from(d <= reach[i] * (1.0 + EDGE)));
                if w > 0.0 {
                    total +=
                        w * *memo.entry((key(reach[i]), quadrature)).or_insert_with(|| rows_within(points_y, reach[i]));
                }
            }
        }
        total
    };
    (count(&gauss_x, &gauss_y, true), count(xs, &ys, false))
}

/// Memory available to a new process, bytes, and where the figure came
/// from: `MemAvailable` of `/proc/meminfo`, else [`FALLBACK_AVAILABLE_BYTES`].
pub fn available_memory() -> (u64, &'static str) {
    let from_proc = std::fs::read_to_string("/proc/meminfo").ok().and_then(|text| {
        text.lines().find_map(|l| {
            let rest = l.strip_prefix("MemAvailable:")?;
            let kb: u64 = rest.trim().trim_end_matches("kB").trim().parse().ok()?;
            Some(kb.saturating_mul(1024))
        })
    });
    match from_proc {
        Some(b) => (b, "MemAvailable in /proc/meminfo"),
        None => (FALLBACK_AVAILABLE_BYTES, "a fixed 16 GiB: /proc/meminfo unreadable"),
    }
}

/// Peak resident memory of this process so far, bytes (`VmHWM` of
/// `/proc/self/status`); `None` where that cannot be read. What the
/// estimate of [`Footprint::bytes`] is tested against.
pub fn peak_resident() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: u64 =
        text.lines().find_map(|l| l.strip_prefix("VmHWM:"))?.trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kb * 1024)
}

/// A discretization that cannot be built here.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MemoryError {
    #[error(
        "the discretization needs about {} of memory ({:.3e} particles, {:.3e} quadrature points, \
         {:.3e} shape-function entries; largest body '{body}') but {} is available ({origin}); \
         use fewer layers or larger fine_spacing / coarse_spacing",
        human_bytes(*.needed), .footprint.particles, .footprint.quadrature_points,
        .footprint.quadrature_entries + .footprint.particle_entries, human_bytes(*.available as Real)
    )]
    TooLarge { footprint: Footprint, needed: Real, available: u64, origin: &'static str, body: String },
    #[error(
        "body '{body}': {:.3e} shape-function entries exceed the solver's 32-bit index range ({:.3e}); \
         use fewer layers or larger spacings",
        .entries, MAX_INDEX
    )]
    IndexRange { body: String, entries: Real },
}

/// Refuse `bodies` (name and grid) if their estimated footprint exceeds
/// `available` bytes or the index range; otherwise return the footprint.
pub fn guard<'a>(
    bodies: impl IntoIterator<Item = (&'a str, &'a RectangleGrid)>,
    available: (u64, &'static str),
) -> Result<Footprint, MemoryError> {
    let mut total = Footprint::default();
    let mut largest = (String::new(), -1.0);
    let mut widest = (String::new(), 0.0);
    for (name, grid) in bodies {
        let f = estimate_grid(grid);
        if f.bytes() > largest.1 {
            largest = (name.to_string(), f.bytes());
        }
        // NaN counts (nonsense grids that validation rejects) are refused too.
        let entries = match f.quadrature_entries.max(f.particle_entries) {
            e if e.is_nan() => Real::INFINITY,
            e => e,
        };
        if entries > widest.1 {
            widest = (name.to_string(), entries);
        }
        total = total + f;
    }
    let needed = total.bytes();
    if needed.is_nan() || needed > available.0 as Real {
        return Err(MemoryError::TooLarge {
            footprint: total,
            needed,
            available: available.0,
            origin: available.1,
            body: largest.0,
        });
    }
    if widest.1 > MAX_INDEX {
        return Err(MemoryError::IndexRange { body: widest.0, entries: widest.1 });
    }
    Ok(total)
}

/// `12.3 GiB`-style size.
pub fn human_bytes(b: Real) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    if !b.is_finite() {
        return format!("{b:.3e} B");
    }
    let mut v = b;
    for u in UNITS {
        if v < 1024.0 {
            return format!("{v:.1} {u}");
        }
        v /= 1024.0;
    }
    format!("{b:.3e} B")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::GeometryMode;

    fn plate(layers: usize, half_width: Real, growth: Real, coarse: Option<Real>, fine: Option<Real>) -> RectangleGrid {
        RectangleGrid {
            x_min: -0.138,
            x_max: 0.138,
            y_min: 0.0,
            y_max: 0.0111,
            layers,
            refine_at: None,
            fine_half_width: half_width,
            fine_spacing: fine,
            column_at: None,
            growth,
            coarse_spacing: coarse,
            support_factor: 2.0,
            gauss: 2,
        }
    }

    #[test]
    fn column_estimate_matches_the_generator() {
        let grids = [
            plate(24, 0.02, 1.03, Some(0.0006), None),
            plate(12, 0.012, 1.1, Some(0.002), None),
            plate(8, 0.0, 1.0, None, None),
            plate(8, 0.0, 1.5, None, None),
            plate(48, 0.02, 1.2, Some(0.004), Some(2e-4)),
            plate(4, 1.0, 1.3, Some(0.01), None),
        ];
        for mut g in grids.into_iter().chain([{
            let mut a = plate(10, 0.01, 1.1, Some(0.003), None);
            a.x_min = 0.0;
            a.refine_at = Some(0.0);
            a
        }]) {
            g.resolve(GeometryMode::PlaneStrain);
            let actual = g.columns().len() as Real;
            let est = estimate_columns(&g);
            assert!(est >= actual - 2.0 && est <= 1.1 * actual + 6.0, "estimate {est}, actual {actual}: {g:?}");
        }
    }

    /// The counted entries are what the table builder makes (the quadrature
    /// table within 5 %, the particle table within 35 %), on a graded plate, a uniform one and a tall narrow
    /// axisymmetric bar (whose estimate was once 24 times too large: the
    /// closed form took the bar's whole width for its largest spacing).
    #[test]
    fn entry_count_matches_the_builder() {
        let mut bar = plate(128, 1.0, 1.0, None, Some(2e-4));
        (bar.x_min, bar.x_max, bar.y_max, bar.refine_at) = (0.0, 0.0038, 0.0254, Some(0.0));
        for (g, mode) in [
            (plate(12, 0.012, 1.1, Some(0.002), None), GeometryMode::PlaneStrain),
            (plate(24, 0.02, 1.03, Some(0.0006), None), GeometryMode::PlaneStrain),
            (plate(8, 0.0, 1.0, None, None), GeometryMode::PlaneStrain),
            (bar, GeometryMode::Axisymmetric),
        ] {
            let mut g = g;
            g.resolve(mode);
            let e = estimate_grid(&g);
            let model = crate::model::Model::build(
                mode,
                &[crate::model::BodySetup {
                    name: "p".into(),
                    grid: g.clone(),
                    material: crate::material::builtin("weldox_460e").unwrap(),
                    initial_velocity: vec![],
                    supports: vec![],
                }],
            )
            .unwrap();
            let (nq, np) = (model.qp_shape.nnz() as Real, model.particle_shape.nnz() as Real);
            // Gauss points never sit on a window's edge: close counts. Particles
            // do, where rounding decides ([`edge_weighted`]): looser.
            let (eq, ep) = (e.quadrature_entries / nq - 1.0, e.particle_entries / np - 1.0);
            assert!(eq.abs() < 0.05, "{} vs {nq}: {g:?}", e.quadrature_entries);
            assert!(ep.abs() < 0.35, "{} vs {np}: {g:?}", e.particle_entries);
            assert_eq!(e.particles, model.particles.len() as Real);
            assert_eq!(e.quadrature_points, model.quad.len() as Real);
            // The closed form used beyond COUNTED_GRID errs high, not low.
            let closed = closed_form_entries(&g);
            assert!(closed * e.particles >= 0.9 * np, "closed form {closed} per row, {np} entries");
        }
    }

    #[test]
    fn absurd_grids_are_refused_fast() {
        let mut g = plate(24, 0.02, 1.03, Some(0.0006), Some(1e-300));
        g.resolve(GeometryMode::PlaneStrain);
        let err = guard([("plate", &g)], (1 << 34, "test")).unwrap_err().to_string();
        assert!(err.contains("available") && err.contains("plate"), "{err}");
        let g = plate(5000, 0.02, 1.03, Some(0.0006), None);
        let err = guard([("plate", &g)], (u64::MAX, "test")).unwrap_err().to_string();
        assert!(err.contains("32-bit index range"), "{err}");
        let g = plate(100_000, 0.02, 1.03, Some(0.0006), None);
        let err = guard([("plate", &g)], (1 << 34, "test")).unwrap_err().to_string();
        assert!(err.contains("plate") && err.contains("available"), "{err}");
        let g = plate(24, 0.02, 1.03, Some(0.0006), None);
        let f = guard([("plate", &g)], (1 << 34, "test")).unwrap();
        assert!(f.particles > 10_000.0 && f.particles < 13_000.0);
        assert!(guard([("plate", &g)], (1 << 20, "test")).is_err());
    }

    #[test]
    fn human_sizes() {
        assert_eq!(human_bytes(512.0), "512.0 B");
        assert_eq!(human_bytes(3.0 * 1024.0 * 1024.0 * 1024.0), "3.0 GiB");
        assert!(human_bytes(Real::INFINITY).contains("inf"));
    }
}
