//! The pitot airspeed aid on the simulator's fixed-wing flight in calm air, GNSS off: the same
//! flight (same seed, the airspeed frames sent in both) navigated with and without
//! `[navigator.airspeed]`, run in-process as the deployment chains it (simulator → fusion →
//! navigator, barometer → altimeter → navigator, magnetometer and airspeed → navigator).
//!
//! What the model predicts. Without the aid only the barometer and the magnetometer aid the
//! filter: nothing observes the horizontal velocity, and an uncorrected horizontal specific-force
//! error b (accelerometer bias, tilt left by the alignment: this flight shows b ≈ 0.15 m/s² on the
//! first leg) grows the velocity error as b·t and the position error as b·t²/2 — over the
//! ~270 s from the first turn to the end, several m/s RMS and kilometres. With the aid (σ 1 m/s at
//! 50 Hz; zero wind is true here) the velocity along the nose is held to σ/√(readings) ≈ 0.1 m/s,
//! but the cross-track velocity is not observed until the heading changes: on the first leg it
//! still grows as b·t, and the first 90° turn turns it into an along-track error that the aid then
//! removes, with the bias that made it. So the errors are compared from the end of the first turn
//! on: with the aid the cross-track velocity regrows on each straight leg only from the residual
//! bias (b/10 over a 60 s leg: about 1 m/s at the end of a leg, 0.5 m/s RMS), and the position
//! keeps what the first leg left (about b·t²/2 ≈ 10² m over 110 s, partly recovered at the turn).
//! The test asserts an RMS velocity error below 1 m/s with the aid, and a factor of 5 on the RMS
//! velocity error, the RMS position error and the final position error against the same flight
//! without it.

use ipc_types::NavMode;
use rins_altimeter::{AltimeterConfig, AltitudeEstimator};
use rins_fusion::{FusionConfig, ImuFuser, ImuSample};
use rins_navigator::aiding::airspeed::AirspeedReading;
use rins_navigator::aiding::readings::Reading;
use rins_navigator::navigator::fused_sample_usable;
use rins_navigator::{Navigator, NavigatorConfig};
use rins_protocol::{FrameType, Payload};
use rins_sim::{SimConfig, Simulator, TickOutput};

/// Device seconds flown: take-off, climb and most of the first circuit pair's legs and turns.
const FLIGHT_S: f64 = 400.0;
/// Earth radius for the small-angle conversion of latitude/longitude errors to metres.
const EARTH_RADIUS_M: f64 = 6_378_137.0;

/// Errors against the truth over the airborne samples (truth ground speed above 10 m/s) from the
/// end of the first turn (the track 45° or more from the first leg's) to the end of the flight.
#[derive(Debug, Clone, Copy)]
struct FlightErrors {
    /// RMS horizontal velocity error, m/s.
    horiz_vel_rms_mps: f64,
    /// RMS horizontal position error, m.
    horiz_pos_rms_m: f64,
    /// Horizontal position error of the last sample, m.
    horiz_pos_end_m: f64,
    /// Airspeed readings the navigator took (accepted updates).
    airspeed_updates: u64,
}

