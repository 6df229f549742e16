//! Solution verification over a ladder of resolutions: how far a result
//! (a residual velocity, a ballistic limit) moves as the particle spacing
//! is refined, and what the moves say about the answer at zero spacing.
//!
//! - [`spread`]: `(max − min) / mean` over the rungs, issue #19's measure
//!   of "the same answer at every resolution"; [`spread_within`] gives
//!   with it the least and most it can be when each value is a bracket.
//! - [`step`]: the change from one rung to the next, with the least and
//!   most it can be when each value is a bracket (a bisected limit).
//! - [`richardson`]: from the three finest rungs, the observed order of
//!   convergence, Richardson's extrapolation to zero spacing and Roache's
//!   grid convergence index of the finest rung, by the procedure of Celik
//!   et al. (2008, J. Fluids Eng. 130, 078001), the one ASME V&V 20
//!   adopts. It is reported only for **monotone convergence** — steps of
//!   one sign, each smaller than the one before: Celik's formula takes
//!   `|ε₃₂/ε₂₁|` and so returns an "order" for steps that grow as well,
//!   which would read a diverging ladder as a converged one. Steps that
//!   grow or change sign are named as such ([`Asymptotic`]). A step within
//!   the rungs' own uncertainty (a limit's bracket) gives no order either:
//!   its sign is not known.
//!
//! None of it is a criterion of the solver: it reads finished runs
//! (`plugsim ballistic --rows`, `plugsim validate --family convergence`).

use crate::math::Real;

/// `(max − min) / mean` of `values` (`None` for fewer than two).
pub fn spread(values: &[Real]) -> Option<Real> {
    if values.len() < 2 {
        return None;
    }
    let (lo, hi) = values.iter().fold((Real::MAX, Real::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    Some((hi - lo) / (values.iter().sum::<Real>() / values.len() as Real))
}

/// [`spread`] of values each given as (value, half-width of its bracket):
/// (central, least, most). The central spread is that of the values; the
/// least and most are the smallest and largest `max − min` that values
/// anywhere in their brackets can give (the least 0 where every bracket
/// shares a point), each relative to the mean of the values. `None` for
/// fewer than two.
pub fn spread_within(values: &[(Real, Real)]) -> Option<(Real, Real, Real)> {
    let central = spread(&values.iter().map(|v| v.0).collect::<Vec<_>>())?;
    let mean = values.iter().map(|v| v.0).sum::<Real>() / values.len() as Real;
    let highest_low = values.iter().map(|(v, h)| v - h).fold(Real::MIN, Real::max);
    let lowest_high = values.iter().map(|(v, h)| v + h).fold(Real::MAX, Real::min);
    let lowest_low = values.iter().map(|(v, h)| v - h).fold(Real::MAX, Real::min);
    let highest_high = values.iter().map(|(v, h)| v + h).fold(Real::MIN, Real::max);
    Some((central, (highest_low - lowest_high).max(0.0) / mean, (highest_high - lowest_low) / mean))
}

/// The change from `coarse` to `fine` relative to `coarse`, each given as
/// (value, half-width of its bracket): (central, least, most), the least and
/// most being the change when each value may lie anywhere in its bracket
/// (a residual velocity has half-width 0, a ballistic limit its bisection's).
pub fn step(coarse: (Real, Real), fine: (Real, Real)) -> (Real, Real, Real) {
    let ((c, hc), (f, hf)) = (coarse, fine);
    ((f - c) / c, (f - hf - (c + hc)) / (c + hc), (f + hf - (c - hc)) / (c - hc))
}

/// One rung of a ladder for [`richardson`]: the particle spacing `h` (m,
/// any unit: only ratios enter), the value and the half-width of its
/// bracket (0 for a value known to its digits).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rung {
    pub spacing: Real,
    pub value: Real,
    pub half_width: Real,
}

/// Richardson's extrapolation from three rungs in monotone convergence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extrapolation {
    /// Observed order of convergence `p` (the error falls as `hᵖ`).
    pub order: Real,
    /// The value at zero spacing, `φ_ext = (r₂₁ᵖ φ₁ − φ₂) / (r₂₁ᵖ − 1)`.
    pub extrapolated: Real,
    /// Grid convergence index of the finest rung, relative:
    /// `1.25 |(φ₁ − φ₂)/φ₁| / (r₂₁ᵖ − 1)` (safety factor 1.25 for three
    /// rungs, Roache 1998): a band that holds the zero-spacing value with
    /// about 95 % confidence once the ladder is in its asymptotic range.
    pub gci_fine: Real,
}

