//! What the watchdog checks before it starts a deployment: the prefix is not another user's, no
//! other deployment runs on it; what a dead run left is removed.

use anyhow::{Result, bail};
use ipc_types::ServiceKind;
use rins_runtime::ipc::{IpcSettings, PREFIX_ENV};
use rins_runtime::shm_cleanup;

/// Refuses to start while another user's files are on the prefix in /dev/shm: they are never
/// opened, never removed.
pub fn refuse_foreign_entries(settings: &IpcSettings) -> Result<()> {
    let foreign = shm_cleanup::foreign_entries(settings, settings.owner);
    if !foreign.is_empty() {
        bail!(
            "IPC prefix {:?} is in use by someone else: {}. Another user runs a deployment on this \
             prefix or planted these files; they are left alone. Set {} to a prefix of your own \
             (the default is per user), or have their owner remove them",
            settings.prefix,
            shm_cleanup::describe_entries(&foreign),
            PREFIX_ENV
        );
    }
    Ok(())
}

/// Refuses to start while another deployment runs on the prefix; otherwise removes what a dead run
/// of ours left.
pub fn ensure_no_live_deployment(settings: &IpcSettings) -> Result<()> {
    let (mut alive, mut tools) = (0, 0);
    rins_runtime::ipc::for_each_live_node(settings, |name| {
        // Only the pipeline's own processes make a deployment; a tool (`rins echo`, `status`,
        // `soak`, …) waiting on the prefix for the pipeline to start does not.
        if name.is_some_and(|n| ServiceKind::from_name(n).is_some()) {
            alive += 1;
        } else {
            tools += 1;
        }
    })?;
    if alive > 0 {
        bail!(
            "another rins deployment is running on IPC prefix {:?} ({alive} live processes): stop it or set {} to another prefix",
            settings.prefix,
            PREFIX_ENV
        );
    }
    // No pipeline alive: whatever is left belongs to a deployment that died; start clean. While a
    // tool is already waiting on the prefix its shared memory must stay, so only the resources of
    // dead nodes go then.
    if tools == 0 {
        let removed = shm_cleanup::remove_all(settings, false);
        if removed > 0 {
            tracing::info!(removed, "removed shared memory left by an earlier run");
        }
    } else {
        let removed = rins_runtime::ipc::remove_dead_nodes(settings)?;
        if removed > 0 {
            tracing::info!(
                removed,
                "removed the resources of dead nodes left by an earlier run"
            );
        }
    }
    Ok(())
}
