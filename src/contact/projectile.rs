//! Projectiles by nose shape: blunt, hemispherical, conical and ogival
//! (SPEC §8, §10), as the polygonal outlines of the rigid master surface.
//!
//! A projectile is a cylinder of diameter `D = 2R` and overall length `L`
//! (tip to back face) ending in a nose of length `L_n < L`:
//! - blunt: a flat face, `L_n = 0`; or a flat face whose edge is rounded
//!   by a quarter circle of radius `r_e < R` onto the shank, `L_n = r_e`
//!   (machined projectiles have one; docs/validation.md, "A rounded
//!   projectile edge", measures what it does to the ballistic limits);
//! - hemispherical: a half sphere of the shank's radius, `L_n = R`;
//! - conical: a cone of length `L_n` (or of included apex angle `α`,
//!   `L_n = R / tan(α/2)`), sharp at the tip;
//! - ogival: a tangent ogive of calibre-radius-head `ψ` (CRH): its arcs
//!   have radius `ρ = ψ D`, meet the shank tangentially and the axis at the
//!   tip, `L_n = R √(4ψ − 1)`; `ψ = ½` is the hemisphere.
//!
//! The body frame has the tip at the origin and the axis along y; the nose
//! points along −y (onto a plate below it, as in every case; the bodies
//! translate only, see [`super::rigid`]).
//!
//! # The outline: the full section in both geometry modes
//! The outline is the projectile's full section through its axis,
//! symmetric about `x = 0`, counter-clockwise from the tip. In plane strain
//! that is the body; in axisymmetry the particles all lie at `r ≥ 0` and
//! only the right half ever meets them, while the mass of revolution
//! ([`super::mass_axisymmetric`]) revolves only `r ≥ 0`. The half section
//! alone would add a false master face along the axis whose corner at the
//! tip tilts the vertex normal there by up to 45° (a particle on the axis
//! under a conical tip would be pushed sideways against its axis
//! condition); the full section makes the tip a symmetric vertex with the
//! exact normal −y. The existing rectangles of the axisymmetric cases are
//! drawn whole for the same reason.
//!
//! # Curved noses are polygons (the resolution rule)
//! Hemispherical and ogival noses are inscribed polygons: vertices on the
//! exact arc, equal angular steps, the tip a vertex. Each arc of radius `r`
//! and turning angle `θ` gets `n = max(⌈r θ / s⌉, ⌈θ / 2°⌉)` segments with
//! `s = h/4`, `h` the smallest particle spacing of the deformable bodies
//! ([`nose_segment_length`]). Then the facets lie within `s²/(8r)` of the
//! true surface (0.2 µm for `h` = 0.5 mm on a 10 mm nose, 4·10⁻⁴ h), the
//! normal turns by at most `s/r` (0.7°) from one facet to the next, and a
//! slave sliding one spacing over the nose crosses about four vertices, so
//! the contact normal it sees follows the analytic one within that turn.
//! Analytic curved masters were the alternative; they would need their own
//! search, gap and pairing cache beside the polygon's, for a difference far
//! below the particle spacing. Straight faces (the flat nose, the cone, the
//! shank) are single segments: exact, and their vertices stay the nearest
//! ones to a point beside them, as the vertex search needs ([`super::search`]).

use crate::math::{Real, Vec2};

/// The smallest angular resolution of a curved nose: at most this turn,
/// degrees, between consecutive facets (module doc).
pub const MAX_FACET_TURN_DEG: Real = 2.0;

/// Facet length for the curved noses over the particle spacing (module doc).
pub const FACET_PER_SPACING: Real = 0.25;

/// A nose shape with its parameters resolved (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NoseShape {
    /// Flat face, its edge rounded onto the shank by a quarter circle of
    /// this radius, m (0: a sharp edge).
    Blunt { edge_radius: Real },
    /// Half sphere of the shank's radius.
    Hemispherical,
    /// Cone of this length, m.
    Conical { nose_length: Real },
    /// Tangent ogive of this calibre-radius-head (ogive radius over
    /// diameter), ≥ ½.
    Ogival { caliber_radius_head: Real },
}

