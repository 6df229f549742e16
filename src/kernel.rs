//! Window (kernel) functions of the RK approximation (SPEC §3).

use crate::math::{Real, Vec2};

/// 1D cubic B-spline `w(s)` on `|s| < 1` with `w(0) = 2/3`, and its
/// derivative `dw/ds`.
///
/// `w(s) = 2/3 − 4s² + 4|s|³` for `|s| ≤ 1/2`, `4/3 (1 − |s|)³` for
/// `1/2 < |s| < 1`, zero beyond.
#[inline]
pub fn window_cubic_spline_1d(s: Real) -> (Real, Real) {
    let r = s.abs();
    let sign = if s < 0.0 { -1.0 } else { 1.0 };
    if r <= 0.5 {
        (2.0 / 3.0 - 4.0 * r * r + 4.0 * r * r * r, sign * (-8.0 * r + 12.0 * r * r))
    } else if r < 1.0 {
        let t = 1.0 - r;
        (4.0 / 3.0 * t * t * t, sign * (-4.0 * t * t))
    } else {
        (0.0, 0.0)
    }
}

/// Tensor-product window `φ_a(Z) = w(Z_x/a) w(Z_y/a)` with `Z = X − X_I`
/// and its gradient with respect to `X` (SPEC §3).
#[inline]
pub fn window_cubic_spline_2d(z: &Vec2, a: Real) -> (Real, Vec2) {
    let (wx, dwx) = window_cubic_spline_1d(z.x / a);
    let (wy, dwy) = window_cubic_spline_1d(z.y / a);
    (wx * wy, Vec2::new(dwx * wy / a, wx * dwy / a))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_is_continuous_and_compact() {
        let (w0, d0) = window_cubic_spline_1d(0.0);
        assert!((w0 - 2.0 / 3.0).abs() < 1e-15 && d0 == 0.0);
        let (wl, dl) = window_cubic_spline_1d(0.5 - 1e-12);
        let (wr, dr) = window_cubic_spline_1d(0.5 + 1e-12);
        assert!((wl - wr).abs() < 1e-10 && (dl - dr).abs() < 1e-9);
        assert_eq!(window_cubic_spline_1d(1.0), (0.0, 0.0));
        assert_eq!(window_cubic_spline_1d(-1.5), (0.0, 0.0));
        // integrates to 1/2 over (-1, 1): the constant cancels in RK but check the shape
        let n = 20000;
        let h = 2.0 / n as f64;
        let integral: f64 = (0..n).map(|k| window_cubic_spline_1d(-1.0 + (k as f64 + 0.5) * h).0 * h).sum();
        assert!((integral - 0.5).abs() < 1e-8);
    }

    #[test]
    fn derivative_matches_finite_difference() {
        for &s in &[-0.9, -0.6, -0.3, -0.05, 0.1, 0.45, 0.55, 0.8, 0.99] {
            let h = 1e-6;
            let fd = (window_cubic_spline_1d(s + h).0 - window_cubic_spline_1d(s - h).0) / (2.0 * h);
            assert!((fd - window_cubic_spline_1d(s).1).abs() < 1e-7, "s = {s}");
        }
        let z = Vec2::new(0.3, -0.7);
        let a = 1.3;
        let (_, g) = window_cubic_spline_2d(&z, a);
        let h = 1e-7;
        for k in 0..2 {
            let mut zp = z;
            let mut zm = z;
            zp[k] += h;
            zm[k] -= h;
            let fd = (window_cubic_spline_2d(&zp, a).0 - window_cubic_spline_2d(&zm, a).0) / (2.0 * h);
            assert!((fd - g[k]).abs() < 1e-7);
        }
    }
}
