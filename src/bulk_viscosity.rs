//! Artificial bulk viscosity: the linear and quadratic pressure that
//! explicit shock codes add to damp the ringing behind a compressive front
//! (von Neumann & Richtmyer; Wilkins). **Deviation from SPEC §5 and
//! \[RL10\]**, which have none; off unless a case asks for it
//! (`[time] bulk_viscosity`), so the paper's mode and every built-in case
//! keep their numbers.
//!
//! At a quadrature point with volumetric strain rate `ε̇_v = tr d`, density
//! `ρ = ρ₀/J`, dilatational wave speed `c_L` and current length `L`,
//!
//! `q = −b₁ ρ c_L L ε̇_v + ρ (b₂ L)² ε̇_v²` if `ε̇_v < 0`, `q = −b₁ ρ c_L L ε̇_v` otherwise,
//!
//! added to the pressure (`σ ← σ − q I`, `q > 0` in compression) in the
//! internal force only: the material's own stress, plastic flow, heating and
//! damage do not see it. A point fractured by its damage
//! (`crate::material::fractured`) keeps only the compressive part: it
//! carries no tension, viscous or not. The linear term is a damper of `b₁` of the critical
//! damping of the highest volumetric mode, in compression and expansion; the
//! quadratic term acts in compression only and spreads a shock over a few
//! lengths `L`. The form and the defaults `b₁ = 0.06`, `b₂ = 1.2` are those of
//! the common explicit codes (LS-DYNA writes the quadratic coefficient as
//! `Q = b₂² ≈ 1.5`, the linear one as 0.06). Its work `−q ε̇_v J dV₀ Δt ≥ 0`
//! in compression is counted in the internal energy, so the energy balance
//! still closes.
//!
//! `L` is the length of the point's background cell, `L₀ = √(Δx Δy)` of the
//! reference lattice ([`crate::quadrature::QuadraturePoints::length`]),
//! scaled by the in-plane area change, `L = L₀ √(F_xx F_yy − F_xy F_yx)`.
//!
//! **The stable step.** The damping lowers the critical step of the
//! central difference (whose force sees the velocity half a step back) by
//! the factor `√(1 + ξ²) − ξ` ([`step_factor`]), with the damping ratio of
//! a point's volumetric mode `ξ = b₁ − b₂² (L/c_L) min(0, ε̇_v)`
//! ([`BulkViscosity::damping_ratio`]): about 0.94 with the defaults at the
//! strain rates of a lattice of full particles. A light particle (a crack
//! split's child) raises its own frequency, and with it its damping ratio,
//! by the same factor `ω/ω_ref` by which the variable step already shrank
//! ([`crate::stability`]); so the step is the elastic one times
//! `step_factor(ξ_max · Δt₀/Δt_el)`, with `ξ_max` the largest ratio of the
//! last material update — conservative, as both maxima are taken apart.
//! Without it, Børvik's 12 mm plate at 300 m/s with 12 rows and `ℓ = 2 mm`
//! blew up at 22 µs (a split child on the axis at 4.9 km/s under 45 GPa);
//! with it, it runs to its end (`docs/validation.md`). Without viscosity
//! the factor is exactly 1 and the step is the elastic one, bit for bit.
//! Test `step_factor_is_the_central_difference_limit` (a damped oscillator
//! integrated as the solver does: stable just below the step, growing just
//! above).
//!
//! Why it exists here (issue #19): behind the compressive front that a
//! rigid projectile drives into the plate, the release converging on the
//! axis pulls the plug's interior into 4–7 GPa of hydrostatic tension at
//! 300 m/s, where the Johnson–Cook locus gives almost no ductility, and the
//! interior's damage passes the crack threshold of the default model. With
//! the viscosity the tension and the damage are smaller, and the residual
//! velocity of Børvik's 12 mm plate at 300 m/s is 240.5 / 238.7 / 243.1 m/s
//! at 12 / 24 / 48 rows (1.8 %; 10.5 % without); Cases I and II and the
//! ballistic limits move within their own scatter (`docs/validation.md`,
//! "At high speed the rigid projectile tears the plug's interior"). Off by
//! default until the whole report is rerun with it. Tests:
//! `tests/dynamics.rs`
//! (`bulk_viscosity_damps_the_ringing_behind_a_front_and_keeps_its_jump`:
//! the exact Riemann bar), `tests/checkpoint.rs` (a resumed run with it is
//! bit-identical), `tests/case_files.rs` and this module's.

use crate::math::Real;
use serde::{Deserialize, Serialize};

/// The two coefficients (`[time] bulk_viscosity = { linear, quadratic }`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BulkViscosity {
    /// `b₁`, the fraction of critical damping of the volumetric mode.
    #[serde(default = "linear_default")]
    pub linear: Real,
    /// `b₂`, in shock lengths.
    #[serde(default = "quadratic_default")]
    pub quadratic: Real,
}

fn linear_default() -> Real {
    BulkViscosity::COMMON.linear
}

fn quadratic_default() -> Real {
    BulkViscosity::COMMON.quadratic
}

impl BulkViscosity {
    /// No viscosity (SPEC §5, \[RL10\]). There is no `Default`: a value
    /// left unset (a field a checkpoint does not store) must be set from
    /// the case, not fall back to either of these.
    pub const NONE: BulkViscosity = BulkViscosity { linear: 0.0, quadratic: 0.0 };
    /// The common explicit codes' values, `b₁ = 0.06`, `b₂ = 1.2`.
    pub const COMMON: BulkViscosity = BulkViscosity { linear: 0.06, quadratic: 1.2 };

    /// [`Self::NONE`], for serde's `default` of a skipped field.
    pub fn none() -> Self {
        Self::NONE
    }

