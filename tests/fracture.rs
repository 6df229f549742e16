//! Crack nucleation, propagation and arrest by particle splitting and the
//! visibility criterion (SPEC §9, [RL10, §4]).
//!
//! The invariants (mass, momentum, reproduction, no support across a crack)
//! are checked after every split with their own code, not the solver's.

mod common;

use plugsim::bulk_viscosity::BulkViscosity;
use plugsim::case::Case;
use plugsim::contact::{SlaveSet, SurfaceDetection};
use plugsim::fracture::growth::nodal_mass;
use plugsim::fracture::{CrackGrowth, Criterion, EventKind, FractureParameters, TipDirection, TipGate};
use plugsim::geometry::GeometryMode;
use plugsim::material::{Elastic, Material};
use plugsim::math::{Block2, Real, Vec2};
use plugsim::model::{BodySetup, Gather, Model};
use plugsim::particles::ParticleFlags;
use plugsim::shape::rk::{is_bounded, row_sums};
use plugsim::shape::{Basis, ShapeTable};
use plugsim::step::{Simulation, TimeStepRule};

const H: Real = 0.5e-3;

fn steel() -> Elastic {
    Elastic { density: 7850.0, youngs_modulus: 200e9, poisson_ratio: 0.3, room_temperature: 293.0, thermal: None }
}

/// A uniform `nx × ny` lattice of spacing `H` on `[0, (nx−1)H] × [0, (ny−1)H]`
/// (stored along a Morton curve: find lattice particle `(i, j)` with [`id`]).
/// Surface particles are contact slaves.
fn plate(nx: usize, ny: usize) -> Model {
    plate_in(GeometryMode::PlaneStrain, nx, ny)
}

/// [`plate`] in either geometry mode (in axisymmetry, x = 0 is the axis).
fn plate_in(mode: GeometryMode, nx: usize, ny: usize) -> Model {
    let grid = common::uniform_lattice(nx, ny, H);
    let body = BodySetup {
        name: "plate".into(),
        grid,
        material: Material::Elastic(steel()),
        initial_velocity: vec![],
        supports: vec![],
    };
    let mut m = Model::build(mode, &[body]).unwrap();
    assert_eq!(m.particles.len(), nx * ny);
    let slaves = SlaveSet::detect(&m.particles.x0, &m.particles.spacing, &SurfaceDetection::default()).unwrap();
    slaves.mark_flags(&mut m.particles.flags).unwrap();
    m
}

/// Index of the lattice particle at `(i H, j H)`.
fn id(m: &Model, i: usize, j: usize) -> usize {
    let x = Vec2::new(i as Real * H, j as Real * H);
    (0..m.particles.len())
        .find(|&k| (m.particles.x0[k] - x).norm() < 1e-9 * H)
        .unwrap_or_else(|| panic!("no particle at lattice ({i}, {j})"))
}

fn params(criterion: Criterion) -> FractureParameters {
    FractureParameters { criterion, ..FractureParameters::default() }
}

fn orient(a: &Vec2, b: &Vec2, x: &Vec2) -> Real {
    let d = b - a;
    (d.x * (x.y - a.y) - d.y * (x.x - a.x)) / d.norm()
}

/// Whether segment `[x, p]` crosses segment `[a, b]` at interior points of
/// both, with both ends clearly (beyond round-off) on opposite sides.
fn strictly_crosses(a: &Vec2, b: &Vec2, x: &Vec2, p: &Vec2) -> bool {
    let tol = 1e-9 * H;
    let (o1, o2) = (orient(a, b, x), orient(a, b, p));
    let (o3, o4) = (orient(x, p, a), orient(x, p, b));
    o1.abs() > tol && o2.abs() > tol && o1 * o2 < 0.0 && o3.abs() > tol && o4.abs() > tol && o3 * o4 < 0.0
}

struct Invariants {
    mass: Real,
    momentum: Vec2,
    /// Mass added by mass scaling (`Particles::added_mass`).
    added: Real,
}

fn snapshot(m: &Model) -> Invariants {
    Invariants {
        mass: m.particles.total_mass(),
        momentum: m.particles.momentum(),
        added: m.particles.added_mass.iter().sum(),
    }
}

/// Mass and momentum unchanged, reproduction at every quadrature point,
/// every row bounded in its values and gradients (Shepard rows aside:
/// `plugsim::shape::rk::MAX_LEBESGUE_SUM`, `MAX_GRADIENT_SUM`), no
/// (evaluation point, particle) pair of either table across a crack, and
/// the force gather equal to the transpose of the table.
fn check_invariants(m: &Model, growth: &CrackGrowth, before: &Invariants, what: &str) {
    let p = &m.particles;
    let mass = p.total_mass();
    assert!((mass - before.mass).abs() <= 1e-12 * before.mass, "{what}: mass {mass} vs {}", before.mass);
    let vmax = p.v.iter().map(|v| v.norm()).fold(0.0, Real::max).max(1.0);
    let dp = (p.momentum() - before.momentum).norm();
    assert!(dp <= 1e-12 * before.mass * vmax, "{what}: momentum changed by {dp:e}");
    // Mass scaling's added mass stays on the particles through the
    // split and the re-lumping, and is part of their mass.
    let added: Real = p.added_mass.iter().sum();
    assert!((added - before.added).abs() <= 1e-12 * before.mass, "{what}: added mass {added} vs {}", before.added);
    assert!((0..p.len()).all(|i| p.added_mass[i] >= 0.0 && p.mass[i] > p.added_mass[i]), "{what}: added mass");
    eprintln!(
        "{what}: relative mass error {:.2e}, momentum error {:.2e} (of M v_max)",
        (mass - before.mass).abs() / before.mass,
        dp / (before.mass * vmax)
    );
    let t = &m.qp_shape;
    for q in 0..t.rows() {
        let (mut s, mut sx, mut g, mut gx) = (0.0, Vec2::zeros(), Vec2::zeros(), nalgebra::Matrix2::<Real>::zeros());
        for k in t.range(q) {
            let i = t.index[k] as usize;
            s += t.value[k];
            sx += p.x0[i] * t.value[k];
            g += t.grad[k];
            gx += p.x0[i] * t.grad[k].transpose();
        }
        let x = m.quad.x0[q];
        assert!((s - 1.0).abs() < 1e-9, "{what}: partition of unity at qp {q}: {s}");
        assert!(g.norm() < 1e-6 / H, "{what}: gradient sum at qp {q}: {g:?}");
        if growth.reduced_quadrature_rows.get(&q) == Some(&Basis::Constant) {
            continue; // no full neighbourhood: partition of unity only
        }
        let row: Vec<_> = t.range(q).map(|k| (t.index[k], t.value[k], t.grad[k])).collect();
        assert!(
            is_bounded(&row, &p.support),
            "{what}: row {q} unbounded: (Lebesgue sum, gradient sum) {:?}",
            row_sums(&row, &p.support)
        );
        assert!((sx - x).norm() < 1e-9 * H, "{what}: linear reproduction at qp {q}");
        assert!((gx - nalgebra::Matrix2::identity()).norm() < 1e-7, "{what}: gradient reproduction at qp {q}");
    }
    let segs: Vec<(Vec2, Vec2)> = growth
        .cracks
        .iter()
        .flat_map(|c| c.vertices.windows(2).map(|w| (w[0].x0, w[1].x0)).collect::<Vec<_>>())
        .collect();
    let crossing = |table: &ShapeTable, points: &[Vec2], label: &str| {
        for (r, point) in points.iter().enumerate().take(table.rows()) {
            for k in table.range(r) {
                let i = table.index[k] as usize;
                for (a, b) in &segs {
                    assert!(
                        !strictly_crosses(a, b, point, &p.x0[i]),
                        "{what}: {label} row {r} uses particle {i} across crack segment {a:?}-{b:?}"
                    );
                }
            }
        }
    };
    crossing(&m.qp_shape, &m.quad.x0, "quadrature");
    crossing(&m.particle_shape, &p.x0, "particle");
    assert_eq!(m.particle_shape.rows(), p.len());
    // The gather patched after each split is the transpose of the table.
    assert!(m.gather == Gather::new(&m.qp_shape, p.len()), "{what}: patched gather differs from a fresh one");
}

/// Drive growth with a prescribed criterion field; check the invariants
/// after every stage that changed something. Returns the growth state.
fn drive(m: &mut Model, g: &mut CrackGrowth, calls: usize) {
    for step in 1..=calls as u64 {
        let before = snapshot(m);
        let n_events = g.events.len();
        g.grow(m, step as Real * 1e-8, step).unwrap();
        if g.events.len() > n_events {
            check_invariants(m, g, &before, &format!("step {step}"));
        }
    }
}

fn set_field(m: &mut Model, f: impl Fn(&Vec2) -> Real) {
    for q in 0..m.quad.len() {
        m.quad.eps_p[q] = f(&m.quad.x0[q]);
    }
}

fn non_uniform_velocity(m: &mut Model) {
    for i in 0..m.particles.len() {
        let x = m.particles.x0[i];
        m.particles.v[i] = Vec2::new(10.0 + 3.0e4 * x.y - 1.0e4 * x.x, -5.0 + 2.0e4 * x.x);
    }
}

/// Rows of the plate of [`oblique_band`].
const BAND_ROWS: usize = 9;
/// Where the band meets the top face, m.
const BAND_TOP_X: Real = 10.0 * H;

/// A 25 × 9 plate moving non-uniformly, `prepare`d, with an oblique band
/// (slope 0.4) of effective strain through the thickness from
/// `BAND_TOP_X`, grown for 30 steps with the invariants checked at every
/// split (`drive`).
fn oblique_band(prepare: impl FnOnce(&mut Model)) -> (Model, CrackGrowth) {
    let mut m = plate(25, BAND_ROWS);
    non_uniform_velocity(&mut m);
    prepare(&mut m);
    let top = (BAND_ROWS - 1) as Real * H;
    set_field(&mut m, |x| 0.6 * (-((x.x - BAND_TOP_X - 0.4 * (top - x.y)) / H).powi(2)).exp());
    let mut g = CrackGrowth::new(params(Criterion::EffectiveStrain));
    drive(&mut m, &mut g, 30);
    (m, g)
}

#[test]
fn splits_conserve_mass_and_momentum_and_reproduction() {
    let ny = BAND_ROWS;
    let (m, g) = oblique_band(|_| {});
    assert_eq!(g.cracks.len(), 1, "one crack (the other surface is within the exclusion distance)");
    let c = &g.cracks[0];
    assert!(c.arrested.is_some(), "the crack runs through and arrests: {:?}", g.events);
    let first = c.vertices[0].x0;
    let last_split = c.vertices[c.vertices.len() - 2].x0;
    assert!((first.y - last_split.y).abs() > (ny - 1) as Real * H - 1e-12, "through the thickness");
    assert!(g.events.iter().filter(|e| e.kind == EventKind::Propagate).count() >= 3);
    // every split particle and its sibling carry the crack-face flag and are slaves
    for e in &g.events {
        for &i in &e.particles[..2] {
            let f = m.particles.flags[i];
            assert!(f.has(ParticleFlags::CRACK_FACE) && f.has(ParticleFlags::SLAVE));
        }
    }
}

