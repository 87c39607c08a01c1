//! The payload version check over real iceoryx2 shared memory, for every kind of consumer: a sample
//! written with another payload version, on any topic a consumer reads, never reaches it and is
//! counted by the reader that dropped it, while the samples of this build around it come through.
//! The merged navigation stream (both navigator lanes) is checked with its subscriber, in
//! rins-navigator's `nav_subscriber_payload_version_ipc` tests.

use std::fmt::Debug;

use iceoryx2::prelude::ZeroCopySend;
use ipc_types::{
    Altitude, FaultApplied, FusedImu, FusionControl, FusionReply, GnssFix, Health, HealthReport,
    NavState, PAYLOAD_VERSION, RawAux, RawBaro, RawImu, RawMag, SimControl, Truth, names,
};
use rins_runtime::ipc::{IpcNode, SampleSource, TopicPublisher, TopicSubscriber};
use rins_runtime::payload::{Received, Versioned};
use rins_runtime::stage_io::StageInput;
use rins_test_support::private_ipc::{OTHER_VERSIONS, on_private_node, on_tool_node};

/// A payload the test can write with any version; `seq` tells the samples apart.
trait TestPayload: Versioned + Debug + ZeroCopySend + Copy + 'static {
    fn with(version: u16, seq: u64) -> Self;
    fn seq(&self) -> u64;
}

macro_rules! with_header {
    ($($t:ty),*) => {$(
        impl TestPayload for $t {
            fn with(version: u16, seq: u64) -> Self {
                let mut s = <$t>::default();
                s.version = version;
                s.header.origin_seq = seq;
                s
            }

            fn seq(&self) -> u64 {
                self.header.origin_seq
            }
        }
    )*};
}

with_header!(
    RawImu, RawBaro, RawMag, RawAux, GnssFix, FusedImu, Altitude, NavState, Truth
);

/// Payloads without a header: the sequence travels in a field of their own.
macro_rules! without_header {
    ($($t:ty => $field:ident: $ty:ty),*) => {$(
        impl TestPayload for $t {
            fn with(version: u16, seq: u64) -> Self {
                let mut s = <$t>::default();
                s.version = version;
                s.$field = seq as $ty;
                s
            }

            fn seq(&self) -> u64 {
                self.$field as u64
            }
        }
    )*};
}

without_header!(
    Health => now_ns: u64,
    HealthReport => uptime_ms: u64,
    FaultApplied => device_time_us: u64,
    FusionControl => request_id: u32,
    FusionReply => request_id: u32,
    SimControl => channel: u8
);

/// Publishes, on `topic`: another version, this build's (seq 2), another version, this build's
/// (seq 4).
fn publish_mixed<T: TestPayload>(publisher: &TopicPublisher<T>) {
    publisher
        .publish(T::with(OTHER_VERSIONS[0], 1))
        .expect("publish");
    publisher
        .publish(T::with(PAYLOAD_VERSION, 2))
        .expect("publish");
    publisher
        .publish(T::with(OTHER_VERSIONS[1], 3))
        .expect("publish");
    publisher
        .publish(T::with(PAYLOAD_VERSION, 4))
        .expect("publish");
}

/// A plain reader of `topic` (mavlink's, the watchdog monitor's, a tool's) gets seq 2 and 4 only
/// and counts the two others.
fn plain_reader_rejects<T: TestPayload>(node: &IpcNode, topic: &'static str) {
    let sub = TopicSubscriber::<T>::new(node, topic).expect("subscriber");
    let publisher = TopicPublisher::<T>::new(node, topic).expect("publisher");
    publish_mixed(&publisher);
    let mut got = Vec::new();
    while let Some(s) = sub.receive().expect("receive") {
        assert!(s.is_current(), "{topic}: {s:?}");
        got.push(s.seq());
    }
    assert_eq!(got, [2, 4], "{topic}");
    assert_eq!(sub.rejected(), 2, "{topic}");
    assert_eq!(SampleSource::rejected(&sub), 2, "{topic}");
}

