//! iceoryx2 set-up shared by every process: an isolated prefix and root per deployment (and per test),
//! and topics made of a publish-subscribe service plus an event service of the same name, so a consumer
//! sleeps until data arrives instead of polling.

use std::fmt::Debug;
use std::time::Duration;

use anyhow::{Result, anyhow};
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use crate::{private_dir, user};

/// Environment variable naming the shared-memory prefix; every process of one deployment uses the same.
pub const PREFIX_ENV: &str = "RINS_IPC_PREFIX";
/// Environment variable naming the iceoryx2 root directory (node and service records).
pub const ROOT_ENV: &str = "RINS_IPC_ROOT";
/// Environment variable naming the user (name or uid) whose deployment a tool may join; the tool's
/// own effective user when unset.
pub const OWNER_ENV: &str = "RINS_IPC_OWNER";
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
    pub prefix: String,
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
    pub fn joining_from_env() -> Result<Self> {
        let mut settings = Self::from_env();
        if let Ok(spec) = std::env::var(OWNER_ENV) {
            settings.owner = user::resolve(&spec).map_err(|e| anyhow!("{OWNER_ENV} = {e}"))?;
        }
        Ok(settings)
    }

    /// Creates the root when it is missing (mode 0700) and checks that it is a private directory
    /// of the owner; returns whether this call created it.
    pub fn ensure_root(&self) -> Result<bool> {
        private_dir::ensure(std::path::Path::new(&self.root), self.owner)
            .map_err(|e| anyhow!("IPC root ({ROOT_ENV}): {e:#}"))
    }

    /// The deployment's own directory under the root (the simulator's terminal link, the
    /// acquisition's resume point), created by `rins up`.
    pub fn run_dir(&self) -> std::path::PathBuf {
        std::path::PathBuf::from(&self.root).join(format!("{}run", self.prefix))
    }

    /// [`Self::run_dir`], created when missing and verified like the root (which it verifies first).
    pub fn ensure_run_dir(&self) -> Result<std::path::PathBuf> {
        self.ensure_root()?;
        let dir = self.run_dir();
        private_dir::ensure(&dir, self.owner).map_err(|e| anyhow!("run directory: {e:#}"))?;
        Ok(dir)
    }

    pub fn iceoryx_config(&self) -> Result<Config> {
        let mut config = Config::default();
        config.global.prefix = FileName::new(self.prefix.as_bytes()).map_err(|e| {
            anyhow!(
                "{PREFIX_ENV} = {:?}: not a valid file-name prefix ({e:?})",
                self.prefix
            )
        })?;
        let root = Path::new(self.root.as_bytes())
            .map_err(|e| anyhow!("{ROOT_ENV} = {:?}: not a valid path ({e:?})", self.root))?;
        config.global.set_root_path(&root);
        Ok(config)
    }
}

pub type IpcNode = Node<ipc::Service>;

/// Makes this deployment's settings iceoryx2's process-wide configuration too. A few internal paths
/// (cleaning up after a dead peer whose records are gone) fall back to the global configuration;
/// without this they would look under the default root and prefix. Checks the root first: every
/// process of a deployment refuses a root that is not a private directory of the owner.
fn install_global_config(settings: &IpcSettings, config: &Config) -> Result<()> {
    settings.ensure_root()?;
    // iceoryx2 takes the first global configuration of a process and ignores later ones.
    if GLOBAL_CONFIG_INSTALLED.load(std::sync::atomic::Ordering::Relaxed) {
        return Ok(());
    }
    let text =
        toml::to_string(config).map_err(|e| anyhow!("cannot encode iceoryx2 config: {e}"))?;
    // iceoryx2 reads its global configuration from a file, once per process, and keeps it in memory:
    // a file of this process's own, gone again once read, so no process reads another's.
    let file = std::path::Path::new(&settings.root).join(format!(
        "{}iceoryx2.{}.toml",
        settings.prefix,
        std::process::id()
    ));
    write_new_private_file(&file, text.as_bytes())?;
    let loaded = FilePath::new(file.to_string_lossy().as_bytes())
        .map_err(|e| anyhow!("{}: not a valid path ({e:?})", file.display()))
        .and_then(|path| {
            Config::setup_global_config_from_file(&path)
                .map(|_| ())
                .map_err(|e| anyhow!("cannot load {}: {e:?}", file.display()))
        });
    let _ = std::fs::remove_file(&file);
    loaded?;
    GLOBAL_CONFIG_INSTALLED.store(true, std::sync::atomic::Ordering::Relaxed);
    Ok(())
}

