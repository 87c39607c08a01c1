//! The frame generator: scheduling, sequence numbers, device time, determinism, truth, faults.

mod common;

use proptest::prelude::*;
use rins_protocol::{Frame, FrameType, ImuFrame, Payload};
use rins_sim::sensor_model::baro::isa_pressure_pa;
use rins_sim::{
    ChannelFault, InertialSensor, Scenario, SimConfig, SimError, Simulator, TickOutput,
};
use rins_test_support::pyramid::optimal_pyramid_axes;

fn imu(frame: &Frame) -> ImuFrame {
    match frame.payload {
        Payload::Imu(f) => f,
        other => panic!("expected IMU, got {other:?}"),
    }
}

fn sim(config: &SimConfig, seed: u64) -> Simulator {
    let axes = optimal_pyramid_axes();
    Simulator::new(config, &axes, &axes, seed).unwrap()
}

#[test]
fn frames_are_scheduled_at_their_rates_with_contiguous_sequences() {
    let config = SimConfig::default();
    let mut s = sim(&config, 1);
    let mut out = TickOutput::default();
    let (mut baro, mut mag, mut aux) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..1000u32 {
        s.step(&mut out);
        assert_eq!(out.imu.seq, k as u16);
        assert_eq!(out.imu.device_time_us, k * 1000);
        assert_eq!(out.truth.device_time_us, u64::from(k) * 1000);
        assert_eq!(out.truth.imu_seq, u64::from(k));
        for (slot, list) in [
            (out.frame(FrameType::Baro), &mut baro),
            (out.frame(FrameType::Mag), &mut mag),
            (out.frame(FrameType::Aux), &mut aux),
        ] {
            if let Some(f) = slot {
                assert_eq!(f.device_time_us, out.imu.device_time_us);
                list.push((k, f.seq));
            }
        }
    }
    assert_eq!(baro.len(), 50);
    assert_eq!(mag.len(), 100);
    assert_eq!(aux.len(), 100);
    for (i, (k, seq)) in baro.iter().enumerate() {
        assert_eq!((*k, *seq), (20 * i as u32, i as u16));
    }
    for (i, (k, seq)) in mag.iter().chain(aux.iter()).enumerate() {
        assert_eq!((*k, *seq), (10 * (i % 100) as u32, (i % 100) as u16));
    }
    assert!(out.frame(FrameType::Baro).is_none() && (s.time_s() - 1.0).abs() < 1e-12);
}

#[test]
fn the_first_tick_carries_every_fitted_sensor_in_frame_type_order() {
    let mut config = SimConfig::default();
    config.airspeed.enabled = true;
    let mut s = sim(&config, 1);
    let mut out = TickOutput::default();
    s.step(&mut out);
    // Every rate falls due on tick 0: one frame of each type, each first of its sequence.
    let frames = out.frames();
    for (t, frame) in FrameType::ALL.into_iter().zip(frames) {
        let frame = frame.unwrap_or_else(|| panic!("no {t:?} frame on tick 0"));
        assert_eq!(frame.payload.frame_type(), t);
        assert_eq!((frame.seq, frame.device_time_us), (0, 0));
        assert_eq!(out.frame(t), Some(frame));
    }
    // Off, the airspeed sensor leaves its place empty, even in an output that held its frame.
    let mut s = sim(&SimConfig::default(), 1);
    s.step(&mut out);
    assert_eq!(out.frame(FrameType::Airspeed), None);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    /// Over n ticks a stream of rate r (≤ IMU rate R) emits ⌊(n−1)·r/R⌋ + 1 frames: no drift, any ratio.
    #[test]
    fn frame_count_follows_rate_ratio(imu_rate in 100u32..4000, baro_frac in 0.01f64..1.0, n in 1usize..3000) {
        let baro_rate = (f64::from(imu_rate) * baro_frac).max(0.5);
        let config = SimConfig {
            imu_rate_hz: f64::from(imu_rate),
            baro_rate_hz: baro_rate,
            mag_rate_hz: f64::from(imu_rate),
            aux_rate_hz: 1.0,
            ..SimConfig::default()
        };
        let mut s = sim(&config, 2);
        let mut out = TickOutput::default();
        let (mut baro, mut mag) = (0usize, 0usize);
        for _ in 0..n {
            s.step(&mut out);
            baro += usize::from(out.frame(FrameType::Baro).is_some());
            mag += usize::from(out.frame(FrameType::Mag).is_some());
        }
        let expected = (((n - 1) as f64) * baro_rate / f64::from(imu_rate)).floor() as usize + 1;
        prop_assert_eq!(baro, expected);
        prop_assert_eq!(mag, n);
    }
}

