//! `[mavlink]`: whether the MAVLink output runs, where it sends, how it presents itself, what it
//! streams at which rate, and whether it takes commands.

use serde::{Deserialize, Serialize};

use crate::dialect::MavType;
use crate::endpoint::Endpoint;
use crate::heartbeat::Profile;

/// The MAVLink output's configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct MavlinkConfig {
    /// Whether `rins up` starts the MAVLink service.
    pub enabled: bool,
    /// Where the stream goes: `udpout:HOST:PORT` sends to a listener (an autopilot's companion
    /// link, a ground station), `udpin:ADDR:PORT` listens and answers whoever spoke last.
    pub endpoints: Vec<String>,
    /// MAVLink system id: the vehicle's, so that the autopilot takes rins as one of its own
    /// components.
    pub system_id: u8,
    /// MAVLink component id of the `onboard` profile (the `display` profile speaks as component 1).
    pub component_id: u8,
    /// `onboard` (an onboard controller beside the autopilot) or `display` (a vehicle for a ground
    /// station on a bench; never beside a real autopilot).
    pub profile: String,
    /// The vehicle type the `display` profile shows: `quadrotor`, `fixed-wing`, `helicopter`,
    /// `hexarotor`, `octorotor`, `ground-rover`.
    pub display_vehicle: String,
    /// Whether COMMAND_LONG re-admissions from the link are carried out (off: the stream is
    /// output only, commands are answered "denied").
    pub accept_commands: bool,
    /// Messages queued between the navigation loop and the network thread; beyond it they are
    /// dropped and counted, never waited for.
    pub queue_capacity: usize,
    /// `[mavlink.rates]`: messages per second of each stream.
    pub rates: MavlinkRates,
}

/// Messages per second of each stream; 0 turns a stream off. Streams that follow the solution
/// are paced by the measurement time, so each keeps its rate whatever the network does.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct MavlinkRates {
    /// HEARTBEAT.
    pub heartbeat_hz: f64,
    /// ATTITUDE_QUATERNION.
    pub attitude_quaternion_hz: f64,
    /// GLOBAL_POSITION_INT.
    pub global_position_int_hz: f64,
    /// LOCAL_POSITION_NED.
    pub local_position_ned_hz: f64,
    /// ODOMETRY.
    pub odometry_hz: f64,
    /// HIGHRES_IMU, from the fused IMU.
    pub highres_imu_hz: f64,
    /// SYS_STATUS.
    pub sys_status_hz: f64,
    /// VIBRATION.
    pub vibration_hz: f64,
}

impl Default for MavlinkConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            endpoints: vec!["udpout:127.0.0.1:14550".into()],
            system_id: 1,
            component_id: 197,
            profile: "onboard".into(),
            display_vehicle: "quadrotor".into(),
            accept_commands: false,
            queue_capacity: 512,
            rates: MavlinkRates::default(),
        }
    }
}

impl Default for MavlinkRates {
    fn default() -> Self {
        Self {
            heartbeat_hz: 1.0,
            attitude_quaternion_hz: 50.0,
            global_position_int_hz: 25.0,
            local_position_ned_hz: 30.0,
            odometry_hz: 30.0,
            highres_imu_hz: 50.0,
            sys_status_hz: 2.0,
            vibration_hz: 0.5,
        }
    }
}

/// The highest rate a stream may ask for: one message per fused sample at the sensor block's
/// fastest rate.
pub const MAX_RATE_HZ: f64 = 1000.0;

/// The vehicle types the `display` profile offers, by their configuration names.
const DISPLAY_VEHICLES: [(&str, MavType); 6] = [
    ("quadrotor", MavType::MAV_TYPE_QUADROTOR),
    ("fixed-wing", MavType::MAV_TYPE_FIXED_WING),
    ("helicopter", MavType::MAV_TYPE_HELICOPTER),
    ("hexarotor", MavType::MAV_TYPE_HEXAROTOR),
    ("octorotor", MavType::MAV_TYPE_OCTOROTOR),
    ("ground-rover", MavType::MAV_TYPE_GROUND_ROVER),
];

