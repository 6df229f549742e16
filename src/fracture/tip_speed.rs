//! The crack tip's speed limited by the material (issue #19; deviation
//! from SPEC §9, module doc of [`crate::fracture`]).
//!
//! \[RL10\]'s tip jumps to the best candidate within `R ≈ 2.5 h` in any step
//! whose material ahead meets the criterion: up to `R/Δt`, hundreds of
//! km/s at the CFL step, whereas no crack outruns the Rayleigh wave
//! (`c_R ≈ 2.9 km/s` in steel; Freund, *Dynamic Fracture Mechanics*, 1990,
//! §5.3). With `"nonlocal_damage"` a growing tip carries an **allowance**:
//! each stage adds `c_max Δt` to it, and the tip advances to its chosen
//! candidate only when the allowance covers the distance, which is then
//! subtracted ([`advance`]). The allowance is reset when no candidate
//! exists (a stalled tip does not store up speed), so the tip's speed,
//! averaged over any advance, is at most `c_max`. Arrest at the outer
//! surface is not limited (the tip is there already).
//!
//! In 3D the same rule holds for each front vertex along its normal in the
//! crack plane: the allowance is a length per front point.

use crate::math::Real;

/// Rayleigh wave speed of an isotropic elastic solid with shear modulus
/// `g`, bulk modulus `k` and density `rho` (SI), m/s: the root
/// `ξ = c_R/c_S ∈ (0, 1)` of
/// `(2 − ξ²)² = 4 √(1 − ξ² c_S²/c_L²) √(1 − ξ²)`, by bisection.
pub fn rayleigh_wave_speed(g: Real, k: Real, rho: Real) -> Real {
    let cs2 = g / rho;
    let cl2 = (k + 4.0 * g / 3.0) / rho;
    let kappa = cs2 / cl2;
    let f = |xi: Real| {
        let x2 = xi * xi;
        (2.0 - x2).powi(2) - 4.0 * (1.0 - x2 * kappa).sqrt() * (1.0 - x2).sqrt()
    };
    // ξ = 0 is a trivial root; f ≈ −2(1 − κ)ξ² < 0 just above it and
    // f(1) = 1 > 0, so the one root in (0, 1) — above 0.87 for ν ≥ 0 — is
    // bracketed by [0.5, 1], where f(0.5) < 0.
    let (mut lo, mut hi) = (0.5, 1.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi) * cs2.sqrt()
}

/// One stage of a tip with stored allowance `allowance` (m), speed limit
/// `speed` (m/s), time since the last stage `dt` (s), and its chosen
/// candidate at `distance` (m; `None`: no candidate). Returns whether the
/// tip advances now and the allowance it keeps.
pub fn advance(allowance: Real, speed: Real, dt: Real, distance: Option<Real>) -> (bool, Real) {
    match distance {
        None => (false, 0.0),
        Some(d) => {
            let a = allowance + speed * dt;
            if a >= d {
                (true, a - d)
            } else {
                (false, a)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ν = 1/4 (K = 5G/3): the exact root is `ξ² = 2 − 2/√3`
    /// (Rayleigh 1885), `ξ = 0.919402`.
    #[test]
    fn rayleigh_speed_for_poisson_quarter_is_rayleighs_root() {
        let (g, rho) = (80e9, 7850.0);
        let c = rayleigh_wave_speed(g, 5.0 * g / 3.0, rho);
        let exact = (2.0 - 2.0 / 3.0_f64.sqrt()).sqrt() * (g / rho).sqrt();
        assert!((c / exact - 1.0).abs() < 1e-12, "{c} vs {exact}");
    }

    /// Viktorov's approximation `c_R/c_S ≈ (0.862 + 1.14 ν)/(1 + ν)` is
    /// within 0.5 % of the root for 0.2 ≤ ν < 0.5 (1.4 % at ν = 0).
    #[test]
    fn rayleigh_speed_follows_viktorovs_approximation() {
        let (e, rho) = (200e9, 7850.0);
        for nu in [0.2, 0.25, 0.3, 0.33, 0.4, 0.45] {
            let g = e / (2.0 * (1.0 + nu));
            let k = e / (3.0 * (1.0 - 2.0 * nu));
            let c = rayleigh_wave_speed(g, k, rho);
            let approx = (0.862 + 1.14 * nu) / (1.0 + nu) * (g / rho).sqrt();
            assert!((c / approx - 1.0).abs() < 5e-3, "nu = {nu}: {c} vs {approx}");
        }
    }

    /// Steps of `dt` toward candidates one spacing `h` ahead at speed `c`:
    /// the tip advances every `h/(c dt)` stages on average.
    #[test]
    fn allowance_paces_the_tip() {
        let (h, c, dt) = (1.0e-4, 1850.0, 2.0e-8); // c dt = 0.37 h
        let (mut a, mut moved) = (0.0, 0);
        for _ in 0..150 {
            let (go, rest) = advance(a, c, dt, Some(h));
            a = rest;
            moved += go as usize;
        }
        // 150 stages × 0.37 h = 55.5 h of allowance: 55 advances.
        assert_eq!(moved, 55);
        // No candidate: the allowance is dropped.
        assert_eq!(advance(0.9 * h, c, dt, None), (false, 0.0));
    }
}
