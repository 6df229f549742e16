//! Geometric detection of the surface particles of a particle set, the
//! initial contact slave set (SPEC §8: "the boundary particles").
//!
//! # Criterion
//! Particle `i` is on the surface when its neighbours leave an empty angular
//! sector wider than `min_empty_sector` (default 120°). Neighbours are the
//! particles `j` with `|X_j − X_i| < c · max(h_i, h_j)` (`c` =
//! `radius_factor`, default 1.75; `h` = local spacing). Only positions and
//! spacings are used, never the generator's flags, so the same function
//! serves any particle set (and, later, the faces a crack opens).
//!
//! Why this criterion:
//! - The largest empty sector is a scale-free, purely angular quantity: it
//!   is ≤ 90° for an interior particle of any rectangular lattice (uniform,
//!   graded, or with different spacings in x and y, once the four axial
//!   neighbours are inside the radius), 180° on a straight edge, 270° at a
//!   convex corner, and above 180° on any convex boundary. On a concave
//!   boundary of radius `R` it shrinks to about `180° − 2 asin(c h / 2R)`,
//!   still ≈ 145° for a hole of radius 3h. The 120° threshold sits between
//!   the interior maximum and those surface values with a margin on both
//!   sides.
//! - The alternative, the offset of the neighbour centroid as a fraction of
//!   `h`, is sensitive to grading (a graded lattice's interior centroid is
//!   offset toward the coarse side by a fraction of `h` that grows with the
//!   grading ratio), so its threshold would depend on the generator.
//! - The pair radius `c · max(h_i, h_j)` is symmetric, so across a grading
//!   step a fine particle still sees its coarse neighbours (with `c · h_i`
//!   alone it would not, and would be mistaken for a surface particle).
//!   `c = 1.75` contains the axial neighbours with room for a grading ratio
//!   up to 1.75 between adjacent spacings and the diagonal neighbours of a
//!   square lattice (√2 ≈ 1.41), while staying below the second-neighbour
//!   distance 2h, so only the first ring of a lattice counts.
//! - Limitation: two faces closer than `c h` see each other (a fresh crack,
//!   whose faces are `2δ ≪ h` apart), so crack faces are not found here; the
//!   crack module adds them with `SlaveSet::add`.
//!
//! Tests: `surface_of_uniform_rectangle`, `surface_of_graded_rectangle`,
//! `surface_of_disc` (in `tests/contact.rs`).

use serde::{Deserialize, Serialize};

use super::grid::PointGrid;
use super::ContactError;
use crate::math::{Real, Vec2};

/// Parameters of [`detect_surface`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SurfaceDetection {
    /// Neighbour radius as a multiple of the larger local spacing of the
    /// pair, dimensionless. Default 1.75 (see the module doc).
    pub radius_factor: Real,
    /// A particle is on the surface when its neighbours leave an empty
    /// angular sector wider than this, rad. Default 2π/3 (120°).
    pub min_empty_sector: Real,
}

impl Default for SurfaceDetection {
    fn default() -> Self {
        Self { radius_factor: 1.75, min_empty_sector: 2.0 * std::f64::consts::PI / 3.0 }
    }
}

/// Indices (ascending) of the surface particles of the set `positions` with
/// local spacings `spacing` (same length). See the module doc for the
/// criterion. O(n) with a cell grid of cell `c · max h`.
pub fn detect_surface(
    positions: &[Vec2],
    spacing: &[Real],
    params: &SurfaceDetection,
) -> Result<Vec<usize>, ContactError> {
    if spacing.len() != positions.len() {
        return Err(ContactError::LengthMismatch { field: "spacing", expected: positions.len(), found: spacing.len() });
    }
    let c = params.radius_factor;
    if !(c.is_finite() && c > 0.0) {
        return Err(ContactError::InvalidParameter { name: "radius_factor", value: c });
    }
    let sector = params.min_empty_sector;
    if !(sector.is_finite() && sector > 0.0 && sector < 2.0 * std::f64::consts::PI) {
        return Err(ContactError::InvalidParameter { name: "min_empty_sector", value: sector });
    }
    if let Some(i) = spacing.iter().position(|h| !(h.is_finite() && *h > 0.0)) {
        return Err(ContactError::InvalidParticle { particle: i, field: "spacing", value: spacing[i] });
    }
    if let Some(i) = positions.iter().position(|x| !x.iter().all(|c| c.is_finite())) {
        return Err(ContactError::InvalidParticle { particle: i, field: "position", value: Real::NAN });
    }
    if positions.is_empty() {
        return Ok(Vec::new());
    }
    let h_max = spacing.iter().cloned().fold(0.0, Real::max);
    let grid = PointGrid::new(positions, c * h_max)
        .ok_or(ContactError::InvalidParameter { name: "radius_factor", value: c })?;
    let mut angles: Vec<Real> = Vec::with_capacity(32);
    let mut surface = Vec::new();
    for (i, xi) in positions.iter().enumerate() {
        angles.clear();
        grid.for_each_within(xi, c * h_max, |j, d2| {
            let r = c * spacing[i].max(spacing[j]);
            if j != i && d2 < r * r && d2 > 0.0 {
                let d = positions[j] - xi;
                angles.push(d.y.atan2(d.x));
            }
        });
        if largest_empty_sector(&mut angles) > sector {
            surface.push(i);
        }
    }
    Ok(surface)
}

/// Largest gap between consecutive directions (rad, in `[0, 2π]`); 2π when
/// there are fewer than two directions. Sorts `angles` in place.
fn largest_empty_sector(angles: &mut [Real]) -> Real {
    if angles.len() < 2 {
        return 2.0 * std::f64::consts::PI;
    }
    angles.sort_unstable_by(Real::total_cmp);
    let wrap = angles[0] + 2.0 * std::f64::consts::PI - angles[angles.len() - 1];
    angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, Real::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_sector_of_known_fans() {
        use std::f64::consts::PI;
        let mut full: Vec<Real> = (0..8).map(|k| k as Real * PI / 4.0 - PI).collect();
        assert!((largest_empty_sector(&mut full) - PI / 4.0).abs() < 1e-12);
        let mut half: Vec<Real> = (0..5).map(|k| k as Real * PI / 4.0).collect();
        assert!((largest_empty_sector(&mut half) - PI).abs() < 1e-12);
        assert_eq!(largest_empty_sector(&mut [0.3]), 2.0 * PI);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let x = [Vec2::zeros(), Vec2::new(1.0, 0.0)];
        let p = SurfaceDetection::default();
        assert!(detect_surface(&x, &[1.0], &p).is_err());
        assert!(detect_surface(&x, &[1.0, 0.0], &p).is_err());
        let bad = SurfaceDetection { min_empty_sector: 7.0, ..p };
        assert!(detect_surface(&x, &[1.0, 1.0], &bad).is_err());
        assert_eq!(detect_surface(&x, &[1.0, 1.0], &p).unwrap(), vec![0, 1]);
    }
}
