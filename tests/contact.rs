//! Contact with rigid bodies (SPEC §8): search against a brute-force
//! reference, one-step normal force, friction, spreading, momentum and
//! energy, rigid-body masses, surface detection, and the comparison of the
//! spreading modes on an elastic impact.
//!
//! The time loop of SPEC §5 is reproduced here in a few lines ([`step`]) so
//! the contact stage is tested without the solver. RK shape functions come
//! from a small reference builder ([`rk_table`], SPEC §3) written for these
//! tests.

use nalgebra::{Matrix4, Vector4};
use plugsim::contact::search::check_pairing;
use plugsim::contact::*;
use plugsim::kernel::window_cubic_spline_2d;
use plugsim::math::{Real, Vec2};
use plugsim::particles::{ParticleFlags, Particles};
use plugsim::shape::ShapeTable;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

const STEEL_DENSITY: Real = 7850.0;
const MODES: [Spreading; 4] =
    [Spreading::None, Spreading::InverseDistance, Spreading::ShapeFunction, Spreading::MassWeighted];

// ---------------------------------------------------------------- helpers

/// SplitMix64 in [0, 1): deterministic random numbers for seeded loops.
fn splitmix(state: &mut u64) -> Real {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as Real / (1u64 << 53) as Real
}

/// Reference RK shape functions (SPEC §3: bilinear basis, tensor-product
/// cubic B-spline window, gradients through `M⁻¹`) of `nodes` at `points`,
/// by an O(n·m) loop.
fn rk_table(nodes: &[Vec2], volume: &[Real], support: &[Real], points: &[Vec2]) -> ShapeTable {
    let mut t = ShapeTable { offsets: vec![0], ..ShapeTable::default() };
    for x in points {
        let mut m = Matrix4::<Real>::zeros();
        let mut dm = [Matrix4::<Real>::zeros(); 2];
        let mut near = Vec::new();
        for (i, xi) in nodes.iter().enumerate() {
            let z = x - xi;
            let (phi, dphi) = window_cubic_spline_2d(&z, support[i]);
            if phi == 0.0 {
                continue;
            }
            let p = Vector4::new(1.0, z.x, z.y, z.x * z.y);
            let dp = [Vector4::new(0.0, 1.0, 0.0, z.y), Vector4::new(0.0, 0.0, 1.0, z.x)];
            let w = phi * volume[i];
            m += p * p.transpose() * w;
            for k in 0..2 {
                dm[k] +=
                    (dp[k] * p.transpose() + p * dp[k].transpose()) * w + p * p.transpose() * (dphi[k] * volume[i]);
            }
            near.push((i, p, dp, phi, dphi));
        }
        let minv = m.try_inverse().expect("moment matrix");
        let b: Vector4<Real> = minv.column(0).into();
        let db = [-(minv * dm[0] * b), -(minv * dm[1] * b)];
        for (i, p, dp, phi, dphi) in near {
            let v = volume[i];
            t.index.push(i as u32);
            t.value.push(b.dot(&p) * phi * v);
            let g = |k: usize| (db[k].dot(&p) + b.dot(&dp[k])) * phi * v + b.dot(&p) * dphi[k] * v;
            t.grad.push(Vec2::new(g(0), g(1)));
        }
        t.offsets.push(t.index.len());
    }
    t
}

/// Half the distance to each neighbour summed: the 1D Voronoi width of
/// each coordinate of a sorted list.
fn voronoi_widths(c: &[Real]) -> Vec<Real> {
    let n = c.len();
    (0..n)
        .map(|k| {
            let left = if k > 0 { c[k] - c[k - 1] } else { 0.0 };
            let right = if k + 1 < n { c[k + 1] - c[k] } else { 0.0 };
            0.5 * (left + right)
        })
        .collect()
}

/// Largest gap to a neighbour in a sorted coordinate list.
fn local_gaps(c: &[Real]) -> Vec<Real> {
    let n = c.len();
    (0..n)
        .map(|k| {
            let left = if k > 0 { c[k] - c[k - 1] } else { 0.0 };
            let right = if k + 1 < n { c[k + 1] - c[k] } else { 0.0 };
            left.max(right)
        })
        .collect()
}

/// A lattice of particles at `xs × ys` (index `j·nx + i`), Voronoi volumes,
/// masses `ρ ΔV`, spacing = larger local gap, support = 2 × spacing
/// (SPEC §3 default).
fn lattice(xs: &[Real], ys: &[Real]) -> Particles {
    let (wx, wy) = (voronoi_widths(xs), voronoi_widths(ys));
    let (gx, gy) = (local_gaps(xs), local_gaps(ys));
    let mut p = Particles::default();
    for (j, y) in ys.iter().enumerate() {
        for (i, x) in xs.iter().enumerate() {
            let h = gx[i].max(gy[j]);
            let k = p.push(Vec2::new(*x, *y), wx[i] * wy[j], h, 2.0 * h, 293.0, 0, ParticleFlags::default());
            p.mass[k] = STEEL_DENSITY * p.volume[k];
        }
    }
    p
}

fn uniform(n: usize, h: Real, start: Real) -> Vec<Real> {
    (0..n).map(|k| start + k as Real * h).collect()
}

/// The particle shape table `N_J(X_I)` (rows = particles).
fn particle_table(p: &Particles) -> ShapeTable {
    rk_table(&p.x0, &p.volume, &p.support, &p.x0)
}

/// One step of SPEC §5's central difference with the contact stage, as the
/// solver does it (`f_int`, `f_ext` already in `p`).
#[allow(clippy::needless_range_loop)] // particle columns indexed in parallel
fn step(
    sys: &mut ContactSystem,
    p: &mut Particles,
    shape: Option<&ShapeTable>,
    dt: Real,
    f_c: &mut Vec<Vec2>,
) -> StepReport {
    f_c.resize(p.len(), Vec2::zeros());
    let report = sys.compute_forces(&StepInput::from_particles(p, shape, dt), f_c).unwrap();
    for i in 0..p.len() {
        let a = (p.f_ext[i] + f_c[i] - p.f_int[i]) / p.mass[i];
        p.v[i] += a * dt;
        let flags = p.flags[i];
        flags.constrain(&mut p.v[i]);
        p.u[i] += p.v[i] * dt;
    }
    sys.advance(&p.v).unwrap();
    report
}

fn single_particle(x0: Vec2, mass: Real) -> Particles {
    let mut p = Particles::default();
    p.push(x0, 1e-6, 1e-3, 2e-3, 293.0, 0, ParticleFlags::default());
    p.mass[0] = mass;
    p
}

/// A wide static wall whose top face (segment 2, normal +y) is at `y = top`.
fn wall(top: Real) -> RigidBody {
    RigidBody::new("wall", rectangle_outline(1.0, 0.2), Vec2::new(0.0, top - 0.1), Vec2::zeros(), 1.0)
        .unwrap()
        .with_prescribed_velocity(Vec2::zeros())
}

fn kinetic(p: &Particles) -> Real {
    (0..p.len()).map(|i| 0.5 * p.mass[i] * p.v[i].norm_squared()).sum()
}

// ---------------------------------------------------------------- search

