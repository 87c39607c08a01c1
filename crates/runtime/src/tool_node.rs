//! The node of a tool that joins a deployment for a moment (`rins echo`, `status`, `latency`,
//! `inject`, `readmit`): when it is dropped it leaves nothing behind, whether a pipeline runs or
//! not.
//!
//! Dropping an iceoryx2 node removes its own records, but the first node of a domain also creates
//! the domain's management segment in /dev/shm and the record directories under the root, and the
//! tool may have created the root itself: made by the tool when no pipeline runs, they would stay
//! until the next `rins up` cleans them. So once the node is gone and no live node is left on the
//! deployment, what is left on its prefix is a tool's and is removed, and the root too when this
//! tool created it and it is empty. While a pipeline runs, its files are left alone but for the
//! connection segments to the tool's own subscribers, which the pipeline's publishers may keep for
//! a long time.

use std::path::Path;

use anyhow::Result;

use crate::ipc::{IpcNode, IpcSettings, create_node, for_each_live_node, own_ports};
use crate::root_lock::RootLock;
use crate::setup_guard::SetupGuard;
use crate::{join_check, private_dir, shm_cleanup, user};

/// Longest a tool's node creation may take. It is quick (milliseconds; up to a second while another
/// process sets the deployment's management segment up); a damaged file of the deployment could
/// make iceoryx2 wait for ever.
pub const JOIN_LIMIT: std::time::Duration = std::time::Duration::from_secs(10);

/// A tool's node on the deployment of the environment's prefix and root (see
/// [`join_check::settings_to_join`]); cleans up after itself when dropped. Create every port from
/// [`ToolNode::node`] after the `ToolNode`, so that the ports are dropped before it.
pub struct ToolNode {
    // Fields drop in declaration order: the node first, then the clean-up that needs it gone,
    // then the lock taken for both (see `Drop`).
    node: IpcNode,
    cleanup: Cleanup,
    lock: Option<RootLock>,
}

impl ToolNode {
    /// Joins the deployment as the node `TOOL-PID` (e.g. `echo-1234`) once it is found to be the
    /// expected user's.
    pub fn join(tool: &str) -> Result<Self> {
        Self::join_settings(tool, join_check::settings_to_join()?)
    }

    /// [`ToolNode::join`] on the deployment of `settings` instead of the environment's (a
    /// deployment a tool started itself on a private root), once it is found to be the expected
    /// user's.
    pub fn join_settings(tool: &str, settings: IpcSettings) -> Result<Self> {
        settings.check_name_lengths()?;
        join_check::check_joinable(&settings)?;
        let root = private_dir::without_trailing_slash(Path::new(&settings.root)).to_path_buf();
        let root_existed = std::fs::symlink_metadata(&root).is_ok();
        // A deployment starting now does not clean the prefix while the node is being made (see
        // `root_lock`). Another user's root cannot be locked, nor is it ever cleaned by us.
        let lock = own_deployment(&settings)
            .then(|| RootLock::shared(&settings))
            .transpose();
        // Bounded whatever the deployment's files hold, and stopped by a stop signal.
        let guard = SetupGuard::arm(
            format!(
                "{tool}: joining the deployment on prefix {:?}",
                settings.prefix
            ),
            Some(JOIN_LIMIT),
            None,
        );
        let node = lock.and_then(|lock| {
            create_node(&format!("{tool}-{}", std::process::id()), &settings).map(|n| (n, lock))
        });
        guard.disarm();
        // Made before the error is returned: a failed creation may have left the root and the
        // domain's segment, and dropping the clean-up removes them.
        let cleanup = Cleanup {
            root_created: !root_existed && root.exists(),
            settings,
        };
        let (node, lock) = node?;
        drop(lock);
        Ok(Self {
            node,
            cleanup,
            lock: None,
        })
    }

    /// The node to create the tool's ports from.
    pub fn node(&self) -> &IpcNode {
        &self.node
    }

    /// The deployment joined.
    pub fn settings(&self) -> &IpcSettings {
        &self.cleanup.settings
    }
}

impl Drop for ToolNode {
    /// A deployment starting now does not count the live nodes while this one goes and its
    /// leftovers are removed: it would see the prefix still in use, or the removal would take
    /// what it just made.
    fn drop(&mut self) {
        if own_deployment(&self.cleanup.settings) {
            self.lock = RootLock::exclusive(&self.cleanup.settings).ok();
        }
    }
}

fn own_deployment(settings: &IpcSettings) -> bool {
    settings.owner == user::effective_uid()
}

/// With a pipeline running: removes the connection segments from its publishers to this process's
/// subscribers, which are gone (see [`own_ports`]); everything else there is the pipeline's.
fn remove_connections_to_own_receivers(settings: &IpcSettings) {
    let ours = own_ports::receivers();
    let uid = user::effective_uid();
    for entry in shm_cleanup::inspect(Path::new(shm_cleanup::SHM_DIR), &settings.prefix) {
        if entry.belongs_to(uid)
            && ours
                .iter()
                .any(|&id| own_ports::is_connection_to(&entry.name, id))
        {
            let _ = std::fs::remove_file(Path::new(shm_cleanup::SHM_DIR).join(&entry.name));
        }
    }
}

/// What a [`ToolNode`] removes once its node is gone.
struct Cleanup {
    settings: IpcSettings,
    /// The root did not exist before the tool joined.
    root_created: bool,
}

impl Drop for Cleanup {
    fn drop(&mut self) {
        // Only the owner's deployment is ever cleaned: a tool that joined another user's (with
        // RINS_IPC_OWNER) removes nothing of it.
        if !own_deployment(&self.settings) {
            return;
        }
        let mut alive = 0usize;
        if for_each_live_node(&self.settings, |_| alive += 1).is_err() {
            return;
        }
        if alive > 0 {
            remove_connections_to_own_receivers(&self.settings);
            return;
        }
        let removed = shm_cleanup::remove_all(&self.settings, self.root_created);
        tracing::debug!(
            removed,
            prefix = self.settings.prefix,
            "no pipeline on the deployment: removed what this tool left"
        );
    }
}
