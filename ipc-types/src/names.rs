//! Service names: each topic's constant, generated from the topic table
//! ([`crate::for_each_topic!`]), the one place where topics are named.

/// A constant per topic, named and documented as in the table.
macro_rules! topic_constants {
    ($($(#[$doc:meta])* $constant:ident $topic:literal $payload:ident $kind:ident;)+) => {$(
        $(#[$doc])*
        pub const $constant: &str = $topic;
    )+};
}

crate::for_each_topic!(topics => topic_constants);

/// The topics `rins echo` shows, by the short name it accepts.
macro_rules! echo_topics {
    ($($short:literal $constant:ident $payload:ident $kind:ident;)+) => {
        /// Every published topic, with the short name `rins echo` accepts, in table order.
        pub const TOPICS: [(&str, &str); [$($short),+].len()] = [$(($short, $constant)),+];
    };
}

crate::for_each_topic!(echo => echo_topics);

/// Output topic of each navigator lane: lane 0 (primary) publishes on [`NAV_STATE`], so a
/// single-lane deployment needs nothing else; lane 1 is the hot standby. Consumers that want the
/// contiguous stream read both through the navigator's lane selector (`rins_navigator::lanes`).
pub const NAV_LANES: [&str; 2] = [NAV_STATE, NAV_STATE_STANDBY];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_echo_short_names_are_the_table_order_of_the_topics_that_have_one() {
        let shorts: Vec<&str> = TOPICS.iter().map(|(s, _)| *s).collect();
        assert_eq!(
            shorts,
            [
                "raw-imu",
                "raw-baro",
                "raw-mag",
                "raw-aux",
                "gnss",
                "gnss-link",
                "fused-imu",
                "altitude",
                "nav",
                "truth",
                "heartbeat",
                "health",
                "raw-airspeed"
            ]
        );
        assert_eq!(TOPICS[8], ("nav", "rins/nav/state"));
        assert_eq!(NAV_LANES, ["rins/nav/state", "rins/nav/state/standby"]);
    }
}