/// The same crack through particles that carry mass added by mass
/// scaling (half their own again, on every particle left of the band's
/// foot): the splits halve it with the mass and the re-lumping keeps it,
/// so the added total, the mass and the momentum stay
/// (`check_invariants`).
#[test]
fn splits_keep_the_mass_that_mass_scaling_added() {
    let mut added = 0.0;
    let (m, g) = oblique_band(|m| {
        for i in 0..m.particles.len() {
            if m.particles.x0[i].x < BAND_TOP_X + 0.5 * H {
                let dm = 0.5 * m.particles.mass[i];
                m.particles.added_mass[i] = dm;
                m.particles.mass[i] += dm;
                added += dm;
            }
        }
    });
    assert!(g.cracks[0].arrested.is_some(), "the crack runs through: {:?}", g.events);
    let carried = g.events.iter().flat_map(|e| e.particles[..2].to_vec()).filter(|&i| m.particles.added_mass[i] > 0.0);
    assert!(carried.count() >= 2, "some split particle carries added mass");
    let end: Real = m.particles.added_mass.iter().sum();
    assert!((end - added).abs() <= 1e-12 * added, "{end} vs {added}");
}

#[test]
fn tip_damage_summary_takes_min_median_max() {
    use plugsim::fracture::TipValues;
    let odd = TipValues::of(vec![0.3, 0.1, 0.2]).unwrap();
    assert_eq!((odd.min, odd.median, odd.max, odd.count), (0.1, 0.2, 0.3, 3));
    let even = TipValues::of(vec![0.4, 0.1, 0.2, 0.3]).unwrap();
    assert_eq!((even.min, even.median, even.max, even.count), (0.1, 0.25, 0.4, 4));
    assert!(TipValues::of(Vec::new()).is_none());
}

/// Every crack event records the deciding particle's own damage, whatever
/// the criterion: the lumped projection of the points' `D`, exact for a
/// constant field (here 0.37 everywhere while the effective strain decides);
/// with the damage criterion it is the criterion value itself.
#[test]
fn crack_events_record_the_tips_own_damage() {
    let (nx, ny) = (25, 9);
    let top = (ny - 1) as Real * H;
    let xc = 10.0 * H;
    let band = move |x: &Vec2| 0.6 * (-((x.x - xc - 0.4 * (top - x.y)) / H).powi(2)).exp();
    let mut m = plate(nx, ny);
    set_field(&mut m, band);
    m.quad.damage.iter_mut().for_each(|d| *d = 0.37);
    let mut g = CrackGrowth::new(params(Criterion::EffectiveStrain));
    drive(&mut m, &mut g, 30);
    assert!(g.events.len() >= 4, "{:?}", g.events);
    for e in &g.events {
        assert!((e.damage - 0.37).abs() < 1e-12, "{e:?}");
        assert!(e.value >= 0.3, "the effective strain decided: {e:?}");
        assert!(e.hardening.is_nan(), "an elastic body has no flow stress to soften: {e:?}");
    }
    assert_eq!(g.tip_hardening(), None);
    let summary = g.tip_damage().unwrap();
    let grown = g.events.iter().filter(|e| e.kind != EventKind::Arrest).count();
    assert_eq!(summary.count, grown);
    assert!((summary.min - 0.37).abs() < 1e-12 && (summary.max - 0.37).abs() < 1e-12, "{summary:?}");
    // Weldox 460 E at a uniform plastic strain and temperature: every
    // point's adiabatic hardening is the material's at that state (no
    // damage coupling), and so is each tip's lumped value.
    let mut m = plate(nx, ny);
    let weldox = plugsim::material::library::weldox_460e();
    let (eps, temperature) = (0.5, 400.0);
    let expected = weldox.adiabatic_hardening(eps, temperature, 0.0, 0.0);
    assert!(expected > 0.0);
    m.materials[0] = Material::JohnsonCook(weldox);
    for q in 0..m.quad.len() {
        m.quad.damage[q] = 2.0 * band(&m.quad.x0[q]);
        m.quad.eps_p[q] = eps;
        m.quad.temperature[q] = temperature;
    }
    let mut g = CrackGrowth::new(FractureParameters { critical_damage: 0.5, ..params(Criterion::Damage) });
    drive(&mut m, &mut g, 30);
    assert!(g.events.len() >= 4, "{:?}", g.events);
    for e in &g.events {
        assert!((e.damage - e.value).abs() <= 1e-12 * e.value.abs(), "{e:?}");
        assert!((e.hardening - expected).abs() <= 1e-12 * expected, "{e:?} against {expected}");
    }
    let h = g.tip_hardening().unwrap();
    assert_eq!(h.count, g.events.iter().filter(|e| e.kind != EventKind::Arrest).count());
    assert!((h.min - expected).abs() <= 1e-12 * expected && (h.max - expected).abs() <= 1e-12 * expected, "{h:?}");
}

#[test]
fn arrest_at_the_far_surface_without_running_along_it() {
    arrest_at_the_far_surface_in(GeometryMode::PlaneStrain);
}

/// The mass floor of the local re-lumping is a revolved nodal mass in
/// axisymmetry: it was `ρ ΔV_I` with `ΔV_I` an area, far above the row-sum
/// masses near the axis, and taking the excess from the neighbours left
/// negative masses (the Borvik axisymmetric run failed in contact with a
/// negative mass). The nodal mass is within a factor two of the row sums on
/// the lattice, on the axis too, and the 45-degree arrival of the plane-strain test keeps
/// every mass positive and the total exact.
#[test]
fn mass_floor_is_revolved_in_axisymmetry() {
    let m = plate_in(GeometryMode::Axisymmetric, 25, 9);
    for i in 0..m.particles.len() {
        let ratio = nodal_mass(&m, i) / m.particles.mass[i];
        // 0.53 to 0.60 on the axis, whose row sum spreads over r < 2h with weight r
        assert!((0.5..1.2).contains(&ratio), "particle {i} at {:?}: nodal / lumped = {ratio}", m.particles.x0[i]);
    }
    arrest_at_the_far_surface_in(GeometryMode::Axisymmetric);
}

fn arrest_at_the_far_surface_in(mode: GeometryMode) {
    let (nx, ny) = (25, 9);
    let mut m = plate_in(mode, nx, ny);
    let top = (ny - 1) as Real * H;
    let xc = 4.0 * H;
    // a 45-degree band to the bottom surface, and the whole bottom strip failed
    set_field(&mut m, |x| {
        let band = (-((x.x - xc - (top - x.y)) / (0.7 * H)).powi(2)).exp();
        let strip = if x.y < 1.2 * H { 1.0 } else { 0.0 };
        0.6 * band.max(strip)
    });
    let mut g = CrackGrowth::new(FractureParameters {
        nucleation_distance_factor: 100.0,
        ..params(Criterion::EffectiveStrain)
    });
    // start at the top where the band begins, pointing down the band
    let (i0, j0) = (4, ny - 1);
    let start = [id(&m, i0, j0), id(&m, i0 + 1, j0 - 1)];
    g.insert_crack(&mut m, &start, false).unwrap();
    drive(&mut m, &mut g, 40);
    let c = &g.cracks[0];
    assert!(c.arrested.is_some(), "arrested: {:?}", g.events);
    let n = c.vertices.len();
    let at_surface = c.vertices[n - 2].x0;
    assert!(at_surface.y.abs() < 1e-12, "stopped on the far surface: {at_surface:?}");
    // no vertex before the arrival runs along the bottom
    assert!(c.vertices[..n - 2].iter().all(|v| v.x0.y > 0.5 * H), "ran along the surface: {:?}", c.vertices);
    // the end point is just outside the surface, below the arrival point
    assert!(c.vertices[n - 1].x0.y < 0.0 && c.vertices[n - 1].x0.y > -0.05 * H);
    // and nothing happens to it afterwards
    let events = g.events.len();
    drive(&mut m, &mut g, 5);
    assert!(g.events[events..].iter().all(|e| e.crack != 0));
    assert!(m.particles.mass.iter().all(|&x| x > 0.0), "positive masses");
}

/// One crack per failed zone: a wide zone at the top surface (many slave
/// particles meeting the criterion, far beyond the distance exclusion of
/// each other) nucleates one crack; a second zone, not connected to the
/// first through failed material, nucleates its own.
#[test]
fn one_crack_nucleates_per_failed_zone() {
    let (nx, ny) = (41, 9);
    let top = (ny - 1) as Real * H;
    let run = |zones: &[(Real, Real)]| {
        let mut m = plate(nx, ny);
        // failed (0.6) inside each [x0, x1] in the top three rows, 0.1 elsewhere
        set_field(&mut m, |x| {
            let inside = zones.iter().any(|&(a, b)| x.x >= a * H && x.x <= b * H) && x.y > top - 2.6 * H;
            if inside {
                0.6
            } else {
                0.1
            }
        });
        let mut g = CrackGrowth::new(FractureParameters {
            nucleation_distance_factor: 1.0,
            ..params(Criterion::EffectiveStrain)
        });
        drive(&mut m, &mut g, 3);
        g.cracks.iter().map(|c| c.vertices[0].x0.x / H).collect::<Vec<_>>()
    };
    // one zone 14 spacings wide: one crack (the distance rule alone would allow several)
    let one = run(&[(3.0, 17.0)]);
    assert_eq!(one.len(), 1, "one crack in one zone: {one:?}");
    // two zones with unfailed material between them: one crack each
    let two = run(&[(3.0, 12.0), (26.0, 36.0)]);
    assert_eq!(two.len(), 2, "one crack per zone: {two:?}");
    assert!(two.iter().any(|&x| x < 13.0) && two.iter().any(|&x| x > 25.0), "{two:?}");
}

/// A crack started at the top centre of a 21 × 13 strip failed along its
/// centre column, grown by 16 stages under the Kirchhoff stress
/// `tau(X)` at every point and the gate of `gate` (with `ℓ` = 2
/// spacings): whether it arrested, and where its tip stands (spacings
/// above the bottom; `None` once arrested).
fn gated_tip(tau: impl Fn(&Vec2) -> nalgebra::Matrix3<Real>, gate: FractureParameters) -> (bool, Option<Real>) {
    let (nx, ny) = (21, 13);
    let mut m = plate(nx, ny);
    set_field(&mut m, |x| if (x.x - 10.0 * H).abs() < 0.6 * H { 0.6 } else { 0.1 });
    for q in 0..m.quad.len() {
        m.quad.tau[q] = Block2::block_part(&tau(&m.quad.x0[q]));
    }
    let mut g = CrackGrowth::new(FractureParameters { nonlocal_radius: 2.0 * H, ..gate });
    let start = [id(&m, 10, ny - 1), id(&m, 10, ny - 2)];
    g.insert_crack(&mut m, &start, false).unwrap();
    drive(&mut m, &mut g, 16);
    let tip = g.cracks[0].tip.map(|t| m.particles.x0[t].y / H);
    (g.cracks[0].arrested.is_some(), tip)
}

/// Shear `1e8 Pa` on the in-plane axes plus the mean stress `p`, Pa.
fn shear_plus(p: Real) -> nalgebra::Matrix3<Real> {
    nalgebra::Matrix3::new(0.0, 1e8, 0.0, 1e8, 0.0, 0.0, 0.0, 0.0, 0.0) + nalgebra::Matrix3::identity() * p
}

