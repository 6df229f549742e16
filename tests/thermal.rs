//! Verification of heat conduction (SPEC §7, `src/thermal.rs`): the erfc
//! solution of a temperature step, exact heat conservation, no spurious flux,
//! the axisymmetric Laplacian, the case switch, thread-count parity.

use plugsim::case::Case;
use plugsim::discretize::RectangleGrid;
use plugsim::geometry::GeometryMode;
use plugsim::material::{Elastic, Material, ThermalProperties};
use plugsim::math::Real;
use plugsim::model::{BodySetup, Model};
use plugsim::run::build_simulation;
use plugsim::thermal::{HeatConduction, DEFAULT_SAFETY_FACTOR};

const RHO: Real = 2000.0;
const CP: Real = 500.0;

/// A rectangle with uniform spacing `h` along x and through the thickness.
fn grid(x: (Real, Real), y: (Real, Real), h: Real) -> RectangleGrid {
    RectangleGrid::uniform(x, y, h)
}

fn conductor(kappa: Real) -> Material {
    Material::Elastic(Elastic {
        density: RHO,
        youngs_modulus: 1e9,
        poisson_ratio: 0.3,
        room_temperature: 300.0,
        thermal: Some(ThermalProperties { specific_heat: CP, conductivity: kappa }),
    })
}

fn model(mode: GeometryMode, g: RectangleGrid, kappa: Real) -> Model {
    let b = BodySetup {
        name: "bar".into(),
        grid: g,
        material: conductor(kappa),
        initial_velocity: vec![],
        supports: vec![],
    };
    Model::build(mode, &[b]).unwrap()
}

