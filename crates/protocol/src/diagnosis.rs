//! What the decoder's refusals say about the line: the decode error as the heartbeat carries it
//! ([`LinkError`]) and the likely cause an operator should look at first.

use ipc_types::LinkError;

use super::error::DecodeError;

/// The [`LinkError`] of a decoder's last refusal ([`crate::DecoderStats::last_error`]); `None`
/// (nothing refused yet) is [`LinkError::None`]. `Incomplete` is not a refusal and maps to `None`.
pub fn link_error(e: Option<&DecodeError>) -> LinkError {
    match e {
        None | Some(DecodeError::Incomplete { .. }) => LinkError::None,
        Some(DecodeError::NoSync) => LinkError::NoSync,
        Some(DecodeError::UnknownFrameType { .. }) => LinkError::UnknownFrameType,
        Some(DecodeError::BadPayloadLength { .. }) => LinkError::BadLength,
        Some(DecodeError::CrcMismatch { .. }) => LinkError::CrcMismatch,
        Some(DecodeError::Content(_) | DecodeError::OutOfRange(_)) => LinkError::BadContent,
    }
}

/// The likely cause of a line on which bytes arrive but no valid frame, from the last refusal and
/// the bytes discarded; one phrase, for a log line, a status report or an exit message.
pub fn likely_cause(last: LinkError, discarded: u64) -> String {
    match last {
        LinkError::NoSync => {
            format!("no sync word in {discarded} bytes: wrong baud rate or not a rins device?")
        }
        LinkError::CrcMismatch => "CRC failures: line noise or wrong baud rate".into(),
        LinkError::UnknownFrameType => {
            "frames of an unknown type: another protocol or a newer device firmware?".into()
        }
        LinkError::BadLength => {
            "frame lengths that do not fit their type: another protocol version or line noise?"
                .into()
        }
        LinkError::BadContent => {
            "frames with impossible content (channel counts, samples beyond 12 bits, values \
             beyond a sensor's range): device firmware fault or another protocol version?"
                .into()
        }
        LinkError::None => format!(
            "{discarded} bytes discarded without a refused frame: the start of a frame that never \
             completed?"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FrameType, ImuContentError};

    #[test]
    fn every_decode_error_has_its_link_error() {
        let cases = [
            (None, LinkError::None),
            (
                Some(DecodeError::Incomplete { needed: 10 }),
                LinkError::None,
            ),
            (Some(DecodeError::NoSync), LinkError::NoSync),
            (
                Some(DecodeError::UnknownFrameType { value: 9 }),
                LinkError::UnknownFrameType,
            ),
            (
                Some(DecodeError::BadPayloadLength {
                    frame_type: FrameType::Baro,
                    len: 7,
                }),
                LinkError::BadLength,
            ),
            (
                Some(DecodeError::CrcMismatch {
                    received: 1,
                    computed: 2,
                }),
                LinkError::CrcMismatch,
            ),
            (
                Some(DecodeError::Content(ImuContentError::CountOutOfRange {
                    field: "gyro_counts",
                    index: 0,
                    value: 3000,
                })),
                LinkError::BadContent,
            ),
        ];
        for (e, want) in cases {
            assert_eq!(link_error(e.as_ref()), want, "{e:?}");
        }
    }

    #[test]
    fn causes_name_what_to_check() {
        assert_eq!(
            likely_cause(LinkError::NoSync, 9600),
            "no sync word in 9600 bytes: wrong baud rate or not a rins device?"
        );
        assert!(likely_cause(LinkError::CrcMismatch, 5).contains("line noise"));
        for e in LinkError::ALL {
            assert!(!likely_cause(e, 1).is_empty(), "{e:?}");
        }
    }
}