/// `nonlocal_tip_triaxiality`: the tip's compression gate reads the
/// triaxiality averaged over `ℓ` (ratio of the averaged mean and von
/// Mises stresses). In a uniform stress state the average is the state's
/// own triaxiality, so the gate decides as the particle's would: at
/// `σ_m/σ_eq = −1/2` a tip stops under the default −1/3 and runs through
/// under −0.6. With the lower part of the strip compressed (−1) and the
/// upper in shear (0), the tip stops within `ℓ` of the boundary, as the
/// particle's gate stops it.
#[test]
fn the_tip_gate_over_a_length() {
    let top = 12.0 * H;
    let run = |eta: Real, below_only: bool, gate: Real, nonlocal: bool| {
        // shear 1e8 has σ_eq = √3·1e8: the mean stress for triaxiality `eta`
        let tau = |x: &Vec2| shear_plus(if !below_only || x.y < top - 3.5 * H { eta * 3f64.sqrt() * 1e8 } else { 0.0 });
        let p = FractureParameters {
            tip_min_triaxiality: gate,
            nonlocal_tip_triaxiality: nonlocal,
            ..params(Criterion::EffectiveStrain)
        };
        gated_tip(tau, p)
    };
    let third = -1.0 / 3.0;
    let start = Some(11.0);
    assert_eq!(run(-0.5, false, third, true), (false, start), "uniform -1/2 under -1/3: no step");
    assert!(run(-0.5, false, -0.6, true).0, "uniform -1/2 under -0.6: through");
    let (arrested, own) = run(-1.0, true, third, false);
    assert!(!arrested, "the particle's gate stops it");
    let (arrested, averaged) = run(-1.0, true, third, true);
    assert!(!arrested, "the averaged gate stops it too");
    // the boundary lies at 8.5 spacings; the average reaches ℓ = 2 spacings
    // across it, a candidate lies up to R = 2.5 spacings ahead
    let (own, averaged) = (own.unwrap(), averaged.unwrap());
    for tip in [own, averaged] {
        assert!((8.5 - 2.0..=8.5 + 2.0 + 2.5).contains(&tip), "stopped at {tip} spacings");
    }
}

/// `tip_gate = "tension"`: the tip steps only where the largest principal
/// stress is tensile, the sign of Cockcroft–Latham's `⟨σ₁⟩`, whatever the
/// triaxiality. Shear `τ` under a pressure `p` has `σ₁ = τ − p` and
/// `σ_m/σ_eq = −p/(√3 τ)`: at `p = 0.8 τ` (−0.46, under −1/3) the
/// triaxiality gate stops the tip and the tension gate lets it through; at
/// `p = 1.2 τ` (`σ₁ < 0`, −0.69) both stop it. An in-plane pressure of
/// 3 with a hoop tension of 0.5 (in units of `τ`; −0.52, `σ₁` = 0.5 > 0)
/// passes the tension gate only. The same at the particle's own point and
/// over `ℓ`, as a uniform state's average is the state.
#[test]
fn the_tension_gate_reads_the_largest_principal_stress() {
    let hoop = nalgebra::Matrix3::from_diagonal(&nalgebra::Vector3::new(-3e8, -3e8, 0.5e8));
    for nonlocal in [false, true] {
        let run = |tau: nalgebra::Matrix3<Real>, gate: TipGate| {
            let p = FractureParameters {
                tip_gate: gate,
                nonlocal_tip_triaxiality: nonlocal,
                ..params(Criterion::EffectiveStrain)
            };
            gated_tip(|_| tau, p).0
        };
        for (tau, triaxiality, tension, what) in [
            (shear_plus(-0.8e8), false, true, "shear under 0.8 of its pressure"),
            (shear_plus(-1.2e8), false, false, "shear under 1.2 of its pressure"),
            (hoop, false, true, "in-plane pressure with hoop tension"),
            (shear_plus(0.0), true, true, "pure shear"),
        ] {
            assert_eq!(run(tau, TipGate::Triaxiality), triaxiality, "{what}, triaxiality gate, nonlocal {nonlocal}");
            assert_eq!(run(tau, TipGate::Tension), tension, "{what}, tension gate, nonlocal {nonlocal}");
        }
    }
}

/// `CrackGrowth::tip_candidates` (`plugsim crack-tips`) reports what the
/// growth stage does: on [`gated_tip`]'s strip in pure shear (`σ₁ > 0`
/// everywhere) under the tension gate, the eligible candidate of largest
/// rank is the particle the tip steps to at the next stage, at each of
/// the crack's steps; with the pressure raised to 1.2 τ, every candidate
/// that meets the criterion reads "gate closed" with the gate's reading
/// the state's own `σ₁ = τ − p = −2e7 Pa` (a uniform state's mean), and
/// the tip does not move.
#[test]
fn tip_candidates_report_what_the_growth_stage_does() {
    use plugsim::fracture::CandidateCheck;
    let (nx, ny) = (21, 13);
    let setup = |tau: nalgebra::Matrix3<Real>| {
        let mut m = plate(nx, ny);
        set_field(&mut m, |x| if (x.x - 10.0 * H).abs() < 0.6 * H { 0.6 } else { 0.1 });
        for q in 0..m.quad.len() {
            m.quad.tau[q] = Block2::block_part(&tau);
        }
        let mut g = CrackGrowth::new(FractureParameters {
            nonlocal_radius: 2.0 * H,
            tip_gate: TipGate::Tension,
            crack_speed_fraction: 0.0,
            ..params(Criterion::EffectiveStrain)
        });
        let start = [id(&m, 10, ny - 1), id(&m, 10, ny - 2)];
        g.insert_crack(&mut m, &start, false).unwrap();
        (m, g)
    };
    let best = |rows: &[plugsim::fracture::TipCandidate]| {
        rows.iter()
            .filter(|r| r.check == CandidateCheck::Eligible)
            .max_by(|a, b| a.rank.total_cmp(&b.rank))
            .map(|r| r.particle)
    };
    // open: each predicted step is the step taken
    let (mut m, mut g) = setup(shear_plus(0.0));
    let mut steps = 0;
    for stage in 1..=16u64 {
        let Some(tip) = g.cracks[0].tip else { break };
        let rows = g.tip_candidates(&m, 0).candidates;
        assert!(!rows.is_empty(), "stage {stage}: candidates within reach");
        let predicted = best(&rows);
        g.grow(&mut m, stage as Real * 1e-8, stage).unwrap();
        let after = g.cracks[0].tip;
        if after != Some(tip) && after.is_some() {
            let reached = g.cracks[0].vertices.last().unwrap().x0;
            let predicted = predicted.unwrap_or_else(|| panic!("stage {stage}: a step with no eligible candidate"));
            assert!(
                (m.particles.x0[predicted] - reached).norm() < 1e-9 * H,
                "stage {stage}: stepped to {reached:?}, predicted {:?}",
                m.particles.x0[predicted]
            );
            steps += 1;
        }
    }
    assert!(steps >= 3, "the tip stepped {steps} times");
    // closed: every candidate over the criterion is held by the gate
    let (mut m, mut g) = setup(shear_plus(-1.2e8));
    let tip = g.cracks[0].tip;
    let rows = g.tip_candidates(&m, 0).candidates;
    let over: Vec<_> = rows.iter().filter(|r| r.value >= 0.3).collect();
    assert!(!over.is_empty(), "failed candidates in the fan");
    for r in &over {
        assert_eq!(r.check, CandidateCheck::GateClosed, "{r:?}");
        assert!((r.gate + 2e7).abs() < 1e-6 * 2e7, "the mean sigma_1 {} Pa", r.gate);
    }
    assert_eq!(best(&rows), None);
    drive(&mut m, &mut g, 3);
    assert_eq!(g.cracks[0].tip, tip, "the gate holds the tip");
}

/// The vertices of the one crack grown by `calls` growth stages with
/// `tip_direction`, on a 21 × 21 lattice failed everywhere, most at the
/// top centre (one core there), after `prepare` has set its stress or
/// velocity.
fn steered_path(tip_direction: TipDirection, calls: usize, prepare: impl Fn(&mut Model)) -> Vec<Vec2> {
    let mut m = plate(21, 21);
    set_field(&mut m, |x| 0.5 + 1e-3 * (x.y / H) - 1e-3 * ((x.x - 10.0 * H).abs() / H));
    prepare(&mut m);
    let mut g = CrackGrowth::new(FractureParameters { tip_direction, ..params(Criterion::EffectiveStrain) });
    drive(&mut m, &mut g, calls);
    assert_eq!(g.cracks.len(), 1, "one crack");
    g.cracks[0].vertices.iter().map(|v| v.x0).collect()
}

/// The top centre of [`steered_path`]'s lattice, where its crack nucleates.
const TOP_CENTRE: Vec2 = Vec2::new(10.0 * H, 20.0 * H);

/// `vertices` start at the top centre and lie on the lattice line through
/// it along `step`, each ahead of the start (`what` names the case).
fn assert_on_line(vertices: &[Vec2], step: Vec2, what: &str) {
    assert!(vertices.len() >= 5, "{what}: {} vertices", vertices.len());
    let start = vertices[0];
    assert!((start - TOP_CENTRE).norm() < 1e-9 * H, "{what}: nucleated at {start:?}");
    for (k, x) in vertices.iter().enumerate() {
        // on the line, one lattice step `step` (or a multiple along it) per vertex
        let r = (x - start) / H;
        let off_line = (r.x * step.y - r.y * step.x).abs() / step.norm();
        assert!(off_line < 1e-9, "{what}: vertex {k} at {r:?} spacings off the line {step:?}");
        assert!(r.dot(&step) >= 0.0, "{what}: vertex {k} behind the start");
    }
}

/// `tip_direction = "max_shear"`: in a plate failed everywhere (every
/// candidate meets the criterion, so only the direction rule decides),
/// under pure shear stress `τ_xy` the current slip lines are x and y; the
/// crack from the top face follows the one nearer its inward normal,
/// pulled back to the reference configuration. Undeformed, that is
/// straight down; after a simple shear `x += γ y` with γ = 1/2, the
/// material line now vertical is `(−γ, 1)` in the reference lattice: the
/// crack runs along the lattice direction `(1, −2)` (exactly its pull-back,
/// `geometry::max_shear_direction`, tested against closed forms there).
#[test]
fn crack_follows_the_slip_line_pulled_back() {
    for (gamma, step) in [(0.0, Vec2::new(0.0, -1.0)), (0.5, Vec2::new(1.0, -2.0))] {
        let vertices = steered_path(TipDirection::MaxShear, 6, |m| {
            for q in 0..m.quad.len() {
                m.quad.tau[q] = Block2 { xx: 0.0, xy: 1e8, yx: 1e8, yy: 0.0, zz: 0.0 };
                m.quad.f[q] = Block2 { xx: 1.0, xy: gamma, yx: 0.0, yy: 1.0, zz: 1.0 };
            }
        });
        assert_on_line(&vertices, step, &format!("γ = {gamma}"));
    }
}

/// `tip_direction = "velocity_jump"` reads the velocity field, not the
/// stress: under a stress whose slip lines are x and y, a band sliding
/// with the normal `n` (a shear flow `v = a (n·(X − X_c))`, `a ⊥ n`,
/// whose RK gradient is `a ⊗ n` exactly) takes the crack along the
/// lattice direction normal to `n`, `(0, −1)` for `n = x`, `(1, −2)` for
/// `n = (2, 1)/√5`, whichever way it slides;
/// `geometry::velocity_jump_direction` is tested against closed forms.
#[test]
fn crack_follows_the_velocity_jump() {
    let inclined = Vec2::new(2.0, 1.0) / 5f64.sqrt();
    let along = Vec2::new(1.0, -2.0) / 5f64.sqrt();
    for (n, a, step) in [
        (Vec2::new(1.0, 0.0), Vec2::new(0.0, -1.0), Vec2::new(0.0, -1.0)),
        (Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(0.0, -1.0)),
        (inclined, along, Vec2::new(1.0, -2.0)),
        (inclined, -along, Vec2::new(1.0, -2.0)),
    ] {
        let vertices = steered_path(TipDirection::VelocityJump, 6, |m| {
            for q in 0..m.quad.len() {
                m.quad.tau[q] = Block2 { xx: 0.0, xy: 1e8, yx: 1e8, yy: 0.0, zz: 0.0 };
            }
            for i in 0..m.particles.len() {
                m.particles.v[i] = a * (n.dot(&(m.particles.x0[i] - TOP_CENTRE)) / H);
            }
        });
        assert_on_line(&vertices, step, &format!("n = {n:?}, a = {a:?}"));
    }
}