/// Complementary error function, Numerical Recipes' Chebyshev fit
/// (`erfcc`), fractional error below 1.2e-7 everywhere.
fn erfc(x: Real) -> Real {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let p = -z * z - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    let r = t * p.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

#[test]
fn erfc_matches_reference_values() {
    // reference values from the series / mpmath to 16 digits
    for (x, want) in [
        (0.0, 1.0),
        (0.1, 0.8875370839817152),
        (0.5, 0.4795001221869535),
        (1.0, 0.15729920705028513),
        (2.0, 0.004677734981047266),
        (3.0, 2.209049699858544e-5),
        (-1.0, 1.8427007929497148),
    ] {
        assert!((erfc(x) - want).abs() <= 1.2e-7 * want, "erfc({x}) = {} vs {want}", erfc(x));
    }
}

/// Deterministic pseudo-random numbers in [0, 1).
fn lcg(s: &mut u64) -> Real {
    *s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    (*s >> 11) as Real / (1u64 << 53) as Real
}

/// `Σ_q ρ₀ C_p w_q T_q`: the heat content of the quadrature points, J.
fn quad_heat(m: &Model) -> Real {
    m.quad.weight.iter().zip(&m.quad.temperature).map(|(w, t)| RHO * CP * w * t).sum()
}

/// `Σ_I c_I T_I` over the particles.
fn particle_heat(m: &Model, heat: &HeatConduction) -> Real {
    (0..m.particles.len()).map(|i| heat.capacity(m, i).unwrap() * m.particles.temperature[i]).sum()
}

/// Physical temperature at the particles, `T(X_I) = Σ_J N_J(X_I) T_J`.
fn physical_temperature(m: &Model) -> Vec<Real> {
    let tab = &m.particle_shape;
    (0..m.particles.len())
        .map(|i| tab.range(i).map(|k| tab.value[k] * m.particles.temperature[tab.index[k] as usize]).sum())
        .collect()
}

/// A temperature step in a long insulated bar (plane strain, no mechanics,
/// F = I; T1 for x < 0, T0 for x > 0) spreads as
/// `T = T0 + (T1−T0)/2 · erfc(x / (2√(αt)))` (= `(T0+T1)/2 − (T1−T0)/2 ·
/// erf(…)`), `α = κ/(ρ C_p)`. Checked at the centreline particles (physical value)
/// and at the quadrature points away from the initial jump, after 20 calls
/// (as 20 mechanical steps), each sub-cycled, when the diffusion length
/// 2√(αt) is 12 particle spacings and the ends (100 spacings away) are still
/// at their initial temperatures.
#[test]
fn temperature_step_in_a_bar_follows_erfc() {
    let h = 2e-3;
    let (t0, t1) = (300.0, 400.0);
    let kappa = 1e6; // α = 1 m²/s
    let alpha = kappa / (RHO * CP);
    let mut m = model(GeometryMode::PlaneStrain, grid((-0.2, 0.2), (0.0, 4.0 * h), h), kappa);
    for q in 0..m.quad.len() {
        m.quad.temperature[q] = if m.quad.x0[q].x < 0.0 { t1 } else { t0 };
    }
    let t_end = (12.0 * h / 2.0).powi(2) / alpha;
    let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
    let calls = 20;
    let mut substeps = 0;
    for _ in 0..calls {
        substeps += heat.conduct(&mut m, t_end / calls as Real).unwrap().substeps;
    }
    assert!(substeps > calls, "the test must exercise sub-cycling ({substeps} sub-steps)");
    let exact = |x: Real| t0 + 0.5 * (t1 - t0) * erfc(x / (2.0 * (alpha * t_end).sqrt()));
    let step = t1 - t0;
    let phys = physical_temperature(&m);
    let mut worst: Real = 0.0;
    let mut checked = 0;
    for (x, t) in m.particles.x0.iter().zip(&phys) {
        if (x.y - 2.0 * h).abs() < 1e-9 {
            let err = (t - exact(x.x)).abs() / step;
            worst = worst.max(err);
            checked += 1;
        }
    }
    assert!(checked > 200);
    assert!(worst < 0.02, "particle field: worst error {:.3} % of the step", 100.0 * worst);
    // The quadrature points keep the sub-particle part of the initial jump
    // (only increments are interpolated back, SPEC §7); beyond two supports
    // from it they follow the same solution.
    let mut worst_q: Real = 0.0;
    for q in 0..m.quad.len() {
        let x = m.quad.x0[q].x;
        if x.abs() > 4.0 * 2.0 * h {
            worst_q = worst_q.max((m.quad.temperature[q] - exact(x)).abs() / step);
        }
    }
    assert!(worst_q < 0.02, "quadrature points: worst error {:.3} % of the step", 100.0 * worst_q);
    // the far ends have not felt it yet
    for q in 0..m.quad.len() {
        if m.quad.x0[q].x.abs() > 0.19 {
            let want = if m.quad.x0[q].x < 0.0 { t1 } else { t0 };
            assert!((m.quad.temperature[q] - want).abs() < 1e-6 * step);
        }
    }
}

/// A closed body conserves heat to round-off over many sub-steps from a
/// random field: `Σ_q ρ₀ C_p w_q T_q` across calls and `Σ_I c_I T_I` within
/// a call — both are exact invariants of the scheme (module doc of
/// `thermal`). Plane strain with a graded grid, and axisymmetry with
/// particles on the axis.
#[test]
fn closed_body_conserves_heat_over_many_substeps() {
    let mut graded = grid((-0.02, 0.02), (0.0, 0.006), 1e-3);
    graded.growth = 1.2;
    graded.coarse_spacing = Some(3e-3);
    graded.fine_half_width = 0.004;
    for (mode, g) in
        [(GeometryMode::PlaneStrain, graded), (GeometryMode::Axisymmetric, grid((0.0, 0.012), (0.0, 0.006), 1e-3))]
    {
        let mut m = model(mode, g, 50.0);
        let mut s = 11u64;
        for t in m.quad.temperature.iter_mut() {
            *t = 300.0 + 500.0 * lcg(&mut s);
        }
        let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
        let e0 = quad_heat(&m);
        let dt = 20.0 * heat.stable_time_step(&mut m).unwrap();
        let mut substeps = 0;
        let mut moved = 0.0;
        for _ in 0..50 {
            heat.stable_time_step(&mut m).unwrap(); // projects: particle field at the start
            let before_q = m.quad.temperature.clone();
            let p0 = particle_heat(&m, &heat);
            substeps += heat.conduct(&mut m, dt).unwrap().substeps;
            let p1 = particle_heat(&m, &heat);
            assert!((p1 - p0).abs() <= 1e-13 * p0.abs(), "{mode:?}: particle heat {p0} -> {p1}");
            moved += m
                .quad
                .temperature
                .iter()
                .zip(&before_q)
                .zip(&m.quad.weight)
                .map(|((a, b), w)| RHO * CP * w * (a - b).abs())
                .sum::<Real>();
        }
        assert!(substeps >= 1000, "{substeps}");
        let e1 = quad_heat(&m);
        assert!((e1 - e0).abs() <= 1e-12 * e0.abs(), "{mode:?}: heat {e0} -> {e1}, rel {:.2e}", (e1 - e0) / e0);
        // and relative to the heat that actually moved, not just to the total
        assert!((e1 - e0).abs() <= 1e-11 * moved, "{mode:?}: imbalance {:.3e} J vs {moved:.3e} J moved", e1 - e0);
        // it did move: the field relaxed towards its mean
        let spread =
            |t: &[Real]| t.iter().cloned().fold(Real::MIN, Real::max) - t.iter().cloned().fold(Real::MAX, Real::min);
        assert!(spread(&m.particles.temperature) < 0.5 * 500.0);
    }
}

/// Long after the diffusion time the particle field is uniform at the
/// capacity-weighted mean, whatever the step: sub-cycling keeps a step
/// thousands of times the stable one stable, and the C-weighted spread of
/// the particle temperatures never grows.
#[test]
fn sub_cycling_keeps_large_steps_stable_and_relaxes_to_the_mean() {
    let mut m = model(GeometryMode::PlaneStrain, grid((0.0, 0.01), (0.0, 0.004), 1e-3), 50.0);
    let mut s = 5u64;
    for t in m.quad.temperature.iter_mut() {
        *t = 300.0 + 200.0 * lcg(&mut s);
    }
    let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
    let stable = heat.stable_time_step(&mut m).unwrap();
    let c: Vec<Real> = (0..m.particles.len()).map(|i| heat.capacity(&m, i).unwrap()).collect();
    let mean = particle_heat(&m, &heat) / c.iter().sum::<Real>();
    let spread =
        |m: &Model| -> Real { m.particles.temperature.iter().zip(&c).map(|(t, c)| c * (t - mean).powi(2)).sum() };
    let first = spread(&m);
    let mut last = first;
    for _ in 0..10 {
        let r = heat.conduct(&mut m, 10.0 * stable).unwrap();
        assert_eq!(r.substeps, 10);
        let now = spread(&m);
        assert!(now < last, "C-weighted spread did not decrease: {last:.4e} -> {now:.4e}");
        last = now;
    }
    assert!(last < 0.5 * first);
    // diffusion time L²/α = 1e-4 / 5e-5 = 2 s; run 20 of them in one call
    let r = heat.conduct(&mut m, 40.0).unwrap();
    assert!(r.substeps > 10_000, "{}", r.substeps);
    for (i, t) in m.particles.temperature.iter().enumerate() {
        assert!((t - mean).abs() < 1e-6 * 200.0, "particle {i}: {t} vs mean {mean}");
    }
}

/// A uniform field has no flux: it stays uniform (to round-off) under many
/// sub-steps, at a temperature that is not a round number.
#[test]
fn uniform_temperature_stays_uniform() {
    for mode in [GeometryMode::PlaneStrain, GeometryMode::Axisymmetric] {
        let mut g = grid((0.0, 0.02), (0.0, 0.005), 1e-3);
        g.growth = 1.15;
        g.refine_at = Some(0.0);
        g.coarse_spacing = Some(2.5e-3);
        let mut m = model(mode, g, 50.0);
        let t = 293.371_234_567;
        m.quad.temperature.iter_mut().for_each(|x| *x = t);
        let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
        let dt = 200.0 * heat.stable_time_step(&mut m).unwrap();
        heat.conduct(&mut m, dt).unwrap();
        let worst = m.quad.temperature.iter().map(|x| (x - t).abs()).fold(0.0, Real::max);
        assert!(worst < 1e-9, "{mode:?}: uniform field drifted by {worst:.3e} K");
    }
}

/// A linear field `T = T0 + G x` carries a uniform flux: interior particles
/// (more than two supports from every edge) keep their temperature up to
/// the quadrature error of `∫∇N_I`, while the insulated ends, where the flux
/// must vanish, do not: the cold end warms and the hot end cools, by far
/// more than the interior changes.
#[test]
fn linear_field_is_steady_inside_but_not_at_insulated_ends() {
    let h = 1e-3;
    let (lx, ly) = (0.03, 0.012);
    let mut m = model(GeometryMode::PlaneStrain, grid((0.0, lx), (0.0, ly), h), 50.0);
    let grad = 1000.0; // K/m
    for q in 0..m.quad.len() {
        m.quad.temperature[q] = 300.0 + grad * m.quad.x0[q].x;
    }
    let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
    let dt = heat.stable_time_step(&mut m).unwrap();
    let before = m.particles.temperature.clone();
    heat.conduct(&mut m, dt).unwrap();
    let a = 2.0 * h;
    let (mut interior, mut cold_end, mut hot_end): (Real, Real, Real) = (0.0, Real::MAX, Real::MAX);
    let p = &m.particles;
    for ((x, t), t_before) in p.x0.iter().zip(&p.temperature).zip(&before) {
        let d = t - t_before;
        let margin = (x.x).min(lx - x.x).min(x.y).min(ly - x.y);
        if margin > 2.0 * a + 1e-9 {
            interior = interior.max(d.abs());
        }
        if x.x < 1e-9 && x.y > a && x.y < ly - a {
            cold_end = cold_end.min(d);
        }
        if x.x > lx - 1e-9 && x.y > a && x.y < ly - a {
            hot_end = hot_end.min(-d);
        }
    }
    assert!(cold_end > 0.0 && hot_end > 0.0, "ends: cold {cold_end:.3e}, hot {hot_end:.3e} (both must be > 0)");
    assert!(
        interior < 1e-3 * cold_end.min(hot_end),
        "interior change {interior:.3e} K vs ends {cold_end:.3e} / {hot_end:.3e} K"
    );
}

/// The axisymmetric Laplacian: `T = b R²` heats at `∇²T·α = 4αb` in an
/// axisymmetric body (the `2πR` weights supply `(1/r)∂T/∂r = 2b`), but at
/// `2αb` for `T = b X²` in plane strain. Measured at interior particles away
/// from the axis and the edges, in one sub-step.
#[test]
fn axisymmetric_r_squared_heats_at_four_alpha() {
    let h = 1e-3;
    let kappa = 50.0;
    let alpha = kappa / (RHO * CP);
    let b = 1e6; // K/m²
    let (r0, r1, z1) = (0.01, 0.04, 0.02);
    for (mode, factor) in [(GeometryMode::Axisymmetric, 4.0), (GeometryMode::PlaneStrain, 2.0)] {
        let mut m = model(mode, grid((r0, r1), (0.0, z1), h), kappa);
        for q in 0..m.quad.len() {
            m.quad.temperature[q] = b * m.quad.x0[q].x.powi(2);
        }
        let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
        let dt = heat.stable_time_step(&mut m).unwrap();
        let before = m.particles.temperature.clone();
        assert_eq!(heat.conduct(&mut m, dt).unwrap().substeps, 1);
        let want = factor * alpha * b;
        let mut n = 0;
        let p = &m.particles;
        for ((x, t), t_before) in p.x0.iter().zip(&p.temperature).zip(&before) {
            let margin = (x.x - r0).min(r1 - x.x).min(x.y).min(z1 - x.y);
            if margin > 5.0 * h {
                let rate = (t - t_before) / dt;
                assert!((rate - want).abs() < 0.01 * want, "{mode:?} at {x:?}: rate {rate:.4e} vs {want:.4e}");
                n += 1;
            }
        }
        assert!(n > 50);
    }
}

/// The same computation gives bit-identical temperatures on 1 and 2 threads.
#[test]
fn one_and_two_threads_give_identical_temperatures() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut g = grid((0.0, 0.03), (0.0, 0.006), 1e-3);
            g.growth = 1.1;
            g.refine_at = Some(0.0);
            let mut m = model(GeometryMode::Axisymmetric, g, 50.0);
            let mut s = 99u64;
            for t in m.quad.temperature.iter_mut() {
                *t = 300.0 + 400.0 * lcg(&mut s);
            }
            let mut heat = HeatConduction::new(&m, DEFAULT_SAFETY_FACTOR).unwrap();
            let dt = 7.3 * heat.stable_time_step(&mut m).unwrap();
            for _ in 0..10 {
                heat.conduct(&mut m, dt).unwrap();
            }
            (m.quad.temperature, m.particles.temperature)
        })
    };
    let (q1, p1) = run(1);
    let (q2, p2) = run(2);
    assert!(q1.iter().zip(&q2).all(|(a, b)| a.to_bits() == b.to_bits()), "quadrature temperatures differ");
    assert!(p1.iter().zip(&p2).all(|(a, b)| a.to_bits() == b.to_bits()), "particle temperatures differ");
}

