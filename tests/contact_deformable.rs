//! Contact between deformable bodies and of crack faces (issue #20,
//! `src/contact/deformable.rs`): momentum to round-off, the energy balance,
//! no interpenetration, Coulomb friction, the physical points, self-contact
//! across a crack, thread-count bit identity, and the symmetric Taylor
//! impact (rod on rod) against the rod on a rigid anvil.

use plugsim::case::Case;
use plugsim::contact::rectangle_boundary;
use plugsim::math::{Real, Vec2};
use plugsim::run::build_simulation;
use plugsim::step::Simulation;

/// Two free elastic steel blocks, 10 × 10 mm with 1 mm particles: `a`
/// flies at `velocity` into `b` (at rest, 0.1 mm away, offset 2 mm up).
fn two_blocks(velocity: [Real; 2], friction: Real) -> Case {
    let text = format!(
        r#"
[geometry]
mode = "plane_strain"
[materials.steel]
model = "elastic"
density = 7850.0
youngs_modulus = 200.0e9
poisson_ratio = 0.3
[[bodies]]
name = "a"
material = "steel"
rectangle = {{ x_min = 0.0, x_max = 0.01, y_min = 0.0, y_max = 0.01, layers = 11 }}
[[bodies.initial_velocity]]
velocity = [{}, {}]
[[bodies]]
name = "b"
material = "steel"
rectangle = {{ x_min = 0.0101, x_max = 0.0201, y_min = 0.002, y_max = 0.012, layers = 11 }}
[contact]
friction_coefficient = {friction}
[time]
end = 8.0e-6
"#,
        velocity[0], velocity[1]
    );
    Case::from_str_with(&text, "two-blocks.toml", &[]).unwrap().resolved()
}

/// Physical positions `X + Σ N U` of every particle.
fn positions(sim: &Simulation) -> Vec<Vec2> {
    let m = &sim.model;
    let u = m.physical(&m.particles.u);
    m.particles.x0.iter().zip(&u).map(|(x, u)| x + u).collect()
}

