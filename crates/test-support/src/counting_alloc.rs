//! A global allocator that counts the allocations made on the current thread while counting is on,
//! for the checks that a per-sample path does not touch the heap.
//!
//! A test binary can have only one global allocator, so each test file that counts installs it
//! itself:
//!
//! ```ignore
//! use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};
//!
//! #[global_allocator]
//! static ALLOCATOR: CountingAllocator = CountingAllocator;
//!
//! assert_eq!(allocations_during(|| per_sample_step()), 0);
//! ```

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};

/// Forwards every call to the system allocator unchanged; while [`allocations_during`] runs on a
/// thread, counts that thread's allocations, zeroed allocations and reallocations.
pub struct CountingAllocator;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

/// Set by the first allocation through [`CountingAllocator`]: without it, a test that forgot to
/// install the allocator would count nothing and pass whatever the code does.
static INSTALLED: AtomicBool = AtomicBool::new(false);

/// Notes one allocation of the current thread. The thread-locals are const-initialised and need
/// no destructor, so touching them never allocates.
fn note_allocation() {
    INSTALLED.store(true, Ordering::Relaxed);
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
    }
}

// SAFETY: forwards every call to the system allocator unchanged; only counts on the side.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note_allocation();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations made on this thread while `f` runs.
///
/// # Panics
///
/// When [`CountingAllocator`] is not the global allocator of this test binary (it would count
/// nothing), or when called from inside `f`.
pub fn allocations_during(f: impl FnOnce()) -> usize {
    // The test harness has allocated long before any test runs: a probe settles it for sure.
    drop(std::hint::black_box(Box::new(0u8)));
    assert!(
        INSTALLED.load(Ordering::Relaxed),
        "CountingAllocator is not the #[global_allocator] of this test binary"
    );
    assert!(
        !COUNTING.with(Cell::get),
        "allocations_during does not nest"
    );
    ALLOCATIONS.with(|a| a.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.with(Cell::get)
}