fn fly(airspeed_aid: bool) -> FlightErrors {
    let mut sim_config = SimConfig::default();
    sim_config.airspeed.enabled = true;
    let fusion = FusionConfig::default();
    let gyro = fusion.geometry.gyro.build().expect("gyro geometry");
    let accel = fusion.geometry.accel.build().expect("accel geometry");
    let mut sim = Simulator::new(&sim_config, gyro.axes(), accel.axes(), 3).expect("simulator");
    let mut fuser = ImuFuser::new(
        &fusion,
        sim_config.gyro_lsb_rps(),
        sim_config.accel_lsb_mps2(),
    )
    .expect("fuser");
    let mut altimeter = AltitudeEstimator::new(AltimeterConfig::default()).expect("altimeter");
    let mut nav_config = NavigatorConfig {
        initial_latitude_deg: Some(sim_config.origin_latitude_deg),
        initial_longitude_deg: Some(sim_config.origin_longitude_deg),
        ..NavigatorConfig::default()
    };
    nav_config.airspeed.enabled = airspeed_aid;
    let mut navigator = Navigator::new(nav_config).expect("navigator");

    let mut tick = TickOutput::default();
    let ticks = (FLIGHT_S * sim_config.imu_rate_hz) as u64;
    let (mut sum_v2, mut sum_p2, mut n, mut end_m) = (0.0, 0.0, 0u64, f64::NAN);
    let mut first_track_rad = None;
    let mut turned = false;
    let mut airspeed_frames = 0u64;
    for _ in 0..ticks {
        sim.step(&mut tick);
        let t_us = tick.truth.device_time_us;
        if let Some(frame) = tick.frame(FrameType::Baro)
            && let Payload::Baro(baro) = frame.payload
        {
            let a = altimeter.update(t_us, f64::from(baro.pressure_pa));
            let _ = navigator.on_baro(t_us, a.height_m, a.height_var, a.valid);
        }
        if let Some(frame) = tick.frame(FrameType::Mag)
            && let Payload::Mag(mag) = frame.payload
        {
            let _ = navigator.on_mag(t_us, mag.field_nt.map(|nt| f64::from(nt) * 1e-3));
        }
        if let Some(frame) = tick.frame(FrameType::Airspeed)
            && let Payload::Airspeed(a) = frame.payload
        {
            airspeed_frames += 1;
            let _ = navigator.on_reading(Reading::Airspeed(AirspeedReading {
                t_us,
                diff_pressure_pa: f64::from(a.diff_pressure_pa),
            }));
        }
        let Payload::Imu(imu) = &tick.imu.payload else {
            unreachable!("every tick carries an IMU frame")
        };
        let n_gyro = usize::from(imu.n_gyro);
        let n_accel = usize::from(imu.n_accel);
        let n_temperature = usize::from(imu.n_temperature);
        let temperatures = imu.temperature_centi_c.map(|c| f32::from(c) / 100.0);
        let fused = fuser.fuse_sample(&ImuSample {
            gyro_counts: &imu.gyro_counts[..n_gyro],
            accel_counts: &imu.accel_counts[..n_accel],
            valid_mask: imu.valid_mask,
            status: u32::from(imu.status),
            temperatures_c: &temperatures[..n_temperature],
        });
        if !fused_sample_usable(fused.flags()) {
            continue;
        }
        navigator.on_fusion_status(fused.flags(), fused.rate_var);
        let Some(out) = navigator.on_imu(t_us, fused.rate, fused.specific_force) else {
            continue;
        };
        let truth = &tick.truth;
        let [vn, ve, _] = truth.velocity_ned_mps;
        if out.mode == NavMode::Aligning || vn.hypot(ve) < 10.0 {
            continue;
        }
        let track = ve.atan2(vn);
        let first = *first_track_rad.get_or_insert(track);
        let off = (track - first + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        turned |= off.abs() > 45f64.to_radians();
        if !turned {
            continue;
        }
        let dvn = out.velocity_ned[0] - vn;
        let dve = out.velocity_ned[1] - ve;
        let dn = (out.lat - truth.latitude_rad) * EARTH_RADIUS_M;
        let de = (out.lon - truth.longitude_rad) * EARTH_RADIUS_M * truth.latitude_rad.cos();
        sum_v2 += dvn * dvn + dve * dve;
        sum_p2 += dn * dn + de * de;
        end_m = dn.hypot(de);
        n += 1;
    }
    assert!(n > 200_000, "samples after the first turn: {n}");
    assert!(
        airspeed_frames > 19_000,
        "airspeed frames: {airspeed_frames}"
    );
    let counts = navigator.output().counts;
    FlightErrors {
        horiz_vel_rms_mps: (sum_v2 / n as f64).sqrt(),
        horiz_pos_rms_m: (sum_p2 / n as f64).sqrt(),
        horiz_pos_end_m: end_m,
        airspeed_updates: counts[rins_navigator::ekf::AidingSource::Airspeed as usize].accepted,
    }
}

#[test]
fn the_airspeed_aid_bounds_the_horizontal_error_of_a_fixed_wing_without_gnss() {
    let (without, with) = std::thread::scope(|s| {
        let without = s.spawn(|| fly(false));
        let with = fly(true);
        (without.join().expect("unaided flight"), with)
    });
    eprintln!("without airspeed: {without:?}");
    eprintln!("with airspeed:    {with:?}");
    assert_eq!(without.airspeed_updates, 0);
    // Nearly every airborne reading (50 Hz over ~350 s) is taken.
    assert!(with.airspeed_updates > 15_000, "{with:?}");
    assert!(with.horiz_vel_rms_mps < 1.0, "{with:?}");
    assert!(
        with.horiz_vel_rms_mps * 5.0 < without.horiz_vel_rms_mps,
        "{with:?} vs {without:?}"
    );
    assert!(
        with.horiz_pos_rms_m * 5.0 < without.horiz_pos_rms_m,
        "{with:?} vs {without:?}"
    );
    assert!(
        with.horiz_pos_end_m * 5.0 < without.horiz_pos_end_m,
        "{with:?} vs {without:?}"
    );
}