/// A projectile: shank diameter and overall length, m, and its nose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projectile {
    pub diameter: Real,
    pub length: Real,
    pub nose: NoseShape,
}

/// Most facets on one nose arc: 20,000 facets put a 10 mm hemisphere
/// within 0.2 nm of its surface. A case whose particle spacing would ask
/// for more (spacings below about 3 µm on a 20 mm nose) is refused by the
/// memory guard anyway; the cap keeps its validation from building an
/// outline of unbounded size first (found by `tests/robustness.rs`'s fuzz).
pub const MAX_ARC_FACETS: Real = 20_000.0;

/// The facet length of curved noses for particles of smallest spacing `h`:
/// `h/4` (module doc).
pub fn nose_segment_length(h: Real) -> Real {
    FACET_PER_SPACING * h
}

/// The length of a cone of radius `radius` and included apex angle
/// `apex_deg` (degrees, in (0, 180)): `r / tan(α/2)`.
pub fn cone_length(radius: Real, apex_deg: Real) -> Real {
    radius / (0.5 * apex_deg.to_radians()).tan()
}

impl Projectile {
    /// Shank radius, m.
    pub fn radius(&self) -> Real {
        0.5 * self.diameter
    }

    /// Length of the nose from the tip to the shank, m.
    pub fn nose_length(&self) -> Real {
        let r = self.radius();
        match self.nose {
            NoseShape::Blunt { edge_radius } => edge_radius,
            NoseShape::Hemispherical => r,
            NoseShape::Conical { nose_length } => nose_length,
            NoseShape::Ogival { caliber_radius_head } => r * (4.0 * caliber_radius_head - 1.0).sqrt(),
        }
    }

    /// Radius of the curved nose's arcs, m (`None` for a sharp-edged flat
    /// nose and for conical ones).
    pub fn arc_radius(&self) -> Option<Real> {
        match self.nose {
            NoseShape::Hemispherical => Some(self.radius()),
            NoseShape::Ogival { caliber_radius_head } => Some(caliber_radius_head * self.diameter),
            NoseShape::Blunt { edge_radius } if edge_radius > 0.0 => Some(edge_radius),
            NoseShape::Blunt { .. } | NoseShape::Conical { .. } => None,
        }
    }

    /// Whether the nose has a flat face through the axis (blunt).
    pub fn is_flat(&self) -> bool {
        matches!(self.nose, NoseShape::Blunt { .. })
    }

    /// The nose's outline `depth` (m) behind its tip, `(r, dr/dz)`: its
    /// radius there and its slope (one evaluation for
    /// [`Projectile::contact_radius`] and [`Projectile::edge_speed_ratio`]);
    /// the shank's radius and 0 behind the nose; `None` for a flat nose.
    fn outline_at(&self, depth: Real) -> Option<(Real, Real)> {
        let (r, ln) = (self.radius(), self.nose_length());
        match self.nose {
            NoseShape::Blunt { .. } => None,
            _ if depth >= ln => Some((r, 0.0)),
            NoseShape::Conical { nose_length } => Some((r * depth.max(0.0) / nose_length, r / nose_length)),
            NoseShape::Hemispherical | NoseShape::Ogival { .. } => {
                // The arc centred on the shoulder's level, `ln` behind the
                // tip, `s` ahead of its centre.
                let rho = self.arc_radius().expect("a curved nose");
                let s = ln - depth.max(0.0);
                let root = (rho * rho - s * s).max(0.0).sqrt();
                Some((r - rho + root, if root > 0.0 { s / root } else { Real::INFINITY }))
            }
        }
    }

    /// How fast the edge of contact runs out over a flat face the nose has
    /// entered by `depth` (m, from its tip), as a multiple of the
    /// projectile's speed: the slope `dr/dz` of the nose's profile there,
    /// the face's own motion neglected. A hemisphere of radius `R` gives
    /// `(R − δ)/√(2Rδ − δ²)` (about `R/a` with `a` the contact radius),
    /// unbounded at the first touch; a cone `R/L_n`; 0 on the shank.
    /// `None` for a flat nose, whose face meets the plate all at once.
    pub fn edge_speed_ratio(&self, depth: Real) -> Option<Real> {
        self.outline_at(depth).map(|(_, slope)| slope)
    }

