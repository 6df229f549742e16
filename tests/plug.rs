//! The plug (`plugsim::plug`): the piece the through-cracks cut out under the
//! impact line, found by a flood fill that the cracks block. Checked on
//! lattices with inserted cracks, against the particles known to lie
//! between them.

mod common;

use plugsim::contact::{SlaveSet, SurfaceDetection};
use plugsim::fracture::{CrackGrowth, Criterion, FractureParameters};
use plugsim::geometry::GeometryMode;
use plugsim::material::{Elastic, Material};
use plugsim::math::{Real, Vec2};
use plugsim::model::{BodySetup, Fix, Model, Region, Support};
use plugsim::plug::{find_plug, plug_particles, seed_particle, PlugTracker};

const H: Real = 0.5e-3;
const NX: usize = 25;
const NY: usize = 8;

fn steel() -> Elastic {
    Elastic { density: 7850.0, youngs_modulus: 200e9, poisson_ratio: 0.3, room_temperature: 293.0, thermal: None }
}

/// A uniform `NX × NY` lattice of spacing `H` from x = 0, clamped over its
/// last two columns (and, in plane strain, its first two).
fn plate(mode: GeometryMode) -> Model {
    let (w, t) = ((NX - 1) as Real * H, (NY - 1) as Real * H);
    let grid = common::uniform_lattice(NX, NY, H);
    let clamp =
        |x_min: Real, x_max: Real| Support { region: Region { x_min, x_max, y_min: 0.0, y_max: t }, fix: Fix::All };
    let mut supports = vec![clamp(w - 1.5 * H, w)];
    if mode == GeometryMode::PlaneStrain {
        supports.push(clamp(0.0, 1.5 * H));
    }
    let body = BodySetup {
        name: "plate".into(),
        grid,
        material: Material::Elastic(steel()),
        initial_velocity: vec![],
        supports,
    };
    let mut m = Model::build(mode, &[body]).unwrap();
    let slaves = SlaveSet::detect(&m.particles.x0, &m.particles.spacing, &SurfaceDetection::default()).unwrap();
    slaves.mark_flags(&mut m.particles.flags).unwrap();
    m
}

fn id(m: &Model, i: usize, j: usize) -> usize {
    let x = Vec2::new(i as Real * H, j as Real * H);
    (0..m.particles.len()).find(|&k| (m.particles.x0[k] - x).norm() < 1e-9 * H).unwrap()
}

/// A straight crack down column `i` from the impact face (top) through
/// `rows` rows, arrested on the far face if it reaches it.
fn cut(m: &mut Model, g: &mut CrackGrowth, i: usize, rows: usize) {
    let path: Vec<usize> = (0..rows).map(|k| id(m, i, NY - 1 - k)).collect();
    g.insert_crack(m, &path, rows == NY).unwrap();
}

fn growth() -> CrackGrowth {
    CrackGrowth::new(FractureParameters { criterion: Criterion::None, ..FractureParameters::default() })
}

/// The particles whose reference x lies strictly between `a` and `b`
/// lattice columns (the split children sit δ ≪ H off their column).
fn between(m: &Model, a: usize, b: usize) -> Vec<usize> {
    (0..m.particles.len())
        .filter(|&k| {
            let x = m.particles.x0[k].x;
            x > a as Real * H && x < b as Real * H
        })
        .collect()
}

#[test]
fn seed_is_mid_thickness_on_the_impact_line() {
    let m = plate(GeometryMode::PlaneStrain);
    let s = seed_particle(&m, 12.2 * H).unwrap();
    let x = m.particles.x0[s];
    assert!((x.x - 12.0 * H).abs() < 1e-12 && ((x.y / H) - 3.5).abs() <= 0.5 + 1e-9, "{x:?}");
}

#[test]
fn two_through_cracks_cut_out_the_particles_between_them() {
    let mut m = plate(GeometryMode::PlaneStrain);
    let mut g = growth();
    cut(&mut m, &mut g, 8, NY);
    cut(&mut m, &mut g, 16, NY);
    let plug = plug_particles(&m, &g, 12.0 * H).expect("a plug");
    assert_eq!(plug, between(&m, 8, 16));
    // 7 full columns plus the two half-columns of split children
    let lumped: Real = plug.iter().map(|&k| m.particles.mass[k]).sum();
    let expected = 7850.0 * 8.0 * H * (NY - 1) as Real * H;
    assert!((lumped / expected - 1.0).abs() < 0.05, "mass {lumped} vs {expected}");
}

