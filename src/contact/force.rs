//! Contact forces of one slave: the one-step normal force, Coulomb friction
//! and the spreading of the slave force over particles (SPEC §8,
//! [RL10, §3]).
//!
//! # Time discretisation (which position and velocity)
//! SPEC §5 integrates `V^{n+½} = V^{n−½} + Δt a^n`, `U^{n+1} = U^n + Δt V^{n+½}`.
//! Splitting `a^n` into the contact-free part `a_free = (f_ext − f_int)/m` and
//! the contact part gives the end-of-step position
//! `x^{n+1} = x̃^{n+1} + Δt² f_c/m` with the *predictor*
//! `Ṽ = V^{n−½} + Δt a_free`, `x̃^{n+1} = X + U^n + Δt Ṽ`
//! (with the integrator's clamps and axis condition applied to `Ṽ`).
//! The gap `g̃` is measured at `x̃^{n+1}` against the master surface
//! predicted at the end of the step (body position `x_b + Δt V_b`, with its
//! prescribed or current velocity), and the force that leaves the slave
//! exactly on that surface is `f_n = m |g̃| / Δt²` along `n_m`
//! ([`one_step_normal_force`]). Likewise the stick force uses the predicted
//! relative velocity `Ṽ − V_b`, so that the slave's tangential velocity over
//! the step matches the body's ([`stick_force`], capped by [`coulomb_cap`]).
//! A free body's own response to the reaction (`Δt² F/M`) is not predicted:
//! it leaves a residual penetration of relative size `m_s/M` (≈ 1e-4 for a
//! particle against the projectile), removed at the next step.
//!
//! # Deviations
//! - **Factor 2.** [RL10, §3] and SPEC §8 write `f_n = 2 m_s |g| / Δt²`. That
//!   is the same condition ("remove the penetration in one step") for a
//!   Taylor update `x^{n+1} = x^n + Δt v^n + ½ Δt² a^n` whose velocity `v^n`
//!   is not itself changed by the contact acceleration. In the central
//!   difference of SPEC §5 it is (`v^n = V^{n−½} + ½ Δt a^n` contains `a^n`,
//!   and the position gains the full `Δt² a^n`), so the factor is 1 with the
//!   predictor above; the factor 2 would put the slave `|g̃|` *outside* the
//!   surface, i.e. reflect its normal velocity every step (an elastic bounce
//!   and contact chatter). Tests:
//!   `one_step_normal_force_puts_free_particle_on_surface`,
//!   `falling_particle_never_penetrates_a_wall`.
//! - **A penetration at the start of a step is held, not pushed out**
//!   (issue #19 item 5). SPEC §8's one-step force puts the slave on the
//!   surface at the end of the step whatever its gap `g⁰` at the start, so
//!   a slave that starts inside by `|g⁰|` leaves at `|g⁰|/Δt`: with
//!   `Δt ≈ ½ h/c_L`, one that starts 0.05 h inside is thrown at about 0.1 `c_L`,
//!   600 m/s in steel, whatever the bodies' speeds. Contact is enforced
//!   every step, yet slaves do start inside: a crack split rebuilds the
//!   shape-function rows around it and moves the physical points `x(X_I)`
//!   of its neighbours at once (coarse axisymmetric Case II, nonlocal
//!   damage with its earlier defaults `nonlocal_point_fracture = false` and
//!   `band_width = nonlocal_radius`: at the nucleation at 74.49 µs a
//!   surface particle beside the projectile's corner jumped 12.5 µm into
//!   its side and was thrown out at 839 m/s, the fastest particle of the
//!   run, with or without self-contact; held, the fastest is 296 m/s, at
//!   the impact, and the contact dissipates 11.3 J over the run where it
//!   put 19.4 J in), and deformable pairs have causes of their own
//!   (`super::deformable`, # Deviations). The end-of-step target is
//!   therefore [`gap_floor`]: 0 (SPEC §8) for a pair that starts outside or
//!   inside by round-off only, else the start gap `g⁰`, measured with the
//!   pair's own master point and normal so that `g̃ − g⁰` is `Δt` times the
//!   pair's predicted relative normal velocity. A pair that starts inside
//!   is kept from going deeper (its relative normal velocity after the step
//!   is ≥ 0) and is opened by the bodies' own motion only: the force stops
//!   an approach and never drives a separation, so the contact cannot put
//!   energy in (pushing an overlap out against the contact pressure `p`
//!   would put in `p δ` per area even slowly: a recovery at 1 m/s, tried,
//!   put 3 J into the 39 J of the test below in 2 µs). This is the "ignore
//!   initial penetration" of explicit finite-element contact (LS-DYNA's
//!   `IGNORE`), which tracks a penetration and resists only its growth.
//!   Measured with the rigid projectile (coarse Case I axisymmetric to 80
//!   µs, Case II axisymmetric with nonlocal damage to 90 µs): every slave
//!   started its step at most 4·10⁻¹⁸ m inside, but the one at that jump,
//!   so rigid contact keeps its bits in every run without such a jump (so
//!   do `borvik-1-axisymmetric`, `borvik-2-axisymmetric` and
//!   `borvik-2-axisymmetric-nonlocal`, whole runs). Tests:
//!   `gap_floor_holds_a_penetration_beyond_round_off`,
//!   `a_particle_starting_inside_is_held_not_pushed_out`,
//!   `exposed_particles_join_the_slaves_and_go_no_deeper`,
//!   `a_slave_starting_inside_a_deformable_master_is_not_thrown_out`,
//!   `a_slave_moved_inside_the_projectile_by_a_crack_is_not_thrown_out`.
//! - **Effective mass.** `m` is the mass the force actually moves at the
//!   point where the gap is measured: `m_s` for [`Spreading::None`],
//!   `m_s / w_ss` for [`Spreading::InverseDistance`] (the slave keeps only
//!   its own weight `w_ss` of the force; [RL10, §3] uses `m_s`, which removes
//!   only that fraction), and `m_eff = (Σ_J N_J(X_s)² / m_J)⁻¹` for
//!   [`Spreading::ShapeFunction`], whose gap point is
//!   `x(X_s) = X_s + Σ_J N_J(X_s) U_J` and whose force `f_J = N_J F` moves
//!   that point by `Δt² F / m_eff` (for a top-row particle of a uniform
//!   lattice `m_eff = 2 m_s`: with `m_s` only half the penetration would go);
//!   `(Σ_J w_J² / m_J)⁻¹ = (Σ m_J N_J)² / Σ m_J N_J²` for
//!   [`Spreading::MassWeighted`].
//!   Where several slaves share particles the forces are solved together
//!   (`ContactSystem::compute_forces`). Test:
//!   `shape_function_contact_of_an_isolated_point_is_exact`.
//! - **Mass-weighted spreading (an option, issue #19 item 5).**
//!   [`Spreading::MassWeighted`] measures the gap at `X_s + Σ_J w_J U_J`
//!   and spreads `f_J = w_J F` with `w_J = m_J N_J(X_s) / Σ_K m_K N_K(X_s)`
//!   ([`mass_weights`]): the row's local centre of mass instead of the
//!   physical point. It is a consistent pair (the force's virtual work is
//!   `F·δ(Σ w_J U_J)`, exactly the variation of the gap), so like the
//!   shape-function mode it conserves force and momentum and its one-step
//!   force can only dissipate; it equals the shape-function mode where the
//!   row's masses are equal (plane strain on a uniform lattice). Why: with
//!   `f_J = N_J F` a light particle in a slave's row (a crack's split
//!   child, the axis ring of an axisymmetric model) is accelerated by
//!   `N_J F / m_J`, five to ten times its neighbours, and a torn child
//!   whose material no longer holds it was pushed down the side wall at
//!   2.45 `v_i` (docs/validation.md, "Three more throws traced");
//!   mass-weighted, every particle of the row takes `N_J F / Σ m_K N_K`.
//!   An earlier try spread by mass but measured the gap at the physical
//!   point: not a consistent pair, it put 7.8 J in. What it costs: the gap
//!   point is not the physical surface where masses differ (it lies
//!   toward the heavier particles' displacements; the offset is a
//!   fraction of a spacing at the axis, zero on a uniform plane lattice),
//!   and a light particle that its material still holds is no longer held
//!   by the contact itself, so it swings with its material instead (the
//!   axis ring under a rounded nose still rings). Deformable pairs keep
//!   the shape-function points; the axis wall (`ContactSystem::with_axis`)
//!   holds the mass-weighted points like the rigid pairs, so a physical
//!   point beside the axis may reach `r < 0` by that offset (left so: the
//!   measured runs have these bits). Not the default (measured in
//!   docs/validation.md, "A mass-weighted contact spreading (an option), and the
//!   hemispherical nose's km/s throw traced"). Tests:
//!   `mass_weighted_contact_of_an_isolated_point_is_exact`,
//!   `mass_weighted_spreading_holds_the_rows_centre_of_mass_not_a_light_particle`,
//!   `momentum_and_energy_with_a_free_body`.
//! - **Inverse-distance weights.** `w_J ∝ 1 / max(|X_J − X_s|, ρ h_s)`
//!   (reference distances, `ρ` = `inverse_distance_floor`, default ½), over
//!   the particles of the slave's shape-function row that lie in the slave's
//!   own window (`|X_J − X_s|_∞ < a_s`): the row respects crack visibility,
//!   the window restricts it to "the particles in the slave's support"
//!   ([RL10, §3]). The floor is our choice: the slave itself is at distance
//!   0, which a pure inverse distance cannot weight. Test:
//!   `spreading_conserves_the_total_force`.