/// A random star-shaped (hence simple) counter-clockwise polygon.
fn star_polygon(n: usize, s: &mut u64) -> Vec<Vec2> {
    (0..n)
        .map(|k| {
            let th = 2.0 * std::f64::consts::PI * (k as Real + 0.9 * splitmix(s)) / n as Real;
            let r = 0.2 + 0.8 * splitmix(s);
            Vec2::new(r * th.cos(), r * th.sin())
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 96,
        rng_seed: RngSeed::Fixed(0x5EED_C0DE),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// SPEC §8 coarse-to-fine search: the grid's nearest vertex gives the
    /// same pairing (feature, gap, normal) as the O(n) reference.
    #[test]
    fn search_matches_brute_force_on_random_outlines(n in 3usize..160, seed in any::<u64>()) {
        let mut s = seed;
        let outline = star_polygon(n, &mut s);
        let position = Vec2::new(splitmix(&mut s) - 0.5, splitmix(&mut s) - 0.5);
        let body = RigidBody::new("star", outline, position, Vec2::zeros(), 1.0).unwrap();
        for _ in 0..200 {
            let y = Vec2::new(3.0 * splitmix(&mut s) - 1.5, 3.0 * splitmix(&mut s) - 1.5);
            let d = y + Vec2::new(splitmix(&mut s) - 0.5, splitmix(&mut s) - 0.5) * 0.1;
            prop_assert_eq!(search_rigid_polygon(&body, &position, &y, &d), search_rigid_polygon_brute_force(&body, &position, &y, &d));
        }
        // and the corner/abreast cases of a rectangle, on its exact lattice
        let rect = RigidBody::new("r", rectangle_outline(2.0, 8.0), Vec2::zeros(), Vec2::zeros(), 1.0).unwrap();
        for k in 0..121 {
            let y = Vec2::new(-1.5 + 0.3 * (k % 11) as Real, -4.5 + 0.9 * (k / 11) as Real);
            let o = Vec2::zeros();
            prop_assert_eq!(search_rigid_polygon(&rect, &o, &y, &y), search_rigid_polygon_brute_force(&rect, &o, &y, &y));
        }
    }
}

/// At scale (a 4000-vertex outline, many cells, 2000 points near it) the
/// grid still returns the brute-force pairing.
#[test]
fn search_matches_brute_force_on_a_fine_outline() {
    let mut s = 99u64;
    let outline = star_polygon(4000, &mut s);
    let body = RigidBody::new("fine", outline, Vec2::zeros(), Vec2::zeros(), 1.0).unwrap();
    for _ in 0..2000 {
        let th = 2.0 * std::f64::consts::PI * splitmix(&mut s);
        let y = Vec2::new(th.cos(), th.sin()) * (0.1 + 1.1 * splitmix(&mut s));
        assert_eq!(
            search_rigid_polygon(&body, &Vec2::zeros(), &y, &y),
            search_rigid_polygon_brute_force(&body, &Vec2::zeros(), &y, &y)
        );
    }
}

/// Reusing last step's pairing while its local test holds gives the fresh
/// search's answer on a rectangle for points circling a corner outside it
/// (inside, reuse deliberately keeps the face crossed: `search` module doc).
#[test]
fn pairing_reuse_agrees_with_fresh_search_outside() {
    let body = RigidBody::new("p", rectangle_outline(20.0, 80.0), Vec2::zeros(), Vec2::zeros(), 1.0).unwrap();
    let o = Vec2::zeros();
    let mut last: Option<MasterFeature> = None;
    let mut reused = 0;
    for k in 0..4000 {
        // a path around the corner (10, -40), always outside the body
        let t = -0.5 * std::f64::consts::PI + 0.75 * std::f64::consts::PI * (k as Real / 4000.0);
        let r = 0.2 + 2.0 * (7.0 * t).sin().abs();
        let y = Vec2::new(10.0, -40.0) + Vec2::new(t.cos(), t.sin()) * r;
        let fresh = search_rigid_polygon(&body, &o, &y, &y).unwrap();
        assert!(fresh.gap > 0.0);
        let got = match last.and_then(|f| check_pairing(&body, &o, f, &y)) {
            Some(p) => {
                reused += 1;
                p
            }
            None => fresh,
        };
        assert_eq!(got, fresh, "step {k}, y = {y:?}");
        last = Some(got.feature);
    }
    assert!(reused > 3900, "reuse should be the common case, got {reused}");
}

// ---------------------------------------------------------------- forces

/// SPEC §8 one-step normal force: after the force and one central-difference
/// step, a free particle that crosses the master surface in the step lies
/// exactly on it — for a flat wall and for an inclined face of a moving
/// body, with a contact-free load acting too.
#[test]
fn one_step_normal_force_puts_free_particle_on_surface() {
    let dt = 1e-7;
    // (a) particle moving into a static wall
    let mut p = single_particle(Vec2::new(0.0, 1e-6), 2e-4);
    p.v[0] = Vec2::new(3.0, -40.0);
    p.f_ext[0] = Vec2::new(0.5, -2.0);
    let none = ContactParameters { spreading: Spreading::None, ..ContactParameters::default() };
    let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), none).unwrap();
    let mut f = Vec::new();
    let r = step(&mut sys, &mut p, None, dt, &mut f);
    assert_eq!(r.active_contacts, 1);
    let g_pred = sys.contacts()[0].gap;
    assert!(g_pred < -1e-6);
    let y_end = p.x0[0].y + p.u[0].y;
    assert!(y_end.abs() <= 1e-12 * g_pred.abs(), "end gap {y_end:e}, predicted {g_pred:e}");
    assert_eq!(p.v[0].x, 3.0 + dt * 0.5 / 2e-4); // frictionless: tangential motion untouched

    // (b) a wedge (inclined faces) driven at a prescribed velocity
    let wedge = vec![Vec2::new(0.0, -1e-3), Vec2::new(2e-3, 1e-3), Vec2::new(-2e-3, 1e-3)];
    let body = RigidBody::new("wedge", wedge, Vec2::new(0.0, 0.0), Vec2::zeros(), 1.0)
        .unwrap()
        .with_prescribed_velocity(Vec2::new(5.0, -30.0));
    // 1.4 µm outside the face x − y = 1e-3 at the start, closing at
    // 4.6 µm a step.
    let mut p = single_particle(Vec2::new(6e-4 + 1e-6, -4e-4 - 1e-6), 1e-4);
    p.v[0] = Vec2::new(-10.0, 20.0);
    p.f_int[0] = Vec2::new(1.0, 1.0);
    let mut sys = ContactSystem::new(vec![body], SlaveSet::from_indices([0]), none).unwrap();
    step(&mut sys, &mut p, None, dt, &mut f);
    let c = sys.contacts()[0];
    assert_eq!(c.pairing.feature, MasterFeature::Segment(0));
    let x = p.x0[0] + p.u[0];
    let g_end = search_rigid_polygon(&sys.bodies[0], &sys.bodies[0].position, &x, &x).unwrap().gap;
    assert!(g_end.abs() <= 1e-12 * c.gap.abs(), "end gap {g_end:e}, predicted {:e}", c.gap);
}

/// A particle that starts the step inside the master beyond round-off
/// ([`plugsim::contact::force::gap_floor`]) is held at its depth, not put
/// on the surface: SPEC §8's force would throw it out at `|g⁰|/Δt`, here
/// 3 km/s. Its normal velocity is stopped, not reversed; the tangential
/// one is untouched (frictionless).
#[test]
fn a_particle_starting_inside_is_held_not_pushed_out() {
    let dt = 1e-7;
    let depth = 3e-4; // 0.3 h
    let mut p = single_particle(Vec2::new(0.0, -depth), 2e-4);
    p.v[0] = Vec2::new(3.0, -40.0);
    let none = ContactParameters { spreading: Spreading::None, ..ContactParameters::default() };
    let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), none).unwrap();
    let mut f = Vec::new();
    let r = step(&mut sys, &mut p, None, dt, &mut f);
    assert_eq!(r.active_contacts, 1);
    let y_end = p.x0[0].y + p.u[0].y;
    assert!((y_end + depth).abs() <= 1e-12 * depth, "end gap {y_end:e}, start gap {:e}", -depth);
    assert!(p.v[0].y.abs() <= 1e-9, "normal velocity {:e}", p.v[0].y);
    assert_eq!(p.v[0].x, 3.0);
}

/// A 7 × 5 lattice (h = 1 mm) with random displacements, velocities and
/// internal forces from `seed` (and masses scaled by 0.2–1.8 if
/// `unequal_masses`), its shape table, and the middle particle of its top
/// row: one slave and its row for the isolated-contact tests.
fn loaded_patch(seed: u64, unequal_masses: bool) -> (Particles, ShapeTable, usize) {
    let h = 1e-3;
    let mut p = lattice(&uniform(7, h, -3.0 * h), &uniform(5, h, -4.0 * h));
    let shape = particle_table(&p);
    let mut s = seed;
    for i in 0..p.len() {
        p.u[i] = Vec2::new(splitmix(&mut s) - 0.5, splitmix(&mut s) - 0.5) * 1e-5;
        p.v[i] = Vec2::new(splitmix(&mut s) - 0.5, splitmix(&mut s)) * 10.0;
        p.f_int[i] = Vec2::new(splitmix(&mut s) - 0.5, splitmix(&mut s) - 0.5) * 1e3;
        if unequal_masses {
            p.mass[i] *= 0.2 + 1.6 * splitmix(&mut s);
        }
    }
    (p, shape, 4 * 7 + 3)
}

