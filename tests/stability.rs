//! The adaptive stable step (`src/stability.rs`): the frequency bound
//! against the exact highest frequency of the discrete system, the step
//! that follows a light (split) particle, and the central difference
//! across changes of step.

use nalgebra::{DMatrix, SymmetricEigen};
use plugsim::discretize::RectangleGrid;
use plugsim::geometry::GeometryMode;
use plugsim::material::{Elastic, Material};
use plugsim::math::{Block2, Real, Vec2};
use plugsim::model::{BodySetup, Model};
use plugsim::stability::{frequency_bounds, step_setters, stiffest_particle, stretch_ratio, Floors, StableStep};
use plugsim::step::{Simulation, TimeStepRule};

const E: Real = 200e9;
const NU: Real = 0.3;
const RHO: Real = 7850.0;

fn steel() -> Material {
    Material::Elastic(Elastic {
        density: RHO,
        youngs_modulus: E,
        poisson_ratio: NU,
        room_temperature: 293.0,
        thermal: None,
    })
}

/// A free elastic plate of `nx × ny` particles, spacing 1 mm.
fn plate(nx: usize, ny: usize) -> Model {
    let h = 1e-3;
    let grid = RectangleGrid {
        x_min: 0.0,
        x_max: (nx - 1) as Real * h,
        y_min: 0.0,
        y_max: (ny - 1) as Real * h,
        layers: ny,
        refine_at: Some(0.0),
        fine_half_width: 1.0,
        fine_spacing: Some(h),
        column_at: None,
        growth: 1.0,
        coarse_spacing: None,
        support_factor: 2.0,
        gauss: 2,
    };
    let body = BodySetup { name: "p".into(), grid, material: steel(), initial_velocity: vec![], supports: vec![] };
    Model::build(GeometryMode::PlaneStrain, &[body]).unwrap()
}

/// The exact highest frequency, rad/s, of the linearized plane-strain
/// system `M ü + K u = 0` of `model` about its state, assembled here
/// independently of the solver: `K = Σ_q B_qᵀ D B_q w_q` with the spatial
/// gradients `F_q⁻ᵀ ∇_X N_I` in `B` and the isotropic elastic moduli `D`,
/// `M` the lumped masses; the largest eigenvalue of `M^{-1/2} K M^{-1/2}`.
///
/// A point fractured by its damage (`D ≥ 1`) and closed (`J < 1`) resists
/// only a change of volume, with the bulk modulus `K` (it carries pressure
/// only); an eroded point adds nothing.
fn exact_highest_frequency(model: &Model) -> Real {
    let n = model.particles.len();
    let (lambda, mu) = (E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU)), E / (2.0 * (1.0 + NU)));
    let intact = nalgebra::Matrix3::new(lambda + 2.0 * mu, lambda, 0.0, lambda, lambda + 2.0 * mu, 0.0, 0.0, 0.0, mu);
    let k_bulk = E / (3.0 * (1.0 - 2.0 * NU));
    let pressure_only = nalgebra::Matrix3::new(k_bulk, k_bulk, 0.0, k_bulk, k_bulk, 0.0, 0.0, 0.0, 0.0);
    let mut k = DMatrix::<Real>::zeros(2 * n, 2 * n);
    let table = &model.qp_shape;
    for q in 0..model.quad.len() {
        let d = match (model.quad.eroded[q], model.quad.damage[q] >= 1.0) {
            (true, _) => continue,
            (false, true) if model.quad.f[q].determinant() < 1.0 => pressure_only,
            (false, true) => continue,
            (false, false) => intact,
        };
        let fi = model.quad.f[q].try_inverse().unwrap();
        let cols: Vec<(usize, nalgebra::Matrix3x2<Real>)> = table
            .range(q)
            .map(|e| {
                let g = table.grad[e];
                let (gx, gy) = (fi.xx * g.x + fi.yx * g.y, fi.xy * g.x + fi.yy * g.y);
                (table.index[e] as usize, nalgebra::Matrix3x2::new(gx, 0.0, 0.0, gy, gy, gx))
            })
            .collect();
        let w = model.quad.weight[q];
        for (i, bi) in &cols {
            for (j, bj) in &cols {
                let kij = bi.transpose() * d * bj * w;
                for a in 0..2 {
                    for b in 0..2 {
                        k[(2 * i + a, 2 * j + b)] += kij[(a, b)];
                    }
                }
            }
        }
    }
    let s: Vec<Real> = (0..2 * n).map(|r| 1.0 / model.particles.mass[r / 2].sqrt()).collect();
    let a = DMatrix::from_fn(2 * n, 2 * n, |r, c| k[(r, c)] * s[r] * s[c]);
    SymmetricEigen::new(a).eigenvalues.max().sqrt()
}

