//! SYS_STATUS: which of the on-board sensors and functions are present, enabled and healthy, as a
//! ground station shows them. rins reports what it has: its gyros, accelerometers and attitude
//! solution (AHRS) always, and the magnetometer, barometer and GNSS receiver once a solution has
//! shown them configured (used, or waited for: [`ipc_types::aiding`]). A gyro or accelerometer is
//! healthy while fusion gives it a valid solution with no fault it could not isolate (an excluded
//! channel with three left is redundancy lost, not a failed sensor: the status text and
//! `rins status` say which); the AHRS while the solution is usable and not invalid; an aiding
//! sensor while the solution takes its updates (not stale, not rejected). Nothing of the extended
//! set (recovery system and the like) exists on rins: those fields are 0.

use ipc_types::{FusedImu, Integrity, NavMode, NavState, aiding, fused_flags};

use crate::dialect::{MavSysStatusSensor, MavSysStatusSensorExtended, SYS_STATUS_DATA};

/// What rins always has: its gyros, accelerometers and attitude solution.
fn always() -> MavSysStatusSensor {
    MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_GYRO
        | MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_ACCEL
        | MavSysStatusSensor::MAV_SYS_STATUS_AHRS
}

/// Each aiding sensor's bit, the aiding bits that say it is configured, and those that say it is
/// not helping (stale, rejected).
const AIDING_SENSORS: [(MavSysStatusSensor, u32, u32); 3] = [
    (
        MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_MAG,
        aiding::MAG | aiding::MAG_STALE,
        aiding::MAG_STALE,
    ),
    (
        MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE,
        aiding::BARO | aiding::BARO_STALE,
        aiding::BARO_STALE,
    ),
    (
        MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_GPS,
        aiding::GNSS | aiding::GNSS_STALE | aiding::GNSS_REJECTED,
        aiding::GNSS_STALE | aiding::GNSS_REJECTED,
    ),
];

/// The sensors present, given every aiding bit the solutions have shown so far (`aiding_seen`,
/// the union of [`NavState::aiding`]): a sensor configured once stays present when it fails.
pub fn present(aiding_seen: u32) -> MavSysStatusSensor {
    AIDING_SENSORS
        .iter()
        .filter(|(_, configured, _)| aiding_seen & configured != 0)
        .fold(always(), |bits, (bit, _, _)| bits | *bit)
}

/// The health bits for the latest fused sample and solution (none before either arrived).
pub fn health(fused: Option<&FusedImu>, nav: Option<&NavState>) -> MavSysStatusSensor {
    let mut healthy = MavSysStatusSensor::empty();
    if let Some(f) = fused {
        let unusable = fused_flags::INPUT_REJECTED;
        let gyro_bad = unusable
            | fused_flags::GYRO_INSUFFICIENT
            | fused_flags::GYRO_SATURATED
            | fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED;
        let accel_bad = unusable
            | fused_flags::ACCEL_INSUFFICIENT
            | fused_flags::ACCEL_SATURATED
            | fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED;
        if f.flags & gyro_bad == 0 {
            healthy |= MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_GYRO;
        }
        if f.flags & accel_bad == 0 {
            healthy |= MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_ACCEL;
        }
    }
    if let Some(n) = nav {
        let usable = NavMode::from_u8(n.mode).is_some_and(NavMode::is_usable);
        let valid = Integrity::from_u8(n.integrity).is_some_and(|i| i != Integrity::Invalid);
        if usable && valid {
            healthy |= MavSysStatusSensor::MAV_SYS_STATUS_AHRS;
        }
        for (bit, configured, failing) in AIDING_SENSORS {
            // Used now (its own bit among the configured ones) and neither stale nor rejected.
            if n.aiding & configured & !failing != 0 && n.aiding & failing == 0 {
                healthy |= bit;
            }
        }
    }
    healthy
}

