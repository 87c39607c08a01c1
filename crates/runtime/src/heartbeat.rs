//! Once-a-second heartbeat with the process's counters, on the `heartbeat` topic.

use ipc_types::{Health, PAYLOAD_VERSION, ServiceKind, names};

use crate::clock::monotonic_ns;
use crate::ipc::{IpcError, IpcNode, TopicPublisher};

/// Heartbeat period, ns.
const PERIOD_NS: u64 = 1_000_000_000;

/// The heartbeat publisher of one process, with what every beat says of the process itself.
pub struct Heartbeat {
    publisher: TopicPublisher<Health>,
    template: Health,
    next_due_ns: u64,
}

impl Heartbeat {
    /// The heartbeat of a process of kind `service` (this process's pid).
    pub fn new(node: &IpcNode, service: ServiceKind) -> Result<Self, IpcError> {
        Ok(Self {
            publisher: TopicPublisher::new(node, names::HEARTBEAT)?,
            template: Health {
                version: PAYLOAD_VERSION,
                service: service as u8,
                pid: std::process::id(),
                ..Health::default()
            },
            next_due_ns: 0,
        })
    }

    /// Publishes `counters` (service, pid and time filled in here) if a second has passed since the last.
    pub fn tick(&mut self, counters: &Health) -> Result<(), IpcError> {
        let now = monotonic_ns();
        if now < self.next_due_ns {
            return Ok(());
        }
        self.next_due_ns = now + PERIOD_NS;
        self.publisher.publish(Health {
            version: self.template.version,
            service: self.template.service,
            pid: self.template.pid,
            now_ns: now,
            ..*counters
        })
    }
}
