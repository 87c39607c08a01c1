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
        Self::with_lanes([
            TopicSubscriber::new(node, names::NAV_LANES[0])?,
            TopicSubscriber::new(node, names::NAV_LANES[1])?,
        ])
    }

    /// Subscribes to both lanes on `node` for a reader that only polls (no listener for the lanes
    /// to notify; [`NavSubscriber::wait`] only sleeps).
    pub fn polled(node: &IpcNode) -> Result<Self, IpcError> {
        Self::with_lanes([
            TopicSubscriber::polled(node, names::NAV_LANES[0])?,
            TopicSubscriber::polled(node, names::NAV_LANES[1])?,
        ])
    }

    fn with_lanes(lanes: [TopicSubscriber<NavState>; LANES]) -> Result<Self, IpcError> {
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
    /// is left in its queue until the selected lane delivers or is found dead. The other lane is
    /// then taken up to the selected lane's next sample ([`Self::catch_up`]).
    pub fn receive(&mut self) -> Result<Option<NavState>, IpcError> {
        let now_ns = monotonic_ns();
        loop {
            let next = self.selector.pop_at(now_ns);
            self.log_switch();
            if let Some(s) = next {
                return Ok(Some(s));
            }
            let mut pulled = false;
            for lane in 0..LANES {
                pulled |= self.selector.has_room(lane) && self.pull(lane)?;
            }
            if !pulled {
                return Ok(None);
            }
            self.catch_up()?;
        }
    }

    /// One sample of `lane` into the selector; whether there was one.
    fn pull(&mut self, lane: usize) -> Result<bool, IpcError> {
        let Some(s) = self.lanes[lane].receive()? else {
            return Ok(false);
        };
        self.lane_totals[lane] += 1;
        self.lane_latest[lane] = Some(s);
        self.selector.push(lane, s);
        Ok(true)
    }

    /// Pulls the other lane up to the selected lane's next sample. A hole in the selected lane is
    /// filled only from what the selector already holds, and the other lane may publish in
    /// batches (the standby reads its input in batches while the primary serves): one sample of
    /// it per round would leave the rest of a hole unfilled.
    fn catch_up(&mut self) -> Result<(), IpcError> {
        let other = 1 - self.selector.selected();
        let Some(next) = self.selector.next_seq(self.selector.selected()) else {
            return Ok(());
        };
        while self.lane_latest[other].is_none_or(|s| s.header.origin_seq + 1 < next)
            && self.selector.has_room(other)
            && self.pull(other)?
        {}
        Ok(())
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
