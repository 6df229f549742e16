//! Verification of the RK shape functions (SPEC §3): reproducing conditions
//! on uniform and graded particle sets, exact reproduction of XY, analytic
//! gradients, and the ill-conditioned-moment error.

use plugsim::discretize::RectangleGrid;
use plugsim::geometry::GeometryMode;
use plugsim::math::{Real, Vec2};
use plugsim::shape::{build_table, AllVisible, ShapeError, ShapeTable};

fn grid(growth: Real, support_factor: Real) -> RectangleGrid {
    RectangleGrid {
        x_min: -0.03,
        x_max: 0.03,
        y_min: 0.0,
        y_max: 0.01,
        layers: 9,
        refine_at: Some(0.004),
        fine_half_width: 0.005,
        fine_spacing: None,
        column_at: None,
        growth,
        coarse_spacing: Some(0.004),
        support_factor,
        gauss: 2,
    }
}

/// The particles and points of [`grid`], resolved and generated in `mode`.
fn generated(growth: Real, support_factor: Real, mode: GeometryMode) -> plugsim::discretize::GeneratedBody {
    let mut g = grid(growth, support_factor);
    g.resolve(mode);
    g.generate(mode)
}

/// Max relative violations of the reproducing conditions over all rows.
fn check_reproduction(t: &ShapeTable, pts: &[Vec2], x0: &[Vec2], scale: Real) -> [Real; 6] {
    let mut worst = [0.0; 6];
    for (p, x) in pts.iter().enumerate() {
        let (mut s0, mut s1, mut sxy) = (0.0, Vec2::zeros(), 0.0);
        let (mut g0, mut g1) = (Vec2::zeros(), nalgebra::Matrix2::<Real>::zeros());
        let mut gxy = Vec2::zeros();
        for k in t.range(p) {
            let i = t.index[k] as usize;
            let xi = x0[i];
            s0 += t.value[k];
            s1 += xi * t.value[k];
            sxy += xi.x * xi.y * t.value[k];
            g0 += t.grad[k];
            g1 += xi * t.grad[k].transpose();
            gxy += t.grad[k] * (xi.x * xi.y);
        }
        let w = [
            (s0 - 1.0).abs(),
            (s1 - x).norm() / scale,
            (sxy - x.x * x.y).abs() / (scale * scale),
            g0.norm() * scale,
            (g1 - nalgebra::Matrix2::identity()).norm(),
            (gxy - Vec2::new(x.y, x.x)).norm() / scale,
        ];
        for c in 0..6 {
            worst[c] = Real::max(worst[c], w[c]);
        }
    }
    worst
}

fn reproduces(growth: Real) {
    let b = generated(growth, 2.0, GeometryMode::PlaneStrain);
    for pts in [&b.quad_points, &b.particles] {
        let t = build_table(pts, &b.particles, &b.support, &b.volume, &AllVisible).unwrap();
        let worst = check_reproduction(&t, pts, &b.particles, 0.06);
        for (c, name) in
            ["sum N", "sum N X", "sum N XY", "sum grad N", "sum grad N (x) X", "grad of XY"].iter().enumerate()
        {
            assert!(worst[c] < 1e-12, "{name}: {:e} (growth {growth})", worst[c]);
        }
    }
}

#[test]
fn reproducing_conditions_uniform() {
    reproduces(1.0);
}

#[test]
fn reproducing_conditions_graded() {
    reproduces(1.25);
}

#[test]
fn gradients_match_finite_differences_of_values() {
    let b = generated(1.2, 2.0, GeometryMode::PlaneStrain);
    let x = Vec2::new(0.0071, 0.0043);
    let h = 1e-7;
    let eval = |p: Vec2| build_table(&[p], &b.particles, &b.support, &b.volume, &AllVisible).unwrap();
    let t = eval(x);
    let tx = [eval(x + Vec2::new(h, 0.0)), eval(x - Vec2::new(h, 0.0))];
    let ty = [eval(x + Vec2::new(0.0, h)), eval(x - Vec2::new(0.0, h))];
    let value_of = |t: &ShapeTable, i: u32| t.range(0).find(|&k| t.index[k] == i).map_or(0.0, |k| t.value[k]);
    let mut checked = 0;
    for k in t.range(0) {
        let i = t.index[k];
        let fd = Vec2::new(
            (value_of(&tx[0], i) - value_of(&tx[1], i)) / (2.0 * h),
            (value_of(&ty[0], i) - value_of(&ty[1], i)) / (2.0 * h),
        );
        let scale = t.grad.iter().map(|g| g.norm()).fold(0.0, Real::max);
        assert!((fd - t.grad[k]).norm() < 1e-6 * scale, "particle {i}: fd {fd:?} vs {:?}", t.grad[k]);
        checked += 1;
    }
    assert!(checked >= 9);
}

#[test]
fn too_small_support_is_a_clear_error_not_nan() {
    let b = generated(1.0, 0.55, GeometryMode::PlaneStrain);
    let err = build_table(&b.quad_points, &b.particles, &b.support, &b.volume, &AllVisible).unwrap_err();
    let ShapeError::SingularMoment { neighbours, .. } = err.clone();
    assert!(neighbours < 16);
    assert!(err.to_string().contains("singular"), "{err}");
}

/// The fused sweep of gradients and values (`gradient_pair_and_values`,
/// the axisymmetric material update's) gives the bits of
/// `gradient_pair` and `interpolate` formed apart, at every point of a
/// graded set, and the values reproduce a linear field.
#[test]
fn fused_gradients_and_values_have_the_bits_of_each_apart() {
    let b = generated(1.2, 2.0, GeometryMode::Axisymmetric);
    let t = build_table(&b.quad_points, &b.particles, &b.support, &b.volume, &AllVisible).unwrap();
    // Two fields with no structure the sums could hide a reordering in.
    let field = |s: Real| -> Vec<Vec2> {
        b.particles
            .iter()
            .enumerate()
            .map(|(i, x)| Vec2::new((s * i as Real).sin() + x.x, (1.3 * s * i as Real).cos() - x.y))
            .collect()
    };
    let (a, c) = (field(0.7), field(1.9));
    let bits = |m: &nalgebra::Matrix2<Real>| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    for p in 0..b.quad_points.len() {
        let (ga, gc, va, vc) = t.gradient_pair_and_values(p, &a, &c);
        let (ga0, gc0) = t.gradient_pair(p, &a, &c);
        assert_eq!((bits(&ga), bits(&gc)), (bits(&ga0), bits(&gc0)), "point {p}");
        let (va0, vc0) = (t.interpolate(p, &a), t.interpolate(p, &c));
        assert_eq!(
            [va.x.to_bits(), va.y.to_bits(), vc.x.to_bits(), vc.y.to_bits()],
            [va0.x.to_bits(), va0.y.to_bits(), vc0.x.to_bits(), vc0.y.to_bits()]
        );
    }
    // A linear field is reproduced (SPEC §3), value and gradient.
    let lin: Vec<Vec2> = b.particles.iter().map(|x| Vec2::new(2.0 * x.x - x.y, 0.5 * x.y)).collect();
    for (p, x) in b.quad_points.iter().enumerate() {
        let (gl, _, vl, _) = t.gradient_pair_and_values(p, &lin, &lin);
        assert!((vl - Vec2::new(2.0 * x.x - x.y, 0.5 * x.y)).norm() < 1e-12, "point {p}");
        assert!((gl - nalgebra::Matrix2::new(2.0, -1.0, 0.0, 0.5)).norm() < 1e-8, "point {p}: {gl}");
    }
}
