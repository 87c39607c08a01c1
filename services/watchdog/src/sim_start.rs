//! Waiting for the simulator to create its pseudo-terminal before the deployment is supervised.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use rins_runtime::shutdown::Shutdown;

use crate::supervisor::{ChildEvent, Supervisor};

/// How long the simulator may take to create its pseudo-terminal.
pub const SIM_START_TIMEOUT: Duration = Duration::from_secs(10);

/// Waits for the simulator's terminal link; returns false when a stop was requested meanwhile (a
/// clean stop, not a failure). A child that exits meanwhile stops the start-up with an error.
pub fn wait_for_path(
    path: &Path,
    supervisor: &mut Supervisor,
    shutdown: &Shutdown,
) -> Result<bool> {
    let deadline = Instant::now() + SIM_START_TIMEOUT;
    let mut events = Vec::new();
    while !path.exists() {
        if shutdown.requested() {
            return Ok(false);
        }
        supervisor.poll(&mut events);
        // A child given up (a restart limit of 0) stops the start-up too rather than being lost.
        if let Some(
            ChildEvent::Exited { name, status, .. } | ChildEvent::GaveUp { name, status, .. },
        ) = events.first()
        {
            bail!(
                "{name} exited ({status}) before creating {}",
                path.display()
            );
        }
        if Instant::now() >= deadline {
            bail!(
                "simulator did not create {} in {:?}",
                path.display(),
                SIM_START_TIMEOUT
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(true)
}
