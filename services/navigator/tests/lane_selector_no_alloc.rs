//! The lane selector runs in every consumer for every navigation sample: taking samples of both
//! lanes, delivering them, switching when the delivering lane dies, must not touch the heap.

use ipc_types::{NavMode, NavState, Stage};
use rins_navigator::lanes::{LaneSelector, SelectorConfig};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

fn sample(seq: u64, lane: u8) -> NavState {
    let mut s = NavState {
        mode: NavMode::Navigating as u8,
        solution_start_seq: 1,
        lane,
        ..NavState::default()
    };
    s.header.origin_seq = seq;
    s.header.stamp(Stage::Navigator, seq * 1_000_000);
    s
}

#[test]
fn selecting_and_switching_lanes_does_not_allocate() {
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    let mut selector = LaneSelector::new(SelectorConfig::default());
    let mut delivered = 0u64;
    let mut last = 0u64;
    let allocations = allocations_during(|| {
        for seq in 1..=10_000u64 {
            // Lane 0 dies at sample 5000; lane 1 carries on.
            if seq < 5000 {
                selector.push(0, sample(seq, 0));
            }
            selector.push(1, sample(seq, 1));
            while let Some(s) = selector.pop() {
                delivered += 1;
                last = s.header.origin_seq;
            }
        }
    });
    assert_eq!(allocations, 0, "allocations in the selector");
    assert_eq!(selector.switches(), 1);
    // Every sample up to what the dead lane held back while the switch lag built up.
    assert!(delivered >= 9_990 && last >= 9_990, "{delivered} {last}");
}
