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

#[macro_use]
mod common;

/// Two free elastic steel blocks, 10 × 10 mm with 1 mm particles: `a`
/// flies at `velocity` into `b` (at rest, 0.1 mm away, offset 2 mm up).
fn two_blocks(velocity: [Real; 2], friction: Real) -> Case {
    let text = format!(
        concat!(
            elastic_steel_plane_strain!(),
            r#"
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
friction_coefficient = {}
[time]
end = 8.0e-6
"#
        ),
        velocity[0], velocity[1], friction
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
    let text = concat!(
        elastic_steel_plane_strain!(),
        r#"
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
"#
    );
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

/// Issue #19 item 5, issue #20: a slave that starts a step inside a
/// deformable master (within the entry rule's `ENTRY_TOLERANCE` of 0.05 h)
/// was pushed out to the surface in that one step, i.e. thrown at
/// `|g⁰|/Δt`: about 0.1 c_L for 0.05 h at the step factor 0.5. In the
/// two-plates case (rigid projectile through two plates, 200 µs) the front
/// plate's plug slid along the back plate's crack face, its corner
/// particles a few hundredths of a spacing inside the face; each one that
/// came back within the tolerance was kicked out at ~800 m/s (10 J a kick),
/// the face's particle flew back into the plug, and the fastest particle
/// reached 4514 m/s while the deformable contact put 1.6 kJ into the run.
///
/// Here the two blocks of [`two_blocks`] start overlapped by 0.03 h (a's
/// generalized displacements shifted by a rigid translation across the
/// 0.1 mm between them and 0.03 h on after the build: the case format
/// refuses overlapping bodies), a closing at
/// 10 m/s. Nothing may move faster than twice that (before the fix the
/// first step threw the face particles apart at up to 253 m/s and the run
/// stopped there with an energy blow-up: 1318 J in the balance against the
/// 39 J put in); momentum stays exact, the contact's
/// work stays negative (it dissipates, here the first step's inelastic
/// stop of the face rows, 0.905 J), and the overlap does not grow.
#[test]
fn a_slave_starting_inside_a_deformable_master_is_not_thrown_out() {
    let v_i = 10.0;
    let case = two_blocks([v_i, 0.0], 0.0);
    let mut sim = build_simulation(&case).unwrap();
    let (h, overlap) = (1.0e-3, 0.03e-3);
    let p = &mut sim.model.particles;
    for i in (0..p.len()).filter(|&i| p.body[i] == 0) {
        p.u[i].x += 0.1e-3 + overlap;
    }
    let depth0 = deepest_penetration(&sim);
    assert!((depth0 - overlap).abs() < 1e-9 * h, "the blocks start overlapped by {depth0:e} m");
    let p0 = sim.model.particles.momentum();
    let (mut fastest, mut worst_momentum, mut deepest, mut touched): (Real, Real, Real, usize) = (0.0, 0.0, 0.0, 0);
    while sim.time < 2.0e-6 {
        sim.step().unwrap();
        let v = sim.model.physical(&sim.model.particles.v);
        fastest = v.iter().map(|v| v.norm()).fold(fastest, Real::max);
        worst_momentum = worst_momentum.max((sim.model.particles.momentum() - p0).norm() / p0.norm());
        deepest = deepest.max(deepest_penetration(&sim));
        let contact = sim.contact.as_ref().unwrap();
        touched += contact.segment_contacts().len();
        let work = contact.deformable_work();
        assert!(work <= 0.0, "by step {} the contact put {work:e} J into the blocks", sim.step);
    }
    assert!(touched > 10, "the overlapped faces are in contact ({touched} pairs)");
    assert!(body_momentum(&sim, 1).x > 0.1 * p0.x, "a pushes b: {:?}", body_momentum(&sim, 1));
    assert!(fastest < 2.0 * v_i, "a particle moved at {fastest:.1} m/s, above 2 v_i = {:.0} m/s", 2.0 * v_i);
    assert!(worst_momentum < 1e-12, "momentum drift {worst_momentum:e} of the total");
    assert!(deepest < overlap + 1e-3 * h, "the overlap grew to {:.4} h", deepest / h);
}

/// A Johnson–Cook steel bar (Weldox 460 E), 4 mm across and 10 mm long,
/// 0.5 mm particles, axisymmetric, at 200 m/s: onto a prescribed rigid
/// anvil, or head on into its mirror image flying at 200 m/s the other
/// way (each bar at v toward the other, the closing speed 2 v: the plane
/// between them stays at rest, as the anvil's face does; "one bar at v/2
/// each" would be the anvil at v/2). No cracks (`criterion = "none"`): a
/// test of the contact, not of the fracture model.
fn taylor(mirror: bool) -> Case {
    let bar = |name: &str, y: [Real; 2], v: Real| {
        format!(
            r#"
[[bodies]]
name = "{name}"
material = "weldox_460e"
rectangle = {{ x_min = 0.0, x_max = 0.002, y_min = {}, y_max = {}, layers = 21 }}
[[bodies.initial_velocity]]
velocity = [0.0, {v}]
"#,
            y[0], y[1]
        )
    };
    let mut text =
        String::from("[geometry]\nmode = \"axisymmetric\"\n[time]\nend = 40.0e-6\n[fracture]\ncriterion = \"none\"\n");
    text += &bar("bar", [0.00005, 0.01005], -200.0);
    if mirror {
        text += &bar("mirror", [-0.01005, -0.00005], 200.0);
    } else {
        text += r#"
[[rigid_bodies]]
name = "anvil"
rectangle = { center = [0.0, -0.005], width = 0.02, height = 0.01 }
density = 7850.0
velocity = [0.0, 0.0]
prescribed = true
"#;
    }
    Case::from_str_with(&text, "taylor.toml", &[]).unwrap().resolved()
}

/// Length of body 0 along y through its physical points, m.
fn length(sim: &Simulation) -> Real {
    let x = positions(sim);
    let p = &sim.model.particles;
    let ys = (0..p.len()).filter(|&i| p.body[i] == 0).map(|i| x[i].y);
    let (lo, hi) = ys.fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)));
    hi - lo
}

