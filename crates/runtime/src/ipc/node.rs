//! This process's iceoryx2 node, and the other nodes of the deployment: creating one (and handing
//! iceoryx2 the deployment's configuration first), finding the dead ones and freeing what they left.

use std::time::Duration;

use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

use super::error::IpcError;
use super::settings::IpcSettings;

/// A node of this deployment; every port of a process is made from it.
pub type IpcNode = Node<ipc::Service>;

/// Retries of a node creation that failed, and the pause before each.
const NODE_CREATE_RETRIES: u32 = 5;
const NODE_CREATE_RETRY_DELAY: Duration = Duration::from_millis(20);

/// Set once this process has handed iceoryx2 its global configuration.
static GLOBAL_CONFIG_INSTALLED: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Makes this deployment's settings iceoryx2's process-wide configuration too. A few internal paths
/// (cleaning up after a dead peer whose records are gone) fall back to the global configuration;
/// without this they would look under the default root and prefix. Checks the root first: every
/// process of a deployment refuses a root that is not a private directory of the owner.
fn install_global_config(settings: &IpcSettings, config: &Config) -> Result<(), IpcError> {
    settings.ensure_root()?;
    // iceoryx2 takes the first global configuration of a process and ignores later ones.
    if GLOBAL_CONFIG_INSTALLED.load(std::sync::atomic::Ordering::Relaxed) {
        return Ok(());
    }
    let text = toml::to_string(config).map_err(|source| IpcError::ConfigEncode { source })?;
    // iceoryx2 reads its global configuration from a file, once per process, and keeps it in memory:
    // a file of this process's own, gone again once read, so no process reads another's.
    let file = std::path::Path::new(&settings.root).join(format!(
        "{}iceoryx2.{}.toml",
        settings.prefix,
        std::process::id()
    ));
    super::config_file::write_new_private_file(&file, text.as_bytes()).map_err(|source| {
        IpcError::ConfigFile {
            path: file.clone(),
            source,
        }
    })?;
    let loaded = FilePath::new(file.to_string_lossy().as_bytes())
        .map_err(|source| IpcError::ConfigPath {
            path: file.clone(),
            source,
        })
        .and_then(|path| {
            Config::setup_global_config_from_file(&path)
                .map(|_| ())
                .map_err(|source| IpcError::ConfigLoad {
                    path: file.clone(),
                    source,
                })
        });
    let _ = std::fs::remove_file(&file);
    loaded?;
    GLOBAL_CONFIG_INSTALLED.store(true, std::sync::atomic::Ordering::Relaxed);
    Ok(())
}

/// Creates this process's node. Signal handling is left to [`crate::shutdown::Shutdown`].
pub fn create_node(name: &str, settings: &IpcSettings) -> Result<IpcNode, IpcError> {
    let config = settings.iceoryx_config()?;
    let node_name = NodeName::new(name).map_err(|source| IpcError::NodeName {
        name: name.to_string(),
        source,
    })?;
    // The deployment's management segment: made owner-only before iceoryx2 would make it
    // writable by everyone; a damaged one is refused here, naming it, rather than retried.
    install_global_config(settings, &config)?;
    super::mgmt_segment::prepare(settings, &config)?;
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
                .map_err(|source| IpcError::NodeCreate { source })
        });
        match result {
            Ok(node) => return Ok(node),
            Err(e) if attempt < NODE_CREATE_RETRIES => {
                attempt += 1;
                tracing::debug!(node = name, error = %crate::error_chain::ErrorChain(&e), attempt, "node creation failed; retrying");
                std::thread::sleep(NODE_CREATE_RETRY_DELAY);
            }
            Err(e) => {
                return Err(IpcError::Node {
                    name: name.to_string(),
                    retries: attempt,
                    source: Box::new(e),
                });
            }
        }
    }
}

/// Removes the shared memory and other resources of every dead node of this deployment (a
/// process that was killed without dropping its node); returns how many nodes were cleaned.
pub fn remove_dead_nodes(settings: &IpcSettings) -> Result<usize, IpcError> {
    let mut removed = 0;
    for_each_dead_node(settings, |_, _| removed += 1)?;
    Ok(removed)
}

/// Like [`remove_dead_nodes`], and calls `on_removed` with the name (empty when its details are
/// gone) and the process id of each node cleaned: iceoryx2's own view of which processes died.
pub fn for_each_dead_node(
    settings: &IpcSettings,
    mut on_removed: impl FnMut(&str, Option<u32>),
) -> Result<(), IpcError> {
    let config = settings.iceoryx_config()?;
    Node::<ipc::Service>::list(&config, |state| {
        if let NodeState::Dead(view) = state {
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
    .map_err(|source| IpcError::NodeList { source })
}

/// Calls `on_alive` with the name of every live node of this deployment (`None` when its details
/// cannot be read).
pub fn for_each_live_node(
    settings: &IpcSettings,
    mut on_alive: impl FnMut(Option<&str>),
) -> Result<(), IpcError> {
    let config = settings.iceoryx_config()?;
    Node::<ipc::Service>::list(&config, |state| {
        if let NodeState::Alive(view) = &state {
            on_alive(view.details().as_ref().map(|d| d.name().as_str()));
        }
        CallbackProgression::Continue
    })
    .map_err(|source| IpcError::NodeList { source })
}