fn bound(model: &Model) -> Real {
    stiffest_particle(model, true, false).0
}

/// The bound's growth against the exact frequency's: within −15 % (the
/// step would then take up to 15 % of the margin the spacing step keeps
/// on the reference lattice, about 2.5×) and +50 % (a step smaller than
/// needed costs time, not stability).
fn tracks(bound_ratio: Real, exact_ratio: Real) {
    assert!(
        bound_ratio >= 0.85 * exact_ratio && bound_ratio <= 1.5 * exact_ratio,
        "the bound grew {bound_ratio:.3}x where the exact frequency grew {exact_ratio:.3}x"
    );
}

/// Gershgorin's bound exceeds the exact highest frequency of the lattice
/// (by a constant of the lattice, under 2 here), and it follows the exact
/// frequency when one particle loses mass (a split child: 1/8 raises the
/// highest frequency by 22 %, the bound by 53 %) or the body is
/// compressed (to 60 % across: 54 % and 35 %). The step `Δt₀ ω_ref /
/// ω_bound` keeps about the margin the spacing step has on the undeformed
/// lattice.
#[test]
fn frequency_bound_tracks_the_exact_highest_frequency() {
    let reference = plate(9, 6);
    let (exact0, bound0) = (exact_highest_frequency(&reference), bound(&reference));
    assert!(bound0 >= exact0, "the bound {bound0:e} is below the exact {exact0:e}");
    assert!(bound0 < 2.0 * exact0, "the bound {bound0:e} is loose against {exact0:e}");
    // The reference configuration's bound equals the deformed one's at F = I.
    assert_eq!(stiffest_particle(&reference, false, false).0, bound0);

    // A light particle inside the plate, as a split leaves one.
    let mut light = reference.clone();
    light.particles.mass[22] /= 8.0;
    let (exact, b) = (exact_highest_frequency(&light), bound(&light));
    assert!(exact > 1.1 * exact0, "a light particle raises the highest frequency ({exact:e} against {exact0:e})");
    tracks(b / bound0, exact / exact0);

    // The plate compressed to 60 % across (uniform F).
    let mut squeezed = reference.clone();
    squeezed.quad.f.fill(Block2 { xx: 0.6, xy: 0.0, yx: 0.0, yy: 1.0, zz: 1.0 });
    let (exact, b) = (exact_highest_frequency(&squeezed), bound(&squeezed));
    assert!(exact > 1.4 * exact0, "compression raises the highest frequency ({exact:e} against {exact0:e})");
    tracks(b / bound0, exact / exact0);
}

/// Held components leave a particle's row: a clamped particle has none.
#[test]
fn clamped_particles_have_no_frequency() {
    let mut model = plate(6, 4);
    model.particles.flags[0].set(plugsim::particles::ParticleFlags::FIX_X | plugsim::particles::ParticleFlags::FIX_Y);
    let bounds = frequency_bounds(&model, false, false);
    assert_eq!(bounds[0], 0.0);
    assert!(bounds[1..].iter().all(|&b| b > 0.0));
}

/// A vibrating plate with a small initial velocity field.
fn vibrating(model: Model, rule: TimeStepRule) -> Simulation {
    let mut sim = Simulation::new(model, rule);
    for i in 0..sim.model.particles.len() {
        let x = sim.model.particles.x0[i] * 1e3;
        sim.model.particles.v[i] = Vec2::new((0.9 * x.y).sin(), (0.7 * x.x + 0.3).cos());
    }
    sim.energies.kinetic = plugsim::step::kinetic_energy(&sim.model.particles.mass, &sim.model.particles.v);
    sim.energies.initial_kinetic = sim.energies.kinetic;
    sim
}

