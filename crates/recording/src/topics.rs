//! Which payload each topic carries, for a recorder that subscribes by name.

use ipc_types::names;

use crate::schema::{self, StructLayout};

/// Every topic a recording may hold, with the layout of the payload it carries: the pipeline's
/// outputs, both navigator lanes, supervision, and the commands with their answers.
pub static TOPICS: [(&str, &StructLayout); 16] = [
    (names::RAW_IMU, &schema::RAW_IMU),
    (names::RAW_BARO, &schema::RAW_BARO),
    (names::RAW_MAG, &schema::RAW_MAG),
    (names::RAW_AUX, &schema::RAW_AUX),
    (names::GNSS, &schema::GNSS_FIX),
    (names::FUSED_IMU, &schema::FUSED_IMU),
    (names::ALTITUDE, &schema::ALTITUDE),
    (names::NAV_LANES[0], &schema::NAV_STATE),
    (names::NAV_LANES[1], &schema::NAV_STATE),
    (names::TRUTH, &schema::TRUTH),
    (names::HEARTBEAT, &schema::HEALTH),
    (names::HEALTH, &schema::HEALTH_REPORT),
    (names::SIM_FAULT_APPLIED, &schema::FAULT_APPLIED),
    (names::SIM_CONTROL, &schema::SIM_CONTROL),
    (names::FUSION_CONTROL, &schema::FUSION_CONTROL),
    (names::FUSION_REPLY, &schema::FUSION_REPLY),
];

/// The layout of the payload published on `topic`, `None` for a topic rins does not publish.
pub fn layout_of_topic(topic: &str) -> Option<&'static StructLayout> {
    TOPICS.iter().find(|(t, _)| *t == topic).map(|(_, l)| *l)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_topic_appears_once_and_every_short_named_topic_is_covered() {
        for (i, (topic, _)) in TOPICS.iter().enumerate() {
            assert!(
                TOPICS[i + 1..].iter().all(|(t, _)| t != topic),
                "{topic} listed twice"
            );
        }
        for (_, topic) in names::TOPICS {
            assert!(layout_of_topic(topic).is_some(), "{topic} has no layout");
        }
    }
}
