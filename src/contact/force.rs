//! Contact forces of one slave: the one-step normal force, Coulomb friction
//! and the spreading of the slave force over particles (SPEC §8,
//! [RL10] §3).
//!
//! # Time discretisation (which position and velocity)
//! SPEC §5 integrates `V^{n+½} = V^{n−½} + Δt a^n`, `U^{n+1} = U^n + Δt V^{n+½}`.
//! Splitting `a^n` into the contact-free part `a_free = (f_ext − f_int)/m` and
//! the contact part gives the end-of-step position
//! `x^{n+1} = x̃^{n+1} + Δt² f_c/m` with the *predictor*
//! `Ṽ = V^{n−½} + Δt a_free`, `x̃^{n+1} = X + U^n + Δt Ṽ`.
//! The gap `g̃` is measured at `x̃^{n+1}` against the master surface
//! predicted at the end of the step, and the force that leaves the slave
//! exactly on that surface is `f_n = m |g̃| / Δt²` along `n_m`
//! ([`normal_force_one_step`]). Likewise the stick force uses the predicted
//! relative velocity `Ṽ − V_body`, so that the slave's tangential velocity
//! over the step matches the body's ([`friction_force`]).
//!
//! # Deviations
//! - **Factor 2.** [RL10] and SPEC §8 write `f_n = 2 m_s |g| / Δt²`. That is
//!   the same condition ("remove the penetration in one step") for a Taylor
//!   update `x^{n+1} = x^n + Δt v^n + ½ Δt² a^n` whose velocity `v^n` is not
//!   itself changed by the contact acceleration. In the central difference
//!   of SPEC §5 it is (`v^n = V^{n−½} + ½ Δt a^n` contains `a^n`, and the
//!   position gains the full `Δt² a^n`), so the factor is 1 with the
//!   predictor above; the factor 2 would put the slave `|g̃|` *outside* the
//!   surface, i.e. reflect its normal velocity every step (an elastic bounce
//!   and contact chatter). Tests: `one_step_normal_force_puts_free_particle_on_surface`,
//!   `falling_particle_never_penetrates_a_wall`.
//! - **Effective mass.** `m` is the mass that the force actually moves at
//!   the point where the gap is measured: `m_s` for [`Spreading::None`] and
//!   [`Spreading::InverseDistance`] (as [RL10]), and
//!   `m_eff = (Σ_J N_J(X_s)² / m_J)⁻¹` for [`Spreading::ShapeFunction`],
//!   whose gap point is `x(X_s) = X_s + Σ_J N_J(X_s) U_J` and whose force
//!   `f_J = N_J F` moves that point by `Δt² F / m_eff`. With `m_s` there the
//!   force would remove only `m_s / m_eff` (typically a third) of the
//!   penetration. Test: `shape_function_contact_of_an_isolated_point_is_exact`.
//! - **Inverse-distance weights.** `w_J ∝ 1 / max(|X_J − X_s|, ρ h_s)`
//!   (reference distances, `ρ` = `inverse_distance_floor`, default ½), over
//!   the particles of the slave's shape-function row that lie in the slave's
//!   own window (`|X_J − X_s|_∞ < a_s`): the row respects crack visibility,
//!   the window restricts it to "the particles in the slave's support"
//!   ([RL10]). The floor is our choice: the slave itself is at distance 0,
//!   which a pure inverse distance cannot weight. Test:
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
    /// slave's support with normalised inverse-distance weights ([RL10]).
    InverseDistance,
    /// Variationally consistent: gap at the physical point
    /// `x(X_s) = X_s + Σ_J N_J(X_s) U_J`, force `f_J = N_J(X_s) F` (the
    /// virtual work of a point force). Default: see the `contact` module doc.
    #[default]
    ShapeFunction,
}

/// Normal force magnitude that removes the predicted penetration `g̃ < 0`
/// in one step: `f_n = m |g̃| / Δt²` (SPEC §8, [RL10, Eq. (3.x)] with the
/// factor of SPEC §5's half-step velocities: module doc, # Deviations);
/// zero when `g̃ ≥ 0`. `mass` is the effective mass of the gap point, kg.
#[inline]
pub fn normal_force_one_step(mass: Real, gap: Real, dt: Real) -> Real {
    if gap < 0.0 {
        mass * (-gap) / (dt * dt)
    } else {
        0.0
    }
}

/// Tangential force (signed, along the tangent whose velocity component is
/// `tangential_velocity`) and whether the contact slips: the stick force
/// `−m v_t / Δt` that cancels the relative tangential velocity over the
/// step, capped by Coulomb's `μ |f_n|` (SPEC §8). `μ = 0` gives exactly no
/// tangential force.
#[inline]
pub fn friction_force(mass: Real, tangential_velocity: Real, dt: Real, mu: Real, normal_force: Real) -> (Real, bool) {
    if mu == 0.0 {
        return (0.0, tangential_velocity != 0.0);
    }
    let stick = -mass * tangential_velocity / dt;
    let cap = mu * normal_force.abs();
    if stick.abs() <= cap {
        (stick, false)
    } else {
        (-cap * tangential_velocity.signum(), true)
    }
}

/// Normalised inverse-distance weights (module doc): for candidate
/// particles `(J, X_J)` around the slave at `x_s`, `w_J ∝ 1/max(|X_J − x_s|,
/// floor)`, appended to `out` as `(J, w_J)` with `Σ w_J = 1`. `out` is
/// cleared first; nothing is appended if there is no candidate.
pub fn inverse_distance_weights(
    x_s: &Vec2,
    floor: Real,
    candidates: impl IntoIterator<Item = (u32, Vec2)>,
    out: &mut Vec<(u32, Real)>,
) {
    out.clear();
    let mut total = 0.0;
    for (j, x) in candidates {
        let w = 1.0 / (x - x_s).norm().max(floor);
        total += w;
        out.push((j, w));
    }
    for e in out.iter_mut() {
        e.1 /= total;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_force_is_zero_without_penetration() {
        assert_eq!(normal_force_one_step(2.0, 1e-3, 1e-6), 0.0);
        assert_eq!(normal_force_one_step(2.0, 0.0, 1e-6), 0.0);
        assert!((normal_force_one_step(2.0, -1e-9, 1e-6) - 2.0e3).abs() < 1e-9);
    }

    #[test]
    fn friction_sticks_below_the_cap_and_slips_above() {
        // stick force 1 N, cap 0.5 * 4 = 2 N: stick
        assert_eq!(friction_force(1.0, -1e-3, 1e-3, 0.5, 4.0), (1.0, false));
        // stick force 10 N > cap 2 N: slip at the cap, opposing the motion
        assert_eq!(friction_force(1.0, 1e-2, 1e-3, 0.5, -4.0), (-2.0, true));
        assert_eq!(friction_force(1.0, 5.0, 1e-3, 0.0, 4.0), (0.0, true));
    }

    #[test]
    fn inverse_distance_weights_sum_to_one_and_floor_the_slave() {
        let mut w = Vec::new();
        let xs = Vec2::new(0.0, 0.0);
        let cands = [(3u32, xs), (4, Vec2::new(1.0, 0.0)), (5, Vec2::new(0.0, -2.0))];
        inverse_distance_weights(&xs, 0.5, cands, &mut w);
        let total: Real = w.iter().map(|e| e.1).sum();
        assert!((total - 1.0).abs() < 1e-15);
        // raw weights 2, 1, 0.5
        assert!((w[0].1 - 2.0 / 3.5).abs() < 1e-15 && (w[2].1 - 0.5 / 3.5).abs() < 1e-15);
    }
}
