//! A private iceoryx2 deployment per test, for the tests that send real samples over shared
//! memory, and the payload versions another build would write.

use ipc_types::PAYLOAD_VERSION;
use rins_runtime::ipc::{IpcNode, IpcSettings, create_node};
use rins_runtime::shm_cleanup;
use rins_runtime::tool_node::ToolNode;

/// Another build's payload version on either side of this one's.
pub const OTHER_VERSIONS: [u16; 2] = [PAYLOAD_VERSION + 1, PAYLOAD_VERSION - 1];

/// The settings of a deployment of its own: the `tag` keeps the tests of one binary apart, the
/// process id keeps test binaries apart.
pub fn private_settings(tag: &str) -> IpcSettings {
    let pid = std::process::id();
    IpcSettings::new(
        format!("pv{tag}{pid}_"),
        std::env::temp_dir()
            .join(format!("pv{tag}{pid}root/"))
            .to_string_lossy()
            .into_owned(),
    )
}

/// Removes the deployment, its shared memory and its root, and checks that nothing of it is left.
pub fn remove(settings: &IpcSettings) {
    shm_cleanup::remove_all(settings, true);
    let _ = std::fs::remove_dir_all(&settings.root);
    let left = shm_cleanup::shm_entries(settings);
    assert!(left.is_empty(), "left in shared memory: {left:?}");
}

/// Runs `check` on a node of its own (as a service has) on a private deployment, removed
/// afterwards.
pub fn on_private_node(tag: &str, check: impl FnOnce(&IpcNode)) {
    let settings = private_settings(tag);
    {
        let node = create_node(tag, &settings).expect("node");
        check(&node);
    }
    remove(&settings);
}

/// Runs `check` on a tool's node (as `rins echo` joins a deployment) on a private deployment,
/// removed afterwards.
pub fn on_tool_node(tag: &str, check: impl FnOnce(&IpcNode)) {
    let settings = private_settings(tag);
    {
        let tool = ToolNode::join_settings("echo", settings.clone()).expect("tool node");
        check(tool.node());
    }
    remove(&settings);
}
