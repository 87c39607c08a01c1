//! The navigation stream as consumers see it: both navigator lanes read and merged by the
//! [`LaneSelector`] into one contiguous sequence. With a single lane the standby topic stays
//! silent and the stream is the primary's. Every lane switch is logged once, with its cause.

use std::time::Duration;

use ipc_types::{NavState, names};

use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcError, IpcNode, SampleSource, TopicSubscriber, TopicWaitSet};

use crate::lanes::selector::{LANES, LaneSelector, SelectorConfig};
use crate::lanes::switch::{Switch, SwitchCounts};

/// Both navigator lanes' topics, merged into the stream consumers see.
pub struct NavSubscriber {
    lanes: [TopicSubscriber<NavState>; LANES],
    /// Wakes on either lane.
    waitset: TopicWaitSet,
    selector: LaneSelector,
    lane_totals: [u64; LANES],
    lane_latest: [Option<NavState>; LANES],
    /// Switches already logged.
    logged_switches: u64,
}

impl NavSubscriber {
    /// Subscribes to both lanes on `node`.
    pub fn new(node: &IpcNode) -> Result<Self, IpcError> {
        let lanes = [
            TopicSubscriber::new(node, names::NAV_LANES[0])?,
            TopicSubscriber::new(node, names::NAV_LANES[1])?,
        ];
        let [a, b] = &lanes;
        let waitset = TopicWaitSet::new(&[a, b])?;
        Ok(Self {
            lanes,
            waitset,
            selector: LaneSelector::new(SelectorConfig::default()),
            lane_totals: [0; LANES],
            lane_latest: [None; LANES],
            logged_switches: 0,
        })
    }

    /// Next sample of the merged stream, if one is due. Takes one sample of each lane at a time,
    /// so that a backlog (a consumer that slept) waits in the lanes' queues, which are deep, and
    /// not in the selector's ring, which holds only what a switch needs; a lane whose ring is full
    /// is left in its queue until the selected lane delivers or is found dead.
    pub fn receive(&mut self) -> Result<Option<NavState>, IpcError> {
        let now_ns = monotonic_ns();
        loop {
            let next = self.selector.pop_at(now_ns);
            self.log_switch();
            if let Some(s) = next {
                return Ok(Some(s));
            }
            let mut pulled = false;
            for (lane, sub) in self.lanes.iter().enumerate() {
                if !self.selector.has_room(lane) {
                    continue;
                }
                if let Some(s) = sub.receive()? {
                    self.lane_totals[lane] += 1;
                    self.lane_latest[lane] = Some(s);
                    self.selector.push(lane, s);
                    pulled = true;
                }
            }
            if !pulled {
                return Ok(None);
            }
        }
    }

    /// One log line per switch, naming its cause; nothing while the lane stays.
    fn log_switch(&mut self) {
        let switches = self.selector.switches();
        if switches == self.logged_switches {
            return;
        }
        self.logged_switches = switches;
        if let Some(s) = self.selector.last_switch() {
            tracing::warn!(
                from = s.from,
                to = s.to,
                at_seq = s.at_seq,
                cause = s.reason.name(),
                switches,
                "navigation lane switch: {s}"
            );
        }
    }

    /// Sleeps until either lane publishes or `timeout` passes.
    pub fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        self.waitset.wait(timeout)
    }

    /// The lane delivering now.
    pub fn selected_lane(&self) -> usize {
        self.selector.selected()
    }

    /// Samples of another payload version dropped from either lane since start (not in
    /// [`NavSubscriber::lane_totals`]).
    pub fn rejected(&self) -> u64 {
        self.lanes.iter().map(TopicSubscriber::rejected).sum()
    }

    /// Samples received from each lane since start.
    pub fn lane_totals(&self) -> [u64; LANES] {
        self.lane_totals
    }

    /// The newest sample of each lane.
    pub fn lane_latest(&self, lane: usize) -> Option<&NavState> {
        self.lane_latest.get(lane).and_then(Option::as_ref)
    }

    /// Samples taken from the other lane to fill a hole in the selected one.
    pub fn filled(&self) -> u64 {
        self.selector.filled()
    }

    /// Lane changes since start, and the most recent one.
    pub fn switches(&self) -> (u64, Option<Switch>) {
        (self.selector.switches(), self.selector.last_switch())
    }

    /// Lane changes since start, by cause.
    pub fn switch_counts(&self) -> SwitchCounts {
        self.selector.switch_counts()
    }
}

impl SampleSource<NavState> for NavSubscriber {
    fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        NavSubscriber::wait(self, timeout)
    }

    fn receive(&mut self) -> Result<Option<NavState>, IpcError> {
        NavSubscriber::receive(self)
    }

    fn rejected(&self) -> u64 {
        NavSubscriber::rejected(self)
    }
}
