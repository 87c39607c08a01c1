//! Topics: a publish-subscribe service plus an event service of the same name, so that a consumer
//! sleeps until data arrives instead of polling. Every process opens a topic with the same
//! settings, so whoever comes first creates it.

use std::cell::Cell;
use std::fmt::Debug;
use std::rc::Rc;
use std::time::Duration;

use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::{EventCreateError, EventOpenError, EventOpenOrCreateError};
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeCreateError, PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use iceoryx2::service::port_factory::{event, publish_subscribe};

use super::error::IpcError;
use super::node::IpcNode;
use crate::payload::{Received, Versioned};

/// Queue depth of every subscriber: a consumer may sleep up to this many samples of a 1 kHz topic
/// (plus margin at 8 kHz) before the oldest is overwritten.
pub const SUBSCRIBER_BUFFER: usize = 512;
/// Publishers per topic: restarted services leave a dead publisher until it is cleaned up.
pub const MAX_PUBLISHERS: usize = 16;
/// Subscribers per topic (the same numbers bound each topic's event service: notifiers and
/// listeners). A program that opens a topic of a running deployment asks for no more than these,
/// or iceoryx2 refuses it as incompatible.
pub const MAX_SUBSCRIBERS: usize = 16;
/// Nodes per topic.
pub const MAX_NODES: usize = 64;

/// Samples of the raw IMU topic its publisher keeps for subscribers that connect later: a fusion
/// process restarted after a crash receives the frames it missed while it was down (up to 256 ms
/// at 1 kHz) and the navigation output has no hole. Other topics keep none: a late consumer of
/// them wants what comes next, not what was.
const RAW_IMU_HISTORY: usize = 256;

/// Samples of topic `name` its publishers keep for subscribers that connect later.
pub fn history_size(name: &str) -> usize {
    if name == ipc_types::names::RAW_IMU {
        RAW_IMU_HISTORY
    } else {
        0
    }
}

fn service_name(topic: &'static str) -> Result<ServiceName, IpcError> {
    ServiceName::new(topic).map_err(|source| IpcError::TopicName { topic, source })
}

fn open_pubsub<T: Debug + ZeroCopySend + 'static>(
    node: &IpcNode,
    topic: &'static str,
) -> Result<publish_subscribe::PortFactory<ipc::Service, T, ()>, IpcError> {
    let name = service_name(topic)?;
    retry_interrupted(
        || {
            node.service_builder(&name)
                .publish_subscribe::<T>()
                .max_publishers(MAX_PUBLISHERS)
                .max_subscribers(MAX_SUBSCRIBERS)
                .max_nodes(MAX_NODES)
                .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
                .history_size(history_size(topic))
                .enable_safe_overflow(true)
                .open_or_create()
        },
        |e| {
            matches!(
                e,
                PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                    PublishSubscribeOpenError::Interrupt
                ) | PublishSubscribeOpenOrCreateError::PublishSubscribeCreateError(
                    PublishSubscribeCreateError::Interrupt
                )
            )
        },
    )
    .map_err(|source| IpcError::OpenTopic { topic, source })
}

/// Tries `open` again while it fails by `interrupted`: a signal (a stop requested during start-up)
/// interrupts a system call of the service's creation, and the process that asked to stop must still
/// come to its loop to stop cleanly. Bounded, so a storm of signals still ends in the error.
fn retry_interrupted<T, E>(
    mut open: impl FnMut() -> Result<T, E>,
    interrupted: impl Fn(&E) -> bool,
) -> Result<T, E> {
    const ATTEMPTS: usize = 8;
    let mut result = open();
    for _ in 1..ATTEMPTS {
        match &result {
            Err(e) if interrupted(e) => result = open(),
            _ => break,
        }
    }
    result
}

fn open_event(
    node: &IpcNode,
    topic: &'static str,
) -> Result<event::PortFactory<ipc::Service>, IpcError> {
    let name = service_name(topic)?;
    retry_interrupted(
        || {
            node.service_builder(&name)
                .event()
                .max_notifiers(MAX_PUBLISHERS)
                .max_listeners(MAX_SUBSCRIBERS)
                .max_nodes(MAX_NODES)
                .open_or_create()
        },
        |e| {
            matches!(
                e,
                EventOpenOrCreateError::EventOpenError(EventOpenError::Interrupt)
                    | EventOpenOrCreateError::EventCreateError(EventCreateError::Interrupt)
            )
        },
    )
    .map_err(|source| IpcError::OpenEvent { topic, source })
}

