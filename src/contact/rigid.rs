//! Rigid bodies: the master side of the contact (SPEC §8, [RL10, §3]).
//!
//! A rigid body is a closed polygon (its outline) fixed in the body frame,
//! which translates with the body: `x = position + X_body`. The body carries
//! translational degrees of freedom only. Its velocity follows the same
//! half-step central difference as the particles (SPEC §5):
//! `V ← V + Δt F/M`, `x ← x + Δt V`, unless a velocity is prescribed.
//!
//! # Deviations
//! - No rotation: the blunt projectile of [RL10, §5] hits the plate normally and
//!   stays aligned in both geometry modes (in axisymmetry it cannot rotate
//!   at all). An oblique impact would need an angular degree of freedom.

use super::grid::PointGrid;
use super::ContactError;
use crate::math::{Real, Vec2};

/// A rigid body with a polygonal outline (SPEC §8).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RigidBody {
    /// Name used in messages and output.
    pub name: String,
    /// Outline vertices in the body frame, m, counter-clockwise, closed
    /// implicitly (segment `k` runs from vertex `k` to vertex `k + 1 mod n`).
    outline: Vec<Vec2>,
    /// Outward unit normal of segment `k`.
    segment_normals: Vec<Vec2>,
    /// Outward unit normal at vertex `k`: the normalised mean of the normals
    /// of the two segments meeting there.
    vertex_normals: Vec<Vec2>,
    /// Grid over the outline vertices, in the body frame (rigid translation
    /// leaves it valid for the whole run).
    grid: PointGrid,
    /// Bounding box of the outline in the body frame, m.
    lower: Vec2,
    upper: Vec2,
    /// Translation of the body frame, m.
    pub position: Vec2,
    /// Velocity, m/s (at the half step, like the particles' `V`).
    pub velocity: Vec2,
    /// Mass, kg (per unit depth in plane strain, the whole body in
    /// axisymmetry; see [`mass_plane_strain`] and [`mass_axisymmetric`]).
    pub mass: Real,
    /// When set, the body moves at this velocity whatever the contact force
    /// (a driven punch, a fixed wall); the reaction is still reported.
    pub prescribed_velocity: Option<Vec2>,
    /// Held on the symmetry axis (axisymmetry): the radial (x) component of
    /// its velocity stays zero whatever the radial contact force, since in
    /// the r–z half section the forces on the mirrored half are missing.
    pub on_axis: bool,
}

impl RigidBody {
    /// A free rigid body. The outline is validated: at least three finite
    /// vertices, no zero-length segment, counter-clockwise (positive signed
    /// area), not self-intersecting; the mass must be positive and finite.
    pub fn new(
        name: impl Into<String>,
        outline: Vec<Vec2>,
        position: Vec2,
        velocity: Vec2,
        mass: Real,
    ) -> Result<Self, ContactError> {
        let name = name.into();
        validate_outline(&name, &outline)?;
        if !(mass.is_finite() && mass > 0.0) {
            return Err(ContactError::InvalidBodyMass { body: name, mass });
        }
        if !(position.iter().all(|c| c.is_finite()) && velocity.iter().all(|c| c.is_finite())) {
            return Err(ContactError::NonFiniteBodyState { body: name });
        }
        let n = outline.len();
        let segment_normals: Vec<Vec2> = (0..n)
            .map(|k| {
                let t = (outline[(k + 1) % n] - outline[k]).normalize();
                Vec2::new(t.y, -t.x)
            })
            .collect();
        let vertex_normals = (0..n)
            .map(|k| {
                let s = segment_normals[(k + n - 1) % n] + segment_normals[k];
                // A hairpin (antiparallel normals) cannot occur in a simple
                // polygon, but keep the result a unit vector regardless.
                s.try_normalize(1e-12).unwrap_or(segment_normals[k])
            })
            .collect();
        let mut lower = outline[0];
        let mut upper = outline[0];
        for v in &outline {
            lower = lower.inf(v);
            upper = upper.sup(v);
        }
        let perimeter: Real = (0..n).map(|k| (outline[(k + 1) % n] - outline[k]).norm()).sum();
        let grid = PointGrid::new(&outline, perimeter / n as Real)
            .ok_or_else(|| ContactError::InvalidOutline { body: name.clone(), reason: "vertex grid".into() })?;
        Ok(Self {
            name,
            outline,
            segment_normals,
            vertex_normals,
            grid,
            lower,
            upper,
            position,
            velocity,
            mass,
            prescribed_velocity: None,
            on_axis: false,
        })
    }

