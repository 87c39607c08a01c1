//! How a stage waits for its next input sample. `Event` sleeps on the topic's iceoryx2 listener
//! until the publisher notifies (no CPU while idle, one wake-up per sample); `Spin` polls the
//! subscriber's queue without sleeping (no wake-up, a whole CPU); `Hybrid` polls for a while after
//! each wake-up — catching a sample that follows soon without another wake-up — then sleeps.

use std::time::{Duration, Instant};

use crate::ipc::{IpcError, TopicSubscriber};

/// See the module documentation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WaitStrategy {
    /// Sleep on the listener until notified.
    #[default]
    Event,
    /// Poll the queue until a sample is there.
    Spin,
    /// Poll for `spin`, then sleep on the listener.
    Hybrid {
        /// How long to poll before sleeping.
        spin: Duration,
    },
}

impl WaitStrategy {
    /// Waits for a sample of `topic` the way this strategy says, at most `timeout`; returns
    /// whether one may be there. A signal to the process cuts a sleep short.
    pub fn wait<T>(&self, topic: &TopicSubscriber<T>, timeout: Duration) -> Result<bool, IpcError>
    where
        T: std::fmt::Debug + iceoryx2::prelude::ZeroCopySend + Copy + 'static,
    {
        match *self {
            WaitStrategy::Event => topic.wait(timeout),
            WaitStrategy::Spin => poll(topic, timeout),
            WaitStrategy::Hybrid { spin } => {
                if poll(topic, spin.min(timeout))? {
                    Ok(true)
                } else {
                    topic.wait(timeout.saturating_sub(spin))
                }
            }
        }
    }
}

/// Polls `topic`'s queue for up to `limit`. The notifications the publisher sends meanwhile are
/// taken off the listener only when the poll finds nothing (before a sleep, which they would
/// otherwise cut short for nothing), not per sample found: that would cost a system call per
/// sample on the path a polling stage exists to make short. Between, they wait in the listener's
/// socket, which a publisher's notification finding full does not fail.
fn poll<T>(topic: &TopicSubscriber<T>, limit: Duration) -> Result<bool, IpcError>
where
    T: std::fmt::Debug + iceoryx2::prelude::ZeroCopySend + Copy + 'static,
{
    let until = Instant::now() + limit;
    loop {
        if topic.has_samples()? {
            return Ok(true);
        }
        if Instant::now() >= until {
            topic.clear_signals()?;
            return Ok(false);
        }
        std::hint::spin_loop();
    }
}