#[test]
fn rod_on_rod_gives_the_final_length_of_rod_on_anvil() {
    let run = |mirror: bool| {
        let case = taylor(mirror);
        let mut sim = build_simulation(&case).unwrap();
        while sim.time < case.time.end {
            sim.step().unwrap();
        }
        (length(&sim), sim)
    };
    let (anvil, _) = run(false);
    let (rod, sim) = run(true);
    // Measured without cracks (the bars' faces would nucleate one, a
    // threshold event whose timing differs between the two runs and is not
    // what this contact test is about): anvil 8.4560 mm, rod on rod
    // 8.4582 mm (+0.026 %); the bar rebounds at 12.4 m/s by then.
    let mass: Real = sim.model.particles.mass[sim.model.bodies[0].particles.clone()].iter().sum();
    let v = body_momentum(&sim, 0).y / mass;
    assert!(v > 0.0, "the bar must have stopped deforming and rebound ({v} m/s)");
    assert!(anvil < 0.0097, "the bar must shorten plastically ({anvil} m)");
    assert!((rod - anvil).abs() < 0.01 * anvil, "rod on rod {rod} m, rod on anvil {anvil} m");
    assert!(sim.energies.drift().abs() < 0.01, "energy drift {}", sim.energies.drift());
}

/// An elastic block (11 × 8 particles of 1 mm) with a crack inserted down
/// the particle column x = 5 mm, through the whole thickness: two pieces
/// whose facing crack faces are each other's masters. The +x piece moves
/// at `-speed` along x, the other at `+speed`.
fn cracked_block(speed: Real, self_contact: bool) -> Simulation {
    let text = concat!(
        elastic_steel_plane_strain!(),
        r#"
[[bodies]]
name = "block"
material = "steel"
rectangle = { x_min = 0.0, x_max = 0.010, y_min = 0.0, y_max = 0.007, layers = 8 }
[fracture]
criterion = "effective_strain"
[time]
end = 2.0e-6
"#
    );
    let set = [format!("contact.self_contact={self_contact}")];
    let case = Case::from_str_with(text, "cracked.toml", &set).unwrap().resolved();
    let mut sim = build_simulation(&case).unwrap();
    let x0 = sim.model.particles.x0.clone();
    let mut path: Vec<usize> = (0..x0.len()).filter(|&i| (x0[i].x - 0.005).abs() < 1e-9).collect();
    path.sort_by(|&a, &b| x0[b].y.total_cmp(&x0[a].y));
    let cracks = sim.cracks.as_mut().unwrap();
    let (_, faces) = cracks.insert_crack(&mut sim.model, &path, true).unwrap();
    sim.crack_faces_changed(&faces);
    let p = &mut sim.model.particles;
    for i in 0..p.len() {
        p.v[i] = Vec2::new(if p.x0[i].x > 0.005 { -speed } else { speed }, 0.0);
    }
    sim
}