/// A small Johnson–Cook plate (power rate law: a true elastic range) whose
/// centre patch is struck at 300 m/s, shears plastically at the patch edges
/// and heats there. `HEAT` is replaced by the `[heat]` section under test.
const STRUCK_JC: &str = r#"
[geometry]
mode = "plane_strain"

[materials.steel]
model = "johnson_cook"
density = 7850.0
youngs_modulus = 200.0e9
poisson_ratio = 0.33
yield_stress = 490.0e6
hardening_modulus = 807.0e6
hardening_exponent = 0.73
rate_sensitivity = 0.0114
softening_exponent = 0.94
melting_temperature = 1800.0
room_temperature = 293.0
reference_strain_rate = 5.0e-4
rate_form = "power"
specific_heat = 452.0
thermal_expansion = 1.1e-5
conductivity = 5.0e4
damage = { d1 = 0.0705, d2 = 1.732, d3 = -0.54, d4 = -0.015, d5 = 0.0 }

[[bodies]]
name = "plate"
material = "steel"
rectangle = { x_min = -0.02, x_max = 0.02, y_min = 0.0, y_max = 0.004, layers = 5 }
[[bodies.initial_velocity]]
velocity = [0.0, -300.0]
region = { x_min = -0.003, x_max = 0.003, y_min = 0.0, y_max = 0.004 }

