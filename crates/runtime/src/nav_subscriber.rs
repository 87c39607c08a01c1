//! The navigation stream as consumers see it: both navigator lanes read and merged by the
//! [`LaneSelector`] into one contiguous sequence. With a single lane the standby topic stays
//! silent and the stream is the primary's.

use std::time::Duration;

use ipc_types::{NavState, names};

use crate::ipc::{IpcError, IpcNode, SampleSource, TopicSubscriber, TopicWaitSet};
use crate::lane_selector::{LANES, LaneSelector, SelectorConfig, Switch};

/// Both navigator lanes' topics, merged into the stream consumers see.
pub struct NavSubscriber {
    lanes: [TopicSubscriber<NavState>; LANES],
    /// Wakes on either lane.
    waitset: TopicWaitSet,
    selector: LaneSelector,
    lane_totals: [u64; LANES],
    lane_latest: [Option<NavState>; LANES],
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
        })
    }

    /// Next sample of the merged stream, if one is due. Takes one sample of each lane at a time,
    /// so that a backlog (a consumer that slept) waits in the lanes' queues, which are deep, and
    /// not in the selector's ring, which holds only what a switch needs.
    pub fn receive(&mut self) -> Result<Option<NavState>, IpcError> {
        loop {
            if let Some(s) = self.selector.pop() {
                return Ok(Some(s));
            }
            let mut pulled = false;
            for (lane, sub) in self.lanes.iter().enumerate() {
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

    /// Sleeps until either lane publishes or `timeout` passes.
    pub fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        self.waitset.wait(timeout)
    }

    /// The lane delivering now.
    pub fn selected_lane(&self) -> usize {
        self.selector.selected()
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
}

impl SampleSource<NavState> for NavSubscriber {
    fn wait(&self, timeout: Duration) -> Result<bool, IpcError> {
        NavSubscriber::wait(self, timeout)
    }

    fn receive(&mut self) -> Result<Option<NavState>, IpcError> {
        NavSubscriber::receive(self)
    }
}
