//! The frame types of the serial protocol, one module per type, generated from
//! [`for_each_frame!`](crate::for_each_frame), the one list of them (in `frame_list.rs`).
//!
//! A frame type's module holds its contents' struct (in device units), its payload layout and
//! sane ranges, and its [`SensorFrame`] implementation: payload length, encoding, decoding, the
//! sanity check, and the raw IPC payload and topic acquisition publishes it as. From the list
//! follow the type byte enum [`FrameType`] (in `frame_type.rs`), the [`Payload`] enum, the codec's
//! dispatch by type and acquisition's publishers. A new frame type is one new file here plus one
//! line in the list.

use ipc_types::Header;

use crate::error::{ContentError, DecodeError};
use crate::frame_type::FrameType;
use crate::wire::Writer;

/// One frame type of the protocol, implemented by its contents' struct in its own module. The
/// codec handles the header and the CRC around it; this is the payload.
pub trait SensorFrame: Copy + Into<Payload> {
    /// The frame type: its type byte on the wire (`TYPE as u8`) and its name (`TYPE.name()`).
    /// Must be the variant of this struct's line in [`for_each_frame!`](crate::for_each_frame)
    /// (checked at compile time).
    const TYPE: FrameType;
    /// Largest payload of this type, bytes; for a fixed-size payload, its only length.
    const MAX_PAYLOAD_LEN: usize;
    /// The raw IPC payload (an `ipc_types` struct) acquisition publishes this frame as.
    type Ipc: Copy + core::fmt::Debug;
    /// The topic that payload is published on (an `ipc_types::names` constant).
    const TOPIC: &'static str;

    /// Whether `len` is a payload length this type can have, judged from the header alone so that
    /// a corrupt length is refused before waiting for bytes that may never belong to it. Default:
    /// a fixed-size payload's one length.
    fn len_plausible(len: usize) -> bool {
        len == Self::MAX_PAYLOAD_LEN
    }

    /// Payload length on the wire of these contents. Default: the fixed size.
    fn wire_len(&self) -> usize {
        Self::MAX_PAYLOAD_LEN
    }

    /// Refuses contents no working sensor of this kind produces: the same check binds what is
    /// encoded and what is decoded (after the CRC matched). Default: every value is sane.
    fn check_sane(&self) -> Result<(), ContentError> {
        Ok(())
    }

    /// Writes the payload; `w` has exactly [`wire_len`](Self::wire_len) bytes left, and the
    /// contents passed [`check_sane`](Self::check_sane).
    fn encode(&self, w: &mut Writer<'_>);

    /// Reads the payload, whose length passed [`len_plausible`](Self::len_plausible). The codec
    /// applies [`check_sane`](Self::check_sane) to the result.
    fn decode(payload: &[u8]) -> Result<Self, DecodeError>;

    /// The raw IPC payload of these contents, stamped with `header` (the frame's origin).
    fn to_ipc(&self, header: Header) -> Self::Ipc;
}

/// Generates, from the frame list: the modules, [`Payload`] and the dispatch by type through
/// [`SensorFrame`].
macro_rules! payload_and_dispatch {
    ($($(#[$doc:meta])* $variant:ident = $byte:literal => $module:ident :: $frame:ident,)+) => {
        $(pub mod $module;)+
        $(pub use self::$module::$frame;)+

        impl FrameType {
            /// Whether `len` is a payload length a frame of this type can have
            /// ([`SensorFrame::len_plausible`]).
            pub fn payload_len_plausible(self, len: usize) -> bool {
                match self {
                    $(FrameType::$variant => <$module::$frame as SensorFrame>::len_plausible(len),)+
                }
            }

            /// Decodes a payload of this type and checks that it is sane.
            pub(crate) fn decode_payload(self, payload: &[u8]) -> Result<Payload, DecodeError> {
                match self {
                    $(FrameType::$variant => decode_sane::<$module::$frame>(payload),)+
                }
            }
        }

        /// A frame's contents, by frame type.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Payload {
            $($(#[$doc])* $variant($frame),)+
        }

        impl Payload {
            /// The frame type that carries this payload.
            pub fn frame_type(&self) -> FrameType {
                match self {
                    $(Payload::$variant(_) => FrameType::$variant,)+
                }
            }

            /// Payload length on the wire, in bytes ([`SensorFrame::wire_len`]).
            pub fn wire_len(&self) -> usize {
                match self {
                    $(Payload::$variant(f) => f.wire_len(),)+
                }
            }

            /// Refuses contents no working sensor produces ([`SensorFrame::check_sane`]).
            pub fn check_sane(&self) -> Result<(), ContentError> {
                match self {
                    $(Payload::$variant(f) => f.check_sane(),)+
                }
            }

            /// Writes the payload ([`SensorFrame::encode`]).
            pub(crate) fn encode(&self, w: &mut Writer<'_>) {
                match self {
                    $(Payload::$variant(f) => f.encode(w),)+
                }
            }
        }

        $(
            impl From<$frame> for Payload {
                fn from(f: $frame) -> Self {
                    Payload::$variant(f)
                }
            }

            // The struct's own idea of its type agrees with its line in the list.
            const _: () = assert!(<$frame as SensorFrame>::TYPE as u8 == FrameType::$variant as u8);
        )+

        /// Largest payload of any frame type, bytes.
        pub(crate) const LARGEST_PAYLOAD_LEN: usize =
            max_of(&[$(<$frame as SensorFrame>::MAX_PAYLOAD_LEN),+]);
    };
}

crate::frame_list::for_each_frame!(payload_and_dispatch);

fn decode_sane<F: SensorFrame>(payload: &[u8]) -> Result<Payload, DecodeError> {
    let frame = F::decode(payload)?;
    frame.check_sane()?;
    Ok(frame.into())
}

const fn max_of(values: &[usize]) -> usize {
    let mut max = 0;
    let mut i = 0;
    while i < values.len() {
        if values[i] > max {
            max = values[i];
        }
        i += 1;
    }
    max
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_lengths_are_judged_by_each_type() {
        let plausible = |t: FrameType| -> Vec<usize> {
            (0..=255)
                .filter(|&len| t.payload_len_plausible(len))
                .collect()
        };
        let imu: Vec<usize> = (9..=81).step_by(2).collect();
        assert_eq!(plausible(FrameType::Imu), imu);
        assert_eq!(plausible(FrameType::Baro), [6]);
        assert_eq!(plausible(FrameType::Mag), [12]);
        assert_eq!(plausible(FrameType::Aux), [2]);
        assert_eq!(plausible(FrameType::Airspeed), [6]);
        assert_eq!(LARGEST_PAYLOAD_LEN, 81);
    }

    #[test]
    fn a_payload_knows_its_type_and_length() {
        let payloads = [
            Payload::from(ImuFrame {
                n_gyro: 3,
                n_accel: 3,
                n_temperature: 1,
                ..ImuFrame::default()
            }),
            BaroFrame::default().into(),
            MagFrame::default().into(),
            AuxFrame::default().into(),
            AirspeedFrame::default().into(),
        ];
        let seen: Vec<(FrameType, usize)> = payloads
            .iter()
            .map(|p| (p.frame_type(), p.wire_len()))
            .collect();
        assert_eq!(
            seen,
            [
                (FrameType::Imu, 9 + 2 * 7),
                (FrameType::Baro, 6),
                (FrameType::Mag, 12),
                (FrameType::Aux, 2),
                (FrameType::Airspeed, 6),
            ]
        );
    }
}
