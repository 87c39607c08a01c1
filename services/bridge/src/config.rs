//! `[zenoh]`: whether the bridge runs, where it connects or listens, how it names itself and its
//! topics on the ROS 2 graph, and which topics it publishes at which rate. Off unless configured;
//! only the topics with a rate above zero are published, and the bridge takes nothing in.

use serde::{Deserialize, Serialize};

use crate::endpoint::Endpoint;

/// The highest ROS domain id (ROS 2's own limit, from the DDS port arithmetic it shares).
pub const MAX_DOMAIN_ID: u32 = 232;

/// The bridge's configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ZenohConfig {
    /// Whether `rins up` starts the bridge.
    pub enabled: bool,
    /// Zenoh routers or peers to connect to (`tcp/HOST:PORT`, `tls/HOST:PORT`); an unreachable
    /// one is retried with backoff.
    pub connect: Vec<String>,
    /// Endpoints to listen on for peers and routers (`tcp/ADDR:PORT`, `tls/ADDR:PORT`).
    pub listen: Vec<String>,
    /// Zenoh session mode: `peer` (as ROS 2 nodes with rmw_zenoh run: discovery through the
    /// router, data directly) or `client` (everything through the router it connects to).
    pub mode: String,
    /// The ROS domain id (`ROS_DOMAIN_ID` of the nodes that read rins), 0 to 232.
    pub domain_id: u32,
    /// The ROS namespace of the node and its topics, e.g. `/rins` (topics `/rins/odom`, ...).
    pub namespace: String,
    /// The ROS node name rins appears as.
    pub node_name: String,
    /// The world frame of the odometry's pose (REP 105), ENU about the first solution's position.
    pub world_frame: String,
    /// The body frame (FLU) of the twist and the IMU.
    pub body_frame: String,
    /// Zenoh's own configuration file (JSON5): TLS certificates, mutual TLS, access control,
    /// anything `connect`/`listen` do not say. `connect`, `listen` and `mode` above override its
    /// values. A regular file owned by the user rins runs as, no write permission for others.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub config_file: Option<String>,
    /// Samples waiting between the IPC side and the network; beyond it they are dropped and
    /// counted (`lost` in the heartbeat), never waited for.
    pub queue_capacity: usize,
    /// `[zenoh.rates]`: messages per second of each topic; 0 leaves the topic out.
    pub rates: ZenohRates,
}

/// Messages per second of each topic, decimated by the samples' measurement time; 0: not
/// published.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ZenohRates {
    /// `odom` (`nav_msgs/msg/Odometry`).
    pub odometry_hz: f64,
    /// `imu` (`sensor_msgs/msg/Imu`, the fused IMU).
    pub imu_hz: f64,
    /// `fix` (`sensor_msgs/msg/NavSatFix`, the navigation's position).
    pub nav_sat_fix_hz: f64,
    /// `/diagnostics` (`diagnostic_msgs/msg/DiagnosticArray`, the watchdog's report).
    pub diagnostics_hz: f64,
}

impl Default for ZenohRates {
    fn default() -> Self {
        Self {
            odometry_hz: 50.0,
            imu_hz: 100.0,
            nav_sat_fix_hz: 5.0,
            diagnostics_hz: 1.0,
        }
    }
}

impl Default for ZenohConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            connect: Vec::new(),
            listen: Vec::new(),
            mode: "peer".into(),
            domain_id: 0,
            namespace: "/rins".into(),
            node_name: "rins".into(),
            world_frame: "map".into(),
            body_frame: "base_link".into(),
            config_file: None,
            queue_capacity: 256,
            rates: ZenohRates::default(),
        }
    }
}

