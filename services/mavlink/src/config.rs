//! `[mavlink]`: whether the MAVLink output runs, where it sends, how it presents itself, what it
//! streams at which rate, whether it signs its messages, and whether and from whom it takes
//! commands.

use std::net::{IpAddr, SocketAddr};

use serde::{Deserialize, Serialize};

use crate::autopilot::Autopilot;
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
    /// The autopilot ODOMETRY is shaped for: `generic` (the message as the message set defines
    /// it), `px4` or `ardupilot` (the frames and fields each one's receiver takes, and the global
    /// origin announced with SET_GPS_GLOBAL_ORIGIN). Only with the `onboard` profile.
    pub autopilot: String,
    /// The vehicle type the `display` profile shows: `quadrotor`, `fixed-wing`, `helicopter`,
    /// `hexarotor`, `octorotor`, `ground-rover`.
    pub display_vehicle: String,
    /// Whether COMMAND_LONG re-admissions from the link are carried out (off: the stream is
    /// output only, commands are answered "denied"). Needs `signing_key_file`, or
    /// `allow_unsigned_commands` to take them from anyone who can reach the link.
    pub accept_commands: bool,
    /// The MAVLink 2 signing key: a file of exactly 64 hexadecimal digits (the 32-byte secret key,
    /// optionally followed by one newline), a regular file owned by the user rins runs as, with
    /// no permission for group or others. When set, every message sent is signed, and commands
    /// and TIMESYNC requests are carried out only when signed with this key.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub signing_key_file: Option<String>,
    /// The link id rins's signatures carry (the signing specification's `link_id`): receivers keep
    /// a timestamp per link, system and component.
    pub signing_link_id: u8,
    /// Carries out commands without a signature (no key set): anyone who can send a datagram to
    /// an endpoint can then re-admit a channel. Only for a link that nobody else can reach.
    pub allow_unsigned_commands: bool,
    /// The senders commands are taken from, by MAVLink system id and optionally component id;
    /// empty: any sender. Commands from others are refused and counted.
    pub command_sources: Vec<CommandSource>,
    /// The network addresses commands are taken from: `IP` (any port) or `IP:PORT`
    /// (`[IPv6]:PORT`); empty: any address. Commands from others are refused and counted.
    pub command_addresses: Vec<String>,
    /// COMMAND_ACKs sent per second at most, on average: a flood of commands cannot make rins
    /// flood the link with answers. Acknowledgements beyond it are dropped and counted.
    pub command_ack_rate_hz: f64,
    /// COMMAND_ACKs that may be sent at once before `command_ack_rate_hz` applies.
    pub command_ack_burst: u32,
    /// Messages queued between the navigation loop and the network thread; beyond it they are
    /// dropped and counted, never waited for.
    pub queue_capacity: usize,
    /// The horizontal position σ (m, the root of the north and east variances' sum) at which
    /// ODOMETRY's `quality` is 50: `100·σ₀²/(σ₀² + σ_h²)`, so a larger σ gives less.
    pub odometry_quality_sigma_m: f64,
    /// `[mavlink.rates]`: messages per second of each stream.
    pub rates: MavlinkRates,
}

/// A sender commands are taken from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CommandSource {
    /// Its MAVLink system id (a ground station is usually 255).
    pub system: u8,
    /// Its component id; absent: any component of that system.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<u8>,
}

impl CommandSource {
    /// Whether a message from `(system, component)` comes from this source. A 32-bit system id
    /// (a MAVLink 2 extension) never matches: the list names 8-bit ids.
    pub fn matches(&self, system: u32, component: u8) -> bool {
        system == u32::from(self.system) && self.component.is_none_or(|c| c == component)
    }
}

/// A network address commands are taken from: a host (any port) or one socket.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandAddress {
    /// Any port of this address.
    Ip(IpAddr),
    /// This address and port only.
    Socket(SocketAddr),
}

impl CommandAddress {
    /// Parses `IP`, `IP:PORT` or `[IPv6]:PORT`; the error says what is wrong, for the caller to
    /// prefix with the field. Names are refused: an allow-list must not depend on a resolver.
    pub fn parse(text: &str) -> Result<Self, String> {
        if let Ok(ip) = text.parse::<IpAddr>() {
            return Ok(Self::Ip(ip.to_canonical()));
        }
        match text.parse::<SocketAddr>() {
            Ok(s) if s.port() == 0 => Err("port 0: use 1..=65535, or no port for any".into()),
            Ok(s) => Ok(Self::Socket(SocketAddr::new(
                s.ip().to_canonical(),
                s.port(),
            ))),
            Err(_) => Err(
                "expected an IP address, IP:PORT or [IPv6]:PORT (host names are not resolved)"
                    .into(),
            ),
        }
    }