#[test]
fn one_through_crack_or_a_crack_still_growing_cuts_nothing_out() {
    let mut m = plate(GeometryMode::PlaneStrain);
    let mut g = growth();
    cut(&mut m, &mut g, 8, NY);
    assert_eq!(plug_particles(&m, &g, 12.0 * H), None, "one crack: the plug still hangs on the other side");
    cut(&mut m, &mut g, 16, NY - 2);
    assert_eq!(plug_particles(&m, &g, 12.0 * H), None, "the second crack stops two rows short of the far face");
    // no arrested crack at all
    let mut m = plate(GeometryMode::PlaneStrain);
    let mut g = growth();
    cut(&mut m, &mut g, 8, NY - 1);
    assert_eq!(plug_particles(&m, &g, 12.0 * H), None);
}

#[test]
fn a_ring_crack_cuts_out_the_axis_region_in_axisymmetry() {
    let mut m = plate(GeometryMode::Axisymmetric);
    let mut g = growth();
    cut(&mut m, &mut g, 8, NY);
    let plug = plug_particles(&m, &g, 0.0).expect("the particles on the axis do not hold the plug");
    let inside: Vec<usize> = (0..m.particles.len()).filter(|&k| m.particles.x0[k].x < 8.0 * H).collect();
    assert_eq!(plug, inside);
}

#[test]
fn plug_mass_and_velocity_are_its_particles_sums() {
    let mut m = plate(GeometryMode::PlaneStrain);
    let mut g = growth();
    cut(&mut m, &mut g, 8, NY);
    cut(&mut m, &mut g, 16, NY);
    let p = &mut m.particles;
    for k in 0..p.len() {
        p.v[k] = Vec2::new(1e4 * p.x0[k].y, -100.0 - 1e4 * p.x0[k].x);
    }
    let plug = find_plug(&m, &g, 12.0 * H).unwrap();
    let p = &m.particles;
    let mass: Real = plug.particles.iter().map(|&k| p.mass[k]).sum();
    let mom = plug.particles.iter().fold(Vec2::zeros(), |a, &k| a + p.v[k] * p.mass[k]);
    assert!((plug.mass - mass).abs() <= 1e-12 * mass);
    assert!((plug.velocity() - mom / mass).norm() < 1e-9);
    // symmetric about the impact line: the mean vertical speed is the one at x = 12 H
    assert!((plug.velocity().y - (-100.0 - 1e4 * 12.0 * H)).abs() < 1e-6, "{:?}", plug.velocity());
}

#[test]
fn the_tracker_follows_velocity_and_recomputes_when_the_cracks_change() {
    let mut m = plate(GeometryMode::PlaneStrain);
    let mut g = growth();
    let mut t = PlugTracker::default();
    cut(&mut m, &mut g, 8, NY);
    assert!(t.update(&m, &g, 12.0 * H, 1e-6).is_none());
    assert_eq!(t.first_cut, None);
    cut(&mut m, &mut g, 16, NY);
    let first = t.update(&m, &g, 12.0 * H, 2e-6).expect("cut out after the second crack");
    assert_eq!(t.first_cut, Some(2e-6), "perforated when first found");
    for v in m.particles.v.iter_mut() {
        *v = Vec2::new(0.0, -50.0);
    }
    let second = t.update(&m, &g, 12.0 * H, 3e-6).unwrap();
    assert_eq!(first.particles, second.particles);
    assert_eq!(t.first_cut, Some(2e-6), "the first cut stays");
    assert!((second.velocity() - Vec2::new(0.0, -50.0)).norm() < 1e-9);
}

/// Break every quadrature point of the background cells between lattice
/// columns `i` and `i + 1` whose centre lies below `y_top`: erode it, or
/// (with `fracture`) set its damage to 1, fractured by the damage model's
/// own measure.
fn break_band(m: &mut Model, i: usize, y_top: Real, fracture: bool) {
    let q = &mut m.quad;
    for k in 0..q.len() {
        let x = q.x0[k];
        if x.x > i as Real * H && x.x < (i + 1) as Real * H && x.y < y_top {
            if fracture {
                q.damage[k] = 1.0;
            } else {
                q.eroded[k] = true;
            }
        }
    }
}

