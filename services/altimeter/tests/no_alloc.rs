//! The per-sample path must not touch the heap, including rejected samples and restarts.

use rins_altimeter::{AltimeterConfig, AltitudeEstimator};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

#[test]
fn update_does_not_allocate() {
    // The counter sees this thread's allocations.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);

    let mut est = AltitudeEstimator::new(AltimeterConfig::default()).unwrap();
    let mut sum = 0.0;
    let allocations = allocations_during(|| {
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
    });
    assert!(sum.is_finite());
    assert_eq!(allocations, 0, "allocations in the per-sample path");
}