/// One step of a punch driven down at 20 m/s onto the lone slave `slave`,
/// its nose 1 µm above `point_y` (the slave's gap point), with spreading
/// `mode`: the contact system after the step and the contact forces.
fn press_once(
    p: &mut Particles,
    shape: &ShapeTable,
    slave: usize,
    mode: Spreading,
    point_y: Real,
) -> (ContactSystem, Vec<Vec2>) {
    let params = ContactParameters { spreading: mode, ..ContactParameters::default() };
    let punch =
        RigidBody::new("punch", rectangle_outline(1.0, 0.2), Vec2::new(0.0, point_y + 1e-6 + 0.1), Vec2::zeros(), 1.0)
            .unwrap()
            .with_prescribed_velocity(Vec2::new(0.0, -20.0));
    let mut sys = ContactSystem::new(vec![punch], SlaveSet::from_indices([slave]), params).unwrap();
    let mut f = Vec::new();
    step(&mut sys, p, Some(shape), 1e-7, &mut f);
    (sys, f)
}

/// With [`Spreading::ShapeFunction`] the gap point is the physical point
/// `x(X_s)`, and the effective mass `(Σ N_J²/m_J)⁻¹` makes an isolated
/// contact exact there too.
#[test]
fn shape_function_contact_of_an_isolated_point_is_exact() {
    let (mut p, shape, slave) = loaded_patch(3, false);
    // A punch driven down, its nose 1 µm above the slave's physical point.
    let y_phys = p.x0[slave].y + shape.interpolate(slave, &p.u).y;
    let (sys, f) = press_once(&mut p, &shape, slave, Spreading::ShapeFunction, y_phys);
    let c = sys.contacts()[0];
    assert!(
        c.gap < 0.0 && c.effective_mass > 1.5 * p.mass[slave],
        "m_eff {} vs m_s {}",
        c.effective_mass,
        p.mass[slave]
    );
    let nose = sys.bodies[0].position.y - 0.1;
    let y_phys = p.x0[slave].y + shape.interpolate(slave, &p.u).y;
    let g_end = nose - y_phys;
    assert!(g_end.abs() <= 1e-10 * c.gap.abs(), "end gap {g_end:e}, predicted {:e}", c.gap);
    // more than one particle received force, and f_J = N_J F
    let row: Vec<usize> = shape.range(slave).collect();
    assert!(row.len() > 4);
    for e in row {
        let j = shape.index[e] as usize;
        assert!((f[j] - c.force * shape.value[e]).norm() <= 1e-15 * c.force.norm());
    }
}

/// [`Spreading::MassWeighted`] on one slave of a row of unequal masses,
/// against the weights computed here: the gap point `X_s + Σ w_J U_J` with
/// `w_J = m_J N_J / Σ m_K N_K` ends the step on the punch's face, the
/// force is spread as `f_J = w_J F`, so that every particle of the row is
/// accelerated by `N_J F / Σ m_K N_K` whatever its mass, and the effective
/// mass is `(Σ m_K N_K)² / Σ m_J N_J²`.
#[test]
fn mass_weighted_contact_of_an_isolated_point_is_exact() {
    let (mut p, shape, slave) = loaded_patch(7, true);
    let row: Vec<(usize, Real)> = shape.range(slave).map(|e| (shape.index[e] as usize, shape.value[e])).collect();
    let sum_mn: Real = row.iter().map(|&(j, n)| p.mass[j] * n).sum();
    let sum_mnn: Real = row.iter().map(|&(j, n)| p.mass[j] * n * n).sum();
    let point = |p: &Particles| p.x0[slave] + row.iter().map(|&(j, n)| p.u[j] * (p.mass[j] * n / sum_mn)).sum::<Vec2>();
    let y_point = point(&p).y;
    let (sys, f) = press_once(&mut p, &shape, slave, Spreading::MassWeighted, y_point);
    let c = sys.contacts()[0];
    let m_eff = sum_mn * sum_mn / sum_mnn;
    assert!(c.gap < 0.0 && (c.effective_mass - m_eff).abs() <= 1e-12 * m_eff, "{} vs {m_eff}", c.effective_mass);
    let g_end = sys.bodies[0].position.y - 0.1 - point(&p).y;
    assert!(g_end.abs() <= 1e-10 * c.gap.abs(), "end gap {g_end:e}, predicted {:e}", c.gap);
    assert!(row.len() > 4);
    let per_n = c.force / sum_mn; // the row's acceleration per unit N
    for &(j, n) in &row {
        assert!((f[j] - c.force * (p.mass[j] * n / sum_mn)).norm() <= 1e-14 * c.force.norm());
        assert!((f[j] / p.mass[j] - per_n * n).norm() <= 1e-12 * per_n.norm(), "particle {j}");
    }
}

/// No penetration over a sequence of steps: a particle under a constant load
/// falls onto a static wall, lands without ever crossing it and then rests
/// on it, for each spreading mode (one particle: identical physics).
#[test]
fn falling_particle_never_penetrates_a_wall() {
    for mode in MODES {
        let mut p = single_particle(Vec2::new(0.0, 2e-4), 1e-4);
        let shape = ShapeTable { offsets: vec![0, 1], index: vec![0], value: vec![1.0], grad: vec![Vec2::zeros()] };
        p.v[0] = Vec2::new(0.0, -3.0);
        p.f_ext[0] = Vec2::new(0.0, -1e-4 * 5e4); // 5e4 m/s² "gravity"
        let params = ContactParameters { spreading: mode, ..ContactParameters::default() };
        let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), params).unwrap();
        let (dt, mut f, mut landed_at) = (1e-6, Vec::new(), None);
        for n in 0..400 {
            let r = step(&mut sys, &mut p, Some(&shape), dt, &mut f);
            let y = p.x0[0].y + p.u[0].y;
            assert!(y >= -1e-15, "{mode:?}: step {n}: y = {y:e}");
            if r.active_contacts > 0 && landed_at.is_none() {
                landed_at = Some(n);
            }
        }
        let n0 = landed_at.expect("it lands");
        assert!(n0 > 10 && n0 < 100, "{mode:?}: landed at step {n0}");
        assert!((p.x0[0].y + p.u[0].y).abs() < 1e-15 && p.v[0].norm() < 1e-9, "{mode:?}: resting");
        // resting: the contact carries exactly the load
        let f_n = sys.contacts()[0].normal_force;
        assert!(
            (f_n - 5.0).abs() < 1e-12,
            "{mode:?}: resting force {f_n}, v = {:?}, y = {:e}",
            p.v[0],
            p.x0[0].y + p.u[0].y
        );
        // the impact dissipated the kinetic energy at landing
        assert!(sys.contact_work() < 0.0);
    }
}

/// Coulomb slip: a point mass sliding on a rigid plane under normal load N
/// decelerates at exactly μN/m, then sticks and stays at rest.
#[test]
fn coulomb_slip_decelerates_at_mu_n_over_m() {
    let (m, load, mu, v0, dt) = (1e-3, 1.0, 0.3, 10.0, 1e-4);
    let mut p = single_particle(Vec2::zeros(), m);
    p.v[0] = Vec2::new(v0, 0.0);
    p.f_ext[0] = Vec2::new(0.0, -load);
    let params =
        ContactParameters { friction_coefficient: mu, spreading: Spreading::None, ..ContactParameters::default() };
    let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), params).unwrap();
    let decel = mu * load / m;
    let mut f = Vec::new();
    let mut stopped = None;
    for n in 1..=600 {
        step(&mut sys, &mut p, None, dt, &mut f);
        let c = sys.contacts()[0];
        assert!((c.normal_force - load).abs() < 1e-9, "normal force = load");
        assert!(p.u[0].y.abs() < 1e-15, "stays on the plane");
        let expected = v0 - n as Real * dt * decel;
        if expected > 0.0 {
            assert!(c.slipping);
            assert!((p.v[0].x - expected).abs() < 1e-9, "step {n}: v = {}, expected {expected}", p.v[0].x);
        } else {
            stopped.get_or_insert(n);
            assert!(p.v[0].x.abs() < 1e-15, "step {n}: sticks");
        }
    }
    let n_stop = stopped.unwrap();
    assert_eq!(n_stop, (v0 / (dt * decel)).ceil() as usize);
    // friction dissipated the kinetic energy ½ m v0² (plus nothing normal)
    assert!((sys.contact_work() + 0.5 * m * v0 * v0).abs() < 1e-9 * 0.5 * m * v0 * v0);
}

