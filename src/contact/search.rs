//! Master-feature search: which segment (or vertex) of a rigid outline a
//! slave point is measured against, and the signed gap (SPEC §8,
//! [RL10] §3).
//!
//! Coarse to fine, with the outline placed at a given body position `x_b`
//! (the predicted one, in the contact stage):
//! 1. the nearest outline vertex, from the body's vertex grid (never a loop
//!    over all vertices);
//! 2. of the two segments meeting at that vertex, the one onto which `y`
//!    projects with parameter `λ ∈ [0, 1]`; if both qualify (inside a convex
//!    corner, or outside a concave one) the one with the larger gap, which
//!    for a convex outline is the face the point is closest to leaving
//!    through; if neither qualifies, the vertex itself with the vertex normal
//!    (see [`MasterFeature::Vertex`]).
//!
//! The gap is `g = (x − x_m)·n_m` with `x_m` a point of the feature and
//! `n_m` its outward normal; `g < 0` is penetration. It is evaluated as
//! `(x − (x_b + X_m))·n_m`, so its round-off is that of the coordinates near
//! the contact, not of the body-frame coordinates (which the one-step force
//! would amplify by `m/Δt²`).
//!
//! A slave's last pairing is reused while its local test succeeds
//! ([`check_pairing`]): the segment still takes the projection (`λ ∈ [0, 1]`)
//! and neither neighbouring segment takes it with a larger gap; a vertex
//! pairing while neither adjacent segment takes it. Reuse returns the same
//! feature as a fresh search whenever the nearest vertex is an end of the
//! reused segment; it can differ only where the nearest-vertex rule itself
//! is ambiguous (a point near a short segment far from its vertices), and
//! there it keeps the face the slave was already sliding on.
//!
//! # Deviations
//! - SPEC §8 / [RL10] ask for `0 < λ < 1`; we accept the closed interval so a
//!   slave exactly abreast of a corner (e.g. a particle column flush with
//!   the projectile's side) gets the face's gap, not the vertex's, and the
//!   gap stays continuous. Test: `search_matches_brute_force_on_random_outlines`
//!   covers both; `vertex_pairing_outside_a_convex_corner` the vertex case.
//! - The vertex normal is the normalised sum of the two segment normals.
//!   Outside a convex corner the vertex gap is then positive (no contact can
//!   be created there); inside a concave corner it pushes the slave out
//!   along the bisector.

use super::rigid::RigidBody;
use super::slave::MasterFeature;
use crate::math::{Real, Vec2};

/// The result of pairing a point with a master feature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// The feature.
    pub feature: MasterFeature,
    /// Signed gap `g = (x − x_m)·n_m`, m; negative when penetrating.
    pub gap: Real,
    /// Outward unit normal `n_m` of the feature.
    pub normal: Vec2,
}

/// Projection parameter and gap of point `x` on segment `k` of the body
/// placed at `at`.
#[inline]
fn on_segment(body: &RigidBody, at: &Vec2, k: usize, x: &Vec2) -> (Real, Real) {
    let o = body.outline();
    let a = o[k];
    let t = o[(k + 1) % o.len()] - a;
    let d = x - (at + a);
    (d.dot(&t) / t.norm_squared(), d.dot(&body.segment_normal(k)))
}

#[inline]
fn takes(lambda: Real) -> bool {
    (0.0..=1.0).contains(&lambda)
}

#[inline]
fn segment(body: &RigidBody, k: usize, gap: Real) -> Projection {
    Projection { feature: MasterFeature::Segment(k as u32), gap, normal: body.segment_normal(k) }
}

