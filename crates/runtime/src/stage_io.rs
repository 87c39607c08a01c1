//! The two ends of a pipeline stage: the topics it reads, each sample checked against this build's
//! payload version on receipt (and counted when refused), and the topics it publishes, each sample
//! stamped with the stage's publish time on its way out.

use std::fmt::Debug;
use std::time::Duration;

use iceoryx2::prelude::ZeroCopySend;
use ipc_types::{Health, Stage};

use crate::clock::monotonic_ns;
use crate::ipc::{IpcError, IpcNode, TopicPublisher, TopicSubscriber};
use crate::payload::{Stamped, Versioned};

/// A sample as [`StageInput::receive`] hands it over.
pub use crate::payload::Received;

/// A topic a stage reads.
pub struct StageInput<T: Debug + ZeroCopySend + 'static> {
    topic: TopicSubscriber<T>,
}

impl<T: Versioned + Debug + ZeroCopySend + Copy + 'static> StageInput<T> {
    /// Subscribes to topic `name`.
    pub fn new(node: &IpcNode, name: &'static str) -> Result<Self, IpcError> {
        Ok(Self {
            topic: TopicSubscriber::new(node, name)?,
        })
    }

    /// The next sample, if one is queued. One written with another payload version (told apart by
    /// the topic's subscriber) is counted in `counters.rejected` here, and handed over as such so
    /// that the stage may answer it in its output stream.
    pub fn receive(&self, counters: &mut Health) -> Result<Option<Received<T>>, IpcError> {
        let received = self.topic.receive_any_version()?;
        if let Some(Received::OtherVersion(_)) = received {
            counters.rejected += 1;
        }
        Ok(received)
    }

    /// Hands every queued sample of this build's payload version to `on_sample`, in order; the
    /// others are counted rejected and dropped.
    pub fn drain(
        &self,
        counters: &mut Health,
        mut on_sample: impl FnMut(T),
    ) -> Result<(), IpcError> {
        while let Some(received) = self.receive(counters)? {
            if let Received::Current(sample) = received {
                on_sample(sample);
            }
        }
        Ok(())
    }

    /// Sleeps until a publisher signals or `timeout` passes; a signal to the process cuts it short.
    pub fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        self.topic.wait(timeout)
    }

    /// Waits for input the way `strategy` says, at most `timeout`.
    pub fn wait_with(
        &self,
        strategy: &crate::wait_strategy::WaitStrategy,
        timeout: Duration,
    ) -> Result<bool, IpcError> {
        strategy.wait(&self.topic, timeout)
    }

    /// Sleeps `period`, then takes the notifications of the samples queued meanwhile off the
    /// listener (so they neither pile up nor wake a later wait for nothing); returns whether a
    /// sample is there.
    pub fn sleep_for_batch(&self, period: Duration) -> Result<bool, IpcError> {
        std::thread::sleep(period);
        self.topic.clear_signals()?;
        self.topic.has_samples()
    }
}

/// A topic a stage publishes: each sample leaves stamped with the stage's publish time.
pub struct StagePublisher<T: Debug + ZeroCopySend + 'static> {
    topic: TopicPublisher<T>,
    stage: Stage,
}

impl<T: Stamped + Debug + ZeroCopySend + Copy + 'static> StagePublisher<T> {
    /// Publishes on topic `name` as `stage`.
    pub fn new(node: &IpcNode, name: &'static str, stage: Stage) -> Result<Self, IpcError> {
        Ok(Self {
            topic: TopicPublisher::new(node, name)?,
            stage,
        })
    }

    /// Stamps `sample` with the stage's publish time, now, and publishes it; returns it as sent.
    pub fn publish(&self, mut sample: T) -> Result<T, IpcError> {
        sample.header_mut().stamp(self.stage, monotonic_ns());
        self.topic.publish(sample)?;
        Ok(sample)
    }
}
