//! How a publisher appears on the ROS 2 graph of rmw_zenoh (ROS 2's Zenoh middleware), following
//! its design document (`docs/design.md` of ros2/rmw_zenoh, "Topic and Service name mapping to
//! Zenoh key expressions" and "Graph Cache"): the key expression a topic's samples travel on, and
//! the liveliness tokens by which nodes discover the node and its publishers (`ros2 node list`,
//! `ros2 topic list`). Pure functions of names; the session around them declares the tokens.

/// A message type as rmw_zenoh names it: the DDS-mangled type name and the type description hash
/// (REP 2011, `RIHS01_` and the SHA-256 of the type's description, as ROS 2 Jazzy generates it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RosType {
    /// `package::msg::dds_::Name_`.
    pub dds_name: &'static str,
    /// `RIHS01_` and 64 lowercase hexadecimal digits.
    pub hash: &'static str,
}

/// `nav_msgs/msg/Odometry`.
pub const ODOMETRY: RosType = RosType {
    dds_name: "nav_msgs::msg::dds_::Odometry_",
    hash: "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0",
};
/// `sensor_msgs/msg/Imu`.
pub const IMU: RosType = RosType {
    dds_name: "sensor_msgs::msg::dds_::Imu_",
    hash: "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b",
};
/// `sensor_msgs/msg/NavSatFix`.
pub const NAV_SAT_FIX: RosType = RosType {
    dds_name: "sensor_msgs::msg::dds_::NavSatFix_",
    hash: "RIHS01_62223ab3fe210a15976021da7afddc9e200dc9ec75231c1b6a557fc598a65404",
};
/// `diagnostic_msgs/msg/DiagnosticArray`.
pub const DIAGNOSTIC_ARRAY: RosType = RosType {
    dds_name: "diagnostic_msgs::msg::dds_::DiagnosticArray_",
    hash: "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e",
};

/// The publishers' quality of service as rmw_zenoh's liveliness tokens spell it: reliable,
/// volatile, keep the last 10, no deadline, no lifespan, automatic liveliness. Every field is
/// written out, so that every rmw_zenoh release reads the same (an empty field means that
/// release's own default, and the defaults changed between releases).
pub const QOS_RELIABLE_VOLATILE_LAST_10: &str = "1:2:1,10:,:,:,,";

/// The fully qualified topic name `namespace/topic` (`/` alone as the namespace gives `/topic`).
pub fn topic_name(namespace: &str, topic: &str) -> String {
    if topic.starts_with('/') {
        return topic.to_string();
    }
    format!("{}/{topic}", namespace.trim_end_matches('/'))
}

/// `/` of a ROS name as rmw_zenoh writes it inside a liveliness token: `%` (a token's parts are
/// separated by `/`).
fn mangle(name: &str) -> String {
    name.replace('/', "%")
}

/// The key expression a topic's samples are put on:
/// `<domain>/<topic without its leading slash>/<type>/<hash>`.
pub fn topic_key(domain: u32, topic: &str, ty: RosType) -> String {
    format!(
        "{domain}/{}/{}/{}",
        topic.trim_matches('/'),
        ty.dds_name,
        ty.hash
    )
}

/// Who declares the tokens: the Zenoh session's id and the node's place on the graph.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeIdentity {
    /// The ROS domain id.
    pub domain: u32,
    /// The Zenoh session id as Zenoh prints it.
    pub zid: String,
    /// The node's entity id within the session.
    pub node_id: u32,
    /// The node's namespace (`/` or `/a/b`).
    pub namespace: String,
    /// The node's name.
    pub name: String,
}

impl NodeIdentity {
    /// `<domain>/<zid>/<node id>/<entity id>/<kind>/<enclave>/<namespace>/<name>`, the prefix
    /// every token of this node starts with after `@ros2_lv/`. The enclave is the root, `/`.
    fn entity(&self, entity_id: u32, kind: &str) -> String {
        format!(
            "@ros2_lv/{}/{}/{}/{entity_id}/{kind}/%/{}/{}",
            self.domain,
            self.zid,
            self.node_id,
            mangle(&self.namespace),
            self.name
        )
    }

    /// The node's liveliness token (kind `NN`, its own id as the entity id).
    pub fn node_token(&self) -> String {
        self.entity(self.node_id, "NN")
    }

    /// The liveliness token of a publisher (kind `MP`) of `ty` on `topic` (fully qualified).
    pub fn publisher_token(&self, entity_id: u32, topic: &str, ty: RosType) -> String {
        format!(
            "{}/{}/{}/{}/{QOS_RELIABLE_VOLATILE_LAST_10}",
            self.entity(entity_id, "MP"),
            mangle(topic),
            ty.dds_name,
            ty.hash
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_and_tokens_are_spelled_as_rmw_zenoh_spells_them() {
        // The forms of rmw_zenoh's design document, with its String example's layout.
        assert_eq!(topic_name("/rins", "odom"), "/rins/odom");
        assert_eq!(topic_name("/", "odom"), "/odom");
        assert_eq!(topic_name("/rins", "/diagnostics"), "/diagnostics");
        assert_eq!(
            topic_key(0, "/rins/odom", ODOMETRY),
            "0/rins/odom/nav_msgs::msg::dds_::Odometry_/RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"
        );
        let me = NodeIdentity {
            domain: 2,
            zid: "8b20917502ee955ac4476e0266340d5c".into(),
            node_id: 0,
            namespace: "/".into(),
            name: "talker".into(),
        };
        assert_eq!(
            me.node_token(),
            "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/0/NN/%/%/talker"
        );
        let ns = NodeIdentity {
            namespace: "/rins".into(),
            name: "rins".into(),
            ..me
        };
        assert_eq!(
            ns.publisher_token(3, "/rins/imu", IMU),
            "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/3/MP/%/%rins/rins/%rins%imu/sensor_msgs::msg::dds_::Imu_/RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b/1:2:1,10:,:,:,,"
        );
    }

    #[test]
    fn every_hash_is_rihs01_and_sha256_long() {
        for t in [ODOMETRY, IMU, NAV_SAT_FIX, DIAGNOSTIC_ARRAY] {
            let hex = t.hash.strip_prefix("RIHS01_").expect(t.hash);
            assert_eq!(hex.len(), 64, "{}", t.dds_name);
            assert!(
                hex.chars()
                    .all(|c| c.is_ascii_digit() || ('a'..='f').contains(&c))
            );
        }
    }
}
