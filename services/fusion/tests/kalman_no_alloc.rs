//! The Kalman fuser's per-sample path, including channel changes, must not touch the heap.

use rins_fusion::GeometryConfig;
use rins_fusion::kalman::KalmanFuser;
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
fn update_and_channel_changes_do_not_allocate() {
    let probe_before = ALLOCATIONS.with(Cell::get);
    let probe = std::hint::black_box(vec![1u8; 8]);
    assert!(ALLOCATIONS.with(Cell::get) > probe_before);
    drop(probe);

    let g = GeometryConfig::Dodecahedron {}.build().unwrap();
    let variances = [1e-4; 6];
    let mut kf = KalmanFuser::new(&g, g.full_mask(), &variances, 0.001, 10.0).unwrap();
    let z = [0.1, -0.2, 0.3, 0.05, f64::NAN, 0.2];
    let before = ALLOCATIONS.with(Cell::get);
    let mut sum = 0.0;
    for k in 0..1000u32 {
        let mask = if k % 2 == 0 { 0b101111 } else { 0b101011 };
        kf.set_channels(&g, mask, &variances).unwrap();
        let (x, v) = kf.update(&z);
        sum += x[0] + v[2];
        if k % 100 == 99 {
            kf.reset();
        }
    }
    let after = ALLOCATIONS.with(Cell::get);
    assert!(sum.is_finite());
    assert_eq!(after - before, 0, "allocations in the per-sample path");
}