/// SYS_STATUS for the latest fused sample and solution, with the sensors `present` (enabled
/// alike: rins uses all it has); `load_permille` is the load in ‰, the pipeline's CPU share
/// ([`crate::pipeline_cpu`]; 0: not measured), at most 1000; no battery (the invalid values),
/// nothing of the extended set.
pub fn sys_status(
    fused: Option<&FusedImu>,
    nav: Option<&NavState>,
    present: MavSysStatusSensor,
    load_permille: u16,
) -> SYS_STATUS_DATA {
    let none = MavSysStatusSensorExtended::empty();
    SYS_STATUS_DATA {
        onboard_control_sensors_present: present,
        onboard_control_sensors_enabled: present,
        onboard_control_sensors_health: health(fused, nav) & present,
        load: load_permille.min(1000),
        voltage_battery: u16::MAX,
        current_battery: -1,
        battery_remaining: -1,
        drop_rate_comm: 0,
        errors_comm: 0,
        errors_count1: 0,
        errors_count2: 0,
        errors_count3: 0,
        errors_count4: 0,
        // The dialect's default for these flag sets is their first flag (a recovery system):
        // set explicitly, none.
        onboard_control_sensors_present_extended: none,
        onboard_control_sensors_enabled_extended: none,
        onboard_control_sensors_health_extended: none,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn navigating(aiding: u32) -> NavState {
        NavState {
            mode: NavMode::Navigating as u8,
            aiding,
            ..NavState::default()
        }
    }

    #[test]
    fn healthy_sensors_and_solution_set_every_bit_of_what_exists() {
        let nav = navigating(0);
        let h = health(Some(&FusedImu::default()), Some(&nav));
        assert_eq!(h, always());
        let m = sys_status(Some(&FusedImu::default()), Some(&nav), present(0), 1200);
        assert_eq!(m.onboard_control_sensors_present, always());
        assert_eq!(m.onboard_control_sensors_enabled, always());
        assert_eq!(m.onboard_control_sensors_health, always());
        assert_eq!(
            (m.load, m.voltage_battery, m.battery_remaining),
            (1000, u16::MAX, -1)
        );
        let none = MavSysStatusSensorExtended::empty();
        assert_eq!(
            (
                m.onboard_control_sensors_present_extended,
                m.onboard_control_sensors_enabled_extended,
                m.onboard_control_sensors_health_extended
            ),
            (none, none, none)
        );
        // Not measured is 0.
        assert_eq!(sys_status(None, None, present(0), 0).load, 0);
    }

    #[test]
    fn aiding_sensors_are_present_once_configured_and_healthy_while_used() {
        let mag = MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_MAG;
        let baro = MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE;
        let gps = MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_GPS;
        // Baro and mag aiding, no GNSS receiver: no GPS bit anywhere.
        let used = aiding::BARO | aiding::MAG | aiding::ZUPT;
        let fitted = present(used);
        assert_eq!(fitted, always() | mag | baro);
        let m = sys_status(
            Some(&FusedImu::default()),
            Some(&navigating(used)),
            fitted,
            0,
        );
        assert_eq!(m.onboard_control_sensors_health, always() | mag | baro);
        assert!(!m.onboard_control_sensors_present.contains(gps));
        // The barometer goes quiet: still present, no longer healthy.
        let stale = aiding::BARO_STALE | aiding::MAG;
        let h = health(None, Some(&navigating(stale))) & present(used | stale);
        assert!(h.contains(mag) && !h.contains(baro));
        // A receiver that only ever had stale or rejected fixes is present and unhealthy.
        let outage = aiding::GNSS_STALE;
        assert!(present(outage).contains(gps));
        assert!(!health(None, Some(&navigating(outage))).contains(gps));
        let rejected = aiding::GNSS | aiding::GNSS_REJECTED;
        assert!(!health(None, Some(&navigating(rejected))).contains(gps));
        assert!(health(None, Some(&navigating(aiding::GNSS))).contains(gps));
        // Health never names a sensor that is not present.
        let m = sys_status(None, Some(&navigating(aiding::GNSS)), present(0), 0);
        assert!(!m.onboard_control_sensors_health.contains(gps));
    }

    #[test]
    fn each_failure_clears_its_own_bit() {
        let nav = navigating(0);
        let gyro_out = FusedImu {
            flags: fused_flags::GYRO_INSUFFICIENT,
            ..FusedImu::default()
        };
        assert_eq!(
            health(Some(&gyro_out), Some(&nav)),
            MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_ACCEL
                | MavSysStatusSensor::MAV_SYS_STATUS_AHRS
        );
        let accel_suspect = FusedImu {
            flags: fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED,
            ..FusedImu::default()
        };
        assert!(
            !health(Some(&accel_suspect), None)
                .contains(MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_ACCEL)
        );
        let invalid = NavState {
            integrity: Integrity::Invalid as u8,
            ..nav
        };
        assert!(!health(None, Some(&invalid)).contains(MavSysStatusSensor::MAV_SYS_STATUS_AHRS));
        let aligning = NavState::default();
        assert!(!health(None, Some(&aligning)).contains(MavSysStatusSensor::MAV_SYS_STATUS_AHRS));
        assert_eq!(health(None, None), MavSysStatusSensor::empty());
    }
}