/// A particle whose mass drops to a hundredth during the run (an extreme
/// split child) makes the spacing step unstable: the motion grows without
/// bound. The adaptive step, evaluated after the change as the time loop
/// does after every split, shrinks to a quarter, and the same run keeps
/// its energy.
#[test]
fn the_step_follows_a_light_particle() {
    let run = |rule: TimeStepRule| {
        let model = plate(9, 6);
        let dt0 = 0.5 * model.min_spacing() / model.max_wave_speed();
        let rule = match rule {
            TimeStepRule::Fixed(_) => TimeStepRule::Fixed(dt0),
            r => r,
        };
        let mut sim = vibrating(model, rule);
        for _ in 0..10 {
            sim.step().unwrap();
        }
        sim.model.particles.mass[22] /= 100.0;
        sim.refresh_time_step();
        let mut largest: Real = 0.0;
        for _ in 0..400 {
            if sim.step().is_err() {
                return (Real::INFINITY, sim.dt / dt0);
            }
            largest = largest.max(sim.energies.drift().abs());
        }
        (largest, sim.dt / dt0)
    };
    let (fixed_drift, _) = run(TimeStepRule::Fixed(0.0));
    let (adaptive_drift, ratio) = run(TimeStepRule::Cfl { safety: 0.5 });
    assert!(fixed_drift > 1.0, "the spacing step stays stable ({fixed_drift})");
    assert!(ratio < 0.6, "the step did not shrink ({ratio})");
    // A constant step leaves the same vibration's balance within about 1 %.
    assert!(adaptive_drift < 0.02, "energy drift {adaptive_drift} with the adaptive step");
}

/// The central difference across changes of step: alternating the step
/// between `Δt` and `Δt/2` every few steps keeps the energy of a free
/// vibration as a constant step does (max drift 0.9 % with the constant
/// step, 2.3 % alternating; the velocity update spans the mean of the two
/// steps), while a velocity update by the new step alone pumps energy in
/// at every change until the balance blows up; the motion stays close to
/// a run at the constant small step.
#[test]
fn changes_of_step_keep_the_central_difference_second_order() {
    let model = plate(9, 6);
    let dt = 0.5 * model.min_spacing() / model.max_wave_speed();
    let steps = 600;
    // Whole blocks: 4 steps of dt, then 8 of dt/2.
    let step_of = |k: usize| if k % 12 < 4 { dt } else { dt / 2.0 };
    let run = |mean_velocity_step: bool| {
        let mut sim = vibrating(model.clone(), TimeStepRule::Fixed(dt));
        let mut drift: Real = 0.0;
        for k in 0..steps {
            sim.dt = step_of(k);
            if !mean_velocity_step {
                sim.dt_previous = sim.dt;
            }
            if sim.step().is_err() {
                return (sim, Real::INFINITY);
            }
            drift = drift.max(sim.energies.drift().abs());
        }
        (sim, drift)
    };
    let (switching, drift) = run(true);
    let (_, naive) = run(false);
    assert!(drift < 0.05 && switching.energies.drift().abs() < 0.01, "energy drift {drift} across changes of step");
    assert!(naive > 0.5, "the velocity update by the new step alone keeps the energy ({naive})");
    let mut steady = vibrating(model, TimeStepRule::Fixed(dt / 2.0));
    while steady.time < switching.time - 1e-3 * dt {
        steady.step().unwrap();
    }
    assert!((switching.time - steady.time).abs() < 1e-6 * dt);
    let (a, b) = (&switching.model.particles.u, &steady.model.particles.u);
    let scale = b.iter().map(|u| u.norm()).fold(0.0, Real::max);
    let error = a.iter().zip(b).map(|(x, y)| (x - y).norm()).fold(0.0, Real::max);
    assert!(error < 1e-2 * scale, "displacement differs by {error:e} (scale {scale:e})");
}

