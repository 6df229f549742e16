//! No spurious ejection (issue #19 item 5): no particle leaves the plate
//! faster than the impact can throw it.

use plugsim::case::Case;
use plugsim::cases::builtin_case;
use plugsim::run::build_simulation;
use plugsim::step::fastest_particle;

/// The coarse plane-strain Borvik Case I (the README's main case) for its
/// first 6 µs: the cracks nucleate at the projectile's corners at ~2 µs
/// and tear the surface particles beside the corners off the plate.
///
/// Bound: a particle moving *against* the impact (up, +y) is thrown back
/// by the release of the compression the projectile drove in. In one
/// dimension a rigid piston at `v_i` drives the material behind its
/// compressive wave at `v_i`, and the release at a free surface adds at
/// most as much again: `2 v_i` relative to the piston's frame is the
/// free-surface doubling, so no particle moves up faster than `2 v_i`
/// (596 m/s) in the ground frame either. Before opened, fractured points
/// stopped pushing (`plugsim::material::fractured`, `J ≥ 1`) the torn-off
/// corner particles reached 683 m/s upward by 6 µs (700 m/s later, and
/// flew 80 mm above the plate); now ~450 m/s. The run's record of the
/// fastest particle (`Simulation::fastest`, the run summary's and
/// history's `max_particle_speed`) is checked against the same speeds
/// recomputed after every step.
#[test]
fn no_particle_leaves_faster_than_the_rear_face_doubling() {
    let text = builtin_case("borvik-1-plane-strain").expect("built-in case");
    let case = Case::from_str_with(text, "borvik-1-plane-strain", &["time.end=6e-6".to_string()]).unwrap();
    let v_i = 298.0;
    let mut sim = build_simulation(&case).unwrap();
    let (mut up, mut fastest) = (0.0_f64, 0.0_f64);
    while sim.time < 6e-6 {
        sim.step().unwrap();
        let v = sim.model.physical(&sim.model.particles.v);
        up = v.iter().map(|v| v.y).fold(up, f64::max);
        fastest = v.iter().map(|v| v.norm()).fold(fastest, f64::max);
        assert_eq!(fastest_particle(&sim.model).0, v.iter().map(|v| v.norm()).fold(0.0, f64::max));
    }
    assert!(sim.cracks.as_ref().unwrap().cracks.len() >= 2, "the corner cracks nucleated");
    assert!(up > 0.5 * v_i, "the corners throw material up: {up:.0} m/s");
    assert!(up < 2.0 * v_i, "a particle moves up at {up:.0} m/s, above 2 v_i = {:.0} m/s", 2.0 * v_i);
    assert_eq!(sim.fastest.speed, fastest, "the run's record is the largest physical speed of any step");
    let i = sim.fastest.particle;
    assert!(i < sim.model.particles.len() && sim.fastest.time > 0.0 && sim.fastest.time <= sim.time);
}
