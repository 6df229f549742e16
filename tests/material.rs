//! Verification of the Johnson–Cook model (SPEC §6) and the material-point
//! driver against independent answers: a reference solution of the
//! constitutive ODEs by RK4, analytic rate-law, softening, heating and damage
//! results, and the analytic hypoelastic Jaumann solution of simple shear.

use nalgebra::{Matrix3, Rotation3, Vector3};
use plugsim::material::johnson_cook::{JohnsonCook, RateForm};
use plugsim::material::library::{
    weldox_460e, weldox_460e_borvik, weldox_460e_borvik_coupled, weldox_460e_cockcroft_latham, weldox_460e_cutoff,
};
use plugsim::material::{fractured, Constitutive, Elastic, Material, PointState, StepKinematics};
use plugsim::material_point::{run, DriverConfig, LoadPath, Record};

type M3 = Matrix3<f64>;

// ---------------------------------------------------------------------------
// Reference: the Johnson–Cook ODEs integrated by RK4 with a tiny step.
// Written from the constitutive equations of SPEC §6, not from the tangent
// update, and using none of the crate's material functions.
// ---------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
struct Y {
    tau: M3,
    eps: f64,
    temp: f64,
    dmg: f64,
}

impl Y {
    fn plus(&self, k: &Y, h: f64) -> Y {
        Y {
            tau: self.tau + k.tau * h,
            eps: self.eps + k.eps * h,
            temp: self.temp + k.temp * h,
            dmg: self.dmg + k.dmg * h,
        }
    }
}

/// `ẏ` of the Johnson–Cook point: `ε̄̇ = φ(τ̄, g)`,
/// `τ̇ = C:(d − ε̄̇ n̂) − 3Kα Ṫ I + wτ − τw`, `Ṫ = χ τ̄ ε̄̇/(ρ₀C_p)`,
/// `Ḋ = ε̄̇/ε_f(σ*, ε̄̇, T*)`; `g` scaled by Børvik's `(1 − D_C D)`, and
/// with his damage-equivalent strain `eps` is `r` and `ṙ = (1 − D_C D) ε̄̇`
/// drives the hardening and `Ḋ = ṙ/ε_f`.
fn rhs(p: &JohnsonCook, y: &Y, d: &M3, w: &M3) -> Y {
    let shear = p.youngs_modulus / (2.0 * (1.0 + p.poisson_ratio));
    let bulk = p.youngs_modulus / (3.0 * (1.0 - 2.0 * p.poisson_ratio));
    let eye = M3::identity();
    let mean = y.tau.trace() / 3.0;
    let s = y.tau - eye * mean;
    let tbar = (1.5 * s.dot(&s)).sqrt();
    let tstar = ((y.temp - p.room_temperature) / (p.melting_temperature - p.room_temperature)).clamp(0.0, 1.0);
    let g = (p.yield_stress + p.hardening_modulus * y.eps.powf(p.hardening_exponent))
        * (1.0 - tstar.powf(p.softening_exponent))
        * (1.0 - p.damage_coupling * y.dmg);
    let ratio = tbar / g;
    let c = p.rate_sensitivity;
    let rate = match p.rate_form {
        RateForm::Log => p.reference_strain_rate * ((ratio - 1.0) / c).exp(),
        RateForm::Power if ratio > 1.0 => p.reference_strain_rate * (ratio.powf(1.0 / c) - 1.0),
        RateForm::Power => 0.0,
    };
    let nhat = if tbar > 0.0 { s * (1.5 / tbar) } else { M3::zeros() };
    let tdot = p.taylor_quinney * tbar * rate / (p.density * p.specific_heat);
    let dprime = d - eye * (d.trace() / 3.0);
    let taudot = eye * (bulk * d.trace()) + (dprime - nhat * rate) * (2.0 * shear)
        - eye * (3.0 * bulk * p.thermal_expansion * tdot)
        + w * y.tau
        - y.tau * w;
    let dc = &p.damage;
    let rstar = rate / p.reference_strain_rate;
    let rate_term = match p.rate_form {
        RateForm::Log => 1.0 + dc.d4 * rstar.max(1.0).ln(),
        RateForm::Power => (1.0 + rstar).powf(dc.d4),
    };
    // Børvik's damage-equivalent strain: hardening and damage over
    // `dr = (1 − D_C D) dε̄`.
    let r_rate = if p.damage_equivalent_strain { rate * (1.0 - p.damage_coupling * y.dmg) } else { rate };
    let dmg = if let Some(w_c) = dc.cockcroft_latham {
        // Cockcroft–Latham: ⟨σ₁⟩ ε̄̇ / W_c, σ₁ by nalgebra's eigenvalues.
        let sigma1 = y.tau.symmetric_eigenvalues().max();
        sigma1.max(0.0) * r_rate / w_c
    } else if tbar > 0.0 {
        let eps_f = (dc.d1 + dc.d2 * (dc.d3 * mean / tbar).exp()) * rate_term * (1.0 + dc.d5 * tstar);
        r_rate / eps_f
    } else {
        0.0
    };
    Y { tau: taudot, eps: r_rate, temp: tdot, dmg }
}

/// RK4 over `[0, t_end]` in `n` steps; returns the states at `t_end·i/marks`,
/// `i = 1..=marks` (`n` a multiple of `marks`).
fn reference(p: &JohnsonCook, d: &M3, w: &M3, t_end: f64, n: usize, marks: usize) -> Vec<Y> {
    assert_eq!(n % marks, 0);
    let h = t_end / n as f64;
    let mut y = Y { tau: M3::zeros(), eps: 0.0, temp: p.room_temperature, dmg: 0.0 };
    let mut out = Vec::new();
    for i in 1..=n {
        let k1 = rhs(p, &y, d, w);
        let k2 = rhs(p, &y.plus(&k1, 0.5 * h), d, w);
        let k3 = rhs(p, &y.plus(&k2, 0.5 * h), d, w);
        let k4 = rhs(p, &y.plus(&k3, h), d, w);
        y = Y {
            tau: y.tau + (k1.tau + (k2.tau + k3.tau) * 2.0 + k4.tau) * (h / 6.0),
            eps: y.eps + (k1.eps + 2.0 * (k2.eps + k3.eps) + k4.eps) * (h / 6.0),
            temp: y.temp + (k1.temp + 2.0 * (k2.temp + k3.temp) + k4.temp) * (h / 6.0),
            dmg: y.dmg + (k1.dmg + 2.0 * (k2.dmg + k3.dmg) + k4.dmg) * (h / 6.0),
        };
        if i % (n / marks) == 0 {
            out.push(y);
        }
    }
    out
}

