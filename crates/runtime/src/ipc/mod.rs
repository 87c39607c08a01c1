//! iceoryx2 set-up shared by every process: an isolated prefix and root per deployment (and per
//! test), this process's node, and topics made of a publish-subscribe service plus an event service
//! of the same name, so a consumer sleeps until data arrives instead of polling.

mod config_file;
mod env;
mod error;
pub mod mgmt_segment;
mod node;
pub mod own_ports;
mod settings;
mod topic;
mod wait_set;

pub use config_file::CONFIG_FILE_NAME;
pub use env::{OWNER_ENV, PREFIX_ENV, ROOT_ENV};
pub use error::{IpcError, OtherError};
pub use node::{IpcNode, create_node, for_each_dead_node, for_each_live_node, remove_dead_nodes};
pub use settings::{IpcSettings, default_prefix, default_root};
pub use topic::{
    MAX_NODES, MAX_PUBLISHERS, MAX_SUBSCRIBERS, SUBSCRIBER_BUFFER, SampleSource, TopicPublisher,
    TopicSubscriber, history_size,
};
pub use wait_set::TopicWaitSet;