/// Set once this process has handed iceoryx2 its global configuration.
static GLOBAL_CONFIG_INSTALLED: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Writes `bytes` to a file that must not exist yet (a stale one of a dead process with our pid is
/// unlinked first: unlink never follows a link), opened without following a link, mode 0600.
fn write_new_private_file(path: &std::path::Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    use std::os::unix::fs::OpenOptionsExt;
    let _ = std::fs::remove_file(path);
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)
        .map_err(|e| anyhow!("cannot create {}: {e}", path.display()))?;
    file.write_all(bytes)
        .map_err(|e| anyhow!("cannot write {}: {e}", path.display()))
}

/// Removes the shared memory and other resources of every dead node of this deployment (a
/// process that was killed without dropping its node); returns how many nodes were cleaned.
pub fn remove_dead_nodes(settings: &IpcSettings) -> Result<usize> {
    let mut removed = 0;
    for_each_dead_node(settings, |_, _| removed += 1)?;
    Ok(removed)
}

/// Like [`remove_dead_nodes`], and calls `on_removed` with the name (empty when its details are
/// gone) and the process id of each node cleaned: iceoryx2's own view of which processes died.
pub fn for_each_dead_node(
    settings: &IpcSettings,
    mut on_removed: impl FnMut(&str, Option<u32>),
) -> Result<()> {
    let config = settings.iceoryx_config()?;
    Node::<ipc::Service>::list(&config, |state| {
        if let NodeState::Dead(view) = state {
            use iceoryx2::node::NodeView;
            let name = view
                .details()
                .as_ref()
                .map(|d| d.name().as_str().to_string())
                .unwrap_or_default();
            let pid = view
                .id()
                .pid::<ipc::Service>()
                .ok()
                .and_then(|p| u32::try_from(p.value()).ok());
            if view.try_remove_stale_resources().is_ok() {
                on_removed(&name, pid);
            }
        }
        CallbackProgression::Continue
    })
    .map_err(|e| anyhow!("cannot list iceoryx2 nodes: {e:?}"))?;
    Ok(())
}

/// Creates this process's node. Signal handling is left to [`crate::shutdown::Shutdown`].
pub fn create_node(name: &str, settings: &IpcSettings) -> Result<IpcNode> {
    let config = settings.iceoryx_config()?;
    let node_name = NodeName::new(name).map_err(|e| anyhow!("node name {name:?}: {e:?}"))?;
    // Creating a node also cleans up dead nodes, and so does the watchdog after a child died:
    // when two processes clean up the same dead node at the same moment, one of them can fail
    // (an internal error, or files of the root vanishing under it). A few short retries let the
    // other finish.
    let mut attempt = 0;
    loop {
        let result = install_global_config(settings, &config).and_then(|()| {
            NodeBuilder::new()
                .name(&node_name)
                .config(&config)
                .signal_handling_mode(SignalHandlingMode::Disabled)
                .create::<ipc::Service>()
                .map_err(|e| anyhow!("{e:?}"))
        });
        match result {
            Ok(node) => return Ok(node),
            Err(e) if attempt < NODE_CREATE_RETRIES => {
                attempt += 1;
                tracing::debug!(node = name, error = %e, attempt, "node creation failed; retrying");
                std::thread::sleep(NODE_CREATE_RETRY_DELAY);
            }
            Err(e) => {
                return Err(anyhow!(
                    "cannot create iceoryx2 node {name:?} (after {attempt} retries): {e}"
                ));
            }
        }
    }
}

/// Retries of a node creation that failed, and the pause before each.
const NODE_CREATE_RETRIES: u32 = 5;
const NODE_CREATE_RETRY_DELAY: Duration = Duration::from_millis(20);

