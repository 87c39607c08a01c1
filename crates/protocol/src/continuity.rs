//! How an extended counter (sequence number, device time) continues from the frame before.

/// What the extension did with one frame's wire value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Continuity {
    /// The previous value plus the wire step, or the first value (the wire value, or the resume
    /// point plus the step to it).
    Continued,
    /// A discontinuity of the device's counter: the extension was re-based so that it continues
    /// from the previous value, with no hole and without running backwards.
    Rebased,
    /// The resume point did not fit the device's first value and was ignored: the extension starts
    /// from the wire value, as on a first start.
    ResumeIgnored,
}
