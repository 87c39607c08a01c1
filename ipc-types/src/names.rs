//! Service names: each topic's constant, generated from the topic table
//! ([`crate::for_each_topic!`]), the one place where topics are named.

/// Generates a constant per topic and the list of the short names `rins echo` accepts.
macro_rules! topic_names {
    ($(
        $payload:ident ($kind:ident) {
            $(
                $(#[$meta:meta])*
                $constant:ident = $topic:literal
                    $(, echo $echo:literal)?
                    $(, record $short:literal at $rank:literal)?;
            )+
        }
    )+) => {
        $($(
            $(#[$meta])*
            pub const $constant: &str = $topic;
        )+)+

        /// Every topic with its `rins echo` short name, if it has one, in table order.
        const ECHO_NAMES: &[(Option<&str>, &str)] = &[$($(
            (topic_names!(@some $($echo)?), $topic),
        )+)+];
    };
    (@some) => { None };
    (@some $echo:literal) => { Some($echo) };
}

crate::for_each_topic!(topic_names);

/// Output topic of each navigator lane: lane 0 (primary) publishes on [`NAV_STATE`], so a
/// single-lane deployment needs nothing else; lane 1 is the hot standby. Consumers that want the
/// contiguous stream read both through the navigator's lane selector (`rins_navigator::lanes`).
pub const NAV_LANES: [&str; 2] = [NAV_STATE, NAV_STATE_STANDBY];

const ECHO_COUNT: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < ECHO_NAMES.len() {
        if ECHO_NAMES[i].0.is_some() {
            n += 1;
        }
        i += 1;
    }
    n
};

/// Every published topic, with the short name `rins echo` accepts.
pub const TOPICS: [(&str, &str); ECHO_COUNT] = {
    let mut out = [("", ""); ECHO_COUNT];
    let mut n = 0;
    let mut i = 0;
    while i < ECHO_NAMES.len() {
        if let (Some(short), topic) = ECHO_NAMES[i] {
            out[n] = (short, topic);
            n += 1;
        }
        i += 1;
    }
    out
};

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
                "fused-imu",
                "altitude",
                "nav",
                "truth",
                "heartbeat",
                "health",
                "raw-airspeed"
            ]
        );
        assert_eq!(TOPICS[7], ("nav", "rins/nav/state"));
        assert_eq!(NAV_LANES, ["rins/nav/state", "rins/nav/state/standby"]);
    }
}
