//! Projectiles by nose shape in the case format (SPEC §8): each nose
//! parses and builds its body, wrong or missing nose parameters are
//! rejected naming the field, and a hemispherical nose striking a free
//! elastic plate conserves momentum and does not let the plate through,
//! and pressed into an elastic plate, slowly or by an impact, meets
//! Hertz's contact.

use plugsim::case::Case;
use plugsim::math::{Real, Vec2};
use plugsim::run::build_simulation;

#[macro_use]
mod common;

/// A free (unsupported) elastic plate, 6 mm thick, and a 10 mm
/// hemispherical-nosed projectile 0.05 mm above it, at 100 m/s.
fn case(mode: &str, projectile: &str) -> String {
    format!(
        r#"
[geometry]
mode = "{mode}"
{steel}
[[bodies]]
name = "plate"
material = "steel"
[bodies.rectangle]
x_min = {x_min}
x_max = 0.02
y_min = 0.0
y_max = 0.006
layers = 7
[[rigid_bodies]]
name = "projectile"
projectile = {projectile}
density = 7850.0
velocity = [0.0, -100.0]
[time]
end = 8.0e-6
"#,
        steel = elastic_steel!(),
        x_min = if mode == "axisymmetric" { "0.0" } else { "-0.02" },
    )
}

const HEMI: &str = r#"{ nose = "hemispherical", tip = [0.0, 0.00605], diameter = 0.01, length = 0.01 }"#;

