//! The wait between attempts to open a device.

use std::time::Duration;

use anyhow::Result;
use rins_runtime::shutdown::Shutdown;

/// How often a wait wakes to look at shutdown and to tick.
const STEP: Duration = Duration::from_millis(10);

/// Sleeps `total` between attempts to open the device, waking early on shutdown and calling
/// `tick` every step (the caller's heartbeat): a process waiting for its device is not hung, and
/// must not be restarted as if it were, however long the backoff. An error from `tick` ends the
/// wait and is returned.
pub fn wait_for_retry(
    total: Duration,
    shutdown: &Shutdown,
    mut tick: impl FnMut() -> Result<()>,
) -> Result<()> {
    let mut left = total;
    while !left.is_zero() && !shutdown.requested() {
        let d = left.min(STEP);
        std::thread::sleep(d);
        left -= d;
        tick()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wait_ticks_once_per_step_and_ends_on_shutdown() {
        let shutdown = Shutdown::manual();
        let mut ticks = 0;
        wait_for_retry(Duration::from_millis(35), &shutdown, || {
            ticks += 1;
            Ok(())
        })
        .unwrap();
        // 10 + 10 + 10 + 5 ms.
        assert_eq!(ticks, 4);
        shutdown.request();
        let mut ticks = 0;
        wait_for_retry(Duration::from_secs(60), &shutdown, || {
            ticks += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(ticks, 0);
    }
}