/// `"velocity_jump"` heads for the band's centre line, not only along
/// it: a crack nucleated two spacings beside a sliding band (a plug's
/// velocity ramped to rest over two spacings, `v_y` linear in `x` there)
/// turns over to the band's centre column within `ℓ` and runs down it,
/// where the direction alone would have run straight down beside it
/// (`geometry::band_aim`).
#[test]
fn crack_heads_for_the_sliding_band() {
    let band = TOP_CENTRE.x + 2.0 * H;
    let vertices = steered_path(TipDirection::VelocityJump, 10, |m| {
        for i in 0..m.particles.len() {
            let s = ((band + H - m.particles.x0[i].x) / (2.0 * H)).clamp(0.0, 1.0);
            m.particles.v[i] = Vec2::new(0.0, -100.0 * s);
        }
    });
    let xs: Vec<Real> = vertices.iter().map(|v| (v.x - TOP_CENTRE.x) / H).collect();
    assert!(xs.len() >= 8, "{xs:?}");
    assert!(xs[0].abs() < 1e-9, "nucleated at the top centre: {xs:?}");
    assert!(xs.iter().all(|&x| x > -1e-9 && x < 2.0 + 1e-9), "between the start and the band: {xs:?}");
    assert!(xs[xs.len() - 4..].iter().all(|&x| (x - 2.0).abs() < 1e-9), "down the band's centre: {xs:?}");
}

/// The triaxiality cut-off: a failed zone under hydrostatic compression
/// (σ_m/σ_eq = −1) nucleates nothing; the same zone in shear (0) does.
#[test]
fn no_crack_nucleates_in_compression() {
    let (nx, ny) = (21, 9);
    let top = (ny - 1) as Real * H;
    let run = |mean: Real| {
        let mut m = plate(nx, ny);
        set_field(&mut m, |x| if (x.x - 10.0 * H).abs() < 3.1 * H && x.y > top - 2.6 * H { 0.6 } else { 0.1 });
        let shear = nalgebra::Matrix3::new(0.0, 1e8, 0.0, 1e8, 0.0, 0.0, 0.0, 0.0, 0.0);
        for q in 0..m.quad.len() {
            // von Mises of the shear part: sqrt(3) 1e8
            m.quad.tau[q] = Block2::block_part(&(shear + nalgebra::Matrix3::identity() * (mean * 3f64.sqrt() * 1e8)));
        }
        let mut g = CrackGrowth::new(params(Criterion::EffectiveStrain));
        drive(&mut m, &mut g, 2);
        g.cracks.len()
    };
    assert_eq!(run(-1.0), 0, "compression: no crack");
    assert_eq!(run(-0.3), 1, "just above the cut-off: a crack");
    assert_eq!(run(0.0), 1, "shear: a crack");
    // nor does a crack grow into compressed material: a crack down a failed
    // column stops where the column is compressed
    let grow = |mean: Real, gate: Real| {
        let mut m = plate(nx, ny);
        set_field(&mut m, |x| if (x.x - 10.0 * H).abs() < 0.6 * H { 0.6 } else { 0.1 });
        let shear = nalgebra::Matrix3::new(0.0, 1e8, 0.0, 1e8, 0.0, 0.0, 0.0, 0.0, 0.0);
        for q in 0..m.quad.len() {
            let below = m.quad.x0[q].y < top - 3.5 * H;
            let p = if below { mean } else { 0.0 };
            m.quad.tau[q] = Block2::block_part(&(shear + nalgebra::Matrix3::identity() * (p * 3f64.sqrt() * 1e8)));
        }
        let mut g =
            CrackGrowth::new(FractureParameters { tip_min_triaxiality: gate, ..params(Criterion::EffectiveStrain) });
        let start = [id(&m, 10, ny - 1), id(&m, 10, ny - 2)];
        g.insert_crack(&mut m, &start, false).unwrap();
        drive(&mut m, &mut g, 12);
        let tip = g.cracks[0].tip.map(|t| m.particles.x0[t].y / H);
        (g.cracks[0].arrested.is_some(), tip)
    };
    let gate = FractureParameters::default().tip_min_triaxiality;
    assert_eq!(gate, -1.0 / 3.0);
    assert!(grow(0.0, gate).0, "shear all the way: through the strip");
    let (arrested, tip) = grow(-1.0, gate);
    assert!(!arrested && tip.is_some_and(|y| y > (ny - 1) as Real - 4.5), "stops above the compressed part: {tip:?}");
    // the gate lifted (`tip_min_triaxiality` below the column's −1): through
    assert!(grow(-1.0, -1.5).0, "gate at -1.5: through the compressed part");
    assert!(!grow(-1.0, -0.5).0, "gate at -0.5: stops");
}

#[test]
fn shape_function_ahead_of_the_tip_is_cut_in_two() {
    let (nx, ny) = (21, 11);
    let xc = 10;
    // top down the middle column
    let path_of = |m: &Model| -> Vec<usize> { (3..ny).rev().map(|j| id(m, xc, j)).collect() };
    let support_of = |m: &Model, i: usize| -> Vec<usize> {
        (0..m.quad.len()).filter(|&q| m.qp_shape.range(q).any(|k| m.qp_shape.index[k] as usize == i)).collect()
    };
    let x_mid = xc as Real * H;
    // crack down to row 6; particle k = (xc, 5) is just ahead of the tip
    let mut a = plate(nx, ny);
    let mut ga = CrackGrowth::new(params(Criterion::None));
    let path = path_of(&a);
    let (k, k_tip) = (id(&a, xc, 5), id(&a, xc, 6));
    ga.insert_crack(&mut a, &path[..5], false).unwrap();
    assert_eq!(ga.cracks[0].tip, Some(k_tip));
    let before = support_of(&a, k);
    assert!(before.iter().any(|&q| a.quad.x0[q].x < x_mid) && before.iter().any(|&q| a.quad.x0[q].x > x_mid));
    // the crack passes k (two more particles)
    let mut b = plate(nx, ny);
    let mut gb = CrackGrowth::new(params(Criterion::None));
    let inv = snapshot(&b);
    gb.insert_crack(&mut b, &path[..7], false).unwrap();
    check_invariants(&b, &gb, &inv, "crack past k");
    let ev = gb.events.iter().find(|e| e.particles[0] == k).expect("k was split");
    let (kl, kr) = (ev.particles[0], ev.particles[1]);
    let (sl, sr) = (support_of(&b, kl), support_of(&b, kr));
    assert!(!sl.is_empty() && !sr.is_empty());
    // growing downward, the left of the path is +x
    assert!(sl.iter().all(|&q| b.quad.x0[q].x > x_mid), "left child lives on the left");
    assert!(sr.iter().all(|&q| b.quad.x0[q].x < x_mid), "right child lives on the right");
    let covered = before.iter().filter(|q| sl.contains(q) || sr.contains(q)).count();
    assert!(covered as Real >= 0.95 * before.len() as Real, "{covered} of {}", before.len());
    // the halves carry the parent's volume
    assert!((b.particles.volume[kl] + b.particles.volume[kr] - a.particles.volume[k]).abs() < 1e-15);
}

/// An edge crack halfway across a plate pulled apart: the normal stress at
/// the quadrature points next to the faces drops to a small fraction of
/// that in the uncracked plate, which carries the load there.
#[test]
fn crack_faces_are_traction_free_under_tension() {
    let (nx, ny) = (21, 21);
    let v0 = 2.0;
    let run = |cracked: bool| -> (Model, Vec<usize>) {
        let mut m = plate(nx, ny);
        if cracked {
            let mut g = CrackGrowth::new(params(Criterion::None));
            let path: Vec<usize> = (0..=10).map(|i| id(&m, i, 10)).collect();
            g.insert_crack(&mut m, &path, false).unwrap();
        }
        for i in 0..m.particles.len() {
            let y = m.particles.x0[i].y;
            if y < 1.5 * H || y > (ny as Real - 2.5) * H {
                m.particles.flags[i].set(ParticleFlags::FIX_Y);
                m.particles.v[i].y = if y < 1.5 * H { -v0 } else { v0 };
            }
        }
        let mut sim = Simulation::new(m, TimeStepRule::Cfl { safety: 0.5 });
        while sim.time < 8e-6 {
            sim.step().unwrap();
        }
        let mid = 10.0 * H;
        let near: Vec<usize> = (0..sim.model.quad.len())
            .filter(|&q| {
                let x = sim.model.quad.x0[q];
                (x.y - mid).abs() < 0.5 * H && x.x < 8.0 * H
            })
            .collect();
        (sim.model, near)
    };
    let sigma_yy = |m: &Model, q: usize| m.quad.tau[q].yy / m.quad.f[q].determinant();
    let (intact, near) = run(false);
    let (cracked, near_c) = run(true);
    assert_eq!(near, near_c);
    let mean = |m: &Model| near.iter().map(|&q| sigma_yy(m, q).abs()).sum::<Real>() / near.len() as Real;
    let (s_intact, s_cracked) = (mean(&intact), mean(&cracked));
    eprintln!("mean |sigma_yy| next to the faces: intact {s_intact:.3e} Pa, cracked {s_cracked:.3e} Pa");
    assert!(s_intact > 50e6, "the intact plate carries the load: {s_intact:e} Pa");
    assert!(s_cracked < 0.15 * s_intact, "faces traction-free: {s_cracked:e} vs {s_intact:e} Pa");
}

fn small_impact(end: Real) -> Simulation {
    let case = Case::from_str_with(common::SMALL_IMPACT, "small", &[format!("time.end={end}")]).unwrap();
    let mut sim = plugsim::run::build_simulation(&case.resolved()).unwrap();
    while sim.time < end {
        sim.step().unwrap();
    }
    sim
}

/// Cracks nucleate at the projectile's corners (x = ±4 mm on the impact
/// face) by themselves and run into the plate.
#[test]
fn end_to_end_cracks_start_at_the_projectile_corners() {
    let sim = small_impact(12e-6);
    let g = sim.cracks.as_ref().unwrap();
    assert!(g.cracks.len() >= 2, "two cracks: {:?}", g.events);
    let mut sides = [false, false];
    for c in &g.cracks {
        let p0 = c.vertices[0].x0;
        assert!((p0.y - 0.004).abs() < 1e-9, "nucleated on the impact face: {p0:?}");
        assert!((p0.x.abs() - 0.004).abs() < 1.5e-3, "at a corner: {p0:?}");
        sides[(p0.x > 0.0) as usize] = true;
        assert!(c.vertices.len() >= 3, "propagated: {:?}", c.vertices);
    }
    assert!(sides[0] && sides[1]);
    let slaves = sim.contact.as_ref().unwrap().slaves.particles().to_vec();
    for e in &g.events {
        for &i in &e.particles[..2] {
            assert!(slaves.binary_search(&(i as u32)).is_ok(), "crack face {i} is a contact slave");
        }
    }
}

