//! The sensor block's serial protocol (see `docs/protocol.md`): frame types, the wire codec and
//! the streaming decoder with its sequence and clock extension — the contract between the device
//! (or the simulator that plays it) and acquisition. Pure: no I/O.
//!
//! Each frame type is one module under [`frames`] (its struct, payload layout, sanity check and IPC
//! form, through [`SensorFrame`]) and one line in [`for_each_frame!`] (`frame_list.rs`);
//! everything kept per type — [`FrameType`], [`Payload`], the codec's dispatch, acquisition's
//! topics — follows from that list.

pub mod arrival;
pub mod codec;
pub mod continuity;
pub mod decoder;
pub mod diagnosis;
pub mod error;
pub mod frame;
mod frame_list;
pub mod frame_period;
pub mod frame_type;
pub mod frames;
pub mod layout;
pub mod line_report;
pub mod lost_runs;
pub mod resume_point;
pub mod seq_extend;
pub mod seq_window;
pub mod time_extend;
pub mod wire;

pub use codec::{decode_frame, encode, peek_frame_len};
pub use continuity::Continuity;
pub use decoder::{Decoder, DecoderStats};
pub use diagnosis::{likely_cause, link_error};
pub use error::{ContentError, DecodeError, EncodeError, ImuContentError};
pub use frame::{DecodedFrame, Frame};
pub use frame_type::FrameType;
pub use frames::airspeed::airspeed_sane;
pub use frames::*;
pub use layout::{MAX_FRAME_LEN, MAX_PAYLOAD_LEN};
pub use line_report::{DeviceSpans, LineReport, LineVerdict, ScanOutcome, TypeRate, scan_outcome};
pub use resume_point::{ResumeError, ResumePoint};
pub use seq_extend::{SeqExtender, SeqVerdict};
pub use time_extend::{ExtendedTime, TimeExtender};