use serde::{Deserialize, Serialize};

use crate::math::{Real, Vec2};

/// How a slave's contact force reaches the particles, and where its gap is
/// measured (SPEC §8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Spreading {
    /// Gap at the slave's generalized position `X_s + U_s`; the whole force
    /// on the slave particle.
    None,
    /// Gap at `X_s + U_s`; the force spread over the particles in the
    /// slave's support with normalised inverse-distance weights ([RL10, §3]).
    InverseDistance,
    /// Variationally consistent: gap at the physical point
    /// `x(X_s) = X_s + Σ_J N_J(X_s) U_J`, force `f_J = N_J(X_s) F` (the
    /// virtual work of a point force). Default: see the `contact` module doc.
    #[default]
    ShapeFunction,
    /// Variationally consistent over the row's mass: gap at
    /// `X_s + Σ_J w_J U_J`, force `f_J = w_J F`, with the weights
    /// `w_J = m_J N_J(X_s) / Σ_K m_K N_K(X_s)` ([`mass_weights`]). Every
    /// particle of the row is accelerated by `N_J F / Σ_K m_K N_K`, in
    /// proportion to its shape function whatever its mass; identical to
    /// [`Spreading::ShapeFunction`] where the row's masses are equal. An
    /// option (issue #19 item 5): module doc, # Deviations.
    MassWeighted,
}

