//! `Simulator::step` must not touch the heap: counted with an instrumented global allocator, for the
//! largest geometry (16 + 16 channels) in the moving UAV scenario, with faults active.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use rins_sim::{ChannelFault, InertialSensor, Scenario, Simulator, TickOutput};

struct CountingAllocator;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; only counts on the current thread.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.with(|a| a.set(a.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.with(|a| a.set(a.get() + 1));
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

#[test]
fn step_does_not_allocate() {
    let config = common::config(Scenario::Uav);
    let axes: Vec<[f64; 3]> = (0..16)
        .map(|i| {
            let a = f64::from(i) * 0.7;
            [a.cos(), a.sin(), 0.5 + 0.03 * f64::from(i)]
        })
        .collect();
    let mut sim = Simulator::new(&config, &axes, &axes, 1).unwrap();
    sim.inject_fault(
        InertialSensor::Gyro,
        3,
        ChannelFault::NoiseBurst { sigma: 0.1 },
    )
    .unwrap();
    sim.inject_fault(
        InertialSensor::Accel,
        5,
        ChannelFault::Intermittent {
            period_s: 0.05,
            dropout_s: 0.01,
        },
    )
    .unwrap();
    let mut out = TickOutput::default();
    COUNTING.with(|c| c.set(true));
    for _ in 0..20_000 {
        sim.step(&mut out);
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(ALLOCATIONS.with(Cell::get), 0);
    assert_eq!(out.truth.imu_seq, 19_999);
}
