//! A subscriber that never takes its notifications off the listener (a polling stage between
//! sleeps, a standby reading in batches, a lane's peer topic read only while it aligns) must not
//! make its publisher fail: thousands of samples published to it all succeed and all arrive, and
//! one clear takes every notification off, so that the next wait sleeps.

use std::time::Duration;

use ipc_types::NavState;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, create_node};
use rins_runtime::shm_cleanup;

#[test]
fn notifications_left_unread_never_fail_the_publisher() {
    let settings = IpcSettings::new(
        format!("rtunread{}_", std::process::id()),
        std::env::temp_dir()
            .join(format!("rtunread{}root/", std::process::id()))
            .to_string_lossy()
            .into_owned(),
    );
    {
        let node = create_node("unread", &settings).expect("node");
        let subscriber = TopicSubscriber::<NavState>::new(&node, "unread").expect("subscriber");
        let publisher = TopicPublisher::<NavState>::new(&node, "unread").expect("publisher");
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
    }
    shm_cleanup::remove_all(&settings, true);
    let _ = std::fs::remove_dir_all(&settings.root);
    assert!(shm_cleanup::shm_entries(&settings).is_empty());
}