/// Smallest opening of the crack, m: over its split vertices, the physical
/// x of the +x face's particle minus that of the other face's (2δ at the
/// start, negative where the faces have crossed).
fn smallest_opening(sim: &Simulation) -> Real {
    let x = positions(sim);
    let crack = &sim.cracks.as_ref().unwrap().cracks[0];
    // Growing downward, the left of the path is +x.
    crack
        .vertices
        .iter()
        .filter_map(|v| v.faces)
        .map(|(l, r)| x[l as usize].x - x[r as usize].x)
        .fold(Real::INFINITY, Real::min)
}

#[test]
fn crack_faces_pressed_together_do_not_cross() {
    let closing = |self_contact: bool| {
        let mut sim = cracked_block(20.0, self_contact);
        let mut worst = Real::INFINITY;
        while sim.time < 2.0e-6 {
            sim.step().unwrap();
            worst = worst.min(smallest_opening(&sim));
        }
        worst
    };
    let h = 1.0e-3;
    let with = closing(true);
    // Measured 1.05e-3 h for a step, where the mouth's corner particles
    // met head on (`contact::deformable`, corners); without the round-off
    // allowance at segment ends it was 2e-3 h.
    assert!(with > -1.5e-3 * h, "the faces crossed by {:.2e} h", -with / h);
    // Without self-contact the pieces pass through each other: the test
    // can fail.
    let without = closing(false);
    assert!(without < -0.02 * h, "{without}");
}

#[test]
fn self_contact_ignores_faces_behind_the_slave() {
    // The pieces move apart: no pair may carry a force, although the
    // particles next to the crack mouth project onto the surface segments
    // across it from a spacing inside (the entry rule).
    let mut sim = cracked_block(-20.0, true);
    assert!(!sim.contact.as_ref().unwrap().deformable.segments().is_empty());
    while sim.time < 2.0e-6 {
        sim.step().unwrap();
        assert!(sim.contact.as_ref().unwrap().segment_contacts().is_empty(), "step {}", sim.step);
    }
    assert!(smallest_opening(&sim) > 2.0e-5, "the crack opens");
}

