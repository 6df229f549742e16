//! Results are bit-identical for any thread count (the force assembly is a
//! gather in fixed order; global sums run in index order).

mod common;
use plugsim::run::build_simulation;
use plugsim::step::Simulation;

fn run_on(threads: usize, steps: usize) -> Simulation {
    // a narrower, coarser plate keeps the test short; physics as the real case
    let case = common::small_borvik_nofracture(&[]);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut sim = build_simulation(&case).unwrap();
        for _ in 0..steps {
            sim.step().unwrap();
        }
        sim
    })
}

fn bits<T: Copy + Into<f64>>(v: impl IntoIterator<Item = T>) -> Vec<u64> {
    v.into_iter().map(|x| x.into().to_bits()).collect()
}

#[test]
fn one_and_two_threads_give_identical_bits() {
    let steps = 120;
    let a = run_on(1, steps);
    let b = run_on(2, steps);
    let (pa, pb) = (&a.model.particles, &b.model.particles);
    let flat = |v: &[plugsim::math::Vec2]| bits(v.iter().flat_map(|x| [x.x, x.y]));
    assert_eq!(flat(&pa.u), flat(&pb.u), "displacements differ");
    assert_eq!(flat(&pa.v), flat(&pb.v), "velocities differ");
    assert_eq!(flat(&pa.f_int), flat(&pb.f_int), "internal forces differ");
    let tens = |v: &[plugsim::math::Block2]| bits(v.iter().flat_map(|t| [t.xx, t.xy, t.yx, t.yy, t.zz]));
    assert_eq!(tens(&a.model.quad.tau), tens(&b.model.quad.tau), "stresses differ");
    assert_eq!(bits(a.model.quad.eps_p.iter().cloned()), bits(b.model.quad.eps_p.iter().cloned()));
    assert_eq!(bits(a.model.quad.temperature.iter().cloned()), bits(b.model.quad.temperature.iter().cloned()));
    let (ca, cb) = (a.contact.as_ref().unwrap(), b.contact.as_ref().unwrap());
    assert_eq!(ca.bodies[0].velocity.y.to_bits(), cb.bodies[0].velocity.y.to_bits());
    assert_eq!(a.energies.total().to_bits(), b.energies.total().to_bits());
    // and the run actually did something: the projectile is in contact and slowed
    assert!(ca.bodies[0].velocity.y > -297.0, "v = {}", ca.bodies[0].velocity.y);
    assert!(a.model.quad.eps_p.iter().cloned().fold(0.0, f64::max) > 0.01, "plastic flow expected");
}
