//! Master-feature search: which segment (or vertex) of a rigid outline a
//! slave point is measured against, and the signed gap (SPEC §8,
//! [RL10, §3]).
//!
//! Coarse to fine, with the outline placed at a given body position `x_b`
//! (the predicted one, in the contact stage):
//! 1. the nearest outline vertex, from the body's vertex grid (never a loop
//!    over all vertices);
//! 2. of the two segments meeting at that vertex, the one onto which `x`
//!    projects with parameter `λ ∈ [0, 1]`; if neither qualifies, the
//!    vertex itself with the vertex normal (see [`MasterFeature::Vertex`]);
//!    if both qualify (inside a convex corner, or outside a concave one): if
//!    the point is strictly outside either face's line, the larger gap
//!    (the signed-distance rule, no contact); if it is inside both, the
//!    *entry face*, the one whose line it crossed last on its straight path
//!    from its start-of-step position `x⁰` (time of crossing
//!    `t = g⁰/(g⁰ − g)` with `g⁰ = max(0, gap at x⁰)`); where that does not
//!    decide (it was inside both already), the face it was shallower
//!    behind at `x⁰` if the depths differ by more than twice the step's
//!    displacement `|x − x⁰|` (a crack-face particle of the fine Borvik run
//!    that slid just inside the projectile's side wall, 20 mm above the
//!    nose, was paired with the nose and thrown 20 mm in one step), else
//!    the face it moves into fastest (smaller `(x − x⁰)·n`), and last the
//!    larger gap.
//!
//! The gap is `g = (x − x_m)·n_m` with `x_m` a point of the feature and
//! `n_m` its outward normal; `g < 0` is penetration. It is evaluated as
//! `(x − (x_b + X_m))·n_m`, so its round-off is that of the coordinates near
//! the contact, not of the body-frame coordinates (which the one-step force
//! would amplify by `m/Δt²`).
//!
//! A slave's last pairing is reused while its local test succeeds
//! ([`check_pairing`]): a segment while the point still projects onto it
//! (`λ ∈ [0, 1]`), a vertex while neither adjacent segment takes the
//! projection. Reuse keeps a penetrating slave on the face it crossed, and
//! the entry-face rule picks that face when the search starts with the slave
//! already inside: a particle under the projectile's nose abreast of its
//! corner is, by distance alone, as close to the side face (gap ≈ 0) as to
//! the nose, and the larger-gap rule alone would pair it with the side and
//! never push it back out (measured in `compare_spreading_on_elastic_impact`,
//! case B: 0.08 h of residual penetration at the corner columns). While the
//! slave is outside the body, reuse and a fresh search agree on a convex
//! outline (`pairing_reuse_agrees_with_fresh_search_outside`).
//!
//! # Deviations
//! - SPEC §8 / [RL10, §3] ask for `0 < λ < 1`; we accept the closed interval so a
//!   slave exactly abreast of a corner (e.g. a particle column flush with
//!   the projectile's side) gets the face's gap, not the vertex's, and the
//!   gap stays continuous. Test: `search_matches_brute_force_on_random_outlines`
//!   covers both; `vertex_pairing_outside_a_convex_corner` the vertex case.
//! - Where both segments take the projection, SPEC §8 does not say which
//!   applies; the entry-face rule above is our choice. Test:
//!   `penetrating_slave_keeps_the_face_it_crossed`.
//! - The vertex normal is the normalised sum of the two segment normals.
//!   Outside a convex corner the vertex gap is then positive (no contact can
//!   be created there); inside a concave corner it pushes the slave out
//!   along the bisector.

use super::rigid::RigidBody;
use super::slave::MasterFeature;
use crate::math::{Real, Vec2};

/// Differences of entry times (dimensionless) and of `d·n` (relative to
/// `|d|`) below which they do not decide between two faces.
const ENTRY_RESOLUTION: Real = 1e-9;

/// Inside two faces' lines at the start of the step, the shallower face is
/// chosen when the depths differ by more than this many step displacements
/// (module doc).
const DEPTH_FACTOR: Real = 2.0;

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

