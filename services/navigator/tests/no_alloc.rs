//! The per-sample path after alignment must not touch the heap.

use rins_earth::normal_gravity;
use rins_navigator::{Navigator, NavigatorConfig};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

#[test]
fn navigating_samples_do_not_allocate() {
    let mut config = NavigatorConfig::default();
    config.gnss.enabled = true;
    let g = normal_gravity(0.0, 0.0);
    let mut nav = Navigator::new(config).unwrap();
    let mut t = 0u64;
    let mut aligned = false;
    // Alignment itself is allocation-free too, but only the navigating path is required to be.
    let aligning = allocations_during(|| {
        while !aligned {
            nav.on_mag(t, [20.0, 0.0, 40.0]);
            let _ = nav.on_baro(t, 10.0, 0.04, true);
            aligned = nav.on_imu(t, [0.001, 0.0, 0.0], [0.0, 0.0, -g]).is_some();
            t += 1000;
        }
    });
    assert_eq!(aligning, 0);

    let mut sink = 0.0;
    let navigating = allocations_during(|| {
        for k in 0..5000u64 {
            let time = t + k * 1000;
            if k.is_multiple_of(10) {
                nav.on_mag(time, [20.0, 0.0, 40.0]);
            }
            if k.is_multiple_of(40) {
                let _ = nav.on_baro(time, 10.5, 0.04, k.is_multiple_of(80));
            }
            if k.is_multiple_of(200) && k > 0 {
                let fix = ipc_types::GnssFix {
                    fix_type: ipc_types::GnssFixType::Fix3d as u8,
                    velocity_valid: 1,
                    receiver_time_us: time,
                    altitude_m: 10.0,
                    horizontal_accuracy_m: 1.5,
                    vertical_accuracy_m: 3.0,
                    speed_accuracy_mps: 0.1,
                    ..ipc_types::GnssFix::default()
                };
                let _ = nav.on_gnss(&fix, time - 80_000);
            }
            let out = nav
                .on_imu(
                    time,
                    [0.001, 0.02 * (k as f64 * 0.01).sin(), 0.0],
                    [0.1, 0.0, -g],
                )
                .unwrap();
            sink += out.alt;
        }
        // A glitch and a non-finite sample take the rejection path.
        let _ = nav.on_imu(0, [0.0; 3], [0.0, 0.0, -g]);
        let _ = nav.on_imu(t + 6_000_000, [f64::NAN; 3], [0.0, 0.0, -g]);
    });
    assert_eq!(navigating, 0);
    assert!(sink.is_finite());
    assert!(
        nav.ekf()
            .unwrap()
            .counts(rins_navigator::ekf::AidingSource::Gnss)
            .accepted
            > 0
    );

    // The counter does see allocations, so the zero above means something.
    let boxed = allocations_during(|| {
        std::hint::black_box(Box::new(1u64));
    });
    assert_eq!(boxed, 1);
}

#[test]
fn the_error_state_filter_and_stance_detector_do_not_allocate_per_sample() {
    use rins_navigator::ekf::AidingSource;
    use rins_navigator::inertial_core::{AidedNavigator, ZuptConfig};

    // With the pedestrian profile's gyro lag (the force's delay line) and a gait-adapted threshold.
    let mut config = NavigatorConfig {
        zupt: ZuptConfig {
            enabled: true,
            ..ZuptConfig::default()
        },
        gyro_lag_s: 0.01,
        ..NavigatorConfig::default()
    };
    config.stance.gait_exponent = 0.25;
    let g = normal_gravity(0.0, 0.0);
    let mut nav = AidedNavigator::new(config.aided_config());
    let mut t = 0u64;
    // Alignment and the start of the filter (one boxed filter) happen before counting.
    while nav.ekf().is_none() {
        let _ = nav.on_imu(t, [0.0; 3], [0.0, 0.0, -g], None);
        t += 1000;
    }
    let mut stances = 0;
    let navigating = allocations_during(|| {
        for k in 0..5000u64 {
            // Alternating swing and stance every 0.5 s.
            let swing = (k / 500) % 2 == 1;
            let rate = if swing { [0.0, 2.0, 0.0] } else { [0.0; 3] };
            let step = nav.on_imu(t + k * 1000, rate, [0.0, 0.0, -g], None);
            stances += usize::from(step.stance);
        }
    });
    assert_eq!(navigating, 0);
    assert!(stances > 2000, "{stances}");
    let ekf = nav.ekf().expect("aligned");
    assert!(ekf.counts(AidingSource::Zupt).accepted > 2000);
    let mut ekf = ekf.clone();
    let updates = allocations_during(|| {
        let _ = ekf.height(1.0, 1.0, 5.0);
        let _ = ekf.heading(AidingSource::Mag, 0.1, 0.05, 5.0);
    });
    assert_eq!(updates, 0);
}
