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
/// weight, body, `F`, `τ` and `P w` (their five block entries) and four
/// scalars (180 B), the step's work scratch (8 B) and the table row offset
/// (8 B), rounded up.
pub const BYTES_PER_QUADRATURE_POINT: Real = 256.0;
/// Bytes per entry of a shape table: particle index (4 B), value (8 B),
/// gradient (16 B), and for the quadrature table its gather entry (table
/// entry and point indices, 8 B, and its copies of the value and gradient,
/// 24 B; [`crate::model::Gather`]).
pub const BYTES_PER_QUADRATURE_ENTRY: Real = 60.0;
/// See [`BYTES_PER_QUADRATURE_ENTRY`]: the particle table has no gather.
pub const BYTES_PER_PARTICLE_ENTRY: Real = 28.0;
/// Factor for what the builders hold while the tables are assembled
/// (neighbour lists, per-body tables before concatenation). Measured peak
/// resident memory of `plugsim check` (`/usr/bin/time -f %M`): 80 MB for
/// `borvik-1-nofracture` (estimate now 160 MiB), 281 MB for it with 48
/// layers; a whole fine plane-strain Borvik run (cracks, output) peaked at
/// 607 MiB (`/usr/bin/time -v`) against an estimate of 799 MiB (472 MiB
/// before crack growth kept spare tables). The estimate errs high, as a
/// guard should (it was once below the run's peak, while the gather's
/// copies of `N` and `∇N` were left out).
pub const BUILD_OVERHEAD: Real = 1.5;
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
    /// larger of the build (the model times [`BUILD_OVERHEAD`]) and the run
    /// with cracks, which holds a spare copy of the tables and the gather
    /// (crack growth rewrites them into it after each split,
    /// `crate::fracture::growth`).
    pub fn bytes(&self) -> Real {
        let tables =
            self.quadrature_entries * BYTES_PER_QUADRATURE_ENTRY + self.particle_entries * BYTES_PER_PARTICLE_ENTRY;
        let model = self.particles * BYTES_PER_PARTICLE + self.quadrature_points * BYTES_PER_QUADRATURE_POINT + tables;
        (BUILD_OVERHEAD * model).max(model + tables)
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

/// Counts of a rectangular body's discretization, from its parameters alone.
///
/// Shape-table entries per row: a window of half-width `a = f h` with
/// `h = max(h_x, h_y)` covers about `2f + 1` particles along x and
/// `(2f + 1) h / h_y` rows through the thickness (at most all of them); the
/// largest `h` of the grid is used, so the count errs high where the grid
/// is graded.
pub fn estimate_grid(grid: &RectangleGrid) -> Footprint {
    let columns = estimate_columns(grid);
    let rows = grid.layers as Real;
    let h_y = grid.layer_spacing();
    let h_f = grid.fine_spacing.unwrap_or(h_y);
    let largest = grid.coarse_spacing.map_or(grid.x_max - grid.x_min, |c| c.max(h_f)).max(h_f);
    let across = 2.0 * grid.support_factor + 1.0;
    let per_row = across * rows.min(across * (largest / h_y).max(1.0));
    let gauss = grid.gauss as Real;
    let particles = columns * rows;
    let quadrature_points = gauss * gauss * (columns - 1.0).max(0.0) * (rows - 1.0).max(0.0);
    Footprint {
        particles,
        quadrature_points,
        quadrature_entries: quadrature_points * per_row,
        particle_entries: particles * per_row,
    }
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

    #[test]
    fn entry_estimate_errs_high_within_a_small_factor() {
        for g in [plate(12, 0.012, 1.1, Some(0.002), None), plate(24, 0.02, 1.03, Some(0.0006), None)] {
            let mut g = g;
            g.resolve(GeometryMode::PlaneStrain);
            let e = estimate_grid(&g);
            let model = crate::model::Model::build(
                GeometryMode::PlaneStrain,
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
            assert!(e.quadrature_entries >= nq && e.quadrature_entries < 3.0 * nq, "{} vs {nq}", e.quadrature_entries);
            assert!(e.particle_entries >= np && e.particle_entries < 3.0 * np, "{} vs {np}", e.particle_entries);
            assert!((e.particles - model.particles.len() as Real).abs() <= 0.1 * e.particles);
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
