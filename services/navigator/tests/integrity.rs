//! The integrity monitor and its recovery policies on a static vehicle: an IMU outage, a device
//! clock that stops, and inertial input that is not motion (which drives the solution away from
//! the baro and the magnetometer until they re-set it).

mod common;

use common::{Noise, angle_diff, earth_field_ned, specific_force_at_rest};
use ipc_types::{Integrity, NavMode, aiding, integrity_reason as why};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rins_earth::normal_gravity;
use rins_navigator::attitude::euler_from_quaternion;
use rins_navigator::ekf::AidingSource;
use rins_navigator::integrity::IntegrityConfig;
use rins_navigator::mechanisation::quaternion_from_euler;
use rins_navigator::{NavOutput, Navigator, NavigatorConfig};

const HEIGHT: f64 = 450.0;
const YAW_DEG: f64 = 60.0;

fn config() -> NavigatorConfig {
    NavigatorConfig {
        initial_latitude_deg: Some(47.0),
        initial_longitude_deg: Some(8.0),
        initial_altitude_m: HEIGHT,
        ..NavigatorConfig::default()
    }
}

/// A static vehicle: IMU at 1 kHz, magnetometer at 100 Hz, baro at 25 Hz, light noise. `extra_*`
/// is added to the IMU (what a faulty block reports that is not motion).
struct Vehicle {
    attitude: UnitQuaternion<f64>,
    gravity: f64,
    field_body: Vector3<f64>,
    noise: Noise,
    extra_rate: Vector3<f64>,
    extra_force: Vector3<f64>,
}

impl Vehicle {
    fn new() -> Self {
        let attitude = quaternion_from_euler(0.0, 0.0, YAW_DEG.to_radians());
        Self {
            attitude,
            gravity: normal_gravity(47f64.to_radians(), HEIGHT),
            field_body: attitude.inverse() * earth_field_ned(21.0, 43.0, 0.0),
            noise: Noise::new(3),
            extra_rate: Vector3::zeros(),
            extra_force: Vector3::zeros(),
        }
    }

    fn time_us(k: u64) -> u64 {
        1_000_000 + k * 1000
    }

    fn aid(&mut self, nav: &mut Navigator, k: u64) {
        let t = Self::time_us(k);
        if k.is_multiple_of(10) {
            let _ = nav.on_mag(t, (self.field_body + self.noise.vector(0.1)).into());
        }
        if k.is_multiple_of(40) {
            let _ = nav.on_baro(t, HEIGHT + self.noise.scalar(0.3), 0.09, true);
        }
    }

    /// Sample `k` (device time 1 s + k ms).
    fn step(&mut self, nav: &mut Navigator, k: u64) -> Option<NavOutput> {
        self.aid(nav, k);
        let rate = self.extra_rate + self.noise.vector(1e-4);
        let f = specific_force_at_rest(&self.attitude, self.gravity)
            + self.extra_force
            + self.noise.vector(0.01);
        nav.on_imu(Self::time_us(k), rate.into(), f.into())
    }

    /// Aligns (1 s) and navigates until sample `until`; returns the last output.
    fn aligned(nav: &mut Navigator, until: u64) -> (Self, NavOutput) {
        let mut v = Self::new();
        let mut last = None;
        for k in 0..=until {
            last = v.step(nav, k);
        }
        let last = last.expect("aligned");
        assert_eq!(last.integrity, Integrity::Ok, "{last:?}");
        (v, last)
    }
}

fn yaw_deg(out: &NavOutput) -> f64 {
    let [w, x, y, z] = out.quaternion;
    let q = UnitQuaternion::new_normalize(Quaternion::new(w, x, y, z));
    euler_from_quaternion(&q)[2].to_degrees()
}