fn von_mises(t: &M3) -> f64 {
    let s = t - M3::identity() * (t.trace() / 3.0);
    (1.5 * s.dot(&s)).sqrt()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Quantities compared with the reference: τ̄, ε̄, temperature rise, D.
fn compared(tau: &M3, eps: f64, temp: f64, dmg: f64, t0: f64) -> [f64; 4] {
    [von_mises(tau), eps, temp - t0, dmg]
}

/// Kinematics of a driver path at signed rate `r`, as the driver documents.
fn path_kinematics(path: LoadPath, r: f64) -> (M3, M3) {
    match path {
        LoadPath::UniaxialStrain => (M3::from_diagonal(&Vector3::new(r, 0.0, 0.0)), M3::zeros()),
        LoadPath::SimpleShear => {
            let mut l = M3::zeros();
            l[(0, 1)] = r;
            ((l + l.transpose()) * 0.5, (l - l.transpose()) * 0.5)
        }
        LoadPath::UniaxialStress => unreachable!("the reference drives prescribed kinematics only"),
    }
}

/// Run the driver with `steps` steps and the reference, compare at four
/// instants; returns the largest relative error of each compared quantity.
fn driver_vs_reference(m: &JohnsonCook, path: LoadPath, rate: f64, strain: f64, steps: usize) -> [f64; 4] {
    let marks = 4;
    let t_end = strain / rate;
    let config = DriverConfig {
        path,
        rate,
        final_strain: strain,
        dt: t_end / steps as f64 * (1.0 + 1e-12),
        initial_temperature: None,
    };
    let records = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
    assert_eq!(records.len(), steps + 1);
    let (d, w) = path_kinematics(path, rate);
    let n_ref = 100_000;
    let coarse = reference(m, &d, &w, t_end, n_ref, marks);
    let fine = reference(m, &d, &w, t_end, 2 * n_ref, marks);
    let t0 = m.room_temperature;
    let mut worst = [0.0f64; 4];
    for i in 0..marks {
        let y = fine[i];
        let want = compared(&y.tau, y.eps, y.temp, y.dmg, t0);
        let yc = coarse[i];
        let check = compared(&yc.tau, yc.eps, yc.temp, yc.dmg, t0);
        let r: &Record = &records[(i + 1) * steps / marks];
        let got = compared(&r.tau, r.eps_p, r.temperature, r.damage, t0);
        for q in 0..4 {
            // Guard: the reference itself is converged.
            assert!(rel(check[q], want[q]) < 1e-6, "reference not converged: {q} {} {}", check[q], want[q]);
            worst[q] = worst[q].max(rel(got[q], want[q]));
        }
    }
    worst
}

fn assert_within(worst: [f64; 4], tol: f64, what: &str) {
    let names = ["equivalent stress", "plastic strain", "temperature rise", "damage"];
    for (name, e) in names.iter().zip(worst) {
        assert!(e < tol, "{what}: {name} relative error {e:.3e}");
    }
}

#[test]
fn simple_shear_at_1e3_matches_reference_ode() {
    let worst = driver_vs_reference(&weldox_460e(), LoadPath::SimpleShear, 1e3, 1.0, 2000);
    assert_within(worst, 0.01, "simple shear 1e3/s");
}

#[test]
fn simple_shear_at_1e5_matches_reference_ode() {
    let worst = driver_vs_reference(&weldox_460e(), LoadPath::SimpleShear, 1e5, 1.0, 2000);
    assert_within(worst, 0.01, "simple shear 1e5/s");
}

#[test]
fn uniaxial_strain_at_1e4_matches_reference_ode() {
    let worst = driver_vs_reference(&weldox_460e(), LoadPath::UniaxialStrain, 1e4, 0.2, 2000);
    assert_within(worst, 0.01, "uniaxial strain 1e4/s");
}

#[test]
fn power_law_simple_shear_at_1e4_matches_reference_ode() {
    let worst = driver_vs_reference(&weldox_460e_borvik(), LoadPath::SimpleShear, 1e4, 1.0, 2000);
    assert_within(worst, 0.01, "power law, simple shear 1e4/s");
}

/// Børvik's coupled model (`D_C = 0.3`) through the peak of the adiabatic
/// shear curve: at `γ = 3` the point has lost `0.3 D ≈ 20 %` of its flow
/// stress to damage, and the reference ODE carries the factor itself; with
/// the damage-equivalent strain `r` (the built-in set) and over `ε̄`.
#[test]
fn borvik_coupled_simple_shear_at_1e4_matches_reference_ode() {
    let m = weldox_460e_borvik_coupled();
    assert!(m.damage_equivalent_strain);
    let over_eps = JohnsonCook { damage_equivalent_strain: false, ..m.clone() };
    for (m, name) in [(&m, "over r"), (&over_eps, "over eps")] {
        let worst = driver_vs_reference(m, LoadPath::SimpleShear, 1e4, 3.0, 4000);
        assert_within(worst, 0.01, &format!("Borvik's coupled model {name}, simple shear 1e4/s"));
    }
    // The coupling is on: the uncoupled point ends at a higher stress.
    let end = |m: &JohnsonCook| {
        let config = DriverConfig {
            path: LoadPath::SimpleShear,
            rate: 1e4,
            final_strain: 3.0,
            dt: 3.0 / 1e4 / 4000.0,
            initial_temperature: None,
        };
        let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
        let last = r.last().unwrap();
        (von_mises(&last.tau), last.damage, last.eps_p)
    };
    let (coupled, d, r) = end(&m);
    let (free, _, _) = end(&weldox_460e_borvik());
    assert!(d > 0.5 && coupled < 0.9 * free, "D {d}, coupled {coupled:.4e} against {free:.4e}");
    // `r` grows at (1 − 0.3 D) of `ε̄`: behind it by 10–20 % at D ≈ 0.6,
    // and so is the damage.
    let (_, d_eps, eps) = end(&over_eps);
    assert!(r < 0.92 * eps && r > 0.75 * eps, "r {r} against eps {eps}");
    assert!(d < 0.92 * d_eps && d > 0.75 * d_eps, "D {d} over r against {d_eps} over eps");
}

/// Observed order: the damage of the tangent update is first order in the
/// step (SPEC §6 takes the triaxiality at the start of the step, and in
/// uniaxial strain it grows steadily), so its error halves with the step.
#[test]
fn damage_error_halves_with_the_step() {
    let error = |steps| driver_vs_reference(&weldox_460e(), LoadPath::UniaxialStrain, 1e4, 0.2, steps)[3];
    let errors = [error(1000), error(2000), error(4000)];
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!((order - 1.0).abs() < 0.1, "order {order} ({errors:?})");
    }
}