    /// The same body, held on the symmetry axis: no radial motion (its
    /// radial velocity is zeroed).
    pub fn held_on_axis(mut self) -> Self {
        self.on_axis = true;
        self.velocity.x = 0.0;
        self
    }

    /// The same body, driven at a prescribed velocity (also set as its
    /// current velocity).
    pub fn with_prescribed_velocity(mut self, velocity: Vec2) -> Self {
        self.prescribed_velocity = Some(velocity);
        self.velocity = velocity;
        self
    }

    /// Outline vertices in the body frame (counter-clockwise).
    pub fn outline(&self) -> &[Vec2] {
        &self.outline
    }

    /// Number of vertices (= number of segments).
    pub fn vertex_count(&self) -> usize {
        self.outline.len()
    }

    /// Outward unit normal of segment `k` (vertex `k` → vertex `k + 1`).
    pub fn segment_normal(&self, k: usize) -> Vec2 {
        self.segment_normals[k]
    }

    /// Outward unit normals of all segments.
    pub fn segment_normals(&self) -> &[Vec2] {
        &self.segment_normals
    }

    /// Outward unit normal at vertex `k` (mean of the adjacent segments').
    pub fn vertex_normal(&self, k: usize) -> Vec2 {
        self.vertex_normals[k]
    }