#[test]
fn an_imu_outage_is_invalid_from_its_limit_on_and_recovers_once_the_aiding_agrees() {
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, before) = Vehicle::aligned(&mut nav, 3000);
    let limit_ms = (IntegrityConfig::default().imu_outage_s * 1e3) as u64;
    // Fused samples arrive without a usable solution from sample 3001 on.
    for k in 3001..=3500 {
        v.aid(&mut nav, k);
        let out = nav.on_unusable_imu(Vehicle::time_us(k)).expect("aligned");
        let elapsed_ms = k - 3001;
        if elapsed_ms < limit_ms {
            assert_eq!(out.integrity, Integrity::Degraded, "after {elapsed_ms} ms");
            assert_eq!(out.mode, NavMode::Navigating);
        } else {
            assert_eq!(out.integrity, Integrity::Invalid, "after {elapsed_ms} ms");
            assert_eq!(out.mode, NavMode::Invalid);
            // Nothing vouches for an invalid solution.
            assert_eq!(out.aiding & (aiding::BARO | aiding::MAG), 0);
        }
        assert!(out.integrity_reasons & why::IMU_UNUSABLE != 0);
        // Nothing is integrated: the solution's epoch stands still (the aiding still updates it).
        assert_eq!(out.device_time_us, before.device_time_us);
    }
    // Usable again: recovering (degraded) for recovery_s, then ok.
    let recovery_ms = (IntegrityConfig::default().recovery_s * 1e3) as u64;
    let mut ok_at = None;
    for k in 3501..=6000 {
        let out = v.step(&mut nav, k).expect("navigating");
        assert_ne!(out.integrity, Integrity::Invalid, "sample {k}");
        if out.integrity == Integrity::Ok {
            ok_at.get_or_insert(k);
        } else {
            assert!(ok_at.is_none(), "ok, then not ok again at {k}: {out:?}");
            // Recovering; the attitude lost during the outage until gravity and the
            // magnetometer have brought its σ back.
            assert_eq!(
                out.integrity_reasons & !why::COVARIANCE,
                why::RECOVERING,
                "{out:?}"
            );
        }
    }
    let ok_at = ok_at.expect("back to ok");
    assert!(
        (3501 + recovery_ms..=3501 + recovery_ms + 50).contains(&ok_at),
        "ok at sample {ok_at}"
    );
    assert!(nav.integrity().0 == Integrity::Ok);
}

#[test]
fn a_device_clock_that_stops_makes_the_solution_invalid_until_it_runs_again() {
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, _) = Vehicle::aligned(&mut nav, 2000);
    let stalls = IntegrityConfig::default().time_stall_samples;
    let frozen = Vehicle::time_us(2000);
    for j in 1..=50u32 {
        let f = specific_force_at_rest(&v.attitude, v.gravity);
        let out = nav.on_imu(frozen, [0.0; 3], f.into()).expect("aligned");
        let want = if j < stalls {
            Integrity::Degraded
        } else {
            Integrity::Invalid
        };
        assert_eq!(out.integrity, want, "stalled sample {j}");
        assert!(out.integrity_reasons & why::TIME_NOT_ADVANCING != 0);
    }
    for k in 2001..=4500 {
        let out = v.step(&mut nav, k).expect("navigating");
        assert_ne!(out.integrity, Integrity::Invalid, "sample {k}");
    }
    assert_eq!(nav.integrity(), (Integrity::Ok, 0));
}

#[test]
fn a_false_rate_turns_the_heading_away_and_the_magnetometer_resets_it() {
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, _) = Vehicle::aligned(&mut nav, 2000);
    // 1.5 s of a 1 rad/s yaw rate that is not motion: 86° of false heading.
    v.extra_rate = Vector3::new(0.0, 0.0, 1.0);
    for k in 2001..=3500 {
        v.step(&mut nav, k);
    }
    v.extra_rate = Vector3::zeros();
    let persist_ms = (IntegrityConfig::default().rejection_persist_s * 1e3) as u64;
    let mut inconsistent = false;
    let mut reset_at = None;
    let mut last = None;
    for k in 3501..=9000 {
        let out = v.step(&mut nav, k).expect("navigating");
        inconsistent |= out.integrity_reasons & why::MAG_INCONSISTENT != 0;
        if reset_at.is_none() && out.resets[AidingSource::Mag as usize] > 0 {
            reset_at = Some(k);
            // Re-set onto the magnetometer's heading: within a few σ of the truth.
            assert!(angle_diff(yaw_deg(&out).to_radians(), YAW_DEG.to_radians()).abs() < 0.1);
        }
        last = Some(out);
    }
    let last = last.unwrap();
    assert!(inconsistent, "the rejected magnetometer was reported");
    let reset_at = reset_at.expect("heading reset from the magnetometer");
    // The rejections began during the false rate; the reset follows within the persistence.
    assert!(reset_at <= 3501 + persist_ms, "reset at sample {reset_at}");
    assert_eq!(last.resets[AidingSource::Mag as usize], 1);
    assert_eq!(last.integrity, Integrity::Ok, "{last:?}");
    assert!(
        angle_diff(yaw_deg(&last).to_radians(), YAW_DEG.to_radians()).abs() < 2f64.to_radians()
    );
}