    /// The radius of the nose's outline `depth` (m) behind its tip: the
    /// radius out to which it touches a flat face it has entered that deep
    /// (the face's own motion neglected); the shank's radius behind the
    /// nose. `None` for a flat nose, which touches its whole face at once.
    pub fn contact_radius(&self, depth: Real) -> Option<Real> {
        self.outline_at(depth).map(|(radius, _)| radius)
    }

    /// The fastest a particle can be thrown by this nose entering a flat
    /// face at `speed` (m/s), `depth` (m) deep: twice the larger of the
    /// speed and the contact edge's speed ([`Projectile::edge_speed_ratio`]).
    /// Twice the speed is the free-surface doubling of an impact's wave;
    /// under a rounded nose the edge of contact runs out faster than the
    /// projectile at first, and a collision point that runs subsonically
    /// throws the material ahead of it as a jet, which in steady jet
    /// theory leaves at the speed the material enters the collision point,
    /// so at no more than twice the edge's speed in the plate's frame
    /// (Walsh, Shreffler & Willig, J. Appl. Phys. 24, 1953;
    /// docs/validation.md, "Three throws traced with
    /// `output.trace_particles`").
    pub fn jet_speed_bound(&self, speed: Real, depth: Real) -> Real {
        2.0 * speed * self.edge_speed_ratio(depth).map_or(1.0, |k| k.max(1.0))
    }

    /// The right half of the section (`x ≥ 0`), from the tip on the axis
    /// along the nose and the shank to the back face's corner `(R, L)`, in
    /// the body frame (tip at the origin, nose toward −y). Curved noses are
    /// faceted with segments of at most `facet` metres (see
    /// [`nose_segment_length`]) and turns of at most
    /// [`MAX_FACET_TURN_DEG`].
    pub fn profile(&self, facet: Real) -> Vec<Vec2> {
        let (r, l, ln) = (self.radius(), self.length, self.nose_length());
        let mut p = Vec::new();
        match self.arc_radius() {
            None => {
                p.push(Vec2::zeros());
                if ln == 0.0 {
                    // blunt: the face is the segment from the axis to the rim
                    p.push(Vec2::new(r, 0.0));
                } else {
                    p.push(Vec2::new(r, ln));
                }
            }
            Some(rho) => {
                // Arc centred at (R − ρ, L_n) from the tip (angle −θ) to the
                // shoulder (angle 0), where it meets the shank tangentially;
                // a rounded flat face runs from the axis to the arc's start
                // (R − r_e, 0), the arc a quarter circle (θ = 90°).
                let centre = Vec2::new(r - rho, ln);
                let start = if self.is_flat() {
                    p.push(Vec2::zeros());
                    Vec2::new(r - rho, 0.0)
                } else {
                    Vec2::zeros()
                };
                let theta = (ln / rho).clamp(-1.0, 1.0).asin();
                let by_length = (rho * theta / facet).ceil();
                let by_turn = (theta / MAX_FACET_TURN_DEG.to_radians()).ceil();
                let n = by_length.max(by_turn).clamp(1.0, MAX_ARC_FACETS) as usize;
                for k in 0..=n {
                    let a = -theta * (1.0 - k as Real / n as Real);
                    p.push(if k == 0 { start } else { centre + Vec2::new(a.cos(), a.sin()) * rho });
                }
                // the shoulder exactly (no round-off off the shank line)
                *p.last_mut().expect("n >= 1") = Vec2::new(r, ln);
            }
        }
        p.push(Vec2::new(r, l));
        p
    }

