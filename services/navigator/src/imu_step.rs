//! What one IMU sample did in the aided navigator.

use crate::ekf::UpdateOutcome;
use crate::mechanisation::StepOutcome;

/// What one IMU sample did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuStep {
    /// The propagation (while aligning: `None`).
    pub propagated: Option<StepOutcome>,
    /// The stance detector fired on this sample.
    pub stance: bool,
    /// The zero-velocity update, when one was attempted.
    pub zupt: Option<UpdateOutcome>,
}