#[test]
fn imu_sequence_wraps_at_16_bits() {
    let mut s = sim(&SimConfig::default(), 1);
    let mut out = TickOutput::default();
    for _ in 0..65_536 {
        s.step(&mut out);
    }
    assert_eq!(out.imu.seq, 65_535);
    s.step(&mut out);
    assert_eq!(out.imu.seq, 0);
    assert_eq!(out.truth.imu_seq, 65_536);
    assert_eq!(out.imu.device_time_us, 65_536_000);
}

#[test]
fn same_seed_gives_identical_frames_and_different_seeds_differ() {
    let config = common::config(Scenario::Uav);
    let (mut a, mut b, mut c) = (sim(&config, 42), sim(&config, 42), sim(&config, 43));
    let (mut oa, mut ob, mut oc) = (
        TickOutput::default(),
        TickOutput::default(),
        TickOutput::default(),
    );
    let mut differing = 0;
    for _ in 0..3000 {
        a.step(&mut oa);
        b.step(&mut ob);
        c.step(&mut oc);
        assert_eq!(oa, ob);
        assert_eq!(oa.truth, oc.truth, "truth does not depend on the seed");
        differing += usize::from(oa.imu != oc.imu);
    }
    // Noise is several counts per sample, so practically every frame differs.
    assert!(differing > 2900, "only {differing} frames differ");
}

#[test]
fn truth_sample_matches_trajectory_and_baro_follows_true_altitude() {
    let config = SimConfig {
        scenario: Scenario::Uav,
        ..common::config(Scenario::Uav)
    };
    let mut s = sim(&config, 4);
    let mut out = TickOutput::default();
    let cruise_tick = 80_000; // 80 s: level at 100 m AGL
    let mut residual_sum = 0.0;
    let mut count = 0.0;
    for k in 0..cruise_tick + 1000 {
        s.step(&mut out);
        if k >= cruise_tick
            && let Some(f) = out.frame(FrameType::Baro)
        {
            let Payload::Baro(b) = f.payload else {
                panic!()
            };
            residual_sum +=
                f64::from(b.pressure_pa) - isa_pressure_pa(out.truth.altitude_m, config.qnh_pa);
            count += 1.0;
        }
    }
    let t = s.trajectory().sample((cruise_tick + 999) as f64 / 1000.0);
    let q = t.attitude.quaternion();
    assert_eq!(out.truth.quaternion, [q.w, q.i, q.j, q.k]);
    assert_eq!(out.truth.velocity_ned_mps, <[f64; 3]>::from(t.velocity_n));
    assert_eq!(out.truth.altitude_m, t.altitude_m);
    assert!((out.truth.altitude_m - config.origin_altitude_m - 100.0).abs() < 1e-6);
    // 50 samples of σ = 2 Pa.
    assert!((residual_sum / count).abs() < 5.0 * 2.0 / count.sqrt() + 0.01);
}

