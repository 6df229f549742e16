//! The time loop does not allocate: scratch is sized up front and reused
//! (STYLE: hot loops don't allocate). A counting global allocator measures
//! allocations over many steps of the Borvik case (contact, Johnson–Cook,
//! heat conduction) after a short warm-up in which scratch reaches its size.

use plugsim::case::Case;

mod common;
use plugsim::run::build_simulation;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn steps_without_cracks_do_not_allocate() {
    let case = common::small_borvik_nofracture(&["heat.every=1"]);
    // Step inside the pool, as a worker: calls from outside would go
    // through rayon's job injector, whose queue allocates a block now and
    // then (rayon's, not ours).
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.install(|| measure(&case));
}

fn measure(case: &Case) {
    let mut sim = build_simulation(case).unwrap();
    assert!(sim.heat.is_some() && sim.contact.is_some());
    for _ in 0..10 {
        sim.step().unwrap();
    }
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    let mut contacts = 0;
    for _ in 0..30 {
        sim.step().unwrap();
        contacts = contacts.max(sim.contact.as_ref().unwrap().sample(0).unwrap().active_contacts);
    }
    let during = ALLOCATIONS.load(Ordering::Relaxed) - before;
    assert!(contacts > 0, "contact must be active during the measurement");
    assert_eq!(during, 0, "{during} allocations in 30 steps");
}
