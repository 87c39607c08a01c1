//! The loop of every pipeline stage that a topic drives (fusion, altimeter, navigator lanes): it
//! waits for the input topic, receives, checks the payload version (once, counting refusals),
//! hands each sample to the stage's step, stamps and publishes what the step returns, keeps the
//! counters, sends the heartbeat and stops when asked. A stage supplies only its step.
//!
//! Per sample the loop adds no allocation, no log and no lock: a receive, a version compare, the
//! step, a clock read and a publish.

use std::fmt::Debug;
use std::time::Duration;

use iceoryx2::prelude::ZeroCopySend;
use ipc_types::{Health, ServiceKind, Stage as StageId};

use crate::ipc::{IpcError, IpcNode};
use crate::payload::{Stamped, Versioned};
use crate::service_loop::ServiceLoop;
use crate::shutdown::Shutdown;
use crate::stage_io::{Received, StageInput, StagePublisher};
use crate::wait_strategy::WaitStrategy;

/// What a stage's step made of one input sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step<T> {
    /// Publish this.
    Publish(T),
    /// The sample was refused (it does not fit the configured stage): counted in
    /// [`Health::rejected`], and this says so downstream.
    Rejected(T),
    /// Nothing to publish for this sample.
    Skip,
}

/// A pipeline stage's own logic, called by [`StageLoop::run`]. Only [`PipelineStage::step`] is required;
/// the other hooks let a stage read side topics and keep its own counters.
pub trait PipelineStage {
    /// What the stage reads from its input topic.
    type Input: Versioned + Debug + ZeroCopySend + Copy + 'static;
    /// What it publishes on its output topic.
    type Output: Stamped + Debug + ZeroCopySend + Copy + 'static;

    /// Once per wake-up, before the input is read: side topics (commands, aiding) whose samples
    /// are older than (or as old as) the input that woke the stage.
    fn before_input(&mut self, counters: &mut Health) -> Result<(), IpcError> {
        let _ = counters;
        Ok(())
    }

    /// Before each input sample is read: side topics that must be taken in sample by sample (an
    /// aiding reading published before the input sample's frame is then always in hand when the
    /// sample is stepped, however the samples were batched).
    fn before_sample(&mut self, counters: &mut Health) -> Result<(), IpcError> {
        let _ = counters;
        Ok(())
    }

    /// Every input sample, whatever its payload version, before it is stepped.
    fn received(&mut self, input: &Self::Input, counters: &mut Health) {
        let _ = (input, counters);
    }

    /// One input sample of this build's payload version.
    fn step(&mut self, input: &Self::Input) -> Step<Self::Output>;

    /// One input sample of another payload version (already counted rejected): what, if anything,
    /// to publish in its place.
    fn other_version(&mut self, input: &Self::Input) -> Option<Self::Output> {
        let _ = input;
        None
    }

    /// An output as it was published (stamped).
    fn published(&mut self, output: &Self::Output) {
        let _ = output;
    }

    /// How long to sleep before reading the input instead of waiting for it, when the stage
    /// reads in batches for now (a standby lane); `None`: wait the loop's way.
    fn batch_period(&self) -> Option<Duration> {
        None
    }

    /// Once per wake-up, after the input was drained; `received` samples were read this time.
    fn after_input(&mut self, received: u64, counters: &mut Health) {
        let _ = (received, counters);
    }
}

/// Which process a stage is and which topics it joins.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StageTopics {
    /// The process: its heartbeat says so.
    pub kind: ServiceKind,
    /// The stamp its outputs carry.
    pub stage: StageId,
    /// The topic that drives it.
    pub input: &'static str,
    /// The topic it publishes.
    pub output: &'static str,
    /// The longest sleep waiting for input: how often the stop flag, the heartbeat and
    /// [`PipelineStage::after_input`] are served when no input comes.
    pub wait: Duration,
}

/// The input, the output and the service loop of one stage.
pub struct StageLoop<I: Debug + ZeroCopySend + 'static, O: Debug + ZeroCopySend + 'static> {
    service: ServiceLoop,
    input: StageInput<I>,
    output: StagePublisher<O>,
    wait: Duration,
    strategy: WaitStrategy,
}

impl<I, O> StageLoop<I, O>
where
    I: Versioned + Debug + ZeroCopySend + Copy + 'static,
    O: Stamped + Debug + ZeroCopySend + Copy + 'static,
{
    /// Joins the stage's topics on `node`; the loop ends when `shutdown` is requested.
    pub fn new(
        node: &IpcNode,
        topics: &StageTopics,
        shutdown: &Shutdown,
    ) -> Result<Self, IpcError> {
        Ok(Self {
            input: StageInput::new(node, topics.input)?,
            output: StagePublisher::new(node, topics.output, topics.stage)?,
            service: ServiceLoop::new(node, topics.kind, shutdown)?,
            wait: topics.wait,
            strategy: WaitStrategy::Event,
        })
    }

    /// Waits for input the way `strategy` says (default: [`WaitStrategy::Event`]).
    pub fn with_wait_strategy(mut self, strategy: WaitStrategy) -> Self {
        self.strategy = strategy;
        self
    }

    /// Runs `stage` until a stop is requested; returns the final counters.
    pub fn run<S: PipelineStage<Input = I, Output = O>>(
        mut self,
        stage: &mut S,
    ) -> Result<Health, IpcError> {
        while self.service.running() {
            match stage.batch_period() {
                Some(period) => self.input.sleep_for_batch(period.min(self.wait))?,
                None => self.input.wait_with(&self.strategy, self.wait)?,
            };
            let counters = &mut self.service.counters;
            stage.before_input(counters)?;
            let mut received = 0;
            while let Some(sample) = self.input.receive(counters)? {
                stage.before_sample(counters)?;
                received += 1;
                counters.received += 1;
                stage.received(sample.payload(), counters);
                let output = match sample {
                    Received::Current(input) => match stage.step(&input) {
                        Step::Publish(output) => Some(output),
                        Step::Rejected(output) => {
                            counters.rejected += 1;
                            Some(output)
                        }
                        Step::Skip => None,
                    },
                    Received::OtherVersion(input) => stage.other_version(&input),
                };
                if let Some(output) = output {
                    let sent = self.output.publish(output)?;
                    counters.published += 1;
                    stage.published(&sent);
                }
            }
            stage.after_input(received, counters);
            self.service.beat()?;
        }
        Ok(self.service.counters)
    }
}
