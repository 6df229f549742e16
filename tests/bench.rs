//! `plugsim bench`'s workloads measure what they name.

mod common;
use plugsim::bench;

/// The ceiling workload runs every copy through the timed steps: two
/// copies of a small case report a positive, finite rate, and copies that
/// go unstable make the figure an error (naming the instability) instead
/// of a number.
#[test]
fn independent_copies_run_every_copy_and_report_an_unstable_one() {
    let case = common::small_borvik_nofracture(&[]);
    let one = bench::independent_copies(&case, 1, 3).unwrap();
    let two = bench::independent_copies(&case, 2, 3).unwrap();
    assert!(one.value.is_finite() && one.value > 0.0, "{one:?}");
    assert!(two.value.is_finite() && two.value > 0.0, "{two:?}");
    assert!(two.name.contains("2 independent"), "{}", two.name);
    // A fixed step far above the stable one blows up within the timed steps.
    let unstable = common::small_borvik_nofracture(&["time.fixed_dt=1e-5"]);
    let error = bench::independent_copies(&unstable, 2, 200).unwrap_err();
    assert!(matches!(error, plugsim::run::RunError::Unstable { .. }), "{error}");
}

/// The material floor times the sweep as the case is and with the plate
/// made elastic; both figures are positive and finite on a small case, and
/// the elastic twin of a Johnson–Cook material is the same elastic body:
/// below yield both give the same stress for the same step.
#[test]
fn material_floor_times_the_case_and_its_elastic_twin() {
    use plugsim::material::{Constitutive, Material, PointState, StepKinematics};
    use plugsim::math::Tensor3;
    let case = common::small_borvik_nofracture(&[]);
    let figs = bench::material_floor(&case, 1, 1e-6, 3).unwrap();
    assert_eq!(figs.len(), 2);
    for f in &figs {
        assert!(f.value.is_finite() && f.value > 0.0, "{f:?}");
    }
    let jc = plugsim::material::builtin("weldox_460e").unwrap();
    let twin = jc.elastic_twin();
    assert!(matches!(twin, Material::Elastic(_)));
    assert_eq!(
        (twin.density(), twin.bulk_modulus(), twin.shear_modulus()),
        (jc.density(), jc.bulk_modulus(), jc.shear_modulus())
    );
    assert_eq!(twin.thermal(), jc.thermal());
    // Ten small in-plane strain increments from rest: about a quarter of the yield stress.
    let d = Tensor3::new(1.5e3, 0.5e3, 0.0, 0.5e3, -0.5e3, 0.0, 0.0, 0.0, 0.0);
    let w = Tensor3::new(0.0, 2e3, 0.0, -2e3, 0.0, 0.0, 0.0, 0.0, 0.0);
    let k = StepKinematics { d, w, dt: 4e-8 };
    let mut a = PointState::at_rest(jc.initial_temperature());
    let mut b = a;
    for _ in 0..10 {
        a = jc.update(&a, &k);
        b = twin.update(&b, &k);
    }
    let scale = b.tau.norm();
    assert!(scale > 1e6, "the step loads the point: {scale}");
    assert!((a.tau - b.tau).norm() <= 1e-12 * scale, "{} vs {}", a.tau, b.tau);
    assert_eq!(a.eps_p, 0.0);
}

/// The diagnostics workload times the two passes it names, each with its
/// rate and its cost in whole steps: four positive, finite figures in
/// that order.
#[test]
fn diagnostics_time_the_fastest_particle_and_the_coefficient_gap() {
    let case = common::small_borvik_nofracture(&[]);
    let figs = bench::diagnostics(&case, 1, 3).unwrap();
    assert_eq!(figs.len(), 4);
    for f in &figs {
        assert!(f.value.is_finite() && f.value > 0.0, "{f:?}");
    }
    assert!(figs[0].name.starts_with("fastest particle") && figs[2].name.starts_with("coefficient gap"));
    assert_eq!((figs[0].unit, figs[1].unit), ("passes/s", "whole steps"));
}
