//! Where a deployment's shared memory and iceoryx2 records live (prefix and root, from the
//! environment, per user by default), and whose they must be.

use iceoryx2::prelude::{Config, FileName, Path, SemanticString};

use super::env::{OWNER_ENV, PREFIX_ENV, ROOT_ENV};
use super::error::IpcError;
use crate::{private_dir, user};

/// The longest path of a Unix socket: `sun_path` holds 108 bytes with the terminating NUL.
const SOCKET_PATH_MAX: usize = 107;
/// Digits of the largest u128, the id iceoryx2 names an event socket by.
const EVENT_SOCKET_ID_DIGITS: usize = 39;
/// What follows the id in an event socket's name.
const EVENT_SOCKET_SUFFIX: &str = ".event";

/// Environment variable iceoryx2-style per-user runtime directories come from.
const XDG_RUNTIME_DIR: &str = "XDG_RUNTIME_DIR";

/// The default prefix of user `uid`: iceoryx2 names its /dev/shm segments by the prefix alone, so
/// two users' deployments on one prefix would share (and fight over) one set of names.
pub fn default_prefix(uid: u32) -> String {
    format!("rins_{uid}_")
}

/// The default root of user `uid`: the per-user runtime directory when the session has one, `/run`
/// for root, else a directory of the user's own in /tmp (created private and verified before use,
/// so a name planted there by another user is refused, not used).
pub fn default_root(uid: u32, xdg_runtime_dir: Option<&str>) -> String {
    match xdg_runtime_dir.filter(|d| !d.is_empty()) {
        Some(dir) => format!("{}/rins/", dir.trim_end_matches('/')),
        None if uid == 0 => "/run/rins/".to_string(),
        None => format!("/tmp/rins-{uid}/"),
    }
}

/// Where this deployment's shared memory and iceoryx2 records live, and whose they must be.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IpcSettings {
    /// The prefix of every /dev/shm segment and iceoryx2 record of the deployment.
    pub prefix: String,
    /// The directory of the deployment's iceoryx2 records, with a trailing slash.
    pub root: String,
    /// The user every directory and shared-memory entry of the deployment must belong to.
    pub owner: u32,
}

impl IpcSettings {
    /// Settings of a deployment of this process's own user on `prefix` and `root`.
    pub fn new(prefix: impl Into<String>, root: impl Into<String>) -> Self {
        let mut root = root.into();
        if !root.ends_with('/') {
            root.push('/');
        }
        Self {
            prefix: prefix.into(),
            root,
            owner: user::effective_uid(),
        }
    }

    /// From `RINS_IPC_PREFIX` / `RINS_IPC_ROOT`, with per-user defaults; the deployment is this
    /// process's user's. Children inherit the environment, so a whole process tree shares one
    /// setting.
    pub fn from_env() -> Self {
        let uid = user::effective_uid();
        let prefix = std::env::var(PREFIX_ENV).unwrap_or_else(|_| default_prefix(uid));
        let root = std::env::var(ROOT_ENV)
            .unwrap_or_else(|_| default_root(uid, std::env::var(XDG_RUNTIME_DIR).ok().as_deref()));
        Self::new(prefix, root)
    }

    /// [`Self::from_env`] for a tool that joins a running deployment: its owner is
    /// `RINS_IPC_OWNER` (a user name or uid) when set, else this process's user.
    pub fn joining_from_env() -> anyhow::Result<Self> {
        let mut settings = Self::from_env();
        if let Ok(spec) = std::env::var(OWNER_ENV) {
            settings.owner =
                user::resolve(&spec).map_err(|e| anyhow::anyhow!("{OWNER_ENV} = {e}"))?;
        }
        Ok(settings)
    }

    /// Creates the root when it is missing (mode 0700) and checks that it is a private directory
    /// of the owner; returns whether this call created it.
    pub fn ensure_root(&self) -> Result<bool, IpcError> {
        private_dir::ensure(std::path::Path::new(&self.root), self.owner)
            .map_err(|e| IpcError::Root { source: e.into() })
    }

    /// The deployment's own directory under the root (the simulator's terminal link, the
    /// acquisition's resume point), created by `rins up`.
    pub fn run_dir(&self) -> std::path::PathBuf {
        std::path::PathBuf::from(&self.root).join(format!("{}run", self.prefix))
    }

    /// [`Self::run_dir`], created when missing and verified like the root (which it verifies first).
    pub fn ensure_run_dir(&self) -> Result<std::path::PathBuf, IpcError> {
        self.ensure_root()?;
        let dir = self.run_dir();
        private_dir::ensure(&dir, self.owner).map_err(|e| IpcError::RunDir { source: e.into() })?;
        Ok(dir)
    }

    /// Whether `path` lies in [`Self::run_dir`]: a device link the deployment makes itself (the
    /// simulator's terminal), which appears moments after the services that read it start.
    pub fn in_run_dir(&self, path: &std::path::Path) -> bool {
        path.parent() == Some(self.run_dir().as_path())
    }