/// The axis of an axisymmetric section is an edge of the lattice (its
/// particles are surface and slave) but no surface of the body: a failed
/// band along the axis, clear of the faces, nucleates nothing.
#[test]
fn no_crack_nucleates_on_the_axis() {
    let mut m = plate_in(GeometryMode::Axisymmetric, 25, 9);
    assert!((0..m.particles.len()).any(|i| {
        let f = m.particles.flags[i];
        f.has(ParticleFlags::ON_AXIS) && f.has(ParticleFlags::SLAVE) && m.particles.x0[i].y > 3.0 * H
    }));
    set_field(&mut m, |x| if x.x < 1.5 * H && x.y > 2.5 * H && x.y < 5.5 * H { 0.6 } else { 0.0 });
    let mut g = CrackGrowth::new(params(Criterion::EffectiveStrain));
    drive(&mut m, &mut g, 5);
    assert!(g.cracks.is_empty(), "cracks: {:?}", g.events);
}

/// With the default model in axisymmetry no ring crack nucleates within
/// the averaging length `ℓ` of the axis (the 48-row 12 mm plate at 300 m/s
/// started one at r = 0.26 mm under the projectile, cut a core along the
/// axis and stopped unstable; docs/validation.md). The same damaged patch
/// beyond `ℓ` nucleates, and with a per-particle criterion the patch near
/// the axis does too ([RL10]'s mode unchanged).
#[test]
fn no_ring_crack_nucleates_within_the_averaging_length_of_the_axis() {
    let top = 8.0 * H;
    let patch =
        |r0: Real| move |x: &Vec2| if x.x >= r0 && x.x <= r0 + 2.0 * H && x.y > top - 2.5 * H { 0.9 } else { 0.0 };
    let patched = |r0: Real| {
        let mut m = plate_in(GeometryMode::Axisymmetric, 25, 9);
        let f = patch(r0);
        for q in 0..m.quad.len() {
            let v = f(&m.quad.x0[q]);
            m.quad.damage[q] = v;
            m.quad.eps_p[q] = v;
        }
        m
    };
    let run = |criterion: Criterion, r0: Real| {
        let mut m = patched(r0);
        let mut g = CrackGrowth::new(params(criterion));
        drive(&mut m, &mut g, 3);
        g
    };
    let l = FractureParameters::default().nonlocal_radius;
    assert_eq!(l, 2.0 * H, "the patch positions below assume l = 2 H");
    let near = run(Criterion::NonlocalDamage, 0.0);
    assert!(near.cracks.iter().all(|c| c.vertices[0].x0.x >= l), "a core inside l: {:?}", near.cracks);
    // Without the rule the particle on the top face at r = H would start
    // one: it meets the criterion with the highest average off the axis.
    let m = patched(0.0);
    let g = CrackGrowth::new(params(Criterion::NonlocalDamage));
    let critical = g.params.critical_value().unwrap();
    let inside = g.criterion_value(&m, id(&m, 1, 8));
    let outside = (2..25).map(|i| g.criterion_value(&m, id(&m, i, 8))).fold(0.0, Real::max);
    assert!(inside >= critical && inside > outside, "inside {inside}, outside {outside}, critical {critical}");
    let far = run(Criterion::NonlocalDamage, 6.0 * H);
    assert!(!far.cracks.is_empty(), "the same patch beyond l nucleates");
    assert!(far.cracks.iter().all(|c| c.vertices[0].x0.x >= l), "{:?}", far.cracks);
    let paper = run(Criterion::EffectiveStrain, 0.0);
    assert!(!paper.cracks.is_empty(), "[RL10]'s criteria keep their nucleation");
}

/// The shipped axisymmetric Borvik case, shrunk (30 mm radius, 12 rows):
/// one crack, from the projectile's corner at r = 10 mm on the impact face,
/// running into the plate; none from the axis. The axis particles are
/// flagged surface and slave (an edge of the r-z section) and, before they
/// were excluded from nucleation, the full case started a crack on the axis
/// near the bottom face at 15 us.
#[test]
fn axisymmetric_crack_starts_at_the_corner_not_on_the_axis() {
    let text = include_str!("../cases/borvik-1-axisymmetric.toml");
    let set: Vec<String> = [
        "bodies.plate.rectangle.x_max=0.03",
        "bodies.plate.rectangle.layers=12",
        "bodies.plate.rectangle.fine_half_width=0.015",
        "bodies.plate.supports.0.region.x_min=0.028",
        "bodies.plate.supports.0.region.x_max=0.03",
        "time.end=20e-6",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let case = Case::from_str_with(text, "borvik-axi", &set).unwrap().resolved();
    let mut sim = plugsim::run::build_simulation(&case).unwrap();
    while sim.time < 20e-6 {
        sim.step().unwrap();
    }
    let h = 0.0111 / 11.0;
    let g = sim.cracks.as_ref().unwrap();
    assert!(!g.cracks.is_empty(), "a crack nucleated");
    for c in &g.cracks {
        let p0 = c.vertices[0].x0;
        assert!((p0.y - 0.0111).abs() < 1e-9, "nucleated on the impact face: {p0:?}");
        assert!((p0.x - 0.01).abs() < 1.5 * h, "at the corner r = 10 mm: {p0:?}");
        assert!(c.vertices.iter().all(|v| v.x0.x > 0.5 * h), "crack {} reaches the axis: {:?}", c.id, c.vertices);
        assert!(c.vertices.len() >= 4, "propagated: {:?}", c.vertices);
    }
    assert!(sim.model.particles.mass.iter().all(|&m| m > 0.0), "positive masses");
    // a body of revolution cannot move radially (held on the axis)
    let projectile = &sim.contact.as_ref().unwrap().bodies[0];
    assert_eq!(projectile.velocity.x, 0.0);
    assert!(projectile.velocity.y > -298.0, "the projectile slowed: {}", projectile.velocity.y);
}

/// The same case gives the same crack path, bit for bit, on 1 and 2 threads.
#[test]
fn crack_paths_do_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let sim = small_impact(8e-6);
            let g = sim.cracks.unwrap();
            (g.events, g.cracks, sim.model.particles.x0)
        })
    };
    let one = run(1);
    let two = run(2);
    assert!(!one.0.is_empty(), "cracks formed");
    assert_eq!(one.0, two.0);
    assert_eq!(one.1, two.1);
    assert_eq!(one.2, two.2);
}

/// The shipped fracture case parses, validates and asks for the
/// effective-strain criterion at [RL10]'s critical value.
#[test]
fn borvik_plane_strain_case_file_is_valid() {
    let text = include_str!("../cases/borvik-1-plane-strain.toml");
    let case = Case::from_str_with(text, "borvik-1-plane-strain.toml", &[]).unwrap();
    assert_eq!(case.fracture.criterion, Criterion::EffectiveStrain);
    assert_eq!(case.fracture.critical_effective_strain, 0.30);
    assert!(case.time.end >= 60e-6);
    // "none": no cracks
    let plain = include_str!("../cases/borvik-1-nofracture.toml");
    let case = Case::from_str_with(plain, "nofracture", &[]).unwrap();
    assert_eq!(case.fracture.criterion, Criterion::None);
    // no [fracture] section: the default model
    let bare = plain.replace("[fracture]\ncriterion = \"none\"", "");
    let case = Case::from_str_with(&bare, "bare", &[]).unwrap();
    assert_eq!(case.fracture, plugsim::fracture::FractureParameters::default());
    assert_eq!(case.fracture.criterion, Criterion::NonlocalDamage);
}

/// Bad `[fracture]` values are all reported, each with its key.
#[test]
fn fracture_section_is_validated() {
    let text = include_str!("../cases/borvik-1-plane-strain.toml");
    let sets = [
        "fracture.critical_effective_strain=-0.1".to_string(),
        "fracture.fan_angle=200.0".to_string(),
        "fracture.offset_ratio=0.5".to_string(),
        "fracture.radius_factor=0.5".to_string(),
        "fracture.nonlocal_radius=0.0".to_string(),
        "fracture.crack_speed_fraction=1.5".to_string(),
        "fracture.tip_min_triaxiality=0.5".to_string(),
    ];
    let err = Case::from_str_with(text, "f.toml", &sets).unwrap_err().to_string();
    let keys = [
        "critical_effective_strain",
        "fan_angle",
        "offset_ratio",
        "radius_factor",
        "nonlocal_radius",
        "crack_speed_fraction",
        "tip_min_triaxiality",
    ];
    for key in keys {
        assert!(err.contains(&format!("fracture.{key}")), "{key} not reported: {err}");
    }
    let unknown = Case::from_str_with(text, "f.toml", &["fracture.theta=1.0".to_string()]).unwrap_err().to_string();
    assert!(unknown.contains("theta"), "{unknown}");
    let bad =
        Case::from_str_with(text, "f.toml", &["fracture.criterion=\"stress\"".to_string()]).unwrap_err().to_string();
    assert!(bad.contains("stress"), "{bad}");
    let bad =
        Case::from_str_with(text, "f.toml", &["fracture.tip_direction=\"north\"".to_string()]).unwrap_err().to_string();
    assert!(bad.contains("north") && bad.contains("max_shear") && bad.contains("velocity_jump"), "{bad}");
    let slip = Case::from_str_with(text, "f.toml", &["fracture.tip_direction=\"max_shear\"".to_string()]).unwrap();
    assert_eq!(slip.fracture.tip_direction, TipDirection::MaxShear);
    let jump = Case::from_str_with(text, "f.toml", &["fracture.tip_direction=\"velocity_jump\"".to_string()]).unwrap();
    assert_eq!(jump.fracture.tip_direction, TipDirection::VelocityJump);
    // a band wider than the averaging length is refused; the non-local criterion parses
    let wide = ["fracture.criterion=\"nonlocal_damage\"".to_string(), "fracture.band_width=2e-3".to_string()];
    let err = Case::from_str_with(text, "f.toml", &wide).unwrap_err().to_string();
    assert!(err.contains("fracture.band_width"), "{err}");
    let ok = ["fracture.criterion=\"nonlocal_damage\"".to_string(), "fracture.band_width=0.2e-3".to_string()];
    let case = Case::from_str_with(text, "f.toml", &ok).unwrap();
    assert_eq!(case.fracture.criterion, Criterion::NonlocalDamage);
    assert_eq!(case.fracture.band_width, 0.2e-3);
}

/// `time.stop_after_release`: a run that perforates ends once the
/// projectile has been free of force along its flight for that long (and
/// the plug cut out as long), not at `time.end`;
/// without a plug (and not stopped) it runs to the end.
#[test]
fn run_stops_after_the_projectile_is_released() {
    use plugsim::run::{execute, RunConfig, RunInfo};
    let dir = std::env::temp_dir().join(format!("plugsim-release-{}", std::process::id()));
    let wait = 1.0e-6;
    let set =
        ["time.end=4e-5".to_string(), format!("time.stop_after_release={wait}"), "output.interval=1e-5".to_string()];
    let case = Case::from_str_with(common::SMALL_IMPACT, "small", &set).unwrap().resolved();
    let cfg = RunConfig::new(dir.clone(), true, RunInfo::current("test", &[]));
    let s = execute(&case, &cfg, &mut |_| {}).unwrap();
    let perforated = s.perforation.expect("the small plate is perforated");
    let released = match s.flights[0].1 {
        plugsim::residual::Verdict::Perforated { since, .. } => since,
        v => panic!("the projectile flies free after perforating: {v:?}"),
    };
    assert!(s.time < 4e-5, "stopped early: {} s", s.time);
    // the wait counts from the later of perforation and the release (the
    // axial force's vanishing; the history's last loaded row is within a
    // history interval of it)
    let from = released.max(perforated);
    assert!(s.time >= from + wait && s.time <= from + wait + 20.0 * s.dt, "{} {released} {perforated}", s.time);
    // a negative wait is rejected, naming the field
    let bad = Case::from_str_with(common::SMALL_IMPACT, "small", &["time.stop_after_release=-1e-6".to_string()]);
    assert!(bad.is_err_and(|e| e.to_string().contains("time.stop_after_release")));
    std::fs::remove_dir_all(&dir).ok();
}