// ---------------------------------------------------------------------------
// Rate law, thermal softening, heating, damage.
// ---------------------------------------------------------------------------

/// No hardening, isothermal: the flow stress is fixed (`g = A (1 − T*ᵐ)`), so
/// steady flow isolates the rate law.
fn perfectly_plastic_isothermal(mut m: JohnsonCook) -> JohnsonCook {
    m.hardening_modulus = 0.0;
    m.taylor_quinney = 0.0;
    m
}

/// Steady equivalent stress of uniaxial strain at axial rate `rate` (the
/// deviatoric equivalent rate is `2/3` of it) from temperature `temp`.
fn steady_uniaxial_strain_stress(m: &JohnsonCook, rate: f64, temp: f64) -> f64 {
    let strain = 0.03;
    let config = DriverConfig {
        path: LoadPath::UniaxialStrain,
        rate,
        final_strain: strain,
        dt: strain / rate / 3000.0,
        initial_temperature: Some(temp),
    };
    run(&Material::JohnsonCook(m.clone()), &config).unwrap().last().unwrap().equivalent_stress
}

#[test]
fn rate_sensitivity_follows_the_rate_law() {
    for base in [weldox_460e(), weldox_460e_borvik()] {
        let m = perfectly_plastic_isothermal(base);
        let rate0 = m.reference_strain_rate;
        let c = m.rate_sensitivity;
        let g = m.yield_stress;
        for plastic_rate in [0.1 * rate0, 1e2, 1e4, 1e6] {
            let got = steady_uniaxial_strain_stress(&m, 1.5 * plastic_rate, m.room_temperature);
            let want = match m.rate_form {
                RateForm::Log => g * (1.0 + c * (plastic_rate / rate0).ln()),
                RateForm::Power => g * (1.0 + plastic_rate / rate0).powf(c),
            };
            assert!(rel(got, want) < 1e-6, "{:?} at {plastic_rate}: {got} vs {want}", m.rate_form);
        }
    }
}

#[test]
fn thermal_softening_scales_flow_stress_by_one_minus_half_to_the_m() {
    let m = perfectly_plastic_isothermal(weldox_460e());
    let half = m.room_temperature + 0.5 * (m.melting_temperature - m.room_temperature);
    // Plastic rate = ε̇₀, where the log-law factor is exactly 1.
    let rate = 1.5 * m.reference_strain_rate;
    let cold = steady_uniaxial_strain_stress(&m, rate, m.room_temperature);
    let hot = steady_uniaxial_strain_stress(&m, rate, half);
    assert!(rel(cold, m.yield_stress) < 1e-6, "{cold}");
    let factor = 1.0 - 0.5f64.powf(m.softening_exponent);
    assert!(rel(hot, factor * cold) < 1e-6, "{hot} vs {}", factor * cold);
}

#[test]
fn adiabatic_heating_equals_plastic_work() {
    for (m, path, rate, strain) in [
        (weldox_460e(), LoadPath::SimpleShear, 1e4, 1.0),
        (weldox_460e(), LoadPath::UniaxialStrain, 1e4, -0.3),
        (weldox_460e_borvik(), LoadPath::UniaxialStress, 1e3, 0.5),
    ] {
        let config = DriverConfig {
            path,
            rate,
            final_strain: strain,
            dt: strain.abs() / rate / 4000.0,
            initial_temperature: None,
        };
        let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
        // ∫ τ̄ dε̄ along the path, trapezoidal rule over the records.
        let work: f64 = r
            .windows(2)
            .map(|p| 0.5 * (p[0].equivalent_stress + p[1].equivalent_stress) * (p[1].eps_p - p[0].eps_p))
            .sum();
        let want = m.taylor_quinney * work / (m.density * m.specific_heat);
        let got = r.last().unwrap().temperature - m.room_temperature;
        assert!(want > 20.0);
        assert!(rel(got, want) < 1e-3, "{path:?}: ΔT {got} vs {want}");
    }
}

#[test]
fn damage_reaches_one_at_the_analytic_failure_strain() {
    // Uniaxial tension (triaxiality 1/3), steady rate, no hardening, isothermal.
    for base in [weldox_460e(), weldox_460e_borvik()] {
        let m = perfectly_plastic_isothermal(base);
        let rate = 1e3;
        let dc = m.damage;
        let rate_star = rate / m.reference_strain_rate;
        let rate_term = match m.rate_form {
            RateForm::Log => 1.0 + dc.d4 * rate_star.ln(),
            RateForm::Power => (1.0 + rate_star).powf(dc.d4),
        };
        let eps_f = (dc.d1 + dc.d2 * (dc.d3 / 3.0).exp()) * rate_term;
        let config = DriverConfig {
            path: LoadPath::UniaxialStress,
            rate,
            final_strain: 1.2 * eps_f,
            dt: 1.2 * eps_f / rate / 4000.0,
            initial_temperature: None,
        };
        let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
        let i = r.iter().position(|x| x.damage >= 1.0).expect("damage reaches 1");
        let (a, b) = (&r[i - 1], &r[i]);
        let at_failure = a.eps_p + (1.0 - a.damage) / (b.damage - a.damage) * (b.eps_p - a.eps_p);
        assert!(rel(at_failure, eps_f) < 2e-3, "{:?}: {at_failure} vs {eps_f}", m.rate_form);
    }
}