impl MavlinkRates {
    /// Each stream's name and rate, in the order the configuration lists them.
    pub fn named(&self) -> [(&'static str, f64); 8] {
        [
            ("heartbeat_hz", self.heartbeat_hz),
            ("attitude_quaternion_hz", self.attitude_quaternion_hz),
            ("global_position_int_hz", self.global_position_int_hz),
            ("local_position_ned_hz", self.local_position_ned_hz),
            ("odometry_hz", self.odometry_hz),
            ("highres_imu_hz", self.highres_imu_hz),
            ("sys_status_hz", self.sys_status_hz),
            ("vibration_hz", self.vibration_hz),
        ]
    }
}

impl MavlinkConfig {
    /// Checks every field; the error names the field and its value.
    pub fn validate(&self) -> Result<(), String> {
        if self.endpoints.is_empty() && self.enabled {
            return Err("mavlink.endpoints = []: the enabled output needs at least one".into());
        }
        for (i, e) in self.endpoints.iter().enumerate() {
            Endpoint::parse(e).map_err(|why| format!("mavlink.endpoints[{i}] = {e:?}: {why}"))?;
        }
        if self.system_id == 0 {
            return Err("mavlink.system_id = 0: 0 is the broadcast id, use 1..=255".into());
        }
        if self.component_id == 0 {
            return Err("mavlink.component_id = 0: 0 is the broadcast id, use 1..=255".into());
        }
        self.profile()?;
        if !(1..=65_536).contains(&self.queue_capacity) {
            return Err(format!(
                "mavlink.queue_capacity = {}: must be 1..=65536",
                self.queue_capacity
            ));
        }
        for (name, hz) in self.rates.named() {
            if !(hz.is_finite() && (0.0..=MAX_RATE_HZ).contains(&hz)) {
                return Err(format!(
                    "mavlink.rates.{name} = {hz}: must be 0 (off) to {MAX_RATE_HZ}"
                ));
            }
        }
        Ok(())
    }

    /// The profile this configuration asks for.
    pub fn profile(&self) -> Result<Profile, String> {
        match self.profile.as_str() {
            "onboard" => Ok(Profile::Onboard),
            "display" => DISPLAY_VEHICLES
                .iter()
                .find(|(name, _)| *name == self.display_vehicle)
                .map(|(_, vehicle)| Profile::Display { vehicle: *vehicle })
                .ok_or_else(|| {
                    let names: Vec<&str> = DISPLAY_VEHICLES.iter().map(|(n, _)| *n).collect();
                    format!(
                        "mavlink.display_vehicle = {:?}: must be one of {}",
                        self.display_vehicle,
                        names.join(", ")
                    )
                }),
            other => Err(format!(
                "mavlink.profile = {other:?}: must be \"onboard\" or \"display\""
            )),
        }
    }

    /// The component id rins speaks as: the configured one on board, 1 in the display profile (a
    /// ground station draws a vehicle only for component 1).
    pub fn speaking_component(&self) -> u8 {
        match self.profile() {
            Ok(Profile::Display { .. }) => 1,
            _ => self.component_id,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_off() {
        let c = MavlinkConfig::default();
        assert_eq!(c.validate(), Ok(()));
        assert!(!c.enabled);
        assert_eq!(c.profile(), Ok(Profile::Onboard));
        assert_eq!(c.speaking_component(), 197);
    }

    #[test]
    fn display_profile_speaks_as_component_one() {
        let c = MavlinkConfig {
            profile: "display".into(),
            display_vehicle: "fixed-wing".into(),
            ..MavlinkConfig::default()
        };
        assert_eq!(
            c.profile(),
            Ok(Profile::Display {
                vehicle: MavType::MAV_TYPE_FIXED_WING
            })
        );
        assert_eq!(c.speaking_component(), 1);
    }

    #[test]
    fn errors_name_the_field_and_value() {
        let bad = |f: fn(&mut MavlinkConfig)| {
            let mut c = MavlinkConfig::default();
            f(&mut c);
            c.validate().unwrap_err()
        };
        assert!(bad(|c| c.rates.odometry_hz = -1.0).starts_with("mavlink.rates.odometry_hz = -1"));
        assert!(bad(|c| c.rates.heartbeat_hz = f64::NAN).contains("heartbeat_hz = NaN"));
        assert!(bad(|c| c.profile = "autopilot".into()).contains("\"autopilot\""));
        assert!(
            bad(|c| {
                c.profile = "display".into();
                c.display_vehicle = "blimp".into();
            })
            .starts_with("mavlink.display_vehicle = \"blimp\"")
        );
        assert!(
            bad(|c| c.endpoints = vec!["tcp:1.2.3.4:5".into()])
                .starts_with("mavlink.endpoints[0] = \"tcp:1.2.3.4:5\"")
        );
        assert!(bad(|c| c.system_id = 0).starts_with("mavlink.system_id = 0"));
        assert!(bad(|c| c.queue_capacity = 0).starts_with("mavlink.queue_capacity = 0"));
        assert!(
            bad(|c| {
                c.enabled = true;
                c.endpoints.clear();
            })
            .starts_with("mavlink.endpoints = []")
        );
    }
}
