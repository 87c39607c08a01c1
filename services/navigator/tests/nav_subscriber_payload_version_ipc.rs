//! The payload version check of the merged navigation stream over real iceoryx2 shared memory: a
//! sample written with another payload version on either lane never reaches the consumer and is
//! counted, while the samples of this build around it come through. Every consumer of the
//! navigation solution (mavlink, the watchdog's monitor, `rins echo nav`, soak) reads it this way,
//! from a node of its own or a tool's.

use ipc_types::{NavMode, NavState, PAYLOAD_VERSION, names};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::ipc::{IpcNode, SampleSource, TopicPublisher};
use rins_runtime::payload::Versioned;
use rins_test_support::private_ipc::{OTHER_VERSIONS, on_private_node, on_tool_node};

fn nav(lane: u8, version: u16, seq: u64) -> NavState {
    let mut s = NavState {
        version,
        mode: NavMode::Navigating as u8,
        lane,
        solution_start_seq: 1,
        ..NavState::default()
    };
    s.header.origin_seq = seq;
    s
}

/// The merged navigation stream drops another version on either lane (in between a contiguous
/// sequence of this build's, so that no lane looks late); the lane totals count only what was
/// taken in.
fn nav_subscriber_rejects(node: &IpcNode) {
    let mut sub = NavSubscriber::new(node).expect("subscriber");
    let lanes = names::NAV_LANES.map(|t| TopicPublisher::<NavState>::new(node, t).expect("lane"));
    for (lane, publisher) in (0u8..).zip(&lanes) {
        for (seq, other) in (1..=3).zip(OTHER_VERSIONS) {
            publisher
                .publish(nav(lane, PAYLOAD_VERSION, seq))
                .expect("publish");
            publisher
                .publish(nav(lane, other, 100 + seq))
                .expect("publish");
        }
        publisher
            .publish(nav(lane, PAYLOAD_VERSION, 3))
            .expect("publish");
    }
    let mut got = Vec::new();
    while let Some(s) = sub.receive().expect("receive") {
        assert!(s.is_current(), "{s:?}");
        got.push((s.header.origin_seq, s.lane));
    }
    assert_eq!(got, [(1, 0), (2, 0), (3, 0)]);
    assert_eq!(sub.rejected(), 4);
    assert_eq!(SampleSource::rejected(&sub), 4);
    assert_eq!(sub.lane_totals(), [3, 3]);
}

/// A service (mavlink, the watchdog) reads the stream from a node of its own.
#[test]
fn the_navigation_stream_drops_another_version_on_either_lane() {
    on_private_node("nv", nav_subscriber_rejects);
}

/// A tool (`rins echo nav`) reads it from the tool's node.
#[test]
fn a_tools_navigation_stream_drops_another_version() {
    on_tool_node("tl", nav_subscriber_rejects);
}