/// Deviation 15: Cockcroft–Latham's damage `∫ ⟨σ₁⟩ dε̄ / W_c` along simple
/// shear (σ₁ = the shear stress, rotating with the material) and uniaxial
/// strain in tension, against the RK4 reference with `σ₁` from nalgebra's
/// eigenvalues.
#[test]
fn cockcroft_latham_simple_shear_matches_reference_ode() {
    let m = weldox_460e_cockcroft_latham();
    let shear = driver_vs_reference(&m, LoadPath::SimpleShear, 1e4, 1.0, 4000);
    assert_within(shear, 1e-2, "Cockcroft–Latham simple shear");
    let tension = driver_vs_reference(&m, LoadPath::UniaxialStrain, 1e4, 0.3, 4000);
    assert_within(tension, 1e-2, "Cockcroft–Latham uniaxial strain");
}

/// Deviation 15: in a quasi-static, isothermal tension test the built-in
/// `W_c` (the work of the hardening curve to the Johnson–Cook fracture
/// strain of `σ* = 1/3`) brings the damage to 1 at that strain: the two
/// loci agree where `W_c` was taken from. In simple shear under the same
/// conditions it fails later, where `∫ σ̄/√3 dε̄ = W_c`.
#[test]
fn cockcroft_latham_tension_fails_at_the_johnson_cook_strain() {
    let mut m = weldox_460e_cockcroft_latham();
    m.taylor_quinney = 0.0;
    let dc = m.damage;
    let eps_f = dc.d1 + dc.d2 * (dc.d3 / 3.0).exp();
    // At the reference rate the log law's factor is 1: τ̄ = A + B ε̄ⁿ.
    let rate = m.reference_strain_rate;
    let strain_at_d1 = |path: LoadPath, strain: f64| {
        let config =
            DriverConfig { path, rate, final_strain: strain, dt: strain / rate / 20_000.0, initial_temperature: None };
        let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
        let i = r.iter().position(|x| x.damage >= 1.0).expect("damage reaches 1");
        let (a, b) = (&r[i - 1], &r[i]);
        a.eps_p + (1.0 - a.damage) / (b.damage - a.damage) * (b.eps_p - a.eps_p)
    };
    let tension = strain_at_d1(LoadPath::UniaxialStress, 1.3 * eps_f);
    assert!(rel(tension, eps_f) < 5e-3, "tension: D = 1 at {tension} vs {eps_f}");
    // Shear: solve A e + B e^{n+1}/(n+1) = √3 W_c for e by bisection.
    let w = |e: f64| {
        m.yield_stress * e + m.hardening_modulus * e.powf(m.hardening_exponent + 1.0) / (m.hardening_exponent + 1.0)
    };
    let target = 3f64.sqrt() * dc.cockcroft_latham.unwrap();
    let (mut lo, mut hi) = (0.0, 10.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if w(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // Simple shear to γ: ε̄ = γ/√3 (small elastic part aside).
    let shear = strain_at_d1(LoadPath::SimpleShear, 1.3 * 3f64.sqrt() * lo);
    assert!(shear > 1.4 * eps_f, "shear fails later than tension: {shear} vs {eps_f}");
    assert!(rel(shear, lo) < 1e-2, "shear: D = 1 at ε̄ = {shear} vs {lo}");
}

/// Deviation 15: no damage where every principal stress is compressive —
/// a point sheared under a pressure that keeps `σ₁ < 0` (the material under
/// a projectile's face) and uniaxial-strain compression — where \[RL10\]'s
/// locus books damage; the flow is the same to the bit (no coupling).
#[test]
fn cockcroft_latham_accrues_no_damage_in_compression() {
    let (paper, cl) = (weldox_460e(), weldox_460e_cockcroft_latham());
    let p0 = 1.2e9;
    let (a, b) = (shear_under_pressure(&paper, p0), shear_under_pressure(&cl, p0));
    assert!(b.iter().all(|s| s.tau.symmetric_eigenvalues().max() < 0.0), "σ₁ < 0 throughout");
    assert!(a.last().unwrap().damage > 0.05, "the paper's locus books damage");
    let first = b.iter().position(|s| s.damage != 0.0);
    assert!(first.is_none(), "Cockcroft–Latham books none: {:?}", first.map(|i| (i, b[i], b[i.saturating_sub(1)])));
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.tau, x.eps_p, x.temperature), (y.tau, y.eps_p, y.temperature));
    }
    let config = DriverConfig {
        path: LoadPath::UniaxialStrain,
        rate: 1e4,
        final_strain: -0.3,
        dt: 0.3 / 1e4 / 2000.0,
        initial_temperature: None,
    };
    let r = run(&Material::JohnsonCook(cl), &config).unwrap();
    assert!(r.last().unwrap().eps_p > 0.15, "{}", r.last().unwrap().eps_p);
    assert!(r.iter().all(|x| x.damage == 0.0), "uniaxial-strain compression");
}

/// `W_c` of the built-in material: the closed form against the trapezoidal
/// area under the crate's own flow stress at room temperature (no rate
/// factor), 200,000 intervals up to the Johnson–Cook fracture strain of
/// uniaxial tension.
#[test]
fn tension_fracture_work_is_the_area_under_the_hardening_curve() {
    let m = weldox_460e();
    let dc = m.damage;
    let eps_f = dc.d1 + dc.d2 * (dc.d3 / 3.0).exp();
    let n = 200_000;
    let h = eps_f / n as f64;
    let f = |e: f64| m.flow_stress(e, m.room_temperature, 0.0);
    let area: f64 = (0..n).map(|i| 0.5 * (f(i as f64 * h) + f((i + 1) as f64 * h)) * h).sum();
    let w = m.tension_fracture_work();
    assert!(rel(w, area) < 1e-6, "{w} vs {area}");
    assert!((1.6e9..1.8e9).contains(&w), "{w}");
    assert_eq!(weldox_460e_cockcroft_latham().damage.cockcroft_latham, Some(w));
}