/// Fine stage: choose between the two segments at vertex `v` (module doc).
fn select_at_vertex(body: &RigidBody, at: &Vec2, v: usize, x: &Vec2) -> Projection {
    let n = body.vertex_count();
    let (kp, kn) = ((v + n - 1) % n, v);
    let (lp, gp) = on_segment(body, at, kp, x);
    let (ln, gn) = on_segment(body, at, kn, x);
    match (takes(lp), takes(ln)) {
        (true, true) if gp > gn => segment(body, kp, gp),
        (true, true) | (false, true) => segment(body, kn, gn),
        (true, false) => segment(body, kp, gp),
        (false, false) => {
            let normal = body.vertex_normal(v);
            let gap = (x - (at + body.outline()[v])).dot(&normal);
            Projection { feature: MasterFeature::Vertex(v as u32), gap, normal }
        }
    }
}

/// Pair point `x` with a feature of `body`'s outline placed at `at`: nearest
/// vertex from the vertex grid, then [`select_at_vertex`]'s rule.
pub fn search_rigid_polygon(body: &RigidBody, at: &Vec2, x: &Vec2) -> Option<Projection> {
    let (v, _) = body.vertex_grid().nearest(&(x - at))?;
    Some(select_at_vertex(body, at, v, x))
}

/// Reference for [`search_rigid_polygon`] with the nearest vertex found by an
/// O(n) loop (ties to the smallest index, as the grid). For tests.
pub fn search_rigid_polygon_brute_force(body: &RigidBody, at: &Vec2, x: &Vec2) -> Option<Projection> {
    let (v, _) = super::grid::nearest_brute_force(body.outline(), &(x - at))?;
    Some(select_at_vertex(body, at, v, x))
}

/// Local test of a previous pairing (module doc): the projection on
/// `feature` if it still holds, `None` if a fresh search is needed.
pub fn check_pairing(body: &RigidBody, at: &Vec2, feature: MasterFeature, x: &Vec2) -> Option<Projection> {
    let n = body.vertex_count();
    match feature {
        MasterFeature::Segment(k) => {
            let k = k as usize;
            if k >= n {
                return None;
            }
            let (l, g) = on_segment(body, at, k, x);
            if !takes(l) {
                return None;
            }
            for j in [(k + n - 1) % n, (k + 1) % n] {
                let (lj, gj) = on_segment(body, at, j, x);
                if takes(lj) && gj > g {
                    return None;
                }
            }
            Some(segment(body, k, g))
        }
        MasterFeature::Vertex(v) => {
            let v = v as usize;
            if v >= n {
                return None;
            }
            let p = select_at_vertex(body, at, v, x);
            matches!(p.feature, MasterFeature::Vertex(_)).then_some(p)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::rigid::rectangle_outline;

    fn rect() -> RigidBody {
        RigidBody::new("p", rectangle_outline(20.0, 80.0), Vec2::zeros(), Vec2::zeros(), 1.0).unwrap()
    }

    #[test]
    fn below_the_nose_pairs_with_the_nose() {
        let b = rect();
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(3.0, -41.0)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
        assert!((p.gap - 1.0).abs() < 1e-12);
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(-9.0, -39.5)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
        assert!((p.gap + 0.5).abs() < 1e-12);
        // inside near the corner but closer to the side: the side
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(9.8, -39.0)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(1));
        assert!((p.gap + 0.2).abs() < 1e-12);
        // flush with the side, below the nose: λ = 1 on the nose is accepted
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(10.0, -40.5)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
    }

    #[test]
    fn vertex_pairing_outside_a_convex_corner() {
        let b = rect();
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(11.0, -41.0)).unwrap();
        assert_eq!(p.feature, MasterFeature::Vertex(1));
        assert!((p.gap - 2.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Vertex(1), &Vec2::new(11.0, -41.0)).is_some());
        assert!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Vertex(1), &Vec2::new(9.0, -41.0)).is_none());
    }

    #[test]
    fn reuse_fails_when_a_neighbour_takes_over() {
        let b = rect();
        let y = Vec2::new(9.9, -39.0); // inside, 0.1 from the side, 1.0 from the nose
        assert!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Segment(0), &y).is_none());
        assert_eq!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Segment(1), &y).unwrap().feature, MasterFeature::Segment(1));
        assert!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Segment(9), &y).is_none());
    }
}