/// Mass scaling (`[time] mass_scaling`) after the extreme split child of
/// `the_step_follows_a_light_particle`: with a floor of half the spacing
/// step, the step stays there (the adaptive step alone goes below a
/// quarter); mass goes only to the light particle, at rest (its momentum
/// stays, the kinetic energy taken out is booked), and no more than the
/// bound asks: its bound sits on the target. Checked against the exact
/// highest frequency of the scaled system (assembled independently): the
/// step keeps the margin the spacing step has on the reference lattice,
/// and the run keeps its energy.
#[test]
fn mass_scaling_holds_the_step_at_its_floor_and_keeps_the_margin() {
    let model = plate(9, 6);
    let dt0 = 0.5 * model.min_spacing() / model.max_wave_speed();
    let margin0 = exact_highest_frequency(&model) * dt0;
    let mut sim = vibrating(model, TimeStepRule::Cfl { safety: 0.5 });
    sim.floors.mass_scaling = Some(0.5);
    for _ in 0..10 {
        sim.step().unwrap();
    }
    let light = 22;
    let m_light = sim.model.particles.mass[light] / 100.0;
    sim.model.particles.mass[light] = m_light;
    let momentum = sim.model.particles.momentum();
    let kinetic = plugsim::step::kinetic_energy(&sim.model.particles.mass, &sim.model.particles.v);
    sim.refresh_time_step();
    let p = &sim.model.particles;
    assert!((sim.dt / dt0 - 0.5).abs() < 1e-9, "the step {} of the spacing step's", sim.dt / dt0);
    // Only the light particle gets mass, and its row meets the target.
    let added: Vec<usize> = (0..p.len()).filter(|&i| p.added_mass[i] > 0.0).collect();
    assert_eq!(added, vec![light]);
    assert!((p.mass[light] - m_light - p.added_mass[light]).abs() < 1e-15 * p.mass[light]);
    let stable = sim.stable.as_ref().unwrap();
    assert_eq!(stable.added.mass, p.added_mass[light]);
    let bounds = frequency_bounds(&sim.model, true, false);
    let top = bounds.iter().cloned().fold(0.0, Real::max);
    let target = (stable.reference / 0.5).powi(2);
    assert!((top / target - 1.0).abs() < 1e-9, "the stiffest bound {top:e} against the target {target:e}");
    assert!((bounds[light] / target - 1.0).abs() < 1e-9);
    // Momentum kept; the kinetic energy taken out is what the balance books.
    let dp = (sim.model.particles.momentum() - momentum).norm();
    assert!(dp <= 1e-13 * momentum.norm().max(1e-30), "momentum moved by {dp:e}");
    let after = plugsim::step::kinetic_energy(&sim.model.particles.mass, &sim.model.particles.v);
    assert!(sim.energies.mass_scaling > 0.0);
    assert!((kinetic - after - sim.energies.mass_scaling).abs() < 1e-12 * kinetic);
    // The exact highest frequency of the scaled system: the step keeps the
    // spacing step's margin (within the bound's tracking, +15 %).
    let margin = exact_highest_frequency(&sim.model) * sim.dt;
    eprintln!(
        "light particle: {:.2}x its mass after scaling; ω dt {margin:.3} (reference lattice {margin0:.3}); kinetic energy out {:.2e} of {kinetic:.2e} J",
        sim.model.particles.mass[light] / m_light,
        sim.energies.mass_scaling
    );
    assert!(margin <= 1.15 * margin0, "ω dt = {margin:.3} against {margin0:.3} on the reference lattice");
    let mut largest: Real = 0.0;
    for _ in 0..400 {
        sim.step().unwrap();
        largest = largest.max(sim.energies.drift().abs());
    }
    assert!(largest < 0.02, "energy drift {largest} with mass scaling");
    assert!(sim.dt >= 0.5 * dt0 * (1.0 - 1e-9));
}