/// A crack change rebuilds the shape functions next to the path, which
/// changes the RK interpolation of the displacement but does not move the
/// material: the deformation gradient `F` of every quadrature point must not
/// jump (`plugsim::fracture` module doc). Across a sheared band the raw
/// `I + Σ u ∇N` of the new one-sided rows differs from the old by O(1); the
/// jump is carried, so `F` is continuous to round-off, and only points whose
/// rows changed carry one.
#[test]
fn deformation_gradient_is_continuous_across_crack_changes() {
    let (nx, ny) = (25, 9);
    let mut m = plate(nx, ny);
    let top = (ny - 1) as Real * H;
    let xc = 10.0 * H;
    // A vertical shear band of width ~H: the criterion field peaks on it and
    // the displacement shears across it (a non-linear field, up to 2 H of slip).
    set_field(&mut m, |x| 0.6 * (-((x.x - xc) / H).powi(2)).exp());
    for i in 0..m.particles.len() {
        let x = m.particles.x0[i];
        m.particles.u[i] = Vec2::new(0.0, -H * (1.0 + ((x.x - xc) / H).tanh()) * (0.5 + 0.5 * x.y / top));
    }
    // The state after a material update: stored F from the current rows.
    for q in 0..m.quad.len() {
        m.quad.f[q] = Block2::block_part(&m.shape_deformation_gradient(q));
    }
    let mut g = CrackGrowth::new(params(Criterion::EffectiveStrain));
    let mut largest_jump: Real = 0.0;
    for step in 1..=30u64 {
        let before: Vec<_> =
            (0..m.quad.len()).map(|q| m.shape_deformation_gradient(q) + m.quad.f_carry_of(q)).collect();
        let n_events = g.events.len();
        g.grow(&mut m, step as Real * 1e-8, step).unwrap();
        if g.events.len() == n_events {
            continue;
        }
        for (q, f_before) in before.iter().enumerate() {
            let raw = m.shape_deformation_gradient(q);
            let f_after = raw + m.quad.f_carry_of(q);
            assert!(
                (f_after - f_before).norm() < 1e-13,
                "step {step}: F of qp {q} jumped by {:e}",
                (f_after - f_before).norm()
            );
            largest_jump = largest_jump.max((raw - f_before).norm());
        }
    }
    assert!(g.cracks.first().is_some_and(|c| c.arrested.is_some()), "the crack runs through: {:?}", g.events);
    // Without the carry, F would have jumped by this much at a point next to
    // the path: the test exercises a real jump, not round-off.
    eprintln!("largest jump of the raw F at a crack change: {largest_jump:.3e}");
    assert!(largest_jump > 1e-2, "largest raw jump {largest_jump:e}");
    // Points far from the path keep no carry.
    for q in 0..m.quad.len() {
        if (m.quad.x0[q].x - xc).abs() > 6.0 * H {
            assert_eq!(m.quad.f_carry_slot[q], plugsim::quadrature::NO_CARRY, "qp {q} at {:?}", m.quad.x0[q]);
        }
    }
}

/// Erosion of inverted failed points (`plugsim::fracture` module doc): a
/// point that inverts after meeting the crack criterion is eroded — no
/// stress, no force, for good — and the run goes on; a point that inverts
/// without having failed, or any inverted point with `erode_inverted =
/// false`, still stops the run with the inverted-point error.
#[test]
fn inverted_failed_points_are_eroded_and_others_stop_the_run() {
    let (nx, ny) = (11, 11);
    let centre = Vec2::new(5.0 * H, 5.0 * H);
    let setup = |failed_strain: Real, erode: bool| {
        let mut m = plate(nx, ny);
        // The centre particle pushed through its right neighbours: the
        // points of its support invert in the first step.
        let c = id(&m, 5, 5);
        m.particles.u[c].x = 3.0 * H;
        for q in 0..m.quad.len() {
            if (m.quad.x0[q] - centre).norm() < 3.5 * H {
                m.quad.eps_p[q] = failed_strain;
            }
        }
        let mut sim = Simulation::new(m, TimeStepRule::Cfl { safety: 0.5 });
        sim.cracks =
            Some(CrackGrowth::new(FractureParameters { erode_inverted: erode, ..params(Criterion::EffectiveStrain) }));
        sim
    };
    let inverted = |sim: &mut Simulation| match sim.step() {
        Err(plugsim::step::SolverError::Inverted { x, y, .. }) => Vec2::new(x, y),
        other => panic!("expected the inverted-point error, got {other:?}"),
    };
    // Failed (ε̄ = 0.5 ≥ ε_cr = 0.3) and erosion on: the step succeeds.
    let mut sim = setup(0.5, true);
    let momentum = sim.model.particles.momentum();
    sim.step().unwrap();
    let q = &sim.model.quad;
    let eroded: Vec<usize> = (0..q.len()).filter(|&k| q.eroded[k]).collect();
    assert!(!eroded.is_empty(), "some points inverted and were eroded");
    for &k in &eroded {
        assert!((q.x0[k] - centre).norm() < 3.5 * H, "only failed points erode: {k} at {:?}", q.x0[k]);
        assert_eq!(q.tau[k], Block2::zeros());
        assert_eq!(q.pw_block(k), Block2::zeros());
    }
    // Eroded for good; nothing else inverts; the forces stay finite.
    for _ in 0..5 {
        sim.step().unwrap();
    }
    let q = &sim.model.quad;
    assert!(eroded.iter().all(|&k| q.eroded[k] && q.tau[k] == Block2::zeros()));
    assert!(sim.model.particles.f_int.iter().all(|f| f.x.is_finite() && f.y.is_finite()));
    // Erosion removes stress, not mass: the free plate keeps its momentum
    // (internal forces sum to zero with or without the eroded points).
    let dp = (sim.model.particles.momentum() - momentum).norm();
    let scale = sim.model.particles.total_mass() * sim.model.particles.v.iter().map(|v| v.norm()).fold(1.0, Real::max);
    assert!(dp < 1e-9 * scale, "momentum changed by {dp:e}");
    eprintln!("eroded {} of {} points", eroded.len(), q.len());

    // Not failed: the run stops, naming a point next to the centre.
    let x = inverted(&mut setup(0.1, true));
    assert!((x - centre).norm() < 3.5 * H, "{x:?}");
    // Erosion off: the run stops even where the points failed.
    let x = inverted(&mut setup(0.5, false));
    assert!((x - centre).norm() < 3.5 * H, "{x:?}");
}

/// An 11 × 11 plate stretched by `stretch` and dilating at `rate` (1/s)
/// about its centre, every point at damage `damage`, with the damage
/// criterion's cracks growing and `viscosity`, after one step.
fn dilated_plate_after_one_step(stretch: Real, rate: Real, damage: Real, viscosity: BulkViscosity) -> Simulation {
    let centre = Vec2::new(5.0 * H, 5.0 * H);
    let mut m = plate(11, 11);
    for i in 0..m.particles.len() {
        m.particles.u[i] = (m.particles.x0[i] - centre) * stretch;
        m.particles.v[i] = (m.particles.x0[i] - centre) * rate;
    }
    m.quad.damage.fill(damage);
    let mut sim = Simulation::new(m, TimeStepRule::Cfl { safety: 0.5 });
    sim.bulk_viscosity = viscosity;
    sim.cracks = Some(CrackGrowth::new(params(Criterion::Damage)));
    sim.step().unwrap();
    sim
}

/// Fractured points (`D ≥ 1`, cracks growing) that are torn open beyond
/// `TORN_VOLUME_RATIO` (`J ≥ 1.05`) are eroded: their deformation
/// gradient no longer describes a continuum, and its `J` can swing toward
/// zero in one step (`material::TORN_VOLUME_RATIO`). Opened less, or not
/// fractured, they are not.
#[test]
fn torn_fractured_points_are_eroded() {
    let eroded_after_one_step = |stretch: Real, damage: Real| {
        // A uniform dilation, J = (1 + stretch)², at rest.
        let sim = dilated_plate_after_one_step(stretch, 0.0, damage, BulkViscosity::NONE);
        let q = &sim.model.quad;
        let eroded = q.eroded.iter().filter(|&&e| e).count();
        assert!((0..q.len()).filter(|&k| q.eroded[k]).all(|k| q.tau[k] == Block2::zeros()));
        (eroded, q.len())
    };
    assert!(1.03f64.powi(2) >= plugsim::material::TORN_VOLUME_RATIO);
    let (eroded, all) = eroded_after_one_step(0.03, 1.2);
    assert_eq!(eroded, all, "every point torn to J = 1.061 is eroded");
    assert_eq!(eroded_after_one_step(0.02, 1.2).0, 0, "J = 1.040: open, not torn");
    assert_eq!(eroded_after_one_step(0.03, 0.9).0, 0, "not fractured");
}

/// A fractured point carries no tension, viscous or not: in a plate
/// dilating at a uniform rate with the bulk viscosity's linear damper on
/// (which pulls back on any expanding point), points at `D ≥ 1` pass no
/// force, while intact ones carry the damper's tension besides their own.
#[test]
fn fractured_points_carry_no_viscous_tension() {
    let force_stress_after_one_step = |damage: Real, viscosity: BulkViscosity| {
        // expanding at 1e4 1/s from rest, J = 1
        let sim = dilated_plate_after_one_step(0.0, 1.0e4, damage, viscosity);
        let q = &sim.model.quad;
        (0..q.len()).map(|k| q.pw_block(k).trace() / q.weight[k]).fold(Real::NEG_INFINITY, Real::max)
    };
    let damper = BulkViscosity { linear: 0.5, quadratic: 0.0 };
    assert_eq!(force_stress_after_one_step(1.2, damper), 0.0, "fractured: no tension");
    let intact = force_stress_after_one_step(0.5, damper);
    let bare = force_stress_after_one_step(0.5, BulkViscosity::NONE);
    assert!(
        bare > 0.0 && intact > 1.5 * bare,
        "intact points in tension: {intact:e} with the damper, {bare:e} without"
    );
}