#[test]
fn a_false_vertical_force_drives_the_altitude_off_and_the_baro_resets_it() {
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, _) = Vehicle::aligned(&mut nav, 2000);
    // 2 s of 20 m/s² downwards that is not motion (the block at full scale, say).
    v.extra_force = Vector3::new(0.0, 0.0, 20.0);
    for k in 2001..=4000 {
        v.step(&mut nav, k);
    }
    v.extra_force = Vector3::zeros();
    let mut inconsistent = false;
    let mut last = None;
    for k in 4001..=14000 {
        let out = v.step(&mut nav, k).expect("navigating");
        inconsistent |= out.integrity_reasons & why::BARO_INCONSISTENT != 0;
        last = Some(out);
    }
    let last = last.unwrap();
    assert!(inconsistent, "the rejected baro was reported");
    assert!(last.resets[AidingSource::Baro as usize] >= 1, "{last:?}");
    assert!((last.alt - HEIGHT).abs() < 1.0, "altitude {}", last.alt);
    assert!(last.velocity_ned[2].abs() < 0.5, "{:?}", last.velocity_ned);
    assert_eq!(last.integrity, Integrity::Ok, "{last:?}");
}

#[test]
fn without_resets_a_solution_every_source_rejects_is_invalid() {
    let cfg = NavigatorConfig {
        integrity: IntegrityConfig {
            reset_from_aiding: false,
            ..IntegrityConfig::default()
        },
        ..config()
    };
    let mut nav = Navigator::new(cfg).unwrap();
    let (mut v, _) = Vehicle::aligned(&mut nav, 2000);
    v.extra_rate = Vector3::new(0.0, 0.0, 1.0);
    v.extra_force = Vector3::new(0.0, 0.0, 20.0);
    for k in 2001..=4000 {
        v.step(&mut nav, k);
    }
    v.extra_rate = Vector3::zeros();
    v.extra_force = Vector3::zeros();
    let mut out = None;
    for k in 4001..=8000 {
        out = v.step(&mut nav, k);
    }
    let out = out.unwrap();
    assert_eq!(out.integrity, Integrity::Invalid, "{out:?}");
    assert_eq!(out.mode, NavMode::Invalid);
    assert!(
        out.integrity_reasons & why::ALL_AIDING_REJECTED != 0,
        "{out:?}"
    );
    assert_eq!(out.resets, [0; AidingSource::COUNT]);
}

#[test]
fn a_vehicle_that_turned_during_an_outage_is_re_levelled_from_gravity_and_the_magnetometer() {
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, _) = Vehicle::aligned(&mut nav, 2000);
    for k in 2001..=3000 {
        v.aid(&mut nav, k);
        let _ = nav.on_unusable_imu(Vehicle::time_us(k));
    }
    // Meanwhile the vehicle rolled by 10°, pitched by −5° and turned by 40°.
    let (roll, pitch, yaw) = (
        10f64.to_radians(),
        -5f64.to_radians(),
        (YAW_DEG + 40.0).to_radians(),
    );
    v.attitude = quaternion_from_euler(roll, pitch, yaw);
    v.field_body = v.attitude.inverse() * earth_field_ned(21.0, 43.0, 0.0);
    let first = v.step(&mut nav, 3001).expect("navigating");
    // The attitude is lost: its σ says so on every axis.
    let lost = IntegrityConfig::default()
        .lost_attitude_sigma_deg
        .to_radians();
    for i in 0..3 {
        assert!(
            (first.covariance_diag[i].sqrt() - lost).abs() < 1e-9,
            "{first:?}"
        );
    }
    assert!(first.integrity_reasons & why::COVARIANCE != 0);
    let mut last = first;
    for k in 3002..=6000 {
        last = v.step(&mut nav, k).expect("navigating");
    }
    let [w, x, y, z] = last.quaternion;
    let e = euler_from_quaternion(&UnitQuaternion::new_normalize(Quaternion::new(w, x, y, z)));
    // Tilt from gravity to its σ (0.1 m/s² over g ≈ 0.6°), heading from the magnetometer.
    assert!(
        (e[0] - roll).abs() < 0.5f64.to_radians(),
        "roll {}",
        e[0].to_degrees()
    );
    assert!(
        (e[1] - pitch).abs() < 0.5f64.to_radians(),
        "pitch {}",
        e[1].to_degrees()
    );
    assert!(
        angle_diff(e[2], yaw).abs() < 2f64.to_radians(),
        "yaw {}",
        e[2].to_degrees()
    );
    assert!(last.counts[AidingSource::Gravity as usize].accepted >= 1);
    assert_eq!(last.integrity, Integrity::Ok, "{last:?}");
}