/// Queue depth of every subscriber: a consumer may sleep up to this many samples of a 1 kHz topic
/// (plus margin at 8 kHz) before the oldest is overwritten.
const SUBSCRIBER_BUFFER: usize = 512;
/// Publishers per topic: restarted services leave a dead publisher until it is cleaned up.
const MAX_PUBLISHERS: usize = 16;
const MAX_SUBSCRIBERS: usize = 16;
const MAX_NODES: usize = 64;

/// Samples of the raw IMU topic its publisher keeps for subscribers that connect later: a fusion
/// process restarted after a crash receives the frames it missed while it was down (up to 256 ms
/// at 1 kHz) and the navigation output has no hole. Other topics keep none: a late consumer of
/// them wants what comes next, not what was.
const RAW_IMU_HISTORY: usize = 256;

fn history_size(name: &str) -> usize {
    if name == ipc_types::names::RAW_IMU {
        RAW_IMU_HISTORY
    } else {
        0
    }
}

fn service_name(name: &str) -> Result<ServiceName> {
    ServiceName::new(name).map_err(|e| anyhow!("service name {name:?}: {e:?}"))
}

/// Every process opens a topic with the same settings, so whoever comes first creates it.
fn open_pubsub<T: Debug + ZeroCopySend + 'static>(
    node: &IpcNode,
    name: &str,
) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>> {
    node.service_builder(&service_name(name)?)
        .publish_subscribe::<T>()
        .max_publishers(MAX_PUBLISHERS)
        .max_subscribers(MAX_SUBSCRIBERS)
        .max_nodes(MAX_NODES)
        .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
        .history_size(history_size(name))
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| anyhow!("cannot open topic {name:?}: {e:?}"))
}

fn open_event(
    node: &IpcNode,
    name: &str,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>> {
    node.service_builder(&service_name(name)?)
        .event()
        .max_notifiers(MAX_PUBLISHERS)
        .max_listeners(MAX_SUBSCRIBERS)
        .max_nodes(MAX_NODES)
        .open_or_create()
        .map_err(|e| anyhow!("cannot open event service {name:?}: {e:?}"))
}

/// Publishing end of a topic: sends the sample, then wakes the topic's listeners.
pub struct TopicPublisher<T: Debug + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
    name: &'static str,
}

impl<T: Debug + ZeroCopySend + 'static> TopicPublisher<T> {
    pub fn new(node: &IpcNode, name: &'static str) -> Result<Self> {
        let publisher = open_pubsub::<T>(node, name)?
            .publisher_builder()
            .create()
            .map_err(|e| anyhow!("cannot create publisher on {name:?}: {e:?}"))?;
        let notifier = open_event(node, name)?
            .notifier_builder()
            .create()
            .map_err(|e| anyhow!("cannot create notifier on {name:?}: {e:?}"))?;
        Ok(Self {
            publisher,
            notifier,
            name,
        })
    }

    /// Writes `value` straight into shared memory and wakes the listeners.
    pub fn publish(&self, value: T) -> Result<()> {
        let sample = self
            .publisher
            .loan_uninit()
            .map_err(|e| anyhow!("loan on {:?} failed: {e:?}", self.name))?;
        sample
            .write_payload(value)
            .send()
            .map_err(|e| anyhow!("send on {:?} failed: {e:?}", self.name))?;
        self.notifier
            .notify()
            .map_err(|e| anyhow!("notify on {:?} failed: {e:?}", self.name))?;
        Ok(())
    }
}

/// Receiving end of a topic.
pub struct TopicSubscriber<T: Debug + ZeroCopySend + 'static> {
    subscriber: Subscriber<ipc::Service, T, ()>,
    listener: Listener<ipc::Service>,
    name: &'static str,
}

