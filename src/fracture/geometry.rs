//! Plane geometry of crack paths in the reference configuration (SPEC §9):
//! sight-line blocking, the side of a split particle, the angle fractions
//! of a split, and the empty-sector (outer-surface) test.

use crate::math::{Real, Vec2};
use crate::particles::FaceSide;

/// `cross(a, b) = a_x b_y − a_y b_x`.
#[inline]
pub fn cross(a: &Vec2, b: &Vec2) -> Real {
    a.x * b.y - a.y * b.x
}

/// The left normal `(−d_y, d_x)` of a direction.
#[inline]
pub fn left_normal(d: &Vec2) -> Vec2 {
    Vec2::new(-d.y, d.x)
}

/// Relative distance below which a point counts as lying on a crack line
/// (as a fraction of the segment length). Points on a crack line — a Gauss
/// point on a cell diagonal that the crack follows, an unsplit particle the
/// path touches — belong to the left side of the path, by convention
/// (left of the direction of growth); 1e-9 is far below any spacing ratio
/// and far above round-off of reference coordinates.
pub const ON_LINE_TOLERANCE: Real = 1e-9;

/// Whether the sight line from evaluation point `x` to particle position
/// `p` is blocked by the (already extended) crack segment `[a, b]`.
///
/// Blocked when `x` and `p` lie on opposite sides of the segment's line and
/// the sight line meets the segment. Ties, by convention: a point `x` on
/// the line counts as lying on its left; a particle `p` on the line (a tip
/// particle, or a particle the path touches) is never blocked by that
/// segment; a sight line that reaches the segment exactly at an end is
/// blocked (the ends are extended beyond the split particles, so this only
/// decides at the extension's tip).
pub fn sight_line_blocked(a: &Vec2, b: &Vec2, x: &Vec2, p: &Vec2) -> bool {
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 == 0.0 {
        return false;
    }
    let tol = ON_LINE_TOLERANCE * len2.sqrt();
    let len = len2.sqrt();
    let ox = cross(&d, &(x - a)) / len; // signed distance of x from the line
    let op = cross(&d, &(p - a)) / len;
    if op.abs() <= tol {
        return false;
    }
    let x_left = ox > -tol;
    let p_left = op > 0.0;
    if x_left == p_left {
        return false;
    }
    // Opposite sides: the sight line crosses the segment's line at one
    // point; is that point within [a, b]?
    let s = x - p;
    let oa = cross(&s, &(a - p));
    let ob = cross(&s, &(b - p));
    oa * ob <= 0.0
}

/// Whether `x` lies on the left of a crack path that passes through
/// `vertex` arriving along unit `incoming` and leaving along unit
/// `outgoing` (left of the direction of growth). Points on the path count
/// as left ([`ON_LINE_TOLERANCE`]).
pub fn left_of_path(vertex: &Vec2, incoming: &Vec2, outgoing: &Vec2, x: &Vec2) -> bool {
    let r = x - vertex;
    let scale = r.norm().max(Real::MIN_POSITIVE);
    let tol = ON_LINE_TOLERANCE * scale;
    let l_in = cross(incoming, &r) > -tol;
    let l_out = cross(outgoing, &r) > -tol;
    if cross(incoming, outgoing) >= 0.0 {
        // turning left (or straight): the left side is the convex wedge
        l_in && l_out
    } else {
        // turning right: the left side is the reflex wedge
        l_in || l_out
    }
}

/// Whether a split particle with crack side `side` may contribute at `x`
/// by the side rule alone (SPEC §9: "each split particle is visible only
/// from its own side"). Beyond `side.reach` the rule does not apply.
pub fn side_allows(side: &FaceSide, x: &Vec2) -> bool {
    if (x - side.vertex).norm() > side.reach {
        return true;
    }
    left_of_path(&side.vertex, &side.incoming, &side.outgoing, x) == side.left
}

/// Angles of the two sectors a crack path makes at a vertex it passes
/// through: `(φ_left, φ_right)`, rad, `φ_left + φ_right = 2π`. A path
/// turning left by `α` leaves `φ_left = π − α` ([RL10, Eqs. (4.16)–(4.19)]).
pub fn sector_angles(incoming: &Vec2, outgoing: &Vec2) -> (Real, Real) {
    let alpha = cross(incoming, outgoing).atan2(incoming.dot(outgoing));
    let pi = std::f64::consts::PI;
    (pi - alpha, pi + alpha)
}