/// Stick below the cap, slip above it, nothing at μ = 0.
#[test]
fn friction_sticks_below_the_cap_and_is_off_at_mu_zero() {
    let (m, load, dt) = (1e-3, 1.0, 1e-4);
    for (mu, pull, accel) in [(0.3, 0.2, 0.0), (0.3, 0.4, (0.4 - 0.3) / 1e-3), (0.0, 0.2, 0.2 / 1e-3)] {
        let mut p = single_particle(Vec2::zeros(), m);
        p.f_ext[0] = Vec2::new(pull, -load);
        let params =
            ContactParameters { friction_coefficient: mu, spreading: Spreading::None, ..ContactParameters::default() };
        let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), params).unwrap();
        let mut f = Vec::new();
        for n in 1..=50 {
            step(&mut sys, &mut p, None, dt, &mut f);
            let c = sys.contacts()[0];
            assert!((p.v[0].x - n as Real * dt * accel).abs() < 1e-9, "μ {mu}, pull {pull}: step {n}");
            if mu == 0.0 {
                assert_eq!(c.tangential_force, 0.0);
            } else if accel == 0.0 {
                assert!(!c.slipping && (c.tangential_force.abs() - pull).abs() < 1e-12);
            }
        }
    }
}

/// Every mode applies exactly the slave force: `Σ_J f_J = F` per contact and
/// the reaction on the body is minus the total, to round-off.
#[test]
fn spreading_conserves_the_total_force() {
    let h = 1e-3;
    for mode in MODES {
        let mut p = lattice(&uniform(9, h, -4.0 * h), &uniform(5, h, -4.0 * h));
        let shape = particle_table(&p);
        let mut s = 11u64;
        for i in 0..p.len() {
            p.v[i] = Vec2::new(splitmix(&mut s) - 0.5, splitmix(&mut s) - 0.5) * 20.0;
        }
        // a diamond pressed into the top surface: inclined normals
        let diamond =
            vec![Vec2::new(0.0, -2.0 * h), Vec2::new(2.0 * h, 0.0), Vec2::new(0.0, 2.0 * h), Vec2::new(-2.0 * h, 0.0)];
        let body = RigidBody::new("diamond", diamond, Vec2::new(0.1 * h, 0.5 * h), Vec2::new(0.0, -50.0), 1.0).unwrap();
        let slaves = SlaveSet::detect(&p.x0, &p.spacing, &SurfaceDetection::default()).unwrap();
        let params = ContactParameters { spreading: mode, friction_coefficient: 0.3, ..ContactParameters::default() };
        let mut sys = ContactSystem::new(vec![body], slaves, params).unwrap();
        let mut f = vec![Vec2::zeros(); p.len()];
        let report = sys.compute_forces(&StepInput::from_particles(&p, Some(&shape), 1e-6), &mut f).unwrap();
        assert!(report.active_contacts >= 2, "{mode:?}: {} contacts", report.active_contacts);
        for c in sys.contacts() {
            let t = Vec2::new(-c.normal.y, c.normal.x);
            let intended = c.normal * c.normal_force + t * c.tangential_force;
            assert!((c.force - intended).norm() <= 1e-15 * intended.norm(), "{mode:?}: {:?} vs {intended:?}", c.force);
        }
        let total: Vec2 = f.iter().sum();
        let reaction = sys.sample(0).unwrap().contact_force;
        assert!((total + reaction).norm() <= 1e-15 * total.norm(), "{mode:?}");
        assert!((total - report.force_on_particles).norm() <= 1e-15 * total.norm());
        let receivers = f.iter().filter(|v| v.norm() > 0.0).count();
        match mode {
            Spreading::None => assert_eq!(receivers, report.active_contacts),
            _ => assert!(receivers > report.active_contacts, "{mode:?} spreads"),
        }
    }
}

/// Particles of unequal masses and a free rigid body: total momentum
/// `Σ m v + M V` is conserved through contact to round-off, and the contact
/// work equals the change of total kinetic energy (the leapfrog identity),
/// for each mode, with friction.
#[test]
fn momentum_and_energy_with_a_free_body() {
    let h = 1e-3;
    for mode in MODES {
        let mut p = lattice(&uniform(6, h, -2.5 * h), &uniform(4, h, -3.0 * h));
        let shape = particle_table(&p);
        let mut s = 5u64;
        for i in 0..p.len() {
            p.v[i] = Vec2::new(splitmix(&mut s) - 0.5, 30.0 + splitmix(&mut s));
            p.mass[i] *= 0.2 + 1.6 * splitmix(&mut s); // unequal masses: mass-weighted rows differ
        }
        let m_particles = p.total_mass();
        let body = RigidBody::new(
            "block",
            rectangle_outline(4.0 * h, 3.0 * h),
            Vec2::new(0.3 * h, 1.6 * h),
            Vec2::new(2.0, -10.0),
            3.0 * m_particles,
        )
        .unwrap();
        let slaves = SlaveSet::detect(&p.x0, &p.spacing, &SurfaceDetection::default()).unwrap();
        let params = ContactParameters { spreading: mode, friction_coefficient: 0.2, ..ContactParameters::default() };
        let mut sys = ContactSystem::new(vec![body], slaves, params).unwrap();
        let momentum = |p: &Particles, sys: &ContactSystem| p.momentum() + sys.body_momentum();
        let energy = |p: &Particles, sys: &ContactSystem| {
            kinetic(p) + 0.5 * sys.bodies[0].mass * sys.bodies[0].velocity.norm_squared()
        };
        let (p0, e0) = (momentum(&p, &sys), energy(&p, &sys));
        let mut f = Vec::new();
        let mut active_steps = 0;
        for _ in 0..300 {
            if step(&mut sys, &mut p, Some(&shape), 1e-6, &mut f).active_contacts > 0 {
                active_steps += 1;
            }
            let dp = (momentum(&p, &sys) - p0).norm();
            assert!(dp <= 1e-12 * p0.norm(), "{mode:?}: momentum drift {dp:e}");
        }
        assert!(active_steps > 5, "{mode:?}: contact happened ({active_steps} steps)");
        let de = energy(&p, &sys) - e0;
        assert!((de - sys.contact_work()).abs() <= 1e-10 * e0, "{mode:?}: ΔKE {de:e} vs W {:e}", sys.contact_work());
        assert!(sys.contact_work() < 0.0, "{mode:?}: contact dissipates");
    }
}