fn error(text: &str) -> String {
    match Case::from_str_with(text, "bad.toml", &[]) {
        Ok(_) => panic!("should be rejected:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn every_nose_builds_its_body_with_the_mass_of_its_solid() {
    let pi = std::f64::consts::PI;
    let (r, l) = (0.005, 0.01);
    for (nose, extra, nose_volume, nose_area, nose_length) in [
        ("blunt", "", 0.0, 0.0, 0.0),
        // a 1 mm edge radius: the face's disc and a quarter-circle ring
        // (Pappus: the quarter disc's centroid at R − e + 4e/3π from the axis)
        (
            "blunt",
            ", edge_radius = 0.001",
            pi * ((r - 0.001) * (r - 0.001) * 0.001
                + 0.5 * pi * (r - 0.001) * 0.001 * 0.001
                + 2.0 / 3.0 * 0.001 * 0.001 * 0.001),
            2.0 * ((r - 0.001) * 0.001 + 0.25 * pi * 0.001 * 0.001),
            0.001,
        ),
        ("hemispherical", "", 2.0 / 3.0 * pi * r * r * r, 0.5 * pi * r * r, r),
        ("conical", ", nose_angle_deg = 90.0", pi * r * r * r / 3.0, r * r, r),
        ("conical", ", nose_length = 0.004", pi * r * r * 0.004 / 3.0, r * 0.004, 0.004),
    ] {
        let p = format!(r#"{{ nose = "{nose}", tip = [0.0, 0.00605], diameter = 0.01, length = 0.01{extra} }}"#);
        for mode in ["plane_strain", "axisymmetric"] {
            let c = Case::from_str_with(&case(mode, &p), "nose.toml", &[]).unwrap_or_else(|e| panic!("{e}"));
            let again: Case = toml::from_str(&c.resolved_toml()).unwrap();
            assert_eq!(again, c.resolved(), "{nose}: the resolved case round-trips");
            let b = &c.rigid_bodies().unwrap()[0];
            assert_eq!(b.position, Vec2::new(0.0, 0.00605), "{nose}: the body frame's origin is the tip");
            let lowest = b.outline_global().map(|v| v.y).fold(Real::INFINITY, Real::min);
            assert!((lowest - 0.00605).abs() < 1e-15, "{nose}: the nose points down, tip lowest");
            let exact = if mode == "axisymmetric" {
                7850.0 * (nose_volume + pi * r * r * (l - nose_length))
            } else {
                7850.0 * (nose_area + 2.0 * r * (l - nose_length))
            };
            // facets of h/4 = 0.25 mm on the 5 mm hemisphere lie up to 1.6 um
            // inside it: 1.2e-4 of the axisymmetric mass (measured)
            assert!((b.mass / exact - 1.0).abs() < 2e-4, "{nose} {mode}: mass {} vs {exact}", b.mass);
        }
    }
    let ogive =
        r#"{ nose = "ogival", tip = [0.0, 0.00605], diameter = 0.01, length = 0.03, caliber_radius_head = 3.0 }"#;
    assert!(Case::from_str_with(&case("axisymmetric", ogive), "ogive.toml", &[]).is_ok());
}

#[test]
fn wrong_nose_parameters_are_named() {
    let with = |p: &str| case("plane_strain", p);
    let cases = [
        (r#"{ nose = "conical", tip = [0.0, 0.007], diameter = 0.01, length = 0.01 }"#, "projectile.nose_length"),
        (
            r#"{ nose = "conical", tip = [0.0, 0.007], diameter = 0.01, length = 0.01, nose_length = 0.002, nose_angle_deg = 60.0 }"#,
            "not both",
        ),
        (
            r#"{ nose = "conical", tip = [0.0, 0.007], diameter = 0.01, length = 0.01, nose_angle_deg = 190.0 }"#,
            "projectile.nose_angle_deg",
        ),
        (
            r#"{ nose = "ogival", tip = [0.0, 0.007], diameter = 0.01, length = 0.03 }"#,
            "projectile.caliber_radius_head",
        ),
        (
            r#"{ nose = "ogival", tip = [0.0, 0.007], diameter = 0.01, length = 0.03, caliber_radius_head = 0.3 }"#,
            "at least 0.5",
        ),
        (
            r#"{ nose = "hemispherical", tip = [0.0, 0.007], diameter = 0.01, length = 0.01, caliber_radius_head = 3.0 }"#,
            "applies to ogival noses only",
        ),
        (r#"{ nose = "hemispherical", tip = [0.0, 0.007], diameter = 0.01, length = 0.004 }"#, "projectile.length"),
        (r#"{ nose = "blunt", tip = [0.0, 0.007], diameter = -0.01, length = 0.01 }"#, "projectile.diameter"),
        (
            r#"{ nose = "blunt", tip = [0.0, 0.007], diameter = 0.01, length = 0.01, edge_radius = 0.005 }"#,
            "projectile.edge_radius",
        ),
        (
            r#"{ nose = "conical", tip = [0.0, 0.007], diameter = 0.01, length = 0.01, nose_length = 0.002, edge_radius = 0.001 }"#,
            "applies to blunt noses only",
        ),
        (r#"{ nose = "ogive", tip = [0.0, 0.007], diameter = 0.01, length = 0.01 }"#, "ogival"),
        (r#"{ nose = "blunt", tip = [0.0, 0.007], diameter = 0.01, length = 0.01, angle = 3 }"#, "angle"),
    ];
    for (p, expect) in cases {
        let e = error(&with(p));
        assert!(e.contains(expect), "{p}: {e}");
    }
    let e = error(&case("axisymmetric", r#"{ nose = "blunt", tip = [0.001, 0.007], diameter = 0.01, length = 0.01 }"#));
    assert!(e.contains("projectile.tip") && e.contains("axis"), "{e}");
    let both = with(HEMI).replace(
        "projectile = {",
        "rectangle = { center = [0.0, 0.012], width = 0.01, height = 0.01 }\nprojectile = {",
    );
    let e = error(&both);
    assert!(e.contains("rigid_bodies[0]") && e.contains("not several"), "{e}");
}

/// The hemispherical nose on a free plate (plane strain and axisymmetry):
/// nothing outside acts on the pair, so `Σ m V + M V_p` stays constant;
/// no slave ends a step inside the nose by more than a small fraction of
/// the spacing (the gap to the exact sphere at the physical point).
#[test]
fn hemispherical_impact_conserves_momentum_and_does_not_penetrate() {
    for mode in ["plane_strain", "axisymmetric"] {
        let c = Case::from_str_with(&case(mode, HEMI), "hemi.toml", &[]).unwrap().resolved();
        let mut sim = build_simulation(&c).unwrap();
        let h = sim.model.min_spacing();
        let momentum =
            |s: &plugsim::step::Simulation| s.model.particles.momentum() + s.contact.as_ref().unwrap().body_momentum();
        let p0 = momentum(&sim);
        let (mut contacted, mut drift, mut deepest): (bool, Real, Real) = (false, 0.0, 0.0);
        while sim.time < c.time.end {
            sim.step().unwrap();
            let contact = sim.contact.as_ref().unwrap();
            contacted |= contact.sample(0).unwrap().active_contacts > 0;
            // y is not conserved in axisymmetry's radial direction: compare the axial component there
            let dp = momentum(&sim) - p0;
            drift = drift.max(if mode == "axisymmetric" { dp.y.abs() } else { dp.norm() } / p0.norm());
            let centre = contact.bodies[0].position + Vec2::new(0.0, 0.005);
            let u = sim.model.physical(&sim.model.particles.u);
            for &s in contact.slaves.particles() {
                let x = sim.model.particles.x0[s as usize] + u[s as usize];
                if x.y < centre.y {
                    deepest = deepest.max(0.005 - (x - centre).norm());
                }
            }
        }
        assert!(contacted, "{mode}: the projectile must hit the plate");
        let v = sim.contact.as_ref().unwrap().bodies[0].velocity.y;
        assert!(v > -99.0, "{mode}: the projectile must slow down (v = {v})");
        assert!(drift < 1e-10, "{mode}: momentum drift {drift:e}");
        assert!(deepest < 0.05 * h, "{mode}: a slave is {:.3} spacings inside the nose", deepest / h);
    }
}

/// The face of the Hertz tests' plate, where the nose's tip starts, m:
/// the nose's depth is `PLATE_TOP − y_tip`.
const PLATE_TOP: Real = 0.02;

/// The Hertz tests' nose radius `R` (the Børvik cases'), m.
const NOSE_RADIUS: Real = 0.01;

/// `E* = E/(1−ν²)` of [`elastic_steel`]'s steel (E = 200 GPa, ν = 0.3), Pa.
const E_STAR: Real = 200.0e9 / (1.0 - 0.3 * 0.3);

/// The Hertz tests' case: a nose of [`NOSE_RADIUS`], its tip on
/// the face of an elastic steel plate (axisymmetric, 20 mm thick, clamped
/// underneath, 0.25 mm particles out to 3 mm from the axis and graded
/// beyond), moving down at `speed` (m/s), held at that speed if
/// `prescribed`, to `end` (s).
fn hertz_case(speed: Real, prescribed: bool, end: Real) -> String {
    format!(
        r#"
[geometry]
mode = "axisymmetric"
{steel}
[[bodies]]
name = "plate"
material = "steel"
[bodies.rectangle]
x_min = 0.0
x_max = 0.02
y_min = 0.0
y_max = {PLATE_TOP}
layers = 80
refine_at = 0.0
fine_half_width = 0.003
fine_spacing = 0.00025
growth = 1.15
coarse_spacing = 0.002
[[bodies.supports]]
fix = "all"
[bodies.supports.region]
x_min = 0.0
x_max = 0.02
y_min = 0.0
y_max = 0.0001
[[rigid_bodies]]
name = "projectile"
projectile = {{ nose = "hemispherical", tip = [0.0, {PLATE_TOP}], diameter = {diameter}, length = {diameter} }}
density = 7850.0
velocity = [0.0, -{speed}]
prescribed = {prescribed}
[time]
end = {end:e}
"#,
        steel = elastic_steel!(),
        diameter = 2.0 * NOSE_RADIUS,
    )
}

/// Hertz's `F = (4/3) E* √R δ^{3/2}`, N, for the rigid sphere of radius
/// [`NOSE_RADIUS`] at depth `δ` in elastic steel ([`E_STAR`]).
fn hertz_force(depth: Real) -> Real {
    4.0 / 3.0 * E_STAR * NOSE_RADIUS.sqrt() * depth.max(0.0).powf(1.5)
}

/// Hertz (1882): a rigid sphere of radius `R` pressed a depth `δ` into an
/// elastic half-space carries `F = (4/3) E* √R δ^{3/2}` over a contact
/// radius `a = √(R δ)`. Here the nose of [`hertz_case`] is driven at a
/// prescribed 2 m/s to `δ` = 0.05 mm. The run is quasi-static (the nose
/// moves 3,000 times slower than the plate's P wave), and `a` stays under
/// 4 % of the thickness, where a clamped layer's stiffening is a few per
/// cent.
///
/// Measured: between `a` = 2 and 2.8 spacings the force follows Hertz's
/// within −5…+4 % (+1…+7 % on a uniform lattice of the same spacing;
/// halving the spacing of a 10 mm plate moved it by 2.5 % at most, and
/// that thinner layer is about 5 % stiffer). It swings about Hertz's
/// curve with the rings of surface particles the widening patch catches
/// one by one (`a/h` + 1 of them in contact, the axis included, within
/// one). So the rounded nose's contact carries the right force on a patch
/// of a few particles; the patch's edge is resolved to the spacing
/// between those rings, no finer.
#[test]
fn a_hemispherical_nose_pressed_into_an_elastic_plate_carries_hertz_force() {
    let text = hertz_case(2.0, true, 25.0e-6);
    let c = Case::from_str_with(&text, "hertz.toml", &[]).unwrap().resolved();
    let mut sim = build_simulation(&c).unwrap();
    let h = 0.00025;
    let (mut lowest, mut highest, mut samples): (Real, Real, usize) = (Real::INFINITY, 0.0, 0);
    while sim.time < c.time.end {
        sim.step().unwrap();
        let body = sim.contact.as_ref().unwrap().sample(0).unwrap();
        let depth = PLATE_TOP - body.position.y;
        let a = (NOSE_RADIUS * depth).sqrt();
        if a < 2.0 * h {
            continue;
        }
        let ratio = body.contact_force.y.abs() / hertz_force(depth);
        (lowest, highest, samples) = (lowest.min(ratio), highest.max(ratio), samples + 1);
        let rings = body.active_contacts as Real;
        assert!((rings - (a / h + 1.0)).abs() <= 1.0, "{rings} slaves in contact over a = {:.2} spacings", a / h);
    }
    let depth = PLATE_TOP - sim.contact.as_ref().unwrap().sample(0).unwrap().position.y;
    assert!((depth - 0.05e-3).abs() < 1e-7, "the nose is driven to 0.05 mm: {depth:e}");
    assert!(samples > 100, "{samples} steps with a patch of two spacings or more");
    assert!(lowest > 0.93 && highest < 1.07, "F / F_Hertz within {lowest:.3}…{highest:.3}");
    eprintln!("F / F_Hertz over a = 2…2.8 spacings: {lowest:.3}…{highest:.3} ({samples} steps)");
}

/// Hertz's impact (Johnson, *Contact Mechanics*, §11.4): a free rigid
/// sphere of mass `M` striking an elastic half-space at `v` reaches the
/// depth `δ_max = (15 M v² / (16 E* √R))^{2/5}` and the force `F(δ_max)`,
/// and leaves after `t_c = 2.943 δ_max / v`, as long as the impact is slow
/// against the waves. Here the nose of [`hertz_case`] (41.1 g) strikes at
/// 10 m/s: `δ_max` = 0.125 mm, `a` = 4.5 spacings, `t_c` = 36.8 µs, five
/// P-wave transits of the 20 mm plate.
///
/// Measured: `δ_max` −1.6 %, the peak force −4.6 % (the ring sawtooth of
/// the test above), the contact time −1.4 %. Catching the rings one at a
/// time dissipates 1e-4 J of the 2.06 J brought in: the one-step contact
/// is no sink at this speed. The nose rebounds at 8.25 m/s, not 10: a
/// third of the energy is left ringing in the clamped 20 mm block, which
/// is no half-space over 36 µs (Hertz's rebound is not asserted).
#[test]
fn a_hemispherical_nose_striking_an_elastic_plate_follows_hertz_impact() {
    let speed: Real = 10.0;
    let c = Case::from_str_with(&hertz_case(speed, false, 45.0e-6), "hertz.toml", &[]).unwrap().resolved();
    let mut sim = build_simulation(&c).unwrap();
    let mass = sim.contact.as_ref().unwrap().bodies[0].mass;
    let depth_max = (15.0 * mass * speed * speed / (16.0 * E_STAR * NOSE_RADIUS.sqrt())).powf(0.4);
    let duration = 2.943 * depth_max / speed;
    let (mut deepest, mut peak, mut first, mut last): (Real, Real, Option<Real>, Real) = (0.0, 0.0, None, 0.0);
    while sim.time < c.time.end {
        sim.step().unwrap();
        let body = sim.contact.as_ref().unwrap().sample(0).unwrap();
        deepest = deepest.max(PLATE_TOP - body.position.y);
        if body.contact_force.y != 0.0 {
            peak = peak.max(body.contact_force.y.abs());
            first.get_or_insert(sim.time);
            last = sim.time;
        }
    }
    let contact_time = last - first.expect("the nose struck");
    let rel = |x: Real, exact: Real| x / exact - 1.0;
    eprintln!(
        "δ_max {:+.3}, F_max {:+.3}, t_c {:+.3} against Hertz",
        rel(deepest, depth_max),
        rel(peak, hertz_force(depth_max)),
        rel(contact_time, duration)
    );
    assert!(rel(deepest, depth_max).abs() < 0.04, "δ_max {deepest:e} against {depth_max:e} m");
    assert!(rel(peak, hertz_force(depth_max)).abs() < 0.07, "F_max {peak:.0} N");
    assert!(rel(contact_time, duration).abs() < 0.05, "t_c {contact_time:e} against {duration:e} s");
    let rebound = sim.contact.as_ref().unwrap().bodies[0].velocity.y;
    assert!(rebound > 0.5 * speed && rebound < speed, "the nose rebounds, slower: {rebound} m/s");
    let e = sim.energies;
    assert!(e.contact_dissipation() >= -1e-9 && e.contact_dissipation() < 1e-3 * e.initial_kinetic, "{e:?}");
    assert!(e.drift().abs() < 1e-4, "energy drift {:e}", e.drift());
}
