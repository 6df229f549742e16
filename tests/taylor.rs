//! Taylor anvil tests (`src/taylor.rs`): the measurement against exact
//! answers, and the impact face's plastic strain against the interior's.

use plugsim::case::Case;
use plugsim::cases::builtin_case;
use plugsim::math::{Real, Vec2};
use plugsim::run::build_simulation;
use plugsim::taylor::{measure, resolution_overrides, run_test, Wall, TAYLOR_TESTS};

fn test_named(name: &str) -> &'static plugsim::taylor::TaylorTest {
    TAYLOR_TESTS.iter().find(|t| t.case == name).unwrap()
}

/// RK shape functions reproduce linear fields, so a bar stretched by
/// `u = (a X, b Y)` has the physical length `(1 + b) L₀` and face diameter
/// `(1 + a) D₀` to round-off; the face and interior peaks read the points
/// of the first cell row and those two spacings up.
#[test]
fn measure_reads_length_diameter_and_peaks_of_a_uniformly_stretched_bar() {
    let t = test_named("taylor-4340-343");
    let set = resolution_overrides(t, 0.4e-3);
    let case = Case::from_str_with(builtin_case(t.case).unwrap(), t.case, &set).unwrap().resolved();
    let mut sim = build_simulation(&case).unwrap();
    let (a, b) = (0.2, -0.1);
    let p = &mut sim.model.particles;
    for i in 0..p.len() {
        p.u[i] = Vec2::new(a * p.x0[i].x, b * p.x0[i].y);
    }
    let q = &mut sim.model.quad;
    let h = 8.1e-3 / 20.0;
    let face = (0..q.len()).find(|&k| q.x0[k].y < 0.5 * h).unwrap();
    let interior = (0..q.len()).find(|&k| q.x0[k].y > 3.0 * h).unwrap();
    let between = (0..q.len()).find(|&k| q.x0[k].y > 1.2 * h && q.x0[k].y < 1.8 * h).unwrap();
    (q.eps_p[face], q.eps_p[interior], q.eps_p[between]) = (2.0, 1.0, 3.0);
    q.temperature[interior] = 700.0;
    let m = measure(&sim.model);
    assert!((m.final_length - 0.9 * t.length).abs() < 1e-12 * t.length, "{}", m.final_length);
    assert!((m.face_diameter - 1.2 * t.diameter).abs() < 1e-12 * t.diameter, "{}", m.face_diameter);
    assert_eq!((m.peak_plastic_strain, m.face_peak_plastic_strain, m.interior_peak_plastic_strain), (3.0, 2.0, 1.0));
    assert_eq!(m.peak_temperature, 700.0);
    // The profile starts on the axis at the face and ends at the top of the
    // outer column.
    let (first, last) = (m.profile[0], *m.profile.last().unwrap());
    assert!(first.0.abs() < 1e-15 && first.1.abs() < 1e-15, "{first:?}");
    assert!((last.0 - 1.2 * t.diameter / 2.0).abs() < 1e-12 && (last.1 - 0.9 * t.length).abs() < 1e-12, "{last:?}");
}

/// Issue #20 item 5: the peak plastic strain on the impact face stays
/// within 10 % of the interior's (two spacings and more from the face) and
/// of the code-to-code reference (DynELA 1.78, Abaqus 1.81, at the face's
/// centre element), for `taylor-42crmo4-287` with its face held axially as
/// the reference codes hold it ([`plugsim::taylor::Wall::Restrained`]).
/// Measured at 0.4 mm: face 1.93 against 1.83 in the interior (+5.3 %),
/// +6.6 % against Abaqus. With the contact anvil instead (the case before
/// the wall was held), the face's centre lifts off under the axial tension
/// of the converging lateral release and re-impacts on the axis, and both
/// assertions fail: face 2.10 against 1.91 (+10.4 %), +16 % against
/// Abaqus (0.2 mm: 2.23 against 2.02, +10.3 %, and +23 % against Abaqus;
/// docs/validation.md, "Taylor anvil tests"). At 0.4 mm (seconds); `plugsim validate --family taylor`
/// measures 0.2 and 0.1 mm (1.94 / 1.90 and 1.93 / 1.90).
#[test]
fn impact_face_peak_plastic_strain_stays_near_the_interior() {
    let t = test_named("taylor-42crmo4-287");
    assert_eq!(t.wall, Wall::Restrained);
    let o = run_test(t, ("coarse", 0.4e-3), &[]);
    assert!(o.failure.is_none(), "{:?}", o.failure);
    let m = o.measurement.unwrap();
    let reference: Real = 1.81;
    assert!(m.face_peak_plastic_strain < 1.1 * m.interior_peak_plastic_strain, "{m:?}");
    assert!((m.peak_plastic_strain - reference).abs() < 0.1 * reference, "{m:?}");
}

/// Every shipped Taylor case runs, shortened to 3 µs at 0.4 mm with its own
/// settings: the bar has met the wall, shortened and widened at the face,
/// and the face heated by plastic work.
#[test]
fn every_taylor_case_runs_shortened() {
    for t in TAYLOR_TESTS {
        let o = run_test(t, ("coarse", 0.4e-3), &["time.end=3e-6".to_string()]);
        assert!(o.failure.is_none(), "{}: {:?}", t.case, o.failure);
        let m = o.measurement.unwrap();
        assert!(m.final_length < t.length && m.face_diameter > t.diameter, "{}: {m:?}", t.case);
        assert!(m.face_peak_plastic_strain > 0.0 && m.peak_temperature > 295.0, "{}: {m:?}", t.case);
    }
}