/// Simple shear at 10⁴ s⁻¹ to `γ = 0.5` of a point that starts under the
/// pressure `p0` (shear is isochoric, so the pressure stays, less the
/// small thermal-expansion term): the stress state under a projectile's
/// face. Returns the state after every step.
fn shear_under_pressure(m: &JohnsonCook, p0: f64) -> Vec<PointState> {
    let (rate, dt, steps) = (1e4, 1e-8, 5000);
    let mut l = M3::zeros();
    l[(0, 1)] = rate;
    let k = StepKinematics { d: (l + l.transpose()) * 0.5, w: (l - l.transpose()) * 0.5, dt };
    let mut state = PointState { tau: M3::identity() * -p0, ..PointState::at_rest(m.room_temperature) };
    (0..steps)
        .map(|_| {
            state = m.update(&state, &k);
            state
        })
        .collect()
}

/// Deviation 14: with Bao & Wierzbicki's cut-off a point sheared under a
/// pressure that keeps `σ* < −1/3` accrues no damage, where \[RL10\]'s locus
/// books `∫ dε̄/ε_f(σ*)`; under tension (`σ* > 0`) the two materials give
/// the same path to the bit. The flow is the same either way (no coupling).
#[test]
fn upsetting_accrues_no_damage_below_the_cut_off() {
    let (paper, cut) = (weldox_460e(), weldox_460e_cutoff());
    let p0 = 0.5e9;
    let (a, b) = (shear_under_pressure(&paper, p0), shear_under_pressure(&cut, p0));
    let triaxiality = |s: &PointState| s.tau.trace() / 3.0 / von_mises(&s.tau);
    // Once plastic, the state stays below the cut-off.
    let plastic = a.iter().position(|s| s.eps_p > 1e-3).unwrap();
    let (lo, hi) = a[plastic..].iter().map(triaxiality).fold((f64::MAX, f64::MIN), |(l, h), t| (l.min(t), h.max(t)));
    assert!(lo > -1.2 && hi < -0.5, "σ* in [{lo}, {hi}]");
    // The paper's locus: damage by the independent sum over the steps of
    // Δε̄ / ε_f(σ*) with ε_f written out here (rate term at each step's rate).
    let dc = paper.damage;
    let mut want = 0.0;
    for w in a.windows(2) {
        let s = &w[0];
        let r = &w[1];
        let rate_term = 1.0 + dc.d4 * r.eps_p_rate.max(1.0).ln();
        let eps_f = (dc.d1 + dc.d2 * (dc.d3 * triaxiality(s)).exp()) * rate_term;
        want += (r.eps_p - s.eps_p) / eps_f;
    }
    let got = a.last().unwrap().damage;
    assert!(got > 0.05 && rel(got, want) < 0.02, "paper's damage {got} vs {want}");
    // The cut-off: none, and the same flow.
    assert!(b.iter().all(|s| s.damage == 0.0), "damage below the cut-off");
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.tau, x.eps_p, x.temperature), (y.tau, y.eps_p, y.temperature));
    }
    // Under tension (σ* > 0 throughout; shear alone would not do: the
    // heating's constrained expansion pressurises the point to σ* ≈ −1/3):
    // the same bits, damage included.
    let (a0, b0) = (shear_under_pressure(&paper, -0.5e9), shear_under_pressure(&cut, -0.5e9));
    assert!(a0.iter().all(|s| triaxiality(s) > 0.0) && a0.last().unwrap().damage > 0.05);
    for (x, y) in a0.iter().zip(&b0) {
        assert_eq!((x.tau, x.eps_p, x.damage), (y.tau, y.eps_p, y.damage));
    }
}

// ---------------------------------------------------------------------------
// Objectivity and the Jaumann rate.
// ---------------------------------------------------------------------------

/// Rotate a pre-stressed point rigidly by `angle` about `axis` in `n` steps
/// (d = 0); returns the largest relative change of `tr τ`, `τ̄` and `det τ`
/// and the distance to the exactly rotated stress `Q τ₀ Qᵀ`.
fn rigid_rotation_errors(m: &Material, tau0: &M3, axis: &Vector3<f64>, angle: f64, n: usize) -> (f64, f64) {
    let omega = 1e3;
    let u = axis.normalize();
    let w = u.cross_matrix() * omega;
    let dt = angle / omega / n as f64;
    let k = StepKinematics { d: M3::zeros(), w, dt };
    let mut s = PointState { tau: *tau0, ..PointState::at_rest(m.initial_temperature()) };
    for _ in 0..n {
        s = m.update(&s, &k);
    }
    let inv = |t: &M3| [t.trace(), von_mises(t), t.determinant()];
    let (a, b) = (inv(tau0), inv(&s.tau));
    let invariants = (0..3).map(|i| rel(b[i], a[i])).fold(0.0, f64::max);
    let q = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(u), angle).into_inner();
    let exact = q * tau0 * q.transpose();
    (invariants, (s.tau - exact).norm() / tau0.norm())
}

#[test]
fn rigid_rotation_leaves_stress_invariants_unchanged() {
    let jc = weldox_460e();
    let g = jc.yield_stress;
    // A general symmetric stress below yield (τ̄ ≈ 0.5 g) with pressure.
    let s = M3::new(0.2, 0.08, -0.05, 0.08, -0.15, 0.1, -0.05, 0.1, -0.05);
    let tau0 = s * (0.5 * g / von_mises(&s)) - M3::identity() * 3e8;
    let axis = Vector3::new(1.0, 2.0, 3.0);
    let elastic = Material::Elastic(Elastic {
        density: 7850.0,
        youngs_modulus: 200e9,
        poisson_ratio: 0.3,
        room_temperature: 293.0,
        thermal: None,
    });
    for m in [Material::JohnsonCook(jc.clone()), Material::JohnsonCook(weldox_460e_borvik()), elastic] {
        let (inv_1, rot_1) = rigid_rotation_errors(&m, &tau0, &axis, std::f64::consts::FRAC_PI_2, 4000);
        let (inv_2, rot_2) = rigid_rotation_errors(&m, &tau0, &axis, std::f64::consts::FRAC_PI_2, 8000);
        assert!(inv_1 < 2e-3 && rot_1 < 2e-3, "{inv_1} {rot_1}");
        // The explicit Jaumann update is first order: halving the step halves the drift.
        assert!((inv_1 / inv_2 - 2.0).abs() < 0.1, "order {}", inv_1 / inv_2);
        assert!((rot_1 / rot_2 - 2.0).abs() < 0.1, "order {}", rot_1 / rot_2);
    }
}