#[test]
fn a_gap_in_the_imu_stream_is_an_outage_and_loses_the_attitude() {
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, _) = Vehicle::aligned(&mut nav, 2000);
    // Nothing at all for 300 ms (a serial outage), then samples again.
    let first = v.step(&mut nav, 2300).expect("navigating");
    assert_eq!(first.integrity, Integrity::Invalid, "{first:?}");
    assert!(first.integrity_reasons & why::IMU_UNUSABLE != 0);
    let next = v.step(&mut nav, 2301).expect("navigating");
    let lost = IntegrityConfig::default()
        .lost_attitude_sigma_deg
        .to_radians();
    assert!(
        (next.covariance_diag[0].sqrt() - lost).abs() < 1e-9,
        "{next:?}"
    );
    let mut last = next;
    for k in 2302..=5000 {
        last = v.step(&mut nav, k).expect("navigating");
    }
    assert_eq!(last.integrity, Integrity::Ok, "{last:?}");
    // A short gap, within the strapdown's largest step, is integrated across: nothing to report.
    let out = v.step(&mut nav, 5050).expect("navigating");
    assert_eq!(out.integrity, Integrity::Ok, "{out:?}");
}

/// A gyro bias fusion detects but cannot isolate: the fused rate carries it and the fused rate
/// variance carries fusion's bound on it. The integrity is degraded from the first such sample,
/// and, the episode having integrated more than the 1° limit, stays so after the isolation, so
/// that no sample with more than the limit of attitude error is called ok.
#[test]
fn a_fault_fusion_cannot_isolate_degrades_the_integrity_until_its_error_is_covered() {
    use ipc_types::fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED as UNISOLATED;
    let mut nav = Navigator::new(config()).unwrap();
    let (mut v, before) = Vehicle::aligned(&mut nav, 3000);
    // 0.015 rad/s on the fused roll rate (a 0.02 rad/s channel bias, three quarters of which
    // reach the solution), unisolated for 2 s: 1.7° of roll error.
    let bias = 0.015;
    let quiet_var = [1e-8; 3];
    let mut first_degraded = None;
    let mut worst_ok_error_deg: f64 = 0.0;
    let (mut widest_sigma_deg, mut last_roll_deg) = (0.0f64, f64::NAN);
    for k in 3001..=12_000u64 {
        let unisolated = k <= 5000;
        v.extra_rate = if unisolated {
            Vector3::new(bias, 0.0, 0.0)
        } else {
            Vector3::zeros()
        };
        let (flags, var) = if unisolated {
            (UNISOLATED, [bias * bias + 1e-8; 3])
        } else {
            (0, quiet_var)
        };
        nav.on_fusion_status(flags, var);
        let out = v.step(&mut nav, k).expect("navigating");
        let roll_deg = euler_from_quaternion(&UnitQuaternion::from_quaternion(Quaternion::new(
            out.quaternion[0],
            out.quaternion[1],
            out.quaternion[2],
            out.quaternion[3],
        )))[0]
            .to_degrees();
        widest_sigma_deg = widest_sigma_deg.max(out.covariance_diag[0].sqrt().to_degrees());
        last_roll_deg = roll_deg;
        if out.integrity == Integrity::Ok {
            worst_ok_error_deg = worst_ok_error_deg.max(roll_deg.abs());
        } else {
            assert!(
                out.integrity_reasons & why::SENSOR_FAULT_UNISOLATED != 0,
                "{out:?}"
            );
            first_degraded.get_or_insert(k);
        }
    }
    assert_eq!(first_degraded, Some(3001), "degraded from the first sample");
    assert!(worst_ok_error_deg < 1.0, "{worst_ok_error_deg}° while ok");
    // The episode's 1.7° were added to the attitude σ; more than the limit was integrated, so
    // the integrity stays degraded for as long as this filter runs.
    let sigma_before = before.covariance_diag[0].sqrt().to_degrees();
    assert!(
        widest_sigma_deg > sigma_before + 0.5,
        "σ roll {widest_sigma_deg} from {sigma_before}"
    );
    let out = nav.output();
    assert_eq!(out.integrity, Integrity::Degraded, "{out:?}");
    assert_eq!(
        out.integrity_reasons,
        why::SENSOR_FAULT_UNISOLATED,
        "{out:?}"
    );
    assert!(last_roll_deg.is_finite());
}

/// Without a configured position the horizontal position is a placeholder: never ok.
#[test]
fn without_an_initial_position_the_integrity_says_the_position_is_unknown() {
    let config = NavigatorConfig {
        initial_latitude_deg: None,
        initial_longitude_deg: None,
        ..config()
    };
    let mut nav = Navigator::new(config).unwrap();
    let mut v = Vehicle::new();
    let mut last = None;
    for k in 0..=3000 {
        last = v.step(&mut nav, k);
    }
    let last = last.expect("aligned");
    assert_eq!(last.integrity, Integrity::Degraded, "{last:?}");
    assert_eq!(last.integrity_reasons, why::POSITION_UNKNOWN, "{last:?}");
    assert_eq!(last.mode, NavMode::Navigating);
}