    /// Refuses a root and prefix too long for iceoryx2's event sockets, which are named
    /// `ROOT/PREFIX<id>.event`: a Unix socket's path is limited, and the id (a u128 in decimal)
    /// grows with every port a process makes. Past the limit a listener fails at run time, in
    /// whichever process comes to make one with a long id first; this says so before anything starts.
    pub fn check_name_lengths(&self) -> Result<(), IpcError> {
        let limit = SOCKET_PATH_MAX - EVENT_SOCKET_ID_DIGITS - EVENT_SOCKET_SUFFIX.len();
        if self.root.len() + self.prefix.len() > limit {
            return Err(IpcError::NamesTooLong {
                root: self.root.clone(),
                root_len: self.root.len(),
                prefix: self.prefix.clone(),
                prefix_len: self.prefix.len(),
                limit,
                id_digits: EVENT_SOCKET_ID_DIGITS,
                socket_path_max: SOCKET_PATH_MAX,
            });
        }
        Ok(())
    }

    /// iceoryx2's configuration for this deployment: its prefix and root.
    pub fn iceoryx_config(&self) -> Result<Config, IpcError> {
        self.check_name_lengths()?;
        let mut config = Config::default();
        config.global.prefix =
            FileName::new(self.prefix.as_bytes()).map_err(|source| IpcError::Prefix {
                prefix: self.prefix.clone(),
                source,
            })?;
        let root = Path::new(self.root.as_bytes()).map_err(|source| IpcError::RootPath {
            root: self.root.clone(),
            source,
        })?;
        config.global.set_root_path(&root);
        Ok(config)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_path_directly_in_the_run_dir_is_the_deployments_own() {
        let s = IpcSettings::new("p_", "/tmp/root");
        assert!(s.in_run_dir(std::path::Path::new("/tmp/root/p_run/sim-tty")));
        assert!(!s.in_run_dir(std::path::Path::new("/tmp/root/late-tty")));
        assert!(!s.in_run_dir(std::path::Path::new("/dev/ttyUSB0")));
        assert!(!s.in_run_dir(std::path::Path::new("/tmp/root/q_run/sim-tty")));
    }

    /// 62 bytes of root and prefix together pass; one more is refused, naming both and the limit.
    #[test]
    fn a_root_and_prefix_too_long_for_a_socket_path_are_refused() {
        let root = format!("/{}/", "r".repeat(40)); // 42 bytes with its slashes
        assert!(
            IpcSettings::new("p".repeat(20), root.clone())
                .check_name_lengths()
                .is_ok()
        );
        let err = IpcSettings::new("p".repeat(21), root)
            .check_name_lengths()
            .unwrap_err()
            .to_string();
        for part in [
            "RINS_IPC_ROOT",
            "42 bytes",
            "RINS_IPC_PREFIX",
            "21 bytes",
            "at most 62",
        ] {
            assert!(err.contains(part), "{part:?} missing from: {err}");
        }
        // The default names of any user fit.
        let uid = u32::MAX;
        assert!(
            IpcSettings::new(
                default_prefix(uid),
                default_root(uid, Some("/run/user/4294967295"))
            )
            .check_name_lengths()
            .is_ok()
        );
    }

    #[test]
    fn defaults_are_per_user() {
        assert_eq!(default_prefix(0), "rins_0_");
        assert_eq!(default_prefix(1000), "rins_1000_");
        // A prefix is never the start of another user's: uid 1 and uid 10.
        assert!(!default_prefix(10).starts_with(&default_prefix(1)));
        assert_eq!(
            default_root(1000, Some("/run/user/1000")),
            "/run/user/1000/rins/"
        );
        assert_eq!(default_root(0, Some("/run/user/0/")), "/run/user/0/rins/");
        assert_eq!(default_root(0, None), "/run/rins/");
        assert_eq!(default_root(1000, None), "/tmp/rins-1000/");
        assert_eq!(default_root(1000, Some("")), "/tmp/rins-1000/");
    }

    #[test]
    fn the_root_and_run_directory_are_created_private_and_a_planted_link_is_refused() {
        use std::os::unix::fs::MetadataExt;
        let base = std::env::temp_dir().join(format!("rins-ipc-root-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir(&base).unwrap();
        let settings = IpcSettings::new("p_", base.join("root").to_string_lossy().into_owned());
        assert!(settings.root.ends_with('/'));
        let run = settings.ensure_run_dir().unwrap();
        for dir in [std::path::Path::new(&settings.root), run.as_path()] {
            assert_eq!(
                std::fs::symlink_metadata(dir).unwrap().mode() & 0o777,
                0o700
            );
        }
        // A run directory replaced by a link to elsewhere is refused, naming it.
        std::fs::remove_dir(&run).unwrap();
        std::os::unix::fs::symlink(&base, &run).unwrap();
        let err = settings.ensure_run_dir().unwrap_err();
        assert!(matches!(err, IpcError::RunDir { .. }), "{err:?}");
        let err = format!("{:#}", anyhow::Error::from(err));
        assert!(
            err.contains("run directory") && err.contains("symbolic link"),
            "{err}"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }
}