impl<T: Debug + ZeroCopySend + Copy + 'static> TopicSubscriber<T> {
    pub fn new(node: &IpcNode, name: &'static str) -> Result<Self> {
        let subscriber = open_pubsub::<T>(node, name)?
            .subscriber_builder()
            .create()
            .map_err(|e| anyhow!("cannot create subscriber on {name:?}: {e:?}"))?;
        let listener = open_event(node, name)?
            .listener_builder()
            .create()
            .map_err(|e| anyhow!("cannot create listener on {name:?}: {e:?}"))?;
        Ok(Self {
            subscriber,
            listener,
            name,
        })
    }

    /// Next queued sample, copied out of shared memory (payloads are small and `Copy`).
    pub fn receive(&self) -> Result<Option<T>> {
        let sample = self
            .subscriber
            .receive()
            .map_err(|e| anyhow!("receive on {:?} failed: {e:?}", self.name))?;
        Ok(sample.map(|s| *s.payload()))
    }

    /// Sleeps until a publisher signals new data or `timeout` passes. Returns whether a signal came.
    pub fn wait(&self, timeout: Duration) -> Result<bool> {
        match self.listener.timed_wait(|_| {}, timeout) {
            Ok(woken) => Ok(woken > 0),
            // A signal (the termination request the caller polls for) cut the wait short.
            Err(ListenerWaitError::InterruptSignal) => Ok(false),
            Err(e) => Err(anyhow!("wait on {:?} failed: {e:?}", self.name)),
        }
    }

    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The descriptor that becomes readable when a publisher signals, for waiting on several
    /// topics at once ([`wait_any`]).
    fn signal_fd(&self) -> i32 {
        // SAFETY: the descriptor is only polled, never closed or read; it lives as long as the
        // listener, which `self` owns.
        unsafe { self.listener.file_descriptor().native_handle() }
    }

    /// Consumes pending signals without sleeping.
    fn clear_signals(&self) -> Result<()> {
        self.listener
            .try_wait(|_| {})
            .map(|_| ())
            .map_err(|e| anyhow!("wait on {:?} failed: {e:?}", self.name))
    }
}

/// Something samples of `T` come from: one topic, or a merged stream such as the navigator lanes.
pub trait SampleSource<T> {
    /// Sleeps until data may be there or `timeout` passes.
    fn wait(&self, timeout: Duration) -> Result<bool>;
    /// The next sample, if one is there.
    fn receive(&mut self) -> Result<Option<T>>;
}

impl<T: Debug + ZeroCopySend + Copy + 'static> SampleSource<T> for TopicSubscriber<T> {
    fn wait(&self, timeout: Duration) -> Result<bool> {
        TopicSubscriber::wait(self, timeout)
    }

    fn receive(&mut self) -> Result<Option<T>> {
        TopicSubscriber::receive(self)
    }
}

/// Sleeps until a publisher of any of `subs` signals or `timeout` passes; returns whether a signal
/// came. One listener per topic cannot wait on two topics, and a poll(2) on their descriptors can.
pub fn wait_any<T: Debug + ZeroCopySend + Copy + 'static>(
    subs: &[&TopicSubscriber<T>],
    timeout: Duration,
) -> Result<bool> {
    const MAX: usize = 4;
    let mut fds = [libc::pollfd {
        fd: -1,
        events: 0,
        revents: 0,
    }; MAX];
    let n = subs.len().min(MAX);
    for (fd, sub) in fds.iter_mut().zip(subs) {
        fd.fd = sub.signal_fd();
        fd.events = libc::POLLIN;
    }
    let ms = libc::c_int::try_from(timeout.as_millis()).unwrap_or(libc::c_int::MAX);
    // SAFETY: `fds[..n]` is a valid array of initialised pollfd structures for the call's duration.
    let ready = unsafe { libc::poll(fds.as_mut_ptr(), n as libc::nfds_t, ms) };
    if ready < 0 {
        let err = std::io::Error::last_os_error();
        // A signal (the termination request the caller polls for) cut the wait short.
        if err.kind() == std::io::ErrorKind::Interrupted {
            return Ok(false);
        }
        return Err(anyhow!("poll on {} topics failed: {err}", n));
    }
    for sub in &subs[..n] {
        sub.clear_signals()?;
    }
    Ok(ready > 0)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let err = format!("{:#}", settings.ensure_run_dir().unwrap_err());
        assert!(
            err.contains("run directory") && err.contains("symbolic link"),
            "{err}"
        );
        std::fs::remove_dir_all(&base).unwrap();
    }
}