HEAT

[time]
end = 1.0e-5
"#;

fn struck(heat: &str) -> Case {
    Case::from_str_with(&STRUCK_JC.replace("HEAT", heat), "struck.toml", &[]).unwrap()
}

/// `[heat] conduction = false`: temperatures change only by the adiabatic
/// update — points that never yielded stay exactly at room temperature.
/// `true` (and the default for a Johnson–Cook body): heat flows from the
/// plastic zone into elastic points. (κ is exaggerated to 5e4 W/(m K) so that
/// 120 steps conduct measurably.)
#[test]
fn heat_section_switches_conduction() {
    let run = |case: &Case| {
        let mut sim = build_simulation(&case.resolved()).unwrap();
        for _ in 0..120 {
            sim.step().unwrap();
        }
        sim
    };
    let t0 = 293.0;
    let off = run(&struck("[heat]\nconduction = false"));
    assert!(off.heat.is_none());
    let q = &off.model.quad;
    let hottest = q.temperature.iter().cloned().fold(0.0, Real::max);
    assert!(hottest > t0 + 1.0, "the case must heat adiabatically (max {hottest} K)");
    let elastic: Vec<usize> = (0..q.len()).filter(|&k| q.eps_p[k] == 0.0).collect();
    assert!(elastic.len() > q.len() / 4);
    assert!(elastic.iter().all(|&k| q.temperature[k] == t0), "adiabatic: elastic points stay at room temperature");

    for text in ["[heat]\nconduction = true", ""] {
        let case = struck(text);
        assert!(case.heat_conduction(), "{text:?}");
        let on = run(&case);
        assert!(on.heat.is_some());
        let q = &on.model.quad;
        let warmed = (0..q.len()).filter(|&k| q.eps_p[k] == 0.0 && q.temperature[k] > t0 + 1e-3).count();
        assert!(warmed > 0, "{text:?}: no elastic point received heat");
        let hottest_on = q.temperature.iter().cloned().fold(0.0, Real::max);
        assert!(hottest_on < hottest, "{text:?}: conduction must lower the peak ({hottest_on} vs {hottest})");
        assert!(on.timers.list().iter().any(|(name, _)| *name == "heat conduction"));
    }
}

