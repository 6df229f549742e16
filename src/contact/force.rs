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
//! - **Effective mass.** `m` is the mass the force actually moves at the
//!   point where the gap is measured: `m_s` for [`Spreading::None`],
//!   `m_s / w_ss` for [`Spreading::InverseDistance`] (the slave keeps only
//!   its own weight `w_ss` of the force; [RL10, §3] uses `m_s`, which removes
//!   only that fraction), and `m_eff = (Σ_J N_J(X_s)² / m_J)⁻¹` for
//!   [`Spreading::ShapeFunction`], whose gap point is
//!   `x(X_s) = X_s + Σ_J N_J(X_s) U_J` and whose force `f_J = N_J F` moves
//!   that point by `Δt² F / m_eff` (for a top-row particle of a uniform
//!   lattice `m_eff = 2 m_s`: with `m_s` only half the penetration would go).
//!   Where several slaves share particles the forces are solved together
//!   (`ContactSystem::compute_forces`). Test:
//!   `shape_function_contact_of_an_isolated_point_is_exact`.
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
