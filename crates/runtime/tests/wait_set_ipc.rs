//! Waiting on many topics at once over real iceoryx2 shared memory: a sample on any one of six
//! topics wakes the waiter (no limit on the number of topics), and the signal is consumed by the
//! wait that reported it.

use std::time::Duration;

use ipc_types::NavState;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, TopicWaitSet, create_node};
use rins_runtime::shm_cleanup;

const TOPICS: [&str; 6] = ["wait-a", "wait-b", "wait-c", "wait-d", "wait-e", "wait-f"];

#[test]
fn a_sample_on_any_of_six_topics_wakes_the_wait_once() {
    let settings = IpcSettings::new(
        format!("rtwait{}_", std::process::id()),
        std::env::temp_dir()
            .join(format!("rtwait{}root/", std::process::id()))
            .to_string_lossy()
            .into_owned(),
    );
    {
        let node = create_node("waiter", &settings).expect("node");
        let subscribers: Vec<TopicSubscriber<NavState>> = TOPICS
            .iter()
            .map(|t| TopicSubscriber::new(&node, t).expect("subscriber"))
            .collect();
        let publishers: Vec<TopicPublisher<NavState>> = TOPICS
            .iter()
            .map(|t| TopicPublisher::new(&node, t).expect("publisher"))
            .collect();
        let topics: Vec<&TopicSubscriber<NavState>> = subscribers.iter().collect();
        let waitset = TopicWaitSet::new(&topics).expect("wait set");
        let short = Duration::from_millis(20);

        assert!(!waitset.wait(short).expect("wait"), "nothing sent");
        for (i, publisher) in publishers.iter().enumerate().rev() {
            let mut sample = NavState::default();
            sample.header.origin_seq = 100 + i as u64;
            publisher.publish(sample).expect("publish");
            assert!(
                waitset.wait(Duration::from_secs(30)).expect("wait"),
                "a sample on {} wakes the wait",
                TOPICS[i]
            );
            assert_eq!(
                subscribers[i]
                    .receive()
                    .expect("receive")
                    .map(|s| s.header.origin_seq),
                Some(100 + i as u64)
            );
            // Reported once: the next wait sleeps until its timeout.
            assert!(!waitset.wait(short).expect("wait"), "{}", TOPICS[i]);
        }
    }
    shm_cleanup::remove_all(&settings, true);
    let _ = std::fs::remove_dir_all(&settings.root);
    assert!(shm_cleanup::shm_entries(&settings).is_empty());
}
