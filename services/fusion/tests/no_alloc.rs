//! The per-sample path must not touch the heap, including when the valid mask changes.

use rins_fusion::{FusionConfig, ImuFuser};
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
fn fuse_does_not_allocate() {
    // The counter sees this thread's allocations.
    let probe_before = ALLOCATIONS.with(Cell::get);
    let probe = std::hint::black_box(vec![1u8; 8]);
    assert!(ALLOCATIONS.with(Cell::get) > probe_before);
    drop(probe);

    let mut fuser = ImuFuser::new(&FusionConfig::default(), 0.0017, 0.0479).unwrap();
    let gyro = [12i16, -40, 300, 7];
    let accel = [-200i16, 10, 5, 90];
    let before = ALLOCATIONS.with(Cell::get);
    let mut sum = 0.0;
    for k in 0..1000u32 {
        // Cycle through full, reduced and insufficient channel sets.
        let mask = match k % 4 {
            0 => 0x000F_000F,
            1 => 0x000E_0007,
            2 => 0x0003_000D,
            _ => 0x000F_000F,
        };
        let f = fuser.fuse(&gyro, &accel, mask);
        sum += f.rate[0] + f.specific_force[2];
    }
    let after = ALLOCATIONS.with(Cell::get);
    assert!(sum.is_finite());
    assert_eq!(after - before, 0, "allocations in the per-sample path");
}
