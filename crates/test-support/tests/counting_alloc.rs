//! The counting allocator counts the allocations inside the closure, and only those.

use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

#[test]
fn counts_allocations_and_reallocations_inside_the_closure_only() {
    let outside = std::hint::black_box(vec![1u8; 8]);
    assert_eq!(allocations_during(|| {}), 0);
    let n = allocations_during(|| {
        let mut v = std::hint::black_box(Vec::<u8>::with_capacity(1));
        v.extend_from_slice(&[0; 64]);
        drop(std::hint::black_box(vec![0u8; 16]));
    });
    assert_eq!(n, 3);
    drop(outside);
}
