//! The environment variables that name a deployment: read by the settings, named in errors.

/// Environment variable naming the shared-memory prefix; every process of one deployment uses the same.
pub const PREFIX_ENV: &str = "RINS_IPC_PREFIX";
/// Environment variable naming the iceoryx2 root directory (node and service records).
pub const ROOT_ENV: &str = "RINS_IPC_ROOT";
/// Environment variable naming the user (name or uid) whose deployment a tool may join; the tool's
/// own effective user when unset.
pub const OWNER_ENV: &str = "RINS_IPC_OWNER";