/// The mass-weighted row of [`Spreading::MassWeighted`]: for the entries
/// `(J, N_J)` of a shape-function row and the particles' masses, the
/// entries `(J, m_J N_J / Σ_K m_K N_K)` in row order, which sum to 1. `Err`
/// with the sum `Σ_K m_K N_K` when it is not positive and finite: the row
/// then has no mass-weighted point.
pub fn mass_weights<'a, I>(row: I, mass: &'a [Real]) -> Result<impl Iterator<Item = (u32, Real)> + 'a, Real>
where
    I: Iterator<Item = (u32, Real)> + Clone + 'a,
{
    let total: Real = row.clone().map(|(j, n)| mass[j as usize] * n).sum();
    if !(total.is_finite() && total > 0.0) {
        return Err(total);
    }
    Ok(row.map(move |(j, n)| (j, mass[j as usize] * n / total)))
}

/// Normal force along `n_m` that removes the gap `g` of a point of effective
/// mass `mass` (kg) in one step: `f_n = −m g / Δt²`, i.e. `m |g| / Δt²` for a
/// penetration (SPEC §8, [RL10, §3] with the factor of SPEC §5's half-step
/// velocities: module doc, # Deviations). `dt2` is `Δt Δt_v`, the product
/// of the step's displacement and velocity steps (`Δt²` unless the step
/// just changed: a force `f` moves the point by `Δt Δt_v f / m`). Negative
/// for an open gap; the caller keeps the total normal force non-negative.
/// An infinite mass (a point that cannot move) gives no force.
#[inline]
pub fn one_step_normal_force(mass: Real, gap: Real, dt2: Real) -> Real {
    if mass.is_finite() {
        -mass * gap / dt2
    } else {
        0.0
    }
}

/// A start-of-step penetration up to this fraction of the slave's spacing
/// is round-off of the last step's contact, which SPEC §8's force removes
/// ([`gap_floor`]): pushed out in one step, it moves the slave at no more
/// than `10⁻⁹ h/Δt ≈ 2·10⁻⁹ c_L/s`, 10⁻⁵ m/s in steel. Contact leaves
/// slaves on the surface to 4·10⁻¹⁸ m (measured, module doc), 10⁻⁵ of this
/// for a spacing of 0.4 mm.
pub const ROUND_OFF_PENETRATION: Real = 1e-9;