    /// Whether a datagram from `from` comes from this address. IPv4 peers seen on an IPv6
    /// socket (`::ffff:a.b.c.d`) match their IPv4 form.
    pub fn matches(&self, from: SocketAddr) -> bool {
        let ip = from.ip().to_canonical();
        match self {
            Self::Ip(a) => *a == ip,
            Self::Socket(s) => s.ip() == ip && s.port() == from.port(),
        }
    }
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
            autopilot: "generic".into(),
            display_vehicle: "quadrotor".into(),
            accept_commands: false,
            signing_key_file: None,
            signing_link_id: 0,
            allow_unsigned_commands: false,
            command_sources: Vec::new(),
            command_addresses: Vec::new(),
            command_ack_rate_hz: 10.0,
            command_ack_burst: 10,
            queue_capacity: 512,
            odometry_quality_sigma_m: 10.0,
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

/// The most COMMAND_ACKs per second and at once that may be configured: far above what an
/// operator sends, far below what would load the link.
pub const MAX_ACK_RATE_HZ: f64 = 1000.0;

/// The range of `odometry_quality_sigma_m`, m: from a centimetre (a σ₀ below any inertial
/// solution's would rate every solution at the bottom) to ten kilometres (every solution 100).
pub const QUALITY_SIGMA_RANGE_M: (f64, f64) = (0.01, 10_000.0);

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
        self.autopilot()?;
        if !(1..=65_536).contains(&self.queue_capacity) {
            return Err(format!(
                "mavlink.queue_capacity = {}: must be 1..=65536",
                self.queue_capacity
            ));
        }
        let (lo, hi) = QUALITY_SIGMA_RANGE_M;
        let sigma = self.odometry_quality_sigma_m;
        if !(sigma.is_finite() && (lo..=hi).contains(&sigma)) {
            return Err(format!(
                "mavlink.odometry_quality_sigma_m = {sigma}: must be {lo} to {hi} m"
            ));
        }
        self.validate_commands()?;
        for (name, hz) in self.rates.named() {
            if !(hz.is_finite() && (0.0..=MAX_RATE_HZ).contains(&hz)) {
                return Err(format!(
                    "mavlink.rates.{name} = {hz}: must be 0 (off) to {MAX_RATE_HZ}"
                ));
            }
        }
        Ok(())
    }

    /// Checks the signing and command fields.
    fn validate_commands(&self) -> Result<(), String> {
        if let Some(path) = &self.signing_key_file {
            if path.is_empty() {
                return Err(
                    "mavlink.signing_key_file = \"\": name the key file, or remove the key to send unsigned"
                        .into(),
                );
            }
            if self.allow_unsigned_commands {
                return Err(format!(
                    "mavlink.allow_unsigned_commands = true with mavlink.signing_key_file = {path:?}: a signed link refuses unsigned commands; remove one of them"
                ));
            }
        } else if self.accept_commands && !self.allow_unsigned_commands {
            return Err(
                "mavlink.accept_commands = true without mavlink.signing_key_file: commands must be signed; set the key file, or allow_unsigned_commands = true to let anyone who can reach the link re-admit channels"
                    .into(),
            );
        }
        for (i, s) in self.command_sources.iter().enumerate() {
            if s.system == 0 {
                return Err(format!(
                    "mavlink.command_sources[{i}].system = 0: 0 is the broadcast id, use 1..=255"
                ));
            }
        }
        for (i, a) in self.command_addresses.iter().enumerate() {
            CommandAddress::parse(a)
                .map_err(|why| format!("mavlink.command_addresses[{i}] = {a:?}: {why}"))?;
        }
        let hz = self.command_ack_rate_hz;
        if !(hz.is_finite() && hz > 0.0 && hz <= MAX_ACK_RATE_HZ) {
            return Err(format!(
                "mavlink.command_ack_rate_hz = {hz}: must be above 0, at most {MAX_ACK_RATE_HZ}"
            ));
        }
        if !(1..=MAX_ACK_RATE_HZ as u32).contains(&self.command_ack_burst) {
            return Err(format!(
                "mavlink.command_ack_burst = {}: must be 1..={}",
                self.command_ack_burst, MAX_ACK_RATE_HZ as u32
            ));
        }
        Ok(())
    }

    /// The parsed `command_addresses`; an entry that does not parse is left out (a validated
    /// configuration has none).
    pub fn command_addresses(&self) -> Vec<CommandAddress> {
        self.command_addresses
            .iter()
            .filter_map(|a| CommandAddress::parse(a).ok())
            .collect()
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

    /// The autopilot this configuration shapes ODOMETRY for. A bench display is never beside a
    /// real autopilot, so it takes only `generic`.
    pub fn autopilot(&self) -> Result<Autopilot, String> {
        let autopilot = Autopilot::parse(&self.autopilot)?;
        if autopilot != Autopilot::Generic && matches!(self.profile(), Ok(Profile::Display { .. }))
        {
            return Err(format!(
                "mavlink.autopilot = {:?} with mavlink.profile = \"display\": the display profile is never beside an autopilot; use \"generic\" or the \"onboard\" profile",
                self.autopilot
            ));
        }
        Ok(autopilot)
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

    /// Asserts that `c` is refused with an error that starts with `start`.
    #[track_caller]
    fn assert_refused(c: &MavlinkConfig, start: &str) {
        let e = c.validate().unwrap_err();
        assert!(e.starts_with(start), "{e}");
    }

    #[test]
    fn defaults_are_valid_and_off() {
        let c = MavlinkConfig::default();
        assert_eq!(c.validate(), Ok(()));
        assert!(!c.enabled);
        assert_eq!(c.profile(), Ok(Profile::Onboard));
        assert_eq!(c.speaking_component(), 197);
        assert_eq!(c.autopilot(), Ok(Autopilot::Generic));
    }

    #[test]
    fn the_autopilot_parses_and_a_display_takes_only_generic() {
        let c: MavlinkConfig = toml::from_str("autopilot = \"ardupilot\"").unwrap();
        assert_eq!(c.validate(), Ok(()));
        assert_eq!(c.autopilot(), Ok(Autopilot::Ardupilot));
        let bad = MavlinkConfig {
            autopilot: "apm".into(),
            ..MavlinkConfig::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .starts_with("mavlink.autopilot = \"apm\": must be one of generic, px4, ardupilot")
        );
        let display = MavlinkConfig {
            profile: "display".into(),
            autopilot: "px4".into(),
            ..MavlinkConfig::default()
        };
        assert_refused(
            &display,
            "mavlink.autopilot = \"px4\" with mavlink.profile = \"display\"",
        );
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
        for sigma in [0.0, -5.0, 0.001, 1e5, f64::NAN, f64::INFINITY] {
            let c = MavlinkConfig {
                odometry_quality_sigma_m: sigma,
                ..MavlinkConfig::default()
            };
            assert_refused(&c, &format!("mavlink.odometry_quality_sigma_m = {sigma}:"));
        }
        assert!(
            bad(|c| {
                c.enabled = true;
                c.endpoints.clear();
            })
            .starts_with("mavlink.endpoints = []")
        );
    }

    #[test]
    fn commands_need_a_key_or_an_explicit_opt_out() {
        let accepting = MavlinkConfig {
            accept_commands: true,
            ..MavlinkConfig::default()
        };
        assert_refused(
            &accepting,
            "mavlink.accept_commands = true without mavlink.signing_key_file",
        );
        let unsigned = MavlinkConfig {
            allow_unsigned_commands: true,
            ..accepting.clone()
        };
        assert_eq!(unsigned.validate(), Ok(()));
        let signed = MavlinkConfig {
            signing_key_file: Some("/etc/rins/mavlink.key".into()),
            ..accepting.clone()
        };
        assert_eq!(signed.validate(), Ok(()));
        let both = MavlinkConfig {
            allow_unsigned_commands: true,
            ..signed.clone()
        };
        assert_refused(
            &both,
            "mavlink.allow_unsigned_commands = true with mavlink.signing_key_file = \"/etc/rins/mavlink.key\"",
        );
    }

    #[test]
    fn command_fields_name_the_field_and_value() {
        let bad = |f: fn(&mut MavlinkConfig)| {
            let mut c = MavlinkConfig::default();
            f(&mut c);
            c.validate().unwrap_err()
        };
        assert!(
            bad(|c| c.signing_key_file = Some(String::new()))
                .starts_with("mavlink.signing_key_file = \"\"")
        );
        assert!(
            bad(|c| c.command_addresses = vec!["10.0.0.1".into(), "gcs.local".into()])
                .starts_with("mavlink.command_addresses[1] = \"gcs.local\"")
        );
        assert!(bad(|c| c.command_addresses = vec!["10.0.0.1:0".into()]).contains("port 0"));
        assert!(
            bad(|c| c.command_sources = vec![CommandSource {
                system: 0,
                component: None
            }])
            .starts_with("mavlink.command_sources[0].system = 0")
        );
        assert!(
            bad(|c| c.command_ack_rate_hz = 0.0).starts_with("mavlink.command_ack_rate_hz = 0")
        );
        assert!(
            bad(|c| c.command_ack_rate_hz = f64::INFINITY)
                .starts_with("mavlink.command_ack_rate_hz = inf")
        );
        assert!(bad(|c| c.command_ack_burst = 0).starts_with("mavlink.command_ack_burst = 0"));
    }

    #[test]
    fn the_allow_lists_parse_from_toml_and_match() {
        let c: MavlinkConfig = toml::from_str(
            r#"
            accept_commands = true
            signing_key_file = "/k"
            command_sources = [{ system = 255, component = 190 }, { system = 254 }]
            command_addresses = ["192.168.7.2", "[::1]:14550"]
            "#,
        )
        .unwrap();
        assert_eq!(c.validate(), Ok(()));
        let gcs = c.command_sources[0];
        assert!(gcs.matches(255, 190));
        assert!(!gcs.matches(255, 191));
        assert!(!gcs.matches(255 + 256, 190));
        assert!(c.command_sources[1].matches(254, 7));
        let addresses = c.command_addresses();
        let at = |s: &str| s.parse::<SocketAddr>().unwrap();
        assert!(addresses[0].matches(at("192.168.7.2:40000")));
        // The same peer seen on an IPv6 socket.
        assert!(addresses[0].matches(at("[::ffff:192.168.7.2]:40000")));
        assert!(!addresses[0].matches(at("192.168.7.3:40000")));
        assert!(addresses[1].matches(at("[::1]:14550")));
        assert!(!addresses[1].matches(at("[::1]:14551")));
    }
}