/// Fine stage: choose between the two segments at vertex `v` (module doc);
/// `from` is where the point was at the start of the step, relative to the
/// body placed at `at`.
fn select_at_vertex(body: &RigidBody, at: &Vec2, v: usize, x: &Vec2, from: &Vec2) -> Projection {
    let n = body.vertex_count();
    let (kp, kn) = ((v + n - 1) % n, v);
    let (lp, gp) = on_segment(body, at, kp, x);
    let (ln, gn) = on_segment(body, at, kn, x);
    match (takes(lp), takes(ln)) {
        (true, true) => {
            if entry_prefers_first(body, at, (kp, gp), (kn, gn), x, from) {
                segment(body, kp, gp)
            } else {
                segment(body, kn, gn)
            }
        }
        (false, true) => segment(body, kn, gn),
        (true, false) => segment(body, kp, gp),
        (false, false) => {
            let normal = body.vertex_normal(v);
            let gap = (x - (at + body.outline()[v])).dot(&normal);
            Projection { feature: MasterFeature::Vertex(v as u32), gap, normal }
        }
    }
}

/// Whether segment `a` rather than `b` is the face to use for a point that
/// projects onto both (module doc): larger gap if outside either line, else
/// the entry face.
fn entry_prefers_first(
    body: &RigidBody,
    at: &Vec2,
    (ka, ga): (usize, Real),
    (kb, gb): (usize, Real),
    x: &Vec2,
    from: &Vec2,
) -> bool {
    if ga > 0.0 || gb > 0.0 {
        return ga > gb;
    }
    // Both end gaps are ≤ 0 here: each crossing time lies in [0, 1].
    let time = |k: usize, g: Real| {
        let g0 = on_segment(body, at, k, from).1;
        if g0 > 0.0 {
            g0 / (g0 - g)
        } else {
            0.0
        }
    };
    let (ta, tb) = (time(ka, ga), time(kb, gb));
    if (ta - tb).abs() > ENTRY_RESOLUTION {
        return ta > tb;
    }
    let d = x - from;
    // Inside both lines already at the start: a face the point was much
    // deeper behind than it can move in a step is not the one it is
    // pressing on (a particle that slid inside a side wall, far from the
    // nose, is not 20 mm into the nose): the shallower face at the start.
    let (g0a, g0b) = (on_segment(body, at, ka, from).1, on_segment(body, at, kb, from).1);
    if (g0a - g0b).abs() > DEPTH_FACTOR * d.norm() {
        return g0a > g0b;
    }
    let (da, db) = (d.dot(&body.segment_normal(ka)), d.dot(&body.segment_normal(kb)));
    if (da - db).abs() > ENTRY_RESOLUTION * d.norm() {
        return da < db;
    }
    ga > gb
}

/// Pair point `x` with a feature of `body`'s outline placed at `at`: nearest
/// vertex from the vertex grid, then the fine rule of the module doc, for
/// which `from` is the point's start-of-step position relative to the body
/// placed at `at` (`from = x`: no history, decide by gap alone).
pub fn search_rigid_polygon(body: &RigidBody, at: &Vec2, x: &Vec2, from: &Vec2) -> Option<Projection> {
    let (v, _) = body.vertex_grid().nearest(&(x - at))?;
    Some(select_at_vertex(body, at, v, x, from))
}

/// Reference for [`search_rigid_polygon`] with the nearest vertex found by an
/// O(n) loop (ties to the smallest index, as the grid). For tests.
pub fn search_rigid_polygon_brute_force(body: &RigidBody, at: &Vec2, x: &Vec2, from: &Vec2) -> Option<Projection> {
    let (v, _) = super::grid::nearest_brute_force(body.outline(), &(x - at))?;
    Some(select_at_vertex(body, at, v, x, from))
}