/// In the rod-on-rod case the measured bar is body 0 alone: its mirror
/// image (stretched otherwise here) enters neither length nor peaks.
#[test]
fn measure_reads_the_bar_of_the_rod_on_rod_case_alone() {
    let t = TAYLOR_TESTS.iter().find(|t| t.anvil_twin.is_some()).unwrap();
    let set = resolution_overrides(t, 0.4e-3);
    let case = Case::from_str_with(builtin_case(t.case).unwrap(), t.case, &set).unwrap().resolved();
    let mut sim = build_simulation(&case).unwrap();
    let p = &mut sim.model.particles;
    for i in 0..p.len() {
        let s = if p.body[i] == 0 { -0.1 } else { 0.5 };
        p.u[i] = Vec2::new(0.0, s * p.x0[i].y);
    }
    let q = &mut sim.model.quad;
    let mirror = (0..q.len()).find(|&k| q.body[k] == 1).unwrap();
    q.eps_p[mirror] = 9.0;
    let m = measure(&sim.model);
    assert!((m.final_length - 0.9 * t.length).abs() < 1e-9 * t.length, "{}", m.final_length);
    assert!(m.peak_plastic_strain < 9.0);
}

/// A 42CrMo4 slab in uniaxial strain (plane strain, every particle held
/// across) at 287 m/s onto a rigid, frictionless wall, 0.2 mm particles, to
/// 0.45 µs (the plastic wave, about 4.7 mm/µs, has passed 2 mm; the elastic
/// precursor has not come back from the far end). `wall`: the prescribed
/// anvil met through contact, or the face row held axially.
fn uniaxial_strain_impact(wall: Wall) -> plugsim::step::Simulation {
    let anvil = "[[rigid_bodies]]\nname = \"anvil\"\nrectangle = { center = [0.0, -0.00501], width = 0.04, height = 0.01 }\nprescribed = true\nmass = 1.0\nvelocity = [0.0, 0.0]\n";
    let held =
        "[[bodies.supports]]\nregion = { x_min = 0.0, x_max = 0.0016, y_min = -1.0e-6, y_max = 1.0e-6 }\nfix = \"y\"\n";
    let text = format!(
        r#"
title = "42CrMo4 slab in uniaxial strain on a rigid wall, 287 m/s"
[geometry]
mode = "plane_strain"
[[bodies]]
name = "bar"
material = "steel_42crmo4"
[bodies.rectangle]
x_min = 0.0
x_max = 0.0016
y_min = 0.0
y_max = 0.006
layers = 31
fine_half_width = 0.02
fine_spacing = 0.0002
[[bodies.initial_velocity]]
velocity = [0.0, -287.0]
[[bodies.supports]]
region = {{ x_min = 0.0, x_max = 0.0016, y_min = 0.0, y_max = 0.006 }}
fix = "x"
{}
[fracture]
criterion = "none"
[heat]
conduction = false
[time]
end = 0.45e-6
"#,
        if wall == Wall::Contact { anvil } else { held }
    );
    let case = Case::from_str_with(&text, "uniaxial-strain", &[]).unwrap().resolved();
    let mut sim = build_simulation(&case).unwrap();
    while sim.time < case.time.end * (1.0 - 1e-12) {
        sim.step().unwrap();
    }
    sim
}

/// Issue #20 item 5, the contact layer alone: in uniaxial strain nothing
/// pulls the face off the wall, so contact and a held face must give the
/// same face layer. The independent answer: a point compressed
/// monotonically along one flow direction has, whatever its rate law,
/// `τ̄ + 3G ε̄p = 2G |ln λ|` (λ the axial stretch of `F`, Kirchhoff `τ̄`):
/// the plastic strain its deformation accounts for. Points 1.3–1.6 mm from
/// the face meet it to 1 %. The first rows do not, with either wall: the
/// instantaneous velocity jump of the impact rings behind the front and
/// yields them in reverse, some 0.025 of plastic strain more than the
/// closed form (0.0625 against 0.0395 on the face row with contact, 0.0657
/// against 0.0407 held); this is the impact's start-up, not the contact's,
/// and the contact's face row stays within 10 % of the held one's.
#[test]
fn contact_layer_makes_no_plastic_work_in_uniaxial_strain() {
    let material = plugsim::material::builtin("steel_42crmo4").unwrap();
    let three_g = 3.0 * plugsim::material::Constitutive::shear_modulus(&material);
    let face_row = |wall: Wall| {
        let sim = uniaxial_strain_impact(wall);
        let q = &sim.model.quad;
        let mut face: Real = 0.0;
        for k in 0..q.len() {
            let f = q.f[k];
            assert!(f.xx == 1.0 && f.xy == 0.0 && f.yx.abs() < 1e-8, "point {k}: F {f:?}");
            let y = q.x0[k].y;
            if y < 0.1e-3 {
                face = face.max(q.eps_p[k]);
            } else if (1.3e-3..1.6e-3).contains(&y) {
                let tau = plugsim::math::von_mises(&q.tau[k].to_tensor());
                let closed_form = (2.0 / 3.0 * three_g * f.yy.ln().abs() - tau) / three_g;
                assert!(closed_form > 0.03, "point {k}: behind the plastic wave");
                let e = q.eps_p[k];
                assert!(
                    (e - closed_form).abs() < 0.01 * closed_form,
                    "{wall:?}, point {k} at {y}: {e} vs {closed_form}"
                );
            }
        }
        face
    };
    let (contact, held) = (face_row(Wall::Contact), face_row(Wall::Restrained));
    assert!(held > 0.03 && (contact - held).abs() < 0.1 * held, "face row: contact {contact}, held {held}");
}