/// Unit bisector of the left sector at a vertex (the direction in which the
/// left particle of a split is offset); the right one is its negative.
pub fn left_bisector(incoming: &Vec2, outgoing: &Vec2) -> Vec2 {
    let b = left_normal(incoming) + left_normal(outgoing);
    let n = b.norm();
    if n > 1e-12 {
        b / n
    } else {
        left_normal(incoming)
    }
}

/// The widest empty angular sector around a point, given the directions to
/// its neighbours: `(width, start)` with the sector running counter-
/// clockwise from angle `start` over `width` (rad). With no neighbours the
/// whole circle is empty.
pub fn widest_empty_sector(directions: &[Vec2]) -> (Real, Real) {
    let two_pi = 2.0 * std::f64::consts::PI;
    if directions.is_empty() {
        return (two_pi, 0.0);
    }
    let mut ang: Vec<Real> = directions.iter().map(|d| d.y.atan2(d.x)).collect();
    ang.sort_by(|a, b| a.partial_cmp(b).expect("finite angles"));
    let mut best = (ang[0] + two_pi - ang[ang.len() - 1], ang[ang.len() - 1]);
    for w in ang.windows(2) {
        if w[1] - w[0] > best.0 {
            best = (w[1] - w[0], w[0]);
        }
    }
    best
}

/// Whether direction `d` points into the sector `(width, start)`.
pub fn sector_contains(sector: (Real, Real), d: &Vec2) -> bool {
    let two_pi = 2.0 * std::f64::consts::PI;
    let a = (d.y.atan2(d.x) - sector.1).rem_euclid(two_pi);
    a <= sector.0
}

/// The point of segment `[a, b]` nearest to `x`.
pub fn closest_point_on_segment(a: &Vec2, b: &Vec2, x: &Vec2) -> Vec2 {
    let d = b - a;
    let l2 = d.norm_squared();
    if l2 == 0.0 {
        return *a;
    }
    let t = ((x - a).dot(&d) / l2).clamp(0.0, 1.0);
    a + d * t
}

/// Distance from point `x` to segment `[a, b]`.
pub fn point_segment_distance(a: &Vec2, b: &Vec2, x: &Vec2) -> Real {
    (closest_point_on_segment(a, b, x) - x).norm()
}