    /// Outline vertices in the global frame at the current position.
    pub fn outline_global(&self) -> impl Iterator<Item = Vec2> + '_ {
        self.outline.iter().map(move |v| v + self.position)
    }

    /// The grid over the outline vertices (body frame).
    pub fn vertex_grid(&self) -> &PointGrid {
        &self.grid
    }

    /// Whether the body-frame point `y` lies in the outline's bounding box
    /// (a necessary condition for being inside the body).
    #[inline]
    pub fn bounding_box_contains(&self, y: &Vec2) -> bool {
        y.x >= self.lower.x && y.x <= self.upper.x && y.y >= self.lower.y && y.y <= self.upper.y
    }

    /// Whether the body-frame point `y` is inside the body or within
    /// `reach ≥ 0` of its outline (Euclidean distance to the nearest
    /// segment; the inside by the crossing-number rule).
    pub fn within_reach(&self, y: &Vec2, reach: Real) -> bool {
        let r = Vec2::new(reach, reach);
        let (lo, hi) = (self.lower - r, self.upper + r);
        if y.x < lo.x || y.x > hi.x || y.y < lo.y || y.y > hi.y {
            return false;
        }
        let n = self.outline.len();
        let mut inside = false;
        let mut nearest = Real::INFINITY;
        for k in 0..n {
            let (a, b) = (self.outline[k], self.outline[(k + 1) % n]);
            if (a.y > y.y) != (b.y > y.y) && y.x < a.x + (y.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                inside = !inside;
            }
            let ab = b - a;
            let t = ((y - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            nearest = nearest.min((y - (a + ab * t)).norm());
        }
        inside || nearest <= reach
    }

    /// Velocity the body will have over the coming step before the contact
    /// reaction is known: the prescribed one, or the current one (the body
    /// carries no other load). Used to predict the master surface (SPEC §8).
    #[inline]
    pub fn predicted_velocity(&self) -> Vec2 {
        self.prescribed_velocity.unwrap_or(self.velocity)
    }

    /// Advance one step under the total force `force` (N) acting on it:
    /// `V ← V + Δt_v F/M`, `x ← x + Δt V` (the particles' central
    /// difference, SPEC §5, with its velocity step `Δt_v`, which differs
    /// from `Δt` on the step after a change of step); a prescribed velocity
    /// overrides `V`.
    pub fn advance(&mut self, force: Vec2, dt_velocity: Real, dt: Real) {
        self.velocity = match self.prescribed_velocity {
            Some(v) => v,
            None => self.velocity + force * (dt_velocity / self.mass),
        };
        if self.on_axis {
            self.velocity.x = 0.0;
        }
        self.position += self.velocity * dt;
    }

    /// Linear momentum `M V`, kg m/s.
    pub fn momentum(&self) -> Vec2 {
        self.velocity * self.mass
    }
}

/// Counter-clockwise rectangle of `width` (x) × `height` (y) centred on the
/// body-frame origin: the blunt projectile's section (SPEC §10: 20 × 80 mm).
/// Its nose (the face at `y = −height/2`) is segment 0.
pub fn rectangle_outline(width: Real, height: Real) -> Vec<Vec2> {
    let (a, b) = (0.5 * width, 0.5 * height);
    vec![Vec2::new(-a, -b), Vec2::new(a, -b), Vec2::new(a, b), Vec2::new(-a, b)]
}

/// Whether the interiors of two closed polygons overlap: an edge of one
/// properly crosses an edge of the other, or a vertex, an edge midpoint or
/// the vertex mean of one lies strictly inside the other. Polygons that only touch (a shared
/// edge, a vertex on an edge) do not overlap. Used to refuse bodies placed
/// inside each other at t = 0 ([`crate::contact`] assumes they start apart).
pub fn polygons_overlap(a: &[Vec2], b: &[Vec2]) -> bool {
    let scale = a.iter().chain(b).map(|v| v.amax()).fold(0.0, Real::max).max(Real::MIN_POSITIVE);
    let eps = 1e-12 * scale * scale;
    // Sign of the turn p -> q -> r, zero within round-off.
    let turn = |p: &Vec2, q: &Vec2, r: &Vec2| {
        let t = (q - p).perp(&(r - p));
        if t > eps {
            1
        } else if t < -eps {
            -1
        } else {
            0
        }
    };
    let edges = |poly: &[Vec2]| (0..poly.len()).map(|k| (poly[k], poly[(k + 1) % poly.len()])).collect::<Vec<_>>();
    let (ea, eb) = (edges(a), edges(b));
    let crossing = ea
        .iter()
        .any(|(p, q)| eb.iter().any(|(r, s)| turn(p, q, r) * turn(p, q, s) < 0 && turn(r, s, p) * turn(r, s, q) < 0));
    // Strictly inside: off every edge, with a non-zero winding number.
    let inside = |x: &Vec2, edges: &[(Vec2, Vec2)]| {
        if edges.iter().any(|(p, q)| turn(p, q, x) == 0 && (x - p).dot(&(x - q)) <= eps) {
            return false;
        }
        let winding: i32 = edges
            .iter()
            .map(|(p, q)| match (p.y <= x.y, q.y <= x.y) {
                (true, false) if turn(p, q, x) > 0 => 1,
                (false, true) if turn(p, q, x) < 0 => -1,
                _ => 0,
            })
            .sum();
        winding != 0
    };
    // Vertices, edge midpoints and the vertex mean: the midpoints find two
    // rectangles of one width stacked into each other, whose corners lie on
    // each other's sides.
    let samples = |poly: &[Vec2], edges: &[(Vec2, Vec2)]| {
        let mean = poly.iter().sum::<Vec2>() / poly.len() as Real;
        poly.iter().copied().chain(edges.iter().map(|(p, q)| 0.5 * (p + q))).chain([mean]).collect::<Vec<_>>()
    };
    crossing || samples(a, &ea).iter().any(|v| inside(v, &eb)) || samples(b, &eb).iter().any(|v| inside(v, &ea))
}

/// Signed area of a closed polygon (shoelace), m²; positive when
/// counter-clockwise.
pub fn polygon_signed_area(outline: &[Vec2]) -> Real {
    let n = outline.len();
    0.5 * (0..n).map(|k| outline[k].perp(&outline[(k + 1) % n])).sum::<Real>()
}

/// Mass per unit depth of a plane-strain section, `ρ A`, kg/m (SPEC §10:
/// in plane strain the projectile is its own 20 × 80 mm section per metre of
/// depth).
pub fn mass_plane_strain(outline: &[Vec2], density: Real) -> Result<Real, ContactError> {
    check_density(density)?;
    let area = polygon_signed_area(outline).abs();
    if !(area.is_finite() && area > 0.0) {
        return Err(ContactError::EmptyBody { area });
    }
    Ok(density * area)
}

/// Mass of the solid swept by revolving the section about the axis `x = 0`
/// (Pappus: `V = 2π ∫ r dA`), kg; the outline is given in the (r, z) frame
/// of the axisymmetric model. Only the part with `r ≥ 0` is revolved: a
/// section drawn whole, symmetric about the axis (e.g.
/// [`rectangle_outline`] centred on it), and its right half give the same
/// body.
pub fn mass_axisymmetric(outline: &[Vec2], density: Real) -> Result<Real, ContactError> {
    check_density(density)?;
    let half = clip_to_right_half_plane(outline);
    let n = half.len();
    // First moment ∫ x dA of a polygon: Σ (x_k + x_{k+1}) (x_k y_{k+1} − x_{k+1} y_k) / 6.
    let moment: Real = (0..n)
        .map(|k| {
            let (a, b) = (half[k], half[(k + 1) % n]);
            (a.x + b.x) * a.perp(&b)
        })
        .sum::<Real>()
        / 6.0;
    let volume = 2.0 * std::f64::consts::PI * moment.abs();
    if !(volume.is_finite() && volume > 0.0) {
        return Err(ContactError::EmptyBody { area: polygon_signed_area(&half).abs() });
    }
    Ok(density * volume)
}

fn check_density(density: Real) -> Result<(), ContactError> {
    if density.is_finite() && density > 0.0 {
        Ok(())
    } else {
        Err(ContactError::InvalidParameter { name: "density", value: density })
    }
}

/// Sutherland–Hodgman clip of a polygon against the half-plane `x ≥ 0`.
fn clip_to_right_half_plane(outline: &[Vec2]) -> Vec<Vec2> {
    let n = outline.len();
    let mut out = Vec::with_capacity(n + 2);
    for k in 0..n {
        let (a, b) = (outline[k], outline[(k + 1) % n]);
        let (ina, inb) = (a.x >= 0.0, b.x >= 0.0);
        if ina {
            out.push(a);
        }
        if ina != inb {
            let t = a.x / (a.x - b.x);
            out.push(Vec2::new(0.0, a.y + t * (b.y - a.y)));
        }
    }
    out
}

/// Check that an outline is a simple counter-clockwise polygon.
fn validate_outline(name: &str, outline: &[Vec2]) -> Result<(), ContactError> {
    let bad = |reason: String| ContactError::InvalidOutline { body: name.to_string(), reason };
    let n = outline.len();
    if n < 3 {
        return Err(bad(format!("{n} vertices, at least 3 needed")));
    }
    if let Some(k) = outline.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
        return Err(bad(format!("vertex {k} is not finite")));
    }
    for k in 0..n {
        if outline[(k + 1) % n] == outline[k] {
            return Err(bad(format!("segment {k} has zero length")));
        }
    }
    let area = polygon_signed_area(outline);
    if area.is_nan() || area <= 0.0 {
        return Err(bad(format!("signed area {area:e} m² is not positive: vertices must run counter-clockwise")));
    }
    // O(n²) pairwise test of non-adjacent segments: done once per body.
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing vertex
            }
            if segments_intersect(outline[i], outline[(i + 1) % n], outline[j], outline[(j + 1) % n]) {
                return Err(bad(format!("segments {i} and {j} intersect")));
            }
        }
    }
    Ok(())
}

