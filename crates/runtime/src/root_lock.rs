//! A lock on the deployment's root directory that orders a tool's arrival against a starting
//! deployment's clean-up.
//!
//! `rins up` counts the live nodes on its prefix and, when none is there, removes everything the
//! prefix has in shared memory (what a dead run left). A tool (`rins echo`, `status`, …) started at
//! the same moment could create its node between that count and that removal: its service files
//! would be deleted under it, the pipeline would create the services afresh, and the tool would
//! wait on files no one publishes to again. With this lock the count and the removal happen while
//! no tool is creating its node (exclusive), and a tool creates its node while no deployment is
//! counting (shared), so the deployment either sees the tool or starts its clean-up before it.
//!
//! The lock is `flock(2)` on the root directory itself: nothing is added to the root (which goes
//! when the run that created it ends), and the root is a private directory of the deployment's
//! user, so no one else can hold it.

use std::fs::File;

use crate::ipc::{IpcError, IpcSettings};

/// Held until dropped.
#[derive(Debug)]
pub struct RootLock {
    /// The open root: closing it releases the lock.
    _root: File,
}

impl RootLock {
    /// Waits for the root's lock alone: for a deployment's check of the prefix and clean-up.
    /// Creates the root when missing (see [`IpcSettings::ensure_root`]).
    pub fn exclusive(settings: &IpcSettings) -> Result<Self, IpcError> {
        let dir = open_root(settings)?;
        dir.lock().map_err(|e| lock_error(settings, e))?;
        Ok(Self { _root: dir })
    }

    /// Waits for the root's lock shared with other tools: for a tool creating its node.
    pub fn shared(settings: &IpcSettings) -> Result<Self, IpcError> {
        let dir = open_root(settings)?;
        dir.lock_shared().map_err(|e| lock_error(settings, e))?;
        Ok(Self { _root: dir })
    }
}

fn open_root(settings: &IpcSettings) -> Result<File, IpcError> {
    // Verified to be a private directory of the owner (created when missing) before it is opened.
    settings.ensure_root()?;
    File::open(&settings.root).map_err(|e| lock_error(settings, e))
}

fn lock_error(settings: &IpcSettings, e: std::io::Error) -> IpcError {
    IpcError::Root {
        source: std::io::Error::new(e.kind(), format!("cannot lock {}: {e}", settings.root)).into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
    use std::time::Duration;

    fn settings(name: &str) -> IpcSettings {
        let root =
            std::env::temp_dir().join(format!("rins-root-lock-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        IpcSettings::new("rins_root_lock_test_", root.display().to_string())
    }

    /// An exclusive holder makes the next exclusive taker wait until it lets go; shared holders
    /// wait for it too, and do not wait for each other.
    #[test]
    fn exclusive_excludes_and_shared_share() {
        let s = settings("excl");
        let first = RootLock::exclusive(&s).expect("first lock");
        let (tx, rx) = mpsc::channel();
        let waiter = {
            let s = s.clone();
            std::thread::spawn(move || {
                let _shared = RootLock::shared(&s).expect("shared lock");
                tx.send(()).expect("send");
            })
        };
        assert!(rx.recv_timeout(Duration::from_millis(200)).is_err());
        drop(first);
        rx.recv_timeout(Duration::from_secs(10))
            .expect("taken once released");
        waiter.join().expect("waiter");
        let a = RootLock::shared(&s).expect("shared a");
        let b = RootLock::shared(&s).expect("shared b");
        drop((a, b));
        let _ = std::fs::remove_dir_all(s.root.trim_end_matches('/'));
    }
}