/// The axis of an axisymmetric model is a frictionless wall
/// ([`ContactSystem::with_axis`]): a free ring thrown at the axis at
/// 1 km/s ends its step on it, exactly, and stays there; its axial motion
/// is untouched, and the axis's work is the radial kinetic energy it took.
/// Without the wall it crosses to `r < 0`. With shape-function spreading,
/// a lattice beside the axis (its first column on it, held radially)
/// driven inward keeps every physical point at `r ≥ 0`, and the axial
/// momentum is kept.
#[test]
fn no_particle_crosses_the_axis() {
    let dt = 1e-7;
    let none = ContactParameters { spreading: Spreading::None, ..ContactParameters::default() };
    // (a) one free particle, 10 µm off the axis, 1 km/s inward.
    let (m, r0, v_r, v_z) = (2e-4, 1e-5, -1000.0, -40.0);
    let mut p = single_particle(Vec2::new(r0, 0.0), m);
    p.v[0] = Vec2::new(v_r, v_z);
    let mut sys = ContactSystem::new(vec![], SlaveSet::from_indices([]), none).unwrap().with_axis(true);
    let mut f = Vec::new();
    step(&mut sys, &mut p, None, dt, &mut f);
    assert_eq!(sys.axis_contacts(), 1);
    let r_end = p.x0[0].x + p.u[0].x;
    assert!(r_end.abs() <= 1e-12 * r0, "end radius {r_end:e}");
    assert!((p.v[0].x + r0 / dt).abs() <= 1e-9 * r0 / dt, "arrives at the axis: {}", p.v[0].x);
    assert_eq!(p.v[0].y, v_z);
    for _ in 0..20 {
        step(&mut sys, &mut p, None, dt, &mut f);
        assert!(p.x0[0].x + p.u[0].x >= -1e-12 * r0 && p.v[0].x.abs() <= 1e-9, "held on the axis");
    }
    assert_eq!(p.v[0].y, v_z);
    let taken = 0.5 * m * v_r * v_r;
    assert!(
        (sys.axis_work() + taken).abs() <= 1e-12 * taken,
        "axis work {:e}, radial energy {taken:e}",
        sys.axis_work()
    );
    assert_eq!(sys.contact_work(), sys.axis_work());
    // Without the wall it crosses.
    let mut p = single_particle(Vec2::new(r0, 0.0), m);
    p.v[0] = Vec2::new(v_r, v_z);
    let mut sys = ContactSystem::new(vec![], SlaveSet::from_indices([]), none).unwrap();
    step(&mut sys, &mut p, None, dt, &mut f);
    assert!(p.x0[0].x + p.u[0].x < -8.0 * r0 && sys.axis_contacts() == 0);

    // (b) a lattice beside the axis, its physical points read through the
    // shape functions.
    let h = 1e-3;
    let mut p = lattice(&uniform(5, h, 0.0), &uniform(4, h, 0.0));
    for i in (0..p.len()).filter(|&i| p.x0[i].x == 0.0) {
        p.flags[i].set(ParticleFlags::ON_AXIS | ParticleFlags::FIX_X);
    }
    let shape = particle_table(&p);
    let mut s = 11u64;
    for i in 0..p.len() {
        p.v[i] = Vec2::new(-3e3 * (1.0 + splitmix(&mut s)), 20.0 * (splitmix(&mut s) - 0.5));
        p.flags[i].constrain(&mut p.v[i]);
    }
    let params = ContactParameters { spreading: Spreading::ShapeFunction, ..ContactParameters::default() };
    let mut sys = ContactSystem::new(vec![], SlaveSet::from_indices([]), params).unwrap().with_axis(true);
    let axial = |p: &Particles| p.momentum().y;
    let z0 = axial(&p);
    let mut held = 0;
    for _ in 0..10 {
        step(&mut sys, &mut p, Some(&shape), 1e-7, &mut f);
        held = held.max(sys.axis_contacts());
        for i in 0..p.len() {
            if p.flags[i].has(ParticleFlags::ON_AXIS) {
                assert_eq!(p.u[i].x, 0.0, "the axis's own particles stay on it");
                continue;
            }
            let r = p.x0[i].x + shape.interpolate(i, &p.u).x;
            // The solve stops at a force change of 1e-8: a remaining
            // penetration of that order of a step's travel (6e3 m/s × Δt).
            assert!(r >= -1e-7 * 6e3 * 1e-7, "particle {i} at r = {r:e}");
        }
        assert!((axial(&p) - z0).abs() <= 1e-12 * p.total_mass() * 20.0, "axial momentum");
    }
    assert!(held >= 4, "the column beside the axis met it ({held} pairs)");
    assert!(sys.axis_work() < 0.0);
}

// ---------------------------------------------------------------- bodies

/// SPEC §10: the 20 × 80 mm projectile at 7850 kg/m³ is 12.56 kg per metre
/// of depth in plane strain, and revolved about its axis the 197 g cylinder
/// (π r² L ρ), from the whole section or its half.
#[test]
fn rigid_body_masses() {
    let section = rectangle_outline(0.020, 0.080);
    let m = mass_plane_strain(&section, STEEL_DENSITY).unwrap();
    assert!((m - 12.56).abs() < 1e-12);
    let cylinder = std::f64::consts::PI * 0.010f64.powi(2) * 0.080 * STEEL_DENSITY;
    assert!((cylinder - 0.1973).abs() < 1e-4);
    let whole = mass_axisymmetric(&section, STEEL_DENSITY).unwrap();
    let half: Vec<Vec2> =
        vec![Vec2::new(0.0, -0.04), Vec2::new(0.01, -0.04), Vec2::new(0.01, 0.04), Vec2::new(0.0, 0.04)];
    let right = mass_axisymmetric(&half, STEEL_DENSITY).unwrap();
    assert!((whole - cylinder).abs() < 1e-14 && (right - cylinder).abs() < 1e-14, "{whole} {right} {cylinder}");
    // a ring section r ∈ [1, 2] mm, 1 mm tall: π (2² − 1²) mm³ · 1 mm
    let ring = vec![Vec2::new(1e-3, 0.0), Vec2::new(2e-3, 0.0), Vec2::new(2e-3, 1e-3), Vec2::new(1e-3, 1e-3)];
    let v = mass_axisymmetric(&ring, 1.0).unwrap();
    assert!((v - std::f64::consts::PI * 3e-9).abs() < 1e-22);
    assert!(mass_plane_strain(&section, -1.0).is_err());
    let left: Vec<Vec2> = half.iter().map(|v| Vec2::new(v.x - 0.02, v.y)).collect();
    assert!(mass_axisymmetric(&left, STEEL_DENSITY).is_err());
}

// ---------------------------------------------------------------- surface

fn boundary_of_lattice(nx: usize, ny: usize) -> Vec<usize> {
    (0..nx * ny).filter(|k| k % nx == 0 || k % nx == nx - 1 || k / nx == 0 || k / nx == ny - 1).collect()
}

#[test]
fn surface_of_uniform_rectangle() {
    for (nx, ny, h) in [(12, 7, 0.5e-3), (3, 3, 1.0), (40, 11, 0.2e-3)] {
        let p = lattice(&uniform(nx, h, 0.0), &uniform(ny, h, -1.0));
        let found = detect_surface(&p.x0, &p.spacing, &SurfaceDetection::default()).unwrap();
        assert_eq!(found, boundary_of_lattice(nx, ny), "{nx} × {ny}");
    }
}

/// Graded in both directions (ratios 1.15 and 1.2 per gap, ×7 and ×5 over
/// the block), and a plate graded symmetrically toward its centre like
/// [RL10, §5]'s model: exactly the boundary rows and columns.
#[test]
fn surface_of_graded_rectangle() {
    let graded = |n: usize, h0: Real, r: Real| {
        let mut c = vec![0.0];
        for k in 0..n - 1 {
            c.push(c[k] + h0 * r.powi(k as i32));
        }
        c
    };
    let xs = graded(16, 1e-4, 1.15);
    let ys = graded(10, 1e-4, 1.2);
    let p = lattice(&xs, &ys);
    let found = detect_surface(&p.x0, &p.spacing, &SurfaceDetection::default()).unwrap();
    assert_eq!(found, boundary_of_lattice(16, 10));
    // plate: fine under the projectile, coarser outward, uniform through the thickness
    let half = graded(14, 2e-4, 1.18);
    let mut xs: Vec<Real> = half.iter().rev().map(|x| -x).collect();
    xs.extend_from_slice(&half[1..]);
    let ys = uniform(12, 2e-4, -11.0 * 2e-4);
    let p = lattice(&xs, &ys);
    let found = detect_surface(&p.x0, &p.spacing, &SurfaceDetection::default()).unwrap();
    assert_eq!(found, boundary_of_lattice(xs.len(), 12));
}

/// A disc of concentric rings: exactly the outer ring.
#[test]
fn surface_of_disc() {
    let h = 1e-3;
    for rings in [3usize, 8, 15] {
        let mut x = vec![Vec2::zeros()];
        let mut ring_of = vec![0];
        for k in 1..=rings {
            let n = (2.0 * std::f64::consts::PI * k as Real).round() as usize;
            let phase = if k % 2 == 1 { 0.5 } else { 0.0 };
            for m in 0..n {
                let th = 2.0 * std::f64::consts::PI * (m as Real + phase) / n as Real;
                x.push(Vec2::new(th.cos(), th.sin()) * (k as Real * h));
                ring_of.push(k);
            }
        }
        let spacing = vec![h; x.len()];
        let found = detect_surface(&x, &spacing, &SurfaceDetection::default()).unwrap();
        let outer: Vec<usize> = (0..x.len()).filter(|&i| ring_of[i] == rings).collect();
        assert_eq!(found, outer, "{rings} rings");
    }
}

// ---------------------------------------------------------------- errors