/// Publishing end of a topic: sends the sample, then wakes the topic's listeners.
pub struct TopicPublisher<T: Debug + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, T, ()>,
    notifier: Notifier<ipc::Service>,
    name: &'static str,
}

impl<T: Debug + ZeroCopySend + 'static> TopicPublisher<T> {
    /// Opens (or creates) topic `name` and a publisher on it.
    pub fn new(node: &IpcNode, name: &'static str) -> Result<Self, IpcError> {
        let publisher = open_pubsub::<T>(node, name)?
            .publisher_builder()
            .create()
            .map_err(|source| IpcError::Publisher {
                topic: name,
                source,
            })?;
        let notifier = open_event(node, name)?
            .notifier_builder()
            .create()
            .map_err(|source| IpcError::Notifier {
                topic: name,
                source,
            })?;
        Ok(Self {
            publisher,
            notifier,
            name,
        })
    }

    /// Writes `value` straight into shared memory and wakes the listeners.
    pub fn publish(&self, value: T) -> Result<(), IpcError> {
        let topic = self.name;
        let sample = self
            .publisher
            .loan_uninit()
            .map_err(|source| IpcError::Loan { topic, source })?;
        sample
            .write_payload(value)
            .send()
            .map_err(|source| IpcError::Send { topic, source })?;
        self.notifier
            .notify()
            .map_err(|source| IpcError::Notify { topic, source })?;
        Ok(())
    }
}

/// Receiving end of a topic. It hands over only samples written with this build's payload version:
/// the others are dropped and counted ([`TopicSubscriber::rejected`]), since their layout may differ
/// from the one this build would read them with.
pub struct TopicSubscriber<T: Debug + ZeroCopySend + 'static> {
    subscriber: Subscriber<ipc::Service, T, ()>,
    /// Shared with a [`super::TopicWaitSet`] that waits on this topic among others: the wait set
    /// keeps the listener attached for as long as it lives. None for a subscriber that only polls
    /// ([`TopicSubscriber::polled`]).
    listener: Option<Rc<Listener<ipc::Service>>>,
    name: &'static str,
    /// Samples of another payload version received since start. A `Cell`: receiving takes `&self`
    /// (the port is not shared between threads).
    rejected: Cell<u64>,
}

impl<T: Debug + ZeroCopySend + Copy + 'static> TopicSubscriber<T> {
    /// Opens (or creates) topic `name` and a subscriber on it, with a listener to wait on.
    pub fn new(node: &IpcNode, name: &'static str) -> Result<Self, IpcError> {
        Self::open(node, name, true)
    }

    /// A subscriber without a listener, for a reader that only polls (the watchdog's counts, a
    /// lane's look at its peer): the publisher then has one listener fewer to notify on every
    /// sample, a system call off the data path. Waiting on it only sleeps.
    pub fn polled(node: &IpcNode, name: &'static str) -> Result<Self, IpcError> {
        Self::open(node, name, false)
    }

    fn open(node: &IpcNode, name: &'static str, listen: bool) -> Result<Self, IpcError> {
        let subscriber = open_pubsub::<T>(node, name)?
            .subscriber_builder()
            .create()
            .map_err(|source| IpcError::Subscriber {
                topic: name,
                source,
            })?;
        super::own_ports::record_receiver(subscriber.id().value());
        let listener = match listen {
            true => Some(Rc::new(
                open_event(node, name)?
                    .listener_builder()
                    .create()
                    .map_err(|source| IpcError::Listener {
                        topic: name,
                        source,
                    })?,
            )),
            false => None,
        };
        Ok(Self {
            subscriber,
            listener,
            name,
            rejected: Cell::new(0),
        })
    }

    /// Sleeps until a publisher signals new data or `timeout` passes. Returns whether a signal came.
    pub fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        let Some(listener) = &self.listener else {
            std::thread::sleep(timeout);
            return Ok(false);
        };
        match listener.timed_wait(|_| {}, timeout) {
            Ok(woken) => Ok(woken > 0),
            // A signal (the termination request the caller polls for) cut the wait short.
            Err(ListenerWaitError::InterruptSignal) => Ok(false),
            Err(source) => Err(IpcError::Wait {
                topic: self.name,
                source,
            }),
        }
    }

    /// Whether a sample is queued (without taking it).
    pub fn has_samples(&self) -> Result<bool, IpcError> {
        self.subscriber
            .has_samples()
            .map_err(|source| IpcError::Connect {
                topic: self.name,
                source,
            })
    }

    /// Takes every pending notification off the listener without sleeping (a poller's chore).
    pub fn clear_signals(&self) -> Result<(), IpcError> {
        let Some(listener) = &self.listener else {
            return Ok(());
        };
        match listener.try_wait(|_| {}) {
            Ok(_) | Err(ListenerWaitError::InterruptSignal) => Ok(()),
            Err(source) => Err(IpcError::Wait {
                topic: self.name,
                source,
            }),
        }
    }

    /// The topic's name.
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The listener a [`super::TopicWaitSet`] attaches (and keeps attached); none when polled.
    pub(super) fn listener(&self) -> Option<Rc<Listener<ipc::Service>>> {
        self.listener.clone()
    }
}

