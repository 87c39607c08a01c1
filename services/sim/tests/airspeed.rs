//! The pitot airspeed sensor in the frame stream: off by default and then invisible, on at its
//! rate without touching any other frame, and reading the dynamic pressure of the true airspeed.

use rins_protocol::{AirspeedFrame, Frame, FrameType, Payload};
use rins_sim::sensor_model::airspeed::isa_density;
use rins_sim::{SimConfig, Simulator, TickOutput};
use rins_test_support::pyramid::optimal_pyramid_axes;

fn sim(config: &SimConfig) -> Simulator {
    let axes = optimal_pyramid_axes();
    Simulator::new(config, &axes, &axes, 4).unwrap()
}

fn airspeed(out: &TickOutput) -> Option<AirspeedFrame> {
    out.frame(FrameType::Airspeed).map(|f| match f.payload {
        Payload::Airspeed(a) => a,
        other => panic!("expected an airspeed frame, got {other:?}"),
    })
}

/// The tick's frames other than the airspeed sensor's.
fn others(out: &TickOutput) -> [Option<Frame>; FrameType::COUNT] {
    FrameType::ALL.map(|t| match t {
        FrameType::Airspeed => None,
        _ => out.frame(t).copied(),
    })
}

#[test]
fn off_by_default_and_on_it_changes_no_other_frame() {
    let off_config = SimConfig::default();
    assert!(!off_config.airspeed.enabled);
    let mut on_config = SimConfig::default();
    on_config.airspeed.enabled = true;
    let (mut off, mut on) = (sim(&off_config), sim(&on_config));
    let (mut a, mut b) = (TickOutput::default(), TickOutput::default());
    let mut frames = Vec::new();
    for _ in 0..2000 {
        off.step(&mut a);
        on.step(&mut b);
        assert_eq!(a.frame(FrameType::Airspeed), None);
        assert_eq!((others(&a), a.truth), (others(&b), b.truth));
        frames.extend(b.frame(FrameType::Airspeed).copied());
    }
    // 50 Hz over 2 s, numbered from 0 without a gap, stamped with the IMU's device time.
    assert_eq!(frames.len(), 100);
    for (k, f) in frames.iter().enumerate() {
        assert_eq!(usize::from(f.seq), k);
        assert_eq!(u64::from(f.device_time_us), k as u64 * 20_000);
    }
}

#[test]
fn in_cruise_the_reading_is_the_dynamic_pressure_of_the_true_airspeed() {
    let mut config = SimConfig::default();
    config.airspeed.enabled = true;
    config.airspeed.offset_pa = 3.0;
    config.airspeed.noise_pa = 1.0;
    let mut s = sim(&config);
    let mut out = TickOutput::default();
    let (mut sum, mut n) = (0.0, 0u32);
    // The first straight climb of the calm-air flight: 60 s to 100 s.
    for _ in 0..100_000 {
        s.step(&mut out);
        let t = out.truth.device_time_us as f64 * 1e-6;
        if let Some(a) = airspeed(&out)
            && t >= 60.0
        {
            let v2: f64 = out.truth.velocity_ned_mps.iter().map(|v| v * v).sum();
            assert!(v2 > 14.0 * 14.0, "in cruise at {t} s");
            let q = 0.5 * isa_density(out.truth.altitude_m, config.qnh_pa) * v2;
            sum += f64::from(a.diff_pressure_pa) - q;
            n += 1;
        }
    }
    assert_eq!(n, 2000);
    // The mean of 2000 readings is the offset to 4σ/√n = 0.09 Pa.
    let mean = sum / f64::from(n);
    assert!((mean - 3.0).abs() < 0.09, "mean reading less q = {mean} Pa");
}