#[test]
fn bad_inputs_are_errors_not_panics() {
    let mut p = single_particle(Vec2::zeros(), 1e-3);
    let mut sys =
        ContactSystem::new(vec![wall(1e-3)], SlaveSet::from_indices([0]), ContactParameters::default()).unwrap();
    let mut f = vec![Vec2::zeros(); 1];
    let r = sys.compute_forces(&StepInput::from_particles(&p, None, 1e-6), &mut f);
    assert!(matches!(r, Err(ContactError::MissingShapeTable { .. })));
    assert!(matches!(sys.advance(&p.v), Err(ContactError::AdvanceWithoutForces)));
    let bad_table = ShapeTable { offsets: vec![0, 1], index: vec![0], value: vec![0.7], grad: vec![Vec2::zeros()] };
    let r = sys.compute_forces(&StepInput::from_particles(&p, Some(&bad_table), 1e-6), &mut f);
    assert!(matches!(r, Err(ContactError::PartitionOfUnity { particle: 0, .. })), "{r:?}");
    let r = sys.compute_forces(&StepInput::from_particles(&p, None, 1e-6), &mut [Vec2::zeros(); 2]);
    assert!(matches!(r, Err(ContactError::MissingShapeTable { .. }) | Err(ContactError::LengthMismatch { .. })));
    let none = ContactParameters { spreading: Spreading::None, ..ContactParameters::default() };
    let mut sys = ContactSystem::new(vec![wall(1e-3)], SlaveSet::from_indices([0]), none).unwrap();
    assert!(matches!(
        sys.compute_forces(&StepInput::from_particles(&p, None, 0.0), &mut f),
        Err(ContactError::InvalidParameter { name: "dt", .. })
    ));
    p.mass[0] = 0.0;
    assert!(matches!(
        sys.compute_forces(&StepInput::from_particles(&p, None, 1e-6), &mut f),
        Err(ContactError::InvalidParticle { particle: 0, .. })
    ));
    p.mass[0] = 1e-3;
    p.u[0].x = Real::NAN;
    assert!(matches!(
        sys.compute_forces(&StepInput::from_particles(&p, None, 1e-6), &mut f),
        Err(ContactError::NonFinite { particle: 0, .. })
    ));
    let mut sys = ContactSystem::new(vec![], SlaveSet::from_indices([3]), none).unwrap();
    assert!(matches!(
        sys.compute_forces(&StepInput::from_particles(&p, None, 1e-6), &mut f),
        Err(ContactError::SlaveOutOfRange { .. })
    ));
    let broken = ShapeTable { offsets: vec![0, 3], index: vec![0], value: vec![1.0], grad: vec![Vec2::zeros()] };
    let mut sys =
        ContactSystem::new(vec![wall(1e-3)], SlaveSet::from_indices([0]), ContactParameters::default()).unwrap();
    p.u[0].x = 0.0;
    assert!(matches!(
        sys.compute_forces(&StepInput::from_particles(&p, Some(&broken), 1e-6), &mut f),
        Err(ContactError::InvalidShapeTable)
    ));
    let good = ShapeTable { offsets: vec![0, 1], index: vec![0], value: vec![1.0], grad: vec![Vec2::zeros()] };
    sys.compute_forces(&StepInput::from_particles(&p, Some(&good), 1e-6), &mut f).unwrap();
    assert!(matches!(sys.advance(&[]), Err(ContactError::LengthMismatch { field: "v", .. })));
    sys.advance(&p.v).unwrap();
    let bad = ContactParameters { friction_coefficient: -0.1, ..ContactParameters::default() };
    assert!(ContactSystem::new(vec![], SlaveSet::new(), bad).is_err());
}

/// The slaves' gap points are predicted in parallel; a bad input still
/// names the first slave in order that has one, for any number of threads.
#[test]
fn prediction_errors_name_the_first_bad_slave_for_any_thread_count() {
    let mut p = lattice(&uniform(64, 1e-3, 0.0), &[0.0, 1e-3]);
    let none = ContactParameters { spreading: Spreading::None, ..ContactParameters::default() };
    // The error of one step on 1, 2 and 3 threads.
    let errors = |p: &Particles| {
        [1, 2, 3].map(|threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut sys = ContactSystem::new(vec![wall(-1e-3)], SlaveSet::from_indices(0..64), none).unwrap();
            let mut f = vec![Vec2::zeros(); p.len()];
            pool.install(|| sys.compute_forces(&StepInput::from_particles(p, None, 1e-7), &mut f)).unwrap_err()
        })
    };
    p.mass[41] = 0.0;
    p.v[17].y = Real::INFINITY;
    p.mass[53] = -1.0;
    for e in errors(&p) {
        assert!(matches!(e, ContactError::NonFinite { particle: 17, .. }), "{e:?}");
    }
    p.v[17].y = 0.0;
    for e in errors(&p) {
        assert!(matches!(e, ContactError::InvalidParticle { particle: 41, .. }), "{e:?}");
    }
}

// ---------------------------------------------------------------- comparison

/// A linear-elastic RK block (plane strain, small strain, 2 × 2 Gauss points
/// per background cell between particles: SPEC §4 with a linear material).
struct ElasticBlock {
    p: Particles,
    shape: ShapeTable,
    qp: ShapeTable,
    qp_weight: Vec<Real>,
    lame: (Real, Real),
}

impl ElasticBlock {
    const YOUNG: Real = 200e9;
    const POISSON: Real = 0.3;

    fn new(xs: &[Real], ys: &[Real]) -> Self {
        let p = lattice(xs, ys);
        let shape = particle_table(&p);
        let g = 0.5 / 3f64.sqrt();
        let (mut pts, mut w) = (Vec::new(), Vec::new());
        for j in 0..ys.len() - 1 {
            for i in 0..xs.len() - 1 {
                let (dx, dy) = (xs[i + 1] - xs[i], ys[j + 1] - ys[j]);
                let c = Vec2::new(xs[i] + 0.5 * dx, ys[j] + 0.5 * dy);
                for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                    pts.push(c + Vec2::new(sx * g * dx, sy * g * dy));
                    w.push(0.25 * dx * dy);
                }
            }
        }
        let qp = rk_table(&p.x0, &p.volume, &p.support, &pts);
        let (e, nu) = (Self::YOUNG, Self::POISSON);
        let lame = (e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), e / (2.0 * (1.0 + nu)));
        Self { p, shape, qp, qp_weight: w, lame }
    }

    /// Longitudinal wave speed `c_L = sqrt((λ + 2μ)/ρ)`.
    fn wave_speed(&self) -> Real {
        ((self.lame.0 + 2.0 * self.lame.1) / STEEL_DENSITY).sqrt()
    }

    /// `f_int,I = Σ_q σ_q ∇N_I(X_q) w_q` with `σ = λ tr ε I + 2μ ε`.
    #[allow(non_snake_case)]
    fn internal_force(&mut self) {
        let (lam, mu) = self.lame;
        let (t, p) = (&self.qp, &mut self.p);
        p.f_int.fill(Vec2::zeros());
        for q in 0..t.rows() {
            // H = Σ U_J ⊗ ∇N_J (displacement gradient)
            let (mut hxx, mut hxy, mut hyx, mut hyy) = (0.0, 0.0, 0.0, 0.0);
            for e in t.range(q) {
                let (U, g) = (p.u[t.index[e] as usize], t.grad[e]);
                hxx += U.x * g.x;
                hxy += U.x * g.y;
                hyx += U.y * g.x;
                hyy += U.y * g.y;
            }
            let (exy, tr) = (0.5 * (hxy + hyx), hxx + hyy);
            let (sxx, syy, sxy) = (lam * tr + 2.0 * mu * hxx, lam * tr + 2.0 * mu * hyy, 2.0 * mu * exy);
            let w = self.qp_weight[q];
            for e in t.range(q) {
                let g = t.grad[e];
                p.f_int[t.index[e] as usize] += Vec2::new(sxx * g.x + sxy * g.y, sxy * g.x + syy * g.y) * w;
            }
        }
    }
}

/// What one impact run measured.
#[derive(Debug)]
struct ImpactMetrics {
    /// Mean contact force over the last two thirds of the run / `ρ c_L v W`.
    force_ratio: Real,
    /// Step-to-step variation of the force, `mean |F_{n+1} − F_n| / mean F`.
    chatter: Real,
    /// Largest penetration of the physical surface `x(X)` (particles and
    /// midpoints under the punch) into the punch, after any step, / h.
    physical_penetration: Real,
    /// The same for the generalized positions `X_s + U_s` of the slaves, / h.
    generalized_penetration: Real,
    /// Energy the contact dissipated / work it did on the target.
    dissipation: Real,
    /// Most Gauss–Seidel sweeps in a step.
    iterations: u32,
    /// Largest departure of the top particle of the column under the
    /// punch's centre from the punch's speed, `max |v_y + v0| / v0`.
    light_swing: Real,
}