#[test]
fn faults_affect_only_their_channel() {
    let config = common::config(Scenario::Static);
    let (mut clean, mut faulty) = (sim(&config, 8), sim(&config, 8));
    let (mut oc, mut of) = (TickOutput::default(), TickOutput::default());
    for _ in 0..100 {
        clean.step(&mut oc);
        faulty.step(&mut of);
    }
    let frozen = imu(&of.imu).gyro_counts[2];
    let lsb = config.gyro_lsb_rps();
    faulty
        .inject_fault(InertialSensor::Gyro, 0, ChannelFault::Dead)
        .unwrap();
    faulty
        .inject_fault(
            InertialSensor::Gyro,
            1,
            ChannelFault::BiasStep { bias: 100.0 * lsb },
        )
        .unwrap();
    faulty
        .inject_fault(InertialSensor::Gyro, 2, ChannelFault::Stuck)
        .unwrap();
    faulty
        .inject_fault(
            InertialSensor::Accel,
            3,
            ChannelFault::NoiseBurst { sigma: 1.0 },
        )
        .unwrap();
    let mut bias_sum = 0.0;
    for _ in 0..500 {
        clean.step(&mut oc);
        faulty.step(&mut of);
        let (c, f) = (imu(&oc.imu), imu(&of.imu));
        assert_eq!(f.valid_mask, 0x000F_000E);
        assert_eq!(f.gyro_counts[0], 0);
        bias_sum += f64::from(f.gyro_counts[1] - c.gyro_counts[1]);
        assert_eq!(f.gyro_counts[2], frozen);
        assert_eq!(
            f.gyro_counts[3], c.gyro_counts[3],
            "unfaulted channel unchanged"
        );
        assert_eq!(&f.accel_counts[..3], &c.accel_counts[..3]);
        assert_eq!(f.status, 0);
    }
    // The bias step shifts each sample by exactly 100 counts (same noise in both runs, ±1 count of
    // rounding).
    assert!((bias_sum / 500.0 - 100.0).abs() < 1.0);

    faulty
        .inject_fault(InertialSensor::Accel, 0, ChannelFault::Saturated)
        .unwrap();
    clean.step(&mut oc);
    faulty.step(&mut of);
    let f = imu(&of.imu);
    assert_eq!(f.accel_counts[0], 2047);
    assert_ne!(f.status & ipc_types::status::SATURATION as u16, 0);

    for ch in 0..3 {
        faulty.clear_fault(InertialSensor::Gyro, ch).unwrap();
    }
    faulty.clear_fault(InertialSensor::Accel, 0).unwrap();
    faulty.clear_fault(InertialSensor::Accel, 3).unwrap();
    clean.step(&mut oc);
    faulty.step(&mut of);
    assert_eq!(of.imu, oc.imu, "clearing restores the clean stream");
}

#[test]
fn ramp_and_intermittent_faults_follow_their_schedules() {
    let config = common::config(Scenario::Static);
    let (mut clean, mut faulty) = (sim(&config, 5), sim(&config, 5));
    let lsb = config.accel_lsb_mps2();
    faulty
        .inject_fault(
            InertialSensor::Accel,
            1,
            ChannelFault::Ramp {
                rate_per_s: 50.0 * lsb,
            },
        )
        .unwrap();
    faulty
        .inject_fault(
            InertialSensor::Gyro,
            3,
            ChannelFault::Intermittent {
                period_s: 0.1,
                dropout_s: 0.03,
            },
        )
        .unwrap();
    let (mut oc, mut of) = (TickOutput::default(), TickOutput::default());
    for k in 0..2000u32 {
        clean.step(&mut oc);
        faulty.step(&mut of);
        let (c, f) = (imu(&oc.imu), imu(&of.imu));
        let diff = f64::from(f.accel_counts[1] - c.accel_counts[1]);
        assert!(
            (diff - 50.0 * f64::from(k) / 1000.0).abs() <= 1.0,
            "ramp at tick {k}"
        );
        let dropped = k % 100 < 30;
        assert_eq!(f.valid_mask & (1 << 3) == 0, dropped, "tick {k}");
    }
}

#[test]
fn invalid_fault_requests_are_rejected() {
    let mut s = sim(&SimConfig::default(), 1);
    let err = s
        .inject_fault(InertialSensor::Gyro, 4, ChannelFault::Dead)
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "gyro channel 4: no such channel (device has 4)"
    );
    let err = s
        .inject_fault(
            InertialSensor::Accel,
            0,
            ChannelFault::NoiseBurst { sigma: -1.0 },
        )
        .unwrap_err();
    assert!(matches!(err, SimError::Fault { field: "sigma", .. }));
    let err = s
        .inject_fault(
            InertialSensor::Accel,
            0,
            ChannelFault::Intermittent {
                period_s: 1.0,
                dropout_s: 2.0,
            },
        )
        .unwrap_err();
    assert!(err.to_string().contains("dropout_s = 2"));
}
