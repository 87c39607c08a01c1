//! The per-sample path must not touch the heap, including rejected samples and restarts.

use rins_altimeter::{AltimeterConfig, AltitudeEstimator};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct CountingAlloc;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: delegates to the system allocator; only counts calls on the current thread.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

#[test]
fn update_does_not_allocate() {
    // The counter sees this thread's allocations.
    let probe_before = ALLOCATIONS.with(Cell::get);
    let probe = std::hint::black_box(vec![1u8; 8]);
    assert!(ALLOCATIONS.with(Cell::get) > probe_before);
    drop(probe);

    let mut est = AltitudeEstimator::new(AltimeterConfig::default()).unwrap();
    let before = ALLOCATIONS.with(Cell::get);
    let mut sum = 0.0;
    for k in 0..1000u64 {
        // Good samples, a rejected one and a gap reset.
        let p = if k % 100 == 50 {
            f64::NAN
        } else {
            95_000.0 + (k % 7) as f64
        };
        let t = k * 20_000 + if k > 500 { 5_000_000 } else { 0 };
        sum += est.update(t, p).height_m;
    }
    let after = ALLOCATIONS.with(Cell::get);
    assert!(sum.is_finite());
    assert_eq!(after - before, 0, "allocations in the per-sample path");
}