/// A ROS name part: letters, digits and underscores, not starting with a digit (ROS 2's rule for
/// node names and the tokens of namespaces and topics).
fn ros_token(text: &str) -> bool {
    text.chars().next().is_some_and(|c| !c.is_ascii_digit())
        && text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// A frame id: what tf2 takes (no leading slash, no spaces).
fn frame_id(text: &str) -> bool {
    !text.is_empty() && !text.starts_with('/') && text.chars().all(|c| c.is_ascii_graphic())
}

impl ZenohConfig {
    /// Checks every field; the error names it with its value.
    pub fn validate(&self) -> Result<(), String> {
        for (field, list) in [("connect", &self.connect), ("listen", &self.listen)] {
            for e in list {
                Endpoint::parse(e).map_err(|why| format!("zenoh.{field} {e:?}: {why}"))?;
            }
        }
        if self.enabled && self.connect.is_empty() && self.listen.is_empty() {
            return Err(
                "zenoh.enabled = true with neither zenoh.connect nor zenoh.listen: say where the bridge reaches the network"
                    .into(),
            );
        }
        if !matches!(self.mode.as_str(), "peer" | "client") {
            return Err(format!(
                "zenoh.mode = {:?}: must be \"peer\" or \"client\"",
                self.mode
            ));
        }
        if self.mode == "client" && self.connect.is_empty() && self.enabled {
            return Err("zenoh.mode = \"client\" needs a router in zenoh.connect".into());
        }
        if self.domain_id > MAX_DOMAIN_ID {
            return Err(format!(
                "zenoh.domain_id = {}: must be 0..={MAX_DOMAIN_ID}",
                self.domain_id
            ));
        }
        let ns_ok = self.namespace == "/"
            || (self.namespace.starts_with('/') && self.namespace[1..].split('/').all(ros_token));
        if !ns_ok {
            return Err(format!(
                "zenoh.namespace = {:?}: must be \"/\" or /NAME[/NAME...] with names of letters, digits and _",
                self.namespace
            ));
        }
        if !ros_token(&self.node_name) {
            return Err(format!(
                "zenoh.node_name = {:?}: letters, digits and _, not starting with a digit",
                self.node_name
            ));
        }
        for (field, value) in [
            ("world_frame", &self.world_frame),
            ("body_frame", &self.body_frame),
        ] {
            if !frame_id(value) {
                return Err(format!(
                    "zenoh.{field} = {value:?}: a frame id without a leading slash or spaces"
                ));
            }
        }
        if !(1..=65_536).contains(&self.queue_capacity) {
            return Err(format!(
                "zenoh.queue_capacity = {}: must be 1..=65536",
                self.queue_capacity
            ));
        }
        let r = &self.rates;
        for (field, hz) in [
            ("odometry_hz", r.odometry_hz),
            ("imu_hz", r.imu_hz),
            ("nav_sat_fix_hz", r.nav_sat_fix_hz),
            ("diagnostics_hz", r.diagnostics_hz),
        ] {
            if !(hz.is_finite() && (0.0..=10_000.0).contains(&hz)) {
                return Err(format!(
                    "zenoh.rates.{field} = {hz}: must be 0 (off) to 10000 Hz"
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ZenohConfig, String> {
        let c: ZenohConfig = toml::from_str(text).map_err(|e| e.to_string())?;
        c.validate().map(|()| c)
    }

    #[test]
    fn the_defaults_are_off_and_valid() {
        let c = parse("").unwrap();
        assert!(!c.enabled);
        assert_eq!(c.rates.odometry_hz, 50.0);
        parse("enabled = true\nconnect = [\"tcp/10.0.0.2:7447\"]").unwrap();
    }

    #[test]
    fn bad_values_are_refused_naming_the_field_and_the_value() {
        for (text, needle) in [
            ("enabled = true", "neither zenoh.connect"),
            (
                "connect = [\"udp/1.2.3.4:1\"]",
                "zenoh.connect \"udp/1.2.3.4:1\"",
            ),
            ("listen = [\"tcp/0.0.0.0\"]", "zenoh.listen"),
            ("mode = \"router\"", "zenoh.mode = \"router\""),
            ("domain_id = 233", "zenoh.domain_id = 233"),
            ("namespace = \"rins\"", "zenoh.namespace = \"rins\""),
            ("namespace = \"/a//b\"", "zenoh.namespace"),
            ("node_name = \"9lives\"", "zenoh.node_name"),
            ("world_frame = \"/map\"", "zenoh.world_frame"),
            ("queue_capacity = 0", "zenoh.queue_capacity = 0"),
            ("[rates]\nimu_hz = -1.0", "zenoh.rates.imu_hz = -1"),
            (
                "[rates]\nodometry_hz = nan",
                "zenoh.rates.odometry_hz = NaN",
            ),
            ("colour = 1", "unknown field"),
        ] {
            let err = parse(text).unwrap_err();
            assert!(err.contains(needle), "{text}: {err}");
        }
    }
}
