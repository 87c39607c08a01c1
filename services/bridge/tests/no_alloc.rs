//! The IPC side of the bridge must not touch the heap per sample: every fused sample, solution and
//! health report through the outbox, and every message due handed to the network thread's queue
//! (the network thread itself encodes and sends, and may allocate: it is off the navigation path).

use ipc_types::{FusedImu, HealthReport, NavMode, NavState};
use rins_bridge::config::ZenohConfig;
use rins_bridge::network::Network;
use rins_bridge::outbox::Outbox;
use rins_bridge::session_config::session_config;
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

fn nav(k: u64) -> NavState {
    let mut nav = NavState {
        mode: NavMode::Navigating as u8,
        quaternion: [1.0, 0.0, 0.0, 0.0],
        ..NavState::default()
    };
    nav.header.origin_rx_ns = k * 1_000_000;
    nav
}

fn fused(k: u64) -> FusedImu {
    let mut f = FusedImu::default();
    f.header.origin_rx_ns = k * 1_000_000;
    f
}

#[test]
fn handing_samples_to_the_network_side_does_not_allocate() {
    // The counter sees this thread's allocations.
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 8]))) > 0);
    // A session that connects nowhere and listens nowhere: the queue fills and drops, as with a
    // router that is away.
    let config = ZenohConfig {
        queue_capacity: 64,
        ..ZenohConfig::default()
    };
    let uid = rins_runtime::user::effective_uid();
    let network = Network::start(&config, session_config(&config, uid).expect("config"))
        .expect("network side");
    let mut outbox = Outbox::new(&config.rates);
    let mut run = |from: u64, to: u64| {
        for k in from..to {
            let mut send = |m| network.send(m);
            outbox.on_fused(&fused(k), &mut send);
            outbox.on_nav(&nav(k), &mut send);
            let report = HealthReport {
                now_ns: k * 1_000_000,
                ..HealthReport::default()
            };
            outbox.on_health(&report, &mut send);
        }
    };
    run(0, 100);
    let allocations = allocations_during(|| run(100, 10_100));
    assert_eq!(
        allocations, 0,
        "allocations on the IPC side over 10 000 samples"
    );
    // The samples were handed over (or dropped at a full queue), none lost silently.
    use std::sync::atomic::Ordering::Relaxed;
    let c = &network.counters;
    let handed = c.queued.load(Relaxed) + c.dropped_full.load(Relaxed);
    // 10 s at 50 + 100 + 5 + 1 messages a second, and the first 100 ms.
    assert!((1_550..=1_600).contains(&handed), "{handed}");
}
