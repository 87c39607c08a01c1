//! The two navigator lanes as one navigation stream.
//!
//! Both lanes run the same filter on the same fused IMU samples and stamp each solution with the
//! sequence number of its IMU sample, so the lanes' outputs are interchangeable sample by sample.
//! Every consumer of the navigation solution reads both lanes and follows one of them:
//! - [`selector`]: the rule that picks the lane to follow and merges both into one contiguous
//!   sequence (pure, allocation-free after construction);
//! - [`trust`]: whether a lane's solution may be chosen for its quality;
//! - [`switch`]: a lane change, its cause, and the changes counted by cause;
//! - [`subscriber`]: both lanes' topics read and merged for a consumer process;
//! - [`standby`]: when the standby lane reads its input in batches.

pub mod selector;
pub mod standby;
pub mod subscriber;
pub mod switch;
#[cfg(test)]
mod test_samples;
pub mod trust;

pub use selector::{LANES, LaneSelector, PENDING, SelectorConfig};
pub use standby::StandbyPacer;
pub use subscriber::NavSubscriber;
pub use switch::{Switch, SwitchCounts, SwitchReason};
pub use trust::{Distrust, distrust, trusted};