/// A punch run of [`punch_impact`].
struct Punch {
    /// Uniaxial strain (every particle held in x) instead of a free block.
    uniaxial: bool,
    /// Punch width, m.
    width: Real,
    /// Punch speed, m/s (down).
    speed: Real,
    steps: usize,
    /// Mass factor of the particle column under the punch's centre (1: the
    /// block's own density): a light column, as the axis ring of an
    /// axisymmetric model or a crack's split children.
    light: Real,
}

/// Rigid punch of width `run.width` driven down at `run.speed` onto the top
/// face (y = 0) of an elastic block, nose initially touching.
#[allow(clippy::needless_range_loop)] // samples and table rows indexed in parallel
fn punch_impact(mode: Spreading, xs: &[Real], ys: &[Real], run: &Punch) -> ImpactMetrics {
    let Punch { uniaxial, width: punch_width, speed: v0, steps, light } = *run;
    let h = ys[1] - ys[0];
    let mut b = ElasticBlock::new(xs, ys);
    let (nx, ny) = (xs.len(), ys.len());
    for i in 0..b.p.len() {
        if uniaxial {
            b.p.flags[i].set(ParticleFlags::FIX_X); // u_x = 0: uniaxial strain
        }
        if i / nx == 0 {
            b.p.flags[i].set(ParticleFlags::FIX_X | ParticleFlags::FIX_Y); // bottom row
        }
    }
    let x_mid = 0.5 * (xs[0] + xs[nx - 1]);
    let half = 0.5 * punch_width;
    let column = (0..nx).min_by(|&a, &b| (xs[a] - x_mid).abs().total_cmp(&(xs[b] - x_mid).abs())).unwrap();
    for j in 0..ny {
        b.p.mass[j * nx + column] *= light;
    }
    let light_top = (ny - 1) * nx + column;
    let mut light_swing: Real = 0.0;
    // sample points of the physical surface under the punch
    let top: Vec<usize> = ((ny - 1) * nx..ny * nx).filter(|&i| (b.p.x0[i].x - x_mid).abs() <= half + 1e-12).collect();
    let mut samples: Vec<Vec2> = top.iter().map(|&i| b.p.x0[i]).collect();
    samples.extend(top.windows(2).map(|w| 0.5 * (b.p.x0[w[0]] + b.p.x0[w[1]])));
    let surf = rk_table(&b.p.x0, &b.p.volume, &b.p.support, &samples);
    let height = 0.5 * punch_width.max(4.0 * h);
    let punch = RigidBody::new(
        "punch",
        rectangle_outline(punch_width, height),
        Vec2::new(x_mid, 0.5 * height),
        Vec2::zeros(),
        1.0,
    )
    .unwrap()
    .with_prescribed_velocity(Vec2::new(0.0, -v0));
    let slaves = SlaveSet::detect(&b.p.x0, &b.p.spacing, &SurfaceDetection::default()).unwrap();
    let params = ContactParameters { spreading: mode, ..ContactParameters::default() };
    let mut sys = ContactSystem::new(vec![punch], slaves, params).unwrap();
    let dt = 0.3 * h / b.wave_speed();
    let (mut f, mut forces) = (Vec::new(), Vec::new());
    let (mut pen_phys, mut pen_gen): (Real, Real) = (0.0, 0.0);
    let mut iterations = 0;
    for _ in 0..steps {
        b.internal_force();
        iterations = iterations.max(step(&mut sys, &mut b.p, Some(&b.shape), dt, &mut f).iterations);
        forces.push(sys.sample(0).unwrap().contact_force.y);
        let (nose, centre) = (sys.bodies[0].position.y - 0.5 * height, sys.bodies[0].position.x);
        // strictly under the nose: a point on the side face's line is not inside
        let under = |x: &Vec2| (x.x - centre).abs() < half - 1e-6 * h;
        for k in 0..samples.len() {
            let x = samples[k] + surf.interpolate(k, &b.p.u);
            if under(&x) {
                pen_phys = pen_phys.max(x.y - nose);
            }
        }
        for &i in &top {
            let x = b.p.x0[i] + b.p.u[i];
            if under(&x) {
                pen_gen = pen_gen.max(x.y - nose);
            }
        }
        light_swing = light_swing.max((b.p.v[light_top].y + v0).abs() / v0);
        assert!(b.p.u.iter().all(|u| u.iter().all(|c| c.is_finite())), "{mode:?}: finite");
    }
    let tail = &forces[steps / 3..];
    let mean = tail.iter().sum::<Real>() / tail.len() as Real;
    let chatter = tail.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<Real>() / (tail.len() - 1) as Real / mean;
    let width = if uniaxial { xs[nx - 1] - xs[0] } else { punch_width };
    let s = sys.sample(0).unwrap();
    ImpactMetrics {
        force_ratio: mean / (STEEL_DENSITY * b.wave_speed() * v0 * width),
        chatter,
        physical_penetration: pen_phys.max(0.0) / h,
        generalized_penetration: pen_gen.max(0.0) / h,
        dissipation: -(s.work_on_particles + s.work_on_body) / s.work_on_particles,
        iterations,
        light_swing,
    }
}

/// SPEC §8 asks to compare [RL10, §3]'s inverse-distance spreading with the
/// variationally consistent one and make the better the default.
///
/// (A) Uniaxial strain: a punch wider than the block drives its top at
/// v = 50 m/s; the contact pressure must be `ρ c_L v` (plane wave) until the
/// wave returns from the clamped bottom. (B) A punch 10 h wide (its corners
/// abreast of particle columns) into a 40 h × 20 h block, laterally free.
/// h = 1 mm, Δt = 0.3 h/c_L, 120 and 50 steps.
///
/// Measured (printed with `-- --nocapture`; force ratio / chatter /
/// physical penetration [h] / contact dissipation / most sweeps):
///
/// | mode            | A                                   | B                                 |
/// |-----------------|-------------------------------------|-----------------------------------|
/// | None            | 1.006 / 0.029 / 1e-16 / 0.7 % / 2   | 1.15 / 0.019 / 0.070 / 1.4 % / 2  |
/// | InverseDistance | 0.982 / 0.098 / 5e-8  / 2.4 % / 50  | 1.45 / 0.060 / 0.035 / 11 % / 46  |
/// | ShapeFunction   | 1.006 / 0.029 / 3e-12 / 0.7 % / 25  | 1.25 / 0.019 / 0.024 / 1.5 % / 32 |
///
/// The shape-function mode leaves the least penetration of the physical
/// surface where it is not trivially interpolating (B), with the smooth force
/// and low dissipation of the point contact; inverse-distance spreading
/// pushes interior particles, which shows as 3–8× the dissipation and force
/// chatter. The assertions below guard that ranking.
#[test]
fn compare_spreading_on_elastic_impact() {
    let h = 1e-3;
    let run = |mode| {
        let a = Punch { uniaxial: true, width: 20.0 * h, speed: 50.0, steps: 120, light: 1.0 };
        let a = punch_impact(mode, &uniform(8, h, 0.0), &uniform(61, h, -60.0 * h), &a);
        let b = Punch { uniaxial: false, width: 10.0 * h, speed: 50.0, steps: 50, light: 1.0 };
        let b = punch_impact(mode, &uniform(41, h, -20.0 * h), &uniform(21, h, -20.0 * h), &b);
        println!("{mode:?}\n  (A) uniaxial: {a:?}\n  (B) punch:    {b:?}");
        (a, b)
    };
    let (none, id, sf) = (run(Spreading::None), run(Spreading::InverseDistance), run(Spreading::ShapeFunction));
    for (a, _) in [&none, &id, &sf] {
        // every mode transmits the plane-wave pressure on average
        assert!((a.force_ratio - 1.0).abs() < 0.05, "force ratio {}", a.force_ratio);
    }
    // uniaxial: the face stays on the punch, without chatter, where the
    // contact is point-wise exact
    assert!(
        none.0.generalized_penetration < 1e-9 && none.1.generalized_penetration < 1e-9,
        "None is exact at X_s + U_s"
    );
    for (a, _) in [&none, &sf] {
        assert!(a.physical_penetration < 1e-6 && a.chatter < 0.05 && a.dissipation < 0.02, "{a:?}");
    }
    // punch with corners: the ranking that makes ShapeFunction the default
    let (sf_b, none_b, id_b) = (&sf.1, &none.1, &id.1);
    assert!(sf_b.physical_penetration < 0.6 * none_b.physical_penetration, "{sf_b:?} vs {none_b:?}");
    assert!(sf_b.physical_penetration < 0.8 * id_b.physical_penetration, "{sf_b:?} vs {id_b:?}");
    assert!(sf_b.chatter < 0.5 * id_b.chatter && sf_b.dissipation < 0.3 * id_b.dissipation, "{sf_b:?} vs {id_b:?}");
    assert!(sf.0.iterations < 50 && sf_b.iterations < 50, "Gauss-Seidel converged within the default cap");
}