/// The direction of the slip line through a point: of the two in-plane
/// directions of maximum shear stress of `tau` (current configuration,
/// its symmetric part; at ±45° to the in-plane principal axes, the
/// characteristics of plane plastic flow), pulled back to the reference
/// configuration by the in-plane deformation gradient `f` (a material line
/// `dx = F dX`), the one nearer to `reference` (up to sign), as a unit
/// vector along `reference`. `None` where the in-plane shear stress
/// vanishes (every direction is one of maximum shear) or `f` is singular.
/// The crack-tip direction `tip_direction = "max_shear"`
/// (module doc of [`crate::fracture`]); in 3D the same reading gives the
/// plane of maximum shear, which contains the intermediate principal axis.
pub fn max_shear_direction(
    tau: &nalgebra::Matrix2<Real>,
    f: &nalgebra::Matrix2<Real>,
    reference: &Vec2,
) -> Option<Vec2> {
    let (sxx, syy, sxy) = (tau[(0, 0)], tau[(1, 1)], 0.5 * (tau[(0, 1)] + tau[(1, 0)]));
    let radius = (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    let scale = sxx.abs().max(syy.abs()).max(sxy.abs());
    if radius.is_nan() || radius <= 1e-9 * scale || reference.norm() == 0.0 {
        return None;
    }
    let finv = f.try_inverse()?;
    let principal = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let quarter = 0.25 * std::f64::consts::PI;
    let mut best: Option<(Real, Vec2)> = None;
    for a in [principal + quarter, principal - quarter] {
        let back = finv * Vec2::new(a.cos(), a.sin());
        let n = back.norm();
        if !(n > 0.0 && n.is_finite()) {
            continue;
        }
        let unit = back / n;
        let c = unit.dot(reference);
        if best.is_none_or(|(bc, _)| c.abs() > bc.abs()) {
            best = Some((c, if c < 0.0 { -unit } else { unit }));
        }
    }
    best.map(|(_, d)| d)
}

/// The direction of the band across which the velocity jumps, through a
/// point with material velocity gradient `fdot` (`Ḟ = ∇_X v`, in-plane,
/// reference configuration): the band's normal `N` is the one across
/// which material slides past material fastest, the largest `|T·Ḟ N|`
/// (`T ⊥ N`); returned is the band's direction `T`, along `reference`
/// (up to sign). With `ω = (Ḟ_yx − Ḟ_xy)/2` the spin and `R` the Mohr
/// radius of the symmetric part (the largest shear rate of the rate of
/// deformation), `T·Ḟ N = ω + R cos(2θ − φ)` for `N` at angle `θ`, so
/// the band is the one of the rate of deformation's two slip lines whose
/// sense of shear the spin shares: a sliding band `Ḟ = γ̇ T₀ ⊗ N₀` gives
/// its own `T₀` exactly (not the conjugate line; a compression across it
/// or a stretch along it tilts the answer); a spin-free rate (a pure compression) leaves the two slip
/// lines at ±45° to its axes and the one nearer `reference` is taken.
/// `None` where no band is preferred (`R = 0`: a rest, a rigid spin, a
/// uniform dilatation). The crack-tip direction `tip_direction =
/// "velocity_jump"` (module doc of [`crate::fracture`]); in 3D the same
/// reading gives the plane of the largest sliding rate.
pub fn velocity_jump_direction(fdot: &nalgebra::Matrix2<Real>, reference: &Vec2) -> Option<Vec2> {
    let (a, b, c, d) = (fdot[(0, 0)], fdot[(0, 1)], fdot[(1, 0)], fdot[(1, 1)]);
    let spin = 0.5 * (c - b);
    let (p, q) = (0.5 * (c + b), 0.5 * (d - a));
    let radius = p.hypot(q);
    if radius.is_nan() || radius <= 1e-9 * (radius + spin.abs()) || reference.norm() == 0.0 {
        return None;
    }
    let phi = q.atan2(p);
    let band = |theta: Real| Vec2::new(-theta.sin(), theta.cos());
    let along = |t: Vec2| if t.dot(reference) < 0.0 { -t } else { t };
    let first = along(band(0.5 * phi));
    let second = along(band(0.5 * phi + 0.5 * std::f64::consts::PI));
    Some(if spin > 0.0 {
        first
    } else if spin < 0.0 {
        second
    } else if first.dot(reference) >= second.dot(reference) {
        first
    } else {
        second
    })
}

/// Where a crack tip heads for along a band of direction `along`
/// (unit) whose centre line lies `offset` from the tip across it (along
/// `left_normal(along)`): the point on the centre line `length` ahead,
/// as a unit vector. A tip on the centre line runs along it; one off it
/// turns back by `atan(offset/length)`, so a step off the band is
/// undone within `length` instead of carried on (the tip direction
/// `"velocity_jump"`, with `length = ℓ`).
pub fn band_aim(along: &Vec2, offset: Real, length: Real) -> Vec2 {
    (along * length + left_normal(along) * offset).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn v(x: Real, y: Real) -> Vec2 {
        Vec2::new(x, y)
    }

    #[test]
    fn sight_lines_across_a_segment_are_blocked_along_it_not() {
        let (a, b) = (v(0.0, 0.0), v(1.0, 0.0));
        assert!(sight_line_blocked(&a, &b, &v(0.5, 1.0), &v(0.4, -1.0)));
        assert!(!sight_line_blocked(&a, &b, &v(0.5, 1.0), &v(0.4, 0.5)));
        // passes beyond the end
        assert!(!sight_line_blocked(&a, &b, &v(1.5, 1.0), &v(1.5, -1.0)));
        // x on the line belongs to the left (y > 0 for a segment along +x)
        assert!(!sight_line_blocked(&a, &b, &v(0.5, 0.0), &v(0.5, 1.0)));
        assert!(sight_line_blocked(&a, &b, &v(0.5, 0.0), &v(0.5, -1.0)));
        // a particle on the line is not blocked
        assert!(!sight_line_blocked(&a, &b, &v(0.5, -1.0), &v(1.0, 0.0)));
    }

    #[test]
    fn side_of_a_kinked_path() {
        let c = v(0.0, 0.0);
        let din = v(0.0, -1.0);
        // turning left (towards +x when going down): outgoing (1, -1)/sqrt2
        let dout = v(1.0, -1.0) / 2f64.sqrt();
        assert!(cross(&din, &dout) > 0.0);
        // left of a downward path is +x; the left wedge lies between up (behind) and dout
        assert!(left_of_path(&c, &din, &dout, &v(1.0, 0.5)));
        assert!(!left_of_path(&c, &din, &dout, &v(1.0, -2.0)));
        assert!(!left_of_path(&c, &din, &dout, &v(-1.0, 0.0)));
        let (l, r) = sector_angles(&din, &dout);
        assert!((l - 0.75 * PI).abs() < 1e-12 && (r - 1.25 * PI).abs() < 1e-12);
        let b = left_bisector(&din, &dout);
        assert!(left_of_path(&c, &din, &dout, &(b * 1e-3)));
        assert!(!left_of_path(&c, &din, &dout, &(-b * 1e-3)));
        // straight path: halves
        let (l, r) = sector_angles(&din, &din);
        assert!((l - PI).abs() < 1e-15 && (r - PI).abs() < 1e-15);
    }

    #[test]
    fn empty_sector_of_a_surface_point_and_an_interior_point() {
        let lattice: Vec<Vec2> = (-2..=2)
            .flat_map(|i| (-2..=2).map(move |j| v(i as Real, j as Real)))
            .filter(|p| p.norm() > 0.0 && p.norm() < 2.5)
            .collect();
        let (w, _) = widest_empty_sector(&lattice);
        assert!(w < 0.5 * PI + 1e-12);
        let half: Vec<Vec2> = lattice.iter().cloned().filter(|p| p.y <= 0.0).collect();
        let s = widest_empty_sector(&half);
        assert!((s.0 - PI).abs() < 1e-12);
        assert!(sector_contains(s, &v(0.3, 1.0)));
        assert!(!sector_contains(s, &v(0.3, -1.0)));
    }

    #[test]
    fn max_shear_direction_is_the_slip_line_pulled_back() {
        use nalgebra::Matrix2;
        let id = Matrix2::identity();
        // pure shear stress: slip lines along x and y
        let shear = Matrix2::new(0.0, 1.0, 1.0, 0.0);
        let d = max_shear_direction(&shear, &id, &v(0.2, -1.0)).unwrap();
        assert!((d - v(0.0, -1.0)).norm() < 1e-12, "{d}");
        let d = max_shear_direction(&shear, &id, &v(1.0, 0.3)).unwrap();
        assert!((d - v(1.0, 0.0)).norm() < 1e-12, "{d}");
        // uniaxial tension along x: slip lines at ±45°
        let tension = Matrix2::new(2.0, 0.0, 0.0, 0.0);
        let d = max_shear_direction(&tension, &id, &v(1.0, 0.9)).unwrap();
        assert!((d - v(1.0, 1.0) / 2f64.sqrt()).norm() < 1e-12, "{d}");
        // hydrostatic stress has no slip line; nor has a singular F
        assert!(max_shear_direction(&Matrix2::identity(), &id, &v(1.0, 0.0)).is_none());
        assert!(max_shear_direction(&shear, &Matrix2::zeros(), &v(1.0, 0.0)).is_none());
        // simple shear x += γ y: the current slip lines x and y are the
        // material lines X (unstretched) and (−γ, 1) (the line now vertical)
        let g = 0.8;
        let f = Matrix2::new(1.0, g, 0.0, 1.0);
        let d = max_shear_direction(&shear, &f, &v(1.0, 0.1)).unwrap();
        assert!((d - v(1.0, 0.0)).norm() < 1e-12, "{d}");
        let d = max_shear_direction(&shear, &f, &v(0.0, 1.0)).unwrap();
        assert!((d - v(-g, 1.0) / (1.0 + g * g).sqrt()).norm() < 1e-12, "{d}");
    }

    #[test]
    fn max_shear_direction_is_objective() {
        // a rigid rotation Q after any deformation: τ → Q τ Qᵀ, F → Q F;
        // the reference direction does not move
        use nalgebra::Matrix2;
        let tau = Matrix2::new(3.0, -1.2, -1.2, 0.5);
        let f = Matrix2::new(1.1, 0.4, -0.2, 0.9);
        let reference = v(0.3, -1.0);
        let d0 = max_shear_direction(&tau, &f, &reference).unwrap();
        for a in [0.3, 1.2, 2.9, -2.0] {
            let q = Matrix2::new(Real::cos(a), -Real::sin(a), Real::sin(a), Real::cos(a));
            let d = max_shear_direction(&(q * tau * q.transpose()), &(q * f), &reference).unwrap();
            assert!((d - d0).norm() < 1e-12, "rotation {a}: {d} against {d0}");
        }
        // and it is a direction of maximum shear: τ_nt at its push-forward
        // is the Mohr circle's radius
        let n = (f * d0).normalize();
        let t = left_normal(&n);
        let radius = (0.25 * (tau[(0, 0)] - tau[(1, 1)]).powi(2) + tau[(0, 1)].powi(2)).sqrt();
        assert!(((t.transpose() * tau * n)[0].abs() - radius).abs() < 1e-12);
    }

    #[test]
    fn velocity_jump_direction_runs_along_a_sliding_band() {
        use nalgebra::Matrix2;
        // a block sliding down (−y) past its surroundings across a band
        // whose normal is x: Ḟ = [v] ⊗ N / w = (0, −1) ⊗ (1, 0)
        let plug = Matrix2::new(0.0, 0.0, -1.0, 0.0);
        let d = velocity_jump_direction(&plug, &v(0.1, -1.0)).unwrap();
        assert!((d - v(0.0, -1.0)).norm() < 1e-12, "{d}");
        // sliding up instead, and a reference nearer the conjugate line
        // (x): the band is still along y
        let d = velocity_jump_direction(&-plug, &v(1.0, -0.9)).unwrap();
        assert!((d - v(0.0, -1.0)).norm() < 1e-12, "{d}");
        // simple shear along x (v_x = γ̇ y) runs along x, whatever the reference
        let d = velocity_jump_direction(&Matrix2::new(0.0, 1.0, 0.0, 0.0), &v(1.0, 1.5)).unwrap();
        assert!((d - v(1.0, 0.0)).norm() < 1e-12, "{d}");
        // a band inclined at 30° from x, N = (−sin 30°, cos 30°), sliding
        // either way: the band's own direction T
        let a = 30f64.to_radians();
        let (t, n) = (v(a.cos(), a.sin()), v(-a.sin(), a.cos()));
        for g in [2.0, -2.0] {
            let d = velocity_jump_direction(&(t * n.transpose() * g), &v(1.0, -0.5)).unwrap();
            assert!((d - t).norm() < 1e-12, "γ̇ = {g}: {d}");
            // with a compression across it and a stretch along it the band
            // tilts: to the normal of the largest |T·Ḟ N| of a fine sweep
            let fdot = t * n.transpose() * g - n * n.transpose() * 0.3 + t * t.transpose() * 0.3;
            let d = velocity_jump_direction(&fdot, &v(1.0, -0.5)).unwrap();
            let rate = |theta: Real| {
                let (nn, tt) = (v(theta.cos(), theta.sin()), v(-theta.sin(), theta.cos()));
                (tt.transpose() * fdot * nn)[0].abs()
            };
            let sweep = (0..36000).map(|k| k as Real * PI / 36000.0);
            let theta = sweep.max_by(|x, y| rate(*x).total_cmp(&rate(*y))).unwrap();
            let expected = v(-theta.sin(), theta.cos());
            assert!(d.dot(&expected).abs() > (1e-4f64).cos(), "γ̇ = {g}: {d} against {expected}");
            assert!(d.dot(&t) > (10f64.to_radians()).cos(), "γ̇ = {g}: {d} within 10° of the band");
        }
        // a pure compression along y has no spin: its slip lines at ±45°,
        // the one nearer the reference
        let squeeze = Matrix2::new(0.0, 0.0, 0.0, -1.0);
        let d = velocity_jump_direction(&squeeze, &v(0.2, -1.0)).unwrap();
        assert!((d - v(1.0, -1.0) / 2f64.sqrt()).norm() < 1e-12, "{d}");
        let d = velocity_jump_direction(&squeeze, &v(-0.2, -1.0)).unwrap();
        assert!((d - v(-1.0, -1.0) / 2f64.sqrt()).norm() < 1e-12, "{d}");
        // a rest, a rigid spin and a uniform dilatation prefer none
        assert!(velocity_jump_direction(&Matrix2::zeros(), &v(1.0, 0.0)).is_none());
        assert!(velocity_jump_direction(&Matrix2::new(0.0, -2.0, 2.0, 0.0), &v(1.0, 0.0)).is_none());
        assert!(velocity_jump_direction(&Matrix2::identity(), &v(1.0, 0.0)).is_none());
    }

    #[test]
    fn band_aim_turns_back_to_the_centre_line() {
        let down = v(0.0, -1.0);
        // on the centre line: along it
        assert!((band_aim(&down, 0.0, 1e-3) - down).norm() < 1e-15);
        // the centre line 1 mm to the left of a downward band (+x): 45°
        // towards it at ℓ = 1 mm, atan(1/2) at ℓ = 2 mm
        let d = band_aim(&down, 1e-3, 1e-3);
        assert!((d - v(1.0, -1.0) / 2f64.sqrt()).norm() < 1e-12, "{d}");
        let d = band_aim(&down, -1e-3, 2e-3);
        assert!((d.x.atan2(-d.y) + 0.5f64.atan()).abs() < 1e-12, "{d}");
    }
}
