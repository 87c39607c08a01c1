//! What can go wrong when a process sets up or uses iceoryx2, with the node or topic it concerns.
//! The iceoryx2 error stays the [`std::error::Error::source`], so `{:#}` (anyhow) or
//! [`crate::error_chain::ErrorChain`] prints both the context and the cause.

use std::path::PathBuf;

use iceoryx2::config::ConfigCreationError;
use iceoryx2::node::{NodeCreationFailure, NodeListFailure};
use iceoryx2::port::listener::{ListenerCreateError, ListenerWaitError};
use iceoryx2::port::notifier::{NotifierCreateError, NotifierNotifyError};
use iceoryx2::port::publisher::PublisherCreateError;
use iceoryx2::port::subscriber::SubscriberCreateError;
use iceoryx2::port::update_connections::ConnectionFailure;
use iceoryx2::port::{LoanError, ReceiveError, SendError};
use iceoryx2::prelude::SemanticStringError;
use iceoryx2::service::builder::event::EventOpenOrCreateError;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenOrCreateError;
use iceoryx2::service::service_name::ServiceNameError;
use iceoryx2::waitset::{WaitSetAttachmentError, WaitSetCreateError, WaitSetRunError};

use super::env::{PREFIX_ENV, ROOT_ENV};

/// An error that is not iceoryx2's (a directory check, a file of our own), kept as the source.
pub type OtherError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// A failed iceoryx2 set-up or operation. Errors on the per-sample path (loan, send, notify,
/// receive, wait) name their topic by a `&'static str`, so making one never allocates.
#[derive(Debug, thiserror::Error)]
pub enum IpcError {
    /// `RINS_IPC_PREFIX` cannot be used as a file-name prefix.
    #[error("{PREFIX_ENV} = {prefix:?}: not a valid file-name prefix")]
    Prefix {
        /// The prefix as given.
        prefix: String,
        /// Why iceoryx2 refused it.
        source: SemanticStringError,
    },
    /// `RINS_IPC_ROOT` is not a path iceoryx2 accepts.
    #[error("{ROOT_ENV} = {root:?}: not a valid path")]
    RootPath {
        /// The root as given.
        root: String,
        /// Why iceoryx2 refused it.
        source: SemanticStringError,
    },
    /// The root and the prefix together leave no room for the name of an event socket.
    #[error(
        "{ROOT_ENV} = {root:?} ({root_len} bytes) and {PREFIX_ENV} = {prefix:?} ({prefix_len} bytes) are \
         too long together: at most {limit} bytes. Every event socket is named ROOT/PREFIX<id>.event, \
         the id up to {id_digits} digits, and a Unix socket's path holds at most {socket_path_max} bytes; \
         choose a shorter root or prefix"
    )]
    NamesTooLong {
        /// The root as given.
        root: String,
        /// Its length with the trailing slash, bytes.
        root_len: usize,
        /// The prefix as given.
        prefix: String,
        /// Its length, bytes.
        prefix_len: usize,
        /// The largest accepted sum of the two.
        limit: usize,
        /// Digits of the longest socket id.
        id_digits: usize,
        /// The longest Unix socket path, bytes.
        socket_path_max: usize,
    },
    /// The root is not (and could not be made) a private directory of the deployment's owner.
    #[error("IPC root ({ROOT_ENV})")]
    Root {
        /// What the directory check found.
        source: OtherError,
    },
    /// The deployment's run directory is not (and could not be made) private.
    #[error("run directory")]
    RunDir {
        /// What the directory check found.
        source: OtherError,
    },
    /// iceoryx2's configuration could not be encoded for the file it is read from.
    #[error("cannot encode iceoryx2 config")]
    ConfigEncode {
        /// The encoder's error.
        source: toml::ser::Error,
    },
    /// The private file that hands iceoryx2 its configuration could not be written.
    #[error("cannot write {}", path.display())]
    ConfigFile {
        /// The file.
        path: PathBuf,
        /// Why it could not be created or written.
        source: OtherError,
    },
    /// iceoryx2 refused the file name of its configuration.
    #[error("{}: not a valid path", path.display())]
    ConfigPath {
        /// The file.
        path: PathBuf,
        /// Why iceoryx2 refused it.
        source: SemanticStringError,
    },
    /// iceoryx2 could not load its configuration.
    #[error("cannot load {}", path.display())]
    ConfigLoad {
        /// The file.
        path: PathBuf,
        /// iceoryx2's error.
        source: ConfigCreationError,
    },
    /// iceoryx2's management segment of the deployment cannot be used (or made owner-only).
    #[error(
        "{}: iceoryx2's management segment of this deployment {problem}; no node can be created \
         on it. Stop every process of the deployment and remove the file (`rins up` removes it at \
         start when no process of the deployment is alive)",
        path.display()
    )]
    ManagementSegment {
        /// The segment's file.
        path: PathBuf,
        /// What was found.
        problem: String,
    },
    /// The node name is not one iceoryx2 accepts.
    #[error("node name {name:?}")]
    NodeName {
        /// The name as given.
        name: String,
        /// Why iceoryx2 refused it.
        source: SemanticStringError,
    },
    /// iceoryx2 refused to create a node (one attempt; [`IpcError::Node`] names the node).
    #[error("node creation failed")]
    NodeCreate {
        /// iceoryx2's error.
        source: NodeCreationFailure,
    },
    /// The node could not be created, even after retries.
    #[error("cannot create iceoryx2 node {name:?} (after {retries} retries)")]
    Node {
        /// The node.
        name: String,
        /// Attempts after the first.
        retries: u32,
        /// What the last attempt failed on.
        source: Box<IpcError>,
    },
    /// The nodes of the deployment could not be listed.
    #[error("cannot list iceoryx2 nodes")]
    NodeList {
        /// iceoryx2's error.
        source: NodeListFailure,
    },
    /// The topic name is not one iceoryx2 accepts.
    #[error("service name {topic:?}")]
    TopicName {
        /// The topic.
        topic: &'static str,
        /// Why iceoryx2 refused it.
        source: ServiceNameError,
    },
    /// The publish-subscribe service of a topic could not be opened or created.
    #[error("cannot open topic {topic:?}")]
    OpenTopic {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: PublishSubscribeOpenOrCreateError,
    },
    /// The event service of a topic could not be opened or created.
    #[error("cannot open event service {topic:?}")]
    OpenEvent {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: EventOpenOrCreateError,
    },
    /// No publisher could be created on a topic.
    #[error("cannot create publisher on {topic:?}")]
    Publisher {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: PublisherCreateError,
    },
    /// No notifier could be created on a topic.
    #[error("cannot create notifier on {topic:?}")]
    Notifier {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: NotifierCreateError,
    },
    /// No subscriber could be created on a topic.
    #[error("cannot create subscriber on {topic:?}")]
    Subscriber {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: SubscriberCreateError,
    },
    /// No listener could be created on a topic.
    #[error("cannot create listener on {topic:?}")]
    Listener {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: ListenerCreateError,
    },
    /// No shared-memory sample could be loaned to publish.
    #[error("loan on {topic:?} failed")]
    Loan {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: LoanError,
    },
    /// A sample could not be sent.
    #[error("send on {topic:?} failed")]
    Send {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: SendError,
    },
    /// The listeners of a topic could not be woken.
    #[error("notify on {topic:?} failed")]
    Notify {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: NotifierNotifyError,
    },
    /// The subscriber could not connect to a publisher of the topic.
    #[error("connecting to the publishers of {topic:?} failed")]
    Connect {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: ConnectionFailure,
    },
    /// A sample could not be received.
    #[error("receive on {topic:?} failed")]
    Receive {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: ReceiveError,
    },
    /// Waiting for a topic's signal failed (other than by a signal to the process).
    #[error("wait on {topic:?} failed")]
    Wait {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: ListenerWaitError,
    },
    /// No wait set could be created.
    #[error("cannot create a wait set")]
    WaitSetCreate {
        /// iceoryx2's error.
        source: WaitSetCreateError,
    },
    /// A topic could not be attached to a wait set.
    #[error("cannot wait on {topic:?} in a wait set")]
    WaitSetAttach {
        /// The topic.
        topic: &'static str,
        /// iceoryx2's error.
        source: WaitSetAttachmentError,
    },
    /// Waiting on several topics at once failed (other than by a signal to the process).
    #[error("wait on {topics} topics failed")]
    WaitSetRun {
        /// How many topics were waited on.
        topics: usize,
        /// iceoryx2's error.
        source: WaitSetRunError,
    },
}