impl<T: Versioned + Debug + ZeroCopySend + Copy + 'static> TopicSubscriber<T> {
    /// Next queued sample of this build's payload version, copied out of shared memory (payloads
    /// are small and `Copy`). Samples of another version before it are dropped and counted.
    pub fn receive(&self) -> Result<Option<T>, IpcError> {
        loop {
            match self.receive_any_version()? {
                Some(Received::Current(sample)) => return Ok(Some(sample)),
                Some(Received::OtherVersion(_)) => {}
                None => return Ok(None),
            }
        }
    }

    /// Next queued sample whatever its payload version, told apart (and one of another version
    /// counted): for the stage loop, which answers such a sample in its output stream.
    pub(crate) fn receive_any_version(&self) -> Result<Option<Received<T>>, IpcError> {
        let sample = self
            .subscriber
            .receive()
            .map_err(|source| IpcError::Receive {
                topic: self.name,
                source,
            })?;
        Ok(sample.map(|s| {
            let payload = *s.payload();
            if payload.is_current() {
                Received::Current(payload)
            } else {
                self.rejected.set(self.rejected.get() + 1);
                Received::OtherVersion(payload)
            }
        }))
    }

    /// Samples of another payload version received (and dropped) since start.
    pub fn rejected(&self) -> u64 {
        self.rejected.get()
    }
}

/// Something samples of `T` come from: one topic, or a merged stream such as the navigator lanes.
pub trait SampleSource<T> {
    /// Sleeps until data may be there or `timeout` passes.
    fn wait(&self, timeout: Duration) -> Result<bool, IpcError>;
    /// The next sample of this build's payload version, if one is there.
    fn receive(&mut self) -> Result<Option<T>, IpcError>;
    /// Samples of another payload version dropped since start.
    fn rejected(&self) -> u64;
}

impl<T: Versioned + Debug + ZeroCopySend + Copy + 'static> SampleSource<T> for TopicSubscriber<T> {
    fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        TopicSubscriber::wait(self, timeout)
    }

    fn receive(&mut self) -> Result<Option<T>, IpcError> {
        TopicSubscriber::receive(self)
    }

    fn rejected(&self) -> u64 {
        TopicSubscriber::rejected(self)
    }
}

#[cfg(test)]
mod tests {
    use super::retry_interrupted;

    /// Opens that fail `interrupts` times by an interrupt, then succeed; the number of calls made.
    fn opened_after(interrupts: usize) -> (Result<(), &'static str>, usize) {
        let mut calls = 0;
        let result = retry_interrupted(
            || {
                calls += 1;
                if calls <= interrupts {
                    Err("interrupt")
                } else {
                    Ok(())
                }
            },
            |e| *e == "interrupt",
        );
        (result, calls)
    }

    #[test]
    fn an_interrupted_open_is_tried_again_until_it_succeeds() {
        assert_eq!(opened_after(0), (Ok(()), 1));
        assert_eq!(opened_after(3), (Ok(()), 4));
    }

    #[test]
    fn a_storm_of_interrupts_ends_in_the_error_after_eight_tries() {
        assert_eq!(opened_after(100), (Err("interrupt"), 8));
    }

    #[test]
    fn any_other_error_is_returned_at_once() {
        let mut calls = 0;
        let result: Result<(), &str> = retry_interrupted(
            || {
                calls += 1;
                Err("denied")
            },
            |e| *e == "interrupt",
        );
        assert_eq!((result, calls), (Err("denied"), 1));
    }
}
