//! The visibility criterion (SPEC §9, [RL10, §4]): crack segments in the
//! reference configuration are opaque to the RK sums.
//!
//! Particle `I` contributes at evaluation point `x` only if
//! 1. the straight sight line from `x` to `X_I` crosses no crack segment
//!    (each segment extended slightly beyond its split ends, see
//!    [`CrackSegments`]), and
//! 2. if `I` was created by a split, `x` lies on `I`'s own side of the
//!    crack near the vertex it was split at ([`side_allows`]). The two
//!    children of a split sit only `δ ≪ h` off the path, so near their
//!    vertex the segment test alone would decide on round-off; the side
//!    rule makes it exact there.
//!
//! Segments are binned in a uniform grid whose cell is at least the
//! largest support, so a query looks at the (at most 2 × 2) cells the
//! sight line's bounding box touches: the cost per query does not grow
//! with the number of cracks.

use super::geometry::{side_allows, sight_line_blocked};
use crate::math::{Real, Vec2};
use crate::particles::FaceSide;
use crate::shape::Visibility;
use std::collections::HashMap;

/// Opaque crack segments (extended), binned for the sight-line test.
#[derive(Clone, Default)]
pub struct CrackSegments {
    /// Extended segment end points `(a, b)`, m.
    pub segments: Vec<(Vec2, Vec2)>,
    cell: Real,
    bins: HashMap<(i64, i64), Vec<u32>>,
}

/// The bins in cell order: a `HashMap` prints in an order that differs
/// between equal maps, and tests compare whole simulations by their
/// `Debug` text.
impl std::fmt::Debug for CrackSegments {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let bins: std::collections::BTreeMap<_, _> = self.bins.iter().collect();
        f.debug_struct("CrackSegments")
            .field("segments", &self.segments)
            .field("cell", &self.cell)
            .field("bins", &bins)
            .finish()
    }
}

impl CrackSegments {
    /// Bin `segments` in cells of size `cell` (> 0, m).
    pub fn new(segments: Vec<(Vec2, Vec2)>, cell: Real) -> Self {
        let cell = if cell > 0.0 && cell.is_finite() { cell } else { 1.0 };
        let mut bins: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        for (k, (a, b)) in segments.iter().enumerate() {
            let (lo, hi) = (a.inf(b), a.sup(b));
            let (i0, j0) = Self::cell_of(cell, &lo);
            let (i1, j1) = Self::cell_of(cell, &hi);
            for i in i0..=i1 {
                for j in j0..=j1 {
                    bins.entry((i, j)).or_default().push(k as u32);
                }
            }
        }
        CrackSegments { segments, cell, bins }
    }

    #[inline]
    fn cell_of(cell: Real, p: &Vec2) -> (i64, i64) {
        ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)
    }

    /// Whether any segment blocks the sight line from `x` to `p`.
    pub fn blocked(&self, x: &Vec2, p: &Vec2) -> bool {
        if self.segments.is_empty() {
            return false;
        }
        let (lo, hi) = (x.inf(p), x.sup(p));
        let (i0, j0) = Self::cell_of(self.cell, &lo);
        let (i1, j1) = Self::cell_of(self.cell, &hi);
        for i in i0..=i1 {
            for j in j0..=j1 {
                if let Some(list) = self.bins.get(&(i, j)) {
                    for &k in list {
                        let (a, b) = &self.segments[k as usize];
                        if sight_line_blocked(a, b, x, p) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}

/// [`Visibility`] of a cracked body: the segments plus the particles'
/// crack sides (owned by the particle store).
#[derive(Clone, Copy, Debug)]
pub struct CrackVisibility<'a> {
    pub segments: &'a CrackSegments,
    /// Reference positions of the particles.
    pub x0: &'a [Vec2],
    /// Crack side of each particle (`None` if never split).
    pub face_side: &'a [Option<FaceSide>],
}

impl Visibility for CrackVisibility<'_> {
    #[inline]
    fn visible(&self, x: &Vec2, particle: usize) -> bool {
        if let Some(side) = &self.face_side[particle] {
            if !side_allows(side, x) {
                return false;
            }
        }
        !self.segments.blocked(x, &self.x0[particle])
    }
}