/// A temperature at or below absolute zero stops the run at once, naming
/// the point, the step and the temperature: an unstable transfer stays
/// finite long before it overflows, so a finiteness check alone lets it run
/// on with garbage in the flow stress and the damage.
#[test]
fn a_temperature_below_absolute_zero_stops_the_run() {
    let mut sim = build_simulation(&struck("").resolved()).unwrap();
    for _ in 0..5 {
        sim.step().unwrap();
    }
    sim.model.quad.temperature[17] = -3.0e13;
    let err = sim.step().unwrap_err();
    assert!(
        matches!(err, plugsim::step::SolverError::BelowAbsoluteZero { point: 17, step: 6, temperature, .. } if temperature == -3.0e13),
        "{err}"
    );
    assert!(err.to_string().contains("absolute zero") && err.to_string().contains("quadrature point 17"), "{err}");
}

/// The default follows the materials; asking for conduction with a material
/// that cannot conduct, or a bad safety factor, is a problem naming the key.
#[test]
fn heat_section_defaults_and_validation() {
    let elastic = r#"
[geometry]
mode = "plane_strain"
[materials.glass]
model = "elastic"
density = 2500.0
youngs_modulus = 70.0e9
poisson_ratio = 0.2
EXTRA
[[bodies]]
name = "pane"
material = "glass"
rectangle = { x_min = 0.0, x_max = 0.01, y_min = 0.0, y_max = 0.002, layers = 3 }
HEAT
[time]
end = 1.0e-6
"#;
    let case = |extra: &str, heat: &str| {
        Case::from_str_with(&elastic.replace("EXTRA", extra).replace("HEAT", heat), "pane.toml", &[])
    };
    // no thermal properties: off by default, and the resolved case says so
    let c = case("", "").unwrap();
    assert!(!c.heat_conduction());
    assert_eq!(c.resolved().heat.conduction, Some(false));
    assert!(build_simulation(&c.resolved()).unwrap().heat.is_none());
    // with them: on by default
    let c = case("specific_heat = 800.0\nthermal_conductivity = 1.0", "").unwrap();
    assert!(c.heat_conduction());
    assert!(build_simulation(&c.resolved()).unwrap().heat.is_some());
    // explicitly on without them: a problem naming heat.conduction and the body
    let e = case("specific_heat = 800.0", "[heat]\nconduction = true").unwrap_err().to_string();
    assert!(e.contains("heat.conduction") && e.contains("pane"), "{e}");
    let e = case("", "[heat]\nsafety_factor = 1.5").unwrap_err().to_string();
    assert!(e.contains("heat.safety_factor"), "{e}");
    let e = case("", "[heat]\nconduktion = true").unwrap_err().to_string();
    assert!(e.contains("conduktion"), "{e}");
    // --set works on the section
    let c = Case::from_str_with(
        &elastic.replace("EXTRA", "specific_heat = 800.0\nthermal_conductivity = 1.0").replace("HEAT", ""),
        "pane.toml",
        &["heat.conduction=false".into()],
    )
    .unwrap();
    assert!(!c.heat_conduction());
}