/// Hypoelastic simple shear with the Jaumann rate: `τ_xy = G sin γ`,
/// `τ_xx = −τ_yy = G (1 − cos γ)` — the well-known spurious oscillation.
fn elastic_shear_error(dgamma: f64) -> f64 {
    let e =
        Elastic { density: 7850.0, youngs_modulus: 200e9, poisson_ratio: 0.3, room_temperature: 293.0, thermal: None };
    let g = e.shear_modulus();
    let gamma_end = 2.0 * std::f64::consts::PI;
    let config = DriverConfig {
        path: LoadPath::SimpleShear,
        rate: 1.0,
        final_strain: gamma_end,
        dt: dgamma,
        initial_temperature: None,
    };
    let r = run(&Material::Elastic(e), &config).unwrap();
    // The oscillation is there: τ_xy changes sign past γ = π.
    let at =
        |gamma: f64| r.iter().min_by(|a, b| (a.strain - gamma).abs().total_cmp(&(b.strain - gamma).abs())).unwrap();
    assert!(at(1.5 * std::f64::consts::PI).tau[(0, 1)] < -0.9 * g);
    r.iter()
        .map(|x| {
            let gm = x.strain;
            let e12 = (x.tau[(0, 1)] - g * gm.sin()).abs();
            let e11 = (x.tau[(0, 0)] - g * (1.0 - gm.cos())).abs();
            let e22 = (x.tau[(1, 1)] + g * (1.0 - gm.cos())).abs();
            e12.max(e11).max(e22) / g
        })
        .fold(0.0, f64::max)
}

#[test]
fn elastic_simple_shear_follows_the_jaumann_solution() {
    let coarse = elastic_shear_error(4e-4);
    let fine = elastic_shear_error(2e-4);
    assert!(fine < 1e-3, "max error {fine} G");
    assert!((coarse / fine - 2.0).abs() < 0.1, "order {}", coarse / fine);
}

/// Shear-band conditions: 1e7/s with [RL10]'s fixed step 4e-9 s, where the
/// step's elastic increment (G·0.04 ≈ 3 GPa) exceeds the flow stress, against
/// the same run with a 40× smaller step.
#[test]
fn simple_shear_at_1e7_with_the_paper_step_is_smooth() {
    let m = weldox_460e();
    let run_with = |dt: f64| {
        let config =
            DriverConfig { path: LoadPath::SimpleShear, rate: 1e7, final_strain: 2.0, dt, initial_temperature: None };
        run(&Material::JohnsonCook(m.clone()), &config).unwrap()
    };
    let coarse = run_with(4e-9);
    let fine = run_with(1e-10);
    assert_eq!((coarse.len(), fine.len()), (51, 2001));
    let rise = fine.last().unwrap().temperature - m.room_temperature;
    for (i, c) in coarse.iter().enumerate().skip(5) {
        let f = &fine[40 * i];
        assert!(
            rel(c.equivalent_stress, f.equivalent_stress) < 0.02,
            "{i}: {} vs {}",
            c.equivalent_stress,
            f.equivalent_stress
        );
        // The unresolved first step (0 → 8 × yield strain) heats ~1.7 K
        // less; the offset stays small against the total rise.
        assert!((c.temperature - f.temperature).abs() < 0.02 * rise, "{i}: {} vs {}", c.temperature, f.temperature);
        // No swapping of the normal stresses from step to step.
        assert!((c.tau[(0, 0)] - c.tau[(1, 1)]).abs() < 0.05 * c.equivalent_stress, "{i}");
    }
}

// ---------------------------------------------------------------------------
// Runs through the pitfalls.
// ---------------------------------------------------------------------------

#[test]
fn adiabatic_softening_runs_up_to_melting() {
    // A low melting point: shear heating drives the point towards melting,
    // where its strength vanishes (the approach is asymptotic: the heating
    // rate is proportional to the vanishing strength).
    let mut m = weldox_460e();
    m.melting_temperature = 450.0;
    let config =
        DriverConfig { path: LoadPath::SimpleShear, rate: 1e4, final_strain: 4.0, dt: 1e-7, initial_temperature: None };
    let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
    let (peak_at, peak) =
        r.iter().map(|x| x.equivalent_stress).enumerate().fold((0, 0.0), |a, (i, v)| if v > a.1 { (i, v) } else { a });
    assert!(peak > 0.8 * m.yield_stress);
    let last = r.last().unwrap();
    assert!(last.equivalent_stress < 0.2 * peak, "{}", last.equivalent_stress);
    // Falls monotonically, up to the O(Δt) jump where the update switches to
    // the radial return (τ̄ < 3GΔt ε̇, Deviation 11; 2e-4 here).
    assert!(r[peak_at..].windows(2).all(|p| p[1].equivalent_stress <= p[0].equivalent_stress * (1.0 + 1e-3)));
    assert!(r.windows(2).all(|p| p[1].temperature >= p[0].temperature && p[1].eps_p >= p[0].eps_p));
    assert!(last.temperature > m.melting_temperature - 20.0 && last.temperature < m.melting_temperature);
}