#[test]
fn a_band_of_broken_points_cuts_out_a_plug_without_cracks() {
    // Two bands of eroded points through the thickness, no crack at all:
    // the particles between them are the plug, as with two through-cracks.
    let mut m = plate(GeometryMode::PlaneStrain);
    let g = growth();
    break_band(&mut m, 8, Real::INFINITY, false);
    assert_eq!(plug_particles(&m, &g, 12.0 * H), None, "one band: the plug still hangs on the other side");
    break_band(&mut m, 15, Real::INFINITY, false);
    assert_eq!(plug_particles(&m, &g, 12.0 * H).expect("a plug"), between(&m, 8, 16));
    // Fractured points (D = 1) break bonds only where the solver fractures
    // points: the per-particle criteria, and the default non-local one
    // unless its point fracture is off.
    let cases = [(Criterion::Damage, true, true), (Criterion::NonlocalDamage, true, true)];
    let cases = cases.into_iter().chain([(Criterion::NonlocalDamage, false, false), (Criterion::None, true, false)]);
    for (criterion, nonlocal_point_fracture, cuts) in cases {
        let mut m = plate(GeometryMode::PlaneStrain);
        break_band(&mut m, 8, Real::INFINITY, true);
        break_band(&mut m, 15, Real::INFINITY, true);
        let params = FractureParameters { criterion, nonlocal_point_fracture, ..FractureParameters::default() };
        let g = CrackGrowth::new(params);
        let plug = plug_particles(&m, &g, 12.0 * H);
        assert_eq!(plug.is_some(), cuts, "{criterion:?}");
        if cuts {
            assert_eq!(plug.unwrap(), between(&m, 8, 16));
        }
    }
    // A ring band in axisymmetry, and a band that meets a crack still
    // growing (its tip's cells broken on both sides): the axis region
    // inside the ring is the plug.
    let mut m = plate(GeometryMode::Axisymmetric);
    break_band(&mut m, 8, Real::INFINITY, false);
    let inside: Vec<usize> = (0..m.particles.len()).filter(|&k| m.particles.x0[k].x < 8.5 * H).collect();
    assert_eq!(plug_particles(&m, &g, 0.0).expect("a ring of eroded points"), inside);
    let mut m = plate(GeometryMode::Axisymmetric);
    let mut g = growth();
    cut(&mut m, &mut g, 8, 4);
    break_band(&mut m, 7, 4.5 * H, false);
    break_band(&mut m, 8, 4.5 * H, false);
    let plug = plug_particles(&m, &g, 0.0).expect("a crack from the top, broken points below it");
    assert!(plug.iter().all(|&k| m.particles.x0[k].x < 8.5 * H));
    assert!(plug.len() >= 8 * NY, "{} particles", plug.len());
}

#[test]
fn one_point_still_carrying_tension_holds_the_plug() {
    let mut m = plate(GeometryMode::PlaneStrain);
    let g = growth();
    break_band(&mut m, 8, Real::INFINITY, false);
    break_band(&mut m, 15, Real::INFINITY, false);
    let mut t = PlugTracker::default();
    // Keep one point of one band's cells intact, mid-thickness.
    let q = &mut m.quad;
    let keep = (0..q.len())
        .filter(|&k| q.eroded[k])
        .min_by(|&a, &b| {
            let d = |k: usize| (q.x0[k] - Vec2::new(8.5 * H, 3.5 * H)).norm();
            d(a).partial_cmp(&d(b)).unwrap()
        })
        .unwrap();
    q.eroded[keep] = false;
    assert_eq!(t.update(&m, &g, 12.0 * H, 1e-6), None, "one unbroken point bonds its cell's links");
    assert_eq!(t.first_cut, None);
    // The tracker fills again when the broken points change.
    m.quad.eroded[keep] = true;
    let plug = t.update(&m, &g, 12.0 * H, 2e-6).expect("the last point broken");
    assert_eq!(plug.particles, between(&m, 8, 16));
    assert_eq!(t.first_cut, Some(2e-6));
    // A band that stops a row short of the far face cuts nothing out.
    let mut m = plate(GeometryMode::PlaneStrain);
    break_band(&mut m, 8, Real::INFINITY, false);
    break_band(&mut m, 15, (NY as Real - 2.0) * H, false);
    assert_eq!(plug_particles(&m, &g, 12.0 * H), None);
}
