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