    /// The closed counter-clockwise outline of the full section (module
    /// doc): the profile, then its mirror image `x → −x` back to the tip.
    pub fn outline(&self, facet: Real) -> Vec<Vec2> {
        let half = self.profile(facet);
        let mut o = half.clone();
        // Mirror, skipping vertices on the axis (the tip of a pointed or
        // curved nose; a blunt face starts at the axis too, so its mirrored
        // rim closes the face).
        o.extend(half.iter().rev().filter(|v| v.x != 0.0).map(|v| Vec2::new(-v.x, v.y)));
        // The blunt face's axis point lies inside the face segment: drop it.
        if self.is_flat() {
            o.remove(0);
        }
        o
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The contact edge's speed is the slope of the nose's own outline: a
    /// central difference of the radius along the faceted profile (the
    /// geometry the contact uses, at a fine facet) at depths through each
    /// nose, against [`Projectile::edge_speed_ratio`]; the closed forms of
    /// the hemisphere and the cone; no edge speed for a flat face, none on
    /// the shank; and the jet bound never under the free-surface doubling.
    #[test]
    fn the_contact_edge_runs_out_at_the_profiles_slope() {
        let radius_at = |p: &Projectile, z: Real| -> Real {
            let prof = p.profile(1e-7);
            let k = prof.windows(2).position(|w| w[0].y <= z && z <= w[1].y).expect("on the profile");
            let (a, b) = (prof[k], prof[k + 1]);
            a.x + (b.x - a.x) * (z - a.y) / (b.y - a.y)
        };
        for p in shapes().iter().filter(|p| !p.is_flat()) {
            let ln = p.nose_length();
            for f in [0.1, 0.3, 0.5, 0.7, 0.9] {
                let (z, dz) = (f * ln, 1e-3 * ln);
                let slope = (radius_at(p, z + dz) - radius_at(p, z - dz)) / (2.0 * dz);
                let a = p.contact_radius(z).unwrap();
                assert!((a - radius_at(p, z)).abs() <= 1e-6 * p.radius(), "{:?} at {f}: {a}", p.nose);
                let k = p.edge_speed_ratio(z).unwrap();
                assert!((k - slope).abs() <= 2e-3 * slope.max(1e-3), "{:?} at {f}: {k} vs {slope}", p.nose);
                assert!(
                    p.jet_speed_bound(300.0, z) >= 600.0
                        && (p.jet_speed_bound(300.0, z) - 600.0 * k.max(1.0)).abs() < 1e-9
                );
            }
            assert_eq!(p.edge_speed_ratio(ln), Some(0.0), "the shank");
        }
        let hemi = Projectile { diameter: D, length: L, nose: NoseShape::Hemispherical };
        let (r, d) = (0.5 * D, 0.3e-3);
        let exact = (r - d) / (2.0 * r * d - d * d).sqrt();
        assert!((hemi.edge_speed_ratio(d).unwrap() - exact).abs() <= 1e-12 * exact);
        assert_eq!(hemi.edge_speed_ratio(0.0), Some(Real::INFINITY));
        let cone = Projectile { nose: NoseShape::Conical { nose_length: 2.0 * D }, ..hemi };
        assert!((cone.edge_speed_ratio(0.5 * D).unwrap() - 0.25).abs() < 1e-15);
        assert_eq!(cone.jet_speed_bound(300.0, 0.5 * D), 600.0, "a slender cone: the doubling");
        let blunt = Projectile { nose: NoseShape::Blunt { edge_radius: 0.0 }, ..hemi };
        assert_eq!((blunt.edge_speed_ratio(1e-4), blunt.jet_speed_bound(300.0, 1e-4)), (None, 600.0));
        assert_eq!((blunt.contact_radius(1e-4), hemi.contact_radius(2.0 * D)), (None, Some(0.5 * D)));
    }
    use crate::contact::{mass_axisymmetric, mass_plane_strain, search_rigid_polygon, RigidBody};
    use std::f64::consts::PI;

    const D: Real = 0.02;
    const L: Real = 0.08;
    const H: Real = 0.0005; // a particle spacing

    fn shapes() -> Vec<Projectile> {
        [
            NoseShape::Blunt { edge_radius: 0.0 },
            NoseShape::Blunt { edge_radius: 0.1 * D },
            NoseShape::Hemispherical,
            NoseShape::Conical { nose_length: cone_length(0.5 * D, 60.0) },
            NoseShape::Ogival { caliber_radius_head: 3.0 },
        ]
        .into_iter()
        .map(|nose| Projectile { diameter: D, length: L, nose })
        .collect()
    }

    /// Exact section area, volume of revolution, and the y of the centroid
    /// of each (from the tip) of cylinder + nose: the nose's half-section
    /// area `a`, its first moment `∫ y dA` over the half, its volume and
    /// `∫ y dV` in closed form.
    fn exact(p: &Projectile) -> (Real, Real, Real, Real) {
        let (r, l, ln) = (p.radius(), p.length, p.nose_length());
        // The same four of a nose of radius profile f over [0, L_n] by
        // Simpson's rule (fine enough to be exact to 1e-7 even where f has a
        // vertical tangent).
        let simpson = |f: &dyn Fn(Real) -> Real| {
            let n = 200_000;
            let mut sums = [0.0; 4];
            for k in 0..=n {
                let y = ln * k as Real / n as Real;
                let w = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let r = f(y);
                for (s, term) in sums.iter_mut().zip([r, y * r, PI * r * r, y * PI * r * r]) {
                    *s += w * term;
                }
            }
            sums.map(|s| s * ln / n as Real / 3.0)
        };
        // nose: (half area, half ∫ y dA, volume, ∫ y dV)
        let (a, ay, v, vy) = match p.nose {
            NoseShape::Blunt { edge_radius: 0.0 } => (0.0, 0.0, 0.0, 0.0),
            NoseShape::Blunt { edge_radius: e } => {
                // r(y) = R − e + √(e² − (e − y)²); area and volume in closed
                // form (a quarter disc; Pappus), the moments by Simpson.
                let f = |y: Real| r - e + (e * e - (e - y).powi(2)).max(0.0).sqrt();
                let [_, ay, _, vy] = simpson(&f);
                let a = (r - e) * e + 0.25 * PI * e * e;
                let v = PI * ((r - e).powi(2) * e + 0.5 * PI * (r - e) * e * e + 2.0 / 3.0 * e.powi(3));
                (a, ay, v, vy)
            }
            NoseShape::Hemispherical => (
                0.25 * PI * r * r,
                0.25 * PI * r * r * (r - 4.0 * r / (3.0 * PI)),
                2.0 / 3.0 * PI * r.powi(3),
                2.0 / 3.0 * PI * r.powi(3) * (r - 3.0 * r / 8.0),
            ),
            NoseShape::Conical { nose_length: h } => {
                (0.5 * r * h, 0.5 * r * h * (2.0 * h / 3.0), PI * r * r * h / 3.0, PI * r * r * h / 3.0 * (0.75 * h))
            }
            NoseShape::Ogival { caliber_radius_head } => {
                // r(y) = √(ρ² − (L_n − y)²) − c, c = ρ − R; s = L_n − y.
                let rho = caliber_radius_head * D;
                let c = rho - r;
                let t = (ln / rho).asin();
                let a = 0.5 * rho * rho * t - 0.5 * ln * c;
                let v = PI * (rho * rho * ln - ln.powi(3) / 3.0 - c * rho * rho * t);
                // first moments by Simpson on the analytic profile
                let f = |y: Real| ((rho * rho - (ln - y).powi(2)).max(0.0)).sqrt() - c;
                let [_, ay, _, vy] = simpson(&f);
                (a, ay, v, vy)
            }
        };
        let shank = l - ln;
        let area = 2.0 * (a + r * shank);
        let area_y = 2.0 * (ay + r * shank * 0.5 * (l + ln));
        let volume = v + PI * r * r * shank;
        let volume_y = vy + PI * r * r * shank * 0.5 * (l + ln);
        (area, area_y / area, volume, volume_y / volume)
    }

    /// Section area and y-centroid of a closed polygon (shoelace moments).
    fn polygon_area_centroid(o: &[Vec2]) -> (Real, Real) {
        let n = o.len();
        let (mut a, mut my) = (0.0, 0.0);
        for k in 0..n {
            let (p, q) = (o[k], o[(k + 1) % n]);
            let c = p.perp(&q);
            a += 0.5 * c;
            my += (p.y + q.y) * c / 6.0;
        }
        (a, my / a)
    }

    /// Volume and y-centroid of the solid swept by the profile (frusta).
    fn revolved_volume_centroid(profile: &[Vec2]) -> (Real, Real) {
        let (mut v, mut vy) = (0.0, 0.0);
        for w in profile.windows(2) {
            let (a, b) = (w[0], w[1]);
            let h = b.y - a.y;
            // frustum between radii a.x and b.x over [a.y, b.y]: π∫ r² dy, π∫ y r² dy
            let (r0, r1) = (a.x, b.x);
            let dv = PI * h * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
            // ∫ y r(y)² dy with r linear: Simpson is exact for cubics
            let mid = 0.5 * (r0 + r1);
            let dvy = PI * h / 6.0 * (a.y * r0 * r0 + 4.0 * 0.5 * (a.y + b.y) * mid * mid + b.y * r1 * r1);
            v += dv;
            vy += dvy;
        }
        // the back face closes the solid on the axis: no volume
        (v, vy / v)
    }

    #[test]
    fn outlines_are_valid_symmetric_and_start_at_the_tip() {
        for p in shapes() {
            let o = p.outline(nose_segment_length(H));
            let body = RigidBody::new("p", o.clone(), Vec2::zeros(), Vec2::zeros(), 1.0)
                .unwrap_or_else(|e| panic!("{p:?}: {e}"));
            let lowest = o.iter().map(|v| v.y).fold(Real::INFINITY, Real::min);
            assert_eq!(lowest, 0.0, "{p:?}: the tip is the lowest point");
            let top = o.iter().map(|v| v.y).fold(Real::NEG_INFINITY, Real::max);
            assert!((top - L).abs() < 1e-15 && o.iter().all(|v| v.x.abs() <= 0.5 * D + 1e-15));
            for v in &o {
                assert!(o.iter().any(|w| (w - Vec2::new(-v.x, v.y)).norm() < 1e-15), "{p:?}: not symmetric at {v:?}");
            }
            if !p.is_flat() {
                // the tip is a vertex with the exact normal −y
                let k = o.iter().position(|v| v.norm() == 0.0).unwrap();
                assert!((body.vertex_normal(k) - Vec2::new(0.0, -1.0)).norm() < 1e-12, "{p:?}");
            }
            // facets within the rule: length ≤ h/4 and turn ≤ 2° on the curved noses
            if let Some(rho) = p.arc_radius() {
                let half = p.profile(nose_segment_length(H));
                // the arc: not the shank, nor a rounded flat face
                let arc = &half[usize::from(p.is_flat())..half.len() - 1];
                for w in arc.windows(2) {
                    let s = (w[1] - w[0]).norm();
                    assert!(s <= nose_segment_length(H) * (1.0 + 1e-12), "{p:?}: facet {s}");
                    assert!(s / rho <= MAX_FACET_TURN_DEG.to_radians() * (1.0 + 1e-9));
                }
            }
        }
    }

    #[test]
    fn area_volume_and_centroids_match_the_analytic_solids() {
        for p in shapes() {
            let (area, ya, volume, yv) = exact(&p);
            let o = p.outline(nose_segment_length(H));
            let (pa, pya) = polygon_area_centroid(&o);
            let (pv, pyv) = revolved_volume_centroid(&p.profile(nose_segment_length(H)));
            // inscribed facets lose at most the sagitta s²/(8ρ) over the nose
            // surface: relative 1e-5 here; the flat and conical noses are exact
            let tol = if p.arc_radius().is_some() { 1e-5 } else { 1e-12 };
            assert!((pa / area - 1.0).abs() < tol, "{p:?}: area {pa:e} vs {area:e}");
            assert!((pv / volume - 1.0).abs() < tol, "{p:?}: volume {pv:e} vs {volume:e}");
            assert!((pya - ya).abs() < tol * L, "{p:?}: section centroid {pya} vs {ya}");
            assert!((pyv - yv).abs() < tol * L, "{p:?}: solid centroid {pyv} vs {yv}");
            // and the masses the case builds from a density use the same solid
            let rho = 7850.0;
            let ms = mass_plane_strain(&o, rho).unwrap();
            let ma = mass_axisymmetric(&o, rho).unwrap();
            assert!((ms / (rho * area) - 1.0).abs() < tol, "{p:?}: plane-strain mass");
            assert!((ma / (rho * volume) - 1.0).abs() < tol, "{p:?}: axisymmetric mass");
        }
        // the hemisphere is the ogive of CRH 1/2
        let hemi = Projectile { diameter: D, length: L, nose: NoseShape::Hemispherical };
        let ogive = Projectile { nose: NoseShape::Ogival { caliber_radius_head: 0.5 }, ..hemi };
        assert_eq!(hemi.profile(1e-4), ogive.profile(1e-4));
    }

    /// A point near the curved or conical nose pairs with a facet whose
    /// normal is the analytic surface normal within one facet turn, and its
    /// gap is the analytic signed distance within the sagitta.
    #[test]
    fn contact_normal_and_gap_follow_the_analytic_nose() {
        let s = nose_segment_length(H);
        for p in shapes().into_iter().filter(|p| p.nose != NoseShape::Blunt { edge_radius: 0.0 }) {
            let body = RigidBody::new("p", p.outline(s), Vec2::zeros(), Vec2::zeros(), 1.0).unwrap();
            let (r, ln) = (p.radius(), p.nose_length());
            let mut checked = 0;
            for i in 1..40 {
                for d in [-0.2 * H, -0.05 * H, 0.05 * H, 0.3 * H] {
                    // a surface point, its analytic outward normal and the point at distance d
                    let (surface, normal, turn) = match p.arc_radius() {
                        Some(rho) => {
                            let theta = (ln / rho).asin();
                            let a = -theta * (1.0 - i as Real / 40.0);
                            let n = Vec2::new(a.cos(), a.sin());
                            (Vec2::new(r - rho, ln) + n * rho, n, s / rho)
                        }
                        None => {
                            let t = Vec2::new(r, ln).normalize();
                            (Vec2::new(r, ln) * (i as Real / 40.0), Vec2::new(t.y, -t.x), 1e-12)
                        }
                    };
                    let x = surface + normal * d;
                    let pr = search_rigid_polygon(&body, &Vec2::zeros(), &x, &x).unwrap();
                    let angle = pr.normal.perp(&normal).abs().atan2(pr.normal.dot(&normal));
                    assert!(angle <= turn, "{p:?} at {x:?}: normal off by {:.3} deg", angle.to_degrees());
                    let sagitta = match p.arc_radius() {
                        Some(rho) => s * s / (8.0 * rho),
                        None => 1e-15,
                    };
                    // the gap is measured along the facet normal: d cos(angle) + facet offset
                    assert!(
                        (pr.gap - d).abs() <= sagitta + d.abs() * (1.0 - angle.cos()) + 1e-15,
                        "{p:?}: gap {} vs {d}",
                        pr.gap
                    );
                    checked += 1;
                }
            }
            assert_eq!(checked, 39 * 4);
        }
    }

    #[test]
    fn nose_lengths() {
        let r = 0.5 * D;
        let len = |nose| Projectile { diameter: D, length: L, nose }.nose_length();
        assert_eq!(len(NoseShape::Blunt { edge_radius: 0.0 }), 0.0);
        assert_eq!(len(NoseShape::Blunt { edge_radius: 0.001 }), 0.001);
        assert_eq!(len(NoseShape::Hemispherical), r);
        assert!((cone_length(r, 90.0) - r).abs() < 1e-15);
        assert!((len(NoseShape::Ogival { caliber_radius_head: 3.0 }) - r * 11f64.sqrt()).abs() < 1e-15);
    }
}
