//! Waiting on several topics at once: one listener per topic cannot wait on two, an iceoryx2 wait
//! set can wait on any number.

use std::fmt::Debug;
use std::time::Duration;

use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;

use super::error::IpcError;
use super::topic::TopicSubscriber;

/// An iceoryx2 wait set, made once and reused: each [`TopicWaitSet::wait`] attaches the topics
/// for the length of the wait only, so the wait set borrows nothing between waits.
pub struct TopicWaitSet {
    waitset: WaitSet<ipc::Service>,
}

impl TopicWaitSet {
    /// A wait set that leaves signals to the caller: a signal cuts a wait short, and the caller
    /// polls its own stop flag ([`crate::shutdown::Shutdown`]).
    pub fn new() -> Result<Self, IpcError> {
        let waitset = WaitSetBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|source| IpcError::WaitSetCreate { source })?;
        Ok(Self { waitset })
    }

    /// Sleeps until a publisher of any of `topics` signals or `timeout` passes; returns whether a
    /// signal came. The topics' pending signals are consumed, so the next wait sleeps again until
    /// new data is signalled. A signal to the process cuts the wait short (returning false).
    pub fn wait<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        topics: &[&TopicSubscriber<T>],
        timeout: Duration,
    ) -> Result<bool, IpcError> {
        if topics.is_empty() {
            std::thread::sleep(timeout);
            return Ok(false);
        }
        let outcome = self.attach_and_wait(topics, topics, timeout)?;
        match outcome {
            (WaitSetRunResult::AllEventsHandled | WaitSetRunResult::StopRequest, _) => {}
            // A signal (the termination request the caller polls for) cut the wait short.
            (WaitSetRunResult::Interrupt | WaitSetRunResult::TerminationRequest, _) => {
                return Ok(false);
            }
        }
        for topic in topics {
            topic.clear_signals()?;
        }
        Ok(outcome.1)
    }

    /// Attaches the first of `rest`, then the others by recursion, and waits once all are
    /// attached: each guard lives on the stack of its own call and detaches its topic when the
    /// call returns, so a wait allocates nothing whatever the number of topics. Returns the run's
    /// result and whether a notification came.
    fn attach_and_wait<T: Debug + ZeroCopySend + Copy + 'static>(
        &self,
        all: &[&TopicSubscriber<T>],
        rest: &[&TopicSubscriber<T>],
        timeout: Duration,
    ) -> Result<(WaitSetRunResult, bool), IpcError> {
        let Some((first, others)) = rest.split_first() else {
            let mut signalled = false;
            let result = self
                .waitset
                .wait_and_process_once_with_timeout(
                    |_| {
                        signalled = true;
                        CallbackProgression::Continue
                    },
                    timeout,
                )
                .map_err(|source| IpcError::WaitSetRun {
                    topics: all.len(),
                    source,
                })?;
            return Ok((result, signalled));
        };
        let _guard = self
            .waitset
            .attach_notification(first.listener())
            .map_err(|source| IpcError::WaitSetAttach {
                topic: first.name(),
                source,
            })?;
        self.attach_and_wait(all, others, timeout)
    }
}