/// Whether closed segments `ab` and `cd` share a point.
fn segments_intersect(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let o = |p: Vec2, q: Vec2, r: Vec2| (q - p).perp(&(r - p));
    let on = |p: Vec2, q: Vec2, r: Vec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    (d1 == 0.0 && on(c, d, a)) || (d2 == 0.0 && on(c, d, b)) || (d3 == 0.0 && on(a, b, c)) || (d4 == 0.0 && on(a, b, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Overlap means interiors meet: crossing, containment (also with the
    /// vertices on the other's boundary), a vertex poking in; touching along
    /// an edge or at a vertex, and a gap, are not overlaps. An L-shaped
    /// (non-convex) polygon whose notch holds the other is not overlapped.
    #[test]
    fn polygon_overlap_is_interiors_meeting() {
        let square = |x: Real, y: Real, a: Real| {
            vec![Vec2::new(x, y), Vec2::new(x + a, y), Vec2::new(x + a, y + a), Vec2::new(x, y + a)]
        };
        let unit = square(0.0, 0.0, 1.0);
        let cases = [
            (square(0.5, 0.5, 1.0), true, "corner in corner"),
            (square(0.25, 0.25, 0.5), true, "inside"),
            (square(-1.0, -1.0, 3.0), true, "around"),
            (square(0.0, 0.0, 1.0), true, "the same"),
            (square(0.0, 0.0, 0.5), true, "inside, sharing two edges"),
            (square(1.0, 0.0, 1.0), false, "sharing an edge"),
            (square(1.0, 1.0, 1.0), false, "sharing a vertex"),
            (square(1.0 + 1e-6, 0.0, 1.0), false, "a gap"),
            (
                vec![Vec2::new(0.0, -0.5), Vec2::new(1.0, -0.5), Vec2::new(1.0, 0.1), Vec2::new(0.0, 0.1)],
                true,
                "one width, stacked into it",
            ),
            (vec![Vec2::new(0.5, -0.5), Vec2::new(0.6, 0.5), Vec2::new(0.4, 0.5)], true, "a tip poking in"),
            (
                vec![Vec2::new(-0.5, 0.4), Vec2::new(1.5, 0.4), Vec2::new(1.5, 0.6), Vec2::new(-0.5, 0.6)],
                true,
                "a bar across",
            ),
        ];
        for (other, overlap, what) in cases {
            assert_eq!(polygons_overlap(&unit, &other), overlap, "{what}");
            assert_eq!(polygons_overlap(&other, &unit), overlap, "{what}, swapped");
        }
        let l_shape = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        assert!(!polygons_overlap(&l_shape, &square(1.2, 1.2, 0.5)), "in the notch");
        assert!(polygons_overlap(&l_shape, &square(0.2, 0.2, 0.5)), "in the arm");
    }

    #[test]
    fn rectangle_normals_point_outward() {
        let b = RigidBody::new("p", rectangle_outline(2.0, 4.0), Vec2::zeros(), Vec2::zeros(), 1.0).unwrap();
        assert_eq!(b.segment_normal(0), Vec2::new(0.0, -1.0)); // nose
        assert_eq!(b.segment_normal(1), Vec2::new(1.0, 0.0));
        assert_eq!(b.segment_normal(2), Vec2::new(0.0, 1.0));
        assert_eq!(b.segment_normal(3), Vec2::new(-1.0, 0.0));
        let s = 0.5f64.sqrt();
        assert!((b.vertex_normal(0) - Vec2::new(-s, -s)).norm() < 1e-15);
        assert!((b.vertex_normal(1) - Vec2::new(s, -s)).norm() < 1e-15);
    }

    #[test]
    fn invalid_outlines_are_errors() {
        let cw: Vec<Vec2> = rectangle_outline(1.0, 1.0).into_iter().rev().collect();
        let bowtie = vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        let dup = vec![Vec2::new(0.0, 0.0), Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
        for o in [cw, bowtie, dup, vec![Vec2::zeros(), Vec2::new(1.0, 0.0)]] {
            assert!(matches!(
                RigidBody::new("x", o, Vec2::zeros(), Vec2::zeros(), 1.0),
                Err(ContactError::InvalidOutline { .. })
            ));
        }
        assert!(matches!(
            RigidBody::new("x", rectangle_outline(1.0, 1.0), Vec2::zeros(), Vec2::zeros(), 0.0),
            Err(ContactError::InvalidBodyMass { .. })
        ));
    }

    #[test]
    fn advance_is_central_difference_and_prescribed_overrides() {
        let mut b = RigidBody::new("p", rectangle_outline(1.0, 1.0), Vec2::zeros(), Vec2::new(1.0, 0.0), 2.0).unwrap();
        b.advance(Vec2::new(4.0, -2.0), 0.5, 0.5);
        assert_eq!(b.velocity, Vec2::new(2.0, -0.5));
        assert_eq!(b.position, Vec2::new(1.0, -0.25));
        let mut w = b.clone().with_prescribed_velocity(Vec2::new(0.0, -3.0));
        w.advance(Vec2::new(1e9, 1e9), 0.5, 0.5);
        assert_eq!(w.velocity, Vec2::new(0.0, -3.0));
        assert_eq!(w.position, Vec2::new(1.0, -1.75));
    }
}