/// Local test of a previous pairing (module doc): the projection on
/// `feature` if it still holds, `None` if a fresh search is needed.
/// Test: `penetrating_slave_keeps_the_face_it_crossed`.
pub fn check_pairing(body: &RigidBody, at: &Vec2, feature: MasterFeature, x: &Vec2) -> Option<Projection> {
    let n = body.vertex_count();
    match feature {
        MasterFeature::Segment(k) => {
            let k = k as usize;
            if k >= n {
                return None;
            }
            let (l, g) = on_segment(body, at, k, x);
            takes(l).then(|| segment(body, k, g))
        }
        MasterFeature::Vertex(v) => {
            let v = v as usize;
            if v >= n {
                return None;
            }
            let p = select_at_vertex(body, at, v, x, x);
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
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(3.0, -41.0), &Vec2::new(3.0, -41.0)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
        assert!((p.gap - 1.0).abs() < 1e-12);
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(-9.0, -39.5), &Vec2::new(-9.0, -39.5)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
        assert!((p.gap + 0.5).abs() < 1e-12);
        // inside near the corner but closer to the side: the side
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(9.8, -39.0), &Vec2::new(9.8, -39.0)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(1));
        assert!((p.gap + 0.2).abs() < 1e-12);
        // flush with the side, below the nose: λ = 1 on the nose is accepted
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(10.0, -40.5), &Vec2::new(10.0, -40.5)).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
    }

    #[test]
    fn vertex_pairing_outside_a_convex_corner() {
        let b = rect();
        let p = search_rigid_polygon(&b, &Vec2::zeros(), &Vec2::new(11.0, -41.0), &Vec2::new(11.0, -41.0)).unwrap();
        assert_eq!(p.feature, MasterFeature::Vertex(1));
        assert!((p.gap - 2.0 / 2f64.sqrt()).abs() < 1e-12);
        assert!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Vertex(1), &Vec2::new(11.0, -41.0)).is_some());
        assert!(check_pairing(&b, &Vec2::zeros(), MasterFeature::Vertex(1), &Vec2::new(9.0, -41.0)).is_none());
    }

    #[test]
    fn penetrating_slave_keeps_the_face_it_crossed() {
        let b = rect();
        let o = Vec2::zeros();
        // abreast of the corner, 0.5 inside through the nose: the fresh rule
        // sees the side at gap 0, the pairing from outside keeps the nose
        let y = Vec2::new(10.0, -39.5);
        assert_eq!(search_rigid_polygon(&b, &o, &y, &y).unwrap().feature, MasterFeature::Segment(1));
        // the same point found fresh, having come from below the nose: the
        // nose; having come from beside the side face: the side
        let below = Vec2::new(10.0, -40.2);
        assert_eq!(search_rigid_polygon(&b, &o, &y, &below).unwrap().feature, MasterFeature::Segment(0));
        let beside = Vec2::new(10.2, -38.0);
        let y = Vec2::new(9.9, -39.0);
        assert_eq!(search_rigid_polygon(&b, &o, &y, &beside).unwrap().feature, MasterFeature::Segment(1));
        // already inside at the start (no crossing): the motion decides
        let y = Vec2::new(9.5, -39.5);
        let from = Vec2::new(9.5, -39.6);
        assert_eq!(search_rigid_polygon(&b, &o, &y, &from).unwrap().feature, MasterFeature::Segment(0));
        let p = check_pairing(&b, &o, MasterFeature::Segment(0), &y).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(0));
        assert!((p.gap + 0.5).abs() < 1e-12);
        // inside just behind the side wall, far above the nose, moving up
        // (away from the nose, deeper behind its line): the side
        let y = Vec2::new(9.999, -20.0);
        let from = Vec2::new(9.999, -20.01);
        let p = search_rigid_polygon(&b, &o, &y, &from).unwrap();
        assert_eq!(p.feature, MasterFeature::Segment(1));
        assert!((p.gap + 0.001).abs() < 1e-9);
        // past the end of the segment the pairing is dropped
        assert!(check_pairing(&b, &o, MasterFeature::Segment(0), &Vec2::new(10.5, -39.5)).is_none());
        assert!(check_pairing(&b, &o, MasterFeature::Segment(9), &y).is_none());
    }
}