/// What three rungs say about convergence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Asymptotic {
    /// Steps of one sign, each smaller than the one before.
    Converging(Extrapolation),
    /// No positive order fits: the last step is too large for the ladder
    /// to be converging (with equal refinement ratios: at least as large
    /// as the one before).
    StepsGrow,
    /// The steps change sign.
    Oscillating,
    /// A step is within the rungs' brackets (its sign is not known), both
    /// steps are zero, or the order would exceed 1000.
    Unresolved,
}

/// [`Asymptotic`] of the three finest of `rungs` (any order; `None` for
/// fewer than three or equal spacings). Celik et al. (2008), steps 3–5,
/// with `1` the finest rung: `ε₃₂ = φ₃ − φ₂`, `ε₂₁ = φ₂ − φ₁`,
/// `r = h_coarse / h_fine`, and the order solves
/// `p = ln(ε₃₂/ε₂₁) / ln r₂₁ + ln((r₂₁ᵖ − 1)/(r₃₂ᵖ − 1)) / ln r₂₁`
/// (with equal ratios the second term is 0), here by bisection: the
/// right-hand side's `ε₃₂/ε₂₁` is monotone in `p`, where Celik's
/// fixed-point iteration can fail to converge.
pub fn richardson(rungs: &[Rung]) -> Option<Asymptotic> {
    let mut r: Vec<Rung> = rungs.to_vec();
    r.sort_by(|a, b| a.spacing.total_cmp(&b.spacing));
    let [f1, f2, f3] = [*r.first()?, *r.get(1)?, *r.get(2)?];
    let (r21, r32) = (f2.spacing / f1.spacing, f3.spacing / f2.spacing);
    if !(r21 > 1.0 && r32 > 1.0) {
        return None;
    }
    let (e32, e21) = (f3.value - f2.value, f2.value - f1.value);
    if e32.abs() <= f3.half_width + f2.half_width || e21.abs() <= f2.half_width + f1.half_width {
        return Some(Asymptotic::Unresolved);
    }
    if e32 * e21 < 0.0 {
        return Some(Asymptotic::Oscillating);
    }
    // `ε₃₂/ε₂₁ = r₂₁ᵖ (r₃₂ᵖ − 1) / (r₂₁ᵖ − 1)` for `φ = φ₀ + C hᵖ`, which
    // rises with `p` from `ln r₃₂ / ln r₂₁` at `p → 0`: a positive order
    // exists only above that (1 with equal ratios: a smaller last step).
    let ratio = e32 / e21; // > 0
    let model = |p: Real| p * r21.ln() + (r32.powf(p) - 1.0).ln() - (r21.powf(p) - 1.0).ln();
    if ratio.ln() <= r32.ln().ln() - r21.ln().ln() {
        return Some(Asymptotic::StepsGrow);
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    while model(hi) < ratio.ln() {
        (lo, hi) = (hi, 2.0 * hi);
        if hi > 1e3 {
            return Some(Asymptotic::Unresolved);
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if model(mid) < ratio.ln() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = 0.5 * (lo + hi);
    let rp = r21.powf(p);
    Some(Asymptotic::Converging(Extrapolation {
        order: p,
        extrapolated: (rp * f1.value - f2.value) / (rp - 1.0),
        gci_fine: 1.25 * ((f1.value - f2.value) / f1.value).abs() / (rp - 1.0),
    }))
}

/// A table cell for [`richardson`]'s answer: "p = 1.65, 112.28, GCI 1.2 %",
/// or what kept it from one.
pub fn describe(a: Option<Asymptotic>) -> String {
    match a {
        None => "—".into(),
        Some(Asymptotic::Converging(e)) => {
            format!("p = {:.2}, {:.2}, GCI {:.1} %", e.order, e.extrapolated, 100.0 * e.gci_fine)
        }
        Some(Asymptotic::StepsGrow) => "steps grow: no order".into(),
        Some(Asymptotic::Oscillating) => "steps change sign: no order".into(),
        Some(Asymptotic::Unresolved) => "a step within the brackets: no order".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rung(spacing: Real, value: Real) -> Rung {
        Rung { spacing, value, half_width: 0.0 }
    }

    /// A ladder that follows `φ(h) = φ₀ + C hᵖ` exactly gives back `p`, `φ₀`
    /// and a GCI that holds `φ₀`, for equal and for unequal refinement
    /// ratios (the last one a ladder whose last step, 4× in spacing, is
    /// larger than the one before, 1.25×: converging all the same), and in
    /// any order of the rungs.
    #[test]
    fn an_exact_power_law_gives_back_its_order_and_limit() {
        for (p, c, hs) in [
            (2.0, 3.0, [1.0, 0.5, 0.25]),
            (1.3, -7.0, [0.9, 0.5, 0.2]),
            (0.7, 2.0, [4.0, 1.5, 1.0]),
            (1.0, 5.0, [1.25, 1.0, 0.25]),
        ] {
            let phi = |h: Real| 100.0 + c * Real::powf(h, p);
            let rungs: Vec<Rung> = [hs[1], hs[2], hs[0]].iter().map(|&h| rung(h, phi(h))).collect();
            let Some(Asymptotic::Converging(e)) = richardson(&rungs) else { panic!("{hs:?}: not converging") };
            assert!((e.order - p).abs() < 1e-9, "order {} against {p}", e.order);
            assert!((e.extrapolated - 100.0).abs() < 1e-9, "extrapolated {}", e.extrapolated);
            // Exact: `|φ₁ − φ₂| / (r₂₁ᵖ − 1) = |φ₁ − φ₀|`, so the GCI is 1.25
            // times the finest rung's relative error.
            let err = (phi(hs[2]) - 100.0).abs() / phi(hs[2]);
            assert!((e.gci_fine - 1.25 * err).abs() < 1e-9 * err, "GCI {} against 1.25 × {err}", e.gci_fine);
        }
    }

    /// Celik et al. (2008), Table 1: their three-grid example (the first
    /// of their variables, φ₁ = 6.063, φ₂ = 5.972, φ₃ = 5.863 on grids with
    /// r₂₁ = 1.5, r₃₂ = 1.333) gives p = 1.53, φ_ext = 6.1685 and
    /// GCI_fine = 2.2 %.
    #[test]
    fn celik_et_al_s_worked_example() {
        let h1 = 1.0;
        let (h2, h3) = (1.5 * h1, 1.5 * 1.333 * h1);
        let Some(Asymptotic::Converging(e)) = richardson(&[rung(h1, 6.063), rung(h2, 5.972), rung(h3, 5.863)]) else {
            panic!("not converging")
        };
        assert!((e.order - 1.53).abs() < 0.01, "p = {}", e.order);
        assert!((e.extrapolated - 6.1685).abs() < 2e-3, "φ_ext = {}", e.extrapolated);
        assert!((100.0 * e.gci_fine - 2.2).abs() < 0.05, "GCI = {} %", 100.0 * e.gci_fine);
    }

    /// The 12 mm plate's limits scanned at 1 m/s steps (docs/validation.md,
    /// "Sharp and mixed limits"): 136.50 / 125.50 / 119.50 ± 0.50 m/s at
    /// 12 / 24 / 48 rows. The steps −11 and −6 give `2ᵖ = 11/6`, so
    /// `p = log₂(11/6) = 0.874`, `φ_ext = 119.5 − 6 / (5/6) = 112.30` and
    /// `GCI = 1.25 × 7.2 / 119.5 = 7.53 %`. Case I's and Case II's
    /// scanned ladders (124.50 / 122.50 / 115.75 ± 0.25 and 123.50 /
    /// 121.50 / 118.75 ± 0.25) have steps that grow.
    #[test]
    fn the_scanned_ladders_by_hand() {
        let limits = |v: [Real; 3], h: [Real; 3]| -> Vec<Rung> {
            (0..3).map(|i| Rung { spacing: 4.0 / (1 << i) as Real, value: v[i], half_width: h[i] }).collect()
        };
        let Some(Asymptotic::Converging(e)) = richardson(&limits([136.5, 125.5, 119.5], [0.5; 3])) else {
            panic!("not converging")
        };
        assert!((e.order - (11.0 / 6.0 as Real).log2()).abs() < 1e-9, "p = {}", e.order);
        assert!((e.extrapolated - 112.3).abs() < 1e-9, "φ_ext = {}", e.extrapolated);
        assert!((e.gci_fine - 1.25 * 7.2 / 119.5).abs() < 1e-12, "GCI = {}", e.gci_fine);
        assert_eq!(richardson(&limits([124.5, 122.5, 115.75], [0.5, 0.5, 0.25])), Some(Asymptotic::StepsGrow));
        assert_eq!(richardson(&limits([123.5, 121.5, 118.75], [0.5, 0.5, 0.25])), Some(Asymptotic::StepsGrow));
    }

    /// Steps that grow, change sign or lie within the brackets give no
    /// order; so do fewer than three rungs.
    #[test]
    fn no_order_outside_monotone_convergence() {
        let grow = [rung(4.0, 244.76), rung(2.0, 246.18), rung(1.0, 248.91)];
        assert_eq!(richardson(&grow), Some(Asymptotic::StepsGrow));
        let swing = [rung(4.0, 136.88), rung(2.0, 126.67), rung(1.0, 130.0)];
        assert_eq!(richardson(&swing), Some(Asymptotic::Oscillating));
        let mut bracketed = [rung(4.0, 123.14), rung(2.0, 115.75), rung(1.0, 113.39)];
        bracketed[1].half_width = 1.5;
        bracketed[2].half_width = 1.0;
        assert_eq!(richardson(&bracketed), Some(Asymptotic::Unresolved));
        assert_eq!(richardson(&grow[..2]), None);
        assert_eq!(describe(richardson(&grow)), "steps grow: no order");
    }

    #[test]
    fn spread_and_step_by_hand() {
        assert_eq!(spread(&[1.0]), None);
        assert!((spread(&[90.0, 110.0]).unwrap() - 0.2).abs() < 1e-15);
        assert_eq!(spread_within(&[(1.0, 0.5)]), None);
        // Case II's plate at 24 / 48 / 72 rows (docs/validation.md): the
        // middles 173.23 / 176.93 / 175.85 m/s are 3.70 / 175.337 = 2.1 %
        // apart; the brackets' nearest ends, 173.71 and 175.85, 1.2 %, and
        // their farthest, 172.75 and 178.01, 3.0 %.
        let (mid, least, most) = spread_within(&[(173.23, 0.48), (176.93, 1.08), (175.85, 2.15)]).unwrap();
        let mean = (173.23 + 176.93 + 175.85) / 3.0;
        assert!((mid - 3.70 / mean).abs() < 1e-12 && (100.0 * mid - 2.11).abs() < 0.01, "{mid}");
        assert!((least - (176.93 - 1.08 - (173.23 + 0.48)) / mean).abs() < 1e-12, "{least}");
        assert!((most - (176.93 + 1.08 - (173.23 - 0.48)) / mean).abs() < 1e-12, "{most}");
        assert!((100.0 * least - 1.22).abs() < 0.01 && (100.0 * most - 3.00).abs() < 0.01, "{least} {most}");
        // brackets that overlap can all hold one value: no least spread
        let (mid, least, most) = spread_within(&[(100.0, 2.0), (103.0, 2.0)]).unwrap();
        assert!((mid - 3.0 / 101.5).abs() < 1e-15 && least == 0.0 && (most - 7.0 / 101.5).abs() < 1e-15);
        // exact values: all three the same
        let (mid, least, most) = spread_within(&[(90.0, 0.0), (110.0, 0.0)]).unwrap();
        assert!((mid - 0.2).abs() < 1e-15 && least == mid && most == mid);
        let (mid, least, most) = step((100.0, 1.0), (98.0, 0.5));
        assert!((mid + 0.02).abs() < 1e-15);
        assert!((least - (97.5 - 101.0) / 101.0).abs() < 1e-15);
        assert!((most - (98.5 - 99.0) / 99.0).abs() < 1e-15);
    }
}