/// [`Spreading::MassWeighted`] (issue #19 item 5) and a light column:
/// particles a fifth as heavy as the block's (as the axis ring of an
/// axisymmetric model, or a crack's split children) under the centre of
/// punch (B) above. The two spreadings hold different points: the
/// shape-function gap point's mobility `Σ N_J²/m_J` is dominated by the
/// light particle, so the contact holds that particle; the mass-weighted
/// point is the row's local centre of mass, dominated by the heavy ones,
/// so the light particle is kicked no more than its neighbours by the
/// contact but is then left to its material, which (five times lighter,
/// as stiff) swings it about the punch's speed. Measured (`--
/// --nocapture`): the light top particle's largest departure from the
/// punch's speed is 0.60 v with the shape-function spreading and 1.16 v
/// mass-weighted (0.003 v for both in the uniform block). Both dissipate
/// (a consistent pair of gap and force never puts energy in), and with
/// equal masses the two spreadings are the same to round-off. So the
/// option does not remove the ringing of a light particle that its
/// material holds (the axis ring under the rounded nose's first contact,
/// docs/validation.md "A mass-weighted contact spreading"); it removes the
/// contact's push on a light particle that its material no longer holds.
#[test]
fn mass_weighted_spreading_holds_the_rows_centre_of_mass_not_a_light_particle() {
    let h = 1e-3;
    let run = |mode, light| {
        let punch = Punch { uniaxial: false, width: 10.0 * h, speed: 50.0, steps: 50, light };
        let m = punch_impact(mode, &uniform(41, h, -20.0 * h), &uniform(21, h, -20.0 * h), &punch);
        println!("{mode:?}, light column x{light}: {m:?}");
        m
    };
    let (sf, mw) = (run(Spreading::ShapeFunction, 0.2), run(Spreading::MassWeighted, 0.2));
    let (sf1, mw1) = (run(Spreading::ShapeFunction, 1.0), run(Spreading::MassWeighted, 1.0));
    // equal masses: the same spreading
    for (a, b) in [(sf1.force_ratio, mw1.force_ratio), (sf1.light_swing, mw1.light_swing)] {
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{sf1:?} vs {mw1:?}");
    }
    // the light column swings under either, more when the contact holds
    // the row's centre of mass instead of it
    assert!(sf1.light_swing < 0.01, "{sf1:?}");
    assert!(sf.light_swing > 0.3 && mw.light_swing > 1.5 * sf.light_swing, "{sf:?} vs {mw:?}");
    for m in [&sf, &mw] {
        assert!(m.dissipation > 0.0 && m.dissipation < 0.05, "the contact dissipates: {m:?}");
        assert!((m.force_ratio - sf1.force_ratio).abs() < 0.05 * sf1.force_ratio, "{m:?}");
        assert!(m.physical_penetration < 0.05, "{m:?}");
    }
}

// ---------------------------------------------------------------- exposure

/// [`RigidBody::within_reach`]: inside, near a face, and near a corner
/// (Euclidean distance, not the bounding box) against hand-computed
/// distances, for a rectangle and a triangle.
#[test]
fn within_reach_of_a_rigid_outline() {
    let at = Vec2::new(0.3, -0.2);
    let rect = RigidBody::new("r", rectangle_outline(0.02, 0.08), at, Vec2::zeros(), 1.0).unwrap();
    let y = |x: Real, y: Real| Vec2::new(x, y); // body frame: centre at 0
    assert!(rect.within_reach(&y(0.0, 0.0), 0.0), "centre");
    assert!(rect.within_reach(&y(0.0099, -0.0399), 0.0), "just inside a corner");
    assert!(!rect.within_reach(&y(0.0, -0.0401), 0.0), "just below the face");
    assert!(rect.within_reach(&y(0.0, -0.0401), 1.01e-4), "within reach below the face");
    assert!(!rect.within_reach(&y(0.0, -0.0401), 0.99e-4), "beyond reach below the face");
    // 1e-3 out in x and y from the corner (0.01, -0.04): distance √2·1e-3,
    // inside the bounding box grown by 1.2e-3 but beyond that reach.
    assert!(!rect.within_reach(&y(0.011, -0.041), 1.2e-3), "corner, diagonal");
    assert!(rect.within_reach(&y(0.011, -0.041), 1.5e-3), "corner, within reach");
    // a triangle: a point in its bounding box but outside the slanted face
    let tri = RigidBody::new(
        "t",
        vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)],
        Vec2::zeros(),
        Vec2::zeros(),
        1.0,
    )
    .unwrap();
    assert!(tri.within_reach(&y(0.2, 0.2), 0.0), "inside");
    let d = (0.9 + 0.9 - 1.0) / (2.0 as Real).sqrt(); // distance of (0.9, 0.9) to x + y = 1
    assert!(!tri.within_reach(&y(0.9, 0.9), 0.99 * d), "outside the slanted face");
    assert!(tri.within_reach(&y(0.9, 0.9), 1.01 * d), "within reach of the slanted face");
}

/// Slaves by exposure ([`ContactSystem::admit_exposed`]): of three
/// particles that are not slaves, the one inside a wall and the one within
/// a spacing of it join the set (once), the far one does not; a step then
/// puts the one crossing the surface on it and holds the one inside, moving
/// in, at its depth (a penetration at the start of a step is held, not
/// pushed out: `contact::force`, # Deviations). With the option off
/// nothing joins and the particle inside goes deeper.
#[test]
fn exposed_particles_join_the_slaves_and_go_no_deeper() {
    let dt = 1e-7;
    let h = 1e-3;
    let particles = || {
        let mut p = Particles::default();
        for (x, y) in [(0.0, 5.0 * h), (0.1, -0.3 * h), (0.2, 0.5 * h), (0.3, 2.5 * h)] {
            let k = p.push(Vec2::new(x, y), 1e-6, h, 2.0 * h, 293.0, 0, ParticleFlags::default());
            p.mass[k] = 2e-4;
        }
        p.v[1] = Vec2::new(0.0, -1.0);
        p.v[2] = Vec2::new(0.0, -8.0 * h / dt); // crosses the surface this step
        p
    };
    let none = ContactParameters { spreading: Spreading::None, ..ContactParameters::default() };
    assert!(none.admit_exposed, "on by default");
    let mut p = particles();
    let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), none).unwrap();
    assert_eq!(sys.admit_exposed(&p.x0, &p.u, &p.spacing), 2);
    assert_eq!(sys.slaves.particles(), &[0, 1, 2]);
    assert_eq!(sys.admit_exposed(&p.x0, &p.u, &p.spacing), 0, "members stay, nobody joins twice");
    let mut f = Vec::new();
    let r = step(&mut sys, &mut p, None, dt, &mut f);
    assert_eq!(r.active_contacts, 2);
    for (i, y) in [(1, -0.3 * h), (2, 0.0)] {
        let y_end = p.x0[i].y + p.u[i].y;
        assert!((y_end - y).abs() <= 1e-12 * h, "particle {i} ends at y = {y_end:e}, not {y:e}");
    }
    assert_eq!(p.u[3], Vec2::zeros(), "the far particle feels nothing");

    let off = ContactParameters { admit_exposed: false, ..none };
    let mut p = particles();
    let mut sys = ContactSystem::new(vec![wall(0.0)], SlaveSet::from_indices([0]), off).unwrap();
    assert_eq!(sys.admit_exposed(&p.x0, &p.u, &p.spacing), 0);
    let r = step(&mut sys, &mut p, None, dt, &mut f);
    assert_eq!(r.active_contacts, 0);
    assert!(p.x0[1].y + p.u[1].y < -0.3 * h, "without exposure the particle inside goes deeper");
}
