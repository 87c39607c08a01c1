//! The merged navigation stream over real iceoryx2 shared memory: a consumer that slept through a
//! backlog of both lanes still gets every sample once, in order.

use ipc_types::{NavMode, NavState, names};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, create_node};
use rins_runtime::shm_cleanup;
use rins_test_support::private_ipc::on_private_node;

fn nav(lane: u8, seq: u64) -> NavState {
    let mut s = NavState {
        mode: NavMode::Navigating as u8,
        lane,
        solution_start_seq: 1,
        ..NavState::default()
    };
    s.header.origin_seq = seq;
    s
}

#[test]
fn a_backlog_of_both_lanes_is_delivered_whole() {
    let settings = IpcSettings::new(
        format!("lnav{}_", std::process::id()),
        std::env::temp_dir()
            .join(format!("lnav{}root/", std::process::id()))
            .to_string_lossy()
            .into_owned(),
    );
    {
        let node = create_node("lanes", &settings).expect("node");
        let mut sub = NavSubscriber::new(&node).expect("subscriber");
        let primary = TopicPublisher::<NavState>::new(&node, names::NAV_LANES[0]).expect("lane 0");
        let standby = TopicPublisher::<NavState>::new(&node, names::NAV_LANES[1]).expect("lane 1");
        // 300 samples of each lane queue up while the consumer sleeps: far more than the
        // selector's own ring, well within the topic queue.
        for seq in 1..=300 {
            primary.publish(nav(0, seq)).expect("publish");
            standby.publish(nav(1, seq)).expect("publish");
        }
        let mut got = Vec::new();
        while let Some(s) = sub.receive().expect("receive") {
            got.push((s.header.origin_seq, s.lane));
        }
        assert_eq!(got.len(), 300);
        assert!(
            got.iter()
                .enumerate()
                .all(|(i, &(seq, lane))| seq == i as u64 + 1 && lane == 0)
        );
        assert_eq!(sub.lane_totals(), [300, 300]);
        // The primary stops; the standby's next samples are delivered after the switch lag.
        for seq in 301..=320 {
            standby.publish(nav(1, seq)).expect("publish");
        }
        let mut after = Vec::new();
        while let Some(s) = sub.receive().expect("receive") {
            after.push(s.header.origin_seq);
        }
        assert_eq!(after, (301..=320).collect::<Vec<_>>());
        assert_eq!(sub.selected_lane(), 1);
    }
    shm_cleanup::remove_all(&settings, true);
    let _ = std::fs::remove_dir_all(&settings.root);
    assert!(shm_cleanup::shm_entries(&settings).is_empty());
}

/// The standby publishes in batches while the primary serves. A primary that skips samples (it took
/// the standby's solution over) leaves a hole the standby's batch covers: the consumer fills all of
/// it, not only the first sample, even though the batch and the primary's next sample are queued
/// together.
#[test]
fn a_hole_in_the_primary_is_filled_whole_from_the_standbys_batch() {
    on_private_node("lanehole", |node| {
        let mut sub = NavSubscriber::new(node).expect("subscriber");
        let primary = TopicPublisher::<NavState>::new(node, names::NAV_LANES[0]).expect("lane 0");
        let standby = TopicPublisher::<NavState>::new(node, names::NAV_LANES[1]).expect("lane 1");
        for seq in 1..=10 {
            primary.publish(nav(0, seq)).expect("publish");
        }
        let mut got = Vec::new();
        while let Some(s) = sub.receive().expect("receive") {
            got.push(s.header.origin_seq);
        }
        // The standby's batch up to 22, then the primary goes on at 23 (11..=22 skipped).
        for seq in 1..=22 {
            standby.publish(nav(1, seq)).expect("publish");
        }
        for seq in 23..=30 {
            primary.publish(nav(0, seq)).expect("publish");
        }
        while let Some(s) = sub.receive().expect("receive") {
            got.push(s.header.origin_seq);
        }
        assert_eq!(got, (1..=30).collect::<Vec<_>>());
        assert_eq!(sub.selected_lane(), 0, "a hole is filled, not switched for");
        assert_eq!(sub.filled(), 12);
    });
}