#[test]
fn melted_point_flows_like_a_fluid_through_the_driver() {
    let m = weldox_460e();
    let config = DriverConfig {
        path: LoadPath::UniaxialStrain,
        rate: 1e4,
        final_strain: -0.02,
        dt: 1e-8,
        initial_temperature: Some(m.melting_temperature + 1.0),
    };
    let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
    let k = m.bulk_modulus();
    for x in &r {
        // No deviator, up to the round-off of (3p)/3.
        assert!(x.equivalent_stress <= 1e-15 * x.pressure.abs());
        // Pressure of the explicit hypoelastic update, K·|ε|, exactly linear.
        assert!((x.pressure + k * x.strain).abs() <= 1e-9 * k * 0.02);
        assert!((x.eps_p - 2.0 / 3.0 * x.strain.abs()).abs() < 1e-12);
        assert_eq!(x.temperature, m.melting_temperature + 1.0);
    }
}

#[test]
fn virgin_point_yields_under_every_path_and_law() {
    for m in [weldox_460e(), weldox_460e_borvik()] {
        for path in [LoadPath::UniaxialStrain, LoadPath::UniaxialStress, LoadPath::SimpleShear] {
            let config = DriverConfig { path, rate: 1e3, final_strain: 0.05, dt: 1e-7, initial_temperature: None };
            let r = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
            let last = r.last().unwrap();
            assert!(last.eps_p > 0.01, "{:?} {path:?}", m.rate_form);
            assert!(last.equivalent_stress < 1.5 * m.yield_stress, "{:?} {path:?}", m.rate_form);
        }
    }
}

/// A point whose Johnson–Cook damage reaches 1 keeps only compressive
/// pressure (`plugsim::material::fractured`); below 1 nothing changes.
#[test]
fn fractured_points_carry_only_compression() {
    let jc = weldox_460e();
    // shear plus volumetric stretch: tension and shear
    let d = M3::new(1e5, 2e5, 0.0, 2e5, 1e5, 0.0, 0.0, 0.0, 0.0);
    let k = StepKinematics { d, w: M3::zeros(), dt: 1e-8 };
    let tau0 = M3::new(3e8, 4e8, 0.0, 4e8, 3e8, 0.0, 0.0, 0.0, 1e8);
    let below = PointState { tau: tau0, eps_p: 0.5, eps_p_rate: 1e4, temperature: 400.0, damage: 0.2 };
    let own = jc.update(&below, &k);
    assert_eq!(fractured(own, 1.1), own, "intact points keep the model's update");
    let failed = PointState { damage: 1.0, ..below };
    let own = jc.update(&failed, &k);
    let s = fractured(own, 1.01);
    assert!(own.tau.trace() > 0.0 && (own.tau - M3::identity() * own.tau.trace() / 3.0).norm() > 1e8);
    assert_eq!(s.tau, M3::zeros(), "no tension, no shear: {}", s.tau);
    assert_eq!((s.eps_p, s.temperature, s.damage), (own.eps_p, own.temperature, own.damage));
    // compression stays, as pressure only
    let k_c = StepKinematics { d: M3::identity() * -1e5, w: M3::zeros(), dt: 1e-8 };
    let pressed = PointState { tau: M3::identity() * -5e8 + tau0 * 0.1, ..failed };
    let own = jc.update(&pressed, &k_c);
    let s = fractured(own, 0.99);
    assert!((s.tau - M3::identity() * (own.tau.trace() / 3.0)).norm() < 1e-9 * own.tau.norm());
    assert!(s.tau.trace() < -1.0e9);
}

/// A fractured point carries pressure only while closed (`J < 1`;
/// `plugsim::material::fractured`). The rate form alone measures pressure
/// from the last state: a fractured point opened to `J = 1.16` (its
/// tension dropped every step) and then squeezed back by 1 % would carry
/// `K · 0.01 ≈ 1.7 GPa`, a spring that pushes and never pulls with its
/// rest length at the largest stretch, which threw torn-off particles of
/// the Borvik Case I up at 700 m/s. Driven through that cycle, the point
/// carries nothing while open and the Kirchhoff pressure of its closure
/// once `J < 1` (`K ln J` within a few per cent: only the part of the path
/// below `J = 1` counts).
#[test]
fn open_fractured_material_does_not_push() {
    let jc = weldox_460e();
    let k_bulk = jc.bulk_modulus();
    let dt = 1e-8;
    let mut s = PointState { tau: M3::zeros(), eps_p: 1.0, eps_p_rate: 0.0, temperature: 293.0, damage: 1.0 };
    let mut ln_j: f64 = 0.0;
    // open to J = 1.16, close to J = 1.1484 (1 % squeeze), then to J = 0.98
    let legs: [(f64, usize); 3] = [(1.16_f64.ln(), 100), ((1.16_f64 * 0.99).ln(), 10), (0.98_f64.ln(), 100)];
    let mut squeezed_while_open = None;
    for (target, n) in legs {
        let rate = (target - ln_j) / (n as f64 * dt);
        for _ in 0..n {
            ln_j += rate * dt;
            let d = M3::identity() * (rate / 3.0);
            s = fractured(jc.update(&s, &StepKinematics { d, w: M3::zeros(), dt }), ln_j.exp());
        }
        if squeezed_while_open.is_none() && target < 1.16_f64.ln() && target > 0.0 {
            squeezed_while_open = Some(s.tau);
        }
    }
    assert_eq!(squeezed_while_open.unwrap(), M3::zeros(), "open material squeezed by 1 % pushes nothing");
    let p = s.tau.trace() / 3.0;
    let closed = k_bulk * 0.98_f64.ln();
    assert!(
        p < 0.0 && (p - closed).abs() < 0.05 * closed.abs(),
        "closed to J = 0.98: {p:.4e} vs K ln J = {closed:.4e}"
    );
    // the rate form without the closure condition pushes in the squeeze
    let mut s = PointState { tau: M3::zeros(), ..s };
    let rate = (0.99_f64).ln() / (10.0 * dt);
    for _ in 0..10 {
        s = fractured(jc.update(&s, &StepKinematics { d: M3::identity() * (rate / 3.0), w: M3::zeros(), dt }), 0.999);
    }
    assert!(s.tau.trace() / 3.0 < -1.0e9, "closed material squeezed by 1 % pushes back: {:.3e}", s.tau.trace() / 3.0);
}

// ---------------------------------------------------------------------------
// Adiabatic hardening (the onset of adiabatic shear localization).
// ---------------------------------------------------------------------------

