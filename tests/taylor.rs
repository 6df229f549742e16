//! Taylor anvil tests (`src/taylor.rs`): the measurement against exact
//! answers, and the impact face's plastic strain against the interior's.

use plugsim::case::Case;
use plugsim::cases::builtin_case;
use plugsim::math::{Real, Vec2};
use plugsim::run::build_simulation;
use plugsim::taylor::{measure, resolution_overrides, run_test, TAYLOR_TESTS};

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

/// Issue #20: a contact layer must not manufacture plastic work; the peak
/// on the impact face should stay within 10 % of the interior's and of the
/// code-to-code reference (DynELA 1.78, Abaqus 1.81, at the face's centre
/// element). Fails today: at the defaults (variable stable step) the 0.2 mm
/// run gives a face peak of 2.23 at the axis against 2.02 in the interior
/// (2.29 against 2.03 with `time.safety_factor = 0.1`). The cause
/// (docs/validation.md, "Taylor anvil tests"): the face's centre lifts off
/// the wall under the axial tension the converging lateral release leaves
/// on the axis, and its re-impact converges on the axis point, whose
/// plastic strain then grows with refinement (0.94, 1.27, 1.96 at 0.2, 0.1,
/// 0.05 mm, 5 µs) while its deformation converges. Minutes in the test
/// profile: `cargo test --release --test taylor -- --ignored`.
#[test]
#[ignore = "fails: the impact face's centre re-impacts on the axis (issue #20, docs/validation.md)"]
fn impact_face_peak_plastic_strain_stays_near_the_interior() {
    let t = test_named("taylor-42crmo4-287");
    let o = run_test(t, ("medium", 0.2e-3), &[]);
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