/// Deepest penetration of a particle of one body into the boundary polygon
/// (through its physical points) of another, m: the distance from a point
/// inside the polygon to its boundary; 0 if none is inside.
fn deepest_penetration(sim: &Simulation) -> Real {
    let x = positions(sim);
    let p = &sim.model.particles;
    let mut worst: Real = 0.0;
    for (b, body) in sim.model.bodies.iter().enumerate() {
        let loop_: Vec<Vec2> =
            rectangle_boundary(&p.x0, &p.flags, body.particles.clone()).iter().map(|s| x[s[0] as usize]).collect();
        for i in (0..p.len()).filter(|&i| p.body[i] != b as u32) {
            let q = x[i];
            let mut inside = false;
            let mut dist = Real::INFINITY;
            for k in 0..loop_.len() {
                let (a, c) = (loop_[k], loop_[(k + 1) % loop_.len()]);
                if (a.y > q.y) != (c.y > q.y) && q.x < a.x + (q.y - a.y) / (c.y - a.y) * (c.x - a.x) {
                    inside = !inside;
                }
                let d = c - a;
                let t = ((q - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                dist = dist.min((q - (a + d * t)).norm());
            }
            if inside {
                worst = worst.max(dist);
            }
        }
    }
    worst
}

/// `Σ m V` of the particles of `body`.
fn body_momentum(sim: &Simulation, body: u32) -> Vec2 {
    let p = &sim.model.particles;
    (0..p.len()).filter(|&i| p.body[i] == body).fold(Vec2::zeros(), |acc, i| acc + p.v[i] * p.mass[i])
}

#[test]
fn two_free_bodies_conserve_momentum_close_the_energy_balance_and_do_not_interpenetrate() {
    let case = two_blocks([100.0, 10.0], 0.0);
    let mut sim = build_simulation(&case).unwrap();
    let p0 = sim.model.particles.momentum();
    let (mut worst_momentum, mut worst_depth, mut worst_drift): (Real, Real, Real) = (0.0, 0.0, 0.0);
    let mut touched = 0;
    while sim.time < case.time.end {
        sim.step().unwrap();
        worst_momentum = worst_momentum.max((sim.model.particles.momentum() - p0).norm() / p0.norm());
        worst_depth = worst_depth.max(deepest_penetration(&sim));
        worst_drift = worst_drift.max(sim.energies.drift().abs());
        touched += sim.contact.as_ref().unwrap().segment_contacts().len();
    }
    assert!(touched > 100, "the blocks must collide ({touched} contacts)");
    // b was hit: it moves along +x now, a slowed down.
    let (pa, pb) = (body_momentum(&sim, 0), body_momentum(&sim, 1));
    assert!(pb.x > 0.5 * p0.x && pa.x < 0.5 * p0.x, "a {pa:?}, b {pb:?}, total {p0:?}");
    assert!(worst_momentum < 1e-12, "momentum drift {worst_momentum:e} of the total");
    assert!(worst_drift < 0.01, "energy balance off by {:.3} %", 100.0 * worst_drift);
    let dissipated = sim.energies.contact_dissipation();
    assert!(dissipated > 0.0 && dissipated < 0.05 * sim.energies.initial_kinetic, "contact dissipated {dissipated} J");
    let h = 1.0e-3;
    assert!(worst_depth < 1e-3 * h, "a particle went {:.2e} h into the other body", worst_depth / h);
}

#[test]
fn friction_between_deformable_bodies_obeys_coulomb() {
    // a slides along b's top face while pressed onto it.
    let mu = 0.2;
    let text = r#"
[geometry]
mode = "plane_strain"
[materials.steel]
model = "elastic"
density = 7850.0
youngs_modulus = 200.0e9
poisson_ratio = 0.3
[[bodies]]
name = "a"
material = "steel"
rectangle = { x_min = 0.0, x_max = 0.006, y_min = 0.00601, y_max = 0.01001, layers = 5 }
[[bodies.initial_velocity]]
velocity = [40.0, -20.0]
[[bodies]]
name = "b"
material = "steel"
rectangle = { x_min = -0.01, x_max = 0.03, y_min = 0.0, y_max = 0.006, layers = 7 }
[time]
end = 4.0e-6
"#;
    let run = |mu: Real| {
        let case = Case::from_str_with(text, "slide.toml", &[format!("contact.friction_coefficient={mu}")])
            .unwrap()
            .resolved();
        let mut sim = build_simulation(&case).unwrap();
        let p0 = body_momentum(&sim, 0);
        let (mut slipping, mut worst) = (0, 0.0 as Real);
        while sim.time < case.time.end {
            sim.step().unwrap();
            for c in sim.contact.as_ref().unwrap().segment_contacts() {
                // |f_t| <= mu f_n, at the cap when slipping.
                worst = worst.max(c.tangential_force.abs() - mu * c.normal_force);
                if c.slipping {
                    slipping += 1;
                    assert!((c.tangential_force.abs() - mu * c.normal_force).abs() <= 1e-9 * c.normal_force);
                }
            }
        }
        (body_momentum(&sim, 0) - p0, slipping, worst)
    };
    let (dp, slipping, worst) = run(mu);
    assert!(worst <= 1e-9, "a tangential force exceeded the Coulomb cap by {worst:e} N");
    assert!(slipping > 0, "a slides: some contacts must slip");
    // The impulse on a: braked along x by mu times the normal impulse while
    // it slides throughout (measured 0.2006: the deformed faces' normals
    // tilt a little from y, which the frictionless run shows).
    assert!(dp.y > 0.0 && dp.x < 0.0, "{dp:?}");
    let ratio = -dp.x / dp.y;
    assert!((ratio - mu).abs() < 0.01 * mu, "tangential/normal impulse {ratio}");
    // Without friction, almost no tangential impulse.
    let (dp0, _, _) = run(0.0);
    assert!(dp0.x.abs() < 0.005 * dp0.y, "{dp0:?}");
}
