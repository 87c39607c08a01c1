//! Which payload each topic carries, for a recorder that subscribes by name.

use ipc_types::names;

use crate::schema::{self, StructLayout};

/// Lists every topic of the topic table with its payload's layout.
macro_rules! topic_layouts {
    ($($(#[$doc:meta])* $constant:ident $topic:literal $payload:ident $kind:ident;)+) => {
        /// Every topic a recording may hold, with the layout of the payload it carries: the
        /// pipeline's outputs, both navigator lanes, supervision, and the commands with their
        /// answers.
        pub static TOPICS: [(&str, &StructLayout); TOPIC_COUNT] = [$(
            (names::$constant, schema::layout_of::<ipc_types::$payload>()),
        )+];

        const TOPIC_COUNT: usize = [$(names::$constant),+].len();
    };
}

ipc_types::for_each_topic!(topics => topic_layouts);

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
