//! `Simulator::step` must not touch the heap: counted with an instrumented global allocator, for the
//! largest geometry (16 + 16 channels) in the moving UAV scenario, with faults active.

mod common;

use rins_sim::{ChannelFault, InertialSensor, Scenario, Simulator, TickOutput};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

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
    let allocations = allocations_during(|| {
        for _ in 0..20_000 {
            sim.step(&mut out);
        }
    });
    assert_eq!(allocations, 0);
    assert_eq!(out.truth.imu_seq, 19_999);
}

/// The multirotor scenario too: its attitude solve, blade-phase table and vibration, through the
/// take-off and into the pattern.
#[test]
fn multirotor_step_does_not_allocate() {
    let config = common::config(Scenario::Multirotor);
    let axes = rins_test_support::pyramid::optimal_pyramid_axes();
    let mut sim = Simulator::new(&config, &axes, &axes, 1).unwrap();
    let mut out = TickOutput::default();
    let allocations = allocations_during(|| {
        for _ in 0..40_000 {
            sim.step(&mut out);
        }
    });
    assert_eq!(allocations, 0);
}
