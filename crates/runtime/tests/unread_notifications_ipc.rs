//! A subscriber that never takes its notifications off the listener (a polling stage between
//! sleeps, a standby reading in batches, a lane's peer topic read only while it aligns) must not
//! make its publisher fail: thousands of samples published to it all succeed and all arrive, and
//! one clear takes every notification off, so that the next wait sleeps.

use std::time::Duration;

use ipc_types::NavState;
use rins_runtime::ipc::{TopicPublisher, TopicSubscriber};
use rins_test_support::private_ipc::on_private_node;

#[test]
fn notifications_left_unread_never_fail_the_publisher() {
    on_private_node("unread", |node| {
        let subscriber = TopicSubscriber::<NavState>::new(node, "unread").expect("subscriber");
        let publisher = TopicPublisher::<NavState>::new(node, "unread").expect("publisher");
        // Far more notifications than a listener's socket holds; samples read as they come (the
        // queue is finite), notifications never.
        let mut received = 0u64;
        for seq in 1..=20_000u64 {
            let mut sample = NavState::default();
            sample.header.origin_seq = seq;
            publisher
                .publish(sample)
                .expect("a full listener fails no publish");
            while let Some(s) = subscriber.receive().expect("receive") {
                received += 1;
                assert_eq!(s.header.origin_seq, received);
            }
        }
        assert_eq!(received, 20_000);
        subscriber.clear_signals().expect("clear");
        assert!(
            !subscriber.wait(Duration::from_millis(20)).expect("wait"),
            "every notification was taken off"
        );
    });
}
