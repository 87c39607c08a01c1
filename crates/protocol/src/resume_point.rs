//! Where a run's extended numbering stood, for the run that replaces it, and the bounds a point
//! must keep to be used at all.

use core::fmt;

use super::frame_type::FrameType;

/// The last extended sequence number of each frame type (indexed by [`FrameType::index`]) and
/// the last extended device time, each with the wire value it was given to. A restarted
/// acquisition continues from the point its previous run saved, so the sequence numbers consumers
/// see never run backwards. The wire values matter after a sequence jump or a re-based clock,
/// when the extended value's low bits no longer are the wire's; without them (`None`) the low bits
/// stand in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ResumePoint {
    /// Last extended sequence number handed out, per frame type; `None` for a type never received.
    pub seq: [Option<u64>; FrameType::COUNT],
    /// The wire sequence number of that frame, per frame type.
    pub seq_wire: [Option<u16>; FrameType::COUNT],
    /// Last extended device time handed out, µs; `None` before the first frame.
    pub time_us: Option<u64>,
    /// The wire device time of that frame, µs.
    pub time_wire: Option<u32>,
}

/// A sequence number this large (2^48: 8 900 years of frames at 1 kHz) is not one a run reached.
pub const MAX_RESUME_SEQ: u64 = 1 << 48;
/// A device time this large (2^62 µs: 146 000 years) is not one a run reached.
pub const MAX_RESUME_TIME_US: u64 = 1 << 62;

/// Why a resume point was rejected as a whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ResumeError {
    /// A sequence number at or above [`MAX_RESUME_SEQ`].
    SeqOutOfBounds {
        /// The frame type whose number it is.
        frame_type: FrameType,
        /// The rejected number.
        value: u64,
    },
    /// A device time at or above [`MAX_RESUME_TIME_US`].
    TimeOutOfBounds {
        /// The rejected time, µs.
        value: u64,
    },
}

impl fmt::Display for ResumeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ResumeError::SeqOutOfBounds { frame_type, value } => write!(
                f,
                "resume point seq.{} = {value}: must be < 2^48 ({MAX_RESUME_SEQ})",
                frame_type.name()
            ),
            ResumeError::TimeOutOfBounds { value } => write!(
                f,
                "resume point time_us = {value}: must be < 2^62 ({MAX_RESUME_TIME_US})"
            ),
        }
    }
}

impl std::error::Error for ResumeError {}

impl ResumePoint {
    /// Whether every value is within bounds; the first that is not, named.
    pub fn check(&self) -> Result<(), ResumeError> {
        for (frame_type, seq) in FrameType::ALL.into_iter().zip(self.seq) {
            if let Some(value) = seq.filter(|&s| s >= MAX_RESUME_SEQ) {
                return Err(ResumeError::SeqOutOfBounds { frame_type, value });
            }
        }
        match self.time_us {
            Some(value) if value >= MAX_RESUME_TIME_US => {
                Err(ResumeError::TimeOutOfBounds { value })
            }
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_beyond_the_bounds_are_named() {
        let good = ResumePoint {
            seq: [Some(MAX_RESUME_SEQ - 1), None, Some(0), None, None],
            time_us: Some(MAX_RESUME_TIME_US - 1),
            ..ResumePoint::default()
        };
        assert_eq!(good.check(), Ok(()));
        let seq = ResumePoint {
            seq: [None, None, Some(MAX_RESUME_SEQ), None, None],
            ..good
        };
        let e = seq.check().unwrap_err();
        assert_eq!(
            e,
            ResumeError::SeqOutOfBounds {
                frame_type: FrameType::Mag,
                value: MAX_RESUME_SEQ
            }
        );
        assert!(e.to_string().contains("seq.mag = 281474976710656"), "{e}");
        let time = ResumePoint {
            time_us: Some(u64::MAX),
            ..good
        };
        assert!(
            time.check()
                .unwrap_err()
                .to_string()
                .contains("time_us = 18446744073709551615")
        );
    }
}