/// The gap (m, ≤ 0) that a pair's normal force leaves at the end of a step,
/// for its gap `start_gap` (m) at the start of the step measured with the
/// same master point and normal and the slave's spacing `spacing` (m): 0
/// (SPEC §8) unless the pair started inside by more than
/// [`ROUND_OFF_PENETRATION`]` · spacing`, else `start_gap` (module doc, #
/// Deviations).
#[inline]
pub fn gap_floor(start_gap: Real, spacing: Real) -> Real {
    if start_gap >= -ROUND_OFF_PENETRATION * spacing {
        0.0
    } else {
        start_gap
    }
}

/// Stick force along the tangent that cancels the relative tangential
/// velocity `v_t` over one step: `−m v_t / Δt` (SPEC §8). Zero for an
/// infinite mass.
#[inline]
pub fn stick_force(mass: Real, tangential_velocity: Real, dt: Real) -> Real {
    if mass.is_finite() {
        -mass * tangential_velocity / dt
    } else {
        0.0
    }
}

/// Coulomb's cap on a trial tangential force: `(trial, false)` if
/// `|trial| ≤ cap` (stick), else `(±cap, true)` with the trial's sign (slip).
/// With `cap = 0` (μ = 0 or no normal force) the force is exactly zero and
/// the contact slips unless the trial is zero.
#[inline]
pub fn coulomb_cap(trial: Real, cap: Real) -> (Real, bool) {
    if trial.abs() <= cap {
        (trial, false)
    } else {
        (cap.copysign(trial), true)
    }
}

/// Normalised inverse-distance weights (module doc): for candidate
/// particles `(J, X_J)` around the slave at `x_s`, `w_J ∝ 1/max(|X_J − x_s|,
/// floor)`, appended to `out` as `(J, w_J)` with `Σ w_J = 1` over the
/// appended entries; nothing is appended if there is no candidate.
pub fn inverse_distance_weights(
    x_s: &Vec2,
    floor: Real,
    candidates: impl IntoIterator<Item = (u32, Vec2)>,
    out: &mut Vec<(u32, Real)>,
) {
    let start = out.len();
    let mut total = 0.0;
    for (j, x) in candidates {
        let w = 1.0 / (x - x_s).norm().max(floor);
        total += w;
        out.push((j, w));
    }
    for e in &mut out[start..] {
        e.1 /= total;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_step_forces_and_the_coulomb_cap() {
        assert!((one_step_normal_force(2.0, -1e-9, 1e-12) - 2.0e3).abs() < 1e-9);
        assert!(one_step_normal_force(2.0, 1e-9, 1e-12) < 0.0);
        assert_eq!(one_step_normal_force(Real::INFINITY, -1.0, 1.0), 0.0);
        assert_eq!(stick_force(1.0, -1e-3, 1e-3), 1.0);
        // stick below the cap, slip at the cap with the trial's sign above it
        assert_eq!(coulomb_cap(1.0, 2.0), (1.0, false));
        assert_eq!(coulomb_cap(-10.0, 2.0), (-2.0, true));
        assert_eq!(coulomb_cap(5.0, 0.0), (0.0, true));
        assert_eq!(coulomb_cap(0.0, 0.0), (0.0, false));
    }

    #[test]
    fn gap_floor_holds_a_penetration_beyond_round_off() {
        let h = 1e-3;
        let round_off = ROUND_OFF_PENETRATION * h;
        // Outside, on the surface, or inside by round-off: SPEC §8's 0.
        for g0 in [1e-6, 0.0, -0.5 * round_off, -round_off] {
            assert_eq!(gap_floor(g0, h), 0.0, "{g0}");
        }
        // Deeper: held where it is.
        for g0 in [-2.0 * round_off, -1e-5] {
            assert_eq!(gap_floor(g0, h), g0);
        }
    }

    #[test]
    fn inverse_distance_weights_sum_to_one_and_floor_the_slave() {
        let mut w = vec![(9, 0.25)];
        let xs = Vec2::new(0.0, 0.0);
        let cands = [(3u32, xs), (4, Vec2::new(1.0, 0.0)), (5, Vec2::new(0.0, -2.0))];
        inverse_distance_weights(&xs, 0.5, cands, &mut w);
        let total: Real = w[1..].iter().map(|e| e.1).sum();
        assert!((total - 1.0).abs() < 1e-15 && w[0] == (9, 0.25));
        // raw weights 2, 1, 0.5
        assert!((w[1].1 - 2.0 / 3.5).abs() < 1e-15 && (w[3].1 - 0.5 / 3.5).abs() < 1e-15);
    }
}
