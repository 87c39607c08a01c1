//! The per-sample path must not touch the heap — with faults being detected and reported, the
//! adaptive noise estimate running, and invalid bits toggling on excluded channels, with either
//! fusion method. Only a change of the active set (reconfiguration) may allocate.

use rins_fusion::GeometryConfig;
use rins_fusion::fdi::ParityNoise;
use rins_fusion::kalman::KalmanFuser;
use rins_fusion::{FusionConfig, FusionMethod, ImuFuser, ImuSample};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Deterministic pseudo-noise of a few counts (no RNG allocation concerns, varies every sample).
fn wobble(k: u32, i: u32) -> i16 {
    let h = (k.wrapping_mul(2_654_435_761) ^ i.wrapping_mul(40_503)).rotate_left(7);
    (h % 7) as i16 - 3
}

fn frame(k: u32, gyro_bias: i16) -> ([i16; 4], [i16; 4]) {
    // Moving: the gyro signal swings by ±100 counts, so the vehicle is never stationary.
    let swing = ((f64::from(k) * 0.05).sin() * 100.0) as i16;
    let gyro =
        std::array::from_fn(|i| swing + wobble(k, i as u32) + if i == 1 { gyro_bias } else { 0 });
    let accel = std::array::from_fn(|i| [-150, 140, -150, 140][i] + wobble(k, 10 + i as u32));
    (gyro, accel)
}

#[test]
fn fuse_does_not_allocate() {
    // The counter sees this thread's allocations.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);

    let cases = [
        (ParityNoise::Configured, FusionMethod::Wls),
        (ParityNoise::Adaptive, FusionMethod::Wls),
        (ParityNoise::Configured, FusionMethod::Kalman),
        (ParityNoise::Adaptive, FusionMethod::Kalman),
    ];
    for (mode, method) in cases {
        let mut cfg = FusionConfig::default();
        cfg.fdi.parity_noise = mode;
        cfg.method = method;
        let mut fuser = ImuFuser::new(&cfg, 0.0025566, 0.0383).unwrap();
        // Warm-up (may allocate): accel channel 3 drops out and is excluded for good.
        for k in 0..2000u32 {
            let (g, a) = frame(k, 0);
            let mask = if k == 10 { 0x0007_000F } else { 0x000F_000F };
            fuser.fuse(&g, &a, mask);
        }
        assert_eq!(
            fuser.monitor(ipc_types::SensorType::Accel).active_mask(),
            0b0111
        );

        let mut sum = 0.0;
        let mut flagged = 0;
        let temperatures = [25.0f32, 200.0];
        let allocations = allocations_during(|| {
            for k in 2000..12_000u32 {
                // A gyro bias of 60 counts from k = 5000: detected, not isolated (N = 4, moving).
                let (g, a) = frame(k, if k >= 5000 { 60 } else { 0 });
                let mask = if k % 3 == 0 { 0x000F_000F } else { 0x0007_000F };
                let f = fuser.fuse_sample(&ImuSample {
                    gyro_counts: &g,
                    accel_counts: &a,
                    valid_mask: mask,
                    status: if k % 100 == 0 {
                        ipc_types::status::DEVICE_ERROR
                    } else {
                        0
                    },
                    temperatures_c: &temperatures,
                });
                sum += f.rate[0] + f.specific_force[2] + f.events.len() as f64;
                flagged += usize::from(f.gyro_status.detected_not_isolated);
            }
        });
        assert!(sum.is_finite());
        assert!(
            flagged > 1000,
            "{mode:?}/{method:?}: the fault path was exercised ({flagged})"
        );
        assert_eq!(
            allocations, 0,
            "{mode:?}/{method:?}: allocations in the per-sample path"
        );
    }
}

/// A channel re-admitted by command is tested on every sample of its probation, out of the
/// solution: that must not touch the heap either (only its return at the end reconfigures).
#[test]
fn a_probation_does_not_allocate() {
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    let cfg = FusionConfig::default();
    let samples = cfg.fdi.readmit_probation_samples;
    let mut fuser = ImuFuser::new(&cfg, 0.0025566, 0.0383).unwrap();
    for k in 0..2000u32 {
        let (g, a) = frame(k, 0);
        let mask = if k == 10 { 0x000E_000F } else { 0x000F_000F };
        fuser.fuse(&g, &a, mask);
    }
    let accel = ipc_types::SensorType::Accel;
    assert_eq!(fuser.readmit(accel, 0), Ok(true));
    let mut sum = 0.0;
    let allocations = allocations_during(|| {
        for k in 2000..2000 + samples - 1 {
            let (g, a) = frame(k, 0);
            let f = fuser.fuse(&g, &a, 0x000F_000F);
            sum += f.specific_force[2];
        }
    });
    assert!(sum.is_finite());
    assert!(fuser.monitor(accel).on_probation(0), "the probation ran");
    assert_eq!(allocations, 0, "allocations during the probation");
}

/// The Kalman fuser alone: its update and channel changes must not touch the heap either.
#[test]
fn update_and_channel_changes_do_not_allocate() {
    // The counter sees this thread's allocations.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);

    let g = GeometryConfig::Dodecahedron {}.build().unwrap();
    let variances = [1e-4; 6];
    let mut kf = KalmanFuser::new(&g, g.full_mask(), &variances, 0.001, 10.0).unwrap();
    let z = [0.1, -0.2, 0.3, 0.05, f64::NAN, 0.2];
    let mut sum = 0.0;
    let allocations = allocations_during(|| {
        for k in 0..1000u32 {
            let mask = if k % 2 == 0 { 0b101111 } else { 0b101011 };
            kf.set_channels(&g, mask, &variances).unwrap();
            let (x, v) = kf.update(&z);
            sum += x[0] + v[2];
            if k % 100 == 99 {
                kf.reset();
            }
        }
    });
    assert!(sum.is_finite());
    assert_eq!(allocations, 0, "allocations in the per-sample path");
}