    /// Whether it adds anything.
    pub fn is_active(&self) -> bool {
        self.linear > 0.0 || self.quadratic > 0.0
    }

    /// The viscous pressure `q`, Pa (positive in compression), at density
    /// `density`, wave speed `wave_speed`, current length `length` and
    /// volumetric strain rate `volume_rate` (module doc).
    pub fn pressure(&self, density: Real, wave_speed: Real, length: Real, volume_rate: Real) -> Real {
        let linear = -self.linear * density * wave_speed * length * volume_rate;
        if volume_rate < 0.0 {
            linear + density * (self.quadratic * length * volume_rate).powi(2)
        } else {
            linear
        }
    }

    /// The damping ratio `ξ = b₁ − b₂² (L/c_L) min(0, ε̇_v)` of a point's
    /// volumetric mode at wave speed `wave_speed`, current length `length`
    /// and volumetric strain rate `volume_rate` (module doc): the fraction
    /// of critical damping the viscous pressure adds.
    pub fn damping_ratio(&self, wave_speed: Real, length: Real, volume_rate: Real) -> Real {
        self.linear - self.quadratic * self.quadratic * length / wave_speed * volume_rate.min(0.0)
    }

    /// Problems with the coefficients, as `(field, message)`: both finite
    /// and non-negative, `b₁ < 1` (at or past critical damping the
    /// explicit step is no longer stable at the CFL step).
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        if !(self.linear.is_finite() && (0.0..1.0).contains(&self.linear)) {
            out.push(("linear", format!("must lie in [0, 1) (a fraction of critical damping), got {}", self.linear)));
        }
        if !(self.quadratic.is_finite() && self.quadratic >= 0.0 && self.quadratic <= 4.0) {
            out.push(("quadratic", format!("must lie in [0, 4] (shock lengths), got {}", self.quadratic)));
        }
        out
    }
}

/// The factor `√(1 + ξ²) − ξ` by which a damping ratio `ξ` lowers the
/// critical step of the central difference when the damping force is taken
/// from the velocity half a step back (the solver's order): an oscillator
/// `ẍ + 2ξω ẋ + ω² x = 0` so integrated is stable for `ω Δt ≤ 2 (√(1 + ξ²) − ξ)`.
/// Exactly 1 at `ξ = 0`.
pub fn step_factor(damping_ratio: Real) -> Real {
    let xi = damping_ratio.max(0.0);
    if xi == 0.0 {
        1.0
    } else {
        (1.0 + xi * xi).sqrt() - xi
    }
}

/// The current length of a point whose reference cell length is `length0`
/// under the in-plane part of `F` (`F_xx F_yy − F_xy F_yx`, the area ratio of
/// the section): `L₀ √(area ratio)`.
#[inline]
pub fn current_length(length0: Real, in_plane_area_ratio: Real) -> Real {
    length0 * in_plane_area_ratio.max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The critical step of the central difference with lagged damping, as
    /// the solver integrates (`v ← v + Δt (−ω² x − 2ξω v)`, `x ← x + Δt v`):
    /// the oscillator stays bounded at 0.98 of `2 step_factor(ξ)/ω` and
    /// grows without bound at 1.02 of it, undamped, lightly and heavily damped.
    #[test]
    fn step_factor_is_the_central_difference_limit() {
        let omega = 1.0e6;
        let grows = |xi: Real, dt: Real| {
            let (mut x, mut v) = (1.0, 0.0);
            for _ in 0..20_000 {
                v += dt * (-omega * omega * x - 2.0 * xi * omega * v);
                x += dt * v;
            }
            // bounded (the undamped orbit's x swells towards the limit)
            // or grown past any bound
            x.is_nan() || x.abs() >= 1e3
        };
        for xi in [0.0, 0.06, 0.5, 2.0] {
            let critical = 2.0 * step_factor(xi) / omega;
            assert!(!grows(xi, 0.98 * critical), "xi = {xi}: unstable below the step");
            assert!(grows(xi, 1.02 * critical), "xi = {xi}: stable above the step");
        }
        assert_eq!(step_factor(0.0), 1.0);
        let b = BulkViscosity::COMMON;
        assert_eq!(b.damping_ratio(5000.0, 1e-3, 1e4), 0.06);
        assert!((b.damping_ratio(5000.0, 1e-3, -1e5) - (0.06 + 1.44 * 1e-3 / 5000.0 * 1e5)).abs() < 1e-15);
    }

    /// The closed forms: linear in both signs, quadratic in compression only.
    #[test]
    fn pressure_has_its_closed_form() {
        let b = BulkViscosity::COMMON;
        let (rho, c, l) = (7850.0, 5900.0, 1e-3);
        let rate = -2.0e5;
        let want = 0.06 * rho * c * l * 2.0e5 + rho * (1.2 * l * 2.0e5_f64).powi(2);
        assert!((b.pressure(rho, c, l, rate) / want - 1.0).abs() < 1e-14);
        // expansion: the linear damper only, a tension
        let want = -0.06 * rho * c * l * 2.0e5;
        assert!((b.pressure(rho, c, l, 2.0e5) / want - 1.0).abs() < 1e-14);
        assert_eq!(BulkViscosity::NONE.pressure(rho, c, l, rate), 0.0);
        assert!(!BulkViscosity::NONE.is_active() && b.is_active());
        assert_eq!(current_length(2e-3, 0.25), 1e-3);
    }

    #[test]
    fn bad_coefficients_are_named() {
        let p = BulkViscosity { linear: 1.0, quadratic: -1.0 }.problems();
        assert_eq!(p.iter().map(|(f, _)| *f).collect::<Vec<_>>(), ["linear", "quadratic"]);
        assert!(BulkViscosity::COMMON.problems().is_empty());
        assert!(BulkViscosity::NONE.problems().is_empty());
    }
}
