//! What every service's loop shares, whatever wakes it (a topic, a serial line, a clock): the stop
//! flag it polls, the counters it keeps and the heartbeat that carries them once a second.

use ipc_types::{Health, ServiceKind};

use crate::heartbeat::Heartbeat;
use crate::ipc::{IpcError, IpcNode};
use crate::shutdown::Shutdown;

/// The stop flag, the counters and the heartbeat of one process.
pub struct ServiceLoop {
    shutdown: Shutdown,
    heartbeat: Heartbeat,
    /// What the process counted so far; the heartbeat publishes them.
    pub counters: Health,
}

impl ServiceLoop {
    /// The loop of a process of `kind` on `node`, stopped by `shutdown`.
    pub fn new(node: &IpcNode, kind: ServiceKind, shutdown: &Shutdown) -> Result<Self, IpcError> {
        Ok(Self {
            shutdown: shutdown.clone(),
            heartbeat: Heartbeat::new(node, kind)?,
            counters: Health::default(),
        })
    }

    /// False once a stop was requested: the loop ends its round and returns.
    pub fn running(&self) -> bool {
        !self.shutdown.requested()
    }

    /// The stop flag, for waits that poll it while beating (a clone shares the flag).
    pub fn shutdown(&self) -> &Shutdown {
        &self.shutdown
    }

    /// Publishes the counters when a heartbeat is due (once a second); cheap otherwise.
    pub fn beat(&mut self) -> Result<(), IpcError> {
        self.heartbeat.tick(&self.counters)
    }
}