/// With `m = 1` and no rate sensitivity the adiabatic stress–strain curve
/// has a closed form: `1 − T* = exp(−k (A ε̄ + B ε̄ⁿ⁺¹/(n+1)))`,
/// `k = χ/(ρ₀ C_p (T_m − T₀))`, so `τ̄ = (A + B ε̄ⁿ)(1 − T*)` peaks where
/// `B n ε̄ⁿ⁻¹ = k (A + B ε̄ⁿ)²`. The hardening vanishes there, on that
/// curve, and is positive before and negative after.
#[test]
fn adiabatic_hardening_vanishes_at_the_peak_of_the_closed_form_adiabatic_curve() {
    let m = JohnsonCook { softening_exponent: 1.0, rate_sensitivity: 0.0, ..weldox_460e() };
    let (a, b, n) = (m.yield_stress, m.hardening_modulus, m.hardening_exponent);
    let span = m.melting_temperature - m.room_temperature;
    let k = m.taylor_quinney / (m.density * m.specific_heat * span);
    let temperature =
        |e: f64| m.room_temperature + span * (1.0 - (-k * (a * e + b * e.powf(n + 1.0) / (n + 1.0))).exp());
    let excess = |e: f64| b * n * e.powf(n - 1.0) - k * (a + b * e.powf(n)).powi(2);
    let (mut lo, mut hi) = (1e-3, 10.0);
    assert!(excess(lo) > 0.0 && excess(hi) < 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let peak = 0.5 * (lo + hi);
    assert!(peak > 0.3 && peak < 3.0, "{peak}");
    let h = |e: f64| m.adiabatic_hardening(e, temperature(e), 0.0, 1.0);
    let scale = h(0.5 * peak);
    assert!(scale > 0.0);
    assert!(h(peak).abs() < 1e-9 * scale, "at the peak {}: {} (scale {scale})", peak, h(peak));
    assert!(h(0.9 * peak) > 0.0 && h(1.1 * peak) < 0.0);
    // The same through the material enum; an elastic material has none.
    assert_eq!(Material::JohnsonCook(m.clone()).adiabatic_hardening(peak, temperature(peak), 0.0, 1.0), Some(h(peak)));
    let elastic =
        Elastic { density: 7850.0, youngs_modulus: 200e9, poisson_ratio: 0.3, room_temperature: 293.0, thermal: None };
    assert_eq!(Material::Elastic(elastic).adiabatic_hardening(1.0, 293.0, 0.0, 1.0), None);
}

/// Weldox 460 E as it is (m = 0.94, rate-sensitive) in adiabatic simple
/// shear at 10⁴ 1/s through the material-point driver: the hardening
/// evaluated on the driver's states changes sign where the driver's
/// stress–strain curve peaks (the elastic part and the slow change of the
/// plastic rate make the two differ by a little).
#[test]
fn adiabatic_hardening_changes_sign_at_the_peak_of_the_driven_shear_curve() {
    let m = weldox_460e();
    let config =
        DriverConfig { path: LoadPath::SimpleShear, rate: 1e4, final_strain: 4.0, dt: 2e-7, initial_temperature: None };
    let records = run(&Material::JohnsonCook(m.clone()), &config).unwrap();
    let peak = records.iter().max_by(|x, y| x.equivalent_stress.partial_cmp(&y.equivalent_stress).unwrap()).unwrap();
    let onset = records
        .iter()
        .skip(1)
        .find(|r| m.adiabatic_hardening(r.eps_p, r.temperature, r.damage, r.eps_p_rate) <= 0.0)
        .expect("the point softens before gamma = 4");
    assert!(peak.eps_p > 1.0 && peak.eps_p < 3.0, "peak at {}", peak.eps_p);
    assert!((onset.eps_p - peak.eps_p).abs() < 0.005 * peak.eps_p, "onset at {}, peak at {}", onset.eps_p, peak.eps_p);
}

/// `∫ η dε̄`, the triaxiality integrated over the plastic strain
/// (`strain_path_increment`, the quadrature points' `triaxiality_strain`
/// and the output field `average_triaxiality`): per step, the exact
/// triaxialities of uniaxial tension (1/3), uniaxial compression (−1/3),
/// pure shear and a pure pressure (0), and nothing without flow; over an
/// elastic-plastic uniaxial-stress path (the driver's lateral stress
/// iterated to zero), the path's own 1/3 and −1/3 to the lateral
/// iteration's tolerance, the elastic start adding nothing.
#[test]
fn triaxiality_over_the_strain_path_averages_the_paths_own() {
    use plugsim::material::strain_path_increment;
    let diag = |a: f64, b: f64, c: f64| M3::from_diagonal(&nalgebra::Vector3::new(a, b, c));
    let s = 7.0e8;
    assert!(rel(strain_path_increment(&diag(s, 0.0, 0.0), 0.02), 0.02 / 3.0) < 1e-14);
    assert!(rel(strain_path_increment(&diag(-s, 0.0, 0.0), 0.02), -0.02 / 3.0) < 1e-14);
    assert_eq!(strain_path_increment(&diag(s, -s, 0.0), 0.02), 0.0);
    assert_eq!(strain_path_increment(&diag(-s, -s, -s), 0.02), 0.0, "no deviator: no triaxiality");
    assert_eq!(strain_path_increment(&diag(s, 0.0, 0.0), 0.0), 0.0, "no flow");
    for (strain, want) in [(0.3, 1.0 / 3.0), (-0.3, -1.0 / 3.0)] {
        let config = DriverConfig {
            path: LoadPath::UniaxialStress,
            rate: 1e3,
            final_strain: strain,
            dt: 0.3 / 1e3 / 3000.0,
            initial_temperature: None,
        };
        let r = run(&Material::JohnsonCook(weldox_460e()), &config).unwrap();
        let integral: f64 = r.windows(2).map(|p| strain_path_increment(&p[1].tau, p[1].eps_p - p[0].eps_p)).sum();
        let eps = r.last().unwrap().eps_p;
        assert!(eps > 0.25, "{eps}");
        assert!((integral / eps - want).abs() < 1e-6, "{strain}: {}", integral / eps);
    }
}