/// A stage's input tells the samples apart, counts the others in its counters' `rejected`, and
/// `drain` hands over only this build's.
fn stage_input_rejects<T: TestPayload>(node: &IpcNode, topic: &'static str) {
    let input = StageInput::<T>::new(node, topic).expect("input");
    let publisher = TopicPublisher::<T>::new(node, topic).expect("publisher");
    publish_mixed(&publisher);
    let mut counters = Health::default();
    let mut seen = Vec::new();
    while let Some(r) = input.receive(&mut counters).expect("receive") {
        seen.push(match r {
            Received::Current(s) => (true, s.seq()),
            Received::OtherVersion(s) => (false, s.seq()),
        });
    }
    assert_eq!(
        seen,
        [(false, 1), (true, 2), (false, 3), (true, 4)],
        "{topic}"
    );
    assert_eq!(counters.rejected, 2, "{topic}");

    publish_mixed(&publisher);
    let mut got = Vec::new();
    input
        .drain(&mut counters, |s| got.push(s.seq()))
        .expect("drain");
    assert_eq!(got, [2, 4], "{topic}");
    assert_eq!(counters.rejected, 4, "{topic}");
}

#[test]
fn stage_inputs_count_and_set_apart_another_version() {
    on_private_node("st", |node| {
        stage_input_rejects::<RawImu>(node, names::RAW_IMU);
        stage_input_rejects::<FusionControl>(node, names::FUSION_CONTROL);
        stage_input_rejects::<RawBaro>(node, names::RAW_BARO);
        stage_input_rejects::<FusedImu>(node, names::FUSED_IMU);
        stage_input_rejects::<Altitude>(node, names::ALTITUDE);
        stage_input_rejects::<RawMag>(node, names::RAW_MAG);
        stage_input_rejects::<GnssFix>(node, names::GNSS);
    });
}

#[test]
fn the_mavlink_readers_drop_another_version() {
    on_private_node("mv", |node| {
        plain_reader_rejects::<FusedImu>(node, names::FUSED_IMU);
        plain_reader_rejects::<HealthReport>(node, names::HEALTH);
        plain_reader_rejects::<FusionReply>(node, names::FUSION_REPLY);
    });
}

/// What the watchdog's monitor reads besides the navigation stream: every topic it watches.
fn watchdog_readers_reject(node: &IpcNode) {
    plain_reader_rejects::<RawImu>(node, names::RAW_IMU);
    plain_reader_rejects::<RawBaro>(node, names::RAW_BARO);
    plain_reader_rejects::<RawMag>(node, names::RAW_MAG);
    plain_reader_rejects::<FusedImu>(node, names::FUSED_IMU);
    plain_reader_rejects::<Altitude>(node, names::ALTITUDE);
    plain_reader_rejects::<Truth>(node, names::TRUTH);
    plain_reader_rejects::<Health>(node, names::HEARTBEAT);
    plain_reader_rejects::<FaultApplied>(node, names::SIM_FAULT_APPLIED);
}

#[test]
fn the_watchdog_readers_drop_another_version() {
    on_private_node("wd", |node| {
        watchdog_readers_reject(node);
    });
}

/// A tool (`rins echo`, `rins status`) reads every topic the watchdog does, and the rest of those
/// `rins echo` shows, from its own node.
#[test]
fn a_tools_readers_drop_another_version() {
    on_tool_node("tl", |node| {
        watchdog_readers_reject(node);
        plain_reader_rejects::<RawAux>(node, names::RAW_AUX);
        plain_reader_rejects::<GnssFix>(node, names::GNSS);
        plain_reader_rejects::<HealthReport>(node, names::HEALTH);
        plain_reader_rejects::<SimControl>(node, names::SIM_CONTROL);
    });
}