/// The crack-tip speed limit of `"nonlocal_damage"` (`fracture::tip_speed`):
/// a column of material failed everywhere (Johnson–Cook damage 5) down a
/// tall plate. Limited to the Rayleigh speed `c_R`, the tip's path after
/// nucleation is at most `c_R (t − t_n)` and trails it by less than one
/// advance (`R`); unlimited (`crack_speed_fraction = 0`, [RL10]'s jump),
/// it advances one particle per stage.
#[test]
fn crack_tip_advances_at_the_prescribed_speed() {
    let (nx, ny) = (11, 41);
    let dt = 4.0e-8;
    let run = |fraction: Real| {
        let mut m = plate(nx, ny);
        for q in 0..m.quad.len() {
            m.quad.damage[q] = if (m.quad.x0[q].x - 5.0 * H).abs() < 0.6 * H { 5.0 } else { 0.0 };
        }
        let p = FractureParameters {
            nonlocal_radius: 0.8 * H,
            crack_speed_fraction: fraction,
            ..params(Criterion::NonlocalDamage)
        };
        let mut g = CrackGrowth::new(p);
        let mut track = Vec::new();
        for step in 1..=400u64 {
            g.grow(&mut m, step as Real * dt, step).unwrap();
            let Some(c) = g.cracks.first() else { continue };
            if c.arrested.is_some() {
                break;
            }
            let v = &c.vertices;
            let path: Real = v.windows(2).skip(1).map(|w| (w[1].x0 - w[0].x0).norm()).sum();
            track.push((step as Real * dt - c.nucleated.0, path, m.particles.x0[c.tip.unwrap()].x));
        }
        (g, track)
    };
    let mat = steel();
    let nu = mat.poisson_ratio;
    let (gm, km) = (mat.youngs_modulus / (2.0 * (1.0 + nu)), mat.youngs_modulus / (3.0 * (1.0 - 2.0 * nu)));
    let c_r = plugsim::fracture::tip_speed::rayleigh_wave_speed(gm, km, mat.density);
    // Viktorov's approximation, within 0.5 %
    let viktorov = (0.862 + 1.14 * nu) / (1.0 + nu) * (gm / mat.density).sqrt();
    assert!((c_r / viktorov - 1.0).abs() < 5e-3, "c_R of steel: {c_r} vs {viktorov}");
    let (g, track) = run(1.0);
    assert_eq!(g.cracks.len(), 1);
    assert!(track.len() > 100, "grew over {} stages", track.len());
    let advances = g.events.iter().filter(|e| e.kind == EventKind::Propagate).count();
    assert!(advances >= 15, "{advances} advances");
    for &(t, path, x) in &track {
        assert!((x - 5.0 * H).abs() < 1e-9, "straight down the failed column: x = {x}");
        assert!(path <= c_r * t + 1e-9 * H, "ahead of c_R t: {path} > {}", c_r * t);
        assert!(path > c_r * t - 2.5 * H, "behind c_R t by more than R: {path} vs {}", c_r * t);
    }
    // unlimited: one particle per stage
    let (g, track) = run(0.0);
    let advances = g.events.iter().filter(|e| e.kind == EventKind::Propagate).count();
    assert!(advances >= 30 && track.len() <= advances + 1, "{advances} advances in {} stages", track.len());
}

/// Two cracks that passed side by side (`CrackGrowth::junction`, found
/// on Case II's plate at 96 rows): a crack from the top ran down column 8,
/// stepped aside to column 7 and on down beside a crack from the bottom
/// surface, whose tip, one spacing below the first's path, is failed but
/// has nowhere to go: straight ahead is the first crack's face, up-left is
/// hidden by it, and up-right lies intact material that has not failed.
/// No intact particle lies between its tip and the first crack's path, so
/// it joins it there, and the two cut out the piece left of them; a rule
/// that joins only where every particle ahead is a face or hidden waits
/// for ever (the up-right particle is intact), and the plug is held by the
/// bridge the passing cracks leave. The tip is compressed, as under the
/// projectile's rim: the gate on a tip's steps does not hold a join. The
/// tip of the first crack, beside the second's path with an intact
/// particle between it and that path, does not join.
#[test]
fn a_tip_beside_another_crack_joins_it_across_no_ligament() {
    let (nx, ny) = (25, 13);
    let mut m = plate(nx, ny);
    non_uniform_velocity(&mut m);
    // failed left of column 8.5 above row 4.5: the second crack's tip
    // meets the criterion, the intact particle up-right of it does not,
    // nor does anything around the first crack's tip
    set_field(&mut m, |x| if x.x < 8.6 * H && x.y > 4.4 * H { 0.6 } else { 0.0 });
    let mut g = CrackGrowth::new(FractureParameters {
        nucleation_distance_factor: 100.0,
        ..params(Criterion::EffectiveStrain)
    });
    let mut top: Vec<(usize, usize)> = (6..ny).rev().map(|j| (8, j)).collect();
    top.extend([(7, 5), (7, 4), (7, 3)]);
    let top: Vec<usize> = top.iter().map(|&(i, j)| id(&m, i, j)).collect();
    g.insert_crack(&mut m, &top, false).unwrap();
    let bottom: Vec<usize> = (0..=5).map(|j| id(&m, 8, j)).collect();
    g.insert_crack(&mut m, &bottom, false).unwrap();
    let tip = id(&m, 8, 5);
    assert_eq!(g.cracks[1].tip, Some(tip));
    let critical = g.params.critical_value().unwrap();
    assert!(g.criterion_value(&m, tip) >= critical, "the second tip has failed");
    assert!(g.criterion_value(&m, id(&m, 9, 6)) < critical, "up-right of it has not");
    // Under the projectile's rim, where this was found, the tip is
    // compressed past the gate on a tip's steps (triaxiality −1.7 here):
    // the join steps into no material and does not ask it.
    for q in 0..m.quad.len() {
        m.quad.tau[q] = Block2 { xx: -3e8, xy: 1e8, yx: 1e8, yy: -3e8, zz: -3e8 };
    }
    assert!(g.triaxiality(&m, tip) < g.params.tip_min_triaxiality, "{}", g.triaxiality(&m, tip));
    assert!(plugsim::plug::plug_particles(&m, &g, 0.0).is_none(), "the bridge between them holds");
    let events = g.events.len();
    drive(&mut m, &mut g, 3);
    let new = &g.events[events..];
    let joins: Vec<_> = new.iter().filter(|e| e.kind == EventKind::Join).collect();
    assert_eq!(joins.len(), 1, "{new:?}");
    assert_eq!(joins[0].crack, 1, "the second crack joins");
    assert!(new.iter().all(|e| e.crack == 1), "the first crack's tip stays: {new:?}");
    let c = &g.cracks[1];
    assert!(c.tip.is_none() && c.arrested.is_some());
    // on the first crack's path, half a diagonal up-left of the tip
    let end = c.vertices.last().unwrap().x0;
    assert!((end - Vec2::new(7.5 * H, 5.5 * H)).norm() < 1e-12, "ends on the first crack's step aside: {end:?}");
    assert_eq!(g.cracks[0].tip, Some(id(&m, 7, 3)), "the first crack grows on, unchanged");
    // the piece left of the two joined paths is cut out
    let plug = plugsim::plug::plug_particles(&m, &g, 0.0).expect("cut out by the two cracks");
    assert!(plug.iter().all(|&i| m.particles.x0[i].x < 8.5 * H), "left of the joined cracks");
    assert!(plug.len() > 80, "{} particles", plug.len());
}

/// Coalescence (`CrackGrowth::junction`): a crack from the top whose tip
/// is one spacing above a second crack's face (from the bottom surface,
/// turned sideways under it) has no candidate — every particle ahead is a
/// face of the other crack or behind it — and is not on an outer surface.
/// Without the join it would wait forever and hold the plug by that
/// bridge (found at 96 rows, docs/validation.md); it ends on the other
/// crack instead, with the split's invariants, and the two cracks cut out
/// the piece between them and the free edge.
#[test]
fn a_tip_that_reaches_another_crack_joins_it() {
    let (nx, ny) = (25, 9);
    // A crack from the bottom surface turned sideways along row 2 (its tip
    // at (10, 2)), and one down column 8 from the top to row `lowest`.
    let two_cracks = |field: &dyn Fn(&Vec2) -> Real, lowest: usize| {
        let mut m = plate(nx, ny);
        non_uniform_velocity(&mut m);
        set_field(&mut m, field);
        let mut g = CrackGrowth::new(FractureParameters {
            nucleation_distance_factor: 100.0,
            ..params(Criterion::EffectiveStrain)
        });
        let bottom: Vec<usize> = [(2, 0), (3, 1), (4, 2), (5, 2), (6, 2), (7, 2), (8, 2), (9, 2), (10, 2)]
            .iter()
            .map(|&(i, j)| id(&m, i, j))
            .collect();
        g.insert_crack(&mut m, &bottom, false).unwrap();
        let top: Vec<usize> = (lowest..ny).rev().map(|j| id(&m, 8, j)).collect();
        g.insert_crack(&mut m, &top, false).unwrap();
        assert_eq!(g.cracks[1].tip, Some(id(&m, 8, lowest)));
        (m, g)
    };
    // failed left of x = 9H, intact to the right (the second crack's tip stays put)
    let (mut m, mut g) = two_cracks(&|x| if x.x < 9.0 * H { 0.6 } else { 0.0 }, 3);
    assert!(plugsim::plug::plug_particles(&m, &g, 0.0).is_none(), "the bridge under the tip holds");
    let events = g.events.len();
    drive(&mut m, &mut g, 3);
    let joins: Vec<_> = g.events[events..].iter().filter(|e| e.kind == EventKind::Join).collect();
    assert_eq!(joins.len(), 1, "{:?}", &g.events[events..]);
    assert_eq!(joins[0].crack, 1);
    let c = &g.cracks[1];
    assert!(c.tip.is_none() && c.arrested.is_some());
    let end = c.vertices.last().unwrap().x0;
    assert!((end - Vec2::new(8.0 * H, 2.0 * H)).norm() < 1e-12, "ends on the other crack's path below: {end:?}");
    assert!(g.cracks[0].tip.is_some(), "the other crack grows on, unchanged");
    // the piece left of the top crack and above the bottom one is cut out
    let plug = plugsim::plug::plug_particles(&m, &g, 0.0).expect("cut out by the two cracks");
    assert!(plug.iter().all(|&i| m.particles.x0[i].x < 8.0 * H), "left of the joined crack");
    assert!(plug.len() > 40, "{} particles", plug.len());
    // A tip with intact material ahead does not join a crack beyond it:
    // the top crack stopped one spacing higher, nothing failed below it
    // (the criterion decides that ligament).
    let (mut m, mut g) = two_cracks(&|x| if x.x < 9.0 * H && x.y > 3.5 * H { 0.6 } else { 0.0 }, 4);
    let events = g.events.len();
    drive(&mut m, &mut g, 3);
    assert!(g.events[events..].iter().all(|e| e.kind != EventKind::Join), "{:?}", &g.events[events..]);
    assert_eq!(g.cracks[1].tip, Some(id(&m, 8, 4)), "waits for the criterion");
}

/// Particle `i`'s share of its material at points not eroded, by hand
/// from the quadrature table's rows (`Σ_live |N_i| w / Σ |N_i| w`, one
/// density), not from the gather the solver reads; 1 where no row holds
/// it.
fn share_by_hand(m: &Model, i: usize) -> Real {
    let (mut live, mut all) = (0.0, 0.0);
    for q in 0..m.quad.len() {
        for k in m.qp_shape.range(q).filter(|&k| m.qp_shape.index[k] as usize == i) {
            let w = m.qp_shape.value[k].abs() * m.quad.weight[q];
            all += w;
            live += if m.quad.eroded[q] { 0.0 } else { w };
        }
    }
    if all > 0.0 {
        live / all
    } else {
        1.0
    }
}

