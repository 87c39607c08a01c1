//! The one shape of every rins process: a service is built from the configuration (so a bad one is
//! refused before any process starts), then run with what every process is given — where the
//! deployment lives and the flag that asks it to stop.

use ipc_types::ServiceKind;

use crate::ipc::{IpcError, IpcNode, IpcSettings, create_node};
use crate::shutdown::Shutdown;

/// A built service, ready to run.
pub trait Service {
    /// Runs the service until `ctx.shutdown` is requested (or it fails).
    fn run(self, ctx: ServiceContext) -> anyhow::Result<()>;
}

/// What every service runs with.
#[derive(Clone)]
pub struct ServiceContext {
    /// The deployment this process belongs to.
    pub settings: IpcSettings,
    /// Set when the process is asked to stop; every loop polls it.
    pub shutdown: Shutdown,
    /// How a stage driven by a topic waits for its input.
    pub wait: crate::wait_strategy::WaitStrategy,
}

impl ServiceContext {
    /// A context for `settings`, stopped by `shutdown`.
    pub fn new(settings: IpcSettings, shutdown: Shutdown) -> Self {
        Self {
            settings,
            shutdown,
            wait: crate::wait_strategy::WaitStrategy::Event,
        }
    }

    /// The node of a process of `kind`, named after it (the watchdog tells the pipeline's nodes
    /// from tools' by these names).
    pub fn create_node(&self, kind: ServiceKind) -> Result<IpcNode, IpcError> {
        create_node(kind.name(), &self.settings)
    }
}