#[test]
fn deformable_contact_measures_the_physical_points() {
    // b under a, touching; a is given a displacement that RK interpolation
    // does not reproduce (quadratic in x), so its generalized positions
    // X + U differ from its physical points X + Σ N U, and a velocity
    // toward b (pairs that start inside only resist going deeper).
    let text = concat!(
        elastic_steel_plane_strain!(),
        r#"
[[bodies]]
name = "a"
material = "steel"
rectangle = { x_min = 0.0, x_max = 0.01, y_min = 0.006, y_max = 0.01, layers = 5 }
[[bodies]]
name = "b"
material = "steel"
rectangle = { x_min = -0.002, x_max = 0.012, y_min = 0.0, y_max = 0.006, layers = 7 }
[time]
end = 1.0e-6
"#
    );
    let case = Case::from_str_with(text, "touching.toml", &[]).unwrap().resolved();
    let mut sim = build_simulation(&case).unwrap();
    let p = &mut sim.model.particles;
    for i in (0..p.len()).filter(|&i| p.body[i] == 0) {
        let dx = p.x0[i].x - 0.005;
        p.u[i] = Vec2::new(0.0, -2.0e-6 - 0.4 * dx * dx);
        p.v[i] = Vec2::new(0.0, -1.0);
    }
    let dt = sim.dt;
    let contact = sim.contact.as_mut().unwrap();
    let input = plugsim::contact::StepInput::from_particles(&sim.model.particles, Some(&sim.model.particle_shape), dt);
    let mut f = vec![Vec2::zeros(); sim.model.particles.len()];
    contact.compute_forces(&input, &mut f).unwrap();
    // The gaps are predicted at the end of the step, `U + Δt V` (no other
    // force acts).
    for i in 0..sim.model.particles.len() {
        let p = &mut sim.model.particles;
        p.u[i] += p.v[i] * dt;
    }
    let physical = positions(&sim);
    let p = &sim.model.particles;
    let generalized: Vec<Vec2> = p.x0.iter().zip(&p.u).map(|(x, u)| x + u).collect();
    // The gap of slave s on segment [a, b] through the points `x`.
    let gap = |x: &[Vec2], s: u32, [a, b]: [u32; 2]| {
        let (xs, xa, xb) = (x[s as usize], x[a as usize], x[b as usize]);
        let d = xb - xa;
        let lambda = ((xs - xa).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        ((xs - xa - d * lambda).dot(&(Vec2::new(d.y, -d.x) / d.norm())), lambda)
    };
    let contacts = sim.contact.as_ref().unwrap().segment_contacts();
    assert!(contacts.len() >= 8, "{} contacts", contacts.len());
    let mut differs = 0;
    for c in contacts {
        let (g, lambda) = gap(&physical, c.particle, c.segment);
        assert!((g - c.gap).abs() < 1e-12 * 1e-3 && (lambda - c.lambda).abs() < 1e-9, "{c:?}: physical gap {g}");
        let (g_generalized, _) = gap(&generalized, c.particle, c.segment);
        differs += usize::from((g_generalized - g).abs() > 1e-7);
    }
    assert!(differs > 0, "the generalized points would give the same gaps: the test proves nothing");
}

#[test]
fn deformable_contact_is_bit_identical_on_any_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let case = two_blocks([100.0, 10.0], 0.3);
            let mut sim = build_simulation(&case).unwrap();
            while sim.time < case.time.end {
                sim.step().unwrap();
            }
            let p = &sim.model.particles;
            let bits = |v: &[Vec2]| v.iter().flat_map(|v| [v.x.to_bits(), v.y.to_bits()]).collect::<Vec<u64>>();
            (bits(&p.u), bits(&p.v), sim.energies.total().to_bits(), sim.energies.contact_work.to_bits())
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn crack_rows_stay_in_their_body() {
    // A block lying on a plate; a crack split into the plate from its top
    // face right under the block. The rebuilt rows of the plate must not
    // take in the block's particles (nor the block's rows the plate's).
    let text = concat!(
        elastic_steel_plane_strain!(),
        r#"
[[bodies]]
name = "plate"
material = "steel"
rectangle = { x_min = 0.0, x_max = 0.010, y_min = 0.0, y_max = 0.004, layers = 5 }
[[bodies]]
name = "block"
material = "steel"
rectangle = { x_min = 0.002, x_max = 0.008, y_min = 0.004, y_max = 0.007, layers = 4 }
[fracture]
criterion = "effective_strain"
[time]
end = 1.0e-6
"#
    );
    let case = Case::from_str_with(text, "stacked.toml", &[]).unwrap().resolved();
    let mut sim = build_simulation(&case).unwrap();
    let x0 = sim.model.particles.x0.clone();
    let body = sim.model.particles.body.clone();
    let mut path: Vec<usize> = (0..x0.len()).filter(|&i| body[i] == 0 && (x0[i].x - 0.005).abs() < 1e-9).collect();
    path.sort_by(|&a, &b| x0[b].y.total_cmp(&x0[a].y));
    path.truncate(3);
    let momentum = sim.model.particles.momentum();
    let cracks = sim.cracks.as_mut().unwrap();
    cracks.insert_crack(&mut sim.model, &path, false).unwrap();
    let m = &sim.model;
    let p = &m.particles;
    for (table, owner) in [(&m.qp_shape, &m.quad.body), (&m.particle_shape, &p.body)] {
        for (row, &own) in owner.iter().enumerate().take(table.rows()) {
            for e in table.range(row) {
                assert_eq!(p.body[table.index[e] as usize], own, "row {row} takes particle {}", table.index[e]);
            }
        }
    }
    assert!((p.momentum() - momentum).norm() <= 1e-12 * momentum.norm().max(1.0));
}
