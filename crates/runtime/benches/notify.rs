//! What a hop's publish and a poller's chores cost on top of the sample itself: `publish` (loan,
//! write, send, and one notification per listener of the topic) with no listener, one and three;
//! and a poller taking the notifications off its listener. In one process, so no wake-up is
//! measured: this is the work a spinning hop does per sample.
//!
//! Measured (`cargo bench -p rins-runtime --bench notify`, 2-vCPU AMD EPYC VM): publish 0.31 µs
//! without a listener; 2.40 µs with one listener and 6.74 µs with three whose notifications are
//! taken off each time (each delivered one and its removal about 2 µs); 0.33 µs with one listener
//! that never takes them off (its socket full, the notification fails at once) against 2.25 µs
//! when it does.

// `criterion_group!` generates `pub fn benches` and takes no attributes, so no doc can be attached
// to it; nothing else in this benchmark binary is public.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use ipc_types::NavState;
use rins_runtime::ipc::{TopicPublisher, TopicSubscriber};
use rins_test_support::private_ipc::on_private_node;

fn publish(c: &mut Criterion) {
    on_private_node("notifybench", |node| {
        for listeners in [0usize, 1, 3] {
            let topic: &'static str = ["notify-0", "notify-1", "notify-3"][listeners.min(2)];
            let polled = TopicSubscriber::<NavState>::polled(node, topic).expect("subscriber");
            let listening: Vec<TopicSubscriber<NavState>> = (0..listeners)
                .map(|_| TopicSubscriber::new(node, topic).expect("subscriber"))
                .collect();
            let publisher = TopicPublisher::<NavState>::new(node, topic).expect("publisher");
            let mut seq = 0u64;
            c.bench_function(&format!("publish, {listeners} listeners"), |b| {
                b.iter(|| {
                    seq += 1;
                    let mut s = NavState::default();
                    s.header.origin_seq = seq;
                    publisher.publish(s).expect("publish");
                    // Keep the queues short: the receive is not part of the figure's point but is
                    // what every hop does too.
                    let _ = polled.receive();
                    for l in &listening {
                        let _ = l.receive();
                        let _ = l.clear_signals();
                    }
                })
            });
        }
        let sub = TopicSubscriber::<NavState>::new(node, "notify-clear").expect("subscriber");
        let publisher = TopicPublisher::<NavState>::new(node, "notify-clear").expect("publisher");
        c.bench_function("publish and receive, no notification taken off", |b| {
            b.iter(|| {
                publisher.publish(NavState::default()).expect("publish");
                let _ = sub.receive();
            })
        });
        c.bench_function("publish, receive and take the notification off", |b| {
            b.iter(|| {
                publisher.publish(NavState::default()).expect("publish");
                let _ = sub.receive();
                let _ = sub.clear_signals();
            })
        });
    });
}

criterion_group!(benches, publish);
criterion_main!(benches);
