//! Payloads as CDR messages, and back.
//!
//! A payload's bytes are already a valid CDR (little-endian) encoding of its ROS 2 definition:
//! CDR aligns each primitive to its own size, counted from the byte after the 4-byte
//! encapsulation header, and every payload places each primitive at an offset that is a multiple
//! of its size with explicit padding fields in the gaps (the layout tests prove it). So a message
//! is the header followed by the payload's bytes, copied, with no per-field work on the hot path.

use crate::schema::{self, StructLayout};

/// The CDR encapsulation header: plain CDR, little endian, no options. Payloads are in the host's
/// byte order, and every host rins runs on is little endian (see the compile-time check below).
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

// The header above promises little endian; a big-endian build would write lies.
const _: () = assert!(cfg!(target_endian = "little"));

/// Appends the CDR message of a payload's bytes to `out`: the encapsulation header, then the bytes.
pub fn encode_into(payload_bytes: &[u8], out: &mut Vec<u8>) {
    out.reserve(CDR_LE_HEADER.len() + payload_bytes.len());
    out.extend_from_slice(&CDR_LE_HEADER);
    out.extend_from_slice(payload_bytes);
}

/// The payload bytes of a CDR message, `None` when the message does not start with the
/// little-endian header this crate writes.
pub fn payload_of(message: &[u8]) -> Option<&[u8]> {
    message.strip_prefix(&CDR_LE_HEADER[..])
}

/// A payload that can be recorded: a `#[repr(C)]` type with a described [`StructLayout`].
///
/// # Safety
///
/// Implement only for a `#[repr(C)]` type whose layout has no hidden padding (every byte belongs
/// to a field: the layout tests check that the fields of [`Recordable::layout`] cover
/// `size_of::<Self>()` without a gap) and whose fields are all valid for any bit pattern (integers,
/// floats, arrays and structs of those; no `bool`, enum, reference or pointer). Then viewing a
/// value as bytes reads only initialised memory, and any bytes of the right length are a value.
pub unsafe trait Recordable: Copy + 'static {
    /// The payload's layout and ROS 2 name.
    fn layout() -> &'static StructLayout;

    /// The payload's bytes as they are in shared memory.
    fn as_bytes(&self) -> &[u8] {
        // SAFETY: `Self` is `#[repr(C)]` with no padding (the trait's contract, checked by the
        // layout tests), so all `size_of::<Self>()` bytes behind `self` are initialised, and the
        // slice borrows `self`, so it cannot outlive it. `u8` has alignment 1.
        unsafe {
            core::slice::from_raw_parts((self as *const Self).cast::<u8>(), size_of::<Self>())
        }
    }

    /// The payload whose bytes are `bytes`; `None` when the length is not `size_of::<Self>()`.
    /// The version field is not checked here (a reader does, see [`crate::Messages`]).
    fn from_bytes(bytes: &[u8]) -> Option<Self> {
        if bytes.len() != size_of::<Self>() {
            return None;
        }
        // SAFETY: the length is checked above; `read_unaligned` copes with a byte buffer's
        // alignment; every field of `Self` is valid for any bit pattern (the trait's contract:
        // integers, floats and the `u8` discriminants enums travel as), so the value is valid.
        Some(unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<Self>()) })
    }
}

/// Makes every payload of the topic table [`Recordable`].
macro_rules! recordable {
    ($($payload:ident $kind:ident;)+) => {$(
        // SAFETY: a `#[repr(C)]` payload of `ipc-types` made of integers, floats, arrays and
        // nested structs of those, with explicit padding fields; its layout is tested to have no
        // gap (`schema` tests).
        unsafe impl Recordable for ipc_types::$payload {
            fn layout() -> &'static StructLayout {
                schema::layout_of::<Self>()
            }
        }
    )+};
}

ipc_types::for_each_topic!(payloads => recordable);

#[cfg(test)]
mod tests {
    use ipc_types::Altitude;

    use super::*;

    #[test]
    fn a_message_is_the_header_then_the_bytes() {
        let alt = Altitude {
            version: ipc_types::PAYLOAD_VERSION,
            height_m: 12.5,
            ..Default::default()
        };
        let mut out = Vec::new();
        encode_into(alt.as_bytes(), &mut out);
        assert_eq!(out.len(), 4 + size_of::<Altitude>());
        assert_eq!(out[..4], CDR_LE_HEADER);
        let back = payload_of(&out).and_then(Altitude::from_bytes);
        assert_eq!(back, Some(alt));
    }

    #[test]
    fn a_wrong_length_or_header_is_refused() {
        let alt = Altitude::default();
        assert_eq!(Altitude::from_bytes(&alt.as_bytes()[1..]), None);
        assert_eq!(payload_of(&[0x00, 0x00, 0x00, 0x00, 1]), None);
    }

    /// Checks every payload of the topic table.
    macro_rules! check_every_payload {
        ($($payload:ident $kind:ident;)+) => {$(
            check::<ipc_types::$payload>();
        )+};
    }

    fn check<T: Recordable>() {
        assert_eq!(T::layout().size, size_of::<T>());
        assert_eq!(T::layout().align, align_of::<T>());
    }

    #[test]
    fn every_recordable_has_its_own_layout() {
        ipc_types::for_each_topic!(payloads => check_every_payload);
    }
}
