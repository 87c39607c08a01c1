//! SYS_STATUS: which of the on-board sensors and functions are present, enabled and healthy, as a
//! ground station shows them. rins reports its gyros, accelerometers and attitude solution (AHRS):
//! a sensor type is healthy while fusion gives it a valid solution with no fault it could not
//! isolate (an excluded channel with three left is redundancy lost, not a failed sensor: the status
//! text and `rins status` say which), the AHRS while the solution is usable and not invalid.

use ipc_types::{FusedImu, Integrity, NavMode, NavState, fused_flags};

use crate::dialect::{MavSysStatusSensor, SYS_STATUS_DATA};

/// What rins reports on: its gyros, accelerometers and attitude solution.
fn reported() -> MavSysStatusSensor {
    MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_GYRO
        | MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_ACCEL
        | MavSysStatusSensor::MAV_SYS_STATUS_AHRS
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
    }
    healthy
}

/// SYS_STATUS for the latest fused sample and solution; `load_permille` is the CPU load of the
/// pipeline in ‰ of one core; no battery (the invalid values).
pub fn sys_status(
    fused: Option<&FusedImu>,
    nav: Option<&NavState>,
    load_permille: u16,
) -> SYS_STATUS_DATA {
    SYS_STATUS_DATA {
        onboard_control_sensors_present: reported(),
        onboard_control_sensors_enabled: reported(),
        onboard_control_sensors_health: health(fused, nav),
        load: load_permille.min(1000),
        voltage_battery: u16::MAX,
        current_battery: -1,
        battery_remaining: -1,
        ..SYS_STATUS_DATA::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn healthy_sensors_and_solution_set_every_bit() {
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            ..NavState::default()
        };
        let h = health(Some(&FusedImu::default()), Some(&nav));
        assert_eq!(h, reported());
        let m = sys_status(Some(&FusedImu::default()), Some(&nav), 1200);
        assert_eq!(m.onboard_control_sensors_present, reported());
        assert_eq!(
            (m.load, m.voltage_battery, m.battery_remaining),
            (1000, u16::MAX, -1)
        );
    }

    #[test]
    fn each_failure_clears_its_own_bit() {
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            ..NavState::default()
        };
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