/// A failed sliver: the quadrature points of a few cells fractured by
/// their damage (`D ≥ 1`, pressure only) and sheared at nearly constant volume to a stretch of
/// about 12, as the punch shears the impact face's sliver between a rim
/// crack and the projectile's edge at 96 rows (`docs/performance.md`,
/// "The fine rungs: what sets their step"). It alone takes the step far
/// below the spacing step. With the erosion floor at half the spacing step
/// some of those points, and no other, are eroded; the step is the spacing step again,
/// and the exact highest frequency of the system (assembled independently,
/// the fractured points at their bulk modulus) confirms both: with the
/// sliver the spacing step is unstable (`ω Δt₀ > 2`), after erosion the
/// step keeps half the stability limit (`ω Δt < 1`; 0.80 on the reference
/// lattice). The same distortion at an intact point, or at a
/// point short of fracture (`D = 0.9`), erodes nothing; a mildly sheared
/// fractured point (stretch 1.3) is left alone, as it does not take the
/// step below the floor; without the floor nothing is eroded.
#[test]
fn erosion_at_the_floor_removes_a_failed_sliver_and_only_it() {
    let reference = plate(9, 6);
    let dt0 = 0.5 * reference.min_spacing() / reference.max_wave_speed();
    let margin0 = exact_highest_frequency(&reference) * dt0;
    // The sliver: the points of the cells around the plate's middle.
    let middle = Vec2::new(4e-3, 2.5e-3);
    let sliver: Vec<usize> =
        (0..reference.quad.len()).filter(|&p| (reference.quad.x0[p] - middle).norm() < 0.8e-3).collect();
    assert!(sliver.len() >= 4, "{sliver:?}");
    // Simple shear by γ at volume ratio J.
    let sheared = |gamma: Real, j: Real| {
        let s = j.sqrt();
        Block2 { xx: s, xy: s * gamma, yx: 0.0, yy: s, zz: 1.0 }
    };
    let evaluate = |damage: Real, gamma: Real, floor: Option<Real>| {
        let mut model = plate(9, 6);
        for &q in &sliver {
            model.quad.f[q] = sheared(gamma, 0.99);
            model.quad.damage[q] = damage;
        }
        let mut stable = StableStep::new(&model, dt0);
        let floors = Floors { erosion: floor, ..Floors::default() };
        let (dt, removed) = stable.evaluate(&mut model, 0.0, true, 0.0, floors);
        assert_eq!(removed, 0.0);
        (model, stable, dt)
    };
    // Without the floor the sliver takes the step down.
    let (model, stable, dt) = evaluate(1.5, 12.0, None);
    assert_eq!((stable.eroded, model.quad.eroded.iter().filter(|&&e| e).count()), (0, 0));
    let with_sliver = exact_highest_frequency(&model) * dt0;
    assert!(dt < 0.5 * dt0, "the sliver's step {} of the spacing step's", dt / dt0);
    assert!(with_sliver > 2.0 * margin0, "exact ω Δt₀ {with_sliver:.3} against {margin0:.3}");
    // With it, only the sliver's points go, and the step comes back.
    let (model, stable, dt) = evaluate(1.5, 12.0, Some(0.5));
    let eroded: Vec<usize> = (0..model.quad.len()).filter(|&p| model.quad.eroded[p]).collect();
    assert!(!eroded.is_empty() && eroded.iter().all(|p| sliver.contains(p)), "eroded {eroded:?} of {sliver:?}");
    assert_eq!(stable.eroded, eroded.len() as u64);
    assert!(eroded.iter().all(|&p| model.quad.tau[p] == Block2::zeros() && model.quad.pw_zz[p] == 0.0));
    assert!(dt >= 0.5 * dt0, "the step {} of the spacing step's after erosion", dt / dt0);
    let margin = exact_highest_frequency(&model) * dt;
    eprintln!(
        "sliver: {} of {} points eroded; exact ω Δt₀ {with_sliver:.3} with it, ω Δt {margin:.3} after erosion (reference {margin0:.3}); step {:.3} Δt₀",
        eroded.len(),
        sliver.len(),
        dt / dt0
    );
    // The central difference is stable below ω Δt = 2; the spacing step
    // keeps 0.80 on the reference lattice, and the step after erosion (its
    // bound at or under the floor's target, the bound as loose as a
    // lattice's) keeps half the limit.
    assert!(with_sliver > 2.0 && margin < 1.0, "ω Δt = {margin:.3} against {margin0:.3} on the reference lattice");
    // What the floor does not erode: intact or merely damaged points at the
    // same distortion, and a fractured point the step tolerates.
    for (damage, gamma) in [(0.0, 12.0), (0.9, 12.0), (1.5, 1.3)] {
        let (model, stable, dt) = evaluate(damage, gamma, Some(0.5));
        assert!(model.quad.eroded.iter().all(|&e| !e), "D = {damage}, γ = {gamma}: a point eroded");
        assert_eq!(stable.eroded, 0);
        if damage < 1.0 {
            assert!(dt < 0.5 * dt0, "D = {damage}: the step {} of the spacing step's", dt / dt0);
        }
    }
}

