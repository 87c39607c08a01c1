//! Integrity of the navigation solution end to end: a device played by the test (a pseudo-terminal
//! speaking the wire protocol) feeds `rins up --port`, and the navigation stream must say what is
//! wrong when the input goes wrong, and come back when it is right again.

mod common;

use std::time::Duration;

use common::device::FakeDevice;
use common::topic_stream::TopicStream;
use common::{Isolated, PipelineSlot, spawn_up, stop_up};
use rins_sim::Scenario;

fn mode(v: &serde_json::Value) -> u64 {
    v["mode"].as_u64().unwrap_or(u64::MAX)
}

#[test]
fn a_device_on_a_pseudo_terminal_is_navigated() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("integrity_clean");
    let device = FakeDevice::start(Scenario::Static, |_| {});
    let up = spawn_up(&ipc, &["--port", device.tty(), "--json"]);
    let nav = TopicStream::start(&ipc, "nav");
    let (_, first) = nav.wait_for("navigating", 0, Duration::from_secs(60), |v| mode(v) == 1);
    assert!(first["altitude_m"].as_f64().is_some(), "{first}");
    drop(nav);
    let summary = stop_up(&ipc, up);
    assert_eq!(summary["crc_errors"], 0, "{summary}");
}
