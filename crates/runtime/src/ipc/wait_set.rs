//! Waiting on several topics at once: one listener per topic cannot wait on two, an iceoryx2 wait
//! set can wait on any number.
//!
//! The topics are attached once, when the wait set is made, and stay attached for its life: a wait
//! is then one `epoll_wait` and one read per signalled listener, with no attach and detach system
//! calls around it (a consumer waits a thousand times a second). An attachment borrows the wait
//! set and the listener, so both live in one self-referential cell with the attachments.

use std::fmt::Debug;
use std::rc::Rc;
use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::waitset::{WaitSetGuard, WaitSetRunResult};
use self_cell::self_cell;

use super::error::IpcError;
use super::topic::TopicSubscriber;

/// What the attachments borrow: the wait set and the topics' listeners.
struct Attachable {
    waitset: WaitSet<ipc::Service>,
    /// One per topic, shared with the topic's subscriber.
    listeners: Vec<Rc<Listener<ipc::Service>>>,
}

/// One attachment per listener, each borrowing the wait set and its listener.
type Attachments<'a> = Vec<WaitSetGuard<'a, 'a, ipc::Service>>;

self_cell!(
    /// The wait set with every topic attached.
    struct AttachedTopics {
        owner: Attachable,

        #[not_covariant]
        dependent: Attachments,
    }
);

/// An iceoryx2 wait set with a fixed set of topics attached for its whole life.
pub struct TopicWaitSet {
    attached: AttachedTopics,
    /// The topics' names, in the listeners' order, for errors.
    names: Vec<&'static str>,
}

impl TopicWaitSet {
    /// Attaches `topics`. Signals are left to the caller: a signal cuts a wait short, and the
    /// caller polls its own stop flag ([`crate::shutdown::Shutdown`]).
    pub fn new<T: Debug + ZeroCopySend + Copy + 'static>(
        topics: &[&TopicSubscriber<T>],
    ) -> Result<Self, IpcError> {
        let waitset = WaitSetBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|source| IpcError::WaitSetCreate { source })?;
        // A polled topic has no listener to attach: the wait never wakes for it.
        let listening: Vec<_> = topics
            .iter()
            .filter_map(|t| Some((t.name(), t.listener()?)))
            .collect();
        let names: Vec<&'static str> = listening.iter().map(|(name, _)| *name).collect();
        let owner = Attachable {
            waitset,
            listeners: listening.into_iter().map(|(_, l)| l).collect(),
        };
        let attached = AttachedTopics::try_new(owner, |owner| {
            owner
                .listeners
                .iter()
                .zip(&names)
                .map(|(listener, &topic)| {
                    owner
                        .waitset
                        .attach_notification(listener.as_ref())
                        .map_err(|source| IpcError::WaitSetAttach { topic, source })
                })
                .collect::<Result<Attachments<'_>, IpcError>>()
        })?;
        Ok(Self { attached, names })
    }

    /// Sleeps until a publisher of any of the topics signals or `timeout` passes; returns whether
    /// a signal came. The pending signals are consumed, so the next wait sleeps again until new
    /// data is signalled. A signal to the process cuts the wait short (returning false).
    pub fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        let owner = self.attached.borrow_owner();
        if owner.listeners.is_empty() {
            std::thread::sleep(timeout);
            return Ok(false);
        }
        let mut signalled = false;
        let result = owner
            .waitset
            .wait_and_process_once_with_timeout(
                |_| {
                    signalled = true;
                    CallbackProgression::Continue
                },
                timeout,
            )
            .map_err(|source| IpcError::WaitSetRun {
                topics: owner.listeners.len(),
                source,
            })?;
        match result {
            WaitSetRunResult::AllEventsHandled | WaitSetRunResult::StopRequest => {}
            // A signal (the termination request the caller polls for) cut the wait short.
            WaitSetRunResult::Interrupt | WaitSetRunResult::TerminationRequest => return Ok(false),
        }
        for (listener, &topic) in owner.listeners.iter().zip(&self.names) {
            listener
                .try_wait(|_| {})
                .map_err(|source| IpcError::Wait { topic, source })?;
        }
        Ok(signalled)
    }
}