/// A particle that erosion has left (almost) without material is an
/// eroded element's free node (`fracture.detach_below`,
/// `CrackGrowth::detach_isolated`). In a deformed, moving plate the
/// points around its centre are eroded; every particle whose share of
/// material at live points (by hand from the table's rows, `Σ |N| ρ w`)
/// is under 0.1 is detached, and then those that their leaving leaves
/// under 0.1, and no other: each is in no row of
/// either table, so it takes no internal force and no slave's particle
/// row spreads contact force onto it (the two pushes of the 610 m/s
/// throw, `docs/validation.md`), and it keeps its mass
/// and velocity; the total mass and the momentum are kept; every point's
/// deformation gradient (the shape part plus the carried jump) is
/// unchanged, so no stress jumps; its own particle row is itself alone
/// (its displacement is its own). Stepped on, it flies at its velocity.
/// At 0.5 a whole fragment leaves: the points whose particles are all
/// detached are eroded and their rows emptied, instead of a singular row.
/// With `detach_below = 0` nothing is detached.
#[test]
fn isolated_particles_are_detached_and_fly_free() {
    let centre = Vec2::new(5.0 * H, 5.0 * H);
    let setup = |detach_below: Real, eroded_radius: Real| {
        let mut m = plate(11, 11);
        for i in 0..m.particles.len() {
            let x = m.particles.x0[i] - centre;
            m.particles.u[i] = Vec2::new(1e-3 * x.x + 2e-3 * x.y, -0.5e-3 * x.y);
            m.particles.v[i] = Vec2::new(3.0 + 1e3 * x.y, -2.0 + 5e2 * x.x);
        }
        for q in 0..m.quad.len() {
            if (m.quad.x0[q] - centre).norm() < eroded_radius {
                m.quad.eroded[q] = true;
            }
        }
        let cracks = CrackGrowth::new(FractureParameters { detach_below, ..params(Criterion::Damage) });
        (m, cracks)
    };
    let (mut m, mut cracks) = setup(0.1, 2.2 * H);
    let n = m.particles.len();
    let expected: Vec<usize> = (0..n).filter(|&i| share_by_hand(&m, i) < 0.1).collect();
    let middle = (0..n).min_by(|&a, &b| {
        (m.particles.x0[a] - centre).norm().partial_cmp(&(m.particles.x0[b] - centre).norm()).unwrap()
    });
    assert!(expected.contains(&middle.unwrap()), "{expected:?}");
    let (mass0, momentum0) = (m.particles.mass.clone(), m.particles.momentum());
    let f_before: Vec<_> = (0..m.quad.len()).map(|q| m.shape_deformation_gradient(q) + m.quad.f_carry_of(q)).collect();
    let detached = cracks.detach_isolated(&mut m, 0.0).unwrap();
    eprintln!("detached {detached:?} of {n}");
    // First those under 0.1 by hand; then those the first ones' leaving
    // left under it (the rows rebuilt without them give their eroded
    // points to the particles that stay): after the call, every particle
    // still attached has at least 0.1 (by hand again).
    assert_eq!(detached[..expected.len()], expected[..]);
    for i in (0..n).filter(|i| !detached.contains(i)) {
        let share = share_by_hand(&m, i);
        assert!(share >= 0.1, "particle {i} kept with a share of {share}");
    }
    assert_eq!(cracks.detached, detached.iter().map(|&i| (i, 0.0)).collect::<Vec<_>>());
    for &i in &detached {
        assert!(m.particles.flags[i].has(ParticleFlags::DETACHED));
        if expected.contains(&i) {
            // (one detached in a later round keeps the mass the first
            // round's re-lumping gave it)
            assert_eq!(m.particles.mass[i], mass0[i], "a detached particle keeps its mass");
        }
        assert!(!m.qp_shape.index.contains(&(i as u32)));
        // Its own particle row is itself; no other row holds it.
        let ps = &m.particle_shape;
        assert!((0..ps.rows()).all(|r| r == i || !ps.range(r).any(|k| ps.index[k] == i as u32)));
        let own = ps.range(i);
        assert_eq!((own.len(), ps.index[own.start], ps.value[own.start]), (1, i as u32, 1.0));
        assert_eq!(ps.grad[own.start], Vec2::zeros());
    }
    let total: Real = mass0.iter().sum();
    assert!((m.particles.total_mass() - total).abs() < 1e-12 * total);
    let dp = (m.particles.momentum() - momentum0).norm();
    assert!(dp < 1e-12 * momentum0.norm(), "momentum moved by {dp:e}");
    for (q, before) in f_before.iter().enumerate() {
        let after = m.shape_deformation_gradient(q) + m.quad.f_carry_of(q);
        assert!((after - before).norm() < 1e-12, "point {q}: F moved by {:e}", (after - before).norm());
    }
    // No more erosion, no more detaching.
    assert!(cracks.detach_isolated(&mut m, 0.0).unwrap().is_empty());
    // Stepped on: no internal force on the detached particles, which keep
    // their velocity (no contact, no load).
    let v0: Vec<Vec2> = detached.iter().map(|&i| m.particles.v[i]).collect();
    let mut sim = Simulation::new(m, TimeStepRule::Cfl { safety: 0.5 });
    sim.cracks = Some(cracks);
    for _ in 0..5 {
        sim.step().unwrap();
    }
    for (&i, v) in detached.iter().zip(&v0) {
        assert_eq!(sim.model.particles.f_int[i], Vec2::zeros());
        assert!((sim.model.particles.v[i] - v).norm() < 1e-12 * v.norm(), "particle {i}");
    }
    // A fragment: a wider eroded disk at 0.5; where a point's particles
    // are all detached, the point belongs to no body and is eroded, its
    // row empty; every other row keeps a particle.
    let (mut m, mut cracks) = setup(0.5, 3.2 * H);
    let eroded_before = m.quad.eroded.iter().filter(|&&e| e).count();
    let detached = cracks.detach_isolated(&mut m, 0.0).unwrap();
    let orphans: Vec<usize> = (0..m.quad.len()).filter(|&q| m.qp_shape.range(q).is_empty()).collect();
    let eroded_after = m.quad.eroded.iter().filter(|&&e| e).count();
    eprintln!("at 0.5: detached {}, {} points left without particles", detached.len(), orphans.len());
    assert!(!orphans.is_empty() && orphans.iter().all(|&q| m.quad.eroded[q]), "{orphans:?}");
    assert!(eroded_after >= eroded_before && eroded_after - eroded_before <= orphans.len());
    let total = m.particles.total_mass();
    let mass0: Real = plate(11, 11).particles.mass.iter().sum();
    assert!((total - mass0).abs() < 1e-12 * mass0);
    // Off: nothing detached.
    let (mut m, mut cracks) = setup(0.0, 2.2 * H);
    assert!(cracks.detach_isolated(&mut m, 0.0).unwrap().is_empty());
    assert!(m.particles.flags.iter().all(|f| !f.has(ParticleFlags::DETACHED)));
}

/// A split can cut a particle off its live material with no point newly
/// eroded: a crack-face child sees only the points on its own side. In
/// [`oblique_band`]'s plate the points in a strip left of the band are
/// eroded before the crack comes; the particles next to the band keep
/// their share through the live points across it, and the crack then
/// splits them. After every crack stage and `detach_isolated` (as the
/// solver calls them), no attached particle has a share under
/// `detach_below` (the share by hand from the rows), and some particles
/// were detached in stages that eroded nothing: crack-face children the
/// splits cut off, and neighbours whose rows the splits rebuilt (the
/// 480 m/s throw of Case I's 48-row plate, `docs/validation.md`,
/// "Detaching made the default model's").
#[test]
fn a_split_that_cuts_a_particle_off_its_live_material_detaches_it() {
    let threshold = 0.1;
    let mut m = plate(25, BAND_ROWS);
    non_uniform_velocity(&mut m);
    let top = (BAND_ROWS - 1) as Real * H;
    let band = |x: &Vec2| x.x - BAND_TOP_X - 0.4 * (top - x.y);
    set_field(&mut m, |x| 0.6 * (-(band(x) / H).powi(2)).exp());
    for q in 0..m.quad.len() {
        let d = band(&m.quad.x0[q]);
        if (-2.5 * H..-0.2 * H).contains(&d) {
            m.quad.eroded[q] = true;
        }
    }
    let mut g = CrackGrowth::new(FractureParameters { detach_below: threshold, ..params(Criterion::EffectiveStrain) });
    let attached_above = |m: &Model, what: &str| {
        for i in 0..m.particles.len() {
            if !m.particles.flags[i].has(ParticleFlags::DETACHED) {
                let s = share_by_hand(m, i);
                assert!(s >= threshold, "{what}: particle {i} kept with a share of {s}");
            }
        }
    };
    let first = g.detach_isolated(&mut m, 0.0).unwrap();
    attached_above(&m, "before the crack");
    let (mut by_splits, mut splits) = (Vec::new(), 0);
    for step in 1..=30u64 {
        let eroded: usize = m.quad.eroded.iter().filter(|&&e| e).count();
        let events = g.events.len();
        let t = step as Real * 1e-8;
        g.grow(&mut m, t, step).unwrap();
        let detached = g.detach_isolated(&mut m, t).unwrap();
        attached_above(&m, &format!("step {step}"));
        splits += g.events.len() - events;
        // Counted after the growth and the detaching (which erodes a point
        // whose particles all left): a stage that eroded nothing.
        let eroded_after = m.quad.eroded.iter().filter(|&&e| e).count();
        if !detached.is_empty() && eroded_after == eroded {
            by_splits.extend(detached);
        }
    }
    eprintln!(
        "detached {} before the crack, {} by {splits} crack events alone: {by_splits:?}",
        first.len(),
        by_splits.len()
    );
    assert!(splits >= 3, "the crack grows");
    assert!(!by_splits.is_empty(), "some particle is cut off by a split alone");
    assert!(by_splits.iter().any(|&i| m.particles.flags[i].has(ParticleFlags::CRACK_FACE)), "a crack-face child");
}

/// The energy balance books what the crack stage's changes move
/// (`Energies::crack_changes`): a split re-lumps masses and corrects the
/// momentum, which changes the kinetic energy with no work done. In a
/// spinning plate (no load, no contact) with a failed column, cracks
/// nucleate and run; at every step with a crack change the balance's
/// total moves by no more than at the steps without one, while the
/// booked changes are many times that, so without them the balance would
/// jump at each split.
#[test]
fn the_energy_balance_books_the_crack_changes() {
    let (nx, ny) = (11, 21);
    let mut m = plate(nx, ny);
    let centre = Vec2::new(5.0 * H, 10.0 * H);
    let omega = 4000.0;
    for i in 0..m.particles.len() {
        let r = m.particles.x0[i] - centre;
        m.particles.v[i] = Vec2::new(-omega * r.y, omega * r.x);
    }
    for q in 0..m.quad.len() {
        m.quad.damage[q] = if (m.quad.x0[q].x - 5.0 * H).abs() < 0.6 * H { 5.0 } else { 0.0 };
    }
    let mut sim = Simulation::new(m, TimeStepRule::Cfl { safety: 0.5 });
    sim.cracks = Some(CrackGrowth::new(params(Criterion::Damage)));
    let (mut quiet, mut booked_steps) = (Vec::new(), Vec::new());
    for _ in 0..40 {
        let (total, booked, events) =
            (sim.energies.total(), sim.energies.crack_changes, sim.cracks.as_ref().unwrap().events.len());
        sim.step().unwrap();
        let d_total = (sim.energies.total() - total).abs();
        let d_booked = sim.energies.crack_changes - booked;
        if sim.cracks.as_ref().unwrap().events.len() > events {
            booked_steps.push((d_total, d_booked));
        } else {
            assert_eq!(d_booked, 0.0, "booked without a crack change");
            quiet.push(d_total);
        }
    }
    let quiet_max = quiet.iter().cloned().fold(0.0, Real::max);
    let kinetic = sim.energies.initial_kinetic;
    eprintln!("quiet steps: |Δtotal| ≤ {quiet_max:.3e} J of {kinetic:.3e} J; crack steps (|Δtotal|, booked): {booked_steps:?}");
    assert!(booked_steps.len() >= 3 && !quiet.is_empty(), "{} crack steps", booked_steps.len());
    let largest_booked = booked_steps.iter().map(|b| b.1.abs()).fold(0.0, Real::max);
    assert!(largest_booked > 20.0 * quiet_max, "booked {largest_booked:e} against quiet drift {quiet_max:e}");
    for &(d_total, d_booked) in &booked_steps {
        assert!(
            d_total <= 2.0 * quiet_max + 1e-3 * d_booked.abs(),
            "Δtotal {d_total:e} at a crack step booking {d_booked:e}"
        );
    }
}