/// `plugsim time-step`'s report ([`step_setters`]) against exact answers.
/// A uniform in-plane compression `F = ½ I` doubles every spatial
/// gradient, so every particle's bound rises by exactly 4 (its
/// distortion), the stiffest allows exactly half the spacing step, every
/// live point reads `J = ¼` and a stretch ratio of 1. A particle at a
/// hundredth of its mass on the undeformed lattice comes first, with no
/// distortion, allowing exactly the step the run's own evaluation takes.
/// The stretch ratio of a simple shear `γ` is `σ₁²` with `σ₁ = γ/2 +
/// √(1 + γ²/4)`.
#[test]
fn the_time_step_report_names_what_sets_the_step() {
    let mut sim = Simulation::new(plate(9, 6), TimeStepRule::Cfl { safety: 0.5 });
    let stable = sim.stable.clone().expect("the adaptive step");
    let n = sim.model.particles.len();
    let close = |a: Real, b: Real| (a - b).abs() <= 1e-12 * b.abs();
    for f in sim.model.quad.f.iter_mut() {
        *f = Block2 { xx: 0.5, xy: 0.0, yx: 0.0, yy: 0.5, zz: 1.0 };
    }
    let squeezed = step_setters(&sim.model, &stable, false, n);
    assert_eq!(squeezed.len(), n);
    assert!(close(squeezed[0].step, 0.5 * stable.base), "{} of {}", squeezed[0].step, stable.base);
    for s in &squeezed {
        assert!(close(s.distortion, 4.0), "particle {}: {}", s.particle, s.distortion);
        assert!(close(s.least_j, 0.25) && close(s.largest_stretch, 1.0), "{s:?}");
        assert_eq!((s.eroded, s.fractured, s.added_mass), (0, 0, 0.0));
    }
    assert!(squeezed.windows(2).all(|w| w[0].step <= w[1].step), "smallest step first");
    for f in sim.model.quad.f.iter_mut() {
        *f = Block2::identity_scaled(1.0);
    }
    sim.model.particles.mass[22] /= 100.0;
    let light = step_setters(&sim.model, &stable, false, 3);
    assert_eq!(light.len(), 3);
    assert_eq!(light[0].particle, 22);
    assert!(close(light[0].distortion, 1.0), "{}", light[0].distortion);
    sim.refresh_time_step();
    assert_eq!(sim.dt, light[0].step, "the run's own evaluation");
    let gamma: Real = 3.0;
    let s1 = 0.5 * gamma + (1.0 + 0.25 * gamma * gamma).sqrt();
    let shear = Block2 { xx: 1.0, xy: gamma, yx: 0.0, yy: 1.0, zz: 1.0 };
    assert!(close(stretch_ratio(&shear), s1 * s1), "{} vs {}", stretch_ratio(&shear), s1 * s1);
    assert!(close(stretch_ratio(&Block2::identity_scaled(0.3)), 1.0));
    assert_eq!(stretch_ratio(&Block2 { xx: 1.0, xy: 2.0, yx: 0.5, yy: 1.0, zz: 1.0 }), Real::INFINITY);
}
