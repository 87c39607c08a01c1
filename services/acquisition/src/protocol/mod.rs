//! The sensor block's serial protocol (see `docs/protocol.md`): frame types, the wire codec and
//! the streaming decoder.

pub mod codec;
pub mod decoder;
pub mod error;
pub mod extend;
pub mod frame;
pub mod layout;

pub use codec::{decode_frame, encode, peek_frame_len};
pub use decoder::{Decoder, DecoderStats, ResumePoint};
pub use error::{DecodeError, EncodeError};
pub use extend::{SeqExtender, TimeExtender};
pub use frame::*;
pub use layout::{MAX_FRAME_LEN, MAX_PAYLOAD_LEN};
